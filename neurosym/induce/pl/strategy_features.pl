/*  strategy_features.pl -- the predicates a learned strategy's features call.

    `neurosym induce strategy` copies the text below this comment,
    byte for byte, into every learned strategy file (then the text of
    strategy_route.pl): the world features (kinds, Manhattan distances,
    Box-World's keys and locks, Minigrid's doors) and the network's relation
    features. They read at/5, holding/3, object/2, door_state/4, attends/8,
    holds/5 and attention/6.
*/

%!  goal_candidate(?E, ?T, -O) is nondet.
%   The objects on the map in state T (at/5, not the agent), in the standard order of their ids.
%   For a given state, findall/3 and sort/2: the answers of setof/3, at a fraction of its cost
%   (every clause of goal/3 asks).
goal_candidate(E, T, O) :-
    (   ground(E-T)
    ->  findall(O1, ( at(E, T, O1, _, _), O1 \== agent ), Os0),
        sort(Os0, Os)
    ;   setof(O1, R^C^(at(E, T, O1, R, C), O1 \== agent), Os)
    ),
    member(O, Os).

%!  object_kind(?O, ?Kind) is nondet.
%   The kind of object O: its type, or the type's functor (key, lock) for key(C), lock(C).
object_kind(O, K) :- object(O, Ty), ( compound(Ty) -> functor(Ty, K, _) ; K = Ty ).

%!  object_colour(?O, ?C) is nondet.
object_colour(O, C) :- object(O, Ty), compound(Ty), arg(1, Ty, C).

%!  holding_kind(+E, +T, ?Kind) is nondet.
holding_kind(E, T, K) :- holding(E, T, I), ( compound(I) -> functor(I, K, _) ; K = I ).

%!  on_map(+E, +T, ?Kind) is semidet.
%   An object of this kind is on the map in state T.
on_map(E, T, K) :- once((goal_candidate(E, T, O), object_kind(O, K))).

%!  agent_distance(+E, +T, +O, -D) is semidet.
%   Manhattan distance from the agent to object O in state T.
agent_distance(E, T, O, D) :-
    at(E, T, agent, R0, C0), at(E, T, O, R, C), !,
    D is abs(R - R0) + abs(C - C0).

%!  nearest_of_kind(+E, +T, +O) is semidet.
%   No object of O's kind is strictly nearer to the agent.
nearest_of_kind(E, T, O) :-
    object_kind(O, K), agent_distance(E, T, O, D),
    \+ ( goal_candidate(E, T, O2), O2 \== O, object_kind(O2, K),
         agent_distance(E, T, O2, D2), D2 < D ).

%!  nearest_object(+E, +T, +O) is semidet.
%   No object is strictly nearer to the agent.
nearest_object(E, T, O) :-
    agent_distance(E, T, O, D),
    \+ ( goal_candidate(E, T, O2), O2 \== O, agent_distance(E, T, O2, D2), D2 < D ).

%!  lock_of_held_key(+E, +T, +O) is semidet.
%   Box-World: O is a lock of the colour of the key the agent holds.
lock_of_held_key(E, T, O) :-
    object_kind(O, lock), object_colour(O, C), holding(E, T, key(C)), !.

%!  key_fits_lock(+E, +T, +O) is semidet.
%   Box-World: O is a key and a lock of its colour is on the map.
key_fits_lock(E, T, O) :-
    object_kind(O, key), object_colour(O, C),
    once(( goal_candidate(E, T, L), object(L, lock(C)) )).

%!  loose(+E, +T, +O) is semidet.
%   Box-World: O is a key with no lock to its right (not a box's content).
loose(E, T, O) :-
    object_kind(O, key), at(E, T, O, R, C), !, C1 is C + 1,
    \+ ( at(E, T, L, R, C1), object_kind(L, lock) ).

%!  box_content(+E, +T, +Lock, -Content) is semidet.
%   Box-World: the object in the cell left of the lock.
box_content(E, T, L, X) :-
    object_kind(L, lock), at(E, T, L, R, C), !, C0 is C - 1,
    at(E, T, X, R, C0), X \== agent, !.

%!  box_holds_gem(+E, +T, +O) is semidet.
box_holds_gem(E, T, O) :- box_content(E, T, O, X), object_kind(X, gem).

%!  box_holds_useful_key(+E, +T, +O) is semidet.
%   Box-World: O's box holds a key of a colour some other lock on the map takes.
box_holds_useful_key(E, T, O) :-
    box_content(E, T, O, X), object_kind(X, key), object_colour(X, C),
    once(( goal_candidate(E, T, L), L \== O, object(L, lock(C)) )).

%!  door_open(+E, +T, +O) is semidet.
%   Minigrid: O is a door that is open in state T (door_state/4).
door_open(E, T, O) :- object_kind(O, door), door_state(E, T, O, open), !.

%!  door_locked(+E, +T, +O) is semidet.
%   Minigrid: O is a door that is locked in state T.
door_locked(E, T, O) :- object_kind(O, door), door_state(E, T, O, locked), !.

%!  door_of_held_key(+E, +T, +O) is semidet.
%   Minigrid: O is a door of the colour of the key the agent holds.
door_of_held_key(E, T, O) :-
    object_kind(O, door), object_colour(O, C), holding(E, T, key(C)), !.

%!  key_of_locked_door(+E, +T, +O) is semidet.
%   Minigrid: O is a key and a locked door of its colour is on the map.
key_of_locked_door(E, T, O) :-
    object_kind(O, key), object_colour(O, C),
    once(( goal_candidate(E, T, D), object(D, door(C)), door_state(E, T, D, locked) )).

%!  attended_by(+E, +T, ?H, ?Arg, +O) is nondet.
%   PrediNet: head H's argument Arg attends the cell of object O (the cell mapped through at/5).
attended_by(E, T, H, A, O) :- at(E, T, O, R, C), attends(E, T, H, A, _, R, C, _).

%!  related(+E, +T, ?J, ?Pos, +O) is nondet.
%   PrediNet: relation J holds with O's entity (its object/2 type) as argument Pos (1 or 2).
related(E, T, J, 1, O) :- object(O, Ty), holds(E, T, r(J), Ty, _).
related(E, T, J, 2, O) :- object(O, Ty), holds(E, T, r(J), _, Ty).

%!  agent_query_attends(+E, +T, ?H, +O) is nondet.
%   MHDPA: head H's query from the agent's cell attends O's entity (its object/2 type).
agent_query_attends(E, T, H, O) :- object(O, Ty), attention(E, T, H, agent, Ty, _).

%!  query_attends_agent(+E, +T, ?H, +O) is nondet.
%   MHDPA: head H's query from O's entity attends the agent.
query_attends_agent(E, T, H, O) :- object(O, Ty), attention(E, T, H, Ty, agent, _).

%!  attending_queries(+E, +T, +H, +O, -N) is det.
%   MHDPA: how many of head H's query cells attend O's entity.
attending_queries(E, T, H, O, N) :-
    object(O, Ty), aggregate_all(count, attention(E, T, H, _, Ty, _), N).
