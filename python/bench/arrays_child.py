"""The Python side of the arrays benchmark (bench_arrays.py), run in a fresh interpreter.

    python arrays_child.py DIR        # load DIR/*.f64, build, render, print one line
    python arrays_child.py --baseline # import numpy and gtsphere only, print the RSS

It does what examples/render_arrays.rs does, through gtsphere's Python API: the arrays are
read with np.fromfile (float64, C-contiguous, so from_arrays reads them in place), the scene
is built with the headlight off, a PointLight at (3, 3, 3) and a DirectionalLight along
-(1, 1, 1), and rendered 512 x 512 with one sample at each pixel's centre on one thread.

It prints one line of key=value, the same keys as the Rust example (n, build_s, render_s,
tile_s, total_s, cpu_s, peak_rss_bytes, checksum) plus rss_after_load_bytes, the resident set
right after the arrays were read and before from_arrays. total_s runs from the start of
from_arrays to the end of render (reading the files is not included, as in Rust).
"""

import math
import sys
import time

import numpy as np

import gtsphere as gt

SIZE = 512


def status_bytes(key):
    """A `kB` field of /proc/self/status (VmRSS, VmHWM) in bytes."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    raise RuntimeError(f"no {key} in /proc/self/status")


def rust_float(x):
    """`x` as Rust's `{:.16e}` writes it (17 significant digits, exponent without + or 0s)."""
    mantissa, exponent = f"{x:.16e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def sequential_sum(values):
    """The sum of `values` added one after another, as the Rust example does (numpy's sum is
    pairwise, Python's sum compensated; both would differ in the last bits)."""
    return float(np.add.accumulate(values)[-1]) if values.size else 0.0


def main(argv):
    if argv == ["--baseline"]:
        print(f"rss_bytes={status_bytes('VmRSS')} peak_rss_bytes={status_bytes('VmHWM')}")
        return 0
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    d = argv[0]
    centers = np.fromfile(f"{d}/centers.f64", dtype="<f8").reshape(-1, 3)
    radii = np.fromfile(f"{d}/radii.f64", dtype="<f8")
    colors = np.fromfile(f"{d}/colors.f64", dtype="<f8").reshape(-1, 3)
    # A single value is the radius of every sphere (Radii::One on the Rust side).
    radius = float(radii[0]) if radii.size == 1 else radii
    rss_after_load = status_bytes("VmRSS")

    start = time.perf_counter()
    cpu_start = time.process_time()  # all threads of the process, as the Rust example
    scene = gt.Scene.from_arrays(centers, radius, colors=colors, headlight=False)
    scene.add_point_light((3.0, 3.0, 3.0))
    scene.add_directional_light((-1.0, -1.0, -1.0))  # normalised by the binding
    build_s = time.perf_counter() - start

    camera = gt.Camera.look_at((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), fov=math.pi / 4)
    before_render = time.perf_counter()
    film = gt.render(scene, camera, SIZE, SIZE, spp=1, sampler="center", threads=1)
    end = time.perf_counter()
    cpu_s = time.process_time() - cpu_start
    peak = status_bytes("VmHWM")  # before the checksum, whose running sums take memory

    checksum = sequential_sum(np.ascontiguousarray(film.rgb).ravel())
    print(
        f"n={len(centers)} build_s={build_s:.6f} render_s={end - before_render:.6f} "
        f"tile_s={film.seconds:.6f} total_s={end - start:.6f} cpu_s={cpu_s:.6f} "
        f"peak_rss_bytes={peak} rss_after_load_bytes={rss_after_load} "
        f"checksum={rust_float(checksum)}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
