/*  route_table.pl -- the route lengths of a trace's states, for induce's feature columns.

    neurosym/induce/strategy_route.py loads this file and rules/route.pl into
    a KB of their own, asserts a trace's state facts there (assert_trace/4),
    and reads every state's route lengths (trace_route/5): the Python columns
    of the route features are route.pl's own answers, the ones a learned
    strategy's route_length/4 gives when it plays.
*/

%!  assert_trace(+Objects, +Ats, +Terrain, +Grids) is det.
%   Assert a trace's object/2 ([Id, TypeText]), at/5 ([E, T, Id, R, C]), terrain/4
%   ([E, TypeText, R, C]) and grid/3 ([E, Rows, Cols]) facts; a type is read from the
%   canonical text induce keeps it as.
assert_trace(Objects, Ats, Terrain, Grids) :-
    forall(member([Id, Text], Objects), ( term_to_atom(Type, Text), assertz(object(Id, Type)) )),
    forall(member([E, T, Id, R, C], Ats), assertz(at(E, T, Id, R, C))),
    forall(member([E, Text, R, C], Terrain), ( term_to_atom(Type, Text), assertz(terrain(E, Type, R, C)) )),
    forall(member([E, Rows, Cols], Grids), assertz(grid(E, Rows, Cols))).

%!  trace_route(-E, -T, -From, -O, -D) is nondet.
%   In each state (E, T) with the agent on the map, the route length D (route_moves/5)
%   to each object O other than the agent that a route reaches (D < 999), from the
%   agent's cell (From = agent) and from each teleport end's cell (From = that end).
trace_route(E, T, From, O, D) :-
    findall(E0-T0, at(E0, T0, agent, _, _), States0),
    sort(States0, States),
    member(E-T, States),
    once(at(E, T, agent, R0, C0)),
    (   From = agent, Cell = R0-C0
    ;   at(E, T, From, R, C), From \== agent, teleport_end_(From), Cell = R-C
    ),
    at(E, T, O, _, _),
    O \== agent,
    route_moves(E, T, Cell, O, D),
    D < 999.

teleport_end_(Id) :-
    object(Id, Type),
    (   compound(Type) -> functor(Type, teleport, _) ; Type == teleport ),
    !.

%!  forget_trace is det.
%   Forget the routes route.pl remembered for the asserted episodes.
forget_trace :-
    forall(distinct(E, at(E, _, _, _, _)), route_forget(E)).
