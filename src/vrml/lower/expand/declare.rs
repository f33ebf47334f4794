//! PROTO declarations. A PROTO or EXTERNPROTO is recorded as its events while it is read;
//! when its declaration ends it becomes a [`ProtoDecl`]: the interface (access, type, name
//! and the events of each default value, checked against its type, with the USEs in defaults
//! resolved), and for a PROTO the body's events, checked so that every `IS` names an
//! interface field of the same type and a compatible access (VRML97 4.8.3, Table 4.4). The
//! body is kept in a form that expands fast: a copy of its events up to the end of its first
//! node, and for each `field IS target` the index of `target` in the interface. An
//! EXTERNPROTO becomes the PROTO it names in a local file (see `extern_proto`) when one of
//! its urls can be read, and stays a declaration without a body otherwise.

use std::ops::Range;
use std::rc::Rc;

use hashbrown::HashMap;

use super::gas_particle;
use super::proto::{InterfaceField, ProtoDecl};
use super::record::{value_end, Rec};
use super::template;
use super::Expander;
use crate::error::Error;
use crate::source::SourceWindow;
use crate::vrml::lower::build::fields::warn_if_event;
use crate::vrml::lower::build::Builder;
use crate::vrml::lower::context::Ctx;
use crate::vrml::schema::{self, Access, FieldType};
use crate::vrml::syntax::{OwnedEvent, OwnedValue};

impl Expander {
    pub(in crate::vrml::lower) fn declare_proto(
        &mut self,
        cx: &mut Ctx,
        b: &mut Builder,
        src: &SourceWindow,
        range: Range<usize>,
    ) -> Result<(), Error> {
        if self.rec.proto_decls > 0 {
            // Nested in another declaration: it is declared when that body is expanded.
            return Ok(());
        }
        let (name, external, at) = match &self.rec.arena[range.start] {
            Rec::Ev(OwnedEvent::ProtoStart { name, external, at }) => {
                (name.clone(), *external, *at)
            }
            _ => return Err(Error::Internal("PROTO recording without its start".into())),
        };
        let mut fields: Vec<InterfaceField> = Vec::new();
        let mut i = range.start + 1;
        let mut body = None;
        while i < range.end {
            match &self.rec.arena[i] {
                Rec::Ev(OwnedEvent::Decl {
                    access,
                    ty,
                    name: fname,
                    at,
                }) => {
                    let access_k = Access::from_keyword(access).ok_or_else(|| {
                        cx.diags
                            .error(src, *at, format!("unknown access type '{access}'"))
                    })?;
                    let fty = FieldType::from_name(ty).ok_or_else(|| {
                        cx.diags
                            .error(src, *at, format!("unknown field type '{ty}'"))
                    })?;
                    let fname = fname.clone();
                    let dat = *at;
                    if fields.iter().any(|f| f.name == fname) {
                        cx.diags
                            .warn(src, dat, format!("PROTO {name} declares '{fname}' twice"));
                    }
                    let mut default = None;
                    if !external && matches!(access_k, Access::Field | Access::ExposedField) {
                        // The value events follow the declaration.
                        let vstart = i + 1;
                        let vend = value_end(&self.rec.arena, vstart);
                        if let Some(Rec::Ev(OwnedEvent::Field { value, at: vat, .. })) =
                            self.rec.arena.get(vstart)
                        {
                            if let Err(e) = schema::check_value(fty, &value.as_value()) {
                                return Err(cx.diags.error(
                                    src,
                                    *vat,
                                    format!("default of '{fname}' {e}"),
                                ));
                            }
                        }
                        self.resolve_default_uses(cx, src, vstart..vend)?;
                        default = Some(vstart..vend);
                        i = vend - 1;
                    }
                    fields.push(InterfaceField {
                        access: access_k,
                        ty: fty,
                        name: fname,
                        default,
                        at: dat,
                    });
                }
                Rec::Ev(OwnedEvent::ProtoBody { .. }) => {
                    body = Some(i + 1..range.end - 1);
                    break;
                }
                _ => {}
            }
            i += 1;
        }
        // exposedField x already defines set_x and x_changed.
        for f in &fields {
            if matches!(f.access, Access::EventIn | Access::EventOut) {
                let base = f
                    .name
                    .strip_prefix("set_")
                    .or_else(|| f.name.strip_suffix("_changed"));
                if let Some(b) = base {
                    if fields
                        .iter()
                        .any(|g| &*g.name == b && g.access == Access::ExposedField)
                    {
                        cx.diags.warn(
                            src,
                            at,
                            format!(
                                "PROTO {name}: '{}' conflicts with exposedField '{b}'",
                                f.name
                            ),
                        );
                    }
                }
            }
        }
        let mut decl = ProtoDecl {
            name: name.clone(),
            fields,
            body,
            body_events: Rc::from([]),
            body_is: Rc::from([]),
            first_end: 0,
            sphere: None,
            gas: None,
            public: None,
            home: None,
        };
        if let Some(b) = decl.body.clone() {
            self.check_body(cx, src, &decl, b.clone())?;
            decl.body_events = self.rec.arena[b].into();
            let mut is = Vec::with_capacity(decl.body_events.len());
            let (mut depth, mut protos) = (0i32, 0i32);
            decl.first_end = decl.body_events.len();
            for (k, r) in decl.body_events.iter().enumerate() {
                let mut first_done = false;
                let mut index = u32::MAX;
                match r {
                    Rec::Ev(OwnedEvent::ProtoStart { .. }) => protos += 1,
                    Rec::Ev(OwnedEvent::ProtoEnd { .. }) => protos -= 1,
                    Rec::Ev(OwnedEvent::NodeStart { .. }) if protos == 0 => depth += 1,
                    Rec::Ev(OwnedEvent::NodeEnd { .. }) if protos == 0 => {
                        depth -= 1;
                        first_done = depth == 0;
                    }
                    Rec::Ev(OwnedEvent::Field {
                        value: OwnedValue::Is(t),
                        ..
                    }) if protos == 0 => {
                        index = decl
                            .field_index(t)
                            .and_then(|i| u32::try_from(i).ok())
                            .unwrap_or(u32::MAX);
                    }
                    // A USE as the body's first node.
                    Rec::Used { .. } => first_done = protos == 0 && depth == 0,
                    _ => {}
                }
                is.push(index);
                if first_done {
                    decl.first_end = k + 1;
                    break;
                }
            }
            decl.body_is = is.into();
            decl.sphere = template::compile(&decl).map(Rc::new);
            decl.gas = gas_particle::recognise(&decl);
        }
        if external {
            // The PROTO it names in a local file, if one of its urls leads to one.
            let urls = match self.rec.arena.get(range.end - 1) {
                Some(Rec::Ev(OwnedEvent::ProtoEnd { urls, .. })) => urls.clone(),
                _ => Rc::from([]),
            };
            if let Some(imported) = self.import_proto(cx, b, src, &name, &decl.fields, &urls, at)? {
                decl = imported;
            }
        } else {
            self.externs.declared(&name);
        }
        let decl = Rc::new(decl);
        self.rec.pinned = self.rec.pinned.max(range.end);
        let standard_name = schema::node_index(&name).is_some();
        if self.scopes.depth() == 1 {
            if let Some(w) = &mut self.watch {
                w.declared = true;
            }
        }
        self.scopes.declare(name, decl, standard_name);
        Ok(())
    }

    /// Resolves the USEs in an interface default value: a DEF earlier in the same value, or a
    /// DEF of the enclosing file made before the declaration. Each default is a namespace of its
    /// own, so a USE of a DEF in another field's default is an error (OpenVRML's test suite).
    fn resolve_default_uses(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        range: Range<usize>,
    ) -> Result<(), Error> {
        let mut open: Vec<(Option<Rc<str>>, usize)> = Vec::new();
        let mut local: HashMap<Rc<str>, Range<usize>> = HashMap::new();
        let mut protos = 0;
        for i in range {
            let Rec::Ev(ev) = &self.rec.arena[i] else {
                continue;
            };
            match ev {
                OwnedEvent::ProtoStart { .. } => protos += 1,
                OwnedEvent::ProtoEnd { .. } => protos -= 1,
                _ if protos > 0 => {}
                OwnedEvent::NodeStart { def, .. } => open.push((def.clone(), i)),
                OwnedEvent::NodeEnd { .. } => {
                    if let Some((Some(name), start)) = open.pop() {
                        local.insert(name, start..i + 1);
                    }
                }
                OwnedEvent::Use { name, at } => {
                    let (name, at) = (name.clone(), *at);
                    let found = match local.get(&name) {
                        Some(r) => Some(r.clone()),
                        None => self.lookup_def(&name).map(|d| d.range),
                    };
                    match found {
                        Some(r) => self.rec.arena[i] = Rec::Used { range: r, at },
                        None => {
                            let msg =
                                format!("USE of undefined name '{name}' in a PROTO field default");
                            return Err(cx.diags.error(src, at, msg));
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Checks every `IS` in a PROTO body: the interface field exists, and its type and access
    /// fit the body field (VRML97 4.8.3, Table 4.4).
    fn check_body(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        decl: &ProtoDecl,
        body: Range<usize>,
    ) -> Result<(), Error> {
        let mut types: Vec<Rc<str>> = Vec::new();
        let mut proto_depth = 0;
        for i in body {
            let Rec::Ev(ev) = &self.rec.arena[i] else {
                continue;
            };
            match ev {
                OwnedEvent::ProtoStart { .. } => proto_depth += 1,
                OwnedEvent::ProtoEnd { .. } => proto_depth -= 1,
                _ if proto_depth > 0 => {}
                OwnedEvent::NodeStart { ty, .. } => types.push(ty.clone()),
                OwnedEvent::NodeEnd { .. } => {
                    types.pop();
                }
                OwnedEvent::Field {
                    name,
                    at,
                    value: OwnedValue::Is(target),
                } => {
                    let Some(iface) = decl.field(target) else {
                        return Err(cx.diags.error(
                            src,
                            *at,
                            format!(
                                "'IS {target}': PROTO {} has no interface field '{target}'",
                                decl.name
                            ),
                        ));
                    };
                    let Some(node_ty) = types.last() else {
                        continue;
                    };
                    let Some(spec) = schema::node_spec(node_ty) else {
                        continue;
                    };
                    let Some((f, access)) = spec.event(name) else {
                        continue;
                    };
                    if f.ty != iface.ty {
                        return Err(cx.diags.error(
                            src,
                            *at,
                            format!(
                                "'{name} IS {target}': {node_ty}.{name} is {} but interface field '{target}' is {}",
                                f.ty.name(),
                                iface.ty.name()
                            ),
                        ));
                    }
                    let ok = match (iface.access, access) {
                        (Access::ExposedField, a) => a == Access::ExposedField,
                        (Access::Field, a) => matches!(a, Access::Field | Access::ExposedField),
                        (Access::EventIn, a) => matches!(a, Access::EventIn | Access::ExposedField),
                        (Access::EventOut, a) => {
                            matches!(a, Access::EventOut | Access::ExposedField)
                        }
                    };
                    if !ok {
                        cx.diags.warn(
                            src,
                            *at,
                            format!(
                                "'{name} IS {target}': a {} cannot be mapped to an interface {}",
                                access.keyword(),
                                iface.access.keyword()
                            ),
                        );
                    }
                }
                OwnedEvent::Field { name, at, .. } | OwnedEvent::NodesStart { name, at } => {
                    let Some(node_ty) = types.last() else {
                        continue;
                    };
                    let Some(spec) = schema::node_spec(node_ty) else {
                        continue;
                    };
                    if let Some((_, access)) = spec.event(name) {
                        warn_if_event(&mut cx.diags, src, name, node_ty, access, *at);
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }
}
