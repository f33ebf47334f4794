//! The VRML97 parser: an explicit-stack state machine over a streaming text window.
//!
//! Each step reads one item (a node header, a field with its value, a list element, an
//! interface declaration, a ROUTE) with the nom parsers of [`super::lex`] and pushes events
//! to the [`Sink`]. Nesting lives on a heap stack, so 100 000 nested Groups cannot overflow
//! the call stack, and nothing but the current item is held: the sink decides what to keep.

use super::lex::{self, identifier, number, starts_number, string, ws, NumberProblem};
use super::syntax::{Event, Sink, Value};
use crate::diag::Severity;
use crate::error::Error;
use crate::source::{Pos, SourceWindow};

#[derive(Clone, Copy, Debug)]
enum Frame {
    Top,
    /// Inside a node's braces.
    Body,
    /// Inside the brackets of an MFNode value.
    List,
    /// A node given without brackets as a field value: `NodesEnd` follows when it closes.
    Single,
    /// A PROTO or EXTERNPROTO interface.
    Iface {
        external: bool,
    },
    ProtoBody,
}

/// A parse failure inside one item: where, what, and whether the input ran out first.
struct PErr<'a> {
    at: &'a str,
    msg: String,
    incomplete: bool,
}

type PResult<'a, T> = Result<(&'a str, T), PErr<'a>>;

fn fail<T>(at: &str, msg: impl Into<String>) -> PResult<'_, T> {
    Err(PErr {
        at,
        msg: msg.into(),
        incomplete: at.is_empty(),
    })
}

/// How near the window's end a failed item is read again with more text: longer than any
/// number or keyword, so that one cut by the end is never taken for an error (an error is
/// only found again, further on, once the window has grown).
const RUNS_TO_END: usize = 1024;

/// Scratch vectors that hold a value's items while its event is delivered.
#[derive(Default)]
struct Scratch {
    nums: Vec<f64>,
    bools: Vec<bool>,
    strs: Vec<String>,
}

/// What a field value turned out to be.
enum Val<'a> {
    Value(Value<'a>),
    Use(&'a str),
    Null,
    /// A node without brackets; its header has been read. The last item is where it starts.
    Node(Option<&'a str>, &'a str, &'a str),
    /// `[` followed by nodes: the list's items follow.
    List,
}

enum Item<'a> {
    /// `}` `]`
    Close,
    Node(Option<&'a str>, &'a str),
    Use(&'a str),
    Null,
    Proto(&'a str, bool),
    Route(&'a str, &'a str, &'a str, &'a str),
    Field(&'a str, Val<'a>),
    Decl(&'a str, &'a str, &'a str, Option<Val<'a>>),
    /// The URL list that ends an EXTERNPROTO.
    Urls(&'a [String]),
}

mod items;
use items::*;
pub(crate) use items::{is_reserved, plain_word};

/// Parses one VRML97 source, pushing events to `sink`.
pub struct Parser {
    pub src: SourceWindow,
    stack: Vec<Frame>,
    scratch: Scratch,
    /// The nodes read whole are read into these (see [`sphere`]).
    flat: flat::FlatNode,
    /// Stop at the end of the input, wherever it is, instead of requiring the file's end
    /// there (see [`Parser::resume`]).
    pub pause_at_end: bool,
    /// With `floor` frames open (0: never), stop before a `}` or `]` instead of closing the
    /// innermost (see [`Run::Floor`]).
    pub floor: usize,
}

/// Where [`Parser::resume`] stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Run {
    /// At the end of the file, every node closed.
    Done,
    /// At the end of the input, which may be anywhere between items: the driver continues it
    /// ([`SourceWindow::jump`]) or stops there.
    Paused,
    /// Before a `}` or `]` with [`Parser::floor`] frames open (a piece of a list read apart
    /// reached the list's end).
    Floor,
}

/// A read error (I/O, corrupt gzip) at the point where the text stopped.
fn io_err(src: &SourceWindow, e: std::io::Error) -> Error {
    let at = src.base + src.buf.len() as u64;
    Error::Diag(Box::new(src.diagnostic(
        Severity::Error,
        at,
        format!("cannot read further: {e}"),
    )))
}

impl Parser {
    pub fn new(src: SourceWindow) -> Self {
        Parser {
            src,
            stack: Vec::new(),
            scratch: Scratch::default(),
            flat: flat::FlatNode::default(),
            pause_at_end: false,
            floor: 0,
        }
    }

    fn error_at(&self, at: u64, msg: impl Into<String>) -> Error {
        Error::Diag(Box::new(self.src.diagnostic(
            Severity::Error,
            at,
            msg.into(),
        )))
    }

    /// Skips white space; returns the next byte and how many bytes the window holds from it,
    /// or None at the end of the input.
    #[inline(always)]
    fn skip_ws(&mut self) -> Result<Option<(u8, usize)>, Error> {
        loop {
            self.src.ensure().map_err(|e| io_err(&self.src, e))?;
            let rest = ws(self.src.rest());
            if rest.is_empty() && !self.src.eof {
                // White space to the end of the window: pass it, all but a comment still
                // open on its last line (which must be skipped again with what follows), so
                // that a long run of spaces is never held in memory; then read more.
                let text = self.src.rest();
                let line = text.rfind(['\n', '\r']).map_or(0, |i| i + 1);
                let open_comment = text[line..].find('#').map(|i| line + i);
                self.src
                    .advance_to(text.len() - open_comment.unwrap_or(text.len()));
                self.src.grow().map_err(|e| io_err(&self.src, e))?;
                continue;
            }
            let n = rest.len();
            let next = rest.as_bytes().first().map(|&b| (b, n));
            self.src.advance_to(n);
            return Ok(next);
        }
    }

    fn header(&mut self) -> Result<(), Error> {
        self.src.ensure().map_err(|e| io_err(&self.src, e))?;
        let text = self.src.rest();
        let bom = if text.starts_with('\u{feff}') { 3 } else { 0 };
        let text = &text[bom..];
        if lex::header(text).is_err() {
            let msg = if text.starts_with("#VRML V1.0") {
                "VRML 1.0 files are not supported: gtsphere reads VRML97 ('#VRML V2.0 utf8')"
            } else if text.starts_with("#X3D") || text.starts_with("<?xml") {
                "X3D files are not supported: gtsphere reads VRML97 ('#VRML V2.0 utf8')"
            } else {
                "not a VRML97 file: the first line must start with '#VRML V2.0 utf8'"
            };
            return Err(self.error_at(self.src.offset(), msg));
        }
        // The rest of the header line is a comment (exporters write their name there).
        let end = text.find('\n').unwrap_or(text.len());
        let n = text.len() - end;
        self.src.advance_to(n);
        Ok(())
    }

    /// Reads the whole source.
    ///
    /// Generic over the sink so that a concrete sink's event handling is compiled into the
    /// parser (each event's variant is then known where it is handled); `&mut dyn Sink` works
    /// too.
    pub fn run<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<(), Error> {
        self.begin()?;
        self.resume(sink).map(|_| ())
    }

    /// Reads the header line; [`Self::resume`] reads the rest.
    pub fn begin(&mut self) -> Result<(), Error> {
        self.header()?;
        self.stack.push(Frame::Top);
        Ok(())
    }

    /// How many frames are open (the top level is one).
    pub fn depth(&self) -> usize {
        self.stack.len()
    }

    /// At the end of the input: an error unless every node is closed.
    pub fn end(&self) -> Result<(), Error> {
        let what = match *self.stack.last().unwrap_or(&Frame::Top) {
            Frame::Top => return Ok(()),
            Frame::Body | Frame::Single => "expected '}' to close a node",
            Frame::List => "expected ']' to close a list of nodes",
            Frame::Iface { .. } => "expected ']' to close a PROTO interface",
            Frame::ProtoBody => "expected '}' to close a PROTO body",
        };
        Err(self.error_at(self.src.offset(), format!("unexpected end of file: {what}")))
    }

    /// Reads items to the end of the input (then `Done`, or `Paused` with `pause_at_end`).
    pub fn resume<S: Sink + ?Sized>(&mut self, sink: &mut S) -> Result<Run, Error> {
        loop {
            let next = self.skip_ws()?;
            let at = Pos::at(self.src.offset());
            let top = *self.stack.last().unwrap_or(&Frame::Top);
            let Some((first, ahead)) = next else {
                if self.pause_at_end {
                    return Ok(Run::Paused);
                }
                self.end()?;
                return Ok(Run::Done);
            };
            if matches!(first, b'}' | b']') && self.stack.len() == self.floor {
                return Ok(Run::Floor);
            }
            match (top, first) {
                (Frame::ProtoBody, b'}') => {
                    self.src.pos += 1;
                    self.stack.pop();
                    sink.event(&self.src, Event::ProtoEnd { at, urls: &[] })?;
                    continue;
                }
                (Frame::Iface { external }, b']') => {
                    self.src.pos += 1;
                    self.stack.pop();
                    self.skip_ws()?;
                    let at2 = self.src.offset();
                    if external {
                        self.step(sink, Pos::at(at2), ItemIn::Urls)?;
                    } else {
                        if !self.src.rest().starts_with('{') {
                            return Err(self.error_at(at2, "expected '{' to open the PROTO body"));
                        }
                        self.src.pos += 1;
                        self.stack.push(Frame::ProtoBody);
                        sink.event(&self.src, Event::ProtoBody { at: Pos::at(at2) })?;
                    }
                    continue;
                }
                // A `}` or `]` closing a node or a list, when more text follows in the window:
                // what `step` does with the Close item, without the item parser and its retry
                // check.
                (Frame::Body, b'}') | (Frame::List, b']') if ahead > 1 => {
                    let k = self.stack.len();
                    let under = k.checked_sub(2).map(|j| self.stack[j]);
                    // (A Close item's events do not use the text after it.)
                    let pushes = emit(&self.src, sink, at, Item::Close, Some(top), under, "")?;
                    self.src.pos += 1;
                    self.apply(pushes);
                    continue;
                }
                _ => {}
            }
            // A node read whole from its text by the sink, or a node of plain numbers read
            // whole here, if the sink takes it.
            if matches!(top, Frame::Top | Frame::List) && first.is_ascii_alphabetic() {
                if let Some(len) = sink.whole_node(&self.src, at, self.src.rest())? {
                    self.src.pos += len;
                    continue;
                }
                if flat::read_flat_node(self.src.rest(), &mut self.flat) {
                    let text = self.src.rest();
                    if sink.flat_node(&self.src, at, text, &self.flat)? {
                        self.src.pos += self.flat.len;
                        continue;
                    }
                }
            }
            match top {
                Frame::Top | Frame::ProtoBody => self.step(sink, at, ItemIn::Statement)?,
                Frame::Body => self.step(sink, at, ItemIn::Body)?,
                Frame::List => self.step(sink, at, ItemIn::List)?,
                Frame::Iface { external } => self.step(sink, at, ItemIn::Iface { external })?,
                Frame::Single => unreachable!("a Single frame is popped when its node closes"),
            }
        }
    }

    /// Runs one item parser, retrying with more input when it ran into the end of the window,
    /// then turns the item into events.
    #[inline(always)]
    fn step<S: Sink + ?Sized>(&mut self, sink: &mut S, at: Pos, what: ItemIn) -> Result<(), Error> {
        loop {
            let eof = self.src.eof;
            let i = self.src.rest();
            let s = &mut self.scratch;
            // Direct calls (not a closure per kind), so that the item parsers are inlined here
            // and their result need not be built in memory.
            let parsed = match what {
                ItemIn::Body => body_element(i, s),
                ItemIn::Statement => statement(i),
                ItemIn::List => list_item(i),
                ItemIn::Iface { external } => iface_element(i, external, s),
                ItemIn::Urls => url_list(i, s),
            };
            match parsed {
                // An item that failed within a token's length of the window's end may only
                // have been cut by it (`-` of `-0.5`, `1e` of `1e-3`): read more and retry.
                Err(e) if eof || !(e.incomplete || e.at.len() < RUNS_TO_END) => {
                    let off = self.src.offset_of(e.at);
                    let msg = e.msg;
                    return Err(self.error_at(off, msg));
                }
                Ok((rest, _)) if rest.is_empty() && !eof => {}
                Err(_) => {}
                Ok((rest, item)) => {
                    let k = self.stack.len();
                    let top = self.stack.last().copied();
                    let under = k.checked_sub(2).map(|j| self.stack[j]);
                    let pushes = emit(&self.src, sink, at, item, top, under, rest)?;
                    let n = rest.len();
                    self.src.advance_to(n);
                    self.apply(pushes);
                    return Ok(());
                }
            }
            self.src.grow().map_err(|e| io_err(&self.src, e))?;
        }
    }

    #[inline(always)]
    fn apply(&mut self, p: StackOp) {
        match p {
            StackOp::None => {}
            StackOp::Push(f) => self.stack.push(f),
            StackOp::Push2(a, b) => {
                self.stack.push(a);
                self.stack.push(b);
            }
            StackOp::Pop => {
                self.stack.pop();
            }
            StackOp::PopCloseSingle => {
                self.stack.pop();
                if let Some(Frame::Single) = self.stack.last() {
                    self.stack.pop();
                }
            }
        }
    }
}

/// Which item parser a step runs.
#[derive(Clone, Copy)]
enum ItemIn {
    Statement,
    Body,
    List,
    Iface { external: bool },
    Urls,
}

enum StackOp {
    None,
    Push(Frame),
    Push2(Frame, Frame),
    Pop,
    PopCloseSingle,
}

/// Position of the start of `rest`-relative text, for events inside one item.
fn off(src: &SourceWindow, s: &str) -> Pos {
    Pos::at(src.offset_of(s))
}

#[inline(always)]
fn emit_val<S: Sink + ?Sized>(
    src: &SourceWindow,
    sink: &mut S,
    name: &str,
    at: Pos,
    v: Val<'_>,
    end: &str,
) -> Result<StackOp, Error> {
    match v {
        Val::Value(value) => {
            sink.event(src, Event::Field { name, at, value })?;
            Ok(StackOp::None)
        }
        Val::Use(u) => {
            sink.event(src, Event::NodesStart { name, at })?;
            sink.event(src, Event::Use { name: u, at })?;
            sink.event(src, Event::NodesEnd { at: off(src, end) })?;
            Ok(StackOp::None)
        }
        Val::Null => {
            sink.event(src, Event::NodesStart { name, at })?;
            sink.event(src, Event::Null { at })?;
            sink.event(src, Event::NodesEnd { at: off(src, end) })?;
            Ok(StackOp::None)
        }
        Val::Node(def, ty, start) => {
            sink.event(src, Event::NodesStart { name, at })?;
            let at = off(src, start);
            sink.event(src, Event::NodeStart { def, ty, at })?;
            Ok(StackOp::Push2(Frame::Single, Frame::Body))
        }
        Val::List => {
            sink.event(src, Event::NodesStart { name, at })?;
            Ok(StackOp::Push(Frame::List))
        }
    }
}

#[inline(always)]
fn emit<S: Sink + ?Sized>(
    src: &SourceWindow,
    sink: &mut S,
    at: Pos,
    item: Item<'_>,
    top: Option<Frame>,
    under: Option<Frame>,
    rest: &str,
) -> Result<StackOp, Error> {
    match item {
        Item::Urls(urls) => {
            sink.event(src, Event::ProtoEnd { at, urls })?;
            Ok(StackOp::None)
        }
        Item::Close => match top {
            Some(Frame::List) => {
                sink.event(src, Event::NodesEnd { at })?;
                Ok(StackOp::Pop)
            }
            _ => {
                sink.event(src, Event::NodeEnd { at })?;
                // Closing a node given without brackets also closes its field.
                if let Some(Frame::Single) = under {
                    sink.event(src, Event::NodesEnd { at })?;
                }
                Ok(StackOp::PopCloseSingle)
            }
        },
        Item::Node(def, ty) => {
            sink.event(src, Event::NodeStart { def, ty, at })?;
            Ok(StackOp::Push(Frame::Body))
        }
        Item::Use(name) => {
            sink.event(src, Event::Use { name, at })?;
            Ok(StackOp::None)
        }
        Item::Null => {
            sink.event(src, Event::Null { at })?;
            Ok(StackOp::None)
        }
        Item::Proto(name, external) => {
            sink.event(src, Event::ProtoStart { name, at, external })?;
            Ok(StackOp::Push(Frame::Iface { external }))
        }
        Item::Route(a, b, c, d) => {
            sink.event(
                src,
                Event::Route {
                    from_node: a,
                    from_field: b,
                    to_node: c,
                    to_field: d,
                    at,
                },
            )?;
            Ok(StackOp::None)
        }
        Item::Field(name, v) => emit_val(src, sink, name, at, v, rest),
        Item::Decl(access, ty, name, v) => {
            sink.event(
                src,
                Event::Decl {
                    access,
                    ty,
                    name,
                    at,
                },
            )?;
            match v {
                Some(v) => emit_val(src, sink, name, at, v, rest),
                None => Ok(StackOp::None),
            }
        }
    }
}

pub mod flat;

#[cfg(test)]
mod tests;
