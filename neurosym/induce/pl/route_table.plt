/*  plunit tests of route_table.pl: the route lengths of a trace's states
    that induce's route feature columns are built from, asserted and asked
    as neurosym/induce/strategy_route.py does (beside rules/route.pl, ids and
    types as the atoms janus makes of Python's strings).

    swipl -g run_tests -t halt neurosym/induce/pl/route_table.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/../../../rules/route.pl', Route),
   atom_concat(Dir, '/route_table.pl', Table),
   consult(Route), consult(Table).

%   The trace: episode 0 (2 x 4), state 0, and episode 1 (1 x 3), where a
%   wall cuts the terminal off.
%         c0 c1 c2 c3
%     r0   A  .  .  T          X teleport_1, Y teleport_2
%     r1   X  .  Y  .
%   state 1 of episode 0: the agent has gone from the map.
:- assert_trace([[terminal, terminal], [teleport_1, teleport], [teleport_2, teleport],
                 [key_red, 'key(red)']],
                [[0, 0, agent, 0, 0], [0, 0, terminal, 0, 3], [0, 0, teleport_1, 1, 0],
                 [0, 0, teleport_2, 1, 2], [0, 1, terminal, 0, 3],
                 [1, 0, agent, 0, 0], [1, 0, terminal, 0, 2]],
                [[1, wall, 0, 1]],
                [[0, 2, 4], [1, 1, 3]]).

:- begin_tests(route_table).

test(types_read_from_their_text, [Ts == [terminal-terminal, teleport_1-teleport,
                                         teleport_2-teleport, key_red-key(red)]]) :-
    findall(O-T, object(O, T), Ts).

test(facts_asserted, [Fs == [grid(0, 2, 4), grid(1, 1, 3)]-[terrain(1, wall, 0, 1)]-7]) :-
    findall(grid(E, R, C), grid(E, R, C), Gs),
    findall(terrain(E, Ty, R, C), terrain(E, Ty, R, C), Ts),
    aggregate_all(count, at(_, _, _, _, _), N),
    Fs = Gs-Ts-N.

% From the agent, and from each teleport end's cell (from an end's own cell
% to that end: out and back, 2); the unreachable terminal of episode 1 and
% the state without the agent give no rows.
test(trace_route, [Rows == [ 0-0-agent-teleport_1-1, 0-0-agent-teleport_2-3, 0-0-agent-terminal-3,
                             0-0-teleport_1-teleport_1-2, 0-0-teleport_1-teleport_2-2,
                             0-0-teleport_1-terminal-4,
                             0-0-teleport_2-teleport_1-2, 0-0-teleport_2-teleport_2-2,
                             0-0-teleport_2-terminal-2 ]]) :-
    findall(E-T-From-O-D, trace_route(E, T, From, O, D), Rows0),
    msort(Rows0, Rows).

test(forget_trace_forgets_the_searches, [Before-After == true-0]) :-
    once(trace_route(_, _, _, _, _)),
    ( route:searched_(0, _, _, _, _) -> Before = true ; Before = false ),
    forget_trace,
    aggregate_all(count, ( route:searched_(_, _, _, _, _) ; route:grid_(_, _, _, _) ), After).

:- end_tests(route_table).
