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

test(optimal_visit_order, Os == [0, 1, 2, 3]) :-
    findall(E, optimal_visit_order(E, [sword, teleport, enemy, terminal]), Os).

test(off_optimal_order, Os == [1-[teleport, enemy, sword, terminal],
                               2-[sword, pit],
                               3-[sword, teleport, enemy]]) :-
    findall(E-V, off_optimal_order(E, V, _), Os).

% The order compared with is the level's own: rgw1's route (sword, enemy,
% terminal, no teleport) makes episode 3's visits the optimal ones.
test(optimal_order_of_the_level, [ setup(( user:retract(optimal_visits(3, Saved)),
                                           user:assertz(optimal_visits(3, [sword, teleport, enemy])) )),
                                   cleanup(( user:retractall(optimal_visits(3, _)),
                                             user:assertz(optimal_visits(3, Saved)) )),
                                   true(Es == [0, 3]) ]) :-
    findall(E, optimal_order(E), Es).

% A KB without optimal_visits/2 (recorded before it) answers no episode.
test(no_optimal_visits_no_answer, [ setup(( findall(E-O, user:optimal_visits(E, O), Saved),
                                            user:retractall(optimal_visits(_, _)) )),
                                    cleanup(forall(member(E-O, Saved),
                                                   user:assertz(optimal_visits(E, O)))),
                                    fail ]) :-
    optimal_order(_).

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

% The armed states: episode 0's 12, 1's 21 (its first meeting, at 7, was
% before the sword), 3's 9; episode 2 never meets the enemy.
test(armed_enemy_link_none, S == share(0, 3)) :-
    armed_enemy_link(S).

test(armed_enemy_link, [ setup(( user:assertz(holds(0, 12, r(4), enemy, agent)),
                                 user:assertz(holds(0, 12, r(5), agent, enemy)),
                                 user:assertz(holds(1, 7, r(4), agent, enemy)),
                                 user:assertz(attention(3, 9, 0, agent, enemy, 0.7)) )),
                         cleanup(( user:retract(holds(0, 12, r(4), enemy, agent)),
                                   user:retract(holds(0, 12, r(5), agent, enemy)),
                                   user:retract(holds(1, 7, r(4), agent, enemy)),
                                   user:retract(attention(3, 9, 0, agent, enemy, 0.7)) )),
                         true(S == share(2, 3)) ]) :-
    armed_enemy_link(S).

test(armed_enemy_link_needs_the_sword_in_hand,
     [ setup(( user:assertz(holds(0, 12, r(4), enemy, agent)),
               user:retract(holding(0, 12, sword)) )),
       cleanup(( user:retract(holds(0, 12, r(4), enemy, agent)),
                 user:assertz(holding(0, 12, sword)) )),
       true(S == share(0, 2)) ]) :-
    armed_enemy_link(S).

test(orders_sword_before_enemy, Rs == [r(1)]) :-
    findall(R, orders_sword_before_enemy(R), Rs).

test(sword_enemy_direct, Ls == [r(1), r(0)]) :-
    findall(L, sword_enemy_direct(L), Ls).

test(sword_enemy_via, Xs == [agent, teleport]) :-
    findall(X, sword_enemy_via(X), Xs).

% Shares are of the 124 states the agent acted in (14 + 23 + 7 + 40 + 40);
% r(1) and r(0) hold between sword and enemy on 4 states.
test(link_direct, A == direct([r(1), r(0)], share(4, 124))) :-
    sword_enemy_link(A).

test(link_indirect, [ setup(( saved_holds_(Saved),
                              forall(( member(holds(E, T, R, X, Y), Saved),
                                       msort([X, Y], [enemy, sword]) ),
                                     user:retract(holds(E, T, R, X, Y))) )),
                      cleanup(restore_holds_(Saved)),
                      true(A == indirect([via(agent, share(1, 124)),
                                          via(teleport, share(1, 124))])) ]) :-
    sword_enemy_link(A).

% rgw1's head 0: the agent with the sword on states 0-5, with the enemy on
% 12-19. The two links never meet in time: co-occurring, not indirect.
test(link_co_occurring, [ setup(( saved_holds_(Saved),
                                  user:retractall(holds(_, _, _, _, _)),
                                  forall(between(0, 5, T), user:assertz(holds(0, T, r(0), agent, sword))),
                                  forall(between(12, 19, T), user:assertz(holds(0, T, r(0), enemy, agent))) )),
                          cleanup(restore_holds_(Saved)),
                          true(A == co_occurring([apart(agent, share(6, 124), share(8, 124))])) ]) :-
    sword_enemy_link(A).

% Consecutive states of one episode carry the link; both states count.
test(link_consecutive_states, [ setup(( saved_holds_(Saved),
                                        user:retractall(holds(_, _, _, _, _)),
                                        user:assertz(holds(0, 5, r(0), agent, sword)),
                                        user:assertz(holds(0, 6, r(1), enemy, agent)) )),
                                cleanup(restore_holds_(Saved)),
                                true(A == indirect([via(agent, share(2, 124))])) ]) :-
    sword_enemy_link(A).

% Two states apart, or the same T in two episodes, is not consecutive.
test(link_not_consecutive, [ setup(( saved_holds_(Saved),
                                     user:retractall(holds(_, _, _, _, _)),
                                     user:assertz(holds(0, 5, r(0), agent, sword)),
                                     user:assertz(holds(0, 7, r(1), enemy, agent)),
                                     user:assertz(holds(1, 5, r(1), enemy, agent)) )),
                             cleanup(restore_holds_(Saved)),
                             true(A == co_occurring([apart(agent, share(1, 124), share(2, 124))])) ]) :-
    sword_enemy_link(A).

% Every state of a run of links counts once, whichever side it is on.
test(link_share_counts_states, [ setup(( saved_holds_(Saved),
                                         user:retractall(holds(_, _, _, _, _)),
                                         forall(between(0, 3, T), user:assertz(holds(1, T, r(0), agent, sword))),
                                         user:assertz(holds(1, 4, r(0), enemy, agent)),
                                         user:assertz(holds(1, 4, r(1), enemy, agent)),
                                         user:assertz(holds(1, 9, r(1), teleport, sword)),
                                         user:assertz(holds(1, 9, r(1), enemy, teleport)) )),
                                 cleanup(restore_holds_(Saved)),
                                 true(A == indirect([via(agent, share(2, 124)),
                                                     via(teleport, share(1, 124))])) ]) :-
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
