# brdfprof: `make run` sets up and runs the main job (a profile on the default device);
# `make test` sets up and runs the tests (lavapipe, validation layer on).
CARGO ?= cargo
BIN := target/release/brdfprof

.PHONY: setup build run test spv

setup:
	@sh scripts/setup.sh

build: setup
	$(CARGO) build --release --locked

run: build
	$(BIN) devices
	$(BIN) profile

test: setup
	$(CARGO) test --release --locked

# Recompile glsl/ into spv/ (needs glslang); commit the result.
spv:
	sh glsl/build-spv.sh
