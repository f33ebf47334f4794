//! Typing a parsed value against a field type. The parser reads values without knowing their
//! field (numbers, booleans, strings, `[ ]` or `IS`); once the lowering knows the field, or a
//! PROTO interface declaration gives its type, [`check_value`] says whether the value fits,
//! and its error names the expected type and what was found, for messages such as
//! `field 'translation' of Transform expects SFVec3f (3 number(s) per value), found 2 number(s)`.

use super::FieldType;
use crate::vrml::syntax::Value;

/// What a value is, for messages (`3 number(s)`, `[ ]`, `IS x`).
pub(crate) fn type_name(v: &Value) -> String {
    let (n, what, bracketed) = match v {
        Value::Numbers {
            values, bracketed, ..
        } => (values.len(), "number(s)", *bracketed),
        Value::Bools { values, bracketed } => (values.len(), "boolean(s)", *bracketed),
        Value::Strings { values, bracketed } => (values.len(), "string(s)", *bracketed),
        Value::Empty => return "[ ]".into(),
        Value::Is(n) => return format!("IS {n}"),
    };
    if bracketed {
        format!("[ {n} {what} ]")
    } else {
        format!("{n} {what}")
    }
}

/// Checks a generic value against a field type; the error says what was expected.
///
/// `IS` fits any type (it is checked against the PROTO interface instead), `[ ]` any MF type;
/// a single value without brackets is also an MF value of one element.
#[inline]
pub(crate) fn check_value(ty: FieldType, v: &Value) -> Result<(), String> {
    let ok = match (ty, v) {
        (_, Value::Is(_)) => true,
        (t, Value::Empty) => t.is_mf(),
        (FieldType::SFBool, Value::Bools { values, bracketed }) => values.len() == 1 && !bracketed,
        (FieldType::SFString, Value::Strings { values, bracketed }) => {
            values.len() == 1 && !bracketed
        }
        (FieldType::MFString, Value::Strings { values, bracketed }) => {
            *bracketed || values.len() == 1
        }
        (
            FieldType::SFImage,
            Value::Numbers {
                values, integer, ..
            },
        ) => {
            *integer && values.len() >= 3 && {
                let (w, h) = (values[0], values[1]);
                w >= 0.0 && h >= 0.0 && values.len() as f64 == 3.0 + w * h
            }
        }
        (
            t,
            Value::Numbers {
                values,
                integer,
                bracketed,
            },
        ) => match t.arity() {
            Some(_) if t.is_integer() && !integer => false,
            Some(k) if t.is_mf() => values.len() % k == 0 && (*bracketed || values.len() == k),
            Some(k) => values.len() == k && !bracketed,
            None => false,
        },
        _ => false,
    };
    if ok {
        Ok(())
    } else {
        Err(value_mismatch(ty, v))
    }
}

/// The message of [`check_value`] for a value that does not fit its field's type.
#[cold]
#[inline(never)]
fn value_mismatch(ty: FieldType, v: &Value) -> String {
    let want = match ty.arity() {
        Some(k) if ty.is_integer() => format!("{} ({k} integer(s) per value)", ty.name()),
        Some(k) => format!("{} ({k} number(s) per value)", ty.name()),
        None => ty.name().to_string(),
    };
    // Several values of an MF field without brackets: say what is missing.
    // (Unbracketed strings and booleans are one value each.)
    let unbracketed = match v {
        Value::Numbers {
            values, bracketed, ..
        } => !bracketed && values.len() > ty.arity().unwrap_or(1),
        _ => false,
    };
    let hint = if ty.is_mf() && unbracketed {
        " (more than one value needs [ ])"
    } else {
        ""
    };
    format!("expects {want}, found {}{hint}", type_name(v))
}

#[cfg(test)]
mod tests {
    use super::super::FieldType::*;
    use super::*;

    fn numbers(values: &[f64], integer: bool, bracketed: bool) -> Value<'_> {
        Value::Numbers {
            values,
            integer,
            bracketed,
        }
    }

    #[test]
    fn numbers_fit_by_arity_brackets_and_integrality() {
        let three = [1.0, 2.0, 3.0];
        assert!(check_value(SFVec3f, &numbers(&three, false, false)).is_ok());
        assert!(check_value(SFVec3f, &numbers(&three, false, true)).is_err());
        assert!(check_value(MFFloat, &numbers(&three, false, true)).is_ok());
        // An MF value of one element may be written without brackets, not of three.
        assert!(check_value(MFVec3f, &numbers(&three, false, false)).is_ok());
        assert!(check_value(MFFloat, &numbers(&three, false, false)).is_err());
        assert!(check_value(MFVec2f, &numbers(&three, false, true)).is_err());
        assert!(check_value(SFInt32, &numbers(&[1.5], false, false)).is_err());
        assert!(check_value(SFInt32, &numbers(&[2.0], true, false)).is_ok());
        assert!(check_value(SFFloat, &numbers(&[2.0], true, false)).is_ok());
        // SFImage: width, height, components, then width * height pixels.
        let image = [2.0, 1.0, 3.0, 255.0, 0.0];
        assert!(check_value(SFImage, &numbers(&image, true, false)).is_ok());
        assert!(check_value(SFImage, &numbers(&image[..4], true, false)).is_err());
    }

    #[test]
    fn empty_lists_and_is_fit_where_the_standard_allows() {
        assert!(check_value(MFNode, &Value::Empty).is_ok());
        assert!(check_value(MFString, &Value::Empty).is_ok());
        assert!(check_value(SFVec3f, &Value::Empty).is_err());
        for t in [SFBool, SFNode, MFVec3f, SFImage] {
            assert!(check_value(t, &Value::Is("x")).is_ok(), "{t:?}");
        }
    }

    #[test]
    fn mismatch_messages_name_the_type_and_what_was_found() {
        let two = [1.0, 2.0];
        assert_eq!(
            check_value(SFVec3f, &numbers(&two, false, false)),
            Err("expects SFVec3f (3 number(s) per value), found 2 number(s)".into())
        );
        assert_eq!(
            check_value(SFInt32, &numbers(&[1.5], false, false)),
            Err("expects SFInt32 (1 integer(s) per value), found 1 number(s)".into())
        );
        assert_eq!(
            check_value(
                SFBool,
                &Value::Bools {
                    values: &[true, false],
                    bracketed: true
                }
            ),
            Err("expects SFBool, found [ 2 boolean(s) ]".into())
        );
        // A list where one value goes, several values of a list without brackets.
        assert_eq!(
            check_value(SFVec3f, &numbers(&[1.0, 2.0, 3.0], false, true)),
            Err("expects SFVec3f (3 number(s) per value), found [ 3 number(s) ]".into())
        );
        assert_eq!(
            check_value(MFFloat, &numbers(&two, false, false)),
            Err("expects MFFloat (1 number(s) per value), found 2 number(s) (more than one value needs [ ])".into())
        );
        assert_eq!(
            check_value(SFVec3f, &Value::Empty),
            Err("expects SFVec3f (3 number(s) per value), found [ ]".into())
        );
    }
}
