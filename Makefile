# The two front-door commands: `make demo` (main job on the embedded simulator)
# and `make test` (the whole suite). Both create the virtualenv on first use.
VENV := .venv
STAMP := $(VENV)/.installed

# pytest-xdist workers. The ROS, ROS 2 and browser tests spend most of their time
# waiting on real time (nodes, servers, a robot driving at 1x-4x), so on a 2-core
# machine more workers than cores pay; each ROS test has its own rosmaster port or
# ROS 2 domain (tests/ros2_support.py leases domains across workers). loadgroup: a
# module whose tests share a Nav2 bringup or a browser runs on one worker
# (tests/conftest.py groups them).
TEST_WORKERS ?= 4
FAST_WORKERS ?= 4
PYTEST_PARALLEL = -n $(TEST_WORKERS) --dist loadgroup

.PHONY: demo test test-fast test-pythons lint bench fuzz venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml setup.py scripts/bootstrap
	scripts/bootstrap $(VENV)
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/navseq run examples/turtlebot3_world.yaml

test: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/ruff format --check src tests benchmarks
	$(VENV)/bin/mypy
	$(VENV)/bin/python -m pytest $(PYTEST_PARALLEL)

# The edit-test loop: every test that needs no ROS and no browser, on FAST_WORKERS
# workers (half their time is spent waiting on the navseq processes they start, so
# more workers than cores pay here too). `make test` runs these too.
test-fast: $(STAMP)
	$(VENV)/bin/python -m pytest -n $(FAST_WORKERS) --dist worksteal \
		-m "not ros and not ros2 and not browser"

# The non-ROS tests on the other Python versions navseq supports (3.10: ROS 2 Humble,
# 3.12: Jazzy), from the interpreters the test machine carries (../shared/python):
# unpacked into /opt/navseq-python, one venv each (.venv310, .venv312). `make test` is
# Debian's 3.11 with ROS.
test-pythons:
	scripts/python-versions.sh

# The loaders' fuzz tests at scale: FUZZ_SCALE x 2000 cases per loader (6 loaders;
# the default 10 runs 120 000 cases). The normal test run does 2000 per loader.
FUZZ_SCALE ?= 10
fuzz: $(STAMP)
	NAVSEQ_FUZZ_SCALE=$(FUZZ_SCALE) $(VENV)/bin/python -m pytest -q -p no:cacheprovider \
		--durations=0 tests/test_fuzz_loaders.py

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(VENV)/bin/python $$b || exit 1; done

clean:
	rm -rf $(VENV) .venv310 .venv312 navseq-out
