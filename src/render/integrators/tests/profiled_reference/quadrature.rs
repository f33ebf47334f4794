//! Gauss-Legendre rules, the optical depth of a chord of one profiled sphere, and the shadow interval of a sphere: the pieces the reference integrates with.

use super::*;

// ---- Gauss-Legendre.

/// The `n`-point Gauss-Legendre rule on [-1, 1] (n in 1..=24), by Newton's method on P_n.
pub(super) fn rule(n: usize) -> &'static [(f64, f64)] {
    static RULES: OnceLock<Vec<Vec<(f64, f64)>>> = OnceLock::new();
    &RULES.get_or_init(|| (0..=24).map(legendre_rule).collect())[n]
}

pub(super) fn legendre_rule(n: usize) -> Vec<(f64, f64)> {
    // P_n(x) and P_n'(x) by the three-term recurrence.
    let legendre = |x: f64| {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
            p0 = p1;
            p1 = p2;
        }
        (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
    };
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            for _ in 0..100 {
                let (p, dp) = legendre(x);
                let dx = p / dp;
                x -= dx;
                if dx.abs() < 1e-17 {
                    break;
                }
            }
            let dp = legendre(x).1;
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// `rule` applied to `g` on `[a, b]`.
pub(super) fn rule_sum(rule: &[(f64, f64)], a: f64, b: f64, g: impl Fn(f64) -> f64) -> f64 {
    let (m, hw) = (0.5 * (a + b), 0.5 * (b - a));
    hw * rule.iter().map(|&(x, wt)| wt * g(m + hw * x)).sum::<f64>()
}

// ---- Chords.

/// The line `o + s d` (`|d| = 1`) against a sphere: closest approach to the centre at `s = sc`,
/// the centre's distance from the line `beta` and the chord's half-length `h`, in radii.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chord {
    pub(super) sc: f64,
    pub(super) beta: f64,
    pub(super) h: f64,
}

pub(super) fn chord(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<Chord> {
    let f = o - c;
    let b = f.dot(d);
    let beta = (f - b * d).length() / r;
    (beta < 1.0).then(|| Chord {
        sc: -b,
        beta,
        h: ((1.0 - beta) * (1.0 + beta)).sqrt(),
    })
}

/// `integral_p^q f dv` along a chord, `0 <= p <= q <= h`, numerically; `panels` refines it.
pub(super) fn radial(profile: Profile, ch: &Chord, p: f64, q: f64, panels: usize) -> f64 {
    if q <= p {
        return 0.0;
    }
    let f = |v: f64| profile.on_chord(ch.beta, ch.h, v);
    let split = |a: f64, b: f64, n: usize, rule: &[(f64, f64)]| -> f64 {
        (0..n)
            .map(|k| {
                let x0 = a + (b - a) * k as f64 / n as f64;
                let x1 = a + (b - a) * (k + 1) as f64 / n as f64;
                rule_sum(rule, x0, x1, f)
            })
            .sum()
    };
    match profile {
        // Polynomials in v on [p, q] (v >= 0): the rule is exact.
        Profile::Constant | Profile::Quadratic => rule_sum(rule(2), p, q, f),
        Profile::Linear => {
            // Branch points at v = +-i beta: cells halving towards p until a cell is no wider
            // than their distance from p (so every cell sees them at least a cell's width
            // away), or than 1e-9 of the part (then beta < 1e-9 (q - p), and f differs from
            // the polynomial 1 - v by at most beta on a last cell that narrow: negligible).
            let near = p.hypot(ch.beta).max(1e-9 * (q - p));
            let (mut sum, mut width) = (0.0, q - p);
            while width > near {
                sum += split(p + 0.5 * width, p + width, panels, rule(16));
                width *= 0.5;
            }
            sum + split(p, p + width, panels, rule(16))
        }
        Profile::Gaussian(s) => {
            let n = ((q - p) / (2.0 * s)).ceil().max(1.0) as usize;
            split(p, q, n * panels, rule(16))
        }
    }
}

/// `integral sigma ds` along the line `o + s d` (`|d| = 1`) for `s` in `[s0, s1]`, through a
/// sphere of peak extinction `sigma0`: the chord clipped to the interval, split at the closest
/// approach.
#[allow(clippy::too_many_arguments)]
pub(super) fn depth_on_line(
    c: DVec3,
    r: f64,
    sigma0: f64,
    profile: Profile,
    o: DVec3,
    d: DVec3,
    s0: f64,
    s1: f64,
    panels: usize,
) -> f64 {
    let Some(ch) = chord(o, d, c, r) else {
        return 0.0;
    };
    let v0 = ((s0 - ch.sc) / r).max(-ch.h);
    let v1 = ((s1 - ch.sc) / r).min(ch.h);
    if v1 <= v0 {
        return 0.0;
    }
    let i = if v0 >= 0.0 {
        radial(profile, &ch, v0, v1, panels)
    } else if v1 <= 0.0 {
        radial(profile, &ch, -v1, -v0, panels)
    } else {
        radial(profile, &ch, 0.0, -v0, panels) + radial(profile, &ch, 0.0, v1, panels)
    };
    sigma0 * r * i
}

/// The optical depth of gas sphere `b` along `o + s d` (`|d| = 1`), `s` in `[s0, s1]`, as the
/// light paths use it (`panels` 2).
pub fn line_depth(b: &Ball, o: DVec3, d: DVec3, s0: f64, s1: f64) -> f64 {
    let profile = b.gas.expect("a gas sphere").3;
    depth_on_line(b.c, b.r, sigma0(b), profile, o, d, s0, s1, 2)
}

// ---- Shadows: gas_reference's search (the light path's distance from the centre depends
// on the sphere's centre and radius alone, not on its gas).

/// Where along `[t0, t1]` the light path from `o + t w` enters the sphere `(c, r)`.
pub(super) fn shadow_interval(
    c: DVec3,
    r: f64,
    lamp: &Lamp,
    o: DVec3,
    w: DVec3,
    t0: f64,
    t1: f64,
) -> Option<(f64, f64)> {
    let ball = gas_reference::Ball { c, r, gas: None };
    gas_reference::shadow_interval(&ball, lamp, o, w, t0, t1)
}
