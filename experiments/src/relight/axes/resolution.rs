//! Vollick and Lessig's tables: map resolution times kept ratio, with the time of each stage,
//! and the floor each lat-long resolution sets (its own quadrature).

use std::time::Instant;

use crate::Result;
use crate::relight::RelightRecord;
use crate::relight::condition::Condition;
use crate::relight::scene::{Relit, SceneUnderTest};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::material::orient::BrdfRotation;
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::reference::ReferenceVisibility;
use haarshift_relight::{ReferenceOptions, ShadeOptions};

impl SceneUnderTest<'_> {
    /// Vollick and Lessig's tables: map resolution times kept ratio, time per stage.
    pub(in crate::relight) fn resolution_axis(
        &mut self,
        condition: &Condition<'_>,
    ) -> Result<Vec<RelightRecord>> {
        let sizes: Vec<(ParamKind, usize)> = (self.protocol.latlong_resolutions.iter())
            .map(|&n| (ParamKind::LatLong, n))
            .chain(
                self.protocol
                    .cube_resolutions
                    .iter()
                    .map(|&n| (ParamKind::Cube, n)),
            )
            .collect();
        let mut out = Vec::new();
        for (kind, n) in sizes {
            let param = Parameterization::new(kind, n)?;
            if kind == ParamKind::LatLong {
                out.push(self.quadrature_floor(condition, param)?);
            }
            // The thesis's rotation is lat-long only: cube maps take the exact lobe.
            let rotation = match kind {
                ParamKind::LatLong => BrdfRotation::Haar,
                ParamKind::Cube => BrdfRotation::Direct,
            };
            for &ratio in &self.protocol.ratios.clone() {
                let keep = kept_details(param, ratio);
                let select = keep.map_or(Selection::All, Selection::Largest);
                let shade = ShadeOptions {
                    keep_visibility: keep.map(Selection::Largest),
                    depth: None,
                };
                let glossy = GlossyOptions {
                    rotation,
                    keep_brdf: keep,
                    ..GlossyOptions::default()
                };
                let s = self.haar(condition, (kind, n), select, &shade, &glossy)?;
                let mut r = self.record("resolution", condition, &s, param)?;
                r.kept_ratio = Some(ratio);
                r.parameters = format!("ratio {ratio}");
                out.push(r);
            }
        }
        Ok(out)
    }

    /// The floor a resolution sets: the reference quadrature itself at lat-long `param`
    /// (rays cast at that resolution, no transform, no truncation). At the truth's
    /// resolution it is the truth.
    fn quadrature_floor(
        &mut self,
        condition: &Condition<'_>,
        param: Parameterization,
    ) -> Result<RelightRecord> {
        let scene = &self.subject.scene;
        let n = param.face_size();
        let start = Instant::now();
        let bits = ReferenceVisibility::new(&scene.mesh, &self.bvh, n, false)?;
        let precompute_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let lighting = condition
            .light
            .environment
            .lat_long(n, &condition.rotation)?;
        let options = ReferenceOptions {
            progress: false,
            brdf: condition.brdf.clone(),
            eye: Some(self.eye(condition)),
            object_vertices: Some(scene.object_vertices()),
        };
        let (radiance, _) =
            bits.reference(&scene.mesh, scene.albedo.view(), &lighting, &options)?;
        let shaded = Relit {
            radiance,
            precompute_seconds,
            relight_seconds: start.elapsed().as_secs_f64(),
            method: "reference".into(),
            light_coefficients: param.texels(),
            brdf_coefficients: None,
        };
        let mut r = self.record("resolution", condition, &shaded, param)?;
        r.parameters = "quadrature".into();
        Ok(r)
    }
}

/// The detail coefficients a kept ratio leaves of `param`'s (`None`: ratio 1, all).
fn kept_details(param: Parameterization, ratio: f64) -> Option<usize> {
    let details = param.texels() - param.faces();
    (ratio < 1.0).then(|| ((ratio * details as f64).round() as usize).clamp(1, details))
}
