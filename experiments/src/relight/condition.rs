//! The experimental condition of a group of records: which lighting, turned how, on which
//! material, seen by which camera.

use super::Light;
use crate::Result;
use haarshift::sphere::SphereRotation;
use haarshift_relight::Brdf;
use haarshift_relight::shade::FrameSpec;

/// The lighting, its rotation, the material and the camera of a group of records.
pub(super) struct Condition<'a> {
    pub(super) light: &'a Light,
    /// Yaw, pitch and roll of the lighting, degrees.
    pub(super) angles: [f64; 3],
    pub(super) rotation: SphereRotation,
    pub(super) brdf: &'a Brdf,
    /// 0: the scene's camera; 1: the one orbited by [`SECOND_CAMERA`](super::SECOND_CAMERA).
    pub(super) camera: usize,
}

impl<'a> Condition<'a> {
    pub(super) fn new(
        light: &'a Light,
        angles: [f64; 3],
        brdf: &'a Brdf,
        camera: usize,
    ) -> Result<Self> {
        Ok(Condition {
            light,
            angles,
            rotation: SphereRotation::from_degrees(angles[0], angles[1], angles[2])?,
            brdf,
            camera,
        })
    }

    /// The frame of this condition seen from `eye`.
    pub(super) fn frame(&self, eye: [f64; 3]) -> FrameSpec<'_> {
        FrameSpec {
            environment: &self.light.environment,
            rotation: self.rotation,
            eye: Some(eye),
        }
    }
}
