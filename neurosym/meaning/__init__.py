"""What the relations mean: probes that name them, controlled experiments that test them.

* :mod:`~neurosym.meaning.predicates` -- symbolic predicates of each recorded state, from the trace
* :mod:`~neurosym.meaning.features` -- replaying a recording through a network, per-head vectors,
  head ablation hooks
* :mod:`~neurosym.meaning.probe` -- ``probe(agent, ...)``: linear probes with control tasks
* :mod:`~neurosym.meaning.levels` -- changed RGW levels (remove, move, swap objects)
* :mod:`~neurosym.meaning.intervene` -- ``intervene(agent, ...)``: controlled experiments
* ``cli_probe``, ``cli_intervene`` -- the ``neurosym probe`` and ``neurosym intervene`` commands

Nothing is imported here, so ``import neurosym.meaning.levels`` does not pay for torch.
"""
