//! The pictures of the relighting experiment: renders of per-vertex radiance, and the grid
//! of the rotation axis (each method's render over its false-colour luminance error).

use ndarray::{Array2, Array3, Axis};

use super::condition::Condition;
use super::scene::{Relit, SceneUnderTest};
use super::{PictureGrid, RelightRecord};
use crate::Result;
use crate::plot::labelled_colour_tiles;
use haarshift::PlanarImage;
use haarshift_relight::Scene;
use haarshift_relight::render::{Background, Camera, LitMesh, render, to_srgb8};

impl SceneUnderTest<'_> {
    /// The renders of the rotation axis over their false-colour error images, and the truth
    /// over a blank.
    pub(super) fn grid(
        &self,
        condition: &Condition<'_>,
        shaded: &[(RelightRecord, Relit)],
        truth: &Array2<f64>,
    ) -> Result<PictureGrid> {
        let scene = &self.subject.scene;
        let camera = &self.cameras[condition.camera];
        let size = self.protocol.image;
        let backdrop = condition.light.environment.lat_long(
            condition.light.environment.map().height().min(512),
            &condition.rotation,
        )?;
        let background = Background::Environment(&backdrop);
        let exposure = crate::gallery::exposure_for(truth);
        let black = Background::Colour([0.0; 3]);
        let want = luminance(&draw(scene, camera, size, truth, black)?);
        let mut errors = Vec::new();
        for (_, s) in shaded {
            let got = luminance(&draw(scene, camera, size, &s.radiance, black)?);
            errors.push(&got - &want);
        }
        // One scale for the whole grid: the 99th percentile of |error| over every tile, so
        // that the colours compare across methods.
        let mut all: Vec<f64> = errors.iter().flatten().map(|e| e.abs()).collect();
        all.sort_by(f64::total_cmp);
        let scale = all
            .get(all.len() * 99 / 100)
            .copied()
            .filter(|&v| v > 0.0)
            .unwrap_or(1.0);
        let mut tiles: Vec<(String, Array3<f64>)> = Vec::new();
        for (r, s) in shaded {
            let image = to_srgb8(
                &draw(scene, camera, size, &s.radiance, background)?,
                exposure,
            )?;
            tiles.push((
                format!("{} {}: {:.1e}", r.method, r.parameters, r.rms_relative),
                image.planes().mapv(f64::from),
            ));
        }
        let image = to_srgb8(&draw(scene, camera, size, truth, background)?, exposure)?;
        tiles.push(("truth".into(), image.planes().mapv(f64::from)));
        for (e, (r, _)) in errors.iter().zip(shaded) {
            tiles.push((
                format!("error of {} {}", r.method, r.parameters),
                false_colour(e, scale),
            ));
        }
        let (h, w) = want.dim();
        let bar = Array2::from_shape_fn((h, w), |(_, j)| scale * (2.0 * j as f64 / w as f64 - 1.0));
        tiles.push((
            format!("scale: -{scale:.1e} to +{scale:.1e}"),
            false_colour(&bar, scale),
        ));
        let views: Vec<(String, ndarray::ArrayView3<'_, f64>)> =
            tiles.iter().map(|(l, t)| (l.clone(), t.view())).collect();
        let image = labelled_colour_tiles(&views, shaded.len() + 1, 1)?;
        Ok(PictureGrid {
            name: format!(
                "{}-{}-{}",
                self.subject.name, condition.light.name, condition.brdf
            )
            .replace(':', ""),
            caption: format!(
                "{} under {} ({}), {}, camera {}: top, each rotation method's render and the \
                 truth; below each, the luminance error (blue: too dark, red: too bright, \
                 white: none; saturated at +-{scale:.2e}, the 99th percentile of every tile)",
                self.subject.name,
                condition.light.name,
                format_angles(condition.angles),
                condition.brdf,
                condition.camera
            ),
            image,
        })
    }
}

fn format_angles(a: [f64; 3]) -> String {
    format!("yaw {} pitch {} roll {}", a[0], a[1], a[2])
}

/// `radiance` (`(V, 3)`) drawn by `camera`, linear.
pub(super) fn draw(
    scene: &Scene,
    camera: &Camera,
    (width, height): (usize, usize),
    radiance: &Array2<f64>,
    background: Background<'_>,
) -> Result<PlanarImage<f32>> {
    let radiance = radiance.mapv(|v| v as f32);
    let mesh = LitMesh {
        positions: scene.mesh.positions(),
        triangles: scene.mesh.triangles(),
        radiance: radiance.view(),
    };
    render(camera, width, height, &mesh, background)
}

/// Rec. 709 luminance of a linear RGB image.
fn luminance(image: &PlanarImage<f32>) -> Array2<f64> {
    let p = image.planes();
    let lum = |c: usize| p.index_axis(Axis(0), c).mapv(f64::from);
    lum(0) * 0.2126 + lum(1) * 0.7152 + lum(2) * 0.0722
}

/// A diverging false colour, `(3, H, W)` in 0..=255: blue for `-scale`, white for 0, red for
/// `+scale`, saturated beyond.
pub(super) fn false_colour(error: &Array2<f64>, scale: f64) -> Array3<f64> {
    let (h, w) = error.dim();
    Array3::from_shape_fn((3, h, w), |(c, i, j)| {
        let t = (error[[i, j]] / scale).clamp(-1.0, 1.0);
        let v = match (c, t >= 0.0) {
            (0, true) | (2, false) => 1.0,
            _ => 1.0 - t.abs(),
        };
        255.0 * v
    })
}
