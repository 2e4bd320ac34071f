#!/usr/bin/env python3
"""Seed inputs for tests/fuzz/fuzz_api.c: byte sequences that its reader turns into meaningful API
sequences (contexts that exist, meshes and ramps that are valid, frames that draw), so that the
fuzzer starts from inputs that reach deep into end_frame instead of from empty ones.

usage: tests/fuzz/seed_api.py DIR      (writes DIR/seed_NN; libFuzzer then grows and mutates them)

The byte layout follows the reader in fuzz_api.c call by call; change both together."""
import os
import sys


def context(gl=False, tier=2, variants=0, caps=1, dialect=5, queries=0, samples=0, overflow=0, msaa=0, leave=0,
            preferred=None, loader=0, speedups_off=0):
    b = [(3 if gl else 0) | (4 if leave else 0)]
    b += [tier, variants] + ([2, preferred] if preferred is not None else [0])
    b += [overflow, msaa, 1]  # encoding_bits byte 1 -> 0 (default)
    b += [1] + [(speedups_off >> k) & 255 for k in (0, 8, 16, 24)] if speedups_off else [0]
    b += [0, 0]  # dither on, engine_mrt 0
    if gl:
        b += [0, 0, loader << 1]  # dialect: not 9 -> next byte % 9 = 0 (from the context); the loader
    else:
        b += [caps, dialect, queries, 0, 5, samples, 0]
    return b


def mesh(slot=0, kind=0, weld=3, open_=1):
    b = [0, slot, kind]
    if kind in (0, 1, 2, 3):
        b += [1] if kind == 0 else [4, 2] if kind in (1, 3) else [2]
    b += [1]  # no transform
    if kind == 4:
        b += [0]  # every corner
    if kind in (5, 6):
        b += [2, 1, 1, 1]  # stride 20, offset 4, both kept
    b += [open_, weld, 1, 0]  # allow_open byte, weld selector, index_type kept, no report
    return b


def ramp(slot=0, density=3, model=0, blend=0, keys=0):
    return [3, slot, model, 0, 0, 0, 1, density, 1, keys] + [1, 1, 1, 1, 1] * keys + [1, 0, blend, 1, 1, 1]


def texture(slot=0, w=2, h=2):
    return [6, slot, w, h, 1] + [200] * (w * h * 4) + [1, 1, 1]


def begin(w=63, h=63, composite=1, show=1, downsample=1, depth_tex=0, source=0, camkind=9, debug=1):
    cam = [4, 50, camkind, 4, 4, 8, 1, 40, 1] + ([1] if camkind == 5 else [])  # (5: the forward kept)
    b = [8, 0] + cam + [w, h, 4, 4, composite, 1, 1, 1, show, downsample, 1, depth_tex, 1, 1, source, 1, debug]
    return b + ([0] if debug == 0 else [])  # the read-back on: for the first group


def volume(mesh_slot=0, ramp_slot=0, matrix=(7,), negative=1, density_tex=False, color_tex=False):
    b = [10, mesh_slot, ramp_slot] + list(matrix) + [negative]
    b += [0, 0] if density_tex else [1]
    b += [0, 0] if color_tex else [1]
    return b + [1, 1]


def occluder(mesh_slot=0):
    return [13, 1, mesh_slot, 7, 1]


def light(mesh_slot=0):
    return [14, mesh_slot, 7, 0, 1, 1]


def end():
    return [15, 1]


def occluder_callback():  # its model matrix comes from the byte after the end_frame that calls it
    return [13, 0, 1]


def validate(kind=0):
    return [21] + mesh(kind=kind)[2:]


def prepare(which):
    return [18, which, 1]


def post(which):
    if which == 0:
        return [19, 0, 1, 1, 1, 1, 1, 1, 6]
    if which == 1:
        return [19, 1, 1, 0, 0, 1, 1]
    return [19, 2, 1, 0, 1]


def frames(k, n=3, **kw):
    return sum((frame_seq(n, **kw) for _ in range(k)), [])


def frame_seq(n=3, **kw):
    b = begin(**kw)
    for i in range(n):
        b += volume(matrix=(0, 3, 16 + 2 * i - 2, 16, 16)) if i else volume()
    return b + end()


SEEDS = [
    context() + mesh() + ramp() + frame_seq() + frame_seq(composite=0, depth_tex=1) + post(0) + post(1) + post(2),
    context(tier=4, variants=0x40, caps=2) + mesh() + ramp() + ramp(1, density=8) + frame_seq(4),
    context(gl=True, tier=4) + mesh() + ramp() + frame_seq() + frame_seq(composite=0, downsample=2),
    context(gl=True, tier=2) + mesh() + ramp() + frame_seq() + frame_seq(show=0),
    context(gl=True, tier=3) + mesh() + ramp() + begin() + prepare(1) + volume() + end(),
    context(tier=2) + mesh() + mesh(1, kind=0) + ramp() + begin() + occluder(1) + volume() + end()
    + begin() + prepare(0) + volume() + end(),
    context(tier=4, caps=2) + mesh() + ramp() + begin() + light() + volume() + end(),
    context(tier=2) + mesh(kind=2, weld=0) + mesh(1, kind=4, weld=0) + ramp() + begin() + volume(0)
    + volume(1) + end(),
    context(tier=2, queries=1, overflow=2) + mesh() + ramp() + frame_seq() * 1 + frame_seq() + frame_seq(),
    context(gl=True, tier=4) + mesh() + ramp() + frame_seq(depth_tex=1) + post(0) + post(1) + post(2),
    context(tier=1, caps=0) + mesh() + ramp() + frame_seq(),
    context(tier=2, variants=0x02) + mesh() + ramp() + frame_seq(),
    context(tier=2, variants=0x01) + mesh() + ramp() + frame_seq(),
    context(tier=2, variants=0x20, caps=1) + mesh() + ramp() + frame_seq(),
    context(tier=4, caps=3, samples=4) + mesh() + ramp() + frame_seq(),
    context(tier=2) + mesh(kind=5, weld=3) + mesh(1, kind=6, weld=3) + ramp() + texture() + begin()
    + volume(0, density_tex=True, color_tex=True) + volume(1) + end(),
    context(gl=True, tier=4, variants=0x10) + mesh() + ramp() + frame_seq(depth_tex=1) + frame_seq(source=1),
    context(tier=2) + mesh(kind=1) + mesh(1, kind=3) + ramp() + ramp(1, model=2, keys=1) + begin(camkind=0)
    + volume(0) + volume(1, 1) + end() + begin(camkind=1) + volume(0) + end() + begin(camkind=5) + volume(1) + end(),
    context(leave=1) + mesh() + mesh(1, kind=2, weld=0) + ramp() + ramp(1) + texture() + frame_seq(),
    context(gl=True, tier=2, leave=1) + mesh() + ramp() + texture() + begin() + volume(0, density_tex=True) + end(),
    context(tier=0, preferred=0x52, caps=2) + mesh() + ramp() + frame_seq(),
    context(gl=True, tier=0, preferred=0x10, loader=1) + mesh() + ramp() + frame_seq(depth_tex=1),
    context(gl=True, tier=2, loader=2) + mesh() + ramp() + frame_seq(),
    # the paths the first corpus did not reach (gcov of its replay)
    context(tier=4, variants=0x40, caps=2) + mesh() + ramp() + ramp(1, density=9) + frame_seq(4, composite=0),
    context(gl=True, tier=4) + mesh() + ramp() + frame_seq(debug=0) + frame_seq(debug=0, composite=0),
    context(gl=True, tier=2) + mesh(kind=3) + ramp() + frames(3, debug=0, show=0),
    context(tier=2, variants=0x01) + mesh(kind=3) + ramp() + frame_seq(debug=0) + frame_seq(show=0),
    context(tier=4, caps=3) + mesh() + ramp() + frame_seq(downsample=2, debug=0),
    context(tier=2, queries=1, overflow=2) + mesh(kind=3) + ramp() + frames(4),
    context(tier=1, queries=1, caps=1) + mesh(kind=3) + ramp() + frames(3, debug=0),
    context(gl=True, tier=1) + mesh(kind=3) + ramp() + frames(2, debug=0),
    context(gl=True, tier=3) + mesh() + ramp() + begin(debug=0) + prepare(1) + volume() + end(),
    context(gl=True, tier=2, variants=0x10) + mesh() + ramp() + frame_seq(depth_tex=1, debug=0),
    context(gl=True, tier=4) + mesh() + mesh(1, kind=3) + ramp() + begin() + light() + occluder(1) + volume()
    + end() + begin() + prepare(0) + volume() + end(),
    context(gl=True, tier=2) + mesh() + mesh(1) + ramp() + begin() + occluder(1) + light() + volume() + end(),
    context(gl=True, tier=2, speedups_off=(1 << 13) | (1 << 14)) + mesh(kind=3) + ramp() + frames(3, debug=0),
    context(tier=2, variants=0x20) + mesh() + ramp() + frame_seq(debug=0),
    context(tier=2) + mesh() + ramp() + begin() + occluder_callback() + volume() + end() + [7] + [20, 1]
    + validate(3) + validate(7),
    context(gl=True, tier=4) + mesh() + ramp() + begin() + occluder_callback() + volume() + end() + [7],
]


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for i, s in enumerate(SEEDS):
        with open(os.path.join(out, "seed_%02d" % i), "wb") as f:
            f.write(bytes(x & 255 for x in s))


if __name__ == "__main__":
    main()
