//! Spherical harmonics of `B` bands against Haar at equal coefficient counts, and Haar at
//! larger budgets (to compare at equal time).

use crate::Result;
use crate::relight::RelightRecord;
use crate::relight::condition::Condition;
use crate::relight::scene::SceneUnderTest;
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::ShadeOptions;
use haarshift_relight::shade::glossy::GlossyOptions;
use haarshift_relight::shade::{Method, ShaderSpec};

impl SceneUnderTest<'_> {
    /// Haar against spherical harmonics at equal coefficient counts, and Haar at larger
    /// budgets.
    pub(in crate::relight) fn harmonics_axis(
        &mut self,
        condition: &Condition<'_>,
    ) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.harmonics_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut out = Vec::new();
        for &bands in &self.protocol.sh_bands.clone() {
            let spec = ShaderSpec {
                method: Method::Sh,
                material: GlossyOptions::default().for_brdf(condition.brdf),
                sh_bands: Some(bands),
                ..ShaderSpec::default()
            };
            let s = self.relight(condition, (ParamKind::LatLong, n, true), &spec)?;
            let mut r = self.record("harmonics", condition, &s, param)?;
            r.sh_bands = Some(bands);
            r.parameters = format!("{bands} bands");
            out.push(r);
        }
        let mut budgets: Vec<usize> = self.protocol.sh_bands.iter().map(|b| b * b).collect();
        budgets.extend(&self.protocol.haar_budgets);
        for count in budgets {
            if count < param.faces() || count > param.texels() {
                continue;
            }
            let keep = Selection::Largest(count - param.faces());
            let shade = ShadeOptions {
                keep_visibility: Some(keep),
                depth: None,
            };
            let glossy = GlossyOptions {
                keep_brdf: Some(count - param.faces()),
                ..GlossyOptions::default()
            };
            let s = self.haar(condition, (ParamKind::LatLong, n), keep, &shade, &glossy)?;
            let mut r = self.record("harmonics", condition, &s, param)?;
            r.parameters = format!("{count} coefficients");
            out.push(r);
        }
        Ok(out)
    }
}
