/*  meaning_facts.pl -- probe facts and a few holds/5 facts for meaning.plt.

    r(3) encodes holding(sword) selectively in head 0 (0.95 against a control
    of 0.6) and visited(sword) less so; r(5) is only as good as its control;
    head 1's whole vector encodes adjacent(agent,sword).
*/
:- dynamic probe/5, probe_untrained/5, holds/5.

probe(0, 3, holding(sword), 0.95, 0.6).
probe(1, 3, holding(sword), 0.7, 0.6).
probe(0, 3, visited(sword), 0.9, 0.65).
probe(0, 5, holding(sword), 0.6, 0.6).
probe(1, all, adjacent(agent,sword), 0.98, 0.7).
probe(1, all, holding(sword), 0.8, 0.75).

probe_untrained(0, 3, holding(sword), 0.7, 0.6).
probe_untrained(1, all, adjacent(agent,sword), 0.75, 0.7).

holds(0, 4, r(3), agent, sword).
holds(0, 5, r(5), agent, enemy).
