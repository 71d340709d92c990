/*  causal.plt -- plunit tests for causal.pl over the scenario files tests/causal_*_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/causal.plt

    Each test loads one scenario's facts (asserted from the file, the previous
    scenario's retracted first), so one run checks every answer.
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/causal.pl', Rules),
   consult(Rules),
   assertz(causal_test_dir_(Dir)).

:- dynamic causal_test_dir_/1.

load_scenario_(Name) :-
    forall(member(P, [experiment/3, measure/3, effect/3, relates/4]),
           ( P = F/A, functor(H, F, A), retractall(user:H) )),
    causal_test_dir_(Dir),
    format(atom(File), '~w/tests/causal_~w_facts.pl', [Dir, Name]),
    setup_call_cleanup(open(File, read, In),
                       assert_terms_(In),
                       close(In)).

assert_terms_(In) :-
    read_term(In, T, []),
    (   T == end_of_file
    ->  true
    ;   assertz(user:T),
        assert_terms_(In)
    ).

:- begin_tests(causal).

test(margin, M == 0.5) :-
    causal_margin(M).

test(correlational, A == correlational([meets_enemy_unarmed([measure(baseline, enemy_defeated, 1.0),
                                                             measure(swap_sword_enemy, enemy_unarmed, 1.0)])])) :-
    load_scenario_(correlational),
    sword_enemy_cause(A).

test(correlational_no_direct_evidence, [fail]) :-
    load_scenario_(correlational),
    direct_evidence(_).

test(direct_by_avoidance, A == direct([avoids_enemy_without_sword([measure(baseline, sword_before_enemy, 0.95),
                                                                   effect(remove_sword, enemy_met, -0.85)])])) :-
    load_scenario_(direct),
    sword_enemy_cause(A).

test(ablation_of_an_unrelated_head_is_no_evidence, Es == [avoids_enemy_without_sword]) :-
    load_scenario_(direct),
    findall(F, ( direct_evidence(E), functor(E, F, _) ), Es).

test(direct_by_ablation, A == direct([ablation_breaks_order([experiment(ablate_head_1, ablate(head(1))),
                                                             relates(1, enemy, sword, 0.3),
                                                             measure(baseline, sword_before_enemy, 0.8),
                                                             effect(ablate_head_1, sword_before_enemy, -0.7)])])) :-
    load_scenario_(ablation),
    sword_enemy_cause(A).

test(none, A == none) :-
    load_scenario_(none),
    sword_enemy_cause(A).

test(level_experiments, Xs == [baseline, remove_sword, swap_sword_enemy]) :-
    load_scenario_(correlational),
    findall(X, level_experiment(X, _), Xs).

:- end_tests(causal).
