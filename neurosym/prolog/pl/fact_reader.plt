/*  plunit tests of fact_reader.pl: the rule that admits a knowledge-base file as data.

    swipl -g run_tests -t halt neurosym/prolog/pl/fact_reader.plt

Each test writes a small file, reads it into a fresh module with
load_facts/7 as Python does (neurosym.prolog.knowledge_base), and checks
what the module holds afterwards and the one-line refusal.
*/

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/fact_reader.pl', Reader),
   use_module(Reader).
:- neurosym_facts:set_max_depth(100).     % neurosym.terms.MAX_DEPTH

:- begin_tests(fact_reader).

:- use_module(library(lists), [numlist/3]).
:- use_module(library(apply), [maplist/3]).

% --- helpers -------------------------------------------------------------

c_stack(16777216).

%   kb(-M): a fresh module set up as the bridge's new_kb/1 sets up a KB.
kb(M) :-
    gensym(plt_fact_kb_, M),
    set_module(M:class(temporary)),
    set_module(M:base(system)).

%   file(+Text, -File): a temporary file holding Text as UTF-8.
file(Text, File) :-
    tmp_file_stream(File, S, [encoding(utf8), extension(pl)]),
    write(S, Text),
    close(S).

%   read_into(+M, +Text, +Mode, +RuleFiles, -Count, -Status, -File)
read_into(M, Text, Mode, RuleFiles, Count, Status, File) :-
    file(Text, File),
    c_stack(CStack),
    load_facts(M, File, Mode, RuleFiles, CStack, Count, Status).

read_into(M, Text, Count, Status) :-
    read_into(M, Text, assert, [], Count, Status, _).

%   refusal(+Text, -Line, -What, -Shown): the parts of the one-line refusal
%   of Text (read into a fresh module), which must be one.
refusal(Text, Line, What, Shown) :-
    kb(M),
    read_into(M, Text, assert, [], Count, Status, File),
    Count == 0,
    Status = error-Message,
    atom_concat(File, ':', Prefix),
    string_concat(Prefix, Rest0, Message),
    split_string(Rest0, ":", "", [LineText|_]),
    number_string(Line, LineText),
    sub_string(Rest0, B, _, 0, "; a fact file holds only ground facts such as p(a, 1). and the \c
                                writer's :- encoding/dynamic headers (load code as rules, or trust the file)"),
    sub_string(Rest0, 0, B, _, Body),
    string_concat(LineText, ": found ", Lead),
    string_concat(Lead, Found, Body),
    once(sub_string(Found, W, _, _, ": ")),
    sub_string(Found, 0, W, _, What),
    W2 is W + 2,
    sub_string(Found, W2, _, 0, Shown).

clauses(M, Head, Terms) :- findall(Head, M:Head, Terms).

%   nested(+Levels, -Text): the fact f(...f(a)...), Levels levels deep (Levels f/1).
nested(Levels, Text) :-
    length(Opens, Levels), maplist(=("f("), Opens),
    length(Closes, Levels), maplist(=(")"), Closes),
    atomic_list_concat(Opens, Open), atomic_list_concat(Closes, Close),
    format(string(Text), "~wa~w.~n", [Open, Close]).

% --- facts and headers admitted -----------------------------------------

test(facts_admitted, [Ps-Qs-N == [p(a, 1), p('B c', -2.5)]-[q("text", [1, [2]], f(g(h)))]-4]) :-
    kb(M),
    read_into(M, "p(a, 1).\np('B c', -2.5).\nq(\"text\", [1, [2]], f(g(h))).\nkb_meta(x).\n",
              N, Status),
    Status == ok,
    clauses(M, p(_, _), Ps),
    clauses(M, q(_, _, _), Qs).

test(unicode_names_admitted, [Ts == [ключ(значение)]]) :-
    kb(M),
    read_into(M, "ключ(значение).\n", 1, ok),
    clauses(M, ключ(_), Ts).

test(encoding_and_dynamic_headers_accepted, [N-Ps == 4-[p(1)]]) :-
    kb(M),
    read_into(M, ":- encoding(utf8).\n:- dynamic p/1, q/2.\n:- dynamic([r/0]).\np(1).\n", N, Status),
    Status == ok,
    clauses(M, p(_), Ps),
    predicate_property(M:q(_, _), dynamic),
    predicate_property(M:r, dynamic),
    \+ M:q(_, _).

test(encoding_header_applies_to_the_stream, [Ts == [p('caf\u00e9')]]) :-
    tmp_file_stream(File, S, [encoding(octet), extension(pl)]),
    format(S, ":- encoding(iso_latin_1).~np(caf~c).~n", [0xE9]),
    close(S),
    kb(M),
    c_stack(CStack),
    load_facts(M, File, assert, [], CStack, 2, ok),
    clauses(M, p(_), Ts).

test(depth_at_the_limit_admitted, [Status == ok]) :-
    nested(100, Text),
    kb(M),
    read_into(M, Text, 1, Status).

test(check_mode_adds_nothing, [Count-Status == 2-ok]) :-
    kb(M),
    read_into(M, "p(a).\np(b).\n", check, [], Count, Status, _),
    \+ current_predicate(M:p/1).

% --- everything but facts refused ---------------------------------------

refused_case("p(a).\n:- initialization(halt).\n", 2, "a directive", ":-initialization halt").
refused_case("?- halt.\n", 1, "a directive", "?-halt").
refused_case(":- shell(ls).\n", 1, "a directive", ":-shell(ls)").
refused_case("p(a).\np(X) :- q(X).\n", 2, "a clause with a body (a rule)", "p(A):-q(A)").
refused_case("p(X) => q(X).\n", 1, "a rule (Head => Body)", "p(A)=>q(A)").
refused_case("greeting --> [hello].\n", 1, "a grammar rule", "greeting-->[hello]").
refused_case("user:p(a).\n", 1, "a module-qualified clause", "user:p(a)").
refused_case("a = b.\n", 1, "a term whose name = (=/2) is not a plain predicate name", "a=b").
refused_case("- p.\n", 1, "a term whose name - (-/1) is not a plain predicate name", "-p").
refused_case("'p q'(a).\n", 1, "a term whose name 'p q' ('p q'/1) is not a plain predicate name",
             "'p q'(a)").
refused_case("'P'(a).\n", 1, "a term whose name 'P' ('P'/1) is not a plain predicate name", "'P'(a)").
refused_case("42.\n", 1, "a term that is not a fact", "42").
refused_case("X.\n", 1, "a variable where a fact should be", "A").
refused_case("p(a).\n\np(X).\n", 3, "a fact with a variable (facts are ground)", "p(A)").
refused_case("atom(a).\n", 1, "a fact for the built-in predicate atom/1", "atom(a)").
refused_case("dynamic(p/1).\n", 1, "a fact for the built-in predicate dynamic/1", "dynamic p/1").
refused_case("term_expansion(a, b).\n", 1, "a fact for the hook predicate term_expansion/2",
             "term_expansion(a, b)").
refused_case("goal_expansion(a, b).\n", 1, "a fact for the hook predicate goal_expansion/2",
             "goal_expansion(a, b)").
refused_case("portray(x).\n", 1, "a fact for the hook predicate portray/1", "portray(x)").
refused_case("message_hook(a, b, c).\n", 1, "a fact for the hook predicate message_hook/3",
             "message_hook(a, b, c)").
refused_case("append(a, b, c).\n", 1, "a fact for the library predicate append/3 (library lists)",
             "append(a, b, c)").
refused_case("p({|string(X)||some text|}).\n", 1, "a quasi-quotation",
             "p(A)").      % the quotation is left unread
refused_case(":- dynamic atom/1.\n", 1, "a fact for the built-in predicate atom/1",
             ":-dynamic atom/1").
refused_case(":- dynamic 'a b'/1.\n", 1,
             "a declaration of 'a b'/1, which is not a plain predicate name", ":-dynamic'a b'/1").
refused_case(":- dynamic X.\n", 1, "a directive", ":-dynamic A").
refused_case(":- encoding(no_such_encoding).\n", 1, "a directive", ":-encoding(no_such_encoding)").

test(refused, [forall(refused_case(Text, Line, What, Shown)), true(Got == Line-What)]) :-
    refusal(Text, L, W, S),
    Got = L-W,
    (   S == Shown
    ->  true
    ;   format(user_error, "~q shown as ~q, expected ~q~n", [Text, S, Shown]), fail
    ).

test(over_deep_term_refused, [W == "a term nested more than 100 levels deep"]) :-
    nested(101, Deep),
    string_concat("p(a).\n", Deep, Text),
    refusal(Text, 2, W, _).

test(rule_file_predicate_refused, [Ts == [r(1)]]) :-
    kb(M),
    file("r(1).\nrule(X) :- r(X).\n", Rules),
    load_files(M:Rules, [silent(true)]),
    read_into(M, "r(2).\n", assert, [Rules], 0, Status, _),
    Status = error-Message,
    once(sub_string(Message, _, _, _, "found a fact for r/1, which the rule files define: r(2);")),
    clauses(M, r(_), Ts).

test(imported_predicate_refused, [Status = error-_]) :-
    kb(M),
    assertz(plt_fact_other:shared(1)),
    plt_fact_other:export(shared/1),
    M:import(plt_fact_other:shared/1),
    read_into(M, "shared(2).\n", Count, Status),
    Count == 0,
    Status = error-Message,
    once(sub_string(Message, _, _, _,
                    "found a fact for shared/1, which the rules import from module plt_fact_other")),
    clauses(M, shared(_), [shared(1)]).

test(invalid_utf8_refused) :-
    tmp_file_stream(File, S, [encoding(octet), extension(pl)]),
    format(S, "p(a).~np('~c').~n", [0xFF]),
    close(S),
    kb(M),
    c_stack(CStack),
    load_facts(M, File, assert, [], CStack, 0, error-Message),
    atom_concat(File, ': ', Prefix),
    string_concat(Prefix, _, Message),
    sub_string(Message, _, _, 0, "(a fact file is UTF-8 text, or says :- encoding(Enc). first)"),
    \+ current_predicate(M:p/1).

test(syntax_error_names_file_and_line, [true(sub_string(Message, 0, _, _, Prefix))]) :-
    kb(M),
    read_into(M, "p(a).\np(b.\n", assert, [], 0, error-Message, File),
    format(string(Prefix), "~w:2:", [File]),
    \+ current_predicate(M:p/1).

% --- a refused file leaves the module as it was ---------------------------

test(refused_file_leaves_the_module_as_it_was, [Before == After]) :-
    kb(M),
    read_into(M, ":- dynamic d/1.\np(a).\nq(1).\n", 3, ok),
    snapshot(M, Before),
    read_into(M, ":- dynamic z/1.\np(b).\nq(2).\nnew(x).\nz(9).\nfoo :- bar.\n", 0, error-_),
    snapshot(M, After),
    \+ current_predicate(M:new/1),
    \+ current_predicate(M:z/1).

snapshot(M, [ps(Ps), qs(Qs), ds(Ds)]) :-
    clauses(M, p(_), Ps),
    clauses(M, q(_), Qs),
    clauses(M, d(_), Ds).

% --- chunked parallel reading = front to back ----------------------------

%   many_facts(+N, +Extra, -Text): N facts of three predicates, Extra after them.
many_facts(N, Extra, Text) :-
    numlist(1, N, Is),
    maplist(fact_line, Is, Lines),
    atomic_list_concat(Lines, Body),
    string_concat(Body, Extra, Text).

fact_line(I, Line) :-
    K is I mod 3,
    (   K =:= 0 -> format(atom(Line), "rel(~w, 'a b', [x, ~w], f(g(~w))).~n", [I, I, I])
    ;   K =:= 1 -> format(atom(Line), "obj(~w, \"s~w\", 1.5e3).~n", [I, I])
    ;   format(atom(Line), "ev(~w).~n", [I])
    ).

%   read_both(+Text, -Front, -Chunked, -Taken): what a front-to-back read
%   and a 3-thread chunked read of Text give: Count-Status-Clauses each.
read_both(Text, Front, Chunked, Taken) :-
    file(Text, File),
    setup_call_cleanup(
        set_chunk_bytes(256),
        ( read_with(File, 1, Front, _),
          read_with(File, 3, Chunked, Taken) ),
        ( set_chunk_bytes(8388608), set_reader_threads(auto) )).

read_with(File, Threads, Count-Status-Clauses, Taken) :-
    set_reader_threads(Threads),
    kb(M),
    c_stack(CStack),
    load_facts(M, File, assert, [], CStack, Count, Status0),
    chunks_taken(Taken),
    (   Status0 = error-Message
    ->  Status = error-Message
    ;   Status = Status0
    ),
    findall(T, ( member(H, [rel(_, _, _, _), obj(_, _, _), ev(_), late(_)]),
                 current_predicate(_, M:H), M:H, T = H ), Clauses).

test(chunked_read_is_a_front_to_back_read, [Front == Chunked]) :-
    many_facts(200, "", Text),
    read_both(Text, Front, Chunked, Taken),
    Front = 200-ok-_,
    Taken > 0.

test(chunked_read_keeps_a_late_header_in_order, [Front == Chunked]) :-
    many_facts(150, ":- dynamic late/1.\nlate(1).\n", Text0),
    many_facts(50, "", More),
    string_concat(Text0, More, Text),
    read_both(Text, Front, Chunked, _),
    Front = 202-ok-_.

test(chunked_read_refuses_a_late_rule_at_its_line, [Front == Chunked]) :-
    many_facts(190, "late(X) :- shell(X).\n", Text0),
    many_facts(20, "", More),
    string_concat(Text0, More, Text),
    read_both(Text, Front, Chunked, _),
    Front = 0-(error-Message)-[],
    once(sub_string(Message, _, _, _, ":191: found a clause with a body (a rule): late(A):-shell(A);")).

test(chunked_read_names_a_late_syntax_error_line, [Front == Chunked]) :-
    many_facts(190, "late(.\n", Text),
    read_both(Text, Front, Chunked, _),
    Front = 0-(error-Message)-[],
    once(sub_string(Message, _, _, _, ":191:")).

:- end_tests(fact_reader).
