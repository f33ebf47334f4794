//! One integration-test binary of named modules: the library's tests (the `gtsphere`
//! binary's are in cli/tests/it/).

mod api; // scenes from arrays and validate, cameras, one prepared scene many cameras, cancel
mod bvh; // the BVH's closest, any and all hits against a brute-force loop over every sphere
mod coincident; // opaque copies in one place drawn once, coincident gas adding up
mod convert_csv; // particle tables to VRML: dialects, columns, bad rows, table -> VRML -> IR
mod corpus; // every ../shared/corpus file reads or fails with a positioned error
mod corpus_counts; // the hand-counted expectations of corpus files (data for `corpus`)
mod depth_limits; // recursion bounds (USE, PROTO, Inline) at the bound and just past it
mod errors; // each error and warning: message and line:col, exactly
mod expansion; // USE, PROTO, IS, mesh and gzip blow-ups refused at the construct, before the copies
mod extern_proto; // EXTERNPROTO from local files: by name or first, defaults, urls, cycles, depth
mod gas_accuracy; // the exact cases of ../shared/cases/gas-accuracy as regression tests
mod gas_mc; // the Monte Carlo integrator: standard errors honest, agrees with exact
mod gas_particle; // GasParticle PROTO: profiles on materials, positioned errors, prepare refuses profiled gas
mod gas_reference; // the brute-force gas reference the gas tests share (and its own checks)
mod gas_scatter; // exact single scattering against the brute-force reference
mod gas_truncation; // exact: truncation bounds and error estimates against the reference
mod geom; // f64 ray/sphere and ray/ellipsoid math against exact and brute-force oracles
mod hard_cases; // numerical hard cases: tiny, huge, far, tangent, coincident
mod headlight; // the headlight carried by the viewer (no shadows, through the gas in front) and strict
mod internals_doc; // docs/internals.md's table of modules is the modules' own first sentences
mod lexical; // VRML97 lexical corners, gzip, invalid UTF-8, items longer than the window
mod light_grid; // the lights' grids: candidates hold every sphere a band meets, and prune
mod mesh_glyphs; // merged sphere glyphs, points as particles, Box/Cylinder/Cone as surfaces
mod mesh_spheres; // IndexedFaceSets on a sphere become that sphere; other meshes are skipped
mod module_cycles; // the library's modules depend on each other one way
mod output; // PNG, EXR, PFM bytes against independent readers; the atomic write
mod parallel_read; // reading in pieces on several threads gives one reader's scene, warnings and errors
mod profile_chords; // density profiles' closed-form optical depth against independent quadrature
mod profiled_gas; // gas with density profiles: closed forms, tolerance, error estimates, mc, against the reference
mod profiled_reference; // the brute-force reference for profiled gas (numerical density integrals) and its own checks
mod proto_template; // PROTO instances lowered by a compiled sphere template equal the body's replay
mod regression; // inputs that once broke an invariant, named after what they guard
mod render_gas; // gas emission and absorption against closed forms
mod render_limits; // sizes beyond the memory refused before allocating; cancelled renders stop
mod render_opaque; // opaque spheres against the VRML97 lighting equation in closed form
mod render_surfaces; // cylinders, cones, boxes, triangles against the lighting equation, shadows both ways
mod roundtrip; // property: random scene trees printed as VRML parse back to their IR
mod semantics; // what the IR means: transforms, scopes, Switch, LOD, DEF/USE, PROTO
mod shadow_query; // the shadow-volume query against testing every sphere
mod support; // helpers: load a scene, errors, scratch directories, `Rng` (SplitMix64)
mod surface_bvh; // closest and any hit over mixed primitives against testing every one
mod surface_reference; // the tests' own ray/cylinder, cone, box and triangle
mod verify; // random scenes from the whole model, every integrator against an independent reference
mod vmd; // VMD's PROTO VMDMat colours, against a hand-worked fixture
mod vrml_support; // docs/vrml.md is made of the schema's support tables, and they say what the reader does
mod whole_sphere_nodes;
mod writer; // the VRML writer against the reader; both writers format numbers alike // plain sphere nodes read whole from the text equal their events
