//! Each lexical corner of VRML97 that real exporters write reads correctly, and the bytes
//! around them: gzip, invalid UTF-8, items longer than the reading window.

use std::io::Write;

use gtsphere::vrml::{load_bytes, LoadOptions};

use super::support::scene;

const BALL: &str =
    "Shape { appearance Appearance { material Material { } } geometry Sphere { radius 2 } }";

#[test]
fn number_forms() {
    let (s, _) = scene(
        "Transform { translation .5 -0 +2. children Shape { geometry Sphere { radius 1e-3 } } }",
    );
    let b = &s.spheres[0];
    assert_eq!(b.center.to_array(), [0.5, 0.0, 2.0]);
    assert_eq!(b.radius, 1e-3);
}

#[test]
fn seventeen_digit_and_tiny_numbers_are_exact() {
    let (s, _) = scene(
        "Transform { translation 0.30000000000000004 1e-18 -1.2345678901234567 children Shape { geometry Sphere { radius 0.10000000000000001 } } }",
    );
    let c = s.spheres[0].center;
    assert_eq!(c.x.to_bits(), 0.30000000000000004f64.to_bits());
    assert_eq!(c.y, 1e-18);
    assert_eq!(c.z.to_bits(), (-1.2345678901234567f64).to_bits());
    assert_eq!(s.spheres[0].radius, 0.1);
}

#[test]
fn hex_integers_in_int32_and_sfimage_fields() {
    // Switch.whichChoice is SFInt32; PixelTexture.image is SFImage (2x1, one component).
    let (s, _) = scene(&format!(
        "Switch {{ whichChoice 0x1 choice [ Group {{}} {BALL} ] }}\n\
         Shape {{ appearance Appearance {{ texture PixelTexture {{ image 2 1 1 0xFF 0x00 }} }} }}"
    ));
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn comments_and_commas_are_white_space() {
    let (s, r) = scene(&format!(
        "# a comment\nGroup {{ # another\n children [ {BALL}, {BALL}, ] # trailing comma before ]\n}},,"
    ));
    assert_eq!(s.spheres.len(), 2);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
}

#[test]
fn commas_between_vector_components() {
    let (s, _) = scene("Transform { translation 1, 2, 3, children Shape { geometry Sphere {} } }");
    assert_eq!(s.spheres[0].center.to_array(), [1.0, 2.0, 3.0]);
}

#[test]
fn strings_with_escapes_and_newlines() {
    let (s, _) = scene("Viewpoint { description \"say \\\"hi\\\" \\\\ there\nsecond line\" }");
    assert_eq!(
        s.viewpoints[0].description,
        "say \"hi\" \\ there\nsecond line"
    );
}

#[test]
fn text_after_utf8_on_the_header_line() {
    let (s, _) = super::support::load(&format!("#VRML V2.0 utf8 Produced by PyMOL {{ [\n{BALL}"));
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn single_node_without_brackets_as_mfnode_value() {
    let (s, _) = scene(&format!("Group {{ children {BALL} }}"));
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn gzip_is_read_by_content() {
    let text = format!("#VRML V2.0 utf8\n{BALL}\n");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(text.as_bytes()).expect("gzip");
    let bytes = enc.finish().expect("gzip");
    let (s, _) = load_bytes("ball.wrl", bytes, &LoadOptions::default()).expect("gzip scene");
    assert_eq!(s.spheres.len(), 1);
    // And from a file named .wrz.
    let dir = std::env::temp_dir().join(format!("gtsphere-gz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let path = dir.join("ball.wrz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(text.as_bytes()).expect("gzip");
    std::fs::write(&path, enc.finish().expect("gzip")).expect("write");
    let (s, _) = gtsphere::vrml::load_path(&path, &LoadOptions::default()).expect("wrz");
    assert_eq!(s.spheres.len(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn invalid_utf8_is_replaced_with_one_warning() {
    let mut bytes = b"#VRML V2.0 utf8\n# caf\xe9\nShape { geometry Sphere {} }\n".to_vec();
    bytes.extend_from_slice(b"# \xff\xfe\n");
    let (s, r) =
        load_bytes("latin1.wrl", bytes, &LoadOptions::default()).expect("latin-1 comments");
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(r.warnings.len(), 1);
    assert!(
        r.warnings[0]
            .headline()
            .starts_with("latin1.wrl:2:6: warning: invalid UTF-8"),
        "{}",
        r.warnings[0]
    );
}

#[test]
fn long_items_cross_the_reading_window() {
    // A 300 kB string, a 2 MB coordinate list and a 200 kB comment are read whole.
    let long = "x".repeat(300_000);
    let coords: Vec<String> = (0..200_000).map(|i| format!("{i}.5")).collect();
    let comment = "#".repeat(200_000);
    let text = format!(
        "#VRML V2.0 utf8\n{comment}\nWorldInfo {{ info \"{long}\" }}\n\
         Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point [ {} ] }} }} }}\n\
         Viewpoint {{ description \"{long}\" }}\n{BALL}",
        coords.join(" ")
    );
    let (s, r) = super::support::load(&text);
    // The coordinate list has no faces: its 66 666 whole points are particles (the last
    // two numbers make no point).
    assert_eq!((s.spheres.len(), r.point_spheres), (1 + 66_666, 66_666));
    assert_eq!(s.viewpoints[0].description.len(), 300_000);
    assert_eq!(s.spheres[0].center, glam::DVec3::new(0.5, 1.5, 2.5));
}

#[test]
fn numbers_cut_by_the_reading_window_read_whole() {
    // The first read of a file ends at 1 MiB: put that end inside a number, after each of
    // its prefixes that is not a number by itself.
    const WINDOW: usize = 1 << 20;
    for number in ["-0.25", "-2.5e-1", "+2.5E-1"] {
        for cut in 1..number.len() {
            let head = "#VRML V2.0 utf8\nShape { geometry PointSet { coord Coordinate { point [\n";
            let mut text = String::from(head);
            while text.len() + 6 + cut < WINDOW {
                text.push_str("1 1 1\n");
            }
            while text.len() + cut < WINDOW {
                text.push(' ');
            }
            text.push_str(number);
            text.push_str(" 2 3\n");
            for _ in 0..1000 {
                text.push_str("1 1 1\n");
            }
            text.push_str("] } } }\n");
            assert_eq!(text.find(number), Some(WINDOW - cut));
            let (s, _) = load_bytes("cut.wrl", text.into_bytes(), &LoadOptions::default())
                .unwrap_or_else(|e| panic!("{number} cut after {cut} bytes: {e}"));
            let want = glam::DVec3::new(-0.25, 2.0, 3.0);
            let want = if number.starts_with('+') {
                want * glam::DVec3::new(-1.0, 1.0, 1.0)
            } else {
                want
            };
            assert!(
                s.spheres.iter().any(|sp| sp.center == want),
                "{number} cut after {cut} bytes: no point at {want}"
            );
        }
    }
}
