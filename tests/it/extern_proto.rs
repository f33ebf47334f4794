//! EXTERNPROTO from local files (VRML97 4.9): the PROTO a url names (`file.wrl#Name`, or the
//! first PROTO of `file.wrl`) is read with the rules of Inline and expands like a PROTO
//! written in the scene; its defaults are its own, the EXTERNPROTO's interface says what an
//! instance may set. Fixtures are written to a scratch folder per test; positions expected
//! in messages are found by searching the fixture text, not by running the reader.

use std::path::{Path, PathBuf};

use gtsphere::scene::{Material, Scene};
use gtsphere::vrml::{load_path, LoadOptions, LoadReport};

const HEADER: &str = "#VRML V2.0 utf8\n";

/// A PROTO whose instance is one sphere: radius `r`, colour `c`, centre `at`.
const BALL: &str =
    "PROTO Ball [ field SFFloat r 0.5 field SFColor c 1 0 0 exposedField SFVec3f at 0 0 0 ]\n\
{ Transform { translation IS at children Shape {\n  \
  appearance Appearance { material Material { diffuseColor IS c } }\n  \
  geometry Sphere { radius IS r } } } }\n";

/// The interface of [`BALL`], as an EXTERNPROTO declares it.
const BALL_IFACE: &str = "[ field SFFloat r field SFColor c exposedField SFVec3f at ]";

/// A library: [`BALL`], a second PROTO, and top-level nodes that must not be drawn (a
/// sphere, and an Inline of a file with another).
fn library() -> String {
    format!(
        "{BALL}PROTO Second [ field SFFloat r 2 ] {{ Shape {{ geometry Sphere {{ radius IS r }} }} }}\n\
         DEF Big Shape {{ geometry Sphere {{ radius 9 }} }}\n\
         Inline {{ url \"drawn.wrl\" }}\n"
    )
}

/// A fresh folder for one test.
fn folder(test: &str) -> PathBuf {
    crate::support::scratch("extern_proto", test)
}

/// Writes `HEADER` + `body` to `dir/name` (folders made as needed); the path.
fn write(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, format!("{HEADER}{body}")).unwrap();
    path
}

fn load_with(path: &Path, opts: &LoadOptions) -> (Scene, LoadReport) {
    load_path(path, opts).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn load(path: &Path) -> (Scene, LoadReport) {
    load_with(path, &LoadOptions::default())
}

/// The first line of the error loading `path` gives.
fn error(path: &Path) -> String {
    let e = load_path(path, &LoadOptions::default()).expect_err("an error");
    e.to_string().lines().next().unwrap_or("").to_string()
}

/// Each sphere's centre, radius and material.
fn balls(s: &Scene) -> Vec<([f64; 3], f64, Material)> {
    s.spheres
        .iter()
        .map(|b| (b.center.to_array(), b.radius, s.material_of(b)))
        .collect()
}

fn headlines(r: &LoadReport) -> Vec<String> {
    r.warnings.iter().map(|w| w.headline()).collect()
}

/// `line:col` (1-based) of the `nth` (0-based) occurrence of `needle` in the file written
/// with `body` (the header line counts).
fn at(body: &str, needle: &str, nth: usize) -> String {
    let text = format!("{HEADER}{body}");
    let (k, _) = text
        .match_indices(needle)
        .nth(nth)
        .unwrap_or_else(|| panic!("'{needle}' #{nth} not in the fixture"));
    let line = text[..k].matches('\n').count() + 1;
    let col = k - text[..k].rfind('\n').map_or(0, |n| n + 1) + 1;
    format!("{line}:{col}")
}

#[test]
fn a_proto_by_name_or_first_in_its_file_gives_the_spheres_of_the_proto_written_inline() {
    let dir = folder("same_as_inline");
    write(&dir, "lib.wrl", &library());
    write(
        &dir,
        "drawn.wrl",
        "Shape { geometry Sphere { radius 8 } }\n",
    );
    let uses = "Ball { r 1 c 0 1 0 at 1 2 3 }\nBall { }\nBall { at -1 0 0 }\n";
    let inline = write(&dir, "inline.wrl", &format!("{BALL}{uses}"));
    let by_name = write(
        &dir,
        "by_name.wrl",
        &format!("EXTERNPROTO Ball {BALL_IFACE} \"lib.wrl#Ball\"\n{uses}"),
    );
    let first = write(
        &dir,
        "first.wrl",
        &format!("EXTERNPROTO Ball {BALL_IFACE} [ \"lib.wrl\" ]\n{uses}"),
    );
    let (want, want_r) = load(&inline);
    assert_eq!(want.spheres.len(), 3);
    for path in [&by_name, &first] {
        let (s, r) = load(path);
        assert_eq!(balls(&s), balls(&want), "{}", path.display());
        assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
        assert!(r.skipped.is_empty(), "{:?}", r.skipped);
        // The library's own nodes (a sphere, an Inline) are read, not lowered nor counted.
        assert_eq!(r.nodes, want_r.nodes);
        assert_eq!(r.files.len(), 2);
        assert!(r.files[1].ends_with("lib.wrl"), "{:?}", r.files);
    }
    // Two EXTERNPROTOs naming the same file: it is read once.
    let both = write(
        &dir,
        "both.wrl",
        &format!(
            "EXTERNPROTO Ball {BALL_IFACE} \"lib.wrl#Ball\"\n\
             EXTERNPROTO First {BALL_IFACE} \"./lib.wrl\"\n\
             EXTERNPROTO Two [ field SFFloat r ] \"lib.wrl#Second\"\n\
             Ball {{ }} First {{ r 2 }} Two {{ }}\n"
        ),
    );
    let (s, r) = load(&both);
    let radii: Vec<f64> = s.spheres.iter().map(|b| b.radius).collect();
    assert_eq!(radii, [0.5, 2.0, 2.0]);
    assert_eq!(r.files.len(), 2, "{:?}", r.files);
}

#[test]
fn defaults_come_from_the_external_file_and_instances_set_only_what_the_interface_declares() {
    let dir = folder("defaults");
    write(&dir, "lib.wrl", BALL);
    let main_text = "EXTERNPROTO Ball [ field SFFloat r ] \"lib.wrl#Ball\"\n\
                     Ball { }\nBall { r 3 }\nBall { c 0 0 1 }\n";
    let main = write(&dir, "main.wrl", main_text);
    let (s, r) = load(&main);
    let red = [1.0, 0.0, 0.0];
    let got: Vec<(f64, [f64; 3])> = balls(&s)
        .iter()
        .map(|(_, r, m)| (*r, m.diffuse.to_array()))
        .collect();
    assert_eq!(got, [(0.5, red), (3.0, red), (0.5, red)]);
    assert_eq!(
        headlines(&r),
        [format!(
            "{}:{}: warning: unknown field 'c' of PROTO Ball: ignored",
            main.display(),
            at(main_text, "c 0 0 1", 0)
        )]
    );
}

#[test]
fn an_interface_that_disagrees_with_the_external_proto_is_a_warning_at_each_field() {
    let dir = folder("mismatch");
    write(&dir, "lib.wrl", BALL);
    let main_text = "EXTERNPROTO Ball [ field SFInt32 r\n  field SFColor c\n  field SFVec3f at\n  \
                     field SFBool shiny ] \"lib.wrl#Ball\"\n\
                     Ball { r 2 c 0 0 1 at 1 0 0 shiny TRUE }\n";
    let main = write(&dir, "main.wrl", main_text);
    let (s, r) = load(&main);
    // Only `c` was declared alike: the rest keep the external defaults.
    assert_eq!(balls(&s).len(), 1);
    let (centre, radius, m) = balls(&s)[0];
    assert_eq!((centre, radius), ([0.0; 3], 0.5));
    assert_eq!(m.diffuse.to_array(), [0.0, 0.0, 1.0]);
    let m = main.display();
    let field = |n| at(main_text, "field", n);
    let inst = |needle| at(main_text, needle, 0);
    assert_eq!(
        headlines(&r),
        [
            format!(
                "{m}:{}: warning: EXTERNPROTO Ball declares field SFInt32 r, but PROTO Ball in \
                 'lib.wrl#Ball' has field SFFloat r: it cannot be set",
                field(0)
            ),
            format!(
                "{m}:{}: warning: EXTERNPROTO Ball declares field SFVec3f at, but PROTO Ball in \
                 'lib.wrl#Ball' has exposedField SFVec3f at: it cannot be set",
                field(2)
            ),
            format!(
                "{m}:{}: warning: EXTERNPROTO Ball declares 'shiny', which PROTO Ball in \
                 'lib.wrl#Ball' does not have: it cannot be set",
                field(3)
            ),
            format!(
                "{m}:{}: warning: unknown field 'r' of PROTO Ball: ignored",
                inst("r 2")
            ),
            format!(
                "{m}:{}: warning: unknown field 'at' of PROTO Ball: ignored",
                inst("at 1")
            ),
            format!(
                "{m}:{}: warning: unknown field 'shiny' of PROTO Ball: ignored",
                inst("shiny TRUE")
            ),
        ]
    );
}

#[test]
fn network_and_absolute_urls_are_never_read_and_missing_files_fall_through() {
    let dir = folder("urls");
    write(&dir, "lib.wrl", BALL);
    // A file at an absolute path that would give a sphere of radius 7 if it were read.
    let abs = write(
        &dir,
        "abs.wrl",
        "PROTO Ball [ field SFFloat r 7 ] { Shape { geometry Sphere { radius IS r } } }\n",
    );
    assert!(abs.is_absolute());
    let refused = format!(
        "\"urn:example:Ball\" \"http://example.com/abs.wrl#Ball\" \"file:abs.wrl#Ball\" \
         \"{}#Ball\" \"missing.wrl#Ball\"",
        abs.display()
    );
    let main = write(
        &dir,
        "main.wrl",
        &format!(
            "EXTERNPROTO Ball [ field SFFloat r ] [ {refused} \"lib.wrl#Ball\" ]\nBall {{ }}\n"
        ),
    );
    let (s, r) = load(&main);
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].radius, 0.5);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
    assert_eq!(r.files.len(), 2);
    assert!(r.files[1].ends_with("lib.wrl"), "{:?}", r.files);

    // None leads to a PROTO: one warning saying what was tried; the instance is skipped.
    let main_text = format!(
        "EXTERNPROTO Ball [ field SFFloat r ] [ {refused} \"lib.wrl#Nope\" ]\nBall {{ }}\n"
    );
    let main = write(&dir, "none.wrl", &main_text);
    let (s, r) = load(&main);
    assert!(s.spheres.is_empty());
    assert_eq!(r.skipped.get("Ball"), Some(&1));
    let m = main.display();
    assert_eq!(
        headlines(&r),
        [
            format!(
                "{m}:2:1: warning: EXTERNPROTO Ball not loaded: 'urn:example:Ball' (not a local \
                 relative path), 'http://example.com/abs.wrl#Ball' (not a local relative path), \
                 'file:abs.wrl#Ball' (not a local relative path), '{}#Ball' (not a local \
                 relative path), 'missing.wrl#Ball' (no such file), 'lib.wrl#Nope' (no PROTO \
                 Nope at its top level)",
                abs.display()
            ),
            format!(
                "{m}:3:1: warning: EXTERNPROTO Ball is not available (none of its urls was \
                 loaded): skipped"
            ),
        ]
    );
    assert!(
        !r.files.iter().any(|f| f.ends_with("abs.wrl")),
        "{:?}",
        r.files
    );

    // Other files are not read at all when Inlines are not.
    let main = write(
        &dir,
        "off.wrl",
        "EXTERNPROTO Ball [ ] \"lib.wrl#Ball\"\nBall { }\n",
    );
    let opts = LoadOptions {
        inline: false,
        ..LoadOptions::default()
    };
    let (s, r) = load_with(&main, &opts);
    assert!(s.spheres.is_empty());
    assert_eq!(r.skipped.get("Ball"), Some(&1));
    assert_eq!(r.files.len(), 1);
}

/// Writes `f0.wrl` .. `f{files-1}.wrl`: `f0.wrl` instantiates `f1.wrl`'s P, and each P
/// moves the P of the next file by 1 in x, down to the last, a sphere of radius `r`.
fn extern_chain(test: &str, files: usize) -> PathBuf {
    let dir = folder(test);
    write(
        &dir,
        "f0.wrl",
        "EXTERNPROTO Q [ field SFFloat r ] \"f1.wrl#P\"\nQ { r 2 }\n",
    );
    for k in 1..files {
        let body = if k + 1 < files {
            format!(
                "EXTERNPROTO Q [ field SFFloat r ] \"f{}.wrl#P\"\n\
                 PROTO P [ field SFFloat r 1 ] {{ Transform {{ translation 1 0 0 children Q {{ r IS r }} }} }}\n",
                k + 1
            )
        } else {
            "PROTO P [ field SFFloat r 1 ] { Shape { geometry Sphere { radius IS r } } }\n"
                .to_string()
        };
        write(&dir, &format!("f{k}.wrl"), &body);
    }
    dir.join("f0.wrl")
}

#[test]
fn external_protos_nest_up_to_the_depth_limit() {
    let depth = LoadOptions::default().max_inline_depth;
    // The scene file and 16 files read for their PROTOs, each inside the one before.
    let f0 = extern_chain("depth_limit", depth + 1);
    let (s, r) = load(&f0);
    assert_eq!(r.files.len(), depth + 1);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
    // f1 .. f15 each move by 1; the radius went through every IS.
    assert_eq!(balls(&s).len(), 1);
    let (centre, radius, _) = balls(&s)[0];
    assert_eq!((centre, radius), ([(depth - 1) as f64, 0.0, 0.0], 2.0));
}

#[test]
fn external_protos_past_the_depth_limit_are_an_error_at_the_innermost_declaration() {
    let depth = LoadOptions::default().max_inline_depth;
    let f0 = extern_chain("past_depth_limit", depth + 2);
    let inner = f0.with_file_name(format!("f{depth}.wrl"));
    assert_eq!(
        error(&f0),
        format!(
            "{}:2:1: EXTERNPROTO Q: 'f{}.wrl#P' nests deeper than {depth} files",
            inner.display(),
            depth + 1
        )
    );
}

#[test]
fn the_external_files_nodes_and_names_stay_in_it() {
    let dir = folder("no_leak");
    write(&dir, "lib.wrl", &library());
    write(
        &dir,
        "drawn.wrl",
        "Shape { geometry Sphere { radius 8 } }\n",
    );
    let main_text = "EXTERNPROTO Ball [ ] \"lib.wrl#Ball\"\nBall { }\nSecond { }\n";
    let main = write(&dir, "main.wrl", main_text);
    let (s, r) = load(&main);
    // Only the instance: not the library's sphere, nor its Inline's.
    let radii: Vec<f64> = s.spheres.iter().map(|b| b.radius).collect();
    assert_eq!(radii, [0.5]);
    assert_eq!(r.files.len(), 2, "{:?}", r.files);
    // Its other PROTO and its DEFs are not the scene's.
    assert_eq!(
        headlines(&r),
        [format!(
            "{}:4:1: warning: unknown node type 'Second': skipped",
            main.display()
        )]
    );
    let main = write(
        &dir,
        "use.wrl",
        "EXTERNPROTO Ball [ ] \"lib.wrl#Ball\"\nBall { }\nUSE Big\n",
    );
    assert_eq!(
        error(&main),
        format!("{}:4:1: USE of undefined name 'Big'", main.display())
    );
}

#[test]
fn errors_and_origins_of_an_external_body_point_into_its_file() {
    let dir = folder("positions");
    let lib_text = "PROTO Ball [ field MFNode kids [ ] ] {\n  \
                    Group { children [ Shape { geometry Sphere { } } Group { children IS kids } ] } }\n\
                    PROTO Bad [ ] {\n  Shape { geometry Sphere { radius -1 } } }\n";
    let lib = write(&dir, "lib.wrl", lib_text);
    let main_text = "EXTERNPROTO Ball [ field MFNode kids ] \"lib.wrl#Ball\"\n\
                     Ball { kids Shape { geometry Sphere { radius 2 bogus 1 } } }\n";
    let main = write(&dir, "main.wrl", main_text);
    let (s, r) = load(&main);
    // A warning in the instance's value is in the scene file.
    assert_eq!(
        headlines(&r),
        [format!(
            "{}:{}: warning: unknown field 'bogus' of Sphere: ignored",
            main.display(),
            at(main_text, "bogus", 0)
        )]
    );
    // Each sphere remembers the file it was written in.
    let origins: Vec<String> = s.spheres.iter().map(|b| s.position(b.origin)).collect();
    assert_eq!(
        origins,
        [
            format!("{}:{}", lib.display(), at(lib_text, "Sphere", 0)),
            format!("{}:{}", main.display(), at(main_text, "Sphere", 0)),
        ]
    );
    // An error met while an external body expands is in its file.
    let main = write(
        &dir,
        "bad.wrl",
        "EXTERNPROTO Bad [ ] \"lib.wrl#Bad\"\nBad { }\n",
    );
    assert_eq!(
        error(&main),
        format!(
            "{}:{}: Sphere radius must be positive, found -1",
            lib.display(),
            at(lib_text, "radius -1", 0)
        )
    );
    // And so is a syntax error in it.
    let broken = write(
        &dir,
        "broken.wrl",
        "PROTO Ball [ ] {\n  Shape { geometry Sphere { ] } }\n",
    );
    let main = write(
        &dir,
        "syntax.wrl",
        "EXTERNPROTO Ball [ ] \"broken.wrl\"\nBall { }\n",
    );
    let e = error(&main);
    assert!(e.starts_with(&format!("{}:3:", broken.display())), "{e}");
}

#[test]
fn the_body_sees_its_files_protos_and_the_instances_values_see_the_scenes() {
    let dir = folder("namespaces");
    write(
        &dir,
        "lib.wrl",
        "PROTO Paint [ ] { Material { diffuseColor 1 0 0 } }\n\
         PROTO Ball [ field MFNode kids [ ] ] { Group { children [\n  \
         Shape { appearance Appearance { material Paint { } } geometry Sphere { } }\n  \
         Group { children IS kids } ] } }\n",
    );
    let main = write(
        &dir,
        "main.wrl",
        "PROTO Paint [ ] { Material { diffuseColor 0 0 1 } }\n\
         EXTERNPROTO Ball [ field MFNode kids ] \"lib.wrl#Ball\"\n\
         Ball { kids Shape { appearance Appearance { material Paint { } } geometry Sphere { radius 2 } } }\n",
    );
    let (s, r) = load(&main);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
    let got: Vec<(f64, [f64; 3])> = balls(&s)
        .iter()
        .map(|(_, r, m)| (*r, m.diffuse.to_array()))
        .collect();
    assert_eq!(got, [(1.0, [1.0, 0.0, 0.0]), (2.0, [0.0, 0.0, 1.0])]);
}

#[test]
fn urls_in_an_external_file_are_relative_to_it() {
    let dir = folder("relative");
    // Beside the scene: files of the same names that must not be read.
    write(&dir, "part.wrl", "Shape { geometry Sphere { radius 5 } }\n");
    write(
        &dir,
        "far.wrl",
        "PROTO Far [ ] { Shape { geometry Sphere { radius 6 } } }\n",
    );
    write(
        &dir,
        "sub/part.wrl",
        "Shape { geometry Sphere { radius 3 } }\n",
    );
    write(
        &dir,
        "sub/far.wrl",
        "PROTO Far [ ] { Shape { geometry Sphere { radius 4 } } }\n",
    );
    // An EXTERNPROTO at the top level of sub/lib.wrl, and one and an Inline in a body (read
    // when it expands, in the scene file).
    write(
        &dir,
        "sub/lib.wrl",
        "EXTERNPROTO Near [ ] \"far.wrl\"\n\
         PROTO Ball [ ] { EXTERNPROTO Far [ ] \"far.wrl#Far\"\n  \
         Group { children [ Inline { url \"part.wrl\" } Far { } Near { } ] } }\n",
    );
    let main = write(
        &dir,
        "main.wrl",
        "EXTERNPROTO Ball [ ] \"sub/lib.wrl#Ball\"\nBall { }\n",
    );
    let (s, r) = load(&main);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
    let radii: Vec<f64> = s.spheres.iter().map(|b| b.radius).collect();
    assert_eq!(radii, [3.0, 4.0, 4.0]);
}

#[test]
fn a_gzipped_external_file_is_read_by_its_content() {
    use std::io::Write as _;
    let dir = folder("gzip");
    let mut enc = flate2::write::GzEncoder::new(
        std::fs::File::create(dir.join("lib.wrl")).unwrap(),
        flate2::Compression::default(),
    );
    enc.write_all(format!("{HEADER}{BALL}").as_bytes()).unwrap();
    enc.finish().unwrap();
    let main = write(
        &dir,
        "main.wrl",
        "EXTERNPROTO Ball [ ] \"lib.wrl\"\nBall { }\n",
    );
    let (s, r) = load(&main);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn a_file_read_inside_a_recorded_node_stays_out_of_its_recording() {
    // part.wrl is Inline'd inside a DEF, so the Group's events are being recorded when
    // part.wrl's EXTERNPROTO reads lib.wrl: lib.wrl's events must not become the Group's
    // (a USE would then draw the library's own sphere and declare its PROTOs here).
    let dir = folder("inside_def");
    write(&dir, "lib.wrl", &library());
    write(
        &dir,
        "drawn.wrl",
        "Shape { geometry Sphere { radius 8 } }\n",
    );
    write(
        &dir,
        "part.wrl",
        "EXTERNPROTO Ball [ ] \"lib.wrl#Ball\"\nBall { }\n",
    );
    let main = write(
        &dir,
        "main.wrl",
        "DEF G Group { children [ Inline { url \"part.wrl\" } Shape { geometry Sphere { radius 2 } } ] }\n\
         Transform { translation 5 0 0 children USE G }\nSecond { }\n",
    );
    let (s, r) = load(&main);
    assert!(
        s.spheres.iter().all(|b| b.radius == 0.5 || b.radius == 2.0),
        "{:?}",
        balls(&s)
    );
    // The Group's own sphere, once in place and once moved.
    let twos: Vec<[f64; 3]> = balls(&s)
        .iter()
        .filter(|b| b.1 == 2.0)
        .map(|b| b.0)
        .collect();
    assert_eq!(twos, [[0.0; 3], [5.0, 0.0, 0.0]]);
    assert_eq!(r.skipped.get("Second"), Some(&1));
}

mod cycles;
