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

use crate::gas_reference::{self, roots, Lamp};

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

/// GasParticle as `convert` and the VRML writer declare it.
pub const GAS_PARTICLE_PROTO: &str = "PROTO GasParticle [
  field SFVec3f position 0 0 0
  field SFFloat radius 1
  field SFColor color 0.8 0.8 0.8
  field SFColor emission 0 0 0
  field SFFloat transparency 0.5
  field SFString profile \"constant\"
  field SFFloat width 0.3333333333333333
] {
  Transform {
    translation IS position
    children Shape {
      appearance Appearance {
        material Material { diffuseColor IS color emissiveColor IS emission transparency IS transparency }
      }
      geometry Sphere { radius IS radius }
    }
  }
}
";

/// The scene as VRML (headlight off, no Viewpoint: the tests trace their own rays): gas
/// spheres as GasParticle instances (every profile, constant included), opaque spheres and
/// lights as `gas_reference::vrml` writes them. Numbers are written in full (`{:e}` is the
/// shortest form that reads back to the same f64).
pub fn vrml(balls: &[Ball], lamps: &[Lamp]) -> String {
    // NavigationInfo and the lights, exactly as gas_reference writes them.
    let mut s = gas_reference::vrml(&[], lamps);
    s.push_str(GAS_PARTICLE_PROTO);
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

// ---- Gauss-Legendre.

/// The `n`-point Gauss-Legendre rule on [-1, 1] (n in 1..=24), by Newton's method on P_n.
fn rule(n: usize) -> &'static [(f64, f64)] {
    static RULES: OnceLock<Vec<Vec<(f64, f64)>>> = OnceLock::new();
    &RULES.get_or_init(|| (0..=24).map(legendre_rule).collect())[n]
}

fn legendre_rule(n: usize) -> Vec<(f64, f64)> {
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
fn rule_sum(rule: &[(f64, f64)], a: f64, b: f64, g: impl Fn(f64) -> f64) -> f64 {
    let (m, hw) = (0.5 * (a + b), 0.5 * (b - a));
    hw * rule.iter().map(|&(x, wt)| wt * g(m + hw * x)).sum::<f64>()
}

// ---- Chords.

/// The line `o + s d` (`|d| = 1`) against a sphere: closest approach to the centre at `s = sc`,
/// the centre's distance from the line `beta` and the chord's half-length `h`, in radii.
#[derive(Clone, Copy, Debug)]
struct Chord {
    sc: f64,
    beta: f64,
    h: f64,
}

fn chord(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<Chord> {
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
fn radial(profile: Profile, ch: &Chord, p: f64, q: f64, panels: usize) -> f64 {
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
fn depth_on_line(
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
fn shadow_interval(
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

// ---- The reference's own checks.

/// The profiles the checks go through.
pub const PROFILES: [Profile; 6] = [
    Profile::Constant,
    Profile::Linear,
    Profile::Quadratic,
    Profile::Gaussian(1.0 / 3.0),
    Profile::Gaussian(0.15),
    Profile::Gaussian(0.05),
];

/// Tanh-sinh (double exponential) quadrature of `g` on `[a, b]` with step `h` (a rule
/// unrelated to Gauss-Legendre, for the checks): nodes are placed by their distance from the
/// nearer end, so that they keep their precision there.
fn tanh_sinh(a: f64, b: f64, h: f64, g: impl Fn(f64) -> f64) -> f64 {
    let half = 0.5 * (b - a);
    let n = (4.0 / h).ceil() as i64;
    let mut sum = 0.0;
    for k in -n..=n {
        let s = k as f64 * h;
        let y = std::f64::consts::FRAC_PI_2 * s.sinh();
        // 1 - tanh|y| = 2 / (e^{2|y|} + 1): the distance from the nearer end over `half`.
        let delta = 2.0 / ((2.0 * y.abs()).exp() + 1.0);
        let weight = std::f64::consts::FRAC_PI_2 * s.cosh() / (y.cosh() * y.cosh());
        if weight == 0.0 || delta == 0.0 {
            continue;
        }
        let t = if k >= 0 {
            b - half * delta
        } else {
            a + half * delta
        };
        sum += weight * g(t);
    }
    sum * half * h
}

/// `integral_a^b g` by tanh-sinh at steps 1/64 and 1/128, which must agree to 1e-14.
fn fine_integral(a: f64, b: f64, g: impl Fn(f64) -> f64) -> f64 {
    let coarse = tanh_sinh(a, b, 1.0 / 64.0, &g);
    let fine = tanh_sinh(a, b, 1.0 / 128.0, &g);
    assert!(
        (fine - coarse).abs() <= 1e-14 * fine.abs() + 1e-300,
        "tanh-sinh: {fine} vs {coarse}"
    );
    fine
}

/// The optical depth of `b` along `o + s d` for `s` in `[s0, s1]`, independently: `f` of
/// `|x - c| / r` at each point, tanh-sinh on each side of the closest approach, `sigma0` from
/// `I_f` by tanh-sinh too.
fn fine_depth(b: &Ball, o: DVec3, d: DVec3, s0: f64, s1: f64) -> f64 {
    let (tr, _, _, profile) = b.gas.unwrap();
    let i_f = fine_integral(0.0, 1.0, |u| profile.f(u));
    let sigma0 = -f64::ln(tr) / (2.0 * b.r * i_f);
    let Some((t0, t1)) = roots(o, d, b.c, b.r) else {
        return 0.0;
    };
    let (t0, t1) = (t0.max(s0), t1.min(s1));
    if t1 <= t0 {
        return 0.0;
    }
    let g = |t: f64| profile.f(((o + t * d - b.c).length() / b.r).min(1.0));
    let tc = (b.c - o).dot(d).clamp(t0, t1);
    sigma0 * (fine_integral(t0, tc, g) + fine_integral(tc, t1, g))
}

/// One sphere, no lights, any profile: `L = C (1 - exp(-tau))` (the integrand is the
/// derivative of `-C exp(-tau(0, t))`), with `tau` from the independent quadrature; rays
/// through the centre, at several distances from it (down to 1e-3 of the radius from
/// grazing: the independent quadrature's `1 - u` loses digits beyond) and round it.
#[test]
fn one_emitting_sphere_is_c_times_one_minus_exp_tau() {
    let (c, r) = (DVec3::new(0.2, -0.1, 0.3), 0.8);
    let col = DVec3::new(0.9, 0.5, 0.1);
    let o = DVec3::new(0.3, 0.2, 5.0);
    let (mut worst, mut own) = ((0.0f64, String::new()), 0.0f64);
    for profile in PROFILES {
        for tr in [0.25, 1e-3, 0.999] {
            let ball = Ball {
                c,
                r,
                gas: Some((tr, col, DVec3::new(0.5, 0.5, 0.5), profile)),
            };
            for (k, rho) in [0.0, 0.01, 0.3, 0.7, 0.95, 0.999].into_iter().enumerate() {
                let (o, w) = ray_past(o, c, rho * r, k as f64 * 2.4);
                let (got, ref_err) = checked(&[ball], &[], o, w);
                let tau = fine_depth(&ball, o, w, 0.0, f64::INFINITY);
                let want = col * -f64::exp_m1(-tau);
                let rel = (got.gas - want).abs().max_element() / want.max_element();
                let rel_tau = (got.tau - tau).abs() / tau;
                let what = format!("{profile:?} tr {tr} rho {rho}: {} vs {want}", got.gas);
                own = own.max(ref_err / want.max_element());
                assert!(got.pieces > 0, "{what}");
                if rel.max(rel_tau) > worst.0 {
                    worst = (rel.max(rel_tau), what.clone());
                }
                assert!(
                    rel <= 1e-12 && rel_tau <= 1e-12 && ref_err <= 1e-11 * want.max_element(),
                    "{what}: rel {rel:e}, tau rel {rel_tau:e}, own error {ref_err:e}"
                );
            }
        }
    }
    eprintln!(
        "one emitting sphere: worst relative error {:.2e} ({}), largest own error {own:.2e}",
        worst.0, worst.1
    );
}

/// Along a diameter the transmittance is the sphere's transparency, whatever its profile:
/// by the camera ray's accumulated optical depth and by the light paths' chord integral.
#[test]
fn a_diameter_transmits_the_transparency() {
    let (c, r) = (DVec3::new(-0.4, 0.3, 0.1), 1.3);
    let mut worst = 0.0f64;
    for profile in PROFILES {
        for tr in [0.5, 1e-6, 0.9999] {
            let ball = Ball {
                c,
                r,
                gas: Some((tr, DVec3::ONE, DVec3::ZERO, profile)),
            };
            let o = c + DVec3::new(0.3, -2.0, 5.0);
            let w = (c - o).normalize();
            let want = -f64::ln(tr);
            for (what, tau) in [
                ("camera", reference(&[ball], &[], o, w, 1).tau),
                ("light path", line_depth(&ball, o, w, 0.0, f64::INFINITY)),
                ("camera, 2 panels", reference(&[ball], &[], o, w, 2).tau),
            ] {
                let rel = (tau - want).abs() / want;
                worst = worst.max(rel);
                assert!(
                    rel <= 1e-13,
                    "{profile:?} tr {tr} {what}: exp(-tau) {} rel {rel:e}",
                    (-tau).exp()
                );
            }
        }
    }
    // I_f of the gaussian against tanh-sinh.
    for s in [1.0, 1.0 / 3.0, 0.15, 0.05] {
        let p = Profile::Gaussian(s);
        let want = fine_integral(0.0, 1.0, |u| p.f(u));
        assert!(
            (p.integral() - want).abs() <= 1e-14 * want,
            "I_f({s}) {} vs {want}",
            p.integral()
        );
    }
    eprintln!("diameters: worst relative error of tau {worst:.2e}");
}

/// The light paths' chord integral against the independent quadrature: random lines and
/// segments (from inside or outside, towards or away from the centre, to a point inside or
/// beyond), lines at distances from the centre down to 1e-12 of the radius, every profile.
#[test]
fn light_path_depths_match_an_independent_quadrature() {
    let mut rng = crate::support::Rng(77);
    let mut worst = 0.0f64;
    for profile in PROFILES {
        let ball = Ball {
            c: DVec3::new(0.1, 0.2, -0.3),
            r: 0.9,
            gas: Some((0.2, DVec3::ONE, DVec3::ZERO, profile)),
        };
        for k in 0..60 {
            let mut unit = || {
                let z = rng.range(-1.0, 1.0);
                let a = rng.range(0.0, std::f64::consts::TAU);
                let s = (1.0 - z * z).sqrt();
                DVec3::new(s * a.cos(), s * a.sin(), z)
            };
            let d = unit();
            let n = (unit() - d * unit().dot(d)).normalize();
            // The line's distance from the centre (some through it to 1e-12), then a start
            // point on it anywhere within 1.5 radii of the closest approach.
            let rho = match k % 4 {
                0 => 1e-12 * rng.f(),
                1 => 10f64.powf(rng.range(-6.0, 0.0)),
                _ => 0.999 * rng.f(),
            } * ball.r;
            let closest = ball.c + rho * n;
            let o = closest + d * rng.range(-1.5, 1.5) * ball.r;
            let (s0, s1) = match k % 3 {
                0 => (0.0, f64::INFINITY),
                1 => (0.0, rng.range(0.0, 2.0)),
                _ => (rng.range(-0.5, 0.5), rng.range(0.5, 2.5)),
            };
            let got = line_depth(&ball, o, d, s0, s1);
            let want = fine_depth(&ball, o, d, s0, s1);
            let rel = if got == want {
                0.0
            } else {
                (got - want).abs() / want.abs().max(1e-300)
            };
            worst = worst.max(rel);
            assert!(
                rel <= 1e-12,
                "{profile:?} line {k}: {got} vs {want}: rel {rel:e}"
            );
        }
    }
    eprintln!("light paths: worst relative error {worst:.2e}");
}

/// A point light at the centre of a scattering sphere, a ray through the centre: the light's
/// path from `x(t)` and the camera ray's path to it add up to the depth `tau_1 = -ln(tr) / 2`
/// of a radius (before the centre) or `tau_1 + 2 tau(centre, x)` (after it), whatever the
/// profile, so `L = p a e^{-tau_1} (tau_1 + (1 - e^{-2 tau_1}) / 2)` (attenuation 1).
#[test]
fn a_point_light_at_the_centre_is_closed_form_for_every_profile() {
    let (c, r) = (DVec3::new(0.1, 0.2, -0.1), 0.7);
    let a = DVec3::new(0.8, 0.6, 0.4);
    let lamps = [Lamp::Point {
        p: c,
        power: DVec3::ONE,
        att: DVec3::new(1.0, 0.0, 0.0),
    }];
    let mut worst = 0.0f64;
    for profile in PROFILES {
        for tr in [0.2, 1e-4, 0.99] {
            let balls = [Ball {
                c,
                r,
                gas: Some((tr, DVec3::ZERO, a, profile)),
            }];
            let (o, w) = ray_past(DVec3::new(-0.5, 0.4, 4.0), c, 0.0, 0.0);
            let (got, ref_err) = checked(&balls, &lamps, o, w);
            let t1 = -f64::ln(tr) / 2.0;
            let want = a * 0.25 / std::f64::consts::PI
                * (-t1).exp()
                * (t1 + 0.5 * -f64::exp_m1(-2.0 * t1));
            let rel = (got.gas - want).abs().max_element() / want.max_element();
            worst = worst.max(rel);
            assert!(
                rel <= 1e-12 && ref_err <= 1e-12 * want.max_element(),
                "{profile:?} tr {tr}: {} vs {want}: rel {rel:e}, own error {ref_err:e}",
                got.gas
            );
        }
    }
    eprintln!("point light at the centre: worst relative error {worst:.2e}");
}

/// The constant profile is `gas_reference`'s model: on a small lit scene (three overlapping
/// gas spheres, an opaque one, a directional and a point light) the two references agree to
/// 1e-9 (the constant case differs only in how each integrates the transmittance).
#[test]
fn the_constant_profile_matches_gas_reference() {
    let gas = |c: DVec3, r: f64, tr: f64, e: DVec3, a: DVec3| Ball {
        c,
        r,
        gas: Some((tr, e, a, Profile::Constant)),
    };
    let balls = [
        gas(
            DVec3::new(-0.3, 0.0, 0.0),
            0.6,
            0.3,
            DVec3::new(0.05, 0.02, 0.01),
            DVec3::new(0.9, 0.6, 0.3),
        ),
        gas(
            DVec3::new(0.3, 0.1, 0.1),
            0.5,
            0.05,
            DVec3::new(0.0, 0.03, 0.06),
            DVec3::new(0.3, 0.8, 0.9),
        ),
        gas(
            DVec3::new(0.0, -0.4, -0.2),
            0.45,
            0.8,
            DVec3::ZERO,
            DVec3::ONE,
        ),
        Ball {
            c: DVec3::new(0.4, 1.0, 0.2),
            r: 0.2,
            gas: None,
        },
    ];
    let lamps = [
        Lamp::Point {
            p: DVec3::new(0.1, 0.0, 0.0),
            power: DVec3::ONE,
            att: DVec3::new(1.0, 0.3, 0.1),
        },
        Lamp::Dir {
            to_light: DVec3::new(0.3, 1.0, 0.5).normalize(),
            power: DVec3::splat(0.7),
        },
    ];
    let plain_balls: Vec<gas_reference::Ball> = balls.iter().map(plain).collect();
    let mut worst = 0.0f64;
    let o = DVec3::new(0.05, -0.02, 4.0);
    for k in 0..12 {
        let (o, w) = ray_past(o, DVec3::ZERO, 0.06 * k as f64, k as f64 * 2.4);
        let got = reference(&balls, &lamps, o, w, 2).gas;
        let want = gas_reference::reference(&plain_balls, &lamps, o, w, 2).gas;
        assert!(want != DVec3::ZERO, "ray {k} sees nothing");
        let rel = (got - want).abs().max_element() / want.abs().max_element();
        worst = worst.max(rel);
        assert!(rel <= 1e-9, "ray {k}: {got} vs {want}: rel {rel:e}");
    }
    eprintln!("constant profile against gas_reference: worst relative difference {worst:.2e}");
}

/// The reference refines: on the lit profiled cloud of `profiled_gas` (every profile, two
/// lights, opaque spheres), 1 and 2 panels per cell agree to 1e-10 of the value on every ray
/// (checked where the cloud's references are computed).
#[test]
fn the_reference_refines_on_the_lit_cloud() {
    let start = std::time::Instant::now();
    let refs = crate::profiled_gas::cloud_references();
    let worst = refs
        .iter()
        .map(|r| r.ref_err / r.want.abs().max_element())
        .fold(0.0, f64::max);
    eprintln!(
        "lit cloud: {} rays, worst reference error {worst:.2e} of the value ({:.2} s)",
        refs.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(worst <= 1e-10, "{worst:e}");
}
