# Everything a fresh machine needs: `make demo` and `make test` create .venv and install by themselves.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
RL_STAMP := $(VENV)/.installed-rl
ROS_STAMP := $(VENV)/.installed-ros
TRAIN_STAMP := $(VENV)/.installed-train
DEMO_OUT ?= demo-worlds

.PHONY: demo test test-gazebo bench bench-learning fuzz clean

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

$(ROS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[ros]'
	touch $@

# stable-baselines3 brings PyTorch (the benchmark runs it on the CPU, one thread).
$(TRAIN_STAMP): $(RL_STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[train]'
	touch $@

## demo: install, then generate worlds from the cluttered generator's defaults, say where they are
## and what to try next
demo: $(STAMP)
	$(VENV)/bin/worldgen generate cluttered --seed 0 --count 3 --out $(DEMO_OUT)
	@echo "worlds written under $(abspath $(DEMO_OUT))/: each folder holds world.sdf, world.mjcf.xml, world.urdf, world.json, scenario.yaml, map.pgm + map.yaml and preview.png"
	@echo ""
	@echo "Try next:"
	@echo "  $(VENV)/bin/python -m mujoco.viewer --mjcf=$$(ls -d $(DEMO_OUT)/cluttered-s0-* | head -n 1)/world.mjcf.xml   # look at a world (needs a display)"
	@echo "  $(VENV)/bin/worldgen list cluttered   # every parameter you can --set, with its range"
	@echo "  $(VENV)/bin/python examples/lidar_unit_test.py   # a sensor unit test; as pytest tests: README step 3, docs/testing.md"
	@echo "  $(VENV)/bin/worldgen pack build examples/recipes/ci_smoke.yaml --out packs/ci_smoke --jobs 2   # many worlds, one manifest"

## test: install with the test extras, lint (ruff: pyflakes, pycodestyle, import order), check the
## whole package's types (mypy), then run the whole suite
test: $(TEST_STAMP)
	$(VENV)/bin/ruff check worldgen tests benchmarks examples
	$(VENV)/bin/mypy
	$(PY) -m pytest -q

## test-gazebo: only the tests that run a real Gazebo server (every kind of world loaded and stepped, tests/sim;
## marker `gazebo`; also part of `make test`); Fortress from WORLDGEN_GAZEBO_SETUP or /opt/gz-fortress2,
## Harmonic from /opt/gz-harmonic (a sample; WORLDGEN_GAZEBO_ALL=1 for every case) (docs/gazebo.md)
test-gazebo: $(TEST_STAMP)
	$(PY) -m pytest -q -m gazebo tests

## bench: per-stage medians for cluttered worlds against the serialisation floor, a 1,000-world pack
## with --jobs 2, the RL environment's steps/s and reset split, BARN's metrics against worldgen's
## (ratios over 40 worlds per generator) and barn_metrics' speed, `worldgen judge` on a 60 s bag and
## its peak memory over batches of 10 to 1,000 bags, the difficulty score against the probes' failures
## over 1,600 worlds, worlds made to a level, the reactive probe's success per level, a curriculum
## reset against a plain one, worlds with people (10, 20, 50) generated and certified, 1,000 episodes
## of the timed path among reacting people with the step's and the certificate's cost, and `worldgen
## drive` of a 10 m path in Gazebo (skipped without it) and MuJoCo, the crowd files against the pipeline, a
## campaign's adaptive search against random sampling, a 20 x 20 m terrain world and terrain's difficulty
## terms, a naive robot among regular and impassive people, and `worldgen drive` in 200 random dynamic
## worlds in MuJoCo (its Gazebo sample by hand: docs/benchmarks.md); tables on stdout with each target met or missed,
## JSON in benchmarks/results/
bench: $(RL_STAMP) $(ROS_STAMP)
	$(PY) benchmarks/bench_pipeline.py
	$(PY) benchmarks/bench_pack.py --worlds 1000 --jobs 2
	$(PY) benchmarks/bench_env.py
	$(PY) benchmarks/bench_barn.py
	$(PY) benchmarks/bench_judge.py
	nice -n 10 $(PY) benchmarks/bench_difficulty.py
	nice -n 10 $(PY) benchmarks/bench_leveling.py
	nice -n 10 $(PY) benchmarks/bench_ladder.py
	WORLDGEN_SWEEPS=1 $(PY) -m pytest -q -p no:cacheprovider tests/envs/test_ladder.py
	$(PY) benchmarks/bench_curriculum.py
	$(PY) benchmarks/bench_people.py
	$(PY) benchmarks/bench_reacting.py
	$(PY) benchmarks/bench_tracking.py
	$(PY) benchmarks/bench_drive.py
	nice -n 10 $(PY) benchmarks/bench_requests.py
	$(PY) benchmarks/bench_crowd.py
	$(PY) benchmarks/bench_campaign.py
	$(PY) benchmarks/bench_terrain.py
	nice -n 10 $(PY) benchmarks/bench_terrain_difficulty.py
	nice -n 10 $(PY) benchmarks/bench_naive_robot.py
	nice -n 10 $(PY) benchmarks/bench_drive_dynamic.py

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
