:- module(neurosym_facts, [load_facts/7, set_chunk_bytes/1, set_reader_threads/1,
                            chunks_taken/1, lines_text/2]).

/** <module> Reading a fact file as data

A knowledge base is something people pass around, so loading one must not
run it. Consulting a file runs its directives (=|:- shell(...)|=) and lets
it define term_expansion/2 and other hooks; this reader never consults. It
reads the file term by term with read_term/3 (syntax errors raise, nothing
is expanded, quasi-quotations are returned unparsed so no parser runs, and a
term holding one is refused) and admits only what has the shape of a fact,
rather than refusing a list of known bad forms (so that a clause-like form
SWI-Prolog adds one day, as it added =|Head => Body|=, is refused too):

  - facts: a ground atom or compound whose name is a plain predicate name
    (a lowercase letter, then letters, digits, underscores: never an
    operator such as =|:-|=, =|=>|=, =|-->|= or =|:|=, never a quoted name),
    nested at most max_depth_/1 levels (set_max_depth/1: Python's
    =|neurosym.terms.MAX_DEPTH|=), and whose predicate is not built in, not
    a hook (term_expansion, goal_expansion, portray, message_hook, ...), not
    autoloadable from the library, and not defined by the KB's rule files
    (static) or imported into its module;
  - the headers neurosym's writer emits: =|:- encoding(Enc).|= (applied to
    the stream) and =|:- dynamic Name/Arity, ...|= (the same checks on each
    predicate).

A file SWI-Prolog warns about while reading it (text that is not valid
UTF-8, or not valid in the encoding it declares) is refused too. Files are
read in a thread of their own whose C stack holds a level of nesting for
every opening bracket of the file: embedded in Python, SWI-Prolog has no
guard against C-stack overflow, and a term nested 50,000 deep killed the
process. (The parser recurses on opening brackets only, operators are
parsed in a loop, so the file's count of opening brackets bounds the depth
a parse reaches; a term nested deeper than the limit is refused right after
it is read, before anything else walks it.)

Anything else stops the load with =|error-Text|=, one line naming file, line
and what was found. Clauses are added with assertz/1 as they are read; a
refusal further down erases what this file added, so a refused file leaves
the KB as it was. With mode =check= nothing is asserted (used before
compiling a source to =|.qlf|=). The caller passes a private copy of the
file (=|neurosym.prolog.snapshot|=), so the bytes checked are the bytes
loaded or compiled.

Reading is the cost: read_term/3 is about 3/5 of a load, checking 1/5,
assertz/1 1/5 (SWI-Prolog's profiler, 200,000 relation/7 facts; no read
option made reading measurably cheaper, and loading the same text with
load_files/2 from a stream, read and compiled, took 6 times as long as
reading it and adding the terms with assertz/1). So files of 8 MB and more
are cut at line starts into one chunk per core (up to 4): helper threads
read and check chunks 1.. into lists on their own stacks while the loading
thread reads and adds chunk 0 (the smaller one), then each helper adds its
own list in turn, so clauses are added in file order and never copied
between threads. A cut is used only when the chunk before it ends exactly
there, and a helper's chunk only when all of it is plain facts read without
a warning; otherwise the loading thread reads that part itself, so results,
order and error lines are those of a front-to-back read.
set_reader_threads/1 overrides the choice (tests use it to run the chunked
path on any machine).

Python loads this file once per process (=|neurosym/prolog/fact_reader.py|=)
and calls set_max_depth/1; fact_reader.plt beside it tests the admission
rule in Prolog.
*/

:- use_module(library(lists), [member/2, append/3]).
:- use_module(library(apply), [exclude/3]).
:- use_module(library(error), [must_be/2]).

:- thread_local touched_/3.   % touched_(Name, Arity, ClausesBefore | new)
:- dynamic chunk_bytes_/1.    % files this large are read in parallel chunks
chunk_bytes_(8388608).
:- dynamic reader_threads_/1. % set: threads that read a large file (1: front to back)
:- dynamic max_depth_/1.      % set_max_depth/1: the deepest term admitted

%!  set_max_depth(+Levels) is det.
%   Terms nested more than Levels deep are refused (a compound or a proper
%   list is one level). Python sets it to neurosym.terms.MAX_DEPTH right
%   after loading this file, the bound its writer and the bridge keep; not
%   exported (the bridge has one of its own), so called as
%   neurosym_facts:set_max_depth(Levels).
set_max_depth(Levels) :-
    must_be(positive_integer, Levels),
    retractall(max_depth_(_)),
    assertz(max_depth_(Levels)).

%!  set_reader_threads(+Threads) is det.
%   Threads reading a large file, 1 to 4; auto: the cores, up to 4.
set_reader_threads(Threads) :-
    (   Threads == auto
    ->  retractall(reader_threads_(_))
    ;   must_be(between(1, 4), Threads),
        retractall(reader_threads_(_)),
        assertz(reader_threads_(Threads))
    ).

reader_threads(Threads) :-
    (   reader_threads_(Threads)
    ->  true
    ;   current_prolog_flag(cpu_count, Cores),
        Threads is max(1, min(Cores, 4))
    ).

%!  chunks_taken(-Count) is det.
%   How many helper chunks the last chunked load added as read (tests ask).
chunks_taken(Count) :- flag(neurosym_chunks_taken, Count, Count).

%!  set_chunk_bytes(+Bytes) is det.
%   Tests read small files in chunks with this.
set_chunk_bytes(Bytes) :-
    retractall(chunk_bytes_(_)),
    assertz(chunk_bytes_(Bytes)).

%!  load_facts(+Module, +File, +Mode, +RuleFiles, +CStack, -Count, -Status) is det.
%   Mode: assert or check. RuleFiles: the source ids of the KB's rule files.
%   CStack: bytes of C stack for the threads that read File. Count: terms
%   read. Status: ok or error-Text.
%
%   Embedded in Python, SWI-Prolog runs without its signal handlers, and
%   these are what turn a C-stack overflow into an error: parsing a term
%   nested deeper than the C stack holds would kill the process. So File is
%   read in a thread of its own whose C stack holds more levels than any term
%   in File can reach while it is parsed (the caller counts the opening
%   brackets of a copy nobody else writes).
load_facts(M, File, Mode, RuleFiles, CStack, Count, Status) :-
    catch(thread_create(load_facts_(M, File, Mode, RuleFiles, CStack), Id, [c_stack(CStack)]),
          E, true),
    (   nonvar(E)
    ->  Count = 0, message_(E, File, Text), Status = error-Text
    ;   thread_join(Id, Exit),
        (   Exit = exited(Count-Status)
        ->  true
        ;   Count = 0, message_(Exit, File, Text), Status = error-Text
        )
    ).

load_facts_(M, File, Mode, RuleFiles, CStack) :-
    thread_self(Me),
    assertz(reading_(Me)),
    b_setval(neurosym_rule_files, RuleFiles),
    b_setval(neurosym_c_stack, CStack),
    catch(( load_(M, File, Mode, RuleFiles, Count0), no_warnings_(Me) ), E, true),
    (   var(E)
    ->  Count = Count0, Status = ok
    ;   Count = 0,
        ( Mode == assert -> rollback_(M) ; true ),
        message_(E, File, Text),
        Status = error-Text
    ),
    retractall(warned_(Me, _)),
    thread_exit(Count-Status).

% Anything SWI-Prolog warns about while reading (text that is not valid in
% the file's encoding, above all) refuses the file: a warning printed on the
% way would be the only sign that facts were read wrong.
:- thread_local reading_/1.   % reading_(Owner): this thread reads for load thread Owner
:- dynamic warned_/2.         % warned_(Owner, Text): the first warning of a load

:- multifile user:message_hook/3.
:- dynamic user:message_hook/3.
user:message_hook(_Term, Kind, Lines) :-
    ( Kind == warning ; Kind == error ),
    neurosym_facts:reading_(Owner),
    !,
    neurosym_facts:note_warning_(Owner, Lines).

note_warning_(Owner, Lines) :-
    (   warned_(Owner, _)
    ->  true
    ;   lines_text(Lines, Text),
        assertz(warned_(Owner, Text))
    ).

no_warnings_(Owner) :-
    (   warned_(Owner, Text)
    ->  throw(neurosym_warned(Text))
    ;   true
    ).

% A large file is cut at line starts into one chunk per thread. Helper
% threads read and check chunks 1.. into lists on their own stacks while this
% thread reads chunk 0 and adds it; then each helper in turn, when told to,
% adds its own list (nothing is copied between threads), so clauses are added
% in file order. A helper's chunk is used only once the chunk before it is
% known to end exactly at its first byte (so a cut inside a quoted atom or a
% comment is detected), and only when the helper read all of it as plain
% facts without a warning; otherwise this thread reads that part itself, so
% results, order and error lines never depend on the cuts.
load_(M, File, Mode, RuleFiles, Count) :-
    cuts_(File, Cuts),
    flag(neurosym_chunks_taken, _, 0),
    setup_call_cleanup(
        ( open(File, read, S, [encoding(utf8)]),
          start_helpers_(Cuts, File, M, Mode, RuleFiles, Helpers) ),
        read_chunks_(Helpers, S, M, Mode, Count),
        ( close(S), stop_helpers_(Helpers) )).

cuts_(File, Cuts) :-
    size_file(File, Size),
    reader_threads(Threads),
    chunk_bytes_(Min),
    (   Size >= Min, Threads >= 2, current_prolog_flag(threads, true)
    ->  setup_call_cleanup(open(File, read, S, [type(binary)]),
                           findall(Cut, ( between(1, Threads, I), I < Threads,
                                          cut_guess_(I, Threads, Size, Guess),
                                          line_start_(S, Guess, Cut) ), Cuts0),
                           close(S)),
        sort(Cuts0, Cuts)
    ;   Cuts = []
    ).

% This thread reads and adds chunk 0 while the helpers only read theirs, and
% they add theirs after it, so chunk 0 is the smaller one: reading and
% checking are about 4/5 of the work, and with 2 threads both finish reading
% at about the same time when chunk 0 is 0.45 of the file (1 M facts: the
% loading thread 2.6 s, the helper 2.6 s reading and 0.4 s adding, CPU
% seconds on a busy machine).
cut_guess_(I, Threads, Size, Guess) :-
    First is 0.9 / Threads,
    Guess is truncate(Size * (First + (I - 1) * (1 - First) / (Threads - 1))).

line_start_(S, Guess, Cut) :-
    seek(S, Guess, bof, _),
    skip(S, 0'\n),
    \+ at_end_of_stream(S),
    byte_count(S, Cut).

% helper(Thread, Queue, From, To): the chunk [From, To), To = eof for the last one.
start_helpers_(Cuts, File, M, Mode, RuleFiles, Helpers) :-
    append(Cuts, [eof], Ends),
    start_helpers_(Cuts, Ends, File, M, Mode, RuleFiles, Helpers).

start_helpers_([], _, _, _, _, _, []).
start_helpers_([From|Fs], [_, To|Ts], File, M, Mode, RuleFiles, [helper(Id, Q, From, To)|Hs]) :-
    message_queue_create(Q),
    b_getval(neurosym_c_stack, CStack),
    thread_create(read_chunk_(File, M, Mode, RuleFiles, Q, From, To), Id, [c_stack(CStack)]),
    start_helpers_(Fs, [To|Ts], File, M, Mode, RuleFiles, Hs).

% A helper waiting for add is woken by the signal.
stop_helpers_(Helpers) :-
    forall(member(helper(Id, Q, _, _), Helpers),
           (   catch(thread_signal(Id, throw(neurosym_stop)), _, true),
               catch(thread_join(Id, _), _, true),
               catch(message_queue_destroy(Q), _, true)
           )).

% In a helper thread: reads and checks the chunk [From, To) into a list (in
% mode check, only checks it), then sends ready(End, Count, Preds, Lines-Col),
% End the byte after its last term (eof at the end of the file), Preds the
% Name/Arity it holds, Lines-Col the new lines it read and the column it
% stopped at (the stream's position counts), or failed: at anything but
% plain facts, or a warning, the main thread reads that part itself. Then it
% waits for add, adds its list, and sends added. stop_helpers_/1 stops it
% with neurosym_stop at any point.
read_chunk_(File, M, Mode, RuleFiles, Q, From, To) :-
    catch(chunk_(File, M, Mode, RuleFiles, Q, From, To), neurosym_stop, true).

chunk_(File, M, Mode, RuleFiles, Q, From, To) :-
    thread_self(Me),
    assertz(reading_(Me)),
    b_setval(neurosym_rule_files, RuleFiles),
    (   catch(setup_call_cleanup(
                  ( open(File, read, S, [encoding(utf8)]), seek(S, From, bof, _) ),
                  ( line_count(S, L0), line_position(S, P0),
                    chunk_terms_(S, M, Mode, To, -, -1, From, [], Terms, 0, K, Preds, End),
                    line_count(S, L1), line_position(S, P1) ),
                  close(S)),
              _, fail),
        \+ warned_(Me, _)
    ->  Lines is L1 - L0,
        ( Lines > 0 -> Col = P1 ; Col is P1 - P0 ),
        thread_send_message(Q, ready(End, K, Preds, Lines-Col)),
        thread_get_message(add),
        add_all_(Terms, M),
        thread_send_message(Q, added)
    ;   retractall(warned_(Me, _)),
        thread_send_message(Q, failed)
    ).

% chunk_terms_(+S, +M, +Mode, +To, +PName, +PArity, +B0, +Preds0, -Terms, +K0, -K, -Preds, -End):
% the terms up to the one that reaches byte To (all of them in mode assert,
% none in mode check), K counting them; fails at anything but a plain fact.
chunk_terms_(S, M, Mode, To, PName, PArity, B0, Preds0, Terms, K0, K, Preds, End) :-
    read_(S, 0, B0, T, QQ, B1),
    (   T == end_of_file
    ->  Terms = [], K = K0, Preds = Preds0, End = eof
    ;   QQ == [],
        (   same_(T, PName, PArity)
        ->  Name = PName, Arity = PArity, Preds1 = Preds0
        ;   T \= (:- _),
            check_(T, S, M, check, 0, Name, Arity),
            ( memberchk(Name/Arity, Preds0) -> Preds1 = Preds0 ; Preds1 = [Name/Arity|Preds0] )
        ),
        ( Mode == assert -> Terms = [T|Terms1] ; Terms = Terms1 ),
        K1 is K0 + 1,
        (   To \== eof, at_stop_(S, To, B1, B), B >= To
        ->  Terms1 = [], K = K1, Preds = Preds1, End = B
        ;   chunk_terms_(S, M, Mode, To, Name, Arity, B1, Preds1, Terms1, K1, K, Preds, End)
        )
    ).

add_all_([], _).
add_all_([T|Ts], M) :- assertz(M:T), add_all_(Ts, M).

% Chunk 0 from the stream, then each helper's chunk while the cuts hold.
read_chunks_([], S, M, Mode, N) :- !,
    read_loop_(S, M, Mode, -, -1, 0, N).
read_chunks_(Helpers, S, M, Mode, N) :-
    Helpers = [helper(_, _, Cut, _)|_],
    read_until_(S, M, Mode, Cut, -, -1, 0, N0, PName, PArity, End),
    (   End == Cut
    ->  line_count(S, Line),
        take_chunks_(Helpers, S, M, Mode, Line, N0, N)
    ;   End == eof
    ->  N = N0
    ;   read_loop_(S, M, Mode, PName, PArity, N0, N)
    ).

% Each helper adds its chunk once this thread has noted what the chunk
% touches (for the rollback of a refused file); a helper that failed has its
% chunk read here, and so has the rest of a chunk that did not end at the
% next cut. Line: the line at From, so that a syntax error read here names
% its line (the stream is positioned with its line count).
take_chunks_([], _, _, _, _, N, N).
take_chunks_([helper(Id, Q, From, To)|Hs], S, M, Mode, Line, N0, N) :-
    helper_message_(Id, Q, Msg),
    (   Msg = ready(End, K, Preds, Lines-Col)
    ->  forall(member(Name/Arity, Preds), note_touched_(M, Name, Arity)),
        thread_send_message(Id, add),
        helper_message_(Id, Q, Done),
        (   Done == added
        ->  true
        ;   throw(error(system_error('a reading thread stopped while adding its facts'), _))
        ),
        flag(neurosym_chunks_taken, Taken, Taken + 1),
        N1 is N0 + K,
        Line1 is Line + Lines,
        (   End == To
        ->  take_chunks_(Hs, S, M, Mode, Line1, N1, N)
        ;   End == eof          % an end_of_file term ends the facts
        ->  N = N1
        ;   set_stream_position(S, '$stream_position'(End, Line1, Col, End)),
            read_loop_(S, M, Mode, -, -1, N1, N)
        )
    ;   set_stream_position(S, '$stream_position'(From, Line, 0, From)),
        read_loop_(S, M, Mode, -, -1, N0, N)
    ).

% The helper's next message; failed when it is gone without one.
helper_message_(Id, Q, Msg) :-
    (   thread_get_message(Q, Msg0, [timeout(1)])
    ->  Msg = Msg0
    ;   catch(thread_property(Id, status(running)), _, fail)
    ->  helper_message_(Id, Q, Msg)
    ;   thread_get_message(Q, Msg0, [timeout(0)])
    ->  Msg = Msg0
    ;   Msg = failed
    ).

% Like read_loop_, stopping after the term that reaches byte Stop: End is
% that byte position, or eof.
read_until_(S, M, Mode, Stop, PName, PArity, N0, N, LName, LArity, End) :-
    byte_count(S, B0),
    read_until_(S, M, Mode, Stop, PName, PArity, B0, N0, N, LName, LArity, End).

read_until_(S, M, Mode, Stop, PName, PArity, B0, N0, N, LName, LArity, End) :-
    N1 is N0 + 1,
    read_(S, N1, B0, T, QQ, B1),
    (   T == end_of_file
    ->  N = N0, LName = PName, LArity = PArity, End = eof
    ;
        (   QQ \== []
        ->  refuse_(N1, 'a quasi-quotation', T)
        ;   same_(T, PName, PArity)
        ->  Name = PName, Arity = PArity
        ;   check_(T, S, M, Mode, N1, Name, Arity),
            (   T = (:- encoding(Enc)), Enc \== utf8
            ->  Stop1 = never   % the helpers decoded the rest as UTF-8
            ;   true
            )
        ),
        (   Name == (:-)
        ->  Name2 = PName, Arity2 = PArity
        ;   ( Mode == assert -> assertz(M:T) ; true ),
            Name2 = Name, Arity2 = Arity
        ),
        ( var(Stop1) -> Stop1 = Stop ; true ),
        (   Stop1 \== never, at_stop_(S, Stop1, B1, B), B >= Stop1
        ->  N = N1, LName = Name2, LArity = Arity2, End = B
        ;   read_until_(S, M, Mode, Stop1, Name2, Arity2, B1, N1, N, LName, LArity, End)
        )
    ).

%   at_stop_(+S, +Stop, +B0, -B): B is B0, the byte position after the term
%   just read, or the position after the white space that follows it when
%   that reaches byte Stop: read_term/3 leaves the new line after a full stop
%   unread, and a cut is a line start.
at_stop_(S, Stop, B0, B) :-
    (   ( B0 >= Stop ; B0 + 4 < Stop )
    ->  B = B0
    ;   peek_code(S, C), C >= 0, code_type(C, space)
    ->  get_code(S, _),
        byte_count(S, B1),
        at_stop_(S, Stop, B1, B)
    ;   B = B0
    ).

% The tight loop: a fact of the same predicate as the previous one needs no
% check beyond its functor and groundness; a new functor goes through check_/7 once.
read_loop_(S, M, Mode, PName, PArity, N0, N) :-
    byte_count(S, B0),
    read_loop_(S, M, Mode, PName, PArity, B0, N0, N).

read_loop_(S, M, Mode, PName, PArity, B0, N0, N) :-
    N1 is N0 + 1,
    read_(S, N1, B0, T, QQ, B),
    (   T == end_of_file
    ->  N = N0
    ;
        (   QQ \== []
        ->  refuse_(N1, 'a quasi-quotation', T)
        ;   same_(T, PName, PArity)
        ->  Name = PName, Arity = PArity
        ;   check_(T, S, M, Mode, N1, Name, Arity)
        ),
        (   Name == (:-)
        ->  read_loop_(S, M, Mode, PName, PArity, B, N1, N)  % an accepted header
        ;   ( Mode == assert -> assertz(M:T) ; true ),
            read_loop_(S, M, Mode, Name, Arity, B, N1, N)
        )
    ).

%   read_(+S, +N, +B0, -T, -QQ, -B): the N-th term of S (end_of_file at the
%   end), refused when nested more than max_depth_/1 levels deep; B0 and B:
%   the byte positions before and after it. Each level takes at least one
%   byte of text (an opening bracket or an operator), so only a term whose
%   text is longer than that limit is measured (B - B0 counts the layout
%   before it too: a bound, still). The parse itself is safe: the reading
%   thread's C stack holds as many levels as the file's brackets (load_facts/7).
read_(S, N, B0, T, QQ, B) :-
    read_term(S, T, [syntax_errors(error), quasi_quotations(QQ), module(neurosym_facts)]),
    byte_count(S, B),
    max_depth_(D),
    (   B - B0 =< D
    ->  true
    ;   shallow_(T, D)
    ->  true
    ;   format(atom(What), 'a term nested more than ~D levels deep', [D]),
        refuse_(N, What, T)
    ).

%   shallow_(+T, +D): T is nested at most D levels deep (a compound or a
%   proper list is one level, as the bridge counts answers).
shallow_(T, D) :-
    (   compound(T)
    ->  D > 0,
        D1 is D - 1,
        (   is_list(T)
        ->  forall(member(X, T), shallow_(X, D1))
        ;   compound_name_arguments(T, _, As),
            forall(member(A, As), shallow_(A, D1))
        )
    ;   true
    ).

%   same_(+T, +Name, +Arity): T is a ground fact of the predicate just checked.
same_(T, Name, Arity) :- nonvar(T), functor(T, Name, Arity), ground(T).

%   check_(+Term, +Stream, +M, +Mode, +N, -Name, -Arity): the predicate of a
%   fact, or (:-)/1 for an accepted header; throws neurosym_refused/3.
%   A term is admitted when it has the shape of a fact (fact_shape_/1), not
%   when it misses a list of known bad forms: a clause-like form SWI-Prolog
%   adds one day has an operator for a name, and is refused as it is today.
check_((:- D), S, M, Mode, N, (:-), 1) :- nonvar(D), !, header_(D, S, M, Mode, N).
check_(T, _, M, _, N, Name, Arity) :-
    (   fact_shape_(T)
    ->  functor(T, Name, Arity),
        predicate_check_(M, Name, Arity, N, T),
        ( ground(T) -> true ; refuse_(N, 'a fact with a variable (facts are ground)', T) ),
        note_touched_(M, Name, Arity)
    ;   not_a_fact_(T, What),
        refuse_(N, What, T)
    ).

%   fact_shape_(+T): T is an atom or compound whose name is a plain
%   predicate name (plain_name_/1); check_/7 then asks for it to be ground.
fact_shape_(T) :-
    callable(T),
    functor(T, Name, _),
    plain_name_(Name).

%   plain_name_(+Name): a name written without quotes that is no operator:
%   a lowercase letter, then letters, digits and underscores (p, kb_meta,
%   ключ). Operators (:-, =>, -->, ?-, :) and quoted names are not.
plain_name_(Name) :-
    atom(Name),
    atom_codes(Name, [C|Cs]),
    code_type(C, csymf), C \== 0'_, \+ code_type(C, upper),
    forall(member(X, Cs), code_type(X, csym)).

%   not_a_fact_(+T, -What): what T is, for the message.
not_a_fact_(T, 'a variable where a fact should be') :- var(T), !.
not_a_fact_((?- _), 'a directive') :- !.
not_a_fact_((:- _), 'a directive') :- !.
not_a_fact_((_ :- _), 'a clause with a body (a rule)') :- !.
not_a_fact_((_ => _), 'a rule (Head => Body)') :- !.
not_a_fact_((_ --> _), 'a grammar rule') :- !.
not_a_fact_((_ : _), 'a module-qualified clause') :- !.
not_a_fact_(T, 'a term that is not a fact') :- \+ callable(T), !.
not_a_fact_(T, What) :-
    functor(T, Name, Arity),
    \+ plain_name_(Name), !,
    format(atom(What), 'a term whose name ~q (~q/~w) is not a plain predicate name', [Name, Name, Arity]).

header_(D, S, M, Mode, N) :-
    (   D = encoding(Enc), atom(Enc),
        catch(set_stream(S, encoding(Enc)), _, fail)
    ->  true
    ;   D = dynamic(Spec), specs_(Spec, PIs)
    ->  forall(member(Name/Arity, PIs),
               (   (   plain_name_(Name)
                   ->  true
                   ;   format(atom(What), 'a declaration of ~q/~w, which is not a plain predicate name',
                              [Name, Arity]),
                       refuse_(N, What, (:- D))
                   ),
                   predicate_check_(M, Name, Arity, N, (:- D)),
                   note_touched_(M, Name, Arity),
                   ( Mode == assert -> dynamic(M:Name/Arity) ; true )
               ))
    ;   refuse_(N, 'a directive', (:- D))
    ).

specs_(Spec, _) :- var(Spec), !, fail.
specs_((A, B), PIs) :- !, specs_(A, P1), specs_(B, P2), append(P1, P2, PIs).
specs_(List, PIs) :- is_list(List), !, specs_list_(List, PIs).
specs_(Name/Arity, [Name/Arity]) :- atom(Name), integer(Arity), Arity >= 0.

specs_list_([], []).
specs_list_([H|T], PIs) :- specs_(H, P1), specs_list_(T, P2), append(P1, P2, PIs).

predicate_check_(M, Name, Arity, N, T) :-
    (   predicate_problem_(M, Name, Arity, What)
    ->  refuse_(N, What, T)
    ;   true
    ).

% The library index is asked before anything that could autoload.
predicate_problem_(M, Name, Arity, What) :-
    functor(Head, Name, Arity),
    (   hook_(Name, Arity)
    ->  format(atom(What), 'a fact for the hook predicate ~q/~w', [Name, Arity])
    ;   catch('$in_library'(Name, Arity, Lib), _, fail)
    ->  file_base_name(Lib, Base),
        format(atom(What), 'a fact for the library predicate ~q/~w (library ~w)', [Name, Arity, Base])
    ;   predicate_property(system:Head, defined)
    ->  format(atom(What), 'a fact for the built-in predicate ~q/~w', [Name, Arity])
    ;   predicate_property(M:Head, imported_from(From))
    ->  format(atom(What), 'a fact for ~q/~w, which the rules import from module ~q', [Name, Arity, From])
    ;   predicate_property(M:Head, defined), \+ predicate_property(M:Head, dynamic),
        predicate_property(M:Head, file(File)),
        b_getval(neurosym_rule_files, RuleFiles), memberchk(File, RuleFiles)
    ->  format(atom(What), 'a fact for ~q/~w, which the rule files define', [Name, Arity])
    ).

% Hook and expansion predicates: SWI-Prolog calls these by name (some in the
% loading module, most in user or prolog), so data may never define them.
hook_(term_expansion, 2).
hook_(term_expansion, 4).
hook_(goal_expansion, 2).
hook_(goal_expansion, 4).
hook_(portray, 1).
hook_(message_hook, 3).
hook_(prolog_load_file, 2).
hook_(exception, 3).
hook_(expand_query, 4).
hook_(expand_answer, 2).
hook_(file_search_path, 2).
hook_(library_directory, 1).
hook_(prolog_file_type, 2).
hook_(resource, 2).
hook_(resource, 3).
hook_(message_property, 2).
hook_(prolog_message, 3).
hook_(message, 3).
hook_(prolog_list_goal, 1).
hook_(prolog_predicate_name, 2).
hook_(prolog_clause_name, 2).
hook_(prolog_uncaught_exception_hook, 4).
hook_(prolog_exception_hook, 4).
hook_(prolog_exception_hook, 5).
hook_(prolog_trace_interception, 4).
hook_(prolog_event_hook, 1).
hook_(attr_unify_hook, 2).
hook_(attribute_goals, 3).
hook_(attr_portray_hook, 2).
hook_(term_to_atom_hook, 2).
hook_(Name, Arity) :-
    functor(Head, Name, Arity),
    (   predicate_property(user:Head, multifile)
    ;   predicate_property(prolog:Head, multifile)
    ;   predicate_property(system:Head, multifile)
    ),
    !.

note_touched_(M, Name, Arity) :-
    functor(Head, Name, Arity),
    (   touched_(Name, Arity, _)
    ->  true
    ;   predicate_property(M:Head, number_of_clauses(C))
    ->  assertz(touched_(Name, Arity, C))
    ;   predicate_property(M:Head, defined)
    ->  assertz(touched_(Name, Arity, 0))
    ;   assertz(touched_(Name, Arity, new))
    ).

% What this file added is taken out again: clauses past the count a
% predicate had before, and predicates the file created.
rollback_(M) :-
    forall(touched_(Name, Arity, Before),
           (   functor(Head, Name, Arity),
               (   Before == new
               ->  catch(abolish(M:Name/Arity), _, true)
               ;   forall(( nth_clause(M:Head, I, Ref), I > Before ), erase(Ref))
               )
           )).

refuse_(N, What, Term) :- throw(neurosym_refused(N, What, Term)).

% One line: File:Line: what was found, and what a fact file may hold.
message_(neurosym_refused(N, What, Term), File, Text) :- !,
    term_line_(File, N, Line),
    with_output_to(string(Shown),
                   \+ \+ ( numbervars(Term, 0, _),
                           write_term(Term, [quoted(true), max_depth(8), portray(false),
                                             numbervars(true), spacing(next_argument)]) )),
    format(string(Text),
           "~w:~w: found ~w: ~w; a fact file holds only ground facts such as p(a, 1). and the \c
            writer's :- encoding/dynamic headers (load code as rules, or trust the file)",
           [File, Line, What, Shown]).
message_(neurosym_warned(Warning), File, Text) :- !,
    format(string(Text), "~w: ~w (a fact file is UTF-8 text, or says :- encoding(Enc). first)",
           [File, Warning]).
message_(error(syntax_error(What), Context), File, Text) :- !,
    (   catch('$messages':translate_message(error(syntax_error(What), _), Lines, []), _, fail),
        lines_text(Lines, Msg)
    ->  true
    ;   format(string(Msg), "Syntax error: ~w", [What])
    ),
    (   compound(Context), Context =.. [_, _, Line, LinePos, _], integer(Line)
    ->  format(string(Text), "~w:~w:~w: ~w", [File, Line, LinePos, Msg])
    ;   format(string(Text), "~w: ~w", [File, Msg])
    ).
message_(E, File, Text) :-
    (   catch('$messages':translate_message(E, Lines, []), _, fail),
        lines_text(Lines, Msg)
    ->  true
    ;   format(string(Msg), "~q", [E])
    ),
    format(string(Text), "~w: ~w", [File, Msg]).

%!  lines_text(+Lines, -Text:string) is det.
%   A message's format lines (print_message_lines/3) as one line of text, runs of
%   white space and the line breaks between them as single spaces. The bridge
%   words its load messages with it too.
lines_text(Lines, Text) :-
    with_output_to(string(Text0), print_message_lines(current_output, '', Lines)),
    split_string(Text0, "\n", " \t", Parts0),
    exclude(==(""), Parts0, Parts),
    atomic_list_concat(Parts, ' ', Atom),
    atom_string(Atom, Text).

% The line where the N-th term starts (only computed for an error).
term_line_(File, N, Line) :-
    catch(setup_call_cleanup(
              open(File, read, S, [encoding(utf8)]),
              nth_term_line_(S, N, Line),
              close(S)),
          _, Line = '?').

nth_term_line_(S, N, Line) :-
    read_term(S, T, [syntax_errors(quiet), term_position(P), quasi_quotations(_),
                     module(neurosym_facts)]),
    (   N =:= 1
    ->  stream_position_data(line_count, P, Line)
    ;   T == end_of_file
    ->  Line = '?'
    ;   ( T = (:- encoding(Enc)), atom(Enc) -> catch(set_stream(S, encoding(Enc)), _, true) ; true ),
        N1 is N - 1,
        nth_term_line_(S, N1, Line)
    ).
