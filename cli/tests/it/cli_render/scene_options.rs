//! Tiles merged, gas and profiles, surfaces and points, the NPY film, threads, and the headlight's shadows.

use super::*;

/// Three row bands and two regions rendered separately and merged equal the whole render,
/// bit for bit (colour, alpha and AOVs), with stratified sampling and gas.
#[test]
fn merged_parts_equal_the_whole_render() {
    let dir = scratch("merge");
    let common = [
        "--width",
        "37",
        "--height",
        "29",
        "--spp",
        "4",
        "--seed",
        "5",
        "--aov",
        "depth,error",
        "--quiet",
    ];
    let scene = sample_gas();
    let run = |extra: &[&str]| {
        let mut args = vec!["render", scene.as_str()];
        args.extend_from_slice(&common);
        args.extend_from_slice(extra);
        let out = gtsphere(&args, &dir);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&["-o", "whole.exr"]);
    for k in 1..=3 {
        run(&["-o", &format!("band{k}.exr"), "--tile", &format!("{k}/3")]);
    }
    let merged = gtsphere(
        &[
            "merge",
            "band1.exr",
            "band2.exr",
            "band3.exr",
            "-o",
            "merged.exr",
        ],
        &dir,
    );
    assert!(
        merged.status.success(),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    let (a, b) = (
        read_image(&dir.join("whole.exr")).unwrap(),
        read_image(&dir.join("merged.exr")).unwrap(),
    );
    assert_eq!(a, b);
    // Two regions side by side, and a missing or overlapping part is refused.
    run(&["-o", "left.exr", "--region", "0,0,20,29"]);
    run(&["-o", "right.exr", "--region", "20,0,37,29"]);
    let out = gtsphere(&["merge", "left.exr", "right.exr", "-o", "lr.exr"], &dir);
    assert!(out.status.success());
    assert_eq!(read_image(&dir.join("lr.exr")).unwrap(), a);
    let out = gtsphere(&["merge", "left.exr", "-o", "x.exr"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("in no part"));
    let out = gtsphere(
        &["merge", "left.exr", "left.exr", "right.exr", "-o", "x.exr"],
        &dir,
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("already in another part"));
    assert!(!dir.join("x.exr").exists());
    // A part must be EXR.
    let out = gtsphere(
        &[
            "render",
            &sample_gas(),
            "--tile",
            "1/2",
            "-o",
            "p.png",
            "--quiet",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(1));
}

fn sample_gas() -> String {
    sample("gas.wrl")
}

/// A scene with a Box, a Cylinder, a triangle and a point cloud: `info` counts each kind and
/// says the radius given to the points; `render` draws them and says it too; `--spheres-only`
/// and `--point-radius` change what is drawn; a bad `--point-radius` is an error.
#[test]
fn surfaces_and_points_are_counted_drawn_and_optional() {
    let dir = scratch("surfaces");
    std::fs::write(
        dir.join("s.wrl"),
        "#VRML V2.0 utf8\nNavigationInfo { headlight TRUE }\nViewpoint { position 0 0 8 }\n\
         Shape { appearance Appearance { material Material { } } geometry Box { size 1 1 1 } }\n\
         Transform { translation 2 0 0 children Shape { appearance Appearance { material Material { } } geometry Cylinder { radius 0.3 } } }\n\
         Shape { geometry IndexedFaceSet { coord Coordinate { point [ -3 -1 0, -2 -1 0, -2.5 0 0 ] } coordIndex [ 0 1 2 ] } }\n\
         Shape { appearance Appearance { material Material { } } geometry PointSet { coord Coordinate { point [ 0 2 0, 0.5 2 0, 1 2 0 ] } } }\n",
    )
    .unwrap();
    let info = gtsphere(&["info", "s.wrl"], &dir);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "{text}");
    assert!(
        text.contains("surfaces:   3 (boxes 1, cylinders 1, cones 0, triangles 1)"),
        "{text}"
    );
    assert!(text.contains("from points: 3"), "{text}");
    assert!(
        text.contains("s.wrl:7:66: note: PointSet: 3 points drawn as spheres of radius 0.25"),
        "{text}"
    );
    let json = gtsphere(&["info", "s.wrl", "--json", "--spheres-only"], &dir);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).expect("json");
    assert_eq!(v["surfaces"]["boxes"], 0);
    assert_eq!(v["spheres"], 3);
    assert_eq!(v["skipped"]["Box"], 1);
    // Drawn: the Box in the middle of the default framing is lit.
    let render = gtsphere(
        &[
            "render", "s.wrl", "--width", "64", "--height", "48", "-o", "s.exr",
        ],
        &dir,
    );
    let err = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{err}");
    assert!(
        err.contains("3 other surfaces") && err.contains("note:"),
        "{err}"
    );
    let img = read_image(&dir.join("s.exr")).expect("s.exr");
    let lit = img.alpha.iter().filter(|a| **a > 0.0).count();
    let only = gtsphere(
        &[
            "render",
            "s.wrl",
            "--width",
            "64",
            "--height",
            "48",
            "--spheres-only",
            "--point-radius",
            "0.1",
            "-o",
            "o.exr",
        ],
        &dir,
    );
    assert!(only.status.success());
    let img = read_image(&dir.join("o.exr")).expect("o.exr");
    let fewer = img.alpha.iter().filter(|a| **a > 0.0).count();
    assert!(
        fewer * 4 < lit,
        "{fewer} pixels drawn with spheres only, {lit} with everything"
    );
    let bad = gtsphere(&["render", "s.wrl", "--point-radius", "-1"], &dir);
    assert_eq!(bad.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&bad.stderr).contains("--point-radius must be a positive number")
    );
}

/// `-o x.npy` writes the f64 film as a NumPy array: read here with a parser of the test's
/// own, its pixels rounded to f32 are the PFM's of the same render, and they carry more
/// digits than f32 holds.
#[test]
fn npy_output_is_the_f64_film() {
    let dir = scratch("npy");
    let scene = sample("cluster.wrl");
    let common = ["--width", "40", "--height", "30", "--sampler", "center"];
    for out in ["c.npy", "c.pfm"] {
        let mut args = vec!["render", scene.as_str(), "-o", out, "-q"];
        args.extend(common);
        let r = gtsphere(&args, &dir);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let bytes = std::fs::read(dir.join("c.npy")).unwrap();
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + len) % 64, 0);
    let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    assert!(
        header.starts_with("{'descr': '<f8', 'fortran_order': False, 'shape': (30, 40, 3), }"),
        "{header}"
    );
    let data: Vec<f64> = bytes[10 + len..]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(data.len(), 30 * 40 * 3);
    let pfm = read_image(&dir.join("c.pfm")).unwrap();
    let mut wider = 0;
    for (k, v) in data.iter().enumerate() {
        let (px, c) = (k / 3, k % 3);
        assert_eq!(*v as f32, pfm.rgb[px][c], "pixel {px} channel {c}");
        wider += usize::from(f64::from(*v as f32) != *v);
    }
    assert!(wider > 100, "only {wider} values need f64");
}

#[test]
fn threads_bound_the_reading_too() {
    // A file large enough to be read in pieces (twice the 4 MiB piece): `--threads 1` reads
    // it with one reader, `--threads 2` in pieces, and `--read-threads` overrides either.
    let dir = scratch("read_threads");
    let mut text = String::from("#VRML V2.0 utf8\n");
    let mut i = 0u64;
    while text.len() < 9 << 20 {
        let f = |k: u64| ((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0;
        text += &format!(
            "Transform {{ translation {} {} {} children Shape {{ geometry Sphere {{ radius 0.01 }} }} }}\n",
            f(1),
            f(2),
            f(3)
        );
        i += 1;
    }
    std::fs::write(dir.join("big.wrl"), &text).unwrap();
    let pieces = |extra: &[&str]| -> usize {
        let mut args = vec![
            "render", "big.wrl", "--width", "4", "--height", "4", "--stats",
        ];
        args.extend_from_slice(extra);
        let out = gtsphere(&args, &dir);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        let line = stdout
            .lines()
            .find(|l| l.starts_with("read pieces"))
            .unwrap_or_else(|| panic!("no read pieces line in\n{stdout}"));
        line.split_whitespace().last().unwrap().parse().unwrap()
    };
    assert_eq!(pieces(&["--threads", "1"]), 0);
    assert!(pieces(&["--threads", "2"]) >= 2);
    assert!(pieces(&["--threads", "1", "--read-threads", "2"]) >= 2);
    assert_eq!(pieces(&["--threads", "2", "--read-threads", "1"]), 0);
}

#[test]
fn profiles_are_named_and_profiled_gas_is_drawn() {
    let dir = scratch("profile");
    std::fs::write(
        dir.join("g.wrl"),
        "#VRML V2.0 utf8\nPROTO GasParticle [ field SFVec3f position 0 0 0 field SFFloat radius 1 field SFFloat transparency 0.5 field SFString profile \"constant\" field SFFloat width 0.3333333333333333 ] { Transform { translation IS position children Shape { appearance Appearance { material Material { transparency IS transparency } } geometry Sphere { radius IS radius } } } }\nGasParticle { profile \"gaussian\" width 0.5 }\n",
    )
    .unwrap();
    let small = ["--width", "8", "--height", "8"];
    let run = |extra: &[&str]| {
        let mut args = vec!["render", "g.wrl", "-o", "g.png"];
        args.extend_from_slice(&small);
        args.extend_from_slice(extra);
        gtsphere(&args, &dir)
    };
    for (arg, want) in [
        ("fuzzy", "--profile fuzzy: unknown density profile `fuzzy`"),
        (
            "gaussian:2",
            "--profile gaussian:2: gaussian width 2 is outside (0, 1]",
        ),
        (
            "linear:0.5",
            "--profile linear:0.5: the linear profile takes no width",
        ),
        (
            "gaussian:x",
            "--profile gaussian:x: the width `x` is not a number",
        ),
    ] {
        let out = run(&["--profile", arg]);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{arg}: {err}");
    }
    // The scene's gaussian gas is drawn as such, and --profile constant draws it constant:
    // the same transparency, so the same diameter transmittance, but another picture.
    let rendered = |extra: &[&str]| {
        let out = run(extra);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read(dir.join("g.png")).unwrap()
    };
    // info counts the profiled gas and the instances lowered by template.
    let info = gtsphere(&["info", "g.wrl", "--json"], &dir);
    let v: serde_json::Value = serde_json::from_slice(&info.stdout).expect("json");
    assert_eq!(v["profiled_gas"], 1);
    assert_eq!(v["template_instances"], 1);
    let text = String::from_utf8_lossy(&gtsphere(&["info", "g.wrl"], &dir).stdout).to_string();
    assert!(text.contains("gas with a density profile: 1"), "{text}");
    let gaussian = rendered(&[]);
    let constant = rendered(&["--profile", "constant"]);
    assert_ne!(gaussian, constant);
    assert_eq!(rendered(&["--profile", "gaussian:0.5"]), gaussian);
}

#[test]
fn headlight_shadows_flag_gives_the_strict_directional_headlight() {
    // A small sphere in front of a large one, off the view axis, the headlight alone: by
    // default nothing visible is in its shadow; with --headlight-shadows a crescent is.
    let dir = scratch("headlight");
    std::fs::write(
        dir.join("h.wrl"),
        "#VRML V2.0 utf8\nViewpoint { position 0 0 6 fieldOfView 0.8 }\n\
         Shape { appearance Appearance { material Material { } } geometry Sphere { } }\n\
         Transform { translation 0.6 0.4 2.5 children Shape { appearance Appearance { \
         material Material { } } geometry Sphere { radius 0.25 } } }\n",
    )
    .unwrap();
    let common = ["render", "h.wrl", "--width", "48", "--height", "48"];
    let run = |extra: &[&str], out: &str| {
        let args: Vec<&str> = common
            .iter()
            .chain(extra)
            .chain(&["-o", out])
            .copied()
            .collect();
        let o = gtsphere(&args, &dir);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        read_image(&dir.join(out)).expect(out)
    };
    let carried = run(&["--sampler", "center"], "carried.pfm");
    let strict = run(
        &["--sampler", "center", "--headlight-shadows"],
        "strict.pfm",
    );
    let crescent = carried
        .rgb
        .iter()
        .zip(&strict.rgb)
        .filter(|(a, b)| a[0] > 0.0 && b[0] == 0.0)
        .count();
    assert!(crescent > 0, "no pixel in the headlight's shadow");
}
