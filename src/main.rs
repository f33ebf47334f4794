//! The `gtsphere` command: a thin shell over the library (see `gtsphere --help`).

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = gtsphere::cli::Cli::parse();
    match gtsphere::cli::run(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("{e}");
            ExitCode::from(1)
        }
    }
}
