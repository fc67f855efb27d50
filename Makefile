# The two commands: `make test` and `make bench`. Each builds .venv when it is missing or
# pyproject.toml changed.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: test test-fast bench bench-full bench-generic library env clean-env

env: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev,robots]'
	touch $(STAMP)

# Everything, as CI runs it (slow tests included: the installed-wheel check, native planners, campaigns).
test: $(STAMP)
	MPLBACKEND=Agg $(PY) -m pytest -q

# The fast loop while editing: everything not marked slow.
test-fast: $(STAMP)
	MPLBACKEND=Agg $(PY) -m pytest -q -m "not slow"

# Default campaign (about 2 min on 2 cores): 24 queries at 500 and 2500 samples (batched motion
# validator; OMPL's per-state validator on 4 queries at 500 beside it) plus a short anytime run.
bench: $(STAMP)
	MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --queries planning_necessary --name bench \
		--max-queries 24 --samples 500 2500 --alt-checker-queries 4 --alt-checker-samples 500 \
		--anytime 0.1 0.5 1 --anytime-queries 6 --workers 2

# Full campaign, both named query sets: Table 4 (500..2500 samples, one run per ladder) on all 120
# queries of each; OMPL's per-state validator on 12 stratified queries per set at 500 and 2500;
# the anytime comparison (0.1..2 s; one run per budget ladder where exact) on 2 stratified queries per set.
bench-full: $(STAMP)
	MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --queries planning_necessary --name full --workers 2 \
		--alt-checker-queries 12 --alt-checker-samples 500 2500 --anytime-queries 2
	MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --queries paper_random --name full_random --workers 2 \
		--alt-checker-queries 12 --alt-checker-samples 500 2500 --anytime-queries 2

# The generic problems (plain OMPL + numpy set-ups), each in its own campaign with short settings:
# all 10 queries, 500 samples, anytime 0.1/0.5/1 s (tpee-ompl bench --list-problems lists them).
# panda-shelf (7 joints, hard: shelf compartments) runs next, on 6 queries at 1 and 5 s, then kinova-posts
# (6 joints, 3 continuous) on 10 queries at 0.5 and 1 s.
GENERIC_PROBLEMS := arm4 arm6 arm7 arm8 arm5-so2 point4-hole narrow3
bench-generic: $(STAMP)
	for p in $(GENERIC_PROBLEMS); do \
		MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --problem $$p --name $$p \
			--samples 500 --anytime 0.1 0.5 1 --workers 2 --no-progress || exit 1; \
	done
	MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --problem panda-shelf --name panda-shelf --max-queries 6 \
		--samples 500 --anytime 1 5 --workers 2 --no-progress
	MPLBACKEND=Agg $(PY) experiments/run_benchmark.py --problem kinova-posts --name kinova-posts --max-queries 10 \
		--samples 500 --anytime 0.5 1 --workers 2 --no-progress

# Default cross-sector DMP path library (12 pairs x <= 20 dimension-RRT demos, ~3.5 min on 2 cores).
# --force: this target rebuilds the packaged library on purpose (library build never replaces a file without it).
library: $(STAMP)
	$(PY) experiments/build_library.py --workers 2 --force --library tpee_ompl/data/library/default.npz

clean-env:
	rm -rf $(VENV)
