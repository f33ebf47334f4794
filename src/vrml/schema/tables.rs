//! The interface of each of the 54 standard VRML97 nodes, field for field and in the same
//! order as its declaration in ISO/IEC 14772-1:1997 clause 6: every `field`, `exposedField`,
//! `eventIn` and `eventOut`, with its type (`fld`, `exp`, `ein`, `eout` below). [`NODES`]
//! lists them sorted by name. Nothing else lives here, so a table can be checked against the
//! standard line by line (the tests that do so are in the parent module).

use super::lookup::{name_slot, node, same_bytes};
use super::FieldType::*;
use super::{Access, FieldSpec, FieldType, NodeSpec};

const fn spec(name: &'static str, ty: FieldType, access: Access) -> FieldSpec {
    FieldSpec { name, ty, access }
}

const fn fld(name: &'static str, ty: FieldType) -> FieldSpec {
    spec(name, ty, Access::Field)
}

const fn exp(name: &'static str, ty: FieldType) -> FieldSpec {
    spec(name, ty, Access::ExposedField)
}

const fn ein(name: &'static str, ty: FieldType) -> FieldSpec {
    spec(name, ty, Access::EventIn)
}

const fn eout(name: &'static str, ty: FieldType) -> FieldSpec {
    spec(name, ty, Access::EventOut)
}

// The tables below follow the node declarations of ISO/IEC 14772-1:1997 clause 6, field for
// field and in the same order.

static ANCHOR: &[FieldSpec] = &[
    ein("addChildren", MFNode),
    ein("removeChildren", MFNode),
    exp("children", MFNode),
    exp("description", SFString),
    exp("parameter", MFString),
    exp("url", MFString),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
];

static APPEARANCE: &[FieldSpec] = &[
    exp("material", SFNode),
    exp("texture", SFNode),
    exp("textureTransform", SFNode),
];

static AUDIO_CLIP: &[FieldSpec] = &[
    exp("description", SFString),
    exp("loop", SFBool),
    exp("pitch", SFFloat),
    exp("startTime", SFTime),
    exp("stopTime", SFTime),
    exp("url", MFString),
    eout("duration_changed", SFTime),
    eout("isActive", SFBool),
];

static BACKGROUND: &[FieldSpec] = &[
    ein("set_bind", SFBool),
    exp("groundAngle", MFFloat),
    exp("groundColor", MFColor),
    exp("backUrl", MFString),
    exp("bottomUrl", MFString),
    exp("frontUrl", MFString),
    exp("leftUrl", MFString),
    exp("rightUrl", MFString),
    exp("topUrl", MFString),
    exp("skyAngle", MFFloat),
    exp("skyColor", MFColor),
    eout("isBound", SFBool),
];

static BILLBOARD: &[FieldSpec] = &[
    ein("addChildren", MFNode),
    ein("removeChildren", MFNode),
    exp("axisOfRotation", SFVec3f),
    exp("children", MFNode),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
];

static BOX: &[FieldSpec] = &[fld("size", SFVec3f)];

static COLLISION: &[FieldSpec] = &[
    ein("addChildren", MFNode),
    ein("removeChildren", MFNode),
    exp("children", MFNode),
    exp("collide", SFBool),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
    fld("proxy", SFNode),
    eout("collideTime", SFTime),
];

static COLOR: &[FieldSpec] = &[exp("color", MFColor)];

static COLOR_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFColor),
    eout("value_changed", SFColor),
];

static CONE: &[FieldSpec] = &[
    fld("bottomRadius", SFFloat),
    fld("height", SFFloat),
    fld("side", SFBool),
    fld("bottom", SFBool),
];

static COORDINATE: &[FieldSpec] = &[exp("point", MFVec3f)];

static COORDINATE_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFVec3f),
    eout("value_changed", MFVec3f),
];

static CYLINDER: &[FieldSpec] = &[
    fld("bottom", SFBool),
    fld("height", SFFloat),
    fld("radius", SFFloat),
    fld("side", SFBool),
    fld("top", SFBool),
];

static CYLINDER_SENSOR: &[FieldSpec] = &[
    exp("autoOffset", SFBool),
    exp("diskAngle", SFFloat),
    exp("enabled", SFBool),
    exp("maxAngle", SFFloat),
    exp("minAngle", SFFloat),
    exp("offset", SFFloat),
    eout("isActive", SFBool),
    eout("rotation_changed", SFRotation),
    eout("trackPoint_changed", SFVec3f),
];

static DIRECTIONAL_LIGHT: &[FieldSpec] = &[
    exp("ambientIntensity", SFFloat),
    exp("color", SFColor),
    exp("direction", SFVec3f),
    exp("intensity", SFFloat),
    exp("on", SFBool),
];

static ELEVATION_GRID: &[FieldSpec] = &[
    ein("set_height", MFFloat),
    exp("color", SFNode),
    exp("normal", SFNode),
    exp("texCoord", SFNode),
    fld("height", MFFloat),
    fld("ccw", SFBool),
    fld("colorPerVertex", SFBool),
    fld("creaseAngle", SFFloat),
    fld("normalPerVertex", SFBool),
    fld("solid", SFBool),
    fld("xDimension", SFInt32),
    fld("xSpacing", SFFloat),
    fld("zDimension", SFInt32),
    fld("zSpacing", SFFloat),
];

static EXTRUSION: &[FieldSpec] = &[
    ein("set_crossSection", MFVec2f),
    ein("set_orientation", MFRotation),
    ein("set_scale", MFVec2f),
    ein("set_spine", MFVec3f),
    fld("beginCap", SFBool),
    fld("ccw", SFBool),
    fld("convex", SFBool),
    fld("creaseAngle", SFFloat),
    fld("crossSection", MFVec2f),
    fld("endCap", SFBool),
    fld("orientation", MFRotation),
    fld("scale", MFVec2f),
    fld("solid", SFBool),
    fld("spine", MFVec3f),
];

static FOG: &[FieldSpec] = &[
    exp("color", SFColor),
    exp("fogType", SFString),
    exp("visibilityRange", SFFloat),
    ein("set_bind", SFBool),
    eout("isBound", SFBool),
];

static FONT_STYLE: &[FieldSpec] = &[
    fld("family", MFString),
    fld("horizontal", SFBool),
    fld("justify", MFString),
    fld("language", SFString),
    fld("leftToRight", SFBool),
    fld("size", SFFloat),
    fld("spacing", SFFloat),
    fld("style", SFString),
    fld("topToBottom", SFBool),
];

static GROUP: &[FieldSpec] = &[
    ein("addChildren", MFNode),
    ein("removeChildren", MFNode),
    exp("children", MFNode),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
];

static IMAGE_TEXTURE: &[FieldSpec] = &[
    exp("url", MFString),
    fld("repeatS", SFBool),
    fld("repeatT", SFBool),
];

static INDEXED_FACE_SET: &[FieldSpec] = &[
    ein("set_colorIndex", MFInt32),
    ein("set_coordIndex", MFInt32),
    ein("set_normalIndex", MFInt32),
    ein("set_texCoordIndex", MFInt32),
    exp("color", SFNode),
    exp("coord", SFNode),
    exp("normal", SFNode),
    exp("texCoord", SFNode),
    fld("ccw", SFBool),
    fld("colorIndex", MFInt32),
    fld("colorPerVertex", SFBool),
    fld("convex", SFBool),
    fld("coordIndex", MFInt32),
    fld("creaseAngle", SFFloat),
    fld("normalIndex", MFInt32),
    fld("normalPerVertex", SFBool),
    fld("solid", SFBool),
    fld("texCoordIndex", MFInt32),
];

static INDEXED_LINE_SET: &[FieldSpec] = &[
    ein("set_colorIndex", MFInt32),
    ein("set_coordIndex", MFInt32),
    exp("color", SFNode),
    exp("coord", SFNode),
    fld("colorIndex", MFInt32),
    fld("colorPerVertex", SFBool),
    fld("coordIndex", MFInt32),
];

static INLINE: &[FieldSpec] = &[
    exp("url", MFString),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
];

static LOD: &[FieldSpec] = &[
    exp("level", MFNode),
    fld("center", SFVec3f),
    fld("range", MFFloat),
];

static MATERIAL: &[FieldSpec] = &[
    exp("ambientIntensity", SFFloat),
    exp("diffuseColor", SFColor),
    exp("emissiveColor", SFColor),
    exp("shininess", SFFloat),
    exp("specularColor", SFColor),
    exp("transparency", SFFloat),
];

static MOVIE_TEXTURE: &[FieldSpec] = &[
    exp("loop", SFBool),
    exp("speed", SFFloat),
    exp("startTime", SFTime),
    exp("stopTime", SFTime),
    exp("url", MFString),
    fld("repeatS", SFBool),
    fld("repeatT", SFBool),
    eout("duration_changed", SFTime),
    eout("isActive", SFBool),
];

static NAVIGATION_INFO: &[FieldSpec] = &[
    ein("set_bind", SFBool),
    exp("avatarSize", MFFloat),
    exp("headlight", SFBool),
    exp("speed", SFFloat),
    exp("type", MFString),
    exp("visibilityLimit", SFFloat),
    eout("isBound", SFBool),
];

static NORMAL: &[FieldSpec] = &[exp("vector", MFVec3f)];

static NORMAL_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFVec3f),
    eout("value_changed", MFVec3f),
];

static ORIENTATION_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFRotation),
    eout("value_changed", SFRotation),
];

static PIXEL_TEXTURE: &[FieldSpec] = &[
    exp("image", SFImage),
    fld("repeatS", SFBool),
    fld("repeatT", SFBool),
];

static PLANE_SENSOR: &[FieldSpec] = &[
    exp("autoOffset", SFBool),
    exp("enabled", SFBool),
    exp("maxPosition", SFVec2f),
    exp("minPosition", SFVec2f),
    exp("offset", SFVec3f),
    eout("isActive", SFBool),
    eout("trackPoint_changed", SFVec3f),
    eout("translation_changed", SFVec3f),
];

static POINT_LIGHT: &[FieldSpec] = &[
    exp("ambientIntensity", SFFloat),
    exp("attenuation", SFVec3f),
    exp("color", SFColor),
    exp("intensity", SFFloat),
    exp("location", SFVec3f),
    exp("on", SFBool),
    exp("radius", SFFloat),
];

static POINT_SET: &[FieldSpec] = &[exp("color", SFNode), exp("coord", SFNode)];

static POSITION_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFVec3f),
    eout("value_changed", SFVec3f),
];

static PROXIMITY_SENSOR: &[FieldSpec] = &[
    exp("center", SFVec3f),
    exp("size", SFVec3f),
    exp("enabled", SFBool),
    eout("isActive", SFBool),
    eout("position_changed", SFVec3f),
    eout("orientation_changed", SFRotation),
    eout("enterTime", SFTime),
    eout("exitTime", SFTime),
];

static SCALAR_INTERPOLATOR: &[FieldSpec] = &[
    ein("set_fraction", SFFloat),
    exp("key", MFFloat),
    exp("keyValue", MFFloat),
    eout("value_changed", SFFloat),
];

static SCRIPT: &[FieldSpec] = &[
    exp("url", MFString),
    fld("directOutput", SFBool),
    fld("mustEvaluate", SFBool),
];

static SHAPE: &[FieldSpec] = &[exp("appearance", SFNode), exp("geometry", SFNode)];

static SOUND: &[FieldSpec] = &[
    exp("direction", SFVec3f),
    exp("intensity", SFFloat),
    exp("location", SFVec3f),
    exp("maxBack", SFFloat),
    exp("maxFront", SFFloat),
    exp("minBack", SFFloat),
    exp("minFront", SFFloat),
    exp("priority", SFFloat),
    exp("source", SFNode),
    fld("spatialize", SFBool),
];

static SPHERE: &[FieldSpec] = &[fld("radius", SFFloat)];

static SPHERE_SENSOR: &[FieldSpec] = &[
    exp("autoOffset", SFBool),
    exp("enabled", SFBool),
    exp("offset", SFRotation),
    eout("isActive", SFBool),
    eout("rotation_changed", SFRotation),
    eout("trackPoint_changed", SFVec3f),
];

static SPOT_LIGHT: &[FieldSpec] = &[
    exp("ambientIntensity", SFFloat),
    exp("attenuation", SFVec3f),
    exp("beamWidth", SFFloat),
    exp("color", SFColor),
    exp("cutOffAngle", SFFloat),
    exp("direction", SFVec3f),
    exp("intensity", SFFloat),
    exp("location", SFVec3f),
    exp("on", SFBool),
    exp("radius", SFFloat),
];

static SWITCH: &[FieldSpec] = &[exp("choice", MFNode), exp("whichChoice", SFInt32)];

static TEXT: &[FieldSpec] = &[
    exp("string", MFString),
    exp("fontStyle", SFNode),
    exp("length", MFFloat),
    exp("maxExtent", SFFloat),
];

static TEXTURE_COORDINATE: &[FieldSpec] = &[exp("point", MFVec2f)];

static TEXTURE_TRANSFORM: &[FieldSpec] = &[
    exp("center", SFVec2f),
    exp("rotation", SFFloat),
    exp("scale", SFVec2f),
    exp("translation", SFVec2f),
];

static TIME_SENSOR: &[FieldSpec] = &[
    exp("cycleInterval", SFTime),
    exp("enabled", SFBool),
    exp("loop", SFBool),
    exp("startTime", SFTime),
    exp("stopTime", SFTime),
    eout("cycleTime", SFTime),
    eout("fraction_changed", SFFloat),
    eout("isActive", SFBool),
    eout("time", SFTime),
];

static TOUCH_SENSOR: &[FieldSpec] = &[
    exp("enabled", SFBool),
    eout("hitNormal_changed", SFVec3f),
    eout("hitPoint_changed", SFVec3f),
    eout("hitTexCoord_changed", SFVec2f),
    eout("isActive", SFBool),
    eout("isOver", SFBool),
    eout("touchTime", SFTime),
];

static TRANSFORM: &[FieldSpec] = &[
    ein("addChildren", MFNode),
    ein("removeChildren", MFNode),
    exp("center", SFVec3f),
    exp("children", MFNode),
    exp("rotation", SFRotation),
    exp("scale", SFVec3f),
    exp("scaleOrientation", SFRotation),
    exp("translation", SFVec3f),
    fld("bboxCenter", SFVec3f),
    fld("bboxSize", SFVec3f),
];

static VIEWPOINT: &[FieldSpec] = &[
    ein("set_bind", SFBool),
    exp("fieldOfView", SFFloat),
    exp("jump", SFBool),
    exp("orientation", SFRotation),
    exp("position", SFVec3f),
    fld("description", SFString),
    eout("bindTime", SFTime),
    eout("isBound", SFBool),
];

static VISIBILITY_SENSOR: &[FieldSpec] = &[
    exp("center", SFVec3f),
    exp("enabled", SFBool),
    exp("size", SFVec3f),
    eout("enterTime", SFTime),
    eout("exitTime", SFTime),
    eout("isActive", SFBool),
];

static WORLD_INFO: &[FieldSpec] = &[fld("info", MFString), fld("title", SFString)];

/// All 54 standard node types, sorted by name (binary-searchable).
pub static NODES: &[NodeSpec] = &[
    node("Anchor", ANCHOR),
    node("Appearance", APPEARANCE),
    node("AudioClip", AUDIO_CLIP),
    node("Background", BACKGROUND),
    node("Billboard", BILLBOARD),
    node("Box", BOX),
    node("Collision", COLLISION),
    node("Color", COLOR),
    node("ColorInterpolator", COLOR_INTERPOLATOR),
    node("Cone", CONE),
    node("Coordinate", COORDINATE),
    node("CoordinateInterpolator", COORDINATE_INTERPOLATOR),
    node("Cylinder", CYLINDER),
    node("CylinderSensor", CYLINDER_SENSOR),
    node("DirectionalLight", DIRECTIONAL_LIGHT),
    node("ElevationGrid", ELEVATION_GRID),
    node("Extrusion", EXTRUSION),
    node("Fog", FOG),
    node("FontStyle", FONT_STYLE),
    node("Group", GROUP),
    node("ImageTexture", IMAGE_TEXTURE),
    node("IndexedFaceSet", INDEXED_FACE_SET),
    node("IndexedLineSet", INDEXED_LINE_SET),
    node("Inline", INLINE),
    node("LOD", LOD),
    node("Material", MATERIAL),
    node("MovieTexture", MOVIE_TEXTURE),
    node("NavigationInfo", NAVIGATION_INFO),
    node("Normal", NORMAL),
    node("NormalInterpolator", NORMAL_INTERPOLATOR),
    node("OrientationInterpolator", ORIENTATION_INTERPOLATOR),
    node("PixelTexture", PIXEL_TEXTURE),
    node("PlaneSensor", PLANE_SENSOR),
    node("PointLight", POINT_LIGHT),
    node("PointSet", POINT_SET),
    node("PositionInterpolator", POSITION_INTERPOLATOR),
    node("ProximitySensor", PROXIMITY_SENSOR),
    node("ScalarInterpolator", SCALAR_INTERPOLATOR),
    node("Script", SCRIPT),
    node("Shape", SHAPE),
    node("Sound", SOUND),
    node("Sphere", SPHERE),
    node("SphereSensor", SPHERE_SENSOR),
    node("SpotLight", SPOT_LIGHT),
    node("Switch", SWITCH),
    node("Text", TEXT),
    node("TextureCoordinate", TEXTURE_COORDINATE),
    node("TextureTransform", TEXTURE_TRANSFORM),
    node("TimeSensor", TIME_SENSOR),
    node("TouchSensor", TOUCH_SENSOR),
    node("Transform", TRANSFORM),
    node("Viewpoint", VIEWPOINT),
    node("VisibilitySensor", VISIBILITY_SENSOR),
    node("WorldInfo", WORLD_INFO),
];

/// The standard node type named exactly `name` (case-sensitive).
#[inline]
pub fn node_spec(name: &str) -> Option<&'static NodeSpec> {
    node_index(name).map(|i| &NODES[i])
}

/// The index in [`NODES`] of the standard node type named exactly `name` (case-sensitive).
#[inline(always)]
pub fn node_index(name: &str) -> Option<usize> {
    let mut h = name_slot(name.as_bytes());
    loop {
        let k = NODE_SLOTS[h] as usize;
        if k == 0 {
            return None;
        }
        if same_bytes(NODES[k - 1].name.as_bytes(), name.as_bytes()) {
            return Some(k - 1);
        }
        h = (h + 1) % NODE_SLOTS.len();
    }
}

/// An open-addressing table over [`NODES`] (index + 1, 0 for empty), built at compile time.
pub(super) static NODE_SLOTS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut i = 0;
    while i < NODES.len() {
        let mut h = name_slot(NODES[i].name.as_bytes());
        while t[h] != 0 {
            h = (h + 1) % 256;
        }
        t[h] = i as u8 + 1;
        i += 1;
    }
    t
};
