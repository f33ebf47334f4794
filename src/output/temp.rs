//! The hidden temporary files outputs are written to: `.NAME.tmp.PID` beside `NAME` (or
//! `.NAME.tmp.PID.N`), renamed over `NAME` when complete.
//!
//! Every one this process is writing is listed in a process-wide registry, so that a program
//! stopped by a signal can remove them ([`remove_unfinished`]); the library installs no signal
//! handler itself. A file of this pattern left by a process that no longer exists (killed with
//! SIGKILL, or a crashed machine) is removed at the next write to the same `NAME`: on Linux a
//! process exists while `/proc/PID` does; elsewhere no such file is removed, since there is no
//! cheap and certain way to tell.

use std::ffi::{OsStr, OsString};
use std::fs::{self, File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::Error;

/// The temporary files of this process not yet renamed or removed, and whether
/// [`remove_unfinished`] has closed the registry.
struct Registry {
    paths: Vec<PathBuf>,
    closed: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    paths: Vec::new(),
    closed: false,
});

fn lock(registry: &Mutex<Registry>) -> MutexGuard<'_, Registry> {
    // The registry is consistent after every statement, so a panic elsewhere while it was
    // held leaves nothing half-done.
    registry.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Removes every temporary file this process is writing an output to, and makes every later
/// write through [`crate::output`] fail with [`Error::Cancelled`] before it creates a file: for
/// a program about to exit on a signal (the `gtsphere` command calls it on SIGINT and
/// SIGTERM). A write whose rename has already happened is complete and stays. Returns how many
/// files were removed.
pub fn remove_unfinished() -> usize {
    remove_registered(&REGISTRY)
}

fn remove_registered(registry: &Mutex<Registry>) -> usize {
    let mut reg = lock(registry);
    reg.closed = true;
    let mut removed = 0;
    for path in reg.paths.drain(..) {
        if fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The hidden sibling an output is written to; removed on drop unless renamed.
pub(super) struct TempFile {
    path: PathBuf,
    renamed: bool,
    registry: &'static Mutex<Registry>,
}

impl TempFile {
    /// Creates `.NAME.tmp.PID` next to `target` (`.NAME.tmp.PID.N` if that exists: another
    /// thread of this process writing the same name) and registers it. `create_new` never
    /// opens a file someone else is writing. Stale files of `target` are removed first.
    pub(super) fn create(target: &Path) -> Result<(TempFile, File), Error> {
        Self::create_in(&REGISTRY, target)
    }

    fn create_in(
        registry: &'static Mutex<Registry>,
        target: &Path,
    ) -> Result<(TempFile, File), Error> {
        let bad = |message: &str| Error::Image {
            path: target.display().to_string(),
            message: message.to_string(),
        };
        let name = target.file_name().ok_or_else(|| bad("not a file name"))?;
        let dir = target.parent().unwrap_or(Path::new(""));
        remove_stale(dir, name);
        let pid = std::process::id();
        for attempt in 0..1000u32 {
            let path = dir.join(temp_name(name, pid, attempt));
            // Created and registered under the lock, so that `remove_unfinished` sees every
            // file that exists.
            let mut reg = lock(registry);
            if reg.closed {
                return Err(Error::Cancelled);
            }
            match OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(file) => {
                    reg.paths.push(path.clone());
                    let temp = TempFile {
                        path,
                        renamed: false,
                        registry,
                    };
                    return Ok((temp, file));
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(source) => {
                    return Err(Error::Io {
                        path: target.display().to_string(),
                        source,
                    })
                }
            }
        }
        Err(bad("cannot find a free temporary file name next to it"))
    }

    /// Renames the (closed) file over `target`, unless [`remove_unfinished`] has removed it:
    /// then [`Error::Cancelled`] and `target` is untouched.
    pub(super) fn rename_to(&mut self, target: &Path) -> Result<(), Error> {
        pause_for_test();
        let mut reg = lock(self.registry);
        let Some(i) = reg.paths.iter().position(|p| *p == self.path) else {
            return Err(Error::Cancelled);
        };
        fs::rename(&self.path, target).map_err(|source| Error::Io {
            path: target.display().to_string(),
            source,
        })?;
        reg.paths.swap_remove(i);
        self.renamed = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.renamed {
            let mut reg = lock(self.registry);
            reg.paths.retain(|p| *p != self.path);
            // The writer has closed the file by now. Nothing to report on failure: the
            // caller already has the error that brought us here.
            let _ = fs::remove_file(&self.path);
        }
    }
}

/// `.NAME.tmp.PID`, or `.NAME.tmp.PID.N` for `attempt` N > 0.
fn temp_name(name: &OsStr, pid: u32, attempt: u32) -> OsString {
    let mut temp = OsString::from(".");
    temp.push(name);
    temp.push(format!(".tmp.{pid}"));
    if attempt > 0 {
        temp.push(format!(".{attempt}"));
    }
    temp
}

/// The process id in `file`, if it is exactly `.NAME.tmp.PID` or `.NAME.tmp.PID.N` for this
/// `name` (decimal numbers without sign or leading zero).
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
fn temp_owner(file: &[u8], name: &[u8]) -> Option<u32> {
    let rest = file.strip_prefix(b".")?.strip_prefix(name)?;
    let rest = rest.strip_prefix(b".tmp.")?;
    let number = |s: &[u8]| {
        let canonical = !s.is_empty() && s[0] != b'0' && s.iter().all(u8::is_ascii_digit);
        canonical
            .then(|| std::str::from_utf8(s).ok()?.parse::<u32>().ok())
            .flatten()
    };
    match rest.iter().position(|&b| b == b'.') {
        None => number(rest),
        Some(dot) => {
            number(&rest[dot + 1..])?;
            number(&rest[..dot])
        }
    }
}

/// Removes the temporary files of `name` in `dir` whose process no longer exists; any
/// failure (an unreadable directory, a file removed meanwhile) is left to the write itself.
#[cfg(target_os = "linux")]
fn remove_stale(dir: &Path, name: &OsStr) {
    use std::os::unix::ffi::OsStrExt;
    let proc = Path::new("/proc");
    // Without a mounted /proc no process can be told to be gone.
    if !proc.join("self").exists() {
        return;
    }
    let own = std::process::id();
    let listed = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let Ok(entries) = fs::read_dir(listed) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(pid) = temp_owner(file.as_bytes(), name.as_bytes()) else {
            continue;
        };
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if pid != own && is_file && !proc.join(pid.to_string()).exists() {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Elsewhere a stale file is left alone: whether its process exists is not known for sure.
#[cfg(not(target_os = "linux"))]
fn remove_stale(_dir: &Path, _name: &OsStr) {}

/// A test hook of the `gtsphere` command's tests: when `GTSPHERE_TEST_PAUSE_BEFORE_RENAME`
/// names a file, it is created once the temporary file is complete, and the write waits
/// (at most a minute) while it exists, so a test can signal the process at that moment.
fn pause_for_test() {
    let Some(flag) = std::env::var_os("GTSPHERE_TEST_PAUSE_BEFORE_RENAME") else {
        return;
    };
    if File::create(&flag).is_err() {
        return;
    }
    let start = std::time::Instant::now();
    while Path::new(&flag).exists() && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temp_owner_takes_exactly_the_pattern_of_the_name() {
        let own = |f: &str| temp_owner(f.as_bytes(), b"out.png");
        assert_eq!(own(".out.png.tmp.123"), Some(123));
        assert_eq!(own(".out.png.tmp.123.4"), Some(123));
        for other in [
            "out.png",
            ".out.png.tmp.",
            ".out.png.tmp.12x",
            ".out.png.tmp.+12",
            ".out.png.tmp.012",
            ".out.png.tmp.12.",
            ".out.png.tmp.12.0",
            ".out.png.tmp.12.3.4",
            ".out.png.tmp.99999999999",
            ".out.pngx.tmp.12",
            ".xout.png.tmp.12",
            "..out.png.tmp.12",
            ".out.png.tmp.12.part",
        ] {
            assert_eq!(own(other), None, "{other}");
        }
    }

    #[test]
    fn names_written_are_names_recognised() {
        let name = OsStr::new("a b.exr");
        for attempt in [0, 1, 999] {
            let file = temp_name(name, 4321, attempt);
            assert_eq!(
                temp_owner(file.as_encoded_bytes(), name.as_encoded_bytes()),
                Some(4321)
            );
        }
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn stale_files_of_gone_processes_go_and_live_ones_stay() {
        let dir = std::env::temp_dir().join(format!("gtsphere-stale-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let max: u64 = fs::read_to_string("/proc/sys/kernel/pid_max")
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let gone = max + 1;
        let own = std::process::id();
        let stale = [format!(".f.png.tmp.{gone}"), format!(".f.png.tmp.{gone}.3")];
        let kept = [
            format!(".f.png.tmp.{own}"),
            format!(".g.png.tmp.{gone}"),
            format!(".f.png.tmp.{gone}.x"),
        ];
        for f in stale.iter().chain(&kept) {
            fs::write(dir.join(f), b"x").unwrap();
        }
        remove_stale(&dir, OsStr::new("f.png"));
        for f in &stale {
            assert!(!dir.join(f).exists(), "{f}");
        }
        for f in &kept {
            assert!(dir.join(f).exists(), "{f}");
        }
        fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn remove_unfinished_leaves_no_file_and_stops_later_writes() {
        // A registry of its own: closing the process's one would stop the other tests' writes.
        static OWN: Mutex<Registry> = Mutex::new(Registry {
            paths: Vec::new(),
            closed: false,
        });
        let dir = std::env::temp_dir().join(format!("gtsphere-unfinished-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let target = dir.join("a.png");
        let (mut temp, file) = TempFile::create_in(&OWN, &target).unwrap();
        drop(file);
        assert!(temp.path.exists());
        assert_eq!(remove_registered(&OWN), 1);
        assert!(!temp.path.exists());
        assert!(matches!(temp.rename_to(&target), Err(Error::Cancelled)));
        assert!(!target.exists());
        assert!(matches!(
            TempFile::create_in(&OWN, &target),
            Err(Error::Cancelled)
        ));
        drop(temp);
        assert_eq!(fs::read_dir(&dir).unwrap().count(), 0);
        fs::remove_dir_all(&dir).unwrap();
    }
}
