//! Sample positions inside a pixel, seeded from (seed, pixel, sample index) only, so that an
//! image does not depend on the thread count or tile order.

/// SplitMix64's output function: a bijective 64-bit mixer.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A small deterministic generator (SplitMix64).
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The generator of stream `stream` under `seed`; distinct streams give unrelated sequences.
    pub fn new(seed: u64, stream: u64) -> Rng {
        Rng(mix(seed ^ mix(stream.wrapping_add(0x9E37_79B9_7F4A_7C15))))
    }
    /// The next 64 uniformly distributed bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.0)
    }
    /// Uniform in `[0, 1)` with 53 random bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// How samples are placed in a pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    /// `spp` stratified samples over the pixel's square: a jittered `m x m` grid when `spp` is
    /// a square number `m^2`, otherwise Latin hypercube (one sample in each of `spp` rows and
    /// each of `spp` columns).
    #[default]
    Stratified,
    /// One sample at the pixel's exact centre.
    Center,
}

/// The `spp` sample offsets in `[0,1)^2` for pixel number `pixel`, in a fixed order.
pub fn offsets(kind: SamplerKind, spp: u32, seed: u64, pixel: u64, out: &mut Vec<(f64, f64)>) {
    out.clear();
    if kind == SamplerKind::Center {
        out.push((0.5, 0.5));
        return;
    }
    let n = spp.max(1) as usize;
    let mut rng = Rng::new(seed, pixel);
    let m = (n as f64).sqrt().round() as usize;
    if m * m == n {
        let inv = 1.0 / m as f64;
        for k in 0..n {
            let (sx, sy) = ((k % m) as f64, (k / m) as f64);
            out.push(((sx + rng.next_f64()) * inv, (sy + rng.next_f64()) * inv));
        }
    } else {
        let inv = 1.0 / n as f64;
        let mut perm: Vec<usize> = (0..n).collect();
        for k in (1..n).rev() {
            let j = (rng.next_u64() % (k as u64 + 1)) as usize;
            perm.swap(k, j);
        }
        for (k, &p) in perm.iter().enumerate() {
            out.push((
                (k as f64 + rng.next_f64()) * inv,
                (p as f64 + rng.next_f64()) * inv,
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each sample lies in its own stratum: every row and column of the grid (or of the
    /// Latin hypercube) holds exactly one sample per stratum.
    #[test]
    fn strata_are_filled_once() {
        let mut v = Vec::new();
        for spp in [1u32, 2, 3, 4, 5, 9, 16, 17] {
            for pixel in 0..50 {
                offsets(SamplerKind::Stratified, spp, 7, pixel, &mut v);
                assert_eq!(v.len(), spp as usize);
                let n = spp as usize;
                let m = (n as f64).sqrt().round() as usize;
                let (cols, rows) = if m * m == n { (m, m) } else { (n, n) };
                let mut seen = vec![0usize; cols * rows];
                let mut col_count = vec![0usize; cols];
                for &(x, y) in &v {
                    assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                    let (cx, cy) = ((x * cols as f64) as usize, (y * rows as f64) as usize);
                    seen[cy * cols + cx] += 1;
                    col_count[cx] += 1;
                }
                assert!(col_count.iter().all(|&c| c == n / cols), "{spp}: {v:?}");
                assert!(seen.iter().all(|&c| c <= 1));
            }
        }
    }

    #[test]
    fn same_inputs_same_samples_other_pixels_differ() {
        let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        offsets(SamplerKind::Stratified, 16, 1, 42, &mut a);
        offsets(SamplerKind::Stratified, 16, 1, 42, &mut b);
        offsets(SamplerKind::Stratified, 16, 1, 43, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
