/* test_engine_msaa.c - fogvol inside an engine that renders into a 4x MSAA
   framebuffer (multisample colour and depth renderbuffers).

   The engine draws an opaque box (flat colour) into its MSAA framebuffer over
   a flat background; a fog box is cut by that occluder and shows its own
   silhouettes. fogvol gets the occluder and the volume and composites into
   the engine framebuffer; the engine resolves it (glBlitFramebuffer to a
   single-sample renderbuffer) and reads it back.

   Ground truth, per sample: the sample positions of the engine framebuffer
   (glGetMultisamplefv(GL_SAMPLE_POSITION)), the ray through each, the
   analytic view-depth extent of the fog box along it, cut at the occluder's
   entry (ray/oriented-box slabs); the engine's colour there (occluder or
   background), fogged with the ramp's formula a = clamp(t * density) as
   rgb' = rgb (1 - a) + fog a, quantised to 8 bits per sample, then averaged
   over the samples (the resolve). Errors in /255 (largest channel) over all
   pixels, over "edge" pixels (occluder edges inside fog: the samples disagree
   on the occluder and some see fog) and over volume silhouettes.

   Before: FOGVOL_MSAA_SINGLE_SAMPLE, i.e. single-sample targets and one fog
   value per pixel (what fogvol did before it looked at the engine's samples).
   After: FOGVOL_MSAA_AUTO (per-sample targets and shading; FLOAT + engine depth: the faces depth-tested
   against the engine's multisample depth per sample and shaded once per pixel into a multisample RG32F
   sum, the composite per sample, FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST, asserted on every single frame and
   counted on the sequences' views).
   Figures (llvmpipe, 160x120, 4x; printed by the test), /255, over the 82
   pixels on occluder edges inside fog ("edges") and over all pixels:
     before (every tier): edges mean 29.7, max 60; all pixels mean 0.46, max 60
     after  FLOAT, PS20 (+single, +count), PS13, FLOAT with the geometry
            composite: edges mean 1.0, max 2; all pixels mean 0.34, max 3
   Cost (FLOAT, 640x480, min of 5 frames of fogvol_end_frame + glFinish, one
   run): 4x per sample / the same scene on a single-sample engine framebuffer
   = 3.9-4.6x over several runs (printed as "cost"); every sample is shaded.
   The engine's GL_MULTISAMPLE, GL_SAMPLE_SHADING, min sample shading value
   and multisample texture bindings are checked to come back unchanged;
   dialects without the per-sample path are refused with a logged reason, and
   the opt-in fallback is reported in the frame stats. Writes
   build/engine_msaa.png: truth | before | after | 8x|before-truth| | 8x|after-truth|. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/sequence.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>
#include <time.h>

#define W 160
#define H 120
#define NS 4
#define ZNEAR 1.0
#define ZFAR 20.0
#define DENSITY 0.15f

static const float k_bg[3] = {0.15f, 0.25f, 0.45f};
static const float k_occ[3] = {0.9f, 0.55f, 0.15f};
static const float k_fog[3] = {0.9f, 0.92f, 1.0f};

static char g_log[2048];
static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l <= FOGVOL_LOG_WARNING) snprintf(g_log, sizeof g_log, "%s", m);
}

/* ---- oriented boxes: mesh and ray slabs ---------------------------------- */
typedef struct obox {
    double c[3], h[3], r[9]; /* centre, half sizes, rotation columns (local -> view) */
} obox;

static void obox_init(obox *b, double cx, double cy, double cz, double hx, double hy, double hz, double ax,
                      double ay)
{
    double ca = cos(ax), sa = sin(ax), cb = cos(ay), sb = sin(ay);
    /* R = Ry(ay) * Rx(ax), column-major: r[col*3 + row] */
    double rx[9] = {1, 0, 0, 0, ca, sa, 0, -sa, ca}, ry[9] = {cb, 0, -sb, 0, 1, 0, sb, 0, cb};
    int i, j, k;
    b->c[0] = cx, b->c[1] = cy, b->c[2] = cz;
    b->h[0] = hx, b->h[1] = hy, b->h[2] = hz;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double s = 0;
            for (k = 0; k < 3; ++k) s += ry[k * 3 + j] * rx[i * 3 + k];
            b->r[i * 3 + j] = s;
        }
}

/* 8 corners, 12 triangles wound counter-clockwise seen from outside */
static void obox_mesh(const obox *b, float pos[24], uint32_t idx[36])
{
    static const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    int v, i, f;
    for (v = 0; v < 8; ++v) {
        double l[3] = {(v & 1) ? b->h[0] : -b->h[0], (v & 2) ? b->h[1] : -b->h[1], (v & 4) ? b->h[2] : -b->h[2]};
        for (i = 0; i < 3; ++i)
            pos[v * 3 + i] = (float)(b->c[i] + b->r[0 * 3 + i] * l[0] + b->r[1 * 3 + i] * l[1] + b->r[2 * 3 + i] * l[2]);
    }
    for (f = 0; f < 6; ++f) {
        const int *q = quads[f];
        double e1[3], e2[3], n[3], fc[3] = {0, 0, 0}, d = 0;
        for (i = 0; i < 3; ++i) {
            e1[i] = pos[q[1] * 3 + i] - pos[q[0] * 3 + i];
            e2[i] = pos[q[2] * 3 + i] - pos[q[0] * 3 + i];
            for (v = 0; v < 4; ++v) fc[i] += pos[q[v] * 3 + i] / 4.0;
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (i = 0; i < 3; ++i) d += n[i] * (fc[i] - b->c[i]);
        if (d > 0) {
            idx[f * 6 + 0] = (uint32_t)q[0], idx[f * 6 + 1] = (uint32_t)q[1], idx[f * 6 + 2] = (uint32_t)q[2];
            idx[f * 6 + 3] = (uint32_t)q[0], idx[f * 6 + 4] = (uint32_t)q[2], idx[f * 6 + 5] = (uint32_t)q[3];
        } else {
            idx[f * 6 + 0] = (uint32_t)q[0], idx[f * 6 + 1] = (uint32_t)q[2], idx[f * 6 + 2] = (uint32_t)q[1];
            idx[f * 6 + 3] = (uint32_t)q[0], idx[f * 6 + 4] = (uint32_t)q[3], idx[f * 6 + 5] = (uint32_t)q[2];
        }
    }
}

/* ray from the eye (view origin) along dir: parameter interval inside the box */
static int obox_ray_faces(const obox *b, const double dir[3], double *t0, double *t1, int *f0, int *f1);
static int obox_ray(const obox *b, const double dir[3], double *t0, double *t1)
{
    return obox_ray_faces(b, dir, t0, t1, NULL, NULL);
}

/* obox_ray, and the faces the ray enters and leaves by (f0, f1: axis * 2, + 1 for the +h side) */
static int obox_ray_faces(const obox *b, const double dir[3], double *t0, double *t1, int *f0, int *f1)
{
    double lo = -1e300, hi = 1e300;
    int a, fa = 0, fb = 0;
    for (a = 0; a < 3; ++a) {
        const double *ax = b->r + a * 3;
        double o = -(b->c[0] * ax[0] + b->c[1] * ax[1] + b->c[2] * ax[2]); /* origin in local coordinates */
        double d = dir[0] * ax[0] + dir[1] * ax[1] + dir[2] * ax[2];
        if (fabs(d) < 1e-300) {
            if (fabs(o) > b->h[a]) return 0;
            continue;
        }
        {
            double ta = (-b->h[a] - o) / d, tb = (b->h[a] - o) / d;
            int sa = 0, sb = 1;
            if (ta > tb) {
                double t = ta;
                ta = tb;
                tb = t;
                sa = 1;
                sb = 0;
            }
            if (ta > lo) lo = ta, fa = a * 2 + sa;
            if (tb < hi) hi = tb, fb = a * 2 + sb;
        }
    }
    *t0 = lo;
    *t1 = hi;
    if (f0) *f0 = fa;
    if (f1) *f1 = fb;
    return lo < hi;
}

/* the view depth at which the ray dir meets the plane of face f of b */
static double obox_plane(const obox *b, int f, const double dir[3])
{
    const double *ax = b->r + (f >> 1) * 3;
    double d = dir[0] * ax[0] + dir[1] * ax[1] + dir[2] * ax[2];
    double c = b->c[0] * ax[0] + b->c[1] * ax[1] + b->c[2] * ax[2] + ((f & 1) ? b->h[f >> 1] : -b->h[f >> 1]);
    return fabs(d) < 1e-12 ? (c * d >= 0 ? 1e30 : -1e30) : c / d;
}

/* the box b moved by the rigid transform m (column-major, view space) */
static obox obox_xf(const obox *b, const double m[16])
{
    obox o;
    int i, k;
    for (i = 0; i < 3; ++i) {
        o.c[i] = m[12 + i];
        o.h[i] = b->h[i];
        for (k = 0; k < 3; ++k) o.c[i] += m[k * 4 + i] * b->c[k];
    }
    for (k = 0; k < 3; ++k)
        for (i = 0; i < 3; ++i)
            o.r[k * 3 + i] = m[i] * b->r[k * 3] + m[4 + i] * b->r[k * 3 + 1] + m[8 + i] * b->r[k * 3 + 2];
    return o;
}

static obox g_vol0, g_occ0; /* the scene as the meshes hold it */
static obox g_vol, g_occ;   /* and as this frame sees it (g_model applied) */
static double g_model[16];  /* view-space transform of the scene this frame (the camera's walk) */
static int g_occ_on = 1;    /* the occluder is there this frame */
static float g_proj[16];

static void scene_init(int w, int h)
{
    obox_init(&g_vol0, 0.0, -0.2, -8.0, 2.6, 1.6, 2.2, 0.35, 0.55);
    obox_init(&g_occ0, 0.9, 0.5, -7.2, 0.9, 0.9, 0.9, 0.6, -0.4);
    g_vol = g_vol0;
    g_occ = g_occ0;
    memset(g_model, 0, sizeof g_model);
    g_model[0] = g_model[5] = g_model[10] = g_model[15] = 1.0;
    glu_perspective(g_proj, 50.0, (double)w / h, ZNEAR, ZFAR);
}

/* The camera at walk position w (0: the first pose; 1: inside the fog box, the occluder beside
   it), as the scene moved and turned the other way, with a w x h viewport's aspect. */
static void scene_pose(double walk, int w, int h)
{
    double a = -0.3 * walk, c = cos(a), sn = sin(a);
    memset(g_model, 0, sizeof g_model);
    g_model[0] = c, g_model[2] = -sn, g_model[5] = 1.0, g_model[8] = sn, g_model[10] = c, g_model[15] = 1.0;
    g_model[12] = -1.0 * walk;
    g_model[13] = 0.2 * walk;
    g_model[14] = 7.0 * walk;
    g_vol = obox_xf(&g_vol0, g_model);
    g_occ = obox_xf(&g_occ0, g_model);
    glu_perspective(g_proj, 50.0, (double)w / h, ZNEAR, ZFAR);
}

static int obox_contains(const obox *b, const double p[3])
{
    int a;
    for (a = 0; a < 3; ++a) {
        const double *ax = b->r + a * 3;
        double d = (p[0] - b->c[0]) * ax[0] + (p[1] - b->c[1]) * ax[1] + (p[2] - b->c[2]) * ax[2];
        if (fabs(d) > b->h[a]) return 0;
    }
    return 1;
}

/* the 8-bit colour of thickness t over the occluder (hit) or the background */
static void fog_colour(int hit, double t, unsigned char out[3])
{
    double a = t * DENSITY;
    int i;
    if (a > 1) a = 1;
    for (i = 0; i < 3; ++i) {
        double c = (hit ? k_occ[i] : k_bg[i]) * (1 - a) + k_fog[i] * a;
        out[i] = (unsigned char)floor(c * 255.0 + 0.5);
    }
}

/* True 8-bit colour of one sample at window position (x, y); returns flags. */
static int truth_sample(double x, double y, int w, int h, unsigned char out[3])
{
    double dir[3], a0, a1, o0, o1, t = 0, tend = ZFAR;
    int hit;
    dir[0] = (2.0 * x / w - 1.0) / g_proj[0];
    dir[1] = (2.0 * y / h - 1.0) / g_proj[5];
    dir[2] = -1.0; /* the parameter is the view depth */
    /* the occluder's nearest face at or beyond the near plane (the GL clips there; the faces are
       drawn two-sided) */
    hit = g_occ_on && obox_ray(&g_occ, dir, &o0, &o1) && (o0 > ZNEAR ? o0 : o1) > ZNEAR &&
          (o0 > ZNEAR ? o0 : o1) < ZFAR;
    if (hit) tend = o0 > ZNEAR ? o0 : o1;
    if (obox_ray(&g_vol, dir, &a0, &a1)) {
        double s = a0 > ZNEAR ? a0 : ZNEAR, e = a1 < tend ? a1 : tend;
        if (e > s) t = e - s;
    }
    fog_colour(hit, t, out);
    return (hit ? 1 : 0) | (t > 0 ? 2 : 0); /* occluder seen, fog on the ray */
}

/* What evaluating the depths of the faces a sample's ray crosses at the pixel centre (cx, cy)
   instead of at the sample (x, y) changes in its 8-bit colour (every combination of the entry,
   exit and occluder faces), over NS. llvmpipe shades per sample but, in some triangles, takes the
   interpolated depth at the pixel centre (measured here: the plain GL's w of a face at a sample
   equals its value at the pixel centre), which moves a thickness by up to the depth change of a
   grazing face across half a pixel. */
static double centre_slack(double x, double y, double cx, double cy, int w, int h, const unsigned char at[3])
{
    double dir[3], dc[3], a0, a1, o0 = 0, o1 = 0, m = 0;
    int f0 = 0, f1 = 0, g0 = 0, g1 = 0, hit = 0, vol, k, c;
    dir[0] = (2.0 * x / w - 1.0) / g_proj[0];
    dir[1] = (2.0 * y / h - 1.0) / g_proj[5];
    dc[0] = (2.0 * cx / w - 1.0) / g_proj[0];
    dc[1] = (2.0 * cy / h - 1.0) / g_proj[5];
    dir[2] = dc[2] = -1.0;
    if (g_occ_on && obox_ray_faces(&g_occ, dir, &o0, &o1, &g0, &g1)) {
        int near_cut = !(o0 > ZNEAR);
        hit = (near_cut ? o1 : o0) > ZNEAR && (near_cut ? o1 : o0) < ZFAR;
        if (near_cut) o0 = o1, g0 = g1;
    }
    vol = obox_ray_faces(&g_vol, dir, &a0, &a1, &f0, &f1);
    if (!vol) return 0.0;
    for (k = 1; k < 8; ++k) {
        double tin = (k & 1) ? obox_plane(&g_vol, f0, dc) : a0, tout = (k & 2) ? obox_plane(&g_vol, f1, dc) : a1;
        double tend = !hit ? ZFAR : (k & 4) ? obox_plane(&g_occ, g0, dc) : o0;
        double s = tin > ZNEAR ? tin : ZNEAR, e = tout < tend ? tout : tend;
        unsigned char o[3];
        fog_colour(hit, e > s ? e - s : 0.0, o);
        for (c = 0; c < 3; ++c)
            if (abs((int)o[c] - (int)at[c]) > m) m = abs((int)o[c] - (int)at[c]);
    }
    return m / NS;
}

/* ---- the engine ------------------------------------------------------------ */
typedef struct engine {
    GLuint fbo, rb_color, rb_depth, tex_depth, tex_color, resolve_fbo, rb_resolve, prog, vao, vbo, ibo;
    int w, h, samples;
    float pos[2][3];
} engine;

static GLuint compile(GLenum type, const char *src)
{
    GLuint s = glCreateShader(type);
    GLint ok = 0;
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    assert_true(ok);
    return s;
}

/* depth_texture: the depth buffer is a (multisample) depth texture instead of a renderbuffer; 2: made with
   fixedsamplelocations GL_FALSE, and the colour buffer a multisample texture made so too (a framebuffer
   whose textures do not agree on it, or that mixes such textures with renderbuffers, is incomplete) */
static void engine_create_ex(engine *e, int w, int h, int samples, int depth_texture)
{
    static const char *vs = "#version 330 core\nlayout(location = 0) in vec3 p;\nuniform mat4 mvp;\n"
                            "void main() { gl_Position = mvp * vec4(p, 1.0); }\n";
    static const char *fs = "#version 330 core\nuniform vec3 col;\nout vec4 o;\nvoid main() { o = vec4(col, 1.0); }\n";
    float pos[24];
    uint32_t idx[36];
    GLuint a, b;
    GLint ok = 0;
    memset(e, 0, sizeof *e);
    e->w = w;
    e->h = h;
    e->samples = samples;
    glGenFramebuffers(1, &e->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    if (depth_texture == 2 && samples > 1) {
        glGenTextures(1, &e->tex_color);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, e->tex_color);
        glTexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, samples, GL_RGBA8, w, h, GL_FALSE);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D_MULTISAMPLE, e->tex_color, 0);
    } else {
        glGenRenderbuffers(1, &e->rb_color);
        glBindRenderbuffer(GL_RENDERBUFFER, e->rb_color);
        if (samples > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
        else glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, e->rb_color);
    }
    if (depth_texture) {
        GLenum target = samples > 1 ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
        glGenTextures(1, &e->tex_depth);
        glBindTexture(target, e->tex_depth);
        if (samples > 1)
            glTexImage2DMultisample(target, samples, GL_DEPTH24_STENCIL8, w, h, depth_texture == 2 ? GL_FALSE : GL_TRUE);
        else glTexImage2D(target, 0, GL_DEPTH24_STENCIL8, w, h, 0, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, NULL);
        glBindTexture(target, 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, target, e->tex_depth, 0);
    } else {
        glGenRenderbuffers(1, &e->rb_depth);
        glBindRenderbuffer(GL_RENDERBUFFER, e->rb_depth);
        if (samples > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8, w, h);
        else glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, e->rb_depth);
    }
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glGenRenderbuffers(1, &e->rb_resolve);
    glBindRenderbuffer(GL_RENDERBUFFER, e->rb_resolve);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glGenFramebuffers(1, &e->resolve_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->resolve_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, e->rb_resolve);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    e->prog = glCreateProgram();
    a = compile(GL_VERTEX_SHADER, vs);
    b = compile(GL_FRAGMENT_SHADER, fs);
    glAttachShader(e->prog, a);
    glAttachShader(e->prog, b);
    glLinkProgram(e->prog);
    glGetProgramiv(e->prog, GL_LINK_STATUS, &ok);
    assert_true(ok);
    glDeleteShader(a);
    glDeleteShader(b);
    obox_mesh(&g_occ0, pos, idx);
    glGenVertexArrays(1, &e->vao);
    glBindVertexArray(e->vao);
    glGenBuffers(1, &e->vbo);
    glBindBuffer(GL_ARRAY_BUFFER, e->vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof pos, pos, GL_STATIC_DRAW);
    glGenBuffers(1, &e->ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof idx, idx, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
    glEnableVertexAttribArray(0);
    glBindVertexArray(0);
}

static void engine_create(engine *e, int w, int h, int samples) { engine_create_ex(e, w, h, samples, 0); }

static void engine_destroy(engine *e)
{
    glDeleteFramebuffers(1, &e->fbo);
    glDeleteFramebuffers(1, &e->resolve_fbo);
    if (e->rb_color) glDeleteRenderbuffers(1, &e->rb_color);
    if (e->tex_color) glDeleteTextures(1, &e->tex_color);
    if (e->rb_depth) glDeleteRenderbuffers(1, &e->rb_depth);
    if (e->tex_depth) glDeleteTextures(1, &e->tex_depth);
    glDeleteRenderbuffers(1, &e->rb_resolve);
    glDeleteProgram(e->prog);
    glDeleteVertexArrays(1, &e->vao);
    glDeleteBuffers(1, &e->vbo);
    glDeleteBuffers(1, &e->ibo);
}

/* The engine's opaque pass into viewport vp: background and (occluder) the occluder box moved by
   g_model (view = identity). */
static void engine_draw_view(engine *e, const int vp[4], int occluder)
{
    float mvp[16];
    int i, k;
    for (i = 0; i < 16; ++i) {
        double v = 0;
        for (k = 0; k < 4; ++k) v += (double)g_proj[k * 4 + i % 4] * g_model[(i / 4) * 4 + k];
        mvp[i] = (float)v;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glViewport(vp[0], vp[1], vp[2], vp[3]);
    glScissor(vp[0], vp[1], vp[2], vp[3]);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_MULTISAMPLE);
    glClearColor(k_bg[0], k_bg[1], k_bg[2], 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(e->prog);
    glUniformMatrix4fv(glGetUniformLocation(e->prog, "mvp"), 1, GL_FALSE, mvp);
    glUniform3fv(glGetUniformLocation(e->prog, "col"), 1, k_occ);
    glBindVertexArray(e->vao);
    if (occluder) glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_INT, NULL);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
}

static void engine_draw(engine *e)
{
    const int vp[4] = {0, 0, e->w, e->h};
    engine_draw_view(e, vp, 1);
}

static void engine_resolve(engine *e, unsigned char *rgba)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, e->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, e->resolve_fbo);
    glBlitFramebuffer(0, 0, e->w, e->h, 0, 0, e->w, e->h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, e->resolve_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, e->w, e->h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
}

/* ---- fogvol ------------------------------------------------------------------ */
static fogvol_msaa g_msaa; /* of the context fv_create made last */
typedef struct fv_scene {
    fogvol_context *fv;
    fogvol_mesh *vol, *occ;
    fogvol_ramp *ramp;
} fv_scene;

static fogvol_result fv_create(fv_scene *s, fogvol_tier tier, unsigned variants, fogvol_dialect dialect,
                               fogvol_msaa msaa)
{
    fogvol_context_desc cd;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    float pos[24];
    uint32_t idx[36];
    fogvol_result r;
    memset(s, 0, sizeof *s);
    memset(&cd, 0, sizeof cd);
    cd.logger.func = logger;
    cd.tier = tier;
    cd.variants = variants;
    cd.msaa = msaa;
    cd.gl.get_proc_address = glu_proc;
    cd.gl.dialect = dialect;
    cd.gl.software = 1; /* FLOAT + ENGINE_DEPTH depth-tested on any GL (a GPU's would read the depth per face) */
    g_msaa = msaa;
    r = fogvol_create_context(&cd, &s->fv);
    if (r != FOGVOL_SUCCESS) return r;
    memset(&md, 0, sizeof md);
    md.positions = pos;
    md.vertex_count = 8;
    md.indices = idx;
    md.index_count = 36;
    obox_mesh(&g_vol0, pos, idx);
    assert_int_equal(fogvol_create_mesh(s->fv, &md, &s->vol, NULL), FOGVOL_SUCCESS);
    obox_mesh(&g_occ0, pos, idx);
    assert_int_equal(fogvol_create_mesh(s->fv, &md, &s->occ, NULL), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_LINEAR;
    memcpy(rd.color, k_fog, sizeof rd.color);
    rd.density = DENSITY;
    assert_int_equal(fogvol_create_ramp(s->fv, &rd, &s->ramp), FOGVOL_SUCCESS);
    return FOGVOL_SUCCESS;
}

static void fv_destroy(fv_scene *s)
{
    fogvol_destroy_mesh(s->fv, s->vol);
    fogvol_destroy_mesh(s->fv, s->occ);
    fogvol_destroy_ramp(s->fv, s->ramp);
    fogvol_destroy_context(s->fv);
}

static fogvol_composite g_composite; /* of the next frames */
/* ENGINE_DEPTH cases: where the engine's depth comes from (else fogvol draws the occluder) */
enum { DEPTH_NONE, DEPTH_BOUND, DEPTH_BY_NAME, DEPTH_TEXTURE, DEPTH_ENGINE_O, DEPTH_TEXTURE_UNFIXED };
/* the engine framebuffer's kind of depth buffer for engine_create_ex: a renderbuffer, a multisample depth texture
   (DEPTH_TEXTURE), the same made with fixedsamplelocations GL_FALSE (DEPTH_TEXTURE_UNFIXED) */
#define DEPTH_KIND(d) ((d) == DEPTH_TEXTURE ? 1 : (d) == DEPTH_TEXTURE_UNFIXED ? 2 : 0)
static int g_depth; /* (DEPTH_ENGINE_O: no ENGINE_DEPTH; the engine draws the occluder into fogvol's O) */
static const engine *g_engine; /* whose depth */

/* DEPTH_ENGINE_O: the engine draws the occluder box (model) into fogvol's O itself
   (fogvol_occluder_prepare, fogvol_occluder_snippet) with a depth buffer of O's sample count, which is
   the engine framebuffer's bound now (single-sample with FOGVOL_MSAA_SINGLE_SAMPLE), then binds that
   framebuffer again for end_frame. */
static void engine_o(fv_scene *s, const float model[16])
{
    static const char *vs = "#version 330 core\nlayout(location = 0) in vec3 p;\nuniform mat4 mv, proj;\n"
                            "out float vd;\nvoid main() { vec4 q = mv * vec4(p, 1.0); vd = -q.z; gl_Position = proj * q; }\n";
    const char *fs[3];
    fogvol_occluder_info oi;
    GLint bound = 0, samples = 0, ok = 0;
    GLuint prog, a, b, fbo, rb;
    GLenum target;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    glGetIntegerv(GL_SAMPLES, &samples);
    assert_int_equal(fogvol_occluder_prepare(s->fv, &oi), FOGVOL_SUCCESS);
    assert_int_equal(oi.samples, samples > 1 && g_msaa != FOGVOL_MSAA_SINGLE_SAMPLE ? samples : 0);
    fs[0] = "#version 330 core\n";
    fs[1] = fogvol_occluder_snippet();
    fs[2] = "in float vd;\nout vec4 o;\nvoid main() { o = fogvol_occluder_color(vd); }\n";
    prog = glCreateProgram();
    a = compile(GL_VERTEX_SHADER, vs);
    b = glCreateShader(GL_FRAGMENT_SHADER);
    glShaderSource(b, 3, fs, NULL);
    glCompileShader(b);
    glAttachShader(prog, a);
    glAttachShader(prog, b);
    glLinkProgram(prog);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    assert_true(ok);
    glDeleteShader(a);
    glDeleteShader(b);
    target = oi.samples ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    if (oi.samples) glRenderbufferStorageMultisample(GL_RENDERBUFFER, oi.samples, GL_DEPTH_COMPONENT24, oi.width, oi.height);
    else glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, oi.width, oi.height);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, target, (GLuint)oi.texture, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glViewport(0, 0, oi.width, oi.height);
    glClearBufferfv(GL_COLOR, 0, oi.clear_color);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "mv"), 1, GL_FALSE, model);
    glUniformMatrix4fv(glGetUniformLocation(prog, "proj"), 1, GL_FALSE, g_proj);
    glUniform4fv(glGetUniformLocation(prog, "fogvol_mrt"), 2, oi.uniforms);
    glBindVertexArray(g_engine->vao);
    glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_INT, NULL);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)bound);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    glDeleteProgram(prog);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

/* The frame desc of viewport vp (view = identity, the scene moved by g_model) and the volume, and
   the occluder unless the engine's depth holds it (occluder 0: nothing occludes). */
static void fv_begin(fv_scene *s, const int vp[4], int occluder, float *debug)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    float ident[16], model[16];
    int i;
    glu_identity(ident);
    for (i = 0; i < 16; ++i) model[i] = (float)g_model[i];
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, ident, sizeof ident);
    memcpy(fd.projection, g_proj, sizeof g_proj);
    fd.znear = (float)ZNEAR;
    fd.zfar = (float)ZFAR;
    memcpy(fd.viewport, vp, sizeof fd.viewport);
    fd.debug_thickness = debug;
    fd.composite = g_composite;
    if (g_depth == DEPTH_BOUND) fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
    if (g_depth == DEPTH_BY_NAME) fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT;
    fd.engine_depth_framebuffer = g_engine ? g_engine->fbo : 0;
    fd.engine_depth_texture = DEPTH_KIND(g_depth) && g_engine ? g_engine->tex_depth : 0;
    assert_int_equal(fogvol_begin_frame(s->fv, &fd), FOGVOL_SUCCESS);
    if (!g_depth && occluder) assert_int_equal(fogvol_add_occluder(s->fv, s->occ, model), FOGVOL_SUCCESS);
    if (g_depth == DEPTH_ENGINE_O && occluder) engine_o(s, model);
    memset(&vd, 0, sizeof vd);
    vd.mesh = s->vol;
    memcpy(vd.model, model, sizeof model);
    vd.ramp = s->ramp;
    assert_int_equal(fogvol_add_volume(s->fv, &vd), FOGVOL_SUCCESS);
}

/* One fogvol frame into the engine framebuffer bound now. */
static fogvol_result fv_frame(fv_scene *s, int w, int h, fogvol_frame_stats *st, float *debug)
{
    const int vp[4] = {0, 0, w, h};
    fv_begin(s, vp, 1, debug);
    return fogvol_end_frame(s->fv, st);
}

/* ---- comparison ---------------------------------------------------------------- */
typedef struct errs {
    double mean_all, mean_edge;
    int max_all, max_edge, edges, max_sil;
} errs;

static unsigned char *g_truth; /* resolved truth, RGBA */
static unsigned char *g_edge;  /* 1: an occluder edge inside fog (the samples disagree on the occluder,
                                  some see fog); 2: a volume silhouette (the samples disagree on fog) */

/* What the GL's vertex snapping (2^-GL_SUBPIXEL_BITS pixels) may change in the resolved 8-bit colour
   of the sample at (x, y) of a w x h viewport: the largest channel difference between the truth there
   and at the sample moved by that much, over NS (the resolve's share of one sample). */
static double sample_slack(double x, double y, int w, int h, const unsigned char at[3], double snap, int ns)
{
    double m = 0;
    int k, c;
    for (k = 0; k < 4; ++k) {
        unsigned char o[3];
        truth_sample(x + ((k & 1) ? snap : -snap), y + ((k & 2) ? snap : -snap), w, h, o);
        for (c = 0; c < 3; ++c)
            if (abs((int)o[c] - (int)at[c]) > m) m = abs((int)o[c] - (int)at[c]);
    }
    return m / ns;
}

/* The engine framebuffer's sample positions (single-sample: the pixel centre) and count, and the
   GL's vertex snapping grid in pixels. */
static int sample_positions(engine *e, const float (**sp)[2], double *snap_px)
{
    static float sp4[NS][2];
    static const float sp1[1][2] = {{0.5f, 0.5f}};
    static double snap;
    static int have_sp;
    int i;
    if (!have_sp) {
        GLint samples = 0, bits = 0;
        glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
        glGetIntegerv(GL_SAMPLES, &samples);
        assert_int_equal(samples, NS);
        for (i = 0; i < NS; ++i) glGetMultisamplefv(GL_SAMPLE_POSITION, (GLuint)i, sp4[i]);
        glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
        snap = ldexp(1.0, -(bits < 4 ? 4 : bits));
        have_sp = 1;
    }
    *sp = e->samples > 1 ? (const float(*)[2])sp4 : sp1;
    *snap_px = snap;
    return e->samples > 1 ? NS : 1;
}

/* What vertex snapping and the GL's choice of where it evaluates depth may change in the resolved
   colour of window pixel (x, y) of viewport vp (sample_slack, centre_slack over its samples). */
static double pixel_slack(engine *e, const int vp[4], int x, int y)
{
    const float(*sp)[2];
    double snap, sum = 0;
    int k, ns = sample_positions(e, &sp, &snap);
    for (k = 0; k < ns; ++k) {
        double sx = x - vp[0] + sp[k][0], sy = y - vp[1] + sp[k][1];
        unsigned char at[3];
        truth_sample(sx, sy, vp[2], vp[3], at);
        sum += sample_slack(sx, sy, vp[2], vp[3], at, snap, ns) +
               centre_slack(sx, sy, x - vp[0] + 0.5, y - vp[1] + 0.5, vp[2], vp[3], at);
    }
    return sum;
}

/* The resolved truth of viewport vp (the camera of g_model and g_proj) into the W x H images truth
   and edge (1: an occluder edge inside fog; 2: a volume silhouette), at the engine framebuffer's own
   sample positions (single-sample: the pixel centre). */
static void truth_rect(engine *e, const int vp[4], unsigned char *truth, unsigned char *edge)
{
    const float(*sp)[2];
    double snap;
    int x, y, c, k, ns = sample_positions(e, &sp, &snap);
    for (y = vp[1]; y < vp[1] + vp[3]; ++y)
        for (x = vp[0]; x < vp[0] + vp[2]; ++x) {
            unsigned char s[NS][3];
            int sum[3] = {0, 0, 0}, any = 0, all = 3;
            for (k = 0; k < ns; ++k) {
                int f = truth_sample(x - vp[0] + sp[k][0], y - vp[1] + sp[k][1], vp[2], vp[3], s[k]);
                any |= f;
                all &= f;
                for (c = 0; c < 3; ++c) sum[c] += s[k][c];
            }
            edge[y * W + x] = 0;
            if ((any & 1) != (all & 1) && (any & 2)) edge[y * W + x] = 1;
            else if ((any & 2) != (all & 2)) edge[y * W + x] = 2;
            for (c = 0; c < 3; ++c) truth[(y * W + x) * 4 + c] = (unsigned char)((sum[c] + ns / 2) / ns);
            truth[(y * W + x) * 4 + 3] = 255;
        }
}

static void build_truth(engine *e)
{
    const int vp[4] = {0, 0, W, H};
    g_truth = (unsigned char *)calloc((size_t)W * H, 4);
    g_edge = (unsigned char *)calloc((size_t)W * H, 1);
    truth_rect(e, vp, g_truth, g_edge);
}

static errs compare(const unsigned char *img)
{
    errs r;
    long sa = 0, se = 0;
    int i, c;
    memset(&r, 0, sizeof r);
    for (i = 0; i < W * H; ++i) {
        int m = 0;
        for (c = 0; c < 3; ++c) {
            int d = abs((int)img[i * 4 + c] - (int)g_truth[i * 4 + c]);
            if (d > m) m = d;
        }
        sa += m;
        if (m > r.max_all) r.max_all = m;
        if (g_edge[i] == 2) r.max_sil = m > r.max_sil ? m : r.max_sil;
        if (g_edge[i] == 1) {
            r.edges++;
            se += m;
            if (m > r.max_edge) r.max_edge = m;
        }
    }
    r.mean_all = (double)sa / (W * H);
    r.mean_edge = r.edges ? (double)se / r.edges : 0;
    return r;
}

static void write_png(const unsigned char *before, const unsigned char *after)
{
    const int S = 3, PW = W * 5 * S;
    const unsigned char *img[3] = {g_truth, before, after};
    unsigned char *out = (unsigned char *)calloc((size_t)PW * H * S, 4);
    int x, y, p, c;
    for (y = 0; y < H * S; ++y)
        for (x = 0; x < W * 5 * S; ++x) {
            int panel = x / (W * S), sx = (x % (W * S)) / S, sy = H - 1 - y / S, i = sy * W + sx;
            unsigned char *o = out + ((size_t)y * PW + x) * 4;
            for (c = 0; c < 3; ++c) {
                if (panel < 3) {
                    o[c] = img[panel][i * 4 + c];
                } else {
                    p = abs((int)img[panel - 2][i * 4 + c] - (int)g_truth[i * 4 + c]) * 8;
                    o[c] = (unsigned char)(p > 255 ? 255 : p);
                }
            }
            o[3] = 255;
        }
    mkdir("build", 0755);
    stbi_write_png("build/engine_msaa.png", PW, H * S, 4, out, PW * 4);
    free(out);
}

/* ---- tests ------------------------------------------------------------------------ */
typedef struct tcase {
    fogvol_tier tier;
    unsigned variants;
    const char *name;
    int bound; /* max error (/255) over every pixel after the fix */
    fogvol_composite composite;
    int depth; /* DEPTH_NONE: fogvol draws the occluder; else ENGINE_DEPTH from the engine framebuffer
                  bound, named, or its multisample depth texture */
} tcase;

static const tcase g_cases[] = {
    {FOGVOL_TIER_FLOAT, 0, "FLOAT", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_NONE},
    {FOGVOL_TIER_PS20, 0, "PS20", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_NONE},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, "PS20+single", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_NONE},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, "PS20+count", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_NONE},
    {FOGVOL_TIER_PS13, 0, "PS13", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_NONE},
    {FOGVOL_TIER_FLOAT, 0, "FLOAT+geometry", 3, FOGVOL_COMPOSITE_GEOMETRY, DEPTH_NONE}, /* stencil per sample */
    /* the engine's depth, every sample of it */
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth bound", 3, FOGVOL_COMPOSITE_FULLSCREEN,
     DEPTH_BOUND},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth by name", 3, FOGVOL_COMPOSITE_GEOMETRY,
     DEPTH_BY_NAME},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth texture", 3, FOGVOL_COMPOSITE_FULLSCREEN,
     DEPTH_TEXTURE},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, "PS20+enginedepth bound", 3, FOGVOL_COMPOSITE_FULLSCREEN,
     DEPTH_BOUND},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH | FOGVOL_VARIANT_SINGLE_TARGET, "PS20+single+enginedepth by name",
     3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_BY_NAME},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, "PS20+enginedepth texture", 3, FOGVOL_COMPOSITE_FULLSCREEN,
     DEPTH_TEXTURE},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth texture, unfixed", 3,
     FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_TEXTURE_UNFIXED},
    /* the engine draws the occluder into fogvol's O (fogvol_occluder_prepare), per sample */
    {FOGVOL_TIER_FLOAT, 0, "FLOAT engine-drawn O", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_ENGINE_O},
    {FOGVOL_TIER_PS20, 0, "PS20 engine-drawn O", 3, FOGVOL_COMPOSITE_FULLSCREEN, DEPTH_ENGINE_O},
};
#define NCASES ((int)(sizeof g_cases / sizeof g_cases[0]))

static void test_tier(void **state)
{
    const tcase *tc = (const tcase *)*state;
    glu_ctx g;
    engine e;
    fv_scene s;
    fogvol_frame_stats st;
    unsigned char *before = (unsigned char *)malloc((size_t)W * H * 4);
    unsigned char *after = (unsigned char *)malloc((size_t)W * H * 4);
    errs eb, ea;
    assert_true(glu_create(&g, 16, 16, 1));
    scene_init(W, H);
    engine_create_ex(&e, W, H, NS, DEPTH_KIND(tc->depth));
    if (!g_truth) build_truth(&e);
    g_composite = tc->composite;
    g_depth = tc->depth;
    g_engine = &e;

    /* before: single-sample targets, one fog value per pixel (opt-in fallback; with the engine's
       depth, resolved to one sample per pixel; a multisample depth texture has no single-sample
       reading: before this version such frames were refused) */
    if (!DEPTH_KIND(tc->depth)) {
        assert_int_equal(fv_create(&s, tc->tier, tc->variants, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_SINGLE_SAMPLE), 0);
        engine_draw(&e);
        g_log[0] = 0;
        assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
        assert_int_equal(st.msaa_fallback, 1);
        assert_int_equal(st.samples, 1);
        assert_non_null(strstr(g_log, "single-sample"));
        assert_int_equal(glGetError(), GL_NO_ERROR);
        engine_resolve(&e, before);
        fv_destroy(&s);
    }

    /* after: per-sample targets and shading */
    assert_int_equal(fv_create(&s, tc->tier, tc->variants, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
    engine_draw(&e);
    assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
    assert_int_equal(st.msaa_fallback, 0);
    assert_int_equal(st.samples, NS);
    /* FLOAT + engine depth: the faces depth-tested against the engine's multisample depth, shaded once per
       pixel (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST); the others read the depth per sample */
    assert_int_equal(st.engine_depth_tested,
                     tc->tier == FOGVOL_TIER_FLOAT && (tc->variants & FOGVOL_VARIANT_ENGINE_DEPTH) ? 1 : 0);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    engine_resolve(&e, after);
    /* a second frame reuses the targets and programs and gives the same image */
    engine_draw(&e);
    assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
    {
        unsigned char *again = (unsigned char *)malloc((size_t)W * H * 4);
        engine_resolve(&e, again);
        if (!(tc->variants & FOGVOL_VARIANT_SINGLE_TARGET) || tc->tier == FOGVOL_TIER_FLOAT)
            assert_memory_equal(again, after, (size_t)W * H * 4);
        free(again);
    }
    if (tc->depth == DEPTH_TEXTURE_UNFIXED) { /* one sum attached to fixed and unfixed engine depths in turn */
        unsigned char *img = (unsigned char *)malloc((size_t)W * H * 4);
        engine e2;
        int k;
        engine_create_ex(&e2, W, H, NS, 1);
        for (k = 0; k < 4; ++k) {
            engine *ek = k & 1 ? &e : &e2;
            errs er;
            g_engine = ek;
            engine_draw(ek);
            assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
            assert_int_equal(st.engine_depth_tested, 1);
            engine_resolve(ek, img);
            er = compare(img);
            print_message("#   frame %d, the %s engine depth: all max %d, edges mean %.2f [/255]\n", k,
                          k & 1 ? "unfixed" : "fixed", er.max_all, er.mean_edge);
            assert_true(er.max_all <= tc->bound);
        }
        g_engine = &e;
        engine_destroy(&e2);
        free(img);
    }
    fv_destroy(&s);

    if (DEPTH_KIND(tc->depth)) memcpy(before, after, (size_t)W * H * 4);
    eb = compare(before);
    ea = compare(after);
    print_message("# %-31s %d occluder-edge pixels in fog | before: edges mean %.2f max %d, silhouettes max %d, "
                  "all mean %.3f max %d | after: edges mean %.2f max %d, silhouettes max %d, all mean %.3f max %d "
                  "[/255]\n",
                  tc->name, ea.edges, eb.mean_edge, eb.max_edge, eb.max_sil, eb.mean_all, eb.max_all, ea.mean_edge,
                  ea.max_edge, ea.max_sil, ea.mean_all, ea.max_all);
    if (tc->tier == FOGVOL_TIER_FLOAT) write_png(before, after);
    assert_true(ea.edges > 50); /* the scene has occluder edges inside the fog */
    if (!DEPTH_KIND(tc->depth)) {
        assert_true(eb.mean_edge > 10.0); /* single-sample targets get edges wrong */
        assert_true(eb.max_edge > 40);
    }
    assert_true(ea.max_all <= tc->bound);         /* per sample: within the 8-bit result everywhere */
    assert_true(ea.mean_edge <= 1.5);
    g_composite = FOGVOL_COMPOSITE_FULLSCREEN;
    g_depth = DEPTH_NONE;
    g_engine = NULL;
    engine_destroy(&e);
    glu_destroy(&g);
    free(before);
    free(after);
}

/* ---- sequences (tests/sequence.h) ---------------------------------------------------------
   Each case through the default script: the camera walks into the fog box (the scene moves and
   turns in view space) and out again, the occluder leaves and comes back (the engine stops drawing
   it; fogvol is not given it), the viewport shrinks to a rectangle at an offset, a split-screen
   frame draws two views with their own cameras into the two halves (each its own fogvol frame,
   the engine's depth of that view; the second into a single-sample engine framebuffer, as a
   minimap or a reflection drawn without MSAA: fogvol switches to single-sample targets and
   programs and back), a cancelled frame comes in between. Every view's resolved
   pixels are compared with the per-sample truth of its own camera; wrong: more than the case's
   bound (3/255, the single-frame test's), and the mean over occluder edges inside fog stays within
   the single-frame bound (1.5/255). PS20+count keeps the camera outside the volume (COUNT refuses
   a volume the near plane cuts). */
typedef struct mseq {
    const tcase *tc;
    engine e, e1; /* the 4x engine framebuffer; e1: single-sample, for the second view of split frames */
    fv_scene s;
    unsigned char *img, *truth, *edge, *sheet;
    int failed; /* views whose end_frame failed */
    int tested, drawn; /* views drawn depth-tested (fogvol_frame_stats.engine_depth_tested), views drawn */
    double edge_sum;
    long edges;
} mseq;

static double mseq_walk(const mseq *m, double walk)
{
    return (m->tc->variants & FOGVOL_VARIANT_COUNT) ? 0.35 * walk : walk;
}

static void mseq_cancel(void *user, const sq_view *v)
{
    mseq *m = (mseq *)user;
    g_engine = &m->e;
    scene_pose(mseq_walk(m, 1.0 - v->walk), v->viewport[2], v->viewport[3]);
    fv_begin(&m->s, v->viewport, 1, NULL);
    assert_int_equal(fogvol_cancel_frame(m->s.fv), FOGVOL_SUCCESS);
}

/* frame f's column of the contact sheet: the resolved framebuffer over the truth over 8x the error */
static void mseq_sheet(mseq *m, const sq_view *v)
{
    int x, y, c, r;
    if (!m->sheet || v->frame >= SQ_DEFAULT_FRAMES) return;
    for (y = v->viewport[1]; y < v->viewport[1] + v->viewport[3]; ++y)
        for (x = v->viewport[0]; x < v->viewport[0] + v->viewport[2]; ++x)
            for (r = 0; r < 3; ++r) {
                unsigned char *o = m->sheet + (((size_t)(r * H + H - 1 - y) * W * SQ_DEFAULT_FRAMES) +
                                               (size_t)v->frame * W + x) * 3;
                for (c = 0; c < 3; ++c) {
                    int a = m->img[(y * W + x) * 4 + c], t = m->truth[(y * W + x) * 4 + c], d = abs(a - t) * 8;
                    o[c] = (unsigned char)(r == 0 ? a : r == 1 ? t : d > 255 ? 255 : d);
                }
            }
}

static void mseq_view(void *user, const sq_view *v, sq_check *out)
{
    mseq *m = (mseq *)user;
    engine *e = v->view == 1 ? &m->e1 : &m->e;
    fogvol_frame_stats st;
    fogvol_result r;
    int x, y, c;
    scene_pose(mseq_walk(m, v->walk), v->viewport[2], v->viewport[3]);
    g_occ_on = v->occluders;
    g_engine = e;
    engine_draw_view(e, v->viewport, v->occluders);
    fv_begin(&m->s, v->viewport, v->occluders, NULL);
    r = fogvol_end_frame(m->s.fv, &st);
    if (r != FOGVOL_SUCCESS && !m->failed++) print_message("#   end_frame: %s\n", fogvol_result_string(r));
    assert_int_equal(glGetError(), GL_NO_ERROR);
    if (r == FOGVOL_SUCCESS) assert_int_equal(st.samples, e->samples > 1 ? NS : 1);
    m->tested += r == FOGVOL_SUCCESS && st.engine_depth_tested;
    m->drawn += r == FOGVOL_SUCCESS;
    engine_resolve(e, m->img);
    truth_rect(e, v->viewport, m->truth, m->edge);
    out->bound = m->tc->bound;
    for (y = v->viewport[1]; y < v->viewport[1] + v->viewport[3]; ++y)
        for (x = v->viewport[0]; x < v->viewport[0] + v->viewport[2]; ++x) {
            int i = y * W + x, d = 0;
            double slack = 0.0;
            for (c = 0; c < 3; ++c) {
                int dc = abs((int)m->img[i * 4 + c] - (int)m->truth[i * 4 + c]);
                if (dc > d) d = dc;
            }
            out->pixels++;
            if (r != FOGVOL_SUCCESS) d = 255; /* nothing drawn: the view is wrong */
            if (d > m->tc->bound) slack = pixel_slack(e, v->viewport, x, y); /* (only where it matters) */
            out->wrong += d > m->tc->bound + slack;
            if (d - slack > out->max_err) out->max_err = d - slack;
            if (m->edge[i] == 1) {
                m->edges++;
                m->edge_sum += d;
            }
        }
    mseq_sheet(m, v);
    g_occ_on = 1;
}

/* One case through n frames of a script; the resolved pictures of the default script's frames go
   to build/engine_msaa_sequence.png for the first ENGINE_DEPTH case. */
static void run_mseq(const tcase *tc, const sq_step *steps, int n, const char *what)
{
    static const double origin[3] = {0.0, 0.0, 0.0};
    glu_ctx g;
    mseq m;
    char name[80], where[200];
    sq_totals t;
    assert_true(glu_create(&g, 16, 16, 1));
    memset(&m, 0, sizeof m);
    m.tc = tc;
    scene_init(W, H);
    scene_pose(mseq_walk(&m, 1.0), W, H); /* the walk's end: inside the fog, outside the occluder */
    assert_int_equal(obox_contains(&g_vol, origin), !(tc->variants & FOGVOL_VARIANT_COUNT));
    assert_false(obox_contains(&g_occ, origin));
    scene_init(W, H);
    engine_create_ex(&m.e, W, H, NS, DEPTH_KIND(tc->depth));
    engine_create_ex(&m.e1, W, H, 1, DEPTH_KIND(tc->depth));
    g_composite = tc->composite;
    g_depth = tc->depth;
    g_engine = &m.e;
    assert_int_equal(fv_create(&m.s, tc->tier, tc->variants, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
    m.img = (unsigned char *)calloc((size_t)W * H, 4);
    m.truth = (unsigned char *)calloc((size_t)W * H, 4);
    m.edge = (unsigned char *)calloc((size_t)W * H, 1);
    if (tc == &g_cases[6] && steps == sq_default_script)
        m.sheet = (unsigned char *)calloc((size_t)W * SQ_DEFAULT_FRAMES * H * 3, 3);
    snprintf(name, sizeof name, "MSAA %s%s", what, tc->name);
    t = sq_play(name, W, H, steps, n, SQ_ALL, mseq_view, mseq_cancel, &m, where);
    print_message("#   occluder edges inside fog: mean %.2f over %ld pixels, max %.0f [/255]%s; %d of %d views "
                  "depth-tested\n",
                  m.edges ? m.edge_sum / m.edges : 0.0, m.edges, t.worst * tc->bound,
                  m.failed ? "; end_frame failed" : "", m.tested, m.drawn);
    /* FLOAT + engine depth: views that fit depth-tested (multisampled or not, at any viewport); the
       other tiers never */
    if (tc->tier == FOGVOL_TIER_FLOAT && (tc->variants & FOGVOL_VARIANT_ENGINE_DEPTH))
        assert_true(m.tested > 0);
    else
        assert_int_equal(m.tested, 0);
    if (m.sheet) {
        mkdir("build", 0755);
        stbi_write_png("build/engine_msaa_sequence.png", W * SQ_DEFAULT_FRAMES, H * 3, 3, m.sheet,
                       W * SQ_DEFAULT_FRAMES * 3);
    }
    if (t.wrong) fail_msg("sequence %s: %ld wrong pixels; the first in %s", name, t.wrong, where);
    assert_true(m.edges > 100);
    assert_true(m.edge_sum / m.edges <= 1.5);
    fv_destroy(&m.s);
    engine_destroy(&m.e);
    engine_destroy(&m.e1);
    glu_destroy(&g);
    g_composite = FOGVOL_COMPOSITE_FULLSCREEN;
    g_depth = DEPTH_NONE;
    g_engine = NULL;
    free(m.img);
    free(m.truth);
    free(m.edge);
    free(m.sheet);
    scene_init(W, H);
}

static void test_sequence(void **state)
{
    run_mseq((const tcase *)*state, sq_default_script, SQ_DEFAULT_FRAMES, "");
}

/* The engine's depth per sample over tests/sequence.h's 60-frame walk (into the fog and out, the
   occluder leaving 3 frames in 8, split-screen, cancelled and smaller-viewport frames). */
#define MSAA_WALK_FRAMES 60
static void test_walk(void **state)
{
    sq_step steps[MSAA_WALK_FRAMES];
    sq_walk_script(steps, MSAA_WALK_FRAMES);
    run_mseq((const tcase *)*state, steps, MSAA_WALK_FRAMES, "walk ");
}

/* 1 when the rays through (sx, sy) moved by the vertex snapping grid (snap pixels) in x and y cross
   the fog box through faces f0 and f1 as the ray through (sx, sy) does: the GL may cover a sample
   nearer an edge than that with the neighbouring face (NVIDIA snaps to 1/256 pixel) */
static int same_faces_near(double sx, double sy, int f0, int f1, double snap)
{
    int j;
    for (j = 0; j < 4; ++j) {
        double dir[3], a0, a1;
        int g0, g1;
        dir[0] = (2.0 * (sx + (j == 0 ? snap : j == 1 ? -snap : 0.0)) / W - 1.0) / g_proj[0];
        dir[1] = (2.0 * (sy + (j == 2 ? snap : j == 3 ? -snap : 0.0)) / H - 1.0) / g_proj[5];
        dir[2] = -1.0;
        if (!obox_ray_faces(&g_vol, dir, &a0, &a1, &g0, &g1) || g0 != f0 || g1 != f1) return 0;
    }
    return 1;
}

/* The GL itself, without fogvol: a plain program sums the signed view depth w of the fog box's
   faces per sample (per-sample shading, 4x), at the walk's half-way pose, where the box's top face
   is seen nearly edge-on. Each sample's sum must be the ray cast's thickness at the sample, or
   what the faces' depths evaluated at the pixel centre give (the envelope centre_slack allows in
   the sequences). Prints how many samples took the pixel centre's depths (llvmpipe: some). */
static void test_gl_sample_depths(void **state)
{
    static const char *vs = "#version 330 core\nlayout(location = 0) in vec3 p;\nuniform mat4 mvp;\n"
                            "void main() { gl_Position = mvp * vec4(p, 1.0); }\n";
    static const char *fs = "#version 400\nout vec4 o;\n"
                            "void main() { float w = 1.0 / gl_FragCoord.w; o = vec4(gl_FrontFacing ? -w : w); }\n";
    static const char *fs_fetch = "#version 330 core\nuniform sampler2DMS s;\nout vec4 o;\nvoid main() {\n"
                                  "    ivec2 c = ivec2(gl_FragCoord.xy);\n"
                                  "    o = texelFetch(s, ivec2(c.x / 4, c.y), c.x % 4);\n}\n";
    static const char *vs_full = "#version 330 core\nlayout(location = 0) in vec3 p;\n"
                                 "void main() { gl_Position = vec4(p.xy, 0.0, 1.0); }\n";
    static const float tri[9] = {-1, -1, 0, 3, -1, 0, -1, 3, 0};
    glu_ctx g;
    float pos[24], sp[NS][2], *out = (float *)malloc(sizeof(float) * 4 * W * NS * H);
    uint32_t idx[36];
    GLuint prog[2], vao, vbo[2], ibo, tex[2], fb[2];
    int x, y, k, centre = 0, outside = 0, samples = 0;
    double snap = snap_pixels();
    (void)state;
    assert_true(glu_create(&g, 16, 16, 1));
    scene_init(W, H);
    scene_pose(0.5, W, H);
    g_occ_on = 0;
    prog[0] = glCreateProgram();
    glAttachShader(prog[0], compile(GL_VERTEX_SHADER, vs));
    glAttachShader(prog[0], compile(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(prog[0]);
    prog[1] = glCreateProgram();
    glAttachShader(prog[1], compile(GL_VERTEX_SHADER, vs_full));
    glAttachShader(prog[1], compile(GL_FRAGMENT_SHADER, fs_fetch));
    glLinkProgram(prog[1]);
    obox_mesh(&g_vol, pos, idx); /* (view space: mvp = projection) */
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(2, vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo[1]);
    glBufferData(GL_ARRAY_BUFFER, sizeof tri, tri, GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, vbo[0]);
    glBufferData(GL_ARRAY_BUFFER, sizeof pos, pos, GL_STATIC_DRAW);
    glGenBuffers(1, &ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof idx, idx, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
    glEnableVertexAttribArray(0);
    glGenTextures(2, tex);
    glGenFramebuffers(2, fb);
    glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, tex[0]);
    glTexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, NS, GL_RGBA32F, W, H, GL_TRUE);
    glBindFramebuffer(GL_FRAMEBUFFER, fb[0]);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D_MULTISAMPLE, tex[0], 0);
    for (k = 0; k < NS; ++k) glGetMultisamplefv(GL_SAMPLE_POSITION, (GLuint)k, sp[k]);
    glViewport(0, 0, W, H);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glEnable(GL_MULTISAMPLE);
    glEnable(GL_SAMPLE_SHADING);
    glMinSampleShading(1.0f);
    glUseProgram(prog[0]);
    glUniformMatrix4fv(glGetUniformLocation(prog[0], "mvp"), 1, GL_FALSE, g_proj);
    glDrawElements(GL_TRIANGLES, 36, GL_UNSIGNED_INT, NULL);
    glDisable(GL_BLEND);
    glDisable(GL_SAMPLE_SHADING);
    glBindTexture(GL_TEXTURE_2D, tex[1]); /* every sample into a 4W x H float texture */
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, NS * W, H, 0, GL_RGBA, GL_FLOAT, NULL);
    glBindFramebuffer(GL_FRAMEBUFFER, fb[1]);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex[1], 0);
    glViewport(0, 0, NS * W, H);
    glUseProgram(prog[1]);
    glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, tex[0]);
    glBindBuffer(GL_ARRAY_BUFFER, vbo[1]);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glReadPixels(0, 0, NS * W, H, GL_RGBA, GL_FLOAT, out);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x)
            for (k = 0; k < NS; ++k) {
                double sx = x + sp[k][0], sy = y + sp[k][1], dir[3], dc[3], a0, a1, got, lo, hi, t;
                int f0, f1, j;
                dir[0] = (2.0 * sx / W - 1.0) / g_proj[0];
                dir[1] = (2.0 * sy / H - 1.0) / g_proj[5];
                dc[0] = (2.0 * (x + 0.5) / W - 1.0) / g_proj[0];
                dc[1] = (2.0 * (y + 0.5) / H - 1.0) / g_proj[5];
                dir[2] = dc[2] = -1.0;
                if (!obox_ray_faces(&g_vol, dir, &a0, &a1, &f0, &f1) || a0 < ZNEAR) continue;
                if (!same_faces_near(sx, sy, f0, f1, snap)) continue; /* an edge within the snapping grid */
                got = out[((size_t)y * NS * W + (size_t)x * NS + k) * 4];
                lo = hi = t = a1 - a0;
                for (j = 1; j < 4; ++j) { /* entry, exit at the pixel centre */
                    double v = ((j & 2) ? obox_plane(&g_vol, f1, dc) : a1) - ((j & 1) ? obox_plane(&g_vol, f0, dc) : a0);
                    lo = v < lo ? v : lo;
                    hi = v > hi ? v : hi;
                }
                samples++;
                centre += fabs(got - t) > 1e-3 * t;
                outside += got < lo - 1e-3 * t || got > hi + 1e-3 * t;
            }
    print_message("# the GL's own per-sample depths, 4x: %d of %d samples in the fog box took a face depth at the "
                  "pixel centre, %d outside the centre/sample envelope\n",
                  centre, samples, outside);
    assert_true(samples > 10000);
    assert_int_equal(outside, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(2, fb);
    glDeleteTextures(2, tex);
    glDeleteBuffers(2, vbo);
    glDeleteBuffers(1, &ibo);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(prog[0]);
    glDeleteProgram(prog[1]);
    g_occ_on = 1;
    scene_init(W, H);
    glu_destroy(&g);
    free(out);
}

/* The engine's multisample state comes back as it was, whatever it was. */
static void test_state_restored(void **state)
{
    static const struct {
        int ms, shading;
        float min;
    } cfg[2] = {{1, 0, 0.25f}, {0, 1, 0.5f}};
    glu_ctx g;
    engine e;
    fv_scene s;
    fogvol_frame_stats st;
    GLuint tex[2];
    int k;
    (void)state;
    assert_true(glu_create(&g, 16, 16, 1));
    scene_init(W, H);
    engine_create(&e, W, H, NS);
    assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
    glGenTextures(2, tex);
    for (k = 0; k < 2; ++k) {
        GLint b0 = -1, b3 = -1, active = 0;
        GLfloat mn = -1;
        engine_draw(&e);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, tex[0]);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, tex[1]);
        glActiveTexture(GL_TEXTURE1);
        if (cfg[k].ms) glEnable(GL_MULTISAMPLE);
        else glDisable(GL_MULTISAMPLE);
        if (cfg[k].shading) glEnable(GL_SAMPLE_SHADING);
        else glDisable(GL_SAMPLE_SHADING);
        glMinSampleShading(cfg[k].min);
        assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
        assert_int_equal(st.samples, NS);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        assert_int_equal(glIsEnabled(GL_MULTISAMPLE), cfg[k].ms);
        assert_int_equal(glIsEnabled(GL_SAMPLE_SHADING), cfg[k].shading);
        glGetFloatv(GL_MIN_SAMPLE_SHADING_VALUE, &mn);
        assert_true(mn == cfg[k].min);
        glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
        assert_int_equal(active, GL_TEXTURE1);
        glActiveTexture(GL_TEXTURE0);
        glGetIntegerv(GL_TEXTURE_BINDING_2D_MULTISAMPLE, &b0);
        glActiveTexture(GL_TEXTURE3);
        glGetIntegerv(GL_TEXTURE_BINDING_2D_MULTISAMPLE, &b3);
        assert_int_equal(b0, (GLint)tex[0]);
        assert_int_equal(b3, (GLint)tex[1]);
        glActiveTexture(GL_TEXTURE0);
    }
    glEnable(GL_MULTISAMPLE);
    glDisable(GL_SAMPLE_SHADING);
    glDeleteTextures(2, tex);
    fv_destroy(&s);
    engine_destroy(&e);
    glu_destroy(&g);
}

/* Where the per-sample path does not exist: refused with a logged reason and
   the engine framebuffer untouched, or drawn per pixel when opted in. */
static void test_refusals(void **state)
{
    glu_ctx g;
    engine e;
    fv_scene s;
    fogvol_frame_stats st;
    unsigned char *ref = (unsigned char *)malloc((size_t)W * H * 4), *img = (unsigned char *)malloc((size_t)W * H * 4);
    float *debug = (float *)calloc((size_t)W * H, sizeof(float));
    (void)state;
    assert_true(glu_create(&g, 16, 16, 1));
    scene_init(W, H);
    engine_create(&e, W, H, NS);
    engine_draw(&e);
    engine_resolve(&e, ref);

    /* the engine drew its occluders into O prepared for the 4x framebuffer, then binds a single-sample one
       for end_frame: refused, logged, nothing drawn (O would be made again empty) */
    {
        engine e1;
        const int vp[4] = {0, 0, W, H};
        engine_create(&e1, W, H, 1);
        engine_draw(&e1);
        engine_resolve(&e1, img);
        assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
        g_depth = DEPTH_ENGINE_O;
        g_engine = &e;
        glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
        fv_begin(&s, vp, 1, NULL);
        glBindFramebuffer(GL_FRAMEBUFFER, e1.fbo);
        g_log[0] = 0;
        assert_int_equal(fogvol_end_frame(s.fv, &st), FOGVOL_ERROR_INVALID_STATE);
        assert_non_null(strstr(g_log, "occluder_prepare with 4"));
        assert_int_equal(glGetError(), GL_NO_ERROR);
        {
            unsigned char *after = (unsigned char *)malloc((size_t)W * H * 4);
            engine_resolve(&e1, after);
            assert_memory_equal(after, img, (size_t)W * H * 4);
            free(after);
        }
        g_depth = DEPTH_NONE;
        g_engine = NULL;
        fv_destroy(&s);
        engine_destroy(&e1);
        engine_draw(&e);
    }

    /* GLSL 130 has no sampler2DMS / gl_SampleID */
    assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_130, FOGVOL_MSAA_AUTO), 0);
    g_log[0] = 0;
    assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_ERROR_UNSUPPORTED);
    assert_non_null(strstr(g_log, "4-sample engine framebuffer"));
    assert_non_null(strstr(g_log, "GLSL 130"));
    assert_int_equal(glGetError(), GL_NO_ERROR);
    engine_resolve(&e, img);
    assert_memory_equal(img, ref, (size_t)W * H * 4);
    fv_destroy(&s);
    /* ... unless the single-sample fallback is asked for: drawn, reported */
    assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_130, FOGVOL_MSAA_SINGLE_SAMPLE), 0);
    assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
    assert_int_equal(st.msaa_fallback, 1);
    assert_int_equal(st.samples, 1);
    engine_resolve(&e, img);
    assert_memory_not_equal(img, ref, (size_t)W * H * 4);
    fv_destroy(&s);
    engine_draw(&e);

    /* the debug read-back cannot read multisampled targets */
    assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
    g_log[0] = 0;
    assert_int_equal(fv_frame(&s, W, H, &st, debug), FOGVOL_ERROR_UNSUPPORTED);
    assert_non_null(strstr(g_log, "debug_thickness"));
    engine_resolve(&e, img);
    assert_memory_equal(img, ref, (size_t)W * H * 4);
    /* a single-sample engine framebuffer afterwards: single-sample targets again, debug works */
    {
        engine e1;
        int i, n = 0;
        engine_create(&e1, W, H, 1);
        engine_draw(&e1);
        assert_int_equal(fv_frame(&s, W, H, &st, debug), FOGVOL_SUCCESS);
        assert_int_equal(st.samples, 1);
        for (i = 0; i < W * H; ++i) n += debug[i] > 0.5f;
        assert_true(n > 1000);
        engine_destroy(&e1);
    }
    fv_destroy(&s);

    /* the engine's depth per sample from a single-sample framebuffer: each pixel's depth goes to all its
       samples (desktop GL's blit replicates it). (Another sample count is refused, logged: llvmpipe
       makes every multisampled buffer 4x, so no test here reaches it.) */
    {
        engine e1;
        if (!g_truth) build_truth(&e);
        engine_create(&e1, W, H, 1);
        g_depth = DEPTH_BY_NAME;
        g_engine = &e1;
        assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_GLSL_AUTO,
                                   FOGVOL_MSAA_AUTO), 0);
        engine_draw(&e1);
        engine_draw(&e);
        assert_int_equal(fv_frame(&s, W, H, &st, NULL), FOGVOL_SUCCESS);
        assert_int_equal(st.samples, NS);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        engine_resolve(&e, img);
        {
            errs er = compare(img);
            print_message("# 4x frame, engine depth from a single-sample framebuffer: edges mean %.2f max %d, all "
                          "max %d [/255]\n", er.mean_edge, er.max_edge, er.max_all);
            assert_true(er.max_edge > 20); /* one depth per pixel: an edge is a pixel's, not a sample's */
        }
        fv_destroy(&s);
        g_depth = DEPTH_NONE;
        g_engine = NULL;
        engine_destroy(&e1);
    }

    /* the support table */
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_330), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_150), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS13, 0, FOGVOL_GLSL_330), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_GLSL_330),
                     FOGVOL_SUCCESS);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_GLSL_150),
                     FOGVOL_SUCCESS);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, FOGVOL_GLSL_330),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, FOGVOL_VARIANT_WIDE, FOGVOL_GLSL_330),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_MRT, 0, FOGVOL_GLSL_330), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_130), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_100), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_300ES), FOGVOL_ERROR_UNSUPPORTED);
    engine_destroy(&e);
    glu_destroy(&g);
    free(ref);
    free(img);
    free(debug);
}

/* A backend without FOGVOL_CAP_MULTISAMPLE is refused; with it, every pass is per sample. */
static void test_null_backend(void **state)
{
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_frame_stats st;
    fogvol_mesh *m;
    fogvol_ramp *ramp;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    float pos[24];
    uint32_t idx[36];
    int k, i;
    (void)state;
    scene_init(W, H);
    for (k = 0; k < 2; ++k) {
        memset(&cd, 0, sizeof cd);
        cd.logger.func = logger;
        fogvol_null_backend_init(&nb, &cd.backend);
        if (k) cd.backend.caps |= FOGVOL_CAP_MULTISAMPLE;
        nb.samples = 4;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        memset(&md, 0, sizeof md);
        obox_mesh(&g_vol, pos, idx);
        md.positions = pos;
        md.vertex_count = 8;
        md.indices = idx;
        md.index_count = 36;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
        memset(&rd, 0, sizeof rd);
        rd.density = 1.0f;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
        memset(&fd, 0, sizeof fd);
        glu_identity(fd.view);
        memcpy(fd.projection, g_proj, sizeof g_proj);
        fd.znear = 1.0f;
        fd.zfar = 20.0f;
        fd.viewport[2] = W;
        fd.viewport[3] = H;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        memset(&vd, 0, sizeof vd);
        vd.mesh = m;
        glu_identity(vd.model);
        vd.ramp = ramp;
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        g_log[0] = 0;
        assert_int_equal(fogvol_end_frame(fv, &st), k ? FOGVOL_SUCCESS : FOGVOL_ERROR_UNSUPPORTED);
        if (!k) {
            assert_int_equal(nb.pass_count, 0);
            assert_non_null(strstr(g_log, "per-sample shading"));
        } else {
            assert_int_equal(st.samples, 4);
            assert_true(nb.pass_count >= 3);
            for (i = 0; i < nb.pass_count; ++i) assert_int_equal(nb.passes[i].per_sample, 1);
        }
        fogvol_destroy_mesh(fv, m);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
    }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* min over 5 frames of fogvol_end_frame + glFinish */
static double time_frames(fv_scene *s, engine *e)
{
    double best = 1e30;
    int i;
    fogvol_frame_stats st;
    for (i = 0; i < 6; ++i) {
        double t0;
        engine_draw(e);
        glFinish();
        t0 = now_s();
        assert_int_equal(fv_frame(s, e->w, e->h, &st, NULL), FOGVOL_SUCCESS);
        glFinish();
        if (i > 0 && now_s() - t0 < best) best = now_s() - t0;
    }
    return best;
}

/* The cost of the per-sample path: 4x per sample vs the same scene on a
   single-sample engine framebuffer (and vs the per-pixel fallback on 4x). */
static void test_cost(void **state)
{
    const int w = 640, h = 480;
    glu_ctx g;
    engine e1, e4;
    fv_scene s, sf;
    double t1, t4, tf;
    (void)state;
    assert_true(glu_create(&g, 16, 16, 1));
    scene_init(w, h);
    engine_create(&e1, w, h, 1);
    engine_create(&e4, w, h, NS);
    assert_int_equal(fv_create(&s, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_AUTO), 0);
    assert_int_equal(fv_create(&sf, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, FOGVOL_MSAA_SINGLE_SAMPLE), 0);
    t1 = time_frames(&s, &e1);
    t4 = time_frames(&s, &e4);
    tf = time_frames(&sf, &e4);
    print_message("# cost (FLOAT, %dx%d): 1x %.2f ms, 4x per-sample %.2f ms (%.2fx), 4x single-sample fallback "
                  "%.2f ms\n",
                  w, h, t1 * 1e3, t4 * 1e3, t4 / t1, tf * 1e3);
    assert_true(t4 > 0 && t1 > 0);
    fv_destroy(&s);
    fv_destroy(&sf);
    engine_destroy(&e1);
    engine_destroy(&e4);
    glu_destroy(&g);
    scene_init(W, H);
}

int main(void)
{
    static struct CMUnitTest tests[3 * NCASES + 8]; /* each case, its sequence, the walks, the rest */
    int n = 0, i;
    for (i = 0; i < NCASES; ++i) {
        tests[n].name = g_cases[i].name;
        tests[n].test_func = test_tier;
        tests[n].initial_state = (void *)&g_cases[i];
        ++n;
    }
    for (i = 0; i < NCASES; ++i) {
        static char names[NCASES][64];
        snprintf(names[i], sizeof names[i], "sequence %s", g_cases[i].name);
        tests[n].name = names[i];
        tests[n].test_func = test_sequence;
        tests[n].initial_state = (void *)&g_cases[i];
        ++n;
    }
    for (i = 0; i < NCASES; ++i) { /* the engine's depth from the bound framebuffer, FLOAT and PS20 */
        static char names[NCASES][64];
        if (g_cases[i].depth != DEPTH_BOUND) continue;
        snprintf(names[i], sizeof names[i], "walk %s", g_cases[i].name);
        tests[n].name = names[i];
        tests[n].test_func = test_walk;
        tests[n].initial_state = (void *)&g_cases[i];
        ++n;
    }
    tests[n].name = "gl_sample_depths";
    tests[n++].test_func = test_gl_sample_depths;
    tests[n].name = "state_restored";
    tests[n++].test_func = test_state_restored;
    tests[n].name = "refusals";
    tests[n++].test_func = test_refusals;
    tests[n].name = "null_backend";
    tests[n++].test_func = test_null_backend;
    tests[n].name = "cost";
    tests[n++].test_func = test_cost;
    if (getenv("FV_TEST_FILTER")) cmocka_set_test_filter(getenv("FV_TEST_FILTER")); /* e.g. "*sequence*" */
    n = cmocka_run_group_tests_name("engine_msaa", tests, NULL, NULL); /* zeroed entries are skipped */
    free(g_truth);
    free(g_edge);
    return n;
}
