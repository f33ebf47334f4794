//! The Monte Carlo integrator's standard error is honest: the mc cases of
//! ../shared/cases/gas-accuracy (expected values from an independent reference) agree within
//! their reported standard errors, where there is something to see the standard error is not
//! 0 unless the value is exact, and on a small lit scene mc agrees with `exact` pixel by pixel
//! in z-scores and converges like 1 / sqrt(n); per camera ray, on gas_scatter's cloud, mc
//! agrees with `exact` within a stated confidence.

use std::path::{Path, PathBuf};

use crate::output::Image;
use crate::render::{Aovs, Film, Integrator, RenderOptions, SamplerKind};
use crate::scene::Scene;
use crate::vrml::{load_path, LoadOptions};

use crate::testing as support;

/// The cases, or `None` (the test is skipped) when ../shared is not beside the checkout.
fn cases_dir() -> Option<PathBuf> {
    support::shared("cases/gas-accuracy")
}

/// One row of the cases README: `gtsphere render FILE --width W --height H ... --spp N` at
/// pixel (row, col), expected value (largest RGB channel).
struct Case {
    file: String,
    width: u32,
    height: u32,
    spp: u32,
    row: u32,
    col: u32,
    expected: f64,
    /// Half a unit in the last digit the README prints: how well `expected` is known here.
    printed: f64,
}

fn flag(words: &[&str], name: &str) -> Option<u32> {
    let k = words.iter().position(|w| *w == name)?;
    Some(words[k + 1].parse().expect("flag value"))
}

/// The README's table rows whose command uses `--integrator mc`.
fn mc_cases(cases: &Path) -> Vec<Case> {
    let path = cases.join("README.md");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (shared/ must be beside the checkout)",
            path.display()
        )
    });
    let mut out = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // ["", case, command, pixel, expected, got, rel err, error AOV, ""]
        if cells.len() < 6 || !cells[2].contains("--integrator mc") {
            continue;
        }
        let words: Vec<&str> = cells[2].trim_matches('`').split_whitespace().collect();
        let (row, col) = cells[3].split_once(',').expect("pixel row,col");
        let e = cells[4];
        let mantissa = e.split(['e', 'E']).next().unwrap();
        let exponent: i32 = e.split_once(['e', 'E']).map_or(0, |x| x.1.parse().unwrap());
        let decimals = mantissa.split_once('.').map_or(0, |x| x.1.len()) as i32;
        out.push(Case {
            file: words[2].to_string(),
            width: flag(&words, "--width").expect("--width"),
            height: flag(&words, "--height").expect("--height"),
            spp: flag(&words, "--spp").unwrap_or(16),
            row: row.trim().parse().unwrap(),
            col: col.trim().parse().unwrap(),
            expected: e.parse().unwrap(),
            printed: 0.5 * 10f64.powi(exponent - decimals),
        });
    }
    out
}

fn options(width: u32, height: u32, spp: u32, integrator: Integrator) -> RenderOptions {
    RenderOptions {
        width,
        height,
        spp,
        sampler: SamplerKind::Center,
        integrator,
        tol: 1e-9,
        aovs: Aovs {
            error: true,
            ..Aovs::default()
        },
        ..RenderOptions::default()
    }
}

/// A render: the film and its f32 image (whose "error" layer [`error_aov`] reads).
struct Rendered {
    film: Film,
    image: Image,
}

fn render_scene(scene: Scene, opts: &RenderOptions) -> Rendered {
    let film = support::render_auto(scene, opts);
    let image = film.image();
    Rendered { film, image }
}

/// The error AOV (absolute; for mc the standard error of the mean, worst channel).
fn error_aov(r: &Rendered) -> &[f32] {
    &r.image
        .layers
        .iter()
        .find(|l| l.name == "error")
        .expect("error layer")
        .data
}

/// Largest RGB channel (the README's value) of pixel `at`.
fn largest(r: &Rendered, at: usize) -> f64 {
    r.film.rgb[at].into_iter().fold(f64::MIN, f64::max)
}

/// Every mc case pixel agrees with the reference within 4 standard errors. For a normal
/// estimate that fails with probability 6.3e-5 per pixel, so at most 4e-4 for the 6 pixels
/// of the README (union bound); the seeds are fixed, so the outcome is deterministic. A
/// pixel whose expected value is > 0 must report a standard error > 0, or be exact to 1e-9
/// relative (its value then comes from the closed forms alone).
#[test]
fn mc_cases_agree_within_their_standard_error() {
    let Some(dir) = cases_dir() else { return };
    let cases = mc_cases(&dir);
    assert!(cases.len() >= 6, "{} mc cases in the README", cases.len());
    let mut report = String::new();
    let mut failed = false;
    for c in &cases {
        let (scene, _) = load_path(&dir.join(&c.file), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", c.file));
        let r = render_scene(scene, &options(c.width, c.height, c.spp, Integrator::Mc));
        let at = (c.row * c.width + c.col) as usize;
        let (got, se) = (largest(&r, at), f64::from(error_aov(&r)[at]));
        let err = (got - c.expected).abs();
        let exact = err <= 1e-9 * c.expected.abs();
        let within = err <= 4.0 * se + c.printed;
        let ok = (exact || within) && (c.expected <= 0.0 || se > 0.0 || exact);
        failed |= !ok;
        report.push_str(&format!(
            "{} spp {} ({},{}): got {got:.10e} se {se:.3e} expected {:.10e} rel err {:.2e}{}\n",
            c.file,
            c.spp,
            c.row,
            c.col,
            c.expected,
            err / c.expected.abs(),
            if ok { "" } else { "  FAILED" }
        ));
    }
    eprint!("{report}");
    assert!(!failed, "\n{report}");
}

/// A small lit scene: three overlapping scattering gas spheres (one thick, one thin, one in
/// between), a grey albedo and white lights (so every channel's scattering is proportional
/// and the worst channel's standard error belongs to the largest value), an opaque sphere
/// whose shadow falls across the gas, and a directional and a point light.
const LIT: &str = "NavigationInfo { headlight FALSE }
Viewpoint { position 0 0 4 fieldOfView 0.4 }
DirectionalLight { direction -1 -0.5 -1 intensity 0.8 }
PointLight { location 0.9 0.9 0.9 intensity 1 attenuation 0 0 1 radius 100 }
Transform { translation 0 0 0 children Shape { appearance Appearance { material Material {
  diffuseColor 0.7 0.7 0.7 emissiveColor 0.05 0.03 0.01 transparency 0.3 } } geometry Sphere { radius 0.5 } } }
Transform { translation 0.3 0.2 0.3 children Shape { appearance Appearance { material Material {
  diffuseColor 0.6 0.6 0.6 transparency 0.02 } } geometry Sphere { radius 0.3 } } }
Transform { translation -0.35 -0.3 -0.1 children Shape { appearance Appearance { material Material {
  diffuseColor 0.8 0.8 0.8 transparency 0.9 } } geometry Sphere { radius 0.35 } } }
Transform { translation 0.45 0.5 0.65 children Shape { appearance Appearance { material Material {
  diffuseColor 0.5 0.5 0.5 } } geometry Sphere { radius 0.1 } } }
";

/// mc against exact on every pixel of the lit scene: with `z = (mc - exact) / se`, every
/// covered pixel has |z| <= 6 (two-sided normal tail 2e-9 per pixel, so a false failure with
/// probability below 1e-6 for the 400 pixels, union bound; the exact side is good to its
/// reported error, added to the allowance). The standard error is not inflated either: the
/// mean of z^2 over the pixels is near 1 (about 170 pixels with scattering, so the mean of
/// z^2 has a standard deviation of about 0.11 and the band [0.5, 1.6] is more than 4.5 of
/// them wide on either side). Pixels with a standard error of 0 (no scattering gas) must
/// equal exact to 1e-9 relative. Seeds are fixed: the outcome is deterministic.
#[test]
fn mc_pixels_agree_with_exact_in_z_scores() {
    let (w, h, spp) = (20, 20, 256);
    let exact = render_scene(
        support::scene(LIT).0,
        &options(w, h, spp, Integrator::Exact),
    );
    let mc = render_scene(support::scene(LIT).0, &options(w, h, spp, Integrator::Mc));
    let (e_err, m_se) = (error_aov(&exact), error_aov(&mc));
    let (mut n, mut sum_z2, mut worst) = (0usize, 0.0, (0.0f64, 0usize));
    for at in 0..(w * h) as usize {
        let se = f64::from(m_se[at]);
        let want = exact.film.rgb[at];
        let got = mc.film.rgb[at];
        let diff = (0..3).map(|k| (got[k] - want[k]).abs()).fold(0.0, f64::max);
        let scale = want.into_iter().fold(0.0, f64::max);
        if se == 0.0 {
            assert!(
                diff <= 1e-9 * scale + f64::from(e_err[at]),
                "pixel {at}: se 0 but mc {got:?} vs exact {want:?}"
            );
            continue;
        }
        let z = (diff - f64::from(e_err[at]) - 1e-12 * scale).max(0.0) / se;
        n += 1;
        sum_z2 += (diff / se).powi(2);
        if z > worst.0 {
            worst = (z, at);
        }
        assert!(
            z <= 6.0,
            "pixel {at}: mc {got:?} +- {se:e} vs exact {want:?}: z {z}"
        );
    }
    assert!(n >= 100, "only {n} pixels with scattering");
    let mean_z2 = sum_z2 / n as f64;
    eprintln!(
        "{n} pixels, mean z^2 {mean_z2:.3}, worst |z| {:.2} at {}",
        worst.0, worst.1
    );
    assert!(
        (0.5..=1.6).contains(&mean_z2),
        "mean z^2 {mean_z2} over {n} pixels: the standard error is not the spread"
    );
}

/// 1 / sqrt(n): quadrupling the paths halves the standard error (median ratio over the
/// pixels between 0.4 and 0.6; the expected 0.5 with ~5 % scatter per pixel at 256 paths).
#[test]
fn mc_standard_error_shrinks_like_one_over_sqrt_n() {
    let (w, h) = (12, 12);
    let a = render_scene(support::scene(LIT).0, &options(w, h, 64, Integrator::Mc));
    let b = render_scene(support::scene(LIT).0, &options(w, h, 256, Integrator::Mc));
    let (sa, sb) = (error_aov(&a), error_aov(&b));
    let mut ratios: Vec<f64> = sa
        .iter()
        .zip(sb)
        .filter(|(x, _)| **x > 0.0)
        .map(|(x, y)| f64::from(*y) / f64::from(*x))
        .collect();
    assert!(ratios.len() >= 30, "{} pixels", ratios.len());
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    assert!((0.4..=0.6).contains(&median), "median se ratio {median}");
}

/// Monte Carlo agrees with exact on every camera ray and channel, with an overall confidence:
/// the test makes `12 x 3` comparisons and allows each `|mc - exact| <= Z se` with `Z` the
/// two-sided normal quantile of `ALPHA / 36` (Bonferroni), so that a correct integrator fails
/// with probability at most `ALPHA` over all of them (the mean of 4000 samples is normal to a
/// good approximation; the standard error is estimated from the same samples, which the
/// `1e-12` floor and Student's t at 3999 degrees of freedom, within 0.1 % of the normal,
/// leave unaffected). On failure every comparison is written to a CSV file whose path the
/// message gives.
#[test]
fn monte_carlo_agrees_with_exact() {
    use crate::render::integrators::tests::gas_scatter::{camera_rays, cloud, ours, prepared};
    use crate::render::integrators::{self, Scratch};
    use crate::render::sampler::Rng;
    use crate::render::Counters;
    use glam::DVec3;
    /// Overall probability of a false failure.
    const ALPHA: f64 = 1e-4;
    /// Two-sided normal quantile of ALPHA / 36 = 2.78e-6: P(|N(0, 1)| > 4.69) = 2.73e-6.
    const Z: f64 = 4.69;
    let (balls, lamps) = cloud();
    let (exact, mc) = (
        prepared(&balls, &lamps, Integrator::Exact, 1e-8),
        prepared(&balls, &lamps, Integrator::Mc, 1e-8),
    );
    let (exact, mc) = (exact.view(), mc.view());
    let rays = camera_rays(12);
    let comparisons = 3 * rays.len();
    assert_eq!(comparisons, 36, "Z is computed for 36 comparisons");
    let mut rows = vec!["ray,channel,mc,standard_error,exact,z".to_string()];
    let mut failed = Vec::new();
    for (g, (o, w)) in rays.into_iter().enumerate() {
        let want = ours(&exact, o, w).0;
        let mut rng = Rng::new(11, g as u64);
        let mut scratch = Scratch::default();
        let n = 4000;
        let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
        for _ in 0..n {
            let v =
                integrators::radiance(&mc, o, w, &mut rng, &mut scratch, &mut Counters::default())
                    .value;
            s += v;
            s2 += v * v;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean).max(DVec3::ZERO) / (n as f64 - 1.0)).powf(0.5);
        for k in 0..3 {
            let z = (mean[k] - want[k]).abs() / (se[k] + 1e-12 / Z);
            rows.push(format!(
                "{g},{k},{:e},{:e},{:e},{z:.2}",
                mean[k], se[k], want[k]
            ));
            if (mean[k] - want[k]).abs() > Z * se[k] + 1e-12 {
                failed.push(format!(
                    "ray {g} channel {k}: mc {} +- {} vs exact {} ({z:.2} standard errors)",
                    mean[k], se[k], want[k]
                ));
            }
        }
    }
    if !failed.is_empty() {
        let path =
            support::scratch("gas_mc", "monte_carlo_agrees_with_exact").join("comparisons.csv");
        std::fs::write(&path, rows.join("\n") + "\n").unwrap();
        panic!(
            "{} of {comparisons} comparisons beyond {Z} standard errors (overall false-failure \
             probability {ALPHA:e}); all comparisons in {}:\n{}",
            failed.len(),
            path.display(),
            failed.join("\n")
        );
    }
}
