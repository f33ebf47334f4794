"""The type hints (gtsphere/_native.pyi) against the installed module: mypy's stubtest checks
every name, class, signature and default; the Literal option types are checked against the
values render, from_arrays and load accept; and the examples and the documentation's code
type-check against the hints."""

import ast
import pathlib
import re

import pytest

import gtsphere as gt
from markdown_blocks import as_script, python_blocks

ROOT = pathlib.Path(__file__).resolve().parents[2]
STUB = pathlib.Path(gt.__file__).with_name("_native.pyi")


def test_stubs_match_the_module(mypy):
    assert STUB.exists() and STUB.with_name("py.typed").exists(), "the wheel ships the hints"
    # No allowlist: every difference stubtest can see is an error.
    p = mypy("mypy.stubtest", "--mypy-config-file", mypy.config, "gtsphere")
    assert p.returncode == 0, p.stdout + p.stderr
    assert "Success: no issues found" in p.stdout


def literal_values(alias):
    """The strings of `_Alias = Literal[...]` in the installed stub."""
    for node in ast.parse(STUB.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and [t.id for t in node.targets] == [alias]:
            sub = node.value
            assert isinstance(sub, ast.Subscript) and ast.unparse(sub.value) == "Literal"
            return {e.value for e in ast.walk(sub.slice) if isinstance(e, ast.Constant)}
    raise AssertionError(f"{alias} is not in {STUB}")


def quoted(message):
    return set(re.findall(r'"(\w+)"', message))


def test_literal_types_are_the_values_the_module_accepts():
    scene = gt.Scene.from_arrays([[0, 0, 0]], 1.0, transparency=[0.5])

    opaque = gt.Scene.from_arrays([[0, 0, 0], [1.5, 0, 0]], 1.0)
    integrators = literal_values("_Integrator")
    for name in integrators:
        # (Exact AO is for opaque spheres; a scene with gas is refused.)
        on = opaque if name == "ao" else scene
        gt.render(on, None, 4, 4, spp=2, integrator=name, step=0.1 if name == "march" else None)
    methods = literal_values("_AoMethod")
    for name in methods:
        gt.render(opaque, None, 4, 4, spp=1, integrator="ao", ao_method=name)
    with pytest.raises(ValueError) as bad:
        gt.render(opaque, None, 4, 4, integrator="ao", ao_method="other")
    assert quoted(str(bad.value)) == methods | {"other"}
    weightings = literal_values("_Weighting")
    for name in weightings:
        gt.render(opaque, None, 4, 4, spp=1, integrator="ao", ao_weighting=name)
    with pytest.raises(ValueError) as bad:
        gt.render(opaque, None, 4, 4, integrator="ao", ao_weighting="other")
    assert quoted(str(bad.value)) == weightings | {"other"}
    with pytest.raises(ValueError) as bad:
        gt.render(scene, None, 4, 4, integrator="other")
    assert quoted(str(bad.value)) == integrators | {"other"}

    samplers = literal_values("_Sampler")
    for name in samplers:
        gt.render(scene, None, 4, 4, spp=2, sampler=name)
    with pytest.raises(ValueError) as bad:
        gt.render(scene, None, 4, 4, sampler="other")
    assert quoted(str(bad.value)) == samplers | {"other"}

    aovs = literal_values("_Aov")
    # (The ao channel is exact AO: opaque spheres only.)
    film = gt.render(opaque, None, 4, 4, spp=2, aovs=sorted(aovs))
    assert all(getattr(film, name) is not None for name in aovs)
    with pytest.raises(ValueError) as bad:
        gt.render(scene, None, 4, 4, aovs=["other"])
    assert quoted(str(bad.value)) == aovs | {"other"}

    profiles = literal_values("_Profile")
    for name in profiles:
        gt.Scene.from_arrays([[0, 0, 0]], 1.0, transparency=[0.5], profile=name)
    with pytest.raises(ValueError, match=r"expected .*\)$") as bad:
        gt.Scene.from_arrays([[0, 0, 0]], 1.0, transparency=[0.5], profile="other")
    listed = re.search(r"expected (.*)\)$", str(bad.value)).group(1)
    assert set(re.split(r", | or ", listed)) == profiles


def test_examples_and_documentation_type_check(mypy):
    files = sorted((ROOT / "examples").glob("*.py"))
    pages = {ROOT / "docs" / "python.md": "docs_python_md.py",
             ROOT / "python" / "README.md": "python_readme_md.py"}
    for page, name in pages.items():
        # Line N of the script is line N of the page.
        (mypy.folder / name).write_text(as_script(page, python_blocks(page)))
        files.append(mypy.folder / name)
    p = mypy("mypy", "--config-file", mypy.config, "--check-untyped-defs",
             "--warn-unused-ignores", "--no-incremental", *files)
    out = p.stdout + p.stderr
    for page, name in pages.items():
        out = out.replace(str(mypy.folder / name), name).replace(name, str(page.relative_to(ROOT)))
    assert p.returncode == 0, out
