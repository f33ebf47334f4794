//! Adaptive Gauss-Kronrod quadrature (7-point Gauss, 15-point Kronrod) of vector-valued
//! integrands over several pieces at once, refining the piece with the largest error estimate
//! until the total estimate meets the tolerance (QUADPACK's QAG strategy, over a set of
//! pieces).
//!
//! Each piece is integrated after the change of variable `t = a + (b - a) s(u)`,
//! `s(u) = 3u^2 - 2u^3`: `s'` vanishes at both ends, so an integrand that behaves like
//! `sqrt(t - a)` at an end (a shadow boundary met at a breakpoint, where a light's path length
//! through a sphere is the square root of a quadratic in `t`) becomes smooth in `u`.

use glam::DVec3;

/// Kronrod abscissae (positive half, descending; the last is 0) and weights; Gauss weights
/// for the odd-indexed abscissae and the centre (QUADPACK `qk15`).
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
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One Gauss-Kronrod estimate over `[u0, u1]` of the piece `[a, b]` (in the smoothed
/// variable): the Kronrod value and QUADPACK's error estimate
/// `resasc * min(1, (200 |K - G| / resasc)^1.5)` per channel (max over channels).
fn gk15(
    f: &mut impl FnMut(usize, f64) -> DVec3,
    piece: usize,
    a: f64,
    b: f64,
    u0: f64,
    u1: f64,
) -> (DVec3, f64) {
    let c = 0.5 * (u0 + u1);
    let h = 0.5 * (u1 - u0);
    let mut g = |u: f64| {
        let t = a + (b - a) * u * u * (3.0 - 2.0 * u);
        let jac = (b - a) * 6.0 * u * (1.0 - u);
        if jac == 0.0 {
            DVec3::ZERO
        } else {
            f(piece, t) * jac
        }
    };
    let fc = g(c);
    let mut k = fc * WGK[7];
    let mut gauss = fc * WG[3];
    let mut fv = [DVec3::ZERO; 15];
    fv[7] = fc;
    for j in 0..7 {
        let x = h * XGK[j];
        let (f1, f2) = (g(c - x), g(c + x));
        fv[j] = f1;
        fv[14 - j] = f2;
        k += (f1 + f2) * WGK[j];
        if j % 2 == 1 {
            gauss += (f1 + f2) * WG[j / 2];
        }
    }
    let mean = k * 0.5;
    let mut resasc = DVec3::ZERO;
    for j in 0..7 {
        resasc += ((fv[j] - mean).abs() + (fv[14 - j] - mean).abs()) * WGK[j];
    }
    resasc += (fc - mean).abs() * WGK[7];
    let (k, gauss, resasc) = (k * h, gauss * h, resasc * h);
    let mut err: f64 = 0.0;
    for ch in 0..3 {
        let diff = (k[ch] - gauss[ch]).abs();
        let e = if resasc[ch] != 0.0 && diff != 0.0 {
            resasc[ch] * (50.0 * diff / resasc[ch]).powf(1.5).min(1.0)
        } else {
            diff
        };
        // Never claim better than rounding of the sum allows.
        err = err.max(e.max(50.0 * f64::EPSILON * k[ch].abs()));
    }
    (k, err)
}

/// Result of [`integrate`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quad {
    pub value: DVec3,
    /// Estimated absolute error (max over channels).
    pub error: f64,
    /// Integrand evaluations.
    pub evals: u64,
}

/// Reusable buffers of [`integrate`].
#[derive(Default)]
pub struct QuadScratch {
    parts: Vec<(f64, DVec3, usize, f64, f64)>,
}

/// Integrates `f(piece, t)` over every piece `[a, b]` of `pieces` and sums, refining until the summed
/// error estimate is at most `tol(value)` (a function of the running total, so that a
/// relative tolerance can be asked for) or `max_intervals` sub-intervals are in use.
pub fn integrate(
    pieces: &[(f64, f64)],
    mut f: impl FnMut(usize, f64) -> DVec3,
    tol: impl Fn(DVec3) -> f64,
    max_intervals: usize,
    scratch: &mut QuadScratch,
) -> Quad {
    // (error, value, piece index, u0, u1)
    let parts = &mut scratch.parts;
    parts.clear();
    let mut evals = 0u64;
    for (i, &(a, b)) in pieces.iter().enumerate() {
        if b > a {
            let (v, e) = gk15(&mut f, i, a, b, 0.0, 1.0);
            evals += 15;
            parts.push((e, v, i, 0.0, 1.0));
        }
    }
    loop {
        let value: DVec3 = parts.iter().map(|p| p.1).sum();
        let error: f64 = parts.iter().map(|p| p.0).sum();
        let worst = parts
            .iter()
            .enumerate()
            .max_by(|x, y| x.1 .0.total_cmp(&y.1 .0))
            .map(|(k, _)| k);
        let Some(w) = worst else {
            return Quad::default();
        };
        if error <= tol(value) || parts.len() >= max_intervals {
            return Quad {
                value,
                error,
                evals,
            };
        }
        let (_, _, i, u0, u1) = parts[w];
        let um = 0.5 * (u0 + u1);
        if um <= u0 || um >= u1 {
            // The interval cannot be split further in f64.
            return Quad {
                value,
                error,
                evals,
            };
        }
        let (a, b) = pieces[i];
        let (v1, e1) = gk15(&mut f, i, a, b, u0, um);
        let (v2, e2) = gk15(&mut f, i, a, b, um, u1);
        evals += 30;
        parts[w] = (e1, v1, i, u0, um);
        parts.push((e2, v2, i, um, u1));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scalar(pieces: &[(f64, f64)], f: impl Fn(f64) -> f64, tol: f64) -> Quad {
        integrate(
            pieces,
            |_, t| DVec3::splat(f(t)),
            |_| tol,
            10_000,
            &mut QuadScratch::default(),
        )
    }

    #[test]
    fn polynomials_and_smooth_functions_against_closed_forms() {
        // x^5 on [0, 2]: 64 / 6.
        let q = scalar(&[(0.0, 2.0)], |x| x.powi(5), 1e-13);
        assert!((q.value.x - 64.0 / 6.0).abs() < 1e-12, "{q:?}");
        // exp on two pieces.
        let q = scalar(&[(-1.0, 0.5), (0.5, 3.0)], f64::exp, 1e-13);
        let want = 3f64.exp() - (-1f64).exp();
        assert!((q.value.x - want).abs() < 1e-12 * want, "{q:?}");
    }

    #[test]
    fn square_root_ends_and_an_interior_kink() {
        // sqrt(1 - x^2) on [-1, 1] (square-root behaviour at both ends): pi / 2.
        let q = scalar(&[(-1.0, 1.0)], |x| (1.0 - x * x).max(0.0).sqrt(), 1e-12);
        assert!(
            (q.value.x - std::f64::consts::FRAC_PI_2).abs() < 1e-11,
            "{q:?}"
        );
        // |x - 0.3| on [0, 1] without a breakpoint at the kink: adaptivity copes, and the
        // estimate is honest (the true error is below it).
        let want = 0.5 * (0.09 + 0.49);
        let q = scalar(&[(0.0, 1.0)], |x| (x - 0.3).abs(), 1e-9);
        let err = (q.value.x - want).abs();
        assert!(
            err <= q.error && q.error < 1e-8,
            "err {err:e}, estimate {:e}",
            q.error
        );
    }

    #[test]
    fn relative_tolerance_through_the_closure() {
        let q = integrate(
            &[(0.0, 1.0)],
            |_, x| DVec3::new(1e-12 * x.cos(), 0.0, 0.0),
            |v| 1e-8 * v.abs().max_element(),
            10_000,
            &mut QuadScratch::default(),
        );
        let want = 1e-12 * 1f64.sin();
        assert!((q.value.x - want).abs() < 1e-8 * want);
    }
}
