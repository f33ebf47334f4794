//! `prepare` gives the gas of `GasParticle` instances and of plain Materials their profile
//! and centre density, in the BVH's primitives.

use crate::render::{self, PrepareOptions};
use crate::scene::Profile;
use crate::testing as support;
use crate::testing::GAS_PARTICLE_PROTO;

/// `prepare` gives each gas primitive its material's profile and the extinction at its centre
/// that keeps `transparency` the transmittance along a diameter (docs/model.md section 6,
/// `sigma0 = -ln(transparency) / (2 r I_f)`); `--profile` (`PrepareOptions::profile`) gives
/// every gas sphere its own; an opaque sphere's profile does not matter.
#[test]
fn prepare_gives_gas_its_profile_and_centre_density() {
    let (scene, _) = support::scene(&format!(
        "{GAS_PARTICLE_PROTO}GasParticle {{ profile \"quadratic\" transparency 0 }}\nGasParticle {{ profile \"linear\" radius 2 position 3 0 0 }}\n"
    ));
    let by_sphere = |prep: &render::Prepared, i: u32| {
        (0..prep.bvh.len() as u32)
            .map(|k| prep.bvh.prim(k))
            .find(|p| p.sphere == i)
            .expect("primitive")
    };
    let prep = render::prepare(scene.clone(), &PrepareOptions::default()).expect("prepare");
    let opaque = by_sphere(&prep, 0);
    assert!(!opaque.is_gas() && !opaque.is_profiled(), "{opaque:?}");
    let linear = by_sphere(&prep, 1);
    assert_eq!(linear.profile, Profile::Linear);
    // transparency 0.5, r = 2, I_f = 1/2.
    let want = 2f64.ln() / (2.0 * 2.0 * 0.5);
    assert!((linear.sigma - want).abs() <= 1e-15 * want, "{linear:?}");
    // Every gas sphere made constant: the constant extinction, -ln(0.5) / (2 r).
    let constant = PrepareOptions {
        profile: Some(Profile::Constant),
        ..PrepareOptions::default()
    };
    let prep = render::prepare(scene, &constant).expect("prepare");
    let p = by_sphere(&prep, 1);
    assert_eq!(p.profile, Profile::Constant);
    assert_eq!(p.sigma, -(0.5f64.ln()) / (2.0 * 2.0));
    // A gaussian for a plain Material: I_f by Simpson's rule here, not the renderer's erf.
    let (plain, _) = support::scene(
        "Shape { appearance Appearance { material Material { transparency 0.5 } } geometry Sphere { } }",
    );
    let gaussian = PrepareOptions {
        profile: Some(Profile::Gaussian { width: 0.5 }),
        ..PrepareOptions::default()
    };
    let prep = render::prepare(plain, &gaussian).expect("prepare");
    let p = prep.bvh.prim(0);
    assert_eq!(p.profile, Profile::Gaussian { width: 0.5 });
    let n = 2000;
    let f = |u: f64| (-u * u / (2.0 * 0.25)).exp();
    let h = 1.0 / n as f64;
    let simpson: f64 = (0..n)
        .map(|k| {
            let a = k as f64 * h;
            h / 6.0 * (f(a) + 4.0 * f(a + 0.5 * h) + f(a + h))
        })
        .sum();
    let want = 2f64.ln() / (2.0 * simpson);
    assert!(
        (p.sigma - want).abs() <= 1e-12 * want,
        "{} vs {want}",
        p.sigma
    );
}
