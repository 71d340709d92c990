/*  armed_link.pl -- how often an RGW network relates the enemy to the sword it carries.

    Once picked, the sword leaves the map (no at/5, no entity named sword): it is a plane of
    the agent's own cell. So "sword and enemy in one state" between taking the sword and
    meeting the enemy can only be the agent that holds it and the enemy. Loaded beside a KB:

        neurosym query --kb kb.pl --rules experiments/armed_link.pl 'armed_link(A)'

    armed_link(share(N, D)): D counts the states from the one after the sword was picked to
    the one whose action meets the enemy, over every episode that did both; N those with a
    relation (holds/5, either orientation) between agent and enemy while holding(E, T, sword).
    sword_link(share(N, D)): the same states with a sword-enemy relation (0: no sword entity).
*/

armed_link(share(N, D)) :-
    armed_states(States),
    length(States, D),
    aggregate_all(count, ( member(E-T, States), related(E, T, agent, enemy) ), N).

sword_link(share(N, D)) :-
    armed_states(States),
    length(States, D),
    aggregate_all(count, ( member(E-T, States), related(E, T, sword, enemy) ), N).

armed_states(States) :-
    findall(E-T,
            ( episode(E, _, _, _),
              aggregate_all(min(T0), event(E, T0, picked(sword)), Tp),
              aggregate_all(min(T1), ( event(E, T1, Ev), meets_enemy(Ev), T1 > Tp ), Te),
              Tp1 is Tp + 1,
              between(Tp1, Te, T),
              holding(E, T, sword) ),
            States).

related(E, T, A, B) :- once(( holds(E, T, _, A, B) ; holds(E, T, _, B, A) )).

meets_enemy(defeated(enemy)).
meets_enemy(hurt_by(enemy)).
