"""docs/python.md's example runs as written from the repository root (here: a fresh directory
laid out like it, so that its outputs stay out of the sources)."""

import os
import pathlib
import re
import subprocess
import sys

import jointid
from conftest import SOURCE


def test_the_example_of_docs_python_md(tmp_path):
    text = (SOURCE / "docs" / "python.md").read_text()
    block = re.search(r"<!-- python-example:begin -->\n```python\n(.*?)```\n"
                      r"<!-- python-example:end -->", text, re.S)
    assert block, "no example between <!-- python-example:begin/end --> in docs/python.md"
    (tmp_path / "examples").symlink_to(SOURCE / "examples")
    (tmp_path / "out").mkdir()
    (tmp_path / "example.py").write_text(block.group(1))
    module = pathlib.Path(jointid.__file__).resolve().parents[1]  # PYTHONPATH may be relative
    env = {**os.environ, "PYTHONPATH": str(module)}
    done = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True,
                          text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert "k   = " in done.stdout and "k3  = " in done.stdout
