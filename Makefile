# Two commands on a fresh machine: `make demo` and `make test`.
# Both install the locked versions of requirements.lock (every direct and transitive dependency
# at an exact version), so a new machine gets what CI tested. `make lock` refreshes the lock;
# `make test-latest` runs the suite on the newest versions pyproject.toml admits.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
LOCK   := requirements.lock
PIP_TOOLS := pip-tools==7.6.2

.PHONY: demo test bench lock test-latest clean docs docs-check

$(STAMP): pyproject.toml $(LOCK)
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --disable-pip-version-check -r $(LOCK)
	$(PY) -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation -e .
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/satmd reproduce --out report

# The suite on every core (pytest-xdist: the tests are independent), one BLAS thread a worker: two
# workers of two BLAS threads each would fight over two cores. A module's tests on one worker (loadscope):
# spread test by test, both workers built the same module fixtures (simulations, fits): 500 s → 358 s.
# Bytecode is written and read whatever the caller's environment says (PYTHONDONTWRITEBYTECODE set: each
# worker and each `satmd` the docs' and README's blocks run compiled satmd's modules afresh).
TEST_ENV := OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 PYTHONDONTWRITEBYTECODE=
PYTEST_XDIST := -n auto --dist loadscope
test: $(STAMP)
	$(TEST_ENV) $(PY) -m pytest -q $(PYTEST_XDIST)

bench: $(STAMP)
	@for b in benchmarks/*.py; do case $$b in */readme_tables.py|*/_*.py) continue;; esac; \
	  echo "== $$b"; $(PY) $$b || exit 1; done
	$(PY) benchmarks/readme_tables.py   # README's result tables from the new JSON

# The lock: the newest versions pyproject.toml admits (torch held by constraints.txt to the
# build the project's machines have), resolved by pip-tools in a throw-away environment.
lock:
	@test -x .venv-lock/bin/pip-compile || ($(PYTHON) -m venv .venv-lock && \
	  .venv-lock/bin/pip install -q --disable-pip-version-check $(PIP_TOOLS))
	.venv-lock/bin/pip-compile -q --upgrade --extra all --extra dev --extra docs --strip-extras --allow-unsafe \
	  -c constraints.txt --no-emit-index-url --no-emit-find-links -o $(LOCK) pyproject.toml
	sed -i '/^satmd @ /d' $(LOCK)   # the project itself (its `all` extra names it) is installed editable

# The documentation site (docs/, Sphinx): warnings are errors. `docs` runs the gallery (examples/plot_*.py,
# each under a minute on 2 cores) and writes build/docs/html; `docs-check` (what tests/test_docs.py and so CI
# build) leaves the gallery unexecuted, so a broken reference or docstring fails in well under a minute.
# Nothing is fetched from the network: the intersphinx inventories are written from the installed packages.
SPHINX := $(PY) -m sphinx -W --keep-going -j 1 -q
docs: $(STAMP)
	$(SPHINX) -b html docs build/docs/html
	@echo "docs: build/docs/html/index.html"

docs-check: $(STAMP)
	$(SPHINX) -b html -D plot_gallery=0 docs build/docs/check

# Drift, seen rather than suffered: the suite on the newest versions, in its own environment.
test-latest:
	@test -x .venv-latest/bin/python || $(PYTHON) -m venv .venv-latest
	.venv-latest/bin/pip install -q --disable-pip-version-check --upgrade -c constraints.txt -e '.[all,dev]'
	$(TEST_ENV) .venv-latest/bin/python -m pytest -q $(PYTEST_XDIST)

clean:
	rm -rf $(VENV) .venv-lock .venv-latest report .pytest_cache .hypothesis build docs/api/generated docs/auto_examples \
	  docs/api/satmd*.rst docs/sg_execution_times.rst
