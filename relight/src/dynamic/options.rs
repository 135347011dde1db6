//! How a dynamic scene is precomputed and shaded: [`DynamicOptions`], and the budgets a caller
//! states them by ([`DynamicBudgets`]).

use crate::dynamic::fields::{FieldOptions, Truncation};
use crate::{Error, Result};
use haarshift::faces::param::Parameterization;
use haarshift::product::Selection;

/// How a dynamic scene is precomputed and shaded; see the [module docs](super).
///
/// ```
/// use haarshift_relight::dynamic::DynamicOptions;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let o = DynamicOptions::new(Parameterization::new(ParamKind::LatLong, 32).unwrap());
/// assert_eq!(o.field.samples(), 29_720); // Sun 2006's fields
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicOptions {
    /// The occlusion fields; their parameterisation is the scene's.
    pub field: FieldOptions,
    /// What each vertex's own transport keeps.
    pub keep_visibility: Selection,
    /// Truncation of looked-up occlusion maps.
    pub truncation: Truncation,
    /// What just-in-time radiance transfer keeps of each vertex's fixed product.
    pub keep_product: Selection,
    /// Detail levels taking part, `0..=log2 S` (`None`: all).
    pub depth: Option<usize>,
    /// Report progress ([`progress`](haarshift::progress)).
    pub progress: bool,
}

impl DynamicOptions {
    /// Sun 2006's fields, everything kept, every level.
    pub fn new(param: Parameterization) -> Self {
        DynamicOptions {
            field: FieldOptions::new(param),
            keep_visibility: Selection::All,
            truncation: Truncation::Before,
            keep_product: Selection::All,
            depth: None,
            progress: false,
        }
    }

    /// The parameterisation of every map.
    pub fn param(&self) -> Parameterization {
        self.field.param
    }

    /// The options of `budgets`: the fields' sample counts and every truncation, as
    /// `relight scene` and `haarshift.relight.scene` take them.
    ///
    /// ```
    /// use haarshift::product::Selection;
    /// use haarshift_relight::dynamic::{DynamicBudgets, DynamicOptions};
    /// use haarshift_relight::dynamic::fields::Truncation;
    /// use haarshift::faces::{ParamKind, Parameterization};
    /// let param = Parameterization::new(ParamKind::LatLong, 16).unwrap();
    /// let budgets = DynamicBudgets { keep_field: Some(40), truncate_after: true, ..DynamicBudgets::new(param) };
    /// let o = DynamicOptions::from_budgets(&budgets);
    /// assert_eq!((o.field.keep, o.truncation), (Selection::Largest(40), Truncation::After(Selection::Largest(40))));
    /// assert_eq!(DynamicOptions::from_budgets(&DynamicBudgets::new(param)), DynamicOptions::new(param));
    /// ```
    pub fn from_budgets(budgets: &DynamicBudgets) -> Self {
        let largest = |k: Option<usize>| k.map_or(Selection::All, Selection::Largest);
        DynamicOptions {
            field: FieldOptions {
                keep: largest(budgets.keep_field),
                circles: budgets.circles,
                circle_points: budgets.circle_points,
                shells: budgets.shells,
                shell_grid: budgets.shell_grid,
                progress: budgets.progress,
                ..FieldOptions::new(budgets.param)
            },
            keep_visibility: largest(budgets.keep_visibility),
            truncation: if budgets.truncate_after {
                Truncation::After(largest(budgets.keep_field))
            } else {
                Truncation::Before
            },
            keep_product: largest(budgets.keep_product),
            depth: budgets.depth,
            progress: budgets.progress,
        }
    }

    /// Checks every budget against the parameterisation; returns the detail levels taking
    /// part.
    pub(crate) fn check(&self) -> Result<usize> {
        let p = self.param();
        let details = p.texels() - p.faces();
        self.keep_visibility.limit(details)?;
        self.keep_product.limit(details)?;
        if let Truncation::After(keep) = self.truncation {
            keep.limit(details)?;
        }
        let levels = p.face_size().trailing_zeros() as usize;
        match self.depth {
            Some(d) if d > levels => Err(Error::parameter(
                "depth",
                format!(
                    "{d}: faces of side {} have detail levels 0 to {levels}",
                    p.face_size()
                ),
            )),
            Some(d) => Ok(d),
            None => Ok(levels),
        }
    }
}

/// A dynamic scene's budgets as a caller states them: the fields' parameterisation and sample
/// counts, and how many detail coefficients each factor keeps (`None`: all);
/// [`DynamicOptions::from_budgets`] makes the options.
///
/// ```
/// use haarshift_relight::dynamic::DynamicBudgets;
/// use haarshift::faces::{ParamKind, Parameterization};
/// let b = DynamicBudgets::new(Parameterization::new(ParamKind::LatLong, 32).unwrap());
/// assert_eq!((b.circles, b.circle_points, b.shells, b.shell_grid), (100, 200, 20, 9));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicBudgets {
    /// Every map's parameterisation.
    pub param: Parameterization,
    /// Detail coefficients of each vertex's own transport.
    pub keep_visibility: Option<usize>,
    /// Detail coefficients of each occlusion map.
    pub keep_field: Option<usize>,
    /// Detail coefficients of each vertex's fixed product (animations).
    pub keep_product: Option<usize>,
    /// Truncate looked-up occlusion maps after blending them (to `keep_field`), not before.
    pub truncate_after: bool,
    /// Detail levels taking part, `0..D` (`None`: all).
    pub depth: Option<usize>,
    /// Circles of the planar field.
    pub circles: usize,
    /// Points per circle.
    pub circle_points: usize,
    /// Shells of the spherical field.
    pub shells: usize,
    /// Points per face edge of each shell's cube grid.
    pub shell_grid: usize,
    /// Report progress ([`progress`](haarshift::progress)).
    pub progress: bool,
}

impl DynamicBudgets {
    /// Sun 2006's fields in `param`, everything kept.
    pub fn new(param: Parameterization) -> Self {
        let f = FieldOptions::new(param);
        DynamicBudgets {
            param,
            keep_visibility: None,
            keep_field: None,
            keep_product: None,
            truncate_after: false,
            depth: None,
            circles: f.circles,
            circle_points: f.circle_points,
            shells: f.shells,
            shell_grid: f.shell_grid,
            progress: false,
        }
    }
}
