/*  rgw.pl -- Relational-Grid-World: what the agent did, and what its network relates.

    Load it beside a neurosym knowledge base:  swipl kb.pl rules/rgw.pl

    Behavioural rules read the recorded trace:
        episode/4, event/3 (picked(sword), teleported, defeated(enemy),
        hurt_by(enemy), reached(terminal), fell(pit)), holding/3.
    optimal_visits/2 holds each level's optimal visit order (the env's
    solver), which optimal_order/1 compares the agent's with.
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
            optimal_visit_order/2,
            off_optimal_order/3,
            orders_sword_before_enemy/1,
            sword_enemy_direct/1,
            sword_enemy_via/1,
            sword_enemy_link/1,
            armed_enemy_link/1
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
%   Episode visited the key objects in the order of its level's optimal
%   route: its visit_order/2 equals its optimal_visits/2 fact, the order in
%   which the env's own solver (neurosym/envs/rgw_solver.py, playing the
%   level's best return) first reaches them. On rgw2 that is sword, teleport,
%   enemy, terminal; on rgw1 and procedural levels it is whatever their map
%   asks. An episode without the fact (a KB recorded before it, a level the
%   solver cannot search) is never answered.
%
%       ?- optimal_order(E).
%       E = 0.

optimal_order(E) :-
    optimal_visit_order(E, Optimal),
    visit_order(E, Optimal).

%!  optimal_visit_order(?Episode, -Order:list) is nondet.
%
%   Order is the key objects of Episode's level in the order its optimal
%   route first reaches them (the KB's optimal_visits/2 fact, written by
%   the recorder from the env's solver). Deterministic when Episode is bound.
%
%       ?- optimal_visit_order(0, O).
%       O = [sword, teleport, enemy, terminal].

optimal_visit_order(E, Order) :-
    kb_episode_(E),
    kb_fact_(optimal_visits(E, Order)).

%!  off_optimal_order(?Episode, -Visited:list, -Optimal:list) is nondet.
%
%   Episode's level has an optimal visit order (optimal_visits/2) and the
%   agent visited the key objects in another one.
%
%       ?- off_optimal_order(1, V, O).
%       V = [teleport, enemy, sword, terminal],
%       O = [sword, teleport, enemy, terminal].

off_optimal_order(E, Visited, Optimal) :-
    optimal_visit_order(E, Optimal),
    visit_order(E, Visited),
    Visited \== Optimal.

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
%   The network relates sword and enemy directly at some state: some head
%   attended the pair {sword, enemy} with relation Link above threshold
%   (Link = r(J), PrediNet), or some MHDPA head's strongest key for one of
%   them is the other (Link = attention(Head)). Each Link once.
%
%       ?- sword_enemy_direct(L).
%       L = r(1).

sword_enemy_direct(Link) :-
    distinct(Link, kb_link_(sword, enemy, Link)).

%!  sword_enemy_via(?Object) is nondet.
%
%   The network relates the sword to Object and Object to the enemy at one
%   state, or at two consecutive states of one episode (either orientation,
%   any relation or head): Object may carry the link between them. Object is
%   another entity type that occurs as an object, or the agent. Answered most
%   states first (see sword_enemy_link/1), whether or not a direct link
%   exists too.
%
%       ?- sword_enemy_via(X).
%       X = teleport.

sword_enemy_via(X) :-
    kb_thirds_([sword], [sword], [enemy], SStates),
    kb_thirds_([enemy], [sword], [enemy], EStates),
    kb_via_(SStates, EStates, 0, Near, _),
    member(via(X, _), Near).

%!  sword_enemy_link(-Answer) is det.
%
%   How the network relates sword and enemy, state by state. Every share is
%   share(N, D): N states out of the D states the agent acted in, over all
%   episodes (D is the sum of episode/4's Steps: states 0..Steps-1 of each
%   episode, those with a step/4 fact and the network's outputs).
%
%     * direct(Links, share(N, D)): some Link (r(J) or attention(Head))
%       relates sword and enemy at one state; N states have such a link.
%     * indirect(Vias), when no state has a direct link: Vias lists
%       via(Object, share(N, D)), most states first. The network relates the
%       sword to Object and Object to the enemy at one state or at two
%       consecutive states of one episode; N counts the states at which one
%       of the two links holds and the other holds at that state, the one
%       before or the one after.
%     * co_occurring(Vias), when no Object does that: Vias lists
%       apart(Object, share(NS, D), share(NE, D)): Object is related to the
%       sword on NS states and to the enemy on NE states, but never at one
%       state or two consecutive ones: the two links only share the recording.
%     * none: neither is related to a common object at all.
%
%       ?- sword_enemy_link(A).
%       A = direct([r(1), r(0)], share(4, 124)).

sword_enemy_link(Answer) :-
    kb_link_answer_([sword], [enemy], Answer).

%!  armed_enemy_link(-Share) is det.
%
%   How often the network relates the enemy to the sword the agent carries,
%   state by state, between taking the sword and meeting the enemy. A picked
%   sword leaves the map (no at/5, no entity named sword): it is a plane of
%   the agent's own cell, so a sword-enemy relation there is one between the
%   agent and the enemy. Share is share(N, D): D counts the states from the
%   one after the sword was picked to the one whose action first meets the
%   enemy after it, in which the agent holds the sword (holding/3), over
%   every episode that did both; N those at which some link (r(J) or
%   attention(Head)) relates agent and enemy. share(0, 0) when no episode
%   took the sword and then met the enemy.
%
%       ?- armed_enemy_link(S).
%       S = share(1, 3).

armed_enemy_link(share(N, D)) :-
    findall(E-T, armed_state_(E, T), States),
    length(States, D),
    aggregate_all(count,
                  ( member(E-T, States), once(kb_link_at_(E, T, agent, enemy, _)) ),
                  N).

%   armed_state_(-E, -T): state T of episode E lies after the sword was
%   picked and up to the first meeting with the enemy after that, and the
%   agent holds the sword there.
armed_state_(E, T) :-
    kb_episode_(E),
    kb_first_event_(E, picked(sword), Tp),
    aggregate_all(min(T1), ( event(E, T1, Ev), meets_enemy_(Ev), T1 > Tp ), Te),
    Tp1 is Tp + 1,
    between(Tp1, Te, T),
    holding(E, T, sword).

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

