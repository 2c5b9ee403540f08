# strapdown — two commands set everything up: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
DEVSTAMP := $(VENV)/.installed-dev
DEMO_OUT ?= reports/li2017

.PHONY: demo test bench lint fuzz clean docs

# Python writes its bytecode caches (__pycache__/, ignored by git) even when the caller's
# environment says not to (PYTHONDONTWRITEBYTECODE): the suite starts some hundred
# interpreters, command lines and workers, that would each compile the package's source again
# (~0.2 s each) and pytest would rewrite every test module in each worker.
unexport PYTHONDONTWRITEBYTECODE

# Installs go through uv (from PyPI, into the venv by pip): it resolves and installs the dev
# extras in ~5 s where pip took ~40 s, an eighth of make test's budget on two cores.
UV      := $(VENV)/bin/uv
INSTALL := $(UV) pip install --quiet --python $(PY)

$(PY):
	$(PYTHON) -m venv $(VENV)

$(UV): | $(PY)
	$(PY) -m pip install --quiet uv

$(STAMP): pyproject.toml | $(UV)
	$(INSTALL) -e .
	touch $@

$(DEVSTAMP): pyproject.toml | $(UV)
	$(INSTALL) -e ".[dev]"
	touch $@ $(STAMP)

## demo: create .venv, install, run the flagship reproduction (Li & Zhang 2017), write its report
demo: $(STAMP)
	$(VENV)/bin/strapdown reproduce li2017 --out $(DEMO_OUT)
	@echo "Report: $(DEMO_OUT)/report.md"

## test: install dev extras, lint (style, import layers, types), run the whole suite on every
## core (pytest-xdist; a module's tests that share its fixture run on one worker) and list the
## slowest 20 tests. make lint runs beside the suite (mostly mypy, single-threaded: it fills
## the time a worker waits for the other's numba warm-up), its output printed after the
## suite's; either one failing fails make test
test: $(DEVSTAMP)
	@$(MAKE) --no-print-directory lint > $(VENV)/lint.log 2>&1 & lint=$$!; \
	$(PY) -m pytest -q -n auto --durations=20; suite=$$?; \
	wait $$lint; linted=$$?; \
	echo "make lint (run beside the suite):"; cat $(VENV)/lint.log; \
	if [ $$linted -ne 0 ]; then echo "make lint failed (exit $$linted)"; exit 1; fi; \
	exit $$suite

## fuzz: the long fuzz campaign — the corpus and >= 10^4 generated hostile files through every
## reader and every command that reads a file, under a memory cap and a time limit (counts per
## format at the end; fails on any exception but InputError, traceback, signal, run over 10 s,
## peak over 500 MB or partial output), then the hypothesis strategies at 2000 examples each
fuzz: $(DEVSTAMP)
	$(PY) tests/fuzz/campaign.py --profile long
	STRAPDOWN_FUZZ_EXAMPLES=2000 $(PY) -m pytest -q -p no:cacheprovider tests/fuzz/test_fuzz_files.py -k "not campaign"

## docs: the reference site into site/ (mkdocs.yml): API from the docstrings, the command line,
## the pages of docs/, the examples gallery and the quick reproductions run at build time;
## every warning (a broken link, anchor or reference) is an error
DOCSSTAMP := $(VENV)/.installed-docs
$(DOCSSTAMP): pyproject.toml | $(UV)
	$(INSTALL) -e ".[docs]"
	touch $@ $(STAMP)

docs: $(DOCSSTAMP)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

## bench: throughput benchmarks with peers (numbers are reported, never asserted)
bench: $(STAMP)
	$(INSTALL) -e ".[bench]"
	$(PY) benchmarks/run.py --out reports/bench.json

## lint: ruff (style), import-linter (imports only point down the layers), mypy (types), and
## the model's own rules (tools/lint_model.py: no comparison against a registry name — family,
## structure, coefficient set, motion — outside the model's modules; no function over 80 lines
## outside the numba kernels)
lint: $(DEVSTAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/lint-imports
	$(VENV)/bin/mypy
	$(PY) tools/lint_model.py src/strapdown

clean:
	rm -rf $(VENV) build reports .pytest_cache site
