"""neurosym: make a reinforcement-learning agent's relational reasoning explicit.

The top-level names are imported lazily so that ``import neurosym`` (and the
``neurosym query`` command) does not pay for importing torch.

    >>> import neurosym
    >>> agent = neurosym.load_agent("checkpoints/rgw2-predinet.pt")
    >>> rec = neurosym.record(agent, "rgw2", episodes=5, seed=0)
    >>> facts = neurosym.extract_facts(rec, threshold="quantile:0.9")
    >>> kb = neurosym.KnowledgeBase(facts.to_prolog("kb/rgw2.pl"), rules=["rules/rgw.pl"])
    >>> kb.query("sword_before_enemy(E)")
"""

from __future__ import annotations

from neurosym.lazy import lazy_attributes

__version__ = "0.1.0"

_LAZY = {
    "make": "neurosym.envs",
    "make_batched": "neurosym.envs",
    "load_agent": "neurosym.agent.checkpoint",
    "record": "neurosym.export.recorder",
    "Recording": "neurosym.export.recording",
    "extract_facts": "neurosym.export.facts",
    "FactSet": "neurosym.export.facts",
    "head_summary": "neurosym.export.heads",
    "KnowledgeBase": "neurosym.prolog.knowledge_base",
    "NeurosymError": "neurosym.errors",
    "PrologError": "neurosym.errors",
    "CheckpointError": "neurosym.errors",
    "Term": "neurosym.terms",
    "probe": "neurosym.meaning.probe",
    "intervene": "neurosym.meaning.intervene",
}

__all__ = ["__version__", *_LAZY]


__getattr__ = lazy_attributes(__name__, _LAZY)
