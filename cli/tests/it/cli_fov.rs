//! `render --fov-across` on a PyMOL export of the corpus: PyMOL writes the Viewpoint's
//! fieldOfView as the angle across the image width, and `--fov-across width` reads it so.
//! The framing is checked against a closed form: the first and last rows any sphere covers,
//! from the spheres' centres and radii and the camera's half tangents.

use std::path::{Path, PathBuf};

use gtsphere::output::read_image;
use gtsphere::vrml::{load_path, LoadOptions};

/// The corpus's PyMOL export of a 20-residue peptide as spheres, if the corpus is there.
fn peptide() -> Option<PathBuf> {
    let corpus = crate::support::shared("corpus")?;
    Some(corpus.join("tools/pymol/pymol_peptide20_spheres.wrl"))
}

/// Renders `scene` at `w x h` (one ray through each pixel centre, EXR) with `extra`
/// arguments; the first and last rows with any covered pixel, and what it printed on stderr.
fn covered_rows(
    scene: &Path,
    dir: &Path,
    w: u32,
    h: u32,
    extra: &[&str],
) -> ((usize, usize), String) {
    let out_path = dir.join(format!("{w}x{h}{}.exr", extra.join("")));
    let (ws, hs) = (w.to_string(), h.to_string());
    let (scene, out_name) = (scene.display().to_string(), out_path.display().to_string());
    let args = [
        &[
            "render",
            &scene,
            "-o",
            &out_name,
            "--width",
            &ws,
            "--height",
            &hs,
            "--sampler",
            "center",
        ][..],
        extra,
    ]
    .concat();
    let out = crate::support::gtsphere(&args, dir);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    let img = read_image(&out_path).expect("the render");
    let rows: Vec<usize> = (0..img.height)
        .filter(|&j| (0..img.width).any(|i| img.alpha[j * img.width + i] > 0.0))
        .collect();
    ((rows[0], rows[rows.len() - 1]), err)
}

/// The rows that the closed form says are the first and last covered, for a camera on the
/// +z axis at `eye_z` looking down -z whose image plane spans `+-half_h` (tangent units)
/// vertically over `h` rows. A sphere (centre c, radius r) seen from the eye reaches up to
/// the tangent `tan(atan2(c.y, d) + asin(r / |(c.y, d)|))`, with `d = eye_z - c.z` (the
/// tangent planes through the eye that hold the x direction touch it there).
fn predicted_rows(scene: &Path, eye_z: f64, half_h: f64, h: u32) -> (usize, usize) {
    let (s, _) = load_path(scene, &LoadOptions::default()).expect("the scene reads");
    let (mut top, mut bottom) = (f64::NEG_INFINITY, f64::INFINITY);
    for sp in &s.spheres {
        let d = eye_z - sp.center.z;
        let rho = sp.center.y.hypot(d);
        let (at, spread) = (sp.center.y.atan2(d), (sp.radius / rho).asin());
        top = top.max((at + spread).tan());
        bottom = bottom.min((at - spread).tan());
    }
    // Row j's centre is at tangent (1 - 2 (j + 0.5) / h) half_h.
    let h = f64::from(h);
    let row = |t: f64| h * (1.0 - t / half_h) / 2.0 - 0.5;
    (row(top).ceil() as usize, row(bottom).floor() as usize)
}

fn near(got: (usize, usize), want: (usize, usize)) -> bool {
    got.0.abs_diff(want.0) <= 1 && got.1.abs_diff(want.1) <= 1
}

/// At 4:3, `--fov-across width` spans the file's angle across the width (half tangent
/// `tan(fov / 2)` over 320 columns, so `0.75 tan(fov / 2)` over 240 rows); by default the
/// same angle spans the height. The covered rows match the closed form for both, and the
/// peptide is drawn 4/3 as tall across the width.
#[test]
fn pymol_export_is_framed_across_the_width() {
    let Some(scene) = peptide() else { return };
    let dir = crate::support::scratch("cli_fov", "width");
    let (s, _) = load_path(&scene, &LoadOptions::default()).expect("the scene reads");
    let vp = &s.viewpoints[0];
    let (eye_z, t) = (vp.position.z, (0.5 * vp.field_of_view).tan());
    assert_eq!(vp.field_of_view, 0.465421);

    let (width_rows, _) = covered_rows(&scene, &dir, 640, 480, &["--fov-across", "width"]);
    let want = predicted_rows(&scene, eye_z, 0.75 * t, 480);
    assert!(near(width_rows, want), "{width_rows:?} vs {want:?}");

    let (vrml_rows, _) = covered_rows(&scene, &dir, 640, 480, &[]);
    let want_vrml = predicted_rows(&scene, eye_z, t, 480);
    assert!(near(vrml_rows, want_vrml), "{vrml_rows:?} vs {want_vrml:?}");

    let tall = |r: (usize, usize)| (r.1 - r.0 + 1) as f64;
    let ratio = tall(width_rows) / tall(vrml_rows);
    assert!((ratio - 4.0 / 3.0).abs() < 0.02, "{ratio}");

    // Portrait: the width is the smaller side, so both readings are the same camera.
    let (portrait, _) = covered_rows(&scene, &dir, 480, 640, &["--fov-across", "width"]);
    let (portrait_vrml, _) = covered_rows(&scene, &dir, 480, 640, &[]);
    assert_eq!(portrait, portrait_vrml);
    let want = predicted_rows(&scene, eye_z, t * 640.0 / 480.0, 640);
    assert!(near(portrait, want), "{portrait:?} vs {want:?}");

    // Height: at 4:3 the height is the smaller side, the same as the default.
    let (height_rows, _) = covered_rows(&scene, &dir, 640, 480, &["--fov-across", "height"]);
    assert_eq!(height_rows, vrml_rows);
}

/// `render` says once that the file is a PyMOL export and how to frame it as PyMOL does,
/// unless `--fov-across` is given; a scene of another tool gets no such note.
#[test]
fn pymol_export_is_noted_until_a_side_is_chosen() {
    let Some(scene) = peptide() else { return };
    let dir = crate::support::scratch("cli_fov", "note");
    let (_, err) = covered_rows(&scene, &dir, 64, 48, &[]);
    assert_eq!(err.matches("--fov-across width").count(), 1, "{err}");
    assert!(err.contains("PyMOL"), "{err}");
    let (_, err) = covered_rows(&scene, &dir, 64, 48, &["--fov-across", "smaller"]);
    assert!(!err.contains("PyMOL"), "{err}");
    let (_, err) = covered_rows(&scene, &dir, 64, 48, &["--fov-across", "width"]);
    assert!(!err.contains("PyMOL"), "{err}");
    assert!(
        err.contains("camera: Viewpoint \"Z view\" (fieldOfView across the image width)"),
        "{err}"
    );
    let other = crate::support::sample("gas.wrl");
    let (_, err) = covered_rows(Path::new(&other), &dir, 64, 48, &[]);
    assert!(!err.contains("PyMOL"), "{err}");
}

/// `--fov-across` is refused with `--ortho` and `--vrml-default-camera`, which take no
/// fieldOfView from the file.
#[test]
fn fov_across_conflicts_with_cameras_without_a_field_of_view() {
    let dir = crate::support::scratch("cli_fov", "conflicts");
    for other in ["--ortho", "--vrml-default-camera"] {
        let out = crate::support::gtsphere(
            &[
                "render",
                &crate::support::sample("gas.wrl"),
                "-o",
                "x.png",
                "--fov-across",
                "width",
                other,
            ],
            &dir,
        );
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("cannot be used with"), "{err}");
    }
}
