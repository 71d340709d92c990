/*  world_facts.pl -- hand-written states for world_background.plt.

    Episode 0 (3 x 3), the same map in every state:
          c0 c1 c2
      r0   .  .  S         S sword, T terminal
      r1   .  W  .         W wall, M mountain
      r2   M  .  T
    state 0: agent at (0,0), up (off the map); state 1: agent at (0,1),
    right (onto the sword); state 2: agent at (1,0), down (onto the
    mountain); state 3: agent at (0,1), down (into the wall).
*/

:- dynamic step/4, at/5, object/2, terrain/4, grid/3.

object(sword, sword).
object(terminal, terminal).

grid(0, 3, 3).
terrain(0, wall, 1, 1).
terrain(0, mountain, 2, 0).

step(0, 0, up, 0.0).
step(0, 1, right, 0.0).
step(0, 2, down, -0.1).
step(0, 3, down, 0.0).

at(0, 0, agent, 0, 0).
at(0, 1, agent, 0, 1).
at(0, 2, agent, 1, 0).
at(0, 3, agent, 0, 1).
at(0, T, sword, 0, 2) :- between(0, 3, T).
at(0, T, terminal, 2, 2) :- between(0, 3, T).
