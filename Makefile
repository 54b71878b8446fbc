# The two front-door commands: `make demo` (main job on the embedded simulator)
# and `make test` (the whole suite). Both create the virtualenv on first use.
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: demo test lint bench venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml setup.py scripts/bootstrap
	scripts/bootstrap $(VENV)
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/navseq run examples/turtlebot3_world.yaml

test: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/python -m pytest

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(VENV)/bin/python $$b || exit 1; done

clean:
	rm -rf $(VENV) navseq-out
