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

/// Counts events and notes the largest window the parser held.
struct Watch {
    events: usize,
    largest: usize,
}

impl Sink for Watch {
    fn event(&mut self, src: &SourceWindow, _: Event<'_>) -> Result<(), Error> {
        self.events += 1;
        self.largest = self.largest.max(src.buf.capacity());
        Ok(())
    }
}

#[test]
fn long_runs_of_white_space_are_passed_not_held() {
    // 32 MiB of blanks and blank lines between two nodes, then a comment line as long,
    // streamed: the window stays a few reads long, and the node after a comment that spans
    // reads is still one node. (Only the comment line is held, as it is read.)
    let mut text = b"#VRML V2.0 utf8\nGroup { }\n".to_vec();
    for k in 0..(32 << 20) {
        text.push(if k % 1000 == 999 { b'\n' } else { b' ' });
    }
    text.extend_from_slice(b"# ");
    text.resize(text.len() + (1 << 20), b'x');
    text.extend_from_slice(b"\nShape { }\n");
    let src = SourceWindow::new("blank.wrl".into(), Box::new(std::io::Cursor::new(text)));
    let mut parser = Parser::new(src);
    let mut watch = Watch {
        events: 0,
        largest: 0,
    };
    parser.run(&mut watch).unwrap();
    assert_eq!(watch.events, 4);
    assert!(watch.largest <= 4 << 20, "{}", watch.largest);
}
