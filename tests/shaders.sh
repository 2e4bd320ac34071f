#!/usr/bin/env bash
# Every shader string of every program and dialect passes glslangValidator.
set -u
b=${BUILD:-build}
mkdir -p "$b/shaders"
rm -f "$b/shaders"/*.vert "$b/shaders"/*.frag
"$b/dump_shaders" "$b/shaders" || { echo "not ok 1 - dump_shaders"; exit 1; }
n=0
for f in "$b/shaders"/*.vert "$b/shaders"/*.frag; do
  n=$((n + 1))
  if out=$(glslangValidator "$f" 2>&1); then echo "ok $n - $(basename "$f")"
  else echo "not ok $n - $(basename "$f")"; echo "$out" | head -10 | sed 's/^/#   /'; fi
done
echo "1..$n"
