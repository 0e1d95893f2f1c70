# tailor: the two commands a new user types are `make run` and `make test`.
# Everything else is here for developers. All targets install missing packages first (make deps).

MAKEFLAGS += --no-print-directory
BUILD_DIR ?= build
JOBS ?= 2
CMAKE_FLAGS ?=
EXAMPLE_MESH := examples/spot.obj
EXAMPLE_TEXTURE := examples/gravel.png
PREFIX ?= /usr/local

.PHONY: all deps deps-blender configure build test run install bench fuzz tsan lsan format clean blender-addon

all: build

deps:
	@bash scripts/deps.sh

# Blender (Debian's, ~400 MB with its libraries): only for the add-on's test and its pictures.
deps-blender:
	@TAILOR_BLENDER=1 bash scripts/deps.sh

# Compiles through ccache when it is there (make deps installs it): a rebuild after a pull, and
# tests/install_test.sh's shared-library build of the same sources, come from its cache
# (~/.cache/ccache). Its base directory is the build folder: paths in it are hashed relative to
# where the compiler runs, so the shared build beneath it (unity sources in its own folder) finds
# the objects. CMAKE_FLAGS="-DCMAKE_CXX_COMPILER_LAUNCHER=" configures without it (each make
# configures again: give it every time).
configure: deps
	@cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release $$(command -v ccache >/dev/null && \
	   echo "-DCMAKE_CXX_COMPILER_LAUNCHER=env;CCACHE_BASEDIR=$(abspath $(BUILD_DIR));ccache" || \
	   echo "-DCMAKE_CXX_COMPILER_LAUNCHER=") $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# Unit, integration, CLI and browser tests (ctest runs them all), then short fuzz runs.
test: build
	@bash scripts/check_format.sh
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
	@bash scripts/fuzz.sh short

# The main job on the bundled example: textured .glb, preview pictures and stats in out/. Builds
# only the tailor command (`make build` and `make test` build the tests, benchmarks and tools too).
run: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target tailor
	@mkdir -p out
	@$(BUILD_DIR)/tailor tile $(EXAMPLE_TEXTURE) -o out/gravel_tile.png
	@$(BUILD_DIR)/tailor map $(EXAMPLE_MESH) --texture out/gravel_tile.png -o out/example.glb \
	   --stats out/example_stats.json --preview out/example_preview.png --preview-all
	@echo "open it in a browser: $(BUILD_DIR)/tailor view out/example.glb"

# The tailor command, its web viewer, and the C++ libraries with their headers, CMake package and
# pkg-config file, under PREFIX (default /usr/local); DESTDIR=/stage prefixes every path (packaging).
install: build
	@DESTDIR="$(DESTDIR)" cmake --install $(BUILD_DIR) --prefix "$(PREFIX)"

# The Blender add-on as a zip (Edit > Preferences > Add-ons > Install...), with the Python module.
blender-addon: build
	@bash scripts/blender_addon.sh $(BUILD_DIR) out/tailor_addon.zip

bench: build
	@bash scripts/bench.sh $(BUILD_DIR)

fuzz: deps
	@bash scripts/fuzz.sh long

# The threaded stages (crack closing, metrics, orientation) under ThreadSanitizer: their
# thread-count tests, and the closing on real meshes with 4 threads.
tsan: deps
	@bash scripts/tsan.sh

# The preview renderer (OSMesa) under LeakSanitizer: render_test in build-lsan (docs/hardening.md).
lsan: deps
	@bash scripts/lsan.sh

# Rewrite the C++ sources as .clang-format says (make test fails on unformatted files).
format: deps
	@bash scripts/check_format.sh --fix

clean:
	rm -rf $(BUILD_DIR) build-fuzz build-tsan build-lsan out
