//! The reference's own checks: closed forms, an independent quadrature of the light paths, and agreement with the constant-density reference.

use super::*;

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
    let mut rng = crate::testing::Rng(77);
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
    let refs = crate::render::integrators::tests::profiled_gas::cloud_references();
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
