//! Plain sphere nodes read whole from their text: `Transform { translation x y z children
//! Shape { appearance Appearance { material Material { ... } } geometry Sphere { radius r }
//! } }` (members in any order, `children` with or without brackets, the Appearance, its
//! Material and the radius optional), which exporters write once per particle, is read in
//! one pass into a [`SphereNode`] when the parser offers the lowering a node's text
//! ([`crate::vrml::syntax::Sink::whole_node`]). A lowering that takes it has what the node's
//! events would have told it; otherwise it gets the events as usual, and nothing was
//! consumed. So does any other text (a DEF, another field, a field given twice, a list where
//! one value goes); comments and commas between members make no difference.
//!
//! What it saves, with the PROTO templates fed by [`crate::vrml::parse::flat`] (`gtsphere
//! bench parse`, 1e6 particles, one reader, the hidden `--replay-every-instance` turning
//! both off, 2026-12-05): 0.38 s against 1.30 s on top-level sphere nodes (`flat`, 3.4x),
//! 0.34 against 1.43 s on `convert`'s PROTO instances with a colour per particle (4.2x),
//! 0.34 against 0.90 s on copies of PyMOL's export (2.6x).

use super::lex::{identifier, number, starts_number, ws};

/// The Material fields a sphere node may set, with their number of values.
pub const MATERIAL_FIELDS: [(&str, usize); 6] = [
    ("diffuseColor", 3),
    ("emissiveColor", 3),
    ("specularColor", 3),
    ("shininess", 1),
    ("ambientIntensity", 1),
    ("transparency", 1),
];

/// At most this many Material fields (repeats included) are taken.
const MAX_MATERIAL_FIELDS: usize = 8;

/// A sphere node's values as written. Offsets are from the start of the Transform.
#[derive(Clone, Debug, Default)]
pub struct SphereNode {
    pub translation: Option<[f64; 3]>,
    /// Whether the Shape has an Appearance, and whether that has a Material.
    pub appearance: bool,
    pub material: bool,
    /// The Material's fields in the order written: index into [`MATERIAL_FIELDS`], values.
    material_fields: [(u8, [f64; 3]); MAX_MATERIAL_FIELDS],
    material_count: u8,
    pub radius: Option<f64>,
    /// Where the Sphere node starts.
    pub sphere_at: usize,
    /// The nodes it holds (Transform, Shape, Appearance, Material, Sphere), as counted when
    /// read event by event.
    pub nodes: u64,
    /// The length of its text.
    pub len: usize,
}

impl PartialEq for SphereNode {
    /// (What a node read into a buffer holds beyond its fields is not part of it.)
    fn eq(&self, o: &Self) -> bool {
        (
            self.translation,
            self.appearance,
            self.material,
            self.radius,
        ) == (o.translation, o.appearance, o.material, o.radius)
            && (self.sphere_at, self.nodes, self.len) == (o.sphere_at, o.nodes, o.len)
            && self.material_fields().eq(o.material_fields())
    }
}

impl SphereNode {
    /// The Material's fields in the order written: which ([`MATERIAL_FIELDS`]) and values.
    pub fn material_fields(&self) -> impl Iterator<Item = (usize, &[f64])> {
        self.material_fields[..usize::from(self.material_count)]
            .iter()
            .map(|(f, v)| (usize::from(*f), &v[..MATERIAL_FIELDS[usize::from(*f)].1]))
    }
}

#[cfg(test)]
/// Reads a sphere node at the start of `text` (a `Transform` not preceded by DEF). `None`:
/// not one, or the text ends first.
pub fn sphere_node(text: &str) -> Option<SphereNode> {
    let mut node = SphereNode::default();
    read_sphere_node(text, &mut node).then_some(node)
}

/// [`sphere_node`] into `node` (the parser keeps one: a node is a few hundred bytes to copy
/// for every one read): false if not one.
#[inline]
pub fn read_sphere_node(text: &str, node: &mut SphereNode) -> bool {
    node.translation = None;
    node.appearance = false;
    node.material = false;
    node.material_count = 0;
    node.radius = None;
    node.nodes = 0;
    let mut r = Reader {
        all: text,
        rest: text,
        node,
    };
    if r.transform().is_none() {
        return false;
    }
    r.node.len = text.len() - r.rest.len();
    true
}

struct Reader<'a, 'n> {
    all: &'a str,
    rest: &'a str,
    node: &'n mut SphereNode,
}

impl<'a> Reader<'a, '_> {
    /// The next word, after white space.
    #[inline(always)]
    fn word(&mut self) -> Option<&'a str> {
        let (rest, id) = identifier(ws(self.rest)).ok()?;
        self.rest = rest;
        Some(id)
    }

    /// The next byte after white space, if it is `c` (consumed).
    #[inline(always)]
    fn byte(&mut self, c: u8) -> bool {
        let r = ws(self.rest);
        if r.as_bytes().first() == Some(&c) {
            self.rest = &r[1..];
            true
        } else {
            false
        }
    }

    /// Exactly `n` numbers (no more follow), as one field value.
    #[inline(always)]
    fn numbers(&mut self, n: usize) -> Option<[f64; 3]> {
        let mut v = [0.0; 3];
        for x in v.iter_mut().take(n) {
            let (rest, num) = number(ws(self.rest)).ok()?;
            *x = num.value;
            self.rest = rest;
        }
        let next = ws(self.rest);
        // (At the end of the text the value might go on: not read here.)
        if next.is_empty() || starts_number(next) {
            return None;
        }
        Some(v)
    }

    /// `Type {` with this type; returns where the type starts.
    #[inline(always)]
    fn open(&mut self, ty: &str) -> Option<usize> {
        let at = self.all.len() - ws(self.rest).len();
        (self.word()? == ty && self.byte(b'{')).then_some(at)
    }

    /// The members of a node up to its `}`, each word read by `member`.
    #[inline(always)]
    fn members(&mut self, mut member: impl FnMut(&mut Self, &str) -> Option<()>) -> Option<()> {
        loop {
            if self.byte(b'}') {
                return Some(());
            }
            let w = self.word()?;
            member(self, w)?;
        }
    }

    fn transform(&mut self) -> Option<()> {
        self.open("Transform")?;
        self.node.nodes += 1;
        let mut shape = false;
        self.members(|r, w| {
            match w {
                "translation" if r.node.translation.is_none() => {
                    r.node.translation = Some(r.numbers(3)?);
                }
                "children" if !shape => {
                    shape = true;
                    if r.byte(b'[') {
                        r.shape()?;
                        r.byte(b']').then_some(())?;
                    } else {
                        r.shape()?;
                    }
                }
                _ => return None,
            }
            Some(())
        })?;
        shape.then_some(())
    }

    fn shape(&mut self) -> Option<()> {
        self.open("Shape")?;
        self.node.nodes += 1;
        let mut sphere = false;
        self.members(|r, w| {
            match w {
                "appearance" if !r.node.appearance => {
                    r.node.appearance = true;
                    r.appearance()?;
                }
                "geometry" if !sphere => {
                    sphere = true;
                    r.sphere()?;
                }
                _ => return None,
            }
            Some(())
        })?;
        sphere.then_some(())
    }

    fn appearance(&mut self) -> Option<()> {
        self.open("Appearance")?;
        self.node.nodes += 1;
        self.members(|r, w| {
            if w != "material" || r.node.material {
                return None;
            }
            r.node.material = true;
            r.material()
        })
    }

    fn material(&mut self) -> Option<()> {
        self.open("Material")?;
        self.node.nodes += 1;
        self.members(|r, w| {
            let f = MATERIAL_FIELDS.iter().position(|(name, _)| *name == w)?;
            let v = r.numbers(MATERIAL_FIELDS[f].1)?;
            let k = usize::from(r.node.material_count);
            *r.node.material_fields.get_mut(k)? = (f as u8, v);
            r.node.material_count += 1;
            Some(())
        })
    }

    fn sphere(&mut self) -> Option<()> {
        self.node.sphere_at = self.open("Sphere")?;
        self.node.nodes += 1;
        self.members(|r, w| {
            if w != "radius" || r.node.radius.is_some() {
                return None;
            }
            r.node.radius = Some(r.numbers(1)?[0]);
            Some(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_common_forms_are_read_whole() {
        let t = "Transform { translation 1 2 3 children Shape { appearance Appearance { \
                 material Material { diffuseColor 0.1 0.2 0.3 shininess 0.5 } } \
                 geometry Sphere { radius 0.25 } } } Transform";
        let n = sphere_node(t).unwrap();
        assert_eq!(n.translation, Some([1.0, 2.0, 3.0]));
        assert_eq!(n.radius, Some(0.25));
        assert_eq!(n.nodes, 5);
        assert_eq!(&t[n.sphere_at..n.sphere_at + 6], "Sphere");
        assert_eq!(&t[n.len..], " Transform");
        let fields: Vec<_> = n.material_fields().collect();
        assert_eq!(fields, [(0, &[0.1, 0.2, 0.3][..]), (3, &[0.5][..])]);
        // PyMOL's order, brackets, commas and comments, no Appearance.
        let t = "Transform {\n children [ Shape { geometry Sphere { radius 1.8 } # atom\n \
                 appearance Appearance { material Material { specularColor 0.8, 0.8, 0.8 } } } ]\n \
                 translation -1 0 2 }\n";
        assert_eq!(sphere_node(t).unwrap().nodes, 5);
        let t = "Transform { children Shape { geometry Sphere { } } } ";
        let n = sphere_node(t).unwrap();
        assert_eq!((n.nodes, n.radius, n.appearance), (3, None, false));
    }

    #[test]
    fn a_node_read_into_the_buffer_of_another_keeps_nothing_of_it() {
        let mut sphere = sphere_node(
            "Transform { translation 1 2 3 children Shape { appearance Appearance { material \
             Material { shininess 0.5 } } geometry Sphere { radius 2 } } }",
        )
        .unwrap();
        assert!(read_sphere_node(
            "Transform { children Shape { geometry Sphere { } } }",
            &mut sphere
        ));
        assert_eq!(
            sphere,
            sphere_node("Transform { children Shape { geometry Sphere { } } }").unwrap()
        );
    }

    #[test]
    fn anything_else_is_left_to_the_events() {
        for t in [
            "Transform { translation 1 2 3 4 children Shape { geometry Sphere { } } } ",
            "Transform { translation 1 2 children Shape { geometry Sphere { } } } ",
            "Transform { scale 1 2 3 children Shape { geometry Sphere { } } } ",
            "Transform { children Shape { geometry Box { } } } ",
            "Transform { children Shape { appearance Appearance { } } } ",
            "Transform { children [ Shape { geometry Sphere { } } Shape { geometry Sphere { } } ] } ",
            "Transform { children DEF S Shape { geometry Sphere { } } } ",
            "Transform { children Shape { geometry Sphere { radius IS r } } } ",
            "Transform { children Shape { geometry Sphere { radius 1 radius 2 } } } ",
            "Transform { translation 1 2 3 translation 1 2 3 children Shape { geometry Sphere { } } } ",
            "Transform { children Shape { geometry USE S } } ",
            "Transform { children Shape { appearance Appearance { material Material { diffuseColor [ 1 0 0 ] } } geometry Sphere { } } } ",
            "Transform { children Shape { geometry Sphere { radius 1 } } ",
            "Transform { children Shape { geometry Sphere { radius 1",
            "Transforms { children Shape { geometry Sphere { } } } ",
        ] {
            assert_eq!(sphere_node(t), None, "{t}");
        }
    }
}
