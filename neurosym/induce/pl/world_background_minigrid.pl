/*  world_background_minigrid.pl -- the background knowledge Minigrid world rules are learned over.

    `neurosym induce world` grounds these predicates on a Minigrid or BabyAI
    training KB (neurosym/induce/examples.py) and copies the text below this
    comment, byte for byte, into every learned world.pl, so that the file
    needs nothing but a KB's state facts (step/4, at/5, object/2, holding/3,
    facing/3, door_state/4, terrain/4, grid/3).
    Load it beside a KB:  swipl kb.pl world_background_minigrid.pl
*/

%! action(?E, ?T, ?Action) is nondet.
%  The action taken in state T (left, right, forward, pickup, drop, toggle, done).
action(E, T, Action) :-
    step(E, T, Action, _).

%! front(?E, ?T, ?R, ?C) is nondet.
%  The cell (R, C) the agent faces in state T (the agent's cell plus its direction's offset).
front(E, T, R, C) :-
    step(E, T, _, _),
    at(E, T, agent, R0, C0),
    facing(E, T, Direction),
    direction_offset(Direction, DR, DC),
    R is R0 + DR,
    C is C0 + DC.

%! direction_offset(?Direction, ?DR, ?DC) is nondet.
direction_offset(east, 0, 1).
direction_offset(south, 1, 0).
direction_offset(west, 0, -1).
direction_offset(north, -1, 0).

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
%  What occupies the cell the agent faces in state T.
ahead(E, T, What) :-
    front(E, T, R, C),
    cell_holds(E, T, R, C, What).

%! ahead_door(?E, ?T, ?State) is nondet.
%  The state (open, closed, locked) of the door in the cell the agent faces.
ahead_door(E, T, State) :-
    front(E, T, R, C),
    at(E, T, Id, R, C),
    door_state(E, T, Id, State).

%! carrying(?E, ?T, ?What) is nondet.
%  What the agent carries in state T (key(C), ball(C), box(C)), or nothing.
carrying(E, T, What) :-
    step(E, T, _, _),
    (   holding(E, T, _)
    ->  holding(E, T, What)
    ;   What = nothing
    ).
