//! The support table's entries: one per standard node type, each member of a read node's
//! interface with its VRML97 default and what becomes of a value.

use super::*;

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
