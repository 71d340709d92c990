/*  world_minigrid_facts.pl -- hand-written states for world_background_minigrid.plt.

    Episode 0 (4 x 4, walls all round), one room:
          c0 c1 c2 c3
      r0   W  W  W  W       W wall, k key(yellow), D door(yellow)
      r1   W  .  k  W
      r2   W  .  D  W
      r3   W  W  W  W
    state 0: agent at (1,1) facing east (the key), empty-handed: pickup;
    state 1: at (1,1) facing east (now empty), carrying the key: right;
    state 2: at (1,1) facing south (empty): forward;
    state 3: at (2,1) facing south (a wall): left;
    state 4: at (2,1) facing east (the locked door): toggle;
    state 5: at (2,1) facing east (the door, now open): no step (the episode ended).
*/

:- dynamic step/4, at/5, object/2, holding/3, facing/3, door_state/4, terrain/4, grid/3.

object(agent, agent).
object(key_yellow, key(yellow)).
object(door_yellow, door(yellow)).

grid(0, 4, 4).
terrain(0, wall, R, C) :-
    between(0, 3, R), between(0, 3, C),
    ( R =:= 0 ; R =:= 3 ; C =:= 0 ; C =:= 3 ).

step(0, 0, pickup, 0.0).
step(0, 1, right, 0.0).
step(0, 2, forward, 0.0).
step(0, 3, left, 0.0).
step(0, 4, toggle, 0.0).

at(0, T, agent, 1, 1) :- between(0, 2, T).
at(0, T, agent, 2, 1) :- between(3, 5, T).
at(0, 0, key_yellow, 1, 2).
at(0, T, door_yellow, 2, 2) :- between(0, 5, T).

facing(0, 0, east).
facing(0, 1, east).
facing(0, 2, south).
facing(0, 3, south).
facing(0, 4, east).
facing(0, 5, east).

holding(0, T, key(yellow)) :- between(1, 5, T).

door_state(0, T, door_yellow, locked) :- between(0, 4, T).
door_state(0, 5, door_yellow, open).
