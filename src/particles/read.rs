//! Reading particle tables as a stream: dialect, header, column roles, and one particle per
//! row, in memory independent of the number of rows.
//!
//! - Delimiter: `;` if the first line has one, else tab, else `,`, else runs of white space
//!   (`--delimiter` overrides). Comma, semicolon and tab files are read by the `csv` crate
//!   (quoting, trimming); white-space files by splitting lines, since `csv` knows only single
//!   delimiters. Lines starting with `#` are comments. In semicolon files a decimal comma
//!   (`1,5`) is read as a decimal point.
//! - Header: the first row is a header when one of its fields is not a number. Without one,
//!   `--columns` names the columns in order; 3 columns default to `x y z`, 4 to
//!   `x y z radius`.
//! - XYZ files (white space, a first line holding only the atom count, then a comment line,
//!   then `element x y z` rows) are recognised; the first frame is read.
//! - Colours are 0-1 or 0-255: decided from the first [`SNIFF_ROWS`] rows (a fractional value
//!   means 0-1; only integers with one above 1 means 0-255), or `--color-scale`.
//! - Errors are `file:LINE:FIELD: message`, LINE the file's line (1-based) and FIELD the
//!   1-based field number of the offending value.

use std::io::{BufRead, BufReader, Read};
use std::sync::Arc;

use csv::ByteRecord;

use super::columns::{ColumnMap, ColumnSpec, Role};
use crate::diag::{Diagnostic, Severity};
use crate::scene::profile::{Profile, ProfileError};

mod header;

/// How many data rows decide the colour scale.
pub const SNIFF_ROWS: usize = 1000;

/// The field separator of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Delimiter {
    /// `,` (a CSV file).
    Comma,
    /// `;`, with a decimal comma read as a decimal point.
    Semicolon,
    /// A tab character (TSV).
    Tab,
    /// One or more spaces or tabs.
    Whitespace,
}

/// The range colour values are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorScale {
    /// Floats from 0 to 1.
    Unit,
    /// Integers from 0 to 255.
    Byte,
}

/// How to read a particle table.
#[derive(Clone, Debug, Default)]
pub struct TableOptions {
    /// `--columns`: the roles of the columns, for a table without a header.
    pub columns: ColumnSpec,
    /// `--radius`: the radius of every particle (overrides a radius column).
    pub radius: Option<f64>,
    /// `--delimiter`; `None` guesses it from the first line.
    pub delimiter: Option<Delimiter>,
    /// `--color-scale`; `None` guesses it from the first [`SNIFF_ROWS`] rows.
    pub color_scale: Option<ColorScale>,
    /// Skip bad rows (counted) instead of stopping at the first.
    pub skip_bad: bool,
}

/// A number and, when it was read as is, its text (written back verbatim, digits kept).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num<'a> {
    /// The number read.
    pub value: f64,
    /// Its text in the table, when VRML can take that text as is; `None` otherwise (a value
    /// computed, such as a radius from a diameter or a 0-255 colour, or one with a decimal comma).
    pub text: Option<&'a [u8]>,
}

/// One particle. Colours are linear 0-1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle<'a> {
    /// The centre's x, y and z, in world units.
    pub position: [Num<'a>; 3],
    /// The radius, in world units.
    pub radius: Num<'a>,
    /// The diffuse colour's red, green and blue, 0-1; `None` when the table gives none.
    pub color: Option<[Num<'a>; 3]>,
    /// The emissive colour's red, green and blue; `None` when the table gives none.
    pub emission: Option<[Num<'a>; 3]>,
    /// VRML transparency: 0 opaque, in (0, 1] a gas sphere.
    pub transparency: Option<f64>,
    /// The density profile, when the table gives one (an empty cell: constant).
    pub profile: Option<Profile>,
}

enum Rows {
    Csv(csv::Reader<Box<dyn Read>>),
    Whitespace {
        reader: BufReader<Box<dyn Read>>,
        line: u64,
        buf: Vec<u8>,
    },
}

impl Rows {
    /// The next row and its line number, or `None` at the end.
    fn next(&mut self, rec: &mut ByteRecord) -> Result<Option<u64>, String> {
        match self {
            Rows::Csv(r) => loop {
                match r.read_byte_record(rec) {
                    Ok(false) => return Ok(None),
                    Ok(true) => {
                        // Blank lines inside a file come back as one empty field.
                        if rec.len() == 1 && rec[0].is_empty() {
                            continue;
                        }
                        return Ok(Some(rec.position().map_or(0, |p| p.line())));
                    }
                    Err(e) => return Err(e.to_string()),
                }
            },
            Rows::Whitespace { reader, line, buf } => loop {
                buf.clear();
                let n = reader.read_until(b'\n', buf).map_err(|e| e.to_string())?;
                if n == 0 {
                    return Ok(None);
                }
                *line += 1;
                rec.clear();
                for field in buf
                    .split(|b| b.is_ascii_whitespace())
                    .filter(|f| !f.is_empty())
                {
                    rec.push_field(field);
                }
                if rec.is_empty() || rec[0].starts_with(b"#") {
                    continue;
                }
                return Ok(Some(*line));
            },
        }
    }
}

impl Rows {
    /// Skips one raw line of a white-space table, blank or not (an XYZ comment line).
    fn skip_line(&mut self) -> Result<(), String> {
        if let Rows::Whitespace { reader, line, buf } = self {
            buf.clear();
            reader.read_until(b'\n', buf).map_err(|e| e.to_string())?;
            *line += 1;
        }
        Ok(())
    }
}

/// A row kept aside while the colour scale is decided.
struct Held {
    line: u64,
    rec: ByteRecord,
}

/// Reads particles from a table, one row at a time.
pub struct ParticleReader {
    file: Arc<str>,
    rows: Rows,
    map: ColumnMap,
    opts: TableOptions,
    delimiter: Delimiter,
    scale: ColorScale,
    held: std::collections::VecDeque<Held>,
    rec: ByteRecord,
    /// The current row's values by role (see [`Role::ALL`]).
    vals: [Option<f64>; 18],
    /// The current row's density profile, when the table has a profile column.
    profile: Option<Profile>,
    /// The current row's element radius and colour, when the table relies on them.
    element: Option<(f64, [f64; 3])>,
    /// Whether the element column gives the radius and the colour (the table does not).
    element_gives: (bool, bool),
    line: u64,
    /// Data rows still to read (XYZ files say how many atoms a frame has).
    remaining: Option<u64>,
    /// Rows skipped with `--skip-bad`, and the first reason.
    pub skipped: u64,
    /// The reason the first of them was skipped.
    pub first_skip: Option<Diagnostic>,
    /// What was decided about the file, for the user (one line each).
    pub notes: Vec<String>,
}

/// An error at `line`, field `col` (1-based) of `file`.
fn diagnostic(file: &Arc<str>, line: u64, col: u64, message: String) -> Diagnostic {
    Diagnostic {
        severity: Severity::Error,
        file: file.clone(),
        line,
        col,
        message,
        snippet: None,
        repeats: 0,
    }
}

/// A decimal number (Rust's syntax: `1`, `-.5`, `+2.`, `1e-3`; `inf` and `nan` too, which
/// the caller rejects), with a decimal comma when `decimal_comma`.
fn number(field: &[u8], decimal_comma: bool) -> Option<f64> {
    let s = field.trim_ascii();
    match fast_float2::parse::<f64, _>(s) {
        Ok(v) => Some(v),
        Err(_) if decimal_comma && s.contains(&b',') => {
            let dotted: Vec<u8> = s
                .iter()
                .map(|&b| if b == b',' { b'.' } else { b })
                .collect();
            fast_float2::parse(dotted).ok()
        }
        Err(_) => None,
    }
}

fn text(field: &[u8]) -> &str {
    std::str::from_utf8(field.trim_ascii()).unwrap_or("").trim()
}

fn guess_delimiter(head: &[u8]) -> Delimiter {
    let line = head
        .split(|&b| b == b'\n')
        .find(|l| {
            let t = l.trim_ascii();
            !t.is_empty() && !t.starts_with(b"#")
        })
        .unwrap_or(b"");
    if line.contains(&b';') {
        Delimiter::Semicolon
    } else if line.contains(&b'\t') && !line.contains(&b',') {
        // A tab file; white space if the tabs only pad columns (checked when splitting).
        Delimiter::Tab
    } else if line.contains(&b',') {
        Delimiter::Comma
    } else {
        Delimiter::Whitespace
    }
}

impl ParticleReader {
    /// The lines read so far (the header's included).
    pub fn lines_read(&self) -> u64 {
        self.line
    }

    /// Whether the table has a profile column (its particles are then `GasParticle`s).
    pub fn has_profiles(&self) -> bool {
        self.map.get(Role::Profile).is_some()
    }

    /// Opens a table from a byte stream named `file` in messages.
    pub fn new(
        file: &str,
        reader: Box<dyn Read>,
        opts: TableOptions,
    ) -> Result<ParticleReader, Diagnostic> {
        let file: Arc<str> = Arc::from(file);
        let mut reader = BufReader::with_capacity(1 << 16, reader);
        let read_error = |e: std::io::Error| diagnostic(&file, 1, 1, e.to_string());
        // A UTF-8 byte order mark (spreadsheet exports) is not part of the first name.
        if reader
            .fill_buf()
            .map_err(read_error)?
            .starts_with(b"\xEF\xBB\xBF")
        {
            reader.consume(3);
        }
        let head = reader.fill_buf().map_err(read_error)?;
        let delimiter = opts.delimiter.unwrap_or_else(|| guess_delimiter(head));
        let rows = match delimiter {
            Delimiter::Whitespace => Rows::Whitespace {
                reader,
                line: 0,
                buf: Vec::new(),
            },
            d => Rows::Csv(
                csv::ReaderBuilder::new()
                    .delimiter(match d {
                        Delimiter::Semicolon => b';',
                        Delimiter::Tab => b'\t',
                        _ => b',',
                    })
                    .has_headers(false)
                    .flexible(true)
                    .comment(Some(b'#'))
                    .buffer_capacity(1 << 16)
                    .from_reader(Box::new(reader) as Box<dyn Read>),
            ),
        };
        let mut me = ParticleReader {
            file,
            rows,
            map: ColumnMap::default(),
            opts,
            delimiter,
            scale: ColorScale::Unit,
            held: std::collections::VecDeque::new(),
            rec: ByteRecord::new(),
            vals: [None; 18],
            profile: None,
            element: None,
            element_gives: (false, false),
            line: 0,
            remaining: None,
            skipped: 0,
            first_skip: None,
            notes: Vec::new(),
        };
        me.start()?;
        Ok(me)
    }

    /// The delimiter the table is read with, given or guessed.
    pub fn delimiter(&self) -> Delimiter {
        self.delimiter
    }

    fn error(&self, line: u64, col: usize, message: String) -> Diagnostic {
        diagnostic(&self.file, line, col as u64, message)
    }

    /// An I/O or CSV error while reading the line after the current one.
    fn read_failed(&self, m: String) -> Diagnostic {
        self.error(self.line + 1, 1, format!("cannot read the table: {m}"))
    }

    fn read_row(&mut self, rec: &mut ByteRecord) -> Result<Option<u64>, Diagnostic> {
        let got = self.rows.next(rec).map_err(|m| self.read_failed(m))?;
        if let Some(line) = got {
            self.line = line;
        }
        Ok(got)
    }

    /// Whether an XYZ frame has rows beyond those held.
    fn remaining_after_held(&self) -> bool {
        self.remaining.is_none_or(|n| (self.held.len() as u64) < n)
    }

    /// The next particle, `None` at the end of the table (or of an XYZ frame).
    pub fn next_particle(&mut self) -> Result<Option<Particle<'_>>, Diagnostic> {
        loop {
            if self.remaining == Some(0) {
                return Ok(None);
            }
            let line = if let Some(h) = self.held.pop_front() {
                self.rec = h.rec;
                h.line
            } else {
                // Into `self.rec` itself (a separate record would allocate per row).
                let got = self.rows.next(&mut self.rec);
                match got.map_err(|m| self.read_failed(m))? {
                    Some(line) => line,
                    None => {
                        if let Some(n) = self.remaining {
                            return Err(self.error(
                                self.line + 1,
                                1,
                                format!(
                                    "the XYZ header promised {n} more atom lines, but the file ends"
                                ),
                            ));
                        }
                        return Ok(None);
                    }
                }
            };
            self.line = line;
            if let Some(n) = self.remaining.as_mut() {
                *n -= 1;
            }
            match self.check_row(line) {
                Ok(()) => break,
                Err(d) if self.opts.skip_bad => {
                    self.skipped += 1;
                    if self.first_skip.is_none() {
                        self.first_skip = Some(d);
                    }
                }
                Err(d) => return Err(d),
            }
        }
        Ok(Some(self.particle()))
    }

    /// An error about the value in column `col` (0-based) of the row on `line`.
    fn column_error(&self, line: u64, col: usize, what: impl std::fmt::Display) -> Diagnostic {
        self.error(
            line,
            col + 1,
            format!("column \"{}\": {what}", self.map.name(col)),
        )
    }

    /// Field `col` of the current row.
    fn field(&self, line: u64, col: usize) -> Result<&[u8], Diagnostic> {
        self.rec.get(col).ok_or_else(|| {
            self.error(
                line,
                self.rec.len() + 1,
                format!(
                    "the row has {} fields; column {} (\"{}\") is missing",
                    self.rec.len(),
                    col + 1,
                    self.map.name(col)
                ),
            )
        })
    }

    /// The value of `role` in the current row, checked finite.
    fn value(&self, line: u64, role: Role) -> Result<Option<f64>, Diagnostic> {
        let Some(col) = self.map.get(role) else {
            return Ok(None);
        };
        let field = self.field(line, col)?;
        let bad = |what: String| self.column_error(line, col, what);
        if field.trim_ascii().is_empty() {
            // An empty cell leaves an optional value at its default.
            return match role {
                Role::X | Role::Y | Role::Z | Role::Radius | Role::Diameter => {
                    Err(bad("the value is missing (an empty field)".to_string()))
                }
                _ => Ok(None),
            };
        }
        let v = number(field, self.delimiter == Delimiter::Semicolon)
            .ok_or_else(|| bad(format!("\"{}\" is not a number", text(field))))?;
        if !v.is_finite() {
            return Err(bad(format!("{} is not a finite number", text(field))));
        }
        let range = |lo: f64, hi: f64, what: &str| {
            if v >= lo && v <= hi {
                Ok(Some(v))
            } else {
                Err(bad(format!("{v} is outside {lo}..{hi} ({what})")))
            }
        };
        match role {
            Role::Radius | Role::Diameter if v <= 0.0 => {
                Err(bad(format!("{role} {v} is not positive")))
            }
            Role::Density if v < 0.0 => Err(bad(format!("density {v} is negative"))),
            Role::Opacity | Role::Transparency => range(0.0, 1.0, role.name()),
            r if r.is_colour() => match self.scale {
                ColorScale::Unit => range(
                    0.0,
                    1.0,
                    "colours are read as 0-1 floats; --color-scale 255 reads 0-255",
                ),
                ColorScale::Byte if v.fract() != 0.0 => Err(bad(format!(
                    "{v} is not an integer (colours are read as 0-255 integers; --color-scale 1 reads 0-1 floats)"
                ))),
                ColorScale::Byte => range(0.0, 255.0, "colours are read as 0-255 integers")
                    .map(|v| v.map(|v| v / 255.0)),
            },
            _ => Ok(Some(v)),
        }
    }

    /// Every value of the current row that matters, checked, into `self.vals`.
    fn check_row(&mut self, line: u64) -> Result<(), Diagnostic> {
        for (k, role) in Role::ALL.into_iter().enumerate() {
            self.vals[k] = None;
            let given = matches!(role, Role::Radius | Role::Diameter) && self.opts.radius.is_some();
            if role == Role::Element || role == Role::Profile || given {
                continue;
            }
            self.vals[k] = self.value(line, role)?;
        }
        // A colour is all three channels or none (empty cells).
        for group in [
            [Role::Red, Role::Green, Role::Blue],
            [Role::EmissionRed, Role::EmissionGreen, Role::EmissionBlue],
        ] {
            let given = group.map(|r| self.vals[r.index()].is_some());
            if given.contains(&true) {
                if let Some(k) = given.iter().position(|g| !g) {
                    let col = self.map.get(group[k]).unwrap_or(0);
                    return Err(self.column_error(
                        line,
                        col,
                        "empty, but the row gives other channels of its colour",
                    ));
                }
            }
        }
        self.profile = None;
        if let Some(col) = self.map.get(Role::Profile) {
            let name = text(self.field(line, col)?).trim();
            let width = self.vals[Role::Width.index()];
            if !name.is_empty() {
                let (p, _) = Profile::parse_beside(name, width).map_err(|e| {
                    let col = match e {
                        ProfileError::Width(_) => self.map.get(Role::Width).unwrap_or(col),
                        _ => col,
                    };
                    self.column_error(line, col, e.to_string())
                })?;
                self.profile = Some(p);
            }
        }
        self.element = None;
        if let Some(col) = self.map.get(Role::Element) {
            let (need_radius, need_colour) = self.element_gives;
            if need_radius || need_colour {
                let label = text(self.field(line, col)?);
                let element = super::elements::lookup(label);
                if element.is_none() && need_radius {
                    return Err(self.column_error(
                        line,
                        col,
                        format!("no radius known for element \"{label}\"; give every particle one with --radius R"),
                    ));
                }
                self.element = element;
            }
        }
        Ok(())
    }

    /// The current row as a particle; [`Self::check_row`] has accepted it.
    fn particle(&self) -> Particle<'_> {
        let get = |role: Role| self.vals[role.index()];
        let num = |role: Role| {
            let col = self.map.get(role).unwrap_or(0);
            let t = self.rec.get(col).unwrap_or(b"").trim_ascii();
            Num {
                value: get(role).unwrap_or(0.0),
                // A finite number in Rust's syntax is one in VRML's; a decimal comma is not.
                text: (!t.contains(&b',')).then_some(t),
            }
        };
        let radius = match (self.opts.radius, get(Role::Radius), get(Role::Diameter)) {
            (Some(r), _, _) => Num {
                value: r,
                text: None,
            },
            (None, Some(_), _) => num(Role::Radius),
            (None, None, Some(d)) => Num {
                value: 0.5 * d,
                text: None,
            },
            (None, None, None) => Num {
                value: self.element.map_or(1.0, |e| e.0),
                text: None,
            },
        };
        // 0-1 colours are written as read; 0-255 ones as their quotient.
        let colour = |role: Role| match self.scale {
            ColorScale::Unit => num(role),
            ColorScale::Byte => Num {
                value: get(role).unwrap_or(0.0),
                text: None,
            },
        };
        let rgb = |r: Role, g: Role, b: Role| {
            get(r)?;
            Some([colour(r), colour(g), colour(b)])
        };
        let computed = |c: [f64; 3]| c.map(|value| Num { value, text: None });
        let emission = if get(Role::Emission).is_some() {
            Some([colour(Role::Emission); 3])
        } else {
            rgb(Role::EmissionRed, Role::EmissionGreen, Role::EmissionBlue)
        };
        let transparency = get(Role::Transparency)
            .or_else(|| get(Role::Opacity).map(|o| 1.0 - o))
            .or_else(|| {
                // A density is the profile's sigma0, its value at the centre (docs/model.md
                // section 6: the diameter's optical depth is 2 r I_f sigma0).
                let i_f = self.profile.map_or(1.0, |p| p.integral());
                get(Role::Density).map(|s| (-2.0 * radius.value * i_f * s).exp())
            });
        Particle {
            position: [num(Role::X), num(Role::Y), num(Role::Z)],
            radius,
            color: rgb(Role::Red, Role::Green, Role::Blue)
                .or_else(|| self.element.map(|e| computed(e.1))),
            emission,
            transparency,
            profile: self.profile,
        }
    }
}
