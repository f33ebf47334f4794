//! The seeded scene generator: 2 to 40 primitives of every kind (opaque spheres, constant and
//! profiled gas that overlaps, nests, touches or coincides, boxes, cylinders, cones,
//! triangles) under Transforms and Groups, PointLights whose radius and attenuation corner
//! fall inside gas and that sit at gas centres or on sphere surfaces, scoped
//! DirectionalLights, the headlight on or off, and a perspective or orthographic camera,
//! sometimes inside gas. The same seed gives the same scene.

use glam::{DMat3, DQuat, DVec3};

use super::scenes::{
    DirectionalLight, Geometry, Material, Node, PointLight, Profile, Rgb, SceneDesc, Viewpoint, Xf,
};
use crate::support::Rng;

fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn color(rng: &mut Rng) -> Rgb {
    [rng.f(), rng.f(), rng.f()]
}

fn point(rng: &mut Rng, half: f64) -> DVec3 {
    DVec3::new(
        rng.range(-half, half),
        rng.range(-half, half),
        rng.range(-half, half),
    )
}

fn chance(rng: &mut Rng, p: f64) -> bool {
    rng.f() < p
}

/// A translation-only Transform around `n`.
pub fn at(c: DVec3, n: Node) -> Node {
    Node::Group {
        xf: Some(Xf {
            translation: c,
            axis: DVec3::Y,
            angle: 0.0,
            scale: 1.0,
        }),
        children: vec![n],
    }
}

fn random_xf(rng: &mut Rng) -> Xf {
    Xf {
        translation: point(rng, 0.5),
        axis: unit(rng),
        angle: rng.range(-3.0, 3.0),
        scale: rng.log10(-0.2, 0.2),
    }
}

fn material(rng: &mut Rng, transparency: f64, profile: Profile) -> Material {
    let gas = transparency > 0.0;
    Material {
        diffuse: color(rng),
        emissive: if chance(rng, if gas { 0.7 } else { 0.25 }) {
            color(rng).map(|c| c * 0.6)
        } else {
            [0.0; 3]
        },
        specular: if chance(rng, 0.5) {
            color(rng)
        } else {
            [0.0; 3]
        },
        shininess: rng.range(0.01, 1.0),
        ambient: if chance(rng, 0.6) { rng.f() } else { 0.2 },
        transparency,
        profile,
    }
}

/// A gas sphere's transparency: optical depth along a diameter from 1e-6 to 7e2 (or 0:
/// transparency 1).
fn transparency(rng: &mut Rng) -> f64 {
    if chance(rng, 0.03) {
        1.0
    } else {
        (-rng.log10(-6.0, 2.85)).exp()
    }
}

fn profile(rng: &mut Rng) -> Profile {
    match rng.below(3) {
        0 => Profile::Linear,
        1 => Profile::Quadratic,
        _ => Profile::Gaussian(rng.range(0.15, 1.0)),
    }
}

/// The spheres placed so far at top level: centre and radius (for gas relations and lights).
struct Placed {
    c: DVec3,
    r: f64,
    gas: bool,
}

fn radius(rng: &mut Rng) -> f64 {
    if chance(rng, 0.05) {
        rng.log10(-3.0, -2.0)
    } else {
        rng.log10(-1.2, 0.2)
    }
}

/// One primitive (at top level, possibly under its own random Transform).
fn primitive(rng: &mut Rng, placed: &mut Vec<Placed>) -> Node {
    let kind = rng.below(100);
    if kind < 65 {
        let gas = kind >= 22;
        let (mut c, mut r) = (point(rng, 1.3), radius(rng));
        let prev: Vec<&Placed> = placed.iter().filter(|p| p.gas && gas).collect();
        if !prev.is_empty() && chance(rng, 0.35) {
            let p = prev[rng.below(prev.len())];
            match rng.below(3) {
                0 => (c, r) = (p.c, p.r),
                1 => {
                    (c, r) = (
                        p.c + unit(rng) * p.r * rng.f() * 0.3,
                        p.r * rng.range(0.1, 0.7),
                    )
                }
                _ => c = p.c + unit(rng) * (p.r + r),
            }
        }
        let m = if !gas {
            (!chance(rng, 0.1)).then(|| material(rng, 0.0, Profile::Constant))
        } else {
            let pr = if kind >= 45 {
                profile(rng)
            } else {
                Profile::Constant
            };
            let t = transparency(rng);
            Some(material(rng, t, pr))
        };
        placed.push(Placed { c, r, gas });
        let shape = Node::Shape {
            geometry: Geometry::Sphere { r },
            material: m,
        };
        return at(c, shape);
    }
    let geometry = match kind {
        65..=73 => Geometry::Box {
            size: DVec3::new(
                rng.range(0.2, 1.5),
                rng.range(0.2, 1.5),
                rng.range(0.2, 1.5),
            ),
        },
        74..=82 => Geometry::Cylinder {
            r: rng.range(0.1, 0.8),
            h: rng.range(0.2, 1.5),
        },
        83..=90 => Geometry::Cone {
            r: rng.range(0.1, 0.8),
            h: rng.range(0.2, 1.5),
        },
        _ => {
            let c = point(rng, 1.3);
            return Node::Shape {
                geometry: Geometry::Triangle {
                    p: [
                        c + point(rng, 0.8),
                        c + point(rng, 0.8),
                        c + point(rng, 0.8),
                    ],
                },
                material: (!chance(rng, 0.1)).then(|| material(rng, 0.0, Profile::Constant)),
            };
        }
    };
    let m = (!chance(rng, 0.1)).then(|| material(rng, 0.0, Profile::Constant));
    let xf = Xf {
        translation: point(rng, 1.3),
        axis: unit(rng),
        angle: rng.range(-3.0, 3.0),
        scale: 1.0,
    };
    Node::Group {
        xf: Some(xf),
        children: vec![Node::Shape {
            geometry,
            material: m,
        }],
    }
}

fn directional(rng: &mut Rng) -> Node {
    Node::Directional(DirectionalLight {
        on: !chance(rng, 0.1),
        direction: unit(rng),
        color: color(rng),
        intensity: rng.range(0.2, 1.2),
        ambient: if chance(rng, 0.5) { rng.f() } else { 0.0 },
    })
}

fn point_light(rng: &mut Rng, placed: &[Placed]) -> Node {
    let gas: Vec<&Placed> = placed.iter().filter(|p| p.gas).collect();
    let near = |rng: &mut Rng| -> Option<&Placed> {
        let all: &[&Placed] = if gas.is_empty() { &[] } else { &gas };
        (!all.is_empty()).then(|| all[rng.below(all.len())])
    };
    let location = match rng.below(4) {
        0 => near(rng).map_or(point(rng, 2.0), |p| p.c),
        1 if !placed.is_empty() => {
            let s = &placed[rng.below(placed.len())];
            s.c + unit(rng) * s.r
        }
        _ => point(rng, 2.5),
    };
    // A radius that cuts through a gas sphere, or one that reaches everything.
    let radius = match (rng.below(3), near(rng)) {
        (0 | 1, Some(p)) => ((p.c - location).length() + rng.range(-0.9, 0.9) * p.r).max(0.05),
        _ => 100.0,
    };
    let attenuation = match rng.below(3) {
        0 => DVec3::new(1.0, 0.0, 0.0),
        // Its corner (where the quadratic reaches 1) at 0.3 to 3 units: often inside gas.
        1 => {
            let d = rng.range(0.3, 3.0);
            let a0 = rng.range(0.0, 0.8);
            let a1 = rng.range(0.0, (1.0 - a0) / d);
            DVec3::new(a0, a1, (1.0 - a0 - a1 * d) / (d * d))
        }
        _ => DVec3::new(
            rng.range(0.0, 2.0),
            rng.range(0.0, 1.0),
            rng.range(0.0, 1.0),
        ),
    };
    Node::Point(PointLight {
        on: !chance(rng, 0.1),
        location,
        color: color(rng),
        intensity: rng.range(0.2, 1.5),
        ambient: if chance(rng, 0.5) { rng.f() } else { 0.0 },
        attenuation,
        radius,
    })
}

/// Wraps a random run of `nodes` in a Group or Transform, sometimes with a DirectionalLight
/// among them (which then lights only that run).
fn group(rng: &mut Rng, nodes: &mut Vec<Node>) {
    if nodes.len() < 2 {
        return;
    }
    let a = rng.below(nodes.len());
    let b = a + 1 + rng.below(nodes.len() - a);
    let mut children: Vec<Node> = nodes.drain(a..b).collect();
    if chance(rng, 0.7) {
        let k = rng.below(children.len() + 1);
        children.insert(k, directional(rng));
    }
    let xf = chance(rng, 0.5).then(|| random_xf(rng));
    nodes.insert(a, Node::Group { xf, children });
}

/// Orientation (unit axis, angle) that turns -z to `forward` with `up` upwards.
fn orientation(forward: DVec3, up: DVec3) -> (DVec3, f64) {
    let right = forward.cross(up).normalize();
    let up = right.cross(forward);
    let q = DQuat::from_mat3(&DMat3::from_cols(right, up, -forward)).normalize();
    let (axis, angle) = q.to_axis_angle();
    if angle.abs() < 1e-12 {
        (DVec3::Z, 0.0)
    } else {
        (axis.normalize(), angle)
    }
}

/// Every light's intensity and every emissive colour of `n` times `k`; unlit shapes (white
/// whatever the lights) become black opaque ones.
fn dim(n: &mut Node, k: f64) {
    match n {
        Node::Shape { material, .. } => match material {
            Some(m) => m.emissive = m.emissive.map(|c| c * k),
            None => {
                *material = Some(Material {
                    diffuse: [0.0; 3],
                    emissive: [0.0; 3],
                    specular: [0.0; 3],
                    shininess: 0.2,
                    ambient: 0.2,
                    transparency: 0.0,
                    profile: Profile::Constant,
                })
            }
        },
        Node::Point(l) => l.intensity *= k,
        Node::Directional(l) => l.intensity *= k,
        Node::Group { children, .. } => children.iter_mut().for_each(|c| dim(c, k)),
    }
}

pub fn scene(seed: u64) -> SceneDesc {
    let mut rng = Rng::new(seed);
    let n = 2 + (38.0 * rng.f() * rng.f()) as usize;
    let mut placed = Vec::new();
    let mut nodes = Vec::new();
    for _ in 0..n {
        let mut p = primitive(&mut rng, &mut placed);
        if chance(&mut rng, 0.2) {
            p = Node::Group {
                xf: Some(random_xf(&mut rng)),
                children: vec![p],
            };
        }
        nodes.push(p);
    }
    for _ in 0..rng.below(4) {
        group(&mut rng, &mut nodes);
    }
    for _ in 0..rng.below(3) {
        let l = point_light(&mut rng, &placed);
        nodes.push(l);
    }
    for _ in 0..rng.below(2) {
        nodes.push(directional(&mut rng));
    }
    let headlight = chance(&mut rng, 0.6);
    let gas: Vec<&Placed> = placed.iter().filter(|p| p.gas).collect();
    let position = if !gas.is_empty() && chance(&mut rng, 0.15) {
        let p = gas[rng.below(gas.len())];
        p.c + unit(&mut rng) * p.r * rng.f() * 0.8
    } else {
        unit(&mut rng) * rng.range(4.0, 8.0)
    };
    let target = point(&mut rng, 0.5);
    let forward = (target - position).normalize();
    let up = if forward.y.abs() > 0.95 {
        DVec3::X
    } else {
        DVec3::Y
    };
    let (axis, angle) = orientation(forward, up);
    let ortho = chance(&mut rng, 0.25).then(|| rng.range(2.0, 5.0));
    let fov = rng.range(0.3, 1.2);
    let mut background = if chance(&mut rng, 0.5) {
        color(&mut rng).map(|c| c * 0.3)
    } else {
        [0.0; 3]
    };
    let (width, height) = (8 + rng.below(5) as u32, 8 + rng.below(5) as u32);
    // Scenes faint everywhere: every pixel near 1e-12, where an error estimate must still
    // bound with a margin, not equal, what it truncates.
    let mut headlight = headlight;
    if chance(&mut rng, 0.1) {
        let k = rng.log10(-14.0, -9.0);
        for n in &mut nodes {
            dim(n, k);
        }
        background = [0.0; 3];
        headlight = false;
    }
    SceneDesc {
        seed,
        nodes,
        viewpoint: Viewpoint {
            position,
            axis,
            angle,
            fov,
            ortho,
        },
        headlight,
        background,
        width,
        height,
    }
}
