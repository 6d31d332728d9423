//! Progress bars (on a terminal only) and stage timings.

use std::io::IsTerminal;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Hands out progress bars: visible on a terminal unless quiet, hidden otherwise.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    visible: bool,
}

impl Progress {
    pub fn new(quiet: bool) -> Self {
        Progress { visible: !quiet && std::io::stderr().is_terminal() }
    }

    pub fn hidden() -> Self {
        Progress { visible: false }
    }

    /// A bar counting `len` steps of work named `what`.
    pub fn bar(&self, len: u64, what: &str) -> ProgressBar {
        if !self.visible {
            return ProgressBar::hidden();
        }
        let style = ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        ProgressBar::new(len).with_style(style).with_message(what.to_owned())
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
