"""mkdocs-gallery's configuration beyond mkdocs.yml: the files an example writes are shown.

An example that shows a robot moving writes the offline viewer page of its trajectory
(``trajectory.to_html("name.html")``, one self-contained file), and one may save a figure
(``trajectory.plot("name.png")``), into its working folder, as it would for a user running it.
mkdocs-gallery runs each example in ``examples/`` with that folder as the working folder; after
each code block, :func:`written_files` moves the pages and pictures the block wrote next to the
gallery's images and embeds them in the example's page (a viewer page in a frame), as the
matplotlib scraper does with the figures that pyplot holds.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

#: The height of an embedded viewer page in pixels (its width is the text's).
VIEWER_HEIGHT = 480
#: Pictures shown as images (those mkdocs-gallery takes as an example's figures).
PICTURES = {".png", ".svg", ".gif", ".jpg"}


def written_files(block: Any, script: Any, **kwargs: Any) -> str:
    """Markdown showing every ``*.html`` page and picture that the block wrote into the working
    folder, each moved into the gallery's images folder first. Pictures are numbered with the
    example's figures (the first one is its thumbnail in the gallery)."""
    images = Path(script.gallery.images_dir)
    images.mkdir(parents=True, exist_ok=True)
    markdown = ""
    for written in sorted(Path.cwd().iterdir()):
        if not written.is_file() or written.suffix not in PICTURES | {".html"}:
            continue
        if written.suffix in PICTURES:
            target = next(script.run_vars.image_path_iterator).with_suffix(written.suffix)
            written.replace(target)
            markdown += f"\n![{written.stem}](./images/{target.name})\n\n"
            continue
        name = f"mkd_glr_{script.src_py_file.stem}_{written.name}"
        written.replace(images / name)
        # the example's page is gallery/<example>/index.html (directory URLs): its images are one
        # level up; the Markdown link below is rewritten by MkDocs, the frame's address is not
        markdown += (
            f'\n<iframe class="robodyn-viewer" src="../images/{name}" height="{VIEWER_HEIGHT}" '
            f'title="3-D viewer: {written.stem}" loading="lazy"></iframe>\n\n'
            f"[Open the 3-D viewer in a page of its own](./images/{name})\n\n"
        )
    return markdown


conf = {
    "image_scrapers": ("matplotlib", written_files),
    # examples/_compare.py is a helper the examples import, not an example
    "ignore_pattern": r"/_",
    # every example runs (not only those named plot_*)
    "filename_pattern": r"/",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "show_memory": False,
}
