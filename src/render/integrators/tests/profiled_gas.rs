//! Gas spheres with radial density profiles (docs/model.md section 6) rendered against the
//! independent brute-force reference of `profiled_reference` (numerical density integrals
//! along the camera ray and every light path, no closed-form chords, no BVH), ray by ray
//! through `integrators::radiance` as `gas_scatter` does:
//!
//! - one emitting sphere of each profile, no lights: the closed form `C (1 - exp(-tau))`,
//!   to 1e-12 up to 0.9 of the radius from the centre (1e-9 grazing), with a zero or
//!   negligible reported error; `march` converging to it as its step shrinks;
//! - overlapping spheres of different profiles and emission colours, no lights (the emission
//!   needs quadrature): within 1e-6 at tol 1e-8, the reported error covering the true error on
//!   at least 95 % of the rays;
//! - a lit cloud of every profile with opaque spheres and both kinds of light: the same at
//!   tol 1e-8, coverage at tol 1e-3, and Monte Carlo within 4 standard errors on 95 % of rays;
//! - GasParticle with the constant profile renders bit for bit like plain Materials.

use std::sync::OnceLock;

use crate::render::integrators::{self, Estimate, Scratch};
use crate::render::sampler::Rng;
use crate::render::{Counters, Integrator, PrepareOptions, RenderOptions, View};
use glam::DVec3;

use crate::render::integrators::tests::gas_reference::{self, roots, Lamp};
use crate::render::integrators::tests::profiled_reference::{
    checked, plain, ray_past, vrml, Ball, Profile,
};
use crate::testing as support;

fn prepared(balls: &[Ball], lamps: &[Lamp], integrator: Integrator, tol: f64) -> support::Setup {
    let (scene, _) = support::scene(&vrml(balls, lamps));
    let opts = RenderOptions {
        integrator,
        tol,
        ..RenderOptions::default()
    };
    support::Setup::new(scene, &PrepareOptions::default(), opts)
}

/// The renderer's estimate along one ray (background black), with the random stream `rng`
/// (used by Monte Carlo only).
fn ours(view: &View, o: DVec3, w: DVec3, rng: &mut Rng) -> Estimate {
    integrators::radiance(
        view,
        o,
        w,
        rng,
        &mut Scratch::default(),
        &mut Counters::default(),
    )
}

/// A camera ray with the reference's value and its own error.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RefRay {
    pub o: DVec3,
    pub w: DVec3,
    pub want: DVec3,
    pub ref_err: f64,
}

/// The reference for every ray that sees gas and misses the opaque spheres (its line meets
/// none), each checked to `ref_rel` of its value.
fn references(
    balls: &[Ball],
    lamps: &[Lamp],
    rays: &[(DVec3, DVec3)],
    ref_rel: f64,
) -> Vec<RefRay> {
    rays.iter()
        .filter(|(o, w)| {
            !balls
                .iter()
                .any(|b| b.gas.is_none() && roots(*o, *w, b.c, b.r).is_some())
        })
        .filter_map(|&(o, w)| {
            let (r, ref_err) = checked(balls, lamps, o, w);
            assert!(r.pieces > 0 || r.gas == DVec3::ZERO);
            assert!(
                ref_err <= ref_rel * r.gas.abs().max_element(),
                "reference refinement: {ref_err:e} of {}",
                r.gas
            );
            (r.gas != DVec3::ZERO).then_some(RefRay {
                o,
                w,
                want: r.gas,
                ref_err,
            })
        })
        .collect()
}

/// `n` rays from `o` to a sunflower of points filling the disc of `radius` about the origin in
/// the plane z = 0.
fn sunflower(o: DVec3, radius: f64, n: usize) -> Vec<(DVec3, DVec3)> {
    (0..n)
        .map(|k| {
            let a = k as f64 * 2.399_963_229_728_653;
            let r = radius * ((k as f64 + 0.5) / n as f64).sqrt();
            (
                o,
                (DVec3::new(r * a.cos(), r * a.sin(), 0.0) - o).normalize(),
            )
        })
        .collect()
}

/// Renders every ray of `refs` with the exact integrator at `tol`. Each ray's value must be
/// within `rel` of the reference (if given), and the reported error must cover the true error
/// (up to rounding, 1e-12 of the value, and twice the reference's own error) on at least 95 %
/// of the rays.
fn judge(name: &str, balls: &[Ball], lamps: &[Lamp], refs: &[RefRay], tol: f64, rel: Option<f64>) {
    let start = std::time::Instant::now();
    let setup = prepared(balls, lamps, Integrator::Exact, tol);
    let view = setup.view();
    // worst_over: the largest true error / (estimate + rounding allowance), <= 1 if covered.
    let (mut covered, mut worst_rel, mut worst_over) = (0, (0.0f64, 0), (0.0f64, 0));
    let mut far = Vec::new();
    for (k, r) in refs.iter().enumerate() {
        let e = ours(&view, r.o, r.w, &mut Rng::new(0, 0));
        let scale = r.want.abs().max_element();
        let err = (e.value - r.want).abs().max_element();
        let allowed = e.error + 1e-12 * scale + 2.0 * r.ref_err;
        covered += usize::from(err <= allowed);
        if err / scale > worst_rel.0 {
            worst_rel = (err / scale, k);
        }
        if err / allowed > worst_over.0 {
            worst_over = (err / allowed, k);
        }
        if rel.is_some_and(|rel| err > rel * scale) {
            far.push(format!(
                "ray {k}: got {} want {} rel {:.2e} (estimate {:.2e})",
                e.value,
                r.want,
                err / scale,
                e.error
            ));
        }
    }
    let n = refs.len();
    let line = format!(
        "{name} tol {tol:e}: {n} rays in {:.2} s, worst relative error {:.2e} (ray {}), estimate \
         covers the true error on {covered} ({:.1} %), worst true / allowed error {:.2e} (ray {})",
        start.elapsed().as_secs_f64(),
        worst_rel.0,
        worst_rel.1,
        100.0 * covered as f64 / n as f64,
        worst_over.0,
        worst_over.1
    );
    eprintln!("{line}");
    assert!(far.is_empty(), "{line}\n{}", far.join("\n"));
    assert!(
        covered * 100 >= 95 * n,
        "{line}\nthe estimate covers the true error on {covered} of {n} rays, below 95 %"
    );
}

// ---- One emitting sphere: the closed form.

/// One emitting sphere of `profile`, no lights, at three transparencies, against
/// `C (1 - exp(-tau))` to 1e-12 up to 0.9 of the radius from the centre: rays through the
/// centre, grazing (1e-2 and 1e-4 of the radius inside the rim: further in, the ray's own
/// rounding, a few 1e-16 of the centre's distance from the eye, is more than 1e-9 of the
/// optical depth), at random distances from the centre, and one just missing it.
fn one_emitting_sphere(profile: Profile) {
    let (c, r) = (DVec3::new(0.2, -0.1, 0.3), 0.8);
    let eye = DVec3::new(0.3, 0.2, 5.0);
    let mut rng = support::Rng(3);
    // (ray, its distance from the centre)
    let mut rays = vec![(ray_past(eye, c, 0.0, 0.0), 0.0)];
    for (k, inside) in [1e-2, 1e-4].into_iter().enumerate() {
        let rho = (1.0 - inside) * r;
        rays.push((ray_past(eye, c, rho, 1.0 + k as f64), rho));
    }
    for _ in 0..16 {
        let (rho, phi) = (rng.f() * r, rng.range(0.0, std::f64::consts::TAU));
        rays.push((ray_past(eye, c, rho, phi), rho));
    }
    rays.push((ray_past(eye, c, 1.01 * r, 0.5), 1.01 * r));
    let mut worst = (0.0f64, 0.0f64);
    for tr in [0.25, 1e-3, 0.999] {
        let balls = [Ball {
            c,
            r,
            gas: Some((tr, DVec3::new(0.9, 0.5, 0.1), DVec3::splat(0.6), profile)),
        }];
        let setup = prepared(&balls, &[], Integrator::Exact, 1e-8);
        let view = setup.view();
        for (k, &((o, w), rho)) in rays.iter().enumerate() {
            let (want, ref_err) = checked(&balls, &[], o, w);
            let want = want.gas;
            let e = ours(&view, o, w, &mut Rng::new(0, 0));
            let scale = want.abs().max_element();
            let what = format!(
                "{profile:?} tr {tr} ray {k}: got {} ± {:e} want {want}",
                e.value, e.error
            );
            if want == DVec3::ZERO {
                assert_eq!(e.value, DVec3::ZERO, "{what}");
                continue;
            }
            assert!(
                ref_err <= 1e-11 * scale,
                "{what}: reference error {ref_err:e}"
            );
            let rel = (e.value - want).abs().max_element() / scale;
            worst = (worst.0.max(rel), worst.1.max(e.error / scale));
            // docs/model.md section 6's closed form to 1e-12 (plus the reference's own error)
            // wherever the ray's rounding allows it: up to 0.9 of the radius from the centre.
            let limit = if rho <= 0.9 * r {
                1e-12 + 2.0 * ref_err / scale
            } else {
                1e-9
            };
            assert!(rel <= limit, "{what}: rel {rel:e} (limit {limit:e})");
            assert!(
                e.error <= 1e-9 * scale,
                "{what}: reported error {:e}",
                e.error
            );
        }
    }
    eprintln!(
        "one emitting {profile:?} sphere: worst relative error {:.2e}, largest reported error {:.2e} of the value",
        worst.0, worst.1
    );
}

#[test]
fn one_emitting_linear_sphere_is_closed_form() {
    one_emitting_sphere(Profile::Linear);
}

#[test]
fn one_emitting_quadratic_sphere_is_closed_form() {
    one_emitting_sphere(Profile::Quadratic);
}

#[test]
fn one_emitting_gaussian_sphere_is_closed_form() {
    one_emitting_sphere(Profile::Gaussian(1.0 / 3.0));
}

#[test]
fn one_emitting_narrow_gaussian_sphere_is_closed_form() {
    one_emitting_sphere(Profile::Gaussian(0.15));
}

/// `march` samples profiled densities at its steps' midpoints: on one emitting sphere of each
/// profile (lit, so that the light's shadow through the sphere counts too), its error against
/// the reference falls at least 3 times when the step is quartered (march is first order: it
/// weights each step's source by the transmittance at the step's start), and is below 1e-2
/// of the value at a step of 1/160 of the radius.
#[test]
fn march_converges_on_profiled_gas() {
    let (c, r) = (DVec3::new(0.2, -0.1, 0.3), 0.8);
    let eye = DVec3::new(0.3, 0.2, 5.0);
    let lamps = [Lamp::Dir {
        to_light: DVec3::new(0.3, 0.8, 0.5).normalize(),
        power: DVec3::ONE,
    }];
    for profile in [
        Profile::Linear,
        Profile::Quadratic,
        Profile::Gaussian(1.0 / 3.0),
    ] {
        let balls = [Ball {
            c,
            r,
            gas: Some((0.2, DVec3::new(0.3, 0.2, 0.1), DVec3::splat(0.7), profile)),
        }];
        for (k, rho) in [0.0, 0.35, 0.7].into_iter().enumerate() {
            let (o, w) = ray_past(eye, c, rho * r, 0.7 * k as f64);
            let (want, _) = checked(&balls, &lamps, o, w);
            let want = want.gas;
            let err = |step: f64| {
                let setup = prepared(&balls, &lamps, Integrator::March { step }, 1e-4);
                let got = ours(&setup.view(), o, w, &mut Rng::new(0, 0)).value;
                (got - want).abs().max_element() / want.abs().max_element()
            };
            let (coarse, fine) = (err(0.02), err(0.005));
            assert!(
                fine * 3.0 <= coarse && fine <= 1e-2,
                "{profile:?} rho {rho}: step 0.02 error {coarse:e}, step 0.005 error {fine:e}"
            );
        }
    }
}

// ---- Overlapping emitters.

/// Five overlapping spheres, one of each profile (the gaussian at two widths), each its own
/// emission colour, no lights: the source `sum sigma_j C_j / sigma_t` varies along the ray,
/// so the emission has no closed form.
#[test]
fn overlapping_emitters_of_different_profiles_within_tolerance() {
    let gas = |c: DVec3, r: f64, tr: f64, e: DVec3, p: Profile| Ball {
        c,
        r,
        gas: Some((tr, e, DVec3::splat(0.5), p)),
    };
    let balls = vec![
        gas(
            DVec3::new(-0.3, 0.0, 0.0),
            0.7,
            0.2,
            DVec3::new(0.9, 0.2, 0.1),
            Profile::Linear,
        ),
        gas(
            DVec3::new(0.3, 0.1, 0.1),
            0.6,
            0.05,
            DVec3::new(0.1, 0.8, 0.3),
            Profile::Quadratic,
        ),
        gas(
            DVec3::new(0.0, -0.35, -0.2),
            0.55,
            0.5,
            DVec3::new(0.2, 0.3, 0.9),
            Profile::Gaussian(1.0 / 3.0),
        ),
        gas(
            DVec3::new(0.1, 0.3, 0.2),
            0.5,
            0.3,
            DVec3::new(0.6, 0.6, 0.1),
            Profile::Gaussian(0.15),
        ),
        gas(
            DVec3::new(-0.1, -0.1, 0.4),
            0.3,
            0.7,
            DVec3::splat(0.05),
            Profile::Constant,
        ),
    ];
    let start = std::time::Instant::now();
    let rays = sunflower(DVec3::new(0.05, -0.02, 4.0), 0.95, 48);
    let refs = references(&balls, &[], &rays, 1e-11);
    eprintln!(
        "overlapping emitters: reference for {} rays in {:.2} s",
        refs.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(refs.len() >= 40, "only {} rays", refs.len());
    judge("overlapping emitters", &balls, &[], &refs, 1e-8, Some(1e-6));
}

// ---- The lit cloud.

/// 18 overlapping gas spheres of random profiles (each profile at least twice), emission
/// colours and albedos, transparency 0.2 to 0.9, two opaque spheres, a directional and a
/// point light.
pub(crate) fn cloud() -> (Vec<Ball>, Vec<Lamp>) {
    let profiles = [
        Profile::Constant,
        Profile::Linear,
        Profile::Quadratic,
        Profile::Gaussian(1.0 / 3.0),
        Profile::Gaussian(0.15),
    ];
    let mut rng = support::Rng(17);
    let mut rnd = || rng.f();
    let mut balls: Vec<Ball> = (0..18)
        .map(|k| {
            let c = DVec3::new(rnd(), rnd(), rnd()) * 2.0 - 1.0;
            let r = 0.3 + 0.4 * rnd();
            let tr = 0.2 + 0.7 * rnd();
            let emit = DVec3::new(rnd(), rnd(), rnd()) * 0.05;
            let albedo = DVec3::new(rnd(), rnd(), rnd());
            // Every profile twice, then at random.
            let p = if k < 10 {
                profiles[k % 5]
            } else {
                profiles[(rnd() * 5.0) as usize]
            };
            Ball {
                c,
                r,
                gas: Some((tr, emit, albedo, p)),
            }
        })
        .collect();
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

/// The cloud's references (40 rays of `gas_scatter::camera_rays`, those missing the opaque
/// spheres), computed once for every test that uses them, each checked to 1e-10.
pub(crate) fn cloud_references() -> &'static [RefRay] {
    static REFS: OnceLock<Vec<RefRay>> = OnceLock::new();
    REFS.get_or_init(|| {
        let (balls, lamps) = cloud();
        let start = std::time::Instant::now();
        let refs = references(
            &balls,
            &lamps,
            &crate::render::integrators::tests::gas_scatter::camera_rays(40),
            1e-10,
        );
        eprintln!(
            "lit profiled cloud: reference for {} rays in {:.2} s",
            refs.len(),
            start.elapsed().as_secs_f64()
        );
        assert!(refs.len() >= 20, "only {} rays", refs.len());
        refs
    })
}

#[test]
fn lit_cloud_of_every_profile_within_tolerance() {
    let (balls, lamps) = cloud();
    judge(
        "lit cloud",
        &balls,
        &lamps,
        cloud_references(),
        1e-8,
        Some(1e-6),
    );
}

/// At a loose tolerance the true error is within the reported error on 95 % of the rays.
#[test]
fn lit_cloud_error_estimate_covers_the_true_error_at_a_loose_tolerance() {
    let (balls, lamps) = cloud();
    judge("lit cloud", &balls, &lamps, cloud_references(), 1e-3, None);
}

/// Monte Carlo on the lit cloud: per ray the mean of 2000 samples (one random stream per ray)
/// is within 4 standard errors of the reference in every channel on at least 95 % of the rays
/// (for a normal mean a channel fails with probability 6.3e-5), allowing besides 1e-6 of the
/// value (the exact integrator's bar at this tol) for what the estimator does not sample: a
/// channel whose standard error is 0 must be that close.
#[test]
fn lit_cloud_monte_carlo_agrees_with_the_reference() {
    let (balls, lamps) = cloud();
    let refs = cloud_references();
    let start = std::time::Instant::now();
    let setup = prepared(&balls, &lamps, Integrator::Mc, 1e-8);
    let view = setup.view();
    let n = 2000;
    let mut failed = Vec::new();
    let mut worst_z = 0.0f64;
    for (g, r) in refs.iter().enumerate() {
        let mut rng = Rng::new(29, g as u64);
        let mut scratch = Scratch::default();
        let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
        for _ in 0..n {
            let v = integrators::radiance(
                &view,
                r.o,
                r.w,
                &mut rng,
                &mut scratch,
                &mut Counters::default(),
            )
            .value;
            s += v;
            s2 += v * v;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean).max(DVec3::ZERO) / (n as f64 - 1.0)).powf(0.5);
        // What is not sampled (emission, transmittance) may come from quadrature to tol.
        let slack = 1e-6 * r.want.abs().max_element() + r.ref_err;
        let ok = (0..3).all(|k| (mean[k] - r.want[k]).abs() <= 4.0 * se[k] + slack);
        for k in 0..3 {
            if se[k] > 0.0 {
                worst_z = worst_z.max((mean[k] - r.want[k]).abs() / se[k]);
            }
        }
        if !ok {
            failed.push(format!("ray {g}: mc {mean} ± {se} vs reference {}", r.want));
        }
    }
    eprintln!(
        "lit cloud mc: {} rays of {n} samples in {:.2} s, {} beyond 4 standard errors, worst |z| {worst_z:.2}",
        refs.len(),
        start.elapsed().as_secs_f64(),
        failed.len()
    );
    assert!(
        failed.len() * 100 <= 5 * refs.len(),
        "{} of {} rays beyond 4 standard errors:\n{}",
        failed.len(),
        refs.len(),
        failed.join("\n")
    );
}

// ---- The constant profile through GasParticle.

/// The cloud with every gas sphere constant, written once as GasParticle instances and once
/// with plain Materials (`gas_reference::vrml`): the two render bit for bit alike, ray by ray
/// with each integrator (value and reported error) and as a whole picture.
#[test]
fn constant_gas_particles_render_like_plain_materials() {
    let (mut balls, lamps) = cloud();
    for b in &mut balls {
        if let Some(g) = &mut b.gas {
            g.3 = Profile::Constant;
        }
    }
    let plain_balls: Vec<gas_reference::Ball> = balls.iter().map(plain).collect();
    let texts = [
        vrml(&balls, &lamps),
        gas_reference::vrml(&plain_balls, &lamps),
    ];
    assert!(texts[0].contains("GasParticle {") && !texts[1].contains("GasParticle"));
    for integrator in [Integrator::Exact, Integrator::Mc] {
        let setups = texts.clone().map(|text| {
            let (scene, _) = support::scene(&text);
            let opts = RenderOptions {
                width: 16,
                height: 12,
                spp: 2,
                integrator,
                tol: 1e-6,
                ..RenderOptions::default()
            };
            support::Setup::new(scene, &PrepareOptions::default(), opts)
        });
        let views = [setups[0].view(), setups[1].view()];
        for (k, (o, w)) in crate::render::integrators::tests::gas_scatter::camera_rays(24)
            .into_iter()
            .enumerate()
        {
            let [a, b] = [0, 1].map(|s| ours(&views[s], o, w, &mut Rng::new(7, k as u64)));
            assert!(
                a.value == b.value && a.error == b.error && a.covered == b.covered,
                "{integrator:?} ray {k}: GasParticle {a:?} vs Material {b:?}"
            );
        }
        let [a, b] = [0, 1].map(|s| support::render_prepared(&setups[s].prep, &setups[s].opts));
        assert!(
            a.rgb == b.rgb && a.alpha == b.alpha,
            "{integrator:?}: the pictures differ"
        );
    }
}
