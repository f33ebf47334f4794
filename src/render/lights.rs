//! Lights as the integrators use them (docs/model.md section 1): switched-off lights dropped,
//! colour premultiplied by intensity and by ambient intensity, the headlight added.
//!
//! The headlight is carried by the viewer: its light reaches a point along the camera ray
//! that sees the point, so nothing the camera sees is in its shadow, and in gas it is
//! attenuated by the gas in front of the point along that ray ([`LightSource::carried`]).
//! It shades with VRML's constant direction, towards the viewer along the view axis. With
//! `headlight_shadows` it is an ordinary DirectionalLight instead, shadowed like any other.

use glam::DVec3;

use crate::scene::{Light, LightScope};

/// Where a light's light comes from and what it reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Lights points within `radius` of `position`, attenuated by
    /// `1 / max(a0 + a1 d + a2 d^2, 1)`.
    Point {
        /// The light's position, in world space.
        position: DVec3,
        /// The coefficients `(a0, a1, a2)`.
        attenuation: DVec3,
        /// Distance beyond which it lights nothing, in world units.
        radius: f64,
    },
    /// Unit vector towards the light (opposite to VRML's `direction`); lights the spheres
    /// of `scope` and the surfaces of `surface_scope`.
    Directional {
        /// The unit vector towards the light.
        to_light: DVec3,
        /// The spheres it lights.
        scope: LightScope,
        /// The surfaces it lights.
        surface_scope: LightScope,
    },
}

/// A light that is on, as the integrators use it: its kind and its colours premultiplied by
/// its intensities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSource {
    /// Where its light comes from and what it reaches.
    pub kind: LightKind,
    /// `C_i * I_i`.
    pub direct: DVec3,
    /// `C_i * Ia_i`.
    pub ambient: DVec3,
    /// The viewer's headlight: its visibility at a point is the camera ray's transmittance
    /// up to that point, never a shadow ray's.
    pub carried: bool,
}

/// What light `l` contributes at world point `x` before visibility: the unit vector towards
/// the light, the distance to it (infinite for directional lights) and the attenuation factor;
/// `None` where the light does not reach (outside a point light's radius, or `x` on it).
#[inline]
pub fn towards(l: &LightSource, x: DVec3) -> Option<(DVec3, f64, f64)> {
    match l.kind {
        LightKind::Directional { to_light, .. } => Some((to_light, f64::INFINITY, 1.0)),
        LightKind::Point {
            position,
            attenuation: a,
            radius,
        } => {
            let v = position - x;
            let d = v.length();
            if d > radius || d == 0.0 {
                return None;
            }
            Some((v / d, d, attenuation(a, d)))
        }
    }
}

/// The light ray from `x`: unit vector towards the light and distance to it (infinite for
/// directional lights), whether or not the light reaches `x` (a point light's `radius` is not
/// applied); `None` only at the light itself.
#[inline]
pub fn path_to(l: &LightSource, x: DVec3) -> Option<(DVec3, f64)> {
    match l.kind {
        LightKind::Directional { to_light, .. } => Some((to_light, f64::INFINITY)),
        LightKind::Point { position, .. } => {
            let v = position - x;
            let d = v.length();
            (d > 0.0).then(|| (v / d, d))
        }
    }
}

/// How far along a light ray of length `dist` an opaque primitive blocks it: all but the
/// last 1e-9 of it. A point light on an opaque surface (to within the rounding of its
/// coordinates) lights the side its tangent plane faces: a ray from there meets the surface
/// only at the light, and rounding must not decide that it enters it just before.
#[inline]
pub fn opaque_reach(dist: f64) -> f64 {
    dist * (1.0 - 1e-9)
}

/// A point light's attenuation at distance `d`: `1 / max(a0 + a1 d + a2 d^2, 1)`.
#[inline]
pub fn attenuation(a: DVec3, d: f64) -> f64 {
    1.0 / (a.x + a.y * d + a.z * d * d).max(1.0)
}

/// Whether light `l` may light sphere `sphere` (VRML scoping of DirectionalLights).
#[inline]
pub fn in_scope(l: &LightSource, sphere: u32) -> bool {
    match l.kind {
        LightKind::Directional { scope, .. } => scope.contains(sphere),
        LightKind::Point { .. } => true,
    }
}

/// Whether light `l` may light surface `surface` (an index into `Scene::surfaces`).
#[inline]
pub fn in_surface_scope(l: &LightSource, surface: u32) -> bool {
    match l.kind {
        LightKind::Directional { surface_scope, .. } => surface_scope.contains(surface),
        LightKind::Point { .. } => true,
    }
}

/// How the headlight is added, if at all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Headlight {
    /// No headlight.
    Off,
    /// Carried by the viewer: no shadows (docs/model.md section 1).
    Carried,
    /// A strict DirectionalLight along the view, shadowed like any other.
    Shadowed,
}

/// The lights of a scene of `spheres` spheres and `surfaces` surfaces that are on, plus the
/// headlight (along `view`, intensity 1, ambientIntensity 0, white) unless it is off.
pub fn collect(
    lights: &[Light],
    headlight: Headlight,
    spheres: usize,
    surfaces: usize,
    view: DVec3,
) -> Vec<LightSource> {
    let mut out = Vec::new();
    for l in lights {
        match l {
            Light::Point(p) if p.on => out.push(LightSource {
                kind: LightKind::Point {
                    position: p.location,
                    attenuation: p.attenuation,
                    radius: p.radius,
                },
                direct: p.color * p.intensity,
                ambient: p.color * p.ambient_intensity,
                carried: false,
            }),
            Light::Directional(d) if d.on => out.push(LightSource {
                kind: LightKind::Directional {
                    to_light: -d.direction,
                    // A scope holding every sphere is All, which integrators recognise as "no
                    // scoping to apply".
                    scope: if d.scope.covers_all(spheres) {
                        LightScope::All
                    } else {
                        d.scope
                    },
                    surface_scope: if d.surface_scope.covers_all(surfaces) {
                        LightScope::All
                    } else {
                        d.surface_scope
                    },
                },
                direct: d.color * d.intensity,
                ambient: d.color * d.ambient_intensity,
                carried: false,
            }),
            _ => {}
        }
    }
    if headlight != Headlight::Off {
        out.push(LightSource {
            kind: LightKind::Directional {
                to_light: -view,
                scope: LightScope::All,
                surface_scope: LightScope::All,
            },
            direct: DVec3::ONE,
            ambient: DVec3::ZERO,
            carried: headlight == Headlight::Carried,
        });
    }
    out
}
