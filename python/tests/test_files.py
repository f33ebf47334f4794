"""save() writes what the command line writes; compare() prints what `gtsphere compare` prints."""

import re

import numpy as np
import pytest

import gtsphere as gt


def small_film(seed=0, spp=2):
    rng = np.random.default_rng(seed)
    scene = gt.Scene.from_arrays(rng.uniform(-1, 1, (30, 3)), 0.2, colors=rng.uniform(0, 1, (30, 3)))
    return gt.render(scene, gt.Camera.frame(scene), 24, 16, spp=spp)


def test_save_every_format(tmp_path):
    film = small_film()
    for ext in ("exr", "png", "pfm", "npy"):
        gt.save(film, tmp_path / f"a.{ext}")
        assert (tmp_path / f"a.{ext}").stat().st_size > 0
    assert np.array_equal(np.load(tmp_path / "a.npy"), film.rgb)
    gt.save(film.rgb, tmp_path / "b.npy")
    assert np.array_equal(np.load(tmp_path / "b.npy"), film.rgb)
    # An array saved as EXR reads back (through compare) as its f32 values.
    gt.save(film.rgb, tmp_path / "b.exr")
    m = gt.compare(tmp_path / "b.exr", film.rgb.astype(np.float32))
    assert m["max_abs"] == 0.0
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "a.exr", "a.npy", "a.pfm", "a.png", "b.exr", "b.npy"
    ], "no temporary files are left"


def test_save_rejects_bad_input(tmp_path):
    film = small_film()
    with pytest.raises(gt.Error, match=r"unsupported image file name"):
        gt.save(film, tmp_path / "a.jpg")
    with pytest.raises(ValueError, match=r"image must have shape \(H, W, 3\), \(H, W, 4\) or \(H, W\), got \(4,\)"):
        gt.save(np.zeros(4), tmp_path / "a.png")
    assert list(tmp_path.iterdir()) == []


def test_compare_equals_the_cli(tmp_path, gtsphere_cli):
    a, b = small_film(0, spp=1), small_film(0, spp=4)
    gt.save(a, tmp_path / "a.exr")
    gt.save(b, tmp_path / "b.exr")
    out = gtsphere_cli("compare", tmp_path / "a.exr", tmp_path / "b.exr").stdout
    m = gt.compare(tmp_path / "a.exr", tmp_path / "b.exr")
    printed = dict(
        rmse=r"rmse +(\S+)",
        relative_rmse=r"relative rmse +(\S+)",
        psnr=r"psnr +(\S+) dB",
        max_abs=r"max abs error +(\S+) at",
    )
    for key, pattern in printed.items():
        shown = re.search(pattern, out).group(1)
        digits = 2 if key == "psnr" else 6
        # The same number, to the digits the command prints.
        assert float(shown) == float(f"{m[key]:.{digits}{'f' if key == 'psnr' else 'e'}}"), key
    x, y = m["max_at"]
    assert f"at pixel ({x}, {y})" in out
    assert m["rmse"] > 0
    # Films compare at full precision, and an image equals itself.
    assert gt.compare(a, a)["rmse"] == 0.0
    assert gt.compare(a, b)["rmse"] == pytest.approx(m["rmse"], rel=1e-5)
    with pytest.raises(ValueError, match="differ in size"):
        gt.compare(a, np.zeros((3, 3, 3)))
