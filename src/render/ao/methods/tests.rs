//! The approximations against independent answers: the exact method (`ao::unoccluded`, itself
//! checked against a reference and Monte Carlo), hand-computed direction sets, the single-cap
//! form factor, and properties of the voxel grid.

use glam::DVec3;

use super::super::cap::{blocked_by_ball, Blocked};
use super::super::tests::unoccluded as exact;
use super::super::{AoScratch, AoSettings, Weighting};
use super::{directions, mc, sum, voxel, AoMethod};
use crate::render::sampler::Rng;
use crate::render::visibility::Opaque;
use crate::render::{self, Prepared};
use crate::scene::{Radii, Scene, SphereArrays};

/// The scene of `spheres` (centre, radius), prepared.
fn prepared(spheres: &[(DVec3, f64)]) -> Prepared {
    let centers: Vec<f64> = spheres.iter().flat_map(|(c, _)| c.to_array()).collect();
    let radii: Vec<f64> = spheres.iter().map(|s| s.1).collect();
    let scene = Scene::from_arrays(&SphereArrays::new(&centers, Radii::Each(&radii))).unwrap();
    render::prepare(scene, &render::PrepareOptions::default()).unwrap()
}

/// Per sphere of the scene, its primitive's index in the BVH.
fn leaves(prep: &Prepared) -> Vec<u32> {
    let mut of = vec![0; prep.spheres];
    for i in 0..prep.bvh.len() as u32 {
        of[prep.bvh.prim(i).sphere as usize] = i;
    }
    of
}

fn unit(rng: &mut Rng) -> DVec3 {
    let z = 2.0 * rng.next_f64() - 1.0;
    let a = std::f64::consts::TAU * rng.next_f64();
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * a.cos(), r * a.sin(), z)
}

/// The exact AO tests' packing, seeded from `rng`.
fn packing(rng: &mut Rng, count: usize) -> Vec<(DVec3, f64)> {
    let seed = (rng.next_f64() * (1u64 << 53) as f64) as u64;
    super::super::tests::packing(&mut super::super::tests::Mix(seed), count)
}

/// `count` points on the packing's spheres: (point, normal, the sphere's BVH primitive).
fn points(
    spheres: &[(DVec3, f64)],
    prep: &Prepared,
    rng: &mut Rng,
    count: usize,
) -> Vec<(DVec3, DVec3, Option<u32>)> {
    let leaf = leaves(prep);
    (0..count)
        .map(|k| {
            let s = k * 7 % spheres.len();
            let n = unit(rng);
            (spheres[s].0 + spheres[s].1 * n, n, Some(leaf[s]))
        })
        .collect()
}

fn exact_at(prep: &Prepared, (x, n, own): (DVec3, DVec3, Option<u32>), reach: f64) -> f64 {
    exact(
        prep,
        x,
        n,
        own.map(Opaque::Sphere),
        (reach, Weighting::Cosine),
        &mut AoScratch::default(),
    )
}

#[test]
fn mc_converges_to_exact_within_five_standard_errors() {
    // 5 standard errors: a false failure once in 1.7 million points.
    let mut rng = Rng::new(1, 2);
    let spheres = packing(&mut rng, 60);
    let prep = prepared(&spheres);
    let mut worst: f64 = 0.0;
    for (k, p) in points(&spheres, &prep, &mut rng, 40)
        .into_iter()
        .enumerate()
    {
        for (reach, w) in [
            (f64::INFINITY, Weighting::Cosine),
            (1.5, Weighting::Uniform),
        ] {
            let own = p.2.map(Opaque::Sphere);
            let want = exact(&prep, p.0, p.1, own, (reach, w), &mut AoScratch::default());
            let (got, se) = mc::unoccluded(&prep.bvh, p, (reach, w), 4000, &mut rng);
            worst = worst.max((got - want).abs() / se);
            assert!(
                (got - want).abs() <= 5.0 * se + 1e-12,
                "point {k}, reach {reach} {w:?}: mc {got} ± {se}, exact {want}"
            );
        }
    }
    eprintln!("mc against exact: worst {worst:.2} standard errors");
}

#[test]
fn mc_pixel_errors_are_standard_errors() {
    // Renders exact and mc (16 rays, 4 samples a pixel at the same positions), and counts the
    // covered pixels whose difference is within 2 reported standard errors: about 95 % for
    // a standard error, at least 90 % asked.
    use crate::render::{Aovs, Camera, Integrator, Lens, RenderOptions};
    let mut rng = Rng::new(3, 4);
    let spheres = packing(&mut rng, 40);
    let prep = prepared(&spheres);
    let middle = spheres.iter().map(|s| s.0).sum::<DVec3>() / spheres.len() as f64;
    let eye = middle + DVec3::new(1.0, 1.5, 10.0);
    let cam = Camera::look_at(eye, middle, DVec3::Y, Lens::default()).unwrap();
    let film = |method| {
        let opts = RenderOptions {
            width: 64,
            height: 48,
            spp: 4,
            aovs: Aovs {
                error: true,
                ..Aovs::default()
            },
            integrator: Integrator::Ao(AoSettings {
                reach: 2.0,
                method,
                ..AoSettings::default()
            }),
            ..RenderOptions::default()
        };
        render::render(&prep, &cam, &opts, &()).unwrap()
    };
    let (want, got) = (film(AoMethod::Exact), film(AoMethod::MC));
    let errors = got.error.as_ref().unwrap();
    let (mut within, mut covered) = (0, 0);
    for (p, &error) in errors.iter().enumerate() {
        if got.alpha[p] == 0.0 {
            continue;
        }
        covered += 1;
        let diff = (got.rgb[p][0] - want.rgb[p][0]).abs();
        assert!(error > 0.0, "pixel {p}: an error estimate");
        within += usize::from(diff <= 2.0 * error);
    }
    assert!(covered > 500, "{covered} pixels on spheres");
    let share = within as f64 / covered as f64;
    eprintln!("mc pixels within 2 standard errors: {share:.3} of {covered}");
    assert!(share >= 0.9, "{share}");
    assert_eq!(want.max_error, 0.0);
}

#[test]
fn mc_renders_the_same_on_any_thread_count() {
    use crate::render::{Camera, Integrator, Lens, RenderOptions};
    let mut rng = Rng::new(5, 6);
    let spheres = packing(&mut rng, 30);
    let prep = prepared(&spheres);
    let cam = Camera::look_at(
        DVec3::new(3.0, 4.0, 16.0),
        DVec3::splat(2.0),
        DVec3::Y,
        Lens::default(),
    )
    .unwrap();
    let opts = RenderOptions {
        width: 40,
        height: 30,
        spp: 2,
        integrator: Integrator::Ao(AoSettings {
            method: AoMethod::MC,
            ..AoSettings::default()
        }),
        ..RenderOptions::default()
    };
    let on = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render::render(&prep, &cam, &opts, &()).unwrap())
    };
    let (one, three) = (on(1), on(3));
    assert_eq!(one.rgb, three.rgb);
    assert!(one.rgb.iter().any(|p| p[0] > 0.0 && p[0] < 1.0));
}

/// ChimeraX's `sphere_points(k)`, written out again from its formula.
fn bauer(k: u32) -> Vec<DVec3> {
    (0..k)
        .map(|i| {
            let phi = (-1.0 + (2.0 * f64::from(i) + 1.0) / f64::from(k)).acos();
            let theta = (f64::from(k) * std::f64::consts::PI).sqrt() * phi;
            DVec3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos())
        })
        .collect()
}

#[test]
fn directions_by_hand_with_one_occluder() {
    // The point at the origin on a unit sphere below it, normal +z.
    let own = (DVec3::new(0.0, 0.0, -1.0), 1.0);
    let at = |occluder: (DVec3, f64), k: u32, reach: f64| {
        let prep = prepared(&[own, occluder]);
        let mut dirs = Vec::new();
        directions::spiral(k, &mut dirs);
        let p = (DVec3::ZERO, DVec3::Z, Some(leaves(&prep)[0]));
        directions::unoccluded(&prep.bvh, p, (reach, Weighting::Cosine), &dirs)
    };
    // Two directions: z = -1/2 (below the horizon) and z = 1/2, at azimuth sqrt(2 pi) pi / 3.
    let two = bauer(2);
    let (below, above) = (two[0], two[1]);
    assert!((below.z + 0.5).abs() < 1e-15 && (above.z - 0.5).abs() < 1e-15);
    // An occluder along the upper direction blocks it: 0. Beyond the reach, or on the z axis
    // (60 degrees from that direction, 19.5 degrees wide), it does not: 1.
    assert_eq!(at((above * 3.0, 1.0), 2, f64::INFINITY), (0.0, 1));
    assert_eq!(at((above * 3.0, 1.0), 2, 1.5), (1.0, 1));
    assert_eq!(at((DVec3::Z * 3.0, 1.0), 2, f64::INFINITY), (1.0, 1));
    // 64 directions and a sphere at distance 3 on the axis: the directions within
    // asin(1/3) of +z are blocked.
    let cos = (1.0f64 - 1.0 / 9.0).sqrt();
    let (mut open, mut all) = (0.0, 0.0);
    for d in bauer(64).into_iter().filter(|d| d.z > 0.0) {
        all += d.z;
        if d.z < cos {
            open += d.z;
        }
    }
    let (got, rays) = at((DVec3::Z * 3.0, 1.0), 64, f64::INFINITY);
    assert!(
        (got - open / all).abs() < 1e-12,
        "{got} against {}",
        open / all
    );
    assert_eq!(rays, 32);
    // The exact answer is 1 - sin²(asin(1/3)) = 8/9; 64 directions are within 0.04 of it.
    assert!((got - 8.0 / 9.0).abs() < 0.04, "{got}");
}

#[test]
fn many_directions_come_within_a_hundredth_of_exact() {
    let mut rng = Rng::new(7, 8);
    let spheres = packing(&mut rng, 60);
    let prep = prepared(&spheres);
    let mut dirs = Vec::new();
    directions::spiral(4096, &mut dirs);
    assert_eq!(dirs.len(), 4096);
    assert!(dirs
        .iter()
        .zip(bauer(4096))
        .all(|(a, b)| (*a - b).length() < 1e-12));
    let mut worst: f64 = 0.0;
    for p in points(&spheres, &prep, &mut rng, 60) {
        for reach in [f64::INFINITY, 1.5] {
            let want = exact_at(&prep, p, reach);
            let (got, _) = directions::unoccluded(&prep.bvh, p, (reach, Weighting::Cosine), &dirs);
            worst = worst.max((got - want).abs());
        }
    }
    eprintln!("4096 directions against exact: worst {worst:e}");
    assert!(worst <= 1e-2, "{worst}");
}

/// The sum method at the origin (normal +z, on a unit sphere below it) among `occluders`.
fn sum_and_exact(occluders: &[(DVec3, f64)], reach: f64) -> (f64, f64) {
    let own = (DVec3::new(0.0, 0.0, -1.0), 1.0);
    let all: Vec<(DVec3, f64)> = std::iter::once(own)
        .chain(occluders.iter().copied())
        .collect();
    let prep = prepared(&all);
    let p = (DVec3::ZERO, DVec3::Z, Some(leaves(&prep)[0]));
    (
        sum::unoccluded(&prep.bvh, p, reach, &mut Vec::new()),
        exact_at(&prep, p, reach),
    )
}

#[test]
fn sum_is_exact_for_one_occluder() {
    for (c, r, reach) in [
        (DVec3::new(0.0, 0.0, 3.0), 1.0, f64::INFINITY),
        (DVec3::new(2.0, 0.5, 0.3), 0.9, f64::INFINITY),
        (DVec3::new(2.0, 0.5, -0.2), 0.9, f64::INFINITY),
        (DVec3::new(1.0, 1.0, 1.5), 0.7, 1.4),
        (DVec3::new(0.2, 0.0, 1.3), 1.2, 0.5),
    ] {
        let (got, want) = sum_and_exact(&[(c, r)], reach);
        assert!(
            (got - want).abs() < 1e-12,
            "{c} {r} {reach}: {got} against {want}"
        );
        assert!(want < 1.0, "{c}: occludes");
    }
}

#[test]
fn sum_overcounts_overlapping_caps_and_clamps() {
    // Two spheres whose caps overlap: their form factors add, the overlap counted twice.
    let pair = [
        (DVec3::new(0.4, 0.0, 2.5), 1.0),
        (DVec3::new(-0.4, 0.0, 2.5), 1.0),
    ];
    let (got, want) = sum_and_exact(&pair, f64::INFINITY);
    let one = |(c, r): (DVec3, f64)| match blocked_by_ball(DVec3::ZERO, c, r, f64::INFINITY) {
        Blocked::Cap(cap) => cap.form_factor(DVec3::Z),
        other => panic!("{other:?}"),
    };
    assert!((got - (1.0 - one(pair[0]) - one(pair[1]))).abs() < 1e-12);
    assert!(1.0 - got > 1.0 - want + 0.05, "sum {got}, exact {want}");
    // Eight spheres round the point, 30 degrees up: their caps leave the zenith open, and
    // their form factors add to more than 1.
    let ring: Vec<(DVec3, f64)> = (0..8)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
            (
                DVec3::new(a.cos() * 0.75f64.sqrt(), a.sin() * 0.75f64.sqrt(), 0.5) * 1.5,
                1.0,
            )
        })
        .collect();
    let (got, want) = sum_and_exact(&ring, f64::INFINITY);
    assert_eq!(got, 0.0);
    assert!(want > 0.05, "exact {want}");
}

/// The voxel method's answer at `count` points spread over the first of `spheres`.
fn voxel_on_first(spheres: &[(DVec3, f64)], reach: f64, count: u32) -> Vec<f64> {
    let prep = prepared(spheres);
    let v = voxel::VoxelSettings::MEGAMOL;
    let grid = voxel::Grid::build(spheres.iter().copied(), prep.bvh.bounds(), v.resolution);
    let mut dirs = Vec::new();
    directions::spiral(count, &mut dirs);
    let (c, r) = spheres[0];
    dirs.iter()
        .map(|&n| voxel::unoccluded(&grid, &v, reach, (c + r * n, n)))
        .collect()
}

#[test]
fn voxel_sees_a_lone_sphere_occlude_itself_a_little() {
    // Nothing occludes a lone sphere, but the voxel method's own sphere is in its grid:
    // alone in it (64 voxels a radius), and with another sphere 40 radii away (3.2 voxels a
    // radius). The module comment quotes these means.
    let lone = (DVec3::new(0.3, -0.2, 0.5), 1.0);
    let far = (lone.0 + DVec3::new(40.0, 0.0, 0.0), 1.0);
    for (scene, reach, low) in [
        (&[lone][..], 1.0, 0.75),
        (&[lone][..], f64::INFINITY, 0.75),
        (&[lone, far][..], 1.0, 0.65),
        (&[lone, far][..], f64::INFINITY, 0.65),
    ] {
        let got = voxel_on_first(scene, reach, 200);
        let mean = got.iter().sum::<f64>() / got.len() as f64;
        let min = got.iter().copied().fold(1.0, f64::min);
        eprintln!(
            "lone sphere, {} in the grid, reach {reach}: mean {mean:.3}, least {min:.3}",
            scene.len()
        );
        assert!(got.iter().all(|v| (low..=1.0).contains(v)), "{got:?}");
    }
}

#[test]
fn voxel_occludes_a_point_inside_a_shell() {
    // A unit sphere inside a shell of 80 unit spheres at distance 3: about nine tenths of
    // every point's hemisphere is covered.
    let mut shell = vec![(DVec3::ZERO, 1.0)];
    shell.extend(bauer(80).into_iter().map(|d| (d * 3.0, 1.0)));
    let prep = prepared(&shell);
    let leaf = leaves(&prep);
    let got = voxel_on_first(&shell, f64::INFINITY, 50);
    let exact_mean = bauer(50)
        .into_iter()
        .map(|n| exact_at(&prep, (n, n, Some(leaf[0])), f64::INFINITY))
        .sum::<f64>()
        / 50.0;
    let mean = got.iter().sum::<f64>() / got.len() as f64;
    eprintln!("inside a shell: voxel mean {mean:.3}, exact mean {exact_mean:.3}");
    assert!(exact_mean < 0.2, "{exact_mean}");
    assert!(got.iter().all(|v| (0.0..=0.35).contains(v)), "{got:?}");
}

#[test]
fn voxel_grid_holds_the_spheres_volume_and_answers_in_the_unit_interval() {
    let mut rng = Rng::new(9, 10);
    let spheres = packing(&mut rng, 50);
    let prep = prepared(&spheres);
    // One sphere: the grid's densities add up to its volume, to the 27-point sampling's
    // error; the mip levels keep the mean.
    let centre = DVec3::new(0.1, 0.2, 0.3);
    let one = [(centre, 1.3)];
    let grid = voxel::Grid::build(one.iter().copied(), (centre - 1.3, centre + 1.3), 64);
    let h = 2.6 / 64.0;
    assert_eq!(grid.dims(), [64, 64, 64]);
    assert_eq!(grid.level_count(), 6);
    // 64³ + 32³ + ... + 2³ voxels of 4 bytes.
    assert_eq!(grid.bytes(), 4 * 299_592);
    let mut sum = 0.0;
    for k in 0..64 {
        for j in 0..64 {
            for i in 0..64 {
                let p = centre - 1.3 + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * h;
                sum += grid.density(p, 0.0);
            }
        }
    }
    let volume = 4.0 / 3.0 * std::f64::consts::PI * 1.3f64.powi(3);
    assert!(
        (sum * h.powi(3) / volume - 1.0).abs() < 0.02,
        "{}",
        sum * h.powi(3)
    );
    assert!(grid.density(centre, 0.0) > 1.0 - 1e-12);
    assert!(grid.density(centre + 5.0, 0.0) == 0.0);
    // Any point of a packing: an answer in [0, 1].
    let v = voxel::VoxelSettings::MEGAMOL;
    let grid = voxel::Grid::build(spheres.iter().copied(), prep.bvh.bounds(), v.resolution);
    for (x, n, _) in points(&spheres, &prep, &mut rng, 200) {
        for reach in [f64::INFINITY, 1.0] {
            let got = voxel::unoccluded(&grid, &v, reach, (x, n));
            assert!((0.0..=1.0).contains(&got), "{got}");
        }
    }
}

#[test]
fn settings_out_of_range_are_refused() {
    use super::check;
    let with = |method| AoSettings {
        method,
        ..AoSettings::default()
    };
    for method in [
        AoMethod::Mc { samples: 0 },
        AoMethod::Mc {
            samples: super::MAX_SAMPLES + 1,
        },
        AoMethod::Directions { count: 0 },
        AoMethod::Voxel(voxel::VoxelSettings {
            resolution: 1,
            ..voxel::VoxelSettings::MEGAMOL
        }),
        AoMethod::Voxel(voxel::VoxelSettings {
            apex_degrees: f64::NAN,
            ..voxel::VoxelSettings::MEGAMOL
        }),
    ] {
        assert!(check(&with(method)).is_err(), "{method:?}");
    }
    for method in [AoMethod::Sum, AoMethod::VOXEL] {
        let uniform = AoSettings {
            weighting: Weighting::Uniform,
            ..with(method)
        };
        let e = check(&uniform).unwrap_err();
        assert!(e.contains("cosine-weighted"), "{e}");
    }
    for method in [
        AoMethod::Exact,
        AoMethod::MC,
        AoMethod::DIRECTIONS,
        AoMethod::Sum,
        AoMethod::VOXEL,
    ] {
        assert_eq!(check(&with(method)), Ok(()));
    }
}
