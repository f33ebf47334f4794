//! One integration-test binary of named modules: the library's tests (the `gtsphere`
//! binary's are in cli/tests/it/).

mod api; // scenes from arrays and validate, cameras, one prepared scene many cameras, cancel
mod coincident; // opaque copies in one place drawn once, coincident gas adding up
mod convert_csv; // particle tables to VRML: dialects, columns, bad rows, table -> VRML -> IR
mod corpus; // every ../shared/corpus file reads or fails with a positioned error
mod corpus_counts; // the hand-counted expectations of corpus files (data for `corpus`)
mod depth_limits; // recursion bounds (USE, PROTO, Inline) at the bound and just past it
mod errors; // each error and warning: message and line:col, exactly
mod expansion; // USE, PROTO, IS, mesh and gzip blow-ups refused at the construct, before the copies
mod extern_proto; // EXTERNPROTO from local files: by name or first, defaults, urls, cycles, depth
mod gas_accuracy; // the exact cases of ../shared/cases/gas-accuracy as regression tests
mod gas_particle; // GasParticle PROTO: profiles on materials, positioned errors, prepare refuses profiled gas
#[allow(dead_code)]
#[path = "../../src/render/integrators/tests/gas_reference.rs"]
mod gas_reference; // the brute-force gas reference, compiled from the library's unit tests
mod headlight; // the headlight carried by the viewer (no shadows, through the gas in front) and strict
mod internals_doc; // docs/internals.md's table of modules is the modules' own first sentences
mod lexical; // VRML97 lexical corners, gzip, invalid UTF-8, items longer than the window
mod mesh_glyphs; // merged sphere glyphs, points as particles, Box/Cylinder/Cone as surfaces
mod mesh_spheres; // IndexedFaceSets on a sphere become that sphere; other meshes are skipped
mod module_cycles; // the library's modules depend on each other one way
mod output; // PNG, EXR, PFM bytes against independent readers; the atomic write
mod parallel_read; // reading in pieces on several threads gives one reader's scene, warnings and errors
mod regression; // inputs that once broke an invariant, named after what they guard
mod render_limits; // sizes beyond the memory refused before allocating; cancelled renders stop
mod render_opaque; // opaque spheres against the VRML97 lighting equation in closed form
mod render_surfaces; // cylinders, cones, boxes, triangles against the lighting equation, shadows both ways
mod roundtrip; // property: random scene trees printed as VRML parse back to their IR
mod semantics; // what the IR means: transforms, scopes, Switch, LOD, DEF/USE, PROTO
mod support; // helpers: load a scene, errors, scratch directories, `Rng` (SplitMix64)
mod surface_reference; // the tests' own ray/cylinder, cone, box and triangle
mod verify; // random scenes from the whole model, every integrator against an independent reference
mod vmd; // VMD's PROTO VMDMat colours, against a hand-worked fixture
mod writer; // the VRML writer against the reader: parse(write(ir)) is ir, and renders alike
