"""From recorded episodes to facts: recording, thresholds, fact tables and their writers.

* :mod:`~neurosym.export.recorder` -- ``record(agent, env, episodes, seed)`` -> Recording
* :mod:`~neurosym.export.recording` -- the Recording tables and their Parquet round trip
* :mod:`~neurosym.export.thresholds` -- ``abs:X``, ``quantile:Q``, ``z:K`` per relation
* :mod:`~neurosym.export.facts` -- ``extract_facts(recording, threshold)`` -> FactSet
* :mod:`~neurosym.export.heads` -- ``head_summary(recording)``: which heads relate two objects
* :mod:`~neurosym.export.prolog_writer` -- pandas tables -> Prolog fact file (.pl, .qlf)
* :mod:`~neurosym.export.cli_extract` -- the ``neurosym extract`` command

Nothing is imported here, so ``import neurosym.export.facts`` does not pay for torch.
"""
