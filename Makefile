# fogvol.h - tests, demo and examples. The library itself is fogvol.h alone.
#   make check  the fast inner loop (CPU, null backend, GL smoke tests, README blocks: < 1 min)
#   make test   build and run every test (installs missing Debian packages)
#   make demo   render the headless demo into build/demo/*.png
#   make images refresh the README pictures in docs/ from the demo
#   make run    the interactive GLFW demo (under Xvfb with a screenshot when there is no display)
#   make bench  the benchmark (bench/RESULTS.md, bench/plot.png)
#   make web    the browser demo (emscripten, WebGL1 + WebGL2) into build/web/demo_web.html
#   make test-web  load it in headless Chromium (software GL) and check the pictures
CC      ?= cc
BUILD   ?= build
WARN     = -Wall -Wextra -pedantic -Werror
CFLAGS  ?= -O2 -g
SAN      = -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
INC      = -I.
GL_LIBS  = -lOSMesa -lm
LSAN_ENV = ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
           UBSAN_OPTIONS=print_stacktrace=1
TAP      = CMOCKA_MESSAGE_OUTPUT=TAP
VALGRIND = valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite
FUZZ_TIME ?= 60
EMCC     ?= emcc
CHROMIUM ?= chromium

HEADERS  = fogvol.h tests/gl_util.h tests/shapes.h tests/raycast.h

.PHONY: all check test demo images fuzz run examples bench bench-quick bench-analytic deps-test deps-demo deps-run clean \
        web test-web deps-web

all: test

deps-test:
	@tools/deps.sh test
deps-demo:
	@tools/deps.sh demo
deps-run:
	@tools/deps.sh run
deps-web:
	@tools/deps.sh web

$(BUILD):
	@mkdir -p $(BUILD)

# --- test programs: plain and under ASan+UBSan ---------------------------------
$(BUILD)/test_cpu: tests/test_cpu.c fogvol.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka -lm
$(BUILD)/test_cpu_cpp: tests/test_cpu.c fogvol.h | $(BUILD)
	$(CXX) -x c++ -std=c++11 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka -lm
$(BUILD)/test_cpu_san: tests/test_cpu.c fogvol.h | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka -lm
$(BUILD)/test_raycast: tests/test_raycast_selftest.c tests/raycast.h tests/shapes.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) -Itests $< -o $@ -lm
$(BUILD)/test_render: tests/test_render.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_render_san: tests/test_render.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_speedups: tests/test_speedups.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_speedups_san: tests/test_speedups.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_glstate: tests/test_glstate.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_glstate_san: tests/test_glstate.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_fb: tests/test_engine_fb.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_fb_san: tests/test_engine_fb.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_tiers: tests/test_tiers.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_tiers_san: tests/test_tiers.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_overflow: tests/test_overflow.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_overflow_san: tests/test_overflow.c tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_backend: tests/test_backend.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_backend_san: tests/test_backend.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_msaa: tests/test_engine_msaa.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 -D_POSIX_C_SOURCE=200809L $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_msaa_san: tests/test_engine_msaa.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 -D_POSIX_C_SOURCE=200809L $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_depth: tests/test_engine_depth.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_depth_san: tests/test_engine_depth.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_input: tests/test_engine_input.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_engine_input_san: tests/test_engine_input.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
# OpenGL ES through Mesa's EGL surfaceless platform: -lEGL -lGLESv2, no OSMesa
GLES_LIBS = -lEGL -lGLESv2 -lm
$(BUILD)/test_gles: tests/test_gles.c tests/egl_util.h tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GLES_LIBS)
$(BUILD)/test_gles_san: tests/test_gles.c tests/egl_util.h tests/scenes.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GLES_LIBS)
$(BUILD)/test_post: tests/test_post.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_post_san: tests/test_post.c $(HEADERS) | $(BUILD)
$(BUILD)/test_texlight: tests/test_texlight.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_texlight_san: tests/test_texlight.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_cpu_vg: tests/test_cpu.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -O1 -g $(WARN) $(INC) $< -o $@ -lcmocka -lm
$(BUILD)/replay_mesh: tests/fuzz/replay.c tests/fuzz/fuzz_mesh.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -D_DEFAULT_SOURCE -O1 -g $(WARN) $(INC) tests/fuzz/replay.c tests/fuzz/fuzz_mesh.c -o $@ -lm
$(BUILD)/fuzz_mesh: tests/fuzz/fuzz_mesh.c fogvol.h | $(BUILD)
	clang -g -O1 -fsanitize=fuzzer,address,undefined $(INC) $< -o $@ -lm
$(BUILD)/replay_analytic: tests/fuzz/replay.c tests/fuzz/fuzz_analytic.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -D_DEFAULT_SOURCE -O1 -g $(WARN) $(INC) tests/fuzz/replay.c tests/fuzz/fuzz_analytic.c -o $@ -lm
$(BUILD)/fuzz_analytic: tests/fuzz/fuzz_analytic.c fogvol.h | $(BUILD)
	clang -g -O1 -fsanitize=fuzzer,address,undefined $(INC) $< -o $@ -lm
$(BUILD)/test_analytic: tests/test_analytic.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/test_analytic_san: tests/test_analytic.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) $< -o $@ -lcmocka $(GL_LIBS)
$(BUILD)/dump_shaders: tests/dump_shaders.c fogvol.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lm

TEST_BINS = $(BUILD)/test_cpu $(BUILD)/test_cpu_cpp $(BUILD)/test_cpu_san $(BUILD)/test_raycast \
            $(BUILD)/test_render $(BUILD)/test_render_san $(BUILD)/test_speedups $(BUILD)/test_speedups_san $(BUILD)/test_glstate $(BUILD)/test_glstate_san \
            $(BUILD)/test_engine_fb $(BUILD)/test_engine_fb_san \
            $(BUILD)/test_tiers $(BUILD)/test_tiers_san $(BUILD)/test_backend $(BUILD)/test_backend_san \
            $(BUILD)/test_engine_input $(BUILD)/test_engine_input_san \
            $(BUILD)/test_overflow $(BUILD)/test_overflow_san \
            $(BUILD)/dump_shaders $(BUILD)/test_cpu_vg $(BUILD)/replay_mesh $(BUILD)/fuzz_mesh \
            $(BUILD)/replay_analytic $(BUILD)/fuzz_analytic \
            $(BUILD)/demo_headless $(BUILD)/bench $(BUILD)/test_analytic $(BUILD)/test_analytic_san
TEST_BINS += $(BUILD)/test_engine_msaa $(BUILD)/test_engine_msaa_san
TEST_BINS += $(BUILD)/test_engine_depth $(BUILD)/test_engine_depth_san
TEST_BINS += $(BUILD)/test_gles $(BUILD)/test_gles_san
TEST_BINS += $(BUILD)/test_post $(BUILD)/test_post_san
# the browser test runs in make test when emscripten and chromium are installed (tools/deps.sh web)
HAVE_WEB := $(shell command -v $(EMCC) >/dev/null 2>&1 && command -v $(CHROMIUM) >/dev/null 2>&1 && echo 1)
ifeq ($(HAVE_WEB),1)
TEST_BINS += $(BUILD)/web/demo_web.html
WEB_TEST = "web=BUILD=$(BUILD) CHROMIUM=$(CHROMIUM) tests/web_test.sh"
endif
TEST_BINS += $(BUILD)/test_texlight $(BUILD)/test_texlight_san

# the fast inner loop (under a minute on two cores): CPU tests (encoding, dither, textures, mesh
# validation), the renderer on the null backend plus the GL backend smoke tests, the README's code blocks
check: deps-test
	@$(MAKE) --no-print-directory -j2 $(BUILD)/test_cpu $(BUILD)/test_backend
	@LOGDIR=$(BUILD)/logs tests/run.sh "cpu=$(TAP) $(BUILD)/test_cpu" "backend=$(TAP) $(BUILD)/test_backend" \
	  "readme_blocks=BUILD=$(BUILD) tests/readme_blocks.sh"

test: deps-test deps-run
	@$(MAKE) --no-print-directory $(TEST_BINS)
	@LOGDIR=$(BUILD)/logs tests/run.sh \
	  "compile_matrix=BUILD=$(BUILD) tests/compile_matrix.sh" \
	  "demo_headless=$(BUILD)/demo_headless $(BUILD)/demo --check" \
	  "examples=BUILD=$(BUILD) CC=$(CC) tests/examples.sh" \
	  "bench_quick=$(BUILD)/bench --quick" \
	  "analytic=BUILD=$(BUILD) $(TAP) $(BUILD)/test_analytic" \
	  "analytic_asan_ubsan=BUILD=$(BUILD) $(TAP) $(LSAN_ENV) $(BUILD)/test_analytic_san" \
	  "shaders=BUILD=$(BUILD) tests/shaders.sh" \
	  "readme_blocks=BUILD=$(BUILD) tests/readme_blocks.sh" \
	  "cpu=$(TAP) $(BUILD)/test_cpu" \
	  "cpu_cxx=$(TAP) $(BUILD)/test_cpu_cpp" \
	  "cpu_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_cpu_san" \
	  "raycast_selftest=$(BUILD)/test_raycast" \
	  "render=$(TAP) $(BUILD)/test_render" \
	  "render_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_render_san" \
	  "speedups=$(TAP) $(BUILD)/test_speedups" \
	  "speedups_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_speedups_san" \
	  "glstate=$(TAP) $(BUILD)/test_glstate" \
	  "glstate_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_glstate_san" \
	  "engine_fb=$(TAP) $(BUILD)/test_engine_fb" \
	  "engine_fb_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_engine_fb_san" \
	  "tiers=$(TAP) $(BUILD)/test_tiers" \
	  "tiers_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_tiers_san" \
	  "backend=$(TAP) $(BUILD)/test_backend" \
	  "backend_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_backend_san" \
	  "engine_msaa=$(TAP) $(BUILD)/test_engine_msaa" \
	  "engine_msaa_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_engine_msaa_san" \
	  "engine_depth=$(TAP) $(BUILD)/test_engine_depth" \
	  "engine_depth_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_engine_depth_san" \
	  "engine_input=$(TAP) $(BUILD)/test_engine_input" \
	  "engine_input_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_engine_input_san" \
	  "overflow=$(TAP) $(BUILD)/test_overflow" \
	  "texlight=$(TAP) $(BUILD)/test_texlight" \
	  "texlight_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_texlight_san" \
	  "overflow_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_overflow_san" \
	  "gles=$(TAP) $(BUILD)/test_gles" \
	  "gles_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_gles_san" \
	  "post=$(TAP) $(BUILD)/test_post" \
	  "post_asan_ubsan=$(TAP) $(LSAN_ENV) $(BUILD)/test_post_san" \
	  "cpu_valgrind=$(TAP) $(VALGRIND) $(BUILD)/test_cpu_vg" \
	  "fuzz_corpus_valgrind=$(VALGRIND) $(BUILD)/replay_mesh tests/fuzz/corpus_mesh" \
	  "fuzz_mesh_5s=mkdir -p $(BUILD)/fuzz/mesh && $(BUILD)/fuzz_mesh -max_total_time=5 $(BUILD)/fuzz/mesh tests/fuzz/corpus_mesh" \
	  "fuzz_analytic_corpus_valgrind=$(VALGRIND) $(BUILD)/replay_analytic tests/fuzz/corpus_analytic" \
	  "fuzz_analytic_5s=mkdir -p $(BUILD)/fuzz/analytic && $(BUILD)/fuzz_analytic -max_total_time=5 $(BUILD)/fuzz/analytic tests/fuzz/corpus_analytic" \
	  $(WEB_TEST)

# --- demo --------------------------------------------------------------------------
$(BUILD)/demo_headless: examples/demo_headless.c examples/demo_scene.h $(HEADERS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ $(GL_LIBS)

demo: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/demo_headless
	@$(BUILD)/demo_headless $(BUILD)/demo

$(BUILD)/demo_glfw: examples/demo_glfw.c examples/demo_scene.h fogvol.h tests/shapes.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ -lglfw -lGL -lm

# the interactive demo; without a display: 120 frames under Xvfb into $(BUILD)/demo_glfw.png
run: deps-run
	@$(MAKE) --no-print-directory $(BUILD)/demo_glfw
	@if [ -n "$$DISPLAY" ]; then $(BUILD)/demo_glfw; \
	else echo "no DISPLAY: rendering under Xvfb into $(BUILD)/demo_glfw.png"; \
	  xvfb-run -a $(BUILD)/demo_glfw --frames 120 --screenshot $(BUILD)/demo_glfw.png; fi

# the examples alone: build, run headless / under Xvfb, check, package consumers
examples: deps-demo deps-run
	@LOGDIR=$(BUILD)/logs tests/run.sh "examples=BUILD=$(BUILD) CC=$(CC) tests/examples.sh"

$(BUILD)/bench: bench/bench.c $(HEADERS) | $(BUILD)
	$(CC) -std=c99 -O2 $(WARN) $(INC) $< -o $@ $(GL_LIBS)

# full run, 4-5 min: writes bench/RESULTS.md and bench/plot.png (ratios taken in one run)
bench: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/bench
	$(BUILD)/bench

# smoke test (smallest scene, a few frames), also part of make test
bench-quick: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/bench
	$(BUILD)/bench --quick

$(BUILD)/bench_analytic: bench/bench_analytic.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -O2 $(WARN) $(INC) $< -o $@ -lm

# analytic fog: vertex x volume evaluations per second, batch against a scalar loop
bench-analytic: $(BUILD)/bench_analytic
	$(BUILD)/bench_analytic

# libFuzzer on mesh validation and the analytic fog input, FUZZ_TIME seconds per target; new inputs go to
# build/fuzz (merge them into tests/fuzz/corpus_* with -merge=1 when they matter)
fuzz: deps-test $(BUILD)/fuzz_mesh $(BUILD)/fuzz_analytic
	@mkdir -p $(BUILD)/fuzz/mesh $(BUILD)/fuzz/analytic
	$(BUILD)/fuzz_mesh -max_total_time=$(FUZZ_TIME) -print_final_stats=1 $(BUILD)/fuzz/mesh tests/fuzz/corpus_mesh
	$(BUILD)/fuzz_analytic -max_total_time=$(FUZZ_TIME) -print_final_stats=1 $(BUILD)/fuzz/analytic \
	  tests/fuzz/corpus_analytic

# the README pictures, regenerated from the demo
images: demo
	@mkdir -p docs
	cp $(BUILD)/demo/scene_overview.png docs/demo_overview.png
	cp $(BUILD)/demo/scene_low.png docs/demo_low.png
	cp $(BUILD)/demo/scene_inside_fog_bank.png docs/demo_inside_fog_bank.png
	cp $(BUILD)/demo/tiers.png $(BUILD)/demo/dither.png $(BUILD)/demo/ramps.png $(BUILD)/demo/thickness.png docs/

# --- browser build: emscripten (Debian's emcc ships its system libraries prebuilt), one page for
# WebGL1 (?webgl1) and WebGL2 (?webgl2, the default), the wasm embedded so it loads from file://.
# NODE_PATH: Debian's emscripten finds its node modules (acorn) there even under a node from elsewhere
WEB_FLAGS = -std=c99 -O2 $(WARN) $(INC) -I/usr/include/stb -sMIN_WEBGL_VERSION=1 -sMAX_WEBGL_VERSION=2 \
            -sSINGLE_FILE=1 -sWASM_ASYNC_COMPILATION=0 -sALLOW_MEMORY_GROWTH=1 -sMINIFY_HTML=0
$(BUILD)/web/demo_web.html: examples/web/demo_web.c examples/web/shell.html fogvol.h tests/raycast.h tests/shapes.h
	@mkdir -p $(BUILD)/web
	NODE_PATH=/usr/share/nodejs $(EMCC) $(WEB_FLAGS) $< --shell-file examples/web/shell.html -o $@

web: deps-web
	@$(MAKE) --no-print-directory $(BUILD)/web/demo_web.html
	@echo "open $(BUILD)/web/demo_web.html?webgl1 or ?webgl2 in a browser"

test-web: deps-web
	@$(MAKE) --no-print-directory $(BUILD)/web/demo_web.html
	@LOGDIR=$(BUILD)/logs tests/run.sh "web=BUILD=$(BUILD) CHROMIUM=$(CHROMIUM) tests/web_test.sh"

clean:
	rm -rf $(BUILD)
