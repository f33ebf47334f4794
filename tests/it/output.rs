//! Image files: each format checked against an independent reader or hand-built bytes, and the
//! temporary-file-then-rename write that never leaves a broken file at the destination.

use std::fs;
use std::path::{Path, PathBuf};

use exr::prelude::{
    f16, read, AnyChannel, AnyChannels, Blocks, Compression, FlatSamples, ReadChannels, ReadLayers,
    Vec2, WritableImage,
};
use gtsphere::output::{format_for, read_image, write_image, Format, Image, Layer};
use gtsphere::Error;

mod files;

/// A fresh, empty directory for one test.
fn scratch(test: &str) -> PathBuf {
    crate::support::scratch("output", test)
}

/// The names in `dir`, sorted (hidden temporaries included).
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn image(width: usize, height: usize, rgb: Vec<[f32; 3]>) -> Image {
    Image {
        width,
        height,
        alpha: vec![1.0; rgb.len()],
        rgb,
        layers: Vec::new(),
    }
}

fn error_of(r: Result<impl std::fmt::Debug, Error>) -> Error {
    match r {
        Ok(v) => panic!("expected an error, got {v:?}"),
        Err(e) => e,
    }
}

// ---------------------------------------------------------------------------------------------
// PNG

/// Linear values through the sRGB curve, decoded by the `image` crate. The expected codes are
/// round(255 * f(clamp(c))) with f(c) = 12.92 c for c <= 0.0031308, else
/// 1.055 c^(1/2.4) - 0.055, evaluated by hand (in f64, Python):
///   0.001     -> 3.2946  -> 3      0.0031308 -> 10.3147 -> 10 (boundary, both branches agree)
///   0.01      -> 25.462  -> 25     0.2       -> 123.555 -> 124
///   0.5       -> 187.516 -> 188    0.75      -> 224.610 -> 225
///   1.0       -> 255;  >1, +inf -> 255;  negative, -inf, NaN -> 0.
#[test]
fn png_codes_follow_the_exact_srgb_curve() {
    let cases: [(f32, u8); 13] = [
        (0.0, 0),
        (0.001, 3),
        (0.003_130_8, 10),
        (0.01, 25),
        (0.2, 124),
        (0.5, 188),
        (0.75, 225),
        (1.0, 255),
        (1.5, 255),
        (f32::INFINITY, 255),
        (-0.5, 0),
        (f32::NEG_INFINITY, 0),
        (f32::NAN, 0),
    ];
    // Each value in one channel of its own pixel, the other channels fixed, so a channel mix-up
    // or a row flip shows too.
    let mut rgb = Vec::new();
    let mut expected = Vec::new();
    for (c, code) in cases {
        rgb.push([c, 0.0, 1.0]);
        expected.extend([code, 0, 255]);
        rgb.push([1.0, c, 0.0]);
        expected.extend([255, code, 0]);
    }
    let dir = scratch("png_codes");
    let path = dir.join("codes.png");
    write_image(&path, &image(2, cases.len(), rgb)).unwrap();

    let decoded = image::load_from_memory(&fs::read(&path).unwrap()).unwrap();
    assert_eq!(
        decoded.color(),
        image::ColorType::Rgb8,
        "8-bit RGB, no alpha"
    );
    assert_eq!((decoded.width(), decoded.height()), (2, cases.len() as u32));
    assert_eq!(decoded.as_bytes(), &expected[..]);
}

/// A PNG made by the `image` crate reads back to linear through the inverse curve:
/// v = code / 255; c = v / 12.92 for v <= 0.04045, else ((v + 0.055) / 1.055)^2.4.
#[test]
fn png_is_read_back_to_linear() {
    let dir = scratch("png_read");
    let path = dir.join("in.png");
    // 2x1, RGBA: (0, 10, 188, a=255), (255, 128, 0, a=64).
    let bytes: Vec<u8> = vec![0, 10, 188, 255, 255, 128, 0, 64];
    image::save_buffer(&path, &bytes, 2, 1, image::ExtendedColorType::Rgba8).unwrap();

    let img = read_image(&path).unwrap();
    assert_eq!((img.width, img.height), (2, 1));
    let expected = [
        [0.0, 0.003_035_269_835_488_375, 0.502_886_458_032_568_7],
        [1.0, 0.215_860_500_113_899_26, 0.0],
    ];
    for (got, want) in img.rgb.iter().zip(expected) {
        for (g, w) in got.iter().zip(want) {
            assert!(
                (f64::from(*g) - w).abs() <= 1e-6 * w.max(1e-3),
                "{got:?} vs {want:?}"
            );
        }
    }
    // PNG alpha is linear: 64 / 255.
    assert_eq!(img.alpha, [1.0, 64.0 / 255.0]);
    assert!(img.layers.is_empty());
}

// ---------------------------------------------------------------------------------------------
// PFM

/// The whole file of a 2x2 image, byte for byte: header text, then the BOTTOM row first,
/// little-endian f32.
#[test]
fn pfm_bytes_are_header_then_rows_bottom_to_top_little_endian() {
    let dir = scratch("pfm_bytes");
    let path = dir.join("tiny.pfm");
    let top = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]];
    let bottom = [[0.25, -2.5, 7.0], [8.0, 9.0, 10.0]];
    let img = image(2, 2, vec![top[0], top[1], bottom[0], bottom[1]]);
    write_image(&path, &img).unwrap();

    let bytes = fs::read(&path).unwrap();
    let header = b"PF\n2 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    assert_eq!(bytes.len(), header.len() + 2 * 2 * 3 * 4);
    let samples: Vec<f32> = bytes[header.len()..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(
        samples,
        [0.25, -2.5, 7.0, 8.0, 9.0, 10.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    );
    // Spelled out once, so the byte order does not rest on `from_le_bytes` alone:
    // 0.25 = 0x3e800000, little-endian 00 00 80 3e.
    assert_eq!(
        &bytes[header.len()..header.len() + 4],
        &[0x00, 0x00, 0x80, 0x3e]
    );
}

/// A big-endian colour PFM (positive scale), built by hand.
#[test]
fn pfm_big_endian_is_read() {
    let dir = scratch("pfm_big_endian");
    let path = dir.join("be.pfm");
    let mut bytes = b"PF\n2 2\n1.0\n".to_vec();
    // Bottom row, then top row. 0.25 = 3e800000, -2.5 = c0200000, 3.0 = 40400000.
    let be = |v: u32| v.to_be_bytes();
    for v in [
        0x3e80_0000u32,
        0xc020_0000,
        0x4040_0000, // bottom left
        0x4040_0000,
        0x3e80_0000,
        0x0000_0000, // bottom right
        0xc020_0000,
        0x0000_0000,
        0x0000_0000, // top left
        0x0000_0000,
        0x0000_0000,
        0x4040_0000, // top right
    ] {
        bytes.extend(be(v));
    }
    fs::write(&path, &bytes).unwrap();

    let img = read_image(&path).unwrap();
    assert_eq!((img.width, img.height), (2, 2));
    assert_eq!(
        img.rgb,
        [
            [-2.5, 0.0, 0.0],
            [0.0, 0.0, 3.0],
            [0.25, -2.5, 3.0],
            [3.0, 0.25, 0.0]
        ]
    );
    assert_eq!(img.alpha, [1.0; 4]);
}

/// Greyscale `Pf`, both byte orders; the header may wrap its numbers differently; a scale
/// other than 1 multiplies the samples by its magnitude.
#[test]
fn pfm_greyscale_either_endianness_and_scale() {
    let dir = scratch("pfm_grey");
    let path = dir.join("grey.pfm");

    // 1x2 little-endian, width and height on separate lines: bottom 1.0, top 3.0.
    let mut bytes = b"Pf\n1\n2\n-1\n".to_vec();
    bytes.extend([0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x40, 0x40]);
    fs::write(&path, &bytes).unwrap();
    let img = read_image(&path).unwrap();
    assert_eq!(img.rgb, [[3.0; 3], [1.0; 3]]);

    // 2x1 big-endian with scale 0.5: 3.0 and 1.0 become 1.5 and 0.5.
    let mut bytes = b"Pf 2 1 0.5\n".to_vec();
    bytes.extend([0x40, 0x40, 0x00, 0x00, 0x3f, 0x80, 0x00, 0x00]);
    fs::write(&path, &bytes).unwrap();
    let img = read_image(&path).unwrap();
    assert_eq!((img.width, img.height), (2, 1));
    assert_eq!(img.rgb, [[1.5; 3], [0.5; 3]]);
}

/// Malformed PFM files: an error naming the file and what is wrong, never a panic.
#[test]
fn pfm_bad_input_is_an_error_naming_the_file() {
    let dir = scratch("pfm_bad");
    let path = dir.join("bad.pfm");
    let data = |n: usize| vec![0u8; n];
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (Vec::new(), "does not start with 'PF' or 'Pf'"),
        (
            b"P6\n1 1\n255\n".to_vec(),
            "does not start with 'PF' or 'Pf'",
        ),
        (b"PF".to_vec(), "expected whitespace before the width"),
        (b"PF\n".to_vec(), "header ends before the width"),
        (b"PF\n2".to_vec(), "expected whitespace before the height"),
        (
            b"PF\nx 2\n-1.0\n".to_vec(),
            "width 'x' is not a positive integer",
        ),
        (
            b"PF\n0 2\n-1.0\n".to_vec(),
            "width '0' is not a positive integer",
        ),
        (
            b"PF\n2 -2\n-1.0\n".to_vec(),
            "height '-2' is not a positive integer",
        ),
        (
            b"PF\n2 2\n0.0\n".to_vec(),
            "scale '0.0' is not a finite non-zero number",
        ),
        (
            b"PF\n2 2\nnan\n".to_vec(),
            "scale 'nan' is not a finite non-zero number",
        ),
        (
            b"PF\n2 2\n-1.0".to_vec(),
            "header is not followed by a whitespace byte",
        ),
        (
            [b"PF\n2 2\n-1.0\n".to_vec(), data(47)].concat(),
            "2x2 with 3 channel(s) needs 48 bytes of samples, the file has 47",
        ),
        (
            [b"PF\n2 2\n-1.0\n".to_vec(), data(49)].concat(),
            "2x2 with 3 channel(s) needs 48 bytes of samples, the file has 49",
        ),
        (
            [b"Pf\n2 2\n-1.0\n".to_vec(), data(48)].concat(),
            "2x2 with 1 channel(s) needs 16 bytes of samples, the file has 48",
        ),
        (
            b"PF\n99999999999 99999999999\n-1.0\n".to_vec(),
            "99999999999x99999999999 is too large",
        ),
    ];
    for (bytes, message) in cases {
        fs::write(&path, &bytes).unwrap();
        let e = error_of(read_image(&path));
        assert!(matches!(e, Error::Image { .. }), "{e:?}");
        assert_eq!(e.to_string(), format!("{}: PFM: {message}", path.display()));
    }
}

// ---------------------------------------------------------------------------------------------
// EXR

/// Read back with the `exr` crate itself: one layer, sorted channel names, f32 samples with
/// row 0 at the top, alpha and every layer, ZIP compression in scanlines.
#[test]
fn exr_channels_as_the_exr_crate_reads_them() {
    let dir = scratch("exr_channels");
    let path = dir.join("aov.exr");
    let (w, h) = (3, 2);
    let rgb: Vec<[f32; 3]> = (0..w * h)
        .map(|i| [i as f32, 10.0 + i as f32, -(i as f32) - 0.5])
        .collect();
    let img = Image {
        width: w,
        height: h,
        rgb,
        alpha: vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.125],
        layers: vec![
            Layer {
                name: "depth".into(),
                data: vec![1.0, 2.0, f32::INFINITY, 4.0, 5.0, 6.0],
            },
            Layer {
                name: "normal.X".into(),
                data: vec![-1.0, 0.0, 1.0, 0.5, -0.5, 0.0],
            },
            Layer {
                name: "id".into(),
                data: vec![16_777_216.0, 0.0, 1.0, 2.0, 3.0, 4.0],
            },
        ],
    };
    write_image(&path, &img).unwrap();

    let file = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_file(&path)
        .unwrap();
    assert_eq!(file.layer_data.len(), 1, "one part");
    let layer = &file.layer_data[0];
    assert_eq!(layer.size, Vec2(3, 2));
    assert_eq!(layer.encoding.compression, Compression::ZIP16);
    assert_eq!(layer.encoding.blocks, Blocks::ScanLines);
    let channel = |name: &str| -> Vec<f32> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .unwrap_or_else(|| panic!("no channel {name}"));
        match &c.sample_data {
            FlatSamples::F32(v) => v.clone(),
            other => panic!("channel {name} is not f32: {other:?}"),
        }
    };
    let names: Vec<String> = layer
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    assert_eq!(names, ["A", "B", "G", "R", "depth", "id", "normal.X"]);
    assert_eq!(channel("R"), [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!(channel("G"), [10.0, 11.0, 12.0, 13.0, 14.0, 15.0]);
    assert_eq!(channel("B"), [-0.5, -1.5, -2.5, -3.5, -4.5, -5.5]);
    assert_eq!(channel("A"), img.alpha);
    for l in &img.layers {
        assert_eq!(channel(&l.name), l.data, "layer {}", l.name);
    }
}

/// An EXR written by the `exr` crate, half-float RGB without alpha: our reader takes the
/// colour, gives alpha 1 and keeps the other channels as layers.
#[test]
fn exr_from_elsewhere_is_read() {
    let dir = scratch("exr_read");
    let path = dir.join("half.exr");
    let half = |v: &[f32]| FlatSamples::F16(v.iter().map(|&x| f16::from_f32(x)).collect());
    let channels = AnyChannels::sort(
        vec![
            AnyChannel::new("R", half(&[0.5, 1.0])),
            AnyChannel::new("G", half(&[0.25, 2.0])),
            AnyChannel::new("B", half(&[0.125, 4.0])),
            AnyChannel::new("Z", FlatSamples::F32(vec![7.0, 8.0])),
        ]
        .into(),
    );
    exr::prelude::Image::from_channels((2, 1), channels)
        .write()
        .to_file(&path)
        .unwrap();

    let img = read_image(&path).unwrap();
    assert_eq!((img.width, img.height), (2, 1));
    assert_eq!(img.rgb, [[0.5, 0.25, 0.125], [1.0, 2.0, 4.0]]);
    assert_eq!(img.alpha, [1.0, 1.0]);
    assert_eq!(
        img.layers,
        [Layer {
            name: "Z".into(),
            data: vec![7.0, 8.0]
        }]
    );
}

/// An EXR without colour channels, and a file that is not an EXR at all.
#[test]
fn exr_bad_input_is_an_error_naming_the_file() {
    let dir = scratch("exr_bad");
    let path = dir.join("bad.exr");
    let channels =
        AnyChannels::sort(vec![AnyChannel::new("Y", FlatSamples::F32(vec![1.0]))].into());
    exr::prelude::Image::from_channels((1, 1), channels)
        .write()
        .to_file(&path)
        .unwrap();
    let e = error_of(read_image(&path)).to_string();
    assert_eq!(
        e,
        format!(
            "{}: EXR has no R, G and B channels (channels: Y)",
            path.display()
        )
    );

    // A good file cut short, and text.
    let good = dir.join("good.exr");
    write_image(&good, &image(4, 4, vec![[1.0; 3]; 16])).unwrap();
    let bytes = fs::read(&good).unwrap();
    for broken in [&bytes[..bytes.len() / 2], &bytes[..10], b"not an exr"] {
        fs::write(&path, broken).unwrap();
        let e = error_of(read_image(&path)).to_string();
        assert!(e.starts_with(&format!("{}: ", path.display())), "{e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Formats by name, and the temporary file
