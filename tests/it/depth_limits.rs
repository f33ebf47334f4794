//! The reader's recursion bounds, tested at the bound and just past it: nested USE and PROTO
//! replays (at most 200 at once, `MAX_REPLAY_DEPTH` in src/vrml/lower/expand/replay.rs) and nested
//! Inline files (`LoadOptions::max_inline_depth`, 16 by default). At the bound the scene
//! loads whole; past it the error names the file, line and column of the USE, instance or
//! Inline that goes too deep, with no panic and no stack overflow. Group nesting has no
//! bound: 100 000 nested Groups read without recursion.

use super::support::{close, error_of, load};

/// The replay depth the reader allows (`MAX_REPLAY_DEPTH`).
const MAX_REPLAY_DEPTH: usize = 200;

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

/// `PROTO P0` draws a sphere; `PROTO Pk`'s body is one `P(k-1)` instance; the file ends with
/// an instance of `P(top)`, whose expansion replays `top + 1` bodies, one inside the other.
/// Line `k + 2` declares `Pk`.
fn proto_chain(top: usize) -> String {
    let mut text = String::from("#VRML V2.0 utf8\nPROTO P0 [] { Shape { geometry Sphere { } } }\n");
    for k in 1..=top {
        text.push_str(&format!("PROTO P{k} [] {{ P{} {{ }} }}\n", k - 1));
    }
    text.push_str(&format!("P{top} {{ }}\n"));
    text
}

/// `DEF A0` is a sphere and `DEF Ak` a Group of `USE A(k-1)`: reading `DEF Ak` replays `k`
/// recordings, one inside the other. Line `k + 2` defines `Ak`.
fn use_chain(top: usize) -> String {
    let mut text = String::from("#VRML V2.0 utf8\nDEF A0 Shape { geometry Sphere { } }\n");
    for k in 1..=top {
        text.push_str(&format!("DEF A{k} Group {{ children USE A{} }}\n", k - 1));
    }
    text
}

#[test]
fn proto_expansions_nest_up_to_the_replay_limit() {
    let (s, r) = load(&proto_chain(MAX_REPLAY_DEPTH - 1));
    assert_eq!(s.spheres.len(), 1);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn proto_expansions_past_the_replay_limit_are_an_error_at_the_innermost_instance() {
    let e = error_of(&proto_chain(MAX_REPLAY_DEPTH));
    // The 201st body is P0's, expanded for the `P0 { }` in P1's body (line 3, column 15).
    assert_eq!(
        first_line(&e),
        "test.wrl:3:15: PROTO expansions nest deeper than 200"
    );
}

#[test]
fn uses_nest_up_to_the_replay_limit() {
    let (s, r) = load(&use_chain(MAX_REPLAY_DEPTH));
    // One sphere per DEF, the last one drawn through 200 nested USEs.
    assert_eq!(s.spheres.len(), MAX_REPLAY_DEPTH + 1);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn uses_past_the_replay_limit_are_an_error_at_the_innermost_use() {
    let e = error_of(&use_chain(MAX_REPLAY_DEPTH + 1));
    // The 201st replay is of A0, for the `USE A0` in A1's Group, on line 3. (The parser
    // places a USE that is a field's value at the field's name, column 16, as it does for
    // "USE of undefined name".)
    assert_eq!(
        first_line(&e),
        "test.wrl:3:16: USE and PROTO expansions nest deeper than 200"
    );
}

/// Writes `f0.wrl` .. `f{files-1}.wrl` in a fresh folder: each moves its Inline of the next
/// file by 1 along x, and the last draws a unit sphere. Returns the folder.
fn inline_chain(name: &str, files: usize) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("gtsphere-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("tmp");
    for k in 0..files {
        let body = if k + 1 < files {
            format!(
                "Transform {{ translation 1 0 0 children\nInline {{ url \"f{}.wrl\" }} }}\n",
                k + 1
            )
        } else {
            "Shape { geometry Sphere { } }\n".to_string()
        };
        std::fs::write(
            dir.join(format!("f{k}.wrl")),
            format!("#VRML V2.0 utf8\n{body}"),
        )
        .expect("write");
    }
    dir
}

#[test]
fn inlines_nest_up_to_the_depth_limit() {
    let depth = gtsphere::vrml::LoadOptions::default().max_inline_depth;
    assert_eq!(depth, 16);
    // The scene file and 16 nested Inlines.
    let dir = inline_chain("inline-limit", depth + 1);
    let (s, r) =
        gtsphere::vrml::load_path(&dir.join("f0.wrl"), &Default::default()).expect("loads");
    assert_eq!(r.files.len(), depth + 1);
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].center.x, depth as f64);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn inlines_past_the_depth_limit_are_an_error_at_the_innermost_inline() {
    let depth = gtsphere::vrml::LoadOptions::default().max_inline_depth;
    let dir = inline_chain("inline-past-limit", depth + 2);
    let e =
        gtsphere::vrml::load_path(&dir.join("f0.wrl"), &Default::default()).expect_err("too deep");
    // f16.wrl's Inline of f17.wrl would be the 17th nested one.
    let at = dir.join(format!("f{depth}.wrl"));
    assert_eq!(
        first_line(&e.to_string()),
        format!(
            "{}:3:1: Inline 'f{}.wrl' nests deeper than 16 files",
            at.display(),
            depth + 1
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn hundred_thousand_nested_groups_work() {
    let n = 100_000;
    let mut text = String::from("#VRML V2.0 utf8\n");
    for _ in 0..n {
        text.push_str("Group { children [\n");
    }
    text.push_str("Shape { geometry Sphere { radius 2 } }");
    for _ in 0..n {
        text.push_str("] }\n");
    }
    let (s, _) = super::support::load(&text);
    assert_eq!(s.spheres.len(), 1);
    assert!(close(s.spheres[0].radius, 2.0, 0.0));
}
