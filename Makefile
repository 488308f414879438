# creaturegen: self-bootstrapping entry points. A clean clone needs only python3 (>= 3.11),
# node/npm and, for the browser tests, root or password-less sudo on Debian (or network for
# Playwright's Chromium). `make build` and `make test` install everything else on first use.

SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:

PYTHON ?= python3
VENV := .venv
VENV_PY := $(VENV)/bin/python
VENV_STAMP := $(VENV)/.installed
WEB_LAB := generator/creaturegen/web_lab
NODE_STAMP := $(WEB_LAB)/node_modules/.package-lock.json
# The default example is a creature (the product's spine); frost effects build the same way.
EXAMPLE ?= examples/reference/hopper.json
FROST_EXAMPLES := $(wildcard examples/frost/*.json)
# Every creature example (each builds with every gate).
CREATURE_EXAMPLES := $(wildcard examples/reference/*.json) examples/beetle.json examples/lizard.json examples/moth.json
LAB_HOST ?= 127.0.0.1
LAB_PORT ?= 8765
# Extra pytest arguments for local runs, e.g. PYTEST_ARGS='-k smoke'. CI leaves it empty: every test
# runs, browser-marked ones included, and "no tests collected" (exit 5) fails like any other error.
PYTEST_ARGS ?=
# pytest-xdist workers. Two fill a 2-core CI machine: much of the suite waits on Chromium, node and
# subprocess builds, and the workers share one surface cache and one package folder (tests/conftest.py).
PYTEST_WORKERS ?= 2
# The generated creature corpus of `make corpus` (seeds 0 .. CORPUS_COUNT-1, every tier, builds in parallel
# over the machine's cores; results are kept by spec, tier and compiler digest, so a rerun only builds what
# changed). CORPUS_TIERS and CORPUS_JOBS narrow or widen it.
CORPUS_COUNT ?= 200
CORPUS_TIERS ?= hero,repeated,distant
CORPUS_JOBS ?= $(shell nproc 2>/dev/null || echo 2)
# `make fuzz`: documents through the spec gate and real builds of mutated valid specs (make test runs a
# fixed 2,000-case subset, tests/test_fuzz.py).
FUZZ_CASES ?= 50000
FUZZ_BUILDS ?= 50
# Only folders that exist: git does not keep empty ones, and ruff fails on a missing path.
LINT_PATHS := $(wildcard generator tests bench)

.PHONY: help setup system-deps build bestiary parity corpus fuzz test test-full schemas lab bench golden clean distclean

help:
	@echo "make setup    .venv + pip install -e '.[dev]', npm ci in $(WEB_LAB), chromium + lavapipe"
	@echo "make build    creaturegen build \$$EXAMPLE (now $(EXAMPLE)) into out/"
	@echo "make bestiary build-many every example at every tier (and its parity job): out/bestiary/index.html"
	@echo "make parity   build every frost and creature example and run its parity job (out/<slug>/parity/)"
	@echo "make corpus   build $(CORPUS_COUNT) generated creatures at $(CORPUS_TIERS): out/corpus/report.json, index.html"
	@echo "make fuzz     $(FUZZ_CASES) hostile/mutated specs through the gate + $(FUZZ_BUILDS) real builds: out/fuzz/report.json"
	@echo "make test     ruff, ruff format --check, mypy, pytest (browser tests included; per-example jobs on a subset)"
	@echo "make test-full  pytest with the per-example parity and motion-core checks on every example"
	@echo "make schemas  export JSON Schemas into schemas/"
	@echo "make golden   rebuild tests/golden/ (the byte-for-byte package records); review and commit the diff"
	@echo "make lab      serve $(WEB_LAB)/ at http://$(LAB_HOST):$(LAB_PORT)/"
	@echo "make bench    bench/results/field.json (candidates, analytic vs FD), frost.json (tiers, tiles, idle),"
	@echo "              frost_strokes.json (1, 8, 64 strokes at once: binned vs unbinned update, p50/p95),"
	@echo "              surface.json (narrow band vs dense, numpy vs wgpu, extraction, gates),"
	@echo "              runtime.json (creature frame p50/p95 vs bodies, per-body cost, baseline vs 7P/K, spawns),"
	@echo "              motion.json (locomotion core in Node: µs per creature per step, rope cost, allocation),"
	@echo "              validate.json (the spec gate on the worst shapes up to the 1 MiB limit),"
	@echo "              batch.json (build-many: 1 and 2 workers, Dask, cache hit rate on a rebuild, parity stage)"
	@echo "make clean    remove build output and caches; distclean also removes .venv and node_modules"

# --- setup ------------------------------------------------------------------------------------

$(VENV_PY):
	@echo "==> creating $(VENV) with $$($(PYTHON) --version)"
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "creaturegen needs Python >= 3.11")'
	@bash tools/ensure-system-deps.sh venv $(PYTHON)
	$(PYTHON) -m venv $(VENV)

$(VENV_STAMP): pyproject.toml | $(VENV_PY)
	@echo "==> installing creaturegen[dev] into $(VENV)"
	$(VENV_PY) -m pip install --disable-pip-version-check --quiet -e '.[dev]'
	@touch $@

$(NODE_STAMP): $(WEB_LAB)/package.json $(WEB_LAB)/package-lock.json
	@command -v npm >/dev/null || { echo "error: npm not found; install Node.js >= 18 (e.g. apt-get install nodejs npm)" >&2; exit 1; }
	@echo "==> npm ci in $(WEB_LAB)"
	cd $(WEB_LAB) && npm ci --no-audit --no-fund
	@touch $@

system-deps: $(VENV_STAMP)
	@bash tools/ensure-system-deps.sh runtime $(VENV_PY)

setup: $(VENV_STAMP) $(NODE_STAMP) system-deps
	@echo "==> setup done"

# --- products ---------------------------------------------------------------------------------

build: setup
	@echo "==> creaturegen build $(EXAMPLE)"
	$(VENV)/bin/creaturegen build $(EXAMPLE)

# Every example at every tier through build-many, with the parity jobs: out/bestiary/index.json and a gallery.
bestiary: setup
	$(VENV)/bin/creaturegen build-many examples -o out/bestiary --parity

SLUG_OF := $(VENV_PY) -c 'import json, sys; from creaturegen.spec import slugify; print(slugify(json.load(open(sys.argv[1]))["name"]))'

parity: setup
	@pkgs=""; for spec in $(FROST_EXAMPLES) $(CREATURE_EXAMPLES); do \
	  echo "==> creaturegen build $$spec"; $(VENV)/bin/creaturegen build $$spec >/dev/null || exit 2; \
	  pkgs="$$pkgs out/$$($(SLUG_OF) $$spec)"; done; \
	$(VENV)/bin/creaturegen parity $$pkgs

corpus: $(VENV_STAMP)
	@echo "==> corpus: $(CORPUS_COUNT) generated creatures at $(CORPUS_TIERS), $(CORPUS_JOBS) builds at a time"
	$(VENV_PY) -m creaturegen.corpus --count $(CORPUS_COUNT) --tiers $(CORPUS_TIERS) --jobs $(CORPUS_JOBS) -o out/corpus

fuzz: $(VENV_STAMP)
	@echo "==> fuzz: $(FUZZ_CASES) documents through the spec gate, $(FUZZ_BUILDS) builds of mutated valid specs"
	$(VENV_PY) tools/fuzz.py --cases $(FUZZ_CASES) --builds $(FUZZ_BUILDS) -o out/fuzz

schemas: $(VENV_STAMP)
	@echo "==> exporting JSON Schemas into schemas/"
	$(VENV)/bin/creaturegen schema --out schemas

golden: $(VENV_STAMP)
	@echo "==> regenerating tests/golden/ (commit the result)"
	$(VENV_PY) tools/regen-golden.py

lab: $(VENV_STAMP) $(NODE_STAMP)
	$(VENV)/bin/creaturegen lab --out out --host $(LAB_HOST) --port $(LAB_PORT)

bench: setup
	@echo "==> field benchmark into bench/results/field.json"
	$(VENV_PY) bench/field.py --out bench/results/field.json
	@echo "==> frost benchmark (WebGPU on SwiftShader) into bench/results/frost.json"
	$(VENV_PY) bench/frost.py --out bench/results/frost.json
	@echo "==> frost strokes benchmark (1, 8, 64 strokes at once, binned vs unbinned) into bench/results/frost_strokes.json"
	$(VENV_PY) bench/frost_strokes.py --out bench/results/frost_strokes.json
	@echo "==> surface benchmark (narrow band vs dense, numpy vs wgpu, extraction, gates) into bench/results/surface.json"
	$(VENV_PY) bench/surface.py --out bench/results/surface.json
	@echo "==> runtime benchmark (creature population on WebGPU/SwiftShader, shipped vs forbidden baseline) into bench/results/runtime.json"
	$(VENV_PY) bench/runtime.py --out bench/results/runtime.json
	@echo "==> validation benchmark (the spec gate on the worst 1 MiB shapes) into bench/results/validate.json"
	$(VENV_PY) bench/validate.py --out bench/results/validate.json
	@echo "==> motion benchmark (locomotion core in Node: cost per step, rope cost, allocation) into bench/results/motion.json"
	$(VENV_PY) bench/motion.py --out bench/results/motion.json
	@echo "==> batch benchmark (build-many: 1 and 2 workers, Dask, rebuild, resume, parity stage) into bench/results/batch.json"
	$(VENV_PY) bench/batch.py --out bench/results/batch.json

# --- checks -----------------------------------------------------------------------------------

test: setup
	@echo "==> ruff check"
	$(VENV)/bin/ruff check $(LINT_PATHS)
	@echo "==> ruff format --check"
	$(VENV)/bin/ruff format --check $(LINT_PATHS)
	@echo "==> mypy"
	$(VENV)/bin/mypy generator
	@echo "==> pytest"
	CREATUREGEN_STRICT_SETUP=1 $(VENV_PY) -m pytest -n $(PYTEST_WORKERS) $(PYTEST_ARGS)

# make test with the per-example browser parity jobs and motion-core checks on every example (tests/conftest.py
# TEST_FULL), not only the fixed subset.
test-full: setup
	CREATUREGEN_TEST_FULL=1 CREATUREGEN_STRICT_SETUP=1 $(VENV_PY) -m pytest -n $(PYTEST_WORKERS) $(PYTEST_ARGS)

# --- housekeeping -----------------------------------------------------------------------------

clean:
	@echo "==> removing build output and caches"
	find out -mindepth 1 -maxdepth 1 ! -name README.md -exec rm -rf {} +
	rm -rf build dist .pytest_cache .mypy_cache .ruff_cache bench/results
	find generator tests -name __pycache__ -type d -prune -exec rm -rf {} +
	find generator -maxdepth 2 -name '*.egg-info' -type d -prune -exec rm -rf {} +

distclean: clean
	@echo "==> removing $(VENV) and $(WEB_LAB)/node_modules"
	rm -rf $(VENV) $(WEB_LAB)/node_modules
