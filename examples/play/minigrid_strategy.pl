/*  minigrid_strategy.pl -- a hand-written Minigrid strategy for
    `neurosym play` (DoorKey and the like; not learned: the learned ones
    come from `neurosym induce strategy`): the key of the locked door, then
    the door, then the goal.

    goal(E, T, Object): the object to go for next in state T of episode E;
    the first answer counts. route.pl's route/4, which `neurosym play`
    loads beside it, turns the agent, walks it next to the object, facing
    it, and does the interaction: pickup a key, toggle a door, forward onto
    the goal.

        neurosym play --policy examples/play/minigrid_strategy.pl --env MiniGrid-DoorKey-8x8-v0
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
