//! `gtsphere bench parse`: parse speed and peak memory on generated particle files.
//!
//! Each measurement runs `gtsphere info --json` in a fresh child process, so that its peak
//! resident memory (VmHWM) belongs to that parse alone. Reported: median MB/s over the runs,
//! IR bytes, peak resident bytes, and peak / IR.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use clap::ValueEnum;

use super::measure::median;
use gtsphere::error::Error;
use gtsphere::scenes::{self, write_particles};

/// `--layout`: how the particles are laid out in the file ([`scenes::Layout`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LayoutArg {
    /// A million top-level Transforms.
    Flat,
    /// A million children of one Group (what VMD-style exporters write).
    Group,
}

impl From<LayoutArg> for scenes::Layout {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Flat => scenes::Layout::Flat,
            LayoutArg::Group => scenes::Layout::Group,
        }
    }
}

fn generate(dir: &Path, n: usize, layout: scenes::Layout) -> Result<PathBuf, Error> {
    let name = format!(
        "gtsphere-bench-{}-{n}.wrl",
        format!("{layout:?}").to_lowercase()
    );
    let path = dir.join(name);
    if path.is_file() {
        return Ok(path);
    }
    let io = |e| Error::Io {
        path: path.display().to_string(),
        source: e,
    };
    let tmp = path.with_extension("wrl.part");
    let file = std::fs::File::create(&tmp).map_err(io)?;
    let mut w = BufWriter::with_capacity(1 << 20, file);
    write_particles(&mut w, n, layout).map_err(io)?;
    w.flush().map_err(io)?;
    drop(w);
    std::fs::rename(&tmp, &path).map_err(io)?;
    Ok(path)
}

pub fn run(
    particles: usize,
    runs: usize,
    dir: Option<PathBuf>,
    layout: Vec<LayoutArg>,
) -> Result<ExitCode, Error> {
    let dir = dir.unwrap_or_else(std::env::temp_dir);
    let exe = std::env::current_exe()
        .map_err(|e| Error::Other(format!("cannot find own executable: {e}")))?;
    println!("| layout | particles | file MB | median MB/s | median s | IR MB | peak RSS MB | peak / IR |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for l in layout {
        let l = scenes::Layout::from(l);
        let path = generate(&dir, particles, l)?;
        let mut speeds = Vec::new();
        let mut secs = Vec::new();
        let mut ir = 0.0;
        let mut peak: f64 = 0.0;
        let mut bytes = 0.0;
        for _ in 0..runs.max(1) {
            let out = Command::new(&exe)
                .args(["info", "--json"])
                .arg(&path)
                .output()
                .map_err(|e| Error::Other(format!("cannot run {}: {e}", exe.display())))?;
            if !out.status.success() {
                return Err(Error::Other(
                    String::from_utf8_lossy(&out.stderr).into_owned(),
                ));
            }
            let v: serde_json::Value = serde_json::from_slice(&out.stdout)
                .map_err(|e| Error::Other(format!("bad JSON from info: {e}")))?;
            speeds.push(v["mb_per_s"].as_f64().unwrap_or(0.0));
            secs.push(v["parse_seconds"].as_f64().unwrap_or(0.0));
            ir = v["ir_bytes"].as_f64().unwrap_or(0.0) / 1e6;
            bytes = v["bytes_read"].as_f64().unwrap_or(0.0) / 1e6;
            peak = peak.max(v["peak_rss_bytes"].as_f64().unwrap_or(0.0) / 1e6);
        }
        println!(
            "| {:?} | {} | {:.1} | {:.1} | {:.3} | {:.1} | {:.1} | {:.2} |",
            l,
            particles,
            bytes,
            median(speeds),
            median(secs),
            ir,
            peak,
            if ir > 0.0 { peak / ir } else { 0.0 }
        );
    }
    Ok(ExitCode::SUCCESS)
}
