/*  strategy_route.pl -- the route features of a learned strategy.

    `neurosym induce strategy` copies the text below this comment,
    byte for byte, into every learned strategy file, after the text of
    strategy_features.pl. The routes themselves are rules/route.pl's
    route_moves/4,5 (one breadth-first search per state and start cell,
    remembered): load route.pl beside the strategy, as `neurosym play` does:
        swipl kb.pl rules/route.pl strategy.pl
    A route passes only empty cells, mountains and the sword's cell; its
    length is its number of moves, 999 when there is none.
*/

%!  route_length(+E, +T, +O, -D) is det.
%   Moves on the shortest route from the agent to object O that passes only empty cells,
%   mountains and the sword's cell; 999 when there is none (route_moves/4 of rules/route.pl).
route_length(E, T, O, D) :- route_moves(E, T, O, D).

%!  route_from_(+E, +T, +From, +O, -D) is det.
%   As route_length/4, from cell From (Row-Col) instead of the agent's.
route_from_(E, T, From, O, D) :- route_moves(E, T, From, O, D).

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
