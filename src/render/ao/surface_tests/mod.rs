//! Exact AO among triangles and Boxes against independent answers: the closed forms of one
//! polygon (its solid angle by Van Oosterom and Strackee, its cosine-weighted share by
//! Lambert's edge sum, both after clipping it to the horizon), the reference's quadrature
//! that meets each triangle along each meridian (`reference::covered_with_triangles`), and
//! Monte Carlo over rays with a stated confidence.

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::cap::{blocked_by_ball, form_factor as one_cap, Blocked};
use super::polygon::{blocked_by_box, blocked_by_polygon, BoxBlocks};
use super::tests::unoccluded;
use super::tests::Mix;
use super::union::{covered_fraction_of_regions, RegionScratch, Regions, Weighting};
use super::AoScratch;
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

mod meshes;
mod scenes;
