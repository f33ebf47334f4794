//! Materials while they are read. An open Material's fields live on a stack
//! ([`Materials::open`]) rather than in its frame, so that frames stay small; when it closes
//! it becomes what a Shape's geometry refers to: the scene's record of its fields but the
//! diffuse colour (shared with every equal one), and its colour.

use super::Builder;
use crate::scene::{Material, Paint};

/// Open Materials, and the unlit white of a Shape without Appearance or Material.
#[derive(Default)]
pub(in crate::vrml::lower) struct Materials {
    /// The fields of the open Material nodes, innermost last (see `Leaf::Material`).
    pub(in crate::vrml::lower) open: Vec<Material>,
    /// [`Material::unlit`], stored when the lowerer starts.
    pub(in crate::vrml::lower) unlit: Paint,
}

impl Builder {
    /// The innermost open Material's paint; its fields are taken off `open` (read in place:
    /// no copy of the material).
    pub(in crate::vrml::lower) fn close_material(&mut self) -> Paint {
        if let (Some(p), Some(m)) = (self.gas_profile, self.materials.open.last_mut()) {
            m.profile = p;
        }
        let m = self.materials.open.last().expect("open Material");
        let paint = self.scene.materials.add(m);
        self.materials.open.pop();
        paint
    }
}
