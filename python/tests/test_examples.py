"""Every script in examples/ runs and its textbook values agree with robodyn's (each asserts it)."""

from __future__ import annotations

import runpy
import sys

import pytest
from conftest import REPOSITORY

EXAMPLES = sorted(p for p in (REPOSITORY / "examples").glob("*.py") if not p.name.startswith("_"))


def test_there_is_an_example_per_section_of_the_notes_dynamics():
    assert {p.stem for p in EXAMPLES} >= {"coriolis", "mass_matrix_three_ways", "cartesian_dynamics", "inertia_tensor", "free_floating_body", "energy_momentum"}


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(script, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(sys, "path", [str(script.parent), *sys.path])
    # the pages and figures an example writes land in its working folder
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(script), run_name="__main__")
    assert "textbook" in capsys.readouterr().out
