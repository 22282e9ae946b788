"""The README's examples run as written."""

from __future__ import annotations

import re

from conftest import REPOSITORY

import robodyn

README = (REPOSITORY / "README.md").read_text()


def test_python_examples_run():
    """In order, in one session, as a reader would run them."""
    blocks = re.findall(r"```python\n(.*?)```", README, re.S)
    assert len(blocks) >= 2
    session: dict = {}
    for block in blocks:
        exec(compile(block, "README.md", "exec"), session)


def test_toml_example_loads(tmp_path):
    (block,) = re.findall(r"```toml\n(.*?)```", README, re.S)
    path = tmp_path / "robot.toml"
    path.write_text(block)
    model = robodyn.load(path)
    assert model.joint_names == ["shoulder_pan"]
