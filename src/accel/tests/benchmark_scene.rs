//! The benchmark scene's shadow rays and camera packets, the last blockers, gas among opaque spheres, and concentric spheres, against brute force.

use super::*;

/// The benchmark scene of `gtsphere bench trace` at 20 000 spheres, prepared, and its
/// spheres (centre and radius) for brute force.
fn benchmark_scene() -> (Vec<(DVec3, f64)>, crate::render::Prepared) {
    let scene = crate::bench::scenes::random_spheres(20_000);
    let spheres = scene.spheres.iter().map(|s| (s.center, s.radius)).collect();
    (spheres, crate::testing::prepare(scene))
}

/// The benchmark scene of `gtsphere bench trace` at 20 000 spheres: camera hits and shadow
/// visibility through the renderer's own functions against a brute-force loop.
#[test]
fn benchmark_scene_shadows_match_brute_force() {
    use crate::render::integrators::surface::{first_hit, surface_point};
    use crate::render::lights::towards;
    use crate::render::visibility::visible;
    use crate::render::RenderOptions;
    let (spheres, prep) = benchmark_scene();
    let view = crate::testing::view(&prep, &RenderOptions::default());
    let cam = view.camera;
    let (mut lit, mut checked) = (0, 0);
    for j in 0..64 {
        for i in 0..64 {
            let (o, d) = cam.ray((i as f64 + 0.5) / 64.0, (j as f64 + 0.5) / 64.0);
            let Some(h) = first_hit(&prep, o, d, 0.0) else {
                continue;
            };
            let sp = surface_point(&prep, o, d, h);
            let own = sp.scene_index(&prep) as usize;
            for l in &view.lights {
                let (dir, dist, _) = towards(l, sp.x).unwrap();
                let got = visible(&prep, sp.x, dir, dist, Some(sp.on)) > 0.0;
                let want = spheres.iter().enumerate().all(|(k, &(c, r))| {
                    k == own
                        || !sphere_roots(sp.x, dir, c, r)
                            .is_some_and(|(t0, _)| t0 > 0.0 && t0 < dist)
                });
                assert_eq!(got, want, "pixel ({i},{j})");
                checked += 1;
                lit += usize::from(got);
            }
        }
    }
    assert!(checked > 2000 && lit > 500, "{checked} {lit}");
}

/// The benchmark scene's camera rays four by four pixels in a packet, as the renderer traces
/// them (`first_hits`), with jittered samples: the same first hits as the brute-force loop.
#[test]
fn benchmark_scene_camera_packets_match_brute_force() {
    use crate::accel::{PacketStack, PACKET};
    use crate::render::integrators::surface::{first_hits, Opaque};
    use crate::render::RenderOptions;
    let (spheres, prep) = benchmark_scene();
    let view = crate::testing::view(&prep, &RenderOptions::default());
    let cam = view.camera;
    let mut rng = Rng(77);
    let mut stack = PacketStack::default();
    let mut hits = 0;
    for by in (0..96).step_by(4) {
        for bx in (0..96).step_by(4) {
            let mut rays = Vec::new();
            for j in by..by + 4 {
                for i in bx..bx + 4 {
                    rays.push(cam.ray((i as f64 + rng.f()) / 96.0, (j as f64 + rng.f()) / 96.0));
                }
            }
            let mut got = [None; PACKET];
            first_hits(&prep, &rays, 0.0, &mut got, &mut stack);
            for (k, &(o, d)) in rays.iter().enumerate() {
                let want = spheres
                    .iter()
                    .enumerate()
                    .filter_map(|(s, &(c, r))| {
                        let (t0, _) = sphere_roots(o, d, c, r)?;
                        (t0 > 0.0).then_some((t0, s))
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                let got = got[k].map(|h| match h.on {
                    Opaque::Sphere(p) => (h.t, prep.bvh.prim(p).sphere as usize),
                    Opaque::Surface(_) => unreachable!("the scene has only spheres"),
                });
                assert_eq!(got, want, "packet ({bx},{by}) ray {k}");
                hits += usize::from(want.is_some());
            }
        }
    }
    assert!(hits > 3000, "{hits}");
}

/// Shadow rays that first try the sphere that blocked the previous ray towards the same light
/// ([`visible_after`]): the same answers as the brute-force loop, pixel after pixel with the
/// slots carried over (so that the last blocker often blocks again, and answers alone), and
/// with slots spoiled on purpose: the point's own sphere (which a ray into it meets at a root
/// of either sign near 0), a sphere out of the scene, a random one.
#[test]
fn shadow_rays_after_the_last_blocker_match_brute_force() {
    use crate::render::integrators::surface::{first_hit, surface_point, Opaque};
    use crate::render::lights::towards;
    use crate::render::visibility::{visible_after, Blockers};
    use crate::render::RenderOptions;
    let (spheres, prep) = benchmark_scene();
    let view = crate::testing::view(&prep, &RenderOptions::default());
    let cam = view.camera;
    let n = prep.bvh.len() as u32;
    let blocks = |x: DVec3, dir: DVec3, dist: f64, k: usize| {
        sphere_roots(x, dir, spheres[k].0, spheres[k].1)
            .is_some_and(|(t0, _)| t0 > 0.0 && t0 < dist)
    };
    let mut rng = Rng(11);
    let mut blockers = Blockers::default();
    let (mut answered_by_slot, mut spoiled, mut checked) = (0, 0, 0);
    // The middle 64 x 64 pixels of a 256 x 256 image: a sphere spans a few pixels.
    for j in 96..160 {
        for i in 96..160 {
            let (o, d) = cam.ray((i as f64 + 0.5) / 256.0, (j as f64 + 0.5) / 256.0);
            let Some(h) = first_hit(&prep, o, d, 0.0) else {
                continue;
            };
            let sp = surface_point(&prep, o, d, h);
            let own = sp.scene_index(&prep) as usize;
            let Opaque::Sphere(own_prim) = sp.on else {
                panic!("the scene has only spheres");
            };
            for (k, l) in view.lights.iter().enumerate() {
                let (dir, dist, _) = towards(l, sp.x).unwrap();
                let slot = blockers.slot(k);
                match (rng.f() * 20.0) as u32 {
                    0 => *slot = Some(own_prim),
                    1 => *slot = Some(n + (rng.f() * 5.0) as u32),
                    2 => *slot = Some((rng.f() * f64::from(n)) as u32),
                    _ => {}
                }
                spoiled += usize::from(*slot == Some(own_prim));
                let by_slot = slot.is_some_and(|p| {
                    p < n
                        && p != own_prim
                        && blocks(sp.x, dir, dist, prep.bvh.prim(p).sphere as usize)
                });
                let want = (0..spheres.len()).all(|s| s == own || !blocks(sp.x, dir, dist, s));
                let got = visible_after(&prep, sp.x, dir, dist, Some(sp.on), slot) > 0.0;
                assert_eq!(got, want, "pixel ({i},{j}), light {k}");
                checked += 1;
                answered_by_slot += usize::from(by_slot);
            }
        }
    }
    // The slots do answer many rays alone, and the own-sphere spoiling happened.
    assert!(
        checked > 2000 && answered_by_slot > checked / 10 && spoiled > 100,
        "{checked} {answered_by_slot} {spoiled}"
    );
}

/// With gas spheres (constant and linear density) among the opaque ones, a slot naming a gas
/// sphere (whose optical depth only adds up) never stops a ray: the same transmittance as
/// without slots, bit for bit.
#[test]
fn last_blockers_leave_gas_transmittance_unchanged() {
    use crate::render::visibility::{visible, visible_after};
    use crate::scene::Material;
    let mut scene = crate::bench::scenes::random_spheres(3000);
    let gas = Material {
        transparency: 0.3,
        ..Material::default()
    };
    // Constant and linear density (whose optical depth depends on where the chord lies).
    let linear = Material {
        profile: crate::scene::Profile::Linear,
        ..gas
    };
    let gas_index = scene.materials.add(&gas).material;
    assert_eq!(scene.materials.add(&linear).material, gas_index + 1);
    for (i, s) in scene.spheres.iter_mut().enumerate() {
        match i % 6 {
            0 => s.material = gas_index,
            3 => s.material = gas_index + 1,
            _ => {}
        }
    }
    let prep = crate::testing::prepare(scene);
    let n = prep.bvh.len() as u32;
    let mut rng = Rng(5);
    let (mut partial, mut blocked) = (0, 0);
    let mut last = None;
    for _ in 0..4000 {
        let x = DVec3::new(rng.f(), rng.f(), rng.f()) * 2.4 - 1.2;
        let mut l = rng.unit();
        let dist = if rng.f() < 0.5 {
            f64::INFINITY
        } else {
            3.0 * rng.f()
        };
        let pick = (rng.f() * f64::from(n)) as u32;
        match (rng.f() * 4.0) as u32 {
            // Aimed through a gas sphere that the slot names.
            0 | 1 if prep.bvh.prim(pick).is_gas() => {
                l = (prep.bvh.prim(pick).center - x).normalize();
                last = Some(pick);
            }
            2 => last = Some(pick),
            _ => {}
        }
        let want = visible(&prep, x, l, dist, None);
        let got = visible_after(&prep, x, l, dist, None, &mut last);
        assert_eq!(got.to_bits(), want.to_bits(), "{x} {l} {dist}");
        partial += usize::from(want > 0.0 && want < 1.0);
        blocked += usize::from(want == 0.0);
    }
    assert!(partial > 300 && blocked > 300, "{partial} {blocked}");
}

/// Degenerate sets make deep trees (obvhs's own traversal stack holds 32 entries and drops
/// the rest silently): 600 concentric and 300 coincident spheres are all found.
#[test]
fn concentric_and_coincident_spheres_are_all_found() {
    let mut ps: Vec<Prim> = (0..600)
        .map(|k| Prim {
            center: DVec3::ZERO,
            radius: 0.01 * (k + 1) as f64,
            color: crate::scene::Color::default(),
            material: 0,
            sphere: k,
            ellipsoid: None,
            gas: false,
            sigma: 0.0,
            profile: crate::scene::Profile::Constant,
        })
        .collect();
    ps.extend((0..300).map(|k| Prim {
        center: DVec3::new(2.0, 0.0, 0.0),
        radius: 0.5,
        color: crate::scene::Color::default(),
        material: 0,
        sphere: 600 + k,
        ellipsoid: None,
        gas: false,
        sigma: 0.0,
        profile: crate::scene::Profile::Constant,
    }));
    let bvh = SphereBvh::build(ps, &[]);
    let o = DVec3::new(-10.0, 0.0, 0.0);
    let mut seen = BTreeSet::new();
    bvh.all(o, DVec3::X, 0.0, f64::INFINITY, |_, p, _| {
        seen.insert(p.sphere);
    });
    assert_eq!(seen.len(), 900);
    let h = bvh
        .closest(o, DVec3::X, 0.0, f64::INFINITY, |_, _, (t0, _)| Some(t0))
        .unwrap();
    assert_eq!(bvh.prim(h.prim).sphere, 599);
    // From inside the innermost sphere, every concentric one is left, none entered.
    assert!(!bvh.any(
        DVec3::ZERO,
        DVec3::Y,
        0.0,
        f64::INFINITY,
        |_, _, (t0, _)| t0 > 0.0
    ));
    assert!(bvh.any(
        DVec3::new(2.0, 5.0, 0.0),
        DVec3::NEG_Y,
        0.0,
        10.0,
        |_, _, (t0, _)| t0 > 0.0
    ));
}
