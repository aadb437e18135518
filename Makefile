# Two commands on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -c constraints.txt -e '.[all,dev]'
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/satmd reproduce --out report

test: $(STAMP)
	$(PY) -m pytest -q

bench: $(STAMP)
	@for b in benchmarks/*.py; do case $$b in */readme_tables.py|*/_*.py) continue;; esac; \
	  echo "== $$b"; $(PY) $$b || exit 1; done
	$(PY) benchmarks/readme_tables.py   # README's result tables from the new JSON

clean:
	rm -rf $(VENV) report .pytest_cache .hypothesis
