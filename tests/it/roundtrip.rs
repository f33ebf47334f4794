//! Property: random scene trees printed as VRML text and parsed back give the IR computed
//! directly from the tree (top-down matrix products here; the lowerer applies matrices
//! bottom-up to index ranges, so the two paths are independent).

use glam::{DAffine3, DQuat, DVec3};
use gtsphere::scene::Light;
use proptest::prelude::*;

#[derive(Clone, Debug)]
enum Node {
    Ball {
        radius: f64,
        color: [f64; 3],
        def: bool,
    },
    Light {
        dir: [f64; 3],
    },
    Group {
        kids: Vec<Node>,
    },
    Transform {
        t: [f64; 3],
        axis: [f64; 3],
        angle: f64,
        scale: f64,
        kids: Vec<Node>,
    },
}

fn finite(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    lo..hi
}

fn node() -> impl Strategy<Value = Node> {
    let leaf = prop_oneof![
        4 => (finite(1e-6, 1e3), [0.0..1.0f64, 0.0..1.0, 0.0..1.0], any::<bool>())
            .prop_map(|(radius, color, def)| Node::Ball { radius, color, def }),
        1 => [-1.0..1.0f64, -1.0..1.0, 0.1..1.0].prop_map(|dir| Node::Light { dir }),
    ];
    leaf.prop_recursive(5, 48, 6, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..6).prop_map(|kids| Node::Group { kids }),
            (
                [-1e3..1e3f64, -1e3..1e3, -1e3..1e3],
                [-1.0..1.0f64, -1.0..1.0, 0.05..1.0],
                -7.0..7.0f64,
                0.01..100.0f64,
                prop::collection::vec(inner, 0..6)
            )
                .prop_map(|(t, axis, angle, scale, kids)| Node::Transform {
                    t,
                    axis,
                    angle,
                    scale,
                    kids
                }),
        ]
    })
}

/// Separators and number spellings vary, to exercise the lexer too.
struct Printer {
    out: String,
    style: u32,
    defs: usize,
}

impl Printer {
    fn num(&mut self, x: f64) {
        self.style = self.style.wrapping_mul(1103515245).wrapping_add(12345);
        match (self.style >> 16) % 3 {
            0 => self.out.push_str(&format!("{x:?}")),
            1 => self.out.push_str(&format!("{x:e}")),
            _ => self.out.push_str(&format!("{x:.17e}")),
        }
        self.sep();
    }
    fn sep(&mut self) {
        self.style = self.style.wrapping_mul(1103515245).wrapping_add(12345);
        self.out.push_str(match (self.style >> 16) % 4 {
            0 => " ",
            1 => ", ",
            2 => " # note\n",
            _ => "\n\t",
        });
    }
    fn node(&mut self, n: &Node) {
        match n {
            Node::Ball { radius, color, def } => {
                if *def {
                    self.defs += 1;
                    self.out.push_str(&format!("DEF B{} ", self.defs));
                }
                self.out
                    .push_str("Shape { appearance Appearance { material Material { diffuseColor ");
                for c in color {
                    self.num(*c);
                }
                self.out.push_str("} } geometry Sphere { radius ");
                self.num(*radius);
                self.out.push_str("} }");
                if *def {
                    // A USE right after the DEF: the same sphere again.
                    self.out.push_str(&format!(" USE B{} ", self.defs));
                }
            }
            Node::Light { dir } => {
                self.out.push_str("DirectionalLight { direction ");
                for c in dir {
                    self.num(*c);
                }
                self.out.push('}');
            }
            Node::Group { kids } => {
                self.out.push_str("Group { children [ ");
                for k in kids {
                    self.node(k);
                    self.sep();
                }
                self.out.push_str("] }");
            }
            Node::Transform {
                t,
                axis,
                angle,
                scale,
                kids,
            } => {
                // Fields after children half of the time.
                let late = self.style % 2 == 0;
                self.out.push_str("Transform { ");
                if !late {
                    self.fields(t, axis, *angle, *scale);
                }
                self.out.push_str("children [ ");
                for k in kids {
                    self.node(k);
                    self.sep();
                }
                self.out.push_str("] ");
                if late {
                    self.fields(t, axis, *angle, *scale);
                }
                self.out.push('}');
            }
        }
    }
    fn fields(&mut self, t: &[f64; 3], axis: &[f64; 3], angle: f64, scale: f64) {
        self.out.push_str("translation ");
        for c in t {
            self.num(*c);
        }
        self.out.push_str("rotation ");
        for c in axis {
            self.num(*c);
        }
        self.num(angle);
        self.out.push_str("scale ");
        for _ in 0..3 {
            self.num(scale);
        }
    }
}

#[derive(Debug, Default)]
struct Expected {
    spheres: Vec<(DVec3, f64, [f64; 3])>,
    /// (direction, scope start, scope end)
    lights: Vec<(DVec3, u32, u32)>,
}

fn expect(n: &Node, m: DAffine3, scale: f64, out: &mut Expected, scope_start: u32) {
    match n {
        Node::Ball { radius, color, def } => {
            let copies = if *def { 2 } else { 1 };
            for _ in 0..copies {
                out.spheres.push((m.translation, radius * scale, *color));
            }
        }
        Node::Light { dir } => {
            let d = m.transform_vector3(DVec3::from_array(*dir)).normalize();
            out.lights.push((d, scope_start, u32::MAX));
        }
        Node::Group { kids } => children(kids, m, scale, out),
        Node::Transform {
            t,
            axis,
            angle,
            scale: s,
            kids,
        } => {
            let q = DQuat::from_axis_angle(DVec3::from_array(*axis).normalize(), *angle);
            let local = DAffine3::from_scale_rotation_translation(
                DVec3::splat(*s),
                q,
                DVec3::from_array(*t),
            );
            children(kids, m * local, scale * s, out);
        }
    }
}

fn children(kids: &[Node], m: DAffine3, scale: f64, out: &mut Expected) {
    let start = out.spheres.len() as u32;
    let first_light = out.lights.len();
    for k in kids {
        let before = out.lights.len();
        expect(k, m, scale, out, start);
        // Lights that are direct children get this group's range; nested ones were closed inside.
        if let Node::Light { .. } = k {
            let _ = before;
        }
    }
    let end = out.spheres.len() as u32;
    for l in &mut out.lights[first_light..] {
        if l.2 == u32::MAX {
            l.1 = start;
            l.2 = end;
        }
    }
}

fn rel_close(a: DVec3, b: DVec3, scale: f64) -> bool {
    (a - b).length() <= 1e-9 * (1.0 + scale + b.length())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]
    #[test]
    fn printed_trees_parse_back_to_the_same_ir(roots in prop::collection::vec(node(), 0..5), style in any::<u32>()) {
        let mut p = Printer { out: String::from("#VRML V2.0 utf8\n"), style, defs: 0 };
        for r in &roots {
            p.node(r);
            p.sep();
        }
        let mut want = Expected::default();
        children(&roots, DAffine3::IDENTITY, 1.0, &mut want);
        let (s, rep) = gtsphere::vrml::load_bytes("prop.wrl", p.out.clone().into_bytes(), &Default::default())
            .map_err(|e| TestCaseError::fail(format!("{e}\n{}", p.out)))?;
        prop_assert!(rep.warnings.is_empty(), "{:?}", rep.warnings);
        prop_assert_eq!(s.spheres.len(), want.spheres.len());
        for (b, (c, r, col)) in s.spheres.iter().zip(&want.spheres) {
            prop_assert!(rel_close(b.center, *c, 1e3), "centre {} vs {}", b.center, c);
            prop_assert!((b.radius - r).abs() <= 1e-12 * r, "radius {} vs {}", b.radius, r);
            prop_assert_eq!(s.material_of(b).diffuse.to_array(), *col);
        }
        let got: Vec<_> = s.lights.iter().map(|l| match l {
            Light::Directional(d) => {
                let (start, end) = d.scope.range(s.spheres.len());
                (d.direction, start, end)
            }
            Light::Point(_) => unreachable!(),
        }).collect();
        prop_assert_eq!(got.len(), want.lights.len());
        for (g, w) in got.iter().zip(&want.lights) {
            prop_assert!(rel_close(g.0, w.0, 1.0), "direction {} vs {}", g.0, w.0);
            prop_assert_eq!((g.1, g.2), (w.1, w.2));
        }
    }
}
