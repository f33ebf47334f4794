"""The ```python blocks of a Markdown page, run in order in one namespace, and the same code
as one Python file with the page's line numbers (for a type checker).

A block whose first line starts with `>>>` is a doctest: its printed output must match
(with ELLIPSIS and NORMALIZE_WHITESPACE). Any other block runs as a script. Errors and
tracebacks name the page and its line numbers."""

import doctest
import pathlib
import re
import traceback
from dataclasses import dataclass

FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([\w+-]*)")
PYTHON = {"python", "py", "python3", "pycon"}


@dataclass
class Block:
    line: int  # the page's line number (1-based) of the block's first line of code
    text: str

    @property
    def is_doctest(self):
        return self.text.lstrip().startswith(">>>")


def python_blocks(path):
    """Every fenced block of the page whose language is Python, in order."""
    lines = pathlib.Path(path).read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, language = len(m.group(1)), m.group(2), m.group(3).lower()
        end = i + 1
        while end < len(lines) and not lines[end].strip().startswith(fence):
            end += 1
        if end == len(lines):
            raise ValueError(f"{path}:{i + 1}: the code block is not closed")
        if language in PYTHON:
            body = [line[indent:] for line in lines[i + 1 : end]]
            blocks.append(Block(i + 2, "\n".join(body) + "\n"))
        i = end + 1
    return blocks


def run_blocks(path, blocks, namespace):
    """Runs the blocks in order in `namespace` (a dict, updated); raises AssertionError with
    doctest's report, or the block's own exception, at the first failure."""
    path = str(path)
    for block in blocks:
        if block.is_doctest:
            test = doctest.DocTestParser().get_doctest(
                block.text, namespace, f"{path}:{block.line}", path, block.line - 1
            )
            runner = doctest.DocTestRunner(
                optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
            )
            report = []
            runner.run(test, out=report.append, clear_globs=False)
            namespace.update(test.globs)
            if runner.failures:
                raise AssertionError("".join(report))
        else:
            code = compile("\n" * (block.line - 1) + block.text, path, "exec")
            try:
                exec(code, namespace)
            except Exception:
                # The traceback's lines are read from the page: the example's own lines.
                raise AssertionError(
                    f"the example at {path}:{block.line} failed:\n{traceback.format_exc()}"
                ) from None


def as_script(path, blocks):
    """The blocks as one Python file whose line N is the page's line N (other lines blank):
    doctest prompts removed, doctest output lines left blank."""
    total = len(pathlib.Path(path).read_text(encoding="utf-8").splitlines())
    out = [""] * total
    for block in blocks:
        for k, line in enumerate(block.text.splitlines()):
            if block.is_doctest:
                stripped = line.lstrip()
                if stripped.startswith((">>> ", "... ")):
                    line = stripped[4:]
                elif stripped in (">>>", "..."):
                    line = ""
                else:
                    line = ""  # expected output
            out[block.line - 1 + k] = line
    return "\n".join(out) + "\n"
