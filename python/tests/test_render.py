"""Rendering from numpy: against the command line, against the VRML equation and the gas
closed form, and prepared scenes reused across cameras."""

import math

import numpy as np
import pytest

import gtsphere as gt


def cloud(n=60, seed=3, gas=False):
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-1.0, 1.0, (n, 3))
    radii = rng.uniform(0.08, 0.25, n)
    colors = rng.uniform(0.0, 1.0, (n, 3))
    transparency = np.where(rng.uniform(size=n) < 0.5, rng.uniform(0.2, 0.9, n), 0.0) if gas else None
    emissive = rng.uniform(0.0, 0.3, (n, 3)) if gas else None
    return centers, radii, colors, transparency, emissive


def vrml_of(centers, radii, colors, transparency, emissive):
    """The same spheres as VRML97 text, every number written with repr (round-trips)."""
    f = repr
    out = [
        "#VRML V2.0 utf8",
        "NavigationInfo { headlight FALSE }",
        "Viewpoint { position 0 0 5 }",
        "PointLight { location 3 3 3 intensity 0.8 }",
        "DirectionalLight { direction -0.5773502691896258 -0.5773502691896258 -0.5773502691896258 intensity 0.5 }",
    ]
    for i in range(len(centers)):
        c = centers[i]
        mat = "diffuseColor {} {} {}".format(*map(f, map(float, colors[i])))
        if transparency is not None:
            mat += f" transparency {f(float(transparency[i]))}"
        if emissive is not None:
            mat += " emissiveColor {} {} {}".format(*map(f, map(float, emissive[i])))
        out.append(
            "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ {} }} }} geometry Sphere {{ radius {} }} }} }}".format(
                *map(f, map(float, c)), mat, f(float(radii[i]))
            )
        )
    return "\n".join(out) + "\n"


def scene_of(centers, radii, colors, transparency, emissive):
    s = gt.Scene.from_arrays(centers, radii, colors, transparency, emissive, headlight=False)
    s.add_point_light((3, 3, 3), intensity=0.8)
    s.add_directional_light((-1, -1, -1), intensity=0.5)
    return s


@pytest.mark.parametrize("gas", [False, True])
def test_arrays_equal_vrml_through_the_cli_bit_for_bit(tmp_path, gtsphere_cli, gas):
    data = cloud(gas=gas)
    wrl = tmp_path / "cloud.wrl"
    wrl.write_text(vrml_of(*data))
    out = tmp_path / "cli.npy"
    gtsphere_cli("render", wrl, "-o", out, "--width", 48, "--height", 36, "--spp", 4, "--quiet")
    want = np.load(out)

    scene = scene_of(*data)
    cam = gt.Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0))
    film = gt.render(scene, cam, 48, 36, spp=4)
    assert film.rgb.shape == want.shape == (36, 48, 3)
    assert film.rgb.dtype == np.float64
    assert np.count_nonzero(want) > 100, "the scene must show something"
    assert np.array_equal(film.rgb, want), np.abs(film.rgb - want).max()


def ortho_pixel_ray(cam_pos, height, width_px, height_px, i, j):
    """Origin of the orthographic ray through pixel (i, j)'s centre, camera looking down -z."""
    half = 0.5 * height
    aspect = width_px / height_px
    hw, hh = (half * aspect, half) if width_px >= height_px else (half, half / aspect)
    u, v = (i + 0.5) / width_px, (j + 0.5) / height_px
    return np.array([cam_pos[0] + (2 * u - 1) * hw, cam_pos[1] + (1 - 2 * v) * hh, cam_pos[2]])


def test_lit_sphere_pixel_is_the_vrml_equation():
    diffuse = np.array([0.9, 0.6, 0.3])
    scene = gt.Scene.from_arrays([[0.0, 0.0, 0.0]], 1.0, colors=[diffuse], headlight=False)
    point, p_int, p_amb = np.array([2.0, 1.5, 3.0]), 0.7, 0.3
    scene.add_point_light(point, intensity=p_int, ambient_intensity=p_amb)
    d_dir, d_int = np.array([0.3, -0.2, -1.0]), 0.6
    scene.add_directional_light(d_dir, intensity=d_int)
    cam_pos, h, w_px, h_px = (0.0, 0.0, 5.0), 2.5, 9, 7
    cam = gt.Camera.look_at(cam_pos, (0, 0, 0), (0, 1, 0), ortho_height=h)
    film = gt.render(scene, cam, w_px, h_px, sampler="center")
    checked = 0
    for j in range(h_px):
        for i in range(w_px):
            o = ortho_pixel_ray(cam_pos, h, w_px, h_px, i, j)
            b2 = o[0] ** 2 + o[1] ** 2
            if b2 >= 1.0:
                assert np.all(film.rgb[j, i] == 0.0)
                continue
            x = np.array([o[0], o[1], math.sqrt(1.0 - b2)])  # the hit on the unit sphere
            n = x
            # VRML97 4.14.4: ambient of the point light (attenuation 1 here) plus each light's
            # diffuse term (specular colour is 0 by default); both lights see the point unless
            # N.L <= 0, the sphere being alone.
            want = p_amb * 0.2 * diffuse  # material ambientIntensity 0.2
            lp = point - x
            lp /= np.linalg.norm(lp)
            want = want + p_int * max(n @ lp, 0.0) * diffuse
            ld = -d_dir / np.linalg.norm(d_dir)
            want = want + d_int * max(n @ ld, 0.0) * diffuse
            np.testing.assert_allclose(film.rgb[j, i], want, rtol=1e-12, atol=1e-15)
            checked += 1
    assert checked >= 20


def constant_depth(t, r, b2):
    """Constant extinction -ln(t) / (2 r) along the chord 2 sqrt(r^2 - b^2)."""
    return -math.log(t) / (2 * r) * 2 * math.sqrt(max(r * r - b2, 0.0))


def quadratic_depth(t, r, b2):
    """f = 1 - u^2: a chord at distance b from the centre has optical depth
    sigma0 r (4/3) h^3, h = sqrt(1 - b^2 / r^2), and sigma0 = -ln(t) / (2 r 2/3)."""
    half = math.sqrt(max(1 - b2 / (r * r), 0.0))
    return -math.log(t) / (2 * r * 2 / 3) * r * 4 / 3 * half**3


@pytest.mark.parametrize(
    "profile,depth,t",
    [(None, constant_depth, t) for t in (0.9, 0.3, 1e-3)]
    + [("quadratic", quadratic_depth, t) for t in (0.9, 0.3)],
)
def test_gas_sphere_pixel_is_the_closed_form(profile, depth, t):
    r, c = 0.8, np.array([0.7, 0.4, 0.1])
    scene = gt.Scene.from_arrays(
        [[0.1, -0.2, 0.0]], r, colors=[[0, 0, 0]], transparency=[t], emissive=[c],
        headlight=False, profile=profile,
    )
    cam_pos, h, w_px, h_px = (0.1, -0.2, 4.0), 2.0, 11, 11
    cam = gt.Camera.look_at(cam_pos, (0.1, -0.2, 0.0), (0, 1, 0), ortho_height=h)
    film = gt.render(scene, cam, w_px, h_px, sampler="center")
    inside = 0
    for j in range(h_px):
        for i in range(w_px):
            o = ortho_pixel_ray(cam_pos, h, w_px, h_px, i, j)
            b2 = (o[0] - 0.1) ** 2 + (o[1] + 0.2) ** 2
            tau = depth(t, r, b2)
            want = c * -np.expm1(-tau)
            np.testing.assert_allclose(film.rgb[j, i], want, rtol=1e-12, atol=1e-300)
            inside += tau > 0
    assert inside >= 30
    # The centre pixel's chord is the diameter: 1 - transparency, whatever the profile.
    np.testing.assert_allclose(film.rgb[5, 5], c * (1 - t), rtol=1e-12)


def test_profile_keyword_renders_like_the_cli_and_refuses_bad_names(tmp_path, gtsphere_cli):
    data = cloud(gas=True)
    wrl = tmp_path / "g.wrl"
    wrl.write_text(vrml_of(*data))
    out = tmp_path / "g.npy"
    gtsphere_cli("render", wrl, "-o", out, "--width", 12, "--height", 10, "--spp", 1,
                 "--profile", "gaussian:0.25", "--quiet")
    scene = gt.load(wrl, profile="gaussian", profile_width=0.25)
    film = gt.render(scene, None, 12, 10, spp=1)
    assert np.array_equal(film.rgb, np.load(out))
    assert not np.array_equal(film.rgb, gt.render(gt.load(wrl), None, 12, 10, spp=1).rgb)
    with pytest.raises(ValueError, match="unknown density profile `fuzzy`"):
        gt.load(wrl, profile="fuzzy")
    with pytest.raises(ValueError, match="gaussian width 2"):
        gt.Scene.from_arrays([[0, 0, 0]], 1.0, transparency=[0.5], profile="gaussian", profile_width=2.0)
    with pytest.raises(ValueError, match="width is the gaussian profile's"):
        gt.Scene.from_arrays([[0, 0, 0]], 1.0, transparency=[0.5], profile_width=0.5)


def test_one_prepared_scene_two_cameras_equals_two_fresh_renders():
    data = cloud(gas=True)
    cams = [
        gt.Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0)),
        gt.Camera.look_at((4, 1, 2), (0, 0, 0), (0, 1, 0), fov=0.6),
    ]
    shared = scene_of(*data)
    twice = [gt.render(shared, c, 32, 24, spp=2) for c in cams]
    fresh = [gt.render(scene_of(*data), c, 32, 24, spp=2) for c in cams]
    for a, b in zip(twice, fresh):
        assert np.array_equal(a.rgb, b.rgb)
        assert np.array_equal(a.error, b.error)
    assert not np.array_equal(twice[0].rgb, twice[1].rgb)


def test_threads_do_not_change_the_pixels():
    scene = scene_of(*cloud(gas=True))
    cam = gt.Camera.frame(scene, direction=(0, -1, -1), up=(0, 1, 0))
    one = gt.render(scene, cam, 40, 30, spp=2, threads=1)
    two = gt.render(scene, cam, 40, 30, spp=2, threads=2)
    assert np.array_equal(one.rgb, two.rgb)


def test_aovs_and_film_arrays():
    scene = gt.Scene.from_arrays([[0, 0, 0], [3, 0, 0]], [1.0, 0.5])
    cam = gt.Camera.look_at((0, 0, 5), (0, 0, 0), (0, 1, 0))
    film = gt.render(scene, cam, 20, 10, spp=1, aovs=("depth", "normal", "id"), sampler="center")
    assert film.alpha.shape == film.depth.shape == film.id.shape == film.error.shape == (10, 20)
    assert film.normal.shape == (10, 20, 3) and film.id.dtype == np.int64
    centre = film.id[5, 10]
    assert centre == 0 and film.depth[4, 10] == pytest.approx(4.0, abs=0.2)
    assert film.id[0, 0] == -1 and np.isinf(film.depth[0, 0])
    np.testing.assert_allclose(np.linalg.norm(film.normal[film.id >= 0], axis=1), 1.0, rtol=1e-12)
    plain = gt.render(scene, cam, 20, 10, spp=1, sampler="center")
    assert plain.depth is None and plain.normal is None and plain.id is None


def test_load_renders_like_the_cli(tmp_path, gtsphere_cli):
    data = cloud()
    wrl = tmp_path / "c.wrl"
    wrl.write_text(vrml_of(*data))
    out = tmp_path / "c.npy"
    gtsphere_cli("render", wrl, "-o", out, "--width", 30, "--height", 20, "--spp", 2, "--quiet")
    scene = gt.load(wrl)
    assert len(scene) == len(data[0]) and scene.lights == 2 and not scene.headlight
    film = gt.render(scene, gt.Camera.from_scene(scene), 30, 20, spp=2)
    assert np.array_equal(film.rgb, np.load(out))
    # camera=None is the same default camera.
    assert np.array_equal(gt.render(scene, None, 30, 20, spp=2).rgb, film.rgb)


def test_fov_across_the_width_renders_like_the_cli(tmp_path, gtsphere_cli):
    # A Viewpoint whose fieldOfView spans the image width, as PyMOL writes it.
    wrl = tmp_path / "w.wrl"
    wrl.write_text(
        "#VRML V2.0 utf8\n"
        'Viewpoint { position 0 0 6 fieldOfView 0.9 description "Z view" }\n'
        "Shape { appearance Appearance { material Material { } } geometry Sphere { } }\n"
    )
    out = tmp_path / "w.npy"
    gtsphere_cli("render", wrl, "-o", out, "--width", 32, "--height", 20, "--spp", 1,
                 "--fov-across", "width", "--quiet")
    scene = gt.load(wrl)
    wide = gt.Camera.from_scene(scene, fov_across="width", size=(32, 20))
    assert np.array_equal(gt.render(scene, wide, 32, 20, spp=1).rgb, np.load(out))
    # Across the height of a 32 x 20 image is the smaller side: the VRML97 reading.
    assert gt.Camera.from_scene(scene, fov_across="height", size=(32, 20)).fov == 0.9
    assert wide.fov < 0.9
    with pytest.raises(ValueError, match="needs the image's size"):
        gt.Camera.from_scene(scene, fov_across="width")
    with pytest.raises(ValueError, match="fov_across"):
        gt.Camera.from_scene(scene, fov_across="diagonal", size=(32, 20))  # type: ignore[arg-type]


def test_options_after_the_size_are_keywords_and_a_film_shows_as_png():
    scene = gt.Scene.from_arrays([[0, 0, 0]], 1.0)
    cam = gt.Camera.frame(scene)
    with pytest.raises(TypeError):
        gt.render(scene, cam, 8, 6, 4)
    film = gt.render(scene, cam, 8, 6, spp=1)
    png = film._repr_png_()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    # The IHDR chunk: width and height as big-endian u32.
    assert int.from_bytes(png[16:20], "big") == 8 and int.from_bytes(png[20:24], "big") == 6
    assert repr(film).startswith("<gtsphere.Film 8x6,")


def test_progress_callback_and_its_exception_stops_the_render():
    scene = scene_of(*cloud())
    cam = gt.Camera.frame(scene)
    seen = []
    gt.render(scene, cam, 64, 64, spp=1, progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1] == (16, 16)
    assert all(t == 16 and 0 <= d <= 16 for d, t in seen)

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop

    with pytest.raises(Stop):
        gt.render(scene, cam, 256, 256, spp=64, progress=stop)
    # The scene stays usable.
    assert gt.render(scene, cam, 8, 8, spp=1).rgb.shape == (8, 8, 3)


def test_headlight_casts_no_shadow_unless_asked():
    # A small sphere in front of a large one, off the view axis, lit by the headlight alone:
    # carried by the viewer (the default) it lights every visible point as N.L says; as a
    # strict directional light (headlight_shadows=True) it leaves a crescent in shadow.
    centers = [[0.0, 0.0, 0.0], [0.6, 0.4, 2.5]]
    scene = gt.Scene.from_arrays(centers, [1.0, 0.25], colors=[[0.8, 0.6, 0.4], [0.2, 0.9, 0.3]])
    cam = gt.Camera.look_at((0, 0, 6), (0, 0, 0), (0, 1, 0), fov=0.8)
    carried = gt.render(scene, cam, 48, 48, sampler="center")
    strict = gt.render(scene, cam, 48, 48, sampler="center", headlight_shadows=True)
    lit = carried.rgb.max(axis=2) > 0
    dark = strict.rgb.max(axis=2) == 0
    crescent = int(np.count_nonzero(lit & dark))
    assert crescent > 0
    # Elsewhere the two agree to the last bit.
    same = ~(lit & dark)
    assert np.array_equal(carried.rgb[same], strict.rgb[same])


def sphere_form_factor(cos_theta, sin_alpha):
    """The cosine-weighted fraction of a hemisphere covered by one cap of angular radius alpha
    whose axis is at theta from the normal (Snyder 1996; Lagarde and de Rousiers 2014)."""
    x, s2 = cos_theta, sin_alpha**2
    if x * x > s2:
        return max(x * s2, 0.0)
    cot = math.sqrt(1.0 / s2 - 1.0)
    sin_theta = math.sqrt(1.0 - x * x)
    y = -cot * x / sin_theta
    z = sin_theta * math.sqrt(max(1.0 - y * y, 0.0))
    return max(((x * math.acos(max(-1.0, min(1.0, y))) - cot * z) * s2 + math.atan(z / cot)) / math.pi, 0.0)


def test_ambient_occlusion_of_a_sphere_beside_another_is_the_form_factor():
    # Two unit spheres touching at x = 1; each pixel on the first sees the second as one cap.
    scene = gt.Scene.from_arrays([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], 1.0, headlight=False)
    cam_pos, h, w_px, h_px = (0.0, 0.0, 5.0), 2.5, 11, 9
    cam = gt.Camera.look_at(cam_pos, (0, 0, 0), (0, 1, 0), ortho_height=h)
    film = gt.render(scene, cam, w_px, h_px, sampler="center", integrator="ao", aovs=["id"])
    checked = 0
    for j in range(h_px):
        for i in range(w_px):
            o = ortho_pixel_ray(cam_pos, h, w_px, h_px, i, j)
            b2 = o[0] ** 2 + o[1] ** 2
            if b2 >= 1.0 or film.id[j, i] != 0:
                continue
            x = np.array([o[0], o[1], math.sqrt(1.0 - b2)])
            to = np.array([2.0, 0.0, 0.0]) - x
            d = np.linalg.norm(to)
            want = 1.0 - sphere_form_factor(float(x @ to / d), 1.0 / d)
            np.testing.assert_allclose(film.rgb[j, i], [want] * 3, rtol=0, atol=1e-7)
            checked += 1
    assert checked >= 15
    # A reach shorter than the gap to the other sphere: nothing occludes.
    far = gt.render(scene, cam, w_px, h_px, sampler="center", integrator="ao", ao_reach=1e-3, aovs=["id"])
    assert np.all(far.rgb[far.id == 0] == 1.0)
    for bad in [dict(ao_reach=0.0), dict(ao_reach=float("nan")), dict(ao_weighting="flat")]:
        with pytest.raises(ValueError, match="ao_"):
            gt.render(scene, cam, 4, 4, integrator="ao", **bad)


def test_the_ao_channel_is_the_ao_picture_beside_a_lit_one():
    centers, radii, colors, _, _ = cloud(n=40, seed=5)
    scene = scene_of(centers, radii, colors, None, None)
    cam = gt.Camera.frame(scene)
    lit = gt.render(scene, cam, 24, 18, sampler="center", aovs=["ao"], ao_reach=0.5)
    ao = gt.render(scene, cam, 24, 18, sampler="center", integrator="ao", ao_reach=0.5)
    hit = ao.alpha > 0
    assert hit.sum() > 50
    np.testing.assert_array_equal(lit.ao[hit], ao.rgb[..., 0][hit])
    assert np.all(np.isnan(lit.ao[~hit]))


def test_ambient_occlusion_on_a_box_under_a_sphere_is_the_spheres_form_factor(tmp_path):
    # A floor Box (top face at z = 0) under a unit sphere at height 1.5: each pixel on the
    # floor sees the sphere as one cap, about the face's normal +z.
    wrl = tmp_path / "floor.wrl"
    wrl.write_text(
        "#VRML V2.0 utf8\n"
        "Transform { translation 0 0 -0.1 children Shape { geometry Box { size 8 8 0.2 } } }\n"
        "Transform { translation 0 0 1.5 children Shape { geometry Sphere { radius 1 } } }\n"
    )
    scene = gt.load(wrl)
    cam_pos, h, w_px, h_px = (0.0, 0.0, 5.0), 6.0, 13, 11
    cam = gt.Camera.look_at(cam_pos, (0, 0, 0), (0, 1, 0), ortho_height=h)
    film = gt.render(scene, cam, w_px, h_px, sampler="center", integrator="ao", aovs=["id"])
    centre = np.array([0.0, 0.0, 1.5])
    checked = 0
    for j in range(h_px):
        for i in range(w_px):
            if film.id[j, i] != 1:
                continue
            o = ortho_pixel_ray(cam_pos, h, w_px, h_px, i, j)
            x = np.array([o[0], o[1], 0.0])
            to = centre - x
            d = np.linalg.norm(to)
            want = 1.0 - sphere_form_factor(float(to[2] / d), 1.0 / d)
            np.testing.assert_allclose(film.rgb[j, i], [want] * 3, rtol=0, atol=1e-9)
            checked += 1
    assert checked >= 80
    # The approximations know spheres only; a closed cylinder is an occluder of exact AO (to
    # the tolerance), an open one is not.
    with pytest.raises(ValueError, match="knows spheres only"):
        gt.render(scene, cam, 4, 4, integrator="ao", ao_method="mc")
    text = wrl.read_text()
    wrl.write_text(text + "Shape { geometry Cylinder { } }\n")
    film = gt.render(gt.load(wrl), cam, 4, 4, integrator="ao")
    assert np.all(film.error <= 1e-4 * 1.000001)
    wrl.write_text(text + "Shape { geometry Cylinder { top FALSE } }\n")
    with pytest.raises(ValueError, match="1 open cylinders or cones"):
        gt.render(gt.load(wrl), cam, 4, 4, integrator="ao")
