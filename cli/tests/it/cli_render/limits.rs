//! Sizes beyond the machine's memory refused before the scene is read; `--threads` beyond
//! four per core lowered with a warning.

use gtsphere::render::{limits, RenderOptions};

use super::{gtsphere, scratch};

/// 50000 x 50000 pixels need some 200 GB: refused with the sizes in the message, before
/// the scene is read (it does not exist) and before any output is written.
#[test]
fn an_image_larger_than_the_memory_is_refused_before_reading() {
    let dir = scratch("too_large");
    let need = RenderOptions {
        width: 50_000,
        height: 50_000,
        ..RenderOptions::default()
    }
    .memory_bytes(1)
    .unwrap();
    match limits::available_memory() {
        Some(have) if have < need => {}
        other => {
            eprintln!("available memory {other:?} is not below {need} bytes: test skipped");
            return;
        }
    }
    let out = gtsphere(
        &[
            "render",
            "missing.wrl",
            "-o",
            "x.png",
            "--width",
            "50000",
            "--height",
            "50000",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("a 50000x50000 image (spp 16, ")
            && err.contains(" GB of memory; this machine has "),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

#[test]
fn threads_beyond_four_per_core_are_lowered_with_a_warning() {
    let dir = scratch("many_threads");
    std::fs::write(
        dir.join("s.wrl"),
        "#VRML V2.0 utf8\nShape { geometry Sphere { } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render",
            "s.wrl",
            "-o",
            "x.png",
            "--width",
            "64",
            "--height",
            "48",
            "--threads",
            "100000",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let cap = limits::max_threads();
    assert!(
        err.contains(&format!(
            "warning: --threads 100000 is more than 4 per core of this machine's {} core",
            cap / 4
        )) && err.contains(&format!(": using {cap}\n")),
        "{err}"
    );
    assert!(dir.join("x.png").exists());
}

/// A scene no camera can frame (it reaches 1e308) is refused at the item that reaches
/// farthest, before the BVH is built, and nothing is written.
#[test]
fn a_scene_beyond_framing_is_refused_at_its_farthest_item() {
    let dir = scratch("beyond_framing");
    std::fs::write(
        dir.join("far.wrl"),
        "#VRML V2.0 utf8\nShape { geometry Sphere {} }\n\
         Transform { translation 1e308 0 0 children Shape { geometry Sphere { radius 1e307 } } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render", "far.wrl", "-o", "x.png", "--width", "8", "--height", "8",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("far.wrl:3:61: the scene reaches this far from the origin"),
        "{err}"
    );
    assert!(!dir.join("x.png").exists());
}
