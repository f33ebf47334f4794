//! `bench.png` of `gtsphere bench`: log-log time (x) against relative RMS error (y), one panel
//! per scene, one curve per integrator.
//!
//! plotters draws the axes, grid and curves; it is built without its font features (which
//! need system fonts through font-kit and fontconfig), so its own text drawing would panic.
//! Text is drawn here instead, pixel by pixel, from the public-domain 8x8 bitmap font of the
//! `font8x8` crate. The pixels are encoded to PNG by the `image` crate the renderer already
//! uses.

use std::path::Path;

use plotters::prelude::*;

use super::measure::{BenchScene, Row};
use gtsphere::error::Error;

/// What the plot shows, for bench.md.
pub const LEGEND: &str = "One panel per scene. x: seconds (median wall time of the render \
loop), y: relative RMS error against the scene's reference, both log scale with a grid line \
at each power of ten (labels 1eN). One curve per integrator, its settings joined in sweep \
order: exact blue (tol), march orange (step), mc green (spp), surface purple (stratified spp, \
opaque scene). An error of exactly 0 (equal to the reference bit for bit) is drawn on the \
bottom edge of its panel (1e-17).\n";

/// Where an error of exactly zero is drawn.
const ZERO_AT: f64 = 1e-17;

const PANEL: (u32, u32) = (520, 480);
const MARGIN: (i32, i32, i32, i32) = (72, 44, 16, 44); // left, top, right, bottom

fn colour(integrator: &str) -> RGBColor {
    match integrator {
        "exact" => RGBColor(31, 119, 180),
        "march" => RGBColor(255, 127, 14),
        "mc" => RGBColor(44, 160, 44),
        _ => RGBColor(148, 103, 189),
    }
}

fn err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Other(format!("cannot draw bench.png: {e:?}"))
}

/// Draws `s` with its top-left corner at (x, y), each font pixel `scale` pixels wide.
fn text<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (x, y): (i32, i32),
    s: &str,
    scale: i32,
    c: &RGBColor,
) -> Result<(), Error> {
    for (k, ch) in s.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY
            .get(ch as usize)
            .copied()
            .unwrap_or([0; 8]);
        let x0 = x + 8 * scale * k as i32;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                // Bit 0 is the leftmost pixel of the row.
                if bits >> col & 1 == 1 {
                    let (px, py) = (x0 + col * scale, y + row as i32 * scale);
                    area.draw(&Rectangle::new(
                        [(px, py), (px + scale, py + scale)],
                        c.filled(),
                    ))
                    .map_err(err)?;
                }
            }
        }
    }
    Ok(())
}

fn text_width(s: &str, scale: i32) -> i32 {
    8 * scale * s.chars().count() as i32
}

/// How many points along the polylines `curves` fall inside the box `(x0, y0, x1, y1)`.
fn crossings(curves: &[Vec<(i32, i32)>], (x0, y0, x1, y1): (i32, i32, i32, i32)) -> usize {
    let inside = |(x, y): (f64, f64)| {
        (f64::from(x0)..=f64::from(x1)).contains(&x) && (f64::from(y0)..=f64::from(y1)).contains(&y)
    };
    let mut n = 0;
    for c in curves {
        for (k, p) in c.iter().enumerate() {
            let q = c.get(k + 1).unwrap_or(p);
            for i in 0..=32 {
                let f = f64::from(i) / 32.0;
                let at = (
                    f64::from(p.0) + f * f64::from(q.0 - p.0),
                    f64::from(p.1) + f * f64::from(q.1 - p.1),
                );
                n += usize::from(inside(at));
            }
        }
    }
    n
}

/// Powers of ten covering `[lo, hi]`, as (value, exponent).
fn decades(lo: f64, hi: f64) -> Vec<(f64, i32)> {
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (a..=b).map(|e| (10f64.powi(e), e)).collect()
}

/// The range of positive values, widened to whole powers of ten.
fn log_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| *v > 0.0 && v.is_finite())
        .fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return (1e-3, 1.0);
    }
    // A margin of 1.5x, so that no point sits on the frame.
    let (lo, hi) = (
        10f64.powf((lo / 1.5).log10().floor()),
        10f64.powf((hi * 1.5).log10().ceil()),
    );
    (lo, if hi > lo { hi } else { lo * 10.0 })
}

pub fn plot(rows: &[Row], scenes: &[BenchScene], path: &Path) -> Result<(), Error> {
    let (w, h) = (PANEL.0 * scenes.len().max(1) as u32, PANEL.1);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let grey = RGBColor(225, 225, 225);
        for (k, s) in scenes.iter().enumerate() {
            let mine: Vec<&Row> = rows.iter().filter(|r| r.scene == s.name).collect();
            let (x0, x1) = log_range(mine.iter().map(|r| r.seconds));
            let (mut y0, y1) = log_range(mine.iter().map(|r| r.rel_rms));
            if mine.iter().any(|r| r.rel_rms == 0.0) {
                // Room below f64 rounding, so that a zero drawn on the edge reads as one.
                y0 = y0.min(ZERO_AT);
            }
            let left = k as i32 * PANEL.0 as i32;
            let area = root.clone().shrink(
                (left + MARGIN.0, MARGIN.1),
                (
                    PANEL.0 - (MARGIN.0 + MARGIN.2) as u32,
                    PANEL.1 - (MARGIN.1 + MARGIN.3) as u32,
                ),
            );
            let mut chart = ChartBuilder::on(&area)
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(err)?;
            let black = RGBColor(0, 0, 0);
            for (v, e) in decades(x0, x1) {
                chart
                    .draw_series(LineSeries::new([(v, y0), (v, y1)], &grey))
                    .map_err(err)?;
                let (px, py) = chart.backend_coord(&(v, y0));
                let label = format!("1e{e}");
                text(
                    &root,
                    (px - text_width(&label, 1) / 2, py + 6),
                    &label,
                    1,
                    &black,
                )?;
            }
            let ys = decades(y0, y1);
            let every = ys.len().div_ceil(20).max(1);
            for (i, (v, e)) in ys.into_iter().enumerate() {
                chart
                    .draw_series(LineSeries::new([(x0, v), (x1, v)], &grey))
                    .map_err(err)?;
                if i % every == 0 {
                    let (px, py) = chart.backend_coord(&(x0, v));
                    let label = format!("1e{e}");
                    text(
                        &root,
                        (px - text_width(&label, 1) - 4, py - 4),
                        &label,
                        1,
                        &black,
                    )?;
                }
            }
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x0, y0), (x1, y1)],
                    black.stroke_width(1),
                )))
                .map_err(err)?;
            let mut names: Vec<&str> = mine.iter().map(|r| r.integrator).collect();
            names.dedup();
            let curves: Vec<Vec<(f64, f64)>> = names
                .iter()
                .map(|name| {
                    mine.iter()
                        .filter(|r| r.integrator == *name)
                        .map(|r| (r.seconds.clamp(x0, x1), r.rel_rms.clamp(y0, y1)))
                        .collect()
                })
                .collect();
            for (name, pts) in names.iter().zip(&curves) {
                let c = colour(name);
                chart
                    .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                    .map_err(err)?;
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                    .map_err(err)?;
            }
            // The key goes in the inner corner that the curves cross least.
            let pixels: Vec<Vec<(i32, i32)>> = curves
                .iter()
                .map(|c| c.iter().map(|p| chart.backend_coord(p)).collect())
                .collect();
            let (kw, kh) = (96, 14 * names.len() as i32 + 8);
            let (ix0, iy0) = (left + MARGIN.0, MARGIN.1);
            let (ix1, iy1) = (left + PANEL.0 as i32 - MARGIN.2, PANEL.1 as i32 - MARGIN.3);
            let (kx, ky) = [
                (ix1 - kw, iy0 + 4),
                (ix1 - kw, iy1 - kh),
                (ix0 + 8, iy1 - kh),
                (ix0 + 8, iy0 + 4),
            ]
            .into_iter()
            .min_by_key(|&(x, y)| crossings(&pixels, (x, y, x + kw, y + kh)))
            .unwrap_or((ix1 - kw, iy0 + 4));
            for (n, name) in names.iter().enumerate() {
                let (kx, ky) = (kx + 4, ky + 4 + 14 * n as i32);
                root.draw(&Rectangle::new(
                    [(kx, ky), (kx + 16, ky + 8)],
                    colour(name).filled(),
                ))
                .map_err(err)?;
                text(&root, (kx + 22, ky), name, 1, &black)?;
            }
            text(&root, (left + MARGIN.0, 10), s.name, 2, &black)?;
            text(
                &root,
                (left + MARGIN.0, MARGIN.1 - 12),
                "rel. RMS error",
                1,
                &black,
            )?;
            let xl = "seconds";
            text(
                &root,
                (
                    left + PANEL.0 as i32 - MARGIN.2 - text_width(xl, 1),
                    PANEL.1 as i32 - 14,
                ),
                xl,
                1,
                &black,
            )?;
        }
        root.present().map_err(err)?;
    }
    let img = image::RgbImage::from_raw(w, h, buf)
        .ok_or_else(|| Error::Other("bench.png: buffer size".into()))?;
    img.save(path)
        .map_err(|e| Error::Other(format!("{}: {e}", path.display())))
}
