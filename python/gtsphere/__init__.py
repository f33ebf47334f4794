"""gtsphere: ground-truth pictures of particle data drawn as spheres.

Opaque spheres with exact hard shadows from point and directional lights (the VRML97
lighting equation), and spheres of glowing, absorbing, scattering gas integrated in closed
form or to a stated tolerance, with an honest per-pixel error estimate.

    import numpy as np, gtsphere as gt
    rng = np.random.default_rng(1)
    scene = gt.Scene.from_arrays(rng.uniform(-1, 1, (500, 3)), 0.08,
                                 colors=rng.uniform(0.2, 1, (500, 3)), headlight=False)
    scene.add_point_light((3, 3, 3))
    film = gt.render(scene, gt.Camera.frame(scene), 320, 240)
    gt.save(film, "cloud.png")

Names: Scene (from_arrays, add_point_light, add_directional_light), load, Camera
(look_at, frame, from_scene), render -> Film (rgb, alpha, error, depth, normal, id),
occlusion (each sphere's ambient occlusion), save, compare, and the exceptions Error, ParseError (file:line:col) and the warning
category SceneWarning. Bad values raise ValueError naming the array, index and value.
"""

from ._native import (
    Camera,
    Error,
    Film,
    ParseError,
    Scene,
    SceneWarning,
    __version__,
    compare,
    load,
    occlusion,
    render,
    save,
)

__all__ = [
    "Camera",
    "Error",
    "Film",
    "ParseError",
    "Scene",
    "SceneWarning",
    "__version__",
    "compare",
    "load",
    "occlusion",
    "render",
    "save",
]
