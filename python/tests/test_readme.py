"""The README's examples run as written: each Python block on its own, in a fresh subprocess in an
empty temporary folder (not the repository), with the interpreter of a clean environment that has
only the wheel and its `robots` and `distributed` extras when the test command provides one
(ROBODYN_CLEAN_PYTHON), else this one."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from conftest import REPOSITORY

import robodyn

README = (REPOSITORY / "README.md").read_text()
PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", README, re.S)
#: a clean environment's interpreter (scripts/test makes one), or this one
PYTHON = os.environ.get("ROBODYN_CLEAN_PYTHON", sys.executable)
#: the longest a README block may take (the simulation block is the slowest)
BLOCK_TIMEOUT_S = 300


def test_the_readme_has_python_blocks():
    assert len(PYTHON_BLOCKS) >= 8


@pytest.mark.parametrize("block", PYTHON_BLOCKS, ids=[f"block{k}" for k in range(len(PYTHON_BLOCKS))])
def test_python_block_runs_on_its_own(block, tmp_path):
    script = tmp_path / "block.py"
    script.write_text(block)
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    # the block writes its figures without a display
    environment["MPLBACKEND"] = "Agg"
    result = subprocess.run([PYTHON, str(script)], cwd=tmp_path, env=environment, capture_output=True,
                            text=True, timeout=BLOCK_TIMEOUT_S)
    assert result.returncode == 0, f"the block failed:\n{block}\n{result.stderr[-3000:]}"


def test_toml_example_loads(tmp_path):
    (block,) = re.findall(r"```toml\n(.*?)```", README, re.S)
    path = tmp_path / "robot.toml"
    path.write_text(block)
    model = robodyn.load(path)
    assert model.joint_names == ["shoulder_pan"]
