"""Ctrl-C (SIGINT sent from another thread) stops a long render quickly and cleanly."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import gtsphere as gt


@pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="needs SIGINT")
def test_sigint_from_a_thread_stops_a_long_render_within_a_second():
    rng = np.random.default_rng(0)
    n = 2000
    scene = gt.Scene.from_arrays(
        rng.uniform(-1, 1, (n, 3)), 0.15, colors=rng.uniform(0, 1, (n, 3)),
        transparency=np.full(n, 0.3), headlight=False,
    )
    scene.add_point_light((3, 3, 3))
    cam = gt.Camera.frame(scene)
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    # Python turns SIGINT into KeyboardInterrupt only if SIGINT was not ignored when it
    # started (a command started in the background of a non-interactive shell ignores it).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, interrupt)
    start = time.monotonic()
    timer.start()
    try:
        # Many minutes of work at this size: it cannot finish before the signal.
        with pytest.raises(KeyboardInterrupt):
            gt.render(scene, cam, 1024, 1024, spp=256, tol=1e-6)
    finally:
        stopped = time.monotonic()
        timer.join()
        signal.signal(signal.SIGINT, previous)
    assert sent, "the signal was sent"
    assert stopped - sent[0] < 1.0, f"stopped {stopped - sent[0]:.2f} s after the signal"
    assert stopped - start >= 0.5
    # The interpreter and the scene are still usable.
    film = gt.render(scene, cam, 16, 16, spp=1)
    assert film.rgb.shape == (16, 16, 3) and np.isfinite(film.rgb).all()


def test_the_gil_is_released_while_rendering():
    rng = np.random.default_rng(1)
    n = 1000
    scene = gt.Scene.from_arrays(
        rng.uniform(-1, 1, (n, 3)), 0.1, transparency=np.full(n, 0.5), headlight=False
    )
    scene.add_point_light((3, 3, 3))
    cam = gt.Camera.frame(scene)
    done = threading.Event()
    result = []

    def work():
        # About 1 s on one thread (the lit gas is the slow part; 64 x 64 became too fast).
        result.append(gt.render(scene, cam, 128, 128, spp=2, threads=1))
        done.set()

    t = threading.Thread(target=work)
    stamps = []
    t.start()
    while not done.is_set():
        stamps.append(time.monotonic())  # Python running in this thread meanwhile
    t.join()
    assert result and result[0].rgb.shape == (128, 128, 3)
    elapsed = stamps[-1] - stamps[0]
    assert elapsed > 0.3, "the render must take long enough to tell"
    # Were the GIL held for the render, this thread would stand still for all of it: one
    # gap as long as the render. Released, it runs but for the 50 ms polls' brief takes.
    gap = max(b - a for a, b in zip(stamps, stamps[1:]))
    assert gap < 0.25 * elapsed, (gap, elapsed)


def test_changing_a_scene_while_it_renders_says_why_and_changes_nothing():
    rng = np.random.default_rng(2)
    n = 500
    scene = gt.Scene.from_arrays(
        rng.uniform(-1, 1, (n, 3)), 0.15, transparency=np.full(n, 0.4), headlight=False
    )
    scene.add_point_light((3, 3, 3))
    cam = gt.Camera.frame(scene)
    started, stop = threading.Event(), threading.Event()

    class Stop(Exception):
        pass

    def progress(done, total):
        started.set()
        if stop.is_set():
            raise Stop

    ended = []

    def work():
        # Minutes of work, stopped through the callback once the changes have been tried.
        try:
            gt.render(scene, cam, 1024, 1024, spp=64, threads=1, progress=progress)
        except Exception as e:
            ended.append(e)

    t = threading.Thread(target=work)
    t.start()
    try:
        assert started.wait(60), "the render reports progress"
        changes = [
            lambda: scene.add_point_light((0, 3, 0)),
            lambda: scene.add_directional_light((0, -1, 0)),
            lambda: setattr(scene, "headlight", True),
            lambda: setattr(scene, "background", (1, 1, 1)),
        ]
        for change in changes:
            with pytest.raises(RuntimeError, match="^the scene is being rendered; change it after the render$"):
                change()
    finally:
        stop.set()
        t.join()
    assert len(ended) == 1 and isinstance(ended[0], Stop), ended
    assert scene.lights == 1 and not scene.headlight and scene.background == (0, 0, 0)
    # After the render the scene changes as usual.
    scene.add_point_light((0, 3, 0))
    assert scene.lights == 2
