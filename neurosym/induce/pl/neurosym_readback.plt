/*  plunit tests of neurosym_readback.pl: a learned file is written only when
    its text reads back as exactly the parts it must hold (fixed code, each
    learned clause as one term), and reading runs nothing.

    swipl -g run_tests -t halt neurosym/induce/pl/neurosym_readback.plt

Kinds and texts arrive as janus makes them from Python (strings), as
neurosym/induce/readback.py passes them.
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/neurosym_readback.pl', Readback),
   use_module(Readback).

:- begin_tests(neurosym_readback).

code("% a header comment\n:- dynamic seen/1.\nhelper(X) :- seen(X).\n").

% --- accepted: the text is the parts, term by term ------------------------

test(code_and_learned_clauses_read_back, [R == ""]) :-
    code(Code),
    string_concat(Code, "% learned\ngoal(E, T, 'a b') :- helper(E), T > 1.\nfact(\"s\", [1, 2.5]).\n", Text),
    readback(Text, ["code", "term", "term"],
             [Code, "goal(E, T, 'a b') :- helper(E), T > 1 .", "fact(\"s\", [1, 2.5]) ."], R).

test(layout_and_variable_names_do_not_matter_but_sharing_does, [R == ""]) :-
    readback("p( X ,\n  Y , X ).", ["term"], ["p(X, Y, X) ."], R).

test(empty_text_is_no_parts, [R == ""]) :-
    readback("% nothing but a comment\n", [], [], R).

% --- refused: one term more, less, or different ---------------------------

test(extra_directive_refused, [R == "term 2, :-(initialization(halt)), is not one of them"]) :-
    readback("p(a).\n:- initialization(halt).\n", ["term"], ["p(a) ."], R).

test(foreign_clause_refused, [R == "term 3, :-(goal(A,B,C),shell(ls)), is not one of them"]) :-
    code(Code),
    string_concat(Code, "goal(A, B, C) :- shell(ls).\n", Text),
    readback(Text, ["code"], [Code], R).

test(missing_clause_refused, [R == "term 2, q(b), is missing"]) :-
    readback("p(a).\n", ["term", "term"], ["p(a) .", "q(b) ."], R).

test(atom_read_as_variable_refused, [R == "term 1 reads as p(X), not p(x)"]) :-
    readback("p(X).\n", ["term"], ["p(x) ."], R).

test(variables_no_longer_shared_refused, [R == "term 1 reads as p(X,Y), not p(X,X)"]) :-
    readback("p(X, Y).\n", ["term"], ["p(X, X) ."], R).

test(quote_that_closes_early_refused, [R == "term 1 reads as p(a,b), not p('a, b')"]) :-
    readback("p('a', b).\n", ["term"], ["p('a, b') ."], R).

test(quasi_quotation_refused, [R == "a quasi-quotation"]) :-
    readback("p({|string(X)||some text|}).\n", ["term"], ["p(x) ."], R).

test(syntax_error_names_its_line,
     [R == "syntax error: operator_expected on line 2"]) :-
    readback("p(a).\np(a b).\n", ["term", "term"], ["p(a) .", "p(b) ."], R).

test(term_part_must_be_one_term, [R == "not one term: p(a). q(b)."]) :-
    readback("p(a).\nq(b).\n", ["term"], ["p(a). q(b)."], R).

% --- nothing in the text runs ---------------------------------------------

test(directives_are_read_not_run) :-
    readback(":- assertz(plt_readback_ran).\n", ["term"], [":- assertz(plt_readback_ran) ."], R),
    R == "",
    \+ current_predicate(_:plt_readback_ran/0).

test(operator_directive_does_not_change_the_reading,
     [R == "syntax error: operator_expected on line 2"]) :-
    readback(":- op(700, xfx, ===>).\na ===> b.\n", ["code"], [":- op(700, xfx, ===>).\na ===> b.\n"], R).

:- end_tests(neurosym_readback).
