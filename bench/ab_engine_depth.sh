#!/bin/sh
# A/B of the FLOAT + ENGINE_DEPTH face program, one change at a time (issue 34): the benchmark
# built against copies of fogvol.h whose FLOAT face program differs in one thing, each run on one
# scene (bench --scene N, default 0: 16 spheres, no occluders); prints the per-pass breakdown rows
# of FLOAT, FLOAT + engine depth and the floor at 1280x720 for each build. Ratios are read within
# one build's run (FLOAT+engine depth B-F / FLOAT B-F), never across runs.
#   original   the engine's depth fetched per fragment and linearised per fragment
#   no-read    neither: o = 1 (what the face pass costs without the engine's depth)
#   fetch      the fetch, not the linearisation: o = the window depth as it is
#   linearise  the linearisation, not the fetch: o = linearised gl_FragCoord.z
# The variants draw wrong fog (they only time the program); the library is not changed.
# usage: bench/ab_engine_depth.sh [scene] (from the repository root; BUILD as for make)
set -e
SCENE=${1:-0}
DIR=${BUILD:-build}/ab_engine_depth
mkdir -p "$DIR"
python3 - "$DIR" <<'EOF'
import sys, os
d = sys.argv[1]
src = open('fogvol.h').read()
old = ('    "#ifdef FV_ENGINE_DEPTH\\n"\n'
       '    "    float z = FV_ENGINE_Z(fv_opaque);\\n"\n'
       '    "    float o = fv_engine_view_depth(fv_st(), z) * fv_nf.x + fv_nf.y;\\n"\n'
       '    "#else\\n"\n'
       '    "    float o = 1.0;\\n"')
assert src.count(old) == 1, 'the FLOAT face program changed: update bench/ab_engine_depth.sh'
def variant(line):
    return src.replace(old, '    "#ifdef FV_ENGINE_DEPTH\\n"\n' + line +
                       '    "#else\\n"\n    "    float o = 1.0;\\n"')
variants = {
    'original': src,
    'no-read': variant('    "    float o = 1.0;\\n"\n'),
    'fetch': variant('    "    float o = FV_ENGINE_Z(fv_opaque);\\n"\n'),
    'linearise': variant('    "    float o = fv_engine_view_depth(fv_st(), gl_FragCoord.z) * fv_nf.x + fv_nf.y;\\n"\n'),
}
for name, text in variants.items():
    os.makedirs(os.path.join(d, name), exist_ok=True)
    open(os.path.join(d, name, 'fogvol.h'), 'w').write(text)
EOF
for v in original no-read fetch linearise; do
    ${CC:-cc} -std=c99 -O2 -I"$DIR/$v" -I. bench/bench.c -o "$DIR/$v/bench" -lOSMesa -lm
done
for v in original no-read fetch linearise; do
    echo "== $v"
    "$DIR/$v/bench" --scene "$SCENE" 2>/dev/null | grep -E '^\| [^|]* \| (FLOAT|FLOAT\+engine depth|PS20|PS20\+engine depth|floor) \| [A-Zg]' || true
done
