/*  rgw_trivial.pl -- the trivial Relational-Grid-World strategy: always the
    terminal. A floor to compare a strategy with (`neurosym play --compare
    trivial`): what route.pl alone makes of the levels, going straight for
    the end (with --fallback none, the levels whose terminal no route
    reaches fail).
*/
%! features: world

goal(_, _, terminal).
