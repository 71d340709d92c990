/*  plunit tests of minigrid_handwritten.pl, a strategy `neurosym play
    --compare` plays: its first answer on the Minigrid states of
    rules/tests/route_facts.pl (episode 10), with module route
    (rules/route.pl) loaded beside it as `neurosym play` loads it.

    swipl -g run_tests -t halt neurosym/play/strategies/minigrid_handwritten.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/tests/route_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/minigrid_handwritten.pl', Strategy),
   consult(Facts), consult(Route), consult(Strategy).

:- begin_tests(minigrid_handwritten).

% The door is locked and its key on the map: the key.
test(key_first) :-
    goal(10, 0, G), !, G == key_yellow.

% Holding the key, the door still locked: the door.
test(then_its_door) :-
    goal(10, 2, G), !, G == door_yellow.

% The door open: the goal.
test(then_the_goal) :-
    goal(10, 3, G), !, G == goal.

:- end_tests(minigrid_handwritten).
