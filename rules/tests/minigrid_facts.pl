/*  minigrid_facts.pl -- a hand-written Minigrid / BabyAI KB for minigrid.plt.

    0  DoorKey: picks up key(yellow) at 1, unlocks and opens door(yellow) at
       4 holding it, reaches the goal at 8.
    1  BabyAI "pick up the red ball": picks up ball(red) at 3, mission done.
    2  BabyAI "go to the blue key": ends at (2, 2) facing east, key(blue) at
       (2, 3), mission done.
    3  BabyAI "open the green door": opens the closed door(green) at 2 (no
       key needed), mission done.
    4  two doors: key(blue) picked at 1, door(blue) unlocked at 3, the key
       dropped at 4, key(red) picked at 6, door(red) unlocked at 8; timeout.
    5  "go to the red box": the agent carries key(purple) from the start and
       unlocks door(purple) at 2 (no pick-up event); timeout.
    holding/3, facing/3 and at/5 are given only at the states the rules read.
*/

:- dynamic kb_meta/2, object/2, episode/4, step/4, at/5, holding/3, event/3,
           facing/3, door_state/4, mission/2,
           attends/8, relation/7, holds/5, threshold/2, attention/6.

object(agent, agent).
object(ball_red, ball(red)).
object(door_blue, door(blue)).
object(door_green, door(green)).
object(door_purple, door(purple)).
object(door_red, door(red)).
object(door_yellow, door(yellow)).
object(goal, goal).
object(key_blue, key(blue)).
object(key_red, key(red)).
object(key_yellow, key(yellow)).

episode(0, 9, 0.9676, goal).
episode(1, 4, 0.95, mission).
episode(2, 6, 0.93, mission).
episode(3, 3, 0.96, mission).
episode(4, 40, 0.0, timeout).
episode(5, 40, 0.0, timeout).

mission(0, 'use the key to open the door and then get to the goal').
mission(1, 'pick up the red ball').
mission(2, 'go to the blue key').
mission(3, 'open the green door').
mission(4, 'use the key to open the door and then get to the goal').
mission(5, 'go to the red box').

event(0, 0, bumped(key(yellow))).
event(0, 1, picked(key(yellow))).
event(0, 4, unlocked(door(yellow))).
event(0, 4, opened(door(yellow))).
event(0, 8, reached(goal)).
event(0, 8, achieved(mission)).
event(1, 3, picked(ball(red))).
event(1, 3, achieved(mission)).
event(2, 5, achieved(mission)).
event(3, 2, opened(door(green))).
event(3, 2, achieved(mission)).
event(4, 1, picked(key(blue))).
event(4, 3, unlocked(door(blue))).
event(4, 3, opened(door(blue))).
event(4, 4, dropped(key(blue))).
event(4, 6, picked(key(red))).
event(4, 8, unlocked(door(red))).
event(4, 8, opened(door(red))).
event(5, 2, unlocked(door(purple))).
event(5, 2, opened(door(purple))).

holding(0, 4, key(yellow)).
holding(4, 3, key(blue)).
holding(4, 8, key(red)).
holding(5, 2, key(purple)).

door_state(0, 3, door_yellow, locked).
door_state(0, 5, door_yellow, open).

at(2, 6, agent, 2, 2).
at(2, 6, key_blue, 2, 3).
at(5, 40, agent, 1, 1).

facing(2, 6, east).
facing(5, 40, south).

holds(0, 3, r(1), key(yellow), door(yellow)).
holds(0, 4, r(2), door(yellow), key(yellow)).
holds(0, 5, r(1), key(yellow), door(yellow)).
holds(4, 2, r(0), key(red), door(blue)).
attention(4, 5, 1, key(blue), door(blue), 0.8).
