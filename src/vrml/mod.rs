//! VRML97: scenes read into the scene IR ([`load_path`], [`load_bytes`], [`load_str`]) and
//! written back ([`write_scene`]), by a lexer, a streaming parser, node field tables and the
//! lowering to the IR.

pub(crate) mod cut_file;
pub(crate) mod lex;
pub(crate) mod lower;
pub(crate) mod number;
pub(crate) mod parse;
pub(crate) mod schema;
pub(crate) mod sphere_node;
pub(crate) mod split;
pub(crate) mod syntax;
pub(crate) mod write;

pub use lower::{
    load_bytes, load_path, load_str, LoadOptions, LoadReport, DEFAULT_EXPANSION_BASE,
    DEFAULT_MAX_EXPANSION,
};
pub use write::{write_scene, write_scene_file};

#[cfg(test)]
mod tests;
