"""The background knowledge world rules are learned over, and the events they are learned for.

Each env family's world-rule language is declared once here (:data:`FAMILIES`):
the Prolog file of its background predicates, the body predicates the search
may use (in the order it tries them), which of them bind E and T through
``step/4``, and the events it learns rules for. The background's text is both
what the learner grounds on the training KB (so the examples it learns from
are Prolog's own answers) and what a learned ``world.pl`` carries, so the file
needs nothing but a KB.

RGW and Box-World (``pl/world_background.pl``), over ``step/4``, ``at/5``,
``object/2``, ``holding/3``, ``terrain/4``, ``grid/3``:

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

Minigrid and BabyAI (``pl/world_background_minigrid.pl``), over the same facts
plus ``facing/3`` and ``door_state/4`` (an action does not move the agent
towards a cell: it turns, steps forward, or acts on the cell it faces):

* ``action(E, T, Action)``: the action of state T (``forward``, ``toggle``, ...);
* ``ahead(E, T, What)``: what occupies the cell the agent faces (``cell_holds``
  as above: ``door(yellow)``, ``wall``, ``goal``, ``lava``, ``empty``);
* ``ahead_door(E, T, State)``: the state of the door it faces (``open``,
  ``closed``, ``locked``);
* ``carrying(E, T, What)``: what it carries (``key(red)``), or ``nothing``.
"""

from __future__ import annotations

from dataclasses import dataclass

from neurosym.induce.prolog_text import pl_text


@dataclass(frozen=True)
class Family:
    """One env family's world-rule language (see the module docstring)."""

    name: str
    file: str
    """the background's file in neurosym/induce/pl/"""
    predicates: tuple[str, ...]
    """the body predicates ``P(E, T, Value)``, in the order the search tries them"""
    binds_state: tuple[str, ...]
    """those whose positive literal binds E and T through ``step/4`` (written first in a body;
    a body without one starts with ``step(E, T, _, _)``)"""
    vocabulary: tuple[str, ...]
    """the events world rules are learned for; ``C`` is a colour variable"""
    facts: tuple[str, ...] = ("step/4", "at/5", "object/2", "holding/3", "terrain/4", "grid/3")
    """the KB facts the background reads (a learned file's header names them)"""
    links_first: bool = False
    """on equal gain, a positive literal that links a colour variable already bound wins over
    the others (``carrying(E, T, key(C))`` over ``\\+ carrying(E, T, nothing)`` where DoorKey's
    one key makes them cover the same states: the rule that names the colour is the one
    that also holds where keys of other colours lie about)"""

    @property
    def background(self) -> str:
        """The background predicates' Prolog text, as a learned file carries it."""
        return pl_text(self.file)


_RGW_PREDICATES = ("ahead", "left_of_ahead", "right_of_ahead", "holding", "on_map")
_RGW_CELLS = ("ahead", "left_of_ahead", "right_of_ahead")
_MINIGRID_CARRIED = ("key", "ball", "box")

FAMILIES: dict[str, Family] = {
    "rgw": Family(
        "rgw",
        "world_background.pl",
        _RGW_PREDICATES,
        _RGW_CELLS,
        (
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
    ),
    "boxworld": Family(
        "boxworld",
        "world_background.pl",
        _RGW_PREDICATES,
        _RGW_CELLS,
        ("got(key(C))", "opened(lock(C))", "got(gem)", "hit(distractor)"),
    ),
    "minigrid": Family(
        "minigrid",
        "world_background_minigrid.pl",
        ("action", "ahead", "ahead_door", "carrying"),
        ("action", "ahead", "ahead_door", "carrying"),
        (
            "bumped(wall)",
            *(f"bumped({t}(C))" for t in (*_MINIGRID_CARRIED, "door")),
            *(f"picked({t}(C))" for t in _MINIGRID_CARRIED),
            *(f"dropped({t}(C))" for t in _MINIGRID_CARRIED),
            "unlocked(door(C))",
            "opened(door(C))",
            "closed(door(C))",
            "opened(box(C))",
            "reached(goal)",
            "fell(lava)",
            "achieved(mission)",
        ),
        ("step/4", "at/5", "object/2", "holding/3", "facing/3", "door_state/4", "terrain/4",
         "grid/3"),
        links_first=True,
    ),
}
"""every env family's world-rule language, declared once"""

BACKGROUND = FAMILIES["rgw"].background
"""RGW's and Box-World's background text (neurosym/induce/pl/world_background.pl)."""

VOCABULARY: dict[str, tuple[str, ...]] = {name: f.vocabulary for name, f in FAMILIES.items()}
"""the events world rules are learned for, per env family; ``C`` is a colour variable"""

STEP_BOUND: frozenset[str] = frozenset(p for f in FAMILIES.values() for p in f.binds_state)
"""predicates whose positive literal binds E and T through ``step/4`` (in every family that
has them)"""

COLOURED = ("key", "lock", "ball", "box", "door")
"""object types with a colour argument: the learner writes their colour as a variable"""
