//! Helpers for the library's unit tests (built only under `cargo test`). The integration
//! tests compile this same file into their `support` module, so both have one generator.

/// SplitMix64: the tests' one deterministic generator, `Rng(seed)` or `Rng::new(seed)`, the
/// same stream on every run (state = seed, then `state += 0x9E37_79B9_7F4A_7C15` and
/// SplitMix64's output mix per draw).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// 64 random bits.
    pub fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 random bits.
    pub fn f(&mut self) -> f64 {
        (self.u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }

    /// `10^x` with `x` uniform in `[lo, hi)`.
    pub fn log10(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.range(lo, hi))
    }

    /// An integer in `0..n` (`n > 0`), as `floor(f() * n)`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.f() * n as f64) as usize
    }
}
