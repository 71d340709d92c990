"""The link answers of rules/lib/kb_common.pl as `neurosym extract` prints them: each says
what kind of link it is and what its share counts (states out of the states acted in)."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.reports.terminal import link_text
from neurosym.terms import Term

REPO = Path(__file__).resolve().parents[2]


def share(n: int, d: int) -> Term:
    return Term("share", (n, d))


@pytest.mark.parametrize(
    ("answer", "words"),
    [
        (Term("direct", ((Term("r", (1,)), Term("attention", (2,))), share(4, 124))),
         "direct: r(1), attention(2) on 4 of 124 states"),
        (Term("indirect", ((Term("via", ("agent", share(2, 40))),
                            Term("via", ("teleport", share(1, 40)))),)),
         "indirect via agent on 2 of 40 states; teleport on 1 of 40 states"),
        (Term("co_occurring", ((Term("apart", ("agent", share(6, 40), share(8, 40))),),)),
         "co-occurring only: agent: with sword on 6, with enemy on 8 of 40 states, "
         "never within one step"),
        ("none", "none"),
    ],
)  # fmt: skip
def test_link_answers_in_words(answer: object, words: str) -> None:
    assert link_text(answer, ("sword", "enemy")) == words


# rgw1's head 0 (the agent with the sword on states 0-5, with the enemy on 12-19) as a
# KB: the whole-recording rule called this indirect([agent]); in time it is co-occurring.
RGW1_LIKE = "".join(
    [":- dynamic attention/6.\n", "object(sword, sword).\n", "object(enemy, enemy).\n",
     "episode(0, 20, 11.0, terminal).\n"]
    + [f"holds(0, {t}, r(0), agent, sword).\n" for t in range(6)]
    + [f"holds(0, {t}, r(0), enemy, agent).\n" for t in range(12, 20)]
)  # fmt: skip


def test_a_link_through_the_agent_at_different_times_co_occurs(tmp_path: Path) -> None:
    kb_path = tmp_path / "kb.pl"
    kb_path.write_text(RGW1_LIKE)
    with KnowledgeBase(kb_path, rules=["rgw", "relations"]) as kb:
        answer = kb.once("sword_enemy_link(A)")["A"]
        assert answer == Term(
            "co_occurring", ((Term("apart", ("agent", share(6, 20), share(8, 20))),),)
        )
        assert kb.query("sword_enemy_via(X)") == []
        assert kb.once("entity_link(sword, enemy, A)")["A"] == answer  # the generic rule
        assert kb.once("entity_link(agent, sword, A)")["A"] == Term(
            "direct", ((Term("r", (0,)),), share(6, 20))
        )


def test_extract_prints_the_link_and_what_it_counts(neurosym_main, tmp_path: Path) -> None:
    """A tiny recording (2 random episodes of the shipped rgw1 MHDPA agent): the answer in
    words with its share, and the note saying what the shares count."""
    out = tmp_path / "kb"
    proc = neurosym_main(
        "extract", "--checkpoint", REPO / "checkpoints" / "rgw1-mhdpa.pt", "--episodes", "2",
        "--actions", "random", "--out", out,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    with KnowledgeBase(out / "kb.pl", rules=["rgw"]) as kb:
        assert kb.once("sword_enemy_link(A)")["A"] == Term(
            "indirect", ((Term("via", ("agent", share(65, 200))),),)
        )
    lines = proc.stdout.splitlines()
    assert " sword-enemy link in the network       │ indirect via agent on 65 of 200 states " in (
        lines
    )
    assert "(links: states out of all the states the agent acted in; indirect: through" in (
        proc.stdout
    )
