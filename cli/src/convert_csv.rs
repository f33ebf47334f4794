//! `gtsphere convert`: particle tables to VRML97 ([`gtsphere::particles`]), or VRML97 back out
//! ([`super::convert_vrml`]). The input kind is decided by content: a file whose text starts
//! with `#VRML` (after gunzip) is a scene, anything else a particle table.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use gtsphere::error::Error;
use gtsphere::input::sniff;
use gtsphere::particles::ColumnSpec;
use gtsphere::particles::{self, ColorScale, Delimiter, Extras, TableOptions, WriteOptions};

/// `--delimiter` ([`Delimiter`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DelimiterArg {
    Comma,
    Semicolon,
    Tab,
    /// One or more spaces or tabs.
    Whitespace,
}

impl From<DelimiterArg> for Delimiter {
    fn from(a: DelimiterArg) -> Self {
        match a {
            DelimiterArg::Comma => Delimiter::Comma,
            DelimiterArg::Semicolon => Delimiter::Semicolon,
            DelimiterArg::Tab => Delimiter::Tab,
            DelimiterArg::Whitespace => Delimiter::Whitespace,
        }
    }
}

/// `--color-scale` ([`ColorScale`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorScaleArg {
    /// Floats from 0 to 1.
    #[value(name = "1")]
    Unit,
    /// Integers from 0 to 255.
    #[value(name = "255")]
    Byte,
}

impl From<ColorScaleArg> for ColorScale {
    fn from(a: ColorScaleArg) -> Self {
        match a {
            ColorScaleArg::Unit => ColorScale::Unit,
            ColorScaleArg::Byte => ColorScale::Byte,
        }
    }
}

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// Input: a particle table (.csv, .tsv, .txt, .xyz, ...; may be gzipped) or a VRML97
    /// scene (.wrl, .wrz, .wrl.gz).
    pub input: PathBuf,
    /// Output .wrl file (written to a temporary name, then renamed).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Column roles: `ROLE=NAME` or `ROLE=NUMBER` (1-based) to map other names, e.g.
    /// `--columns x=posx,radius=size`; or the names of all columns in order for files without
    /// a header, e.g. `--columns element,x,y,z` (`skip` for unused columns). Roles: x, y, z,
    /// radius, diameter, red, green, blue, density, opacity, transparency, emission,
    /// emission_red, emission_green, emission_blue, element (van der Waals radius and CPK
    /// colour when the table gives none), profile and width (a gas sphere's density profile,
    /// written as a GasParticle).
    #[arg(long, value_name = "SPEC")]
    pub columns: Vec<String>,
    /// Radius of every particle (when the table has no radius column; overrides one).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub radius: Option<f64>,
    /// Field separator (default: guessed from the first line).
    #[arg(long, value_enum)]
    pub delimiter: Option<DelimiterArg>,
    /// Colour values are 0-1 floats (`1`) or 0-255 integers (`255`) (default: guessed from
    /// the first 1000 rows).
    #[arg(long, value_enum, value_name = "1|255")]
    pub color_scale: Option<ColorScaleArg>,
    /// Skip bad rows (and say how many) instead of stopping at the first.
    #[arg(long)]
    pub skip_bad: bool,
    /// Write Transform/Shape/Sphere nodes instead of `PROTO Particle` instances.
    #[arg(long)]
    pub plain: bool,
    /// Do not add a Viewpoint that frames the particles.
    #[arg(long)]
    pub no_viewpoint: bool,
    /// Do not add lights (a key and a fill DirectionalLight, headlight off).
    #[arg(long)]
    pub no_lights: bool,
    /// Turn every warning of the VRML reader into an error (VRML input).
    #[arg(long)]
    pub strict: bool,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

impl ConvertArgs {
    /// The options that only mean something for particle tables, by flag name, if given.
    fn table_flags(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        let flags = [
            (!self.columns.is_empty(), "--columns"),
            (self.radius.is_some(), "--radius"),
            (self.delimiter.is_some(), "--delimiter"),
            (self.color_scale.is_some(), "--color-scale"),
            (self.skip_bad, "--skip-bad"),
            (self.plain, "--plain"),
            (self.no_viewpoint, "--no-viewpoint"),
            (self.no_lights, "--no-lights"),
        ];
        for (given, name) in flags {
            if given {
                v.push(name);
            }
        }
        v
    }
}

fn open(path: &Path) -> Result<Box<dyn Read>, Error> {
    let io = |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    };
    let file = File::open(path).map_err(io)?;
    Ok(sniff(file).map_err(io)?)
}

/// Whether the (decompressed) input starts with the VRML header.
fn is_vrml(path: &Path) -> Result<bool, Error> {
    let mut head = Vec::with_capacity(5);
    open(path)?
        .take(5)
        .read_to_end(&mut head)
        .map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e,
        })?;
    Ok(head == b"#VRML")
}

pub fn run(args: &ConvertArgs) -> Result<ExitCode, Error> {
    if is_vrml(&args.input)? {
        let flags = args.table_flags();
        if !flags.is_empty() {
            return Err(Error::Other(format!(
                "{}: is a VRML scene; {} only apply to particle tables",
                args.input.display(),
                flags.join(", ")
            )));
        }
        return super::convert_vrml::run(&args.input, &args.output, args.strict, args.quiet);
    }
    if let Some(r) = args.radius.filter(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(Error::Other(format!(
            "--radius {r}: a radius must be a positive finite number"
        )));
    }
    let columns = ColumnSpec::parse(&args.columns).map_err(Error::Other)?;
    let table = TableOptions {
        columns,
        radius: args.radius,
        delimiter: args.delimiter.map(Delimiter::from),
        color_scale: args.color_scale.map(ColorScale::from),
        skip_bad: args.skip_bad,
    };
    let opts = WriteOptions {
        plain: args.plain,
        extras: Extras {
            viewpoint: !args.no_viewpoint,
            lights: !args.no_lights,
        },
    };
    // Progress over the bytes of the (possibly compressed) file; drawn only on a terminal.
    let size = std::fs::metadata(&args.input).map(|m| m.len()).ok();
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(size, ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] {binary_bytes}/{binary_total_bytes} ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar
    };
    let file = File::open(&args.input).map_err(|e| Error::Io {
        path: args.input.display().to_string(),
        source: e,
    })?;
    let input = sniff(bar.wrap_read(file)).map_err(|e| Error::Io {
        path: args.input.display().to_string(),
        source: e,
    })?;
    let name = args.input.display().to_string();
    let converted = particles::convert_to_file(&name, input, &args.output, table, opts);
    bar.finish_and_clear();
    let s = converted?;
    if !args.quiet {
        for n in &s.notes {
            eprintln!("{name}: {n}");
        }
        if s.skipped > 0 {
            if let Some(first) = &s.first_skip {
                eprintln!(
                    "skipped {} bad row{}; the first: {}",
                    s.skipped,
                    if s.skipped == 1 { "" } else { "s" },
                    first.headline()
                );
            }
        }
        let bounds = s
            .bounds
            .map(|(lo, hi)| format!(", bounds {lo} .. {hi}"))
            .unwrap_or_default();
        eprintln!(
            "wrote {} ({} particle{}{bounds})",
            args.output.display(),
            s.particles,
            if s.particles == 1 { "" } else { "s" }
        );
    }
    Ok(ExitCode::SUCCESS)
}
