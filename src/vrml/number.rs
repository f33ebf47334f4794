//! How a number is written into VRML text: one rule for every writer (`convert` of a scene,
//! [`super::write`], and of a particle table, [`crate::particles::write`]).
//!
//! The rule: the fewest significant digits that read back as the same f64, bit for bit
//! (ryu's shortest round-trip digits; Rust's `{}` finds as many, and the same ones except
//! where the exact value lies halfway between two shortest candidates, 890114082626052.25:
//! ryu writes `.2`, `{}` `.3`, and both read back exactly), in ryu's layout:
//! positional for `1e-5 <= |v| < 1e16` (`0.1`, `123456789.125`, `0.00001`), scientific
//! outside (`1e-6`, `1e300`, `1.5e20`), and integers without ryu's trailing `.0` (`3`, `-0`).
//! Every result is a VRML97 float; `-0` keeps the sign of zero. Rust's `{}` never writes an
//! exponent, so it takes 302 characters for 1e-300 (the scene writer used it before).
//!
//! Numbers a particle table gave as text are not formatted at all: the table writer echoes
//! that text (it reads back as the same f64, as it was read from it).

use std::fmt;

/// `v` by the rule above, in `buf`. Finite values only make sense in VRML; NaN and infinities
/// come out as ryu writes them (`NaN`, `inf`), which no VRML reader accepts.
pub fn format(buf: &mut ryu::Buffer, v: f64) -> &str {
    let s = buf.format(v);
    s.strip_suffix(".0").unwrap_or(s)
}

/// `v` by the rule above, for `format!` and `write!`.
#[derive(Clone, Copy, Debug)]
pub struct Float(pub f64);

impl fmt::Display for Float {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(format(&mut ryu::Buffer::new(), self.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;
    use crate::vrml::lex::number;

    fn text(v: f64) -> String {
        Float(v).to_string()
    }

    #[test]
    fn the_layout_of_the_rule() {
        for (v, want) in [
            (0.1, "0.1"),
            (3.0, "3"),
            (-0.0, "-0"),
            (0.0, "0"),
            (123456789.125, "123456789.125"),
            (1e15, "1000000000000000"),
            (1e16, "1e16"),
            (1.5e20, "1.5e20"),
            (1e-5, "0.00001"),
            (1e-6, "1e-6"),
            (1e-7, "1e-7"),
            (1e-300, "1e-300"),
            (1e300, "1e300"),
            (f64::MAX, "1.7976931348623157e308"),
            (5e-324, "5e-324"),
        ] {
            assert_eq!(text(v), want);
        }
    }

    /// Random bit patterns (every exponent, subnormals included) read back through the VRML
    /// reader as the same f64, in as few significant digits as Rust's `{}` (an independent
    /// shortest round-trip formatter) takes.
    #[test]
    fn random_f64_read_back_bit_for_bit() {
        let mut rng = Rng::new(13);
        let mut checked = 0;
        for _ in 0..200_000 {
            let v = f64::from_bits(rng.u64());
            if !v.is_finite() {
                continue;
            }
            let t = text(v);
            let (rest, n) = number(&t).unwrap_or_else(|_| panic!("{t} is not a VRML number"));
            assert_eq!(rest, "", "{t}");
            assert_eq!(n.value.to_bits(), v.to_bits(), "{t}");
            let digits = |s: &str| -> String {
                let mantissa = s.split('e').next().unwrap_or("");
                let d: String = mantissa.chars().filter(char::is_ascii_digit).collect();
                d.trim_matches('0').to_string()
            };
            assert_eq!(
                digits(&t).len(),
                digits(&format!("{v}")).len(),
                "{t} against {v}"
            );
            checked += 1;
        }
        assert!(checked > 190_000);
    }
}
