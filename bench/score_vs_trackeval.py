"""``rgbd-eval score`` against TrackEval 1.3.0 on a MOTChallenge folder of MOT17-train size.

    .venv/bin/python bench/score_vs_trackeval.py [--runs 3] [--ours SRC ...] [--json FILE]

Writes, deterministically (seeded RNG, not timed), a MOTChallenge folder shaped like
MOT17-train: the 7 sequences with their published ``seqLength`` and image sizes and
``gt.txt`` row counts (112,297 rows over 5,316 frames; every class, MOT17's consider
flags and visibilities), each under the three public detectors' names (DPM, FRCNN,
SDP) as MOT17-train's 21 sequences are: 15,948 frames, 336,891 ground-truth rows. One
tracker's output per sequence, drawn from the ground truth: people found with a
probability that grows with visibility, box noise, occasional identity switches and
false positives (about the size of the pedestrian ground truth).

Then, after one untimed run of each ``--ours`` source, its modules byte-compiled first as an
installed package's are (``--no-warm-up``: neither; the first run also writes numba's cache),
times, alternating, in child processes pinned to one CPU, by their CPU time
(``getrusage(RUSAGE_CHILDREN)``, user + system; the machine may be shared): ``python
-m rgbd_eval score TRACKS --gt GT --out NEW`` as a user runs it (CLEAR, Identity and
HOTA; report.json, report.md, report.html and one events.csv per sequence written),
once per ``--ours`` source folder (``PYTHONPATH``; default: the package imported
here), and TrackEval's ``Evaluator`` with ``MotChallenge2DBox`` (``BENCHMARK MOT17``,
``SKIP_SPLIT_FOL``, its default summary and detailed outputs, curves not plotted,
no parallelism) and ``CLEAR``, ``Identity``, ``HOTA``, as its ``run_mot_challenge.py``
does. Both include the interpreter's start and imports. Prints each run, the medians,
the ratios TrackEval / ours, the load average, and checks that every sequence's
CLEAR and Identity counts (TP, FN, FP, IDSW, Frag, MT, PT, ML, IDTP, IDFN, IDFP) and
HOTA's TP, FN, FP at alpha 0.5 equal TrackEval's (exit 1 and the differences if not).
``--keep DIR`` writes the data into a new folder DIR and keeps it (to profile).
"""

from __future__ import annotations

import argparse
import compileall
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

#: MOT17-train (motchallenge.net, seqinfo.ini and gt.txt): name, seqLength, width,
#: height, frame rate, gt.txt rows.
SEQUENCES = (
    ("MOT17-02", 600, 1920, 1080, 30, 18581),
    ("MOT17-04", 1050, 1920, 1080, 30, 47557),
    ("MOT17-05", 837, 640, 480, 14, 6917),
    ("MOT17-09", 525, 1920, 1080, 30, 5325),
    ("MOT17-10", 654, 1920, 1080, 30, 12839),
    ("MOT17-11", 900, 1920, 1080, 30, 9436),
    ("MOT17-13", 750, 1920, 1080, 25, 11642),
)
DETECTORS = ("DPM", "FRCNN", "SDP")
TRACKER = "synthetic"

#: MOT17 classes and how often each appears in the ground truth (pedestrians dominate).
CLASSES = np.array([1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12])
CLASS_P = np.array([0.60, 0.03, 0.04, 0.01, 0.02, 0.01, 0.12, 0.05, 0.01, 0.01, 0.02, 0.08])

TRACKEVAL = """
import sys
import trackeval
gt, trackers, seqmap, name = sys.argv[1:5]
eval_config = trackeval.Evaluator.get_default_eval_config()
eval_config.update({"USE_PARALLEL": False, "PLOT_CURVES": False, "PRINT_CONFIG": False})
dataset_config = trackeval.datasets.MotChallenge2DBox.get_default_dataset_config()
dataset_config.update({
    "GT_FOLDER": gt, "TRACKERS_FOLDER": trackers, "BENCHMARK": "MOT17",
    "SKIP_SPLIT_FOL": True, "SEQMAP_FILE": seqmap, "TRACKERS_TO_EVAL": [name],
    "PRINT_CONFIG": False,
})
metrics = [trackeval.metrics.HOTA(), trackeval.metrics.CLEAR(), trackeval.metrics.Identity()]
trackeval.Evaluator(eval_config).evaluate([trackeval.datasets.MotChallenge2DBox(dataset_config)], metrics)
"""

#: Our count key -> TrackEval's detailed CSV column.
COUNTS = {
    "num_matches": "CLR_TP",
    "fn": "CLR_FN",
    "fp": "CLR_FP",
    "id_switches": "IDSW",
    "fragmentations": "Frag",
    "mostly_tracked": "MT",
    "partly_tracked": "PT",
    "mostly_lost": "ML",
    "idtp": "IDTP",
    "idfn": "IDFN",
    "idfp": "IDFP",
}


def ground_truth(
    rng: np.random.Generator, length: int, width: int, height: int, rows: int
) -> np.ndarray:
    """Exactly ``rows`` ground-truth rows (frame, id, x, y, w, h, consider, class,
    visibility), sorted by id then frame as MOT17's are."""
    gt: list[np.ndarray] = []
    total, oid = 0, 0
    while total < rows:
        oid += 1
        duration = int(min(length, max(1, rng.gamma(2.0, length / 6.0)), rows - total))
        start = int(rng.integers(1, length - duration + 2))
        frames = np.arange(start, start + duration)
        cls = int(rng.choice(CLASSES, p=CLASS_P))
        h0 = rng.uniform(0.08, 0.45) * height
        w0 = h0 * rng.uniform(0.3, 0.5)
        x0, y0 = rng.uniform(-0.05, 0.95) * width, rng.uniform(0.1, 0.9) * height - h0 / 2
        vx, vy, grow = rng.normal(0, 2.0), rng.normal(0, 0.4), rng.normal(0, 0.0008)
        t = frames - start
        scale = np.clip(1.0 + grow * t, 0.5, 2.0)
        consider = 1 if cls in (1, 2, 7) and rng.random() > 0.02 else 0
        vis = np.clip(rng.uniform(0.0, 1.2) + 0.3 * np.sin(t / rng.uniform(10, 60)), 0, 1)
        block = np.column_stack(
            [
                frames,
                np.full(duration, oid),
                np.round(x0 + vx * t),
                np.round(y0 + vy * t),
                np.round(w0 * scale),
                np.round(h0 * scale),
                np.full(duration, consider),
                np.full(duration, cls),
                np.round(vis, 5),
            ]
        )
        gt.append(block)
        total += duration
    return np.concatenate(gt)


def tracker(
    rng: np.random.Generator, gt_rows: np.ndarray, length: int, width: int, height: int
) -> np.ndarray:
    """One tracker's rows (frame, id, x, y, w, h, conf, -1, -1, -1), sorted by frame."""
    people = gt_rows[np.isin(gt_rows[:, 7], (1, 7)) & (gt_rows[:, 8] > 0.1)]
    found = people[rng.random(len(people)) < 0.45 + 0.5 * people[:, 8]]
    ids = found[:, 1].copy()
    switch = rng.random(len(found)) < 0.004  # from here on this person has a new id
    for k in np.flatnonzero(switch):
        ids[(found[:, 1] == found[k, 1]) & (found[:, 0] >= found[k, 0])] = 10_000 + k
    noise = rng.normal(0, 0.06, (len(found), 4)) * found[:, [4, 5, 4, 5]]
    boxes = found[:, 2:6] + noise
    boxes[:, 2:] = np.maximum(boxes[:, 2:], 2.0)
    n_fp = int(0.12 * len(found))
    fp_frames = rng.integers(1, length + 1, n_fp)
    fp_h = rng.uniform(0.08, 0.4, n_fp) * height
    fp_boxes = np.column_stack(
        [
            rng.uniform(0, width, n_fp),
            rng.uniform(0, height * 0.8, n_fp),
            fp_h * 0.4,
            fp_h,
        ]
    )
    trk = np.column_stack(
        [
            np.concatenate([found[:, 0], fp_frames]),
            np.concatenate([ids, 100_000 + np.arange(n_fp)]),
            np.concatenate([boxes, fp_boxes]),
            rng.uniform(0.3, 1.0, len(found) + n_fp),
            np.full((len(found) + n_fp, 3), -1.0),
        ]
    )
    return trk[np.lexsort((trk[:, 1], trk[:, 0]))]


def write_folder(root: Path, seed: int = 17) -> tuple[Path, Path, Path, int, int]:
    """The MOTChallenge folder: ground truth, tracker data folder, seqmap, GT rows, frames."""
    rng = np.random.default_rng(seed)
    gt_root, data = root / "gt", root / "trackers" / TRACKER / "data"
    data.mkdir(parents=True)
    names, gt_total, frames = [], 0, 0
    for base, length, width, height, rate, rows in SEQUENCES:
        gt_rows = ground_truth(rng, length, width, height, rows)
        for det in DETECTORS:
            name = f"{base}-{det}"
            names.append(name)
            trk = tracker(np.random.default_rng([seed, len(names)]), gt_rows, length, width, height)
            seq = gt_root / name
            (seq / "gt").mkdir(parents=True)
            (seq / "seqinfo.ini").write_text(
                f"[Sequence]\nname={name}\nimDir=img1\nframeRate={rate}\nseqLength={length}\n"
                f"imWidth={width}\nimHeight={height}\nimExt=.jpg\n"
            )
            np.savetxt(seq / "gt" / "gt.txt", gt_rows, fmt="%d,%d,%d,%d,%d,%d,%d,%d,%.5g")
            np.savetxt(data / f"{name}.txt", trk, fmt="%d,%d,%.2f,%.2f,%.2f,%.2f,%.4f,%d,%d,%d")
            gt_total += len(gt_rows)
            frames += length
    seqmap = root / "seqmap.txt"
    seqmap.write_text("name\n" + "".join(f"{n}\n" for n in names))
    return gt_root, data, seqmap, gt_total, frames


def _cpu_of_child(cmd: list[str], env: dict[str, str], cpu: int) -> float:
    """CPU seconds (user + system) of ``cmd`` run to completion, pinned to ``cpu``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(
        cmd,
        env=env,
        capture_output=True,
        text=True,
        preexec_fn=lambda: os.sched_setaffinity(0, {cpu}),
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"{cmd[:4]} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return float(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)


def _env(src: str | None) -> dict[str, str]:
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    if src is not None:
        env["PYTHONPATH"] = src
    return env


def _package_folder(src: str | None) -> str:
    """The ``rgbd_eval`` folder of a ``--ours`` source (default: the one imported here)."""
    if src is not None:
        return str(Path(src) / "rgbd_eval")
    import rgbd_eval

    return str(Path(rgbd_eval.__file__).parent)


def our_counts(report: Path) -> dict[str, dict[str, int]]:
    """Per sequence, the compared counts of our report.json."""
    doc = json.loads(report.read_text())
    out = {}
    for seq in doc["sequences"]:
        c = seq["counts"]
        row = {k: int(c[k]) for k in COUNTS}
        for k in ("tp", "fn", "fp"):
            row[f"hota_{k}@0.5"] = int(c["hota"][k][9])
        out[seq["name"]] = row
    return out


def trackeval_counts(detailed: Path) -> dict[str, dict[str, int]]:
    """Per sequence, the same counts from TrackEval's ``pedestrian_detailed.csv``."""
    out = {}
    with detailed.open() as f:
        for row in csv.DictReader(f):
            if row["seq"] == "COMBINED":
                continue
            counts = {k: int(float(row[v])) for k, v in COUNTS.items()}
            for k in ("tp", "fn", "fp"):
                counts[f"hota_{k}@0.5"] = int(float(row[f"HOTA_{k.upper()}___50"]))
            out[row["seq"]] = counts
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="timed runs of each (median)")
    parser.add_argument(
        "--ours",
        action="append",
        metavar="SRC",
        help="a source folder holding rgbd_eval (PYTHONPATH); repeat to compare versions",
    )
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument(
        "--no-warm-up",
        dest="warm_up",
        action="store_false",
        help="time each --ours source's first run too (default: compiled, one untimed run first)",
    )
    parser.add_argument("--json", type=Path, help="also write the numbers here")
    parser.add_argument("--keep", type=Path, help="write the data here (a new folder), kept")
    args = parser.parse_args()
    cpu = min(os.sched_getaffinity(0))
    variants = args.ours or [None]
    with tempfile.TemporaryDirectory(prefix="score_vs_trackeval-") as tmp:
        root = args.keep or Path(tmp)
        gt, data, seqmap, gt_rows, frames = write_folder(root, args.seed)
        trk_rows = sum(len(p.read_text().splitlines()) for p in data.iterdir())
        print(
            f"{len(DETECTORS) * len(SEQUENCES)} sequences, {frames} frames, "
            f"{gt_rows} ground-truth rows, {trk_rows} tracker rows (seed {args.seed})"
        )
        te_cmd = [
            sys.executable,
            "-c",
            TRACKEVAL,
            str(gt),
            str(data.parent.parent),
            str(seqmap),
            TRACKER,
        ]
        times: dict[str, list[float]] = {"trackeval": []}
        reports: dict[str, Path] = {}
        # Untimed first: each source byte-compiled, as pip does for an installed package
        # (TrackEval's modules are; with PYTHONDONTWRITEBYTECODE set, a source folder's
        # modules were compiled anew in every run: 133 of them, 0.46 s of CPU), then one run
        # that writes numba's cache (31.7 s against 22.1 s in the runs after it, measured).
        score = [sys.executable, "-m", "rgbd_eval", "score", str(data), "--gt", str(gt)]
        if args.warm_up:
            for k, src in enumerate(variants):
                compileall.compile_dir(_package_folder(src), quiet=1)
                _cpu_of_child([*score, "--out", str(root / f"warm-{k}")], _env(src), cpu)
        for r in range(args.runs):
            line = [f"run {r}:"]
            for k, src in enumerate(variants):
                label = src or "ours"
                out = root / f"out-{k}-{r}"
                t = _cpu_of_child([*score, "--out", str(out)], _env(src), cpu)
                times.setdefault(label, []).append(t)
                reports[label] = out / "report.json"
                line.append(f"{label} {t:.2f} s")
            t = _cpu_of_child(te_cmd, _env(None), cpu)
            times["trackeval"].append(t)
            line.append(f"trackeval {t:.2f} s")
            print("  ".join(line), f"(load {' '.join(f'{x:.2f}' for x in os.getloadavg())})")
        theirs = trackeval_counts(data.parent / "pedestrian_detailed.csv")
        agree = {label: our_counts(path) == theirs for label, path in reports.items()}
        if not all(agree.values()):
            for label, path in reports.items():
                ours = our_counts(path)
                for name in sorted(theirs):
                    if ours.get(name) != theirs[name]:
                        print(f"{label} {name}: ours {ours.get(name)} trackeval {theirs[name]}")
    te = statistics.median(times["trackeval"])
    print(f"CPU seconds, median of {args.runs}, one core (cpu {cpu}):")
    ratios: dict[str, float] = {}
    for label, ts in times.items():
        if label == "trackeval":
            continue
        med = statistics.median(ts)
        ratios[label] = te / med
        print(
            f"  {label}: {med:.2f} s  TrackEval {te:.2f} s  TrackEval / ours {te / med:.2f}x  "
            f"counts {'equal' if agree[label] else 'DIFFER'}"
        )
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.json:
        result = {"cpu": cpu, "load_average": os.getloadavg(), "runs": times, "ratios": ratios}
        args.json.write_text(json.dumps(result, indent=1) + "\n")
    if not all(agree.values()):
        sys.exit("counts differ from TrackEval's")


if __name__ == "__main__":
    main()
