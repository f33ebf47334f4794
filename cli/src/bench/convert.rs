//! `gtsphere bench convert`: particle CSV to VRML, rows and megabytes per second on one core,
//! and peak memory, on a generated table.
//!
//! The conversion runs in this process, after the table is generated (which streams and
//! holds little), so the process's peak resident memory (VmHWM) is the conversion's, give or
//! take the few megabytes of the program itself.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use super::measure::median;
use crate::memory::peak_rss_bytes;
use gtsphere::bench::scenes::{write_table, TableColours};
use gtsphere::error::Error;
use gtsphere::output::write_file_atomically;
use gtsphere::particles::{self, Extras, TableOptions, WriteOptions};

pub fn generate(dir: &Path, n: usize) -> Result<PathBuf, Error> {
    let path = dir.join(format!("gtsphere-bench-particles-{n}.csv"));
    if path.is_file() {
        return Ok(path);
    }
    write_file_atomically(&path, |w| write_table(w, n, TableColours::Bytes))?;
    Ok(path)
}

pub fn options() -> WriteOptions {
    WriteOptions {
        plain: false,
        extras: Extras {
            viewpoint: true,
            lights: true,
        },
    }
}

fn open(table: &Path) -> Result<Box<dyn std::io::Read>, Error> {
    let file = std::fs::File::open(table).map_err(|e| Error::Io {
        path: table.display().to_string(),
        source: e,
    })?;
    Ok(Box::new(std::io::BufReader::with_capacity(1 << 16, file)))
}

/// Seconds to convert `table` into a real file (written, synced, renamed: what `gtsphere
/// convert` does), and the file's size.
fn to_file(table: &Path, out_path: &Path) -> Result<(f64, f64), Error> {
    let name = table.display().to_string();
    let input = open(table)?;
    let t0 = Instant::now();
    particles::convert_to_file(&name, input, out_path, TableOptions::default(), options())?;
    let secs = t0.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(out_path).map(|m| m.len()).unwrap_or(0) as f64;
    let _ = std::fs::remove_file(out_path);
    Ok((secs, bytes))
}

/// Seconds to read, check and format `table` with the output thrown away (no disk writes).
fn to_sink(table: &Path) -> Result<f64, Error> {
    let name = table.display().to_string();
    let input = open(table)?;
    let t0 = Instant::now();
    particles::convert(
        &name,
        input,
        std::io::sink(),
        TableOptions::default(),
        options(),
    )?;
    Ok(t0.elapsed().as_secs_f64())
}

pub fn run(rows: usize, runs: usize, dir: Option<PathBuf>) -> Result<ExitCode, Error> {
    let dir = dir.unwrap_or_else(std::env::temp_dir);
    let table = generate(&dir, rows)?;
    let out_path = dir.join(format!("gtsphere-bench-particles-{rows}.wrl"));
    let in_mb = std::fs::metadata(&table).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
    let (mut file_secs, mut sink_secs) = (Vec::new(), Vec::new());
    let mut out_mb = 0.0;
    for _ in 0..runs.max(1) {
        sink_secs.push(to_sink(&table)?);
        let (s, bytes) = to_file(&table, &out_path)?;
        file_secs.push(s);
        out_mb = bytes / 1e6;
    }
    let peak = peak_rss_bytes().unwrap_or(0) as f64 / 1e6;
    println!(
        "{rows} rows: CSV {in_mb:.1} MB, VRML {out_mb:.1} MB, peak resident memory {peak:.1} MB"
    );
    println!("| output | median s | rows/s | CSV MB/s |");
    println!("|---|---:|---:|---:|");
    for (what, secs) in [
        ("file (written, synced, renamed)", file_secs),
        ("discarded (read, check, format)", sink_secs),
    ] {
        let s = median(secs);
        println!(
            "| {what} | {s:.3} | {:.3e} | {:.1} |",
            rows as f64 / s,
            in_mb / s
        );
    }
    Ok(ExitCode::SUCCESS)
}
