/*  rgw.pl -- Relational-Grid-World: what the agent did, and what its network relates.

    Load it beside a neurosym knowledge base:  swipl kb.pl rules/rgw.pl

    Behavioural rules read the recorded trace:
        episode/4, event/3 (picked(sword), teleported, defeated(enemy),
        hurt_by(enemy), reached(terminal), fell(pit)), holding/3.
    Representational rules read the network's facts:
        holds/5 (PrediNet, thresholded and oriented so the value is positive),
        attention/6 (MHDPA, strongest keys per query), object/2.
    A neurosym KB declares every schema predicate dynamic, so a rule over facts
    the KB has none of fails instead of raising an existence error.

    Time: event(E, T, Ev) is the transition from state T to T+1, so "before"
    compares those T. Meeting the enemy is defeated(enemy) or hurt_by(enemy).

    A module (rgw) whose helpers stay inside it, so it loads beside the
    other rule files without clashes. It reads the facts as unqualified
    goals, which resolve through its default import module: user in plain
    swipl, the KB's own module in neurosym.prolog.KnowledgeBase (which loads
    the rule modules once per KB, see lib/kb_common.pl).
*/

:- module(rgw,
          [ sword_before_enemy/1,
            teleport_before_enemy/1,
            enemy_beaten_with_sword/1,
            visit_order/2,
            optimal_order/1,
            orders_sword_before_enemy/1,
            sword_enemy_direct/1,
            sword_enemy_via/1,
            sword_enemy_link/1
          ]).

:- use_module(library(lists)).
:- use_module(library(pairs)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).

:- include(lib/kb_common).

%!  sword_before_enemy(?Episode) is nondet.
%
%   In Episode the agent picked up the sword and then met the enemy, having
%   not met it before. Each episode is answered once, in episode order.
%
%       ?- sword_before_enemy(E).
%       E = 0 ;
%       E = 3.

sword_before_enemy(E) :-
    kb_episode_(E),
    kb_first_event_(E, picked(sword), Ts),
    first_enemy_(E, Te),
    Ts < Te.

%!  teleport_before_enemy(?Episode) is nondet.
%
%   In Episode the agent went through a teleport before it first met the enemy.
%
%       ?- teleport_before_enemy(0).
%       true.

teleport_before_enemy(E) :-
    kb_episode_(E),
    kb_first_event_(E, teleported, Tt),
    first_enemy_(E, Te),
    Tt < Te.

%!  enemy_beaten_with_sword(?Episode) is nondet.
%
%   In Episode the agent defeated the enemy while holding the sword (in the
%   state the defeating step started from). Each episode once.
%
%       ?- enemy_beaten_with_sword(E).
%       E = 0.

enemy_beaten_with_sword(E) :-
    kb_episode_(E),
    once(( event(E, T, Event),
           Event == defeated(enemy),
           holding(E, T1, Item),
           T1 == T,
           Item == sword )).

%!  visit_order(?Episode, -Order:list) is nondet.
%
%   Order lists the key objects (sword, teleport, enemy, terminal, pit) in the
%   order Episode first reached them, read from the events. Deterministic when
%   Episode is bound.
%
%       ?- visit_order(0, Order).
%       Order = [sword, teleport, enemy, terminal].

visit_order(E, Order) :-
    kb_episode_(E),
    findall(T-Object, ( event(E, T, Event), visit_(Event, Object) ), Pairs0),
    keysort(Pairs0, Pairs),
    pairs_values(Pairs, Objects),
    list_to_set(Objects, Order).

%!  optimal_order(?Episode) is nondet.
%
%   Episode visited the key objects in the order of the optimal route of
%   Configuration-2 (thesis, figure 9): sword, teleport, enemy, terminal.
%
%       ?- optimal_order(E).
%       E = 0.

optimal_order(E) :-
    visit_order(E, [sword, teleport, enemy, terminal]).

%!  orders_sword_before_enemy(?Relation) is nondet.
%
%   Relation (r(J) for PrediNet) holds from sword to enemy at least once above
%   its threshold and never from enemy to sword: it consistently orders the
%   sword before the enemy.
%
%       ?- orders_sword_before_enemy(R).
%       R = r(1).

orders_sword_before_enemy(R) :-
    distinct(R, holds(_, _, R, sword, enemy)),
    \+ holds(_, _, R, enemy, sword).

%!  sword_enemy_direct(?Link) is nondet.
%
%   The network relates sword and enemy directly: some head attended the pair
%   {sword, enemy} with relation Link above threshold (Link = r(J), PrediNet),
%   or some MHDPA head's strongest key for one of them is the other
%   (Link = attention(Head)). Each Link once.
%
%       ?- sword_enemy_direct(L).
%       L = r(1).

sword_enemy_direct(Link) :-
    distinct(Link, kb_link_(sword, enemy, Link)).

%!  sword_enemy_via(?Object) is nondet.
%
%   The network relates the sword to Object and Object to the enemy (either
%   orientation, any relation or head, anywhere in the KB): Object may carry
%   the link between them. Object is another entity type that occurs as an
%   object or is the agent. Each Object once.
%
%       ?- sword_enemy_via(X).
%       X = agent ;
%       X = teleport.

sword_enemy_via(X) :-
    entity_type_(X),
    X \== sword,
    X \== enemy,
    once(kb_link_(sword, X, _)),
    once(kb_link_(X, enemy, _)).

%!  sword_enemy_link(-Answer) is det.
%
%   How the network relates sword and enemy: direct(Links) when it relates
%   them directly (the list of links), otherwise indirect(Objects) when only
%   through other objects, otherwise none.
%
%       ?- sword_enemy_link(A).
%       A = direct([r(1), r(0)]).

sword_enemy_link(Answer) :-
    findall(L, sword_enemy_direct(L), Links),
    (   Links \== []
    ->  Answer = direct(Links)
    ;   findall(X, sword_enemy_via(X), Xs),
        (   Xs \== []
        ->  Answer = indirect(Xs)
        ;   Answer = none
        )
    ).

% ------------------------------------------------------------------ helpers
%
% Episodes, first events and the network's links: lib/kb_common.pl.

%   first_enemy_(+E, -T): the first time the agent met the enemy in E.
first_enemy_(E, T) :-
    aggregate_all(min(T0), ( event(E, T0, Ev), meets_enemy_(Ev) ), T).

meets_enemy_(defeated(enemy)).
meets_enemy_(hurt_by(enemy)).

%   visit_(+Event, -Object): the key object an event reaches.
visit_(picked(sword), sword).
visit_(teleported, teleport).
visit_(defeated(enemy), enemy).
visit_(hurt_by(enemy), enemy).
visit_(reached(terminal), terminal).
visit_(fell(pit), pit).

%   entity_type_(-Type): object types of the map, and the agent; each once.
entity_type_(Type) :-
    distinct(Type, ( Type = agent ; object(_, Type) )).
