//! The scene IR back out as VRML97: flattened, every sphere at its world
//! position, each material an `Appearance` DEF'd at its first use and USE'd after (while the
//! writer remembers it), lights, viewpoints, headlight and background. Reading the output gives the same IR (spheres,
//! materials, lights, viewpoints) up to the rounding of rotations written as axis-angle.
//!
//! - Numbers are written by [`super::number`]'s rule (the shortest digits that read back as
//!   the same f64), so every f64 reads back exactly.
//! - A DirectionalLight's scope (the spheres `scope.0 .. scope.1`) is kept by putting the light
//!   inside a `Group` around exactly those spheres; scopes come from a tree, so they nest.
//! - An ellipsoid's affine map `x -> A x + t` is written as a Transform: `A = Q P` (polar
//!   decomposition, `Q` a rotation, `P = V diag(s) V^T` symmetric positive definite) gives
//!   `rotation` from `Q`, `scale` from `s` and `scaleOrientation` from `V`, around a unit Sphere.
//!   A Box, Cylinder or Cone is written the same way; a triangle as a one-face
//!   IndexedFaceSet (with its corner normals and colours, so it reads back as the same
//!   triangle: a lone triangle is never a sphere).
//! - A sphere whose material has a density profile other than constant is a `GasParticle`
//!   instance (the PROTO the reader recognises, declared once at the top when needed), with
//!   every Material field, so it reads back with the same material and profile.

use std::io::{self, Write};

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::number::Float;
use crate::geom::shapes::Solid;
use crate::scene::{Light, Material, Paint, Profile, Scene, Sphere, Surface, SurfaceShape};

/// The `GasParticle` PROTO the writer declares: every Material field, and the profile (the
/// reader recognises it by its name and its `profile` and `width` fields).
const GAS_PARTICLE: &str = "PROTO GasParticle [
  field SFVec3f position 0 0 0
  field SFFloat radius 1
  field SFColor color 0.8 0.8 0.8
  field SFColor emission 0 0 0
  field SFColor specular 0 0 0
  field SFFloat shininess 0.2
  field SFFloat ambientIntensity 0.2
  field SFFloat transparency 0.5
  field SFString profile \"constant\"
  field SFFloat width 0.3333333333333333
] {
  Transform {
    translation IS position
    children Shape {
      appearance Appearance {
        material Material { diffuseColor IS color emissiveColor IS emission specularColor IS specular shininess IS shininess ambientIntensity IS ambientIntensity transparency IS transparency }
      }
      geometry Sphere { radius IS radius }
    }
  }
}";

/// A sphere of material `m` is written as a `GasParticle` (its profile is not constant).
fn profiled(m: &Material) -> bool {
    !m.unlit && m.profile != Profile::Constant
}

/// A `GasParticle` instance of material `m` at `position` with `radius`.
fn gas_particle(m: &Material, position: DVec3, radius: f64) -> String {
    let width = match m.profile {
        Profile::Gaussian { width } => format!(" width {}", Float(width)),
        _ => String::new(),
    };
    format!(
        "GasParticle {{ position {} radius {} color {} emission {} specular {} shininess {} ambientIntensity {} transparency {} profile \"{}\"{width} }}",
        v3(position),
        Float(radius),
        v3(m.diffuse),
        v3(m.emissive),
        v3(m.specular),
        Float(m.shininess),
        Float(m.ambient_intensity),
        Float(m.transparency),
        m.profile.name()
    )
}

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
        "# Written by gtsphere {}: {} spheres and {} other surfaces, flattened to world coordinates.",
        env!("CARGO_PKG_VERSION"),
        scene.spheres.len(),
        scene.surfaces.len()
    )?;
    writeln!(
        out,
        "NavigationInfo {{ headlight {} }}",
        if scene.headlight { "TRUE" } else { "FALSE" }
    )?;
    writeln!(out, "Background {{ skyColor {} }}", v3(scene.background))?;
    if scene
        .spheres
        .iter()
        .any(|s| profiled(scene.materials.record(s.material)))
    {
        writeln!(out, "{GAS_PARTICLE}")?;
    }
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
    // A DirectionalLight scoped to part of the scene opens a Group around that part: one
    // around its spheres, one around its surfaces (the IR keeps the two ranges apart, so such
    // a light is written once for each; it lights the same things when read back).
    let (n, ns) = (scene.spheres.len(), scene.surfaces.len());
    let mut scoped: Vec<(u32, u32, usize)> = Vec::new();
    let mut scoped_surfaces: Vec<(u32, u32, usize)> = Vec::new();
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
            Light::Directional(d)
                if d.scope.covers_all(n) && d.surface_scope.covers_all(ns) =>
            {
                writeln!(out, "{}", directional(l))?
            }
            Light::Directional(d) => {
                let (start, end) = d.scope.range(n);
                let (s0, s1) = d.surface_scope.range(ns);
                // (A light that lights nothing is kept, in an empty Group, by the first list.)
                if start < end || s0 >= s1 {
                    scoped.push((start, end, k));
                }
                if s0 < s1 {
                    scoped_surfaces.push((s0, s1, k));
                }
            }
        }
    }
    let mut defined = Defined::default();
    write_scoped(scene, n, scoped, out, |i, out| {
        write_sphere(scene, &scene.spheres[i], &mut defined, out)
    })?;
    let mut defined_surfaces = Defined::default();
    write_scoped(scene, ns, scoped_surfaces, out, |i, out| {
        write_surface(scene, &scene.surfaces[i], &mut defined_surfaces, out)
    })
}

/// Writes items `0..n` by `item`, each range `start..end` of `scoped` inside a Group that
/// holds the DirectionalLight `k` (ranges nest, as the grouping nodes they came from did).
fn write_scoped<W: Write>(
    scene: &Scene,
    n: usize,
    mut scoped: Vec<(u32, u32, usize)>,
    out: &mut W,
    mut item: impl FnMut(usize, &mut W) -> io::Result<()>,
) -> io::Result<()> {
    // Outer scopes first: by start, then by end descending.
    scoped.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
    let mut open: Vec<u32> = Vec::new(); // ends of open Groups
    let mut next_scope = 0;
    for i in 0..n {
        let i32_ = i as u32;
        while open.last().is_some_and(|&end| end <= i32_) {
            open.pop();
            writeln!(out, "] }}")?;
        }
        while next_scope < scoped.len() && scoped[next_scope].0 <= i32_ {
            let (start, end, k) = scoped[next_scope];
            next_scope += 1;
            if end <= start {
                // A light that lights nothing here: an empty Group keeps it.
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
        item(i, out)?;
    }
    for _ in open {
        writeln!(out, "] }}")?;
    }
    // Lights whose scope starts after the last item light nothing: empty Groups.
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

/// The Appearances written lately, by their DEF numbers: a direct-mapped table of
/// [`Defined::SLOTS`] entries, so that a scene of few materials shares one Appearance per
/// material while one of a colour per sphere (nothing to share) costs no memory per sphere.
/// A material whose entry was taken by another is DEF'd again under a new name.
struct Defined {
    slots: Vec<Option<(Paint, usize)>>,
    next: usize,
}

impl Default for Defined {
    fn default() -> Self {
        Defined {
            slots: vec![None; Self::SLOTS],
            next: 0,
        }
    }
}

impl Defined {
    const SLOTS: usize = 4096;

    /// The DEF number of `paint` and whether it is new.
    fn number(&mut self, paint: Paint) -> (usize, bool) {
        use std::hash::{BuildHasher, BuildHasherDefault};
        let hash = BuildHasherDefault::<std::collections::hash_map::DefaultHasher>::default()
            .hash_one(paint);
        let slot = &mut self.slots[hash as usize % Self::SLOTS];
        match *slot {
            Some((p, i)) if p == paint => (i, false),
            _ => {
                let i = self.next;
                self.next += 1;
                *slot = Some((paint, i));
                (i, true)
            }
        }
    }
}

/// The `appearance` field of a Shape of material `paint`: DEF'd at its first use, USE'd after
/// (`prefix` keeps the DEF names of the sphere and surface passes apart); none for unlit white.
fn appearance(scene: &Scene, paint: Paint, prefix: &str, defined: &mut Defined) -> String {
    let m = &scene.materials.get(paint.material, paint.color);
    if m.unlit && m.diffuse == DVec3::ONE {
        return String::new();
    }
    match defined.number(paint) {
        (i, false) => format!("appearance USE {prefix}{i} "),
        (i, true) => format!(
            "appearance DEF {prefix}{i} Appearance {{ material {} }} ",
            material(m)
        ),
    }
}

fn write_sphere(
    scene: &Scene,
    s: &Sphere,
    defined: &mut Defined,
    out: &mut impl Write,
) -> io::Result<()> {
    let m = scene.material_of(s);
    if profiled(&m) {
        return match s.ellipsoid {
            None => writeln!(out, "{}", gas_particle(&m, s.center, s.radius)),
            Some(e) => writeln!(
                out,
                "Transform {{ {} children {} }}",
                ellipsoid_transform(&scene.ellipsoids[e.index()]),
                gas_particle(&m, DVec3::ZERO, 1.0)
            ),
        };
    }
    let appearance = appearance(scene, s.paint(), "M", defined);
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

/// A surface: a Box, Cylinder or Cone under the Transform of its map (a mirroring map is
/// written as the mirror image about the object's x = 0 plane, which all three are symmetric
/// about), or a triangle as a one-face IndexedFaceSet with its normals and colours.
fn write_surface(
    scene: &Scene,
    s: &Surface,
    defined: &mut Defined,
    out: &mut impl Write,
) -> io::Result<()> {
    let appearance = appearance(scene, s.paint(), "S", defined);
    let on = |b: bool| if b { "TRUE" } else { "FALSE" };
    match &s.shape {
        SurfaceShape::Solid { solid, to_world } => {
            let geometry = match *solid {
                Solid::Cuboid { half } => format!("Box {{ size {} }}", v3(2.0 * half)),
                Solid::Cylinder {
                    radius,
                    half_height,
                    bottom,
                    side,
                    top,
                } => format!(
                    "Cylinder {{ radius {} height {} bottom {} side {} top {} }}",
                    Float(radius),
                    Float(2.0 * half_height),
                    on(bottom),
                    on(side),
                    on(top)
                ),
                Solid::Cone {
                    radius,
                    half_height,
                    side,
                    bottom,
                } => format!(
                    "Cone {{ bottomRadius {} height {} side {} bottom {} }}",
                    Float(radius),
                    Float(2.0 * half_height),
                    on(side),
                    on(bottom)
                ),
            };
            writeln!(
                out,
                "Transform {{ {} children Shape {{ {appearance}geometry {geometry} }} }}",
                ellipsoid_transform(to_world)
            )
        }
        SurfaceShape::Triangle(t) => {
            let list = |v: &[DVec3; 3]| v.iter().map(|p| v3(*p)).collect::<Vec<_>>().join(", ");
            let normal =
                t.n.map(|n| format!(" normal Normal {{ vector [ {} ] }}", list(&n)))
                    .unwrap_or_default();
            let color = t
                .color
                .map(|c| format!(" color Color {{ color [ {} ] }}", list(&c)))
                .unwrap_or_default();
            writeln!(
                out,
                "Shape {{ {appearance}geometry IndexedFaceSet {{ solid {} coord Coordinate {{ point [ {} ] }} coordIndex [ 0 1 2 -1 ]{normal}{color} }} }}",
                on(t.solid),
                list(&t.p)
            )
        }
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
