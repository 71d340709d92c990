"""World rules learned from 100 recorded episodes, scored on 100 held-out ones; prints JSON lines.

For each case (rgw-random under each enemy mode, bw1, bw2, bw3) it records
``--episodes`` training episodes from seed 0 and as many held-out ones from
seed 1,000,000 with a shipped checkpoint (MHDPA: the smallest KBs), writes both
KBs as ``neurosym extract`` does, learns with
:func:`neurosym.induce.induce_world` and prints one line per case:

* ``learn_s``: learning time (loading and grounding the training KB, then the
  clause search), ``ground_s`` the first part;
* ``events``: per event of the vocabulary its status, clauses, train and
  held-out precision/recall, and ``solved`` (IGGP's "solved perfectly");
* ``solved``/``determined``: how many determined events are solved perfectly;
* with ``--baseline``, a second line per case: a scikit-learn decision tree
  per determined event over the same answers propositionalised (held-out
  precision, recall, leaves), the learner the clause search was chosen over.

Actions are uniformly random (``--actions random``, the default) or the
agent's own (``--actions agent``, greedy), so the two can be compared.

    python bench/induce.py                          # every case, random actions
    python bench/induce.py --cases rgw-pass --actions agent
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CASES: dict[str, tuple[str, str, dict[str, Any]]] = {
    "rgw-pass": ("rgw-random-mhdpa", "rgw-random", {"enemy": "pass"}),
    "rgw-block": ("rgw-random-mhdpa", "rgw-random", {"enemy": "block"}),
    "rgw-end": ("rgw-random-mhdpa", "rgw-random", {"enemy": "end"}),
    "bw1": ("bw1-mhdpa", "bw1", {}),
    "bw2": ("bw2-mhdpa", "bw2", {}),
    "bw3": ("bw3-mhdpa", "bw3", {}),
}
HOLDOUT_SEED = 1_000_000


def emit(**fields: Any) -> None:
    print(json.dumps(fields), flush=True)


def write_kb(
    agent: Any, env: str, options: dict, episodes: int, seed: int, actions: str, path: Path
) -> dict:
    from neurosym.facts.tables import extract_facts
    from neurosym.record.recorder import record

    start = time.perf_counter()
    rec = record(agent, env, episodes, seed=seed, actions=actions, env_kwargs=options)
    extract_facts(rec).to_prolog(path)
    return {"steps": rec.n_steps, "record_s": round(time.perf_counter() - start, 1)}


def tree_baseline(train: Path, held: Path, templates: list[str]) -> dict[str, list[float]]:
    """A scikit-learn decision tree per event over the same grounded answers, propositionalised.

    Features: one boolean per (predicate, value) (colours as constants, as a
    tree must have them); label: the step has some event of the template
    (the colour the event names is not predicted, which a tree cannot do).
    Returns event -> [held-out precision, held-out recall, leaves].
    """
    import numpy as np
    from sklearn.tree import DecisionTreeClassifier

    from neurosym.induce.examples import PREDICATES, ground
    from neurosym.induce.foil import positives

    g, h = ground(train), ground(held)
    columns = [(p, v) for p in PREDICATES for v in g.values]

    def features(x: Any) -> np.ndarray:
        cols = []
        for pred, value in columns:
            i = x.value_index.get(value)
            cols.append(x.matrix[pred][:, i] if i is not None else np.zeros(x.n_states, bool))
        return np.stack(cols, axis=1)

    def labels(x: Any, template: str) -> np.ndarray:
        keys = positives(x, template)
        step = keys // max(len(x.colours), 1) if "C" in template else keys
        y = np.zeros(x.n_states, bool)
        y[step] = True
        return y

    xg, xh = features(g), features(h)
    out = {}
    for template in templates:
        tree = DecisionTreeClassifier(random_state=0).fit(xg, labels(g, template))
        pred, y = tree.predict(xh), labels(h, template)
        tp = int((pred & y).sum())
        out[template] = [
            round(tp / pred.sum(), 4) if pred.sum() else 1.0,
            round(tp / y.sum(), 4) if y.sum() else 1.0,
            int(tree.get_n_leaves()),
        ]
    return out


def run_case(name: str, episodes: int, actions: str, folder: Path, baseline: bool) -> None:
    from neurosym.agent.agent import load_agent
    from neurosym.induce import induce_world

    ckpt, env, options = CASES[name]
    agent = load_agent(ROOT / "checkpoints" / f"{ckpt}.pt")
    train, held = folder / f"{name}-train.pl", folder / f"{name}-held.pl"
    made = [
        write_kb(agent, env, options, episodes, seed, actions, path)
        for seed, path in ((0, train), (HOLDOUT_SEED, held))
    ]
    rules = induce_world(train, holdout=held)
    events = {
        e: {
            "status": s.status,
            "clauses": [" ".join(x.strip() for x in c.text().splitlines()) for c in s.clauses],
            "train": [s.train_examples, s.train_precision, s.train_recall],
            "holdout": [s.holdout_examples, s.holdout_precision, s.holdout_recall],
            "solved": s.solved if s.status == "determined" else None,
            **({"reason": s.reason} if s.reason else {}),
        }
        for e, s in rules.scores.items()
    }
    determined = [s for s in rules.scores.values() if s.status == "determined"]
    emit(
        case=name, checkpoint=ckpt, env=env, options=options, actions=actions,
        episodes=episodes, train_steps=made[0]["steps"], holdout_steps=made[1]["steps"],
        kb_mb=round(train.stat().st_size / 1e6, 1),
        learn_s=round(rules.seconds, 2), ground_s=round(rules.ground_seconds, 2),
        determined=len(determined), solved=sum(s.solved for s in determined), events=events,
    )  # fmt: skip
    if baseline:
        start = time.perf_counter()
        tree = tree_baseline(train, held, [s.event for s in determined])
        emit(case=name, baseline="tree", seconds=round(time.perf_counter() - start, 2), events=tree)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default=",".join(CASES), help="comma-separated cases")
    parser.add_argument("--episodes", type=int, default=100)
    parser.add_argument("--actions", choices=("random", "agent"), default="random")
    parser.add_argument(
        "--baseline", action="store_true", help="also score a decision tree per event (sklearn)"
    )
    args = parser.parse_args()
    emit(machine={"cores": os.cpu_count(), "load": os.getloadavg()})
    with tempfile.TemporaryDirectory(prefix="bench-induce-") as tmp:
        for name in args.cases.split(","):
            run_case(name, args.episodes, args.actions, Path(tmp), args.baseline)


if __name__ == "__main__":
    main()
