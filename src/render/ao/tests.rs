//! The exact union against independent answers: the single cap's closed form, and Monte
//! Carlo over cosine-weighted directions with a stated confidence.

use glam::DVec3;

use super::cap::{blocked_by_ball, form_factor as one_cap, Blocked, Cap};
use super::union::{covered_fraction, UnionScratch, Weighting};
use super::AoScratch;
use crate::render::visibility::Opaque;
use crate::render::Prepared;

/// A small generator of its own (splitmix64).
pub(super) struct Mix(pub(super) u64);
impl Mix {
    pub(super) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// An index below `n`.
    pub(super) fn next_index(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
    pub(super) fn unit(&mut self) -> DVec3 {
        let z = 2.0 * self.next() - 1.0;
        let a = std::f64::consts::TAU * self.next();
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * a.cos(), r * a.sin(), z)
    }
}

/// [`super::unoccluded_to`] among occluders none of which is a Cylinder or a Cone: exact.
pub(super) fn unoccluded(
    prep: &Prepared,
    x: DVec3,
    n: DVec3,
    own: Option<Opaque>,
    reach: (f64, Weighting),
    s: &mut AoScratch,
) -> f64 {
    let (v, error) = super::unoccluded_to(prep, x, n, own, reach, 0.0, s);
    assert_eq!(error, 0.0, "a round solid near the point");
    v
}

#[test]
fn one_cap_matches_the_closed_form_everywhere() {
    let mut s = UnionScratch::default();
    let mut worst: f64 = 0.0;
    for ti in 0..=180 {
        let theta = f64::from(ti) * std::f64::consts::PI / 180.0;
        for ai in 1..90 {
            let alpha = f64::from(ai) * std::f64::consts::FRAC_PI_2 / 90.0;
            let axis = DVec3::new(theta.sin(), 0.0, theta.cos());
            let cap = Cap {
                axis,
                cos: alpha.cos(),
            };
            let got = covered_fraction(DVec3::Z, &[cap], Weighting::Cosine, &mut s);
            let want = one_cap(theta.cos(), theta.sin(), alpha.cos());
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() < 1e-13,
                "theta {theta} alpha {alpha}: {got} against {want}"
            );
        }
    }
    eprintln!("one cap: worst {worst:e}");
}

/// The cosine-weighted fraction covered by `caps`, by `n` directions; and its standard error.
fn monte_carlo(caps: &[Cap], n: usize, rng: &mut Mix) -> (f64, f64) {
    let mut hits = 0usize;
    for _ in 0..n {
        // Cosine-weighted about z: a uniform point of the disk lifted onto the hemisphere.
        let (u, v) = (rng.next(), rng.next());
        let r = u.sqrt();
        let a = std::f64::consts::TAU * v;
        let w = DVec3::new(r * a.cos(), r * a.sin(), (1.0 - u).max(0.0).sqrt());
        hits += usize::from(caps.iter().any(|c| c.axis.dot(w) >= c.cos));
    }
    let p = hits as f64 / n as f64;
    (p, (p * (1.0 - p) / n as f64).sqrt())
}

#[test]
fn unions_match_monte_carlo() {
    // 5 standard errors: a false failure once in 1.7 million cases.
    let mut rng = Mix(7);
    let mut s = UnionScratch::default();
    for case in 0..40 {
        let k = 1 + case % 12;
        let caps: Vec<Cap> = (0..k)
            .map(|_| Cap {
                axis: rng.unit(),
                cos: 0.3 + 0.69 * rng.next(),
            })
            .collect();
        let exact = covered_fraction(DVec3::Z, &caps, Weighting::Cosine, &mut s);
        let (mc, se) = monte_carlo(&caps, 200_000, &mut rng);
        assert!(
            (exact - mc).abs() <= 5.0 * se + 1e-12,
            "case {case}: exact {exact}, Monte Carlo {mc} ± {se}"
        );
    }
}

/// The reference's answer for `caps` about `n`.
fn reference(n: DVec3, caps: &[Cap], w: Weighting) -> f64 {
    let caps: Vec<([f64; 3], f64)> = caps.iter().map(|c| (c.axis.to_array(), c.cos)).collect();
    match w {
        Weighting::Cosine => super::reference::covered_cosine(n.to_array(), &caps),
        Weighting::Uniform => super::reference::covered_uniform(n.to_array(), &caps),
    }
}

/// Random spheres (radii 0.5 to 1) in a cube filled to about 0.3 of its volume.
pub(super) fn packing(rng: &mut Mix, count: usize) -> Vec<(DVec3, f64)> {
    let side = (count as f64 * 4.0 / 3.0 * std::f64::consts::PI * 0.42 / 0.3).cbrt();
    (0..count)
        .map(|_| {
            let c = DVec3::new(rng.next(), rng.next(), rng.next()) * side;
            (c, 0.5 + 0.5 * rng.next())
        })
        .collect()
}

/// The caps the spheres other than `own` block from `x` within `reach`; `None` if `x` is
/// inside one.
fn caps_at(spheres: &[(DVec3, f64)], own: usize, x: DVec3, reach: f64) -> Option<Vec<Cap>> {
    let mut caps = Vec::new();
    for (k, &(c, r)) in spheres.iter().enumerate() {
        if k == own {
            continue;
        }
        match blocked_by_ball(x, c, r, reach) {
            Blocked::Nothing => {}
            Blocked::Cap(cap) => caps.push(cap),
            Blocked::Everything => return None,
        }
    }
    Some(caps)
}

#[test]
fn random_packings_match_the_reference() {
    let mut rng = Mix(11);
    let mut s = UnionScratch::default();
    let (mut worst, mut points) = (0.0f64, 0);
    for _ in 0..3 {
        let spheres = packing(&mut rng, 80);
        for k in 0..12 {
            let (c, r) = spheres[k * 5];
            let n = rng.unit();
            let x = c + r * n;
            for (reach, w) in [
                (f64::INFINITY, Weighting::Cosine),
                (2.0, Weighting::Cosine),
                (0.6, Weighting::Cosine),
                (f64::INFINITY, Weighting::Uniform),
                (1.0, Weighting::Uniform),
            ] {
                let Some(caps) = caps_at(&spheres, k * 5, x, reach) else {
                    continue;
                };
                let got = covered_fraction(n, &caps, w, &mut s);
                let want = reference(n, &caps, w);
                worst = worst.max((got - want).abs());
                points += 1;
                assert!(
                    (got - want).abs() <= 1e-12,
                    "sphere {} reach {reach} {w:?}: {} caps, {got} against {want}",
                    k * 5,
                    caps.len()
                );
            }
        }
    }
    assert!(points > 100, "{points} points outside every other sphere");
    eprintln!("random packings: worst {worst:e} over {points} points");
}

/// Renders `spheres` as AO seen from `eye` (the pixel centres, with the normal and id
/// channels), and checks every covered pixel against the reference at the point the channels
/// give: the BVH's search for occluders and the whole render path. The bound is `1e-12`,
/// plus what the rounding of a hit point far from the origin moves AO by (`1e-13` per
/// radius of distance from it).
fn render_matches_reference(
    spheres: &[(DVec3, f64)],
    (eye, size): (DVec3, (u32, u32)),
    (reach, weighting): (f64, Weighting),
) -> (usize, f64) {
    use crate::render::{self, Aovs, Camera, Integrator, Lens, PrepareOptions, RenderOptions};
    use crate::scene::{Radii, Scene, SphereArrays};
    let centers: Vec<f64> = spheres.iter().flat_map(|(c, _)| c.to_array()).collect();
    let radii: Vec<f64> = spheres.iter().map(|s| s.1).collect();
    let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&radii))).unwrap();
    let prep = render::prepare(scene, &PrepareOptions::default()).unwrap();
    let middle = spheres.iter().map(|s| s.0).sum::<DVec3>() / spheres.len() as f64;
    let cam = Camera::look_at(eye, middle, DVec3::Y, Lens::default()).unwrap();
    let opts = RenderOptions {
        width: size.0,
        height: size.1,
        spp: 1,
        sampler: render::SamplerKind::Center,
        aovs: Aovs {
            normal: true,
            id: true,
            ..Aovs::default()
        },
        integrator: Integrator::Ao(super::AoSettings {
            reach,
            weighting,
            ..super::AoSettings::default()
        }),
        ..RenderOptions::default()
    };
    let film = render::render(&prep, &cam, &opts, &()).unwrap();
    let (normals, ids) = (film.normal.unwrap(), film.id.unwrap());
    let (mut covered, mut worst) = (0, 0.0f64);
    for p in 0..film.rgb.len() {
        let Ok(k) = usize::try_from(ids[p]) else {
            assert_eq!(film.rgb[p], [0.0; 3], "pixel {p}: the background");
            continue;
        };
        let n = DVec3::from_array(normals[p]);
        let (c, r) = spheres[k];
        let x = c + r * n;
        let want =
            caps_at(spheres, k, x, reach).map_or(0.0, |caps| 1.0 - reference(n, &caps, weighting));
        let got = film.rgb[p][0];
        let bound = 1e-12 + 1e-13 * x.abs().max_element() / r;
        worst = worst.max((got - want).abs());
        assert!(
            (got - want).abs() <= bound,
            "pixel {p} on sphere {k}, reach {reach} {weighting:?}: {got} against {want}"
        );
        covered += 1;
    }
    (covered, worst)
}

/// Random scenes over the AO model: packings at three scales, far from the origin or not,
/// with touching pairs, coincident copies and spheres inside others, seen from outside and
/// from within, every reach and weighting; each pixel against the reference.
#[test]
fn random_scenes_render_as_the_reference_says() {
    let mut rng = Mix(5);
    let (mut pixels, mut worst) = (0, 0.0f64);
    for case in 0..8 {
        let scale = [1.0, 1e-3, 1e3][case % 3];
        let offset = if case % 4 == 3 {
            DVec3::new(1e5, -2e5, 3e4) * scale
        } else {
            DVec3::ZERO
        };
        let mut spheres: Vec<(DVec3, f64)> = packing(&mut rng, 24)
            .into_iter()
            .map(|(c, r)| (c * scale + offset, r * scale))
            .collect();
        // A sphere touching another, a coincident copy, a small sphere inside a large one.
        let (c0, r0) = spheres[0];
        let dir = rng.unit();
        spheres.push((c0 + dir * (r0 + 0.6 * scale), 0.6 * scale));
        spheres.push(spheres[1]);
        spheres.push((spheres[2].0, 0.3 * spheres[2].1));
        let middle = spheres.iter().map(|s| s.0).sum::<DVec3>() / spheres.len() as f64;
        let eye = if case % 2 == 0 {
            middle + DVec3::new(3.0, 4.0, 16.0) * scale
        } else {
            // Among the spheres, looking across them.
            middle + rng.unit() * 1.5 * scale
        };
        let reach = [f64::INFINITY, 2.0 * scale, 0.7 * scale][case % 3];
        let weighting = [Weighting::Cosine, Weighting::Uniform][(case / 3) % 2];
        let (n, w) = render_matches_reference(&spheres, (eye, (24, 18)), (reach, weighting));
        pixels += n;
        worst = worst.max(w);
    }
    assert!(pixels > 800, "{pixels} pixels on spheres");
    eprintln!("random AO scenes: worst {worst:e} over {pixels} pixels");
}

#[test]
fn uniform_weighting_matches_closed_forms_and_monte_carlo() {
    let mut s = UnionScratch::default();
    // One cap wholly above the horizon: its solid angle, 2π (1 - cos α), over 2π.
    for (theta, alpha) in [(0.0, 0.3), (0.5, 0.9), (1.0, 0.5), (0.2, 1.3)] {
        let cap = Cap {
            axis: DVec3::new(f64::sin(theta), 0.0, f64::cos(theta)),
            cos: f64::cos(alpha),
        };
        let got = covered_fraction(DVec3::Z, &[cap], Weighting::Uniform, &mut s);
        assert!(
            (got - (1.0 - cap.cos)).abs() < 1e-14,
            "{theta} {alpha}: {got}"
        );
    }
    // Unions against uniform directions of the hemisphere, 5 standard errors.
    let mut rng = Mix(3);
    for case in 0..20 {
        let caps: Vec<Cap> = (0..1 + case % 9)
            .map(|_| Cap {
                axis: rng.unit(),
                cos: 0.2 + 0.79 * rng.next(),
            })
            .collect();
        let exact = covered_fraction(DVec3::Z, &caps, Weighting::Uniform, &mut s);
        let n = 200_000;
        let mut hits = 0;
        for _ in 0..n {
            let mut w = rng.unit();
            w.z = w.z.abs();
            hits += usize::from(caps.iter().any(|c| c.axis.dot(w) >= c.cos));
        }
        let p = hits as f64 / n as f64;
        let se = (p * (1.0 - p) / n as f64).sqrt();
        assert!(
            (exact - p).abs() <= 5.0 * se + 1e-12,
            "case {case}: exact {exact}, Monte Carlo {p} ± {se}"
        );
    }
}

/// The unoccluded fraction at `x` (normal `n`) among `occluders`, exactly, with the
/// reference's and (where given) a closed form's answers.
fn check_point(occluders: &[(DVec3, f64)], x: DVec3, n: DVec3, reach: f64, closed: Option<f64>) {
    let mut s = UnionScratch::default();
    let caps = caps_at(occluders, usize::MAX, x, reach).expect("outside the occluders");
    for w in [Weighting::Cosine, Weighting::Uniform] {
        let got = covered_fraction(n, &caps, w, &mut s);
        let want = reference(n, &caps, w);
        assert!(
            (got - want).abs() <= 1e-12,
            "{occluders:?} at {x} {w:?}: {got} against the reference's {want}"
        );
    }
    if let Some(closed) = closed {
        let got = covered_fraction(n, &caps, Weighting::Cosine, &mut s);
        assert!((got - closed).abs() <= 1e-13, "{got} against {closed}");
    }
}

#[test]
fn touching_nested_coincident_and_shared_boundaries() {
    let z = DVec3::Z;
    let one = |c: DVec3, r: f64, reach: f64| match blocked_by_ball(DVec3::ZERO, c, r, reach) {
        Blocked::Cap(cap) => one_cap(cap.axis.z, cap.axis.cross(z).length(), cap.cos),
        other => panic!("{other:?}"),
    };
    // A point where its sphere touches another: the other fills the whole hemisphere.
    check_point(
        &[(DVec3::new(0.0, 0.0, 1.0), 1.0)],
        DVec3::ZERO,
        z,
        f64::INFINITY,
        Some(1.0),
    );
    // Near that point, on a unit sphere centred at -z, and the neighbour touching it at 0.
    for angle in [1e-9, 1e-6, 1e-3, 0.1] {
        let n = DVec3::new(f64::sin(angle), 0.0, f64::cos(angle));
        let x = n - z;
        check_point(&[(z, 1.0)], x, n, f64::INFINITY, None);
        check_point(&[(z, 1.0)], x, n, 0.5, None);
    }
    // The same sphere twice, and a sphere inside another: the larger cap alone.
    let big = (DVec3::new(0.5, 0.2, 2.0), 0.8);
    for reach in [f64::INFINITY, 1.6] {
        let closed = Some(one(big.0, big.1, reach));
        check_point(&[big, big], DVec3::ZERO, z, reach, closed);
        check_point(&[big, (big.0 + 0.1, 0.3)], DVec3::ZERO, z, reach, closed);
    }
    // Two spheres on one axis whose caps within a reach share their boundary circle:
    // `(d² + D² - r²) / (2 d D)` equal for both.
    let (axis, reach, cos) = (DVec3::new(0.3, 0.1, 1.0).normalize(), 2.0, 0.9);
    let r_at = |d: f64| (d * d + reach * reach - 2.0 * d * reach * cos).sqrt();
    // (Both beyond `reach / cos`, where the reach, not the tangent cone, bounds the cap.)
    let pair = [(axis * 2.4, r_at(2.4)), (axis * 3.0, r_at(3.0))];
    let closed = one(pair[0].0, pair[0].1, reach);
    check_point(&pair, DVec3::ZERO, z, reach, Some(closed));
    assert!((closed - one(pair[1].0, pair[1].1, reach)).abs() < 1e-14);
    // Inside another sphere: nothing of the sky is seen.
    assert_eq!(
        blocked_by_ball(DVec3::ZERO, DVec3::X, 1.5, 0.1),
        Blocked::Everything
    );
}

#[test]
fn per_particle_means_match_an_average_over_a_fibonacci_lattice() {
    use super::AoScratch;
    use crate::render::particle_ao::sphere_ao;
    use crate::render::visibility::Opaque;
    use crate::render::{self, PrepareOptions};
    use crate::scene::{Radii, Scene, SphereArrays};
    // A sphere touching one neighbour, cut by another, and a third farther off; and a sphere
    // alone.
    let spheres = [
        (DVec3::ZERO, 1.0),
        (DVec3::new(2.0, 0.0, 0.0), 1.0),
        (DVec3::new(-0.5, 1.2, 0.3), 0.7),
        (DVec3::new(0.0, -1.0, 2.8), 1.3),
        (DVec3::new(30.0, 0.0, 0.0), 1.0),
    ];
    let centers: Vec<f64> = spheres.iter().flat_map(|(c, _)| c.to_array()).collect();
    let radii: Vec<f64> = spheres.iter().map(|s| s.1).collect();
    let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&radii))).unwrap();
    let prep = render::prepare(scene, &PrepareOptions::default()).unwrap();
    let prim_of =
        |k: usize| (0..prep.bvh.len() as u32).find(|&i| prep.bvh.prim(i).sphere == k as u32);
    let mut s = AoScratch::default();
    for (k, &(c, r)) in spheres.iter().enumerate() {
        for ao in [
            (f64::INFINITY, Weighting::Cosine),
            (1.0, Weighting::Uniform),
        ] {
            let got = sphere_ao(&prep, (c, r), prim_of(k), ao, 1e-4, &mut s);
            // The same AO at 40 000 points spread evenly over the sphere.
            let n = 40_000;
            let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let mut sum = 0.0;
            for i in 0..n {
                let u = 1.0 - (2.0 * f64::from(i) + 1.0) / f64::from(n);
                let phi = golden * f64::from(i);
                let sin = (1.0 - u * u).sqrt();
                let d = DVec3::new(sin * phi.cos(), sin * phi.sin(), u);
                let own = prim_of(k).map(Opaque::Sphere);
                sum += unoccluded(&prep, c + r * d, d, own, ao, &mut s);
            }
            let lattice = sum / f64::from(n);
            assert!(
                (got.mean - lattice).abs() < 2e-3 && got.error <= 1e-4,
                "sphere {k} {ao:?}: {got:?} against the lattice's {lattice}"
            );
            if k == 4 && ao.0 < 29.0 {
                // Nothing within reach (with no limit, the others are seen far off).
                assert!((got.mean - 1.0).abs() < 1e-15, "alone: {got:?}");
            }
        }
    }
}

#[test]
fn the_ao_channel_is_exact_ao_beside_any_integrator() {
    use crate::render::{self, Aovs, Camera, Integrator, Lens, PrepareOptions, RenderOptions};
    use crate::scene::{Radii, Scene, SphereArrays};
    let spheres = packing(&mut Mix(8), 30);
    let centers: Vec<f64> = spheres.iter().flat_map(|(c, _)| c.to_array()).collect();
    let radii: Vec<f64> = spheres.iter().map(|s| s.1).collect();
    let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&radii))).unwrap();
    let prep = render::prepare(scene, &PrepareOptions::default()).unwrap();
    let middle = spheres.iter().map(|s| s.0).sum::<DVec3>() / spheres.len() as f64;
    let eye = middle + DVec3::new(1.0, 2.0, 15.0);
    let cam = Camera::look_at(eye, middle, DVec3::Y, Lens::default()).unwrap();
    let ao = super::AoSettings {
        reach: 2.5,
        weighting: Weighting::Uniform,
        ..super::AoSettings::default()
    };
    let base = RenderOptions {
        width: 32,
        height: 24,
        spp: 1,
        sampler: render::SamplerKind::Center,
        ao,
        ..RenderOptions::default()
    };
    let with_channel = RenderOptions {
        aovs: Aovs {
            ao: true,
            ..Aovs::default()
        },
        ..base.clone()
    };
    let lit = render::render(&prep, &cam, &with_channel, &()).unwrap();
    let picture = RenderOptions {
        integrator: Integrator::Ao(ao),
        ..base
    };
    let drawn = render::render(&prep, &cam, &picture, &()).unwrap();
    let channel = lit.ao.unwrap();
    let mut covered = 0;
    for (p, &a) in channel.iter().enumerate() {
        if drawn.alpha[p] == 0.0 {
            assert!(a.is_nan(), "pixel {p}: a miss is NaN");
        } else {
            assert_eq!(a, drawn.rgb[p][0], "pixel {p}");
            covered += 1;
        }
    }
    assert!(covered > 100);
    assert_ne!(lit.rgb, drawn.rgb, "the lit picture is not the AO picture");
}
