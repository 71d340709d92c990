"""``neurosym report``: one self-contained HTML page per agent.

The page puts what the other commands find about an agent side by side: its
card, an episode player (the map, each head's attention and relation values,
step by step), the head summary, the strongest relations, the rule answers,
and, when given, probe and experiment tables. Its data come from the folder
``neurosym extract --out DIR`` writes (``recording/``, ``kb.pl``) and are
embedded in the page as JSON; the page needs no network and no server.

* :mod:`neurosym.reports.web.player` -- the recording's tables, per episode, for the player;
* :mod:`neurosym.reports.web.tables` -- the summary tables, with links to episode and step;
* :mod:`neurosym.reports.web.card` -- the agent's card from the checkpoint;
* :mod:`neurosym.reports.web.extras` -- probe and experiment folders;
* :mod:`neurosym.reports.web.page` -- the Jinja2 template rendered and written atomically;
* :mod:`neurosym.reports.web.pages` -- :func:`report_recording`, :func:`report_agent`: the pipeline;
* :mod:`neurosym.reports.web.cli_report` -- the command.
"""
