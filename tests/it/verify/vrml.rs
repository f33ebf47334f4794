//! The VRML97 text of a [`SceneDesc`]: numbers printed so that they read back to the same
//! f64 (Rust's shortest round-trip form), profiled gas as `GasParticle` instances (the
//! README's PROTO), and the camera as the file's first Viewpoint.

use std::fmt::Write as _;

use glam::DVec3;

use super::scenes::{Geometry, Material, Node, Profile, Rgb, SceneDesc};

/// The PROTO the README defines for profiled gas.
const GAS_PROTO: &str = "PROTO GasParticle [
  field SFVec3f position 0 0 0  field SFFloat radius 1  field SFColor color 0.8 0.8 0.8
  field SFColor emission 0 0 0  field SFFloat transparency 0.5
  field SFString profile \"constant\"  field SFFloat width 0.3333333333333333
] { Transform { translation IS position children Shape { appearance Appearance {
    material Material { diffuseColor IS color emissiveColor IS emission
    transparency IS transparency } } geometry Sphere { radius IS radius } } } }
";

/// A number that reads back to `x` exactly.
fn num(x: f64) -> String {
    if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e15) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn vec3(v: DVec3) -> String {
    format!("{} {} {}", num(v.x), num(v.y), num(v.z))
}

fn rgb(c: Rgb) -> String {
    format!("{} {} {}", num(c[0]), num(c[1]), num(c[2]))
}

fn material(m: &Material) -> String {
    format!(
        "Material {{ diffuseColor {} emissiveColor {} specularColor {} shininess {} \
         ambientIntensity {} transparency {} }}",
        rgb(m.diffuse),
        rgb(m.emissive),
        rgb(m.specular),
        num(m.shininess),
        num(m.ambient),
        num(m.transparency)
    )
}

fn geometry(g: &Geometry) -> String {
    match *g {
        Geometry::Sphere { r } => format!("Sphere {{ radius {} }}", num(r)),
        Geometry::Box { size } => format!("Box {{ size {} }}", vec3(size)),
        Geometry::Cylinder { r, h } => {
            format!("Cylinder {{ radius {} height {} }}", num(r), num(h))
        }
        Geometry::Cone { r, h } => {
            format!("Cone {{ bottomRadius {} height {} }}", num(r), num(h))
        }
        Geometry::Triangle { p } => format!(
            "IndexedFaceSet {{ solid FALSE coord Coordinate {{ point [ {}, {}, {} ] }} \
             coordIndex [ 0 1 2 -1 ] }}",
            vec3(p[0]),
            vec3(p[1]),
            vec3(p[2])
        ),
    }
}

fn node(out: &mut String, n: &Node, depth: usize) {
    let pad = "  ".repeat(depth);
    match n {
        Node::Shape {
            geometry: g,
            material: m,
        } => match (g, m) {
            (Geometry::Sphere { r }, Some(m)) if m.profile != Profile::Constant => {
                let width = match m.profile {
                    Profile::Gaussian(s) => format!(" width {}", num(s)),
                    _ => String::new(),
                };
                let _ = writeln!(
                    out,
                    "{pad}GasParticle {{ radius {} color {} emission {} transparency {} \
                     profile \"{}\"{width} }}",
                    num(*r),
                    rgb(m.diffuse),
                    rgb(m.emissive),
                    num(m.transparency),
                    m.profile.name()
                );
            }
            (g, Some(m)) => {
                let _ = writeln!(
                    out,
                    "{pad}Shape {{ appearance Appearance {{ material {} }} geometry {} }}",
                    material(m),
                    geometry(g)
                );
            }
            (g, None) => {
                let _ = writeln!(out, "{pad}Shape {{ geometry {} }}", geometry(g));
            }
        },
        Node::Point(l) => {
            let _ = writeln!(
                out,
                "{pad}PointLight {{ on {} location {} color {} intensity {} \
                 ambientIntensity {} attenuation {} radius {} }}",
                if l.on { "TRUE" } else { "FALSE" },
                vec3(l.location),
                rgb(l.color),
                num(l.intensity),
                num(l.ambient),
                vec3(l.attenuation),
                num(l.radius)
            );
        }
        Node::Directional(l) => {
            let _ = writeln!(
                out,
                "{pad}DirectionalLight {{ on {} direction {} color {} intensity {} \
                 ambientIntensity {} }}",
                if l.on { "TRUE" } else { "FALSE" },
                vec3(l.direction),
                rgb(l.color),
                num(l.intensity),
                num(l.ambient)
            );
        }
        Node::Group { xf, children } => {
            match xf {
                Some(x) => {
                    let _ = writeln!(
                        out,
                        "{pad}Transform {{ translation {} rotation {} {} scale {s} {s} {s} \
                         children [",
                        vec3(x.translation),
                        vec3(x.axis),
                        num(x.angle),
                        s = num(x.scale)
                    );
                }
                None => {
                    let _ = writeln!(out, "{pad}Group {{ children [");
                }
            }
            for c in children {
                node(out, c, depth + 1);
            }
            let _ = writeln!(out, "{pad}] }}");
        }
    }
}

/// The whole file.
pub fn write(s: &SceneDesc) -> String {
    let mut out = String::from("#VRML V2.0 utf8\n");
    let _ = writeln!(out, "# gtsphere verification matrix, seed {}", s.seed);
    out.push_str(GAS_PROTO);
    let v = &s.viewpoint;
    let _ = writeln!(
        out,
        "Viewpoint {{ position {} orientation {} {} fieldOfView {} }}",
        vec3(v.position),
        vec3(v.axis),
        num(v.angle),
        num(v.fov)
    );
    let _ = writeln!(
        out,
        "NavigationInfo {{ headlight {} }}",
        if s.headlight { "TRUE" } else { "FALSE" }
    );
    let _ = writeln!(out, "Background {{ skyColor [ {} ] }}", rgb(s.background));
    for n in &s.nodes {
        node(&mut out, n, 0);
    }
    out
}
