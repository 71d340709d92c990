/*  causal_direct_facts.pl -- an agent whose use of the enemy depends on the sword.

    Without the sword it keeps away from the enemy (met in 10 % of the
    episodes), with the sword it meets it first thing, and no level makes it
    walk into the enemy unarmed. Ablating head 2, which does not relate sword
    and enemy, breaks the order too: that alone is no evidence.
*/
experiment(baseline, baseline, unchanged).
experiment(remove_sword, remove(sword), cells([cell(0,6,sword,empty)])).
experiment(swap_sword_enemy, swap(sword,enemy), cells([cell(0,6,sword,enemy),cell(9,1,enemy,sword)])).
experiment(ablate_head_2, ablate(head(2)), replaced(r_vector,mean_over(baseline))).

measure(baseline, sword_before_enemy, 0.95).
measure(baseline, enemy_met, 0.95).
measure(baseline, enemy_defeated, 0.95).
measure(baseline, enemy_unarmed, 0.0).
measure(remove_sword, enemy_met, 0.1).
measure(remove_sword, enemy_unarmed, 0.1).
measure(swap_sword_enemy, enemy_met, 0.9).
measure(swap_sword_enemy, enemy_unarmed, 0.05).
measure(ablate_head_2, sword_before_enemy, 0.0).

effect(remove_sword, enemy_met, -0.85).
effect(swap_sword_enemy, enemy_met, -0.05).
effect(ablate_head_2, sword_before_enemy, -0.95).

relates(2, agent, wall, 0.4).
