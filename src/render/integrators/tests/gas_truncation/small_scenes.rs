//! A thousand concentric shells and the small scenes: the reported error against the true one.

use super::*;

/// 1000 concentric thin gas shells (radii 0.001 .. 1, transparency 0.99 each, so optical
/// depth ~5 ln(1/rho) per unit length at radius rho): 2000 segment events and up to 1000
/// shadow boundaries per ray. (One test for both claims: the renderer takes seconds a ray.)
#[test]
fn a_thousand_concentric_shells_are_within_the_reported_error_and_within_100x() {
    let balls: Vec<Ball> = (1..=1000)
        .map(|j| Ball {
            c: DVec3::ZERO,
            r: j as f64 * 1e-3,
            gas: Some((
                0.99,
                DVec3::new(0.02, 0.015, 0.01),
                DVec3::new(0.8, 0.8, 0.7),
            )),
        })
        .collect();
    let lamps = vec![Lamp::Point {
        p: DVec3::new(2.0, 1.5, 1.0),
        power: DVec3::new(1.0, 0.9, 0.8),
        att: DVec3::new(1.0, 0.0, 0.0),
    }];
    let o = DVec3::new(0.0, 0.0, 4.0);
    let rays: Vec<(DVec3, DVec3)> = [0.0, 3e-3, 0.3, 0.9]
        .iter()
        .enumerate()
        .map(|(k, &b)| {
            let a = k as f64 * 2.4;
            (
                o,
                (DVec3::new(b * a.cos(), b * a.sin(), 0.0) - o).normalize(),
            )
        })
        .collect();
    judge_all(
        "1000 shells",
        &balls,
        &lamps,
        &rays,
        &[1e-4, 1e-6],
        &[Claim::CoversEvery, Claim::Tight],
        4,
    );
}

/// Small scenes for the coverage tests, each with the radius of the disc of targets its rays aim at.
fn small_scenes() -> Vec<(&'static str, Vec<Ball>, Vec<Lamp>, f64)> {
    let gas = |c: DVec3, r: f64, tr: f64, e: DVec3, a: DVec3| Ball {
        c,
        r,
        gas: Some((tr, e, a)),
    };
    let overlapping = vec![
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
    ];
    let overlapping_lamps = vec![
        Lamp::Point {
            p: DVec3::new(0.1, 0.0, 0.0),
            power: DVec3::ONE,
            att: DVec3::new(1.0, 0.3, 0.1),
        },
        Lamp::Dir {
            to_light: DVec3::new(-0.3, 1.0, 0.5).normalize(),
            power: DVec3::splat(0.7),
        },
    ];
    let shadowed = vec![
        gas(
            DVec3::ZERO,
            1.0,
            0.6,
            DVec3::splat(0.01),
            DVec3::new(0.8, 0.8, 0.6),
        ),
        Ball {
            c: DVec3::new(0.5, 1.6, 0.3),
            r: 0.3,
            gas: None,
        },
        gas(
            DVec3::new(-0.6, 1.5, 0.4),
            0.35,
            (-30.0f64).exp(),
            DVec3::ZERO,
            DVec3::splat(0.5),
        ),
    ];
    let shadowed_lamps = vec![
        Lamp::Dir {
            to_light: DVec3::new(0.2, 1.0, 0.1).normalize(),
            power: DVec3::ONE,
        },
        Lamp::Point {
            p: DVec3::new(-1.2, 3.0, 0.8),
            power: DVec3::splat(0.9),
            att: DVec3::new(1.0, 0.0, 0.0),
        },
    ];
    // Seed 2 leaves 37 of the 40 rays for the check, which needs 25 (the others hit the
    // opaque sphere or see no gas); with some seeds (6, 99) fewer are left.
    let mut rng = support::Rng(2);
    let mut rnd = || rng.f();
    let mut cloud: Vec<Ball> = (0..12)
        .map(|_| {
            gas(
                DVec3::new(rnd(), rnd(), rnd()) * 1.6 - 0.8,
                0.2 + 0.3 * rnd(),
                (-8.0 * rnd() - 0.05).exp(),
                DVec3::new(rnd(), rnd(), rnd()) * 0.03,
                DVec3::new(rnd(), rnd(), rnd()),
            )
        })
        .collect();
    cloud.push(Ball {
        c: DVec3::new(0.2, 0.9, 0.1),
        r: 0.15,
        gas: None,
    });
    let cloud_lamps = vec![
        Lamp::Point {
            p: DVec3::new(0.0, 0.2, 0.1),
            power: DVec3::new(1.0, 0.9, 0.8),
            att: DVec3::new(1.0, 0.0, 0.5),
        },
        Lamp::Dir {
            to_light: DVec3::new(1.0, 0.7, 0.2).normalize(),
            power: DVec3::splat(0.6),
        },
    ];
    vec![
        ("overlapping emitters", overlapping, overlapping_lamps, 0.85),
        ("shadowed sphere", shadowed, shadowed_lamps, 1.0),
        ("small cloud", cloud, cloud_lamps, 1.0),
    ]
}

/// On each small scene separately, at tol 1e-2, 1e-4 and 1e-6, `claims` hold.
fn small_scenes_check(claims: &[Claim]) {
    let mut failures = Vec::new();
    for (name, balls, lamps, radius) in small_scenes() {
        let rays = sunflower(DVec3::new(0.05, -0.02, 4.0), DVec3::ZERO, radius, 40);
        let refs = references(&balls, &lamps, &rays);
        assert!(refs.len() >= 25, "{name}: only {} rays", refs.len());
        for tol in [1e-2, 1e-4, 1e-6] {
            if let Err(e) = judge(name, &balls, &lamps, &refs, tol, claims) {
                failures.push(e);
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// The reported error covers the true error on at least 95 % of the rays of each scene.
#[test]
fn error_estimate_covers_the_true_error_on_small_scenes() {
    small_scenes_check(&[Claim::CoversMost]);
}

/// The reported error is within [`TIGHT_MEDIAN`] of the true error in the median, on each scene.
#[test]
fn error_estimate_is_within_100x_of_the_true_error_on_small_scenes() {
    small_scenes_check(&[Claim::Tight]);
}

/// The exact integrator's error estimate is honest on gas_scatter's cloud: at a loose
/// tolerance, the true error (against the reference) is below the estimate on at least 95 % of
/// rays, and the estimate is within 100x of the true error on most rays where the error is
/// measurable.
#[test]
fn error_estimate_is_honest() {
    use crate::render::integrators::tests::gas_reference::reference;
    use crate::render::integrators::tests::gas_scatter::{camera_rays, cloud, ours, prepared};
    let (balls, lamps) = cloud();
    let setup = prepared(&balls, &lamps, Integrator::Exact, 1e-3);
    let view = setup.view();
    let (mut n, mut below, mut measurable, mut tight) = (0, 0, 0, 0);
    for (o, w) in camera_rays(60) {
        if balls
            .iter()
            .any(|b| b.gas.is_none() && roots(o, w, b.c, b.r).is_some())
        {
            continue;
        }
        let want = reference(&balls, &lamps, o, w, 1).gas;
        if want == DVec3::ZERO {
            continue;
        }
        let (got, est) = ours(&view, o, w);
        let err = (got - want).abs().max_element();
        // The reference is good to far better than 1e-8 relative (refinement check in the
        // cloud test); this floor was set for an earlier, coarser one.
        let floor = 3e-8 * want.abs().max_element();
        n += 1;
        below += usize::from(err <= est + floor);
        if err > 10.0 * floor {
            measurable += 1;
            tight += usize::from(est <= 100.0 * err);
        }
    }
    assert!(n >= 30, "{n}");
    assert!(
        below * 100 >= 95 * n,
        "estimate below the true error on {} of {n}",
        n - below
    );
    if measurable > 0 {
        assert!(
            tight * 2 > measurable,
            "within 100x on {tight} of {measurable}"
        );
    }
}
