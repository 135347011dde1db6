//! The transport stored in half the bytes: 16-bit coefficients with a scale per vertex.
//!
//! A Lambertian frame reads every vertex's sparse transport once, so its floor is the time to
//! stream those bytes (8 a coefficient as `f32` with a `u32` index). [`QuantisedTransport`]
//! stores each coefficient in 4: the gap to the previous index (the first's to 0) as a `u16`,
//! the value as an `i16`. Vertex `v`'s values are
//! `c = q s_v`, `s_v = max |c| / 32767`, rounded to the nearest step, so a coefficient is off by
//! at most `s_v / 2` (and f32's rounding) and the radiance by at most
//! `albedo / pi x s_v / 2 x sum_k |L(i_k)|` per channel (tested), beside which f32's rounding is
//! small. A gap over 65,535 (faces of side 256 and more) is bridged by entries of value 0, which
//! add nothing. The dot product is accumulated as [`PreparedTransport`]'s is (runs of
//! [`RUN`](super::RUN) in f32, four accumulators, runs in f64), with `s_v` applied once per
//! vertex. What it costs in accuracy on real maps: `results/relight/quantised.md`.

use ndarray::Array2;

use super::{LightRows, PreparedTransport};
use crate::Result;
use crate::light::lighting::Lighting;
use haarshift::Sample;
use haarshift::faces::Parameterization;

/// The largest magnitude of a quantised coefficient.
const STEPS: f32 = 32767.0;

/// A [`PreparedTransport`]'s coefficients in 16 bits each; see the module docs.
///
/// ```
/// use haarshift::product::Selection;
/// use haarshift_relight::shade::lambert::QuantisedTransport;
/// use haarshift_relight::{Lighting, PreparedTransport, ShadeOptions, TransportSet};
/// use haarshift::faces::param::{ParamKind, Parameterization, SphereMap};
/// use ndarray::{Array2, Array3};
/// let param = Parameterization::new(ParamKind::LatLong, 8).unwrap();
/// let mut set = TransportSet::new(param, Selection::All);
/// set.push(Array3::from_shape_fn((2, 8, 8), |(f, r, c)| (f + r * c) as f32 / 64.0).view()).unwrap();
/// let sky = SphereMap::<f64>::from_fn(param, 3, |d, out| out.fill(1.0 + d[1])).unwrap();
/// let light = Lighting::from_map(&sky, Selection::All).unwrap();
/// let albedo = Array2::from_elem((1, 3), 0.5f32);
/// let exact = PreparedTransport::<f32>::new(&set, albedo.view(), &ShadeOptions::default()).unwrap();
/// let packed = QuantisedTransport::new(&exact);
/// assert_eq!(packed.entry_count(), exact.coefficient_count()); // no gap over 65,535
/// assert_eq!(packed.stored_bytes(), 4 * exact.coefficient_count() + 8 * 2);
/// let (a, b) = (exact.shade(&light).unwrap(), packed.shade(&light).unwrap());
/// assert!((a[[0, 1]] - b[[0, 1]]).abs() < 1e-4 * a[[0, 1]]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct QuantisedTransport {
    /// Entries of vertex `v`: `offsets[v]..offsets[v + 1]` of `gaps` and `values`.
    offsets: Vec<u64>,
    /// Each entry's index less the previous entry's (the vertex's first: its index).
    gaps: Vec<u16>,
    /// Each entry's value in steps of the vertex's scale.
    values: Vec<i16>,
    /// `s_v`, the value of one step, per vertex.
    scales: Vec<f32>,
    /// `albedo / pi x s_v`, RGB, per vertex: everything a vertex's sum is multiplied by.
    factors: Vec<[f64; 3]>,
    /// The lighting's parameterisation, checked on every frame.
    param: Parameterization,
}

impl QuantisedTransport {
    /// Quantises `prepared`'s coefficients (as re-truncated and depth-limited).
    pub fn new(prepared: &PreparedTransport<f32>) -> Self {
        let vertices = prepared.vertex_count();
        let mut offsets = Vec::with_capacity(vertices + 1);
        let mut gaps = Vec::with_capacity(prepared.coefficient_count());
        let mut quantised = Vec::with_capacity(prepared.coefficient_count());
        let mut scales = Vec::with_capacity(vertices);
        let mut factors = Vec::with_capacity(vertices);
        offsets.push(0);
        for v in 0..vertices {
            let (indices, values) = prepared.coefficients(v);
            let largest = values.iter().fold(0.0f32, |m, c| m.max(c.abs()));
            let scale = largest / STEPS;
            let mut previous = 0u32;
            for (&i, &c) in indices.iter().zip(values) {
                let mut gap = i - previous;
                while gap > u32::from(u16::MAX) {
                    gaps.push(u16::MAX);
                    quantised.push(0);
                    gap -= u32::from(u16::MAX);
                }
                gaps.push(gap as u16);
                // |c| <= largest, so the quotient rounds into -32767..=32767.
                quantised.push(if scale > 0.0 {
                    (c / scale).round() as i16
                } else {
                    0
                });
                previous = i;
            }
            offsets.push(gaps.len() as u64);
            let albedo = prepared.albedo(v);
            scales.push(scale);
            factors.push(albedo.map(|a| a * std::f64::consts::FRAC_1_PI * f64::from(scale)));
        }
        QuantisedTransport {
            offsets,
            gaps,
            values: quantised,
            scales,
            factors,
            param: prepared.param(),
        }
    }

    /// Vertices.
    pub fn vertex_count(&self) -> usize {
        self.factors.len()
    }

    /// Entries stored: the coefficients, and the zero entries that bridge gaps over 65,535.
    pub fn entry_count(&self) -> usize {
        self.gaps.len()
    }

    /// Bytes a frame streams: the entries and the offsets (the exact transport's are
    /// `8 x` coefficients `+ 8 x (V + 1)`).
    pub fn stored_bytes(&self) -> usize {
        self.gaps.len() * 4 + self.offsets.len() * 8
    }

    /// Vertex `v`'s entries as they are stored: the gaps between indices and the values in
    /// steps (what a frame reads).
    pub fn entries(&self, v: usize) -> (&[u16], &[i16]) {
        let entries = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        (&self.gaps[entries.clone()], &self.values[entries])
    }

    /// Vertex `v`'s entries decoded: Mallat indices (ascending) and the values `q s_v`
    /// (the entries that bridge gaps over 65,535 are there too, with value 0).
    pub fn coefficients(&self, v: usize) -> (Vec<u32>, Vec<f32>) {
        let entries = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        let mut index = 0u32;
        let gaps = self.gaps[entries.clone()].iter().map(|&gap| {
            index += u32::from(gap);
            index
        });
        let values = self.values[entries]
            .iter()
            .map(|&q| f32::from(q) * self.scales[v]);
        (gaps.collect(), values.collect())
    }

    /// Every vertex's outgoing radiance under `lighting`, `(V, 3)`.
    pub fn shade(&self, lighting: &Lighting) -> Result<Array2<f32>> {
        let mut out = Array2::zeros((self.vertex_count(), 3));
        self.shade_into(lighting, &mut out)?;
        Ok(out)
    }

    /// [`shade`](Self::shade) into `out` (`(V, 3)`), in any sample type; the arithmetic is f32.
    pub fn shade_into<T: Sample>(&self, lighting: &Lighting, out: &mut Array2<T>) -> Result<()> {
        let out = super::checked_output(self.param, self.vertex_count(), lighting, out)?;
        let light = LightRows::<f32>::new(lighting);
        let upcoming = |w: usize| {
            if w < self.vertex_count() {
                let (gaps, values) = self.entries(w);
                super::prefetch(gaps);
                super::prefetch(values);
            }
        };
        super::shade_vertices(
            out,
            || (),
            upcoming,
            |v, ()| {
                let (gaps, values) = self.entries(v);
                let mut index = 0usize;
                let next = move |gap: u16| {
                    index += usize::from(gap);
                    index
                };
                let sum = light.gather(gaps, values, next, f32::from);
                let f = self.factors[v];
                std::array::from_fn(|c| sum[c] * f[c])
            },
        );
        Ok(())
    }
}

#[cfg(test)]
#[path = "quantised_tests.rs"]
mod tests;
