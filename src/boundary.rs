//! How a signal is continued past its edges: used for padding to a power of two and for
//! samples that a shift or rotation brings in from outside.

crate::named::named_enum! {
    /// Extension of a finite signal beyond its ends.
    ///
    /// For a signal `a b c d`:
    ///
    /// | mode | to the left | to the right |
    /// |---|---|---|
    /// | `Zero` | `0 0 0` | `0 0 0` |
    /// | `Edge` | `a a a` | `d d d` |
    /// | `Reflect` (half-sample symmetric, numpy `symmetric`, scipy `reflect`) | `c b a` | `d c b` |
    /// | `Wrap` (periodic) | `b c d` | `a b c` |
    ///
    /// ```
    /// use haarshift::BoundaryMode;
    /// let n = 4;
    /// assert_eq!(BoundaryMode::Reflect.source_index(-1, n), Some(0));
    /// assert_eq!(BoundaryMode::Reflect.source_index(5, n), Some(2));
    /// assert_eq!(BoundaryMode::Wrap.source_index(-1, n), Some(3));
    /// assert_eq!(BoundaryMode::Edge.source_index(9, n), Some(3));
    /// assert_eq!(BoundaryMode::Zero.source_index(4, n), None);
    /// ```
    #[derive(Default)]
    pub enum BoundaryMode ("boundary mode") {
        /// Zeros outside.
        #[default]
        Zero = "zero",
        /// The edge sample repeated.
        Edge = "edge",
        /// Mirror about the signal's end, the edge sample repeated once (half-sample symmetric).
        Reflect = "reflect",
        /// Periodic continuation.
        Wrap = "wrap",
    }
}

impl BoundaryMode {
    /// The index inside `0..n` whose sample stands at position `i`, or `None` when the sample
    /// there is zero (only `Zero` outside the signal, or any mode when `n == 0`).
    #[inline]
    pub fn source_index(self, i: isize, n: usize) -> Option<usize> {
        let len = n as isize;
        if n == 0 {
            return None;
        }
        if (0..len).contains(&i) {
            return Some(i as usize);
        }
        match self {
            BoundaryMode::Zero => None,
            BoundaryMode::Edge => Some(i.clamp(0, len - 1) as usize),
            BoundaryMode::Wrap => Some(i.rem_euclid(len) as usize),
            BoundaryMode::Reflect => {
                let m = i.rem_euclid(2 * len);
                Some(if m < len { m } else { 2 * len - 1 - m } as usize)
            }
        }
    }
}

#[cfg(test)]
#[path = "boundary_tests.rs"]
mod tests;
