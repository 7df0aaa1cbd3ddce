# Everything a fresh machine needs: `make demo` runs the main job, `make test` the tests.
# Both create the virtual environment in .venv and install the package on first use.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp

.PHONY: demo test lint validation-doc clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

BIN := $(VENV)/bin
DEMO := build/demo-run

# The main job: validate the physics against the papers, generate the demo dataset, train a
# model on it, simulate a new worn-actuator recording to MCAP, diagnose it, replay it.
demo: $(STAMP)
	mkdir -p $(DEMO)
	$(BIN)/prsm-health validate > $(DEMO)/validation.txt && tail -n 1 $(DEMO)/validation.txt
	$(BIN)/prsm-health generate datasets/demo.toml --out $(DEMO)/dataset
	$(BIN)/prsm-health train $(DEMO)/dataset --out $(DEMO)/model.skops --cv 3
	$(BIN)/prsm-health simulate --clearance 22e-6 --speed 90 --load 50 --load-profile reversing \
		--load-amplitude 300 --load-frequency 10 --accel-time 0.002 --contact-law hertz \
		--duration 2 --seed 99 --out $(DEMO)/recording.mcap --plot $(DEMO)/recording.png
	$(BIN)/prsm-health diagnose $(DEMO)/recording.mcap --model $(DEMO)/model.skops --plot $(DEMO)/diagnosis.png
	$(BIN)/prsm-health replay $(DEMO)/recording.mcap --model $(DEMO)/model.skops --out $(DEMO)/recording-diagnosed.mcap
	@echo "demo outputs in $(DEMO)/ (validation.txt, recording.png, diagnosis.png, recording-diagnosed.mcap)"

test: $(STAMP)
	$(PY) -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check prsm_health tests tools
	$(VENV)/bin/ruff format --check prsm_health tests tools

validation-doc: $(STAMP)
	$(PY) tools/make_validation_doc.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
