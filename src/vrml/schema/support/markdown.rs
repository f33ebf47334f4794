//! The page `docs/vrml.md`, made from the support table and the node interfaces.

use super::*;

/// The page's text before the node tables.
const INTRO: &str = r#"# VRML97 support

<!-- Made by support_markdown() from src/vrml/schema/support.rs: do not edit by hand.
     Remake it with: GTSPHERE_WRITE_DOCS=1 cargo test -p gtsphere --lib vrml_support -->

gtsphere reads scenes in VRML97 (ISO/IEC 14772-1:1997) and draws one still image of them.
This page says, for each of the 54 standard node types and each member of its interface,
what gtsphere does with it. It is generated from the reader's own tables
(`src/vrml/schema/`), and a test fails when it no longer matches them.

## Reading the tables

What gtsphere does with a value:

- **used**: the value goes into the scene (something drawn, the camera, a light, the
  background).
- **ignored**: read and checked against the field's type, then dropped without a warning.
- **warning**: dropped with a warning. `gtsphere info` lists the warnings; `--strict` turns
  each into an error.
- **not read**: passed over: no type check, no warning.
- **refused**: loading stops with an error at the value (`file:line:col`).

The node types fall into four kinds:

- **Used**: read into the scene. Each field is looked up in the node's interface: an
  unknown field name is a warning, a value given to an eventIn or eventOut is a warning, and
  a value of the wrong type (`translation 1 2`) is refused. An exposedField `x` has the
  events `set_x` and `x_changed`.
- **Mesh**: IndexedFaceSet, PointSet, ElevationGrid and Extrusion are drawn, but their
  fields are read leniently, without the interface: an unknown field name, an event or a
  value of another type is passed over without a warning.
- **Mesh part**: Coordinate, Color and Normal are read, leniently, in the field of a mesh
  that takes them (`coord`, `color`, `normal`); anywhere else they are skipped.
- **Skipped**: the standard node types gtsphere does not model. They are valid VRML97, so
  they are counted under `skipped` in the load report (`gtsphere info`), without a warning.
  Nothing in them is drawn and their fields are not read; DEF names in them can still be
  used.

The defaults are VRML97's; a field that is not given has its default value.

## Beyond the standard nodes

- **Unknown node types** (neither standard nor a PROTO): a warning
  (`unknown node type 'X': skipped`), and they are counted as skipped. Nothing in them is
  drawn and their fields are not read; DEF names in them can still be used.
- **PROTO**: an instance is drawn as the first node of the PROTO's body, its `IS` fields
  taken from the instance or from the interface's defaults; the other nodes of the body are
  not drawn. The instance's fields are checked against the PROTO's interface as a standard
  node's are. A PROTO may take a standard node's name; the name then means the PROTO.
- **EXTERNPROTO**: the PROTO is read from the first url that names a readable local file
  (`file.wrl#Name`, or the first PROTO of `file.wrl`), by the rules of Inline. None
  readable: a warning, and each instance is skipped with a warning. A url may name the
  file itself (`own.wrl#Ball` inside own.wrl) or a file being read: its PROTO declarations
  are read again, not its scene. Only a declaration that needs itself is refused (a cycle).
- **GasParticle**: a PROTO of this name with a `field SFString profile` gives the spheres
  of its instances a density profile (see [the rendering model](model.md)); other viewers
  draw its body.
- **DEF and USE**: a USE draws the DEF'd node again, where it stands; a USE of a name not
  defined is refused.
- **ROUTE**: checked, not run. A node not defined, an event the node lacks, an event of the
  wrong direction or two events of different types is a warning.
- **Script**: not run (see [Script](#script)).

## Limits

A file costs what its text declares:

- **Expansion.** What USE, PROTO instances, `IS` and generated geometry create (nodes,
  copied events and their values, the triangles of a reused mesh, an Extrusion's points) may
  reach 4,194,304 plus 16 per byte of text read. Text read straight spends about one per
  byte, so only copies that multiply can pass it: a file of 30 DEFs each USEing the one
  before twice (2^30 spheres from 2 KB) is refused at the USE that goes over, with its
  `file:line:col`, before the copies are made. `--max-expansion K` (Python:
  `load(..., max_expansion=K)`) sets the 16.
- **Compressed text.** Gzip data may inflate to 16 MiB plus 8 K (128) times its compressed
  size; VRML text compresses 3 to 12 times. Long runs of white space are passed as they are
  read, not held.
- **Colours.** A negative colour or intensity (Material, PointLight, DirectionalLight) is
  clamped to 0 with a warning; a shininess or transparency outside [0, 1] is clamped to it
  with a warning. Values above 1 are used as given.
- **Nesting.** USE, Switch and PROTO replays nest at most 200 deep; Inline files and files
  read for EXTERNPROTOs at most 16.
"#;

/// The name of a kind of node, for the page.
fn role_name(role: NodeRole) -> &'static str {
    match role {
        NodeRole::Used => "Used",
        NodeRole::Mesh => "Mesh",
        NodeRole::MeshPart => "Mesh part",
        NodeRole::Skipped => "Skipped",
    }
}

/// The mdBook anchor of a node's heading (`### Transform` -> `transform`).
fn anchor(name: &str) -> String {
    name.to_ascii_lowercase()
}

/// What happens to a member, for the last column of a node's table.
fn what_happens(node: NodeRole, f: &FieldSupport) -> String {
    let label = match (f.role, node) {
        (FieldRole::Used, _) => "**used**",
        (FieldRole::Ignored, _) => "**ignored**",
        (FieldRole::NotRead, _) => "**not read**",
        (FieldRole::Event, NodeRole::Used) => "**warning** if given a value",
        (FieldRole::Event, _) => "**not read**",
    };
    if f.note.is_empty() {
        label.to_string()
    } else {
        format!("{label}. {}", f.note)
    }
}

/// `value` as code in a table cell (empty stays empty).
fn code(value: &str) -> String {
    if value.is_empty() {
        String::new()
    } else {
        format!("`{value}`")
    }
}

/// The table of a node that gtsphere reads.
fn read_node_table(out: &mut String, n: &NodeSupport, spec: &NodeSpec) {
    out.push_str("| Field | Access | Type | Default | gtsphere |\n");
    out.push_str("|---|---|---|---|---|\n");
    for (f, s) in n.fields.iter().zip(spec.fields) {
        let _ = writeln!(
            out,
            "| `{}` | {} | {} | {} | {} |",
            f.name,
            s.access.keyword(),
            s.ty.name(),
            code(f.default),
            what_happens(n.role, f)
        );
    }
}

/// The table of a skipped node: its members, none of them read.
fn skipped_node_table(out: &mut String, spec: &NodeSpec) {
    out.push_str("| Field | Access | Type |\n");
    out.push_str("|---|---|---|\n");
    for s in spec.fields {
        let _ = writeln!(
            out,
            "| `{}` | {} | {} |",
            s.name,
            s.access.keyword(),
            s.ty.name()
        );
    }
}

/// The page `docs/vrml.md`: what gtsphere does with every standard node type and every member
/// of its interface, from [`SUPPORT`] and [`NODES`].
pub fn support_markdown() -> String {
    let mut out = String::from(INTRO);
    out.push_str("\n## Node types by kind\n\n");
    for role in [
        NodeRole::Used,
        NodeRole::Mesh,
        NodeRole::MeshPart,
        NodeRole::Skipped,
    ] {
        let links: Vec<String> = SUPPORT
            .iter()
            .filter(|n| n.role == role)
            .map(|n| format!("[{}](#{})", n.name, anchor(n.name)))
            .collect();
        let _ = writeln!(out, "- **{}**: {}.", role_name(role), links.join(", "));
    }
    out.push_str("\n## Node types\n");
    for (n, spec) in SUPPORT.iter().zip(NODES) {
        let _ = write!(
            out,
            "\n### {}\n\n**{}.** {}",
            n.name,
            role_name(n.role),
            n.summary
        );
        if n.role == NodeRole::Skipped {
            out.push_str(" Its fields are not read.\n\n");
            skipped_node_table(&mut out, spec);
        } else {
            out.push_str("\n\n");
            read_node_table(&mut out, n, spec);
        }
    }
    out
}
