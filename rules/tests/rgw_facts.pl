/*  rgw_facts.pl -- a hand-written Relational-Grid-World KB for rgw.plt.

    Episodes (events only where they matter):
      0  optimal: sword, teleport, enemy (beaten), terminal
      1  teleport, hurt by the enemy, back for the sword, enemy beaten, terminal
      2  sword, then a pit
      3  sword, teleport, enemy beaten, then timeout
      4  nothing happens, timeout
    optimal_visits/2 gives rgw2's optimal order for episodes 0-3 and none
    for episode 4 (a level the solver could not search).
    Network facts relate sword and enemy directly (r(1), r(0)) and also
    through the teleport and the agent; through `empty`, which is no object
    type of the map, must not count.
*/

:- dynamic kb_meta/2, object/2, episode/4, step/4, at/5, holding/3, event/3,
           attends/8, relation/7, holds/5, threshold/2, attention/6,
           optimal_visits/2.

kb_meta(env, rgw2).
kb_meta(module, predinet).

object(enemy, enemy).
object(pit_7_8, pit).
object(sword, sword).
object(teleport_3_9, teleport).
object(teleport_8_8, teleport).
object(terminal, terminal).

episode(0, 14, 11.8, terminal).
episode(1, 23, 9.7, terminal).
episode(2, 7, -1.1, pit).
episode(3, 40, 0.8, timeout).
episode(4, 40, -0.5, timeout).

optimal_visits(0, [sword, teleport, enemy, terminal]).
optimal_visits(1, [sword, teleport, enemy, terminal]).
optimal_visits(2, [sword, teleport, enemy, terminal]).
optimal_visits(3, [sword, teleport, enemy, terminal]).

event(0, 3, picked(sword)).
event(0, 8, teleported).
event(0, 12, defeated(enemy)).
event(0, 13, reached(terminal)).
event(1, 5, teleported).
event(1, 7, hurt_by(enemy)).
event(1, 10, teleported).
event(1, 14, picked(sword)).
event(1, 18, teleported).
event(1, 21, defeated(enemy)).
event(1, 22, reached(terminal)).
event(2, 2, picked(sword)).
event(2, 6, fell(pit)).
event(3, 3, picked(sword)).
event(3, 6, teleported).
event(3, 9, defeated(enemy)).

holding(0, 12, sword).
holding(1, 21, sword).
holding(3, 9, sword).

holds(0, 2, r(1), sword, enemy).
holds(0, 5, r(1), sword, enemy).
holds(1, 3, r(0), enemy, sword).
holds(1, 4, r(0), sword, enemy).
holds(0, 1, r(2), sword, teleport).
holds(0, 1, r(2), teleport, enemy).
holds(2, 0, r(3), agent, sword).
holds(2, 0, r(3), enemy, agent).
holds(3, 1, r(0), sword, empty).
holds(3, 1, r(0), empty, enemy).
