"""The background knowledge world rules are learned over, and the events they are learned for.

The learned clauses read a KB's state facts (``step/4``, ``at/5``, ``object/2``,
``holding/3``, ``terrain/4``, ``grid/3``) through the predicates below. Their
Prolog text (:data:`BACKGROUND`) is both what the learner grounds on the
training KB (so the examples it learns from are Prolog's own answers) and
what a learned ``world.pl`` carries, so the file needs nothing but a KB.

* ``target(E, T, R, C)``: the cell the action of state T moves towards
  (the agent's cell plus the action's offset; it may lie outside the grid);
* ``cell_holds(E, T, R, C, What)``: what occupies cell (R, C) in state T:
  the type of an object there (``sword``, ``key(red)``), a terrain type
  (``wall``, ``mountain``), ``border`` outside the grid, else ``empty``;
* ``ahead(E, T, What)``: what occupies the target cell;
* ``left_of_ahead(E, T, What)``, ``right_of_ahead(E, T, What)``: what
  occupies the cell left / right of the target (Box-World keeps a box's
  content left of its lock);
* ``on_map(E, T, What)``: some object of type What is on the map in state T.
"""

from __future__ import annotations

from neurosym.induce.prolog_text import pl_text

BACKGROUND = pl_text("world_background.pl")
"""The background predicates' Prolog text (neurosym/induce/pl/world_background.pl)."""

CELL_PREDICATES = ("ahead", "left_of_ahead", "right_of_ahead")
"""background predicates that hold one value per acted state: what occupies a cell"""

STATE_PREDICATES = ("holding", "on_map")
"""predicates with any number of values per state"""

VOCABULARY: dict[str, tuple[str, ...]] = {
    "rgw": (
        "bumped(border)",
        "bumped(wall)",
        "teleported",
        "crossed(mountain)",
        "picked(sword)",
        "defeated(enemy)",
        "hurt_by(enemy)",
        "fell(pit)",
        "reached(terminal)",
        "bumped(enemy)",
        "killed_by(enemy)",
    ),
    "boxworld": ("got(key(C))", "opened(lock(C))", "got(gem)", "hit(distractor)"),
}
"""the events world rules are learned for, per env family; ``C`` is a colour variable"""

COLOURED = ("key", "lock")
"""object types with a colour argument: the learner writes their colour as a variable"""
