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
use std::cell::Cell;

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
    pub value: f64,
    pub integer: bool,
}

/// Errors of number parsing that deserve their own message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberProblem {
    NotANumber,
    OutOfRange,
}

fn hex_text(i: &str) -> IResult<&str, (Option<char>, &str)> {
    (
        opt(one_of("+-")),
        preceded(alt((tag("0x"), tag("0X"))), hex_digit1),
    )
        .parse(i)
}

/// Powers of ten that are exact in f64 (10^22 is the largest).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A number: `1`, `-0`, `.5`, `+2.`, `1e-3`, `0xFF`. Values must be finite.
///
/// Decimal text is `[+-]? (digits (. digits*)? | . digits) ([eE] [+-]? digits)?`. Values with at
/// most 19 digits, a mantissa below 2^53 and a decimal exponent within ±22 are computed
/// exactly by one IEEE multiplication or division (Clinger's fast path: both operands are
/// exact, so the one rounding is the correct one and the result is bit for bit what
/// `str::parse` gives); everything else goes to `str::parse`.
#[inline(always)]
pub fn number(i: &str) -> Result<(&str, Number), NumberProblem> {
    if let Some((k, n)) = short_decimal(i.as_bytes()) {
        return Ok((&i[k..], n));
    }
    number_general(i)
}

/// Digits of up to 8 bytes at `b[k..]`, 8 at a time (SWAR): how many of the (at most 8) bytes
/// are digits before the first non-digit, and their value. None when fewer than 8 bytes are
/// left (the caller then takes the general path).
#[inline(always)]
fn digit_run(b: &[u8], k: usize) -> Option<(usize, u64)> {
    let bytes: [u8; 8] = b.get(k..k + 8)?.try_into().ok()?;
    let chunk = u64::from_le_bytes(bytes);
    // Per byte: high bit set when it is not an ASCII digit (no carries between bytes).
    let t = chunk ^ 0x3030_3030_3030_3030;
    let not_digit =
        (((t & 0x7F7F_7F7F_7F7F_7F7F) + 0x7676_7676_7676_7676) | t) & 0x8080_8080_8080_8080;
    let n = (not_digit.trailing_zeros() / 8) as usize;
    // Shift the n digits to the top and fill the bottom with '0's: "00012345" reads 12345.
    // No branch on n (a run's length is random, as where a colour's 16 to 18 fraction digits
    // end): the shifts are of 128 bits, so that shifting by 64 (n = 0 or 8) leaves zero.
    let s = 64 - 8 * n as u32;
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let digits = ((u128::from(chunk) << s) as u64) | ((u128::from(ZEROS) >> (8 * n)) as u64);
    // Eight ASCII digits to their value, first byte most significant (Lemire's method).
    let mut v = digits.wrapping_sub(0x3030_3030_3030_3030);
    v = v.wrapping_mul(10).wrapping_add(v >> 8);
    v = ((v & 0x0000_00FF_0000_00FF)
        .wrapping_mul(0x000F_4240_0000_0064)
        .wrapping_add(((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(0x0000_2710_0000_0001)))
        >> 32;
    Some((n, v))
}

/// The common number shape, `[+-]? digits (. digits)?` with fewer than 8 digits before the
/// point and 19 in all, no exponent, read without a byte loop (`convert` writes the colours
/// of 8-bit tables with 16 to 18 fraction digits, their shortest round-trip text). Returns
/// where it ends and its value, or None for anything else (which [`number_general`] then
/// reads, with the same result for these).
#[inline(always)]
fn short_decimal(b: &[u8]) -> Option<(usize, Number)> {
    let signed = matches!(b.first(), Some(b'+' | b'-'));
    let mut k = usize::from(signed);
    let (n1, int) = digit_run(b, k)?;
    if n1 == 0 || n1 == 8 {
        return None;
    }
    k += n1;
    let mut integer = true;
    let mut mantissa = int;
    let mut frac = 0;
    if b[k] == b'.' {
        integer = false;
        k += 1;
        let (n2, f) = digit_run(b, k)?;
        k += n2;
        frac = n2;
        mantissa = int * POW10_INT[n2] + f;
        // While a run of 8 was whole, up to 8 more, at most 19 digits in all (below 2^64).
        let mut run = n2;
        while run == 8 {
            let (n, g) = digit_run(b, k)?;
            if n1 + frac + n > 19 {
                return None;
            }
            k += n;
            frac += n;
            mantissa = mantissa * POW10_INT[n] + g;
            run = n;
        }
    }
    // The next byte must end the number: not a digit (after 19 digits in all) nor an
    // identifier character (which takes in an exponent `e`, hex `x` and errors like "1a"),
    // so the general path agrees.
    match b.get(k) {
        Some(&c) if !c.is_ascii_digit() && !is_id_first_byte(c) => {}
        _ => return None,
    }
    // A mantissa of at most 2^53 and the power of ten (at most 10^19, exact up to 10^22) are
    // exact, so the one division is correctly rounded, as in number_general; a larger one
    // (17 to 19 digits: the shortest text of most f64s) is divided in integers, as there.
    // (Converted through i64, which x86-64 does in one instruction; the value is exact.)
    let v = if mantissa <= 1 << 53 {
        mantissa as i64 as f64 / POW10[frac]
    } else {
        recent_quotient(mantissa, frac as u32)
    };
    // The sign as a bit, not a branch (coordinates' signs are random); `-` of 0 is -0.0.
    let value = f64::from_bits(v.to_bits() | (u64::from(b[0] == b'-') << 63));
    Some((k, Number { value, integer }))
}

/// 10^0 to 10^19, every power of ten a u64 holds.
const POW10_INT: [u64; 20] = {
    let mut t = [1u64; 20];
    let mut k = 1;
    while k < 20 {
        t[k] = t[k - 1] * 10;
        k += 1;
    }
    t
};

/// [`number`] for every form: hex, exponents, long digit strings, numbers at the end of the
/// text.
fn number_general(i: &str) -> Result<(&str, Number), NumberProblem> {
    let b = i.as_bytes();
    let signed = matches!(b.first(), Some(b'+' | b'-'));
    let mut k = usize::from(signed);
    if b.get(k) == Some(&b'0') && matches!(b.get(k + 1), Some(b'x' | b'X')) {
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
    }
    let mut mantissa: u64 = 0;
    let mut digits = 0usize;
    let int_start = k;
    while k < b.len() && b[k].is_ascii_digit() {
        mantissa = mantissa
            .wrapping_mul(10)
            .wrapping_add(u64::from(b[k] - b'0'));
        k += 1;
    }
    let int_digits = k - int_start;
    digits += int_digits;
    let mut frac_digits = 0;
    let mut integer = true;
    if b.get(k) == Some(&b'.') {
        integer = false;
        k += 1;
        let s = k;
        while k < b.len() && b[k].is_ascii_digit() {
            mantissa = mantissa
                .wrapping_mul(10)
                .wrapping_add(u64::from(b[k] - b'0'));
            k += 1;
        }
        frac_digits = k - s;
        digits += frac_digits;
    }
    if int_digits == 0 && frac_digits == 0 {
        return Err(NumberProblem::NotANumber);
    }
    let mut exp: i64 = 0;
    if matches!(b.get(k), Some(b'e' | b'E')) {
        let mut j = k + 1;
        let neg = b.get(j) == Some(&b'-');
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let s = j;
        while j < b.len() && b[j].is_ascii_digit() {
            exp = exp
                .saturating_mul(10)
                .saturating_add(i64::from(b[j] - b'0'));
            j += 1;
        }
        if j > s {
            k = j;
            integer = false;
            if neg {
                exp = -exp;
            }
        }
    }
    let (text, rest) = i.split_at(k);
    // A number must not run straight into an identifier character ("1a" is not a number).
    if let Some(&c) = rest.as_bytes().first() {
        if is_id_first_byte(c) {
            return Err(NumberProblem::NotANumber);
        }
    }
    let exp10 = exp.saturating_sub(frac_digits as i64);
    let exact = digits <= 19 && mantissa <= 1 << 53 && (-22..=22).contains(&exp10);
    let value = if exact || (digits <= 19 && (-19..0).contains(&exp10)) {
        let v = if exact {
            let m = mantissa as f64;
            if exp10 < 0 {
                m / POW10[exp10.unsigned_abs() as usize]
            } else {
                m * POW10[exp10 as usize]
            }
        } else {
            // 17 to 19 significant digits (shortest round-trip text needs up to 17).
            divide_by_power_of_ten(mantissa, exp10.unsigned_abs() as u32)
        };
        if b[0] == b'-' {
            -v
        } else {
            v
        }
    } else {
        text.parse::<f64>().map_err(|_| NumberProblem::NotANumber)?
    };
    if !value.is_finite() {
        return Err(NumberProblem::OutOfRange);
    }
    Ok((rest, Number { value, integer }))
}

/// Slots of [`RECENT_QUOTIENTS`].
const QUOTIENT_SLOTS: usize = 256;

thread_local! {
    /// The last mantissa and power of ten [`divide_by_power_of_ten`] was given in each slot,
    /// and its value: a file's long numbers are often few distinct ones (`convert` writes an
    /// 8-bit table's colours as their 16 to 18 digit shortest text), each read a million
    /// times. (Mantissas here are above 2^53, so the zero of an empty slot never matches.)
    static RECENT_QUOTIENTS: [Cell<(u64, u32, f64)>; QUOTIENT_SLOTS] =
        const { [const { Cell::new((0, 0, 0.0)) }; QUOTIENT_SLOTS] };
}

/// [`divide_by_power_of_ten`], remembered: a slot's value is the one computed for its
/// mantissa and power, so the result is the same bit for bit.
#[inline]
fn recent_quotient(m: u64, k: u32) -> f64 {
    let slot = (m.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 56) as usize ^ k as usize;
    RECENT_QUOTIENTS.with(|r| {
        let c = &r[slot % QUOTIENT_SLOTS];
        let (cm, ck, v) = c.get();
        if cm == m && ck == k {
            return v;
        }
        let v = divide_by_power_of_ten(m, k);
        c.set((m, k, v));
        v
    })
}

/// `m / 10^k` correctly rounded (to nearest, ties to even), for `m > 2^53` and `1 <= k <= 19`
/// (where one f64 division would round twice). The f64 quotient of `m` rounded is within two
/// units in the last place of the true one (two roundings of at most half a unit each); it
/// is then moved a unit at a time while the true quotient lies beyond the midpoint to a
/// neighbour, each side compared exactly in integers (products below 2^119). No integer
/// division: the 128-bit one it replaced was a library call of about 40 cycles.
fn divide_by_power_of_ten(m: u64, k: u32) -> f64 {
    debug_assert!(m > 1 << 53 && (1..=19).contains(&k));
    let d = u128::from(POW10_INT[k as usize]);
    let mut x = m as f64 / POW10[k as usize];
    loop {
        // x = mant * 2^e, normal (m / 10^k lies between 2^-11 and 2^64).
        let bits = x.to_bits();
        let e = (bits >> 52) as i32 - 1075;
        let mant = bits & ((1 << 52) - 1) | 1 << 52;
        // m / 10^k against (c / 4) * 2^e, both scaled by 4 * 10^k * 2^-e.
        let (left, right_shift) = if e <= 2 {
            (u128::from(m) << (2 - e), 0)
        } else {
            (u128::from(m), e - 2)
        };
        let right = |c: u64| (u128::from(c) * d) << right_shift;
        let odd = mant & 1 == 1;
        // The midpoint above (ties go to the even neighbour).
        let above = right(4 * mant + 2);
        if left > above || (left == above && odd) {
            x = f64::from_bits(bits + 1);
            continue;
        }
        // The midpoint below: a quarter unit below a power of two, whose neighbour below is
        // half a unit away.
        let below = right(if mant == 1 << 52 {
            4 * mant - 1
        } else {
            4 * mant - 2
        });
        if left < below || (left == below && odd) {
            x = f64::from_bits(bits - 1);
            continue;
        }
        return x;
    }
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
