/** <module> neurosym_readback: does a learned file read back as the clauses learned?

neurosym/induce/readback.py hands this module a learned file's text and the
parts it must hold (fixed code, learned clauses as terms); nothing is run.
*/

:- module(neurosym_readback, [readback/4]).

%!  readback(+Text, +Kinds, +Texts, -Result) is det.
%   Read Text term by term and compare it with the terms of the parts (Kinds: code,
%   every term of the text; term: exactly one term). Result: "" when they are the same, else a string saying where they differ.
readback(Text, Kinds, Texts, Result) :-
    catch(readback_(Text, Kinds, Texts, Result), E, error_text_(E, Result)).

readback_(Text, Kinds, Texts, Result) :-
    terms_of_(Text, Got),
    parts_(Kinds, Texts, Wants),
    append(Wants, Want),
    compare_(Got, Want, 1, Result).

error_text_(error(format(F, A), _), Result) :- !,
    format(string(Result), F, A).
error_text_(error(syntax_error(What), stream(_, Line, _, _)), Result) :- !,
    format(string(Result), 'syntax error: ~w on line ~d', [What, Line]).
error_text_(E, Result) :-
    format(string(Result), '~q', [E]).

parts_([], [], []).
parts_([K|Ks], [T|Ts], [Terms|Rest]) :-
    atom_string(Kind, K),
    part_(Kind, T, Terms),
    parts_(Ks, Ts, Rest).

part_(code, Text, Terms) :- terms_of_(Text, Terms).
part_(term, Text, [Term]) :-
    (   terms_of_(Text, [Term0]) -> Term = Term0 ; throw(error(format('not one term: ~s', [Text]), _)) ).

terms_of_(Text, Terms) :-
    setup_call_cleanup(open_string(Text, S), read_all_(S, Terms), close(S)).

read_all_(S, Terms) :-
    read_term(S, T, [ variable_names(Vs), quasi_quotations(QQ), syntax_errors(error),
                      module(neurosym_readback) ]),
    (   QQ \== []
    ->  throw(error(format('a quasi-quotation', []), _))
    ;   T == end_of_file
    ->  Terms = []
    ;   name_vars_(Vs),
        Terms = [T|Rest],
        read_all_(S, Rest)
    ).

name_vars_([]).
name_vars_([Name=Var|Vs]) :- Var = '$VAR'(Name), name_vars_(Vs).

compare_([], [], _, "") :- !.
compare_([G|_], [], I, Result) :- !,
    text_(G, GT), format(string(Result), 'term ~d, ~s, is not one of them', [I, GT]).
compare_([], [W|_], I, Result) :- !,
    text_(W, WT), format(string(Result), 'term ~d, ~s, is missing', [I, WT]).
compare_([G|Gs], [W|Ws], I, Result) :-
    (   G =@= W
    ->  I1 is I + 1, compare_(Gs, Ws, I1, Result)
    ;   text_(G, GT), text_(W, WT),
        format(string(Result), 'term ~d reads as ~s, not ~s', [I, GT, WT])
    ).

text_(T, Text) :-
    format(string(Text), '~W', [T, [quoted(true), numbervars(true), ignore_ops(true)]]).
