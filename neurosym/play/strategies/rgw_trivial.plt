/*  plunit tests of rgw_trivial.pl, a strategy `neurosym play --compare` plays:
    its first answer on a state of rules/tests/route_facts.pl, with module
    route (rules/route.pl) loaded beside it as `neurosym play` loads it.

    swipl -g run_tests -t halt neurosym/play/strategies/rgw_trivial.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/tests/route_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/rgw_trivial.pl', Strategy),
   consult(Facts), consult(Route), consult(Strategy).

:- begin_tests(rgw_trivial).

% the terminal, whatever the state.
test(first_answer) :-
    goal(0, 0, G), G == terminal.

:- end_tests(rgw_trivial).
