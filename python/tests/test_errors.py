"""Bad input raises ValueError (or a gtsphere.Error) naming the array, index and value."""

import errno
import math
import pickle

import numpy as np
import pytest

import gtsphere as gt

C = np.zeros((4, 3)) + np.arange(4)[:, None]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(radii=[1, 1, -1.0, 1]), r"^radii\[2\] = -1\.0: radius must be positive and finite$"),
        (dict(radii=[1, 1, 1, math.nan]), r"^radii\[3\] = NaN: radius must be positive and finite$"),
        (dict(radii=-2.0), r"^radius = -2\.0: radius must be positive and finite$"),
        (dict(radii=[1, 1]), r"^radii has 2 values for 4 centres$"),
        (dict(radii=1, colors=np.full((4, 3), 0.5) + [[0, 0, 0], [0, 0, 0], [0, 1.5, 0], [0, 0, 0]]),
         r"^colors\[2\] = \[0\.5, 2\.0, 0\.5\]: colour channels must be in \[0, 1\]$"),
        (dict(radii=1, colors=np.zeros((3, 3))), r"^colors has 9 values for 4 spheres"),
        (dict(radii=1, colors=np.zeros((4, 2))), r"^colors must have shape \(N, 3\), got \(4, 2\)$"),
        (dict(radii=1, transparency=[0, 0.5, 0, 1.5]), r"^transparency\[3\] = 1\.5: transparency must be in \[0, 1\]$"),
        (dict(radii=1, emissive=-np.ones((4, 3))), r"^emissive\[0\] = \[-1\.0, -1\.0, -1\.0\]: colour channels must be in \[0, 1\]$"),
        (dict(radii=1, colors="red"), r"^colors must be an array of numbers"),
    ],
)
def test_from_arrays_errors_name_array_index_and_value(kwargs, message):
    with pytest.raises(ValueError, match=message):
        gt.Scene.from_arrays(C, **kwargs)


def test_bad_centres():
    bad = C.copy()
    bad[1, 2] = math.inf
    with pytest.raises(ValueError, match=r"^centers\[1\] = \[1\.0, 1\.0, inf\]: the centre must be finite$"):
        gt.Scene.from_arrays(bad, 0.5)
    with pytest.raises(ValueError, match=r"^centers must have shape \(N, 3\), got \(4, 2\)$"):
        gt.Scene.from_arrays(np.zeros((4, 2)), 0.5)


def test_inputs_are_converted_once_not_kept():
    # float32, non-contiguous and list inputs are converted; the scene does not alias them.
    centers = np.asfortranarray(C.astype(np.float32))
    s = gt.Scene.from_arrays(centers, np.full(4, 0.25, dtype=np.float32), colors=[[0.1, 0.2, 0.3]] * 4)
    centers[:] = 99
    assert s.bounds == ((-0.25, -0.25, -0.25), (3.25, 3.25, 3.25))


def test_light_and_camera_errors():
    s = gt.Scene.from_arrays(C, 0.5)
    with pytest.raises(ValueError, match=r"^color = \(2\.0, 0\.0, 0\.0\): colour channels must be in \[0, 1\]$"):
        s.add_point_light((0, 0, 5), color=(2, 0, 0))
    with pytest.raises(ValueError, match=r"^intensity = -1\.0: must be finite and non-negative$"):
        s.add_directional_light((0, 0, -1), intensity=-1)
    with pytest.raises(ValueError, match="direction must be a finite non-zero vector"):
        s.add_directional_light((0, 0, 0))
    with pytest.raises(ValueError, match="location must be three numbers"):
        s.add_point_light((0, 0))
    with pytest.raises(ValueError, match="target is its own position"):
        gt.Camera.look_at((1, 2, 3), (1, 2, 3))
    with pytest.raises(ValueError, match="parallel to the view direction"):
        gt.Camera.look_at((0, 0, 5), (0, 0, 0), up=(0, 0, 1))
    with pytest.raises(ValueError, match="field of view 4 is not between 0 and pi"):
        gt.Camera.look_at((0, 0, 5), fov=4)
    with pytest.raises(ValueError, match="orthographic height -1 is not positive"):
        gt.Camera.look_at((0, 0, 5), ortho_height=-1)
    with pytest.raises(ValueError, match="no Viewpoint named \"top\""):
        gt.Camera.from_scene(s, "top")
    assert s.lights == 0, "a rejected light is not added"


def test_render_option_errors():
    s = gt.Scene.from_arrays(C, 0.5)
    cam = gt.Camera.frame(s)
    cases = [
        (dict(width=0), "the image size 0x10 is empty"),
        (dict(tol=0.0), r"tol = 0: the tolerance must be positive"),
        (dict(spp=0), "spp must be at least 1"),
        (dict(integrator="exakt"), r"integrator = \"exakt\": must be"),
        (dict(integrator="march"), "needs step="),
        (dict(integrator="march", step=-1.0), r"step = -1: the march step must be positive"),
        (dict(aovs=("depht",)), r"unknown channel \"depht\""),
        (dict(sampler="random"), r"sampler = \"random\""),
        (dict(threads=0), "threads must be at least 1"),
    ]
    for kwargs, message in cases:
        args = dict(width=10, height=10) | kwargs
        with pytest.raises(ValueError, match=message):
            gt.render(s, cam, **args)


def test_parse_errors_carry_file_line_col(tmp_path):
    bad = tmp_path / "bad.wrl"
    bad.write_text("#VRML V2.0 utf8\nShape {\n  geometry Sphere { radius -1 }\n}\n")
    with pytest.raises(gt.ParseError, match=r"bad\.wrl:3:21: Sphere radius must be positive"):
        gt.load(bad)
    bad.write_text("#VRML V2.0 utf8\nShape { geometry Sphere { radius 1 }\n")
    with pytest.raises(gt.ParseError, match=r"bad\.wrl:\d+:\d+: "):
        gt.load(bad)
    with pytest.raises(FileNotFoundError, match="missing.wrl") as missing:
        gt.load(tmp_path / "missing.wrl")
    assert missing.value.errno == errno.ENOENT
    assert missing.value.filename == str(tmp_path / "missing.wrl")
    assert issubclass(gt.ParseError, gt.Error)


def test_errors_pickle_as_themselves(tmp_path):
    # What a ProcessPoolExecutor does with an exception raised in a worker.
    bad = tmp_path / "bad.wrl"
    bad.write_text("#VRML V2.0 utf8\nShape { geometry Sphere { radius 1 }\n")
    with pytest.raises(gt.ParseError) as caught:
        gt.load(bad)
    back = pickle.loads(pickle.dumps(caught.value))
    assert type(back) is gt.ParseError and str(back) == str(caught.value)
    assert gt.ParseError.__module__ == gt.Error.__module__ == "gtsphere"
    with pytest.raises(FileNotFoundError) as missing:
        gt.load(tmp_path / "missing.wrl")
    back = pickle.loads(pickle.dumps(missing.value))
    assert back.filename == missing.value.filename and back.errno == errno.ENOENT


def test_warnings_are_python_warnings(tmp_path):
    f = tmp_path / "w.wrl"
    f.write_text("#VRML V2.0 utf8\nShape { appearance Appearance { material Material { transparency 2 } } geometry Sphere { } }\n")
    with pytest.warns(gt.SceneWarning, match=r"w\.wrl:2:\d+: .*transparency 2 is outside \[0, 1\]: clamped"):
        s = gt.load(f)
    assert len(s.warnings) == 1
    with pytest.raises(gt.ParseError):
        gt.load(f, strict=True)


def test_one_version_for_the_package_and_the_module():
    from importlib.metadata import version

    assert gt.__version__ == version("gtsphere")


def test_a_use_blowup_is_refused_and_max_expansion_raises_the_limit(tmp_path):
    # Each DEF USEs the one before twice: 2^k spheres from a few lines.
    def bomb(levels):
        lines = ["#VRML V2.0 utf8", "DEF L0 Shape { geometry Sphere { radius 0.01 } }"]
        lines += [f"DEF L{i} Transform {{ translation 0.02 0 0 children [ USE L{i - 1} USE L{i - 1} ] }}"
                  for i in range(1, levels + 1)]
        return "\n".join(lines) + "\n"

    path = tmp_path / "bomb.wrl"
    path.write_text(bomb(30))
    with pytest.raises(gt.ParseError, match=r"bomb\.wrl:\d+:\d+: this USE takes the scene past its expansion limit"):
        gt.load(path)
    # 2^19 - 1 spheres (each level is drawn too) from 1.5 KB pass the default limit; a
    # higher one lets them through.
    path.write_text(bomb(18))
    with pytest.raises(gt.ParseError, match="expansion limit"):
        gt.load(path)
    assert gt.load(path, max_expansion=100_000).spheres == (1 << 19) - 1
