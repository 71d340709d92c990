/*  boxworld_trivial.pl -- the trivial Box-World strategy: always the gem.
    A floor to compare a strategy with (`neurosym play --compare trivial`):
    the gem lies in a locked box, so route.pl finds a path to it only once
    the box is open (with --fallback none, every level fails at once).
*/
%! features: world

goal(E, T, Gem) :- object(Gem, gem), at(E, T, Gem, _, _).
