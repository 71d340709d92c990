/*  boxworld.plt -- plunit tests for boxworld.pl over tests/boxworld_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/boxworld.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/boxworld.pl', Rules),
   atom_concat(Dir, '/tests/boxworld_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(boxworld_map).

test(boxes, Bs == [lock(red)-key(blue), lock(blue)-gem, lock(red)-key(green)]) :-
    findall(L-X, box(0, L, X), Bs).

test(loose_key, Ks == [0-key(red), 1-key(red), 2-key(yellow)]) :-
    findall(E-K, loose_key(E, K), Ks).

test(solution_chain, [true(C == [key(red), key(blue), gem]), nondet]) :-
    solution_chain(0, C).

test(solution_chains, Cs == [0-[key(red), key(blue), gem],
                             1-[key(red), key(blue), gem],
                             2-[key(yellow), gem]]) :-
    findall(E-C, solution_chain(E, C), Cs).

test(distractor_box, Ds == [0-lock(red)-key(green), 1-lock(red)-key(green)]) :-
    findall(E-L-X, distractor_box(E, L, X), Ds).

test(no_distractor_in_episode_2, [fail]) :-
    distractor_box(2, _, _).

:- end_tests(boxworld_map).

:- begin_tests(boxworld_trace).

test(key_opens, Ps == [key(red)-lock(red), key(blue)-lock(blue)]) :-
    findall(K-L, key_opens(K, L), Ps).

test(got_order, Os == [0-[key(red), key(blue), gem], 1-[key(red), key(green)], 2-[]]) :-
    findall(E-O, got_order(E, O), Os).

test(gem_chain, Cs == [0-[key(red), key(blue), gem]]) :-
    findall(E-C, gem_chain(E, C), Cs).

test(followed_solution, Es == [0]) :-
    findall(E, followed_solution(E), Es).

test(distractor_taken, Es == [1]) :-
    findall(E, distractor_taken(E), Es).

test(distractor_avoided, Es == [0]) :-
    findall(E, distractor_avoided(E), Es).

:- end_tests(boxworld_trace).

:- begin_tests(boxworld_network).

% Shares are of the 317 states the agent acted in (12 + 5 + 300).
test(key_lock_link, Ls == [blue-direct([r(2)], share(1, 317)),
                           red-direct([r(1)], share(1, 317)),
                           yellow-none]) :-
    findall(C-L, key_lock_link(C, L), Ls).

% The held key and the loose key are one key: held(yellow) beside the agent
% at state 3 and the agent beside lock(yellow) at state 4 link them through
% the agent, on both states.
test(key_lock_link_through_the_agent,
     [ setup(( user:assertz(holds(2, 3, r(0), held(yellow), agent)),
               user:assertz(holds(2, 4, r(1), agent, lock(yellow))) )),
       cleanup(( user:retract(holds(2, 3, r(0), held(yellow), agent)),
                 user:retract(holds(2, 4, r(1), agent, lock(yellow))) )),
       true(A == indirect([via(agent, share(2, 317))])) ]) :-
    key_lock_link(yellow, A).

test(wrong_key_lock_link, Ws == [held(red)-lock(green)-r(0)]) :-
    findall(K-L-R, wrong_key_lock_link(K, L, R), Ws).

test(mhdpa_link, [ setup(user:assertz(attention(0, 3, 2, held(yellow), lock(yellow), 0.5))),
                   cleanup(user:retractall(attention(_, _, _, _, _, _))),
                   true(A == direct([attention(2)], share(1, 317))) ]) :-
    key_lock_link(yellow, A).

test(attends_matching_lock, As == [0-4-1]) :-
    findall(E-T-H, attends_matching_lock(E, T, H), As).

test(attends_other_colour_is_no_match, [fail]) :-
    attends_matching_lock(0, 12, _).

test(matching_lock_rate, A-N == 1-5) :-
    matching_lock_rate(A, N).

:- end_tests(boxworld_network).
