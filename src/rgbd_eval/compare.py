"""Compare two run reports: what got better, what got worse, what regressed beyond tolerance."""

from __future__ import annotations

import enum
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rgbd_eval.errors import CompareInputError
from rgbd_eval.report import REPORT_SCHEMA_VERSION


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
    MISSING = "missing"  # one side has no value


@dataclass(frozen=True)
class Delta:
    """One metric of one sequence (or 'overall') in both reports."""

    sequence: str
    metric: str
    baseline: float | None
    current: float | None
    tolerance: float
    status: Status

    @property
    def change(self) -> float | None:
        if self.baseline is None or self.current is None:
            return None
        return self.current - self.baseline


@dataclass(frozen=True)
class Comparison:
    deltas: tuple[Delta, ...]
    config_changes: tuple[str, ...]

    @property
    def regressions(self) -> tuple[Delta, ...]:
        return tuple(d for d in self.deltas if d.status is Status.REGRESSED)


def load_report(path: Path) -> dict[str, Any]:
    """A ``report.json`` (or a run folder holding one); CompareInputError when unusable."""
    path = Path(path)
    if path.is_dir():
        path = path / "report.json"
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise CompareInputError(f"{path}: cannot read report ({err.strerror})") from err
    except json.JSONDecodeError as err:
        raise CompareInputError(f"{path}: not valid JSON ({err.msg} at line {err.lineno})") from err
    if not isinstance(data, dict) or data.get("schema_version") != REPORT_SCHEMA_VERSION:
        version = data.get("schema_version") if isinstance(data, dict) else None
        raise CompareInputError(
            f"{path}: report schema version {version!r}, this tool reads {REPORT_SCHEMA_VERSION}"
        )
    return data


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
        if out[name] < 0:
            raise CompareInputError(f"--tolerance {item!r}: must be >= 0")
    return out


def _status(base: float | None, cur: float | None, better: Better, tol: float) -> Status:
    if base is None or cur is None:
        return Status.SAME if base is None and cur is None else Status.MISSING
    gain = (cur - base) if better is Better.HIGHER else (base - cur)
    if abs(gain) <= 1e-12:
        return Status.SAME
    if gain > 0:
        return Status.BETTER
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
) -> Comparison:
    """Per sequence and overall deltas; CompareInputError when the reports are not comparable."""
    tolerances = dict(tolerances or {})
    base_seqs = {s["name"]: s for s in baseline["sequences"]}
    cur_seqs = {s["name"]: s for s in current["sequences"]}
    if set(base_seqs) != set(cur_seqs):
        raise CompareInputError(
            f"different datasets: baseline has {sorted(base_seqs)}, current has {sorted(cur_seqs)}"
        )
    for name, seq in base_seqs.items():
        if seq.get("sha256") != cur_seqs[name].get("sha256"):
            raise CompareInputError(
                f"different datasets: sequence {name!r} has different content (sha256)"
            )
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
            deltas.append(Delta(seq, metric, b, c, tol, _status(b, c, better, tol)))
    flat_b: dict[str, Any] = {}
    flat_c: dict[str, Any] = {}
    flatten("", baseline.get("config", {}), flat_b)
    flatten("", current.get("config", {}), flat_c)
    changes = tuple(
        f"{k}: {flat_b.get(k)!r} -> {flat_c.get(k)!r}"
        for k in sorted(set(flat_b) | set(flat_c))
        if flat_b.get(k) != flat_c.get(k)
    )
    return Comparison(tuple(deltas), changes)


def _fmt(value: float | None, metric: str) -> str:
    if value is None:
        return "-"
    if metric.endswith("_rate") or metric in ("mota", "idf1", "hota", "main_tr", "all_tr"):
        return f"{100 * value:.2f}%"
    if metric == "motp":
        return f"{value:.4f}"
    return f"{value:g}"


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
                d.status.value,
            ]
        )
    return rows


HEADER = ["sequence", "metric", "baseline", "current", "change", "status"]


def markdown(comparison: Comparison) -> str:
    lines = ["| " + " | ".join(HEADER) + " |", "|" + "|".join("---" for _ in HEADER) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in table_rows(comparison)]
    verdict = (
        f"**{len(comparison.regressions)} regression(s)** beyond tolerance."
        if comparison.regressions
        else "No regression beyond tolerance."
    )
    lines += ["", verdict]
    if comparison.config_changes:
        lines += ["", "Config changes:", *(f"- `{c}`" for c in comparison.config_changes)]
    return "\n".join(lines) + "\n"
