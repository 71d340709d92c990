/*  route.pl -- background knowledge for a Prolog agent: the first action of a
    cheapest path from the agent to an object, in Relational-Grid-World and
    Box-World.

    This file is background knowledge written by hand, not learned: a learned
    strategy (strategy.pl, goal(E, T, Object)) says which object the agent goes
    for next; route/4 says how to get there. `neurosym play` loads it beside
    the strategy. Load it beside a neurosym knowledge base or live state:
        swipl kb.pl rules/route.pl

    Expects the facts of docs/design.md for state T of episode E:
        at(E, T, Id, Row, Col)   the agent (Id agent) and the objects on the map
        object(Id, Type)         RGW sword, enemy, terminal, teleport, pit;
                                 Box-World key(C), lock(C), gem
        holding(E, T, Item)      sword, or key(C)
        terrain(E, Type, Row, Col)  wall, mountain (cells that hold no object)
        grid(E, Rows, Cols)      the map's size

    Moves: up, right, down, left (row - 1, col + 1, row + 1, col - 1). A path
    may not leave the grid, enter a wall, or enter a cell of an object other
    than the goal: entering one triggers an event on the way (RGW: the sword is
    picked up, an unarmed enemy hurts or blocks, a teleport end moves the agent,
    a pit ends the episode, the terminal ends it; Box-World: a loose key is
    picked up and the held key lost, a lock or a box's content blocks). The
    only exception: when no such path exists and the agent holds the sword, RGW
    enemies may be crossed (the env pays +1 and removes them).

    Cost: a step costs 1; entering a mountain costs 1 + Rows * Cols, more than
    any path without it. The env pays -0.1 for a mountain and nothing for a
    step, so a path with fewer mountains always earns more; among those, the
    shortest is taken (the step limit is the only price of a step). Ties go
    to the first action in the order up, right, down, left.

    Dijkstra's search over library(heaps), visited cells in library(assoc).
    Helpers start with route_, so this file loads beside the other rule files.
*/

:- use_module(library(heaps)).
:- use_module(library(assoc)).
:- use_module(library(lists)).

:- dynamic at/5, object/2, holding/3, terrain/4, grid/3.

%!  route(+E, +T, +Goal, -Action) is semidet.
%
%   Action (up, right, down or left) is the first move of a cheapest path
%   from the agent to the cell of object Goal in state T of episode E. Fails
%   when Goal is not on the map, the agent already stands on its cell, or no
%   path exists.
%
%       ?- route(0, 0, sword, A).
%       A = right.

route(E, T, Goal, Action) :-
    route(E, T, Goal, Action, _).

%!  route(+E, +T, +Goal, -Action, -Cost) is semidet.
%
%   As route/4; Cost is the path's cost (steps, plus Rows * Cols per mountain).

route(E, T, Goal, Action, Cost) :-
    at(E, T, agent, R0, C0),
    at(E, T, Goal, GR, GC),
    Goal \== agent,
    \+ (R0 == GR, C0 == GC),
    !,
    grid(E, Rows, Cols),
    route_mountain_cost_(Rows, Cols, Mountain),
    (   route_blocked_(E, T, Goal, strict, Blocked),
        route_search_(R0-C0, GR-GC, Rows, Cols, Blocked, Mountain, E, Action, Cost)
    ->  true
    ;   holding(E, T, sword),
        route_blocked_(E, T, Goal, armed, Blocked),
        route_search_(R0-C0, GR-GC, Rows, Cols, Blocked, Mountain, E, Action, Cost)
    ).

%!  route_distance(+E, +T, +Goal, -Cost) is semidet.
%
%   The cost of a cheapest path to Goal (0 when the agent stands on its cell).

route_distance(E, T, Goal, 0) :-
    at(E, T, agent, R, C),
    at(E, T, Goal, R, C),
    Goal \== agent,
    !.
route_distance(E, T, Goal, Cost) :-
    route(E, T, Goal, _, Cost).

%!  reachable(+E, +T, +Goal) is semidet.
%
%   A path to Goal exists (route/4 has an answer).

reachable(E, T, Goal) :-
    route(E, T, Goal, _).

%!  safe_step(+E, +T, -Action) is semidet.
%
%   The first action, in the order up, right, down, left, that moves the agent
%   into a cell inside the grid holding no wall and no object: a harmless move
%   for when there is nowhere to go.

safe_step(E, T, Action) :-
    at(E, T, agent, R, C),
    grid(E, Rows, Cols),
    route_blocked_(E, T, none, strict, Blocked),
    route_move_(Action, R-C, R1-C1),
    route_inside_(R1-C1, Rows, Cols),
    Cell is R1 * Cols + C1,
    \+ get_assoc(Cell, Blocked, _),
    !.

% --------------------------------------------------------------- helpers

route_move_(up,    R-C, R1-C) :- R1 is R - 1.
route_move_(right, R-C, R-C1) :- C1 is C + 1.
route_move_(down,  R-C, R1-C) :- R1 is R + 1.
route_move_(left,  R-C, R-C1) :- C1 is C - 1.

route_move_index_(up, 0).
route_move_index_(right, 1).
route_move_index_(down, 2).
route_move_index_(left, 3).

route_inside_(R-C, Rows, Cols) :-
    R >= 0, R < Rows, C >= 0, C < Cols.

route_mountain_cost_(Rows, Cols, Cost) :-
    Cost is 1 + Rows * Cols.

%   route_blocked_(+E, +T, +Goal, +Mode, -Blocked): assoc of the cells (Row *
%   Cols + Col) a path may not enter: walls (and any terrain other than
%   mountains) and the objects other than Goal; in Mode armed, RGW enemies
%   are left open.
route_blocked_(E, T, Goal, Mode, Blocked) :-
    grid(E, _, Cols),
    findall(Cell-wall,
            ( terrain(E, Type, R, C), Type \== mountain, Cell is R * Cols + C ),
            Walls),
    findall(Cell-Id,
            ( at(E, T, Id, R, C), Id \== agent, Id \== Goal,
              \+ route_open_(Mode, Id),
              Cell is R * Cols + C ),
            Objects),
    append(Walls, Objects, Pairs),
    list_to_assoc_(Pairs, Blocked).

route_open_(armed, Id) :- object(Id, enemy).

list_to_assoc_(Pairs, Assoc) :-
    empty_assoc(A0),
    foldl(route_put_, Pairs, A0, Assoc).

route_put_(K-V, A0, A) :- put_assoc(K, A0, V, A).

%   route_search_(+Start, +Target, +Rows, +Cols, +Blocked, +Mountain, +E,
%                 -Action, -Cost): Dijkstra from Start; each queue entry keeps
%   the first action of its path and is keyed Cost * 4 + the action's index,
%   so that of equally cheap paths the one whose first action comes first in
%   up, right, down, left wins. The target is always enterable.
route_search_(R0-C0, GR-GC, Rows, Cols, Blocked, Mountain, E, Action, Cost) :-
    Start is R0 * Cols + C0,
    Target is GR * Cols + GC,
    route_mountains_(E, Cols, Mountains),
    empty_assoc(Done0),
    put_assoc(Start, Done0, true, Done1),
    route_expand_(R0-C0, none, 0, Rows, Cols, Blocked, Mountains, Mountain,
                  Target, Done1, Heap0),
    route_loop_(Heap0, Rows, Cols, Blocked, Mountains, Mountain, Target, Done1,
                Action, Cost).

route_mountains_(E, Cols, Mountains) :-
    findall(Cell-m, ( terrain(E, mountain, R, C), Cell is R * Cols + C ), Pairs),
    list_to_assoc_(Pairs, Mountains).

route_loop_(Heap0, Rows, Cols, Blocked, Mountains, Mountain, Target, Done0,
            Action, Cost) :-
    get_from_heap(Heap0, Key, Cell-First, Heap1),
    D is Key // 4,
    (   Cell =:= Target
    ->  Action = First, Cost = D
    ;   get_assoc(Cell, Done0, _)
    ->  route_loop_(Heap1, Rows, Cols, Blocked, Mountains, Mountain, Target,
                    Done0, Action, Cost)
    ;   put_assoc(Cell, Done0, true, Done1),
        R is Cell // Cols, C is Cell mod Cols,
        route_expand_(R-C, First, D, Rows, Cols, Blocked, Mountains, Mountain,
                      Target, Done1, Heap1, Heap2),
        route_loop_(Heap2, Rows, Cols, Blocked, Mountains, Mountain, Target,
                    Done1, Action, Cost)
    ).

route_expand_(RC, First, D, Rows, Cols, Blocked, Mountains, Mountain, Target,
              Done, Heap) :-
    empty_heap(Heap0),
    route_expand_(RC, First, D, Rows, Cols, Blocked, Mountains, Mountain,
                  Target, Done, Heap0, Heap).

%   Neighbours in the order up, right, down, left; a path's first action is
%   its first move (First is none at the start).
route_expand_(RC, First, D, Rows, Cols, Blocked, Mountains, Mountain, Target,
              Done, Heap0, Heap) :-
    foldl(route_neighbour_(RC, First, D, Rows, Cols, Blocked, Mountains,
                           Mountain, Target, Done),
          [up, right, down, left], Heap0, Heap).

route_neighbour_(RC, First, D, Rows, Cols, Blocked, Mountains, Mountain,
                 Target, Done, Move, Heap0, Heap) :-
    route_move_(Move, RC, R1-C1),
    Cell is R1 * Cols + C1,
    (   route_inside_(R1-C1, Rows, Cols),
        \+ get_assoc(Cell, Done, _),
        ( Cell =:= Target -> true ; \+ get_assoc(Cell, Blocked, _) )
    ->  ( get_assoc(Cell, Mountains, _) -> Step is 1 + Mountain ; Step = 1 ),
        D1 is D + Step,
        ( First == none -> First1 = Move ; First1 = First ),
        route_move_index_(First1, I),
        Key is D1 * 4 + I,
        add_to_heap(Heap0, Key, Cell-First1, Heap)
    ;   Heap = Heap0
    ).

%!  default_goal(+E, +T, -Object) is semidet.
%
%   The object a Prolog agent goes for when its strategy names none: RGW the
%   terminal; Box-World the lock of the held key's colour, else the nearest
%   loose key it can reach.
%
%       ?- default_goal(0, 0, G).
%       G = terminal.

default_goal(E, T, terminal) :-
    at(E, T, terminal, _, _),
    !.
default_goal(E, T, Lock) :-
    holding(E, T, key(C)),
    object(Lock, lock(C)),
    at(E, T, Lock, _, _),
    reachable(E, T, Lock),
    !.
default_goal(E, T, Key) :-
    findall(Cost-K,
            ( object(K, key(_)), at(E, T, K, _, _), route_distance(E, T, K, Cost) ),
            Keys),
    msort(Keys, [_-Key|_]).
