/*  plunit tests of minigrid_trivial.pl, a strategy `neurosym play --compare`
    plays: its first answer on a Minigrid state of rules/tests/route_facts.pl,
    with module route (rules/route.pl) loaded beside it as `neurosym play`
    loads it.

    swipl -g run_tests -t halt neurosym/play/strategies/minigrid_trivial.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/tests/route_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/minigrid_trivial.pl', Strategy),
   consult(Facts), consult(Route), consult(Strategy).

:- begin_tests(minigrid_trivial).

% the goal, whatever the state.
test(first_answer) :-
    goal(10, 0, G), G == goal.

:- end_tests(minigrid_trivial).
