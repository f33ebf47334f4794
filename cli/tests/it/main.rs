//! The `gtsphere` binary's tests: one integration-test binary of named modules, each running
//! the command as a user does (the library's own tests are in the project's tests/it/).

mod cli_ao; // `render --integrator ao`, `occlusion`: fractions, tables, refusals
mod cli_ao_methods; // `render --integrator ao --ao-method`: every method renders, compares; option errors
mod cli_bench; // `bench --quick`, `bench gas --scaling --quick`: reports, ratios, written clouds
mod cli_compare; // `compare`: hand-checked metrics, the heat map, `--max-rmse` exit codes
mod cli_convert; // `convert`: scenes and tables to VRML, exit codes, gzip, pipes, the sample
mod cli_fov; // `render --fov-across` on PyMOL exports: framing against a closed form, notes
mod cli_render; // `render`, `merge`: defaults, formats and AOVs, errors, framing, --as-gas, tiles
mod cli_signals; // SIGINT and SIGTERM while rendering and writing; stale temporary files
mod support; // helpers: run the binary, scratch directories, sample paths
