# Everything a fresh machine needs: `make demo` runs the main job, `make test` the tests.
# Both create the virtual environment in .venv and install the package on first use.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp

.PHONY: demo test lint validation-doc clean chromium vendor

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

BIN := $(VENV)/bin
DEMO := build/demo-run

# The main job: validate the physics against the papers, generate the demo dataset, train a
# model on it, simulate a new worn-actuator recording to MCAP and its health check to Parquet,
# diagnose the recording, read the health check phase by phase with the shipped model, replay.
demo: $(STAMP)
	mkdir -p $(DEMO)
	$(BIN)/prsm-health validate > $(DEMO)/validation.txt && tail -n 1 $(DEMO)/validation.txt
	$(BIN)/prsm-health generate datasets/demo.toml --out $(DEMO)/dataset
	$(BIN)/prsm-health train $(DEMO)/dataset --out $(DEMO)/model.skops --cv 3
	$(BIN)/prsm-health simulate --clearance 22e-6 --speed 90 --load 0 --load-profile reversing \
		--load-amplitude 20%C_a --load-frequency 10 --accel-time 0.002 --contact-law hertz \
		--duration 2 --seed 99 --out $(DEMO)/recording.mcap --plot $(DEMO)/recording.png
	$(BIN)/prsm-health simulate --profile health-check --clearance 22e-6 --seed 99 --contact-law hertz \
		--out $(DEMO)/check.parquet --plot $(DEMO)/check.png
	$(BIN)/prsm-health diagnose $(DEMO)/recording.mcap --model $(DEMO)/model.skops --plot $(DEMO)/diagnosis.png
	$(BIN)/prsm-health diagnose $(DEMO)/check.parquet > $(DEMO)/check-diagnosis.txt && head -n 4 $(DEMO)/check-diagnosis.txt
	$(BIN)/prsm-health replay $(DEMO)/recording.mcap --model $(DEMO)/model.skops --out $(DEMO)/recording-diagnosed.mcap
	@echo "demo outputs in $(DEMO)/ (validation.txt, recording.png, check.png, diagnosis.png, check-diagnosis.txt, recording-diagnosed.mcap)"

# The dashboard's browser test (tests/service/test_dashboard_browser.py) drives Debian's
# Chromium: installed here when missing (apt-get, as root). Without it that test fails;
# PRSM_HEALTH_SKIP_BROWSER=1 skips it (and this step).
CHROMIUM := /usr/bin/chromium
chromium:
	@if [ "$$PRSM_HEALTH_SKIP_BROWSER" = 1 ] || [ -x $(CHROMIUM) ]; then exit 0; fi; \
	if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		echo "installing Debian's chromium for the dashboard's browser test (apt-get)"; \
		{ apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
			chromium chromium-driver; } >/dev/null || \
		echo "warning: apt-get could not install chromium: the browser test will fail (apt-get install -y chromium, or PRSM_HEALTH_SKIP_BROWSER=1 to skip it)" >&2; \
	else \
		echo "warning: $(CHROMIUM) is missing and only root can apt-get it: the browser test will fail (sudo apt-get install -y chromium, or PRSM_HEALTH_SKIP_BROWSER=1 to skip it)" >&2; \
	fi

# Two worker processes (pytest-xdist), each test file on one of them: module fixtures (a
# trained model, a dataset) are built once, and a 2-core machine runs the suite in ≈ 5 min
# instead of ≈ 9 (docs/performance.md).
test: $(STAMP) chromium
	$(PY) -m pytest -q -n 2 --dist loadfile

# Re-vendor the dashboard's plotting library from the npm registry (needs npm; the files it
# writes under prsm_health/apps/service/static/vendor/ are committed).
vendor:
	$(PYTHON) tools/release/vendor_js.py

lint: $(STAMP)
	$(VENV)/bin/ruff check prsm_health tests tools
	$(VENV)/bin/ruff format --check prsm_health tests tools

validation-doc: $(STAMP)
	$(PY) tools/release/make_validation_doc.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
