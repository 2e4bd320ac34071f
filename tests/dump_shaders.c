/* Writes every shader string combination to DIR/<tier>_<program>_<dialect>.<vert|frag>
   (or reports that the combination is unsupported) for glslangValidator. */
#define FOGVOL_IMPLEMENTATION
#define FOGVOL_NO_GL
#include "fogvol.h"
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    static const char *const prog[FOGVOL_PROGRAM_COUNT] = {"encode", "face", "composite", "composite_mesh"};
    static const char *const dia[FOGVOL_GLSL_COUNT] = {"auto", "110", "120", "130", "150", "330", "100", "300es"};
    const char *dir = argc > 1 ? argv[1] : ".";
    int p, d, st, n = 0;
    for (p = 0; p < FOGVOL_PROGRAM_COUNT; ++p)
        for (d = 1; d < FOGVOL_GLSL_COUNT; ++d)
            for (st = 0; st < 2; ++st) {
                const char *s[FOGVOL_MAX_SHADER_STRINGS];
                int count = 0, i;
                char path[512];
                FILE *f;
                if (fogvol_shader_source(FOGVOL_TIER_PS20, (fogvol_program)p, (fogvol_dialect)d,
                                         (fogvol_stage)st, s, &count) != FOGVOL_SUCCESS) {
                    fprintf(stderr, "missing: ps20 %s %s\n", prog[p], dia[d]);
                    return 1;
                }
                snprintf(path, sizeof path, "%s/ps20_%s_%s.%s", dir, prog[p], dia[d], st ? "frag" : "vert");
                f = fopen(path, "w");
                if (!f) return 1;
                for (i = 0; i < count; ++i) fputs(s[i], f);
                fclose(f);
                ++n;
            }
    /* unsupported combinations give a result code, never a string */
    {
        const char *s[FOGVOL_MAX_SHADER_STRINGS];
        int count = 7;
        if (fogvol_shader_source(FOGVOL_TIER_PS20, FOGVOL_PROGRAM_COUNT, FOGVOL_GLSL_330, FOGVOL_STAGE_VERTEX, s,
                                 &count) != FOGVOL_ERROR_UNSUPPORTED || count != 0)
            return 1;
        if (fogvol_shader_source(FOGVOL_TIER_PS20, FOGVOL_PROGRAM_FACE, FOGVOL_GLSL_AUTO, FOGVOL_STAGE_VERTEX, s,
                                 &count) != FOGVOL_ERROR_UNSUPPORTED)
            return 1;
    }
    printf("%d shaders written to %s\n", n, dir);
    return 0;
}
