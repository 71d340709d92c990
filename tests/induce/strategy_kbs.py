"""Small knowledge bases written as text for the strategy tests (the schema of neurosym extract)."""

from __future__ import annotations

import random
from pathlib import Path

HEADER = """:- encoding(utf8).
""" + "".join(
    f":- dynamic {p}.\n"
    for p in (
        "kb_meta/2", "object/2", "episode/4", "grid/3", "terrain/4", "step/4", "at/5",
        "holding/3", "event/3", "attends/8", "relation/7", "holds/5", "threshold/2", "attention/6",
    )
)  # fmt: skip

MOVES = {"up": (-1, 0), "right": (0, 1), "down": (1, 0), "left": (0, -1)}


def write_kb(path: Path, facts: list[str]) -> Path:
    path.write_text(HEADER + "\n".join(facts) + "\n", encoding="utf-8")
    return path


def nearest_key_kb(path: Path, episodes: int, seed: int, size: int = 7) -> Path:
    """Episodes in which the agent walks to the nearest key (a gem, often nearer, is ignored).

    Each episode has three loose keys and a gem on a size x size grid (no terrain); the
    agent moves rows first, then columns, into the nearest key, which is then picked
    (got(key(C))). Levels with a tie for the nearest key are drawn again. Relation facts:
    head 0's argument 1 attends the key the agent goes for, argument 2 a random object.
    """
    rng = random.Random(seed)
    colours = ("blue", "green", "red")
    facts = ["kb_meta(env,bw1).", "kb_meta(module,predinet).", "kb_meta(heads,1).",
             "kb_meta(relations,1).", "object(agent,agent).", "object(gem,gem)."]  # fmt: skip
    facts += [f"object(key_{c},key({c}))." for c in colours]
    for e in range(episodes):
        while True:
            cells = rng.sample([(r, c) for r in range(size) for c in range(size)], 5)
            agent, gem, keys = cells[0], cells[1], dict(zip(colours, cells[2:], strict=True))
            dist = {c: abs(r - agent[0]) + abs(k - agent[1]) for c, (r, k) in keys.items()}
            if sorted(dist.values())[0] < sorted(dist.values())[1]:
                break
        goal = min(dist, key=dist.__getitem__)
        walk = _walk(agent, keys[goal])
        facts.append(f"grid({e},{size},{size}).")
        pos = agent
        for t, action in enumerate(walk):
            facts.append(f"at({e},{t},agent,{pos[0]},{pos[1]}).")
            facts.append(f"at({e},{t},gem,{gem[0]},{gem[1]}).")
            for c, (r, k) in keys.items():
                facts.append(f"at({e},{t},key_{c},{r},{k}).")
            facts.append(f"attends({e},{t},0,1,key({goal}),{keys[goal][0]},{keys[goal][1]},1.0).")
            other = rng.choice([gem, *keys.values()])
            facts.append(f"attends({e},{t},0,2,gem,{other[0]},{other[1]},1.0).")
            facts.append(f"step({e},{t},{action},0.0).")
            dr, dc = MOVES[action]
            pos = (pos[0] + dr, pos[1] + dc)
        facts.append(f"event({e},{len(walk) - 1},got(key({goal}))).")
        facts.append(f"episode({e},{len(walk)},0.0,timeout).")
    return write_kb(path, facts)


def _walk(start: tuple[int, int], goal: tuple[int, int]) -> list[str]:
    rows = goal[0] - start[0]
    cols = goal[1] - start[1]
    return ["down" if rows > 0 else "up"] * abs(rows) + ["right" if cols > 0 else "left"] * abs(cols)
