#!/usr/bin/env bash
# Runs every test command given as "name=command", counts TAP lines
# ("ok ..." / "not ok ...") and prints one closing line "N passed, M failed".
# A command that exits non-zero without reporting a failure counts as one failure.
set -u
logdir=${LOGDIR:-build/logs}
mkdir -p "$logdir"
pass=0; fail=0
for spec in "$@"; do
  name=${spec%%=*}; cmd=${spec#*=}
  echo "=== $name"
  log="$logdir/$name.log"
  bash -c "$cmd" > "$log" 2>&1
  rc=$?
  cat "$log"
  p=$(grep -cE '^ok [0-9]+' "$log" || true)
  f=$(grep -cE '^not ok [0-9]+' "$log" || true)
  if [ "$rc" = 0 ] && [ "$p" = 0 ] && [ "$f" = 0 ]; then
    p=1 # a program without TAP output passes by its exit status
  fi
  if [ "$rc" != 0 ] && [ "$f" = 0 ]; then
    echo "not ok - $name exited with status $rc"
    f=1
  fi
  pass=$((pass + p)); fail=$((fail + f))
done
echo
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
