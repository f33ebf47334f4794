//! `gtsphere bench scale`: the whole path of particle data at growing N.
//! For each N: a generated particle table (`scenes::write_table`, as `bench convert`), its
//! conversion to VRML (`PROTO Particle` instances, as `gtsphere convert` writes them), then
//! `gtsphere render` of that file in a child process (so that its peak resident memory is
//! the whole command's: reading, building, rendering), whose `--stats` give the seconds of
//! each step.
//!
//! The files are kept in `--dir` (default: the system temp folder) and reused by later runs;
//! a 1e8 table needs about 6.5 GB and its VRML about 12 GB of disk.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

use super::convert::{generate, options};
use gtsphere::error::Error;
use gtsphere::particles::{self, TableOptions};

/// One N's measurements.
struct Step {
    n: usize,
    vrml_mb: f64,
    convert_s: f64,
    load_s: f64,
    build_s: f64,
    render_s: f64,
    whole_s: f64,
    peak: u64,
}

/// `value` of the `--stats` line starting with `key`.
fn stat(stdout: &str, key: &str) -> Option<f64> {
    stdout
        .lines()
        .find(|l| l.starts_with(key))?
        .split_whitespace()
        .last()?
        .parse()
        .ok()
}

/// The VRML file for `n` particles, converted from the generated table unless already there;
/// the conversion's seconds (0 when reused).
fn vrml_for(dir: &Path, n: usize) -> Result<(PathBuf, f64), Error> {
    let wrl = dir.join(format!("gtsphere-bench-scale-{n}.wrl"));
    if wrl.is_file() {
        return Ok((wrl, 0.0));
    }
    let table = generate(dir, n)?;
    let name = table.display().to_string();
    let input = std::fs::File::open(&table).map_err(|e| Error::Io {
        path: name.clone(),
        source: e,
    })?;
    let t0 = Instant::now();
    particles::convert_to_file(
        &name,
        Box::new(std::io::BufReader::with_capacity(1 << 16, input)),
        &wrl,
        TableOptions::default(),
        options(),
    )?;
    Ok((wrl, t0.elapsed().as_secs_f64()))
}

fn measure(dir: &Path, n: usize, size: u32, threads: usize) -> Result<Step, Error> {
    let (wrl, convert_s) = vrml_for(dir, n)?;
    let vrml_mb = std::fs::metadata(&wrl).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
    let exe = std::env::current_exe().map_err(|e| Error::Other(format!("own path: {e}")))?;
    let out = dir.join(format!("gtsphere-bench-scale-{n}.png"));
    let t0 = Instant::now();
    let child = Command::new(exe)
        .arg("render")
        .arg(&wrl)
        .arg("-o")
        .arg(&out)
        .args(["--width", &size.to_string(), "--height", &size.to_string()])
        .args(["--spp", "1", "--threads", &threads.to_string()])
        .args(["--stats", "--quiet"])
        .output()
        .map_err(|e| Error::Other(format!("cannot run gtsphere render: {e}")))?;
    let whole_s = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    if !child.status.success() {
        return Err(Error::Other(format!(
            "gtsphere render {} failed:\n{}",
            wrl.display(),
            String::from_utf8_lossy(&child.stderr)
        )));
    }
    let stdout = String::from_utf8_lossy(&child.stdout);
    let get = |key: &str| {
        stat(&stdout, key).ok_or_else(|| {
            Error::Other(format!(
                "gtsphere render --stats printed no '{key}':\n{stdout}"
            ))
        })
    };
    Ok(Step {
        n,
        vrml_mb,
        convert_s,
        load_s: get("load seconds")?,
        build_s: get("prepare seconds")?,
        render_s: get("render seconds")?,
        whole_s,
        peak: get("peak resident")? as u64,
    })
}

pub fn run(
    sizes: &[usize],
    size: u32,
    threads: usize,
    dir: Option<PathBuf>,
) -> Result<ExitCode, Error> {
    let dir = dir.unwrap_or_else(std::env::temp_dir);
    println!(
        "gtsphere render FILE --width {size} --height {size} --spp 1 --threads {threads} \
         (a child process per N; FILE converted from a generated table)"
    );
    println!(
        "| N | VRML MB | convert s | read s | read particles/s | prepare (BVH) s | render s \
         | whole command s | peak MB | peak bytes/sphere |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for &n in sizes {
        let s = measure(&dir, n, size, threads)?;
        println!(
            "| {:.0e} | {:.1} | {} | {:.3} | {:.3e} | {:.3} | {:.3} | {:.3} | {:.1} | {:.0} |",
            s.n as f64,
            s.vrml_mb,
            if s.convert_s > 0.0 {
                format!("{:.2}", s.convert_s)
            } else {
                "(reused)".to_string()
            },
            s.load_s,
            s.n as f64 / s.load_s.max(1e-9),
            s.build_s,
            s.render_s,
            s.whole_s,
            s.peak as f64 / 1e6,
            s.peak as f64 / s.n.max(1) as f64,
        );
    }
    Ok(ExitCode::SUCCESS)
}
