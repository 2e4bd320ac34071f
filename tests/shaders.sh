#!/usr/bin/env bash
# Every shader string of every program and dialect passes glslangValidator.
set -u
b=${BUILD:-build}
mkdir -p "$b/shaders"
rm -f "$b/shaders"/*.vert "$b/shaders"/*.frag
"$b/dump_shaders" "$b/shaders" || { echo "not ok 1 - dump_shaders"; exit 1; }
# one glslangValidator per file, two at a time; numbered afterwards
ls "$b/shaders"/*.vert "$b/shaders"/*.frag | xargs -P 2 -I{} sh -c \
  'if out=$(glslangValidator "{}" 2>&1); then echo "ok - $(basename "{}")"; else
     echo "not ok - $(basename "{}")"; echo "$out" | head -10 | sed "s/^/#   /"; fi' > "$b/shaders.tap"
awk '/^(ok|not ok) - /{ n++; sub(/ - /, " " n " - "); } { print } END { print "1.." n }' "$b/shaders.tap"
