/* test_limits.c - fogvol at the limits of its input (issue 31, sections 4-6): no undefined
 * behaviour at extreme input, the same results from the large-count fast paths, everything freed
 * with the context, and refusals that say why. The renderer runs on the recording null backend
 * wrapped by a recorder (every pass, draw and uploaded index array kept), the GL tests under
 * OSMesa. Every expectation comes from a reference written here:
 *   L1 far volumes and the GEOMETRY composite: boxes 1e9 .. 3e38 pixels off screen (float -> int
 *      casts of the old rectangle, UBSan's float-cast-overflow), the composite's scissor against
 *      the rectangle projected here; the one-pass colour group (COLORS) likewise.
 *   L2 viewport origins near INT_MAX / INT_MIN (signed overflow in the post effects' check):
 *      refused with a logged INVALID_ARGUMENT; the bounds -32768 and 32767 taken.
 *   L3 weld against an O(n^2) reference of its definition (the lowest-numbered kept vertex within
 *      the distance met earlier in the sweep along the axis of largest extent): per-face
 *      subdivided cubes, lattices with many vertices on one sweep coordinate, points exactly the
 *      distance apart, non-finite vertices, 16-bit indices, interleaved layouts; the uploaded
 *      indices are the reference's representatives of the given ones.
 *   L4 colour-ramp groups at large counts: 120 ramps over 360 volumes (negatives, groups of
 *      negatives only), PS20: the passes in order of first appearance, each drawing its group's
 *      volumes in the frame's order (test_backend's test_passes_of_a_frame_* for many groups).
 *   L5 lifetime: fogvol_destroy_context with meshes, ramps and volume textures alive (and a frame
 *      open) frees every allocation and backend object (null backend) and every GL object
 *      (OSMesa, names counted through the loader), and logs what was left.
 *   L6 convexity on the welded, used vertices: raylib's GenMeshSphere (par_shapes' parametric
 *      sphere, unindexed, rebuilt here: 16 rings x 32 slices = 3,072 vertices welded to 482, and
 *      16 x 16) is convex and a light; a box plus one vertex no triangle uses is convex.
 *   L7 meshes without an index array: validation, weld, convexity, upload (the indices 0 .. n-1,
 *      welded), rendered by the GL backend (centre thickness against the analytic chord).
 *   L8 every refusal logged: INVALID_STATE of calls out of order, NULL descs, unknown enums
 *      (volume texture filter and wrap, GLSL dialects of the GL desc and of a backend table).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#include <limits.h>
#include <math.h>

/* ---- logger capture ---- */
typedef struct logcap {
    int errors, warnings;
    char last_error[1024], last_warning[1024];
} logcap;

static void cap_log(void *u, fogvol_log_level l, const char *m)
{
    logcap *c = (logcap *)u;
    if (l == FOGVOL_LOG_ERROR) {
        c->errors++;
        snprintf(c->last_error, sizeof c->last_error, "%s", m);
    } else if (l == FOGVOL_LOG_WARNING) {
        c->warnings++;
        snprintf(c->last_warning, sizeof c->last_warning, "%s", m);
    }
}

/* ---- counting allocator ---- */
typedef struct counting {
    long live;
} counting;

static void *cnt_alloc(size_t size, void *u)
{
    void *p = malloc(size);
    if (p) ((counting *)u)->live++;
    return p;
}

static void cnt_free(void *p, void *u)
{
    ((counting *)u)->live--;
    free(p);
}

/* ---- recorder: the null backend with every pass, draw and uploaded index array kept ---- */
typedef struct rec_pass {
    fogvol_handle target;
    fogvol_cull cull;
    int clear, fullscreen, scissor[4];
    int ndraw, capdraw;
    fogvol_handle *draws;
} rec_pass;

typedef struct rec_mesh {
    fogvol_handle handle;
    uint32_t *idx;
    int count;
} rec_mesh;

typedef struct recorder {
    fogvol_null_backend nb;
    fogvol_backend inner;
    rec_pass *passes;
    int npass, cappass;
    rec_mesh meshes[64];
    int nmesh;
} recorder;

static void rec_begin_pass(void *u, const fogvol_pass *p)
{
    recorder *r = (recorder *)u;
    rec_pass *rp;
    r->inner.begin_pass(&r->nb, p);
    if (r->npass == r->cappass) {
        r->cappass = r->cappass ? 2 * r->cappass : 64;
        r->passes = (rec_pass *)realloc(r->passes, sizeof *r->passes * (size_t)r->cappass);
        assert_non_null(r->passes);
    }
    rp = &r->passes[r->npass++];
    memset(rp, 0, sizeof *rp);
    rp->target = p->target;
    rp->cull = p->cull;
    rp->clear = p->clear;
    memcpy(rp->scissor, p->scissor, sizeof rp->scissor);
}

static void rec_draw_mesh(void *u, fogvol_handle m, const fogvol_draw *d)
{
    recorder *r = (recorder *)u;
    rec_pass *rp = &r->passes[r->npass - 1];
    r->inner.draw_mesh(&r->nb, m, d);
    if (rp->ndraw == rp->capdraw) {
        rp->capdraw = rp->capdraw ? 2 * rp->capdraw : 16;
        rp->draws = (fogvol_handle *)realloc(rp->draws, sizeof *rp->draws * (size_t)rp->capdraw);
        assert_non_null(rp->draws);
    }
    rp->draws[rp->ndraw++] = m;
}

static void rec_draw_fullscreen(void *u)
{
    recorder *r = (recorder *)u;
    r->inner.draw_fullscreen(&r->nb);
    r->passes[r->npass - 1].fullscreen++;
}

static fogvol_result rec_create_mesh(void *u, const fogvol_mesh_data *d, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    fogvol_result res = r->inner.create_mesh(&r->nb, d, out);
    int i;
    if (res == FOGVOL_SUCCESS && r->nmesh < 64) {
        rec_mesh *m = &r->meshes[r->nmesh++];
        m->handle = *out;
        m->count = d->index_count;
        m->idx = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)d->index_count);
        assert_non_null(m->idx);
        for (i = 0; i < d->index_count; ++i)
            m->idx[i] = d->index_type == FOGVOL_INDEX_UINT16 ? d->indices16[i] : d->indices[i];
    }
    return res;
}

static void rec_clear(recorder *r)
{
    int i;
    for (i = 0; i < r->npass; ++i) free(r->passes[i].draws);
    r->npass = 0;
}

static void rec_free(recorder *r)
{
    int i;
    rec_clear(r);
    free(r->passes);
    for (i = 0; i < r->nmesh; ++i) free(r->meshes[i].idx);
    memset(r, 0, sizeof *r);
}

/* the uploaded indices of mesh handle h */
static const rec_mesh *rec_find(const recorder *r, fogvol_handle h)
{
    int i;
    for (i = 0; i < r->nmesh; ++i)
        if (r->meshes[i].handle == h) return &r->meshes[i];
    fail_msg("mesh %lu was not uploaded", (unsigned long)h);
    return NULL;
}

/* A context on the recorder (caps added to the null backend's), tier and variants as given. */
static fogvol_context *rec_context(recorder *r, unsigned caps, fogvol_tier tier, unsigned variants, logcap *lc,
                                   counting *cnt)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    memset(r, 0, sizeof *r);
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&r->nb, &r->inner);
    cd.backend = r->inner;
    cd.backend.user_data = r; /* (the null backend's state is its first member: its entries take it too) */
    cd.backend.caps |= caps;
    cd.backend.begin_pass = rec_begin_pass;
    cd.backend.draw_mesh = rec_draw_mesh;
    cd.backend.draw_fullscreen = rec_draw_fullscreen;
    cd.backend.create_mesh = rec_create_mesh;
    cd.tier = tier;
    cd.variants = variants;
    if (lc) {
        cd.logger.func = cap_log;
        cd.logger.user_data = lc;
    }
    if (cnt) {
        cd.allocator.alloc = cnt_alloc;
        cd.allocator.free = cnt_free;
        cd.allocator.user_data = cnt;
    }
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    return fv;
}

/* ---- frames ---- */
#define VW 640
#define VH 360

/* camera at (0, 0, 10) looking at the origin, 60 degrees, near 0.5, far 100, viewport (x, y, VW, VH) */
static void frame_desc(fogvol_frame_desc *fd, int x, int y, fogvol_composite composite)
{
    double eye[3] = {0, 0, 10}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    memset(fd, 0, sizeof *fd);
    glu_look_at(fd->view, eye, at, up);
    glu_perspective(fd->projection, 60.0, (double)VW / VH, 0.5, 100.0);
    fd->znear = 0.5f;
    fd->zfar = 100.0f;
    fd->viewport[0] = x;
    fd->viewport[1] = y;
    fd->viewport[2] = VW;
    fd->viewport[3] = VH;
    fd->composite = composite;
}

/* translate (tx, ty, tz) after a uniform scale s */
static void model_ts(float m[16], double tx, double ty, double tz, double s)
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = (float)s;
    m[12] = (float)tx;
    m[13] = (float)ty;
    m[14] = (float)tz;
    m[15] = 1.0f;
}

/* The window rectangle the GEOMETRY composite may cover for boxes [-1,1]^3 under the models given,
   worked out here in double: the corners through model, view and projection; a corner at clip w
   below the near plane gives the whole viewport; else the extent rounded out (floor - 1, floor + 2)
   and clamped to the viewport; nothing inside: 1x1 at the viewport's origin. */
static void expected_rect(const fogvol_frame_desc *fd, const float (*models)[16], int n, int rect[4])
{
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    const int *vp = fd->viewport;
    int i, k, c, j;
    memcpy(rect, vp, 4 * sizeof(int));
    for (i = 0; i < n; ++i)
        for (k = 0; k < 8; ++k) {
            double p[4], v[4], q[4];
            p[0] = (k & 1) ? 1 : -1;
            p[1] = (k & 2) ? 1 : -1;
            p[2] = (k & 4) ? 1 : -1;
            p[3] = 1;
            for (j = 0; j < 4; ++j)
                v[j] = models[i][j] * p[0] + models[i][4 + j] * p[1] + models[i][8 + j] * p[2] + models[i][12 + j] * p[3];
            for (j = 0; j < 4; ++j)
                q[j] = fd->view[j] * v[0] + fd->view[4 + j] * v[1] + fd->view[8 + j] * v[2] + fd->view[12 + j] * v[3];
            for (j = 0; j < 4; ++j)
                v[j] = fd->projection[j] * q[0] + fd->projection[4 + j] * q[1] + fd->projection[8 + j] * q[2] +
                       fd->projection[12 + j] * q[3];
            if (!(v[3] >= fd->znear * (1.0 - 1e-6))) return;
            for (c = 0; c < 2; ++c) {
                double win = vp[c] + (v[c] / v[3] * 0.5 + 0.5) * vp[c + 2];
                if (win < lo[c]) lo[c] = win;
                if (win > hi[c]) hi[c] = win;
            }
        }
    for (c = 0; c < 2; ++c) {
        double a = floor(lo[c]) - 1.0, b = floor(hi[c]) + 2.0;
        if (a < vp[c]) a = vp[c];
        if (a > vp[c] + vp[c + 2]) a = vp[c] + vp[c + 2];
        if (b > vp[c] + vp[c + 2]) b = vp[c] + vp[c + 2];
        if (b < vp[c]) b = vp[c];
        rect[c] = (int)a;
        rect[c + 2] = b > a ? (int)(b - a) : 0;
    }
    if (rect[2] <= 0 || rect[3] <= 0) {
        rect[0] = vp[0];
        rect[1] = vp[1];
        rect[2] = rect[3] = 1;
    }
}

static fogvol_mesh *box_mesh(fogvol_context *fv)
{
    shp_mesh b = shp_box(1.0f, 1.0f, 1.0f);
    fogvol_mesh_desc md;
    fogvol_mesh *m = NULL;
    memset(&md, 0, sizeof md);
    md.positions = b.pos;
    md.vertex_count = b.vcount;
    md.indices = b.idx;
    md.index_count = b.icount;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
    shp_free(&b);
    return m;
}

static fogvol_ramp *plain_ramp(fogvol_context *fv, float density)
{
    fogvol_ramp_desc rd;
    fogvol_ramp *r = NULL;
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.7f;
    rd.density = density;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &r), FOGVOL_SUCCESS);
    return r;
}

/* the composite passes (window target, one full-screen draw) of the last frame, in order */
static int composites(const recorder *r, const rec_pass **out, int cap)
{
    int i, n = 0;
    for (i = 0; i < r->npass; ++i)
        if (r->passes[i].target == 0 && r->passes[i].fullscreen == 1 && n < cap) out[n++] = &r->passes[i];
    return n;
}

/* ==== L1 far volumes and the GEOMETRY composite ==== */
static void test_far_volumes_geometry(void **state)
{
    /* each case: the translations of up to 3 unit boxes of one ramp (a scale of 1e30 on the last) */
    static const struct {
        double t[3][3];
        int n, scale_last;
        const char *what;
    } cases[] = {{{{1e9, 0, 0}}, 1, 0, "1e9 to the right"},
                 {{{-1e9, 0, 0}}, 1, 0, "1e9 to the left"},
                 {{{0, 3e38, 0}}, 1, 0, "3e38 above"},
                 {{{0, 0, 0}, {1e30, 0, 0}}, 2, 0, "one at the centre, one 1e30 to the right"},
                 {{{0, 0, 0}, {0, -1e20, -5}}, 2, 0, "one at the centre, one 1e20 below"},
                 {{{2, 1, 0}, {0, 0, -1e6}, {0, 0, 0}}, 3, 1, "a box scaled by 1e30 reaching behind the eye"}};
    unsigned variants;
    int ci, mode;
    (void)state;
    for (mode = 0; mode < 2; ++mode) /* 0: PS20 ramp groups, 1: FLOAT + COLORS (the one-pass colour group) */
        for (ci = 0; ci < (int)(sizeof cases / sizeof cases[0]); ++ci) {
            recorder r;
            logcap lc;
            fogvol_context *fv;
            fogvol_mesh *mesh;
            fogvol_ramp *ramp;
            fogvol_frame_desc fd;
            fogvol_frame_stats st;
            const rec_pass *cp[4];
            float models[3][16];
            int i, want[4];
            memset(&lc, 0, sizeof lc);
            variants = mode ? FOGVOL_VARIANT_COLORS : 0u;
            fv = rec_context(&r, mode ? FOGVOL_CAP_FLOAT_BLEND : 0u, mode ? FOGVOL_TIER_FLOAT : FOGVOL_TIER_PS20,
                             variants, &lc, NULL);
            mesh = box_mesh(fv);
            ramp = plain_ramp(fv, 0.5f);
            frame_desc(&fd, 10, 20, FOGVOL_COMPOSITE_GEOMETRY);
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
            for (i = 0; i < cases[ci].n; ++i) {
                fogvol_volume_desc vd;
                memset(&vd, 0, sizeof vd);
                model_ts(models[i], cases[ci].t[i][0], cases[ci].t[i][1], cases[ci].t[i][2],
                         cases[ci].scale_last && i == cases[ci].n - 1 ? 1e30 : 1.0);
                memcpy(vd.model, models[i], sizeof vd.model);
                vd.mesh = mesh;
                vd.ramp = ramp;
                assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
            }
            rec_clear(&r);
            assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
            assert_int_equal(composites(&r, cp, 4), mode ? 1 : 1);
            expected_rect(&fd, (const float(*)[16])models, cases[ci].n, want);
            print_message("  %s, %s: scissor (%d, %d) %dx%d\n", mode ? "FLOAT + COLORS" : "PS20", cases[ci].what,
                          cp[0]->scissor[0], cp[0]->scissor[1], cp[0]->scissor[2], cp[0]->scissor[3]);
            assert_memory_equal(cp[0]->scissor, want, sizeof want);
            fogvol_destroy_ramp(fv, ramp);
            fogvol_destroy_mesh(fv, mesh);
            fogvol_destroy_context(fv);
            rec_free(&r);
        }
}

/* ==== L2 viewport origins at the ends of int ==== */
static void test_viewport_origins(void **state)
{
    static const struct {
        int x, y, ok;
    } cases[] = {{INT_MAX - 10, 0, 0}, {0, INT_MAX - 100, 0}, {INT_MIN + 5, 0, 0}, {0, INT_MIN, 0},
                 {-32769, 0, 0},       {32768, 0, 0},         {-32768, 0, 1},      {32767, 32767, 1}, {-5, 7, 1}};
    recorder r;
    logcap lc;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp;
    fogvol_dof_desc dd;
    fogvol_frame_desc fd;
    int i;
    (void)state;
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    mesh = box_mesh(fv);
    ramp = plain_ramp(fv, 0.5f);
    for (i = 0; i < (int)(sizeof cases / sizeof cases[0]); ++i) {
        fogvol_volume_desc vd;
        int errors = lc.errors;
        frame_desc(&fd, cases[i].x, cases[i].y, FOGVOL_COMPOSITE_GEOMETRY);
        if (!cases[i].ok) {
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
            assert_int_equal(lc.errors, errors + 1);
            assert_non_null(strstr(lc.last_error, "origin"));
            continue;
        }
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        memset(&vd, 0, sizeof vd);
        model_ts(vd.model, 0, 0, 0, 1);
        vd.mesh = mesh;
        vd.ramp = ramp;
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    }
    /* the post effects: an origin near INT_MAX with a texture size (origin + width overflowed) */
    frame_desc(&fd, INT_MAX - 50, 0, FOGVOL_COMPOSITE_FULLSCREEN);
    fd.engine_depth_texture = 77;
    memset(&dd, 0, sizeof dd);
    dd.frame = &fd;
    dd.color_texture = 78;
    dd.texture_size[0] = dd.texture_size[1] = 100;
    dd.focus_distance = 5.0f;
    dd.focus_range = 2.0f;
    lc.errors = 0;
    assert_int_equal(fogvol_post_dof(fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(lc.errors, 1);
    assert_non_null(strstr(lc.last_error, "origin"));
    fd.viewport[0] = 0;
    fd.viewport[1] = INT_MAX - 50;
    assert_int_equal(fogvol_post_dof(fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.viewport[1] = 0;
    fd.viewport[2] = fd.viewport[3] = 100;
    assert_int_equal(fogvol_post_dof(fv, &dd), FOGVOL_SUCCESS);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    rec_free(&r);
}

/* ==== L3 the weld against its definition ==== */
typedef struct wkey {
    float key;
    int i;
} wkey;

static int wkey_cmp(const void *a, const void *b)
{
    const wkey *x = (const wkey *)a, *y = (const wkey *)b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->i - y->i;
}

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

/* fogvol_mesh_desc.weld_distance as documented, in O(n^2): the finite vertices in order of their
   coordinate on the axis of largest extent (float extents, the first axis on ties), then of their
   number; each merges into the lowest-numbered vertex kept before it in that order that lies within
   dist on every axis, else it is kept. rep[i]: vertex i's representative. Returns the merged count. */
static int ref_weld(const unsigned char *base, int stride, int nv, float dist, int *rep)
{
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    wkey *order = (wkey *)malloc(sizeof *order * (size_t)nv);
    char *kept = (char *)calloc((size_t)nv, 1);
    int i, a, b, k, axis = 0, any = 0, n = 0, merged = 0;
    assert_non_null(order);
    assert_non_null(kept);
    for (i = 0; i < nv; ++i) {
        const float *v = (const float *)(const void *)(base + (size_t)i * stride);
        rep[i] = i;
        if (!finite3(v)) continue;
        for (k = 0; k < 3; ++k) {
            if (!any || v[k] < lo[k]) lo[k] = v[k];
            if (!any || v[k] > hi[k]) hi[k] = v[k];
        }
        any = 1;
    }
    for (k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    for (i = 0; i < nv; ++i) {
        const float *v = (const float *)(const void *)(base + (size_t)i * stride);
        if (!finite3(v)) continue;
        order[n].key = v[axis];
        order[n++].i = i;
    }
    qsort(order, (size_t)n, sizeof *order, wkey_cmp);
    for (a = 0; a < n; ++a) {
        const float *v = (const float *)(const void *)(base + (size_t)order[a].i * stride);
        int best = -1;
        for (b = 0; b < a; ++b) {
            const float *w = (const float *)(const void *)(base + (size_t)order[b].i * stride);
            if (!kept[order[b].i] || (best >= 0 && order[b].i > best)) continue;
            if (fabs((double)w[0] - v[0]) <= dist && fabs((double)w[1] - v[1]) <= dist &&
                fabs((double)w[2] - v[2]) <= dist)
                best = order[b].i;
        }
        if (best < 0) kept[order[a].i] = 1;
        else {
            rep[order[a].i] = best;
            merged++;
        }
    }
    free(order);
    free(kept);
    return merged;
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

/* nv points of set `kind` into pos (3 floats each), shuffled */
static void weld_points(int kind, float *pos, int nv, float d, uint32_t seed)
{
    int i, k;
    for (i = 0; i < nv; ++i) {
        float *p = pos + 3 * i;
        switch (kind) {
        case 0: /* a lattice of spacing d: neighbours exactly d apart, rows sharing the sweep coordinate */
            p[0] = d * (float)(i % 7);
            p[1] = d * (float)(i / 7 % 9);
            p[2] = d * (float)(i / 63);
            break;
        case 1: /* few x values (one sweep coordinate holds many), duplicates and near duplicates */
            p[0] = (float)(lcg(&seed) % 3) * 0.5f;
            p[1] = (float)(lcg(&seed) % 40) * 0.37f * d;
            p[2] = (float)(lcg(&seed) % 40) * 0.61f * d;
            if (lcg(&seed) % 4 == 0) p[1] += (lcg(&seed) % 2 ? 1.0f : -1.0f) * d;
            break;
        case 2: /* far from the origin, as large as floats go */
            for (k = 0; k < 3; ++k) p[k] = 1e30f + (float)(lcg(&seed) % 5) * 1e24f;
            if (i % 5 == 0) p[0] = -3.0e38f;
            break;
        default: /* signed zeros, tiny values, non-finite ones */
            for (k = 0; k < 3; ++k) p[k] = (lcg(&seed) % 2 ? -0.0f : 0.0f) + (float)(lcg(&seed) % 3) * 1e-40f;
            if (i % 11 == 3) p[1] = NAN;
            if (i % 13 == 5) p[2] = -INFINITY;
            break;
        }
    }
    for (i = nv - 1; i > 0; --i) { /* the vertex numbers unrelated to the sweep */
        int j = (int)(lcg(&seed) % (uint32_t)(i + 1));
        float t[3];
        memcpy(t, pos + 3 * i, sizeof t);
        memcpy(pos + 3 * i, pos + 3 * j, sizeof t);
        memcpy(pos + 3 * j, t, sizeof t);
    }
}

/* weld pos (nv points, 3 floats each) through fogvol: in a stride-20, offset-8 vertex buffer with
   16-bit or 32-bit triangles (i, i+1, i+2) over every vertex; the uploaded indices (create_mesh on
   the recorder; validate_mesh alone where a vertex is not finite) against the reference */
static void weld_check(const float *pos, int nv, float dist, int idx16, const char *what)
{
    unsigned char *buf = (unsigned char *)calloc((size_t)nv, 20);
    uint32_t *idx = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)nv * 3);
    uint16_t *idx16v = (uint16_t *)malloc(sizeof(uint16_t) * (size_t)nv * 3);
    int *rep = (int *)malloc(sizeof(int) * (size_t)nv), i, merged, finite = 1;
    fogvol_mesh_desc md;
    fogvol_mesh_report mr;
    assert_true(buf && idx && idx16v && rep);
    for (i = 0; i < nv; ++i) {
        memcpy(buf + 20 * i + 8, pos + 3 * i, 12);
        finite &= finite3(pos + 3 * i);
    }
    for (i = 0; i < 3 * nv; ++i) idx[i] = idx16v[i] = (uint16_t)((i / 3 + i % 3) % nv);
    merged = ref_weld(buf + 8, 20, nv, dist, rep);
    memset(&md, 0, sizeof md);
    md.positions = (const float *)(const void *)buf;
    md.vertex_count = nv;
    md.stride = 20;
    md.offset = 8;
    md.index_count = 3 * nv;
    if (idx16) {
        md.index_type = FOGVOL_INDEX_UINT16;
        md.indices16 = idx16v;
    } else {
        md.indices = idx;
    }
    md.weld_distance = dist;
    md.allow_open = 1;
    assert_int_equal(fogvol_validate_mesh(&md, NULL, &mr) == FOGVOL_ERROR_INVALID_ARGUMENT, 0);
    print_message("  %s: %d vertices, %d merged (reference %d)\n", what, nv, mr.welded_vertices, merged);
    assert_int_equal(mr.welded_vertices, merged);
    assert_int_equal(mr.vertices, nv - merged);
    if (finite) {
        recorder r;
        fogvol_context *fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, NULL, NULL);
        fogvol_mesh *m = NULL;
        const rec_mesh *up;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
        up = rec_find(&r, r.meshes[r.nmesh - 1].handle);
        assert_int_equal(up->count, 3 * nv);
        for (i = 0; i < 3 * nv; ++i)
            if (up->idx[i] != (uint32_t)rep[idx[i]])
                fail_msg("%s: index %d: vertex %u uploaded as %u, the reference welds it to %d", what, i, idx[i],
                         up->idx[i], rep[idx[i]]);
        fogvol_destroy_mesh(fv, m);
        fogvol_destroy_context(fv);
        rec_free(&r);
    }
    free(buf);
    free(idx);
    free(idx16v);
    free(rep);
}

static void test_weld_reference(void **state)
{
    static const struct {
        int kind, nv;
        float dist;
        const char *what;
    } sets[] = {{0, 630, 0.25f, "lattice of spacing d (neighbours exactly d apart)"},
                {0, 630, 0.2499999f, "the same lattice, d a hair below the spacing"},
                {1, 2000, 1e-3f, "three sweep coordinates, duplicates and near duplicates"},
                {1, 1500, 0.3f, "the same, d larger than the structure"},
                {2, 800, 1e-5f, "coordinates near 1e30 and -3e38"},
                {2, 800, 1e37f, "the same, d = 1e37"},
                {3, 600, 1e-39f, "signed zeros, 1e-40 steps, NaN and -inf"}};
    shp_mesh cube = shp_cube_faces(1.0f, 9);
    int s;
    (void)state;
    weld_check(cube.pos, cube.vcount, 1e-5f, 0, "per-face cube 6 x 10^2");
    weld_check(cube.pos, cube.vcount, 0.3f, 1, "the same cube at 0.3 (16-bit indices)");
    for (s = 0; s < (int)(sizeof sets / sizeof sets[0]); ++s) {
        float *pos = (float *)malloc(sizeof(float) * 3 * (size_t)sets[s].nv);
        assert_non_null(pos);
        weld_points(sets[s].kind, pos, sets[s].nv, sets[s].dist, 12345u + (uint32_t)s);
        weld_check(pos, sets[s].nv, sets[s].dist, s % 2, sets[s].what);
        free(pos);
    }
    shp_free(&cube);
}

/* ==== L4 colour-ramp groups at large counts ==== */
#define NRAMP 120
#define NVOL 360
static void test_ramp_groups(void **state)
{
    recorder r;
    logcap lc;
    fogvol_context *fv;
    fogvol_mesh *mesh[NVOL / 6];
    fogvol_ramp *ramp[NRAMP];
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    int vr[NVOL], neg[NVOL], first[NRAMP], i, g, p = 0, groups = 0, k;
    (void)state;
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    for (i = 0; i < NVOL / 6; ++i) mesh[i] = box_mesh(fv);
    for (i = 0; i < NRAMP; ++i) ramp[i] = plain_ramp(fv, 0.1f + 0.01f * (float)i);
    frame_desc(&fd, 0, 0, FOGVOL_COMPOSITE_FULLSCREEN);
    /* volume i: ramp (7 i + i / 40) mod 120, negative every 5th; ramps 0 mod 17 hold negatives only */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    for (i = 0; i < NVOL; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vr[i] = (7 * i + i / 40) % NRAMP;
        neg[i] = i % 5 == 0 || vr[i] % 17 == 0;
        model_ts(vd.model, (double)(i % 19) - 9.0, (double)(i % 7) - 3.0, -(double)(i % 5), 0.2);
        vd.mesh = mesh[i % (NVOL / 6)];
        vd.ramp = ramp[vr[i]];
        vd.negative = neg[i];
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    }
    rec_clear(&r);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    for (g = 0; g < NRAMP; ++g) first[g] = -1;
    for (i = 0; i < NVOL; ++i)
        if (first[vr[i]] < 0) first[vr[i]] = i;
    while (p < r.npass && r.passes[p].ndraw == 0 && !r.passes[p].fullscreen) ++p; /* O (no occluders) */
    /* groups in order of first appearance; each: B positives (cull FRONT, clear), B negatives (cull BACK),
       F positives (cull BACK, clear), F negatives (cull FRONT), composite */
    for (i = 0; i < NVOL; ++i) {
        int rg = vr[i], pos = 0, nneg = 0, step;
        if (first[rg] != i) continue;
        for (k = 0; k < NVOL; ++k)
            if (vr[k] == rg) {
                pos += !neg[k];
                nneg += neg[k];
            }
        if (!pos) continue; /* negatives only: nothing to subtract from, not drawn */
        groups++;
        for (step = 0; step < 5; ++step) {
            int want_neg = step == 1 || step == 3, n = 0;
            const rec_pass *rp;
            if (want_neg && !nneg) continue;
            assert_true(p < r.npass);
            rp = &r.passes[p++];
            if (step == 4) {
                assert_int_equal(rp->target, 0);
                assert_int_equal(rp->fullscreen, 1);
                continue;
            }
            assert_int_equal(rp->cull, (step == 0 || step == 3) ? FOGVOL_CULL_FRONT : FOGVOL_CULL_BACK);
            assert_int_equal(rp->clear, step == 0 || step == 2);
            for (k = 0; k < NVOL; ++k)
                if (vr[k] == rg && neg[k] == want_neg) {
                    assert_true(n < rp->ndraw);
                    assert_int_equal(rp->draws[n], r.meshes[k % (NVOL / 6)].handle); /* (mesh j: the j-th upload) */
                    n++;
                }
            assert_int_equal(rp->ndraw, n);
        }
    }
    assert_int_equal(p, r.npass);
    assert_int_equal(st.groups, groups);
    print_message("  %d volumes, %d ramps: %d groups drawn, %d passes, in order\n", NVOL, NRAMP, groups, st.passes);
    for (i = 0; i < NRAMP; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    for (i = 0; i < NVOL / 6; ++i) fogvol_destroy_mesh(fv, mesh[i]);
    fogvol_destroy_context(fv);
    rec_free(&r);
}

/* ==== L5 lifetime ==== */
static fogvol_mesh *welded_mesh(fogvol_context *fv, int idx16)
{
    shp_mesh c = shp_cube_faces(1.0f, 3);
    uint16_t *i16 = (uint16_t *)malloc(sizeof(uint16_t) * (size_t)c.icount);
    fogvol_mesh_desc md;
    fogvol_mesh *m = NULL;
    int i;
    assert_non_null(i16);
    for (i = 0; i < c.icount; ++i) i16[i] = (uint16_t)c.idx[i];
    memset(&md, 0, sizeof md);
    md.positions = c.pos;
    md.vertex_count = c.vcount;
    if (idx16) {
        md.index_type = FOGVOL_INDEX_UINT16;
        md.indices16 = i16;
    } else {
        md.indices = c.idx;
    }
    md.index_count = c.icount;
    md.weld_distance = 1e-5f;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
    free(i16);
    shp_free(&c);
    return m;
}

static fogvol_volume_texture *vtex(fogvol_context *fv)
{
    static const unsigned char px[16] = {255, 0, 0, 255, 128, 0, 0, 255, 64, 0, 0, 255, 0, 0, 0, 255};
    fogvol_texture_desc td;
    fogvol_volume_texture *t = NULL;
    memset(&td, 0, sizeof td);
    td.width = td.height = 2;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &t), FOGVOL_SUCCESS);
    return t;
}

/* what the caller forgets: 3 meshes, 2 ramps, 2 volume textures, and a frame left open with volumes */
static void forget_things(fogvol_context *fv)
{
    fogvol_mesh *m[3];
    fogvol_ramp *r[2];
    fogvol_volume_texture *t[2];
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    m[0] = box_mesh(fv);
    m[1] = welded_mesh(fv, 0);
    m[2] = welded_mesh(fv, 1);
    r[0] = plain_ramp(fv, 0.3f);
    r[1] = plain_ramp(fv, 0.6f);
    t[0] = vtex(fv);
    t[1] = vtex(fv);
    frame_desc(&fd, 0, 0, FOGVOL_COMPOSITE_GEOMETRY);
    fd.viewport[2] = fd.viewport[3] = 64;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS); /* targets made */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    model_ts(vd.model, 0, 0, 0, 1);
    vd.mesh = m[1];
    vd.ramp = r[1];
    vd.density = t[0];
    vd.color = t[1];
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    (void)m[2];
    (void)r[0];
}

static void test_lifetime_null(void **state)
{
    recorder r;
    logcap lc;
    counting cnt;
    fogvol_context *fv;
    (void)state;
    memset(&lc, 0, sizeof lc);
    memset(&cnt, 0, sizeof cnt);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, &cnt);
    forget_things(fv);
    lc.warnings = 0;
    fogvol_destroy_context(fv);
    print_message("  null backend: %ld allocations and %d backend objects left; warning: %s\n", cnt.live,
                  r.nb.creates - r.nb.destroys, lc.last_warning);
    assert_int_equal(cnt.live, 0);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    assert_int_equal(lc.warnings, 1);
    assert_non_null(strstr(lc.last_warning, "3 meshes, 2 ramps and 2 volume textures"));
    rec_free(&r);
}

/* GL objects created and deleted through the loader fogvol is given */
#define GLK 7
static struct {
    long live[GLK];
    void (*gen[5])(GLsizei, GLuint *);
    void (*del[5])(GLsizei, const GLuint *);
    GLuint (*create_program)(void);
    void (*delete_program)(GLuint);
    GLuint (*create_shader)(GLenum);
    void (*delete_shader)(GLuint);
} g_gl;

static void gl_count(int kind, GLsizei n, const GLuint *ids, int sign)
{
    GLsizei i;
    for (i = 0; i < n; ++i) g_gl.live[kind] += ids[i] ? sign : 0;
}

#define GL_PAIR(k, Name)                                                                                            \
    static void w_Gen##Name(GLsizei n, GLuint *ids)                                                                 \
    {                                                                                                                \
        g_gl.gen[k](n, ids);                                                                                         \
        gl_count(k, n, ids, 1);                                                                                      \
    }                                                                                                                \
    static void w_Delete##Name(GLsizei n, const GLuint *ids)                                                        \
    {                                                                                                                \
        gl_count(k, n, ids, -1);                                                                                     \
        g_gl.del[k](n, ids);                                                                                         \
    }
GL_PAIR(0, Textures)
GL_PAIR(1, Buffers)
GL_PAIR(2, Framebuffers)
GL_PAIR(3, Renderbuffers)
GL_PAIR(4, VertexArrays)

static GLuint w_CreateProgram(void)
{
    GLuint id = g_gl.create_program();
    g_gl.live[5] += id != 0;
    return id;
}
static void w_DeleteProgram(GLuint id)
{
    g_gl.live[5] -= id != 0;
    g_gl.delete_program(id);
}
static GLuint w_CreateShader(GLenum t)
{
    GLuint id = g_gl.create_shader(t);
    g_gl.live[6] += id != 0;
    return id;
}
static void w_DeleteShader(GLuint id)
{
    g_gl.live[6] -= id != 0;
    g_gl.delete_shader(id);
}

static fogvol_gl_proc counting_loader(const char *name, void *user)
{
    static const struct {
        const char *name;
        fogvol_gl_proc fn;
    } w[] = {{"glGenTextures", (fogvol_gl_proc)w_GenTextures},
             {"glDeleteTextures", (fogvol_gl_proc)w_DeleteTextures},
             {"glGenBuffers", (fogvol_gl_proc)w_GenBuffers},
             {"glDeleteBuffers", (fogvol_gl_proc)w_DeleteBuffers},
             {"glGenFramebuffers", (fogvol_gl_proc)w_GenFramebuffers},
             {"glDeleteFramebuffers", (fogvol_gl_proc)w_DeleteFramebuffers},
             {"glGenRenderbuffers", (fogvol_gl_proc)w_GenRenderbuffers},
             {"glDeleteRenderbuffers", (fogvol_gl_proc)w_DeleteRenderbuffers},
             {"glGenVertexArrays", (fogvol_gl_proc)w_GenVertexArrays},
             {"glDeleteVertexArrays", (fogvol_gl_proc)w_DeleteVertexArrays},
             {"glCreateProgram", (fogvol_gl_proc)w_CreateProgram},
             {"glDeleteProgram", (fogvol_gl_proc)w_DeleteProgram},
             {"glCreateShader", (fogvol_gl_proc)w_CreateShader},
             {"glDeleteShader", (fogvol_gl_proc)w_DeleteShader}};
    size_t i;
    for (i = 0; i < sizeof w / sizeof w[0]; ++i)
        if (strcmp(name, w[i].name) == 0) return w[i].fn;
    return glu_proc(name, user);
}

static void counting_init(void)
{
    static const char *const gens[5] = {"glGenTextures", "glGenBuffers", "glGenFramebuffers", "glGenRenderbuffers",
                                        "glGenVertexArrays"};
    static const char *const dels[5] = {"glDeleteTextures", "glDeleteBuffers", "glDeleteFramebuffers",
                                        "glDeleteRenderbuffers", "glDeleteVertexArrays"};
    int i;
    memset(&g_gl, 0, sizeof g_gl);
    for (i = 0; i < 5; ++i) {
        g_gl.gen[i] = (void (*)(GLsizei, GLuint *))glu_proc(gens[i], NULL);
        g_gl.del[i] = (void (*)(GLsizei, const GLuint *))glu_proc(dels[i], NULL);
    }
    g_gl.create_program = (GLuint(*)(void))glu_proc("glCreateProgram", NULL);
    g_gl.delete_program = (void (*)(GLuint))glu_proc("glDeleteProgram", NULL);
    g_gl.create_shader = (GLuint(*)(GLenum))glu_proc("glCreateShader", NULL);
    g_gl.delete_shader = (void (*)(GLuint))glu_proc("glDeleteShader", NULL);
}

static void test_lifetime_gl(void **state)
{
    static const char *const kinds[GLK] = {"textures", "buffers", "framebuffers", "renderbuffers",
                                           "vertex arrays", "programs", "shaders"};
    static const fogvol_tier tiers[2] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_PS20};
    glu_ctx g;
    int t, k;
    (void)state;
    assert_true(glu_create(&g, 64, 64, 1));
    for (t = 0; t < 2; ++t) {
        fogvol_context_desc cd;
        fogvol_context *fv = NULL;
        logcap lc;
        counting cnt;
        memset(&lc, 0, sizeof lc);
        memset(&cnt, 0, sizeof cnt);
        counting_init();
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = counting_loader;
        cd.tier = tiers[t];
        cd.logger.func = cap_log;
        cd.logger.user_data = &lc;
        cd.allocator.alloc = cnt_alloc;
        cd.allocator.free = cnt_free;
        cd.allocator.user_data = &cnt;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        forget_things(fv);
        fogvol_destroy_context(fv);
        for (k = 0; k < GLK; ++k)
            if (g_gl.live[k]) fail_msg("%s: %ld GL %s left", fogvol_tier_name(tiers[t]), g_gl.live[k], kinds[k]);
        assert_int_equal(cnt.live, 0);
        assert_non_null(strstr(lc.last_warning, "3 meshes, 2 ramps and 2 volume textures"));
        print_message("  GL backend, %s: no GL object and no allocation left\n", fogvol_tier_name(tiers[t]));
    }
    glu_destroy(&g);
}

/* ==== L6 convexity on the welded, used vertices ==== */
/* raylib's GenMeshSphere(1, rings, slices): par_shapes_create_parametric_sphere(slices, rings) with
   par_shapes' degenerate-triangle removal off (raylib sets its epsilon to 0): (slices + 1) (rings + 1)
   points at u = stack / stacks, v = slice / slices, phi = u PAR_PI, theta = v 2 PAR_PI in float
   (PAR_PI = 3.14159265359, a double), (cos theta sin phi, sin theta sin phi, cos phi); two triangles
   per cell as par_shapes_create_parametric winds them; then copied out unindexed, vertex k =
   points[triangles[k]], as GenMeshSphere does. 3 * 2 * slices * rings vertices. */
static float *raylib_sphere(int rings, int slices, int *nv)
{
    const double par_pi = 3.14159265359;
    int np = (slices + 1) * (rings + 1), nt = 2 * slices * rings, st, sl, v = 0, k, t = 0;
    float *pts = (float *)malloc(sizeof(float) * 3 * (size_t)np), *out = (float *)malloc(sizeof(float) * 9 * (size_t)nt);
    int *tri = (int *)malloc(sizeof(int) * 3 * (size_t)nt);
    assert_true(pts && out && tri);
    for (st = 0, k = 0; st < rings + 1; ++st) {
        float u = (float)st / rings;
        for (sl = 0; sl < slices + 1; ++sl, ++k) {
            float w = (float)sl / slices, phi = (float)(u * par_pi), theta = (float)(w * 2 * par_pi);
            pts[3 * k] = cosf(theta) * sinf(phi);
            pts[3 * k + 1] = sinf(theta) * sinf(phi);
            pts[3 * k + 2] = cosf(phi);
        }
    }
    for (st = 0; st < rings; ++st) {
        for (sl = 0; sl < slices; ++sl) {
            int next = sl + 1;
            tri[t++] = v + sl + slices + 1;
            tri[t++] = v + next;
            tri[t++] = v + sl;
            tri[t++] = v + sl + slices + 1;
            tri[t++] = v + next + slices + 1;
            tri[t++] = v + next;
        }
        v += slices + 1;
    }
    for (k = 0; k < 3 * nt; ++k) memcpy(out + 3 * k, pts + 3 * tri[k], 3 * sizeof(float));
    free(pts);
    free(tri);
    *nv = 3 * nt;
    return out;
}

static void test_convex_welded(void **state)
{
    static const int sizes[2][3] = {{16, 32, 482}, {16, 16, 242}}; /* rings, slices, welded vertices */
    static const float box_plus[27] = {-1, -1, -1, 1, -1, -1, -1, 1, -1, 1, 1, -1, -1, -1, 1,
                                       1,  -1, 1,  -1, 1, 1, 1,  1,  1, 3, 3, 3}; /* vertex 8: no triangle */
    recorder r;
    logcap lc;
    fogvol_context *fv;
    int s, i;
    (void)state;
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    for (s = 0; s < 2; ++s) {
        int nv;
        float *pos = raylib_sphere(sizes[s][0], sizes[s][1], &nv);
        uint32_t *idx = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)nv);
        fogvol_mesh_desc md;
        fogvol_mesh_report rep;
        fogvol_mesh *m = NULL;
        fogvol_light_desc ld;
        assert_non_null(idx);
        for (i = 0; i < nv; ++i) idx[i] = (uint32_t)i; /* the index array an adopter writes for it */
        memset(&md, 0, sizeof md);
        md.positions = pos;
        md.vertex_count = nv;
        md.indices = idx;
        md.index_count = nv;
        md.weld_distance = 1e-5f;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_SUCCESS);
        print_message("  GenMeshSphere(1, %d, %d): %d vertices welded to %d, valid %d, convex %d\n", sizes[s][0],
                      sizes[s][1], nv, rep.vertices, rep.valid, rep.convex);
        assert_int_equal(rep.vertices, sizes[s][2]);
        assert_int_equal(rep.convex, 1);
        memset(&ld, 0, sizeof ld);
        ld.mesh = m;
        model_ts(ld.model, 0, 0, 0, 1);
        ld.color[0] = 1.0f;
        {
            fogvol_frame_desc fd;
            frame_desc(&fd, 0, 0, FOGVOL_COMPOSITE_FULLSCREEN);
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
        }
        fogvol_destroy_mesh(fv, m);
        free(idx);
        free(pos);
    }
    { /* a box in a shared vertex buffer that holds one more vertex no triangle uses */
        shp_mesh b = shp_box(1.0f, 1.0f, 1.0f);
        fogvol_mesh_desc md;
        fogvol_mesh_report rep;
        fogvol_mesh *m = NULL;
        memset(&md, 0, sizeof md);
        md.positions = box_plus;
        md.vertex_count = 9;
        md.indices = b.idx;
        md.index_count = b.icount;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_SUCCESS);
        print_message("  box + an unused vertex at (3, 3, 3): convex %d\n", rep.convex);
        assert_int_equal(rep.convex, 1);
        fogvol_destroy_mesh(fv, m);
        shp_free(&b);
    }
    fogvol_destroy_context(fv);
    rec_free(&r);
}

/* ==== L6b the convexity test's tree against every (face, vertex) pair ==== */
/* fogvol_mesh_report.convex by its documented rule, tested on every pair: every vertex within
   1e-5 of the vertices' box diagonal of the inner side of every face plane (degenerate faces,
   |n| <= 1e-12 diag^2, have none). Returns the largest (n . (p - a)) / |n| over the pairs in units
   of that tolerance: convex exactly when <= 1. */
static double reference_excess(const float *pos, const unsigned *idx, int nt, int nv)
{
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300}, diag = 0, worst = -1e300;
    int t, v, k;
    for (v = 0; v < nv; ++v)
        for (k = 0; k < 3; ++k) {
            lo[k] = pos[3 * v + k] < lo[k] ? pos[3 * v + k] : lo[k];
            hi[k] = pos[3 * v + k] > hi[k] ? pos[3 * v + k] : hi[k];
        }
    for (k = 0; k < 3; ++k) diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    diag = sqrt(diag);
    for (t = 0; t < nt; ++t) {
        const float *a = pos + 3 * idx[3 * t], *b = pos + 3 * idx[3 * t + 1], *c = pos + 3 * idx[3 * t + 2];
        double e1[3], e2[3], n[3], len;
        for (k = 0; k < 3; ++k) {
            e1[k] = (double)b[k] - a[k];
            e2[k] = (double)c[k] - a[k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-12 * diag * diag)) continue;
        for (v = 0; v < nv; ++v) {
            const float *p = pos + 3 * v;
            double d = (n[0] * (p[0] - (double)a[0]) + n[1] * (p[1] - (double)a[1]) + n[2] * (p[2] - (double)a[2])) / len;
            if (d / (1e-5 * diag) > worst) worst = d / (1e-5 * diag);
        }
    }
    return worst;
}

/* The mesh with vertex `moved` (and its copies: the cube's faces repeat their edges) at
   base + s * dir: its excess by the rule. */
static double excess_moved(shp_mesh *m, const float *base, int moved, const double dir[3], double s)
{
    int v, k;
    memcpy(m->pos, base, sizeof(float) * 3 * (size_t)m->vcount);
    for (v = 0; v < m->vcount; ++v)
        if (!memcmp(base + 3 * v, base + 3 * moved, 3 * sizeof(float)))
            for (k = 0; k < 3; ++k) m->pos[3 * v + k] = (float)(base[3 * moved + k] + s * dir[k]);
    return reference_excess(m->pos, m->idx, m->icount / 3, m->vcount);
}

/* A sphere (1,106 vertices) and a cube of 12 x 12 squares a face (many vertices on each face plane,
   welded): one vertex moved out (a bump) or in (a dent) along its outward direction. The distance
   where the rule turns the mesh concave is found by bisection on the rule tested on every pair;
   each mesh of a sweep across it (0.5, 0.99, 1.01 and 2 times that distance, and far beyond) must be
   convex exactly as the rule says. The tree skips boxes more than half the tolerance inside a
   plane: the answers near the border are the ones it could get wrong. */
static void test_convex_tree(void **state)
{
    static const double at[] = {0.0, 0.5, 0.99, 1.01, 2.0, 50.0};
    recorder r;
    logcap lc;
    fogvol_context *fv;
    int shape, sign, j, seen[2] = {0, 0};
    (void)state;
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    for (shape = 0; shape < 2; ++shape) {
        shp_mesh m = shape == 0 ? shp_sphere(1.0f, 48, 24) : shp_cube_faces(1.0f, 12);
        int moved = shape == 0 ? 500 : 5 * 13 + 7, k; /* sphere: mid-latitude; cube: inside face 0 */
        float *base = (float *)malloc(sizeof(float) * 3 * (size_t)m.vcount);
        double dir[3], lo = 0.0, hi = 0.02, len = 0.0;
        assert_true(m.pos && base);
        memcpy(base, m.pos, sizeof(float) * 3 * (size_t)m.vcount);
        for (k = 0; k < 3; ++k) len += (double)base[3 * moved + k] * base[3 * moved + k];
        for (k = 0; k < 3; ++k) dir[k] = shape == 0 ? base[3 * moved + k] / sqrt(len) : (k == 0 ? 1.0 : 0.0);
        for (sign = 1; sign >= -1; sign -= 2) {
            int it;
            lo = 0.0;
            hi = 0.02;
            assert_true(excess_moved(&m, base, moved, dir, 0.0) <= 1.0);
            assert_true(excess_moved(&m, base, moved, dir, sign * hi) > 1.0);
            for (it = 0; it < 40; ++it) { /* the border: excess 1 at distance (lo + hi) / 2 */
                double mid = 0.5 * (lo + hi);
                if (excess_moved(&m, base, moved, dir, sign * mid) <= 1.0) lo = mid;
                else hi = mid;
            }
            for (j = 0; j < (int)(sizeof at / sizeof at[0]); ++j) {
                double s = sign * at[j] * lo, excess = excess_moved(&m, base, moved, dir, s);
                int want = excess <= 1.0;
                fogvol_mesh_desc md;
                fogvol_mesh_report rep;
                fogvol_mesh *fm = NULL;
                memset(&md, 0, sizeof md);
                md.positions = m.pos;
                md.vertex_count = m.vcount;
                md.indices = (const uint32_t *)m.idx;
                md.index_count = m.icount;
                md.weld_distance = shape == 1 ? 1e-6f : 0.0f;
                assert_int_equal(fogvol_create_mesh(fv, &md, &fm, &rep), FOGVOL_SUCCESS);
                if (j == 2 || j == 3 || rep.convex != want)
                    print_message("  %s, a %s of %.3g (%.2f x the border): largest excess %.4f tolerances, convex %d "
                                  "(rule: %d)\n", shape ? "cube 12x12 a face" : "sphere 48x24", sign > 0 ? "bump" : "dent",
                                  fabs(s), at[j], excess, rep.convex, want);
                assert_int_equal(rep.convex, want);
                seen[want]++;
                fogvol_destroy_mesh(fv, fm);
            }
        }
        free(base);
        shp_free(&m);
    }
    print_message("  %d meshes convex and %d not, each as the rule tested on every pair says\n", seen[1], seen[0]);
    assert_true(seen[0] >= 8 && seen[1] >= 8);
    fogvol_destroy_context(fv);
    rec_free(&r);
}

/* ==== L7 meshes without an index array ==== */
static void test_non_indexed(void **state)
{
    shp_mesh b = shp_box(1.0f, 1.0f, 1.0f);
    float flat[36 * 3];
    int rep_ref[36], i, merged;
    recorder r;
    logcap lc;
    fogvol_context *fv;
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    fogvol_mesh *m = NULL;
    const rec_mesh *up;
    (void)state;
    for (i = 0; i < 36; ++i) memcpy(flat + 3 * i, b.pos + 3 * b.idx[i], 3 * sizeof(float));
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    memset(&md, 0, sizeof md);
    md.positions = flat;
    md.vertex_count = 36;
    md.weld_distance = 1e-6f;
    assert_int_equal(fogvol_validate_mesh(&md, NULL, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.triangles, 12);
    assert_int_equal(rep.vertices, 8);
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.convex, 1);
    merged = ref_weld((const unsigned char *)flat, 12, 36, 1e-6f, rep_ref);
    assert_int_equal(merged, 28);
    up = rec_find(&r, r.meshes[r.nmesh - 1].handle);
    assert_int_equal(up->count, 36);
    for (i = 0; i < 36; ++i) assert_int_equal(up->idx[i], rep_ref[i]);
    fogvol_destroy_mesh(fv, m);
    /* no weld: 36 loose vertices, every edge open: no volume, an occluder; indices 0 .. 35 */
    md.weld_distance = 0.0f;
    md.index_type = FOGVOL_INDEX_UINT16; /* (no array of either type: still none) */
    lc.errors = 0;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(lc.errors, 1);
    md.allow_open = 1;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_SUCCESS);
    up = rec_find(&r, r.meshes[r.nmesh - 1].handle);
    assert_int_equal(up->count, 36);
    for (i = 0; i < 36; ++i) assert_int_equal(up->idx[i], i);
    fogvol_destroy_mesh(fv, m);
    /* vertex_count not a multiple of 3; an index_count without an array */
    md.vertex_count = 35;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(lc.last_error, "multiple of 3"));
    md.vertex_count = 36;
    md.index_count = 36;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(lc.last_error, "no index array"));
    fogvol_destroy_context(fv);
    rec_free(&r);
    shp_free(&b);
}

/* A raylib sphere without indices (welded), drawn by the GL backend, FLOAT: the thickness at the
   centre pixel against the analytic chord through the centre of the unit sphere (2, minus what the
   32-gon cross-section loses: chord of the polygon's inscribed radius at the pole-to-pole axis is
   exact at the poles, so 2 within the tessellation's 1 - cos(pi / 16) = 1.9%). */
static void test_non_indexed_gl(void **state)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    fogvol_mesh_desc md;
    fogvol_mesh *m = NULL;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    float *thick = (float *)malloc(sizeof(float) * 64 * 64), *pos;
    double eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0}, t;
    int nv;
    (void)state;
    assert_non_null(thick);
    assert_true(glu_create(&g, 64, 64, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.tier = FOGVOL_TIER_FLOAT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    pos = raylib_sphere(16, 32, &nv);
    memset(&md, 0, sizeof md);
    md.positions = pos;
    md.vertex_count = nv;
    md.weld_distance = 1e-5f;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
    ramp = plain_ramp(fv, 0.5f);
    memset(&fd, 0, sizeof fd);
    glu_look_at(fd.view, eye, at, up);
    glu_perspective(fd.projection, 40.0, 1.0, 0.5, 20.0);
    fd.znear = 0.5f;
    fd.zfar = 20.0f;
    fd.viewport[2] = fd.viewport[3] = 64;
    fd.debug_thickness = thick;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    model_ts(vd.model, 0, 0, 0, 1);
    /* the poles on the z axis look at the camera: the centre ray runs pole to pole, chord 2 */
    vd.mesh = m;
    vd.ramp = ramp;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    t = (thick[31 * 64 + 31] + thick[31 * 64 + 32] + thick[32 * 64 + 31] + thick[32 * 64 + 32]) / 4.0;
    print_message("  unindexed GenMeshSphere(1, 16, 32), GL, FLOAT: centre thickness %.4f (chord 2)\n", t);
    assert_true(fabs(t - 2.0) < 0.02);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, m);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    free(pos);
    free(thick);
}

/* ==== L8 every refusal logged ==== */
#define REFUSED(call, code)                                                                                       \
    do {                                                                                                          \
        int e0_ = lc.errors;                                                                                      \
        assert_int_equal((call), (code));                                                                         \
        if (lc.errors <= e0_) fail_msg("%s refused with %s and nothing logged", #call, fogvol_result_string(code)); \
        print_message("  %-70s %s: %s\n", #call, fogvol_result_string(code), lc.last_error);                      \
    } while (0)

static void occluder_cb(fogvol_context *ctx, void *u)
{
    (void)ctx;
    (void)u;
}

static fogvol_gl_proc no_gl(const char *name, void *user)
{
    (void)name;
    (void)user;
    return NULL;
}

static void test_refusals_logged(void **state)
{
    static const unsigned char px[4] = {255, 255, 255, 255};
    recorder r;
    logcap lc;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp;
    fogvol_mesh *mo = NULL;
    fogvol_ramp *ro = NULL;
    fogvol_volume_texture *to = NULL;
    fogvol_volume_desc vd;
    fogvol_light_desc ld;
    fogvol_texture_desc td;
    fogvol_frame_desc fd;
    fogvol_mrt_info mi;
    fogvol_occluder_info oi;
    fogvol_context_desc cd;
    fogvol_context *fv2 = NULL;
    fogvol_backend be;
    fogvol_null_backend nb2;
    float model[16];
    (void)state;
    memset(&lc, 0, sizeof lc);
    fv = rec_context(&r, 0u, FOGVOL_TIER_PS20, 0u, &lc, NULL);
    mesh = box_mesh(fv);
    ramp = plain_ramp(fv, 0.5f);
    model_ts(model, 0, 0, 0, 1);
    memset(&vd, 0, sizeof vd);
    memcpy(vd.model, model, sizeof model);
    vd.mesh = mesh;
    vd.ramp = ramp;
    memset(&ld, 0, sizeof ld);
    memcpy(ld.model, model, sizeof model);
    ld.mesh = mesh;
    /* out of order */
    REFUSED(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_add_occluder(fv, mesh, model), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_add_occluder_callback(fv, occluder_cb, NULL), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_add_light(fv, &ld), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_occluder_transform(fv, model), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_occluder_prepare(fv, &oi), FOGVOL_ERROR_INVALID_STATE);
    REFUSED(fogvol_mrt_prepare(fv, &mi), FOGVOL_ERROR_INVALID_STATE);
    frame_desc(&fd, 0, 0, FOGVOL_COMPOSITE_FULLSCREEN);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    REFUSED(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_STATE); /* twice */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    REFUSED(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_STATE); /* after a cancel */
    /* NULL where something is needed */
    REFUSED(fogvol_begin_frame(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_create_mesh(fv, NULL, &mo, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_create_ramp(fv, NULL, &ro), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_create_volume_texture(fv, NULL, &to), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_mrt_prepare(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_occluder_prepare(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    vd.ramp = NULL;
    REFUSED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    vd.ramp = ramp;
    REFUSED(fogvol_add_occluder(fv, NULL, model), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_add_occluder_callback(fv, NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    REFUSED(fogvol_add_light(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    /* unknown enums */
    fd.composite = (fogvol_composite)7;
    REFUSED(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    memset(&td, 0, sizeof td);
    td.width = td.height = 1;
    td.pixels = px;
    td.filter = (fogvol_filter)2;
    REFUSED(fogvol_create_volume_texture(fv, &td, &to), FOGVOL_ERROR_INVALID_ARGUMENT);
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = (fogvol_wrap)-1;
    REFUSED(fogvol_create_volume_texture(fv, &td, &to), FOGVOL_ERROR_INVALID_ARGUMENT);
    td.wrap = FOGVOL_WRAP_CLAMP;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &to), FOGVOL_SUCCESS);
    fogvol_destroy_volume_texture(fv, to);
    /* GLSL dialects: of the GL desc (before any GL call), of a backend table */
    memset(&cd, 0, sizeof cd);
    cd.logger.func = cap_log;
    cd.logger.user_data = &lc;
    cd.gl.get_proc_address = no_gl;
    cd.gl.dialect = (fogvol_dialect)42;
    REFUSED(fogvol_create_context(&cd, &fv2), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv2);
    REFUSED(fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &be), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.gl.dialect = FOGVOL_GLSL_AUTO;
    fogvol_null_backend_init(&nb2, &cd.backend);
    cd.backend.dialect = (fogvol_dialect)FOGVOL_GLSL_COUNT;
    REFUSED(fogvol_create_context(&cd, &fv2), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.backend.dialect = (fogvol_dialect)-3;
    REFUSED(fogvol_create_context(&cd, &fv2), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv2);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    rec_free(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_far_volumes_geometry), cmocka_unit_test(test_viewport_origins),
        cmocka_unit_test(test_weld_reference),       cmocka_unit_test(test_ramp_groups),
        cmocka_unit_test(test_lifetime_null),        cmocka_unit_test(test_lifetime_gl),
        cmocka_unit_test(test_convex_welded),        cmocka_unit_test(test_convex_tree),        cmocka_unit_test(test_non_indexed),
        cmocka_unit_test(test_non_indexed_gl),       cmocka_unit_test(test_refusals_logged),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
