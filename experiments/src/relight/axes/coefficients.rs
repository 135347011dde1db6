//! Thesis Fig. 4.7 (Sun 2006): each rotated BRDF map cut coarse to fine or to its largest
//! coefficients.

use crate::relight::RelightRecord;
use crate::relight::condition::Condition;
use crate::relight::scene::SceneUnderTest;
use crate::{Error, Result};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::ShadeOptions;
use haarshift_relight::shade::glossy::GlossyOptions;

impl SceneUnderTest<'_> {
    /// Thesis Fig. 4.7: the rotated BRDF cut coarse to fine or to its largest coefficients.
    pub(in crate::relight) fn coefficient_axis(
        &mut self,
        condition: &Condition<'_>,
    ) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.rotation_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let levels = n.trailing_zeros() as usize;
        let mut out = Vec::new();
        let mut cuts: Vec<(String, Option<usize>, GlossyOptions)> = Vec::new();
        for &c in &self.protocol.coefficient_counts {
            let l = (c.trailing_zeros() / 2) as usize;
            if 4usize.pow(l as u32) != c || l > levels {
                return Err(Error::parameter(
                    "coefficient counts",
                    format!("{c}: expected a power of 4 up to {}", n * n),
                ));
            }
            cuts.push((
                format!("cutoff {c}/face"),
                Some(c),
                GlossyOptions {
                    brdf_levels: Some(l),
                    ..GlossyOptions::default()
                },
            ));
            cuts.push((
                format!("largest {c}/face"),
                Some(c),
                GlossyOptions {
                    keep_brdf: Some((c - 1) * param.faces()),
                    ..GlossyOptions::default()
                },
            ));
        }
        cuts.push(("every coefficient".into(), None, GlossyOptions::default()));
        for (label, count, glossy) in cuts {
            let s = self.haar(
                condition,
                (ParamKind::LatLong, n),
                Selection::All,
                &ShadeOptions::default(),
                &glossy,
            )?;
            let mut r = self.record("coefficients", condition, &s, param)?;
            r.parameters = label;
            r.brdf_coefficients = count;
            out.push(r);
        }
        Ok(out)
    }
}
