//! The tests' reference for the covered fraction of a hemisphere, by quadrature over the
//! azimuth, written apart from [`super::union`].
//!
//! It computes the fraction of the hemisphere about a normal `n` that a union of spherical
//! caps covers:
//!
//! ```text
//!   F = (1/pi)    * integral over w in H ∩ U of (n . w) dw     (cosine weighted)
//!   G = (1/(2pi)) * integral over w in H ∩ U of 1       dw     (uniform)
//! ```
//!
//! with `H = { w : |w| = 1, n.w >= 0 }` and `U` the union of the caps
//! `{ w : |w| = 1, axis_k . w >= cos_k }`, `cos_k` in `[0, 1)`.
//!
//! # Method
//!
//! Spherical coordinates about `n`: `w = sin(t) u(p) + cos(t) n`, `u(p) = cos(p) e1 + sin(p) e2`,
//! azimuth `p` in `[0, 2pi)`, polar angle `t` in `[0, pi/2]`. Then `dw = sin t dt dp` and
//!
//! ```text
//!   F = (1/pi)  * integral_0^{2pi} f_c(p) dp,   f_c(p) = integral over covered t of cos t sin t dt
//!   G = (1/2pi) * integral_0^{2pi} f_u(p) dp,   f_u(p) = integral over covered t of sin t dt
//! ```
//!
//! 1. **Inner integral (exact).** On the meridian of azimuth `p`,
//!    `axis.w = sin t (axis.u) + cos t (axis.n) = rho cos(t - beta)` with
//!    `rho = hypot(axis.u, axis.n)`, `beta = atan2(axis.u, axis.n)`. The cap condition
//!    `rho cos(t - beta) >= c` is `t - beta in [-g, g] (mod 2pi)`, `g = acos(c / rho)` (empty if
//!    `rho <= c`). Because `c >= 0`, `g <= pi/2`; with `beta in (-pi, pi]` the shifted copies
//!    `[beta - g ± 2pi, beta + g ± 2pi]` meet `[0, pi/2]` in at most a single point, so the covered
//!    set on this half-meridian is exactly `[beta - g, beta + g] ∩ [0, pi/2]`. The intervals of
//!    all caps are sorted and merged, and each merged `[t0, t1]` contributes in closed form
//!    `(sin^2 t1 - sin^2 t0)/2 = sin(t1 - t0) sin(t1 + t0) / 2` (cosine) or
//!    `cos t0 - cos t1 = 2 sin((t1 + t0)/2) sin((t1 - t0)/2)` (uniform). The product forms avoid
//!    cancellation for narrow intervals.
//!
//! 2. **Outer integral (tanh-sinh between breakpoints).** `f(p)` is analytic except at the
//!    azimuths where the combinatorial structure of the merged intervals changes, i.e. where
//!    * a meridian is tangent to a cap boundary (`rho(p) = c`; an interval is born or dies, with a
//!      square-root singularity). This also covers a boundary passing through the pole `n`
//!      (`axis.n = c`), where an interval end reaches `t = 0`: an interval end can only reach
//!      `t = 0` if the boundary circle contains `n`;
//!    * a cap boundary crosses the horizon (an interval end reaches `t = pi/2` and clipping
//!      starts/stops);
//!    * two cap boundaries intersect (two interval ends coincide: merging changes).
//!
//!    All of these azimuths are computed in closed form (see `fn breakpoints`); between consecutive
//!    breakpoints `f` is analytic (the set of live intervals, their clipping and their order are
//!    fixed, and the ends are analytic functions of `p`), and at the breakpoints it has at worst
//!    algebraic end-point singularities. Each sub-interval is integrated with tanh-sinh
//!    (double-exponential) quadrature, refined level by level (step halving, reusing all previous
//!    nodes) until two successive estimates agree to ~1e-15.
//!
//!    Besides these real events, `f` can be steep near a *complex* singularity close to the real
//!    axis (a boundary that nearly passes through the pole); those lie at the azimuths of minimal
//!    `rho`, which are added as breakpoints as well (details in `fn breakpoints`).
//!
//! Extra breakpoints are harmless (an analytic function is integrated on two pieces instead of
//! one), so the breakpoint generation errs on the side of including candidates (e.g. tangencies
//! below the horizon). Missing one would only slow the convergence, which the refinement would
//! detect ([`Stats::unconverged`]).
//!
//! # Triangles
//!
//! Triangles ([`covered_with_triangles`]) are not turned into caps: on each meridian the
//! directions whose rays meet a triangle within the reach `D` are found from the triangle
//! itself. The meridian's plane (through the point, spanned by `n` and `u(p)`) cuts the
//! triangle in a segment, found from the signed distances of its corners to the plane; the
//! segment is clipped to the meridian's side of the `n` axis (`u(p) . y >= 0`) and to the
//! ball `|y| <= D`, and the directions towards its points are the polar angles between
//! those of its ends (the angle is monotonic along a segment that misses the point), cut to
//! `[0, pi/2]`. A segment through the point (the point in the triangle's plane) is seen
//! edge-on and blocks nothing. The breakpoints add the azimuths of the corners, and treat
//! the planes through the point and each edge (great circles), the circle of directions
//! that meet the triangle's plane at distance `D`, as more circles for (a) to (c); of the
//! crossings of two circles only those on both occluders' boundaries are kept (the others
//! change nothing), which keeps the count of sub-intervals near linear.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::OnceLock;

mod triangles;

pub use triangles::covered_with_triangles;
use triangles::triangle_on_meridian;

/// A 3-vector.
pub type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn normalize(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    assert!(l > 0.0 && l.is_finite(), "zero or non-finite vector");
    scale(a, 1.0 / l)
}

/// Orthonormal `e1, e2` perpendicular to unit `n` (Duff et al. 2017, "Building an orthonormal
/// basis, revisited"). Any orthonormal pair would do: the result does not depend on it.
fn basis(n: V3) -> (V3, V3) {
    let sign = 1.0f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    let e1 = [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
    let e2 = [b, sign + n[1] * n[1] * a, -n[1]];
    (e1, e2)
}

/// Which weight to integrate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weight {
    /// `(n.w)/pi` — the result is `F`.
    Cosine,
    /// `1/(2 pi)` — the result is `G`.
    Uniform,
}

/// Diagnostics of one evaluation.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Number of azimuth sub-intervals integrated.
    pub intervals: usize,
    /// Number of evaluations of the azimuthal integrand `f(p)`.
    pub evaluations: usize,
    /// Deepest tanh-sinh level used (step `2^-level`).
    pub max_level: usize,
    /// Sub-intervals whose successive estimates never agreed to the tolerance (should be 0).
    pub unconverged: usize,
}

/// Cosine-weighted covered fraction `F` of the hemisphere around `n` (see the crate docs).
/// `caps` are `(axis, cos_half_angle)` with `cos_half_angle` in `[0, 1)`; vectors need not be
/// exactly normalised (they are normalised here).
pub fn covered_cosine(n: V3, caps: &[(V3, f64)]) -> f64 {
    covered_with_stats(n, caps, Weight::Cosine).0
}

/// Uniformly weighted covered fraction `G` (solid angle of `H ∩ U` over `2 pi`).
pub fn covered_uniform(n: V3, caps: &[(V3, f64)]) -> f64 {
    covered_with_stats(n, caps, Weight::Uniform).0
}

/// One cap expressed in the frame `(e1, e2, n)`.
#[derive(Clone, Copy, Debug)]
struct Cap {
    /// The unit axis in world coordinates (for circle-circle intersections).
    axis: V3,
    /// Axis components along e1, e2, n.
    a1: f64,
    a2: f64,
    a3: f64,
    /// cos and sin of the half-angle.
    c: f64,
    s: f64,
}

/// Same as [`covered_cosine`] / [`covered_uniform`], also returning diagnostics.
pub fn covered_with_stats(n: V3, caps: &[(V3, f64)], weight: Weight) -> (f64, Stats) {
    let n = normalize(n);
    let (e1, e2) = basis(n);
    let stats = Stats::default();

    let mut cs: Vec<Cap> = Vec::with_capacity(caps.len());
    for &(axis, c) in caps {
        assert!((0.0..1.0).contains(&c), "cap cosine {c} outside [0, 1)");
        let axis = normalize(axis);
        let s = ((1.0 - c) * (1.0 + c)).sqrt();
        let a3 = dot(axis, n);
        // The highest point of the cap has n.w = cos(theta - s) with cos(theta) = a3, which is
        // <= 0 iff theta >= pi/2 + s iff a3 <= -sin(s): such a cap meets H in at most a point.
        if a3 <= -s {
            continue;
        }
        cs.push(Cap {
            axis,
            a1: dot(axis, e1),
            a2: dot(axis, e2),
            a3,
            c,
            s,
        });
    }
    if cs.is_empty() {
        return (0.0, stats);
    }

    let bps = breakpoints(n, e1, e2, &cs);
    let mut eval = Integrand {
        caps: &cs,
        tris: &[],
        flats: &[],
        reach: f64::INFINITY,
        n,
        e1,
        e2,
        weight,
        buf: Vec::with_capacity(cs.len()),
    };

    integrate_azimuth(&bps, &mut eval, weight, stats)
}

/// The integral of `eval` over the azimuth, between each breakpoint of `bps` and the next
/// (round the circle), summed with Neumaier (compensated) summation, as a covered fraction
/// under `weight`.
fn integrate_azimuth(
    bps: &[f64],
    eval: &mut Integrand<'_>,
    weight: Weight,
    mut stats: Stats,
) -> (f64, Stats) {
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    for i in 0..bps.len() {
        let a = bps[i];
        let b = if i + 1 < bps.len() {
            bps[i + 1]
        } else {
            bps[0] + TAU
        };
        let v = tanh_sinh(|p| eval.f(p), a, b, &mut stats);
        let t = sum + v;
        comp += if sum.abs() >= v.abs() {
            (sum - t) + v
        } else {
            (v - t) + sum
        };
        sum = t;
    }
    let total = sum + comp;
    let result = match weight {
        Weight::Cosine => total / PI,
        Weight::Uniform => total / TAU,
    };
    (result, stats)
}

/// The azimuthal integrand `f(p)`: exact integral over the covered polar angles.
struct Integrand<'a> {
    caps: &'a [Cap],
    /// Triangles, corners relative to the point, met within `reach`.
    tris: &'a [[V3; 3]],
    /// Per triangle, its corners in the tangent plane.
    flats: &'a [[bool; 3]],
    reach: f64,
    n: V3,
    e1: V3,
    e2: V3,
    weight: Weight,
    buf: Vec<(f64, f64)>,
}

impl Integrand<'_> {
    fn f(&mut self, p: f64) -> f64 {
        let (sp, cp) = p.sin_cos();
        self.buf.clear();
        for cap in self.caps {
            // axis.u(p) and the meridian representation axis.w = rho cos(t - beta).
            let au = cap.a1 * cp + cap.a2 * sp;
            // rho^2 - c^2 (> 0 iff the meridian's great circle enters the cap's interior).
            let d2 = au * au + cap.a3 * cap.a3 - cap.c * cap.c;
            if d2 <= 0.0 {
                continue;
            }
            let beta = au.atan2(cap.a3); // in (-pi, pi]
            let g = d2.sqrt().atan2(cap.c); // = acos(c / rho), in (0, pi/2]
                                            // Only the unshifted copy can meet [0, pi/2] in more than a point (crate docs).
            let lo = (beta - g).max(0.0);
            let hi = (beta + g).min(FRAC_PI_2);
            if lo < hi {
                self.buf.push((lo, hi));
            }
        }
        if !self.tris.is_empty() {
            let u = add(scale(self.e1, cp), scale(self.e2, sp));
            for (tri, &flat) in self.tris.iter().zip(self.flats) {
                if let Some(iv) = triangle_on_meridian(tri, flat, self.n, u, self.reach) {
                    self.buf.push(iv);
                }
            }
        }
        if self.buf.is_empty() {
            return 0.0;
        }
        self.buf.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
        let piece = |t0: f64, t1: f64| match self.weight {
            // (sin^2 t1 - sin^2 t0) / 2
            Weight::Cosine => 0.5 * (t1 - t0).sin() * (t1 + t0).sin(),
            // cos t0 - cos t1
            Weight::Uniform => 2.0 * (0.5 * (t1 + t0)).sin() * (0.5 * (t1 - t0)).sin(),
        };
        let mut total = 0.0;
        let (mut cl, mut ch) = self.buf[0];
        for &(lo, hi) in &self.buf[1..] {
            if lo <= ch {
                ch = ch.max(hi);
            } else {
                total += piece(cl, ch);
                cl = lo;
                ch = hi;
            }
        }
        total + piece(cl, ch)
    }
}

/// Circle pairs whose intersection equation misses a (double) root by less than this still get
/// the (tangency) point as a breakpoint. Not needed for correctness (nearly tangent circles that
/// do not cross leave f analytic), merely defensive: extra breakpoints are harmless.
const NEAR: f64 = 1e-10;

/// Sorted azimuths in `[0, 2pi)` (always including 0) at which `f` may be non-analytic.
fn breakpoints(n: V3, e1: V3, e2: V3, caps: &[Cap]) -> Vec<f64> {
    // The quarter points are not needed, but cheap; they keep sub-intervals short.
    let mut p: Vec<f64> = vec![0.0, FRAC_PI_2, PI, 3.0 * FRAC_PI_2];
    for cap in caps {
        // In the azimuth plane, axis.u(p) = r cos(p - phi).
        let r = cap.a1.hypot(cap.a2);
        let phi = cap.a2.atan2(cap.a1);

        // (a) Tangency of a meridian: rho(p)^2 = c^2, i.e. (r cos(p - phi))^2 = c^2 - a3^2 =: q^2.
        //     cos(p - phi) = ±q/r, and since r^2 + a3^2 = 1, sqrt(1 - (q/r)^2) = sin(s)/r, so
        //     p - phi = ±atan2(sin s, ±q) (no acos near ±1). q = 0 is the boundary through the pole.
        let q2 = (cap.c - cap.a3.abs()) * (cap.c + cap.a3.abs());
        if q2 >= 0.0 && r > 0.0 {
            let q = q2.sqrt();
            for th in [cap.s.atan2(q), cap.s.atan2(-q)] {
                p.push(phi + th);
                p.push(phi - th);
            }
        }
        //     When q^2 < 0 (|a3| > c: the cap contains n or -n) the zeros of rho^2 - c^2 (branch
        //     points of g) and of rho^2 (branch points of beta) are complex, at
        //     Re p = phi ± pi/2, Im p = asinh(sqrt(a3^2 - c^2)/r) resp. asinh(|a3|/r). They come
        //     close to the real axis when the boundary nearly passes through the pole (or the axis
        //     is nearly on the horizon) and would then make f steep there. Putting breakpoints at
        //     phi ± pi/2 (the azimuths of minimal rho) turns such a near-singularity into an
        //     end-point one, which tanh-sinh handles. These are the only non-real singularities
        //     of the formulas for f (the clipping and merging are decided on real p only).
        p.push(phi + FRAC_PI_2);
        p.push(phi - FRAC_PI_2);

        // (b) Boundary crossing the horizon: w = u(p), axis.w = r cos(p - phi) = c.
        let h2 = (r - cap.c) * (r + cap.c);
        if h2 >= 0.0 {
            let th = h2.sqrt().atan2(cap.c);
            p.push(phi + th);
            p.push(phi - th);
        }
    }

    // (c) Intersections of two boundary circles (only those in the closed upper hemisphere matter).
    for i in 0..caps.len() {
        for j in (i + 1)..caps.len() {
            for x in circle_intersections(caps[i].axis, caps[i].c, caps[j].axis, caps[j].c)
                .into_iter()
                .flatten()
            {
                if dot(x, n) >= -1e-9 {
                    p.push(dot(x, e2).atan2(dot(x, e1)));
                }
            }
        }
    }

    sorted_azimuths(p)
}

/// [`breakpoints`] of `circles` (each with the occluder whose boundary it bounds, `None` for a
/// whole cap, and whether it is a triangle's edge), with the azimuths `extra` added; of the
/// crossings of two circles only those that `on_boundary` keeps for both occluders.
fn breakpoints_of(
    n: V3,
    e1: V3,
    e2: V3,
    circles: &[(Cap, Option<usize>, bool)],
    extra: &[f64],
    on_boundary: impl Fn(V3, Option<usize>) -> bool,
) -> Vec<f64> {
    let caps: Vec<Cap> = circles.iter().map(|c| c.0).collect();
    // (a) and (b) of every circle, without the crossings (none of one circle alone).
    let mut p: Vec<f64> = Vec::new();
    for cap in &caps {
        p.extend(breakpoints(n, e1, e2, std::slice::from_ref(cap)));
    }
    p.extend_from_slice(extra);
    for i in 0..caps.len() {
        for j in (i + 1)..caps.len() {
            if circles[i].2 && circles[j].2 && circles[i].1 == circles[j].1 {
                // Two edges of one triangle cross at its corners, already in.
                continue;
            }
            for x in circle_intersections(caps[i].axis, caps[i].c, caps[j].axis, caps[j].c)
                .into_iter()
                .flatten()
            {
                if dot(x, n) >= -1e-9
                    && on_boundary(x, circles[i].1)
                    && on_boundary(x, circles[j].1)
                {
                    p.push(dot(x, e2).atan2(dot(x, e1)));
                }
            }
        }
    }
    sorted_azimuths(p)
}

/// The finite angles of `p` in `[0, 2π)`, sorted, with (near-)duplicates dropped:
/// sub-intervals shorter than 1e-14 carry nothing, and moving a breakpoint by < 1e-14
/// changes the quadrature error by O((1e-14)^1.5).
fn sorted_azimuths(p: Vec<f64>) -> Vec<f64> {
    let mut p: Vec<f64> = p
        .into_iter()
        .filter(|v| v.is_finite())
        .map(|v| {
            let w = v.rem_euclid(TAU);
            if w >= TAU {
                0.0
            } else {
                w
            }
        })
        .collect();
    p.sort_unstable_by(|a, b| a.total_cmp(b));
    let mut out: Vec<f64> = Vec::with_capacity(p.len());
    for v in p {
        if out.last().is_none_or(|&l| v - l > 1e-14) {
            out.push(v);
        }
    }
    while out.len() > 1 && out[0] + TAU - out[out.len() - 1] <= 1e-14 {
        out.pop();
    }
    out
}

/// Intersection points of the circles `{a.x = ca}` and `{b.x = cb}` on the unit sphere, written
/// as `x = alpha a + beta b + gamma (a x b)`: the two linear conditions give alpha, beta and
/// `|x| = 1` gives `gamma^2 = (1 - alpha ca - beta cb) / |a x b|^2`. `None` for (nearly) coaxial
/// circles (they coincide or are disjoint: no crossing of interval ends) or disjoint circles.
/// Tangent circles give a double point (kept; it is harmless).
fn circle_intersections(a: V3, ca: f64, b: V3, cb: f64) -> Option<[V3; 2]> {
    let w = cross(a, b);
    let s2 = dot(w, w); // = 1 - (a.b)^2, computed without cancellation
    if s2 < 1e-20 {
        return None;
    }
    let d = dot(a, b);
    let alpha = (ca - cb * d) / s2;
    let beta = (cb - ca * d) / s2;
    let g2 = (1.0 - alpha * ca - beta * cb) / s2;
    if g2 < -NEAR {
        return None;
    }
    let gamma = g2.max(0.0).sqrt();
    let base = add(scale(a, alpha), scale(b, beta));
    Some([add(base, scale(w, gamma)), add(base, scale(w, -gamma))])
}

// ---------------------------------------------------------------------------------------------
// Tanh-sinh quadrature.
//
// integral_a^b f = hl * integral_{-inf}^{inf} f(m + hl x(tau)) x'(tau) dtau with
// x(tau) = tanh(pi/2 sinh tau), x'(tau) = (pi/2) cosh tau / cosh^2(pi/2 sinh tau), m the midpoint
// and hl the half length. The trapezoidal rule with step h = 2^-k converges double
// exponentially for f analytic inside (a, b), even with algebraic end-point singularities. Nodes
// are placed at a + hl d and b - hl d with d = 1 - tanh(u) = 2/(e^{2u} + 1) computed directly, so
// nodes next to the ends are accurate. The integrand here is bounded (0 <= f <= 1), so truncating
// at |tau| <= 3.5 (weight < 3e-21, 1 - x < 6e-23) loses nothing.

const TMAX: f64 = 3.5;
const MIN_LEVEL: usize = 4;
const MAX_LEVEL: usize = 10;

/// `levels[k]` = (d, weight) of the nodes tau > 0 that are new at level k.
fn ts_table() -> &'static Vec<Vec<(f64, f64)>> {
    static TABLE: OnceLock<Vec<Vec<(f64, f64)>>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=MAX_LEVEL)
            .map(|k| {
                let h = 0.5f64.powi(k as i32);
                let mut v = Vec::new();
                let mut m = 1usize;
                loop {
                    // level 0: tau = 1, 2, 3; level k >= 1: odd multiples of h.
                    let tau = if k == 0 {
                        m as f64
                    } else {
                        (2 * m - 1) as f64 * h
                    };
                    if tau > TMAX {
                        break;
                    }
                    let u = FRAC_PI_2 * tau.sinh();
                    let d = 2.0 / ((2.0 * u).exp() + 1.0);
                    let w = FRAC_PI_2 * tau.cosh() / (u.cosh() * u.cosh());
                    v.push((d, w));
                    m += 1;
                }
                v
            })
            .collect()
    })
}

/// Integral of `f` over `[a, b]`, refined until successive levels agree to ~1e-15.
fn tanh_sinh<F: FnMut(f64) -> f64>(mut f: F, a: f64, b: f64, stats: &mut Stats) -> f64 {
    stats.intervals += 1;
    let hl = 0.5 * (b - a);
    let m = a + hl;
    let table = ts_table();
    let mut evals = 1;
    // acc = sum of weight * f over all nodes so far (tau = 0 has weight pi/2).
    let mut acc = FRAC_PI_2 * f(m);
    let mut prev = f64::NAN;
    let mut result = 0.0;
    for (k, level) in table.iter().enumerate() {
        for &(d, w) in level {
            acc += w * (f(a + hl * d) + f(b - hl * d));
        }
        evals += 2 * level.len();
        let h = 0.5f64.powi(k as i32);
        result = hl * h * acc;
        stats.max_level = stats.max_level.max(k);
        let tol = 1e-15 + 16.0 * f64::EPSILON * result.abs();
        if k >= MIN_LEVEL && (result - prev).abs() <= tol {
            stats.evaluations += evals;
            return result;
        }
        prev = result;
    }
    stats.evaluations += evals;
    stats.unconverged += 1;
    result
}
