"""From a trained checkpoint to rule answers in a few lines.

    python examples/extract_and_query.py [CHECKPOINT] [OUT_DIR]

Records greedy episodes of the agent on the environment it was trained on,
thresholds each relation at the 0.9 quantile of its |values|, writes the
knowledge base and asks the rules what the agent did and what its network
relates. Defaults: the shipped agent rgw2-predinet, kb_out/example. Shipped
agents and rule files go by name (``neurosym agents`` lists the agents).
"""

import sys
from pathlib import Path

import neurosym
from neurosym.envs import env_family

checkpoint = sys.argv[1] if len(sys.argv) > 1 else "rgw2-predinet"
out = Path(sys.argv[2] if len(sys.argv) > 2 else "kb_out/example")

agent = neurosym.load_agent(checkpoint)
recording = neurosym.record(agent, episodes=10, seed=0)  # on the env it was trained on
facts = neurosym.extract_facts(recording, threshold="quantile:0.9")
print(facts.summary())
kb_path = facts.to_prolog(out / "kb.pl")

family = env_family(agent.env_name)  # "rgw" or "boxworld"
with neurosym.KnowledgeBase(kb_path, rules=[family, "relations"]) as kb:  # shipped rule files
    if family == "rgw":
        print(
            "sword before enemy in episodes:", [a["E"] for a in kb.query("sword_before_enemy(E)")]
        )
        print(
            "visited in the level's optimal order:", [a["E"] for a in kb.query("optimal_order(E)")]
        )
        # direct(Links, share(N, D)): related at one state, on N of the D states the agent
        # acted in; indirect([via(X, share(N, D))]): through X at one state or two consecutive
        # ones; co_occurring([apart(X, ...)]): through X only across the recording; none
        print("how the network links sword and enemy:", kb.once("sword_enemy_link(A)")["A"])
    else:
        print(
            "reached the gem along the solution:",
            [a["E"] for a in kb.query("followed_solution(E)")],
        )
        # per lock colour, the same answers as sword_enemy_link/1 (rules/rgw.pl)
        print("key-lock links in the network:", kb.query("key_lock_link(C, A)"))
    print("relations that consistently order two object types:")
    print(kb.query_df("consistently_orders(J, A, B), A \\== empty, B \\== empty"))
