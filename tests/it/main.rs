//! One integration-test binary of named modules.

mod corpus;
mod corpus_counts;
mod errors;
mod geom;
mod lexical;
mod output;
mod regression;
mod roundtrip;
mod semantics;
mod support;
mod vmd;
