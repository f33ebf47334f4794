//! Gas spheres as occluders (docs/model.md section 11): a direction that no opaque occluder
//! blocks within the reach sees the sky through the gas on its way, with the transmittance
//! `T = exp(-τ)` of the part within the reach; AO is the weighted mean of that visibility.
//!
//! The opaque part is exact (the union of caps and regions); the gas takes from it
//! `∫ V (1 - T) dμ` over the hemisphere, `V` the opaque visibility. That integral is taken in
//! polar coordinates about the normal (`θ` from it, `φ` about it): an outer adaptive
//! Gauss-Kronrod quadrature over `φ`, an inner one over `θ` ([`integrate`]). Along a
//! meridian the integrand jumps or bends where it crosses a circle: an opaque cap's or a
//! region's circles (inside which `V` is 0, so the piece is left out, exactly), and the edge
//! and reach circles of the gas balls; the meridian is cut at those crossings, in closed
//! form. The outer integral is cut at the azimuths where one of these circles is tangent to a
//! meridian above the horizon or crosses the horizon. The quadrature's change of variable
//! makes the square-root behaviour at a cut (a chord near a ball's edge) smooth, so each piece
//! converges fast.
//!
//! The error is the quadratures' own estimate (the inner integrals' at most `2π` times their
//! largest), not a bound. The cost is a nested quadrature per point whose pieces grow with
//! the circles, each evaluation summing the depths of the balls: on `samples/gas.wrl` (two
//! opaque spheres in 40 overlapping gas balls), 0.5 to 60 ms per point at `tol` 1e-2 or 1e-3
//! alike, the pieces' first rule already within it. (One integral per ball over its own cap,
//! with `1 - Π T_j = Σ_i (1 - T_i) Π_{j<i} T_j`, took 1.3 times as long there.)

use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, PI, TAU};

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
        if d <= r {
            return Some(Ball {
                prim: p,
                edge: None,
                reach: reach_circle,
            });
        }
        let domain = match blocked_by_ball(x, p.center, r, reach) {
            Blocked::Nothing => return None,
            Blocked::Cap(c) => c,
            // (Within rounding of its surface: on it, the half space towards it.)
            Blocked::Everything => Cap {
                axis: v / d,
                cos: 0.0,
            },
        };
        // Wholly below the horizon: its axis more than 90 degrees plus its radius from `n`.
        let sin = ((1.0 - domain.cos) * (1.0 + domain.cos)).sqrt();
        (domain.axis.dot(n) > -sin).then_some(Ball {
            prim: p,
            edge: Some(Cap {
                axis: v / d,
                cos: (((d - r) * (d + r)).max(0.0)).sqrt() / d,
            }),
            reach: reach_circle,
        })
    }
}

/// Reusable buffers of one worker.
#[derive(Default)]
pub struct GasScratch {
    balls: Vec<Ball>,
    /// The circles the meridians are cut at.
    circles: Vec<Cap>,
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

/// Whether the circle of `c` has a point in the cap `domain`.
fn crosses(c: &Cap, domain: &Cap) -> bool {
    let (delta, beta, theta) = (
        angle(domain.axis, c.axis),
        c.cos.clamp(-1.0, 1.0).acos(),
        domain.cos.clamp(-1.0, 1.0).acos(),
    );
    (delta - beta).abs() <= theta
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
    // The circles the integrand jumps or bends on, all of which cross the hemisphere.
    s.circles.clear();
    let hemisphere = Cap { axis: n, cos: 0.0 };
    s.circles
        .extend(caps.iter().filter(|c| crosses(c, &hemisphere)));
    for k in 0..regions.len() {
        s.circles
            .extend(regions.region(k).iter().filter(|c| crosses(c, &hemisphere)));
    }
    for b in &s.balls {
        for c in [b.edge, b.reach].into_iter().flatten() {
            if crosses(&c, &hemisphere) {
                s.circles.push(c);
            }
        }
    }
    let (u, v) = n.any_orthonormal_pair();
    // The azimuths where a circle is tangent to a meridian or crosses the horizon.
    s.azimuths.clear();
    for c in &s.circles {
        let p = n.dot(c.axis);
        let side = c.axis - p * n;
        let rho = side.length();
        if rho < 1e-14 {
            continue;
        }
        let phi_b = side.dot(v).atan2(side.dot(u));
        // Tangent where the meridian's `e . b = ±sqrt(cos^2 - p^2)`, at `θ = atan2(e . b, p)`
        // (the other side for a circle of negative cosine): kept above the horizon.
        let tangent = c.cos * c.cos - p * p;
        if tangent >= 0.0 && tangent.sqrt() <= rho {
            let q = tangent.sqrt();
            for q in [q, -q] {
                let mut at = q.atan2(p);
                if c.cos < 0.0 {
                    at += if at > 0.0 { -PI } else { PI };
                }
                if at > 0.0 && at < FRAC_PI_2 {
                    let turn = (q / rho).acos();
                    s.azimuths.push(phi_b + turn);
                    s.azimuths.push(phi_b - turn);
                }
            }
        }
        let e = c.cos / rho;
        if e.abs() <= 1.0 {
            s.azimuths.push(phi_b + e.acos());
            s.azimuths.push(phi_b - e.acos());
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
        circles,
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
            let at = |t: f64| t.cos() * n + t.sin() * e;
            // The meridian's crossings of the circles, above the horizon.
            cuts.clear();
            for c in circles.iter() {
                let (p, q) = (n.dot(c.axis), e.dot(c.axis));
                let r = p.hypot(q);
                if r <= c.cos.abs() {
                    continue;
                }
                let (t0, dt) = (q.atan2(p), (c.cos / r).acos());
                for t in [t0 - dt, t0 + dt] {
                    let t = if t <= -PI { t + TAU } else { t };
                    if t > 0.0 && t < FRAC_PI_2 {
                        cuts.push(t);
                    }
                }
            }
            cuts.sort_unstable_by(f64::total_cmp);
            // The pieces no opaque occluder blocks.
            inner_pieces.clear();
            let mut from = 0.0;
            for &to in cuts.iter().chain(std::iter::once(&FRAC_PI_2)) {
                if to > from {
                    let mid = at(0.5 * (from + to));
                    let open = !caps.iter().any(|c| mid.dot(c.axis) >= c.cos)
                        && !(0..regions.len())
                            .any(|k| regions.region(k).iter().all(|c| mid.dot(c.axis) >= c.cos));
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
                    let depth: f64 = balls
                        .iter()
                        .map(|b| gas_depth(prep, &b.prim, x, dir, reach))
                        .sum();
                    DVec3::splat(weight * k * t.sin() * -(-depth).exp_m1())
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
