//! What gtsphere does with each standard node type and each member of its interface, as data
//! next to the interfaces themselves: [`SUPPORT`] has one [`NodeSupport`] per entry of
//! [`NODES`], in the same order, and each node that gtsphere reads lists every member of its
//! interface in declaration order with its VRML97 default and what becomes of a value
//! ([`FieldRole`]). [`support_markdown`] turns the two tables into the page `docs/vrml.md`;
//! a test of the integration tests fails when that file differs from it, and the unit tests
//! below fail when a node or member of [`NODES`] is not classified here.
//!
//! The tables describe the lowering (`crate::vrml::lower`): which node types it models and
//! which fields it stores. The integration tests check them against it by loading scenes:
//! skipped nodes are counted as skipped, unknown names and events warn where the table says,
//! a default given explicitly changes nothing, and an ignored field changes nothing either.

use std::fmt::Write as _;

use super::{NodeSpec, NODES};

/// How gtsphere reads a standard node type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeRole {
    /// Lowered into the scene (drawn, or used for the camera, the lights or the background),
    /// its fields checked against its interface: an unknown name or a value given to an event
    /// is a warning, a value of the wrong type an error.
    Used,
    /// Drawn as a Shape's geometry, its fields read leniently without the interface: an
    /// unknown name, an event or a value of another type is passed over without a warning
    /// (IndexedFaceSet, PointSet, ElevationGrid, Extrusion).
    Mesh,
    /// Read, leniently, only in the field of a mesh that takes it (Coordinate, Color,
    /// Normal); anywhere else skipped.
    MeshPart,
    /// Not modelled: counted in the load report's `skipped`, without a warning; nothing in it
    /// is drawn and its fields are not read.
    Skipped,
}

/// What gtsphere does with a member of a node's interface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldRole {
    /// The value goes into the scene.
    Used,
    /// Read and checked against the field's type, then dropped without a warning.
    Ignored,
    /// Passed over: no type check, no warning.
    NotRead,
    /// An eventIn or eventOut: it takes no value in a file. A value given to one is a
    /// warning where the node's fields are checked ([`NodeRole::Used`]), passed over
    /// otherwise; ROUTEs to and from it are checked, not run.
    Event,
}

/// What gtsphere does with one member of a node's interface.
#[derive(Debug)]
pub struct FieldSupport {
    /// The member's name, as in the node's [`NodeSpec`].
    pub name: &'static str,
    /// What becomes of a value.
    pub role: FieldRole,
    /// The VRML97 default as written in a file (`0 0 1 0`, `[]`, `NULL`); empty for events.
    pub default: &'static str,
    /// More about what happens (limits, warnings, refusals); empty or whole sentences.
    pub note: &'static str,
}

/// What gtsphere does with one standard node type.
#[derive(Debug)]
pub struct NodeSupport {
    /// The node type's name, as in [`NODES`].
    pub name: &'static str,
    /// How it is read.
    pub role: NodeRole,
    /// What it becomes, in whole sentences.
    pub summary: &'static str,
    /// Every member of its interface in declaration order; empty for a
    /// [`NodeRole::Skipped`] node, whose fields are not read.
    pub fields: &'static [FieldSupport],
}

impl NodeSupport {
    /// The node's interface ([`NODES`] entry of the same name).
    pub fn spec(&self) -> Option<&'static NodeSpec> {
        super::node_spec(self.name)
    }

    /// What happens to the member `name` of this node: its entry's role, [`FieldRole::NotRead`]
    /// for any member of a skipped node; None for a name the node's interface lacks.
    pub fn field_role(&self, name: &str) -> Option<FieldRole> {
        let spec = self.spec()?.field(name)?;
        match self.role {
            NodeRole::Skipped => Some(FieldRole::NotRead),
            _ => self
                .fields
                .iter()
                .find(|f| f.name == spec.name)
                .map(|f| f.role),
        }
    }
}

/// The entry of the standard node type named `name`.
pub fn node_support(name: &str) -> Option<&'static NodeSupport> {
    super::node_index(name).map(|i| &SUPPORT[i])
}

const fn used(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Used,
        default,
        note,
    }
}

const fn ignored(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Ignored,
        default,
        note,
    }
}

const fn not_read(name: &'static str, default: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::NotRead,
        default,
        note,
    }
}

const fn event(name: &'static str, note: &'static str) -> FieldSupport {
    FieldSupport {
        name,
        role: FieldRole::Event,
        default: "",
        note,
    }
}

const fn node(
    name: &'static str,
    role: NodeRole,
    summary: &'static str,
    fields: &'static [FieldSupport],
) -> NodeSupport {
    NodeSupport {
        name,
        role,
        summary,
        fields,
    }
}

const fn skipped(name: &'static str, summary: &'static str) -> NodeSupport {
    node(name, NodeRole::Skipped, summary, &[])
}

/// The note of `addChildren` and `removeChildren` of the grouping nodes.
const CHILD_EVENT: &str =
    "The warning says the value is ignored, yet the nodes given are drawn as children.";
const BBOX_CENTER: FieldSupport = ignored("bboxCenter", "0 0 0", "");
const BBOX_SIZE: FieldSupport = ignored("bboxSize", "-1 -1 -1", "");
const CHILDREN: FieldSupport = used("children", "[]", "");
const ADD_CHILDREN: FieldSupport = event("addChildren", CHILD_EVENT);
const REMOVE_CHILDREN: FieldSupport = event("removeChildren", CHILD_EVENT);
const SET_BIND: FieldSupport = event("set_bind", "");
const IS_BOUND: FieldSupport = event("isBound", "");
const ANIMATION: &str = "No animation: the image is one still frame.";
const SENSOR: &str = "No interaction: the image is one still frame.";
const TEXTURE: &str = "Textures are not applied: the Material's colours are used.";
const MESH_COLOR: &str = "A Color node: one colour per vertex or per face, as colorPerVertex says.";
const MESH_NORMAL: &str = "A Normal node.";
const CREASE: &str = "Gives the normals when no Normal node does (0: flat faces).";
const NOT_INTEGERS: &str =
    "Values that are not integers: the mesh is not drawn and is counted as skipped, without a warning.";
const CONVEX: &str = "Faces are triangulated as they are, concave or not.";

/// One entry per entry of [`NODES`], in the same order.
pub static SUPPORT: &[NodeSupport] = &[
    node(
        "Anchor",
        NodeRole::Used,
        "Drawn as a Group: its children are drawn; the link is not followed.",
        &[
            ADD_CHILDREN,
            REMOVE_CHILDREN,
            CHILDREN,
            ignored("description", "\"\"", ""),
            ignored("parameter", "[]", ""),
            ignored("url", "[]", ""),
            BBOX_CENTER,
            BBOX_SIZE,
        ],
    ),
    node(
        "Appearance",
        NodeRole::Used,
        "Gives its Shape a Material. Textures are not applied.",
        &[
            used(
                "material",
                "NULL",
                "A Material; another node type is a warning and is ignored. Without one the \
                 Shape is unlit: white, or the colours of its mesh's Color node.",
            ),
            ignored("texture", "NULL", "Its node is skipped."),
            ignored("textureTransform", "NULL", "Its node is skipped."),
        ],
    ),
    skipped("AudioClip", "No sound."),
    node(
        "Background",
        NodeRole::Used,
        "The first Background in file order gives the colour behind the scene (black without \
         one); later ones are ignored without a warning.",
        &[
            SET_BIND,
            ignored("groundAngle", "[]", ""),
            ignored("groundColor", "[]", ""),
            ignored("backUrl", "[]", ""),
            ignored("bottomUrl", "[]", ""),
            ignored("frontUrl", "[]", ""),
            ignored("leftUrl", "[]", ""),
            ignored("rightUrl", "[]", ""),
            ignored("topUrl", "[]", ""),
            ignored("skyAngle", "[]", ""),
            used(
                "skyColor",
                "0 0 0",
                "Its first colour is the background; the others are ignored.",
            ),
            IS_BOUND,
        ],
    ),
    node(
        "Billboard",
        NodeRole::Used,
        "Drawn as a Group: its children are drawn, not turned to face the viewer.",
        &[
            ADD_CHILDREN,
            REMOVE_CHILDREN,
            ignored("axisOfRotation", "0 1 0", ""),
            CHILDREN,
            BBOX_CENTER,
            BBOX_SIZE,
        ],
    ),
    node(
        "Box",
        NodeRole::Used,
        "Drawn as an exact opaque box when it is a Shape's geometry (left out by \
         `--spheres-only`).",
        &[used(
            "size",
            "2 2 2",
            "Each component must be above 0, else refused.",
        )],
    ),
    node(
        "Collision",
        NodeRole::Used,
        "Drawn as a Group: its children are drawn; nothing collides.",
        &[
            ADD_CHILDREN,
            REMOVE_CHILDREN,
            CHILDREN,
            ignored("collide", "TRUE", ""),
            BBOX_CENTER,
            BBOX_SIZE,
            ignored(
                "proxy",
                "NULL",
                "Its node is not drawn (DEF names in it can still be used).",
            ),
            event("collideTime", ""),
        ],
    ),
    node(
        "Color",
        NodeRole::MeshPart,
        "The colours of the IndexedFaceSet, PointSet or ElevationGrid whose `color` field \
         holds it; anywhere else it is skipped.",
        &[used("color", "[]", "")],
    ),
    skipped("ColorInterpolator", ANIMATION),
    node(
        "Cone",
        NodeRole::Used,
        "Drawn as an exact opaque cone when it is a Shape's geometry (left out by \
         `--spheres-only`).",
        &[
            used("bottomRadius", "1", "Must be above 0, else refused."),
            used("height", "2", "Must be above 0, else refused."),
            used("side", "TRUE", ""),
            used("bottom", "TRUE", ""),
        ],
    ),
    node(
        "Coordinate",
        NodeRole::MeshPart,
        "The points of the IndexedFaceSet or PointSet whose `coord` field holds it; anywhere \
         else it is skipped.",
        &[used("point", "[]", "")],
    ),
    skipped("CoordinateInterpolator", ANIMATION),
    node(
        "Cylinder",
        NodeRole::Used,
        "Drawn as an exact opaque cylinder when it is a Shape's geometry (left out by \
         `--spheres-only`).",
        &[
            used("bottom", "TRUE", ""),
            used("height", "2", "Must be above 0, else refused."),
            used("radius", "1", "Must be above 0, else refused."),
            used("side", "TRUE", ""),
            used("top", "TRUE", ""),
        ],
    ),
    skipped("CylinderSensor", SENSOR),
    node(
        "DirectionalLight",
        NodeRole::Used,
        "A light along a direction. As VRML97 says, it lights only its siblings in the \
         grouping node that holds it, and what they hold; the Transforms above it turn it.",
        &[
            used("ambientIntensity", "0", ""),
            used("color", "1 1 1", ""),
            used(
                "direction",
                "0 0 -1",
                "Zero or not finite: a warning, and `0 0 -1` is used.",
            ),
            used("intensity", "1", ""),
            used("on", "TRUE", ""),
        ],
    ),
    node(
        "ElevationGrid",
        NodeRole::Mesh,
        "Drawn when it is a Shape's geometry: its quads are drawn as an IndexedFaceSet's \
         faces. A grid of fewer than 2 by 2 points is not drawn and is counted as skipped; too \
         few heights or a spacing that is not finite is a warning, and the grid is not drawn.",
        &[
            event("set_height", ""),
            used("color", "NULL", MESH_COLOR),
            used("normal", "NULL", MESH_NORMAL),
            not_read("texCoord", "NULL", ""),
            used("height", "[]", ""),
            used("ccw", "TRUE", ""),
            used("colorPerVertex", "TRUE", ""),
            used("creaseAngle", "0", CREASE),
            used("normalPerVertex", "TRUE", ""),
            used("solid", "TRUE", ""),
            used("xDimension", "0", ""),
            used("xSpacing", "1", ""),
            used("zDimension", "0", ""),
            used("zSpacing", "1", ""),
        ],
    ),
    node(
        "Extrusion",
        NodeRole::Mesh,
        "Drawn when it is a Shape's geometry: its sides and caps are drawn as an \
         IndexedFaceSet's faces. Fewer than two spine or cross-section points, or points that \
         are not finite, is a warning, and the extrusion is not drawn.",
        &[
            event("set_crossSection", ""),
            event("set_orientation", ""),
            event("set_scale", ""),
            event("set_spine", ""),
            used("beginCap", "TRUE", ""),
            used("ccw", "TRUE", ""),
            not_read("convex", "TRUE", CONVEX),
            used("creaseAngle", "0", CREASE),
            used("crossSection", "[ 1 1, 1 -1, -1 -1, -1 1, 1 1 ]", ""),
            used("endCap", "TRUE", ""),
            used("orientation", "0 0 1 0", ""),
            used("scale", "1 1", ""),
            used("solid", "TRUE", ""),
            used("spine", "[ 0 0 0, 0 1 0 ]", ""),
        ],
    ),
    skipped("Fog", "No fog."),
    skipped("FontStyle", "Text is not drawn."),
    node(
        "Group",
        NodeRole::Used,
        "Its children are drawn.",
        &[
            ADD_CHILDREN,
            REMOVE_CHILDREN,
            CHILDREN,
            BBOX_CENTER,
            BBOX_SIZE,
        ],
    ),
    skipped("ImageTexture", TEXTURE),
    node(
        "IndexedFaceSet",
        NodeRole::Mesh,
        "Drawn when it is a Shape's geometry. Each connected set of its faces whose corners \
         lie on one sphere (at least 12 points) and have one colour is drawn as that exact \
         sphere; the other faces are drawn as triangles (left out by `--spheres-only`). \
         Without faces, its points are drawn as a PointSet's. Without points it is not drawn \
         and is counted as skipped.",
        &[
            event("set_colorIndex", ""),
            event("set_coordIndex", ""),
            event("set_normalIndex", ""),
            event("set_texCoordIndex", ""),
            used("color", "NULL", MESH_COLOR),
            used("coord", "NULL", "A Coordinate node."),
            used("normal", "NULL", MESH_NORMAL),
            not_read("texCoord", "NULL", ""),
            used("ccw", "TRUE", ""),
            used("colorIndex", "[]", NOT_INTEGERS),
            used("colorPerVertex", "TRUE", ""),
            not_read("convex", "TRUE", CONVEX),
            used(
                "coordIndex",
                "[]",
                "Empty, or only -1: the points are drawn as a PointSet's. An index that is not \
                 one of the points is a warning, and the faces using it are left out. Values \
                 that are not integers: as colorIndex.",
            ),
            used("creaseAngle", "0", CREASE),
            used("normalIndex", "[]", NOT_INTEGERS),
            used("normalPerVertex", "TRUE", ""),
            used("solid", "TRUE", ""),
            not_read("texCoordIndex", "[]", ""),
        ],
    ),
    skipped("IndexedLineSet", "Lines are not drawn."),
    node(
        "Inline",
        NodeRole::Used,
        "The file it names is read and drawn in its place: local relative paths to VRML97 \
         files only (never a network URL), at most 16 files deep, a file that includes itself \
         refused. With `--no-inline` it is not read, without a warning.",
        &[
            used(
                "url",
                "[]",
                "The first url that names a readable file is read; none: a warning.",
            ),
            BBOX_CENTER,
            BBOX_SIZE,
        ],
    ),
    node(
        "LOD",
        NodeRole::Used,
        "Only its first level, the most detailed, is drawn.",
        &[
            used(
                "level",
                "[]",
                "The first node is drawn; the others are not (DEF names in them can still be \
                 used).",
            ),
            ignored("center", "0 0 0", ""),
            ignored("range", "[]", ""),
        ],
    ),
    node(
        "Material",
        NodeRole::Used,
        "The colours of its Shape, lit by VRML97's lighting equation.",
        &[
            used("ambientIntensity", "0.2", ""),
            used("diffuseColor", "0.8 0.8 0.8", ""),
            used("emissiveColor", "0 0 0", ""),
            used(
                "shininess",
                "0.2",
                "Outside [0, 1]: a warning, and it is clamped.",
            ),
            used("specularColor", "0 0 0", ""),
            used(
                "transparency",
                "0",
                "Above 0, a sphere is drawn as a ball of gas (see the rendering model); boxes, \
                 cylinders, cones and triangles stay opaque. Outside [0, 1]: a warning, and it \
                 is clamped.",
            ),
        ],
    ),
    skipped("MovieTexture", TEXTURE),
    node(
        "NavigationInfo",
        NodeRole::Used,
        "The first NavigationInfo in file order says whether there is a headlight; later ones \
         are ignored without a warning.",
        &[
            SET_BIND,
            ignored("avatarSize", "[ 0.25 1.6 0.75 ]", ""),
            used("headlight", "TRUE", ""),
            ignored("speed", "1", ""),
            ignored("type", "[ \"WALK\" \"ANY\" ]", ""),
            ignored("visibilityLimit", "0", ""),
            IS_BOUND,
        ],
    ),
    node(
        "Normal",
        NodeRole::MeshPart,
        "The normals of the IndexedFaceSet or ElevationGrid whose `normal` field holds it; \
         anywhere else it is skipped.",
        &[used("vector", "[]", "")],
    ),
    skipped("NormalInterpolator", ANIMATION),
    skipped("OrientationInterpolator", ANIMATION),
    skipped("PixelTexture", TEXTURE),
    skipped("PlaneSensor", SENSOR),
    node(
        "PointLight",
        NodeRole::Used,
        "A light at a point; the Transforms above it move it.",
        &[
            used("ambientIntensity", "0", ""),
            used("attenuation", "1 0 0", ""),
            used("color", "1 1 1", ""),
            used("intensity", "1", ""),
            used("location", "0 0 0", ""),
            used("on", "TRUE", ""),
            used("radius", "100", "Negative: a warning."),
        ],
    ),
    node(
        "PointSet",
        NodeRole::Mesh,
        "Drawn when it is a Shape's geometry: each point is drawn as a sphere of radius \
         `--point-radius`, by default half the median distance to the nearest other point \
         (said in a note). Without points it is not drawn and is counted as skipped.",
        &[
            used("color", "NULL", "A Color node: one colour per point."),
            used("coord", "NULL", "A Coordinate node."),
        ],
    ),
    skipped("PositionInterpolator", ANIMATION),
    skipped("ProximitySensor", SENSOR),
    skipped("ScalarInterpolator", ANIMATION),
    skipped(
        "Script",
        "Not run. The fields it declares itself are checked: an unknown type is refused, an \
         exposedField is a warning.",
    ),
    node(
        "Shape",
        NodeRole::Used,
        "Draws its geometry with its appearance. Geometry anywhere but in a Shape is not \
         drawn.",
        &[
            used(
                "appearance",
                "NULL",
                "An Appearance; another node type is a warning and is ignored. Without one \
                 the geometry is unlit: white, or the colours of its mesh's Color node.",
            ),
            used(
                "geometry",
                "NULL",
                "A Sphere, Box, Cylinder, Cone, IndexedFaceSet, PointSet, ElevationGrid or \
                 Extrusion; other geometry (Text, IndexedLineSet) is skipped.",
            ),
        ],
    ),
    skipped("Sound", "No sound."),
    node(
        "Sphere",
        NodeRole::Used,
        "Drawn as an exact sphere when it is a Shape's geometry; a Transform with a \
         non-uniform scale makes it an exact ellipsoid.",
        &[used("radius", "1", "Must be above 0, else refused.")],
    ),
    skipped("SphereSensor", SENSOR),
    skipped(
        "SpotLight",
        "Not a light in gtsphere: the scene is lit without it, and no warning says so.",
    ),
    node(
        "Switch",
        NodeRole::Used,
        "Draws the chosen node.",
        &[
            used(
                "choice",
                "[]",
                "Only the chosen node is drawn; the others are not (DEF names in them can \
                 still be used).",
            ),
            used(
                "whichChoice",
                "-1",
                "Negative: nothing is drawn. Past the last choice: a warning, and nothing is \
                 drawn.",
            ),
        ],
    ),
    skipped("Text", "Text is not drawn."),
    skipped("TextureCoordinate", TEXTURE),
    skipped("TextureTransform", TEXTURE),
    skipped("TimeSensor", ANIMATION),
    skipped("TouchSensor", SENSOR),
    node(
        "Transform",
        NodeRole::Used,
        "Its children are drawn moved by its matrix, `T C R SR S -SR -C` as VRML97 says. \
         Spheres stay spheres under translation, rotation and uniform scale and become exact \
         ellipsoids otherwise; lights and viewpoints move too. A zero scale hides what it \
         holds, with a warning; a matrix that makes coordinates overflow is refused.",
        &[
            ADD_CHILDREN,
            REMOVE_CHILDREN,
            used("center", "0 0 0", ""),
            CHILDREN,
            used("rotation", "0 0 1 0", ""),
            used("scale", "1 1 1", ""),
            used("scaleOrientation", "0 0 1 0", ""),
            used("translation", "0 0 0", ""),
            BBOX_CENTER,
            BBOX_SIZE,
        ],
    ),
    node(
        "Viewpoint",
        NodeRole::Used,
        "A camera. The first Viewpoint in file order is the default camera; `--viewpoint` \
         picks one by DEF name or description. The Transforms above it move it.",
        &[
            SET_BIND,
            used(
                "fieldOfView",
                "0.785398",
                "The angle of the smaller side of the image. Outside (0, π): a warning, and \
                 π/4 is used.",
            ),
            ignored("jump", "TRUE", ""),
            used("orientation", "0 0 1 0", ""),
            used("position", "0 0 10", ""),
            used("description", "\"\"", "Names it for `--viewpoint`."),
            event("bindTime", ""),
            IS_BOUND,
        ],
    ),
    skipped("VisibilitySensor", SENSOR),
    skipped("WorldInfo", "Nothing to draw."),
];

/// The page's text before the node tables.
const INTRO: &str = r#"# VRML97 support

<!-- Made by support_markdown() from src/vrml/schema/support.rs: do not edit by hand.
     Remake it with: GTSPHERE_WRITE_DOCS=1 cargo test --test it vrml_support -->

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
  readable: a warning, and each instance is skipped with a warning.
- **GasParticle**: a PROTO of this name with a `field SFString profile` gives the spheres
  of its instances a density profile (see [the rendering model](model.md)); other viewers
  draw its body.
- **DEF and USE**: a USE draws the DEF'd node again, where it stands; a USE of a name not
  defined is refused.
- **ROUTE**: checked, not run. A node not defined, an event the node lacks, an event of the
  wrong direction or two events of different types is a warning.
- **Script**: not run (see [Script](#script)).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vrml::schema::{Access, FieldSpec};

    /// Whether `access` is that of an event (a member that takes no value in a file).
    fn is_event(access: Access) -> bool {
        matches!(access, Access::EventIn | Access::EventOut)
    }

    /// Every member of `spec` paired with its entry in `n`, or why they differ.
    fn check_node(n: &NodeSupport, spec: &NodeSpec) -> Result<(), String> {
        let who = n.name;
        if n.name != spec.name {
            return Err(format!("{who} stands where NODES has {}", spec.name));
        }
        if n.role == NodeRole::Skipped {
            return match n.fields.is_empty() {
                true => Ok(()),
                false => Err(format!("{who} is skipped but lists fields")),
            };
        }
        let names = |fields: &mut dyn Iterator<Item = &'static str>| fields.collect::<Vec<_>>();
        let listed = names(&mut n.fields.iter().map(|f| f.name));
        let declared = names(&mut spec.fields.iter().map(|f: &FieldSpec| f.name));
        if listed != declared {
            return Err(format!(
                "{who} lists {listed:?}, its interface declares {declared:?}"
            ));
        }
        for (f, s) in n.fields.iter().zip(spec.fields) {
            let at = format!("{who}.{}", f.name);
            if (f.role == FieldRole::Event) != is_event(s.access) {
                return Err(format!("{at}: an event exactly when its access is one"));
            }
            if f.default.is_empty() != is_event(s.access) {
                return Err(format!("{at}: a default exactly when it is not an event"));
            }
            if s.ty.is_node() && !is_event(s.access) {
                let want = if s.ty.is_mf() { "[]" } else { "NULL" };
                if f.default != want {
                    return Err(format!("{at}: the default of a {} is {want}", s.ty.name()));
                }
            }
            if n.role == NodeRole::Used && f.role == FieldRole::NotRead {
                return Err(format!("{at}: the fields of a Used node are all read"));
            }
            if n.role != NodeRole::Used && f.role == FieldRole::Ignored {
                return Err(format!(
                    "{at}: a lenient node's fields are used or not read"
                ));
            }
        }
        Ok(())
    }

    #[test]
    fn every_node_and_member_is_classified() {
        assert_eq!(SUPPORT.len(), NODES.len());
        for (n, spec) in SUPPORT.iter().zip(NODES) {
            if let Err(e) = check_node(n, spec) {
                panic!("{e}");
            }
        }
    }

    #[test]
    fn the_kinds_are_the_reader_s() {
        let of = |role| -> Vec<&str> {
            SUPPORT
                .iter()
                .filter(|n| n.role == role)
                .map(|n| n.name)
                .collect()
        };
        // The lowering models 25 node types (`lower::start`): these and the mesh parts.
        assert_eq!(of(NodeRole::Used).len() + of(NodeRole::Mesh).len() + 1, 25);
        assert_eq!(
            of(NodeRole::Mesh),
            ["ElevationGrid", "Extrusion", "IndexedFaceSet", "PointSet"]
        );
        assert_eq!(of(NodeRole::MeshPart), ["Color", "Coordinate", "Normal"]);
        assert_eq!(of(NodeRole::Skipped).len(), 29 - 2);
    }

    #[test]
    fn lookups_answer_for_every_member() {
        for spec in NODES {
            let n = node_support(spec.name).unwrap();
            assert!(std::ptr::eq(n.spec().unwrap(), spec));
            for s in spec.fields {
                assert!(n.field_role(s.name).is_some(), "{}.{}", spec.name, s.name);
            }
            assert_eq!(n.field_role("noSuchField"), None);
        }
        assert!(node_support("Separator").is_none());
        let t = node_support("Transform").unwrap();
        assert_eq!(t.field_role("translation"), Some(FieldRole::Used));
        assert_eq!(t.field_role("bboxSize"), Some(FieldRole::Ignored));
        assert_eq!(t.field_role("addChildren"), Some(FieldRole::Event));
        let text = node_support("Text").unwrap();
        assert_eq!(text.field_role("string"), Some(FieldRole::NotRead));
    }

    #[test]
    fn the_text_keeps_the_tables_whole() {
        // A `|` would split a table cell; a line break would end the row.
        for n in SUPPORT {
            assert!(!n.summary.contains(['|', '\n']), "{}", n.name);
            assert!(n.summary.ends_with('.'), "{}", n.name);
            for f in n.fields {
                assert!(
                    !f.default.contains(['|', '\n', '`']),
                    "{}.{}",
                    n.name,
                    f.name
                );
                assert!(!f.note.contains(['|', '\n']), "{}.{}", n.name, f.name);
                assert!(f.note.is_empty() || f.note.ends_with('.'), "{}", f.name);
            }
        }
    }

    #[test]
    fn the_page_has_every_node_and_member() {
        let page = support_markdown();
        for spec in NODES {
            assert!(
                page.contains(&format!("\n### {}\n", spec.name)),
                "{}",
                spec.name
            );
            for s in spec.fields {
                let row = format!(
                    "| `{}` | {} | {} |",
                    s.name,
                    s.access.keyword(),
                    s.ty.name()
                );
                assert!(page.contains(&row), "{}.{}", spec.name, s.name);
            }
        }
        assert!(page.ends_with("|\n"));
    }
}
