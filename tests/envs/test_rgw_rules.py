"""Relational-Grid-World rules: optimal returns, exact transition tables, reference models.

The reference models below are written straight from the rule lists (the
thesis text for the default rules, reference/rgw-original.md for classic=True),
one plain Python function per rule set, and every (cell, holding, action) of
rgw1 and rgw2 is checked against them.
"""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs.rgw import RGWEnv
from neurosym.envs.rgw_maps import load_map

UP, RIGHT, DOWN, LEFT = 0, 1, 2, 3
DELTA = {UP: (-1, 0), RIGHT: (0, 1), DOWN: (1, 0), LEFT: (0, -1)}

# Sword across one mountain, leave by another, one mountain before the teleport,
# teleport (3,9) -> (8,8), then along row 9 to the enemy and the terminal.
RGW2_OPTIMAL = [RIGHT] * 6 + [DOWN] * 3 + [RIGHT] * 3 + [DOWN] + [LEFT] * 8


def play(env: RGWEnv, actions: list[int]) -> tuple[float, list[dict]]:
    env.reset(seed=0)
    total, infos = 0.0, []
    for t, a in enumerate(actions):
        _, r, term, trunc, info = env.step(a)
        total += r
        infos.append(info)
        assert not trunc, f"[{t}] truncated"
        assert term == (t == len(actions) - 1), f"[{t}] terminated={term}"
    return total, infos


@pytest.mark.parametrize("classic", [False, True])
def test_rgw2_optimal_route_returns_10_7(classic: bool) -> None:
    total, infos = play(RGWEnv("rgw2", classic=classic), RGW2_OPTIMAL)
    assert round(total, 9) == 10.7
    events = [e for info in infos for e in info["events"]]
    assert events == [
        "crossed(mountain)",
        "picked(sword)",
        "crossed(mountain)",
        "crossed(mountain)",
        "teleported",
        "defeated(enemy)",
        "reached(terminal)",
    ]
    assert infos[-1]["outcome"] == "terminal"
    assert infos[-1]["agent"] == (9, 0)


def test_rgw1_optimal_route_returns_11() -> None:
    env = RGWEnv("rgw1")
    # rgw1 has no pits: walk down the right-hand side instead of teleporting.
    actions = [RIGHT] * 6 + [DOWN] * 5 + [RIGHT] * 3 + [DOWN] * 4 + [LEFT] * 9
    total, infos = play(env, actions)
    assert round(total, 9) == 11.0
    assert [e for i in infos for e in i["events"]] == [
        "picked(sword)",
        "defeated(enemy)",
        "reached(terminal)",
    ]


def test_rgw1_route_through_the_teleport_also_returns_11() -> None:
    actions = [RIGHT] * 6 + [DOWN] * 3 + [RIGHT] * 3 + [DOWN] + [LEFT] * 8
    total, _ = play(RGWEnv("rgw1"), actions)
    assert round(total, 9) == 11.0


def test_no_route_on_rgw2_beats_10_7() -> None:
    """Best undiscounted return over (cell, holding) by value iteration on the env's own steps."""
    env = RGWEnv("rgw2")
    env.reset(seed=0)
    cells = load_map("rgw2").cells.reshape(10, 10)
    states = [(r, c, h) for r in range(10) for c in range(10) for h in (0, 1) if cells[r, c] != 5]
    moves = {}
    for r, c, h in states:
        for a in range(4):
            env.set_state((r, c), holding=bool(h))
            _, rew, term, _, info = env.step(a)
            # Once the enemy is beaten only the terminal (next to it) is worth anything: +10.
            if "defeated(enemy)" in info["events"]:
                moves[(r, c, h, a)] = (rew + 10.0, None)
            else:
                nxt = None if term else (*info["agent"], 1 if info["holding"] else 0)
                moves[(r, c, h, a)] = (rew, nxt)
    value = dict.fromkeys(states, -np.inf)  # best return of a finished episode from each state
    while True:
        new = {
            s: max(
                rew + (0.0 if nxt is None else value[nxt])
                for rew, nxt in (moves[(*s, a)] for a in range(4))
            )
            for s in states
        }
        if new == value:
            break
        value = new
    assert round(value[(0, 0, 0)], 9) == 10.7


# -- reference models -----------------------------------------------------------


def reference_default(rows: list[str], pos, holding, enemy_alive, action, enemy="pass"):
    """The thesis text's rules, cell by cell. Returns (pos, reward, done, holding, events).

    ``enemy``: what an unarmed meeting does: pass (-1, stand on its cell),
    block (-1, stay where it was), end (-1, the episode ends).
    """
    H, W = len(rows), len(rows[0])
    r, c = pos
    dr, dc = DELTA[action]
    nr, nc = r + dr, c + dc
    if not (0 <= nr < H and 0 <= nc < W):
        return pos, 0.0, False, holding, ["bumped(border)"]
    if rows[nr][nc] == "W":
        return pos, 0.0, False, holding, ["bumped(wall)"]
    events = []
    if rows[nr][nc] in "OQ":
        ends = [(i, j) for i in range(H) for j in range(W) if rows[i][j] in "OQ"]
        nr, nc = ends[1] if (nr, nc) == ends[0] else ends[0]
        events.append("teleported")
    ch = rows[nr][nc]
    if ch == "S" and not holding:
        return (nr, nc), 0.0, False, True, [*events, "picked(sword)"]
    if ch == "E" and enemy_alive:
        if holding:
            return (nr, nc), 1.0, False, holding, [*events, "defeated(enemy)"]
        if enemy == "block":
            return pos, -1.0, False, holding, [*events, "hurt_by(enemy)", "bumped(enemy)"]
        if enemy == "end":
            return (nr, nc), -1.0, True, holding, [*events, "hurt_by(enemy)", "killed_by(enemy)"]
        return (nr, nc), -1.0, False, holding, [*events, "hurt_by(enemy)"]
    if ch == "M":
        return (nr, nc), -0.1, False, holding, [*events, "crossed(mountain)"]
    if ch == "P":
        return (nr, nc), -1.0, True, holding, [*events, "fell(pit)"]
    if ch == "T":
        return (nr, nc), 10.0, True, holding, [*events, "reached(terminal)"]
    return (nr, nc), 0.0, False, holding, events


def reference_classic(rows: list[str], pos, holding, action):
    """reference/rgw-original.md, 'Original dynamics', steps 1-8 literally."""
    H, W = len(rows), len(rows[0])
    r, c = pos
    dr, dc = DELTA[action]
    nr, nc = min(max(r + dr, 0), H - 1), min(max(c + dc, 0), W - 1)  # 1. clip
    if rows[nr][nc] == "W":  # 2. wall: stay
        nr, nc = r, c
    if rows[nr][nc] in "OQ":  # 3. teleport
        ends = [(i, j) for i in range(H) for j in range(W) if rows[i][j] in "OQ"]
        nr, nc = ends[1] if (nr, nc) == ends[0] else ends[0]
    new_holding = holding or rows[nr][nc] == "S"  # 4. sword
    state = r * W + c + (H * W if holding else 0)
    ch = rows[nr][nc]
    reward, done = 0.0, False
    if ch == "P":  # 5. first match wins
        reward, done = -1.0, True
    elif ch in "MQ":
        reward = -0.1
    elif ch == "E":
        reward = 1.0 if state > H * W else -1.0  # 8. the original's `>` test
    if ch == "T":
        reward, done = reward + 10.0, True
    return (nr, nc), reward, done, new_holding


def all_states(rows: list[str]):
    for r, row in enumerate(rows):
        for c, ch in enumerate(row):
            if ch != "W":
                for holding in (False, True):
                    for a in range(4):
                        yield (r, c), holding, a


@pytest.mark.parametrize("enemy", ["pass", "block", "end"])
@pytest.mark.parametrize("name", ["rgw1", "rgw2"])
def test_every_transition_matches_the_default_reference(name: str, enemy: str) -> None:
    rows = load_map(name).text().replace("A", ".").split()
    env = RGWEnv(name, enemy=enemy)
    env.reset(seed=0)
    for (r, c), holding, a in all_states(rows):
        env.set_state((r, c), holding=holding)
        _, rew, term, trunc, info = env.step(a)
        want = reference_default(rows, (r, c), holding, True, a, enemy)
        got = (info["agent"], rew, term, bool(info["holding"]), list(info["events"]))
        assert got == want, f"({r},{c}) holding={holding} action={a}: {got} != {want}"
        assert not trunc


@pytest.mark.parametrize("name", ["rgw1", "rgw2"])
def test_every_transition_matches_the_classic_reference(name: str) -> None:
    rows = load_map(name).text().replace("A", ".").split()
    env = RGWEnv(name, classic=True)
    env.reset(seed=0)
    for (r, c), holding, a in all_states(rows):
        env.set_state((r, c), holding=holding)
        _, rew, term, _, info = env.step(a)
        want = reference_classic(rows, (r, c), holding, a)
        got = (info["agent"], rew, term, bool(info["holding"]))
        assert got == want, f"({r},{c}) holding={holding} action={a}: {got} != {want}"


# -- exact tables for the cases that tell the rule sets apart -------------------

TINY = """\
AE.
S.M
T.P
"""

# (classic, actions from the start, expected per step: (agent, reward, terminated, events, holding))
CASES = [
    pytest.param(
        False,
        [RIGHT, LEFT, RIGHT, UP],
        [
            ((0, 1), -1.0, False, ("hurt_by(enemy)",), ()),
            ((0, 0), 0.0, False, (), ()),
            ((0, 1), -1.0, False, ("hurt_by(enemy)",), ()),
            ((0, 1), 0.0, False, ("bumped(border)",), ()),  # staying on the enemy pays nothing
        ],
        id="default-enemy-without-sword",
    ),
    pytest.param(
        True,
        [RIGHT, UP, UP],
        [
            ((0, 1), -1.0, False, ("hurt_by(enemy)",), ()),
            ((0, 1), -1.0, False, ("bumped(border)", "hurt_by(enemy)"), ()),  # paid again in place
            ((0, 1), -1.0, False, ("bumped(border)", "hurt_by(enemy)"), ()),
        ],
        id="classic-enemy-without-sword",
    ),
    pytest.param(
        False,
        [DOWN, UP, RIGHT, LEFT, RIGHT, UP],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((0, 0), 0.0, False, (), ("sword",)),
            ((0, 1), 1.0, False, ("defeated(enemy)",), ("sword",)),  # removed
            ((0, 0), 0.0, False, (), ("sword",)),
            ((0, 1), 0.0, False, (), ("sword",)),
            ((0, 1), 0.0, False, ("bumped(border)",), ("sword",)),
        ],
        id="default-enemy-with-sword-is-removed",
    ),
    pytest.param(
        True,
        [DOWN, UP, RIGHT, UP, UP],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((0, 0), 0.0, False, (), ("sword",)),
            # the original's `state > nS_pos`: holding at cell (0, 0) counts as not holding
            ((0, 1), -1.0, False, ("hurt_by(enemy)",), ("sword",)),
            ((0, 1), 1.0, False, ("bumped(border)", "defeated(enemy)"), ("sword",)),
            ((0, 1), 1.0, False, ("bumped(border)", "defeated(enemy)"), ("sword",)),
        ],
        id="classic-enemy-never-removed-and-off-by-one",
    ),
    pytest.param(
        False,
        [DOWN, RIGHT, RIGHT, DOWN],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((1, 1), 0.0, False, (), ("sword",)),
            ((1, 2), -0.1, False, ("crossed(mountain)",), ("sword",)),
            ((2, 2), -1.0, True, ("fell(pit)",), ("sword",)),
        ],
        id="default-mountain-then-pit",
    ),
    pytest.param(
        True,
        [DOWN, RIGHT, RIGHT, RIGHT, UP],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((1, 1), 0.0, False, (), ("sword",)),
            ((1, 2), -0.1, False, ("crossed(mountain)",), ("sword",)),
            ((1, 2), -0.1, False, ("bumped(border)", "crossed(mountain)"), ("sword",)),
            ((0, 2), 0.0, False, (), ("sword",)),
        ],
        id="classic-mountain-pays-in-place",
    ),
    pytest.param(
        False,
        [DOWN, RIGHT, RIGHT, UP, DOWN],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((1, 1), 0.0, False, (), ("sword",)),
            ((1, 2), -0.1, False, ("crossed(mountain)",), ("sword",)),
            ((0, 2), 0.0, False, (), ("sword",)),
            ((1, 2), -0.1, False, ("crossed(mountain)",), ("sword",)),
        ],
        id="default-mountain-on-entering",
    ),
    pytest.param(
        False,
        [DOWN, DOWN],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",)),
            ((2, 0), 10.0, True, ("reached(terminal)",), ("sword",)),
        ],
        id="default-terminal",
    ),
]


@pytest.mark.parametrize(("classic", "actions", "expected"), CASES)
def test_transition_table(classic: bool, actions: list[int], expected: list) -> None:
    env = RGWEnv(TINY, classic=classic)
    env.reset(seed=0)
    for t, (a, (agent, reward, term, events, holding)) in enumerate(
        zip(actions, expected, strict=True)
    ):
        _, r, te, tr, info = env.step(a)
        assert info["agent"] == agent, f"[{t}] agent {info['agent']} != {agent}"
        assert r == reward, f"[{t}] reward {r} != {reward}"
        assert te == term, f"[{t}] terminated {te}"
        assert not tr, f"[{t}] truncated"
        assert info["events"] == events, f"[{t}] events {info['events']} != {events}"
        assert info["holding"] == holding, f"[{t}] holding {info['holding']}"


def test_teleport_landing_default_and_classic() -> None:
    """rgw2: entering (8,8) from below lands on (3,9); classic also charges its mountain."""
    for classic, reward, events in [
        (False, 0.0, ("teleported",)),
        (True, -0.1, ("teleported", "crossed(mountain)")),
    ]:
        env = RGWEnv("rgw2", classic=classic)
        env.reset(seed=0)
        env.set_state((9, 8))
        _, r, _, _, info = env.step(UP)
        assert (info["agent"], r, info["events"]) == ((3, 9), reward, events), classic


def test_bumping_on_a_teleport_end_teleports_only_in_classic() -> None:
    for classic, agent, events in [
        (False, (3, 9), ("bumped(border)",)),
        (True, (8, 8), ("bumped(border)", "teleported")),
    ]:
        env = RGWEnv("rgw2", classic=classic)
        env.reset(seed=0)
        env.set_state((3, 9))
        _, r, _, _, info = env.step(RIGHT)
        assert (info["agent"], r, info["events"]) == (agent, 0.0, events), classic


def test_enemy_leaves_the_objects_when_defeated() -> None:
    env = RGWEnv(TINY)
    env.reset(seed=0)
    ids = [o[0] for o in env.step(DOWN)[4]["objects"]]
    assert "sword" not in ids and "enemy" in ids
    env.step(UP)
    info = env.step(RIGHT)[4]
    assert "enemy" not in [o[0] for o in info["objects"]]
    assert info["objects"][0] == ("agent", "agent", 0, 1)
    assert env.entity_grid()[0].tolist() == [8, 0, 8]


def test_timeout_is_truncation_not_termination() -> None:
    env = RGWEnv("rgw2", max_steps=3)
    env.reset(seed=0)
    results = [env.step(LEFT) for _ in range(3)]
    assert [(r[2], r[3], r[4]["outcome"]) for r in results] == [
        (False, False, None),
        (False, False, None),
        (False, True, "timeout"),
    ]


def test_terminal_on_the_last_step_is_termination_only() -> None:
    env = RGWEnv(TINY, max_steps=2)
    env.reset(seed=0)
    env.step(DOWN)
    _, r, term, trunc, info = env.step(DOWN)
    assert (r, term, trunc, info["outcome"]) == (10.0, True, False, "terminal")


def test_no_step_limit_with_max_steps_none() -> None:
    env = RGWEnv("rgw2", max_steps=None)
    env.reset(seed=0)
    assert not any(env.step(LEFT)[3] for _ in range(500))


def test_observation_planes_follow_the_entity_grid() -> None:
    env = RGWEnv("rgw2")
    obs, _ = env.reset(seed=0)
    ent = env.entity_grid()
    for code in range(8):
        assert (obs[code] == (ent == code)).all(), env.entity_names[code]
    assert obs[8].sum() == 0
    for a in RGW2_OPTIMAL[:6]:
        obs, *_ = env.step(a)
    ent = env.entity_grid()
    assert (obs[8] == 1).all()  # holding the sword
    assert obs[1].sum() == 0 and (obs[0] == (ent == 0)).all()


def test_grey_observation_uses_the_original_intensities() -> None:
    env = RGWEnv("rgw2", obs_mode="grey", classic=True)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (1, 10, 10) and obs.dtype == np.uint8
    g = obs[0]
    assert (g[0, 0], g[9, 0], g[3, 9], g[8, 8], g[0, 6], g[9, 1]) == (128, 255, 200, 200, 75, 175)
    assert (g[0, 5], g[7, 8], g[6, 0], g[5, 5]) == (150, 30, 0, 220)
    for a in RGW2_OPTIMAL[:7]:
        obs, *_ = env.step(a)
    assert obs[0, 0, 6] == 220 and obs[0, 1, 6] == 128  # sword taken, agent on the mountain
    assert env.obs_scale == 1 / 255


def test_bad_actions_are_refused() -> None:
    env = RGWEnv("rgw2")
    env.reset(seed=0)
    for bad in (4, -1, 1.5, "up", None):
        with pytest.raises(ValueError, match="action must be an integer 0..3"):
            env.step(bad)
    env.step(np.int64(2))  # numpy integers are fine


# -- what an unarmed meeting with the enemy does: exact tables, single and batched -------

# Agent on a mountain beside the enemy: a blocked step keeps it on the mountain.
GUARD = """\
AME
S.T
"""

# (enemy, actions, expected per step: (agent, reward, terminated, events, holding, outcome))
ENEMY_CASES = [
    pytest.param(
        "pass",
        [RIGHT, RIGHT, DOWN],
        [
            ((0, 1), -0.1, False, ("crossed(mountain)",), (), None),
            ((0, 2), -1.0, False, ("hurt_by(enemy)",), (), None),  # passes, stands on it
            ((1, 2), 10.0, True, ("reached(terminal)",), (), "terminal"),
        ],
        id="pass",
    ),
    pytest.param(
        "block",
        [RIGHT, RIGHT, RIGHT, UP, LEFT, LEFT, DOWN, RIGHT, RIGHT],
        [
            ((0, 1), -0.1, False, ("crossed(mountain)",), (), None),
            ((0, 1), -1.0, False, ("hurt_by(enemy)", "bumped(enemy)"), (), None),  # stays
            ((0, 1), -1.0, False, ("hurt_by(enemy)", "bumped(enemy)"), (), None),  # every time
            ((0, 1), 0.0, False, ("bumped(border)",), (), None),  # staying pays nothing
            ((0, 0), 0.0, False, (), (), None),
            ((0, 0), 0.0, False, ("bumped(border)",), (), None),
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",), None),
            ((1, 1), 0.0, False, (), ("sword",), None),
            ((1, 2), 10.0, True, ("reached(terminal)",), ("sword",), "terminal"),
        ],
        id="block",
    ),
    pytest.param(
        "block",
        [DOWN, UP, RIGHT, RIGHT, LEFT, RIGHT, DOWN],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",), None),
            ((0, 0), 0.0, False, (), ("sword",), None),
            ((0, 1), -0.1, False, ("crossed(mountain)",), ("sword",), None),
            ((0, 2), 1.0, False, ("defeated(enemy)",), ("sword",), None),  # armed: unchanged
            ((0, 1), -0.1, False, ("crossed(mountain)",), ("sword",), None),
            ((0, 2), 0.0, False, (), ("sword",), None),  # the enemy is gone
            ((1, 2), 10.0, True, ("reached(terminal)",), ("sword",), "terminal"),
        ],
        id="block-armed",
    ),
    pytest.param(
        "end",
        [RIGHT, RIGHT],
        [
            ((0, 1), -0.1, False, ("crossed(mountain)",), (), None),
            ((0, 2), -1.0, True, ("hurt_by(enemy)", "killed_by(enemy)"), (), "enemy"),
        ],
        id="end",
    ),
    pytest.param(
        "end",
        [DOWN, UP, RIGHT, RIGHT, DOWN],
        [
            ((1, 0), 0.0, False, ("picked(sword)",), ("sword",), None),
            ((0, 0), 0.0, False, (), ("sword",), None),
            ((0, 1), -0.1, False, ("crossed(mountain)",), ("sword",), None),
            ((0, 2), 1.0, False, ("defeated(enemy)",), ("sword",), None),
            ((1, 2), 10.0, True, ("reached(terminal)",), ("sword",), "terminal"),
        ],
        id="end-armed",
    ),
]


def _redraw(grid: np.ndarray, holding: bool) -> np.ndarray:
    """The onehot observation drawn from scratch from an entity grid."""
    obs = (grid[None] == np.arange(9)[:, None, None]).astype(np.uint8)
    obs[8] = holding
    return obs


@pytest.mark.parametrize(("enemy", "actions", "expected"), ENEMY_CASES)
def test_enemy_mode_table_single_and_batched(enemy: str, actions: list[int], expected) -> None:
    from neurosym.envs.rgw_vector import RGWVectorEnv

    env = RGWEnv(GUARD, enemy=enemy)
    vec = RGWVectorEnv(1, map=GUARD, enemy=enemy)
    env.reset(seed=0)
    vec.reset(seed=0)
    for t, (a, (agent, reward, term, events, holding, outcome)) in enumerate(
        zip(actions, expected, strict=True)
    ):
        obs, r, te, tr, info = env.step(a)
        vobs, vr, vte, vtr, vinfo = vec.step([a])
        want = (agent, reward, term, events, holding, outcome)
        got = (info["agent"], r, te, info["events"], info["holding"], info["outcome"])
        assert got == want, f"[{t}] single {got} != {want}"
        vgot = vec.decode_info(vinfo, 0)
        vgot = (vgot["agent"], vr[0], vte[0], vgot["events"], vgot["holding"], vgot["outcome"])
        assert vgot == want, f"[{t}] batched {vgot} != {want}"
        assert not tr and not vtr[0], f"[{t}] truncated"
        assert (obs == vobs[0]).all(), f"[{t}] observations differ"
        assert (obs == _redraw(env.entity_grid(), bool(holding))).all(), f"[{t}] not a redraw"


def test_enemy_mode_is_checked() -> None:
    from neurosym.errors import ConfigError

    with pytest.raises(ConfigError, match="enemy 'wall' is not one of pass, block, end"):
        RGWEnv("rgw2", enemy="wall")
    with pytest.raises(ConfigError, match="classic=True: the original release always lets"):
        RGWEnv("rgw2", classic=True, enemy="block")
    assert RGWEnv("rgw2").enemy == "pass"  # the thesis's rule stays the default


@pytest.mark.parametrize("enemy", ["pass", "block", "end"])
def test_rgw2_optimal_route_in_every_enemy_mode(enemy: str) -> None:
    total, _ = play(RGWEnv("rgw2", enemy=enemy), RGW2_OPTIMAL)
    assert round(total, 9) == 10.7
