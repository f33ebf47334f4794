//! Materials while they are read. An open Material's fields live on a stack
//! ([`Materials::open`]) rather than in its frame, so that frames stay small; when it closes
//! it becomes an index into the scene's materials, shared with every equal material met
//! before (see [`crate::vrml::materials`]). When the store of materials is merged of its
//! duplicates, every index held so far is renumbered: the spheres' and the open
//! Appearances' and Shapes'.

use glam::DVec3;

use super::open::{Kind, Leaf};
use super::Lowerer;
use crate::scene::Material;
use crate::vrml::materials::RecentMaterials;

/// The scene's index of [`Material::unlit`] (a Shape without Appearance or Material): the
/// first material, interned when the lowerer starts ([`super::Lowerer`]'s constructor).
pub(super) const UNLIT: u32 = 0;

/// Open Materials and the materials met recently.
#[derive(Default)]
pub(super) struct Materials {
    /// Recent materials by content (equal ones are shared).
    pub(super) recent: RecentMaterials,
    /// The fields of the open Material nodes, innermost last (see [`Leaf::Material`]).
    pub(super) open: Vec<Material>,
}

impl Lowerer {
    /// The scene's index of the innermost open Material's fields, which it takes off
    /// `open` (read in place: no copy of the material until it is stored).
    pub(super) fn close_material(&mut self) -> u32 {
        if let (Some(p), Some(m)) = (self.gas_profile, self.materials.open.last_mut()) {
            m.profile = p;
        }
        let m = self.materials.open.last().expect("open Material");
        let i = self.materials.recent.index(m, &mut self.scene.materials);
        self.materials.open.pop();
        if self.materials.recent.wants_merge(&self.scene.materials) {
            return self.merge_materials(i);
        }
        i
    }

    /// The index of material `base` with its diffuseColor replaced by `colour` (a mesh's
    /// Color node; for an unlit material, its colour), shared like any other material.
    pub(super) fn recolored(&mut self, base: u32, colour: DVec3) -> u32 {
        let mut m = self.scene.materials.get(base as usize);
        if m.diffuse == colour {
            return base;
        }
        m.diffuse = colour;
        let i = self.materials.recent.index(&m, &mut self.scene.materials);
        if self.materials.recent.wants_merge(&self.scene.materials) {
            return self.merge_materials(i);
        }
        i
    }

    /// Merges the duplicate materials stored so far and renumbers every material index held:
    /// the spheres', the open Appearances' and Shapes', and `i` (returned).
    #[cold]
    #[inline(never)]
    pub(super) fn merge_materials(&mut self, i: u32) -> u32 {
        let Some(new_index) = self.materials.recent.merge(&mut self.scene.materials) else {
            return i;
        };
        let renumber = |m: &mut u32| *m = new_index[*m as usize];
        self.scene
            .spheres
            .iter_mut()
            .for_each(|s| renumber(&mut s.material));
        self.scene
            .surfaces
            .iter_mut()
            .for_each(|s| renumber(&mut s.material));
        for f in &mut self.open.frames {
            match &mut f.kind {
                Kind::Leaf(Leaf::Appearance {
                    material: Some(m), ..
                })
                | Kind::Leaf(Leaf::Shape {
                    appearance: Some(Some(m)),
                    ..
                }) => renumber(m),
                _ => {}
            }
        }
        new_index[i as usize]
    }
}
