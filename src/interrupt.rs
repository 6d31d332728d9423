//! SIGINT and SIGTERM: remove the temporaries of the atomic writes under way, say so, and exit
//! with 128 + the signal number (130, 143), as a shell reports a process the signal ended.
//!
//! The two signals are blocked in every thread (threads inherit the mask of the thread that
//! starts them, so [`install`] must run before any other thread starts) and taken by one thread
//! that waits for them: the cleanup runs as ordinary code, not in a signal handler.

/// Take SIGINT and SIGTERM from now on (Unix; elsewhere the default behaviour stays).
pub fn install() {
    #[cfg(unix)]
    unix::install();
}

#[cfg(unix)]
mod unix {
    pub fn install() {
        // SAFETY: plain libc calls on a signal set that lives on this stack.
        let set = unsafe {
            let mut set: libc::sigset_t = std::mem::zeroed();
            libc::sigemptyset(&mut set);
            libc::sigaddset(&mut set, libc::SIGINT);
            libc::sigaddset(&mut set, libc::SIGTERM);
            if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
                return;
            }
            set
        };
        let waiter = std::thread::Builder::new().name("signals".into()).spawn(move || wait(set));
        if waiter.is_err() {
            // No thread to take them: let the signals end the process as before.
            // SAFETY: as above.
            unsafe { libc::pthread_sigmask(libc::SIG_UNBLOCK, &set, std::ptr::null_mut()) };
        }
    }

    fn wait(set: libc::sigset_t) {
        let mut signal = 0;
        // SAFETY: `set` and `signal` are valid for the call.
        while unsafe { libc::sigwait(&set, &mut signal) } != 0 {}
        let _held = crate::io::remove_temporaries_and_hold();
        let name = if signal == libc::SIGINT { "SIGINT" } else { "SIGTERM" };
        eprintln!("error: interrupted by {name}; outputs not complete yet were not written");
        // SAFETY: ends the process at once; the other threads may be anywhere, so no exit
        // handlers or destructors run.
        unsafe { libc::_exit(128 + signal) };
    }
}
