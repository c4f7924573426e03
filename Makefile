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
# images); then each of the five methods on its own demo-sized recording (basso2012 and
# pinto2022 on the demo, 160x120 depth; satake2009 on its stereo pair at 512x384;
# cielniak2010 and dmtbs on the first 150 frames of a scenario of theirs) and a summary:
# CPU fps on one core, the decode floor, their ratio, below 60 fps. JSON under runs/bench/.
BENCH_SYNTH := $(BIN)/rgbd-eval synth --frames 150
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
	@test -f runs/bench/satake2009.mcap || $(BENCH_SYNTH) configs/scenarios/satake2009_crossing.yaml -o runs/bench/satake2009.mcap
	@test -f runs/bench/cielniak2010.mcap || $(BENCH_SYNTH) configs/scenarios/cielniak2010/thermal_corridor.yaml -o runs/bench/cielniak2010.mcap
	@test -f runs/bench/dmtbs.mcap || $(BENCH_SYNTH) configs/scenarios/dmtbs/scene1.yaml -o runs/bench/dmtbs.mcap
	$(BIN)/rgbd-eval bench runs/bench/satake2009.mcap --method satake2009 --repeat 3 --json > runs/bench/method_satake2009.json
	$(BIN)/rgbd-eval bench runs/bench/cielniak2010.mcap --method cielniak2010 --repeat 3 --json > runs/bench/method_cielniak2010.json
	$(BIN)/rgbd-eval bench runs/bench/dmtbs.mcap --method dmtbs --repeat 3 --json > runs/bench/method_dmtbs.json
	cp runs/bench/demo.json runs/bench/method_basso2012.json
	cp runs/bench/demo_pinto2022.json runs/bench/method_pinto2022.json
	$(BIN)/python -m bench.methods_summary runs/bench/method_*.json

test: $(STAMP) test-deps
	$(BIN)/python -m pytest -q -n 2

test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

lint: $(STAMP)
	$(BIN)/ruff check src tests
	$(BIN)/ruff format --check src tests
	$(BIN)/mypy

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache runs .cache
