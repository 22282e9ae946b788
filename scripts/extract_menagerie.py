"""Write out a git snapshot of MuJoCo Menagerie whose largest files are absent, and list those.

usage: python scripts/extract_menagerie.py GIT_DIR OUT [COMMIT]

A mirror that leaves out blobs over a size limit cannot be checked out or `git archive`d: this
writes every blob it has under OUT, file by file (git is called with argument lists, never through
a shell: a file name in some snapshots is a shell command), and lists the blobs it lacks in
OUT/ABSENT.txt, one path a line, for `scripts/menagerie_table.py --absent OUT/ABSENT.txt OUT`.
It prints the commit written.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def git(git_dir: str, *arguments: str) -> bytes:
    return subprocess.run(["git", "--git-dir", git_dir, *arguments], capture_output=True, check=True).stdout


def main(git_dir: str, out: str, commit: str = "HEAD") -> None:
    commit = git(git_dir, "rev-parse", commit).decode().strip()
    root = Path(out).resolve()
    absent: list[str] = []
    for entry in git(git_dir, "ls-tree", "-r", "-z", commit).split(b"\0"):
        if not entry:
            continue
        meta, name = entry.split(b"\t", 1)
        _, kind, blob = meta.split()
        path = name.decode()
        if kind != b"blob":
            continue
        contents = subprocess.run(["git", "--git-dir", git_dir, "cat-file", "blob", blob.decode()], capture_output=True)
        if contents.returncode != 0:
            absent.append(path)
            continue
        destination = (root / path).resolve()
        if root not in destination.parents:
            sys.exit(f"{path!r} lies outside {root}")
        destination.parent.mkdir(parents=True, exist_ok=True)
        destination.write_bytes(contents.stdout)
    (root / "ABSENT.txt").write_text("".join(f"{path}\n" for path in absent))
    print(commit)


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    main(*sys.argv[1:])
