"""Each page in a real headless browser (Debian's chromium): not blank, and every image loaded.

``make test`` installs chromium (the ``test-deps`` target). Two browser runs per page:
a screenshot, whose pixels must not be a blank page, and a DOM dump of a copy of the
page carrying a probe script that records, after the load event, how many images
there are and how many decoded (``naturalWidth > 0``).
"""

from __future__ import annotations

import base64
import re
import shutil
import subprocess
from pathlib import Path

import cv2
import numpy as np
import pytest

pytestmark = pytest.mark.slow

_PROBE = """<script>
window.addEventListener("load", () => {
  const images = Array.from(document.images);
  document.body.dataset.images = images.length;
  document.body.dataset.loaded = images.filter((i) => i.complete && i.naturalWidth > 0).length;
});
</script>
</body>"""


def _chromium(tmp: Path, *args: str) -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.fail("chromium not found: `make test-deps` installs it (Debian package chromium)")
    flags = [
        "--headless",
        "--no-sandbox",  # tests may run as root (containers, CI)
        "--disable-gpu",
        "--hide-scrollbars",
        "--no-first-run",
        f"--user-data-dir={tmp / 'profile'}",
    ]
    done = subprocess.run(
        [exe, *flags, *args], capture_output=True, text=True, timeout=180, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


@pytest.mark.parametrize(
    "page", ["run", "unscored", "score", "sweep", "compare", "reproduce", "bench"]
)
def test_page_renders_with_every_image_loaded(
    pages: dict[str, Path], page: str, tmp_path: Path
) -> None:
    source = pages[page]
    html = source.read_text(encoding="utf-8")
    expected = len(re.findall(r"<img\b", html))
    assert expected > 0

    shot = tmp_path / f"{page}.png"
    _chromium(tmp_path, "--window-size=1280,1600", f"--screenshot={shot}", source.as_uri())
    pixels = cv2.imread(str(shot), cv2.IMREAD_GRAYSCALE)
    assert pixels is not None and pixels.shape == (1600, 1280)
    # A blank page is one flat colour; ours has text, tables and plots on white.
    assert pixels.std() > 20
    assert (pixels < 200).mean() > 0.005

    assert _images_loaded(html, tmp_path) == (expected, expected)


def _images_loaded(html: str, tmp: Path) -> tuple[int, int]:
    """(images, images decoded) once ``html`` has loaded in the browser."""
    probe = tmp / "probe.html"  # images are inline: a copy elsewhere shows the same
    probe.write_text(html.replace("</body>", _PROBE), encoding="utf-8")
    dom = _chromium(tmp, "--virtual-time-budget=10000", "--dump-dom", probe.as_uri())
    found = re.search(r'<body data-images="(\d+)" data-loaded="(\d+)"', dom)
    assert found is not None, "the probe did not run: " + dom[:300]
    return int(found[1]), int(found[2])


def test_the_probe_sees_a_broken_image(tmp_path: Path) -> None:
    png = base64.b64encode(cv2.imencode(".png", np.full((8, 8, 3), 90, np.uint8))[1].tobytes())
    page = (
        f'<!DOCTYPE html><html><body><img src="data:image/png;base64,{png.decode()}">'
        '<img src="data:image/png;base64,bm90IGEgcG5n"></body></html>'  # "not a png"
    )
    assert _images_loaded(page, tmp_path) == (2, 1)
