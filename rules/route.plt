/*  route.plt -- plunit tests for route.pl over tests/route_facts.pl.

    Run from any directory:  swipl -g run_tests -t halt rules/route.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/route.pl', Rules),
   atom_concat(Dir, '/tests/route_facts.pl', Facts),
   consult(Facts),
   consult(Rules).

:- begin_tests(route).

% Straight on crosses the mountain (4 steps); around it takes 8 steps.
test(around_the_mountain, A-C == down-8) :-
    route(0, 0, sword, A, C).

% Down the left column, then along row 2: the pit at (3,0) and the
% teleport end at (3,2) are not entered.
test(avoids_pit_and_teleport, A-C == down-7) :-
    route(0, 0, terminal, A, C).

test(teleport_as_goal, A-C == down-5) :-
    route(0, 0, teleport_1, A, C).

% The enemy at (2,1) closes row 2 from the left: over the mountain instead.
test(unarmed_avoids_the_enemy, [true(A == right), true(C > 20)]) :-
    route(1, 0, terminal, A, C).

% Unarmed, meeting the enemy costs -1: no route to it.
test(no_route_to_an_enemy_unarmed, fail) :-
    route(1, 0, enemy, _).

test(no_route_into_a_pit, fail) :-
    route(0, 0, pit, _).

test(enemy_as_goal_armed, A-C == right-1) :-
    route(2, 1, enemy, A, C).

% The wall column closes the terminal off; entering the teleport end at
% (0,1) lands on (2,3). Up and right both reach it in 3 steps: up first.
test(through_the_teleport, A-C == up-6) :-
    route(4, 0, terminal, A, C).

test(teleport_end_as_goal, A-C == up-3) :-
    route(4, 0, teleport_1, A, C).

test(no_path_unarmed, fail) :-
    route(2, 0, terminal, _).

test(holding_the_sword_crosses_the_enemy, A-C == right-3) :-
    route(2, 1, terminal, A, C).

test(standing_on_the_goal, fail) :-
    route(2, 0, agent, _).

test(not_on_the_map, fail) :-
    route(0, 0, enemy, _).

test(distance, D == 8) :-
    route_distance(0, 0, sword, D).

% Box-World: the loose key at (0,2) and the gem at (0,3) block row 0; right
% and down tie at 6 steps, and right comes first.
test(boxworld_around_the_key, A-C == right-6) :-
    route(3, 1, lock_red, A, C).

test(boxworld_key_as_goal, A-C == right-2) :-
    route(3, 0, key_blue, A, C).

test(safe_step, A == right) :-
    safe_step(3, 0, A).

% In the 1 x 4 corridor the enemy holds the only neighbour.
test(safe_step_none, fail) :-
    safe_step(2, 0, _).

test(default_goal_sword_first, G == sword) :-
    default_goal(0, 0, G).

test(default_goal_enemy_when_armed, G == enemy) :-
    default_goal(2, 1, G).

test(default_goal_terminal, G == terminal) :-
    default_goal(4, 0, G).

test(default_goal_boxworld_lock, G == lock_red) :-
    default_goal(3, 1, G).

test(default_goal_boxworld_key, G == key_blue) :-
    default_goal(3, 0, G).

:- end_tests(route).
