//! Finding a standard node type by name, and a member of its interface by name, without
//! scanning: each [`NodeSpec`] carries an open-addressing table over its fields, and the list
//! of node types (`tables`) has one over the type names, both built at compile time by
//! `const fn`s. Every
//! node and field of a scene is looked up here, so the hashes are a few byte reads and the
//! name comparison avoids a `memcmp` call for the usual 4 to 16 bytes.

use super::{Access, FieldSpec};

/// A standard node type and its interface, in declaration order.
#[derive(Debug)]
pub struct NodeSpec {
    /// The node type's name as written in a file, e.g. `Transform`.
    pub name: &'static str,
    /// Its interface members, in the standard's declaration order.
    pub fields: &'static [FieldSpec],
    /// An open-addressing table over `fields` (index + 1, 0 for empty) by [`name_slot`], so
    /// that a field name is found without scanning the list.
    field_slots: [u8; FIELD_SLOTS],
}

/// Slots of [`NodeSpec::field_slots`]: a power of two, more than twice the longest field list.
const FIELD_SLOTS: usize = 64;

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

/// `a == b` for names: those of 4 to 16 bytes (almost all) are compared as two overlapping
/// words instead of through a `memcmp` call.
#[inline(always)]
pub(crate) fn same_bytes(a: &[u8], b: &[u8]) -> bool {
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

/// Where a node type name starts its probe in the table over the node type names: a hash of its length and its
/// first, middle and last bytes (every name is looked up, so this must be cheap).
#[inline]
pub(super) const fn name_slot(b: &[u8]) -> usize {
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

/// A [`NodeSpec`] with its field table (used by the tables to declare each node).
pub(super) const fn node(name: &'static str, fields: &'static [FieldSpec]) -> NodeSpec {
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

#[cfg(test)]
mod tests {
    use super::super::tables::{node_index, node_spec, NODES, NODE_SLOTS};
    use super::super::FieldType::*;
    use super::*;

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
}
