/* test_overflow.c - depth-complexity overflow: show_overflow marks every wrong
   pixel on every RGBA8 tier and variant, and the per-frame count from the
   backend's occlusion queries (no read-back, read a frame or more later,
   never waiting) matches the debug read-back; the policies react to it.

   Scenes: k concentric spheres in four groups (radius 0.25 + 0.2 g + 0.004 j:
   the silhouettes of a group lie within about a pixel, so the rings between
   them are interior pixels crossing k/4, k/2, 3k/4 and k shells) seen from 8.6
   units away, so the depths sit at d = 0.75..0.95 of the range and the channel
   sums are large (and from 5 units, d = 0.37..0.58). At L = 4 a target sums 16 faces (SINGLE_TARGET 8): 12 shells fit
   two targets but not one, 20 fit neither. WIDE (L = 3) sums 32: 24 and 40.
   Ground truth: the thickness ray-cast from the very triangles
   (tests/raycast.h: exact ray/triangle chords of the drawn shells). A pixel is
   wrong when |error| > 1 LSB per pair of faces (the tiers' bound). PS20 and MRT run their digits
   here (FOGVOL_SPEEDUP_EXACT_SUM off: this GL would sum them as 32-bit integers, which cannot
   saturate); exact_sum: those integer sums over 20 shells, no overflow, against the ray cast. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/raycast.h"
#include "tests/shapes.h"
#include "tests/scenes.h"
#include "tests/fixtures.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

/* ---- logging and a GL loader that watches query reads --------------------- */
typedef struct logcap {
    int warnings, errors;
    char last[512];
} logcap;

static void logger(void *u, fogvol_log_level l, const char *m)
{
    logcap *c = (logcap *)u;
    if (l == FOGVOL_LOG_ERROR) c->errors++;
    if (l == FOGVOL_LOG_WARNING) c->warnings++;
    if (l <= FOGVOL_LOG_WARNING) snprintf(c->last, sizeof c->last, "%s", m);
    if (l == FOGVOL_LOG_ERROR) print_message("  [fogvol error] %s\n", m);
}

/* A blocking read is GL_QUERY_RESULT on a query whose GL_QUERY_RESULT_AVAILABLE was not
   just seen true: counted in g_blocking_reads. */
static GLuint g_avail_id;
static int g_blocking_reads, g_result_reads;

static void APIENTRY watch_get_query_object(GLuint id, GLenum pname, GLuint *out)
{
    glGetQueryObjectuiv(id, pname, out);
    if (pname == GL_QUERY_RESULT_AVAILABLE) g_avail_id = *out ? id : 0;
    if (pname == GL_QUERY_RESULT) {
        g_result_reads++;
        if (g_avail_id != id) g_blocking_reads++;
        g_avail_id = 0;
    }
}

static void (*watch_proc(const char *name, void *user))(void)
{
    if (strcmp(name, "glGetQueryObjectuiv") == 0) return (void (*)(void))watch_get_query_object;
    return glu_proc(name, user);
}

/* ---- the shells ----------------------------------------------------------- */
static tscene *shell_scene(int k, int near)
{
    float m[16];
    int i;
    tscene *s = new_scene("shells", 0.04, 0.03, near ? 5.0 : 8.6, 0, 0, 0, 0.5, 10);
    s->cam.fovy_deg = near ? 22.0 : 14.0;
    shp_mat_identity(m);
    for (i = 0; i < k; ++i) { /* one volume per shell; beyond MAX_OBJ a volume holds two shells */
        shp_mesh one = shp_sphere(0.25f + 0.2f * (float)(i % 4) + 0.004f * (float)(i / 4), 40, 20);
        if (i < MAX_OBJ) {
            add(s, one, 1, m);
        } else {
            shp_append(&s->obj[i % MAX_OBJ].mesh, &one);
            shp_free(&one);
        }
    }
    return s;
}

typedef struct truth {
    int k, near;
    tscene *s;
    double *gt, *slope, tmax;
    int *pairs, max_faces;
    unsigned char *interior, *covered;
} truth;

#define NTRUTH 8
static truth g_truth[NTRUTH]; /* k = 12, 20, 24, 40, far and near */

static const truth *get_truth(int k, int near)
{
    int i;
    for (i = 0; i < NTRUTH; ++i) {
        truth *t = &g_truth[i];
        if (t->k == k && t->near == near) return t;
        if (t->k == 0) {
            t->k = k;
            t->near = near;
            t->s = shell_scene(k, near);
            t->gt = (double *)malloc(sizeof(double) * W * H);
            t->slope = (double *)malloc(sizeof(double) * W * H);
            t->pairs = (int *)malloc(sizeof(int) * W * H);
            t->interior = (unsigned char *)malloc(W * H);
            t->covered = (unsigned char *)malloc(W * H);
            ground_truth(t->s, t->gt, t->pairs, t->interior, t->covered, &t->max_faces, &t->tmax, t->slope);
            return t;
        }
    }
    fail_msg("truth cache full");
    return NULL;
}

typedef struct combo {
    fogvol_tier tier;
    unsigned variants;
    const char *name;
    int bits;
    int k[2]; /* shells: within the two-target limit, beyond it */
} combo;

static const combo g_combos[] = {
    {FOGVOL_TIER_PS20, 0, "PS20", 4, {12, 20}},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, "PS20+single", 4, {12, 20}},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_ALU, "PS20+alu+single", 4, {12, 20}},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, "PS20+count", 4, {12, 20}},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_WIDE, "PS20+wide", 3, {24, 40}},
    {FOGVOL_TIER_PS13, 0, "PS13", 4, {12, 20}},
    {FOGVOL_TIER_PS13, FOGVOL_VARIANT_COUNT, "PS13+count", 4, {12, 20}},
    {FOGVOL_TIER_MRT, 0, "MRT", 4, {12, 20}},
    {FOGVOL_TIER_MRT, FOGVOL_VARIANT_SINGLE_TARGET, "MRT+single", 4, {12, 20}},
};
#define NCOMBO ((int)(sizeof g_combos / sizeof g_combos[0]))

typedef struct outcome {
    int wrong, wrong_unmarked, magenta, magenta_within_limit, readback_sat, late, late_frame, frames_to_count;
    double max_err_lsb, min_wrong_lsb; /* the largest error; the smallest error of a wrong pixel */
    fogvol_result result;
} outcome;

static outcome g_out[NCOMBO][3];

/* A frame of the shells; MRT: the engine's part is a cleared O ("far": no occluders). */
static int g_show_overflow = 1; /* shell_frame's fogvol_frame_desc.show_overflow */

static fogvol_result shell_frame(fogvol_context *fv, const tscene *s, fogvol_mesh **meshes, fogvol_ramp *ramp,
                                 float *thick, fogvol_frame_stats *st)
{
    fogvol_frame_desc fd;
    fx_frame_desc(&fd, &s->cam, W, H);
    fd.show_overflow = g_show_overflow;
    fd.debug_thickness = thick;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    if (fogvol_context_tier(fv, NULL) == FOGVOL_TIER_MRT) {
        fogvol_mrt_info mrt;
        GLuint fbo;
        assert_int_equal(fogvol_mrt_prepare(fv, &mrt), FOGVOL_SUCCESS);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, (GLuint)mrt.texture, 0);
        glClearBufferfv(GL_COLOR, 0, mrt.clear_color);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
    }
    add_scene(fv, s, meshes, ramp, 1);
    return fogvol_end_frame(fv, st);
}

static int is_magenta(const unsigned char *p) { return p[0] == 255 && p[1] == 0 && p[2] == 255; }
static int count_magenta(const unsigned char *px)
{
    int i, n = 0;
    for (i = 0; i < W * H; ++i) n += is_magenta(px + 4 * i);
    return n;
}

static void write_png(const char *name, int k, const unsigned char *px)
{
    char path[256], *q;
    mkdir("build", 0777);
    mkdir("build/overflow", 0777);
    snprintf(path, sizeof path, "build/overflow/%s_%d.png", name, k);
    for (q = path + 15; *q; ++q)
        if (*q == '+') *q = '_';
    stbi_flip_vertically_on_write(1);
    stbi_write_png(path, W, H, 4, px, W * 4);
}

/* which: 0 = within the two-target limit, 1 = beyond it, 2 = the first seen from 5 units (depths
   0.37..0.58: smaller red digits; SINGLE_TARGET saturates in some channels of some pixels) */
static void run_combo(int ci, int which)
{
    const combo *c = &g_combos[ci];
    const truth *t = get_truth(c->k[which == 1], which == 2);
    const tscene *s = t->s;
    outcome *o = &g_out[ci][which];
    int single = (c->variants & FOGVOL_VARIANT_SINGLE_TARGET) != 0, i, frame;
    double range = s->cam.zfar - s->cam.znear, snap;
    double lsb = range / pow(2.0, ((c->variants & FOGVOL_VARIANT_WIDE) ? 6.0 : 3.0) * c->bits);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    unsigned char *px = (unsigned char *)malloc((size_t)W * H * 4);
    glu_ctx g;
    logcap lc;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    fogvol_frame_stats st;
    int limit;
    memset(o, 0, sizeof *o);
    memset(&lc, 0, sizeof lc);
    assert_true(glu_create(&g, W, H, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = watch_proc;
    cd.logger.func = logger;
    cd.logger.user_data = &lc;
    cd.tier = c->tier;
    cd.variants = c->variants;
    cd.encoding_bits = c->bits;
    cd.disable_dither = 1;
    cd.disable_speedups = FOGVOL_SPEEDUP_EXACT_SUM; /* the digits */
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    limit = single ? fogvol_context_encoding(fv)->max_faces_single : fogvol_context_encoding(fv)->max_faces;
    upload_meshes(fv, s, meshes);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.2f;
    rd.color[1] = 0.8f;
    rd.color[2] = 0.3f;
    rd.density = 0.4f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);

    g_blocking_reads = g_result_reads = 0;
    snap = snap_pixels();
    o->result = shell_frame(fv, s, meshes, ramp, thick, &st);
    assert_int_equal(st.frame, 0);
    assert_int_equal(st.overflow_pixels_late, -1); /* nothing known yet: the GPU has not been asked */
    o->readback_sat = st.overflow_pixels;
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
    for (i = 0; i < W * H; ++i) {
        double err = fabs(thick[i] - t->gt[i]) / lsb;
        int wrong, mag = is_magenta(px + 4 * i);
        if (!t->interior[i]) continue;
        wrong = err > t->pairs[i] + 1e-6 * range / lsb + t->slope[i] * snap / lsb;
        if (err > o->max_err_lsb) o->max_err_lsb = err;
        if (wrong && (o->min_wrong_lsb == 0 || err < o->min_wrong_lsb)) o->min_wrong_lsb = err;
        o->wrong += wrong;
        o->wrong_unmarked += wrong && !mag;
        o->magenta += mag;
        o->magenta_within_limit += mag && t->pairs[i] <= limit;
    }
    if (which == 1 || single) write_png(c->name, c->k[which == 1] + 1000 * (which == 2), px);
    /* the count of frame 0 arrives without a read-back, a frame or two later */
    o->late = -1;
    for (frame = 1; frame <= 3 && st.overflow_frame < 0; ++frame) {
        shell_frame(fv, s, meshes, ramp, NULL, &st);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px); /* what an engine's swap would do */
    }
    o->frames_to_count = frame - 1;
    o->late = st.overflow_pixels_late;
    o->late_frame = (int)st.overflow_frame;
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_int_equal(g_blocking_reads, 0);
    assert_true(g_result_reads > 0);
    for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    free(thick);
    free(px);

    print_message("  %-16s %2d %s shells (max %2d faces, limit %2d): %-22s read-back %4d saturated, GPU count %4d "
                  "(frame %d, after %d frames); %4d wrong (%.1f..%.1f LSB), %4d unmarked, %4d magenta, %d magenta "
                  "within the limit\n",
                  c->name, c->k[which == 1], which == 2 ? "near" : "far ", t->max_faces, limit, fogvol_result_string(o->result), o->readback_sat, o->late,
                  o->late_frame, o->frames_to_count, o->wrong, o->min_wrong_lsb, o->max_err_lsb, o->wrong_unmarked, o->magenta,
                  o->magenta_within_limit);
    assert_int_equal(o->wrong_unmarked, 0);       /* every wrong pixel is magenta */
    assert_int_equal(o->magenta_within_limit, 0); /* and none where the faces fit */
    assert_int_equal(o->late_frame, 0);
    assert_true(o->frames_to_count <= 2);
    assert_int_equal(o->late, o->readback_sat); /* the GPU count is the read-back's */
    if (t->max_faces <= limit) assert_int_equal(o->readback_sat, 0); /* the faces fit: nothing saturates */
    if (which == 1) assert_true(o->readback_sat > 0);                 /* the scene is built to overflow */
    if (o->readback_sat == 0) { /* more faces than the limit need not saturate: then nothing is wrong */
        assert_int_equal(o->result, FOGVOL_SUCCESS);
        assert_int_equal(o->magenta, 0);
        assert_int_equal(o->late, 0);
        assert_int_equal(o->wrong, 0);
    } else {
        assert_int_equal(o->result, FOGVOL_ERROR_DEPTH_OVERFLOW);
        assert_true(o->late > 0);
        assert_true(o->magenta > 0);
    }
}

static void test_combo(void **state)
{
    const int *p = (const int *)*state;
    run_combo(p[0], p[1]);
}

/* show_overflow on a 4x engine framebuffer: PS20 + SINGLE_TARGET summing digits (no integer sums, no
   framebuffer fetch, no depth-tested COUNT frames, every check pass), 12 nested spheres of radius
   0.3 .. 1.4 16 units away, whose 24 faces on the centre ray run the single biased sum past its digits: the centre
   pixel is magenta on a single-sample framebuffer and on a 4x one, frame after frame with the two
   alternating. (The overflow mask V, which SINGLE_TARGET's check writes at the sum's peak, was
   single-sample, and the per-sample composite read it as 0: no magenta at 4x.) */
static void test_show_overflow_msaa(void **state)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *m[12];
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    GLuint fbo[2], rb[4], rfbo, rrb;
    int i, f, k;
    (void)state;
    assert_true(glu_create(&g, 64, 64, 1));
    glGenFramebuffers(2, fbo);
    glGenRenderbuffers(4, rb);
    for (k = 0; k < 2; ++k) {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo[k]);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[2 * k]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, k ? 4 : 0, GL_RGBA8, 64, 64);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[2 * k]);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[2 * k + 1]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, k ? 4 : 0, GL_DEPTH24_STENCIL8, 64, 64);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, rb[2 * k + 1]);
        assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    }
    glGenRenderbuffers(1, &rrb);
    glBindRenderbuffer(GL_RENDERBUFFER, rrb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 64, 64);
    glGenFramebuffers(1, &rfbo);
    glBindFramebuffer(GL_FRAMEBUFFER, rfbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rrb);
    {
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.tier = FOGVOL_TIER_PS20;
        cd.variants = FOGVOL_VARIANT_SINGLE_TARGET;
        cd.overflow_policy = FOGVOL_OVERFLOW_COUNT_ONLY;
        cd.disable_speedups = FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH | FOGVOL_SPEEDUP_EXACT_SUM | FOGVOL_SPEEDUP_DEPTH_TEST |
                              FOGVOL_SPEEDUP_SKIP_CHECK;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        for (i = 0; i < 12; ++i) {
            shp_mesh s = shp_sphere(0.3f + 0.1f * (float)i, 16, 8);
            fogvol_mesh_desc md;
            memset(&md, 0, sizeof md);
            md.positions = s.pos;
            md.vertex_count = s.vcount;
            md.indices = (const uint32_t *)s.idx;
            md.index_count = s.icount;
            assert_int_equal(fogvol_create_mesh(fv, &md, &m[i], NULL), FOGVOL_SUCCESS);
            shp_free(&s);
        }
        memset(&rd, 0, sizeof rd);
        rd.color[0] = 1.0f;
        rd.color[1] = 0.8f;
        rd.color[2] = 0.5f;
        rd.density = 0.05f;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
        for (f = 0; f < 4; ++f) {
            fogvol_frame_desc fd;
            fogvol_volume_desc vd;
            fogvol_frame_stats st;
            unsigned char c[4];
            double eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
            k = f & 1;
            glBindFramebuffer(GL_FRAMEBUFFER, fbo[k]);
            glViewport(0, 0, 64, 64);
            glClearColor(0, 0, 0, 1);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            memset(&fd, 0, sizeof fd);
            glu_look_at(fd.view, eye, at, up);
            glu_perspective(fd.projection, 60.0, 1.0, 0.5, 20.0);
            fd.znear = 0.5f;
            fd.zfar = 20.0f;
            fd.viewport[2] = fd.viewport[3] = 64;
            fd.show_overflow = 1;
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
            memset(&vd, 0, sizeof vd);
            vd.ramp = ramp;
            glu_identity(vd.model);
            vd.model[14] = -11.0f; /* (16 units away: deep digits, which the 24 faces overflow) */
            for (i = 0; i < 12; ++i) {
                vd.mesh = m[i];
                assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
            }
            (void)fogvol_end_frame(fv, &st); /* (FOGVOL_ERROR_DEPTH_OVERFLOW once counted) */
            assert_int_equal(st.samples, k ? 4 : 1);
            glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo[k]);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, rfbo);
            glBlitFramebuffer(0, 0, 64, 64, 0, 0, 64, 64, GL_COLOR_BUFFER_BIT, GL_NEAREST);
            glBindFramebuffer(GL_READ_FRAMEBUFFER, rfbo);
            glReadPixels(32, 32, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, c);
            print_message("# show_overflow, PS20+single, %s framebuffer: centre %d %d %d\n",
                          k ? "4x" : "single-sample", c[0], c[1], c[2]);
            assert_true(c[0] == 255 && c[1] == 0 && c[2] == 255);
            assert_int_equal(glGetError(), GL_NO_ERROR);
        }
        for (i = 0; i < 12; ++i) fogvol_destroy_mesh(fv, m[i]);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
    }
    glDeleteFramebuffers(2, fbo);
    glDeleteFramebuffers(1, &rfbo);
    glDeleteRenderbuffers(4, rb);
    glDeleteRenderbuffers(1, &rrb);
    glu_destroy(&g);
}

/* ---- policies on the GPU -------------------------------------------------- */
/* The policy tests' rig: a W x H OSMesa context, fogvol (PS20 unless cd says otherwise) with the 20
   shells (they overflow at L = 4) and a ramp; cd may hold what a test changes (policy, bits ...). */
typedef struct shellrig {
    const truth *t;
    glu_ctx g;
    logcap lc;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp *ramp;
} shellrig;
static int g_rig_exact; /* 1: rig_open leaves FOGVOL_SPEEDUP_EXACT_SUM on (else the digits) */

static void rig_open(shellrig *r, fogvol_context_desc *cd)
{
    fogvol_ramp_desc rd;
    memset(r, 0, sizeof *r);
    r->t = get_truth(20, 0);
    assert_true(glu_create(&r->g, W, H, 1));
    if (!cd->gl.get_proc_address) cd->gl.get_proc_address = watch_proc;
    if (!cd->tier) cd->tier = FOGVOL_TIER_PS20;
    cd->logger.func = logger;
    cd->logger.user_data = &r->lc;
    if (!g_rig_exact) cd->disable_speedups |= FOGVOL_SPEEDUP_EXACT_SUM; /* the digits */
    assert_int_equal(fogvol_create_context(cd, &r->fv), FOGVOL_SUCCESS);
    upload_meshes(r->fv, r->t->s, r->meshes);
    memset(&rd, 0, sizeof rd);
    rd.density = 0.4f;
    assert_int_equal(fogvol_create_ramp(r->fv, &rd, &r->ramp), FOGVOL_SUCCESS);
}

static fogvol_result rig_frame(shellrig *r, float *thick, fogvol_frame_stats *st)
{
    return shell_frame(r->fv, r->t->s, r->meshes, r->ramp, thick, st);
}

static void rig_close(shellrig *r)
{
    int i;
    for (i = 0; i < r->t->s->n; ++i) fogvol_destroy_mesh(r->fv, r->meshes[i]);
    fogvol_destroy_ramp(r->fv, r->ramp);
    fogvol_destroy_context(r->fv);
    glu_destroy(&r->g);
}
/* LOWER_BITS: 20 shells at L = 4 overflow; the count arrives, L drops to 3 once (frames drawn
   before the change report overflow too, and must not lower it again), and the next frames are
   within the bound of the new encoding. */
static void test_lower_bits(void **state)
{
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    shellrig rig;
    const truth *t;
    fogvol_context_desc cd;
    fogvol_frame_stats st;
    fogvol_result r;
    double range, max_before = 0, max_after = 0, snap;
    int frame, i, lowered_at = -1, bad_after = 0;
    (void)state;
    memset(&cd, 0, sizeof cd);
    cd.encoding_bits = 4;
    cd.disable_dither = 1;
    cd.overflow_policy = FOGVOL_OVERFLOW_LOWER_BITS;
    rig_open(&rig, &cd);
    t = rig.t;
    range = t->s->cam.zfar - t->s->cam.znear;
    snap = snap_pixels();
    for (frame = 0; frame < 6; ++frame) {
        int bits = fogvol_context_encoding(rig.fv)->bits;
        double lsb = range / pow(2.0, 3.0 * bits), max = 0;
        unsigned char px[4];
        r = rig_frame(&rig, thick, &st);
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
        for (i = 0; i < W * H; ++i) {
            double err;
            if (!t->interior[i]) continue;
            err = fabs(thick[i] - t->gt[i]) / lsb;
            if (err > max) max = err;
            if (bits == 3 && err > t->pairs[i] + 1e-6 * range / lsb + t->slope[i] * snap / lsb) ++bad_after;
        }
        print_message("  lower_bits frame %d: L = %d, %s, late count %d (frame %lld), max error %.1f LSB\n", frame, bits,
                      fogvol_result_string(r), st.overflow_pixels_late, (long long)st.overflow_frame, max);
        if (bits == 4) {
            assert_int_equal(r, FOGVOL_ERROR_DEPTH_OVERFLOW);
            if (max > max_before) max_before = max;
        } else {
            assert_int_equal(bits, 3);
            assert_int_equal(r, FOGVOL_SUCCESS);
            assert_int_equal(st.overflow_pixels, 0);
            if (max > max_after) max_after = max;
        }
        if (lowered_at < 0 && fogvol_context_encoding(rig.fv)->bits == 3) lowered_at = frame;
    }
    print_message("  lower_bits: lowered after frame %d; max error %.1f LSB (L=4) -> %.2f LSB (L=3); %d warnings\n",
                  lowered_at, max_before, max_after, rig.lc.warnings);
    assert_true(lowered_at >= 0 && lowered_at <= 2);
    assert_int_equal(fogvol_context_encoding(rig.fv)->bits, 3); /* once, not again for the frames drawn at L = 4 */
    assert_int_equal(bad_after, 0);
    assert_int_equal(st.overflow_pixels_late, 0); /* the GPU agrees: frames at L = 3 fit */
    assert_true(max_before > 16);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    rig_close(&rig);
    free(thick);
}

/* FOGVOL_SPEEDUP_EXACT_SUM: PS20 and MRT sum the 20 shells (40 faces on the innermost rays, which
   overflow both targets' digits at L = 4) as 32-bit integers: no overflow reported, no check pass,
   and the debug thickness within 1e-5 of the depth range plus vertex snapping of the ray-cast
   chords (the digits' bound is an LSB of 2^-12 per pair of faces). */
static void test_exact_sum(void **state)
{
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    int tier;
    (void)state;
    g_rig_exact = 1;
    for (tier = 0; tier < 2; ++tier) {
        shellrig rig;
        fogvol_context_desc cd;
        fogvol_frame_stats st;
        double range, snap = snap_pixels(), max = 0;
        int frame, i, bad = 0, n = 0;
        memset(&cd, 0, sizeof cd);
        cd.tier = tier ? FOGVOL_TIER_MRT : FOGVOL_TIER_PS20;
        cd.encoding_bits = 4;
        rig_open(&rig, &cd);
        if (!glu_has_fetch()) { /* no integer sums without framebuffer fetch (NVIDIA's desktop driver) */
            print_message("  this GL has no EXT_shader_framebuffer_fetch: skipped\n");
            rig_close(&rig);
            g_rig_exact = 0;
            free(thick);
            skip();
        }
        range = rig.t->s->cam.zfar - rig.t->s->cam.znear;
        for (frame = 0; frame < 3; ++frame) {
            assert_int_equal(rig_frame(&rig, thick, &st), FOGVOL_SUCCESS);
            assert_int_equal(st.exact_sum, 1);
            assert_int_equal(st.overflow_pixels, 0);
            assert_int_equal(st.overflow_pixels_late, 0);
            assert_int_equal(st.overflow_passes, 0);
        }
        for (i = 0; i < W * H; ++i) {
            double err;
            if (!rig.t->interior[i]) continue;
            ++n;
            err = fabs(thick[i] - rig.t->gt[i]);
            if (err > max) max = err;
            if (err > 1e-5 * range + rig.t->slope[i] * snap) ++bad;
        }
        print_message("  exact_sum %s: 20 shells, %d interior pixels, max |error| %.2e of the depth range, no "
                      "overflow, no check pass\n", tier ? "MRT" : "PS20", n, max / range);
        assert_true(n > W * H / 8);
        assert_int_equal(bad, 0);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        rig_close(&rig);
    }
    g_rig_exact = 0;
    free(thick);
}

/* WARN_ONCE (the default): one warning however many frames overflow; COUNT_ONLY: none. */
static void test_warn_once(void **state)
{
    int policy;
    (void)state;
    for (policy = 0; policy < 2; ++policy) {
        shellrig rig;
        fogvol_context_desc cd;
        fogvol_frame_stats st;
        int frame;
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.overflow_policy = policy ? FOGVOL_OVERFLOW_COUNT_ONLY : FOGVOL_OVERFLOW_WARN_ONCE;
        rig_open(&rig, &cd);
        for (frame = 0; frame < 5; ++frame) {
            unsigned char px[4];
            assert_int_equal(rig_frame(&rig, NULL, &st), FOGVOL_SUCCESS); /* no read-back */
            glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
        }
        assert_true(st.overflow_pixels_late > 0);
        assert_int_equal(st.overflow_frame, 3);
        assert_int_equal(rig.lc.warnings, policy ? 0 : 1);
        if (!policy) assert_non_null(strstr(rig.lc.last, "logged once"));
        assert_int_equal(fogvol_context_encoding(rig.fv)->bits, 4);
        rig_close(&rig);
    }
}

/* FOGVOL_SPEEDUP_OVERFLOW_BANDS (the default, without show_overflow): each frame checks one band
   of the picture; once every band has been counted, the count of the still picture is the debug
   read-back's count of saturated pixels, and never more before that. Then show_overflow in the
   same context marks exactly those pixels (the composite built with the overflow test again). */
static void test_bands(void **state)
{
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    shellrig rig;
    fogvol_context_desc cd;
    fogvol_frame_stats st;
    int frame, readback, last = -1, passes = 0, partial = 0, magenta_off, magenta_on;
    (void)state;
    memset(&cd, 0, sizeof cd);
    cd.overflow_policy = FOGVOL_OVERFLOW_COUNT_ONLY;
    rig_open(&rig, &cd);
    g_show_overflow = 0;
    g_blocking_reads = 0;
    assert_int_equal(rig_frame(&rig, thick, &st), FOGVOL_ERROR_DEPTH_OVERFLOW);
    readback = st.overflow_pixels;
    assert_true(readback > 100);
    passes += st.overflow_passes;
    for (frame = 1; frame < 2 * FOGVOL_OVERFLOW_BANDS + 2; ++frame) {
        unsigned char px[4];
        assert_int_equal(rig_frame(&rig, NULL, &st), FOGVOL_SUCCESS);
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px); /* what an engine's swap would do */
        passes += st.overflow_passes;
        if (st.overflow_frame < 0) continue;
        assert_true(st.overflow_pixels_late >= last); /* bands add up */
        assert_true(st.overflow_pixels_late <= readback);
        if (st.overflow_pixels_late != last)
            print_message("  bands: frame %d reads the count up to frame %lld: %d\n", frame, (long long)st.overflow_frame,
                          st.overflow_pixels_late);
        last = st.overflow_pixels_late;
        partial += last < readback; /* not every band counted yet */
    }
    magenta_off = count_magenta(glu_pixels(&rig.g)); /* the composite built without the overflow test */
    g_show_overflow = 1; /* the same context: the composite with it, this frame */
    assert_int_equal(rig_frame(&rig, NULL, &st), FOGVOL_SUCCESS);
    magenta_on = count_magenta(glu_pixels(&rig.g));
    print_message("  bands: read-back %d saturated pixels, sum of the %d bands %d (frame %lld), %d check passes in "
                  "%d frames; magenta pixels %d without show_overflow, %d with it\n",
                  readback, FOGVOL_OVERFLOW_BANDS, st.overflow_pixels_late, (long long)st.overflow_frame, passes, frame,
                  magenta_off, magenta_on);
    assert_int_equal(magenta_off, 0);
    assert_int_equal(magenta_on, readback); /* the program switched back to the overflow test */
    assert_true(st.overflow_frame >= FOGVOL_OVERFLOW_BANDS);
    assert_int_equal(st.overflow_pixels_late, readback);
    assert_true(partial > 0); /* whole-picture checks would give the full count at once */
    assert_true(passes <= frame); /* one check pass a frame at most (none where a band holds no row) */
    assert_int_equal(g_blocking_reads, 0);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    rig_close(&rig);
    free(thick);
}

/* An engine's own occlusion query running across fogvol's frame: fogvol does not start its own
   (GL would refuse it), the frame is not counted, no GL error reaches the engine. */
static void test_engine_query_active(void **state)
{
    shellrig rig;
    fogvol_context_desc cd;
    fogvol_frame_stats st;
    GLuint q;
    GLint cur = 0;
    int frame;
    (void)state;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    rig_open(&rig, &cd);
    glGenQueries(1, &q);
    for (frame = 0; frame < 3; ++frame) {
        glBeginQuery(GL_SAMPLES_PASSED, q);
        rig_frame(&rig, NULL, &st);
        glGetQueryiv(GL_SAMPLES_PASSED, GL_CURRENT_QUERY, &cur);
        assert_int_equal((GLuint)cur, q); /* still the engine's */
        glEndQuery(GL_SAMPLES_PASSED);
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    assert_int_equal(st.overflow_pixels_late, -1);
    rig_frame(&rig, NULL, &st); /* the engine's query ended: counted again */
    glFinish();
    rig_frame(&rig, NULL, &st);
    assert_int_equal(st.overflow_frame, 3);
    assert_true(st.overflow_pixels_late > 0);
    glDeleteQueries(1, &q);
    rig_close(&rig);
}

/* GLES 3 (a desktop context treated as GLES 3.0, GLSL 300 es): ANY_SAMPLES_PASSED reports 1 for
   a frame with overflow and 0 without. */
static void test_gles3_any_samples(void **state)
{
    int which;
    (void)state;
    for (which = 0; which < 2; ++which) {
        const truth *t = get_truth(which ? 20 : 12, 0);
        glu_ctx g;
        logcap lc;
        fogvol_context_desc cd;
        fogvol_context *fv;
        fogvol_mesh *meshes[MAX_OBJ];
        fogvol_ramp *ramp;
        fogvol_ramp_desc rd;
        fogvol_frame_stats st;
        int i, frame;
        memset(&lc, 0, sizeof lc);
        assert_true(glu_create(&g, W, H, 1));
        if (!strstr((const char *)glGetString(GL_VERSION), "Mesa")) {
            /* a desktop context passes for GLES 3 only where the driver takes the ES enums on desktop
               too, as Mesa does; NVIDIA's 580 driver answers GL_INVALID_ENUM (test_gles covers real
               ES contexts) */
            print_message("  GLES 3 as desktop GL: %s is not Mesa: skipped\n", (const char *)glGetString(GL_VERSION));
            glu_destroy(&g);
            skip();
        }
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = watch_proc;
        cd.gl.gles = 1;
        cd.gl.version_major = 3;
        cd.logger.func = logger;
        cd.logger.user_data = &lc;
        cd.tier = FOGVOL_TIER_PS20;
        cd.disable_speedups = FOGVOL_SPEEDUP_EXACT_SUM; /* the digits */
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        upload_meshes(fv, t->s, meshes);
        memset(&rd, 0, sizeof rd);
        rd.density = 0.4f;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
        g_blocking_reads = 0;
        for (frame = 0; frame < 3; ++frame) {
            unsigned char px[4];
            shell_frame(fv, t->s, meshes, ramp, NULL, &st);
            glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
        }
        print_message("  GLES 3, %d shells: late count %d (frame %lld)\n", t->k, st.overflow_pixels_late,
                      (long long)st.overflow_frame);
        assert_int_equal(st.overflow_frame, 1);
        assert_int_equal(st.overflow_pixels_late, which);
        assert_int_equal(g_blocking_reads, 0);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        for (i = 0; i < t->s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
        glu_destroy(&g);
    }
}

/* ---- sequences (tests/sequence.h) ------------------------------------------------------------
   The overflow counts over frames that change: the camera walks from the far shells' view to the
   near one, "occluders" are here the shells beyond the two-target limit (the frames that have them
   overflow, the others fit), the viewport shrinks and splits, a cancelled frame comes in between.
   Every view is drawn with show_overflow and the debug read-back; the GPU count of fogvol frame f,
   when it arrives in a later frame, must be frame f's own read-back count (a count that belongs to
   another frame, a query read twice or a count kept across frames fail); every wrong pixel is
   magenta and none is where the faces fit, against the ray cast of that view's camera. */
typedef struct vtruth {
    int k, near, w, h;
    rc_camera cam;
    rc_scene rs;     /* kept for what is found per pixel when asked (vtruth_interior) */
    double *gt, *slope;
    int *pairs, max_faces;
    signed char *interior; /* -1: not known yet */
} vtruth;
#define NVTRUTH 16
static vtruth g_vtruth[NVTRUTH]; /* made on first use, shared by the sequences */

/* Whether pixel p of the view is interior (rc_interior) and, if so, its depth slope: found when first
   asked (only pixels that would fail a check need it), then kept. */
static int vtruth_interior(vtruth *t, int p)
{
    if (t->interior[p] < 0) {
        int x = p % t->w, y = p / t->w;
        t->interior[p] = (signed char)rc_interior(&t->rs, &t->cam, x, y);
        t->slope[p] = t->interior[p] ? rc_depth_slope(&t->rs, &t->cam, x, y) : 0.0;
    }
    return t->interior[p];
}

/* The truth of the shells (k, near) through a vw x vh viewport (the scene's camera, its aspect):
   thickness and pairs of faces per pixel now, interior and slope when asked. */
static vtruth *view_truth(int k, int near, int vw, int vh)
{
    vtruth *t;
    int i, x, y;
    for (i = 0; i < NVTRUTH && g_vtruth[i].k; ++i)
        if (g_vtruth[i].k == k && g_vtruth[i].near == near && g_vtruth[i].w == vw && g_vtruth[i].h == vh)
            return &g_vtruth[i];
    assert_true(i < NVTRUTH);
    t = &g_vtruth[i];
    t->k = k;
    t->near = near;
    t->w = vw;
    t->h = vh;
    t->gt = (double *)malloc(sizeof(double) * vw * vh);
    t->slope = (double *)malloc(sizeof(double) * vw * vh);
    t->pairs = (int *)malloc(sizeof(int) * vw * vh);
    t->interior = (signed char *)malloc((size_t)vw * vh);
    memset(t->interior, -1, (size_t)vw * vh);
    t->cam = get_truth(k, near)->s->cam;
    t->cam.width = vw;
    t->cam.height = vh;
    t->cam.aspect = (double)vw / vh;
    scene_raycaster(get_truth(k, near)->s, 1, &t->rs);
    for (y = 0; y < vh; ++y)
        for (x = 0; x < vw; ++x) {
            rc_result r = rc_trace(&t->rs, &t->cam, x + 0.5, y + 0.5);
            int p = y * vw + x;
            t->gt[p] = r.thickness;
            t->pairs[p] = r.faces_front > r.faces_back ? r.faces_front : r.faces_back;
            if (t->pairs[p] < 1) t->pairs[p] = 1;
            if (t->pairs[p] > t->max_faces) t->max_faces = t->pairs[p];
        }
    return t;
}

static void free_view_truths(void)
{
    int i;
    for (i = 0; i < NVTRUTH; ++i) {
        if (g_vtruth[i].k) rc_scene_free(&g_vtruth[i].rs);
        free(g_vtruth[i].gt);
        free(g_vtruth[i].slope);
        free(g_vtruth[i].pairs);
        free(g_vtruth[i].interior);
    }
    memset(g_vtruth, 0, sizeof g_vtruth);
}

typedef struct ovseq {
    const combo *c;
    glu_ctx *g;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ]; /* the most shells' scene: a frame adds the first k */
    fogvol_ramp *ramp;
    float *thick;
    unsigned char *px;
    int readback[64]; /* the read-back's saturated pixels per fogvol frame number */
    int checked, mismatched, lowered_at, show, bits_at[64];
    logcap lc;
} ovseq;

/* a frame of the first k shells, camera near or far, into viewport vp (MRT: the engine's O cleared) */
static fogvol_result ovseq_frame(ovseq *q, int k, int near, const int vp[4], float *thick, fogvol_frame_stats *st,
                                 int cancel)
{
    const tscene *s = get_truth(k, near)->s;
    rc_camera cam = s->cam;
    fogvol_frame_desc fd;
    int i;
    cam.width = vp[2];
    cam.height = vp[3];
    cam.aspect = (double)vp[2] / vp[3];
    fx_frame_desc(&fd, &cam, vp[2], vp[3]);
    fd.viewport[0] = vp[0];
    fd.viewport[1] = vp[1];
    fd.show_overflow = q->show;
    fd.debug_thickness = thick;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    assert_int_equal(fogvol_begin_frame(q->fv, &fd), FOGVOL_SUCCESS);
    if (q->c->tier == FOGVOL_TIER_MRT) {
        fogvol_mrt_info mrt;
        GLuint fbo;
        assert_int_equal(fogvol_mrt_prepare(q->fv, &mrt), FOGVOL_SUCCESS);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, (GLuint)mrt.texture, 0);
        glClearBufferfv(GL_COLOR, 0, mrt.clear_color);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
    }
    for (i = 0; i < k && i < MAX_OBJ; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = q->meshes[i];
        vd.ramp = q->ramp;
        memcpy(vd.model, s->obj[i].model, sizeof vd.model);
        assert_int_equal(fogvol_add_volume(q->fv, &vd), FOGVOL_SUCCESS);
    }
    if (cancel) return fogvol_cancel_frame(q->fv);
    return fogvol_end_frame(q->fv, st);
}

static void ovseq_cancel(void *user, const sq_view *v)
{
    ovseq *q = (ovseq *)user;
    assert_int_equal(ovseq_frame(q, q->c->k[1], v->walk < 0.5, v->viewport, NULL, NULL, 1), FOGVOL_SUCCESS);
}

static void ovseq_view(void *user, const sq_view *v, sq_check *out)
{
    ovseq *q = (ovseq *)user;
    int k = q->c->k[v->occluders], near = v->walk >= 0.5, single = (q->c->variants & FOGVOL_VARIANT_SINGLE_TARGET) != 0;
    vtruth *t = view_truth(k, near, v->viewport[2], v->viewport[3]);
    const fogvol_encoding *enc = fogvol_context_encoding(q->fv);
    int bits = enc->bits, limit = single ? enc->max_faces_single : enc->max_faces, x, y;
    double range = get_truth(k, near)->s->cam.zfar - get_truth(k, near)->s->cam.znear, snap = snap_pixels();
    double lsb = range / pow(2.0, ((q->c->variants & FOGVOL_VARIANT_WIDE) ? 6.0 : 3.0) * bits);
    fogvol_frame_stats st;
    fogvol_result r;
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    r = ovseq_frame(q, k, near, v->viewport, q->thick, &st, 0);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, q->px); /* (what an engine's swap would do) */
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_true(st.frame < 64);
    q->readback[st.frame] = st.overflow_pixels;
    q->bits_at[st.frame] = bits;
    out->wrong += r != (st.overflow_pixels > 0 ? FOGVOL_ERROR_DEPTH_OVERFLOW : FOGVOL_SUCCESS);
    if (st.overflow_frame >= 0) { /* a count arrived: it is the read-back of the frame it names */
        q->checked++;
        if (st.overflow_pixels_late != q->readback[st.overflow_frame]) {
            q->mismatched++;
            out->wrong++;
            print_message("#   frame %lld: GPU count %d, its read-back %d\n", (long long)st.overflow_frame,
                          st.overflow_pixels_late, q->readback[st.overflow_frame]);
        }
    }
    if (q->lowered_at < 0 && fogvol_context_encoding(q->fv)->bits != bits) q->lowered_at = (int)st.frame;
    out->bound = 1.0; /* in LSBs per pair of faces */
    for (y = 0; y < v->viewport[3]; ++y)
        for (x = 0; x < v->viewport[2]; ++x) {
            int p = y * v->viewport[2] + x, mag = is_magenta(q->px + 4 * ((v->viewport[1] + y) * W + v->viewport[0] + x));
            double err = fabs(q->thick[p] - t->gt[p]) / lsb, allowed = t->pairs[p] + 1e-6 * range / lsb;
            /* the interior test and the slope only where a pixel would fail without them */
            if (((err > allowed && !mag) || (mag && t->pairs[p] <= limit)) && !vtruth_interior(t, p)) continue;
            if (t->interior[p] > 0) allowed += t->slope[p] * snap / lsb;
            out->pixels++;
            if (!mag && err / allowed > out->max_err) out->max_err = err / allowed;
            out->wrong += (err > allowed && !mag) || (mag && t->pairs[p] <= limit);
        }
}

static void ovseq_open(ovseq *q, const combo *c, unsigned policy, glu_ctx *g, unsigned speedups_off)
{
    fogvol_context_desc cd;
    fogvol_ramp_desc rd;
    memset(q, 0, sizeof *q);
    q->c = c;
    q->g = g;
    q->lowered_at = -1;
    q->show = 1;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = watch_proc;
    cd.logger.func = logger;
    cd.logger.user_data = &q->lc;
    cd.tier = c->tier;
    cd.variants = c->variants;
    cd.encoding_bits = c->bits;
    cd.disable_dither = 1;
    cd.disable_speedups = FOGVOL_SPEEDUP_EXACT_SUM | speedups_off; /* the digits */
    cd.overflow_policy = (fogvol_overflow_policy)policy;
    assert_int_equal(fogvol_create_context(&cd, &q->fv), FOGVOL_SUCCESS);
    upload_meshes(q->fv, get_truth(c->k[1], 0)->s, q->meshes);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.2f;
    rd.color[1] = 0.8f;
    rd.color[2] = 0.3f;
    rd.density = 0.4f;
    assert_int_equal(fogvol_create_ramp(q->fv, &rd, &q->ramp), FOGVOL_SUCCESS);
    q->thick = (float *)calloc((size_t)W * H, sizeof(float));
    q->px = (unsigned char *)malloc((size_t)W * H * 4);
}

static void ovseq_close(ovseq *q)
{
    int i;
    for (i = 0; i < get_truth(q->c->k[1], 0)->s->n; ++i) fogvol_destroy_mesh(q->fv, q->meshes[i]);
    fogvol_destroy_ramp(q->fv, q->ramp);
    fogvol_destroy_context(q->fv);
    free(q->thick);
    free(q->px);
}

static void test_overflow_sequence(void **state)
{
    static const int picks[] = {0, 1, 3, 5, 7}; /* PS20, +single, +count, PS13, MRT */
    glu_ctx g;
    int i;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (i = 0; i < (int)(sizeof picks / sizeof picks[0]); ++i) {
        ovseq q;
        char name[64];
        ovseq_open(&q, &g_combos[picks[i]], FOGVOL_OVERFLOW_COUNT_ONLY, &g, 0);
        g_blocking_reads = 0;
        snprintf(name, sizeof name, "overflow counts %s", q.c->name);
        sq_run(name, W, H, sq_default_script, SQ_DEFAULT_FRAMES,
               q.c->tier == FOGVOL_TIER_MRT ? SQ_CAMERA | SQ_OCCLUDER | SQ_CANCEL : SQ_ALL, ovseq_view, ovseq_cancel,
               &q);
        print_message("#   %d GPU counts checked against their frames' read-backs, %d differed\n", q.checked,
                      q.mismatched);
        assert_true(q.checked >= 4);
        assert_int_equal(g_blocking_reads, 0);
        ovseq_close(&q);
    }
    glu_destroy(&g);
}

/* LOWER_BITS over a sequence whose first two frames overflow (then as the default script: fitting
   frames, a split and a cancelled frame, overflowing ones): the first count lowers L once, from then
   on every frame (any camera, viewport, shells) is within the new encoding's bound, and the second
   frame's count, arriving after the change, does not lower it again. The lookup textures (ALU
   encode off) must follow L. */
static const sq_step g_lb_script[6] = {
    {{0.0, 0.0}, 1, 1, 0, 0},  {{0.5, 0.0}, 1, 1, 0, 0}, {{1.0, 0.0}, 0, 1, 1, 0},
    {{0.25, 0.75}, 1, 2, 0, 1}, {{0.0, 0.0}, 0, 1, 0, 1}, {{0.0, 0.0}, 1, 1, 0, 0},
};

static void test_lower_bits_sequence(void **state)
{
    glu_ctx g;
    ovseq q;
    int f;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    ovseq_open(&q, &g_combos[0], FOGVOL_OVERFLOW_LOWER_BITS, &g, FOGVOL_SPEEDUP_ALU);
    sq_run("LOWER_BITS PS20 (lookup textures)", W, H, g_lb_script, 6, SQ_ALL, ovseq_view, ovseq_cancel, &q);
    print_message("#   L lowered after fogvol frame %d; L per frame:", q.lowered_at);
    for (f = 0; f < 7; ++f) print_message(" %d", q.bits_at[f]);
    print_message("\n");
    assert_true(q.lowered_at >= 0 && q.lowered_at <= 2);
    assert_int_equal(fogvol_context_encoding(q.fv)->bits, 3);
    ovseq_close(&q);
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_OVERFLOW_BANDS over stills that change: the 20 shells, then 12 (no overflow), then
   20 again through a smaller viewport after a cancelled frame, 12 frames each; no show_overflow (bands
   on). Each band's count is replaced by its newest: after the 8 bands and the query latency, the
   count is the new still's read-back count, whatever the bands held before; in between it never
   exceeds the two stills' read-backs together (the bands partition the picture). Then with
   LOWER_BITS: the bands counted at the old L are forgotten when it changes, so it changes once and
   the count settles at 0 (20 shells fit at L = 3). */
static void test_bands_sequence(void **state)
{
    static const struct {
        int k, small;
    } stills[3] = {{20, 0}, {12, 0}, {20, 1}};
    glu_ctx g;
    ovseq q;
    int s, f, prev = 0, vp[4];
    fogvol_frame_stats st;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    ovseq_open(&q, &g_combos[0], FOGVOL_OVERFLOW_COUNT_ONLY, &g, 0);
    q.show = 0;
    for (s = 0; s < 3; ++s) {
        int rb = -1, last = -1;
        sq_viewport(W, H, stills[s].small, 1, 0, vp);
        if (s == 2) assert_int_equal(ovseq_frame(&q, 20, 1, vp, NULL, NULL, 1), FOGVOL_SUCCESS);
        for (f = 0; f < FOGVOL_OVERFLOW_BANDS + 4; ++f) {
            unsigned char px[4];
            ovseq_frame(&q, stills[s].k, 0, vp, f == 0 ? q.thick : NULL, &st, 0);
            if (f == 0) rb = st.overflow_pixels;
            glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
            assert_true(st.overflow_pixels_late <= rb + prev);
            last = st.overflow_pixels_late;
        }
        prev = rb;
        print_message("#   bands: still %d (%d shells%s): read-back %d saturated, the count after %d frames %d\n", s,
                      stills[s].k, stills[s].small ? ", smaller viewport" : "", rb, f, last);
        assert_int_equal(last, rb);
        if (stills[s].k == 20) assert_true(rb > 0);
        else assert_int_equal(rb, 0);
    }
    assert_int_equal(glGetError(), GL_NO_ERROR);
    ovseq_close(&q);
    ovseq_open(&q, &g_combos[0], FOGVOL_OVERFLOW_LOWER_BITS, &g, 0);
    q.show = 0;
    sq_viewport(W, H, 0, 1, 0, vp);
    for (f = 0; f < 2 * FOGVOL_OVERFLOW_BANDS + 4; ++f) {
        unsigned char px[4];
        ovseq_frame(&q, 20, 0, vp, NULL, &st, 0);
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    }
    print_message("#   bands with LOWER_BITS: L %d after %d frames, count %d (frame %lld)\n",
                  fogvol_context_encoding(q.fv)->bits, f, st.overflow_pixels_late, (long long)st.overflow_frame);
    assert_int_equal(fogvol_context_encoding(q.fv)->bits, 3);
    assert_int_equal(st.overflow_pixels_late, 0);
    ovseq_close(&q);
    glu_destroy(&g);
}

/* ---- the null backend: the plumbing ------------------------------------- */
typedef struct nullrig {
    fogvol_null_backend nb;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp;
    logcap lc;
} nullrig;

/* null_open: whole-picture checks, and the check kept: the rig's one tetrahedron is convex, whose sums
   cannot saturate (FOGVOL_SPEEDUP_SKIP_CHECK would leave out the pass these tests look at) */
#define NULL_OFF (FOGVOL_SPEEDUP_OVERFLOW_BANDS | FOGVOL_SPEEDUP_SKIP_CHECK)
static unsigned g_null_speedups_off = NULL_OFF;

static void null_open(nullrig *n, fogvol_tier tier, unsigned variants, unsigned caps, int queries,
                      fogvol_overflow_policy policy)
{
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    fogvol_context_desc cd;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    memset(n, 0, sizeof *n);
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&n->nb, &cd.backend);
    cd.backend.caps = caps;
    n->nb.queries = queries;
    cd.tier = tier;
    cd.variants = variants;
    cd.overflow_policy = policy;
    cd.disable_speedups = g_null_speedups_off;
    cd.logger.func = logger;
    cd.logger.user_data = &n->lc;
    assert_int_equal(fogvol_create_context(&cd, &n->fv), FOGVOL_SUCCESS);
    memset(&md, 0, sizeof md);
    md.positions = pos;
    md.vertex_count = 4;
    md.indices = idx;
    md.index_count = 12;
    assert_int_equal(fogvol_create_mesh(n->fv, &md, &n->mesh, NULL), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.density = 1;
    assert_int_equal(fogvol_create_ramp(n->fv, &rd, &n->ramp), FOGVOL_SUCCESS);
}

static int g_vp_x0, g_vp_y0; /* the viewport's origin in null_frame (0, 0 unless a test moves it) */

/* A frame looking down -z from the origin, near 0.5 and far 10, with a w x h viewport at (0, 0). */
static void frame_at(fogvol_frame_desc *fd, double fovy, int w, int h)
{
    memset(fd, 0, sizeof *fd);
    glu_identity(fd->view);
    glu_perspective(fd->projection, fovy, 1, 0.5, 10);
    fd->znear = 0.5f;
    fd->zfar = 10;
    fd->viewport[2] = w;
    fd->viewport[3] = h;
}

static fogvol_result null_frame(nullrig *n, int show_overflow, int volumes, fogvol_frame_stats *st)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    frame_at(&fd, 60, 16, 16);
    fd.viewport[0] = g_vp_x0;
    fd.viewport[1] = g_vp_y0;
    fd.show_overflow = show_overflow;
    assert_int_equal(fogvol_begin_frame(n->fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = n->mesh;
    vd.ramp = n->ramp;
    glu_translate_scale(vd.model, 0, 0, -3, 1);
    if (volumes) assert_int_equal(fogvol_add_volume(n->fv, &vd), FOGVOL_SUCCESS);
    return fogvol_end_frame(n->fv, st);
}

static void null_close(nullrig *n)
{
    fogvol_destroy_mesh(n->fv, n->mesh);
    fogvol_destroy_ramp(n->fv, n->ramp);
    fogvol_destroy_context(n->fv);
    assert_int_equal(n->nb.creates, n->nb.destroys);
    assert_int_equal(n->nb.query_active, 0);
}

/* Query results over time on the null backend. (a) A multisampled frame's check pass counts samples:
   12 saturated samples at 4 samples per pixel are reported as 3 pixels (as 12 at one sample).
   (b) Records read in the order of their frames: PS20, COUNT_ONLY, bands on; frame f's query counts
   10 (f + 1) samples, frame 2 checks the whole picture (show_overflow) and counts 500; the GPU answers
   frame 0's query at frame 2 and frames 1 and 2 at frame 3, where frame 2's record is the one frame 0
   left. Frame 3 reports 500 of frame 2, frame 4 the same. (Read in array order, frame 1's older band came
   last and frame 3 reported bands 0 + 1, 30, as frame 2's count.) */
static fogvol_backend g_q_inner;
static int g_q_frames;                 /* backend begin_frame calls */
static fogvol_handle g_q_handle[64];   /* each query begun, and the frame it was begun in */
static int g_q_frame[64], g_q_n;

static fogvol_result q_begin_frame(void *u, fogvol_frame_info *info)
{
    g_q_frames++;
    return g_q_inner.begin_frame(u, info);
}

static int q_begin_query(void *u, fogvol_handle q)
{
    int i;
    for (i = 0; i < g_q_n && g_q_handle[i] != q; ++i) {
    }
    if (i == g_q_n && g_q_n < 64) g_q_handle[g_q_n++] = q;
    if (i < 64) g_q_frame[i] = g_q_frames - 1;
    return g_q_inner.begin_query(u, q);
}

static int q_result(void *u, fogvol_handle q, uint64_t *samples)
{
    int i, f, now = g_q_frames - 1;
    (void)u;
    for (i = 0; i < g_q_n && g_q_handle[i] != q; ++i) {
    }
    if (i == g_q_n) return 0;
    f = g_q_frame[i];
    if (now < (f == 0 ? 2 : f <= 2 ? 3 : f + 2)) return 0; /* frame 0 at frame 2, frames 1 and 2 at frame 3 */
    *samples = f == 2 ? 500u : 10u * (uint64_t)(f + 1);
    return 1;
}

static void test_null_query_results_over_time(void **state)
{
    nullrig n;
    fogvol_frame_stats st;
    fogvol_context_desc cd;
    int f, ms;
    (void)state;
    for (ms = 0; ms < 2; ++ms) { /* (a) */
        null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MULTISAMPLE, 1,
                  FOGVOL_OVERFLOW_COUNT_ONLY);
        n.nb.samples = ms ? 4 : 0;
        n.nb.query_samples = 12;
        assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
        assert_int_equal(st.samples, ms ? 4 : 1);
        (void)null_frame(&n, 0, 1, &st); /* (FOGVOL_ERROR_DEPTH_OVERFLOW once the count is in) */
        assert_int_equal(st.overflow_frame, 0);
        assert_int_equal(st.overflow_pixels_late, ms ? 3 : 12);
        null_close(&n);
    }
    /* (b): the null backend's table, wrapped (its user_data: the null backend's state); bands on */
    memset(&n, 0, sizeof n);
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&n.nb, &g_q_inner);
    g_q_inner.caps = FOGVOL_CAP_HIGHP_FRAGMENT;
    n.nb.queries = 1;
    cd.backend = g_q_inner;
    cd.backend.begin_frame = q_begin_frame;
    cd.backend.begin_query = q_begin_query;
    cd.backend.query_result = q_result;
    cd.tier = FOGVOL_TIER_PS20;
    cd.overflow_policy = FOGVOL_OVERFLOW_COUNT_ONLY;
    cd.disable_speedups = FOGVOL_SPEEDUP_SKIP_CHECK;
    cd.logger.func = logger;
    cd.logger.user_data = &n.lc;
    g_q_frames = g_q_n = 0;
    assert_int_equal(fogvol_create_context(&cd, &n.fv), FOGVOL_SUCCESS);
    {
        static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
        static const uint32_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
        fogvol_mesh_desc md;
        fogvol_ramp_desc rd;
        memset(&md, 0, sizeof md);
        md.positions = pos;
        md.vertex_count = 4;
        md.indices = idx;
        md.index_count = 12;
        assert_int_equal(fogvol_create_mesh(n.fv, &md, &n.mesh, NULL), FOGVOL_SUCCESS);
        memset(&rd, 0, sizeof rd);
        rd.density = 0.5f;
        assert_int_equal(fogvol_create_ramp(n.fv, &rd, &n.ramp), FOGVOL_SUCCESS);
    }
    for (f = 0; f < 5; ++f) {
        (void)null_frame(&n, f == 2, 1, &st);
        print_message("# frame %d%s: overflow_pixels_late %d of frame %lld\n", f, f == 2 ? " (whole picture)" : "",
                      st.overflow_pixels_late, (long long)st.overflow_frame);
        if (f == 2) { /* frame 0's band 0 */
            assert_int_equal(st.overflow_pixels_late, 10);
            assert_int_equal(st.overflow_frame, 0);
        }
        if (f >= 3) {
            assert_int_equal(st.overflow_pixels_late, 500);
            assert_int_equal(st.overflow_frame, 2);
        }
    }
    null_close(&n);
}

/* A frame with more check passes than its record holds queries (40 ramp groups, 32 queries) is not
   counted, but the queries it began are in the GPU's work: its record waits for them like any other,
   so the next frames take other records and no query is begun again before its result is read (a
   Vulkan backend resets a query on the host when it begins it). The GPU never answers here: frames 1-3
   take the 3 other records, frame 4 finds none free and begins no query. (The record was reused at once:
   frame 1 began frame 0's queries again.) */
static int g_r_begun[64], g_r_frame_of[64], g_r_reused; /* per query handle: begun in which frame */
static int g_r_frame;
static int r_begin_query(void *u, fogvol_handle q)
{
    if (q < 64) {
        if (g_r_begun[q] && g_r_frame_of[q] != g_r_frame) g_r_reused++;
        g_r_begun[q] = 1;
        g_r_frame_of[q] = g_r_frame;
    }
    return g_q_inner.begin_query(u, q);
}

static void test_null_uncounted_frame_waits(void **state)
{
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramps[40];
    fogvol_frame_stats st;
    logcap lc;
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t idx[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    fogvol_mesh_desc md;
    int i, f;
    (void)state;
    memset(&lc, 0, sizeof lc);
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &g_q_inner);
    g_q_inner.caps = FOGVOL_CAP_HIGHP_FRAGMENT;
    nb.queries = 1;
    nb.query_not_ready = 1000000; /* the GPU never answers */
    cd.backend = g_q_inner;
    cd.backend.begin_query = r_begin_query;
    cd.tier = FOGVOL_TIER_PS20;
    cd.overflow_policy = FOGVOL_OVERFLOW_COUNT_ONLY;
    cd.disable_speedups = NULL_OFF;
    cd.logger.func = logger;
    cd.logger.user_data = &lc;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    memset(&md, 0, sizeof md);
    md.positions = pos;
    md.vertex_count = 4;
    md.indices = idx;
    md.index_count = 12;
    assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, NULL), FOGVOL_SUCCESS);
    for (i = 0; i < 40; ++i) {
        fogvol_ramp_desc rd;
        memset(&rd, 0, sizeof rd);
        rd.density = 0.1f + 0.01f * (float)i;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramps[i]), FOGVOL_SUCCESS);
    }
    memset(g_r_begun, 0, sizeof g_r_begun);
    g_r_reused = 0;
    for (f = 0; f < 6; ++f) {
        fogvol_frame_desc fd;
        fogvol_volume_desc vd;
        int begun = nb.queries_begun;
        g_r_frame = f;
        frame_at(&fd, 60, 16, 16);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        memset(&vd, 0, sizeof vd);
        vd.mesh = mesh;
        glu_translate_scale(vd.model, 0, 0, -3, 1);
        for (i = 0; i < (f == 0 ? 40 : 1); ++i) {
            vd.ramp = ramps[i];
            assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        }
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        print_message("# frame %d: %d check passes, %d queries begun\n", f, st.overflow_passes,
                      nb.queries_begun - begun);
        if (f == 0) assert_int_equal(nb.queries_begun - begun, 32);
        else if (f <= 3) assert_int_equal(nb.queries_begun - begun, 1);
        else assert_int_equal(nb.queries_begun - begun, 0); /* every record waits */
        assert_int_equal(st.overflow_pixels_late, -1);
    }
    assert_int_equal(g_r_reused, 0);
    for (i = 0; i < 40; ++i) fogvol_destroy_ramp(fv, ramps[i]);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    assert_int_equal(nb.creates, nb.destroys);
}

static void test_null_plumbing(void **state)
{
    nullrig n;
    fogvol_frame_stats st;
    int f;
    (void)state;
    /* PS20: one check pass per frame, bracketed by a query, after the sums, before the composite */
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_WARN_ONCE);
    n.nb.query_samples = 1234;
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.passes, 4);           /* O, B, F, composite: as before */
    assert_int_equal(st.overflow_passes, 1);  /* + the check */
    assert_int_equal(n.nb.pass_count, 5);
    assert_int_equal(n.nb.fullscreen[3], 1);
    assert_int_equal(n.nb.passes[3].blend, FOGVOL_PASS_BLEND_NONE);
    assert_true(n.nb.passes[3].target != 0);
    assert_int_equal(n.nb.passes[3].textures[0], n.nb.passes[1].target); /* reads B ... */
    assert_int_equal(n.nb.passes[3].textures[1], n.nb.passes[2].target); /* ... and F */
    assert_int_equal(n.nb.passes[4].target, 0);                          /* then the composite */
    { /* check and composite scissored to the volume's rectangle: window coordinates for the composite,
         fogvol's target (window - viewport origin) for the check; the tetrahedron at distance 3 covers
         part of the 16 x 16 view only */
        const int *cs = n.nb.passes[3].scissor, *ws = n.nb.passes[4].scissor;
        assert_int_equal(cs[0], ws[0]);
        assert_int_equal(cs[1], ws[1]);
        assert_int_equal(cs[2], ws[2]);
        assert_int_equal(cs[3], ws[3]);
        assert_true(ws[2] > 0 && ws[3] > 0 && ws[2] * ws[3] < 16 * 16);
        null_close(&n);
        g_vp_x0 = 5;
        g_vp_y0 = 3;
        null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_WARN_ONCE);
        assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
        g_vp_x0 = g_vp_y0 = 0;
        assert_int_equal(cs[0], ws[0] - 5);
        assert_int_equal(cs[1], ws[1] - 3);
        assert_int_equal(cs[2], ws[2]);
        assert_int_equal(cs[3], ws[3]);
        assert_true(ws[0] >= 5 && ws[1] >= 3 && ws[0] + ws[2] <= 21 && ws[1] + ws[3] <= 19);
        null_close(&n);
        null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_WARN_ONCE);
        n.nb.query_samples = 1234;
        assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    }
    assert_int_equal(n.nb.queries_begun, 1);
    assert_int_equal(n.nb.queries_ended, 1);
    assert_int_equal(st.overflow_pixels_late, -1);
    assert_int_equal(st.overflow_frame, -1);
    assert_int_equal(n.lc.warnings, 0);
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.frame, 1);
    assert_int_equal(st.overflow_pixels_late, 1234); /* frame 0's count, read in frame 1 */
    assert_int_equal(st.overflow_frame, 0);
    assert_int_equal(n.lc.warnings, 1);
    /* the GPU lags: polls answer "not yet", nothing waits, the count comes when it is there */
    n.nb.query_not_ready = 3;
    n.nb.query_samples = 7;
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_frame, 0); /* frame 1 not ready yet: still frame 0's */
    assert_int_equal(st.overflow_pixels_late, 1234);
    for (f = 0; f < 3 && st.overflow_frame < 2; ++f) null_frame(&n, 0, 1, &st);
    assert_true(st.overflow_frame >= 2);
    assert_int_equal(st.overflow_pixels_late, 7);
    assert_int_equal(n.lc.warnings, 1); /* once */
    /* a frame without volumes counts 0 at once */
    n.nb.query_samples = 0;
    assert_int_equal(null_frame(&n, 0, 0, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_passes, 0);
    assert_int_equal(st.overflow_frame, st.frame);
    assert_int_equal(st.overflow_pixels_late, 0);
    /* the GPU more than four frames behind: frames go uncounted, none waits */
    n.nb.query_not_ready = 1000;
    for (f = 0; f < 8; ++f) assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_true(n.nb.queries_begun - n.nb.queries_ended == 0);
    n.nb.query_not_ready = 0;
    null_frame(&n, 0, 1, &st);
    null_frame(&n, 0, 1, &st);
    assert_true(st.overflow_frame > 5);
    null_close(&n);

    /* SINGLE_TARGET: a check after the additions (clears the mask, depth-tested) and one after the
       subtractions; the composite reads the mask as its second texture */
    null_open(&n, FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, FOGVOL_CAP_HIGHP_FRAGMENT, 1,
              FOGVOL_OVERFLOW_WARN_ONCE);
    assert_int_equal(null_frame(&n, 1, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.passes, 4);
    assert_int_equal(st.overflow_passes, 2);
    assert_int_equal(n.nb.pass_count, 6); /* O, S+, check, S-, check, composite */
    assert_int_equal(n.nb.passes[2].clear, 1);
    assert_int_equal(n.nb.passes[2].depth_test, 1);
    assert_int_equal(n.nb.passes[2].depth_write, 1);
    assert_int_equal(n.nb.passes[2].textures[0], n.nb.passes[1].target);
    assert_int_equal(n.nb.passes[3].blend, FOGVOL_PASS_BLEND_SUBTRACT);
    assert_int_equal(n.nb.passes[4].clear, 0);
    assert_int_equal(n.nb.passes[4].target, n.nb.passes[2].target);
    assert_int_equal(n.nb.passes[5].textures[1], n.nb.passes[2].target);
    assert_int_equal(n.nb.queries_begun, 2);
    null_close(&n);

    /* no queries (the default null backend): the single-target peak check still runs for
       show_overflow, nothing is counted */
    null_open(&n, FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, FOGVOL_CAP_HIGHP_FRAGMENT, 0,
              FOGVOL_OVERFLOW_WARN_ONCE);
    assert_int_equal(null_frame(&n, 1, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_passes, 1);
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_passes, 0);
    assert_int_equal(st.overflow_pixels_late, -1);
    assert_int_equal(n.nb.queries_begun, 0);
    null_close(&n);

    /* OFF: no check pass, no query even with queries */
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_OFF);
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_passes, 0);
    assert_int_equal(n.nb.pass_count, 3); /* B, F, composite: O (no occluder) still the far plane of frame 0 */
    assert_int_equal(st.overflow_pixels_late, -1);
    assert_int_equal(n.nb.create_calls, n.nb.creates); /* no query was even created */
    null_close(&n);

    /* FLOAT cannot overflow: 0, for this very frame, with no check pass */
    null_open(&n, FOGVOL_TIER_FLOAT, 0, FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_FLOAT_BLEND, 1,
              FOGVOL_OVERFLOW_WARN_ONCE);
    assert_int_equal(null_frame(&n, 1, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.overflow_passes, 0);
    assert_int_equal(st.overflow_pixels_late, 0);
    assert_int_equal(st.overflow_frame, st.frame);
    assert_int_equal(n.nb.queries_begun, 0);
    null_close(&n);

    /* LOWER_BITS on the null backend: L 4 -> 3 -> 2 -> 1 as counts keep coming, then a warning */
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_LOWER_BITS);
    n.nb.query_samples = 5;
    for (f = 0; f < 12; ++f) null_frame(&n, 0, 1, &st);
    assert_int_equal(fogvol_context_encoding(n.fv)->bits, 1);
    /* three lowerings, then "cannot" once, and once that the digits step by more than 1/16 of the
       volume's depth (fogvol_frame_stats.depth_lsb) */
    assert_int_equal(n.lc.warnings, 5);
    null_close(&n);
}

/* The bands on the null backend: frame f checks band f mod 8 of the composite's rectangle (rows
   [h b / 8, h (b + 1) / 8), the same columns); the 8 bands tile it; the count is the sum of each
   band's newest count; a band without rows draws no check pass and counts 0; show_overflow checks
   the whole rectangle; lowering L forgets the bands counted before. */
static void test_null_bands(void **state)
{
    nullrig n;
    fogvol_frame_stats st;
    int f, rows = 0, nonempty = 0, ws[4];
    (void)state;
    g_null_speedups_off = FOGVOL_SPEEDUP_SKIP_CHECK;
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_COUNT_ONLY);
    n.nb.query_samples = 3;
    for (f = 0; f < FOGVOL_OVERFLOW_BANDS; ++f) {
        const fogvol_pass *check, *comp;
        int y0, y1;
        assert_int_equal(null_frame(&n, 0, 1, &st), FOGVOL_SUCCESS);
        comp = &n.nb.passes[n.nb.pass_count - 1];
        memcpy(ws, comp->scissor, sizeof ws);
        assert_true(ws[2] > 0 && ws[3] > 0);
        y0 = ws[3] * f / FOGVOL_OVERFLOW_BANDS;
        y1 = ws[3] * (f + 1) / FOGVOL_OVERFLOW_BANDS;
        assert_int_equal(st.overflow_passes, y1 > y0);
        if (y1 == y0) continue;
        check = &n.nb.passes[n.nb.pass_count - 2];
        assert_int_equal(check->blend, FOGVOL_PASS_BLEND_NONE);
        assert_int_equal(check->scissor[0], ws[0]);
        assert_int_equal(check->scissor[1], ws[1] + y0);
        assert_int_equal(check->scissor[2], ws[2]);
        assert_int_equal(check->scissor[3], y1 - y0);
        rows += y1 - y0;
        nonempty++;
    }
    assert_int_equal(rows, ws[3]); /* the bands tile the rectangle */
    null_frame(&n, 0, 1, &st);    /* reads frame 7's query */
    print_message("  null bands: rectangle %d x %d, %d bands with rows, count %d\n", ws[2], ws[3], nonempty,
                  st.overflow_pixels_late);
    assert_int_equal(st.overflow_frame, FOGVOL_OVERFLOW_BANDS - 1);
    assert_int_equal(st.overflow_pixels_late, 3 * nonempty);
    n.nb.query_samples = 10; /* band 0 again (frame 8): its count replaces the old one */
    null_frame(&n, 0, 1, &st);
    assert_int_equal(st.overflow_frame, FOGVOL_OVERFLOW_BANDS);
    assert_int_equal(st.overflow_pixels_late, 3 * nonempty + (ws[3] / FOGVOL_OVERFLOW_BANDS > 0 ? 7 : 0));
    /* show_overflow: the whole rectangle, counted as such */
    assert_int_equal(null_frame(&n, 1, 1, &st), FOGVOL_SUCCESS);
    assert_int_equal(memcmp(n.nb.passes[n.nb.pass_count - 2].scissor, ws, sizeof ws), 0);
    null_frame(&n, 0, 1, &st);
    assert_int_equal(st.overflow_pixels_late, 10);
    null_close(&n);

    /* LOWER_BITS: a count lowers L once; the bands counted before it, and the band of the frame
       drawn with the old L whose count arrives after the change, do not lower it again */
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_LOWER_BITS);
    n.nb.query_samples = 5;
    null_frame(&n, 0, 1, &st); /* frame 0 */
    null_frame(&n, 0, 1, &st); /* frame 1 reads frame 0's 5: L 4 -> 3 from frame 2 on */
    assert_int_equal(fogvol_context_encoding(n.fv)->bits, 3);
    null_frame(&n, 0, 1, &st); /* frame 2 reads frame 1's 5, drawn at L = 4: not kept */
    assert_int_equal(fogvol_context_encoding(n.fv)->bits, 3);
    n.nb.query_samples = 0;
    for (f = 0; f < 2 * FOGVOL_OVERFLOW_BANDS; ++f) null_frame(&n, 0, 1, &st);
    assert_int_equal(fogvol_context_encoding(n.fv)->bits, 3);
    assert_int_equal(st.overflow_pixels_late, 0);
    null_close(&n);
    g_null_speedups_off = NULL_OFF;
}

/* FOGVOL_SPEEDUP_SKIP_CHECK: a group whose sums cannot saturate draws no check pass. On the null
   backend (whole-picture checks): one convex tetrahedron, and 8 of them (at most one back and one
   front face each on a ray; half the 16 faces L = 4 sums, a margin for meshes convex within the
   convexity test's tolerance), skip it and count 0 at once, the check's program and mask not made
   until a frame checks; 9 of them, a concave torus, NEAR_CLAMP (faces folded onto the
   near plane) and the speed-up switched off draw it. In GL (PS20 on OSMesa, L = 6: 4 faces a
   target), 2 overlapping spheres skip it and the debug read-back finds no saturated pixel, with the
   pixels of the frame that checks; 3 spheres check. */
static int skip_frame(nullrig *n, const fogvol_mesh *mesh, int volumes, fogvol_frame_stats *st)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    int i;
    frame_at(&fd, 60, 16, 16);
    assert_int_equal(fogvol_begin_frame(n->fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = mesh;
    vd.ramp = n->ramp;
    for (i = 0; i < volumes; ++i) {
        glu_translate_scale(vd.model, 0.01f * (float)i, 0, -3, 1);
        assert_int_equal(fogvol_add_volume(n->fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(n->fv, st), FOGVOL_SUCCESS);
    return st->overflow_passes;
}

static void gl_spheres(int k, unsigned off, unsigned char *px, float *thick, fogvol_frame_stats *st)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *m;
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    shp_mesh sph = shp_sphere(0.7f, 32, 16);
    int i;
    assert_true(glu_create(&g, W, H, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_PS20;
    cd.encoding_bits = 6;
    cd.disable_speedups = FOGVOL_SPEEDUP_OVERFLOW_BANDS | FOGVOL_SPEEDUP_EXACT_SUM | off;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    fx_mesh_desc(&md, &sph, 0);
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.convex, 1);
    memset(&rd, 0, sizeof rd);
    rd.density = 0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    frame_at(&fd, 50, W, H);
    fd.debug_thickness = thick;
    glClearColor(0.2f, 0.3f, 0.4f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = m;
    vd.ramp = ramp;
    for (i = 0; i < k; ++i) { /* overlapping along x, every pixel of the middle crosses all k */
        glu_translate_scale(vd.model, 0.25f * (float)i - 0.125f * (float)(k - 1), 0, -4, 1);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(fv, st), FOGVOL_SUCCESS);
    memcpy(px, glu_pixels(&g), (size_t)W * H * 4);
    fogvol_destroy_mesh(fv, m);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    shp_free(&sph);
    glu_destroy(&g);
}

static void test_skip_check(void **state)
{
    nullrig n;
    fogvol_frame_stats st;
    fogvol_mesh *torus;
    fogvol_mesh_desc md;
    shp_mesh tor = shp_torus(1.0f, 0.4f, 16, 8);
    unsigned char *px[2];
    float *thick[2];
    int k, i, fogged, creates;
    (void)state;
    g_null_speedups_off = FOGVOL_SPEEDUP_OVERFLOW_BANDS;
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_COUNT_ONLY);
    n.nb.query_samples = 7;
    assert_int_equal(skip_frame(&n, n.mesh, 1, &st), 0);
    assert_int_equal(st.overflow_pixels_late, 0); /* counted at once: nothing to wait for */
    assert_int_equal(st.overflow_frame, 0);
    creates = n.nb.creates;
    assert_int_equal(skip_frame(&n, n.mesh, 8, &st), 0);
    assert_int_equal(n.nb.creates, creates); /* no check program or mask while every group skips */
    assert_int_equal(skip_frame(&n, n.mesh, 9, &st), 1);
    assert_true(n.nb.creates >= creates + 2); /* made by the first check */
    fx_mesh_desc(&md, &tor, 0);
    assert_int_equal(fogvol_create_mesh(n.fv, &md, &torus, NULL), FOGVOL_SUCCESS);
    assert_int_equal(skip_frame(&n, torus, 1, &st), 1);
    assert_int_equal(skip_frame(&n, n.mesh, 1, &st), 0);
    fogvol_destroy_mesh(n.fv, torus);
    null_close(&n);
    null_open(&n, FOGVOL_TIER_PS20, FOGVOL_VARIANT_NEAR_CLAMP, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_COUNT_ONLY);
    assert_int_equal(skip_frame(&n, n.mesh, 1, &st), 1);
    null_close(&n);
    g_null_speedups_off = FOGVOL_SPEEDUP_OVERFLOW_BANDS | FOGVOL_SPEEDUP_SKIP_CHECK;
    null_open(&n, FOGVOL_TIER_PS20, 0, FOGVOL_CAP_HIGHP_FRAGMENT, 1, FOGVOL_OVERFLOW_COUNT_ONLY);
    assert_int_equal(skip_frame(&n, n.mesh, 1, &st), 1);
    null_close(&n);
    g_null_speedups_off = NULL_OFF;
    shp_free(&tor);
    for (k = 0; k < 2; ++k) {
        px[k] = (unsigned char *)malloc((size_t)W * H * 4);
        thick[k] = (float *)malloc((size_t)W * H * sizeof(float));
    }
    gl_spheres(2, 0, px[0], thick[0], &st);
    assert_int_equal(st.overflow_passes, 0);
    assert_int_equal(st.overflow_pixels, 0); /* the debug read-back: no saturated channel */
    gl_spheres(2, FOGVOL_SPEEDUP_SKIP_CHECK, px[1], thick[1], &st);
    assert_int_equal(st.overflow_passes, 1);
    assert_int_equal(st.overflow_pixels, 0);
    assert_memory_equal(px[0], px[1], (size_t)W * H * 4);
    assert_memory_equal(thick[0], thick[1], (size_t)W * H * sizeof(float));
    for (i = 0, fogged = 0; i < W * H; ++i) fogged += thick[0][i] > 0.0f;
    assert_true(fogged > W * H / 8);
    gl_spheres(3, 0, px[1], thick[1], &st);
    assert_int_equal(st.overflow_passes, 1);
    print_message("  skip check: 1 and 8 convex volumes skip it, 9, a torus and NEAR_CLAMP check; 2 spheres at "
                  "L = 6 skip it (%d fogged pixels, none saturated), 3 check\n", fogged);
    for (k = 0; k < 2; ++k) {
        free(px[k]);
        free(thick[k]);
    }
}

static void test_bad_policy(void **state)
{
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    logcap lc;
    (void)state;
    memset(&lc, 0, sizeof lc);
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    cd.logger.func = logger;
    cd.logger.user_data = &lc;
    cd.overflow_policy = (fogvol_overflow_policy)7;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv);
    assert_int_equal(lc.errors, 1);
    assert_int_equal(nb.creates, 0);
}

int main(void)
{
    static int params[NCOMBO * 3][2];
    static struct CMUnitTest tests[NCOMBO * 3 + 24]; /* zeroed: the unused entries are skipped */
    int n = 0, i, j, fails;
    char *names[NCOMBO * 3];
    build_scenes(); /* scenes.h keeps its scenes; the shells are added after them */
    assert_int_equal(scene_index("sphere"), 0);
    for (i = 0; i < NCOMBO; ++i)
        for (j = 0; j < 3; ++j) {
            params[n][0] = i;
            params[n][1] = j;
            names[n] = (char *)malloc(64);
            snprintf(names[n], 64, "%s_%d_shells%s", g_combos[i].name, g_combos[i].k[j == 1], j == 2 ? "_near" : "");
            memset(&tests[n], 0, sizeof tests[n]);
            tests[n].name = names[n];
            tests[n].test_func = test_combo;
            tests[n].initial_state = params[n];
            ++n;
        }
    {
        const struct CMUnitTest more[] = {
            cmocka_unit_test(test_null_plumbing),   cmocka_unit_test(test_null_bands),
            cmocka_unit_test(test_bands),           cmocka_unit_test(test_bad_policy),
            cmocka_unit_test(test_skip_check),
            cmocka_unit_test(test_lower_bits), cmocka_unit_test(test_exact_sum), cmocka_unit_test(test_warn_once),
            cmocka_unit_test(test_engine_query_active), cmocka_unit_test(test_gles3_any_samples),
            cmocka_unit_test(test_overflow_sequence), cmocka_unit_test(test_lower_bits_sequence),
            cmocka_unit_test(test_bands_sequence), cmocka_unit_test(test_show_overflow_msaa), cmocka_unit_test(test_null_query_results_over_time), cmocka_unit_test(test_null_uncounted_frame_waits),
        };
        for (i = 0; i < (int)(sizeof more / sizeof more[0]); ++i) {
            if (n >= (int)(sizeof tests / sizeof tests[0])) {
                fprintf(stderr, "test_overflow: the test table is too small\n");
                return 1;
            }
            tests[n++] = more[i];
        }
    }
    if (getenv("FV_TEST_FILTER")) cmocka_set_test_filter(getenv("FV_TEST_FILTER")); /* e.g. "*sequence*" */
    fails = cmocka_run_group_tests_name("overflow", tests, NULL, NULL);
    for (i = 0; i < NCOMBO * 3; ++i) free(names[i]);
    for (i = 0; i < NTRUTH; ++i) {
        free(g_truth[i].gt);
        free(g_truth[i].pairs);
        free(g_truth[i].interior);
        free(g_truth[i].covered);
    }
    free_view_truths();
    free_scenes();
    return fails;
}
