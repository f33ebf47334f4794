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
#[inline]
pub fn ws(i: &str) -> &str {
    let b = i.as_bytes();
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

/// Characters that may not start an identifier (VRML97 Annex A IdFirstChar).
#[inline]
fn is_id_first(c: char) -> bool {
    !(c <= ' '
        || c.is_ascii_digit()
        || matches!(
            c,
            '"' | '#' | '\'' | '+' | ',' | '-' | '.' | '[' | '\\' | ']' | '{' | '}' | '\x7f'
        ))
}

/// Characters allowed after the first (IdRestChars: digits, `+` and `-` allowed too).
#[inline]
fn is_id_rest(c: char) -> bool {
    !(c <= ' '
        || matches!(
            c,
            '"' | '#' | '\'' | ',' | '.' | '[' | '\\' | ']' | '{' | '}' | '\x7f'
        ))
}

/// An identifier (node type, field, DEF name, keyword).
pub fn identifier(i: &str) -> IResult<&str, &str> {
    let mut chars = i.char_indices();
    match chars.next() {
        Some((_, c)) if is_id_first(c) => {}
        _ => return Err(nom::Err::Error(Error::new(i, ErrorKind::Alpha))),
    }
    let end = chars
        .find(|&(_, c)| !is_id_rest(c))
        .map(|(k, _)| k)
        .unwrap_or(i.len());
    Ok((&i[end..], &i[..end]))
}

/// True when the text starts like a number (`+`, `-`, `.`, or a digit).
#[inline]
pub fn starts_number(i: &str) -> bool {
    matches!(i.as_bytes().first(), Some(b'0'..=b'9' | b'+' | b'-' | b'.'))
}

/// A parsed number and whether it was written as an integer (decimal or hex, no `.` or exponent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Number {
    pub value: f64,
    pub integer: bool,
}

/// Errors of number parsing that deserve their own message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberProblem {
    NotANumber,
    OutOfRange,
}

/// The text of a float: `[+-]? (digits (. digits*)? | . digits) ([eE] [+-]? digits)?`.
fn float_text(i: &str) -> IResult<&str, &str> {
    let b = i.as_bytes();
    let digits = |mut k: usize| {
        let s = k;
        while k < b.len() && b[k].is_ascii_digit() {
            k += 1;
        }
        (k, k - s)
    };
    let mut k = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let (k1, int_digits) = digits(k);
    k = k1;
    let mut frac_digits = 0;
    if b.get(k) == Some(&b'.') {
        let (k2, n) = digits(k + 1);
        k = k2;
        frac_digits = n;
    }
    if int_digits == 0 && frac_digits == 0 {
        return Err(nom::Err::Error(Error::new(i, ErrorKind::Digit)));
    }
    if matches!(b.get(k), Some(b'e' | b'E')) {
        let mut j = k + 1;
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let (j2, n) = digits(j);
        if n > 0 {
            k = j2;
        }
    }
    Ok((&i[k..], &i[..k]))
}

fn hex_text(i: &str) -> IResult<&str, (Option<char>, &str)> {
    (
        opt(one_of("+-")),
        preceded(alt((tag("0x"), tag("0X"))), hex_digit1),
    )
        .parse(i)
}

/// A number: `1`, `-0`, `.5`, `+2.`, `1e-3`, `0xFF`. Values must be finite.
pub fn number(i: &str) -> Result<(&str, Number), NumberProblem> {
    if let Ok((rest, (sign, digits))) = hex_text(i) {
        let v = u64::from_str_radix(digits, 16).map_err(|_| NumberProblem::OutOfRange)?;
        let v = v as f64;
        let value = if sign == Some('-') { -v } else { v };
        return Ok((
            rest,
            Number {
                value,
                integer: true,
            },
        ));
    }
    let (rest, text) = float_text(i).map_err(|_| NumberProblem::NotANumber)?;
    // A number must not run straight into an identifier character ("1a" is not a number).
    if let Some(c) = rest.chars().next() {
        if is_id_first(c) {
            return Err(NumberProblem::NotANumber);
        }
    }
    let integer = !text.contains(['.', 'e', 'E']);
    let value: f64 = text.parse().map_err(|_| NumberProblem::NotANumber)?;
    if !value.is_finite() {
        return Err(NumberProblem::OutOfRange);
    }
    Ok((rest, Number { value, integer }))
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
mod tests {
    use super::*;

    fn num(s: &str) -> Number {
        number(s).unwrap().1
    }

    #[test]
    fn numbers_agree_with_std_parse() {
        for s in [
            "0",
            "-0",
            ".5",
            "+2.",
            "1e-3",
            "1E+3",
            "-1.25e-18",
            "12345678901234567",
            "0.30000000000000004",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(num(s).value.to_bits(), want.to_bits(), "{s}");
        }
        assert!(num("-0").value.is_sign_negative());
        assert!(num("7").integer && !num("7.").integer && !num("7e0").integer);
    }

    #[test]
    fn hex_integers() {
        assert_eq!(
            num("0xFF"),
            Number {
                value: 255.0,
                integer: true
            }
        );
        assert_eq!(num("0Xff").value, 255.0);
        assert_eq!(num("-0x10").value, -16.0);
        assert_eq!(num("0xFFFFFFFF").value, 4294967295.0);
    }

    #[test]
    fn bad_numbers() {
        assert_eq!(number("1e400"), Err(NumberProblem::OutOfRange));
        assert_eq!(number("-1e999"), Err(NumberProblem::OutOfRange));
        assert_eq!(number("."), Err(NumberProblem::NotANumber));
        assert_eq!(number("1abc"), Err(NumberProblem::NotANumber));
        assert_eq!(number("+"), Err(NumberProblem::NotANumber));
    }

    #[test]
    fn number_stops_at_delimiters() {
        assert_eq!(number("1.5]").unwrap().0, "]");
        assert_eq!(number("3,4").unwrap().0, ",4");
        assert_eq!(number("2 x").unwrap().0, " x");
    }

    #[test]
    fn identifiers() {
        assert_eq!(identifier("Transform{").unwrap(), ("{", "Transform"));
        assert_eq!(identifier("FROM-NODE.val").unwrap(), (".val", "FROM-NODE"));
        assert_eq!(identifier("a+b-1 ").unwrap(), (" ", "a+b-1"));
        assert!(identifier("1abc").is_err());
        assert!(identifier("-x").is_err());
        assert_eq!(identifier("Ünïcode x").unwrap().1, "Ünïcode");
    }

    #[test]
    fn strings_with_escapes() {
        assert_eq!(
            string(r#""a\"b\\c" x"#).unwrap(),
            (" x", "a\"b\\c".to_string())
        );
        assert_eq!(string("\"two\nlines\"").unwrap().1, "two\nlines");
        assert!(string("\"unterminated").is_err());
    }

    #[test]
    fn white_space_and_comments() {
        assert_eq!(ws(" ,\t# comment\n ,x"), "x");
        assert_eq!(ws("# only a comment"), "");
    }

    #[test]
    fn header_forms() {
        assert!(header("#VRML V2.0 utf8").is_ok());
        assert!(header("#VRML V2.0 utf8 CosmoWorlds V1.0").is_ok());
        assert!(header("#VRML V1.0 ascii").is_err());
    }

    #[test]
    fn route() {
        let (rest, r) = route_body(" A.b TO C . d rest").unwrap();
        assert_eq!(r, ("A", "b", "C", "d"));
        assert_eq!(rest, " rest");
    }
}
