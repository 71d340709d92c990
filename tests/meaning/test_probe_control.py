"""The probes' untrained control: a freshly initialised network of the agent's shape, probed on
the agent's very states, beside the control task (selectivity next to the untrained network's)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import torch

from neurosym.agent.networks.model import ActorCritic
from neurosym.meaning import features
from neurosym.meaning.probe import probe_recording
from neurosym.record.recorder import record


def test_the_untrained_probes_read_a_fresh_network_on_the_same_states(
    monkeypatch,
    small_agent,  # noqa: ANN001
) -> None:
    agent = small_agent("rgw2")
    with torch.random.fork_rng():
        torch.manual_seed(7)  # weights of another seed than the control's: a stand-in for training
        agent = replace(agent, model=ActorCritic(agent.config).eval())
    seen: list[tuple[torch.nn.Module, np.ndarray]] = []
    head_vectors = features.head_vectors

    def spy(model, obs):  # noqa: ANN001, ANN202
        seen.append((model, obs))
        return head_vectors(model, obs)

    monkeypatch.setattr(features, "head_vectors", spy)
    rec = record(agent, "rgw2", episodes=6, seed=0, greedy=False)
    report = probe_recording(agent, rec, seed=3)
    (trained, obs), (untrained, obs_untrained) = seen
    assert trained is agent.model
    assert obs_untrained is obs  # the very states the agent visited
    with torch.random.fork_rng():
        torch.manual_seed(3)  # the probe's seed
        fresh = ActorCritic(agent.config).state_dict()
    mine = agent.model.state_dict()
    for name, value in untrained.state_dict().items():
        assert torch.equal(value, fresh[name]), name
    assert any(not torch.equal(value, mine[name]) for name, value in fresh.items())
    table = report.table
    assert len(table) > 0
    assert table["untrained_selectivity"].notna().all()
    np.testing.assert_allclose(
        table["untrained_selectivity"], table["untrained_accuracy"] - table["untrained_control"]
    )
    facts = report.facts()
    assert len(facts["probe_untrained"]) == len(facts["probe"]) == len(table)
