#!/usr/bin/env bash
# Every shader string of every program and dialect passes glslangValidator (each different text
# compiled once; every file gets a TAP line).
# The files go to glslangValidator in batches (one process compiles many files, each on
# its own, no linking), JOBS batches at a time; a file passes when its part of the
# output holds no ERROR line. One TAP line a file, in file-name order.
set -u
b=${BUILD:-build}
jobs=${JOBS:-$(nproc 2> /dev/null || echo 2)}
mkdir -p "$b/shaders"
rm -f "$b/shaders"/*.vert "$b/shaders"/*.frag "$b/shaders"/batch_*
"$b/dump_shaders" "$b/shaders" || { echo "not ok 1 - dump_shaders"; exit 1; }
# glslangValidator (Debian 12's) does not know EXT_shader_framebuffer_fetch: it checks those fragment
# shaders (FOGVOL_SPECIALIZE_FETCH_O, EXACT_SUM) with the extension line left out and the fetched
# inputs as plain outputs, which it reads; gl_compile compiles them as written with a driver that has it
grep -l "^#extension GL_EXT_shader_framebuffer_fetch" "$b/shaders"/*.frag |
  xargs -r sed -i -e '/^#extension GL_EXT_shader_framebuffer_fetch/d' -e 's/^layout(location = \([01]\)) inout /layout(location = \1) out /'
ls "$b/shaders"/*.vert "$b/shaders"/*.frag | LC_ALL=C sort > "$b/shaders/all_list"
# many files hold the same text: each text is compiled once, from its first file (in name order), and
# every file gets its text's result (file -> first file of the same contents, same stage)
xargs md5sum < "$b/shaders/all_list" |
  awk '{ stage = $2; sub(/.*\./, "", stage); key = $1 stage; if (!(key in first)) { first[key] = $2; print $2 > "/dev/stderr" }
         print $2, first[key] }' > "$b/shaders/same_as" 2> "$b/shaders/batch_list"
# batches of 100 files; each writes its output and exit status to its own files
split -l 100 -d -a 4 "$b/shaders/batch_list" "$b/shaders/batch_in_"
ls "$b/shaders"/batch_in_* | xargs -P "$jobs" -I{} sh -c \
  'xargs glslangValidator < "{}" > "{}.out" 2>&1; echo $? > "{}.rc"'
# glslangValidator prints each file's name on a line of its own, then that file's messages
for f in "$b/shaders"/batch_in_*[0-9]; do
  awk -v list="$f" -v rc="$(cat "$f.rc")" '
    BEGIN { while ((getline p < list) > 0) { order[++n] = p; want[p] = 1 } }
    ($0 in want) { cur = $0; seen[cur] = 1; next }
    cur != "" { if ($0 ~ /^ERROR/) bad[cur] = 1; if (cnt[cur] < 10 && $0 != "") msg[cur] = msg[cur] "#   " $0 "\n"; cnt[cur]++ }
    END {
      errs = 0
      for (i = 1; i <= n; ++i) {
        p = order[i]; name = p; sub(/.*\//, "", name)
        if (!(p in seen)) { print "not ok - " name " (no output from glslangValidator, exit " rc ")"; errs++ }
        else if (p in bad) { print "not ok - " name; printf "%s", msg[p]; errs++ }
        else print "ok - " name
      }
      if (rc != 0 && errs == 0) print "not ok - " list ": glslangValidator exited with " rc " without an ERROR line"
    }' "$f.out"
done > "$b/shaders.unique.tap"
# every file: the line of the first file with its text
awk 'FNR == NR { line = $0; name = $0; sub(/^(not )?ok - /, "", name); sub(/ .*/, "", name); res[name] = line
                 if ($0 ~ /^#/) { msg[last] = msg[last] "\n" $0 } else last = name; next }
     { f = $1; g = $2; sub(/.*\//, "", f); sub(/.*\//, "", g)
       if (!(g in res)) { print "not ok - " f " (its text was not compiled)"; next }
       r = res[g]; sub(/ - [^ ]*/, " - " f, r); print r msg[g] }' \
  "$b/shaders.unique.tap" "$b/shaders/same_as" > "$b/shaders.tap"
echo "# $(wc -l < "$b/shaders/all_list") shader files, $(wc -l < "$b/shaders/batch_list") different texts compiled"
rm -f "$b/shaders"/batch_* "$b/shaders/all_list" "$b/shaders/same_as" "$b/shaders.unique.tap"
awk '/^(ok|not ok) - /{ n++; sub(/ - /, " " n " - "); } { print } END { print "1.." n }' "$b/shaders.tap"
! grep -q "^not ok" "$b/shaders.tap"
