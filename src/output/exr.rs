//! OpenEXR: linear f32 `R`, `G`, `B`, `A` and one f32 channel per layer, in one part of
//! scanlines with ZIP compression (16 lines a block; lossless, and f32 stays f32).
//!
//! EXR stores channels sorted by name, so layers read back in that order.

use std::io::{Seek, Write};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image as ExrImage, Layer as ExrLayer,
    LayerAttributes, ReadChannels, ReadLayers, Text, WritableImage,
};

use super::{Fault, Image, Layer, Placement};

pub(super) fn write(
    out: &mut (impl Write + Seek),
    img: &Image,
    at: Option<Placement>,
) -> Result<(), Fault> {
    let plane = |i: usize| FlatSamples::F32(img.rgb.iter().map(|p| p[i]).collect());
    let mut list = vec![
        AnyChannel::new("R", plane(0)),
        AnyChannel::new("G", plane(1)),
        AnyChannel::new("B", plane(2)),
        AnyChannel::new("A", FlatSamples::F32(img.alpha.clone())),
    ];
    for layer in &img.layers {
        // Channel names are null-terminated Latin-1 in the file.
        let name = Text::new_or_none(&layer.name)
            .filter(|_| !layer.name.contains('\0'))
            .ok_or_else(|| {
                Fault::Bad(format!(
                    "layer name '{}' cannot be an EXR channel name (Latin-1, no NUL)",
                    layer.name.escape_debug()
                ))
            })?;
        list.push(AnyChannel::new(name, FlatSamples::F32(layer.data.clone())));
    }
    let mut attributes = LayerAttributes::default();
    if let Some(at) = at {
        attributes.layer_position = exr::math::Vec2(at.x as i32, at.y as i32);
    }
    let layer = ExrLayer::new(
        (img.width, img.height),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list.into()),
    );
    let mut image = ExrImage::from_layer(layer);
    if let Some(at) = at {
        image.attributes.display_window =
            exr::meta::attribute::IntegerBounds::new((0, 0), (at.full_width, at.full_height));
    }
    image.write().to_buffered(out).map_err(exr_fault)
}

pub(super) fn read(path: &Path) -> Result<Image, Fault> {
    read_placed(path).map(|(img, _)| img)
}

/// The image and where it sits: its data window's position and the display window's size.
pub(super) fn read_placed(path: &Path) -> Result<(Image, Placement), Fault> {
    let file = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(exr_fault)?;
    let display = file.attributes.display_window;
    let layer = file.layer_data;
    let (width, height) = (layer.size.x(), layer.size.y());
    let pos = layer.attributes.layer_position;
    let at = if pos.x() < 0 || pos.y() < 0 || display.position.x() != 0 || display.position.y() != 0
    {
        return Err(Fault::Bad(
            "EXR data or display window starts at a negative position".into(),
        ));
    } else {
        Placement {
            x: pos.x() as usize,
            y: pos.y() as usize,
            full_width: display.size.x().max(pos.x() as usize + width),
            full_height: display.size.y().max(pos.y() as usize + height),
        }
    };
    let n = width * height;

    let mut colour: [Option<Vec<f32>>; 4] = [None, None, None, None];
    let mut layers = Vec::new();
    for channel in layer.channel_data.list {
        let name = channel.name.to_string();
        let data: Vec<f32> = channel.sample_data.values_as_f32().collect();
        if data.len() != n {
            return Err(Fault::Bad(format!(
                "EXR channel '{name}' has {} samples for {width}x{height} (subsampled channels \
                 are not supported)",
                data.len()
            )));
        }
        match ["R", "G", "B", "A"].iter().position(|c| *c == name) {
            Some(i) => colour[i] = Some(data),
            None => layers.push(Layer { name, data }),
        }
    }
    let [Some(r), Some(g), Some(b), a] = colour else {
        let mut names: Vec<&str> = ["R", "G", "B", "A"]
            .into_iter()
            .zip(&colour)
            .filter(|(_, c)| c.is_some())
            .map(|(name, _)| name)
            .collect();
        names.extend(layers.iter().map(|l| l.name.as_str()));
        return Err(Fault::Bad(format!(
            "EXR has no R, G and B channels (channels: {})",
            names.join(", ")
        )));
    };
    let rgb = r
        .into_iter()
        .zip(g)
        .zip(b)
        .map(|((r, g), b)| [r, g, b])
        .collect();
    Ok((
        Image {
            width,
            height,
            rgb,
            alpha: a.unwrap_or_else(|| vec![1.0; n]),
            layers,
        },
        at,
    ))
}

fn exr_fault(e: exr::error::Error) -> Fault {
    match e {
        exr::error::Error::Io(e) => Fault::Io(e),
        e => Fault::Bad(format!("EXR: {e}")),
    }
}
