//! Gas spheres as AO occluders against independent answers: the thin-gas closed form, a
//! one-dimensional quadrature written here for a ball on the normal's axis, and Monte Carlo
//! over stratified directions with a stated confidence, the transmittance of each direction
//! computed here (its own ray roots; Simpson's rule over a profile's density).

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::tests::Mix;
use super::{unoccluded_to, AoScratch, Weighting};
use crate::accel::Prim;
use crate::render::visibility::Opaque;
use crate::render::{self, PrepareOptions, Prepared};
use crate::testing::{self as support, GAS_PARTICLE_PROTO};

/// A ball of a test scene: centre, radius, and `None` (opaque) or the gas's transparency and
/// profile name.
type Ball = (DVec3, f64, Option<(f64, &'static str)>);

/// The scene of `balls`, through VRML and `prepare`.
fn prepared(balls: &[Ball]) -> Prepared {
    prepared_with(balls, &[])
}

/// The scene of `balls` and the axis-aligned Boxes `boxes` (corners `lo`, `hi`).
fn prepared_with(balls: &[Ball], boxes: &[(DVec3, DVec3)]) -> Prepared {
    let mut text = String::from(GAS_PARTICLE_PROTO);
    for (lo, hi) in boxes {
        let (c, size) = (0.5 * (*lo + *hi), *hi - *lo);
        text += &format!(
            "Transform {{ translation {} {} {} children Shape {{ geometry Box {{ size {} {} {} }} }} }}\n",
            c.x, c.y, c.z, size.x, size.y, size.z
        );
    }
    for (c, r, gas) in balls {
        match gas {
            None => text += &format!(
                "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ \
                 material Material {{ }} }} geometry Sphere {{ radius {r} }} }} }}\n",
                c.x, c.y, c.z
            ),
            Some((t, profile)) => {
                text += &format!(
                    "GasParticle {{ position {} {} {} radius {r} transparency {t} profile \"{profile}\" }}\n",
                    c.x, c.y, c.z
                )
            }
        }
    }
    let (scene, _) = support::scene(&text);
    render::prepare(scene, &PrepareOptions::default()).expect("prepare")
}

/// The BVH's primitive of scene sphere `i`.
fn prim_of(prep: &Prepared, i: u32) -> (u32, Prim) {
    (0..prep.bvh.len() as u32)
        .map(|k| (k, prep.bvh.prim(k)))
        .find(|(_, p)| p.sphere == i)
        .expect("primitive")
}

/// Where the line `x + t w` (unit `w`) is inside the ball `(c, r)`, by the quadratic.
fn roots(x: DVec3, w: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    let v = c - x;
    let b = v.dot(w);
    let disc = r * r - (v - b * w).length_squared();
    (disc > 0.0).then(|| (b - disc.sqrt(), b + disc.sqrt()))
}

/// The optical depth of `x + t w`, `t` in `[0, reach]`, through gas primitive `p`: the chord
/// times the extinction, or Simpson's rule over the profile's density (split at the closest
/// approach to the centre, where the linear profile bends).
fn depth(p: &Prim, x: DVec3, w: DVec3, reach: f64) -> f64 {
    let Some((t0, t1)) = roots(x, w, p.center, p.radius) else {
        return 0.0;
    };
    let (a, b) = (t0.max(0.0), t1.min(reach));
    if b <= a {
        return 0.0;
    }
    if !p.is_profiled() {
        return p.sigma * (b - a);
    }
    // (The ends are on the surface: `u` rounded above 1 would read the cut gaussian as 0.)
    let density = |t: f64| {
        let u = (x + t * w - p.center).length() / p.radius;
        p.sigma * p.profile.f(u.min(1.0))
    };
    let simpson = |a: f64, b: f64| {
        let n = 100;
        let h = (b - a) / n as f64;
        (0..n)
            .map(|k| {
                let t = a + k as f64 * h;
                h / 6.0 * (density(t) + 4.0 * density(t + 0.5 * h) + density(t + h))
            })
            .sum::<f64>()
    };
    let tc = (p.center - x).dot(w).clamp(a, b);
    simpson(a, tc) + simpson(tc, b)
}

/// The visibility of the sky along `w` from `x` within `reach`: 0 if an opaque ball or one
/// of the `boxes` is entered on the way, else the transmittance of the gas; `own` (opaque or
/// gas) left out.
fn visibility(
    prep: &Prepared,
    (x, w): (DVec3, DVec3),
    reach: f64,
    own: Option<u32>,
    boxes: &[(DVec3, DVec3)],
) -> f64 {
    for (lo, hi) in boxes {
        // The slabs: entered at the latest entry, left at the earliest exit.
        let (a, b) = ((*lo - x) / w, (*hi - x) / w);
        let (enter, leave) = (a.min(b).max_element(), a.max(b).min_element());
        if enter <= leave && leave > 0.0 && enter <= reach {
            return 0.0;
        }
    }
    let mut tau = 0.0;
    for k in 0..prep.bvh.len() as u32 {
        let p = prep.bvh.prim(k);
        if Some(k) == own {
            continue;
        }
        if p.is_gas() {
            tau += depth(&p, x, w, reach);
        } else {
            if let Some((t0, t1)) = roots(x, w, p.center, p.radius) {
                if t1 > 0.0 && t0 <= reach {
                    return 0.0;
                }
            }
        }
    }
    (-tau).exp()
}

/// The direction about `n` of the point `(s, t)` of the unit square, mapped so that equal
/// areas have equal weight `w`: cosine, the disc's area lifted onto the hemisphere (Nusselt);
/// uniform, `cos θ` uniform.
fn weighted(n: DVec3, w: Weighting, s: f64, t: f64) -> DVec3 {
    let (u, v) = n.any_orthonormal_pair();
    let z = match w {
        Weighting::Cosine => (1.0 - s).sqrt(),
        Weighting::Uniform => 1.0 - s,
    };
    let rho = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * t;
    z * n + rho * (phi.cos() * u + phi.sin() * v)
}

/// The stratified Monte Carlo estimate of AO at `x` (normal `n`), `side^2` directions, and
/// the upper bound of its standard deviation (a mean of values in [0, 1]).
fn monte_carlo(
    (prep, boxes): (&Prepared, &[(DVec3, DVec3)]),
    (x, n, own): (DVec3, DVec3, Option<u32>),
    (reach, w): (f64, Weighting),
    side: u32,
    rng: &mut Mix,
) -> (f64, f64) {
    let mut sum = 0.0;
    for i in 0..side {
        for j in 0..side {
            let s = (f64::from(i) + rng.next()) / f64::from(side);
            let t = (f64::from(j) + rng.next()) / f64::from(side);
            sum += visibility(prep, (x, weighted(n, w, s, t)), reach, own, boxes);
        }
    }
    let count = f64::from(side * side);
    let p = sum / count;
    let q = (25.0 / count).min(0.5);
    (p, (p * (1.0 - p)).max(q * (1.0 - q)).sqrt() / count.sqrt())
}

/// A point on top of the opaque ball `(0, 0, -1)`, radius 1: the origin, normal `+z`.
const FLOOR: Ball = (DVec3::new(0.0, 0.0, -1.0), 1.0, None);

fn at_top(prep: &Prepared) -> Option<Opaque> {
    Some(Opaque::Sphere(prim_of(prep, 0).0))
}

/// Optically thin gas: `1 - AO` is, to first order in the optical depth, the extinction
/// times `(1/2π) ∫_ball |y - x|^-2 dy` (uniform weighting, the ball wholly above the
/// horizon), which is `(1/2d) [(r^2 - d^2) ln((d + r)/(d - r)) + 2 d r]`; depths from 1e-12
/// to 1e-6 along a diameter.
#[test]
fn thin_gas_takes_the_closed_form() {
    let mut worst: f64 = 0.0;
    for (k, &(c, r)) in [
        (DVec3::new(0.3, 0.2, 3.0), 1.0),
        (DVec3::new(-2.0, 1.0, 1.5), 0.7),
        (DVec3::new(0.0, 0.0, 1.2), 1.0),
        (DVec3::new(40.0, -30.0, 25.0), 5.0),
    ]
    .iter()
    .enumerate()
    {
        for diameter_depth in [1e-12f64, 1e-9, 1e-6] {
            let transparency = (-diameter_depth).exp();
            let prep = prepared(&[FLOOR, (c, r, Some((transparency, "constant")))]);
            let sigma = prim_of(&prep, 1).1.sigma;
            let d = c.length();
            let exact =
                sigma / (2.0 * d) * ((r * r - d * d) * ((d + r) / (d - r)).ln() + 2.0 * d * r);
            let (v, err) = unoccluded_to(
                &prep,
                DVec3::ZERO,
                DVec3::Z,
                at_top(&prep),
                (f64::INFINITY, Weighting::Uniform),
                1e-6,
                &mut AoScratch::default(),
            );
            // Second order: the loss is (1 - e^-τ), within τ^2 / 2 of τ.
            let allowed = err + 2.0 * f64::EPSILON + diameter_depth * exact;
            let off = ((1.0 - v) - exact).abs();
            assert!(off <= allowed, "case {k}, depth {diameter_depth}: 1 - AO = {:e}, closed form {exact:e}, error {err:e}", 1.0 - v);
            worst = worst.max(off / allowed);
        }
    }
    eprintln!("thin gas: worst difference {worst:.3} of the allowance");
}

/// The loss of a ball `(0, 0, d)`, radius `r`, seen from the origin with normal `+z` (its
/// cap is about the normal, so the integral is over `θ` alone): `∫ k(θ) (1 - T(θ)) dθ`,
/// pieces cut at the ball's edge and reach circles, each by the midpoint rule after
/// `θ = a + (b - a) sin²(πs/2)`, which smooths a square root at either end, and extrapolated
/// from two step sizes; with a bound of its own error (the two sizes' difference).
fn on_axis_loss(p: &Prim, reach: f64, w: Weighting) -> (f64, f64) {
    let (d, r) = (p.center.z, p.radius);
    let mut cuts = vec![0.0, FRAC_PI_2];
    if d > r {
        cuts.push((r / d).asin());
    }
    if reach.is_finite() {
        let c = (d * d + reach * reach - r * r) / (2.0 * d * reach);
        if c.abs() < 1.0 {
            cuts.push(c.acos());
        }
    }
    cuts.retain(|&t| t <= FRAC_PI_2);
    cuts.sort_by(f64::total_cmp);
    let integrand = |t: f64| {
        let dir = DVec3::new(t.sin(), 0.0, t.cos());
        let k = match w {
            Weighting::Cosine => 2.0 * t.cos(),
            Weighting::Uniform => 1.0,
        };
        k * t.sin() * -(-depth(p, DVec3::ZERO, dir, reach)).exp_m1()
    };
    let midpoint = |n: usize| -> f64 {
        cuts.windows(2)
            .map(|ab| {
                let (a, b) = (ab[0], ab[1]);
                (0..n)
                    .map(|i| {
                        let s = (i as f64 + 0.5) / n as f64;
                        let q = (0.5 * PI * s).sin();
                        let t = a + (b - a) * q * q;
                        let dt = (b - a) * PI * q * (0.5 * PI * s).cos();
                        integrand(t) * dt / n as f64
                    })
                    .sum::<f64>()
            })
            .sum()
    };
    // Richardson on the midpoint rule's h^2 error, which also says how far it may be off.
    let (coarse, fine) = (midpoint(3000), midpoint(6000));
    (fine + (fine - coarse) / 3.0, (fine - coarse).abs())
}

/// A ball on the normal's axis, outside the point and around it, every profile, optical
/// depths along a diameter from 1e-3 to 700 (a transparency of 1e-304), with and without a reach, both weightings,
/// against the one-dimensional quadrature: within the reported error, which stays near the
/// tolerance.
#[test]
fn a_ball_on_the_axis_takes_the_one_dimensional_integral() {
    let (mut worst, mut worst_ratio, mut cases) = (0.0f64, 0.0f64, 0);
    for (d, r) in [(2.5, 1.0), (1.0005, 1.0), (0.5, 1.5), (6.0, 4.0)] {
        for profile in ["constant", "linear", "quadratic", "gaussian"] {
            for diameter_depth in [1e-3f64, 1.0, 30.0, 700.0] {
                for reach in [f64::INFINITY, 1.0 * d, 0.7 * d + 0.3 * r] {
                    for w in [Weighting::Cosine, Weighting::Uniform] {
                        let transparency = (-diameter_depth).exp();
                        let c = DVec3::new(0.0, 0.0, d);
                        let prep = prepared(&[FLOOR, (c, r, Some((transparency, profile)))]);
                        let p = prim_of(&prep, 1).1;
                        let (loss, loss_error) = on_axis_loss(&p, reach, w);
                        let want = 1.0 - loss;
                        for tol in [1e-3, 1e-6] {
                            let (v, err) = unoccluded_to(
                                &prep,
                                DVec3::ZERO,
                                DVec3::Z,
                                at_top(&prep),
                                (reach, w),
                                tol,
                                &mut AoScratch::default(),
                            );
                            let off = (v - want).abs();
                            assert!(
                                off <= err + loss_error + 1e-12,
                                "d {d} r {r} {profile} depth {diameter_depth} reach {reach} \
                                 {w:?} tol {tol}: {v} against {want}, error {err:e}"
                            );
                            assert!(
                                err <= 10.0 * tol,
                                "d {d} {profile} depth {diameter_depth}: error {err:e} at tol {tol}"
                            );
                            worst = worst.max(off);
                            if off > loss_error + 1e-12 {
                                worst_ratio = worst_ratio.max(off / err);
                            }
                            cases += 1;
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "balls on the axis: {cases} cases, worst difference {worst:e}, at most {worst_ratio:.3} \
         of the reported error where above the reference's"
    );
}

/// Random scenes of opaque and gas balls (every profile, some around the point, overlapping
/// each other and the opaque ones), points on the opaque balls, with and without a reach,
/// both weightings, against stratified Monte Carlo: within `5 σ` plus the reported error.
#[test]
fn random_scenes_of_gas_and_opaque_balls_take_monte_carlo() {
    let mut rng = Mix(44);
    let profiles = ["constant", "linear", "quadratic", "gaussian"];
    let (mut worst, mut points, mut gas_points) = (0.0f64, 0, 0);
    for scene in 0..12 {
        let mut balls: Vec<Ball> = Vec::new();
        for _ in 0..4 {
            let c = DVec3::new(rng.next(), rng.next(), rng.next()) * 4.0 - 2.0;
            balls.push((c, 0.3 + 0.4 * rng.next(), None));
        }
        for _ in 0..6 {
            let c = DVec3::new(rng.next(), rng.next(), rng.next()) * 4.0 - 2.0;
            let depth = 10f64.powf(-2.0 + 4.0 * rng.next());
            let profile = profiles[rng.next_index(4)];
            balls.push((c, 0.4 + 0.8 * rng.next(), Some(((-depth).exp(), profile))));
        }
        let prep = prepared(&balls);
        let reach = if scene % 2 == 0 {
            f64::INFINITY
        } else {
            0.5 + 2.0 * rng.next()
        };
        let w = if scene % 3 == 0 {
            Weighting::Uniform
        } else {
            Weighting::Cosine
        };
        let tol = [1e-2, 1e-3, 1e-4][scene % 3];
        for b in 0..4 {
            let (k, p) = prim_of(&prep, b);
            for _ in 0..3 {
                let n = rng.unit();
                let x = p.center + p.radius * n;
                let own = Some(k);
                let (v, err) = unoccluded_to(
                    &prep,
                    x,
                    n,
                    Some(Opaque::Sphere(k)),
                    (reach, w),
                    tol,
                    &mut AoScratch::default(),
                );
                let (mc, sigma) = monte_carlo((&prep, &[]), (x, n, own), (reach, w), 160, &mut rng);
                let excess = ((v - mc).abs() - err).max(0.0) / sigma;
                assert!(
                    excess <= 5.0,
                    "scene {scene}, ball {b}: {v} (error {err:e}) against {mc} ± {sigma:e}"
                );
                worst = worst.max(excess);
                points += 1;
                if err > 0.0 {
                    gas_points += 1;
                }
            }
        }
    }
    assert!(
        gas_points > points / 2,
        "{gas_points} of {points} points see gas"
    );
    eprintln!(
        "gas and opaque balls: {points} points ({gas_points} seeing gas), worst {worst:.2} σ \
         beyond the reported error"
    );
}

/// A point inside a gas ball sees every direction through it: optical depths from 1e-12 to
/// 700 across a diameter keep AO between the transmittances of the shortest and the longest
/// way out.
#[test]
fn a_point_inside_gas_is_dimmed_by_all_of_it() {
    for diameter_depth in [1e-12f64, 1e-3, 1.0, 700.0] {
        let prep = prepared(&[
            FLOOR,
            (
                DVec3::new(0.2, 0.1, 0.3),
                2.0,
                Some(((-diameter_depth).exp(), "constant")),
            ),
        ]);
        let p = prim_of(&prep, 1).1;
        let (v, err) = unoccluded_to(
            &prep,
            DVec3::ZERO,
            DVec3::Z,
            at_top(&prep),
            (f64::INFINITY, Weighting::Cosine),
            1e-4,
            &mut AoScratch::default(),
        );
        assert!((0.0..=1.0).contains(&v), "{v}");
        // Every ray leaves the ball between r - d = 1.63 and r + d = 2.37 from the point.
        let (lo, hi) = ((-p.sigma * 2.4).exp(), (-p.sigma * 1.6).exp());
        assert!(
            v >= lo - err && v <= hi + err,
            "depth {diameter_depth}: {v} outside [{lo}, {hi}] (error {err:e})"
        );
    }
}

/// Gas beside Boxes (the regions' circles cut the meridians, and the pieces inside a region
/// are left out): points on an opaque ball among two Boxes and four gas balls, one around
/// the point, against Monte Carlo with the Boxes' slabs: within `5 σ` plus the reported
/// error.
#[test]
fn gas_beside_boxes_takes_monte_carlo() {
    let boxes = [
        (DVec3::new(0.6, -0.5, -0.3), DVec3::new(1.4, 0.7, 0.9)),
        (DVec3::new(-1.5, -0.4, 0.2), DVec3::new(-0.7, 0.2, 0.6)),
    ];
    let gas = |c: DVec3, r: f64, depth: f64, profile| (c, r, Some(((-depth).exp(), profile)));
    let balls = [
        FLOOR,
        gas(DVec3::new(0.2, 0.3, 0.1), 0.8, 1.5, "constant"),
        gas(DVec3::new(1.0, 0.1, 1.2), 0.7, 4.0, "linear"),
        gas(DVec3::new(-1.0, -0.2, 0.5), 0.6, 0.5, "gaussian"),
        gas(DVec3::new(0.0, -1.2, 1.0), 0.9, 2.0, "quadratic"),
    ];
    let prep = prepared_with(&balls, &boxes);
    let (k, p) = prim_of(&prep, 0);
    let mut rng = Mix(7);
    let mut worst: f64 = 0.0;
    for (i, reach) in [f64::INFINITY, 1.2].into_iter().enumerate() {
        for w in [Weighting::Cosine, Weighting::Uniform] {
            for _ in 0..4 {
                let n = (DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.8)).normalize();
                let x = p.center + p.radius * n;
                let (v, err) = unoccluded_to(
                    &prep,
                    x,
                    n,
                    Some(Opaque::Sphere(k)),
                    (reach, w),
                    1e-3,
                    &mut AoScratch::default(),
                );
                let (mc, sigma) =
                    monte_carlo((&prep, &boxes), (x, n, Some(k)), (reach, w), 160, &mut rng);
                let excess = ((v - mc).abs() - err).max(0.0) / sigma;
                assert!(
                    excess <= 5.0,
                    "reach {i}, {w:?}: {v} (error {err:e}) against {mc} ± {sigma:e}"
                );
                worst = worst.max(excess);
            }
        }
    }
    eprintln!("gas beside Boxes: 16 points, worst {worst:.2} σ beyond the reported error");
}

/// The per-particle mean over an opaque sphere beside gas and over a gas sphere (itself left
/// out) beside an opaque one, against Monte Carlo: one weighted ray from each of many uniform
/// points of the surface, within `5 σ` plus the reported error.
#[test]
fn a_particles_mean_among_gas_takes_monte_carlo() {
    use crate::render::particle_ao::sphere_ao;
    let prep = prepared(&[
        (DVec3::ZERO, 0.5, None),
        (DVec3::new(0.9, 0.3, 0.0), 0.6, Some((0.2, "constant"))),
        (DVec3::new(-0.4, 0.9, 0.3), 0.5, Some((0.05, "linear"))),
    ]);
    let mut rng = Mix(11);
    let mut s = AoScratch::default();
    for (b, w, reach) in [
        (0, Weighting::Cosine, f64::INFINITY),
        (1, Weighting::Uniform, 1.5),
    ] {
        let (k, p) = prim_of(&prep, b);
        let a = sphere_ao(
            &prep,
            (p.center, p.radius),
            Some(k),
            (reach, w),
            1e-3,
            &mut s,
        );
        const N: usize = 100_000;
        let mut sum = 0.0;
        for _ in 0..N {
            let n = rng.unit();
            let dir = weighted(n, w, rng.next(), rng.next());
            sum += visibility(&prep, (p.center + p.radius * n, dir), reach, Some(k), &[]);
        }
        let mc = sum / N as f64;
        let sigma = (mc * (1.0 - mc) / N as f64).sqrt();
        assert!(
            (a.mean - mc).abs() <= 5.0 * sigma + a.error,
            "sphere {b}: {} (error {:e}) against {mc} ± {sigma:e}",
            a.mean,
            a.error
        );
        assert!(mc < 0.95, "{mc}: the gas and the other sphere occlude");
        eprintln!(
            "sphere {b}: mean {:.5} (error {:.1e}, {} points) against {mc:.5} ± {sigma:.1e}",
            a.mean, a.error, a.points
        );
    }
}
