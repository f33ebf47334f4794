//! Exact AO among spheres, triangles and Boxes on random scenes and on meshes near their
//! edges, against the reference and pixel by pixel through the renderer.

use glam::{DAffine3, DVec3};

use super::*;

/// Random scenes of spheres, triangles (a loose mesh and stray ones) and Boxes, with points
/// on each kind, every reach and weighting, against the reference.
#[test]
fn random_mixed_scenes_match_the_reference() {
    let mut rng = Mix(27);
    let (mut worst, mut points) = (0.0f64, 0usize);
    for scene in 0..6 {
        let spheres = crate::render::ao::tests::packing(&mut rng, 14);
        let side = spheres
            .iter()
            .map(|s| s.0.max_element())
            .fold(0.0, f64::max);
        let mut triangles = Vec::new();
        // A height field of 3 x 3 quads through the packing.
        let grid = |i: usize, j: usize| {
            let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
            DVec3::new(
                u * side,
                v * side,
                0.5 * side + 0.8 * ((5.0 * u).sin() + (4.0 * v).cos()),
            )
        };
        tessellate(3, &grid, &mut triangles);
        for _ in 0..4 {
            let c = DVec3::new(rng.next(), rng.next(), rng.next()) * side;
            triangles.push(std::array::from_fn(|_| c + rng.unit() * (0.5 + rng.next())));
        }
        let boxes: Vec<(DVec3, DAffine3)> = (0..2)
            .map(|_| {
                let c = DVec3::new(rng.next(), rng.next(), rng.next()) * side;
                skewed_box(c, &mut rng)
            })
            .collect();
        let occ = Occluders {
            spheres,
            triangles,
            boxes,
        };
        let prep = occ.prepared();
        let mut s = AoScratch::default();
        for k in 0..24 {
            // A point on a sphere, a triangle or a Box, with its outward (or either) normal.
            let (x, n, on) = match k % 3 {
                0 => {
                    let i = rng.next_index(occ.spheres.len());
                    let (c, r) = occ.spheres[i];
                    let d = rng.unit();
                    (c + r * d, d, On::Sphere(i))
                }
                1 => {
                    let i = rng.next_index(occ.triangles.len());
                    let t = occ.triangles[i];
                    let (a, b) = (rng.next(), rng.next());
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    let x = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                    let g = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                    (x, if rng.next() < 0.5 { g } else { -g }, On::Triangle(i))
                }
                _ => {
                    let i = rng.next_index(occ.boxes.len());
                    let (half, to_world) = occ.boxes[i];
                    let axis = rng.next_index(3);
                    let mut p = DVec3::new(
                        2.0 * rng.next() - 1.0,
                        2.0 * rng.next() - 1.0,
                        2.0 * rng.next() - 1.0,
                    ) * half;
                    let sign = if rng.next() < 0.5 { -1.0 } else { 1.0 };
                    p[axis] = sign * half[axis];
                    let mut normal = DVec3::ZERO;
                    normal[axis] = sign;
                    let n = (to_world.matrix3.inverse().transpose() * normal).normalize();
                    (to_world.transform_point3(p), n, On::Box(i))
                }
            };
            let own = occ.own(&prep, on);
            for (reach, w) in [
                (f64::INFINITY, Weighting::Cosine),
                (2.0, Weighting::Cosine),
                (0.7, Weighting::Uniform),
                (f64::INFINITY, Weighting::Uniform),
            ] {
                let got = 1.0 - unoccluded(&prep, x, n, own, (reach, w), &mut s);
                let (want, unconverged) = occ.reference(x, n, on, reach, w);
                assert_eq!(unconverged, 0, "scene {scene} point {k}");
                worst = worst.max((got - want).abs());
                points += 1;
                assert!(
                    (got - want).abs() <= 1e-12,
                    "scene {scene} point {k} on {on:?} reach {reach} {w:?}: {got} against {want}"
                );
            }
        }
    }
    eprintln!("random mixed scenes: worst {worst:e} over {points} points");
}

/// Renders `occ` as AO seen from `eye` (the pixel centres, with the depth, normal and id
/// channels), and checks every covered pixel against the reference at the point the
/// channels give: the gathering through both BVHs, the normal at a triangle's or Box's hit
/// and the whole render path. Returns the pixels on spheres, triangles and Boxes and the
/// worst error.
fn render_matches_reference(
    occ: &Occluders,
    (eye, size): (DVec3, (u32, u32)),
    (reach, weighting): (f64, Weighting),
) -> ([usize; 3], f64) {
    use crate::render::{Aovs, Camera, Integrator, Lens, RenderOptions};
    let prep = occ.prepared();
    let middle = occ.spheres.iter().map(|s| s.0).sum::<DVec3>() / occ.spheres.len() as f64;
    let cam = Camera::look_at(eye, middle, DVec3::Y, Lens::default()).unwrap();
    let opts = RenderOptions {
        width: size.0,
        height: size.1,
        spp: 1,
        sampler: render::SamplerKind::Center,
        aovs: Aovs {
            depth: true,
            normal: true,
            id: true,
            ..Aovs::default()
        },
        integrator: Integrator::Ao(crate::render::ao::AoSettings {
            reach,
            weighting,
            ..crate::render::ao::AoSettings::default()
        }),
        ..RenderOptions::default()
    };
    let film = render::render(&prep, &cam, &opts, &()).unwrap();
    let plane = cam.image_plane(size.0, size.1);
    let (depth, normals, ids) = (film.depth.unwrap(), film.normal.unwrap(), film.id.unwrap());
    let (mut covered, mut worst) = ([0; 3], 0.0f64);
    let spheres = occ.spheres.len();
    for p in 0..film.rgb.len() {
        let Ok(id) = usize::try_from(ids[p]) else {
            continue;
        };
        let (i, j) = (p as u32 % size.0, p as u32 / size.0);
        let (o, d) = plane.ray(
            (f64::from(i) + 0.5) / f64::from(size.0),
            (f64::from(j) + 0.5) / f64::from(size.1),
        );
        let x = o + depth[p] * d;
        let normal = DVec3::from_array(normals[p]);
        let (on, n, kind) = if id < spheres {
            (On::Sphere(id), normal, 0)
        } else if id - spheres < occ.triangles.len() {
            // The geometric normal, on the side the ray came from.
            let t = occ.triangles[id - spheres];
            let g = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            (
                On::Triangle(id - spheres),
                if g.dot(d) > 0.0 { -g } else { g },
                1,
            )
        } else {
            (On::Box(id - spheres - occ.triangles.len()), normal, 2)
        };
        let (want, unconverged) = occ.reference(x, n, on, reach, weighting);
        assert_eq!(unconverged, 0, "pixel {p}");
        let got = film.rgb[p][0];
        let err = (got - (1.0 - want)).abs();

        worst = worst.max(err);
        assert!(
            err <= 1e-12,
            "pixel {p} on {on:?}, reach {reach} {weighting:?}: {got} against {}",
            1.0 - want
        );
        covered[kind] += 1;
    }
    (covered, worst)
}

/// Random scenes of spheres, a folded mesh behind them and Boxes, seen from outside and
/// from among them, every reach and weighting: each pixel against the reference.
#[test]
fn random_scenes_with_triangles_and_boxes_render_as_the_reference_says() {
    let mut rng = Mix(28);
    let (mut pixels, mut worst) = ([0usize; 3], 0.0f64);
    for case in 0..6 {
        let spheres = crate::render::ao::tests::packing(&mut rng, 10);
        let side = spheres
            .iter()
            .map(|s| s.0.max_element())
            .fold(0.0, f64::max);
        let grid = |i: usize, j: usize| {
            // A folded wall behind the spheres, facing the cameras.
            let (u, v) = (i as f64 - 0.5, j as f64 - 0.5);
            DVec3::new(
                u * side,
                v * side,
                -0.1 * side + 0.6 * ((3.0 * u).sin() * (2.0 * v).cos()),
            )
        };
        let mut triangles = Vec::new();
        tessellate(2, &grid, &mut triangles);
        let boxes = (0..3)
            .map(|_| {
                let (half, to_world) = skewed_box(
                    DVec3::new(rng.next(), rng.next(), rng.next()) * side,
                    &mut rng,
                );
                (half * 1.5, to_world)
            })
            .collect();
        let occ = Occluders {
            spheres,
            triangles,
            boxes,
        };
        let middle = occ.spheres.iter().map(|s| s.0).sum::<DVec3>() / occ.spheres.len() as f64;
        let eye = if case % 2 == 0 {
            middle + DVec3::new(2.0, 6.0, 12.0)
        } else {
            middle + rng.unit() * 1.2
        };
        let reach = [f64::INFINITY, 2.0, 0.7][case % 3];
        let weighting = [Weighting::Cosine, Weighting::Uniform][(case / 3) % 2];
        let (n, w) = render_matches_reference(&occ, (eye, (16, 12)), (reach, weighting));
        for k in 0..3 {
            pixels[k] += n[k];
        }
        worst = worst.max(w);
    }
    assert!(
        pixels.iter().all(|&p| p > 30),
        "pixels on spheres, triangles and Boxes: {pixels:?}"
    );
    eprintln!("random AO scenes with triangles and Boxes: worst {worst:e} over {pixels:?} pixels");
}

/// Points on a folded mesh near its shared edges and corners, off their triangle's plane by
/// what the rounding of a hit point seen from far away gives (up to `1e-12` of the mesh's
/// size): the planes through the point and the neighbours' edges then turn by that over the
/// distance to the edge, which the shared corners and edges taken in the tangent plane undo.
#[test]
fn points_on_a_mesh_near_its_edges_and_off_its_plane_by_rounding() {
    let mut rng = Mix(29);
    let grid = |i: usize, j: usize| {
        let (u, v) = (i as f64 * 0.7, j as f64 * 0.7);
        DVec3::new(u, 0.3 * (2.0 * u).sin() + 0.25 * (1.7 * v).cos(), v)
    };
    let mut triangles = Vec::new();
    tessellate(4, &grid, &mut triangles);
    let occ = Occluders {
        spheres: vec![(DVec3::new(1.4, 1.2, 1.4), 0.5)],
        triangles,
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    let (mut worst, mut worst_ratio, mut unconverged_near_corners) = (0.0f64, 0.0f64, 0);
    for k in 0..120 {
        let i = rng.next_index(occ.triangles.len());
        let t = occ.triangles[i];
        // Near an edge (down to 1e-7 of its length), near a corner (down to 1e-5), or
        // anywhere.
        let (a, b) = match k % 3 {
            0 => (10f64.powf(-3.0 - 4.0 * rng.next()), rng.next()),
            1 => (
                10f64.powf(-3.0 - 2.0 * rng.next()),
                10f64.powf(-3.0 - 2.0 * rng.next()),
            ),
            _ => (rng.next(), rng.next()),
        };
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let g = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        let g = if g.y < 0.0 { -g } else { g };
        let off = (2.0 * rng.next() - 1.0) * 10f64.powf(-12.0 - 4.0 * rng.next());
        let x = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b + g * off;
        let own = occ.own(&prep, On::Triangle(i));
        // Within d of a corner, the planes through the point and the edges there turn by the
        // rounding of the corners relative to the point over d, in the exact method and in
        // the reference alike.
        let d = t
            .iter()
            .map(|p| (*p - x).length())
            .fold(f64::INFINITY, f64::min);
        let bound = 1e-12 + 4e-16 / d;
        for (reach, w) in [
            (f64::INFINITY, Weighting::Cosine),
            (0.6, Weighting::Uniform),
        ] {
            let got = 1.0 - unoccluded(&prep, x, g, own, (reach, w), &mut s);
            let (want, unconverged) = occ.reference(x, g, On::Triangle(i), reach, w);
            // (Near a corner the reference's quadrature may stop short of 1e-15 on a piece of
            // the azimuth; it is still held to the bound.)
            assert!(
                unconverged == 0 || d < 1e-3,
                "point {k}: {unconverged} unconverged"
            );
            unconverged_near_corners += unconverged;
            worst = worst.max((got - want).abs());
            worst_ratio = worst_ratio.max((got - want).abs() / bound);
            assert!(
                (got - want).abs() <= bound,
                "point {k} on triangle {i} ({a:e}, {b:e}, off {off:e}) reach {reach} {w:?}: \
                 {got} against {want}"
            );
        }
    }
    eprintln!(
        "points on a mesh near its edges: worst {worst:e}, {worst_ratio:.3} of the bound \
         ({unconverged_near_corners} pieces of the reference unconverged near corners)"
    );
}

/// Adds to `triangles` the `cells` x `cells` squares of the grid of points `grid(i, j)`, each
/// as two triangles sharing its diagonal.
fn tessellate(cells: usize, grid: &dyn Fn(usize, usize) -> DVec3, triangles: &mut Vec<[DVec3; 3]>) {
    for i in 0..cells {
        for j in 0..cells {
            let (a, b, c, d) = (
                grid(i, j),
                grid(i + 1, j),
                grid(i + 1, j + 1),
                grid(i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
}
