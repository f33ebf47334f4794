//! Cylinders, cones, boxes and triangles against the VRML97 lighting equation evaluated here,
//! pixel by pixel, with the test's own intersections (`surface_reference`), own camera rays
//! and own shadow tests: each surface alone under a directional and a point light, a
//! cylinder shadowing a sphere, a sphere shadowing a triangle, a triangle between a gas
//! sphere and its light, and a triangle that stops a gas ray.

use glam::{DAffine3, DVec3};
use gtsphere::render::{Integrator, RenderOptions};

use crate::render_opaque::{center_opts, pixel_ray, vrml_term, Mat};
use crate::support;
use crate::surface_reference::{blocks, first_hit, trs, RefShape};

const EYE: DVec3 = DVec3::new(0.0, 0.0, 6.0);
const FOV: f64 = 0.7;
const VIEW: &str =
    "NavigationInfo { headlight FALSE }\nViewpoint { position 0 0 6 fieldOfView 0.7 }\n";

/// The two lights of every case, as VRML and as the reference uses them.
const LIGHTS: &str = "DirectionalLight { direction -1 -2 -3 color 1 0.9 0.8 intensity 0.8 ambientIntensity 0.3 }\n\
PointLight { location 3 4 5 color 0.9 1 1 intensity 0.9 ambientIntensity 0.2 attenuation 1 0.1 0.01 }\n";

const MATERIAL: &str = "Material { diffuseColor 0.7 0.5 0.3 specularColor 0.4 0.4 0.4 shininess 0.3 ambientIntensity 0.25 emissiveColor 0.05 0 0 }";

fn mat() -> Mat {
    Mat {
        diffuse: DVec3::new(0.7, 0.5, 0.3),
        emissive: DVec3::new(0.05, 0.0, 0.0),
        specular: DVec3::splat(0.4),
        shininess: 0.3,
        ambient: 0.25,
    }
}

/// One light as the reference sees it at `x`: direction towards it, distance, attenuation,
/// colour, intensity, ambient intensity.
fn lights_at(x: DVec3) -> [(DVec3, f64, f64, DVec3, f64, f64); 2] {
    let dir = -DVec3::new(-1.0, -2.0, -3.0).normalize();
    let p = DVec3::new(3.0, 4.0, 5.0);
    let dist = (p - x).length();
    let att = 1.0 / (1.0 + 0.1 * dist + 0.01 * dist * dist).max(1.0);
    [
        (dir, f64::INFINITY, 1.0, DVec3::new(1.0, 0.9, 0.8), 0.8, 0.3),
        (
            (p - x) / dist,
            dist,
            att,
            DVec3::new(0.9, 1.0, 1.0),
            0.9,
            0.2,
        ),
    ]
}

/// Radiance at `x` with normal `n` seen along `d`; `shadowed(x, l, dist)` is the reference's
/// shadow test (`None`: too close to a shadow edge to say).
fn radiance(
    m: &Mat,
    x: DVec3,
    n: DVec3,
    d: DVec3,
    shadowed: impl Fn(DVec3, DVec3, f64) -> Option<bool>,
) -> Option<DVec3> {
    let mut sum = m.emissive;
    for (l, dist, att, color, intensity, ambient) in lights_at(x) {
        // Its own far side (N.L <= 0), or something in the way.
        let dark = n.dot(l) <= 0.0 || shadowed(x, l, dist)?;
        let vis = if dark { 0.0 } else { 1.0 };
        sum += vrml_term(m, n, -d, l, color, intensity, ambient, att, vis);
    }
    Some(sum)
}

fn rendered(body: &str, opts: RenderOptions) -> Vec<[f64; 3]> {
    let (scene, report) = support::scene(body);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    support::render_auto(scene, &opts).rgb
}

/// Compares every pixel whose expectation is known with the render, to `rel`; returns how
/// many were compared and how many of them were covered.
fn compare(
    got: &[[f64; 3]],
    w: u32,
    h: u32,
    rel: f64,
    expect: impl Fn(DVec3, DVec3) -> Option<Option<DVec3>>,
) -> (usize, usize) {
    let (mut compared, mut covered) = (0, 0);
    for j in 0..h {
        for i in 0..w {
            let (o, d) = pixel_ray(EYE, FOV, w, h, i, j);
            let Some(want) = expect(o, d) else {
                continue;
            };
            compared += 1;
            let want = want.map_or(DVec3::ZERO, |c| {
                covered += 1;
                c
            });
            let g = DVec3::from_array(got[(j * w + i) as usize]);
            for k in 0..3 {
                assert!(
                    (g[k] - want[k]).abs() <= rel * (1e-3 + want[k].abs()),
                    "pixel ({i},{j}) channel {k}: got {g}, want {want}"
                );
            }
        }
    }
    (compared, covered)
}

/// `(shape, object-to-world, VRML geometry)` for each solid case, under one Transform.
fn solid_cases() -> Vec<(&'static str, RefShape, &'static str)> {
    vec![
        (
            "cylinder",
            RefShape::Cylinder { r: 0.8, h: 1.6 },
            "Cylinder { radius 0.8 height 1.6 }",
        ),
        (
            "cone",
            RefShape::Cone { r: 0.9, h: 1.8 },
            "Cone { bottomRadius 0.9 height 1.8 }",
        ),
        (
            "box",
            RefShape::Cuboid {
                size: DVec3::new(1.2, 0.9, 1.5),
            },
            "Box { size 1.2 0.9 1.5 }",
        ),
    ]
}

#[test]
fn each_solid_alone_matches_the_lighting_equation() {
    let (w, h) = (64, 48);
    let m = trs(
        DVec3::new(0.2, -0.1, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        0.7,
        DVec3::new(1.0, 1.5, 0.8),
    );
    for (name, shape, vrml) in solid_cases() {
        let body = format!(
            "{VIEW}{LIGHTS}Transform {{ translation 0.2 -0.1 0 rotation 1 1 0 0.7 scale 1 1.5 0.8 \
             children Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry {vrml} }} }}"
        );
        let got = rendered(&body, center_opts(w, h));
        let (compared, covered) =
            compare(&got, w, h, 1e-9, |o, d| match first_hit(&shape, &m, o, d) {
                None => Some(None),
                Some(hit) if hit.margin < 1e-7 => None,
                // A convex solid alone: its only shadow is its own (N.L <= 0).
                Some(hit) => {
                    radiance(&mat(), o + hit.t * d, hit.n, d, |_, _, _| Some(false)).map(Some)
                }
            });
        assert!(covered > 250, "{name}: {covered} pixels on it");
        assert!(
            compared > w as usize * h as usize * 9 / 10,
            "{name}: only {compared} compared"
        );
    }
}

#[test]
fn a_triangle_alone_matches_the_lighting_equation_from_both_sides() {
    let (w, h) = (64, 48);
    let p = [
        DVec3::new(-1.5, -1.0, 0.2),
        DVec3::new(1.4, -0.8, -0.3),
        DVec3::new(0.1, 1.3, 0.4),
    ];
    for (order, front) in [("0 1 2", true), ("0 2 1", false)] {
        let body = format!(
            "{VIEW}{LIGHTS}Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry IndexedFaceSet {{ solid FALSE \
             coord Coordinate {{ point [ -1.5 -1 0.2, 1.4 -0.8 -0.3, 0.1 1.3 0.4 ] }} coordIndex [ {order} -1 ] }} }}"
        );
        let got = rendered(&body, center_opts(w, h));
        let shape = RefShape::Triangle { p };
        let (_, covered) = compare(&got, w, h, 1e-9, |o, d| {
            match first_hit(&shape, &DAffine3::IDENTITY, o, d) {
                None => Some(None),
                Some(hit) if hit.margin < 1e-7 => None,
                // Two-sided: the normal faces the viewer, whichever way the face winds.
                Some(hit) => {
                    radiance(&mat(), o + hit.t * d, hit.n, d, |_, _, _| Some(false)).map(Some)
                }
            }
        });
        assert!(covered > 300, "front {front}: {covered} pixels on it");
    }
}

/// Whether the segment from `x` towards `l` (length `dist`) is blocked by `shape`, or `None`
/// when the primitive grown or shrunk by 1e-7 about its centre answers otherwise.
fn robust_blocks(shape: &RefShape, m: &DAffine3, x: DVec3, l: DVec3, dist: f64) -> Option<bool> {
    let grown = *m * DAffine3::from_scale(DVec3::splat(1.0 + 1e-7));
    let shrunk = *m * DAffine3::from_scale(DVec3::splat(1.0 - 1e-7));
    let smax = dist.min(1e6);
    let (a, b) = (
        blocks(shape, &grown, x, l, smax),
        blocks(shape, &shrunk, x, l, smax),
    );
    (a == b).then_some(a)
}

/// The unit sphere at the origin against `o + t d`: `(t, normal)`.
fn unit_sphere(o: DVec3, d: DVec3) -> Option<(f64, DVec3, f64)> {
    let b = o.dot(d);
    let disc = b * b - (o.dot(o) - 1.0);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 0.0).then(|| (t, (o + t * d).normalize(), disc))
}

/// Whether the unit sphere blocks `x + s l`, `s` in `(0, dist)` (None near tangency).
fn sphere_blocks(x: DVec3, l: DVec3, dist: f64) -> Option<bool> {
    let b = x.dot(l);
    let disc = b * b - (x.dot(x) - 1.0);
    if disc.abs() < 1e-7 {
        return None;
    }
    Some(
        disc > 0.0 && {
            let t0 = -b - disc.sqrt();
            t0 > 1e-9 && t0 < dist
        },
    )
}

/// A sphere and a surface together: the nearest of the two seen, each shadowing the other.
fn sphere_and_surface(name: &str, shape: RefShape, m: DAffine3, vrml: &str) {
    let (w, h) = (64, 48);
    let body = format!(
        "{VIEW}{LIGHTS}Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry Sphere {{ radius 1 }} }}\n{vrml}"
    );
    let got = rendered(&body, center_opts(w, h));
    let counter = std::cell::Cell::new((0usize, 0usize));
    let (compared, covered) = compare(&got, w, h, 1e-9, |o, d| {
        let s = unit_sphere(o, d);
        let f = first_hit(&shape, &m, o, d);
        if s.is_some_and(|s| s.2 < 1e-7) || f.is_some_and(|f| f.margin < 1e-7) {
            return None;
        }
        match (s, f) {
            (None, None) => Some(None),
            (Some((ts, n, _)), f) if f.is_none_or(|f| f.t > ts) => {
                let x = o + ts * d;
                let v = radiance(&mat(), x, n, d, |x, l, dist| {
                    let b = robust_blocks(&shape, &m, x, l, dist)?;
                    let (a, c) = counter.get();
                    counter.set(if b { (a + 1, c) } else { (a, c + 1) });
                    Some(b)
                })?;
                Some(Some(v))
            }
            (_, Some(f)) => {
                let x = o + f.t * d;
                radiance(&mat(), x, f.n, d, sphere_blocks).map(Some)
            }
            (Some(_), None) => unreachable!("the sphere's arm takes it"),
        }
    });
    let (shadowed, lit) = counter.get();
    assert!(
        covered > 500 && compared > 2500,
        "{name}: {covered} covered, {compared} compared"
    );
    assert!(
        shadowed > 30 && lit > 30,
        "{name}: the shadow must fall on the sphere ({shadowed} shadowed, {lit} lit light rays)"
    );
}

#[test]
fn a_cylinder_shadows_a_sphere() {
    // A bar above the sphere, across the point light's and the directional light's rays.
    let m = trs(
        DVec3::new(0.6, 1.5, 1.2),
        DVec3::new(1.0, 0.0, -1.0),
        1.2,
        DVec3::ONE,
    );
    sphere_and_surface(
        "cylinder",
        RefShape::Cylinder { r: 0.3, h: 3.0 },
        m,
        &format!(
            "Transform {{ translation 0.6 1.5 1.2 rotation 1 0 -1 1.2 children Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry Cylinder {{ radius 0.3 height 3 }} }} }}"
        ),
    );
}

#[test]
fn a_sphere_shadows_a_triangle() {
    // A large floor triangle below and behind the sphere, facing up; the sphere's shadow
    // from both lights falls on it (the shadowed light rays are counted on its points).
    let (w, h) = (64, 48);
    let p = [
        DVec3::new(-6.0, -1.3, 3.0),
        DVec3::new(6.0, -1.3, 3.0),
        DVec3::new(0.0, -2.5, -8.0),
    ];
    let shape = RefShape::Triangle { p };
    let body = format!(
        "{VIEW}{LIGHTS}Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry Sphere {{ radius 1 }} }}\n\
         Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry IndexedFaceSet {{ coord Coordinate {{ point [ -6 -1.3 3, 6 -1.3 3, 0 -2.5 -8 ] }} coordIndex [ 0 1 2 ] }} }}"
    );
    let got = rendered(&body, center_opts(w, h));
    let counter = std::cell::Cell::new((0usize, 0usize));
    let (_, covered) = compare(&got, w, h, 1e-9, |o, d| {
        let s = unit_sphere(o, d);
        let f = first_hit(&shape, &DAffine3::IDENTITY, o, d);
        if s.is_some_and(|s| s.2 < 1e-7) || f.is_some_and(|f| f.margin < 1e-7) {
            return None;
        }
        match (s, f) {
            (None, None) => Some(None),
            (Some((ts, n, _)), f) if f.is_none_or(|f| f.t > ts) => {
                radiance(&mat(), o + ts * d, n, d, |_, _, _| Some(false)).map(Some)
            }
            (_, Some(f)) => {
                // The triangle is solid (the default) and seen from above: its front.
                let v = radiance(&mat(), o + f.t * d, f.n, d, |x, l, dist| {
                    let b = sphere_blocks(x, l, dist)?;
                    let (a, c) = counter.get();
                    counter.set(if b { (a + 1, c) } else { (a, c + 1) });
                    Some(b)
                })?;
                Some(Some(v))
            }
            (Some(_), None) => unreachable!("the sphere's arm takes it"),
        }
    });
    let (shadowed, lit) = counter.get();
    assert!(covered > 1000, "{covered} covered");
    assert!(
        shadowed > 30 && lit > 30,
        "{shadowed} shadowed, {lit} lit light rays on the floor"
    );
}

/// Simpson's rule on `n` (even) panels.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for k in 1..n {
        s += f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

#[test]
fn a_triangle_between_a_gas_sphere_and_its_light_shadows_the_gas_exactly() {
    // Gas sphere at the origin (radius 1, transparency 0.3, albedo 0.8), a directional light
    // straight down, and an opaque triangle in the plane y = 1.5 covering x < 0: the half of
    // the gas with x < 0 gets no light. The reference integrates single scattering along each
    // camera ray with the shadow edge (x = 0) found in closed form and Simpson's rule on
    // each smooth piece. The triangle faces up and is solid: the camera, below it, does not
    // see it, but it blocks the light all the same.
    let (w, h) = (40, 40);
    let body = format!(
        "{VIEW}DirectionalLight {{ direction 0 -1 0 intensity 1 }}\n\
         Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0.8 0.8 0.8 transparency 0.3 }} }} geometry Sphere {{ radius 1 }} }}\n\
         Shape {{ appearance Appearance {{ material {MATERIAL} }} geometry IndexedFaceSet {{ coord Coordinate {{ point [ 0 1.5 -10, 0 1.5 10, -10 1.5 0 ] }} coordIndex [ 0 2 1 ] }} }}"
    );
    let opts = RenderOptions {
        integrator: Integrator::Exact,
        tol: 1e-7,
        ..center_opts(w, h)
    };
    let got = rendered(&body, opts);
    let sigma = -(0.3f64).ln() / 2.0;
    let albedo = 0.8;
    let phase = 0.25 / std::f64::consts::PI;
    let (dark, lit) = (std::cell::Cell::new(0), std::cell::Cell::new(0));
    let (_, covered) = compare(&got, w, h, 1e-6, |o, d| {
        let b = o.dot(d);
        let disc = b * b - (o.dot(o) - 1.0);
        if disc <= 1e-6 {
            return Some(None).filter(|_| disc < -1e-6);
        }
        let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
        let source = |t: f64| {
            let x = o + t * d;
            // Light from above: through the gas up to the sphere's surface, unless the
            // triangle (y = 1.5, x < 0) is in the way.
            if x.x < 0.0 {
                return 0.0;
            }
            let up = ((1.0 - x.x * x.x - x.z * x.z).max(0.0)).sqrt() - x.y;
            (-sigma * (t - t0)).exp() * sigma * albedo * phase * (-sigma * up.max(0.0)).exp()
        };
        // The shadow edge along the ray: x(t).x = 0.
        let mut cuts = vec![t0, t1];
        if d.x != 0.0 {
            let te = -o.x / d.x;
            if te > t0 && te < t1 {
                if (te - t0).min(t1 - te) < 1e-9 {
                    return None;
                }
                cuts.insert(1, te);
            }
        }
        let v: f64 = cuts
            .windows(2)
            .map(|c| simpson(source, c[0], c[1], 4000))
            .sum();
        let count = if v == 0.0 { &dark } else { &lit };
        count.set(count.get() + 1);
        Some(Some(DVec3::splat(v)))
    });
    assert!(covered > 150, "{covered} pixels on the gas");
    assert!(
        dark.get() > 20 && lit.get() > 20,
        "both halves: {} dark, {} lit",
        dark.get(),
        lit.get()
    );
}

#[test]
fn a_triangle_stops_a_gas_ray() {
    // An unlit white triangle through the centre of a glowing gas sphere, facing the camera:
    // a ray sees the gas in front of it, then the triangle behind that gas,
    // C (1 - exp(-sigma l)) + exp(-sigma l) * 1.
    let (w, h) = (24, 24);
    let body = format!(
        "{VIEW}Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0 0 0 emissiveColor 0.6 0.3 0.1 transparency 0.2 }} }} geometry Sphere {{ radius 1 }} }}\n\
         Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ -3 -3 0, 3 -3 0, 0 4 0 ] }} coordIndex [ 0 1 2 ] }} }}"
    );
    let got = rendered(&body, center_opts(w, h));
    let sigma = -(0.2f64).ln() / 2.0;
    let c = DVec3::new(0.6, 0.3, 0.1);
    let shape = RefShape::Triangle {
        p: [
            DVec3::new(-3.0, -3.0, 0.0),
            DVec3::new(3.0, -3.0, 0.0),
            DVec3::new(0.0, 4.0, 0.0),
        ],
    };
    let (_, covered) = compare(&got, w, h, 1e-9, |o, d| {
        let tri = first_hit(&shape, &DAffine3::IDENTITY, o, d)?;
        let b = o.dot(d);
        let disc = b * b - (o.dot(o) - 1.0);
        if disc.abs() < 1e-7 {
            return None;
        }
        // The gas in front of the triangle: from the sphere's entry to the triangle or to
        // the sphere's exit, whichever comes first.
        let l = if disc > 0.0 {
            (tri.t.min(-b + disc.sqrt()) - (-b - disc.sqrt())).max(0.0)
        } else {
            0.0
        };
        let tr = (-sigma * l).exp();
        Some(Some(c * (1.0 - tr) + DVec3::splat(tr)))
    });
    assert!(covered > 300, "{covered}");
}
