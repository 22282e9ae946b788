"""The documentation's examples run as written: each Python block of the README, the getting-started
page and the user guide (docs/guide/) on its own, in a fresh subprocess in an empty temporary folder
(not the repository), with the interpreter of a clean environment that has only the wheel and its
`robots` and `distributed` extras when the test command provides one (ROBODYN_CLEAN_PYTHON), else
this one. Every block runs: a page shows no Python it does not run (a shell line is a plain ``` block)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import REPOSITORY

import robodyn

#: the pages whose Python blocks are users' first code: the README, getting started, the guide
DOCUMENTS = [REPOSITORY / "README.md", REPOSITORY / "docs" / "getting-started.md",
             *sorted((REPOSITORY / "docs" / "guide").glob("*.md"))]
#: the guide's topics, each a page (the documentation site's navigation names the same files)
GUIDE_PAGES = {"loading-models", "kinematics", "dynamics", "derivatives", "constraints", "contacts", "mimic", "symbolic", "simulation", "scene-simulation",
               "viewer", "datasets", "conventions", "performance"}
#: a clean environment's interpreter (scripts/test makes one), or this one
PYTHON = os.environ.get("ROBODYN_CLEAN_PYTHON", sys.executable)
#: the longest a block may take (the simulation blocks are the slowest)
BLOCK_TIMEOUT_S = 300
#: the README is one screen or three; the guide pages hold the rest
README_MAX_LINES = 250


def python_blocks(path: Path) -> list[str]:
    """The ```python blocks of a Markdown file, in order."""
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


#: (page, index, code) of every Python block of the documents
BLOCKS = [(path.relative_to(REPOSITORY).as_posix(), k, block)
          for path in DOCUMENTS for k, block in enumerate(python_blocks(path))]


def test_the_readme_is_short_and_states_the_test_command():
    readme = (REPOSITORY / "README.md").read_text()
    assert len(readme.splitlines()) <= README_MAX_LINES
    # .ci/run runs "exactly the README's test command": the README's shell block names it
    command = re.search(r"The test command.*?\n```\n(\S+)", readme, re.S)
    assert command and command.group(1) == "./scripts/test"
    assert "\n./scripts/test\n" in (REPOSITORY / ".ci" / "run").read_text()


def test_every_guide_page_exists_and_has_python():
    assert {path.stem for path in DOCUMENTS if path.parent.name == "guide"} == GUIDE_PAGES
    for path in DOCUMENTS:
        assert python_blocks(path), f"{path.relative_to(REPOSITORY)} has no Python block"


@pytest.mark.parametrize("page,index,block", BLOCKS, ids=[f"{page}:{k}" for page, k, _ in BLOCKS])
def test_python_block_runs_on_its_own(page, index, block, tmp_path):
    script = tmp_path / "block.py"
    script.write_text(block)
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    # the block writes its figures without a display
    environment["MPLBACKEND"] = "Agg"
    result = subprocess.run([PYTHON, str(script)], cwd=tmp_path, env=environment, capture_output=True,
                            text=True, timeout=BLOCK_TIMEOUT_S)
    assert result.returncode == 0, f"block {index} of {page} failed:\n{block}\n{result.stderr[-3000:]}"


def test_dh_toml_example_loads(tmp_path):
    page = REPOSITORY / "docs" / "guide" / "loading-models.md"
    (block,) = re.findall(r"```toml\n(.*?)```", page.read_text(), re.S)
    path = tmp_path / "robot.toml"
    path.write_text(block)
    model = robodyn.load(path)
    assert model.joint_names == ["shoulder_pan"]
