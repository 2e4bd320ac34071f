#!/usr/bin/env bash
# The figures README.md and docs/*.md state agree with the code and with the files that measure them.
# A figure lives in a marked block that this script writes:
#     <!-- figures:NAME -->
#     (text generated from its source)
#     <!-- /figures:NAME -->
# and the check regenerates every block and compares. Sources, by block name:
#   version          FOGVOL_VERSION_STRING (fogvol.h)
#   functions        the public functions declared in fogvol.h (the count tests/doc_index.sh checks)
#   test-programs    TESTS and EGL_TESTS in the Makefile
#   shaders          what build/dump_shaders writes for the GL dialects (files, texts, kinds)
#   vulkan-shaders   what build/dump_shaders --vulkan writes
#   bench-summary    bench/RESULTS.md's summary line (make bench writes it)
#   bench-gpu-summary  bench/RESULTS-gpu.md's summary line (make bench-egl)
#   tiers-table      the error table test_tiers prints (BUILD/logs/tiers.log, written by make test)
# Besides the blocks: CHANGELOG.md's first version heading and the doc block's first line name the
# version; README.md has at most 350 lines and its first C block (the quick start) at most 40.
# Usage: tests/doc_figures.sh [--write] [--no-shaders] [NAME...]   (no NAME: every block)
#   --write       rewrite the blocks instead of checking them (make docs)
#   --no-shaders  leave out the blocks that need build/dump_shaders (make check)
#   --no-tiers    leave out the tiers table (make test, which rewrites the log it would compare with)
# The tiers table is checked when BUILD/logs/tiers.log holds a complete table newer than fogvol.h and
# tests/test_tiers.c (make test writes it: make check after make test compares it), and skipped
# otherwise, unless REQUIRE_TIERS_LOG=1 (CI, after make test). TAP.
set -u
cd "$(dirname "$0")/.."
b=${BUILD:-build}
write=0; shaders=1; tiers=1; only=()
for a in "$@"; do
  case "$a" in
    --write) write=1 ;;
    --no-shaders) shaders=0 ;;
    --no-tiers) tiers=0 ;;
    *) only+=("$a") ;;
  esac
done
docs=(README.md docs/*.md)
n=0; fails=0
ok() { n=$((n + 1)); echo "ok $n - $1"; }
bad() { n=$((n + 1)); fails=$((fails + 1)); echo "not ok $n - $1"; [ -n "${2:-}" ] && echo "$2" | sed 's/^/#   /'; }
skip() { n=$((n + 1)); echo "ok $n - $1 # SKIP $2"; }
wanted() { [ ${#only[@]} = 0 ] && return 0; local o; for o in "${only[@]}"; do [ "$o" = "$1" ] && return 0; done; return 1; }

# ---- the sources -----------------------------------------------------------------------------
version=$(sed -n 's/^#define FOGVOL_VERSION_STRING "\(.*\)"/\1/p' fogvol.h)
decl_end=$(grep -n '^/\* >>cpu' fogvol.h | head -1 | cut -d: -f1)
functions=$(head -n "$decl_end" fogvol.h | tr '\n' ' ' | grep -oE 'FOGVOL_API [^;{]*;' |
            grep -oE 'fogvol_[a-z0-9_]+ *\(' | tr -d ' (' | sort -u | wc -l)
make_list() { sed -n "s/^$1 *= *//p" Makefile | head -1; }
tests_n=$(make_list TESTS | wc -w)
egl_n=$(make_list EGL_TESTS | wc -w)

gen_version() { echo "This is fogvol.h $version."; }
gen_functions() {
  echo "fogvol.h has $functions public functions; the API INDEX at the top of the header lists them by task,"
  echo "one line each."
}
gen_test_programs() {
  echo "The suite has $tests_n cmocka test programs (\`TESTS\` in the Makefile), each also built under ASan+UBSan;"
  echo "$egl_n of them draw with GL and run on a GPU driver too (\`EGL_TESTS\`, \`make gpu-test\`)."
}
shader_dir=""
dump() { # the GL dialects' and the Vulkan dialect's shaders, once
  [ -n "$shader_dir" ] && return 0
  [ -x "$b/dump_shaders" ] || return 1
  shader_dir=$(mktemp -d)
  mkdir -p "$shader_dir/gl" "$shader_dir/vk"
  "$b/dump_shaders" "$shader_dir/gl" > /dev/null && "$b/dump_shaders" --vulkan "$shader_dir/vk" > /dev/null
}
texts() { (cd "$1" && md5sum -- * | awk '{ e = $2; sub(/.*\./, "", e); print $1 e }' | sort -u | wc -l); }
gen_shaders() {
  dump || return 1
  local d=$shader_dir/gl all post ms spec frag
  all=$(ls "$d" | wc -l); post=$(ls "$d" | grep -c '^post_'); ms=$(ls "$d" | grep -c '_ms')
  spec=$(ls "$d" | grep -c '_s[0-9]'); frag=$(ls "$d" | grep -c '\.frag$')
  echo "\`dump_shaders\` writes $all vertex and fragment shaders for the GL dialects ($(texts "$d") different texts):"
  echo "$((all - post)) of the volume programs ($spec of them specialised builds, $ms per-sample MSAA fragment shaders)"
  echo "and $post of the image-space effects; $frag programs (a fragment shader with its vertex shader) to link."
}
gen_vulkan_shaders() {
  dump || return 1
  echo "\`dump_shaders --vulkan\` writes $(ls "$shader_dir/vk" | wc -l) Vulkan shaders, $(texts "$shader_dir/vk") different texts."
}
summary_of() { [ -f "$1" ] || return 1; grep -m1 '^summary: ' "$1" | sed 's/^/    /'; }
gen_bench_summary() { summary_of bench/RESULTS.md; }
gen_bench_gpu_summary() { summary_of bench/RESULTS-gpu.md; }
tiers_log=$b/logs/tiers.log
tiers_legend='(max error / mean error per pair of faces'
tiers_fresh() {
  [ -f "$tiers_log" ] && grep -qF "$tiers_legend" "$tiers_log" && [ "$tiers_log" -nt fogvol.h ] &&
    [ "$tiers_log" -nt tests/test_tiers.c ]
}
gen_tiers_table() {
  tiers_fresh || return 1
  sed -n '/^| tier + variants/,/^(max error/p' "$tiers_log" | sed 's/ *$//'
}

# ---- the blocks --------------------------------------------------------------------------------
block() { # file name: the text between the markers
  awk -v s="<!-- figures:$2 -->" -v e="<!-- /figures:$2 -->" '$0 == e { on = 0 } on { print } $0 == s { on = 1 }' "$1"
}
replace() { # file name text-file
  awk -v s="<!-- figures:$2 -->" -v e="<!-- /figures:$2 -->" -v t="$3" '
    $0 == e { while ((getline l < t) > 0) print l; close(t); on = 0 }
    !on { print } $0 == s { on = 1 }' "$1" > "$1.tmp" && mv "$1.tmp" "$1"
}
names=(version functions test-programs shaders vulkan-shaders bench-summary bench-gpu-summary tiers-table)
used=$(cat "${docs[@]}" | grep -oE '^<!-- figures:[a-z-]+ -->$' | sed 's/<!-- figures://; s/ -->//' | sort -u)
for u in $used; do
  case " ${names[*]} " in *" $u "*) ;; *) bad "a figures block names no source: $u" ;; esac
done
tmp=$(mktemp)
for name in "${names[@]}"; do
  wanted "$name" || continue
  files=$(grep -lx -- "<!-- figures:$name -->" "${docs[@]}" 2> /dev/null)
  if [ -z "$files" ]; then bad "no block $name in README.md or docs/"; continue; fi
  if [ "$shaders" = 0 ] && { [ "$name" = shaders ] || [ "$name" = vulkan-shaders ]; }; then
    skip "figures:$name" "--no-shaders"; continue
  fi
  if [ "$tiers" = 0 ] && [ "$name" = tiers-table ]; then
    skip "figures:$name" "--no-tiers: make test writes the log it compares with while this runs"; continue
  fi
  if ! "gen_${name//-/_}" > "$tmp" 2> /dev/null || [ ! -s "$tmp" ]; then
    if [ "$name" = tiers-table ] && [ "${REQUIRE_TIERS_LOG:-0}" != 1 ]; then
      skip "figures:tiers-table" "no complete $tiers_log newer than fogvol.h and tests/test_tiers.c (make test)"
    elif [ "$name" = shaders ] || [ "$name" = vulkan-shaders ]; then
      bad "figures:$name: $b/dump_shaders failed or is missing (make $b/dump_shaders)"
    else
      bad "figures:$name: its source is missing"
    fi
    continue
  fi
  for f in $files; do
    if [ "$write" = 1 ]; then
      replace "$f" "$name" "$tmp"; ok "figures:$name written in $f"
    elif d=$(diff <(block "$f" "$name") "$tmp"); then
      ok "figures:$name in $f agrees with its source"
    else
      bad "figures:$name in $f disagrees with its source (tests/doc_figures.sh --write $name; < file, > source)" "$d"
    fi
  done
done
rm -f "$tmp"
[ -n "$shader_dir" ] && rm -rf "$shader_dir"

# ---- the rest ----------------------------------------------------------------------------------
if [ ${#only[@]} = 0 ] && [ "$write" = 0 ]; then
  first=$(grep -m1 -oE '^## [0-9]+\.[0-9]+\.[0-9]+|^## Unreleased' CHANGELOG.md | sed 's/^## //')
  if [ "$first" = "$version" ] || [ "$first" = Unreleased ]; then ok "CHANGELOG.md's first heading is $first (header: $version)"
  else bad "CHANGELOG.md's first version heading is $first, fogvol.h says $version"; fi
  if head -1 fogvol.h | grep -q " v$version "; then ok "the doc block's first line names v$version"
  else bad "the doc block's first line does not name v$version" "$(head -1 fogvol.h)"; fi
  wrong=$(grep -noE 'find_package\(fogvol [0-9]+\.[0-9]+' "${docs[@]}" CMakeLists.txt | grep -v "fogvol ${version%.*}\$")
  if [ -z "$wrong" ]; then ok "every find_package(fogvol X.Y) in the docs and CMakeLists.txt asks for ${version%.*}"
  else bad "find_package(fogvol X.Y) with another version than ${version%.*}" "$wrong"; fi
  lines=$(wc -l < README.md)
  if [ "$lines" -le 350 ]; then ok "README.md has $lines lines (at most 350)"; else bad "README.md has $lines lines (at most 350)"; fi
  # every relative link and picture points at a file that exists (and an anchor at a heading there)
  broken=""
  for f in "${docs[@]}"; do
    for l in $(grep -oE '\]\([^) ]+\)' "$f" | sed 's/^](//; s/)$//' | grep -vE '^(https?|mailto):'); do
      p=${l%%#*}; a=${l#"$p"}; a=${a#\#}
      [ -n "$p" ] && t=$(dirname "$f")/$p || t=$f
      if [ ! -e "$t" ]; then broken="$broken $f:$l"; continue; fi
      if [ -n "$a" ] && ! grep -E '^#+ ' "$t" | tr 'A-Z' 'a-z' | sed -E 's/^#+ //; s/[^a-z0-9 -]//g; s/ /-/g' | grep -qx -- "$a"
      then broken="$broken $f:$l"; fi
    done
  done
  if [ -z "$broken" ]; then ok "the links and pictures of README.md and docs/*.md point at files and headings that exist"
  else bad "broken links:$broken"; fi
  # the speed-up table names each FOGVOL_SPEEDUP_* of the header once, and nothing else
  have=$(grep -oE '^ +FOGVOL_SPEEDUP_[A-Z_]+ = 1u <<' fogvol.h | grep -oE 'SPEEDUP_[A-Z_]+' | sed 's/^SPEEDUP_//' | sort)
  rows=$(grep -oE '^\| `[A-Z_]+` \|' docs/PERFORMANCE.md | grep -oE '[A-Z_]+' | sort)
  d=$(diff <(echo "$have") <(echo "$rows"))
  if [ -z "$d" ]; then ok "docs/PERFORMANCE.md's speed-up table names the $(echo "$have" | wc -l) FOGVOL_SPEEDUP_* once each"
  else bad "docs/PERFORMANCE.md's speed-up table and the header's FOGVOL_SPEEDUP_* differ (< header, > table)" "$d"; fi
  # the README's tier section names every tier and every variant
  section=$(sed -n '/^## Which tier/,/^## /p' README.md)
  miss=""
  for v in $(grep -oE '^ +FOGVOL_VARIANT_[A-Z_]+ = 1u <<' fogvol.h | grep -oE 'VARIANT_[A-Z_]+' | sed 's/^VARIANT_//') \
           $(grep -oE '^ +FOGVOL_TIER_[A-Z0-9]+ = [1-9]' fogvol.h | grep -v TIER_COUNT | grep -oE 'TIER_[A-Z0-9]+' | sed 's/^TIER_//'); do
    echo "$section" | grep -q "\`$v\`" || miss="$miss $v"
  done
  if [ -z "$miss" ]; then ok "README.md's \"Which tier\" names every tier and variant of the header"
  else bad "README.md's \"Which tier\" does not name:$miss"; fi
  qs=$(awk '/^```c[ \t]*$/ { on = 1; next } on && /^```/ { exit } on { n++ } END { print n + 0 }' README.md)
  if [ "$qs" -ge 1 ] && [ "$qs" -le 40 ]; then ok "README.md's quick start (its first C block) has $qs lines (at most 40)"
  else bad "README.md's quick start (its first C block) has $qs lines (1 to 40)"; fi
fi
echo "1..$n"
[ "$fails" = 0 ]
