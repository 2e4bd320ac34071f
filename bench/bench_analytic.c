/* bench_analytic.c - vertex x volume evaluations per second of the analytic fog
   volumes (seeds/002) on one core: fogvol_analytic_batch against a straightforward
   scalar implementation of the same maths written here (per vertex, per volume, an
   array of volume structs with a switch on the shape; "per call": the 4x4 inverse of
   each transform computed for every vertex, as a textbook loop over the raw volume
   descriptions would; "prepared": inverses computed once), both with the seed's
   event list for interpenetrating volumes (sorted from scratch per vertex by
   insertion sort) and the consistent EXP/LINEAR compositing.

   Build and run (no GL):
     cc -std=c99 -O2 -I. bench/bench_analytic.c -o build/bench_analytic -lm && build/bench_analytic
   (add -fno-math-errno to let the compiler vectorise fogvol's square roots too)

   The machine may be noisy: every figure is the best of several repetitions, and
   the ratios compare runs made side by side in the same process. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#define FOGVOL_IMPLEMENTATION
#define FOGVOL_NO_GL
#include "fogvol.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NV 32768 /* vertices per pass */
#define REPS 7

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static unsigned rng = 12345u;
static double rnd(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (double)(rng >> 8) / 16777216.0;
}

/* ---- the naive implementation ---------------------------------------------- */

/* textbook 4x4 inverse (cofactors), column-major */
static int naive_inverse(const float *m, double *inv)
{
    double a[16], det;
    int i;
    for (i = 0; i < 16; ++i) a[i] = m[i];
    inv[0] = a[5] * a[10] * a[15] - a[5] * a[11] * a[14] - a[9] * a[6] * a[15] + a[9] * a[7] * a[14] +
             a[13] * a[6] * a[11] - a[13] * a[7] * a[10];
    inv[4] = -a[4] * a[10] * a[15] + a[4] * a[11] * a[14] + a[8] * a[6] * a[15] - a[8] * a[7] * a[14] -
             a[12] * a[6] * a[11] + a[12] * a[7] * a[10];
    inv[8] = a[4] * a[9] * a[15] - a[4] * a[11] * a[13] - a[8] * a[5] * a[15] + a[8] * a[7] * a[13] +
             a[12] * a[5] * a[11] - a[12] * a[7] * a[9];
    inv[12] = -a[4] * a[9] * a[14] + a[4] * a[10] * a[13] + a[8] * a[5] * a[14] - a[8] * a[6] * a[13] -
              a[12] * a[5] * a[10] + a[12] * a[6] * a[9];
    inv[1] = -a[1] * a[10] * a[15] + a[1] * a[11] * a[14] + a[9] * a[2] * a[15] - a[9] * a[3] * a[14] -
             a[13] * a[2] * a[11] + a[13] * a[3] * a[10];
    inv[5] = a[0] * a[10] * a[15] - a[0] * a[11] * a[14] - a[8] * a[2] * a[15] + a[8] * a[3] * a[14] +
             a[12] * a[2] * a[11] - a[12] * a[3] * a[10];
    inv[9] = -a[0] * a[9] * a[15] + a[0] * a[11] * a[13] + a[8] * a[1] * a[15] - a[8] * a[3] * a[13] -
             a[12] * a[1] * a[11] + a[12] * a[3] * a[9];
    inv[13] = a[0] * a[9] * a[14] - a[0] * a[10] * a[13] - a[8] * a[1] * a[14] + a[8] * a[2] * a[13] +
              a[12] * a[1] * a[10] - a[12] * a[2] * a[9];
    inv[2] = a[1] * a[6] * a[15] - a[1] * a[7] * a[14] - a[5] * a[2] * a[15] + a[5] * a[3] * a[14] +
             a[13] * a[2] * a[7] - a[13] * a[3] * a[6];
    inv[6] = -a[0] * a[6] * a[15] + a[0] * a[7] * a[14] + a[4] * a[2] * a[15] - a[4] * a[3] * a[14] -
             a[12] * a[2] * a[7] + a[12] * a[3] * a[6];
    inv[10] = a[0] * a[5] * a[15] - a[0] * a[7] * a[13] - a[4] * a[1] * a[15] + a[4] * a[3] * a[13] +
              a[12] * a[1] * a[7] - a[12] * a[3] * a[5];
    inv[14] = -a[0] * a[5] * a[14] + a[0] * a[6] * a[13] + a[4] * a[1] * a[14] - a[4] * a[2] * a[13] -
              a[12] * a[1] * a[6] + a[12] * a[2] * a[5];
    inv[3] = -a[1] * a[6] * a[11] + a[1] * a[7] * a[10] + a[5] * a[2] * a[11] - a[5] * a[3] * a[10] -
             a[9] * a[2] * a[7] + a[9] * a[3] * a[6];
    inv[7] = a[0] * a[6] * a[11] - a[0] * a[7] * a[10] - a[4] * a[2] * a[11] + a[4] * a[3] * a[10] +
             a[8] * a[2] * a[7] - a[8] * a[3] * a[6];
    inv[11] = -a[0] * a[5] * a[11] + a[0] * a[7] * a[9] + a[4] * a[1] * a[11] - a[4] * a[3] * a[9] -
              a[8] * a[1] * a[7] + a[8] * a[3] * a[5];
    inv[15] = a[0] * a[5] * a[10] - a[0] * a[6] * a[9] - a[4] * a[1] * a[10] + a[4] * a[2] * a[9] +
              a[8] * a[1] * a[6] - a[8] * a[2] * a[5];
    det = a[0] * inv[0] + a[1] * inv[4] + a[2] * inv[8] + a[3] * inv[12];
    if (det == 0) return 0;
    for (i = 0; i < 16; ++i) inv[i] /= det;
    return 1;
}

static void xform(const double *m, const double p[3], double w, double out[3])
{
    int r;
    for (r = 0; r < 3; ++r) out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r] * w;
}

static int quad_roots(double a, double b, double c, double *t1, double *t2)
{
    double disc = b * b - a * c, s;
    if (a <= 0 || disc <= 0) return 0;
    s = sqrt(disc);
    *t1 = (-b - s) / a;
    *t2 = (-b + s) / a;
    return 1;
}

/* entry/exit of one volume, clamped to [0, 1]; 0 = miss */
static int naive_segment(const fogvol_analytic_volume *v, const double *inv_pre, const double e[3], const double d[3],
                         double len, double *t1, double *t2)
{
    double inv[16], o[3], dd[3], a, b, c, lo = 0, hi = 1;
    int k;
    switch (v->shape) {
    case FOGVOL_SHAPE_DISTANCE:
        if (len <= 0) return 0;
        lo = v->min_distance / len;
        hi = v->max_distance > 0 ? v->max_distance / len : 1;
        break;
    case FOGVOL_SHAPE_HALF_SPACE: {
        double s0 = v->plane[0] * e[0] + v->plane[1] * e[1] + v->plane[2] * e[2] + v->plane[3];
        double s1 = v->plane[0] * d[0] + v->plane[1] * d[1] + v->plane[2] * d[2];
        if (s1 > 0) lo = -s0 / s1;
        else if (s1 < 0) hi = -s0 / s1;
        else if (s0 < 0) return 0;
        break;
    }
    case FOGVOL_SHAPE_SPHERE: {
        double oc[3];
        for (k = 0; k < 3; ++k) oc[k] = e[k] - v->center[k];
        a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
        c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - (double)v->radius * v->radius;
        if (!quad_roots(a, b, c, &lo, &hi)) return 0;
        break;
    }
    default:
        if (inv_pre) memcpy(inv, inv_pre, sizeof inv);
        else if (!naive_inverse(v->transform, inv)) return 0;
        xform(inv, e, 1, o);
        xform(inv, d, 0, dd);
        if (v->shape == FOGVOL_SHAPE_ELLIPSOID) {
            a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
            b = o[0] * dd[0] + o[1] * dd[1] + o[2] * dd[2];
            c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1;
            if (!quad_roots(a, b, c, &lo, &hi)) return 0;
        } else {
            int first = v->shape == FOGVOL_SHAPE_BOX ? 0 : 2;
            if (v->shape == FOGVOL_SHAPE_CYLINDER) {
                a = dd[0] * dd[0] + dd[1] * dd[1];
                b = o[0] * dd[0] + o[1] * dd[1];
                c = o[0] * o[0] + o[1] * o[1] - 1;
                if (a > 0) {
                    if (!quad_roots(a, b, c, &lo, &hi)) return 0;
                } else if (c > 0) {
                    return 0;
                }
                lo = lo > 0 ? lo : 0;
                hi = hi < 1 ? hi : 1;
            }
            for (k = first; k < 3; ++k) {
                if (dd[k] != 0) {
                    double ta = (-1 - o[k]) / dd[k], tb = (1 - o[k]) / dd[k];
                    if (ta > tb) {
                        double tmp = ta;
                        ta = tb;
                        tb = tmp;
                    }
                    if (ta > lo) lo = ta;
                    if (tb < hi) hi = tb;
                } else if (o[k] < -1 || o[k] > 1) {
                    return 0;
                }
            }
        }
        break;
    }
    if (lo < 0) lo = 0;
    if (hi > 1) hi = 1;
    if (!(hi > lo)) return 0;
    *t1 = lo;
    *t2 = hi;
    return 1;
}

typedef struct event {
    double t;
    double c[3], d; /* colour * density, density (negative on exit) */
} event;

/* the seed's interpenetrating algorithm with the consistent compositing */
static void naive_vertex(const fogvol_analytic_volume *vols, const double *invs, int n, const double e[3],
                         const float p[3], int law, float *fog, float col[3])
{
    event ev[64];
    double d[3], len, f = 1, w = 0, num[3] = {0, 0, 0}, acc[4] = {0, 0, 0, 0}, last = 0;
    int m = 0, v, i, j, k, open = 0;
    for (k = 0; k < 3; ++k) d[k] = p[k] - e[k];
    len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (v = 0; v < n; ++v) {
        double t1, t2;
        if (!naive_segment(&vols[v], invs ? invs + 16 * v : NULL, e, d, len, &t1, &t2)) continue;
        ev[m].t = t1;
        ev[m + 1].t = t2;
        for (k = 0; k < 3; ++k) ev[m].c[k] = vols[v].color[k] * vols[v].density, ev[m + 1].c[k] = -ev[m].c[k];
        ev[m].d = vols[v].density;
        ev[m + 1].d = -ev[m].d;
        m += 2;
    }
    for (i = 1; i < m; ++i) { /* insertion sort from scratch */
        event x = ev[i];
        for (j = i; j > 0 && ev[j - 1].t > x.t; --j) ev[j] = ev[j - 1];
        ev[j] = x;
    }
    for (i = 0; i < m; ++i) {
        if (open > 0 && ev[i].t > last && acc[3] > 0) {
            double l = (ev[i].t - last) * len, tau = acc[3] * l;
            if (law == FOGVOL_FOG_EXP) {
                double cover = f * (1 - exp(-tau));
                for (k = 0; k < 3; ++k) num[k] += acc[k] / acc[3] * cover;
                w += cover;
                f *= exp(-tau);
                if (f < 1e-7) break;
            } else {
                double a = tau < f ? tau : f;
                for (k = 0; k < 3; ++k) num[k] += acc[k] / acc[3] * a;
                w += a;
                f -= a;
                if (f <= 0) break;
            }
        }
        for (k = 0; k < 3; ++k) acc[k] += ev[i].c[k];
        acc[3] += ev[i].d;
        open += ev[i].d > 0 ? 1 : -1;
        last = ev[i].t;
    }
    *fog = (float)f;
    for (k = 0; k < 3; ++k) col[k] = (float)(w > 0 ? num[k] / w : 0);
}

/* ---- the scene --------------------------------------------------------------- */

static void make_volumes(fogvol_analytic_volume *v, int n)
{
    int i, k;
    memset(v, 0, (size_t)n * sizeof *v);
    for (i = 0; i < n; ++i) {
        float s = (float)(0.8 + 1.2 * rnd()), c = (float)cos(rnd() * 6.28), sn = (float)sin(rnd() * 6.28);
        v[i].shape = (fogvol_analytic_shape)(2 + i % 4); /* sphere, ellipsoid, box, cylinder */
        for (k = 0; k < 3; ++k) v[i].color[k] = (float)rnd();
        v[i].density = (float)(0.05 + 0.1 * rnd());
        v[i].center[0] = (float)(rnd() * 4 - 2), v[i].center[1] = (float)(rnd() * 4 - 2);
        v[i].center[2] = (float)(rnd() * 4 - 2), v[i].radius = s;
        /* rotation about z, scale, translation */
        v[i].transform[0] = c * s, v[i].transform[1] = sn * s;
        v[i].transform[4] = -sn * s * 0.6f, v[i].transform[5] = c * s * 0.6f;
        v[i].transform[10] = s * 1.4f;
        v[i].transform[12] = v[i].center[0], v[i].transform[13] = v[i].center[1], v[i].transform[14] = v[i].center[2];
        v[i].transform[15] = 1;
    }
}

int main(void)
{
    static const int counts[3] = {1, 4, 16};
    float *pos = (float *)malloc(NV * 3 * sizeof(float)), *fog = (float *)malloc(NV * sizeof(float));
    float *col = (float *)malloc(NV * 3 * sizeof(float)), *nfog = (float *)malloc(NV * sizeof(float));
    float *ncol = (float *)malloc(NV * 3 * sizeof(float));
    const float eye[3] = {0.5f, 1.5f, 9.0f};
    const double e[3] = {0.5, 1.5, 9.0};
    int law, ci, i, r;
    if (!pos || !fog || !col || !nfog || !ncol) return 1;
    /* a 256 x 128 grid of vertices on a wavy surface behind and through the volumes */
    for (i = 0; i < NV; ++i) {
        double x = -5 + 10.0 * (i % 256) / 255, y = -4 + 8.0 * (i / 256) / 127;
        pos[3 * i] = (float)x, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = (float)(-3 + 2 * sin(x) * cos(y));
    }
    for (law = FOGVOL_FOG_EXP; law >= FOGVOL_FOG_LINEAR; --law) {
        printf("\n%s law, interpenetrating volumes, %d vertices, best of %d runs\n\n",
               law == FOGVOL_FOG_EXP ? "EXP" : "LINEAR", NV, REPS);
        printf("| volumes | naive, inverse per call | naive, inverses prepared | fogvol_analytic_batch | "
               "batch / naive per call | batch / naive prepared | sorted vertices | max diff |\n");
        printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (ci = 0; ci < 3; ++ci) {
            int n = counts[ci];
            fogvol_analytic_volume vols[16];
            fogvol_analytic_set set;
            fogvol_analytic_order order;
            double invs[16 * 16], best[3] = {1e30, 1e30, 1e30}, diff = 0, rate[3];
            make_volumes(vols, n);
            for (i = 0; i < n; ++i) naive_inverse(vols[i].transform, invs + 16 * i);
            if (fogvol_analytic_prepare(&set, vols, n) != FOGVOL_SUCCESS) return 1;
            memset(&order, 0, sizeof order);
            for (r = 0; r < REPS; ++r) {
                double t0 = now();
                for (i = 0; i < NV; ++i) naive_vertex(vols, NULL, n, e, &pos[3 * i], law, &nfog[i], &ncol[3 * i]);
                t0 = now() - t0;
                if (t0 < best[0]) best[0] = t0;
                t0 = now();
                for (i = 0; i < NV; ++i) naive_vertex(vols, invs, n, e, &pos[3 * i], law, &nfog[i], &ncol[3 * i]);
                t0 = now() - t0;
                if (t0 < best[1]) best[1] = t0;
                t0 = now();
                fogvol_analytic_batch(&set, eye, pos, NV, 0, (fogvol_fog_law)law, FOGVOL_MIX_INTERPENETRATING, fog, 0,
                                      col, 0, &order, NULL);
                t0 = now() - t0;
                if (t0 < best[2]) best[2] = t0;
            }
            for (i = 0; i < NV; ++i) {
                int k;
                diff = fmax(diff, fabs(fog[i] - nfog[i]));
                for (k = 0; k < 3; ++k) diff = fmax(diff, fabs(col[3 * i + k] - ncol[3 * i + k]) * (1 - fog[i]));
            }
            for (i = 0; i < 3; ++i) rate[i] = (double)NV * n / best[i];
            printf("| %d | %.1f M/s | %.1f M/s | %.1f M/s | %.2fx | %.2fx | %.0f%% | %.1e |\n", n, rate[0] * 1e-6,
                   rate[1] * 1e-6, rate[2] * 1e-6, rate[2] / rate[0], rate[2] / rate[1],
                   100.0 * order.sorted_vertices / NV, diff);
        }
    }
    printf("\n(M/s = million vertex x volume evaluations per second; sorted vertices: share that needed the\n"
           " library's event sort, the others took the order-free shortcut)\n");
    free(pos);
    free(fog);
    free(col);
    free(nfog);
    free(ncol);
    return 0;
}
