//! An independent brute-force reference for the gas part of a camera ray's radiance in scenes
//! of gas spheres with radial density profiles (docs/model.md sections 3 and 6: emission,
//! absorption and single scattering), for the profiled-gas tests. It shares no code with
//! `src/`: no BVH, no closed-form chords, no shadow-volume formulas. Every optical depth is a
//! numerical integral of the density.
//!
//! - **Camera ray.** Cut at every gas sphere's entry and exit, at the closest approach to the
//!   centre of every linear sphere (`f = 1 - u` has a kink there when the ray passes through
//!   the centre, and bends sharply when it passes near it) and every gaussian one (so that a
//!   narrow bump sits at a piece's end, where the cells below are fine), at every shadow
//!   boundary, and where a point light's attenuation switches, as `gas_reference` cuts (its
//!   shadow interval search is copied here: it is private there). Each half-piece is mapped by
//!   `t - a = H u^2` (smooth in `u` where the light's chord grows like `sqrt(t - a)`) and
//!   integrated by 8-point Gauss-Legendre on cells in `u` refined geometrically towards the
//!   end (deep enough for the densest shadower's boundary layer, and for a linear sphere's
//!   bend or a gaussian's bump at the end), each cut into `panels` panels (more for a narrow
//!   gaussian's bump).
//! - **Camera transmittance.** `T(0, t) = exp(-tau(0, t))` with `tau` accumulated in order
//!   along the ray: the nodes of a piece are sorted and the density is integrated between
//!   consecutive nodes (and to the piece's end) by 8-point Gauss-Legendre.
//! - **Light paths.** `V_i(x)`: 0 if an opaque sphere is between `x` and the light, else
//!   `exp(-sum of the light path's optical depth through every gas sphere)`, each a numerical
//!   integral of `sigma0 f` along the chord in the chord's own coordinate `v` (distance from
//!   the closest approach, in radii), split at the closest approach: Gauss-Legendre on cells
//!   graded towards the closest approach down to the scale of the line's distance from the
//!   centre (linear: `sqrt(beta^2 + v^2)` has branch points at `v = +-i beta`), panels no
//!   wider than twice the width (gaussian), or one exact rule (constant, quadratic:
//!   polynomials in `v`). `1 - u^2` is formed as `(h - |v|)(h + |v|)`, `h` the chord's half-length, so that the
//!   density keeps its relative precision near the chord's ends (grazing lines).
//!
//! Callers check the reference by comparing `panels` 2 and 4 ([`checked`]), which refines the
//! camera quadrature, the transmittance integrals and the light chords together. Its own
//! checks below hold it against an unrelated quadrature (tanh-sinh of `f(|x - c| / r)`), closed
//! forms that hold for every profile, and `gas_reference` for the constant profile.

use std::sync::OnceLock;

use glam::DVec3;

use crate::render::integrators::tests::gas_reference::{self, roots, Lamp};

mod quadrature;
use quadrature::*;

mod checks;

/// A radial density profile `f(u)`, `u = |x - c| / r` (docs/model.md section 6): the tests' own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile {
    Constant,
    /// `f = 1 - u`.
    Linear,
    /// `f = 1 - u^2`.
    Quadratic,
    /// `f = exp(-u^2 / (2 s^2))`, cut at `u = 1`; the width `s` is in `(0, 1]`.
    Gaussian(f64),
}

impl Profile {
    /// The name GasParticle's `profile` field takes.
    pub fn name(self) -> &'static str {
        match self {
            Profile::Constant => "constant",
            Profile::Linear => "linear",
            Profile::Quadratic => "quadratic",
            Profile::Gaussian(_) => "gaussian",
        }
    }

    /// `f(u)` as docs/model.md writes it (for the tests' own quadratures).
    pub fn f(self, u: f64) -> f64 {
        match self {
            Profile::Constant => 1.0,
            Profile::Linear => 1.0 - u,
            Profile::Quadratic => 1.0 - u * u,
            Profile::Gaussian(s) => (-u * u / (2.0 * s * s)).exp(),
        }
    }

    /// `f` at `u^2 = beta^2 + v^2` on a chord of half-length `h = sqrt(1 - beta^2)`
    /// (`|v| <= h`), with `1 - u^2 = (h - |v|)(h + |v|)`.
    fn on_chord(self, beta: f64, h: f64, v: f64) -> f64 {
        let a = v.abs();
        match self {
            Profile::Constant => 1.0,
            Profile::Linear => ((h - a) * (h + a)).max(0.0) / (1.0 + (beta * beta + v * v).sqrt()),
            Profile::Quadratic => ((h - a) * (h + a)).max(0.0),
            Profile::Gaussian(s) => (-(beta * beta + v * v) / (2.0 * s * s)).exp(),
        }
    }

    /// `I_f`, the integral of `f` over `[0, 1]`: 1, 1/2, 2/3, and for the gaussian 16-point
    /// Gauss-Legendre on panels no wider than `s / 2` (no `erf` needed).
    pub fn integral(self) -> f64 {
        match self {
            Profile::Constant => 1.0,
            Profile::Linear => 0.5,
            Profile::Quadratic => 2.0 / 3.0,
            Profile::Gaussian(s) => {
                let n = (2.0 / s).ceil() as usize;
                (0..n)
                    .map(|k| {
                        let (a, b) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                        rule_sum(rule(16), a, b, |u| self.f(u))
                    })
                    .sum()
            }
        }
    }
}

/// A sphere: opaque (`gas` None; grey, diffuse 0.5, as in `gas_reference`) or gas
/// `(transparency, C emissive, a diffuse, profile)`.
#[derive(Clone, Copy, Debug)]
pub struct Ball {
    pub c: DVec3,
    pub r: f64,
    pub gas: Option<(f64, DVec3, DVec3, Profile)>,
}

/// The peak extinction `sigma0 = -ln(transparency) / (2 r I_f)` (0 for opaque spheres).
pub fn sigma0(b: &Ball) -> f64 {
    b.gas.map_or(0.0, |(tr, _, _, p)| {
        -f64::ln(tr) / (2.0 * b.r * p.integral())
    })
}

/// The same sphere for `gas_reference` (its profile dropped).
pub fn plain(b: &Ball) -> gas_reference::Ball {
    gas_reference::Ball {
        c: b.c,
        r: b.r,
        gas: b.gas.map(|(tr, e, a, _)| (tr, e, a)),
    }
}

/// The scene as VRML (headlight off, no Viewpoint: the tests trace their own rays): gas
/// spheres as GasParticle instances (every profile, constant included), opaque spheres and
/// lights as `gas_reference::vrml` writes them. Numbers are written in full (`{:e}` is the
/// shortest form that reads back to the same f64).
pub fn vrml(balls: &[Ball], lamps: &[Lamp]) -> String {
    // NavigationInfo and the lights, exactly as gas_reference writes them.
    let mut s = gas_reference::vrml(&[], lamps);
    s.push_str(crate::testing::GAS_PARTICLE_PROTO);
    let v = |p: DVec3| format!("{:e} {:e} {:e}", p.x, p.y, p.z);
    for b in balls {
        match b.gas {
            Some((tr, e, a, profile)) => {
                let width = match profile {
                    Profile::Gaussian(w) => format!(" width {w:e}"),
                    _ => String::new(),
                };
                s.push_str(&format!(
                    "GasParticle {{ position {} radius {:e} color {} emission {} transparency {tr:e} profile \"{}\"{width} }}\n",
                    v(b.c),
                    b.r,
                    v(a),
                    v(e),
                    profile.name()
                ));
            }
            None => s.push_str(&format!(
                "Transform {{ translation {} children Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0.5 0.5 0.5 }} }} geometry Sphere {{ radius {:e} }} }} }}\n",
                v(b.c),
                b.r
            )),
        }
    }
    s
}

/// A ray from `o` whose line passes at distance `rho` (< |c - o|) from `c`, turned about the
/// line `o -> c` by `phi`.
pub fn ray_past(o: DVec3, c: DVec3, rho: f64, phi: f64) -> (DVec3, DVec3) {
    let d = (c - o).length();
    let e = (c - o) / d;
    let n1 = e.any_orthonormal_vector();
    let n2 = e.cross(n1);
    let n = phi.cos() * n1 + phi.sin() * n2;
    let sin = rho / d;
    let cos = ((1.0 - sin) * (1.0 + sin)).sqrt();
    (o, (cos * e + sin * n).normalize())
}

// ---- The reference.

/// The scene with each sphere's peak extinction.
struct Scene<'a> {
    balls: &'a [Ball],
    sigma0: Vec<f64>,
}

/// What lamp sends to `x` through the spheres `near` (indices into the balls): an opaque
/// sphere entered blocks it, gas attenuates it by its optical depth along the light path.
fn arriving(scene: &Scene, near: &[usize], lamp: &Lamp, x: DVec3, panels: usize) -> DVec3 {
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
        let b = &scene.balls[k];
        match b.gas {
            None => {
                if roots(x, dir, b.c, b.r).is_some_and(|(t0, _)| t0 > 0.0 && t0 < dist) {
                    return DVec3::ZERO;
                }
            }
            Some((_, _, _, profile)) => {
                tau += depth_on_line(
                    b.c,
                    b.r,
                    scene.sigma0[k],
                    profile,
                    x,
                    dir,
                    0.0,
                    dist,
                    panels,
                );
            }
        }
    }
    power * att * (-tau).exp()
}

/// A gas sphere the camera ray crosses: its chord and what it adds where it is.
#[derive(Clone, Copy)]
struct Crossing {
    t0: f64,
    t1: f64,
    ch: Chord,
    r: f64,
    sigma0: f64,
    profile: Profile,
    emit: DVec3,
    albedo: DVec3,
}

impl Crossing {
    fn sigma(&self, t: f64) -> f64 {
        self.sigma0
            * self
                .profile
                .on_chord(self.ch.beta, self.ch.h, (t - self.ch.sc) / self.r)
    }
}

/// Extinction, source `sum sigma_j C_j` and scattering `sum sigma_j a_j` at `t`.
fn medium(active: &[Crossing], t: f64) -> (f64, DVec3, DVec3) {
    let (mut sig, mut emit, mut alb) = (0.0, DVec3::ZERO, DVec3::ZERO);
    for x in active {
        let s = x.sigma(t);
        sig += s;
        emit += s * x.emit;
        alb += s * x.albedo;
    }
    (sig, emit, alb)
}

/// `integral_t0^t1 sigma_t dt` by 8-point Gauss-Legendre (between neighbouring nodes).
fn depth_between(active: &[Crossing], t0: f64, t1: f64) -> f64 {
    if t1 <= t0 {
        return 0.0;
    }
    rule_sum(rule(8), t0, t1, |t| active.iter().map(|x| x.sigma(t)).sum())
}

/// The reference along one camera ray.
#[derive(Clone, Copy, Debug)]
pub struct Reference {
    /// Emission plus single scattering of the gas in front of the first opaque hit.
    pub gas: DVec3,
    /// The camera ray's optical depth up to the end of the gas (or the opaque hit).
    pub tau: f64,
    /// Pieces integrated (camera events and shadow boundaries).
    pub pieces: usize,
}

/// The gas part of the camera ray `o + t w` (`|w| = 1`, background black) with `panels`
/// Gauss-Legendre panels per cell.
pub fn reference(balls: &[Ball], lamps: &[Lamp], o: DVec3, w: DVec3, panels: usize) -> Reference {
    assert!((w.length() - 1.0).abs() < 1e-12, "w must be a unit vector");
    let scene = Scene {
        balls,
        sigma0: balls.iter().map(sigma0).collect(),
    };
    let t_end = balls
        .iter()
        .filter(|b| b.gas.is_none())
        .filter_map(|b| roots(o, w, b.c, b.r).map(|r| r.0).filter(|&t| t > 0.0))
        .fold(f64::INFINITY, f64::min);
    let crossings: Vec<Crossing> = balls
        .iter()
        .zip(&scene.sigma0)
        .filter_map(|(b, &sigma0)| {
            let (_, emit, albedo, profile) = b.gas?;
            let ch = chord(o, w, b.c, b.r)?;
            let (t0, t1) = (ch.sc - ch.h * b.r, ch.sc + ch.h * b.r);
            (t1 > 0.0 && t0 < t_end).then_some(Crossing {
                t0,
                t1,
                ch,
                r: b.r,
                sigma0,
                profile,
                emit,
                albedo,
            })
        })
        .collect();
    // The gas ends at the last exit, or at the opaque hit.
    let t_max = crossings
        .iter()
        .map(|x| x.t1)
        .fold(0.0, f64::max)
        .min(t_end);
    if crossings.is_empty() {
        return Reference {
            gas: DVec3::ZERO,
            tau: 0.0,
            pieces: 0,
        };
    }
    let mut cuts = vec![0.0, t_max];
    for x in &crossings {
        cuts.extend([x.t0, x.t1]);
        if matches!(x.profile, Profile::Linear | Profile::Gaussian(_)) {
            cuts.push(x.ch.sc);
        }
    }

    // Shadow boundaries, and per lamp the spheres that shadow some part of [0, t_max]:
    // (sphere, start, end of the part it shadows).
    let mut shadows: Vec<Vec<(usize, f64, f64)>> = vec![Vec::new(); lamps.len()];
    for (li, lamp) in lamps.iter().enumerate() {
        for (k, b) in balls.iter().enumerate() {
            if let Lamp::Point { p, .. } = *lamp {
                let dc = (p - b.c).length();
                if (dc - b.r).abs() <= 1e-12 * b.r {
                    // A light on the surface (see gas_reference): cut at the tangent plane.
                    let n = (p - b.c) / dc;
                    if w.dot(n) != 0.0 {
                        cuts.push((p - o).dot(n) / w.dot(n));
                    }
                    shadows[li].push((k, 0.0, t_max));
                    continue;
                }
            }
            if let Some((ta, tb)) = shadow_interval(b.c, b.r, lamp, o, w, 0.0, t_max) {
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
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();

    // Geometric cells in u towards each end of a half-piece, deep enough that the boundary
    // layer of the densest shadower (peak optical depth over a diameter) spans several.
    let tau_max = balls
        .iter()
        .filter_map(|b| b.gas.map(|(tr, _, _, p)| -f64::ln(tr) / p.integral()))
        .fold(0.0, f64::max);
    let levels = (tau_max.max(1e-3).log2().ceil() as i32 + 6).clamp(4, 24);
    let gl = rule(8);
    let phase = 0.25 / std::f64::consts::PI;
    let (mut l, mut tau) = (DVec3::ZERO, 0.0);
    let mut pieces = 0;
    let mut nodes: Vec<(f64, f64)> = Vec::new();
    for pair in cuts.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if b <= a {
            continue;
        }
        let tm = 0.5 * (a + b);
        let active: Vec<Crossing> = crossings
            .iter()
            .filter(|x| x.t0 <= tm && tm <= x.t1)
            .copied()
            .collect();
        if active.is_empty() {
            continue;
        }
        pieces += 1;
        let scatters = active.iter().any(|x| x.albedo != DVec3::ZERO) && !lamps.is_empty();
        // Only the spheres shadowing the piece's midpoint can shadow any of it.
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
        // A sphere's closest approach at an end of the piece: a linear one's density bends
        // on the scale of beta r there (branch points at beta r from the end), a gaussian's
        // on s r, so the cells reach below it (t - end = H u^2: a cell at u = 2^-k spans
        // ~H 4^-k). A gaussian's bump, ~exp(-(H u^2)^2 / (2 s^2 r^2)), is ~sqrt(s r / H)
        // wide in u: the cells get more panels when that is narrow.
        let (mut deep, mut more) = (levels, 1usize);
        for x in active.iter().filter(|x| x.ch.sc == a || x.ch.sc == b) {
            let scale = match x.profile {
                Profile::Linear => x.ch.beta * x.r,
                Profile::Gaussian(s) => {
                    let narrow = (0.6 / (s * x.r / half).sqrt()).ceil() as usize;
                    more = more.max(narrow.min(8));
                    s * x.r
                }
                _ => continue,
            }
            .max(1e-12 * half);
            deep = deep.max((0.5 * (half / scale).log2()).ceil() as i32 + 3);
        }
        let (deep, panels) = (deep.min(30), panels * more);
        let mut cells = vec![(0.0, 0.5f64.powi(deep))];
        for k in (0..deep).rev() {
            cells.push((0.5f64.powi(k + 1), 0.5f64.powi(k)));
        }
        nodes.clear();
        for (end, dir) in [(a, 1.0), (b, -1.0)] {
            for &(u0, u1) in &cells {
                let du = (u1 - u0) / panels as f64;
                for p in 0..panels {
                    for &(x, wt) in gl {
                        let u = u0 + du * (p as f64 + 0.5 + 0.5 * x);
                        // t = end + dir H u^2, dt = 2 H u du.
                        nodes.push((end + dir * half * u * u, 0.5 * du * wt * 2.0 * half * u));
                    }
                }
            }
        }
        nodes.sort_by(|p, q| p.0.total_cmp(&q.0));
        // T(0, t) accumulated from node to node.
        let mut prev = a;
        for &(t, weight) in &nodes {
            tau += depth_between(&active, prev, t);
            prev = t;
            let (_, emit, alb) = medium(&active, t);
            let mut e = DVec3::ZERO;
            if scatters {
                let pos = o + t * w;
                for (lamp, nr) in lamps.iter().zip(&near) {
                    e += arriving(&scene, nr, lamp, pos, panels);
                }
            }
            l += weight * (-tau).exp() * (emit + phase * alb * e);
        }
        tau += depth_between(&active, prev, b);
    }
    Reference {
        gas: l,
        tau,
        pieces,
    }
}

/// The reference with 4 panels per cell, and its own error: the largest channel difference
/// from 2 panels per cell (a bound on the error of the coarser, so generous for the finer).
pub fn checked(balls: &[Ball], lamps: &[Lamp], o: DVec3, w: DVec3) -> (Reference, f64) {
    let coarse = reference(balls, lamps, o, w, 2);
    let fine = reference(balls, lamps, o, w, 4);
    let diff = (fine.gas - coarse.gas).abs().max_element();
    (fine, diff)
}
