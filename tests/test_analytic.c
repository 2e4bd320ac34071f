/* test_analytic.c - analytic fog volumes (seeds/002): fogvol_analytic_* and their GLSL.
 *
 * Ground truth is computed here, independently of the library: a point-inside
 * predicate per shape written in this file (its own inverse of each transform, by
 * Gauss-Jordan elimination in long double), rays marched in fine steps and the
 * transitions refined by bisection.
 *   1 segments, random rays: every shape, eye outside / inside the volume, vertex
 *     inside, general affine matrices (shear) for ellipsoid/box/cylinder, 2000 rays
 *     per shape; |dt| <= 1e-5 for t1 and t2.
 *   2 segments, grazing rays: tangent to spheres/ellipsoids and cylinder sides (the
 *     touching point moved by 0, +-1e-5, +-1e-3), along box faces, edges and cylinder
 *     caps, exactly parallel to a box face / the cylinder axis (the division-free
 *     branch), rays parallel to half-space planes, |vertex - eye| ~ the distance
 *     fog's bounds; |dt| <= 1e-5.
 *   3 combined fog against numeric integration along the ray (the interpenetrating
 *     model: small steps, each with the summed density and density-weighted colour of
 *     the volumes containing it, steps refined by bisection where the set of volumes
 *     changes), random sets of 1..8 overlapping volumes of every shape, both laws
 *     (LINEAR: f = 1 - clamp01(sum density * d), EXP: f = exp(-sum density * d)),
 *     eval and batch (every batch kernel forced: double within 1e-6 of eval, the float
 *     ones within 1.2e-5 of eval and 1e-4 of the integration, maxima printed):
 *     |dfog| <= 1e-4 and |d(colour * (1 - fog))| <= 1e-4; SEPARATE
 *     mode against the same integration on disjoint volumes, and on overlapping ones
 *     against the seed's separate algorithm applied to ground-truth chords.
 *   4 the seed's colour formula (FOGVOL_FOG_LINEAR_SEED) against its closed form for
 *     two and three volumes, and how it differs from the consistent one.
 *   5 batch = eval, strides (outputs interleaved with positions), no allocation path.
 *   6 coherence: per-vertex orders from garbage bytes give bit-identical results, a
 *     repeated frame needs 0 insertion-sort moves, a slightly moved eye fewer moves
 *     than sorting from scratch; the carried per-batch order likewise.
 *  6b the batch kernels (double, float C, SSE2, AVX2; each forced) on edge cases
 *     against hand-computed chords (test_kernel_edges, see there); <= 1.2e-5.
 *  6c the float kernels' per-block culling: fans of rays just inside / outside each
 *     volume where its bounding sphere is tightest, against ground-truth chords.
 *  6d the SIMD kernels (gather, culling, exp()) = the plain-C float kernel bit for bit
 *     on strided arrays with NaN / infinite / huge coordinates, every law and mix, and
 *     on 32 spheres on one ray (the stretch buffer flushed mid-block).
 *   7 degenerate input: zero-size volumes, singular / non-affine matrices, NaN and
 *     infinite fields, zero normal, too many volumes, NaN / infinite vertices and eye,
 *     vertex at the eye, huge coordinates; result codes, never NaN.
 *   8 fogvol_fold_fog by hand; 9 the uniform layout of fogvol_analytic_pack_uniforms.
 *  10 every shader string (7 dialects x 2 stages x per-vertex/per-pixel) through
 *     glslangValidator (files under $BUILD/analytic_shaders; skipped without it).
 *  11 GLSL = CPU under OSMesa: a 32x32 grid of points (per-vertex programs) and a
 *     full-screen quad (per-pixel programs) whose world positions span a tilted plane
 *     through the volumes, rendered into RGBA32F, read back and compared with
 *     fogvol_analytic_batch at the same points: <= 1/255 in fog and colour, every law
 *     and mix; 330 core, 150, 300 es and 100 in the core context, 120 and 110 in the
 *     compatibility context.
 *
 * Build (from the repository root):
 *   gcc -std=c99 -Wall -Wextra -pedantic -Werror -I. tests/test_analytic.c -o build/test_analytic \
 *       -lcmocka -lOSMesa -lm
 *   add -fsanitize=address,undefined and run with
 *   LSAN_OPTIONS=suppressions=tests/lsan.supp (OSMesa keeps a few hundred bytes).
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include <GL/glext.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ==== random numbers ==================================================== */

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static double rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}
static double rnd_range(double a, double b) { return a + (b - a) * rnd(); }
static void rnd_unit(double u[3])
{
    double n;
    do {
        u[0] = rnd_range(-1, 1), u[1] = rnd_range(-1, 1), u[2] = rnd_range(-1, 1);
        n = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    } while (n < 0.01 || n > 1.0);
    n = sqrt(n);
    u[0] /= n, u[1] /= n, u[2] /= n;
}

/* ==== test-side volumes: the shape as an inside predicate =================== */

typedef struct tvol {
    fogvol_analytic_volume v;
    long double inv[3][4]; /* world -> unit shape, from the float transform (Gauss-Jordan) */
} tvol;

/* inverse of the affine float transform, Gauss-Jordan with partial pivoting */
static void tv_invert(tvol *t)
{
    long double a[3][7];
    int r, c, k;
    const float *m = t->v.transform;
    for (r = 0; r < 3; ++r) {
        for (c = 0; c < 3; ++c) a[r][c] = m[c * 4 + r];
        for (c = 0; c < 3; ++c) a[r][3 + c] = r == c;
        a[r][6] = 0;
    }
    for (k = 0; k < 3; ++k) {
        int p = k;
        for (r = k + 1; r < 3; ++r)
            if (fabsl(a[r][k]) > fabsl(a[p][k])) p = r;
        for (c = 0; c < 6; ++c) {
            long double tmp = a[k][c];
            a[k][c] = a[p][c];
            a[p][c] = tmp;
        }
        for (c = 5; c >= k; --c) a[k][c] /= a[k][k];
        for (r = 0; r < 3; ++r)
            if (r != k) {
                long double f = a[r][k];
                for (c = k; c < 6; ++c) a[r][c] -= f * a[k][c];
            }
    }
    for (r = 0; r < 3; ++r) {
        for (c = 0; c < 3; ++c) t->inv[r][c] = a[r][3 + c];
        t->inv[r][3] = -(t->inv[r][0] * m[12] + t->inv[r][1] * m[13] + t->inv[r][2] * m[14]);
    }
}

static int tv_inside(const tvol *t, const long double x[3], const long double eye[3])
{
    const fogvol_analytic_volume *v = &t->v;
    long double y[3];
    int r;
    switch (v->shape) {
    case FOGVOL_SHAPE_DISTANCE: {
        long double d = sqrtl((x[0] - eye[0]) * (x[0] - eye[0]) + (x[1] - eye[1]) * (x[1] - eye[1]) +
                              (x[2] - eye[2]) * (x[2] - eye[2]));
        return d >= v->min_distance && (v->max_distance <= 0 || d <= v->max_distance);
    }
    case FOGVOL_SHAPE_HALF_SPACE:
        return (long double)v->plane[0] * x[0] + (long double)v->plane[1] * x[1] + (long double)v->plane[2] * x[2] +
                   v->plane[3] >=
               0;
    case FOGVOL_SHAPE_SPHERE:
        return (x[0] - v->center[0]) * (x[0] - v->center[0]) + (x[1] - v->center[1]) * (x[1] - v->center[1]) +
                   (x[2] - v->center[2]) * (x[2] - v->center[2]) <=
               (long double)v->radius * v->radius;
    default: break;
    }
    for (r = 0; r < 3; ++r) y[r] = t->inv[r][0] * x[0] + t->inv[r][1] * x[1] + t->inv[r][2] * x[2] + t->inv[r][3];
    if (v->shape == FOGVOL_SHAPE_ELLIPSOID) return y[0] * y[0] + y[1] * y[1] + y[2] * y[2] <= 1;
    if (v->shape == FOGVOL_SHAPE_BOX) return fabsl(y[0]) <= 1 && fabsl(y[1]) <= 1 && fabsl(y[2]) <= 1;
    return y[0] * y[0] + y[1] * y[1] <= 1 && fabsl(y[2]) <= 1;
}

static int tv_inside_t(const tvol *t, const float eye[3], const float p[3], long double s)
{
    long double e[3], x[3];
    int i;
    for (i = 0; i < 3; ++i) {
        e[i] = eye[i];
        x[i] = e[i] + s * ((long double)p[i] - e[i]);
    }
    return tv_inside(t, x, e);
}

/* Ground-truth segment: an inside point from 1024 steps (or a seed), then bisection
   to the entry and the exit (the inside set of a convex volume on a ray is one
   interval). Returns 0 when no inside point was found. */
static int gt_segment(const tvol *t, const float eye[3], const float p[3], const double *seeds, int ns, double *a,
                      double *b)
{
    const int n = 1024;
    long double s = -1, lo, hi;
    int k, it;
    for (k = 0; k <= n && s < 0; ++k)
        if (tv_inside_t(t, eye, p, (long double)k / n)) s = (long double)k / n;
    for (k = 0; k < ns && s < 0; ++k)
        if (seeds[k] >= 0 && seeds[k] <= 1 && tv_inside_t(t, eye, p, seeds[k])) s = seeds[k];
    if (s < 0) return 0;
    if (tv_inside_t(t, eye, p, 0)) {
        *a = 0;
    } else {
        for (lo = 0, hi = s, it = 0; it < 80; ++it) {
            long double m = 0.5L * (lo + hi);
            if (tv_inside_t(t, eye, p, m)) hi = m;
            else lo = m;
        }
        *a = (double)hi;
    }
    if (tv_inside_t(t, eye, p, 1)) {
        *b = 1;
    } else {
        for (lo = s, hi = 1, it = 0; it < 80; ++it) {
            long double m = 0.5L * (lo + hi);
            if (tv_inside_t(t, eye, p, m)) lo = m;
            else hi = m;
        }
        *b = (double)lo;
    }
    return 1;
}

/* affine transform: linear part R diag(s) or (general) a random matrix with a sane
   determinant, translation in [-2, 2]^3 */
static void rand_transform(float m[16], int general)
{
    int r, c;
    memset(m, 0, 16 * sizeof(float));
    if (general) {
        double a[3][3], det;
        do {
            for (r = 0; r < 3; ++r)
                for (c = 0; c < 3; ++c) a[r][c] = rnd_range(-1.5, 1.5);
            det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                  a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        } while (fabs(det) < 0.3);
        for (r = 0; r < 3; ++r)
            for (c = 0; c < 3; ++c) m[c * 4 + r] = (float)a[r][c];
    } else {
        double q[4], n = 0, s[3], R[3][3];
        for (r = 0; r < 4; ++r) q[r] = rnd_range(-1, 1), n += q[r] * q[r];
        n = sqrt(n);
        for (r = 0; r < 4; ++r) q[r] /= n;
        R[0][0] = 1 - 2 * (q[2] * q[2] + q[3] * q[3]), R[0][1] = 2 * (q[1] * q[2] - q[0] * q[3]),
        R[0][2] = 2 * (q[1] * q[3] + q[0] * q[2]);
        R[1][0] = 2 * (q[1] * q[2] + q[0] * q[3]), R[1][1] = 1 - 2 * (q[1] * q[1] + q[3] * q[3]),
        R[1][2] = 2 * (q[2] * q[3] - q[0] * q[1]);
        R[2][0] = 2 * (q[1] * q[3] - q[0] * q[2]), R[2][1] = 2 * (q[2] * q[3] + q[0] * q[1]),
        R[2][2] = 1 - 2 * (q[1] * q[1] + q[2] * q[2]);
        for (c = 0; c < 3; ++c) s[c] = rnd_range(0.3, 2.0);
        for (r = 0; r < 3; ++r)
            for (c = 0; c < 3; ++c) m[c * 4 + r] = (float)(R[r][c] * s[c]);
    }
    for (r = 0; r < 3; ++r) m[12 + r] = (float)rnd_range(-2, 2);
    m[15] = 1;
}

static tvol rand_volume(int shape)
{
    tvol t;
    int i;
    memset(&t, 0, sizeof t);
    t.v.shape = (fogvol_analytic_shape)shape;
    for (i = 0; i < 3; ++i) t.v.color[i] = (float)rnd();
    t.v.density = (float)rnd_range(0.05, 1.2);
    switch (shape) {
    case FOGVOL_SHAPE_DISTANCE:
        t.v.min_distance = rnd() < 0.2 ? 0.0f : (float)rnd_range(0, 3); /* 0: the eye is in it */
        t.v.max_distance = rnd() < 0.2 ? 0.0f : t.v.min_distance + (float)rnd_range(0.5, 6);
        break;
    case FOGVOL_SHAPE_HALF_SPACE: {
        double n[3];
        rnd_unit(n);
        for (i = 0; i < 3; ++i) t.v.plane[i] = (float)(n[i] * rnd_range(0.5, 3));
        t.v.plane[3] = (float)rnd_range(-3, 3);
        break;
    }
    case FOGVOL_SHAPE_SPHERE:
        for (i = 0; i < 3; ++i) t.v.center[i] = (float)rnd_range(-2, 2);
        t.v.radius = (float)rnd_range(0.3, 2.5);
        break;
    default:
        rand_transform(t.v.transform, rnd() < 0.5);
        tv_invert(&t);
        break;
    }
    return t;
}

/* world point of unit-shape point y (transform shapes and spheres) */
static void tv_to_world(const tvol *t, const double y[3], float out[3])
{
    int r;
    if (t->v.shape == FOGVOL_SHAPE_SPHERE) {
        for (r = 0; r < 3; ++r) out[r] = (float)(t->v.center[r] + t->v.radius * y[r]);
        return;
    }
    for (r = 0; r < 3; ++r)
        out[r] = (float)(t->v.transform[r] * y[0] + t->v.transform[4 + r] * y[1] + t->v.transform[8 + r] * y[2] +
                         t->v.transform[12 + r]);
}

static void rand_point(float p[3], double range)
{
    p[0] = (float)rnd_range(-range, range), p[1] = (float)rnd_range(-range, range),
    p[2] = (float)rnd_range(-range, range);
}

/* Compares the library's segment with the ground truth. Both hit: |dt| on both
   ends; one of them hits: that chord must be shorter than tol (a grazing touch). */
static double seg_error(const tvol *t, const float eye[3], const float p[3], const double *seeds, int ns)
{
    float t1 = -1, t2 = -1;
    double a = 0, b = 0, sd[8], err;
    int gt, i;
    assert_int_equal(fogvol_analytic_segment(&t->v, eye, p, &t1, &t2), FOGVOL_SUCCESS);
    assert_true(t1 >= 0 && t2 <= 1 && t1 <= t2);
    if (eye[0] == p[0] && eye[1] == p[1] && eye[2] == p[2]) return t2 - t1; /* no ray: 0, 0 */
    for (i = 0; i < ns && i < 7; ++i) sd[i] = seeds[i];
    sd[i++] = 0.5 * ((double)t1 + t2); /* the library's midpoint as a seed, checked by the predicate */
    gt = gt_segment(t, eye, p, sd, i, &a, &b);
    if (gt && t2 > t1) err = fmax(fabs(a - t1), fabs(b - t2));
    else if (gt) err = b - a;
    else err = (double)t2 - t1;
    return err;
}

/* ==== 1, 2: segments ========================================================= */

static const char *const shape_name[6] = {"distance", "half-space", "sphere", "ellipsoid", "box", "cylinder"};

static void test_segments_random(void **state)
{
    int shape, k;
    (void)state;
    for (shape = 0; shape < 6; ++shape) {
        double worst = 0;
        int hits = 0, inside_eye = 0;
        for (k = 0; k < 2000; ++k) {
            tvol t = rand_volume(shape);
            float eye[3], p[3];
            double e;
            rand_point(eye, 4);
            rand_point(p, 4);
            if (shape >= FOGVOL_SHAPE_SPHERE && (k % 4) != 0) { /* eye and/or vertex inside */
                double y[3], r;
                rnd_unit(y);
                r = pow(rnd(), 1.0 / 3.0);
                if (shape == FOGVOL_SHAPE_BOX) y[0] = rnd_range(-1, 1), y[1] = rnd_range(-1, 1), y[2] = rnd_range(-1, 1), r = 1;
                y[0] *= r, y[1] *= r, y[2] *= r;
                if (shape == FOGVOL_SHAPE_CYLINDER) y[2] = rnd_range(-1, 1);
                tv_to_world(&t, y, (k % 4) == 3 ? p : eye);
            }
            e = seg_error(&t, eye, p, NULL, 0);
            if (e > worst) worst = e;
            if (e > 1e-5) {
                float t1, t2;
                fogvol_analytic_segment(&t.v, eye, p, &t1, &t2);
                print_message("# %s ray %d: |dt| = %g (lib %.9f %.9f)\n", shape_name[shape], k, e, t1, t2);
            }
            {
                float t1, t2;
                fogvol_analytic_segment(&t.v, eye, p, &t1, &t2);
                hits += t2 > t1;
                inside_eye += tv_inside_t(&t, eye, p, 0);
            }
        }
        print_message("# %-10s 2000 random rays: %4d hits, eye inside %4d, max |dt| %.2e\n", shape_name[shape], hits,
                      inside_eye, worst);
        assert_true(worst <= 1e-5);
        assert_true(hits > 200);
    }
}

static void test_segments_grazing(void **state)
{
    static const double offs[5] = {0.0, 1e-5, -1e-5, 1e-3, -1e-3};
    int shape, k;
    (void)state;
    for (shape = FOGVOL_SHAPE_SPHERE; shape <= FOGVOL_SHAPE_CYLINDER; ++shape) {
        double worst = 0;
        for (k = 0; k < 1000; ++k) {
            tvol t = rand_volume(shape);
            double y0[3], u[3], q[3], ye[3], yp[3], al = rnd_range(0.3, 3), be = rnd_range(0.3, 3), f = 1 + offs[k % 5];
            double seeds[1], e, dd;
            float eye[3], p[3];
            int i;
            if (shape == FOGVOL_SHAPE_SPHERE || shape == FOGVOL_SHAPE_ELLIPSOID) {
                /* tangent to the unit sphere at y0 */
                rnd_unit(y0);
                rnd_unit(u);
                dd = u[0] * y0[0] + u[1] * y0[1] + u[2] * y0[2];
                for (i = 0; i < 3; ++i) u[i] -= dd * y0[i];
                for (i = 0; i < 3; ++i) q[i] = f * y0[i];
            } else if (shape == FOGVOL_SHAPE_BOX) {
                /* along a face, an edge or through a corner region */
                int ax = k % 3, kind = (k / 5) % 3;
                double s0 = rnd() < 0.5 ? -1 : 1;
                for (i = 0; i < 3; ++i) q[i] = rnd_range(-0.9, 0.9);
                q[ax] = s0 * f;
                if (kind >= 1) q[(ax + 1) % 3] = (rnd() < 0.5 ? -1 : 1) * f;
                if (kind == 2) q[(ax + 2) % 3] = (rnd() < 0.5 ? -1 : 1) * f;
                rnd_unit(u);
                u[ax] = kind == 0 ? 1e-3 * rnd_range(-1, 1) : 0; /* (almost) in the face plane */
                if (kind == 2) u[(ax + 1) % 3] = 0;
            } else {
                /* cylinder: tangent to the side, or along a cap */
                double ph = rnd_range(0, 6.283185307179586);
                if ((k / 5) % 2 == 0) {
                    q[0] = f * cos(ph), q[1] = f * sin(ph), q[2] = rnd_range(-0.9, 0.9);
                    u[0] = -sin(ph), u[1] = cos(ph), u[2] = rnd_range(-0.5, 0.5);
                } else {
                    q[0] = 0.7 * cos(ph), q[1] = 0.7 * sin(ph), q[2] = (rnd() < 0.5 ? -1 : 1) * f;
                    u[0] = rnd_range(-1, 1), u[1] = rnd_range(-1, 1), u[2] = 0;
                }
            }
            for (i = 0; i < 3; ++i) ye[i] = q[i] - al * u[i], yp[i] = q[i] + be * u[i];
            tv_to_world(&t, ye, eye);
            tv_to_world(&t, yp, p);
            seeds[0] = al / (al + be);
            e = seg_error(&t, eye, p, seeds, 1);
            if (e > worst) worst = e;
            if (e > 1e-5) print_message("# %s grazing ray %d: |dt| = %g\n", shape_name[shape], k, e);
        }
        print_message("# %-10s 1000 grazing rays: max |dt| %.2e\n", shape_name[shape], worst);
        assert_true(worst <= 1e-5);
    }
    { /* rays exactly parallel to a box face / the cylinder axis (v == 0: no division) */
        tvol box, cyl;
        float eye[3], p[3];
        double worst = 0;
        memset(&box, 0, sizeof box);
        memset(&cyl, 0, sizeof cyl);
        box.v.shape = FOGVOL_SHAPE_BOX;
        cyl.v.shape = FOGVOL_SHAPE_CYLINDER;
        box.v.density = cyl.v.density = 1;
        glu_translate_scale(box.v.transform, 0.5f, -0.25f, 0, 2);
        glu_translate_scale(cyl.v.transform, 0.5f, -0.25f, 0, 2);
        tv_invert(&box);
        tv_invert(&cyl);
        for (k = 0; k < 400; ++k) {
            double e;
            float side = (float)((k % 3) - 1) * (k % 2 ? 2.0f : 1.0f); /* -2, 0, 2: on the face plane */
            eye[0] = 0.5f + (k % 5 == 0 ? side : (float)rnd_range(-3, 3)), eye[1] = (float)rnd_range(-3, 3);
            eye[2] = (float)rnd_range(-5, 5);
            p[0] = eye[0], p[1] = eye[1], p[2] = (float)rnd_range(-5, 5);
            e = seg_error(&box, eye, p, NULL, 0);
            worst = fmax(worst, e);
            e = seg_error(&cyl, eye, p, NULL, 0);
            worst = fmax(worst, e);
        }
        /* on the face x = 2.5 exactly: the closed box contains the ray */
        {
            float t1, t2;
            eye[0] = 2.5f, eye[1] = 0, eye[2] = -5;
            p[0] = 2.5f, p[1] = 0, p[2] = 5;
            assert_int_equal(fogvol_analytic_segment(&box.v, eye, p, &t1, &t2), FOGVOL_SUCCESS);
            assert_true(fabs(t1 - 0.3) < 1e-6 && fabs(t2 - 0.7) < 1e-6);
            eye[0] = p[0] = 2.5001f;
            assert_int_equal(fogvol_analytic_segment(&box.v, eye, p, &t1, &t2), FOGVOL_SUCCESS);
            assert_true(t1 == 0 && t2 == 0);
        }
        print_message("# axis-parallel rays (box faces, cylinder axis): max |dt| %.2e\n", worst);
        assert_true(worst <= 1e-5);
    }
    { /* half-spaces: rays parallel to the plane (up to float rounding of p) */
        double worst = 0;
        for (k = 0; k < 2000; ++k) {
            tvol t = rand_volume(FOGVOL_SHAPE_HALF_SPACE);
            double n[3], u[3], d;
            float eye[3], p[3];
            int i;
            for (i = 0; i < 3; ++i) n[i] = t.v.plane[i];
            rand_point(eye, 4);
            rnd_unit(u);
            d = (u[0] * n[0] + u[1] * n[1] + u[2] * n[2]) / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (i = 0; i < 3; ++i) u[i] -= d * n[i];
            if (k % 2) /* almost parallel */
                for (i = 0; i < 3; ++i) u[i] += 1e-4 * n[i] * (k % 4 == 1 ? 1 : -1);
            for (i = 0; i < 3; ++i) p[i] = (float)(eye[i] + rnd_range(0.5, 8) * u[i]);
            worst = fmax(worst, seg_error(&t, eye, p, NULL, 0));
        }
        print_message("# half-space 2000 rays (almost) parallel to the plane: max |dt| %.2e\n", worst);
        assert_true(worst <= 1e-5);
    }
    { /* distance fog: vertex distance ~ min or max */
        double worst = 0;
        for (k = 0; k < 2000; ++k) {
            tvol t = rand_volume(FOGVOL_SHAPE_DISTANCE);
            double u[3], r;
            float eye[3], p[3];
            int i;
            rand_point(eye, 4);
            rnd_unit(u);
            r = (k % 2 || t.v.max_distance <= 0 ? t.v.min_distance : t.v.max_distance) * (1 + offs[k % 5]);
            for (i = 0; i < 3; ++i) p[i] = (float)(eye[i] + r * u[i]);
            worst = fmax(worst, seg_error(&t, eye, p, NULL, 0));
        }
        print_message("# distance 2000 rays ending near min/max distance: max |dt| %.2e\n", worst);
        assert_true(worst <= 1e-5);
    }
}

/* ==== 3, 4: combined fog ====================================================== */

typedef struct gt_state {
    double f, w, num[3]; /* fog (LINEAR) or transmittance (EXP), cover, colour * cover */
} gt_state;

/* one step of length l (world units) with the volumes of mask */
static void gt_step(const tvol *vs, unsigned mask, double l, int law, gt_state *st)
{
    double sig = 0, cs[3] = {0, 0, 0}, tau, k;
    int v, c;
    for (v = 0; v < 32; ++v)
        if (mask & (1u << v)) {
            sig += vs[v].v.density;
            for (c = 0; c < 3; ++c) cs[c] += (double)vs[v].v.density * vs[v].v.color[c];
        }
    tau = sig * l;
    if (tau <= 0 || st->f <= 0) return;
    if (law == FOGVOL_FOG_EXP) {
        double cover = st->f * (1 - exp(-tau));
        for (c = 0; c < 3; ++c) st->num[c] += cs[c] / sig * cover;
        st->w += cover;
        st->f *= exp(-tau);
    } else {
        k = tau > st->f ? st->f / tau : 1; /* the step that ends the fog counts in part */
        for (c = 0; c < 3; ++c) st->num[c] += cs[c] / sig * tau * k;
        st->w += tau * k;
        st->f -= tau * k;
    }
}

static unsigned gt_mask(const tvol *vs, int n, const float eye[3], const float p[3], long double t)
{
    unsigned m = 0;
    int v;
    for (v = 0; v < n; ++v)
        if (tv_inside_t(&vs[v], eye, p, t)) m |= 1u << v;
    return m;
}

static void gt_interval(const tvol *vs, int n, const float eye[3], const float p[3], double len, int law,
                        long double t0, long double t1, unsigned m0, unsigned m1, int depth, gt_state *st)
{
    long double tm = 0.5L * (t0 + t1);
    unsigned mm = gt_mask(vs, n, eye, p, tm);
    if ((m0 == m1 && mm == m0) || depth > 44) {
        gt_step(vs, mm, (double)(t1 - t0) * len, law, st);
        return;
    }
    gt_interval(vs, n, eye, p, len, law, t0, tm, m0, mm, depth + 1, st);
    gt_interval(vs, n, eye, p, len, law, tm, t1, mm, m1, depth + 1, st);
}

/* numeric integration of the interpenetrating model along eye -> p */
static void gt_fog(const tvol *vs, int n, const float eye[3], const float p[3], int law, double *fog, double pc[3])
{
    const int steps = 2000;
    double len = sqrt(((double)p[0] - eye[0]) * ((double)p[0] - eye[0]) + ((double)p[1] - eye[1]) * ((double)p[1] - eye[1]) +
                      ((double)p[2] - eye[2]) * ((double)p[2] - eye[2]));
    gt_state st;
    unsigned m0 = gt_mask(vs, n, eye, p, 0);
    int k;
    memset(&st, 0, sizeof st);
    st.f = 1;
    for (k = 1; k <= steps; ++k) {
        long double t0 = (long double)(k - 1) / steps, t1 = (long double)k / steps;
        unsigned m1 = gt_mask(vs, n, eye, p, t1);
        gt_interval(vs, n, eye, p, len, law, t0, t1, m0, m1, 0, &st);
        m0 = m1;
    }
    *fog = st.f;
    for (k = 0; k < 3; ++k) pc[k] = st.num[k]; /* colour * (1 - fog) */
}

/* the batch's kernels (fogvol_analytic_kernel), each forced in turn; a level this
   build or CPU lacks resolves to another one and is left out */
static const int kernels[4] = {FOGVOL_ANALYTIC_KERNEL_DOUBLE, FOGVOL_ANALYTIC_KERNEL_FLOAT, FOGVOL_ANALYTIC_KERNEL_SSE2,
                               FOGVOL_ANALYTIC_KERNEL_AVX2};
static const char *const kernel_name[4] = {"double", "float C", "SSE2", "AVX2"};
static int kernel_there(int k) { return (int)fogvol_analytic_kernel_resolve((fogvol_analytic_kernel)kernels[k]) == kernels[k]; }
/* worst difference of each kernel's batch from eval (double), and from the ground
   truth, over the lib_fog calls since the last reset */
static double kern_eval_worst[4], kern_gt_worst[4];

static void lib_fog_gt(const fogvol_analytic_set *set, const float eye[3], const float p[3], int law, int mix,
                       double *fog, double pc[3], double col[3], const double *gf, const double *gc)
{
    fogvol_analytic_set ks = *set;
    float f, c[3], fb, cb[3];
    int k, j, inv = -1;
    assert_int_equal(fogvol_analytic_eval(set, eye, p, (fogvol_fog_law)law, (fogvol_fog_mix)mix, &f, c), FOGVOL_SUCCESS);
    for (j = 0; j < 4; ++j) {
        if (!kernel_there(j)) continue;
        ks.kernel = kernels[j];
        assert_int_equal(fogvol_analytic_batch(&ks, eye, p, 1, 0, (fogvol_fog_law)law, (fogvol_fog_mix)mix, &fb, 0,
                                               cb, 0, NULL, &inv),
                         FOGVOL_SUCCESS);
        assert_int_equal(inv, 0);
        kern_eval_worst[j] = fmax(kern_eval_worst[j], fabs(f - fb));
        for (k = 0; k < 3; ++k) kern_eval_worst[j] = fmax(kern_eval_worst[j], fabs(c[k] - cb[k]) * (1 - f));
        if (gf) {
            kern_gt_worst[j] = fmax(kern_gt_worst[j], fabs(*gf - fb));
            for (k = 0; k < 3; ++k) kern_gt_worst[j] = fmax(kern_gt_worst[j], fabs(gc[k] - (double)cb[k] * (1 - fb)));
        }
        /* the double kernel is eval's arithmetic; the float ones stay within 1.2e-5 */
        assert_true(fabs(f - fb) <= (j == 0 ? 1e-6 : 1.2e-5));
        for (k = 0; k < 3; ++k) assert_true(fabs(c[k] - cb[k]) * (1 - f) <= (j == 0 ? 1e-6 : 1.2e-5));
    }
    assert_true(f >= 0 && f <= 1);
    *fog = f;
    for (k = 0; k < 3; ++k) pc[k] = (double)c[k] * (1 - f), col[k] = c[k];
}

static void lib_fog(const fogvol_analytic_set *set, const float eye[3], const float p[3], int law, int mix,
                    double *fog, double pc[3], double col[3])
{
    lib_fog_gt(set, eye, p, law, mix, fog, pc, col, NULL, NULL);
}

static void kern_reset(void)
{
    memset(kern_eval_worst, 0, sizeof kern_eval_worst);
    memset(kern_gt_worst, 0, sizeof kern_gt_worst);
}

/* prints (and asserts) the worst differences of every kernel since kern_reset */
static void kern_report(const char *what, double gt_bound)
{
    int j;
    for (j = 0; j < 4; ++j) {
        if (!kernel_there(j)) {
            print_message("# %s: %s kernel not available here, skipped\n", what, kernel_name[j]);
            continue;
        }
        print_message("# %s: %-7s batch max |d| vs eval %.2e, vs integration %.2e\n", what, kernel_name[j],
                      kern_eval_worst[j], kern_gt_worst[j]);
        assert_true(kern_eval_worst[j] <= (j == 0 ? 1e-6 : 1.2e-5));
        assert_true(kern_gt_worst[j] <= gt_bound);
    }
}

static void test_fog_integration(void **state)
{
    int law, k;
    (void)state;
    kern_reset();
    for (law = FOGVOL_FOG_LINEAR; law <= FOGVOL_FOG_EXP; ++law) {
        double worst_f = 0, worst_c = 0;
        int partial = 0, full = 0;
        for (k = 0; k < 300; ++k) {
            tvol vs[8];
            fogvol_analytic_volume raw[8];
            fogvol_analytic_set set;
            float eye[3], p[3];
            double gf, gc[3], lf, lc[3], col[3];
            int n = 1 + k % 8, v, c;
            for (v = 0; v < n; ++v) {
                vs[v] = rand_volume((int)(rnd() * 6));
                if (law == FOGVOL_FOG_LINEAR) vs[v].v.density *= 0.25f; /* keep some rays below full fog */
                raw[v] = vs[v].v;
            }
            assert_int_equal(fogvol_analytic_prepare(raw, n, &set), FOGVOL_SUCCESS);
            rand_point(eye, 4);
            rand_point(p, 4);
            gt_fog(vs, n, eye, p, law, &gf, gc);
            lib_fog_gt(&set, eye, p, law, FOGVOL_MIX_INTERPENETRATING, &lf, lc, col, &gf, gc);
            worst_f = fmax(worst_f, fabs(gf - lf));
            for (c = 0; c < 3; ++c) worst_c = fmax(worst_c, fabs(gc[c] - lc[c]));
            if (fabs(gf - lf) > 1e-4) print_message("# set %d (%d volumes): fog %.6f, integrated %.6f\n", k, n, lf, gf);
            partial += lf > 0.01 && lf < 0.99;
            full += lf == 0;
        }
        print_message("# %s, interpenetrating, 300 random sets of 1..8 volumes (%d partly fogged, %d fully): "
                      "max |dfog| %.2e, max |d(colour*(1-fog))| %.2e\n",
                      law == FOGVOL_FOG_EXP ? "EXP   " : "LINEAR", partial, full, worst_f, worst_c);
        assert_true(worst_f <= 1e-4);
        assert_true(worst_c <= 1e-4);
        assert_true(partial > 50);
    }
    kern_report("interpenetrating, 600 random sets", 1e-4);
    /* SEPARATE on volumes that do not overlap: the same integral */
    for (law = FOGVOL_FOG_LINEAR; law <= FOGVOL_FOG_EXP; ++law) {
        double worst = 0;
        for (k = 0; k < 100; ++k) {
            tvol vs[4];
            fogvol_analytic_volume raw[4];
            fogvol_analytic_set set;
            float eye[3], p[3];
            double gf, gc[3], lf, lc[3], col[3];
            int v, c;
            for (v = 0; v < 4; ++v) {
                memset(&vs[v], 0, sizeof vs[v]);
                vs[v].v.shape = FOGVOL_SHAPE_SPHERE;
                vs[v].v.center[0] = (float)(-4.5 + 3 * v), vs[v].v.center[1] = (float)rnd_range(-0.5, 0.5);
                vs[v].v.center[2] = (float)rnd_range(-0.5, 0.5);
                vs[v].v.radius = (float)rnd_range(0.5, 1.4);
                vs[v].v.density = (float)rnd_range(0.05, 0.5);
                for (c = 0; c < 3; ++c) vs[v].v.color[c] = (float)rnd();
                raw[v] = vs[v].v;
            }
            assert_int_equal(fogvol_analytic_prepare(raw, 4, &set), FOGVOL_SUCCESS);
            eye[0] = (float)(k % 2 ? -8 : 8), eye[1] = (float)rnd_range(-1, 1), eye[2] = (float)rnd_range(-1, 1);
            p[0] = (float)-eye[0], p[1] = (float)rnd_range(-1, 1), p[2] = (float)rnd_range(-1, 1);
            gt_fog(vs, 4, eye, p, law, &gf, gc);
            lib_fog(&set, eye, p, law, FOGVOL_MIX_SEPARATE, &lf, lc, col);
            worst = fmax(worst, fabs(gf - lf));
            for (c = 0; c < 3; ++c) worst = fmax(worst, fabs(gc[c] - lc[c]));
        }
        print_message("# %s, separate, 100 rays through 4 disjoint spheres: max |dfog|, |dcolour| %.2e\n",
                      law == FOGVOL_FOG_EXP ? "EXP   " : "LINEAR", worst);
        assert_true(worst <= 1e-4);
    }
}

/* SEPARATE on overlapping volumes: the seed's algorithm (each volume whole, front to
   back by entry) applied to ground-truth chords */
static void test_separate_overlapping(void **state)
{
    int law, k;
    (void)state;
    for (law = FOGVOL_FOG_LINEAR; law <= FOGVOL_FOG_EXP; ++law) {
        double worst = 0;
        for (k = 0; k < 200; ++k) {
            tvol vs[6];
            fogvol_analytic_volume raw[6];
            fogvol_analytic_set set;
            float eye[3], p[3];
            double a[6], b[6], lf, lc[3], col[3], len;
            int n = 2 + k % 5, v, c, ord[6], i, j;
            gt_state st;
            for (v = 0; v < n; ++v) {
                vs[v] = rand_volume(2 + (int)(rnd() * 4));
                vs[v].v.density *= 0.4f;
                raw[v] = vs[v].v;
            }
            assert_int_equal(fogvol_analytic_prepare(raw, n, &set), FOGVOL_SUCCESS);
            rand_point(eye, 4);
            rand_point(p, 4);
            len = sqrt(((double)p[0] - eye[0]) * ((double)p[0] - eye[0]) + ((double)p[1] - eye[1]) * ((double)p[1] - eye[1]) +
                       ((double)p[2] - eye[2]) * ((double)p[2] - eye[2]));
            for (v = 0; v < n; ++v) {
                float t1, t2;
                double sd;
                fogvol_analytic_segment(&vs[v].v, eye, p, &t1, &t2);
                sd = 0.5 * ((double)t1 + t2);
                if (!gt_segment(&vs[v], eye, p, &sd, 1, &a[v], &b[v])) a[v] = b[v] = 0;
                ord[v] = v;
            }
            for (i = 1; i < n; ++i) /* by entry, ties by index */
                for (j = i; j > 0 && a[ord[j - 1]] > a[ord[j]]; --j) {
                    int tmp = ord[j];
                    ord[j] = ord[j - 1];
                    ord[j - 1] = tmp;
                }
            memset(&st, 0, sizeof st);
            st.f = 1;
            for (i = 0; i < n; ++i) gt_step(vs, 1u << ord[i], (b[ord[i]] - a[ord[i]]) * len, law, &st);
            lib_fog(&set, eye, p, law, FOGVOL_MIX_SEPARATE, &lf, lc, col);
            worst = fmax(worst, fabs(st.f - lf));
            for (c = 0; c < 3; ++c) worst = fmax(worst, fabs(st.num[c] - lc[c]));
        }
        print_message("# %s, separate, 200 rays through 2..6 overlapping volumes: max |dfog|, |dcolour| %.2e\n",
                      law == FOGVOL_FOG_EXP ? "EXP   " : "LINEAR", worst);
        assert_true(worst <= 1e-4);
    }
}

static void test_seed_colour(void **state)
{
    fogvol_analytic_volume v[3];
    fogvol_analytic_set set;
    float eye[3] = {-10, 0, 0}, p[3] = {10, 0, 0}, f, c[3];
    const float cols[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float dens[3] = {0.1f, 0.15f, 0.05f};
    double a[3], fog, want[3];
    int i, k, mix, n;
    (void)state;
    /* three disjoint spheres on the x axis, radii 1, 1.5, 2: chords 2, 3, 4 */
    memset(v, 0, sizeof v);
    for (i = 0; i < 3; ++i) {
        v[i].shape = FOGVOL_SHAPE_SPHERE;
        v[i].center[0] = (float)(-6 + 6 * i);
        v[i].radius = 1.0f + 0.5f * (float)i;
        v[i].density = dens[i];
        memcpy(v[i].color, cols[i], sizeof cols[i]);
        a[i] = fmin(1.0, dens[i] * 2.0 * v[i].radius);
    }
    for (n = 2; n <= 3; ++n) {
        assert_int_equal(fogvol_analytic_prepare(v, n, &set), FOGVOL_SUCCESS);
        /* the seed: fogColor = volColor * fog + fogColor * (1 - fog), fog = fog + volFog - 1 */
        fog = 1;
        want[0] = want[1] = want[2] = 0;
        for (i = 0; i < n; ++i) {
            for (k = 0; k < 3; ++k) want[k] = cols[i][k] * fog + want[k] * (1 - fog);
            fog -= a[i];
        }
        for (mix = 0; mix < 2; ++mix) {
            assert_int_equal(fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_LINEAR_SEED, (fogvol_fog_mix)mix, &f, c),
                             FOGVOL_SUCCESS);
            assert_true(fabs(f - fog) < 1e-6);
            for (k = 0; k < 3; ++k) assert_true(fabs(c[k] - want[k]) < 1e-6);
            /* consistent colour: (sum c a) / (sum a) */
            assert_int_equal(fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_LINEAR, (fogvol_fog_mix)mix, &f, c),
                             FOGVOL_SUCCESS);
            assert_true(fabs(f - fog) < 1e-6);
            for (k = 0; k < 3; ++k) {
                double s = 0, w = 0;
                for (i = 0; i < n; ++i) s += cols[i][k] * a[i], w += a[i];
                assert_true(fabs(c[k] - s / w) < 1e-6);
            }
        }
        print_message("# %d volumes taking %.1f, %.2f, %.1f of the fog: seed colour (%.3f %.3f %.3f), consistent "
                      "(%.3f %.3f %.3f)\n",
                      n, a[0], a[1], n > 2 ? a[2] : 0.0, want[0], want[1], want[2], c[0], c[1], c[2]);
    }
    /* fully fogged: the seed's formula is exact, both agree (0.8 + 0.2 of the 0.9 behind) */
    v[0].density = 0.4f;
    v[1].density = 0.3f;
    assert_int_equal(fogvol_analytic_prepare(v, 2, &set), FOGVOL_SUCCESS);
    {
        float f2, c2[3];
        fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_LINEAR_SEED, FOGVOL_MIX_SEPARATE, &f, c);
        fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_LINEAR, FOGVOL_MIX_SEPARATE, &f2, c2);
        assert_true(f == 0 && f2 == 0);
        for (k = 0; k < 3; ++k) assert_true(fabs(c[k] - c2[k]) < 1e-6);
        assert_true(fabs(c[0] - 0.8) < 1e-6 && fabs(c[1] - 0.2) < 1e-6);
    }
}

/* ==== 5, 6: batch, strides, coherence ========================================== */

typedef struct vtx {
    float pos[3];
    float fog;
    float col[3];
    float pad;
} vtx;

static void random_set(fogvol_analytic_set *set, tvol *vs, int n)
{
    fogvol_analytic_volume raw[FOGVOL_ANALYTIC_CAPACITY];
    int v;
    for (v = 0; v < n; ++v) {
        vs[v] = rand_volume((int)(rnd() * 6));
        vs[v].v.density *= 0.3f;
        raw[v] = vs[v].v;
    }
    assert_int_equal(fogvol_analytic_prepare(raw, n, set), FOGVOL_SUCCESS);
}

static void test_batch_matches_eval(void **state)
{
    enum { N = 1000 };
    vtx *vb = (vtx *)calloc(N, sizeof(vtx));
    float *pos = (float *)calloc(N * 3, sizeof(float)), *fog = (float *)calloc(N, sizeof(float));
    float *col = (float *)calloc(N * 3, sizeof(float));
    tvol vs[12];
    fogvol_analytic_set set;
    float eye[3];
    int law, mix, i, k, inv;
    double worst = 0;
    (void)state;
    assert_non_null(vb);
    assert_non_null(pos);
    random_set(&set, vs, 12);
    rand_point(eye, 3);
    for (i = 0; i < N; ++i) {
        rand_point(&pos[3 * i], 5);
        memcpy(vb[i].pos, &pos[3 * i], 12);
    }
    for (law = 0; law < 3; ++law)
        for (mix = 0; mix < 2; ++mix) {
            /* packed arrays; interleaved vertices with the outputs in the same structs */
            assert_int_equal(fogvol_analytic_batch(&set, eye, pos, N, 0, (fogvol_fog_law)law, (fogvol_fog_mix)mix, fog,
                                                   0, col, 0, NULL, &inv),
                             FOGVOL_SUCCESS);
            assert_int_equal(inv, 0);
            assert_int_equal(fogvol_analytic_batch(&set, eye, vb[0].pos, N, sizeof(vtx), (fogvol_fog_law)law,
                                                   (fogvol_fog_mix)mix, &vb[0].fog, sizeof(vtx), vb[0].col,
                                                   sizeof(vtx), NULL, NULL),
                             FOGVOL_SUCCESS);
            for (i = 0; i < N; ++i) {
                float f, c[3];
                assert_int_equal(fogvol_analytic_eval(&set, eye, &pos[3 * i], (fogvol_fog_law)law, (fogvol_fog_mix)mix,
                                                      &f, c),
                                 FOGVOL_SUCCESS);
                assert_true(fog[i] == vb[i].fog);
                assert_memory_equal(&col[3 * i], vb[i].col, 12);
                worst = fmax(worst, fabs(f - fog[i]));
                for (k = 0; k < 3; ++k) worst = fmax(worst, fabs(c[k] - col[3 * i + k]) * (1 - f));
            }
        }
    print_message("# batch vs eval, 12 volumes, 1000 vertices, 3 laws x 2 mixes: max difference %.2e\n", worst);
    assert_true(worst <= 1e-6);
    /* NULL outputs are allowed; count 0 */
    assert_int_equal(fogvol_analytic_batch(&set, eye, pos, N, 0, FOGVOL_FOG_EXP, FOGVOL_MIX_SEPARATE, NULL, 0, NULL,
                                           0, NULL, NULL),
                     FOGVOL_SUCCESS);
    assert_int_equal(fogvol_analytic_batch(&set, eye, NULL, 0, 0, FOGVOL_FOG_EXP, FOGVOL_MIX_SEPARATE, NULL, 0, NULL,
                                           0, NULL, NULL),
                     FOGVOL_SUCCESS);
    free(vb);
    free(pos);
    free(fog);
    free(col);
}

static void test_order_coherence(void **state)
{
    enum { N = 4096 };
    float *pos = (float *)calloc(N * 3, sizeof(float));
    float *f0 = (float *)calloc(N, sizeof(float)), *f1 = (float *)calloc(N, sizeof(float));
    float *c0 = (float *)calloc(N * 3, sizeof(float)), *c1 = (float *)calloc(N * 3, sizeof(float));
    fogvol_analytic_volume raw[16];
    fogvol_analytic_set set;
    fogvol_analytic_order ord, fresh, batch;
    unsigned char *buf;
    float eye[3] = {0.3f, 0.2f, 9.0f}, eye2[3] = {0.32f, 0.21f, 8.97f};
    int i, mix;
    int64_t first, again, moved, scratch;
    (void)state;
    /* 16 interpenetrating spheres and ellipsoids around the origin, a grid of vertices behind them */
    for (i = 0; i < 16; ++i) {
        tvol t = rand_volume(i % 2 ? FOGVOL_SHAPE_SPHERE : FOGVOL_SHAPE_ELLIPSOID);
        raw[i] = t.v;
        raw[i].density *= 0.1f;
        raw[i].color[0] = (float)i / 16;
    }
    assert_int_equal(fogvol_analytic_prepare(raw, 16, &set), FOGVOL_SUCCESS);
    set.kernel = FOGVOL_ANALYTIC_KERNEL_DOUBLE; /* the kernel that carries orders (the float ones sort hits only) */
    for (i = 0; i < N; ++i) {
        pos[3 * i] = -4.0f + 8.0f * (float)(i % 64) / 63, pos[3 * i + 1] = -4.0f + 8.0f * (float)(i / 64) / 63;
        pos[3 * i + 2] = -5.0f;
    }
    buf = (unsigned char *)malloc(FOGVOL_ANALYTIC_ORDER_BYTES(N, 16));
    assert_non_null(buf);
    for (mix = 0; mix < 2; ++mix) {
        for (i = 0; i < (int)FOGVOL_ANALYTIC_ORDER_BYTES(N, 16); ++i) buf[i] = (unsigned char)(rnd() * 256); /* garbage */
        memset(&ord, 0, sizeof ord);
        ord.vertex_orders = buf;
        ord.vertex_orders_size = FOGVOL_ANALYTIC_ORDER_BYTES(N, 16);
        assert_int_equal(fogvol_analytic_batch(&set, eye, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f0, 0, c0, 0,
                                               NULL, NULL),
                         FOGVOL_SUCCESS);
        assert_int_equal(fogvol_analytic_batch(&set, eye, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f1, 0, c1, 0,
                                               &ord, NULL),
                         FOGVOL_SUCCESS);
        assert_memory_equal(f0, f1, N * sizeof(float)); /* bit-identical */
        assert_memory_equal(c0, c1, 3 * N * sizeof(float));
        first = ord.moves;
        assert_true(ord.sorted_vertices > N / 4);
        assert_int_equal(fogvol_analytic_batch(&set, eye, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f1, 0, c1, 0,
                                               &ord, NULL),
                         FOGVOL_SUCCESS);
        again = ord.moves;
        assert_true(again == 0);
        /* the next frame, the eye moved a little */
        assert_int_equal(fogvol_analytic_batch(&set, eye2, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f1, 0, c1,
                                               0, &ord, NULL),
                         FOGVOL_SUCCESS);
        moved = ord.moves;
        memset(&fresh, 0, sizeof fresh); /* no per-vertex orders: one carried from vertex to vertex */
        memset(&batch, 0, sizeof batch);
        assert_int_equal(fogvol_analytic_batch(&set, eye2, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f0, 0, c0,
                                               0, &fresh, NULL),
                         FOGVOL_SUCCESS);
        assert_memory_equal(f0, f1, N * sizeof(float));
        assert_memory_equal(c0, c1, 3 * N * sizeof(float));
        /* from scratch: every vertex's order reset to the identity before the call */
        {
            fogvol_analytic_order id;
            int j;
            memset(&id, 0, sizeof id);
            id.vertex_orders = buf;
            id.vertex_orders_size = FOGVOL_ANALYTIC_ORDER_BYTES(N, 16);
            for (i = 0; i < N; ++i)
                for (j = 0; j < 32; ++j) buf[32 * i + j] = (unsigned char)j;
            assert_int_equal(fogvol_analytic_batch(&set, eye2, pos, N, 0, FOGVOL_FOG_EXP, (fogvol_fog_mix)mix, f0, 0,
                                                   c0, 0, &id, NULL),
                             FOGVOL_SUCCESS);
            assert_memory_equal(f0, f1, N * sizeof(float));
            scratch = id.moves;
        }
        print_message("# %s, 16 volumes, 64x64 vertices: insertion-sort moves from garbage orders %lld, same frame "
                      "again %lld, eye moved %lld (per-vertex orders) / %lld (one carried order), from scratch %lld\n",
                      mix ? "interpenetrating" : "separate", (long long)first, (long long)again, (long long)moved,
                      (long long)fresh.moves, (long long)scratch);
        assert_true(moved < scratch / 4);
        assert_true(fresh.moves < scratch);
    }
    free(buf);
    free(pos);
    free(f0);
    free(f1);
    free(c0);
    free(c1);
}

/* ==== 6b: the batch's kernels on edge cases ========================================
   Every kernel (double, float in plain C, SSE2, AVX2; each forced through
   fogvol_analytic_set.kernel) against hand-computed chords: vertices exactly on
   sphere and box boundaries, rays tangent to a sphere and grazing it by 1e-7 ..
   0.5 (the lanes the float kernels redo in double), an eye 500 radii away (the
   volumes they evaluate in double whole), FOGVOL_ANALYTIC_CAPACITY disjoint spheres
   on one ray (hit masks up to the last bit; EXP colour by hand), no volumes, zero
   density, NaN and huge vertices, a density float sums could overflow (the double
   kernel runs) and a denormal one; |dfog| and |d(colour * (1 - fog))| <= 1.2e-5. */

#define KN 64 /* vertices per edge-case batch: two blocks, every lane used */

/* runs kernel j on the KN vertices in pos; returns the invalid count */
static int kern_batch(const fogvol_analytic_set *set, int j, const float eye[3], const float *pos, int law,
                      float *fog, float *col)
{
    fogvol_analytic_set ks = *set;
    int inv = -1;
    ks.kernel = kernels[j];
    fogvol_analytic_batch(&ks, eye, pos, KN, 0, (fogvol_fog_law)law, FOGVOL_MIX_INTERPENETRATING, fog, 0, col, 0,
                          NULL, &inv);
    return inv;
}

static double sphere_chord(const double e[3], const double p[3], const double c[3], double r)
{
    /* the part of segment e -> p inside the sphere, in world units, by the closed form */
    double d[3], oc[3], a = 0, b = 0, cc = -r * r, disc, s, t1, t2;
    int k;
    for (k = 0; k < 3; ++k) d[k] = p[k] - e[k], oc[k] = e[k] - c[k];
    for (k = 0; k < 3; ++k) a += d[k] * d[k], b += oc[k] * d[k], cc += oc[k] * oc[k];
    disc = b * b - a * cc;
    if (disc <= 0) return 0;
    s = sqrt(disc);
    t1 = fmax((-b - s) / a, 0), t2 = fmin((-b + s) / a, 1);
    return t2 > t1 ? (t2 - t1) * sqrt(a) : 0;
}

static void test_kernel_edges(void **state)
{
    static float pos[KN * 3], fog[KN], col[KN * 3], fog_c[KN], col_c[KN * 3];
    fogvol_analytic_volume v[FOGVOL_ANALYTIC_CAPACITY];
    fogvol_analytic_set set;
    double want[KN], worst[4] = {0, 0, 0, 0};
    const double dens = 0.7;
    int j, i, k;
    (void)state;
    /* resolve: AUTO is a float kernel, DOUBLE and FLOAT always there, bad values refused */
    assert_true(fogvol_analytic_kernel_resolve(FOGVOL_ANALYTIC_KERNEL_AUTO) >= FOGVOL_ANALYTIC_KERNEL_FLOAT);
    assert_int_equal(fogvol_analytic_kernel_resolve(FOGVOL_ANALYTIC_KERNEL_DOUBLE), FOGVOL_ANALYTIC_KERNEL_DOUBLE);
    assert_int_equal(fogvol_analytic_kernel_resolve(FOGVOL_ANALYTIC_KERNEL_FLOAT), FOGVOL_ANALYTIC_KERNEL_FLOAT);
    assert_int_equal(fogvol_analytic_kernel_resolve((fogvol_analytic_kernel)7), FOGVOL_ANALYTIC_KERNEL_COUNT);
    for (j = 0; j < 4; ++j) print_message("# kernel %-7s %s\n", kernel_name[j], kernel_there(j) ? "runs here" : "not available here");
    memset(v, 0, sizeof v);
    v[0].shape = FOGVOL_SHAPE_SPHERE, v[0].radius = 1, v[0].density = (float)dens, v[0].color[0] = 1;
    assert_int_equal(fogvol_analytic_prepare(v, 1, &set), FOGVOL_SUCCESS);
    {
        /* rays from (0, 0, 5) to (0, y, -5) tangent to the unit sphere (scaled by 1 - delta: grazing it
           inside, or just missing it), and vertices on its boundary: (0, 0, 1) (chord 0), (0, 0, -1) (chord 2), (0.6, 0, -0.8) */
        const float eye[3] = {0, 0, 5};
        for (i = 0; i < KN; ++i) {
            double delta = i < 40 ? (i % 2 ? 1 : -1) * pow(10.0, -7.0 + 0.18 * (i / 2)) : 0.5 * (i - 40) / 24;
            /* the ray from the eye to (0, yt, -5) touches the sphere: 5 yt = sqrt(yt^2 + 100) */
            double y = sqrt(100.0 / 24.0) * (1 - delta), e[3] = {0, 0, 5}, p[3] = {0, 0, -5}, c[3] = {0, 0, 0};
            pos[3 * i] = 0, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = -5;
            p[1] = pos[3 * i + 1];
            want[i] = exp(-dens * sphere_chord(e, p, c, 1));
        }
        pos[0] = 0, pos[1] = 0, pos[2] = 1, want[0] = 1;
        pos[3] = 0, pos[4] = 0, pos[5] = -1, want[1] = exp(-dens * 2);
        pos[6] = 0.6f, pos[7] = 0, pos[8] = -0.8f;
        {
            double e[3] = {0, 0, 5}, p[3] = {0.6f, 0, -0.8f}, c[3] = {0, 0, 0};
            want[2] = exp(-dens * sphere_chord(e, p, c, 1));
        }
        for (j = 0; j < 4; ++j) {
            if (!kernel_there(j)) continue;
            assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 0);
            for (i = 0; i < KN; ++i) worst[j] = fmax(worst[j], fabs(fog[i] - want[i]));
        }
    }
    for (j = 0; j < 4; ++j)
        if (kernel_there(j)) {
            print_message("# %-7s sphere boundaries and rays grazing it by 0 .. 0.5: max |dfog| %.2e\n", kernel_name[j],
                          worst[j]);
            assert_true(worst[j] <= 1.2e-5);
        }
    {
        /* the eye 500 radii from the sphere, vertices behind it: every ray of this volume in double */
        const float eye[3] = {0, 0, 500};
        memset(worst, 0, sizeof worst);
        for (i = 0; i < KN; ++i) {
            double e[3] = {0, 0, 500}, p[3], c[3] = {0, 0, 0};
            pos[3 * i] = (float)(-1.2 + 2.4 * i / (KN - 1)), pos[3 * i + 1] = 0.3f, pos[3 * i + 2] = -3;
            for (k = 0; k < 3; ++k) p[k] = pos[3 * i + k];
            want[i] = exp(-dens * sphere_chord(e, p, c, 1));
        }
        for (j = 0; j < 4; ++j) {
            if (!kernel_there(j)) continue;
            assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 0);
            for (i = 0; i < KN; ++i) worst[j] = fmax(worst[j], fabs(fog[i] - want[i]));
            print_message("# %-7s eye 500 radii away: max |dfog| %.2e\n", kernel_name[j], worst[j]);
            assert_true(worst[j] <= 1.2e-5);
        }
    }
    {
        /* a box [-1,1]^3 scaled by 2: vertices on its faces and edges, the eye outside */
        const float eye[3] = {0.5f, 0.25f, 7};
        fogvol_analytic_volume b;
        memset(&b, 0, sizeof b);
        b.shape = FOGVOL_SHAPE_BOX, b.density = (float)dens;
        glu_translate_scale(b.transform, 0, 0, 0, 2);
        assert_int_equal(fogvol_analytic_prepare(&b, 1, &set), FOGVOL_SUCCESS);
        for (i = 0; i < KN; ++i) {
            /* vertex on the back face z = -2 (chord 4 when it enters through the front face) or the front one */
            double x = -2 + 4.0 * (i % 8) / 7, y = -2 + 4.0 * (i / 8) / 7, zf = i % 3 ? -2 : 2, tin;
            pos[3 * i] = (float)x, pos[3 * i + 1] = (float)y, pos[3 * i + 2] = (float)zf;
            /* the segment enters at z = 2 (t = (7 - 2) / (7 - zf)); x, y stay inside: linear in t between
               eye and vertex, both within [-2, 2] at the entry */
            tin = zf < 0 ? 5.0 / 9.0 : 1;
            {
                double ex = 0.5 + tin * (x - 0.5), ey = 0.25 + tin * (y - 0.25), len = sqrt((x - 0.5) * (x - 0.5) + (y - 0.25) * (y - 0.25) + (zf - 7) * (zf - 7));
                assert_true(fabs(ex) <= 2 && fabs(ey) <= 2);
                want[i] = exp(-dens * (1 - tin) * len);
            }
        }
        memset(worst, 0, sizeof worst);
        for (j = 0; j < 4; ++j) {
            if (!kernel_there(j)) continue;
            assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 0);
            for (i = 0; i < KN; ++i) worst[j] = fmax(worst[j], fabs(fog[i] - want[i]));
            print_message("# %-7s box, vertices on its faces and edges: max |dfog| %.2e\n", kernel_name[j], worst[j]);
            assert_true(worst[j] <= 1.2e-5);
        }
    }
    {
        /* FOGVOL_ANALYTIC_CAPACITY disjoint spheres of radius 0.04 on the z axis, each its own colour; the vertex
           at z = -1 behind them all (every hit bit set) or between them; EXP by hand: sphere s (front to back)
           covers T_s (1 - exp(-0.08 dens)) */
        const float eye[3] = {0, 0, 1};
        const int n = FOGVOL_ANALYTIC_CAPACITY;
        const double dz = 4.0 / n;
        for (i = 0; i < n; ++i) {
            memset(&v[i], 0, sizeof v[i]);
            v[i].shape = FOGVOL_SHAPE_SPHERE, v[i].radius = 0.04f, v[i].density = 0.3f;
            v[i].center[2] = (float)(0.5 - dz * i);
            v[i].color[0] = (float)i / n, v[i].color[1] = 1 - (float)i / n, v[i].color[2] = (float)(i % 3) / 2;
        }
        assert_int_equal(fogvol_analytic_prepare(v, n, &set), FOGVOL_SUCCESS);
        for (i = 0; i < KN; ++i) {
            int last = i % (n + 1); /* spheres passed whole */
            pos[3 * i] = 0, pos[3 * i + 1] = 0;
            pos[3 * i + 2] = (float)(0.5 - dz * last + 0.5 * dz);
        }
        memset(worst, 0, sizeof worst);
        for (j = 0; j < 4; ++j) {
            if (!kernel_there(j)) continue;
            assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 0);
            for (i = 0; i < KN; ++i) {
                int last = i % (n + 1), s2;
                double t = 1, num[3] = {0, 0, 0}, a = exp(-0.3 * 2 * (double)0.04f);
                for (s2 = 0; s2 < last; ++s2) {
                    for (k = 0; k < 3; ++k) num[k] += v[s2].color[k] * t * (1 - a);
                    t *= a;
                }
                worst[j] = fmax(worst[j], fabs(fog[i] - t));
                for (k = 0; k < 3; ++k) worst[j] = fmax(worst[j], fabs(col[3 * i + k] * (1 - fog[i]) - num[k]));
            }
            print_message("# %-7s %d disjoint spheres on one ray (EXP, colours): max |d| %.2e\n", kernel_name[j], n,
                          worst[j]);
            assert_true(worst[j] <= 1.2e-5);
            /* up to n stretches per vertex, more than a block's stretch buffer holds: the SIMD kernels
               flush it mid-block, and still give the plain-C float kernel's bits */
            if (j == 1) memcpy(fog_c, fog, sizeof fog_c), memcpy(col_c, col, sizeof col_c);
            if (j >= 2 && kernel_there(1)) {
                assert_memory_equal(fog, fog_c, sizeof fog_c);
                assert_memory_equal(col, col_c, sizeof col_c);
            }
        }
    }
    {
        /* no volumes; zero density; NaN and huge vertices (the huge ones match the double kernel) */
        const float eye[3] = {0.1f, 0.2f, 3};
        float fd[KN], cd[KN * 3];
        for (i = 0; i < KN; ++i) rand_point(&pos[3 * i], 3);
        pos[3 * 5 + 1] = (float)NAN, pos[3 * 9] = (float)INFINITY;
        pos[3 * 7] = 1e30f, pos[3 * 7 + 2] = -1e30f, pos[3 * 8 + 1] = -3e20f;
        for (k = 0; k < 2; ++k) {
            memset(v, 0, sizeof v);
            v[0].shape = FOGVOL_SHAPE_HALF_SPACE, v[0].plane[1] = 1, v[0].density = k ? 0.0f : 0.2f;
            v[1].shape = FOGVOL_SHAPE_ELLIPSOID, v[1].density = k ? 0.0f : 0.5f, v[1].color[2] = 1;
            v[2].shape = FOGVOL_SHAPE_DISTANCE, v[2].max_distance = 0, v[2].density = k ? 0.0f : 1e-3f;
            assert_int_equal(fogvol_analytic_prepare(v, 3, &set), FOGVOL_SUCCESS);
            assert_int_equal(kern_batch(&set, 0, eye, pos, FOGVOL_FOG_EXP, fd, cd), 2);
            for (j = 1; j < 4; ++j) {
                if (!kernel_there(j)) continue;
                assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 2);
                assert_true(fog[5] == 1 && fog[9] == 1 && col[15] == 0 && col[27] == 0);
                for (i = 0; i < KN; ++i) {
                    assert_true(fog[i] >= 0 && fog[i] <= 1 && isfinite(col[3 * i]));
                    assert_true(fabs(fog[i] - fd[i]) <= 1.2e-5);
                    if (k) assert_true(fog[i] == 1 && col[3 * i] == 0 && col[3 * i + 2] == 0);
                }
                assert_true((fog[7] < 1) == (fd[7] < 1) && (fog[8] < 1) == (fd[8] < 1)); /* the huge ones went through the half-space */
            }
        }
        assert_int_equal(fogvol_analytic_prepare(NULL, 0, &set), FOGVOL_SUCCESS);
        for (j = 0; j < 4; ++j) {
            if (!kernel_there(j)) continue;
            assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_LINEAR, fog, col), 2);
            for (i = 0; i < KN; ++i) assert_true(fog[i] == 1 && col[3 * i] == 0 && col[3 * i + 1] == 0);
        }
        /* numbers a float sum could overflow (density 1e7): the call runs the double kernel, bit for bit;
           a denormal density: no NaN */
        memset(v, 0, sizeof v);
        v[0].shape = FOGVOL_SHAPE_SPHERE, v[0].radius = 2, v[0].density = 1e7f, v[0].color[1] = 1;
        v[1].shape = FOGVOL_SHAPE_SPHERE, v[1].radius = 1, v[1].density = 1e-40f, v[1].color[0] = 1;
        v[1].center[0] = 0.5f;
        for (k = 0; k < 2; ++k) {
            assert_int_equal(fogvol_analytic_prepare(v + k, 1, &set), FOGVOL_SUCCESS);
            assert_int_equal(kern_batch(&set, 0, eye, pos, FOGVOL_FOG_EXP, fd, cd), 2);
            for (j = 1; j < 4; ++j) {
                if (!kernel_there(j)) continue;
                assert_int_equal(kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col), 2);
                for (i = 0; i < KN; ++i) {
                    assert_true(fog[i] >= 0 && fog[i] <= 1);
                    assert_true(isfinite(col[3 * i]) && isfinite(col[3 * i + 1]) && isfinite(col[3 * i + 2]));
                    if (!k) assert_true(fog[i] == fd[i] && col[3 * i + 1] == cd[3 * i + 1]);
                    else assert_true(fabs(fog[i] - fd[i]) <= 1.2e-5);
                }
            }
        }
        set.kernel = 99; /* not a kernel */
        assert_int_equal(fogvol_analytic_batch(&set, eye, pos, KN, 0, FOGVOL_FOG_EXP, FOGVOL_MIX_SEPARATE, fog, 0, NULL,
                                               0, NULL, NULL),
                         FOGVOL_ERROR_INVALID_ARGUMENT);
    }
}

/* ==== 7: degenerate input ======================================================= */

/* The float kernels skip, per block of 32 vertices, the volumes whose bounding
   sphere lies outside the cone of the block's rays. Fans of 32 rays whose first
   ray passes just inside a volume near the point furthest from its centre (where
   the bounding sphere is tightest: 0.999 of the way out, or 1.001: just outside)
   and whose other rays turn away from it by up to 40 degrees; every shape with a
   bounding sphere, rotated/scaled and sheared transforms, eyes all around. The
   first ray's fog against the ground-truth chord (the test's inside predicate and
   bisection): |dfog| <= 1.2e-5 for every float kernel (a volume skipped wrongly
   would leave fog 1 there, about 0.1 away). */
static void test_block_culling(void **state)
{
    static float pos[KN * 3], fog[KN], col[KN * 3];
    double worst[4] = {0, 0, 0, 0};
    int shape, trial, j, i, k, hits = 0;
    (void)state;
    for (shape = FOGVOL_SHAPE_SPHERE; shape <= FOGVOL_SHAPE_CYLINDER; ++shape)
        for (trial = 0; trial < 40; ++trial) {
            tvol t = rand_volume(shape);
            fogvol_analytic_set set;
            float ext[3], c[3], eye[3], x[3];
            double want[2], best = -1, y[3] = {0, 0, 0}, u[3], dir[3], w[3], rl = 0, wl = 0, dot = 0, far, len;
            t.v.density = 1.0f;
            tv_to_world(&t, y, c);
            for (k = 0; k < 256; ++k) { /* the unit shape's boundary point furthest from the centre */
                float q[3];
                double d = 0;
                rnd_unit(u);
                if (shape == FOGVOL_SHAPE_BOX) u[0] = u[0] < 0 ? -1 : 1, u[1] = u[1] < 0 ? -1 : 1, u[2] = u[2] < 0 ? -1 : 1;
                if (shape == FOGVOL_SHAPE_CYLINDER) {
                    double r = sqrt(u[0] * u[0] + u[1] * u[1]);
                    u[0] /= r, u[1] /= r, u[2] = u[2] < 0 ? -1 : 1;
                }
                tv_to_world(&t, u, q);
                for (i = 0; i < 3; ++i) d += (q[i] - c[i]) * (q[i] - c[i]);
                if (d > best) best = d, ext[0] = q[0], ext[1] = q[1], ext[2] = q[2];
            }
            far = sqrt(best);
            rnd_unit(u);
            for (i = 0; i < 3; ++i) eye[i] = (float)(c[i] + u[i] * far * rnd_range(1.5, 6));
            assert_int_equal(fogvol_analytic_prepare(&t.v, 1, &set), FOGVOL_SUCCESS);
            for (k = 0; k < 2; ++k) { /* block k: the first ray 0.999 / 1.001 of the way out */
                double s = k == 0 ? 0.999 : 1.001, a = 0, b = 0, seeds[256];
                for (i = 0; i < 3; ++i) x[i] = (float)(c[i] + s * (ext[i] - c[i]));
                for (i = 0; i < 3; ++i) dir[i] = 1.5 * (x[i] - eye[i]), rl += dir[i] * dir[i];
                rl = sqrt(rl);
                for (i = 0; i < 3; ++i) dot += (x[i] - c[i]) * dir[i] / rl;
                for (i = 0; i < 3; ++i) w[i] = (x[i] - c[i]) - dot * dir[i] / rl, wl += w[i] * w[i];
                wl = sqrt(wl) + 1e-30;
                for (j = 0; j < 32; ++j)
                    for (i = 0; i < 3; ++i)
                        pos[3 * (32 * k + j) + i] = (float)(eye[i] + dir[i] + w[i] / wl * rl * tan(0.7 * j / 31.0));
                len = 0;
                for (i = 0; i < 3; ++i) len += ((double)pos[96 * k + i] - eye[i]) * ((double)pos[96 * k + i] - eye[i]);
                for (i = 0; i < 256; ++i) seeds[i] = 1 / 1.5 + (i - 128) * 2e-5; /* around the point 1.5 from the eye */
                want[k] = gt_segment(&t, eye, &pos[96 * k], seeds, 256, &a, &b) ? exp(-sqrt(len) * (b - a)) : 1.0;
                hits += want[k] < 0.999;
                rl = wl = dot = 0;
            }
            for (j = 1; j < 4; ++j) {
                if (!kernel_there(j)) continue;
                kern_batch(&set, j, eye, pos, FOGVOL_FOG_EXP, fog, col);
                for (k = 0; k < 2; ++k) worst[j] = fmax(worst[j], fabs(fog[32 * k] - want[k]));
            }
        }
    for (j = 1; j < 4; ++j)
        if (kernel_there(j))
            print_message("# %-7s fans of rays at the volumes' furthest points (%d of 320 hit): max |dfog| %.2e\n",
                          kernel_name[j], hits, worst[j]);
    assert_true(hits >= 100);
    for (j = 1; j < 4; ++j) assert_true(worst[j] <= 1.2e-5);
}

/* 6d: the SIMD kernels' own gather (whole blocks of 8 read with AVX2 gathers, strides up to 1 MB),
   culling and exp() (the order-free fog, the sorted vertices' stretches) against the plain-C float
   kernel, which does the same arithmetic: bit for bit over 995
   to 1000 vertices (whole blocks and a partial one) at strides of 12, 16, 20 and 4096 bytes, with
   NaN, infinite, 1e10 and 3e20 coordinates mixed in, six interpenetrating volumes of every bounded
   shape, every law and mix; the invalid counts equal too. */
static void test_kernel_strides(void **state)
{
    static float buf[1000 * 1024], fog[2][1000], col[2][3000];
    static const int strides[4] = {12, 16, 20, 4096};
    fogvol_analytic_volume v[6];
    fogvol_analytic_set set;
    const float eye[3] = {0.5f, 1.5f, 9.0f};
    int si, law, mix, i, j, k, c, compared = 0, invalid = 0;
    (void)state;
    for (i = 0; i < 6; ++i) v[i] = rand_volume(FOGVOL_SHAPE_SPHERE + i % 4).v;
    assert_int_equal(fogvol_analytic_prepare(v, 6, &set), FOGVOL_SUCCESS);
    for (si = 0; si < 4; ++si)
        for (law = FOGVOL_FOG_LINEAR; law <= FOGVOL_FOG_LINEAR_SEED; ++law)
            for (mix = FOGVOL_MIX_SEPARATE; mix <= FOGVOL_MIX_INTERPENETRATING; ++mix) {
                int n = 1000 - 2 * si - law, inv[2];
                for (i = 0; i < n; ++i) {
                    float *q = (float *)((char *)buf + (size_t)i * (size_t)strides[si]);
                    double r = rnd();
                    for (c = 0; c < 3; ++c) q[c] = (float)rnd_range(-4, 4);
                    c = (int)(rnd() * 3);
                    if (r < 0.03) q[c] = NAN;
                    else if (r < 0.06) q[c] = rnd() < 0.5 ? INFINITY : -INFINITY;
                    else if (r < 0.09) q[c] = rnd() < 0.5 ? 3e20f : -1e10f;
                }
                for (j = 2; j < 4; ++j) {
                    if (!kernel_there(j)) continue;
                    for (k = 0; k < 2; ++k) { /* non-finite vertices: INVALID_ARGUMENT, fog 1, colour 0 */
                        fogvol_analytic_set ks = set;
                        ks.kernel = kernels[k ? j : 1];
                        assert_int_equal(fogvol_analytic_batch(&ks, eye, buf, n, strides[si], (fogvol_fog_law)law,
                                                               (fogvol_fog_mix)mix, fog[k], 0, col[k], 0, NULL, &inv[k]),
                                         FOGVOL_ERROR_INVALID_ARGUMENT);
                    }
                    assert_int_equal(inv[0], inv[1]);
                    assert_memory_equal(fog[0], fog[1], (size_t)n * sizeof(float));
                    assert_memory_equal(col[0], col[1], (size_t)n * 3 * sizeof(float));
                    compared += n;
                    invalid += inv[0];
                }
            }
    print_message("# SSE2/AVX2 = float C bit for bit on %d strided vertices (%d of them invalid)\n", compared, invalid);
    assert_true(invalid > 0);
}

static void test_degenerate(void **state)
{
    fogvol_analytic_volume v[40], ok;
    fogvol_analytic_set set;
    float eye[3] = {0, 0, 5}, p[3] = {0, 0, -5}, t1, t2, f, c[3];
    const float nanf_ = (float)NAN, inff = (float)INFINITY;
    int i, inv;
    (void)state;
    memset(&ok, 0, sizeof ok);
    ok.shape = FOGVOL_SHAPE_SPHERE;
    ok.radius = 1;
    ok.density = 0.5f;
    ok.color[1] = 1;
    /* a zeroed volume is valid (no fog); a zeroed transform is the identity */
    memset(v, 0, sizeof v);
    assert_int_equal(fogvol_analytic_prepare(v, 1, &set), FOGVOL_SUCCESS);
    assert_int_equal(set.count, 1);
    v[0].shape = FOGVOL_SHAPE_ELLIPSOID;
    v[0].density = 1;
    assert_int_equal(fogvol_analytic_segment(&v[0], eye, p, &t1, &t2), FOGVOL_SUCCESS);
    assert_true(fabs(t1 - 0.4) < 1e-6 && fabs(t2 - 0.6) < 1e-6);
    /* each bad volume: INVALID_ARGUMENT from segment and prepare, left out, the good one stays */
    for (i = 0; i < 16; ++i) {
        fogvol_analytic_volume bad[2];
        float e2;
        bad[0] = ok;
        bad[1] = ok;
        switch (i) {
        case 0: bad[0].radius = 0; break;                                  /* zero-size sphere */
        case 1: bad[0].radius = -1; break;
        case 2: bad[0].shape = FOGVOL_SHAPE_ELLIPSOID; glu_translate_scale(bad[0].transform, 0, 0, 0, 1);
                bad[0].transform[10] = 0; break;                             /* flat ellipsoid */
        case 3: bad[0].shape = FOGVOL_SHAPE_BOX; glu_identity(bad[0].transform);
                bad[0].transform[4] = 1; bad[0].transform[5] = 0; break;     /* rank 2 box */
        case 4: bad[0].shape = FOGVOL_SHAPE_CYLINDER; glu_identity(bad[0].transform); /* col2 = col0 + col1 */
                bad[0].transform[8] = 1; bad[0].transform[9] = 1; bad[0].transform[10] = 1e-7f; break;
        case 5: bad[0].shape = FOGVOL_SHAPE_ELLIPSOID; glu_identity(bad[0].transform); bad[0].transform[3] = 0.5f; break;
        case 6: bad[0].shape = FOGVOL_SHAPE_BOX; glu_identity(bad[0].transform); bad[0].transform[15] = 2; break;
        case 7: bad[0].shape = FOGVOL_SHAPE_ELLIPSOID; glu_identity(bad[0].transform); bad[0].transform[13] = nanf_; break;
        case 8: bad[0].shape = FOGVOL_SHAPE_HALF_SPACE; memset(bad[0].plane, 0, sizeof bad[0].plane);
                bad[0].plane[3] = 1; break;                                  /* zero normal */
        case 9: bad[0].shape = FOGVOL_SHAPE_DISTANCE; bad[0].min_distance = 5; bad[0].max_distance = 5; break;
        case 10: bad[0].shape = FOGVOL_SHAPE_DISTANCE; bad[0].min_distance = 5; bad[0].max_distance = 2; break;
        case 11: bad[0].shape = FOGVOL_SHAPE_DISTANCE; bad[0].min_distance = -1; break;
        case 12: bad[0].density = -0.5f; break;
        case 13: bad[0].color[2] = inff; break;
        case 14: bad[0].center[0] = nanf_; break;
        case 15: bad[0].shape = (fogvol_analytic_shape)77; break;
        }
        assert_int_equal(fogvol_analytic_segment(&bad[0], eye, p, &t1, &t2), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_true(t1 == 0 && t2 == 0);
        assert_int_equal(fogvol_analytic_prepare(bad, 2, &set), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(set.count, 1);
        assert_int_equal(set.ignored, 1);
        assert_int_equal(set.source[0], 1);
        assert_int_equal(fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_EXP, FOGVOL_MIX_INTERPENETRATING, &f, c),
                         FOGVOL_SUCCESS);
        e2 = (float)exp(-1.0); /* the good sphere: chord 2, density 0.5 */
        assert_true(fabs(f - e2) < 1e-6 && c[1] == 1);
    }
    /* a huge max_distance means no far bound */
    v[0] = ok;
    v[0].shape = FOGVOL_SHAPE_DISTANCE;
    v[0].min_distance = 1, v[0].max_distance = 3e38f;
    assert_int_equal(fogvol_analytic_prepare(v, 1, &set), FOGVOL_SUCCESS);
    assert_true(set.map[0][0] == 1 && set.map[0][1] == 0);
    /* too many volumes */
    for (i = 0; i < 40; ++i) v[i] = ok;
    assert_int_equal(fogvol_analytic_prepare(v, 40, &set), FOGVOL_ERROR_BUFFER_TOO_SMALL);
    assert_int_equal(set.count, FOGVOL_ANALYTIC_CAPACITY);
    assert_int_equal(set.truncated, 40 - FOGVOL_ANALYTIC_CAPACITY);
    v[0].radius = 0;
    assert_int_equal(fogvol_analytic_prepare(v, 40, &set), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_analytic_prepare(v, 1, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_analytic_prepare(NULL, 1, &set), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_analytic_prepare(v, -1, &set), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* NaN / infinite vertices and eye: fog 1, colour 0, counted; others as eval */
    {
        float pos[8][3] = {{0, 0, -5}, {0, nanf_, -5}, {0.5f, 0, -5}, {inff, 0, 0}, {0, 0, -inff}, {0, 0, 5},
                           {1e30f, 1e30f, -1e30f}, {0.1f, 0.1f, 4.9f}};
        float fog[8], col[24];
        fogvol_analytic_volume two[3];
        two[0] = ok;
        two[1] = ok;
        two[1].shape = FOGVOL_SHAPE_DISTANCE;
        two[1].min_distance = 2;
        two[1].max_distance = 0;
        two[1].color[0] = 1;
        two[1].density = 0.01f;
        two[2] = ok;
        two[2].shape = FOGVOL_SHAPE_HALF_SPACE;
        two[2].plane[1] = 1;
        two[2].density = 0.02f;
        assert_int_equal(fogvol_analytic_prepare(two, 3, &set), FOGVOL_SUCCESS);
        for (i = 0; i < 3; ++i) {
            int law;
            for (law = 0; law < 3; ++law) {
                assert_int_equal(fogvol_analytic_batch(&set, eye, &pos[0][0], 8, 0, (fogvol_fog_law)law,
                                                       (fogvol_fog_mix)(i % 2), fog, 0, col, 0, NULL, &inv),
                                 FOGVOL_ERROR_INVALID_ARGUMENT);
                assert_int_equal(inv, 3);
                assert_true(fog[1] == 1 && fog[3] == 1 && fog[4] == 1);
                assert_true(col[3] == 0 && col[4] == 0 && col[5] == 0 && col[9] == 0 && col[14] == 0);
                assert_true(fog[5] == 1); /* the vertex at the eye */
                {
                    int k;
                    for (k = 0; k < 8; ++k) {
                        assert_true(fog[k] >= 0 && fog[k] <= 1);
                        assert_true(isfinite(col[3 * k]) && isfinite(col[3 * k + 1]) && isfinite(col[3 * k + 2]));
                    }
                }
                assert_int_equal(fogvol_analytic_eval(&set, eye, pos[1], (fogvol_fog_law)law, FOGVOL_MIX_SEPARATE, &f,
                                                      c),
                                 FOGVOL_ERROR_INVALID_ARGUMENT);
                assert_true(f == 1 && c[0] == 0 && c[1] == 0 && c[2] == 0);
            }
        }
        {
            float bad_eye[3] = {0, nanf_, 0};
            assert_int_equal(fogvol_analytic_batch(&set, bad_eye, &pos[0][0], 8, 0, FOGVOL_FOG_LINEAR,
                                                   FOGVOL_MIX_SEPARATE, fog, 0, col, 0, NULL, &inv),
                             FOGVOL_ERROR_INVALID_ARGUMENT);
            assert_int_equal(inv, 8);
            for (i = 0; i < 8; ++i) assert_true(fog[i] == 1 && col[3 * i] == 0);
            assert_int_equal(fogvol_analytic_segment(&ok, bad_eye, p, &t1, &t2), FOGVOL_ERROR_INVALID_ARGUMENT);
        }
        /* bad arguments */
        assert_int_equal(fogvol_analytic_batch(&set, eye, &pos[0][0], 8, 8, FOGVOL_FOG_LINEAR, FOGVOL_MIX_SEPARATE, fog,
                                               0, col, 0, NULL, &inv),
                         FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_analytic_batch(&set, eye, &pos[0][0], 8, 0, (fogvol_fog_law)3, FOGVOL_MIX_SEPARATE,
                                               fog, 0, col, 0, NULL, &inv),
                         FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_analytic_eval(&set, eye, p, FOGVOL_FOG_LINEAR, (fogvol_fog_mix)2, &f, c),
                         FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(fogvol_analytic_eval(NULL, eye, p, FOGVOL_FOG_LINEAR, FOGVOL_MIX_SEPARATE, &f, c),
                         FOGVOL_ERROR_INVALID_ARGUMENT);
    }
    /* extreme but finite volumes and points: never NaN, fog in [0, 1] */
    {
        double worst_bad = 0;
        int k;
        for (k = 0; k < 3000; ++k) {
            fogvol_analytic_volume w[4];
            float e3[3], q[3], scale = (float)pow(10.0, rnd_range(-30, 30));
            int j, law = k % 3;
            for (j = 0; j < 4; ++j) {
                tvol t = rand_volume((int)(rnd() * 6));
                int m;
                w[j] = t.v;
                w[j].density = (float)pow(10.0, rnd_range(-30, 30));
                w[j].radius *= scale;
                w[j].min_distance *= scale;
                w[j].max_distance *= scale;
                for (m = 0; m < 3; ++m) w[j].center[m] *= scale;
                for (m = 0; m < 16; ++m)
                    if (m != 15) w[j].transform[m] *= scale;
                w[j].plane[3] *= scale;
            }
            fogvol_analytic_prepare(w, 4, &set); /* some may be refused (map out of range) */
            rand_point(e3, 3);
            rand_point(q, 3);
            for (j = 0; j < 3; ++j) e3[j] *= scale, q[j] *= (float)pow(10.0, rnd_range(-30, 30));
            fogvol_analytic_eval(&set, e3, q, (fogvol_fog_law)law, (fogvol_fog_mix)(k % 2), &f, c);
            if (!(f >= 0 && f <= 1) || !isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2])) worst_bad = 1;
            for (j = 0; j < 4; ++j) {
                fogvol_analytic_segment(&w[j], e3, q, &t1, &t2);
                if (!(t1 >= 0 && t2 <= 1 && t1 <= t2)) worst_bad = 1;
            }
        }
        assert_true(worst_bad == 0);
    }
}

/* ==== 8, 9: fold, uniforms ======================================================= */

static void test_fold(void **state)
{
    const float d[4] = {0.8f, 0.6f, 0.4f, 0.5f}, s[4] = {0.1f, 0.2f, 0.3f, 1.0f}, fc[3] = {0.0f, 0.5f, 1.0f};
    float nd[4], ns[4], tex[3] = {0.9f, 0.3f, 0.6f};
    int i;
    (void)state;
    fogvol_fold_fog(d, s, 0.25f, fc, nd, ns);
    /* new diffuse = diffuse * fog, new specular = specular * fog + fog colour * (1 - fog) */
    assert_true(fabs(nd[0] - 0.2) < 1e-7 && fabs(nd[1] - 0.15) < 1e-7 && fabs(nd[2] - 0.1) < 1e-7 && nd[3] == 0.5f);
    assert_true(fabs(ns[0] - 0.025) < 1e-7 && fabs(ns[1] - 0.425) < 1e-7 && fabs(ns[2] - 0.825) < 1e-7 &&
                ns[3] == 1.0f);
    /* texture * newDiffuse + newSpecular = (texture * diffuse + specular) * fog + fogColor * (1 - fog) */
    for (i = 0; i < 3; ++i)
        assert_true(fabs(tex[i] * nd[i] + ns[i] - ((tex[i] * d[i] + s[i]) * 0.25 + fc[i] * 0.75)) < 1e-6);
    memcpy(nd, d, sizeof nd);
    memcpy(ns, s, sizeof ns);
    fogvol_fold_fog(nd, ns, (float)NAN, fc, nd, ns); /* in place; NaN fog = no fog */
    assert_memory_equal(nd, d, sizeof nd);
    assert_memory_equal(ns, s, sizeof ns);
    fogvol_fold_fog(d, s, 7.0f, fc, nd, ns); /* clamped to 1 */
    assert_memory_equal(nd, d, sizeof nd);
    fogvol_fold_fog(d, s, -1.0f, fc, nd, ns); /* clamped to 0 */
    assert_true(nd[0] == 0 && ns[0] == fc[0] && ns[1] == fc[1] && ns[2] == fc[2]);
    fogvol_fold_fog(NULL, NULL, 0.5f, fc, NULL, NULL);
}

static void test_pack_uniforms(void **state)
{
    fogvol_analytic_volume v[10];
    fogvol_analytic_set set;
    float u[FOGVOL_ANALYTIC_UNIFORM_FLOATS], eye[3] = {1, 2, 3};
    int i;
    (void)state;
    assert_int_equal(FOGVOL_ANALYTIC_UNIFORM_FLOATS, 168);
    memset(v, 0, sizeof v);
    v[0].shape = FOGVOL_SHAPE_SPHERE;
    v[0].center[0] = 2, v[0].center[1] = -1, v[0].center[2] = 4, v[0].radius = 2;
    v[0].density = 0.5f, v[0].color[0] = 0.25f, v[0].color[1] = 0.5f, v[0].color[2] = 0.75f;
    v[1].shape = FOGVOL_SHAPE_DISTANCE;
    v[1].min_distance = 3, v[1].max_distance = 9, v[1].density = 1.0f / 6;
    v[2].shape = FOGVOL_SHAPE_HALF_SPACE;
    v[2].plane[1] = -2, v[2].plane[3] = 4, v[2].density = 1;
    v[3].shape = FOGVOL_SHAPE_BOX;
    glu_translate_scale(v[3].transform, 1, 1, 1, 4);
    v[3].density = 2;
    assert_int_equal(fogvol_analytic_prepare(v, 4, &set), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_analytic_pack_uniforms(&set, eye, FOGVOL_FOG_EXP, FOGVOL_MIX_INTERPENETRATING, u),
                     FOGVOL_SUCCESS);
    assert_true(u[0] == 1 && u[1] == 2 && u[2] == 3 && u[3] == 4);
    assert_true(u[4] == 1 && u[5] == 1);
    /* sphere: rows of (X - c) / r, then colour + density, shape */
    assert_true(u[8] == 0.5f && u[9] == 0 && u[10] == 0 && u[11] == -1.0f);
    assert_true(u[12] == 0 && u[13] == 0.5f && u[15] == 0.5f && u[19] == -2.0f);
    assert_true(u[20] == 0.25f && u[21] == 0.5f && u[22] == 0.75f && u[23] == 0.5f && u[24] == 2);
    /* distance: (min, max); half-space: unit normal; box: inverse of scale 4 + translation */
    assert_true(u[28] == 3 && u[29] == 9 && u[44] == 0);
    assert_true(u[48] == 0 && u[49] == -1 && u[50] == 0 && u[51] == 2 && u[64] == 1);
    assert_true(u[68] == 0.25f && u[71] == -0.25f && u[73] == 0.25f && u[78] == 0.25f && u[79] == -0.25f && u[84] == 4);
    for (i = 88; i < FOGVOL_ANALYTIC_UNIFORM_FLOATS; ++i) assert_true(u[i] == 0);
    for (i = 4; i < 10; ++i) v[i] = v[0];
    assert_int_equal(fogvol_analytic_prepare(v, 10, &set), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_analytic_pack_uniforms(&set, eye, FOGVOL_FOG_LINEAR, FOGVOL_MIX_SEPARATE, u),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_true(u[3] == 8);
}

/* ==== 10: glslangValidator ========================================================= */

static const char *const dialect_tag[FOGVOL_GLSL_COUNT] = {"auto", "110", "120", "130", "150", "330", "100", "300es",
                                                           "vulkan"};

static void test_shaders_glslang(void **state)
{
    const char *b = getenv("BUILD") ? getenv("BUILD") : "build";
    char dir[512], cmd[4096];
    int d, st, pp, n = 0, failed = 0;
    (void)state;
    {
        const char *s[FOGVOL_MAX_SHADER_STRINGS];
        int count = 7;
        assert_int_equal(fogvol_analytic_shader_strings(FOGVOL_GLSL_AUTO, FOGVOL_STAGE_VERTEX, 0, s, &count),
                         FOGVOL_ERROR_UNSUPPORTED);
        assert_int_equal(count, 0);
        assert_int_equal(fogvol_analytic_shader_strings((fogvol_dialect)99, FOGVOL_STAGE_VERTEX, 0, s, &count),
                         FOGVOL_ERROR_UNSUPPORTED);
        assert_int_equal(fogvol_analytic_snippet(NULL, 0), 3);
        assert_int_equal(fogvol_analytic_snippet(s, 2), 3);
    }
    if (system("glslangValidator --version > /dev/null 2>&1") != 0) {
        print_message("# glslangValidator not installed (apt-get install glslang-tools): skipped\n");
        skip();
    }
    snprintf(dir, sizeof dir, "%s/analytic_shaders", b);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    for (d = 1; d < FOGVOL_GLSL_COUNT; ++d)
        for (pp = 0; pp < 2; ++pp)
            for (st = 0; st < 2; ++st) {
                const char *s[FOGVOL_MAX_SHADER_STRINGS];
                char path[700];
                int count, i;
                FILE *f;
                assert_int_equal(fogvol_analytic_shader_strings((fogvol_dialect)d, (fogvol_stage)st, pp, s, &count),
                                 FOGVOL_SUCCESS);
                snprintf(path, sizeof path, "%s/analytic_%s_%s.%s", dir, pp ? "pixel" : "vertex", dialect_tag[d],
                         st ? "frag" : "vert");
                f = fopen(path, "w");
                assert_non_null(f);
                for (i = 0; i < count; ++i) fputs(s[i], f);
                fclose(f);
                if (d == FOGVOL_GLSL_VULKAN) /* to SPIR-V, validated (the block, explicit locations) */
                    snprintf(cmd, sizeof cmd, "glslangValidator -V '%s' -o '%s.spv' > '%s.log' 2>&1 && "
                             "spirv-val '%s.spv' >> '%s.log' 2>&1", path, path, path, path, path);
                else
                    snprintf(cmd, sizeof cmd, "glslangValidator '%s' > '%s.log' 2>&1", path, path);
                if (system(cmd) != 0) {
                    print_message("# glslangValidator failed on %s (see %s.log)\n", path, path);
                    ++failed;
                }
                ++n;
            }
    print_message("# %d analytic shaders written to %s, %d rejected by glslangValidator\n", n, dir, failed);
    assert_int_equal(failed, 0);
}

/* ==== 11: GLSL = CPU under OSMesa ================================================= */

#define GW 32
#define GH 32

static GLuint gl_shader(GLenum type, const char **s, int n, const char *what)
{
    GLuint sh = glCreateShader(type);
    GLint ok = 0;
    glShaderSource(sh, n, s, NULL);
    glCompileShader(sh);
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        print_message("# %s: %s\n", what, log);
        glDeleteShader(sh);
        return 0;
    }
    return sh;
}

static GLuint gl_program(fogvol_dialect d, int per_pixel)
{
    const char *vs[FOGVOL_MAX_SHADER_STRINGS], *fs[FOGVOL_MAX_SHADER_STRINGS];
    int nv, nf;
    GLuint v, f, p;
    GLint ok = 0;
    char what[64];
    fogvol_analytic_shader_strings(d, FOGVOL_STAGE_VERTEX, per_pixel, vs, &nv);
    fogvol_analytic_shader_strings(d, FOGVOL_STAGE_FRAGMENT, per_pixel, fs, &nf);
    snprintf(what, sizeof what, "%s %s vertex shader", dialect_tag[d], per_pixel ? "per-pixel" : "per-vertex");
    v = gl_shader(GL_VERTEX_SHADER, vs, nv, what);
    snprintf(what, sizeof what, "%s %s fragment shader", dialect_tag[d], per_pixel ? "per-pixel" : "per-vertex");
    f = gl_shader(GL_FRAGMENT_SHADER, fs, nf, what);
    if (!v || !f) {
        if (v) glDeleteShader(v);
        if (f) glDeleteShader(f);
        return 0;
    }
    p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glBindAttribLocation(p, 0, "fv_position");
    if (d == FOGVOL_GLSL_130 || d == FOGVOL_GLSL_150) glBindFragDataLocation(p, 0, "fv_fragcolor");
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        print_message("# link %s: %s\n", dialect_tag[d], log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

typedef struct gl_scene {
    fogvol_analytic_volume v[8];
    int n;
    float eye[3];
    float model[16]; /* object plane z = 0, x, y in [-1, 1] -> world */
    int disjoint;    /* SEPARATE is meant for volumes that do not overlap on the rays */
} gl_scene;

#define GL_SCENES 4

static void gl_scenes(gl_scene *sc)
{
    int i;
    memset(sc, 0, GL_SCENES * sizeof *sc);
    /* scene 0: 8 interpenetrating volumes of every shape, eye outside, a tilted plane */
    sc[0].n = 8;
    for (i = 0; i < 8; ++i) {
        tvol t;
        do t = rand_volume(i < 6 ? i : i == 6 ? FOGVOL_SHAPE_DISTANCE : FOGVOL_SHAPE_ELLIPSOID);
        while (t.v.shape == FOGVOL_SHAPE_HALF_SPACE && fabs(t.v.plane[3]) < 0.5);
        sc[0].v[i] = t.v;
        sc[0].v[i].density *= 0.3f;
    }
    /* distance fog beyond 4 units with no far bound; another one between 6 and 9 units;
       fog above y = 1 (the eye is in it) */
    sc[0].v[0].min_distance = 4, sc[0].v[0].max_distance = 0;
    memset(sc[0].v[1].plane, 0, sizeof sc[0].v[1].plane);
    sc[0].v[1].plane[1] = 1, sc[0].v[1].plane[3] = -1, sc[0].v[1].density = 0.3f;
    sc[0].v[6].min_distance = 6, sc[0].v[6].max_distance = 9;
    sc[0].eye[0] = 0.7f, sc[0].eye[1] = 2.5f, sc[0].eye[2] = 9.0f;
    glu_identity(sc[0].model);
    sc[0].model[0] = 4.5f, sc[0].model[1] = 0.5f, sc[0].model[2] = -1.0f;
    sc[0].model[4] = 0.3f, sc[0].model[5] = 3.5f, sc[0].model[6] = 2.0f;
    sc[0].model[12] = 0.2f, sc[0].model[13] = -0.3f, sc[0].model[14] = -1.5f;
    /* scene 1: 5 disjoint spheres/ellipsoids/boxes/cylinders, eye inside one of them */
    sc[1].n = 5;
    sc[1].disjoint = 1;
    for (i = 0; i < 5; ++i) {
        fogvol_analytic_volume *v = &sc[1].v[i];
        v->shape = (fogvol_analytic_shape)(2 + i % 4);
        v->density = (float)rnd_range(0.2, 0.8);
        v->color[0] = (float)rnd(), v->color[1] = (float)rnd(), v->color[2] = (float)rnd();
        v->center[0] = (float)(-6 + 3 * i), v->center[2] = -1, v->radius = 1.2f;
        glu_translate_scale(v->transform, (float)(-6 + 3 * i), 0, -1, 1.2f);
        v->transform[4] = 0.3f; /* a little shear */
    }
    sc[1].eye[0] = -6.2f, sc[1].eye[1] = 0.3f, sc[1].eye[2] = -0.8f;
    glu_identity(sc[1].model);
    sc[1].model[0] = 9.0f, sc[1].model[5] = 2.5f, sc[1].model[6] = 0.5f, sc[1].model[14] = -1.2f;
    /* scene 2: axis-aligned box and cylinder, half-spaces with normals x and y, and the eye
       above a pixel centre (world (2 x_ndc, 2 y_ndc, -5), pixel 20 of 32 -> 0.5625): that row
       and column of rays are exactly parallel to box faces, the cylinder axis and the
       planes (the shaders' v == 0 branches) */
    sc[2].n = 6;
    sc[2].eye[0] = sc[2].eye[1] = 2.0f * ((2.0f * 20.0f + 1.0f) / GW - 1.0f), sc[2].eye[2] = 5;
    glu_identity(sc[2].model);
    sc[2].model[0] = 2, sc[2].model[5] = 2, sc[2].model[14] = -5;
    for (i = 0; i < 6; ++i) {
        sc[2].v[i].density = 0.1f + 0.05f * (float)i;
        sc[2].v[i].color[i % 3] = 1, sc[2].v[i].color[(i + 1) % 3] = 0.5f;
    }
    sc[2].v[0].shape = FOGVOL_SHAPE_BOX;
    glu_translate_scale(sc[2].v[0].transform, 0, 0, 0, 1.5f);
    sc[2].v[0].transform[10] = 2;
    sc[2].v[1].shape = FOGVOL_SHAPE_CYLINDER;
    glu_translate_scale(sc[2].v[1].transform, 0.3f, 0.3f, -2, 1);
    sc[2].v[2].shape = FOGVOL_SHAPE_HALF_SPACE;
    sc[2].v[2].plane[0] = 1, sc[2].v[2].plane[3] = -0.2f; /* x >= 0.2: the eye's column is in it */
    sc[2].v[3].shape = FOGVOL_SHAPE_HALF_SPACE;
    sc[2].v[3].plane[1] = 1, sc[2].v[3].plane[3] = -0.9f; /* y >= 0.9: the eye's row is not */
    sc[2].v[4].shape = FOGVOL_SHAPE_BOX;
    glu_translate_scale(sc[2].v[4].transform, sc[2].eye[0] + 1.5f, sc[2].eye[1], 0, 1); /* the eye's column: outside */
    sc[2].v[5].shape = FOGVOL_SHAPE_CYLINDER; /* the ray below the eye runs along its axis, outside */
    glu_translate_scale(sc[2].v[5].transform, sc[2].eye[0] + 1.5f, sc[2].eye[1], -1, 1);
    /* scene 3: thin fog, the eye inside fog above y = 1, distance fog, a sphere and a box */
    sc[3].n = 4;
    sc[3].eye[0] = 0.5f, sc[3].eye[1] = 2.5f, sc[3].eye[2] = 6;
    memcpy(sc[3].model, sc[0].model, sizeof sc[3].model);
    for (i = 0; i < 4; ++i) {
        sc[3].v[i].color[0] = (float)rnd(), sc[3].v[i].color[1] = (float)rnd(), sc[3].v[i].color[2] = (float)rnd();
        sc[3].v[i].density = 0.05f;
    }
    sc[3].v[0].shape = FOGVOL_SHAPE_HALF_SPACE;
    sc[3].v[0].plane[1] = 1, sc[3].v[0].plane[3] = -1;
    sc[3].v[1].shape = FOGVOL_SHAPE_DISTANCE;
    sc[3].v[1].min_distance = 7, sc[3].v[1].density = 0.03f;
    sc[3].v[2].shape = FOGVOL_SHAPE_SPHERE;
    sc[3].v[2].radius = 2, sc[3].v[2].center[1] = -1, sc[3].v[2].density = 0.15f;
    sc[3].v[3].shape = FOGVOL_SHAPE_BOX;
    rand_transform(sc[3].v[3].transform, 1);
}

/* renders the scene with one program and law/mix; compares with the CPU */
static double gl_compare(GLuint prog, const gl_scene *sc, int law, int mix, int per_pixel, GLuint vbo_points,
                         GLuint vbo_quad, int *compared, int *partial)
{
    fogvol_analytic_set set;
    float u[FOGVOL_ANALYTIC_UNIFORM_FLOATS], ident[16], *px = (float *)malloc(GW * GH * 4 * sizeof(float));
    float *wp = (float *)malloc(GW * GH * 3 * sizeof(float)), *fog = (float *)malloc(GW * GH * sizeof(float));
    float *col = (float *)malloc(GW * GH * 3 * sizeof(float));
    double worst = 0;
    int i, k, inv = 0;
    assert_non_null(px);
    assert_non_null(wp);
    assert_int_equal(fogvol_analytic_prepare(sc->v, sc->n, &set), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_analytic_pack_uniforms(&set, sc->eye, (fogvol_fog_law)law, (fogvol_fog_mix)mix, u),
                     FOGVOL_SUCCESS);
    glu_identity(ident);
    glUseProgram(prog);
    glUniform4fv(glGetUniformLocation(prog, "fv_analytic"), FOGVOL_ANALYTIC_UNIFORM_VEC4S, u);
    glUniformMatrix4fv(glGetUniformLocation(prog, "fv_mvp"), 1, GL_FALSE, ident);
    glUniformMatrix4fv(glGetUniformLocation(prog, "fv_model"), 1, GL_FALSE, sc->model);
    glClearColor(-1, -1, -1, -1);
    glClear(GL_COLOR_BUFFER_BIT);
    glBindBuffer(GL_ARRAY_BUFFER, per_pixel ? vbo_quad : vbo_points);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, (const void *)0);
    glEnableVertexAttribArray(0);
    if (per_pixel) glDrawArrays(GL_TRIANGLES, 0, 6);
    else glDrawArrays(GL_POINTS, 0, GW * GH);
    glReadPixels(0, 0, GW, GH, GL_RGBA, GL_FLOAT, px);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    /* the CPU at the same world points (pixel centres through the model matrix) */
    for (i = 0; i < GW * GH; ++i) {
        float x = (2.0f * (float)(i % GW) + 1.0f) / GW - 1.0f, y = (2.0f * (float)(i / GW) + 1.0f) / GH - 1.0f;
        for (k = 0; k < 3; ++k) wp[3 * i + k] = sc->model[k] * x + sc->model[4 + k] * y + sc->model[12 + k];
    }
    fogvol_analytic_batch(&set, sc->eye, wp, GW * GH, 0, (fogvol_fog_law)law, (fogvol_fog_mix)mix, fog, 0, col, 0,
                          NULL, &inv);
    assert_int_equal(inv, 0);
    *compared = 0;
    for (i = 0; i < GW * GH; ++i) *partial += fog[i] > 0.02f && fog[i] < 0.98f;
    for (i = 0; i < GW * GH; ++i) {
        double df = fabs(px[4 * i + 3] - fog[i]), dc = 0, cover = 1 - fog[i];
        int near_edge = 0, v;
        /* the seed's colour law jumps where a chord shrinks to 0: skip pixels near silhouettes */
        if (law == FOGVOL_FOG_LINEAR_SEED)
            for (v = 0; v < sc->n; ++v) {
                float t1, t2;
                double len = sqrt(((double)wp[3 * i] - sc->eye[0]) * ((double)wp[3 * i] - sc->eye[0]) +
                                  ((double)wp[3 * i + 1] - sc->eye[1]) * ((double)wp[3 * i + 1] - sc->eye[1]) +
                                  ((double)wp[3 * i + 2] - sc->eye[2]) * ((double)wp[3 * i + 2] - sc->eye[2]));
                fogvol_analytic_segment(&sc->v[v], sc->eye, &wp[3 * i], &t1, &t2);
                if ((t2 - t1) * len * sc->v[v].density > 0 && (t2 - t1) * len * sc->v[v].density < 0.03) near_edge = 1;
            }
        for (k = 0; k < 3; ++k) {
            /* colour where the fog is visible; colour * (1 - fog) where it is not */
            double d = fabs(px[4 * i + k] - col[3 * i + k]);
            if (cover < 0.01) d *= cover;
            dc = fmax(dc, d);
        }
        if (near_edge) dc = 0;
        else ++*compared;
        worst = fmax(worst, fmax(df, dc));
    }
    free(px);
    free(wp);
    free(fog);
    free(col);
    return worst;
}

static void gl_run_context(int core, const fogvol_dialect *dialects, int nd, int *programs_run)
{
    glu_ctx g;
    GLuint fbo, tex, vao = 0, vbo[2];
    float *pts = (float *)malloc(GW * GH * 3 * sizeof(float));
    const float quad[18] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0};
    gl_scene sc[GL_SCENES];
    int i, di, pp, law, mix, s;
    assert_true(glu_create(&g, GW, GH, core));
    assert_non_null(pts);
    for (i = 0; i < GW * GH; ++i) {
        pts[3 * i] = (2.0f * (float)(i % GW) + 1.0f) / GW - 1.0f;
        pts[3 * i + 1] = (2.0f * (float)(i / GW) + 1.0f) / GH - 1.0f;
        pts[3 * i + 2] = 0;
    }
    glGenFramebuffers(1, &fbo);
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, GW, GH, 0, GL_RGBA, GL_FLOAT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glViewport(0, 0, GW, GH);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(2, vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo[0]);
    glBufferData(GL_ARRAY_BUFFER, GW * GH * 3 * sizeof(float), pts, GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, vbo[1]);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
    gl_scenes(sc);
    for (di = 0; di < nd; ++di)
        for (pp = 0; pp < 2; ++pp) {
            GLuint prog = gl_program(dialects[di], pp);
            double worst = 0;
            int compared = 0, total = 0, partial = 0;
            if (!prog) {
                print_message("# %s context: GLSL %s %s did not compile or link\n", core ? "core" : "compat",
                              dialect_tag[dialects[di]], pp ? "per-pixel" : "per-vertex");
                fail();
            }
            for (s = 0; s < GL_SCENES; ++s)
                for (law = 0; law < 3; ++law)
                    for (mix = 0; mix < 2; ++mix) {
                        double w;
                        if (mix == FOGVOL_MIX_SEPARATE && !sc[s].disjoint) continue;
                        w = gl_compare(prog, &sc[s], law, mix, pp, vbo[0], vbo[1], &compared, &partial);
                        total += compared;
                        if (w > 1.0 / 255) print_message("# scene %d law %d mix %d: %.2e\n", s, law, mix, w);
                        worst = fmax(worst, w);
                    }
            print_message("# %s context, GLSL %-5s %-10s: %6d pixel values compared (%d%% partly fogged), max |GPU - CPU| "
                          "%.2e (1/255 = 3.9e-3)\n",
                          core ? "core  " : "compat", dialect_tag[dialects[di]], pp ? "per-pixel" : "per-vertex",
                          total, 100 * partial / total, worst);
            assert_true(worst <= 1.0 / 255);
            assert_true(partial > total / 4);
            glDeleteProgram(prog);
            ++*programs_run;
        }
    glDeleteBuffers(2, vbo);
    glDeleteVertexArrays(1, &vao);
    glDeleteTextures(1, &tex);
    glDeleteFramebuffers(1, &fbo);
    free(pts);
    glu_destroy(&g);
}

static void test_gl_matches_cpu(void **state)
{
    static const fogvol_dialect core[4] = {FOGVOL_GLSL_330, FOGVOL_GLSL_150, FOGVOL_GLSL_300ES, FOGVOL_GLSL_100};
    static const fogvol_dialect compat[3] = {FOGVOL_GLSL_120, FOGVOL_GLSL_110, FOGVOL_GLSL_130};
    int n = 0;
    (void)state;
    gl_run_context(1, core, 4, &n);
    gl_run_context(0, compat, 3, &n);
    assert_int_equal(n, 14);
}

/* wall time per test, printed after it */
static double t_start;
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
static int timer_start(void **state)
{
    (void)state;
    t_start = now();
    return 0;
}
static int timer_stop(void **state)
{
    (void)state;
    print_message("# %.2f s\n", now() - t_start);
    return 0;
}
#define TIMED(f) cmocka_unit_test_setup_teardown(f, timer_start, timer_stop)

int main(void)
{
    const struct CMUnitTest tests[] = {
        TIMED(test_segments_random),
        TIMED(test_segments_grazing),
        TIMED(test_fog_integration),
        TIMED(test_separate_overlapping),
        TIMED(test_seed_colour),
        TIMED(test_batch_matches_eval),
        TIMED(test_order_coherence),
        TIMED(test_kernel_edges),
        TIMED(test_block_culling),
        TIMED(test_kernel_strides),
        TIMED(test_degenerate),
        TIMED(test_fold),
        TIMED(test_pack_uniforms),
        TIMED(test_shaders_glslang),
        TIMED(test_gl_matches_cpu),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
