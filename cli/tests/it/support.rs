//! Helpers shared by the binary's tests.

/// The project's root folder (this crate is `cli/` inside it).
pub fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The path of `samples/NAME` of the project.
pub fn sample(name: &str) -> String {
    root().join("samples").join(name).display().to_string()
}

/// Runs the `gtsphere` binary with `args` in `dir`.
pub fn gtsphere(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_gtsphere"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run gtsphere")
}

/// Runs `cmd` and returns what it printed on stdout; panics with its stderr unless it
/// succeeds.
pub fn stdout_of(cmd: &mut std::process::Command) -> String {
    let out = cmd.output().expect("run gtsphere");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A fresh, empty directory `group/name` under the target dir's test scratch space.
pub fn scratch(group: &str, name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
