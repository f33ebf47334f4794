//! Whole spheres: a sphere node lowered at once from its values. A sphere node is a Transform
//! holding a Shape with a Sphere, with at most a translation, a Material and a radius; it is
//! lowered doing what opening and closing its nodes one by one would do (the same node count, material table, sphere and
//! Transform, through the same functions). The expander's compiled PROTO templates and the
//! parser's whole sphere nodes ([`crate::vrml::sphere_node`]) both come here; whatever
//! would warn or be refused is left to the node-by-node path by the caller.

use glam::DVec3;

use super::open::Kind;
use super::transform::{Marks, TransformFields};
use super::Builder;
use crate::error::Error;
use crate::scene::{Material, Sphere};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::sphere_node::{SphereNode, MATERIAL_FIELDS};

/// A Material field the template sets, in the body's order: one of
/// [`MATERIAL_FIELDS`], in that table's order (its name and number of values are there).
#[derive(Clone, Copy, Debug)]
pub(in crate::vrml::lower) enum MaterialField {
    Diffuse,
    Emissive,
    Specular,
    Shininess,
    AmbientIntensity,
    Transparency,
}

impl MaterialField {
    /// By index into [`MATERIAL_FIELDS`].
    pub(in crate::vrml::lower) const ALL: [MaterialField; 6] = [
        MaterialField::Diffuse,
        MaterialField::Emissive,
        MaterialField::Specular,
        MaterialField::Shininess,
        MaterialField::AmbientIntensity,
        MaterialField::Transparency,
    ];

    pub(in crate::vrml::lower) fn of(name: &str) -> Option<MaterialField> {
        let i = MATERIAL_FIELDS.iter().position(|(n, _)| *n == name)?;
        Some(Self::ALL[i])
    }
    /// Sets this field of `m` to `v` (its `arity` values), as replaying would without a
    /// warning; `None` where replaying would warn ([`in_range`]).
    pub(in crate::vrml::lower) fn set(self, m: &mut Material, v: &[f64]) -> Option<()> {
        match self {
            _ if !in_range(self, v) => return None,
            MaterialField::Diffuse => m.diffuse = DVec3::from_slice(v),
            MaterialField::Emissive => m.emissive = DVec3::from_slice(v),
            MaterialField::Specular => m.specular = DVec3::from_slice(v),
            MaterialField::Shininess => m.shininess = v[0],
            MaterialField::AmbientIntensity => m.ambient_intensity = v[0],
            MaterialField::Transparency => m.transparency = v[0],
        }
        Some(())
    }
    pub(in crate::vrml::lower) fn arity(self) -> usize {
        MATERIAL_FIELDS[self as usize].1
    }
}

/// A Material value replaying stores without a warning: shininess and transparency in
/// [0, 1], colours and ambientIntensity not negative.
pub(in crate::vrml::lower) fn in_range(f: MaterialField, v: &[f64]) -> bool {
    match f {
        MaterialField::Shininess | MaterialField::Transparency => (0.0..=1.0).contains(&v[0]),
        _ => v.iter().all(|x| *x >= 0.0),
    }
}

/// A radius replaying accepts.
pub(in crate::vrml::lower) fn radius_ok(r: f64) -> bool {
    r > 0.0 && r.is_finite()
}

/// Up to three numbers in a fixed array, the rest zero. (Element by element: copying a slice
/// of varying length called `memcpy`, six times a particle in the PROTO layout.)
#[inline(always)]
pub(in crate::vrml::lower) fn padded3(values: &[f64]) -> [f64; 3] {
    let mut v = [0.0; 3];
    for (i, x) in v.iter_mut().enumerate() {
        if let Some(&y) = values.get(i) {
            *x = y;
        }
    }
    v
}

/// Where a sphere node's parts are, how many nodes it has, and what it spends of the
/// expansion budget.
pub(in crate::vrml::lower) struct Placed {
    pub(in crate::vrml::lower) nodes: u64,
    pub(in crate::vrml::lower) spent: u64,
    pub(in crate::vrml::lower) transform_at: Pos,
    pub(in crate::vrml::lower) sphere_at: Pos,
}

/// An instance's values as the template needs them, read before anything changes.
pub(in crate::vrml::lower) struct Inputs {
    pub(in crate::vrml::lower) translation: Option<DVec3>,
    pub(in crate::vrml::lower) material: Option<Material>,
    pub(in crate::vrml::lower) radius: f64,
}

impl Builder {
    /// Whether a sphere's `nodes` nodes lowered at once here are what opening and closing
    /// them one by one would give: not inside a node that is not lowered, nor where the
    /// Transform is out of place (anywhere but the top level or a grouping node's
    /// `children`), nor past the expansion budget.
    #[inline]
    pub(in crate::vrml::lower) fn sphere_fits_here(
        &self,
        cx: &Ctx,
        src: &SourceWindow,
        nodes: u64,
    ) -> bool {
        if self.open.quiet > 0 {
            return false;
        }
        if let Some(ctx) = self.open.fields.last() {
            let in_children = &*ctx.name == "children"
                && matches!(
                    self.open.frames[ctx.frame].kind,
                    Kind::Group {
                        inline_urls: None,
                        ..
                    }
                );
            if !in_children {
                return false;
            }
        }
        cx.fits(nodes, src)
    }

    /// A plain sphere node read whole from the text (see [`crate::vrml::sphere_node`]) at
    /// `at`, where [`Self::sphere_fits_here`] (and nothing recorded): lowered as its events
    /// would be, if its values are ones that lower without a message. False: its events
    /// follow.
    #[inline]
    pub(in crate::vrml::lower) fn whole_sphere_node(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        at: Pos,
        node: &SphereNode,
    ) -> Result<bool, Error> {
        let material = if node.material {
            let mut m = Material::default();
            for (f, v) in node.material_fields() {
                if MaterialField::ALL[f].set(&mut m, v).is_none() {
                    return Ok(false);
                }
            }
            Some(m)
        } else {
            None
        };
        let radius = node.radius.unwrap_or(1.0);
        if !radius_ok(radius) {
            return Ok(false);
        }
        let inputs = Inputs {
            translation: node.translation.map(DVec3::from_array),
            material,
            radius,
        };
        let placed = Placed {
            nodes: node.nodes,
            spent: node.nodes,
            transform_at: at,
            sphere_at: at + node.sphere_at as u64,
        };
        self.lower_sphere(cx, src, placed, inputs)?;
        self.whole_nodes += 1;
        Ok(true)
    }

    /// Lowers a sphere node (a Transform holding a Shape with a Sphere) with `inputs`.
    pub(in crate::vrml::lower) fn lower_sphere(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        tpl: Placed,
        inputs: Inputs,
    ) -> Result<(), Error> {
        // What replaying does, in its order: the nodes are counted as they start, the
        // Material is stored when it closes, the sphere when the Shape closes, and the
        // Transform moves it when it closes.
        cx.nodes += tpl.nodes;
        cx.spent += tpl.spent;
        cx.watch_nodes(src.offset());
        let marks = Marks::of(&self.scene);
        let paint = match inputs.material {
            Some(m) => {
                self.materials.open.push(m);
                self.close_material()
            }
            None => self.materials.unlit,
        };
        self.scene.spheres.push(Sphere {
            center: DVec3::ZERO,
            radius: inputs.radius,
            color: paint.color,
            material: paint.material,
            ellipsoid: None,
            origin: cx.origin(tpl.sphere_at),
        });
        let t = TransformFields {
            translation: inputs.translation.unwrap_or(DVec3::ZERO),
            ..TransformFields::default()
        };
        self.close_transform(cx, src, &t, marks, tpl.transform_at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn material_fields_follow_the_parsers_table() {
        // `arity` and the whole sphere node index MATERIAL_FIELDS by the variant's number.
        for (i, f) in MaterialField::ALL.iter().enumerate() {
            assert_eq!(*f as usize, i);
            assert!(matches!(MaterialField::of(MATERIAL_FIELDS[i].0), Some(g) if g as usize == i));
        }
        assert_eq!(MaterialField::Specular.arity(), 3);
        assert_eq!(MaterialField::Transparency.arity(), 1);
        assert!(MaterialField::of("diffuse").is_none());
    }
}
