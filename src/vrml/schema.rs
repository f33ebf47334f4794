//! Field tables of the 54 standard VRML97 nodes (ISO/IEC 14772-1:1997 clause 6).
//!
//! Each [`NodeSpec`] lists the node's interface exactly as its clause 6 declaration does, in
//! declaration order: every `field`, `exposedField`, `eventIn` and `eventOut`, with its type.
//! Defaults are not recorded here. Script lists only its three fixed fields (`url`,
//! `directOutput`, `mustEvaluate`); the rest of a Script's interface is declared by the author.

use FieldType::*;

/// The 20 field types of VRML97 (clause 5), by their file-format names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldType {
    SFBool,
    SFColor,
    SFFloat,
    SFImage,
    SFInt32,
    SFNode,
    SFRotation,
    SFString,
    SFTime,
    SFVec2f,
    SFVec3f,
    MFColor,
    MFFloat,
    MFInt32,
    MFNode,
    MFRotation,
    MFString,
    MFTime,
    MFVec2f,
    MFVec3f,
}

/// How a member of a node's interface may be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// `field`: set in the file only.
    Field,
    /// `exposedField`: a field with an implicit `set_<name>` eventIn and `<name>_changed` eventOut.
    ExposedField,
    /// `eventIn`: a ROUTE destination only.
    EventIn,
    /// `eventOut`: a ROUTE source only.
    EventOut,
}

/// One member of a node's interface.
#[derive(Debug)]
pub struct FieldSpec {
    pub name: &'static str,
    pub ty: FieldType,
    pub access: Access,
}

/// A standard node type and its interface, in declaration order.
#[derive(Debug)]
pub struct NodeSpec {
    pub name: &'static str,
    pub fields: &'static [FieldSpec],
    /// An open-addressing table over `fields` (index + 1, 0 for empty) by [`name_slot`], so
    /// that a field name is found without scanning the list.
    field_slots: [u8; FIELD_SLOTS],
}

/// Slots of [`NodeSpec::field_slots`]: a power of two, more than twice the longest field list.
const FIELD_SLOTS: usize = 64;

impl FieldType {
    /// Every field type, in declaration order.
    const ALL: [FieldType; 20] = [
        SFBool, SFColor, SFFloat, SFImage, SFInt32, SFNode, SFRotation, SFString, SFTime, SFVec2f,
        SFVec3f, MFColor, MFFloat, MFInt32, MFNode, MFRotation, MFString, MFTime, MFVec2f, MFVec3f,
    ];

    /// The type named `s` as written in a file (`"SFBool"` -> `SFBool`); case-sensitive.
    pub fn from_name(s: &str) -> Option<FieldType> {
        Self::ALL.into_iter().find(|t| t.name() == s)
    }

    /// The type's name as written in a file.
    pub fn name(self) -> &'static str {
        match self {
            SFBool => "SFBool",
            SFColor => "SFColor",
            SFFloat => "SFFloat",
            SFImage => "SFImage",
            SFInt32 => "SFInt32",
            SFNode => "SFNode",
            SFRotation => "SFRotation",
            SFString => "SFString",
            SFTime => "SFTime",
            SFVec2f => "SFVec2f",
            SFVec3f => "SFVec3f",
            MFColor => "MFColor",
            MFFloat => "MFFloat",
            MFInt32 => "MFInt32",
            MFNode => "MFNode",
            MFRotation => "MFRotation",
            MFString => "MFString",
            MFTime => "MFTime",
            MFVec2f => "MFVec2f",
            MFVec3f => "MFVec3f",
        }
    }

    /// Whether this is a multiple-valued (`MF*`) type.
    pub fn is_mf(self) -> bool {
        matches!(
            self,
            MFColor
                | MFFloat
                | MFInt32
                | MFNode
                | MFRotation
                | MFString
                | MFTime
                | MFVec2f
                | MFVec3f
        )
    }

    /// Whether values of this type are nodes (`SFNode` or `MFNode`).
    pub fn is_node(self) -> bool {
        matches!(self, SFNode | MFNode)
    }

    /// Numbers per element for numeric types (SFColor 3, SFRotation 4, SFVec2f 2, SFFloat 1, SFInt32 1, SFTime 1, ...); None for SFBool, SFString, SFImage, SFNode, MF variants answer for their element.
    pub fn arity(self) -> Option<usize> {
        match self {
            SFFloat | SFInt32 | SFTime | MFFloat | MFInt32 | MFTime => Some(1),
            SFVec2f | MFVec2f => Some(2),
            SFColor | SFVec3f | MFColor | MFVec3f => Some(3),
            SFRotation | MFRotation => Some(4),
            SFBool | SFImage | SFNode | SFString | MFNode | MFString => None,
        }
    }

    /// Whether the numbers of this type are integers (`SFInt32`, `MFInt32`, `SFImage`).
    pub fn is_integer(self) -> bool {
        matches!(self, SFInt32 | MFInt32 | SFImage)
    }
}

impl Access {
    /// The access named by a declaration keyword (`"exposedField"` -> `ExposedField`).
    pub fn from_keyword(s: &str) -> Option<Access> {
        match s {
            "field" => Some(Access::Field),
            "exposedField" => Some(Access::ExposedField),
            "eventIn" => Some(Access::EventIn),
            "eventOut" => Some(Access::EventOut),
            _ => None,
        }
    }

    /// The declaration keyword of this access.
    pub fn keyword(self) -> &'static str {
        match self {
            Access::Field => "field",
            Access::ExposedField => "exposedField",
            Access::EventIn => "eventIn",
            Access::EventOut => "eventOut",
        }
    }
}

impl NodeSpec {
    /// The interface member declared with exactly this name (no event aliases).
    #[inline(always)]
    pub fn field(&self, name: &str) -> Option<&'static FieldSpec> {
        let fields: &'static [FieldSpec] = self.fields;
        let b = name.as_bytes();
        let mut h = field_slot(b);
        loop {
            let k = self.field_slots[h] as usize;
            if k == 0 {
                return None;
            }
            let f = &fields[k - 1];
            if same_bytes(f.name.as_bytes(), b) {
                return Some(f);
            }
            h = (h + 1) % FIELD_SLOTS;
        }
    }

    /// Resolves exposedField event aliases too: for an exposedField `foo`, `set_foo` is its eventIn and `foo_changed` its eventOut.
    /// Returns the spec and the access with which the name was used (EventIn for set_foo, EventOut for foo_changed).
    ///
    /// A declared name always wins over an alias, and a plain declared name answers with its
    /// declared access (so an exposedField named as itself answers `ExposedField`).
    #[inline(always)]
    pub fn event(&self, name: &str) -> Option<(&'static FieldSpec, Access)> {
        match self.field(name) {
            Some(f) => Some((f, f.access)),
            None => self.event_alias(name),
        }
    }

    /// [`NodeSpec::event`] for a name that is not declared: `set_foo` or `foo_changed`.
    #[cold]
    #[inline(never)]
    fn event_alias(&self, name: &str) -> Option<(&'static FieldSpec, Access)> {
        let exposed = |base: &str| {
            self.field(base)
                .filter(|f| f.access == Access::ExposedField)
        };
        if let Some(f) = name.strip_prefix("set_").and_then(exposed) {
            return Some((f, Access::EventIn));
        }
        if let Some(f) = name.strip_suffix("_changed").and_then(exposed) {
            return Some((f, Access::EventOut));
        }
        None
    }
}

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

/// `a == b` for names: those of 4 to 16 bytes (almost all) are compared as two overlapping
/// words instead of through a `memcmp` call.
#[inline(always)]
fn same_bytes(a: &[u8], b: &[u8]) -> bool {
    let n = a.len();
    if n != b.len() {
        return false;
    }
    let w8 = |s: &[u8], i: usize| u64::from_le_bytes(s[i..i + 8].try_into().unwrap_or([0; 8]));
    let w4 = |s: &[u8], i: usize| u32::from_le_bytes(s[i..i + 4].try_into().unwrap_or([0; 4]));
    match n {
        8..=16 => w8(a, 0) == w8(b, 0) && w8(a, n - 8) == w8(b, n - 8),
        4..=7 => w4(a, 0) == w4(b, 0) && w4(a, n - 4) == w4(b, n - 4),
        _ => a == b,
    }
}

/// Where a node type name starts its probe in [`NODE_SLOTS`]: a hash of its length and its
/// first, middle and last bytes (every name is looked up, so this must be cheap).
#[inline]
const fn name_slot(b: &[u8]) -> usize {
    let n = b.len();
    if n == 0 {
        return 0;
    }
    let key = (n as u32) | (b[0] as u32) << 8 | (b[n / 2] as u32) << 16 | (b[n - 1] as u32) << 24;
    (key.wrapping_mul(0x9E37_79B1) >> 24) as usize
}

/// Where a field name starts its probe in a [`NodeSpec::field_slots`]: a hash of its length
/// and its first and last bytes (a node's few field names rarely share all three).
#[inline]
const fn field_slot(b: &[u8]) -> usize {
    let n = b.len();
    if n == 0 {
        return 0;
    }
    let key = (n as u32) | (b[0] as u32) << 8 | (b[n - 1] as u32) << 16;
    (key.wrapping_mul(0x9E37_79B1) >> 26) as usize
}

/// An open-addressing table over [`NODES`] (index + 1, 0 for empty), built at compile time.
static NODE_SLOTS: [u8; 256] = {
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

const fn node(name: &'static str, fields: &'static [FieldSpec]) -> NodeSpec {
    assert!(2 * fields.len() < FIELD_SLOTS);
    let mut field_slots = [0u8; FIELD_SLOTS];
    let mut i = 0;
    while i < fields.len() {
        let mut h = field_slot(fields[i].name.as_bytes());
        while field_slots[h] != 0 {
            h = (h + 1) % FIELD_SLOTS;
        }
        field_slots[h] = i as u8 + 1;
        i += 1;
    }
    NodeSpec {
        name,
        fields,
        field_slots,
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn field_slots_find_what_a_scan_finds() {
        for n in NODES {
            for f in n.fields {
                let scan = n.fields.iter().find(|g| g.name == f.name).unwrap();
                assert!(
                    std::ptr::eq(n.field(f.name).unwrap(), scan),
                    "{}.{}",
                    n.name,
                    f.name
                );
                for miss in [
                    format!("{}x", f.name),
                    f.name[1..].to_string(),
                    f.name.to_uppercase(),
                ] {
                    let want = n.fields.iter().find(|g| g.name == miss).map(|g| g.name);
                    assert_eq!(n.field(&miss).map(|g| g.name), want, "{}.{miss}", n.name);
                }
            }
            assert!(n.field("").is_none());
        }
    }

    fn has(node: &str, name: &str, ty: FieldType, access: Access) {
        let spec = node_spec(node).unwrap_or_else(|| panic!("no node {node}"));
        let f = spec
            .field(name)
            .unwrap_or_else(|| panic!("{node} has no {name}"));
        assert_eq!((f.ty, f.access), (ty, access), "{node}.{name}");
    }

    #[test]
    fn exactly_54_nodes_sorted_and_unique() {
        assert_eq!(NODES.len(), 54);
        for w in NODES.windows(2) {
            assert!(w[0].name < w[1].name, "{} !< {}", w[0].name, w[1].name);
        }
        let names: HashSet<_> = NODES.iter().map(|n| n.name).collect();
        assert_eq!(names.len(), 54);
    }

    #[test]
    fn every_node_is_found_by_name() {
        for (i, n) in NODES.iter().enumerate() {
            assert!(std::ptr::eq(node_spec(n.name).unwrap(), n));
            assert_eq!(node_index(n.name), Some(i));
        }
        // The lookup table stays short: at most 3 probes for any standard name.
        for n in NODES {
            let home = name_slot(n.name.as_bytes());
            let at = NODE_SLOTS
                .iter()
                .position(|&k| k != 0 && NODES[k as usize - 1].name == n.name)
                .unwrap();
            assert!((at + 256 - home) % 256 < 3, "{} probes far", n.name);
        }
        for name in [
            "Transfor",
            "Transforms",
            "Sphere2",
            "A",
            "TransformX",
            "Tr\u{e4}nsform",
        ] {
            assert!(node_spec(name).is_none(), "{name}");
        }
        assert!(node_spec("transform").is_none());
        assert!(node_spec("Separator").is_none());
        assert!(node_spec("").is_none());
    }

    #[test]
    fn no_duplicate_field_names() {
        for n in NODES {
            let mut seen = HashSet::new();
            for f in n.fields {
                assert!(seen.insert(f.name), "{}.{} twice", n.name, f.name);
            }
            assert!(!n.fields.is_empty(), "{} has no fields", n.name);
        }
    }

    #[test]
    fn aliases_do_not_shadow_declared_names() {
        // No declared name collides with an exposedField alias of the same node.
        for n in NODES {
            for f in n.fields.iter().filter(|f| f.access == Access::ExposedField) {
                for alias in [format!("set_{}", f.name), format!("{}_changed", f.name)] {
                    assert!(n.field(&alias).is_none(), "{}.{alias}", n.name);
                }
            }
        }
    }

    #[test]
    fn spot_checks_against_the_spec() {
        use Access::*;
        has("Transform", "scaleOrientation", SFRotation, ExposedField);
        has("Transform", "addChildren", MFNode, EventIn);
        has("Transform", "removeChildren", MFNode, EventIn);
        has("Transform", "bboxSize", SFVec3f, Field);
        has("Material", "shininess", SFFloat, ExposedField);
        has("Material", "diffuseColor", SFColor, ExposedField);
        has("Viewpoint", "set_bind", SFBool, EventIn);
        has("Viewpoint", "bindTime", SFTime, EventOut);
        has("Viewpoint", "description", SFString, Field);
        has("Switch", "choice", MFNode, ExposedField);
        has("Switch", "whichChoice", SFInt32, ExposedField);
        has("LOD", "level", MFNode, ExposedField);
        has("LOD", "center", SFVec3f, Field);
        has("LOD", "range", MFFloat, Field);
        has("Sphere", "radius", SFFloat, Field);
        has("PointLight", "attenuation", SFVec3f, ExposedField);
        has("TimeSensor", "fraction_changed", SFFloat, EventOut);
        has(
            "OrientationInterpolator",
            "keyValue",
            MFRotation,
            ExposedField,
        );
        has(
            "OrientationInterpolator",
            "value_changed",
            SFRotation,
            EventOut,
        );
        has("CoordinateInterpolator", "value_changed", MFVec3f, EventOut);
        has("PixelTexture", "image", SFImage, ExposedField);
        has("Extrusion", "set_spine", MFVec3f, EventIn);
        has("ElevationGrid", "xDimension", SFInt32, Field);
        has("Script", "mustEvaluate", SFBool, Field);
        assert_eq!(node_spec("Script").unwrap().fields.len(), 3);
        assert_eq!(node_spec("Sphere").unwrap().fields.len(), 1);
        assert_eq!(node_spec("Transform").unwrap().fields.len(), 10);
        assert_eq!(node_spec("IndexedFaceSet").unwrap().fields.len(), 18);
    }

    #[test]
    fn event_aliases_resolve() {
        let t = node_spec("Transform").unwrap();
        let (f, a) = t.event("set_translation").unwrap();
        assert_eq!((f.name, f.ty, a), ("translation", SFVec3f, Access::EventIn));
        let (f, a) = t.event("rotation_changed").unwrap();
        assert_eq!(
            (f.name, f.ty, a),
            ("rotation", SFRotation, Access::EventOut)
        );
        let (f, a) = t.event("translation").unwrap();
        assert_eq!((f.name, a), ("translation", Access::ExposedField));
        let (f, a) = t.event("addChildren").unwrap();
        assert_eq!((f.name, a), ("addChildren", Access::EventIn));
        // Fields (not exposed) have no aliases.
        assert!(t.event("set_bboxSize").is_none());
        assert!(t.event("bboxSize_changed").is_none());
        assert!(t.event("set_").is_none());
        assert!(t.event("_changed").is_none());
        assert!(t.event("nonsense").is_none());
        // A declared eventIn/eventOut answers as itself.
        let vp = node_spec("Viewpoint").unwrap();
        assert_eq!(vp.event("set_bind").unwrap().1, Access::EventIn);
        assert_eq!(vp.event("isBound").unwrap().1, Access::EventOut);
        let ci = node_spec("ColorInterpolator").unwrap();
        let (f, a) = ci.event("value_changed").unwrap();
        assert_eq!(
            (f.name, f.ty, a),
            ("value_changed", SFColor, Access::EventOut)
        );
        // Extrusion's set_scale is a declared eventIn, its scale a plain field.
        let ex = node_spec("Extrusion").unwrap();
        let (f, a) = ex.event("set_scale").unwrap();
        assert_eq!((f.name, a), ("set_scale", Access::EventIn));
        assert!(ex.event("scale_changed").is_none());
    }

    #[test]
    fn field_type_names_round_trip() {
        for t in FieldType::ALL {
            assert_eq!(FieldType::from_name(t.name()), Some(t));
        }
        assert_eq!(FieldType::from_name("SFBool"), Some(SFBool));
        assert_eq!(FieldType::from_name("sfbool"), None);
        assert_eq!(FieldType::from_name("SFVec3d"), None);
        assert_eq!(FieldType::ALL.iter().filter(|t| t.is_mf()).count(), 9);
        for t in FieldType::ALL {
            assert_eq!(t.is_mf(), t.name().starts_with("MF"), "{t:?}");
        }
    }

    #[test]
    fn field_type_properties() {
        assert_eq!(SFColor.arity(), Some(3));
        assert_eq!(SFRotation.arity(), Some(4));
        assert_eq!(SFVec2f.arity(), Some(2));
        assert_eq!(SFVec3f.arity(), Some(3));
        assert_eq!(SFFloat.arity(), Some(1));
        assert_eq!(SFInt32.arity(), Some(1));
        assert_eq!(SFTime.arity(), Some(1));
        assert_eq!(MFRotation.arity(), Some(4));
        assert_eq!(MFVec2f.arity(), Some(2));
        for t in [SFBool, SFString, SFImage, SFNode, MFString, MFNode] {
            assert_eq!(t.arity(), None, "{t:?}");
        }
        assert!(SFNode.is_node() && MFNode.is_node() && !SFString.is_node());
        assert!(SFInt32.is_integer() && MFInt32.is_integer() && SFImage.is_integer());
        assert!(!SFFloat.is_integer() && !SFTime.is_integer());
    }

    #[test]
    fn access_keywords_round_trip() {
        for a in [
            Access::Field,
            Access::ExposedField,
            Access::EventIn,
            Access::EventOut,
        ] {
            assert_eq!(Access::from_keyword(a.keyword()), Some(a));
        }
        assert_eq!(Access::from_keyword("exposedfield"), None);
        assert_eq!(Access::from_keyword("inputOutput"), None);
    }
}
