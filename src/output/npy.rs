//! NPY (NumPy's array file, format version 1.0): the RGB pixels as an `H x W x 3` array of
//! little-endian float64, row 0 at the top, so that `numpy.load` gives every digit the
//! integrators computed (PFM and EXR hold f32).
//!
//! ```text
//! \x93NUMPY 1 0      magic and version
//! <u16 LE>           header length; magic + 2 + 2 + header is a multiple of 64
//! {'descr': '<f8', 'fortran_order': False, 'shape': (H, W, 3), }   padded with spaces, '\n'
//! <H*W*3 f64 LE>     row-major: rows from the top, pixels left to right, R G B
//! ```

use std::io::Write;

use super::{Fault, Image};

/// The header of an `H x W x 3` float64 array.
fn header(height: usize, width: usize) -> Vec<u8> {
    header_of_shape(&format!("({height}, {width}, 3)"))
}

/// The header of a float64 array of shape `shape` (a Python tuple).
fn header_of_shape(shape: &str) -> Vec<u8> {
    let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    // magic (6) + version (2) + length (2) + dict + padding + '\n' = a multiple of 64.
    let unpadded = 10 + dict.len() + 1;
    let pad = (64 - unpadded % 64) % 64;
    let mut h = Vec::with_capacity(unpadded + pad);
    h.extend_from_slice(b"\x93NUMPY\x01\x00");
    let len = (dict.len() + pad + 1) as u16;
    h.extend_from_slice(&len.to_le_bytes());
    h.extend_from_slice(dict.as_bytes());
    h.extend(std::iter::repeat_n(b' ', pad));
    h.push(b'\n');
    h
}

/// Writes `rgb` (`width * height` pixels, row 0 at the top) as float64.
pub(super) fn write_f64(
    out: &mut impl Write,
    width: usize,
    height: usize,
    rgb: &[[f64; 3]],
) -> std::io::Result<()> {
    out.write_all(&header(height, width))?;
    let mut row = Vec::with_capacity(width * 24);
    for line in rgb.chunks(width.max(1)) {
        row.clear();
        for c in line.iter().flatten() {
            row.extend_from_slice(&c.to_le_bytes());
        }
        out.write_all(&row)?;
    }
    Ok(())
}

/// Writes `rows` (each of `columns` values) as an `N x columns` float64 array.
pub(super) fn write_table(
    out: &mut impl Write,
    columns: usize,
    rows: &[Vec<f64>],
) -> std::io::Result<()> {
    out.write_all(&header_of_shape(&format!("({}, {columns})", rows.len())))?;
    for row in rows {
        for v in row {
            out.write_all(&v.to_le_bytes())?;
        }
    }
    Ok(())
}

/// An [`Image`]'s f32 pixels, widened exactly.
pub(super) fn write(out: &mut impl Write, img: &Image) -> Result<(), Fault> {
    let rgb: Vec<[f64; 3]> = img.rgb.iter().map(|p| p.map(f64::from)).collect();
    write_f64(out, img.width, img.height, &rgb)?;
    Ok(())
}

/// Reads what [`write_f64`] writes (an `H x W x 3` little-endian float64 C-order array),
/// rounded to an [`Image`]'s f32, alpha 1.
pub(super) fn read(bytes: &[u8]) -> Result<Image, Fault> {
    let bad = |m: &str| Fault::Bad(format!("NPY: {m}"));
    if bytes.get(..8) != Some(b"\x93NUMPY\x01\x00") {
        return Err(bad("not a version 1.0 .npy file"));
    }
    let len = match bytes.get(8..10) {
        Some(&[a, b]) => u16::from_le_bytes([a, b]) as usize,
        _ => return Err(bad("truncated header")),
    };
    let dict = bytes
        .get(10..10 + len)
        .and_then(|d| std::str::from_utf8(d).ok())
        .ok_or_else(|| bad("truncated header"))?;
    if !dict.contains("'descr': '<f8'") || !dict.contains("'fortran_order': False") {
        return Err(bad("not a little-endian float64 C-order array"));
    }
    let shape = dict
        .split("'shape': (")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("no shape"))?;
    let dims: Vec<usize> = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| bad("shape is not integers")))
        .collect::<Result<_, _>>()?;
    let [height, width, 3] = dims[..] else {
        return Err(bad("shape is not (height, width, 3)"));
    };
    let data = bytes.get(10 + len..).unwrap_or_default();
    let n = width
        .checked_mul(height)
        .ok_or_else(|| bad("shape overflows"))?;
    if Some(data.len()) != n.checked_mul(24) || n == 0 {
        return Err(bad("data length does not match the shape"));
    }
    let rgb = data
        .chunks_exact(24)
        .map(|p| {
            [0, 1, 2].map(|k| {
                f64::from_le_bytes(p[8 * k..8 * k + 8].try_into().expect("8 bytes")) as f32
            })
        })
        .collect();
    Ok(Image {
        width,
        height,
        rgb,
        alpha: vec![1.0; n],
        layers: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_header_pads_to_64_bytes() {
        for (h, w) in [(1, 1), (480, 640), (123_456, 7)] {
            let b = super::header(h, w);
            assert_eq!(b.len() % 64, 0);
            assert_eq!(*b.last().unwrap(), b'\n');
            assert_eq!(u16::from_le_bytes([b[8], b[9]]) as usize, b.len() - 10);
        }
    }
}
