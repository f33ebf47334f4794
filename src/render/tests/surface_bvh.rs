//! The acceleration structure over mixed primitives (spheres, boxes, cylinders, cones,
//! triangles) against a brute-force loop over all of them with the same exact tests: the
//! BVH may only prune what cannot be hit. Rays include grazing ones along triangle edges, in
//! the plane of a triangle, and through cylinder and cone rims.

use crate::geom::shapes::Solid;
use crate::render::integrators::surface::{first_hit, Opaque};
use crate::scene::{Material, Origin, Scene, Sphere, Surface, SurfaceShape, Triangle};
use glam::{DAffine3, DQuat, DVec3};

use crate::testing::Rng;

fn random_scene(rng: &mut Rng, n: usize) -> Scene {
    let mut s = Scene::default();
    let paint = s.materials.add(&Material::default());
    let v = |rng: &mut Rng| DVec3::new(rng.f(), rng.f(), rng.f()) * 20.0 - 10.0;
    for k in 0..n {
        let c = v(rng);
        let size = 0.2 + 1.5 * rng.f();
        let rot = DQuat::from_axis_angle(v(rng).normalize(), 6.0 * rng.f());
        let scale = DVec3::new(0.5 + rng.f(), 0.5 + rng.f(), 0.5 + rng.f());
        let to_world = DAffine3::from_scale_rotation_translation(scale, rot, c);
        let solid = |solid| SurfaceShape::Solid { solid, to_world };
        let shape = match k % 5 {
            0 => {
                s.spheres.push(Sphere {
                    center: c,
                    radius: size,
                    color: paint.color,
                    material: paint.material,
                    ellipsoid: None,
                    origin: Origin::default(),
                });
                continue;
            }
            1 => solid(Solid::Cuboid {
                half: DVec3::new(size, 0.5 * size, 0.8 * size),
            }),
            2 => solid(Solid::Cylinder {
                radius: 0.3 * size,
                half_height: size,
                bottom: rng.f() < 0.8,
                side: true,
                top: rng.f() < 0.8,
            }),
            3 => solid(Solid::Cone {
                radius: 0.6 * size,
                half_height: size,
                side: true,
                bottom: rng.f() < 0.8,
            }),
            _ => SurfaceShape::Triangle(Box::new(Triangle {
                p: [c, c + v(rng) * 0.2, c + v(rng) * 0.2],
                n: None,
                color: None,
                solid: rng.f() < 0.5,
            })),
        };
        s.surfaces.push(Surface {
            shape,
            color: paint.color,
            material: paint.material,
            origin: Origin::default(),
        });
    }
    s
}

/// Rays: random, along triangle edges (through two of its corners), in a triangle's plane,
/// and through points of cylinder and cone rims.
fn rays(rng: &mut Rng, scene: &Scene, n: usize) -> Vec<(DVec3, DVec3)> {
    let mut out = Vec::new();
    let v = |rng: &mut Rng| DVec3::new(rng.f(), rng.f(), rng.f()) * 30.0 - 15.0;
    for k in 0..n {
        let s = &scene.surfaces[rng.below(scene.surfaces.len())];
        let o = v(rng) * 1.5;
        let target = match (&s.shape, k % 4) {
            (SurfaceShape::Triangle(t), 1) => {
                // Along an edge: from beyond one corner through it to the next.
                let (a, b) = (t.p[k % 3], t.p[(k + 1) % 3]);
                out.push((a - 3.0 * (b - a), (b - a).normalize()));
                continue;
            }
            (SurfaceShape::Triangle(t), 2) => {
                // In its plane, from a point of the plane through an edge's midpoint.
                let m = 0.5 * (t.p[0] + t.p[1]);
                let start = t.p[2] + 5.0 * (t.p[2] - m);
                out.push((start, (m - start).normalize()));
                continue;
            }
            (SurfaceShape::Solid { solid, to_world }, 3) => {
                let (r, h) = match *solid {
                    Solid::Cylinder {
                        radius,
                        half_height,
                        ..
                    } => (radius, half_height),
                    Solid::Cone {
                        radius,
                        half_height,
                        ..
                    } => (radius, -half_height),
                    Solid::Cuboid { half } => (half.x, half.y),
                };
                let a = std::f64::consts::TAU * rng.f();
                to_world.transform_point3(DVec3::new(r * a.cos(), h, r * a.sin()))
            }
            _ => v(rng) * 0.5,
        };
        out.push((o, (target - o).normalize()));
    }
    out
}

#[test]
fn closest_and_any_hit_match_every_primitive_tested() {
    let mut rng = Rng::new(2024);
    let scene = random_scene(&mut rng, 600);
    let spheres: Vec<(DVec3, f64)> = scene.spheres.iter().map(|s| (s.center, s.radius)).collect();
    let ray_list = rays(&mut rng, &scene, 4000);
    let prep = crate::testing::prepare(scene);
    let items = &prep.surfaces.items;
    let (mut surface_hits, mut blocked) = (0, 0);
    for (o, d) in ray_list {
        // Brute force: the nearest sphere seen from outside, then any surface before it
        // (spheres win ties), the lowest index among equal surfaces.
        let mut best: Option<(f64, Opaque)> = None;
        for (k, &(c, r)) in spheres.iter().enumerate() {
            if let Some((t0, _)) = crate::geom::sphere_roots(o, d, c, r) {
                if t0 > 0.0 && best.is_none_or(|b| t0 < b.0) {
                    best = Some((t0, Opaque::Sphere(k as u32)));
                }
            }
        }
        let tmax = best.map_or(f64::INFINITY, |b| b.0);
        let mut surface: Option<(f64, u32)> = None;
        for (i, it) in items.iter().enumerate() {
            if let Some(t) = it.seen_at(o, d, 0.0, tmax) {
                if t < tmax && surface.is_none_or(|s| t < s.0) {
                    surface = Some((t, i as u32));
                }
            }
        }
        let want = match surface {
            Some((t, i)) => Some((t, Opaque::Surface(i))),
            None => best,
        };
        let got = first_hit(&prep, o, d, 0.0).map(|h| {
            // Sphere hits name BVH primitives: compare scene indices.
            let on = match h.on {
                Opaque::Sphere(p) => Opaque::Sphere(prep.bvh.prim(p).sphere),
                s => s,
            };
            (h.t, on)
        });
        assert_eq!(got, want, "ray {o} {d}");
        if matches!(want, Some((_, Opaque::Surface(_)))) {
            surface_hits += 1;
        }
        // Any hit over a segment of the ray (shadow rays).
        let len = 12.0;
        let any = items.iter().any(|it| it.crosses(o, d, 0.0, len));
        assert_eq!(
            prep.surfaces.blocks(o, d, 0.0, len, None),
            any,
            "ray {o} {d}"
        );
        blocked += usize::from(any);
    }
    assert!(
        surface_hits > 800 && blocked > 500,
        "{surface_hits} surface hits, {blocked} blocked"
    );
}
