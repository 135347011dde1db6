//! The per-vertex side of the glossy shading ([module docs](super)): the cache bins a vertex
//! blends, the buffers a thread reuses from vertex to vertex, and the dense sum over texels.

use super::{MapKey, Maps, Planes};
use crate::material::orient::LobeWork;
use crate::shade::lambert::RUN;
use haarshift::Sample;

/// The cache bins one vertex blends, with their weights: up to four (a Phong vertex's
/// nearest bins), in no allocation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Blend {
    pub(super) bins: [(MapKey, f64); 4],
    pub(super) len: usize,
}

impl Blend {
    /// No bins yet.
    pub(super) fn new() -> Blend {
        Blend {
            bins: [(MapKey::Mirror(0, 0), 0.0); 4],
            len: 0,
        }
    }

    /// Adds `weight` to `key`'s (a bin met twice, at a pole, counts once).
    pub(super) fn add(&mut self, key: MapKey, weight: f64) {
        match self.bins[..self.len].iter_mut().find(|(k, _)| *k == key) {
            Some((_, w)) => *w += weight,
            None => {
                self.bins[self.len] = (key, weight);
                self.len += 1;
            }
        }
    }

    /// The bins.
    pub(super) fn keys(&self) -> impl Iterator<Item = MapKey> + '_ {
        self.bins[..self.len].iter().map(|(k, _)| *k)
    }

    /// The blended map `sum_k w_k rho_k` (the triple product is linear in the BRDF): a bin of
    /// weight 1 as it is, else written into `out`.
    pub(super) fn blend<'a, T: Sample>(&self, maps: &'a Maps<T>, out: &'a mut Vec<T>) -> &'a [T] {
        let bins = &self.bins[..self.len];
        if let [(key, w)] = bins
            && *w == 1.0
        {
            return &maps[key];
        }
        out.clear();
        for (k, (key, w)) in bins.iter().enumerate() {
            let (map, w) = (&maps[key], T::from_f64(*w));
            if k == 0 {
                out.extend(map.iter().map(|&x| w * x));
            } else {
                for (o, &x) in out.iter_mut().zip(map.iter()) {
                    *o += w * x;
                }
            }
        }
        out
    }
}

/// One thread's buffers for the vertices it shades, reused from vertex to vertex.
#[derive(Debug, Default)]
pub(super) struct VertexWork<T> {
    pub(super) lobe: LobeBuffers,
    pub(super) rho: Planes<T>,
    pub(super) transport: TransportWork<T>,
}

/// The BRDF's planes in f64 before truncation and conversion, and the rotation's scratch.
#[derive(Debug, Default)]
pub(super) struct LobeBuffers {
    pub(super) planes: Vec<f64>,
    pub(super) work: LobeWork,
}

/// A vertex's transport coefficients (dense), its texel values and the inverse's scratch.
#[derive(Debug, Default)]
pub(super) struct TransportWork<T> {
    pub(super) coefficients: Vec<T>,
    pub(super) pixels: Vec<T>,
    pub(super) scratch: Vec<T>,
}

/// Partial sums of a run kept side by side, so that the loop over a run vectorises.
const LANES: usize = 8;

/// `sum_p t(p) L_c(p) rho_c(p)` per channel over the texels, `light` three planes and `rho`
/// one or three: over runs of [`RUN`] texels, `t rho` once per BRDF channel, then eight lanes
/// in `T` per lighting channel (a loop that vectorises), the runs added in f64.
pub(super) fn triple_sum<T: Sample>(t: &[T], light: &[T], rho: &[T]) -> [f64; 3] {
    let texels = t.len();
    let channels = rho.len() / texels;
    let mut total = [0.0f64; 3];
    let mut weighted = [T::zero(); RUN];
    for start in (0..texels).step_by(RUN) {
        let len = RUN.min(texels - start);
        let tw = &mut weighted[..len];
        for (c, sum) in total.iter_mut().enumerate() {
            if c < channels {
                let r = &rho[c * texels + start..][..len];
                for ((o, &t), &r) in tw.iter_mut().zip(&t[start..]).zip(r) {
                    *o = t * r;
                }
            }
            let l = &light[c * texels + start..][..len];
            let mut lanes = [T::zero(); LANES];
            let (w8, l8) = (tw.chunks_exact(LANES), l.chunks_exact(LANES));
            let rest = (w8.remainder(), l8.remainder());
            for (w, l) in w8.zip(l8) {
                for k in 0..LANES {
                    lanes[k] += w[k] * l[k];
                }
            }
            let mut run = lanes.iter().fold(T::zero(), |a, &b| a + b);
            for (&w, &l) in rest.0.iter().zip(rest.1) {
                run += w * l;
            }
            *sum += run.as_f64();
        }
    }
    total
}
