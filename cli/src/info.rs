//! `gtsphere info SCENE [--json]`.

use std::path::Path;
use std::process::ExitCode;

use serde_json::json;

use gtsphere::error::Error;
use gtsphere::render::pymol_export;
use gtsphere::scene::{Light, Scene};
use gtsphere::vrml::{load_path, LoadOptions, LoadReport};

use crate::render::PYMOL_FOV_NOTE;

pub fn run(
    path: &Path,
    as_json: bool,
    strict: bool,
    no_inline: bool,
    geometry: &crate::load_args::GeometryArgs,
) -> Result<ExitCode, Error> {
    let (opts, warning) = geometry.apply(LoadOptions {
        strict,
        inline: !no_inline,
        ..LoadOptions::default()
    })?;
    if let Some(w) = warning {
        eprintln!("{w}");
    }
    let (scene, report) = load_path(path, &opts)?;
    if as_json {
        println!(
            "{}",
            serde_json::to_string_pretty(&to_json(path, &scene, &report)).unwrap_or_default()
        );
    } else {
        print!("{}", to_text(path, &scene, &report));
    }
    Ok(ExitCode::SUCCESS)
}

fn mb_per_s(r: &LoadReport) -> f64 {
    if r.seconds > 0.0 {
        r.bytes as f64 / 1e6 / r.seconds
    } else {
        0.0
    }
}

/// The report as JSON (keys documented in docs/workflows.md).
pub fn to_json(path: &Path, s: &Scene, r: &LoadReport) -> serde_json::Value {
    let gas = s.gas_count();
    let viewpoints: Vec<_> = s
        .viewpoints
        .iter()
        .map(|v| {
            json!({
                "name": v.name,
                "description": v.description,
                "position": v.position.to_array(),
                "orientation_quat_xyzw": v.orientation.to_array(),
                "field_of_view": v.field_of_view,
            })
        })
        .collect();
    json!({
        "file": path.display().to_string(),
        "spheres": s.spheres.len(),
        "opaque": s.spheres.len() - gas,
        "gas": gas,
        "profiled_gas": s.profiled_gas_count(),
        "ellipsoids": s.ellipsoid_count(),
        "surfaces": s.surface_counts(),
        "materials": s.materials.len(),
        "lights": {
            "point": s.point_light_count(),
            "directional": s.directional_light_count(),
            "headlight": s.headlight,
        },
        "viewpoints": viewpoints,
        "default_camera": s.viewpoints.is_empty(),
        "background": s.background.to_array(),
        "mesh_spheres": r.mesh_spheres,
        "point_spheres": r.point_spheres,
        "notes": r
            .notes
            .iter()
            .map(|w| w.headline())
            .chain(
                pymol_export(&s.viewpoints)
                    .then(|| format!("{}: note: {PYMOL_FOV_NOTE}", path.display())),
            )
            .collect::<Vec<_>>(),
        "skipped": r.skipped,
        "warnings": r.warnings.iter().map(|w| w.headline()).collect::<Vec<_>>(),
        "bounds": s.bounds(),
        "ir_bytes": s.heap_bytes(),
        "recorded_bytes": r.recorded_bytes,
        "bytes_read": r.bytes,
        "parse_seconds": r.seconds,
        "mb_per_s": mb_per_s(r),
        "nodes": r.nodes,
        "read_pieces": r.read_pieces,
        "template_instances": r.template_instances,
        "whole_sphere_nodes": r.whole_sphere_nodes,
        "read_again": r.read_again,
        "read_on": r.read_on,
        "files": r.files,
        "peak_rss_bytes": crate::memory::peak_rss_bytes(),
    })
}

fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.2} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.2} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.1} kB", b / 1e3)
    } else {
        format!("{bytes} B")
    }
}

pub fn to_text(path: &Path, s: &Scene, r: &LoadReport) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let gas = s.gas_count();
    let _ = writeln!(o, "scene:      {}", path.display());
    if r.files.len() > 1 {
        let _ = writeln!(o, "also read:  {}", r.files[1..].join(", "));
    }
    let _ = writeln!(
        o,
        "read:       {} in {:.3} s ({:.1} MB/s), {} nodes",
        human(r.bytes),
        r.seconds,
        mb_per_s(r),
        r.nodes
    );
    if r.read_pieces > 0 {
        let _ = writeln!(o, "            in {} pieces at once", r.read_pieces);
    }
    if let Some(why) = &r.read_on {
        let _ = writeln!(o, "            then by one reader {why}");
    }
    if let Some(why) = &r.read_again {
        let _ = writeln!(o, "            by one reader ({why})");
    }
    let _ = writeln!(
        o,
        "spheres:    {} (opaque {}, gas {}, ellipsoids {})",
        s.spheres.len(),
        s.spheres.len() - gas,
        gas,
        s.ellipsoid_count()
    );
    let profiled = s.profiled_gas_count();
    if profiled > 0 {
        let _ = writeln!(o, "            gas with a density profile: {profiled}");
    }
    if r.mesh_spheres > 0 {
        let _ = writeln!(
            o,
            "            from IndexedFaceSets (tessellated spheres): {}",
            r.mesh_spheres
        );
    }
    if r.point_spheres > 0 {
        let _ = writeln!(o, "            from points: {}", r.point_spheres);
    }
    let c = s.surface_counts();
    let _ = writeln!(
        o,
        "surfaces:   {} (boxes {}, cylinders {}, cones {}, triangles {})",
        s.surfaces.len(),
        c.boxes,
        c.cylinders,
        c.cones,
        c.triangles
    );
    let _ = writeln!(
        o,
        "materials:  {} distinct apart from their colours",
        s.materials.len()
    );
    let _ = writeln!(
        o,
        "lights:     {} point, {} directional; headlight {}",
        s.point_light_count(),
        s.directional_light_count(),
        if s.headlight { "on" } else { "off" }
    );
    for l in &s.lights {
        match l {
            Light::Point(p) => {
                let _ = writeln!(
                    o,
                    "            PointLight at ({:.4}, {:.4}, {:.4}) intensity {} radius {}{}",
                    p.location.x,
                    p.location.y,
                    p.location.z,
                    p.intensity,
                    p.radius,
                    if p.on { "" } else { " (off)" }
                );
            }
            Light::Directional(d) => {
                let (start, end) = d.scope.range(s.spheres.len());
                let _ = writeln!(
                    o,
                    "            DirectionalLight towards ({:.4}, {:.4}, {:.4}) intensity {} lights spheres {}..{}{}",
                    d.direction.x, d.direction.y, d.direction.z, d.intensity, start, end,
                    if d.on { "" } else { " (off)" }
                );
            }
        }
    }
    if s.viewpoints.is_empty() {
        let _ = writeln!(
            o,
            "viewpoints: none (the renderer frames the scene bounds, looking down -z)"
        );
    } else {
        let _ = writeln!(o, "viewpoints: {}", s.viewpoints.len());
        for v in &s.viewpoints {
            let _ = writeln!(
                o,
                "            {} {:?} at ({:.4}, {:.4}, {:.4}) fieldOfView {:.4}",
                v.name.as_deref().unwrap_or("(no DEF name)"),
                v.description,
                v.position.x,
                v.position.y,
                v.position.z,
                v.field_of_view
            );
        }
        if pymol_export(&s.viewpoints) {
            let _ = writeln!(o, "            note: {PYMOL_FOV_NOTE}");
        }
    }
    match s.bounds() {
        Some(b) => {
            let _ = writeln!(
                o,
                "bounds:     ({:.4}, {:.4}, {:.4}) .. ({:.4}, {:.4}, {:.4})",
                b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]
            );
        }
        None => {
            let _ = writeln!(o, "bounds:     empty (nothing drawn)");
        }
    }
    if r.skipped.is_empty() {
        let _ = writeln!(o, "skipped:    none");
    } else {
        let list: Vec<String> = r.skipped.iter().map(|(k, v)| format!("{k} {v}")).collect();
        let _ = writeln!(o, "skipped:    {} (not rendered)", list.join(", "));
    }
    let _ = writeln!(
        o,
        "memory:     IR {}, recorded DEF/PROTO events {}{}",
        human(s.heap_bytes() as u64),
        human(r.recorded_bytes as u64),
        crate::memory::peak_rss_bytes()
            .map(|p| format!(", peak resident {}", human(p)))
            .unwrap_or_default()
    );
    for n in &r.notes {
        let _ = writeln!(o, "{}", n.headline());
    }
    let _ = writeln!(o, "warnings:   {}", r.warnings.len());
    for w in &r.warnings {
        let _ = writeln!(o, "{w}");
    }
    o
}
