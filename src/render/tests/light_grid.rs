//! The lights' grids (`render::light_grid`) against testing every sphere: for random scenes at
//! scales from 1e-4 to 1e4 and far from the origin, lights of both kinds (a point light inside
//! the cloud, at a sphere's centre, on a sphere's surface, on the diagonals where the cube's
//! faces meet, far away), random segments and depth bands, every sphere that meets the band
//! (by the independent distance of `shadow_query::band_distance`) is among the candidates. The
//! candidates must also prune: a grid that returned every sphere would pass the first check.

use crate::accel::Prim;
use crate::render::light_grid::LightGrid;
use crate::render::lights::LightKind;
use crate::scene::LightScope;
use glam::DVec3;

use crate::render::tests::shadow_query::band_distance;
use crate::testing::Rng;

fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0;
        if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

fn cloud(rng: &mut Rng, n: usize, scale: f64, offset: DVec3) -> Vec<Prim> {
    (0..n)
        .map(|i| {
            let c = DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0;
            // Mostly small spheres, a few large ones.
            let r = if i % 50 == 7 {
                0.3 + 0.5 * rng.f()
            } else {
                0.01 + 0.08 * rng.f().powi(2)
            };
            Prim {
                center: offset + c * scale,
                radius: r * scale,
                color: crate::scene::Color::default(),
                material: 0,
                sphere: i as u32,
                ellipsoid: None,
                gas: i % 9 != 4,
                sigma: 1.0,
                profile: crate::scene::Profile::Constant,
            }
        })
        .collect()
}

fn lights(rng: &mut Rng, prims: &[Prim], scale: f64, offset: DVec3) -> Vec<LightKind> {
    let point = |position: DVec3| LightKind::Point {
        position,
        attenuation: DVec3::X,
        radius: f64::INFINITY,
    };
    let along = |to_light: DVec3| LightKind::Directional {
        to_light,
        scope: LightScope::All,
        surface_scope: LightScope::All,
    };
    let p = &prims[3];
    vec![
        along(unit(rng)),
        along(DVec3::Z),
        point(offset + (unit(rng) * 0.5) * scale),
        point(p.center),
        point(p.center + unit(rng) * p.radius),
        point(offset + DVec3::new(3.0, 3.0, 3.0) * scale),
        point(offset + DVec3::new(1e3, -2e2, 5e2) * scale),
        // On the diagonals where faces meet, seen from a sphere.
        point(p.center + DVec3::new(1.0, 1.0, 0.0).normalize() * 0.7 * scale),
        point(p.center + DVec3::ONE.normalize() * 0.7 * scale),
    ]
}

#[test]
fn grid_candidates_hold_every_sphere_that_meets_the_band() {
    let mut rng = Rng(4242);
    let (mut met, mut listed, mut tested, mut fallbacks) = (0usize, 0usize, 0usize, 0usize);
    for (scale, offset) in [
        (1.0, DVec3::ZERO),
        (1e-4, DVec3::ZERO),
        (1e4, DVec3::new(-3e4, 1e4, 2e4)),
        (1.0, DVec3::new(1e6, -1e6, 5e5)),
    ] {
        let prims = cloud(&mut rng, 400, scale, offset);
        for light in lights(&mut rng, &prims, scale, offset) {
            let grid = LightGrid::build(&light, &prims).expect("a grid");
            let mut out = Vec::new();
            for case in 0..40 {
                let a = offset + (DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0) * scale;
                let b = match case % 5 {
                    // A point, a short segment, one along the light's direction.
                    0 => a,
                    1 => a + unit(&mut rng) * 0.05 * scale,
                    2 => match light {
                        LightKind::Directional { to_light, .. } => a + to_light * 0.5 * scale,
                        LightKind::Point { position, .. } => a + (position - a) * 0.3,
                    },
                    _ => offset + (DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0) * scale,
                };
                let f = match light {
                    LightKind::Directional { .. } => {
                        let f0 = if case % 3 == 0 { 0.0 } else { rng.f() * scale };
                        (f0, f0 + [0.08, 0.6, 20.0][case % 3] * scale)
                    }
                    LightKind::Point { .. } => {
                        let f0 = if case % 3 == 0 { 0.0 } else { rng.f() * 0.7 };
                        (f0, (f0 + [0.02, 0.2, 1.0][case % 3]).min(1.0))
                    }
                };
                out.clear();
                if !grid.candidates(a, b, f, &mut out) {
                    fallbacks += 1;
                    continue;
                }
                out.sort_unstable();
                out.dedup();
                listed += out.len();
                tested += prims.len();
                for (i, p) in prims.iter().enumerate() {
                    let dist = band_distance(p.center, a, b, &light, f);
                    if dist <= p.radius * (1.0 - 1e-9) {
                        met += 1;
                        assert!(
                            out.binary_search(&(i as u32)).is_ok(),
                            "sphere {i} (distance {dist}, radius {}) meets band {f:?} of \
                             {a}..{b} towards {light:?} (scale {scale}) but is not a candidate",
                            p.radius
                        );
                    }
                }
            }
        }
    }
    assert!(met > 2000, "the test should meet spheres ({met})");
    // Segments through a point light may fall back to the BVH; only a few do here.
    assert!(fallbacks < 40, "{fallbacks} fallbacks");
    assert!(
        (listed as f64) < 0.25 * tested as f64,
        "the grids should prune: {listed} candidates of {tested} spheres"
    );
}

/// A segment through a point light: the grid either answers with every sphere the band meets
/// or declines (the caller then searches the BVH); it never answers with a partial list.
#[test]
fn a_segment_through_a_point_light_is_declined_or_answered_in_full() {
    let mut rng = Rng(99);
    let prims = cloud(&mut rng, 300, 1.0, DVec3::ZERO);
    let p = DVec3::new(0.1, -0.2, 0.3);
    let light = LightKind::Point {
        position: p,
        attenuation: DVec3::X,
        radius: f64::INFINITY,
    };
    let grid = LightGrid::build(&light, &prims).unwrap();
    let mut declined = 0;
    for _ in 0..50 {
        let d = unit(&mut rng);
        let (a, b) = (p - d * rng.f(), p + d * rng.f());
        let mut out = Vec::new();
        if !grid.candidates(a, b, (0.0, 1.0), &mut out) {
            assert!(out.is_empty());
            declined += 1;
            continue;
        }
        for (i, q) in prims.iter().enumerate() {
            if band_distance(q.center, a, b, &light, (0.0, 1.0)) <= q.radius * (1.0 - 1e-9) {
                assert!(out.contains(&(i as u32)), "sphere {i} left out");
            }
        }
    }
    assert!(declined > 0);
}

/// A large scene (so that the grid samples the spheres' sizes with a stride) in which one face
/// of a point light's cube sees only two spheres: that face must still list them.
#[test]
fn a_face_with_few_spheres_in_a_large_scene_lists_them() {
    let mut rng = Rng(5);
    let mut prims = cloud(&mut rng, 140_000, 1.0, DVec3::new(10.0, 0.0, 0.0));
    // At odd indices: the stride (2 here) samples none of them.
    let few = [1usize, 3];
    for (k, x) in few.into_iter().zip([-5.0, -7.0]) {
        prims[k].center = DVec3::new(x, 0.01, 0.02);
        prims[k].radius = 0.05;
    }
    let light = LightKind::Point {
        position: DVec3::ZERO,
        attenuation: DVec3::X,
        radius: f64::INFINITY,
    };
    let grid = LightGrid::build(&light, &prims).expect("a grid");
    for k in few {
        let c = prims[k].center;
        // A short segment just beyond the sphere, whose light rays pass through its centre.
        let (a, b) = (
            c * 1.2 + DVec3::new(0.0, 0.01, 0.0),
            c * 1.2 - DVec3::new(0.0, 0.01, 0.0),
        );
        let mut out = Vec::new();
        assert!(grid.candidates(a, b, (0.0, 1.0), &mut out));
        assert!(band_distance(c, a, b, &light, (0.0, 1.0)) < prims[k].radius);
        assert!(out.contains(&(k as u32)), "sphere {k} left out");
    }
}
