"""The Prolog half of ``neurosym play``: live-state facts asserted as data, one decision per call.

Kept as text (like :mod:`neurosym.prolog.bridge`) and consulted once per
process as module ``neurosym_play``. Its predicates work on a KB module M made
by :class:`~neurosym.prolog.knowledge_base.KnowledgeBase` (which holds the
rule files, route.pl and the strategy, as code):

* ``begin_episode(M, E, Objects, Terrain, Grid)`` asserts ``object/2`` (once
  per id), ``terrain/4`` and ``grid/3`` of episode E;
* ``decide(M, E, T, State, Prev, Extra, Limit, Seen, Out)`` asserts state
  T's ``at/5`` and ``holding/3``, the previous transition's ``step/4`` and
  ``event/3``, and Extra (the network's ``holds/5``, ``attends/8`` or
  ``attention/6`` facts of state T), then asks ``goal(E, T, G)`` (first
  answer) and ``route(E, T, G, A)``; when either fails it falls back to
  ``default_goal/3``, then ``safe_step/3``, then ``up``. Seen ``true`` (the
  episode was in this very state before) goes to the fallback at once. Out
  is ``Status-Goal-Action`` (Status ``ok``, ``no_goal``, ``no_route`` or
  ``loop``) or ``error-Text`` when the strategy raised or ran past Limit
  inferences;
* ``end_episode(M, E)`` retracts every fact of episode E (not object/2,
  which, as in a KB, lists the ids of every episode) and the routes
  route.pl remembered for it (``route_forget/1``).

Values arrive from janus as atoms, numbers and lists; a compound term arrives
as the tuple ``('$t', Functor, Args)`` and is rebuilt with
``compound_name_arguments/3``: nothing passed in is ever called, and Extra
may only hold the three network predicates.
"""

from __future__ import annotations

MODULE = "neurosym_play"

SOURCE = r"""
:- module(neurosym_play, [begin_episode/5, decide/9, end_episode/2]).
:- use_module(library(apply), [maplist/2, maplist/3]).
:- use_module(library(lists), [member/2]).

term_(X, X) :- atomic(X), !.
term_(-('$t', F, As0), T) :- !, maplist(term_, As0, As), compound_name_arguments(T, F, As).
term_(L0, L) :- is_list(L0), maplist(term_, L0, L).

begin_episode(M, E, Objects, Terrain, [Rows, Cols]) :-
    forall(member([Id, Type0], Objects),
           ( term_(Type0, Type),
             ( M:object(Id, Type) -> true ; assertz(M:object(Id, Type)) ) )),
    forall(member([Type, R, C], Terrain), assertz(M:terrain(E, Type, R, C))),
    assertz(M:grid(E, Rows, Cols)).

end_episode(M, E) :-
    (   current_predicate(M:route_forget/1) -> M:route_forget(E) ; true ),
    retractall(M:at(E, _, _, _, _)),
    retractall(M:holding(E, _, _)),
    retractall(M:step(E, _, _, _)),
    retractall(M:event(E, _, _)),
    retractall(M:terrain(E, _, _, _)),
    retractall(M:grid(E, _, _)),
    retractall(M:holds(E, _, _, _, _)),
    retractall(M:attends(E, _, _, _, _, _, _, _)),
    retractall(M:attention(E, _, _, _, _, _)).

extra_(holds, 5).
extra_(attends, 8).
extra_(attention, 6).

assert_state_(M, E, T, [Ats, Held], Prev, Extra) :-
    forall(member([Id, R, C], Ats), assertz(M:at(E, T, Id, R, C))),
    forall(member(I0, Held), ( term_(I0, I), assertz(M:holding(E, T, I)) )),
    (   Prev = [Action, Reward, Events]
    ->  T0 is T - 1,
        assertz(M:step(E, T0, Action, Reward)),
        forall(member(Ev0, Events), ( term_(Ev0, Ev), assertz(M:event(E, T0, Ev)) ))
    ;   true
    ),
    forall(member(X0, Extra),
           ( term_(X0, X), functor(X, N, A), extra_(N, A), assertz(M:X) )).

decide(M, E, T, State, Prev, Extra, Limit, Seen, Out) :-
    assert_state_(M, E, T, State, Prev, Extra),
    catch(call_with_inference_limit(choose_(M, E, T, Seen, Out0), Limit, Result), Err, true),
    (   nonvar(Err)
    ->  message_to_codes_(Err, Text), Out = error-Text
    ;   Result == inference_limit_exceeded
    ->  format(string(Text), "the strategy took more than ~D inferences to choose in state ~w of episode ~w", [Limit, T, E]),
        Out = error-Text
    ;   Out = Out0
    ).

choose_(M, E, T, true, Out) :-
    !,
    fallback_(M, E, T, loop, none, Status, Goal, Action),
    Out = Status-Goal-Action.
choose_(M, E, T, false, Status-Goal-Action) :-
    (   once(M:goal(E, T, G))
    ->  (   M:route(E, T, G, A)
        ->  Status = ok, Goal = G, Action = A
        ;   fallback_(M, E, T, no_route, G, Status, Goal, Action)
        )
    ;   fallback_(M, E, T, no_goal, none, Status, Goal, Action)
    ).

fallback_(M, E, T, Why, G0, Why, Goal, Action) :-
    (   M:default_goal(E, T, G), G \== G0, M:route(E, T, G, A)
    ->  Goal = G, Action = A
    ;   M:safe_step(E, T, A)
    ->  Goal = G0, Action = A
    ;   Goal = G0, Action = up
    ).

message_to_codes_(E, Text) :-
    (   catch(message_to_codes(E, _, Codes), _, fail)
    ->  string_codes(Text0, Codes)
    ;   format(string(Text0), "~q", [E])
    ),
    split_string(Text0, "\n", " \t", Parts),
    atomic_list_concat(Parts, ' ', A),
    atom_string(A, Text).

message_to_codes(E, _, Codes) :-
    '$messages':translate_message(E, Lines, []),
    with_output_to(codes(Codes), print_message_lines(current_output, '', Lines)).
"""
