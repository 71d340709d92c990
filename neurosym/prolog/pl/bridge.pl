:- module(neurosym_bridge, [new_kb/1, close_kb/2, load/6, solve/8, count/7]).

/** <module> The Prolog half of the janus bridge

Python (=|neurosym/prolog/knowledge_base.py|=) loads this file once per
process and calls set_max_depth/1; bridge.plt beside it tests it in Prolog.
What it does, and why in Prolog:

  - new_kb/1 makes a temporary module whose default is =system= (not
    =user=), so a KB sees library predicates but nothing someone else put in
    =user=; close_kb/2 unloads its files and destroys the module.
  - load/6 loads one file into a KB module under a per-module source id,
    because SWI-Prolog refuses (or silently reconsults) one non-module file
    in two modules. Predicates already loaded are declared multifile first,
    so several fact files add up instead of replacing each other. Errors and
    warnings printed during the load are captured with message_hook/3 and
    returned instead of being printed. The dynamic, discontiguous and
    multifile directives a =|.qlf|= replays land in the KB's module. A rule
    file (format =rules=) that is a module file, as the shipped rule files
    are, is loaded for each KB as a module of its own (=|rgw@KB|=) whose
    default import module is the KB's module, so that the rules' goals for
    facts resolve to that KB's facts as plain calls; the KB imports its
    exports (see =|rules/lib/kb_common.pl|=).
  - solve/8 parses the goal text in the KB module, binds the inputs by
    variable name (values never pass through goal text), runs it under
    limit/2 and returns every answer in one call, each value encoded so
    janus converts it unambiguously: atoms and strings -> str, numbers,
    lists -> list, compounds -> =|Functor-Args|= (a Python tuple), an
    unbound output -> None, a variable inside a value -> the dict =|var:N|=.
    Values nested deeper than max_depth_/1 (or cyclic) and integers of more
    than 4,300 digits are refused with one line: Python could not take them.
  - the goal text must be one goal: a variable, a number or text after its
    full stop is refused with one line.
*/

:- use_module(library(time), [call_with_time_limit/2]).
:- use_module(library(solution_sequences), [limit/2]).
:- use_module(library(apply), [maplist/3, partition/4]).
:- use_module(library(lists), [member/2]).
:- use_module(library(error), [must_be/2]).
:- use_module(fact_reader, [lines_text/2]).

:- thread_local collecting_/0, collected_/2.
:- dynamic max_depth_/1.      % set_max_depth/1: the deepest answer passed to Python

%!  set_max_depth(+Levels) is det.
%   Answers nested more than Levels deep are refused (a compound or a proper
%   list is one level). Python sets it to neurosym.terms.MAX_DEPTH right
%   after loading this file; not exported (the fact reader has one of its
%   own), so called as neurosym_bridge:set_max_depth(Levels).
set_max_depth(Levels) :-
    must_be(positive_integer, Levels),
    retractall(max_depth_(_)),
    assertz(max_depth_(Levels)).

% Embedded in Python there is nobody to answer the debugger: an error that
% slips through must become an exception, never an interactive prompt.
:- set_prolog_flag(debug_on_error, false).
:- multifile user:message_hook/3.
:- dynamic user:message_hook/3.

user:message_hook(_Term, Kind, Lines) :-
    collecting_,
    ( Kind == error ; Kind == warning ),
    !,
    lines_text(Lines, Text0),
    (   source_location(File, Line),
        \+ sub_string(Text0, 0, _, _, File)
    ->  format(string(Text), "~w:~w: ~w", [File, Line, Text0])
    ;   Text = Text0
    ),
    assertz(collected_(Kind, Text)).

error_text_(E0, Text) :-
    (   E0 = error(existence_error(procedure, PI), _)
    ->  E = error(existence_error(procedure, PI), _)  % its context names findall_loop/4
    ;   E = E0
    ),
    (   catch(translate_(E, Text), _, fail)
    ->  true
    ;   format(string(Text), "~q", [E])
    ).

translate_(E, Text) :-
    '$messages':translate_message(E, Lines, []),
    lines_text(Lines, Text).

%!  new_kb(+Module) is det.
%   Makes Module a knowledge base: a temporary module whose default module
%   is system (libraries, not user) and where an unknown predicate is an error.
new_kb(M) :-
    set_module(M:class(temporary)),
    set_module(M:base(system)),
    set_prolog_flag(M:unknown, error).

%!  close_kb(+Module, +Files) is det.
%   Files: the source ids load/6 used. Not every file loaded with context M:
%   libraries autoloaded from M are shared with everyone else.
close_kb(M, Files) :-
    forall(member(File, Files), catch(unload_file(File), _, true)),
    retractall(system:'$load_context_module'(_, M, _)),
    forall(retract(rule_module_(M, Own)), drop_rule_module_(M, Own)),
    '$destroy_module'(M).

%!  load(+Module, +Id, +File, +Format, +CStack, -Messages) is det.
%   Messages: list of Kind-Text, Kind error or warning. The file is loaded
%   in a thread whose C stack is CStack bytes (the caller sizes it by the
%   file's nesting bound, neurosym.prolog.snapshot): embedded in Python, SWI-Prolog has no guard
%   against C-stack overflow, and a deeply nested term would kill the process.
load(M, Id, File, Format, CStack, Messages) :-
    catch(thread_create(load_thread_(M, Id, File, Format), T, [c_stack(CStack)]), E, true),
    (   nonvar(E)
    ->  error_text_(E, Text), Messages = [error-Text]
    ;   thread_join(T, Exit),
        (   Exit = exited(Messages)
        ->  true
        ;   format(string(Text), "~w: loading stopped: ~q", [File, Exit]),
            Messages = [error-Text]
        )
    ).

load_thread_(M, Id, File, Format) :-
    retractall(collected_(_, _)),
    multifile_loaded_(M),
    setup_call_cleanup(
        assertz(collecting_),
        catch(load_(M, Id, File, Format), E, print_message(error, E)),
        retractall(collecting_)),
    findall(Kind-Text, retract(collected_(Kind, Text)), Messages),
    thread_exit(Messages).

% Several files of one KB add up: without this a second file with clauses
% for relation/7 would silently replace those of the first.
multifile_loaded_(M) :-
    forall(( current_predicate(_, M:Head),
             \+ predicate_property(M:Head, imported_from(_)) ),
           ( functor(Head, Name, Arity), multifile(M:Name/Arity) )).

load_(M, Id, File, rules) :-
    (   module_file_(File, Name)
    ->  load_rule_module_(M, Id, File, Name)
    ;   load_(M, Id, File, source)
    ).
load_(M, Id, File, source) :-
    setup_call_cleanup(
        open(File, read, S, [encoding(utf8)]),
        load_files(M:Id, [stream(S), silent(true)]),
        close(S)).
load_(M, Id, File, qlf) :-
    setup_call_cleanup(
        open(File, read, S, [type(binary)]),
        load_files(M:Id, [stream(S), format(qlf), silent(true)]),
        close(S)).

%   module_file_(+File, -Name): File's first term is the header of module
%   Name. A file whose first term cannot be read is no module file: loading
%   it as source reports the syntax error.
module_file_(File, Name) :-
    setup_call_cleanup(
        open(File, read, S, [encoding(utf8)]),
        catch(read_term(S, First, []), error(_, _), fail),
        close(S)),
    nonvar(First),
    (   First = (:- module(Name, _))
    ;   First = (:- module(Name, _, _))
    ),
    atom(Name),
    !.

%   load_rule_module_(+M, +Id, +File, +Name): the module file File loaded
%   for KB M as a module of its own, Name@M, whose default import module is
%   M instead of user: the rules' unqualified goals for facts resolve to M's
%   facts (plain calls, linked on first use), and M imports the exports.
%   Each KB loads its own copy (SWI-Prolog loads one module file into one
%   module only, and a module's goals resolve in the module, then its
%   default import modules); close_kb/2 empties it (drop_rule_module_/2).
load_rule_module_(M, Id, File, Name) :-
    format(atom(Own), '~w@~w', [Name, M]),
    setup_call_cleanup(
        assertz(renaming_(Id, File, Name, Own)),
        load_(M, Id, File, source),
        retractall(renaming_(Id, _, _, _))),
    add_import_module(Own, M, start),
    delete_import_module(Own, user),
    assertz(rule_module_(M, Own)).

%   drop_rule_module_(+M, +Own): KB M's rule module Own, its file
%   unloaded, emptied and cut off from M, which is about to be destroyed.
%   The empty module stays: SWI-Prolog destroys only temporary modules, and
%   a module that a file declared is no longer one.
drop_rule_module_(M, Own) :-
    forall(( current_predicate(_, Own:Head),
             \+ predicate_property(Own:Head, imported_from(_)) ),
           catch(abolish(Own:Head), _, true)),
    delete_import_module(Own, M),
    add_import_module(Own, system, end).

:- thread_local renaming_/4.   % renaming_(Id, File, Name, Own): the header to rename
:- dynamic rule_module_/2.     % rule_module_(KB, Own): the KB's rule modules

% In system, not user: the file is loaded into the KB's module, whose
% default import module is system, and SWI-Prolog asks the term_expansion/2
% of that module and the modules it imports from.
:- multifile system:term_expansion/2.
:- dynamic system:term_expansion/2.

system:term_expansion((:- module(Name, Exports)), (:- module(Own, Exports))) :-
    renaming_source_(Name, Own).
system:term_expansion((:- module(Name, Exports, Dialect)), (:- module(Own, Exports, Dialect))) :-
    renaming_source_(Name, Own).

% The header of the very file load_rule_module_/4 loads (SWI-Prolog names
% its source by the file, or by the source id), not of a library it loads.
renaming_source_(Name, Own) :-
    renaming_(Id, File, Name, Own),
    prolog_load_context(source, Source),
    ( Source == File ; Source == Id ),
    !.

% A .qlf replays a file's directives qualified with the module it was
% compiled in. neurosym compiles into neurosym_qlf (see neurosym/prolog/qlf.py),
% and these declarations there forward to the module being loaded.
:- redefine_system_predicate(neurosym_qlf:dynamic(_)).
:- redefine_system_predicate(neurosym_qlf:discontiguous(_)).
:- redefine_system_predicate(neurosym_qlf:multifile(_)).
neurosym_qlf:dynamic(Spec) :- load_module_(M), dynamic(M:Spec).
neurosym_qlf:discontiguous(Spec) :- load_module_(M), discontiguous(M:Spec).
neurosym_qlf:multifile(Spec) :- load_module_(M), multifile(M:Spec).

load_module_(M) :-
    (   prolog_load_context(module, M0)
    ->  M = M0
    ;   M = neurosym_qlf
    ).

% Ctrl-C: while Prolog runs a goal in Python's main thread, Python handles
% no signals. Every 100,000 inferences Prolog calls into Python, which then
% raises KeyboardInterrupt; solve/8 and count/7 pass it on (interrupt_/1)
% rather than turning it into an error status. Without library(janus) loaded
% there is no Python to ask (a plain swipl running bridge.plt).
:- multifile prolog:heartbeat/0.
prolog:heartbeat :-
    thread_self(main),
    current_predicate(janus:py_call/1),
    !,
    py_call(janus_swi:heartbeat_tick()).
prolog:heartbeat.

:- set_prolog_flag(heartbeat, 100000).

interrupt_(error(python_error('KeyboardInterrupt', _), _)).

%!  solve(+M, +Text, +Inputs, +Limit, +Bounds, -Names, -Rows, -Status) is det.
%   Status: ok, missing-Names, limit-Text or error-Text (pairs: janus makes
%   them tuples). Bounds: see bounded_/2.
solve(M, Text, Inputs, Limit, Bounds, Names, Rows, Status) :-
    catch(solve_(M, Text, Inputs, Limit, Bounds, Names, Rows, Status), E,
          ( interrupt_(E) -> throw(E) ; failure_(E, Bounds, Status), Names = [], Rows = [] )).

solve_(M, Text, Inputs, Limit, Bounds, Names, Rows, Status) :-
    prepare_(M, Text, Inputs, Goal, Names, Vars, Missing),
    (   Missing \== []
    ->  Rows = [], Status = missing-Missing
    ;   Template =.. [v|Vars],
        (   Limit == all
        ->  bounded_(Bounds, findall(Template, M:Goal, Raw))
        ;   bounded_(Bounds, findall(Template, limit(Limit, M:Goal), Raw))
        ),
        maplist(encode_row_, Raw, Rows),
        Status = ok
    ).

%!  count(+M, +Text, +Inputs, +Limit, +Bounds, -N, -Status) is det.
%   N: the number of answers of the goal Text (at most Limit, or all), found
%   without building them; Status as for solve/8.
count(M, Text, Inputs, Limit, Bounds, N, Status) :-
    catch(( prepare_(M, Text, Inputs, Goal, _, _, Missing),
            (   Missing \== []
            ->  N = 0, Status = missing-Missing
            ;   Limit == all
            ->  bounded_(Bounds, aggregate_all(count, M:Goal, N)), Status = ok
            ;   bounded_(Bounds, aggregate_all(count, limit(Limit, M:Goal), N)), Status = ok
            )
          ), E,
          ( interrupt_(E) -> throw(E) ; failure_(E, Bounds, Status), N = 0 )).

%   bounded_(+Bounds, :Goal): run the deterministic Goal (a findall) within
%   Bounds, a list of timeout-Seconds, inferences-N, stack-Bytes. Going
%   past one throws neurosym_limit(Which); the KB stays usable.
bounded_([], Goal) :- !, call(Goal).
bounded_([timeout-T|Bs], Goal) :- !,
    catch(call_with_time_limit(T, bounded_(Bs, Goal)), time_limit_exceeded,
          throw(neurosym_limit(timeout(T)))).
bounded_([inferences-N|Bs], Goal) :- !,
    call_with_inference_limit(bounded_(Bs, Goal), N, Result),
    (   Result == inference_limit_exceeded
    ->  throw(neurosym_limit(inferences(N)))
    ;   true
    ).
bounded_([stack-Bytes|Bs], Goal) :- !,
    current_prolog_flag(stack_limit, Old),
    setup_call_cleanup(set_prolog_flag(stack_limit, Bytes),
                       bounded_(Bs, Goal),
                       set_prolog_flag(stack_limit, Old)).

failure_(E, Bounds, Status) :-
    (   limit_text_(E, Bounds, Msg)
    ->  Status = limit-Msg
    ;   neurosym_text_(E, Msg)
    ->  Status = error-Msg
    ;   error_text_(E, Msg),
        Status = error-Msg
    ).

neurosym_text_(neurosym_goal(variable), "the goal is a variable; give a goal such as object(Id, Type)").
neurosym_text_(neurosym_goal(not_callable(G)), Msg) :-
    format(string(Msg), "the goal ~q is not something to run; give a goal such as object(Id, Type)", [G]).
neurosym_text_(neurosym_goal(trailing(Rest)), Msg) :-
    format(string(Msg), "the goal has text after its full stop (~w); give one goal, \c
                         joining goals with ',' rather than '.'", [Rest]).
neurosym_text_(neurosym_answer(deep), Msg) :-
    max_depth_(D),
    format(string(Msg), "an answer is nested more than ~D levels deep (or is cyclic); \c
                         neurosym passes answers up to ~D levels to Python", [D, D]).
neurosym_text_(neurosym_answer(big_integer), "an answer holds an integer of more than 4,300 digits, \c
                                               which Python cannot write as text").

limit_text_(neurosym_limit(timeout(T)), _, Msg) :-
    format(string(Msg), "time limit exceeded: the goal ran longer than ~w s and was stopped", [T]).
limit_text_(neurosym_limit(inferences(N)), _, Msg) :-
    format(string(Msg), "inference limit exceeded: the goal took more than ~D inferences and was stopped", [N]).
limit_text_(E, Bounds, Msg) :-
    E = error(resource_error(What), _),
    stack_overflow_(What, E),
    (   memberchk(stack-Bytes, Bounds) -> true ; current_prolog_flag(stack_limit, Bytes) ),
    MB is Bytes / 1048576,
    format(string(Msg), "stack limit exceeded: the goal needed more than ~1f MB of Prolog stack \c
                         (a runaway recursion?) and was stopped", [MB]).

stack_overflow_(What, _) :- memberchk(What, [stack, global_stack, local_stack, trail_stack,
                                             stack_overflow, memory]), !.
stack_overflow_(_, error(_, Context)) :- is_dict(Context, stack_overflow).

prepare_(M, Text, Inputs, Goal, Names, Vars, Missing) :-
    goal_(M, Text, Goal, Bindings),
    bind_inputs_(Inputs, Bindings, Missing),
    outputs_(Bindings, Inputs, Names, Vars).

%   goal_(+M, +Text, -Goal, -Bindings): Text read as one goal; throws
%   neurosym_goal(Why) for an empty goal, a variable, a number, or text
%   after the goal's full stop (which would be ignored without a word).
goal_(M, Text, Goal, Bindings) :-
    term_string(Goal, Text, [variable_names(Bindings), module(M)]),
    (   Goal == end_of_file
    ->  throw(error(syntax_error(empty_goal), _))
    ;   var(Goal)
    ->  throw(neurosym_goal(variable))
    ;   \+ callable(Goal)
    ->  throw(neurosym_goal(not_callable(Goal)))
    ;   after_full_stop_(Text, Rest)
    ->  throw(neurosym_goal(trailing(Rest)))
    ;   true
    ).

%   after_full_stop_(+Text, -Rest): Text has a full stop with more text after it.
after_full_stop_(Text, Rest) :-
    setup_call_cleanup(
        open_string(Text, S),
        (   catch('$raw_read'(S, _), error(syntax_error(_), _), fail),  % no full stop: one goal
            character_count(S, End),
            catch('$raw_read'(S, Next), error(syntax_error(_), _), Next = more),
            Next \== end_of_file
        ),
        close(S)),
    sub_string(Text, End, _, 0, Rest0),
    normalize_space(string(Rest), Rest0).

% The named variables that are not inputs, in order; no findall: it would copy them.
outputs_([], _, [], []).
outputs_([Name=Var|T], Inputs, Names, Vars) :-
    (   ( sub_atom(Name, 0, _, _, '_') ; memberchk(Name-_, Inputs) )
    ->  outputs_(T, Inputs, Names, Vars)
    ;   Names = [Name|Names1], Vars = [Var|Vars1],
        outputs_(T, Inputs, Names1, Vars1)
    ).

bind_inputs_([], _, []).
bind_inputs_([Name-Value0|T], Bindings, Missing) :-
    (   memberchk(Name=Var, Bindings)
    ->  decode_(Value0, Value),
        Var = Value,
        Missing = Missing1
    ;   Missing = [Name|Missing1]
    ),
    bind_inputs_(T, Bindings, Missing1).

% Python -> Prolog: janus made atoms, numbers and lists already; a Term
% arrives as the tuple ('$neurosym_term', Functor, Args).
decode_(X, X) :- var(X), !.
decode_(-('$neurosym_term', F, As0), T) :- !,
    maplist(decode_, As0, As),
    compound_name_arguments(T, F, As).
decode_(L0, L) :- is_list(L0), !, maplist(decode_, L0, L).
decode_(X, X).

encode_row_(Template, Row) :-
    Template =.. [v|Values],
    term_variables(Values, Vars),
    max_depth_(Depth),
    maplist(encode_top_(Vars, Depth), Values, Row).

% An unbound output variable is None; variables inside a value are dicts
% var:N (N numbering the row's variables from 1), which Python names _G<N>.
encode_top_(_, _, V, @(none)) :- var(V), !.
encode_top_(Vars, Depth, X, E) :- encode_(X, Vars, Depth, E).

% Prolog -> Python, see the module comment. Depth: the levels of nesting
% still allowed; a deeper value (or a cyclic one) throws neurosym_answer(deep),
% an integer Python cannot print throws neurosym_answer(big_integer).
encode_(V, Vars, _, _{var:N}) :- var(V), !, nth_var_(Vars, V, 1, N).
encode_(X, _, _, X) :- atom(X), !.
encode_(X, _, _, X) :- integer(X), !, small_enough_(X).
encode_(X, _, _, X) :- number(X), !.
encode_(X, _, _, X) :- string(X), !.
encode_(_, _, 0, _) :- !, throw(neurosym_answer(deep)).
encode_(L, Vars, D, E) :- is_list(L), !, D1 is D - 1, maplist(encode_el_(Vars, D1), L, E).
encode_(D, _, _, S) :- is_dict(D), !, format(string(S), "~q", [D]).
encode_(T, Vars, D, F-As) :- compound(T), !,
    compound_name_arguments(T, F, As0),
    D1 is D - 1,
    maplist(encode_el_(Vars, D1), As0, As).
encode_(X, _, _, S) :- format(string(S), "~q", [X]).

encode_el_(Vars, D, X, E) :- encode_(X, Vars, D, E).

nth_var_([V0|Vs], V, I, N) :- ( V0 == V -> N = I ; I1 is I + 1, nth_var_(Vs, V, I1, N) ).

% Python writes integers of up to 4,300 digits as text; 2^14284 has 4,300.
small_enough_(X) :-
    (   X > -(1 << 62), X < 1 << 62
    ->  true
    ;   msb(abs(X)) < 14284
    ->  true
    ;   throw(neurosym_answer(big_integer))
    ).
