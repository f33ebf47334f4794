//! The progress of `gtsphere render`'s tile loop: a bar on a terminal, lines in a log.

use gtsphere::render::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::atomic::Ordering;

/// The progress of the tile loop, unless `--quiet`: a bar when stderr is a terminal, and
/// otherwise (a batch job's log, a pipe) a line when the render starts and one every
/// [`LINE_SECONDS`] while it runs.
pub(crate) struct TileBar {
    bar: ProgressBar,
    lines: Option<Lines>,
    words: Words,
}

/// How the progress is worded: what is counted, and the verb while and after.
#[derive(Clone, Copy)]
pub(crate) struct Words {
    pub unit: &'static str,
    pub doing: &'static str,
    pub done: &'static str,
}

/// The render's tiles.
const TILES: Words = Words {
    unit: "tiles",
    doing: "rendering",
    done: "rendered",
};

/// Seconds between progress lines when stderr is not a terminal.
const LINE_SECONDS: u64 = 5;

struct Lines {
    start: std::time::Instant,
    total: std::sync::atomic::AtomicU64,
    done: std::sync::atomic::AtomicU64,
    /// Milliseconds since `start` after which the next line is due.
    next_ms: std::sync::atomic::AtomicU64,
}

impl TileBar {
    pub(super) fn new(show: bool) -> Self {
        Self::counting(show, TILES)
    }

    /// A progress counting what `words` say.
    pub(crate) fn counting(show: bool, words: Words) -> Self {
        use std::io::IsTerminal;
        if !show {
            return TileBar {
                bar: ProgressBar::hidden(),
                lines: None,
                words,
            };
        }
        if !std::io::stderr().is_terminal() {
            return TileBar {
                bar: ProgressBar::hidden(),
                lines: Some(Lines {
                    start: std::time::Instant::now(),
                    total: 0.into(),
                    done: 0.into(),
                    next_ms: (LINE_SECONDS * 1000).into(),
                }),
                words,
            };
        }
        let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        pb.set_style(
            ProgressStyle::with_template(&format!(
                "{{elapsed_precise}} [{{bar:40}}] {{percent:>3}}% {}, ETA {{eta}}",
                words.unit
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        TileBar {
            bar: pb,
            lines: None,
            words,
        }
    }
}

impl Progress for TileBar {
    fn start(&self, tiles: u64) {
        self.bar.set_length(tiles);
        if let Some(l) = &self.lines {
            l.total.store(tiles, Ordering::Relaxed);
            eprintln!("{} {tiles} {}", self.words.doing, self.words.unit);
        }
    }
    fn tile_done(&self) {
        self.bar.inc(1);
        if let Some(l) = &self.lines {
            let done = l.done.fetch_add(1, Ordering::Relaxed) + 1;
            let ms = l.start.elapsed().as_millis() as u64;
            let due = l.next_ms.load(Ordering::Relaxed);
            // One thread prints each line: the one that moves the next one on.
            if ms >= due
                && l.next_ms
                    .compare_exchange(
                        due,
                        ms + LINE_SECONDS * 1000,
                        Ordering::Relaxed,
                        Ordering::Relaxed,
                    )
                    .is_ok()
            {
                let total = l.total.load(Ordering::Relaxed).max(1);
                eprintln!(
                    "{} {done} of {total} {} ({:.0} %), {:.0} s",
                    self.words.done,
                    self.words.unit,
                    100.0 * done as f64 / total as f64,
                    ms as f64 / 1000.0
                );
            }
        }
    }
    fn finish(&self) {
        self.bar.finish_and_clear();
    }
    /// After SIGINT or SIGTERM (see `crate::signals`).
    fn cancelled(&self) -> bool {
        crate::signals::received()
    }
}
