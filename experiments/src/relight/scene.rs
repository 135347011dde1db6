//! One scene of the relighting experiment as the axes measure it: its ray-cast truth and its
//! renders, its two cameras, its transports by parameterisation (each precomputed once), and
//! the one way every axis relights it (a [`ShaderSpec`] built and shaded) and records the
//! result against the truth.

use std::collections::HashMap;
use std::time::Instant;

use ndarray::Array2;

use super::condition::Condition;
use super::picture::draw;
use super::{RelightProtocol, RelightRecord, SECOND_CAMERA, Subject};
use crate::Result;
use haarshift::PlanarImage;
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::metrics::RelativeError;
use haarshift::product::Selection;
use haarshift_relight::render::view::ViewSpec;
use haarshift_relight::render::{Background, Camera};
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::reference::ReferenceVisibility;
use haarshift_relight::shade::{ShaderSpec, ShadingInput};
use haarshift_relight::{
    ReferenceOptions, SceneBvh, ShadeOptions, TransportSet, VisibilityOptions, vertex_major,
};

/// A transport precomputed at one parameterisation, with what it cost.
pub(super) struct TimedTransport {
    pub(super) set: TransportSet,
    pub(super) seconds: f64,
}

/// What a method produced for one condition, and what it says of itself for the record.
pub(super) struct Relit {
    pub(super) radiance: Array2<f64>,
    pub(super) precompute_seconds: f64,
    pub(super) relight_seconds: f64,
    /// [`ShaderSpec::label`].
    pub(super) method: String,
    /// Coefficients of the lighting used ([`Shading::light_coefficients`](haarshift_relight::shade::Shading::light_coefficients)).
    pub(super) light_coefficients: usize,
    /// Coefficients kept of each rotated BRDF map, scaling coefficients included (`None`:
    /// all, or no BRDF map).
    pub(super) brdf_coefficients: Option<usize>,
}

/// One scene's working state: its ray-cast truth, cameras, and transports by parameterisation.
pub(super) struct SceneUnderTest<'a> {
    pub(super) subject: &'a Subject,
    pub(super) protocol: &'a RelightProtocol,
    pub(super) bvh: SceneBvh,
    pub(super) cameras: [Camera; 2],
    pub(super) truth_bits: ReferenceVisibility,
    truths: HashMap<String, Array2<f64>>,
    truth_renders: HashMap<String, PlanarImage<f32>>,
    transports: HashMap<(ParamKind, usize, bool), TimedTransport>,
}

impl<'a> SceneUnderTest<'a> {
    pub(super) fn new(subject: &'a Subject, protocol: &'a RelightProtocol) -> Result<Self> {
        let scene = &subject.scene;
        let bvh = SceneBvh::new(&scene.mesh);
        let first = ViewSpec::default().camera(scene.camera.as_ref(), &scene.mesh)?;
        let cameras = [first, first.orbited(SECOND_CAMERA)?];
        let truth_bits =
            ReferenceVisibility::new(&scene.mesh, &bvh, protocol.truth_resolution, true)?;
        Ok(SceneUnderTest {
            subject,
            protocol,
            bvh,
            cameras,
            truth_bits,
            truths: HashMap::new(),
            truth_renders: HashMap::new(),
            transports: HashMap::new(),
        })
    }

    pub(super) fn eye(&self, condition: &Condition<'_>) -> [f64; 3] {
        self.cameras[condition.camera].position()
    }

    /// The ground truth of `condition` (cached, and shared by the cameras when the material
    /// does not depend on the eye).
    pub(super) fn truth(&mut self, condition: &Condition<'_>) -> Result<Array2<f64>> {
        let camera = if condition.brdf.is_view_dependent() {
            condition.camera
        } else {
            0
        };
        let key = format!(
            "{}/{:?}/{}/{camera}",
            condition.light.name, condition.angles, condition.brdf
        );
        if let Some(t) = self.truths.get(&key) {
            return Ok(t.clone());
        }
        let scene = &self.subject.scene;
        let lighting = condition
            .light
            .environment
            .lat_long(self.protocol.truth_resolution, &condition.rotation)?;
        let options = ReferenceOptions {
            progress: false,
            brdf: condition.brdf.clone(),
            eye: Some(self.cameras[camera].position()),
            object_vertices: Some(scene.object_vertices()),
        };
        let (truth, _) =
            self.truth_bits
                .reference(&scene.mesh, scene.albedo.view(), &lighting, &options)?;
        self.truths.insert(key, truth.clone());
        Ok(truth)
    }

    /// The transport at `kind` `n` (with `sh` bands of spherical harmonics beside it when
    /// asked), precomputed once.
    fn transport(&mut self, kind: ParamKind, n: usize, sh: bool) -> Result<&TimedTransport> {
        let key = (kind, n, sh);
        if !self.transports.contains_key(&key) {
            let param = Parameterization::new(kind, n)?;
            let mut options = VisibilityOptions::new(param);
            options.sh_bands = sh
                .then(|| self.protocol.sh_bands.iter().copied().max())
                .flatten();
            let start = Instant::now();
            let (set, _) = vertex_major(&self.subject.scene.mesh, &self.bvh, &options)?;
            let seconds = start.elapsed().as_secs_f64();
            self.transports.insert(key, TimedTransport { set, seconds });
        }
        Ok(&self.transports[&key])
    }

    /// `condition` relit by `spec` from the transport at `kind` `n` (with `sh` bands of
    /// spherical harmonics when asked): every method goes through here.
    pub(super) fn relight(
        &mut self,
        condition: &Condition<'_>,
        (kind, n, sh): (ParamKind, usize, bool),
        spec: &ShaderSpec,
    ) -> Result<Relit> {
        let eye = self.eye(condition);
        let subject: &'a Subject = self.subject;
        let scene = &subject.scene;
        let precomputed = self.transport(kind, n, sh)?;
        let input = ShadingInput::new(
            &scene.mesh,
            scene.albedo.view(),
            Some(&precomputed.set),
            scene.object_vertices(),
        );
        let mut shader = spec.build(&input)?;
        let shading = shader.shade(&condition.frame(eye))?;
        let faces = precomputed.set.param().faces();
        Ok(Relit {
            radiance: shading.radiance.to_f64(),
            precompute_seconds: precomputed.seconds + shader.preparation().seconds,
            relight_seconds: shading.timing.total_seconds(),
            method: spec.label(),
            light_coefficients: shading.light_coefficients.unwrap_or(0),
            brdf_coefficients: spec.material.keep_brdf.map(|k| k + faces),
        })
    }

    /// Haar relighting of `condition` at `kind` `n`: the lighting kept by `light`, the
    /// shading options `shade`, and for a glossy material the BRDF brought into each frame by
    /// `glossy`.
    pub(super) fn haar(
        &mut self,
        condition: &Condition<'_>,
        (kind, n): (ParamKind, usize),
        light: Selection,
        shade: &ShadeOptions,
        glossy: &GlossyOptions,
    ) -> Result<Relit> {
        let spec = ShaderSpec {
            material: glossy.for_brdf(condition.brdf),
            shade: *shade,
            keep_light: light,
            ..ShaderSpec::default()
        };
        self.relight(condition, (kind, n, false), &spec)
    }

    /// A record of `relit` against the truth of `condition`, with the render's image error.
    pub(super) fn record(
        &mut self,
        axis: &str,
        condition: &Condition<'_>,
        relit: &Relit,
        param: Parameterization,
    ) -> Result<RelightRecord> {
        let truth = self.truth(condition)?;
        let error = RelativeError::between(relit.radiance.view(), truth.view())?;
        let camera = &self.cameras[condition.camera];
        let (w, h) = self.protocol.image;
        let black = Background::Colour([0.0; 3]);
        let got = draw(&self.subject.scene, camera, (w, h), &relit.radiance, black)?;
        // The truth's render, once per condition and camera.
        let key = format!(
            "{}/{:?}/{}/{}",
            condition.light.name, condition.angles, condition.brdf, condition.camera
        );
        if !self.truth_renders.contains_key(&key) {
            let image = draw(&self.subject.scene, camera, (w, h), &truth, black)?;
            self.truth_renders.insert(key.clone(), image);
        }
        let want = &self.truth_renders[&key];
        let image_rms = RelativeError::between(
            got.planes()
                .view()
                .into_shape_with_order((3 * h, w))
                .expect("contiguous"),
            want.planes()
                .view()
                .into_shape_with_order((3 * h, w))
                .expect("contiguous"),
        )?
        .rms_relative;
        Ok(RelightRecord {
            axis: axis.into(),
            scene: self.subject.name.clone(),
            vertices: self.subject.scene.mesh.vertex_count(),
            envmap: condition.light.name.clone(),
            light_rotation: format!(
                "{}/{}/{}",
                condition.angles[0], condition.angles[1], condition.angles[2]
            ),
            material: condition.brdf.to_string(),
            camera: condition.camera,
            method: relit.method.clone(),
            parameters: String::new(),
            param: param.kind().to_string(),
            resolution: param.face_size(),
            level: None,
            kept_ratio: None,
            light_coefficients: relit.light_coefficients,
            brdf_coefficients: relit.brdf_coefficients,
            depth: param.face_size().trailing_zeros() as usize,
            sh_bands: None,
            rms_relative: error.rms_relative,
            max_relative: error.max_relative,
            rms: error.rms,
            max: error.max,
            image_rms,
            spatial_difference: None,
            precompute_seconds: relit.precompute_seconds,
            relight_seconds: relit.relight_seconds,
            peak_mib: haarshift::memory::peak_resident_bytes().unwrap_or(0) as f64
                / (1u64 << 20) as f64,
        })
    }
}
