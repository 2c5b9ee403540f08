# strapdown — two commands set everything up: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
DEVSTAMP := $(VENV)/.installed-dev
DEMO_OUT ?= reports/li2017

.PHONY: demo test bench lint clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e .
	touch $@

$(DEVSTAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $@ $(STAMP)

## demo: create .venv, install, run the flagship reproduction (Li & Zhang 2017), write its report
demo: $(STAMP)
	$(VENV)/bin/strapdown reproduce li2017 --out $(DEMO_OUT)
	@echo "Report: $(DEMO_OUT)/report.md"

## test: install dev extras, lint (style, import layers, types), run the whole suite
test: lint
	$(PY) -m pytest -q

## bench: throughput benchmarks with peers (numbers are reported, never asserted)
bench: $(STAMP)
	$(PY) -m pip install --quiet -e ".[bench]"
	$(PY) benchmarks/run.py --out reports/bench.json

## lint: ruff (style), import-linter (imports only point down the layers), mypy (types)
lint: $(DEVSTAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/lint-imports
	$(VENV)/bin/mypy

clean:
	rm -rf $(VENV) build reports .pytest_cache
