use super::*;

/// The pieces of `text` fed in blocks of `block` bytes.
fn pieces(text: &str, chunk: u64, block: usize) -> Vec<Piece> {
    pieces_with(text, (chunk, 1 << 20), block)
}

/// [`pieces`], with a prefix of at most `prefix_max` bytes.
fn pieces_with(text: &str, (chunk, prefix_max): (u64, u64), block: usize) -> Vec<Piece> {
    let mut s = Splitter::new(chunk, prefix_max);
    let mut v = Vec::new();
    let mut r = std::io::Cursor::new(text.as_bytes());
    while s.read_from(&mut r, block, &mut |p| v.push(p)).unwrap() > 0 {}
    s.finish(&mut |p| v.push(p));
    v
}

/// The text put back together, and the chunks' texts.
fn rejoin(v: &[Piece]) -> (String, Vec<String>) {
    let mut all = Vec::new();
    let mut chunks = Vec::new();
    for p in v {
        match p {
            Piece::Text(t) => all.extend_from_slice(t),
            Piece::Chunk { start, text } => {
                assert_eq!(*start as usize, all.len());
                all.extend_from_slice(text);
                chunks.push(String::from_utf8(text.clone()).unwrap());
            }
            Piece::Prefix(_) | Piece::RegionEnd { .. } | Piece::Range { .. } => {}
        }
    }
    (String::from_utf8(all).unwrap(), chunks)
}

#[test]
fn splits_top_level_and_children_and_keeps_every_byte() {
    let node = "Transform { translation 1 2 3 children Shape { geometry Sphere {} } }\n";
    let flat = format!("#VRML V2.0 utf8\n{}", node.repeat(50));
    let group = format!(
        "#VRML V2.0 utf8\nGroup {{ children [\n{}] }}\n",
        node.repeat(50)
    );
    for text in [&flat, &group] {
        for block in [1, 7, 4096] {
            let v = pieces(text, 200, block);
            let (all, chunks) = rejoin(&v);
            assert_eq!(&all, text);
            assert!(chunks.len() >= 10, "{} chunks", chunks.len());
            // Every chunk but the last (which holds the rest of the file) is whole
            // siblings of at least 200 bytes, and every one starts a sibling's line.
            let (last, whole) = chunks.split_last().unwrap();
            for c in whole {
                assert!(c.ends_with('\n') && c.len() >= 200, "{c:?}");
                assert_eq!(c.matches('{').count(), c.matches('}').count());
            }
            assert!(chunks.iter().all(|c| c.starts_with("Transform {")));
            assert!(last.ends_with(if text == &group { "] }\n" } else { "} }\n" }));
        }
    }
}

/// A list is taken as the region once it holds `prefix_max` of siblings when no other
/// list could be then; with a cut in a list it is in, only with a chunk's worth.
#[test]
fn a_list_is_taken_after_the_longest_prefix_when_no_other_could_be() {
    let node = "Transform { translation 1 2 3 children Shape { geometry Sphere {} } }\n";
    let first_chunk = |text: &str| {
        let (all, chunks) = rejoin(&pieces_with(text, (4000, 1000), 64));
        assert_eq!(all, text);
        chunks[0].len()
    };
    let flat = format!("#VRML V2.0 utf8\n{}", node.repeat(200));
    let n = first_chunk(&flat);
    assert!((1000..1000 + node.len()).contains(&n), "{n}");
    // A Group's children, the Group the first node: no cut at the top level.
    let group = |before: &str| {
        format!(
            "#VRML V2.0 utf8\n{before}Group {{ children [\n{}] }}\n",
            node.repeat(200)
        )
    };
    let n = first_chunk(&group(""));
    assert!((1000..1000 + node.len()).contains(&n), "{n}");
    // After a top-level node (a cut at the top level, which may hold far more nodes after
    // the Group): a chunk's worth.
    for before in [
        "Viewpoint { position 0 0 9 }\n",
        "Group { children [\nShape {}\n] }\n",
    ] {
        let n = first_chunk(&group(before));
        assert!((4000..4000 + node.len()).contains(&n), "{n}");
    }
}

/// In the region the cuts are guessed from its first sibling's line: its indentation and
/// word must start the line, whole; with no such line for long, the text is cut anyway.
#[test]
fn guesses_cuts_from_the_first_siblings_line() {
    assert_eq!(
        sibling_mark(b"\n# note\n  \t DEF A Shape {}\n"),
        b"\n  \t DEF"
    );
    assert_eq!(sibling_mark(b"  Shape {}"), b"\n  Shape");
    assert_eq!(sibling_mark(b"\n  [ x ]\nShape {}"), b"\n");
    // (The prefix ends after the first sibling: the region starts at the second.)
    let head = "#VRML V2.0 utf8\nGroup { children [\n  Transform {}\n";
    // Lines that look like the sibling's but are not: a longer word, other indentation.
    let node = "  Shape { geometry Sphere {} }\n  ShapeX {}\n    Shape {}\n";
    let text = format!("{head}{}] }}\n", node.repeat(40));
    let (all, chunks) = rejoin(&pieces(&text, 100, 9));
    assert_eq!(all, text);
    assert!(chunks.len() > 5);
    assert!(
        chunks.iter().all(|c| c.starts_with("  Shape { geometry")),
        "{chunks:?}"
    );
    // No line like the first sibling's: cuts at 8 MB (the least bound), at a line's start.
    let mut text = format!("#VRML V2.0 utf8\n{}", "Shape {}\n".repeat(40_000));
    text += &"  Group {}\n".repeat(1_000_000);
    let (all, chunks) = rejoin(&pieces(&text, 100_000, 1 << 16));
    assert_eq!(all, text);
    let long: Vec<_> = chunks.iter().filter(|c| c.len() > 100_000 + 20).collect();
    assert!(!long.is_empty());
    for c in &long[..long.len() - 1] {
        assert!(
            c.len() > 8 << 20 && c.len() <= (8 << 20) + (1 << 16),
            "{}",
            c.len()
        );
        assert!(c.ends_with('\n'));
    }
}

#[test]
fn leaves_def_protos_and_strings_alone() {
    let node = "Transform { children Shape { geometry Sphere {} } }\n";
    // A DEF'd group, a grouping node inside a string, an EXTERNPROTO: no region.
    let texts = [
        format!(
            "#VRML V2.0 utf8\nDEF G Group {{ children [\n{}] }}\n",
            node.repeat(50)
        ),
        format!(
            "#VRML V2.0 utf8\nEXTERNPROTO P [] \"p.wrl\"\n{}",
            node.repeat(50)
        ),
        format!(
            "#VRML V2.0 utf8\nWorldInfo {{ info \"Group {{ children [\" }}\n{}",
            "Shape { geometry Sphere {} }\n".repeat(3)
        ),
    ];
    let (_, chunks) = rejoin(&pieces(&texts[0], 100, 13));
    // The top level holds one node: no cut inside the DEF'd Group.
    assert!(chunks.is_empty(), "{chunks:?}");
    let (all, chunks) = rejoin(&pieces(&texts[1], 100, 13));
    assert_eq!(all, texts[1]);
    assert!(chunks.is_empty());
    let (all, _) = rejoin(&pieces(&texts[2], 10, 5));
    assert_eq!(all, texts[2]);
    // A PROTO at the top level: the region starts after it and ends at the next one.
    let text = format!(
        "#VRML V2.0 utf8\nPROTO P [ field SFNode n Group {{}} ] {{ Group {{ children [ Shape {{}} ] }} }}\n{}PROTO Q [] {{ Group {{}} }}\n{}",
        "P {}\n".repeat(40),
        "Q {}\n".repeat(40)
    );
    let v = pieces(&text, 30, 11);
    let (all, chunks) = rejoin(&v);
    assert_eq!(all, text);
    assert!(!chunks.is_empty());
    // The cuts are guessed at lines starting with `P` as a word: not at `PROTO Q` (whose
    // chunk the reader then turns down) nor at `Q`.
    assert!(chunks.iter().all(|c| c.starts_with("P {}")));
    let prefix = v.iter().find_map(|p| match p {
        Piece::Prefix(p) => Some(String::from_utf8(p.to_vec()).unwrap()),
        _ => None,
    });
    assert!(prefix.unwrap().contains("PROTO P"));
}
