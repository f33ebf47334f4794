"""The examples in examples/ run (at small sizes, through their own arguments), write their
pictures and show their progress."""

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run_example(name, *args, cwd):
    p = subprocess.run(
        [sys.executable, str(ROOT / "examples" / name), *map(str, args)],
        cwd=cwd, capture_output=True, timeout=600,
    )
    assert p.returncode == 0, p.stderr.decode()
    return p.stdout.decode()  # bytes decoded here: text mode would turn "\r" into "\n"


def test_particles(tmp_path):
    out = run_example("particles.py", 64, 48, cwd=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gas.png", "opaque.png"]
    for name in ("opaque", "gas"):
        assert f"\r{name}: 100 %" in out, out  # the progress callback's last call
        assert f"\r{name}: " in out and "max error" in out


def test_turntable(tmp_path):
    out = run_example("turntable.py", 500, 24, cwd=tmp_path)
    frames = sorted(p.name for p in (tmp_path / "turntable").iterdir())
    assert frames == [f"frame_{k:02d}.png" for k in range(36)]
    assert "\rframe 36/36: 100 %" in out and out.count(" s\n") == 36, out
