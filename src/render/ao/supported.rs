//! Which scenes exact AO takes (docs/model.md section 11), and why it refuses the others.

use super::bracket;
use crate::render::surfaces::Traced;
use crate::render::Prepared;

/// Why `prep` cannot be rendered with exact AO, if it cannot: the occluders exact AO knows
/// are opaque spheres, triangles and Boxes (exactly), closed Cylinders and Cones (to the
/// tolerance, `bracket`), and gas spheres (to the tolerance, [`gas`]) where no Cylinder or
/// Cone occludes.
pub(crate) fn unsupported(prep: &Prepared) -> Option<String> {
    let (mut ellipsoids, mut gas) = (0, 0);
    for q in prep.bvh.packed() {
        if q.is_ellipsoid() {
            ellipsoids += 1;
        } else if q.is_gas() {
            gas += 1;
        }
    }
    let (mut open, mut closed) = (0, 0);
    for t in &prep.surfaces.items {
        if let Traced::Solid { solid, .. } = t {
            if bracket::is_round(solid) {
                if bracket::is_closed_round(solid) {
                    closed += 1;
                } else {
                    open += 1;
                }
            }
        }
    }
    let beside = |count: usize, other: usize| if other > 0 { count } else { 0 };
    let what = [
        (beside(gas, closed), "gas spheres"),
        (
            beside(closed, gas),
            "closed cylinders or cones beside the gas",
        ),
        (ellipsoids, "ellipsoids (spheres under a non-uniform scale)"),
        (
            open,
            "open cylinders or cones (a side, cap or base left out)",
        ),
    ];
    let found: Vec<String> = what
        .iter()
        .filter(|(count, _)| *count > 0)
        .map(|(count, what)| format!("{count} {what}"))
        .collect();
    (!found.is_empty()).then(|| {
        format!(
            "ambient occlusion knows opaque spheres, triangles, boxes, closed cylinders and \
             cones, and gas spheres where no cylinder or cone occludes, and this scene has {}",
            found.join(", ")
        )
    })
}
