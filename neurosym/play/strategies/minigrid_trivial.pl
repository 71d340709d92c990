/*  minigrid_trivial.pl -- the trivial Minigrid strategy: always the goal. A
    floor to compare a strategy with (`neurosym play --compare trivial`):
    what route.pl alone makes of the levels, going straight for the goal
    (on DoorKey the locked door stands in the way, so with --fallback none
    those levels fail).
*/
%! features: world

goal(_, _, goal).
