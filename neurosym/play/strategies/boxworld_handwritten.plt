/*  plunit tests of boxworld_handwritten.pl, a strategy `neurosym play --compare` plays:
    its first answer on a state of rules/tests/route_facts.pl, with module
    route (rules/route.pl) loaded beside it as `neurosym play` loads it.

    swipl -g run_tests -t halt neurosym/play/strategies/boxworld_handwritten.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/tests/route_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/boxworld_handwritten.pl', Strategy),
   consult(Facts), consult(Route), consult(Strategy).

:- begin_tests(boxworld_handwritten).

% holding key(red), the lock whose box holds the gem.
test(first_answer) :-
    once(goal(3, 1, G)), G == lock_red.

:- end_tests(boxworld_handwritten).
