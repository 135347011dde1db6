//! Where a dynamic object is ([`Placement`]): a uniform scale, a turn about the vertical by
//! whole lat-long columns, and a translation.

use std::sync::Arc;

use crate::Mesh;
use crate::SceneError;
use crate::dynamic::fields::OcclusionField;
use crate::scene::Transform;
use crate::{Error, Result};
use haarshift::faces::param::{ParamKind, Parameterization};
use haarshift::sphere::SphereRotation;

/// Where an object is: world `= Ry(turn) (scale x local) + translate`; see the
/// [module docs](super).
///
/// ```
/// use haarshift_relight::dynamic::Placement;
/// use haarshift_relight::Transform;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let param = Parameterization::new(ParamKind::LatLong, 32).unwrap(); // 64 columns
/// let t = Transform { yaw: 92.0, translate: [1.0, 0.0, 0.0], ..Transform::default() };
/// let p = Placement::from_transform(&t, param).unwrap();
/// assert_eq!(p.turn, 16); // 92 degrees is 16.4 columns of 5.625 degrees
/// let w = p.to_world([0.0, 0.0, 1.0], param);
/// assert!((w[0] - 2.0).abs() < 1e-12 && w[2].abs() < 1e-12); // +Z turned to +X, moved
/// assert!((p.to_local(w, param)[2] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Added last.
    pub translate: [f64; 3],
    /// Uniform scale, applied first (positive).
    pub scale: f64,
    /// Whole columns of the lat-long parameterisation turned about +Y.
    pub turn: usize,
}

impl Placement {
    /// The placement of a scene file's transform, its yaw rounded to whole columns.
    pub fn from_transform(t: &Transform, param: Parameterization) -> Result<Self> {
        if t.pitch != 0.0 || t.roll != 0.0 {
            return Err(SceneError::SceneFile(format!(
                "pitch {} and roll {}: a dynamic object turns about the vertical only (yaw)",
                t.pitch, t.roll
            ))
            .into());
        }
        if !(t.scale.is_finite() && t.scale > 0.0) || t.translate.iter().any(|x| !x.is_finite()) {
            return Err(SceneError::SceneFile(format!(
                "scale {} and translate {:?}: the scale must be positive and finite, the \
                 translation finite",
                t.scale, t.translate
            ))
            .into());
        }
        Ok(Placement {
            translate: t.translate,
            scale: t.scale,
            turn: turn_columns(t.yaw, param)?,
        })
    }

    /// The turn in degrees.
    pub fn yaw_degrees(&self, param: Parameterization) -> f64 {
        self.turn as f64 * 360.0 / columns(param) as f64
    }

    /// The turn as a rotation of the sphere.
    pub(crate) fn rotation(&self, param: Parameterization) -> SphereRotation {
        SphereRotation::from_degrees(self.yaw_degrees(param), 0.0, 0.0)
            .expect("a whole number of columns is a finite angle")
    }

    /// A point of the object's own frame in the world.
    pub fn to_world(&self, p: [f64; 3], param: Parameterization) -> [f64; 3] {
        let q = self.rotation(param).apply(p.map(|x| x * self.scale));
        std::array::from_fn(|k| q[k] + self.translate[k])
    }

    /// A world point in the object's own frame.
    pub fn to_local(&self, p: [f64; 3], param: Parameterization) -> [f64; 3] {
        let d = std::array::from_fn(|k| p[k] - self.translate[k]);
        self.rotation(param)
            .inverse()
            .apply(d)
            .map(|x| x / self.scale)
    }

    /// As a scene file's transform.
    pub fn transform(&self, param: Parameterization) -> Transform {
        Transform {
            translate: self.translate,
            scale: self.scale,
            yaw: self.yaw_degrees(param),
            ..Transform::default()
        }
    }
}

/// Columns of a lat-long map of `param`'s size (`2N`).
pub(crate) fn columns(param: Parameterization) -> usize {
    2 * param.face_size()
}

/// A yaw in degrees as whole columns, `0..2N`; a cube map takes no turn.
fn turn_columns(yaw: f64, param: Parameterization) -> Result<usize> {
    if !yaw.is_finite() || yaw.abs() > 1e6 {
        return Err(Error::parameter(
            "yaw",
            format!("{yaw} degrees is not a finite angle of at most 1e6 degrees"),
        ));
    }
    let w = columns(param) as f64;
    let k = (yaw / 360.0 * w).round().rem_euclid(w) as usize;
    if param.kind() == ParamKind::Cube && k != 0 {
        return Err(Error::parameter(
            "yaw",
            format!("{yaw} degrees: turning an object's occlusion field needs --param latlong"),
        ));
    }
    Ok(k)
}

pub(super) fn turned(field: &Arc<OcclusionField>, turn: usize) -> Result<Arc<OcclusionField>> {
    Ok(if turn == 0 {
        field.clone()
    } else {
        Arc::new(field.turned(turn)?)
    })
}

pub(super) fn place_mesh(mesh: &Mesh, p: &Placement, param: Parameterization) -> Result<Mesh> {
    let rot = p.rotation(param);
    mesh.mapped(|q| p.to_world(q, param), |n| rot.apply(n))
}
