#!/usr/bin/env bash
# make gpu-test and make bench-egl on a GPU machine that has the driver but no compiler packages
# (a lent device with no network): build the EGL programs here, carry them there, run them there.
#   tools/gpu_remote.sh build   here: the EGL test programs (the Makefile's EGL_TESTS), the headless demo, test_gles, bench_egl
#                               and bench_analytic into build-gpu/ (-O2), and the runtime libraries
#                               they link (libEGL, libOpenGL, libGLESv2, libcmocka; Debian .debs,
#                               amd64) into .gl/; both paths are ignored by git
#   tools/gpu_remote.sh run     there, in the repository root with build-gpu/ and .gl/ beside it:
#                               unpacks the .debs into /, runs bench_egl (bench/RESULTS-gpu.md,
#                               plot-gpu.png), bench_egl --large (RESULTS-gpu-large.md) and the
#                               gpu-test programs through tests/run.sh (JOBS=4); copies the results
#                               and a tarball of the logs into $OUT (default /tmp/out)
# NO_BENCH=1 skips the benchmark, NO_DEB=1 the unpacking (a machine with the libraries installed).
set -u
cd "$(dirname "$0")/.."
B=${B:-build-gpu}
case "${1:-}" in
build)
  set -e
  mkdir -p "$B"
  make -s --no-print-directory --eval 'egl-tests: ; @echo $(EGL_TESTS)' egl-tests > "$B/egl_tests.txt"
  T=$(cat "$B/egl_tests.txt")
  make -j"$(nproc)" -s BUILD="$B" CFLAGS=-O2 $(for t in $T; do echo "$B/egl/test_$t"; done) \
    "$B/egl/demo_headless" "$B/test_gles" "$B/bench_egl" "$B/bench_analytic"
  mkdir -p .gl /tmp/amd64/partial
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  apt-get $o update -qq
  (cd .gl && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2 libcmocka0)
  ;;
run)
  OUT=${OUT:-/tmp/out}
  mkdir -p "$OUT"
  if [ -z "${NO_DEB:-}" ]; then for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig; fi
  j=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  [ -f "$j" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$j
  t0=$(date +%s)
  if [ -z "${NO_BENCH:-}" ]; then
    "$B/bench_analytic" > "$B/bench_analytic.txt" 2>&1
    FOGVOL_BENCH_ANALYTIC=$B/bench_analytic.txt timeout 300 "$B/bench_egl" > "$B/bench_egl.txt" 2>&1
    echo "bench_egl rc=$? at $(($(date +%s) - t0)) s"
    timeout 300 "$B/bench_egl" --large > "$B/bench_large.txt" 2>&1
    echo "bench_egl --large rc=$? at $(($(date +%s) - t0)) s"
    cp bench/RESULTS-gpu.md bench/plot-gpu.png bench/RESULTS-gpu-large.md "$OUT"/ 2> /dev/null
  fi
  specs=()
  for t in $(cat "$B/egl_tests.txt"); do specs+=("$t=BUILD=$B CMOCKA_MESSAGE_OUTPUT=TAP $B/egl/test_$t"); done
  specs+=("gles=CMOCKA_MESSAGE_OUTPUT=TAP $B/test_gles" "demo_headless=$B/egl/demo_headless $B/demo_egl --check")
  LOGDIR=$B/logs_egl JOBS=${JOBS:-4} timeout 400 tests/run.sh "${specs[@]}" > "$B/gpu_test.txt" 2>&1
  echo "gpu-test rc=$? at $(($(date +%s) - t0)) s"
  grep -E '^not ok|passed, ' "$B/gpu_test.txt" | grep -v '# SKIP'
  tar czf "$OUT/logs.tgz" "$B/logs_egl" "$B/gpu_test.txt" "$B"/bench_*.txt "$B/demo_egl" 2> /dev/null
  ;;
*)
  echo "usage: $0 build|run" >&2
  exit 2
  ;;
esac
