/** <module> neurosym_play: the Prolog half of `neurosym play`

Live-state facts asserted as data into a KB module M (which holds the rule
files, rules/route.pl and the strategy, as code), one decision per call.
neurosym/play/prolog.py says what each exported predicate does; the Python
side (neurosym/play/agent.py) calls them through janus.
*/

:- module(neurosym_play, [begin_episode/5, decide/10, decide_all/5, end_episode/2, check_policy/4, guard/1]).
:- use_module(library(apply), [maplist/2, maplist/3]).
:- use_module(library(lists), [member/2]).
:- use_module(library(error), [must_be/2]).

:- thread_local choosing_/0, halted_/1.

term_(X, X) :- atomic(X), !.
term_(-('$t', F, As0), T) :- !, maplist(term_, As0, As), compound_name_arguments(T, F, As).
term_(L0, L) :- is_list(L0), maplist(term_, L0, L).

%!  begin_episode(+M, +E, +Objects, +Terrain, +Grid) is det.
%   Assert object/2 (once per id), terrain/4 and grid/3 of episode E in KB module M.
begin_episode(M, E, Objects, Terrain, [Rows, Cols]) :-
    forall(member([Id, Type0], Objects),
           ( term_(Type0, Type),
             ( M:object(Id, Type) -> true ; assertz(M:object(Id, Type)) ) )),
    forall(member([Type, R, C], Terrain), assertz(M:terrain(E, Type, R, C))),
    assertz(M:grid(E, Rows, Cols)).

%!  end_episode(+M, +E) is det.
%   Retract every fact of episode E (not object/2, which, as in a KB, lists the ids
%   of every episode) and the routes route.pl remembered for it (route_forget/1).
end_episode(M, E) :-
    (   current_predicate(M:route_forget/1) -> M:route_forget(E) ; true ),
    retractall(M:at(E, _, _, _, _)),
    retractall(M:holding(E, _, _)),
    retractall(M:step(E, _, _, _)),
    retractall(M:event(E, _, _)),
    retractall(M:terrain(E, _, _, _)),
    retractall(M:grid(E, _, _)),
    retractall(M:facing(E, _, _)),
    retractall(M:door_state(E, _, _, _)),
    retractall(M:holds(E, _, _, _, _)),
    retractall(M:attends(E, _, _, _, _, _, _, _)),
    retractall(M:attention(E, _, _, _, _, _)).

extra_(holds, 5).
extra_(attends, 8).
extra_(attention, 6).

assert_state_(M, E, T, [Ats, Held|Minigrid], Prev, Extra) :-
    forall(member([Id, R, C], Ats), assertz(M:at(E, T, Id, R, C))),
    forall(member(I0, Held), ( term_(I0, I), assertz(M:holding(E, T, I)) )),
    (   Minigrid = [Dir, Doors]
    ->  atom(Dir),
        assertz(M:facing(E, T, Dir)),
        forall(member([Id, S], Doors), ( atom(Id), atom(S), assertz(M:door_state(E, T, Id, S)) ))
    ;   Minigrid == []
    ),
    (   Prev = [Action, Reward, Events]
    ->  T0 is T - 1,
        assertz(M:step(E, T0, Action, Reward)),
        forall(member(Ev0, Events), ( term_(Ev0, Ev), assertz(M:event(E, T0, Ev)) ))
    ;   true
    ),
    forall(member(X0, Extra),
           ( term_(X0, X), functor(X, N, A), extra_(N, A), assertz(M:X) )).

%!  decide_all(+M, +Items, +Limit, +Fallback, -Outs) is det.
%   decide/10 for each item [E, T, State, Prev, Extra, Seen] in turn (the running
%   episodes of one step: one call from Python per step); Outs their Outs, in order.
decide_all(M, Items, Limit, Fallback, Outs) :-
    must_be(list, Items),
    maplist(decide_item_(M, Limit, Fallback), Items, Outs).

decide_item_(M, Limit, Fallback, [E, T, State, Prev, Extra, Seen], Out) :-
    decide(M, E, T, State, Prev, Extra, Limit, Seen, Fallback, Out).

%!  decide(+M, +E, +T, +State, +Prev, +Extra, +Limit, +Seen, +Fallback, -Out) is det.
%   Assert state T's at/5 and holding/3 (State [Ats, Held], or on Minigrid [Ats, Held,
%   Dir, Doors]: facing/3 and door_state/4 too), the previous transition's step/4 and event/3,
%   and Extra (the network's holds/5, attends/8 or attention/6 facts of state T), then
%   ask goal(E, T, G) (first answer) and route(E, T, G, A). Out is
%   [Decider, Why, Goal, Action]: [strategy, none, G, A] when both answer. Else Why is
%   no_goal (goal/3 has no answer), no_route (route/4 has none for G) or loop (Seen is
%   true: the episode was in this very state before, and a strategy that reads the
%   state would choose as it did then), and Fallback says what happens: default
%   falls back to default_goal/3 (Decider default_goal), then safe_step/3
%   (safe_step), then up (up); none decides nothing (Decider none, Action none: the
%   episode fails). Out is error-Text when the strategy raised or ran past Limit
%   inferences.
decide(M, E, T, State, Prev, Extra, Limit, Seen, Fallback, Out) :-
    assert_state_(M, E, T, State, Prev, Extra),
    retractall(halted_(_)),
    setup_call_cleanup(
        assertz(choosing_),
        catch(call_with_inference_limit(choose_(M, E, T, Seen, Fallback, Out0), Limit, Result),
              Err, true),
        retractall(choosing_)),
    (   retract(halted_(Goal))
    ->  format(string(Text), "the strategy called ~q while choosing in state ~w of episode ~w: a strategy may not end the process", [Goal, T, E]),
        Out = error-Text
    ;   nonvar(Err)
    ->  message_to_codes_(Err, Text), Out = error-Text
    ;   Result == inference_limit_exceeded
    ->  format(string(Text), "the strategy took more than ~D inferences to choose in state ~w of episode ~w", [Limit, T, E]),
        Out = error-Text
    ;   Out = Out0
    ).

choose_(M, E, T, Seen, Fallback, Out) :-
    (   Seen == true
    ->  Why = loop, G0 = none
    ;   once(M:goal(E, T, G))
    ->  (   M:route(E, T, G, A)
        ->  Out = [strategy, none, G, A]
        ;   Why = no_route, G0 = G
        )
    ;   Why = no_goal, G0 = none
    ),
    (   nonvar(Out)
    ->  true
    ;   Fallback == none
    ->  Out = [none, Why, G0, none]
    ;   fallback_(M, E, T, G0, By, Goal, Action),
        Out = [By, Why, Goal, Action]
    ).

fallback_(M, E, T, G0, By, Goal, Action) :-
    (   M:default_goal(E, T, G), G \== G0, M:route(E, T, G, A)
    ->  By = default_goal, Goal = G, Action = A
    ;   M:safe_step(E, T, A)
    ->  By = safe_step, Goal = G0, Action = A
    ;   By = up, Goal = G0, Action = up
    ).

message_to_codes_(E, Text) :-
    (   catch(message_to_codes(E, _, Codes), _, fail)
    ->  string_codes(Text0, Codes)
    ;   format(string(Text0), "~q", [E])
    ),
    split_string(Text0, "\n", " \t", Parts),
    atomic_list_concat(Parts, ' ', A),
    atom_string(A, Text).

% -- a strategy may not end the process ------------------------------------

%   A halt that reaches SWI-Prolog while a strategy chooses is cancelled
%   (halt/0,1 then fail) and decide/9 reports it.
:- at_halt(cancel_strategy_halt_).

cancel_strategy_halt_ :-
    (   choosing_
    ->  assertz(halted_(halt)),
        cancel_halt(neurosym_play)
    ;   true
    ).

:- multifile user:message_hook/3.
user:message_hook(cancel_halt(neurosym_play), _, _).

forbidden_(halt, 0).
forbidden_(halt, 1).
forbidden_(abort, 0).
forbidden_(break, 0).
forbidden_(prolog, 0).
forbidden_(shell, 0).
forbidden_(shell, 1).
forbidden_(shell, 2).
forbidden_(process_create, 3).
forbidden_(process_kill, 1).
forbidden_(process_kill, 2).
forbidden_(thread_signal, 2).
forbidden_(thread_exit, 1).
forbidden_(on_signal, 3).
forbidden_(at_halt, 1).
forbidden_(cancel_halt, 1).
forbidden_(set_prolog_flag, 2).
forbidden_(create_prolog_flag, 3).
forbidden_(consult, 1).
forbidden_(load_files, 1).
forbidden_(load_files, 2).
forbidden_(ensure_loaded, 1).
forbidden_(use_module, 1).
forbidden_(use_module, 2).
forbidden_(unload_file, 1).
forbidden_(make, 0).
forbidden_(qsave_program, 1).
forbidden_(qsave_program, 2).
forbidden_(redefine_system_predicate, 1).
forbidden_(abolish, 1).
forbidden_(abolish, 2).
forbidden_(delete_file, 1).
forbidden_(rename_file, 2).
forbidden_(setenv, 2).
forbidden_(unsetenv, 1).
forbidden_(chdir, 1).
forbidden_(working_directory, 2).

%!  guard(+M) is det.
guard(M) :-
    forall(forbidden_(N, A), guard_(M, N, A)).

guard_(M, N, A) :-
    functor(H, N, A),
    catch(( (   built_in_(N, A)
            ->  redefine_system_predicate(M:H)
            ;   true
            ),
            assertz(M:(H :- neurosym_play:refused_(N/A))) ),
          _, true).  % imported by the strategy: its body was checked for the name

%   A predicate of the system itself, asked without autoloading anything.
built_in_(N, A) :-
    current_predicate(system:N/A),
    functor(H, N, A),
    predicate_property(system:H, built_in).

refused_(PI) :-
    throw(error(permission_error(call, procedure, PI),
                context(_, 'a strategy may not end the process, run programs, load code or change files'))).

%!  check_policy(+M, +File, +CStack, -Problem) is det.
check_policy(M, File, CStack, Problem) :-
    thread_create(check_file_(M, File), T, [c_stack(CStack)]),
    thread_join(T, Exit),
    (   Exit = exited(Problem)
    ->  true
    ;   format(string(Text), "reading stopped: ~q", [Exit]),
        Problem = 0-Text
    ).

check_file_(M, File) :-
    catch(setup_call_cleanup(open(File, read, S, [encoding(utf8)]),
                             check_terms_(M, S, Problem),
                             close(S)),
          E,
          ( message_to_codes_(E, Text), Problem = 0-Text )),
    thread_exit(Problem).

check_terms_(M, S, Problem) :-
    catch(read_term(S, T, [term_position(Pos)]), E, true),
    (   nonvar(E)
    ->  read_error_(E, Line, Text),
        Problem = Line-Text
    ;   T == end_of_file
    ->  Problem = none
    ;   stream_position_data(line_count, Pos, Line),
        (   term_problem_(M, T, Text)
        ->  Problem = Line-Text
        ;   check_terms_(M, S, Problem)
        )
    ).

read_error_(error(Formal, Context), Line, Text) :-
    (   ( Context = stream(_, Line, _, _) ; Context = file(_, Line, _, _) )
    ->  message_to_codes_(error(Formal, _), Text)
    ;   Line = 0,
        message_to_codes_(error(Formal, Context), Text)
    ),
    !.
read_error_(E, 0, Text) :-
    message_to_codes_(E, Text).

term_problem_(_, T, "a variable is not a clause") :-
    var(T),
    !.
term_problem_(_, (:- D), Text) :-
    !,
    directive_problem_(D, Text).
term_problem_(_, (?- D), Text) :-
    !,
    directive_problem_(D, Text).
term_problem_(M, Clause, Text) :-
    clause_parts_(Clause, H, B),
    (   head_problem_(M, H, Text)
    ->  true
    ;   body_problem_(M, B, Text)
    ).

directive_problem_(D, Text) :-
    \+ allowed_directive_(D),
    format(string(Text), "the directive :- ~q would run when the strategy loads; a strategy file holds goal/3 and its helpers as clauses, and its directives may only be dynamic, discontiguous or use_module(library(Name))", [D]).

allowed_directive_(D) :-
    var(D),
    !,
    fail.
allowed_directive_(dynamic(Specs)) :- plain_specs_(Specs).
allowed_directive_(discontiguous(Specs)) :- plain_specs_(Specs).
allowed_directive_(use_module(library(L))) :- library_name_(L).
allowed_directive_(use_module(library(L), _)) :- library_name_(L).
allowed_directive_(ensure_loaded(library(L))) :- library_name_(L).

plain_specs_(S) :- var(S), !, fail.
plain_specs_((A, B)) :- !, plain_specs_(A), plain_specs_(B).
plain_specs_([]) :- !.
plain_specs_([S|Ss]) :- !, plain_specs_(S), plain_specs_(Ss).
plain_specs_(N/A) :- atom(N), integer(A).

library_name_(L) :-
    atom(L),
    atom_codes(L, [C|Cs]),
    code_type(C, lower),
    forall(member(X, Cs), code_type(X, csym)).

clause_parts_((H0 :- B), H, B) :- !, H = H0.
clause_parts_(((H0, G) => B), H, (G, B)) :- !, H = H0.
clause_parts_((H0 => B), H, B) :- !, H = H0.
clause_parts_((H0 --> B), H, B) :- !, ( nonvar(H0), H0 = (H1, _) -> H = H1 ; H = H0 ).
clause_parts_(H, H, true).

head_problem_(_, H, "a clause whose head is not a predicate") :-
    \+ callable(H),
    !.
head_problem_(_, Q:H, Text) :-
    !,
    (   callable(H) -> functor(H, N, A) ; N = H, A = 0 ),
    format(string(Text), "a clause for ~q:~q/~w; a strategy defines its predicates where it is loaded, not in another module", [Q, N, A]).
head_problem_(M, H, Text) :-
    functor(H, N, A),
    functor(G, N, A),
    (   hook_(N, A)
    ->  format(string(Text), "a clause for ~q/~w, which SWI-Prolog calls while it loads files; a strategy may not define it", [N, A])
    ;   built_in_(N, A)
    ->  format(string(Text), "a clause for the built-in predicate ~q/~w", [N, A])
    ;   route_module_(M, R),
        current_predicate(M:N/A),  % asked first: predicate_property/2 could autoload
        predicate_property(M:G, imported_from(R))
    ->  route_exports_(R, Exports),
        format(string(Text), "a clause for ~q/~w, which module route (rules/route.pl) exports; a strategy calls route's predicates (~w) and may not redefine them", [N, A, Exports])
    ;   current_predicate(M:N/A),
        \+ predicate_property(M:G, dynamic),
        \+ predicate_property(M:G, imported_from(_))
    ->  format(string(Text), "a clause for ~q/~w, which is defined where the strategy loads; a strategy may not redefine it", [N, A])
    ).

%   route_module_(+M, -R): the module whose route/4 M imports (module route, or
%   its copy route@M in a neurosym KB).
route_module_(M, R) :-
    current_predicate(M:route/4),
    predicate_property(M:route(_, _, _, _), imported_from(R)),
    !.

route_exports_(R, Text) :-
    module_property(R, exports(PIs0)),
    msort(PIs0, PIs),
    maplist([N/A, X]>>format(atom(X), "~q/~w", [N, A]), PIs, Xs),
    atomic_list_concat(Xs, ', ', Text).

%   A goal qualified with the name of route's module (route, route@KB, or the
%   module M imports route/4 from): route's helpers stay inside it.
route_qualifier_(M, Q) :-
    atom(Q),
    (   Q == route
    ;   sub_atom(Q, 0, _, _, 'route@')
    ;   route_module_(M, Q)
    ),
    !.

hook_(term_expansion, 2).
hook_(term_expansion, 4).
hook_(goal_expansion, 2).
hook_(goal_expansion, 4).

body_problem_(_, B, Text) :-
    sub_term(S, B),
    callable(S),
    functor(S, N, A),
    forbidden_(N, A),
    !,
    format(string(Text), "it names ~q/~w; a strategy may not end the process, run programs, load code or change files", [N, A]).
body_problem_(M, B, Text) :-
    sub_term(S, B),
    compound(S),
    S = Q:G,
    route_qualifier_(M, Q),
    !,
    (   callable(G) -> functor(G, N, A), format(atom(What), "~q/~w", [N, A]) ; What = G ),
    (   route_module_(M, R) -> route_exports_(R, Exports) ; Exports = "route/4, ..." ),
    format(string(Text), "it calls ~q:~w; a strategy calls the predicates module route exports (~w) as they are, unqualified, and none of its own", [Q, What, Exports]).

message_to_codes(E, _, Codes) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(codes(Codes), print_message_lines(current_output, '', Lines)).
