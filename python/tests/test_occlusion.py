"""gt.occlusion: each sphere's mean ambient occlusion over its surface, against a sphere
alone (1), a Monte Carlo estimate written here with numpy for two touching spheres, and the
`gtsphere occlusion` command's table; its errors, progress and cancellation; and
Scene.sphere_arrays, the spheres its rows stand for."""

import functools
import pathlib
import threading
import time

import numpy as np
import pytest

import gtsphere as gt

# Two touching spheres of equal radii, and of radii 1 and 0.5.
EQUAL = (((0.0, 0.0, 0.0), 1.0), ((2.0, 0.0, 0.0), 1.0))
UNEQUAL = (((0.0, 0.0, 0.0), 1.0), ((1.5, 0.0, 0.0), 0.5))
TOL = 1e-4
ROOT = pathlib.Path(__file__).resolve().parents[2]


def scene_of(spheres):
    return gt.Scene.from_arrays([c for c, _ in spheres], [r for _, r in spheres])


def unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@functools.lru_cache(maxsize=None)
def monte_carlo(target, other, reach, weighting, n=8_000_000, seed=7):
    """The mean over `target`'s surface of the fraction of its tangent hemisphere (weighted
    by `weighting`) from which `other` is not met within `reach`: the probability that a
    point uniform on the surface and a direction drawn from the weighting give a ray that
    misses. Returns the estimate and its standard error."""
    rng = np.random.default_rng(seed)
    (c0, r0), (c1, r1) = target, other
    c0, c1 = np.asarray(c0), np.asarray(c1)
    free = 0
    chunk = 1_000_000
    for start in range(0, n, chunk):
        m = min(chunk, n - start)
        normal = unit(rng.normal(size=(m, 3)))
        v = unit(rng.normal(size=(m, 3)))
        if weighting == "cosine":
            # The normal plus a uniform unit vector points along a cosine-weighted direction
            # (Malley's method seen on the unit sphere tangent at the point).
            d = unit(normal + v)
        else:
            d = np.where((v * normal).sum(axis=1, keepdims=True) < 0, -v, v)
        oc = c0 + r0 * normal - c1
        b = (d * oc).sum(axis=1)
        disc = b * b - ((oc * oc).sum(axis=1) - r1 * r1)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        free += m - np.count_nonzero((disc >= 0) & (t > 0) & (t <= reach))
    p = free / n
    return p, np.sqrt(p * (1 - p) / n)


def lattice(n):
    """n spheres of radius 0.4 on a cubic lattice of spacing 1: each shades its neighbours
    within a reach of 0.3, and none overlaps another."""
    g = np.stack(np.meshgrid(*[np.arange(8.0)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    return gt.Scene.from_arrays(g[:n], 0.4)


def test_a_sphere_alone_sees_the_whole_sky():
    for weighting in ("cosine", "uniform"):
        ao, err = gt.occlusion(gt.Scene.from_arrays([[1.0, 2.0, 3.0]], 0.7), ao_weighting=weighting)
        assert ao.shape == err.shape == (1,) and ao.dtype == err.dtype == np.float64
        assert abs(ao[0] - 1.0) < 1e-12 and 0 <= err[0] < 1e-12, (ao, err)


@pytest.mark.parametrize("pair", [EQUAL, UNEQUAL], ids=["equal", "unequal"])
@pytest.mark.parametrize("reach, weighting", [(None, "cosine"), (0.5, "uniform")])
def test_two_touching_spheres_agree_with_monte_carlo(pair, reach, weighting):
    ao, err = gt.occlusion(scene_of(pair), ao_reach=reach, ao_weighting=weighting, tol=TOL)
    assert (err <= TOL).all(), err
    for k, (target, other) in enumerate([pair, pair[::-1]]):
        p, se = monte_carlo(target, other, np.inf if reach is None else reach, weighting)
        # Five standard errors (about 5e-4): a false failure once in 1.7 million seeds (the
        # estimate is a mean of 8 million Bernoulli draws, normal to well within that).
        assert abs(ao[k] - p) <= 5 * se + TOL, (k, ao[k], p, se)
        # The neighbour shades it, visibly beyond the test's resolution.
        assert ao[k] < 1 - 50 * se
    if pair is EQUAL:
        assert abs(ao[0] - ao[1]) <= 2 * TOL


def test_every_copy_of_a_repeated_sphere_takes_its_value():
    (a, b) = UNEQUAL
    order = [a, b, a, b, b, a]
    scene = scene_of(order)
    ao, err = gt.occlusion(scene, tol=TOL)
    assert ao.shape == (6,)
    # The rows are the scene's spheres, copies included, in its order.
    centers, radii = scene.sphere_arrays()
    assert np.array_equal(centers, [c for c, _ in order]) and np.array_equal(radii, [r for _, r in order])
    for k, s in enumerate(order):
        p, se = monte_carlo(s, b if s is a else a, np.inf, "cosine")
        assert abs(ao[k] - p) <= 5 * se + TOL, (k, ao[k], p, se)
    # Copies are drawn as one sphere: each takes its first copy's value, bit for bit, and the
    # pair alone gives the same (a copy does not shade the sphere it repeats).
    pair, pair_err = gt.occlusion(scene_of([a, b]), tol=TOL)
    first = [0, 1, 0, 1, 1, 0]
    assert np.array_equal(ao, pair[first]) and np.array_equal(err, pair_err[first])


def test_the_command_line_writes_the_same_values(gtsphere_cli, tmp_path):
    # Two front ends of one library: a consistency test, not an independent check.
    scene = ROOT / "samples" / "cluster.wrl"
    table = tmp_path / "ao.npy"
    gtsphere_cli("occlusion", scene, "-o", table, "--ao-reach", "2",
                 "--ao-weighting", "uniform", "--tol", "1e-3", "-q")
    rows = np.load(table)
    loaded = gt.load(scene)
    ao, err = gt.occlusion(loaded, ao_reach=2, ao_weighting="uniform", tol=1e-3)
    centers, radii = loaded.sphere_arrays()
    assert rows.shape == (len(ao), 7) and len(ao) == 24
    assert np.array_equal(rows[:, 0], np.arange(len(ao)))
    assert np.array_equal(rows[:, 1:4], centers) and np.array_equal(rows[:, 4], radii)
    assert np.array_equal(rows[:, 5], ao) and np.array_equal(rows[:, 6], err)


def test_the_values_do_not_depend_on_the_threads():
    scene = lattice(100)
    one = gt.occlusion(scene, threads=1, ao_reach=0.3)
    two = gt.occlusion(scene, threads=2, ao_reach=0.3)
    assert np.array_equal(one[0], two[0]) and np.array_equal(one[1], two[1])
    assert (one[0] < 1).all() and (one[0] > 0.5).all()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(tol=0.0), r"^tol = 0: the tolerance must be between 0 and 1$"),
        (dict(tol=1.0), r"^tol = 1: the tolerance must be between 0 and 1$"),
        (dict(tol=float("nan")), r"^tol = NaN: the tolerance must be between 0 and 1$"),
        (dict(ao_reach=-1.0), r"^ao_reach = -1\.0: must be a positive distance \(or None: any distance\)$"),
        (dict(ao_reach=0.0), r"^ao_reach = 0\.0: must be a positive distance"),
        (dict(ao_weighting="cos"), r"^ao_weighting = \"cos\": must be \"cosine\" or \"uniform\"$"),
        (dict(threads=0), r"^threads must be at least 1$"),
    ],
)
def test_bad_keywords_raise_value_error_naming_them(kwargs, message):
    with pytest.raises(ValueError, match=message):
        gt.occlusion(scene_of(EQUAL), **kwargs)


def test_scenes_ao_does_not_take_are_refused_and_surfaces_occlude(tmp_path):
    gas = gt.Scene.from_arrays([[0, 0, 0], [2, 0, 0]], 1.0, transparency=[0.0, 0.5])
    with pytest.raises(
        ValueError,
        match=r"^scene: per-particle AO knows opaque spheres, triangles, boxes and closed "
        r"cylinders and cones only, and this scene has 1 gas spheres \(AO pictures take gas "
        r"as an occluder\)$",
    ):
        gt.occlusion(gas)
    # A Box beside a sphere occludes it; a closed cylinder too, to the tolerance; an open one
    # is refused.
    lone = tmp_path / "lone.wrl"
    lone.write_text("#VRML V2.0 utf8\nShape { geometry Sphere { } }\n")
    (alone,), _ = gt.occlusion(gt.load(lone))
    assert abs(alone - 1.0) <= 1e-12
    for solid in ("Box { }", "Cylinder { }"):
        f = tmp_path / "beside.wrl"
        f.write_text(
            "#VRML V2.0 utf8\nShape { geometry Sphere { } }\n"
            f"Transform {{ translation 2.5 0 0 children Shape {{ geometry {solid} }} }}\n"
        )
        (ao,), (err,) = gt.occlusion(gt.load(f), tol=1e-2)
        assert 0.5 < ao < 1.0 and err <= 1.5e-2, (solid, ao, err)
    f.write_text("#VRML V2.0 utf8\nShape { geometry Sphere { } }\nShape { geometry Cylinder { top FALSE } }\n")
    with pytest.raises(ValueError, match=r"this scene has 1 open cylinders or cones"):
        gt.occlusion(gt.load(f))


def test_progress_counts_spheres_and_an_exception_from_it_stops_the_work():
    scene = lattice(300)
    calls = []
    gt.occlusion(scene, ao_reach=0.3, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (300, 300)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop

    started = time.monotonic()
    # Minutes of work on one thread at this tolerance: it cannot finish first.
    with pytest.raises(Stop):
        gt.occlusion(scene, tol=1e-8, threads=1, progress=stop)
    assert time.monotonic() - started < 2.0
    # The scene is still usable.
    assert gt.occlusion(scene, ao_reach=0.3)[0].shape == (300,)


def test_the_gil_is_released_while_integrating():
    scene = lattice(300)
    done = threading.Event()
    result = []

    def work():
        # About 2 s on one thread.
        result.append(gt.occlusion(scene, ao_reach=0.3, tol=1e-4, threads=1))
        done.set()

    t = threading.Thread(target=work)
    stamps = []
    t.start()
    while not done.is_set():
        stamps.append(time.monotonic())
    t.join()
    assert result and result[0][0].shape == (300,)
    elapsed = stamps[-1] - stamps[0]
    assert elapsed > 0.3, "the work must take long enough to tell"
    # Were the GIL held, this thread would stand still for all of the work.
    gap = max(b - a for a, b in zip(stamps, stamps[1:]))
    assert gap < 0.25 * elapsed, (gap, elapsed)
