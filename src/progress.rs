//! Progress bars (on a terminal only), progress reported to a caller, and stage timings.

use std::io::IsTerminal;
use std::sync::Arc;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Told the stage and the fraction of it done (0 at its start, 1 at its end).
pub type Observer = Arc<dyn Fn(&str, f64) + Send + Sync>;

/// Hands out progress bars (visible on a terminal unless quiet, hidden otherwise) and tells an
/// observer, if any, how far each stage is: the Python package's callback.
#[derive(Clone, Default)]
pub struct Progress {
    visible: bool,
    observer: Option<Observer>,
}

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Progress {{ visible: {}, observed: {} }}", self.visible, self.observer.is_some())
    }
}

impl Progress {
    pub fn new(quiet: bool) -> Self {
        Progress { visible: !quiet && std::io::stderr().is_terminal(), observer: None }
    }

    pub fn hidden() -> Self {
        Progress::default()
    }

    /// No bar; every stage and step reported to `observer`.
    pub fn observed(observer: Observer) -> Self {
        Progress { visible: false, observer: Some(observer) }
    }

    fn tell(&self, stage: &str, fraction: f64) {
        if let Some(observer) = &self.observer {
            observer(stage, fraction);
        }
    }

    /// Run `f` as stage `name`, timed in `timings`, and tell the observer its start and end.
    pub fn stage<T>(&self, timings: &mut Timings, name: &str, f: impl FnOnce() -> T) -> T {
        self.tell(name, 0.0);
        let out = timings.time(name, f);
        self.tell(name, 1.0);
        out
    }

    /// A bar counting the steps of stage `what`, as many as the last [`Bar::set`] says.
    pub fn bar(&self, what: &str) -> Bar<'_> {
        let bar = if self.visible {
            let style = ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {elapsed}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
            ProgressBar::new(0).with_style(style).with_message(what.to_owned())
        } else {
            ProgressBar::hidden()
        };
        Bar { bar, progress: self, what: what.to_owned() }
    }
}

/// A progress bar on a terminal and the observer's steps of one stage.
pub struct Bar<'a> {
    bar: ProgressBar,
    progress: &'a Progress,
    what: String,
}

impl Bar<'_> {
    /// `done` of `total` steps.
    pub fn set(&self, done: u64, total: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
        if total > 0 {
            self.progress.tell(&self.what, (done as f64 / total as f64).min(1.0));
        }
    }

    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}

/// Wall-clock time of each pipeline stage, in the order they ran.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    pub stages: Vec<StageTime>,
}

#[derive(Clone, Debug, Serialize)]
pub struct StageTime {
    pub stage: String,
    pub seconds: f64,
}

impl Timings {
    /// Run `f` as stage `name` and record how long it took.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        let seconds = start.elapsed().as_secs_f64();
        // A stage run again (the layers and the core in peeling rounds) adds up.
        match self.stages.iter_mut().find(|s| s.stage == name) {
            Some(stage) => stage.seconds += seconds,
            None => self.stages.push(StageTime { stage: name.to_owned(), seconds }),
        }
        out
    }

    pub fn total(&self) -> f64 {
        self.stages.iter().map(|s| s.seconds).sum()
    }
}

impl std::fmt::Display for Timings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for s in &self.stages {
            writeln!(f, "  {:<12} {:>9.3} s", s.stage, s.seconds)?;
        }
        write!(f, "  {:<12} {:>9.3} s", "total", self.total())
    }
}

/// Peak resident memory of this process so far (Linux `VmHWM`), or of a child process that
/// ended if larger (the core mesher's), in MiB; `None` elsewhere.
pub fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.max(children_peak_kib()) / 1024.0)
}

/// The largest resident set of the child processes that ended (the core mesher runs in one,
/// see `fill::isolate`), KiB.
fn children_peak_kib() -> f64 {
    // SAFETY: an all-zero rusage is valid, and getrusage only writes into it.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `usage` is valid for writes.
    if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) } != 0 {
        return 0.0;
    }
    usage.ru_maxrss as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timings_add_up_and_memory_is_read() {
        let mut t = Timings::default();
        let x = t.time("a", || 2 + 2);
        assert_eq!(x, 4);
        assert_eq!(t.stages.len(), 1);
        assert!(t.total() >= 0.0);
        if cfg!(target_os = "linux") {
            assert!(peak_memory_mib().is_some_and(|m| m > 1.0));
        }
    }
}
