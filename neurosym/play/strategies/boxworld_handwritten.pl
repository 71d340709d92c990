/*  boxworld_handwritten.pl -- the hand-written Box-World strategy that
    `neurosym play --policy` plays, and `--compare handwritten` beside a
    strategy (not learned; the learned ones come from
    `neurosym induce strategy`).

    goal(E, T, Object): the object to go for next in state T of episode E;
    the first answer counts. A lock is worth opening when its box holds the
    gem, or a key whose lock is worth opening; a loose key lies in no box (no
    lock right of it). Uses route.pl's route_exists/3, which `neurosym play`
    loads beside it.

        neurosym play --policy neurosym/play/strategies/boxworld_handwritten.pl --env bw2
        neurosym play --policy strategy.pl --env bw2 --compare handwritten
*/
%! features: world

:- dynamic at/5, object/2, holding/3.

% Holding a key: the lock of its colour worth opening.
goal(E, T, Lock) :-
    holding(E, T, key(C)),
    object(Lock, lock(C)),
    at(E, T, Lock, _, _),
    bws_useful(E, T, Lock),
    route_exists(E, T, Lock).
% Else a loose key that opens a lock worth opening.
goal(E, T, Key) :-
    object(Key, key(C)),
    at(E, T, Key, R, Col),
    bws_loose(E, T, R, Col),
    object(Lock, lock(C)),
    at(E, T, Lock, _, _),
    bws_useful(E, T, Lock),
    route_exists(E, T, Key).

bws_content(E, T, Lock, Content) :-
    at(E, T, Lock, R, C),
    Left is C - 1,
    at(E, T, X, R, Left),
    object(X, Content).

bws_useful(E, T, Lock) :-
    bws_content(E, T, Lock, gem),
    !.
bws_useful(E, T, Lock) :-
    bws_content(E, T, Lock, key(C)),
    object(Next, lock(C)),
    Next \== Lock,
    at(E, T, Next, _, _),
    bws_useful(E, T, Next),
    !.

bws_loose(E, T, R, C) :-
    Right is C + 1,
    \+ ( at(E, T, X, R, Right), object(X, lock(_)) ).
