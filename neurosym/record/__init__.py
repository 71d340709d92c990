"""Recording an agent: its episodes played and kept as tables, and the ``extract`` command.

* :mod:`~neurosym.record.recorder` -- ``record(agent, env, episodes, seed)`` -> Recording
* :mod:`~neurosym.record.recording` -- the Recording tables and their Parquet round trip
* :mod:`~neurosym.record.heads` -- ``head_summary(recording)``: which heads relate two objects
* :mod:`~neurosym.record.cli_extract` -- the ``neurosym extract`` command (record, then
  :mod:`neurosym.facts`)

Nothing is imported here, so ``import neurosym.record.recording`` does not pay for torch.
"""
