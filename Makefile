# The two commands of the quick start: `make run` and `make test`.
# Both create .venv on first use (Python 3.11+, nothing else needed).
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test lint docs bench clean opcua-nodesets

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	@touch $(STAMP)

# The OPC UA models of `boltwatch serve opcua` (node-opcua-nodesets, pinned and checked,
# into .cache/opcua-nodesets/; without npm it says so and the rest goes on).
opcua-nodesets: $(STAMP)
	@$(BIN)/python -m services.opcua.nodeset_files

run: $(STAMP) opcua-nodesets
	$(BIN)/boltwatch up $(ARGS)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports
	$(BIN)/python -m tests.support.import_rules

# The unit tests on two xdist workers, then the system tests in one process, one after
# another and alone (real processes, namespaces and buses in real time: beside other work
# their keep-alives and timers fail). Both run when the first fails; either fails the target.
test: lint opcua-nodesets
	$(BIN)/pytest -n 2 tests/unit; unit=$$?; $(BIN)/pytest tests/system; system=$$?; \
		exit $$((unit || system))

# docs/ as a site in site/: the generated reference pages written again, then built with
# --strict (a warning or a broken link fails). mkdocs comes with the dev extra.
docs: $(STAMP)
	$(BIN)/python -m services.cli.reference_pages
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

bench: $(STAMP)
	$(BIN)/pytest tests/benchmarks -s

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache site
