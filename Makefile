# neurosym: `make test` and `make demo` set everything up on a fresh machine
# (virtual environment, torch CPU build, neurosym, then `neurosym setup-prolog`: SWI-Prolog
# >= 9.1.12 and janus-swi) and are quick once it is there.
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.neurosym-setup
TORCH_SPEC ?= torch==2.13.0
SWIPL_PATH_FILE := $(VENV)/swipl-path
export PYTHONHASHSEED := 0

.PHONY: setup test test-fast demo bench lint clean

setup: $(STAMP)

$(STAMP): pyproject.toml setup.py neurosym/setup_swipl.sh neurosym/setup_prolog.py Makefile
	@test -x $(PY) || python3 -m venv $(VENV)
	@# torch first, pinned, so that the package's range never pulls the CUDA wheels.
	@$(PY) -m pip show torch >/dev/null 2>&1 || $(PY) -m pip install -q "$(TORCH_SPEC)"
	@$(PY) -m pip install -q -e ".[dev]"
	@# The pip route's own step: SWI-Prolog >= 9.1.12 (found, or built into $(VENV)/swipl),
	@# linked as $(VENV)/bin/swipl, and janus-swi built against it.
	@$(VENV)/bin/neurosym setup-prolog
	@$(PY) -c "from neurosym.prolog.locate import swipl_executable; print(swipl_executable())" > $(SWIPL_PATH_FILE).tmp
	@mv $(SWIPL_PATH_FILE).tmp $(SWIPL_PATH_FILE)
	@touch $@
	@echo "neurosym: set up in $(VENV) (swipl: $$(cat $(SWIPL_PATH_FILE)))"

# Two pytest workers (pytest-xdist): each test computes on one thread (tests/conftest.py), so
# two keep both cores busy; TEST_WORKERS=0 runs the suite in one process.
TEST_WORKERS ?= 2
test: setup
	@bash scripts/setup_browser.sh
	$(PY) -m pytest -q -n $(TEST_WORKERS)

test-fast: setup
	@bash scripts/setup_browser.sh
	$(PY) -m pytest -q -n $(TEST_WORKERS) -m "not expensive and not subprocess"

# One story in three steps (under a minute once set up); `neurosym extract --verbose` prints the full tables.
NS := $(VENV)/bin/neurosym
demo: setup
	@echo "== 1/3 The general PrediNet (trained on random levels) plays rgw2, a map it never saw: its route,"
	@echo "==     its relation heads (head 0 relates the agent to what it is after) and the rules' answers:"
	@echo "==     whether it followed each level's optimal order, and whether the heads relate sword and enemy"
	@echo "==     at one state (direct), through an object within one step (indirect) or only in one recording"
	@$(NS) extract --checkpoint checkpoints/rgw-random-predinet-cellkeys.pt --env rgw2 --episodes 20 --seed 0 --out kb_out/rgw2-cellkeys
	@echo "   The same episodes on one page (open it in a browser: episode player, heads, rule answers):"
	@$(NS) report --recording kb_out/rgw2-cellkeys
	@echo
	@echo "== 2/3 A Box-World agent (bw2-predinet) on 20 unseen bw2 levels: head 0 relates the agent to locks"
	@$(NS) extract --checkpoint checkpoints/bw2-predinet.pt --episodes 20 --seed 3000000000 --out kb_out/bw2
	@echo
	@echo "== 3/3 The contrast: rgw2-predinet learnt one map (it plays rgw2 optimally); on 100 random levels:"
	@$(NS) eval --checkpoint checkpoints/rgw2-predinet.pt --env rgw-random --episodes 100 --seed 3000000000 --json > kb_out/contrast.json
	@$(PY) -c 'import json, neurosym; r = json.load(open("kb_out/contrast.json")); \
	  g = neurosym.load_agent("rgw-random-predinet-cellkeys").meta["card"]["held_out"]["greedy"]; \
	  print("success %.0f %%, mean return %.2f (the general PrediNet: %.0f %% on 300 such levels)" \
	  % (100 * r["success_rate"], r["mean_return"], 100 * g["success_rate"]))'
	@echo
	@echo "Next: neurosym query --kb kb_out/rgw2-cellkeys/kb.pl --rules rgw 'visit_order(E, Order)'; 'sword_enemy_link(How)'; neurosym agents"

bench: setup
	$(PY) bench/envs.py
	$(PY) bench/kb.py
	$(PY) bench/train.py
	$(PY) bench/extract.py
	$(PY) bench/meaning.py
	$(PY) bench/structure.py

lint: setup
	$(PY) -m ruff check neurosym tests bench examples experiments scripts

clean:
	rm -rf $(VENV) kb_out runs .pytest_cache
