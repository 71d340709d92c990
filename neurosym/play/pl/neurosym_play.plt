/*  plunit tests of neurosym_play.pl, the Prolog agent's side of `neurosym play`:
    its decisions on small hand-written states, their fallbacks, the
    strategy errors it reports, and the strategy files and calls it refuses.

    swipl -g run_tests -t halt neurosym/play/pl/neurosym_play.plt

A KB module is set up as neurosym/play/agent.py sets one up: the state
predicates dynamic, module route (rules/route.pl) loaded for it by the janus
bridge's load/6 (a copy, route@KB, that reads the KB's facts), the strategy
(tests/play_strategy.pl) loaded into it as code, then guard/1. Values are passed as janus passes
them: atoms, numbers, lists, a compound as -('$t', Name, Args).
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/neurosym_play.pl', Play),
   atom_concat(Dir, '/../../prolog/pl/bridge.pl', Bridge),
   use_module(Play),
   use_module(Bridge, [load/6]).

:- begin_tests(neurosym_play).

:- use_module(library(lists), [member/2]).

c_stack(16777216).

dir(Dir) :- source_file(dir(_), File), file_directory_name(File, Dir).

%   kb(+M, +Strategy, +Guard): KB module M with route.pl and, when Strategy
%   is true, the strategy (checked first), guarded when Guard is true.
kb(M, Strategy, Guard) :-
    set_module(M:class(temporary)),
    set_module(M:base(system)),
    forall(member(PI, [at/5, object/2, holding/3, terrain/4, grid/3, step/4, event/3,
                       holds/5, attends/8, attention/6]),
           dynamic(M:PI)),
    dir(Dir),
    atom_concat(Dir, '/../../../rules/route.pl', Route),
    format(atom(Id), "~w#~w", [Route, M]),
    c_stack(CStack0),
    load(M, Id, Route, rules, CStack0, []),
    (   Strategy == true
    ->  atom_concat(Dir, '/tests/play_strategy.pl', File),
        c_stack(CStack),
        check_policy(M, File, CStack, none),
        load_into(M, File)
    ;   true
    ),
    (   Guard == true -> guard(M) ; true ).

%   load_into(+M, +File): File loaded into M under a source id of its own
%   (File#M), as the bridge loads a file into each KB that names it.
load_into(M, File) :-
    format(atom(Id), "~w#~w", [File, M]),
    setup_call_cleanup(open(File, read, S, [encoding(utf8)]),
                       load_files(M:Id, [stream(S), silent(true)]),
                       close(S)).

:- kb(plt_play_kb, true, true).
:- kb(plt_play_unguarded, true, false).
:- kb(plt_play_policy, false, false).     % route.pl only, as when check_policy/4 runs

objects([[terminal, terminal], [sword, sword], [key_red, -('$t', key, [red])]]).

%   episode(+E, -Terrain, -Grid, -Ats): the hand-written maps.
%     0: A . . T      1: S . A      2: A W T      3: A W T
%                                     . . W
episode(0, [], [1, 4], [[agent, 0, 0], [terminal, 0, 3]]).
episode(1, [], [1, 3], [[sword, 0, 0], [agent, 0, 2]]).
episode(2, [[wall, 0, 1], [wall, 1, 2]], [2, 3], [[agent, 0, 0], [terminal, 0, 2]]).
episode(3, [[wall, 0, 1]], [1, 3], [[agent, 0, 0], [terminal, 0, 2]]).

%   decide_(+M, +E, +T, +Seen, -Out): begin episode E (state 0) and decide in state T.
decide_(M, E, T, Seen, Out) :-
    decide_(M, E, T, Seen, default, Out).

decide_(M, E, T, Seen, Fallback, Out) :-
    objects(Os),
    (   episode(E, Terrain, Grid, Ats) -> true ; Terrain = [], Grid = [1, 1], Ats = [] ),
    end_episode(M, E),
    begin_episode(M, E, Os, Terrain, Grid),
    decide(M, E, T, [Ats, []], [], [], 100000, Seen, Fallback, Out0),
    trimmed(Out0, Out).

%   trimmed(+Out0, -Out): an error line without the space message_to_codes_/2
%   leaves at its end (Python splits the line into words anyway).
trimmed(error-Text0, Out) :- !, split_string(Text0, "", " ", [Text]), Out = error-Text.
trimmed(Out, Out).

guarded(M, N) :- clause(M:N, neurosym_play:refused_(N/0)).

% --- decisions and fallbacks ---------------------------------------------

test(goal_and_route, [Out == [strategy, none, terminal, right]]) :-
    decide_(plt_play_kb, 0, 0, false, Out).

test(no_goal_falls_back_to_the_default_goal, [Out == [default_goal, no_goal, sword, left]]) :-
    decide_(plt_play_kb, 1, 0, false, Out).

test(no_route_falls_back_to_a_safe_step, [Out == [safe_step, no_route, terminal, down]]) :-
    decide_(plt_play_kb, 2, 0, false, Out).

test(nowhere_safe_falls_back_to_up, [Out == [up, no_route, terminal, up]]) :-
    decide_(plt_play_kb, 3, 0, false, Out).

test(a_state_seen_before_goes_to_the_fallback, [Out == [default_goal, loop, terminal, right]]) :-
    decide_(plt_play_kb, 0, 0, true, Out).

% Fallback none: what the strategy left undecided is not decided.
test(fallback_none, [Outs == [[strategy, none, terminal, right], [none, no_goal, none, none],
                              [none, no_route, terminal, none], [none, loop, none, none]]]) :-
    findall(Out, ( member(E-Seen, [0-false, 1-false, 2-false, 0-true]),
                   decide_(plt_play_kb, E, 0, Seen, none, Out) ),
            Outs).

% decide_all/5: the running episodes of a step in one call, in order.
test(decide_all, [Outs == [[strategy, none, terminal, right], [default_goal, no_goal, sword, left]]]) :-
    M = plt_play_kb,
    objects(Os),
    forall(member(E, [20, 21]), begin_episode(M, E, Os, [], [1, 4])),
    decide_all(M, [[20, 0, [[[agent, 0, 0], [terminal, 0, 3]], []], [], [], false],
                   [21, 0, [[[agent, 0, 2], [sword, 0, 0]], []], [], [], false]],
               100000, default, Outs).

% --- facts asserted and retracted ----------------------------------------

test(begin_episode_asserts_objects_once, [Os-Gs-Ts == [terminal-terminal, sword-sword, key_red-key(red)]
                                                      -[2-3]-[wall-0-1, wall-1-2]]) :-
    M = plt_play_kb,
    objects(Os0),
    begin_episode(M, 2, Os0, [[wall, 0, 1], [wall, 1, 2]], [2, 3]),
    begin_episode(M, 2, Os0, [], [2, 3]),
    findall(O-T, M:object(O, T), Os),
    findall(R-C, M:grid(2, R, C), Gs0), sort(Gs0, Gs),
    findall(Ty-R-C, M:terrain(2, Ty, R, C), Ts0), sort(Ts0, Ts).

test(decide_asserts_the_state_the_transition_and_the_extra,
     [Fs == [at(10, 1, agent, 0, 1)]-[holding(10, 1, key(red))]-[step(10, 0, right, -0.1)]
            -[event(10, 0, picked(key(red)))]-[holds(10, 1, r(2), sword, terminal)]]) :-
    M = plt_play_kb,
    objects(Os),
    begin_episode(M, 10, Os, [], [1, 2]),
    decide(M, 10, 1, [[[agent, 0, 1]], [-('$t', key, [red])]],
           [right, -0.1, [-('$t', picked, [-('$t', key, [red])])]],
           [-('$t', holds, [10, 1, -('$t', r, [2]), sword, terminal])], 100000, false, default, _),
    findall(at(10, T, I, R, C), M:at(10, T, I, R, C), As),
    findall(holding(10, T, I), M:holding(10, T, I), Hs),
    findall(step(10, T, A, W), M:step(10, T, A, W), Ss),
    findall(event(10, T, V), M:event(10, T, V), Vs),
    findall(holds(10, T, J, A, B), M:holds(10, T, J, A, B), Xs),
    Fs = As-Hs-Ss-Vs-Xs.

test(extra_other_than_the_network_facts_refused, [fail]) :-
    M = plt_play_kb,
    decide(M, 11, 0, [[], []], [], [-('$t', at, [11, 0, terminal, 0, 0])], 100000, false, default, _).

test(extra_refused_is_not_asserted, [fail]) :-
    M = plt_play_kb,
    \+ decide(M, 11, 0, [[], []], [], [-('$t', at, [11, 0, terminal, 0, 0])], 100000, false, default, _),
    M:at(11, 0, terminal, _, _).

test(end_episode_retracts_the_episode_but_not_object, [Left == []-[]-[]-3]) :-
    M = plt_play_kb,
    decide_(M, 12, 0, false, _),
    objects(Os),
    decide(M, 12, 1, [[[agent, 0, 0]], [sword]], [up, 0.0, [-('$t', picked, [sword])]],
           [-('$t', attention, [12, 1, 0, agent, sword, 0.5])], 100000, false, default, _),
    predicate_property(M:route(_, _, _, _), imported_from(R)),
    M:route_moves(12, 1, 0-0, terminal, _),
    R:grid_(12, _, _, _),                    % route remembered the episode's terrain
    end_episode(M, 12),
    findall(x, M:at(12, _, _, _, _), A),
    findall(x, ( M:step(12, _, _, _) ; M:event(12, _, _) ; M:holding(12, _, _)
               ; M:grid(12, _, _) ; M:attention(12, _, _, _, _, _) ), B),
    findall(x, R:grid_(12, _, _, _), C),
    aggregate_all(count, M:object(_, _), N),
    length(Os, N),
    Left = A-B-C-N.

% --- a strategy's errors ---------------------------------------------------

test(strategy_exception_is_an_error_line, [Out == error-"Unknown message: strategy_gave_up"]) :-
    decide_(plt_play_kb, 6, 0, false, Out).

test(strategy_error_is_an_error_line,
     [Out == error-"atom_length/2: Type error: `text' expected, found `f(x)' (a compound)"]) :-
    decide_(plt_play_kb, 9, 0, false, Out).

test(inference_limit, [Out == error-"the strategy took more than 1,000 inferences to choose \c
                                     in state 0 of episode 8"]) :-
    objects(Os),
    begin_episode(plt_play_kb, 8, Os, [], [1, 1]),
    decide(plt_play_kb, 8, 0, [[], []], [], [], 1000, false, default, Out).

% --- a strategy may not end the process -------------------------------------

test(guard_defines_the_process_level_predicates_as_refusals) :-
    guarded(plt_play_kb, halt),
    guarded(plt_play_kb, abort),
    clause(plt_play_kb:shell(_), neurosym_play:refused_(shell/1)),
    clause(plt_play_kb:delete_file(_), neurosym_play:refused_(delete_file/1)).

test(guarded_call_built_at_run_time_refused,
     [Out == error-"No permission to call procedure `halt/0' \c
                    (a strategy may not end the process, run programs, load code or change files)"]) :-
    guarded(plt_play_kb, halt),          % else the call below would end this test run
    decide_(plt_play_kb, 7, 0, false, Out).

%   Unguarded, halt(3) reaches SWI-Prolog and is cancelled; were it not,
%   this run would end with status 3 and fail.
test(halt_while_choosing_cancelled,
     [Out == error-"the strategy called halt while choosing in state 0 of episode 5: \c
                    a strategy may not end the process"]) :-
    decide_(plt_play_unguarded, 5, 0, false, Out).

% --- strategy files refused before they load -------------------------------

policy_problem(Text, Problem) :-
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, Text), close(S),
    c_stack(CStack),
    check_policy(plt_play_policy, File, CStack, Problem).

policy_case("goal(E, T, G) :- at(E, T, G, _, _).\n\c
             :- dynamic seen/1.\n:- discontiguous goal/3.\n\c
             :- use_module(library(lists)).\n:- use_module(library(apply), [maplist/2]).\n",
            none).
policy_case("goal(_, _, x).\n:- initialization(main).\n",
            2-"the directive :- initialization main would run when the strategy loads; \c
               a strategy file holds goal/3 and its helpers as clauses, and its directives \c
               may only be dynamic, discontiguous or use_module(library(Name))").
policy_case("?- consult(other).\n",
            1-"the directive :- consult(other) would run when the strategy loads; \c
               a strategy file holds goal/3 and its helpers as clauses, and its directives \c
               may only be dynamic, discontiguous or use_module(library(Name))").
policy_case(":- use_module('/tmp/x').\n",
            1-"the directive :- use_module('/tmp/x') would run when the strategy loads; \c
               a strategy file holds goal/3 and its helpers as clauses, and its directives \c
               may only be dynamic, discontiguous or use_module(library(Name))").
policy_case("goal(E, T, G) :- G = x, shell(ls).\n",
            1-"it names shell/1; a strategy may not end the process, run programs, load code \c
               or change files").
policy_case("goal(_, _, x) :- catch(halt, _, true).\n",
            1-"it names halt/0; a strategy may not end the process, run programs, load code \c
               or change files").
policy_case("\ngoal(_, _, x).\nroute(_, _, _, up).\n",
            3-"a clause for route/4, which module route (rules/route.pl) exports; a strategy \c
               calls route's predicates (default_goal/3, route/4, route/5, route_distance/4, \c
               route_exists/3, route_forget/1, route_moves/4, route_moves/5, safe_step/3) and \c
               may not redefine them").
policy_case("route_moves(_, _, _, 0).\n",
            1-"a clause for route_moves/4, which module route (rules/route.pl) exports; a strategy \c
               calls route's predicates (default_goal/3, route/4, route/5, route_distance/4, \c
               route_exists/3, route_forget/1, route_moves/4, route_moves/5, safe_step/3) and \c
               may not redefine them").
% What a learned strategy imports from route: route_moves/4,5, called as they are.
policy_case("route_length(E, T, O, D) :- route_moves(E, T, O, D).\n\c
             route_from_(E, T, F, O, D) :- route_moves(E, T, F, O, D).\n\c
             goal(E, T, O) :- route_length(E, T, O, D), D < 3, route_exists(E, T, O).\n",
            none).
policy_case("goal(E, T, O) :- route:grid_(E, _, _, _), O = terminal.\n",
            1-"it calls route:grid_/4; a strategy calls the predicates module route exports \c
               (default_goal/3, route/4, route/5, route_distance/4, route_exists/3, \c
               route_forget/1, route_moves/4, route_moves/5, safe_step/3) as they are, \c
               unqualified, and none of its own").
policy_case("goal(E, T, O) :- assertz('route@kb':searched_(E, T, O, [], x)).\n",
            1-"it calls 'route@kb':searched_/5; a strategy calls the predicates module route \c
               exports (default_goal/3, route/4, route/5, route_distance/4, route_exists/3, \c
               route_forget/1, route_moves/4, route_moves/5, safe_step/3) as they are, \c
               unqualified, and none of its own").
policy_case("user:goal(_, _, x).\n",
            1-"a clause for user:goal/3; a strategy defines its predicates where it is loaded, \c
               not in another module").
policy_case("term_expansion(a, b).\n",
            1-"a clause for term_expansion/2, which SWI-Prolog calls while it loads files; \c
               a strategy may not define it").
policy_case("atom(x).\n", 1-"a clause for the built-in predicate atom/1").
policy_case("X.\n", 1-"a variable is not a clause").
policy_case("42.\n", 1-"a clause whose head is not a predicate").

test(check_policy, [forall(policy_case(Text, Want)), Got == Want]) :-
    policy_problem(Text, Got).

test(check_policy_syntax_error_names_its_line, [Line == 2]) :-
    policy_problem("goal(_, _, x).\ngoal(_, _ x).\n", Line-Text),
    sub_string(Text, 0, _, _, "Syntax error: ").

test(check_policy_runs_nothing, [fail]) :-
    policy_problem(":- assertz(plt_play_ran).\n", _-_),
    current_predicate(_:plt_play_ran/0).

:- end_tests(neurosym_play).
