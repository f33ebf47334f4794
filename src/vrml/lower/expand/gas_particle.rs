//! `GasParticle`: how a VRML97 scene gives a gas sphere a density profile (docs/model.md section
//! 6) and stays a file that every other viewer shows as a translucent sphere. A PROTO named
//! `GasParticle` with a `field SFString profile` (and optionally `field SFFloat width`) is
//! recognised by that name and signature, the way VMD's `VMDMat` appearances are; its body is
//! an ordinary Transform/Shape/Sphere, lowered as any PROTO body is, and every Material lowered
//! inside an instance takes the instance's profile:
//!
//! ```text
//! PROTO GasParticle [
//!   field SFVec3f position 0 0 0  field SFFloat radius 1  field SFColor color 0.8 0.8 0.8
//!   field SFColor emission 0 0 0  field SFFloat transparency 0.5
//!   field SFString profile "constant"  field SFFloat width 0.3333333333333333
//! ] { Transform { translation IS position children Shape { appearance Appearance {
//!     material Material { diffuseColor IS color emissiveColor IS emission
//!     transparency IS transparency } } geometry Sphere { radius IS radius } } } }
//! GasParticle { position 1 2 3 radius 0.5 transparency 0.2 profile "gaussian" width 0.25 }
//! ```
//!
//! An unknown profile name or a width outside (0, 1] is an error at the field that gives it
//! (the instance's, or the interface default's); a width given to a profile other than
//! gaussian is a warning (the width is ignored).

use std::ops::Range;

use super::proto::{GasFields, ProtoDecl};
use super::record::Rec;
use super::Expander;
use crate::error::Error;
use crate::scene::profile::{Profile, ProfileError};
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema::{Access, FieldType};
use crate::vrml::syntax::{OwnedEvent, OwnedValue};

/// The PROTO name that carries a profile.
pub(in crate::vrml::lower) const NAME: &str = "GasParticle";

/// A PROTO's profile fields, if it is a `GasParticle`.
pub(in crate::vrml::lower) fn recognise(decl: &ProtoDecl) -> Option<GasFields> {
    if &*decl.name != NAME {
        return None;
    }
    let field = |name: &str, ty: FieldType| {
        decl.fields.iter().position(|f| {
            &*f.name == name
                && f.ty == ty
                && matches!(f.access, Access::Field | Access::ExposedField)
        })
    };
    Some(GasFields {
        profile: field("profile", FieldType::SFString)?,
        width: field("width", FieldType::SFFloat),
    })
}

impl Expander {
    /// The profile an instance of a `GasParticle` gives (`values`: its values by interface
    /// field, as `instance` found them).
    pub(in crate::vrml::lower) fn instance_profile(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        proto: &ProtoDecl,
        gas: GasFields,
        values: &[Option<Range<usize>>],
        at: Pos,
    ) -> Result<Profile, Error> {
        // A value: the instance's, or the interface default; with its position.
        let value = |fi: usize| -> Option<(&OwnedValue, Pos, bool)> {
            let (range, given) = match values.get(fi).cloned().flatten() {
                Some(r) => (r, true),
                None => (proto.fields[fi].default.clone()?, false),
            };
            match self.rec.arena.get(range.start)? {
                Rec::Ev(OwnedEvent::Field { value, at, .. }) => Some((value, *at, given)),
                _ => None,
            }
        };
        let (name, name_at) = match value(gas.profile) {
            Some((OwnedValue::Strings { values, .. }, vat, _)) if values.len() == 1 => {
                (values[0].clone(), vat)
            }
            _ => ("constant".to_string(), at),
        };
        let width = gas
            .width
            .and_then(value)
            .and_then(|(v, vat, given)| match v {
                OwnedValue::Numbers { values, .. } if values.len() == 1 => {
                    Some((values[0], vat, given))
                }
                _ => None,
            });
        let (profile, ignored) =
            Profile::parse_beside(&name, width.map(|(v, _, _)| v)).map_err(|e| {
                let at = match (&e, width) {
                    (ProfileError::Width(_), Some((_, wat, _))) => wat,
                    _ => name_at,
                };
                cx.diags.error(src, at, format!("{NAME}: {e}"))
            })?;
        // (A width the PROTO's default gives is no one's mistake.)
        if let (Some(_), Some((_, wat, true))) = (ignored, width) {
            cx.diags.warn(
                src,
                wat,
                format!("{NAME} width applies to the gaussian profile only: ignored"),
            );
        }
        Ok(profile)
    }
}
