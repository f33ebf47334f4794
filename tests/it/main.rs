//! One integration-test binary of named modules: the library's tests (the `gtsphere`
//! binary's are in cli/tests/it/).

mod bvh;
mod convert_csv;
mod corpus;
mod corpus_counts;
mod depth_limits;
mod errors;
mod gas_accuracy;
mod gas_mc;
mod gas_reference;
mod gas_scatter;
mod gas_truncation;
mod geom;
mod hard_cases;
mod lexical;
mod mesh_spheres;
mod output;
mod regression;
mod render_gas;
mod render_opaque;
mod roundtrip;
mod semantics;
mod shadow_query;
mod support;
mod vmd;
mod writer;
