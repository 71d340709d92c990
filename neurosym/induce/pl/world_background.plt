/*  plunit tests of world_background.pl: the background predicates world
    rules are learned over, loaded beside a KB's state facts as a learned
    world.pl is (tests/world_facts.pl, drawn there).

    swipl -g run_tests -t halt neurosym/induce/pl/world_background.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/tests/world_facts.pl', Facts),
   atom_concat(Dir, '/world_background.pl', Background),
   consult(Facts), consult(Background).

:- begin_tests(world_background).

test(action_offsets, [Os == [up-(-1)-0, right-0-1, down-1-0, left-0-(-1)]]) :-
    findall(A-DR-DC, action_offset(A, DR, DC), Os).

test(target, [Ts == [0-(-1)-0, 1-0-2, 2-2-0, 3-1-1]]) :-
    findall(T-R-C, target(0, T, R, C), Ts).

test(ahead, [Ws == [0-border, 1-sword, 2-mountain, 3-wall]]) :-
    findall(T-W, ahead(0, T, W), Ws).

% Left of the sword's cell is the agent's own: empty (the agent is no object there).
test(left_of_ahead, [Ws == [0-border, 1-empty, 2-border, 3-empty]]) :-
    findall(T-W, left_of_ahead(0, T, W), Ws).

test(right_of_ahead, [Ws == [0-border, 1-border, 2-empty, 3-empty]]) :-
    findall(T-W, right_of_ahead(0, T, W), Ws).

test(cell_holds_each_cell_once, [Ws == [ (-1)-0-border, 0-0-empty, 0-1-empty, 0-2-sword,
                                         1-0-empty, 1-1-wall, 1-2-empty,
                                         2-0-mountain, 2-1-empty, 2-2-terminal, 3-3-border ]]) :-
    findall(R-C-W, ( member(R-C, [(-1)-0, 0-0, 0-1, 0-2, 1-0, 1-1, 1-2, 2-0, 2-1, 2-2, 3-3]),
                     cell_holds(0, 1, R, C, W) ), Ws).

test(on_map, [Ws == [sword, terminal]]) :-
    findall(W, on_map(0, 2, W), Ws).

test(no_step_no_target, [fail]) :-
    ahead(0, 4, _).

:- end_tests(world_background).
