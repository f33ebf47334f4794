//! Reading a file in pieces on several threads gives what one reader gives: the same scene
//! (every sphere, its order, materials, lights and their scopes, viewpoints), the same
//! warnings and counts, and the same errors. The pieces here are tiny, so that small files
//! are cut in many places; files where a piece depends on another across a cut (DEF/USE,
//! PROTOs) are generated on purpose, and the report says whether the pieces' result was
//! kept or the file read again.

use gtsphere::scene::Scene;
use gtsphere::vrml::{load_bytes, LoadOptions, LoadReport};
use proptest::prelude::*;

fn load(text: &str, threads: usize, chunk: u64) -> Result<(Scene, LoadReport), String> {
    let opts = LoadOptions {
        read_threads: threads,
        read_chunk_bytes: chunk,
        ..LoadOptions::default()
    };
    load_bytes("scene.wrl", text.as_bytes().to_vec(), &opts).map_err(|e| e.to_string())
}

/// Loads `text` by one reader and in pieces, and checks that the two agree bit for bit.
/// Returns the pieces' report.
fn same(text: &str, threads: usize, chunk: u64) -> Option<LoadReport> {
    agree(load(text, 1, chunk), load(text, threads, chunk), text)
}

/// One reader's result and the pieces' agree bit for bit (scene, messages, counts).
type Loaded = Result<(Scene, LoadReport), String>;
fn agree(one: Loaded, many: Loaded, text: &str) -> Option<LoadReport> {
    match (one, many) {
        (Ok((a, ra)), Ok((b, rb))) => {
            assert_eq!(ra.read_pieces, 0);
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "scenes differ:\n{text}");
            assert!(a == b);
            assert_eq!(ra.warnings, rb.warnings, "{text}");
            assert_eq!(ra.notes, rb.notes);
            assert_eq!(ra.skipped, rb.skipped);
            assert_eq!(ra.nodes, rb.nodes);
            assert_eq!(ra.bytes, rb.bytes);
            assert_eq!(ra.mesh_spheres, rb.mesh_spheres);
            Some(rb)
        }
        (Err(a), Err(b)) => {
            assert_eq!(a, b, "{text}");
            None
        }
        (a, b) => panic!(
            "one reader: {:?}\nin pieces: {:?}\n{text}",
            a.map(|r| r.1.read_pieces),
            b.map(|r| r.1.read_pieces)
        ),
    }
}

fn particle(i: usize) -> String {
    let c = |k: usize| ((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0;
    format!(
        "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ diffuseColor {} {} {} }} }} geometry Sphere {{ radius {} }} }} }}\n",
        c(1) * 10.0,
        c(2) * 10.0,
        c(3) * 10.0,
        c(4),
        c(5),
        c(6),
        0.1 + c(7) * 0.2
    )
}

#[test]
fn the_three_layouts_and_ellipsoids_are_read_in_pieces() {
    let flat: String = (0..300).map(particle).collect();
    let flat = format!("#VRML V2.0 utf8\n{flat}");
    let group: String = (0..300).map(particle).collect();
    let group = format!(
        "#VRML V2.0 utf8\nViewpoint {{ position 0 0 30 }}\nTransform {{ children [\n{group}] translation 1 2 3 scale 2 1 1 }}\n"
    );
    let mut proto = String::from(
        "#VRML V2.0 utf8\nPROTO P [ field SFVec3f c 0 0 0 field SFFloat r 1 field SFColor k 1 1 1 ] {\n  Transform { translation IS c children Shape { appearance Appearance { material Material { diffuseColor IS k } } geometry Sphere { radius IS r } } }\n}\n",
    );
    for i in 0..300 {
        proto += &format!("P {{ c {i} 0 1 r 0.{} k 0.5 0.{} 1 }}\n", 1 + i % 9, i % 10);
    }
    // Each particle an ellipsoid of its own: every piece's ellipsoids are numbered on from
    // those of the pieces before it.
    let scaled: String = (0..300)
        .map(|i| {
            let s = 1.0 + (i % 7) as f64 / 4.0;
            format!("Transform {{ scale {s} 1 2 children {} }}\n", particle(i))
        })
        .collect();
    let scaled = format!("#VRML V2.0 utf8\n{scaled}");
    for text in [&flat, &group, &proto, &scaled] {
        for threads in [2, 3] {
            let r = same(text, threads, 500).expect("loads");
            assert!(
                r.read_pieces >= 10,
                "{} pieces {:?}",
                r.read_pieces,
                r.read_again
            );
            assert_eq!(r.read_again, None);
            // The top level's pieces go to the file's end; the Group's list ends in its last
            // piece, from which the main reader reads on.
            if text == &group {
                let on = r.read_on.expect("read on");
                assert!(on.contains("the region's list ends"), "{on}");
            } else {
                assert_eq!(r.read_on, None);
            }
        }
    }
}

/// The cuts after the first are guessed at lines that start as the region's first sibling's;
/// each piece is checked, and the main reader reads on from the first that fails, with the
/// same result as one reader.
#[test]
fn guessed_cuts_are_checked() {
    let body: String = (0..150).map(particle).collect();
    let reads_on = |text: &str, why: &str| {
        for threads in [2, 3] {
            let r = same(text, threads, 500).expect("loads");
            assert!(r.read_pieces >= 2 && r.read_again.is_none(), "{r:?}");
            let on = r.read_on.expect("read on");
            assert!(on.contains(why), "{on}");
        }
    };
    // Nested nodes at the siblings' indentation: a guessed cut inside a node.
    let nested: String = (0..150)
        .map(|i| format!("Group {{ children [\nShape {{}}\n{}] }}\n", particle(i)))
        .collect();
    reads_on(
        &format!(
            "#VRML V2.0 utf8\n{}{nested}",
            &body[..body.match_indices('\n').nth(9).unwrap().0 + 1]
        ),
        "it ends inside a node",
    );
    // Two lists one after the other: a piece may close the first and open the second, and
    // end as deep as it began.
    reads_on(
        &format!(
            "#VRML V2.0 utf8\nTransform {{ translation 5 0 0 children [\n{body}] }}\nTransform {{ translation -5 0 0 children [\n{body}] }}\n"
        ),
        "the region's list ends",
    );
    // A PROTO declared among the siblings and instanced after them.
    reads_on(
        &format!(
            "#VRML V2.0 utf8\n{body}PROTO R [ field SFFloat r 1 ] {{ Shape {{ geometry Sphere {{ radius IS r }} }} }}\n{body}R {{ r 2 }}\n"
        ),
        "it declares a PROTO",
    );
    // Strings across lines, holding lines like a sibling's: a guessed cut inside a string.
    let strings: String = (0..150)
        .map(|i| {
            format!(
                "{}WorldInfo {{ info [ \"a\nTransform {{ b\" ] }}\n",
                particle(i)
            )
        })
        .collect();
    reads_on(&format!("#VRML V2.0 utf8\n{body}{strings}"), "");
}

#[test]
fn a_use_across_a_cut_is_read_again_by_one_reader() {
    // A DEF in one piece, USEd in a later one: the later piece cannot see it, and says so.
    let mut text = String::from("#VRML V2.0 utf8\nDEF A Shape { geometry Sphere {} }\n");
    for i in 0..100 {
        text += &particle(i);
    }
    text += "DEF B Shape { geometry Sphere { radius 2 } }\n";
    for i in 0..100 {
        text += &particle(i);
    }
    text += "Transform { translation 1 1 1 children USE B }\nTransform { children USE A }\n";
    let r = same(&text, 2, 500).expect("loads");
    assert!(r.read_again.is_some(), "{:?}", r.read_pieces);
    // A DEF of the prefix USEd in a piece: fine, every piece reads the prefix.
    let mut text = String::from("#VRML V2.0 utf8\nDEF A Shape { geometry Sphere {} }\n");
    for i in 0..200 {
        text += &particle(i);
        text += "Transform { translation 0 1 0 children USE A }\n";
    }
    let r = same(&text, 2, 500).expect("loads");
    assert!(r.read_pieces > 5 && r.read_again.is_none());
}

#[test]
fn errors_and_warnings_are_one_readers() {
    let body: String = (0..200).map(particle).collect();
    let cases = [
        format!("#VRML V2.0 utf8\n{body}Transform {{ children USE Nobody }}\n{body}"),
        format!("#VRML V2.0 utf8\n{body}Shape {{ geometry Sphere {{ radius -1 }} }}\n{body}"),
        format!("#VRML V2.0 utf8\n{body}Frobnicate {{ }}\nShape {{ wibble 3 }}\n{body}"),
        format!("#VRML V2.0 utf8\nGroup {{ children [\n{body}\n"),
        format!("#VRML V2.0 utf8\n{body}}}\n"),
    ];
    for text in &cases {
        same(text, 2, 700);
    }
}

#[test]
fn a_piece_stands_up_to_where_its_list_ends() {
    // The region's list ends in its last piece: what the piece read before the end stands,
    // and the main reader reads on from the end, with one reader's lines and messages after
    // it (a warning, an error), from memory and from the file.
    let body: String = (0..200).map(particle).collect();
    let cases = [
        format!("#VRML V2.0 utf8\nGroup {{ children [\n{body}]\n\n}}\nFrobnicate {{ }}\n"),
        format!("#VRML V2.0 utf8\nGroup {{ children [\n{body}\n}}\n]\n"),
        format!("#VRML V2.0 utf8\n{body}\n}}\n{body}"),
    ];
    for text in &cases {
        for r in [same(text, 2, 700), same_on_disk(text, 2, 700, false)] {
            let Some(r) = r else { continue };
            assert!(r.read_pieces > 5 && r.read_again.is_none(), "{r:?}");
            let on = r.read_on.expect("read on");
            assert!(on.contains("the region's list ends"), "{on}");
        }
    }
}

/// One random node of a generated scene, `depth` levels down.
fn node(rng: &mut impl FnMut() -> u64, depth: usize, defs: &mut Vec<String>) -> String {
    let pick = rng() % 16;
    let mut s = String::new();
    // A DEF'd particle or group; its name is USEable once the node is written.
    let name = (pick <= 7 && rng() % 6 == 0).then(|| format!("N{}", rng() % 8));
    let def = name.as_ref().map_or(String::new(), |n| format!("DEF {n} "));
    match pick {
        0..=5 => {
            s += &particle(rng() as usize % 1000).replacen(
                "Transform",
                &format!("{def}Transform"),
                1,
            )
        }
        6 | 7 if depth < 3 => {
            let kids: String = (0..rng() % 6).map(|_| node(rng, depth + 1, defs)).collect();
            let ty = ["Group", "Transform", "Anchor", "Billboard"][rng() as usize % 4];
            let after = if ty == "Transform" && rng() % 2 == 0 {
                " translation 1 0 0 scale 1 2 1"
            } else {
                ""
            };
            s += &format!("{def}{ty} {{ children [\n{kids}]{after} }}\n");
        }
        8 if !defs.is_empty() => {
            let name = &defs[rng() as usize % defs.len()];
            s += &format!(
                "Transform {{ translation 0 {} 0 children USE {name} }}\n",
                rng() % 5
            );
        }
        9 => s += "DirectionalLight { direction 0 -1 0 intensity 0.5 }\n",
        10 => s += &format!("PointLight {{ location {} 1 1 }}\n", rng() % 9),
        11 => s += "Viewpoint { position 0 0 9 description \"a { view [ with } brackets\" }\n",
        12 => s += "# a comment with a Group { children [ in it\n",
        13 => s += "NavigationInfo { headlight FALSE }\nBackground { skyColor 0.1 0.2 0.3 }\n",
        14 => s += "Switch { whichChoice 0 choice [ Shape { geometry Sphere { radius 3 } } ] }\n",
        _ => s += "P { c 1 2 3 }\n",
    }
    defs.extend(name);
    s
}

fn scene(seed: u64) -> String {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut rng = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11
    };
    let mut text = String::from("#VRML V2.0 utf8\n");
    if rng() % 8 != 0 {
        text += "PROTO P [ field SFVec3f c 0 0 0 ] { Transform { translation IS c children Shape { geometry Sphere { radius 0.5 } } } }\n";
    }
    let mut defs = Vec::new();
    let wrap = rng() % 3 == 0;
    if wrap {
        text += "Transform { translation 5 0 0 children [\n";
    }
    let mut declared = false;
    for _ in 0..(20 + rng() % 60) {
        text += &node(&mut rng, 0, &mut defs);
        // A PROTO among the top level's siblings, and instances of it after.
        if !wrap && rng() % 40 == 0 {
            text += "PROTO R [ field SFFloat r 1 ] { Shape { geometry Sphere { radius IS r } } }\n";
            declared = true;
        }
        if declared && rng() % 4 == 0 {
            text += "R { r 2 }\n";
        }
        // A string across lines, one of which starts as a sibling's.
        if rng() % 30 == 0 {
            text += "WorldInfo { info [ \"a\nTransform { b\" ] }\n";
        }
    }
    if wrap {
        text += "] rotation 0 1 0 0.5 }\n";
    }
    if rng() % 5 == 0 {
        text += "PROTO Q [] { Group {} }\nQ {}\n";
    }
    for _ in 0..rng() % 10 {
        text += &node(&mut rng, 0, &mut defs);
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn pieces_agree_with_one_reader(seed in any::<u64>(), chunk in 64u64..1500, threads in 2usize..4) {
        same(&scene(seed), threads, chunk);
    }
}

/// Loads `text` from a file by one reader and in pieces (a plain file's chunks after the
/// first are read from the file by their readers, see `vrml::cut_file`; gzip, as a stream),
/// and checks that the two agree bit for bit. Returns the pieces' report.
fn same_on_disk(text: &str, threads: usize, chunk: u64, gzip: bool) -> Option<LoadReport> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static FILES: AtomicUsize = AtomicUsize::new(0);
    let k = FILES.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("gtsphere-pieces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("scene{k}.wrl"));
    let bytes = if gzip {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(text.as_bytes()).unwrap();
        e.finish().unwrap()
    } else {
        text.as_bytes().to_vec()
    };
    std::fs::write(&path, bytes).unwrap();
    let load = |threads| {
        let opts = LoadOptions {
            read_threads: threads,
            read_chunk_bytes: chunk,
            ..LoadOptions::default()
        };
        gtsphere::vrml::load_path(&path, &opts).map_err(|e| e.to_string())
    };
    let (one, many) = (load(1), load(threads));
    std::fs::remove_file(&path).unwrap();
    agree(one, many, text)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(80))]
    #[test]
    fn pieces_read_from_the_file_agree_with_one_reader(
        seed in any::<u64>(),
        chunk in 64u64..1500,
        threads in 2usize..4,
        gzip in proptest::bool::weighted(0.2),
    ) {
        same_on_disk(&scene(seed), threads, chunk, gzip);
    }
}

#[test]
fn files_on_disk_are_read_in_pieces_from_the_file() {
    // Two layouts, and files whose pieces break off (a warning in a piece, invalid UTF-8 in
    // a piece): kept, or read on from the file, as from memory.
    let body: String = (0..300).map(particle).collect();
    let flat = format!("#VRML V2.0 utf8\n{body}");
    let group = format!("#VRML V2.0 utf8\nGroup {{ children [\n{body}] }}\n");
    for text in [&flat, &group] {
        let r = same_on_disk(text, 2, 700, false).expect("loads");
        assert!(r.read_pieces > 10 && r.read_again.is_none(), "{r:?}");
        // The top level's pieces go to the file's end; the Group's list ends in its last.
        match r.read_on {
            Some(on) => assert!(text == &group && on.contains("list ends"), "{on}"),
            None => assert!(text == &flat),
        }
    }
    let broken = format!("{flat}Frobnicate {{ }}\n{body}");
    let r = same_on_disk(&broken, 3, 700, false).expect("loads");
    assert!(r.read_on.is_some() && r.read_again.is_none(), "{r:?}");
    let mut bytes = flat.clone().into_bytes();
    bytes.extend_from_slice(b"WorldInfo { title \"caf\xE9\" }\n");
    bytes.extend_from_slice(body.as_bytes());
    let dir = std::env::temp_dir().join(format!("gtsphere-pieces-utf8-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.wrl");
    std::fs::write(&path, &bytes).unwrap();
    let load = |threads| {
        let opts = LoadOptions {
            read_threads: threads,
            read_chunk_bytes: 700,
            ..LoadOptions::default()
        };
        gtsphere::vrml::load_path(&path, &opts).map_err(|e| e.to_string())
    };
    match (load(1), load(2)) {
        (Ok((a, ra)), Ok((b, rb))) => {
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
            assert_eq!(ra.warnings, rb.warnings);
            let on = rb.read_on.expect("read on");
            assert!(on.contains("UTF-8"), "{on}");
        }
        (Err(a), Err(b)) => assert_eq!(a, b),
        (a, b) => panic!("{:?} / {:?}", a.is_ok(), b.is_ok()),
    }
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn random_scenes_take_both_paths() {
    // The property above would pass if nothing were ever read in pieces, or if nothing were
    // ever read again: count both.
    let reports: Vec<LoadReport> = (0..200)
        .filter_map(|seed| same(&scene(seed), 2, 300))
        .collect();
    let kept = reports
        .iter()
        .filter(|r| r.read_pieces > 1 && r.read_again.is_none())
        .count();
    let again = reports.iter().filter(|r| r.read_again.is_some()).count();
    assert!(
        kept >= 20 && again >= 20,
        "{kept} kept, {again} read again, of {}",
        reports.len()
    );
}

#[test]
fn corpus_files_in_pieces_are_one_readers() {
    // Real exporters' files, cut into 2 kB pieces wherever the scan allows.
    let Some(corpus) = crate::support::shared("corpus") else {
        return;
    };
    let mut files = Vec::new();
    crate::corpus::walk(&corpus, &mut files);
    let load = |f: &std::path::Path, threads| {
        let opts = LoadOptions {
            read_threads: threads,
            read_chunk_bytes: 2048,
            ..LoadOptions::default()
        };
        gtsphere::vrml::load_path(f, &opts).map_err(|e| e.to_string())
    };
    let (mut kept, mut again) = (0, 0);
    for f in &files {
        match (load(f, 1), load(f, 2)) {
            (Ok((a, ra)), Ok((b, rb))) => {
                assert_eq!(format!("{a:?}"), format!("{b:?}"), "{}", f.display());
                assert_eq!(ra.warnings, rb.warnings, "{}", f.display());
                assert_eq!((ra.skipped, ra.nodes), (rb.skipped, rb.nodes));
                kept += usize::from(rb.read_pieces > 1);
                again += usize::from(rb.read_again.is_some());
            }
            (Err(a), Err(b)) => assert_eq!(a, b, "{}", f.display()),
            (a, b) => panic!("{}: {:?} / {:?}", f.display(), a.is_ok(), b.is_ok()),
        }
    }
    // Both paths are taken on real files.
    assert!(
        kept >= 10 && again >= 1,
        "{kept} in pieces, {again} read again"
    );
}

#[test]
fn invalid_utf8_in_a_piece_is_one_readers_warning() {
    let body: String = (0..200).map(particle).collect();
    let mut bytes = format!("#VRML V2.0 utf8\n{body}").into_bytes();
    bytes.extend_from_slice(b"# bad \xff\xfe bytes\n");
    bytes.extend_from_slice(body.as_bytes());
    let load = |threads| {
        let opts = LoadOptions {
            read_threads: threads,
            read_chunk_bytes: 700,
            ..LoadOptions::default()
        };
        load_bytes("scene.wrl", bytes.clone(), &opts).expect("loads")
    };
    let ((a, ra), (b, rb)) = (load(1), load(2));
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    assert_eq!(ra.warnings, rb.warnings);
    assert_eq!(ra.warnings.len(), 1, "{:?}", ra.warnings);
    // The main reader reads on by itself from the piece with the bad bytes, and says so.
    assert!(rb.read_pieces > 0 && rb.read_again.is_none());
    let on = rb.read_on.expect("read on by one reader");
    assert!(on.contains("invalid UTF-8"), "{on}");
}

/// Colours that do not pack into a sphere's word (more decimals than it holds) are listed in
/// the scene's materials once each, in the order first met, whether the file is read by one
/// reader or in pieces whose prefixes DEF the same Appearance again.
#[test]
fn listed_colours_are_one_readers() {
    let long = |i: usize| format!("0.{:09} 0.5 0.25", 100_000_007 + (i % 5) * 1_000_003);
    let def = "0.987654321 0.5 0.25";
    let mut text = format!(
        "#VRML V2.0 utf8\nDEF A Appearance {{ material Material {{ diffuseColor {def} }} }}\nGroup {{ children [\n"
    );
    for i in 0..400 {
        let appearance = if i % 3 == 0 {
            "USE A".to_string()
        } else {
            format!(
                "Appearance {{ material Material {{ diffuseColor {} }} }}",
                long(i)
            )
        };
        text += &format!(
            "Transform {{ translation {i} 0 0 children Shape {{ appearance {appearance} geometry Sphere {{}} }} }}\n"
        );
    }
    text += "] }\n";
    let report = same(&text, 2, 600).expect("read");
    assert!(report.read_pieces > 1, "{}", report.read_pieces);
    let (s, _) = load(&text, 2, 600).unwrap();
    // The DEF'd colour and the five others.
    assert_eq!(s.materials.listed_colors().len(), 6);
    for (i, sphere) in s.spheres.iter().enumerate() {
        let want = if i % 3 == 0 { def.to_string() } else { long(i) };
        let want: Vec<f64> = want.split(' ').map(|t| t.parse().unwrap()).collect();
        assert_eq!(s.material_of(sphere).diffuse.to_array().to_vec(), want);
    }
}
