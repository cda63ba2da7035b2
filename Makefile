# Quick start: `make demo` runs the main demo, `make test` runs the whole test suite.
# Both create their own virtual environment in .venv on first use (needs only python3) and
# compile the numba kernels into their cache once (`taut compile`, docs/compiled_kernels.md).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
# `make demo` installs only what the demo needs: the core and the viz extra (its --plot),
# not the test extra (MuJoCo, Dask, OMPL, Selenium, mypy); `make test` adds the rest.
DEMO_STAMP := $(VENV)/.demo-stamp

.PHONY: demo test test-slow bench clean clean-cache

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(DEMO_STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[viz]'
	$(BIN)/taut compile
	touch $(DEMO_STAMP)

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/taut compile
	touch $(STAMP)

demo: $(DEMO_STAMP)
	$(BIN)/taut fk examples/sheet/example2_r2_r4_353mm.yaml --mass 1.0 --plot out/example2.png

# `taut compile` returns at once when the kernels are cached; after a kernel edit it
# compiles them once here, not in the middle of the tests.
# The suite runs on one pytest-xdist worker per core (`auto`; TEST_WORKERS=0: one process),
# each test file whole on one worker (`loadfile`): a module's fixtures are built once and
# tests/test_readme.py's snippets run in order in one namespace. mypy and the doctests run
# beside it (mypy from an empty cache is ~40 s of CPU) and print when the suite is done;
# the target fails if any of the three fails.
TEST_WORKERS ?= auto
test: $(STAMP)
	$(BIN)/taut compile
	@log=$$(mktemp); \
	{ $(BIN)/python -m mypy; types=$$?; \
	  $(BIN)/python -m pytest --doctest-modules src/taut -p no:cacheprovider; docs=$$?; \
	  [ $$types -eq 0 ] && [ $$docs -eq 0 ]; } >$$log 2>&1 & checks=$$!; \
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadfile -m "not slow and not browser"; \
	tests=$$?; wait $$checks; checked=$$?; \
	echo "--- mypy and the doctests:"; cat $$log; rm -f $$log; \
	[ $$tests -eq 0 ] && [ $$checked -eq 0 ]

# Heavy cases (marked `slow`) and the app's browser tests (a Chromium each, seconds per test);
# CI runs them after `make test`. Exit 5 = none collected.
test-slow: $(STAMP)
	$(BIN)/python -m pytest -m "slow or browser" || [ $$? -eq 5 ]

bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test,bench]'
	$(BIN)/python bench/bench_fk.py

# numba's cache notices edits to a kernel's own file only, not to kernels it calls from
# other files (src/taut/_jit.py): after editing a kernel, drop the cached code.
clean-cache:
	find src -name '*.nbi' -delete -o -name '*.nbc' -delete -o -name 'taut-jit-*.stamp*' -delete

clean: clean-cache
	rm -rf $(VENV) out .pytest_cache .hypothesis
