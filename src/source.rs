//! Streaming source text: a window over a decoded UTF-8 stream with absolute byte offsets,
//! a line index for `line:col`, the refill/retry protocol the parser relies on, and [`Pos`],
//! a position in the scene text that may be in another file than the one being read.

use std::io::Read;

use crate::diag::{Diagnostic, Severity};
use std::sync::Arc;

/// Bytes kept ahead of the cursor before each item is parsed, so that any token shorter than
/// this is seen whole. Longer items (huge bracketed lists) are retried with a larger window.
pub const LOOKAHEAD: usize = 64 * 1024;
const CHUNK: usize = 1 << 20;

/// Text kept behind the cursor for diagnostics. A diagnostic shows its line's text (and
/// counts its column in characters) when the line starts at most this far behind the cursor:
/// a rule of the cursor alone, so that it does not depend on how the text was read in (one
/// stream, or pieces read apart and joined with [`SourceWindow::jump`]).
pub const KEEP: u64 = 64 * 1024;

/// A position in the scene text: a byte offset in the file being read, or one *tagged* with
/// the index in `Scene::files` of the file it is in, for positions recorded from a file read
/// for its PROTOs (EXTERNPROTO), whose messages and IR items must point into that file
/// although they are made while another is read.
///
/// One word: the low 44 bits are the byte offset, the 20 above the file's index (0: the file
/// being read), the layout of [`crate::scene::Origin`]. Offsets are ordered within one file.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Pos(u64);

impl Pos {
    /// How many low bits hold the byte offset.
    const OFFSET_BITS: u32 = 44;
    const OFFSET_MASK: u64 = (1 << Self::OFFSET_BITS) - 1;
    const MAX_FILE: u32 = (1 << (64 - Self::OFFSET_BITS)) - 1;

    /// Byte `offset` of the file being read.
    #[inline(always)]
    pub const fn at(offset: u64) -> Pos {
        Pos(offset)
    }

    /// This position, tagged with file `file` (its index in `Scene::files`, never 0; capped
    /// at 2^20 - 1, the offset at 2^44 - 1); a position already tagged keeps its file (it
    /// came from yet another file).
    pub fn tagged(self, file: u32) -> Pos {
        if self.file().is_some() {
            return self;
        }
        Pos(u64::from(file.min(Self::MAX_FILE)) << Self::OFFSET_BITS
            | self.0.min(Self::OFFSET_MASK))
    }

    /// The file a tagged position is in (its index in `Scene::files`); `None`: the file
    /// being read.
    #[inline(always)]
    pub fn file(self) -> Option<u32> {
        let file = (self.0 >> Self::OFFSET_BITS) as u32;
        (file != 0).then_some(file)
    }

    /// The byte offset in its file, tagged or not.
    #[inline(always)]
    pub fn offset(self) -> u64 {
        self.0 & Self::OFFSET_MASK
    }
}

/// The position `bytes` further on, in the same file.
impl std::ops::Add<u64> for Pos {
    type Output = Pos;
    #[inline(always)]
    fn add(self, bytes: u64) -> Pos {
        Pos(self.0 + bytes)
    }
}

impl std::fmt::Debug for Pos {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.file() {
            Some(file) => write!(f, "Pos(file {file}, {})", self.offset()),
            None => write!(f, "Pos({})", self.offset()),
        }
    }
}

/// Byte offsets of line starts, for turning offsets into 1-based line and column.
///
/// Offsets are kept as their low 32 bits (4 bytes a line instead of 8: a million-line file
/// saves 4 MB of peak memory); `spans[k]` is the index of the first line starting at or past
/// `(k + 1) << 32`, so inputs over 4 GiB still get exact positions.
#[derive(Debug, Clone)]
pub struct LineIndex {
    low: Vec<u32>,
    spans: Vec<usize>,
}

impl Default for LineIndex {
    fn default() -> Self {
        LineIndex::new()
    }
}

impl LineIndex {
    /// An index holding only line 1, starting at offset 0.
    pub fn new() -> Self {
        LineIndex {
            low: vec![0],
            spans: Vec::new(),
        }
    }

    /// Records the lines that start after each newline of `text`, which begins at `offset`.
    fn push_newlines(&mut self, offset: u64, text: &[u8]) {
        for nl in memchr::memchr_iter(b'\n', text) {
            self.push(offset + nl as u64 + 1);
        }
    }

    /// Records a line starting at `offset` (offsets must increase).
    #[inline]
    fn push(&mut self, offset: u64) {
        let high = (offset >> 32) as usize;
        while self.spans.len() < high {
            self.spans.push(self.low.len());
        }
        self.low.push(offset as u32);
    }

    /// The start of line `i` (0-based).
    #[inline]
    fn start(&self, i: usize) -> u64 {
        let high = self.spans.partition_point(|&first| first <= i) as u64;
        (high << 32) | u64::from(self.low[i])
    }

    /// 1-based line and 1-based byte column of an absolute offset.
    pub fn line_col(&self, offset: u64) -> (u64, u64) {
        // The last line starting at or before the offset (line 0 starts at 0).
        let (mut lo, mut hi) = (0, self.low.len());
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if self.start(mid) <= offset {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (lo as u64 + 1, offset - self.start(lo) + 1)
    }

    /// Room for `more` lines, if it can be had (a hint: asked for without aborting).
    pub fn try_reserve(&mut self, more: usize) {
        let _ = self.low.try_reserve_exact(more);
    }

    /// The line starts past `offset`, in order.
    pub fn starts_after(&self, offset: u64) -> impl Iterator<Item = u64> + '_ {
        // The first line starting past `offset` follows the one `offset` is on.
        let first = self.line_col(offset).0 as usize;
        (first..self.low.len()).map(|i| self.start(i))
    }
}

/// A window over the source text; `buf[0]` is at absolute offset `base`.
pub struct SourceWindow {
    /// The source's name, as diagnostics print it.
    pub name: Arc<str>,
    reader: Box<dyn Read>,
    /// The text in the window.
    pub buf: String,
    /// Absolute byte offset of `buf[0]` in the source.
    pub base: u64,
    /// The cursor: index into `buf` of the first unread byte.
    pub pos: usize,
    /// Whether the reader is exhausted, so that `buf` ends where the text ends.
    pub eof: bool,
    pending: Vec<u8>,
    /// The line starts seen so far.
    pub lines: LineIndex,
    /// Absolute offset of the first invalid UTF-8 byte, if any (replaced by `?`).
    pub bad_utf8: Option<u64>,
    /// Bytes of text read so far, those skipped by [`Self::jump`] included.
    pub bytes_read: u64,
    /// The end of the text read before the last [`Self::jump`], and its offset.
    held: (u64, String),
}

impl SourceWindow {
    /// A window over the text of `reader`, named `name`, nothing read yet.
    pub fn new(name: Arc<str>, reader: Box<dyn Read>) -> Self {
        SourceWindow {
            name,
            reader,
            buf: String::new(),
            base: 0,
            pos: 0,
            eof: false,
            pending: Vec::new(),
            lines: LineIndex::new(),
            bad_utf8: None,
            bytes_read: 0,
            held: (0, String::new()),
        }
    }

    /// The unread text in the window.
    #[inline]
    pub fn rest(&self) -> &str {
        &self.buf[self.pos..]
    }

    /// Absolute offset of the cursor.
    #[inline]
    pub fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }

    /// Absolute offset of a suffix `rest` of the window.
    #[inline]
    pub fn offset_of(&self, rest: &str) -> u64 {
        self.base + (self.buf.len() - rest.len()) as u64
    }

    /// Moves the cursor to the suffix of the window that is `rest_len` bytes long.
    #[inline]
    pub fn advance_to(&mut self, rest_len: usize) {
        self.pos = self.buf.len() - rest_len;
    }

    /// Makes sure at least `LOOKAHEAD` bytes are ahead of the cursor, or the end of input is in the window.
    #[inline]
    pub fn ensure(&mut self) -> std::io::Result<()> {
        if !self.eof && self.buf.len() - self.pos < LOOKAHEAD {
            self.fill(LOOKAHEAD)?;
        }
        Ok(())
    }

    /// Reads more input so that the window holds at least `want` bytes past the cursor (or to EOF).
    ///
    /// The input is read straight onto the end of the window's text (no chunk buffer copied
    /// in: that copy was 2-3 % of reading), then the text is checked as UTF-8 where it stands.
    pub fn fill(&mut self, want: usize) -> std::io::Result<()> {
        self.compact();
        while !self.eof && self.buf.len() - self.pos < want {
            let size = CHUNK.max(want);
            let mut bytes = std::mem::take(&mut self.buf).into_bytes();
            let start = bytes.len();
            // A character split by the previous read's end comes first.
            bytes.append(&mut self.pending);
            // Room for the whole read at once: grown as it is read, the window was copied at
            // each doubling (a piece's reader starts each piece with a small window).
            bytes.reserve(size);
            let read = (&mut self.reader).take(size as u64).read_to_end(&mut bytes);
            let n = match read {
                Ok(n) => n,
                Err(e) => {
                    // (What was there is the text it was: valid.)
                    bytes.truncate(start);
                    self.buf = String::from_utf8(bytes).unwrap_or_default();
                    return Err(e);
                }
            };
            // Fewer than asked for: the input has ended.
            self.eof = n < size;
            self.bytes_read += n as u64;
            self.buf = self.checked_text(bytes, start);
            let start_abs = self.base + start as u64;
            self.lines
                .push_newlines(start_abs, &self.buf.as_bytes()[start..]);
        }
        Ok(())
    }

    /// `bytes` as text, valid before `start`: each byte of an invalid sequence after it is
    /// replaced by `?` (so byte offsets stay exact), and a character cut off at the end is
    /// kept for the next read (or replaced at the end of the input).
    fn checked_text(&mut self, bytes: Vec<u8>, start: usize) -> String {
        let mut bytes = match String::from_utf8(bytes) {
            Ok(text) => return text,
            Err(e) => e.into_bytes(),
        };
        let mut i = start;
        while let Err(e) = std::str::from_utf8(&bytes[i..]) {
            let at = i + e.valid_up_to();
            let bad = match e.error_len() {
                Some(n) => n,
                None if self.eof => bytes.len() - at,
                None => {
                    self.pending = bytes.split_off(at);
                    break;
                }
            };
            self.bad_utf8.get_or_insert(self.base + at as u64);
            bytes[at..at + bad].fill(b'?');
            i = at + bad;
        }
        // (Valid now: the check above went through to the end.)
        String::from_utf8(bytes).unwrap_or_default()
    }

    /// Doubles what is ahead of the cursor (for items longer than the lookahead). Returns false at EOF.
    pub fn grow(&mut self) -> std::io::Result<bool> {
        if self.eof {
            return Ok(false);
        }
        let want = (self.buf.len() - self.pos).max(LOOKAHEAD) * 2;
        self.fill(want)?;
        Ok(true)
    }

    /// Lines of text read elsewhere, past what was read here (before a [`Self::jump`] over
    /// them).
    pub fn lines_skipped(&mut self, starts: impl IntoIterator<Item = u64>) {
        for l in starts {
            self.lines.push(l);
        }
    }

    /// Continues the text at offset `to` (at or past the end of what was read), from
    /// `reader`: the text in between was read elsewhere (see `vrml::lower::parallel`), and
    /// its lines given to [`Self::lines_skipped`]. Everything read so far must have been
    /// consumed; its last [`KEEP`] bytes stay at hand for diagnostics.
    pub fn jump(&mut self, to: u64, reader: Box<dyn Read>) {
        let end = self.base + self.buf.len() as u64;
        debug_assert!(to >= end && self.pos == self.buf.len() && self.pending.is_empty());
        let mut from = self.buf.len().saturating_sub(KEEP as usize);
        while !self.buf.is_char_boundary(from) {
            from -= 1;
        }
        self.held = (self.base + from as u64, self.buf[from..].to_string());
        self.bytes_read += to - end;
        self.buf.clear();
        self.base = to;
        self.pos = 0;
        self.eof = false;
        self.reader = reader;
    }

    /// As [`Self::jump`], with the whole rest of the text at hand (a piece read elsewhere,
    /// already checked to be UTF-8): it becomes the window as it is, without being read or
    /// copied.
    pub fn jump_to_string(&mut self, to: u64, text: String) {
        self.jump(to, Box::new(std::io::empty()));
        self.bytes_read += text.len() as u64;
        self.lines.push_newlines(to, text.as_bytes());
        self.buf = text;
        self.eof = true;
    }

    /// The text given to [`Self::jump_to_string`] at offset `to`, back, if it is still the
    /// whole window (the window has not moved since); the window is then empty.
    pub fn take_text_back(&mut self, to: u64) -> Option<Vec<u8>> {
        (self.base == to && self.eof).then(|| {
            self.pos = 0;
            std::mem::take(&mut self.buf).into_bytes()
        })
    }

    fn compact(&mut self) {
        if self.pos < CHUNK {
            return;
        }
        // Keep the last KEEP bytes, so that diagnostics can still show their lines.
        let keep_from_abs = self.offset().saturating_sub(KEEP).max(self.base);
        let mut keep = (keep_from_abs - self.base) as usize;
        while !self.buf.is_char_boundary(keep) {
            keep -= 1;
        }
        self.buf.drain(..keep);
        self.base += keep as u64;
        self.pos -= keep;
    }

    /// A diagnostic at an absolute offset of this window's text, with the line's text if it
    /// is still in the window. (A window is one file and knows nothing of [`Pos`] tags: a
    /// tagged position is placed in the window of its own file, by its [`Pos::offset`].)
    pub fn diagnostic(&self, severity: Severity, offset: u64, message: String) -> Diagnostic {
        let (line, byte_col) = self.lines.line_col(offset);
        let line_start = offset + 1 - byte_col;
        let mut col = byte_col;
        let mut snippet = None;
        let kept = line_start.saturating_add(KEEP) >= self.offset();
        let text = if line_start >= self.base && line_start <= self.base + self.buf.len() as u64 {
            Some(&self.buf[..]).zip(usize::try_from(line_start - self.base).ok())
        } else {
            let (base, held) = (self.held.0, &self.held.1);
            (line_start >= base && line_start < base + held.len() as u64)
                .then(|| (&held[..], (line_start - base) as usize))
        };
        if let Some((buf, from)) = text.filter(|_| kept) {
            if buf.is_char_boundary(from) {
                let text = &buf[from..];
                let end = text.find('\n').unwrap_or(text.len());
                let line_text = text[..end].trim_end_matches('\r');
                let upto = ((offset - line_start) as usize).min(line_text.len());
                if line_text.is_char_boundary(upto) {
                    col = line_text[..upto].chars().count() as u64 + 1;
                }
                if line_text.len() <= 300 {
                    snippet = Some(line_text.to_string());
                }
            }
        }
        Diagnostic {
            severity,
            file: self.name.clone(),
            line,
            col,
            message,
            snippet,
            repeats: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{LineIndex, Pos, SourceWindow, CHUNK, LOOKAHEAD};
    use crate::scene::Origin;

    #[test]
    fn tagged_positions_have_the_layout_of_origins() {
        for (file, offset) in [(1, 0), (3, 123_456_789), (Pos::MAX_FILE, Pos::OFFSET_MASK)] {
            let at = Pos::at(offset).tagged(file);
            assert_eq!((at.file(), at.offset()), (Some(file), offset));
            let o = Origin::new(file, offset);
            assert_eq!((o.file(), o.offset()), (file, offset));
        }
        // Untagged positions are in the file being read; a tag is not replaced.
        assert_eq!(Pos::at(12).file(), None);
        assert_eq!(Pos::at(5).tagged(2).tagged(7).file(), Some(2));
        // One word, as the positions recorded in events were.
        assert_eq!(std::mem::size_of::<Pos>(), std::mem::size_of::<u64>());
    }

    /// A reader that gives at most `step` bytes a call.
    struct Dribble(std::io::Cursor<Vec<u8>>, usize);
    impl std::io::Read for Dribble {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let k = buf.len().min(self.1);
            self.0.read(&mut buf[..k])
        }
    }

    /// The text the window should hold: every byte of an invalid sequence a `?`.
    fn replaced(bytes: &[u8]) -> String {
        let mut s = String::new();
        for c in bytes.utf8_chunks() {
            s.push_str(c.valid());
            s.extend(std::iter::repeat_n('?', c.invalid().len()));
        }
        s
    }

    #[test]
    fn characters_and_bad_bytes_across_reads_keep_their_offsets() {
        // Two- to four-byte characters across the reads' ends (1 MiB apart), invalid bytes
        // next to them, a line break in each, and a character cut off by the end of input.
        let mut bytes = Vec::new();
        for (k, tail) in [
            &b"\xc3\xa9"[..],
            "\u{20ac}".as_bytes(),
            "\u{1f600}".as_bytes(),
        ]
        .iter()
        .enumerate()
        {
            let end = (k + 1) * CHUNK;
            bytes.resize(end - 1 - k, b'a');
            bytes.extend_from_slice(tail);
            bytes.extend_from_slice(b"\n\xff\xfe b \xe2\x82 c\n");
        }
        bytes.extend_from_slice(b"end \xf0\x9f\x98");
        let want = replaced(&bytes);
        assert_eq!(want.len(), bytes.len());
        for step in [usize::MAX, 4096, 7] {
            let reader = Dribble(std::io::Cursor::new(bytes.clone()), step);
            let mut w = SourceWindow::new("t.wrl".into(), Box::new(reader));
            let mut got = String::new();
            loop {
                w.fill(LOOKAHEAD).unwrap();
                got.push_str(w.rest());
                w.pos = w.buf.len();
                if w.eof && w.rest().is_empty() {
                    break;
                }
            }
            assert!(got == want, "step {step}");
            assert_eq!(w.bytes_read, bytes.len() as u64);
            let first_bad = bytes.utf8_chunks().next().map(|c| c.valid().len() as u64);
            assert_eq!(w.bad_utf8, first_bad);
            // Every line start, at the offset of the byte after its newline.
            let newlines: Vec<u64> = (0..bytes.len())
                .filter(|&i| bytes[i] == b'\n')
                .map(|i| i as u64 + 1)
                .collect();
            for &l in &newlines {
                assert_eq!(w.lines.line_col(l).1, 1, "line at {l}");
            }
            assert_eq!(
                w.lines.line_col(bytes.len() as u64 - 1).0,
                newlines.len() as u64 + 1
            );
        }
    }

    #[test]
    fn line_index_agrees_with_full_offsets_past_4_gib() {
        let starts: Vec<u64> = vec![
            0,
            5,
            6,
            4_294_967_295,
            4_294_967_296,
            4_294_967_300,
            9_000_000_000,
            13_000_000_000,
        ];
        let mut li = LineIndex::new();
        for &s in &starts[1..] {
            li.push(s);
        }
        let probes = starts.iter().flat_map(|&s| [s, s + 1, s.saturating_sub(1)]);
        for off in probes {
            let i = starts.iter().rposition(|&s| s <= off).unwrap();
            assert_eq!(
                li.line_col(off),
                (i as u64 + 1, off - starts[i] + 1),
                "{off}"
            );
        }
    }
}
