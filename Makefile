# Everything a fresh machine needs: `make demo` and `make test` create .venv and install by themselves.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
RL_STAMP := $(VENV)/.installed-rl
TRAIN_STAMP := $(VENV)/.installed-train
DEMO_OUT ?= demo-worlds

.PHONY: demo test bench bench-learning fuzz clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e .
	touch $@

$(TEST_STAMP): $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[test]'
	touch $@

$(RL_STAMP): $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[rl]'
	touch $@

# stable-baselines3 brings PyTorch (the benchmark runs it on the CPU, one thread).
$(TRAIN_STAMP): $(RL_STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[train]'
	touch $@

## demo: install, then generate worlds from the cluttered generator's defaults and say where they are
demo: $(STAMP)
	$(VENV)/bin/worldgen generate cluttered --seed 0 --count 3 --out $(DEMO_OUT)
	@echo "worlds written under $(abspath $(DEMO_OUT))/: each folder holds world.sdf, world.mjcf.xml, world.urdf, world.json, scenario.yaml, map.pgm + map.yaml and preview.png"

## test: install with the test extras, lint (ruff: pyflakes, pycodestyle, import order), check the
## public API's types (mypy), then run the whole suite
test: $(TEST_STAMP)
	$(VENV)/bin/ruff check worldgen tests benchmarks examples
	$(VENV)/bin/mypy
	$(PY) -m pytest -q

## bench: per-stage medians for cluttered worlds against the serialisation floor, a 1,000-world pack
## with --jobs 2, then the RL environment's steps/s and reset split; tables on stdout with each
## target met or missed, JSON in benchmarks/results/
bench: $(RL_STAMP)
	$(PY) benchmarks/bench_pipeline.py
	$(PY) benchmarks/bench_pack.py --worlds 1000 --jobs 2
	$(PY) benchmarks/bench_env.py

## bench-learning: PPO (stable-baselines3) on one core learns worldgen/Navigation-v0 with the default
## reward and with `walkthrough`, against random, heuristic and path-follower baselines on held-out
## worlds: hours of CPU, not in `make test` or CI (benchmarks/bench_learning.py; JSON in
## benchmarks/results/, the curves in docs/img/learning.png)
bench-learning: $(TRAIN_STAMP)
	$(PY) benchmarks/bench_learning.py

## fuzz: the long fuzz sweep over every generator's full parameter ranges (a table; reproducers of defects)
fuzz: $(TEST_STAMP)
	$(PY) benchmarks/fuzz_sweep.py

clean:
	rm -rf $(VENV) $(DEMO_OUT) tests/.cache .pytest_cache .hypothesis
