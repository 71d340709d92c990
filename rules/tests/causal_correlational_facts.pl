/*  causal_correlational_facts.pl -- an agent that goes to places, not objects.

    It defeats the enemy with the sword on the baseline; without the sword it
    never reaches the enemy (it stays stuck where the sword was), but with
    sword and enemy swapped it walks into the enemy unarmed: it meets the
    enemy either way. No head relates sword and enemy. (The shape of what
    rgw2-predinet does.)
*/
experiment(baseline, baseline, unchanged).
experiment(remove_sword, remove(sword), cells([cell(0,6,sword,empty)])).
experiment(swap_sword_enemy, swap(sword,enemy), cells([cell(0,6,sword,enemy),cell(9,1,enemy,sword)])).
experiment(ablate_head_0, ablate(head(0)), replaced(r_vector,mean_over(baseline))).

measure(baseline, sword_before_enemy, 1.0).
measure(baseline, enemy_met, 1.0).
measure(baseline, enemy_defeated, 1.0).
measure(baseline, enemy_unarmed, 0.0).
measure(remove_sword, sword_before_enemy, 0.0).
measure(remove_sword, enemy_met, 0.0).
measure(remove_sword, enemy_defeated, 0.0).
measure(remove_sword, enemy_unarmed, 0.0).
measure(swap_sword_enemy, sword_before_enemy, 0.0).
measure(swap_sword_enemy, enemy_met, 1.0).
measure(swap_sword_enemy, enemy_defeated, 0.0).
measure(swap_sword_enemy, enemy_unarmed, 1.0).
measure(ablate_head_0, sword_before_enemy, 0.0).
measure(ablate_head_0, enemy_unarmed, 0.0).

effect(remove_sword, enemy_met, -1.0).
effect(remove_sword, sword_before_enemy, -1.0).
effect(swap_sword_enemy, enemy_met, 0.0).
effect(swap_sword_enemy, enemy_unarmed, 1.0).
effect(ablate_head_0, sword_before_enemy, -1.0).

relates(0, agent, empty, 0.5).
