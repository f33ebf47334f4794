"""Shared helpers: the `gtsphere` command (for comparisons with the CLI) and small scenes."""

import os
import pathlib
import shutil
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_binary():
    """The gtsphere command: $GTSPHERE_BIN, else the workspace's debug or release build."""
    env = os.environ.get("GTSPHERE_BIN")
    if env:
        return env
    for profile in ("debug", "release"):
        p = ROOT / "target" / profile / "gtsphere"
        if p.exists():
            return str(p)
    found = shutil.which("gtsphere")
    if found:
        return found
    if os.environ.get("CI"):
        pytest.fail("the gtsphere command is not built (cargo build) and GTSPHERE_BIN is unset")
    pytest.skip("the gtsphere command is not built (run cargo build)")


@pytest.fixture
def gtsphere_cli():
    """Runs the gtsphere command with the given arguments; returns the completed process."""
    binary = cli_binary()

    def run(*args, check=True):
        p = subprocess.run(
            [binary, *map(str, args)], capture_output=True, text=True, timeout=600
        )
        if check and p.returncode != 0:
            raise AssertionError(f"gtsphere {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def mypy(tmp_path_factory):
    """Runs `python -m MODULE ARGS` for mypy's modules (mypy, mypy.stubtest) in an empty
    folder with an empty configuration, so that `gtsphere` is the installed package, not the
    source folder; returns the completed process. Skips when mypy is not installed, except
    under CI (pip install "./python[test]" installs it)."""
    import importlib.util
    import sys

    if importlib.util.find_spec("mypy") is None:
        if os.environ.get("CI"):
            pytest.fail('mypy is not installed: pip install "./python[test]"')
        pytest.skip('mypy is not installed (pip install "./python[test]")')
    folder = tmp_path_factory.mktemp("mypy")
    config = folder / "mypy.ini"
    config.write_text("[mypy]\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MYPYPATH")}

    def run(module, *args):
        return subprocess.run(
            [sys.executable, "-m", module, *map(str, args)],
            cwd=folder, env=env, capture_output=True, text=True, timeout=600,
        )

    run.folder = folder
    run.config = config
    return run
