"""A benchmark: spheres from arrays rendered from Python cost what they cost in Rust.

    python python/bench/bench_arrays.py [N] [--runs R] [--seed S] [--const-radius]
                                        [--build] [--strict]

Targets: building a scene of N spheres from arrays and rendering it 512 x 512 from Python
takes within 5 % of the time the Rust API takes on the same scene (without reading the
files), and Python's peak memory is at most Rust's plus one copy of the input arrays (plus
what the interpreter with numpy and gtsphere imported holds before any work, measured here
as the baseline).

N random spheres (centres uniform in [-1, 1]^3, radius 0.6 N^(-1/3), varied by +-10 %
unless --const-radius, colours uniform in [0.2, 1]) are written as raw float64 files to a
temporary folder. Then R rounds alternate, in the order ABBA..., between

  (a) the Rust example examples/render_arrays.rs (target/release/examples/render_arrays,
      built with `cargo build --release --example render_arrays` if it is missing or with
      --build), and
  (b) a fresh Python interpreter running arrays_child.py, which does the same through the
      gtsphere package (np.fromfile, Scene.from_arrays, the two lights, render on one
      thread).

Each prints one key=value line; the table shows medians. The time target is judged on wall
time (total_s); the CPU time of the same interval (cpu_s) is shown beside it, as it is less
disturbed by other programs on a busy machine. The script also says whether the imported
gtsphere._native is the release build and whether Rust sources changed after it was built
(a debug build from `maturin develop` without --release is several times slower).

Both must draw the same pixels:
the checksums (sum of all RGB values) are compared and the script exits with 1 if they
differ. With --strict it also exits with 1 when a target is missed.
"""

import argparse
import filecmp
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
CHILD = HERE / "arrays_child.py"
TIME_TARGET = 1.05


def target_dir():
    return Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))


def rust_binary(force_build):
    exe = target_dir() / "release" / "examples" / "render_arrays"
    if force_build or not exe.exists():
        cmd = ["cargo", "build", "--release", "--example", "render_arrays"]
        print("building:", " ".join(cmd), file=sys.stderr, flush=True)
        subprocess.run(cmd, cwd=ROOT, check=True)
    return exe


def module_note():
    """Which build of gtsphere._native the interpreter imports: a debug build (what
    `maturin develop` without --release installs) renders far slower than the Rust example."""
    p = subprocess.run(
        [sys.executable, "-c", "import gtsphere._native as m; print(m.__file__)"],
        stdout=subprocess.PIPE, text=True, check=True,
    )
    module = Path(p.stdout.strip())
    for profile in ("release", "debug"):
        built = target_dir() / profile / "lib_native.so"
        if built.exists() and filecmp.cmp(module, built, shallow=False):
            return profile, module
    return "unknown (not the target dir's release or debug build)", module


def newer_sources(than):
    """Rust sources of the library or the binding changed after the file `than` was made."""
    made = than.stat().st_mtime
    sources = list((ROOT / "src").rglob("*.rs")) + list((ROOT / "python" / "src").rglob("*.rs"))
    return [p.relative_to(ROOT) for p in sources if p.stat().st_mtime > made]


def make_inputs(n, seed, const_radius, folder):
    """Writes centers.f64, radii.f64, colors.f64 to `folder`; returns their total bytes."""
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-1.0, 1.0, (n, 3))
    r0 = 0.6 * n ** (-1.0 / 3.0)
    radii = np.array([r0]) if const_radius else r0 * rng.uniform(0.9, 1.1, n)
    colors = rng.uniform(0.2, 1.0, (n, 3))
    total = 0
    for name, a in (("centers", centers), ("radii", radii), ("colors", colors)):
        a.astype("<f8").tofile(folder / f"{name}.f64")
        total += a.nbytes
    return total


def parse(line):
    out = {}
    for field in line.split():
        key, value = field.split("=", 1)
        out[key] = value if key == "checksum" else float(value)
    return out


def run(cmd):
    """Runs `cmd` and returns its last stdout line as a dict (stderr is passed through)."""
    p = subprocess.run(cmd, stdout=subprocess.PIPE, text=True, check=False)
    if p.returncode != 0:
        sys.exit(f"{' '.join(map(str, cmd))} failed with exit code {p.returncode}:\n{p.stdout}")
    return parse(p.stdout.strip().splitlines()[-1])


def mib(b):
    return f"{b / 2**20:.1f} MiB"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("n", nargs="?", type=float, default=1e6, help="spheres (default 1e6)")
    ap.add_argument("--runs", type=int, default=3, help="rounds of Rust and Python (default 3)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--const-radius", action="store_true", help="one radius for all spheres")
    ap.add_argument("--build", action="store_true", help="rebuild the Rust example first")
    ap.add_argument("--strict", action="store_true", help="exit 1 when a target is missed")
    args = ap.parse_args()
    n = int(args.n)

    exe = rust_binary(args.build)
    profile, module = module_note()
    print(f"Rust:   {exe}\nPython: {sys.executable}, gtsphere._native = {module} ({profile} build)")
    if profile != "release":
        print("WARNING: gtsphere._native is not the release build; rebuild it with "
              "`maturin develop --release` in python/ for meaningful timings")
    stale = newer_sources(module)
    if stale:
        print(f"WARNING: {len(stale)} Rust sources changed since gtsphere._native was built "
              f"(e.g. {stale[0]}); Rust and Python may not run the same code")
    python = [sys.executable, str(CHILD)]
    folder = Path(tempfile.mkdtemp(prefix="gtsphere-bench-arrays-"))
    try:
        array_bytes = make_inputs(n, args.seed, args.const_radius, folder)
        baseline = [run(python + ["--baseline"])["peak_rss_bytes"] for _ in range(3)]
        rust, py = [], []
        for k in range(args.runs):
            order = [("rust", [exe, folder]), ("python", python + [str(folder)])]
            if k % 2:
                order.reverse()
            for side, cmd in order:
                r = run(cmd)
                (rust if side == "rust" else py).append(r)
                print(
                    f"round {k + 1} {side:6}: build {r['build_s']:.3f} s, render "
                    f"{r['render_s']:.3f} s, total {r['total_s']:.3f} s, cpu "
                    f"{r['cpu_s']:.3f} s, peak {mib(r['peak_rss_bytes'])}",
                    flush=True,
                )
    finally:
        shutil.rmtree(folder, ignore_errors=True)

    med = lambda runs, key: statistics.median(r[key] for r in runs)  # noqa: E731
    base = statistics.median(baseline)
    rows = [
        ("build_s (from_arrays + prepare)", "build_s"),
        ("render_s (render, wall)", "render_s"),
        ("  of which tile loop (Film.seconds)", "tile_s"),
        ("total_s (build + render)", "total_s"),
        ("cpu_s (CPU time of total_s)", "cpu_s"),
    ]
    print(f"\nN = {n} spheres, 512 x 512, spp 1, sampler center, 1 thread, "
          f"{args.runs} rounds, medians")
    print(f"{'':38}{'Rust':>12}{'Python':>12}{'Py/Rust':>10}")
    for label, key in rows:
        a, b = med(rust, key), med(py, key)
        print(f"{label:38}{a:12.3f}{b:12.3f}{b / a:10.3f}")
    ratio = med(py, "total_s") / med(rust, "total_s")
    rust_peak, py_peak = med(rust, "peak_rss_bytes"), med(py, "peak_rss_bytes")
    limit = rust_peak + array_bytes + base
    print(f"{'peak RSS (VmHWM)':38}{mib(rust_peak):>12}{mib(py_peak):>12}"
          f"{py_peak / rust_peak:10.3f}")
    loaded = med(py, "rss_after_load_bytes")
    print(f"{'Python RSS after loading the arrays':38}{'':12}{mib(loaded):>12}")
    print(f"input arrays: {array_bytes} bytes ({mib(array_bytes)}); "
          f"interpreter + numpy + gtsphere baseline: {mib(base)}")
    cpu_ratio = med(py, "cpu_s") / med(rust, "cpu_s")
    time_ok = ratio <= TIME_TARGET
    memory_ok = py_peak <= limit
    print(f"time:   Python/Rust total = {ratio:.3f} -> within 5 %: {'yes' if time_ok else 'NO'} "
          f"(CPU time ratio {cpu_ratio:.3f})")
    print(f"memory: Python peak {mib(py_peak)} <= Rust peak + arrays + baseline "
          f"{mib(limit)}: {'yes' if memory_ok else 'NO'} "
          f"(margin {mib(limit - py_peak)})")

    rust_sums = sorted({r["checksum"] for r in rust})
    py_sums = sorted({r["checksum"] for r in py})
    print(f"checksum Rust:   {', '.join(rust_sums)}")
    print(f"checksum Python: {', '.join(py_sums)}")
    same = len(rust_sums) == 1 and rust_sums == py_sums
    if not same:
        print("FAIL: the checksums differ (Rust and Python drew different pixels)")
        return 1
    print("checksums equal")
    if args.strict and not (time_ok and memory_ok):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
