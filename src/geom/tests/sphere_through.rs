//! `sphere_through` on point sets given directly: tessellated spheres at any place and
//! scale, Jmol's three-decimal vertices, and shapes that are not spheres.

use glam::DVec3;

use crate::geom::fit::sphere_through;
use crate::testing::{icosahedron, uv_sphere};

fn flat(v: &[DVec3]) -> Vec<f64> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

#[test]
fn icosahedron_and_uv_sphere_are_spheres_at_any_place_and_scale() {
    for (c, r) in [
        (DVec3::ZERO, 1.0),
        (DVec3::new(3.0, -2.0, 7.5), 0.25),
        (DVec3::new(-1e4, 2e4, 0.5), 1e3),
        (DVec3::new(1e-3, 0.0, -1e-3), 1e-4),
    ] {
        for shape in [icosahedron(), uv_sphere(7, 12, std::f64::consts::PI)] {
            let pts: Vec<_> = shape.iter().map(|p| c + r * *p).collect();
            let (c2, r2) = sphere_through(&flat(&pts)).expect("a sphere");
            assert!((c2 - c).length() <= 1e-12 * (r + c.length()), "{c2} vs {c}");
            assert!((r2 - r).abs() <= 1e-12 * r, "{r2} vs {r}");
        }
    }
}

#[test]
fn three_decimal_vertices_are_a_sphere() {
    // As Jmol writes them: each coordinate rounded to three decimals.
    let pts: Vec<_> = uv_sphere(9, 16, std::f64::consts::PI)
        .into_iter()
        .map(|p| (p * 1000.0).round() / 1000.0)
        .collect();
    let (c, r) = sphere_through(&flat(&pts)).expect("a sphere");
    assert!(c.length() < 1e-3 && (r - 1.0).abs() < 1e-3);
}

#[test]
fn other_shapes_are_not_spheres() {
    let pi = std::f64::consts::PI;
    let cube: Vec<_> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
        .collect();
    // A cube subdivided: its 26 surface lattice points (not equidistant from the centre).
    let mut cube26 = Vec::new();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    cube26.push(DVec3::new(x as f64, y as f64, z as f64));
                }
            }
        }
    }
    // A flat disk's rim (all equidistant from its centre) and a regular 20-gon.
    let circle: Vec<_> = (0..20)
        .map(|j| {
            let ph = std::f64::consts::TAU * j as f64 / 20.0;
            DVec3::new(ph.cos(), ph.sin(), 0.0)
        })
        .collect();
    // A cylinder's two rims (Jmol's bond mesh): equidistant from the centre too.
    let cylinder: Vec<_> = circle
        .iter()
        .flat_map(|p| [*p + 0.5 * DVec3::Z, *p - 0.5 * DVec3::Z])
        .collect();
    let hemisphere = uv_sphere(6, 12, pi / 2.0 + 1e-9);
    // A sphere with a cap missing (everything within 60 degrees of the south pole).
    let capless = uv_sphere(8, 12, pi / 3.0 * 2.0);
    let ellipsoid: Vec<_> = uv_sphere(7, 12, pi)
        .into_iter()
        .map(|p| p * DVec3::new(1.0, 1.0, 1.01))
        .collect();
    let mut with_nan = icosahedron();
    with_nan[3].x = f64::NAN;
    for (name, pts) in [
        ("cube", cube),
        ("cube26", cube26),
        ("circle", circle),
        ("cylinder", cylinder),
        ("hemisphere", hemisphere),
        ("capless", capless),
        ("ellipsoid", ellipsoid),
        ("nan", with_nan),
        ("eleven", icosahedron()[..11].to_vec()),
    ] {
        assert_eq!(sphere_through(&flat(&pts)), None, "{name}");
    }
    assert_eq!(sphere_through(&[0.0; 37]), None);
    assert_eq!(sphere_through(&[1.0; 36]), None, "one point repeated");
}
