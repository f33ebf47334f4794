//! Opening scene files: plain or gzip-compressed (`.wrz`, `.wrl.gz`, or any file that starts
//! with the gzip magic number), read as a stream.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::sync::Arc;

use crate::error::Error;
use crate::source::SourceWindow;

pub(crate) const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Wraps a reader, decompressing it when it starts with the gzip magic number.
pub fn sniff(reader: impl Read + Send + 'static) -> std::io::Result<Box<dyn Read + Send>> {
    let mut br = BufReader::with_capacity(1 << 16, reader);
    let head = br.fill_buf()?;
    if head.len() >= 2 && head[..2] == GZIP_MAGIC {
        Ok(Box::new(flate2::bufread::MultiGzDecoder::new(br)))
    } else {
        Ok(Box::new(br))
    }
}

/// Opens a scene file as a streaming source window.
pub fn open(path: &Path) -> Result<SourceWindow, Error> {
    let name: Arc<str> = Arc::from(path.display().to_string());
    let file = File::open(path).map_err(|e| Error::Io {
        path: name.to_string(),
        source: e,
    })?;
    let reader = sniff(file).map_err(|e| Error::Io {
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
pub fn line_col_in(path: &Path, offset: u64) -> Option<(u64, u64)> {
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
