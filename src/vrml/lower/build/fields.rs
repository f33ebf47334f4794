//! Field values of the open node. A value is looked up in the node's table (an unknown
//! name is a warning; an eventIn or eventOut given a value is one too), typed against the
//! field ([`schema::check_value`]: a mismatch is an error at the value), and then stored in
//! the frame's [`Kind`] where the node is modelled. Node-valued fields push a [`FieldCtx`]
//! so that the nodes inside know where they stand. Values arrive already parsed, so the
//! accessors below only pick numbers out of them (their count was checked).

use std::rc::Rc;

use glam::DVec3;

use super::mesh::mesh_field;
use super::open::Name;
use super::open::{FieldCtx, Frame, Kind, Leaf};
use super::transform::quat;
use super::Builder;
use crate::error::Error;
use crate::geom::shapes::Solid;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::lower::diags::Diags;
use crate::vrml::schema::{self, Access};
use crate::vrml::syntax::Value;

/// Whether a member with this access takes no value in a node (an eventIn or eventOut).
#[inline(always)]
pub(in crate::vrml::lower) fn is_event(access: Access) -> bool {
    matches!(access, Access::EventIn | Access::EventOut)
}

/// Warns when a value is given to an eventIn or eventOut (`name` of node type `ty`).
pub(in crate::vrml::lower) fn warn_if_event(
    diags: &mut Diags,
    src: &SourceWindow,
    name: &str,
    ty: &str,
    access: Access,
    at: Pos,
) {
    if is_event(access) {
        let msg = format!(
            "'{name}' of {ty} is an {}, not a field: ignored",
            access.keyword()
        );
        diags.warn(src, at, msg);
    }
}

fn nums<'a>(v: &Value<'a>) -> &'a [f64] {
    match *v {
        Value::Numbers { values, .. } => values,
        _ => &[],
    }
}
fn vec3(v: &Value) -> DVec3 {
    let n = nums(v);
    DVec3::new(n[0], n[1], n[2])
}
fn num1(v: &Value) -> f64 {
    nums(v)[0]
}
fn bool1(v: &Value) -> bool {
    matches!(v, Value::Bools { values, .. } if values[0])
}
fn rot4(v: &Value) -> [f64; 4] {
    let n = nums(v);
    [n[0], n[1], n[2], n[3]]
}

/// A field of a Box, Cylinder or Cone (VRML97 6.4, 6.12, 6.17): sizes must be positive.
fn solid_field(s: &mut Solid, name: &str, v: &Value) -> Result<(), String> {
    let positive = |what: &str, x: f64| {
        if x > 0.0 && x.is_finite() {
            Ok(x)
        } else {
            Err(format!("{what} must be positive, found {x}"))
        }
    };
    match (s, name) {
        (Solid::Cuboid { half }, "size") => {
            let size = vec3(v);
            for x in size.to_array() {
                positive("Box size", x)?;
            }
            *half = 0.5 * size;
        }
        (Solid::Cylinder { radius, .. }, "radius") => {
            *radius = positive("Cylinder radius", num1(v))?
        }
        (Solid::Cylinder { half_height, .. }, "height") => {
            *half_height = 0.5 * positive("Cylinder height", num1(v))?
        }
        (Solid::Cylinder { bottom, .. }, "bottom") => *bottom = bool1(v),
        (Solid::Cylinder { side, .. }, "side") => *side = bool1(v),
        (Solid::Cylinder { top, .. }, "top") => *top = bool1(v),
        (Solid::Cone { radius, .. }, "bottomRadius") => {
            *radius = positive("Cone bottomRadius", num1(v))?
        }
        (Solid::Cone { half_height, .. }, "height") => {
            *half_height = 0.5 * positive("Cone height", num1(v))?
        }
        (Solid::Cone { side, .. }, "side") => *side = bool1(v),
        (Solid::Cone { bottom, .. }, "bottom") => *bottom = bool1(v),
        _ => {}
    }
    Ok(())
}

impl Builder {
    /// A non-node field value of the innermost open node.
    pub(in crate::vrml::lower) fn field(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        name: &str,
        at: Pos,
        value: Value<'_>,
    ) -> Result<(), Error> {
        if self.open.quiet > 0 {
            return Ok(());
        }
        let Some((f, access)) = self.field_spec(cx, src, name, at) else {
            // (IndexedFaceSet and Coordinate frames have no table: their fields come here.)
            if let Some(Frame {
                kind: k @ (Kind::Mesh(_) | Kind::MeshArray(..)),
                ..
            }) = self.open.frames.last_mut()
            {
                mesh_field(k, name, &value, &mut self.meshes);
            }
            return Ok(());
        };
        if is_event(access) {
            let ty = self.open.open_type();
            warn_if_event(&mut cx.diags, src, name, &ty, access, at);
            return Ok(());
        }
        if f.ty.is_node() {
            if value == Value::Empty {
                return Ok(());
            }
            let ty = self.open.open_type();
            return Err(cx.diags.error(
                src,
                at,
                format!(
                    "field '{name}' of {ty} expects {}, found {}",
                    f.ty.name(),
                    schema::type_name(&value)
                ),
            ));
        }
        if let Err(e) = schema::check_value(f.ty, &value) {
            let ty = self.open.open_type();
            return Err(cx
                .diags
                .error(src, at, format!("field '{name}' of {ty} {e}")));
        }
        self.apply_field(cx, src, f.name, at, &value)
    }

    /// The field table entry for `name` in the innermost open standard node, with the access it
    /// was used with. Unknown names are warned about; nodes without a table (PROTO instances,
    /// unknown types) give None silently.
    #[inline(always)]
    fn field_spec(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        name: &str,
        at: Pos,
    ) -> Option<(&'static schema::FieldSpec, Access)> {
        let frame = self.open.frames.last()?;
        let found = frame.spec?.event(name);
        if found.is_none() {
            let ty = self.open.open_type();
            cx.diags
                .warn(src, at, format!("unknown field '{name}' of {ty}: ignored"));
        }
        found
    }

    /// A node-valued field (SFNode or MFNode) starts: the nodes until its end stand in it.
    pub(in crate::vrml::lower) fn nodes_start(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        name: &str,
        at: Pos,
    ) -> Result<(), Error> {
        let idx = self.open.frames.len().saturating_sub(1);
        let mut known = None;
        if self.open.quiet == 0 {
            if let Some((f, access)) = self.field_spec(cx, src, name, at) {
                known = Some(f.name);
                if !f.ty.is_node() {
                    let ty = self.open.open_type();
                    return Err(cx.diags.error(
                        src,
                        at,
                        format!(
                            "field '{name}' of {ty} expects {}, found a node",
                            f.ty.name()
                        ),
                    ));
                }
                if is_event(access) {
                    let ty = self.open.open_type();
                    warn_if_event(&mut cx.diags, src, name, &ty, access, at);
                }
            }
        }
        // The table's entry is this name unless it was found through a set_/_changed alias
        // (which is longer).
        let name = match known {
            Some(k) if k.len() == name.len() => Name::Static(k),
            _ => Name::Shared(Rc::from(name)),
        };
        self.open.fields.push(FieldCtx { name, frame: idx });
        Ok(())
    }

    /// Stores a checked value in the innermost open frame, where its node is modelled.
    #[inline(always)]
    fn apply_field(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        name: &str,
        at: Pos,
        v: &Value<'_>,
    ) -> Result<(), Error> {
        let frame = self.open.frames.last_mut().expect("open frame");
        let mut problem: Option<String> = None;
        match &mut frame.kind {
            Kind::Group {
                transform: Some(t), ..
            } => match name {
                "translation" => t.translation = vec3(v),
                "rotation" => t.rotation = rot4(v),
                "scale" => t.scale = vec3(v),
                "scaleOrientation" => t.scale_orientation = rot4(v),
                "center" => t.center = vec3(v),
                _ => {}
            },
            Kind::Group {
                inline_urls: Some(u),
                ..
            } if name == "url" => {
                if let Value::Strings { values, .. } = v {
                    *u = Box::from(*values);
                }
            }
            Kind::Switch { which, .. } if name == "whichChoice" => *which = num1(v) as i64,
            Kind::Leaf(Leaf::Material) => {
                let m = self.materials.open.last_mut().expect("open Material");
                // VRML97 keeps every one in [0, 1]. Shininess and transparency outside are
                // clamped (VMD writes its raw Phong exponent, 40, as shininess); a negative
                // colour or intensity is clamped to 0. Each with a warning. (Values above 1
                // are used as given: brighter than VRML97 allows, as the model defines them.)
                let p = &mut problem;
                match name {
                    "diffuseColor" => m.diffuse = colour(name, vec3(v), p),
                    "emissiveColor" => m.emissive = colour(name, vec3(v), p),
                    "specularColor" => m.specular = colour(name, vec3(v), p),
                    "shininess" => m.shininess = unit(name, num1(v), p),
                    "ambientIntensity" => m.ambient_intensity = intensity(name, num1(v), p),
                    "transparency" => m.transparency = unit(name, num1(v), p),
                    _ => {}
                }
            }
            Kind::Leaf(Leaf::Sphere { radius }) if name == "radius" => {
                let r = num1(v);
                if r <= 0.0 || !r.is_finite() {
                    return Err(cx.diags.error(
                        src,
                        at,
                        format!("Sphere radius must be positive, found {r}"),
                    ));
                }
                *radius = r;
            }
            Kind::Leaf(Leaf::Solid(i)) => {
                if let Err(e) = solid_field(&mut self.meshes.solids[*i as usize], name, v) {
                    return Err(cx.diags.error(src, at, e));
                }
            }
            Kind::PointLight(l) => match name {
                "location" => l.location = vec3(v),
                "color" => l.color = colour(name, vec3(v), &mut problem),
                "intensity" => l.intensity = intensity(name, num1(v), &mut problem),
                "ambientIntensity" => l.ambient_intensity = intensity(name, num1(v), &mut problem),
                "attenuation" => l.attenuation = vec3(v),
                "radius" => {
                    l.radius = num1(v);
                    if l.radius < 0.0 {
                        problem = Some("PointLight radius must not be negative".into());
                    }
                }
                "on" => l.on = bool1(v),
                _ => {}
            },
            Kind::DirectionalLight(l) => match name {
                "direction" => l.direction = vec3(v),
                "color" => l.color = colour(name, vec3(v), &mut problem),
                "intensity" => l.intensity = intensity(name, num1(v), &mut problem),
                "ambientIntensity" => l.ambient_intensity = intensity(name, num1(v), &mut problem),
                "on" => l.on = bool1(v),
                _ => {}
            },
            Kind::Viewpoint(vp) => match name {
                "position" => vp.position = vec3(v),
                "orientation" => vp.orientation = quat(rot4(v)),
                "fieldOfView" => {
                    let f = num1(v);
                    if !(f > 0.0 && f < std::f64::consts::PI) {
                        problem = Some(format!("fieldOfView {f} is outside (0, pi): using pi/4"));
                        vp.field_of_view = std::f64::consts::FRAC_PI_4;
                    } else {
                        vp.field_of_view = f;
                    }
                }
                "description" => {
                    if let Value::Strings { values, .. } = v {
                        vp.description = values[0].clone();
                    }
                }
                _ => {}
            },
            Kind::NavigationInfo { headlight } if name == "headlight" => {
                *headlight = Some(bool1(v));
            }
            Kind::Background { sky } if name == "skyColor" => {
                let n = nums(v);
                if n.len() >= 3 {
                    *sky = Some(DVec3::new(n[0], n[1], n[2]));
                }
            }
            _ => {}
        }
        if let Some(p) = problem {
            cx.diags.warn(src, at, p);
        }
        Ok(())
    }
}

/// `x` clamped to [0, 1], VRML97's range for `name`; outside, `problem` says so.
fn unit(name: &str, x: f64, problem: &mut Option<String>) -> f64 {
    if !(0.0..=1.0).contains(&x) {
        *problem = Some(format!("{name} {x} is outside [0, 1]: clamped"));
    }
    x.clamp(0.0, 1.0)
}

/// `x`, or 0 if it is negative (`problem` then says so).
fn intensity(name: &str, x: f64, problem: &mut Option<String>) -> f64 {
    if x < 0.0 {
        *problem = Some(format!("{name} {x} is negative: clamped to 0"));
    }
    x.max(0.0)
}

/// [`intensity`] for each channel of a colour.
fn colour(name: &str, c: DVec3, problem: &mut Option<String>) -> DVec3 {
    if !c.cmpge(DVec3::ZERO).all() {
        *problem = Some(format!(
            "{name} {} {} {} is negative: clamped to 0",
            c.x, c.y, c.z
        ));
    }
    c.max(DVec3::ZERO)
}
