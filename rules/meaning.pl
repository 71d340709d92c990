/*  meaning.pl -- names for relations, from the probes of `neurosym probe`.

    Load it beside a probe KB (and, to read holds/5 by name, an extract KB):
        swipl kb_out/probe/kb.pl kb_out/rgw2/kb.pl rules/meaning.pl

    Facts it reads:
        probe(Head, J, Predicate, Accuracy, Control)      J an integer or all
        probe_untrained(Head, J, Predicate, Accuracy, Control)
        holds(E, T, r(J), A, B)                           (extract KB, optional)

    Selectivity = Accuracy - Control (Hewitt and Liang 2019). A relation earns a
    name when some head's probe of it is at least min_selectivity/1 selective:
    W_S is shared by all heads, so relation j means the same thing in every head.

    A module (meaning) whose helpers stay inside it. It reads the facts as
    unqualified goals, which resolve through its default import module:
    user in plain swipl, the KB's own module in neurosym.prolog.KnowledgeBase
    (which loads the rule modules once per KB, see lib/kb_common.pl). A KB
    without facts of one of the three predicates above is read as having none
    of them (kb_fact_/1), as when they are declared dynamic.
*/

:- module(meaning,
          [ min_selectivity/1,
            selectivity/4,
            relation_means/2,
            relation_name/3,
            head_encodes/3,
            training_added/4,
            named_holds/5
          ]).

:- use_module(library(lists)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).

:- include(lib/kb_common).

%!  min_selectivity(-S:float) is det.
%
%   The selectivity a probe needs before its predicate names a relation.
%
%       ?- min_selectivity(S).
%       S = 0.2.

min_selectivity(0.2).

%!  selectivity(?Head, ?J, ?Predicate, -Selectivity) is nondet.
%
%   Selectivity of the probe of relation J (or all) of Head for Predicate.
%
%       ?- selectivity(0, 3, holding(sword), S).
%       S = 0.42.

selectivity(H, J, P, S) :-
    kb_fact_(probe(H, J, P, Acc, Ctl)),
    S is Acc - Ctl.

%!  relation_means(?Relation, ?Predicate) is nondet.
%
%   Relation r(J) encodes Predicate selectively in at least one head. Each
%   pair once.
%
%       ?- relation_means(r(3), P).
%       P = holding(sword).

relation_means(r(J), P) :-
    min_selectivity(Min),
    distinct(J-P, ( selectivity(_, J, P, S), integer(J), S >= Min )).

%!  relation_name(?Relation, -Predicate, -Selectivity) is nondet.
%
%   The most selective predicate of Relation (over all heads), when it is
%   selective enough: one answer per relation.
%
%       ?- relation_name(r(3), P, S).
%       P = holding(sword), S = 0.42.

relation_name(r(J), P, S) :-
    min_selectivity(Min),
    distinct(J, ( kb_fact_(probe(_, J, _, _, _)), integer(J) )),
    aggregate_all(max(S0, P0), ( selectivity(_, J, P0, S0) ), max(S, P)),
    S >= Min.

%!  head_encodes(?Head, ?Predicate, -Selectivity) is nondet.
%
%   Head's whole vector (J = all) encodes Predicate selectively.
%
%       ?- head_encodes(1, P, S).
%       P = visited(sword), S = 0.35.

head_encodes(H, P, S) :-
    min_selectivity(Min),
    selectivity(H, all, P, S),
    S >= Min.

%!  training_added(?Head, ?J, ?Predicate, -Gain) is nondet.
%
%   Training made the probe more selective by Gain than the same probe on an
%   untrained network of the same shape; only selective probes are listed.
%
%       ?- training_added(1, all, visited(sword), G).
%       G = 0.3.

training_added(H, J, P, Gain) :-
    min_selectivity(Min),
    selectivity(H, J, P, S),
    S >= Min,
    kb_fact_(probe_untrained(H, J, P, Acc0, Ctl0)),
    Gain is S - (Acc0 - Ctl0).

%!  named_holds(?E, ?T, ?Name, ?A, ?B) is nondet.
%
%   holds(E, T, r(J), A, B) read through its name: Name is the predicate
%   relation_name/3 gives r(J).
%
%       ?- named_holds(0, T, holding(sword), A, B).
%       T = 4, A = agent, B = sword.

named_holds(E, T, Name, A, B) :-
    relation_name(R, Name, _),
    kb_fact_(holds(E, T, R, A, B)).
