/*  rgw.plt -- plunit tests for rgw.pl over tests/rgw_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/rgw.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/rgw.pl', Rules),
   atom_concat(Dir, '/tests/rgw_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(rgw_behaviour).

test(sword_before_enemy, Es == [0, 3]) :-
    findall(E, sword_before_enemy(E), Es).

test(sword_before_enemy_bound, nondet) :-
    sword_before_enemy(0).

test(enemy_met_before_sword, [fail]) :-
    sword_before_enemy(1).

test(no_enemy_no_answer, [fail]) :-
    sword_before_enemy(2).

test(teleport_before_enemy, Es == [0, 1, 3]) :-
    findall(E, teleport_before_enemy(E), Es).

test(enemy_beaten_with_sword, Es == [0, 1, 3]) :-
    findall(E, enemy_beaten_with_sword(E), Es).

test(beaten_needs_the_sword_in_hand, [ setup(user:retract(holding(3, 9, sword))),
                                       cleanup(user:assertz(holding(3, 9, sword))),
                                       true(Es == [0, 1]) ]) :-
    findall(E, enemy_beaten_with_sword(E), Es).

test(visit_order, Order == [sword, teleport, enemy, terminal]) :-
    visit_order(0, Order).

test(visit_order_first_visits_only, Order == [teleport, enemy, sword, terminal]) :-
    visit_order(1, Order).

test(visit_order_all, Os == [0-[sword, teleport, enemy, terminal],
                             1-[teleport, enemy, sword, terminal],
                             2-[sword, pit],
                             3-[sword, teleport, enemy],
                             4-[]]) :-
    findall(E-O, visit_order(E, O), Os).

test(optimal_order, Es == [0]) :-
    findall(E, optimal_order(E), Es).

% The rules look events up by episode only: after running all of them,
% SWI-Prolog's just-in-time indexes on event/3 are on the first argument alone.
test(event_indexed_on_the_episode_only, Kinds == [single(1)]) :-
    forall(member(G, [sword_before_enemy(_), teleport_before_enemy(_),
                      enemy_beaten_with_sword(_), visit_order(_, _)]),
           forall(G, true)),
    predicate_property(user:event(_, _, _), indexed(Indexes)),
    findall(K, member(K-_, Indexes), Kinds).

:- end_tests(rgw_behaviour).

:- begin_tests(rgw_network).

test(orders_sword_before_enemy, Rs == [r(1)]) :-
    findall(R, orders_sword_before_enemy(R), Rs).

test(sword_enemy_direct, Ls == [r(1), r(0)]) :-
    findall(L, sword_enemy_direct(L), Ls).

test(sword_enemy_via, Xs == [agent, teleport]) :-
    findall(X, sword_enemy_via(X), Xs).

test(link_direct, A == direct([r(1), r(0)])) :-
    sword_enemy_link(A).

test(link_indirect, [ setup(( saved_holds_(Saved),
                              forall(( member(holds(E, T, R, X, Y), Saved),
                                       msort([X, Y], [enemy, sword]) ),
                                     user:retract(holds(E, T, R, X, Y))) )),
                      cleanup(restore_holds_(Saved)),
                      true(A == indirect([agent, teleport])) ]) :-
    sword_enemy_link(A).

test(link_none, [ setup(( saved_holds_(Saved), user:retractall(holds(_, _, _, _, _)) )),
                  cleanup(restore_holds_(Saved)),
                  true(A == none) ]) :-
    sword_enemy_link(A).

test(mhdpa_direct, [ setup(user:assertz(attention(4, 2, 3, enemy, sword, 0.5))),
                     cleanup(user:retractall(attention(_, _, _, _, _, _))),
                     true(Ls == [r(1), r(0), attention(3)]) ]) :-
    findall(L, sword_enemy_direct(L), Ls).

% The KB's holds/5 facts, in order, and putting exactly those back.
saved_holds_(Saved) :-
    findall(holds(E, T, R, A, B), user:holds(E, T, R, A, B), Saved).

restore_holds_(Saved) :-
    user:retractall(holds(_, _, _, _, _)),
    forall(member(F, Saved), user:assertz(F)).

:- end_tests(rgw_network).
