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

/// `../shared/SUB` beside the checkout (`corpus`, the VRML corpus), or `None` when it is not
/// there (the test then returns early, saying so on stderr). Under `CI` (set to anything but
/// `false` or `0`) a missing folder fails the test instead.
pub fn shared(sub: &str) -> Option<std::path::PathBuf> {
    // cli/ is in the checkout, and shared/ beside the checkout.
    let checkout = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("cli/ is inside the checkout");
    let beside = checkout.parent().unwrap_or(checkout).join("shared");
    let path = beside.join(sub);
    if path.exists() {
        return Some(path);
    }
    let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
    assert!(
        !ci,
        "{} is missing: the corpus must be beside the checkout, and under CI=true its \
         absence is a failure",
        path.display()
    );
    eprintln!("{} is missing: test skipped", path.display());
    None
}
