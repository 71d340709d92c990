/*  play_strategy.pl -- a hand-written strategy for neurosym_play.plt.

    It goes for the terminal; in episodes 5 to 9 it misbehaves, each in
    its own way, building the names it calls at run time (a name written
    in a clause is refused by check_policy/4 before the file loads).
*/

goal(5, _, _) :- !, atom_string(N, "halt"), G =.. [N, 3], call(G).
goal(6, _, _) :- !, throw(strategy_gave_up).
goal(7, _, _) :- !, atom_string(N, "halt"), call(N).
goal(8, _, _) :- !, spin_.
goal(9, _, _) :- !, atom_length(f(x), _).
goal(E, T, G) :- at(E, T, G, _, _), object(G, terminal).

spin_ :- spin_.
