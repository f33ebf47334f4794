//! Cutting the rest of a region in the file itself (a plain file read in pieces, see
//! `lower::parallel`): once the scan has found the region, the text need not pass through
//! it. Each cut is looked for in a small window read at the offset where it is due, and each
//! chunk's reader reads its own bytes from the file, straight into its own (cache-resident)
//! window, rather than the scan reading everything into large buffers for the readers to
//! read again from memory written on another core.
//!
//! The cuts are those [`crate::vrml::split::Splitter::cut_ahead`] makes from the whole text:
//! the first line after `chunk_bytes` (from the chunk's start) that starts with the region's
//! first sibling's mark, whole; with none within `8 * chunk_bytes`, the last line start seen.

use crate::vrml::split::{is_word, Piece, RegionAt};

/// Bytes read at a time to look for a cut.
const WINDOW: usize = 64 << 10;

/// Reads up to `buf.len()` bytes at `offset`, fewer only at the end of the file.
pub type ReadAt<'a> = dyn FnMut(&mut [u8], u64) -> std::io::Result<usize> + 'a;

fn read_full(read_at: &mut ReadAt, buf: &mut [u8], offset: u64) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match read_at(&mut buf[n..], offset + n as u64) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// The offset where the file ends, read from `from` on (which is at or before it).
fn end_of_file(read_at: &mut ReadAt, buf: &mut [u8], mut from: u64) -> std::io::Result<u64> {
    loop {
        let n = read_full(read_at, buf, from)?;
        from += n as u64;
        if n < buf.len() {
            return Ok(from);
        }
    }
}

/// Hands on the rest of the region from `at` as [`Piece::Range`]s, then
/// [`Piece::RegionEnd`] at the end of the file (the region, as the chunks' checks will tell,
/// ends somewhere in the last chunks, as when the text is cut in memory). `out` returns false
/// to stop.
pub fn cut_in_file(
    at: RegionAt,
    read_at: &mut ReadAt,
    chunk_bytes: u64,
    out: &mut dyn FnMut(Piece) -> bool,
) -> std::io::Result<()> {
    cut_with_window(at, read_at, (chunk_bytes, WINDOW), out)
}

/// [`cut_in_file`], reading `window` bytes at a time.
fn cut_with_window(
    at: RegionAt,
    read_at: &mut ReadAt,
    (chunk_bytes, window): (u64, usize),
    out: &mut dyn FnMut(Piece) -> bool,
) -> std::io::Result<()> {
    let mark = &at.sibling[..];
    let want = chunk_bytes.max(1);
    let cap = 8 * want.max(1 << 20);
    let mut buf = vec![0u8; window.max(2 * mark.len())];
    let (mut base, mut chunks) = (at.base, at.chunks);
    loop {
        // Where the next cut is, or the file's end (no cut: the rest is the last chunk).
        let mut from = base + want - 1;
        let mut last_line = None;
        let (end, last) = loop {
            let n = read_full(read_at, &mut buf, from)?;
            let text = &buf[..n];
            let mut found = None;
            let mut i = 0;
            while let Some(k) = memchr::memmem::find(&text[i..], mark) {
                let m = i + k;
                match text.get(m + mark.len()) {
                    // The line's word goes on: not a sibling's start.
                    Some(&b) if mark.len() > 1 && is_word(b) => i = m + 1,
                    Some(_) => {
                        found = Some(from + m as u64 + 1);
                        break;
                    }
                    // At the window's end: read again from the mark. At the file's end: the
                    // word may be the whole rest, and no cut is made there.
                    None => break,
                }
            }
            if let Some(c) = found {
                break (c, false);
            }
            if n == 0 && from > base {
                // Past the end: the rest is shorter than a chunk; where does it end?
                break (end_of_file(read_at, &mut buf, base)?, true);
            }
            if n < buf.len() {
                break (from + n as u64, true);
            }
            if let Some(k) = memchr::memrchr(b'\n', text) {
                last_line = Some(from + k as u64 + 1);
            }
            // On from where a mark that this window cut short (or whose next byte it cut
            // off) starts.
            from += (n - mark.len()) as u64;
            if from - base > cap {
                // No likely cut for long: cut anyway (the chunk's check then fails).
                break (last_line.filter(|&l| l > base).unwrap_or(from), false);
            }
        };
        if end > base && !out(Piece::Range { start: base, end }) {
            return Ok(());
        }
        chunks += usize::from(end > base);
        base = end;
        if last {
            out(Piece::RegionEnd { chunks, end });
            return Ok(());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vrml::split::Splitter;

    /// The cuts the scan makes of `text` in memory, and those made in the file once the
    /// region is found: the same.
    fn both_ways(text: &[u8], chunk: u64, window: usize) {
        let block = 97;
        let in_memory = {
            let mut s = Splitter::new(chunk, 1 << 20);
            let mut v = Vec::new();
            let mut r = std::io::Cursor::new(text);
            while s.read_from(&mut r, block, &mut |p| v.push(p)).unwrap() > 0 {}
            s.finish(&mut |p| v.push(p));
            v
        };
        let in_file = {
            let mut s = Splitter::new(chunk, 1 << 20);
            let mut v = Vec::new();
            let mut r = std::io::Cursor::new(text);
            loop {
                let n = s.read_from(&mut r, block, &mut |p| v.push(p)).unwrap();
                if let Some(at) = s.region_at() {
                    let mut read_at = |buf: &mut [u8], off: u64| {
                        let off = (off as usize).min(text.len());
                        let n = buf.len().min(text.len() - off);
                        buf[..n].copy_from_slice(&text[off..off + n]);
                        Ok(n)
                    };
                    cut_with_window(at, &mut read_at, (chunk, window), &mut |p| {
                        v.push(p);
                        true
                    })
                    .unwrap();
                    break;
                }
                if n == 0 {
                    s.finish(&mut |p| v.push(p));
                    break;
                }
            }
            v
        };
        let cuts = |v: &[Piece]| -> Vec<(u64, u64)> {
            v.iter()
                .filter_map(|p| match p {
                    Piece::Chunk { start, text } => Some((*start, start + text.len() as u64)),
                    Piece::Range { start, end } => Some((*start, *end)),
                    Piece::RegionEnd { chunks, end } => Some((*chunks as u64, *end)),
                    _ => None,
                })
                .collect()
        };
        assert_eq!(
            cuts(&in_file),
            cuts(&in_memory),
            "{}",
            String::from_utf8_lossy(text)
        );
    }

    #[test]
    fn cuts_in_the_file_are_the_scans() {
        let node = |i: usize| {
            format!(
                "Transform {{ translation {i} 2 3 children Shape {{ geometry Sphere {{}} }} }}\n"
            )
        };
        let flat: String = (0..400).map(node).collect();
        let flat = format!("#VRML V2.0 utf8\n{flat}");
        let group: String = (0..400).map(|i| format!("  {}", node(i))).collect();
        let group = format!("#VRML V2.0 utf8\nGroup {{ children [\n{group}] }}\n");
        // A word that only starts as the mark does, and a long stretch with no likely cut.
        let odd: String = (0..400)
            .map(|i| match i % 50 {
                7 => "TransformX { }\n".to_string(),
                20 => format!("Group {{ children [ {} ] }}\n", "Shape { } ".repeat(300)),
                _ => node(i),
            })
            .collect();
        let odd = format!("#VRML V2.0 utf8\n{odd}");
        for text in [&flat, &group, &odd] {
            for chunk in [1, 50, 300, 2000, 1 << 20] {
                // Windows that cut marks and the bytes after them short, and one that holds
                // the whole text.
                for window in [1, 7, 64, 1000, WINDOW] {
                    both_ways(text.as_bytes(), chunk, window);
                }
            }
        }
    }
}
