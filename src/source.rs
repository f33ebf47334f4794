//! Streaming source text: a window over a decoded UTF-8 stream with absolute byte offsets,
//! a line index for `line:col`, and the refill/retry protocol the parser relies on.

use std::io::Read;

use crate::diag::{Diagnostic, Severity};
use std::sync::Arc;

/// Bytes kept ahead of the cursor before each item is parsed, so that any token shorter than
/// this is seen whole. Longer items (huge bracketed lists) are retried with a larger window.
pub const LOOKAHEAD: usize = 64 * 1024;
const CHUNK: usize = 1 << 20;

/// Byte offsets of line starts, for turning offsets into 1-based line and column.
#[derive(Debug, Default, Clone)]
pub struct LineIndex {
    starts: Vec<u64>,
}

impl LineIndex {
    pub fn new() -> Self {
        LineIndex { starts: vec![0] }
    }
    /// 1-based line and 1-based byte column of an absolute offset.
    pub fn line_col(&self, offset: u64) -> (u64, u64) {
        let i = match self.starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        (i as u64 + 1, offset - self.starts[i] + 1)
    }
    pub fn line_start(&self, offset: u64) -> u64 {
        let (line, col) = self.line_col(offset);
        let _ = line;
        offset + 1 - col
    }
    pub fn heap_bytes(&self) -> usize {
        self.starts.capacity() * 8
    }
}

/// A window over the source text; `buf[0]` is at absolute offset `base`.
pub struct SourceWindow {
    pub name: Arc<str>,
    reader: Box<dyn Read>,
    pub buf: String,
    pub base: u64,
    pub pos: usize,
    pub eof: bool,
    pending: Vec<u8>,
    /// Read buffer, reused for every chunk.
    chunk: Vec<u8>,
    pub lines: LineIndex,
    /// Absolute offset of the first invalid UTF-8 byte, if any (replaced by `?`).
    pub bad_utf8: Option<u64>,
    pub bytes_read: u64,
}

impl SourceWindow {
    pub fn new(name: Arc<str>, reader: Box<dyn Read>) -> Self {
        SourceWindow {
            name,
            reader,
            buf: String::new(),
            base: 0,
            pos: 0,
            eof: false,
            pending: Vec::new(),
            chunk: Vec::new(),
            lines: LineIndex::new(),
            bad_utf8: None,
            bytes_read: 0,
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
    pub fn fill(&mut self, want: usize) -> std::io::Result<()> {
        self.compact();
        while !self.eof && self.buf.len() - self.pos < want {
            let mut chunk = std::mem::take(&mut self.chunk);
            let size = CHUNK.max(want);
            if chunk.len() < size {
                chunk.resize(size, 0);
            }
            let mut n = 0;
            while n < size {
                match self.reader.read(&mut chunk[n..size]) {
                    Ok(0) => {
                        self.eof = true;
                        break;
                    }
                    Ok(k) => n += k,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(e) => return Err(e),
                }
            }
            self.append_bytes(&chunk[..n]);
            // Keep the buffer for the next chunk, unless an oversized item needed a big one.
            if chunk.len() <= CHUNK {
                self.chunk = chunk;
            }
        }
        Ok(())
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

    fn compact(&mut self) {
        if self.pos < CHUNK {
            return;
        }
        // Keep the current line's start (up to 2 KiB back) so diagnostics can still show it.
        let abs = self.offset();
        let line_start = self.lines.line_start(abs);
        let keep_from_abs = line_start.max(abs.saturating_sub(2048)).max(self.base);
        let mut keep = (keep_from_abs - self.base) as usize;
        while !self.buf.is_char_boundary(keep) {
            keep -= 1;
        }
        self.buf.drain(..keep);
        self.base += keep as u64;
        self.pos -= keep;
    }

    fn append_bytes(&mut self, bytes: &[u8]) {
        self.bytes_read += bytes.len() as u64;
        let joined;
        let bytes = if self.pending.is_empty() {
            bytes
        } else {
            // A character split by the previous chunk's end.
            let mut p = std::mem::take(&mut self.pending);
            p.extend_from_slice(bytes);
            joined = p;
            &joined[..]
        };
        let start_abs = self.base + self.buf.len() as u64;
        let mut i = 0;
        loop {
            match std::str::from_utf8(&bytes[i..]) {
                Ok(s) => {
                    self.buf.push_str(s);
                    break;
                }
                Err(e) => {
                    let good = e.valid_up_to();
                    // SAFETY-free: the prefix is valid UTF-8 by from_utf8's word.
                    self.buf
                        .push_str(std::str::from_utf8(&bytes[i..i + good]).unwrap_or(""));
                    i += good;
                    match e.error_len() {
                        Some(n) => {
                            // Replace each invalid byte by '?' so byte offsets stay exact.
                            let at = self.base + self.buf.len() as u64;
                            self.bad_utf8.get_or_insert(at);
                            for _ in 0..n {
                                self.buf.push('?');
                            }
                            i += n;
                        }
                        None => {
                            if self.eof {
                                let at = self.base + self.buf.len() as u64;
                                self.bad_utf8.get_or_insert(at);
                                for _ in i..bytes.len() {
                                    self.buf.push('?');
                                }
                            } else {
                                self.pending = bytes[i..].to_vec();
                            }
                            break;
                        }
                    }
                }
            }
        }
        let new_start = (start_abs - self.base) as usize;
        for nl in memchr::memchr_iter(b'\n', &self.buf.as_bytes()[new_start..]) {
            self.lines.starts.push(start_abs + nl as u64 + 1);
        }
    }

    /// A diagnostic at an absolute offset, with the line's text if it is still in the window.
    pub fn diagnostic(&self, severity: Severity, offset: u64, message: String) -> Diagnostic {
        let (line, byte_col) = self.lines.line_col(offset);
        let line_start = offset + 1 - byte_col;
        let mut col = byte_col;
        let mut snippet = None;
        if line_start >= self.base && line_start <= self.base + self.buf.len() as u64 {
            let from = (line_start - self.base) as usize;
            if self.buf.is_char_boundary(from) {
                let text = &self.buf[from..];
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
