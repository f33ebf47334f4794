//! `--threads N` of the benchmarks: at most [`limits::max_threads`], with a warning on
//! stderr when that lowers it (`render` says it in its own messages, under `--quiet`).

use gtsphere::render::limits;

/// `n` threads, or [`limits::max_threads`] and a warning on stderr if that is fewer.
pub fn capped(asked: usize) -> usize {
    let (n, why) = limits::capped_threads(asked);
    if let Some(w) = why {
        eprintln!("warning: --threads {asked} {w}");
    }
    n
}
