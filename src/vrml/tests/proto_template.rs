//! A PROTO whose body is one sphere (what `convert` writes) is lowered by a compiled template
//! rather than by replaying its body for every instance; the result must be the replay's bit
//! for bit: scene, warnings, notes, node counts and errors. Each file is loaded both ways
//! (`LoadOptions::replay_every_instance`), and the tests check that the template was really
//! used where it may be and not used where replaying does more.

use crate::particles::write::{Extras, ParticleWriter};
use crate::scene::Scene;
use crate::vrml::lower::{load_bytes, LoadOptions, LoadReport};
use proptest::prelude::*;

/// Loads `text` with an expansion budget of `base` plus one per byte.
pub fn load(text: &str, replay: bool, base: u64) -> Result<(Scene, LoadReport), String> {
    let opts = LoadOptions {
        read_threads: 1,
        replay_every_instance: replay,
        expansion_base: base,
        max_expansion: 1,
        ..LoadOptions::default()
    };
    load_bytes("scene.wrl", text.as_bytes().to_vec(), &opts).map_err(|e| e.to_string())
}

/// Loads `text` both ways and checks they agree; the template's report (`None`: an error,
/// the same both ways).
pub fn same_limited(text: &str, base: u64) -> Option<LoadReport> {
    match (load(text, true, base), load(text, false, base)) {
        (Ok((a, ra)), Ok((b, rb))) => {
            assert_eq!(ra.template_instances, 0);
            assert_eq!(ra.whole_sphere_nodes, 0);
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "scenes differ:\n{text}");
            assert!(a == b);
            assert_eq!(ra.warnings, rb.warnings, "{text}");
            assert_eq!(ra.notes, rb.notes);
            assert_eq!(ra.skipped, rb.skipped);
            assert_eq!(ra.nodes, rb.nodes, "{text}");
            assert_eq!(ra.expansion, rb.expansion, "{text}");
            Some(rb)
        }
        (Err(a), Err(b)) => {
            assert_eq!(a, b, "{text}");
            None
        }
        (a, b) => panic!(
            "replayed: {:?}\ntemplate: {:?}\n{text}",
            a.map(|r| r.0.spheres.len()),
            b.map(|r| r.0.spheres.len())
        ),
    }
}

pub fn same(text: &str) -> Option<LoadReport> {
    same_limited(text, LoadOptions::default().expansion_base)
}

/// The header `gtsphere convert` writes (its `PROTO Particle`), from the writer itself.
fn convert_header() -> String {
    let w = ParticleWriter::new(Vec::new(), "t.csv", false, false, None).unwrap();
    let none = Extras {
        viewpoint: false,
        lights: false,
    };
    String::from_utf8(w.finish(none).unwrap()).unwrap()
}

#[test]
fn converts_proto_is_lowered_by_its_template() {
    let mut text = convert_header();
    for i in 0..500 {
        let f = |k: usize| ((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0;
        text += &format!(
            "Particle {{ position {} {} {} radius {} color {} {} {} }}\n",
            f(1),
            f(2),
            f(3),
            0.01 + f(4),
            f(5),
            f(6),
            f(7)
        );
    }
    text += "Particle { }\nParticle { transparency 0.5 emission 1 0 0 }\n";
    let r = same(&text).expect("loads");
    assert_eq!(r.template_instances, 502);
}

#[test]
fn where_replaying_does_more_it_replays() {
    // Each of these instances must be replayed; the first one of each file is a plain one
    // that the template takes, so that the count shows which were.
    let cases = [
        // A transparency outside [0, 1]: replaying warns and clamps.
        ("Particle { transparency 1.5 }", 0),
        // A bad radius: an error at the body's radius.
        ("Particle { radius -1 }", 0),
        ("Particle { radius 0 }", 0),
        // Out of place: as a Shape's appearance (a warning); as a Collision's proxy (ignored,
        // while its children are not).
        (
            "Shape { appearance Particle { } geometry Sphere { } }",
            0,
        ),
        // A Switch's choice is lowered when the Switch closes, where its parent's children
        // stand: by template.
        ("Switch { whichChoice 0 choice Particle { } }", 1),
        ("Collision { proxy Particle { } children Particle { } }", 1),
        // Inside another PROTO's body, its value given by IS: the outer body is replayed, the
        // inner instance (whose IS was replaced while it was recorded) by template.
        (
            "PROTO Q [ field SFVec3f p 1 2 3 ] { Particle { position IS p } } Q { } Q { p 3 2 1 }",
            2,
        ),
        // An instance inside another PROTO's body with its own values (read from the body's
        // events into the template, not from the text), a field given twice (the last
        // counts).
        (
            "PROTO R [ ] { Particle { position 1 2 3 radius 0.5 position 4 5 6 } } R { } R { }",
            2,
        ),
        // DEF and USE of an instance: the DEF'd one by template, the USE replays its events.
        ("DEF A Particle { radius 2 } USE A", 2),
        // Inside transforms that rotate and scale: the template's sphere moves as replayed.
        (
            "Transform { rotation 0 0 1 0.5 scale 2 3 4 children [ Particle { position 1 2 3 } Transform { translation 1 0 0 children Particle { } } ] }",
            2,
        ),
        // A Transform that makes a centre infinite: the same error at the body's Transform.
        ("Particle { position 1e308 0 0 } Transform { scale 1e10 1 1 children Particle { position 1e308 0 0 } }", 2),
        // An unknown field of the instance: the same warning, then the template.
        ("Particle { colour 1 0 0 }", 1),
    ];
    for (tail, templated) in cases {
        let text = format!(
            "{}Particle {{ position 9 9 9 }}\n{tail}\n",
            convert_header()
        );
        if let Some(r) = same(&text) {
            assert_eq!(r.template_instances, 1 + templated, "{tail}");
        }
    }
    // A PROTO named like a standard node could stand for the body's nodes: replay all.
    let text = format!(
        "{}PROTO Cone [ ] {{ Group {{ }} }}\nParticle {{ }} Particle {{ }}\n",
        convert_header()
    );
    assert_eq!(same(&text).unwrap().template_instances, 0);
}

#[test]
fn instances_of_several_protos_in_turn_are_the_replay() {
    // Instances read whole remember the last PROTO found by name and the fields the last
    // instance gave, in its order: two PROTOs whose fields share names but not types, in
    // turn, in varying orders, a field given twice, one PROTO declared again under the same
    // name, and a wrong value after a run of right ones.
    let a = "PROTO A [ field SFVec3f p 0 0 0 field SFFloat r 1 field SFColor c 1 1 1 ] \
             { Transform { translation IS p children Shape { appearance Appearance { \
             material Material { diffuseColor IS c } } geometry Sphere { radius IS r } } } }";
    let b = "PROTO B [ field SFFloat p 1 field SFVec3f r 0 0 0 field MFFloat c [ ] ] \
             { Transform { translation IS r children Shape { geometry Sphere { radius IS p } } } }";
    let a2 = "PROTO A [ field SFFloat r 1 field SFVec3f p 0 0 0 ] \
              { Transform { translation IS p children Shape { geometry Sphere { radius IS r } } } }";
    let body = [
        "A { p 1 2 3 r 0.5 c 1 0 0 }",
        "B { p 0.5 r 1 2 3 }",
        "A { p 1 2 3 r 0.5 c 0 1 0 }",
        "B { p 0.25 r 3 2 1 c 7 }",
        "A { r 2 p 1 1 1 }",
        "A { r 2 p 1 1 1 r 3 }",
        "A { p 1 2 3 p 4 5 6 c 0 0 1 }",
        "B { r 1 1 1 p 2 }",
        "A { p 1 2 3 r 0.5 c 0 1 0 }",
        a2,
        "A { p 1 2 3 r 0.5 }",
        "A { r 0.5 p 3 2 1 }",
    ];
    let text = format!("#VRML V2.0 utf8\n{a}\n{b}\n{}\n", body.join("\n"));
    let r = same(&text).expect("loads");
    assert_eq!(r.template_instances, 11);
    // A value of the wrong length once the fields are known (an error both ways), and the
    // other PROTO's field of that name in the same place (which takes it).
    for tail in [
        "A { p 1 2 r 0.5 }",
        "B { p 1 2 3 }",
        "B { p 2 r 1 2 3 } A { p 2 r 1 }",
    ] {
        let text = format!(
            "#VRML V2.0 utf8\n{a}\n{b}\nA {{ p 1 2 3 r 0.5 }} B {{ p 2 r 1 2 3 }}\n{tail}\n"
        );
        same(&text);
    }
}

#[test]
fn the_expansion_limit_is_the_replays() {
    // Ten instances USEd fifty times: far more spent than bytes, so that the limit (the base
    // plus one per byte read) is reached inside an instance, at each node in turn.
    let mut text = convert_header();
    text += "DEF G Group { children [";
    for i in 0..10 {
        text += &format!(" Particle {{ radius 0.{} }}", i + 1);
    }
    text += " ] }\nGroup { children [";
    for _ in 0..50 {
        text += " USE G";
    }
    text += " ] }\n";
    let all = same(&text).expect("loads without a limit");
    assert_eq!(all.template_instances, 510);
    let over = all.expansion - text.len() as u64;
    let (mut errs, mut oks) = (0, 0);
    for max in over - 13..=over + 1 {
        match same_limited(&text, max) {
            None => errs += 1,
            Some(_) => oks += 1,
        }
    }
    assert_eq!((errs, oks), (13, 2));
}

#[test]
fn bodies_that_are_not_templates_replay() {
    let bodies = [
        // A DEF in the body, a rotation, a second child, a ROUTE-less extra field.
        "DEF T Transform { translation IS p children Shape { geometry Sphere { } } }",
        "Transform { rotation 0 1 0 1 children Shape { geometry Sphere { } } }",
        "Transform { children [ Shape { geometry Sphere { } } Shape { geometry Sphere { } } ] }",
        "Transform { children Shape { geometry Box { } } }",
        "Transform { children Shape { appearance Appearance { texture ImageTexture { } } geometry Sphere { } } }",
        "Group { children Shape { geometry Sphere { } } }",
        "Transform { children Shape { appearance Appearance { material Material { shininess 40 } } geometry Sphere { } } }",
    ];
    for body in bodies {
        let text = format!(
            "#VRML V2.0 utf8\nPROTO P [ field SFVec3f p 0 0 0 ] {{ {body} }}\nP {{ }} P {{ p 1 2 3 }}\n"
        );
        let r = same(&text);
        assert_eq!(r.map_or(0, |r| r.template_instances), 0, "{body}");
    }
}

/// A random template body: each part optional, each value given or `IS` an interface field
/// (whose default may be out of range, so that some instances are replayed).
fn random_file(seed: u64) -> String {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let mut pick = |n: usize| (next() % n as u64) as usize;
    let mut body_material = String::new();
    let mut iface = String::from(
        "field SFVec3f p 0 0 0 field SFFloat r 1 field SFColor c 0.8 0.8 0.8 field SFFloat t 0 field SFFloat s 0.2 field SFNode n NULL field MFFloat m [ ]",
    );
    for (name, is, given) in [
        ("diffuseColor", "c", "0.1 0.2 0.3"),
        ("emissiveColor", "c", "0 0 1"),
        ("specularColor", "c", "1 1 1"),
        ("transparency", "t", "0.5"),
        ("shininess", "s", "0.9"),
        ("ambientIntensity", "t", "0.3"),
    ] {
        match pick(3) {
            0 => body_material += &format!(" {name} IS {is}"),
            1 => body_material += &format!(" {name} {given}"),
            _ => {}
        }
    }
    let appearance = match pick(4) {
        0 => String::new(),
        1 => "appearance Appearance { }".to_string(),
        _ => format!("appearance Appearance {{ material Material {{{body_material} }} }}"),
    };
    let translation = ["", "translation IS p", "translation 1 2 3"][pick(3)];
    let radius = ["", "radius IS r", "radius 0.5"][pick(3)];
    let body = if pick(2) == 0 {
        format!("Transform {{ {translation} children Shape {{ {appearance} geometry Sphere {{ {radius} }} }} }}")
    } else {
        format!("Transform {{ children [ Shape {{ geometry Sphere {{ {radius} }} {appearance} }} ] {translation} }}")
    };
    if pick(4) == 0 {
        iface = iface.replace("SFFloat t 0", "SFFloat t 1.5");
    }
    let mut text = format!("#VRML V2.0 utf8\nPROTO P [ {iface} ] {{ {body} }}\n");
    let bad_file = pick(4) == 0;
    let groups = [
        "",
        "Transform { scale 2 2 2 children [",
        "Group { children [",
        "Transform { rotation 1 0 0 1 translation 1 1 1 children [",
    ];
    for _ in 0..(5 + pick(40)) {
        let g = groups[pick(groups.len())];
        let mut inst = String::from("P {");
        // Mostly plain numbers, which an instance read into its template keeps as they come;
        // the rest makes it recorded part way (a bracketed list, a node, an unknown field), and
        // a field may come twice. One file in four has values of the wrong type or length
        // (errors both ways).
        let wrong = if bad_file {
            &["1 2", "\"x\"", "TRUE"][..]
        } else {
            &[][..]
        };
        for (f, vals, odds) in [
            ("p", &["1 2 3", "-1 0 0.5"][..], 3),
            ("r", &["0.25", "2", "-1"][..], 3),
            ("c", &["0 0 0", "0.5 0.25 1"][..], 3),
            ("t", &["0", "0.75", "2"][..], 3),
            ("s", &["0.5", "3"][..], 3),
            ("n", &["NULL", "Group { }"][..], 6),
            ("m", &["[ 1 2 3 4 ]", "[ 1 ]", "2"][..], 6),
            ("q", &["1"][..], 8),
            ("p", &["4 5 6"][..], 5),
            (["p", "r", "s"][pick(3)], wrong, 20),
        ] {
            if !vals.is_empty() && pick(odds) == 0 {
                inst += &format!(" {f} {}", vals[pick(vals.len())]);
            }
        }
        inst += " }";
        if g.is_empty() {
            text += &format!("{inst}\n");
        } else {
            text += &format!("{g} {inst} ] }}\n");
        }
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    #[test]
    fn random_templates_are_the_replay(seed in any::<u64>()) {
        same(&random_file(seed));
    }
}

#[test]
fn random_templates_take_the_template() {
    // So that the property above compares something: most random files use the template.
    let used = (0..100u64)
        .filter(|&seed| same(&random_file(seed)).is_some_and(|r| r.template_instances > 0))
        .count();
    assert!(used >= 50, "{used} of 100");
}
