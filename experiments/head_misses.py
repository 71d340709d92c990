"""Where a head's argument is not the agent's next object: counted by what each holds.

    python experiments/head_misses.py KB.pl [--head 0] [--arg 2]

For every labelled state of a KB (its next object, as ``neurosym induce strategy`` labels
it: the object of the agent's next contact), whether ``attends/8`` of the head's argument
names that object's cell, tabulated by the next object's kind against the kind of what the
argument names instead ("empty": a cell no object is on), and the episodes with the most
misses (a greedy agent looping repeats one miss for the rest of its episode). Counts are
states, each state of each recorded episode once.
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurosym.induce.strategy_data import labels, load_trace


def kind(type_text: str) -> str:
    """``key(red)`` -> ``key``."""
    return type_text.split("(")[0]


def misses(kb: str, head: int, arg: int) -> pd.DataFrame:
    """Per labelled state: E, T, the next object's kind, what the argument names, hit."""
    trace = load_trace(kb)
    states = labels(trace)
    types = {o: kind(t) for o, t in zip(trace.object["O"], trace.object["Ty"], strict=True)}
    types["agent"] = "agent"
    at = trace.at
    cell = {(e, t, o): (r, c) for e, t, o, r, c in at.itertuples(index=False)}
    on: dict[tuple, list[str]] = {}
    for e, t, o, r, c in at.itertuples(index=False):
        on.setdefault((e, t, r, c), []).append(types[o])
    a = trace.attends
    picked = a[(a["H"] == head) & (a["Arg"] == arg)][["E", "T", "R", "C"]]
    m = states.merge(picked, on=["E", "T"], how="left")
    rows = []
    for e, t, goal, r, c in m[["E", "T", "Goal", "R", "C"]].itertuples(index=False):
        named = "none" if pd.isna(r) else ",".join(sorted(on.get((e, t, int(r), int(c)), ["empty"])))
        hit = not pd.isna(r) and cell.get((e, t, goal)) == (int(r), int(c))
        rows.append((e, t, types[goal], named, hit))
    return pd.DataFrame(rows, columns=["E", "T", "next", "named", "hit"])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("kb")
    p.add_argument("--head", type=int, default=0)
    p.add_argument("--arg", type=int, default=2, choices=(1, 2))
    args = p.parse_args()
    m = misses(args.kb, args.head, args.arg)
    print(f"{len(m)} labelled states; head {args.head} argument {args.arg} names the next object "
          f"on {m.hit.sum()} ({m.hit.mean():.3f})")  # fmt: skip
    print("\nnext object (rows) against what the argument names when it misses (columns):")
    print(pd.crosstab(m[~m.hit]["next"], m[~m.hit]["named"], margins=True).to_string())
    print("\nby next object: states, share named")
    print(m.groupby("next").hit.agg(["size", "mean"]).round(3).to_string())
    per = m.groupby("E").agg(states=("hit", "size"), misses=("hit", lambda s: int((~s).sum())))
    print("\nepisodes with the most misses:")
    print(per.sort_values("misses", ascending=False).head(5).to_string())


if __name__ == "__main__":
    main()
