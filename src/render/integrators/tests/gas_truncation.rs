//! Truncation and error-estimate honesty of the exact integrator, per camera ray against the
//! untruncated brute-force reference of `gas_reference` (no BVH, every sphere, every shadow
//! boundary). The integrator may stop a camera ray once what lies behind cannot change its
//! value within the tolerance, stop light paths whose optical depth makes the rest negligible
//! and skip shadowers below the budget, but every bound it uses must be in its reported
//! error: here the true error must never exceed the reported one, and the reported one must
//! not be uselessly large: its median over a scene's rays is within [`TIGHT_MEDIAN`] of the
//! true error.
//!
//! Rounding: the true error is known only to the reference's own error (panels 1 vs 2,
//! checked far below each tolerance) plus f64 rounding (1e-12 of the value allowed). Where
//! the true error is at that level (below [`Ray::floor`]) the estimate's tightness cannot be
//! measured: such rays count as tight when the estimate is within 100x of the floor and are
//! left out of the median otherwise.

use glam::DVec3;

/// The largest median estimate/true error the tightness tests accept.
const TIGHT_MEDIAN: f64 = 100.0;
use crate::render::integrators::{self, Estimate, Scratch};
use crate::render::sampler::Rng;
use crate::render::{Counters, Integrator, PrepareOptions, RenderOptions, View};

use crate::render::integrators::tests::gas_reference::{
    checked, hits_opaque, in_shadow_somewhere, roots, sigma_of, vrml, Ball, Lamp,
};
use crate::testing as support;

mod small_scenes;

fn prepared(balls: &[Ball], lamps: &[Lamp], tol: f64) -> support::Setup {
    let (scene, _) = support::scene(&vrml(balls, lamps));
    let opts = RenderOptions {
        integrator: Integrator::Exact,
        tol,
        ..RenderOptions::default()
    };
    support::Setup::new(scene, &PrepareOptions::default(), opts)
}

fn ours(view: &View, o: DVec3, w: DVec3) -> Estimate {
    integrators::radiance(
        view,
        o,
        w,
        &mut Rng::new(0, 0),
        &mut Scratch::default(),
        &mut Counters::default(),
    )
}

/// `n` rays from `o` to a sunflower of points filling the disc of `radius` about `centre` in
/// the plane z = centre.z.
fn sunflower(o: DVec3, centre: DVec3, radius: f64, n: usize) -> Vec<(DVec3, DVec3)> {
    (0..n)
        .map(|k| {
            let a = k as f64 * 2.399_963_229_728_653;
            let r = radius * ((k as f64 + 0.5) / n as f64).sqrt();
            let target = centre + DVec3::new(r * a.cos(), r * a.sin(), 0.0);
            (o, (target - o).normalize())
        })
        .collect()
}

/// One camera ray: the renderer's value and error estimate, and the reference with its own
/// error.
struct Ray {
    value: DVec3,
    est: f64,
    want: DVec3,
    ref_err: f64,
}

impl Ray {
    fn scale(&self) -> f64 {
        self.want.abs().max_element()
    }
    fn true_err(&self) -> f64 {
        (self.value - self.want).abs().max_element()
    }
    /// Below this the true error is not measurable: f64 rounding of the value, or the
    /// reference's own error.
    fn floor(&self) -> f64 {
        (1e-13 * self.scale()).max(10.0 * self.ref_err)
    }
    fn covered(&self) -> bool {
        self.true_err() <= self.est + 1e-12 * self.scale() + 2.0 * self.ref_err
    }
}

/// What a set of rays says about the estimate.
struct Verdict {
    rays: usize,
    covered: usize,
    /// The largest true error / estimate, and at which ray.
    worst: (f64, usize),
    /// Rays in the median, and left out of it (true error at rounding level, estimate not).
    ranked: usize,
    unmeasurable: usize,
    median: f64,
    /// The largest reference error, relative to the value.
    ref_rel: f64,
    /// The largest estimate relative to the value.
    est_rel: f64,
}

fn verdict(rays: &[Ray]) -> Verdict {
    let mut ratios = Vec::new();
    let (mut covered, mut worst, mut unmeasurable) = (0, (0.0f64, 0), 0);
    let (mut ref_rel, mut est_rel) = (0.0f64, 0.0f64);
    for (k, r) in rays.iter().enumerate() {
        covered += usize::from(r.covered());
        let over = r.true_err() / r.est.max(1e-300);
        if over > worst.0 {
            worst = (over, k);
        }
        let floor = r.floor();
        if r.true_err() > floor || r.est <= 100.0 * floor {
            ratios.push(r.est / r.true_err().max(floor));
        } else {
            unmeasurable += 1;
        }
        ref_rel = ref_rel.max(r.ref_err / r.scale());
        est_rel = est_rel.max(r.est / r.scale());
    }
    ratios.sort_by(f64::total_cmp);
    let median = if ratios.is_empty() {
        0.0
    } else {
        ratios[ratios.len() / 2]
    };
    Verdict {
        rays: rays.len(),
        covered,
        worst,
        ranked: ratios.len(),
        unmeasurable,
        median,
        ref_rel,
        est_rel,
    }
}

/// The reference for every ray into gas (rays with nothing to see, or hitting an opaque
/// sphere, are dropped), computed once for all tolerances.
fn references(
    balls: &[Ball],
    lamps: &[Lamp],
    rays: &[(DVec3, DVec3)],
) -> Vec<(DVec3, DVec3, DVec3, f64)> {
    rays.iter()
        .filter(|(o, w)| !hits_opaque(balls, *o, *w))
        .filter_map(|&(o, w)| {
            let (r, err) = checked(balls, lamps, o, w);
            assert!(r.pieces > 0 || r.gas == DVec3::ZERO);
            (r.gas != DVec3::ZERO).then_some((o, w, r.gas, err))
        })
        .collect()
}

/// What a test claims of the reported error.
#[derive(Clone, Copy, PartialEq)]
enum Claim {
    /// It covers the true error on every ray.
    CoversEvery,
    /// It covers the true error on at least 95 % of the rays.
    CoversMost,
    /// The median of estimate / true error is at most 100.
    Tight,
}

/// Renders every referenced ray at `tol` and judges the `claims`; `Err` says which failed
/// and by how much. A reference whose own error is not 1000x below `tol` fails too.
fn judge(
    name: &str,
    balls: &[Ball],
    lamps: &[Lamp],
    refs: &[(DVec3, DVec3, DVec3, f64)],
    tol: f64,
    claims: &[Claim],
) -> Result<(), String> {
    let start = std::time::Instant::now();
    let setup = prepared(balls, lamps, tol);
    let view = setup.view();
    let rays: Vec<Ray> = refs
        .iter()
        .map(|&(o, w, want, ref_err)| {
            let e = ours(&view, o, w);
            Ray {
                value: e.value,
                est: e.error,
                want,
                ref_err,
            }
        })
        .collect();
    let v = verdict(&rays);
    let line = format!(
        "{name} tol {tol:e}: rendered in {:.2} s: {} rays, estimate covers the true error on {} ({:.1} %), worst \
         true/estimate {:.3e} (ray {}), median estimate/true {:.3e} over {} rays ({} at \
         rounding level left out), largest estimate {:.2e} of the value, reference error \
         {:.1e} of the value",
        start.elapsed().as_secs_f64(),
        v.rays,
        v.covered,
        100.0 * v.covered as f64 / v.rays as f64,
        v.worst.0,
        v.worst.1,
        v.median,
        v.ranked,
        v.unmeasurable,
        v.est_rel,
        v.ref_rel
    );
    eprintln!("{line}");
    let mut why = Vec::new();
    if claims.contains(&Claim::CoversEvery) && v.covered < v.rays {
        let r = &rays[v.worst.1];
        let missed: Vec<usize> = (0..rays.len()).filter(|&k| !rays[k].covered()).collect();
        why.push(format!(
            "the true error exceeds the estimate on rays {missed:?}, worst ray {}: value {} \
             reference {} true error {:.3e} estimate {:.3e}",
            v.worst.1,
            r.value,
            r.want,
            r.true_err(),
            r.est
        ));
    }
    if claims.contains(&Claim::CoversMost) && v.covered * 100 < 95 * v.rays {
        why.push(format!(
            "covered on {} of {} rays, below 95 %",
            v.covered, v.rays
        ));
    }
    if claims.contains(&Claim::Tight) && v.median > TIGHT_MEDIAN {
        why.push(format!(
            "median estimate/true {:.3e} > {TIGHT_MEDIAN:e}",
            v.median
        ));
    }
    if v.ref_rel > 1e-3 * tol {
        why.push(format!(
            "the reference's own error {:.1e} is not far below tol",
            v.ref_rel
        ));
    }
    if why.is_empty() {
        Ok(())
    } else {
        Err(format!("{line}\n  {}", why.join("\n  ")))
    }
}

fn judge_all(
    name: &str,
    balls: &[Ball],
    lamps: &[Lamp],
    rays: &[(DVec3, DVec3)],
    tols: &[f64],
    claims: &[Claim],
    min_rays: usize,
) {
    // The reference is computed once for every tolerance.
    let start = std::time::Instant::now();
    let refs = references(balls, lamps, rays);
    eprintln!(
        "{name}: reference for {} rays in {:.2} s",
        refs.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(refs.len() >= min_rays, "{name}: only {} rays", refs.len());
    let failures: Vec<String> = tols
        .iter()
        .filter_map(|&tol| judge(name, balls, lamps, &refs, tol, claims).err())
        .collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// `n` barely overlapping gas spheres in [-1, 1]^3, each of optical depth `tau` along a
/// diameter, under a point light and a directional light.
fn thick_cloud(n: usize, tau: f64) -> (Vec<Ball>, Vec<Lamp>) {
    let mut rng = support::Rng(2024);
    let mut rnd = || rng.f();
    let r = 0.6 * (n as f64).powf(-1.0 / 3.0);
    let albedo = DVec3::new(0.9, 0.7, 0.5);
    let balls = (0..n)
        .map(|_| Ball {
            c: DVec3::new(rnd(), rnd(), rnd()) * 2.0 - 1.0,
            r,
            gas: Some(((-tau).exp(), DVec3::ZERO, albedo)),
        })
        .collect();
    let lamps = vec![
        Lamp::Point {
            p: DVec3::splat(3.0),
            power: DVec3::splat(0.8),
            att: DVec3::new(1.0, 0.0, 0.0),
        },
        Lamp::Dir {
            to_light: DVec3::ONE.normalize(),
            power: DVec3::splat(0.5),
        },
    ];
    (balls, lamps)
}

/// A thick cloud: the camera ray may stop early, light paths through several dense spheres
/// may stop early, and most of the spheres are negligible shadowers for most rays. 300
/// spheres of optical depth 4, and 400 of optical depth 16 so that most camera rays end
/// far below every tolerance.
fn thick_cloud_check(claims: &[Claim]) {
    for (n, tau) in [(300, 4.0), (400, 16.0)] {
        let (balls, lamps) = thick_cloud(n, tau);
        let rays = sunflower(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, 1.0, 64);
        // How thick: the optical depth of each camera ray through the whole cloud.
        let mut depth: Vec<f64> = rays
            .iter()
            .map(|&(o, w)| {
                balls
                    .iter()
                    .filter_map(|b| roots(o, w, b.c, b.r).map(|(t0, t1)| sigma_of(b) * (t1 - t0)))
                    .sum()
            })
            .collect();
        depth.sort_by(f64::total_cmp);
        let name = format!("thick cloud ({n} spheres of tau {tau})");
        eprintln!(
            "{name}: camera-ray optical depth median {:.1}, max {:.1}",
            depth[depth.len() / 2],
            depth[depth.len() - 1]
        );
        judge_all(&name, &balls, &lamps, &rays, &[1e-4, 1e-6], claims, 50);
    }
}

#[test]
fn truncation_in_a_thick_cloud_is_within_the_reported_error() {
    thick_cloud_check(&[Claim::CoversEvery]);
}

#[test]
fn reported_error_in_a_thick_cloud_is_within_100x_of_the_true_error() {
    thick_cloud_check(&[Claim::Tight]);
}

/// Camera rays crossing the boundary of `shadower`'s shadow (for `lamp`) inside `lit`, at
/// offsets from 1e-2 down to 1e-8 either side, along the line of targets `from` -> `to`
/// (a target at `from` must see the shadow, one at `to` must not).
fn rim_rays(
    o: DVec3,
    lit: &Ball,
    shadower: &Ball,
    lamp: &Lamp,
    from: DVec3,
    to: DVec3,
) -> Vec<(DVec3, DVec3)> {
    let ray = |s: f64| (o, (from + s * (to - from) - o).normalize());
    let sees = |s: f64| {
        let (o, w) = ray(s);
        roots(o, w, lit.c, lit.r)
            .is_some_and(|(t0, t1)| in_shadow_somewhere(shadower, lamp, o, w, t0.max(0.0), t1))
    };
    assert!(sees(0.0) && !sees(1.0), "rim search from {from} to {to}");
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let m = 0.5 * (lo + hi);
        if sees(m) {
            lo = m;
        } else {
            hi = m;
        }
    }
    [-1e-2, -1e-4, -1e-6, -1e-8, 1e-8, 1e-6, 1e-4, 1e-2]
        .iter()
        .map(|d| ray(lo + d))
        .collect()
}

/// A thin gas sphere lit by a point light and a directional light, each behind a dense gas
/// sphere (optical depth 700 and 30): rays through the shadows, along their rims (the
/// shadow boundary grazed to 1e-8) and outside them.
fn dense_shadowers_check(claims: &[Claim]) {
    let lit = Ball {
        c: DVec3::ZERO,
        r: 1.0,
        gas: Some((0.5, DVec3::splat(0.01), DVec3::new(0.9, 0.8, 0.7))),
    };
    let point = Lamp::Point {
        p: DVec3::new(0.2, 5.0, -0.2),
        power: DVec3::ONE,
        att: DVec3::new(1.0, 0.0, 0.0),
    };
    let to_light = DVec3::new(0.5, 1.0, 0.3).normalize();
    let dir = Lamp::Dir {
        to_light,
        power: DVec3::new(0.6, 0.7, 0.8),
    };
    let tau700 = Ball {
        c: DVec3::new(0.1, 2.2, -0.1),
        r: 0.35,
        gas: Some(((-700.0f64).exp(), DVec3::ZERO, DVec3::splat(0.5))),
    };
    let tau30 = Ball {
        c: 1.9 * to_light + DVec3::new(0.05, 0.0, -0.05),
        r: 0.3,
        gas: Some(((-30.0f64).exp(), DVec3::ZERO, DVec3::splat(0.5))),
    };
    let balls = vec![lit, tau700, tau30];
    let lamps = vec![point, dir];
    let o = DVec3::new(0.0, 0.0, 4.0);
    let mut rays = sunflower(o, DVec3::ZERO, 1.0, 40);
    for (shadower, lamp) in [(&tau700, &point), (&tau700, &dir), (&tau30, &dir)] {
        for (from, to) in [
            (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.5, 0.0, 0.0)),
            (DVec3::new(0.0, 0.3, 0.0), DVec3::new(-1.5, 0.3, 0.0)),
        ] {
            if !(0..2).all(|e| {
                let t = [from, to][e];
                let w = (t - o).normalize();
                let seen = roots(o, w, lit.c, lit.r).is_some_and(|(t0, t1)| {
                    in_shadow_somewhere(shadower, lamp, o, w, t0.max(0.0), t1)
                });
                seen == (e == 0)
            }) {
                continue;
            }
            rays.extend(rim_rays(o, &lit, shadower, lamp, from, to));
        }
    }
    assert!(rays.len() >= 40 + 4 * 8, "{} rays", rays.len());
    judge_all(
        "dense shadowers",
        &balls,
        &lamps,
        &rays,
        &[1e-4, 1e-6],
        claims,
        60,
    );
}

#[test]
fn shadows_of_dense_spheres_are_within_the_reported_error() {
    dense_shadowers_check(&[Claim::CoversEvery]);
}

#[test]
fn reported_error_under_dense_shadows_is_within_100x_of_the_true_error() {
    dense_shadowers_check(&[Claim::Tight]);
}
