#!/usr/bin/env bash
# The examples and the packaging, as TAP:
#  - every example builds as C99 with -Wall -Wextra -pedantic -Werror
#  - demo_glfw and engine_integration render a few frames under xvfb-run and write
#    screenshots into $BUILD/examples/; demo_glfw's keys re-create the context
#  - engine_integration --check: 0 pixels differ outside the fog, 0 GL state values
#    differ (FLOAT + the engine's depth texture, and the PS20 fallback)
#  - custom_backend: the recording backend renders the same picture as the default one
#  - the CMake package: install, then find_package(fogvol) and add_subdirectory
#    consumers build and run; pkg-config --cflags fogvol; the tests build and pass under ctest
# Needs gcc, libglfw3-dev, libgl-dev, xvfb, xauth, libosmesa6-dev, libstb-dev, and
# cmake + pkg-config for the packaging tests (skipped when absent).
# Usage: BUILD=build CC=cc tests/examples.sh [examples|package] (one part: the examples, or the CMake
# package and pkg-config; make test runs the two as entries of their own, at once; none: both)
set -u
part=${1:-all}
cd "$(dirname "$0")/.."
root=$(pwd)
build=${BUILD:-build}
case $build in /*) ;; *) build="$root/$build" ;; esac
out=$build/examples
cc=${CC:-cc}
mkdir -p "$out"
n=0
fails=0
log=$out/last_$part.log

ok() { n=$((n + 1)); echo "ok $n - $1"; }
not_ok() {
  n=$((n + 1)); fails=$((fails + 1)); echo "not ok $n - $1"
  [ -s "$log" ] && tail -n 25 "$log" | sed 's/^/#   /'
}
skip() { n=$((n + 1)); echo "ok $n - $1 # SKIP $2"; }
# run DESCRIPTION COMMAND...: ok when the command exits 0 within RUN_TIMEOUT seconds (60; output in $log)
run() {
  local desc=$1; shift
  if timeout "${RUN_TIMEOUT:-60}" "$@" > "$log" 2>&1; then ok "$desc"; else not_ok "$desc (exit $?)"; fi
}
# expect DESCRIPTION REGEX: ok when the last command's output matches (extended regex)
expect() {
  if grep -Eq "$2" "$log"; then ok "$1"; else not_ok "$1 (no line matches /$2/)"; fi
}
note() { grep -E "$1" "$log" | sed 's/^/# /'; }
png_ok() { # a PNG file of at least 10 kB
  [ -f "$1" ] && [ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] && [ "$(wc -c < "$1")" -gt 10000 ]
}
xrun=(xvfb-run -a -s "-screen 0 1280x1024x24")
CTEST_PROGRAMS=${CTEST_PROGRAMS:-glstate} # the cmocka programs the CMake test builds and runs

if [ "$part" != package ]; then # the examples: build, run, check
# ---- build ---------------------------------------------------------------------------
flags="-std=c99 -O1 -Wall -Wextra -pedantic -Werror -I." # -O1: the flow warnings; -O2 builds of the same code in make test
# name, libraries: OSMesa for the headless ones (every GL call must reach OSMesa), GLFW + libGL for the windows
builds="demo_headless:-lOSMesa custom_backend:-lOSMesa demo_glfw:-lglfw_-lGL engine_integration:-lglfw_-lGL"
# BUILT_ELSEWHERE: examples another entry of make test builds with the same warnings (demo_headless: its
# own entry builds and runs it), reported as a SKIP here
for b in $builds; do # in parallel; each writes its own log (300 s each: make test runs other jobs beside them)
  name=${b%%:*}; libs=$(echo "${b#*:}" | tr _ ' ')
  case " ${BUILT_ELSEWHERE:-} " in *" $name "*) continue ;; esac
  (timeout 300 $cc $flags "examples/$name.c" -o "$out/$name" $libs -lm > "$out/build_$name.log" 2>&1
   echo $? > "$out/build_$name.rc") &
done
wait
for b in $builds; do
  name=${b%%:*}; libs=$(echo "${b#*:}" | tr _ ' ')
  case " ${BUILT_ELSEWHERE:-} " in
    *" $name "*) skip "build $name (C99, -Wall -Wextra -pedantic -Werror, $libs)" "built by its own make test entry"; continue ;;
  esac
  cp "$out/build_$name.log" "$log"
  if [ "$(cat "$out/build_$name.rc")" = 0 ]; then ok "build $name (C99, -Wall -Wextra -pedantic -Werror, $libs)"
  else not_ok "build $name (C99, -Wall -Wextra -pedantic -Werror, $libs)"; fi
  rm -f "$out/build_$name.log" "$out/build_$name.rc"
done
# every example also compiles as C++11 with the same warnings (the header says "one C or C++ file")
for b in $builds; do
  name=${b%%:*}
  run "$name compiles as C++11 (-Wall -Wextra -pedantic -Werror)" \
    ${CXX:-c++} -x c++ -std=c++11 -Wall -Wextra -pedantic -Werror -fsyntax-only -I. "examples/$name.c"
done
# the Vulkan example (make test builds and runs it on its own: vulkan_check) compiles as C++11 too
if [ -f /usr/include/vulkan/vulkan.h ] && [ -f /usr/include/shaderc/shaderc.h ]; then
  run "vulkan_backend compiles as C++11 (-Wall -Wextra -pedantic -Werror)" \
    ${CXX:-c++} -x c++ -std=c++11 -Wall -Wextra -pedantic -Werror -fsyntax-only -D_POSIX_C_SOURCE=200809L -I. \
    examples/vulkan_backend.c
else
  skip "vulkan_backend compiles as C++11" "libvulkan-dev or libshaderc-dev not installed"
fi
lines=$(grep -c 'fogvol \*/' examples/engine_integration.c)
if [ "$lines" -gt 0 ] && [ "$lines" -lt 40 ]; then ok "engine_integration adds fog in $lines marked lines (< 40)"
else not_ok "engine_integration adds fog in $lines marked lines (want 1..39)"; fi

# ---- windowed examples under Xvfb ------------------------------------------------------------
if ! command -v xvfb-run > /dev/null; then
  : > "$log"; not_ok "xvfb-run is missing (apt-get install xvfb xauth)"
else
  run "demo_glfw: 8 frames, screenshot" "${xrun[@]}" "$out/demo_glfw" --frames 8 --size 640x360 \
    --screenshot "$out/demo_glfw.png"
  note '^demo:'
  if png_ok "$out/demo_glfw.png"; then ok "demo_glfw.png written"; else not_ok "demo_glfw.png written"; fi
  run "demo_glfw: camera inside the fog bank, PS20, screenshot" "${xrun[@]}" "$out/demo_glfw" --frames 4 --size 640x360 \
    --tier ps20 --camera -7,0.5,-1.5,63,5 --screenshot "$out/demo_glfw_inside.png"
  expect "demo_glfw --tier ps20 runs PS20" '\[T\] PS20'
  run "demo_glfw: keys T B G R L re-create the context and ramps" "${xrun[@]}" "$out/demo_glfw" --frames 7 --size 480x270 \
    --keys TBGRLOP --screenshot "$out/demo_glfw_keys.png"
  expect "demo_glfw: keys reached PS13, 5 bits, dither off, linear ramp, light blend" \
    '\[T\] PS13 \| \[B\] 5 bits/ch.*dither off \| \[R\] linear \| \[L\] light'
  note '^demo:'

  run "engine_integration: 5 frames with fog, screenshot" "${xrun[@]}" "$out/engine_integration" --frames 5 \
    --screenshot "$out/engine_integration.png"
  note '^engine:'
  run "engine_integration: 5 frames --no-fog, screenshot" "${xrun[@]}" "$out/engine_integration" --frames 5 --no-fog \
    --screenshot "$out/engine_integration_nofog.png"
  run "engine_integration: 5 frames PS20 fallback, screenshot" "${xrun[@]}" "$out/engine_integration" --frames 5 --ps20 \
    --screenshot "$out/engine_integration_ps20.png"
  if png_ok "$out/engine_integration.png" && png_ok "$out/engine_integration_nofog.png" &&
     ! cmp -s "$out/engine_integration.png" "$out/engine_integration_nofog.png"; then
    ok "engine_integration: the fog changes the picture"
  else
    not_ok "engine_integration: the fog changes the picture"
  fi
  for mode in float ps20; do # FLOAT + the engine's depth texture, and the PS20 fallback with occluders
    flag=; [ $mode = ps20 ] && flag=--ps20
    run "engine_integration --check ($mode)" "${xrun[@]}" "$out/engine_integration" --check $flag
    note '^check:'
    expect "engine_integration --check ($mode): 0 pixels differ outside the fog" 'outside the fog compared, 0 differ'
    expect "engine_integration --check ($mode): 0 GL state values differ" 'compared after fogvol_end_frame, 0 differ'
  done
fi

# ---- custom backend (headless) ---------------------------------------------------------------
run "custom_backend: recording backend renders, logs, writes a PNG" "$out/custom_backend" "$out/custom_backend.png"
note '^  (begin_pass|draw_mesh|draw_fullscreen) |^  [0-9]+ |differ|violations'
expect "custom_backend: same pixels as the default GL backend" ' 0 of [0-9]+ pixels differ'
expect "custom_backend: the occlusion queries forwarded (overflow counts through the wrapper)" '^  create_query +[1-9]'
run "custom_backend --tier float" "$out/custom_backend" --tier float "$out/custom_backend_float.png"

fi # the examples

# ---- CMake package and pkg-config ------------------------------------------------------------
if [ "$part" = examples ]; then
  : # the examples only
elif ! command -v cmake > /dev/null; then
  skip "CMake package: install, find_package, add_subdirectory" "cmake not installed"
else
  cm=$out/cmake
  rm -rf "$cm"
  mkdir -p "$cm/consumer"
  cat > "$cm/consumer/main.c" << 'EOF'
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#include <stdio.h>
int main(void)
{
    fogvol_encoding e;
    if (fogvol_encoding_init(FOGVOL_DEFAULT_BITS, &e) != FOGVOL_SUCCESS) return 1;
    printf("fogvol %s: %d-bit encoding, %d faces\n", FOGVOL_VERSION_STRING, e.precision_bits, e.max_faces);
    return e.max_faces == 16 ? 0 : 1;
}
EOF
  cat > "$cm/consumer/CMakeLists.txt" << 'EOF'
cmake_minimum_required(VERSION 3.14)
project(fogvol_consumer C)
if(FOGVOL_SOURCE_DIR)
  add_subdirectory("${FOGVOL_SOURCE_DIR}" fogvol)
  if(TARGET demo_glfw OR TARGET demo_headless)
    message(FATAL_ERROR "fogvol's examples must be off in a subproject")
  endif()
  if(TARGET test_cpu OR TARGET test_raycast)
    message(FATAL_ERROR "fogvol's tests must be off in a subproject")
  endif()
else()
  find_package(fogvol ${FOGVOL_WANT} REQUIRED)
endif()
add_executable(consumer main.c)
target_link_libraries(consumer PRIVATE fogvol::fogvol)
EOF
  prefix=$cm/prefix
  run "cmake: configure, build and install fogvol (the defaults)" bash -c "cmake -S '$root' -B '$cm/fogvol' \
    -DCMAKE_INSTALL_PREFIX='$prefix' && cmake --build '$cm/fogvol' && cmake --install '$cm/fogvol'"
  # installing the header builds nothing: no example, no test program
  if [ -z "$(find "$cm/fogvol" -type f -perm -u+x -newer "$root/fogvol.h" ! -path '*/CMakeFiles/*' 2> /dev/null)" ]; then
    ok "cmake: installing builds no program (examples and tests are off by default)"
  else
    not_ok "cmake: installing builds no program (examples and tests are off by default)"
  fi
  if [ -f "$prefix/include/fogvol.h" ] && [ -f "$prefix/share/cmake/fogvol/fogvolConfig.cmake" ] &&
     [ -f "$prefix/share/cmake/fogvol/fogvolConfigVersion.cmake" ] && [ -f "$prefix/share/pkgconfig/fogvol.pc" ]; then
    ok "cmake: installed fogvol.h, fogvolConfig.cmake, fogvolConfigVersion.cmake, fogvol.pc"
  else
    not_ok "cmake: installed fogvol.h, fogvolConfig.cmake, fogvolConfigVersion.cmake, fogvol.pc"
  fi
  run "cmake: find_package(fogvol 0.2) consumer builds and runs" bash -c "cmake -S '$cm/consumer' -B '$cm/find' \
    -DCMAKE_PREFIX_PATH='$prefix' -DFOGVOL_WANT=0.2 && cmake --build '$cm/find' && '$cm/find/consumer'"
  note '^fogvol [0-9]'
  for want in 1.0 0.1; do # 0.1: the API before 0.2's breaking changes
    if cmake -S "$cm/consumer" -B "$cm/find_wrong" -DCMAKE_PREFIX_PATH="$prefix" -DFOGVOL_WANT=$want > "$log" 2>&1; then
      not_ok "cmake: find_package(fogvol $want) is refused (0.x is only compatible within its minor version)"
    else
      ok "cmake: find_package(fogvol $want) is refused (0.x is only compatible within its minor version)"
    fi
    rm -rf "$cm/find_wrong"
  done
  run "cmake: add_subdirectory consumer builds and runs (examples off)" bash -c "cmake -S '$cm/consumer' \
    -B '$cm/subdir' -DFOGVOL_SOURCE_DIR='$root' && cmake --build '$cm/subdir' && '$cm/subdir/consumer'"
  # the tests through CMake (a Debug build: -O0, the fastest to compile): configure, build and ctest (one
  # cmocka program, the ray-cast self-test and a script test, the README blocks: the cheapest; `make test`
  # runs the whole list, the shader script with the dump_shaders that this build makes too among them)
  RUN_TIMEOUT=900 run "cmake -B b && cmake --build b && ctest --test-dir b (tests: $CTEST_PROGRAMS)" bash -c "cmake -S '$root' \
    -B '$cm/ctest' -DCMAKE_BUILD_TYPE=Debug -DFOGVOL_BUILD_EXAMPLES=OFF -DFOGVOL_BUILD_TESTS=ON -DFOGVOL_TESTS='$CTEST_PROGRAMS' && \
    cmake --build '$cm/ctest' -j '${JOBS:-2}' && ctest --test-dir '$cm/ctest' -R '^($CTEST_PROGRAMS|raycast_selftest|readme_blocks)\$' \
    --output-on-failure"
  expect "ctest: every test passed" '100% tests passed, 0 tests failed out of [3-9]'
  if command -v pkg-config > /dev/null; then
    run "pkg-config --cflags --libs fogvol" env PKG_CONFIG_PATH="$prefix/share/pkgconfig" \
      pkg-config --cflags --libs fogvol
    # the .pc finds its prefix from its own place (${pcfiledir}): the include dir must be $prefix/include
    inc=$(sed -n 's/^-I\([^ ]*\).*/\1/p' "$log")
    if [ -n "$inc" ] && [ "$(cd "$inc" 2>/dev/null && pwd -P)" = "$(cd "$prefix/include" && pwd -P)" ] &&
       grep -Eq -- ' -lm *$' "$log"; then
      ok "pkg-config: -I resolves to $prefix/include, -lm"
    else
      not_ok "pkg-config: -I resolves to $prefix/include, -lm (got: $(cat "$log"))"
    fi
    # installed to another prefix than the one configured: the .pc and the CMake package follow
    moved=$cm/moved
    run "cmake --install --prefix (not the configured prefix)" cmake --install "$cm/fogvol" --prefix "$moved"
    run "pkg-config consumer builds against the moved install" bash -c "$cc -std=c99 '$cm/consumer/main.c' \
      -o '$cm/pc_moved' \$(PKG_CONFIG_PATH='$moved/share/pkgconfig' pkg-config --cflags --libs fogvol) && \
      test \"\$(PKG_CONFIG_PATH='$moved/share/pkgconfig' pkg-config --variable=includedir fogvol | xargs realpath)\" \
        = \"\$(realpath '$moved/include')\" && '$cm/pc_moved'"
    run "cmake: find_package from the moved install" bash -c "cmake -S '$cm/consumer' -B '$cm/find_moved' \
      -DCMAKE_PREFIX_PATH='$moved' -DFOGVOL_WANT=0.2 && cmake --build '$cm/find_moved' && '$cm/find_moved/consumer'"
    run "pkg-config consumer builds and runs" bash -c "$cc -std=c99 '$cm/consumer/main.c' -o '$cm/pc_consumer' \
      \$(PKG_CONFIG_PATH='$prefix/share/pkgconfig' pkg-config --cflags --libs fogvol) && '$cm/pc_consumer'"
  else
    skip "pkg-config --cflags fogvol" "pkg-config not installed"
  fi
fi
rm -f "$log"
echo "1..$n"
[ "$fails" = 0 ]
