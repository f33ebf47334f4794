//! `GasParticle`: the PROTO that gives gas spheres a density profile (docs/model.md section 6) in
//! standard VRML97. Recognised by its name and `profile` field; every Material of an instance
//! takes the instance's profile; bad names and widths are positioned errors; the PROTO's
//! template and its replay agree. (What `prepare` makes of the profiles is checked in the
//! library's unit tests, `render/tests/gas_particle.rs`.)

use gtsphere::scene::{Profile, Scene};
use gtsphere::vrml::{load_str, LoadOptions};

use crate::support;

/// The PROTO as `convert` and the VRML writer declare it, in a file of its own.
fn proto() -> String {
    format!("#VRML V2.0 utf8\n{}", support::GAS_PARTICLE_PROTO)
}

fn profiles(scene: &Scene) -> Vec<Profile> {
    scene
        .spheres
        .iter()
        .map(|s| scene.material_of(s).profile)
        .collect()
}

#[test]
fn each_instance_gives_its_spheres_its_profile() {
    let proto = proto();
    let text = format!(
        "{proto}GasParticle {{ }}
GasParticle {{ profile \"linear\" transparency 0.25 }}
GasParticle {{ profile \"quadratic\" position 1 0 0 }}
GasParticle {{ profile \"gaussian\" }}
GasParticle {{ profile \"gaussian\" width 0.25 }}
GasParticle {{ profile \"constant\" }}
Transform {{ scale 2 1 1 children GasParticle {{ profile \"linear\" }} }}
Shape {{ appearance Appearance {{ material Material {{ transparency 0.5 }} }} geometry Sphere {{ }} }}
"
    );
    for replay in [false, true] {
        let opts = LoadOptions {
            replay_every_instance: replay,
            ..LoadOptions::default()
        };
        let (scene, report) = load_str("test.wrl", &text, &opts).expect("loads");
        assert!(report.warnings.is_empty(), "{:?}", report.warnings);
        assert_eq!(
            profiles(&scene),
            [
                Profile::Constant,
                Profile::Linear,
                Profile::Quadratic,
                Profile::Gaussian { width: 1.0 / 3.0 },
                Profile::Gaussian { width: 0.25 },
                Profile::Constant,
                Profile::Linear,
                Profile::Constant,
            ]
        );
        // The rest of the material is the instance's, as for any PROTO.
        let m = scene.material_of(&scene.spheres[1]);
        assert_eq!(m.transparency, 0.25);
        assert_eq!(scene.spheres[2].center.x, 1.0);
        // The profile is part of the material: equal fields, other profile, other material.
        assert_eq!(scene.spheres[0].material, scene.spheres[5].material);
        assert_ne!(scene.spheres[0].material, scene.spheres[3].material);
        assert_eq!(report.template_instances, if replay { 0 } else { 7 });
    }
}

#[test]
fn bad_names_and_widths_are_errors_at_the_field() {
    let proto = proto();
    let cases = [
        (
            "GasParticle { profile \"fuzzy\" }",
            "test.wrl:21:15: GasParticle: unknown density profile `fuzzy` (expected constant, linear, quadratic or gaussian)",
        ),
        (
            "GasParticle { profile \"gaussian\" width 0 }",
            "test.wrl:21:34: GasParticle: gaussian width 0 is outside (0, 1]",
        ),
        (
            "GasParticle { profile \"gaussian\" width 1.5 }",
            "test.wrl:21:34: GasParticle: gaussian width 1.5 is outside (0, 1]",
        ),
    ];
    for (instance, want) in cases {
        let e = support::error_of(&format!("{proto}{instance}\n"));
        assert!(e.starts_with(want), "{instance}:\n{e}\nwanted {want}");
    }
    // A default the PROTO declares is checked where it is declared, when an instance uses it.
    let bad_default = proto.replace("profile \"constant\"", "profile \"cloudy\"");
    let e = support::error_of(&format!("{bad_default}GasParticle {{ }}\n"));
    assert!(
        e.starts_with("test.wrl:8:3: GasParticle: unknown density profile `cloudy`"),
        "{e}"
    );
}

#[test]
fn a_width_for_another_profile_is_a_warning() {
    let proto = proto();
    let (scene, report) = support::load(&format!(
        "{proto}GasParticle {{ profile \"linear\" width 0.5 }}\n"
    ));
    assert_eq!(profiles(&scene), [Profile::Linear]);
    assert_eq!(report.warnings.len(), 1);
    let w = report.warnings[0].to_string();
    assert!(
        w.starts_with(
            "test.wrl:21:32: warning: GasParticle width applies to the gaussian profile only: ignored"
        ),
        "{w}"
    );
}

#[test]
fn only_the_name_and_signature_are_recognised() {
    let proto = proto();
    // Another name, or a GasParticle whose profile is not an SFString field: constant gas.
    for text in [
        proto.replace("GasParticle", "Blob") + "Blob { profile \"linear\" }\n",
        proto.replace("SFString profile \"constant\"", "SFFloat profile 1")
            + "GasParticle { profile 2 }\n",
    ] {
        let (scene, _) = support::load(&text);
        assert_eq!(profiles(&scene), [Profile::Constant], "{text}");
    }
}
