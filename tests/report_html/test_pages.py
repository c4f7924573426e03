"""The pages as files: outputs of a real run, no external reference, images that decode."""

from __future__ import annotations

import base64
import re
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import cv2
import numpy as np
import pytest

from tests.report_html.conftest import FRAMES

#: Attributes that make a browser fetch something.
SVG = "{http://www.w3.org/2000/svg}"
_URL_ATTRIBUTES = {"src", "href", "srcset", "poster", "data", "action", "formaction", "background"}


class _Refs(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.refs: list[str] = []
        self.images: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name in _URL_ATTRIBUTES and value is not None:
                self.refs.append(value)
                if tag == "img" and name == "src":
                    self.images.append(value)


def external_references(html: str) -> list[str]:
    """Everything in ``html`` that would make a browser fetch something outside the file.

    Allowed: ``data:`` URIs, ``#fragments`` and relative names of files beside the
    page (``./<name>``, the overlay video). Anything with a scheme (``http:``, ``file:``,
    ``//host``), CSS ``url(...)`` or ``@import`` is external.
    """
    parser = _Refs()
    parser.feed(html)
    bad = [
        r
        for r in parser.refs
        if not r.startswith(("data:", "#"))
        and (":" in r or r.startswith("/") or "/" in r.removeprefix("./"))
    ]
    # ':' is not in the base64 alphabet, so a scheme cannot hide inside an inline image.
    bad += re.findall(r"[a-zA-Z][a-zA-Z0-9+.-]*://[^\s\"'<>)]*", html)
    bad += re.findall(r"url\((?!\s*['\"]?data:)[^)]*\)|@import[^;]*", html)
    return bad


def test_the_checker_finds_external_references() -> None:
    page = (
        '<link href="https://cdn.example/x.css"><img src="//host/a.png">'
        '<script src="/abs/x.js"></script><style>a{background:url(b.png)}</style>'
        '<a href="sub/dir.html">x</a><img src="data:image/png;base64,AAAA"><a href="#top">t</a>'
        '<a href="demo.overlay.mp4">video</a><a href="./a.overlay.mp4">video</a>'
        '<a href="./javascript:alert(1)">x</a><a href="javascript:alert(1)">x</a>'
    )
    found = external_references(page)
    for expected in (
        "https://cdn.example/x.css",
        "//host/a.png",
        "/abs/x.js",
        "url(b.png)",
        "sub/dir.html",
        "./javascript:alert(1)",
        "javascript:alert(1)",
    ):
        assert any(expected in f for f in found), expected
    assert not any("data:" in f or f == "#top" or "overlay" in f for f in found)


def test_run_writes_html_plots_and_video_beside_the_report(run_dir: Path) -> None:
    for name in (
        "report.html",
        "report.json",
        "report.md",
        "short.birdseye.png",
        "short.overlay.mp4",
    ):
        assert (run_dir / name).stat().st_size > 0, name
    assert not list(run_dir.glob(".*tmp*"))
    video = cv2.VideoCapture(str(run_dir / "short.overlay.mp4"))
    try:
        # The demo scenario records at 30 Hz; every frame of the run is in the video.
        assert video.get(cv2.CAP_PROP_FRAME_COUNT) == FRAMES
        assert video.get(cv2.CAP_PROP_FPS) == pytest.approx(30.0, rel=1e-3)
        ok, first = video.read()
        assert ok and first.shape == (480, 640, 3)
    finally:
        video.release()
    html = (run_dir / "report.html").read_text()
    assert 'href="./short.overlay.mp4"' in html


@pytest.mark.parametrize(
    "page", ["run", "unscored", "score", "sweep", "compare", "reproduce", "bench"]
)
def test_page_is_self_contained_and_its_images_decode(pages: dict[str, Path], page: str) -> None:
    html = pages[page].read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>")
    assert external_references(html) == []
    parser = _Refs()
    parser.feed(html)
    assert parser.images, "every page shows at least one plot"
    for uri in parser.images:
        head, _, payload = uri.partition(",")
        assert head in (
            "data:image/png;base64",
            "data:image/jpeg;base64",
            "data:image/svg+xml;base64",
        )
        if head == "data:image/svg+xml;base64":  # timeline and analysis plots: well-formed SVG
            svg = ET.fromstring(base64.b64decode(payload))
            assert svg.tag == f"{SVG}svg"
            shapes = {f"{SVG}{t}" for t in ("path", "circle", "rect", "line")}
            marks = [e for e in svg.iter() if e.tag in shapes][1:]  # after the white background
            labels = [e.text for e in svg.iter(f"{SVG}text")]
            assert marks and labels, "a plot draws marks and labels its axes"
            continue
        image = cv2.imdecode(np.frombuffer(base64.b64decode(payload), np.uint8), cv2.IMREAD_COLOR)
        assert image is not None and image.shape[0] > 50 and image.shape[1] > 50
        assert image.std() > 5  # not a flat colour


def test_run_page_content(pages: dict[str, Path], run_dir: Path) -> None:
    import json

    html = pages["run"].read_text()
    report = json.loads((run_dir / "report.json").read_text())
    seq = report["sequences"][0]
    assert seq["sha256"] in html
    assert "None: the method's defaults" in html  # no --set: no config difference
    # The metrics table shows the report's MOTA as the terminal table does.
    assert f"{100 * seq['metrics']['mota']:.1f}%" in html
    # Worst frames are JPEG photographs; plots are PNG, the error timeline SVG.
    shots = re.findall(r'<img src="data:image/jpeg;base64,[^"]*" alt="short frame (\d+)"', html)
    assert shots and len(shots) <= 6
    assert shots == sorted(shots, key=int)


def test_run_page_shows_where_it_fails_intervals_and_breakdowns(
    pages: dict[str, Path], run_dir: Path
) -> None:
    import json

    html = pages["run"].read_text()
    report = json.loads((run_dir / "report.json").read_text())
    seq = report["sequences"][0]
    # A run has the camera's pose from odometry and tf: every breakdown is available.
    for kind in ("distance", "visibility", "motion"):
        assert seq["breakdowns"][kind]["available"], kind
    assert (run_dir / seq["frames_file"]["name"]).is_file()
    # "Where it fails" opens the page; the analysis follows the metrics table.
    assert html.index('id="where-it-fails"') < html.index("<h2>Run</h2>")
    metrics = html.index("<h2>Metrics</h2>")
    assert metrics < html.index('id="intervals"') < html.index('id="breakdowns"')
    for title in ("Distance from the camera", "Visibility of the person", "Robot motion"):
        assert f"<h3>{title}</h3>" in html
    assert 'alt="metrics per band of each breakdown"' in html
    lo, hi = seq["intervals"]["mota"]
    assert f"[{100 * lo:.1f}, {100 * hi:.1f}]" in html


def test_run_page_without_ground_truth_shows_the_tracks_on_the_camera_image(
    pages: dict[str, Path], unscored_dir: Path
) -> None:
    html = pages["unscored"].read_text()
    assert "Nothing was scored (no ground truth)." in html
    assert "Worst frames" not in html
    # Four frames spread over the 24, each captioned with the tracks drawn on it.
    shots = re.findall(
        r'<img src="data:image/jpeg;base64,[^"]*" alt="short frame (\d+)">'
        r"<figcaption>frame \1: (\d+) tracks?</figcaption>",
        html,
    )
    frames = [int(f) for f, _ in shots]
    assert len(frames) == 4 and frames == sorted(frames)
    assert [f * 4 // FRAMES for f in frames] == [0, 1, 2, 3]  # one from each quarter
    assert sum(int(n) for _, n in shots) > 0
    assert (unscored_dir / "short.birdseye.png").stat().st_size > 0


def test_compare_page_colours_rows_by_status(pages: dict[str, Path]) -> None:
    html = pages["compare"].read_text()
    assert '<tr class="regressed">' in html and "<td>id_switches</td>" in html
    assert '<tr class="better">' in html
    assert "1 regression(s) beyond tolerance" in html


def test_reproduce_page_shows_paper_beside_measured_and_claims(pages: dict[str, Path]) -> None:
    html = pages["reproduce"].read_text()
    # Table 7.2, static_simple: the thesis' MOTA 93.1% beside our 85.0%.
    assert "93.1% / <b>85.0%</b>" in html
    # Table 7.6 at -1.0: the thesis' FP 4.4% beside our 8.0%.
    assert "4.4% / <b>8.0%</b>" in html
    assert html.count('class="left held"') == 1 and html.count('class="left failed"') == 1


def test_config_diff_lists_only_what_differs_from_the_method_defaults() -> None:
    from rgbd_eval.config import load_config
    from rgbd_eval.report.html.pages import config_diff

    assert config_diff(load_config(method="basso2012")) == []
    changed = load_config(None, ["tracker.min_confidence=-1.0"], method="basso2012")
    # methods/basso2012/method.yaml keeps Table 6.1's -0.5
    assert config_diff(changed) == [("tracker.min_confidence", -0.5, -1.0)]


def test_score_page_shows_the_errors_of_recorded_tracks(pages: dict[str, Path]) -> None:
    html = pages["score"].read_text()
    # 4 ground-truth instances: 1 FP (track 9), 1 FN (frame 3), 1 ID switch (frame 4):
    # MOTA = 1 - 3/4 = 25.0%; no world positions, so no bird's-eye plot and no images.
    assert "<td>25.0%</td>" in html
    assert "bird&#39;s-eye" not in html and "image/jpeg" not in html
    # The error timeline; the others are the analysis' plots (intervals, gap recovery).
    assert html.count('alt="errors per frame of') == 1
    assert html.count("<img ") == 1 + html.count('alt="metrics with their') + html.count(
        'alt="recovery rate'
    )
    assert not (pages["score"].parent / "tracks.birdseye.png").exists()


def test_score_page_tables(pages: dict[str, Path], score_dir: Path) -> None:
    import json

    html = pages["score"].read_text()
    # Metrics: FP and FN with their counts; person 1 matched in 3 of 4 frames: partly tracked.
    assert "<th>FP</th><th>FN</th>" in html and "<th>MT</th><th>PT</th><th>ML</th>" in html
    assert "<td>25.0% (1)</td><td>25.0% (1)</td>" in html
    assert "<td>0</td><td>1</td><td>0</td>" in html  # MT, PT, ML
    # Inputs: each file on its own line with its own checksum.
    seq = json.loads((score_dir / "report.json").read_text())["sequences"][0]
    lines = {
        m[0]: m[1]
        for m in re.findall(
            r'<td class="left mono">([0-9a-f]{64})</td><td class="left mono">([^<]*)</td>', html
        )
    }
    assert lines == {
        seq["tracks_sha256"]: seq["path"],
        seq["sha256"]: seq["ground_truth"]["source"],
    }


def test_reproduce_claims_named_by_their_thesis_sentence_keep_source_and_evidence() -> None:
    # basso2012's ReproduceResult names each claim by the thesis' sentence; the page still
    # finds its source and evidence in the JSON data.
    from rgbd_eval.methods.basso2012.experiments import Claim, Reproduction, to_json
    from rgbd_eval.plugins import ReproduceResult
    from rgbd_eval.report.html.pages import _claims

    res = Reproduction()
    res.claims = [
        Claim(
            "7.3, Table 7.6",
            "FN at 0.5 - FN at -0.5 >= 0.02",
            True,
            "FN 5% -> 9%",
            "A high threshold instead",
        )
    ]
    result = ReproduceResult(
        markdown="", data=to_json(res), claims=(("A high threshold instead", True),)
    )
    (row,) = _claims(result)
    assert (row.source, row.evidence) == ("7.3, Table 7.6", "FN 5% -> 9%")


def test_reproduce_page_shows_an_inconclusive_verdict_apart() -> None:
    # a claim that flips between seeds is shown as inconclusive, neither held nor failed
    from rgbd_eval.plugins import ReproduceResult
    from rgbd_eval.report.html.pages import reproduce_page
    from rgbd_eval.verdicts import Verdict

    result = ReproduceResult(
        markdown="",
        data={
            "claims": [{"text": "B", "source": "s", "evidence": "seed 2: held | seed 3: failed"}]
        },
        claims=(("A", Verdict.HELD), ("B", Verdict.INCONCLUSIVE), ("C", False)),
    )
    html = reproduce_page(result, "satake2009", paper={})
    assert html.count('class="left inconclusive">inconclusive<') == 1
    assert html.count('class="left held">held<') == 1
    assert html.count('class="left failed">did not hold<') == 1
    assert "seed 2: held | seed 3: failed" in html
