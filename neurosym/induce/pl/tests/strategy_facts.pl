/*  strategy_facts.pl -- hand-written states for strategy_features.plt and strategy_route.plt.

    Episode 0 (RGW, 3 x 5): state 0 as drawn; in state 1 the agent stands at
    (1,1) holding the sword, which is gone from the map.
          c0 c1 c2 c3 c4
      r0   A  S  W  .  T       A agent, S sword, T terminal, W wall
      r1   .  .  W  .  .       X teleport_1, Y teleport_2, E enemy
      r2   X  .  W  Y  E
    Episode 1 (Box-World, 3 x 6): state 0 as drawn; in state 1 the agent
    holds key(blue).
          c0 c1 c2 c3 c4 c5
      r0   A  .  b  .  g  R    b key_blue (loose), g gem in lock_red R's box
      r1   .  .  .  .  r  B    r key_red in lock_blue B's box
      r2   k  .  .  .  .  .    k key_green (loose, no green lock)
    Episode 2 (RGW, 2 x 4): the route through the teleport is as long as the
    one without.
          c0 c1 c2 c3
      r0   A  .  .  T
      r1   X  .  Y  .
    Network facts (PrediNet attends/8, holds/5; MHDPA attention/6) of
    episode 0, state 0.
*/

:- dynamic object/2, at/5, holding/3, terrain/4, grid/3, attends/8, holds/5, attention/6.
:- discontiguous at/5, holding/3, terrain/4, grid/3.

object(sword, sword).
object(terminal, terminal).
object(enemy, enemy).
object(teleport_1, teleport).
object(teleport_2, teleport).
object(key_blue, key(blue)).
object(key_red, key(red)).
object(key_green, key(green)).
object(lock_red, lock(red)).
object(lock_blue, lock(blue)).
object(gem, gem).

grid(0, 3, 5).
terrain(0, wall, R, 2) :- between(0, 2, R).
at(0, 0, agent, 0, 0).
at(0, 0, sword, 0, 1).
at(0, 1, agent, 1, 1).
holding(0, 1, sword).
at(0, T, terminal, 0, 4) :- member(T, [0, 1]).
at(0, T, teleport_1, 2, 0) :- member(T, [0, 1]).
at(0, T, teleport_2, 2, 3) :- member(T, [0, 1]).
at(0, T, enemy, 2, 4) :- member(T, [0, 1]).

attends(0, 0, 1, 1, sword, 0, 1, 0.8).
attends(0, 0, 1, 2, terminal, 0, 4, 0.6).
holds(0, 0, r(3), sword, enemy).
attention(0, 0, 2, agent, terminal, 0.7).
attention(0, 0, 2, sword, terminal, 0.3).
attention(0, 0, 2, enemy, agent, 0.5).

grid(1, 3, 6).
at(1, T, agent, 0, 0) :- member(T, [0, 1]).
at(1, T, key_blue, 0, 2) :- member(T, [0, 1]).
at(1, T, gem, 0, 4) :- member(T, [0, 1]).
at(1, T, lock_red, 0, 5) :- member(T, [0, 1]).
at(1, T, key_red, 1, 4) :- member(T, [0, 1]).
at(1, T, lock_blue, 1, 5) :- member(T, [0, 1]).
at(1, T, key_green, 2, 0) :- member(T, [0, 1]).
holding(1, 1, key(blue)).

grid(2, 2, 4).
at(2, 0, agent, 0, 0).
at(2, 0, terminal, 0, 3).
at(2, 0, teleport_1, 1, 0).
at(2, 0, teleport_2, 1, 2).
