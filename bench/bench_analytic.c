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
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts); /* time on the core: other processes' time slices do not count */
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

/* the methods timed side by side: the scalar loop (inverse per call, inverses
   prepared) and fogvol_analytic_batch with each kernel (fogvol_analytic_set.kernel) */
enum { M_PER_CALL, M_PREPARED, M_DOUBLE, M_FLOAT, M_SSE2, M_AVX2, M_AUTO, M_COUNT };
static const char *const method_name[M_COUNT] = {"scalar, inverse per call", "scalar, prepared", "batch double",
                                                 "batch float C", "batch SSE2", "batch AVX2", "batch auto"};
static const int method_kernel[M_COUNT] = {-1, -1, FOGVOL_ANALYTIC_KERNEL_DOUBLE, FOGVOL_ANALYTIC_KERNEL_FLOAT,
                                           FOGVOL_ANALYTIC_KERNEL_SSE2, FOGVOL_ANALYTIC_KERNEL_AVX2,
                                           FOGVOL_ANALYTIC_KERNEL_AUTO};

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

/* max |fog difference| and |colour x (1 - fog) difference| */
static double max_diff(const float *fa, const float *ca, const float *fb, const float *cb)
{
    double d = 0;
    int i, k;
    for (i = 0; i < NV; ++i) {
        d = fmax(d, fabs(fa[i] - fb[i]));
        for (k = 0; k < 3; ++k) d = fmax(d, fabs(ca[3 * i + k] * (1 - fa[i]) - cb[3 * i + k] * (1 - fb[i])));
    }
    return d;
}

typedef struct run {
    const float *pos;
    const double *e;
    const float *eye;
    float *fog[M_COUNT], *col[M_COUNT];
    int sorted;
} run;

static double time_method(run *r, int meth, const fogvol_analytic_volume *vols, const double *invs, int n,
                          fogvol_analytic_set *set, int law)
{
    double t0 = now();
    int i;
    if (meth <= M_PREPARED) {
        for (i = 0; i < NV; ++i)
            naive_vertex(vols, meth == M_PREPARED ? invs : NULL, n, r->e, &r->pos[3 * i], law, &r->fog[meth][i],
                         &r->col[meth][3 * i]);
    } else {
        fogvol_analytic_order order;
        memset(&order, 0, sizeof order);
        set->kernel = method_kernel[meth];
        fogvol_analytic_batch(set, r->eye, r->pos, NV, 0, (fogvol_fog_law)law, FOGVOL_MIX_INTERPENETRATING,
                              r->fog[meth], 0, r->col[meth], 0, &order, NULL);
        r->sorted = order.sorted_vertices;
    }
    return now() - t0;
}

int main(int argc, char **argv)
{
    static const int counts[3] = {1, 4, 16};
    float *pos = (float *)malloc(NV * 3 * sizeof(float));
    const float eye[3] = {0.5f, 1.5f, 9.0f};
    const double e[3] = {0.5, 1.5, 9.0};
    int law, ci, i, r, meth, reps = REPS, pass = 1, there[M_COUNT];
    double worst_ratio = 1e30, worst_rate = 1e30;
    run rn;
    if (argc > 1 && strcmp(argv[1], "--quick") == 0) reps = 3;
    if (!pos) return 1;
    memset(&rn, 0, sizeof rn);
    rn.pos = pos, rn.e = e, rn.eye = eye;
    for (meth = 0; meth < M_COUNT; ++meth) {
        rn.fog[meth] = (float *)malloc(NV * sizeof(float));
        rn.col[meth] = (float *)malloc(NV * 3 * sizeof(float));
        if (!rn.fog[meth] || !rn.col[meth]) return 1;
        there[meth] = method_kernel[meth] <= FOGVOL_ANALYTIC_KERNEL_AUTO ||
                      (int)fogvol_analytic_kernel_resolve((fogvol_analytic_kernel)method_kernel[meth]) ==
                          method_kernel[meth];
    }
    /* a 256 x 128 grid of vertices on a wavy surface behind and through the volumes */
    for (i = 0; i < NV; ++i) {
        double x = -5 + 10.0 * (i % 256) / 255, y = -4 + 8.0 * (i / 256) / 127;
        pos[3 * i] = (float)x, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = (float)(-3 + 2 * sin(x) * cos(y));
    }
    printf("batch auto runs the %s kernel\n",
           method_name[M_DOUBLE + fogvol_analytic_kernel_resolve(FOGVOL_ANALYTIC_KERNEL_AUTO) - 1]);
    for (law = FOGVOL_FOG_EXP; law >= FOGVOL_FOG_LINEAR; --law) {
        printf("\n%s law, interpenetrating volumes, %d vertices, median of %d interleaved runs; M/s (x scalar "
               "prepared)\n\n| volumes |",
               law == FOGVOL_FOG_EXP ? "EXP" : "LINEAR", NV, reps);
        for (meth = 0; meth < M_COUNT; ++meth) printf(" %s |", method_name[meth]);
        printf(" sorted vertices | max diff float vs double | max diff vs scalar |\n|---:|");
        for (meth = 0; meth < M_COUNT; ++meth) printf("---:|");
        printf("---:|---:|---:|\n");
        for (ci = 0; ci < 3; ++ci) {
            int n = counts[ci];
            fogvol_analytic_volume vols[16];
            fogvol_analytic_set set;
            double invs[16 * 16], t[M_COUNT][REPS], rate[M_COUNT], dfl = 0, dsc = 0;
            make_volumes(vols, n);
            for (i = 0; i < n; ++i) naive_inverse(vols[i].transform, invs + 16 * i);
            if (fogvol_analytic_prepare(vols, n, &set) != FOGVOL_SUCCESS) return 1;
            for (r = 0; r < reps; ++r) /* interleaved: every method once per repetition */
                for (meth = 0; meth < M_COUNT; ++meth)
                    if (there[meth]) t[meth][r] = time_method(&rn, meth, vols, invs, n, &set, law);
            for (meth = 0; meth < M_COUNT; ++meth) rate[meth] = there[meth] ? (double)NV * n / median(t[meth], reps) : 0;
            printf("| %d |", n);
            for (meth = 0; meth < M_COUNT; ++meth) {
                if (!there[meth]) {
                    printf(" n/a |");
                    continue;
                }
                printf(" %.1f M/s (%.2fx) |", rate[meth] * 1e-6, rate[meth] / rate[M_PREPARED]);
                if (meth >= M_FLOAT) dfl = fmax(dfl, max_diff(rn.fog[M_DOUBLE], rn.col[M_DOUBLE], rn.fog[meth], rn.col[meth]));
                if (meth >= M_DOUBLE) dsc = fmax(dsc, max_diff(rn.fog[M_PREPARED], rn.col[M_PREPARED], rn.fog[meth], rn.col[meth]));
            }
            printf(" %.0f%% | %.1e | %.1e |\n", 100.0 * rn.sorted / NV, dfl, dsc);
            if (n == 16) {
                worst_ratio = fmin(worst_ratio, rate[M_AUTO] / rate[M_PREPARED]);
                worst_rate = fmin(worst_rate, rate[M_AUTO]);
            }
        }
    }
    pass = worst_ratio >= 3.0 && worst_rate >= 250e6;
    printf("\n(M/s = million vertex x volume evaluations per second; sorted vertices: share that needed the\n"
           " event sort, the others took the order-free shortcut; max diff: fog and colour x (1 - fog))\n");
    printf("\n%s: 16 interpenetrating volumes, batch auto, worst law: %.2fx the prepared scalar loop (target >= 3x), "
           "%.0f M/s (target >= 250)\n",
           pass ? "PASS" : "MISS", worst_ratio, worst_rate * 1e-6);
    printf("summary: analytic 16 volumes %.2fx scalar %.0f M/s\n", worst_ratio, worst_rate * 1e-6);
    for (meth = 0; meth < M_COUNT; ++meth) {
        free(rn.fog[meth]);
        free(rn.col[meth]);
    }
    free(pos);
    return 0;
}
