use super::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs())
}

/// The lens of a Viewpoint read across each side: the image plane's half extent across
/// that side is `tan(fov / 2)`, the other one follows the aspect, and the smaller-side
/// angle is the closed form `2 atan(tan(fov / 2) * min(W, H) / S)`.
#[test]
fn fov_across_a_side_matches_the_closed_form() {
    for fov in [0.1, 0.465421, FRAC_PI_4, 1.5, 3.0] {
        let t = (0.5 * fov).tan();
        for (w, h) in [
            (640u32, 480u32),
            (480, 640),
            (500, 500),
            (1920, 1080),
            (7, 3000),
        ] {
            let (fw, fh) = (f64::from(w), f64::from(h));
            let smaller = fw.min(fh);
            for (across, side) in [
                (FovAcross::Smaller, smaller),
                (FovAcross::Width, fw),
                (FovAcross::Height, fh),
            ] {
                let got = across.smaller_side_fov(fov, w, h);
                let want = 2.0 * (t * smaller / side).atan();
                assert!(
                    close(got, want),
                    "{across:?} {fov} {w}x{h}: {got} vs {want}"
                );
                assert!(got > 0.0 && got <= fov);
                let vp = Viewpoint {
                    field_of_view: fov,
                    ..Viewpoint::default()
                };
                let plane = Camera::from_viewpoint_across(&vp, across, w, h)
                    .unwrap()
                    .image_plane(w, h);
                // Half extents: tangents of the half angles across width and height.
                let across_side = match across {
                    FovAcross::Smaller if w <= h => plane.half_w,
                    FovAcross::Smaller => plane.half_h,
                    FovAcross::Width => plane.half_w,
                    FovAcross::Height => plane.half_h,
                };
                assert!(
                    (across_side - t).abs() <= 1e-14 * t,
                    "{across:?} {fov} {w}x{h}: {across_side} vs {t}"
                );
                assert!((plane.half_w / plane.half_h - fw / fh).abs() <= 1e-13 * fw / fh);
            }
        }
    }
    // The side that is the smaller one keeps the angle bit for bit.
    assert_eq!(FovAcross::Width.smaller_side_fov(0.7, 480, 640), 0.7);
    assert_eq!(FovAcross::Height.smaller_side_fov(0.7, 640, 480), 0.7);
    assert_eq!(FovAcross::Smaller.smaller_side_fov(0.7, 640, 480), 0.7);
}

/// PyMOL shows its vertical field of view `f` (20 degrees by default) and writes
/// `a = f * W / H` (radians). Read across the width, `a` gives a vertical half tangent of
/// `tan(a / 2) * H / W`: PyMOL's `tan(f / 2)` but 0.8 % larger at 4:3 and 2.3 % at 16:9
/// (PyMOL scales the angle, not its tangent). Read across the smaller side, it draws the
/// scene `tan(f / 2) / tan(a / 2)` times as large as PyMOL: 0.744 at 4:3, 0.550 at 16:9.
#[test]
fn pymol_angle_read_across_the_width() {
    let f = 20f64.to_radians();
    for (w, h, wider, shrink) in [(640u32, 480u32, 0.0081, 0.744), (1920, 1080, 0.0229, 0.550)] {
        let a = std::f64::consts::PI * 20.0 * f64::from(w) / (180.0 * f64::from(h));
        let as_vrml = Camera::from_viewpoint_across(
            &Viewpoint {
                field_of_view: a,
                ..Viewpoint::default()
            },
            FovAcross::Smaller,
            w,
            h,
        )
        .unwrap()
        .image_plane(w, h);
        let as_pymol = Camera::from_viewpoint_across(
            &Viewpoint {
                field_of_view: a,
                ..Viewpoint::default()
            },
            FovAcross::Width,
            w,
            h,
        )
        .unwrap()
        .image_plane(w, h);
        let pymol = (0.5 * f).tan();
        let off = as_pymol.half_h / pymol - 1.0;
        assert!((off - wider).abs() < 1e-4, "{w}x{h}: {off}");
        let scale = pymol / as_vrml.half_h;
        assert!((scale - shrink).abs() < 5e-4, "{w}x{h}: {scale}");
    }
}

#[test]
fn pymol_viewpoint_is_recognised_and_nothing_else() {
    let pymol = Viewpoint {
        description: "Z view".into(),
        position: DVec3::new(0.0, 0.0, 75.52772522),
        field_of_view: 0.465421,
        ..Viewpoint::default()
    };
    assert!(pymol_export(std::slice::from_ref(&pymol)));
    assert!(!pymol_export(&[]));
    assert!(!pymol_export(&[pymol.clone(), pymol.clone()]));
    let changed = [
        Viewpoint {
            name: Some("Z".into()),
            ..pymol.clone()
        },
        Viewpoint {
            description: "Default View".into(),
            ..pymol.clone()
        },
        Viewpoint {
            position: DVec3::new(0.1, 0.0, 75.0),
            ..pymol.clone()
        },
        Viewpoint {
            position: DVec3::new(0.0, 0.0, -75.0),
            ..pymol.clone()
        },
        Viewpoint {
            orientation: DQuat::from_rotation_y(0.3),
            ..pymol.clone()
        },
    ];
    for vp in changed {
        assert!(!pymol_export(std::slice::from_ref(&vp)), "{vp:?}");
    }
}
