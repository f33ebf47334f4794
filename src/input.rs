//! Opening scene files: plain or gzip-compressed (`.wrz`, `.wrl.gz`, or any file that starts
//! with the gzip magic number), read as a stream; and plain files read at any offset.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use crate::error::Error;
use crate::source::SourceWindow;

const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Wraps a reader, decompressing it when it starts with the gzip magic number.
pub fn sniff(reader: impl Read + Send + 'static) -> std::io::Result<Box<dyn Read + Send>> {
    sniff_bounded(reader, u64::MAX)
}

/// Text that gzip data may inflate to whatever its compressed size, when a scene is loaded:
/// beyond it, at most [`LoadOptions::inflate_ratio`](crate::vrml::LoadOptions::inflate_ratio)
/// times the compressed bytes read so far.
pub const INFLATE_BASE: u64 = 16 << 20;

/// [`sniff`], where gzip data may inflate to at most [`INFLATE_BASE`] plus `max_ratio` times
/// the compressed bytes read so far; past that, reading fails (`InvalidData`), before the
/// text is held or read on. Deflate can inflate 1032 times; VRML text compresses 3 to 12
/// times (particle tables as `convert` writes them, copies of a tool's export).
pub(crate) fn sniff_bounded(
    reader: impl Read + Send + 'static,
    max_ratio: u64,
) -> std::io::Result<Box<dyn Read + Send>> {
    let compressed = Arc::new(AtomicU64::new(0));
    let counted = Counted {
        inner: reader,
        count: compressed.clone(),
    };
    let mut br = BufReader::with_capacity(1 << 16, counted);
    let head = br.fill_buf()?;
    if head.len() >= 2 && head[..2] == GZIP_MAGIC {
        Ok(Box::new(Inflated {
            inner: flate2::bufread::MultiGzDecoder::new(br),
            compressed,
            inflated: 0,
            max_ratio,
        }))
    } else {
        Ok(Box::new(br))
    }
}

/// A reader that counts the bytes read through it.
struct Counted<R> {
    inner: R,
    count: Arc<AtomicU64>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.fetch_add(n as u64, Ordering::Relaxed);
        Ok(n)
    }
}

/// Inflated gzip text, bounded by a ratio to the compressed bytes read.
struct Inflated<R> {
    inner: R,
    compressed: Arc<AtomicU64>,
    inflated: u64,
    max_ratio: u64,
}

impl<R: Read> Read for Inflated<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.inflated += n as u64;
        let compressed = self.compressed.load(Ordering::Relaxed);
        let limit = INFLATE_BASE.saturating_add(self.max_ratio.saturating_mul(compressed));
        if self.inflated > limit {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "the gzip data inflates more than {} times its compressed size ({} bytes \
                     from {compressed}); `--max-expansion` (Python: `max_expansion`) raises \
                     the ratio",
                    self.max_ratio, self.inflated
                ),
            ));
        }
        Ok(n)
    }
}

/// The file at `path` opened, if it is plain text (not gzip: that is read as a stream, see
/// [`sniff`]) and can be read at any offset (see [`read_at`]).
pub(crate) fn open_plain(path: &Path) -> Option<File> {
    if !cfg!(any(unix, windows)) {
        return None;
    }
    let file = File::open(path).ok()?;
    let mut head = [0u8; 2];
    let n = read_at(&file, &mut head, 0).ok()?;
    (n < 2 || head != GZIP_MAGIC).then_some(file)
}

/// Bytes `at..end` of a file, read without moving its cursor (so that several readers share
/// one open file, whatever happens to its name meanwhile).
pub(crate) struct FileRange {
    pub(crate) file: Arc<File>,
    pub(crate) at: u64,
    pub(crate) end: u64,
}

impl FileRange {
    /// The range as a reader of its own: the file opened again when the path still names
    /// the same file, so that reads go straight into the reader's buffer (a positional
    /// reader's buffer is zeroed before every read on stable Rust: 8 ms of CPU per million
    /// particles); else the range itself.
    pub(crate) fn into_reader(self, path: &Path) -> Box<dyn Read> {
        match self.reopen(path) {
            Some(file) => Box::new(file.take(self.end.saturating_sub(self.at))),
            None => Box::new(self),
        }
    }

    #[cfg(unix)]
    fn reopen(&self, path: &Path) -> Option<File> {
        use std::io::{Seek, SeekFrom};
        use std::os::unix::fs::MetadataExt;
        let mut file = File::open(path).ok()?;
        let (a, b) = (file.metadata().ok()?, self.file.metadata().ok()?);
        if (a.dev(), a.ino()) != (b.dev(), b.ino()) {
            return None;
        }
        file.seek(SeekFrom::Start(self.at)).ok()?;
        Some(file)
    }

    #[cfg(not(unix))]
    fn reopen(&self, _path: &Path) -> Option<File> {
        None
    }
}

impl Read for FileRange {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.end.saturating_sub(self.at) as usize);
        if n == 0 {
            return Ok(0);
        }
        let k = read_at(&self.file, &mut buf[..n], self.at)?;
        self.at += k as u64;
        Ok(k)
    }
}

/// Reads at `offset` of `file` without moving its cursor.
pub(crate) fn read_at(file: &File, buf: &mut [u8], offset: u64) -> std::io::Result<usize> {
    #[cfg(unix)]
    {
        std::os::unix::fs::FileExt::read_at(file, buf, offset)
    }
    #[cfg(windows)]
    {
        std::os::windows::fs::FileExt::seek_read(file, buf, offset)
    }
    #[cfg(not(any(unix, windows)))]
    {
        let _ = (file, buf, offset);
        Err(std::io::Error::other(
            "positional reads are not supported here",
        ))
    }
}

/// Opens a scene file as a streaming source window; gzip data may inflate `max_ratio` times
/// its size (see [`sniff_bounded`]).
pub(crate) fn open(path: &Path, max_ratio: u64) -> Result<SourceWindow, Error> {
    let name: Arc<str> = Arc::from(path.display().to_string());
    let file = File::open(path).map_err(|e| Error::Io {
        path: name.to_string(),
        source: e,
    })?;
    let reader = sniff_bounded(file, max_ratio).map_err(|e| Error::Io {
        path: name.to_string(),
        source: e,
    })?;
    Ok(SourceWindow::new(name, reader))
}

/// The 1-based line and byte column of byte `offset` of the file at `path` (decompressed if
/// gzip), by reading it again up to there: positions are kept as byte offsets only
/// ([`crate::scene::Origin`]), and the line index is dropped after loading (it would cost
/// 4 bytes per line, 40 MB for a 1e7-line file, for errors that are rare). `None` if the
/// file cannot be read or is shorter than `offset` (changed since it was loaded).
pub(crate) fn line_col_in(path: &Path, offset: u64) -> Option<(u64, u64)> {
    let mut reader = sniff(File::open(path).ok()?).ok()?;
    let (mut line, mut line_start, mut at) = (1u64, 0u64, 0u64);
    let mut buf = vec![0u8; 1 << 16];
    while at < offset {
        let n = reader.read(&mut buf).ok()?;
        if n == 0 {
            return None;
        }
        let take = (n as u64).min(offset - at) as usize;
        for (k, &b) in buf[..take].iter().enumerate() {
            if b == b'\n' {
                line += 1;
                line_start = at + k as u64 + 1;
            }
        }
        at += take as u64;
    }
    Some((line, offset - line_start + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_reads_the_file_it_was_cut_from() {
        let dir = std::env::temp_dir().join(format!("gtsphere-range-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("scene.wrl");
        std::fs::write(&path, b"0123456789abcdef").unwrap();
        let file = Arc::new(open_plain(&path).unwrap());
        let range = |at, end| FileRange {
            file: file.clone(),
            at,
            end,
        };
        let read = |r: Box<dyn Read>| {
            let mut s = String::new();
            let mut r = r;
            r.read_to_string(&mut s).unwrap();
            s
        };
        // The path names the file: opened again, the range alone is read.
        assert_eq!(read(range(3, 9).into_reader(&path)), "345678");
        assert_eq!(read(range(10, u64::MAX).into_reader(&path)), "abcdef");
        // Another file renamed over the path: still the first file's bytes.
        let other = dir.join("other.wrl");
        std::fs::write(&other, b"ZYXWVUTSRQPONMLK").unwrap();
        std::fs::rename(&other, &path).unwrap();
        assert_eq!(read(range(3, 9).into_reader(&path)), "345678");
        // No file at the path at all: the same.
        std::fs::remove_file(&path).unwrap();
        assert_eq!(read(range(0, 4).into_reader(&path)), "0123");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
