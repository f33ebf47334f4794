//! Long work on worker threads with the GIL released (`render`, `occlusion`): the `threads`
//! keyword, and the watch that lets Python run its signal handlers (Ctrl-C) and a progress
//! callback meanwhile, cancelling the work when either raises.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use gtsphere::render::{limits, Cancel, Progress};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Units of work done (tiles, spheres), for the progress callback, and the cancel flag.
#[derive(Default)]
pub struct Watch {
    done: AtomicU64,
    total: AtomicU64,
    cancel: Cancel,
}

impl Progress for Watch {
    fn start(&self, units: u64) {
        self.total.store(units, Ordering::Relaxed);
    }
    fn tile_done(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }
}

/// A pool of `threads` worker threads (None: one per core). 0 raises ValueError; more than
/// a few per core only share the cores, so they are lowered to `limits::max_threads` with a
/// RuntimeWarning.
pub fn pool(py: Python<'_>, threads: Option<usize>) -> PyResult<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err(PyValueError::new_err("threads must be at least 1"));
    }
    let threads = match threads {
        Some(asked) => {
            let (n, why) = limits::capped_threads(asked);
            if let Some(w) = why {
                let warn = py.import("warnings")?;
                let category = py.get_type::<pyo3::exceptions::PyRuntimeWarning>();
                warn.call_method1("warn", (format!("threads={asked} {w}"), &category, 1))?;
            }
            Some(n)
        }
        None => None,
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| crate::Error::new_err(format!("cannot start worker threads: {e}")))
}

/// Runs `job` on `pool` with the GIL released. This thread wakes every 50 ms, takes the GIL
/// to let Python run its signal handlers (Ctrl-C) and `progress(done, total)` (when more is
/// done), and cancels the job through the watch if either raised; that exception is then
/// returned. `what` names the work in the message of a panic.
pub fn watched<T: Send>(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    progress: Option<&Py<PyAny>>,
    what: &str,
    job: impl FnOnce(&Watch) -> T + Send,
) -> PyResult<T> {
    let watch = Watch::default();
    let mut reported = u64::MAX;
    let (result, interrupted) = py.detach(|| {
        let waiting = std::thread::current();
        std::thread::scope(|s| {
            let worker = s.spawn(|| {
                let r = pool.install(|| job(&watch));
                waiting.unpark(); // return at once, not at the next 50 ms tick
                r
            });
            let mut interrupted: Option<PyErr> = None;
            loop {
                let finished = worker.is_finished();
                if interrupted.is_none() {
                    let step = Python::attach(|py| -> PyResult<()> {
                        py.check_signals()?;
                        if let Some(cb) = progress {
                            let done = watch.done.load(Ordering::Relaxed);
                            let total = watch.total.load(Ordering::Relaxed);
                            if done != reported && total > 0 {
                                reported = done;
                                cb.call1(py, (done, total))?;
                            }
                        }
                        Ok(())
                    });
                    if let Err(e) = step {
                        watch.cancel.cancel();
                        interrupted = Some(e);
                    }
                }
                if finished {
                    break;
                }
                std::thread::park_timeout(Duration::from_millis(50));
            }
            (worker.join(), interrupted)
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    result.map_err(|_| crate::Error::new_err(format!("{what} panicked (a bug; please report it)")))
}
