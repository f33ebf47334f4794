use super::*;

#[test]
fn plain_words_are_no_keywords() {
    // Every word the item parsers compare names against must fail `plain_word`.
    let mut words: Vec<String> = SPECIAL_WORDS.iter().map(|w| w.to_string()).collect();
    for w in ["nan", "inf", "infinity"] {
        for mask in 0..1u32 << w.len() {
            let v = w
                .chars()
                .enumerate()
                .map(|(k, c)| {
                    if mask & 1 << k != 0 {
                        c.to_ascii_uppercase()
                    } else {
                        c
                    }
                })
                .collect();
            words.push(v);
        }
    }
    for w in &words {
        assert!(!plain_word(w), "{w}");
    }
    for w in words.iter().filter(|w| !is_nan_word(w)) {
        assert!(is_reserved(w), "{w}");
    }
    for w in [
        "Group",
        "Shape",
        "translation",
        "children",
        "radius",
        "diffuseColor",
    ] {
        assert!(plain_word(w), "{w}");
    }
    assert!(!plain_word(""));
}
