# The two commands of the README: `make run` starts the workstation,
# `make test` runs every test. Both set up what they need first.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: run test bench soak setup system screenshots example-report clean

setup: system $(STAMP)

system:
	@bash tools/system-packages.sh

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	@touch $(STAMP)

run: setup
	@bash tools/run-gui.sh

# Three worker processes (pytest-xdist): a test file stays in one worker, the JACK rig's tests all in one
# (tests/scheduling.py), the longest units first. The rig's tests run in real time and keep their worker busy
# less than half the time (90 tests: 7 min 9 s wall, 139 s CPU at load ~14, one BLAS thread per process as
# tests/conftest.py sets), so on two cores a third worker takes the CPU they leave.
# TEST_WORKERS=0 runs the tests in this process, one after another. The 40 slowest tests are listed at the
# end: where the suite's time goes, run after run.
TEST_WORKERS ?= 3
test: setup
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile --durations=40 tests

# `make bench` runs every suite; `make bench gui validity` only those (the words after bench name suites, not
# targets of their own).
ifeq (bench,$(firstword $(MAKECMDGOALS)))
BENCH_SUITES := $(wordlist 2,$(words $(MAKECMDGOALS)),$(MAKECMDGOALS))
$(eval $(BENCH_SUITES):;@:)
endif
bench: setup
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m bench $(BENCH_SUITES)

# 200 measurements on the virtual rig in one process: memory, files and threads must not grow (not in CI).
soak: setup
	$(BIN)/python tools/soak.py

screenshots: setup
	QT_QPA_PLATFORM=offscreen $(BIN)/python tools/screenshots.py

example-report: setup
	$(BIN)/python tools/example_report.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
