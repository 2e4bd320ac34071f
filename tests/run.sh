#!/usr/bin/env bash
# Runs every test command given as "name=command", counts TAP lines
# ("ok ..." / "not ok ...") and prints one closing line "N passed, M failed".
# A command that exits non-zero without reporting a failure counts as one failure.
# Up to JOBS commands (default: the number of cores) run at once, each into its own
# log under LOGDIR; the logs are printed in the order the commands were given, each
# as soon as it and every one before it have finished, so the output is the same
# whatever the timing. The commands start longest first: by the CPU time (user + sys) each
# took in the last run with this LOGDIR (LOGDIR/durations, else the file DURATIONS names: make test's
# tests/durations); those without one start first, in the order given. Each log's header line says
# the command's wall and CPU time.
set -u
logdir=${LOGDIR:-build/logs}
jobs=${JOBS:-$(nproc 2> /dev/null || echo 2)}
[ "$jobs" -ge 1 ] 2> /dev/null || jobs=1
mkdir -p "$logdir"
names=(); cmds=()
for spec in "$@"; do
  names+=("${spec%%=*}"); cmds+=("${spec#*=}")
done
total=${#names[@]}
for ((i = 0; i < total; ++i)); do rm -f "$logdir/${names[i]}.log" "$logdir/${names[i]}.rc"; done
order=() # the indices in the order the commands start
durations=$logdir/durations
[ -f "$durations" ] || durations=${DURATIONS:-/dev/null}
while read -r _ i; do order+=("$i"); done < <(
  for ((i = 0; i < total; ++i)); do
    t=$(awk -v n="${names[i]}" '$1 == n { print $2 }' "$durations" 2> /dev/null)
    echo "${t:-1e9} $i"
  done | sort -s -k1,1gr)
: > "$logdir/durations.new"

pass=0; fail=0; shown=0
# report I: print job I's log and add its counts
report() {
  local name=${names[$1]} log="$logdir/${names[$1]}.log" rc p f
  rc=$(cat "$logdir/$name.rc")
  echo "=== $name ($(cat "$logdir/$name.time" 2> /dev/null || echo ?))"
  sed -n 's/.*cpu \([0-9.]*\)+\([0-9.]*\) s$/\1 \2/p' "$logdir/$name.time" 2> /dev/null |
    awk -v n="$name" '{ print n, $1 + $2 }' >> "$logdir/durations.new"
  cat "$log"
  p=$(grep -cE '^ok [0-9]+' "$log" || true)
  f=$(grep -E '^not ok [0-9]+' "$log" | grep -vc '# SKIP' || true) # cmocka writes a skipped test as "not ok N # SKIP"
  if [ "$rc" = 0 ] && [ "$p" = 0 ] && [ "$f" = 0 ]; then
    p=1 # a program without TAP output passes by its exit status
  fi
  if [ "$rc" != 0 ] && [ "$f" = 0 ]; then
    echo "not ok - $name exited with status $rc"
    f=1
  fi
  pass=$((pass + p)); fail=$((fail + f))
  rm -f "$logdir/$name.rc" "$logdir/$name.time"
}
# print every finished job at the head of the list
flush() {
  while [ "$shown" -lt "$total" ] && [ -f "$logdir/${names[shown]}.rc" ]; do
    report "$shown"; shown=$((shown + 1))
  done
}
for i in "${order[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do
    wait -n; flush
  done
  ( TIMEFORMAT='%1R s, cpu %1U+%1S s'
    { time bash -c "${cmds[i]}" > "$logdir/${names[i]}.log" 2>&1; } 2> "$logdir/${names[i]}.time"
    rc=$?
    # the last line is the time; any before it is bash's word on the command (killed by a signal) for its log
    head -n -1 "$logdir/${names[i]}.time" >> "$logdir/${names[i]}.log"
    sed -i '$!d' "$logdir/${names[i]}.time"
    echo $rc > "$logdir/${names[i]}.rc.tmp" && mv "$logdir/${names[i]}.rc.tmp" "$logdir/${names[i]}.rc" ) &
done
wait
flush
awk '{ cpu += $2 } END { printf "# %d commands, %.0f s of CPU (user + sys)\n", NR, cpu }' "$logdir/durations.new"
# the times of this run, and those of commands it did not run (make check and make test share a LOGDIR)
awk 'NR == FNR { seen[$1] = 1; next } !($1 in seen)' "$logdir/durations.new" "$logdir/durations" \
  >> "$logdir/durations.new" 2> /dev/null
mv "$logdir/durations.new" "$logdir/durations"
echo
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
