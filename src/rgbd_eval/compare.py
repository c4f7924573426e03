"""Compare two run reports: what got better, what got worse, what regressed beyond tolerance.

Where both reports have their per-frame tables (``<name>.frames.npz`` beside
``report.json``), each change also gets the 95 % interval of a paired block bootstrap
(:func:`rgbd_eval.significance.paired_intervals`): the same resampled frames of the same
sequence in both reports. A change whose interval excludes 0 is beyond noise;
``significance`` gates on that instead of the fixed tolerance (metrics without an interval
keep their tolerance).
"""

from __future__ import annotations

import enum
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.errors import CompareInputError
from rgbd_eval.io import provenance
from rgbd_eval.report.run import REPORT_SCHEMA_VERSION


class Better(enum.Enum):
    HIGHER = "higher"
    LOWER = "lower"


#: Metrics compared by default: direction and default tolerance (absolute, in the metric's unit;
#: shares are fractions, so 0.01 is one percentage point).
DEFAULT_TOLERANCES: dict[str, tuple[Better, float]] = {
    "mota": (Better.HIGHER, 0.01),
    "motp": (Better.HIGHER, 0.01),  # direction flips to LOWER under metric gating (metres)
    "idf1": (Better.HIGHER, 0.01),
    "hota": (Better.HIGHER, 0.01),
    "main_tr": (Better.HIGHER, 0.02),
    "all_tr": (Better.HIGHER, 0.01),
    "fp_rate": (Better.LOWER, 0.01),
    "fn_rate": (Better.LOWER, 0.01),
    "id_switches": (Better.LOWER, 0.0),
    "recall_errors": (Better.LOWER, 0.0),
    "fragmentations": (Better.LOWER, 0.0),
}


#: Reports written before conventions existed were scored the motmetrics way.
_LEGACY_CONVENTION = "motmetrics"


class Status(enum.Enum):
    SAME = "same"
    BETTER = "better"
    WORSE = "worse"  # worse, but within tolerance
    REGRESSED = "regressed"  # worse beyond tolerance
    MISSING = "missing"  # the baseline has a value, the current report none: a failure
    NEW = "new"  # only the current report has a value


@dataclass(frozen=True)
class Delta:
    """One metric of one sequence (or 'overall') in both reports."""

    sequence: str
    metric: str
    baseline: float | None
    current: float | None
    tolerance: float
    status: Status
    #: The 95 % interval of the change (current - baseline) by the paired bootstrap.
    interval: tuple[float, float] | None = None

    @property
    def change(self) -> float | None:
        if self.baseline is None or self.current is None:
            return None
        return self.current - self.baseline

    @property
    def beyond_noise(self) -> bool | None:
        """Whether the change's interval excludes 0 (None without an interval)."""
        if self.interval is None:
            return None
        return not self.interval[0] <= 0.0 <= self.interval[1]


@dataclass(frozen=True)
class Comparison:
    deltas: tuple[Delta, ...]
    config_changes: tuple[str, ...]
    #: What a reader must know besides the deltas (recordings of one provenance that differ).
    notes: tuple[str, ...] = ()
    #: Whether metrics with an interval were gated on it (``--significance``).
    significance: bool = False

    @property
    def gate(self) -> str:
        """What a regression is beyond, in words."""
        return "noise or tolerance" if self.significance else "tolerance"

    @property
    def regressions(self) -> tuple[Delta, ...]:
        """Metrics worse beyond tolerance, or present in the baseline and missing now."""
        return tuple(d for d in self.deltas if d.status in (Status.REGRESSED, Status.MISSING))


def _refuse_constant(name: str) -> float:
    raise ValueError(f"{name} is not a JSON number")


def _finite_float(text: str) -> float:
    """A JSON number as a float; ValueError when it overflows (``1e400`` reads as inf)."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"number {text[:40]} is too large for a float")
    return value


def load_report(path: Path) -> dict[str, Any]:
    """A ``report.json`` (or a run folder holding one); CompareInputError when unusable."""
    from rgbd_eval.files import MAX_NESTING, read_text, too_deep

    path = Path(path)
    if path.is_dir():
        path = path / "report.json"

    def error(message: str) -> CompareInputError:
        return CompareInputError(f"{path}: {message}")

    text = read_text(path, error, "report")
    try:
        data = json.loads(text, parse_constant=_refuse_constant, parse_float=_finite_float)
    except json.JSONDecodeError as err:
        raise CompareInputError(f"{path}: not valid JSON ({err.msg} at line {err.lineno})") from err
    except ValueError as err:  # NaN / Infinity, 1e400, an integer of thousands of digits
        raise CompareInputError(f"{path}: not valid JSON ({err})") from err
    except RecursionError as err:  # json recurses once per level of nesting
        raise CompareInputError(f"{path}: not a report (JSON nested too deeply)") from err
    if too_deep(data):  # comparing configs recurses too
        raise CompareInputError(
            f"{path}: not a report (JSON nests deeper than {MAX_NESTING} levels)"
        )
    if not isinstance(data, dict) or data.get("schema_version") != REPORT_SCHEMA_VERSION:
        version = data.get("schema_version") if isinstance(data, dict) else None
        raise CompareInputError(
            f"{path}: report schema version {version!r}, this tool reads {REPORT_SCHEMA_VERSION}"
        )
    check_report(data, str(path))
    return data


def _number_or_none(value: Any) -> bool:
    return value is None or (isinstance(value, int | float) and not isinstance(value, bool))


def _check_metrics(metrics: Any, where: str) -> None:
    if metrics is None:
        return
    if not isinstance(metrics, dict):
        raise CompareInputError(f"{where}: 'metrics' must be an object or null")
    for key, value in metrics.items():
        if not _number_or_none(value):
            raise CompareInputError(f"{where}: metric {key!r} is {value!r}, not a number or null")


def check_report(data: Mapping[str, Any], source: str) -> None:
    """The keys and types :func:`compare_reports` reads; CompareInputError naming the first bad one."""
    evaluation = data.get("evaluation")
    if not isinstance(evaluation, dict) or not isinstance(evaluation.get("gating"), str):
        raise CompareInputError(f"{source}: no 'evaluation' object with a 'gating' name")
    if not _number_or_none(evaluation.get("threshold")):
        raise CompareInputError(f"{source}: 'evaluation.threshold' is not a number")
    sequences = data.get("sequences")
    if not isinstance(sequences, list):
        raise CompareInputError(f"{source}: no 'sequences' list")
    for k, seq in enumerate(sequences):
        where = f"{source}: sequences[{k}]"
        if not isinstance(seq, dict) or not isinstance(seq.get("name"), str):
            raise CompareInputError(f"{where}: not an object with a 'name' string")
        if "metrics" not in seq:
            raise CompareInputError(f"{where} ({seq['name']}): no 'metrics' (null when unscored)")
        _check_metrics(seq["metrics"], f"{where} ({seq['name']})")
    overall = data.get("overall")
    if overall is not None:
        if not isinstance(overall, dict):
            raise CompareInputError(f"{source}: 'overall' must be an object or null")
        _check_metrics(overall.get("metrics"), f"{source}: overall")
    if not isinstance(data.get("config", {}), dict):
        raise CompareInputError(f"{source}: 'config' must be an object")


def parse_tolerances(items: list[str]) -> dict[str, float]:
    """``metric=value`` strings; unknown metrics are an error naming the known ones."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or name not in DEFAULT_TOLERANCES:
            known = ", ".join(DEFAULT_TOLERANCES)
            raise CompareInputError(
                f"--tolerance {item!r}: expected METRIC=VALUE with METRIC one of {known}"
            )
        try:
            out[name] = float(value)
        except ValueError as err:
            raise CompareInputError(f"--tolerance {item!r}: {value!r} is not a number") from err
        if not math.isfinite(out[name]) or out[name] < 0:
            raise CompareInputError(f"--tolerance {item!r}: must be a finite number >= 0")
    return out


def _status(
    base: float | None,
    cur: float | None,
    better: Better,
    tol: float,
    interval: tuple[float, float] | None = None,
) -> Status:
    """The status of one change: against ``tol``, or with ``interval`` (significance
    gating) against the noise: worse and beyond noise regresses."""
    if base is None or cur is None:
        if base is None:
            return Status.SAME if cur is None else Status.NEW
        return Status.MISSING  # scored in the baseline, lost in the current report: fails
    gain = (cur - base) if better is Better.HIGHER else (base - cur)
    if abs(gain) <= 1e-12:
        return Status.SAME
    if gain > 0:
        return Status.BETTER
    if interval is not None:
        return Status.REGRESSED if not interval[0] <= 0.0 <= interval[1] else Status.WORSE
    return Status.REGRESSED if -gain > tol + 1e-12 else Status.WORSE


def flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    """Nested mappings -> ``out[dotted.key] = leaf`` (configs compared key by key)."""
    if isinstance(value, Mapping):
        for k, v in value.items():
            flatten(f"{prefix}.{k}" if prefix else str(k), v, out)
    else:
        out[prefix] = value


def compare_reports(
    baseline: Mapping[str, Any],
    current: Mapping[str, Any],
    tolerances: Mapping[str, float] | None = None,
    intervals: Mapping[tuple[str, str], tuple[float, float]] | None = None,
    significance: bool = False,
) -> Comparison:
    """Per sequence and overall deltas; CompareInputError when the reports are not comparable.

    ``intervals`` maps ``(sequence or 'overall', metric)`` to the 95 % interval of the
    change (:func:`rgbd_eval.significance.paired_intervals`); with ``significance`` a metric
    that has one regresses when worse beyond noise, whatever its tolerance.
    """
    tolerances = dict(tolerances or {})
    intervals = dict(intervals or {})
    base_seqs = {s["name"]: s for s in baseline["sequences"]}
    cur_seqs = {s["name"]: s for s in current["sequences"]}
    if set(base_seqs) != set(cur_seqs):
        raise CompareInputError(
            f"different datasets: baseline has {sorted(base_seqs)}, current has {sorted(cur_seqs)}"
        )
    notes = [
        note
        for name in sorted(base_seqs)
        if (note := _same_recording(name, baseline, current)) is not None
    ]
    conventions = [
        r["evaluation"].get("convention", _LEGACY_CONVENTION) for r in (baseline, current)
    ]
    if conventions[0] != conventions[1]:
        raise CompareInputError(
            f"different conventions: baseline scored with {conventions[0]!r}, current with "
            f"{conventions[1]!r}; rescore one of them with --convention"
        )
    gating = baseline["evaluation"]["gating"]
    if (
        gating != current["evaluation"]["gating"]
        or baseline["evaluation"]["threshold"] != current["evaluation"]["threshold"]
    ):
        raise CompareInputError(
            f"different scoring: baseline {gating} @ {baseline['evaluation']['threshold']}, current "
            f"{current['evaluation']['gating']} @ {current['evaluation']['threshold']}"
        )
    rows: list[tuple[str, Mapping[str, Any] | None, Mapping[str, Any] | None]] = [
        (name, base_seqs[name]["metrics"], cur_seqs[name]["metrics"]) for name in sorted(base_seqs)
    ]
    if len(base_seqs) > 1:
        rows.append(
            (
                "overall",
                (baseline.get("overall") or {}).get("metrics"),
                (current.get("overall") or {}).get("metrics"),
            )
        )
    deltas = []
    for seq, base, cur in rows:
        for metric, (better, default_tol) in DEFAULT_TOLERANCES.items():
            if metric == "motp" and gating == "metric":
                better = Better.LOWER
            tol = tolerances.get(metric, default_tol)
            b = None if base is None else base.get(metric)
            c = None if cur is None else cur.get(metric)
            interval = intervals.get((seq, metric))
            gate = interval if significance else None
            deltas.append(Delta(seq, metric, b, c, tol, _status(b, c, better, tol, gate), interval))
        for metric in sorted(set(base or {}) - set(DEFAULT_TOLERANCES)):
            b, c = (base or {})[metric], (cur or {}).get(metric)
            if b is not None and c is None:  # not gated by value, but must not vanish
                deltas.append(Delta(seq, metric, b, None, 0.0, Status.MISSING))
    flat_b: dict[str, Any] = {}
    flat_c: dict[str, Any] = {}
    flatten("", baseline.get("config", {}), flat_b)
    flatten("", current.get("config", {}), flat_c)
    changes = tuple(
        f"{k}: {flat_b.get(k)!r} -> {flat_c.get(k)!r}"
        for k in sorted(set(flat_b) | set(flat_c))
        if flat_b.get(k) != flat_c.get(k)
    )
    return Comparison(tuple(deltas), changes, tuple(notes), significance)


def _same_recording(
    name: str, baseline: Mapping[str, Any], current: Mapping[str, Any]
) -> str | None:
    """None when sequence ``name`` read the same bytes in both reports; a note when the bytes
    differ but the recordings have one provenance; CompareInputError otherwise."""
    base = next(s for s in baseline["sequences"] if s["name"] == name)
    cur = next(s for s in current["sequences"] if s["name"] == name)
    if base.get("sha256") == cur.get("sha256"):
        return None
    prov_b, prov_c = base.get("provenance"), cur.get("provenance")
    prov_b = prov_b if isinstance(prov_b, Mapping) else None
    prov_c = prov_c if isinstance(prov_c, Mapping) else None
    differ = provenance.differences(prov_b, prov_c)
    if differ or prov_b is None:
        raise CompareInputError(
            f"different datasets: sequence {name!r} has different content (sha256) and "
            f"different provenance ({'; '.join(differ)})"
        )
    made = (
        f"scenario {prov_b.get('scenario')!r} sha256 {str(prov_b.get('scenario_sha256'))[:12]}, "
        f"seed {prov_b.get('seed')}, {prov_b.get('frames')} frames, "
        f"rgbd-eval {prov_b.get('tool_version')} renderer {prov_b.get('renderer_version')}"
    )
    env = _environment_differences(baseline, current)
    return (
        f"sequence {name!r}: the recordings differ in bytes (sha256 "
        f"{str(base.get('sha256'))[:12]} vs {str(cur.get('sha256'))[:12]}) but have one "
        f"provenance ({made}); "
        + (
            f"the reports' machines or libraries differ: {'; '.join(env)}"
            if env
            else "the reports name the same machine and libraries"
        )
        + "; compared as the same recording"
    )


def _environment_differences(baseline: Mapping[str, Any], current: Mapping[str, Any]) -> list[str]:
    """``key: a -> b`` for the machine and library versions the two reports name differently."""
    out = []
    for section in ("machine", "libraries"):
        a, b = baseline.get(section), current.get(section)
        a = a if isinstance(a, Mapping) else {}
        b = b if isinstance(b, Mapping) else {}
        for key in sorted(set(a) | set(b)):
            if a.get(key) != b.get(key):
                out.append(f"{section}.{key}: {a.get(key)!r} -> {b.get(key)!r}")
    return out


def _fmt(value: float | None, metric: str) -> str:
    if value is None:
        return "-"
    if metric.endswith("_rate") or metric in ("mota", "idf1", "hota", "main_tr", "all_tr"):
        return f"{100 * value:.2f}%"
    if metric == "motp":
        return f"{value:.4f}"
    return f"{value:g}"


def _interval_text(d: Delta) -> str:
    """``[-1.20, +0.30] pp (noise)``: the change's interval and whether it excludes 0."""
    if d.interval is None:
        return "-"
    percent = _fmt(0.0, d.metric).endswith("%")
    scale = 100.0 if percent else 1.0
    lo, hi = (scale * v for v in d.interval)
    digits = ".2f" if percent else (".4f" if d.metric == "motp" else "g")
    text = f"[{lo:+{digits}}, {hi:+{digits}}]" + (" pp" if percent else "")
    return f"{text} ({'beyond noise' if d.beyond_noise else 'noise'})"


def table_rows(comparison: Comparison, changed_only: bool = False) -> list[list[str]]:
    rows = []
    for d in comparison.deltas:
        if changed_only and d.status is Status.SAME:
            continue
        change = d.change
        sign = "" if change is None else ("+" if change > 0 else "")
        shown = (
            "-"
            if change is None
            else sign
            + _fmt(change, d.metric).rstrip("%")
            + (" pp" if _fmt(0.0, d.metric).endswith("%") else "")
        )
        rows.append(
            [
                d.sequence,
                d.metric,
                _fmt(d.baseline, d.metric),
                _fmt(d.current, d.metric),
                shown,
                _interval_text(d),
                d.status.value,
            ]
        )
    return rows


HEADER = ["sequence", "metric", "baseline", "current", "change", "95% interval", "status"]


def markdown(comparison: Comparison) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "|".join("---" for _ in HEADER) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in table_rows(comparison)]
    verdict = (
        f"**{len(comparison.regressions)} regression(s)** beyond {comparison.gate}."
        if comparison.regressions
        else f"No regression beyond {comparison.gate}."
    )
    lines += ["", verdict]
    if comparison.config_changes:
        lines += ["", "Config changes:", *(f"- `{c}`" for c in comparison.config_changes)]
    if comparison.notes:
        lines += ["", "Notes:", *(f"- {n}" for n in comparison.notes)]
    return "\n".join(lines) + "\n"
