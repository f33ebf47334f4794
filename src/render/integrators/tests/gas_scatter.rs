//! Single scattering against the independent brute-force reference of `gas_reference`: the
//! camera ray is cut at the gas spheres' entries and exits and at the shadow boundaries
//! (found by a Lipschitz scan and bisection, not by the renderer's cylinder/cone formulas),
//! and each piece is integrated by composite Gauss-Legendre, with exact chords computed by a
//! loop over the spheres (no BVH, no adaptivity, no closed forms). Its own accuracy is
//! checked by halving the panel width.

use crate::render::integrators::{self, Scratch};
use crate::render::sampler::Rng;
use crate::render::{Counters, Integrator, PrepareOptions, RenderOptions, View};
use glam::DVec3;

use super::gas_reference::{checked, gauss_legendre, reference, roots, vrml, Ball, Lamp};
use crate::testing as support;

pub(crate) fn prepared(
    balls: &[Ball],
    lamps: &[Lamp],
    integrator: Integrator,
    tol: f64,
) -> support::Setup {
    let (scene, _) = support::scene(&vrml(balls, lamps));
    let opts = RenderOptions {
        integrator,
        tol,
        ..RenderOptions::default()
    };
    support::Setup::new(scene, &PrepareOptions::default(), opts)
}

/// The renderer's gas part along a ray: its radiance minus what reaches it from behind
/// the gas (background black; rays here miss the opaque spheres or the test says so).
pub(crate) fn ours(view: &View, o: DVec3, w: DVec3) -> (DVec3, f64) {
    let e = integrators::radiance(
        view,
        o,
        w,
        &mut Rng::new(0, 0),
        &mut Scratch::default(),
        &mut Counters::default(),
    );
    (e.value, e.error)
}

fn assert_rel(got: DVec3, want: DVec3, rel: f64, what: &str) {
    let scale = want.abs().max_element();
    let err = (got - want).abs().max_element();
    assert!(
        err <= rel * scale,
        "{what}: got {got} want {want}: rel {:e}",
        err / scale
    );
}

pub(crate) fn camera_rays(n: usize) -> Vec<(DVec3, DVec3)> {
    let o = DVec3::new(0.1, -0.05, 6.0);
    (0..n)
        .map(|k| {
            let a = k as f64 * 2.399_963;
            let r = 1.05 * ((k as f64 + 0.5) / n as f64).sqrt();
            (
                o,
                (DVec3::new(r * a.cos(), r * a.sin(), 0.0) - o).normalize(),
            )
        })
        .collect()
}

fn one_sphere(lamp: Lamp) {
    let balls = [Ball {
        c: DVec3::ZERO,
        r: 1.0,
        gas: Some((0.3, DVec3::new(0.05, 0.02, 0.01), DVec3::new(0.9, 0.7, 0.5))),
    }];
    let lamps = [lamp];
    let setup = prepared(&balls, &lamps, Integrator::Exact, 1e-10);
    let view = setup.view();
    for (o, w) in camera_rays(24) {
        let (want, diff) = checked(&balls, &lamps, o, w);
        let want = want.gas;
        assert!(
            diff <= 1e-10 * want.abs().max_element(),
            "reference refinement: {diff:e} of {want}"
        );
        if want == DVec3::ZERO {
            continue;
        }
        assert_rel(ours(&view, o, w).0, want, 1e-6, "one sphere");
    }
}

#[test]
fn one_sphere_directional_light() {
    one_sphere(Lamp::Dir {
        to_light: DVec3::new(0.3, 1.0, 0.2).normalize(),
        power: DVec3::new(1.0, 0.9, 0.8),
    });
}

#[test]
fn one_sphere_point_light_inside() {
    one_sphere(Lamp::Point {
        p: DVec3::new(0.2, 0.1, 0.3),
        power: DVec3::new(1.0, 0.8, 0.6),
        att: DVec3::new(0.0, 0.5, 0.2),
    });
}

#[test]
fn one_sphere_point_light_outside() {
    one_sphere(Lamp::Point {
        p: DVec3::new(2.0, 1.5, 1.0),
        power: DVec3::new(0.9, 0.9, 1.0),
        att: DVec3::new(1.0, 0.1, 0.05),
    });
}

/// About 20 overlapping gas spheres and 2 opaque ones, both kinds of light: 1e-5.
pub(crate) fn cloud() -> (Vec<Ball>, Vec<Lamp>) {
    let mut rng = crate::testing::Rng(5);
    let mut rnd = || rng.f();
    let mut balls = Vec::new();
    for _ in 0..20 {
        let c = DVec3::new(rnd(), rnd(), rnd()) * 2.0 - 1.0;
        balls.push(Ball {
            c,
            r: 0.3 + 0.4 * rnd(),
            gas: Some((
                0.2 + 0.7 * rnd(),
                DVec3::new(rnd(), rnd(), rnd()) * 0.05,
                DVec3::new(rnd(), rnd(), rnd()),
            )),
        });
    }
    balls.push(Ball {
        c: DVec3::new(0.3, 0.2, -0.2),
        r: 0.3,
        gas: None,
    });
    balls.push(Ball {
        c: DVec3::new(-0.5, -0.4, 0.4),
        r: 0.25,
        gas: None,
    });
    let lamps = vec![
        Lamp::Dir {
            to_light: DVec3::new(1.0, 0.6, 0.4).normalize(),
            power: DVec3::new(0.8, 0.9, 1.0),
        },
        Lamp::Point {
            p: DVec3::new(0.1, 0.6, 0.3),
            power: DVec3::ONE,
            att: DVec3::new(0.5, 0.0, 1.0),
        },
    ];
    (balls, lamps)
}

#[test]
fn cloud_of_twenty_gas_spheres_and_two_opaque_ones() {
    let (balls, lamps) = cloud();
    let setup = prepared(&balls, &lamps, Integrator::Exact, 1e-9);
    let view = setup.view();
    let mut rays = 0;
    for (o, w) in camera_rays(40) {
        let (r, diff) = checked(&balls, &lamps, o, w);
        let gas = r.gas;
        assert!(
            diff <= 1e-10 * gas.abs().max_element(),
            "reference refinement: {diff:e} of {gas}"
        );
        // Only rays that miss the opaque spheres (their surfaces are tested elsewhere); the
        // background is black.
        if balls
            .iter()
            .any(|b| b.gas.is_none() && roots(o, w, b.c, b.r).is_some())
            || gas == DVec3::ZERO
        {
            continue;
        }
        assert_rel(ours(&view, o, w).0, gas, 1e-5, "cloud");
        rays += 1;
    }
    assert!(rays >= 20, "{rays}");
}

#[test]
fn one_sphere_point_light_at_the_centre() {
    one_sphere(Lamp::Point {
        p: DVec3::ZERO,
        power: DVec3::new(1.0, 0.8, 0.6),
        att: DVec3::new(1.0, 0.0, 0.0),
    });
}

#[test]
fn one_sphere_point_light_on_the_surface() {
    one_sphere(Lamp::Point {
        p: DVec3::new(0.6, 0.0, 0.8),
        power: DVec3::new(1.0, 0.8, 0.6),
        att: DVec3::new(0.0, 1.0, 0.0),
    });
}

// The reference's own checks.

#[test]
fn gauss_legendre_integrates_degree_15_exactly() {
    let gl = gauss_legendre();
    let sum: f64 = gl.iter().map(|p| p.1).sum();
    assert!((sum - 2.0).abs() < 1e-15, "{sum}");
    let x14: f64 = gl.iter().map(|p| p.1 * p.0.powi(14)).sum();
    assert!((x14 - 2.0 / 15.0).abs() < 1e-15, "{x14}");
}

/// The reference against closed forms: one emitting sphere, C (1 - exp(-tau)); a point
/// light at the centre of a scattering sphere, on a ray through the centre (the light's
/// path from x(t) has length |t - t_c| in the gas).
#[test]
fn reference_matches_closed_forms() {
    let (r, tr) = (0.7, 0.2);
    let sigma = -f64::ln(tr) / (2.0 * r);
    let col = DVec3::new(0.9, 0.5, 0.1);
    let o = DVec3::new(0.0, 0.0, 5.0);
    for k in 0..20 {
        let target = DVec3::new(0.035 * k as f64, 0.01 * k as f64, 0.0);
        let w = (target - o).normalize();
        let balls = [Ball {
            c: DVec3::ZERO,
            r,
            gas: Some((tr, col, DVec3::ZERO)),
        }];
        let got = reference(&balls, &[], o, w, 1);
        let want = match roots(o, w, DVec3::ZERO, r) {
            Some((t0, t1)) => col * -f64::exp_m1(-sigma * (t1 - t0)),
            None => DVec3::ZERO,
        };
        assert!(
            (got.gas - want).abs().max_element() <= 1e-14 * want.max_element().max(1e-300),
            "emission ray {k}: {} vs {want}",
            got.gas
        );
    }
    let a = DVec3::new(0.8, 0.6, 0.4);
    let balls = [Ball {
        c: DVec3::ZERO,
        r,
        gas: Some((tr, DVec3::ZERO, a)),
    }];
    let lamps = [Lamp::Point {
        p: DVec3::ZERO,
        power: DVec3::ONE,
        att: DVec3::new(1.0, 0.0, 0.0),
    }];
    let got = reference(&balls, &lamps, o, DVec3::NEG_Z, 1).gas;
    let e = (-sigma * r).exp();
    let want = sigma * a * 0.25 / std::f64::consts::PI
        * (r * e + e * -f64::exp_m1(-2.0 * sigma * r) / (2.0 * sigma));
    assert!(
        (got - want).abs().max_element() <= 1e-13 * want.max_element(),
        "{got} vs {want}"
    );
}
