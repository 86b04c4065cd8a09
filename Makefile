# Every target that needs Python sets up .venv (with the package installed
# editable, plus the test and bench extras) the first time it runs.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
ARGS ?=

.PHONY: run test bench lint format wheel clean

$(STAMP): pyproject.toml
	@echo "First run: making $(VENV) and installing airtable with pygame-ce, numpy and the test tools (a minute or so)..."
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --disable-pip-version-check --progress-bar on -e '.[test,bench]'
	touch $(STAMP)
	@echo "Done. To type the commands of README.md as written, activate it: . $(VENV)/bin/activate"

run: $(STAMP)
	$(BIN)/python -m airtable $(ARGS)

# One worker per core (pytest-xdist), each test handed to whichever is free.
test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist worksteal

bench: $(STAMP)
	$(BIN)/python -m bench $(ARGS)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

# dist/airtable-*.whl: what a student installs with pip to get airtable-client.
wheel: $(STAMP)
	$(BIN)/python -m pip wheel --no-deps --wheel-dir dist .

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .ruff_cache
