//! Gas spheres as occluders (docs/model.md section 11): a direction that no opaque occluder
//! blocks within the reach sees the sky through the gas on its way, with the transmittance
//! `T = exp(-τ)` of the part within the reach; AO is the weighted mean of that visibility.
//!
//! The opaque part is exact (the union of caps and regions); the gas takes from it
//! `Σ_i ∫ V (1 - T_i) Π_{j<i} T_j dμ` over the directions, `V` the opaque visibility (since
//! `1 - Π_j T_j = Σ_i (1 - T_i) Π_{j<i} T_j`). Term `i` is zero outside ball `i`'s
//! directions, a cap about the direction of its centre (within the reach, the cap of
//! [`blocked_by_ball`]), or every direction of the hemisphere if the point is inside it. Each
//! term is integrated in polar coordinates about that cap's axis (`θ` from it, `φ` about it):
//! an outer adaptive Gauss-Kronrod quadrature over `φ`, an inner one over `θ`
//! ([`integrate`]). Along a meridian the integrand jumps or bends where it crosses a circle:
//! the horizon, an opaque cap's or a region's circles (inside which `V` is 0, so the piece is
//! left out), and the edge and reach circles of the balls; the meridian is cut at those
//! crossings, in closed form. The outer integral is cut at the azimuths where one of these
//! circles is tangent to a meridian or crosses the edge of the domain. The quadrature's
//! change of variable makes the square-root behaviour at a cut (a chord near a ball's edge)
//! smooth, so each piece converges fast.
//!
//! The error is the quadratures' own estimate, summed over the terms (the inner integrals'
//! estimates at most `2π` times their largest), not a bound. The cost is a nested quadrature
//! per ball near the point, each evaluation summing the depths of the balls before it whose
//! directions overlap its own: on `samples/gas.wrl` (two opaque spheres in 40 overlapping gas
//! balls), `render --integrator ao --width 96 --height 72 --tol 1e-2` (16 samples per pixel)
//! takes 116 s on two threads.

use std::f64::consts::{FRAC_1_PI, PI, TAU};

use glam::DVec3;

use super::cap::{blocked_by_ball, Blocked, Cap};
use super::union::{Regions, Weighting};
use crate::accel::Prim;
use crate::render::density::gas_depth;
use crate::render::quadrature::{integrate, QuadScratch};
use crate::render::Prepared;

/// The most sub-intervals of one outer (azimuth) and one inner (polar angle) integral.
const OUTER_INTERVALS: usize = 256;
const INNER_INTERVALS: usize = 128;

/// A gas ball as seen from the shading point.
#[derive(Clone, Copy, Debug)]
struct Ball {
    prim: Prim,
    /// The directions along which it lies within the reach: every ray in this cap (about the
    /// normal, of angular radius 90 degrees, for a ball the point is inside) may cross it.
    domain: Cap,
    /// Whether the point is inside it.
    inside: bool,
    /// Its edge as seen from outside, where a ray grazes it.
    edge: Option<Cap>,
    /// The directions whose rays reach its surface at exactly the reach.
    reach: Option<Cap>,
}

impl Ball {
    /// Ball `p` from `x` (normal `n`) within `reach`; `None` if it cannot attenuate a ray of
    /// the hemisphere.
    fn seen(p: Prim, x: DVec3, n: DVec3, reach: f64) -> Option<Ball> {
        let v = p.center - x;
        let (d, r) = (v.length(), p.radius);
        let reach_circle = (d > 0.0 && reach.is_finite() && (d - r).abs() < reach && reach < d + r)
            .then(|| Cap {
                axis: v / d,
                cos: (((d - r) * (d + r) + reach * reach) / (2.0 * d * reach)).clamp(-1.0, 1.0),
            });
        let ball = if d <= r {
            Ball {
                prim: p,
                domain: Cap { axis: n, cos: 0.0 },
                inside: true,
                edge: None,
                reach: reach_circle,
            }
        } else {
            let domain = match blocked_by_ball(x, p.center, r, reach) {
                Blocked::Nothing => return None,
                Blocked::Cap(c) => c,
                // (Within rounding of its surface: on it, the half space towards it.)
                Blocked::Everything => Cap {
                    axis: v / d,
                    cos: 0.0,
                },
            };
            Ball {
                prim: p,
                domain,
                inside: false,
                edge: Some(Cap {
                    axis: v / d,
                    cos: (((d - r) * (d + r)).max(0.0)).sqrt() / d,
                }),
                reach: reach_circle,
            }
        };
        // Wholly below the horizon: its axis more than 90 degrees plus its radius from `n`.
        let sin = ((1.0 - ball.domain.cos) * (1.0 + ball.domain.cos)).sqrt();
        (ball.domain.axis.dot(n) > -sin).then_some(ball)
    }
}

/// Reusable buffers of one worker.
#[derive(Default)]
pub struct GasScratch {
    balls: Vec<Ball>,
    /// The balls before the current one whose directions overlap its own.
    before: Vec<usize>,
    /// The circles the current term's meridians are cut at.
    circles: Vec<Cap>,
    /// The opaque caps, and the regions (indices), that overlap the current term's domain.
    blockers: Vec<Cap>,
    regions: Vec<usize>,
    azimuths: Vec<f64>,
    outer_pieces: Vec<(f64, f64)>,
    cuts: Vec<f64>,
    inner_pieces: Vec<(f64, f64)>,
    outer: QuadScratch,
    inner: QuadScratch,
}

impl GasScratch {
    /// Forgets the balls of the last point.
    pub fn clear(&mut self) {
        self.balls.clear();
    }

    /// Takes in gas primitive `p` as a possible occluder of `x` (normal `n`) within `reach`.
    pub fn add(&mut self, p: Prim, x: DVec3, n: DVec3, reach: f64) {
        if let Some(b) = Ball::seen(p, x, n, reach) {
            self.balls.push(b);
        }
    }

    /// Whether no gas ball was taken in.
    pub fn is_empty(&self) -> bool {
        self.balls.is_empty()
    }
}

/// The angle between unit vectors.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// Whether the circle of `c` crosses the cap `domain`.
fn crosses(c: &Cap, domain: &Cap) -> bool {
    let (delta, beta, theta) = (
        angle(domain.axis, c.axis),
        c.cos.clamp(-1.0, 1.0).acos(),
        domain.cos.clamp(-1.0, 1.0).acos(),
    );
    (delta - beta).abs() <= theta
}

/// Whether the caps `a` and `b` overlap.
fn overlap(a: &Cap, b: &Cap) -> bool {
    angle(a.axis, b.axis) < a.cos.clamp(-1.0, 1.0).acos() + b.cos.clamp(-1.0, 1.0).acos()
}

/// What the gas balls taken into `s` take from the unoccluded fraction at `x` (normal `n`),
/// where the opaque occluders block the caps `caps` and the `regions`: the value and its
/// estimated error, to about `tol`.
pub(crate) fn gas_loss(
    prep: &Prepared,
    (x, n): (DVec3, DVec3),
    (reach, w): (f64, Weighting),
    tol: f64,
    (caps, regions): (&[Cap], &Regions),
    s: &mut GasScratch,
) -> (f64, f64) {
    let terms = s.balls.len();
    let tol_term = tol / terms as f64;
    let (mut loss, mut error) = (0.0, 0.0);
    for i in 0..terms {
        let ball = s.balls[i];
        let domain = ball.domain;
        // What overlaps the domain: opaque blockers, regions, earlier balls; the circles.
        s.blockers.clear();
        s.regions.clear();
        s.before.clear();
        s.circles.clear();
        let horizon = Cap { axis: n, cos: 0.0 };
        if !ball.inside && crosses(&horizon, &domain) {
            s.circles.push(horizon);
        }
        let mut buried = false;
        for c in caps {
            if overlap(c, &domain) {
                if angle(c.axis, domain.axis) + domain.cos.clamp(-1.0, 1.0).acos() <= c.cos.acos() {
                    buried = true;
                    break;
                }
                s.blockers.push(*c);
                if crosses(c, &domain) {
                    s.circles.push(*c);
                }
            }
        }
        if buried {
            continue;
        }
        for k in 0..regions.len() {
            let cone = regions.bound(k);
            let bound = Cap {
                axis: cone.axis,
                cos: cone.angle.cos(),
            };
            if overlap(&bound, &domain) {
                s.regions.push(k);
                for c in regions.region(k) {
                    if crosses(c, &domain) {
                        s.circles.push(*c);
                    }
                }
            }
        }
        for j in 0..i {
            let other = &s.balls[j];
            if other.inside || overlap(&other.domain, &domain) {
                s.before.push(j);
                for c in [other.edge, other.reach].into_iter().flatten() {
                    if crosses(&c, &domain) {
                        s.circles.push(c);
                    }
                }
            }
        }
        if let Some(c) = ball.reach {
            if crosses(&c, &domain) {
                s.circles.push(c);
            }
        }
        let (value, err) = term(prep, (x, n), (reach, w), ball, tol_term, (caps, regions), s);
        loss += value;
        error += err;
    }
    (loss, error)
}

/// Term `i` of [`gas_loss`]: `∫ V (1 - T_i) Π_{j<i} T_j dμ` over the domain of `ball`, with
/// `s.blockers`, `s.regions`, `s.before` and `s.circles` made for it.
fn term(
    prep: &Prepared,
    (x, n): (DVec3, DVec3),
    (reach, w): (f64, Weighting),
    ball: Ball,
    tol: f64,
    (_, regions): (&[Cap], &Regions),
    s: &mut GasScratch,
) -> (f64, f64) {
    let a = ball.domain.axis;
    let (u, v) = a.any_orthonormal_pair();
    let cos_t = ball.domain.cos.clamp(-1.0, 1.0);
    let theta = cos_t.acos();
    let sin_t = theta.sin();
    // The azimuths where a circle is tangent to a meridian or crosses the domain's edge.
    s.azimuths.clear();
    for c in &s.circles {
        let p = a.dot(c.axis);
        let side = c.axis - p * a;
        let rho = side.length();
        if rho < 1e-14 {
            continue;
        }
        let phi_b = side.dot(v).atan2(side.dot(u));
        let tangent = (c.cos * c.cos - p * p).max(-1.0);
        if tangent >= 0.0 {
            let t = tangent.sqrt() / rho;
            if t <= 1.0 {
                for q in [t.acos(), (-t).acos()] {
                    s.azimuths.push(phi_b + q);
                    s.azimuths.push(phi_b - q);
                }
            }
        }
        if sin_t > 0.0 {
            let e = (c.cos - p * cos_t) / (sin_t * rho);
            if e.abs() <= 1.0 {
                s.azimuths.push(phi_b + e.acos());
                s.azimuths.push(phi_b - e.acos());
            }
        }
    }
    for phi in s.azimuths.iter_mut() {
        *phi = phi.rem_euclid(TAU);
    }
    s.azimuths.sort_unstable_by(f64::total_cmp);
    s.azimuths.dedup();
    s.outer_pieces.clear();
    match (s.azimuths.first(), s.azimuths.last()) {
        (Some(&first), Some(&last)) => {
            s.outer_pieces
                .extend(s.azimuths.windows(2).map(|p| (p[0], p[1])));
            s.outer_pieces.push((last, first + TAU));
        }
        _ => s.outer_pieces.push((0.0, TAU)),
    }
    let weight = match w {
        Weighting::Cosine => FRAC_1_PI,
        Weighting::Uniform => 0.5 * FRAC_1_PI,
    };
    let mut worst_inner: f64 = 0.0;
    let inner_tol = 0.5 * tol / TAU;
    let GasScratch {
        balls,
        before,
        circles,
        blockers,
        regions: near_regions,
        cuts,
        inner_pieces,
        outer_pieces,
        outer,
        inner,
        ..
    } = s;
    let outer_result = integrate(
        outer_pieces,
        |_, phi| {
            let e = phi.cos() * u + phi.sin() * v;
            let at = |t: f64| t.cos() * a + t.sin() * e;
            // The meridian's crossings of the circles, within (0, theta).
            cuts.clear();
            for c in circles.iter() {
                let (p, q) = (a.dot(c.axis), e.dot(c.axis));
                let r = p.hypot(q);
                if r <= c.cos.abs() {
                    continue;
                }
                let (t0, dt) = (q.atan2(p), (c.cos / r).acos());
                for t in [t0 - dt, t0 + dt] {
                    let t = if t <= -PI { t + TAU } else { t };
                    if t > 0.0 && t < theta {
                        cuts.push(t);
                    }
                }
            }
            cuts.sort_unstable_by(f64::total_cmp);
            inner_pieces.clear();
            let mut from = 0.0;
            for &to in cuts.iter().chain(std::iter::once(&theta)) {
                if to > from {
                    let mid = at(0.5 * (from + to));
                    let open = mid.dot(n) > 0.0
                        && !blockers.iter().any(|c| mid.dot(c.axis) >= c.cos)
                        && !near_regions
                            .iter()
                            .any(|&k| regions.region(k).iter().all(|c| mid.dot(c.axis) >= c.cos));
                    if open {
                        inner_pieces.push((from, to));
                    }
                }
                from = to;
            }
            if inner_pieces.is_empty() {
                return DVec3::ZERO;
            }
            let q = integrate(
                inner_pieces,
                |_, t| {
                    let dir = at(t);
                    let k = match w {
                        Weighting::Cosine => dir.dot(n).max(0.0),
                        Weighting::Uniform => 1.0,
                    };
                    let own = gas_depth(prep, &ball.prim, x, dir, reach);
                    if own <= 0.0 {
                        return DVec3::ZERO;
                    }
                    let earlier: f64 = before
                        .iter()
                        .map(|&j| gas_depth(prep, &balls[j].prim, x, dir, reach))
                        .sum();
                    DVec3::splat(weight * k * t.sin() * (-earlier).exp() * -(-own).exp_m1())
                },
                |_| inner_tol,
                INNER_INTERVALS,
                inner,
            );
            worst_inner = worst_inner.max(q.error);
            q.value
        },
        |_| 0.5 * tol,
        OUTER_INTERVALS,
        outer,
    );
    (outer_result.value.x, outer_result.error + TAU * worst_inner)
}
