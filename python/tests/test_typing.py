"""mypy --strict passes on every Python block of the README and the guide (test_readme's pages) and
every script in examples/, as a user's type checker sees them (robodyn's stubs, simulate's overloads)."""

from __future__ import annotations

import subprocess
import sys

from conftest import REPOSITORY
from test_readme import BLOCKS

#: simulate's overloads: one configuration gives a Trajectory, a batch a list of them
OVERLOADS = '''
import robodyn
from robodyn import Trajectory

m = robodyn.load("ur5")
one: Trajectory = robodyn.simulate(m, m.neutral(), t_end=0.01)
many: list[Trajectory] = robodyn.simulate(m, m.random_configuration(n=2, seed=0), t_end=0.01)
listed: Trajectory = robodyn.simulate(m, [0.0] * 6, t_end=0.01)
print(one.t, many[0].q, listed.energy)
'''


def test_mypy_strict_on_the_readme_and_examples(tmp_path):
    files = []
    for k, (_, _, block) in enumerate(BLOCKS):
        path = tmp_path / f"doc_block_{k}.py"
        path.write_text(block)
        files.append(str(path))
    (tmp_path / "overloads.py").write_text(OVERLOADS)
    files.append(str(tmp_path / "overloads.py"))
    files += [str(p) for p in sorted((REPOSITORY / "examples").glob("*.py"))]
    result = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--config-file", str(REPOSITORY / "pyproject.toml"),
         "--cache-dir", str(REPOSITORY / ".mypy_cache"), *files],
        capture_output=True, text=True, cwd=tmp_path,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert f"no issues found in {len(files)} source files" in result.stdout
