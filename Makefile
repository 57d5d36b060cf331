# Both targets create .venv on first use and install the project from its own files.
PY ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow lint bench clean browser cf-units screenshots

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	@# The compiled wavenumber-domain loops (numba) built once here, not on a first call.
	$(BIN)/python -c "from holoradar.imaging.migration.backends import columns; columns.warm()"
	@touch $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/holoradar demo --out demo_out --force

# The viewer's end-to-end tests drive Debian's headless Chromium with its chromedriver:
# installed here when missing and this user may (root, or password-less sudo); where it
# cannot be, those tests skip and say why.
BROWSER_PKGS := chromium chromium-driver
browser:
	@if command -v chromium >/dev/null && command -v chromedriver >/dev/null; then :; \
	elif [ "$$(id -u)" = 0 ]; then \
	  (apt-get install -y -q $(BROWSER_PKGS) >/dev/null 2>&1 || \
	   (apt-get update -q >/dev/null 2>&1 && apt-get install -y -q $(BROWSER_PKGS) >/dev/null)) \
	  || echo "could not install $(BROWSER_PKGS): the browser tests will skip"; \
	elif sudo -n true 2>/dev/null; then \
	  sudo -n apt-get install -y -q $(BROWSER_PKGS) >/dev/null \
	  || echo "could not install $(BROWSER_PKGS): the browser tests will skip"; \
	else echo "$(BROWSER_PKGS) missing and not installable here: the browser tests will skip"; \
	fi

# The CF conventions checker (cfchecker, in the test extras) loads the UDUNITS-2 C library:
# Debian's libudunits2-0, installed here when missing and this user may; where it cannot
# be, the checker's test skips and says why.
UDUNITS_PKG := libudunits2-0
cf-units:
	@if ldconfig -p 2>/dev/null | grep -q libudunits2; then :; \
	elif [ "$$(id -u)" = 0 ]; then \
	  (apt-get install -y -q $(UDUNITS_PKG) >/dev/null 2>&1 || \
	   (apt-get update -q >/dev/null 2>&1 && apt-get install -y -q $(UDUNITS_PKG) >/dev/null)) \
	  || echo "could not install $(UDUNITS_PKG): the CF checker's test will skip"; \
	elif sudo -n true 2>/dev/null; then \
	  sudo -n apt-get install -y -q $(UDUNITS_PKG) >/dev/null \
	  || echo "could not install $(UDUNITS_PKG): the CF checker's test will skip"; \
	else echo "$(UDUNITS_PKG) missing and not installable here: the CF checker's test will skip"; \
	fi

# The suite runs on every core (pytest-xdist, a test file per worker so that its shared
# set-up is made once), each worker's BLAS on one thread: two suites' worth of BLAS
# threads on two cores would only wait on each other.
PYTEST_PARALLEL := -n auto --dist loadfile
# Compiled bytecode of src and tests kept (in their __pycache__ folders, ignored by git),
# even where the environment turns bytecode off, and made once before the workers
# start: otherwise each of them compiles every module again (~4.5 s of collection
# each). (Not PYTHONPYCACHEPREFIX: under it Python reads no __pycache__ folder, and
# recompiled every installed package it imports, numpy to bokeh, in every worker.)
# And numba's loop checked (rebuilt if its source changed) so that no worker compiles it.
PYCACHE := PYTHONDONTWRITEBYTECODE=
PREPARE := $(PYCACHE) $(BIN)/python -m compileall -q -j 0 src tests && \
	$(PYCACHE) $(BIN)/python -c "from holoradar.imaging.migration.backends import columns; columns.warm()"
test: $(STAMP) browser cf-units
	$(BIN)/ruff check src tests benchmarks examples tools
	$(PREPARE)
	$(PYCACHE) MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -q $(PYTEST_PARALLEL)

test-slow: $(STAMP)
	$(PREPARE)
	$(PYCACHE) MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -q -m slow $(PYTEST_PARALLEL)

# The documentation's pictures of the viewer, taken by its browser tests.
screenshots: $(STAMP) browser
	HOLORADAR_SCREENSHOTS=docs/figures MPLBACKEND=Agg $(BIN)/python -m pytest -q \
	  -m "browser" tests/test_viewer_browser.py tests/test_report_browser.py

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples tools

bench: $(STAMP)
	$(BIN)/python -m pip install -q -e '.[test,bench]'
	$(BIN)/python benchmarks/bench_migrate.py

clean:
	rm -rf $(VENV) demo_out .pytest_cache .ruff_cache
