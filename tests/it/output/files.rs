//! Writing image files: the format by extension, images read back, and failures that leave nothing or the old file.

use super::*;

#[test]
fn format_is_chosen_by_extension_ignoring_case() {
    assert_eq!(format_for(Path::new("a/b.png")).unwrap(), Format::Png);
    assert_eq!(format_for(Path::new("B.EXR")).unwrap(), Format::Exr);
    assert_eq!(format_for(Path::new("c.Pfm")).unwrap(), Format::Pfm);
    assert_eq!(format_for(Path::new("d.NPY")).unwrap(), Format::Npy);
    assert_eq!(
        error_of(format_for(Path::new("out/picture.jpg"))).to_string(),
        "out/picture.jpg: unsupported image file name (extension '.jpg'); expected .png, .exr, .pfm or .npy"
    );
    assert_eq!(
        error_of(format_for(Path::new("picture"))).to_string(),
        "picture: unsupported image file name (no extension); expected .png, .exr, .pfm or .npy"
    );
}

/// Every format through our own reader: what EXR and PFM store comes back exactly.
#[test]
fn written_images_read_back() {
    let dir = scratch("read_back");
    let rgb = vec![[0.1, -3.0, 1e30], [f32::MIN_POSITIVE, 0.0, 65504.5]];
    let mut img = image(1, 2, rgb.clone());
    img.alpha = vec![0.5, 0.0];
    img.layers = vec![Layer {
        name: "error".into(),
        data: vec![1e-7, 2.0],
    }];

    let exr = dir.join("x.exr");
    write_image(&exr, &img).unwrap();
    assert_eq!(read_image(&exr).unwrap(), img);

    let pfm = dir.join("x.pfm");
    write_image(&pfm, &img).unwrap();
    let back = read_image(&pfm).unwrap();
    assert_eq!(back.rgb, rgb);
    assert_eq!(back.alpha, [1.0, 1.0]);
    assert!(back.layers.is_empty());
}

#[test]
fn missing_directory_fails_and_leaves_nothing() {
    let dir = scratch("missing_dir");
    let path = dir.join("no/such/dir/x.png");
    let e = error_of(write_image(&path, &image(1, 1, vec![[0.5; 3]])));
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn unsupported_extension_fails_before_creating_a_file() {
    let dir = scratch("bad_extension");
    for name in ["x.jpg", "x", "x.png.bak"] {
        let e = error_of(write_image(&dir.join(name), &image(1, 1, vec![[0.5; 3]])));
        assert!(matches!(e, Error::Image { .. }), "{e:?}");
    }
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

/// Inconsistent images are errors, not panics, and are caught before any file is touched.
#[test]
fn bad_image_fails_and_keeps_the_old_file() {
    let dir = scratch("keep_old");
    let good = || image(2, 2, vec![[0.5; 3]; 4]);
    let bad: Vec<(Image, &str)> = vec![
        (
            image(2, 2, vec![[0.5; 3]; 3]),
            "rgb has 3 values, expected 4 for 2x2",
        ),
        (
            Image {
                alpha: vec![1.0; 5],
                ..good()
            },
            "alpha has 5 values, expected 4 for 2x2",
        ),
        (
            Image {
                layers: vec![Layer {
                    name: "depth".into(),
                    data: vec![0.0; 2],
                }],
                ..good()
            },
            "layer 'depth' has 2 values, expected 4 for 2x2",
        ),
        (
            Image {
                layers: vec![Layer {
                    name: "A".into(),
                    data: vec![0.0; 4],
                }],
                ..good()
            },
            "layer name 'A' is reserved for the colour and alpha",
        ),
        (
            Image {
                layers: vec![
                    Layer {
                        name: "id".into(),
                        data: vec![0.0; 4],
                    },
                    Layer {
                        name: "id".into(),
                        data: vec![0.0; 4],
                    },
                ],
                ..good()
            },
            "two layers are named 'id'",
        ),
        (image(0, 3, Vec::new()), "image is empty (0x3)"),
    ];
    for ext in ["png", "exr", "pfm"] {
        let path = dir.join(format!("old.{ext}"));
        fs::write(&path, b"old contents").unwrap();
        for (img, message) in &bad {
            let e = error_of(write_image(&path, img));
            assert_eq!(e.to_string(), format!("{}: {message}", path.display()));
            assert_eq!(fs::read(&path).unwrap(), b"old contents");
        }
        write_image(&path, &good()).unwrap();
        assert_ne!(fs::read(&path).unwrap(), b"old contents");
    }
    assert_eq!(listing(&dir), ["old.exr", "old.pfm", "old.png"]);
}

/// A failure after the temporary file is written (the rename, here onto a directory) removes
/// the temporary file.
#[test]
fn failed_rename_removes_the_temporary_file() {
    let dir = scratch("failed_rename");
    let path = dir.join("taken.pfm");
    fs::create_dir(&path).unwrap();
    let e = error_of(write_image(&path, &image(1, 1, vec![[0.5; 3]])));
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
    assert_eq!(listing(&dir), ["taken.pfm"]);
    assert!(path.is_dir());
}

/// A stale temporary file with our own name (a crashed run with the same process id) is
/// neither overwritten nor in the way.
#[test]
fn stale_temporary_file_is_left_alone() {
    let dir = scratch("stale_temp");
    let path = dir.join("x.pfm");
    let stale = dir.join(format!(".x.pfm.tmp.{}", std::process::id()));
    fs::write(&stale, b"someone else's").unwrap();
    write_image(&path, &image(1, 1, vec![[0.5; 3]])).unwrap();
    assert_eq!(fs::read(&stale).unwrap(), b"someone else's");
    assert_eq!(read_image(&path).unwrap().rgb, [[0.5; 3]]);
    let stale_name = stale.file_name().unwrap().to_string_lossy().into_owned();
    assert_eq!(listing(&dir), [stale_name, "x.pfm".to_string()]);
}

/// A float64 .npy written from an image reads back as that image; cut or foreign files are
/// errors naming the file, never a panic.
#[test]
fn npy_round_trips_and_broken_files_are_errors() {
    let dir = crate::support::scratch("output", "npy");
    let path = dir.join("a.npy");
    let img = Image {
        width: 3,
        height: 2,
        rgb: (0..6)
            .map(|k| [k as f32 * 0.25, 1.0 / (k as f32 + 1.0), -2.5])
            .collect(),
        alpha: vec![1.0; 6],
        layers: Vec::new(),
    };
    write_image(&path, &img).unwrap();
    assert_eq!(read_image(&path).unwrap(), img);
    let bytes = fs::read(&path).unwrap();
    for broken in [
        &bytes[..bytes.len() - 8],
        &bytes[..9],
        &bytes[..70],
        b"\x93NUMPY\x01\x00",
    ] {
        let cut = dir.join("cut.npy");
        fs::write(&cut, broken).unwrap();
        let e = error_of(read_image(&cut)).to_string();
        assert!(e.starts_with(&format!("{}: ", cut.display())), "{e}");
    }
}
