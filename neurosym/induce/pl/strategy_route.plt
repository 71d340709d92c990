/*  plunit tests of strategy_route.pl: a learned strategy's route features,
    loaded as `neurosym play` loads a strategy (after the KB, beside
    rules/route.pl, after strategy_features.pl's text), over the
    hand-written states of tests/strategy_facts.pl (drawn there).

    swipl -g run_tests -t halt neurosym/induce/pl/strategy_route.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/tests/strategy_facts.pl', Facts),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/strategy_features.pl', Features),
   atom_concat(Dir, '/strategy_route.pl', Routes),
   consult(Facts), consult(Route), consult(Features), consult(Routes).

:- begin_tests(strategy_route).

% Episode 0, state 0: the wall column cuts the terminal and the enemy off.
test(route_length, [Ds == [enemy-999, sword-1, teleport_1-2, teleport_2-999, terminal-999]]) :-
    findall(O-D, ( goal_candidate(0, 0, O), route_length(0, 0, O, D) ), Ds).

test(route_from_a_cell, [Ds == [enemy-1, sword-999, teleport_1-999, terminal-3]]) :-
    findall(O-D, ( member(O, [enemy, sword, teleport_1, terminal]),
                   route_from_(0, 0, 2-3, O, D) ), Ds).

test(reachable, [Os == [sword, teleport_1]]) :-
    findall(O, ( goal_candidate(0, 0, O), reachable(0, 0, O) ), Os).

test(reachable_kind, [Ks == [sword, teleport]]) :-
    findall(K, ( member(K, [enemy, sword, teleport, terminal]), reachable_kind(0, 0, K) ), Ks).

test(nearest_reachable_of_kind, [Os == [sword, teleport_1]]) :-
    findall(O, ( goal_candidate(0, 0, O), nearest_reachable_of_kind(0, 0, O) ), Os).

% sword (1) is nearer than teleport_1 (2); no terminal is reachable.
test(route_not_longer, [Ps == [sword-teleport, sword-terminal, teleport_1-terminal]]) :-
    findall(O-K, ( member(O, [sword, teleport_1]), member(K, [sword, teleport, terminal]),
                   O \== K, \+ object_kind(O, K), route_not_longer(0, 0, O, K) ), Ps).

test(route_not_longer_of_an_unreachable_object, [fail]) :-
    route_not_longer(0, 0, terminal, sword).

% Into teleport_1 (2 moves), out of teleport_2: the enemy (1) and the
% terminal (3), which no route without the teleport reaches.
test(teleport_shortcut, [Ks == [enemy, terminal]]) :-
    findall(K, ( member(K, [enemy, sword, terminal]), teleport_shortcut(0, 0, teleport_1, K) ), Ks).

test(teleport_end_out_of_reach_is_no_shortcut, [fail]) :-
    teleport_shortcut(0, 0, teleport_2, _).

test(teleport_shortcut_to, [Ks == [enemy, terminal]]) :-
    findall(K, ( member(K, [enemy, sword, teleport, terminal]), teleport_shortcut_to(0, 0, K) ), Ks).

% Episode 2: 1 move into teleport_1, 2 from teleport_2 to the terminal, 3
% without: as long, so not a shortcut, but not longer.
test(teleport_as_long_is_no_shortcut, [fail]) :-
    teleport_shortcut(2, 0, teleport_1, terminal).

test(teleport_not_longer, [true]) :-
    teleport_not_longer(2, 0, teleport_1, terminal).

% Into teleport_2 (3 moves), out of teleport_1 (4 more): longer than 3.
test(teleport_not_longer_than_a_shorter_route, [fail]) :-
    teleport_not_longer(2, 0, teleport_2, terminal).

:- end_tests(strategy_route).
