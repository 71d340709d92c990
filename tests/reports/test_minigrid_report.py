"""``neurosym report`` on a Minigrid recording: the page's data carry the level (walls, the
door, the key, the goal, the agent's direction, the door's state per step) and, in a headless
browser, the map draws the locked door, the open door and the way the agent faces."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from minigrid_scripted import DOOR, doorkey_recording
from pages import embedded, errors, extract_folder, open_page, report


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = extract_folder(doorkey_recording(), tmp_path_factory.mktemp("minigrid") / "out")
    report(folder)
    return folder / "index.html"


def test_the_page_data_hold_the_level(page: Path) -> None:
    data = embedded(page.read_text(encoding="utf-8"))
    player = data["player"]
    terrain = player["terrains"][0]
    assert player["shape"] == [5, 5]
    assert terrain[0] == ["wall"] * 5 and terrain[DOOR[0]][DOOR[1]] == "empty"  # objects: per step
    ep = player["episodes"][0]
    tables = ep["tables"]
    assert tables["facing"]["direction"] == ["south"] * 3 + ["east"] * 5 + ["south"] * 2
    doors = tables["doors"]
    assert list(zip(doors["t"], doors["id"], doors["state"], strict=True))[3:6] == [
        (3, "door_yellow", "locked"),
        (4, "door_yellow", "locked"),
        (5, "door_yellow", "open"),
    ]
    placed = set(zip(tables["positions"]["object"], tables["positions"]["type"], strict=True))
    assert {("door_yellow", "door(yellow)"), ("key_yellow", "key(yellow)"), ("goal", "goal")} <= placed
    styles = data["entities"]
    assert styles["door(yellow)"]["fill"] == styles["key(yellow)"]["fill"] == "#ffff00"
    assert {styles[n]["label"] for n in ("door(yellow)", "key(yellow)", "goal", "wall")} == {
        "D", "k", "G", "W",
    }  # fmt: skip


def _marks(driver: Any) -> list[tuple]:
    return driver.execute_script(
        """
        const map = document.querySelector('#map svg');
        return Array.from(map.querySelectorAll('g.marks > *')).map((m) =>
          m.classList.contains('door') ? ['door', Number(m.dataset.row), Number(m.dataset.col),
                                          m.dataset.state]
                                       : ['facing', m.dataset.direction]);
        """
    )


def test_the_map_draws_doors_and_the_direction(browser: Any, page: Path) -> None:
    r, c = DOOR
    for t, want in (
        (0, [["door", r, c, "locked"], ["facing", "south"]]),
        (4, [["door", r, c, "locked"], ["facing", "east"]]),
        (5, [["door", r, c, "open"], ["facing", "east"]]),
        (6, [["facing", "east"]]),  # the agent stands in the doorway
    ):
        open_page(browser, page, f"#e=0&t={t}")
        assert browser.execute_script("return window.neurosymReport.t") == t
        assert _marks(browser) == want, t
    assert errors(browser) == []
