"""What neurosym reports about an agent: in the terminal and as a web page.

* :mod:`~neurosym.reports.terminal` -- what ``neurosym extract`` prints (episodes, facts,
  heads, relations, rule answers)
* :mod:`~neurosym.reports.web` -- ``neurosym report``: one self-contained HTML page per agent
"""
