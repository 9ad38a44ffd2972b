# Two user-facing targets: `make demo` and `make test`. Both set up what they
# need (a local .venv with the package installed editable, the C build) and are
# quick when nothing changed: the install re-runs only when pyproject.toml or the
# C sources change, and CMake rebuilds only what changed.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
CBUILD := build/c
C_SOURCES := $(wildcard fmu_src/core/*.c fmu_src/core/*.h) fmu_src/core/cflags.txt
# the compiled extensions pip builds (pyproject.toml): the friction law and the ring's block LU
EXT_SOURCES := $(C_SOURCES) $(wildcard harmonic_balance/bladed_disk/*.c harmonic_balance/bladed_disk/*.h)
C_ALL     := $(C_SOURCES) $(wildcard fmu_src/*/*.c fmu_src/*/*.h fmu_src/*/*.in) CMakeLists.txt $(wildcard fmu_src/*/CMakeLists.txt)
# System cmake, not the one fmpy's dependencies put in the venv.
CMAKE  ?= cmake

.PHONY: demo test pytest ctest cbuild lint bench accel browser clean locale docs validation docs-bench docs-bench-surface docs-bench-peers docs-bench-peers-1pct docs-stress

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip

$(STAMP): pyproject.toml $(EXT_SOURCES) | $(PY)
	$(PY) -m pip install -q -e '.[dev]' > $(VENV)/install.log 2>&1 || (cat $(VENV)/install.log; exit 1)
	@# Fast sparse solver without root (MKL PARDISO from pip), best effort: scipy otherwise.
	@$(PY) -m pip install -q -e '.[fast]' >> $(VENV)/install.log 2>&1 \
	  || echo "note: fast solver (pypardiso) not installed (see $(VENV)/install.log); using scipy"
	@# Optional accelerator, best effort: CHOLMOD when SuiteSparse's headers are there (make accel).
	@if [ -f /usr/include/suitesparse/cholmod.h ]; then \
	  $(PY) -m pip install -q 'scikit-sparse<0.5' >> $(VENV)/install.log 2>&1 \
	  || echo "note: CHOLMOD accelerator not built (see $(VENV)/install.log); using scipy"; fi
	touch $@

$(CBUILD)/.built: $(C_ALL) | $(PY)
	mkdir -p $(CBUILD)
	$(CMAKE) -S . -B $(CBUILD) -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=$(abspath $(PY)) > $(CBUILD)/build.log 2>&1 || (cat $(CBUILD)/build.log; exit 1)
	$(CMAKE) --build $(CBUILD) -j 2 >> $(CBUILD)/build.log 2>&1 || (cat $(CBUILD)/build.log; exit 1)
	touch $@

cbuild: $(CBUILD)/.built

ctest: cbuild
	cd $(CBUILD) && ctest --output-on-failure

# The run records its reference checks (tests/refcheck.py); the check after it fails when
# docs/data/validation.json (the documentation's validation table) no longer lists them.
# On PYTEST_WORKERS processes (pytest-xdist), a test file's tests on one of them, so a
# file's module fixtures are built once; the workers' records are merged (tests/conftest.py).
PYTEST_WORKERS ?= 2
pytest: $(STAMP) cbuild browser
	DAMPER_VALIDATION_JSON=build/validation.json OPENBLAS_NUM_THREADS=1 $(PY) -m pytest -q \
	  -n $(PYTEST_WORKERS) --dist loadfile
	$(PY) docs/tools/validation_check.py build/validation.json docs/data/validation.json

lint: $(STAMP)
	$(VENV)/bin/ruff check .

test: lint locale ctest docs pytest

# A decimal-comma locale for the FMU locale tests (tests/fmu/test_fmu_trust.py):
# generated with localedef when missing; as root on a fresh Debian/Ubuntu machine the
# `locales` package (localedef and the locale sources) is installed first. Without
# root or apt-get the step is skipped and the tests skip with a reason.
TEST_LOCALE := de_DE.UTF-8
locale:
	@if locale -a 2>/dev/null | grep -qi '^de_DE\.utf-\?8$$'; then exit 0; fi; \
	if [ ! -f /usr/share/i18n/locales/de_DE ] && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  apt-get install -y -qq locales >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq locales) >/dev/null 2>&1; fi; \
	if [ -f /usr/share/i18n/locales/de_DE ] && [ "$$(id -u)" = 0 ]; then \
	  localedef -i de_DE -f UTF-8 $(TEST_LOCALE) && echo "generated locale $(TEST_LOCALE)"; \
	else echo "note: locale $(TEST_LOCALE) not available (needs root and the locales package): its tests skip"; fi

# The bundled default scene through `damper run`; a second run loads every stage from
# the cache (.damper_cache) and says so.
demo: $(STAMP)
	$(VENV)/bin/damper run examples/scenes/default.toml --out out

# Headless Chromium for the HTML-report test, best effort: installed with apt-get when
# we are root on Debian; otherwise the test skips and says why.
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	  { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && \
	    (apt-get update -qq && apt-get install -y -qq chromium) >/dev/null 2>&1; } || \
	  echo "note: no chromium (needs root and apt-get): the HTML report browser test will skip"

# The documentation site (docs/, Sphinx): offline, warnings are errors, every example in
# examples/ runs (the long ones in their quick mode: docs/tools/gallery.py). Opens at
# build/docs/html/index.html.
docs: $(STAMP) cbuild
	OPENBLAS_NUM_THREADS=1 $(VENV)/bin/sphinx-build -W --keep-going -q -b html docs build/docs/html
	@echo "documentation: build/docs/html/index.html"

# The data behind the generated documentation pages, one command each (stamped with
# command, revision, date and machine; commit the JSON, then `make docs`):
# validation: the tests that make reference checks (tests/refcheck.py), recorded;
# docs-bench / docs-stress: the full `damper bench` / `damper stress` runs (long).
validation: $(STAMP) cbuild
	DAMPER_VALIDATION_JSON=docs/data/validation.json DAMPER_VALIDATION_COMMAND="make validation" \
	  OPENBLAS_NUM_THREADS=1 $(PY) -m pytest -q -p no:cacheprovider $$(grep -rl --include='test_*.py' 'from refcheck import' tests)
docs-bench: $(STAMP) cbuild
	nice $(PY) docs/tools/record.py docs/data/bench.json -- $(VENV)/bin/damper bench --json --out out/bench
# docs-bench-surface: the surface stage by itself (20 nodes per side at H 7: minutes).
docs-bench-surface: $(STAMP) cbuild
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/bench_surface.json -- \
	  $(VENV)/bin/damper bench --stage surface --json --out out/bench_surface
# docs-bench-peers: the hb stage against pyHarm and NLvib (PYHARM = a Python with pyharm-os,
# NLVIB = a checkout of maltekrack/NLvib, GNU Octave on the PATH; about 45 minutes).
docs-bench-peers: $(STAMP) cbuild
	@test -n "$(PYHARM)" -a -n "$(NLVIB)" || { echo "give PYHARM=python-with-pyharm NLVIB=nlvib-folder"; exit 2; }
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/bench_peers.json -- \
	  $(VENV)/bin/damper bench --stage hb --pyharm $(PYHARM) --nlvib $(NLVIB) --json --out out/bench_peers
# docs-bench-peers-1pct: each tool at the H that brings it within 1 % of the converged peak,
# ours against pyHarm (PYHARM = a Python with pyharm-os; every default case, the 5-mass
# chain at H up to 21 included: about an hour; CASES=sdof, e.g., for a subset).
docs-bench-peers-1pct: $(STAMP) cbuild
	@test -n "$(PYHARM)" || { echo "give PYHARM=python-with-pyharm"; exit 2; }
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/bench_peers_1pct.json -- \
	  $(PY) -m damper.bench.peers_1pct --pyharm $(PYHARM) $(foreach c,$(CASES),--case $(c)) --json
# docs-accuracy: the truncation-error estimate against the true error (about 50 minutes).
docs-accuracy: $(STAMP) cbuild
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/accuracy.json -- \
	  $(PY) -m damper.bench.hb_accuracy --only frf --json
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/accuracy_upd.json -- \
	  $(PY) -m damper.bench.hb_accuracy --only upd --json
	OPENBLAS_NUM_THREADS=1 nice $(PY) docs/tools/record.py docs/data/accuracy_contact.json -- \
	  $(PY) -m damper.bench.hb_accuracy --only contact --json
docs-stress: $(STAMP) cbuild
	nice $(PY) docs/tools/record.py docs/data/stress.json -- $(VENV)/bin/damper stress --json --out out/stress

# Benchmarks print tables (case, size, error, time, memory); long, never in CI.
# One report of every stage (out/bench/bench.html, bench.json), sparse back ends included.
bench: $(STAMP) cbuild
	nice $(VENV)/bin/damper bench --solvers --out out/bench

# Optional accelerator: the system's CHOLMOD (scikit-sparse) for the FE condensation, same
# answers as PARDISO and the scipy fallback, as fast as PARDISO. Needs root for apt-get.
accel: $(STAMP)
	apt-get update -qq && apt-get install -y -qq libsuitesparse-dev libopenblas0-pthread
	$(PY) -m pip install -q 'scikit-sparse<0.5'

clean:
	rm -rf build out .damper_cache docs/_generated docs/auto_examples
