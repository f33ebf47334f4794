//! What a gas primitive contributes (docs/model.md section 1): emission colour `C = emissiveColor`,
//! albedo `a = diffuseColor`; a shape without a Material (unlit) glows white (or its Color
//! node's colour) and ignores lights (`C = 1, a = 0`).

use glam::DVec3;

use crate::accel::Prim;
use crate::scene::MaterialTable;

/// `(C, a)` of a gas primitive.
#[inline]
pub fn emission_albedo(materials: &MaterialTable, p: &Prim) -> (DVec3, DVec3) {
    let m = materials.get(p.material, p.color);
    if m.unlit {
        (m.diffuse, DVec3::ZERO)
    } else {
        (m.emissive, m.diffuse)
    }
}
