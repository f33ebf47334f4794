//! The scan itself: brackets, strings and comments byte by byte, the lists they open and
//! close, and the cuts between siblings that make the prefix and the first chunk.

use super::*;

impl Splitter {
    /// The last `k` (at most 3) words before `hold[i]` (nearest first), if the span holds no
    /// string or comment.
    fn words_before(&self, i: usize, k: usize) -> Option<Words<'_>> {
        if self.dirty {
            return None;
        }
        let text = &self.hold[self.span.min(i)..i];
        let mut words = Words {
            words: [&[]; 3],
            len: 0,
        };
        let mut end = text.len();
        while words.len < k.min(3) {
            while end > 0 && is_ws(text[end - 1]) {
                end -= 1;
            }
            let mut start = end;
            while start > 0 && is_word(text[start - 1]) {
                start -= 1;
            }
            if start == end {
                break;
            }
            words.words[words.len] = &text[start..end];
            words.len += 1;
            end = start;
        }
        Some(words)
    }

    pub(super) fn scan(&mut self, out: &mut impl FnMut(Piece)) {
        while self.at < self.hold.len() && self.mode == Mode::Seeking {
            let b = self.hold[self.at];
            match self.lex {
                Lex::String => {
                    match b {
                        b'"' => self.lex = Lex::Code,
                        b'\\' => self.lex = Lex::Escape,
                        _ => {}
                    }
                    self.at += 1;
                    continue;
                }
                Lex::Escape => {
                    self.lex = Lex::String;
                    self.at += 1;
                    continue;
                }
                Lex::Comment => {
                    match memchr::memchr(b'\n', &self.hold[self.at..]) {
                        Some(k) => {
                            self.at += k;
                            self.lex = Lex::Code;
                            if self.clean_comment {
                                self.span = self.at;
                                self.dirty = false;
                            }
                        }
                        None => self.at = self.hold.len(),
                    }
                    continue;
                }
                Lex::Code => {}
            }
            if self.after_close {
                if b == b'\n' {
                    self.after_close = false;
                    self.at += 1;
                    self.cut(self.base + self.at as u64, out);
                    continue;
                }
                if is_ws(b) {
                    self.at += 1;
                    continue;
                }
                // A comment on the line is still on it (the cut follows its end).
                self.after_close = b == b'#';
            }
            if !STRUCTURAL[b as usize] {
                match self.next_structural() {
                    Some(k) => self.at = k,
                    None => {
                        self.at = self.hold.len();
                        continue;
                    }
                }
            }
            let i = self.at;
            self.at += 1;
            match self.hold[i] {
                b'"' => {
                    self.lex = Lex::String;
                    self.dirty = true;
                }
                b'#' => {
                    self.lex = Lex::Comment;
                    self.clean_comment =
                        !self.dirty && self.hold[self.span.min(i)..i].iter().all(|&c| is_ws(c));
                    self.dirty = true;
                }
                b'{' => self.open_brace(i, out),
                b'[' => self.open_bracket(i, out),
                b'}' => self.close(false, out),
                b']' => self.close(true, out),
                _ => unreachable!(),
            }
            if self.lex == Lex::Code {
                self.span = self.at;
                self.dirty = false;
            }
        }
    }

    fn open_brace(&mut self, i: usize, out: &mut impl FnMut(Piece)) {
        if self.stack.is_empty() && self.proto == Proto::AfterInterface {
            self.proto = Proto::Body;
            self.stack.push(Frame {
                list: false,
                split: false,
                first_cut: None,
            });
            return;
        }
        let parent_split = match self.stack.last() {
            None => true,
            Some(f) => f.list && f.split,
        };
        let split = parent_split
            && !self.grouping_shadowed
            && self.words_before(i, 3).is_some_and(|w| {
                w.first()
                    .is_some_and(|ty| GROUPING.iter().any(|g| g.as_bytes() == *ty))
                    && w.get(2).is_none_or(|d| *d != b"DEF")
            });
        if self.stack.is_empty() && self.proto != Proto::None {
            // Not a VRML97 statement: leave it to the parser to say so.
            self.give_up(out);
            return;
        }
        self.stack.push(Frame {
            list: false,
            split,
            first_cut: None,
        });
    }

    fn open_bracket(&mut self, i: usize, out: &mut impl FnMut(Piece)) {
        if self.stack.is_empty() {
            // Only a PROTO or EXTERNPROTO interface opens with `[` at the top level.
            let words = self.words_before(i, 2);
            let keyword = words.as_ref().and_then(|w| w.get(1).copied());
            if keyword != Some(b"PROTO") || self.proto != Proto::None {
                self.give_up(out);
                return;
            }
            let name = words
                .as_ref()
                .and_then(|w| w.first().copied())
                .unwrap_or(b"");
            self.grouping_shadowed |= GROUPING.iter().any(|g| g.as_bytes() == name);
            self.proto = Proto::Interface;
            // A region starts after the PROTOs it may instance.
            self.top_first_cut = None;
            self.stack.push(Frame {
                list: true,
                split: false,
                first_cut: None,
            });
            return;
        }
        let parent = *self.stack.last().expect("not the top level");
        let split = !parent.list
            && parent.split
            && self
                .words_before(i, 1)
                .is_some_and(|w| w.first().is_some_and(|f| *f == b"children"));
        self.stack.push(Frame {
            list: true,
            split,
            first_cut: None,
        });
    }

    fn close(&mut self, list: bool, out: &mut impl FnMut(Piece)) {
        let Some(f) = self.stack.pop() else {
            // Unbalanced: leave it to the parser to say so.
            self.give_up(out);
            return;
        };
        if f.list != list {
            self.give_up(out);
            return;
        }
        if self.stack.is_empty() {
            match self.proto {
                Proto::Interface if list => {
                    self.proto = Proto::AfterInterface;
                    return;
                }
                Proto::Body if !list => self.proto = Proto::None,
                Proto::None => {}
                _ => {
                    self.give_up(out);
                    return;
                }
            }
        }
        // A sibling in a list that may be the region ends: its line's end is a cut.
        if !list && self.stack.last().is_none_or(|p| p.list && p.split) {
            self.after_close = true;
        }
    }

    /// A cut at offset `c` in the innermost list (while seeking the region: after it, the
    /// scan stops).
    fn cut(&mut self, c: u64, out: &mut impl FnMut(Piece)) {
        if self.mode != Mode::Seeking {
            return;
        }
        let first = match self.stack.last_mut() {
            None => &mut self.top_first_cut,
            Some(f) => &mut f.first_cut,
        };
        let Some(start) = *first else {
            *first = Some(c);
            return;
        };
        // Once the list holds `prefix_max` of siblings, no list after it can be the region
        // (its prefix would be too long), nor can an enclosing list that has no cut yet (its
        // first would come after this one). So unless an enclosing list has a cut (it may
        // hold far more siblings after this list's node), the list is taken then, and the
        // other threads start after a short scan; else it needs a chunk's worth.
        let enclosing_cut = self.stack.split_last().is_some_and(|(_, up)| {
            self.top_first_cut.is_some() || up.iter().any(|f| f.list && f.first_cut.is_some())
        });
        let enough = if enclosing_cut {
            self.chunk_bytes
        } else {
            self.chunk_bytes.min(self.prefix_max)
        };
        if c - start < enough || start > self.prefix_max {
            return;
        }
        // The region starts: the prefix goes to the main reader and to the chunks'.
        let prefix = self.split_off_prefix(start);
        out(Piece::Prefix(Arc::from(&prefix[..])));
        out(Piece::Text(prefix));
        self.mode = Mode::Region;
        self.sibling = sibling_mark(&self.hold);
        self.chunk(c, out);
        self.at = 0;
    }
}
