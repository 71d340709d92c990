/*  kb_common.pl -- lookups in a knowledge base's facts that the rule files share.

    Not a rule file to load beside a KB: the rule modules include it
    (:- include(lib/kb_common)), so each holds its own copy of these helpers
    and reads the facts as its own unqualified goals. Those resolve through
    the rule module's default import module: user when the rules are loaded
    beside a KB in plain swipl (swipl kb.pl rules/rgw.pl), the KB's own
    module in neurosym.prolog.KnowledgeBase, which loads each rule module
    once per KB (see load/6 in neurosym/prolog/pl/bridge.pl). So a fact
    lookup is a plain call, as fast as in a file without a module.
*/

:- use_module(library(ordsets)).

%   kb_episode_(?E): E is an episode; enumerates in episode order.
kb_episode_(E) :-
    episode(E, _, _, _).

%   kb_first_event_(+E, +Event, -T): T is the first time Event happened in
%   E; fails when it never did.
%
%   Speed: events are looked up by episode only (event(E, T, Ev) with E
%   bound, then Ev compared), so SWI-Prolog builds one just-in-time index, on
%   the first argument of event/3, and no composite index on (E, Event),
%   whose construction dominated the first call over large KBs.
kb_first_event_(E, Event, T) :-
    aggregate_all(min(T0), ( event(E, T0, Ev), Ev == Event ), T).

%   kb_event_(+E, +Event): Event happened in E (looked up by episode only).
kb_event_(E, Event) :-
    once(( event(E, _, Ev), Ev == Event )).

%   kb_link_at_(?E, ?T, ?A, ?B, -Link): at state T of episode E the network
%   relates A and B, in either orientation: r(J) from holds/5 (PrediNet,
%   above threshold), or attention(Head) when MHDPA head Head's strongest key
%   for one of them is the other (attention/6). One answer per fact, holds/5
%   first. Called with A bound, SWI-Prolog indexes the facts on A's argument.
kb_link_at_(E, T, A, B, R) :- holds(E, T, R, A, B).
kb_link_at_(E, T, A, B, R) :- holds(E, T, R, B, A).
kb_link_at_(E, T, A, B, attention(H)) :- attention(E, T, H, A, B, _).
kb_link_at_(E, T, A, B, attention(H)) :- attention(E, T, H, B, A, _).

%   kb_link_(?A, ?B, -Link): kb_link_at_/5 at any state.
kb_link_(A, B, R) :- kb_link_at_(_, _, A, B, R).

%   kb_acted_states_(-D): the states the agent acted in, over every episode:
%   the sum of episode/4's Steps (states 0..Steps-1 of each episode, the ones
%   with a step/4 fact and the network's outputs). The denominator of every
%   share(N, D) the link answers give. A hand-made KB without episode/4
%   facts counts instead the distinct states that have a network fact
%   (holds/5, attention/6).
kb_acted_states_(D) :-
    aggregate_all(sum(S), kb_fact_(episode(_, S, _, _)), D0),
    (   D0 > 0
    ->  D = D0
    ;   aggregate_all(count, distinct(E-T, kb_network_state_(E, T)), D)
    ).

kb_network_state_(E, T) :- kb_fact_(holds(E, T, _, _, _)).
kb_network_state_(E, T) :- kb_fact_(attention(E, T, _, _, _, _)).

%   kb_link_answer_(+As, +Bs, -Answer): how the network relates the entities
%   As to the entities Bs (lists: key(red) and held(red) are one key), state
%   by state; see sword_enemy_link/1 in rgw.pl for the answers. D is
%   kb_acted_states_/1.
%
%     direct(Links, share(N, D))   some Link relates an A and a B at one
%                                  state; N states have such a link
%     indirect(Vias)               no direct link; Vias lists via(Z, share(N,
%                                  D)), most states first: Z is related to an
%                                  A and to a B at one state or at two
%                                  consecutive states of one episode, N such
%                                  states (a state counts when one of the two
%                                  links holds there and the other at that
%                                  state, the one before or the one after)
%     co_occurring(Vias)           no such Z; Vias lists apart(Z, share(NA,
%                                  D), share(NB, D)): Z is related to an A on
%                                  NA states and to a B on NB states, never
%                                  at one state or two consecutive ones
%     none                         nothing of the above
%
%   Z ranges over the agent, the map's object types (object/2) and
%   Box-World's held key held(C); never one of As or Bs. Speed: one lookup of
%   the links of each A and each B (indexed on that argument), then sorted
%   lists of E-T states per Z intersected in order: no scan per pair of
%   states, no pass over facts that involve neither side.
kb_link_answer_(As, Bs, Answer) :-
    kb_acted_states_(D),
    (   kb_direct_(As, Bs, Links, N)
    ->  Answer = direct(Links, share(N, D))
    ;   kb_thirds_(As, As, Bs, AStates),
        kb_thirds_(Bs, As, Bs, BStates),
        kb_via_(AStates, BStates, D, Near, Apart),
        (   Near \== []
        ->  Answer = indirect(Near)
        ;   Apart \== []
        ->  Answer = co_occurring(Apart)
        ;   Answer = none
        )
    ).

%   kb_direct_(+As, +Bs, -Links, -N): Links (each once, in the order found)
%   relate an A to a B at some state; N states have one. Fails when none
%   does.
kb_direct_(As, Bs, Links, N) :-
    findall(S-L, ( member(A, As), member(B, Bs), kb_link_at_(E, T, A, B, L), S = E-T ), Found),
    Found \== [],
    pairs_keys_values(Found, States, Ls),
    list_to_set(Ls, Links),
    sort(States, Distinct),
    length(Distinct, N).

%   kb_thirds_(+Xs, +As, +Bs, -ZStates): Z-States for each third entity Z
%   that the network relates to an X of Xs, in standard order of Z; States
%   are the sorted states of those links, each E-T as the integer
%   E << 32 + T (integers compare faster than pairs, and T - 1 and T + 1
%   stay within the episode: no state has T >= 2^32). One findall over the links of
%   each X (indexed on X's argument), one sort, then a filter on the few
%   distinct Zs.
kb_thirds_(Xs, As, Bs, ZStates) :-
    findall(Z-S, ( member(X, Xs), kb_link_at_(E, T, X, Z, _), S is E << 32 + T ), Pairs),
    sort(Pairs, Sorted),
    group_pairs_by_key(Sorted, Groups),
    findall(Z-States, ( member(Z-States, Groups),
                        \+ memberchk(Z, As), \+ memberchk(Z, Bs),
                        kb_third_entity_(Z) ), ZStates).

kb_third_entity_(agent) :- !.
kb_third_entity_(held(_)) :- !.
kb_third_entity_(Z) :- once(object(_, Z)).

%   kb_via_(+AStates, +BStates, +D, -Near, -Apart): the thirds related to both
%   sides, split into via/2 (some state near) and apart/3 (none).
kb_via_(AStates, BStates, D, Near, Apart) :-
    findall(Key-Via,
            ( member(Z-SA, AStates),
              memberchk(Z-SB, BStates),
              kb_near_count_(SA, SB, N),
              (   N > 0
              ->  Key = near(NegN, Z), NegN is -N, Via = via(Z, share(N, D))
              ;   Key = apart(Z), length(SA, NA), length(SB, NB),
                  Via = apart(Z, share(NA, D), share(NB, D))
              ) ),
            Keyed),
    msort(Keyed, Sorted),
    findall(V, member(near(_, _)-V, Sorted), Near),
    findall(V, member(apart(_)-V, Sorted), Apart).

%   kb_near_count_(+SA, +SB, -N): the states of SA or SB at which the other
%   side holds at that state, the one before or the one after (same
%   episode). SA and SB are sorted state keys (kb_thirds_/4).
kb_near_count_(SA, SB, N) :-
    kb_widen_(SB, WB),
    kb_widen_(SA, WA),
    ord_intersection(SA, WB, InA),
    ord_intersection(SB, WA, InB),
    ord_union(InA, InB, Near),
    length(Near, N).

%   kb_widen_(+States, -Wide): sorted States with each state's neighbours
%   (the state keys one less and one more) added, sorted.
kb_widen_(States, Wide) :-
    findall(S1, ( member(S, States), ( S1 is S - 1 ; S1 = S ; S1 is S + 1 ) ), Ws),
    sort(Ws, Wide).

%   kb_fact_(+Fact): Fact, for facts a KB may lack altogether: fails, rather
%   than raising an existence error, when no predicate of Fact's name and
%   arity is visible (as if it were declared dynamic).
kb_fact_(Fact) :-
    current_predicate(_, Fact),
    call(Fact).
