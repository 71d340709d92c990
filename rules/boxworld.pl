/*  boxworld.pl -- Box-World: keys, locks, the chain to the gem, distractors,
    and what the network relates.

    Load it beside a neurosym knowledge base:  swipl kb.pl rules/boxworld.pl

    Expects the facts of docs/design.md:
        object(Id, Type)    Type key(C), lock(C), gem, agent
        at(E, T, Id, R, C)  a box is a lock with its content in the cell to
                            its left; a loose key has no lock to its right
        holding(E, T, key(C)), event(E, T, got(key(C)) | got(gem) |
        opened(lock(C)) | hit(distractor)), episode(E, Steps, Return, Outcome)
        holds/5, attention/6, attends/8 for the network-level rules; the held
        key is the entity held(C) (drawn in the top-left border cell).
    The map of an episode is read at its state 0.

    A module (boxworld) whose helpers stay inside it, so it loads beside the
    other rule files without clashes. It reads the facts as unqualified
    goals, which resolve through its default import module: user in plain
    swipl, the KB's own module in neurosym.prolog.KnowledgeBase (which loads
    the rule modules once per KB, see lib/kb_common.pl).
*/

:- module(boxworld,
          [ box/3,
            loose_key/2,
            solution_chain/2,
            distractor_box/3,
            key_opens/2,
            got_order/2,
            gem_chain/2,
            followed_solution/1,
            distractor_taken/1,
            distractor_avoided/1,
            key_lock_link/2,
            wrong_key_lock_link/3,
            attends_matching_lock/3,
            matching_lock_rate/2
          ]).

:- use_module(library(lists)).
:- use_module(library(pairs)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).

:- include(lib/kb_common).

%!  box(?Episode, ?Lock, ?Content) is nondet.
%
%   At the start of Episode a box locked with Lock (lock(C)) holds Content
%   (key(C2) or gem).
%
%       ?- box(0, lock(red), X).
%       X = key(blue).

box(E, Lock, Content) :-
    box_at_(E, Lock, Content, _, _).

%!  loose_key(?Episode, ?Key) is nondet.
%
%   Key lies loose (in no box) at the start of Episode.
%
%       ?- loose_key(0, K).
%       K = key(red).

loose_key(E, key(C)) :-
    at(E, 0, Id, R, Col),
    object(Id, key(C)),
    Right is Col + 1,
    \+ ( at(E, 0, Id2, R, Right), object(Id2, lock(_)) ).

%!  solution_chain(?Episode, -Chain:list) is nondet.
%
%   Chain is the way from a loose key to the gem in Episode's map: the loose
%   key, then the content of each box that the previous key opens, ending
%   with gem. Distractor branches end in keys that open nothing and are not
%   part of any chain.
%
%       ?- solution_chain(0, Chain).
%       Chain = [key(red), key(blue), gem].

solution_chain(E, [Key|Rest]) :-
    loose_key(E, Key),
    chain_from_(E, Key, [Key], Rest).

%!  distractor_box(?Episode, ?Lock, ?Content) is nondet.
%
%   A box of Episode's map that is not on the solution chain: its lock takes
%   a key but its content leads nowhere (opening it ends the episode).
%
%       ?- distractor_box(0, L, X).
%       L = lock(red), X = key(green).

distractor_box(E, Lock, Content) :-
    box(E, Lock, Content),
    \+ on_chain_(E, Lock, Content).

%!  key_opens(?Key, ?Lock) is nondet.
%
%   Some episode opened Lock while holding Key: which key opens which lock,
%   read from the trace. Each pair once.
%
%       ?- key_opens(key(red), L).
%       L = lock(red).

key_opens(Key, Lock) :-
    distinct(Key-Lock, ( event(E, T, opened(Lock)), holding(E, T, Key) )).

%!  got_order(?Episode, -Items:list) is nondet.
%
%   Items lists what the agent got in Episode (keys and the gem), in order.
%   Deterministic when Episode is bound.
%
%       ?- got_order(0, Items).
%       Items = [key(red), key(blue), gem].

got_order(E, Items) :-
    kb_episode_(E),
    findall(T-I, ( event(E, T, Ev), Ev = got(I) ), Pairs0),
    keysort(Pairs0, Pairs),
    pairs_values(Pairs, Items).

%!  gem_chain(?Episode, -Chain:list) is nondet.
%
%   Episode reached the gem and Chain is what it got on the way, in order.
%
%       ?- gem_chain(E, C).
%       E = 0, C = [key(red), key(blue), gem].

gem_chain(E, Chain) :-
    got_order(E, Chain),
    last(Chain, gem).

%!  followed_solution(?Episode) is nondet.
%
%   Episode reached the gem along its map's solution chain, getting nothing
%   else on the way.
%
%       ?- followed_solution(E).
%       E = 0.

followed_solution(E) :-
    gem_chain(E, Chain),
    once(solution_chain(E, Chain)).

%!  distractor_taken(?Episode) is nondet.
%
%   Episode opened a distractor box (which ended it).
%
%       ?- distractor_taken(E).
%       E = 1.

distractor_taken(E) :-
    kb_episode_(E),
    kb_event_(E, hit(distractor)).

%!  distractor_avoided(?Episode) is nondet.
%
%   Episode's map had a distractor box and the agent reached the gem without
%   opening one.
%
%       ?- distractor_avoided(E).
%       E = 0.

distractor_avoided(E) :-
    kb_episode_(E),
    once(distractor_box(E, _, _)),
    kb_event_(E, got(gem)),
    \+ kb_event_(E, hit(distractor)).

%!  key_lock_link(?Colour, -Answer) is nondet.
%
%   How the network relates a key of Colour (loose key(C) or held key
%   held(C), as one key) with the lock(C) of the same colour, state by
%   state: Answer is direct(Links, share(N, D)), indirect(Vias),
%   co_occurring(Vias) or none, as sword_enemy_link/1 of rgw.pl words them.
%   Every share(N, D) is N states out of the D states the agent acted in,
%   over all episodes (the sum of episode/4's Steps). One answer per colour
%   of a lock among the KB's objects (object/2), in standard order.
%
%       ?- key_lock_link(C, A).
%       C = blue, A = direct([r(2)], share(1, 317)) ;
%       C = red, A = direct([r(1)], share(1, 317)) ;
%       C = yellow, A = none.

key_lock_link(C, Answer) :-
    setof(C0, Id^object(Id, lock(C0)), Cs),
    member(C, Cs),
    kb_link_answer_([key(C), held(C)], [lock(C)], Answer).

%!  wrong_key_lock_link(?Key, ?Lock, ?Link) is nondet.
%
%   The network relates Key (key(C1) or held(C1)) with Lock = lock(C2) of
%   another colour, through Link. Each triple once.
%
%       ?- wrong_key_lock_link(K, L, R).
%       K = held(red), L = lock(green), R = r(0).

wrong_key_lock_link(Key, lock(C2), Link) :-
    distinct(Key-C2-Link, ( kb_link_(Key, lock(C2), Link),
                            key_colour_(Key, C1),
                            C1 \== C2 )).

%!  attends_matching_lock(?Episode, ?T, ?Head) is nondet.
%
%   At state T of Episode the agent held key(C) and Head's first or second
%   attended entity was lock(C): the head looked at a lock the held key
%   opens. Each (Episode, T, Head) once.
%
%       ?- attends_matching_lock(E, T, H).
%       E = 0, T = 4, H = 1.

attends_matching_lock(E, T, H) :-
    holding(E, T, key(C)),
    distinct(H, attends(E, T, H, _, lock(C), _, _, _)).

%!  matching_lock_rate(-Attended, -Holding) is det.
%
%   Of the Holding states at which the agent held a key, Attended had some
%   head attending a lock of the held key's colour.
%
%       ?- matching_lock_rate(A, N).
%       A = 1, N = 5.

matching_lock_rate(Attended, Holding) :-
    aggregate_all(count, holding(_, _, key(_)), Holding),
    aggregate_all(count,
                  ( holding(E, T, key(C)),
                    once(attends(E, T, _, _, lock(C), _, _, _)) ),
                  Attended).

% ------------------------------------------------------------------ helpers
%
% Episodes, events and the network's links: lib/kb_common.pl.

%   box_at_(?E, ?Lock, ?Content, ?Row, ?Col): a box at the start of E, its
%   lock at (Row, Col) and its content at (Row, Col - 1).
box_at_(E, lock(C), Content, R, Col) :-
    at(E, 0, LockId, R, Col),
    object(LockId, lock(C)),
    Left is Col - 1,
    at(E, 0, ContentId, R, Left),
    object(ContentId, Content).

%   chain_from_(+E, +Key, +Seen, -Rest): Rest leads from Key to the gem.
chain_from_(E, key(C), Seen, Chain) :-
    box(E, lock(C), Content),
    \+ memberchk(Content, Seen),
    (   Content == gem
    ->  Chain = [gem]
    ;   Chain = [Content|Rest],
        chain_from_(E, Content, [Content|Seen], Rest)
    ).

%   on_chain_(+E, +Lock, +Content): the box Lock/Content is a step of a
%   solution chain of E (key(C) followed by Content, Lock = lock(C)).
on_chain_(E, lock(C), Content) :-
    solution_chain(E, Chain),
    nextto(key(C), Content, Chain),
    !.

key_colour_(key(C), C).
key_colour_(held(C), C).
