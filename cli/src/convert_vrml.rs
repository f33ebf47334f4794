//! `gtsphere convert scene.wrl -o out.wrl`: the scene as the renderer sees it, written back as
//! flattened VRML97 (see [`gtsphere::vrml::write_scene`]).

use std::path::Path;
use std::process::ExitCode;

use gtsphere::error::Error;
use gtsphere::vrml::write_scene_file;
use gtsphere::vrml::{load_path, LoadOptions};

pub fn run(input: &Path, output: &Path, strict: bool, quiet: bool) -> Result<ExitCode, Error> {
    let opts = LoadOptions {
        strict,
        ..LoadOptions::default()
    };
    let (scene, report) = load_path(input, &opts)?;
    if !quiet {
        for w in &report.warnings {
            eprintln!("{w}");
        }
    }
    write_scene_file(output, &scene)?;
    if !quiet {
        eprintln!(
            "wrote {} ({} spheres, {} other surfaces, {} materials, {} lights, {} viewpoints)",
            output.display(),
            scene.spheres.len(),
            scene.surfaces.len(),
            scene.materials.len(),
            scene.lights.len(),
            scene.viewpoints.len()
        );
    }
    Ok(ExitCode::SUCCESS)
}
