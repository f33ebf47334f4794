//! Which matrix scenes AO must refuse (gas beside Cylinders or Cones), whether the library's
//! message counts them, and the AO part checked instead: the scene without its gas.

use super::super::scenes::{Geometry, Material, Node};

/// What a scene holds that AO refuses together: gas spheres and Cylinders or Cones (the
/// generator's Cylinders and Cones have all their parts, and it makes no ellipsoids). Either
/// kind alone is rendered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unsupported {
    pub gas: usize,
    /// Cylinders and Cones.
    pub rounds: usize,
}

/// Whether shape node `geometry` with `material` is a gas sphere.
fn is_gas(geometry: &Geometry, material: &Option<Material>) -> bool {
    matches!(geometry, Geometry::Sphere { .. }) && material.is_some_and(|m| m.transparency > 0.0)
}

impl Unsupported {
    pub fn of(nodes: &[Node]) -> Unsupported {
        let mut u = Unsupported::default();
        for n in nodes {
            match n {
                Node::Shape { geometry, material } => {
                    if is_gas(geometry, material) {
                        u.gas += 1;
                    }
                    if matches!(geometry, Geometry::Cylinder { .. } | Geometry::Cone { .. }) {
                        u.rounds += 1;
                    }
                }
                Node::Group { children, .. } => {
                    let inner = Unsupported::of(children);
                    u.gas += inner.gas;
                    u.rounds += inner.rounds;
                }
                Node::Point(_) | Node::Directional(_) => {}
            }
        }
        u
    }

    /// Whether AO must refuse the scene: it has gas and Cylinders or Cones.
    pub fn refused(&self) -> bool {
        self.gas > 0 && self.rounds > 0
    }

    /// What is wrong with `message`, the library's refusal: what it says the scene has (after
    /// "this scene has") must give the count of gas spheres and the count of Cylinders and
    /// Cones (a number followed by words naming cylinders or cones), and name no ellipsoids.
    pub fn judge(&self, message: &str) -> Option<String> {
        let m = message.to_lowercase();
        let Some(at) = m.rfind("this scene has") else {
            return Some("does not say what the scene has".into());
        };
        let has = &m[at + "this scene has".len()..];
        // The phrases of the list, each a count and what it counts.
        let phrases: Vec<&str> = has
            .split([',', ';'])
            .flat_map(|p| p.split(" and "))
            .map(str::trim)
            .collect();
        let counts = |n: usize, words: &[&str]| {
            phrases.iter().any(|p| {
                p.split_whitespace().next() == Some(n.to_string().as_str())
                    && words.iter().any(|w| p.contains(w))
            })
        };
        if !counts(self.gas, &["gas sphere"]) {
            return Some(format!("does not say {} gas sphere(s)", self.gas));
        }
        if !counts(self.rounds, &["cylinder", "cone"]) {
            return Some(format!("does not say {} cylinders or cones", self.rounds));
        }
        if has.contains("ellipsoid") {
            return Some("names ellipsoids, which the scene has none of".into());
        }
        None
    }
}

/// `nodes` without their gas spheres.
pub fn ao_part(nodes: &[Node]) -> Vec<Node> {
    nodes
        .iter()
        .filter_map(|n| match n {
            Node::Shape { geometry, material } => (!is_gas(geometry, material)).then(|| n.clone()),
            Node::Group { xf, children } => Some(Node::Group {
                xf: *xf,
                children: ao_part(children),
            }),
            _ => Some(n.clone()),
        })
        .collect()
}
