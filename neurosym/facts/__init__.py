"""Facts: the KB schema, the fact tables a Recording gives, and their Prolog writer.

* :mod:`~neurosym.facts.schema` -- every KB predicate declared once (names, arguments, meaning)
* :mod:`~neurosym.facts.thresholds` -- ``abs:X``, ``quantile:Q``, ``z:K`` per relation
* :mod:`~neurosym.facts.tables` -- ``extract_facts(recording, threshold)`` -> FactSet
* :mod:`~neurosym.facts.prolog_writer` -- pandas tables -> Prolog fact file (.pl, .qlf)

Nothing is imported here, so ``import neurosym.facts.tables`` does not pay for torch.
"""
