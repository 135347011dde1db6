//! A software shadow buffer: the orthographic depth map of the scene seen along one direction
//! (Microsoft 2003's direction-major visibility, where each direction's shadow buffer answers the
//! visibility of every vertex at once).
//!
//! **Frame.** For a direction `d` (towards the light) the map looks down `-d` onto the plane
//! through the scene's bounding-sphere centre `c`, spanned by `u, v` perpendicular to `d`; it
//! covers the square `[-R, R]^2` (`R` the bounding sphere's radius, half the bounding-box
//! diagonal) with `size x size` texels. A point's *height* is `(p - c) . d`; each texel keeps
//! the greatest height of the triangles covering its centre (the surface nearest the light).
//!
//! **Test.** A point of height `h` is lit when `h + bias >= depth`, with a slope-scaled bias
//! `texel x (1 + min(tan theta, 4))` ([`ShadowMap::bias`]), `theta` the angle between the vertex
//! normal and `d`: a surface tilted away from the light rises by up to `texel x tan theta` across
//! the texel around its own vertex, which must not shadow the vertex itself (shadow acne).
//!
//! **Where it disagrees with rays.** Near silhouettes, where a texel centre and a ray pass on
//! different sides of an edge ([`ShadowMap::near_silhouette`] tells whether the lit/unlit answer
//! changes within a given number of texels); and for *contact* occluders closer to the vertex
//! than the bias (where the bunny's base touches the ground, in creases at grazing angles),
//! which no depth map can separate from the receiver.

use crate::Mesh;
use crate::scene::mesh::{cross, dot, sub};

/// An orthographic depth map of a mesh along one direction; see the [module docs](self).
///
/// ```
/// use haarshift_relight::{Mesh, ShadowMap};
/// use ndarray::array;
/// // A square roof at y = 1 over the origin.
/// let roof = Mesh::new(array![[-1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, -1.0],
///                             [-1.0, 1.0, -1.0], [0.0, 0.0, 0.0]],
///                      vec![[0, 1, 2], [0, 2, 3]], None).unwrap();
/// let map = ShadowMap::render(&roof, [0.0, 1.0, 0.0], 64);
/// assert!(!map.lit([0.0, 0.0, 0.0], 1.0)); // under the roof
/// assert!(map.lit([0.0, 1.5, 0.0], 1.0)); // above it
/// ```
#[derive(Clone, Debug)]
pub struct ShadowMap {
    direction: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
    centre: [f64; 3],
    radius: f64,
    size: usize,
    texel: f64,
    depth: Vec<f32>,
}

impl ShadowMap {
    /// Renders `mesh` seen along the unit `direction` into a `size x size` map.
    pub fn render(mesh: &Mesh, direction: [f64; 3], size: usize) -> Self {
        let bounds = mesh.bounds();
        let radius = 0.5 * bounds.diagonal().max(f64::MIN_POSITIVE);
        // Any axis not parallel to d gives the frame.
        let axis = if direction[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let u = normalise(cross(axis, direction));
        let v = cross(direction, u);
        let mut map = ShadowMap {
            direction,
            u,
            v,
            centre: bounds.centre(),
            radius,
            size: size.max(1),
            texel: 2.0 * radius / size.max(1) as f64,
            depth: vec![f32::NEG_INFINITY; size.max(1) * size.max(1)],
        };
        let p = mesh.positions();
        let projected: Vec<[f64; 3]> = p
            .outer_iter()
            .map(|r| map.project([r[0], r[1], r[2]]))
            .collect();
        for t in mesh.triangles() {
            map.rasterise(t.map(|i| projected[i as usize]));
        }
        map
    }

    /// `(x, y)` in texel units and the height of `p`.
    fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let q = sub(p, self.centre);
        [
            (dot(q, self.u) + self.radius) / self.texel,
            (dot(q, self.v) + self.radius) / self.texel,
            dot(q, self.direction),
        ]
    }

    /// Keeps, in every texel whose centre the projected triangle covers, the greatest height.
    fn rasterise(&mut self, [a, b, c]: [[f64; 3]; 3]) {
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if area.abs() < 1e-12 {
            return; // edge-on: its neighbours cover the same texels
        }
        let n = self.size as f64;
        let lo = |k: usize| (a[k].min(b[k]).min(c[k]) - 0.5).ceil().max(0.0) as usize;
        let hi = |k: usize| ((a[k].max(b[k]).max(c[k]) - 0.5).floor().min(n - 1.0)).max(-1.0);
        let (x1, y1) = (hi(0), hi(1));
        if x1 < 0.0 || y1 < 0.0 {
            return;
        }
        let (x0, y0, x1, y1) = (lo(0), lo(1), x1 as usize, y1 as usize);
        let inv = 1.0 / area;
        for y in y0..=y1 {
            let py = y as f64 + 0.5;
            for x in x0..=x1 {
                let px = x as f64 + 0.5;
                // Barycentric coordinates from the edge functions.
                let wa = ((b[0] - px) * (c[1] - py) - (c[0] - px) * (b[1] - py)) * inv;
                let wb = ((c[0] - px) * (a[1] - py) - (a[0] - px) * (c[1] - py)) * inv;
                let wc = 1.0 - wa - wb;
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                let h = (wa * a[2] + wb * b[2] + wc * c[2]) as f32;
                let d = &mut self.depth[y * self.size + x];
                *d = d.max(h);
            }
        }
    }

    /// The texel under `p` and `p`'s height plus its bias, `cos_theta` the cosine between the
    /// vertex normal and the direction.
    fn locate(&self, p: [f64; 3], cos_theta: f64) -> (isize, isize, f64) {
        let [x, y, h] = self.project(p);
        (
            x.floor() as isize,
            y.floor() as isize,
            h + self.bias(cos_theta),
        )
    }

    fn lit_at(&self, x: isize, y: isize, h: f64) -> bool {
        let n = self.size as isize;
        if x < 0 || y < 0 || x >= n || y >= n {
            return true;
        }
        h >= f64::from(self.depth[y as usize * self.size + x as usize])
    }

    /// Whether the point `p` (already offset off its surface) is lit along the map's direction;
    /// `cos_theta` is `n . d` at its vertex (it scales the bias).
    pub fn lit(&self, p: [f64; 3], cos_theta: f64) -> bool {
        let (x, y, h) = self.locate(p, cos_theta);
        self.lit_at(x, y, h)
    }

    /// Whether the lit/unlit answer for `p` changes within `radius` texels of its own texel (a
    /// silhouette of the scene seen along the direction passes there).
    pub fn near_silhouette(&self, p: [f64; 3], cos_theta: f64, radius: usize) -> bool {
        let (x, y, h) = self.locate(p, cos_theta);
        let own = self.lit_at(x, y, h);
        let r = radius as isize;
        (-r..=r).any(|dy| (-r..=r).any(|dx| self.lit_at(x + dx, y + dy, h) != own))
    }

    /// The depth bias, in world units, for a vertex whose normal makes `cos_theta` with the
    /// direction: `texel x (1 + min(tan theta, 4))`.
    pub fn bias(&self, cos_theta: f64) -> f64 {
        let cos = cos_theta.clamp(1e-6, 1.0);
        let tan = ((1.0 - cos * cos).sqrt() / cos).min(4.0);
        self.texel * (1.0 + tan)
    }

    /// How far (in texels) the surface nearest the light at `p`'s texel lies above `p`.
    #[cfg(test)]
    pub(crate) fn clearance(&self, p: [f64; 3]) -> f64 {
        let [x, y, h] = self.project(p);
        let (x, y) = (x.floor() as usize, y.floor() as usize);
        (f64::from(self.depth[y * self.size + x]) - h) / self.texel
    }

    /// The side of a texel in world units.
    pub fn texel(&self) -> f64 {
        self.texel
    }

    /// Bytes held by the depth buffer.
    pub fn bytes(&self) -> usize {
        self.depth.len() * std::mem::size_of::<f32>()
    }
}

fn normalise(a: [f64; 3]) -> [f64; 3] {
    let len = dot(a, a).sqrt();
    a.map(|x| x / len)
}
