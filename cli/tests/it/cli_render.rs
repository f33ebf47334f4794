//! `gtsphere render` as a user runs it: the binary, its files and its errors.

use std::path::{Path, PathBuf};
use std::process::Output;

use gtsphere::output::read_image;

mod limits;
mod scene_options;

fn gtsphere(args: &[&str], dir: &Path) -> Output {
    crate::support::gtsphere(args, dir)
}

/// A fresh empty directory under the target dir.
fn scratch(name: &str) -> PathBuf {
    crate::support::scratch("cli_render", name)
}

fn sample(name: &str) -> String {
    crate::support::sample(name)
}

#[test]
fn renders_a_sample_with_defaults_to_scene_name_png() {
    let dir = scratch("defaults");
    let out = gtsphere(&["render", &sample("cluster.wrl")], &dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = read_image(&dir.join("cluster.png")).expect("cluster.png");
    assert_eq!((img.width, img.height), (800, 600));
    // Lit spheres on a dark background: some bright pixels, some background.
    let bright = img.rgb.iter().filter(|p| p[0] > 0.5).count();
    assert!(bright > 1000, "{bright}");
    // Nothing but the image is left in the directory (no temporary files).
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

/// Off a terminal (a batch job's log), progress is a line at the start and one every few
/// seconds; `--quiet` prints none.
#[test]
fn progress_is_lines_when_stderr_is_not_a_terminal() {
    let dir = scratch("progress_lines");
    let args = [
        "render",
        &sample("cluster.wrl"),
        "--width",
        "64",
        "--height",
        "48",
    ];
    let out = gtsphere(&args, &dir);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("rendering 12 tiles\n"), "{err}");
    let quiet = gtsphere(&[&args[..], &["-q"]].concat(), &dir);
    assert!(
        quiet.status.success() && quiet.stderr.is_empty(),
        "{quiet:?}"
    );
}

#[test]
fn pfm_of_an_unlit_sphere_is_the_exact_disc() {
    // Unlit white unit sphere, orthographic height 4 on a 32x32 image: pixel centres inside
    // the unit disc are exactly 1, outside exactly the background.
    let dir = scratch("pfm");
    std::fs::write(
        dir.join("s.wrl"),
        "#VRML V2.0 utf8\nBackground { skyColor 0.25 0.5 0.75 }\nShape { geometry Sphere { } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render",
            "s.wrl",
            "-o",
            "s.pfm",
            "--width",
            "32",
            "--height",
            "32",
            "--ortho",
            "--ortho-height",
            "4",
            "--sampler",
            "center",
            "--quiet",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stderr.is_empty(), "--quiet prints nothing");
    let img = read_image(&dir.join("s.pfm")).unwrap();
    for j in 0..32 {
        for i in 0..32 {
            let x = ((i as f64 + 0.5) / 32.0 * 2.0 - 1.0) * 2.0;
            let y = (1.0 - (j as f64 + 0.5) / 32.0 * 2.0) * 2.0;
            let want = if x * x + y * y < 1.0 {
                [1.0, 1.0, 1.0]
            } else {
                [0.25, 0.5, 0.75]
            };
            assert_eq!(img.rgb[j * 32 + i], want, "pixel ({i},{j})");
        }
    }
}

#[test]
fn exr_carries_alpha_and_the_requested_aovs() {
    let dir = scratch("exr");
    let out = gtsphere(
        &[
            "render",
            &sample("cluster.wrl"),
            "-o",
            "c.exr",
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "4",
            "--aov",
            "depth,normal,id",
            "--quiet",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = read_image(&dir.join("c.exr")).unwrap();
    let mut names: Vec<&str> = img.layers.iter().map(|l| l.name.as_str()).collect();
    names.sort();
    assert_eq!(names, ["depth", "id", "normal.X", "normal.Y", "normal.Z"]);
    assert!(img.alpha.contains(&1.0) && img.alpha.contains(&0.0));
    let layer = |n: &str| &img.layers.iter().find(|l| l.name == n).unwrap().data;
    let (depth, id, nz) = (layer("depth"), layer("id"), layer("normal.Z"));
    for k in 0..img.alpha.len() {
        if id[k] < 0.0 {
            assert!(depth[k].is_infinite());
        } else {
            assert!(depth[k] > 0.0 && depth[k] < 20.0);
            // Seen surfaces face the camera (at +z, looking down -z): N.V > 0 with V within the
            // half field of view (0.3 rad, about 0.42 rad at the corners) of +z.
            assert!(nz[k] > -0.42, "normal.Z {}", nz[k]);
        }
    }
}

#[test]
fn bad_scene_gives_a_positioned_error_and_no_file() {
    let dir = scratch("bad");
    std::fs::write(
        dir.join("bad.wrl"),
        "#VRML V2.0 utf8\nShape { geometry Sphere { radius -1 } }\n",
    )
    .unwrap();
    let out = gtsphere(&["render", "bad.wrl", "-o", "bad.png"], &dir);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("bad.wrl:2:"), "{err}");
    assert!(!dir.join("bad.png").exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
}

#[test]
fn bad_arguments_are_refused_before_any_work() {
    let dir = scratch("args");
    let cases: &[(&[&str], &str)] = &[
        (&["-o", "x.jpg"], "expected .png, .exr, .pfm or .npy"),
        (
            &["-o", "x.png", "--aov", "depth"],
            "--aov needs an .exr output",
        ),
        (&["-o", "x.png", "--spp", "0"], "--spp must be between"),
        (&["-o", "x.png", "--width", "0"], "--width and --height"),
        (
            &["-o", "x.png", "--viewpoint", "nope"],
            "no Viewpoint named \"nope\"",
        ),
        (
            &["-o", "x.png", "--ortho", "--ortho-height=-2"],
            "--ortho-height must be",
        ),
        (
            &["-o", "x.png", "--threads", "0"],
            "--threads must be at least 1",
        ),
    ];
    for (extra, want) in cases {
        let mut args = vec!["render", "s.wrl"];
        args.extend_from_slice(extra);
        std::fs::write(
            dir.join("s.wrl"),
            "#VRML V2.0 utf8\nShape { geometry Sphere { } }\n",
        )
        .unwrap();
        let out = gtsphere(&args, &dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!dir.join("x.png").exists() && !dir.join("x.jpg").exists());
    }
}

#[test]
fn says_when_the_camera_is_framed_because_there_is_no_viewpoint() {
    let dir = scratch("frame");
    std::fs::write(
        dir.join("s.wrl"),
        "#VRML V2.0 utf8\nShape { geometry Sphere { } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &["render", "s.wrl", "--width", "16", "--height", "16"],
        &dir,
    );
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no Viewpoint in the scene"), "{err}");
}

#[test]
fn as_gas_turns_an_unlit_sphere_into_glowing_gas() {
    // Unlit shape as gas: C = 1, a = 0; orthographic rays parallel to z through a unit sphere:
    // value = 1 - exp(-sigma * chord) + background * exp(-sigma * chord).
    let dir = scratch("as_gas");
    std::fs::write(
        dir.join("s.wrl"),
        "#VRML V2.0 utf8\nBackground { skyColor 0.5 0 0 }\nShape { geometry Sphere { } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render",
            "s.wrl",
            "-o",
            "s.exr",
            "--width",
            "16",
            "--height",
            "16",
            "--ortho",
            "--ortho-height",
            "2.5",
            "--sampler",
            "center",
            "--as-gas",
            "0.7",
            "--aov",
            "error",
            "--quiet",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = read_image(&dir.join("s.exr")).unwrap();
    let error = &img.layers.iter().find(|l| l.name == "error").unwrap().data;
    for j in 0..16 {
        for i in 0..16 {
            let x = ((i as f64 + 0.5) / 16.0 * 2.0 - 1.0) * 1.25;
            let y = (1.0 - (j as f64 + 0.5) / 16.0 * 2.0) * 1.25;
            let rho2 = x * x + y * y;
            let chord = if rho2 < 1.0 {
                2.0 * (1.0 - rho2).sqrt()
            } else {
                0.0
            };
            let t = (-0.7 * chord).exp();
            let want = [1.0 - t + 0.5 * t, 1.0 - t, 1.0 - t];
            let got = img.rgb[j * 16 + i];
            for k in 0..3 {
                assert!(
                    (f64::from(got[k]) - want[k]).abs() < 1e-6,
                    "({i},{j}): {got:?} vs {want:?}"
                );
            }
            // No lights: closed form only, no quadrature error.
            assert_eq!(error[j * 16 + i], 0.0);
        }
    }
}
