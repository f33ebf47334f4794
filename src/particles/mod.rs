//! Particle tables (CSV, TSV, white-space columns, XYZ) to VRML97, streamed: a row is read,
//! checked and written before the next is read, so memory does not grow with the row count.
//!
//! `read` finds the dialect, the header and what each column means (`columns`); `write`
//! writes a `PROTO Particle` instance (or plain nodes) per row and the framing.

pub(crate) mod columns;
pub(crate) mod elements;
pub(crate) mod read;
pub(crate) mod write;

use std::io::{Read, Write};
use std::path::Path;

use crate::diag::Diagnostic;
use crate::error::Error;
use crate::output::write_file_atomically;
pub use columns::{ColumnSpec, Role};
use read::ParticleReader;
pub use read::{ColorScale, Delimiter, TableOptions, SNIFF_ROWS};
pub use write::Extras;
use write::ParticleWriter;

/// What a conversion did.
#[derive(Debug)]
pub struct Summary {
    /// Particles written.
    pub particles: u64,
    /// Rows skipped under `--skip-bad`, and the first one's reason.
    pub skipped: u64,
    /// The first skipped row's reason.
    pub first_skip: Option<Diagnostic>,
    /// What was decided about the input (dialect, columns, colour scale).
    pub notes: Vec<String>,
    /// The box `(min, max)` of every sphere written; `None` when none were.
    pub bounds: Option<(glam::DVec3, glam::DVec3)>,
}

/// Output settings.
#[derive(Clone, Copy, Debug)]
pub struct WriteOptions {
    /// Transform/Shape/Sphere nodes instead of PROTO instances.
    pub plain: bool,
    /// The viewpoint and lights to add after the particles.
    pub extras: Extras,
}

fn diag(d: Diagnostic) -> Error {
    Error::Diag(Box::new(d))
}

/// [`convert`] into the file `path`, written to a temporary name and renamed: a bad row or an
/// empty table leaves no file (and an existing one as it was).
pub fn convert_to_file(
    name: &str,
    input: Box<dyn Read>,
    path: &Path,
    table: TableOptions,
    opts: WriteOptions,
) -> Result<Summary, Error> {
    // Conversion errors are kept aside: the atomic writer only knows I/O errors.
    let mut failure = None;
    let mut summary = None;
    let written = write_file_atomically(path, |w| match convert(name, input, w, table, opts) {
        Ok((_, s)) => {
            summary = Some(s);
            Ok(())
        }
        Err(e) => {
            failure = Some(e);
            Err(std::io::Error::other("conversion failed"))
        }
    });
    if let Some(e) = failure {
        return Err(e);
    }
    written?;
    summary.ok_or_else(|| Error::Internal("the conversion gave no summary".to_string()))
}

/// Converts the table read from `input` (named `name` in messages) into VRML on `out`.
/// A bad row (without `skip_bad`) or a table without particles is an error; `out` then holds
/// a partial file, which the caller discards.
pub fn convert<W: Write>(
    name: &str,
    input: Box<dyn Read>,
    out: W,
    table: TableOptions,
    opts: WriteOptions,
) -> Result<(W, Summary), Error> {
    let io = |source| Error::Io {
        path: "the VRML output".into(),
        source,
    };
    let radius = table.radius;
    let mut reader = ParticleReader::new(name, input, table).map_err(diag)?;
    let profiles = reader.has_profiles();
    if profiles && opts.plain {
        return Err(Error::Invalid(format!(
            "{name}: the profile column needs the PROTO form (GasParticle): leave out --plain"
        )));
    }
    let mut writer = ParticleWriter::new(out, name, opts.plain, profiles, radius).map_err(io)?;
    while let Some(p) = reader.next_particle().map_err(diag)? {
        writer.particle(&p).map_err(io)?;
    }
    if writer.count() == 0 {
        let why = match &reader.first_skip {
            Some(d) => format!(" (every row was bad; the first: {})", d.headline()),
            None => String::new(),
        };
        // Positioned where the table ends.
        let end = reader.lines_read() + 1;
        return Err(Error::Invalid(format!(
            "{name}:{end}:1: no particles in the table{why}"
        )));
    }
    let bounds = writer.bounds();
    if opts.extras.viewpoint && writer.framing().is_none() {
        reader.notes.push(
            "no Viewpoint written: the particles reach too close to the largest f64 for a camera to frame them".to_string(),
        );
    }
    let particles = writer.count();
    let out = writer.finish(opts.extras).map_err(io)?;
    let mut notes = vec![format!("delimiter: {:?}", reader.delimiter()).to_lowercase()];
    notes.append(&mut reader.notes);
    Ok((
        out,
        Summary {
            particles,
            skipped: reader.skipped,
            first_skip: reader.first_skip.take(),
            notes,
            bounds,
        },
    ))
}
