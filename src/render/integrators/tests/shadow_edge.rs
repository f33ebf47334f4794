//! The surface integrator ray by ray against geometry: where a shadow's edge lies on a lit
//! sphere, from the blocker's shadow cylinder.

use glam::DVec3;

use crate::render::integrators::surface;
use crate::render::visibility::Blockers;
use crate::render::{Counters, RenderOptions, SamplerKind};
use crate::testing as support;

const CAM: &str =
    "Viewpoint { position 0 0 5 fieldOfView 0.6 }\nNavigationInfo { headlight FALSE }\n";

fn sphere_shape(material: &str) -> String {
    format!("Shape {{ appearance Appearance {{ material Material {{ {material} }} }} geometry Sphere {{ radius 1 }} }}")
}

/// Textbook ray/sphere: nearest root in front of the origin (all test geometry is benign).
fn hit(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<f64> {
    let f = o - c;
    let b = f.dot(d);
    let disc = b * b - (f.dot(f) - r * r);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 0.0).then_some(t)
}

/// Points on the receiver just inside and just outside the blocker's shadow cylinder (the
/// light line passes within r_B (1 -+ 1e-9) of the blocker's centre) are dark and lit.
#[test]
fn shadow_edge_lies_where_geometry_puts_it() {
    let opts = RenderOptions {
        width: 8,
        height: 8,
        spp: 1,
        sampler: SamplerKind::Center,
        ..RenderOptions::default()
    };
    let body = format!(
        "{CAM}DirectionalLight {{ direction -1 0 0 }}\n{}\nTransform {{ translation 2 0.3 0.2 children Shape {{ appearance Appearance {{ material Material {{ }} }} geometry Sphere {{ radius 0.5 }} }} }}",
        sphere_shape("diffuseColor 1 1 1 ambientIntensity 0")
    );
    let prep = support::prepare(support::scene(&body).0);
    let view = support::view(&prep, &opts);
    let (cb, rb) = (DVec3::new(2.0, 0.3, 0.2), 0.5);
    let l = DVec3::X;
    // Distance from the blocker's centre to the light line through x (x's y, z vs the centre's).
    let gap = |x: DVec3| ((x.y - cb.y).powi(2) + (x.z - cb.z).powi(2)).sqrt() - rb;
    let mut checked = 0;
    // Kept from ray to ray, as the renderer keeps it from pixel to pixel: the blocker found
    // for a point just inside the shadow is tried first for the point just outside.
    let mut blockers = Blockers::default();
    for k in 0..40 {
        // Walk along a meridian of the receiver's lit side (x > 0) and bisect for the edge.
        let phi = 0.3 + 0.05 * k as f64;
        let on = |theta: f64| {
            DVec3::new(
                theta.cos(),
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin() + 0.0,
            )
        };
        let (mut a, mut b) = (0.0f64, 1.4f64);
        if gap(on(a)).signum() == gap(on(b)).signum() {
            continue;
        }
        for _ in 0..200 {
            let m = 0.5 * (a + b);
            if gap(on(m)).signum() == gap(on(a)).signum() {
                a = m;
            } else {
                b = m;
            }
        }
        let edge = 0.5 * (a + b);
        let o = DVec3::new(0.0, 0.0, 5.0);
        let xe = on(edge);
        let de = (xe - o).normalize();
        // Only edge points the camera sees on the receiver, on its lit side.
        if hit(o, de, cb, rb).is_some_and(|tb| tb < (xe - o).length()) || xe.dot(l) <= 1e-3 {
            continue;
        }
        let mut sides = [false; 2];
        for off in [-1e-9, 1e-9] {
            // 1e-9 rad off the edge: |gap| ~ 1e-9, far above the test's own rounding (~1e-16).
            let x = on(edge + off);
            let inside = gap(x) < 0.0;
            let d = (x - o).normalize();
            let mut c = Counters::default();
            let e = surface::radiance(&view, o, d, &mut blockers, &mut c);
            let want = if inside { 0.0 } else { x.dot(l) };
            assert!(
                (e.value.x - want).abs() < 1e-6,
                "phi {phi}: gap {:e}, got {} want {want}",
                gap(x),
                e.value.x
            );
            sides[usize::from(inside)] = true;
            checked += 1;
        }
        assert!(sides[0] && sides[1], "both sides of the edge at phi {phi}");
    }
    assert!(checked > 20, "checked {checked}");
}
