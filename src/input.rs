//! Opening scene files: plain or gzip-compressed (`.wrz`, `.wrl.gz`, or any file that starts
//! with the gzip magic number), read as a stream.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::sync::Arc;

use crate::error::Error;
use crate::source::SourceWindow;

const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Wraps a reader, decompressing it when it starts with the gzip magic number.
pub fn sniff(reader: impl Read + 'static) -> std::io::Result<Box<dyn Read>> {
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
