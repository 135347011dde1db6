//! Thesis Figs. 4.5-4.6 (Sun 2006): every way of bringing the BRDF into each vertex's frame,
//! every coefficient kept, with the thesis's own metric against the spatial rotation and the
//! picture grid of the condition.

use crate::Result;
use crate::relight::condition::Condition;
use crate::relight::scene::SceneUnderTest;
use crate::relight::{PictureGrid, RelightRecord};
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::metrics::rms;
use haarshift::product::Selection;
use haarshift_relight::ShadeOptions;
use haarshift_relight::material::orient::BrdfRotation;
use haarshift_relight::shade::glossy::GlossyOptions;

impl SceneUnderTest<'_> {
    /// Thesis Figs. 4.5-4.6: every orienting method (`reference` only `with_reference`),
    /// every coefficient kept; and the picture grid of this condition.
    pub(in crate::relight) fn rotation_axis(
        &mut self,
        condition: &Condition<'_>,
        with_reference: bool,
    ) -> Result<(Vec<RelightRecord>, PictureGrid)> {
        let n = self.protocol.rotation_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut shaded = Vec::new();
        for o in &self.protocol.orientings.clone() {
            if o.rotation == BrdfRotation::Reference && !with_reference {
                continue;
            }
            let glossy = GlossyOptions {
                rotation: o.rotation,
                level: o.level,
                ..GlossyOptions::default()
            };
            let s = self.haar(
                condition,
                (ParamKind::LatLong, n),
                Selection::All,
                &ShadeOptions::default(),
                &glossy,
            )?;
            let mut r = self.record("rotation", condition, &s, param)?;
            r.level = o.level;
            r.parameters = match o.level {
                Some(l) => format!("level {l} (thesis {})", l + 1),
                None => "finest level".into(),
            };
            shaded.push((o.rotation, r, s));
        }
        // The thesis's metric is the difference to the spatially rotated render.
        let spatial = shaded
            .iter()
            .find(|(rotation, _, _)| *rotation == BrdfRotation::Spatial)
            .map(|(_, _, s)| s.radiance.clone());
        let truth = self.truth(condition)?;
        if let Some(spatial) = &spatial {
            // Relative to the truth's RMS, as every other figure.
            let scale = rms(truth.view());
            for (_, r, s) in &mut shaded {
                r.spatial_difference = Some(rms((&s.radiance - spatial).view()) / scale);
            }
        }
        let shaded: Vec<_> = shaded.into_iter().map(|(_, r, s)| (r, s)).collect();
        let grid = self.grid(condition, &shaded, &truth)?;
        Ok((shaded.into_iter().map(|(r, _)| r).collect(), grid))
    }
}
