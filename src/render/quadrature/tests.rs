use super::*;
use crate::testing::Rng;
use std::cell::Cell;

thread_local! {
    /// Heap comparisons made on this thread (see `Entry::cmp`).
    pub(super) static COMPARISONS: Cell<u64> = const { Cell::new(0) };
}

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

/// Nodes and weights of `n`-point Gauss-Legendre on [-1, 1], by Newton's method on the
/// Legendre recurrence (for the reference integrals: a rule independent of the one tested).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// The integral of `f` over `[a, b]`, split at `breaks` (every kink and square-root point,
/// in any order), and `integral |f|`: composite 20-point Gauss-Legendre on `panels` panels
/// of each cell of a mesh graded geometrically towards both ends of every sub-interval, so
/// that square-root ends and singularities just outside converge (a rule and a treatment
/// of the ends independent of the ones tested).
fn composite(f: &dyn Fn(f64) -> f64, a: f64, b: f64, breaks: &[f64], panels: usize) -> (f64, f64) {
    thread_local! {
        static GL: Vec<(f64, f64)> = gauss_legendre(20);
    }
    let mut pts: Vec<f64> = breaks.iter().copied().filter(|&x| x > a && x < b).collect();
    pts.push(a);
    pts.push(b);
    pts.sort_by(f64::total_cmp);
    pts.dedup();
    let mut mesh = Vec::new();
    for w in pts.windows(2) {
        let h = w[1] - w[0];
        mesh.push(w[0]);
        // Down to cells far above the spacing of f64 there, so that no node rounds onto
        // the end (where a chord's indicator jumps); the last cell's square root costs
        // (1e6 ulp / h)^1.5.
        let ulp = f64::EPSILON * w[0].abs().max(w[1].abs());
        let mut d = 0.5 * h;
        while d > 1e6 * ulp {
            mesh.push(w[0] + d);
            mesh.push(w[1] - d);
            d *= 0.5;
        }
    }
    mesh.push(b);
    mesh.sort_by(f64::total_cmp);
    mesh.dedup();
    let (mut sum, mut abs) = (Sum::default(), 0.0);
    GL.with(|gl| {
        for w in mesh.windows(2) {
            let h = (w[1] - w[0]) / panels as f64;
            for k in 0..panels {
                let c = w[0] + (k as f64 + 0.5) * h;
                for &(x, wt) in gl {
                    let y = f(c + 0.5 * h * x) * wt * 0.5 * h;
                    sum.add(DVec3::splat(y));
                    abs += y.abs();
                }
            }
        }
    });
    (sum.get().x, abs)
}

/// One random integrand: its pieces, and what the reference needs.
struct Case {
    f: Box<dyn Fn(f64) -> f64>,
    pieces: Vec<(f64, f64)>,
    /// Kinks and square-root points of `f` (for the reference).
    breaks: Vec<f64>,
    /// The closed form, where there is one.
    exact: Option<f64>,
    /// The parameters, for messages.
    what: String,
}

impl Case {
    /// The reference value, `integral |f|`, and the reference's uncertainty: the change
    /// when the panel width is halved (asserted small), or the rounding of a closed form.
    fn reference(&self) -> (f64, f64, f64) {
        let (a, b) = (self.pieces[0].0, self.pieces.last().unwrap().1);
        let mut breaks = self.breaks.clone();
        breaks.extend(self.pieces.iter().map(|p| p.0));
        let (c1, _) = composite(&*self.f, a, b, &breaks, 3);
        let (c2, abs) = composite(&*self.f, a, b, &breaks, 6);
        let unc = (c1 - c2).abs();
        assert!(
            unc <= 1e-12 * abs,
            "reference not converged: {c1:e} vs {c2:e} ({:e}) for {} on {:?}",
            (c1 - c2) / abs,
            self.what,
            self.pieces
        );
        if let Some(e) = self.exact {
            assert!((e - c2).abs() <= 1e-13 * abs, "closed form {e:e} vs {c2:e}");
            return (e, abs, 4.0 * f64::EPSILON * abs);
        }
        (c2, abs, unc)
    }
}

/// An interval `[a, b]` of random position and length, cut into 1 to `n` pieces at random.
fn random_pieces(rng: &mut Rng, n: usize, extra: &[f64]) -> (f64, f64, Vec<(f64, f64)>) {
    let len = rng.log10(-2.0, 2.0);
    let a = rng.range(-2.0, 2.0) * len;
    let b = a + len;
    let mut cuts: Vec<f64> = (0..rng.below(n)).map(|_| rng.range(a, b)).collect();
    cuts.extend(extra.iter().copied().filter(|&x| x > a && x < b));
    cuts.push(a);
    cuts.push(b);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let pieces = cuts.windows(2).map(|w| (w[0], w[1])).collect();
    (a, b, pieces)
}

/// (a) Smooth: a polynomial, an exponential and a cosine of random scales, with closed
/// forms.
fn smooth(rng: &mut Rng) -> Case {
    let (a, b, pieces) = random_pieces(rng, 4, &[]);
    let len = b - a;
    let deg = rng.below(16);
    let coef: Vec<f64> = (0..=deg).map(|_| rng.range(-1.0, 1.0)).collect();
    let wp = rng.log10(-3.0, 1.0);
    let k = rng.range(-30.0, 30.0) / len;
    let we = rng.log10(-3.0, 1.0);
    let om = rng.range(0.0, 60.0) / len;
    let phi = rng.range(0.0, 6.3);
    let wc = rng.log10(-3.0, 1.0);
    let scale = rng.log10(-3.0, 3.0);
    // Positive: the polynomial of (t - a) / len is bounded by the sum of |coef|.
    let offset = coef.iter().map(|c| c.abs()).sum::<f64>() * wp + wc;
    let f = {
        let coef = coef.clone();
        move |t: f64| {
            let x = (t - a) / len;
            let p = coef.iter().rev().fold(0.0, |s, c| s * x + c);
            scale * (offset + wp * p + we * (k * (t - a)).exp() + wc * (om * t + phi).cos())
        }
    };
    let poly: f64 = coef
        .iter()
        .enumerate()
        .map(|(i, c)| c / (i + 1) as f64)
        .sum();
    let ex = if k == 0.0 {
        len
    } else {
        (k * len).exp_m1() / k
    };
    let co = if om == 0.0 {
        len * phi.cos()
    } else {
        ((om * b + phi).sin() - (om * a + phi).sin()) / om
    };
    let exact = scale * (offset * len + wp * poly * len + we * ex + wc * co);
    Case {
        f: Box::new(f),
        pieces,
        breaks: vec![],
        exact: Some(exact),
        what: format!("smooth {coef:?} {wp} {k} {we} {om} {phi} {wc} {scale}"),
    }
}

/// (b) The gas integrand: extinction along the camera ray, a light's falloff, and the
/// attenuation along light paths through spheres whose chords begin and end at the
/// breakpoints (shadow boundaries) or just outside the interval; some are partial chords,
/// `c + sqrt(..)`.
fn gas(rng: &mut Rng) -> Case {
    let len = rng.log10(-2.0, 2.0);
    let a = rng.range(-2.0, 2.0) * len;
    let b = a + len;
    let mut chords = Vec::new();
    let mut ends = Vec::new();
    for _ in 0..rng.below(5) {
        let tau = rng.log10(-3.0, 30f64.log10());
        // Ends inside the interval (breakpoints), at its ends, or just outside.
        let mut end = |rng: &mut Rng, side: f64| match rng.below(4) {
            0 => {
                let x = rng.range(a, b);
                ends.push(x);
                x
            }
            1 => {
                if side < 0.0 {
                    a
                } else {
                    b
                }
            }
            2 => {
                if side < 0.0 {
                    a - len * rng.log10(-6.0, 0.0)
                } else {
                    b + len * rng.log10(-6.0, 0.0)
                }
            }
            _ => {
                if side < 0.0 {
                    a - len * rng.range(0.0, 3.0)
                } else {
                    b + len * rng.range(0.0, 3.0)
                }
            }
        };
        let lo = end(rng, -1.0);
        let hi = end(rng, 1.0);
        let (lo, hi) = if lo < hi { (lo, hi) } else { (hi, lo) };
        let c = if rng.below(3) == 0 {
            rng.range(0.0, 1.0)
        } else {
            0.0
        };
        chords.push((lo, hi, tau, c));
    }
    let s = rng.range(0.0, 50.0) / len;
    let p = rng.range(a - len, b + len);
    let d = len * rng.log10(-1.0, 1.0);
    let scale = rng.log10(-3.0, 3.0);
    let what = format!("{chords:?}");
    let f = move |t: f64| {
        let mut od = 0.0;
        for &(lo, hi, tau, c) in &chords {
            // Inside the chord by comparison with its ends, so that the jump of `c`
            // lies exactly on the breakpoints.
            if lo < t && t < hi {
                // 1 - x^2 as a product, without the cancellation near the ends that
                // the square root would amplify.
                let q = 4.0 * (t - lo) * (hi - t) / ((hi - lo) * (hi - lo));
                od += tau * (c + q.sqrt());
            }
        }
        scale * (-s * (t - a)).exp() / (1.0 + ((t - p) / d).powi(2)) * (-od).exp()
    };
    let mut pieces = Vec::new();
    let mut cuts = ends.clone();
    cuts.push(a);
    cuts.push(b);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    for w in cuts.windows(2) {
        pieces.push((w[0], w[1]));
    }
    Case {
        f: Box::new(f),
        pieces,
        what: format!("gas {what} s {s} p {p} d {d} scale {scale}"),
        breaks: ends,
        exact: None,
    }
}

/// (c) A kink or an interior square root that no breakpoint marks, on a smooth
/// background.
fn kink(rng: &mut Rng) -> Case {
    let (a, b, pieces) = random_pieces(rng, 3, &[]);
    let len = b - a;
    let t0 = rng.range(a, b);
    let kind = rng.below(3);
    let amp = rng.log10(-2.0, 1.0);
    let k = rng.range(-10.0, 10.0) / len;
    let scale = rng.log10(-3.0, 3.0);
    let f = move |t: f64| {
        let x = (t - t0) / len;
        let g = match kind {
            0 => x.abs(),
            1 => x.max(0.0).sqrt(),
            _ => (-x).max(0.0).sqrt(),
        };
        scale * (k * (t - a)).exp() * (1.0 + amp * g)
    };
    Case {
        f: Box::new(f),
        pieces,
        breaks: vec![t0],
        exact: None,
        what: format!("kink {kind} at {t0} amp {amp} k {k}"),
    }
}

/// (d) A narrow Gaussian or Lorentzian bump on a smooth background, of width down to
/// 1e-3 of its piece.
fn gaussian(rng: &mut Rng) -> Case {
    narrow_bump(rng, false)
}
fn lorentzian(rng: &mut Rng) -> Case {
    narrow_bump(rng, true)
}
fn narrow_bump(rng: &mut Rng, lorentz: bool) -> Case {
    let (a, b, pieces) = random_pieces(rng, 3, &[]);
    let len = b - a;
    let t0 = rng.range(a, b);
    let piece = pieces.iter().find(|p| p.0 <= t0 && t0 <= p.1).unwrap();
    let eps = (piece.1 - piece.0) * rng.log10(-3.0, -1.0);
    // The bump's integral relative to the background's.
    let amp = rng.log10(-2.0, 1.0) * len / eps;
    let k = rng.range(-5.0, 5.0) / len;
    let scale = rng.log10(-3.0, 3.0);
    let f = move |t: f64| {
        let x = (t - t0) / eps;
        let bump = if lorentz {
            1.0 / (1.0 + x * x)
        } else {
            (-x * x).exp()
        };
        scale * ((k * (t - a)).exp() + amp * bump)
    };
    let breaks = (-8..=8).map(|i| t0 + i as f64 * eps).collect();
    Case {
        f: Box::new(f),
        pieces,
        breaks,
        exact: None,
        what: format!("narrow lorentz {lorentz} at {t0} eps {eps} amp {amp} k {k}"),
    }
}

/// A generator of random integrands.
type Family = fn(&mut Rng) -> Case;

const FAMILIES: [(&str, Family); 5] = [
    ("smooth", smooth),
    ("gas", gas),
    ("kink", kink),
    ("gauss", gaussian),
    ("lorentz", lorentzian),
];
const TOLS: [f64; 4] = [1e-2, 1e-4, 1e-6, 1e-8];

/// Coverage (fraction of cases whose true error is at most the estimate), median
/// estimate / true error over the cases whose true error is above rounding, how many
/// those are, and mean evaluations.
#[derive(Debug)]
struct Stats {
    coverage: f64,
    median: f64,
    above: usize,
    evals: f64,
}

fn measure(est: Estimator, family: Family, tol: f64, n: usize) -> Stats {
    let mut rng = Rng::new(0x5EED ^ tol.to_bits());
    let mut scratch = QuadScratch::default();
    let (mut covered, mut ratios, mut evals) = (0, Vec::new(), 0);
    for _ in 0..n {
        let case = family(&mut rng);
        let (want, abs, unc) = case.reference();
        let q = integrate_with(
            est,
            &case.pieces,
            |_, t| DVec3::new((case.f)(t), 0.0, 0.0),
            |v| tol * v.abs().max_element(),
            4000,
            &mut scratch,
        );
        evals += q.evals;
        let err = (q.value.x - want).abs();
        if err <= q.error + unc {
            covered += 1;
        }
        if err > (1e-14 * abs).max(10.0 * unc) {
            ratios.push(q.error / err);
        }
    }
    ratios.sort_by(f64::total_cmp);
    Stats {
        coverage: covered as f64 / n as f64,
        median: ratios.get(ratios.len() / 2).copied().unwrap_or(f64::NAN),
        above: ratios.len(),
        evals: evals as f64 / n as f64,
    }
}

/// Coverage >= 95% on each family at each tolerance (Gaussian bumps narrower than the
/// spacing of the first nodes excepted: no rule sees them, see `report_estimators`), and
/// the median estimate / true error between 1 and `median_at_most`.
fn check_family(name: &str, family: Family, median_at_most: f64) {
    for tol in TOLS {
        let s = measure(Estimator::Embedded, family, tol, 400);
        assert!(s.coverage >= 0.95, "{name} at tol {tol:e}: {s:?}");
        assert!(
            s.above == 0 || (1.0..=median_at_most).contains(&s.median),
            "{name} at tol {tol:e}: {s:?}"
        );
    }
}

#[test]
fn estimate_covers_smooth_integrands_within_100x() {
    check_family("smooth", smooth, 100.0);
}

#[test]
fn estimate_covers_the_gas_integrand_within_100x() {
    check_family("gas", gas, 100.0);
}

#[test]
fn estimate_covers_interior_kinks_within_100x() {
    check_family("kink", kink, 100.0);
}

#[test]
fn estimate_covers_narrow_lorentzian_bumps_within_100x() {
    check_family("lorentzian", lorentzian, 100.0);
}

#[test]
fn a_second_identical_call_does_not_allocate() {
    for n in [1, 2000] {
        let pieces: Vec<(f64, f64)> = (0..n).map(|i| (i as f64, i as f64 + 1.0)).collect();
        let f = |_: usize, t: f64| DVec3::new((t - 0.3).abs().sqrt(), t.cos(), 1.0);
        let mut scratch = QuadScratch::default();
        let capacities = |s: &QuadScratch| (s.parts.capacity(), s.heap.capacity());
        let first = integrate(&pieces, f, |_| 1e-10, 8000, &mut scratch);
        let after_first = capacities(&scratch);
        let second = integrate(&pieces, f, |_| 1e-10, 8000, &mut scratch);
        assert_eq!(first, second);
        assert_eq!(capacities(&scratch), after_first, "{n} pieces");
        assert!(first.evals > 15 * n as u64, "the test should refine");
    }
}

#[test]
fn the_scratch_can_move_to_another_thread() {
    fn send<T: Send + Default>() {}
    send::<QuadScratch>();
}

#[test]
fn finding_the_worst_interval_is_not_quadratic() {
    // 2000 pieces refined up to 16000 intervals: a heap makes O(log n) comparisons per
    // split, a linear search n.
    let pieces: Vec<(f64, f64)> = (0..2000).map(|i| (i as f64, i as f64 + 1.0)).collect();
    COMPARISONS.with(|c| c.set(0));
    let q = integrate(
        &pieces,
        |_, t| DVec3::splat((t - t.floor() - 0.37).abs()),
        |_| 0.0,
        16_000,
        &mut QuadScratch::default(),
    );
    let n = (q.evals / 15) as f64;
    let cmp = COMPARISONS.with(|c| c.get()) as f64;
    assert!(n > 15_000.0, "{q:?}");
    assert!(
        cmp < 4.0 * n * n.log2(),
        "{cmp} comparisons for {n} intervals"
    );
}

#[test]
#[ignore = "a report, not a check: cargo test --lib quadrature -- --ignored --nocapture"]
fn report_estimators() {
    // Coverage / median estimate over true error / mean evaluations, per tolerance.
    for (name, est) in [
        ("power law", Estimator::PowerLaw),
        ("embedded", Estimator::Embedded),
    ] {
        for (fam, gen) in FAMILIES {
            let mut line = format!("{name} {fam:8}");
            for tol in TOLS {
                let s = measure(est, gen, tol, 200);
                line += &format!(
                    " | {tol:.0e}: {:.3} {:8.1e} {:4.0}",
                    s.coverage, s.median, s.evals
                );
            }
            println!("{line}");
        }
    }
}
