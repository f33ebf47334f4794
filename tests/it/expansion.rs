//! The expansion budget: small files that multiply through USE, PROTO, IS or generated
//! geometry, and gzip data that inflates far beyond its size, are refused at the construct
//! that went over, before the copies are made; ordinary files never come near it.

use std::io::Write;

use gtsphere::vrml::{load_bytes, LoadOptions, LoadReport};

fn load(text: &[u8], opts: &LoadOptions) -> Result<LoadReport, String> {
    load_bytes("scene.wrl", text.to_vec(), opts)
        .map(|(_, r)| r)
        .map_err(|e| e.to_string())
}

fn refused(text: &str) -> String {
    load(text.as_bytes(), &LoadOptions::default()).expect_err("refused")
}

/// `levels` PROTOs, each passing its MFNode field twice to the one before: 2^levels copies
/// of the one node given at the top.
fn doubling_mfnode_protos(levels: usize) -> String {
    let mut text = String::from(
        "#VRML V2.0 utf8\nPROTO L0 [ field MFNode c [] ] { Group { children IS c } }\n",
    );
    for i in 1..=levels {
        text += &format!(
            "PROTO L{i} [ field MFNode c [] ] {{ L{} {{ c [ Group {{ children IS c }} \
             Group {{ children IS c }} ] }} }}\n",
            i - 1
        );
    }
    text + &format!("L{levels} {{ c Shape {{ geometry Sphere {{}} }} }}\n")
}

#[test]
fn an_mfnode_doubled_through_proto_levels_is_refused_at_its_is() {
    // 40 levels would be 2^40 copies (the process once died asking for 10 GiB).
    let e = refused(&doubling_mfnode_protos(40));
    assert!(
        e.contains("this IS value takes the scene past its expansion limit"),
        "{e}"
    );
    // Refused at an IS of one of the PROTO declarations (lines 3 to 42), with its line shown.
    let line: usize = e.split(':').nth(1).unwrap().parse().unwrap();
    assert!((3..=42).contains(&line), "{e}");
    assert!(e.contains("children IS c"), "{e}");
    // A few levels are an ordinary scene, spending a few units per copy.
    let text = doubling_mfnode_protos(6);
    let (scene, r) = load_bytes("ok.wrl", text.into_bytes(), &LoadOptions::default()).unwrap();
    assert_eq!(scene.spheres.len(), 64);
    assert!(r.expansion < 10_000, "{}", r.expansion);
}

#[test]
fn proto_instances_doubling_per_level_are_refused_at_a_node() {
    let mut text = String::from("#VRML V2.0 utf8\nPROTO Q0 [] { Shape { geometry Sphere {} } }\n");
    for i in 1..=30 {
        text += &format!(
            "PROTO Q{i} [] {{ Group {{ children [ Q{0} {{}} Q{0} {{}} ] }} }}\n",
            i - 1
        );
    }
    text += "Q30 {}\n";
    let e = refused(&text);
    assert!(
        e.contains("this node takes the scene past its expansion limit"),
        "{e}"
    );
    // With a budget of exactly what 2^16 spheres spend, 16 levels load and 17 do not.
    let sixteen = text.replace("Q30 {}", "Q16 {}");
    let (scene, r) = load_bytes(
        "ok.wrl",
        sixteen.clone().into_bytes(),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(scene.spheres.len(), 1 << 16);
    let opts = LoadOptions {
        expansion_base: r.expansion,
        max_expansion: 0,
        ..LoadOptions::default()
    };
    assert!(load(sixteen.as_bytes(), &opts).is_ok());
    let e = load(text.replace("Q30 {}", "Q17 {}").as_bytes(), &opts).unwrap_err();
    assert!(e.contains("past its expansion limit"), "{e}");
}

#[test]
fn def_use_doubling_is_refused_whatever_the_nodes_are() {
    // Each level a Transform of two USEs of the level below: 2^30 spheres from 2 KB.
    let mut text = String::from(
        "#VRML V2.0 utf8\nDEF A0 Transform { children Shape { geometry Sphere { radius 0.1 } } }\n",
    );
    for i in 1..=30 {
        text += &format!(
            "DEF A{i} Transform {{ translation 0.1 0 0 children [ USE A{0} USE A{0} ] }}\n",
            i - 1
        );
    }
    let e = refused(&text);
    assert!(e.contains("this USE takes the scene past"), "{e}");
    // A DEF'd mesh reused costs its triangles at each USE, though it is lowered once.
    let mut text = String::from(
        "#VRML V2.0 utf8\nDEF M0 Transform { children Shape { geometry IndexedFaceSet { \
         coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 -1 ] } } }\n",
    );
    for i in 1..=30 {
        text += &format!(
            "DEF M{i} Transform {{ children [ USE M{0} USE M{0} ] }}\n",
            i - 1
        );
    }
    let e = refused(&text);
    assert!(
        e.contains("takes the scene past its expansion limit"),
        "{e}"
    );
}

#[test]
fn a_large_extrusion_from_small_text_is_refused_before_it_is_built() {
    // 2000 spine points and 2001 cross-section points: 4 million points, 8 million
    // triangles, from 40 KB.
    let spine: Vec<String> = (0..2000).map(|i| format!("0 {i} 0")).collect();
    let cross: Vec<String> = (0..2001).map(|i| format!("{} {}", i % 3, i % 5)).collect();
    let text = format!(
        "#VRML V2.0 utf8\nShape {{ geometry Extrusion {{ spine [ {} ] crossSection [ {} ] }} }}\n",
        spine.join(", "),
        cross.join(", ")
    );
    let e = refused(&text);
    assert!(e.contains("this Extrusion takes the scene past"), "{e}");
    assert!(e.starts_with("scene.wrl:2:"), "{e}");
    // A tube of ordinary size is drawn.
    let small = text
        .replace(&spine[10..].join(", "), "0 10 0")
        .replace(&cross[32..].join(", "), "0 0");
    let (scene, _) = load_bytes("ok.wrl", small.into_bytes(), &LoadOptions::default()).unwrap();
    assert!(!scene.surfaces.is_empty());
}

fn gzip(text: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    enc.write_all(text).unwrap();
    enc.finish().unwrap()
}

#[test]
fn gzip_data_that_inflates_far_beyond_its_size_is_refused() {
    // 24 MiB of spaces compress to about 24 KB: a ratio of 1000.
    let mut text = b"#VRML V2.0 utf8\n".to_vec();
    text.resize(24 << 20, b' ');
    text.extend_from_slice(b"Shape { geometry Sphere {} }\n");
    let gz = gzip(&text);
    assert!(gz.len() < 64 << 10, "{}", gz.len());
    let e = load(&gz, &LoadOptions::default()).unwrap_err();
    assert!(
        e.contains("the gzip data inflates more than 128 times its compressed size"),
        "{e}"
    );
    // A higher ratio lets it through; the spaces are passed, not held.
    let opts = LoadOptions {
        max_expansion: 200,
        ..LoadOptions::default()
    };
    let r = load(&gz, &opts).unwrap();
    assert_eq!(r.bytes, text.len() as u64);
    // Ordinary text compressed as much as gzip can is far below the default ratio.
    let mut lines = b"#VRML V2.0 utf8\n".to_vec();
    for i in 0..20_000 {
        lines.extend_from_slice(
            format!(
                "Transform {{ translation {i} 0 0 children Shape {{ geometry Sphere {{ }} }} }}\n"
            )
            .as_bytes(),
        );
    }
    assert!(load(&gzip(&lines), &LoadOptions::default()).is_ok());
}

#[test]
fn the_documented_limits_are_the_readers() {
    use gtsphere::vrml::{DEFAULT_EXPANSION_BASE, DEFAULT_MAX_EXPANSION};
    let page =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/vrml.md")).unwrap();
    let base = DEFAULT_EXPANSION_BASE.to_string();
    let grouped = format!("{},{},{}", &base[..1], &base[1..4], &base[4..]);
    let opts = LoadOptions::default();
    for said in [
        format!("may\n  reach {grouped} plus {DEFAULT_MAX_EXPANSION} per byte"),
        format!("sets the {DEFAULT_MAX_EXPANSION}."),
        format!("16 MiB plus 8 K ({}) times", opts.inflate_ratio()),
        format!("at most {} deep", 200),
        format!("EXTERNPROTOs at most {}.", opts.max_inline_depth),
    ] {
        assert!(page.contains(&said), "docs/vrml.md does not say: {said}");
    }
    assert_eq!(gtsphere::input::INFLATE_BASE, 16 << 20);
}

#[test]
fn a_gzip_stream_cut_short_is_a_positioned_error() {
    let gz = gzip(b"#VRML V2.0 utf8\nShape { geometry Sphere {} }\n");
    for cut in [5, gz.len() / 2, gz.len() - 4] {
        let e = load(&gz[..cut], &LoadOptions::default()).unwrap_err();
        assert!(
            e.starts_with("scene.wrl:") && e.contains("cannot read further"),
            "{cut}: {e}"
        );
    }
}
