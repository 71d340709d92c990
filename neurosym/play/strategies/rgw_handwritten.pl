/*  rgw_handwritten.pl -- the hand-written Relational-Grid-World strategy
    that `neurosym play --policy` plays, and `--compare handwritten` beside a
    strategy (not learned; the learned ones come from
    `neurosym induce strategy`).

    goal(E, T, Object): the object to go for next in state T of episode E;
    the first answer counts. It uses route.pl's route_exists/3 and
    route_distance/4, which `neurosym play` loads beside it.

        neurosym play --policy neurosym/play/strategies/rgw_handwritten.pl --env rgw-random
        neurosym play --policy strategy.pl --env rgw-random --compare handwritten
*/
%! features: world

:- dynamic at/5, object/2, holding/3.

% The sword first, while it is on the map and reachable: guarded levels need
% it, and every enemy beaten with it pays +1.
goal(E, T, sword) :-
    \+ holding(E, T, sword),
    at(E, T, sword, _, _),
    route_exists(E, T, sword).
% Holding the sword: the nearest reachable enemy.
goal(E, T, Enemy) :-
    holding(E, T, sword),
    findall(D-X, ( object(X, enemy), at(E, T, X, _, _), route_distance(E, T, X, D) ), Ds),
    msort(Ds, [_-Enemy|_]).
goal(E, T, terminal) :-
    route_exists(E, T, terminal).
% The terminal out of reach: through the teleport (an end the agent is not on).
goal(E, T, End) :-
    object(End, teleport),
    at(E, T, End, _, _),
    route_exists(E, T, End).
goal(_, _, terminal).
