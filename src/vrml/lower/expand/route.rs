//! ROUTE statements. Events are not simulated (the scene is one still frame), but a ROUTE is
//! still checked so that a mistyped one is reported: both ends must name DEF'd nodes, the
//! source field must be an eventOut or exposedField and the destination an eventIn or
//! exposedField of the node (or of the PROTO it instantiates), and the two types must be the
//! same. Script nodes declare their own interface and are not checked. Every problem is a
//! warning, not an error.

use super::Expander;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema::{self, Access, FieldType};

impl Expander {
    /// Checks a ROUTE: both nodes are DEF'd, the source is an eventOut (or exposedField) and
    /// the destination an eventIn (or exposedField) of the same type. Problems are warnings.
    // (Its own arguments, and the context and builder lent to the expander.)
    #[allow(clippy::too_many_arguments)]
    pub(in crate::vrml::lower) fn check_route(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        from: &str,
        ff: &str,
        to: &str,
        tf: &str,
        at: Pos,
    ) {
        let mut end =
            |this: &mut Self, node: &str, field: &str, want_out: bool| -> Option<FieldType> {
                let Some(d) = this.lookup_def(node) else {
                    cx.diags
                        .warn(src, at, format!("ROUTE refers to undefined node '{node}'"));
                    return None;
                };
                let ty = d.ty.clone();
                let found = if let Some(p) = this.scopes.proto(&ty) {
                    p.event(field).map(|(f, a)| (f.ty, a))
                } else if let Some(spec) = schema::node_spec(&ty) {
                    if &*ty == "Script" {
                        return None;
                    }
                    spec.event(field).map(|(f, a)| (f.ty, a))
                } else {
                    return None;
                };
                let Some((fty, access)) = found else {
                    cx.diags.warn(
                        src,
                        at,
                        format!("ROUTE: {ty} '{node}' has no event '{field}'"),
                    );
                    return None;
                };
                let ok = if want_out {
                    matches!(access, Access::EventOut | Access::ExposedField)
                } else {
                    matches!(access, Access::EventIn | Access::ExposedField)
                };
                if !ok {
                    let want = if want_out {
                        "an eventOut"
                    } else {
                        "an eventIn"
                    };
                    cx.diags
                        .warn(src, at, format!("ROUTE: '{node}.{field}' is not {want}"));
                    return None;
                }
                Some(fty)
            };
        let a = end(self, from, ff, true);
        let b = end(self, to, tf, false);
        if let (Some(a), Some(b)) = (a, b) {
            if a != b {
                cx.diags.warn(
                    src,
                    at,
                    format!("ROUTE from {} to {}: the types differ", a.name(), b.name()),
                );
            }
        }
    }
}
