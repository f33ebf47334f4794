//! Adaptive Gauss-Kronrod (7/15) quadrature, the textbook QUADPACK rule, for the reference:
//! an interval is accepted when QUADPACK's error estimate (|Kronrod - Gauss| scaled by the
//! integrand's spread and raised to 1.5, still an over-estimate for smooth integrands) is
//! below `rel` times the Kronrod sum's size plus `abs` per unit length; otherwise it is
//! halved. The returned error is the sum of the accepted estimates.

/// Kronrod abscissae on [-1, 1] (non-negative half; the last is the centre).
const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
/// Kronrod weights for `XGK`.
const WGK: [f64; 8] = [
    0.022_935_322_010_529_225,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_18,
    0.140_653_259_715_525_92,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_83,
];
/// Gauss weights for the odd-indexed `XGK` (1, 3, 5, 7).
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// Deepest halving: an interval 2^-60 of the piece is below f64 resolution of its ends.
const MAX_DEPTH: u32 = 60;
/// Most rules applied to one integral: past it the remaining intervals are accepted with
/// their estimates, which then say how good the value is (bounded time on hard rays).
const MAX_RULES: usize = 400;

thread_local! {
    /// Past this instant every interval is accepted as it is (see [`set_deadline`]).
    static DEADLINE: std::cell::Cell<Option<std::time::Instant>> =
        const { std::cell::Cell::new(None) };
}

/// Makes this thread's quadratures stop refining after `at`, so that a reference pixel
/// whose nested quadratures would run for minutes ends soon after; its caller then
/// discards the results (they are no longer to their tolerance).
pub fn set_deadline(at: Option<std::time::Instant>) {
    DEADLINE.with(|d| d.set(at));
}

fn past_deadline() -> bool {
    DEADLINE.with(|d| d.get().is_some_and(|t| std::time::Instant::now() > t))
}

/// One 15-point rule on [a, b] of a vector-valued `f`: (Kronrod sum, |Kronrod - Gauss| summed
/// over the components).
fn rule<const N: usize>(f: &mut impl FnMut(f64) -> [f64; N], a: f64, b: f64) -> ([f64; N], f64) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut k = [0.0; N];
    let mut g = [0.0; N];
    let mut vals = Vec::with_capacity(15);
    let mut idx = Vec::with_capacity(15);
    for i in 0..8 {
        let xs: &[f64] = if i == 7 {
            &[c]
        } else {
            &[c - h * XGK[i], c + h * XGK[i]]
        };
        for &x in xs {
            let v = f(x);
            vals.push(v);
            idx.push(i);
            for n in 0..N {
                k[n] += WGK[i] * v[n];
                if i % 2 == 1 {
                    g[n] += WG[i / 2] * v[n];
                }
            }
        }
    }
    // QUADPACK's estimate (qk15): |K - G| scaled by the integrand's spread about its mean,
    // raised to 1.5 (the Kronrod sum converges much faster than the Gauss one).
    let mut asc = [0.0; N];
    for (n, a) in asc.iter_mut().enumerate() {
        let mean = k[n] * 0.5;
        for (j, v) in vals.iter().enumerate() {
            *a += WGK[idx[j]] * (v[n] - mean).abs();
        }
    }
    let mut err = 0.0;
    for n in 0..N {
        let diff = (k[n] - g[n]).abs() * h;
        let spread = asc[n] * h;
        k[n] *= h;
        err += if spread > 0.0 && diff > 0.0 {
            spread * (200.0 * diff / spread).powf(1.5).min(1.0)
        } else {
            diff
        };
    }
    (k, err)
}

/// The integral of `f` over [a, b] and its error estimate, to `rel` relative (of each accepted
/// interval's value, so for a non-negative integrand of the whole) plus `abs` per unit length.
pub fn integrate<const N: usize>(
    f: &mut impl FnMut(f64) -> [f64; N],
    a: f64,
    b: f64,
    rel: f64,
    abs: f64,
) -> ([f64; N], f64) {
    let mut total = [0.0; N];
    let mut err = 0.0;
    if b <= a {
        return (total, err);
    }
    let mut stack = vec![(a, b, 0u32)];
    let mut rules = 0;
    let mut late = false;
    while let Some((x0, x1, depth)) = stack.pop() {
        let (v, e) = rule(f, x0, x1);
        rules += 1;
        let size: f64 = v.iter().map(|x| x.abs()).sum();
        let mid = 0.5 * (x0 + x1);
        if rules % 16 == 1 && !late {
            late = past_deadline();
        }
        let splittable = depth < MAX_DEPTH && mid > x0 && mid < x1 && rules < MAX_RULES && !late;
        if e <= rel * size + abs * (x1 - x0) || !splittable {
            for n in 0..N {
                total[n] += v[n];
            }
            err += e;
        } else {
            stack.push((x0, mid, depth + 1));
            stack.push((mid, x1, depth + 1));
        }
    }
    (total, err)
}

/// A scalar integral to `rel` relative (plus a tiny absolute floor), without its estimate.
pub fn scalar(mut f: impl FnMut(f64) -> f64, a: f64, b: f64, rel: f64) -> f64 {
    integrate(&mut |x| [f(x)], a, b, rel, 1e-300).0[0]
}
