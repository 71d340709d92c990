:- module(neurosym_interrupt, [stop/1]).

/** <module> Ctrl-C for janus calls: the Prolog half

Python (=|neurosym/prolog/interrupt.py|=) loads this file once per process.
Its watcher thread posts stop/1 to the Prolog thread of Python's main thread
with thread_signal/2 when SIGINT arrives during an interruptible block.
*/

%!  stop(+Block) is det.
%   Posted to the main thread by the watcher; aborts the goal while
%   interruptible block Block still runs (abort/0: a catch/3 in the goal
%   cannot swallow it), and does nothing when the signal arrives after the
%   block ended (Python's running(Block) says which block runs).
stop(Block) :-
    py_call('neurosym.prolog.interrupt':running(Block), Running),
    (   Running == @(true)
    ->  abort
    ;   true
    ).
