/*  route.plt -- plunit tests for module route (route.pl) over tests/route_facts.pl,
    loaded as a user would: the facts in user, then the module.

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

% route_moves/4,5: moves of a contact-free path; a mountain is one move.
test(moves_over_the_mountain, D == 4) :-
    route_moves(0, 0, sword, D).

test(moves_past_pit_and_teleport, D == 7) :-
    route_moves(0, 0, terminal, D).

% The sword's cell may be crossed; route/4 takes the sword as an object.
test(moves_cross_the_sword, D == 3) :-
    route_moves(5, 0, terminal, D).

% An enemy blocks a contact-free path, even when the agent holds the sword.
test(moves_blocked_by_the_enemy, D-D1 == 999-999) :-
    route_moves(2, 0, terminal, D),
    route_moves(2, 1, terminal, D1).

test(moves_boxworld_around_the_key, D == 6) :-
    route_moves(3, 1, lock_red, D).

% The wall column closes the terminal off: no teleport jump in a count.
test(moves_unreachable, D == 999) :-
    route_moves(4, 0, terminal, D).

test(moves_not_on_the_map, D == 999) :-
    route_moves(0, 0, enemy, D).

test(moves_from_a_teleport_end, D == 3) :-
    route_moves(4, 0, 2-3, terminal, D).

% The searches of the state last asked are remembered until route_forget/1:
% a wall added later is seen only after it.
test(moves_remembered_until_forgotten,
     [ true(D0-D1-D2 == 3-3-999),
       cleanup(( retractall(user:terrain(5, wall, 0, 2)), route_forget(5) ))]) :-
    route_moves(5, 0, terminal, D0),
    assertz(user:terrain(5, wall, 0, 2)),
    route_moves(5, 0, terminal, D1),
    route_forget(5),
    route_moves(5, 0, terminal, D2).

% A route with mountains (Dijkstra's search) and one without (the
% breadth-first search) asked in the same state, then again: the same answers.
test(routes_remembered_in_a_state, Answers == [down-8, down-7, down-8, down-7]) :-
    route_forget(0),
    route(0, 0, sword, A1, C1),
    route(0, 0, terminal, A2, C2),
    route(0, 0, sword, A3, C3),
    route(0, 0, terminal, A4, C4),
    Answers = [A1-C1, A2-C2, A3-C3, A4-C4].

% What route remembers lives in module route: facts named like its memos
% where the KB's facts are (here user) do not change an answer
% (tests/route_facts.pl holds some from the start).
test(kb_facts_cannot_reach_the_memos,
     [ true(Answers == [7, down-7, 4, down-8]),
       setup(( route_forget(0),
              assertz(user:searched_(0, 1, _, _, _)),
              assertz(user:grid_(0, 1, 1, cells(wall))),
              assertz(user:cache_key_(routes, nowhere)) )),
      cleanup(( retractall(user:searched_(_, _, _, _, _)),
                retractall(user:grid_(_, _, _, _)),
                retractall(user:cache_key_(_, _)),
                route_forget(0) ))]) :-
    route_moves(0, 0, terminal, D1),
    route(0, 0, terminal, A1, C1),
    route_moves(0, 0, sword, D2),
    route(0, 0, sword, A2, C2),
    Answers = [D1, A1-C1, D2, A2-C2].

% Its helpers stay inside the module: the user sees only the exports.
test(exports_only, Visible == [default_goal/3, route/4, route/5, route_distance/4,
                               route_exists/3, route_forget/1, route_moves/4,
                               route_moves/5, safe_step/3]) :-
    findall(N/A, ( predicate_property(user:H, imported_from(route)),
                   functor(H, N, A) ), Visible0),
    sort(Visible0, Visible).

% Minigrid (episode 10): a route over (cell, direction) states. Facing north,
% one right turn and one step forward face the key: then pickup (cost 3).
test(minigrid_turn_then_forward, A-C == right-3) :-
    route(10, 0, key_yellow, A, C).

test(minigrid_pickup_facing_a_key, A-C == pickup-1) :-
    route(10, 1, key_yellow, A, C).

% The wall and the key close the short ways: down the left column (two
% turns, the tie going to left), along the bottom row, a left turn to face
% the door from below, then toggle: 8 actions and the toggle.
test(minigrid_around_to_the_door, A-C == left-9) :-
    route(10, 0, door_yellow, A, C).

test(minigrid_toggle_facing_a_locked_door, A-C == toggle-1) :-
    route(10, 2, door_yellow, A, C).

test(minigrid_forward_into_an_open_door, A-C == forward-1) :-
    route(10, 3, door_yellow, A, C).

test(minigrid_turn_to_the_goal, A-C == right-2) :-
    route(10, 3, goal, A, C).

% The locked door blocks: the only way to the goal is round the left and
% bottom (the agent at (0,0) facing north).
test(minigrid_goal_around, A-C == left-8) :-
    route(10, 0, goal, A, C).

% Ahead is off the grid: a left turn, never a move of RGW's.
test(minigrid_safe_step, A == left) :-
    safe_step(10, 0, A).

test(minigrid_default_goal_key, G == key_yellow) :-
    default_goal(10, 0, G).

test(minigrid_default_goal_door_with_its_key, G == door_yellow) :-
    default_goal(10, 2, G).

test(minigrid_default_goal_goal_once_open, G == goal) :-
    default_goal(10, 3, G).

:- end_tests(route).
