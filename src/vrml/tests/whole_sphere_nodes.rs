//! A plain sphere node (`Transform { translation .. children Shape { appearance Appearance {
//! material Material { .. } } geometry Sphere { radius .. } } }`, what exporters write per
//! particle) is read whole from the text and lowered at once; the result must be what its
//! events give, bit for bit: scene, warnings, notes, node counts and errors. Each file is
//! loaded both ways (`LoadOptions::replay_every_instance` turns the shortcut off), on one
//! reader and in pieces.

use super::proto_template::{same, same_limited};
use crate::vrml::lower::{load_bytes, LoadOptions};
use proptest::prelude::*;

/// A sphere node with its parts in random order and form; some are not plain (an extra
/// field, a DEF, a value out of range, a comment), so that both paths are taken, and with
/// `bad` some are errors (a radius that is not positive, values of the wrong length).
fn sphere_node(pick: &mut impl FnMut(usize) -> usize, bad: bool) -> String {
    let num = |pick: &mut dyn FnMut(usize) -> usize| {
        [
            "0",
            "1",
            "-2.5",
            "0.125",
            "3e-2",
            "1.0000000000000002",
            "0.28627450980392155",
        ][pick(7)]
        .to_string()
    };
    let mut material = Vec::new();
    for _ in 0..pick(4) {
        let (name, arity) = [
            ("diffuseColor", 3),
            ("emissiveColor", 3),
            ("specularColor", 3),
            ("shininess", 1),
            ("ambientIntensity", 1),
            ("transparency", 1),
        ][pick(6)];
        let values: Vec<String> = (0..arity)
            .map(|_| ["0.5", "0", "1", "0.25", "1.5"][pick(5)].to_string())
            .collect();
        material.push(format!("{name} {}", values.join(" ")));
    }
    let material = format!("Material {{ {} }}", material.join(" "));
    let appearance = match pick(4) {
        0 => String::new(),
        1 => "appearance Appearance { }".to_string(),
        2 if pick(8) == 0 => format!("appearance DEF M Appearance {{ material {material} }}"),
        _ => format!("appearance Appearance {{ material {material} }}"),
    };
    let radius = match pick(if bad { 16 } else { 8 }) {
        0 => String::new(),
        8 => "radius -1".to_string(),
        9 => format!("radius {} {}", num(pick), num(pick)),
        _ => format!("radius {}", ["0.5", "1e-3", "2", "0.00876"][pick(4)]),
    };
    let geometry = format!("geometry Sphere {{ {radius} }}");
    let mut shape = [appearance, geometry];
    if pick(2) == 0 {
        shape.swap(0, 1);
    }
    let shape = format!("Shape {{ {} {} }}", shape[0], shape[1]);
    let children = match pick(3) {
        0 => format!("children [ {shape} ]"),
        _ => format!("children {shape}"),
    };
    let translation = match pick(10) {
        0 => String::new(),
        1 if bad => "translation 1 2".to_string(),
        _ => format!("translation {} {} {}", num(pick), num(pick), num(pick)),
    };
    let mut members = vec![translation, children];
    match pick(12) {
        0 => members.push("rotation 0 0 1 0.5".into()),
        1 => members.push("# a comment\n".into()),
        2 => members.push(",".into()),
        _ => {}
    }
    if pick(2) == 0 {
        members.reverse();
    }
    let def = if pick(20) == 0 { "DEF T " } else { "" };
    format!("{def}Transform {{ {} }}", members.join(" "))
}

/// A file of sphere nodes at the top level and in containers where they are (grouping
/// nodes' children) and are not (a Switch's choice, a Collision's proxy, a node-valued
/// field) read whole; sometimes a PROTO named like a standard node comes first.
fn random_file(seed: u64) -> String {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut pick = move |n: usize| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s % n as u64) as usize
    };
    let mut text = String::from("#VRML V2.0 utf8\n");
    let bad = pick(5) == 0;
    if pick(10) == 0 {
        text += "PROTO Sphere [ field SFFloat radius 1 ] { Box { } }\n";
    }
    for _ in 0..(3 + pick(25)) {
        let node = sphere_node(&mut pick, bad);
        text += &match pick(8) {
            0 => format!(
                "Group {{ children [ {node} {} ] }}\n",
                sphere_node(&mut pick, bad)
            ),
            1 => format!("Transform {{ scale 2 3 4 rotation 0 1 0 1 children [ {node} ] }}\n"),
            2 => format!("Switch {{ whichChoice 0 choice [ {node} ] }}\n"),
            3 => format!("Collision {{ proxy {node} children [ {node} ] }}\n"),
            4 => format!("Anchor {{ children {node} }}\n"),
            _ => format!("{node}\n"),
        };
    }
    if text.contains("DEF T ") && pick(2) == 0 {
        text += "Transform { translation 5 0 0 children USE T }\n";
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]
    #[test]
    fn random_sphere_nodes_are_their_events(seed in any::<u64>()) {
        let text = random_file(seed);
        same(&text);
        // With a node limit the file passes part of the way through.
        same_limited(&text, seed % 60);
    }
}

#[test]
fn random_files_take_the_shortcut() {
    // So that the property above compares something: most random files read some sphere
    // nodes whole, and some are errors.
    let (mut used, mut errors) = (0, 0);
    for seed in 0..100u64 {
        match same(&random_file(seed)) {
            Some(r) => used += usize::from(r.whole_sphere_nodes > 0),
            None => errors += 1,
        }
    }
    assert!(
        used >= 40 && errors >= 5,
        "{used} used, {errors} errors of 100"
    );
}

#[test]
fn exporters_layouts_are_read_whole() {
    // PyMOL's (geometry first, three Material fields, brackets-free children, line breaks)
    // and the bench's (one line per particle) forms, at the top level and in a Group.
    let pymol = "Transform {\n translation -619.300781 -0.249160 -1.485840\n children Shape {\n  \
                 geometry Sphere { radius 1.800000 }\n  appearance Appearance {\n   material \
                 Material { diffuseColor 0.2000 0.2000 1.0000 \n specularColor 0.8 0.8 0.8 \n \
                 shininess 0.8 }\n  }\n }\n}\n";
    let flat = "Transform { translation -0.711058 0.292565 0.069184 children Shape { appearance \
                Appearance { material Material { diffuseColor 0.046 0.468 0.408 } } geometry \
                Sphere { radius 0.00876 } } }\n";
    let text = format!("#VRML V2.0 utf8\n{pymol}{flat}Group {{ children [\n{pymol}{flat}] }}\n");
    let r = same(&text).expect("loads");
    assert_eq!(r.whole_sphere_nodes, 4);
}

#[test]
fn in_pieces_too() {
    // Read on two threads in pieces of a few hundred bytes: the pieces read sphere nodes
    // whole as one reader does, and give one reader's scene.
    let text = (0..200u64).map(random_file).collect::<Vec<_>>();
    for t in text
        .iter()
        .filter(|t| !t.contains("PROTO") && !t.contains("DEF"))
    {
        let load = |threads, shortcut: bool| {
            let opts = LoadOptions {
                read_threads: threads,
                read_chunk_bytes: 300,
                replay_every_instance: !shortcut,
                ..LoadOptions::default()
            };
            load_bytes("scene.wrl", t.as_bytes().to_vec(), &opts)
                .map(|(s, r)| (format!("{s:?}"), r.warnings, r.nodes))
                .map_err(|e| e.to_string())
        };
        assert_eq!(load(2, true), load(1, false), "{t}");
    }
}
