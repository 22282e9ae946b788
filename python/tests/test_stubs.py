"""mypy's stubtest keeps ``python/robodyn/_core.pyi`` true to the compiled extension: every class,
function, method and property the extension has, with the parameters it takes, and nothing it
lacks. Nothing is allowlisted: the extension's signatures carry what stubtest compares (a default
the binding computes shows as ``...`` at run time, and is written so in the stubs)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import robodyn
from conftest import REPOSITORY

#: stubtest type-checks the package around the stubs; the rest of it has its own tests, so only
#: the errors in robodyn._core's stubs count here
MYPY_CONFIG = """\
[mypy]
python_version = 3.10
cache_dir = {cache}

[mypy-robodyn.*]
ignore_errors = True

[mypy-robodyn._core]
ignore_errors = False

[mypy-sympy.*]
ignore_missing_imports = True
"""


def test_the_core_stubs_match_the_extension(tmp_path):
    config = tmp_path / "mypy.ini"
    config.write_text(MYPY_CONFIG.format(cache=REPOSITORY / ".mypy_cache" / "stubtest"))
    # the stubs are read from the source tree; the extension is the one the tests import
    imported_from = str(Path(robodyn.__file__).resolve().parents[1])
    environment = {**os.environ, "MYPYPATH": str(REPOSITORY / "python"),
                   "PYTHONPATH": os.pathsep.join([imported_from, os.environ.get("PYTHONPATH", "")])}
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "robodyn._core", "--mypy-config-file", str(config)],
        capture_output=True, text=True, cwd=tmp_path, env=environment,
    )
    assert result.returncode == 0, result.stdout + result.stderr
