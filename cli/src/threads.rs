//! Thread options (`--threads N`, `--read-threads N`): at most [`limits::max_threads`], with
//! a warning when that lowers them. `render` says the warning in its own messages (under
//! `--quiet`); the benchmarks print it on stderr.

use gtsphere::render::limits;

/// `asked` threads of option `flag`, or [`limits::max_threads`] and the warning to give if
/// that is fewer.
pub fn cap(flag: &str, asked: usize) -> (usize, Option<String>) {
    let (n, why) = limits::capped_threads(asked);
    (n, why.map(|w| format!("warning: {flag} {asked} {w}")))
}

/// `--threads asked` of a benchmark, [`cap`]ped, the warning on stderr.
pub fn capped(asked: usize) -> usize {
    let (n, warning) = cap("--threads", asked);
    if let Some(w) = warning {
        eprintln!("{w}");
    }
    n
}
