# brdfprof: `make run` sets up and runs the main job (a profile on the default device);
# `make test` sets up and runs the tests (lavapipe, validation layer on).
CARGO ?= cargo
BIN := target/release/brdfprof

.PHONY: setup build run test spv baseline

setup:
	@sh scripts/setup.sh

build: setup
	$(CARGO) build --release --locked

# A default output never overwrites a file git tracks (docs/commands.md), so the run names its own, outside results/.
RUN_JSON ?= brdfprof-results/profile.json
run: build
	$(BIN) devices
	$(BIN) profile --json $(RUN_JSON)

test: setup
	$(CARGO) test --release --locked

# Regenerate glsl/generated/ from the Rust tables and recompile glsl/ into spv/ (needs glslang); commit both.
spv:
	$(CARGO) run --release --locked -- __generate-glsl glsl/generated
	sh glsl/build-spv.sh

# Re-measure the committed `check` baseline after a deliberate change to the kernels (or to spv/ after a
# merge): prints the comparison with the old baseline, then replaces it; commit the result.
BASELINE := results/baseline-llvmpipe.json
# The compile-only targets' baselines (ACO for navi21 and vangogh, ptxas for sm_89, IGC for gen12lp, ir3 for a660, Bifrost for g52, brw for tgl; no GPU needed) likewise.
TARGET_BASELINES := radv:navi21 radv:vangogh nvidia:sm_89 intel:gen12lp adreno:a660 mali:g52 anv:tgl
baseline: build
	$(BIN) check --baseline $(BASELINE) --save-baseline $(BASELINE); test $$? -le 1
	for t in $(TARGET_BASELINES); do \
		f=results/baseline-$$(echo $$t | tr : -).json; \
		$(BIN) check --device $$t --baseline $$f --save-baseline $$f; \
		test $$? -le 1 || exit 1; \
	done
