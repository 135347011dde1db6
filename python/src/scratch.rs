//! Scratch memory kept between calls, one kind per sample type: a call reuses the buffers of
//! the previous one instead of faulting in fresh pages every time.

use std::any::Any;
use std::sync::{Mutex, MutexGuard, PoisonError};

use haarshift::Sample;

/// A kind of scratch, generic over the sample type.
pub trait Kind {
    /// The scratch for samples of `T`.
    type Of<T: Sample>: Default + Send + 'static;
}

/// One scratch of kind `K` for `f32` and one for `f64`.
pub struct Scratch<K: Kind> {
    single: K::Of<f32>,
    double: K::Of<f64>,
}

impl<K: Kind> Default for Scratch<K> {
    fn default() -> Self {
        Scratch {
            single: Default::default(),
            double: Default::default(),
        }
    }
}

impl<K: Kind> Scratch<K> {
    /// The scratch for `T`.
    pub fn get<T: Sample>(&mut self) -> &mut K::Of<T> {
        let single: &mut dyn Any = &mut self.single;
        if single.is::<K::Of<T>>() {
            return single.downcast_mut().expect("checked");
        }
        let double: &mut dyn Any = &mut self.double;
        double
            .downcast_mut()
            .expect("Sample is implemented for f32 and f64 only")
    }
}

/// `scratch` locked, whatever an earlier panic left in it (scratch holds no invariant).
pub fn lock<K: Kind>(scratch: &Mutex<Scratch<K>>) -> MutexGuard<'_, Scratch<K>> {
    scratch.lock().unwrap_or_else(PoisonError::into_inner)
}
