//! The syntax layer's output: a stream of events, one per piece of a node, in file order.
//!
//! The parser knows nothing of what a Sphere means; it pushes each piece to a [`Sink`] as soon
//! as it is read, so a million-node file is never a million-node tree. [`OwnedEvent`] is the
//! recorded form kept for DEF'd nodes and PROTO declarations, replayed for USE and instances.

use std::rc::Rc;

use crate::error::Error;
use crate::source::{Pos, SourceWindow};

/// A non-node field value, read without knowing the field's type (checked later).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value<'a> {
    /// Numbers; `integer` when every one was written as an integer (decimal or hex).
    Numbers {
        values: &'a [f64],
        integer: bool,
        bracketed: bool,
    },
    Bools {
        values: &'a [bool],
        bracketed: bool,
    },
    Strings {
        values: &'a [String],
        bracketed: bool,
    },
    /// `[ ]`: an empty list of any type.
    Empty,
    /// `IS interfaceField` inside a PROTO body.
    Is(&'a str),
}

/// One piece of the scene text. `at` is where the piece starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event<'a> {
    NodeStart {
        def: Option<&'a str>,
        ty: &'a str,
        at: Pos,
    },
    NodeEnd {
        at: Pos,
    },
    Field {
        name: &'a str,
        at: Pos,
        value: Value<'a>,
    },
    /// An SFNode or MFNode field: node events, `Use` and `Null` follow until `NodesEnd`.
    NodesStart {
        name: &'a str,
        at: Pos,
    },
    NodesEnd {
        at: Pos,
    },
    Use {
        name: &'a str,
        at: Pos,
    },
    Null {
        at: Pos,
    },
    /// An interface declaration (PROTO, EXTERNPROTO or Script): `access type name`; for
    /// `field` and `exposedField` outside EXTERNPROTO a value event follows, named `name`.
    Decl {
        access: &'a str,
        ty: &'a str,
        name: &'a str,
        at: Pos,
    },
    ProtoStart {
        name: &'a str,
        at: Pos,
        external: bool,
    },
    /// The `{` that opens a PROTO body.
    ProtoBody {
        at: Pos,
    },
    /// The end of a PROTO (its `}`) or EXTERNPROTO (after its URL list).
    ProtoEnd {
        at: Pos,
        urls: &'a [String],
    },
    Route {
        from_node: &'a str,
        from_field: &'a str,
        to_node: &'a str,
        to_field: &'a str,
        at: Pos,
    },
}

/// Receives events in file order.
pub trait Sink {
    /// `src` is there to turn offsets into positioned diagnostics.
    fn event(&mut self, src: &SourceWindow, ev: Event<'_>) -> Result<(), Error>;

    /// The text from `at`, where a node starts that may stand there (the top level or a list
    /// of nodes), for a sink that reads some nodes whole: the bytes it read the node from if
    /// it took it, `None` to be given its events instead (the default). Text up to the end
    /// of the window is there; a node that goes past it is left to the events.
    fn whole_node(
        &mut self,
        src: &SourceWindow,
        at: Pos,
        text: &str,
    ) -> Result<Option<usize>, Error> {
        let _ = (src, at, text);
        Ok(None)
    }

    /// A node of plain numbers read whole (see [`crate::vrml::parse::flat::flat_node`]),
    /// `text` from its start, at `at` where a node may stand: true if the sink took it,
    /// false to be given its events instead (the default).
    fn flat_node(
        &mut self,
        src: &SourceWindow,
        at: Pos,
        text: &str,
        node: &crate::vrml::parse::flat::FlatNode,
    ) -> Result<bool, Error> {
        let _ = (src, at, text, node);
        Ok(false)
    }
}

/// An owned value, for recorded events.
#[derive(Clone, Debug, PartialEq)]
pub enum OwnedValue {
    Numbers {
        values: Nums,
        integer: bool,
        bracketed: bool,
    },
    Bools {
        values: Rc<[bool]>,
        bracketed: bool,
    },
    Strings {
        values: Rc<[String]>,
        bracketed: bool,
    },
    Empty,
    Is(Rc<str>),
}

/// Recorded numbers: up to [`Nums::INLINE`] held in place (a PROTO instance's vectors and
/// colours, no allocation per field), longer lists shared.
#[derive(Clone, Debug)]
pub enum Nums {
    Inline {
        len: u8,
        values: [f64; Nums::INLINE],
    },
    Shared(Rc<[f64]>),
}

impl Nums {
    pub const INLINE: usize = 4;

    pub fn new(values: &[f64]) -> Self {
        if values.len() <= Self::INLINE {
            let mut v = [0.0; Self::INLINE];
            v[..values.len()].copy_from_slice(values);
            Nums::Inline {
                len: values.len() as u8,
                values: v,
            }
        } else {
            Nums::Shared(values.into())
        }
    }
}

impl std::ops::Deref for Nums {
    type Target = [f64];
    #[inline]
    fn deref(&self) -> &[f64] {
        match self {
            Nums::Inline { len, values } => &values[..usize::from(*len)],
            Nums::Shared(v) => v,
        }
    }
}

impl PartialEq for Nums {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// An owned event; names are reference counted so that replay clones cheaply.
#[derive(Clone, Debug, PartialEq)]
pub enum OwnedEvent {
    NodeStart {
        def: Option<Rc<str>>,
        ty: Rc<str>,
        at: Pos,
    },
    NodeEnd {
        at: Pos,
    },
    Field {
        name: Rc<str>,
        at: Pos,
        value: OwnedValue,
    },
    NodesStart {
        name: Rc<str>,
        at: Pos,
    },
    NodesEnd {
        at: Pos,
    },
    Use {
        name: Rc<str>,
        at: Pos,
    },
    Null {
        at: Pos,
    },
    Decl {
        access: Rc<str>,
        ty: Rc<str>,
        name: Rc<str>,
        at: Pos,
    },
    ProtoStart {
        name: Rc<str>,
        at: Pos,
        external: bool,
    },
    ProtoBody {
        at: Pos,
    },
    ProtoEnd {
        at: Pos,
        urls: Rc<[String]>,
    },
    Route {
        from_node: Rc<str>,
        from_field: Rc<str>,
        to_node: Rc<str>,
        to_field: Rc<str>,
        at: Pos,
    },
}

impl Value<'_> {
    pub fn to_owned_value(self) -> OwnedValue {
        match self {
            Value::Numbers {
                values,
                integer,
                bracketed,
            } => OwnedValue::Numbers {
                values: Nums::new(values),
                integer,
                bracketed,
            },
            Value::Bools { values, bracketed } => OwnedValue::Bools {
                values: values.into(),
                bracketed,
            },
            Value::Strings { values, bracketed } => OwnedValue::Strings {
                values: values.into(),
                bracketed,
            },
            Value::Empty => OwnedValue::Empty,
            Value::Is(n) => OwnedValue::Is(n.into()),
        }
    }
}

impl OwnedValue {
    /// How many values it holds (numbers, booleans or strings).
    pub fn len(&self) -> usize {
        match self {
            OwnedValue::Numbers { values, .. } => values.len(),
            OwnedValue::Bools { values, .. } => values.len(),
            OwnedValue::Strings { values, .. } => values.len(),
            OwnedValue::Empty | OwnedValue::Is(_) => 0,
        }
    }

    pub fn as_value(&self) -> Value<'_> {
        match self {
            OwnedValue::Numbers {
                values,
                integer,
                bracketed,
            } => Value::Numbers {
                values,
                integer: *integer,
                bracketed: *bracketed,
            },
            OwnedValue::Bools { values, bracketed } => Value::Bools {
                values,
                bracketed: *bracketed,
            },
            OwnedValue::Strings { values, bracketed } => Value::Strings {
                values,
                bracketed: *bracketed,
            },
            OwnedValue::Empty => Value::Empty,
            OwnedValue::Is(n) => Value::Is(n),
        }
    }
}

impl Event<'_> {
    pub fn to_owned_event(self) -> OwnedEvent {
        match self {
            Event::NodeStart { def, ty, at } => OwnedEvent::NodeStart {
                def: def.map(Rc::from),
                ty: ty.into(),
                at,
            },
            Event::NodeEnd { at } => OwnedEvent::NodeEnd { at },
            Event::Field { name, at, value } => OwnedEvent::Field {
                name: name.into(),
                at,
                value: value.to_owned_value(),
            },
            Event::NodesStart { name, at } => OwnedEvent::NodesStart {
                name: name.into(),
                at,
            },
            Event::NodesEnd { at } => OwnedEvent::NodesEnd { at },
            Event::Use { name, at } => OwnedEvent::Use {
                name: name.into(),
                at,
            },
            Event::Null { at } => OwnedEvent::Null { at },
            Event::Decl {
                access,
                ty,
                name,
                at,
            } => OwnedEvent::Decl {
                access: access.into(),
                ty: ty.into(),
                name: name.into(),
                at,
            },
            Event::ProtoStart { name, at, external } => OwnedEvent::ProtoStart {
                name: name.into(),
                at,
                external,
            },
            Event::ProtoBody { at } => OwnedEvent::ProtoBody { at },
            Event::ProtoEnd { at, urls } => OwnedEvent::ProtoEnd {
                at,
                urls: urls.into(),
            },
            Event::Route {
                from_node,
                from_field,
                to_node,
                to_field,
                at,
            } => OwnedEvent::Route {
                from_node: from_node.into(),
                from_field: from_field.into(),
                to_node: to_node.into(),
                to_field: to_field.into(),
                at,
            },
        }
    }
}

impl OwnedEvent {
    pub fn as_event(&self) -> Event<'_> {
        match self {
            OwnedEvent::NodeStart { def, ty, at } => Event::NodeStart {
                def: def.as_deref(),
                ty,
                at: *at,
            },
            OwnedEvent::NodeEnd { at } => Event::NodeEnd { at: *at },
            OwnedEvent::Field { name, at, value } => Event::Field {
                name,
                at: *at,
                value: value.as_value(),
            },
            OwnedEvent::NodesStart { name, at } => Event::NodesStart { name, at: *at },
            OwnedEvent::NodesEnd { at } => Event::NodesEnd { at: *at },
            OwnedEvent::Use { name, at } => Event::Use { name, at: *at },
            OwnedEvent::Null { at } => Event::Null { at: *at },
            OwnedEvent::Decl {
                access,
                ty,
                name,
                at,
            } => Event::Decl {
                access,
                ty,
                name,
                at: *at,
            },
            OwnedEvent::ProtoStart { name, at, external } => Event::ProtoStart {
                name,
                at: *at,
                external: *external,
            },
            OwnedEvent::ProtoBody { at } => Event::ProtoBody { at: *at },
            OwnedEvent::ProtoEnd { at, urls } => Event::ProtoEnd { at: *at, urls },
            OwnedEvent::Route {
                from_node,
                from_field,
                to_node,
                to_field,
                at,
            } => Event::Route {
                from_node,
                from_field,
                to_node,
                to_field,
                at: *at,
            },
        }
    }
}
