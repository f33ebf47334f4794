//! Lexical parsers (nom) for VRML97: white space (commas and `#` comments included),
//! identifiers, numbers (float, int32 with hex), and strings with escapes.
//!
//! Each parser takes the unread text and returns the rest. White space is skipped by the
//! caller before a token, never inside these parsers.

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while1};
use nom::character::complete::{char, hex_digit1, one_of};
use nom::combinator::{opt, recognize};
use nom::error::{Error, ErrorKind};
use nom::sequence::preceded;
use nom::{IResult, Parser};

/// Skips white space: blanks, tabs, CR, LF, commas and `#` comments to the end of the line.
#[inline(always)]
pub fn ws(i: &str) -> &str {
    let b = i.as_bytes();
    // Most white space between tokens is one blank: skip it without the loop.
    if let [b' ', c, ..] = *b {
        if c > b' ' && c != b',' && c != b'#' {
            return &i[1..];
        }
    }
    let mut k = 0;
    while k < b.len() {
        match b[k] {
            b' ' | b'\t' | b'\r' | b'\n' | b',' => k += 1,
            b'#' => match memchr::memchr2(b'\n', b'\r', &b[k..]) {
                Some(n) => k += n,
                None => k = b.len(),
            },
            _ => break,
        }
    }
    &i[k..]
}

/// Which bytes may start an identifier (VRML97 Annex A IdFirstChar) and which may follow
/// (IdRestChars: digits, `+` and `-` allowed too). Bytes of multi-byte UTF-8 characters are
/// allowed: every non-ASCII character is an identifier character, so an identifier always
/// ends on an ASCII byte (a character boundary).
const ID_FIRST: u8 = 1;
const ID_REST: u8 = 2;
const ID_CLASS: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut c = 0;
    while c < 256 {
        let b = c as u8;
        let never = b <= b' '
            || matches!(
                b,
                b'"' | b'#' | b'\'' | b',' | b'.' | b'[' | b'\\' | b']' | b'{' | b'}' | 0x7f
            );
        if !never {
            t[c] = ID_REST;
            if !(b.is_ascii_digit() || b == b'+' || b == b'-') {
                t[c] |= ID_FIRST;
            }
        }
        c += 1;
    }
    t
};

/// Whether the byte may start an identifier (for a non-ASCII lead byte: the character may).
#[inline]
fn is_id_first_byte(b: u8) -> bool {
    ID_CLASS[b as usize] & ID_FIRST != 0
}

/// An identifier (node type, field, DEF name, keyword).
#[inline(always)]
pub fn identifier(i: &str) -> IResult<&str, &str> {
    let b = i.as_bytes();
    match b.first() {
        Some(&c) if is_id_first_byte(c) => {}
        _ => return Err(nom::Err::Error(Error::new(i, ErrorKind::Alpha))),
    }
    let mut end = 1;
    // Letters and digits 8 at a time, then the table for the rest (`_`, `-`, non-ASCII, ...)
    // and for the byte that ends the identifier.
    while let Some(chunk) = b
        .get(end..end + 8)
        .and_then(|c| <[u8; 8]>::try_from(c).ok())
    {
        let n = alnum_run(u64::from_le_bytes(chunk));
        end += n;
        if n < 8 {
            break;
        }
    }
    while end < b.len() && ID_CLASS[b[end] as usize] & ID_REST != 0 {
        end += 1;
    }
    Ok((&i[end..], &i[..end]))
}

/// How many of the 8 bytes of `chunk` (first byte least significant) are ASCII letters or
/// digits before the first that is not (SWAR: no carries cross bytes, as every byte is
/// below 0x80 when added to).
#[inline(always)]
fn alnum_run(chunk: u64) -> usize {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    // High bit of each byte: v >= lo, and v > hi.
    let at_least = |v: u64, lo: u8| v + u64::from(0x80 - lo) * ONES;
    let above = |v: u64, hi: u8| v + u64::from(0x7f - hi) * ONES;
    let x = chunk & !HIGH;
    let lower = x | (0x20 * ONES);
    let letter = at_least(lower, b'a') & !above(lower, b'z');
    let digit = at_least(x, b'0') & !above(x, b'9');
    let ok = (letter | digit) & !chunk & HIGH;
    (!ok & HIGH).trailing_zeros() as usize / 8
}

/// The bytes a number may start with (`+`, `-`, `.`, a digit).
const NUMBER_START: [bool; 256] = {
    let mut t = [false; 256];
    let mut c = 0;
    while c < 256 {
        t[c] = matches!(c as u8, b'0'..=b'9' | b'+' | b'-' | b'.');
        c += 1;
    }
    t
};

/// True when the text starts like a number (`+`, `-`, `.`, or a digit).
///
/// (One table load: as a chain of range tests, the branches mispredicted on coordinates whose
/// signs are random, about six times a particle by cachegrind's branch simulation.)
#[inline]
pub fn starts_number(i: &str) -> bool {
    i.as_bytes()
        .first()
        .is_some_and(|&c| NUMBER_START[c as usize])
}

/// A parsed number and whether it was written as an integer (decimal or hex, no `.` or exponent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number {
    /// The number's value, correctly rounded to f64.
    pub value: f64,
    /// Whether it was written as an integer (decimal or hex, without `.` or exponent).
    pub integer: bool,
}

/// Errors of number parsing that deserve their own message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberProblem {
    /// The text is not a number in VRML's syntax.
    NotANumber,
    /// The number is too large: beyond f64's range, or a hex integer beyond 64 bits.
    OutOfRange,
}

fn hex_text(i: &str) -> IResult<&str, (Option<char>, &str)> {
    (
        opt(one_of("+-")),
        preceded(alt((tag("0x"), tag("0X"))), hex_digit1),
    )
        .parse(i)
}

/// A number: `1`, `-0`, `.5`, `+2.`, `1e-3`, `0xFF`. Values must be finite.
///
/// Decimal text is `[+-]? (digits (. digits*)? | . digits) ([eE] [+-]? digits)?`, read by
/// `fast_float2` (correctly rounded: bit for bit what `str::parse` gives). A hand-written
/// reader (eight digits at a time, with a memo of long quotients) was measured against it on
/// `gtsphere bench parse`'s files, one reader, medians of 5 alternating runs: the crate was
/// 0.98-0.99 of its time on generated and converted particles (8-bit and continuous
/// colours), 0.94 on VTK glyphs and 1.04-1.05 on copies of PyMOL and Jmol exports.
#[inline(always)]
pub fn number(i: &str) -> Result<(&str, Number), NumberProblem> {
    let b = i.as_bytes();
    let k = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    match b.get(k) {
        Some(b'0') if matches!(b.get(k + 1), Some(b'x' | b'X')) => return hex_number(i),
        Some(c) if c.is_ascii_digit() || *c == b'.' => {}
        _ => return Err(NumberProblem::NotANumber),
    }
    let (value, n) =
        fast_float2::parse_partial::<f64, _>(b).map_err(|_| NumberProblem::NotANumber)?;
    // A number must not run straight into an identifier character ("1a", "1e" are not
    // numbers).
    if b.get(n).is_some_and(|&c| is_id_first_byte(c)) {
        return Err(NumberProblem::NotANumber);
    }
    if !value.is_finite() {
        return Err(NumberProblem::OutOfRange);
    }
    let integer = !b[..n].iter().any(|c| matches!(c, b'.' | b'e' | b'E'));
    Ok((&i[n..], Number { value, integer }))
}

/// `[+-]? 0x hexdigits`, an integer.
fn hex_number(i: &str) -> Result<(&str, Number), NumberProblem> {
    let (rest, (sign, digits)) = hex_text(i).map_err(|_| NumberProblem::NotANumber)?;
    let v = u64::from_str_radix(digits, 16).map_err(|_| NumberProblem::OutOfRange)? as f64;
    let value = if sign == Some('-') { -v } else { v };
    Ok((
        rest,
        Number {
            value,
            integer: true,
        },
    ))
}

/// A double-quoted string; `\"` and `\\` are escapes, any other `\c` stands for `c`.
/// Strings may span lines.
pub fn string(i: &str) -> IResult<&str, String> {
    let (body, _) = char('"').parse(i)?;
    let mut out = String::new();
    let b = body.as_bytes();
    let mut k = 0;
    let mut run = 0;
    while k < b.len() {
        match b[k] {
            b'"' => {
                out.push_str(&body[run..k]);
                return Ok((&body[k + 1..], out));
            }
            b'\\' if k + 1 < b.len() => {
                out.push_str(&body[run..k]);
                let c = body[k + 1..].chars().next().unwrap_or('\\');
                out.push(c);
                k += 1 + c.len_utf8();
                run = k;
            }
            _ => k += 1,
        }
    }
    Err(nom::Err::Error(Error::new(i, ErrorKind::Char)))
}

/// One identifier keyword, whole (so `TO` does not match `TOP`).
pub fn keyword<'a>(word: &'static str) -> impl Fn(&'a str) -> IResult<&'a str, &'a str> {
    move |i: &'a str| {
        let (rest, id) = identifier(i)?;
        if id == word {
            Ok((rest, id))
        } else {
            Err(nom::Err::Error(Error::new(i, ErrorKind::Tag)))
        }
    }
}

/// `ROUTE a.b TO c.d` (after `ROUTE`), white space allowed between the tokens.
pub fn route_body(i: &str) -> IResult<&str, (&str, &str, &str, &str)> {
    let (i, from_node) = preceded(ws_p, identifier).parse(i)?;
    let (i, from_field) = preceded((ws_p, char('.'), ws_p), identifier).parse(i)?;
    let (i, _) = preceded(ws_p, keyword("TO")).parse(i)?;
    let (i, to_node) = preceded(ws_p, identifier).parse(i)?;
    let (i, to_field) = preceded((ws_p, char('.'), ws_p), identifier).parse(i)?;
    Ok((i, (from_node, from_field, to_node, to_field)))
}

fn ws_p(i: &str) -> IResult<&str, ()> {
    Ok((ws(i), ()))
}

/// The `#VRML V2.0 utf8` header. Anything after `utf8` on the line is accepted.
pub fn header(i: &str) -> IResult<&str, &str> {
    let (rest, h) = recognize((
        tag("#VRML"),
        take_while1(|c| c == ' ' || c == '\t'),
        tag("V2.0"),
        take_while1(|c| c == ' ' || c == '\t'),
        tag("utf8"),
    ))
    .parse(i)?;
    Ok((rest, h))
}

#[cfg(test)]
mod tests;
