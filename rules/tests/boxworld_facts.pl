/*  boxworld_facts.pl -- a hand-written Box-World KB for boxworld.plt.

    Episodes 0 and 1 share one map (row, col at state 0):
        loose key(red) (2,3); box lock(red) (5,6) holding key(blue) (5,5);
        box lock(blue) (8,8) holding gem (8,7); distractor box lock(red)
        (10,3) holding key(green) (10,2).
      0  key(red), opens lock(red) -> key(blue), opens lock(blue) -> gem
      1  key(red), opens the distractor lock(red) -> key(green), ends
    Episode 2: loose key(yellow) (3,3), box lock(yellow) (6,6) holding the
    gem (6,5); nothing happens until the timeout.
    holding/3 and attends/8 are given only at the states the tests look at.
*/

:- dynamic kb_meta/2, object/2, episode/4, step/4, at/5, holding/3, event/3,
           attends/8, relation/7, holds/5, threshold/2, attention/6.

object(agent, agent).
object(gem, gem).
object(key_blue, key(blue)).
object(key_green, key(green)).
object(key_red, key(red)).
object(key_yellow, key(yellow)).
object(lock_blue, lock(blue)).
object(lock_red, lock(red)).
object(lock_red_2, lock(red)).
object(lock_yellow, lock(yellow)).

episode(0, 12, 12.0, gem).
episode(1, 5, -1.0, distractor).
episode(2, 300, 0.0, timeout).

at(0, 0, agent, 1, 1).
at(0, 0, key_red, 2, 3).
at(0, 0, key_blue, 5, 5).
at(0, 0, lock_red, 5, 6).
at(0, 0, gem, 8, 7).
at(0, 0, lock_blue, 8, 8).
at(0, 0, key_green, 10, 2).
at(0, 0, lock_red_2, 10, 3).
at(0, 1, agent, 1, 2).
at(1, 0, agent, 1, 1).
at(1, 0, key_red, 2, 3).
at(1, 0, key_blue, 5, 5).
at(1, 0, lock_red, 5, 6).
at(1, 0, gem, 8, 7).
at(1, 0, lock_blue, 8, 8).
at(1, 0, key_green, 10, 2).
at(1, 0, lock_red_2, 10, 3).
at(2, 0, agent, 11, 11).
at(2, 0, key_yellow, 3, 3).
at(2, 0, gem, 6, 5).
at(2, 0, lock_yellow, 6, 6).

event(0, 3, got(key(red))).
event(0, 7, opened(lock(red))).
event(0, 7, got(key(blue))).
event(0, 12, opened(lock(blue))).
event(0, 12, got(gem)).
event(1, 2, got(key(red))).
event(1, 5, opened(lock(red))).
event(1, 5, got(key(green))).
event(1, 5, hit(distractor)).

holding(0, 4, key(red)).
holding(0, 5, key(red)).
holding(0, 7, key(red)).
holding(0, 12, key(blue)).
holding(1, 5, key(red)).

attends(0, 4, 0, 1, empty, 3, 3, 0.25).
attends(0, 4, 1, 2, lock(red), 5, 6, 0.75).
attends(0, 4, 1, 1, lock(red), 5, 6, 0.5).
attends(0, 5, 0, 1, key(blue), 5, 5, 0.5).
attends(0, 12, 2, 1, lock(red), 10, 3, 0.5).

holds(0, 2, r(1), key(red), lock(red)).
holds(0, 5, r(0), held(red), lock(green)).
holds(0, 9, r(2), lock(blue), held(blue)).
