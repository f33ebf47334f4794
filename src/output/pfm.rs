//! PFM (Portable Float Map): a text header, then raw f32 samples, rows BOTTOM to TOP.
//!
//! ```text
//! PF\n            colour ("Pf" for greyscale)
//! W H\n           width and height in pixels
//! -1.0\n          scale: negative means little-endian, positive big-endian
//! <W*H*3 f32>     rows from the bottom of the picture up, pixels left to right
//! ```
//!
//! We write `PF`, little-endian, scale -1.0. We read `PF` and `Pf`, either byte order, and
//! multiply the samples by |scale| when it is not 1 (as pbrt does). The header must be
//! followed by exactly the samples it announces: a shorter or longer file is an error.

use std::io::Write;

use super::{Fault, Image};

pub(super) fn write(out: &mut impl Write, img: &Image) -> Result<(), Fault> {
    write!(out, "PF\n{} {}\n-1.0\n", img.width, img.height)?;
    let mut row = Vec::with_capacity(img.width * 12);
    for y in (0..img.height).rev() {
        row.clear();
        for px in &img.rgb[y * img.width..(y + 1) * img.width] {
            for c in px {
                row.extend_from_slice(&c.to_le_bytes());
            }
        }
        out.write_all(&row)?;
    }
    Ok(())
}

pub(super) fn read(bytes: &[u8]) -> Result<Image, Fault> {
    let bad = |m: String| Fault::Bad(format!("PFM: {m}"));
    let channels = match bytes.get(..2) {
        Some(b"PF") => 3,
        Some(b"Pf") => 1,
        _ => return Err(bad("does not start with 'PF' or 'Pf'".to_string())),
    };
    let mut header = Header { bytes, pos: 2 };
    let width = header.dimension("width").map_err(bad)?;
    let height = header.dimension("height").map_err(bad)?;
    let scale_text = header.token("scale").map_err(bad)?;
    let scale: f32 = scale_text
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or_else(|| {
            bad(format!(
                "scale '{}' is not a finite non-zero number",
                shown(scale_text)
            ))
        })?;
    // Exactly one whitespace byte separates the header from the samples.
    match bytes.get(header.pos) {
        Some(b) if b.is_ascii_whitespace() => header.pos += 1,
        _ => {
            return Err(bad(
                "header is not followed by a whitespace byte".to_string()
            ))
        }
    }
    let data = &bytes[header.pos..];

    let count = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels))
        .filter(|n| n.checked_mul(4).is_some())
        .ok_or_else(|| bad(format!("{width}x{height} is too large")))?;
    if data.len() != count * 4 {
        return Err(bad(format!(
            "{width}x{height} with {channels} channel(s) needs {} bytes of samples, the file has {}",
            count * 4,
            data.len()
        )));
    }
    let little = scale < 0.0;
    let factor = scale.abs();
    let samples: Vec<f32> = data
        .chunks_exact(4)
        .map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            let v = if little {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            };
            if factor == 1.0 {
                v
            } else {
                v * factor
            }
        })
        .collect();

    let mut rgb = Vec::with_capacity(width * height);
    // File rows go bottom to top; ours top to bottom.
    for y in (0..height).rev() {
        let row = &samples[y * width * channels..(y + 1) * width * channels];
        if channels == 3 {
            rgb.extend(row.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        } else {
            rgb.extend(row.iter().map(|&v| [v, v, v]));
        }
    }
    Ok(Image {
        width,
        height,
        rgb,
        alpha: vec![1.0; width * height],
        layers: Vec::new(),
    })
}

/// Whitespace-separated ASCII tokens of the header.
struct Header<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Header<'_> {
    fn token(&mut self, what: &str) -> Result<&str, String> {
        // At least one whitespace byte before each token (after the magic, too).
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(u8::is_ascii_whitespace)
        {
            self.pos += 1;
        }
        if self.pos == start {
            return Err(format!("expected whitespace before the {what}"));
        }
        let begin = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if begin == self.pos {
            return Err(format!("header ends before the {what}"));
        }
        std::str::from_utf8(&self.bytes[begin..self.pos])
            .map_err(|_| format!("{what} is not ASCII text"))
    }

    fn dimension(&mut self, what: &str) -> Result<usize, String> {
        let text = self.token(what)?;
        text.parse::<usize>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("{what} '{}' is not a positive integer", shown(text)))
    }
}

/// A header token for a message, cut short if the "header" is really something else.
fn shown(text: &str) -> String {
    const MAX: usize = 24;
    match text.char_indices().nth(MAX) {
        Some((cut, _)) => format!("{}...", &text[..cut]),
        None => text.to_string(),
    }
}
