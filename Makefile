# Front door. `make check`, `make test` and `make demo` work on a fresh Debian
# 12 as root: they install the Debian packages that are missing (and only
# those), configure CMake once, build with -Wall -Wextra -Werror and run.

BUILD      ?= build
BUILD_TYPE ?= RelWithDebInfo
JOBS       ?= $(shell nproc)
PREFIX     ?= /usr/local
comma      := ,

# New build directories use Ninja: it compiles a target's sources while the
# libraries the target links are still being built (Make waits for them), so
# both cores stay busy to the end. A directory keeps the generator it was
# configured with; CMAKE_GENERATOR in the environment picks another.
export CMAKE_GENERATOR ?= Ninja

# Debian packages the project needs; see README.md for why each is here.
# BUILD_PACKAGES configure and build the tree (tests/sandbox's configure
# needs libseccomp-dev and systemd-analyze); TEST_PACKAGES are what only
# running the tests needs. `make`, `make demo` and `make demo-offline`
# install the first alone: chromium and lintian bring hundreds of
# megabytes the demo does not run.
BUILD_PACKAGES := build-essential cmake pkg-config libeigen3-dev libsuitesparse-dev \
                  libmodbus-dev libsystemd-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev \
                  libgtest-dev libgmock-dev libgpiod-dev systemd ninja-build libseccomp-dev \
                  libinih-dev
TEST_PACKAGES  := mbpoll bubblewrap lintian chromium tidy nodejs python3
DEB_PACKAGES   := $(BUILD_PACKAGES) $(TEST_PACKAGES)
# mbpoll: a Modbus master neither the daemon nor the virtual robot shares
# code with, for the load cell's cross-check test. bubblewrap: the test that
# runs the daemon in the unit's sandbox. lintian: the package test. chromium
# and tidy: the tests that read the HTML reports in a headless browser and
# check them as HTML5 (tools/check-report). nodejs: runs the independent
# CANopen peer (tests/peer, the npm package canopen; see peer-deps below);
# python3: node-gyp builds canopen's CRC addon (node-crc) with it.
# Ceres and Google Benchmark are used by the benchmark comparison only,
# never linked into the daemon.
BENCH_PACKAGES := libceres-dev libbenchmark-dev
# clang and its runtimes (libFuzzer, ASan, UBSan) for make fuzz only.
FUZZ_PACKAGES := clang libclang-rt-14-dev

FUZZ_BUILD   ?= $(BUILD)-fuzz
FUZZ_SECONDS ?= 600
FUZZ_TARGETS ?=

.PHONY: all deps build-deps bench-deps peer-deps configure check test sanitize fuzz demo demo-offline bench install deb docs clean

all: configure
	cmake --build $(BUILD) -j $(JOBS)

deps:
	@./tools/install-deps.sh $(DEB_PACKAGES)

build-deps:
	@./tools/install-deps.sh $(BUILD_PACKAGES)

bench-deps:
	@./tools/install-deps.sh $(BENCH_PACKAGES)

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCDPR_WERROR=ON

configure: build-deps $(BUILD)/CMakeCache.txt

# The day-to-day loop: builds what the unit tests run, runs the tests
# labelled unit (cmake/CdprTesting.cmake), seconds after the build. Twice
# as many tests at a time as cores: a fifth of the unit tests' time is
# spent waiting (timeouts, sockets, child processes), not computing, and a
# waiting test would hold a core's slot idle (docs/measurements/make-check.md).
CHECK_JOBS ?= $(shell echo $$((2 * $(JOBS))))
check: deps configure
	cmake --build $(BUILD) -j $(JOBS) --target unit_test_binaries
	cd $(BUILD) && ctest --output-on-failure -j $(CHECK_JOBS) -L '^unit$$'

# The CANopen peer's npm package (tests/peer/package-lock.json pins it),
# for the integration tests against a stack we did not write. Debian 12's
# nodejs comes without npm, which is the Debian package npm; a nodejs from
# elsewhere (NodeSource) brings its own npm and conflicts with Debian's, so
# the package is installed only when the command is missing. Without the
# registry the peer's tests skip and say why.
PEER_DIR := tests/peer
peer-deps: deps
	@command -v npm >/dev/null || ./tools/install-deps.sh npm
	@[ -f $(PEER_DIR)/node_modules/canopen/package.json ] || \
	  (cd $(PEER_DIR) && npm ci --no-audit --no-fund) || \
	  echo "peer-deps: npm could not install $(PEER_DIR)'s packages (registry unreachable?): the CANopen peer tests will skip"

# Every test: unit, integration and slow.
test: deps peer-deps all
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The whole test suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (any UB is fatal, leaks fail). Built cheaper than the normal build: -O1
# -g1 and only the test binaries (no tools, no benchmarks). CI runs it.
SANITIZE_BUILD ?= $(BUILD)-asan
SANITIZE_ENV := ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
# CI's subset (.ci/run): every test but the slow label's (so every unit
# test, the fuzz corpora's replays and the integration label), plus this
# one whole daemon run; the full suite under the sanitizers would take CI
# past its time (docs/development.md "CI's arithmetic").
SANITIZE_CI_WHOLE_RUN := ^FullCalibration.LargeRobotSequentialReachesTheTargetWithFewerWaypoints$$
.PHONY: sanitize-build sanitize-ci
sanitize-build: deps peer-deps
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE= "-DCMAKE_CXX_FLAGS=-O1 -g1" "-DCMAKE_C_FLAGS=-O1 -g1" \
	  -DCDPR_WERROR=ON -DCDPR_SANITIZE=ON
	cmake --build $(SANITIZE_BUILD) -j $(JOBS) --target test_binaries

sanitize: sanitize-build
	cd $(SANITIZE_BUILD) && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS)

sanitize-ci: sanitize-build
	cd $(SANITIZE_BUILD) && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS) -LE '^slow$$'
	cd $(SANITIZE_BUILD) && $(SANITIZE_ENV) ctest --output-on-failure -R '$(SANITIZE_CI_WHOLE_RUN)'

# Every libFuzzer target (tests/fuzz) for FUZZ_SECONDS each, one after the
# other, from its seed corpus; prints execs, coverage and crashes per target.
# FUZZ_TARGETS=robot_toml,... picks some. Fails when a fuzzer finds a crash.
fuzz: deps
	@./tools/install-deps.sh $(FUZZ_PACKAGES)
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE= "-DCMAKE_CXX_FLAGS=-O1 -g" \
	  "-DCMAKE_C_FLAGS=-O1 -g" -DCDPR_WERROR=OFF -DCDPR_FUZZ=ON
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzzers
	./tests/fuzz/run_fuzzers.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(subst $(comma), ,$(FUZZ_TARGETS))

# The daemon against the virtual robot over real sockets, button via calibctl.
# Builds those three programs only. QUIRKS=rpm-units (or two-tpdo-encoder,
# rtr-bit30, no-type-255): the robot's CANopen nodes play that vendor quirk.
QUIRKS ?= none
demo: configure
	cmake --build $(BUILD) -j $(JOBS) --target cdpr-calibd virtual-robot calibctl
	DEMO_QUIRKS=$(QUIRKS) ./tools/demo.sh $(BUILD)

# The offline pipeline only: cdpr-sim, cdpr-calib solve, compare with truth.
demo-offline: configure
	cmake --build $(BUILD) -j $(JOBS) --target cdpr-sim cdpr-calib
	./tools/demo-offline.sh $(BUILD)

bench: bench-deps configure
	cmake -S . -B $(BUILD) -DCDPR_BENCH=ON
	cmake --build $(BUILD) -j $(JOBS) --target cdpr-bench
	$(BUILD)/tools/cdpr-bench

# The generated docs, rewritten from the code that owns them: the key
# listing of docs/configuration.md from the key tables, the model-term tables
# of docs/diagnosis.md and docs/DESIGN.md from solver/model/effects.h (unit
# tests hold the pages to them and say when to run this).
docs: configure
	cmake --build $(BUILD) -j $(JOBS) --target daemon_tests
	CDPR_UPDATE_DOCS=1 $(BUILD)/tests/daemon_tests --gtest_filter='ConfigTable.TheDocsPage*'
	cmake --build $(BUILD) -j $(JOBS) --target solver_model_tests
	CDPR_UPDATE_DOCS=1 $(BUILD)/tests/solver_model_tests --gtest_filter='EffectCatalogue.TheDocs*'

# The unit installed with the daemon names it under $(PREFIX) (systemd/CMakeLists.txt).
install: all
	cmake --install $(BUILD) --prefix $(PREFIX)

# $(BUILD)/cdpr-calibration_<version>_<arch>.deb (tools/make-deb.sh, packaging/deb/).
deb: all
	cmake --build $(BUILD) --target deb

clean:
	rm -rf $(BUILD)
