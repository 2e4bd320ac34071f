/* libFuzzer target: the analytic fog input. The bytes become up to 8 volume
   descriptions (shape, colour, density, distances, plane, sphere, matrix),
   an eye, a few vertices and the law/mix; fogvol_analytic_prepare, _eval,
   _batch (every kernel) and _segment must never crash, never read out of
   bounds and never return NaN or values outside [0, 1] for fog. */
#ifndef FOGVOL_TEST_LINKED /* make test links fogvol's implementation built once (Makefile: FUZZ_IMPL) */
#define FOGVOL_IMPLEMENTATION
#endif
#define FOGVOL_NO_GL
#include "fogvol.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int in01(float v) { return v >= 0.0f && v <= 1.0f; } /* false for NaN */

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fogvol_analytic_volume vols[8];
    fogvol_analytic_set set;
    fogvol_analytic_order order;
    float eye[3], pos[4 * 3], fog[4], col[4 * 3];
    size_t need = sizeof eye + sizeof pos + 2;
    int n, i, k, invalid = 0;
    fogvol_fog_law law;
    fogvol_fog_mix mix;
    if (size < need + 1) return 0;
    law = (fogvol_fog_law)(data[0] % 3);
    mix = (fogvol_fog_mix)(data[1] % 2);
    memcpy(eye, data + 2, sizeof eye);
    memcpy(pos, data + 2 + sizeof eye, sizeof pos);
    data += need;
    size -= need;
    n = (int)(size / sizeof(fogvol_analytic_volume));
    if (n > 8) n = 8;
    memset(vols, 0, sizeof vols);
    for (i = 0; i < n; ++i) {
        memcpy(&vols[i], data + (size_t)i * sizeof(fogvol_analytic_volume), sizeof(fogvol_analytic_volume));
        vols[i].shape = (fogvol_analytic_shape)((unsigned)vols[i].shape % 8u); /* also out-of-range shapes */
    }
    fogvol_analytic_prepare(vols, n, &set);
    for (i = 0; i < 4; ++i) {
        float f = -1, c[3] = {-1, -1, -1}, t1, t2;
        fogvol_analytic_eval(&set, eye, pos + 3 * i, law, mix, &f, c);
        if (!in01(f) || c[0] != c[0] || c[1] != c[1] || c[2] != c[2]) abort();
        for (k = 0; k < n; ++k) {
            fogvol_analytic_segment(&vols[k], eye, pos + 3 * i, &t1, &t2);
            if (!in01(t1) || !in01(t2) || t1 > t2) abort();
        }
    }
    for (k = 0; k < (int)FOGVOL_ANALYTIC_KERNEL_COUNT; ++k) { /* every kernel of the batch */
        memset(&order, 0, sizeof order);
        set.kernel = k;
        fogvol_analytic_batch(&set, eye, pos, 4, 0, law, mix, fog, 0, col, 0, &order, &invalid);
        for (i = 0; i < 4; ++i)
            if (!in01(fog[i]) || col[3 * i] != col[3 * i] || col[3 * i + 1] != col[3 * i + 1] ||
                col[3 * i + 2] != col[3 * i + 2])
                abort();
        if (invalid < 0 || invalid > 4) abort();
    }
    return 0;
}
