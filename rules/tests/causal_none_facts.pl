/*  causal_none_facts.pl -- an agent that never meets the enemy: no evidence either way. */
experiment(baseline, baseline, unchanged).
experiment(remove_sword, remove(sword), cells([cell(0,6,sword,empty)])).

measure(baseline, sword_before_enemy, 0.0).
measure(baseline, enemy_met, 0.0).
measure(baseline, enemy_defeated, 0.0).
measure(baseline, enemy_unarmed, 0.0).
measure(remove_sword, enemy_met, 0.0).
measure(remove_sword, enemy_unarmed, 0.0).

effect(remove_sword, enemy_met, 0.0).
