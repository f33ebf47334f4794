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

/// Deterministic pseudo-random integers below `n`, the same sequence for the same seed.
fn random_below(seed: u64) -> impl FnMut(u64) -> u64 {
    let mut rng = crate::testing::Rng::new(seed);
    move |n| rng.below(n as usize) as u64
}

#[test]
fn generated_numbers_agree_with_std_parse() {
    // Every shape the scanner distinguishes: signs, digit counts around the fast path's
    // limits (19 digits, 2^53, exponent ±22), leading and trailing zeros, exponents.
    let mut next = random_below(0x2545_F491_4F6C_DD1D);
    let mut checked = 0;
    for _ in 0..200_000 {
        let mut t = String::new();
        t.push_str(["", "+", "-"][next(3) as usize]);
        let digit = |d: u64| char::from(b'0' + d as u8);
        for _ in 0..next(24) {
            let d = if next(4) == 0 { 0 } else { next(10) };
            t.push(digit(d));
        }
        if next(3) != 0 {
            t.push('.');
            for _ in 0..next(24) {
                let d = if next(4) == 0 { 0 } else { next(10) };
                t.push(digit(d));
            }
        }
        if next(3) == 0 {
            t.push(if next(2) == 0 { 'e' } else { 'E' });
            t.push_str(["", "+", "-"][next(3) as usize]);
            for _ in 0..1 + next(3) {
                t.push(digit(next(10)));
            }
        }
        let want: Result<f64, _> = t.parse();
        match number(&t) {
            Ok((rest, n)) => {
                assert_eq!(rest, "", "{t}");
                assert_eq!(n.value.to_bits(), want.unwrap().to_bits(), "{t}");
                checked += 1;
            }
            Err(NumberProblem::OutOfRange) => assert!(want.unwrap().is_infinite(), "{t}"),
            Err(NumberProblem::NotANumber) => {
                assert!(
                    !t.bytes().any(|b| b.is_ascii_digit()) || want.is_err(),
                    "{t}"
                )
            }
        }
    }
    assert!(checked > 100_000);
}

#[test]
fn seventeen_to_nineteen_digits_agree_with_std_parse() {
    // Shortest round-trip text of an f64 takes up to 17 digits, whose mantissa is above 2^53;
    // read at the end of the text and before more text. Halfway cases first (2^53 + 1 and 2^52 + 1/2 lie between two f64s), then random ones.
    let mut cases: Vec<String> = [
        "9007199254740993.0",
        "9007199254740995.0",
        "9007199254740993.00",
        "4503599627370496.5",
        "4503599627370497.5",
        "-4503599627370496.50",
        "0.9999999999999999999",
        // 1 - 6e-17 rounds down to 1 - 2^-53, though its f64 estimate is 1: the midpoint
        // below a power of two is a quarter unit away (19 digits with the 0, so that the
        // integer division takes it, not str::parse).
        "0.999999999999999940",
        "-0.999999999999999940",
        "1844674407370955.1615",
        "0.10000000000000000555",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let mut next = random_below(0x51_7CC1_B727_220A);
    for _ in 0..200_000 {
        let digits = 17 + next(3) as usize;
        let point = 1 + next(digits as u64 - 1) as usize;
        let mut t: String = (0..digits)
            .map(|_| char::from(b'0' + next(10) as u8))
            .collect();
        t.insert(point, '.');
        // Shortest texts of random f64s too (17 digits where 16 do not read back).
        let v = f64::from_bits(next(u64::MAX) >> 2) % 1e6;
        cases.push(t);
        cases.push(format!("{v:.17}"));
        // 10^19 against a 55- or 56-bit mantissa leaves the quotient few bits below the last
        // kept one, so that they are often exactly a half with a remainder beyond them.
        let m = 20_000_000_000_000_000 + next(79_999_999_999_999_999);
        cases.push(format!(".00{m}"));
    }
    let mut divided = 0;
    for t in &cases {
        let want: f64 = t.parse().unwrap();
        let (rest, n) = number(t).unwrap();
        assert_eq!(rest, "");
        assert_eq!(n.value.to_bits(), want.to_bits(), "{t}");
        // With text after it.
        let tail = format!("{t} 0.5 0.25 ]");
        let (rest, n) = number(&tail).unwrap();
        assert_eq!(rest, " 0.5 0.25 ]");
        assert_eq!(n.value.to_bits(), want.to_bits(), "{t} (followed)");
        let digits = t.bytes().filter(u8::is_ascii_digit).count();
        divided += usize::from(digits >= 17);
    }
    assert!(divided > 300_000, "{divided}");
    // Again, backwards: nothing read before changes a value.
    for t in cases.iter().rev() {
        let want: f64 = t.parse().unwrap();
        let (_, n) = number(&format!("{t} 1")).unwrap();
        assert_eq!(n.value.to_bits(), want.to_bits(), "{t} (again)");
    }
}

#[test]
fn a_few_long_numbers_read_many_times_agree_with_std_parse() {
    // What `convert` writes for an 8-bit colour table: k/255 in its shortest text (16 to 18
    // digits), each colour many times, in any order; with the same digits and the point
    // moved (the same mantissa over another power of ten).
    let mut texts: Vec<String> = (0..256).map(|k| format!("{}", k as f64 / 255.0)).collect();
    let moved: Vec<String> = texts
        .iter()
        .filter(|t| t.len() > 12)
        .map(|t| format!("{}.{}", &t[2..4], &t[4..]))
        .collect();
    texts.extend(moved);
    let long = texts.iter().filter(|t| t.len() >= 18).count();
    assert!(long > 150, "{long}");
    let mut next = random_below(0x2545_F491_4F6C_DD1D);
    for _ in 0..100_000 {
        let t = &texts[next(texts.len() as u64) as usize];
        let want: f64 = t.parse().unwrap();
        let (_, n) = number(&format!("{t} 0.5 ]")).unwrap();
        assert_eq!(n.value.to_bits(), want.to_bits(), "{t}");
    }
}

/// The grammar's reading of a number, written apart: `[+-]? 0x hexdigits`, or the longest
/// prefix `[+-]? (digits (. digits*)? | . digits) ([eE] [+-]? digits)?` with its value by
/// `str::parse` and an error when an identifier character follows (or no digit was read).
fn reference(t: &str) -> Result<(&str, u64, bool), NumberProblem> {
    let b = t.as_bytes();
    let digits = |mut k: usize| {
        while k < b.len() && b[k].is_ascii_digit() {
            k += 1;
        }
        k
    };
    let start = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    if matches!(b.get(start..start + 2), Some(b"0x" | b"0X")) {
        let mut e = start + 2;
        while e < b.len() && b[e].is_ascii_hexdigit() {
            e += 1;
        }
        if e > start + 2 {
            let v = u64::from_str_radix(&t[start + 2..e], 16).unwrap() as f64;
            let v = if b[0] == b'-' { -v } else { v };
            return Ok((&t[e..], v.to_bits(), true));
        }
    }
    let mut k = digits(start);
    let mut seen = k > start;
    let mut integer = true;
    if b.get(k) == Some(&b'.') {
        let f = digits(k + 1);
        seen |= f > k + 1;
        k = f;
        integer = false;
    }
    if !seen {
        return Err(NumberProblem::NotANumber);
    }
    if matches!(b.get(k), Some(b'e' | b'E')) {
        let s = k + 1 + usize::from(matches!(b.get(k + 1), Some(b'+' | b'-')));
        let e = digits(s);
        if e > s {
            k = e;
            integer = false;
        }
    }
    if b.get(k)
        .is_some_and(|&c| c == b'_' || c.is_ascii_alphabetic() || c >= 0x80)
    {
        return Err(NumberProblem::NotANumber);
    }
    let v: f64 = t[..k].parse().map_err(|_| NumberProblem::NotANumber)?;
    if !v.is_finite() {
        return Err(NumberProblem::OutOfRange);
    }
    Ok((&t[k..], v.to_bits(), integer))
}

#[test]
fn numbers_in_context_agree_with_the_grammar() {
    let mut next = random_below(0x9E37_79B9_7F4A_7C15);
    let tails = [
        "",
        " ",
        "]",
        "}",
        ",",
        " 1 2 3 4 5 6 7 8 9",
        "x  ",
        "e5 ",
        "E-3    ",
        "e+",
        ".5      ",
        "-1      ",
        "\u{e9}       ",
        "#c      ",
        "\n       ",
        "1234567890",
        "0x10     ",
    ];
    let mut read = 0;
    for _ in 0..300_000 {
        let mut t = String::new();
        t.push_str(["", "+", "-"][next(3) as usize]);
        for _ in 0..next(10) {
            t.push(char::from(b'0' + next(10) as u8));
        }
        if next(3) != 0 {
            t.push('.');
            for _ in 0..next(21) {
                t.push(char::from(b'0' + next(10) as u8));
            }
        }
        t.push_str(tails[next(tails.len() as u64) as usize]);
        let got = number(&t).map(|(r, n)| (r, n.value.to_bits(), n.integer));
        assert_eq!(got, reference(&t), "{t:?}");
        read += usize::from(got.is_ok());
    }
    assert!(read > 100_000, "{read}");
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
fn identifier_bytes_agree_with_the_grammar_characters() {
    // Annex A, by characters, as the byte table must implement it.
    fn first(c: char) -> bool {
        !(c <= ' '
            || c.is_ascii_digit()
            || matches!(
                c,
                '"' | '#' | '\'' | '+' | ',' | '-' | '.' | '[' | '\\' | ']' | '{' | '}' | '\x7f'
            ))
    }
    fn rest(c: char) -> bool {
        !(c <= ' '
            || matches!(
                c,
                '"' | '#' | '\'' | ',' | '.' | '[' | '\\' | ']' | '{' | '}' | '\x7f'
            ))
    }
    let chars: Vec<char> = (0u8..128)
        .map(char::from)
        .chain(['\u{80}', '\u{a0}', 'é', 'Ω', '\u{2028}', '😀', '\u{feff}'])
        .collect();
    for &a in &chars {
        for &b in &chars {
            let t = format!("{a}{b}x {b}");
            let want = if first(a) {
                let n = t.char_indices().skip(1).find(|&(_, c)| !rest(c)).unwrap().0;
                Some(&t[..n])
            } else {
                None
            };
            assert_eq!(identifier(&t).ok().map(|r| r.1), want, "{t:?}");
        }
    }
}

#[test]
fn long_identifiers_agree_with_the_byte_table() {
    // The 8-byte letter and digit scan must stop where the byte table does.
    let alphabet: Vec<char> = "aZz09_-+.{ }\t#\u{e9}AmM".chars().collect();
    let mut next = random_below(0x2545_F491_4F6C_DD1D);
    for _ in 0..100_000 {
        let mut t = String::from("x");
        for _ in 0..next(30) {
            t.push(if next(3) == 0 {
                alphabet[next(alphabet.len() as u64) as usize]
            } else {
                char::from(b'a' + next(26) as u8)
            });
        }
        let n = t
            .char_indices()
            .find(|&(_, c)| c.is_ascii() && ID_CLASS[c as usize] & ID_REST == 0)
            .map_or(t.len(), |(k, _)| k);
        assert_eq!(identifier(&t).unwrap(), (&t[n..], &t[..n]), "{t:?}");
    }
    for b in 0..=255u8 {
        let chunk = u64::from_le_bytes([b'a', b'Z', b'5', b, b'q', b'q', b'q', b'q']);
        let want = if b.is_ascii_alphanumeric() { 8 } else { 3 };
        assert_eq!(alnum_run(chunk), want, "{b}");
    }
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
