//! `gtsphere convert` as a user runs it: a scene flattened to VRML that reads back the same,
//! exit codes, gzip input, VRML against tables, named pipes, and the sample table (the
//! reader itself is tested in the library's tests/it/convert_csv.rs).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use gtsphere::scene::Scene;
use gtsphere::vrml::LoadOptions;

fn centres(s: &Scene) -> Vec<[f64; 4]> {
    s.spheres
        .iter()
        .map(|p| [p.center.x, p.center.y, p.center.z, p.radius])
        .collect()
}

fn gtsphere(args: &[&str], dir: &Path) -> Output {
    crate::support::gtsphere(args, dir)
}

fn scratch(name: &str) -> PathBuf {
    crate::support::scratch("convert_csv", name)
}

fn load_file(path: &Path) -> Scene {
    gtsphere::vrml::load_path(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

#[test]
fn cli_bad_row_exits_1_and_leaves_no_output() {
    let dir = scratch("bad");
    std::fs::write(
        dir.join("p.csv"),
        "x,y,z,radius\n0,0,0,1\n1,2,zz,1\n2,2,2,1\n",
    )
    .unwrap();
    let out = gtsphere(&["convert", "p.csv", "-o", "p.wrl"], &dir);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("p.csv:3:3: column \"z\": \"zz\" is not a number"),
        "{stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        left,
        vec![std::ffi::OsString::from("p.csv")],
        "no output, no temporary file"
    );
    // An existing output is left as it was.
    std::fs::write(dir.join("p.wrl"), "old").unwrap();
    let out = gtsphere(&["convert", "p.csv", "-o", "p.wrl"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(dir.join("p.wrl")).unwrap(), "old");
    // --skip-bad skips it and says so.
    let out = gtsphere(&["convert", "p.csv", "-o", "p.wrl", "--skip-bad"], &dir);
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("skipped 1 bad row; the first: p.csv:3:3:"),
        "{stderr}"
    );
    assert_eq!(load_file(&dir.join("p.wrl")).spheres.len(), 2);
}

#[test]
fn cli_reads_gzip_and_tells_vrml_from_tables() {
    let dir = scratch("gzip");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(b"x\ty\tz\n1\t2\t3\n4\t5\t6\n").unwrap();
    std::fs::write(dir.join("p.tsv.gz"), gz.finish().unwrap()).unwrap();
    let out = gtsphere(
        &[
            "convert", "p.tsv.gz", "-o", "p.wrl", "--radius", "0.5", "--plain",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = load_file(&dir.join("p.wrl"));
    assert_eq!(
        centres(&s),
        vec![[1.0, 2.0, 3.0, 0.5], [4.0, 5.0, 6.0, 0.5]]
    );
    // VRML input goes to the scene writer; table options are refused there.
    let out = gtsphere(&["convert", "p.wrl", "-o", "q.wrl"], &dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(centres(&load_file(&dir.join("q.wrl"))), centres(&s));
    let out = gtsphere(&["convert", "p.wrl", "-o", "r.wrl", "--radius", "1"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("only apply to particle tables"));
    let out = gtsphere(
        &["convert", "p.tsv.gz", "-o", "r.wrl", "--radius", "-1"],
        &dir,
    );
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn cli_converted_table_renders() {
    let dir = scratch("render");
    let mut table = String::from("x,y,z,radius,red,green,blue\n");
    for k in 0..27 {
        let (i, j, l) = (k % 3, (k / 3) % 3, k / 9);
        table.push_str(&format!(
            "{i},{j},{l},0.4,{},{},{}\n",
            80 * i + 50,
            80 * j + 50,
            80 * l + 50
        ));
    }
    std::fs::write(dir.join("p.csv"), table).unwrap();
    let out = gtsphere(&["convert", "p.csv", "-o", "p.wrl"], &dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = gtsphere(
        &[
            "render", "p.wrl", "-o", "p.png", "--width", "64", "--height", "48", "--spp", "1",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = gtsphere::output::read_image(&dir.join("p.png")).unwrap();
    let lit = img.rgb.iter().filter(|p| p[0] + p[1] + p[2] > 0.05).count();
    let n = img.rgb.len();
    // The framed lattice covers a good part of the picture, and not all of it.
    assert!(lit > n / 10 && lit < n * 9 / 10, "{lit} of {n}");
}

#[test]
fn cli_writes_into_a_named_pipe_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("fifo");
    std::fs::write(dir.join("p.csv"), "x y z\n1 2 3\n").unwrap();
    let fifo = dir.join("out.pipe");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo is not available; skipped");
        return;
    }
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = gtsphere(
        &["convert", "p.csv", "-o", "out.pipe", "--radius", "1"],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = reader.join().unwrap();
    assert!(text.contains("Particle { position 1 2 3 }"), "{text}");
    // Still a pipe: not replaced by a renamed temporary file.
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

/// The sample table converts as docs/gallery.md says: 240 opaque beads and 12 gas spheres.
#[test]
fn sample_table_converts() {
    let dir = scratch("sample");
    let csv = crate::support::sample("particles.csv");
    let out = gtsphere(&["convert", &csv, "-o", "particles.wrl"], &dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = load_file(&dir.join("particles.wrl"));
    assert_eq!(s.spheres.len(), 252);
    assert_eq!(s.gas_count(), 12);
    assert_eq!(s.viewpoints.len(), 1);
}

#[test]
fn convert_writes_vrml_that_reads_back_to_the_same_scene() {
    let dir = scratch("scene_to_vrml");
    let out = gtsphere(
        &[
            "convert",
            &crate::support::sample("lattice.wrl"),
            "-o",
            "flat.wrl",
            "--quiet",
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let opts = gtsphere::vrml::LoadOptions::default();
    let (a, _) =
        gtsphere::vrml::load_path(Path::new(&crate::support::sample("lattice.wrl")), &opts)
            .unwrap();
    let (b, _) = gtsphere::vrml::load_path(&dir.join("flat.wrl"), &opts).unwrap();
    assert_eq!(a.spheres.len(), 125);
    for (s, t) in a.spheres.iter().zip(&b.spheres) {
        assert_eq!((s.center, s.radius), (t.center, t.radius));
        assert_eq!(a.material_of(s), b.material_of(t));
    }
    // A missing input: an error naming it and no output.
    let out = gtsphere(&["convert", "p.csv", "-o", "p.wrl"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("p.csv"));
    assert!(!dir.join("p.wrl").exists());
}
