/*  relations.pl -- generic questions over the network's facts of any neurosym KB.

    Load it beside a knowledge base:  swipl kb.pl rules/relations.pl

    Expects the facts of docs/design.md (a neurosym KB declares them all dynamic):
        relation(E, T, Head, J, A, B, Value)   PrediNet: D^h_j between the
                                               entities heads attended
        holds(E, T, r(J), A, B)                thresholded, oriented: Value > 0
        threshold(J, Value)
        attention(E, T, Head, Query, Key, W)   MHDPA: strongest keys per query
    episode(E, Steps, Return, Outcome)     entity_link/3's shares count
                                           states out of the Steps' sum
    Heads and relations count from 0. Entities are named by type (sword,
    key(red), ...), so these rules speak about types, not single objects.

    A module (relations) whose helpers stay inside it, so it loads beside the
    other rule files without clashes. It reads the facts as unqualified
    goals, which resolve through its default import module: user in plain
    swipl, the KB's own module in neurosym.prolog.KnowledgeBase (which loads
    the rule modules once per KB, see lib/kb_common.pl).
*/

:- module(relations,
          [ head/1,
            head_pairs/2,
            head_top_pair/4,
            relation_stats/5,
            pair_strength/5,
            held_count/4,
            consistently_orders/3,
            order_support/5,
            strongest_pairs/2,
            entity_link/3
          ]).

:- use_module(library(lists)).
:- use_module(library(pairs)).
:- use_module(library(apply)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).

:- include(lib/kb_common).

%!  head(?Head) is nondet.
%
%   Head is a head that has facts in the KB (relation/7 or attention/6),
%   each once, in increasing order. Semidet when Head is bound.
%
%       ?- head(H).
%       H = 0 ;
%       H = 1.

head(H) :-
    integer(H),
    !,
    once(has_head_(H)).
head(H) :-
    setof(H0, has_head_(H0), Hs),
    member(H, Hs).

%!  head_pairs(?Head, -Pairs:list) is nondet.
%
%   Pairs lists Count-(A-B) for every ordered pair of entity types that Head
%   compared (PrediNet: A attended by a1, B by a2; MHDPA: query A, key B),
%   most frequent first, ties in standard order of A-B. Deterministic when
%   Head is bound.
%
%       ?- head_pairs(0, Ps).
%       Ps = [3-(sword-enemy), 1-(agent-sword)].

head_pairs(H, Pairs) :-
    head(H),
    findall(A-B, compares_(H, A, B), AB),
    msort(AB, Sorted),
    clumped(Sorted, Clumps),
    findall(N-P, member(P-N, Clumps), Counted),
    sort(1, @>=, Counted, Pairs).

%!  head_top_pair(?Head, -A, -B, -Count) is nondet.
%
%   A-B is the pair of entity types Head compared most often (Count states);
%   on a tie the first in standard order. One answer per head.
%
%       ?- head_top_pair(0, A, B, N).
%       A = sword, B = enemy, N = 3.

head_top_pair(H, A, B, N) :-
    head_pairs(H, [N-(A-B)|_]).

%!  relation_stats(?J, -Count, -Mean, -Min, -Max) is nondet.
%
%   Statistics of the recorded values of relation J (relation/7, all heads).
%
%       ?- relation_stats(0, N, Mean, Min, Max).
%       N = 5, Mean = 0.1, Min = -0.75, Max = 1.0.

relation_stats(J, N, Mean, Min, Max) :-
    relation_index_(J),
    aggregate_all(r(count, sum(V), min(V), max(V)), relation(_, _, _, J, _, _, V), r(N, Sum, Min, Max)),
    Mean is Sum / N.

%!  pair_strength(?J, ?A, ?B, -Count, -Mean) is nondet.
%
%   Over the Count relation/7 rows that compare types A and B with relation J
%   (either way round), Mean is the mean of D_j(A, B), the value read from A
%   to B (a row for (B, A) counts with its sign flipped). A \== B.
%
%       ?- pair_strength(0, sword, enemy, N, M).
%       N = 4, M = 0.625.

pair_strength(J, A, B, N, Mean) :-
    distinct(J-A-B, pair_(J, A, B)),
    aggregate_all(r(count, sum(V)), oriented_value_(J, A, B, V), r(N, Sum)),
    Mean is Sum / N.

%!  held_count(?J, ?A, ?B, -Count) is nondet.
%
%   r(J) held from A to B (above threshold) at Count states.
%
%       ?- held_count(0, sword, enemy, N).
%       N = 2.

held_count(J, A, B, N) :-
    distinct(J-A-B, holds(_, _, r(J), A, B)),
    aggregate_all(count, holds(_, _, r(J), A, B), N).

%!  consistently_orders(?J, ?A, ?B) is nondet.
%
%   Relation r(J) orders type A before type B consistently: above threshold it
%   held from A to B at least once and never from B to A. A \== B.
%
%       ?- consistently_orders(J, sword, enemy).
%       J = 0.

consistently_orders(J, A, B) :-
    distinct(J-A-B, holds(_, _, r(J), A, B)),
    A \== B,
    \+ holds(_, _, r(J), B, A).

%!  order_support(?J, ?A, ?B, -For, -Against) is nondet.
%
%   For is how often r(J) held from A to B, Against how often from B to A;
%   answered for every pair with For > 0 and A \== B.
%
%       ?- order_support(1, sword, enemy, F, A).
%       F = 2, A = 1.

order_support(J, A, B, For, Against) :-
    held_count(J, A, B, For),
    A \== B,
    aggregate_all(count, holds(_, _, r(J), B, A), Against).

%!  strongest_pairs(+N, -Top:list) is det.
%
%   Top lists up to N terms held(J, A, B, Count) with A \== B, the oriented
%   pairs that held most often, most first (ties in standard order).
%
%       ?- strongest_pairs(1, Top).
%       Top = [held(0, sword, enemy, 2)].

strongest_pairs(N, Top) :-
    findall(k(NC, J, A, B), ( held_count(J, A, B, C), A \== B, NC is -C ), Keys),
    msort(Keys, Sorted),
    length(Sorted, Len),
    K is min(N, Len),
    length(First, K),
    append(First, _, Sorted),
    maplist(held_, First, Top).

%!  entity_link(+A, +B, -Answer) is det.
%
%   How the network relates entity types A and B, state by state (holds/5
%   above threshold, attention/6's strongest keys): Answer is
%   direct(Links, share(N, D)) when some Link relates them at one state (N
%   such states), else indirect(Vias) with via(Z, share(N, D)) for each
%   third entity Z related to both at one state or two consecutive states
%   of one episode (N states: one link there and the other at that state,
%   the one before or the one after; most first), else co_occurring(Vias)
%   with apart(Z, share(NA, D), share(NB, D)) for each Z related to A on NA
%   states and to B on NB states, never close in time, else none. D is
%   the number of states the agent acted in, over all episodes (the sum of
%   episode/4's Steps). Z is the agent, a map object's type or a held key.
%
%       ?- entity_link(sword, agent, A).
%       A = direct([r(0)], share(1, 8)).

entity_link(A, B, Answer) :-
    must_be(ground, A),
    must_be(ground, B),
    kb_link_answer_([A], [B], Answer).

% ------------------------------------------------------------------ helpers

has_head_(H) :- relation(_, _, H, _, _, _, _).
has_head_(H) :- attention(_, _, H, _, _, _).

%   compares_(?H, ?A, ?B): one answer per state at which head H compared
%   A (first argument / query) with B. PrediNet rows exist for every relation
%   J at each state; counting the J = 0 rows counts the states once.
compares_(H, A, B) :- relation(_, _, H, 0, A, B, _).
compares_(H, A, B) :- attention(_, _, H, A, B, _).

relation_index_(J) :-
    setof(J0, E^T^H^A^B^V^relation(E, T, H, J0, A, B, V), Js),
    member(J, Js).

pair_(J, A, B) :- relation(_, _, _, J, A, B, _), A \== B.
pair_(J, A, B) :- relation(_, _, _, J, B, A, _), A \== B.

oriented_value_(J, A, B, V) :- relation(_, _, _, J, A, B, V).
oriented_value_(J, A, B, V) :- relation(_, _, _, J, B, A, V0), V is -V0.

held_(k(NC, J, A, B), held(J, A, B, C)) :- C is -NC.
