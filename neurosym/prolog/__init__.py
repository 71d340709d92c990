"""SWI-Prolog from Python: knowledge bases, the query command, locating Prolog.

* :mod:`~neurosym.prolog.knowledge_base`: :class:`KnowledgeBase` (facts and
  rules in a module of their own, queried with Python values through janus);
* :mod:`~neurosym.prolog.cli_query`: ``neurosym query``;
* :mod:`~neurosym.prolog.qlf`: compiling fact files to quick-load ``.qlf``;
* :mod:`~neurosym.prolog.locate`: the one place that finds ``swipl`` and
  points janus at its home (import janus only through ``import_janus``);
* :mod:`~neurosym.prolog.bridge`, :mod:`~neurosym.prolog.fact_reader`: the
  Prolog half of the bridge and the reader that admits a fact file as data,
  SWI-Prolog modules in ``pl/`` (plunit tests beside them, ``*.plt``),
  loaded once per process by :func:`~neurosym.prolog.locate.janus_with`.

Nothing here imports janus or pandas until a KnowledgeBase is made.
"""
