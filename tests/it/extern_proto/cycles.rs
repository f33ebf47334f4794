//! Files that name themselves or each other: their PROTO declarations are read again, and
//! only a declaration that needs itself is a cycle.

use super::{error, folder, headlines, load, write};

#[test]
fn a_declaration_that_needs_itself_is_a_positioned_error() {
    let dir = folder("self_cycle");
    // The message, at the EXTERNPROTO on line 2 of `file`.
    let needs_itself = |file: &std::path::Path| {
        format!(
            "{}:2:1: EXTERNPROTO P: 'a.wrl#P' names an EXTERNPROTO that needs a file whose \
             PROTOs are being read: it needs itself (a cycle)",
            file.display()
        )
    };
    let a = write(&dir, "a.wrl", "EXTERNPROTO P [ ] \"a.wrl#P\"\nP { }\n");
    assert_eq!(error(&a), needs_itself(&a));
    // The same through another file: b's P needs a's P, which is b's.
    let a = write(&dir, "a.wrl", "EXTERNPROTO P [ ] \"b.wrl#P\"\nP { }\n");
    let b = write(&dir, "b.wrl", "EXTERNPROTO P [ ] \"a.wrl#P\"\n");
    assert_eq!(error(&a), needs_itself(&b));
}

/// A file may name its own PROTOs (`own.wrl#Ball` inside own.wrl), as FreeWRL's tests do:
/// only its PROTO declarations are read again, not its scene.
#[test]
fn a_file_may_name_its_own_protos() {
    let dir = folder("own");
    let own = write(
        &dir,
        "own.wrl",
        "EXTERNPROTO Ball2 [ field SFFloat r ] \"own.wrl#Ball\"\n\
         PROTO Ball [ field SFFloat r 1 ] { Shape { geometry Sphere { radius IS r } } }\n\
         Ball2 { r 2 }\nBall { r 0.5 }\n",
    );
    let (s, r) = load(&own);
    let radii: Vec<f64> = s.spheres.iter().map(|s| s.radius).collect();
    assert_eq!(radii, vec![2.0, 0.5]);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
}

#[test]
fn files_that_name_each_others_protos_read_when_no_declaration_needs_itself() {
    let dir = folder("cycle");
    // a's P is b's P, whose body is a's Q: each file names the other, no PROTO needs itself.
    let a = write(
        &dir,
        "a.wrl",
        "PROTO Q [ ] { Shape { geometry Sphere { radius 3 } } }\nEXTERNPROTO P [ ] \"b.wrl#P\"\nP { }\n",
    );
    write(
        &dir,
        "b.wrl",
        "\nEXTERNPROTO Q [ ] \"a.wrl#Q\"\nPROTO P [ ] { Q { } }\n",
    );
    let (s, r) = load(&a);
    assert_eq!(s.spheres.len(), 1);
    assert_eq!(s.spheres[0].radius, 3.0);
    assert!(r.warnings.is_empty(), "{:?}", headlines(&r));
}
