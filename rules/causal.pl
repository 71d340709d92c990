/*  causal.pl -- does the agent's use of the enemy depend on the sword? Answers from experiments.

    Load it beside a KB written by `neurosym intervene`:
        swipl kb_out/intervene/kb.pl rules/causal.pl

    Facts it reads (docs/design.md, "Facts", controlled experiments):
        experiment(X, Kind, Detail)   Kind: baseline, remove(sword), remove(enemy),
                                      move(Obj, R, C), swap(sword, enemy), ablate(head(H)),
                                      ablate(heads)
        measure(X, Measure, Value)    absolute shares per experiment: enemy_met,
                                      enemy_unarmed, enemy_defeated, sword_before_enemy, ...
        effect(X, Measure, Change)    the same minus the baseline's
        relates(H, A, B, Share)       share of baseline states at which head H relates A and B

    The thesis (ch. 5) could only see that attention associates the sword and
    the enemy; these rules ask the experiments instead:

    * direct: the agent's use of the enemy depends on holding the sword -- it
      stops meeting the enemy when the sword is removed, meets it once it holds
      the sword, and never walks into it unarmed on any level tried -- or
      ablating a head that relates sword and enemy breaks sword-before-enemy;
    * correlational: it meets the enemy either way, with the sword on the
      baseline and unarmed on some level (the sword removed, moved or swapped);
    * none: no experiment says either.

    A change counts when it is at least causal_margin/1 (a share of episodes).

    A module (causal) whose helpers stay inside it. It reads the facts as
    unqualified goals, which resolve through its default import module:
    user in plain swipl, the KB's own module in neurosym.prolog.KnowledgeBase
    (which loads the rule modules once per KB, see lib/kb_common.pl). A KB
    without facts of one of the four predicates above is read as having none
    of them (kb_fact_/1), as when they are declared dynamic.
*/

:- module(causal,
          [ causal_margin/1,
            sword_enemy_cause/1,
            direct_evidence/1,
            correlational_evidence/1,
            level_experiment/2
          ]).

:- use_module(library(lists)).

:- include(lib/kb_common).

%!  causal_margin(-Share:float) is det.
%
%   The smallest share of episodes that counts as a behaviour, and the
%   smallest change of a share that counts as an effect.
%
%       ?- causal_margin(M).
%       M = 0.5.

causal_margin(0.5).

%!  sword_enemy_cause(-Answer) is det.
%
%   The thesis's question, answered from the experiments: direct(Evidence),
%   correlational(Evidence) or none. Evidence is the list of findings used,
%   each naming the facts it rests on (see direct_evidence/1 and
%   correlational_evidence/1).
%
%       ?- sword_enemy_cause(A).
%       A = correlational([meets_enemy_unarmed([measure(baseline,enemy_defeated,1.0),
%                                               measure(swap_sword_enemy,enemy_unarmed,1.0)])]).

sword_enemy_cause(Answer) :-
    findall(E, direct_evidence(E), Direct),
    (   Direct \== []
    ->  Answer = direct(Direct)
    ;   findall(E, correlational_evidence(E), Corr),
        (   Corr \== []
        ->  Answer = correlational(Corr)
        ;   Answer = none
        )
    ).

%!  direct_evidence(-Evidence) is nondet.
%
%   Evidence = avoids_enemy_without_sword(Facts): removing the sword makes the
%   agent stop meeting the enemy, it met it holding the sword on the baseline,
%   and no level made it meet the enemy unarmed.
%   Evidence = ablation_breaks_order(Facts): ablating head H, which relates
%   sword and enemy on the baseline, breaks sword-before-enemy.
%
%       ?- direct_evidence(E).
%       E = ablation_breaks_order([experiment(ablate_head_1,ablate(head(1))),
%                                  relates(1,enemy,sword,0.2), ...]).

direct_evidence(avoids_enemy_without_sword([measure(baseline, sword_before_enemy, B),
                                            effect(X, enemy_met, D)])) :-
    causal_margin(M),
    kb_fact_(measure(baseline, sword_before_enemy, B)),
    B >= M,
    kb_fact_(experiment(X, remove(sword), _)),
    kb_fact_(effect(X, enemy_met, D)),
    D =< -M,
    \+ unarmed_meeting_(_, _).
direct_evidence(ablation_breaks_order([experiment(X, ablate(head(H))),
                                       relates(H, A, B, S),
                                       measure(baseline, sword_before_enemy, B0),
                                       effect(X, sword_before_enemy, D)])) :-
    causal_margin(M),
    kb_fact_(measure(baseline, sword_before_enemy, B0)),
    B0 >= M,
    kb_fact_(experiment(X, ablate(head(H)), _)),
    relates_(H, A, B, S),
    S > 0,
    kb_fact_(effect(X, sword_before_enemy, D)),
    D =< -M.

%!  correlational_evidence(-Evidence) is nondet.
%
%   Evidence = meets_enemy_unarmed(Facts): the agent defeats the enemy with
%   the sword on the baseline and meets it unarmed on level X (one per X).
%
%       ?- correlational_evidence(E).
%       E = meets_enemy_unarmed([measure(baseline,enemy_defeated,1.0),
%                                measure(swap_sword_enemy,enemy_unarmed,1.0)]).

correlational_evidence(meets_enemy_unarmed([measure(baseline, enemy_defeated, B),
                                            measure(X, enemy_unarmed, V)])) :-
    causal_margin(M),
    kb_fact_(measure(baseline, enemy_defeated, B)),
    B >= M,
    unarmed_meeting_(X, V).

%!  level_experiment(?X, ?Kind) is nondet.
%
%   X changes the level (or is the baseline), as opposed to ablating heads.
%
%       ?- level_experiment(X, remove(sword)).
%       X = remove_sword.

level_experiment(X, Kind) :-
    kb_fact_(experiment(X, Kind, _)),
    level_kind_(Kind).

% ------------------------------------------------------------------ helpers

%   unarmed_meeting_(?X, ?Share): on level X the agent met the enemy
%   without the sword in at least causal_margin/1 of the episodes.
unarmed_meeting_(X, V) :-
    causal_margin(M),
    level_experiment(X, _),
    kb_fact_(measure(X, enemy_unarmed, V)),
    V >= M.

level_kind_(baseline).
level_kind_(remove(_)).
level_kind_(move(_, _, _)).
level_kind_(swap(_, _)).

%   relates_(?H, -A, -B, -Share): head H relates sword and enemy (either order).
relates_(H, sword, enemy, S) :- kb_fact_(relates(H, sword, enemy, S)).
relates_(H, enemy, sword, S) :- kb_fact_(relates(H, enemy, sword, S)).
