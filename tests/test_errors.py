"""errors.py: every message is one line, and no character of a user's text reaches a terminal
as a command (C0 and C1 controls, line and paragraph separators, bidirectional overrides)."""

from __future__ import annotations

import pytest

from lagrangian.errors import InputError, ModelError


@pytest.mark.parametrize("character", ["\n", "\r", "\x1b", "\x7f", "\x85", "\x9b", "\u2028",
                                       "\u2029", "\u202e", "\u2066", "\x00"])
def test_a_users_control_character_is_an_escape(character):
    for error in (InputError(f"'a{character}b' is not a coordinate", field="independent"),
                  ModelError("bad", field=f"key{character}", source="model.toml")):
        text = str(error)
        assert len(text.splitlines()) == 1
        assert character not in text and "\\" in text


def test_printable_text_is_kept():
    text = str(InputError("'θ̇ ×2' is not a coordinate", field="q"))
    assert text == "q: 'θ̇ ×2' is not a coordinate"


def test_a_warning_quoting_a_users_text_is_one_line(capsys):
    from lagrangian.cli.common import flush_warnings, warn

    warn("parameter 'k\u2028\x1b[2J' is never used")
    flush_warnings()
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "\x1b" not in err and "\u2028" not in err
