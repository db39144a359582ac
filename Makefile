# brdfprof: `make run` sets up and runs the main job (a profile on the default device; it needs no Mesa build);
# `make test` sets up, builds Mesa's noop drivers (`make mesa`) and runs the tests (lavapipe, validation layer on).
CARGO ?= cargo
BIN := target/release/brdfprof

.PHONY: setup setup-tests mesa mesa-adreno mesa-mali mesa-anv mesa-nak mesa-key build run test test-crates spv baseline install

# System packages and the compiler wheels (NVRTC, slangc): all that brdfprof needs to run (`make run` builds no
# Mesa). apt-get runs as root or through sudo; nothing else needs root.
setup:
	@sh scripts/setup.sh

# What only the tests need besides (Chromium, npm and the SARIF Multitool).
setup-tests: setup
	@sh scripts/setup-tests.sh

# Mesa's drivers on noop drm-shims for the adreno:, mali:, anv: and nak: targets: once per machine (cached in
# ~/.cache/brdfprof), so `run` does not wait for it; `test` and `baseline` use them. `make mesa VENDORS="adreno
# nak"` or `make mesa-adreno` builds only what those families load; `make mesa-key` prints the cache key (docs/ci.md).
VENDORS ?= adreno mali anv nak
mesa: setup
	@BRDFPROF_MESA_VENDORS="$(VENDORS)" sh scripts/mesa-noop.sh
mesa-adreno mesa-mali mesa-anv mesa-nak: setup
	@BRDFPROF_MESA_VENDORS="$(@:mesa-%=%)" sh scripts/mesa-noop.sh
mesa-key:
	@BRDFPROF_MESA_VENDORS="$(VENDORS)" sh scripts/mesa-noop.sh --key

build: setup
	$(CARGO) build --release --locked

# A default output never overwrites a file git tracks (docs/commands.md), so the run names its own, outside results/.
RUN_JSON ?= brdfprof-results/profile.json
run: build
	$(BIN) devices
	$(BIN) profile --json $(RUN_JSON)

# The tests compile on every target, the adreno:, mali: and anv: ones included, so they need `mesa`.
test: setup-tests mesa
	$(CARGO) test --release --locked --workspace

# The binary into PREFIX/bin, its man page and shell completions beside it; it finds its tools (the wheels of
# `make setup`, the Mesa builds of `make mesa`) in the per-user data directory, not in this checkout, so the
# checkout may move or go. `cargo install --path .` installs the same binary (without the man page).
PREFIX ?= $(HOME)/.local
install: build
	install -Dm755 $(BIN) "$(PREFIX)/bin/brdfprof"
	mkdir -p "$(PREFIX)/share/man/man1" "$(PREFIX)/share/bash-completion/completions" "$(PREFIX)/share/zsh/site-functions" "$(PREFIX)/share/fish/vendor_completions.d"
	$(BIN) __man "$(PREFIX)/share/man/man1"
	$(BIN) completions bash > "$(PREFIX)/share/bash-completion/completions/brdfprof"
	$(BIN) completions zsh > "$(PREFIX)/share/zsh/site-functions/_brdfprof"
	$(BIN) completions fish > "$(PREFIX)/share/fish/vendor_completions.d/brdfprof.fish"

# The leaf crates' own tests (BRDF mathematics, process layer, SPIR-V to C writer): no Vulkan driver, no Mesa,
# none of ash, naga or plotters to compile; the quick loop for changes below the application.
LEAF_CRATES := brdfprof-brdf brdfprof-files brdfprof-front brdfprof-isa-cost brdfprof-process brdfprof-spirv-c
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
