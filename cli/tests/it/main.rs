//! The `gtsphere` binary's tests: one integration-test binary of named modules, each running
//! the command as a user does (the library's own tests are in the project's tests/it/).

mod cli_bench;
mod cli_convert;
mod cli_render;
mod support;
