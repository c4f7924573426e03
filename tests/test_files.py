"""Safe input files: regular files only, bounded, UTF-8 with BOM, strict YAML."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from rgbd_eval.cli.common import MAX_MESSAGE_CHARS, one_line
from rgbd_eval.errors import ConfigError
from rgbd_eval.files import MAX_YAML_VALUES, check_folder, parse_yaml, read_text, too_deep


def _error(message: str) -> ConfigError:
    return ConfigError(message)


def test_bom_is_skipped_and_latin1_named(tmp_path: Path) -> None:
    f = tmp_path / "a.csv"
    f.write_bytes(b"\xef\xbb\xbfframe,id\n")
    assert read_text(f, _error) == "frame,id\n"
    f.write_bytes("caf\xe9".encode("latin-1"))
    with pytest.raises(ConfigError, match=r"not UTF-8 text \(byte 0xe9 at offset 3\)"):
        read_text(f, _error)


def test_non_regular_files_are_refused_without_opening(tmp_path: Path) -> None:
    os.mkfifo(tmp_path / "pipe")  # opening it would block until a writer came
    with pytest.raises(ConfigError, match="named pipe"):
        read_text(tmp_path / "pipe", _error)
    (tmp_path / "zero").symlink_to("/dev/zero")
    with pytest.raises(ConfigError, match="device"):
        read_text(tmp_path / "zero", _error)


def test_size_limit(tmp_path: Path) -> None:
    f = tmp_path / "big"
    f.write_bytes(b"x" * 11)
    with pytest.raises(ConfigError, match="11 bytes, more than the 10-byte limit"):
        read_text(f, _error, limit=10)


def test_duplicate_keys_at_any_depth() -> None:
    assert parse_yaml("a: {b: 1}\nc: 2\n", _error) == {"a": {"b": 1}, "c": 2}
    with pytest.raises(ConfigError, match="duplicate key 'b'"):
        parse_yaml("a:\n  b: 1\n  b: 2\n", _error)


def test_alias_bomb_is_refused() -> None:
    # 9 levels of 9 aliases each: 9**9 = 387 420 489 leaves, far above the limit.
    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefgh", "bcdefghi", strict=True)
    )
    with pytest.raises(ConfigError, match=f"more than {MAX_YAML_VALUES} values"):
        parse_yaml(bomb, _error)
    # A few aliases are fine: 1 mapping + 2 keys + 2 lists + 2 x 2 items = 9 values.
    assert parse_yaml("a: &a [1, 2]\nb: *a\n", _error) == {"a": [1, 2], "b": [1, 2]}


def test_error_lines_are_bounded() -> None:
    text = "x " * 10_000
    line = one_line(text)
    assert len(line) < MAX_MESSAGE_CHARS + 40 and line.endswith("(19399 more characters)")
    assert one_line("a\n  b") == "a b"


@pytest.mark.parametrize(
    "text",
    [
        "[" * 5000 + "]" * 5000,  # flow sequences
        "a: " + "{a: " * 2000 + "1" + "}" * 2000,  # flow mappings
        "".join("  " * i + "a:\n" for i in range(500)) + "  " * 500 + "b: 1\n",  # block
    ],
)
def test_deep_yaml_is_refused_before_the_recursive_composer(text: str) -> None:
    with pytest.raises(ConfigError, match="YAML nests deeper than 100 levels"):
        parse_yaml(text, _error)
    shallow = "a: " + "{a: " * 99 + "1" + "}" * 99
    assert too_deep(parse_yaml(shallow, _error)) is False


def test_too_deep_walks_without_recursion() -> None:
    deep: list[object] = []
    for _ in range(5000):
        deep = [deep]
    assert too_deep(deep) and not too_deep([[1], {"a": [2]}])


def test_folder_entries_must_be_regular(tmp_path: Path) -> None:
    (tmp_path / "metadata.yaml").write_text("a: 1\n")
    (tmp_path / "sub").mkdir()
    check_folder(tmp_path, _error)
    os.mkfifo(tmp_path / "bag.db3")
    with pytest.raises(ConfigError, match=r"entry bag\.db3 is a named pipe"):
        check_folder(tmp_path, _error)
