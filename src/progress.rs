//! Progress of long computations, reported to whoever installed a reporter: the library draws
//! nothing itself.
//!
//! Ray casting, shadow maps, occlusion fields and the reference take seconds to hours. Each
//! asks for a [`ProgressTask`] when its options say `progress: true`, advances it as vertices
//! (or field points) finish, and drops it when done. Where the report goes is the caller's
//! choice: the command-line tool installs a [`Progress`] that draws terminal bars, a server
//! could forward counts to a page, and with no reporter installed (the default: tests, Python,
//! embedding programs) nothing happens at all. The pattern is that of the `log` crate: one
//! process-wide reporter, set once, before the work starts.
//!
//! ```
//! use haarshift::progress::{Progress, ProgressTask, set_reporter};
//! use std::sync::atomic::{AtomicU64, Ordering};
//!
//! /// Counts every unit of every task.
//! struct Count(&'static AtomicU64);
//! struct CountTask(&'static AtomicU64);
//! impl Progress for Count {
//!     fn begin(&self, _what: &str, _len: u64) -> Box<dyn ProgressTask> {
//!         Box::new(CountTask(self.0))
//!     }
//! }
//! impl ProgressTask for CountTask {
//!     fn advance(&self, units: u64) {
//!         self.0.fetch_add(units, Ordering::Relaxed);
//!     }
//! }
//!
//! static DONE: AtomicU64 = AtomicU64::new(0);
//! assert!(set_reporter(Box::new(Count(&DONE))).is_ok());
//! // A second reporter is refused: the first one stays.
//! assert!(set_reporter(Box::new(Count(&DONE))).is_err());
//! ```
use std::sync::OnceLock;

/// Receives the tasks of long computations; implemented by the program that embeds the
/// library (the CLI draws `indicatif` bars).
pub trait Progress: Send + Sync {
    /// A task named `what` (for example "visibility (rays)") of `len` units begins; the
    /// returned task is advanced from worker threads and dropped when the work ends (or
    /// fails).
    fn begin(&self, what: &str, len: u64) -> Box<dyn ProgressTask>;
}

/// One running task: advanced concurrently, finished when dropped.
pub trait ProgressTask: Send + Sync {
    /// `units` more units are done.
    fn advance(&self, units: u64);
}

static REPORTER: OnceLock<Box<dyn Progress>> = OnceLock::new();

/// Installs the process's reporter. Only the first call succeeds; later ones hand their
/// reporter back, so that a library cannot take over a program's display.
///
/// ```
/// # use haarshift::progress::{Progress, ProgressTask, set_reporter};
/// struct Quiet;
/// struct QuietTask;
/// impl Progress for Quiet {
///     fn begin(&self, _: &str, _: u64) -> Box<dyn ProgressTask> { Box::new(QuietTask) }
/// }
/// impl ProgressTask for QuietTask {
///     fn advance(&self, _: u64) {}
/// }
/// assert!(set_reporter(Box::new(Quiet)).is_ok());
/// ```
pub fn set_reporter(reporter: Box<dyn Progress>) -> Result<(), Box<dyn Progress>> {
    REPORTER.set(reporter)
}

/// The task of one computation: nothing when progress was not asked for or no reporter is
/// installed. What a long computation of this crate or one built on it (the relighting)
/// reports through.
///
/// ```
/// use haarshift::progress::Task;
/// // Not asked for: nothing is reported, whatever reporter is installed.
/// let task = Task::begin(false, "a computation", 10);
/// task.advance(10);
/// ```
pub struct Task(Option<Box<dyn ProgressTask>>);

impl Task {
    /// Begins `what` of `len` units if `report` and a reporter is installed.
    pub fn begin(report: bool, what: &str, len: usize) -> Task {
        Task(
            REPORTER
                .get()
                .filter(|_| report)
                .map(|r| r.begin(what, len as u64)),
        )
    }

    /// `units` more units are done.
    pub fn advance(&self, units: usize) {
        if let Some(task) = &self.0 {
            task.advance(units as u64);
        }
    }
}
