//! The reference's own checks: its camera rays agree with the library's (depth AOV of one
//! sphere), and its values agree with closed forms: one gas sphere's emission
//! `C (1 - exp(-tau_chord))` (constant, linear, quadratic profiles, tau 1e-6 to 7e2), thin gas
//! single scattering to first order, the VRML lighting equation on a lit sphere, a known
//! chord's transmittance, and the AO reference (`ao.rs`) against the closed forms of what one
//! sphere (with and without a reach) and one triangle block, its gas optical depths against
//! the quadrature of the density, and what one gas sphere takes away against a closed form
//! (thin gas) and one-dimensional integrals (gas about the normal, outside and around the
//! point, with and without a reach).

use glam::DVec3;
use gtsphere::render::Integrator;

use super::checks;
use super::reference::sphere_roots;
use super::scenes::{DirectionalLight, Geometry, Material, Node, Profile, SceneDesc, Viewpoint};
use super::world::World;

fn mat(transparency: f64, profile: Profile) -> Material {
    Material {
        diffuse: [0.8, 0.5, 0.2],
        emissive: [0.3, 0.6, 0.9],
        specular: [0.4, 0.4, 0.1],
        shininess: 0.3,
        ambient: 0.25,
        transparency,
        profile,
    }
}

/// A shape under a translation-only Transform.
fn at(c: DVec3, geometry: Geometry, material: Option<Material>) -> Node {
    super::generate::at(c, Node::Shape { geometry, material })
}

/// A scene looking down -z from (0, 0, 5) at `nodes`, headlight off.
fn desc(nodes: Vec<Node>, ortho: Option<f64>) -> SceneDesc {
    SceneDesc {
        seed: 0,
        nodes,
        viewpoint: Viewpoint {
            position: DVec3::new(0.0, 0.0, 5.0),
            axis: DVec3::Z,
            angle: 0.0,
            fov: 0.8,
            ortho,
        },
        headlight: false,
        background: [0.0; 3],
        width: 9,
        height: 7,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// The reference's pixel-centre rays are the library's: the depth AOV of one opaque sphere
/// seen from tilted perspective and orthographic viewpoints equals the reference's hit.
#[test]
fn verify_reference_camera_rays_are_the_library_rays() {
    for (k, ortho) in [None, Some(3.0), None, Some(1.7)].into_iter().enumerate() {
        let mut d = desc(
            vec![at(
                DVec3::new(0.2, -0.1, 0.3),
                Geometry::Sphere { r: 1.2 },
                None,
            )],
            ortho,
        );
        d.viewpoint.position = DVec3::new(1.0 + k as f64, 0.5, 4.0);
        d.viewpoint.axis = DVec3::new(0.3, 1.0, 0.1).normalize();
        d.viewpoint.angle = 0.2 + 0.05 * k as f64;
        d.width = 11 + k as u32;
        d.height = 8;
        let world = World::new(&d, false);
        let mut opts = checks::options(&d, Integrator::Exact, 1e-4, false);
        opts.aovs.depth = true;
        let film = checks::library(&super::vrml::write(&d), &d, &opts).expect("render");
        let depth = film.depth.expect("depth AOV");
        let mut hits = 0;
        for j in 0..d.height {
            for i in 0..d.width {
                let (o, w) = world.eye.ray(i, j);
                let t = sphere_roots(DVec3::new(0.2, -0.1, 0.3), 1.2, o, w)
                    .filter(|r| r.0 > 0.0)
                    .map_or(f64::INFINITY, |r| r.0);
                let got = depth[(j * d.width + i) as usize];
                hits += usize::from(t.is_finite());
                assert!(
                    (t.is_infinite() && got.is_infinite()) || rel(got, t) < 1e-12,
                    "view {k} pixel ({i}, {j}): library depth {got}, reference {t}"
                );
            }
        }
        assert!(hits > 2, "view {k}: only {hits} pixels see the sphere");
    }
}

/// Closed-form optical depth of a whole chord at impact parameter beta (unit sphere, sigma0
/// 1): constant 2 v, linear and quadratic from docs/model.md section 6's F.
fn chord_tau(profile: Profile, beta: f64) -> f64 {
    let v = (1.0 - beta * beta).sqrt();
    let f = |v: f64| match profile {
        Profile::Constant => v,
        Profile::Linear => {
            v - v * (beta * beta + v * v).sqrt() / 2.0
                - if beta > 0.0 {
                    beta * beta / 2.0 * (v / beta).asinh()
                } else {
                    0.0
                }
        }
        Profile::Quadratic => (1.0 - beta * beta) * v - v * v * v / 3.0,
        Profile::Gaussian(_) => unreachable!("not used here"),
    };
    f(v) - f(-v)
}

/// One gas sphere emitting alone: `C (1 - exp(-tau))` to 1e-9 relative (and within the
/// reference's own error estimate), for optical depths 1e-6 to 7e2 per diameter.
#[test]
fn verify_reference_single_sphere_emission_is_closed_form() {
    for profile in [Profile::Constant, Profile::Linear, Profile::Quadratic] {
        for tau_d in [1e-6f64, 1e-2, 1.0, 30.0, 700.0] {
            let mut m = mat((-tau_d).exp(), profile);
            m.diffuse = [0.0; 3];
            let d = desc(
                vec![at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, Some(m))],
                None,
            );
            let world = World::new(&d, false);
            let g = world.prims[0].gas().expect("gas");
            for beta in [0.0, 0.3, 0.9, 0.999] {
                let o = DVec3::new(beta, 0.0, 5.0);
                let r = world.ray(o, DVec3::NEG_Z);
                let tau = g.sigma0 * chord_tau(profile, beta);
                for c in 0..3 {
                    let want = m.emissive[c] * -(-tau).exp_m1();
                    let e = (r.value[c] - want).abs();
                    assert!(
                        e <= 1e-9 * want && e <= r.err + 1e-12 * want,
                        "{profile:?} tau_d {tau_d} beta {beta}: {} against {want} (err {})",
                        r.value[c],
                        r.err
                    );
                }
            }
        }
    }
}

/// A thin constant sphere (tau 1e-7 per diameter) lit by a DirectionalLight with nothing in
/// the way scatters `p sigma a C I chord` to first order in tau.
#[test]
fn verify_reference_thin_scattering_is_first_order_closed_form() {
    let mut m = mat((-1e-7f64).exp(), Profile::Constant);
    m.emissive = [0.0; 3];
    let light = DirectionalLight {
        on: true,
        direction: DVec3::new(1.0, -1.0, 0.5).normalize(),
        color: [1.0, 0.5, 0.25],
        intensity: 0.8,
        ambient: 0.7,
    };
    let d = desc(
        vec![
            at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, Some(m)),
            Node::Directional(light),
        ],
        None,
    );
    let world = World::new(&d, false);
    let sigma = world.prims[0].gas().expect("gas").sigma0;
    for beta in [0.0, 0.5, 0.95] {
        let r = world.ray(DVec3::new(0.0, beta, 5.0), DVec3::NEG_Z);
        let chord = 2.0 * (1.0 - beta * beta).sqrt();
        for c in 0..3 {
            let want = sigma * m.diffuse[c] * light.color[c] * light.intensity * chord
                / (4.0 * std::f64::consts::PI);
            assert!(
                rel(r.value[c], want) < 1e-6 && r.scatter[c] == r.value[c],
                "beta {beta} channel {c}: {} against {want}",
                r.value[c]
            );
        }
    }
}

/// The VRML97 lighting equation at the front of a lit opaque sphere, and the same point
/// behind a gas sphere on the light's way: the light times exp(-sigma chord).
#[test]
fn verify_reference_lit_sphere_and_chord_transmittance_are_closed_form() {
    let m = mat(0.0, Profile::Constant);
    let light = DirectionalLight {
        on: true,
        direction: DVec3::NEG_Z,
        color: [0.9, 0.7, 0.5],
        intensity: 0.6,
        ambient: 0.3,
    };
    let want: Vec<f64> = (0..3)
        .map(|c| {
            m.emissive[c]
                + light.color[c]
                    * (light.ambient * m.diffuse[c] * m.ambient
                        + light.intensity * (m.diffuse[c] + m.specular[c]))
        })
        .collect();
    let lit = |nodes: Vec<Node>| {
        let world = World::new(&desc(nodes, None), false);
        world.ray(DVec3::new(0.0, 0.0, 5.0), DVec3::NEG_Z).value
    };
    let sphere = at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, Some(m));
    let got = lit(vec![sphere.clone(), Node::Directional(light)]);
    for c in 0..3 {
        assert!(rel(got[c], want[c]) < 1e-14, "{got:?} against {want:?}");
    }
    // A constant gas shadower of transmittance 0.37 along its diameter, centred on the light
    // ray from the lit point x (normal n, lit head-on) but off the camera ray (along -y).
    let n = DVec3::new(0.0, 1.0, 1.0).normalize();
    let x = n;
    let mut d = desc(
        vec![
            at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, Some(m)),
            at(
                x + 2.0 * n,
                Geometry::Sphere { r: 0.5 },
                Some(Material {
                    emissive: [0.0; 3],
                    diffuse: [0.0; 3],
                    ..mat(0.37, Profile::Constant)
                }),
            ),
            Node::Directional(DirectionalLight {
                direction: -n,
                ..light
            }),
        ],
        None,
    );
    d.viewpoint.position = DVec3::new(0.0, 5.0, 0.0);
    let world = World::new(&d, false);
    let r = world.ray(x + DVec3::new(0.0, 4.0, 0.0), DVec3::NEG_Y);
    let half = (n + DVec3::Y).normalize();
    let spec = n.dot(half).powf(128.0 * m.shininess);
    for k in 0..3 {
        let want = m.emissive[k]
            + light.color[k]
                * (light.ambient * m.diffuse[k] * m.ambient
                    + 0.37 * light.intensity * (m.diffuse[k] + m.specular[k] * spec));
        assert!(
            rel(r.value[k], want) < 1e-12,
            "channel {k}: {} against {want}",
            r.value[k]
        );
    }
}

/// The AO reference at the point (0, 0, 1) on top of a unit sphere, seen by the centre pixel,
/// against closed forms: a sphere of angular radius `a` whose axis makes the angle `t` with
/// the normal (wholly above the horizon) blocks `sin^2 a cos t` of the cosine-weighted
/// hemisphere and `1 - cos a` of the uniform one; within a reach `D` between `d - r` and
/// `sqrt(d^2 - r^2)` the same with the cap of cosine `(d^2 + D^2 - r^2) / (2 d D)`, and
/// nothing for `D < d - r`; a triangle blocks its solid angle (Van Oosterom and Strackee)
/// over 2 pi, or its form factor `(1/2pi) sum_i angle_i n . unit(v_i x v_i+1)` (Lambert).
#[test]
fn verify_ao_reference_matches_closed_forms() {
    use super::ao::{reference, settings, AoRef, SIDE};
    use gtsphere::render::ao::Weighting;

    let x = DVec3::Z;
    let base = at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, None);
    let (c, r) = (DVec3::new(0.8, 0.0, 2.2), 0.3);
    let v = c - x;
    let d = v.length();
    let cos_t = v.z / d;
    let cap = |cos_a: f64, w: Weighting| match w {
        Weighting::Cosine => (1.0 - cos_a * cos_a) * cos_t,
        Weighting::Uniform => 1.0 - cos_a,
    };
    let p = [
        DVec3::new(0.6, 0.3, 1.8),
        DVec3::new(0.2, 0.8, 2.0),
        DVec3::new(0.9, 0.7, 1.6),
    ];
    let triangle = |w: Weighting| {
        let q = p.map(|k| k - x);
        let l = q.map(|k| k.length());
        match w {
            Weighting::Uniform => {
                let num = q[0].dot(q[1].cross(q[2])).abs();
                let den = l[0] * l[1] * l[2]
                    + q[0].dot(q[1]) * l[2]
                    + q[0].dot(q[2]) * l[1]
                    + q[1].dot(q[2]) * l[0];
                2.0 * num.atan2(den) / std::f64::consts::TAU
            }
            Weighting::Cosine => {
                let s: f64 = (0..3)
                    .map(|i| {
                        let (a, b) = (q[i], q[(i + 1) % 3]);
                        a.angle_between(b) * DVec3::Z.dot(a.cross(b).normalize())
                    })
                    .sum();
                s.abs() / std::f64::consts::TAU
            }
        }
    };
    let far = (d * d - r * r).sqrt();
    let reach = 1.3;
    assert!(reach > d - r && reach < far);
    let beta = (d * d + reach * reach - r * r) / (2.0 * d * reach);
    let sphere = at(c, Geometry::Sphere { r }, None);
    let tri = Node::Shape {
        geometry: Geometry::Triangle { p },
        material: None,
    };
    let n = f64::from(SIDE * SIDE);
    for w in [Weighting::Cosine, Weighting::Uniform] {
        let cases = [
            (&sphere, f64::INFINITY, Some(cap((r / d).asin().cos(), w))),
            (&sphere, reach, Some(cap(beta, w))),
            (&sphere, d - r - 0.01, None),
            (&tri, f64::INFINITY, Some(triangle(w))),
        ];
        for (k, (occluder, reach, blocked)) in cases.into_iter().enumerate() {
            let scene = desc(vec![base.clone(), occluder.clone()], None);
            let mut s = settings(0);
            s.reach = reach;
            s.weighting = w;
            let world = World::new(&scene, true);
            let got = reference(&world, &s, k as u64)[(3 * scene.width + 4) as usize];
            match (got, blocked) {
                (AoRef::Estimate { p, gas: false }, Some(b)) => {
                    let want = 1.0 - b;
                    let sigma = (want * (1.0 - want) / n).sqrt();
                    assert!(
                        (p - want).abs() <= 5.0 * sigma && b > 0.01,
                        "{w:?} case {k}: reference {p}, closed form {want} (sigma {sigma:.1e})"
                    );
                }
                (AoRef::Open, None) => {}
                _ => panic!("{w:?} case {k}: reference {got:?}, closed form blocks {blocked:?}"),
            }
        }
    }
}

/// The AO reference's closed-form optical depths (`reference::gas_depth`) equal the quadrature of
/// the density (`World::depth`) on chords of every profile through, beside and from inside a
/// sphere, grazing ones included; and its `erf` matches tabulated values.
#[test]
fn verify_ao_gas_depth_closed_forms_match_quadrature() {
    use super::reference::gas_depth::{erf, gas_depth};
    use super::world::Gas;
    use crate::support::Rng;

    // erf at 0.5, 1, 2, 3.5 (Abramowitz and Stegun, table 7.1, and its continuation).
    for (x, want) in [
        (0.5, 0.520_499_877_813_046_5),
        (1.0, 0.842_700_792_949_714_9),
        (2.0, 0.995_322_265_018_952_7),
        (3.5, 0.999_999_256_901_627_7),
    ] {
        assert!(rel(erf(x), want) < 1e-14, "erf({x}) = {}", erf(x));
        assert!(rel(erf(-x), -want) < 1e-14);
    }
    let mut rng = Rng::new(71);
    let profiles = [
        Profile::Constant,
        Profile::Linear,
        Profile::Quadratic,
        Profile::Gaussian(0.15),
        Profile::Gaussian(0.6),
        Profile::Gaussian(1.0),
    ];
    let mut chords = 0;
    for k in 0..600 {
        let profile = profiles[k % profiles.len()];
        let r = rng.log10(-2.0, 0.5);
        let c = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let g = Gas {
            c,
            r,
            sigma0: rng.log10(-3.0, 3.0),
            m: mat(0.5, profile),
        };
        // A line at a distance from the centre up to the radius, grazing in one case of
        // five; the point on it before, inside or past the sphere.
        let w = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        )
        .normalize();
        let side = w.any_orthonormal_vector();
        let off = if k % 5 == 0 {
            1.0 - rng.log10(-9.0, -3.0)
        } else {
            rng.f()
        };
        let x = c + side * off * r + w * r * rng.range(-3.0, 1.0);
        let Some((t0, t1)) = sphere_roots(c, r, x, w) else {
            continue;
        };
        let (a, b) = (t0.max(0.0), t1);
        if b <= a {
            continue;
        }
        // The whole chord, and a piece of it.
        for (a, b) in [(a, b), (a + 0.3 * (b - a), a + 0.8 * (b - a))] {
            let want = World::depth(&g, x, w, a, b);
            let got = gas_depth(&g, x, w, a, b);
            assert!(
                (got - want).abs() <= 1e-10 * want + 1e-13 * g.sigma0 * r,
                "{profile:?}, r {r}, sigma0 {}, offset {off}: closed form {got}, quadrature \
                 {want}",
                g.sigma0
            );
            chords += 1;
        }
    }
    assert!(chords > 800, "{chords} chords");
}

/// The AO reference at the point (0, 0, 1) on top of a unit sphere, seen by the centre pixel,
/// with gas: (a) thin constant gas, optical depth `tau << 1` along any chord, far above the
/// plane: with uniform weighting `1 - AO = (sigma / 2 pi) integral over the ball of |y -
/// x|^-2 dy = (sigma / 2 pi) (pi / d) [(r^2 - d^2) ln((d + r) / (d - r)) + 2 d r]` to first
/// order in `tau` (the ball's chord integrated over directions is its volume seen with the
/// `t^2` of the solid angle left out); (b) a gas sphere of any profile centred on the normal,
/// outside the point or around it, with and without a reach: by symmetry `1 - AO` is the
/// one-dimensional integral over the angle `theta` from the normal of `1 - exp(-tau(theta))`
/// times `sin theta` (uniform) or `2 sin theta cos theta` (cosine), `tau` from the quadrature
/// of the density (`World::depth`).
#[test]
fn verify_ao_reference_gas_matches_closed_forms() {
    use super::ao::{reference, settings, AoRef, SIDE};
    use super::quad;
    use gtsphere::render::ao::Weighting;

    let x = DVec3::Z;
    let n = f64::from(SIDE * SIDE);
    let centre = (3 * 9 + 4) as usize;
    let base = at(DVec3::ZERO, Geometry::Sphere { r: 1.0 }, None);
    // A gas sphere whose optical depth along a diameter is `tau`.
    let gas = |c: DVec3, r: f64, tau: f64, profile: Profile| {
        at(c, Geometry::Sphere { r }, Some(mat((-tau).exp(), profile)))
    };
    let ao = |node: Node, reach: f64, w: Weighting, seed: u64| {
        let scene = desc(vec![base.clone(), node], None);
        let mut s = settings(0);
        s.reach = reach;
        s.weighting = w;
        let world = World::new(&scene, true);
        (reference(&world, &s, seed)[centre], world)
    };

    // (a) Thin constant gas: sigma r = 1e-6.
    let (c, r) = (DVec3::new(0.3, 0.0, 2.0), 0.6);
    let d = (c - x).length();
    let sigma = 1e-6 / r;
    let want = sigma / 2.0 * ((r * r - d * d) * ((d + r) / (d - r)).ln() + 2.0 * d * r) / d;
    let (got, _) = ao(
        gas(c, r, 2.0 * sigma * r, Profile::Constant),
        f64::INFINITY,
        Weighting::Uniform,
        1,
    );
    let AoRef::Estimate { p, gas: true } = got else {
        panic!("thin gas: reference {got:?}");
    };
    // 1 - V is at most tau_max = 2 sigma r, so its variance is at most tau_max (1 - AO); and
    // 1 - exp(-tau) is tau to within tau^2 / 2.
    let tau_max = 2.0 * sigma * r;
    let sd = (tau_max * want / n).sqrt();
    assert!(
        ((1.0 - p) - want).abs() <= 5.0 * sd + tau_max * want,
        "thin gas: 1 - AO {}, closed form {want} (sd {sd:.1e})",
        1.0 - p
    );
    assert!(want > 10.0 * (5.0 * sd), "thin gas: the check is too loose");

    // (b) A gas sphere centred at x + h n, radius r, diameter depth tau, reach D.
    let cases = [
        (1.0, 0.5, 2.0, Profile::Constant, f64::INFINITY),
        (1.0, 0.5, 2.0, Profile::Constant, 0.8),
        (1.0, 0.6, 5.0, Profile::Linear, f64::INFINITY),
        (1.2, 0.7, 3.0, Profile::Quadratic, 1.0),
        (1.0, 0.5, 40.0, Profile::Gaussian(0.3), f64::INFINITY),
        (0.2, 0.6, 3.0, Profile::Constant, f64::INFINITY),
        (0.2, 0.6, 3.0, Profile::Constant, 0.7),
        (0.3, 0.9, 2.0, Profile::Gaussian(0.5), 0.6),
        (0.1, 0.5, 4.0, Profile::Linear, f64::INFINITY),
    ];
    for (k, (h, r, tau, profile, reach)) in cases.into_iter().enumerate() {
        for w in [Weighting::Cosine, Weighting::Uniform] {
            let (got, world) = ao(
                gas(x + h * DVec3::Z, r, tau, profile),
                reach,
                w,
                10 + k as u64,
            );
            let g = world.prims[1].gas().expect("gas");
            let depth = |theta: f64| {
                let dir = DVec3::new(theta.sin(), 0.0, theta.cos());
                match sphere_roots(g.c, g.r, x, dir) {
                    Some((t0, t1)) if t1.min(reach) > t0.max(0.0) => {
                        World::depth(&g, x, dir, t0.max(0.0), t1.min(reach))
                    }
                    _ => 0.0,
                }
            };
            let density = |theta: f64| match w {
                Weighting::Uniform => theta.sin(),
                Weighting::Cosine => 2.0 * theta.sin() * theta.cos(),
            };
            // Kinks: the sphere's rim seen from outside, and where the reach crosses it.
            let mut cuts = vec![0.0, std::f64::consts::FRAC_PI_2];
            if h > r {
                cuts.push((r / h).asin());
            }
            if reach.is_finite() {
                let cos = (reach * reach + h * h - r * r) / (2.0 * reach * h);
                if cos.abs() < 1.0 {
                    cuts.push(cos.acos());
                }
            }
            cuts.retain(|t| *t <= std::f64::consts::FRAC_PI_2);
            cuts.sort_by(f64::total_cmp);
            let blocked: f64 = cuts
                .windows(2)
                .map(|p| quad::scalar(|t| -(-depth(t)).exp_m1() * density(t), p[0], p[1], 1e-10))
                .sum();
            let want = 1.0 - blocked;
            let AoRef::Estimate { p, gas: true } = got else {
                panic!("case {k} {w:?}: reference {got:?}");
            };
            let sigma = (want * (1.0 - want) / n).sqrt();
            assert!(
                (p - want).abs() <= 5.0 * sigma && blocked > 0.02,
                "case {k} {w:?}: reference {p}, integral {want} (sigma {sigma:.1e})"
            );
        }
    }
}

/// The AO refusal judge (`ao::Unsupported::judge`) takes a message that gives both counts
/// after "this scene has" and rejects one that leaves a count out, gives a wrong one, or
/// names ellipsoids.
#[test]
fn verify_ao_refusal_judge_needs_both_counts() {
    use super::ao::Unsupported;

    let u = Unsupported { gas: 12, rounds: 3 };
    let head = "ambient occlusion knows ..., and this scene has ";
    for good in [
        "12 gas spheres, 3 cylinders or cones",
        "12 gas spheres and 3 cylinders and cones",
        "3 closed cylinders or cones, 12 gas spheres",
    ] {
        let m = format!("{head}{good}");
        assert_eq!(u.judge(&m), None, "{m}");
    }
    for bad in [
        "12 gas spheres",
        "2 gas spheres, 3 cylinders or cones",
        "12 gas spheres, 13 cylinders or cones",
        "12 gas spheres, 3 ellipsoids, 3 cylinders or cones",
        "3 cylinders or cones",
    ] {
        let m = format!("{head}{bad}");
        assert!(u.judge(&m).is_some(), "{m}");
    }
    assert!(u.judge("12 gas spheres, 3 cylinders").is_some());
}
