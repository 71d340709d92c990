/*  causal_ablation_facts.pl -- the link is seen only by ablating the head that relates them.

    The level changes show nothing (the agent meets the enemy without the
    sword in few episodes and is not kept from it either), but head 1 attends
    sword and enemy together in 30 % of the baseline's states and ablating it
    breaks sword-before-enemy; ablating head 0 (which does not relate them)
    changes little.
*/
experiment(baseline, baseline, unchanged).
experiment(remove_sword, remove(sword), cells([cell(0,6,sword,empty)])).
experiment(ablate_head_0, ablate(head(0)), replaced(r_vector,mean_over(baseline))).
experiment(ablate_head_1, ablate(head(1)), replaced(r_vector,mean_over(baseline))).

measure(baseline, sword_before_enemy, 0.8).
measure(baseline, enemy_defeated, 0.8).
measure(baseline, enemy_unarmed, 0.1).
measure(remove_sword, enemy_unarmed, 0.3).
measure(ablate_head_0, sword_before_enemy, 0.75).
measure(ablate_head_1, sword_before_enemy, 0.1).

effect(remove_sword, enemy_met, -0.2).
effect(ablate_head_0, sword_before_enemy, -0.05).
effect(ablate_head_1, sword_before_enemy, -0.7).

relates(1, enemy, sword, 0.3).
relates(0, agent, sword, 0.6).
