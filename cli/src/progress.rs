//! Progress bars on standard error, drawn only when it is a terminal: the CLI's own loops use
//! [`progress_bar`], and the library's long computations report through [`TerminalProgress`].

use std::io::IsTerminal;

use haarshift::progress::{Progress, ProgressTask};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};

/// A progress bar on stderr when stderr is a terminal; hidden otherwise.
pub fn progress_bar(len: usize) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed} {msg}") {
        bar.set_style(style);
    }
    bar
}

/// Draws each of the library's tasks (rays, shadow maps, occlusion fields) as a bar of its
/// own, below any bar of the command's, cleared when the task ends.
pub struct TerminalProgress(MultiProgress);

impl TerminalProgress {
    /// Installs the reporter for the library when stderr is a terminal.
    pub fn install() {
        if std::io::stderr().is_terminal() {
            // Only this call installs a reporter, so it cannot be refused.
            let _ =
                haarshift::progress::set_reporter(Box::new(TerminalProgress(MultiProgress::new())));
        }
    }
}

/// One library task's bar.
struct TaskBar(ProgressBar);

impl Progress for TerminalProgress {
    fn begin(&self, what: &str, len: u64) -> Box<dyn ProgressTask> {
        let bar = self
            .0
            .add(ProgressBar::new(len).with_message(what.to_string()));
        if let Ok(style) = ProgressStyle::with_template("{msg} {wide_bar} {pos}/{len}, eta {eta}") {
            bar.set_style(style);
        }
        Box::new(TaskBar(bar))
    }
}

impl ProgressTask for TaskBar {
    fn advance(&self, units: u64) {
        self.0.inc(units);
    }
}

impl Drop for TaskBar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}
