//! SIGINT and SIGTERM stop `gtsphere render` with 130 and 143 and no temporary file, while it
//! renders and while it writes; temporary files of processes that are gone are removed at the
//! next write to the same name, those of live ones stay.
#![cfg(target_os = "linux")]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How long any one step may take before the test fails: generous for a loaded machine.
const PATIENCE: Duration = Duration::from_secs(120);

fn scratch(name: &str) -> std::path::PathBuf {
    crate::support::scratch("cli_signals", name)
}

/// The names in `dir` that are temporary files of `out.png`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".out.png.tmp."))
        .collect()
}

/// Sends `signal` (`INT`, `TERM`) to `child` with kill(1).
fn send(signal: &str, child: &Child) {
    let status = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .expect("run kill");
    assert!(status.success(), "kill -s {signal} failed");
}

/// Waits for `child` to exit, killing it and failing after [`PATIENCE`].
fn wait(child: &mut Child) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > PATIENCE {
            let _ = child.kill();
            panic!("gtsphere did not exit within {PATIENCE:?} of the signal");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// `gtsphere render` of the cluster sample to `out.png` in `dir`, stderr piped.
fn render(dir: &Path, size: &str, spp: &str, env: Option<(&str, &Path)>) -> Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_gtsphere"));
    cmd.args([
        "render",
        &crate::support::sample("cluster.wrl"),
        "-o",
        "out.png",
    ])
    .args(["--width", size, "--height", size, "--spp", spp])
    .current_dir(dir)
    .stdin(Stdio::null())
    .stdout(Stdio::null())
    .stderr(Stdio::piped());
    if let Some((key, value)) = env {
        cmd.env(key, value);
    }
    cmd.spawn().expect("run gtsphere")
}

/// The lines of `child`'s stderr, as they come.
fn stderr_lines(child: &mut Child) -> mpsc::Receiver<String> {
    let (tx, rx) = mpsc::channel();
    let err = child.stderr.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(err).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

/// A signal while the tiles are being traced (after the "rendering N tiles" line of a render
/// that takes minutes) stops it with `code`, the message naming the signal, and no file.
fn signal_while_rendering(name: &str, signal: &str, code: i32) {
    let dir = scratch(name);
    let mut child = render(&dir, "2000", "1024", None);
    let lines = stderr_lines(&mut child);
    let start = Instant::now();
    loop {
        let left = PATIENCE.saturating_sub(start.elapsed());
        match lines.recv_timeout(left) {
            Ok(line) if line.starts_with("rendering ") => break,
            Ok(_) => {}
            Err(e) => {
                let _ = child.kill();
                panic!("no 'rendering' line from gtsphere: {e}");
            }
        }
    }
    send(signal, &child);
    let status = wait(&mut child);
    let said: Vec<String> = lines.try_iter().collect();
    assert_eq!(status.code(), Some(code), "{status:?}; {said:?}");
    assert!(
        said.iter().any(|l| l.contains(&format!("SIG{signal}"))),
        "{said:?}"
    );
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
    assert!(!dir.join("out.png").exists());
}

/// A signal while the output is written (the test hook holds the write after its temporary
/// file is complete, before the rename) removes that file and exits with `code`.
fn signal_while_writing(name: &str, signal: &str, code: i32) {
    let dir = scratch(name);
    let flag = dir.join("paused");
    let hook = ("GTSPHERE_TEST_PAUSE_BEFORE_RENAME", flag.as_path());
    let mut child = render(&dir, "32", "1", Some(hook));
    let lines = stderr_lines(&mut child);
    let start = Instant::now();
    while !flag.exists() {
        if start.elapsed() > PATIENCE || child.try_wait().unwrap().is_some() {
            let _ = child.kill();
            let said: Vec<String> = lines.try_iter().collect();
            panic!("gtsphere never paused before the rename: {said:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let temp = format!(".out.png.tmp.{}", child.id());
    assert_eq!(temporaries(&dir), [temp]);
    send(signal, &child);
    let status = wait(&mut child);
    let said: Vec<String> = lines.try_iter().collect();
    assert_eq!(status.code(), Some(code), "{status:?}; {said:?}");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
    assert!(!dir.join("out.png").exists());
}

#[test]
fn sigint_while_rendering_exits_130_and_leaves_no_file() {
    signal_while_rendering("int_rendering", "INT", 130);
}

#[test]
fn sigterm_while_rendering_exits_143_and_leaves_no_file() {
    signal_while_rendering("term_rendering", "TERM", 143);
}

#[test]
fn sigint_while_writing_exits_130_and_removes_the_temporary_file() {
    signal_while_writing("int_writing", "INT", 130);
}

#[test]
fn sigterm_while_writing_exits_143_and_removes_the_temporary_file() {
    signal_while_writing("term_writing", "TERM", 143);
}

/// The write goes on when the test hook lets it: the output is whole and nothing else is left.
#[test]
fn a_paused_write_completes_when_let_go() {
    let dir = scratch("let_go");
    let flag = dir.join("paused");
    let hook = ("GTSPHERE_TEST_PAUSE_BEFORE_RENAME", flag.as_path());
    let mut child = render(&dir, "32", "1", Some(hook));
    let _lines = stderr_lines(&mut child);
    let start = Instant::now();
    while !flag.exists() {
        assert!(start.elapsed() < PATIENCE, "gtsphere never paused");
        std::thread::sleep(Duration::from_millis(10));
    }
    std::fs::remove_file(&flag).unwrap();
    assert!(wait(&mut child).success());
    assert!(temporaries(&dir).is_empty());
    assert!(dir.join("out.png").is_file());
}

/// `.out.png.tmp.PID` and `.out.png.tmp.PID.N` of processes that no longer exist go at the
/// next write of out.png; those of a live process, and other names, stay.
#[test]
fn stale_temporary_files_of_gone_processes_are_removed() {
    let dir = scratch("stale");
    let pid_max: u64 = std::fs::read_to_string("/proc/sys/kernel/pid_max")
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    // No process has an id above pid_max; `true` has exited once waited for.
    let mut exited = Command::new("true").spawn().unwrap();
    exited.wait().unwrap();
    let live = std::process::id();
    let gone = [
        format!(".out.png.tmp.{}", pid_max + 1),
        format!(".out.png.tmp.{}.2", pid_max + 7),
        format!(".out.png.tmp.{}", exited.id()),
    ];
    let kept = [
        format!(".out.png.tmp.{live}"),
        format!(".out.png.tmp.{live}.1"),
        format!(".other.png.tmp.{}", pid_max + 1),
        format!(".out.png.tmp.{}.old", pid_max + 1),
    ];
    for name in gone.iter().chain(&kept) {
        std::fs::write(dir.join(name), b"partial").unwrap();
    }
    let out = crate::support::gtsphere(
        &[
            "render",
            &crate::support::sample("cluster.wrl"),
            "-o",
            "out.png",
        ]
        .into_iter()
        .chain(["--width", "32", "--height", "32", "--spp", "1"])
        .collect::<Vec<_>>(),
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("out.png").is_file());
    for name in &gone {
        assert!(!dir.join(name).exists(), "{name} is left");
    }
    for name in &kept {
        assert!(dir.join(name).exists(), "{name} was removed");
    }
}
