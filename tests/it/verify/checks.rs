//! One scene through the library with each integrator, pixel by pixel against the reference:
//!
//! - `exact`: every channel within `tol * max(largest channel, 1e-3)` (the README's
//!   contract: tol times the ray's value, absolute floor tol * 1e-3) plus the reference's own
//!   error and rounding; the error AOV is tallied against the true error (coverage, with
//!   [`MARGIN_SEEN`], and the ratio reported/true over the run are judged in `mod.rs`).
//! - `march`: [`MARCH_STEPS`] steps from h down to about h/32 ([`march_steps`]); the image's
//!   L1 error must fall at first order: its coefficient `error / step` at the two finest
//!   steps at most [`MARCH_GROWTH`] times that at the two coarsest (a march that converges to
//!   a wrong value has a constant error, whose coefficient grows 32-fold), unless the error
//!   is already at rounding. The order fitted in log-log is reported. On one pixel the
//!   error at each level is the boundary's remainder (below) times a constant, pseudo-random
//!   between 0 and the step, so both coarse levels can be lucky: a scene that fails is
//!   looked at again with [`MARCH_STEPS_MORE`] steps (to about h/128), the two finest
//!   against the four coarsest (a constant error still grows 19-fold). March is of first
//!   order: its steps start at the camera,
//!   so the step that holds a sphere's surface (or a shadow edge) miscounts by the
//!   remainder of that boundary's distance modulo the step. With steps h / 2^k that
//!   remainder is the same at every level once it is below the finest step, and the error
//!   does not fall; the steps are therefore spread off the powers of two by the golden
//!   ratio's fractional multiples, so that the remainders differ from level to level.
//! - `mc`: every channel within `z` standard errors (Bonferroni over the run's channels),
//!   plus what samples cannot show: an outcome of probability `p` is missed by all `n`
//!   samples with probability `(1 - p)^n < exp(-p n)`, below the run's false-alarm share
//!   once `p > z^2 / (2 n)`; outcomes rarer than that move the mean by at most that `p`
//!   times the largest a sample can score, `opacity * scatter_scale` (the gas in front of
//!   the hit, times the largest albedo times every light at full strength).

use gtsphere::render::{
    self, CameraChoice, Film, Integrator, PrepareOptions, Projection, RenderOptions, SamplerKind,
};
use gtsphere::vrml::{load_str, LoadOptions};

use super::reference::RayRef;
use super::scenes::SceneDesc;

/// March steps per scene, and how much the first-order coefficient may grow over them.
pub const MARCH_STEPS: u32 = 6;
pub const MARCH_GROWTH: f64 = 8.0;

/// Steps in the second look at a scene whose march error did not fall at first order.
pub const MARCH_STEPS_MORE: u32 = 8;

/// The first `n` march steps for a first step `h`: `h 2^-k (1 + 0.4 frac(k phi))`,
/// k = 0, 1, ...
pub fn march_steps(h: f64, n: u32) -> Vec<f64> {
    let phi = 0.5 * (1.0 + 5f64.sqrt());
    (0..n)
        .map(|k| {
            let k = f64::from(k);
            h * (-k).exp2() * (1.0 + 0.4 * (k * phi).fract())
        })
        .collect()
}
/// Monte Carlo samples per pixel.
pub const MC_SPP: u32 = 256;
/// Relative rounding allowed between two f64 computations of one pixel: transforms composed
/// in another order, hit points found in object space or in world space, then a specular
/// power of up to 128 (which multiplies the relative error of `N.H` by up to 128).
pub const ROUNDING: f64 = 1e-9;

/// How one scene went.
#[derive(Default)]
pub struct Outcome {
    /// What failed, one line each.
    pub failures: Vec<String>,
    pub exact_pixels: u64,
    /// Largest |error| / allowed over exact's channels.
    pub worst_exact: f64,
    /// (reported, true) for exact pixels whose true error is above rounding.
    pub aov_pairs: Vec<(f64, f64)>,
    pub march_pixels: u64,
    /// Observed rate of march's error per halving (None: skipped or converged).
    pub march_rates: Vec<f64>,
    pub march_skipped: bool,
    pub mc_pixels: u64,
    /// Largest |error| / standard error over mc's channels with a standard error.
    pub worst_mc_z: f64,
    /// mc pixels with standard error 0 but a difference above rounding (explained by an
    /// unsampled scattering part no larger than the reference's).
    pub mc_zero_se_differ: u64,
    /// The exact tolerance drawn and march's first step.
    pub tol: f64,
    pub step: f64,
    /// Exact's failing (pixel, channel)s, for a second opinion from march and mc.
    pub exact_failed: Vec<(usize, usize)>,
    /// Seconds in the reference, exact, march, mc and AO (its reference and render).
    pub secs: [f64; 5],
    /// What the AO dimension found.
    pub ao: super::ao::Tally,
    /// The reference took longer than its budget: the scene was not checked.
    pub reference_late: bool,
}

/// The library's image of `desc` with `opts` (its camera from the file's Viewpoint).
pub fn library(text: &str, desc: &SceneDesc, opts: &RenderOptions) -> Result<Film, String> {
    let (scene, _) =
        load_str("verify.wrl", text, &LoadOptions::default()).map_err(|e| format!("load: {e}"))?;
    let prep = render::prepare(scene, &PrepareOptions::default()).map_err(|e| e.to_string())?;
    let projection = match desc.viewpoint.ortho {
        Some(h) => Projection::Ortho { height: Some(h) },
        None => Projection::PERSPECTIVE,
    };
    let (camera, _) = prep
        .camera(&CameraChoice::Auto, projection, desc.width, desc.height)
        .map_err(|e| e.to_string())?;
    render::render(&prep, &camera, opts, &()).map_err(|e| e.to_string())
}

/// The options of one render: the scene's size, one ray through each pixel centre, the
/// error AOV, `MC_SPP` samples, the headlight in the harness's mode.
pub fn options(desc: &SceneDesc, integrator: Integrator, tol: f64, viewer: bool) -> RenderOptions {
    let mut o = RenderOptions {
        width: desc.width,
        height: desc.height,
        spp: MC_SPP,
        seed: desc.seed,
        sampler: SamplerKind::Center,
        integrator,
        tol,
        ..RenderOptions::default()
    };
    o.aovs.error = true;
    super::set_headlight_option(&mut o, viewer);
    o
}

fn largest(v: &[f64; 3]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Slack for a pixel: the reference's own error bound and rounding.
fn slack(r: &RayRef) -> f64 {
    r.err + ROUNDING * largest(&r.value).max(1e-3)
}

/// Relative room in the coverage check for scenes with a point light on an opaque sphere:
/// the library blocks a light ray up to `1 - 1e-9` of its length (`lights::opaque_reach`), so
/// light rays within about 1e-9 rad of the tangent plane at the light count as lit, a wedge
/// worth up to ~1e-8 of a pixel's value where the camera ray runs through it.
pub const LIGHT_ON_SURFACE: f64 = 1e-7;

/// How much more than the true error a reported error must be to cover it: the library
/// reports every truncation bound with a margin of 1/16, so a bound that is tight (gas
/// left out whole, unshadowed under one light) is still above the amount it bounds; one
/// reported level with it (no margin) does not cover.
pub const MARGIN_SEEN: f64 = 1.03;

/// Whether a reported error (with the rounding allowance) covers the true error.
pub fn covers(reported: f64, true_err: f64) -> bool {
    reported >= MARGIN_SEEN * true_err
}

/// `light_on_surface`: the scene has a point light on an opaque sphere
/// ([`LIGHT_ON_SURFACE`]).
pub fn check_exact(
    out: &mut Outcome,
    desc: &SceneDesc,
    film: &Film,
    refs: &[RayRef],
    light_on_surface: bool,
) {
    let room = if light_on_surface {
        LIGHT_ON_SURFACE
    } else {
        ROUNDING
    };
    let err_aov = film.error.as_ref().expect("error AOV asked for");
    let mut uncovered = Vec::new();
    for (k, r) in refs.iter().enumerate() {
        let got = film.rgb[k];
        let allowed = out.tol * largest(&r.value).max(1e-3) + slack(r);
        let mut true_err = 0.0f64;
        for c in 0..3 {
            let e = (got[c] - r.value[c]).abs();
            true_err = true_err.max(e);
            out.worst_exact = out.worst_exact.max(e / allowed);
            if e.is_nan() || e > allowed {
                out.exact_failed.push((k, c));
                out.failures.push(format!(
                    "exact pixel ({}, {}) channel {c}: got {:.10e} reference {:.10e} \
                     (+- {:.1e}): error {:.2e} = {:.2}x allowed; error AOV {:.2e}",
                    k % desc.width as usize,
                    k / desc.width as usize,
                    got[c],
                    r.value[c],
                    r.err,
                    e,
                    e / allowed,
                    err_aov[k]
                ));
            }
        }
        // Coverage is judged relative to the pixel's own value (no absolute floor), so that
        // pixels of scenes faint everywhere count too.
        let rounding = r.err + room * largest(&r.value);
        if true_err > rounding {
            out.aov_pairs.push((err_aov[k] + rounding, true_err));
            if !covers(err_aov[k] + rounding, true_err) {
                uncovered.push(format!(
                    "exact pixel ({}, {}): error AOV {:.3e} does not cover the true error \
                     {:.3e} with {MARGIN_SEEN} to spare (value {:.6e})",
                    k % desc.width as usize,
                    k / desc.width as usize,
                    err_aov[k],
                    true_err,
                    largest(&r.value)
                ));
            }
        }
        out.exact_pixels += 1;
    }
    // In every scene, at least AOV_COVERAGE of the pixels above rounding are covered.
    let counted = out.aov_pairs.len();
    if uncovered.len() as f64 > (1.0 - super::AOV_COVERAGE) * counted as f64 {
        out.failures.extend(uncovered);
    }
}

/// The image's L1 error against the reference, over the pixels march can resolve: a ray
/// whose gas is shorter than twice the finest step `h` may hold no midpoint at all at every
/// step tried (its error is then the gas's whole contribution, whatever the step), so such
/// pixels are left out.
fn l1(film: &Film, refs: &[RayRef], h: f64) -> f64 {
    refs.iter()
        .zip(&film.rgb)
        .filter(|(r, _)| r.gas_length == 0.0 || r.gas_length >= 2.0 * h)
        .map(|(r, g)| (0..3).map(|c| (g[c] - r.value[c]).abs()).sum::<f64>())
        .sum()
}

/// March at h, h/2, h/4, ...: `films` in that order, [`MARCH_STEPS`] of them or
/// [`MARCH_STEPS_MORE`]. Returns whether the error fell at first order (the failure is
/// recorded only when `last_chance`).
pub fn check_march(out: &mut Outcome, films: &[Film], refs: &[RayRef], last_chance: bool) -> bool {
    let steps = march_steps(out.step, films.len() as u32);
    let finest = steps[steps.len() - 1];
    let errs: Vec<f64> = films.iter().map(|f| l1(f, refs, finest)).collect();
    let scale: f64 = refs.iter().map(|r| largest(&r.value)).sum::<f64>() + 1e-3;
    let floor: f64 = refs.iter().map(slack).sum::<f64>() + 1e-9 * scale;
    if errs[0] <= 10.0 * floor {
        out.march_pixels += (films.len() * refs.len()) as u64;
        return true;
    }
    // Least-squares slope of ln(error) against ln(step).
    let pts: Vec<(f64, f64)> = steps
        .iter()
        .zip(&errs)
        .map(|(h, e)| (h.ln(), e.max(floor).ln()))
        .collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let order = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    let coeff: Vec<f64> = errs.iter().zip(&steps).map(|(e, h)| e / h).collect();
    let k = coeff.len();
    // The coarse levels: all but the four finest (two of six, four of eight).
    let coarse = coeff[..k - 4].iter().fold(0.0f64, |m, &c| m.max(c));
    let fine = coeff[k - 2].max(coeff[k - 1]);
    let ok = fine <= MARCH_GROWTH * coarse;
    if ok || last_chance {
        out.march_pixels += (films.len() * refs.len()) as u64;
        out.march_rates.push(order);
    }
    if !ok && last_chance {
        let list: Vec<String> = errs.iter().map(|e| format!("{e:.3e}")).collect();
        out.failures.push(format!(
            "march: image L1 error {} at steps from h to about h/{} (h = {:e}): error / step \
             grew {:.1}-fold, more than {MARCH_GROWTH} (fitted order {order:.2})",
            list.join(", "),
            1u32 << (k - 1),
            out.step,
            fine / coarse
        ));
    }
    ok
}

pub fn check_mc(
    out: &mut Outcome,
    desc: &SceneDesc,
    film: &Film,
    refs: &[RayRef],
    z: f64,
    scatter_scale: f64,
) {
    let se = film.error.as_ref().expect("error AOV asked for");
    let unseen = z * z / (2.0 * f64::from(MC_SPP));
    for (k, r) in refs.iter().enumerate() {
        out.mc_pixels += 1;
        let rare = unseen * r.opacity * scatter_scale;
        for c in 0..3 {
            let e = (film.rgb[k][c] - r.value[c]).abs();
            let s = slack(r) + rare;
            if se[k] > 0.0 {
                out.worst_mc_z = out.worst_mc_z.max((e - s).max(0.0) / se[k]);
            } else if e > slack(r) {
                out.mc_zero_se_differ += 1;
            }
            let ok = e <= z * se[k] + s;
            if !ok {
                out.failures.push(format!(
                    "mc pixel ({}, {}) channel {c}: got {:.10e} reference {:.10e} (scattering \
                     {:.3e}): error {:.2e} = {:.2} standard errors of {:.2e} (z {z:.2})",
                    k % desc.width as usize,
                    k / desc.width as usize,
                    film.rgb[k][c],
                    r.value[c],
                    r.scatter[c],
                    e,
                    e / se[k],
                    se[k]
                ));
            }
        }
    }
}

/// For exact's failing channels: what march at a fine step and mc with many samples say, so
/// that a report shows whether the reference or exact is the odd one out.
pub fn second_opinion(out: &mut Outcome, march: Option<&Film>, mc: &Film, desc: &SceneDesc) {
    let se = mc.error.as_ref().expect("error AOV asked for");
    for &(k, c) in out.exact_failed.iter().take(3) {
        let m = march.map_or(String::from("-"), |f| format!("{:.10e}", f.rgb[k][c]));
        out.failures.push(format!(
            "second opinion at ({}, {}) channel {c}: march (step {:e}) {m}, mc ({} spp) \
             {:.10e} +- {:.1e}",
            k % desc.width as usize,
            k / desc.width as usize,
            out.step / 8.0,
            mc_spp_opinion(),
            mc.rgb[k][c],
            se[k]
        ));
    }
}

/// Samples of the second-opinion mc render.
pub fn mc_spp_opinion() -> u32 {
    4096
}
