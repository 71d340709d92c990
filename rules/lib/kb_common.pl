:- module(kb_common,
          [ kb_episode/2,       % +M, ?Episode
            kb_first_event/4,   % +M, +Episode, +Event, -T
            kb_event/3,         % +M, +Episode, +Event
            kb_link/4,          % +M, ?A, ?B, -Link
            kb_fact/2           % +M, +Fact
          ]).

/** <module> What the rule modules share: lookups in a knowledge base's facts

The rule files (rgw.pl, boxworld.pl, relations.pl, causal.pl, meaning.pl) are
modules, loaded once per process. A knowledge base's facts live in some other
module: =user= when a KB is consulted in plain swipl (=|swipl kb.pl
rules/rgw.pl|=), a module of its own when neurosym.prolog.KnowledgeBase
holds it (several KBs may be open in one process). Each rule module's
exported predicates are module transparent: they take the facts' module
from context_module/1, that is from the module they were called from, and
pass it on. The helpers here take that module (M) first and read the facts
with M:Goal.

This file is not a rule file to load beside a KB: the rule files load it
themselves (=|:- use_module(lib/kb_common)|=, relative to their folder).
*/

:- use_module(library(aggregate), [aggregate_all/3]).

%!  kb_episode(+M, ?Episode) is nondet.
%
%   Episode is an episode of the KB in module M (episode/4), in episode order.

kb_episode(M, E) :-
    M:episode(E, _, _, _).

%!  kb_first_event(+M, +Episode, +Event, -T) is semidet.
%
%   T is the first time Event happened in Episode; fails when it never did.
%
%   Speed: events are looked up by episode only (event(E, T, Ev) with E
%   bound, then Ev compared), so SWI-Prolog builds one just-in-time index on
%   the first argument of event/3, and no composite index on (E, Event),
%   whose construction dominated the first call over large KBs.

kb_first_event(M, E, Event, T) :-
    aggregate_all(min(T0), ( M:event(E, T0, Ev), Ev == Event ), T).

%!  kb_event(+M, +Episode, +Event) is semidet.
%
%   Event happened in Episode (looked up by episode only, see
%   kb_first_event/4).

kb_event(M, E, Event) :-
    once(( M:event(E, _, Ev), Ev == Event )).

%!  kb_link(+M, ?A, ?B, -Link) is nondet.
%
%   The network relates entities A and B, in either orientation: Link =
%   r(J) when holds(_, _, r(J), A, B) or holds(_, _, r(J), B, A) (PrediNet,
%   above threshold), Link = attention(Head) when MHDPA head Head's
%   strongest key for one of them is the other (attention/6). One answer per
%   fact, holds/5 before attention/6.

kb_link(M, A, B, R) :- M:holds(_, _, R, A, B).
kb_link(M, A, B, R) :- M:holds(_, _, R, B, A).
kb_link(M, A, B, attention(H)) :- M:attention(_, _, H, A, B, _).
kb_link(M, A, B, attention(H)) :- M:attention(_, _, H, B, A, _).

%!  kb_fact(+M, +Fact) is nondet.
%
%   Fact, a fact of the KB in module M, for facts a KB may lack altogether:
%   fails, rather than raising an existence error, when M (or a module it
%   inherits from, such as =user=) has no predicate of Fact's name and arity.

kb_fact(M, Fact) :-
    current_predicate(_, M:Fact),
    M:Fact.
