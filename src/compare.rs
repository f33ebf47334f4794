//! Image comparison: error metrics of an image against a reference, and a false-colour error
//! heat map with a legend.
//!
//! All metrics run over every RGB channel value of every pixel (alpha and extra layers are
//! ignored):
//! - `rmse = sqrt(mean (a - b)^2)`;
//! - `relative_rmse = rmse / sqrt(mean b^2)` (`b` is the reference; 0 when both are black);
//! - `psnr = 20 log10(peak / rmse)` dB, `peak` = the reference's largest value (1 if that is
//!   not positive); infinite for identical images;
//! - `max_abs` = the largest `|a - b|`, at pixel `max_at` (x, y; row 0 at the top).

use crate::output::Image;

/// Error metrics of an image against a reference (see the module comment for definitions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Root mean square of the differences, over every channel value.
    pub rmse: f64,
    /// `rmse` over the reference's root mean square; when the reference is black, 0 for an
    /// identical image and infinite otherwise.
    pub relative_rmse: f64,
    /// Peak signal-to-noise ratio in dB; infinite for identical images.
    pub psnr: f64,
    /// The largest absolute difference of one channel value (NaN if any difference is NaN).
    pub max_abs: f64,
    /// The pixel `(x, y)` of `max_abs`, row 0 at the top.
    pub max_at: (usize, usize),
}

/// Metrics of `a` against the reference `b`; the sizes must match.
pub fn metrics(a: &Image, b: &Image) -> Result<Metrics, String> {
    metrics_of((a.width, a.height), &a.rgb, (b.width, b.height), &b.rgb)
}

/// [`metrics`] of two `width x height` RGB buffers of f32 or f64 (row 0 at the top), so
/// that f64 films compare at full precision.
pub fn metrics_of<T: Copy + Into<f64>>(
    a_size: (usize, usize),
    a: &[[T; 3]],
    b_size: (usize, usize),
    b: &[[T; 3]],
) -> Result<Metrics, String> {
    if a_size != b_size {
        return Err(format!(
            "the images differ in size: {}x{} and {}x{}",
            a_size.0, a_size.1, b_size.0, b_size.1
        ));
    }
    let pixels = a_size.0.saturating_mul(a_size.1);
    if a.len() != pixels || b.len() != pixels {
        return Err(format!(
            "the images hold {} and {} pixels, not {}x{}",
            a.len(),
            b.len(),
            a_size.0,
            a_size.1
        ));
    }
    let width = a_size.0;
    let (mut se, mut ref2, mut peak) = (0.0f64, 0.0f64, f64::NEG_INFINITY);
    let (mut max_abs, mut max_at) = (0.0f64, (0, 0));
    for (k, (p, q)) in a.iter().zip(b).enumerate() {
        for c in 0..3 {
            let (x, y): (f64, f64) = (p[c].into(), q[c].into());
            let e = (x - y).abs();
            se += e * e;
            ref2 += y * y;
            peak = peak.max(y);
            // NaN compares false: a NaN pixel is reported as the maximum error.
            if e > max_abs || (e.is_nan() && !max_abs.is_nan()) {
                max_abs = e;
                max_at = (k % width, k / width);
            }
        }
    }
    let n = (3 * a.len()).max(1) as f64;
    let rmse = (se / n).sqrt();
    let ref_rms = (ref2 / n).sqrt();
    let peak = if peak > 0.0 { peak } else { 1.0 };
    Ok(Metrics {
        rmse,
        relative_rmse: if ref_rms > 0.0 {
            rmse / ref_rms
        } else if rmse == 0.0 {
            0.0
        } else {
            f64::INFINITY
        },
        psnr: 20.0 * (peak / rmse).log10(),
        max_abs,
        max_at,
    })
}

/// A colour for `u` in [0, 1]: black, blue, magenta, orange, yellow, white (a perceptually
/// ordered "inferno"-like ramp, linear RGB).
fn ramp(u: f64) -> [f32; 3] {
    const STOPS: [[f64; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [0.05, 0.02, 0.35],
        [0.55, 0.05, 0.45],
        [0.95, 0.35, 0.05],
        [0.98, 0.85, 0.15],
        [1.0, 1.0, 1.0],
    ];
    let u = if u.is_nan() { 1.0 } else { u.clamp(0.0, 1.0) } * (STOPS.len() - 1) as f64;
    let i = (u.floor() as usize).min(STOPS.len() - 2);
    let f = u - i as f64;
    let c = |k: usize| (STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f) as f32;
    [c(0), c(1), c(2)]
}

/// 3x5 bitmaps of the characters the legend needs.
fn glyph(ch: char) -> [u8; 5] {
    match ch {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        '.' => [0, 0, 0, 0, 2],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        'e' => [0, 7, 7, 4, 7],
        _ => [0; 5],
    }
}

/// Draws `text` at (x, y) in `scale`-sized pixels.
fn draw_text(img: &mut Image, text: &str, x: usize, y: usize, scale: usize, colour: [f32; 3]) {
    for (n, ch) in text.chars().enumerate() {
        let rows = glyph(ch);
        for (r, bits) in rows.iter().enumerate() {
            for c in 0..3 {
                if bits >> (2 - c) & 1 == 1 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            let (px, py) = (x + (n * 4 + c) * scale + dx, y + r * scale + dy);
                            if px < img.width && py < img.height {
                                img.rgb[py * img.width + px] = colour;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The per-pixel error `max_c |a - b|` in false colour, scaled from 0 to `top` (default: the
/// largest error), above a legend strip: the colour bar with `0` at its left end and `top` at
/// its right. `a` and `b` must have the same size.
pub fn heatmap(a: &Image, b: &Image, top: Option<f64>) -> Result<Image, String> {
    let m = metrics(a, b)?;
    let top = top.unwrap_or(m.max_abs);
    let top = if top > 0.0 && top.is_finite() {
        top
    } else {
        1.0
    };
    let scale = (a.width / 160).max(1);
    let strip = 14 * scale;
    let (w, h) = (a.width, a.height + strip);
    let mut out = Image {
        width: w,
        height: h,
        rgb: vec![[0.0; 3]; w * h],
        alpha: vec![1.0; w * h],
        layers: Vec::new(),
    };
    for (k, (p, q)) in a.rgb.iter().zip(&b.rgb).enumerate() {
        let e = (0..3)
            .map(|c| (f64::from(p[c]) - f64::from(q[c])).abs())
            .fold(
                0.0,
                |x: f64, y| if y.is_nan() { f64::NAN } else { x.max(y) },
            );
        out.rgb[k] = ramp(e / top);
    }
    // Legend: a colour bar over the middle of the width, labels at its ends.
    let y0 = a.height + 2 * scale;
    let label = format!("{top:.2e}");
    let label_w = (label.len() * 4) * scale;
    let (bx0, bx1) = (8 * scale, w.saturating_sub(label_w + 6 * scale));
    for x in bx0..bx1.max(bx0) {
        let c = ramp((x - bx0) as f64 / (bx1 - bx0).max(1) as f64);
        for y in y0..y0 + 5 * scale {
            out.rgb[y * w + x] = c;
        }
    }
    draw_text(&mut out, "0", scale, y0, scale, [1.0; 3]);
    draw_text(&mut out, &label, bx1 + 2 * scale, y0, scale, [1.0; 3]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: usize, h: usize, v: &[[f32; 3]]) -> Image {
        Image {
            width: w,
            height: h,
            rgb: v.to_vec(),
            alpha: vec![1.0; w * h],
            layers: Vec::new(),
        }
    }

    /// Hand-computed: 2x1 images, reference [[1,1,1],[0,0,0]], test [[1,1,0.5],[0,0.25,0]].
    /// Squared errors 0.25 and 0.0625 over 6 values: mse = 0.3125 / 6; ref mean square
    /// = 3 / 6; peak 1.
    #[test]
    fn metrics_against_hand_computed_values() {
        let b = img(2, 1, &[[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]);
        let a = img(2, 1, &[[1.0, 1.0, 0.5], [0.0, 0.25, 0.0]]);
        let m = metrics(&a, &b).unwrap();
        let rmse = (0.3125f64 / 6.0).sqrt();
        assert!((m.rmse - rmse).abs() < 1e-15);
        assert!((m.relative_rmse - rmse / 0.5f64.sqrt()).abs() < 1e-15);
        assert!((m.psnr - 20.0 * (1.0 / rmse).log10()).abs() < 1e-12);
        assert_eq!((m.max_abs, m.max_at), (0.5, (0, 0)));
        let same = metrics(&b, &b).unwrap();
        assert_eq!((same.rmse, same.max_abs), (0.0, 0.0));
        assert!(same.psnr.is_infinite());
        assert!(metrics(&a, &img(1, 2, &[[0.0; 3]; 2])).is_err());
        // Two black images are identical: no relative error; against black, any is infinite.
        let black = img(2, 1, &[[0.0; 3]; 2]);
        assert_eq!(metrics(&black, &black).unwrap().relative_rmse, 0.0);
        assert!(metrics(&a, &black).unwrap().relative_rmse.is_infinite());
        // Buffers that do not hold width x height pixels are refused, not compared in part.
        let short = Image {
            rgb: vec![[0.0; 3]],
            ..black.clone()
        };
        assert!(metrics(&short, &black).is_err());
    }

    #[test]
    fn heatmap_has_the_legend_strip_and_colours_by_error() {
        let b = img(2, 1, &[[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]);
        let a = img(2, 1, &[[1.0, 1.0, 0.5], [0.0, 0.0, 0.0]]);
        let h = heatmap(&a, &b, None).unwrap();
        assert_eq!((h.width, h.height), (2, 15));
        assert_eq!(h.rgb[0], [1.0, 1.0, 1.0]); // the largest error: top of the ramp
        assert_eq!(h.rgb[1], [0.0, 0.0, 0.0]); // no error
    }
}
