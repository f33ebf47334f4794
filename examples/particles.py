"""A random particle cloud from numpy, drawn twice: opaque spheres with hard shadows, and
the same particles as lit, glowing gas. Writes opaque.png and gas.png, showing each render's
progress.

    python examples/particles.py [WIDTH HEIGHT]    # 480 x 360 by default
"""
import sys

import numpy as np, gtsphere as gt

width, height = (int(sys.argv[1]), int(sys.argv[2])) if len(sys.argv) > 2 else (480, 360)
rng = np.random.default_rng(7)
centers, colors = rng.uniform(-1, 1, (400, 3)), rng.uniform(0.3, 1, (400, 3))
opaque = gt.Scene.from_arrays(centers, 0.1, colors, headlight=False)
gas = gt.Scene.from_arrays(centers, 0.2, colors, np.full(400, 0.3), 0.3 * colors, headlight=False)
for name, scene, spp in [("opaque", opaque, 16), ("gas", gas, 4)]:
    scene.add_point_light((2, 3, 3)); scene.add_directional_light((-1, -1, -1), intensity=0.4)

    def show(done, total):  # called about ten times a second while the render runs
        print(f"\r{name}: {100 * done // total} %", end="", flush=True)

    camera = gt.Camera.frame(scene, direction=(-0.3, -0.4, -1))
    film = gt.render(scene, camera, width, height, spp=spp, progress=show)
    gt.save(film, f"{name}.png"); print(f"\r{name}: {film.seconds:.1f} s, max error {film.max_error:.1e}")
