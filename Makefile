# brdfprof: `make run` sets up and runs the main job (a profile on the default device; it needs no Mesa build);
# `make test` sets up, builds Mesa's noop drivers (`make mesa`) and runs the tests (lavapipe, validation layer on).
CARGO ?= cargo
BIN := target/release/brdfprof

.PHONY: setup mesa build run test test-crates spv baseline

# System packages and NVIDIA's compiler wheels: all that `make run` needs (it builds no Mesa).
setup:
	@sh scripts/setup.sh

# Mesa's Turnip, PanVK and ANV on noop drm-shims, for the adreno:, mali: and anv: targets only: ~20 min on 2 cores,
# once per machine (cached in ~/.cache/brdfprof), so `run` does not wait for it; `test` and `baseline` use them.
mesa: setup
	@sh scripts/mesa-noop.sh

build: setup
	$(CARGO) build --release --locked

# A default output never overwrites a file git tracks (docs/commands.md), so the run names its own, outside results/.
RUN_JSON ?= brdfprof-results/profile.json
run: build
	$(BIN) devices
	$(BIN) profile --json $(RUN_JSON)

# The tests compile on every target, the adreno:, mali: and anv: ones included, so they need `mesa`.
test: setup mesa
	$(CARGO) test --release --locked --workspace

# The leaf crates' own tests (BRDF mathematics, process layer, SPIR-V to C writer): no Vulkan driver, no Mesa,
# none of ash, naga or plotters to compile; the quick loop for changes below the application.
LEAF_CRATES := brdfprof-brdf brdfprof-process brdfprof-spirv-c
test-crates:
	$(CARGO) test --release --locked $(addprefix -p ,$(LEAF_CRATES))

# Regenerate glsl/generated/ from the Rust tables and recompile glsl/ into spv/ (needs glslang); commit both.
spv:
	$(CARGO) run --release --locked -- __generate-glsl glsl/generated
	sh glsl/build-spv.sh

# Re-measure the committed `check` baseline after a deliberate change to the kernels (or to spv/ after a
# merge): prints the comparison with the old baseline, then replaces it; commit the result.
BASELINE := results/baseline-llvmpipe.json
# The compile-only targets' baselines (ACO for navi21 and vangogh, ptxas for sm_89, IGC for gen12lp, ir3 for a660, Bifrost for g52, brw for tgl; no GPU needed) likewise.
TARGET_BASELINES := radv:navi21 radv:vangogh nvidia:sm_89 intel:gen12lp adreno:a660 mali:g52 anv:tgl
baseline: build mesa
	$(BIN) check --baseline $(BASELINE) --save-baseline $(BASELINE); test $$? -le 1
	for t in $(TARGET_BASELINES); do \
		f=results/baseline-$$(echo $$t | tr : -).json; \
		$(BIN) check --device $$t --baseline $$f --save-baseline $$f; \
		test $$? -le 1 || exit 1; \
	done
