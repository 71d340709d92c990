"""Data reaches the terminal as text: markup escaped, control characters visible."""

from __future__ import annotations

import io

from rich.console import Console
from rich.table import Table

from neurosym.display import plain, show


def _render(cell: str) -> str:
    out = io.StringIO()
    table = Table("value")
    table.add_row(cell)
    Console(file=out, width=200, force_terminal=True, color_system="truecolor").print(table)
    return out.getvalue()


def test_lists_and_markup_print_as_written() -> None:
    for text in ("indirect([agent])", "[link=https://evil.example]click[/link]", "[bold]x[/]"):
        assert text in _render(show(text))


def test_control_characters_are_shown_not_sent() -> None:
    assert plain("a\x1b[31mred\nb\tc\x07") == "a\\e[31mred\\nb\\tc\\x07"
    rendered = _render(show("\x1b[31mred"))
    assert "\\e[31mred" in rendered
    assert "\x1b[31mred" not in rendered


def test_printable_text_unchanged() -> None:
    assert plain("sword_enemy_link(indirect)") == "sword_enemy_link(indirect)"
    assert plain(3.5) == "3.5"
