/*  plunit tests of world_background_minigrid.pl: the background predicates
    Minigrid world rules are learned over, loaded beside a KB's state facts as
    a learned world.pl is (tests/world_minigrid_facts.pl, drawn there).

    swipl -g run_tests -t halt neurosym/induce/pl/world_background_minigrid.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/tests/world_minigrid_facts.pl', Facts),
   atom_concat(Dir, '/world_background_minigrid.pl', Background),
   consult(Facts), consult(Background).

:- begin_tests(world_background_minigrid).

test(action, [As == [0-pickup, 1-right, 2-forward, 3-left, 4-toggle]]) :-
    findall(T-A, action(0, T, A), As).

test(front, [Fs == [0-1-2, 1-1-2, 2-2-1, 3-3-1, 4-2-2]]) :-
    findall(T-R-C, front(0, T, R, C), Fs).

test(ahead, [Ws == [0-key(yellow), 1-empty, 2-empty, 3-wall, 4-door(yellow)]]) :-
    findall(T-W, ahead(0, T, W), Ws).

% Only a faced door has a state; state 5 has no step (the episode ended).
test(ahead_door, [Ss == [4-locked]]) :-
    findall(T-S, ahead_door(0, T, S), Ss).

test(carrying, [Cs == [0-nothing, 1-key(yellow), 2-key(yellow), 3-key(yellow), 4-key(yellow)]]) :-
    findall(T-C, carrying(0, T, C), Cs).

% carrying/3 called with its value bound: nothing only where the agent holds nothing
test(carrying_bound, [Ts == [0]]) :-
    findall(T, carrying(0, T, nothing), Ts).

test(carrying_bound_key, [Ts == [1, 2, 3, 4]]) :-
    findall(T, carrying(0, T, key(yellow)), Ts).

test(no_step_nothing_ahead, [fail]) :-
    ahead(0, 5, _).

:- end_tests(world_background_minigrid).
