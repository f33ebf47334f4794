//! Finished pictures to files and back: PNG (8-bit sRGB preview), EXR (linear f32 with alpha and
//! AOV layers), PFM (linear f32 RGB) and NPY (linear f64 RGB, for NumPy), chosen by the file
//! extension.
//!
//! Writing never leaves a half-written file at the destination: the bytes go to a hidden
//! sibling `.NAME.tmp.PID`, which is synced and then renamed over `NAME` (atomic within one
//! directory); on any failure, or a panic, the temporary file is removed. A program stopped by
//! a signal removes the ones it is writing with [`remove_unfinished`]; those of a process that
//! no longer exists are removed at the next write to the same `NAME` (on Linux, where
//! `/proc/PID` tells whether it exists; elsewhere they stay).

mod exr;
mod npy;
mod pfm;
mod png;
mod temp;

pub use temp::remove_unfinished;
use temp::TempFile;

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::Path;

use crate::Error;

/// A finished picture in linear float, row 0 at the TOP, pixel (x, y) at index `y * width + x`.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Linear RGB, `width * height` pixels.
    pub rgb: Vec<[f32; 3]>,
    /// Coverage in `[0, 1]`; written as A in EXR.
    pub alpha: Vec<f32>,
    /// Extra single-channel layers (AOVs) with their EXR channel names, e.g. "depth",
    /// "normal.X", "normal.Y", "normal.Z", "id", "error". Only EXR writes them.
    pub layers: Vec<Layer>,
}

/// One extra single-channel layer, `width * height` values in the same order as [`Image::rgb`].
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    /// Its EXR channel name.
    pub name: String,
    /// Its values, one per pixel.
    pub data: Vec<f32>,
}

/// The file formats, chosen by extension ([`format_for`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// 8-bit RGB, sRGB transfer function, clamped to `[0, 1]`; no alpha, no layers.
    Png,
    /// Linear f32 R, G, B, A and every layer as a channel; one part, scanlines, ZIP (16 lines).
    Exr,
    /// Linear f32 RGB, little-endian, rows bottom to top; no alpha, no layers.
    Pfm,
    /// NumPy `.npy`: an `H x W x 3` float64 array, row 0 at the top; no alpha, no layers
    /// ([`write_npy`] writes the f64 film itself; from an [`Image`], its f32 values).
    Npy,
}

/// Format from the file extension (case-insensitive `.png`/`.exr`/`.pfm`); an error naming
/// the path and the accepted extensions otherwise.
pub fn format_for(path: &Path) -> Result<Format, Error> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("exr") => Ok(Format::Exr),
        Some("pfm") => Ok(Format::Pfm),
        Some("npy") => Ok(Format::Npy),
        _ => {
            let found = match path.extension() {
                Some(e) => format!("extension '.{}'", e.to_string_lossy()),
                None => "no extension".to_string(),
            };
            Err(image_error(
                path,
                format!("unsupported image file name ({found}); expected .png, .exr, .pfm or .npy"),
            ))
        }
    }
}

/// Writes the image by extension to a temporary file in the same directory, then renames it
/// over `path`; on any failure the temporary file is removed and `path` is untouched.
///
/// The extension and the image (buffer lengths, layer names) are checked before any file is
/// created. Replacing `path` replaces the directory entry: an existing file's permissions are
/// not carried over, and a symlink at `path` is replaced rather than followed.
pub fn write_image(path: &Path, img: &Image) -> Result<(), Error> {
    write_placed(path, img, None)
}

/// The image as a PNG file's bytes (8-bit sRGB, as [`write_image`] writes `.png`), for a
/// preview held in memory (the Python `Film`'s picture in a notebook).
pub fn png_bytes(img: &Image) -> Result<Vec<u8>, Error> {
    img.check()
        .map_err(|message| Fault::Bad(message).at(Path::new("<png>")))?;
    let mut out = Vec::new();
    png::write(&mut out, img).map_err(|f| f.at(Path::new("<png>")))?;
    Ok(out)
}

/// Writes a rendered film by extension: `.npy` gets its f64 RGB, the other formats its f32
/// [`crate::render::Film::image`] (EXR with alpha and the extra channels).
pub fn write_film(path: &Path, film: &crate::render::Film) -> Result<(), Error> {
    match format_for(path)? {
        Format::Npy => write_npy(path, film.width, film.height, &film.rgb),
        _ => write_image(path, &film.image()),
    }
}

/// Writes the f64 pixels `rgb` (`width * height`, row 0 at the top, as
/// `Film::rgb`) as a float64 `.npy` array, the way images are written (temporary file,
/// then rename).
pub fn write_npy(path: &Path, width: usize, height: usize, rgb: &[[f64; 3]]) -> Result<(), Error> {
    if width.checked_mul(height) != Some(rgb.len()) || rgb.is_empty() {
        return Err(image_error(
            path,
            format!("{} pixels for a {width}x{height} image", rgb.len()),
        ));
    }
    write_file_atomically(path, |out| npy::write_f64(out, width, height, rgb))
}

/// Writes a table of numbers with the named `columns`, by extension: `.csv` (a header line,
/// then one line per row, each number with the digits that read back to the same f64) or
/// `.npy` (an `N x columns` float64 array, the columns in the order named), the way images
/// are written (temporary file, then rename).
pub fn write_table(path: &Path, columns: &[&str], rows: &[Vec<f64>]) -> Result<(), Error> {
    if let Some(bad) = rows.iter().position(|r| r.len() != columns.len()) {
        return Err(image_error(
            path,
            format!(
                "row {bad} has {} values for {} columns",
                rows[bad].len(),
                columns.len()
            ),
        ));
    }
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("csv") => write_file_atomically(path, |out| {
            writeln!(out, "{}", columns.join(","))?;
            for row in rows {
                let line: Vec<String> = row.iter().map(f64::to_string).collect();
                writeln!(out, "{}", line.join(","))?;
            }
            Ok(())
        }),
        Some("npy") => {
            write_file_atomically(path, |out| npy::write_table(out, columns.len(), rows))
        }
        _ => Err(image_error(
            path,
            "unsupported table file name; expected .csv or .npy".into(),
        )),
    }
}

/// Writes any file the way images are written: into a hidden temporary sibling, synced, then
/// renamed over `path`; on failure the temporary file is removed and `path` is untouched.
pub fn write_file_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), Error> {
    let io_error = |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    };
    if let Some(file) = special_target(path).map_err(io_error)? {
        let mut out = BufWriter::with_capacity(1 << 20, file);
        return write(&mut out).and_then(|()| out.flush()).map_err(io_error);
    }
    let (mut temp, file) = TempFile::create(path)?;
    let written = (|| -> io::Result<()> {
        let mut out = BufWriter::with_capacity(1 << 20, file);
        write(&mut out)?;
        out.flush()?;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        Ok(())
    })();
    // On an error `temp` is dropped on return and removes the temporary file.
    written.map_err(io_error)?;
    temp.rename_to(path)
}

/// `path` opened for writing when it names something other than a regular file or nothing
/// (`/dev/stdout`, a named pipe, a terminal): those are written in place, since renaming a
/// temporary file over them would replace the device or pipe with a plain file.
fn special_target(path: &Path) -> io::Result<Option<File>> {
    match fs::metadata(path) {
        Ok(m) if !m.is_file() && !m.is_dir() => OpenOptions::new().write(true).open(path).map(Some),
        _ => Ok(None),
    }
}

/// Where a part of a picture goes in the whole: its top-left pixel and the whole's size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The column of the part's top-left pixel in the whole picture.
    pub x: usize,
    /// The row of the part's top-left pixel in the whole picture, row 0 at the top.
    pub y: usize,
    /// The whole picture's width in pixels.
    pub full_width: usize,
    /// The whole picture's height in pixels.
    pub full_height: usize,
}

/// Writes `img` as one part of a larger picture (EXR only): the part's position is its EXR
/// data window and the whole picture is the display window, as the format intends.
pub fn write_part(path: &Path, img: &Image, at: Placement) -> Result<(), Error> {
    if format_for(path)? != Format::Exr {
        return Err(image_error(
            path,
            "a part of a picture must be written as .exr (it records where the part goes)".into(),
        ));
    }
    if at.x + img.width > at.full_width || at.y + img.height > at.full_height {
        return Err(image_error(
            path,
            "the part does not fit in the whole picture".into(),
        ));
    }
    write_placed(path, img, Some(at))
}

/// Reads an EXR with where it goes in the whole picture (a plain EXR is a whole picture at 0,0).
pub fn read_part(path: &Path) -> Result<(Image, Placement), Error> {
    if format_for(path)? != Format::Exr {
        return Err(image_error(path, "parts are .exr files".into()));
    }
    let (img, at) = exr::read_placed(path).map_err(|f| f.at(path))?;
    img.check().map_err(|m| image_error(path, m))?;
    Ok((img, at))
}

fn write_placed(path: &Path, img: &Image, at: Option<Placement>) -> Result<(), Error> {
    let format = format_for(path)?;
    img.check().map_err(|m| image_error(path, m))?;
    let encode = |out: &mut BufWriter<File>| -> Result<(), Fault> {
        match format {
            Format::Png => png::write(out, img)?,
            Format::Exr => exr::write(out, img, at)?,
            Format::Pfm => pfm::write(out, img)?,
            Format::Npy => npy::write(out, img)?,
        }
        out.flush()?;
        Ok(())
    };
    if let Some(file) = special_target(path).map_err(|e| Fault::from(e).at(path))? {
        return encode(&mut BufWriter::new(file)).map_err(|f| f.at(path));
    }
    let (mut temp, file) = TempFile::create(path)?;
    let written = (|| -> Result<(), Fault> {
        let mut out = BufWriter::new(file);
        encode(&mut out)?;
        let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
        // Sync before the rename, so a crash cannot leave the new name on empty contents.
        file.sync_all()?;
        // Closed before the rename (required on Windows).
        drop(file);
        Ok(())
    })();
    // On an error `temp` is dropped on return and removes the temporary file.
    written.map_err(|fault| fault.at(path))?;
    temp.rename_to(path)
}

/// Reads PFM, EXR (RGB, and A and the other channels as layers if present) and PNG (decoded
/// back to linear). Without an alpha channel, alpha is 1 everywhere.
///
/// EXR channels come back sorted by name (the file stores them so), whatever the order of
/// [`Image::layers`] when written.
pub fn read_image(path: &Path) -> Result<Image, Error> {
    let format = format_for(path)?;
    let read = || -> Result<Image, Fault> {
        let img = match format {
            Format::Png => png::read(&fs::read(path)?)?,
            Format::Pfm => pfm::read(&fs::read(path)?)?,
            Format::Npy => npy::read(&fs::read(path)?)?,
            Format::Exr => exr::read(path)?,
        };
        // The decoders build consistent images; check anyway, callers index by these lengths.
        img.check().map_err(Fault::Bad)?;
        Ok(img)
    };
    read().map_err(|f| f.at(path))
}

impl Image {
    /// `width * height`, after checking every buffer has that length and the layer names are
    /// usable as distinct EXR channels.
    fn check(&self) -> Result<usize, String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!("image is empty ({}x{})", self.width, self.height));
        }
        let n = self
            .width
            .checked_mul(self.height)
            .ok_or_else(|| format!("image size {}x{} overflows", self.width, self.height))?;
        let expect = |what: &str, len: usize| {
            if len == n {
                Ok(())
            } else {
                Err(format!(
                    "{what} has {len} values, expected {n} for {}x{}",
                    self.width, self.height
                ))
            }
        };
        expect("rgb", self.rgb.len())?;
        expect("alpha", self.alpha.len())?;
        let mut names: Vec<&str> = Vec::with_capacity(self.layers.len());
        for layer in &self.layers {
            let name = layer.name.as_str();
            if name.is_empty() {
                return Err("a layer has an empty name".to_string());
            }
            if ["R", "G", "B", "A"].contains(&name) {
                return Err(format!(
                    "layer name '{name}' is reserved for the colour and alpha"
                ));
            }
            if names.contains(&name) {
                return Err(format!("two layers are named '{name}'"));
            }
            names.push(name);
            expect(&format!("layer '{name}'"), layer.data.len())?;
        }
        Ok(n)
    }
}

/// What went wrong inside a format module, before the path is attached.
enum Fault {
    Io(io::Error),
    /// The image or the file is not what it should be; the message says how.
    Bad(String),
}

impl From<io::Error> for Fault {
    fn from(e: io::Error) -> Self {
        Fault::Io(e)
    }
}

impl Fault {
    fn at(self, path: &Path) -> Error {
        match self {
            Fault::Io(source) => Error::Io {
                path: path.display().to_string(),
                source,
            },
            Fault::Bad(message) => image_error(path, message),
        }
    }
}

fn image_error(path: &Path, message: String) -> Error {
    Error::Image {
        path: path.display().to_string(),
        message,
    }
}
