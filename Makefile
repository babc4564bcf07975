# HapticSculpt: `make demo` and `make test` set up a fresh Debian 12 machine, build and run.
PY          := /usr/bin/python3
BUILD       := build
JOBS        ?= 2
APT_PACKAGES := build-essential cmake ninja-build pkg-config libeigen3-dev pybind11-dev libgtest-dev \
                python3-dev python3-numpy python3-scipy python3-pytest python3-matplotlib \
                freecad-python3 libhidapi-dev xvfb xauth
SUDO        := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build build-asan test test-cpp test-asan test-python demo bench clean

all: build

# Installs only what is missing (dpkg-query is quick when everything is there).
deps:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

build: deps
	cmake -S native_core -B $(BUILD)/release -G Ninja -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD)/release -j $(JOBS)

# C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer (no Python extension: it would need
# the sanitizer runtime preloaded into the interpreter).
build-asan: deps
	cmake -S native_core -B $(BUILD)/asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DHS_SANITIZE=ON -DHS_PYTHON=OFF
	cmake --build $(BUILD)/asan -j $(JOBS)

test-cpp: build
	ctest --test-dir $(BUILD)/release --output-on-failure -j $(JOBS)

test-asan: build-asan
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --test-dir $(BUILD)/asan --output-on-failure -j $(JOBS)

test-python: build
	$(PY) -m pytest -q tests

test: test-cpp test-asan test-python

demo: build
	$(PY) demo.py --out out

bench: build
	$(PY) bench/table1.py

clean:
	rm -rf $(BUILD) HapticSculpt/_core*.so
