"""neurosym: make a reinforcement-learning agent's relational reasoning explicit.

The top-level names are imported lazily so that ``import neurosym`` (and the
``neurosym query`` command) does not pay for importing torch.

    >>> import neurosym
    >>> agent = neurosym.load_agent("checkpoints/rgw2-predinet.pt")
    >>> rec = neurosym.record(agent, "rgw2", episodes=5, seed=0)
    >>> facts = neurosym.extract_facts(rec, threshold="quantile:0.9")
    >>> kb = neurosym.KnowledgeBase(facts.to_prolog("kb/rgw2.pl"), rules=["rules/rgw.pl"])
    >>> kb.query("sword_before_enemy(E)")

The commands' pipelines are library functions returning typed results:
``neurosym.extract(checkpoint, env, ...)`` -> Extraction (recording and fact tables),
``neurosym.evaluate(agent, env, ...)`` -> Evaluation (``.as_dict()`` is ``eval --json``),
``neurosym.score_strategy(policy, env, ...)`` -> StrategyPlay (``play --json``),
``neurosym.report_agent(agent, ...)`` / ``report_recording(folder)`` -> ReportPage.
"""

from __future__ import annotations

from neurosym.lazy import lazy_attributes

__version__ = "0.1.0"

_LAZY = {
    "make": "neurosym.envs",
    "make_batched": "neurosym.envs",
    "load_agent": "neurosym.agent.agent",
    "record": "neurosym.record.recorder",
    "Recording": "neurosym.record.recording",
    "extract_facts": "neurosym.facts.tables",
    "FactSet": "neurosym.facts.tables",
    "head_summary": "neurosym.record.heads",
    "extract": "neurosym.record.extraction",
    "Extraction": "neurosym.record.extraction",
    "evaluate": "neurosym.agent.evaluation",
    "Evaluation": "neurosym.agent.evaluation",
    "score_strategy": "neurosym.play.evaluate",
    "StrategyPlay": "neurosym.play.evaluate",
    "report_agent": "neurosym.reports.web.pages",
    "report_recording": "neurosym.reports.web.pages",
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
