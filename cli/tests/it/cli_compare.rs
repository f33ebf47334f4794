//! `gtsphere compare` as a user runs it: the metrics it prints (checked by hand), the heat
//! map it writes and its exit code under `--max-rmse`.

use std::path::{Path, PathBuf};
use std::process::Output;

use gtsphere::output::read_image;

fn gtsphere(args: &[&str], dir: &Path) -> Output {
    crate::support::gtsphere(args, dir)
}

/// A fresh empty directory under the target dir.
fn scratch(name: &str) -> PathBuf {
    crate::support::scratch("cli_compare", name)
}

#[test]
fn compare_prints_hand_checked_metrics_and_fails_over_max_rmse() {
    use gtsphere::output::{write_image, Image};
    let dir = scratch("compare");
    let mk = |v: Vec<[f32; 3]>| Image {
        width: 2,
        height: 1,
        rgb: v,
        alpha: vec![1.0; 2],
        layers: Vec::new(),
    };
    write_image(
        &dir.join("ref.pfm"),
        &mk(vec![[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]),
    )
    .unwrap();
    write_image(
        &dir.join("a.pfm"),
        &mk(vec![[1.0, 1.0, 0.5], [0.0, 0.25, 0.0]]),
    )
    .unwrap();
    let out = gtsphere(&["compare", "a.pfm", "ref.pfm", "--heatmap", "d.png"], &dir);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // rmse = sqrt((0.25 + 0.0625) / 6) = 0.228218...
    assert!(text.contains("rmse           2.282177e-1"), "{text}");
    assert!(
        text.contains("max abs error  5.000000e-1 at pixel (0, 0)"),
        "{text}"
    );
    assert!(read_image(&dir.join("d.png")).is_ok());
    let out = gtsphere(&["compare", "a.pfm", "ref.pfm", "--max-rmse", "0.2"], &dir);
    assert_eq!(out.status.code(), Some(1));
    let out = gtsphere(&["compare", "a.pfm", "ref.pfm", "--max-rmse", "0.3"], &dir);
    assert_eq!(out.status.code(), Some(0));
}
