//! Every case of ../shared/cases/gas-accuracy/ and ../shared/cases/light-radius/ as a
//! regression test: the scene is read in place, rendered through the library as the README's command does
//! (`--sampler center --aov error --tol T`, f64 film), and each listed pixel (the largest RGB
//! channel) must (1) be within the tolerance of the README's expected value and (2) carry an
//! error estimate (the "error" layer) at least as large as its true error.
//!
//! The expected values come from the cases' own independent reference (good to ~1e-14
//! relative); the README prints them to 10 significant digits, so half a unit in their last
//! printed digit is allowed on top of the true error in check (2). They are checked here
//! against `gas_reference` too, a second independent reference.

use std::path::PathBuf;

use gtsphere::render::{Integrator, RenderOptions, SamplerKind};
use gtsphere::scene::{Light, Scene};
use gtsphere::vrml::{load_path, LoadOptions};

use crate::gas_reference::{checked, Ball, Lamp};

/// The cases, or `None` (the test is skipped) when ../shared is not beside the checkout.
fn cases_dir() -> Option<PathBuf> {
    crate::support::shared("cases/gas-accuracy")
}

/// The `render` settings of a README row other than size and `--tol`.
#[derive(Clone, Copy)]
enum Run {
    /// `--integrator exact` (the default).
    Exact,
    /// `--integrator mc --spp N`: scenes without scattering, where the Monte Carlo
    /// integrator's expected-value emission is the closed form; `tol` is then the relative
    /// error allowed (rounding), and its error layer (a standard error) must cover too.
    Mc(u32),
}

/// One pixel of a README row: (row, col) with row 0 at the top, and the expected value as
/// printed there.
struct Probe {
    row: usize,
    col: usize,
    expected: &'static str,
}

/// One README command: image size and `--tol`, and the pixels listed for it.
struct Command {
    width: u32,
    height: u32,
    tol: f64,
    probes: &'static [Probe],
}

/// A command with `--integrator mc --spp N` (see [`Run::Mc`]).
struct McCommand {
    width: u32,
    height: u32,
    spp: u32,
    probes: &'static [Probe],
}

const fn px(row: usize, col: usize, expected: &'static str) -> Probe {
    Probe { row, col, expected }
}

const LIGHT_ON_SURFACE: &[Command] = &[
    Command {
        width: 32,
        height: 32,
        tol: 1e-8,
        probes: &[px(6, 26, "0.03172993481")],
    },
    Command {
        width: 128,
        height: 128,
        tol: 1e-8,
        probes: &[px(28, 102, "0.03187363157"), px(28, 103, "0.03128416623")],
    },
];

const DENSE_SHADOW_POINT: &[Command] = &[
    Command {
        width: 32,
        height: 32,
        tol: 1e-6,
        probes: &[px(8, 20, "0.00508250201"), px(12, 23, "0.00490844904")],
    },
    Command {
        width: 32,
        height: 32,
        tol: 1e-2,
        probes: &[px(8, 20, "0.00508250201")],
    },
];

const TINY_DENSE_SHADOW: &[Command] = &[
    Command {
        width: 32,
        height: 32,
        tol: 1e-8,
        probes: &[px(9, 22, "0.01510585916"), px(10, 21, "0.01703763063")],
    },
    Command {
        width: 32,
        height: 32,
        tol: 1e-1,
        probes: &[px(15, 16, "0.02014717713")],
    },
];

const ATTENUATION_KINK: &[Command] = &[
    Command {
        width: 32,
        height: 32,
        tol: 1e-6,
        probes: &[px(7, 21, "0.02545802666"), px(13, 22, "0.00876284043")],
    },
    Command {
        width: 32,
        height: 32,
        tol: 1e-8,
        probes: &[px(13, 22, "0.00876284043"), px(13, 23, "0.0100842997")],
    },
];

const ALL: &[(&str, &[Command])] = &[
    ("light_on_surface", LIGHT_ON_SURFACE),
    ("dense_shadow_point", DENSE_SHADOW_POINT),
    ("tiny_dense_shadow", TINY_DENSE_SHADOW),
    ("attenuation_kink", ATTENUATION_KINK),
];

/// Half a unit in the last printed digit of a decimal like "0.00508250201".
fn printed_half_ulp(s: &str) -> f64 {
    let decimals = s.split_once('.').map_or(0, |(_, f)| f.len());
    0.5 * 10f64.powi(-(decimals as i32))
}

/// Renders `case.wrl` once per command and checks every probe; all failures are collected
/// and reported together, with by how much each misses.
fn check_case(case: &str, commands: &[Command]) {
    let Some(cases) = cases_dir() else { return };
    let runs: Vec<_> = commands.iter().map(|c| (c, Run::Exact)).collect();
    check_runs(&cases, case, &runs);
}

/// [`check_case`] for the Monte Carlo rows: `tol` is the relative rounding allowed.
fn check_mc_case(case: &str, commands: &[McCommand]) {
    let Some(cases) = cases_dir() else { return };
    let as_commands: Vec<Command> = commands
        .iter()
        .map(|c| Command {
            width: c.width,
            height: c.height,
            tol: 1e-6,
            probes: c.probes,
        })
        .collect();
    let runs: Vec<_> = as_commands
        .iter()
        .zip(commands)
        .map(|(c, m)| (c, Run::Mc(m.spp)))
        .collect();
    check_runs(&cases, case, &runs);
}

/// Renders `dir/case.wrl` once per command and checks every probe.
fn check_runs(dir: &std::path::Path, case: &str, runs: &[(&Command, Run)]) {
    let path = dir.join(format!("{case}.wrl"));
    let mut failures = Vec::new();
    for &(cmd, run) in runs {
        let (scene, _) = load_path(&path, &LoadOptions::default()).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (shared/ must be beside the checkout)",
                path.display()
            )
        });
        let mut opts = RenderOptions {
            width: cmd.width,
            height: cmd.height,
            sampler: SamplerKind::Center,
            integrator: match run {
                Run::Exact => Integrator::Exact,
                Run::Mc(_) => Integrator::Mc,
            },
            spp: match run {
                Run::Exact => 1,
                Run::Mc(n) => n,
            },
            tol: cmd.tol,
            ..RenderOptions::default()
        };
        opts.aovs.error = true;
        let done = crate::support::render_auto(scene, &opts);
        let image = done.image();
        let error = &image
            .layers
            .iter()
            .find(|l| l.name == "error")
            .expect("error layer")
            .data;
        for p in cmd.probes {
            let at = p.row * cmd.width as usize + p.col;
            let got = done.rgb[at].iter().copied().fold(f64::MIN, f64::max);
            let expected: f64 = p.expected.parse().expect("expected value");
            let true_err = (got - expected).abs();
            let reported = f64::from(error[at]);
            let within_tol = true_err <= cmd.tol * expected;
            // The layer is f32: allow its rounding; the README's values are rounded to
            // their printed digits.
            let covered = reported * (1.0 + 1e-6) + printed_half_ulp(p.expected) >= true_err;
            let line = format!(
                "{case} {}x{} tol {:e} pixel ({},{}): got {got:.12e} expected {expected:.12e}: \
                 rel err {:.2e} = {:.3}x tol, error layer {:.2e} = {:.3}x the true error",
                cmd.width,
                cmd.height,
                cmd.tol,
                p.row,
                p.col,
                true_err / expected,
                true_err / (cmd.tol * expected),
                reported,
                reported / true_err
            );
            eprintln!("{line}");
            if !within_tol || !covered {
                let why = match (within_tol, covered) {
                    (false, false) => "outside tol, error layer below the true error",
                    (false, true) => "outside tol",
                    _ => "error layer below the true error",
                };
                failures.push(format!("{line}: {why}"));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// A PointLight exactly on a gas sphere's surface: its shadow boundary is the tangent plane
/// (a degenerate cone), crossed by these camera rays.
#[test]
fn point_light_on_a_gas_surface_casts_a_resolved_tangent_plane_shadow() {
    check_case("light_on_surface", LIGHT_ON_SURFACE);
}

/// A tau-700 shadower under a PointLight: the rim of its shadow cone must be resolved, and at
/// every tolerance (the error used to be the same at 1e-2 and 1e-6).
#[test]
fn rim_of_a_dense_shadow_cone_is_resolved_at_every_tolerance() {
    check_case("dense_shadow_point", DENSE_SHADOW_POINT);
}

/// Tiny tau-700 shadowers (r 0.04, 0.05) under a DirectionalLight and a PointLight: their
/// shadow rims are thinner than 1e-7 and must still be resolved, or at least reported.
#[test]
fn rims_of_tiny_dense_shadowers_are_resolved_or_reported() {
    check_case("tiny_dense_shadow", TINY_DENSE_SHADOW);
}

/// Attenuation 0 0 1: 1 / max(d^2, 1) has a kink at distance 1 from the light, which must be
/// a break point of the quadrature.
#[test]
fn attenuation_kink_at_unit_distance_is_a_break_point() {
    check_case("attenuation_kink", ATTENUATION_KINK);
}

/// Monte Carlo of an optically thick emitter (tau 9 across) and of what lies behind a tau-25
/// absorber: the rare escaping paths are expected values, not samples, so the values are the
/// closed forms to rounding and the standard error is honestly 0.
#[test]
fn monte_carlo_emission_of_thick_gas_is_its_closed_form() {
    check_mc_case("mc_thick_emitter", MC_THICK_EMITTER);
}

/// Monte Carlo of optically thin gas (tau 1e-8 and 1e-12 across): the emission is seen
/// although no sampled collision would ever happen.
#[test]
fn monte_carlo_emission_of_faint_gas_is_its_closed_form() {
    check_mc_case("mc_faint", MC_FAINT);
}

const MC_THICK_EMITTER: &[McCommand] = &[
    McCommand {
        width: 16,
        height: 16,
        spp: 64,
        probes: &[px(8, 4, "0.799870951"), px(8, 11, "7.367962646e-11")],
    },
    McCommand {
        width: 16,
        height: 16,
        spp: 1024,
        probes: &[px(8, 4, "0.799870951"), px(8, 11, "7.367962646e-11")],
    },
];

const MC_FAINT: &[McCommand] = &[McCommand {
    width: 32,
    height: 32,
    spp: 1024,
    probes: &[px(14, 11, "7.506264449e-09"), px(10, 18, "1.037551111e-12")],
}];

/// A PointLight whose `radius` (1.5) cuts through a gas sphere that shadows itself: the
/// light reaches only the cap within the radius, and there it is attenuated by the sphere
/// like anywhere else (the shadower's extent along the camera ray must not stop at the
/// radius). ../shared/cases/light-radius/, at the default tolerance and a fine one.
#[test]
fn a_point_light_radius_cutting_through_gas_keeps_its_shadow() {
    let Some(dir) = crate::support::shared("cases/light-radius") else {
        return;
    };
    const PROBES: &[Probe] = &[
        px(13, 12, "0.00476366853931"),
        px(11, 11, "0.0123731155209"),
        px(9, 10, "0.0131959377925"),
        px(12, 12, "0.0151357886413"),
        px(6, 15, "0.0317805645174"),
    ];
    let commands = [1e-4, 1e-6, 1e-8].map(|tol| Command {
        width: 24,
        height: 24,
        tol,
        probes: PROBES,
    });
    let runs: Vec<_> = commands.iter().map(|c| (c, Run::Exact)).collect();
    check_runs(&dir, "light_radius_cut", &runs);
}

/// Every row of the README is one of the probes above (with the same size,
/// tol and expected value), so a case added there is not forgotten here.
#[test]
fn every_row_of_the_cases_readme_is_tested() {
    let Some(cases) = cases_dir() else { return };
    let readme = std::fs::read_to_string(cases.join("README.md")).expect("README.md");
    let mut rows = 0;
    for line in readme.lines().filter(|l| l.starts_with("| ")) {
        let cols: Vec<&str> = line.split('|').map(str::trim).collect();
        // | case | command | pixel | expected | got | rel err | error AOV |
        let (case, command, pixel, expected) = (cols[1], cols[2], cols[3], cols[4]);
        if case == "case" || case.starts_with("---") {
            continue;
        }
        let arg = |name: &str| -> &str {
            let words: Vec<&str> = command.trim_matches('`').split_whitespace().collect();
            let k = words
                .iter()
                .position(|w| *w == name)
                .unwrap_or_else(|| panic!("{name} in {command}"));
            words[k + 1]
        };
        let (w, h): (u32, u32) = (
            arg("--width").parse().unwrap(),
            arg("--height").parse().unwrap(),
        );
        let (r, c) = pixel.split_once(',').expect("row,col");
        let (r, c): (usize, usize) = (r.parse().unwrap(), c.parse().unwrap());
        let listed = |probes: &[Probe]| {
            probes
                .iter()
                .any(|p| p.row == r && p.col == c && p.expected == expected)
        };
        if command.contains("--integrator mc") {
            let spp: u32 = arg("--spp").parse().unwrap();
            let commands = match case {
                "mc_thick_emitter" => MC_THICK_EMITTER,
                "mc_faint" => MC_FAINT,
                _ => panic!("Monte Carlo case {case} has no test"),
            };
            let found = commands.iter().any(|cmd| {
                cmd.width == w && cmd.height == h && cmd.spp == spp && listed(cmd.probes)
            });
            assert!(found, "README row not tested: {line}");
            rows += 1;
            continue;
        }
        let tol: f64 = arg("--tol").parse().unwrap();
        let commands = ALL
            .iter()
            .find(|(name, _)| *name == case)
            .unwrap_or_else(|| panic!("case {case} has no test"))
            .1;
        let found = commands
            .iter()
            .any(|cmd| cmd.width == w && cmd.height == h && cmd.tol == tol && listed(cmd.probes));
        assert!(found, "README row not tested: {line}");
        rows += 1;
    }
    assert_eq!(rows, 19, "rows in the README (13 exact, 6 Monte Carlo)");
}

/// The scene as the brute-force reference's spheres and lamps (every case is plain spheres,
/// unscoped lights, headlight off).
fn reference_scene(scene: &Scene) -> (Vec<Ball>, Vec<Lamp>) {
    assert!(!scene.headlight && scene.ellipsoids.is_empty());
    let balls = scene
        .spheres
        .iter()
        .map(|s| {
            let m = &scene.material_of(s);
            Ball {
                c: s.center,
                r: s.radius,
                gas: (m.transparency > 0.0).then_some((m.transparency, m.emissive, m.diffuse)),
            }
        })
        .collect();
    let lamps = scene
        .lights
        .iter()
        .map(|l| match *l {
            Light::Point(p) => {
                assert!(p.on && p.radius >= 100.0);
                Lamp::Point {
                    p: p.location,
                    power: p.color * p.intensity,
                    att: p.attenuation,
                }
            }
            Light::Directional(d) => {
                assert!(d.on && d.scope.covers_all(scene.spheres.len()));
                Lamp::Dir {
                    to_light: -d.direction.normalize(),
                    power: d.color * d.intensity,
                }
            }
        })
        .collect();
    (balls, lamps)
}

/// The README's expected values agree with `gas_reference` at every probe, to their printed
/// digits: two independent references, so a failure above is the renderer's.
#[test]
fn expected_values_agree_with_the_brute_force_reference() {
    let Some(cases) = cases_dir() else { return };
    let mut worst = 0.0f64;
    for (case, commands) in ALL {
        let path = cases.join(format!("{case}.wrl"));
        for cmd in *commands {
            let (scene, _) = load_path(&path, &LoadOptions::default()).expect("load");
            let (balls, lamps) = reference_scene(&scene);
            let opts = RenderOptions {
                width: cmd.width,
                height: cmd.height,
                ..RenderOptions::default()
            };
            let prep = crate::support::prepare(scene);
            let cam =
                crate::support::default_camera(&prep, &opts).image_plane(opts.width, opts.height);
            for p in cmd.probes {
                let (o, w) = cam.ray(
                    (p.col as f64 + 0.5) / f64::from(cmd.width),
                    (p.row as f64 + 0.5) / f64::from(cmd.height),
                );
                let (r, ref_err) = checked(&balls, &lamps, o, w);
                let got = r.gas.max_element();
                let expected: f64 = p.expected.parse().unwrap();
                let diff = (got - expected).abs();
                worst = worst.max(diff / expected);
                eprintln!(
                    "{case} ({},{}): reference {got:.12e}, README {expected:.12e}, rel diff \
                     {:.1e}, reference's own error {:.1e}",
                    p.row,
                    p.col,
                    diff / expected,
                    ref_err / got
                );
                assert!(
                    diff <= printed_half_ulp(p.expected) + 1e-12 * expected
                        && ref_err <= 1e-12 * got,
                    "{case} ({},{}): reference {got:e} +- {ref_err:e}, README {expected:e}",
                    p.row,
                    p.col
                );
            }
        }
    }
    eprintln!("largest relative difference {worst:.1e}");
}

/// The error estimate is an upper estimate over whole images, not just at the probes: every
/// pixel of every exact case at four tolerances against `gas_reference`. Of the pixels whose
/// true error is above rounding (1e-13 of the value), at least 99 % are covered, every pixel
/// is within its tolerance, and the median reported / true error is at most 30.
#[test]
fn error_estimate_covers_every_pixel_of_the_cases() {
    let Some(cases) = cases_dir() else { return };
    let (mut counted, mut covered, mut ratios) = (0usize, 0usize, Vec::new());
    let mut failures = Vec::new();
    for (case, _) in ALL {
        let path = cases.join(format!("{case}.wrl"));
        let (scene, _) = load_path(&path, &LoadOptions::default()).expect("load");
        let (balls, lamps) = reference_scene(&scene);
        let n = 48;
        let base = RenderOptions {
            width: n,
            height: n,
            sampler: SamplerKind::Center,
            ..RenderOptions::default()
        };
        let prep = crate::support::prepare(scene);
        let cam = crate::support::default_camera(&prep, &base).image_plane(base.width, base.height);
        let reference: Vec<(f64, f64)> = (0..n * n)
            .map(|k| {
                let (o, w) = cam.ray(
                    (f64::from(k % n) + 0.5) / f64::from(n),
                    (f64::from(k / n) + 0.5) / f64::from(n),
                );
                let (r, err) = checked(&balls, &lamps, o, w);
                (r.gas.max_element(), err)
            })
            .collect();
        for tol in [1e-2, 1e-4, 1e-6, 1e-8] {
            let mut opts = RenderOptions {
                tol,
                ..base.clone()
            };
            opts.aovs.error = true;
            let film = crate::support::render_prepared(&prep, &opts);
            let error = film.error.as_ref().expect("error");
            for (k, &(want, ref_err)) in reference.iter().enumerate() {
                let got = film.rgb[k].iter().copied().fold(f64::MIN, f64::max);
                let diff = (got - want).abs();
                if diff > tol * want.max(1e-3) + ref_err {
                    failures.push(format!(
                        "{case} tol {tol:e} pixel {k}: got {got:e}, reference {want:e}"
                    ));
                }
                if diff <= 1e-13 * want.max(1e-300) + ref_err {
                    continue;
                }
                counted += 1;
                if error[k] + ref_err >= diff {
                    covered += 1;
                } else {
                    eprintln!(
                        "not covered: {case} tol {tol:e} pixel {k}: got {got:e}, reference \
                         {want:e}, error {:e}, estimate {:e}",
                        diff, error[k]
                    );
                }
                ratios.push(error[k] / diff);
            }
        }
    }
    ratios.sort_by(f64::total_cmp);
    let median = ratios.get(ratios.len() / 2).copied().unwrap_or(0.0);
    let share = covered as f64 / counted.max(1) as f64;
    eprintln!(
        "{counted} pixels above rounding, {covered} covered ({:.2} %), median reported / true \
         {median:.1}, lowest {:.2}",
        100.0 * share,
        ratios.first().copied().unwrap_or(0.0)
    );
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
    assert!(share >= 0.99, "coverage {:.2} %", 100.0 * share);
    assert!(median <= 30.0, "median reported / true {median}");
}
