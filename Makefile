# fogvol.h - tests, demo and examples. The library itself is fogvol.h alone.
#   make check  the fast inner loop (CPU, null backend, GL smoke tests, README blocks: < 1 min)
#   make test   build and run every test (installs missing Debian packages)
#   make demo   render the headless demo into build/demo/*.png
#   make images refresh the README pictures in docs/ from the demo
#   make run    the interactive GLFW demo (under Xvfb with a screenshot when there is no display)
#   make bench  the benchmark (bench/RESULTS.md, bench/plot.png)
#   make docs   rewrite the figures in README.md and docs/*.md (tests/doc_figures.sh checks them)
#   make bench-large  the GPU-scale scenes on this machine (bench/RESULTS-large.md)
#   on a machine with a GPU driver (EGL): make gpu-test, make gl-compile, make bench-egl
#   make web    the browser demo (emscripten, WebGL1 + WebGL2: the courtyard to fly through) into build/web/demo_web.html
#   make vulkan the Vulkan example (examples/vulkan_backend.c, lavapipe) into build/vulkan/*.png
# Adding a test program: one name in TESTS (see "test programs" below). JOBS=n sets how many
# compilers and tests run at once (default: the number of cores).
CC      ?= cc
BUILD   ?= build
WARN     = -Wall -Wextra -pedantic -Werror
CFLAGS  ?= -O2 -g
SAN      = -O1 -g1 -fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer -fno-sanitize-recover=all
# (-g1: line tables for the sanitizers' stack traces; gcc builds fogvol.h under them 30% faster than with -g)
INC      = -I.
GL_LIBS  = -lOSMesa -lm
LSAN_ENV = ASAN_OPTIONS=detect_leaks=1:malloc_context_size=8 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
           UBSAN_OPTIONS=print_stacktrace=1
TAP      = CMOCKA_MESSAGE_OUTPUT=TAP
VALGRIND = valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite
FUZZ_TIME ?= 60
EMCC     ?= emcc
CHROMIUM ?= chromium

.PHONY: all check test docs demo images fuzz run examples bench bench-egl bench-large proto-engine-depth proto-msaa gl-compile gpu-test bench-quick bench-analytic deps-test deps-demo deps-run clean \
        web test-web deps-web vulkan vulkan-bench

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

# --- test programs ---------------------------------------------------------------------
# Adding a test program is one line:
#   - a cmocka program tests/test_NAME.c (including fogvol.h through tests/fogvol_test.h): add NAME
#     to TESTS. The rules below build $(BUILD)/test_NAME (C99) and $(BUILD)/test_NAME_san
#     (ASan+UBSan), linked with fogvol's implementation built once per flag set; both go into TEST_BINS and
#     `make test` runs them as NAME and NAME_asan_ubsan (TAP). It links -lcmocka $(GL_LIBS) unless
#     you set test_NAME_LIBS (e.g. test_gles_LIBS = -lcmocka -lEGL -lGLESv2 -lm); extra compile
#     flags: test_NAME_FLAGS. Add NAME to CXX_TESTS as well for a C++11 build (test_NAME_cpp, run
#     as NAME_cxx).
#   - a script or any other command: add "name=command" to SCRIPT_RUNS (and the programs it needs
#     to TEST_BINS).
#   CMakeLists.txt reads TESTS, test_NAME_LIBS and test_NAME_FLAGS from here for ctest (keep those
#   assignments on one line each).
# tests/run.sh runs everything $(JOBS) at a time and prints the logs in list order, then the one
# summary line "N passed, M failed". Slow entries first: they start first.
TESTS     = tiers render analytic gles texlight speedups backend engine_fb glstate engine_input overflow engine_msaa engine_depth colors post looks limits cpu
CXX_TESTS = cpu
JOBS     ?= $(shell nproc 2> /dev/null || echo 2)

TEST_DEPS = fogvol.h $(wildcard tests/*.h)
TEST_LIBS = -lcmocka $(GL_LIBS)
test_cpu_LIBS          = -lcmocka -lm
test_gles_LIBS         = -lcmocka -lEGL -lGLESv2 -lm
test_engine_msaa_FLAGS = -D_POSIX_C_SOURCE=200809L
dump_shaders_LIBS      = -lm
gl_compile_LIBS        = -lEGL -lm
libs_of = $(or $($(1)_LIBS),$(TEST_LIBS))

$(BUILD)/%: tests/%.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $($*_FLAGS) $(CFLAGS) $(WARN) $(INC) $< -o $@ $(call libs_of,$*)
$(BUILD)/%_san: tests/%.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $($*_FLAGS) $(SAN) $(WARN) $(INC) $< -o $@ $(call libs_of,$*)
# test_backend and test_post keep fogvol's implementation inline (they read its internal tables and
# state): both their builds at -O0, as they run for seconds and gcc compiles fogvol.h 3-4x faster so
INLINE_TESTS = backend post
$(foreach t,$(INLINE_TESTS),$(BUILD)/test_$(t)): $(BUILD)/test_%: tests/test_%.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $(test_$*_FLAGS) $(subst -O2,-O0,$(CFLAGS)) $(WARN) $(INC) $< -o $@ $(call libs_of,test_$*)
$(foreach t,$(INLINE_TESTS),$(BUILD)/test_$(t)_san): $(BUILD)/test_%_san: tests/test_%.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $(test_$*_FLAGS) $(subst -O1,-O0,$(SAN)) $(WARN) $(INC) $< -o $@ $(call libs_of,test_$*)

# The cmocka programs but test_backend and test_post (INLINE_TESTS above) link fogvol's implementation
# built once per flag set (tests/fogvol_impl.c; tests/fogvol_test.h leaves it out with
# FOGVOL_TEST_LINKED): the implementation is compiled twice per build instead of twice per program.
# test_cpu's C++ and valgrind builds keep it inline, built with FOGVOL_NO_GL (and the compile matrix
# builds FOGVOL_NO_GL with every compiler).
LINKED_TESTS = $(filter-out $(INLINE_TESTS),$(TESTS))
$(BUILD)/fogvol_impl.o: tests/fogvol_impl.c fogvol.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) -c $< -o $@
$(BUILD)/fogvol_impl_san.o: tests/fogvol_impl.c fogvol.h | $(BUILD)
	$(CC) -std=c99 $(SAN) $(WARN) $(INC) -c $< -o $@
$(foreach t,$(LINKED_TESTS),$(BUILD)/test_$(t)): $(BUILD)/test_%: tests/test_%.c $(TEST_DEPS) $(BUILD)/fogvol_impl.o
	$(CC) -std=c99 -DFOGVOL_TEST_LINKED $(test_$*_FLAGS) $(CFLAGS) $(WARN) $(INC) $< $(BUILD)/fogvol_impl.o -o $@ \
	  $(call libs_of,test_$*)
$(foreach t,$(LINKED_TESTS),$(BUILD)/test_$(t)_san): $(BUILD)/test_%_san: tests/test_%.c $(TEST_DEPS) \
	  $(BUILD)/fogvol_impl_san.o
	$(CC) -std=c99 -DFOGVOL_TEST_LINKED $(test_$*_FLAGS) $(SAN) $(WARN) $(INC) $< $(BUILD)/fogvol_impl_san.o -o $@ \
	  $(call libs_of,test_$*)
$(BUILD)/%_cpp: tests/%.c $(TEST_DEPS) | $(BUILD)
	$(CXX) -x c++ -std=c++11 $($*_FLAGS) $(subst -O2,-O0,$(CFLAGS)) $(WARN) $(INC) $< -o $@ $(call libs_of,$*)
$(BUILD)/%_vg: tests/%.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $($*_FLAGS) -O1 -g $(WARN) $(INC) $< -o $@ $(call libs_of,$*)

$(BUILD)/test_raycast: tests/test_raycast_selftest.c tests/raycast.h tests/shapes.h | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) -Itests $< -o $@ -lm
$(BUILD)/test_raycast_san: tests/test_raycast_selftest.c tests/raycast.h tests/shapes.h | $(BUILD)
	$(CC) -std=c99 -DRC_SANITIZE $(SAN) $(WARN) $(INC) -Itests $< -o $@ -lm
$(BUILD)/replay_%: tests/fuzz/replay.c tests/fuzz/fuzz_%.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -D_DEFAULT_SOURCE -O1 -g $(WARN) $(INC) tests/fuzz/replay.c tests/fuzz/fuzz_$*.c -o $@ -lm
# The three libFuzzer targets (ASan, UBSan with float-cast-overflow) link fogvol's implementation built
# once with the fuzzer's coverage (fuzz_impl.o; the GL backend in it reaches GL through pointers only):
# -O1 for make fuzz; make test's 5-second smoke runs build them at -O0 in $(BUILD)/smoke (clang compiles
# fogvol.h under the sanitizers 3x faster so).
FUZZ_SAN = -g -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all
fuzz_opt = $(if $(findstring /smoke/,$@),-O0,-O1)
FUZZ_LINK = clang $(FUZZ_SAN) $(fuzz_opt) -fsanitize=fuzzer -DFOGVOL_TEST_LINKED $(INC) $< $(@D)/fuzz_impl.o -o $@ \
            -lOSMesa -lm
$(BUILD)/fuzz_impl.o $(BUILD)/smoke/fuzz_impl.o: tests/fogvol_impl.c fogvol.h
	@mkdir -p $(@D)
	clang $(FUZZ_SAN) $(fuzz_opt) -fsanitize=fuzzer-no-link $(INC) -c $< -o $@
# API sequences on the null and the GL backend (OSMesa): libFuzzer, and its corpus replayed by the
# sanitizer build of the tests (linked with fogvol_impl_san.o; GL under valgrind would take minutes).
# make test's short run starts from the seeds (tests/fuzz/seed_api.py writes them; loading the whole
# corpus into libFuzzer takes a minute), make fuzz from the corpus.
FUZZ_API_DEPS = tests/fuzz/fuzz_api.c fogvol.h tests/gl_util.h tests/shapes.h
$(BUILD)/fuzz_api: $(FUZZ_API_DEPS) $(BUILD)/fuzz_impl.o
	$(FUZZ_LINK)
$(BUILD)/smoke/fuzz_api: $(FUZZ_API_DEPS) $(BUILD)/smoke/fuzz_impl.o
	$(FUZZ_LINK)
$(BUILD)/fuzz_%: tests/fuzz/fuzz_%.c $(BUILD)/fuzz_impl.o
	$(FUZZ_LINK)
$(BUILD)/smoke/fuzz_%: tests/fuzz/fuzz_%.c $(BUILD)/smoke/fuzz_impl.o
	$(FUZZ_LINK)
$(BUILD)/replay_api_san: tests/fuzz/replay.c $(FUZZ_API_DEPS) $(BUILD)/fogvol_impl_san.o | $(BUILD)
	$(CC) -std=c99 -D_DEFAULT_SOURCE -DFOGVOL_TEST_LINKED $(SAN) $(WARN) $(INC) tests/fuzz/replay.c tests/fuzz/fuzz_api.c \
	  $(BUILD)/fogvol_impl_san.o -o $@ -lOSMesa -lm

TEST_BINS = $(foreach t,$(TESTS),$(BUILD)/test_$(t) $(BUILD)/test_$(t)_san) \
            $(foreach t,$(CXX_TESTS),$(BUILD)/test_$(t)_cpp) \
            $(BUILD)/test_raycast $(BUILD)/test_raycast_san $(BUILD)/test_cpu_vg $(BUILD)/dump_shaders \
            $(BUILD)/replay_mesh $(BUILD)/fuzz_mesh $(BUILD)/replay_analytic $(BUILD)/fuzz_analytic \
            $(BUILD)/replay_api_san $(BUILD)/fuzz_api \
            $(BUILD)/demo_headless $(BUILD)/bench $(BUILD)/bench_egl $(BUILD)/proto_engine_depth $(BUILD)/proto_msaa $(BUILD)/gl_compile \
            $(BUILD)/egl/demo_headless \
            $(BUILD)/vulkan_backend

# every shader dump_shaders writes, compiled and linked by an EGL driver (Mesa's llvmpipe here;
# make gl-compile on a machine with a GPU driver)
GL_COMPILE = mkdir -p $(BUILD)/shaders_gl && rm -f $(BUILD)/shaders_gl/*.vert $(BUILD)/shaders_gl/*.frag && \
             $(BUILD)/dump_shaders $(BUILD)/shaders_gl > /dev/null && $(BUILD)/gl_compile $(BUILD)/shaders_gl

# an entry of make test builds its own programs first: $(call built,PROGRAMS) COMMAND
BUILT = $(MAKE) --no-print-directory -s
built = $(BUILT) $(1) &&

# name=command lines for tests/run.sh, besides the cmocka programs
SCRIPT_RUNS = \
  "vulkan_shaders=BUILD=$(BUILD) tests/vulkan_shaders.sh" \
  "vulkan_check=$(VK_ENV) $(BUILD)/vulkan_backend --check" \
  $(foreach t,$(VULKAN_PICTURES),"vulkan_picture_$(t)=$(call VULKAN_PICTURE,$(t))") \
  "examples=BUILD=$(BUILD) CC=$(CC) BUILT_ELSEWHERE=demo_headless tests/examples.sh examples" \
  "examples_package=BUILD=$(BUILD) CC=$(CC) tests/examples.sh package" \
  $(foreach c,gcc clang g++ clang++,"compile_matrix_$(c)=BUILD=$(BUILD) tests/compile_matrix.sh $(c)") \
  "shaders=BUILD=$(BUILD) tests/shaders.sh" \
  "gl_compile=$(call built,$(BUILD)/gl_compile) $(GL_COMPILE)" \
  "readme_blocks=BUILD=$(BUILD) tests/readme_blocks.sh" \
  "doc_index=tests/doc_index.sh" \
  "doc_figures=$(call built,$(BUILD)/dump_shaders) BUILD=$(BUILD) tests/doc_figures.sh --no-tiers" \
  "demo_headless=$(call built,$(BUILD)/demo_headless) $(BUILD)/demo_headless $(BUILD)/demo --check" \
  "bench_quick=$(BUILT) BUILD=$(BUILD)/quick BENCH_OPT=-O1 $(BUILD)/quick/bench && $(BUILD)/quick/bench --quick" \
  "egl_builds=$(BUILT) BUILD=$(BUILD)/egl_check CFLAGS=-O0 BENCH_OPT=-O0 $(BUILD)/egl_check/bench_egl \
    $(BUILD)/egl_check/egl/demo_headless && $(foreach t,$(EGL_TESTS),$(CC) -std=c99 -DGLU_EGL -fsyntax-only \
    $(test_$(t)_FLAGS) $(WARN) $(INC) tests/test_$(t).c && ) $(foreach p,proto_engine_depth proto_msaa,$(CC) -std=c99 \
    -fsyntax-only $(WARN) $(INC) bench/$(p).c && ) true" \
  "raycast_selftest=$(call built,$(BUILD)/test_raycast) $(BUILD)/test_raycast" \
  "raycast_selftest_asan_ubsan=$(call built,$(BUILD)/test_raycast_san) $(LSAN_ENV) $(BUILD)/test_raycast_san" \
  "cpu_valgrind=$(call built,$(BUILD)/test_cpu_vg) $(TAP) FOGVOL_TEST_SUBSET=1 $(VALGRIND) $(BUILD)/test_cpu_vg" \
  "fuzz_corpus_valgrind=$(call built,$(BUILD)/replay_mesh) $(VALGRIND) $(BUILD)/replay_mesh tests/fuzz/corpus_mesh" \
  "fuzz_mesh_5s=$(call built,$(BUILD)/smoke/fuzz_mesh) mkdir -p $(BUILD)/fuzz/mesh && \
    $(BUILD)/smoke/fuzz_mesh -max_total_time=5 $(BUILD)/fuzz/mesh tests/fuzz/corpus_mesh" \
  "fuzz_analytic_corpus_valgrind=$(call built,$(BUILD)/replay_analytic) $(VALGRIND) $(BUILD)/replay_analytic \
    tests/fuzz/corpus_analytic" \
  "fuzz_analytic_5s=$(call built,$(BUILD)/smoke/fuzz_analytic) mkdir -p $(BUILD)/fuzz/analytic && \
    $(BUILD)/smoke/fuzz_analytic -max_total_time=5 $(BUILD)/fuzz/analytic tests/fuzz/corpus_analytic" \
  "fuzz_api_corpus_asan_ubsan=$(call built,$(BUILD)/replay_api_san) $(LSAN_ENV) $(BUILD)/replay_api_san \
    tests/fuzz/corpus_api" \
  "fuzz_api_5s=$(call built,$(BUILD)/smoke/fuzz_api) rm -rf $(BUILD)/fuzz/api5 && mkdir -p $(BUILD)/fuzz/api5 && \
    $(LSAN_ENV) $(BUILD)/smoke/fuzz_api -max_total_time=5 -detect_leaks=0 $(BUILD)/fuzz/api5 tests/fuzz/seeds_api"
# the browser test runs in make test when emscripten and chromium are installed (tools/deps.sh web)
HAVE_WEB := $(shell command -v $(EMCC) >/dev/null 2>&1 && command -v $(CHROMIUM) >/dev/null 2>&1 && echo 1)
ifeq ($(HAVE_WEB),1)
TEST_BINS += $(BUILD)/web/demo_web.html
SCRIPT_RUNS += "web=$(call built,$(BUILD)/web/demo_web.html) BUILD=$(BUILD) CHROMIUM=$(CHROMIUM) tests/web_test.sh"
endif
# the cmocka programs: plain, under ASan+UBSan (their files go to $(BUILD)/san so that the two can run
# at once), C++
# SAN_SUBSET: the programs whose sanitizer build runs a subset of their cases (FOGVOL_TEST_SUBSET=1), chosen
# so that the same lines of fogvol.h run as with every case (gcov); their plain build runs every case
SAN_SUBSET = tiers gles
TEST_RUNS = $(foreach t,$(TESTS),"$(t)=$(call built,$(BUILD)/test_$(t)) BUILD=$(BUILD) $(TAP) $(BUILD)/test_$(t)" \
              "$(t)_asan_ubsan=$(call built,$(BUILD)/test_$(t)_san) BUILD=$(BUILD)/san $(TAP) $(LSAN_ENV) \
                $(if $(filter $(t),$(SAN_SUBSET)),FOGVOL_TEST_SUBSET=1) $(BUILD)/test_$(t)_san") \
            $(foreach t,$(CXX_TESTS),"$(t)_cxx=$(call built,$(BUILD)/test_$(t)_cpp) $(TAP) $(BUILD)/test_$(t)_cpp")

# the fast inner loop (under a minute on two cores): CPU tests (encoding, dither, textures, mesh
# validation), the renderer on the null backend plus the GL backend smoke tests, the README's code blocks
# (each entry builds its program as it starts: the two compile at once, and the scripts run beside them)
check: deps-test | $(BUILD)
	@LOGDIR=$(BUILD)/logs JOBS=$(JOBS) tests/run.sh "backend=$(call built,$(BUILD)/test_backend) $(TAP) $(BUILD)/test_backend" \
	  "cpu=$(call built,$(BUILD)/test_cpu) $(TAP) $(BUILD)/test_cpu" "readme_blocks=BUILD=$(BUILD) tests/readme_blocks.sh" \
	  "doc_index=tests/doc_index.sh" "doc_figures=BUILD=$(BUILD) tests/doc_figures.sh --no-shaders"

# everything; the README's test command and CI. The objects and programs that several entries use
# (TEST_SHARED) are built first; every entry then builds its own programs (TEST_BINS) as it starts, so
# that compiling and testing overlap on the JOBS that tests/run.sh runs at once.
TEST_SHARED = $(BUILD)/fogvol_impl.o $(BUILD)/fogvol_impl_san.o $(BUILD)/smoke/fuzz_impl.o $(BUILD)/dump_shaders \
              $(BUILD)/vulkan_backend
test: deps-test deps-run
	@$(MAKE) --no-print-directory -j$(JOBS) $(TEST_SHARED)
	@LOGDIR=$(BUILD)/logs JOBS=$(JOBS) DURATIONS=tests/durations tests/run.sh $(SCRIPT_RUNS) $(TEST_RUNS)

# --- Vulkan ------------------------------------------------------------------------
# examples/vulkan_backend.c: an engine on Vulkan with fogvol's backend examples/fogvol_vulkan.h (GLSL of
# FOGVOL_GLSL_VULKAN compiled at run time by shaderc: Debian's static libraries, glslang and SPIRV-Tools
# with them) and, for its --check, the GL backend on OSMesa beside it. Mesa's lavapipe runs it
# (VK_ENV: the lavapipe ICD where it is installed, so the check's figures are the same on every machine).
VK_LIBS = -lvulkan -Wl,--start-group -l:libshaderc_combined.a -lglslang -lSPIRV -lMachineIndependent -lOSDependent \
          -lOGLCompiler -lGenericCodeGen -lglslang-default-resource-limits -l:libSPIRV-Tools-opt.a -l:libSPIRV-Tools.a \
          -Wl,--end-group -lstdc++ -lpthread
LVP_ICD := $(firstword $(wildcard /usr/share/vulkan/icd.d/lvp_icd.*.json))
VK_ENV   = $(if $(LVP_ICD),VK_ICD_FILENAMES=$(LVP_ICD) VK_DRIVER_FILES=$(LVP_ICD))
$(BUILD)/vulkan_backend: examples/vulkan_backend.c examples/fogvol_vulkan.h examples/vulkan_scene.h $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 -D_POSIX_C_SOURCE=200809L $(CFLAGS) $(WARN) $(INC) $< -o $@ $(VK_LIBS) $(GL_LIBS)

# the Vulkan pictures (FLOAT with the engine's depth, PS20, MRT), validation layers on; each fails on
# any validation message up to the end of the program (make test runs them too)
VULKAN_PICTURES = float ps20 mrt
VULKAN_PICTURE = mkdir -p $(BUILD)/vulkan && $(VK_ENV) $(BUILD)/vulkan_backend --tier $(1) $(BUILD)/vulkan/vulkan_$(1).png
vulkan: deps-test
	@$(MAKE) --no-print-directory $(BUILD)/vulkan_backend
	$(call VULKAN_PICTURE,float)
	$(call VULKAN_PICTURE,ps20)
	$(call VULKAN_PICTURE,mrt)

# milliseconds per frame: the Vulkan backend on lavapipe beside the GL backend on llvmpipe, same scene
vulkan-bench: deps-test
	@$(MAKE) --no-print-directory $(BUILD)/vulkan_backend
	$(VK_ENV) $(BUILD)/vulkan_backend --bench

# --- demo --------------------------------------------------------------------------
$(BUILD)/demo_headless: examples/demo_headless.c examples/demo_scene.h examples/example_gl.h $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $(CFLAGS) $(WARN) $(INC) $< -o $@ $(GL_LIBS)

demo: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/demo_headless
	@$(BUILD)/demo_headless $(BUILD)/demo

$(BUILD)/demo_glfw: examples/demo_glfw.c examples/demo_scene.h examples/example_gl.h $(TEST_DEPS) | $(BUILD)
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

$(BUILD)/bench: bench/bench.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $(BENCH_OPT) $(WARN) $(INC) $< -o $@ $(GL_LIBS)

# the FLOAT + engine depth face pass as fogvol draws it against a depth-tested design (issue 34), on
# the benchmark's scenes, outside the library: make proto-engine-depth
$(BUILD)/proto_engine_depth: bench/proto_engine_depth.c bench/bench.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 -O2 $(WARN) $(INC) $< -o $@ $(GL_LIBS)

proto-engine-depth: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/proto_engine_depth
	$(BUILD)/proto_engine_depth 15

# what MSAA 4x costs on this renderer against single-sample, designs outside the library: make proto-msaa
$(BUILD)/proto_msaa: bench/proto_msaa.c bench/bench.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 -O2 $(WARN) $(INC) $< -o $@ $(GL_LIBS)

proto-msaa: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/proto_msaa
	$(BUILD)/proto_msaa 9

# the same benchmark through EGL and libOpenGL (glvnd) instead of OSMesa, for a GPU driver:
# build/bench_egl writes bench/RESULTS-gpu.md and bench/plot-gpu.png, timed with GPU timestamps
# (make test's egl_builds entry builds it and the EGL demo with BENCH_OPT=-O0 CFLAGS=-O0 and compiles
# the EGL test programs and the bench prototypes with -fsyntax-only: make test runs none of them)
BENCH_OPT ?= -O2
$(BUILD)/bench_egl: bench/bench.c $(TEST_DEPS) | $(BUILD)
	$(CC) -std=c99 $(BENCH_OPT) $(WARN) -DGLU_EGL $(INC) $< -o $@ -lEGL -lOpenGL -lm

# the GL tests built on tests/gl_util.h's EGL contexts (-DGLU_EGL) instead of OSMesa, for a GPU
# driver: make gpu-test builds and runs them (on the EGL device FOGVOL_EGL_DEVICE, default 0), with
# test_gles (EGL's surfaceless platform, OpenGL ES) and the headless demo
EGL_TESTS = tiers render analytic texlight speedups backend engine_fb glstate engine_input overflow engine_msaa engine_depth colors post looks limits
$(BUILD)/egl/test_%: tests/test_%.c $(TEST_DEPS)
	@mkdir -p $(BUILD)/egl
	$(CC) -std=c99 -DGLU_EGL $(test_$*_FLAGS) $(CFLAGS) $(WARN) $(INC) $< -o $@ -lcmocka -lEGL -lOpenGL -lm

$(BUILD)/egl/demo_headless: examples/demo_headless.c examples/demo_scene.h examples/example_gl.h $(TEST_DEPS)
	@mkdir -p $(BUILD)/egl
	$(CC) -std=c99 -DGLU_EGL $(CFLAGS) $(WARN) $(INC) $< -o $@ -lEGL -lOpenGL -lm

gpu-test: deps-test
	@$(MAKE) --no-print-directory -j$(JOBS) $(foreach t,$(EGL_TESTS),$(BUILD)/egl/test_$(t)) $(BUILD)/egl/demo_headless \
	  $(BUILD)/test_gles
	@LOGDIR=$(BUILD)/logs_egl JOBS=1 tests/run.sh $(foreach t,$(EGL_TESTS),"$(t)=BUILD=$(BUILD) $(TAP) $(BUILD)/egl/test_$(t)") \
	  "gles=$(TAP) $(BUILD)/test_gles" "demo_headless=$(BUILD)/egl/demo_headless $(BUILD)/demo_egl --check"

gl-compile: deps-test
	@$(MAKE) --no-print-directory $(BUILD)/dump_shaders $(BUILD)/gl_compile
	@$(GL_COMPILE) | grep -v '^ok '

bench-egl: deps-test
	@$(MAKE) --no-print-directory $(BUILD)/bench_egl $(BUILD)/bench_analytic
	$(BUILD)/bench_analytic | tee $(BUILD)/bench_analytic.txt
	FOGVOL_BENCH_ANALYTIC=$(BUILD)/bench_analytic.txt $(BUILD)/bench_egl
	BUILD=$(BUILD) tests/doc_figures.sh --write bench-gpu-summary
	$(BUILD)/bench_egl --large

# full run, 5-6 min: writes bench/RESULTS.md and bench/plot.png (ratios taken in one run); the
# analytic fog's figures (bench_analytic, run first) join its summary line, and the Vulkan example's
# --bench (lavapipe beside llvmpipe, where it builds: make vulkan's packages) its own section
bench: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/bench $(BUILD)/bench_analytic
	$(BUILD)/bench_analytic | tee $(BUILD)/bench_analytic.txt
	@rm -f $(BUILD)/bench_vulkan.txt
	-@$(MAKE) --no-print-directory $(BUILD)/vulkan_backend && $(VK_ENV) $(BUILD)/vulkan_backend --bench > $(BUILD)/bench_vulkan.txt.tmp && \
	  mv $(BUILD)/bench_vulkan.txt.tmp $(BUILD)/bench_vulkan.txt && cat $(BUILD)/bench_vulkan.txt
	FOGVOL_BENCH_ANALYTIC=$(BUILD)/bench_analytic.txt FOGVOL_BENCH_VULKAN=$(BUILD)/bench_vulkan.txt $(BUILD)/bench
	BUILD=$(BUILD) tests/doc_figures.sh --write bench-summary

# the figures README.md and docs/*.md state, in their marked blocks, rewritten from their sources: the header,
# the Makefile, dump_shaders, bench/RESULTS*.md and the error table of the last make test's test_tiers
# ($(BUILD)/logs/tiers.log; without it that block stays as it is). tests/doc_figures.sh says what each block holds.
docs:
	@$(MAKE) --no-print-directory $(BUILD)/dump_shaders
	@BUILD=$(BUILD) tests/doc_figures.sh --write

# the GPU-scale scenes (64 volumes, shells k=16, floor + pillars at 2560x1440 and 3840x2160; on
# llvmpipe about 10 minutes): writes bench/RESULTS-large.md
bench-large: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/bench
	$(BUILD)/bench --large

# smoke test (smallest scene, a few frames), also part of make test
bench-quick: deps-demo
	@$(MAKE) --no-print-directory $(BUILD)/bench
	$(BUILD)/bench --quick

$(BUILD)/bench_analytic: bench/bench_analytic.c fogvol.h | $(BUILD)
	$(CC) -std=c99 -O2 $(WARN) $(INC) $< -o $@ -lm

# analytic fog: vertex x volume evaluations per second, batch against a scalar loop
bench-analytic: $(BUILD)/bench_analytic
	$(BUILD)/bench_analytic

# libFuzzer on mesh validation, the analytic fog input and API call sequences (null and GL backends; -detect_leaks=0:
# the target counts its context's allocations and backend objects itself), FUZZ_TIME seconds per target; new inputs go to
# build/fuzz (merge them into tests/fuzz/corpus_* with -merge=1 when they matter)
fuzz: deps-test $(BUILD)/fuzz_mesh $(BUILD)/fuzz_analytic $(BUILD)/fuzz_api
	@mkdir -p $(BUILD)/fuzz/mesh $(BUILD)/fuzz/analytic $(BUILD)/fuzz/api
	$(BUILD)/fuzz_mesh -max_total_time=$(FUZZ_TIME) -print_final_stats=1 $(BUILD)/fuzz/mesh tests/fuzz/corpus_mesh
	$(BUILD)/fuzz_analytic -max_total_time=$(FUZZ_TIME) -print_final_stats=1 $(BUILD)/fuzz/analytic \
	  tests/fuzz/corpus_analytic
	$(LSAN_ENV) $(BUILD)/fuzz_api -max_total_time=$(FUZZ_TIME) -detect_leaks=0 -print_final_stats=1 $(BUILD)/fuzz/api \
	  tests/fuzz/corpus_api

# the README pictures, regenerated from the demo
images: demo
	@mkdir -p docs
	cp $(BUILD)/demo/scene_overview.png docs/demo_overview.png
	cp $(BUILD)/demo/scene_low.png docs/demo_low.png
	cp $(BUILD)/demo/scene_inside_fog_bank.png docs/demo_inside_fog_bank.png
	cp $(BUILD)/demo/tiers.png $(BUILD)/demo/dither.png $(BUILD)/demo/ramps.png $(BUILD)/demo/thickness.png docs/
	cp $(BUILD)/demo/textured_fog.png $(BUILD)/demo/light_compare.png $(BUILD)/demo/dof.png \
	   $(BUILD)/demo/outlines.png $(BUILD)/demo/distance_fog.png docs/
	cp $(BUILD)/demo/soft_edges.png $(BUILD)/demo/before_after.png docs/

# --- browser build: emscripten (Debian's emcc ships its system libraries prebuilt), one page for
# WebGL1 (?webgl1) and WebGL2 (?webgl2, the default), the wasm embedded so it loads from file://.
# NODE_PATH: Debian's emscripten finds its node modules (acorn) there even under a node from elsewhere
WEB_FLAGS = -std=c99 -O2 $(WARN) $(INC) -I/usr/include/stb -sMIN_WEBGL_VERSION=1 -sMAX_WEBGL_VERSION=2 \
            -sSINGLE_FILE=1 -sWASM_ASYNC_COMPILATION=0 -sALLOW_MEMORY_GROWTH=1 -sMINIFY_HTML=0
$(BUILD)/web/demo_web.html: examples/web/demo_web.c examples/web/courtyard.h examples/web/shell.html fogvol.h \
	  examples/example_gl.h examples/demo_scene.h tests/raycast.h tests/shapes.h
	@mkdir -p $(BUILD)/web
	NODE_PATH=/usr/share/nodejs $(EMCC) $(WEB_FLAGS) $< --shell-file examples/web/shell.html -o $@

web: deps-web
	@$(MAKE) --no-print-directory $(BUILD)/web/demo_web.html
	@echo "open $(BUILD)/web/demo_web.html (WebGL2) or demo_web.html?webgl1 in a browser; ?test&webgl1 / ?test&webgl2: its self-test"

test-web: deps-web
	@$(MAKE) --no-print-directory $(BUILD)/web/demo_web.html
	@LOGDIR=$(BUILD)/logs tests/run.sh "web=BUILD=$(BUILD) CHROMIUM=$(CHROMIUM) tests/web_test.sh"

clean:
	rm -rf $(BUILD)
