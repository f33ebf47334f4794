//! One integration-test binary of named modules.

mod corpus;
mod corpus_counts;
mod errors;
mod lexical;
mod regression;
mod roundtrip;
mod semantics;
mod support;
mod vmd;
