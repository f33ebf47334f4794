//! Lights and their scopes. A PointLight lights the whole scene; a DirectionalLight lights
//! only the siblings in its enclosing grouping node and their descendants (VRML97 4.6.7,
//! 6.16). Since a group's contents are one range of the IR, a DirectionalLight's scope is
//! the range of spheres lowered between that group's opening and closing: the light's index
//! is kept in its group's frame ([`DirLights`]) and the range is set when the group closes.

use glam::DVec3;

use super::transform::Marks;
use super::Builder;
use crate::scene::{DirectionalLight, Light, LightScope, PointLight};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;

/// The DirectionalLights among a grouping node's children (indices into the scene's lights).
/// Rare, so boxed: the open-node frames stay small enough to move without a `memcpy` call.
pub(in crate::vrml::lower) type DirLights = Option<Box<Vec<usize>>>;

impl Builder {
    /// A closed PointLight.
    pub(in crate::vrml::lower) fn close_point_light(&mut self, l: PointLight) {
        self.scene.lights.push(Light::Point(l));
    }

    /// A closed DirectionalLight: stored, and its scope left to the enclosing grouping node.
    pub(in crate::vrml::lower) fn close_directional_light(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        mut l: DirectionalLight,
        at: Pos,
    ) {
        let d = l.direction;
        if d.length_squared() == 0.0 || !d.is_finite() {
            cx.diags
                .warn(src, at, "DirectionalLight direction is zero: using 0 0 -1");
            l.direction = DVec3::new(0.0, 0.0, -1.0);
        } else {
            l.direction = d.normalize();
        }
        let idx = self.scene.lights.len();
        self.scene.lights.push(Light::Directional(l));
        // Scope: the siblings in the enclosing grouping node (set when it closes).
        if let Some(dirlights) = self.open.innermost_dirlights() {
            dirlights.get_or_insert_with(Box::default).push(idx);
        }
    }

    /// A grouping node that opened at `marks` closes: its DirectionalLights light what was
    /// lowered inside it.
    pub(in crate::vrml::lower) fn scope_lights(&mut self, marks: Marks, dirlights: DirLights) {
        let end = self.scene.spheres.len() as u32;
        let surfaces_end = self.scene.surfaces.len() as u32;
        for i in dirlights.into_iter().flat_map(|d| *d) {
            if let Light::Directional(l) = &mut self.scene.lights[i] {
                l.scope = LightScope::Range {
                    start: marks.spheres as u32,
                    end,
                };
                l.surface_scope = LightScope::Range {
                    start: marks.surfaces as u32,
                    end: surfaces_end,
                };
            }
        }
    }
}
