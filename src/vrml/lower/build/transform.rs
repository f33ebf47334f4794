//! The Transform node's matrix and what it moves. A Transform's fields are gathered while it
//! is open ([`TransformFields`]); when it closes, its matrix `T C R SR S -SR -C` (VRML97
//! 6.52) applies to every sphere, light and viewpoint lowered since it opened. Spheres stay
//! spheres under similarities (translation, rotation, reflection, uniform scale) and become
//! ellipsoids otherwise; the common particle case, a Transform that only translates spheres,
//! takes a shortcut that gives bit for bit what the full product gives. Every result is
//! checked for overflow, so no infinity or NaN reaches the scene.

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::Builder;
use crate::error::Error;
use crate::scene::{EllipsoidId, Light, Scene};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;

/// How much of the IR existed when a grouping node opened.
#[derive(Clone, Copy, Debug, Default)]
pub(in crate::vrml::lower) struct Marks {
    pub(in crate::vrml::lower) spheres: usize,
    pub(in crate::vrml::lower) surfaces: usize,
    pub(in crate::vrml::lower) lights: usize,
    pub(in crate::vrml::lower) views: usize,
}

impl Marks {
    pub(in crate::vrml::lower) fn of(scene: &Scene) -> Marks {
        Marks {
            spheres: scene.spheres.len(),
            surfaces: scene.surfaces.len(),
            lights: scene.lights.len(),
            views: scene.viewpoints.len(),
        }
    }
}

/// A Transform's fields, with VRML97 defaults.
#[derive(Debug)]
pub(in crate::vrml::lower) struct TransformFields {
    pub(in crate::vrml::lower) translation: DVec3,
    pub(in crate::vrml::lower) rotation: [f64; 4],
    pub(in crate::vrml::lower) scale: DVec3,
    pub(in crate::vrml::lower) scale_orientation: [f64; 4],
    pub(in crate::vrml::lower) center: DVec3,
}

impl Default for TransformFields {
    fn default() -> Self {
        TransformFields {
            translation: DVec3::ZERO,
            rotation: [0.0, 0.0, 1.0, 0.0],
            scale: DVec3::ONE,
            scale_orientation: [0.0, 0.0, 1.0, 0.0],
            center: DVec3::ZERO,
        }
    }
}

/// The boxes of closed Transforms' fields, reused by the next Transforms (one allocation per
/// nesting level, not per Transform).
#[derive(Default)]
pub(in crate::vrml::lower) struct Transforms {
    #[allow(
        clippy::vec_box,
        reason = "the allocations themselves are what is reused"
    )]
    spare: Vec<Box<TransformFields>>,
}

impl Transforms {
    /// A box of default fields for a Transform that opens.
    pub(in crate::vrml::lower) fn take(&mut self) -> Box<TransformFields> {
        match self.spare.pop() {
            Some(mut t) => {
                *t = TransformFields::default();
                t
            }
            None => Box::default(),
        }
    }

    /// Keeps a closed Transform's box for the next one.
    pub(in crate::vrml::lower) fn give_back(&mut self, t: Box<TransformFields>) {
        self.spare.push(t);
    }
}

/// Axis-angle rotation; a zero axis means no rotation.
pub(in crate::vrml::lower) fn quat(r: [f64; 4]) -> DQuat {
    let axis = DVec3::new(r[0], r[1], r[2]);
    let len = axis.length();
    if len == 0.0 || !len.is_finite() || r[3] == 0.0 {
        DQuat::IDENTITY
    } else {
        DQuat::from_axis_angle(axis / len, r[3])
    }
}

/// For a Transform that only translates (the particle case), the translation of its matrix.
///
/// The full product is then exactly `from_translation(shift)`: its other factors are exact
/// identities, and adding their zero translations turns a -0 component into +0, as `+ 0.0`
/// does.
fn translation_only(t: &TransformFields) -> Option<DVec3> {
    let plain = t.rotation[3] == 0.0
        && t.scale_orientation[3] == 0.0
        && t.scale == DVec3::ONE
        && t.center.to_array().map(f64::to_bits) == [0; 3];
    if !plain {
        return None;
    }
    let shift = t.translation + DVec3::ZERO;
    debug_assert_eq!(
        DAffine3::from_translation(shift)
            .to_cols_array()
            .map(f64::to_bits),
        full_transform_matrix(t).to_cols_array().map(f64::to_bits)
    );
    Some(shift)
}

fn full_transform_matrix(t: &TransformFields) -> DAffine3 {
    // M = T * C * R * SR * S * -SR * -C (VRML97 6.52)
    let sr = quat(t.scale_orientation);
    DAffine3::from_translation(t.translation)
        * DAffine3::from_translation(t.center)
        * DAffine3::from_quat(quat(t.rotation))
        * DAffine3::from_quat(sr)
        * DAffine3::from_scale(t.scale)
        * DAffine3::from_quat(sr.inverse())
        * DAffine3::from_translation(-t.center)
}

/// The uniform scale of a linear map that is a similarity (rotation, reflection, uniform scale).
fn similarity_scale(m: &DMat3) -> Option<f64> {
    let g = m.transpose() * *m;
    let d = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let tol = 1e-12 * d.abs().max(f64::MIN_POSITIVE);
    let off = [g.x_axis.y, g.x_axis.z, g.y_axis.z];
    let diag = [g.x_axis.x, g.y_axis.y, g.z_axis.z];
    if off.iter().all(|o| o.abs() <= tol) && diag.iter().all(|x| (x - d).abs() <= tol) {
        Some(d.sqrt())
    } else {
        None
    }
}

/// The rotation closest to a linear map (for viewpoint orientations under scaled transforms).
fn rotation_part(m: &DMat3) -> DQuat {
    let x = m.x_axis.normalize_or_zero();
    let y0 = m.y_axis - x * x.dot(m.y_axis);
    let y = y0.normalize_or_zero();
    let z = x.cross(y);
    if x == DVec3::ZERO || y == DVec3::ZERO {
        return DQuat::IDENTITY;
    }
    DQuat::from_mat3(&DMat3::from_cols(x, y, z)).normalize()
}

/// A sphere after transforms must still be finite with a positive radius (no overflow to
/// infinity or NaN, no underflow to zero).
fn check_sphere(center: DVec3, radius: f64) -> Result<(), String> {
    if !center.is_finite() {
        return Err(format!("a sphere centre overflow ({center})"));
    }
    if !(radius.is_finite() && radius > 0.0) {
        return Err(format!("a sphere radius overflow or underflow ({radius})"));
    }
    Ok(())
}

impl Builder {
    /// Applies a closing Transform's fields to what was lowered inside it (since `marks`).
    #[inline(always)]
    pub(in crate::vrml::lower) fn close_transform(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        t: &TransformFields,
        marks: Marks,
        at: Pos,
    ) -> Result<(), Error> {
        let shift = translation_only(t);
        if let Some(d) = shift {
            if d.is_finite() && only_plain_spheres_since(&self.scene, marks) {
                // What `apply` does for this case, without building the matrix: see there.
                if d == DVec3::ZERO {
                    return Ok(());
                }
                for s in &mut self.scene.spheres[marks.spheres..] {
                    s.center += d;
                    if let Err(what) = check_sphere(s.center, s.radius) {
                        return Err(cx.diags.error(
                            src,
                            at,
                            format!("this Transform makes {what}"),
                        ));
                    }
                }
                return Ok(());
            }
        }
        let m = match shift {
            Some(s) => DAffine3::from_translation(s),
            None => full_transform_matrix(t),
        };
        if m == DAffine3::IDENTITY {
            return Ok(());
        }
        // (An identity linear part, the translation-only case, has determinant 1.)
        let flat = shift.is_none() && m.matrix3.determinant() == 0.0;
        if !m.is_finite() || flat {
            // A zero scale (or a degenerate scaleOrientation) flattens the contents: not shown.
            cx.diags.warn(
                src,
                at,
                "a Transform with a zero or non-finite scale hides its contents",
            );
            self.scene.spheres.truncate(marks.spheres);
            self.scene.surfaces.truncate(marks.surfaces);
            self.scene.lights.truncate(marks.lights);
            self.scene.viewpoints.truncate(marks.views);
            return Ok(());
        }
        // Each matrix is finite, but their product may not be: check what the contents became.
        apply(&mut self.scene, &m, shift.is_some(), marks).map_err(|what| {
            cx.diags
                .error(src, at, format!("this Transform makes {what}"))
        })
    }
}

/// Whether everything lowered since `marks` is spheres (no ellipsoids, lights or viewpoints).
fn only_plain_spheres_since(scene: &Scene, marks: Marks) -> bool {
    scene.lights.len() == marks.lights
        && scene.viewpoints.len() == marks.views
        && scene.surfaces.len() == marks.surfaces
        && scene.spheres[marks.spheres..]
            .iter()
            .all(|s| s.ellipsoid.is_none())
}

/// Applies `m` to everything lowered since `marks`; says what went out of range, if anything.
///
/// `translation` says the linear part is exactly the identity; a point then moves by
/// `p + t`, which is exactly what the affine map computes (`1*x + 0*y + 0*z + t`: the
/// zero terms can only change the sign of a zero, and adding `t`, which has no -0,
/// gives the same result either way).
fn apply(scene: &mut Scene, m: &DAffine3, translation: bool, marks: Marks) -> Result<(), String> {
    let lin = m.matrix3;
    // similarity_scale of the identity is exactly 1.
    let sim = if translation || lin == DMat3::IDENTITY {
        Some(1.0)
    } else {
        similarity_scale(&lin)
    };
    let max_scale = || {
        lin.x_axis
            .length()
            .max(lin.y_axis.length())
            .max(lin.z_axis.length())
    };
    for i in marks.spheres..scene.spheres.len() {
        let s = &mut scene.spheres[i];
        let id = match s.ellipsoid {
            Some(id) => {
                let e = &mut scene.ellipsoids[id.index()];
                *e = *m * *e;
                id
            }
            None => {
                if let Some(k) = sim {
                    s.center = if translation {
                        s.center + m.translation
                    } else {
                        m.transform_point3(s.center)
                    };
                    s.radius *= k;
                    check_sphere(s.center, s.radius)?;
                    continue;
                }
                let a = *m
                    * DAffine3::from_scale_rotation_translation(
                        DVec3::splat(s.radius),
                        DQuat::IDENTITY,
                        s.center,
                    );
                let id = EllipsoidId::new(scene.ellipsoids.len())
                    .ok_or("more than 2^32 - 1 ellipsoids in one scene")?;
                s.ellipsoid = Some(id);
                scene.ellipsoids.push(a);
                id
            }
        };
        let e = scene.ellipsoids[id.index()];
        s.center = e.translation;
        let l = e.matrix3;
        // A bounding radius: the half extents' length bounds every point of the ellipsoid.
        s.radius = DVec3::new(l.row(0).length(), l.row(1).length(), l.row(2).length()).length();
        check_sphere(s.center, s.radius)?;
        // Rays are intersected in the ellipsoid's object space: the map must be invertible.
        if !e.is_finite() || l.determinant() == 0.0 || !l.determinant().is_finite() {
            return Err("an ellipsoid too thin or too large to represent in f64".into());
        }
    }
    let surfaces = &mut scene.surfaces[marks.surfaces..];
    // (Worked out only when there are surfaces: most Transforms move spheres alone.)
    if !surfaces.is_empty() {
        let mapping = crate::scene::Mapping::new(m);
        for s in surfaces {
            s.transform(&mapping);
            if !s.is_sound() {
                return Err("a surface too thin or too large to represent in f64".into());
            }
        }
    }
    for l in &mut scene.lights[marks.lights..] {
        match l {
            Light::Point(p) => {
                p.location = m.transform_point3(p.location);
                p.radius *= sim.unwrap_or_else(max_scale);
                if !p.location.is_finite() || !p.radius.is_finite() {
                    return Err(format!(
                        "a PointLight overflow (location {}, radius {})",
                        p.location, p.radius
                    ));
                }
            }
            Light::Directional(d) => {
                d.direction = m.transform_vector3(d.direction).normalize_or(d.direction);
            }
        }
    }
    let views = &mut scene.viewpoints[marks.views..];
    if views.is_empty() {
        return Ok(());
    }
    let rot = rotation_part(&lin);
    for v in views {
        v.position = m.transform_point3(v.position);
        v.orientation = (rot * v.orientation).normalize();
        if !v.position.is_finite() {
            return Err(format!("a Viewpoint position overflow ({})", v.position));
        }
    }
    Ok(())
}

// ----- PROTO

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn translation_only_matrix_is_the_full_product() {
        // The translation-only shortcut must agree bit for bit with the full product.
        for t in [
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, -0.0],
            [1.5, -2.25, 1e300],
            [-1e-310, 5e-324, -0.0],
            [f64::MAX, -f64::MAX, 0.1],
        ] {
            let fields = TransformFields {
                translation: DVec3::from_array(t),
                ..TransformFields::default()
            };
            let shift = translation_only(&fields).unwrap();
            let fast = DAffine3::from_translation(shift)
                .to_cols_array()
                .map(f64::to_bits);
            let full = full_transform_matrix(&fields)
                .to_cols_array()
                .map(f64::to_bits);
            assert_eq!(fast, full, "{t:?}");
        }
        let rotated = TransformFields {
            rotation: [0.0, 1.0, 0.0, 0.5],
            ..TransformFields::default()
        };
        assert!(translation_only(&rotated).is_none());
    }

    #[test]
    fn nested_transforms_move_spheres_where_hand_computation_puts_them() {
        // Inside an outer translation (10, 0, 0), applied to all three:
        // - A: a uniform scale 2 about centre (1, 0, 0), a quarter turn about z and a
        //   translation (1, 2, 3), over a sphere of radius 0.5 at (0, 1, 0). The scale is
        //   uniform, so scaleOrientation cannot matter: p - c = (-1, 1, 0), scaled (-2, 2, 0),
        //   turned (-2, -2, 0), plus c and t: (0, 0, 3); radius 1.
        // - B: scale (1, 3, 1) turned by scaleOrientation a quarter turn about z, i.e. scale 3
        //   along x; centre (1, 0, 0); a quarter turn about y; translation (0, 0, -5); over a
        //   sphere of radius 2 at the origin: p - c = (-1, 0, 0), scaled (-3, 0, 0), turned
        //   (0, 0, 3), plus c and t: (1, 0, -2). An ellipsoid with axes R diag(6, 2, 2):
        //   columns (0, 0, -6), (0, 2, 0), (2, 0, 0); bounding radius sqrt(6^2 + 2^2 + 2^2).
        // - C: two nested translations (0.5, 0, 0) and (0, 0.25, 0) of a unit sphere (the
        //   translation-only shortcut).
        let q = std::f64::consts::FRAC_PI_2;
        let text = format!(
            "#VRML V2.0 utf8\n\
             Transform {{ translation 10 0 0 children [\n\
               Transform {{ translation 1 2 3 rotation 0 0 1 {q} scale 2 2 2 center 1 0 0\n\
                 scaleOrientation 1 0 0 0.5\n\
                 children Transform {{ translation 0 1 0\n\
                   children Shape {{ geometry Sphere {{ radius 0.5 }} }} }} }}\n\
               Transform {{ translation 0 0 -5 rotation 0 1 0 {q} scale 1 3 1 center 1 0 0\n\
                 scaleOrientation 0 0 1 {q}\n\
                 children Shape {{ geometry Sphere {{ radius 2 }} }} }}\n\
               Transform {{ translation 0.5 0 0\n\
                 children Transform {{ translation 0 0.25 0 children Shape {{ geometry Sphere {{ }} }} }} }}\n\
             ] }}\n"
        );
        let (scene, _) = crate::vrml::load_str("t.wrl", &text, &Default::default()).unwrap();
        let near = |a: DVec3, b: DVec3| (a - b).abs().max_element() < 1e-12;
        let [a, b, c] = &scene.spheres[..] else {
            panic!("{} spheres", scene.spheres.len());
        };
        assert!(near(a.center, DVec3::new(10.0, 0.0, 3.0)), "{}", a.center);
        assert!((a.radius - 1.0).abs() < 1e-12, "{}", a.radius);
        assert_eq!(a.ellipsoid, None);

        assert!(near(b.center, DVec3::new(11.0, 0.0, -2.0)), "{}", b.center);
        assert!((b.radius - 44f64.sqrt()).abs() < 1e-12, "{}", b.radius);
        let e = scene.ellipsoids[b.ellipsoid.expect("an ellipsoid").index()];
        assert!(near(e.matrix3.x_axis, DVec3::new(0.0, 0.0, -6.0)), "{e}");
        assert!(near(e.matrix3.y_axis, DVec3::new(0.0, 2.0, 0.0)), "{e}");
        assert!(near(e.matrix3.z_axis, DVec3::new(2.0, 0.0, 0.0)), "{e}");
        assert!(near(e.translation, b.center), "{e}");

        // The shortcut adds exactly: 0.5 + 10 and 0.25 are exact in binary.
        assert_eq!(c.center, DVec3::new(10.5, 0.25, 0.0));
        assert_eq!((c.radius, c.ellipsoid), (1.0, None));
    }
}
