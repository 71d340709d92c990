"""Route distances on the recorded map, the same in Python and in the learned file's Prolog.

A route goes through the grid's cells (``grid/3``) in the four directions and
passes only empty cells, mountains and the sword's cell: walls and other
terrain, and every other object (a pit, a teleport end, the enemy, the
terminal, a key, a lock) block it, except the object it leads to. So a route
says what the agent can reach without a contact on the way (without the
teleport, in particular). Its length is the number of moves.
"""

from __future__ import annotations

from collections import deque

PASSABLE_TERRAIN = frozenset({"mountain"})
PASSABLE_KINDS = frozenset({"sword"})

UNREACHABLE = 999
"""The route length of an object no route reaches."""

PROLOG = r"""
%!  route_length(+E, +T, +O, -D) is det.
%   Moves on the shortest route from the agent to object O that passes only empty cells,
%   mountains and the sword's cell; 999 when there is none.
route_length(E, T, O, D) :-
    (   at(E, T, agent, R0, C0) -> route_from_(E, T, R0-C0, O, D) ; D = 999 ).

route_from_(E, T, R0-C0, O, D) :-
    (   at(E, T, O, R, C), grid(E, Rows, Cols)
    ->  (   route_bfs_(E, T, Rows, Cols, R-C, [R0-C0], [R0-C0], 0, D0) -> D = D0 ; D = 999 )
    ;   D = 999
    ).

%!  teleport_shortcut_to(+E, +T, ?Kind) is semidet.
%   Some teleport end on the map is a shortcut to an object of this kind.
teleport_shortcut_to(E, T, K) :-
    once(( goal_candidate(E, T, O), teleport_shortcut(E, T, O, K) )).

%!  teleport_not_longer(+E, +T, +O, ?Kind) is semidet.
%   Like teleport_shortcut/4, but the route through O may be as long as the one without.
teleport_not_longer(E, T, O, K) :-
    object_kind(O, teleport), route_length(E, T, O, D1), D1 < 999,
    goal_candidate(E, T, X), X \== O, object_kind(X, teleport), at(E, T, X, XR, XC), !,
    once(( goal_candidate(E, T, Y), object_kind(Y, K), K \== teleport,
           route_from_(E, T, XR-XC, Y, D2), D2 < 999, route_length(E, T, Y, D),
           D1 + D2 =< D )).

%!  route_not_longer(+E, +T, +O, ?Kind) is semidet.
%   O is reachable and its route is not longer than that of any object of this kind
%   (true when none of the kind is reachable).
route_not_longer(E, T, O, K) :-
    route_length(E, T, O, D), D < 999,
    \+ ( goal_candidate(E, T, Y), Y \== O, object_kind(Y, K),
         route_length(E, T, Y, D2), D2 < D ).

%!  teleport_shortcut(+E, +T, +O, ?Kind) is semidet.
%   O is a teleport end, and entering it then walking from the other end reaches an
%   object of this kind in fewer moves than the route without the teleport.
teleport_shortcut(E, T, O, K) :-
    object_kind(O, teleport), route_length(E, T, O, D1), D1 < 999,
    goal_candidate(E, T, X), X \== O, object_kind(X, teleport), at(E, T, X, XR, XC), !,
    once(( goal_candidate(E, T, Y), object_kind(Y, K), K \== teleport,
           route_from_(E, T, XR-XC, Y, D2), D2 < 999, route_length(E, T, Y, D),
           D1 + D2 < D )).

%!  reachable(+E, +T, +O) is semidet.
reachable(E, T, O) :- route_length(E, T, O, D), D < 999.

%!  nearest_reachable_of_kind(+E, +T, +O) is semidet.
%   O is reachable and no object of its kind has a strictly shorter route.
nearest_reachable_of_kind(E, T, O) :-
    route_length(E, T, O, D), D < 999, object_kind(O, K),
    \+ ( goal_candidate(E, T, O2), O2 \== O, object_kind(O2, K),
         route_length(E, T, O2, D2), D2 < D ).

%!  reachable_kind(+E, +T, ?Kind) is semidet.
%   Some object of this kind is reachable.
reachable_kind(E, T, K) :- once(( goal_candidate(E, T, O), object_kind(O, K), reachable(E, T, O) )).

route_bfs_(_, _, _, _, Goal, Frontier, _, K, D) :-
    member(Cell, Frontier), route_step_(Cell, Goal), !, D is K + 1.
route_bfs_(E, T, Rows, Cols, Goal, Frontier, Seen, K, D) :-
    findall(N, ( member(Cell, Frontier), route_step_(Cell, N), route_open_(E, T, Rows, Cols, N),
                 \+ memberchk(N, Seen) ), Ns0),
    sort(Ns0, Ns), Ns \== [],
    append(Ns, Seen, Seen1), K1 is K + 1,
    route_bfs_(E, T, Rows, Cols, Goal, Ns, Seen1, K1, D).

route_step_(R-C, R1-C) :- R1 is R - 1.
route_step_(R-C, R-C1) :- C1 is C + 1.
route_step_(R-C, R1-C) :- R1 is R + 1.
route_step_(R-C, R-C1) :- C1 is C - 1.

route_open_(E, T, Rows, Cols, R-C) :-
    R >= 0, R < Rows, C >= 0, C < Cols,
    \+ ( terrain(E, Ty, R, C), Ty \== mountain ),
    \+ ( at(E, T, X, R, C), X \== agent, \+ object_kind(X, sword) ).
"""


def shortcuts(
    agent: tuple[int, int],
    cells: dict[str, tuple[int, int]],
    kinds: dict[str, str],
    size: tuple[int, int],
    closed: set[tuple[int, int]],
    ties: bool = False,
) -> dict[str, set[str]]:
    """Teleport end -> the kinds it is a shortcut to (:pl:`teleport_shortcut/4`; ``ties``:
    :pl:`teleport_not_longer/4`, the route through it as long as the one without allowed)."""
    direct = route_lengths(agent, cells, size, closed)
    ends = sorted(o for o in cells if kinds[o] == "teleport")
    out: dict[str, set[str]] = {}
    for o in ends:
        others = [x for x in ends if x != o]
        if direct[o] >= UNREACHABLE or not others:
            continue
        after = route_lengths(cells[others[0]], cells, size, closed)
        out[o] = {
            kinds[y]
            for y in cells
            if kinds[y] != "teleport"
            and after[y] < UNREACHABLE
            and (direct[o] + after[y] <= direct[y] if ties else direct[o] + after[y] < direct[y])
        }
    return out


def route_lengths(
    start: tuple[int, int],
    targets: dict[str, tuple[int, int]],
    size: tuple[int, int],
    closed: set[tuple[int, int]],
) -> dict[str, int]:
    """Moves from ``start`` to each target cell through cells not in ``closed`` (999 when none)."""
    rows, cols = size
    dist = {start: 0}
    queue = deque([start])
    while queue:
        r, c = queue.popleft()
        for n in ((r - 1, c), (r, c + 1), (r + 1, c), (r, c - 1)):
            if n not in dist and 0 <= n[0] < rows and 0 <= n[1] < cols and n not in closed:
                dist[n] = dist[(r, c)] + 1
                queue.append(n)
    out = {}
    for name, (r, c) in targets.items():
        near = [dist[n] for n in ((r - 1, c), (r, c + 1), (r + 1, c), (r, c - 1)) if n in dist]
        out[name] = min(near) + 1 if near else UNREACHABLE
    return out
