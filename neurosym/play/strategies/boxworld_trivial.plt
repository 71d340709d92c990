/*  plunit tests of boxworld_trivial.pl, a strategy `neurosym play --compare` plays:
    its first answer on a state of rules/tests/route_facts.pl, with module
    route (rules/route.pl) loaded beside it as `neurosym play` loads it.

    swipl -g run_tests -t halt neurosym/play/strategies/boxworld_trivial.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/tests/route_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/boxworld_trivial.pl', Strategy),
   consult(Facts), consult(Route), consult(Strategy).

:- begin_tests(boxworld_trivial).

% the gem.
test(first_answer) :-
    goal(3, 0, G), G == gem.

:- end_tests(boxworld_trivial).
