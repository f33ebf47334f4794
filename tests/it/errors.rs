//! Each error and warning: its message, and its line:col, checked exactly.

use super::support::{error_of, scene, strict_error_of};

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

#[test]
fn syntax_error_has_position_line_and_caret() {
    let e = error_of(
        "#VRML V2.0 utf8\nGroup {\n  children [ Shape { geometry Sphere { radius 1 } ]\n}\n",
    );
    assert_eq!(
        e,
        "test.wrl:3:51: expected a field name or '}'\n    children [ Shape { geometry Sphere { radius 1 } ]\n                                                    ^"
    );
}

#[test]
fn missing_brace_after_node_type() {
    let e = error_of("#VRML V2.0 utf8\nTransform translation 1 2 3");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:11: expected '{' after node type 'Transform'"
    );
}

#[test]
fn unexpected_end_of_file() {
    let e = error_of("#VRML V2.0 utf8\nGroup { children [ Group {\n");
    assert_eq!(
        first_line(&e),
        "test.wrl:3:1: unexpected end of file: expected '}' to close a node"
    );
}

#[test]
fn vrml1_and_x3d_are_not_supported() {
    let e = error_of("#VRML V1.0 ascii\nSeparator { }");
    assert_eq!(
        first_line(&e),
        "test.wrl:1:1: VRML 1.0 files are not supported: gtsphere reads VRML97 ('#VRML V2.0 utf8')"
    );
    let e = error_of("#X3D V3.2 utf8\nShape {}");
    assert!(
        first_line(&e).starts_with("test.wrl:1:1: X3D files are not supported"),
        "{e}"
    );
    let e = error_of("hello");
    assert!(
        first_line(&e).starts_with("test.wrl:1:1: not a VRML97 file"),
        "{e}"
    );
    let e = error_of("");
    assert!(
        first_line(&e).starts_with("test.wrl:1:1: not a VRML97 file"),
        "{e}"
    );
}

#[test]
fn wrong_field_value_types() {
    let e = error_of("#VRML V2.0 utf8\nTransform { translation 1 2 }");
    assert_eq!(first_line(&e), "test.wrl:2:13: field 'translation' of Transform expects SFVec3f (3 number(s) per value), found 2 number(s)");
    let e = error_of("#VRML V2.0 utf8\nSwitch { whichChoice 1.5 }");
    assert_eq!(first_line(&e), "test.wrl:2:10: field 'whichChoice' of Switch expects SFInt32 (1 integer(s) per value), found 1 number(s)");
    let e = error_of("#VRML V2.0 utf8\nNavigationInfo { headlight 1 }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:18: field 'headlight' of NavigationInfo expects SFBool, found 1 number(s)"
    );
    let e = error_of("#VRML V2.0 utf8\nShape { geometry 3 }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:9: field 'geometry' of Shape expects SFNode, found 1 number(s)"
    );
    let e = error_of("#VRML V2.0 utf8\nTransform { translation Group {} }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:13: field 'translation' of Transform expects SFVec3f, found a node"
    );
    let e = error_of("#VRML V2.0 utf8\nWorldInfo { title [ 1 \"a\" ] }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:23: a list must not mix numbers, strings and booleans"
    );
}

#[test]
fn use_of_an_undefined_name() {
    let e = error_of("#VRML V2.0 utf8\nGroup {}\n  USE Nowhere");
    assert_eq!(
        first_line(&e),
        "test.wrl:3:3: USE of undefined name 'Nowhere'"
    );
}

#[test]
fn nan_and_infinite_numbers() {
    let e = error_of("#VRML V2.0 utf8\nTransform { translation 0 nan 0 }");
    assert_eq!(first_line(&e), "test.wrl:2:13: field 'translation' of Transform expects SFVec3f (3 number(s) per value), found 1 number(s)");
    let e = error_of("#VRML V2.0 utf8\nTransform { translation NaN 0 0 }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:25: NaN and infinite numbers are not allowed"
    );
    let e = error_of("#VRML V2.0 utf8\nTransform { translation 1e999 0 0 }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:25: number out of range (NaN and infinite values are not allowed)"
    );
    let e = error_of("#VRML V2.0 utf8\nTransform { scale [ inf 1 1 ] }");
    assert_eq!(
        first_line(&e),
        "test.wrl:2:21: NaN and infinite numbers are not allowed"
    );
}

#[test]
fn non_positive_radius() {
    for r in ["0", "-1", "-0"] {
        let e = error_of(&format!(
            "#VRML V2.0 utf8\nShape {{ geometry Sphere {{ radius {r} }} }}"
        ));
        assert_eq!(
            first_line(&e),
            format!(
                "test.wrl:2:27: Sphere radius must be positive, found {}",
                r.parse::<f64>().unwrap()
            )
        );
    }
}

#[test]
fn is_outside_a_proto() {
    let e = error_of("#VRML V2.0 utf8\nGroup {\n  children IS foo\n}");
    assert_eq!(
        first_line(&e),
        "test.wrl:3:3: 'children IS foo' outside a PROTO body"
    );
}

#[test]
fn unknown_field_is_a_warning_with_position_and_strict_makes_it_an_error() {
    let text = "#VRML V2.0 utf8\nTransform {\n  kambiExtension 1 2\n  children Shape { geometry Sphere {} }\n}";
    let (s, r) = super::support::load(text);
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(r.warnings.len(), 1);
    assert_eq!(
        r.warnings[0].headline(),
        "test.wrl:3:3: warning: unknown field 'kambiExtension' of Transform: ignored"
    );
    let e = strict_error_of(text);
    assert_eq!(
        first_line(&e),
        "test.wrl:3:3: unknown field 'kambiExtension' of Transform: ignored"
    );
}

#[test]
fn unknown_node_types_warn_once_per_type() {
    let (s, r) = scene(
        "Fancy { a 1 }\nFancy { b [ 1 2 ] c Shape { } }\nOther { }\nShape { geometry Sphere {} }",
    );
    assert_eq!(s.spheres.len(), 1);
    let heads: Vec<String> = r.warnings.iter().map(|w| w.headline()).collect();
    assert_eq!(
        heads,
        vec![
            "test.wrl:2:1: warning: unknown node type 'Fancy': skipped (and 1 more like it)",
            "test.wrl:4:1: warning: unknown node type 'Other': skipped",
        ]
    );
    assert_eq!(r.skipped.get("Fancy"), Some(&2));
}

#[test]
fn errors_in_inlined_files_name_that_file() {
    let dir = std::env::temp_dir().join(format!("gtsphere-inline-err-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    std::fs::write(
        dir.join("main.wrl"),
        "#VRML V2.0 utf8\nInline { url \"part.wrl\" }\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("part.wrl"),
        "#VRML V2.0 utf8\n\nShape { geometry Sphere { radius -2 } }\n",
    )
    .expect("write");
    let e = gtsphere::vrml::load_path(&dir.join("main.wrl"), &Default::default())
        .expect_err("bad radius");
    let part = dir.join("part.wrl");
    assert_eq!(
        first_line(&e.to_string()),
        format!(
            "{}:3:27: Sphere radius must be positive, found -2",
            part.display()
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// After loading, an IR item's origin still turns into `file:line:col` (of a plain and of a
/// gzipped file), at the sphere's node: found here independently, by searching the text for
/// the `Sphere` keywords. Text loaded from memory has no file to read again: a byte offset.
#[test]
fn a_spheres_origin_turns_into_file_line_col_after_loading() {
    use std::io::Write;
    let text = "#VRML V2.0 utf8\n# two spheres\nShape { geometry Sphere { radius 1 } }\n\
                Transform { translation 1 0 0 children [\n    Shape { geometry Sphere { radius 2 } }\n] }\n";
    let want: Vec<(usize, usize)> = text
        .lines()
        .enumerate()
        .filter_map(|(i, l)| l.find("Sphere").map(|c| (i + 1, c + 1)))
        .collect();
    assert_eq!(want, vec![(3, 18), (5, 22)]);
    let dir = super::support::scratch("errors", "origin_position");
    let plain = dir.join("two.wrl");
    std::fs::write(&plain, text).unwrap();
    let gz = dir.join("two.wrz");
    let mut enc = flate2::write::GzEncoder::new(
        std::fs::File::create(&gz).unwrap(),
        flate2::Compression::default(),
    );
    enc.write_all(text.as_bytes()).unwrap();
    enc.finish().unwrap();
    for path in [&plain, &gz] {
        let (scene, _) = gtsphere::vrml::load_path(path, &Default::default()).unwrap();
        let got: Vec<String> = scene
            .spheres
            .iter()
            .map(|s| scene.position(s.origin))
            .collect();
        let expect: Vec<String> = want
            .iter()
            .map(|(l, c)| format!("{}:{l}:{c}", path.display()))
            .collect();
        assert_eq!(got, expect);
    }
    let (scene, _) = gtsphere::vrml::load_str("mem.wrl", text, &Default::default()).unwrap();
    let offset = text.find("Sphere").unwrap();
    assert_eq!(
        scene.position(scene.spheres[0].origin),
        format!("mem.wrl:byte {offset}")
    );
}

#[test]
fn negative_colours_and_intensities_are_clamped_with_a_positioned_warning() {
    let text = "#VRML V2.0 utf8\n\
                Shape { appearance Appearance { material Material { diffuseColor -1 0.5 0 } } geometry Sphere {} }\n\
                PointLight { intensity -2 }\n";
    let (s, r) = super::support::load(text);
    let heads: Vec<String> = r.warnings.iter().map(|w| w.headline()).collect();
    assert_eq!(
        heads,
        [
            "test.wrl:2:53: warning: diffuseColor -1 0.5 0 is negative: clamped to 0",
            "test.wrl:3:14: warning: intensity -2 is negative: clamped to 0",
        ]
    );
    assert_eq!(
        s.materials.diffuse(s.spheres[0].color),
        glam::DVec3::new(0.0, 0.5, 0.0)
    );
    // The scene renders (it did not before: the render refused the material, unpositioned).
    let prep = super::support::prepare(s);
    assert!(prep
        .view(&prep.default_camera(8, 8).unwrap(), &Default::default())
        .is_ok());
    let e = strict_error_of(text);
    assert_eq!(
        first_line(&e),
        "test.wrl:2:53: diffuseColor -1 0.5 0 is negative: clamped to 0"
    );
    // Read by a PROTO template the same.
    let proto = "#VRML V2.0 utf8\n\
                 PROTO P [ field SFColor c 1 1 1 ] { Transform { children Shape { appearance Appearance { material Material { diffuseColor IS c } } geometry Sphere {} } } }\n\
                 P { c 0 -0.25 0 }\n";
    let (s, r) = super::support::load(proto);
    assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
    assert!(r.warnings[0]
        .headline()
        .contains("is negative: clamped to 0"));
    assert_eq!(s.materials.diffuse(s.spheres[0].color), glam::DVec3::ZERO);
}
