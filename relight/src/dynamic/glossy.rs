//! Glossy materials in dynamic scenes: the BRDF rotated into a vertex's frame is one more
//! factor of its n-function product integral, `B_v = a_v x integral of T_v x L x prod O_k x
//! rho_v` (Sun 2006 eq. 3.1 with the BRDF kept), `rho_v(w) = rho(w, w_o)` with `w_o` the unit
//! direction from the vertex to the [eye](DynamicScene::eye). The lobe is the glossy module's
//! ([`Orientation::lobe`], by [`GlossyOptions::rotation`] in the vertex's exact frame), taken to
//! Haar coefficients as the lighting is ([`Lighting::from_map`]: `keep_brdf` keeps its largest
//! details, `brdf_levels` its coarse levels). A Lambertian vertex keeps `a_v / pi` outside the
//! integral.

use super::*;
use crate::material::brdf::MAX_EXPONENT;
use crate::material::orient::Frame;

/// Sparse RGB coefficients: ascending indices and their values.
type SparseRgb = (Vec<u32>, Vec<[f64; 3]>);

impl DynamicScene {
    /// Object `k`'s BRDF (its material's, or what [`set_brdf`](Self::set_brdf) gave it).
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::{Brdf, SceneFile};
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(r#"{"objects": [{"generator": {"sphere": {"cells": 2}},
    ///     "material": {"brdf": "phong", "exponent": 20, "albedo": [1, 1, 1]}}],
    ///     "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]}}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// (options.field.circles, options.field.circle_points) = (4, 8);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// assert_eq!(scene.brdf(0).unwrap(), &Brdf::Phong { exponent: 20.0 });
    /// assert!(scene.brdf(1).is_err());
    /// ```
    pub fn brdf(&self, k: usize) -> Result<&Brdf> {
        self.check_object(k)?;
        Ok(&self.objects[k].brdf)
    }

    /// Gives object `k` the BRDF `brdf` (its albedo stays). A [`JustInTimeTransfer`] formed before holds the
    /// old BRDF in its fixed products: re-form it.
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::{Brdf, SceneFile};
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(
    ///     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// (options.field.circles, options.field.circle_points) = (4, 8);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// scene.set_brdf(0, "blinn:30".parse().unwrap()).unwrap();
    /// assert_eq!(scene.brdf(0).unwrap().to_string(), "blinn:30");
    /// ```
    pub fn set_brdf(&mut self, k: usize, brdf: Brdf) -> Result<()> {
        self.check_object(k)?;
        let before = std::mem::replace(&mut self.objects[k].brdf, brdf);
        self.orient().inspect_err(|_| {
            self.objects[k].brdf = before;
        })
    }

    /// How glossy BRDFs are brought into vertex frames and truncated.
    ///
    /// ```
    /// # use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// # use haarshift_relight::SceneFile;
    /// # use haarshift::faces::{ParamKind, Parameterization};
    /// # let file: SceneFile = serde_json::from_str(
    /// #     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// # let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// # (options.field.circles, options.field.circle_points) = (4, 8);
    /// # (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// assert_eq!(scene.glossy(), &haarshift_relight::shade::glossy::GlossyOptions::default());
    /// ```
    pub fn glossy(&self) -> &GlossyOptions {
        &self.glossy
    }

    /// Sets how glossy BRDFs are brought into vertex frames and truncated: `rotation`, `level`,
    /// `elevations`, `keep_brdf` and `brdf_levels` as [`GlossyShader`](crate::shade::glossy::GlossyShader)
    /// reads them. Its `brdf` is not read (each object has its own, [`set_brdf`](Self::set_brdf)),
    /// and a rotation cache is refused: every vertex's lobe is rotated in its exact frame.
    ///
    /// ```
    /// use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// use haarshift_relight::shade::glossy::GlossyOptions;
    /// use haarshift_relight::material::orient::BrdfRotation;
    /// use haarshift_relight::SceneFile;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(
    ///     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// (options.field.circles, options.field.circle_points) = (4, 8);
    /// (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// let direct = GlossyOptions { rotation: BrdfRotation::Direct, ..GlossyOptions::default() };
    /// scene.set_glossy(&direct).unwrap();
    /// assert_eq!(scene.glossy().rotation, BrdfRotation::Direct);
    /// let cached = GlossyOptions { cache_bins: Some(8), ..GlossyOptions::default() };
    /// assert!(scene.set_glossy(&cached).is_err());
    /// ```
    pub fn set_glossy(&mut self, options: &GlossyOptions) -> Result<()> {
        let before = std::mem::replace(&mut self.glossy, options.clone());
        self.orient().inspect_err(|_| {
            self.glossy = before;
        })
    }

    /// Where glossy vertices are seen from: the scene file's camera position unless
    /// [`set_eye`](Self::set_eye) moved it.
    ///
    /// ```
    /// # use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// # use haarshift_relight::SceneFile;
    /// # use haarshift::faces::{ParamKind, Parameterization};
    /// let file: SceneFile = serde_json::from_str(r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}],
    ///     "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]}}"#).unwrap();
    /// # let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// # (options.field.circles, options.field.circle_points) = (4, 8);
    /// # (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// assert_eq!(scene.eye(), Some([0.0, 1.0, 5.0]));
    /// scene.set_eye([4.0, 1.0, 0.0]).unwrap();
    /// assert_eq!(scene.eye(), Some([4.0, 1.0, 0.0]));
    /// assert!(scene.set_eye([f64::NAN, 0.0, 0.0]).is_err());
    /// ```
    pub fn eye(&self) -> Option<[f64; 3]> {
        self.eye
    }

    /// Moves the eye glossy vertices are seen from (the camera of a [`Change::View`]).
    ///
    /// ```
    /// # use haarshift_relight::dynamic::{DynamicOptions, DynamicScene};
    /// # use haarshift_relight::SceneFile;
    /// # use haarshift::faces::{ParamKind, Parameterization};
    /// # let file: SceneFile = serde_json::from_str(
    /// #     r#"{"objects": [{"generator": {"sphere": {"cells": 2}}}]}"#).unwrap();
    /// # let mut options = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 8).unwrap());
    /// # (options.field.circles, options.field.circle_points) = (4, 8);
    /// # (options.field.shells, options.field.shell_grid) = (2, 2);
    /// let mut scene = DynamicScene::build(&file, std::path::Path::new("."), &options).unwrap();
    /// assert_eq!(scene.eye(), None); // the file has no camera
    /// scene.set_eye([0.0, 2.0, 6.0]).unwrap();
    /// assert_eq!(scene.eye(), Some([0.0, 2.0, 6.0]));
    /// ```
    pub fn set_eye(&mut self, eye: [f64; 3]) -> Result<()> {
        if !eye.iter().all(|x| x.is_finite()) {
            return Err(Error::parameter(
                "eye",
                format!("{eye:?} is not a finite position"),
            ));
        }
        self.eye = Some(eye);
        Ok(())
    }

    /// The eye, which a glossy scene needs.
    pub(super) fn glossy_eye(&self) -> Result<[f64; 3]> {
        self.eye.ok_or_else(|| {
            let k = self.objects.iter().position(|o| !o.brdf.is_lambert());
            Error::parameter(
                "eye",
                format!(
                    "object {} is glossy ({}): its radiance depends on the view; give the scene \
                     file a camera or set the eye",
                    k.unwrap_or(0),
                    k.map_or(Brdf::Lambert, |k| self.objects[k].brdf.clone())
                ),
            )
        })
    }

    /// Checks the glossy options and gives every glossy object the orientation of its BRDF
    /// (one per distinct BRDF, shared).
    pub(super) fn orient(&mut self) -> Result<()> {
        let param = self.param();
        let g = &self.glossy;
        if g.cache_bins.is_some() {
            return Err(Error::parameter(
                "rotation cache",
                "a dynamic scene rotates every glossy vertex's BRDF in its exact frame: no cache",
            ));
        }
        g.check(param)?;
        for (k, o) in self.objects.iter().enumerate() {
            if let Brdf::Phong { exponent } | Brdf::BlinnPhong { exponent } = o.brdf
                && !(0.0..=MAX_EXPONENT).contains(&exponent)
            {
                return Err(Error::parameter(
                    "brdf",
                    format!(
                        "object {k}: the exponent {exponent} of {} must be from 0 to {MAX_EXPONENT}",
                        o.brdf
                    ),
                ));
            }
        }
        let mut made: Vec<(Brdf, Arc<Orientation>)> = Vec::new();
        let mut orientations = Vec::with_capacity(self.objects.len());
        for o in &self.objects {
            if o.brdf.is_lambert() {
                orientations.push(None);
                continue;
            }
            let found = made.iter().find(|(b, _)| *b == o.brdf).map(|m| m.1.clone());
            let orientation = match found {
                Some(x) => x,
                None => {
                    let x = Arc::new(Orientation::new(
                        &o.brdf,
                        param,
                        g.rotation,
                        g.level,
                        g.elevations,
                    )?);
                    made.push((o.brdf.clone(), x.clone()));
                    x
                }
            };
            orientations.push(Some(orientation));
        }
        for (o, x) in self.objects.iter_mut().zip(orientations) {
            o.orientation = x;
        }
        Ok(())
    }

    /// What each vertex's integral is multiplied by, `(V, 3)`: `albedo / pi` for a Lambertian
    /// vertex, `albedo` for a glossy one (its BRDF is inside the integral).
    pub(super) fn reflectance(&self) -> Array2<f64> {
        let mut albedo = self.albedo().mapv(f64::from);
        for (k, o) in self.objects.iter().enumerate() {
            if o.orientation.is_none() {
                let rows = ndarray::s![self.object_vertices(k), ..];
                albedo
                    .slice_mut(rows)
                    .mapv_inplace(|a| a / std::f64::consts::PI);
            }
        }
        if let Some((g, _)) = &self.ground {
            let v = self.vertex_count();
            albedo
                .slice_mut(ndarray::s![v - g.vertex_count().., ..])
                .mapv_inplace(|a| a / std::f64::consts::PI);
        }
        albedo
    }

    /// The BRDF of receiver `r` in its frame as the eye sees it, as Haar coefficients (the
    /// lighting's convention), with the depth it is limited to; `None`: Lambertian.
    fn brdf_coefficients(&self, r: &Receiver, depth: usize) -> Result<Option<(Lighting, usize)>> {
        let Some(orientation) = r.owner.and_then(|k| self.objects[k].orientation.as_ref()) else {
            return Ok(None);
        };
        let eye = self.glossy_eye()?;
        let view = std::array::from_fn(|k| eye[k] - r.position[k]);
        let frame = Frame::new(r.normal, view).map_err(|_| {
            Error::parameter(
                "eye",
                format!("the eye {eye:?} sits on a vertex: it has no view direction"),
            )
        })?;
        let keep = self
            .glossy
            .keep_brdf
            .map_or(Selection::All, Selection::Largest);
        let coefficients = Lighting::from_map(&orientation.lobe(&frame)?, keep)?;
        let depth = depth.min(self.glossy.brdf_levels.unwrap_or(depth));
        Ok(Some((coefficients, depth)))
    }

    /// Receiver `r`'s BRDF factor as a tree (`None`: Lambertian).
    pub(super) fn brdf_tree<T: Sample>(
        &self,
        r: &Receiver,
        depth: usize,
    ) -> Result<Option<HaarTree<T, 3>>> {
        self.brdf_coefficients(r, depth)?
            .map(|(c, depth)| light_tree::<T>(&c, depth))
            .transpose()
    }

    /// Receiver `r`'s BRDF factor as sparse RGB coefficients, ascending (`None`: Lambertian).
    pub(super) fn brdf_sparse(&self, r: &Receiver, depth: usize) -> Result<Option<SparseRgb>> {
        Ok(self
            .brdf_coefficients(r, depth)?
            .map(|(c, depth)| light_sparse::<f64>(&c, depth)))
    }
}

#[cfg(test)]
#[path = "glossy_tests.rs"]
mod tests;
