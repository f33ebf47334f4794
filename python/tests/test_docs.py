"""The Python API page (docs/python.md) and python/README.md: every ```python block runs, in
order, as one script (blocks starting with `>>>` as doctests) in an empty folder with a copy
of the repository's samples/, so that the pages show what the package does."""

import inspect
import pathlib
import shutil

import pytest

import gtsphere as gt
from markdown_blocks import python_blocks, run_blocks

ROOT = pathlib.Path(__file__).resolve().parents[2]
API_PAGE = ROOT / "docs" / "python.md"
PAGES = [API_PAGE, ROOT / "python" / "README.md"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_python_example_of_the_page_runs(page, tmp_path, monkeypatch):
    blocks = python_blocks(page)
    assert blocks, f"{page} has no ```python block"
    shutil.copytree(ROOT / "samples", tmp_path / "samples")
    monkeypatch.chdir(tmp_path)
    run_blocks(page, blocks, {"__name__": "__main__"})


def test_the_api_page_names_every_public_name_and_render_keyword():
    text = API_PAGE.read_text(encoding="utf-8")
    missing = [
        name
        for name in gt.__all__
        if f"`gt.{name}" not in text and f"`{name}`" not in text
    ]
    assert not missing, f"docs/python.md does not name {missing}"
    positional = ("scene", "camera", "width", "height")
    keywords = [k for k in inspect.signature(gt.render).parameters if k not in positional]
    unexplained = [k for k in keywords if f"| `{k}` |" not in text]
    assert not unexplained, f"render keywords without a row in docs/python.md: {unexplained}"
