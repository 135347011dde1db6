//! Ray queries answered by Intel Embree 3 ([`RayTracer::Embree`](super::raycast::RayTracer)),
//! the system's `libembree3.so.3` **loaded at run time** (Debian's and Ubuntu's package
//! `libembree3-3`): nothing is linked, so every build runs on a machine without Embree, and
//! uses it on one with it.
//!
//! **Why Embree.** On the rays of a vertex-major precomputation (one origin, neighbouring
//! directions), Embree's 16-wide packet query `rtcOccluded16` traverses its wide BVHs with
//! SIMD box tests per node and tests several triangles at once: the whole precomputation,
//! rays and encoding, runs 1.9-3.3x faster on one thread than through haarshift's own
//! binary-tree packets (`packet`) on the scenes `benches/rays_results.md`
//! measures, the more the larger the scene. Our packets stay the portable path and the one
//! whose every bit is specified; Embree is chosen where it loads and its device starts
//! ([`RayTracer::best`](super::raycast::RayTracer::best)).
//!
//! **Loading.** The library is `$HAARSHIFT_EMBREE` ([`EMBREE_LIBRARY_VAR`]) when set, else
//! `libembree3.so.3` found by the dynamic loader's search. It is loaded once per process;
//! it must report version 3 (`rtcGetDeviceProperty`), since the structures below are Embree
//! 3's, laid out as its default build has them (`RTC_MAX_INSTANCE_LEVEL_COUNT` 1,
//! `RTC_MIN_WIDTH` 0: Debian's and Intel's releases). Why it did not load is kept, for the
//! one-line refusal of `--ray-tracer embree` and for `relight precompute --help`
//! (`unavailable`).
//!
//! **What is bound** (one table, `Api`): device, geometry and scene creation, the any-hit
//! queries `rtcOccluded1`/`rtcOccluded16` and the closest-hit query `rtcIntersect16`.
//! `rtcInitIntersectContext` is an inline function of Embree's header, not an exported
//! symbol: `IntersectContext::coherent` writes what it writes, with the coherent flag.
//!
//! **What differs from our packets.** Embree's triangle test is its own, so a ray through a
//! shared edge may be answered otherwise than by our packets' Moller-Trumbore: every such ray
//! passes within a few `1e-6` (barycentric) of an edge (`benches/compare_rays.py` works each
//! one out in f64). The scene is built `ROBUST` (Embree's watertight mode, at some cost in
//! speed): a ray through an edge shared by two triangles then hits one of them, and every ray
//! of the three scenes `benches/rays_results.md` measures is answered as Embree 4.4 answers
//! it. A hit counts at `0 <= t <= t_max` (Embree's closed interval, where our packets' is
//! `t < t_max`); visibility asks with `t_max` infinite.
//!
//! **Floating point.** The one device of the process is created on a thread of its own that
//! ends at once, so that whatever Embree sets in that thread's floating-point state
//! (flush-to-zero and denormals-are-zero are its recommendation) never reaches the caller's;
//! queries leave the caller's state alone.

use std::ffi::{CStr, c_char, c_int, c_uint, c_void};
use std::sync::OnceLock;

use libloading::Library;

/// The rays of one `rtcOccluded16` or `rtcIntersect16` packet.
pub(crate) const EMBREE_LANES: usize = 16;

/// The environment variable naming the Embree 3 library to load instead of
/// `libembree3.so.3` (a path, or a name for the dynamic loader to search).
pub const EMBREE_LIBRARY_VAR: &str = "HAARSHIFT_EMBREE";

/// The library loaded when [`EMBREE_LIBRARY_VAR`] is not set.
const DEFAULT_LIBRARY: &str = "libembree3.so.3";

/// Where to get it, for the messages.
const INSTALL: &str = "install libembree3-3 on Debian and Ubuntu (apt-get install libembree3-3)";

type Handle = *mut c_void;

/// `RTC_GEOMETRY_TYPE_TRIANGLE`, `RTC_BUFFER_TYPE_INDEX`/`_VERTEX`, `RTC_FORMAT_UINT3`/`FLOAT3`,
/// `RTC_SCENE_FLAG_ROBUST`, `RTC_BUILD_QUALITY_HIGH`, `RTC_INTERSECT_CONTEXT_FLAG_COHERENT`,
/// `RTC_DEVICE_PROPERTY_VERSION`, `RTC_ERROR_NONE`, `RTC_INVALID_GEOMETRY_ID`: Embree 3's
/// headers (`rtcore_*.h`).
const GEOMETRY_TRIANGLE: c_uint = 0;
const BUFFER_INDEX: c_uint = 0;
const BUFFER_VERTEX: c_uint = 1;
const FORMAT_UINT3: c_uint = 0x5003;
const FORMAT_FLOAT3: c_uint = 0x9003;
const SCENE_ROBUST: c_uint = 1 << 2;
const BUILD_HIGH: c_uint = 2;
const CONTEXT_COHERENT: c_uint = 1;
const PROPERTY_VERSION: c_uint = 0;
const ERROR_NONE: c_uint = 0;
const INVALID_ID: u32 = u32::MAX;

/// The device's configuration: the `embree3` crate's defaults, which the linked build this
/// replaced passed (`max_isa=avx512` and huge pages included), so that the BVHs, and so the
/// answers, are the same.
const CONFIG: &CStr = c"threads=0,verbose=0,set_affinity=0,start_threads=0,max_isa=avx512,\
hugepages=1,enable_selockmemoryprivilege=0,";

/// `struct RTCIntersectContext` of Embree 3 with one instance level and no minimum width.
#[repr(C)]
pub(crate) struct IntersectContext {
    flags: c_uint,
    filter: Option<unsafe extern "C" fn(*const c_void)>,
    inst_id: [c_uint; 1],
}

impl IntersectContext {
    /// What `rtcInitIntersectContext` (inline in `rtcore_common.h`) writes, with the coherent
    /// flag: a vertex's rays share their origin.
    fn coherent() -> Self {
        IntersectContext {
            flags: CONTEXT_COHERENT,
            filter: None,
            inst_id: [INVALID_ID],
        }
    }
}

/// `struct RTCRay` (aligned to 16 bytes).
#[repr(C, align(16))]
struct Ray1 {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: c_uint,
    id: c_uint,
    flags: c_uint,
}

/// `struct RTCRay16` (aligned to 64 bytes), structure of arrays.
#[repr(C, align(64))]
struct Ray16 {
    org: [[f32; EMBREE_LANES]; 3],
    tnear: [f32; EMBREE_LANES],
    dir: [[f32; EMBREE_LANES]; 3],
    time: [f32; EMBREE_LANES],
    tfar: [f32; EMBREE_LANES],
    mask: [c_uint; EMBREE_LANES],
    id: [c_uint; EMBREE_LANES],
    flags: [c_uint; EMBREE_LANES],
}

/// `struct RTCHit16` with one instance level.
#[repr(C, align(64))]
struct Hit16 {
    ng: [[f32; EMBREE_LANES]; 3],
    u: [f32; EMBREE_LANES],
    v: [f32; EMBREE_LANES],
    prim_id: [c_uint; EMBREE_LANES],
    geom_id: [c_uint; EMBREE_LANES],
    inst_id: [[c_uint; EMBREE_LANES]; 1],
}

/// `struct RTCRayHit16`.
#[repr(C, align(64))]
struct RayHit16 {
    ray: Ray16,
    hit: Hit16,
}

/// A 16-lane valid mask, `-1` active and `0` inactive, aligned like the packet as the queries
/// ask.
#[repr(C, align(64))]
struct Valid16([c_int; EMBREE_LANES]);

impl Ray16 {
    /// The segments `origin + t directions[i]`, `0 <= t <= t_max`, in lanes `0..n`, and the
    /// mask of those lanes; the rest are inactive.
    fn segments(origin: [f32; 3], directions: &[[f32; 3]], t_max: f32) -> (Self, Valid16) {
        let mut valid = Valid16([0; EMBREE_LANES]);
        let mut dir = [[0.0; EMBREE_LANES]; 3];
        for (lane, d) in directions.iter().enumerate().take(EMBREE_LANES) {
            valid.0[lane] = -1;
            for k in 0..3 {
                dir[k][lane] = d[k];
            }
        }
        let ray = Ray16 {
            org: origin.map(|x| [x; EMBREE_LANES]),
            tnear: [0.0; EMBREE_LANES],
            dir,
            time: [0.0; EMBREE_LANES],
            tfar: [t_max; EMBREE_LANES],
            mask: [u32::MAX; EMBREE_LANES],
            id: [0; EMBREE_LANES],
            flags: [0; EMBREE_LANES],
        };
        (ray, valid)
    }
}

/// The entry points used, resolved once from the loaded library.
struct Api {
    new_device: unsafe extern "C" fn(*const c_char) -> Handle,
    get_device_error: unsafe extern "C" fn(Handle) -> c_uint,
    get_device_property: unsafe extern "C" fn(Handle, c_uint) -> isize,
    release_device: unsafe extern "C" fn(Handle),
    new_geometry: unsafe extern "C" fn(Handle, c_uint) -> Handle,
    set_new_geometry_buffer:
        unsafe extern "C" fn(Handle, c_uint, c_uint, c_uint, usize, usize) -> *mut c_void,
    commit_geometry: unsafe extern "C" fn(Handle),
    release_geometry: unsafe extern "C" fn(Handle),
    new_scene: unsafe extern "C" fn(Handle) -> Handle,
    set_scene_flags: unsafe extern "C" fn(Handle, c_uint),
    set_scene_build_quality: unsafe extern "C" fn(Handle, c_uint),
    attach_geometry: unsafe extern "C" fn(Handle, Handle) -> c_uint,
    commit_scene: unsafe extern "C" fn(Handle),
    release_scene: unsafe extern "C" fn(Handle),
    occluded1: unsafe extern "C" fn(Handle, *mut IntersectContext, *mut Ray1),
    occluded16: unsafe extern "C" fn(*const c_int, Handle, *mut IntersectContext, *mut Ray16),
    intersect16: unsafe extern "C" fn(*const c_int, Handle, *mut IntersectContext, *mut RayHit16),
}

impl Api {
    /// Resolves every entry point of `library`.
    fn resolve(library: &Library) -> Result<Api, libloading::Error> {
        // SAFETY: each symbol is Embree 3's exported C function of that name, and the type it
        // is read as is the function's prototype in Embree 3's headers (`rtcore_device.h`,
        // `rtcore_geometry.h`, `rtcore_scene.h`), with enums as `unsigned int`, `ssize_t` as
        // `isize` and the structures above for its structures. The pointers are used only
        // while `library` stays loaded: it is kept in the process's one `Embree`, never
        // unloaded.
        unsafe {
            Ok(Api {
                new_device: *library.get(b"rtcNewDevice\0")?,
                get_device_error: *library.get(b"rtcGetDeviceError\0")?,
                get_device_property: *library.get(b"rtcGetDeviceProperty\0")?,
                release_device: *library.get(b"rtcReleaseDevice\0")?,
                new_geometry: *library.get(b"rtcNewGeometry\0")?,
                set_new_geometry_buffer: *library.get(b"rtcSetNewGeometryBuffer\0")?,
                commit_geometry: *library.get(b"rtcCommitGeometry\0")?,
                release_geometry: *library.get(b"rtcReleaseGeometry\0")?,
                new_scene: *library.get(b"rtcNewScene\0")?,
                set_scene_flags: *library.get(b"rtcSetSceneFlags\0")?,
                set_scene_build_quality: *library.get(b"rtcSetSceneBuildQuality\0")?,
                attach_geometry: *library.get(b"rtcAttachGeometry\0")?,
                commit_scene: *library.get(b"rtcCommitScene\0")?,
                release_scene: *library.get(b"rtcReleaseScene\0")?,
                occluded1: *library.get(b"rtcOccluded1\0")?,
                occluded16: *library.get(b"rtcOccluded16\0")?,
                intersect16: *library.get(b"rtcIntersect16\0")?,
            })
        }
    }
}

/// The loaded library, its entry points and the process's device.
struct Embree {
    api: Api,
    device: Handle,
    /// Keeps the entry points valid; never dropped (the process's one `Embree` is static).
    _library: Library,
}

// SAFETY: an Embree device is thread safe (Embree 3's API documentation, "Thread Safety":
// its functions may be called from any thread, and queries on a committed scene from many at
// once); `Api` is plain function pointers and `Library` is Send + Sync.
unsafe impl Send for Embree {}
// SAFETY: as for Send.
unsafe impl Sync for Embree {}

/// The process's Embree, loaded on first use, or why it is not available.
fn embree() -> Result<&'static Embree, &'static str> {
    static EMBREE: OnceLock<Result<Embree, String>> = OnceLock::new();
    EMBREE.get_or_init(load).as_ref().map_err(String::as_str)
}

/// Loads the library, resolves its entry points and starts a device on a thread of its own.
fn load() -> Result<Embree, String> {
    let name = std::env::var_os(EMBREE_LIBRARY_VAR);
    let shown = name.as_ref().map_or_else(
        || DEFAULT_LIBRARY.to_string(),
        |n| format!("{} (${EMBREE_LIBRARY_VAR})", n.to_string_lossy()),
    );
    // SAFETY: loading Embree runs its initialisers, which only set up its own state (no
    // global the process relies on is changed); a library named otherwise must be an Embree
    // 3 build, as EMBREE_LIBRARY_VAR's documentation says.
    let library = unsafe { Library::new(name.as_deref().unwrap_or(DEFAULT_LIBRARY.as_ref())) }
        .map_err(|e| format!("{shown} could not be loaded ({}): {INSTALL}", cause(&e)))?;
    let api =
        Api::resolve(&library).map_err(|e| format!("{shown} is not Embree 3 ({e}): {INSTALL}"))?;
    let new_device = api.new_device;
    // The device is made on a thread that ends at once (see the module docs); the handle is
    // passed back as an address, a pointer not being Send.
    let device = std::thread::spawn(move || {
        // SAFETY: CONFIG is a NUL-terminated configuration string Embree 3 accepts.
        unsafe { new_device(CONFIG.as_ptr()) as usize }
    })
    .join()
    .map_err(|_| format!("{shown}: creating the Embree device panicked"))?
        as Handle;
    if device.is_null() {
        // SAFETY: rtcGetDeviceError takes a null device for the error of a failed creation.
        let code = unsafe { (api.get_device_error)(std::ptr::null_mut()) };
        return Err(format!(
            "{shown}: the Embree device did not start (error {code})"
        ));
    }
    // SAFETY: device is a live device of this library.
    let version = unsafe { (api.get_device_property)(device, PROPERTY_VERSION) };
    if !(30000..40000).contains(&version) {
        // SAFETY: device is live and released once.
        unsafe { (api.release_device)(device) };
        return Err(format!(
            "{shown} reports Embree version {version}, not 3: {INSTALL}"
        ));
    }
    Ok(Embree {
        api,
        device,
        _library: library,
    })
}

/// The loader's own words for `e` (libloading's message wraps them as its source).
fn cause(e: &libloading::Error) -> String {
    std::error::Error::source(e).map_or_else(|| e.to_string(), |s| s.to_string())
}

/// Why Embree cannot trace on this machine (it did not load, or its device did not start),
/// or `None` when it can.
pub(crate) fn unavailable() -> Option<&'static str> {
    embree().err()
}

/// The Embree version string of the loaded library (`3.13.5`), when it loaded.
pub(crate) fn version() -> Option<String> {
    let embree = embree().ok()?;
    // SAFETY: the device is live for the process's life.
    let v = unsafe { (embree.api.get_device_property)(embree.device, PROPERTY_VERSION) };
    Some(format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100))
}

/// A closest hit: the Embree triangle (its index in the soup given to [`EmbreeScene::new`]),
/// the distance and the barycentric weights of its second and third corners.
pub(crate) type RawHit = (u32, f32, f32, f32);

/// A committed Embree scene of a triangle soup; see the [module docs](self).
pub(crate) struct EmbreeScene {
    embree: &'static Embree,
    scene: Handle,
}

// SAFETY: a committed scene may be queried from any number of threads at once (Embree 3's API
// documentation); it is released once, in Drop.
unsafe impl Send for EmbreeScene {}
// SAFETY: as for Send.
unsafe impl Sync for EmbreeScene {}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: the scene is live and this is its one release; no query runs (we own it).
        unsafe { (self.embree.api.release_scene)(self.scene) };
    }
}

impl EmbreeScene {
    /// Builds the scene of `triangles` (not empty), or `None` when Embree is not available or
    /// reports an error (out of memory, say): the caller then traces with its own BVH.
    pub(crate) fn new(triangles: &[[[f32; 3]; 3]]) -> Option<Self> {
        let embree = embree().ok()?;
        let api = &embree.api;
        // Three corners a triangle, each its own vertex: every index must fit a u32.
        let vertices = triangles.len().checked_mul(3)?;
        let corners = u32::try_from(vertices).ok()?;
        // SAFETY: every handle passed is live (the device for the process; the geometry and
        // scene from their creation to their release below or in Drop). The buffers Embree
        // allocates are written within the item counts and strides given (12 bytes an item,
        // `vertices` and `triangles.len()` items; Embree pads the vertex buffer for its SIMD
        // loads itself) before the geometry is committed. A null result is checked before use.
        unsafe {
            let geometry = (api.new_geometry)(embree.device, GEOMETRY_TRIANGLE);
            if geometry.is_null() {
                return None;
            }
            let vertex = (api.set_new_geometry_buffer)(
                geometry,
                BUFFER_VERTEX,
                0,
                FORMAT_FLOAT3,
                12,
                vertices,
            ) as *mut [f32; 3];
            let index = (api.set_new_geometry_buffer)(
                geometry,
                BUFFER_INDEX,
                0,
                FORMAT_UINT3,
                12,
                triangles.len(),
            ) as *mut [u32; 3];
            if vertex.is_null() || index.is_null() {
                (api.release_geometry)(geometry);
                return None;
            }
            std::slice::from_raw_parts_mut(vertex, vertices)
                .copy_from_slice(triangles.as_flattened());
            let index = std::slice::from_raw_parts_mut(index, triangles.len());
            for (triangle, first) in index.iter_mut().zip((0..corners).step_by(3)) {
                *triangle = [first, first + 1, first + 2];
            }
            (api.commit_geometry)(geometry);
            let scene = (api.new_scene)(embree.device);
            if scene.is_null() {
                (api.release_geometry)(geometry);
                return None;
            }
            (api.set_scene_flags)(scene, SCENE_ROBUST);
            (api.set_scene_build_quality)(scene, BUILD_HIGH);
            (api.attach_geometry)(scene, geometry);
            // The scene holds its own reference to the geometry.
            (api.release_geometry)(geometry);
            (api.commit_scene)(scene);
            let built = EmbreeScene { embree, scene };
            ((api.get_device_error)(embree.device) == ERROR_NONE).then_some(built)
        }
    }

    /// Whether the ray `origin + t direction`, `0 <= t <= t_max`, hits a triangle.
    pub(crate) fn occluded(&self, origin: [f32; 3], direction: [f32; 3], t_max: f32) -> bool {
        let mut ray = Ray1 {
            org: origin,
            tnear: 0.0,
            dir: direction,
            time: 0.0,
            tfar: t_max,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        };
        let mut context = IntersectContext::coherent();
        // SAFETY: the scene is committed and live; context and ray are valid, aligned
        // structures of Embree 3's layout that outlive the call.
        unsafe { (self.embree.api.occluded1)(self.scene, &mut context, &mut ray) };
        // Embree marks a blocked ray by setting its far distance to minus infinity.
        ray.tfar == f32::NEG_INFINITY
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
        let (mut rays, valid) = Ray16::segments(origin, directions, t_max);
        let mut context = IntersectContext::coherent();
        // SAFETY: as in `occluded`; valid and rays are 64-byte aligned, as rtcOccluded16 asks.
        unsafe {
            (self.embree.api.occluded16)(valid.0.as_ptr(), self.scene, &mut context, &mut rays)
        };
        for (b, &far) in blocked.iter_mut().zip(&rays.tfar) {
            *b = far == f32::NEG_INFINITY;
        }
    }

    /// The closest hit of each ray `origin + t directions[i]`, `0 <= t <= t_max`, at most
    /// [`EMBREE_LANES`] of them, traced as one packet (`rtcIntersect16`).
    pub(crate) fn closest_packet(
        &self,
        origin: [f32; 3],
        directions: &[[f32; 3]],
        t_max: f32,
        hits: &mut [Option<RawHit>],
    ) {
        debug_assert!(directions.len() <= EMBREE_LANES && hits.len() == directions.len());
        let (ray, valid) = Ray16::segments(origin, directions, t_max);
        let mut rayhit = RayHit16 {
            ray,
            // Embree asks for geomID and instID set to RTC_INVALID_GEOMETRY_ID on entry.
            hit: Hit16 {
                ng: [[0.0; EMBREE_LANES]; 3],
                u: [0.0; EMBREE_LANES],
                v: [0.0; EMBREE_LANES],
                prim_id: [INVALID_ID; EMBREE_LANES],
                geom_id: [INVALID_ID; EMBREE_LANES],
                inst_id: [[INVALID_ID; EMBREE_LANES]],
            },
        };
        let mut context = IntersectContext::coherent();
        // SAFETY: as in `occluded_packet`; rtcIntersect16 writes only the structure given.
        unsafe {
            (self.embree.api.intersect16)(valid.0.as_ptr(), self.scene, &mut context, &mut rayhit)
        };
        let hit = &rayhit.hit;
        for (lane, h) in hits.iter_mut().enumerate() {
            *h = (hit.geom_id[lane] != INVALID_ID).then(|| {
                let t = rayhit.ray.tfar[lane];
                (hit.prim_id[lane], t, hit.u[lane], hit.v[lane])
            });
        }
    }
}
