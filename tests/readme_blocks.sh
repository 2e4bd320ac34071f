#!/usr/bin/env bash
# Every ```c block of README.md compiles as C99 and as C++11 (gcc and g++, clang and
# clang++ when present) with -Wall -Wextra -pedantic -Werror. A block is compiled as
# written: preprocessor lines stay at file scope, everything else goes into a function
# body, after tests/readme_prelude.h, which declares the stand-ins the blocks use
# (your loader, vertex arrays, matrices). TAP output.
set -u
cd "$(dirname "$0")/.."
out=${BUILD:-build}/readme
mkdir -p "$out"
rm -f "$out"/block_*.c
awk -v dir="$out" '
  /^```c[ \t]*$/ { inblock = 1; n++; file = sprintf("%s/block_%d.c", dir, n); top = file ".top"; body = file ".body";
                   printf "" > top; printf "" > body; line0[n] = NR; next }
  /^```/ && inblock { inblock = 0; close(top); close(body); next }
  inblock { if ($0 ~ /^[ \t]*#/) print $0 >> top; else print $0 >> body }
  END { print n > (dir "/count") }' README.md
count=$(cat "$out/count")
n=0; fails=0
compilers=()
for c in "gcc -std=c99 -x c" "clang -std=c99 -x c" "g++ -std=c++11 -x c++" "clang++ -std=c++11 -x c++"; do
  set -- $c
  command -v "$1" > /dev/null 2>&1 && compilers+=("$c")
done
for ((i = 1; i <= count; ++i)); do
  f=$out/block_$i.c
  { cat "$f.top"
    echo '#include "tests/readme_prelude.h"'
    echo 'void readme_block(void);'
    echo 'void readme_block(void) {'
    cat "$f.body"
    echo '}'; } > "$f"
  for c in "${compilers[@]}"; do
    n=$((n + 1))
    if $c -Wall -Wextra -pedantic -Werror -Wno-unused-variable -fsyntax-only -I. "$f" > "$out/log" 2>&1; then
      echo "ok $n - README block $i compiles: $c"
    else
      echo "not ok $n - README block $i compiles: $c"; sed 's/^/#   /' "$out/log" | head -20; fails=$((fails + 1))
    fi
  done
done
if [ "$count" -lt 1 ]; then echo "not ok 1 - README.md has no c block"; n=1; fails=1; fi
echo "1..$n"
[ "$fails" = 0 ]
