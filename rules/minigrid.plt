/*  minigrid.plt -- plunit tests for minigrid.pl over tests/minigrid_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/minigrid.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/minigrid.pl', Rules),
   atom_concat(Dir, '/tests/minigrid_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(minigrid_doors).

test(key_before_door_colours, Ps == [0-yellow, 4-blue, 4-red]) :-
    findall(E-C, key_before_door(E, C), Ps).

test(key_before_door, Es == [0, 4]) :-
    findall(E, key_before_door(E), Es).

test(carried_from_the_start_is_not_before, [fail]) :-
    key_before_door(5).

test(no_unlocking_no_answer, [fail]) :-
    key_before_door(3).

test(unlocked_with_key, Us == [0-4-door(yellow), 4-3-door(blue), 4-8-door(red),
                               5-2-door(purple)]) :-
    findall(E-T-D, unlocked_with_key(E, T, D), Us).

test(opens, Ps == [key(yellow)-door(yellow), key(blue)-door(blue), key(red)-door(red),
                   key(purple)-door(purple)]) :-
    findall(K-D, opens(K, D), Ps).

:- end_tests(minigrid_doors).

:- begin_tests(minigrid_missions).

test(mission_done, Es == [0, 1, 2, 3]) :-
    findall(E, mission_done(E), Es).

test(mission_done_text, M == 'pick up the red ball') :-
    mission_done(1, M).

test(mission_target, Ts == [1-pick_up-ball(red), 2-go_to-key(blue), 3-open-door(green),
                            5-go_to-box(red)]) :-
    findall(E-V-O, mission_target(E, V, O), Ts).

test(no_target_in_doorkey, [fail]) :-
    mission_target(0, _, _).

test(mission_shown, Es == [1, 2, 3]) :-
    findall(E, mission_shown(E), Es).

test(not_done_not_shown, [fail]) :-
    mission_shown(5).

:- end_tests(minigrid_missions).

:- begin_tests(minigrid_network).

test(key_door_link, Ls == [yellow-r(1), yellow-r(2), blue-attention(1)]) :-
    findall(C-L, key_door_link(C, L), Ls).

test(wrong_key_door_link, Ls == [key(red)-door(blue)-r(0)]) :-
    findall(K-D-L, wrong_key_door_link(K, D, L), Ls).

:- end_tests(minigrid_network).
