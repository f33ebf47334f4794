//! An independent brute-force reference for the gas part of a camera ray's radiance (docs/model.md
//! section 3: emission, absorption and single scattering), shared by the gas tests. It
//! shares no code with `src/`: no BVH, no adaptivity, no closed forms, no shadow-volume
//! formulas.
//!
//! - The ray is cut at every gas sphere's entry and exit, and at every shadow boundary: for
//!   each light and sphere, `gap(t)` = (distance from the sphere's centre to the light path
//!   from `x(t)`) - radius is negative exactly when that light path enters the sphere. A
//!   sphere's shadow is convex, so `gap < 0` on one interval of the ray at most; its ends
//!   are found by a scan, golden section to the minimum and bisection ([`shadow_interval`]).
//!   On each piece between cuts, only the spheres whose shadow interval holds the piece are
//!   looped over for that light (the others provably cannot shadow any point of it).
//! - Point lights also cut where the attenuation's `max(.., 1)` switches and at the ray's
//!   closest approach to the light.
//! - Each piece between cuts is smooth, except for `sqrt(t - a)` behaviour at its ends (a
//!   light path's chord through a sphere at a shadow boundary). Each half-piece is mapped by
//!   `t - a = H u^2`, which makes it smooth in `u`, and integrated by 8-point Gauss-Legendre
//!   on cells in `u` refined geometrically towards the end (thin boundary layers of dense
//!   shadowers), each cell cut into `panels` equal panels. Callers check the reference by
//!   comparing `panels` 1 and 2 ([`checked`]).

use std::sync::OnceLock;

use glam::DVec3;

#[derive(Clone, Copy, Debug)]
pub struct Ball {
    pub c: DVec3,
    pub r: f64,
    /// None: opaque (grey, diffuse 0.5). Some((transparency, C, a)): gas.
    pub gas: Option<(f64, DVec3, DVec3)>,
}

#[derive(Clone, Copy, Debug)]
pub enum Lamp {
    /// `to_light` is a unit vector; `power` = colour * intensity.
    Dir { to_light: DVec3, power: DVec3 },
    /// Attenuation `1 / max(att.x + att.y d + att.z d^2, 1)`; radius 1000.
    Point { p: DVec3, power: DVec3, att: DVec3 },
}

/// The scene as VRML (headlight off, no Viewpoint: the tests trace their own rays).
pub fn vrml(balls: &[Ball], lamps: &[Lamp]) -> String {
    let mut s = String::from("NavigationInfo { headlight FALSE }\n");
    for l in lamps {
        match *l {
            Lamp::Dir { to_light, power } => s.push_str(&format!(
                "DirectionalLight {{ direction {} {} {} color {} {} {} intensity 1 }}\n",
                -to_light.x, -to_light.y, -to_light.z, power.x, power.y, power.z
            )),
            Lamp::Point { p, power, att } => s.push_str(&format!(
                "PointLight {{ location {} {} {} color {} {} {} intensity 1 attenuation {} {} {} radius 1000 }}\n",
                p.x, p.y, p.z, power.x, power.y, power.z, att.x, att.y, att.z
            )),
        }
    }
    for b in balls {
        let mat = match b.gas {
            None => "diffuseColor 0.5 0.5 0.5".to_string(),
            Some((tr, c, a)) => format!(
                "transparency {tr:e} emissiveColor {} {} {} diffuseColor {} {} {}",
                c.x, c.y, c.z, a.x, a.y, a.z
            ),
        };
        s.push_str(&format!(
            "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ {mat} }} }} geometry Sphere {{ radius {} }} }} }}\n",
            b.c.x, b.c.y, b.c.z, b.r
        ));
    }
    s
}

/// Roots of the line o + t w (|w| = 1) with a sphere, from the distance of the centre to the
/// line (no b^2 - ac cancellation).
pub fn roots(o: DVec3, w: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    let f = o - c;
    let b = f.dot(w);
    let v = (f - b * w).length();
    if v >= r {
        return None;
    }
    let h = ((r - v) * (r + v)).sqrt();
    Some((-b - h, -b + h))
}

pub fn sigma_of(b: &Ball) -> f64 {
    b.gas.map_or(0.0, |(tr, _, _)| -f64::ln(tr) / (2.0 * b.r))
}

/// Whether the camera ray meets an opaque sphere in front of it.
pub fn hits_opaque(balls: &[Ball], o: DVec3, w: DVec3) -> bool {
    balls
        .iter()
        .filter(|b| b.gas.is_none())
        .any(|b| roots(o, w, b.c, b.r).is_some_and(|r| r.0 > 0.0))
}

/// Distance from the centre of `b` to the light path from `x` (the ray towards a
/// directional light, the segment to a point light), minus the radius.
fn gap(b: &Ball, lamp: &Lamp, x: DVec3) -> f64 {
    let q = b.c - x;
    let closest = match *lamp {
        Lamp::Dir { to_light, .. } => to_light * q.dot(to_light).max(0.0),
        Lamp::Point { p, .. } => {
            let s = p - x;
            let l2 = s.length_squared();
            if l2 == 0.0 {
                DVec3::ZERO
            } else {
                s * (q.dot(s) / l2).clamp(0.0, 1.0)
            }
        }
    };
    (q - closest).length() - b.r
}

/// Where along `[t0, t1]` the light path from `o + t w` enters `b`: the interval
/// `{t : gap(t) < 0}` (None if empty), with its ends inside `(t0, t1)` refined to an ulp.
///
/// The shadow `S = {p + m (y - p) : y in b, m >= 1}` of a ball (and likewise `b + R+ L` for a
/// directional light) is convex: a convex combination of two such points is again one, with
/// `m` the combined weight and `y` a convex combination of two points of `b`. The same holds
/// for the ball of any radius about the centre, so every sublevel set of `gap` along a line
/// is an interval: `gap` is quasiconvex along the ray. Its minimum is bracketed by the
/// lowest of a uniform scan and refined by golden section; then each end of the shadow is a
/// single sign change, found by bisection. (The only flat part, `gap = |c - p| - r` where
/// the segment's closest point is the light, is at the maximum, so it cannot hide the
/// minimum from the scan.)
pub fn shadow_interval(
    b: &Ball,
    lamp: &Lamp,
    o: DVec3,
    w: DVec3,
    t0: f64,
    t1: f64,
) -> Option<(f64, f64)> {
    let g = |t: f64| gap(b, lamp, o + t * w);
    const SCAN: usize = 64;
    let ts: Vec<f64> = (0..=SCAN)
        .map(|k| t0 + (t1 - t0) * k as f64 / SCAN as f64)
        .collect();
    let gs: Vec<f64> = ts.iter().map(|&t| g(t)).collect();
    let low = gs.iter().copied().fold(f64::INFINITY, f64::min);
    let first = gs.iter().position(|&v| v == low).unwrap_or(0);
    let last = gs.iter().rposition(|&v| v == low).unwrap_or(0);
    // Golden section keeping a middle point no higher than the bracket's ends.
    let (mut lo, mut hi) = (ts[first.saturating_sub(1)], ts[(last + 1).min(SCAN)]);
    let (mut x, mut gx) = (ts[first], low);
    let ratio = 0.381_966_011_250_105_1;
    for _ in 0..200 {
        if gx < 0.0 || hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
            break;
        }
        let u = if x - lo > hi - x {
            x - ratio * (x - lo)
        } else {
            x + ratio * (hi - x)
        };
        let gu = g(u);
        if gu < gx {
            if u < x {
                hi = x;
            } else {
                lo = x;
            }
            (x, gx) = (u, gu);
        } else if u < x {
            lo = u;
        } else {
            hi = u;
        }
    }
    if gx >= 0.0 {
        return None;
    }
    // Each end: gap >= 0 on one side, < 0 on the other.
    let edge = |mut inside: f64, mut outside: f64| {
        for _ in 0..200 {
            let m = 0.5 * (inside + outside);
            if m == inside || m == outside {
                break;
            }
            if g(m) < 0.0 {
                inside = m;
            } else {
                outside = m;
            }
        }
        0.5 * (inside + outside)
    };
    let start = if gs[0] < 0.0 { t0 } else { edge(x, t0) };
    let end = if gs[SCAN] < 0.0 { t1 } else { edge(x, t1) };
    Some((start, end))
}

/// Whether some light path from `o + t w`, `t` in `[t0, t1]`, enters `b` (the ray passes
/// through `b`'s shadow there), by the same search as [`reference`].
pub fn in_shadow_somewhere(b: &Ball, lamp: &Lamp, o: DVec3, w: DVec3, t0: f64, t1: f64) -> bool {
    shadow_interval(b, lamp, o, w, t0, t1).is_some()
}

/// 8-point Gauss-Legendre nodes and weights on [-1, 1], by Newton's method on P_8.
pub fn gauss_legendre() -> &'static [(f64, f64)] {
    static GL: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    GL.get_or_init(|| {
        let n = 8usize;
        let legendre = |x: f64| {
            // P_n(x) and P_n'(x) by the three-term recurrence.
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
                for _ in 0..50 {
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
    })
}

/// What a lamp sends to `x` through the spheres `near` (indices into `balls`): an opaque
/// sphere entered blocks it, gas attenuates it by its chord.
fn arriving(balls: &[Ball], near: &[usize], lamp: &Lamp, x: DVec3) -> DVec3 {
    let (dir, dist, power, att) = match *lamp {
        Lamp::Dir { to_light, power } => (to_light, f64::INFINITY, power, 1.0),
        Lamp::Point { p, power, att } => {
            let d = (p - x).length();
            if d == 0.0 {
                return DVec3::ZERO;
            }
            (
                (p - x) / d,
                d,
                power,
                1.0 / (att.x + att.y * d + att.z * d * d).max(1.0),
            )
        }
    };
    let mut tau = 0.0;
    for &k in near {
        let b = &balls[k];
        if let Some((t0, t1)) = roots(x, dir, b.c, b.r) {
            match b.gas {
                None if t0 > 0.0 && t0 < dist => return DVec3::ZERO,
                None => {}
                Some(_) => tau += sigma_of(b) * (t1.min(dist) - t0.max(0.0)).max(0.0),
            }
        }
    }
    power * att * (-tau).exp()
}

/// The reference along one camera ray.
#[derive(Clone, Copy, Debug)]
pub struct Reference {
    /// Emission plus single scattering of the gas in front of the first opaque hit.
    pub gas: DVec3,
    /// Pieces integrated (camera events and shadow boundaries).
    pub pieces: usize,
}

/// The gas part of the camera ray `o + t w` (`|w| = 1`, background black) with `panels`
/// Gauss-Legendre panels per cell.
pub fn reference(balls: &[Ball], lamps: &[Lamp], o: DVec3, w: DVec3, panels: usize) -> Reference {
    assert!((w.length() - 1.0).abs() < 1e-12, "w must be a unit vector");
    let t_end = balls
        .iter()
        .filter(|b| b.gas.is_none())
        .filter_map(|b| roots(o, w, b.c, b.r).map(|r| r.0).filter(|&t| t > 0.0))
        .fold(f64::INFINITY, f64::min);
    let mut cuts = vec![0.0];
    for b in balls.iter().filter(|b| b.gas.is_some()) {
        if let Some((t0, t1)) = roots(o, w, b.c, b.r) {
            cuts.extend([t0, t1].into_iter().filter(|&t| t > 0.0 && t < t_end));
        }
    }
    let t_max = cuts.iter().copied().fold(0.0, f64::max);
    if t_max == 0.0
        && !balls
            .iter()
            .any(|b| b.gas.is_some() && (o - b.c).length() < b.r)
    {
        return Reference {
            gas: DVec3::ZERO,
            pieces: 0,
        };
    }
    let t_max = if t_max == 0.0 { t_end } else { t_max };

    // Shadow boundaries, and per lamp the spheres some light path from [0, t_max] enters
    // (the others cannot shadow any point of this ray).
    // Per lamp: (sphere, start, end of the part of [0, t_max] it shadows).
    let mut shadows: Vec<Vec<(usize, f64, f64)>> = vec![Vec::new(); lamps.len()];
    for (li, lamp) in lamps.iter().enumerate() {
        for (k, b) in balls.iter().enumerate() {
            if let Lamp::Point { p, .. } = *lamp {
                let dc = (p - b.c).length();
                if (dc - b.r).abs() <= 1e-12 * b.r {
                    // A light on the surface: its paths enter the sphere from exactly the
                    // inner side of the tangent plane at the light, a boundary the gap (~0 on
                    // the whole other side) cannot locate by its sign.
                    let n = (p - b.c) / dc;
                    if w.dot(n) != 0.0 {
                        cuts.push((p - o).dot(n) / w.dot(n));
                    }
                    shadows[li].push((k, 0.0, t_max));
                    continue;
                }
            }
            if let Some((ta, tb)) = shadow_interval(b, lamp, o, w, 0.0, t_max) {
                cuts.extend([ta, tb]);
                shadows[li].push((k, ta, tb));
            }
        }
        if let Lamp::Point { p, att, .. } = *lamp {
            // Closest approach to the light, and where a0 + a1 d + a2 d^2 crosses 1.
            cuts.push((p - o).dot(w));
            let (a, b, c) = (att.z, att.y, att.x - 1.0);
            let ds: Vec<f64> = if a != 0.0 {
                let disc = b * b - 4.0 * a * c;
                if disc >= 0.0 {
                    vec![
                        (-b + disc.sqrt()) / (2.0 * a),
                        (-b - disc.sqrt()) / (2.0 * a),
                    ]
                } else {
                    vec![]
                }
            } else if b != 0.0 {
                vec![-c / b]
            } else {
                vec![]
            };
            for d in ds.into_iter().filter(|&d| d > 0.0) {
                if let Some((t0, t1)) = roots(o, w, p, d) {
                    cuts.extend([t0, t1]);
                }
            }
        }
    }
    cuts.retain(|&t| (0.0..=t_max).contains(&t));
    cuts.push(t_max);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();

    // Geometric cells in u towards each end of a half-piece, deep enough that the boundary
    // layer of the densest shadower (width ~ 1 / tau in u) spans several cells.
    let tau_max = balls
        .iter()
        .filter_map(|b| b.gas.map(|(tr, _, _)| -f64::ln(tr)))
        .fold(0.0, f64::max);
    let levels = (tau_max.max(1e-3).log2().ceil() as i32 + 6).clamp(0, 24);
    let mut cells = vec![(0.0, 0.5f64.powi(levels))];
    for k in (0..levels).rev() {
        cells.push((0.5f64.powi(k + 1), 0.5f64.powi(k)));
    }
    let gl = gauss_legendre();
    let phase = 0.25 / std::f64::consts::PI;
    let (mut l, mut tau) = (DVec3::ZERO, 0.0);
    let mut pieces = 0;
    for pair in cuts.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b <= a {
            continue;
        }
        let mid = o + 0.5 * (a + b) * w;
        let (mut sig, mut emit, mut alb) = (0.0, DVec3::ZERO, DVec3::ZERO);
        for ball in balls {
            if let Some((_, c, al)) = ball.gas {
                if (mid - ball.c).length() < ball.r {
                    let s = sigma_of(ball);
                    sig += s;
                    emit += s * c;
                    alb += s * al;
                }
            }
        }
        if sig == 0.0 {
            continue;
        }
        pieces += 1;
        // The piece lies inside or outside each shadow interval (their ends are cuts): only
        // the spheres shadowing its midpoint can shadow any of it.
        let tm = 0.5 * (a + b);
        let near: Vec<Vec<usize>> = shadows
            .iter()
            .map(|sh| {
                sh.iter()
                    .filter(|&&(_, ta, tb)| ta <= tm && tm <= tb)
                    .map(|&(k, _, _)| k)
                    .collect()
            })
            .collect();
        let half = 0.5 * (b - a);
        for (end, dir) in [(a, 1.0), (b, -1.0)] {
            for &(u0, u1) in &cells {
                let du = (u1 - u0) / panels as f64;
                for p in 0..panels {
                    for &(x, wt) in gl {
                        let u = u0 + du * (p as f64 + 0.5 + 0.5 * x);
                        let t = end + dir * half * u * u;
                        // dt = 2 H u du.
                        let weight = 0.5 * du * wt * 2.0 * half * u;
                        let pos = o + t * w;
                        let mut e = DVec3::ZERO;
                        if alb != DVec3::ZERO {
                            for (lamp, nr) in lamps.iter().zip(&near) {
                                e += arriving(balls, nr, lamp, pos);
                            }
                        }
                        let trans = (-(tau + sig * (t - a))).exp();
                        l += weight * trans * (emit + phase * alb * e);
                    }
                }
            }
        }
        tau += sig * (b - a);
    }
    Reference { gas: l, pieces }
}

/// The reference with 2 panels per cell, and its own error: the largest channel difference
/// from 1 panel per cell.
pub fn checked(balls: &[Ball], lamps: &[Lamp], o: DVec3, w: DVec3) -> (Reference, f64) {
    let coarse = reference(balls, lamps, o, w, 1);
    let fine = reference(balls, lamps, o, w, 2);
    let diff = (fine.gas - coarse.gas).abs().max_element();
    (fine, diff)
}
