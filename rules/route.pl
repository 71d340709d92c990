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
    exception: an agent that holds the sword may cross RGW enemies (the env
    pays +1 and removes them). When no such path exists, a second search
    takes the teleport (entering one of its two ends lands on the other). An
    unarmed agent has no route to an enemy: meeting it costs -1 (and with a
    blocking enemy the agent never gets through); nor has any agent a route
    into a pit, which ends the episode.

    Cost: a step costs 1; entering a mountain costs 1 + Rows * Cols, more than
    any path without it. The env pays -0.1 for a mountain and nothing for a
    step, so a path with fewer mountains always earns more; among those, the
    shortest is taken (the step limit is the only price of a step). Ties go
    to the first action in the order up, right, down, left.

    Dijkstra's search over library(heaps); the map and the visited cells are
    terms with one argument per cell, read with arg/3. Each episode's
    terrain and cell neighbours are built once (route_pl_grid_/6).
    Helpers start with route_pl_, so this file loads beside the other rule
    files and beside a learned strategy (whose own helpers start with route_).

    route_moves/4,5 count moves instead, for the route features of a learned
    strategy (`neurosym induce --what strategy`): a breadth-first search
    that enters no object on the way but the sword, and no teleport jump.
    One search from a cell answers for every object of the state: it runs
    once per state and start cell, and its answers are remembered.

    What route/5 and route_moves/5 remember (routes, move counts, searches,
    each episode's map) lives in module route_pl_cache (memo_/5, moves_/5,
    searched_/6, grid_/6, keyed by the module that loaded this file), out of
    reach of the facts: a KB, which holds facts for predicates without a
    module (in its own module, or in user), cannot plant answers there. The file
    itself is plain Prolog (no module header), so that it loads into a KB
    module, into user, and beside other rule files alike.
*/

:- use_module(library(heaps)).
:- use_module(library(assoc)).
:- use_module(library(lists)).
:- use_module(library(apply)).

:- dynamic at/5, object/2, holding/3, terrain/4, grid/3.

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

route(E, T, Goal, Action, Cost) :-
    ground(E-T-Goal),
    !,
    context_module(M),
    route_pl_memo_ready_,
    (   route_pl_cache:memo_(M, E, T, Goal, Found)
    ->  true
    ;   (   route_pl_(E, T, Goal, A, C)
        ->  Found = found(A, C)
        ;   Found = none
        ),
        assertz(route_pl_cache:memo_(M, E, T, Goal, Found))
    ),
    Found = found(Action, Cost).
route(E, T, Goal, Action, Cost) :-
    route_pl_(E, T, Goal, Action, Cost).

%!  route_forget(+E) is det.
%
%   Forget what was remembered for episode E. route/5 remembers its answer
%   for each state and goal, route_moves/5 its searches, both the episode's
%   map, since a state's facts do not change (in a KB, and in the live
%   states of `neurosym play`, which calls this when an episode ends); call
%   it after changing the facts of an episode it was asked about.

route_forget(E) :-
    context_module(M),
    route_pl_memo_ready_,
    retractall(route_pl_cache:memo_(M, E, _, _, _)),
    retractall(route_pl_cache:moves_(_, E, M, _, _)),
    retractall(route_pl_cache:grid_(E, M, _, _, _, _)),
    retractall(route_pl_cache:searched_(E, M, _, _, _, _)).

%   The memos are declared when first used, not by a directive: a directive
%   would tie them to this file, and unloading one copy of the file (a
%   closed KB) would take the other copies' memos with them. Their module
%   inherits from system only, not from user: facts of the same names in
%   user (a KB consulted in plain swipl) stay out of sight. The flag is a
%   global variable (per thread), which no fact can set.
route_pl_memo_ready_ :-
    (   nb_current(route_pl_memo_ready, true)
    ->  true
    ;   set_module(route_pl_cache:base(system)),
        dynamic([ route_pl_cache:memo_/5, route_pl_cache:moves_/5,
                  route_pl_cache:searched_/6, route_pl_cache:grid_/6 ]),
        nb_setval(route_pl_memo_ready, true)
    ).

route_pl_(E, T, Goal, Action, Cost) :-
    at(E, T, agent, R0, C0),
    at(E, T, Goal, GR, GC),
    Goal \== agent,
    \+ (R0 == GR, C0 == GC),
    \+ object(Goal, pit),
    \+ ( object(Goal, enemy), \+ holding(E, T, sword) ),
    !,
    context_module(M),
    route_pl_memo_ready_,
    route_pl_mode_(Mode),
    route_pl_map_(M, E, T, Goal, Mode, GR-GC, Map),
    route_pl_search_(R0-C0, Map, Action, Cost),
    !.

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
    at(E, T, agent, R, C),
    grid(E, Rows, Cols),
    route_pl_blocked_(E, T, none, Blocked),
    route_pl_move_(Action, R-C, R1-C1),
    route_pl_inside_(R1-C1, Rows, Cols),
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
%   every object of the state; it is remembered, keyed by the loading
%   module, E, T and From, until route_forget/1.

route_moves(E, T, From, Goal, Moves) :-
    must_be(ground, E-T-From),
    context_module(M),
    route_pl_memo_ready_,
    (   route_pl_cache:moves_(T, E, M, From, Table)
    ->  true
    ;   route_pl_moves_(M, E, T, From, Table),
        assertz(route_pl_cache:moves_(T, E, M, From, Table))
    ),
    (   get_assoc(Goal, Table, Moves0)
    ->  Moves = Moves0
    ;   Moves = 999
    ).

%   route_pl_moves_(+M, +E, +T, +From, -Table): assoc of each object on
%   the map (its first at/5 fact) to its moves from From: one more than the
%   nearest of its neighbours the search reached, else 999.
route_pl_moves_(M, E, T, R0-C0, Table) :-
    findall(Id-(R-C), at(E, T, Id, R, C), Objects),
    (   route_pl_grid_(M, E, Rows, Cols, Adj, Cells0),
        route_pl_inside_(R0-C0, Rows, Cols)
    ->  S is R0 * Cols + C0 + 1,
        findall(I, ( member(Id-(R-C), Objects), Id \== agent, \+ route_pl_passable_(Id),
                     route_pl_inside_(R-C, Rows, Cols), I is R * Cols + C + 1 ),
                Blocked0),
        sort(Blocked0, Blocked),
        route_pl_searched_(M, E, S, Blocked, Adj, Cells0, Cells),
        Search = search(Rows, Cols, Adj, Cells)
    ;   Search = none
    ),
    empty_assoc(A0),
    foldl(route_pl_moves_put_(Search), Objects, A0, Table).

%   route_pl_searched_(+M, +E, +Start, +Blocked, +Adj, +Cells0, -Cells): the
%   search from cell Start (argument index) with the cells Blocked closed,
%   Cells0 the episode's terrain. It depends on nothing else (the agent's
%   cell is free), so it is remembered by episode, start and the blocked
%   cells (a teleport end's search serves every state until an object
%   moves or goes), until route_forget/1.
route_pl_searched_(M, E, S, Blocked, Adj, Cells0, Cells) :-
    term_hash(Blocked, H),
    (   route_pl_cache:searched_(E, M, S, H, Blocked, Cells1)
    ->  Cells = Cells1
    ;   forall(member(I, Blocked), nb_setarg(I, Cells0, x)),
        nb_setarg(S, Cells0, 0),
        route_pl_bfs_([S], 0, Adj, Cells0),
        assertz(route_pl_cache:searched_(E, M, S, H, Blocked, Cells0)),
        Cells = Cells0
    ).

route_pl_moves_put_(Search, Id-(R-C), A0, A) :-
    (   get_assoc(Id, A0, _)
    ->  A = A0
    ;   route_pl_moves_to_(Search, R, C, Moves),
        put_assoc(Id, A0, Moves, A)
    ).

route_pl_moves_to_(search(Rows, Cols, Adj, Cells), R, C, Moves) :-
    route_pl_inside_(R-C, Rows, Cols),
    !,
    I is R * Cols + C + 1,
    arg(I, Adj, Neighbours),
    foldl(route_pl_nearer_(Cells), Neighbours, 999, Near),
    (   Near < 999 -> Moves is Near + 1 ; Moves = 999 ).
route_pl_moves_to_(_, _, _, 999).

route_pl_nearer_(Cells, I, D0, D) :-
    arg(I, Cells, V),
    (   integer(V), V < D0 -> D = V ; D = D0 ).

%   Objects a contact-free path may cross: the sword (a type sword, or a
%   compound of that name).
route_pl_passable_(Id) :-
    object(Id, Type),
    (   compound(Type) -> functor(Type, sword, _) ; Type == sword ),
    !.

%   route_pl_grid_(+M, +E, -Rows, -Cols, -Adj, -Cells): episode E's map as
%   two terms with one argument per cell (Row * Cols + Col + 1). Adj: the
%   list of the cells a step from it enters inside the grid, in the order
%   up, right, down, left. Cells: a fresh copy (the caller may change it)
%   of the cells' terrain: mountain, wall (any other terrain), unbound for
%   a free cell. Built once per episode and remembered, keyed by the
%   loading module and E, until route_forget/1.
route_pl_grid_(M, E, Rows, Cols, Adj, Cells) :-
    (   route_pl_cache:grid_(E, M, Rows0, Cols0, Adj0, Cells0)
    ->  Rows = Rows0, Cols = Cols0, Adj = Adj0, Cells = Cells0
    ;   grid(E, Rows, Cols),
        !,
        route_pl_terrain_(E, Rows, Cols, Cells),
        route_pl_adjacency_(Rows, Cols, Adj),
        assertz(route_pl_cache:grid_(E, M, Rows, Cols, Adj, Cells))
    ).

route_pl_terrain_(E, Rows, Cols, Cells) :-
    N is Rows * Cols,
    functor(Cells, cells, N),
    forall(terrain(E, Type, R, C),
           ( I is R * Cols + C + 1,
             ( Type == mountain -> nb_setarg(I, Cells, mountain) ; nb_setarg(I, Cells, wall) ) )).

route_pl_adjacency_(Rows, Cols, Adj) :-
    N is Rows * Cols,
    functor(Adj, adj, N),
    forall(between(1, N, I),
           ( Cell is I - 1, R is Cell // Cols, C is Cell mod Cols,
             findall(J, ( route_pl_move_(_, R-C, R1-C1),
                          route_pl_inside_(R1-C1, Rows, Cols),
                          J is R1 * Cols + C1 + 1 ),
                     Js),
             nb_setarg(I, Adj, Js) )).

%   route_pl_bfs_(+Frontier, +D, +Adj, !Cells): the cells D moves away are
%   Frontier (argument indices); mark their free and mountain neighbours
%   D + 1, and go on. Cells: the moves to each cell reached, wall or x for
%   a blocked one.
route_pl_bfs_([], _, _, _) :- !.
route_pl_bfs_(Frontier, D, Adj, Cells) :-
    D1 is D + 1,
    route_pl_bfs_level_(Frontier, D1, Adj, Cells, Next, []),
    route_pl_bfs_(Next, D1, Adj, Cells).

route_pl_bfs_level_([], _, _, _, Next, Next).
route_pl_bfs_level_([I|Is], D, Adj, Cells, Next0, Next) :-
    arg(I, Adj, Neighbours),
    route_pl_bfs_visit_(Neighbours, D, Cells, Next0, Next1),
    route_pl_bfs_level_(Is, D, Adj, Cells, Next1, Next).

route_pl_bfs_visit_([], _, _, Next, Next).
route_pl_bfs_visit_([J|Js], D, Cells, Next0, Next) :-
    arg(J, Cells, V),
    (   ( var(V) ; V == mountain )
    ->  nb_setarg(J, Cells, D),
        Next0 = [J|Next1]
    ;   Next0 = Next1
    ),
    route_pl_bfs_visit_(Js, D, Cells, Next1, Next).

% --------------------------------------------------------------- helpers

route_pl_move_(up,    R-C, R1-C) :- R1 is R - 1.
route_pl_move_(right, R-C, R-C1) :- C1 is C + 1.
route_pl_move_(down,  R-C, R1-C) :- R1 is R + 1.
route_pl_move_(left,  R-C, R-C1) :- C1 is C - 1.

route_pl_move_index_(up, 0).
route_pl_move_index_(right, 1).
route_pl_move_index_(down, 2).
route_pl_move_index_(left, 3).

route_pl_inside_(R-C, Rows, Cols) :-
    R >= 0, R < Rows, C >= 0, C < Cols.

%   route_pl_mode_(-Mode): the rules of a search, tried in turn: strict,
%   then with the teleport's ends as jumps.
route_pl_mode_(strict).
route_pl_mode_(jumps).

%   route_pl_map_(+M, +E, +T, +Goal, +Mode, +Target, -Map): what a search
%   needs, as map(Rows, Cols, Cells, MountainCost, TargetCell, Adj). Cells
%   is a term with one argument per cell (Row * Cols + Col + 1), so that a
%   search looks a cell up with arg/3: unbound for a free cell, wall (walls,
%   and objects a path may not enter), mountain, or jump(Landing) for a
%   teleport end; it starts as a fresh copy of the episode's terrain
%   (route_pl_grid_/6). Adj: each cell's neighbours inside the grid.
route_pl_map_(M, E, T, Goal, Mode, GR-GC, map(Rows, Cols, Cells, Mountain, Target, Adj)) :-
    route_pl_grid_(M, E, Rows, Cols, Adj, Cells),
    Mountain is 1 + Rows * Cols,
    Target is GR * Cols + GC,
    forall(( at(E, T, Id, R, C), Id \== agent, Id \== Goal, \+ route_pl_open_(E, T, Id) ),
           ( I is R * Cols + C + 1, nb_setarg(I, Cells, wall) )),
    route_pl_jumps_(E, T, Goal, Mode, Cols, Cells).

%   route_pl_jumps_: in mode jumps, entering a teleport end (not the goal)
%   lands on the other end, when the map has exactly two.
route_pl_jumps_(E, T, Goal, Mode, Cols, Cells) :-
    (   Mode \== strict,
        findall(Id-(R-C), ( object(Id, teleport), at(E, T, Id, R, C) ), [A-(RA-CA), B-(RB-CB)]),
        A \== Goal, B \== Goal
    ->  CellA is RA * Cols + CA, CellB is RB * Cols + CB,
        IA is CellA + 1, IB is CellB + 1,
        nb_setarg(IA, Cells, jump(CellB)),
        nb_setarg(IB, Cells, jump(CellA))
    ;   true
    ).

%   Objects a path may cross: enemies, while the agent holds the sword.
route_pl_open_(E, T, Id) :- object(Id, enemy), holding(E, T, sword).

%   route_pl_blocked_(+E, +T, +Goal, -Blocked): assoc of the cells a path
%   may not enter (walls, and the objects other than Goal that route/4 does
%   not cross), for safe_step/3.
route_pl_blocked_(E, T, Goal, Blocked) :-
    grid(E, _, Cols),
    findall(Cell-wall,
            ( terrain(E, Type, R, C), Type \== mountain, Cell is R * Cols + C ),
            Walls),
    findall(Cell-Id,
            ( at(E, T, Id, R, C), Id \== agent, Id \== Goal,
              \+ route_pl_open_(E, T, Id),
              Cell is R * Cols + C ),
            Objects),
    append(Walls, Objects, Pairs),
    empty_assoc(A0),
    foldl(route_pl_put_, Pairs, A0, Blocked).

route_pl_put_(K-V, A0, A) :- put_assoc(K, A0, V, A).

%   route_pl_search_(+Start, +Map, -Action, -Cost): Dijkstra from Start;
%   each queue entry keeps the first action of its path and is keyed
%   Cost * 4 + the action's index, so that of equally cheap paths the one
%   whose first action comes first in up, right, down, left wins. The
%   target is always enterable. Done cells are marked in a term with one
%   argument per cell.
route_pl_search_(R0-C0, Map, Action, Cost) :-
    Map = map(Rows, Cols, _, _, _, _),
    Start is R0 * Cols + C0,
    N is Rows * Cols,
    functor(Done, done, N),
    S1 is Start + 1,
    nb_setarg(S1, Done, x),
    empty_heap(Heap0),
    route_pl_expand_start_(Start, Map, Done, Heap0, Heap1),
    route_pl_loop_(Heap1, Map, Done, Action, Cost).

route_pl_loop_(Heap0, Map, Done, Action, Cost) :-
    get_from_heap(Heap0, Key, Cell-First, Heap1),
    D is Key // 4,
    I is Cell + 1,
    arg(I, Done, Seen),
    (   arg(5, Map, Target), Cell =:= Target
    ->  Action = First, Cost = D
    ;   nonvar(Seen)
    ->  route_pl_loop_(Heap1, Map, Done, Action, Cost)
    ;   nb_setarg(I, Done, x),
        route_pl_expand_(Cell, First, D, Map, Done, Heap1, Heap2),
        route_pl_loop_(Heap2, Map, Done, Action, Cost)
    ).

%   From the start: each neighbour's move is the first action of the paths
%   through it.
route_pl_expand_start_(Cell, Map, Done, Heap0, Heap) :-
    arg(2, Map, Cols),
    R is Cell // Cols, C is Cell mod Cols,
    Up is R - 1, Down is R + 1, Left is C - 1, Right is C + 1,
    route_pl_neighbour_(Up, C, up, none, 0, Map, Done, Heap0, Heap1),
    route_pl_neighbour_(R, Right, right, none, 0, Map, Done, Heap1, Heap2),
    route_pl_neighbour_(Down, C, down, none, 0, Map, Done, Heap2, Heap3),
    route_pl_neighbour_(R, Left, left, none, 0, Map, Done, Heap3, Heap).

%   Past the start, a path keeps its first action: the neighbours come from
%   the episode's adjacency (Adj), their order does not matter (a queue
%   key holds cost and first action, so equal keys are equal paths).
route_pl_expand_(Cell, First, D, Map, Done, Heap0, Heap) :-
    arg(6, Map, Adj),
    I is Cell + 1,
    arg(I, Adj, Neighbours),
    route_pl_move_index_(First, MI),
    route_pl_adjacent_(Neighbours, First, MI, D, Map, Done, Heap0, Heap).

route_pl_adjacent_([], _, _, _, _, _, Heap, Heap).
route_pl_adjacent_([J|Js], First, MI, D, Map, Done, Heap0, Heap) :-
    Map = map(_, _, Cells, Mountain, Target, _),
    Cell0 is J - 1,
    (   arg(J, Cells, Kind),
        route_pl_enter_(Kind, Cell0, Target, Mountain, Cell, Step),
        I is Cell + 1,
        arg(I, Done, Seen),
        var(Seen)
    ->  Key is (D + Step) * 4 + MI,
        add_to_heap(Heap0, Key, Cell-First, Heap1)
    ;   Heap1 = Heap0
    ),
    route_pl_adjacent_(Js, First, MI, D, Map, Done, Heap1, Heap).

route_pl_neighbour_(R, C, Move, First, D, Map, Done, Heap0, Heap) :-
    Map = map(Rows, Cols, Cells, Mountain, Target, _),
    (   R >= 0, R < Rows, C >= 0, C < Cols,
        Cell0 is R * Cols + C,
        I0 is Cell0 + 1,
        arg(I0, Cells, Kind),
        route_pl_enter_(Kind, Cell0, Target, Mountain, Cell, Step),
        I is Cell + 1,
        arg(I, Done, Seen),
        var(Seen)
    ->  D1 is D + Step,
        ( First == none -> First1 = Move ; First1 = First ),
        route_pl_move_index_(First1, MI),
        Key is D1 * 4 + MI,
        add_to_heap(Heap0, Key, Cell-First1, Heap)
    ;   Heap = Heap0
    ).

%   route_pl_enter_(+Kind, +Cell0, +Target, +Mountain, -Cell, -Step):
%   entering Cell0 of Kind puts the agent on Cell at the cost Step; fails
%   for a cell a path may not enter.
route_pl_enter_(_, Target, Target, _, Target, 1) :- !.
route_pl_enter_(Kind, Cell0, _, _, Cell0, 1) :- var(Kind), !.
route_pl_enter_(mountain, Cell0, _, Mountain, Cell0, Step) :- !, Step is 1 + Mountain.
route_pl_enter_(jump(Landing), _, _, _, Landing, 1).

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
    route_pl_default_(E, T, Goal),
    route_exists(E, T, Goal),
    !.

route_pl_default_(E, T, sword) :-
    \+ holding(E, T, sword),
    at(E, T, sword, _, _).
route_pl_default_(E, T, Enemy) :-
    holding(E, T, sword),
    route_pl_nearest_(E, T, X, object(X, enemy), Enemy).
route_pl_default_(_, _, terminal).
route_pl_default_(E, T, End) :-
    object(End, teleport),
    at(E, T, End, _, _).
route_pl_default_(E, T, Lock) :-
    holding(E, T, key(C)),
    object(Lock, lock(C)),
    route_pl_useful_(E, T, Lock).
route_pl_default_(E, T, Key) :-
    route_pl_nearest_(E, T, K,
                      ( object(K, key(C)), route_pl_loose_(E, T, K),
                        object(L, lock(C)), route_pl_useful_(E, T, L) ),
                      Key).
route_pl_default_(E, T, Key) :-
    route_pl_nearest_(E, T, K, ( object(K, key(_)), route_pl_loose_(E, T, K) ), Key).

%   route_pl_nearest_(+E, +T, ?X, :Cond, -Nearest): of the objects X on the
%   map for which Cond holds, the one with the cheapest route.
route_pl_nearest_(E, T, X, Cond, Nearest) :-
    findall(D-X, ( Cond, at(E, T, X, _, _), route_distance(E, T, X, D) ), Ds),
    msort(Ds, [_-Nearest|_]).

%   Box-World: a box is a lock with its content in the cell to its left; a
%   loose key has no lock to its right.
route_pl_content_(E, T, Lock, Content) :-
    at(E, T, Lock, R, C),
    Left is C - 1,
    at(E, T, X, R, Left),
    object(X, Content).

route_pl_useful_(E, T, Lock) :-
    at(E, T, Lock, _, _),
    (   route_pl_content_(E, T, Lock, gem)
    ->  true
    ;   route_pl_content_(E, T, Lock, key(C)),
        object(Next, lock(C)),
        Next \== Lock,
        route_pl_useful_(E, T, Next)
    ),
    !.

route_pl_loose_(E, T, Key) :-
    at(E, T, Key, R, C),
    Right is C + 1,
    \+ ( at(E, T, X, R, Right), object(X, lock(_)) ).
