//! PNG: an 8-bit sRGB preview. RGB only; alpha and layers live in the EXR.
//!
//! No alpha because the colour already holds whatever was behind the spheres (background or
//! black), so the picture is final as it is; an 8-bit alpha would only invite compositing it a
//! second time.

use std::io::Write;

use image::codecs::png::PngEncoder;
use image::{ExtendedColorType, ImageEncoder, ImageFormat};

use super::{Fault, Image};

pub(super) fn write(out: &mut impl Write, img: &Image) -> Result<(), Fault> {
    let (w, h) = match (u32::try_from(img.width), u32::try_from(img.height)) {
        (Ok(w), Ok(h)) => (w, h),
        _ => {
            return Err(Fault::Bad(format!(
                "{}x{} is too large for PNG",
                img.width, img.height
            )))
        }
    };
    let bytes: Vec<u8> = img.rgb.iter().flatten().map(|&c| encode(c)).collect();
    PngEncoder::new(out)
        .write_image(&bytes, w, h, ExtendedColorType::Rgb8)
        .map_err(image_fault)
}

pub(super) fn read(bytes: &[u8]) -> Result<Image, Fault> {
    let decoded =
        image::load_from_memory_with_format(bytes, ImageFormat::Png).map_err(image_fault)?;
    let has_alpha = decoded.color().has_alpha();
    // Normalises to [0,1] (v / 255 or v / 65535) without any colour conversion; PNG alpha is
    // linear already, only the colour goes back through the transfer function.
    let rgba = decoded.to_rgba32f();
    let (width, height) = (rgba.width() as usize, rgba.height() as usize);
    let mut rgb = Vec::with_capacity(width * height);
    let mut alpha = Vec::with_capacity(width * height);
    for p in rgba.pixels() {
        rgb.push([decode(p[0]), decode(p[1]), decode(p[2])]);
        alpha.push(if has_alpha { p[3] } else { 1.0 });
    }
    Ok(Image {
        width,
        height,
        rgb,
        alpha,
        layers: Vec::new(),
    })
}

fn image_fault(e: image::ImageError) -> Fault {
    match e {
        image::ImageError::IoError(e) => Fault::Io(e),
        e => Fault::Bad(format!("PNG: {e}")),
    }
}

/// Linear to an 8-bit sRGB code: the exact piecewise curve (IEC 61966-2-1), not gamma 2.2.
/// Clamped to [0,1] first, NaN to 0, rounded to nearest. In f64 so the rounding is that of
/// the curve, not of f32 `powf`.
fn encode(linear: f32) -> u8 {
    let c = if linear.is_nan() {
        0.0
    } else {
        f64::from(linear).clamp(0.0, 1.0)
    };
    let v = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    // v is in [0, 1] (1.0 maps to 254.99999999999997 before rounding), so the cast is exact.
    (v * 255.0).round() as u8
}

/// An sRGB value in [0,1] back to linear, the inverse of the curve in [`encode`].
fn decode(v: f32) -> f32 {
    let v = f64::from(v);
    let c = if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    };
    c as f32
}

#[cfg(test)]
mod tests {
    use super::{decode, encode};

    /// Decoding every code and encoding it again gives the same code.
    #[test]
    fn every_code_survives_decode_then_encode() {
        for code in 0..=255u8 {
            assert_eq!(encode(decode(f32::from(code) / 255.0)), code);
        }
    }
}
