//! Running a piece of work in a forked child process, so that an `abort` or a crash in it (a
//! C++ library's failed assertion) ends the child and becomes an error here, not the end of
//! the program. The child sends its answer back as bytes through a pipe.

use std::ffi::c_int;
use std::io::Read;
use std::os::fd::FromRawFd;

/// How a child ended without an answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChildEnd {
    /// Killed by this signal (6: it aborted).
    Signal(i32),
    /// Exited with this status before its whole answer was read.
    Exit(i32),
    /// No child could be started (no pipe or no fork): the work did not run.
    NotStarted,
}

/// Run `work` in a forked child and return the bytes it produced.
///
/// The child runs only `work`, writes its bytes and leaves with `_exit` (no destructor, no
/// flush of this process's buffers). It first closes every descriptor it inherited but the
/// standard three and its pipe: an inherited copy would keep the parent's files, locks and
/// pipes alive for as long as the child runs (HDF5's lock on a CGNS file another thread was
/// writing made that file unreadable until the child ended). `work` must not need the other
/// threads of this process: they do not exist in the child. glibc's `malloc` stays usable
/// after `fork`.
pub fn in_child(work: impl FnOnce() -> Vec<u8>) -> Result<Vec<u8>, ChildEnd> {
    let mut fds = [0 as c_int; 2];
    // SAFETY: `fds` has room for the two descriptors pipe() writes.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return Err(ChildEnd::NotStarted);
    }
    let (read_end, write_end) = (fds[0], fds[1]);
    // SAFETY: see the function's documentation; the child never returns from this block.
    let pid = unsafe { libc::fork() };
    if pid == 0 {
        // SAFETY: the child's own descriptors; `bytes` outlives the writes from it.
        unsafe {
            let write_end = keep_only_standard_descriptors_and(write_end);
            let bytes = work();
            let mut written = 0;
            while written < bytes.len() {
                let n = libc::write(write_end, bytes[written..].as_ptr().cast(), bytes.len() - written);
                if n <= 0 {
                    libc::_exit(2);
                }
                written += n as usize;
            }
            libc::_exit(0);
        }
    }
    // SAFETY: the parent's copy of the write end is not used again, closed once.
    unsafe { libc::close(write_end) };
    if pid < 0 {
        // SAFETY: the read end is ours and closed once.
        unsafe { libc::close(read_end) };
        return Err(ChildEnd::NotStarted);
    }
    // SAFETY: `read_end` is an open descriptor that this File now owns (and closes).
    let mut pipe = unsafe { std::fs::File::from_raw_fd(read_end) };
    let mut bytes = Vec::new();
    // Read before waiting: a child blocked on a full pipe would never end.
    let read = pipe.read_to_end(&mut bytes);
    let mut status: c_int = 0;
    // SAFETY: `pid` is our child; `status` is valid for writes.
    unsafe { libc::waitpid(pid, &mut status, 0) };
    if libc::WIFSIGNALED(status) {
        return Err(ChildEnd::Signal(libc::WTERMSIG(status)));
    }
    let exit = if libc::WIFEXITED(status) { libc::WEXITSTATUS(status) } else { -1 };
    match read {
        Ok(_) if exit == 0 => Ok(bytes),
        _ => Err(ChildEnd::Exit(exit)),
    }
}

/// In a just-forked child: move `pipe` to descriptor 3 and close every descriptor above it.
/// Returns the pipe's new descriptor. Only async-signal-safe calls (the other threads' locks
/// may be held).
unsafe fn keep_only_standard_descriptors_and(pipe: c_int) -> c_int {
    const KEPT: c_int = 3;
    if pipe != KEPT && (libc::dup2(pipe, KEPT) != KEPT || libc::close(pipe) != 0) {
        libc::_exit(2);
    }
    let first = (KEPT + 1) as libc::c_uint;
    if libc::syscall(libc::SYS_close_range, first, libc::c_uint::MAX, 0 as libc::c_uint) != 0 {
        // No close_range (Linux before 5.9): close them one by one up to the limit.
        let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        let end = if libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) == 0 {
            limit.rlim_cur.min(1 << 20) as c_int
        } else {
            1 << 16
        };
        for fd in KEPT + 1..end {
            libc::close(fd);
        }
    }
    KEPT
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_child_answers_with_its_bytes() {
        let big: Vec<u8> = (0..1_000_000u32).map(|i| (i % 251) as u8).collect();
        let expected = big.clone();
        assert_eq!(in_child(move || big), Ok(expected));
    }

    #[test]
    fn a_child_that_aborts_is_an_error_not_the_end() {
        assert_eq!(in_child(|| std::process::abort()), Err(ChildEnd::Signal(libc::SIGABRT)));
    }

    /// The (device, inode) of the file open as `fd`, if it is open.
    fn file_identity(fd: c_int) -> Option<(u64, u64)> {
        // SAFETY: fstat writes into `stat` only.
        let mut stat: libc::stat = unsafe { std::mem::zeroed() };
        (unsafe { libc::fstat(fd, &mut stat) } == 0).then_some((stat.st_dev, stat.st_ino))
    }

    #[test]
    fn the_child_holds_none_of_the_parents_files() {
        let open = std::fs::File::open("Cargo.toml").unwrap();
        let fd = std::os::fd::AsRawFd::as_raw_fd(&open);
        let parent = file_identity(fd);
        assert!(parent.is_some());
        let child = in_child(move || vec![(file_identity(fd) == parent) as u8]);
        assert_eq!(child, Ok(vec![0]), "the child still had Cargo.toml open as {fd}");
        assert_eq!(file_identity(fd), parent, "the parent's copy stays open");
    }

    #[test]
    fn a_child_that_exits_early_is_an_error() {
        // SAFETY: _exit ends the child at once.
        assert_eq!(in_child(|| unsafe { libc::_exit(3) }), Err(ChildEnd::Exit(3)));
    }
}
