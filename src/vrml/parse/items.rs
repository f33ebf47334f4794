//! The grammar of one item, as the parser's step reads it: values, bracketed lists, node
//! headers, statements, interface declarations and URL lists, as nom parsers over the text
//! window, and the words that cannot be names.

use super::*;

/// The words that mean something where a name could stand: keywords, and the spellings of
/// NaN and infinity (any case) that get their own message.
pub(super) const SPECIAL_WORDS: [&str; 19] = [
    "DEF",
    "USE",
    "PROTO",
    "EXTERNPROTO",
    "ROUTE",
    "TO",
    "IS",
    "NULL",
    "TRUE",
    "FALSE",
    "eventIn",
    "eventOut",
    "field",
    "exposedField",
    "nan",
    "NaN",
    "inf",
    "Inf",
    "INF",
];

/// Which bytes start a word of [`SPECIAL_WORDS`] (`n`/`N`, `i`/`I` for all cases of the
/// NaN words).
const SPECIAL_FIRST: [bool; 256] = {
    let mut t = [false; 256];
    let mut i = 0;
    while i < SPECIAL_WORDS.len() {
        t[SPECIAL_WORDS[i].as_bytes()[0] as usize] = true;
        i += 1;
    }
    t
};

/// True when `id` cannot be a keyword or a NaN word: its first byte starts none of them. Most
/// field names and node types pass this one test and skip the string comparisons.
#[inline(always)]
pub(crate) fn plain_word(id: &str) -> bool {
    id.as_bytes()
        .first()
        .is_some_and(|&b| !SPECIAL_FIRST[b as usize])
}

pub(super) fn is_nan_word(id: &str) -> bool {
    ["nan", "inf", "infinity"]
        .iter()
        .any(|w| id.len() == w.len() && id.eq_ignore_ascii_case(w))
}

/// Whether `id` is a keyword (or `field`/`exposedField`) that cannot name a node type.
pub(crate) fn is_reserved(id: &str) -> bool {
    matches!(
        id,
        "DEF"
            | "USE"
            | "PROTO"
            | "EXTERNPROTO"
            | "ROUTE"
            | "TO"
            | "IS"
            | "NULL"
            | "TRUE"
            | "FALSE"
            | "eventIn"
            | "eventOut"
            | "field"
            | "exposedField"
    )
}

#[inline(always)]
fn ident<'a>(i: &'a str, what: &str) -> PResult<'a, &'a str> {
    match identifier(i) {
        Ok((rest, id)) => Ok((rest, id)),
        Err(_) => fail(i, format!("expected {what}")),
    }
}

/// `[DEF name] Type {` with the first identifier already read.
#[inline(always)]
fn node_header<'a>(first: &'a str, rest: &'a str) -> PResult<'a, (Option<&'a str>, &'a str)> {
    let (def, ty, rest) = if !plain_word(first) && first == "DEF" {
        let (r, name) = ident(ws(rest), "a name after DEF")?;
        let (r, ty) = ident(ws(r), "a node type after the DEF name")?;
        (Some(name), ty, r)
    } else {
        (None, first, rest)
    };
    if !plain_word(ty) && is_reserved(ty) {
        return fail(rest, format!("expected a node type, found keyword '{ty}'"));
    }
    let r = ws(rest);
    match r.as_bytes().first() {
        Some(b'{') => Ok((&r[1..], (def, ty))),
        None => fail(r, format!("expected '{{' after node type '{ty}'")),
        Some(_) => fail(r, format!("expected '{{' after node type '{ty}'")),
    }
}

#[inline(always)]
pub(super) fn num<'a>(i: &'a str) -> PResult<'a, lex::Number> {
    match number(i) {
        Ok((rest, n)) => Ok((rest, n)),
        Err(NumberProblem::OutOfRange) => fail(
            i,
            "number out of range (NaN and infinite values are not allowed)",
        ),
        Err(NumberProblem::NotANumber) => fail(i, "invalid number"),
    }
}

fn str_lit(i: &str) -> PResult<'_, String> {
    match string(i) {
        Ok(r) => Ok(r),
        Err(_) => Err(PErr {
            at: i,
            msg: "unterminated string".into(),
            incomplete: true,
        }),
    }
}

/// A field value of any type, read generically.
#[inline(always)]
pub(super) fn value<'a>(i: &'a str, s: &'a mut Scratch) -> PResult<'a, Val<'a>> {
    s.nums.clear();
    s.bools.clear();
    s.strs.clear();
    match i.as_bytes().first() {
        None => fail(i, "expected a field value"),
        Some(b'[') => {
            let j = ws(&i[1..]);
            match j.as_bytes().first() {
                None => fail(j, "expected a value or ']'"),
                Some(b']') => Ok((&j[1..], Val::Value(Value::Empty))),
                Some(b'"') | Some(b'0'..=b'9' | b'+' | b'-' | b'.') => bracketed(j, s),
                Some(_) => match identifier(j) {
                    Ok((_, "TRUE" | "FALSE")) => bracketed(j, s),
                    Ok((_, id)) if is_nan_word(id) => {
                        fail(j, "NaN and infinite numbers are not allowed")
                    }
                    Ok(_) => Ok((j, Val::List)),
                    Err(_) => fail(j, "expected a value or ']'"),
                },
            }
        }
        Some(b'"') => {
            let (r, st) = str_lit(i)?;
            s.strs.push(st);
            Ok((
                r,
                Val::Value(Value::Strings {
                    values: &s.strs,
                    bracketed: false,
                }),
            ))
        }
        Some(b'0'..=b'9' | b'+' | b'-' | b'.') => {
            let mut r = i;
            let mut integer = true;
            loop {
                let (r2, n) = num(r)?;
                s.nums.push(n.value);
                integer &= n.integer;
                r = r2;
                let next = ws(r);
                if next.is_empty() {
                    // The numbers may go on past the window (or the file ends inside a node).
                    return Err(PErr {
                        at: next,
                        msg: "unexpected end of file in a field value".into(),
                        incomplete: true,
                    });
                }
                if !starts_number(next) {
                    break;
                }
                r = next;
            }
            Ok((
                r,
                Val::Value(Value::Numbers {
                    values: &s.nums,
                    integer,
                    bracketed: false,
                }),
            ))
        }
        Some(_) => {
            let (r, id) = ident(i, "a field value")?;
            if plain_word(id) {
                let (r, (def, ty)) = node_header(id, r)?;
                return Ok((r, Val::Node(def, ty, i)));
            }
            match id {
                "TRUE" | "FALSE" => {
                    s.bools.push(id == "TRUE");
                    Ok((
                        r,
                        Val::Value(Value::Bools {
                            values: &s.bools,
                            bracketed: false,
                        }),
                    ))
                }
                "NULL" => Ok((r, Val::Null)),
                "IS" => {
                    let (r, name) = ident(ws(r), "an interface field name after IS")?;
                    Ok((r, Val::Value(Value::Is(name))))
                }
                "USE" => {
                    let (r, name) = ident(ws(r), "a name after USE")?;
                    Ok((r, Val::Use(name)))
                }
                _ if is_nan_word(id) => fail(i, "NaN and infinite numbers are not allowed"),
                _ => {
                    let (r, (def, ty)) = node_header(id, r)?;
                    Ok((r, Val::Node(def, ty, i)))
                }
            }
        }
    }
}

/// A bracketed list of numbers, strings or booleans (after the `[`).
fn bracketed<'a>(mut j: &'a str, s: &'a mut Scratch) -> PResult<'a, Val<'a>> {
    let mut integer = true;
    #[derive(PartialEq, Clone, Copy)]
    enum Kind {
        Num,
        Str,
        Bool,
    }
    let mut kind = None;
    loop {
        j = ws(j);
        let item = j;
        let this = match j.as_bytes().first() {
            None => return fail(j, "expected ']' to close the list"),
            Some(b']') => {
                let values = match kind {
                    Some(Kind::Str) => Value::Strings {
                        values: &s.strs,
                        bracketed: true,
                    },
                    Some(Kind::Bool) => Value::Bools {
                        values: &s.bools,
                        bracketed: true,
                    },
                    _ => Value::Numbers {
                        values: &s.nums,
                        integer,
                        bracketed: true,
                    },
                };
                return Ok((&j[1..], Val::Value(values)));
            }
            Some(b'"') => {
                let (r, st) = str_lit(j)?;
                s.strs.push(st);
                j = r;
                Kind::Str
            }
            Some(b'0'..=b'9' | b'+' | b'-' | b'.') => {
                let (r, n) = num(j)?;
                s.nums.push(n.value);
                integer &= n.integer;
                j = r;
                Kind::Num
            }
            Some(_) => match identifier(j) {
                Ok((r, b @ ("TRUE" | "FALSE"))) => {
                    s.bools.push(b == "TRUE");
                    j = r;
                    Kind::Bool
                }
                Ok((_, id)) if is_nan_word(id) => {
                    return fail(j, "NaN and infinite numbers are not allowed")
                }
                _ => return fail(j, "expected a value or ']' in this list"),
            },
        };
        if kind.is_some_and(|k| k != this) {
            return fail(item, "a list must not mix numbers, strings and booleans");
        }
        kind = Some(this);
    }
}

/// A statement at the top level or in a PROTO body.
pub(super) fn statement(i: &str) -> PResult<'_, Item<'_>> {
    let (r, id) = ident(i, "a node, PROTO, EXTERNPROTO or ROUTE")?;
    match id {
        "PROTO" | "EXTERNPROTO" => {
            let (r, name) = ident(ws(r), "a PROTO name")?;
            let r = ws(r);
            if !r.starts_with('[') {
                return fail(
                    r,
                    format!("expected '[' to open the interface of {id} {name}"),
                );
            }
            Ok((&r[1..], Item::Proto(name, id == "EXTERNPROTO")))
        }
        "ROUTE" => match lex::route_body(r) {
            Ok((r, (a, b, c, d))) => Ok((r, Item::Route(a, b, c, d))),
            Err(_) => fail(r, "expected 'ROUTE node.eventOut TO node.eventIn'"),
        },
        "USE" => {
            let (r, name) = ident(ws(r), "a name after USE")?;
            Ok((r, Item::Use(name)))
        }
        _ => {
            let (r, (def, ty)) = node_header(id, r)?;
            Ok((r, Item::Node(def, ty)))
        }
    }
}

/// An interface declaration `access type name [value]`; `with_value` for PROTO and Script.
fn decl<'a>(
    access: &'a str,
    r: &'a str,
    with_value: bool,
    s: &'a mut Scratch,
) -> PResult<'a, Item<'a>> {
    let (r, ty) = ident(ws(r), "a field type")?;
    let (r, name) = ident(ws(r), "a field name")?;
    if with_value && (access == "field" || access == "exposedField") {
        let (r, v) = value(ws(r), s)?;
        Ok((r, Item::Decl(access, ty, name, Some(v))))
    } else if with_value {
        // eventIn/eventOut of a Script inside a PROTO may be `IS`-mapped.
        let r2 = ws(r);
        if let Ok((r3, "IS")) = identifier(r2) {
            let (r4, target) = ident(ws(r3), "an interface field name after IS")?;
            return Ok((
                r4,
                Item::Decl(access, ty, name, Some(Val::Value(Value::Is(target)))),
            ));
        }
        Ok((r, Item::Decl(access, ty, name, None)))
    } else {
        Ok((r, Item::Decl(access, ty, name, None)))
    }
}

fn is_access(id: &str) -> bool {
    matches!(id, "eventIn" | "eventOut" | "field" | "exposedField")
}

/// One element of a node body.
#[inline(always)]
pub(super) fn body_element<'a>(i: &'a str, s: &'a mut Scratch) -> PResult<'a, Item<'a>> {
    if let Some(r) = i.strip_prefix('}') {
        return Ok((r, Item::Close));
    }
    let (r, id) = ident(i, "a field name or '}'")?;
    if plain_word(id) {
        let (r, v) = value(ws(r), s)?;
        return Ok((r, Item::Field(id, v)));
    }
    match id {
        "PROTO" | "EXTERNPROTO" | "ROUTE" => statement(i),
        _ if is_access(id) => decl(id, r, true, s),
        "DEF" | "USE" => fail(i, format!("expected a field name before {id}")),
        _ => {
            let (r, v) = value(ws(r), s)?;
            Ok((r, Item::Field(id, v)))
        }
    }
}

pub(super) fn list_item(i: &str) -> PResult<'_, Item<'_>> {
    if let Some(r) = i.strip_prefix(']') {
        return Ok((r, Item::Close));
    }
    let (r, id) = ident(i, "a node, USE or ']'")?;
    match id {
        "USE" => {
            let (r, name) = ident(ws(r), "a name after USE")?;
            Ok((r, Item::Use(name)))
        }
        "NULL" => Ok((r, Item::Null)),
        // PROTO declarations are allowed among nodes only at statement level; be lenient.
        _ => {
            let (r, (def, ty)) = node_header(id, r)?;
            Ok((r, Item::Node(def, ty)))
        }
    }
}

pub(super) fn iface_element<'a>(
    i: &'a str,
    external: bool,
    s: &'a mut Scratch,
) -> PResult<'a, Item<'a>> {
    if let Some(r) = i.strip_prefix(']') {
        return Ok((r, Item::Close));
    }
    let (r, id) = ident(i, "an interface declaration or ']'")?;
    if !is_access(id) {
        return fail(
            i,
            format!("expected eventIn, eventOut, field or exposedField, found '{id}'"),
        );
    }
    decl(id, r, !external, s)
}

/// The URL list after an EXTERNPROTO interface: a string or a bracketed list of strings.
pub(super) fn url_list<'a>(i: &'a str, s: &'a mut Scratch) -> PResult<'a, Item<'a>> {
    match value(i, s)? {
        (r, Val::Value(Value::Strings { values, .. })) => Ok((r, Item::Urls(values))),
        (r, Val::Value(Value::Empty)) => Ok((r, Item::Urls(&[]))),
        _ => fail(
            i,
            "expected the EXTERNPROTO's URL list (a string or [ strings ])",
        ),
    }
}
