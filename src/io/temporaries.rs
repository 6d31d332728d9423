//! The temporaries that atomic writes have open, so that an interrupted run
//! ([`crate::interrupt`]) can remove them before it exits: a signal ends the process without
//! running the destructors that would.
//!
//! The list is locked while a temporary is created and registered, and while it is renamed over
//! its output and deregistered; the interrupt holds the same lock until the process exits, so
//! it sees every temporary either still registered or already an output.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    // A panic elsewhere while locked leaves the list as valid as before.
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A registered temporary; deregistered when dropped (its owner removes it) or finished.
#[must_use]
pub(crate) struct Registration {
    path: PathBuf,
}

/// Create a temporary with `create` and register the path `path_of` gives, as one step. Bind
/// the registration first, so that it is dropped after the temporary (which removes itself).
pub(crate) fn create<T>(
    create: impl FnOnce() -> std::io::Result<T>,
    path_of: impl FnOnce(&T) -> &Path,
) -> std::io::Result<(Registration, T)> {
    let mut list = live();
    let made = create()?;
    let path = path_of(&made).to_owned();
    list.push(path.clone());
    Ok((Registration { path }, made))
}

impl Registration {
    /// Run `finish` (the rename that turns the temporary into an output) and deregister, as one
    /// step.
    pub(crate) fn finish<R>(self, finish: impl FnOnce() -> R) -> R {
        let mut list = live();
        let result = finish();
        remove_entry(&mut list, &self.path);
        std::mem::forget(self);
        result
    }
}

impl Drop for Registration {
    fn drop(&mut self) {
        remove_entry(&mut live(), &self.path);
    }
}

fn remove_entry(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = list.iter().rposition(|p| p == path) {
        list.swap_remove(i);
    }
}

/// Remove every registered temporary (files and directories) and keep the list locked, so that
/// no new one is made and none is renamed into place until the process exits.
pub(crate) fn remove_all_and_hold() -> MutexGuard<'static, Vec<PathBuf>> {
    let mut list = live();
    for path in list.drain(..) {
        let _ = if path.is_dir() { std::fs::remove_dir_all(&path) } else { std::fs::remove_file(&path) };
    }
    list
}

#[cfg(test)]
pub(crate) fn registered() -> Vec<PathBuf> {
    live().clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registrations_end_when_dropped_or_finished() {
        let dir = tempfile::tempdir().unwrap();
        let (reg, file) = create(|| tempfile::NamedTempFile::new_in(dir.path()), |f| f.path()).unwrap();
        assert!(registered().contains(&file.path().to_owned()));
        let path = file.path().to_owned();
        drop(reg);
        assert!(!registered().contains(&path));
        let (reg, file) = create(|| tempfile::NamedTempFile::new_in(dir.path()), |f| f.path()).unwrap();
        let path = file.path().to_owned();
        let out = dir.path().join("out");
        reg.finish(|| file.persist(&out)).unwrap();
        assert!(!registered().contains(&path) && out.exists());
    }
}
