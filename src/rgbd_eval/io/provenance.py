"""Where a synthetic recording came from, written into the recording itself.

``rgbd-eval synth`` writes one ``std_msgs/msg/String`` message on
:data:`PROVENANCE_TOPIC` before the first frame: a JSON object naming the generator,
its version and renderer version, the scenario (its name, the sha256 of the resolved
scenario and of the file it was read from), the seed, the number of frames, the
container and, for a closed-loop recording (``synth --follow``), the sha256 of the
followed target and the method config that drove the robot. Two recordings with the
same provenance should be the same bytes; when they are not, something outside the
provenance differed (the machine or a library), and ``compare`` says so instead of
refusing (see :func:`differences`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

PROVENANCE_TOPIC = "/rgbd_eval/provenance"
PROVENANCE_TYPE = "std_msgs/msg/String"
#: The largest provenance message read (bytes); a larger one is ignored with a warning.
MAX_BYTES = 16_384

#: Keys that identify what was rendered; two recordings that agree on all of them were
#: made from the same input and should be bit-identical.
IDENTITY_KEYS: tuple[str, ...] = (
    "generator",
    "tool_version",
    "renderer_version",
    "scenario",
    "scenario_sha256",
    "seed",
    "frames",
    "container",
    "closed_loop",
)
#: Informative keys (the source file's digest changes with a comment, not the scenario).
OTHER_KEYS: tuple[str, ...] = ("scenario_file_sha256",)


def encode(provenance: Mapping[str, Any]) -> str:
    """The message text: compact JSON with sorted keys (the same bytes for the same values)."""
    unknown = set(provenance) - set(IDENTITY_KEYS) - set(OTHER_KEYS)
    if unknown:
        raise ValueError(f"unknown provenance keys {sorted(unknown)}")
    return json.dumps(dict(provenance), sort_keys=True, separators=(",", ":"))


def decode(text: str) -> dict[str, Any]:
    """The provenance object of a message's text; ValueError when it is not one."""
    if len(text.encode("utf-8", "surrogatepass")) > MAX_BYTES:
        raise ValueError(f"provenance message longer than {MAX_BYTES} bytes")
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as err:
        raise ValueError(f"provenance message is not JSON ({err})") from err
    if not isinstance(data, dict):
        raise ValueError("provenance message is not a JSON object")
    out = {}
    for key in (*IDENTITY_KEYS, *OTHER_KEYS):
        value = data.get(key)
        if value is not None and not isinstance(value, str | int | float | bool):
            raise ValueError(f"provenance key {key!r} is not a plain value")
        out[key] = value
    return out


def differences(a: Mapping[str, Any] | None, b: Mapping[str, Any] | None) -> list[str]:
    """Identity keys on which two provenances differ (``key: a -> b``), or that one is missing."""
    if a is None or b is None:
        return [
            "provenance: " + ("missing in both" if a is None and b is None else "missing in one")
        ]
    return [f"{k}: {a.get(k)!r} -> {b.get(k)!r}" for k in IDENTITY_KEYS if a.get(k) != b.get(k)]


def read(path: Path) -> dict[str, Any] | None:
    """The provenance of the recording at ``path`` (its first provenance message), or None
    when it has none or it cannot be read. Reads only that message, not the images."""
    from rgbd_eval.errors import InputError
    from rgbd_eval.io.source import READ_ERRORS, open_source

    errors: tuple[type[BaseException], ...] = (*READ_ERRORS, InputError)
    try:
        with open_source(path) as src:
            conn = src.topics.get(PROVENANCE_TOPIC)
            if conn is None or conn.msgtype != PROVENANCE_TYPE:
                return None
            for _topic, _stamp, raw in src.messages({PROVENANCE_TOPIC}):
                return decode(str(src.deserialize(raw, PROVENANCE_TYPE).data))
    except errors:
        return None
    return None
