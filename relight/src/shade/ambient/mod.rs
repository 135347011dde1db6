//! Ambient occlusion: `R_v = albedo_v / pi x <T_v, 1>`, the integral of the vertex's transport
//! (visibility x cosine x solid angle), which is what a Lambertian vertex reflects under a
//! white sky of radiance 1. It does not depend on the lighting: a frame's environment and
//! rotation are ignored.
//!
//! It is the Lambertian Haar shading ([`PreparedTransport`]) under the constant lighting 1,
//! encoded once: `<T_v, 1>` is the dot product of the transport's coefficients with those of
//! the constant (each face's scaling coefficient alone). Added as the example of a new
//! [`Shader`]: one file and one [`Method`](super::Method), no caller changed.

use std::time::Instant;

use ndarray::Array2;

use super::{
    FrameSpec, Preparation, PreparedTransport, Radiance, Shader, ShaderSpec, Shading, ShadingInput,
    Timing, seconds,
};
use crate::Lighting;
use crate::{Error, Result};
use haarshift::faces::param::SphereMap;
use haarshift::product::Selection;

/// Ambient occlusion behind [`Shader`]; see the [module docs](self).
#[derive(Debug)]
pub struct AmbientShader {
    prepared: PreparedTransport<f32>,
    white: Lighting,
    prepare_seconds: f64,
}

impl AmbientShader {
    /// `input`'s transport prepared with its albedo and `spec`'s truncation, and the white
    /// sky in its parameterisation. The material must be Lambertian.
    pub(crate) fn new(spec: &ShaderSpec, input: &ShadingInput<'_>) -> Result<Self> {
        let start = Instant::now();
        if !spec.material.brdf.is_lambert() {
            return Err(Error::parameter(
                "basis",
                format!(
                    "ambient occlusion is Lambertian, not {}; use --brdf lambert",
                    spec.material.brdf
                ),
            ));
        }
        let set = input.transport(spec.method)?;
        let prepared = PreparedTransport::new(set, input.albedo, &spec.shade)?;
        let one = SphereMap::<f64>::from_fn(set.param(), 1, |_, out| out[0] = 1.0)?;
        Ok(AmbientShader {
            prepared,
            white: Lighting::from_map(&one, Selection::All)?,
            prepare_seconds: seconds(start),
        })
    }
}

impl Shader for AmbientShader {
    fn shade(&mut self, _: &FrameSpec<'_>) -> Result<Shading> {
        let start = Instant::now();
        let radiance: Array2<f32> = self.prepared.shade(&self.white)?;
        Ok(Shading {
            radiance: Radiance::F32(radiance),
            timing: Timing::unrotated(0.0, seconds(start)),
            description: format!(
                "ambient occlusion, albedo / pi x the transport's integral, transport {} \
                 coefficients; transport prepared once in {:.1} ms",
                self.prepared.coefficient_count(),
                self.prepare_seconds * 1e3
            ),
            maps: None,
            light_coefficients: Some(self.white.param().faces()),
        })
    }

    fn preparation(&self) -> Preparation {
        Preparation {
            seconds: self.prepare_seconds,
            filled: None,
        }
    }
}

#[cfg(test)]
mod tests;
