"""The repository stands alone: no file refers to anything beside it."""

from __future__ import annotations

import re
import subprocess

from conftest import REPOSITORY

#: paths a clone does not have: the folder beside the repository, and the notes' raw file names
OUTSIDE = re.compile(r"\.\./shared|shared/(seeds|mjcf|DESIGN)|\bseeds? 00[0-3]\b", re.IGNORECASE)


def tracked_text_files():
    names = subprocess.run(["git", "ls-files"], cwd=REPOSITORY, capture_output=True, text=True, check=True).stdout.split()
    for name in names:
        path = REPOSITORY / name
        if path.suffix in {".json", ".lock"} or not path.is_file():
            continue
        try:
            yield name, path.read_text()
        except UnicodeDecodeError:
            continue


def test_no_file_refers_beside_the_repository():
    offenders = [
        f"{name}:{number}: {line.strip()}"
        for name, text in tracked_text_files()
        if name != "python/tests/test_repository.py"
        for number, line in enumerate(text.splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not offenders, "files refer to paths a clone does not have:\n" + "\n".join(offenders)


def test_every_test_model_has_its_source_noted():
    readme = (REPOSITORY / "testdata" / "mjcf" / "README.md").read_text()
    for model in (REPOSITORY / "testdata" / "mjcf").glob("*.xml"):
        assert f"`{model.name}`" in readme, f"testdata/mjcf/README.md does not say where {model.name} comes from"
