//! `gtsphere bench parse`: reading speed and peak memory on particle files as users have
//! them. The files: generated Transforms (flat or in one Group), `convert`'s PROTO instances
//! of a table with 8-bit colours and of one with a continuous colour per particle, and copies
//! of a tool's export (`--copies-of FILE`) side by side until there are N spheres.
//!
//! Each measurement runs `gtsphere info --json` in a fresh child process, so that its peak
//! resident memory (VmHWM) belongs to that parse alone. Each run reads the file once by one
//! reader and once on `--read-threads` threads, alternately (the machines are shared: a
//! ratio of runs made side by side means more than either time). Reported per reader count:
//! median MB/s and seconds, particles per second per thread, IR bytes, peak resident bytes,
//! peak / IR; and the median of the runs' speed-ups.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use clap::{Args, ValueEnum};

use super::measure::median;
use gtsphere::bench::scenes::{self, write_particles};
use gtsphere::error::Error;
use gtsphere::output::write_file_atomically;

/// Arguments of `gtsphere bench parse`.
#[derive(Debug, Args)]
pub struct ParseArgs {
    /// Number of particles.
    #[arg(long, default_value_t = 1_000_000)]
    pub particles: usize,
    /// Runs per layout (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Where the generated files go (kept for reuse). Default: the system temp folder.
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Which layouts to measure.
    #[arg(long, value_enum, default_values_t = [LayoutArg::Flat, LayoutArg::Group, LayoutArg::Proto])]
    pub layout: Vec<LayoutArg>,
    /// Reading threads of the runs in pieces (each is paired with a run by one reader).
    #[arg(long, default_value_t = 2)]
    pub read_threads: usize,
    /// The file `--layout copies` copies (a tool's export, for example).
    #[arg(long, value_name = "FILE")]
    pub copies_of: Option<PathBuf>,
    /// Read without the reader's fast paths (every PROTO instance replayed, every sphere
    /// node read event by event), for measuring what they save.
    #[arg(long, hide = true)]
    pub replay_every_instance: bool,
}

/// `--layout`: how the particles are laid out in the file ([`scenes::Layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LayoutArg {
    /// N top-level Transforms.
    Flat,
    /// N children of one Group (what VMD-style exporters write).
    Group,
    /// N PROTO instances, as `gtsphere convert` writes them (of a generated table with 8-bit
    /// colours: few distinct colours).
    Proto,
    /// As proto, of a table with a continuous colour per particle (6 decimals, as a colour
    /// map writes): every particle a colour of its own.
    Continuous,
    /// Copies of the file given by --copies-of, each in a Transform of its own, until they
    /// hold N spheres.
    Copies,
}

impl From<LayoutArg> for scenes::Layout {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Flat => scenes::Layout::Flat,
            LayoutArg::Group => scenes::Layout::Group,
            LayoutArg::Proto | LayoutArg::Continuous | LayoutArg::Copies => {
                unreachable!("converted or copied, not generated")
            }
        }
    }
}

fn generate(
    dir: &Path,
    n: usize,
    layout: LayoutArg,
    copies_of: Option<&Path>,
) -> Result<PathBuf, Error> {
    let stem = match (layout, copies_of) {
        (LayoutArg::Copies, Some(f)) => format!(
            "copies-{}",
            f.file_stem().unwrap_or_default().to_string_lossy()
        ),
        (LayoutArg::Copies, None) => {
            return Err(Error::Other(
                "--layout copies needs --copies-of FILE".to_string(),
            ))
        }
        _ => format!("{layout:?}").to_lowercase(),
    };
    let path = dir.join(format!("gtsphere-bench-{stem}-{n}.wrl"));
    if path.is_file() {
        return Ok(path);
    }
    if let (LayoutArg::Copies, Some(file)) = (layout, copies_of) {
        return write_copies(file, n, &path).map(|()| path);
    }
    if matches!(layout, LayoutArg::Proto | LayoutArg::Continuous) {
        let colours = if layout == LayoutArg::Proto {
            scenes::TableColours::Bytes
        } else {
            scenes::TableColours::Continuous
        };
        let mut table = Vec::new();
        scenes::write_table(&mut table, n, colours).map_err(|e| Error::Other(e.to_string()))?;
        gtsphere::particles::convert_to_file(
            "generated.csv",
            Box::new(std::io::Cursor::new(table)),
            &path,
            gtsphere::particles::TableOptions::default(),
            gtsphere::particles::WriteOptions {
                plain: false,
                extras: gtsphere::particles::Extras {
                    viewpoint: true,
                    lights: true,
                },
            },
        )?;
        return Ok(path);
    }
    let layout = scenes::Layout::from(layout);
    write_file_atomically(&path, |w| write_particles(w, n, layout))?;
    Ok(path)
}

/// Copies of `file` (a VRML97 scene, gzip or not) until they hold at least `n` spheres, each
/// in a Transform moved along x by the file's width, written to `path`. The file's header
/// line is written once; everything else of it, PROTOs and DEFs included, in every copy.
fn write_copies(file: &Path, n: usize, path: &Path) -> Result<(), Error> {
    let (scene, _) = gtsphere::vrml::load_path(file, &gtsphere::vrml::LoadOptions::default())?;
    let spheres = scene.spheres.len();
    if spheres == 0 {
        return Err(Error::Other(format!(
            "{}: no spheres to copy",
            file.display()
        )));
    }
    let width = scene
        .bounds()
        .map_or(1.0, |b| (b.max[0] - b.min[0]).max(1e-3));
    let read_err = |e| Error::Io {
        path: file.display().to_string(),
        source: e,
    };
    let mut text = String::new();
    let raw = std::fs::File::open(file).map_err(read_err)?;
    std::io::Read::read_to_string(
        &mut gtsphere::input::sniff(raw).map_err(read_err)?,
        &mut text,
    )
    .map_err(read_err)?;
    let body = text.split_once('\n').map_or("", |(_, rest)| rest);
    write_file_atomically(path, |w| {
        writeln!(w, "#VRML V2.0 utf8")?;
        for k in 0..n.div_ceil(spheres) {
            let x = k as f64 * 1.1 * width;
            writeln!(
                w,
                "Transform {{ translation {x} 0 0 children [\n{body}\n] }}"
            )?;
        }
        Ok(())
    })
}

/// One `gtsphere info --json` of `path` on `threads` reading threads.
fn measure(
    exe: &Path,
    path: &Path,
    threads: usize,
    replay: bool,
) -> Result<serde_json::Value, Error> {
    let out = Command::new(exe)
        .args(["info", "--json", "--read-threads", &threads.to_string()])
        .args(replay.then_some("--replay-every-instance"))
        .arg(path)
        .output()
        .map_err(|e| Error::Other(format!("cannot run {}: {e}", exe.display())))?;
    if !out.status.success() {
        return Err(Error::Other(
            String::from_utf8_lossy(&out.stderr).into_owned(),
        ));
    }
    serde_json::from_slice(&out.stdout)
        .map_err(|e| Error::Other(format!("bad JSON from info: {e}")))
}

pub fn run(args: &ParseArgs) -> Result<ExitCode, Error> {
    let (particles, runs) = (args.particles, args.runs);
    let dir = args.dir.clone().unwrap_or_else(std::env::temp_dir);
    let exe = std::env::current_exe()
        .map_err(|e| Error::Other(format!("cannot find own executable: {e}")))?;
    let threads = [1, args.read_threads.max(2)];
    println!("| layout | particles | file MB | read threads | pieces | median MB/s | median s | particles/s/thread | speed-up | IR MB | peak RSS MB | peak / IR |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for &l in &args.layout {
        let path = generate(&dir, particles, l, args.copies_of.as_deref())?;
        // secs[k], for threads[k], run by run.
        let mut secs = [Vec::new(), Vec::new()];
        let mut speeds = [Vec::new(), Vec::new()];
        let mut peak = [0.0f64; 2];
        let mut pieces = [0u64; 2];
        let (mut ir, mut bytes) = (0.0, 0.0);
        for _ in 0..runs.max(1) {
            for (k, &t) in threads.iter().enumerate() {
                let v = measure(&exe, &path, t, args.replay_every_instance)?;
                speeds[k].push(v["mb_per_s"].as_f64().unwrap_or(0.0));
                secs[k].push(v["parse_seconds"].as_f64().unwrap_or(0.0));
                ir = v["ir_bytes"].as_f64().unwrap_or(0.0) / 1e6;
                bytes = v["bytes_read"].as_f64().unwrap_or(0.0) / 1e6;
                peak[k] = peak[k].max(v["peak_rss_bytes"].as_f64().unwrap_or(0.0) / 1e6);
                pieces[k] = v["read_pieces"].as_u64().unwrap_or(0);
            }
        }
        let ratios: Vec<f64> = secs[0]
            .iter()
            .zip(&secs[1])
            .map(|(a, b)| if *b > 0.0 { a / b } else { 0.0 })
            .collect();
        let speedup = median(ratios);
        for (k, &t) in threads.iter().enumerate() {
            let s = median(secs[k].clone());
            println!(
                "| {:?} | {} | {:.1} | {} | {} | {:.1} | {:.3} | {:.3e} | {} | {:.1} | {:.1} | {:.2} |",
                l,
                particles,
                bytes,
                t,
                pieces[k],
                median(speeds[k].clone()),
                s,
                if s > 0.0 { particles as f64 / s / t as f64 } else { 0.0 },
                if k == 0 { "1".to_string() } else { format!("{speedup:.2}") },
                ir,
                peak[k],
                if ir > 0.0 { peak[k] / ir } else { 0.0 }
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
