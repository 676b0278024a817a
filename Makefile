# The two commands in README.md: `make demo` and `make test`. Both install what they need first.
SCENE ?= scenes/default.toml
PY := .venv/bin/python
export XDG_CACHE_HOME := $(CURDIR)/.cache
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export MPLBACKEND := Agg

.PHONY: setup demo test test-heavy lint bench clean

setup:
	@bash scripts/setup.sh

demo: setup
	$(PY) -m sandwich.cli demo $(SCENE)

test: setup
	$(PY) -m pytest -q -m "not heavy"

test-heavy: setup
	$(PY) -m pytest -q -m heavy

lint: setup
	$(PY) -m ruff check .

clean:
	rm -rf results .cache .pytest_cache
