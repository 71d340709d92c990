/*  minigrid_handwritten.pl -- the hand-written Minigrid strategy (DoorKey and
    the like) that `neurosym play --policy` plays, and `--compare handwritten`
    beside a strategy (not learned; the learned ones come from `neurosym induce
    strategy`).

    goal(E, T, Object): the object to go for next in state T of episode E;
    the first answer counts. route.pl's route/4, which `neurosym play`
    loads beside it, turns the agent, walks it there and does the
    interaction (pickup a key, toggle a door, forward onto the goal).

        neurosym play --policy neurosym/play/strategies/minigrid_handwritten.pl --env MiniGrid-DoorKey-8x8-v0
        neurosym play --policy strategy.pl --env MiniGrid-DoorKey-8x8-v0 --compare handwritten
*/
%! features: world

:- dynamic at/5, object/2, holding/3, door_state/4.

% The key of a locked door, while not held.
goal(E, T, Key) :-
    object(Door, door(C)),
    door_state(E, T, Door, locked),
    \+ holding(E, T, key(C)),
    object(Key, key(C)),
    at(E, T, Key, _, _).
% Then its door (or any closed one), until it is open.
goal(E, T, Door) :-
    object(Door, door(_)),
    door_state(E, T, Door, State),
    State \== open,
    at(E, T, Door, _, _).
goal(_, _, goal).
