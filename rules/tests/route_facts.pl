/*  route_facts.pl -- hand-written states for route.plt.

    Episode 0 (RGW, 4 x 5), state 0; episode 1 adds an enemy at (2,1):
          c0 c1 c2 c3 c4
      r0   A  .  M  .  S       A agent, M mountain, W wall, S sword
      r1   .  W  .  W  .       P pit, T terminal, X teleport end
      r2   .  .  .  .  .
      r3   P  .  X  .  T
    Episode 2 (RGW, 1 x 4): A E . T; state 1 holds the sword.
    Episode 3 (Box-World, 3 x 5): the agent, a loose key in the way of the
    lock, the box's content left of its lock; state 1 holds key(red).
          c0 c1 c2 c3 c4
      r0   A  .  k  g  l       k key(blue) loose, g gem (content), l lock(red)
      r1   .  .  .  .  .
      r2   #  #  #  #  #       # wall
    Episode 4 (RGW, 3 x 5): a wall column; the teleport's ends on either side.
          c0 c1 c2 c3 c4
      r0   .  X  W  .  T
      r1   .  .  W  .  .
      r2   A  .  W  X  .
    Episode 5 (RGW, 1 x 4): A S . T, the sword between the agent and the
    terminal.
    Episode 10 (Minigrid, 3 x 4): the agent has a direction (facing/3);
    a locked yellow door, its key, the goal.
          c0 c1 c2 c3
      r0   A  .  k  .       A agent (state 0 facing north), k key(yellow)
      r1   .  W  D  .       W wall, D door(yellow) (locked; open in state 3)
      r2   .  .  .  G       G goal
    State 1: the agent at (0,1) facing east (the key ahead). State 2: at
    (2,2) facing north (the door ahead), holding key(yellow). State 3: the
    same, the door open.
*/

:- dynamic object/2, at/5, holding/3, terrain/4, grid/3, facing/3, door_state/4.
:- discontiguous at/5, holding/3, terrain/4, grid/3, facing/3, door_state/4.

object(sword, sword).
object(enemy, enemy).
object(terminal, terminal).
object(pit, pit).
object(teleport_1, teleport).
object(teleport_2, teleport).
object(key_blue, key(blue)).
object(lock_red, lock(red)).
object(gem, gem).
object(key_yellow, key(yellow)).
object(door_yellow, door(yellow)).
object(goal, goal).

grid(0, 4, 5).
grid(1, 4, 5).
grid(2, 1, 4).
grid(3, 3, 5).
grid(4, 3, 5).

terrain(E, mountain, 0, 2) :- member(E, [0, 1]).
terrain(E, wall, 1, 1) :- member(E, [0, 1]).
terrain(E, wall, 1, 3) :- member(E, [0, 1]).
terrain(3, wall, 2, C) :- between(0, 4, C).

at(E, 0, agent, 0, 0) :- member(E, [0, 1]).
at(E, 0, sword, 0, 4) :- member(E, [0, 1]).
at(E, 0, pit, 3, 0) :- member(E, [0, 1]).
at(E, 0, teleport_1, 3, 2) :- member(E, [0, 1]).
at(E, 0, terminal, 3, 4) :- member(E, [0, 1]).
at(1, 0, enemy, 2, 1).

at(2, T, agent, 0, 0) :- member(T, [0, 1]).
at(2, T, enemy, 0, 1) :- member(T, [0, 1]).
at(2, T, terminal, 0, 3) :- member(T, [0, 1]).
holding(2, 1, sword).

at(3, T, agent, 0, 0) :- member(T, [0, 1]).
at(3, T, key_blue, 0, 2) :- member(T, [0, 1]).
at(3, T, gem, 0, 3) :- member(T, [0, 1]).
at(3, T, lock_red, 0, 4) :- member(T, [0, 1]).
holding(3, 1, key(red)).

terrain(4, wall, R, 2) :- between(0, 2, R).
at(4, 0, agent, 2, 0).
at(4, 0, teleport_1, 0, 1).
at(4, 0, teleport_2, 2, 3).
at(4, 0, terminal, 0, 4).

grid(5, 1, 4).
at(5, 0, agent, 0, 0).
at(5, 0, sword, 0, 1).
at(5, 0, terminal, 0, 3).

:- dynamic searched_/5, grid_/4, cache_key_/2.

% Facts named like module route's own memos, here from the start, in the
% module the facts load into: planted answers that must never be seen
% (route.plt's answers would change).
searched_(0, 1, _, [], cells(0)).
grid_(0, 1, 1, cells(wall)).
grid_(4, 1, 1, cells(wall)).
cache_key_(routes, nowhere).
cache_key_(moves, nowhere).

% Episode 10: Minigrid, 3 x 4.
grid(10, 3, 4).
terrain(10, wall, 1, 1).
at(10, 0, agent, 0, 0).
at(10, 0, key_yellow, 0, 2).
at(10, 0, door_yellow, 1, 2).
at(10, 0, goal, 2, 3).
facing(10, 0, north).
door_state(10, 0, door_yellow, locked).
at(10, 1, agent, 0, 1).
at(10, 1, key_yellow, 0, 2).
at(10, 1, door_yellow, 1, 2).
at(10, 1, goal, 2, 3).
facing(10, 1, east).
door_state(10, 1, door_yellow, locked).
at(10, 2, agent, 2, 2).
at(10, 2, door_yellow, 1, 2).
at(10, 2, goal, 2, 3).
facing(10, 2, north).
holding(10, 2, key(yellow)).
door_state(10, 2, door_yellow, locked).
at(10, 3, agent, 2, 2).
at(10, 3, door_yellow, 1, 2).
at(10, 3, goal, 2, 3).
facing(10, 3, north).
holding(10, 3, key(yellow)).
door_state(10, 3, door_yellow, open).
