//! Numerical hard cases, each with its expected value stated here.

use crate::output::Image;
use crate::render::integrators::{self, Scratch};
use crate::render::sampler::Rng;
use crate::render::{self, Counters, PrepareOptions, Prepared, RenderOptions, SamplerKind};
use glam::DVec3;

use crate::testing as support;

fn prep(body: &str) -> Prepared {
    let (scene, _) = support::scene(&format!("NavigationInfo {{ headlight FALSE }}\n{body}"));
    support::prepare(scene)
}

/// The radiance along one ray, as a default render of `p` would compute it.
fn ray(p: &Prepared, o: DVec3, w: DVec3) -> DVec3 {
    let e = integrators::radiance(
        &support::view(p, &RenderOptions::default()),
        o,
        w,
        &mut Rng::new(0, 0),
        &mut Scratch::default(),
        &mut Counters::default(),
    );
    assert!(e.value.is_finite());
    e.value
}

fn unlit_at(c: DVec3, r: f64) -> String {
    format!(
        "Transform {{ translation {} {} {} children Shape {{ geometry Sphere {{ radius {r} }} }} }}\n",
        c.x, c.y, c.z
    )
}

fn gas_at(c: DVec3, r: f64, tr: f64) -> String {
    format!(
        "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ emissiveColor 1 1 1 diffuseColor 0 0 0 transparency {tr} }} }} geometry Sphere {{ radius {r} }} }} }}\n",
        c.x, c.y, c.z
    )
}

/// Tiny and huge spheres, and a small sphere far away: the ray through the centre sees the
/// unlit sphere (value exactly 1), rays 1e-9 (relative) outside its rim see the background.
#[test]
fn tiny_huge_and_far_spheres() {
    for (r, dist) in [(1e-6, 1e-5), (1e6, 1e7), (1e-3, 1e5)] {
        let c = DVec3::new(0.3 * r, -0.2 * r, 0.0);
        let p = prep(&format!(
            "Background {{ skyColor 0 0 0.5 }}\n{}",
            unlit_at(c, r)
        ));
        let o = c + DVec3::new(0.0, 0.0, dist);
        assert_eq!(ray(&p, o, DVec3::NEG_Z), DVec3::ONE, "r {r}");
        // Rays along -z passing r (1 -+ 1e-9) from the centre: just inside and outside the rim.
        for (k, want) in [
            (1.0 - 1e-9, DVec3::ONE),
            (1.0 + 1e-9, DVec3::new(0.0, 0.0, 0.5)),
        ] {
            let o = c + DVec3::new(r * k, 0.0, dist);
            assert_eq!(ray(&p, o, DVec3::NEG_Z), want, "r {r} k {k}");
        }
    }
}

fn render_center(body: &str, w: u32, h: u32) -> Image {
    let (scene, _) = support::scene(body);
    let opts = RenderOptions {
        width: w,
        height: h,
        sampler: SamplerKind::Center,
        spp: 1,
        ..RenderOptions::default()
    };
    support::render_auto(scene, &opts).image()
}

/// The cluster sample translated by 1e7 (camera, lights and spheres) gives the same picture
/// to 1e-6 per pixel: all geometry is relative in f64 and the BVH recentres before f32.
#[test]
fn scene_translated_by_1e7_renders_the_same() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/samples/cluster.wrl"))
        .unwrap();
    let body = text.trim_start_matches("#VRML V2.0 utf8");
    let a = render_center(&format!("#VRML V2.0 utf8\n{body}"), 64, 48);
    let b = render_center(
        &format!("#VRML V2.0 utf8\nTransform {{ translation 1e7 -1e7 1e7 children [\n{body}\n] }}"),
        64,
        48,
    );
    let mut max: f32 = 0.0;
    for (p, q) in a.rgb.iter().zip(&b.rgb) {
        for k in 0..3 {
            max = max.max((p[k] - q[k]).abs());
        }
    }
    assert!(max < 1e-6, "max pixel difference {max:e}");
    assert!(a.alpha.iter().sum::<f32>() > 500.0);
}

/// 1000 concentric gas spheres of one colour: the ray through the centre sees
/// C (1 - exp(-sum sigma_j 2 r_j)).
#[test]
fn a_thousand_concentric_gas_spheres() {
    let mut body = String::new();
    let mut tau = 0.0;
    for k in 1..=1000 {
        let r = k as f64 * 1e-3;
        let tr = 0.999;
        body.push_str(&gas_at(DVec3::ZERO, r, tr));
        tau += -f64::ln(tr); // sigma_j * 2 r_j
    }
    let p = prep(&body);
    let got = ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
    let want = 1.0 - (-tau).exp();
    assert!((got.x - want).abs() < 1e-12, "{got} vs {want}");
}

/// The camera inside a gas sphere sees C (1 - exp(-sigma t_exit)); inside an opaque sphere it
/// sees through it (spheres are solid, culled from inside) to what lies beyond.
#[test]
fn camera_inside_gas_and_inside_opaque_spheres() {
    let p = prep(&gas_at(DVec3::ZERO, 1.0, 0.2));
    let sigma = -f64::ln(0.2) / 2.0;
    let o = DVec3::new(0.3, 0.0, 0.0);
    for w in [DVec3::X, DVec3::NEG_X, DVec3::Y] {
        // Exit distance from o along w.
        let b = o.dot(w);
        let t = -b + (b * b - (o.length_squared() - 1.0)).sqrt();
        let want = 1.0 - (-sigma * t).exp();
        assert!((ray(&p, o, w).x - want).abs() < 1e-13);
    }
    let p = prep(&format!(
        "Background {{ skyColor 0.1 0.2 0.3 }}\n{}{}",
        unlit_at(DVec3::ZERO, 1.0),
        unlit_at(DVec3::new(0.0, 0.0, -3.0), 0.5)
    ));
    assert_eq!(ray(&p, DVec3::ZERO, DVec3::Z), DVec3::new(0.1, 0.2, 0.3));
    assert_eq!(ray(&p, DVec3::ZERO, DVec3::NEG_Z), DVec3::ONE);
}

/// Optical depth 0 (transparency 1): the gas is invisible, the background comes through
/// exactly.
#[test]
fn optical_depth_zero_is_invisible() {
    let p = prep(&format!(
        "Background {{ skyColor 0.25 0.5 1 }}\n{}",
        gas_at(DVec3::ZERO, 1.0, 1.0)
    ));
    assert_eq!(
        ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z),
        DVec3::new(0.25, 0.5, 1.0)
    );
}

/// A point light exactly at a visible surface point: that point gets no direct light (its
/// direction is undefined; docs/model.md's att and N.L need a distance), its neighbours get the
/// equation with the light on their tangent plane (N.L -> 0), and nothing is NaN.
#[test]
fn point_light_on_the_surface() {
    let p = prep(
        "PointLight { location 0 0 1 ambientIntensity 0.5 }\n\
         Shape { appearance Appearance { material Material { diffuseColor 1 1 1 ambientIntensity 0.4 } } geometry Sphere { } }",
    );
    let o = DVec3::new(0.0, 0.0, 5.0);
    // The point (0,0,1) itself: ambient needs the light's reach, which d = 0 does not define:
    // no light at all.
    assert_eq!(ray(&p, o, DVec3::NEG_Z), DVec3::ZERO);
    // A neighbour at angle a from the pole: L from x to (0,0,1), N.L = sin(a/2).
    for a in [1e-6f64, 1e-3, 0.1] {
        let x = DVec3::new(a.sin(), 0.0, a.cos());
        let w = (x - o).normalize();
        let l = (DVec3::Z - x).normalize();
        let want = 0.5 * 0.4 + x.dot(l).max(0.0);
        let got = ray(&p, o, w).x;
        assert!((got - want).abs() < 1e-9, "a {a}: {got} vs {want}");
    }
}

/// Degenerate transforms: scale 0 hides the contents with a warning (no sphere); a rotation
/// about the zero axis is the identity.
#[test]
fn degenerate_transforms() {
    let (scene, report) =
        support::scene("Transform { scale 0 0 0 children Shape { geometry Sphere { } } }");
    assert_eq!(scene.spheres.len(), 0);
    assert!(report
        .warnings
        .iter()
        .any(|w| w.headline().contains("scale")));
    let (scene, _) = support::scene(
        "Transform { rotation 0 0 0 1.5 translation 1 2 3 children Shape { geometry Sphere { radius 2 } } }",
    );
    assert_eq!(scene.spheres[0].center, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(scene.spheres[0].radius, 2.0);
}

/// Bad numbers give a clean positioned error, never a picture: zero, negative, NaN and
/// infinite radii, NaN and infinite coordinates.
#[test]
fn bad_radii_and_coordinates_are_positioned_errors() {
    for (text, col) in [
        ("Shape { geometry Sphere { radius 0 } }", 27),
        ("Shape { geometry Sphere { radius -1 } }", 27),
        ("Shape { geometry Sphere { radius nan } }", 27),
        ("Shape { geometry Sphere { radius inf } }", 27),
        (
            "Transform { translation 1 nan 0 children Shape { geometry Sphere { } } }",
            13,
        ),
        (
            "Transform { translation 1e999 0 0 children Shape { geometry Sphere { } } }",
            13,
        ),
    ] {
        let err = support::error_of(&format!("#VRML V2.0 utf8\n{text}"));
        let head = err.lines().next().unwrap();
        assert!(head.starts_with("test.wrl:2:"), "{text}: {head}");
        let c: usize = head.split(':').nth(2).unwrap().parse().unwrap();
        assert!(c >= col, "{text}: {head}");
    }
}

/// Across tangency the picture is continuous: for rays 1e-3 .. 1e-12 (relative) inside the
/// silhouette of a lit opaque sphere, and of a gas sphere, the value follows the closed form
/// as it tends to its limit (no bright or dark rim, no NaN); just outside is the background.
#[test]
fn values_are_continuous_across_tangency() {
    let opaque = prep(
        "DirectionalLight { direction -1 0 -0.2 }\n\
         Shape { appearance Appearance { material Material { diffuseColor 1 1 1 ambientIntensity 0 } } geometry Sphere { } }",
    );
    let gas = prep(&gas_at(DVec3::ZERO, 1.0, 0.3));
    let sigma = -f64::ln(0.3) / 2.0;
    let l = -DVec3::new(-1.0, 0.0, -0.2).normalize();
    for k in [1e-3, 1e-6, 1e-9, 1e-12] {
        // Rays along -z at distance (1 - k) from the centre, on the +x side (lit).
        let x = 1.0 - k;
        let o = DVec3::new(x, 0.0, 5.0);
        // Half chord without cancellation: 1 - x is exact (Sterbenz).
        let z = ((1.0 - x) * (1.0 + x)).sqrt();
        let n = DVec3::new(x, 0.0, z);
        let want = n.dot(l).max(0.0);
        let got = ray(&opaque, o, DVec3::NEG_Z).x;
        assert!((got - want).abs() < 1e-9, "k {k}: {got} vs {want}");
        let want_gas = 1.0 - (-sigma * 2.0 * z).exp();
        let got_gas = ray(&gas, o, DVec3::NEG_Z).x;
        assert!(
            (got_gas - want_gas).abs() <= 1e-12 * want_gas.max(1e-300) + 1e-15,
            "k {k}: {got_gas} vs {want_gas}"
        );
        // Just outside: nothing.
        let o = DVec3::new(1.0 + k, 0.0, 5.0);
        assert_eq!(ray(&opaque, o, DVec3::NEG_Z), DVec3::ZERO);
        assert_eq!(ray(&gas, o, DVec3::NEG_Z), DVec3::ZERO);
    }
}

/// An opaque sphere that only glows: seen with no lights, its value is `e` exactly.
fn glowing_at(c: DVec3, r: f64, e: DVec3) -> String {
    format!(
        "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0 0 0 emissiveColor {} {} {} }} }} geometry Sphere {{ radius {r} }} }} }}\n",
        c.x, c.y, c.z, e.x, e.y, e.z
    )
}

/// Rays exactly tangent to a sphere, and 1e-12 inside or outside tangency, with the sphere's
/// silhouette at exactly representable offsets: inside and tangent rays see the sphere (a
/// tangent ray touches it at one point: the discriminant is exactly 0), outside ones do not.
#[test]
fn rays_tangent_and_1e_12_from_tangency() {
    let p = prep(&format!(
        "Background {{ skyColor 0 0 0.5 }}\n{}",
        unlit_at(DVec3::ZERO, 1.0)
    ));
    let sky = DVec3::new(0.0, 0.0, 0.5);
    for (x, want) in [
        (1.0 - 1e-12, DVec3::ONE),
        (1.0, DVec3::ONE),
        (1.0 + 1e-12, sky),
        (-1.0, DVec3::ONE),
        (-1.0 - 1e-12, sky),
    ] {
        assert_eq!(
            ray(&p, DVec3::new(x, 0.0, 10.0), DVec3::NEG_Z),
            want,
            "x {x}"
        );
        assert_eq!(ray(&p, DVec3::new(0.0, x, -10.0), DVec3::Z), want, "y {x}");
    }
}

/// Coincident opaque spheres: the one earlier in the file is seen (README, "What is read, and what is
/// modelled"), on
/// every pair of a scene big enough for a real BVH. Nested: an opaque sphere inside another is
/// hidden; inside a gas sphere it is seen through the gas in front of it. Touching gas
/// spheres: their optical depths add along a ray through both.
#[test]
fn coincident_nested_and_touching_spheres() {
    let (red, green) = (DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
    let mut body = String::new();
    let mut want = Vec::new();
    for k in 0..300 {
        let c = DVec3::new((k % 20) as f64 * 3.0, (k / 20) as f64 * 3.0, (k % 7) as f64);
        let (first, second) = if k % 2 == 0 {
            (red, green)
        } else {
            (green, red)
        };
        body.push_str(&glowing_at(c, 1.0, first));
        body.push_str(&glowing_at(c, 1.0, second));
        want.push((c, first));
    }
    let p = prep(&body);
    for (c, first) in want {
        for dx in [0.0, 0.5, -0.9] {
            let o = c + DVec3::new(dx, 0.0, 20.0);
            assert_eq!(ray(&p, o, DVec3::NEG_Z), first, "pair at {c}");
        }
    }

    // Lit coincident spheres look like one: no shadow of one on the other.
    let lit = |c: DVec3, rgb: DVec3| {
        format!(
            "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ diffuseColor {} {} {} ambientIntensity 0 }} }} geometry Sphere {{ }} }} }}\n",
            c.x, c.y, c.z, rgb.x, rgb.y, rgb.z
        )
    };
    let p = prep(&format!(
        "DirectionalLight {{ direction 0 0 -1 }}\n{}{}",
        lit(DVec3::ZERO, red),
        lit(DVec3::ZERO, green)
    ));
    for dx in [0.0, 0.3, 0.6, 0.9] {
        // Hit at (dx, 0, sqrt(1 - dx^2)): N.L = sqrt(1 - dx^2).
        let got = ray(&p, DVec3::new(dx, 0.0, 5.0), DVec3::NEG_Z);
        let want = (1.0 - dx * dx).sqrt() * red;
        assert!(
            (got - want).abs().max_element() < 1e-12,
            "dx {dx}: {got} vs {want}"
        );
    }

    // Nested opaque: the outer one hides the inner.
    let inner = DVec3::new(0.2, 0.4, 0.6);
    let p = prep(&format!(
        "{}{}",
        glowing_at(DVec3::ZERO, 0.5, inner),
        glowing_at(DVec3::ZERO, 1.0, red)
    ));
    assert_eq!(ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z), red);
    // Opaque inside gas (emission 1, transparency 0.3 over the diameter 2): the gas in front
    // is R - r = 0.5 thick.
    let p = prep(&format!(
        "{}{}",
        glowing_at(DVec3::ZERO, 0.5, inner),
        gas_at(DVec3::ZERO, 1.0, 0.3)
    ));
    let sigma = -f64::ln(0.3) / 2.0;
    let t = (-sigma * 0.5).exp();
    let want = DVec3::splat(1.0 - t) + t * inner;
    let got = ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
    assert!((got - want).abs().max_element() < 1e-14, "{got} vs {want}");

    // Touching gas spheres along z (contact at z = -1), red over green.
    let gas_coloured = |c: DVec3, tr: f64, e: DVec3| {
        format!(
            "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ emissiveColor {} {} {} diffuseColor 0 0 0 transparency {tr} }} }} geometry Sphere {{ }} }} }}\n",
            c.x, c.y, c.z, e.x, e.y, e.z
        )
    };
    let p = prep(&format!(
        "{}{}",
        gas_coloured(DVec3::ZERO, 0.4, red),
        gas_coloured(DVec3::new(0.0, 0.0, -2.0), 0.7, green)
    ));
    let want = (1.0 - 0.4) * red + 0.4 * (1.0 - 0.7) * green;
    let got = ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z);
    assert!((got - want).abs().max_element() < 1e-14, "{got} vs {want}");
}

/// A point light at the centre of, inside, and on the surface of an absorbing gas sphere,
/// lighting an opaque diffuse sphere outside it: the light arriving is attenuated by
/// exp(-sigma * chord), the chord from the light to where its ray to the lit point leaves the
/// gas (0 when the light sits on the surface facing the point).
#[test]
fn point_light_inside_at_centre_and_on_a_gas_sphere() {
    let tr = 0.05;
    let sigma = -f64::ln(tr) / 2.0;
    // A point of the receiver (centre (3,0,0), radius 0.5) facing the gas, seen from straight
    // above (the camera ray misses the gas); 0.3 = sqrt(0.5^2 - 0.4^2) exactly in f64.
    let x = DVec3::new(2.6, 0.0, 0.3);
    let n = (x - DVec3::new(3.0, 0.0, 0.0)) / 0.5;
    for light in [
        DVec3::ZERO,
        DVec3::new(0.5, 0.2, -0.1),
        DVec3::new(-0.3, 0.6, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
    ] {
        let p = prep(&format!(
            "PointLight {{ location {} {} {} }}\n\
             Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0 0 0 transparency {tr} }} }} geometry Sphere {{ }} }}\n\
             Transform {{ translation 3 0 0 children Shape {{ appearance Appearance {{ material Material {{ diffuseColor 1 1 1 }} }} geometry Sphere {{ radius 0.5 }} }} }}",
            light.x, light.y, light.z
        ));
        let d = (x - light).normalize();
        // Distance from the light to the unit sphere's exit along d (the light is inside or on it).
        let b = light.dot(d);
        let chord = (-b + (b * b - (light.length_squared() - 1.0)).max(0.0).sqrt()).max(0.0);
        let cos = -d.dot(n);
        assert!(cos > 0.1, "the light must face the point");
        let want = (-sigma * chord).exp() * cos;
        let got = ray(&p, DVec3::new(2.6, 0.0, 5.0), DVec3::NEG_Z);
        assert!(
            (got.x - want).abs() < 1e-12,
            "light at {light}: {} vs {want}",
            got.x
        );
    }
}

/// Optical depths 1e-12 and 1e4 through an emitting gas sphere: L = 1 - exp(-tau), to full
/// relative precision at 1e-12 (no cancellation in 1 - exp), exactly 1 at 1e4, and rays whose
/// chord gives tau = 1 in the dense sphere get 1 - 1/e.
#[test]
fn optical_depths_1e_12_and_1e4() {
    // tau = 1e-12 along the diameter: transparency exp(-1e-12) as written in the file.
    let tr: f64 = "0.999999999999".parse().unwrap();
    let tau = -tr.ln();
    let p = prep(&gas_at(DVec3::ZERO, 1.0, tr));
    let got = ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z).x;
    let want = -(-tau).exp_m1();
    assert!(
        ((got - want) / want).abs() < 1e-9,
        "{got:e} vs {want:e} (1 - exp would give {:e})",
        1.0 - (-tau).exp()
    );

    // tau = 1e4 along the diameter: --as-gas 5000 on a unit sphere.
    let (scene, _) = support::scene(
        "NavigationInfo { headlight FALSE }\nBackground { skyColor 0 0 1 }\n\
         Shape { appearance Appearance { material Material { emissiveColor 1 1 1 diffuseColor 0 0 0 } } geometry Sphere { } }",
    );
    let opts = PrepareOptions {
        as_gas: Some(5000.0),
        ..PrepareOptions::default()
    };
    let p = render::prepare(scene, &opts).expect("prepare");
    assert_eq!(
        ray(&p, DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z),
        DVec3::new(1.0, 1.0, 1.0)
    );
    // Offset b with chord 2 sqrt(1 - b^2) = 1 / 5000: tau = 1 (1 - b^2 is exact in f64).
    let b = (1.0f64 - 1e-8).sqrt();
    let chord = 2.0 * (1.0 - b * b).sqrt();
    let want = -(-5000.0 * chord).exp_m1();
    let got = ray(&p, DVec3::new(b, 0.0, 5.0), DVec3::NEG_Z);
    let sky_left = (-5000.0 * chord).exp();
    assert!(
        (got.x - want).abs() < 1e-6 && (got.z - (want + sky_left)).abs() < 1e-6,
        "{got} vs {want}"
    );
}

/// One emitting profiled sphere (`--profile` with `--as-gas SIGMA0`) at the hard ends:
/// optical depths of 1e-12 and 1e4 along a diameter, a camera at the centre, and a sphere
/// 1e8 from the origin. Expected, from the chord depths written out here: quadratic
/// `tau = sigma0 r (4/3) h^3`, linear `sigma0 r (h - beta^2 asinh(h / beta))` (`h` the half
/// chord in radii at distance `beta`), and from the centre to the surface `sigma0 r I_f`.
#[test]
fn profiled_gas_at_tiny_and_huge_depths_from_inside_and_far_away() {
    use crate::scene::Profile;
    let c = DVec3::new(0.9, 0.6, 0.3);
    let setup = |centre: DVec3, sigma0: f64, profile: Profile| {
        let body = format!(
            "Transform {{ translation {:e} {:e} {:e} children Shape {{ appearance Appearance {{ material Material {{ emissiveColor 0.9 0.6 0.3 transparency 0.5 }} }} geometry Sphere {{ radius 2 }} }} }}",
            centre.x, centre.y, centre.z
        );
        let (scene, _) = support::scene(&format!("NavigationInfo {{ headlight FALSE }}\n{body}"));
        let opts = PrepareOptions {
            as_gas: Some(sigma0),
            profile: Some(profile),
        };
        render::prepare(scene, &opts).expect("prepare")
    };
    let r = 2.0;
    let tau_of = |profile: Profile, sigma0: f64, beta: f64| {
        let h = (1.0 - beta * beta).sqrt();
        sigma0
            * r
            * match profile {
                Profile::Quadratic => 4.0 / 3.0 * h * h * h,
                Profile::Linear if beta == 0.0 => h,
                Profile::Linear => h - beta * beta * (h / beta).asinh(),
                _ => unreachable!(),
            }
    };
    for profile in [Profile::Quadratic, Profile::Linear] {
        for sigma0 in [1e-12, 1e-6, 1.0, 1e4] {
            let p = setup(DVec3::ZERO, sigma0, profile);
            for beta in [0.0, 0.3, 0.9] {
                let o = DVec3::new(beta * r, 0.0, 10.0);
                let got = ray(&p, o, DVec3::NEG_Z);
                let want = c * -(-tau_of(profile, sigma0, beta)).exp_m1();
                let rel = ((got - want).abs() / want).max_element();
                assert!(
                    rel <= 1e-13,
                    "{profile:?} sigma0 {sigma0:e} beta {beta}: {got} vs {want} ({rel:e})"
                );
            }
            // From the centre outwards: half the diameter's depth, sigma0 r I_f.
            let half = sigma0
                * r
                * match profile {
                    Profile::Quadratic => 2.0 / 3.0,
                    _ => 0.5,
                };
            let got = ray(&p, DVec3::ZERO, DVec3::new(0.6, 0.0, 0.8));
            let want = c * -(-half).exp_m1();
            let rel = ((got - want).abs() / want).max_element();
            assert!(
                rel <= 1e-13,
                "{profile:?} sigma0 {sigma0:e} inside: {rel:e}"
            );
        }
        // 1e8 from the origin, seen from 10 away: the ray's own rounding (1e-16 of 1e8 in the
        // closest approach) is all that is lost.
        let far = DVec3::new(1e8, -1e8, 1e8);
        let p = setup(far, 0.5, profile);
        let o = far + DVec3::new(0.3 * r, 0.0, 10.0);
        let got = ray(&p, o, DVec3::NEG_Z);
        let want = c * -(-tau_of(profile, 0.5, 0.3)).exp_m1();
        let rel = ((got - want).abs() / want).max_element();
        assert!(
            rel <= 1e-7,
            "{profile:?} far away: {got} vs {want} ({rel:e})"
        );
    }
}

/// A profiled ellipsoid (a quadratic-profile Sphere under `scale 2 1 1`): the profile follows
/// the ellipsoid's shape, and `transparency` stays the transmittance along a diameter of the
/// volume-equivalent sphere (`r_eq = 2^(1/3)`, as for constant gas). Along an axis of
/// half-length `a` the optical depth is `-ln(t) a / r_eq`; off the x axis at a fraction `b`
/// of the y half-axis, `-ln(t) (2 / r_eq) (1 - b^2)^(3/2)`. Its emission along those lines, and
/// its shadow on an opaque sphere lit through it along z, against those numbers.
#[test]
fn profiled_ellipsoid_emits_and_shadows_along_its_own_shape() {
    use crate::scene::Profile;
    let body = "DirectionalLight { direction 0 0 -1 }
Transform { scale 2 1 1 children Shape { appearance Appearance { material Material { emissiveColor 0.9 0.6 0.3 diffuseColor 0 0 0 transparency 0.5 } } geometry Sphere { } } }
Transform { translation 0 0 -5 children Shape { appearance Appearance { material Material { diffuseColor 1 1 1 } } geometry Sphere { } } }";
    let (scene, _) = support::scene(&format!("NavigationInfo {{ headlight FALSE }}\n{body}"));
    let opts = PrepareOptions {
        profile: Some(Profile::Quadratic),
        ..PrepareOptions::default()
    };
    let p = render::prepare(scene, &opts).expect("prepare");
    let k = -(0.5f64.ln()) / 2f64.cbrt();
    let c = DVec3::new(0.9, 0.6, 0.3);
    for (o, w, tau) in [
        (DVec3::new(10.0, 0.0, 0.0), DVec3::NEG_X, 2.0 * k),
        (DVec3::new(0.0, 10.0, 0.0), DVec3::NEG_Y, k),
        (
            DVec3::new(10.0, 0.5, 0.0),
            DVec3::NEG_X,
            2.0 * k * 0.75f64.powf(1.5),
        ),
    ] {
        let got = ray(&p, o, w);
        let want = c * -(-tau).exp_m1();
        let rel = ((got - want).abs() / want).max_element();
        assert!(rel <= 1e-13, "{o} {w}: {got} vs {want} ({rel:e})");
    }
    // (0, 0, -4) on the opaque sphere, lit along +z through the ellipsoid's z axis (a = 1),
    // seen from (3, 0, -1) by a ray that meets no gas: N.L = 1, white, no specular.
    let o = DVec3::new(3.0, 0.0, -1.0);
    let got = ray(&p, o, (DVec3::new(0.0, 0.0, -4.0) - o).normalize());
    let want = (-k).exp();
    assert!(
        ((got - DVec3::splat(want)).abs() / want).max_element() <= 1e-13,
        "{got} vs {want}"
    );
}
