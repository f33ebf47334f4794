//! `gtsphere bench parse`: parse speed and peak memory on generated particle files.
//!
//! Each measurement runs `gtsphere info --json` in a fresh child process, so that its peak
//! resident memory (VmHWM) belongs to that parse alone. Each run reads the file once by one
//! reader and once on `--read-threads` threads, alternately (the machines are shared: a
//! ratio of runs made side by side means more than either time). Reported per reader count:
//! median MB/s and seconds, particles per second per thread, IR bytes, peak resident bytes,
//! peak / IR; and the median of the runs' speed-ups.

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
    /// N top-level Transforms.
    Flat,
    /// N children of one Group (what VMD-style exporters write).
    Group,
    /// N PROTO instances, as `gtsphere convert` writes them (of a generated table).
    Proto,
}

impl From<LayoutArg> for scenes::Layout {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Flat => scenes::Layout::Flat,
            LayoutArg::Group => scenes::Layout::Group,
            LayoutArg::Proto => unreachable!("converted, not generated"),
        }
    }
}

fn generate(dir: &Path, n: usize, layout: LayoutArg) -> Result<PathBuf, Error> {
    let name = format!(
        "gtsphere-bench-{}-{n}.wrl",
        format!("{layout:?}").to_lowercase()
    );
    let path = dir.join(name);
    if path.is_file() {
        return Ok(path);
    }
    if layout == LayoutArg::Proto {
        let mut table = Vec::new();
        scenes::write_table(&mut table, n).map_err(|e| Error::Other(e.to_string()))?;
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

/// One `gtsphere info --json` of `path` on `threads` reading threads.
fn measure(exe: &Path, path: &Path, threads: usize) -> Result<serde_json::Value, Error> {
    let out = Command::new(exe)
        .args(["info", "--json", "--read-threads", &threads.to_string()])
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

pub fn run(
    particles: usize,
    runs: usize,
    dir: Option<PathBuf>,
    layout: Vec<LayoutArg>,
    read_threads: usize,
) -> Result<ExitCode, Error> {
    let dir = dir.unwrap_or_else(std::env::temp_dir);
    let exe = std::env::current_exe()
        .map_err(|e| Error::Other(format!("cannot find own executable: {e}")))?;
    let threads = [1, read_threads.max(2)];
    println!("| layout | particles | file MB | read threads | pieces | median MB/s | median s | particles/s/thread | speed-up | IR MB | peak RSS MB | peak / IR |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for l in layout {
        let path = generate(&dir, particles, l)?;
        // secs[k], for threads[k], run by run.
        let mut secs = [Vec::new(), Vec::new()];
        let mut speeds = [Vec::new(), Vec::new()];
        let mut peak = [0.0f64; 2];
        let mut pieces = [0u64; 2];
        let (mut ir, mut bytes) = (0.0, 0.0);
        for _ in 0..runs.max(1) {
            for (k, &t) in threads.iter().enumerate() {
                let v = measure(&exe, &path, t)?;
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
