/* Writes every existing shader -- tier x variant set x program x dialect x
   stage -- to DIR/<tier>_v<variants>_<program>_<dialect>.<vert|frag> for
   glslangValidator, and checks that combinations that do not exist give
   FOGVOL_ERROR_UNSUPPORTED and no strings. The per-sample fragment shaders
   (fogvol_shader_desc.samples = 4, where fogvol_msaa_supported) go to
   <tier>_v<variants>_<program>_<dialect>_ms.frag. The programs built for one configuration
   (fogvol_shader_desc.specialize) get _s<bits> before the extension; a program must refuse the
   bits it does not take (spec_applies). FOGVOL_SPECIALIZE_ENCODING(L) is taken by ENCODE and FACE for
   L = 1..8 and refused above; FOGVOL_SPECIALIZE_INLINE_RESOLVE by PS13's COMPOSITE, COMPOSITE_MESH
   and CHECK only; FOGVOL_SPECIALIZE_BLEND_COLOR by COMPOSITE and COMPOSITE_MESH with EXP,
   NO_COLOR_TEXTURE and NO_OVERFLOW only; FOGVOL_SPECIALIZE_FLOAT_O by the programs that write or read
   O (ENCODE, FACE, LIGHT) of MRT, PS20 and PS13 without WIDE and COUNT (ENGINE_DEPTH: PS20's) only;
   FOGVOL_SPECIALIZE_FETCH_O by single-sample FACE programs in GLSL 330 and 300 es that read O (not
   with NO_OPAQUE or COUNT, nor the COUNT, WIDE and COLORS variants, nor FLOAT with ENGINE_DEPTH);
   FOGVOL_SPECIALIZE_EXACT_SUM in GLSL 330 and 300 es by PS20's, MRT's and PS13's FACE (with NO_DENSITY,
   single-sample), COMPOSITE and COMPOSITE_MESH where FLOAT_O could be (not WIDE, COUNT, SINGLE_TARGET;
   ENGINE_DEPTH: PS20's), not with COUNT.
   The Vulkan dialect (FOGVOL_GLSL_VULKAN, SPIR-V) goes apart: `dump_shaders --vulkan DIR` writes only
   its shaders (tests/vulkan_shaders.sh compiles them with glslangValidator -V), `dump_shaders DIR`
   only the GL dialects' (tests/shaders.sh, gl_compile). */
#define FOGVOL_IMPLEMENTATION
#define FOGVOL_NO_GL
#include "fogvol.h"
#include <stdio.h>
#include <string.h>

/* The documented rule of fogvol_shader_desc.specialize: which bits a program takes. */
static int spec_applies(int p, unsigned bits)
{
    const unsigned face = FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_OPAQUE;
    const unsigned comp = FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                          FOGVOL_SPECIALIZE_NO_OVERFLOW | FOGVOL_SPECIALIZE_FAST_EXP;
    if ((bits & FOGVOL_SPECIALIZE_EXP) && (bits & FOGVOL_SPECIALIZE_RAMP)) return 0;
    if ((bits & FOGVOL_SPECIALIZE_OPAQUE) && (bits & FOGVOL_SPECIALIZE_NO_OPAQUE)) return 0;
    bits &= ~(unsigned)(FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DEPTH_FROM_Z); /* every program takes them */
    if (bits & FOGVOL_SPECIALIZE_BLEND_COLOR) { /* a composite of one colour */
        const unsigned one = FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW;
        if ((p != FOGVOL_PROGRAM_COMPOSITE && p != FOGVOL_PROGRAM_COMPOSITE_MESH) || (bits & one) != one) return 0;
        bits &= ~(unsigned)FOGVOL_SPECIALIZE_BLEND_COLOR;
    }
    if ((bits & FOGVOL_SPECIALIZE_ENCODING_MASK) > FOGVOL_SPECIALIZE_ENCODING(8)) return 0; /* L = 1..8 */
    if (p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_ENCODE)
        bits &= ~(unsigned)(FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING_MASK);
    if (!bits) return 1;
    if (p == FOGVOL_PROGRAM_FACE) return (bits & ~face) == 0;
    if (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH) return (bits & ~comp) == 0;
    return 0;
}

/* FOGVOL_SPECIALIZE_COUNT: the COUNT variant's ENCODE, FACE (with NO_DENSITY), RESOLVE and COMPOSITE,
   for PS20 and PS13 whose variants COUNT can join (not SINGLE_TARGET, WIDE, ENGINE_DEPTH, COLORS) */
static int variant_spec_applies(int t, unsigned v, int d, int p, unsigned bits, int ms)
{
    /* FLOAT + ENGINE_DEPTH (not COLORS, NEAR_CLAMP); the face single-sample (multisampled frames shade it once
       per pixel), the composite per sample too */
    if (bits & FOGVOL_SPECIALIZE_ENGINE_TEST)
        return t == FOGVOL_TIER_FLOAT && (v & FOGVOL_VARIANT_ENGINE_DEPTH) &&
               !(v & (FOGVOL_VARIANT_COLORS | FOGVOL_VARIANT_NEAR_CLAMP)) &&
               ((p == FOGVOL_PROGRAM_FACE && !ms && (bits & FOGVOL_SPECIALIZE_NO_DENSITY)) || p == FOGVOL_PROGRAM_COMPOSITE) &&
               !(bits & (FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED | FOGVOL_SPECIALIZE_EXACT_SUM |
                         FOGVOL_SPECIALIZE_FETCH_O)) &&
               variant_spec_applies(t, v, d, p, bits & ~(unsigned)FOGVOL_SPECIALIZE_ENGINE_TEST, ms);
    if (bits & FOGVOL_SPECIALIZE_EXACT_SUM)
        return (t == FOGVOL_TIER_MRT || t == FOGVOL_TIER_PS20 || t == FOGVOL_TIER_PS13) &&
               !(v & (FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_SINGLE_TARGET)) &&
               !(t != FOGVOL_TIER_PS20 && (v & FOGVOL_VARIANT_ENGINE_DEPTH)) &&
               !(bits & FOGVOL_SPECIALIZE_COUNT) &&
               (d == FOGVOL_GLSL_330 || d == FOGVOL_GLSL_300ES) &&
               (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH ||
                (p == FOGVOL_PROGRAM_FACE && !ms && (bits & FOGVOL_SPECIALIZE_NO_DENSITY))) &&
               variant_spec_applies(t, v, d, p, bits & ~(unsigned)FOGVOL_SPECIALIZE_EXACT_SUM, ms);
    if (bits & FOGVOL_SPECIALIZE_FETCH_O)
        return p == FOGVOL_PROGRAM_FACE && !ms && (d == FOGVOL_GLSL_330 || d == FOGVOL_GLSL_300ES) &&
               !(v & (FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_COLORS)) &&
               !(t == FOGVOL_TIER_FLOAT && (v & FOGVOL_VARIANT_ENGINE_DEPTH)) &&
               !(bits & (FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_COUNT)) &&
               variant_spec_applies(t, v, d, p, bits & ~(unsigned)FOGVOL_SPECIALIZE_FETCH_O, ms);
    if (bits & FOGVOL_SPECIALIZE_FLOAT_O)
        return (t == FOGVOL_TIER_MRT || t == FOGVOL_TIER_PS20 || t == FOGVOL_TIER_PS13) &&
               !(v & (FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_COUNT)) &&
               !(t != FOGVOL_TIER_PS20 && (v & FOGVOL_VARIANT_ENGINE_DEPTH)) &&
               !(bits & FOGVOL_SPECIALIZE_COUNT) &&
               (p == FOGVOL_PROGRAM_ENCODE || p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_LIGHT) &&
               variant_spec_applies(t, v, d, p, bits & ~(unsigned)FOGVOL_SPECIALIZE_FLOAT_O, ms);
    if (bits & FOGVOL_SPECIALIZE_INLINE_RESOLVE)
        return t == FOGVOL_TIER_PS13 &&
               (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH || p == FOGVOL_PROGRAM_CHECK) &&
               variant_spec_applies(t, v, d, p, bits & ~(unsigned)FOGVOL_SPECIALIZE_INLINE_RESOLVE, ms);
    if ((bits & FOGVOL_SPECIALIZE_FILTERED) && !(bits & FOGVOL_SPECIALIZE_DOWNSAMPLE)) return 0;
    if (bits & FOGVOL_SPECIALIZE_DOWNSAMPLE) /* FLOAT's composite (not COLORS), single-sample; FILTERED with it */
        return t == FOGVOL_TIER_FLOAT && !(v & FOGVOL_VARIANT_COLORS) && !ms && p == FOGVOL_PROGRAM_COMPOSITE &&
               variant_spec_applies(t, v, d, p,
                                    bits & ~(unsigned)(FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED), ms);
    const unsigned no = FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_WIDE |
                        FOGVOL_VARIANT_ENGINE_DEPTH | FOGVOL_VARIANT_COLORS;
    if (!(bits & FOGVOL_SPECIALIZE_COUNT)) return spec_applies(p, bits);
    if ((t != FOGVOL_TIER_PS20 && t != FOGVOL_TIER_PS13) || (v & no) ||
        fogvol_combination_supported((fogvol_tier)t, v | FOGVOL_VARIANT_COUNT, (fogvol_dialect)d) != FOGVOL_SUCCESS)
        return 0;
    if (p == FOGVOL_PROGRAM_FACE && !(bits & FOGVOL_SPECIALIZE_NO_DENSITY)) return 0;
    if (p != FOGVOL_PROGRAM_ENCODE && p != FOGVOL_PROGRAM_FACE && p != FOGVOL_PROGRAM_RESOLVE &&
        p != FOGVOL_PROGRAM_COMPOSITE)
        return 0;
    return p == FOGVOL_PROGRAM_RESOLVE ? (bits & ~(unsigned)(FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN)) == 0
                                       : spec_applies(p, bits & ~(unsigned)FOGVOL_SPECIALIZE_COUNT);
}

int main(int argc, char **argv)
{
    static const char *const prog[FOGVOL_PROGRAM_COUNT] = {"encode", "face", "composite", "composite_mesh",
                                                           "resolve", "check", "light", "color_face", "color_composite"};
    static const char *const dia[FOGVOL_GLSL_COUNT] = {"auto", "110", "120", "130", "150", "330", "100", "300es",
                                                       "vulkan"};
    static const unsigned specs[] = {0,
                                     FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_RAMP,
                                     FOGVOL_SPECIALIZE_ORIGIN,
                                     FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_FAST_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_NO_OVERFLOW | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_OPAQUE,
                                     FOGVOL_SPECIALIZE_OPAQUE | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_NO_OPAQUE |
                                         FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_COUNT,
                                     FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN,
                                     FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY |
                                         FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_FAST_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_DOWNSAMPLE,
                                     FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_FAST_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_FILTERED,
                                     FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED,
                                     FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED | FOGVOL_SPECIALIZE_ORIGIN |
                                         FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_FAST_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_ENCODING(1),
                                     FOGVOL_SPECIALIZE_ENCODING(4) | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY |
                                         FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_ENCODING(7) | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_ENCODING(8) | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN |
                                         FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_DITHER,
                                     FOGVOL_SPECIALIZE_INLINE_RESOLVE,
                                     FOGVOL_SPECIALIZE_INLINE_RESOLVE | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_ORIGIN |
                                         FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_FAST_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_INLINE_RESOLVE | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_RAMP,
                                     FOGVOL_SPECIALIZE_INLINE_RESOLVE | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_FAST_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_INLINE_RESOLVE |
                                         FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_DOWNSAMPLE |
                                         FOGVOL_SPECIALIZE_FILTERED | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_DEPTH_FROM_Z | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY |
                                         FOGVOL_SPECIALIZE_OPAQUE,
                                     FOGVOL_SPECIALIZE_DEPTH_FROM_Z | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DITHER |
                                         FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_FLOAT_O,
                                     FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY |
                                         FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_INLINE_RESOLVE |
                                         FOGVOL_SPECIALIZE_RAMP,
                                     FOGVOL_SPECIALIZE_FETCH_O,
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_NO_DENSITY |
                                         FOGVOL_SPECIALIZE_OPAQUE,
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_FLOAT_O | FOGVOL_SPECIALIZE_ORIGIN |
                                         FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_DITHER |
                                         FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_DITHER |
                                         FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_NO_OPAQUE,
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE,
                                     FOGVOL_SPECIALIZE_EXACT_SUM,
                                     FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_NO_OPAQUE |
                                         FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_FLOAT_O |
                                         FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_ORIGIN |
                                         FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING(4),
                                     FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_EXP |
                                         FOGVOL_SPECIALIZE_FAST_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW | FOGVOL_SPECIALIZE_BLEND_COLOR,
                                     FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_ORIGIN,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_OPAQUE,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DEPTH_FROM_Z |
                                         FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_FAST_EXP |
                                         FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW |
                                         FOGVOL_SPECIALIZE_BLEND_COLOR,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DEPTH_FROM_Z |
                                         FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                         FOGVOL_SPECIALIZE_NO_OVERFLOW,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_DOWNSAMPLE,
                                     FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_NO_DENSITY,
                                     FOGVOL_SPECIALIZE_ENCODING(9),
                                     FOGVOL_SPECIALIZE_ENCODING(15) | FOGVOL_SPECIALIZE_NO_DENSITY};
    int vulkan = argc > 1 && strcmp(argv[1], "--vulkan") == 0;
    const char *dir = argc > 1 + vulkan ? argv[1 + vulkan] : ".";
    int t, p, d, st, n = 0, refused = 0, ms, k;
    unsigned v;
    for (k = 0; k < (int)(sizeof specs / sizeof specs[0]); ++k)
    for (ms = 0; ms < 2; ++ms)
    for (t = 1; t < FOGVOL_TIER_COUNT; ++t)
        for (v = 0; v <= FOGVOL_VARIANT_ALL; ++v)
            for (d = 1; d < FOGVOL_GLSL_COUNT; ++d)
                for (p = 0; p < FOGVOL_PROGRAM_COUNT; ++p)
                    for (st = 0; st < 2; ++st) {
                        fogvol_shader_desc sd;
                        const char *s[FOGVOL_MAX_SHADER_STRINGS];
                        int count = -1, i;
                        char path[512];
                        FILE *f;
                        fogvol_result r;
                        sd.tier = (fogvol_tier)t;
                        sd.variants = v;
                        sd.program = (fogvol_program)p;
                        sd.dialect = (fogvol_dialect)d;
                        sd.stage = (fogvol_stage)st;
                        sd.samples = ms ? 4 : 0;
                        sd.specialize = specs[k];
                        if (ms && st == FOGVOL_STAGE_VERTEX) continue; /* the same as single-sample */
                        if ((d == FOGVOL_GLSL_VULKAN) != vulkan) continue;
                        r = fogvol_shader_strings(&sd, s, &count);
                        if (fogvol_combination_supported((fogvol_tier)t, v, (fogvol_dialect)d) != FOGVOL_SUCCESS ||
                            !variant_spec_applies(t, v, d, p, specs[k], ms) ||
                            !fogvol_tier_uses_program((fogvol_tier)t, v, (fogvol_program)p) ||
                            (ms && fogvol_msaa_supported((fogvol_tier)t, v, (fogvol_dialect)d) != FOGVOL_SUCCESS)) {
                            if (r != FOGVOL_ERROR_UNSUPPORTED || count != 0) {
                                fprintf(stderr, "a combination that does not exist gave strings\n");
                                return 1;
                            }
                            ++refused;
                            continue;
                        }
                        if (r != FOGVOL_SUCCESS || count < 3 || count > FOGVOL_MAX_SHADER_STRINGS) {
                            fprintf(stderr, "missing: %s v%u %s %s\n", fogvol_tier_name((fogvol_tier)t), v, prog[p],
                                    dia[d]);
                            return 1;
                        }
                        snprintf(path, sizeof path, "%s/%s_v%02u_%s_%s%s%s%.0u.%s", dir, fogvol_tier_name((fogvol_tier)t),
                                 v, prog[p], dia[d], ms ? "_ms" : "", specs[k] ? "_s" : "", specs[k],
                                 st ? "frag" : "vert");
                        f = fopen(path, "w");
                        if (!f) return 1;
                        for (i = 0; i < count; ++i) fputs(s[i], f);
                        fclose(f);
                        ++n;
                    }
    /* image-space effects: every effect variant in every dialect (post_<effect><variant>_<dialect>) */
    {
        static const int eff[8] = {FOGVOL_POST_DOF,      FOGVOL_POST_DOF,      FOGVOL_POST_DOF,
                                   FOGVOL_POST_DOF,      FOGVOL_POST_DOF,      FOGVOL_POST_OUTLINES,
                                   FOGVOL_POST_OUTLINES, FOGVOL_POST_DISTANCE_FOG};
        static const int var[8] = {3, 6, 12, 24, 48, 0, 1, 0};
        static const char *const ename[FOGVOL_POST_EFFECT_COUNT] = {"dof", "outlines", "fog"};
        int e;
        for (e = 0; e < 8; ++e)
            for (d = 1; d < FOGVOL_GLSL_COUNT; ++d)
                for (st = 0; st < 2; ++st) {
                    const char *s[FOGVOL_MAX_SHADER_STRINGS];
                    if ((d == FOGVOL_GLSL_VULKAN) != vulkan) continue;
                    int count = -1, i;
                    char path[512];
                    FILE *f;
                    if (fogvol_post_shader_strings((fogvol_post_effect)eff[e], var[e], (fogvol_dialect)d,
                                                   (fogvol_stage)st, s, &count) != FOGVOL_SUCCESS || count < 3) {
                        fprintf(stderr, "missing: post %s %d %s\n", ename[eff[e]], var[e], dia[d]);
                        return 1;
                    }
                    snprintf(path, sizeof path, "%s/post_%s%d_%s.%s", dir, ename[eff[e]], var[e], dia[d],
                             st ? "frag" : "vert");
                    f = fopen(path, "w");
                    if (!f) return 1;
                    for (i = 0; i < count; ++i) fputs(s[i], f);
                    fclose(f);
                    ++n;
                }
        if (fogvol_post_shader_strings(FOGVOL_POST_DOF, 5, FOGVOL_GLSL_330, FOGVOL_STAGE_FRAGMENT, NULL, NULL) !=
            FOGVOL_ERROR_INVALID_ARGUMENT) {
            fprintf(stderr, "post shader strings without an output accepted\n");
            return 1;
        }
    }
    printf("%d shaders written to %s; %d combinations refused with FOGVOL_ERROR_UNSUPPORTED\n", n, dir, refused);
    return 0;
}
