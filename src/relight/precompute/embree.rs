//! Occlusion queries answered by Intel Embree 3 ([`RayTracer::Embree`](super::raycast::RayTracer),
//! cargo feature `embree`): the system's `libembree3` (Debian's `libembree-dev`, 3.13.5)
//! through the [`embree3`] crate's safe bindings.
//!
//! **Why Embree.** On the rays of a vertex-major precomputation (one origin, neighbouring
//! directions), Embree's 16-wide packet query `rtcOccluded16` traverses its wide BVHs with
//! SIMD box tests per node and tests several triangles at once: the whole precomputation,
//! rays and encoding, runs 1.9-3.3x faster on one thread than through haarshift's own
//! binary-tree packets ([`packet`](super::packet)) on the scenes `benches/rays_results.md`
//! measures, the more the larger the scene. Our packets stay the portable path and the one whose every bit is
//! specified; Embree is chosen when it is compiled in and starts
//! ([`RayTracer::best`](super::raycast::RayTracer::best)).
//!
//! **What differs.** Embree's triangle test is its own, so a ray through a shared edge may be
//! answered otherwise than by our packets' Moller-Trumbore: every such ray passes within a few
//! `1e-6` (barycentric) of an edge (`benches/compare_rays.py` works each one out in f64). The
//! scene is built `ROBUST` (Embree's watertight mode, at some cost in speed): a ray through an
//! edge shared by two triangles then hits one of them, and every ray of the three scenes
//! `benches/rays_results.md` measures is answered as Embree 4.4 answers it. A hit counts at
//! `0 <= t <= t_max` (Embree's closed interval, where our packets' is `t < t_max`);
//! visibility asks with `t_max` infinite.
//!
//! **Floating point.** Creating an Embree device switches the calling thread to
//! flush-to-zero and denormals-are-zero (`embree3` does, for Embree's speed). That would change
//! every later subnormal result of that thread, so the one device of the process is created on
//! a thread of its own that ends at once; queries leave the caller's floating-point state
//! alone.

use std::sync::OnceLock;

use embree3::{
    BufferUsage, BuildQuality, Config, Device, Format, GeometryKind, IntersectContext, Ray, Ray16,
    Scene, SceneFlags, ValidMask, ValidMaskN,
};

/// The rays of one `rtcOccluded16` packet.
pub(crate) const EMBREE_LANES: usize = 16;

/// The process's Embree device, created on first use (`None` when Embree refuses to start:
/// an unsupported CPU, say).
fn device() -> Option<&'static Device> {
    static DEVICE: OnceLock<Option<Device>> = OnceLock::new();
    DEVICE
        .get_or_init(|| {
            // Errors are read back from the device (`rtcGetDeviceError`), not printed.
            let config = Config {
                report_errors: false,
                ..Config::default()
            };
            std::thread::spawn(move || Device::with_config(config).ok())
                .join()
                .ok()
                .flatten()
        })
        .as_ref()
}

/// Whether Embree starts on this machine.
pub(crate) fn available() -> bool {
    device().is_some()
}

/// A committed Embree scene of a triangle soup; see the [module docs](self).
pub(crate) struct EmbreeScene {
    scene: Scene<'static>,
}

/// `rtcOccluded16` asks for its valid mask aligned like its packet, to 64 bytes (`embree3`'s
/// `ValidMaskN` is aligned to 16 only).
#[repr(C, align(64))]
struct Valid16(ValidMaskN<EMBREE_LANES>);

impl EmbreeScene {
    /// Builds the scene of `triangles` (not empty), or `None` when Embree is not available or
    /// reports an error (out of memory, say): the caller then traces with its own BVH.
    pub(crate) fn new(triangles: &[[[f32; 3]; 3]]) -> Option<Self> {
        let device = device()?;
        // Three corners a triangle, each its own vertex: every index must fit a u32.
        let vertices = triangles.len().checked_mul(3)?;
        let corners = u32::try_from(vertices).ok()?;
        let mut geometry = device.create_geometry(GeometryKind::TRIANGLE).ok()?;
        geometry
            .set_new_buffer::<[f32; 3]>(BufferUsage::VERTEX, 0, Format::FLOAT3, 12, vertices)
            .ok()?
            .copy_from_slice(triangles.as_flattened());
        let mut index = geometry
            .set_new_buffer::<[u32; 3]>(BufferUsage::INDEX, 0, Format::UINT3, 12, triangles.len())
            .ok()?;
        for (triangle, first) in index.iter_mut().zip((0..corners).step_by(3)) {
            *triangle = [first, first + 1, first + 2];
        }
        let geometry = geometry.commit();
        let mut scene = device.create_scene().ok()?;
        scene.set_flags(SceneFlags::ROBUST);
        scene.set_build_quality(BuildQuality::HIGH);
        scene.attach_geometry(&geometry);
        scene.commit();
        (device.get_error() == embree3::Error::NONE).then_some(EmbreeScene { scene })
    }

    /// Whether the ray `origin + t direction`, `0 <= t <= t_max`, hits a triangle.
    pub(crate) fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let mut ray = Ray::segment(origin, direction, 0.0, t_max);
        self.scene
            .occluded(&mut IntersectContext::coherent(), &mut ray)
    }

    /// `blocked[i]` for the rays `origin + t directions[i]`, at most [`EMBREE_LANES`] of them,
    /// traced as one packet.
    pub(crate) fn occluded_packet(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        blocked: &mut [bool],
    ) {
        debug_assert!(directions.len() <= EMBREE_LANES && blocked.len() == directions.len());
        let mut valid = Valid16(ValidMaskN::all_active());
        let mut dirs = [[0.0; 3]; EMBREE_LANES];
        for (lane, v) in valid.0.lanes_mut().iter_mut().enumerate() {
            match directions.get(lane) {
                Some(&d) => dirs[lane] = d,
                None => *v = ValidMask::Invalid,
            }
        }
        let mut rays = Ray16::segment(
            [origin; EMBREE_LANES],
            dirs,
            [0.0; EMBREE_LANES],
            [t_max; EMBREE_LANES],
        );
        self.scene
            .occluded16(&mut IntersectContext::coherent(), &mut rays, &valid.0);
        // Embree marks a blocked ray by setting its far distance to minus infinity.
        for (b, &far) in blocked.iter_mut().zip(&rays.tfar) {
            *b = far == f32::NEG_INFINITY;
        }
    }
}
