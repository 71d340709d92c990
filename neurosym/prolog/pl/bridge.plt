/*  plunit tests of bridge.pl: KB modules, loading files into them, and the
    encoding of answers for janus (what Python turns into str, int, float,
    list, tuple, None and variables).

    swipl -g run_tests -t halt neurosym/prolog/pl/bridge.plt
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/bridge.pl', Bridge),
   use_module(Bridge).
:- neurosym_bridge:set_max_depth(100).    % neurosym.terms.MAX_DEPTH

:- begin_tests(bridge).

:- use_module(library(lists), [numlist/3]).

c_stack(16777216).

%   kb(+Text, -M): a new KB module with Text loaded into it as a source file.
kb(Text, M) :-
    gensym(plt_bridge_kb_, M),
    new_kb(M),
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, Text),
    close(S),
    format(atom(Id), "~w#~w", [File, M]),
    c_stack(CStack),
    load(M, Id, File, source, CStack, Messages),
    assertion(Messages == []).

facts("p(a).\n\c
       p(\"text\").\n\c
       p(42).\n\c
       p(-2.5).\n\c
       p([1, [b], \"s\"]).\n\c
       p(f(x, g(1))).\n\c
       p('A b').\n\c
       p(f(X, Y, X)) :- Y = 1 ; true.\n\c
       big(B) :- B is 2^14283.\n\c
       huge(B) :- B is 2^14284.\n\c
       deep(0, x) :- !.\n\c
       deep(N, f(T)) :- N1 is N - 1, deep(N1, T).\n\c
       loop :- loop.\n").

%   solve_(+Goal, +Inputs, +Limit, +Bounds, -Names-Rows-Status): solve/8 in
%   a new KB of facts/1, its outputs unbound as when Python calls it.
solve_(Goal, Inputs, Limit, Bounds, Answer) :-
    facts(Text),
    kb(Text, M),
    solve(M, Goal, Inputs, Limit, Bounds, Names, Rows, Status),
    Answer = Names-Rows-Status.

% --- answers encoded for janus ------------------------------------------

test(values_encoded, [Rows == [[a], ["text"], [42], [-2.5], [[1, [b], "s"]],
                                [f-[x, g-[1]]], ['A b']]]) :-
    solve_("p(X), \\+ X = f(_, _, _)", [], all, [], ['X']-Rows-ok).

test(unbound_output_is_none, [Names-Rows == ['Z', 'Y']-[[1, @(none)]]]) :-
    solve_("Z = 1, p(a) ; Y = Y", [], 1, [], Names-Rows-ok).

test(variables_inside_a_value_are_numbered_dicts) :-
    solve_("p(T), T = f(_, _, _)", [], all, [], ['T']-Rows-ok),
    Rows = [[f-[V1, One, V1b]], [f-[W1, W2, W1b]]],
    One == 1,
    get_dict(var, V1, 1), get_dict(var, V1b, 1),
    get_dict(var, W1, 1), get_dict(var, W2, 2), get_dict(var, W1b, 1).

test(underscore_variables_are_not_outputs, [Names == ['X']]) :-
    solve_("p(X), _Ignored = X", [], 1, [], Names-_-ok).

test(limit_takes_the_first_answers, [Rows == [[a], ["text"]]]) :-
    solve_("p(X)", [], 2, [], ['X']-Rows-ok).

test(count, [N-Status == 9-ok]) :-
    facts(Text), kb(Text, M),
    count(M, "p(_)", [], all, [], N, Status).

test(largest_integer_python_takes, [Status == ok]) :-
    solve_("big(B)", [], all, [], _-_-Status).

% --- inputs bound by name, decoded from what janus made ------------------

test(inputs_bound_by_name, [Rows == [[42]]]) :-
    solve_("p(X), X == V", ['V'-42], all, [], ['X']-Rows-ok).

test(compound_input_decoded, [Rows == [[true]]]) :-
    solve_("R = true, T == f(x, g(1)), p(T)", ['T'-(-('$neurosym_term', f, [x, -('$neurosym_term', g, [1])]))],
           all, [], ['R']-Rows-ok).

test(missing_input_named, [Status == missing-['Nope']]) :-
    solve_("p(X)", ['Nope'-1], all, [], _-_-Status).

% --- one-line refusals ---------------------------------------------------

refusal("X", "the goal is a variable; give a goal such as object(Id, Type)").
refusal("42", "the goal 42 is not something to run; give a goal such as object(Id, Type)").
refusal("p(X). p(Y)", "the goal has text after its full stop (p(Y)); give one goal, \c
                       joining goals with ',' rather than '.'").
refusal("huge(B)", "an answer holds an integer of more than 4,300 digits, \c
                    which Python cannot write as text").
refusal("deep(101, T)", "an answer is nested more than 100 levels deep (or is cyclic); \c
                         neurosym passes answers up to 100 levels to Python").
refusal("X = f(X)", "an answer is nested more than 100 levels deep (or is cyclic); \c
                     neurosym passes answers up to 100 levels to Python").

test(refused, [forall(refusal(Goal, Text)), Status == error-Text]) :-
    solve_(Goal, [], all, [], _-_-Status).

test(depth_at_the_limit_passes, [Status == ok]) :-
    solve_("deep(100, T)", [], all, [], _-_-Status).

test(syntax_error_is_an_error_line, [true(sub_string(Text, _, _, _, "Syntax error"))]) :-
    solve_("p(", [], all, [], _-_-(error-Text)).

test(unknown_predicate_is_an_error_line) :-
    solve_("nope(X)", [], all, [], []-[]-(error-Text)),
    once(sub_string(Text, _, _, _, "nope/1")).

test(inference_limit, [Status == limit-"inference limit exceeded: the goal took more than \c
                                       10,000 inferences and was stopped"]) :-
    solve_("loop", [], all, [inferences-10000], _-_-Status).

test(time_limit, [Status == limit-"time limit exceeded: the goal ran longer than 0.2 s and was stopped"]) :-
    solve_("loop", [], all, [timeout-0.2], _-_-Status).

% --- KB modules and loading -------------------------------------------------

test(kb_sees_the_library_not_user, [Rows == [[[1, 2, 3]]]]) :-
    assertz(user:plt_bridge_private(1)),
    kb("", M),
    solve(M, "numlist(1, 3, L)", [], all, [], ['L'], Rows, ok),
    solve(M, "plt_bridge_private(X)", [], all, [], _, _, error-_).

test(files_add_up, [Rows == [[a], [b]]]) :-
    kb("q(a).\n", M),
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, "q(b).\n"), close(S),
    format(atom(Id), "~w#~w", [File, M]),
    c_stack(CStack),
    load(M, Id, File, source, CStack, []),
    solve(M, "q(X)", [], all, [], ['X'], Rows, ok).

test(load_errors_are_returned_with_file_and_line) :-
    gensym(plt_bridge_kb_, M),
    new_kb(M),
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, "r(a).\nr(b.\n"), close(S),
    c_stack(CStack),
    load(M, File, File, source, CStack, Messages),
    Messages = [error-Text],
    format(string(Prefix), "~w:2:", [File]),
    sub_string(Text, 0, _, _, Prefix).

%   rule_file(+Text, -File): a temporary rule file holding Text.
rule_file(Text, File) :-
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, Text),
    close(S).

%   load_rules(+M, +File): File loaded into KB M as a rule file, without a word.
load_rules(M, File) :-
    format(atom(Id), "~w#~w", [File, M]),
    c_stack(CStack),
    load(M, Id, File, rules, CStack, Messages),
    assertion(Messages == []).

test(a_module_rule_file_is_loaded_for_each_kb_and_reads_its_facts,
     [Rows1-Rows2-From == [[1]]-[[2]]-[Own1, Own2]]) :-
    gensym(plt_bridge_rules_, Mod),
    format(string(Text), ":- module(~q, [answer/1]).\n\c
                          answer(X) :- fact(X).\n", [Mod]),
    rule_file(Text, File),
    kb("fact(1).\n", M1),
    kb("fact(2).\n", M2),
    load_rules(M1, File),
    load_rules(M2, File),
    solve(M1, "answer(X)", [], all, [], _, Rows1, ok),
    solve(M2, "answer(X)", [], all, [], _, Rows2, ok),
    findall(F, ( member(M, [M1, M2]), predicate_property(M:answer(_), imported_from(F)) ), From),
    format(atom(Own1), "~w@~w", [Mod, M1]),
    format(atom(Own2), "~w@~w", [Mod, M2]),
    close_kb(M1, []),
    assertion(\+ import_module(Own1, M1)).

test(a_plain_rule_file_is_loaded_into_each_kb, [Rows1-Rows2 == [[1]]-[[2]]]) :-
    rule_file("answer(X) :- fact(X).\n", File),
    kb("fact(1).\n", M1),
    kb("fact(2).\n", M2),
    load_rules(M1, File),
    load_rules(M2, File),
    solve(M1, "answer(X)", [], all, [], _, Rows1, ok),
    solve(M2, "answer(X)", [], all, [], _, Rows2, ok).

test(close_kb_destroys_the_module) :-
    kb("q(a).\n", M),
    close_kb(M, []),
    \+ current_module(M).

:- end_tests(bridge).
