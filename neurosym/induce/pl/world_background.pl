/*  world_background.pl -- the background knowledge world rules are learned over.

    `neurosym induce world` grounds these predicates on the training
    KB (neurosym/induce/examples.py) and copies the text below this comment,
    byte for byte, into every learned world.pl, so that the file needs
    nothing but a KB's state facts (step/4, at/5, object/2, holding/3,
    terrain/4, grid/3). Load it beside a KB:  swipl kb.pl world_background.pl
*/

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
