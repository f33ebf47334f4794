//! Exact AO among triangles and Boxes against independent answers: the closed forms of one
//! polygon (its solid angle by Van Oosterom and Strackee, its cosine-weighted share by
//! Lambert's edge sum, both after clipping it to the horizon), the reference's quadrature
//! that meets each triangle along each meridian (`reference::covered_with_triangles`), and
//! Monte Carlo over rays with a stated confidence.

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::cap::{blocked_by_ball, form_factor as one_cap, Blocked};
use super::polygon::{blocked_by_box, blocked_by_polygon, BoxBlocks};
use super::tests::Mix;
use super::union::{covered_fraction_of_regions, RegionScratch, Regions, Weighting};
use super::{unoccluded, AoScratch};
use crate::geom::shapes::{triangle_hit, Solid};
use crate::render::visibility::Opaque;
use crate::render::{self, PrepareOptions, Prepared};
use crate::scene::{Material, Scene, Surface, SurfaceShape, Triangle};

/// Occluders of a test scene: spheres, triangles and Boxes (half extents, map to the world).
#[derive(Clone, Default)]
struct Occluders {
    spheres: Vec<(DVec3, f64)>,
    triangles: Vec<[DVec3; 3]>,
    boxes: Vec<(DVec3, DAffine3)>,
}

/// What a test point is on.
#[derive(Clone, Copy, Debug, PartialEq)]
enum On {
    Nothing,
    Sphere(usize),
    Triangle(usize),
    Box(usize),
}

impl Occluders {
    /// The scene, prepared: spheres first, then the triangles, then the Boxes.
    fn prepared(&self) -> Prepared {
        let mut scene = Scene::default();
        let m = Material::default();
        for &(c, r) in &self.spheres {
            scene.add_sphere(c, r, &m);
        }
        let paint = scene.materials.add(&m);
        let mut push = |shape| {
            scene.surfaces.push(Surface {
                shape,
                color: paint.color,
                material: paint.material,
                origin: Default::default(),
            })
        };
        for t in &self.triangles {
            push(SurfaceShape::Triangle(Box::new(Triangle {
                p: *t,
                n: None,
                color: None,
                solid: false,
            })));
        }
        for &(half, to_world) in &self.boxes {
            push(SurfaceShape::Solid {
                solid: Solid::Cuboid { half },
                to_world,
            });
        }
        render::prepare(scene, &PrepareOptions::default()).unwrap()
    }

    /// What `on` is in `prep`'s terms.
    fn own(&self, prep: &Prepared, on: On) -> Option<Opaque> {
        match on {
            On::Nothing => None,
            On::Sphere(k) => (0..prep.bvh.len() as u32)
                .find(|&i| prep.bvh.prim(i).sphere == k as u32)
                .map(Opaque::Sphere),
            On::Triangle(k) => Some(Opaque::Surface(k as u32)),
            On::Box(k) => Some(Opaque::Surface((self.triangles.len() + k) as u32)),
        }
    }

    /// The reference's covered fraction at `x` (normal `n`), `on` left out: the spheres'
    /// caps, the triangles met along the meridians, a Box as its 12 triangles; 1 inside a
    /// sphere or a Box. Triangles in the plane of the one `x` is on are edge-on.
    fn reference(&self, x: DVec3, n: DVec3, on: On, reach: f64, w: Weighting) -> (f64, usize) {
        let mut caps = Vec::new();
        for (k, &(c, r)) in self.spheres.iter().enumerate() {
            if on == On::Sphere(k) {
                continue;
            }
            match blocked_by_ball(x, c, r, reach) {
                Blocked::Nothing => {}
                Blocked::Cap(cap) => caps.push((cap.axis.to_array(), cap.cos)),
                Blocked::Everything => return (1.0, 0),
            }
        }
        let plane = |t: &[DVec3; 3]| {
            let g = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            (g, g.dot(t[0]))
        };
        let mut tris: Vec<([[f64; 3]; 3], [bool; 3])> = Vec::new();
        for (k, t) in self.triangles.iter().enumerate() {
            if on == On::Triangle(k) {
                continue;
            }
            // The corners of the triangle the point is on lie in its tangent plane.
            let mut flat = [false; 3];
            if let On::Triangle(own) = on {
                let (g, d) = plane(&self.triangles[own]);
                if t.iter().all(|p| (g.dot(*p) - d).abs() < 1e-12) {
                    continue;
                }
                flat = t.map(|p| self.triangles[own].contains(&p));
            }
            tris.push((t.map(|p| (p - x).to_array()), flat));
        }
        for (k, &(half, to_world)) in self.boxes.iter().enumerate() {
            if on == On::Box(k) {
                continue;
            }
            let inside = to_world.inverse().transform_point3(x).abs();
            if inside.cmplt(half).all() {
                return (1.0, 0);
            }
            for t in box_triangles(half, &to_world) {
                tris.push((t.map(|p| (p - x).to_array()), [false; 3]));
            }
        }
        let weight = match w {
            Weighting::Cosine => super::reference::Weight::Cosine,
            Weighting::Uniform => super::reference::Weight::Uniform,
        };
        let (v, stats) =
            super::reference::covered_with_triangles(n.to_array(), &caps, &tris, reach, weight);
        (v, stats.unconverged)
    }
}

/// The 12 triangles of a Box's surface, in the world.
fn box_triangles(half: DVec3, to_world: &DAffine3) -> Vec<[DVec3; 3]> {
    let corner = |b: usize| {
        let s = |bit: usize| if b >> bit & 1 == 1 { 1.0 } else { -1.0 };
        to_world.transform_point3(DVec3::new(s(0) * half.x, s(1) * half.y, s(2) * half.z))
    };
    // Each face by its axis and side: the corners with that bit fixed.
    let mut out = Vec::new();
    for axis in 0..3 {
        for side in 0..2 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let c = |a: usize, b: usize| corner(side << axis | a << u | b << v);
            out.push([c(0, 0), c(1, 0), c(1, 1)]);
            out.push([c(0, 0), c(1, 1), c(0, 1)]);
        }
    }
    out
}

/// The solid angle of the triangle `a, b, c` (corners relative to the point), by Van
/// Oosterom and Strackee (IEEE Trans. Biomed. Eng. 30, 1983).
fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let det = a.dot(b.cross(c)).abs();
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * det.atan2(den)
}

/// The convex polygon `poly` (corners relative to the point) clipped to the half-space
/// `n . y >= 0` (Sutherland and Hodgman).
fn clip(poly: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// The closed forms of one convex polygon (corners relative to the point) seen from a point
/// of normal `n`, over the hemisphere: the covered fraction cosine-weighted (Lambert's form
/// factor of a polygon, `(1/2π) Σ Θ_i n . Γ_i`) and uniform (its solid angle over `2π`).
fn closed_forms(poly: &[DVec3], n: DVec3) -> (f64, f64) {
    let p = clip(poly, n);
    if p.len() < 3 {
        return (0.0, 0.0);
    }
    let mut lambert = 0.0;
    for i in 0..p.len() {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let g = a.cross(b);
        if g.length() == 0.0 {
            continue;
        }
        let theta = g.length().atan2(a.dot(b));
        lambert += theta * n.dot(g.normalize());
    }
    let solid: f64 = (1..p.len() - 1)
        .map(|i| solid_angle(p[0], p[i], p[i + 1]))
        .sum();
    (
        (lambert / std::f64::consts::TAU).abs(),
        solid / std::f64::consts::TAU,
    )
}

/// The covered fraction of `polys` (in the world) seen from `x`, exactly: each one's region,
/// their union.
fn exact_polys(polys: &[Vec<DVec3>], x: DVec3, n: DVec3, reach: f64, w: Weighting) -> f64 {
    let mut regions = Regions::default();
    for p in polys {
        blocked_by_polygon(x, n, p, reach, &mut regions);
    }
    covered_fraction_of_regions(n, &[], &regions, w, &mut RegionScratch::default())
}

/// Monte Carlo of the covered fraction, directions drawn as `w` weights them: the share that
/// `blocked` says meet something; and its standard error.
fn monte_carlo(
    n: DVec3,
    w: Weighting,
    rays: usize,
    rng: &mut Mix,
    blocked: impl Fn(DVec3) -> bool,
) -> (f64, f64) {
    let (e1, e2) = n.any_orthonormal_pair();
    let mut hits = 0usize;
    for _ in 0..rays {
        let (u, v) = (rng.next(), rng.next());
        let (z, r) = match w {
            Weighting::Cosine => ((1.0 - u).sqrt(), u.sqrt()),
            Weighting::Uniform => (1.0 - u, (u * (2.0 - u)).sqrt()),
        };
        let a = std::f64::consts::TAU * v;
        let d = (e1 * a.cos() + e2 * a.sin()) * r + n * z;
        hits += usize::from(blocked(d));
    }
    let p = hits as f64 / rays as f64;
    (p, (p * (1.0 - p) / rays as f64).sqrt())
}

fn both() -> [Weighting; 2] {
    [Weighting::Cosine, Weighting::Uniform]
}

#[test]
fn one_triangle_matches_its_closed_forms_in_front_and_across_the_horizon() {
    // Random triangles about a point: wholly above the horizon, and across it (clipped there
    // by the closed forms, whose rounding near a corner on the horizon sets the bound).
    let mut rng = Mix(21);
    let (mut worst, mut across) = (0.0f64, 0);
    for case in 0..400 {
        let x = DVec3::new(rng.next(), rng.next(), rng.next()) - 0.5;
        let n = rng.unit();
        let lift = if case % 2 == 0 { 0.6 } else { -0.3 };
        let tri: Vec<DVec3> = (0..3)
            .map(|_| x + rng.unit() * (0.3 + 2.0 * rng.next()) + n * lift)
            .collect();
        if tri.iter().any(|p| n.dot(*p - x) < 0.0) && tri.iter().any(|p| n.dot(*p - x) > 0.0) {
            across += 1;
        }
        let rel: Vec<DVec3> = tri.iter().map(|p| *p - x).collect();
        let (cosine, uniform) = closed_forms(&rel, n);
        for (w, want) in [(Weighting::Cosine, cosine), (Weighting::Uniform, uniform)] {
            let got = exact_polys(std::slice::from_ref(&tri), x, n, f64::INFINITY, w);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-13,
                "case {case} {w:?}: {got} against the closed form {want}"
            );
        }
    }
    assert!(across > 100, "{across} triangles across the horizon");
    // Edges in planes through the normal (great circles through it, where the solid angle's
    // form of the boundary integral has no digits to spare), and one through the pole.
    for tri in [
        [
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(2.0, 1.0, 1.5),
        ],
        [
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, 2.0),
        ],
        [
            DVec3::new(-1.0, 0.0, 0.5),
            DVec3::new(1.0, 0.0, 0.5),
            DVec3::new(0.0, 1.0, -0.5),
        ],
    ] {
        let (cosine, uniform) = closed_forms(&tri, DVec3::Z);
        for (w, want) in [(Weighting::Cosine, cosine), (Weighting::Uniform, uniform)] {
            let got = exact_polys(&[tri.to_vec()], DVec3::ZERO, DVec3::Z, f64::INFINITY, w);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-13,
                "{tri:?} {w:?}: {got} against {want}"
            );
        }
    }
    eprintln!("one triangle against its closed forms: worst {worst:e}");
}

#[test]
fn one_triangle_with_a_reach_matches_the_reference_and_monte_carlo() {
    let mut rng = Mix(22);
    let (mut worst, mut mc_worst) = (0.0f64, 0.0f64);
    for case in 0..60 {
        let x = DVec3::ZERO;
        let n = DVec3::new(0.2, -0.1, 1.0).normalize();
        let tri: [DVec3; 3] = std::array::from_fn(|_| rng.unit() * (0.5 + 2.5 * rng.next()));
        let reach = 0.4 + 2.0 * rng.next();
        let occ = Occluders {
            triangles: vec![tri],
            ..Occluders::default()
        };
        for w in both() {
            let got = exact_polys(&[tri.to_vec()], x, n, reach, w);
            let (want, unconverged) = occ.reference(x, n, On::Nothing, reach, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "case {case} reach {reach} {w:?}: {got} against the reference's {want}"
            );
            if case % 6 == 0 {
                // 5 standard errors.
                let (mc, se) = monte_carlo(n, w, 100_000, &mut rng, |d| {
                    triangle_hit(&tri, x, d, 0.0, reach).is_some()
                });
                mc_worst = mc_worst.max((got - mc).abs() / se.max(1e-300));
                assert!(
                    (got - mc).abs() <= 5.0 * se + 1e-12,
                    "case {case} {w:?}: {got} against Monte Carlo {mc} ± {se}"
                );
            }
        }
    }
    eprintln!(
        "one triangle with a reach: worst {worst:e} against the reference, \
         {mc_worst:.2} standard errors against Monte Carlo"
    );
}

#[test]
fn a_triangle_edge_on_or_beyond_the_reach_blocks_nothing() {
    let n = DVec3::Z;
    let x = DVec3::new(0.125, 0.25, 0.0);
    let mut regions = Regions::default();
    // In a plane through x (the point outside it, and inside it), upright and tilted.
    for tri in [
        [
            DVec3::new(1.0, 0.25, 0.0),
            DVec3::new(2.0, 0.25, 1.0),
            DVec3::new(1.0, 0.25, 2.0),
        ],
        [
            x + DVec3::new(1.0, 1.0, 1.0),
            x + DVec3::new(2.0, 0.5, 2.0),
            x + DVec3::new(1.5, -1.0, 1.5),
        ],
        [
            x + DVec3::new(-1.0, -1.0, -1.0),
            x + DVec3::new(2.0, 0.0, 2.0),
            x + DVec3::new(0.0, 2.0, 0.0),
        ],
    ] {
        let rel = tri.map(|p| p - x);
        assert_eq!(rel[0].dot(rel[1].cross(rel[2])), 0.0);
        assert!(!blocked_by_polygon(x, n, &tri, f64::INFINITY, &mut regions));
    }
    // A triangle wholly below the horizon, and one whose plane is beyond the reach.
    let low = [
        DVec3::new(0.0, 0.0, -1.0),
        DVec3::new(1.0, 0.0, -1.0),
        DVec3::new(0.0, 1.0, -0.5),
    ];
    assert!(!blocked_by_polygon(x, n, &low, f64::INFINITY, &mut regions));
    let high = [
        DVec3::new(-1.0, -1.0, 2.0),
        DVec3::new(1.0, -1.0, 2.0),
        DVec3::new(0.0, 1.0, 2.0),
    ];
    assert!(!blocked_by_polygon(x, n, &high, 1.9, &mut regions));
    assert!(blocked_by_polygon(x, n, &high, 2.1, &mut regions));
    // A degenerate triangle (collinear corners).
    let flat = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(2.0, 2.0, 1.0),
    ];
    assert!(super::polygon::is_sliver(&flat));
    // Through the whole path: a scene of an edge-on triangle and a sliver is unoccluded.
    let occ = Occluders {
        triangles: vec![
            [
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(2.0, 0.0, 1.0),
                DVec3::new(1.0, 0.0, 2.0),
            ],
            flat,
        ],
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    for w in both() {
        let got = unoccluded(
            &prep,
            DVec3::ZERO,
            DVec3::Z,
            None,
            (f64::INFINITY, w),
            &mut s,
        );
        assert_eq!(got, 1.0);
    }
}

/// A Box under a map with rotation, non-uniform scale and shear, around `centre`.
fn skewed_box(centre: DVec3, rng: &mut Mix) -> (DVec3, DAffine3) {
    let half = DVec3::new(0.3 + rng.next(), 0.3 + rng.next(), 0.3 + rng.next());
    let rot = DQuat::from_axis_angle(rng.unit(), 3.0 * rng.next());
    let shear = DMat3::from_cols(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.3 * rng.next(), 1.0, 0.0),
        DVec3::new(0.0, -0.2 * rng.next(), 0.8 + 0.4 * rng.next()),
    );
    let mut m = DMat3::from_quat(rot) * shear;
    if rng.next() < 0.3 {
        // A mirroring map.
        m *= DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
    }
    (half, DAffine3::from_mat3_translation(m, centre))
}

#[test]
fn boxes_match_their_triangles_the_reference_and_monte_carlo() {
    let mut rng = Mix(23);
    let mut s = RegionScratch::default();
    let (mut worst, mut mesh_worst, mut mc_worst) = (0.0f64, 0.0f64, 0.0f64);
    for case in 0..40 {
        let n = rng.unit();
        let x = DVec3::ZERO;
        let centre = n * (0.5 + 2.0 * rng.next()) + rng.unit() * 1.5;
        let (half, to_world) = skewed_box(centre, &mut rng);
        let to_object = to_world.inverse();
        if to_object.transform_point3(x).abs().cmplt(half).all() {
            continue;
        }
        let reach = [f64::INFINITY, 1.0 + 2.0 * rng.next()][case % 2];
        for w in both() {
            let mut regions = Regions::default();
            let b = blocked_by_box(x, n, half, &to_object, reach, &mut regions);
            assert_eq!(b, BoxBlocks::Faces);
            assert!(regions.len() <= 3, "{} faces face the point", regions.len());
            let got = covered_fraction_of_regions(n, &[], &regions, w, &mut s);
            // The same Box as a closed mesh of 12 triangles, every one of them an occluder.
            let mesh: Vec<Vec<DVec3>> = box_triangles(half, &to_world)
                .iter()
                .map(|t| t.to_vec())
                .collect();
            let as_mesh = exact_polys(&mesh, x, n, reach, w);
            mesh_worst = mesh_worst.max((got - as_mesh).abs());
            assert!(
                (got - as_mesh).abs() <= 1e-12,
                "case {case} {w:?}: the Box {got}, its 12 triangles {as_mesh}"
            );
            let occ = Occluders {
                boxes: vec![(half, to_world)],
                ..Occluders::default()
            };
            let (want, unconverged) = occ.reference(x, n, On::Nothing, reach, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "case {case} reach {reach} {w:?}: {got} against the reference's {want}"
            );
            if case % 5 == 0 {
                let solid = Solid::Cuboid { half };
                let (mc, se) = monte_carlo(n, w, 100_000, &mut rng, |d| {
                    let (o, dd) = (
                        to_object.transform_point3(x),
                        to_object.transform_vector3(d),
                    );
                    solid.blocks(o, dd, 0.0, reach)
                });
                mc_worst = mc_worst.max((got - mc).abs() / se.max(1e-300));
                assert!(
                    (got - mc).abs() <= 5.0 * se + 1e-12,
                    "case {case} {w:?}: {got} against Monte Carlo {mc} ± {se}"
                );
            }
        }
    }
    eprintln!(
        "Boxes: worst {worst:e} against the reference, {mesh_worst:e} against their 12 \
         triangles, {mc_worst:.2} standard errors against Monte Carlo"
    );
}

#[test]
fn inside_a_closed_box_nothing_of_the_sky_is_seen() {
    let mut rng = Mix(24);
    let (half, to_world) = skewed_box(DVec3::new(0.1, 0.0, -0.1), &mut rng);
    let occ = Occluders {
        boxes: vec![(half, to_world)],
        triangles: box_triangles(half * 1.5, &to_world),
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    for reach in [f64::INFINITY, 0.05] {
        for w in both() {
            let n = rng.unit();
            // Inside the Box: nothing, whatever the reach.
            let got = unoccluded(&prep, to_world.translation, n, None, (reach, w), &mut s);
            assert_eq!(got, 0.0, "inside the Box, reach {reach}");
        }
    }
    // Between the Box and the closed mesh around it: every direction meets one of them.
    let x = to_world.transform_point3(DVec3::new(half.x * 1.25, 0.0, 0.0));
    let n = to_world.matrix3.inverse().transpose() * DVec3::X;
    for w in both() {
        let got = unoccluded(&prep, x, n.normalize(), None, (f64::INFINITY, w), &mut s);
        assert!(got.abs() <= 1e-12, "between the Box and the mesh: {got}");
        // On the Box itself, the mesh around it closes the sky.
        let own = occ.own(&prep, On::Box(0));
        let on = to_world.transform_point3(DVec3::new(half.x, 0.1 * half.y, 0.0));
        let got = unoccluded(&prep, on, n.normalize(), own, (f64::INFINITY, w), &mut s);
        assert!(got.abs() <= 1e-12, "on the Box, inside the mesh: {got}");
    }
}

/// A flat square as 2 triangles, and a strip bent along its shared edges, seen from points
/// where neighbours lie side by side and where one hides behind another.
#[test]
fn tessellated_surfaces_count_their_shared_edges_once() {
    let mut rng = Mix(25);
    let (mut worst_square, mut worst_strip) = (0.0f64, 0.0f64);
    // The square and its two halves (both diagonals, both windings).
    let q = [
        DVec3::new(-0.7, -0.4, 1.0),
        DVec3::new(0.9, -0.6, 1.3),
        DVec3::new(1.1, 0.8, 1.1),
        DVec3::new(-0.5, 1.0, 0.8),
    ];
    for case in 0..40 {
        let x = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 0.4 * rng.next() - 0.2);
        let n = (DVec3::Z + rng.unit() * 0.8).normalize();
        let reach = [f64::INFINITY, 1.3][case % 2];
        let halves = match case % 4 {
            0 => vec![vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]],
            1 => vec![vec![q[1], q[2], q[3]], vec![q[1], q[3], q[0]]],
            2 => vec![vec![q[0], q[1], q[2]], vec![q[3], q[2], q[0]]],
            _ => vec![vec![q[2], q[1], q[0]], vec![q[3], q[0], q[2]]],
        };
        for w in both() {
            let whole = exact_polys(&[q.to_vec()], x, n, reach, w);
            let split = exact_polys(&halves, x, n, reach, w);
            worst_square = worst_square.max((whole - split).abs());
            assert!(
                (whole - split).abs() <= 1e-13,
                "case {case} {w:?}: the square {whole}, its halves {split}"
            );
            if reach.is_infinite() {
                let rel: Vec<DVec3> = q.iter().map(|p| *p - x).collect();
                let (cosine, uniform) = closed_forms(&rel, n);
                let want = if w == Weighting::Cosine {
                    cosine
                } else {
                    uniform
                };
                assert!((whole - want).abs() <= 1e-13, "{whole} against {want}");
            }
        }
    }
    // A strip of 8 triangles folded at its edges (a zigzag), seen from points in front of,
    // beside and behind it, so that some neighbours lie behind others.
    let strip: Vec<DVec3> = (0..10)
        .map(|i| {
            let f = i as f64;
            DVec3::new(
                0.5 * f - 2.0,
                if i % 2 == 0 { -0.6 } else { 0.6 },
                0.5 * (f * 1.3).sin(),
            )
        })
        .collect();
    let triangles: Vec<[DVec3; 3]> = (0..8)
        .map(|i| {
            // Alternating windings, as a strip's triangles come.
            if i % 2 == 0 {
                [strip[i], strip[i + 1], strip[i + 2]]
            } else {
                [strip[i + 1], strip[i], strip[i + 2]]
            }
        })
        .collect();
    let occ = Occluders {
        triangles: triangles.clone(),
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    let mut points = 0;
    for case in 0..60 {
        let x = DVec3::new(
            3.0 * rng.next() - 1.5,
            2.0 * rng.next() - 1.0,
            2.5 * rng.next() - 1.25,
        ) + DVec3::new(0.0, 0.0, if case % 3 == 0 { 2.0 } else { 0.0 });
        let n = rng.unit();
        let reach = [f64::INFINITY, 1.5, 0.8][case % 3];
        for w in both() {
            let got = 1.0 - unoccluded(&prep, x, n, None, (reach, w), &mut s);
            let (want, unconverged) = occ.reference(x, n, On::Nothing, reach, w);
            assert_eq!(unconverged, 0);
            worst_strip = worst_strip.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "strip point {case} at {x} reach {reach} {w:?}: {got} against {want}"
            );
            points += 1;
        }
    }
    assert_eq!(points, 120);
    eprintln!(
        "tessellated: worst {worst_square:e} square against its halves, {worst_strip:e} \
         strip against the reference"
    );
}

/// Points on the floor (two triangles) near a sphere resting above it, and a triangle
/// standing at a concave crease: each against its closed form.
#[test]
fn a_point_on_a_triangle_sees_its_neighbours() {
    let floor = [
        [
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, -5.0, 0.0),
            DVec3::new(5.0, 5.0, 0.0),
        ],
        [
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, 5.0, 0.0),
            DVec3::new(-5.0, 5.0, 0.0),
        ],
    ];
    let wall = [
        DVec3::new(-1.0, 2.0, 0.0),
        DVec3::new(1.0, 2.0, 0.0),
        DVec3::new(0.0, 2.5, 1.5),
    ];
    let ball = (DVec3::new(0.3, -0.2, 1.2), 1.0);
    let occ = Occluders {
        spheres: vec![ball],
        triangles: vec![floor[0], floor[1], wall],
        ..Occluders::default()
    };
    let prep = occ.prepared();
    let mut s = AoScratch::default();
    let mut rng = Mix(26);
    let mut worst = 0.0f64;
    for k in 0..200 {
        // On either half of the floor (the seam included), away from the wall's foot.
        let x = DVec3::new(4.0 * rng.next() - 2.0, 3.0 * rng.next() - 2.5, 0.0);
        let x = if k == 0 {
            DVec3::new(0.25, 0.25, 0.0)
        } else {
            x
        };
        let on = if x.x >= x.y { 0 } else { 1 };
        let own = occ.own(&prep, On::Triangle(on));
        for w in both() {
            let got = 1.0 - unoccluded(&prep, x, DVec3::Z, own, (f64::INFINITY, w), &mut s);
            // The sphere's cap and the wall's triangle: apart or not, against the reference;
            // where the wall is below the horizon or hidden, the cap alone.
            let (want, unconverged) =
                occ.reference(x, DVec3::Z, On::Triangle(on), f64::INFINITY, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "floor point {x} {w:?}: {got} against {want}"
            );
        }
        // Cosine-weighted with the wall and the ball apart, the sum of their closed forms.
        let Blocked::Cap(cap) = blocked_by_ball(x, ball.0, ball.1, f64::INFINITY) else {
            panic!("a cap")
        };
        let rel: Vec<DVec3> = wall.iter().map(|p| *p - x).collect();
        let wall_ff = closed_forms(&rel, DVec3::Z).0;
        let cap_ff = one_cap(cap.axis.z, cap.axis.truncate().length(), cap.cos);
        let apart = {
            let mut r = Regions::default();
            blocked_by_polygon(x, DVec3::Z, &wall, f64::INFINITY, &mut r);
            let b = r.bound(0);
            b.axis.dot(cap.axis).acos() > b.angle + cap.cos.acos()
        };
        if apart {
            let got = 1.0
                - unoccluded(
                    &prep,
                    x,
                    DVec3::Z,
                    own,
                    (f64::INFINITY, Weighting::Cosine),
                    &mut s,
                );
            worst = worst.max((got - (wall_ff + cap_ff)).abs());
            assert!((got - (wall_ff + cap_ff)).abs() <= 1e-13, "{x}: {got}");
        }
    }
    // On the wall, facing the floor's side: the floor rises in front of it (a concave crease
    // at its foot) and the ball stands beside it.
    let g = (wall[1] - wall[0]).cross(wall[2] - wall[0]).normalize();
    let g = if g.y > 0.0 { -g } else { g };
    for k in 0..40 {
        let (a, b) = (rng.next(), rng.next());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let x = wall[0] + (wall[1] - wall[0]) * a + (wall[2] - wall[0]) * b;
        for w in both() {
            let own = occ.own(&prep, On::Triangle(2));
            let got = 1.0 - unoccluded(&prep, x, g, own, (f64::INFINITY, w), &mut s);
            let (want, unconverged) = occ.reference(x, g, On::Triangle(2), f64::INFINITY, w);
            assert_eq!(unconverged, 0);
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() <= 1e-12,
                "wall point {k} {w:?}: {got} against {want}"
            );
        }
    }
    eprintln!("points on triangles: worst {worst:e}");
}

/// Random scenes of spheres, triangles (a loose mesh and stray ones) and Boxes, with points
/// on each kind, every reach and weighting, against the reference.
#[test]
fn random_mixed_scenes_match_the_reference() {
    let mut rng = Mix(27);
    let (mut worst, mut points) = (0.0f64, 0usize);
    for scene in 0..6 {
        let spheres = super::tests::packing(&mut rng, 14);
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
        for i in 0..3 {
            for j in 0..3 {
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
        integrator: Integrator::Ao(super::AoSettings {
            reach,
            weighting,
            ..super::AoSettings::default()
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
        let spheres = super::tests::packing(&mut rng, 10);
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
        for i in 0..2 {
            for j in 0..2 {
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
    for i in 0..4 {
        for j in 0..4 {
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
