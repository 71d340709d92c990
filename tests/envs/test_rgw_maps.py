"""Relational-Grid-World maps: the shipped layouts, user maps, and refusal of bad maps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurosym.envs.rgw import RGWEnv
from neurosym.envs.rgw_maps import load_map, parse_map
from neurosym.errors import MapError

# reference/rgw-original.md, "Layout" (Configuration-2).
RGW2_OBJECTS = {
    "agent": [(0, 0)],
    "terminal": [(9, 0)],
    "sword": [(0, 6)],
    "enemy": [(9, 1)],
    "wall": [(6, c) for c in range(8)] + [(4, 3), (5, 3), (8, 0), (8, 1)],
    "pit": [(7, 8), (8, 9)],
    "mountain": [(0, 5), (0, 7), (0, 8), (0, 9), (1, 6), (1, 7), (1, 8), (1, 9)]
    + [(2, 7), (2, 8), (2, 9), (3, 8), (4, 9)],
    "teleport": [(3, 9), (8, 8)],
}


def objects_by_type(name: str) -> dict[str, list[tuple[int, int]]]:
    """The layout as the entity grid names it (terrain included)."""
    env = RGWEnv(name)
    env.reset(seed=0)
    grid = env.entity_grid()
    out: dict[str, list[tuple[int, int]]] = {}
    for (r, c), code in np.ndenumerate(grid):
        kind = env.entity_names[code]
        if kind != "empty":
            out.setdefault(kind, []).append((r, c))
    return {k: sorted(v) for k, v in out.items()}


def test_rgw2_is_the_original_layout() -> None:
    assert objects_by_type("rgw2") == {k: sorted(v) for k, v in RGW2_OBJECTS.items()}


def test_rgw1_is_rgw2_without_mountains_and_pits() -> None:
    want = {k: sorted(v) for k, v in RGW2_OBJECTS.items() if k not in ("mountain", "pit")}
    assert objects_by_type("rgw1") == want


def test_object_ids_are_unique_atoms() -> None:
    env = RGWEnv("rgw2")
    _, info = env.reset(seed=0)
    ids = [o[0] for o in info["objects"]]
    terrain = ("agent", "wall", "mountain")
    assert (
        len(ids)
        == len(set(ids))
        == 1 + sum(len(v) for k, v in RGW2_OBJECTS.items() if k not in terrain)
    )
    assert set(ids) == {
        "agent",
        "sword",
        "enemy",
        "terminal",
        "teleport_1",
        "teleport_2",
        "pit_1",
        "pit_2",
    }
    # Walls and mountains are terrain: named by the entity grid, not listed as objects.
    assert not {kind for _, kind, _, _ in info["objects"]} & {"wall", "mountain"}


def test_map_text_round_trip() -> None:
    m = load_map("rgw2")
    again = parse_map(m.text())
    assert (again.height, again.width, again.start) == (m.height, m.width, m.start)
    assert (again.cells == m.cells).all()
    assert m.text().splitlines()[3] == "........MQ"


def test_user_map_from_string_and_file(tmp_path) -> None:
    text = "# a corridor\nA.ST\n"
    env = RGWEnv(text)
    _, info = env.reset(seed=0)
    assert env.observation_space.shape == (9, 1, 4)
    rewards = [env.step(1)[1] for _ in range(3)]
    assert rewards == [0.0, 0.0, 10.0]
    path = tmp_path / "corridor.txt"
    path.write_text(text)
    env2 = RGWEnv(str(path))
    assert env2.reset(seed=0)[1] == info
    assert RGWEnv(path).source.name == "corridor.txt"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("A.X\n..T\n", r"unknown symbol 'X' at row 0, column 2"),
        ("A..\n..\n..T\n", r"row 1 has 2 cells, expected 3"),
        ("...\n..T\n", r"no agent start 'A'"),
        ("A..\n...\n", r"no terminal 'T'"),
        ("A.O\n..T\n", r"one teleport end at row 0, column 2"),
        ("AOO\nO.T\n", r"third teleport end at row 1, column 0"),
        ("A.A\n..T\n", r"second agent start 'A' at row 0, column 2"),
        ("# only a comment\n", r"no rows"),
    ],
)
def test_bad_maps_name_row_and_column(text: str, message: str) -> None:
    with pytest.raises(MapError, match=message):
        parse_map(text)


def test_unknown_map_name_is_refused() -> None:
    with pytest.raises(MapError, match="not a shipped map"):
        load_map("rgw9")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ("# café\nA.ST\n".encode("latin-1"), "not UTF-8 text (byte 0xe9 at offset 5)"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "not UTF-8 text (byte 0x89 at offset 0)"),
    ],
)
def test_a_map_file_that_is_not_utf8_is_one_line_naming_it(
    tmp_path, neurosym_main, monkeypatch, data: bytes, message: str
) -> None:
    path = tmp_path / "map.txt"
    path.write_bytes(data)
    with pytest.raises(MapError) as err:
        load_map(str(path))
    assert str(err.value) == f"map {str(path)!r}: {message}; a map is lines of .AWMPSETOQ"
    monkeypatch.chdir(Path(__file__).resolve().parents[2])  # checkpoints/ as from the repository
    proc = neurosym_main(
        "eval", "--checkpoint", "checkpoints/rgw2-predinet.pt", "--map", path, "--episodes", 1
    )
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == f"neurosym eval: error: {err.value}\n"


def test_a_utf8_map_with_a_byte_order_mark_loads(tmp_path) -> None:
    path = tmp_path / "bom.txt"
    path.write_bytes("\ufeffA.ST\n".encode())
    assert load_map(str(path)).text() == "A.ST\n"


def test_a_map_file_too_large_for_a_map_is_refused_unread(tmp_path) -> None:
    path = tmp_path / "huge.txt"
    with path.open("wb") as fh:
        fh.truncate(1 << 30)  # sparse: a GiB that takes no disk
    with pytest.raises(MapError, match=r"1,073,741,824 bytes, more than a map's 1,048,576"):
        load_map(str(path))
