/*  plunit tests of interrupt.pl: stop/1 aborts the goal only while the
    interruptible block it was posted for still runs.

    swipl -g run_tests -t halt neurosym/prolog/pl/interrupt.plt

Python answers stop/1's question (neurosym.prolog.interrupt.running/1); no
Python embeds this swipl, so the question is answered here by a py_call/2
defined in the module before the file is loaded: block 7 runs.
*/

:- dynamic neurosym_interrupt:py_call/2.
neurosym_interrupt:py_call('neurosym.prolog.interrupt':running(Block), Running) :-
    ( Block == 7 -> Running = @(true) ; Running = @(false) ).

:- prolog_load_context(directory, Dir),
   atom_concat(Dir, '/interrupt.pl', Interrupt),
   use_module(Interrupt).

:- begin_tests(interrupt).

%   exit(:Goal, -Status): how Goal ends in a thread of its own (abort/0
%   would end this test run too).
exit(Goal, Status) :-
    thread_create(Goal, Id),
    thread_join(Id, Status).

test(aborts_the_running_block, [Status == exception('$aborted')]) :-
    exit(stop(7), Status).

test(does_nothing_once_the_block_ended, [Status == true]) :-
    exit(stop(6), Status).

test(abort_is_not_swallowed_by_the_goal, [Status == exception('$aborted')]) :-
    exit(catch(stop(7), _, true), Status).

:- end_tests(interrupt).
