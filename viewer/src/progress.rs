//! The reference's progress, carried from the library's ray casting to the page that asked.
//!
//! The library reports long computations to one process-wide [`Progress`] reporter. The
//! viewer's, [`PageProgress`], gives each task to the [`Counter`] that the thread starting it
//! has [`watch`]ed (a session's reference thread), and drops the tasks of every other thread,
//! so two pages computing references at once each see their own count.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use haarshift::progress::{Progress, ProgressTask, set_reporter};

/// Units done and in all of the tasks begun on a watched thread.
///
/// ```
/// use haarshift_viewer::progress::Counter;
/// let c = Counter::default();
/// assert_eq!(c.get(), (0, 0));
/// ```
#[derive(Debug, Default)]
pub struct Counter {
    done: AtomicU64,
    total: AtomicU64,
}

impl Counter {
    /// `(done, total)`.
    pub fn get(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }
}

thread_local! {
    static WATCHED: RefCell<Option<Arc<Counter>>> = const { RefCell::new(None) };
}

/// Counts the tasks this thread begins from now on into `counter`.
///
/// ```
/// use haarshift::progress::Progress;
/// use haarshift_viewer::progress::{Counter, PageProgress, watch};
/// use std::sync::Arc;
/// let counter = Arc::new(Counter::default());
/// watch(Arc::clone(&counter));
/// let task = PageProgress.begin("rays", 10);
/// task.advance(4);
/// assert_eq!(counter.get(), (4, 10));
/// // Another thread's tasks are not counted here.
/// std::thread::spawn(|| PageProgress.begin("rays", 99).advance(99)).join().unwrap();
/// assert_eq!(counter.get(), (4, 10));
/// ```
pub fn watch(counter: Arc<Counter>) {
    WATCHED.with(|w| *w.borrow_mut() = Some(counter));
}

/// The viewer's reporter; see the [module docs](self).
pub struct PageProgress;

impl PageProgress {
    /// Installs it as the process's reporter; `false` when another was installed first (the
    /// page then sees no counts, only when the reference is ready).
    ///
    /// ```
    /// use haarshift_viewer::progress::PageProgress;
    /// // A program installs one reporter: the first call wins, a second is refused.
    /// assert!(PageProgress::install());
    /// assert!(!PageProgress::install());
    /// ```
    pub fn install() -> bool {
        set_reporter(Box::new(PageProgress)).is_ok()
    }
}

/// A task counted into a watched thread's counter, or into nothing.
struct CountedTask(Option<Arc<Counter>>);

impl Progress for PageProgress {
    fn begin(&self, _what: &str, len: u64) -> Box<dyn ProgressTask> {
        let counter = WATCHED.with(|w| w.borrow().clone());
        if let Some(c) = &counter {
            c.total.fetch_add(len, Ordering::Relaxed);
        }
        Box::new(CountedTask(counter))
    }
}

impl ProgressTask for CountedTask {
    fn advance(&self, units: u64) {
        if let Some(c) = &self.0 {
            c.done.fetch_add(units, Ordering::Relaxed);
        }
    }
}
