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

BACKGROUND = r"""
%! target(?E, ?T, ?R, ?C) is nondet.
%  The cell (R, C) the action of state T moves towards (possibly outside the grid).
target(E, T, R, C) :-
    step(E, T, Action, _),
    at(E, T, agent, R0, C0),
    action_offset(Action, DR, DC),
    R is R0 + DR,
    C is C0 + DC.

%! action_offset(?Action, ?DR, ?DC) is nondet.
action_offset(up, -1, 0).
action_offset(right, 0, 1).
action_offset(down, 1, 0).
action_offset(left, 0, -1).

%! cell_holds(+E, +T, +R, +C, ?What) is nondet.
%  What occupies cell (R, C) of episode E in state T: an object's type, a terrain
%  type, border (outside the grid) or empty.
cell_holds(E, _, R, C, border) :-
    grid(E, Rows, Cols),
    \+ inside(R, C, Rows, Cols).
cell_holds(E, T, R, C, What) :-
    at(E, T, Id, R, C),
    Id \== agent,
    object(Id, What).
cell_holds(E, _, R, C, What) :-
    terrain(E, What, R, C).
cell_holds(E, T, R, C, empty) :-
    grid(E, Rows, Cols),
    inside(R, C, Rows, Cols),
    \+ ( at(E, T, Id, R, C), Id \== agent ),
    \+ terrain(E, _, R, C).

inside(R, C, Rows, Cols) :-
    R >= 0, C >= 0, R < Rows, C < Cols.

%! ahead(?E, ?T, ?What) is nondet.
%  What occupies the cell the action of state T moves towards.
ahead(E, T, What) :-
    target(E, T, R, C),
    cell_holds(E, T, R, C, What).

%! left_of_ahead(?E, ?T, ?What) is nondet.
%  What occupies the cell left of the target cell.
left_of_ahead(E, T, What) :-
    target(E, T, R, C),
    C1 is C - 1,
    cell_holds(E, T, R, C1, What).

%! right_of_ahead(?E, ?T, ?What) is nondet.
%  What occupies the cell right of the target cell.
right_of_ahead(E, T, What) :-
    target(E, T, R, C),
    C1 is C + 1,
    cell_holds(E, T, R, C1, What).

%! on_map(?E, ?T, ?What) is nondet.
%  Some object of type What is on the map in state T.
on_map(E, T, What) :-
    at(E, T, Id, _, _),
    Id \== agent,
    object(Id, What).
"""

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
