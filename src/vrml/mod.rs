//! VRML97: lexer, streaming parser, node field tables, and lowering to the scene IR.

pub(crate) mod cut_file;
pub mod lex;
pub mod lower;
pub mod number;
pub(crate) mod parse;
pub mod schema;
pub(crate) mod sphere_node;
pub(crate) mod split;
pub(crate) mod syntax;
pub mod write;

pub use lower::{load_bytes, load_path, load_str, LoadOptions, LoadReport};
