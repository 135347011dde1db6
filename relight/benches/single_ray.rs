//! The single-ray path `SceneBvh` traced before its packet traversal: `obvhs`'s compressed
//! 8-wide BVH (CWBVH, Ylitie et al. 2017) built by `build_cwbvh_from_tris` (medium preset) and
//! its any-hit query `ray_traverse_miss`, one ray at a time. The named baseline of the ray
//! benches (`relight/benches/rays.rs`, `tools/measure/src/bin/rays.rs`); shared by both through `#[path]`.

use glam::Vec3A;
use haarshift_relight::{Mesh, Occlusion};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;

/// A mesh's triangles (none degenerate, no tiny scene: the bench scenes) in a CWBVH.
pub struct SingleRay {
    bvh: CwBvh,
    triangles: Vec<RtTriangle>,
}

impl SingleRay {
    pub fn new(mesh: &Mesh) -> Self {
        let p = mesh.positions();
        let point = |i: u32| Vec3A::from_array([0, 1, 2].map(|k| p[[i as usize, k]] as f32));
        let triangles: Vec<Triangle> = (mesh.triangles().iter())
            .map(|t| {
                let [v0, v1, v2] = t.map(point);
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = build_cwbvh_from_tris(
            &triangles,
            BvhBuildParams::medium_build(),
            &mut Default::default(),
        );
        let ordered = (bvh.primitive_indices.iter())
            .map(|&i| RtTriangle::from(&triangles[i as usize]))
            .collect();
        SingleRay {
            bvh,
            triangles: ordered,
        }
    }
}

impl Occlusion for SingleRay {
    fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let ray = Ray::new(
            Vec3A::from_array(origin),
            Vec3A::from_array(direction),
            0.0,
            t_max,
        );
        !(self.bvh).ray_traverse_miss(ray, |ray, id| self.triangles[id].intersect(ray))
    }
}
