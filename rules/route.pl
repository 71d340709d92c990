:- module(route,
          [ route/4,
            route/5,
            route_distance/4,
            route_exists/3,
            route_forget/1,
            safe_step/3,
            default_goal/3,
            route_moves/4,
            route_moves/5
          ]).

/** <module> route: how a Prolog agent gets to an object

Background knowledge for a Prolog agent, written by hand, not learned: the
first action of a cheapest path from the agent to an object, in
Relational-Grid-World and Box-World; in Minigrid and BabyAI (states with
facing/3) the first action of a cheapest path over (cell, direction)
states, turning as it goes, then the interaction with the object (the
Minigrid section at the end). A strategy (strategy.pl, goal(E, T,
Object), learned by `neurosym induce strategy` or written by hand) says which
object the agent goes for next; route/4 says how to get there. `neurosym play`
loads it beside the strategy. Load it beside a neurosym knowledge base or live
state:

    swipl kb.pl rules/route.pl strategy.pl

Reads the facts of docs/design.md for state T of episode E:

    at(E, T, Id, Row, Col)     the agent (Id agent) and the objects on the map
    object(Id, Type)           RGW sword, enemy, terminal, teleport, pit;
                               Box-World key(C), lock(C), gem
    holding(E, T, Item)        sword, or key(C)
    terrain(E, Type, Row, Col) wall, mountain (cells that hold no object)
    grid(E, Rows, Cols)        the map's size
    facing(E, T, Dir)          Minigrid: the agent's direction (east, south, ...)
    door_state(E, T, Id, S)    Minigrid: a door's state (open, closed, locked)

A module whose helpers stay inside it, so it loads beside the other rule
files and beside a strategy (whose own helpers may be called anything but the
exports above). It reads the facts as unqualified goals, which resolve through
its default import module: user in plain swipl, the KB's own module in
neurosym.prolog.KnowledgeBase (which loads a copy of the module per KB, see
rules/lib/kb_common.pl). A KB without at/5 has nothing to route; one that
defines none of the others (no holding/3, say) is read as holding none of
them (a neurosym KB declares every schema predicate dynamic).

Moves: up, right, down, left (row - 1, col + 1, row + 1, col - 1). A path may
not leave the grid, enter a wall, or enter a cell of an object other than the
goal: entering one triggers an event on the way (RGW: the sword is picked up,
an unarmed enemy hurts or blocks, a teleport end moves the agent, a pit ends
the episode, the terminal ends it; Box-World: a loose key is picked up and
the held key lost, a lock or a box's content blocks). The exception: an agent
that holds the sword may cross RGW enemies (the env pays +1 and removes
them). When no such path exists, a second search takes the teleport (entering
one of its two ends lands on the other). An unarmed agent has no route to an
enemy: meeting it costs -1 (and with a blocking enemy the agent never gets
through); nor has any agent a route into a pit, which ends the episode.

Cost: a step costs 1; entering a mountain costs 1 + Rows * Cols, more than any
path without it. The env pays -0.1 for a mountain and nothing for a step, so
a path with fewer mountains always earns more; among those, the shortest is
taken (the step limit is the only price of a step). Ties go to the first
action in the order up, right, down, left.

The search: a breadth-first search with mountains closed, which answers
whenever a path without a mountain exists (every such path is cheaper than
any with one); else a search by layers of mountains crossed, which visits
the paths in the order of Dijkstra's (search_/4). The map and the
visited cells are terms with one argument per cell, read with arg/3; each
episode's terrain is built once, the cells' neighbours once per grid size.

route_moves/4,5 count moves instead, for the route features of a learned
strategy (`neurosym induce strategy`): a breadth-first search that enters no
object on the way but the sword, and no teleport jump. One search from a cell
answers for every object of the state.

What is remembered: the routes and move counts of the state last asked (a
strategy asks route_moves/4 for each candidate object, then the agent asks
route/4 for the one chosen), in global variables of this module's copy (per
thread); the terrain of each episode and the move searches by start cell
and blocked cells, in this module's own dynamic predicates. Facts of a KB,
which live in another module, cannot plant answers there. route_forget/1
forgets an episode.
*/

:- use_module(library(assoc)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(error)).

:- dynamic grid_/4, searched_/5, cache_key_/2.

%   grid_(E, Rows, Cols, Terrain): episode E's terrain as a term with one
%   argument per cell (mountain, wall, unbound for a free cell).
%   searched_(E, Start, Hash, Blocked, Cells): a move search (route_moves/5).
%   cache_key_(Kind, Key): the global variables of this copy of the module
%   (routes, moves, adjacency), named after it when it loads.
:- prolog_load_context(module, M),
   retractall(cache_key_(_, _)),
   forall(member(Kind, [routes, moves, adjacency, turns]),
          ( format(atom(Key), '$route ~w ~w', [M, Kind]),
            assertz(cache_key_(Kind, Key)) )).

%!  route(+E, +T, +Goal, -Action) is semidet.
%
%   Action (up, right, down or left) is the first move of a cheapest path
%   from the agent to the cell of object Goal in state T of episode E. Fails
%   when Goal is not on the map, the agent already stands on its cell, or no
%   path exists.
%
%       ?- route(0, 0, sword, A).
%       A = down.

route(E, T, Goal, Action) :-
    route(E, T, Goal, Action, _).

%!  route(+E, +T, +Goal, -Action, -Cost) is semidet.
%
%   As route/4; Cost is the path's cost (steps, plus Rows * Cols per mountain).
%   The answers of the state last asked are remembered.

route(E, T, Goal, Action, Cost) :-
    ground(E-T-Goal),
    !,
    cache_key_(routes, K),
    (   nb_current(K, routes(E0, T0, Found0)), E0 == E, T0 == T
    ->  true
    ;   Found0 = []
    ),
    (   memberchk(Goal-F, Found0)
    ->  Found = F
    ;   (   search_route_(E, T, Goal, A, C)
        ->  Found = found(A, C)
        ;   Found = none
        ),
        nb_setval(K, routes(E, T, [Goal-Found|Found0]))
    ),
    Found = found(Action, Cost).
route(E, T, Goal, Action, Cost) :-
    search_route_(E, T, Goal, Action, Cost).

%!  route_forget(+E) is det.
%
%   Forget what was remembered for episode E: its terrain, its move
%   searches, and the routes and move counts of its state last asked. Call
%   it after changing the facts of an episode it was asked about (in a KB
%   and in the live states of `neurosym play` a state's facts do not
%   change; play calls it when an episode ends).

route_forget(E) :-
    retractall(grid_(E, _, _, _)),
    retractall(searched_(E, _, _, _, _)),
    forall(( member(Kind, [routes, moves, turns]),
             cache_key_(Kind, K),
             nb_current(K, V),
             compound(V), arg(1, V, E0), E0 == E ),
           nb_setval(K, none)).

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

%!  route_exists(+E, +T, +Goal) is semidet.
%
%   A path to Goal exists (route/4 has an answer).

route_exists(E, T, Goal) :-
    route(E, T, Goal, _).

%!  safe_step(+E, +T, -Action) is semidet.
%
%   The first action, in the order up, right, down, left, that moves the agent
%   into a cell inside the grid holding no wall and no object: a harmless move
%   for when there is nowhere to go.

safe_step(E, T, Action) :-
    kb_facing_(E, T, _),
    !,
    mg_safe_step_(E, T, Action).
safe_step(E, T, Action) :-
    at(E, T, agent, R, C),
    kb_grid_(E, Rows, Cols),
    blocked_(E, T, none, Blocked),
    move_(Action, R-C, R1-C1),
    inside_(R1-C1, Rows, Cols),
    Cell is R1 * Cols + C1,
    \+ get_assoc(Cell, Blocked, _),
    !.

%!  route_moves(+E, +T, +Goal, -Moves) is det.
%
%   Moves on a shortest path from the agent to the cell of object Goal in
%   state T of episode E that enters no object on the way but the sword (a
%   contact-free approach: no enemy, pit, teleport end, terminal, key or lock
%   is entered before Goal) and no wall; mountains count one move like any
%   cell. 999 when there is no such path, or Goal or the agent is not on the
%   map. The features of a learned strategy read it (route_length/4).
%
%       ?- route_moves(0, 0, sword, D).
%       D = 4.

route_moves(E, T, Goal, Moves) :-
    (   at(E, T, agent, R, C)
    ->  route_moves(E, T, R-C, Goal, Moves)
    ;   Moves = 999
    ).

%!  route_moves(+E, +T, +From, +Goal, -Moves) is det.
%
%   As route_moves/4, from cell From (Row-Col) instead of the agent's cell
%   (a teleport end's, say). One breadth-first search from From answers for
%   every object of the state; the searches of the state last asked are
%   remembered.

route_moves(E, T, From, Goal, Moves) :-
    must_be(ground, E-T-From),
    moves_search_(E, T, From, Search),
    (   at(E, T, Goal, R, C)
    ->  moves_to_(Search, R, C, Moves)
    ;   Moves = 999
    ).

%   moves_search_(+E, +T, +From, -Search): the move search from From in
%   state T, search(Rows, Cols, Cells) (Cells: the moves to each cell
%   reached), or none (no grid, or From off it); remembered for the state
%   last asked.
moves_search_(E, T, From, Search) :-
    cache_key_(moves, K),
    (   nb_current(K, moves(E0, T0, Searches)), E0 == E, T0 == T
    ->  true
    ;   Searches = []
    ),
    (   memberchk(From-S, Searches)
    ->  Search = S
    ;   new_moves_search_(E, T, From, Search),
        nb_setval(K, moves(E, T, [From-Search|Searches]))
    ).

new_moves_search_(E, T, R0-C0, Search) :-
    (   grid_terrain_(E, Rows, Cols, Cells0),
        inside_(R0-C0, Rows, Cols)
    ->  S is R0 * Cols + C0 + 1,
        findall(I, ( at(E, T, Id, R, C), Id \== agent, \+ passable_(Id),
                     inside_(R-C, Rows, Cols), I is R * Cols + C + 1 ),
                Blocked0),
        sort(Blocked0, Blocked),
        moves_bfs_(E, S, Blocked, Rows, Cols, Cells0, Cells),
        Search = search(Rows, Cols, Cells)
    ;   Search = none
    ).

%   moves_bfs_(+E, +Start, +Blocked, +Rows, +Cols, +Cells0, -Cells): the
%   search from cell Start (argument index) with the cells Blocked closed,
%   Cells0 the episode's terrain. It depends on nothing else (the agent's
%   cell is free), so it is remembered by episode, start and the blocked
%   cells (a teleport end's search serves every state until an object
%   moves or goes), until route_forget/1.
moves_bfs_(E, S, Blocked, Rows, Cols, Cells0, Cells) :-
    term_hash(Blocked, H),
    (   searched_(E, S, H, Blocked, Cells1)
    ->  Cells = Cells1
    ;   forall(member(I, Blocked), nb_setarg(I, Cells0, x)),
        nb_setarg(S, Cells0, 0),
        adjacency_(Rows, Cols, Adj),
        bfs_([S], 0, Adj, Cells0),
        assertz(searched_(E, S, H, Blocked, Cells0)),
        Cells = Cells0
    ).

%   moves_to_(+Search, +R, +C, -Moves): one more than the nearest of the
%   cell's neighbours the search reached, else 999.
moves_to_(search(Rows, Cols, Cells), R, C, Moves) :-
    inside_(R-C, Rows, Cols),
    !,
    adjacency_(Rows, Cols, Adj),
    I is R * Cols + C + 1,
    arg(I, Adj, Neighbours),
    foldl(nearer_(Cells), Neighbours, 999, Near),
    (   Near < 999 -> Moves is Near + 1 ; Moves = 999 ).
moves_to_(_, _, _, 999).

nearer_(Cells, I, D0, D) :-
    arg(I, Cells, V),
    (   integer(V), V < D0 -> D = V ; D = D0 ).

%   Objects a contact-free path may cross: the sword (a type sword, or a
%   compound of that name).
passable_(Id) :-
    kb_object_(Id, Type),
    (   compound(Type) -> functor(Type, sword, _) ; Type == sword ),
    !.

%   grid_terrain_(+E, -Rows, -Cols, -Cells): episode E's size and a fresh
%   copy (the caller may change it) of its terrain, one argument per cell
%   (Row * Cols + Col + 1): mountain, wall (any other terrain), unbound for
%   a free cell. Built once per episode, until route_forget/1.
grid_terrain_(E, Rows, Cols, Cells) :-
    (   grid_(E, Rows0, Cols0, Cells0)
    ->  Rows = Rows0, Cols = Cols0, Cells = Cells0
    ;   kb_grid_(E, Rows, Cols),
        !,
        terrain_(E, Rows, Cols, Cells),
        assertz(grid_(E, Rows, Cols, Cells))
    ).

terrain_(E, Rows, Cols, Cells) :-
    N is Rows * Cols,
    functor(Cells, cells, N),
    forall(kb_terrain_(E, Type, R, C),
           ( I is R * Cols + C + 1,
             ( Type == mountain -> nb_setarg(I, Cells, mountain) ; nb_setarg(I, Cells, wall) ) )).

%   adjacency_(+Rows, +Cols, -Adj): for each cell (argument Row * Cols + Col
%   + 1), the list of the cells a step from it enters inside the grid, in
%   the order up, right, down, left. Built once per grid size (kept in a
%   global variable: read in place, never copied).
adjacency_(Rows, Cols, Adj) :-
    cache_key_(adjacency, K),
    (   nb_current(K, adjacency(Rows0, Cols0, Adj0)), Rows0 == Rows, Cols0 == Cols
    ->  Adj = Adj0
    ;   build_adjacency_(Rows, Cols, Adj),
        nb_setval(K, adjacency(Rows, Cols, Adj))
    ).

build_adjacency_(Rows, Cols, Adj) :-
    N is Rows * Cols,
    functor(Adj, adj, N),
    forall(between(1, N, I),
           ( Cell is I - 1, R is Cell // Cols, C is Cell mod Cols,
             findall(J, ( move_(_, R-C, R1-C1),
                          inside_(R1-C1, Rows, Cols),
                          J is R1 * Cols + C1 + 1 ),
                     Js),
             nb_setarg(I, Adj, Js) )).

%   bfs_(+Frontier, +D, +Adj, !Cells): the cells D moves away are Frontier
%   (argument indices); mark their free and mountain neighbours D + 1, and
%   go on. Cells: the moves to each cell reached, wall or x for a blocked one.
bfs_([], _, _, _) :- !.
bfs_(Frontier, D, Adj, Cells) :-
    D1 is D + 1,
    bfs_level_(Frontier, D1, Adj, Cells, Next, []),
    bfs_(Next, D1, Adj, Cells).

bfs_level_([], _, _, _, Next, Next).
bfs_level_([I|Is], D, Adj, Cells, Next0, Next) :-
    arg(I, Adj, Neighbours),
    bfs_visit_(Neighbours, D, Cells, Next0, Next1),
    bfs_level_(Is, D, Adj, Cells, Next1, Next).

bfs_visit_([], _, _, Next, Next).
bfs_visit_([J|Js], D, Cells, Next0, Next) :-
    arg(J, Cells, V),
    (   ( var(V) ; V == mountain )
    ->  nb_setarg(J, Cells, D),
        Next0 = [J|Next1]
    ;   Next0 = Next1
    ),
    bfs_visit_(Js, D, Cells, Next1, Next).

% --------------------------------------------------------------- routes

%   search_route_(+E, +T, ?Goal, -Action, -Cost): route/5 without memory.
search_route_(E, T, Goal, Action, Cost) :-
    kb_facing_(E, T, _),
    !,
    mg_route_(E, T, Goal, Action, Cost).
search_route_(E, T, Goal, Action, Cost) :-
    at(E, T, agent, R0, C0),
    at(E, T, Goal, GR, GC),
    Goal \== agent,
    \+ (R0 == GR, C0 == GC),
    \+ kb_object_(Goal, pit),
    \+ ( kb_object_(Goal, enemy), \+ kb_holding_(E, T, sword) ),
    !,
    mode_(Mode),
    map_(E, T, Goal, Mode, GR-GC, Map),
    level_search_(R0-C0, Map, Result),
    (   Result = found(Action, Cost)
    ->  true
    ;   Result == closed(mountain),
        search_(R0-C0, Map, Action, Cost)
    ),
    !.

move_(up,    R-C, R1-C) :- R1 is R - 1.
move_(right, R-C, R-C1) :- C1 is C + 1.
move_(down,  R-C, R1-C) :- R1 is R + 1.
move_(left,  R-C, R-C1) :- C1 is C - 1.

move_index_(up, 0).
move_index_(right, 1).
move_index_(down, 2).
move_index_(left, 3).

inside_(R-C, Rows, Cols) :-
    R >= 0, R < Rows, C >= 0, C < Cols.

%   mode_(-Mode): the rules of a search, tried in turn: strict, then with
%   the teleport's ends as jumps.
mode_(strict).
mode_(jumps).

%   map_(+E, +T, +Goal, +Mode, +Target, -Map): what a search needs, as
%   map(Rows, Cols, Cells, MountainCost, TargetCell, Adj). Cells is a term
%   with one argument per cell (Row * Cols + Col + 1), so that a search
%   looks a cell up with arg/3: unbound for a free cell, wall (walls, and
%   objects a path may not enter), mountain, or jump(Landing) for a
%   teleport end; it starts as a fresh copy of the episode's terrain
%   (grid_terrain_/4). Adj: each cell's neighbours inside the grid.
map_(E, T, Goal, Mode, GR-GC, map(Rows, Cols, Cells, Mountain, Target, Adj)) :-
    grid_terrain_(E, Rows, Cols, Cells),
    adjacency_(Rows, Cols, Adj),
    Mountain is 1 + Rows * Cols,
    Target is GR * Cols + GC,
    forall(( at(E, T, Id, R, C), Id \== agent, Id \== Goal, \+ open_(E, T, Id) ),
           ( I is R * Cols + C + 1, nb_setarg(I, Cells, wall) )),
    jumps_(E, T, Goal, Mode, Cols, Cells).

%   jumps_: in mode jumps, entering a teleport end (not the goal) lands on
%   the other end, when the map has exactly two.
jumps_(E, T, Goal, Mode, Cols, Cells) :-
    (   Mode \== strict,
        findall(Id-(R-C), ( kb_object_(Id, teleport), at(E, T, Id, R, C) ), [A-(RA-CA), B-(RB-CB)]),
        A \== Goal, B \== Goal
    ->  CellA is RA * Cols + CA, CellB is RB * Cols + CB,
        IA is CellA + 1, IB is CellB + 1,
        nb_setarg(IA, Cells, jump(CellB)),
        nb_setarg(IB, Cells, jump(CellA))
    ;   true
    ).

%   Objects a path may cross: enemies, while the agent holds the sword.
open_(E, T, Id) :- kb_object_(Id, enemy), kb_holding_(E, T, sword).

%   blocked_(+E, +T, +Goal, -Blocked): assoc of the cells a path may not
%   enter (walls, and the objects other than Goal that route/4 does not
%   cross), for safe_step/3.
blocked_(E, T, Goal, Blocked) :-
    kb_grid_(E, _, Cols),
    findall(Cell-wall,
            ( kb_terrain_(E, Type, R, C), Type \== mountain, Cell is R * Cols + C ),
            Walls),
    findall(Cell-Id,
            ( at(E, T, Id, R, C), Id \== agent, Id \== Goal,
              \+ open_(E, T, Id),
              Cell is R * Cols + C ),
            Objects),
    append(Walls, Objects, Pairs),
    empty_assoc(A0),
    foldl(put_, Pairs, A0, Blocked).

put_(K-V, A0, A) :- put_assoc(K, A0, V, A).

%   level_search_(+Start, +Map, -Result): a breadth-first search with
%   mountains closed; Result found(Action, Cost). Each step costs 1, so its queue, started with the
%   start's neighbours in the order up, right, down, left, holds the paths
%   in the order of their cost, then of their first action (a path keeps
%   its first action, and the paths one step longer are queued in the order
%   of the paths they extend): the first path to reach the target is the
%   cheapest, with the first action first, as search_/4 would find it, and
%   a path without a mountain is cheaper than any with one. Fails when no
%   path without a mountain reaches the target: Result is then
%   closed(mountain) when a mountain was met (search_/4 may find a path
%   over it), else closed(none) (no path at all). A cell is marked in Done
%   when queued (a teleport end marks the cell it lands on); Done's last
%   argument notes a mountain met.
level_search_(R0-C0, Map, Result) :-
    Map = map(Rows, Cols, _, _, _, _),
    Start is R0 * Cols + C0,
    N is Rows * Cols,
    N1 is N + 1,
    functor(Done, done, N1),
    S1 is Start + 1,
    nb_setarg(S1, Done, x),
    nb_setarg(N1, Done, none),
    Up is R0 - 1, Down is R0 + 1, Left is C0 - 1, Right is C0 + 1,
    first_steps_([Up-C0-0, R0-Right-1, Down-C0-2, R0-Left-3], Map, Done, Frontier, Hit),
    (   Hit == none
    ->  level_(Frontier, 1, Map, Done, MI, Cost)
    ;   MI = Hit, Cost = 1
    ),
    (   nonvar(MI)
    ->  move_index_(Action, MI),
        Result = found(Action, Cost)
    ;   arg(N1, Done, Closed),
        Result = closed(Closed)
    ).

%   first_steps_(+Steps, +Map, !Done, -Queue, -Hit): the start's neighbours
%   (Row-Col-MoveIndex, in the order up, right, down, left) queued; Hit is
%   the move index of the one that is the target, else none.
first_steps_([], _, _, [], none).
first_steps_([R-C-MI|Steps], Map, Done, Q0, Hit) :-
    Map = map(Rows, Cols, Cells, _, Target, _),
    (   R >= 0, R < Rows, C >= 0, C < Cols
    ->  Cell0 is R * Cols + C,
        (   Cell0 =:= Target
        ->  Hit = MI
        ;   I0 is Cell0 + 1,
            arg(I0, Cells, Kind),
            level_enter_(Kind, Cell0, Done, MI, Q0, Q1),
            first_steps_(Steps, Map, Done, Q1, Hit)
        )
    ;   first_steps_(Steps, Map, Done, Q0, Hit)
    ).

%   level_enter_(+Kind, +Cell0, !Done, +MI, -Q0, ?Q): enter Cell0 of Kind
%   (not the target): queue the cell it lands on, Cell-MI, unless closed
%   (wall, mountain: noted in Done's last argument) or marked.
level_enter_(Kind, _, Done, _, Q, Q) :-
    Kind == mountain,
    !,
    functor(Done, _, N1),
    nb_setarg(N1, Done, mountain).
level_enter_(Kind, Cell0, Done, MI, Q0, Q) :-
    (   var(Kind)
    ->  Cell = Cell0
    ;   Kind = jump(Cell)
    ),
    I is Cell + 1,
    arg(I, Done, Seen),
    var(Seen),
    !,
    nb_setarg(I, Done, x),
    Q0 = [Cell-MI|Q].
level_enter_(_, _, _, _, Q, Q).

%   level_(+Frontier, +D, +Map, !Done, -MI, -Cost): Frontier holds the
%   cells D steps away (Cell-MI, in queue order); the first of them next to
%   the target ends the search; MI stays unbound when none is left.
level_([], _, _, _, _, _) :- !.
level_(Frontier, D, Map, Done, MI, Cost) :-
    Map = map(_, _, Cells, _, Target, Adj),
    D1 is D + 1,
    expand_level_(Frontier, Adj, Cells, Target, Done, Next, [], Hit),
    (   Hit == none
    ->  level_(Next, D1, Map, Done, MI, Cost)
    ;   MI = Hit, Cost = D1
    ).

%   expand_level_(+Frontier, +Adj, +Cells, +Target, !Done, -Q0, ?Q, -Hit):
%   the next level queued in Q0-Q, Hit none; or Hit the move index of the
%   first cell of Frontier next to the target.
expand_level_([], _, _, _, _, Q, Q, none).
expand_level_([Cell-MI|Rest], Adj, Cells, Target, Done, Q0, Q, Hit) :-
    I is Cell + 1,
    arg(I, Adj, Neighbours),
    expand_cell_(Neighbours, MI, Cells, Target, Done, Q0, Q1, Hit0),
    (   Hit0 == none
    ->  expand_level_(Rest, Adj, Cells, Target, Done, Q1, Q, Hit)
    ;   Hit = Hit0
    ).

expand_cell_([], _, _, _, _, Q, Q, none).
expand_cell_([J|Js], MI, Cells, Target, Done, Q0, Q, Hit) :-
    Cell0 is J - 1,
    (   Cell0 =:= Target
    ->  Hit = MI
    ;   arg(J, Cells, Kind),
        level_enter_(Kind, Cell0, Done, MI, Q0, Q1),
        expand_cell_(Js, MI, Cells, Target, Done, Q1, Q, Hit)
    ).

%   search_(+Start, +Map, -Action, -Cost): the cheapest path over
%   mountains, where level_search_/3 found none without. Its cost is
%   Steps + Mountains * Mountain (Map's mountain cost, more than any number
%   of steps), so paths rank by their mountains, then their steps, then
%   their first action (up, right, down, left), as in Dijkstra's search
%   keyed Cost * 4 + the action's index; the search visits them in that
%   order without a priority queue: layer by layer of mountains crossed
%   (the cells first entered over one more mountain start the next layer,
%   in the order they were met), and in a layer step by step (the cells
%   reached in S steps: those that start the layer with S, merged by first
%   action with those the layer's breadth-first search reached). The first
%   path to reach the target is the cheapest. A cell is marked in Done when
%   queued (a teleport end marks the cell it lands on).
search_(R0-C0, Map, Action, Cost) :-
    Map = map(Rows, Cols, Cells, Mountain, Target, _),
    Start is R0 * Cols + C0,
    N is Rows * Cols,
    functor(Done, done, N),
    S1 is Start + 1,
    nb_setarg(S1, Done, x),
    Up is R0 - 1, Down is R0 + 1, Left is C0 - 1, Right is C0 + 1,
    first_layer_steps_([Up-C0-0, R0-Right-1, Down-C0-2, R0-Left-3], Rows, Cols, Cells,
                       Target, Done, Frontier, Seeds, Hit),
    (   Hit \== none
    ->  MI = Hit, Cost = 1
    ;   layers_(0, [], Frontier, 1, Seeds, Map, Done, MI, Steps, Crossed),
        Cost is Steps + Crossed * Mountain
    ),
    move_index_(Action, MI).

%   first_layer_steps_(+Steps, +Rows, +Cols, +Cells, +Target, !Done,
%   -Frontier, -Seeds, -Hit): the start's neighbours: Frontier the ones
%   entered without a mountain (MI-Cell), Seeds the mountains (1-MI-Cell),
%   Hit the move index of the target, else none.
first_layer_steps_([], _, _, _, _, _, [], [], none).
first_layer_steps_([R-C-MI|Steps], Rows, Cols, Cells, Target, Done, F0, S0, Hit) :-
    (   R >= 0, R < Rows, C >= 0, C < Cols
    ->  Cell0 is R * Cols + C,
        (   Cell0 =:= Target
        ->  Hit = MI
        ;   I0 is Cell0 + 1,
            arg(I0, Cells, Kind),
            layer_enter_(Kind, Cell0, Done, 1, MI, F0, F1, S0, S1),
            first_layer_steps_(Steps, Rows, Cols, Cells, Target, Done, F1, S1, Hit)
        )
    ;   first_layer_steps_(Steps, Rows, Cols, Cells, Target, Done, F0, S0, Hit)
    ).

%   layer_enter_(+Kind, +Cell0, !Done, +S, +MI, -F0, ?F, -S0, ?S): a path
%   with first action MI enters Cell0 of Kind (not the target) in its S-th
%   step: the cell it lands on is queued in F0-F (MI-Cell), a mountain in
%   S0-S (S-MI-Cell, the next layer's), unless closed or marked.
layer_enter_(Kind, Cell0, Done, S, MI, F0, F, Q0, Q) :-
    Kind == mountain,
    !,
    F0 = F,
    I is Cell0 + 1,
    arg(I, Done, Seen),
    (   var(Seen)
    ->  nb_setarg(I, Done, x),
        Q0 = [S-MI-Cell0|Q]
    ;   Q0 = Q
    ).
layer_enter_(Kind, Cell0, Done, _, MI, F0, F, Q, Q) :-
    (   var(Kind)
    ->  Cell = Cell0
    ;   Kind = jump(Cell)
    ),
    I is Cell + 1,
    arg(I, Done, Seen),
    var(Seen),
    !,
    nb_setarg(I, Done, x),
    F0 = [MI-Cell|F].
layer_enter_(_, _, _, _, _, F, F, Q, Q).

%   layers_(+M, +Seeds, +Frontier, +S, +Next, +Map, !Done, -MI, -Steps,
%   -Crossed): layer M (paths over M mountains): Frontier holds its cells S
%   steps away (MI-Cell, by first action), Seeds its cells entered over a
%   mountain not yet taken (S-MI-Cell, in order), Next the next layer's
%   seeds met so far. The target reached in Steps steps over Crossed
%   mountains with first action MI; fails when no layer is left.
layers_(M, Seeds, Frontier, S, Next, Map, Done, MI, Steps, Crossed) :-
    seeds_at_(Seeds, S, Now, Later),
    merge_by_action_(Now, Frontier, Level),
    (   Level == []
    ->  (   Later = [S2-_-_|_]
        ->  layers_(M, Later, [], S2, Next, Map, Done, MI, Steps, Crossed)
        ;   Next = [S3-_-_|_]
        ->  M1 is M + 1,
            layers_(M1, Next, [], S3, [], Map, Done, MI, Steps, Crossed)
        )
    ;   Map = map(_, _, Cells, _, Target, Adj),
        S1 is S + 1,
        append(Next, More, Next1),       % this layer's mountains after those met before
        expand_layer_(Level, S1, Adj, Cells, Target, Done, Frontier1, [], More, [], Hit),
        (   Hit \== none
        ->  MI = Hit, Steps = S1, Crossed = M
        ;   layers_(M, Later, Frontier1, S1, Next1, Map, Done, MI, Steps, Crossed)
        )
    ).

%   seeds_at_(+Seeds, +S, -Now, -Later): the seeds S steps away (MI-Cell),
%   and the rest.
seeds_at_([S0-MI-Cell|Seeds], S, [MI-Cell|Now], Later) :-
    S0 =:= S,
    !,
    seeds_at_(Seeds, S, Now, Later).
seeds_at_(Seeds, _, [], Seeds).

%   merge_by_action_(+A, +B, -Merged): two lists of MI-Cell, each ordered
%   by MI, merged (stable: A first on equal MI).
merge_by_action_([], B, B) :- !.
merge_by_action_(A, [], A) :- !.
merge_by_action_([MA-CA|As], [MB-CB|Bs], [X|Xs]) :-
    (   MA =< MB
    ->  X = MA-CA, merge_by_action_(As, [MB-CB|Bs], Xs)
    ;   X = MB-CB, merge_by_action_([MA-CA|As], Bs, Xs)
    ).

%   expand_layer_(+Level, +S1, +Adj, +Cells, +Target, !Done, -F0, ?F, -Q0,
%   ?Q, -Hit): the neighbours of Level's cells (MI-Cell, in order), S1
%   steps away: queued in F0-F, mountains in Q0-Q; Hit the move index of
%   the first next to the target, else none.
expand_layer_([], _, _, _, _, _, F, F, Q, Q, none).
expand_layer_([MI-Cell|Rest], S1, Adj, Cells, Target, Done, F0, F, Q0, Q, Hit) :-
    I is Cell + 1,
    arg(I, Adj, Neighbours),
    expand_layer_cell_(Neighbours, MI, S1, Cells, Target, Done, F0, F1, Q0, Q1, Hit0),
    (   Hit0 == none
    ->  expand_layer_(Rest, S1, Adj, Cells, Target, Done, F1, F, Q1, Q, Hit)
    ;   Hit = Hit0
    ).

expand_layer_cell_([], _, _, _, _, _, F, F, Q, Q, none).
expand_layer_cell_([J|Js], MI, S1, Cells, Target, Done, F0, F, Q0, Q, Hit) :-
    Cell0 is J - 1,
    (   Cell0 =:= Target
    ->  Hit = MI
    ;   arg(J, Cells, Kind),
        layer_enter_(Kind, Cell0, Done, S1, MI, F0, F1, Q0, Q1),
        expand_layer_cell_(Js, MI, S1, Cells, Target, Done, F1, F, Q1, Q, Hit)
    ).

% --------------------------------------------------------------- facts

%   The KB's facts but at/5, read where the KB may have none of them at all
%   (a KB of one's own that declares only what it holds): no such predicate
%   visible through the default import module is no answer, not an error.
kb_object_(Id, Type) :- current_predicate(_, object(_, _)), object(Id, Type).
kb_holding_(E, T, Item) :- current_predicate(_, holding(_, _, _)), holding(E, T, Item).
kb_terrain_(E, Type, R, C) :- current_predicate(_, terrain(_, _, _, _)), terrain(E, Type, R, C).
kb_grid_(E, Rows, Cols) :- current_predicate(_, grid(_, _, _)), grid(E, Rows, Cols).
kb_facing_(E, T, Dir) :- current_predicate(_, facing(_, _, _)), facing(E, T, Dir), !.
kb_door_state_(E, T, Id, S) :-
    current_predicate(_, door_state(_, _, _, _)), door_state(E, T, Id, S).

% --------------------------------------------------------------- default goal

%!  default_goal(+E, +T, -Object) is semidet.
%
%   The object a Prolog agent goes for when its strategy names none it can
%   reach, a hand-written strategy. RGW: the sword while it is on the map and
%   not held; holding it, the nearest enemy; then the terminal; then a
%   teleport end. Box-World: the lock of the held key's colour whose box is
%   worth opening (it holds the gem, or a key for such a lock); else the
%   nearest loose key of such a lock; else the nearest loose key. Only
%   objects with a route count.
%
%       ?- default_goal(0, 0, G).
%       G = terminal.

default_goal(E, T, Goal) :-
    kb_facing_(E, T, _),
    !,
    mg_default_(E, T, Goal),
    route_exists(E, T, Goal),
    !.
default_goal(E, T, Goal) :-
    default_(E, T, Goal),
    route_exists(E, T, Goal),
    !.

default_(E, T, sword) :-
    \+ kb_holding_(E, T, sword),
    at(E, T, sword, _, _).
default_(E, T, Enemy) :-
    kb_holding_(E, T, sword),
    nearest_(E, T, X, kb_object_(X, enemy), Enemy).
default_(_, _, terminal).
default_(E, T, End) :-
    kb_object_(End, teleport),
    at(E, T, End, _, _).
default_(E, T, Lock) :-
    kb_holding_(E, T, key(C)),
    kb_object_(Lock, lock(C)),
    useful_(E, T, Lock).
default_(E, T, Key) :-
    nearest_(E, T, K,
             ( kb_object_(K, key(C)), loose_(E, T, K),
               kb_object_(L, lock(C)), useful_(E, T, L) ),
             Key).
default_(E, T, Key) :-
    nearest_(E, T, K, ( kb_object_(K, key(_)), loose_(E, T, K) ), Key).

%   nearest_(+E, +T, ?X, +Cond, -Nearest): of the objects X on the map for
%   which Cond holds, the one with the cheapest route.
nearest_(E, T, X, Cond, Nearest) :-
    findall(D-X, ( call(Cond), at(E, T, X, _, _), route_distance(E, T, X, D) ), Ds),
    msort(Ds, [_-Nearest|_]).

%   Box-World: a box is a lock with its content in the cell to its left; a
%   loose key has no lock to its right.
content_(E, T, Lock, Content) :-
    at(E, T, Lock, R, C),
    Left is C - 1,
    at(E, T, X, R, Left),
    kb_object_(X, Content).

useful_(E, T, Lock) :-
    at(E, T, Lock, _, _),
    (   content_(E, T, Lock, gem)
    ->  true
    ;   content_(E, T, Lock, key(C)),
        kb_object_(Next, lock(C)),
        Next \== Lock,
        useful_(E, T, Next)
    ),
    !.

loose_(E, T, Key) :-
    at(E, T, Key, R, C),
    Right is C + 1,
    \+ ( at(E, T, X, R, Right), kb_object_(X, lock(_)) ).

% --------------------------------------------------------------- Minigrid

%   Minigrid and BabyAI (a state with facing/3): the agent has a direction
%   and acts by turning (left, right) and stepping ahead (forward), so a
%   route is a path over (cell, direction) states, each action costing one
%   step, to a state next to the goal object and facing it, then the
%   interaction: pickup for a key, ball or box; toggle for a closed or
%   locked door (a locked one opens with the held key of its colour);
%   forward for an open door and the goal. Cost: the path's actions plus
%   the interaction. A path may not enter a wall, lava, or a cell of an
%   object other than an open door (keys, balls, boxes and closed doors
%   block; the goal ends the episode). Ties go to the first action in the
%   order left, right, forward. One breadth-first search from the agent's
%   (cell, direction) per state answers for every object
%   (mg_search_/3, remembered for the state last asked).
%
%   Directions: facing/3's east, south, west, north (Minigrid's 0..3);
%   ahead of the agent is its column + 1, row + 1, column - 1, row - 1.

mg_dir_(east, 0).
mg_dir_(south, 1).
mg_dir_(west, 2).
mg_dir_(north, 3).

mg_ahead_(0, 0, 1).
mg_ahead_(1, 1, 0).
mg_ahead_(2, 0, -1).
mg_ahead_(3, -1, 0).

%   mg_route_(+E, +T, +Goal, -Action, -Cost)
mg_route_(E, T, Goal, Action, Cost) :-
    at(E, T, Goal, GR, GC),
    Goal \== agent,
    \+ at(E, T, agent, GR, GC),
    mg_search_(E, T, search(Rows, Cols, Dist)),
    findall(D-AI, ( mg_ahead_(Dir, DR, DC),
                    R is GR - DR, C is GC - DC,
                    inside_(R-C, Rows, Cols),
                    I is (R * Cols + C) * 4 + Dir + 1,
                    arg(I, Dist, V), nonvar(V), V = D-AI ),
            Found),
    msort(Found, [D-AI|_]),
    (   D =:= 0
    ->  mg_interaction_(E, T, Goal, Action)
    ;   nth0(AI, [left, right, forward], Action)
    ),
    Cost is D + 1.

%   mg_interaction_(+E, +T, +Goal, -Action): what the agent does facing Goal.
mg_interaction_(E, T, Goal, Action) :-
    (   kb_object_(Goal, Type), compound(Type)
    ->  functor(Type, Kind, _)
    ;   kb_object_(Goal, Kind)
    ->  true
    ;   Kind = Goal
    ),
    (   memberchk(Kind, [key, ball, box])
    ->  Action = pickup
    ;   Kind == door, \+ kb_door_state_(E, T, Goal, open)
    ->  Action = toggle
    ;   Action = forward
    ).

%   mg_search_(+E, +T, -Search): search(Rows, Cols, Dist), Dist a term with
%   one argument per (cell, direction), (Row * Cols + Col) * 4 + Dir + 1,
%   bound to Moves-FirstActionIndex (0 left, 1 right, 2 forward) for each
%   state the agent reaches; remembered for the state last asked.
mg_search_(E, T, Search) :-
    cache_key_(turns, K),
    (   nb_current(K, turns(E0, T0, S0)), E0 == E, T0 == T
    ->  Search = S0
    ;   mg_new_search_(E, T, Search),
        nb_setval(K, turns(E, T, Search))
    ).

mg_new_search_(E, T, search(Rows, Cols, Dist)) :-
    kb_grid_(E, Rows, Cols),
    at(E, T, agent, R0, C0),
    kb_facing_(E, T, Facing),
    mg_dir_(Facing, Dir0),
    !,
    mg_free_(E, T, Rows, Cols, Free),
    N is Rows * Cols * 4,
    functor(Dist, dist, N),
    Cell0 is R0 * Cols + C0,
    S0 is Cell0 * 4 + Dir0 + 1,
    nb_setarg(S0, Dist, 0-none),
    mg_first_(Cell0, Dir0, Rows, Cols, Free, Dist, Frontier),
    mg_bfs_(Frontier, 1, Rows, Cols, Free, Dist).

%   mg_free_(+E, +T, +Rows, +Cols, -Free): a term with one argument per
%   cell, bound (to x) for a cell a path may not enter.
mg_free_(E, T, Rows, Cols, Free) :-
    N is Rows * Cols,
    functor(Free, free, N),
    forall(( kb_terrain_(E, Type, R, C), Type \== floor, inside_(R-C, Rows, Cols) ),
           ( I is R * Cols + C + 1, nb_setarg(I, Free, x) )),
    forall(( at(E, T, Id, R, C), Id \== agent, inside_(R-C, Rows, Cols),
             \+ kb_door_state_(E, T, Id, open) ),
           ( I is R * Cols + C + 1, nb_setarg(I, Free, x) )).

%   mg_next_(+Cell, +Dir, +AI, +Rows, +Cols, +Free, -Cell1, -Dir1): the
%   state action AI (0 left, 1 right, 2 forward) leads to; fails for a
%   forward into a closed cell or off the grid.
mg_next_(Cell, Dir, 0, _, _, _, Cell, Dir1) :- Dir1 is (Dir + 3) mod 4.
mg_next_(Cell, Dir, 1, _, _, _, Cell, Dir1) :- Dir1 is (Dir + 1) mod 4.
mg_next_(Cell, Dir, 2, Rows, Cols, Free, Cell1, Dir) :-
    mg_ahead_(Dir, DR, DC),
    R is Cell // Cols + DR, C is Cell mod Cols + DC,
    inside_(R-C, Rows, Cols),
    Cell1 is R * Cols + C,
    I is Cell1 + 1,
    arg(I, Free, V),
    var(V).

%   mg_first_: the start's successors, each keeping its own action as the
%   first action (Frontier: Cell-Dir-AI, in the order left, right, forward).
mg_first_(Cell0, Dir0, Rows, Cols, Free, Dist, Frontier) :-
    findall(Cell-Dir-AI,
            ( member(AI, [0, 1, 2]),
              mg_next_(Cell0, Dir0, AI, Rows, Cols, Free, Cell, Dir) ),
            Steps),
    mg_mark_(Steps, 1, Dist, Frontier).

mg_mark_([], _, _, []).
mg_mark_([Cell-Dir-AI|Steps], D, Dist, Frontier) :-
    I is Cell * 4 + Dir + 1,
    arg(I, Dist, V),
    (   var(V)
    ->  nb_setarg(I, Dist, D-AI),
        Frontier = [Cell-Dir-AI|Frontier1]
    ;   Frontier = Frontier1
    ),
    mg_mark_(Steps, D, Dist, Frontier1).

%   mg_bfs_(+Frontier, +D, ...): Frontier's states are D actions away;
%   mark their unmarked successors D + 1 with the first action of the
%   state they extend, in queue order.
mg_bfs_([], _, _, _, _, _) :- !.
mg_bfs_(Frontier, D, Rows, Cols, Free, Dist) :-
    D1 is D + 1,
    findall(Cell1-Dir1-AI,
            ( member(Cell-Dir-AI, Frontier),
              member(A, [0, 1, 2]),
              mg_next_(Cell, Dir, A, Rows, Cols, Free, Cell1, Dir1) ),
            Steps),
    mg_mark_(Steps, D1, Dist, Next),
    mg_bfs_(Next, D1, Rows, Cols, Free, Dist).

%   mg_safe_step_(+E, +T, -Action): forward into a free cell ahead, else a
%   left turn (a harmless action for when there is nowhere to go).
mg_safe_step_(E, T, Action) :-
    (   kb_grid_(E, Rows, Cols),
        at(E, T, agent, R, C),
        kb_facing_(E, T, Facing),
        mg_dir_(Facing, Dir),
        mg_free_(E, T, Rows, Cols, Free),
        Cell is R * Cols + C,
        mg_next_(Cell, Dir, 2, Rows, Cols, Free, _, _)
    ->  Action = forward
    ;   Action = left
    ).

%   mg_default_(+E, +T, -Goal): Minigrid's default strategy: the key of a
%   locked door's colour while not held, then a door that is not open
%   (locked: with its key held), then the goal.
mg_default_(E, T, Key) :-
    kb_object_(Door, door(C)),
    kb_door_state_(E, T, Door, locked),
    \+ kb_holding_(E, T, key(C)),
    kb_object_(Key, key(C)),
    at(E, T, Key, _, _).
mg_default_(E, T, Door) :-
    kb_object_(Door, door(C)),
    kb_door_state_(E, T, Door, State),
    (   State == closed
    ->  true
    ;   State == locked, kb_holding_(E, T, key(C))
    ).
mg_default_(E, T, goal) :-
    at(E, T, goal, _, _).
