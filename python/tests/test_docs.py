"""docs/python.md's example runs as written: every ```python block, in order, in one
namespace, in a folder holding `tiny/` (the simulated tiny street)."""

import os
import re

from conftest import ROOT


def test_docs_example_runs(sim, tmp_path, capsys):
    text = (ROOT / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 3
    (tmp_path / "tiny").symlink_to(sim, target_is_directory=True)
    old = os.getcwd()
    os.chdir(tmp_path)
    try:
        ns = {}
        for b in blocks:
            exec(compile(b, "docs/python.md", "exec"), ns)
    finally:
        os.chdir(old)
    out = capsys.readouterr().out
    assert "edges," in out and "quality" in out and "left candidate" in out
    assert ns["edges"]["features"] and ns["line"].left is not None
