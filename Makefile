# neurosym: `make test` and `make demo` set everything up on a fresh machine
# (virtual environment, torch CPU build, SWI-Prolog >= 9.1.12, janus-swi) and
# are quick once it is there.
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.neurosym-setup
TORCH_SPEC ?= torch==2.13.0
SWIPL_PATH_FILE := $(VENV)/swipl-path
export PYTHONHASHSEED := 0

.PHONY: setup test test-fast demo bench lint clean

setup: $(STAMP)

$(STAMP): pyproject.toml scripts/setup_swipl.sh Makefile
	@test -x $(PY) || python3 -m venv $(VENV)
	@# torch first, pinned, so that the package's range never pulls the CUDA wheels.
	@$(PY) -m pip show torch >/dev/null 2>&1 || $(PY) -m pip install -q "$(TORCH_SPEC)"
	@bash scripts/setup_swipl.sh $(VENV) > $(SWIPL_PATH_FILE).tmp && mv $(SWIPL_PATH_FILE).tmp $(SWIPL_PATH_FILE)
	@# janus-swi compiles against the swipl found on PATH: put ours first, and never
	@# reuse a cached wheel (it would link the libswipl of another checkout).
	@$(PY) -c "import janus_swi" 2>/dev/null || \
	  PATH="$$(dirname "$$(cat $(SWIPL_PATH_FILE))"):$$PATH" $(PY) -m pip install -q --no-cache-dir --no-binary janus-swi "janus-swi>=1.5.3"
	@$(PY) -m pip install -q -e ".[dev]"
	@touch $@
	@echo "neurosym: set up in $(VENV) (swipl: $$(cat $(SWIPL_PATH_FILE)))"

test: setup
	$(PY) -m pytest -q

test-fast: setup
	$(PY) -m pytest -q -m "not expensive"

demo: setup
	$(VENV)/bin/neurosym extract --checkpoint checkpoints/rgw2-predinet.pt --env rgw2 --episodes 20 --seed 0 --out kb_out/rgw2
	$(VENV)/bin/neurosym extract --checkpoint checkpoints/rgw-random-predinet.pt --env rgw-random --episodes 20 --seed 3000000000 --sample --out kb_out/rgw-random
	$(VENV)/bin/neurosym extract --checkpoint checkpoints/rgw-random-predinet.pt --env rgw2 --episodes 20 --seed 0 --sample --out kb_out/rgw2-general
	$(VENV)/bin/neurosym extract --checkpoint checkpoints/rgw-random-predinet-cells.pt --env rgw2 --episodes 20 --seed 0 --out kb_out/rgw2-cells
	$(VENV)/bin/neurosym extract --checkpoint checkpoints/rgw-random-predinet-cellkeys.pt --env rgw2 --episodes 20 --seed 0 --out kb_out/rgw2-cellkeys

bench: setup
	$(PY) bench/envs.py
	$(PY) bench/kb.py
	$(PY) bench/train.py
	$(PY) bench/extract.py
	$(PY) bench/meaning.py

lint: setup
	$(PY) -m ruff check neurosym tests bench examples

clean:
	rm -rf $(VENV) kb_out runs .pytest_cache
