#!/usr/bin/env bash
# The doc block's API INDEX names every public function of fogvol.h once, and nothing else; its
# SECTIONS list names every section banner of the implementation, in the file's order. TAP.
set -u
cd "$(dirname "$0")/.."
n=0
check() { # description, condition output (empty = ok)
  n=$((n + 1))
  if [ -z "$2" ]; then echo "ok $n - $1"; else echo "not ok $n - $1"; echo "$2" | sed 's/^/#   /'; fi
}
doc_end=$(grep -n '^#ifndef FOGVOL_H' fogvol.h | head -1 | cut -d: -f1)
decl_end=$(grep -n '^/\* >>cpu' fogvol.h | head -1 | cut -d: -f1)
declared=$(head -n "$decl_end" fogvol.h | tr '\n' ' ' | grep -oE 'FOGVOL_API [^;{]*;' |
           grep -oE 'fogvol_[a-z0-9_]+ *\(' | tr -d ' (' | sort -u)
index=$(head -n "$doc_end" fogvol.h | sed -n '/API INDEX/,/^   BUILDING/p' |
        grep -oE '^   [a-z]* +fogvol_[a-z0-9_]+|^ {16}fogvol_[a-z0-9_]+' | grep -oE 'fogvol_[a-z0-9_]+')
check "the API INDEX names every public function ($(echo "$declared" | wc -l) declared)" \
  "$(comm -23 <(echo "$declared") <(echo "$index" | sort -u) | sed 's/^/missing from the index: /')"
check "the API INDEX names only public functions" \
  "$(comm -13 <(echo "$declared") <(echo "$index" | sort -u) | sed 's/^/not declared: /')"
check "the API INDEX names each function once" "$(echo "$index" | sort | uniq -d | sed 's/^/twice: /')"
banners=$(grep -oE '^/\* >>[a-z][a-z -]*[a-z]' fogvol.h | sed 's#^/\* >>##')
listed=$(head -n "$doc_end" fogvol.h | sed -n '/SECTIONS (search/,/\*\//p' | grep -oE '>>[a-z][a-z -]*[a-z]' |
         sed 's/^>>//; s/  .*//')
check "the SECTIONS list names every banner in the file's order" \
  "$(diff <(echo "$banners") <(echo "$listed"))"
echo "1..$n"
