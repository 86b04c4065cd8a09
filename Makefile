# Every target that needs Python sets up .venv the first time it runs: `make run` installs
# the app alone (pygame-ce and numpy); `make test`, `make bench` and `make lint` add the
# test, lint and benchmark tools (pytest, hypothesis, ruff, pymunk).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
APP_STAMP := $(VENV)/.app-installed
STAMP := $(VENV)/.installed
ARGS ?=

.PHONY: run test bench lint format wheel clean

$(APP_STAMP): pyproject.toml
	@echo "First run: making $(VENV) and installing airtable with pygame-ce and numpy (a minute or so)..."
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --disable-pip-version-check --progress-bar on -e .
	touch $(APP_STAMP)
	@echo "Done. To type the commands of README.md as written, activate it: . $(VENV)/bin/activate"

$(STAMP): $(APP_STAMP)
	@echo "Installing the test, lint and benchmark tools into $(VENV)..."
	$(BIN)/python -m pip install --disable-pip-version-check --progress-bar on -e '.[test,bench]'
	touch $(STAMP)

run: $(APP_STAMP)
	$(BIN)/python -m airtable $(ARGS)

# One worker per core (pytest-xdist), each test handed to whichever is free.
test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist worksteal

# The benchmarks live in bench/ beside the package (not in the wheel).
bench: $(STAMP)
	$(BIN)/python -m bench $(ARGS)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

# dist/airtable-*.whl: what a student installs with pip to get airtable-client.
wheel: $(APP_STAMP)
	$(BIN)/python -m pip wheel --no-deps --wheel-dir dist .

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .ruff_cache
