//! `gtsphere merge PARTS... -o FULL.exr`: assembles parts written by `render --region` or
//! `--tile` into the whole picture. Every pixel must come from exactly one part; the parts
//! must agree on the whole picture's size and on their channels.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use gtsphere::error::Error;
use gtsphere::output::{read_part, write_image, Image, Layer};

pub fn run(parts: &[PathBuf], out: &Path) -> Result<ExitCode, Error> {
    let bad = |m: String| Error::Other(m);
    if parts.is_empty() {
        return Err(bad("merge needs at least one part".into()));
    }
    let mut whole: Option<(Image, Vec<u8>)> = None;
    for path in parts {
        let (part, at) = read_part(path)?;
        let (img, filled) = whole.get_or_insert_with(|| {
            let n = at.full_width * at.full_height;
            (
                Image {
                    width: at.full_width,
                    height: at.full_height,
                    rgb: vec![[0.0; 3]; n],
                    alpha: vec![0.0; n],
                    layers: part
                        .layers
                        .iter()
                        .map(|l| Layer {
                            name: l.name.clone(),
                            data: vec![0.0; n],
                        })
                        .collect(),
                },
                vec![0u8; n],
            )
        });
        if (img.width, img.height) != (at.full_width, at.full_height) {
            return Err(bad(format!(
                "{}: belongs to a {}x{} picture, the others to {}x{}",
                path.display(),
                at.full_width,
                at.full_height,
                img.width,
                img.height
            )));
        }
        let names = |v: &[Layer]| v.iter().map(|l| l.name.clone()).collect::<Vec<_>>();
        if names(&part.layers) != names(&img.layers) {
            return Err(bad(format!(
                "{}: channels {:?} differ from the first part's {:?}",
                path.display(),
                names(&part.layers),
                names(&img.layers)
            )));
        }
        for y in 0..part.height {
            for x in 0..part.width {
                let (src, dst) = (y * part.width + x, (at.y + y) * img.width + at.x + x);
                if filled[dst] != 0 {
                    return Err(bad(format!(
                        "{}: pixel ({}, {}) is already in another part",
                        path.display(),
                        at.x + x,
                        at.y + y
                    )));
                }
                filled[dst] = 1;
                img.rgb[dst] = part.rgb[src];
                img.alpha[dst] = part.alpha[src];
                for (l, pl) in img.layers.iter_mut().zip(&part.layers) {
                    l.data[dst] = pl.data[src];
                }
            }
        }
    }
    let Some((img, filled)) = whole else {
        return Err(bad("no parts".into()));
    };
    if let Some(k) = filled.iter().position(|&f| f == 0) {
        let missing = filled.iter().filter(|&&f| f == 0).count();
        return Err(bad(format!(
            "{missing} pixels are in no part (the first at ({}, {}))",
            k % img.width,
            k / img.width
        )));
    }
    write_image(out, &img)?;
    println!("merged {} parts into {}", parts.len(), out.display());
    Ok(ExitCode::SUCCESS)
}
