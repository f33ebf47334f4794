use super::*;
use crate::vrml::schema::{Access, FieldSpec};

/// Whether `access` is that of an event (a member that takes no value in a file).
fn is_event(access: Access) -> bool {
    matches!(access, Access::EventIn | Access::EventOut)
}

/// Every member of `spec` paired with its entry in `n`, or why they differ.
fn check_node(n: &NodeSupport, spec: &NodeSpec) -> Result<(), String> {
    let who = n.name;
    if n.name != spec.name {
        return Err(format!("{who} stands where NODES has {}", spec.name));
    }
    if n.role == NodeRole::Skipped {
        return match n.fields.is_empty() {
            true => Ok(()),
            false => Err(format!("{who} is skipped but lists fields")),
        };
    }
    let names = |fields: &mut dyn Iterator<Item = &'static str>| fields.collect::<Vec<_>>();
    let listed = names(&mut n.fields.iter().map(|f| f.name));
    let declared = names(&mut spec.fields.iter().map(|f: &FieldSpec| f.name));
    if listed != declared {
        return Err(format!(
            "{who} lists {listed:?}, its interface declares {declared:?}"
        ));
    }
    for (f, s) in n.fields.iter().zip(spec.fields) {
        let at = format!("{who}.{}", f.name);
        if (f.role == FieldRole::Event) != is_event(s.access) {
            return Err(format!("{at}: an event exactly when its access is one"));
        }
        if f.default.is_empty() != is_event(s.access) {
            return Err(format!("{at}: a default exactly when it is not an event"));
        }
        if s.ty.is_node() && !is_event(s.access) {
            let want = if s.ty.is_mf() { "[]" } else { "NULL" };
            if f.default != want {
                return Err(format!("{at}: the default of a {} is {want}", s.ty.name()));
            }
        }
        if n.role == NodeRole::Used && f.role == FieldRole::NotRead {
            return Err(format!("{at}: the fields of a Used node are all read"));
        }
        if n.role != NodeRole::Used && f.role == FieldRole::Ignored {
            return Err(format!(
                "{at}: a lenient node's fields are used or not read"
            ));
        }
    }
    Ok(())
}

#[test]
fn every_node_and_member_is_classified() {
    assert_eq!(SUPPORT.len(), NODES.len());
    for (n, spec) in SUPPORT.iter().zip(NODES) {
        if let Err(e) = check_node(n, spec) {
            panic!("{e}");
        }
    }
}

#[test]
fn the_kinds_are_the_reader_s() {
    let of = |role| -> Vec<&str> {
        SUPPORT
            .iter()
            .filter(|n| n.role == role)
            .map(|n| n.name)
            .collect()
    };
    // The lowering models 25 node types (`lower::build::node`): these and the mesh parts.
    assert_eq!(of(NodeRole::Used).len() + of(NodeRole::Mesh).len() + 1, 25);
    assert_eq!(
        of(NodeRole::Mesh),
        ["ElevationGrid", "Extrusion", "IndexedFaceSet", "PointSet"]
    );
    assert_eq!(of(NodeRole::MeshPart), ["Color", "Coordinate", "Normal"]);
    assert_eq!(of(NodeRole::Skipped).len(), 29 - 2);
}

#[test]
fn lookups_answer_for_every_member() {
    for spec in NODES {
        let n = node_support(spec.name).unwrap();
        assert!(std::ptr::eq(n.spec().unwrap(), spec));
        for s in spec.fields {
            assert!(n.field_role(s.name).is_some(), "{}.{}", spec.name, s.name);
        }
        assert_eq!(n.field_role("noSuchField"), None);
    }
    assert!(node_support("Separator").is_none());
    let t = node_support("Transform").unwrap();
    assert_eq!(t.field_role("translation"), Some(FieldRole::Used));
    assert_eq!(t.field_role("bboxSize"), Some(FieldRole::Ignored));
    assert_eq!(t.field_role("addChildren"), Some(FieldRole::Event));
    let text = node_support("Text").unwrap();
    assert_eq!(text.field_role("string"), Some(FieldRole::NotRead));
}

#[test]
fn the_text_keeps_the_tables_whole() {
    // A `|` would split a table cell; a line break would end the row.
    for n in SUPPORT {
        assert!(!n.summary.contains(['|', '\n']), "{}", n.name);
        assert!(n.summary.ends_with('.'), "{}", n.name);
        for f in n.fields {
            assert!(
                !f.default.contains(['|', '\n', '`']),
                "{}.{}",
                n.name,
                f.name
            );
            assert!(!f.note.contains(['|', '\n']), "{}.{}", n.name, f.name);
            assert!(f.note.is_empty() || f.note.ends_with('.'), "{}", f.name);
        }
    }
}

#[test]
fn the_page_has_every_node_and_member() {
    let page = support_markdown();
    for spec in NODES {
        assert!(
            page.contains(&format!("\n### {}\n", spec.name)),
            "{}",
            spec.name
        );
        for s in spec.fields {
            let row = format!(
                "| `{}` | {} | {} |",
                s.name,
                s.access.keyword(),
                s.ty.name()
            );
            assert!(page.contains(&row), "{}.{}", spec.name, s.name);
        }
    }
    assert!(page.ends_with("|\n"));
}
