//! What a render may ask of the machine: samples per pixel, the memory its buffers need
//! against the memory available, and worker threads; checked before anything is allocated.

use super::{film, packets, tiles, RenderOptions, SamplerKind};
use super::{Aovs, Integrator};

/// The most samples per pixel a render takes. A pixel's sample positions (and, in scenes
/// without gas, its camera rays and their hits) are held at once while it is traced, so
/// each worker's buffers grow with `spp` ([`RenderOptions::memory_bytes`]).
pub const MAX_SPP: u32 = 1 << 20;

/// Worker threads per core at most ([`capped_threads`]).
pub const THREADS_PER_CORE: usize = 4;

/// The most worker threads a pool is given: [`THREADS_PER_CORE`] per core of this machine.
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    THREADS_PER_CORE.saturating_mul(cores)
}

/// `asked` worker threads bounded by [`max_threads`], with the end of a sentence saying so
/// when the bound applies (`"is more than 4 per core of this machine's 2 cores: using 8"`,
/// after the option and its value): more threads only share the same cores, each with its
/// stack and buffers.
pub fn capped_threads(asked: usize) -> (usize, Option<String>) {
    let cap = max_threads();
    if asked <= cap {
        return (asked, None);
    }
    let cores = cap / THREADS_PER_CORE;
    let why = format!(
        "is more than {THREADS_PER_CORE} per core of this machine's {cores} core{}: using {cap}",
        if cores == 1 { "" } else { "s" }
    );
    (cap, Some(why))
}

/// Bytes of memory this machine can give a process without it failing: on Linux,
/// `MemAvailable` plus `SwapFree` of /proc/meminfo; `None` where that is unknown.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    meminfo_available(&text)
}

/// `MemAvailable + SwapFree` of a /proc/meminfo text, in bytes (`None` without
/// `MemAvailable`; a missing `SwapFree` counts as 0).
fn meminfo_available(text: &str) -> Option<u64> {
    let field = |name: &str| {
        text.lines().find_map(|l| {
            let rest = l.strip_prefix(name)?.strip_prefix(':')?;
            let kb: u64 = rest.trim().strip_suffix("kB")?.trim().parse().ok()?;
            kb.checked_mul(1024)
        })
    };
    let avail = field("MemAvailable")?;
    Some(avail.saturating_add(field("SwapFree").unwrap_or(0)))
}

/// `bytes` in decimal gigabytes (megabytes below one), for messages.
fn human(bytes: u64) -> String {
    let gb = bytes as f64 / 1e9;
    if gb >= 10.0 {
        format!("{gb:.0} GB")
    } else if gb >= 1.0 {
        format!("{gb:.1} GB")
    } else {
        format!("{:.0} MB", (bytes as f64 / 1e6).ceil())
    }
}

/// The extra channels asked for, as words for messages (" with the depth and id AOVs").
fn aov_words(a: Aovs) -> String {
    let names: Vec<&str> = [
        (a.depth, "depth"),
        (a.normal, "normal"),
        (a.id, "id"),
        (a.ao, "ao"),
        (a.error, "error"),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .map(|&(_, n)| n)
    .collect();
    match names.as_slice() {
        [] => String::new(),
        [one] => format!(" with the {one} AOV"),
        [first @ .., last] => format!(" with the {} and {last} AOVs", first.join(", ")),
    }
}

impl RenderOptions {
    /// Samples each pixel holds at once: `spp`, or one at the centre (the centre sampler
    /// takes `spp` paths through the centre for Monte Carlo in gas, counted here whatever
    /// the scene).
    fn samples_held(&self) -> u64 {
        match (self.sampler, self.integrator) {
            (SamplerKind::Center, Integrator::Mc) | (SamplerKind::Stratified, _) => {
                u64::from(self.spp.max(1))
            }
            (SamplerKind::Center, _) => 1,
        }
    }

    /// The bytes a render with these options holds at its peak on `threads` worker threads:
    /// the film (RGB, alpha and each extra channel), the finished tiles waiting to be placed
    /// in it, and each worker's buffers for one tile. The scene and its BVH are not counted
    /// (they exist already). `None` when the count does not fit in 64 bits.
    pub fn memory_bytes(&self, threads: usize) -> Option<u64> {
        let (x0, y0, x1, y1) = self.region.unwrap_or((0, 0, self.width, self.height));
        let pixels = u64::from(x1.checked_sub(x0)?).checked_mul(u64::from(y1.checked_sub(y0)?))?;
        let per_pixel = film::bytes_per_pixel(self.aovs) + tiles::held_per_pixel(self.aovs);
        let tiles = pixels.div_ceil(u64::from(tiles::TILE) * u64::from(tiles::TILE));
        let workers = (threads.max(1) as u64).min(tiles.max(1));
        let worker = tiles::worker_bytes(self.samples_held(), packets::bytes_per_sample())?;
        pixels
            .checked_mul(per_pixel)?
            .checked_add(workers.checked_mul(worker)?)
    }

    /// Refuses a render whose buffers ([`RenderOptions::memory_bytes`] on `threads` workers)
    /// would not fit in `available` bytes (`None`: unknown, then only a count too large for
    /// 64 bits is refused).
    pub(crate) fn check_memory(
        &self,
        threads: usize,
        available: Option<u64>,
    ) -> Result<(), String> {
        let (w, h) = (self.width, self.height);
        let what = match self.region {
            Some((x0, y0, x1, y1)) => {
                format!("the region {x0},{y0},{x1},{y1} of a {w}x{h} image")
            }
            None => format!("a {w}x{h} image"),
        };
        let what = format!("{what}{}", aov_words(self.aovs));
        let Some(need) = self.memory_bytes(threads) else {
            return Err(format!(
                "{what} (spp {}) needs more memory than can be counted",
                self.spp
            ));
        };
        match available {
            Some(have) if need > have => Err(format!(
                "{what} (spp {}, {threads} threads) needs {} of memory; this machine has {} \
                 available",
                self.spp,
                human(need),
                human(have)
            )),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(width: u32, height: u32) -> RenderOptions {
        RenderOptions {
            width,
            height,
            spp: 1,
            ..RenderOptions::default()
        }
    }

    #[test]
    fn meminfo_adds_available_and_swap_free() {
        let text = "MemTotal:       24683792 kB\nMemFree: 1 kB\nMemAvailable:   2000 kB\n\
                    SwapTotal: 0 kB\nSwapFree:        48 kB\n";
        assert_eq!(meminfo_available(text), Some(2048 * 1024));
        assert_eq!(meminfo_available("MemAvailable: 3 kB\n"), Some(3072));
        assert_eq!(meminfo_available("MemTotal: 3 kB\n"), None);
    }

    /// The count is the sum of the parts, in 64 bits for sizes whose product overflows 32.
    #[test]
    fn memory_counts_film_tiles_and_workers() {
        let one = opts(16, 16).memory_bytes(1).unwrap();
        let four = opts(32, 32).memory_bytes(1).unwrap();
        let per_pixel = (four - one) / (32 * 32 - 16 * 16);
        // rgb, alpha, a PixelOut (rgb, alpha, error) at least.
        assert!(per_pixel >= 24 + 8 + 40, "{per_pixel}");
        // Two workers hold two tiles' buffers; one tile needs one worker.
        assert!(opts(32, 32).memory_bytes(2).unwrap() > four);
        assert_eq!(opts(16, 16).memory_bytes(8), Some(one));
        let big = opts(1 << 20, 1 << 20).memory_bytes(2).unwrap();
        assert!(big >= (1u64 << 40) * per_pixel);
        assert_eq!(opts(u32::MAX, u32::MAX).memory_bytes(2), None);
        // A region counts its own pixels.
        let region = RenderOptions {
            region: Some((0, 0, 16, 16)),
            ..opts(1 << 20, 1 << 20)
        };
        assert_eq!(region.memory_bytes(1), Some(one));
        // Each worker holds a pixel's samples (and a band's rays and hits).
        let many = RenderOptions {
            spp: MAX_SPP,
            ..opts(16, 16)
        };
        assert!(many.memory_bytes(1).unwrap() > one + 64 * u64::from(MAX_SPP));
    }

    #[test]
    fn memory_is_refused_beyond_what_is_available() {
        let o = RenderOptions {
            aovs: Aovs {
                depth: true,
                ..Aovs::default()
            },
            ..opts(50_000, 50_000)
        };
        let m = o.check_memory(2, Some(22_000_000_000)).unwrap_err();
        assert!(
            m.starts_with("a 50000x50000 image with the depth AOV (spp 1, 2 threads) needs ")
                && m.ends_with(" GB of memory; this machine has 22 GB available"),
            "{m}"
        );
        assert_eq!(o.check_memory(2, None), Ok(()));
        assert_eq!(opts(64, 48).check_memory(2, Some(100_000_000)), Ok(()));
        assert!(opts(u32::MAX, u32::MAX).check_memory(1, None).is_err());
    }

    #[test]
    fn threads_are_capped_at_four_per_core() {
        let cap = max_threads();
        assert!(cap >= THREADS_PER_CORE);
        assert_eq!(capped_threads(1), (1, None));
        assert_eq!(capped_threads(cap), (cap, None));
        let (n, why) = capped_threads(100_000);
        assert_eq!(n, cap);
        let why = why.unwrap();
        assert!(
            why.starts_with("is more than 4 per core of this machine's "),
            "{why}"
        );
        assert!(why.ends_with(&format!(": using {cap}")), "{why}");
    }

    #[test]
    fn sizes_read_as_words() {
        assert_eq!(human(120_000_000_000), "120 GB");
        assert_eq!(human(2_500_000_000), "2.5 GB");
        assert_eq!(human(1_200_000), "2 MB");
        let all = Aovs {
            depth: true,
            normal: true,
            id: true,
            error: false,
            ao: true,
        };
        assert_eq!(aov_words(all), " with the depth, normal, id and ao AOVs");
        assert_eq!(aov_words(Aovs::default()), "");
    }
}
