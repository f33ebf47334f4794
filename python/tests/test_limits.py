"""Sizes and samples a render cannot hold raise ValueError before anything is allocated;
threads beyond four per core are lowered with a RuntimeWarning."""

import os
import re

import numpy as np
import pytest

import gtsphere as gt


@pytest.fixture
def spheres():
    s = gt.Scene.from_arrays(np.array([[0.0, 0, 0], [1.5, 0, 0]]), 0.5)
    return s, gt.Camera.frame(s)


def test_spp_beyond_the_bound_raises(spheres):
    s, cam = spheres
    with pytest.raises(ValueError, match=r"^spp = 2147483648: at most 1048576 samples per pixel$"):
        gt.render(s, cam, 4, 4, spp=2**31)


def test_an_image_larger_than_the_memory_raises(spheres):
    s, cam = spheres
    # Some 80 TB: more than any machine has; where the memory available is unknown the
    # film's allocation fails instead, also as ValueError.
    with pytest.raises(ValueError) as e:
        gt.render(s, cam, 2**20, 2**20, spp=1)
    if os.path.exists("/proc/meminfo"):
        assert str(e.value).startswith("a 1048576x1048576 image with the error AOV (spp 1, ")
        assert " GB of memory; this machine has " in str(e.value)


def test_an_image_whose_size_overflows_raises(spheres):
    s, cam = spheres
    with pytest.raises(ValueError, match=r"^a 2147483648x2147483648 image with the error AOV \(spp 1\) needs more memory than can be counted$"):
        gt.render(s, cam, 2**31, 2**31, spp=1)


def test_threads_beyond_four_per_core_are_lowered_with_a_warning(spheres):
    s, cam = spheres
    with pytest.warns(RuntimeWarning, match=r"^threads=100000 is more than 4 per core of this machine's (\d+) cores?: using (\d+)$") as w:
        film = gt.render(s, cam, 8, 6, spp=1, threads=100000)
    cores, used = re.search(r"(\d+) cores?: using (\d+)$", str(w[0].message)).groups()
    assert int(used) == 4 * int(cores)
    assert film.rgb.shape == (6, 8, 3)
    assert film.alpha.max() > 0
