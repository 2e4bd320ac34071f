#!/usr/bin/env bash
# The header compiles clean (-Wall -Wextra -pedantic -Werror) as C99, C11, C++11,
# C++17 with gcc and clang: implementation in one TU, static mode, FOGVOL_NO_GL, FOGVOL_NO_ANALYTIC,
# and implementation in one of two TUs (linked and run); C11 and C++17 by the front end (-fsyntax-only) but
# for the two-TU build.
# Usage: tests/compile_matrix.sh [COMPILER...] (default: gcc clang g++ clang++; make test runs one
# compiler an entry, so that they run at once)
set -u
out=${BUILD:-build}/compile
mkdir -p "$out"
n=0
check() { # description, command...
  n=$((n + 1)); desc=$1; shift
  if msg=$("$@" 2>&1); then echo "ok $n - $desc"; else echo "not ok $n - $desc"; echo "$msg" | head -20 | sed 's/^/#   /'; fi
}
flags="-Wall -Wextra -pedantic -Werror -I."
[ $# -gt 0 ] || set -- gcc clang g++ clang++
for cc in "$@"; do
  case $cc in *++) stds="c++11 c++17"; lang="-x c++";; *) stds="c99 c11"; lang="";; esac
  for std in $stds; do
    tag="$cc-$std"
    # the first standard (C99, C++11) compiled and linked; the second (C11, C++17) checked by the front
    # end (-fsyntax-only: its warnings and errors, without code generation, which does not depend on
    # the standard) but for its two-TU build, linked and run
    case $std in c99|c++11) to=(-o); ext=(-lm);; *) to=(-fsyntax-only -o); ext=();; esac
    check "$tag single TU" $cc -std=$std $flags $lang tests/compile/single.c "${to[@]}" "$out/single-$tag" "${ext[@]}"
    check "$tag static" $cc -std=$std $flags $lang -DFOGVOL_STATIC tests/compile/single.c "${to[@]}" "$out/static-$tag" \
      "${ext[@]}"
    check "$tag FOGVOL_NO_GL" $cc -std=$std $flags $lang -DFOGVOL_NO_GL tests/compile/single.c "${to[@]}" "$out/nogl-$tag" \
      "${ext[@]}"
    check "$tag FOGVOL_NO_ANALYTIC" $cc -std=$std $flags $lang -DFOGVOL_NO_ANALYTIC tests/compile/single.c "${to[@]}" \
      "$out/noan-$tag" "${ext[@]}"
    check "$tag two TUs" bash -c "$cc -std=$std $flags $lang -c tests/compile/impl.c -o $out/impl-$tag.o && \
      $cc -std=$std $flags $lang -c tests/compile/user.c -o $out/user-$tag.o && \
      $cc $out/impl-$tag.o $out/user-$tag.o -o $out/two-$tag -lm && $out/two-$tag >/dev/null"
  done
done
echo "1..$n"
