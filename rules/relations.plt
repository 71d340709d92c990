/*  relations.plt -- plunit tests for relations.pl over tests/relations_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/relations.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/relations.pl', Rules),
   atom_concat(Dir, '/tests/relations_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(relations).

test(heads, Hs == [0, 1]) :-
    findall(H, head(H), Hs).

test(head_pairs, Ps == [3-(sword-enemy), 1-(agent-sword)]) :-
    head_pairs(0, Ps).

test(head_pairs_det, Ps == [1-(enemy-sword)]) :-
    head_pairs(1, Ps).

test(head_top_pair, Tops == [0-sword-enemy-3, 1-enemy-sword-1]) :-
    findall(H-A-B-N, head_top_pair(H, A, B, N), Tops).

test(relation_stats, [true(S == [5, 0.1, -0.75, 1.0]), nondet]) :-
    relation_stats(0, N, Mean, Min, Max),
    S = [N, Mean, Min, Max].

test(relation_stats_all, Js == [0, 1]) :-
    findall(J, relation_stats(J, _, _, _, _), Js).

test(pair_strength, [true(N-M == 4-0.625), nondet]) :-
    pair_strength(0, sword, enemy, N, M).

test(pair_strength_reversed, [true(N-M == 4-(-0.625)), nondet]) :-
    pair_strength(0, enemy, sword, N, M).

test(pair_strength_no_self, [fail]) :-
    pair_strength(_, X, X, _, _).

test(held_count, [true(N == 2), nondet]) :-
    held_count(0, sword, enemy, N).

test(consistently_orders, Os == [0-sword-enemy, 0-sword-agent]) :-
    findall(J-A-B, consistently_orders(J, A, B), Os).

test(not_consistent_when_both_ways, [fail]) :-
    consistently_orders(1, _, _).

test(order_support, [true(F-A == 2-1), nondet]) :-
    order_support(1, sword, enemy, F, A).

test(strongest_pairs, Top == [held(0, sword, enemy, 2), held(1, sword, enemy, 2), held(0, sword, agent, 1)]) :-
    strongest_pairs(3, Top).

test(strongest_pairs_short, Top == [held(0, sword, enemy, 2)]) :-
    strongest_pairs(1, Top).

test(mhdpa_heads, [ setup(user:assertz(attention(0, 0, 3, agent, sword, 0.75))),
                    cleanup(user:retractall(attention(_, _, _, _, _, _))),
                    true(X == [0, 1, 3]) ]) :-
    findall(H, head(H), X).

test(mhdpa_pairs, [ setup(( user:assertz(attention(0, 0, 3, agent, sword, 0.75)),
                            user:assertz(attention(0, 1, 3, agent, sword, 0.5)) )),
                    cleanup(user:retractall(attention(_, _, _, _, _, _))),
                    true(Ps == [2-(agent-sword)]) ]) :-
    head_pairs(3, Ps).

test(entity_link_direct, A == direct([r(0), r(1)], share(2, 4))) :-
    entity_link(sword, enemy, A).

test(entity_link_one_way_round, A == direct([r(0)], share(1, 4))) :-
    entity_link(agent, sword, A).

test(entity_link_none, A == none) :-
    entity_link(agent, enemy, A).

:- end_tests(relations).
