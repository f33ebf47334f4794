//! The scene IR back out as VRML97 (issue 6, item 2): flattened, every sphere at its world
//! position, each material an `Appearance` DEF'd at its first use and USE'd after, lights,
//! viewpoints, headlight and background. Reading the output gives the same IR (spheres,
//! materials, lights, viewpoints) up to the rounding of rotations written as axis-angle.
//!
//! - Numbers are written by [`super::number`]'s rule (the shortest digits that read back as
//!   the same f64), so every f64 reads back exactly.
//! - A DirectionalLight's scope (the spheres `scope.0 .. scope.1`) is kept by putting the light
//!   inside a `Group` around exactly those spheres; scopes come from a tree, so they nest.
//! - An ellipsoid's affine map `x -> A x + t` is written as a Transform: `A = Q P` (polar
//!   decomposition, `Q` a rotation, `P = V diag(s) V^T` symmetric positive definite) gives
//!   `rotation` from `Q`, `scale` from `s` and `scaleOrientation` from `V`, around a unit Sphere.

use std::io::{self, Write};

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::number::Float;
use crate::scene::{Light, Material, Scene, Sphere};

fn v3(v: DVec3) -> String {
    format!("{} {} {}", Float(v.x), Float(v.y), Float(v.z))
}

/// `axis angle` of a rotation, the axis normalised; the identity as `0 0 1 0`.
fn axis_angle(q: DQuat) -> String {
    let (axis, angle) = q.normalize().to_axis_angle();
    if angle == 0.0 || !axis.is_finite() || axis.length_squared() == 0.0 {
        "0 0 1 0".to_string()
    } else {
        format!("{} {}", v3(axis.normalize()), Float(angle))
    }
}

/// A VRML string literal.
fn string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        if c == '"' || c == '\\' {
            out.push('\\');
        }
        out.push(c);
    }
    out.push('"');
    out
}

/// Whether `s` can be written as a DEF name (VRML97 Id: no leading digit, sign or dot; no
/// white space, control characters, quotes, braces, brackets, '#', ',' or '\\').
fn is_id(s: &str) -> bool {
    let bad = |c: char| {
        c.is_whitespace()
            || c.is_control()
            || matches!(
                c,
                '"' | '\'' | '#' | ',' | '.' | '[' | ']' | '\\' | '{' | '}'
            )
    };
    let reserved = [
        "DEF",
        "EXTERNPROTO",
        "FALSE",
        "IS",
        "NULL",
        "PROTO",
        "ROUTE",
        "TO",
        "TRUE",
        "USE",
        "eventIn",
        "eventOut",
        "exposedField",
        "field",
    ];
    match s.chars().next() {
        None => false,
        Some(c) if c.is_ascii_digit() || c == '+' || c == '-' || bad(c) => false,
        _ => !s.chars().any(bad) && !reserved.contains(&s),
    }
}

fn material(m: &Material) -> String {
    if m.unlit {
        // An unlit colour other than white (a mesh's Color without a Material): the same
        // picture as a Material that only emits it.
        return format!(
            "Material {{ diffuseColor 0 0 0 emissiveColor {} specularColor 0 0 0 ambientIntensity 0 }}",
            v3(m.diffuse)
        );
    }
    format!(
        "Material {{ diffuseColor {} emissiveColor {} specularColor {} shininess {} ambientIntensity {} transparency {} }}",
        v3(m.diffuse),
        v3(m.emissive),
        v3(m.specular),
        Float(m.shininess),
        Float(m.ambient_intensity),
        Float(m.transparency)
    )
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: `(V, values)`
/// with `S = V diag(values) V^T`, `V` orthonormal.
fn symmetric_eigen(s: DMat3) -> (DMat3, DVec3) {
    let mut a = s.to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..64 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= f64::EPSILON * 1e-3 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let sn = t * c;
            // A <- J^T A J: columns p and q, then rows p and q.
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - sn * akq;
                row[q] = sn * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - sn * rq[k];
                a[q][k] = sn * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - sn * vq;
                row[q] = sn * vp + c * vq;
            }
        }
    }
    // `v` was updated as rows (v[row][col]); glam's arrays are columns.
    (
        DMat3::from_cols_array_2d(&v).transpose(),
        DVec3::new(a[0][0], a[1][1], a[2][2]),
    )
}

/// The Transform fields that map the unit sphere as `m` does.
fn ellipsoid_transform(m: &DAffine3) -> String {
    let mut a = m.matrix3;
    // The unit sphere is symmetric: a reflection changes nothing, so make det(A) > 0.
    if a.determinant() < 0.0 {
        a *= DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
    }
    let (v, l) = symmetric_eigen(a.transpose() * a);
    let s = l.max(DVec3::ZERO).to_array().map(f64::sqrt);
    let mut v = v;
    if v.determinant() < 0.0 {
        v *= DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
    }
    let p = v * DMat3::from_diagonal(DVec3::from(s)) * v.transpose();
    let q = a * p.inverse();
    format!(
        "translation {} rotation {} scale {} scaleOrientation {}",
        v3(m.translation),
        axis_angle(DQuat::from_mat3(&q)),
        v3(DVec3::from(s)),
        axis_angle(DQuat::from_mat3(&v))
    )
}

/// Writes `scene` as VRML97 text.
pub fn write_scene(scene: &Scene, out: &mut impl Write) -> io::Result<()> {
    writeln!(out, "#VRML V2.0 utf8")?;
    writeln!(
        out,
        "# Written by gtsphere {}: {} spheres, flattened to world coordinates.",
        env!("CARGO_PKG_VERSION"),
        scene.spheres.len()
    )?;
    writeln!(
        out,
        "NavigationInfo {{ headlight {} }}",
        if scene.headlight { "TRUE" } else { "FALSE" }
    )?;
    writeln!(out, "Background {{ skyColor {} }}", v3(scene.background))?;
    let mut names = std::collections::HashSet::new();
    for vp in &scene.viewpoints {
        let def = match &vp.name {
            Some(n) if is_id(n) && names.insert(n.clone()) => format!("DEF {n} "),
            _ => String::new(),
        };
        writeln!(
            out,
            "{def}Viewpoint {{ position {} orientation {} fieldOfView {} description {} }}",
            v3(vp.position),
            axis_angle(vp.orientation),
            Float(vp.field_of_view),
            string(&vp.description)
        )?;
    }
    // Directional lights scoped to part of the spheres open a Group around that part.
    let n = scene.spheres.len() as u32;
    let mut scoped: Vec<(u32, u32, usize)> = Vec::new();
    for (k, l) in scene.lights.iter().enumerate() {
        match l {
            Light::Point(p) => writeln!(
                out,
                "PointLight {{ location {} color {} intensity {} ambientIntensity {} attenuation {} radius {} on {} }}",
                v3(p.location),
                v3(p.color),
                Float(p.intensity),
                Float(p.ambient_intensity),
                v3(p.attenuation),
                Float(p.radius),
                if p.on { "TRUE" } else { "FALSE" }
            )?,
            Light::Directional(d) if d.scope.covers_all(n as usize) => {
                writeln!(out, "{}", directional(l))?
            }
            Light::Directional(d) => {
                let (start, end) = d.scope.range(n as usize);
                scoped.push((start, end, k))
            }
        }
    }
    // Outer scopes first: by start, then by end descending.
    scoped.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
    let mut open: Vec<u32> = Vec::new(); // ends of open Groups
    let mut next_scope = 0;
    let mut defined = vec![false; scene.materials.len()];
    for (i, s) in scene.spheres.iter().enumerate() {
        let i = i as u32;
        while open.last().is_some_and(|&end| end <= i) {
            open.pop();
            writeln!(out, "] }}")?;
        }
        while next_scope < scoped.len() && scoped[next_scope].0 <= i {
            let (start, end, k) = scoped[next_scope];
            next_scope += 1;
            if end <= start {
                // A light that lights no sphere: an empty Group keeps it.
                writeln!(
                    out,
                    "Group {{ children [ {} ] }}",
                    directional(&scene.lights[k])
                )?;
                continue;
            }
            if open.last().is_some_and(|&outer| end > outer) {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    "DirectionalLight scopes overlap without nesting",
                ));
            }
            writeln!(out, "Group {{ children [ {}", directional(&scene.lights[k]))?;
            open.push(end);
        }
        write_sphere(scene, s, &mut defined, out)?;
    }
    for _ in open {
        writeln!(out, "] }}")?;
    }
    // Lights whose scope starts after the last sphere light nothing: empty Groups.
    for &(_, _, k) in &scoped[next_scope..] {
        writeln!(
            out,
            "Group {{ children [ {} ] }}",
            directional(&scene.lights[k])
        )?;
    }
    Ok(())
}

fn directional(l: &Light) -> String {
    match l {
        Light::Directional(d) => format!(
            "DirectionalLight {{ direction {} color {} intensity {} ambientIntensity {} on {} }}",
            v3(d.direction),
            v3(d.color),
            Float(d.intensity),
            Float(d.ambient_intensity),
            if d.on { "TRUE" } else { "FALSE" }
        ),
        Light::Point(_) => String::new(),
    }
}

fn write_sphere(
    scene: &Scene,
    s: &Sphere,
    defined: &mut [bool],
    out: &mut impl Write,
) -> io::Result<()> {
    let m = &scene.materials[s.material as usize];
    let appearance = if m.unlit && m.diffuse == glam::DVec3::ONE {
        String::new()
    } else if defined[s.material as usize] {
        format!("appearance USE M{} ", s.material)
    } else {
        defined[s.material as usize] = true;
        format!(
            "appearance DEF M{} Appearance {{ material {} }} ",
            s.material,
            material(m)
        )
    };
    match s.ellipsoid {
        None => writeln!(
            out,
            "Transform {{ translation {} children Shape {{ {appearance}geometry Sphere {{ radius {} }} }} }}",
            v3(s.center),
            Float(s.radius)
        ),
        Some(e) => writeln!(
            out,
            "Transform {{ {} children Shape {{ {appearance}geometry Sphere {{ radius 1 }} }} }}",
            ellipsoid_transform(&scene.ellipsoids[e.index()])
        ),
    }
}

/// Writes `scene` to `path` (temporary file, then rename).
pub fn write_scene_file(path: &std::path::Path, scene: &Scene) -> Result<(), crate::Error> {
    crate::output::write_file_atomically(path, |w| write_scene(scene, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_against_a_known_decomposition() {
        let v = DMat3::from_quat(DQuat::from_axis_angle(
            DVec3::new(1.0, 2.0, 3.0).normalize(),
            0.7,
        ));
        let s = v * DMat3::from_diagonal(DVec3::new(0.5, 2.0, 7.0)) * v.transpose();
        let (w, l) = symmetric_eigen(s);
        let back = w * DMat3::from_diagonal(l) * w.transpose();
        for (a, b) in back.to_cols_array().iter().zip(s.to_cols_array()) {
            assert!((a - b).abs() < 1e-13);
        }
        let mut l = l.to_array();
        l.sort_by(f64::total_cmp);
        assert!(
            (l[0] - 0.5).abs() < 1e-13 && (l[1] - 2.0).abs() < 1e-13 && (l[2] - 7.0).abs() < 1e-13
        );
    }

    #[test]
    fn ids() {
        assert!(
            is_id("Top_view") && is_id("a-1") && !is_id("1a") && !is_id("a b") && !is_id("USE")
        );
    }
}
