/*  relations_facts.pl -- hand-written network facts for relations.plt.

    Two heads, two relations. holds/5 is what extract_facts writes for these
    relation/7 rows with the thresholds below (|value| > threshold, oriented
    so that the value is positive, one fact per (E, T, r(J), A, B)).
    Episode 0 has 3 states the agent acted in, episode 1 one.
*/

:- dynamic kb_meta/2, object/2, episode/4, step/4, at/5, holding/3, event/3,
           attends/8, relation/7, holds/5, threshold/2, attention/6.

episode(0, 3, 0.0, timeout).
episode(1, 1, 0.0, timeout).

threshold(0, 0.3).
threshold(1, 0.3).

%        E  T  Head J  A      B      Value
relation(0, 0, 0, 0, sword, enemy,  1.0).
relation(0, 0, 0, 1, sword, enemy,  0.5).
relation(0, 1, 0, 0, sword, enemy,  0.5).
relation(0, 1, 0, 1, sword, enemy,  0.375).
relation(0, 2, 0, 0, sword, enemy,  0.25).
relation(0, 2, 0, 1, sword, enemy, -0.125).
relation(1, 0, 0, 0, agent, sword, -0.5).
relation(1, 0, 0, 1, agent, sword,  0.125).
relation(0, 0, 1, 0, enemy, sword, -0.75).
relation(0, 0, 1, 1, enemy, sword,  0.375).

holds(0, 0, r(0), sword, enemy).
holds(0, 0, r(1), enemy, sword).
holds(0, 0, r(1), sword, enemy).
holds(0, 1, r(0), sword, enemy).
holds(0, 1, r(1), sword, enemy).
holds(1, 0, r(0), sword, agent).
