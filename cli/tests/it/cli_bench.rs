//! `gtsphere bench --quick`: the speed-against-error report as a user runs it.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::support::stdout_of;

/// One CSV row: (integrator, param, rel_rms, rel_max, seconds).
type Point = (String, f64, f64, f64, f64);

fn read_csv(path: &Path) -> BTreeMap<String, Vec<Point>> {
    let text = std::fs::read_to_string(path).expect("bench.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (sc, ig, pa, rr, rm, se) = (
        col("scene"),
        col("integrator"),
        col("param"),
        col("rel_rms"),
        col("rel_max"),
        col("seconds"),
    );
    let mut by_scene: BTreeMap<String, Vec<Point>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), header.len(), "{line}");
        let num = |k: usize| {
            f[k].parse::<f64>()
                .unwrap_or_else(|e| panic!("{line}: {e}"))
        };
        by_scene.entry(f[sc].to_string()).or_default().push((
            f[ig].to_string(),
            num(pa),
            num(rr),
            num(rm),
            num(se),
        ));
    }
    by_scene
}

fn errors(rows: &[Point], integrator: &str) -> Vec<f64> {
    rows.iter()
        .filter(|r| r.0 == integrator)
        .map(|r| r.2)
        .collect()
}

#[test]
fn bench_quick_writes_csv_table_and_plot() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bench_quick");
    let _ = std::fs::remove_dir_all(&dir);
    let stdout = stdout_of(
        Command::new(env!("CARGO_BIN_EXE_gtsphere"))
            .args(["bench", "--quick", "--out"])
            .arg(&dir),
    );
    let md = std::fs::read_to_string(dir.join("bench.md")).expect("bench.md");
    assert_eq!(stdout, md, "the table printed is bench.md");
    assert!(md.contains("| lit gas | exact | tol 1e-2 |"), "{md}");
    assert!(md.contains("## Throughput"), "{md}");

    let csv = read_csv(&dir.join("bench.csv"));
    let want: [(&str, &[&str]); 4] = [
        ("opaque", &["surface"]),
        ("emission", &["exact", "march", "mc"]),
        ("lit gas", &["exact", "march", "mc"]),
        ("profiled gas", &["exact", "march", "mc"]),
    ];
    assert_eq!(csv.len(), want.len(), "{:?}", csv.keys());
    for (scene, integrators) in want {
        let rows = &csv[scene];
        for r in rows {
            assert!(
                r.2.is_finite() && r.2 >= 0.0 && r.3.is_finite() && r.3 >= 0.0,
                "{scene}: {r:?}"
            );
            assert!(r.4 > 0.0 && r.4.is_finite(), "{scene}: {r:?}");
        }
        for ig in integrators {
            let e = errors(rows, ig);
            assert!(e.len() >= 3, "{scene} {ig}: {e:?}");
            if *ig == "exact" || (*ig == "mc" && scene == "emission") {
                // exact; and mc, whose emission and transmittance are expected values (closed
                // form), is exact where nothing scatters.
                continue;
            }
            // Approximations: a real error that shrinks as the setting tightens.
            assert!(e[0] > 1e-3, "{scene} {ig}: {e:?}");
            assert!(e[e.len() - 1] < 0.5 * e[0], "{scene} {ig}: {e:?}");
        }
    }
    // march is first order in the step: each 4x finer step cuts the error by 2x at least.
    for scene in ["emission", "lit gas", "profiled gas"] {
        let e = errors(&csv[scene], "march");
        assert!(e.windows(2).all(|w| w[1] < 0.5 * w[0]), "{scene}: {e:?}");
    }
    // exact without lights is closed form: equal to the reference up to rounding; so is mc.
    for ig in ["exact", "mc"] {
        let e = errors(&csv["emission"], ig);
        assert!(e.iter().all(|&v| v < 1e-12), "{ig}: {e:?}");
    }
    // exact with scattering: within each tolerance (it truncates what cannot matter at the
    // tolerance asked for, so a loose tol gives a looser answer), no worse as tol tightens,
    // ending below both the loosest setting's error and 1e-8; with profiles too.
    for scene in ["lit gas", "profiled gas"] {
        let e = errors(&csv[scene], "exact");
        let tols: Vec<f64> = csv[scene]
            .iter()
            .filter(|r| r.0 == "exact")
            .map(|r| r.1)
            .collect();
        assert!(
            e.iter().zip(&tols).all(|(&v, &t)| v <= t),
            "{scene}: {e:?} at {tols:?}"
        );
        assert!(
            e.windows(2).all(|w| w[1] <= w[0] * 1.5),
            "{scene}: exact's error grows as tol tightens: {e:?}"
        );
        assert!(
            e[e.len() - 1] < e[0] && e[e.len() - 1] < 1e-8,
            "{scene}: {e:?}"
        );
    }

    let png = std::fs::read(dir.join("bench.png")).expect("bench.png");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let img = image::load_from_memory_with_format(&png, image::ImageFormat::Png)
        .expect("decode bench.png")
        .to_rgb8();
    assert!(img.width() >= 3 * img.height() / 2, "one panel per scene");
    // Every integrator's colour is drawn (exact blue, march orange, mc green, surface
    // purple), so the curves are there, not only the axes.
    for rgb in [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [148, 103, 189],
    ] {
        let n = img.pixels().filter(|p| p.0 == rgb).count();
        assert!(n > 50, "colour {rgb:?}: {n} pixels");
    }
}

/// `gtsphere bench gas --scaling --quick`: the scaling table and its ratios, as a user runs it.
#[test]
fn bench_gas_scaling_quick_prints_the_table_and_the_ratios() {
    let stdout = stdout_of(
        Command::new(env!("CARGO_BIN_EXE_gtsphere"))
            .args(["bench", "gas", "--scaling", "--quick", "--size", "16"])
            .args(["--march-budget", "0.5", "--runs", "1"]),
    );
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| l.starts_with("| 1"))
        .map(|l| l.split('|').map(str::trim).collect())
        .collect();
    let keys: Vec<(&str, &str)> = rows.iter().map(|r| (r[1], r[2])).collect();
    assert_eq!(
        keys,
        [
            ("1000", "thick"),
            ("1000", "thin"),
            ("10000", "thick"),
            ("10000", "thin")
        ],
        "{stdout}"
    );
    for r in &rows {
        let num = |k: usize| r[k].trim_end_matches('%').parse::<f64>().unwrap();
        // seconds (and the lights' grids' part), camera rays/s, nodes per ray, time per
        // shadowing sphere, rel. RMS error, coverage.
        assert!(num(3) > 0.0 && num(6) > 0.0, "{r:?}");
        assert!((0.0..=num(3)).contains(&num(4)), "{r:?}");
        assert!(num(7) > 0.0, "a lit cloud needs quadrature nodes: {r:?}");
        assert!(num(9) > 0.0, "a lit cloud has shadowing spheres: {r:?}");
        assert!(num(10) >= 0.0 && num(10) < 1e-2, "{r:?}");
        assert!((0.0..=100.0).contains(&num(11)), "{r:?}");
        // march's time: measured or projected.
        assert!(r[15] != "-" || r[14] == "not reached", "{r:?}");
    }
    for line in [
        "- thick: time per camera ray relative to N = 1000: N 1000: 1.00x, N 10000: ",
        "- thin: time per shadowing sphere relative to N = 1000: N 1000: 1.00x, N 10000: ",
        "faster than march at equal error (",
        "- largest rel. RMS error at the default tol ",
        "- thick N = 1e4: pixels whose reported error covers the true error ",
        "- thin N = 1e4: pixels whose reported error covers the true error ",
    ] {
        assert!(stdout.contains(line), "no {line:?} in\n{stdout}");
    }
    // Measurements and ratios, not verdicts.
    for word in ["goal", "PASS", "FAIL"] {
        assert!(!stdout.contains(word), "{word:?} in\n{stdout}");
    }
}

/// `gtsphere bench gas --write DIR`: the clouds as files that `gtsphere render` reads.
#[test]
fn bench_gas_write_gives_files_that_render() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bench_gas_write");
    let _ = std::fs::remove_dir_all(&dir);
    stdout_of(
        Command::new(env!("CARGO_BIN_EXE_gtsphere"))
            .args(["bench", "gas", "--sizes", "1e3", "--write"])
            .arg(&dir),
    );
    for cloud in ["thick", "thin"] {
        let wrl = dir.join(format!("cloud-{cloud}-1000.wrl"));
        let img = dir.join(format!("cloud-{cloud}.pfm"));
        stdout_of(
            Command::new(env!("CARGO_BIN_EXE_gtsphere"))
                .arg("render")
                .arg(&wrl)
                .args(["--width", "8", "--height", "8", "--sampler", "center", "-o"])
                .arg(&img),
        );
        let pfm = std::fs::read(&img).expect("image");
        assert!(pfm.starts_with(b"PF\n8 8\n"));
    }
}

/// `gtsphere bench scale`: one row per N with the whole command's numbers; the files are
/// kept and reused by a second run.
#[test]
fn bench_scale_prints_a_row_per_size_and_reuses_its_files() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bench_scale");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = || {
        let stdout = stdout_of(
            Command::new(env!("CARGO_BIN_EXE_gtsphere"))
                .args([
                    "bench", "scale", "--sizes", "1e3,2000", "--size", "16", "--dir",
                ])
                .arg(&dir),
        );
        stdout
    };
    let rows = |text: &str| -> Vec<Vec<String>> {
        text.lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| N "))
            .map(|l| l.split('|').map(|c| c.trim().to_string()).collect())
            .collect()
    };
    let first = rows(&run());
    assert_eq!(first.len(), 2, "one row per size");
    for (row, n) in first.iter().zip([1000.0, 2000.0]) {
        assert_eq!(row.len(), 12, "{row:?}");
        let num = |k: usize| row[k].parse::<f64>().unwrap_or_else(|_| panic!("{row:?}"));
        assert_eq!(num(1), n);
        assert!(
            num(2) > 0.0 && num(3) >= 0.0,
            "VRML size and convert time: {row:?}"
        );
        for k in [4, 6, 7, 8] {
            assert!(num(k) >= 0.0, "seconds in column {k}: {row:?}");
        }
        // Particles read per second, and peak bytes per sphere from the child's own peak.
        assert!(
            (num(5) - n / num(4).max(1e-9)).abs() <= 1e-3 * num(5),
            "{row:?}"
        );
        assert!(
            (num(10) - num(9) * 1e6 / n).abs() <= 0.01 * num(10) + 1.0,
            "{row:?}"
        );
    }
    let second = rows(&run());
    assert!(
        second.iter().all(|r| r[3] == "(reused)"),
        "the VRML files are reused: {second:?}"
    );
}
