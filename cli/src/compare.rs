//! `gtsphere compare IMAGE REFERENCE [--heatmap diff.png] [--max-rmse X]`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use gtsphere::compare::{heatmap, metrics};
use gtsphere::error::Error;
use gtsphere::output::{read_image, write_image};

pub fn run(
    image: &Path,
    reference: &Path,
    heatmap_path: Option<&PathBuf>,
    heatmap_max: Option<f64>,
    max_rmse: Option<f64>,
) -> Result<ExitCode, Error> {
    let a = read_image(image)?;
    let b = read_image(reference)?;
    let what = |m: String| {
        Error::Other(format!(
            "{} vs {}: {m}",
            image.display(),
            reference.display()
        ))
    };
    let m = metrics(&a, &b).map_err(what)?;
    println!("image      {}", image.display());
    println!("reference  {}", reference.display());
    println!("rmse           {:.6e}", m.rmse);
    println!("relative rmse  {:.6e}", m.relative_rmse);
    println!("psnr           {:.2} dB", m.psnr);
    println!(
        "max abs error  {:.6e} at pixel ({}, {})",
        m.max_abs, m.max_at.0, m.max_at.1
    );
    if let Some(p) = heatmap_path {
        let h = heatmap(&a, &b, heatmap_max).map_err(what)?;
        write_image(p, &h)?;
        println!("heatmap        {}", p.display());
    }
    if let Some(limit) = max_rmse {
        if m.rmse.is_nan() || m.rmse > limit {
            eprintln!("rmse {:.6e} exceeds --max-rmse {limit:e}", m.rmse);
            return Ok(ExitCode::from(1));
        }
    }
    Ok(ExitCode::SUCCESS)
}
