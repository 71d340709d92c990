/*  meaning.plt -- plunit tests for meaning.pl over tests/meaning_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/meaning.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/meaning.pl', Rules),
   atom_concat(Dir, '/tests/meaning_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(meaning).

test(relation_means, Ps == [3-holding(sword), 3-visited(sword)]) :-
    findall(J-P, relation_means(r(J), P), Ps0),
    msort(Ps0, Ps).

test(not_selective_no_name, [fail]) :-
    relation_means(r(5), _).

test(relation_name, [nondet, true(P == holding(sword))]) :-
    relation_name(r(3), P, S),
    abs(S - 0.35) < 1e-9.

test(head_encodes, Ps == [adjacent(agent,sword)]) :-
    findall(P, head_encodes(1, P, _), Ps).

test(training_added, [nondet, true(abs(G - 0.25) < 1e-9)]) :-
    training_added(0, 3, holding(sword), G).

test(named_holds, Hs == [4-agent-sword]) :-
    findall(T-A-B, named_holds(0, T, holding(sword), A, B), Hs).

:- end_tests(meaning).
