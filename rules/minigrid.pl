/*  minigrid.pl -- Farama Minigrid and BabyAI: keys before doors, doors opened
    with a key of their colour, missions done, and what the network relates.

    Load it beside a neurosym knowledge base:  swipl kb.pl rules/minigrid.pl

    Expects the facts of docs/design.md:
        object(Id, Type)    Type key(C), door(C), ball(C), box(C), goal, agent
        at(E, T, Id, R, C), holding(E, T, Item), facing(E, T, Dir),
        door_state(E, T, Id, open | closed | locked), mission(E, Text),
        event(E, T, picked(X) | dropped(X) | unlocked(door(C)) |
        opened(door(C)) | closed(door(C)) | opened(box(C)) | bumped(X) |
        reached(goal) | fell(lava) | achieved(mission)),
        episode(E, Steps, Return, Outcome)
        holds/5, attention/6 for the network-level rules.

    A module (minigrid) whose helpers stay inside it, so it loads beside the
    other rule files without clashes; it reads the facts as unqualified goals
    (see lib/kb_common.pl).
*/

:- module(minigrid,
          [ key_before_door/2,
            key_before_door/1,
            unlocked_with_key/3,
            opens/2,
            mission_done/2,
            mission_done/1,
            mission_target/3,
            mission_shown/1,
            key_door_link/2,
            wrong_key_door_link/3
          ]).

:- use_module(library(lists)).
:- use_module(library(aggregate)).
:- use_module(library(solution_sequences)).

:- include(lib/kb_common).

%!  key_before_door(?Episode, ?Colour) is nondet.
%
%   Episode unlocked the door of Colour, and the agent had picked up the
%   key of that colour before (the first pick-up comes before the unlocking).
%
%       ?- key_before_door(0, C).
%       C = yellow.

key_before_door(E, C) :-
    distinct(E-C, event(E, _, unlocked(door(C)))),
    kb_first_event_(E, unlocked(door(C)), Td),
    kb_first_event_(E, picked(key(C)), Tk),
    Tk < Td.

%!  key_before_door(?Episode) is nondet.
%
%   Episode unlocked a door, and every door it unlocked it unlocked after
%   picking up the key of its colour.
%
%       ?- key_before_door(E).
%       E = 0.

key_before_door(E) :-
    kb_episode_(E),
    once(event(E, _, unlocked(_))),
    forall(event(E, _, unlocked(door(C))), key_before_door(E, C)).

%!  unlocked_with_key(?Episode, ?T, ?Door) is nondet.
%
%   At the step of state T the agent unlocked Door (door(C)) while holding
%   the key of its colour, key(C).
%
%       ?- unlocked_with_key(0, T, D).
%       T = 4, D = door(yellow).

unlocked_with_key(E, T, door(C)) :-
    event(E, T, unlocked(door(C))),
    holding(E, T, key(C)).

%!  opens(?Key, ?Door) is nondet.
%
%   Some episode unlocked Door while holding Key: which key opens which
%   door, read from the trace. Each pair once.
%
%       ?- opens(K, D).
%       K = key(yellow), D = door(yellow).

opens(Key, Door) :-
    distinct(Key-Door, ( event(E, T, unlocked(Door)), holding(E, T, Key) )).

%!  mission_done(?Episode, ?Mission) is nondet.
%
%   Episode's mission (its text, an atom) was done: the episode ended with a
%   reward (event achieved(mission)).
%
%       ?- mission_done(E, M).
%       E = 0, M = 'use the key to open the door and then get to the goal'.

mission_done(E, Mission) :-
    kb_episode_(E),
    kb_event_(E, achieved(mission)),
    mission(E, Mission).

%!  mission_done(?Episode) is nondet.
%
%   Episode's mission was done.
%
%       ?- mission_done(E).
%       E = 0.

mission_done(E) :-
    kb_episode_(E),
    kb_event_(E, achieved(mission)).

%!  mission_target(?Episode, ?Verb, ?Object) is nondet.
%
%   Episode's mission is a BabyAI instruction "go to", "pick up" or "open"
%   (Verb go_to, pick_up, open) of Object, a type with its colour
%   (ball(red), door(blue)); "a" and "the" both allowed.
%
%       ?- mission_target(E, V, O).
%       E = 2, V = pick_up, O = ball(red).

mission_target(E, Verb, Object) :-
    mission(E, Text),
    split_string(Text, " ", "", Words),
    target_words_(Words, Verb, Object).

%!  mission_shown(?Episode) is nondet.
%
%   Episode's mission was done and the trace shows its target done: a
%   pick_up mission's object picked up, an open mission's door opened, a
%   go_to mission ended with the agent facing an object of that type and
%   colour in the next cell.
%
%       ?- mission_shown(E).
%       E = 2.

mission_shown(E) :-
    mission_done(E),
    once(mission_target(E, Verb, Object)),
    target_shown_(E, Verb, Object).

%!  key_door_link(?Colour, ?Link) is nondet.
%
%   The network relates the key of Colour with the door of that colour,
%   through Link: r(J) above threshold (PrediNet) or attention(Head)
%   (MHDPA). Each Colour-Link once.
%
%       ?- key_door_link(C, L).
%       C = yellow, L = r(2).

key_door_link(C, Link) :-
    distinct(C-Link, kb_link_(key(C), door(C), Link)).

%!  wrong_key_door_link(?Key, ?Door, ?Link) is nondet.
%
%   The network relates Key = key(C1) with Door = door(C2) of another
%   colour, through Link. Each triple once.
%
%       ?- wrong_key_door_link(K, D, L).
%       K = key(red), D = door(blue), L = r(0).

wrong_key_door_link(key(C1), door(C2), Link) :-
    distinct(C1-C2-Link, ( kb_link_(key(C1), door(C2), Link), C1 \== C2 )).

% ------------------------------------------------------------------ helpers
%
% Episodes, events and the network's links: lib/kb_common.pl.

%   target_words_(+Words, -Verb, -Object): the words of a mission text.
target_words_(["go", "to", Det, C, T|_], go_to, Object) :-
    target_(Det, C, T, Object).
target_words_(["pick", "up", Det, C, T|_], pick_up, Object) :-
    target_(Det, C, T, Object).
target_words_(["open", Det, C, "door"|_], open, door(Colour)) :-
    target_(Det, C, "door", door(Colour)).

target_(Det, C, T, Object) :-
    memberchk(Det, ["a", "the"]),
    atom_string(Colour, C),
    atom_string(Type, T),
    memberchk(Type, [key, ball, box, door]),
    Object =.. [Type, Colour].

%   target_shown_(+E, +Verb, +Object)
target_shown_(E, pick_up, Object) :-
    kb_event_(E, picked(Object)).
target_shown_(E, open, Door) :-
    kb_event_(E, opened(Door)).
target_shown_(E, go_to, Object) :-
    episode(E, S, _, _),
    at(E, S, agent, R, C),
    facing(E, S, Dir),
    ahead_(Dir, R, C, R1, C1),
    at(E, S, Id, R1, C1),
    object(Id, Object),
    !.

ahead_(east, R, C, R, C1) :- C1 is C + 1.
ahead_(south, R, C, R1, C) :- R1 is R + 1.
ahead_(west, R, C, R, C1) :- C1 is C - 1.
ahead_(north, R, C, R1, C) :- R1 is R - 1.
