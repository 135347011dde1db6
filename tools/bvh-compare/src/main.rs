//! Occlusion rays per second of three BVH crates on the same rays: every vertex of a scene
//! (a fixed subset for the large one), every lat-long 32 x 64 texel centre direction above its
//! horizon, origins offset along the normal by 1e-4 x the bounding-box diagonal, stop at the
//! first hit, rayon over vertices. Prints a Markdown table; rerun with
//! `cd tools/bvh-compare && cargo run --release`.

use std::path::Path;
use std::time::Instant;

use haarshift::relight::{Generator, Mesh, Occlusion, SceneBvh, add_ground_plane, ray_offset};
use haarshift::faces::{ParamKind, Parameterization};
use rayon::prelude::*;

/// One vertex's rays: origin and the directions above its horizon.
struct Work {
    origin: [f32; 3],
    directions: Vec<[f32; 3]>,
}

fn workload(mesh: &Mesh, stride: usize) -> Vec<Work> {
    let param = Parameterization::new(ParamKind::LatLong, 32).unwrap();
    let s = param.face_size();
    let dirs: Vec<[f64; 3]> = (0..param.texels())
        .map(|t| param.texel_direction(t / (s * s), (t / s) % s, t % s))
        .collect();
    let eps = ray_offset(mesh);
    (0..mesh.vertex_count())
        .step_by(stride)
        .map(|v| {
            let p = [0, 1, 2].map(|k| mesh.positions()[[v, k]]);
            let n = [0, 1, 2].map(|k| mesh.normals()[[v, k]]);
            Work {
                origin: [0, 1, 2].map(|k| (p[k] + eps * n[k]) as f32),
                directions: dirs
                    .iter()
                    .filter(|d| d[0] * n[0] + d[1] * n[1] + d[2] * n[2] > 0.0)
                    .map(|d| d.map(|x| x as f32))
                    .collect(),
            }
        })
        .collect()
}

/// `bvh` 0.12: a binary SAH BVH; traversal yields candidates, the triangle test is ours
/// (theirs culls back faces, so both windings are tried).
struct BvhCrate {
    bvh: bvh::bvh::Bvh<f32, 3>,
    tris: Vec<Tri>,
}

struct Tri {
    a: nalgebra::Point3<f32>,
    b: nalgebra::Point3<f32>,
    c: nalgebra::Point3<f32>,
    node: usize,
}

impl bvh::aabb::Bounded<f32, 3> for Tri {
    fn aabb(&self) -> bvh::aabb::Aabb<f32, 3> {
        bvh::aabb::Aabb::empty()
            .grow(&self.a)
            .grow(&self.b)
            .grow(&self.c)
    }
}

impl bvh::bounding_hierarchy::BHShape<f32, 3> for Tri {
    fn set_bh_node_index(&mut self, i: usize) {
        self.node = i;
    }
    fn bh_node_index(&self) -> usize {
        self.node
    }
}

fn points(mesh: &Mesh) -> Vec<[f32; 3]> {
    mesh.positions()
        .outer_iter()
        .map(|r| [r[0] as f32, r[1] as f32, r[2] as f32])
        .collect()
}

impl BvhCrate {
    fn new(mesh: &Mesh) -> Self {
        let p = points(mesh);
        let pt = |i: u32| nalgebra::Point3::from(p[i as usize]);
        let mut tris: Vec<Tri> = mesh
            .triangles()
            .iter()
            .map(|t| Tri {
                a: pt(t[0]),
                b: pt(t[1]),
                c: pt(t[2]),
                node: 0,
            })
            .collect();
        let bvh = bvh::bvh::Bvh::build(&mut tris);
        BvhCrate { bvh, tris }
    }
}

impl Occlusion for BvhCrate {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let ray = bvh::ray::Ray::new(
            nalgebra::Point3::from(origin),
            nalgebra::Vector3::from(direction),
        );
        self.bvh.traverse_iterator(&ray, &self.tris).any(|t| {
            let front = ray.intersects_triangle(&t.a, &t.b, &t.c).distance;
            let back = ray.intersects_triangle(&t.a, &t.c, &t.b).distance;
            let t = front.min(back);
            t.is_finite() && t <= t_max
        })
    }
}

/// `parry3d` 0.31: `TriMesh` (its own SIMD quad BVH) and the `RayCast::intersects_local_ray`
/// query.
struct ParryCrate {
    mesh: parry3d::shape::TriMesh,
}

impl ParryCrate {
    fn new(mesh: &Mesh) -> Self {
        let vertices = points(mesh)
            .into_iter()
            .map(parry3d::math::Vector::from)
            .collect();
        ParryCrate {
            mesh: parry3d::shape::TriMesh::new(vertices, mesh.triangles().to_vec())
                .expect("a valid mesh"),
        }
    }
}

impl Occlusion for ParryCrate {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        use parry3d::query::RayCast;
        let ray = parry3d::query::Ray::new(origin.into(), direction.into());
        self.mesh.intersects_local_ray(&ray, t_max)
    }
}

/// Blocked rays and rays per second (wall clock, the median of `rounds`).
fn trace(occ: &impl Occlusion, work: &[Work], rounds: usize) -> (u64, f64) {
    let rays: u64 = work.iter().map(|w| w.directions.len() as u64).sum();
    let mut rates = Vec::new();
    let mut blocked = 0;
    for _ in 0..rounds {
        let start = Instant::now();
        blocked = work
            .par_iter()
            .map(|w| {
                w.directions
                    .iter()
                    .filter(|&&d| occ.occluded(w.origin, d, f32::INFINITY))
                    .count() as u64
            })
            .sum();
        rates.push(rays as f64 / start.elapsed().as_secs_f64());
    }
    rates.sort_by(f64::total_cmp);
    (blocked, rates[rates.len() / 2])
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut bunny = Mesh::load(&root.join("testdata/meshes/bunny.ply")).unwrap();
    add_ground_plane(&mut bunny).expect("the bunny has a ground plane");
    let cubes = Generator::Cubes {
        count: 10,
        cells: 10,
        distance: 1.5,
    }
    .mesh()
    .unwrap();
    println!("threads: {}", rayon::current_num_threads());
    println!("| scene | triangles | rays | crate | build (s) | rays/s (median of 3) | blocked |");
    println!("|---|---|---|---|---|---|---|");
    for (name, mesh, stride) in [("bunny + ground plane", &bunny, 1), ("cubes", &cubes, 20)] {
        let work = workload(mesh, stride);
        let rays: usize = work.iter().map(|w| w.directions.len()).sum();
        let row = |crate_name: &str, build: f64, (blocked, rate): (u64, f64)| {
            println!(
                "| {name} ({} vertices) | {} | {rays} | {crate_name} | {build:.3} | {:.2} M | {blocked} |",
                mesh.vertex_count(),
                mesh.triangles().len(),
                rate / 1e6
            );
        };
        let t = Instant::now();
        let o = SceneBvh::new(mesh);
        let build = t.elapsed().as_secs_f64();
        row("obvhs 0.4 (CWBVH)", build, trace(&o, &work, 3));
        drop(o);
        let t = Instant::now();
        let b = BvhCrate::new(mesh);
        let build = t.elapsed().as_secs_f64();
        row("bvh 0.12", build, trace(&b, &work, 3));
        drop(b);
        let t = Instant::now();
        let p = ParryCrate::new(mesh);
        let build = t.elapsed().as_secs_f64();
        row("parry3d 0.31", build, trace(&p, &work, 3));
    }
}
