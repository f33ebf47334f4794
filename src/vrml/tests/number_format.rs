//! Both VRML writers, the scene's (`vrml::write`) and the particle table's
//! (`particles::write`), format numbers by one rule (`vrml::number`), and the lexer reads
//! them back bit for bit.

use glam::DVec3;

use crate::vrml::write::write_scene;
use crate::vrml::{load_str, LoadOptions};

fn written(scene: &crate::scene::Scene) -> String {
    let mut out = Vec::new();
    write_scene(scene, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

/// The scene writer and the particle-table writer format a number by the same rule
/// (`vrml::number`): the same text for a sphere's position and radius, and it reads back as
/// the same f64.
#[test]
fn scene_and_particle_writers_write_the_same_numbers() {
    use crate::particles::read::{Num, Particle};
    use crate::particles::write::{Extras, ParticleWriter};

    // The text between `before` and the next `after`, in the first line that has it.
    fn field<'a>(text: &'a str, before: &str, after: &str) -> &'a str {
        let start = text
            .find(before)
            .unwrap_or_else(|| panic!("{before} in {text}"))
            + before.len();
        let len = text[start..].find(after).unwrap();
        &text[start..start + len]
    }
    let (one, _) = load_str(
        "one.wrl",
        "#VRML V2.0 utf8\nShape { geometry Sphere { radius 1 } }\n",
        &LoadOptions::default(),
    )
    .unwrap();
    let cases: [(f64, &str); 8] = [
        (0.1, "0.1"),
        (1e-300, "1e-300"),
        (1e300, "1e300"),
        (123456789.125, "123456789.125"),
        (-0.0, "-0"),
        (3.0, "3"),
        (1.0 / 3.0, "0.3333333333333333"),
        (-2.5e-7, "-2.5e-7"),
    ];
    for (v, want) in cases {
        let r = v.abs().max(1e-300);
        let mut scene = one.clone();
        scene.spheres[0].center = DVec3::splat(v);
        scene.spheres[0].radius = r;
        let from_scene = written(&scene);

        let mut w = ParticleWriter::new(Vec::new(), "numbers", true, false, None).unwrap();
        let num = |value| Num { value, text: None };
        w.particle(&Particle {
            position: [num(v); 3],
            radius: num(r),
            color: None,
            emission: None,
            transparency: None,
            profile: None,
        })
        .unwrap();
        let extras = Extras {
            viewpoint: false,
            lights: false,
        };
        let from_table = String::from_utf8(w.finish(extras).unwrap()).unwrap();

        let position = field(&from_scene, "Transform { translation ", " children");
        assert_eq!(position, [want; 3].join(" "), "{v:e}");
        assert_eq!(
            position,
            field(&from_table, "Transform { translation ", " children"),
            "{v:e}"
        );
        let radius = field(&from_scene, "Sphere { radius ", " }");
        assert_eq!(
            radius,
            field(&from_table, "Sphere { radius ", " }"),
            "{v:e}"
        );
        assert_eq!(radius, crate::vrml::number::Float(r).to_string());
        // The text reads back bit for bit, the sign of zero included.
        let (rest, n) = crate::vrml::lex::number(want).unwrap();
        assert!(
            rest.is_empty() && n.value.to_bits() == v.to_bits(),
            "{want}"
        );
        // And both files give the sphere back (the centre as a sum, 0 + t, where -0 is 0).
        for text in [&from_scene, &from_table] {
            let (back, _) = load_str("back.wrl", text, &LoadOptions::default()).unwrap();
            let s = back.spheres[0];
            assert_eq!(s.center, DVec3::splat(v), "{v:e} from\n{text}");
            assert_eq!(s.radius.to_bits(), r.to_bits(), "{v:e}");
        }
    }
}
