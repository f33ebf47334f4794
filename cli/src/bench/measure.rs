//! The measuring shared by `gtsphere bench` ([`super::report`]) and `bench gas`
//! ([`super::gas`]): a [`Case`] (one integrator setting) rendered on a [`BenchScene`] against
//! its reference, timed (a render faster than [`REPEAT_BELOW`] seconds is repeated, up to
//! [`MAX_RUNS`] runs, and the median wall time of the tile loop is kept), its error computed
//! in f64 ([`relative_rms`], [`relative_max`]), and the [`Row`]s as a table and a summary.

use std::fmt::Write as _;

use gtsphere::error::Error;
use gtsphere::render::{
    prepare, render, Counters, Integrator, PrepareOptions, RenderOptions, SamplerKind,
};
use gtsphere::scene::Scene;

/// Renders faster than this (seconds) are repeated for a median.
pub const REPEAT_BELOW: f64 = 0.3;
/// Most runs of one setting.
pub const MAX_RUNS: usize = 5;

/// The median (upper median for an even count); `v` must not be empty.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One measured setting of one integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case {
    pub integrator: Integrator,
    pub sampler: SamplerKind,
    pub spp: u32,
    pub tol: f64,
}

impl Case {
    pub fn exact(tol: f64) -> Case {
        Case {
            integrator: Integrator::Exact,
            sampler: SamplerKind::Center,
            spp: 1,
            tol,
        }
    }
    pub fn march(step: f64) -> Case {
        Case {
            integrator: Integrator::March { step },
            ..Case::exact(0.0)
        }
    }
    /// Monte Carlo with `spp` paths through each pixel centre.
    pub fn mc(spp: u32) -> Case {
        Case {
            integrator: Integrator::Mc,
            spp,
            ..Case::exact(0.0)
        }
    }
    /// The opaque path with `spp` stratified samples per pixel.
    pub fn surface(spp: u32) -> Case {
        Case {
            sampler: SamplerKind::Stratified,
            spp,
            ..Case::exact(1e-4)
        }
    }
    /// The curve this case belongs to.
    pub fn name(&self) -> &'static str {
        match (self.sampler, self.integrator) {
            (SamplerKind::Stratified, _) => "surface",
            (_, Integrator::Exact) => "exact",
            (_, Integrator::March { .. }) => "march",
            (_, Integrator::Mc) => "mc",
            (_, Integrator::Ao(_)) => "ao",
        }
    }
    /// The swept parameter: tol, step or spp.
    pub fn param(&self) -> f64 {
        match (self.sampler, self.integrator) {
            (SamplerKind::Center, Integrator::Exact) => self.tol,
            (SamplerKind::Center, Integrator::March { step }) => step,
            _ => f64::from(self.spp),
        }
    }
    pub fn setting(&self) -> String {
        match (self.sampler, self.integrator) {
            (SamplerKind::Center, Integrator::Exact) => format!("tol {:e}", self.tol),
            (SamplerKind::Center, Integrator::March { step }) => format!("step {step:e}"),
            _ => format!("spp {}", self.spp),
        }
    }
}

/// A scene and what to measure on it.
pub struct BenchScene {
    pub name: &'static str,
    pub description: String,
    pub scene: Scene,
    pub size: u32,
    pub reference: Case,
    pub cases: Vec<Case>,
}

/// One row of the report.
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: &'static str,
    pub integrator: &'static str,
    pub setting: String,
    pub param: f64,
    /// Median wall time of the tile loop.
    pub seconds: f64,
    pub runs: usize,
    pub rel_rms: f64,
    pub rel_max: f64,
    pub counters: Counters,
    pub threads: usize,
}

impl Row {
    /// Camera rays (mc: paths; surface: samples) per second per thread.
    pub fn rays_per_s_per_core(&self) -> f64 {
        self.counters.camera_rays as f64 / self.seconds / self.threads as f64
    }
}

/// One setting's render.
pub struct Measured {
    /// The pixels in f64, row by row.
    pub rgb: Vec<[f64; 3]>,
    /// Median wall time of the tile loop over `runs` runs.
    pub seconds: f64,
    pub runs: usize,
    /// Work counters of one run.
    pub counters: Counters,
}

/// Renders `scene` with `case`, repeated while fast (see the module notes).
pub fn measure(scene: &Scene, size: u32, case: &Case) -> Result<Measured, Error> {
    let opts = RenderOptions {
        width: size,
        height: size,
        spp: case.spp,
        sampler: case.sampler,
        integrator: case.integrator,
        tol: case.tol,
        ..RenderOptions::default()
    };
    let prep = prepare(scene.clone(), &PrepareOptions::default())?;
    let camera = prep.default_camera(size, size)?;
    let mut times = Vec::new();
    let mut total = 0.0;
    loop {
        let done = render(&prep, &camera, &opts, &())?;
        times.push(done.seconds);
        total += done.seconds;
        if done.seconds >= REPEAT_BELOW || times.len() >= MAX_RUNS || total >= 1.0 {
            return Ok(Measured {
                rgb: done.rgb,
                runs: times.len(),
                seconds: median(times),
                counters: done.counters,
            });
        }
    }
}

/// Relative RMS error over all channels: `sqrt(mean |x - ref|^2) / sqrt(mean |ref|^2)`.
pub fn relative_rms(img: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in img.iter().zip(reference) {
        for k in 0..3 {
            num += (a[k] - b[k]) * (a[k] - b[k]);
            den += b[k] * b[k];
        }
    }
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

/// Largest relative error of one channel of one pixel, `|x - ref| / max(|ref|, floor)` with the
/// floor `1e-3 * rms(ref)` so that a near-black reference pixel does not dominate.
pub fn relative_max(img: &[[f64; 3]], reference: &[[f64; 3]]) -> f64 {
    let n = (reference.len() * 3).max(1) as f64;
    let rms = (reference.iter().flatten().map(|v| v * v).sum::<f64>() / n).sqrt();
    let floor = (1e-3 * rms).max(f64::MIN_POSITIVE);
    img.iter()
        .flatten()
        .zip(reference.iter().flatten())
        .map(|(a, b)| (a - b).abs() / b.abs().max(floor))
        .fold(0.0, f64::max)
}

/// Measures every case of `s` against its reference; `progress` is told of each row.
pub fn run_scene(
    s: &BenchScene,
    threads: usize,
    mut progress: impl FnMut(&Row),
) -> Result<(Vec<Row>, f64), Error> {
    let reference = measure(&s.scene, s.size, &s.reference)?;
    let mut rows = Vec::new();
    for case in &s.cases {
        let m = measure(&s.scene, s.size, case)?;
        let row = Row {
            scene: s.name,
            integrator: case.name(),
            setting: case.setting(),
            param: case.param(),
            seconds: m.seconds,
            runs: m.runs,
            rel_rms: relative_rms(&m.rgb, &reference.rgb),
            rel_max: relative_max(&m.rgb, &reference.rgb),
            counters: m.counters,
            threads,
        };
        progress(&row);
        rows.push(row);
    }
    Ok((rows, reference.seconds))
}

/// The Markdown table of `rows`.
pub fn table(rows: &[Row]) -> String {
    let mut t = String::from(
        "| scene | integrator | setting | seconds | runs | rel. RMS error | max rel. error | camera rays/s/core |\n\
         |---|---|---|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let _ = writeln!(
            t,
            "| {} | {} | {} | {:.4} | {} | {:.2e} | {:.2e} | {:.3e} |",
            r.scene,
            r.integrator,
            r.setting,
            r.seconds,
            r.runs,
            r.rel_rms,
            r.rel_max,
            r.rays_per_s_per_core()
        );
    }
    t
}

/// Time for `integrator` on `scene` to reach relative RMS `target`: the fastest measured row
/// that reaches it, else a log-log extrapolation from the last two rows (flagged `true`).
pub fn time_to(rows: &[Row], scene: &str, integrator: &str, target: f64) -> Option<(f64, bool)> {
    let curve: Vec<&Row> = rows
        .iter()
        .filter(|r| r.scene == scene && r.integrator == integrator)
        .collect();
    let reached = curve
        .iter()
        .filter(|r| r.rel_rms <= target)
        .map(|r| r.seconds)
        .fold(f64::INFINITY, f64::min);
    if reached.is_finite() {
        return Some((reached, false));
    }
    // Error ~ time^slope through the two tightest settings.
    let [.., a, b] = curve.as_slice() else {
        return None;
    };
    let slope = (b.rel_rms.ln() - a.rel_rms.ln()) / (b.seconds.ln() - a.seconds.ln());
    (slope < 0.0 && slope.is_finite())
        .then(|| (b.seconds * (target / b.rel_rms).powf(1.0 / slope), true))
}

/// What the lit gas scene's rows say, as lines of text: the time each integrator needs for
/// 1e-4 relative RMS and their ratio, and exact's error as its tolerance tightens.
pub fn summary(rows: &[Row]) -> String {
    let mut t = String::new();
    let fmt = |v: Option<(f64, bool)>| match v {
        Some((s, false)) => format!("{s:.3} s"),
        Some((s, true)) => format!("~{s:.3} s (extrapolated)"),
        None => "not reached".into(),
    };
    let ex = time_to(rows, "lit gas", "exact", 1e-4);
    let ma = time_to(rows, "lit gas", "march", 1e-4);
    let _ = write!(
        t,
        "- lit gas, time to 1e-4 relative RMS: exact {}, march {}",
        fmt(ex),
        fmt(ma)
    );
    if let (Some((e, _)), Some((m, _))) = (ex, ma) {
        let _ = write!(t, " -> march / exact = {:.1}x", m / e);
    }
    t.push('\n');
    let exact: Vec<&Row> = rows
        .iter()
        .filter(|r| r.scene == "lit gas" && r.integrator == "exact")
        .collect();
    let errs: Vec<String> = exact.iter().map(|r| format!("{:.1e}", r.rel_rms)).collect();
    let best = exact
        .iter()
        .map(|r| r.rel_rms)
        .fold(f64::INFINITY, f64::min);
    let _ = writeln!(
        t,
        "- lit gas, exact error as tol tightens: {}; smallest {:.1e}",
        errs.join(", "),
        best
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(integrator: &'static str, seconds: f64, rel_rms: f64) -> Row {
        Row {
            scene: "lit gas",
            integrator,
            setting: String::new(),
            param: 0.0,
            seconds,
            runs: 1,
            rel_rms,
            rel_max: rel_rms,
            counters: Counters::default(),
            threads: 1,
        }
    }

    #[test]
    fn time_to_a_target_measured_or_extrapolated_along_the_curve() {
        // Error ~ 1 / time: 1e-2 at 1 s, 1e-3 at 10 s, so 1e-4 at 100 s.
        let rows = [
            row("march", 1.0, 1e-2),
            row("march", 10.0, 1e-3),
            row("exact", 0.5, 1e-9),
            row("exact", 0.4, 1e-8),
        ];
        let (t, extrapolated) = time_to(&rows, "lit gas", "march", 1e-4).unwrap();
        assert!(extrapolated && (t - 100.0).abs() < 1e-9, "{t}");
        assert_eq!(time_to(&rows, "lit gas", "exact", 1e-4), Some((0.4, false)));
        assert_eq!(time_to(&rows, "lit gas", "mc", 1e-4), None);
        assert!(summary(&rows).contains("march / exact = 250.0x"));
    }

    #[test]
    fn relative_errors_of_known_images() {
        let reference = [[1.0, 2.0, 2.0], [0.0, 0.0, 0.0]];
        assert_eq!(relative_rms(&reference, &reference), 0.0);
        let img = [[1.1, 2.0, 2.0], [0.0, 0.0, 0.0]];
        // sqrt(0.01 / 9)
        assert!((relative_rms(&img, &reference) - 0.1 / 3.0).abs() < 1e-12);
        assert!((relative_max(&img, &reference) - 0.1).abs() < 1e-12);
        // A black reference pixel is judged against the floor, not divided by zero.
        let img = [[1.0, 2.0, 2.0], [1e-6, 0.0, 0.0]];
        let floor = 1e-3 * (9.0f64 / 6.0).sqrt();
        assert!((relative_max(&img, &reference) - 1e-6 / floor).abs() < 1e-12);
    }
}
