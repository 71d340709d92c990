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

%   kb_link_(?A, ?B, -Link): the network relates A and B, in either
%   orientation: r(J) from holds/5 (PrediNet, above threshold), or
%   attention(Head) when MHDPA head Head's strongest key for one of them is
%   the other (attention/6). One answer per fact, holds/5 first.
kb_link_(A, B, R) :- holds(_, _, R, A, B).
kb_link_(A, B, R) :- holds(_, _, R, B, A).
kb_link_(A, B, attention(H)) :- attention(_, _, H, A, B, _).
kb_link_(A, B, attention(H)) :- attention(_, _, H, B, A, _).

%   kb_fact_(+Fact): Fact, for facts a KB may lack altogether: fails, rather
%   than raising an existence error, when no predicate of Fact's name and
%   arity is visible (as if it were declared dynamic).
kb_fact_(Fact) :-
    current_predicate(_, Fact),
    call(Fact).
