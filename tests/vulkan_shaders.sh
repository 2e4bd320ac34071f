#!/usr/bin/env bash
# Every program of the Vulkan dialect (FOGVOL_GLSL_VULKAN: every tier, variant, specialisation and
# image-space effect that exists there, as dump_shaders --vulkan writes them) compiles to SPIR-V
# (glslc, shaderc's compiler on glslang), passes spirv-val (Vulkan 1.0 rules), and is cross-compiled
# by SPIRV-Cross to HLSL (shader model 5.0, D3D11/D3D12) and MSL (Metal): how many convert cleanly is
# reported (the "# vulkan:" line), and a shader that does not is a failure too.
# Identical texts (many tiers share a vertex shader) are compiled once. One TAP line per unique shader.
set -u
b=${BUILD:-build}
jobs=${JOBS:-$(nproc 2> /dev/null || echo 2)}
dir=$(mkdir -p "$b" && cd "$b" && pwd)/shaders_vulkan
for tool in glslc spirv-val spirv-cross; do
  command -v $tool > /dev/null || { echo "not ok 1 - $tool is missing (tools/deps.sh test installs it)"; echo "1..1"; exit 1; }
done
rm -rf "$dir" && mkdir -p "$dir/src" "$dir/u"
"$b/dump_shaders" --vulkan "$dir/src" > "$dir/dump.log" || { echo "not ok 1 - dump_shaders --vulkan"; cat "$dir/dump.log"; exit 1; }
total=$(ls "$dir/src" | wc -l)
# one copy per text: u/<md5>.<vert|frag>, and the list of the files that share it
(cd "$dir/src" && md5sum -- *) | LC_ALL=C sort -k1,1 -k2 | awk -v d="$dir" '
  { ext = $2; sub(/.*\./, "", ext); key = $1 "." ext
    if (!(key in first)) { first[key] = $2; print "cp \"" d "/src/" $2 "\" \"" d "/u/" key "\"" } }
  END { }' | sh
(cd "$dir/src" && md5sum -- *) | awk '{ ext = $2; sub(/.*\./, "", ext); print $1 "." ext, $2 }' > "$dir/names"
ls "$dir/u" | LC_ALL=C sort > "$dir/list"
unique=$(wc -l < "$dir/list")
# glslc compiles a batch of files per process (each on its own: name.spv beside it)
split -l 100 -d -a 4 "$dir/list" "$dir/batch_"
ls "$dir"/batch_* | xargs -P "$jobs" -I{} sh -c \
  'cd "'"$dir"'/u" && xargs glslc -c --target-env=vulkan1.0 < "{}" > "{}.log" 2>&1; true'
cat "$dir"/batch_*.log > "$dir/glslc.log"
# spirv-val, and SPIRV-Cross to HLSL and MSL, per SPIR-V file (status files per check)
export dir
check() {
  f=$1; s="$dir/u/$f.spv"
  [ -f "$s" ] || { echo "$f nospv"; return; }
  spirv-val --target-env vulkan1.0 "$s" > "$dir/u/$f.val" 2>&1 || { echo "$f val"; return; }
  spirv-cross "$s" --hlsl --shader-model 50 --output "$dir/u/$f.hlsl" > "$dir/u/$f.hlsl.log" 2>&1 || echo "$f hlsl"
  spirv-cross "$s" --msl --output "$dir/u/$f.metal" > "$dir/u/$f.msl.log" 2>&1 || echo "$f msl"
  echo "$f done"
}
export -f check
xargs -P "$jobs" -n 50 bash -c 'for f; do check "$f"; done' check_batch < "$dir/list" | LC_ALL=C sort > "$dir/results"
awk -v names="$dir/names" -v glslc="$dir/glslc.log" '
  BEGIN { while ((getline l < names) > 0) { split(l, a, " "); n[a[1]]++; if (!(a[1] in ex)) ex[a[1]] = a[2] } }
  { bad[$1] = bad[$1] ($2 == "done" ? "" : " " $2); seen[$1] = 1 }
  END {
    for (k in seen) keys[++m] = k
    for (i = 1; i <= m; i++) for (j = i + 1; j <= m; j++) if (keys[j] < keys[i]) { t = keys[i]; keys[i] = keys[j]; keys[j] = t }
    for (i = 1; i <= m; i++) {
      k = keys[i]
      if (bad[k] == "") print "ok - " ex[k] " (" n[k] " files)"
      else { print "not ok - " ex[k] ":" bad[k]; while ((getline l < glslc) > 0) if (index(l, k)) print "#   " l; close(glslc) }
    }
  }' "$dir/results" > "$dir/tap"
spv=$(grep -vc ' nospv$' "$dir/results")
val=$(grep -c ' done$' "$dir/results")
hlsl_bad=$(grep -c ' hlsl$' "$dir/results")
msl_bad=$(grep -c ' msl$' "$dir/results")
awk '/^(ok|not ok) - /{ c++; sub(/ - /, " " c " - "); } { print }' "$dir/tap"
n=$(grep -c '^\(ok\|not ok\)' "$dir/tap")
echo "# vulkan: $total shaders ($unique unique texts): $spv compiled to SPIR-V (glslc), $val pass spirv-val," \
     "$((val - hlsl_bad))/$val convert to HLSL 5.0 and $((val - msl_bad))/$val to MSL (spirv-cross)"
echo "1..$n"
[ "$unique" -gt 0 ] && ! grep -q "^not ok" "$dir/tap"
