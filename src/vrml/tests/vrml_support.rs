//! docs/vrml.md is what `support_markdown` makes of the schema's support tables, and those
//! tables say what the reader does. Each node type is loaded in a setting where its fields
//! matter (a Sphere in a Shape, a Material in a Shape's Appearance, ...), and for each member:
//! a default given explicitly changes nothing; a used field given another value changes the
//! scene; an ignored or unread one changes neither the scene nor the warnings; an event given
//! a value warns exactly where the node's fields are checked; an unknown field name warns
//! likewise; and skipped nodes are counted as skipped, their fields unread.

use std::path::PathBuf;
use std::sync::OnceLock;

use crate::scene::Scene;
use crate::vrml::schema::{node_spec, support_markdown, FieldRole, FieldType, NodeRole, SUPPORT};
use crate::vrml::{load_str, LoadOptions, LoadReport};

/// The page, from the crate root.
const PAGE: &str = "docs/vrml.md";
/// The command that writes the page anew.
const REMAKE: &str = "GTSPHERE_WRITE_DOCS=1 cargo test -p gtsphere --lib vrml_support";

#[test]
fn docs_vrml_md_is_what_the_tables_make() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(PAGE);
    let want = support_markdown();
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    let write =
        || std::fs::write(&path, &want).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    crate::testing::generated_page(PAGE, &have, &want, write, REMAKE);
}

/// A folder for the scenes loaded here, with `part.wrl` (one sphere) for Inline's url.
fn folder() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = crate::testing::scratch("vrml_support", "scenes");
        std::fs::write(
            dir.join("part.wrl"),
            "#VRML V2.0 utf8\nShape { geometry Sphere { radius 3 } }\n",
        )
        .unwrap();
        dir
    })
}

/// Loads `#VRML V2.0 utf8` + `body`: the scene, its warnings and its skipped counts.
fn load(body: &str) -> (Scene, Vec<String>, LoadReport) {
    let name = folder().join("test.wrl");
    let text = format!("#VRML V2.0 utf8\n{body}\n");
    match load_str(&name.display().to_string(), &text, &LoadOptions::default()) {
        Ok((scene, report)) => {
            let warnings = report.warnings.iter().map(|w| w.message.clone()).collect();
            (scene, warnings, report)
        }
        Err(e) => panic!("{body}\ndid not load: {e}"),
    }
}

const SPHERE: &str = "Shape { geometry Sphere {} }";
const LIT: &str = "appearance Appearance { material Material {} }";
const POINTS: &str = "[ 0 0 0, 1 0 0, 1 1 0, 0 1 0.2 ]";
const COLOURS: &str = "[ 1 0 0, 0 1 0, 0 0 1, 1 1 0 ]";
const NORMALS: &str = "[ 0 0 1, 0 1 1, 1 0 1, 0 0 -1 ]";
const FACES: &str = "[ 0 1 2 -1, 0 2 3 -1 ]";

/// Where a node of type `ty` stands so that its fields matter: the text before it, the fields
/// it has besides the one tested, and the text after it.
fn setting(ty: &str) -> (String, Vec<(&'static str, String)>, String) {
    let s = String::from;
    let coord = ("coord", format!("Coordinate {{ point {POINTS} }}"));
    let color = ("color", format!("Color {{ color {COLOURS} }}"));
    let faces = ("coordIndex", s(FACES));
    let mesh = |inner: &str| {
        (
            format!("Shape {{ {LIT} geometry IndexedFaceSet {{ {inner} "),
            vec![],
            s(" } }"),
        )
    };
    match ty {
        "Anchor" | "Billboard" | "Collision" | "Group" => {
            (s(""), vec![("children", s(SPHERE))], s(""))
        }
        // (A box, not a sphere at the origin: rotations move it.)
        "Transform" => (
            s(""),
            vec![("children", s("Shape { geometry Box { size 1 2 3 } }"))],
            s(""),
        ),
        "LOD" => (s(""), vec![("level", format!("[ {SPHERE} ]"))], s("")),
        "Switch" => (
            s(""),
            vec![("choice", format!("[ {SPHERE} ]")), ("whichChoice", s("0"))],
            s(""),
        ),
        "Shape" => (
            s(""),
            vec![
                ("appearance", s("Appearance { material Material {} }")),
                ("geometry", s("Sphere {}")),
            ],
            s(""),
        ),
        "Appearance" => (
            s("Shape { appearance "),
            vec![("material", s("Material {}"))],
            s(" geometry Sphere {} }"),
        ),
        "Material" => (
            s("Shape { appearance Appearance { material "),
            vec![],
            s(" } geometry Sphere {} }"),
        ),
        "Sphere" | "Box" | "Cone" | "Cylinder" | "IndexedFaceSet" | "PointSet"
        | "ElevationGrid" | "Extrusion" => {
            let base = match ty {
                "IndexedFaceSet" => vec![coord, faces, color],
                "PointSet" => vec![coord],
                "ElevationGrid" => vec![
                    ("xDimension", s("2")),
                    ("zDimension", s("2")),
                    ("height", s("[ 0 0.1 0.2 0.4 ]")),
                    color,
                ],
                _ => vec![],
            };
            (format!("Shape {{ {LIT} geometry "), base, s(" }"))
        }
        "Coordinate" => mesh(&format!("coordIndex {FACES} coord")),
        "Color" => mesh(&format!(
            "coordIndex {FACES} coord Coordinate {{ point {POINTS} }} color"
        )),
        "Normal" => mesh(&format!(
            "coordIndex {FACES} coord Coordinate {{ point {POINTS} }} normal"
        )),
        _ => (s(""), vec![], s("")),
    }
}

/// More fields of the setting that a field needs to matter (a Transform's `center` only
/// moves what it rotates or scales).
fn needs(ty: &str, field: &str) -> Vec<(&'static str, String)> {
    let s = String::from;
    match (ty, field) {
        ("Transform", "center") => vec![("rotation", s("0 0 1 1"))],
        ("Transform", "scaleOrientation") => vec![("scale", s("1 2 3"))],
        ("IndexedFaceSet", "normalIndex" | "normalPerVertex") => {
            vec![("normal", format!("Normal {{ vector {NORMALS} }}"))]
        }
        ("ElevationGrid", "normalPerVertex") => {
            vec![("normal", format!("Normal {{ vector {NORMALS} }}"))]
        }
        _ => vec![],
    }
}

/// A value of the member's type other than its default, that changes the scene where the
/// member is used.
fn sample(ty: &str, field: &str, t: FieldType, default: &str) -> String {
    let special = match (ty, field) {
        ("Collision", "proxy") => Some(SPHERE.to_string()),
        ("Appearance", "material") => Some("Material {}".into()),
        ("Shape", "appearance") => Some("Appearance { material Material {} }".into()),
        ("Shape", "geometry") => Some("Sphere {}".into()),
        ("Inline", "url") => Some("\"part.wrl\"".into()),
        (_, "coord") => Some(format!("Coordinate {{ point {POINTS} }}")),
        (_, "color") if t == FieldType::SFNode => Some(format!("Color {{ color {COLOURS} }}")),
        (_, "normal") => Some(format!("Normal {{ vector {NORMALS} }}")),
        ("Coordinate", "point") => Some(POINTS.into()),
        ("Color", "color") => Some(COLOURS.into()),
        ("Normal", "vector") => Some(NORMALS.into()),
        ("ElevationGrid", "xDimension" | "zDimension") => Some("2".into()),
        ("ElevationGrid", "height") => Some("[ 0 0.5 0.25 1 ]".into()),
        ("Extrusion", "creaseAngle") => Some("3".into()),
        ("Extrusion", "crossSection") => Some("[ 1 1, 1 -1, -1 -1, 1 1 ]".into()),
        ("Extrusion", "spine") => Some("[ 0 0 0, 0 2 0 ]".into()),
        _ => None,
    };
    if let Some(v) = special {
        return v;
    }
    use FieldType::*;
    let v = match t {
        SFBool if default == "TRUE" => "FALSE",
        SFBool => "TRUE",
        SFColor | SFVec3f => "0.25 0.5 0.75",
        SFFloat => "0.5",
        SFImage => "1 1 1 255",
        SFInt32 => "0",
        SFNode => "WorldInfo {}",
        SFRotation => "0 1 0 0.5",
        SFString => "\"x\"",
        SFTime | MFTime => "1",
        SFVec2f | MFVec2f => "0.5 0.25",
        MFColor | MFVec3f => "[ 0.25 0.5 0.75 ]",
        MFFloat => "[ 0.5 ]",
        MFInt32 => "[ 0 1 2 -1 ]",
        MFNode => return format!("[ {SPHERE} ]"),
        MFRotation => "[ 0 1 0 0.5 ]",
        MFString => "[ \"x\" ]",
    };
    v.to_string()
}

/// The scene of node `ty` in its setting with `field` given `value` (None: the same text with
/// blanks instead, so that every later position stays where it is).
fn with_field(ty: &str, field: &str, value: Option<&str>, blank_as: &str) -> String {
    let (before, mut base, after) = setting(ty);
    base.extend(needs(ty, field));
    base.retain(|(name, _)| *name != field);
    let mut inner: String = base.iter().map(|(n, v)| format!("{n} {v} ")).collect();
    let given = format!("{field} {}", value.unwrap_or(blank_as));
    match value {
        Some(_) => inner.push_str(&given),
        None => inner.push_str(&" ".repeat(given.len())),
    }
    format!("{before}{ty} {{ {inner} }}{after}")
}

/// The default as the reader holds it (VRML97 writes fieldOfView's as 0.785398; the reader's
/// is pi/4 to the last bit).
fn exact_default(default: &str) -> &str {
    match default {
        "0.785398" => "0.7853981633974483",
        d => d,
    }
}

/// Every member of every node the reader reads: (node, field, role, type, default).
fn read_members() -> Vec<(
    &'static str,
    &'static str,
    FieldRole,
    FieldType,
    &'static str,
)> {
    let mut out = Vec::new();
    for n in SUPPORT.iter().filter(|n| n.role != NodeRole::Skipped) {
        let spec = node_spec(n.name).unwrap();
        for (f, s) in n.fields.iter().zip(spec.fields) {
            out.push((n.name, f.name, f.role, s.ty, f.default));
        }
    }
    out
}

/// Fails with every member in `bad`: the tables say what the reader does not.
fn none_differ(what: &str, bad: Vec<String>) {
    assert!(
        bad.is_empty(),
        "src/vrml/schema/support.rs says otherwise than the reader ({what}):\n\n{}\n\n\
         Correct the tables, then remake the page with `{REMAKE}`.",
        bad.join("\n\n")
    );
}

#[test]
fn a_default_given_changes_nothing() {
    let mut bad = Vec::new();
    for (ty, field, role, _, default) in read_members() {
        if role == FieldRole::Event {
            continue;
        }
        let default = exact_default(default);
        let text = with_field(ty, field, Some(default), "");
        let given = load(&text);
        let absent = load(&with_field(ty, field, None, default));
        if given.0 != absent.0 || given.1 != absent.1 {
            bad.push(format!(
                "{ty}.{field}: the default {default} is not the reader's:\n{text}"
            ));
        }
    }
    none_differ("defaults", bad);
}

#[test]
fn a_used_field_changes_the_scene() {
    let mut bad = Vec::new();
    for (ty, field, role, t, default) in read_members() {
        if role != FieldRole::Used {
            continue;
        }
        let value = sample(ty, field, t, default);
        let text = with_field(ty, field, Some(&value), "");
        if load(&text).0 == load(&with_field(ty, field, None, &value)).0 {
            bad.push(format!(
                "{ty}.{field}: used, yet {value} changes nothing:\n{text}"
            ));
        }
    }
    none_differ("used fields", bad);
}

#[test]
fn an_ignored_or_unread_field_changes_nothing() {
    let mut bad = Vec::new();
    for (ty, field, role, t, default) in read_members() {
        if !matches!(role, FieldRole::Ignored | FieldRole::NotRead) {
            continue;
        }
        let value = sample(ty, field, t, default);
        let text = with_field(ty, field, Some(&value), "");
        let given = load(&text);
        let absent = load(&with_field(ty, field, None, &value));
        if given.0 != absent.0 || given.1 != absent.1 {
            bad.push(format!(
                "{ty}.{field}: {role:?}, yet {value} changes the scene or its warnings \
                 ({:?}):\n{text}",
                given.1
            ));
        }
    }
    none_differ("ignored and unread fields", bad);
}

#[test]
fn an_event_given_a_value_warns_where_fields_are_checked() {
    let mut bad = Vec::new();
    for (ty, field, role, t, _) in read_members() {
        if role != FieldRole::Event {
            continue;
        }
        let checked = SUPPORT
            .iter()
            .any(|n| n.name == ty && n.role == NodeRole::Used);
        let value = sample(ty, field, t, "");
        let (_, warnings, _) = load(&with_field(ty, field, Some(&value), ""));
        let warned = warnings.iter().any(|w| w.contains("not a field: ignored"));
        if warned != checked {
            bad.push(format!("{ty}.{field} {value}: warnings {warnings:?}"));
        }
    }
    none_differ("events given a value", bad);
}

#[test]
fn unknown_field_names_warn_where_fields_are_checked() {
    let mut bad = Vec::new();
    for n in SUPPORT {
        let (_, warnings, _) = load(&with_field(n.name, "noSuchField", Some("1"), ""));
        let warned = warnings
            .iter()
            .any(|w| w.contains("unknown field 'noSuchField'"));
        if warned != (n.role == NodeRole::Used) {
            bad.push(format!("{} ({:?}): warnings {warnings:?}", n.name, n.role));
        }
    }
    none_differ("unknown field names", bad);
}

#[test]
fn skipped_nodes_are_counted_and_their_fields_not_read() {
    let mut bad = Vec::new();
    for n in SUPPORT {
        let spec = node_spec(n.name).unwrap();
        let skipped = matches!(n.role, NodeRole::Skipped | NodeRole::MeshPart);
        // A mesh part stands alone here, where it is skipped; every member of a skipped node
        // is given a string, which no type check would pass.
        let body = if skipped {
            let fields: String = spec
                .fields
                .iter()
                .map(|f| format!("{} \"not read\" ", f.name))
                .collect();
            format!("{} {{ {fields}}}", n.name)
        } else {
            with_field(n.name, "", None, "")
        };
        let (_, warnings, report) = load(&body);
        let counted = report.skipped.get(n.name).copied().unwrap_or(0);
        if counted != u64::from(skipped) || (skipped && !warnings.is_empty()) {
            bad.push(format!(
                "{} ({:?}): counted {counted} times as skipped, warnings {warnings:?}:\n{body}",
                n.name, n.role
            ));
        }
    }
    none_differ("skipped nodes", bad);
}
