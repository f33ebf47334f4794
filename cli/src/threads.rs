//! Thread options (`--threads N`, `--read-threads N`): at most [`limits::max_threads`], with
//! a warning when that lowers them. `render` says the warning in its own messages (under
//! `--quiet`); the benchmarks print it on stderr.

use gtsphere::error::Error;
use gtsphere::render::limits;

/// `asked` threads of option `flag`, or [`limits::max_threads`] and the warning to give if
/// that is fewer.
pub fn cap(flag: &str, asked: usize) -> (usize, Option<String>) {
    let (n, why) = limits::capped_threads(asked);
    (n, why.map(|w| format!("warning: {flag} {asked} {w}")))
}

/// The `--threads` option of a command: `None` (one per core) or at least 1, [`cap`]ped, with
/// the warning to give if it was lowered.
pub fn option(asked: Option<usize>) -> Result<(Option<usize>, Option<String>), Error> {
    match asked {
        Some(0) => Err(Error::Other("--threads must be at least 1".into())),
        Some(asked) => {
            let (n, warning) = cap("--threads", asked);
            Ok((Some(n), warning))
        }
        None => Ok((None, None)),
    }
}

/// `--threads asked` of a benchmark, [`cap`]ped, the warning on stderr.
pub fn capped(asked: usize) -> usize {
    let (n, warning) = cap("--threads", asked);
    if let Some(w) = warning {
        eprintln!("{w}");
    }
    n
}
