//! AO among Cylinders and Cones against independent answers: the closed forms of a disc seen
//! on its axis (a Cylinder or a Cone looked at along its axis shows a disc), and Monte Carlo
//! over rays classified here by clipping each ray against the solid's defining inequalities
//! (not the renderer's surface crossings), with a stated confidence. The reported error must
//! bound the true one, and be within the tolerance.

use glam::{DAffine3, DQuat, DVec3};

use super::tests::Mix;
use super::union::Weighting;
use super::{unoccluded_to, AoScratch};
use crate::geom::shapes::Solid;
use crate::render::visibility::Opaque;
use crate::render::{self, PrepareOptions, Prepared};
use crate::scene::{Material, Scene, Surface, SurfaceShape};

fn cylinder(radius: f64, half_height: f64) -> Solid {
    Solid::Cylinder {
        radius,
        half_height,
        bottom: true,
        side: true,
        top: true,
    }
}

fn cone(radius: f64, half_height: f64) -> Solid {
    Solid::Cone {
        radius,
        half_height,
        side: true,
        bottom: true,
    }
}

/// A scene of `spheres` and round `solids` (each with its map to the world), prepared.
fn prepared(spheres: &[(DVec3, f64)], solids: &[(Solid, DAffine3)]) -> Prepared {
    let mut scene = Scene::default();
    let m = Material::default();
    for &(c, r) in spheres {
        scene.add_sphere(c, r, &m);
    }
    let paint = scene.materials.add(&m);
    for &(solid, to_world) in solids {
        scene.surfaces.push(Surface {
            shape: SurfaceShape::Solid { solid, to_world },
            color: paint.color,
            material: paint.material,
            origin: Default::default(),
        });
    }
    render::prepare(scene, &PrepareOptions::default()).unwrap()
}

/// The fraction of the cosine-weighted (or uniform) hemisphere about the axis of a disc of
/// radius `r` seen from distance `z` on its axis, that the disc leaves open.
fn disc_open(r: f64, z: f64, w: Weighting) -> f64 {
    match w {
        Weighting::Cosine => z * z / (r * r + z * z),
        Weighting::Uniform => z / (r * r + z * z).sqrt(),
    }
}

#[test]
fn a_cylinder_or_cone_seen_along_its_axis_leaves_what_a_disc_leaves() {
    let mut rng = Mix(41);
    let mut s = AoScratch::default();
    let mut worst_ratio = 0.0f64;
    for case in 0..24 {
        let (r, h) = (0.3 + rng.next(), 0.2 + rng.next());
        let z = 0.05 + 2.0 * rng.next();
        let w = if case % 2 == 0 {
            Weighting::Cosine
        } else {
            Weighting::Uniform
        };
        let tol = [1e-2, 1e-3, 1e-4, 1e-5][case % 4];
        // Object space: axis y. Seen from above a Cylinder's top cap, or from below a Cone's
        // base, or from above its apex (the base rim then bounds what it blocks).
        let (solid, x_obj, n_obj, want) = match case % 3 {
            0 => (
                cylinder(r, h),
                DVec3::new(0.0, h + z, 0.0),
                -DVec3::Y,
                disc_open(r, z, w),
            ),
            1 => (
                cone(r, h),
                DVec3::new(0.0, -h - z, 0.0),
                DVec3::Y,
                disc_open(r, z, w),
            ),
            _ => (
                cone(r, h),
                DVec3::new(0.0, h + z, 0.0),
                -DVec3::Y,
                disc_open(r, z + 2.0 * h, w),
            ),
        };
        // Anywhere in the world, turned and uniformly scaled.
        let axis = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
        let scale = 0.5 + 2.0 * rng.next();
        let to_world = DAffine3::from_scale_rotation_translation(
            DVec3::splat(scale),
            DQuat::from_axis_angle(axis, 6.0 * rng.next()),
            DVec3::new(100.0 * rng.next(), -50.0, 10.0 * rng.next()),
        );
        let prep = prepared(&[], &[(solid, to_world)]);
        let x = to_world.transform_point3(x_obj);
        let n = to_world.transform_vector3(n_obj).normalize();
        let (v, error) = unoccluded_to(&prep, x, n, None, (f64::INFINITY, w), tol, &mut s);
        let truth = (want - v).abs();
        assert!(
            truth <= error + 1e-12,
            "case {case}: {v} against {want}: off by {truth:e}, bound {error:e}"
        );
        assert!(
            error <= tol,
            "case {case}: bound {error:e} above tol {tol:e}"
        );
        worst_ratio = worst_ratio.max(truth / error.max(1e-300));
    }
    eprintln!("discs on axis: worst true error / bound {worst_ratio:.3}");
}

/// The parameters `t` of the ray `o + t d` (object space) inside a solid of the closed
/// quadric `x² + z² <= (a + b y)²` cut to `|y| <= h`, as an interval (possibly empty), with
/// `a + b y >= 0` in the slab (a cone's apex on its edge).
fn quadric_interval(o: DVec3, d: DVec3, (a, b): (f64, f64), h: f64) -> (f64, f64) {
    // The slab |y| <= h.
    let (mut lo, mut hi) = if d.y == 0.0 {
        if o.y.abs() <= h {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return (1.0, 0.0);
        }
    } else {
        let (t0, t1) = ((-h - o.y) / d.y, (h - o.y) / d.y);
        (t0.min(t1), t0.max(t1))
    };
    // q(t) = (ox + t dx)² + (oz + t dz)² - (a + b (oy + t dy))² <= 0.
    let (ra, rb) = (a + b * o.y, b * d.y);
    let qa = d.x * d.x + d.z * d.z - rb * rb;
    let qb = 2.0 * (o.x * d.x + o.z * d.z - ra * rb);
    let qc = o.x * o.x + o.z * o.z - ra * ra;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa.abs() < 1e-300 {
        // Linear: q = qb t + qc <= 0.
        if qb > 0.0 {
            hi = hi.min(-qc / qb);
        } else if qb < 0.0 {
            lo = lo.max(-qc / qb);
        } else if qc > 0.0 {
            return (1.0, 0.0);
        }
    } else if disc < 0.0 {
        if qa > 0.0 {
            return (1.0, 0.0);
        }
    } else {
        let sq = disc.sqrt();
        let (t0, t1) = ((-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa));
        let (t0, t1) = (t0.min(t1), t0.max(t1));
        if qa > 0.0 {
            lo = lo.max(t0);
            hi = hi.min(t1);
        } else if lo <= t0.min(hi) {
            // Outside (t0, t1): of the two pieces, the one within the slab (the slab holds one
            // nappe of a cone, a convex solid, which a line meets in one interval).
            hi = hi.min(t0);
        } else {
            lo = lo.max(t1);
        }
    }
    (lo, hi)
}

/// Whether the world ray `x + t w`, `0 < t <= reach`, meets one of the occluders.
fn blocked(
    x: DVec3,
    w: DVec3,
    reach: f64,
    spheres: &[(DVec3, f64)],
    solids: &[(Solid, DAffine3)],
) -> bool {
    let meets = |(lo, hi): (f64, f64)| lo <= hi && hi > 0.0 && lo.max(0.0) <= reach;
    for &(c, r) in spheres {
        let oc = x - c;
        let b = oc.dot(w);
        let disc = b * b - (oc.length_squared() - r * r);
        if disc >= 0.0 && meets((-b - disc.sqrt(), -b + disc.sqrt())) {
            return true;
        }
    }
    for (solid, to_world) in solids {
        let to_object = to_world.inverse();
        let (o, d) = (
            to_object.transform_point3(x),
            to_object.transform_vector3(w),
        );
        let interval = match *solid {
            Solid::Cylinder {
                radius,
                half_height,
                ..
            } => quadric_interval(o, d, (radius, 0.0), half_height),
            Solid::Cone {
                radius,
                half_height,
                ..
            } => {
                // Radius r (h - y) / (2h): a = r / 2, b = -r / (2h).
                let b = -radius / (2.0 * half_height);
                quadric_interval(o, d, (radius / 2.0, b), half_height)
            }
            Solid::Cuboid { .. } => unreachable!(),
        };
        if meets(interval) {
            return true;
        }
    }
    false
}

/// A direction of the hemisphere about `n`, cosine-weighted or uniform.
fn direction(n: DVec3, w: Weighting, u1: f64, u2: f64) -> DVec3 {
    let (e1, e2) = n.any_orthonormal_pair();
    let phi = std::f64::consts::TAU * u2;
    let (cos, sin) = match w {
        Weighting::Cosine => ((1.0 - u1).sqrt(), u1.sqrt()),
        Weighting::Uniform => (1.0 - u1, (u1 * (2.0 - u1)).max(0.0).sqrt()),
    };
    (e1 * phi.cos() + e2 * phi.sin()) * sin + n * cos
}

#[test]
fn random_scenes_of_spheres_cylinders_and_cones_match_monte_carlo() {
    let mut rng = Mix(43);
    let mut s = AoScratch::default();
    let (mut worst_sigma, mut points, mut partial) = (0.0f64, 0, 0);
    const RAYS: usize = 40_000;
    for case in 0..16 {
        let spheres: Vec<(DVec3, f64)> = (0..3)
            .map(|_| {
                let c = DVec3::new(rng.next(), rng.next(), rng.next()) * 3.0;
                (c, 0.2 + 0.4 * rng.next())
            })
            .collect();
        let solids: Vec<(Solid, DAffine3)> = (0..4)
            .map(|k| {
                let (r, h) = (0.2 + 0.4 * rng.next(), 0.2 + 0.6 * rng.next());
                let solid = if k % 2 == 0 {
                    cylinder(r, h)
                } else {
                    cone(r, h)
                };
                let axis =
                    DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
                // A non-uniform scale too: an elliptic cylinder or cone is still convex.
                let scale = DVec3::new(0.7 + rng.next(), 0.7 + rng.next(), 0.7 + rng.next());
                let to_world = DAffine3::from_scale_rotation_translation(
                    scale,
                    DQuat::from_axis_angle(axis, 6.0 * rng.next()),
                    DVec3::new(rng.next(), rng.next(), rng.next()) * 3.0,
                );
                (solid, to_world)
            })
            .collect();
        let prep = prepared(&spheres, &solids);
        let w = if case % 2 == 0 {
            Weighting::Cosine
        } else {
            Weighting::Uniform
        };
        let reach = if case % 3 == 0 {
            f64::INFINITY
        } else {
            0.5 + 2.0 * rng.next()
        };
        let tol = if case % 4 == 0 { 1e-5 } else { 1e-3 };
        for k in 0..3 {
            // A point on a sphere (own), about its outward normal, or in the open.
            let (x, n, own) = if k < 2 {
                let (c, r) = spheres[k];
                let n =
                    DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
                let i = (0..prep.bvh.len() as u32)
                    .find(|&i| prep.bvh.prim(i).sphere == k as u32)
                    .unwrap();
                (c + r * n, n, Some(Opaque::Sphere(i)))
            } else {
                let x = DVec3::new(rng.next(), rng.next(), rng.next()) * 3.0;
                let n =
                    DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5).normalize();
                (x, n, None)
            };
            let others: Vec<(DVec3, f64)> = spheres
                .iter()
                .enumerate()
                .filter(|&(j, _)| !(k < 2 && j == k))
                .map(|(_, s)| *s)
                .collect();
            let inside_solid = solids.iter().any(|(solid, to_world)| {
                super::bracket::inside(solid, to_world.inverse().transform_point3(x))
            });
            let inside_sphere = others.iter().any(|&(c, r)| (x - c).length() < r);
            let (v, error) = unoccluded_to(&prep, x, n, own, (reach, w), tol, &mut s);
            if inside_solid || inside_sphere {
                assert_eq!(v, 0.0, "case {case} point {k}: inside an occluder");
                continue;
            }
            // Stratified in u2, plain in u1.
            let mut open = 0usize;
            for i in 0..RAYS {
                let (u1, u2) = (rng.next(), (i as f64 + rng.next()) / RAYS as f64);
                let d = direction(n, w, u1, u2);
                if !blocked(x + 1e-9 * n, d, reach, &others, &solids) {
                    open += 1;
                }
            }
            let p = open as f64 / RAYS as f64;
            let sigma =
                (p.max(1.0 / RAYS as f64) * (1.0 - p).max(1.0 / RAYS as f64) / RAYS as f64).sqrt();
            let off = (v - p).abs();
            assert!(
                off <= 5.0 * sigma + error,
                "case {case} point {k}: {v} (bound {error:e}) against Monte Carlo {p} \
                 (sigma {sigma:e})"
            );
            worst_sigma = worst_sigma.max((off - error).max(0.0) / sigma);
            points += 1;
            partial += usize::from(p > 0.0 && p < 1.0);
        }
    }
    assert!(
        points >= 30 && partial >= 20,
        "{points} points, {partial} partly open"
    );
    eprintln!(
        "round solids against Monte Carlo ({RAYS} rays): worst {worst_sigma:.2} sigma over \
         {points} points"
    );
}

#[test]
fn a_spheres_mean_beside_a_cylinder_and_a_cone_matches_monte_carlo() {
    use crate::render::particle_ao::sphere_ao;
    let mut rng = Mix(47);
    let (c, r) = (DVec3::new(0.0, 0.0, 0.0), 0.5);
    let solids = [
        (
            cylinder(0.3, 1.5),
            DAffine3::from_rotation_translation(
                DQuat::from_rotation_x(0.4),
                DVec3::new(1.0, 0.2, 0.0),
            ),
        ),
        (
            cone(0.6, 0.5),
            DAffine3::from_translation(DVec3::new(-0.3, 1.3, 0.4)),
        ),
    ];
    let prep = prepared(&[(c, r)], &solids);
    let mut s = AoScratch::default();
    for (w, reach) in [
        (Weighting::Cosine, f64::INFINITY),
        (Weighting::Uniform, 1.0),
    ] {
        let a = sphere_ao(&prep, (c, r), Some(0), (reach, w), 1e-3, &mut s);
        // One cosine- (or uniformly) weighted ray from each of many uniform points of the
        // surface.
        const N: usize = 400_000;
        let mut open = 0usize;
        for _ in 0..N {
            let n = loop {
                let v = DVec3::new(rng.next(), rng.next(), rng.next()) * 2.0 - 1.0;
                let l = v.length();
                if l > 1e-3 && l <= 1.0 {
                    break v / l;
                }
            };
            let d = direction(n, w, rng.next(), rng.next());
            if !blocked(c + (r + 1e-9) * n, d, reach, &[], &solids) {
                open += 1;
            }
        }
        let p = open as f64 / N as f64;
        let sigma = (p * (1.0 - p) / N as f64).sqrt();
        assert!(
            (a.mean - p).abs() <= 5.0 * sigma + a.error,
            "{w:?}: {} (error {:e}) against Monte Carlo {p} (sigma {sigma:e})",
            a.mean,
            a.error
        );
        assert!(
            p > 0.05 && p < 0.95,
            "{p}: the solids occlude part of the sphere"
        );
    }
}
