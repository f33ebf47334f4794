//! The headlight (docs/model.md section 1): carried by the viewer, it lights what the camera sees
//! along the ray that sees it, through the gas in front and never in shadow; with
//! `headlight_shadows` it is a strict DirectionalLight along the view. Every pixel is checked
//! against closed forms worked here from textbook ray/sphere roots (the camera ray is the
//! library's, the rest is not).

use glam::DVec3;
use gtsphere::render::{Film, Integrator, RenderOptions, SamplerKind};

use crate::support;

const PHASE: f64 = 0.25 * std::f64::consts::FRAC_1_PI;

/// The roots of `|o + t w - c| = r` (`w` unit), if the line meets the sphere.
fn roots(o: DVec3, w: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    let oc = o - c;
    let b = oc.dot(w);
    let disc = b * b - (oc.length_squared() - r * r);
    (disc > 0.0).then(|| (-b - disc.sqrt(), -b + disc.sqrt()))
}

/// Renders `body` at `w x h` pixel centres with `opts`' integrator, and gives the film with
/// the camera ray of each pixel.
fn render(body: &str, n: u32, opts: RenderOptions) -> (Film, Vec<(DVec3, DVec3)>) {
    let opts = RenderOptions {
        width: n,
        height: n,
        sampler: SamplerKind::Center,
        ..opts
    };
    let (scene, _) = support::scene(body);
    let prep = support::prepare(scene);
    let cam = support::default_camera(&prep, &opts).image_plane(opts.width, opts.height);
    let rays = (0..n * n)
        .map(|k| {
            let (col, row) = (k % n, k / n);
            cam.ray(
                (f64::from(col) + 0.5) / f64::from(n),
                (f64::from(row) + 0.5) / f64::from(n),
            )
        })
        .collect();
    (support::render_prepared(&prep, &opts), rays)
}

/// A large sphere and a small one in front of it, off the view axis, lit by the headlight
/// alone, in perspective: a strict directional light along the view would put part of the
/// large sphere that the camera sees in the small one's shadow (a crescent beside its
/// silhouette).
const CRESCENT: &str = "\
Viewpoint { position 0 0 6 fieldOfView 0.8 }
Shape { appearance Appearance { material Material { diffuseColor 0.8 0.6 0.4 } }
        geometry Sphere { radius 1 } }
Transform { translation 0.6 0.4 2.5 children Shape {
  appearance Appearance { material Material { diffuseColor 0.2 0.9 0.3 } }
  geometry Sphere { radius 0.25 } } }
";

#[test]
fn the_headlight_casts_no_shadow_on_what_the_camera_sees() {
    let big = (DVec3::ZERO, 1.0, DVec3::new(0.8, 0.6, 0.4));
    let small = (DVec3::new(0.6, 0.4, 2.5), 0.25, DVec3::new(0.2, 0.9, 0.3));
    let to_light = DVec3::Z; // towards the viewer along the view axis
    for strict in [false, true] {
        let opts = RenderOptions {
            spp: 1,
            headlight_shadows: strict,
            ..RenderOptions::default()
        };
        let (film, rays) = render(CRESCENT, 48, opts);
        let mut shadowed = 0;
        for (k, &(o, w)) in rays.iter().enumerate() {
            let hit = |(c, r, _): (DVec3, f64, DVec3)| roots(o, w, c, r).map(|(t0, _)| t0);
            let (t, (c, _, color)) = match (hit(big), hit(small)) {
                (Some(a), Some(b)) if b < a => (b, small),
                (Some(a), _) => (a, big),
                (None, Some(b)) => (b, small),
                (None, None) => continue,
            };
            let x = o + t * w;
            let n = (x - c).normalize();
            // Diffuse only (no specular colour, the headlight has no ambient part).
            let mut expected = color * n.dot(to_light).max(0.0);
            if strict && roots(x, to_light, small.0, small.1).is_some_and(|(t0, _)| t0 > 1e-9) {
                expected = DVec3::ZERO;
                shadowed += 1;
            }
            let got = DVec3::from(film.rgb[k]);
            assert!(
                (got - expected).abs().max_element() <= 1e-9,
                "strict {strict}, pixel {k}: got {got}, expected {expected}"
            );
        }
        // The strict light does shadow visible points here, so the default's lack of shadow
        // is tested where it matters.
        assert_eq!(
            shadowed > 0,
            strict,
            "strict {strict}: {shadowed} shadowed pixels"
        );
    }
}

/// Gas of extinction `sigma` and albedo 0.5 in front of an opaque sphere, the headlight
/// alone, in perspective.
fn gas_scene(sigma: f64) -> String {
    let transparency = (-2.0 * sigma).exp(); // radius 1
    format!(
        "Viewpoint {{ position 0 0 6 fieldOfView 0.9 }}\n\
         Transform {{ translation 0.3 0 2 children Shape {{ appearance Appearance {{ material \
         Material {{ diffuseColor 0.5 0.5 0.5 emissiveColor 0 0 0 transparency {transparency:.17e} }} }} \
         geometry Sphere {{ radius 1 }} }} }}\n\
         Transform {{ translation 0 0 -1.5 children Shape {{ appearance Appearance {{ material \
         Material {{ diffuseColor 0.7 0.7 0.7 }} }} geometry Sphere {{ radius 1.6 }} }} }}\n"
    )
}

/// What the camera ray `(o, w)` sees in [`gas_scene`], in closed form: the carried headlight
/// arrives at `o + t w` through the camera ray's own gas, so the scattering integral is
/// `p a sigma int exp(-2 sigma s) ds = p a (1 - exp(-2 sigma l)) / 2` over the chord `l`, and
/// the surface behind gets the light and sends its radiance through the gas once each.
/// With `strict`, only the surface is worked out (where the camera ray misses the gas): its
/// light crosses the gas along the view axis, a chord of its own.
fn gas_expected(o: DVec3, w: DVec3, sigma: f64, strict: bool) -> Option<f64> {
    let gas = (DVec3::new(0.3, 0.0, 2.0), 1.0);
    let surface = (DVec3::new(0.0, 0.0, -1.5), 1.6);
    let chord = roots(o, w, gas.0, gas.1).map_or(0.0, |(t0, t1)| t1 - t0.max(0.0));
    if strict && chord > 0.0 {
        return None;
    }
    let scattered = PHASE * 0.5 * -(-2.0 * sigma * chord).exp_m1() / 2.0;
    let lit = match roots(o, w, surface.0, surface.1) {
        Some((t0, _)) => {
            let x = o + t0 * w;
            let n = (x - surface.0).normalize();
            let seen = (-sigma * chord).exp();
            let light = if strict {
                let through = roots(x, DVec3::Z, gas.0, gas.1).map_or(0.0, |(a, b)| b - a);
                (-sigma * through).exp()
            } else {
                seen
            };
            0.7 * n.dot(DVec3::Z).max(0.0) * light * seen
        }
        None => 0.0,
    };
    Some(scattered + lit)
}

#[test]
fn in_gas_the_headlight_arrives_through_the_gas_in_front() {
    let sigma = 0.8;
    let body = gas_scene(sigma);
    let n = 24;
    // exact: within its tolerance and its error estimate.
    let tol = 1e-7;
    for strict in [false, true] {
        let opts = RenderOptions {
            integrator: Integrator::Exact,
            tol,
            headlight_shadows: strict,
            aovs: gtsphere::render::Aovs {
                error: true,
                ..Default::default()
            },
            ..RenderOptions::default()
        };
        let (film, rays) = render(&body, n, opts);
        let error = film.error.as_ref().expect("error");
        let mut checked = 0;
        for (k, &(o, w)) in rays.iter().enumerate() {
            let Some(expected) = gas_expected(o, w, sigma, strict) else {
                continue;
            };
            let got = film.rgb[k][0];
            let diff = (got - expected).abs();
            assert!(
                diff <= tol * expected.max(1e-3) && diff <= error[k] + 1e-12 * expected,
                "exact, strict {strict}, pixel {k}: got {got:e}, expected {expected:e}, \
                 error estimate {:e}",
                error[k]
            );
            checked += 1;
        }
        assert!(checked > 100, "{checked} pixels checked");
    }

    // mc: within 5 standard errors (over 576 pixels, a false alarm has probability < 1e-3);
    // the scattering varies from sample to sample, so the standard errors are not 0.
    let opts = RenderOptions {
        integrator: Integrator::Mc,
        spp: 64,
        sampler: SamplerKind::Center,
        aovs: gtsphere::render::Aovs {
            error: true,
            ..Default::default()
        },
        ..RenderOptions::default()
    };
    let (film, rays) = render(&body, n, opts);
    let se = film.error.as_ref().expect("error");
    for (k, &(o, w)) in rays.iter().enumerate() {
        let expected = gas_expected(o, w, sigma, false).expect("carried");
        let got = film.rgb[k][0];
        assert!(
            (got - expected).abs() <= 5.0 * se[k] + 1e-12 * expected,
            "mc pixel {k}: got {got:e}, expected {expected:e}, standard error {:e}",
            se[k]
        );
    }

    // march: the error falls with the step at first order or better (a quarter of the step,
    // at most a third of the error).
    let worst = |step: f64| {
        let opts = RenderOptions {
            integrator: Integrator::March { step },
            spp: 1,
            ..RenderOptions::default()
        };
        let (film, rays) = render(&body, n, opts);
        rays.iter()
            .enumerate()
            .map(|(k, &(o, w))| {
                (film.rgb[k][0] - gas_expected(o, w, sigma, false).expect("carried")).abs()
            })
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (worst(0.04), worst(0.01));
    assert!(
        fine <= coarse / 3.0,
        "march: worst error {coarse:e} at step 0.04, {fine:e} at 0.01"
    );
}
