//! Nodes of plain numbers read whole: a node whose fields all hold a few plain numbers
//! ([`FlatNode`]: `Particle { position x y z radius r color r g b }`, what `convert` writes)
//! is offered to the sink ([`super::Sink::flat_node`]), which lowers it at once when it is an
//! instance of a PROTO it can lower by template.

use super::super::lex::{identifier, number, starts_number, ws};
use super::{is_reserved, plain_word};

/// At most this many fields are taken in a [`FlatNode`].
const MAX_FLAT_FIELDS: usize = 8;

/// One field of a [`FlatNode`]: where its name starts (from the node's start) and how long
/// it is, and its one to three numbers.
#[derive(Clone, Copy, Debug, Default)]
pub struct FlatField {
    pub at: u32,
    name_len: u32,
    pub integer: bool,
    len: u8,
    numbers: [f64; 3],
}

impl PartialEq for FlatField {
    fn eq(&self, o: &Self) -> bool {
        (self.at, self.name_len, self.integer) == (o.at, o.name_len, o.integer)
            && self.numbers() == o.numbers()
    }
}

impl FlatField {
    /// The field's name in the node's `text`.
    pub fn name<'t>(&self, text: &'t str) -> &'t str {
        &text[self.at as usize..(self.at + self.name_len) as usize]
    }
    pub fn numbers(&self) -> &[f64] {
        &self.numbers[..usize::from(self.len)]
    }
}

/// A node (without DEF) whose fields each hold one to three plain numbers, as written; its
/// names are read from its text (so that the parser can keep one to fill).
#[derive(Clone, Debug, Default)]
pub struct FlatNode {
    ty_len: u32,
    fields: [FlatField; MAX_FLAT_FIELDS],
    count: u8,
    /// The length of its text.
    pub len: usize,
}

impl PartialEq for FlatNode {
    /// (What a node read into a buffer holds beyond its fields is not part of it.)
    fn eq(&self, o: &Self) -> bool {
        (self.ty_len, self.len) == (o.ty_len, o.len) && self.fields() == o.fields()
    }
}

impl FlatNode {
    /// The node's type in its `text`.
    pub fn ty<'t>(&self, text: &'t str) -> &'t str {
        &text[..self.ty_len as usize]
    }
    /// The fields in the order written.
    pub fn fields(&self) -> &[FlatField] {
        &self.fields[..usize::from(self.count)]
    }
}

#[cfg(test)]
/// Reads a [`FlatNode`] at the start of `text`. `None`: not one, or the text ends first.
pub fn flat_node(text: &str) -> Option<FlatNode> {
    let mut node = FlatNode::default();
    read_flat_node(text, &mut node).then_some(node)
}

/// [`flat_node`] into `node` (the parser keeps one): false if not one.
#[inline]
pub fn read_flat_node(text: &str, node: &mut FlatNode) -> bool {
    read_flat(text, node).is_some()
}

fn read_flat(text: &str, node: &mut FlatNode) -> Option<()> {
    node.count = 0;
    let (rest, ty) = identifier(text).ok()?;
    if !plain_word(ty) && is_reserved(ty) {
        return None;
    }
    node.ty_len = ty.len() as u32;
    let mut rest = ws(rest).strip_prefix('{')?;
    loop {
        rest = ws(rest);
        if let Some(r) = rest.strip_prefix('}') {
            node.len = text.len() - r.len();
            return Some(());
        }
        let at = text.len() - rest.len();
        let (r, name) = identifier(rest).ok()?;
        if !plain_word(name) && is_reserved(name) {
            return None;
        }
        let field = node.fields.get_mut(usize::from(node.count))?;
        field.at = u32::try_from(at).ok()?;
        field.name_len = name.len() as u32;
        field.integer = true;
        field.len = 0;
        rest = ws(r);
        while starts_number(rest) {
            let (r, n) = number(rest).ok()?;
            *field.numbers.get_mut(usize::from(field.len))? = n.value;
            field.len += 1;
            field.integer &= n.integer;
            rest = ws(r);
        }
        // (At the end of the text the value might go on: not read here.)
        if field.len == 0 || rest.is_empty() {
            return None;
        }
        node.count += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_nodes_hold_plain_numbers_only() {
        let t = "Particle { position 1 2.5 -3 radius 0.5 color 1 0 0 } P";
        let n = flat_node(t).unwrap();
        assert_eq!((n.ty(t), &t[n.len..]), ("Particle", " P"));
        let f = n.fields();
        assert_eq!(f.len(), 3);
        assert_eq!(
            (f[0].name(t), f[0].numbers(), f[0].integer),
            ("position", &[1.0, 2.5, -3.0][..], false)
        );
        assert_eq!(
            (
                f[1].name(t),
                &t[f[1].at as usize..][..6],
                f[2].numbers(),
                f[2].integer
            ),
            ("radius", "radius", &[1.0, 0.0, 0.0][..], true)
        );
        // A node read into the buffer of a longer one keeps nothing of it.
        let mut buffer = flat_node("Q { a 1 2 3 b 4 c 5 d 6 }").unwrap();
        assert!(read_flat_node("Particle { b 7 }", &mut buffer));
        assert_eq!(buffer.fields()[0].numbers(), [7.0]);
        assert_eq!(flat_node("Particle { }").unwrap().fields().len(), 0);
        for t in [
            "Particle { position 1 2 3 4 }",
            "Particle { position [ 1 2 3 ] }",
            "Particle { name \"x\" }",
            "Particle { on TRUE }",
            "Particle { child Group { } }",
            "Particle { radius IS r }",
            "DEF P Particle { }",
            "Particle { radius 1 ",
            "Particle { radius 1",
            "Particle [ ]",
        ] {
            assert_eq!(flat_node(t), None, "{t}");
        }
    }
}
