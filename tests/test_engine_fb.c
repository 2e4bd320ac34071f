/* test_engine_fb.c - fogvol inside an engine's framebuffer and GL state (issue 10,
   "the engine's framebuffer"), under OSMesa: GL 4.5 core, 4.5 compatibility, and a
   compatibility context treated as GL 2.1 where the item exists there.

   Ground truth is independent of fogvol: thickness ray-cast from the very
   triangles drawn (tests/raycast.h; error in LSBs of the 12-bit encoding over
   interior pixels, bound 1 LSB per pair of faces), the engine's buffers and state
   read back before and after (byte-identical), and blend results computed by hand
   from the GL blend equations and the sRGB transfer functions.

   Cases:
   - several draw buffers (4 colour attachments): only the named one changes, and
     it ends up exactly as on a one-attachment FBO with the same contents; the
     draw-buffer list and per-buffer blend/mask state come back; refusals logged;
   - the geometry composite leaves every stencil bit alone and writes the same
     bytes as the full-screen composite (several scenes);
   - engine state left set (primitive restart with a > 65535-vertex mesh, clip
     distances, depth clamp, sample shading, sample mask, polygon smooth and
     stipple, transform feedback): right thickness, state unchanged;
   - pending engine GL errors survive end_frame (every frame), create_mesh,
     create_ramp, context creation and the debug read-back;
   - alpha: kept, or written as coverage a + dst.a (1 - a);
   - sRGB: an SRGB8_ALPHA8 target with FRAMEBUFFER_SRGB blends in linear light;
     fogvol's own RGBA8 and R32F targets are unaffected by FRAMEBUFFER_SRGB.
   The image of the 4-attachment case goes to build/engine_fb/. */
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
#include "tests/fixtures.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define W 96
#define H 96
#define NPIX (W * H)
#define ZN 1.0
#define ZF 21.0
#define LSB ((ZF - ZN) / 4096.0) /* 4 bits per channel: 12-bit encoding */
#define MAXOBJ 4

/* ---- logger ---------------------------------------------------------------- */
typedef struct logc {
    int errors, warnings;
    char last[512];
} logc;

static void logger(void *u, fogvol_log_level l, const char *m)
{
    logc *c = (logc *)u;
    if (l == FOGVOL_LOG_ERROR) c->errors++;
    if (l == FOGVOL_LOG_WARNING) c->warnings++;
    if (l <= FOGVOL_LOG_WARNING && !c->last[0]) snprintf(c->last, sizeof c->last, "%s", m); /* the first */
}

/* ---- an engine: GL context, fogvol context, camera, objects --------------- */
typedef struct obj {
    shp_mesh mesh;
    float model[16];
    int sign;
    int ramp; /* index into eng.ramp */
    fogvol_mesh *m;
} obj;

typedef struct eng {
    glu_ctx g;
    fogvol_context *fv;
    logc lc;
    rc_camera cam;
    obj o[MAXOBJ];
    int n;
    fogvol_ramp *ramp[2];
    int core, v21, es30, v33;
} eng;

/* PROF_ES30: the core context treated as OpenGL ES 3.0 (fogvol_gl_desc.gles). PROF_33: treated as
   GL 3.3 core, where per-buffer blending and transform feedback pause are the extensions
   ARB_draw_buffers_blend and ARB_transform_feedback2 (a driver may give exactly the 3.3 asked for). */
enum { PROF_CORE = 0, PROF_COMPAT = 1, PROF_21 = 2, PROF_ES30 = 3, PROF_33 = 4 };

/* glGetError that first returns a code the test queues (errors GL cannot raise on demand). */
static GLenum g_fake_error;
static GLenum APIENTRY fake_get_error(void)
{
    GLenum e = g_fake_error;
    g_fake_error = GL_NO_ERROR;
    return e != GL_NO_ERROR ? e : glGetError();
}
/* glDrawArrays that raises a GL error the test queues after drawing (fogvol's own call failing). */
static GLenum g_draw_error;
static void APIENTRY fake_draw_arrays(GLenum mode, GLint first, GLsizei count)
{
    glDrawArrays(mode, first, count);
    if (g_draw_error == GL_INVALID_ENUM) glBindTexture(0x1234, 0);
    g_draw_error = GL_NO_ERROR;
}
static void (*fake_proc(const char *name, void *user))(void)
{
    if (strcmp(name, "glGetError") == 0) return (void (*)(void))fake_get_error;
    if (strcmp(name, "glDrawArrays") == 0) return (void (*)(void))fake_draw_arrays;
    return glu_proc(name, user);
}

/* The engine's KHR_debug callback: GL_DEBUG_TYPE_ERROR messages counted (the last kept). */
static int g_dbg_errors;
static char g_dbg_last[256];
static void APIENTRY debug_cb(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                              const GLchar *message, const void *user)
{
    (void)source;
    (void)id;
    (void)severity;
    (void)length;
    (void)user;
    if (type != GL_DEBUG_TYPE_ERROR) return;
    g_dbg_errors++;
    snprintf(g_dbg_last, sizeof g_dbg_last, "%s", message);
}
static void debug_on(void)
{
    glEnable(GL_DEBUG_OUTPUT);
    glDebugMessageCallback(debug_cb, NULL);
    g_dbg_errors = 0;
}
static void no_debug_errors(const char *after)
{
    if (g_dbg_errors) fail_msg("%s: %d KHR_debug error messages reached the engine's callback, the last: %s", after,
                               g_dbg_errors, g_dbg_last);
}
static unsigned g_variants; /* fogvol_context_desc.variants of make_fogvol */

static fogvol_result make_fogvol(eng *e, fogvol_tier tier)
{
    fogvol_context_desc cd;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = fake_proc;
    cd.logger.func = logger;
    cd.logger.user_data = &e->lc;
    cd.tier = tier;
    cd.variants = g_variants;
    cd.disable_dither = 1;
    if (e->v21) {
        cd.gl.version_major = 2;
        cd.gl.version_minor = 1;
    }
    if (e->es30) {
        cd.gl.version_major = 3;
        cd.gl.gles = 1;
    }
    if (e->v33) {
        cd.gl.version_major = 3;
        cd.gl.version_minor = 3;
    }
    return fogvol_create_context(&cd, &e->fv);
}

static void make_ramp(eng *e, int i, const float rgba[4])
{
    fogvol_ramp_desc rd;
    fogvol_color_key k[2];
    memset(&rd, 0, sizeof rd);
    if (rgba) { /* constant colour and alpha at every thickness > 0 */
        memset(k, 0, sizeof k);
        k[0].thickness = 0.0f;
        k[1].thickness = 10.0f;
        memcpy(k[0].rgba, rgba, sizeof k[0].rgba);
        memcpy(k[1].rgba, rgba, sizeof k[1].rgba);
        rd.model = FOGVOL_RAMP_GRADIENT;
        rd.keys = k;
        rd.key_count = 2;
    } else {
        rd.color[0] = i ? 0.3f : 0.9f;
        rd.color[1] = 0.6f;
        rd.color[2] = i ? 0.9f : 0.3f;
        rd.density = 0.5f;
    }
    assert_int_equal(fogvol_create_ramp(e->fv, &rd, &e->ramp[i]), FOGVOL_SUCCESS);
}

static void eng_open(eng *e, int prof, fogvol_tier tier)
{
    memset(e, 0, sizeof *e);
    e->core = prof == PROF_CORE || prof == PROF_ES30 || prof == PROF_33;
    e->v21 = prof == PROF_21;
    e->es30 = prof == PROF_ES30;
    e->v33 = prof == PROF_33;
    assert_true(glu_create(&e->g, W, H, e->core));
    e->cam.eye[2] = 6.0;
    e->cam.up[1] = 1.0;
    e->cam.fovy_deg = 50.0;
    e->cam.aspect = 1.0;
    e->cam.znear = ZN;
    e->cam.zfar = ZF;
    e->cam.width = W;
    e->cam.height = H;
    assert_int_equal(make_fogvol(e, tier), FOGVOL_SUCCESS);
    make_ramp(e, 0, NULL);
    make_ramp(e, 1, NULL);
}

static void add_obj(eng *e, shp_mesh m, float tx, float ty, float tz, float s, int sign, int ramp)
{
    obj *o = &e->o[e->n++];
    fogvol_mesh_desc md;
    o->mesh = m;
    o->sign = sign;
    o->ramp = ramp;
    glu_translate_scale(o->model, tx, ty, tz, s);
    fx_mesh_desc(&md, &m, 0);
    assert_int_equal(fogvol_create_mesh(e->fv, &md, &o->m, NULL), FOGVOL_SUCCESS);
}

static void eng_close(eng *e)
{
    int i;
    for (i = 0; i < e->n; ++i) {
        fogvol_destroy_mesh(e->fv, e->o[i].m);
        shp_free(&e->o[i].mesh);
    }
    fogvol_destroy_ramp(e->fv, e->ramp[0]);
    fogvol_destroy_ramp(e->fv, e->ramp[1]);
    fogvol_destroy_context(e->fv);
    glu_destroy(&e->g);
}

static void frame_desc(const eng *e, fogvol_frame_desc *fd)
{
    memset(fd, 0, sizeof *fd);
    rc_camera_matrices(&e->cam, fd->view, fd->projection);
    fd->znear = (float)ZN;
    fd->zfar = (float)ZF;
    fd->viewport[2] = W;
    fd->viewport[3] = H;
}

/* One frame of every object; thick (may be NULL) receives ramp 0's thickness. */
static fogvol_result run(eng *e, fogvol_frame_desc *fd, float *thick)
{
    int i;
    fd->debug_thickness = thick;
    fd->debug_ramp = e->ramp[0];
    assert_int_equal(fogvol_begin_frame(e->fv, fd), FOGVOL_SUCCESS);
    for (i = 0; i < e->n; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = e->o[i].m;
        vd.ramp = e->ramp[e->o[i].ramp];
        vd.negative = e->o[i].sign < 0;
        memcpy(vd.model, e->o[i].model, sizeof vd.model);
        assert_int_equal(fogvol_add_volume(e->fv, &vd), FOGVOL_SUCCESS);
    }
    return fogvol_end_frame(e->fv, NULL);
}

/* Ray-cast truth of ramp 0's volumes, the interior mask, and pairs of faces crossed (>= 1) in interior[] as
   1 + pairs when pairs is set. */
static void truth_pairs(const eng *e, double *gt, unsigned char *interior, int pairs)
{
    rc_object ro[MAXOBJ];
    rc_scene rs;
    int i, k = 0, x, y;
    for (i = 0; i < e->n; ++i) {
        if (e->o[i].ramp != 0) continue;
        ro[k].pos = e->o[i].mesh.pos;
        ro[k].vcount = e->o[i].mesh.vcount;
        ro[k].idx = e->o[i].mesh.idx;
        ro[k].icount = e->o[i].mesh.icount;
        memcpy(ro[k].model, e->o[i].model, sizeof ro[k].model);
        ro[k].sign = e->o[i].sign;
        ++k;
    }
    assert_true(rc_scene_init(&rs, ro, k));
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            rc_result r = rc_trace(&rs, &e->cam, x + 0.5, y + 0.5);
            int np = r.faces_front > r.faces_back ? r.faces_front : r.faces_back;
            gt[y * W + x] = r.thickness;
            interior[y * W + x] = (unsigned char)rc_interior(&rs, &e->cam, x, y);
            if (pairs && interior[y * W + x]) interior[y * W + x] = (unsigned char)(np > 1 ? np : 1);
        }
    rc_scene_free(&rs);
}

static void truth(const eng *e, double *gt, unsigned char *interior) { truth_pairs(e, gt, interior, 0); }

/* Max |thickness error| per pair of faces over interior pixels (pairs[i] > 0), in LSB of the 12-bit
   encoding. */
static double max_err(const float *thick, const double *gt, const unsigned char *pairs, int *fogged)
{
    double m = 0;
    int i;
    *fogged = 0;
    for (i = 0; i < NPIX; ++i) {
        double e;
        if (!pairs[i]) continue;
        e = fabs(thick[i] - gt[i]) / LSB / pairs[i];
        if (e > m) m = e;
        if (gt[i] > 0.05) (*fogged)++;
    }
    return m;
}

/* Render and check the thickness of ramp 0 against the ray cast (1 pair of faces per volume here). */
static double check_thickness(eng *e, fogvol_frame_desc *fd, double bound, const char *what)
{
    float *thick = (float *)calloc(NPIX, sizeof(float));
    double *gt = (double *)calloc(NPIX, sizeof(double));
    unsigned char *in = (unsigned char *)calloc(NPIX, 1);
    double err;
    int fogged;
    assert_int_equal(run(e, fd, thick), FOGVOL_SUCCESS);
    truth_pairs(e, gt, in, 1);
    err = max_err(thick, gt, in, &fogged);
    print_message("# %-40s max thickness error %.3f LSB/pair over %d fogged interior pixels\n", what, err, fogged);
    assert_true(fogged > 500);
    if (err > bound) fail_msg("%s: thickness error %.3f LSB > %.1f", what, err, bound);
    free(thick);
    free(gt);
    free(in);
    return err;
}

/* ---- an engine FBO: n colour textures + depth-stencil renderbuffer -------- */
typedef struct efbo {
    GLuint fbo, tex[4], ds;
    int n;
} efbo;

static void efbo_make(efbo *f, int n, GLenum fmt)
{
    int i;
    memset(f, 0, sizeof *f);
    f->n = n;
    glGenFramebuffers(1, &f->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    glGenTextures(n, f->tex);
    for (i = 0; i < n; ++i) {
        glBindTexture(GL_TEXTURE_2D, f->tex[i]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexImage2D(GL_TEXTURE_2D, 0, (GLint)fmt, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, f->tex[i], 0);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenRenderbuffers(1, &f->ds);
    glBindRenderbuffer(GL_RENDERBUFFER, f->ds);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, W, H);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, f->ds);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
}

static void efbo_free(efbo *f)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &f->fbo);
    glDeleteTextures(f->n, f->tex);
    glDeleteRenderbuffers(1, &f->ds);
}

/* Pseudo-random bytes (alpha included) into attachment i. */
static void tex_fill(GLuint tex, unsigned seed)
{
    unsigned char *p = (unsigned char *)malloc(NPIX * 4);
    int i;
    for (i = 0; i < NPIX * 4; ++i) {
        seed = seed * 1103515245u + 12345u;
        p[i] = (unsigned char)(seed >> 16);
    }
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, p);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(p);
}

static void tex_read(GLuint tex, unsigned char *out)
{
    GLint pb = 0;
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &pb);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glBindTexture(GL_TEXTURE_2D, tex);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, out);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, (GLuint)pb);
}

static int count_diff(const unsigned char *a, const unsigned char *b)
{
    int i, n = 0;
    for (i = 0; i < NPIX; ++i) n += memcmp(a + 4 * i, b + 4 * i, 4) != 0;
    return n;
}

/* ---- state snapshot of what this part of fogvol saves -------------------- */
typedef struct snap {
    GLint draw_buffers[8], fbo, restart_index;
    GLint bf[8][6];
    GLboolean mask[8][4], blend[8];
    GLboolean en[16];
    GLfloat min_sample_shading;
    GLint sample_mask_value;
    GLboolean tf_active, tf_paused;
    GLint viewport[4], scissor[4];
    GLboolean scissor_on;
} snap;

static void take_snap(const eng *e, snap *s)
{
    static const GLenum caps[] = {GL_PRIMITIVE_RESTART, GL_PRIMITIVE_RESTART_FIXED_INDEX, GL_DEPTH_CLAMP,
                                  GL_SAMPLE_SHADING, GL_SAMPLE_MASK, GL_POLYGON_SMOOTH, GL_FRAMEBUFFER_SRGB,
                                  GL_CLIP_DISTANCE0, GL_CLIP_DISTANCE1, GL_CLIP_DISTANCE2, GL_CLIP_DISTANCE3,
                                  GL_CLIP_DISTANCE4, GL_CLIP_DISTANCE5, GL_CLIP_DISTANCE6, GL_CLIP_DISTANCE7,
                                  GL_POLYGON_STIPPLE};
    int i;
    memset(s, 0, sizeof *s);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s->fbo);
    for (i = 0; i < 8; ++i) {
        glGetIntegerv(GL_DRAW_BUFFER0 + (GLenum)i, &s->draw_buffers[i]);
        glGetIntegeri_v(GL_BLEND_SRC_RGB, (GLuint)i, &s->bf[i][0]);
        glGetIntegeri_v(GL_BLEND_DST_RGB, (GLuint)i, &s->bf[i][1]);
        glGetIntegeri_v(GL_BLEND_SRC_ALPHA, (GLuint)i, &s->bf[i][2]);
        glGetIntegeri_v(GL_BLEND_DST_ALPHA, (GLuint)i, &s->bf[i][3]);
        glGetIntegeri_v(GL_BLEND_EQUATION_RGB, (GLuint)i, &s->bf[i][4]);
        glGetIntegeri_v(GL_BLEND_EQUATION_ALPHA, (GLuint)i, &s->bf[i][5]);
        glGetBooleani_v(GL_COLOR_WRITEMASK, (GLuint)i, s->mask[i]);
        s->blend[i] = glIsEnabledi(GL_BLEND, (GLuint)i);
    }
    for (i = 0; i < (int)(sizeof caps / sizeof caps[0]); ++i)
        if (caps[i] != GL_POLYGON_STIPPLE || !e->core) s->en[i] = glIsEnabled(caps[i]);
    glGetIntegerv(GL_PRIMITIVE_RESTART_INDEX, &s->restart_index);
    glGetFloatv(GL_MIN_SAMPLE_SHADING_VALUE, &s->min_sample_shading);
    glGetIntegeri_v(GL_SAMPLE_MASK_VALUE, 0, &s->sample_mask_value);
    glGetBooleanv(GL_TRANSFORM_FEEDBACK_ACTIVE, &s->tf_active);
    glGetBooleanv(GL_TRANSFORM_FEEDBACK_PAUSED, &s->tf_paused);
    glGetIntegerv(GL_VIEWPORT, s->viewport);
    glGetIntegerv(GL_SCISSOR_BOX, s->scissor);
    s->scissor_on = glIsEnabled(GL_SCISSOR_TEST);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void check_snap(const snap *a, const snap *b, const char *what)
{
    int i;
    for (i = 0; i < 8; ++i) {
        if (a->draw_buffers[i] != b->draw_buffers[i])
            fail_msg("%s: DRAW_BUFFER%d 0x%x -> 0x%x", what, i, a->draw_buffers[i], b->draw_buffers[i]);
        if (memcmp(a->bf[i], b->bf[i], sizeof a->bf[i]) || memcmp(a->mask[i], b->mask[i], 4) ||
            a->blend[i] != b->blend[i])
            fail_msg("%s: blend/mask state of draw buffer %d changed", what, i);
    }
    for (i = 0; i < 16; ++i)
        if (a->en[i] != b->en[i]) fail_msg("%s: enable #%d changed %d -> %d", what, i, a->en[i], b->en[i]);
    assert_true(memcmp(a, b, sizeof *a) == 0); /* and everything else */
}

/* ---- 1. several draw buffers ---------------------------------------------- */
static void engine_blend_state(void)
{
    glEnablei(GL_BLEND, 1);
    glBlendFuncSeparatei(1, GL_DST_COLOR, GL_ZERO, GL_ONE, GL_ONE);
    glBlendEquationSeparatei(1, GL_FUNC_SUBTRACT, GL_MAX);
    glColorMaski(2, GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
    glEnablei(GL_BLEND, 3);
    glBlendFunci(3, GL_CONSTANT_COLOR, GL_SRC_ALPHA_SATURATE);
    glDisablei(GL_BLEND, 0);
}

static void write_png4(const unsigned char *const *att, const char *name)
{
    unsigned char *img = (unsigned char *)malloc((size_t)NPIX * 4 * 4);
    char path[256];
    int a, y;
    mkdir("build", 0755);
    mkdir("build/engine_fb", 0755);
    for (a = 0; a < 4; ++a)
        for (y = 0; y < H; ++y) {
            int x;
            for (x = 0; x < W; ++x) {
                unsigned char *d = img + (((size_t)(H - 1 - y) * W * 4) + (size_t)a * W + x) * 4;
                memcpy(d, att[a] + ((size_t)y * W + x) * 4, 3);
                d[3] = 255;
            }
        }
    snprintf(path, sizeof path, "build/engine_fb/%s.png", name);
    stbi_write_png(path, W * 4, H, 4, img, W * 4 * 4);
    free(img);
}

static void drawbuffers_case(int prof, int named, const GLenum *list)
{
    eng e;
    efbo f, ref;
    snap before, after;
    fogvol_frame_desc fd;
    unsigned char *pre[4], *post[4], *refpx = (unsigned char *)malloc(NPIX * 4);
    int i, changed;
    char what[96], png[64];
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
    add_obj(&e, shp_sphere(1.0f, 32, 16), 1.5f, 1.0f, 1.0f, 1, 1, 1);
    efbo_make(&f, 4, GL_RGBA8);
    for (i = 0; i < 4; ++i) {
        pre[i] = (unsigned char *)malloc(NPIX * 4);
        post[i] = (unsigned char *)malloc(NPIX * 4);
        tex_fill(f.tex[i], 7u + (unsigned)i);
        tex_read(f.tex[i], pre[i]);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, f.fbo);
    glDrawBuffers(4, list);
    if (prof == PROF_CORE || prof == PROF_COMPAT || prof == PROF_33) engine_blend_state();
    take_snap(&e, &before);
    frame_desc(&e, &fd);
    fd.draw_buffer = named;
    snprintf(what, sizeof what, "%s, draw buffer %d of 4",
             prof == PROF_CORE     ? "core"
             : prof == PROF_COMPAT ? "compat"
             : prof == PROF_21     ? "GL 2.1 path"
             : prof == PROF_33     ? "as GL 3.3 core"
                                   : "as ES 3.0",
             named);
    check_thickness(&e, &fd, 1.0, what);
    take_snap(&e, &after);
    check_snap(&before, &after, what);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    for (i = 0; i < 4; ++i) tex_read(f.tex[i], post[i]);
    snprintf(png, sizeof png, "four_attachments_%s_buffer%d",
             prof == PROF_CORE     ? "core"
             : prof == PROF_COMPAT ? "compat"
             : prof == PROF_21     ? "gl21"
             : prof == PROF_33     ? "gl33"
                                   : "es30",
             named);
    write_png4((const unsigned char *const *)post, png);
    /* reference: a one-attachment FBO with the same contents, default blend state */
    efbo_make(&ref, 1, GL_RGBA8);
    glBindTexture(GL_TEXTURE_2D, ref.tex[0]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, pre[named]);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, ref.fbo);
    if (prof == PROF_CORE || prof == PROF_COMPAT || prof == PROF_33) {
        glDisablei(GL_BLEND, 0);
        glColorMaski(0, 1, 1, 1, 1);
    }
    frame_desc(&e, &fd);
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_SUCCESS);
    tex_read(ref.tex[0], refpx);
    for (i = 0; i < 4; ++i) {
        changed = count_diff(pre[i], post[i]);
        if (list[i] == GL_NONE || i != named) {
            if (changed) fail_msg("%s: attachment %d: %d pixels changed", what, i, changed);
        } else {
            print_message("# %-40s attachment %d: %d fogged pixels, others unchanged\n", what, i, changed);
            assert_true(changed > 1000);
            assert_int_equal(count_diff(post[i], refpx), 0); /* as on a one-attachment target */
        }
    }
    efbo_free(&ref);
    efbo_free(&f);
    for (i = 0; i < 4; ++i) {
        free(pre[i]);
        free(post[i]);
    }
    free(refpx);
    eng_close(&e);
}

static const GLenum g_list4[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                  GL_COLOR_ATTACHMENT3};
static const GLenum g_list_gap[4] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
static const GLenum g_list_swz[4] = {GL_COLOR_ATTACHMENT3, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT0,
                                     GL_COLOR_ATTACHMENT2};

static void test_drawbuffers_core(void **st)
{
    (void)st;
    drawbuffers_case(PROF_CORE, 0, g_list4);
    drawbuffers_case(PROF_CORE, 2, g_list_gap);
    drawbuffers_case(PROF_33, 1, g_list4);
}
static void test_drawbuffers_compat(void **st)
{
    (void)st;
    drawbuffers_case(PROF_COMPAT, 0, g_list4);
    drawbuffers_case(PROF_COMPAT, 3, g_list4);
}
static void test_drawbuffers_21(void **st)
{
    (void)st;
    drawbuffers_case(PROF_21, 0, g_list4);
    drawbuffers_case(PROF_21, 1, g_list4);
}
static void test_drawbuffers_es30(void **st)
{
    (void)st;
    drawbuffers_case(PROF_ES30, 0, g_list4);
}

/* A list that does not map position i to attachment i: position 2 names attachment 0. */
static void test_drawbuffers_swizzled(void **st)
{
    eng e;
    efbo f;
    fogvol_frame_desc fd;
    unsigned char *pre[4], *post[4];
    int i;
    (void)st;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
    efbo_make(&f, 4, GL_RGBA8);
    for (i = 0; i < 4; ++i) {
        pre[i] = (unsigned char *)malloc(NPIX * 4);
        post[i] = (unsigned char *)malloc(NPIX * 4);
        tex_fill(f.tex[i], 99u + (unsigned)i);
        tex_read(f.tex[i], pre[i]);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, f.fbo);
    glDrawBuffers(4, g_list_swz);
    frame_desc(&e, &fd);
    fd.draw_buffer = 2;
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_SUCCESS);
    for (i = 0; i < 4; ++i) {
        tex_read(f.tex[i], post[i]);
        if (i == 0) assert_true(count_diff(pre[i], post[i]) > 1000);
        else assert_int_equal(count_diff(pre[i], post[i]), 0);
    }
    for (i = 0; i < 4; ++i) {
        GLint v = 0;
        glGetIntegerv(GL_DRAW_BUFFER0 + (GLenum)i, &v);
        assert_int_equal(v, g_list_swz[i]);
        free(pre[i]);
        free(post[i]);
    }
    efbo_free(&f);
    eng_close(&e);
}

/* Refusals: a logged reason, a result code, and the engine's state untouched. */
static void refuse_case(eng *e, int named, const char *what)
{
    fogvol_frame_desc fd;
    snap before, after;
    take_snap(e, &before);
    frame_desc(e, &fd);
    fd.draw_buffer = named;
    e->lc.errors = 0;
    e->lc.last[0] = 0;
    assert_int_equal(run(e, &fd, NULL), FOGVOL_ERROR_UNSUPPORTED);
    assert_true(e->lc.errors >= 1);
    print_message("# refused (%s): %s\n", what, e->lc.last);
    take_snap(e, &after);
    check_snap(&before, &after, what);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

static void test_drawbuffers_refused(void **st)
{
    eng e;
    efbo f;
    fogvol_frame_desc fd;
    (void)st;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    refuse_case(&e, 1, "default framebuffer, draw buffer 1");
    efbo_make(&f, 4, GL_RGBA8);
    glDrawBuffers(4, g_list_gap);
    refuse_case(&e, 1, "draw buffer 1 is GL_NONE");
    refuse_case(&e, 9, "past GL_MAX_DRAW_BUFFERS");
    efbo_free(&f);
    eng_close(&e);
    /* OpenGL ES: list position i can only name COLOR_ATTACHMENTi, so only the first buffer */
    eng_open(&e, PROF_ES30, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    efbo_make(&f, 4, GL_RGBA8);
    glDrawBuffers(4, g_list4);
    refuse_case(&e, 1, "OpenGL ES, draw buffer 1");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    frame_desc(&e, &fd);
    fd.draw_buffer = -1;
    assert_int_equal(fogvol_begin_frame(e.fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.draw_buffer = 0;
    fd.alpha = (fogvol_alpha)7;
    assert_int_equal(fogvol_begin_frame(e.fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    efbo_free(&f);
    eng_close(&e);
}

/* ---- 2. the geometry composite and the engine's stencil ------------------- */
static void stencil_pattern(void)
{
    int i;
    glEnable(GL_SCISSOR_TEST);
    glStencilMask(0xFF);
    for (i = 0; i < 64; ++i) { /* 8x8 blocks of 12 px, every bit pattern differing */
        glScissor((i % 8) * 12, (i / 8) * 12, 12, 12);
        glClearStencil((GLint)((unsigned)(i * 37 + 0x81) & 0xFF));
        glClear(GL_STENCIL_BUFFER_BIT);
    }
    glDisable(GL_SCISSOR_TEST);
    glClearStencil(0);
}

static void read_stencil(unsigned char *out)
{
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, out);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
}

static void composite_case(eng *e, const char *what)
{
    fogvol_frame_desc fd;
    unsigned char *col[2], st0[NPIX], st1[NPIX];
    int c, i, nst;
    for (c = 0; c < 2; ++c) {
        col[c] = (unsigned char *)malloc(NPIX * 4);
        glClearColor(0.2f, 0.5f, 0.8f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        stencil_pattern();
        read_stencil(st0);
        frame_desc(e, &fd);
        fd.composite = c ? FOGVOL_COMPOSITE_GEOMETRY : FOGVOL_COMPOSITE_FULLSCREEN;
        assert_int_equal(run(e, &fd, NULL), FOGVOL_SUCCESS);
        memcpy(col[c], glu_pixels(&e->g), NPIX * 4);
        read_stencil(st1);
        for (i = nst = 0; i < NPIX; ++i) nst += st0[i] != st1[i];
        if (nst) fail_msg("%s: %d stencil pixels changed", what, nst);
    }
    i = count_diff(col[0], col[1]);
    print_message("# %-40s geometry vs full-screen: %d pixels differ; stencil unchanged\n", what, i);
    assert_int_equal(i, 0);
    free(col[0]);
    free(col[1]);
}

static void geometry_scenes(int prof)
{
    eng e;
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(1.0f, 32, 16), -1.0f, 0.5f, 0, 1, 1, 0);
    composite_case(&e, "one small sphere");
    add_obj(&e, shp_sphere(1.5f, 32, 16), 3.2f, -1.0f, -1.0f, 1, 1, 1); /* partly off screen, 2nd ramp */
    composite_case(&e, "two ramps, one partly off screen");
    add_obj(&e, shp_box(0.4f, 0.4f, 0.4f), -1.0f, 0.5f, 0.6f, 1, -1, 0); /* negative inside the first */
    composite_case(&e, "with a negative volume");
    add_obj(&e, shp_sphere(1.2f, 32, 16), 0.2f, 0.0f, 5.5f, 1, 1, 0); /* reaches behind the near plane */
    composite_case(&e, "camera near/inside a volume");
    eng_close(&e);
}

static void test_geometry_core(void **st)
{
    (void)st;
    geometry_scenes(PROF_CORE);
}
static void test_geometry_21(void **st)
{
    (void)st;
    geometry_scenes(PROF_21);
}

/* ---- sequences (tests/sequence.h) -------------------------------------------------------------
   The engine framebuffer over the default script: a 4-attachment FBO with a stencil pattern, the
   draw buffer fogvol composites into changing every frame (frame % 4), the camera walking into the
   big sphere and out, the second ramp's sphere coming and going (the "occluders" of this scene),
   the viewport shrinking and splitting, a cancelled frame in between; full-screen and geometry
   composites. Each view: thickness against its own ray cast (1 LSB per pair of faces, interior
   pixels), the other attachments and the named one outside the viewport byte-identical, the
   stencil untouched, the engine state snapshot unchanged. */
typedef struct fbseq {
    eng e;
    efbo f;
    fogvol_composite composite;
    unsigned char *pre[4], *post, st0[NPIX], st1[NPIX];
    float *thick;
    double *gt;
    unsigned char *in;
} fbseq;

static void fbseq_camera(eng *e, double walk, const int vp[4])
{
    e->cam.eye[0] = 0.5 * walk;
    e->cam.eye[1] = 0.3 * walk;
    e->cam.eye[2] = 6.0 - 5.5 * walk; /* 0.5 at the end: inside the radius-2 sphere */
    e->cam.target[0] = e->cam.eye[0] - 0.2;
    e->cam.target[1] = e->cam.eye[1] - 0.1;
    e->cam.target[2] = e->cam.eye[2] - 6.0;
    e->cam.aspect = (double)vp[2] / vp[3];
    e->cam.width = vp[2];
    e->cam.height = vp[3];
}

/* begin a frame of the view's objects (the second sphere with occluders) into viewport vp */
static void fbseq_begin(fbseq *q, const sq_view *v, double walk, float *thick)
{
    fogvol_frame_desc fd;
    int i;
    fbseq_camera(&q->e, walk, v->viewport);
    memset(&fd, 0, sizeof fd);
    rc_camera_matrices(&q->e.cam, fd.view, fd.projection);
    fd.znear = (float)ZN;
    fd.zfar = (float)ZF;
    memcpy(fd.viewport, v->viewport, sizeof fd.viewport);
    fd.draw_buffer = v->frame % 4;
    fd.composite = q->composite;
    fd.debug_thickness = thick;
    fd.debug_ramp = q->e.ramp[0];
    assert_int_equal(fogvol_begin_frame(q->e.fv, &fd), FOGVOL_SUCCESS);
    for (i = 0; i < q->e.n - !v->occluders; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = q->e.o[i].m;
        vd.ramp = q->e.ramp[q->e.o[i].ramp];
        memcpy(vd.model, q->e.o[i].model, sizeof vd.model);
        assert_int_equal(fogvol_add_volume(q->e.fv, &vd), FOGVOL_SUCCESS);
    }
}

static void fbseq_cancel(void *user, const sq_view *v)
{
    fbseq *q = (fbseq *)user;
    fbseq_begin(q, v, 1.0 - v->walk, NULL);
    assert_int_equal(fogvol_cancel_frame(q->e.fv), FOGVOL_SUCCESS);
}

static void fbseq_view(void *user, const sq_view *v, sq_check *out)
{
    fbseq *q = (fbseq *)user;
    const int *vp = v->viewport;
    snap before, after;
    rc_object ro[MAXOBJ];
    rc_scene rs;
    int i, x, y, named = v->frame % 4;
    double snap = snap_pixels();
    glBindFramebuffer(GL_FRAMEBUFFER, q->f.fbo);
    for (i = 0; i < 4; ++i) {
        tex_fill(q->f.tex[i], 11u * (unsigned)v->frame + (unsigned)i);
        tex_read(q->f.tex[i], q->pre[i]);
    }
    stencil_pattern();
    read_stencil(q->st0);
    take_snap(&q->e, &before);
    fbseq_begin(q, v, v->walk, q->thick);
    assert_int_equal(fogvol_end_frame(q->e.fv, NULL), FOGVOL_SUCCESS);
    take_snap(&q->e, &after);
    out->wrong += memcmp(&before, &after, sizeof before) != 0;
    assert_int_equal(glGetError(), GL_NO_ERROR);
    read_stencil(q->st1);
    for (i = 0; i < NPIX; ++i) out->wrong += q->st0[i] != q->st1[i];
    for (i = 0; i < 4; ++i) { /* only the named attachment, only inside the viewport */
        tex_read(q->f.tex[i], q->post);
        for (y = 0; y < H; ++y)
            for (x = 0; x < W; ++x) {
                int inside = i == named && x >= vp[0] && x < vp[0] + vp[2] && y >= vp[1] && y < vp[1] + vp[3];
                out->wrong += !inside && memcmp(q->pre[i] + 4 * (y * W + x), q->post + 4 * (y * W + x), 4) != 0;
            }
    }
    for (i = 0; i < q->e.n - !v->occluders; ++i) { /* ramp 0's volumes (the read-back's group) */
        ro[i].pos = q->e.o[i].mesh.pos;
        ro[i].vcount = q->e.o[i].mesh.vcount;
        ro[i].idx = q->e.o[i].mesh.idx;
        ro[i].icount = q->e.o[i].mesh.icount;
        memcpy(ro[i].model, q->e.o[i].model, sizeof ro[i].model);
        ro[i].sign = q->e.o[i].ramp == 0 ? q->e.o[i].sign : 0; /* (the other ramp occludes nothing: sign 0 */
        if (q->e.o[i].ramp != 0) ro[i].icount = 0;            /*  and no triangles) */
    }
    assert_true(rc_scene_init(&rs, ro, q->e.n - !v->occluders));
    out->bound = LSB;
    for (y = 0; y < vp[3]; ++y)
        for (x = 0; x < vp[2]; ++x) {
            rc_result r;
            double err;
            int pairs;
            if (!rc_interior(&rs, &q->e.cam, x, y)) continue;
            r = rc_trace(&rs, &q->e.cam, x + 0.5, y + 0.5);
            pairs = r.faces_front > r.faces_back ? r.faces_front : r.faces_back;
            err = fabs(q->thick[y * vp[2] + x] - r.thickness) / (pairs > 1 ? pairs : 1);
            /* the bound + what the GL's vertex snapping may move (snap_pixels), err scaled to LSB */
            err *= LSB / (LSB + rc_depth_slope(&rs, &q->e.cam, x, y) * snap / (pairs > 1 ? pairs : 1));
            out->pixels++;
            out->wrong += err > LSB;
            if (err > out->max_err) out->max_err = err;
        }
    rc_scene_free(&rs);
}

static void test_fb_sequence(void **st)
{
    int c;
    (void)st;
    for (c = 0; c < 2; ++c) {
        fbseq q;
        int i;
        memset(&q, 0, sizeof q);
        q.composite = c ? FOGVOL_COMPOSITE_GEOMETRY : FOGVOL_COMPOSITE_FULLSCREEN;
        eng_open(&q.e, PROF_CORE, FOGVOL_TIER_PS20);
        add_obj(&q.e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
        add_obj(&q.e, shp_sphere(1.0f, 32, 16), 1.5f, 1.0f, -2.0f, 1, 1, 1); /* the one that comes and goes */
        efbo_make(&q.f, 4, GL_RGBA8);
        glDrawBuffers(4, g_list4);
        engine_blend_state();
        for (i = 0; i < 4; ++i) q.pre[i] = (unsigned char *)malloc(NPIX * 4);
        q.post = (unsigned char *)malloc(NPIX * 4);
        q.thick = (float *)calloc(NPIX, sizeof(float));
        sq_run(c ? "engine FBO, 4 draw buffers, geometry composite" : "engine FBO, 4 draw buffers", W, H,
               sq_default_script, SQ_DEFAULT_FRAMES, SQ_ALL, fbseq_view, fbseq_cancel, &q);
        for (i = 0; i < 4; ++i) free(q.pre[i]);
        free(q.post);
        free(q.thick);
        efbo_free(&q.f);
        eng_close(&q.e);
    }
}

/* ---- 3. engine state left set --------------------------------------------- */
typedef struct state_item {
    const char *name;
    int core_only, compat_only;
} state_item;

static const state_item g_items[] = {
    {"primitive restart 0xFFFF", 0, 0}, {"primitive restart fixed index", 0, 0}, {"clip distances 0..7", 0, 0},
    {"depth clamp", 0, 0},              {"sample shading 1.0", 0, 0},            {"sample mask 0", 0, 0},
    {"polygon smooth", 0, 0},           {"polygon stipple", 0, 1}};

static void set_item(int i, int on)
{
    static GLubyte stipple[128];
    int k;
    switch (i) {
    case 0:
        glPrimitiveRestartIndex(on ? 0xFFFF : 0);
        (on ? glEnable : glDisable)(GL_PRIMITIVE_RESTART);
        break;
    case 1: (on ? glEnable : glDisable)(GL_PRIMITIVE_RESTART_FIXED_INDEX); break;
    case 2:
        for (k = 0; k < 8; ++k) (on ? glEnable : glDisable)(GL_CLIP_DISTANCE0 + (GLenum)k);
        break;
    case 3: (on ? glEnable : glDisable)(GL_DEPTH_CLAMP); break;
    case 4:
        glMinSampleShading(on ? 1.0f : 0.0f);
        (on ? glEnable : glDisable)(GL_SAMPLE_SHADING);
        break;
    case 5:
        glSampleMaski(0, on ? 0u : ~0u);
        (on ? glEnable : glDisable)(GL_SAMPLE_MASK);
        break;
    case 6: (on ? glEnable : glDisable)(GL_POLYGON_SMOOTH); break;
    case 7:
        for (k = 0; k < 128; ++k) stipple[k] = (k / 4) % 2 ? 0x00 : 0xFF; /* every other row */
        glPolygonStipple(stipple);
        (on ? glEnable : glDisable)(GL_POLYGON_STIPPLE);
        break;
    }
}

static void state_items(int prof)
{
    eng e;
    fogvol_frame_desc fd;
    snap before, after;
    int i;
    char what[96];
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    /* > 65535 vertices: index 0xFFFF is used; the small sphere crosses the near plane (depth clamp) */
    add_obj(&e, shp_sphere(2.0f, 400, 200), 0, 0, 0, 1, 1, 0);
    add_obj(&e, shp_sphere(0.8f, 32, 16), 0.3f, 0.3f, 4.6f, 1, 1, 0);
    assert_true(e.o[0].mesh.vcount > 65535);
    for (i = 0; i < (int)(sizeof g_items / sizeof g_items[0]); ++i) {
        if ((g_items[i].core_only && prof != PROF_CORE) || (g_items[i].compat_only && prof == PROF_CORE)) continue;
        set_item(i, 1);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        take_snap(&e, &before);
        frame_desc(&e, &fd);
        snprintf(what, sizeof what, "%s: %s", prof == PROF_CORE ? "core" : "compat", g_items[i].name);
        check_thickness(&e, &fd, 1.0, what);
        take_snap(&e, &after);
        check_snap(&before, &after, what);
        set_item(i, 0);
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    eng_close(&e);
}

static void test_state_core(void **st)
{
    (void)st;
    state_items(PROF_CORE);
}
static void test_state_compat(void **st)
{
    (void)st;
    state_items(PROF_COMPAT);
}

/* An active transform feedback of the engine: fogvol's draws are not captured, it stays active. */
static void tf_case(int prof)
{
    static const char *vs = "#version 330 core\nin vec4 p;\nout vec4 cap;\nvoid main() { cap = p; gl_Position = p; }\n";
    static const char *varyings[] = {"cap"};
    eng e;
    fogvol_frame_desc fd;
    snap before, after;
    GLuint sh, prog, buf, q, vao, written = 123;
    GLint ok = 0;
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
    sh = glCreateShader(GL_VERTEX_SHADER);
    glShaderSource(sh, 1, &vs, NULL);
    glCompileShader(sh);
    prog = glCreateProgram();
    glAttachShader(prog, sh);
    glTransformFeedbackVaryings(prog, 1, varyings, GL_INTERLEAVED_ATTRIBS);
    glLinkProgram(prog);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    assert_true(ok);
    glGenBuffers(1, &buf);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, buf);
    glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, 1 << 20, NULL, GL_STATIC_DRAW);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, buf);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenQueries(1, &q);
    glUseProgram(prog);
    glBeginTransformFeedback(GL_TRIANGLES);
    glBeginQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, q);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    take_snap(&e, &before);
    assert_true(before.tf_active && !before.tf_paused);
    frame_desc(&e, &fd);
    check_thickness(&e, &fd, 1.0, prof == PROF_33 ? "as GL 3.3: transform feedback active"
                                                  : "core: transform feedback active");
    take_snap(&e, &after);
    check_snap(&before, &after, "transform feedback");
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glEndQuery(GL_TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN);
    glEndTransformFeedback();
    glGetQueryObjectuiv(q, GL_QUERY_RESULT, &written);
    assert_int_equal(written, 0); /* nothing of fogvol's was captured */
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glUseProgram(0);
    glDeleteQueries(1, &q);
    glDeleteBuffers(1, &buf);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(prog);
    glDeleteShader(sh);
    eng_close(&e);
}

static void test_transform_feedback(void **st)
{
    (void)st;
    tf_case(PROF_CORE);
    tf_case(PROF_33); /* the pause from ARB_transform_feedback2 */
}

/* ---- 4. the engine's pending GL errors ------------------------------------ */
static void raise_engine_error(GLenum code)
{
    GLuint fbo = 0;
    switch (code) {
    case GL_INVALID_ENUM: glBindTexture(0x1234, 0); break;
    case GL_INVALID_VALUE: glLineWidth(-1.0f); break;
    case GL_INVALID_OPERATION: glBindVertexArray(987654); break;
    case GL_INVALID_FRAMEBUFFER_OPERATION: {
        GLint cur = 0;
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &cur);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
        glClear(GL_COLOR_BUFFER_BIT);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)cur);
        glDeleteFramebuffers(1, &fbo);
        break;
    }
    }
}

/* the engine's error, its own KHR_debug message not counted */
static void engine_error(GLenum code)
{
    raise_engine_error(code);
    g_dbg_errors = 0;
}

static void errors_case(int prof)
{
    static const GLenum codes[4] = {GL_INVALID_ENUM, GL_INVALID_VALUE, GL_INVALID_OPERATION,
                                    GL_INVALID_FRAMEBUFFER_OPERATION};
    eng e;
    fogvol_frame_desc fd;
    float *thick = (float *)calloc(NPIX, sizeof(float));
    int c, f;
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    debug_on(); /* raising the engine's errors again reaches no KHR_debug callback (issue 31 3c) */
    for (c = 0; c < 4; ++c) {
        snap before, after;
        for (f = 0; f < 3; ++f) { /* every frame, with and without the debug read-back */
            take_snap(&e, &before);
            engine_error(codes[c]);
            frame_desc(&e, &fd);
            assert_int_equal(run(&e, &fd, f == 1 ? thick : NULL), FOGVOL_SUCCESS);
            no_debug_errors("end_frame");
            assert_int_equal(glGetError(), codes[c]);
            assert_int_equal(glGetError(), GL_NO_ERROR);
            take_snap(&e, &after);
            check_snap(&before, &after, "error re-raised");
        }
        assert_true(thick[(H / 2) * W + W / 2] > 3.9f); /* the frames still rendered (chord 4) */
        {                                                /* resources */
            fogvol_mesh_desc md;
            fogvol_mesh *m = NULL;
            fogvol_ramp *r = NULL;
            fogvol_ramp_desc rd;
            fogvol_context *fv2 = e.fv;
            shp_mesh s = shp_sphere(1.0f, 16, 8);
            memset(&md, 0, sizeof md);
            md.positions = s.pos;
            md.vertex_count = s.vcount;
            md.indices = (const uint32_t *)s.idx;
            md.index_count = s.icount;
            engine_error(codes[c]);
            assert_int_equal(fogvol_create_mesh(e.fv, &md, &m, NULL), FOGVOL_SUCCESS);
            no_debug_errors("create_mesh");
            assert_int_equal(glGetError(), codes[c]);
            memset(&rd, 0, sizeof rd);
            rd.density = 1.0f;
            engine_error(codes[c]);
            assert_int_equal(fogvol_create_ramp(e.fv, &rd, &r), FOGVOL_SUCCESS);
            no_debug_errors("create_ramp");
            assert_int_equal(glGetError(), codes[c]);
            engine_error(codes[c]);
            fogvol_destroy_ramp(e.fv, r);
            fogvol_destroy_mesh(e.fv, m);
            no_debug_errors("destroy_ramp, destroy_mesh");
            assert_int_equal(glGetError(), codes[c]);
            shp_free(&s);
            engine_error(codes[c]);
            assert_int_equal(make_fogvol(&e, FOGVOL_TIER_PS20), FOGVOL_SUCCESS); /* a second context */
            no_debug_errors("create_context");
            assert_int_equal(glGetError(), codes[c]);
            assert_int_equal(glGetError(), GL_NO_ERROR);
            engine_error(codes[c]);
            fogvol_destroy_context(e.fv);
            no_debug_errors("destroy_context");
            assert_int_equal(glGetError(), codes[c]);
            e.fv = fv2;
        }
        print_message("# %s: engine error 0x%04x still pending after end_frame (3 frames), create_mesh, "
                      "create_ramp, create_context\n",
                      prof == PROF_CORE ? "core" : "GL 2.1 path", codes[c]);
    }
    free(thick);
    eng_close(&e);
}

static void test_errors_core(void **st)
{
    (void)st;
    errors_case(PROF_CORE);
}
static void test_errors_21(void **st)
{
    (void)st;
    errors_case(PROF_21);
}

/* Issue 31 3c: fogvol's own GL errors. Each public call that touches GL reports the errors its own GL
   calls raised (a result code and a log line) and leaves exactly the engine's pending errors:
   - fogvol's own draw failing (glDrawArrays made to raise GL_INVALID_ENUM): BACKEND, the code
     logged, the engine's GL_INVALID_VALUE still pending and nothing else (before: fogvol's code was
     left pending as if the engine's);
   - an engine depth texture name that is no texture: INVALID_ARGUMENT, logged, no GL call on it
     (before: success, no fog, the error swallowed; in a compatibility context binding the name
     made an empty texture);
   - post_dof given a colour texture that does not exist: INVALID_ARGUMENT (before: success,
     GL_INVALID_OPERATION left pending);
   - engine_depth_framebuffer 999: INVALID_ARGUMENT with nothing left pending (before:
     GL_INVALID_OPERATION left pending). */
static void test_own_errors(void **st)
{
    eng e;
    fogvol_frame_desc fd;
    fogvol_dof_desc dd;
    float *thick = (float *)calloc(NPIX, sizeof(float));
    GLuint color = 0, depth = 0, fbo = 0;
    (void)st;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    debug_on();
    glLineWidth(-1.0f); /* the engine's GL_INVALID_VALUE */
    g_dbg_errors = 0;
    g_draw_error = GL_INVALID_ENUM;
    frame_desc(&e, &fd);
    e.lc.errors = 0;
    e.lc.last[0] = 0;
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_ERROR_BACKEND);
    print_message("# fogvol's draw failing: %s\n", e.lc.last);
    assert_non_null(strstr(e.lc.last, "0x0500"));
    assert_int_equal(glGetError(), GL_INVALID_VALUE);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_int_equal(g_dbg_errors, 1); /* fogvol's own failing call, and no re-raise */
    g_dbg_errors = 0;
    assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS); /* the next frame is clean */
    assert_true(thick[(H / 2) * W + W / 2] > 3.9f);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    no_debug_errors("the next frame");
    eng_close(&e);

    g_variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_FLOAT);
    g_variants = 0;
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    debug_on();
    fx_color_depth_fbo(W, H, GL_DEPTH_COMPONENT24, GL_UNSIGNED_INT, &color, &depth, &fbo);
    glClear(GL_DEPTH_BUFFER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    frame_desc(&e, &fd);
    fd.engine_depth_texture = depth;
    assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS);
    assert_true(thick[(H / 2) * W + W / 2] > 3.9f);
    /* a depth texture name that is no texture */
    glLineWidth(-1.0f);
    g_dbg_errors = 0;
    e.lc.last[0] = 0;
    fd.engine_depth_texture = 4242;
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    print_message("# engine depth texture 4242: %s\n", e.lc.last);
    assert_non_null(strstr(e.lc.last, "4242"));
    assert_int_equal(glGetError(), GL_INVALID_VALUE);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    no_debug_errors("a bad engine depth texture");
    /* post_dof: the colour texture 4243 does not exist */
    fd.engine_depth_texture = depth;
    memset(&dd, 0, sizeof dd);
    dd.frame = &fd;
    dd.color_texture = color;
    dd.focus_distance = 6.0f;
    dd.focus_range = 2.0f;
    assert_int_equal(fogvol_post_dof(e.fv, &dd), FOGVOL_SUCCESS);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    dd.color_texture = 4243;
    glLineWidth(-1.0f);
    g_dbg_errors = 0;
    e.lc.last[0] = 0;
    assert_int_equal(fogvol_post_dof(e.fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    print_message("# post_dof colour texture 4243: %s\n", e.lc.last);
    assert_non_null(strstr(e.lc.last, "4243"));
    assert_int_equal(glGetError(), GL_INVALID_VALUE);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    no_debug_errors("post_dof with a bad texture");
    /* engine_depth_framebuffer 999 */
    fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT;
    fd.engine_depth_framebuffer = 999;
    e.lc.last[0] = 0;
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    print_message("# engine_depth_framebuffer 999: %s\n", e.lc.last);
    assert_non_null(strstr(e.lc.last, "999"));
    assert_int_equal(glGetError(), GL_NO_ERROR);
    no_debug_errors("engine_depth_framebuffer 999");
    fd.engine_depth_framebuffer = fbo; /* the same through the framebuffer: fine */
    assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS);
    assert_true(thick[(H / 2) * W + W / 2] > 3.9f);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &color);
    glDeleteTextures(1, &depth);
    eng_close(&e);
    free(thick);
}

/* Issue 31 3c: version overrides that a core-profile context cannot honour. OpenGL ES 2.0 and GL 2.1
   draw without vertex array objects and read one GL_EXTENSIONS string, which a core profile has not:
   refused (UNSUPPORTED, logged) with nothing left pending (before: ES 2.0 was accepted and left
   GL_INVALID_OPERATION, 2.1 refused but left GL_INVALID_ENUM). GL 3.0 is drawn as the core profile
   it is (before: refused as a backend error leaving GL_INVALID_ENUM: fogvol touched the
   compatibility profile's alpha test and polygon stipple). */
static void test_override_core(void **st)
{
    static const struct {
        int major, minor, gles;
        fogvol_result want;
    } cases[] = {{2, 0, 1, FOGVOL_ERROR_UNSUPPORTED}, {2, 1, 0, FOGVOL_ERROR_UNSUPPORTED},
                 {3, 0, 0, FOGVOL_SUCCESS},           {3, 1, 0, FOGVOL_SUCCESS},
                 {3, 0, 1, FOGVOL_SUCCESS}};
    eng e;
    int i;
    (void)st;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    debug_on();
    for (i = 0; i < (int)(sizeof cases / sizeof cases[0]); ++i) {
        fogvol_context_desc cd;
        fogvol_context *fv = NULL;
        fogvol_result r;
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.logger.func = logger;
        cd.logger.user_data = &e.lc;
        cd.gl.version_major = cases[i].major;
        cd.gl.version_minor = cases[i].minor;
        cd.gl.gles = cases[i].gles;
        e.lc.last[0] = 0;
        g_dbg_errors = 0;
        r = fogvol_create_context(&cd, &fv);
        print_message("# core profile treated as %s %d.%d: %s%s%s\n", cases[i].gles ? "OpenGL ES" : "GL",
                      cases[i].major, cases[i].minor, fogvol_result_string(r), e.lc.last[0] ? ": " : "", e.lc.last);
        assert_int_equal(r, cases[i].want);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        no_debug_errors("create_context");
        if (r == FOGVOL_SUCCESS) { /* and it draws: the sphere's chord through its centre */
            fogvol_context *own = e.fv;
            fogvol_ramp *own_ramp = e.ramp[0];
            fogvol_frame_desc fd;
            float *thick = (float *)calloc(NPIX, sizeof(float));
            e.fv = fv;
            make_ramp(&e, 0, NULL);
            add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
            frame_desc(&e, &fd);
            assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS);
            assert_true(fabs(thick[(H / 2) * W + W / 2] - 4.0) < 0.05);
            assert_int_equal(glGetError(), GL_NO_ERROR);
            no_debug_errors("a frame");
            fogvol_destroy_mesh(fv, e.o[0].m);
            shp_free(&e.o[0].mesh);
            e.n = 0;
            fogvol_destroy_ramp(fv, e.ramp[0]);
            fogvol_destroy_context(fv);
            e.fv = own;
            e.ramp[0] = own_ramp;
            free(thick);
        } else {
            assert_non_null(strstr(e.lc.last, "core"));
        }
    }
    eng_close(&e);
}

/* Issue 31 3i: fogvol called with another GL context current (one that does not share objects with
   fogvol's). Before: end_frame returned success and deleted two of that context's textures whose
   names were those of fogvol's targets. Now every entry that would touch GL refuses
   (INVALID_STATE, logged: "another GL context is current?") and touches nothing: the other
   context's textures and buffers all exist afterwards and no GL error is left there; fogvol works
   again once its context is current. Told by a per-context object of fogvol's own (its vertex
   array object, or on GL 2 a framebuffer object) and, when the desc has one, by
   fogvol_gl_desc.current_context. */
static void other_context_case(int with_callback)
{
    eng e;
    glu_ctx other;
    fogvol_frame_desc fd;
    fogvol_mesh_desc md;
    fogvol_mesh *m = NULL;
    GLuint tex[8], buf[8];
    float *thick = (float *)calloc(NPIX, sizeof(float));
    shp_mesh s = shp_sphere(1.0f, 16, 8);
    int k, size;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    if (with_callback) { /* the same, told by the callback */
        fogvol_context_desc cd;
        fogvol_destroy_ramp(e.fv, e.ramp[0]);
        fogvol_destroy_ramp(e.fv, e.ramp[1]);
        fogvol_destroy_context(e.fv);
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.gl.current_context = glu_current_context;
        cd.logger.func = logger;
        cd.logger.user_data = &e.lc;
        cd.tier = FOGVOL_TIER_PS20;
        assert_int_equal(fogvol_create_context(&cd, &e.fv), FOGVOL_SUCCESS);
        make_ramp(&e, 0, NULL);
        make_ramp(&e, 1, NULL);
    }
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    frame_desc(&e, &fd);
    assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS);
    assert_true(thick[(H / 2) * W + W / 2] > 3.9f);
    assert_true(glu_create(&other, W, H, 1)); /* now current */
    glGenTextures(8, tex);
    glGenBuffers(8, buf);
    for (k = 0; k < 8; ++k) {
        static const unsigned char px[16] = {0};
        glBindTexture(GL_TEXTURE_2D, tex[k]);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 2, 2, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
        glBindBuffer(GL_ARRAY_BUFFER, buf[k]);
        glBufferData(GL_ARRAY_BUFFER, 16, px, GL_STATIC_DRAW);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    for (size = 0; size < 2; ++size) { /* the same viewport, and one that would make new targets */
        frame_desc(&e, &fd);
        fd.viewport[2] = size ? W / 2 : W;
        e.lc.last[0] = 0;
        assert_int_equal(run(&e, &fd, NULL), FOGVOL_ERROR_INVALID_STATE);
        assert_non_null(strstr(e.lc.last, "context"));
    }
    print_message("# %s: %s\n", with_callback ? "with current_context" : "fingerprint", e.lc.last);
    fx_mesh_desc(&md, &s, 0);
    assert_int_equal(fogvol_create_mesh(e.fv, &md, &m, NULL), FOGVOL_ERROR_INVALID_STATE);
    fogvol_destroy_mesh(e.fv, e.o[0].m); /* forgotten, its GL objects not deleted here */
    e.o[0].m = NULL;
    for (k = 0; k < 8; ++k) {
        assert_true(glIsTexture(tex[k]));
        assert_true(glIsBuffer(buf[k]));
    }
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_true(glu_make_current(&e.g));
    glu_destroy(&other);
    assert_true(glu_make_current(&e.g));
    e.o[0].m = NULL;
    assert_int_equal(fogvol_create_mesh(e.fv, &md, &e.o[0].m, NULL), FOGVOL_SUCCESS);
    frame_desc(&e, &fd);
    memset(thick, 0, NPIX * sizeof(float));
    assert_int_equal(run(&e, &fd, thick), FOGVOL_SUCCESS); /* back in its own context: a sphere of radius 1 */
    assert_true(fabs(thick[(H / 2) * W + W / 2] - 2.0) < 0.05);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    shp_free(&s);
    free(thick);
    eng_close(&e);
}

static void test_other_context(void **st)
{
    (void)st;
    other_context_case(0);
    other_context_case(1);
}

/* Codes GL cannot raise again on demand (out of memory, stack over/underflow, context loss) are logged. */
static void test_errors_unraisable(void **st)
{
    static const GLenum codes[3] = {GL_OUT_OF_MEMORY, GL_STACK_OVERFLOW, GL_CONTEXT_LOST};
    eng e;
    fogvol_frame_desc fd;
    int c;
    char want[16];
    (void)st;
    eng_open(&e, PROF_CORE, FOGVOL_TIER_PS20);
    add_obj(&e, shp_sphere(2.0f, 32, 16), 0, 0, 0, 1, 1, 0);
    for (c = 0; c < 3; ++c) {
        g_fake_error = codes[c];
        e.lc.warnings = 0;
        e.lc.last[0] = 0;
        frame_desc(&e, &fd);
        assert_int_equal(run(&e, &fd, NULL), FOGVOL_SUCCESS);
        assert_int_equal(e.lc.warnings, 1);
        snprintf(want, sizeof want, "0x%04x", codes[c]);
        assert_non_null(strstr(e.lc.last, want));
        print_message("# logged: %s\n", e.lc.last);
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    eng_close(&e);
}

/* ---- 5. alpha, 6. sRGB ---------------------------------------------------- */
static double srgb_decode(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }
static double srgb_encode(double l) { return l <= 0.0031308 ? l * 12.92 : 1.055 * pow(l, 1.0 / 2.4) - 0.055; }

/* Fog of constant colour c and alpha a over a target of constant value d (bytes): every pixel where
   the ray cast sees the volume is compared to the value computed here (tolerance 1). */
static void blend_case(int prof, GLenum fmt, int srgb_on, fogvol_alpha mode, const char *what)
{
    static const float rgba[4] = {0.8f, 0.4f, 0.2f, 0.6f};
    static const unsigned char d[4] = {40, 160, 220, 128};
    eng e;
    efbo f;
    fogvol_frame_desc fd;
    double *gt = (double *)calloc(NPIX, sizeof(double)), want[4];
    unsigned char *in = (unsigned char *)calloc(NPIX, 1), *px = (unsigned char *)malloc(NPIX * 4);
    unsigned char *fill = (unsigned char *)malloc(NPIX * 4);
    int i, k, n = 0, worst = 0;
    double a, cb[4];
    eng_open(&e, prof, FOGVOL_TIER_PS20);
    fogvol_destroy_ramp(e.fv, e.ramp[0]);
    make_ramp(&e, 0, rgba);
    add_obj(&e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
    efbo_make(&f, 1, fmt);
    for (i = 0; i < NPIX; ++i) memcpy(fill + 4 * i, d, 4);
    glBindTexture(GL_TEXTURE_2D, f.tex[0]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, fill);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, f.fbo);
    if (srgb_on) glEnable(GL_FRAMEBUFFER_SRGB);
    frame_desc(&e, &fd);
    fd.alpha = mode;
    assert_int_equal(run(&e, &fd, NULL), FOGVOL_SUCCESS);
    assert_int_equal(glIsEnabled(GL_FRAMEBUFFER_SRGB), srgb_on ? GL_TRUE : GL_FALSE);
    tex_read(f.tex[0], px);
    truth(&e, gt, in);
    /* the ramp texel bytes (what the shader outputs): round(255 v) / 255 */
    for (k = 0; k < 4; ++k) cb[k] = floor(rgba[k] * 255.0 + 0.5) / 255.0;
    a = cb[3];
    for (k = 0; k < 3; ++k) {
        double dst = d[k] / 255.0;
        if (fmt == GL_SRGB8_ALPHA8 && srgb_on) want[k] = 255.0 * srgb_encode(cb[k] * a + srgb_decode(dst) * (1 - a));
        else want[k] = 255.0 * (cb[k] * a + dst * (1 - a));
    }
    want[3] = mode == FOGVOL_ALPHA_COVERAGE ? 255.0 * (a + d[3] / 255.0 * (1 - a)) : d[3];
    for (i = 0; i < NPIX; ++i) {
        if (!in[i] || gt[i] <= 0.05) continue;
        ++n;
        for (k = 0; k < 4; ++k) {
            int e1 = abs((int)px[4 * i + k] - (int)floor(want[k] + 0.5));
            if (e1 > worst) worst = e1;
        }
    }
    print_message("# %-40s expected (%.1f %.1f %.1f %.1f), worst byte error %d over %d pixels\n", what, want[0],
                  want[1], want[2], want[3], worst, n);
    assert_true(n > 1000);
    assert_true(worst <= 1);
    glDisable(GL_FRAMEBUFFER_SRGB);
    efbo_free(&f);
    free(gt);
    free(in);
    free(px);
    free(fill);
    eng_close(&e);
}

static void test_alpha(void **st)
{
    (void)st;
    blend_case(PROF_CORE, GL_RGBA8, 0, FOGVOL_ALPHA_KEEP, "core RGBA8, alpha kept");
    blend_case(PROF_CORE, GL_RGBA8, 0, FOGVOL_ALPHA_COVERAGE, "core RGBA8, alpha coverage");
    blend_case(PROF_21, GL_RGBA8, 0, FOGVOL_ALPHA_COVERAGE, "GL 2.1 path RGBA8, alpha coverage");
}

static void test_srgb(void **st)
{
    (void)st;
    blend_case(PROF_CORE, GL_SRGB8_ALPHA8, 1, FOGVOL_ALPHA_KEEP, "core SRGB8_ALPHA8 + FRAMEBUFFER_SRGB");
    blend_case(PROF_COMPAT, GL_SRGB8_ALPHA8, 1, FOGVOL_ALPHA_COVERAGE, "compat SRGB8_ALPHA8 + FB_SRGB, coverage");
    blend_case(PROF_CORE, GL_RGBA8, 1, FOGVOL_ALPHA_KEEP, "core RGBA8 + FRAMEBUFFER_SRGB (no effect)");
}

/* FRAMEBUFFER_SRGB left on does not touch fogvol's own RGBA8 (PS20) and R32F (FLOAT) targets. */
static void test_srgb_own_targets(void **st)
{
    static const fogvol_tier tiers[2] = {FOGVOL_TIER_PS20, FOGVOL_TIER_FLOAT};
    int t;
    (void)st;
    for (t = 0; t < 2; ++t) {
        eng e;
        efbo f;
        fogvol_frame_desc fd;
        eng_open(&e, PROF_CORE, tiers[t]);
        add_obj(&e, shp_sphere(2.0f, 48, 24), 0, 0, 0, 1, 1, 0);
        efbo_make(&f, 1, GL_SRGB8_ALPHA8);
        glEnable(GL_FRAMEBUFFER_SRGB);
        frame_desc(&e, &fd);
        check_thickness(&e, &fd, t ? 3e-5 * 4096.0 : 1.0,
                        t ? "FLOAT (R32F) with FRAMEBUFFER_SRGB" : "PS20 (RGBA8) with FRAMEBUFFER_SRGB");
        assert_true(glIsEnabled(GL_FRAMEBUFFER_SRGB));
        glDisable(GL_FRAMEBUFFER_SRGB);
        efbo_free(&f);
        eng_close(&e);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drawbuffers_core),  cmocka_unit_test(test_drawbuffers_compat),
        cmocka_unit_test(test_drawbuffers_21),    cmocka_unit_test(test_drawbuffers_es30),
        cmocka_unit_test(test_drawbuffers_swizzled),
        cmocka_unit_test(test_drawbuffers_refused), cmocka_unit_test(test_geometry_core),
        cmocka_unit_test(test_geometry_21),       cmocka_unit_test(test_fb_sequence),
        cmocka_unit_test(test_state_core),
        cmocka_unit_test(test_state_compat),      cmocka_unit_test(test_transform_feedback),
        cmocka_unit_test(test_errors_core),       cmocka_unit_test(test_errors_21),
        cmocka_unit_test(test_errors_unraisable),
        cmocka_unit_test(test_own_errors),        cmocka_unit_test(test_override_core),
        cmocka_unit_test(test_other_context),
        cmocka_unit_test(test_alpha),             cmocka_unit_test(test_srgb),
        cmocka_unit_test(test_srgb_own_targets),
    };
    if (getenv("FV_TEST_FILTER")) cmocka_set_test_filter(getenv("FV_TEST_FILTER")); /* e.g. "*sequence*" */
    return cmocka_run_group_tests(tests, NULL, NULL);
}
