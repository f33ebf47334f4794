//! `render --integrator ao --ao-method NAME` as a user runs it: every method renders the
//! cluster sample and compares with exact, mc's error AOV, and the options' errors.

use gtsphere::output::read_image;

fn gtsphere(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    crate::support::gtsphere(args, dir)
}

const SIZE: [&str; 6] = ["--width", "40", "--height", "30", "--spp", "1"];

#[test]
fn every_method_renders_the_cluster_and_compares_with_exact() {
    let dir = crate::support::scratch("cli_ao", "methods");
    let cluster = crate::support::sample("cluster.wrl");
    for (method, extra) in [
        ("exact", &[][..]),
        ("mc", &["--ao-samples", "8"][..]),
        ("directions", &["--ao-directions", "32"][..]),
        ("sum", &[][..]),
        ("voxel", &[][..]),
    ] {
        let out_name = format!("{method}.exr");
        let mut args = vec![
            "render",
            &cluster,
            "--integrator",
            "ao",
            "--ao-method",
            method,
        ];
        args.extend(extra);
        args.extend(SIZE);
        args.extend(["--ao-reach", "2", "--aov", "error", "-o", &out_name]);
        let out = gtsphere(&args, &dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{method}: {err}");
        assert!(err.contains("ambient occlusion, "), "{method}: {err}");
        let img = read_image(&dir.join(&out_name)).expect("the render");
        let covered: Vec<usize> = (0..img.rgb.len()).filter(|&p| img.alpha[p] > 0.0).collect();
        assert!(
            covered.len() > 100,
            "{method}: {} pixels covered",
            covered.len()
        );
        assert!(
            covered
                .iter()
                .all(|&p| (0.0..=1.0).contains(&img.rgb[p][0])),
            "{method}: values in [0, 1]"
        );
        assert!(
            covered.iter().any(|&p| img.rgb[p][0] < 0.9),
            "{method}: some occlusion"
        );
        let error = img
            .layers
            .iter()
            .find(|l| l.name == "error")
            .expect("error AOV");
        let estimated = error.data.iter().any(|&e| e > 0.0);
        assert_eq!(estimated, method == "mc", "{method}: error estimates");
        if method != "exact" {
            let out = gtsphere(&["compare", &out_name, "exact.exr"], &dir);
            let text = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success() && text.contains("rmse"),
                "{method}: {text}"
            );
        }
    }
}

#[test]
fn ao_options_out_of_place_or_range_are_clear_errors() {
    let dir = crate::support::scratch("cli_ao", "errors");
    let cluster = crate::support::sample("cluster.wrl");
    for (args, message) in [
        (
            &["--ao-method", "mc", "--ao-samples", "0"][..],
            "--ao-samples must be between 1 and 1048576 (got 0)",
        ),
        (
            &["--ao-method", "directions", "--ao-directions", "0"][..],
            "--ao-directions must be between 1 and 65536 (got 0)",
        ),
        (
            &["--ao-method", "directions", "--ao-directions", "70000"][..],
            "--ao-directions must be between 1 and 65536 (got 70000)",
        ),
        (
            &["--ao-samples", "8"][..],
            "--ao-samples is only for --ao-method mc",
        ),
        (
            &["--ao-method", "mc", "--ao-directions", "8"][..],
            "--ao-directions is only for --ao-method directions",
        ),
    ] {
        let mut all = vec!["render", &cluster, "--integrator", "ao", "-o", "x.png"];
        all.extend(args);
        let out = gtsphere(&all, &dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(message), "{args:?}: {err}");
    }
    let out = gtsphere(
        &["render", &cluster, "--ao-method", "sum", "-o", "x.png"],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--ao-method is only for --integrator ao"),
        "{err}"
    );
    let out = gtsphere(
        &["render", &cluster, "--ao-method", "fast", "-o", "x.png"],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("possible values: exact, mc, directions, sum, voxel"),
        "{err}"
    );
}
