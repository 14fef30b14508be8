"""The README's Python examples run as written: every ```python block saved as a script and run
from the repository root, as the README says to run them (`PYTHONPATH=build/python
/usr/bin/python3 script.py`), with the interpreter the module was built for
(tests/test_readme.cpp does the same for the shell examples). A script, not `python3 -c`: Dask's
local workers re-import the main script, which `-c` hides."""
import os
import re
import subprocess
import sys

import pytest

ROOT = os.environ.get("RTCOST_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def python_blocks():
    with open(os.path.join(ROOT, "README.md")) as f:
        text = f.read()
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def test_there_are_python_examples():
    assert len(python_blocks()) >= 2


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_python_example_runs_as_written(index, tmp_path):
    code = python_blocks()[index]
    script = tmp_path / "script.py"
    script.write_text(code)
    p = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"README python block {index}:\n{code}\n{p.stderr}"
    assert p.stdout.strip(), "an example prints what it computes"
