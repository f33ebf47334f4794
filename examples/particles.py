"""A random particle cloud from numpy, drawn twice: opaque spheres with hard shadows, and
the same particles as lit, glowing gas. Writes opaque.png and gas.png."""
import numpy as np, gtsphere as gt

rng = np.random.default_rng(7)
centers, colors = rng.uniform(-1, 1, (400, 3)), rng.uniform(0.3, 1, (400, 3))
opaque = gt.Scene.from_arrays(centers, 0.1, colors, headlight=False)
gas = gt.Scene.from_arrays(centers, 0.2, colors, np.full(400, 0.3), 0.3 * colors, headlight=False)
for name, scene, spp in [("opaque", opaque, 16), ("gas", gas, 4)]:
    scene.add_point_light((2, 3, 3)); scene.add_directional_light((-1, -1, -1), intensity=0.4)
    film = gt.render(scene, gt.Camera.frame(scene, direction=(-0.3, -0.4, -1)), 480, 360, spp=spp)
    gt.save(film, f"{name}.png"); print(name, f"{film.seconds:.1f} s, max error {film.max_error:.1e}")
