# Two commands do all set-up on a fresh Debian machine:
#   make run    - installs everything, generates the demo recording, runs the default method on it
#   make test   - installs everything, runs the whole test suite (slow tests included)
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DEMO   := datasets/demo.mcap

.PHONY: setup system-deps test-deps run test test-fast lint datasets bench clean

# open3d needs the system library libusb-1.0 to import on a bare Debian machine.
system-deps:
	@if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then \
		echo "installing libusb-1.0 (needed by open3d)"; \
		SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
		$$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq libusb-1.0-0 >/dev/null; \
	fi

# The HTML report tests open each page in a real headless browser (Debian's chromium).
test-deps:
	@if ! command -v chromium >/dev/null 2>&1; then \
		echo "installing chromium (headless browser for the HTML report tests)"; \
		SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
		$$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq -o DPkg::Lock::Timeout=900 --no-install-recommends chromium >/dev/null; \
	fi

$(STAMP): pyproject.toml
	@$(MAKE) --no-print-directory system-deps
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e ".[dev]"
	@# Test-only parity reference of the `motchallenge` convention (TrackEval, PyPI packaging).
	@# Without its dependencies: it requires opencv-python, which would shadow our headless
	@# OpenCV; its metrics need only numpy and scipy.
	$(BIN)/python -m pip install -q --no-deps "trackeval==1.3.0"
	@touch $(STAMP)

setup: $(STAMP)

$(DEMO): $(STAMP) configs/scenarios/demo.yaml
	$(BIN)/rgbd-eval synth configs/scenarios/demo.yaml -o $(DEMO)

datasets: $(STAMP)
	$(BIN)/rgbd-eval synth --all

run: $(STAMP) $(DEMO)
	$(BIN)/rgbd-eval run $(DEMO)

# One-core figures (the bench pins itself to one CPU): the demo, one thesis scenario, the
# demo with depth at 320x240, and with raw RGB in .mcap and .bag (decode floor for raw
# images), and pinto2022 on the demo (seed 001 V-C1: 33 Hz with a GPU). JSON under runs/bench/.
bench: $(STAMP) $(DEMO)
	@mkdir -p runs/bench
	$(BIN)/rgbd-eval bench $(DEMO) --repeat 3 --json > runs/bench/demo.json
	@test -f datasets/generated/moving_complex.mcap || $(BIN)/rgbd-eval synth moving_complex
	$(BIN)/rgbd-eval bench datasets/generated/moving_complex.mcap --repeat 1 --json > runs/bench/moving_complex.json
	@test -f runs/bench/demo_raw.mcap || $(BIN)/rgbd-eval synth demo --set recording.rgb_format=raw -o runs/bench/demo_raw.mcap
	@test -f runs/bench/demo_raw.bag || $(BIN)/rgbd-eval synth demo --set recording.rgb_format=raw -o runs/bench/demo_raw.bag
	@test -f runs/bench/demo_320.mcap || $(BIN)/rgbd-eval synth demo --set sensor.depth_decimation=2 -o runs/bench/demo_320.mcap
	$(BIN)/rgbd-eval bench runs/bench/demo_320.mcap --repeat 3 --json > runs/bench/demo_320.json
	$(BIN)/rgbd-eval bench runs/bench/demo_raw.mcap --repeat 3 --json > runs/bench/demo_raw_mcap.json
	$(BIN)/rgbd-eval bench runs/bench/demo_raw.bag --repeat 3 --json > runs/bench/demo_raw_bag.json
	$(BIN)/rgbd-eval bench $(DEMO) --method pinto2022 --repeat 1 --json > runs/bench/demo_pinto2022.json
	$(BIN)/rgbd-eval bench $(DEMO) --repeat 1

test: $(STAMP) test-deps
	$(BIN)/python -m pytest -q

test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

lint: $(STAMP)
	$(BIN)/ruff check src tests
	$(BIN)/ruff format --check src tests
	$(BIN)/mypy

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache runs .cache
