/*  plunit tests of strategy_features.pl: the world and network features a
    learned strategy's clauses call, over the hand-written states of
    tests/strategy_facts.pl (drawn there).

    swipl -g run_tests -t halt neurosym/induce/pl/strategy_features.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/tests/strategy_facts.pl', Facts),
   atom_concat(Dir, '/strategy_features.pl', Features),
   consult(Facts), consult(Features).

:- begin_tests(strategy_features).

% --- kinds ------------------------------------------------------------------

test(goal_candidates_in_id_order, [Os == [gem, key_blue, key_green, key_red, lock_blue, lock_red]]) :-
    findall(O, goal_candidate(1, 0, O), Os).

test(goal_candidates_leave_out_the_agent_and_what_is_gone,
     [Os == [enemy, teleport_1, teleport_2, terminal]]) :-
    findall(O, goal_candidate(0, 1, O), Os).

test(object_kind, [Ks == [sword, teleport, key, lock, gem]]) :-
    findall(K, ( member(O, [sword, teleport_2, key_red, lock_blue, gem]), object_kind(O, K) ), Ks).

test(object_colour, [Cs == [red, blue]]) :-
    findall(C, ( member(O, [lock_red, key_blue, gem, sword]), object_colour(O, C) ), Cs).

test(holding_kind, [Ks == [sword]-[key]-[]]) :-
    findall(K, holding_kind(0, 1, K), K1),
    findall(K, holding_kind(1, 1, K), K2),
    findall(K, holding_kind(1, 0, K), K3),
    Ks = K1-K2-K3.

test(on_map, [Ks == [gem, key, lock]]) :-
    findall(K, ( member(K, [gem, key, lock, sword, teleport]), on_map(1, 0, K) ), Ks).

% --- distances --------------------------------------------------------------

test(agent_distance, [Ds == [4, 5, 2]]) :-
    findall(D, ( member(O, [gem, key_red, key_green]), agent_distance(1, 0, O, D) ), Ds).

test(agent_distance_of_an_object_not_on_the_map, [fail]) :-
    agent_distance(0, 1, sword, _).

test(nearest_of_kind_keeps_ties, [Os == [key_blue, key_green, lock_red]]) :-
    findall(O, ( goal_candidate(1, 0, O), object_kind(O, K), K \== gem,
                 nearest_of_kind(1, 0, O) ), Os).

test(nearest_object, [Os == [key_blue, key_green]]) :-
    findall(O, ( goal_candidate(1, 0, O), nearest_object(1, 0, O) ), Os).

% --- Box-World: keys, locks and boxes --------------------------------------

test(lock_of_held_key, [Ls == [lock_blue]]) :-
    findall(L, ( goal_candidate(1, 1, L), lock_of_held_key(1, 1, L) ), Ls).

test(lock_of_held_key_holding_nothing, [fail]) :-
    lock_of_held_key(1, 0, lock_blue).

test(key_fits_lock, [Ks == [key_blue, key_red]]) :-
    findall(K, ( goal_candidate(1, 0, K), key_fits_lock(1, 0, K) ), Ks).

test(loose_keys, [Ks == [key_blue, key_green]]) :-
    findall(K, ( goal_candidate(1, 0, K), loose(1, 0, K) ), Ks).

test(box_content, [Xs == [lock_blue-key_red, lock_red-gem]]) :-
    findall(L-X, ( goal_candidate(1, 0, L), box_content(1, 0, L, X) ), Xs).

test(box_holds_gem, [Ls == [lock_red]]) :-
    findall(L, ( goal_candidate(1, 0, L), box_holds_gem(1, 0, L) ), Ls).

test(box_holds_useful_key, [Ls == [lock_blue]]) :-
    findall(L, ( goal_candidate(1, 0, L), box_holds_useful_key(1, 0, L) ), Ls).

% --- the network's relations ------------------------------------------------

test(attended_by, [HAs == [sword-(1-1), terminal-(1-2)]]) :-
    findall(O-(H-A), ( goal_candidate(0, 0, O), attended_by(0, 0, H, A, O) ), HAs).

test(related, [Js == [enemy-(3-2), sword-(3-1)]]) :-
    findall(O-(J-P), ( goal_candidate(0, 0, O), related(0, 0, J, P, O) ), Js).

test(agent_query_attends, [Hs == [terminal-2]]) :-
    findall(O-H, ( goal_candidate(0, 0, O), agent_query_attends(0, 0, H, O) ), Hs).

test(query_attends_agent, [Hs == [enemy-2]]) :-
    findall(O-H, ( goal_candidate(0, 0, O), query_attends_agent(0, 0, H, O) ), Hs).

test(attending_queries, [Ns == [enemy-0, sword-0, terminal-2]]) :-
    findall(O-N, ( member(O, [enemy, sword, terminal]), attending_queries(0, 0, 2, O, N) ), Ns).

:- end_tests(strategy_features).
