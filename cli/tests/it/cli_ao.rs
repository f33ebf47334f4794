//! `render --integrator ao` and `occlusion`: what they write, and the scenes and options they
//! refuse.

use crate::support::{gtsphere, sample, scratch};

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The float64 values of an `.npy` file (the header skipped).
fn npy_values(path: &std::path::Path) -> Vec<f64> {
    let bytes = std::fs::read(path).unwrap();
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + header..]
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

#[test]
fn ao_pictures_hold_fractions_and_ao_refuses_what_it_cannot_do_exactly() {
    let dir = scratch("cli_ao", "render");
    let scene = sample("cluster.wrl");
    let out = gtsphere(
        &[
            "render",
            &scene,
            "--integrator",
            "ao",
            "--ao-reach",
            "2",
            "--width",
            "48",
            "--height",
            "36",
            "--spp",
            "1",
            "-o",
            "ao.npy",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("ambient occlusion, exact, cosine weighting, reach 2"));
    let v = npy_values(&dir.join("ao.npy"));
    assert_eq!(v.len(), 48 * 36 * 3);
    // The scene's Background, or grey (the three channels equal) within [0, 1]; occluded
    // somewhere.
    for p in v.chunks(3) {
        let grey = p[0] == p[1] && p[1] == p[2] && (0.0..=1.0).contains(&p[0]);
        assert!(grey || p == [0.05, 0.05, 0.08], "{p:?}");
    }
    assert!(v.iter().any(|&x| x > 0.0 && x < 0.9));
    // Gas occludes by its transmittance, to --tol: an opaque sphere half inside a gas ball
    // is dimmed where it faces the gas.
    std::fs::write(
        dir.join("in_gas.wrl"),
        "#VRML V2.0 utf8\nViewpoint { position 0 0 5 }\nShape { geometry Sphere { } }\n\
         Transform { translation 1 0.5 0.8 children Shape { appearance Appearance { \
         material Material { transparency 0.3 } } geometry Sphere { } } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render",
            "in_gas.wrl",
            "--integrator",
            "ao",
            "--width",
            "12",
            "--height",
            "9",
            "--spp",
            "1",
            "--tol",
            "1e-2",
            "-o",
            "gas.npy",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v = npy_values(&dir.join("gas.npy"));
    let grey: Vec<f64> = v
        .chunks_exact(3)
        .filter(|p| p[0] == p[1] && p[1] == p[2] && p[0] > 0.0)
        .map(|p| p[0])
        .collect();
    assert!(
        grey.len() > 10 && grey.iter().all(|&x| x <= 1.0) && grey.iter().any(|&x| x < 0.9),
        "{grey:?}"
    );
    // Gas beside a Cylinder is refused, with both counts; nothing written.
    std::fs::write(
        dir.join("gas_cylinder.wrl"),
        "#VRML V2.0 utf8\nShape { appearance Appearance { material Material { transparency 0.5 } } \
         geometry Sphere { } }\nTransform { translation 3 0 0 children Shape { geometry Cylinder { } } }\n",
    )
    .unwrap();
    let out = gtsphere(
        &[
            "render",
            "gas_cylinder.wrl",
            "--integrator",
            "ao",
            "-o",
            "refused.png",
        ],
        &dir,
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out)
            .contains("this scene has 1 gas spheres, 1 closed cylinders or cones beside the gas"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("refused.png").exists());
    for bad in [
        vec!["--ao-reach", "2"],
        vec!["--integrator", "ao", "--ao-reach", "-1"],
        vec!["--integrator", "ao", "--ao-reach", "nan"],
    ] {
        let mut args = vec!["render", &scene, "-o", "bad.png"];
        args.extend(bad.iter().copied());
        let out = gtsphere(&args, &dir);
        assert!(!out.status.success(), "{bad:?}");
        assert!(
            stderr(&out).contains("--ao-reach"),
            "{bad:?}: {}",
            stderr(&out)
        );
        assert!(!dir.join("bad.png").exists());
    }
}

/// A floor Box, a sphere above it and a leaning triangle; with `extra` added to the scene.
fn floor_scene(extra: &str) -> String {
    format!(
        "#VRML V2.0 utf8\n\
         Viewpoint {{ position 0 6 6 orientation 1 0 0 -0.785 }}\n\
         Transform {{ translation 0 -0.1 0 children Shape {{ geometry Box {{ size 8 0.2 8 }} }} }}\n\
         Transform {{ translation 0 1.2 0 children Shape {{ geometry Sphere {{ radius 1 }} }} }}\n\
         Shape {{ geometry IndexedFaceSet {{ solid FALSE \
           coord Coordinate {{ point [ 1.5 0 -1, 3 0 -1, 2 2 -2 ] }} coordIndex [ 0 1 2 -1 ] }} }}\n\
         {extra}\n"
    )
}

#[test]
fn ao_takes_triangles_boxes_and_closed_round_solids_and_counts_the_open_ones_it_refuses() {
    let dir = scratch("cli_ao", "surfaces");
    std::fs::write(dir.join("floor.wrl"), floor_scene("")).unwrap();
    let args = |file: &'static str, extra: &[&'static str]| -> Vec<&'static str> {
        let mut a = vec![
            "render",
            file,
            "--integrator",
            "ao",
            "--width",
            "40",
            "--height",
            "30",
            "--spp",
            "1",
            "--sampler",
            "center",
        ];
        a.extend_from_slice(extra);
        a
    };
    let out = gtsphere(&args("floor.wrl", &["-o", "ao.npy"]), &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    // The floor's grey darkens under the sphere and by the triangle; the open floor is white.
    let v = npy_values(&dir.join("ao.npy"));
    assert!(v.iter().all(|&x| (0.0..=1.0).contains(&x) || x == 0.0));
    assert!(v.iter().any(|&x| x > 0.0 && x < 0.8), "some occluded pixel");
    assert!(v.contains(&1.0), "some open floor");
    // The approximations know spheres only.
    let out = gtsphere(
        &args("floor.wrl", &["--ao-method", "mc", "-o", "mc.npy"]),
        &dir,
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("knows spheres only") && stderr(&out).contains("2 surfaces"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("mc.npy").exists());
    // Closed cylinders and cones occlude, to the tolerance, with the bound of the error in
    // the error channel; open ones are refused, counted.
    std::fs::write(
        dir.join("round.wrl"),
        floor_scene(
            "Transform { translation -2 0.5 1 children Shape { geometry Cylinder { } } } \
             Transform { translation 2 0.5 1 children Shape { geometry Cone { } } }",
        ),
    )
    .unwrap();
    let out = gtsphere(
        &args(
            "round.wrl",
            &["--tol", "1e-3", "--aov", "error", "-o", "round.exr"],
        ),
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::write(
        dir.join("more.wrl"),
        floor_scene(
            "Shape { geometry Cylinder { top FALSE } } Shape { geometry Cylinder { } } \
             Shape { geometry Cone { bottom FALSE } }",
        ),
    )
    .unwrap();
    let out = gtsphere(&args("more.wrl", &["-o", "more.npy"]), &dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("2 open cylinders or cones"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("more.npy").exists());
}

#[test]
fn the_ao_channel_goes_beside_a_lit_picture_and_takes_only_reach_and_weighting() {
    let dir = scratch("cli_ao", "channel");
    let scene = sample("cluster.wrl");
    let lit = [
        "render",
        &scene,
        "--aov",
        "ao",
        "--ao-reach",
        "2",
        "--ao-weighting",
        "uniform",
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "1",
    ];
    let out = gtsphere(&[&lit[..], &["-o", "lit.exr"]].concat(), &dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.join("lit.exr").exists());
    // An approximation's options belong to --integrator ao alone.
    let out = gtsphere(
        &[&lit[..], &["--ao-method", "mc", "-o", "mc.exr"]].concat(),
        &dir,
    );
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--ao-method is only for --integrator ao"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("mc.exr").exists());
}

#[test]
fn occlusion_writes_one_row_per_sphere_within_its_tolerance() {
    let dir = scratch("cli_ao", "occlusion");
    let scene = sample("cluster.wrl");
    let out = gtsphere(
        &[
            "occlusion",
            &scene,
            "-o",
            "ao.csv",
            "--ao-reach",
            "2",
            "--tol",
            "1e-3",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.join("ao.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("index,x,y,z,radius,ao,error"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 10);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 7);
        assert_eq!(r[0], k as f64);
        assert!((0.0..=1.0).contains(&r[5]) && r[6] <= 1e-3, "{r:?}");
    }
    // The same as .npy: N x 7.
    let out = gtsphere(
        &["occlusion", &scene, "-o", "ao.npy", "--ao-reach", "2", "-q"],
        &dir,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v = npy_values(&dir.join("ao.npy"));
    assert_eq!(v.len(), rows.len() * 7);
    assert_eq!(v[5], rows[0][5]);
    // A table it cannot write is refused before the work.
    let out = gtsphere(&["occlusion", &scene, "-o", "ao.txt"], &dir);
    assert!(!out.status.success());
    assert!(stderr(&out).contains(".csv or .npy"), "{}", stderr(&out));
    assert!(!dir.join("ao.txt").exists());
}
