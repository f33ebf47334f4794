//! Error-free transformations of f64 arithmetic (Knuth, Dekker, Veltkamp): a sum or product
//! as its rounded value plus the exact rounding error. The exact sphere test (`sphere.rs`)
//! and the density profiles' chords (`render::profile`) build on them. Products are Dekker's
//! by default: without the `fma` target feature a fused multiply-add is a slow library call
//! on x86-64. Code compiled for FMA (the sphere test's AVX2 clone) picks [`Fused`] instead,
//! which gives the same exact pairs in two instructions.

/// `a + b = s + e` exactly, `s = fl(a + b)` (Knuth's TwoSum; no branch on magnitudes).
#[inline(always)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// Veltkamp's split: `a = hi + lo` exactly, each half with at most 26 significant bits, so
/// products of halves are exact. Needs `|a| < 2^995` (no overflow of `2^27 a`).
#[inline(always)]
pub(crate) fn split(a: f64) -> (f64, f64) {
    let t = 134_217_729.0 * a; // 2^27 + 1
    let hi = t - (t - a);
    (hi, a - hi)
}

/// `a * b = p + e` exactly, `p = fl(a * b)` (Dekker's TwoProduct), unless the product
/// underflows; `|a|, |b| < 2^995`.
#[inline(always)]
pub(crate) fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// `a * a = p + e` exactly (Dekker), as [`two_prod`]`(a, a)` with one split.
#[inline(always)]
pub(crate) fn two_square(a: f64) -> (f64, f64) {
    let p = a * a;
    let (h, l) = split(a);
    (p, ((h * h - p) + 2.0 * (h * l)) + l * l)
}

/// Exact products ([`two_prod`], [`two_square`]) by one method or the other. Both give the
/// same pair whenever the product neither overflows nor underflows: `p` is the rounded
/// product and `e = a * b - p` is representable, so there is only one right answer.
pub(crate) trait ExactProducts {
    fn prod(a: f64, b: f64) -> (f64, f64);
    fn square(a: f64) -> (f64, f64);
}

/// Dekker's products (any x86-64).
pub(crate) struct Dekker;

/// Products with one fused multiply-add: only for code compiled with the `fma` feature.
pub(crate) struct Fused;

impl ExactProducts for Dekker {
    #[inline(always)]
    fn prod(a: f64, b: f64) -> (f64, f64) {
        two_prod(a, b)
    }
    #[inline(always)]
    fn square(a: f64) -> (f64, f64) {
        two_square(a)
    }
}

impl ExactProducts for Fused {
    #[inline(always)]
    fn prod(a: f64, b: f64) -> (f64, f64) {
        let p = a * b;
        (p, a.mul_add(b, -p))
    }
    #[inline(always)]
    fn square(a: f64) -> (f64, f64) {
        Fused::prod(a, a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_prod_and_two_sum_are_exact_against_i128() {
        // Integers below 2^53 are exact in f64; i128 holds their exact products and sums.
        let mut rng = crate::testing::Rng::new(0x9e37_79b9_7f4a_7c15);
        for _ in 0..10_000 {
            let a = (rng.u64() >> 11) as i64 - (1 << 52);
            let b = (rng.u64() >> 13) as i64 - (1 << 50);
            let (p, e) = two_prod(a as f64, b as f64);
            assert_eq!(two_square(a as f64), two_prod(a as f64, a as f64));
            assert_eq!(Fused::prod(a as f64, b as f64), (p, e));
            assert_eq!(Fused::square(a as f64), two_square(a as f64));
            assert_eq!(p as i128 + e as i128, a as i128 * b as i128);
            let (s, e) = two_sum(a as f64 * 1024.0, b as f64 / 64.0);
            // Scale by 64 to make both sides integers.
            assert_eq!(
                (s * 64.0) as i128 + (e * 64.0) as i128,
                a as i128 * 65536 + b as i128
            );
        }
    }
}
