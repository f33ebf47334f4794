//! The standard VRML97 node interfaces (ISO/IEC 14772-1:1997 clause 6) and the checks made
//! against them: the field types and access kinds ([`FieldType`], [`Access`]), one
//! [`NodeSpec`] per standard node with its `field`/`exposedField`/`eventIn`/`eventOut`
//! members in declaration order (the tables, in `tables`), name lookups through
//! open-addressing tables built at compile time (`lookup`), and typing of a parsed value
//! against a field type (`value`). The interfaces hold no defaults: those are in `support`,
//! with what gtsphere does with each node and member. Script lists only its
//! three fixed fields (`url`, `directOutput`, `mustEvaluate`); the rest of a Script's
//! interface is declared by the author. The page `docs/vrml.md` is made of `support`'s
//! tables (`support_markdown`, built for the tests that make and check the page).

mod lookup;
#[cfg(test)]
mod support;
mod tables;
mod value;

pub(crate) use lookup::same_bytes;
pub use lookup::NodeSpec;
#[cfg(test)]
pub use support::{support_markdown, FieldRole, NodeRole, SUPPORT};
pub use tables::NODES;
pub use tables::{node_index, node_spec};
pub(crate) use value::{check_value, type_name};

use FieldType::*;

/// The 20 field types of VRML97 (clause 5), by their file-format names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldType {
    /// One boolean, `TRUE` or `FALSE`.
    SFBool,
    /// One RGB colour, three floats in [0, 1].
    SFColor,
    /// One single-precision float.
    SFFloat,
    /// One image: width, height, components per pixel, then one integer per pixel.
    SFImage,
    /// One 32-bit integer.
    SFInt32,
    /// One node, or `NULL`.
    SFNode,
    /// One rotation: an axis (three floats) and an angle in radians.
    SFRotation,
    /// One double-quoted UTF-8 string.
    SFString,
    /// One time, a double in seconds since 1970-01-01 00:00 UTC.
    SFTime,
    /// One 2D vector, two floats.
    SFVec2f,
    /// One 3D vector, three floats.
    SFVec3f,
    /// Zero or more RGB colours.
    MFColor,
    /// Zero or more single-precision floats.
    MFFloat,
    /// Zero or more 32-bit integers.
    MFInt32,
    /// Zero or more nodes.
    MFNode,
    /// Zero or more rotations.
    MFRotation,
    /// Zero or more strings.
    MFString,
    /// Zero or more times.
    MFTime,
    /// Zero or more 2D vectors.
    MFVec2f,
    /// Zero or more 3D vectors.
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
    /// Its name as written in a file, e.g. `diffuseColor`.
    pub name: &'static str,
    /// The type of its values.
    pub ty: FieldType,
    /// How it may be used: set in the file, routed, or both.
    pub access: Access,
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

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
