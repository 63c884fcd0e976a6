"""The compose YAML writer: what it writes reads back (pyyaml, as compose reads YAML) as the
very data it was given, however a string looks, with the comments where they belong."""

from __future__ import annotations

import pytest
import yaml

from catabot.run.compose_yaml import dump

TRICKY = ["yes", "No", "on", "null", "~", "5s", "7447", "1.0", "", "-", "--flag", "-m", "a: b",
          "# not a comment", "${VAR:-x}", "[x]", "{x}", "tcp/router:7447", "it's", 'say "hi"',
          "ünïcode", "a,b", "*alias", "&anchor", "!tag", "@at", "%pct", "`tick`",
          "x\ny"]  # fmt: skip


def test_every_string_reads_back_as_itself() -> None:
    doc = {"services": {"s": {"command": TRICKY, "restart": "no", "n": 3, "flag": True,
                              "env": {k: k for k in TRICKY[:8]}}}}  # fmt: skip
    assert yaml.safe_load(dump(doc, {}, "head")) == doc


def test_nested_maps_lists_of_maps_and_comments() -> None:
    service = {"depends_on": {"b": {"condition": "service_healthy"}},
               "secrets": [{"source": "s", "target": "/t"}]}  # fmt: skip
    doc = {"x": {"list": [], "empty": {}}, "services": {"a": service}}
    text = dump(doc, {"services.a": "first line\nsecond line"}, "line 1\nline 2")
    assert yaml.safe_load(text) == doc
    lines = text.splitlines()
    assert lines[:2] == ["# line 1", "# line 2"]
    at = lines.index("  a:")
    assert lines[at - 2 : at] == ["  # first line", "  # second line"]


def test_a_long_list_is_written_one_item_a_line() -> None:
    doc = {"command": [f"--option-{i}" for i in range(20)]}
    text = dump(doc, {}, "")
    assert all(len(line) <= 99 for line in text.splitlines())
    assert yaml.safe_load(text) == doc


def test_what_yaml_cannot_hold_here_is_refused() -> None:
    with pytest.raises(TypeError, match="cannot write float"):
        dump({"a": 1.5}, {}, "")
    with pytest.raises(TypeError, match="nests lists"):
        dump({"a": [[1]]}, {}, "")
