//! Sun 2006, Fig. 3.5: the traversal depth (detail levels `0..d`).

use crate::Result;
use crate::relight::RelightRecord;
use crate::relight::condition::Condition;
use crate::relight::scene::SceneUnderTest;
use haarshift::faces::{ParamKind, Parameterization};
use haarshift::product::Selection;
use haarshift_relight::ShadeOptions;
use haarshift_relight::shade::glossy::GlossyOptions;

impl SceneUnderTest<'_> {
    /// Sun 2006, Fig. 3.5: the traversal depth.
    pub(in crate::relight) fn depth_axis(
        &mut self,
        condition: &Condition<'_>,
    ) -> Result<Vec<RelightRecord>> {
        let n = self.protocol.depth_resolution;
        let param = Parameterization::new(ParamKind::LatLong, n)?;
        let mut out = Vec::new();
        for depth in 1..=n.trailing_zeros() as usize {
            let shade = ShadeOptions {
                keep_visibility: None,
                depth: Some(depth),
            };
            let s = self.haar(
                condition,
                (ParamKind::LatLong, n),
                Selection::All,
                &shade,
                &GlossyOptions::default(),
            )?;
            let mut r = self.record("depth", condition, &s, param)?;
            r.depth = depth;
            r.parameters = format!("depth {depth}");
            out.push(r);
        }
        Ok(out)
    }
}
