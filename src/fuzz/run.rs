//! Running the `blmesh` binary on one input with a time and an address-space limit, and
//! judging the run: exit 0, or a clean rejection (1, or 2 for usage) naming where the problem
//! is; never a panic (101), a signal, a hang or an allocation beyond the limit.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// How long and how large one run may get.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    pub timeout: Duration,
    /// Address space (RLIMIT_AS): an allocation beyond fails, which Rust reports and aborts on.
    pub memory_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { timeout: Duration::from_secs(60), memory_bytes: 4 << 30 }
    }
}

/// How a run ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Exit {
    Code(i32),
    Signal(i32),
    Timeout,
}

#[derive(Clone, Debug)]
pub struct Outcome {
    pub exit: Exit,
    pub seconds: f64,
    /// Peak resident memory (Linux reports it in KiB).
    pub max_rss_mib: f64,
    pub stderr: String,
}

/// The judgement of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Verdict {
    Accepted,
    /// Exit 1 or 2 with a message that says where the problem is.
    Rejected,
    /// Exit 1 or 2 whose message names no place in the input.
    RejectedUnlocated,
    /// The mesh was made but failed its own check: not a crash, but a finding.
    SelfCheckFailed,
    Panic,
    OutOfMemory,
    Timeout,
    /// Any other exit code or a signal.
    Crash,
}

impl Verdict {
    /// Whether the run is a failure of blmesh (not of its input).
    pub fn is_failure(self) -> bool {
        !matches!(
            self,
            Verdict::Accepted | Verdict::Rejected | Verdict::RejectedUnlocated | Verdict::SelfCheckFailed
        )
    }
}

/// Words by which a message names a place: in the file (line, byte), in the surface (a
/// triangle, vertex, edge, shell, patch, its bounding box), a parameter, a directory, or the
/// file as a whole for problems of the whole file (empty, of an unknown type, without cells).
const PLACES: [&str; 16] = [
    "line ",
    "byte ",
    "triangle",
    "vertex",
    "vertices",
    "edge",
    "shell",
    "patch",
    "bounding box",
    "parameter",
    "empty",
    "unknown file type",
    "no triangles",
    "too short",
    "directory",
    "the file",
];

impl Outcome {
    pub fn verdict(&self, limits: &Limits) -> Verdict {
        let out_of_memory = self.stderr.contains("memory allocation of")
            || self.max_rss_mib * (1 << 20) as f64 > limits.memory_bytes as f64;
        match self.exit {
            _ if out_of_memory => Verdict::OutOfMemory,
            Exit::Timeout => Verdict::Timeout,
            _ if self.stderr.contains("panicked") => Verdict::Panic,
            Exit::Code(0) => Verdict::Accepted,
            Exit::Code(1) if self.stderr.contains("failed its own check") => Verdict::SelfCheckFailed,
            Exit::Code(1 | 2) if self.names_a_place() => Verdict::Rejected,
            Exit::Code(1 | 2) => Verdict::RejectedUnlocated,
            Exit::Code(101) => Verdict::Panic,
            Exit::Code(_) | Exit::Signal(_) => Verdict::Crash,
        }
    }

    fn names_a_place(&self) -> bool {
        let text = self.stderr.to_lowercase();
        PLACES.iter().any(|p| text.contains(p))
    }

    /// The first line of the message, for the record.
    pub fn first_line(&self) -> &str {
        self.stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("")
    }
}

/// Run `binary args` with the limits; stdout is discarded, stderr kept.
#[cfg(unix)]
pub fn run(binary: &Path, args: &[&OsStr], limits: &Limits) -> std::io::Result<Outcome> {
    use std::os::unix::process::CommandExt;
    let stderr_file = tempfile::tempfile()?;
    let memory = limits.memory_bytes;
    let mut command = Command::new(binary);
    command.args(args).stdin(Stdio::null()).stdout(Stdio::null()).stderr(stderr_file.try_clone()?);
    // SAFETY: only setrlimit (async-signal-safe) runs between fork and exec.
    unsafe {
        command.pre_exec(move || {
            let limit = libc::rlimit { rlim_cur: memory, rlim_max: memory };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let start = Instant::now();
    let child = command.spawn()?;
    let pid = child.id() as libc::pid_t;
    let (status, usage, timed_out) = wait_with_timeout(pid, limits.timeout);
    let seconds = start.elapsed().as_secs_f64();
    let exit = if timed_out {
        Exit::Timeout
    } else if libc::WIFEXITED(status) {
        Exit::Code(libc::WEXITSTATUS(status))
    } else {
        Exit::Signal(libc::WTERMSIG(status))
    };
    let stderr = read_all(stderr_file)?;
    Ok(Outcome { exit, seconds, max_rss_mib: usage.ru_maxrss as f64 / 1024.0, stderr })
}

/// Reap `pid`, killing it after `timeout`: (wait status, resource usage, whether it timed out).
#[cfg(unix)]
fn wait_with_timeout(pid: libc::pid_t, timeout: Duration) -> (i32, libc::rusage, bool) {
    let start = Instant::now();
    let mut status = 0;
    // SAFETY: rusage is plain data; wait4 fills it.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let mut timed_out = false;
    loop {
        // SAFETY: waits for our own child only.
        let r = unsafe { libc::wait4(pid, &mut status, libc::WNOHANG, &mut usage) };
        if r == pid || r < 0 {
            return (status, usage, timed_out);
        }
        if !timed_out && start.elapsed() > timeout {
            // SAFETY: the child is not reaped yet, so the pid is still ours.
            unsafe { libc::kill(pid, libc::SIGKILL) };
            timed_out = true;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn read_all(mut file: std::fs::File) -> std::io::Result<String> {
    use std::io::{Read, Seek};
    file.rewind()?;
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes)?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(exit: Exit, stderr: &str) -> Outcome {
        Outcome { exit, seconds: 0.1, max_rss_mib: 10.0, stderr: stderr.into() }
    }

    #[test]
    fn verdicts() {
        let l = Limits::default();
        assert_eq!(outcome(Exit::Code(0), "").verdict(&l), Verdict::Accepted);
        assert_eq!(outcome(Exit::Code(1), "error: x.obj: line 3: bad").verdict(&l), Verdict::Rejected);
        assert_eq!(outcome(Exit::Code(1), "error: failed").verdict(&l), Verdict::RejectedUnlocated);
        let check = "error: the mesh failed its own check (a bug in blmesh; please report it):\ntriangle";
        assert_eq!(outcome(Exit::Code(1), check).verdict(&l), Verdict::SelfCheckFailed);
        let panic = "thread 'main' panicked at src/x.rs:1:1:\ncapacity overflow";
        assert_eq!(outcome(Exit::Code(101), panic).verdict(&l), Verdict::Panic);
        assert_eq!(
            outcome(Exit::Signal(6), "memory allocation of 8 bytes failed").verdict(&l),
            Verdict::OutOfMemory
        );
        assert_eq!(outcome(Exit::Signal(11), "").verdict(&l), Verdict::Crash);
        assert_eq!(outcome(Exit::Timeout, "").verdict(&l), Verdict::Timeout);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_run_is_timed_out_and_measured() {
        let limits = Limits { timeout: Duration::from_millis(200), ..Limits::default() };
        let o = run(Path::new("sleep"), &[OsStr::new("5")], &limits).unwrap();
        assert_eq!(o.exit, Exit::Timeout);
        assert!(o.seconds < 4.0, "{}", o.seconds);
        let o =
            run(Path::new("sh"), &[OsStr::new("-c"), OsStr::new("echo boom >&2; exit 3")], &limits).unwrap();
        assert_eq!((o.exit, o.stderr.as_str()), (Exit::Code(3), "boom\n"));
        assert!(o.max_rss_mib > 0.0);
    }
}
