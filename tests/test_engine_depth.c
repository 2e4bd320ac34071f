/* test_engine_depth.c - depth and camera conventions of real engines.

   The test plays an engine that renders its opaque occluders into its own
   framebuffer (colour texture + 32-bit float depth texture) under one
   convention at a time, leaves that GL state set, and calls fogvol:
   reversed-Z through glClipControl(ZERO_TO_ONE) (with LOWER_LEFT and
   UPPER_LEFT origin), [0,1] forward projections, glDepthRange(1, 0),
   reversed-Z matrices without clip control, orthographic projections (a
   volume reaching far beyond the far plane), infinite far planes,
   TAA-jittered and oblique-near-plane projections, mirrored x or y, and a
   camera given only as view-projection + eye + forward, a camera inside the
   volume, and depth conventions told in the frame desc after the engine reset
   its state. Tiers: PS13, PS20 (+count, +single, +nearclamp), MRT (the engine
   writes fogvol's O through fogvol_mrt_snippet), FLOAT, FLOAT+enginedepth.

   Ground truth is computed here, independently: each pixel's ray comes from
   the inverse of the engine's own view-projection (in double), the volume is
   an axis-aligned box and the occluders axis-aligned rectangles, so the
   thickness (view-depth extent of the box inside [znear, min(zfar, nearest
   occluder)]) is exact. Interior pixels only: the same faces and occluder at
   the pixel centre and at +-0.75 pixel. Bounds: RGBA8 tiers (dither off)
   |error| <= 1 LSB (one pair of faces) + 1e-6 of the range; FLOAT (also with
   the engine's depth texture) |error| <= 3e-5 of the range. The composite
   (fog colour over the engine's picture) is checked within 2/255 and the
   engine's depth state (clip control, depth range, depth func, clear depth)
   must come back unchanged. FLOAT + engine depth draws the frames that fit depth-tested
   (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: fogvol_frame_stats.engine_depth_tested exactly where the box lies
   between the planes or, the camera inside it, holds the near plane's whole rectangle, and the near
   plane is not oblique, worked out here from the scene; the split screen's right half and the
   smaller viewports at an offset too), and
   test_engine_tested_inputs runs it over the engine's depth formats (DEPTH24, DEPTH32F,
   DEPTH24_STENCIL8), sources (texture, bound framebuffer, framebuffer by name), occluders exactly on
   the box's faces and a walk into the box (the near plane cutting its front face: not tested), through
   it and out, also with the box drawn twice and with the box and its negative (the near plane's count
   c = 2 and 1 - 1 with the camera inside). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#include "tests/fixtures.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define W 96
#define H 96
#define DENSITY 0.5

enum { P_GL, P_GL_REV, P_D3D, P_D3D_REV, P_INF, P_INF_REV01, P_JITTER, P_OBLIQUE, P_MIRROR_X, P_MIRROR_Y,
       P_ORTHO, P_ORTHO_REV01 };

typedef struct conv {
    const char *name;
    int proj;
    int zero_to_one; /* engine's glClipControl depth mode ZERO_TO_ONE */
    int upper_left;  /* engine's glClipControl origin UPPER_LEFT */
    int range_rev;   /* engine's glDepthRange(1, 0) */
    int greater;     /* engine's depth test GREATER with clear 0 (reversed-Z) */
    int vp_camera;   /* fogvol gets view-projection + eye + forward only */
    int told;        /* the engine resets clip control and depth range to the defaults after its
                        pass and tells fogvol how its depth texture was drawn */
    int inside;      /* the camera is inside the volume (its near plane cuts it) */
} conv;

static const conv g_convs[] = {
    {"standard GL", P_GL, 0, 0, 0, 0, 0, 0, 0},
    {"clip control ZERO_TO_ONE reversed-Z", P_D3D_REV, 1, 0, 0, 1, 0, 0, 0},
    {"clip control ZERO_TO_ONE forward", P_D3D, 1, 0, 0, 0, 0, 0, 0},
    {"clip control UPPER_LEFT", P_GL, 0, 1, 0, 0, 0, 0, 0},
    {"clip control UPPER_LEFT ZERO_TO_ONE reversed-Z", P_D3D_REV, 1, 1, 0, 1, 0, 0, 0},
    {"depth range (1,0)", P_GL, 0, 0, 1, 1, 0, 0, 0},
    {"reversed-Z matrix, no clip control", P_GL_REV, 0, 0, 0, 1, 0, 0, 0},
    {"orthographic, volume beyond near+2(far-near)", P_ORTHO, 0, 0, 0, 0, 0, 0, 0},
    {"orthographic reversed ZERO_TO_ONE", P_ORTHO_REV01, 1, 0, 0, 1, 0, 0, 0},
    {"infinite far", P_INF, 0, 0, 0, 0, 0, 0, 0},
    {"infinite far reversed ZERO_TO_ONE", P_INF_REV01, 1, 0, 0, 1, 0, 0, 0},
    {"TAA jitter", P_JITTER, 0, 0, 0, 0, 0, 0, 0},
    {"oblique near plane", P_OBLIQUE, 0, 0, 0, 0, 0, 0, 0},
    {"mirrored x", P_MIRROR_X, 0, 0, 0, 0, 0, 0, 0},
    {"mirrored y", P_MIRROR_Y, 0, 0, 0, 0, 0, 0, 0},
    {"view-projection + eye + forward", P_GL, 0, 0, 0, 0, 1, 0, 0},
    {"ZERO_TO_ONE + range (1,0) drawn, told in frame desc", P_D3D, 1, 0, 1, 1, 0, 1, 0},
    {"camera inside, standard GL", P_GL, 0, 0, 0, 0, 0, 0, 1},
    {"camera inside, ZERO_TO_ONE reversed-Z", P_D3D_REV, 1, 0, 0, 1, 0, 0, 1},
    {"camera inside, orthographic", P_ORTHO, 0, 0, 0, 0, 0, 0, 1},
    {"camera inside, reversed-Z matrix", P_GL_REV, 0, 0, 0, 1, 0, 0, 1},
};
#define NCONV ((int)(sizeof g_convs / sizeof g_convs[0]))

typedef struct combo {
    fogvol_tier tier;
    unsigned variants;
    const char *name;
    unsigned speedups_off; /* fogvol_context_desc.disable_speedups */
} combo;

static const combo g_combos[] = {
    {FOGVOL_TIER_PS20, 0, "PS20", 0},
    {FOGVOL_TIER_FLOAT, 0, "FLOAT", 0},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth", 0},
    /* as a GPU draws it (no FOGVOL_CAP_SOFTWARE_RENDERER): every face reads the engine's depth */
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth-read", FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST},
    /* O from the engine's depth, full-screen: an R32F O (FOGVOL_SPEEDUP_FLOAT_O), so the faces sum
       in integers (FOGVOL_SPEEDUP_EXACT_SUM) on this GL, as PS20 does with occluders */
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, "PS20+enginedepth", 0},
    {FOGVOL_TIER_PS13, 0, "PS13", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, "PS20+count", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, "PS20+single", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_NEAR_CLAMP, "PS20+nearclamp", 0},
    {FOGVOL_TIER_MRT, 0, "MRT", 0},
    /* an RGBA8 O, as GPUs without float targets have it: frames whose volumes clear the near and far
       planes count faces with the depth test (FOGVOL_SPEEDUP_DEPTH_TEST), the others compare */
    {FOGVOL_TIER_PS20, 0, "PS20 (RGBA8 O)", FOGVOL_SPEEDUP_FLOAT_O},
};
#define NCOMBO ((int)(sizeof g_combos / sizeof g_combos[0]))

/* the scene, world space: one box volume, two rectangles (z = const) as occluders */
typedef struct rect {
    double z, x0, x1, y0, y1;
} rect;

typedef struct scene {
    double bmin[3], bmax[3];
    rect occ[2];
    double znear, zfar;
} scene;

static const double g_eye[3] = {1.2, 0.8, 1.0};
/* test_engine_tested_inputs: where fogvol takes the engine's depth from (fogvol_frame_desc.engine_depth_source),
   and the cut occluder moved onto a face of the box (1: its back face, 2: its front face; 0: at z -6.3) */
static fogvol_depth_source g_source = FOGVOL_DEPTH_SOURCE_TEXTURE;
static int g_coplanar;
/* test_engine_tested_inputs: the box as 1 volume, 2 volumes (twice the thickness; with the camera
   inside, two volumes whose front faces the near plane clips) or 0: the box and the box again as a
   negative volume (no fog anywhere; with the camera inside, the near plane's count c = 1 - 1) */
static int g_copies = 1;
static int g_vw = W, g_vh = H; /* the viewport of the frame being drawn (projection aspect, jitter, rays) */

/* The camera at walk position w of a sequence (tests/sequence.h): w = 0 is g_eye; outside cases walk
   towards the box and into it (w = 1: at its near end, looking down -z); camera-inside cases walk
   backwards out of the box around the eye (w = 1: 2 units behind its +z face). The view direction
   stays that of g_eye -> at. */
static void walk_eye(double w, int inside, const double at[3], double eye[3], double target[3])
{
    static const double in_path[3] = {-0.9, -0.6, -6.5}, out_path[3] = {0.0, 0.0, 4.0};
    int i;
    for (i = 0; i < 3; ++i) {
        eye[i] = g_eye[i] + (inside ? out_path[i] : in_path[i]) * w;
        target[i] = eye[i] + at[i] - g_eye[i];
    }
}

static void make_scene(scene *s, int ortho, int inside)
{
    static const rect cut = {-6.3, -0.4, 2.5, -3.0, 3.0};
    rect back = {-9.0, -20.0, 20.0, -20.0, 20.0};
    s->bmin[0] = -1.5;
    s->bmax[0] = 1.5;
    s->bmin[1] = -1.2;
    s->bmax[1] = 1.2;
    s->bmin[2] = ortho ? -11.5 : -7.0;
    s->bmax[2] = ortho ? -5.5 : -5.0;
    if (ortho) back.z = -14.0;
    if (inside) { /* around the eye */
        s->bmin[0] = s->bmin[1] = -3.0;
        s->bmax[0] = s->bmax[1] = 3.0;
        s->bmax[2] = 3.0;
    }
    s->occ[0] = cut;
    if (g_coplanar) s->occ[0].z = g_coplanar == 1 ? s->bmin[2] : s->bmax[2]; /* exactly on a face of the box */
    s->occ[1] = back;
    s->znear = ortho ? 4.0 : 1.0;
    s->zfar = ortho ? 8.0 : 50.0;
}

static void mul4d(double *o, const double *a, const double *b)
{
    double t[16];
    int c, r, k;
    for (c = 0; c < 4; ++c)
        for (r = 0; r < 4; ++r) {
            t[c * 4 + r] = 0.0;
            for (k = 0; k < 4; ++k) t[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
        }
    memcpy(o, t, sizeof t);
}

/* Gauss-Jordan inverse (independent of the library's cofactor inverse) */
static int inv4d(const double *m, double *o)
{
    double a[4][8];
    int r, c, k;
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 8; ++c) a[r][c] = c < 4 ? m[c * 4 + r] : (c - 4 == r);
    for (c = 0; c < 4; ++c) {
        int p = c;
        for (r = c + 1; r < 4; ++r)
            if (fabs(a[r][c]) > fabs(a[p][c])) p = r;
        if (fabs(a[p][c]) < 1e-300) return 0;
        for (k = 0; k < 8; ++k) {
            double t = a[c][k];
            a[c][k] = a[p][k];
            a[p][k] = t;
        }
        for (k = 7; k >= c; --k) a[c][k] /= a[c][c];
        for (r = 0; r < 4; ++r)
            if (r != c)
                for (k = 7; k >= c; --k) a[r][k] -= a[r][c] * a[c][k];
    }
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 4; ++c) o[c * 4 + r] = a[r][c + 4];
    return 1;
}

/* The engine's projection for a convention (column-major, view looks down -z). */
static void make_projection(int kind, const scene *s, float p[16])
{
    double n = s->znear, f = s->zfar, t = 1.0 / tan(25.0 * 3.14159265358979323846 / 180.0);
    double aspect = (double)g_vw / g_vh;
    memset(p, 0, 16 * sizeof(float));
    p[0] = (float)(t / aspect);
    p[5] = (float)t;
    p[11] = -1.0f;
    switch (kind) {
    case P_D3D: /* [0,1]: near -> 0, far -> 1 */
        p[10] = (float)(-f / (f - n));
        p[14] = (float)(-f * n / (f - n));
        break;
    case P_D3D_REV: /* [0,1]: near -> 1, far -> 0 */
        p[10] = (float)(n / (f - n));
        p[14] = (float)(f * n / (f - n));
        break;
    case P_INF:
        p[10] = -1.0f;
        p[14] = (float)(-2.0 * n);
        break;
    case P_INF_REV01:
        p[10] = 0.0f;
        p[14] = (float)n;
        break;
    case P_ORTHO:
    case P_ORTHO_REV01:
        p[0] = (float)(1.0 / 3.0 / aspect);
        p[5] = 1.0f / 3.0f;
        p[11] = 0.0f;
        p[15] = 1.0f;
        p[10] = (float)(kind == P_ORTHO ? -2.0 / (f - n) : 1.0 / (f - n));
        p[14] = (float)(kind == P_ORTHO ? -(f + n) / (f - n) : f / (f - n));
        break;
    default: /* GL [-1,1] */
        p[10] = (float)((f + n) / (n - f));
        p[14] = (float)(2.0 * f * n / (n - f));
        break;
    }
    if (kind == P_GL_REV) { /* z_ndc = +1 at near, -1 at far */
        p[10] = -p[10];
        p[14] = -p[14];
    }
    if (kind == P_JITTER) { /* sub-pixel offsets as TAA applies them */
        p[8] = (float)(2.0 * 0.37 / g_vw);
        p[9] = (float)(2.0 * -0.23 / g_vh);
    }
    if (kind == P_MIRROR_X) p[0] = -p[0];
    if (kind == P_MIRROR_Y) p[5] = -p[5];
    if (kind == P_OBLIQUE) { /* Lengyel's oblique near plane: view-space plane C, camera on its negative side */
        const double cp[4] = {0.2, 0.1, -1.0, -2.5};
        double q[4], d, k;
        q[0] = ((cp[0] > 0 ? 1.0 : -1.0) + p[8]) / p[0];
        q[1] = ((cp[1] > 0 ? 1.0 : -1.0) + p[9]) / p[5];
        q[2] = -1.0;
        q[3] = (1.0 + p[10]) / p[14];
        d = cp[0] * q[0] + cp[1] * q[1] + cp[2] * q[2] + cp[3] * q[3];
        k = 2.0 / d;
        p[2] = (float)(cp[0] * k);
        p[6] = (float)(cp[1] * k);
        p[10] = (float)(cp[2] * k + 1.0);
        p[14] = (float)(cp[3] * k);
    }
}

/* ---- ground truth ---- */
typedef struct gt_px {
    double t;        /* thickness */
    double from, to; /* the view depths it spans (entry or znear; exit, occluder or far end) */
    unsigned sig;    /* faces crossed and nearest occluder */
} gt_px;

/* the ray of window position (sx, sy): world point p1 at view depth e1 and the world
   direction per unit of view depth */
static gt_px trace(const scene *s, double far_end, const double *ivp, const double *view, int upper_left, double sx,
                   double sy)
{
    double x = sx / g_vw * 2.0 - 1.0, y = (sy / g_vh * 2.0 - 1.0) * (upper_left ? -1.0 : 1.0), pt[2][3], e[2], dir[3];
    double lo = -1e300, hi = 1e300, opq = 1e300, a, b;
    int i, k, ain = -1, aout = -1, occ = -1;
    gt_px g;
    for (k = 0; k < 2; ++k) {
        double c[4] = {x, y, k ? 0.75 : 0.25, 1.0}, w[4];
        for (i = 0; i < 4; ++i) w[i] = ivp[i] * c[0] + ivp[4 + i] * c[1] + ivp[8 + i] * c[2] + ivp[12 + i] * c[3];
        for (i = 0; i < 3; ++i) pt[k][i] = w[i] / w[3];
        e[k] = -(view[2] * pt[k][0] + view[6] * pt[k][1] + view[10] * pt[k][2] + view[14]);
    }
    for (i = 0; i < 3; ++i) dir[i] = (pt[1][i] - pt[0][i]) / (e[1] - e[0]);
    /* p(e) = pt[0] + dir (e - e[0]) */
    for (i = 0; i < 3; ++i) {
        if (fabs(dir[i]) < 1e-15) {
            if (pt[0][i] < s->bmin[i] || pt[0][i] > s->bmax[i]) lo = 1e300;
            continue;
        }
        a = e[0] + (s->bmin[i] - pt[0][i]) / dir[i];
        b = e[0] + (s->bmax[i] - pt[0][i]) / dir[i];
        if (a > b) {
            double t = a;
            a = b;
            b = t;
        }
        if (a > lo) {
            lo = a;
            ain = i * 2 + (dir[i] < 0);
        }
        if (b < hi) {
            hi = b;
            aout = i * 2 + (dir[i] > 0);
        }
    }
    for (k = 0; k < 2; ++k) {
        const rect *r = &s->occ[k];
        double eh, px, py;
        if (fabs(dir[2]) < 1e-15) continue;
        eh = e[0] + (r->z - pt[0][2]) / dir[2];
        px = pt[0][0] + dir[0] * (eh - e[0]);
        py = pt[0][1] + dir[1] * (eh - e[0]);
        if (eh >= s->znear && eh < opq && px >= r->x0 && px <= r->x1 && py >= r->y0 && py <= r->y1) {
            opq = eh;
            occ = k;
        }
    }
    g.t = g.from = g.to = 0.0;
    g.sig = 0;
    if (lo < hi) {
        double end = opq < far_end ? opq : far_end, from = lo > s->znear ? lo : s->znear, to = hi < end ? hi : end;
        g.t = to > from ? to - from : 0.0;
        g.from = from;
        g.to = to;
        g.sig = 1u + (unsigned)(ain + 1) * 4u + (unsigned)(aout + 1) * 64u;
    }
    g.sig += (unsigned)(occ + 1) * 1024u;
    return g;
}

/* ---- the engine ---- */
typedef struct engine {
    GLuint fbo, color, depth, prog, vao, vbo[3], ibo[3];
    GLsizei count[3];
    GLint u_mvp, u_mv, u_color, u_mrt;
    PFNGLCLIPCONTROLPROC clip_control;
} engine;

static void engine_mesh(engine *e, int i, const shp_mesh *m)
{
    glGenBuffers(1, &e->vbo[i]);
    glBindBuffer(GL_ARRAY_BUFFER, e->vbo[i]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m->vcount * 3 * sizeof(float)), m->pos, GL_STATIC_DRAW);
    glGenBuffers(1, &e->ibo[i]);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->ibo[i]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(m->icount * sizeof(unsigned)), m->idx, GL_STATIC_DRAW);
    e->count[i] = m->icount;
}

static void engine_init(engine *e)
{
    /* colour, and for the MRT tier fogvol's encoded view depth as a second output */
    const char *vs = "#version 330 core\nlayout(location = 0) in vec3 pos;\nuniform mat4 mvp;\nuniform mat4 mv;\n"
                     "out float view_depth;\n"
                     "void main() { gl_Position = mvp * vec4(pos, 1.0); view_depth = -(mv * vec4(pos, 1.0)).z; }\n";
    const char *fs[3];
    fs[0] = "#version 330 core\n";
    fs[1] = fogvol_mrt_snippet();
    fs[2] = "uniform vec4 color;\nin float view_depth;\nlayout(location = 0) out vec4 frag;\n"
            "layout(location = 1) out vec4 fogvol_o;\n"
            "void main() { frag = color; fogvol_o = fogvol_encode_view_depth(view_depth); }\n";
    memset(e, 0, sizeof *e);
    e->prog = fx_program(&vs, 1, fs, 3);
    e->u_mvp = glGetUniformLocation(e->prog, "mvp");
    e->u_color = glGetUniformLocation(e->prog, "color");
    e->u_mv = glGetUniformLocation(e->prog, "mv");
    e->u_mrt = glGetUniformLocation(e->prog, "fogvol_mrt");
    glGenVertexArrays(1, &e->vao);
    fx_color_depth_fbo(W, H, GL_DEPTH_COMPONENT32F, GL_FLOAT, &e->color, &e->depth, &e->fbo);
    e->clip_control = (PFNGLCLIPCONTROLPROC)glu_proc("glClipControl", NULL);
    assert_non_null(e->clip_control);
}

/* The engine's framebuffer again with a depth texture of another format (DEPTH24_STENCIL8: packed, at the
   depth-stencil attachment) */
static void engine_depth_format(engine *e, GLenum format)
{
    int packed = format == GL_DEPTH24_STENCIL8;
    GLenum type = format == GL_DEPTH_COMPONENT32F ? GL_FLOAT : packed ? GL_UNSIGNED_INT_24_8 : GL_UNSIGNED_INT;
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, 0, 0);
    glDeleteTextures(1, &e->depth);
    glGenTextures(1, &e->depth);
    glBindTexture(GL_TEXTURE_2D, e->depth);
    glTexImage2D(GL_TEXTURE_2D, 0, (GLint)format, W, H, 0, packed ? GL_DEPTH_STENCIL : GL_DEPTH_COMPONENT, type, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, packed ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D,
                           e->depth, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void engine_free(engine *e)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &e->fbo);
    glDeleteTextures(1, &e->color);
    glDeleteTextures(1, &e->depth);
    glDeleteBuffers(3, e->vbo);
    glDeleteBuffers(3, e->ibo);
    glDeleteVertexArrays(1, &e->vao);
    glDeleteProgram(e->prog);
}

/* The engine's opaque pass under its convention; the state stays set for fogvol. With
   mrt, fogvol's O texture is its second colour attachment. */
static void engine_draw(engine *e, const conv *c, const float *vp, const float *view, const float model[3][16],
                        const fogvol_mrt_info *mrt, const int port[4], int occluders)
{
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    const float bg[4] = {0.2f, 0.5f, 0.8f, 1.0f}, grey[4] = {0.45f, 0.4f, 0.35f, 1.0f};
    const GLfloat zclear = c->greater ? 0.0f : 1.0f;
    int i;
    e->clip_control(c->upper_left ? GL_UPPER_LEFT : GL_LOWER_LEFT, c->zero_to_one ? GL_ZERO_TO_ONE
                                                                                  : GL_NEGATIVE_ONE_TO_ONE);
    glDepthRange(c->range_rev ? 1.0 : 0.0, c->range_rev ? 0.0 : 1.0);
    glDepthFunc(c->greater ? GL_GREATER : GL_LESS);
    glClearDepth(c->greater ? 0.0 : 1.0);
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, mrt ? (GLuint)mrt->texture : 0, 0);
    glDrawBuffers(mrt ? 2 : 1, bufs);
    glViewport(port[0], port[1], port[2], port[3]);
    glScissor(port[0], port[1], port[2], port[3]);
    glEnable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClearBufferfv(GL_COLOR, 0, bg);
    if (mrt) glClearBufferfv(GL_COLOR, 1, mrt->clear_color);
    glClearBufferfv(GL_DEPTH, 0, &zclear);
    glDisable(GL_SCISSOR_TEST);
    glUseProgram(e->prog);
    glBindVertexArray(e->vao);
    glUniform4fv(e->u_color, 1, grey);
    if (mrt) glUniform4fv(e->u_mrt, 2, mrt->uniforms);
    for (i = !occluders; i < 2; ++i) { /* (0: the occluder that comes and goes; 1: the back wall) */
        double a[16], b[16], m[16];
        float f[16];
        int j;
        for (j = 0; j < 16; ++j) {
            a[j] = vp[j];
            b[j] = model[1 + i][j];
        }
        mul4d(m, a, b);
        for (j = 0; j < 16; ++j) f[j] = (float)m[j];
        glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, f);
        for (j = 0; j < 16; ++j) a[j] = view[j];
        mul4d(m, a, b);
        for (j = 0; j < 16; ++j) f[j] = (float)m[j];
        glUniformMatrix4fv(e->u_mv, 1, GL_FALSE, f);
        glBindBuffer(GL_ARRAY_BUFFER, e->vbo[1 + i]);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, NULL);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->ibo[1 + i]);
        glDrawElements(GL_TRIANGLES, e->count[1 + i], GL_UNSIGNED_INT, NULL);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
    glDrawBuffers(1, bufs); /* fogvol composites into attachment 0 */
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
}

static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l <= FOGVOL_LOG_WARNING) fprintf(stderr, "  [fogvol] %s\n", m);
}

/* The GL backend, watched: which programs linearise the engine's depth from z alone
   (FOGVOL_SPECIALIZE_DEPTH_FROM_Z, "#define FV_DEPTH_FROM_Z"), and how many passes of a frame
   ran one of them. */
static fogvol_backend g_inner;
static fogvol_handle g_from_z[64];
static int g_nfrom_z, g_from_z_passes;
static fogvol_result watch_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    fogvol_result r = g_inner.create_program(u, d, out);
    int i, from_z = 0;
    for (i = 0; i < d->fs_count; ++i) from_z |= strcmp(d->fs[i], "#define FV_DEPTH_FROM_Z\n") == 0;
    if (r == FOGVOL_SUCCESS && from_z) {
        assert_true(g_nfrom_z < 64);
        g_from_z[g_nfrom_z++] = *out;
    }
    return r;
}
static void watch_pass(void *u, const fogvol_pass *p)
{
    int i;
    for (i = 0; i < g_nfrom_z; ++i) g_from_z_passes += p->program == g_from_z[i];
    g_inner.begin_pass(u, p);
}

typedef struct depth_state {
    GLint origin, mode, func;
    GLdouble range[2], clear;
} depth_state;

static void get_depth_state(depth_state *d)
{
    glGetIntegerv(GL_CLIP_ORIGIN, &d->origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &d->mode);
    glGetIntegerv(GL_DEPTH_FUNC, &d->func);
    glGetDoublev(GL_DEPTH_RANGE, d->range);
    glGetDoublev(GL_DEPTH_CLEAR_VALUE, &d->clear);
}

typedef struct result {
    double max_err, bound;
    double max_over; /* max of |err| - what the GL's vertex snapping may move the faces (judged against bound) */
    double comp_max;
    int fogged, interior;
    int state_ok;
    fogvol_result r;
    long wrong;   /* interior pixels off by more than the bound, or whose composite is */
    long outside; /* pixels outside the viewport fogvol changed */
    int tested;   /* fogvol_frame_stats.engine_depth_tested */
    int fits;     /* the frame fits the depth-tested faces (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST): any
                     viewport, no oblique near plane, and the box's corners all between the planes
                     (znear, zfar: the projection's too), or the camera inside the box: the four corners
                     of the near plane's rectangle inside it and its far corners before zfar; computed
                     here from the scene */
    int borderline; /* a near-plane corner within 1/100 of the box's faces: fits is not asserted */
} result;

/* One view of a convention's sequence: the camera's walk position, whether the occluder that comes
   and goes is there, the viewport (tests/sequence.h's sq_view). */
typedef struct tview {
    double walk;
    int occluders;
    int port[4];
} tview;

/* The frame desc of a view (camera, planes, viewport, the engine's depth texture and conventions) and
   the matrices it is made of; fd->debug_thickness is left NULL. */
static void view_desc(const conv *c, const tview *tv, engine *e, scene *s, float view[16], float proj[16],
                      double vpd[16], fogvol_frame_desc *fd)
{
    int i, ortho = c->proj == P_ORTHO || c->proj == P_ORTHO_REV01;
    const double at[3] = {0.0, 0.0, ortho ? -8.5 : -6.0}, up[3] = {0.0, 1.0, 0.0};
    double v[16], p[16], eye[3], target[3];
    g_vw = tv->port[2];
    g_vh = tv->port[3];
    make_scene(s, ortho, c->inside);
    if (!tv->occluders) s->occ[0].x0 = s->occ[0].x1 + 1.0; /* the cut occluder is not there */
    walk_eye(tv->walk, c->inside, at, eye, target);
    glu_look_at(view, eye, target, up);
    make_projection(c->proj, s, proj);
    for (i = 0; i < 16; ++i) {
        v[i] = view[i];
        p[i] = proj[i];
    }
    mul4d(vpd, p, v);
    memset(fd, 0, sizeof *fd);
    if (c->vp_camera) {
        fd->camera = FOGVOL_CAMERA_VIEW_PROJECTION;
        for (i = 0; i < 16; ++i) fd->view_projection[i] = (float)vpd[i];
        for (i = 0; i < 3; ++i) {
            fd->eye[i] = (float)eye[i];
            fd->forward[i] = (float)(target[i] - eye[i]);
        }
    } else {
        memcpy(fd->view, view, 16 * sizeof(float));
        memcpy(fd->projection, proj, 16 * sizeof(float));
    }
    fd->znear = (float)s->znear;
    fd->zfar = (float)s->zfar;
    memcpy(fd->viewport, tv->port, sizeof fd->viewport);
    fd->engine_depth_texture = e->depth;
    fd->engine_depth_source = g_source;
    fd->engine_depth_framebuffer = g_source == FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT ? e->fbo : 0;
    if (c->told) {
        fd->engine_depth_zero_to_one = c->zero_to_one ? 1 : -1;
        fd->engine_depth_range[0] = c->range_rev ? 1.0f : 0.0f;
        fd->engine_depth_range[1] = c->range_rev ? 0.0f : 1.0f;
    }
}

/* the model matrices of the box (0) and the two rectangles */
static void scene_models(const scene *s, float model[3][16])
{
    int i;
    glu_translate_scale(model[0], (float)((s->bmin[0] + s->bmax[0]) / 2), (float)((s->bmin[1] + s->bmax[1]) / 2),
                        (float)((s->bmin[2] + s->bmax[2]) / 2), 1.0f);
    for (i = 0; i < 2; ++i) {
        const rect *r = &s->occ[i];
        glu_identity(model[1 + i]);
        model[1 + i][0] = (float)((r->x1 - r->x0) / 2);
        model[1 + i][5] = (float)((r->y1 - r->y0) / 2);
        model[1 + i][12] = (float)((r->x0 + r->x1) / 2);
        model[1 + i][13] = (float)((r->y0 + r->y1) / 2);
        model[1 + i][14] = (float)r->z;
    }
    /* the box mesh is 1 x 1 x 1 half extents scaled here */
    model[0][0] = (float)((s->bmax[0] - s->bmin[0]) / 2);
    model[0][5] = (float)((s->bmax[1] - s->bmin[1]) / 2);
    model[0][10] = (float)((s->bmax[2] - s->bmin[2]) / 2);
}

/* frames drawn, and those of them whose faces summed in integers (fogvol_frame_stats.exact_sum) */
static int g_frames_drawn, g_frames_exact, g_frames_tested, g_frames_borderline;

/* Render one view of a convention with one tier and compare: thickness and composite inside the
   viewport, and every pixel outside it as the engine left it. */
/* The truth of one view, per pixel of its viewport: interior (the pixel and the four points 0.75 px
   diagonally off it cross the same faces and occluder), thickness, and the sum of the faces' depth
   slopes (vertices snap to the subpixel grid: each face's depth moves by its slope times the snap).
   Every tier combination draws the same views of a convention's sequence, so each view's truth is
   traced once and kept, keyed by every input of trace(); freed at the end of test_conventions. */
typedef struct gt_view {
    double key[6 + 10 + 2 + 1 + 16 + 16 + 1 + 2];
    unsigned char *ok;
    double *t, *slope;
} gt_view;
static gt_view *g_views;
static int g_nviews, g_capviews;

static void free_truths(void)
{
    int k;
    for (k = 0; k < g_nviews; ++k) {
        free(g_views[k].ok);
        free(g_views[k].t);
        free(g_views[k].slope);
    }
    free(g_views);
    g_views = NULL;
    g_nviews = g_capviews = 0;
}

static const gt_view *truth_of_view(const scene *s, double far_end, const double *ivp, const double *v, int upper_left,
                                    const int port[4])
{
    double key[sizeof g_views->key / sizeof(double)];
    gt_view *gv;
    int i, j, k, n = 0;
    memcpy(key + n, s->bmin, 3 * sizeof(double)), n += 3;
    memcpy(key + n, s->bmax, 3 * sizeof(double)), n += 3;
    for (k = 0; k < 2; ++k) {
        key[n++] = s->occ[k].z;
        key[n++] = s->occ[k].x0;
        key[n++] = s->occ[k].x1;
        key[n++] = s->occ[k].y0;
        key[n++] = s->occ[k].y1;
    }
    key[n++] = s->znear;
    key[n++] = s->zfar;
    key[n++] = far_end;
    memcpy(key + n, ivp, 16 * sizeof(double)), n += 16;
    memcpy(key + n, v, 16 * sizeof(double)), n += 16;
    key[n++] = upper_left;
    key[n++] = port[2];
    key[n++] = port[3];
    for (k = 0; k < g_nviews; ++k)
        if (!memcmp(g_views[k].key, key, sizeof key)) return &g_views[k];
    if (g_nviews == g_capviews) {
        g_capviews = g_capviews ? 2 * g_capviews : 64;
        g_views = (gt_view *)realloc(g_views, sizeof *g_views * (size_t)g_capviews);
        assert_non_null(g_views);
    }
    gv = &g_views[g_nviews++];
    memcpy(gv->key, key, sizeof key);
    gv->ok = (unsigned char *)malloc((size_t)(port[2] * port[3]));
    gv->t = (double *)malloc(sizeof(double) * (size_t)(port[2] * port[3]));
    gv->slope = (double *)malloc(sizeof(double) * (size_t)(port[2] * port[3]));
    assert_true(gv->ok && gv->t && gv->slope);
    for (j = 0; j < port[3]; ++j)
        for (i = 0; i < port[2]; ++i) {
            int p = j * port[2] + i, ok = 1;
            gt_px g = trace(s, far_end, ivp, v, upper_left, i + 0.5, j + 0.5);
            for (k = 0; k < 4 && ok; ++k)
                ok = trace(s, far_end, ivp, v, upper_left, i + 0.5 + ((k & 1) ? 0.75 : -0.75),
                           j + 0.5 + ((k & 2) ? 0.75 : -0.75)).sig == g.sig;
            gv->ok[p] = (unsigned char)ok;
            gv->t[p] = g.t;
            gv->slope[p] = 0.0;
            if (ok && g.t > 0.0) {
                const double eps = 1.0 / 1024.0;
                gt_px gx = trace(s, far_end, ivp, v, upper_left, i + 0.5 + eps, j + 0.5),
                      gy = trace(s, far_end, ivp, v, upper_left, i + 0.5, j + 0.5 + eps);
                gv->slope[p] = (fabs(gx.from - g.from) + fabs(gx.to - g.to) + fabs(gy.from - g.from) + fabs(gy.to - g.to)) / eps;
            }
        }
    return gv;
}

/* The NDC depth of the near plane: the point at view depth znear on the view axis (the inverse view
   applied to (0, 0, -znear, 1)) through the view-projection vp. */
static double near_ndc_z(const double v[16], const double vp[16], double znear)
{
    double iv[16], p[4], q[4];
    int j;
    assert_true(inv4d(v, iv));
    for (j = 0; j < 4; ++j) p[j] = -znear * iv[8 + j] + iv[12 + j];
    for (j = 0; j < 4; ++j) q[j] = vp[j] * p[0] + vp[4 + j] * p[1] + vp[8 + j] * p[2] + vp[12 + j] * p[3];
    return q[2] / q[3];
}

static result run_case(engine *e, const conv *c, const combo *cb, const fogvol_mesh *meshes[3],
                       fogvol_context *fv, const fogvol_ramp *ramp, const char *png, const tview *tv)
{
    static float thick[W * H];
    static unsigned char base[W * H * 4], fogged[W * H * 4];
    scene s;
    float view[16], proj[16], model[3][16], vp[16];
    double v[16], vpd[16], ivp[16], range, far_end;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_mrt_info mrt;
    fogvol_frame_stats st;
    depth_state before, after;
    const fogvol_encoding *enc = fogvol_context_encoding(fv);
    const int *port = tv->port;
    const gt_view *gv;
    result res;
    int i, j;
    GLint subpixel = 0;
    double snap;

    memset(&res, 0, sizeof res);
    glGetIntegerv(GL_SUBPIXEL_BITS, &subpixel);
    snap = ldexp(1.0, -(subpixel < 4 ? 4 : subpixel));
    view_desc(c, tv, e, &s, view, proj, vpd, &fd);
    range = s.zfar - s.znear;
    for (i = 0; i < 16; ++i) {
        v[i] = view[i];
        vp[i] = (float)vpd[i];
    }
    assert_true(inv4d(vpd, ivp));
    scene_models(&s, model);
    fd.debug_thickness = thick;
    res.r = fogvol_begin_frame(fv, &fd);
    if (res.r != FOGVOL_SUCCESS) return res;
    if (cb->tier == FOGVOL_TIER_MRT) assert_int_equal(fogvol_mrt_prepare(fv, &mrt), FOGVOL_SUCCESS);
    engine_draw(e, c, vp, view, (const float(*)[16])model, cb->tier == FOGVOL_TIER_MRT ? &mrt : NULL, port,
                tv->occluders);
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, base);
    if (c->told) {
        e->clip_control(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        glDepthRange(0.0, 1.0);
    }
    get_depth_state(&before);
    if (!(cb->variants & FOGVOL_VARIANT_ENGINE_DEPTH) && cb->tier != FOGVOL_TIER_MRT)
        for (i = !tv->occluders; i < 2; ++i)
            assert_int_equal(fogvol_add_occluder(fv, meshes[1 + i], model[1 + i]), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = meshes[0];
    memcpy(vd.model, model[0], sizeof vd.model);
    vd.ramp = ramp;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    if (g_copies != 1) {
        vd.negative = g_copies == 0;
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    }
    for (i = 0; i < W * H; ++i) thick[i] = -1e30f;
    memset(&st, 0, sizeof st);
    res.r = fogvol_end_frame(fv, &st);
    res.tested = st.engine_depth_tested;
    res.fits = c->proj != P_OBLIQUE; /* (any viewport: away from the origin too) */
    {
        int between = 1, before_far = 1;
        double inside = 1e30, zn;
        for (i = 0; i < 8; ++i) { /* view depth of each corner of the box */
            double p[3], e;
            for (j = 0; j < 3; ++j) p[j] = (i >> j & 1) ? s.bmax[j] : s.bmin[j];
            e = -(v[2] * p[0] + v[6] * p[1] + v[10] * p[2] + v[14]);
            between = between && e >= s.znear && e <= s.zfar;
            before_far = before_far && e <= s.zfar;
        }
        /* the camera inside: the near plane's NDC depth from a point at view depth znear on the view
           axis (world: the inverse view's column 3 minus znear times its column 2), then the corners of
           the NDC square there back into world space; each corner's distance inside the box */
        zn = near_ndc_z(v, vpd, s.znear);
        for (i = 0; i < 4; ++i) {
            double nd[4] = {(i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, zn, 1.0}, w[4];
            for (j = 0; j < 4; ++j)
                w[j] = ivp[j] * nd[0] + ivp[4 + j] * nd[1] + ivp[8 + j] * nd[2] + ivp[12 + j] * nd[3];
            for (j = 0; j < 3; ++j) {
                double x = w[j] / w[3], m = x - s.bmin[j] < s.bmax[j] - x ? x - s.bmin[j] : s.bmax[j] - x;
                if (m < inside) inside = m;
            }
        }
        res.borderline = fabs(inside) < 0.01;
        res.fits = res.fits && (between || (inside > 0.0 && before_far));
    }
    g_frames_drawn += res.r == FOGVOL_SUCCESS;
    g_frames_tested += res.r == FOGVOL_SUCCESS && res.tested;
    g_frames_borderline += res.r == FOGVOL_SUCCESS && res.borderline;
    g_frames_exact += res.r == FOGVOL_SUCCESS && st.exact_sum;
    glFinish();
    get_depth_state(&after);
    res.state_ok = before.origin == after.origin && before.mode == after.mode && before.func == after.func &&
                   before.range[0] == after.range[0] && before.range[1] == after.range[1] &&
                   before.clear == after.clear;
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, fogged);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    for (j = 0; j < H; ++j) /* outside the viewport: the engine's pixels */
        for (i = 0; i < W; ++i)
            if ((i < port[0] || i >= port[0] + port[2] || j < port[1] || j >= port[1] + port[3]) &&
                memcmp(base + 4 * (j * W + i), fogged + 4 * (j * W + i), 4))
                res.outside++;

    /* RGBA8 encodings clamp d to 1 - 1.5 LSB (fogvol_constants.depth_max): their far end; integer sums
       (FOGVOL_SPEEDUP_EXACT_SUM, PS20 and MRT on this GL) and FLOAT clamp it to 1 */
    far_end = cb->tier == FOGVOL_TIER_FLOAT || st.exact_sum ? s.zfar
                                            : s.znear + range * (1.0 - 1.5 / ((double)enc->levels * enc->levels * enc->levels));
    res.bound = cb->tier == FOGVOL_TIER_FLOAT || st.exact_sum ? 3e-5 * range
                                              : range / (double)(1 << enc->precision_bits) + 1e-6 * range;
    gv = truth_of_view(&s, far_end, ivp, v, c->upper_left, port);
    for (j = 0; j < port[3]; ++j)
        for (i = 0; i < port[2]; ++i) {
            double err, a, comp = 0, t = gv->t[j * port[2] + i] * g_copies;
            int ch, px = 4 * ((port[1] + j) * W + port[0] + i);
            if (!gv->ok[j * port[2] + i]) continue;
            res.interior++;
            if (t > 0.05) res.fogged++;
            err = fabs((double)thick[j * port[2] + i] - t);
            if (err > res.max_err) res.max_err = err;
            err -= gv->slope[j * port[2] + i] * snap; /* vertices snap to 2^-GL_SUBPIXEL_BITS pixels */
            if (err > res.max_over) res.max_over = err;
            a = 1.0 - exp(-DENSITY * t);
            for (ch = 0; ch < 3; ++ch) {
                double want = base[px + ch] / 255.0 + (0.8 - base[px + ch] / 255.0) * a;
                double got = fogged[px + ch] / 255.0;
                if (fabs(got - want) > comp) comp = fabs(got - want);
            }
            if (comp > res.comp_max) res.comp_max = comp;
            res.wrong += err > res.bound || comp > 2.0 / 255.0;
        }
    if (png) {
        stbi_flip_vertically_on_write(1);
        stbi_write_png(png, W, H, 4, fogged, W * 4);
    }
    return res;
}

/* A convention's sequence (tests/sequence.h's default script): the camera walks into the volume
   and out, the cut occluder leaves and comes back, the viewport shrinks and splits, a frame is
   cancelled in between. Frame 0 is the single frame this test always drew (g_eye, both occluders,
   the whole framebuffer); every view is checked as it was: thickness within the bound on interior
   pixels, composite within 2/255, nothing outside the viewport touched, the engine's depth state
   restored, FV_DEPTH_FROM_Z where it applies. */
typedef struct seqrun {
    engine *e;
    const conv *c;
    const combo *cb;
    const fogvol_mesh **meshes;
    fogvol_context *fv;
    const fogvol_ramp *ramp;
    const char *png;
    double walk_scale;
} seqrun;

static int g_tested_seq[16]; /* fogvol_frame_stats.engine_depth_tested of each frame's first view */

static void seq_cancel(void *user, const sq_view *v)
{
    seqrun *sr = (seqrun *)user;
    scene s;
    float view[16], proj[16], model[3][16];
    double vpd[16];
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_mrt_info mrt;
    tview tv;
    tv.walk = (1.0 - v->walk) * sr->walk_scale;
    tv.occluders = !v->occluders;
    memcpy(tv.port, v->viewport, sizeof tv.port);
    view_desc(sr->c, &tv, sr->e, &s, view, proj, vpd, &fd);
    scene_models(&s, model);
    assert_int_equal(fogvol_begin_frame(sr->fv, &fd), FOGVOL_SUCCESS);
    if (sr->cb->tier == FOGVOL_TIER_MRT) assert_int_equal(fogvol_mrt_prepare(sr->fv, &mrt), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = sr->meshes[0];
    memcpy(vd.model, model[0], sizeof vd.model);
    vd.ramp = sr->ramp;
    assert_int_equal(fogvol_add_volume(sr->fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(sr->fv), FOGVOL_SUCCESS);
}

static void seq_view(void *user, const sq_view *v, sq_check *out)
{
    seqrun *sr = (seqrun *)user;
    const conv *c = sr->c;
    const combo *cb = sr->cb;
    tview tv;
    result r;
    int ok, first = v->frame == 0;
    tv.walk = v->walk * sr->walk_scale;
    tv.occluders = v->occluders;
    memcpy(tv.port, v->viewport, sizeof tv.port);
    g_from_z_passes = 0;
    r = run_case(sr->e, c, cb, sr->meshes, sr->fv, sr->ramp, first ? sr->png : NULL, &tv);
    ok = r.r == FOGVOL_SUCCESS && r.max_over <= r.bound && r.comp_max <= 2.0 / 255.0 && r.state_ok &&
         r.outside == 0 && r.interior > v->viewport[2] * v->viewport[3] / 2;
    if (first) ok = ok && (g_copies ? r.fogged > 200 : r.fogged == 0);
    /* FLOAT + engine depth draws the frames that fit depth-tested (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST), and
       only those; every other combination none */
    ok = ok && (r.borderline || r.tested == (cb->tier == FOGVOL_TIER_FLOAT && (cb->variants & FOGVOL_VARIANT_ENGINE_DEPTH) &&
                                             !(cb->speedups_off & FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST) && r.fits));
    /* the faces that read the engine's depth linearise it from z alone unless the near plane is oblique
       (x and y terms); nothing else reads it; depth-tested frames read it in the composite and in the
       debug read-back's pass instead */
    ok = ok && g_from_z_passes == ((cb->variants & FOGVOL_VARIANT_ENGINE_DEPTH) && c->proj != P_OBLIQUE ? 1 + r.tested : 0);
    if (first || !ok)
        printf("# %-18s %-48s f%d.%d max |err| %.3g (less vertex snapping: %.3f of bound %.3g), composite %.1f/255, "
               "%d fogged of %d interior, %ld outside changed, state %s, %s%s%s\n",
               cb->name, c->name, v->frame, v->view, r.max_err, r.max_over / r.bound, r.bound, r.comp_max * 255.0,
               r.fogged, r.interior, r.outside, r.state_ok ? "restored" : "CHANGED", fogvol_result_string(r.r),
               r.tested ? ", depth-tested" : "", ok ? "" : "  FAIL");
    if (v->frame < 16 && v->view == 0) g_tested_seq[v->frame] = r.tested;
    out->pixels = r.interior;
    out->wrong = r.wrong + r.outside + !ok;
    out->max_err = r.max_over;
    out->bound = r.bound;
}

static void test_conventions(void **state)
{
    glu_ctx g;
    engine e;
    int ci, ti, failures = 0, views = 0;
    shp_mesh box = shp_box(1.0f, 1.0f, 1.0f), quad = shp_grid_plane(1.0f, 1.0f, 1);
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    engine_init(&e);
    engine_mesh(&e, 0, &box);
    engine_mesh(&e, 1, &quad);
    engine_mesh(&e, 2, &quad);
    mkdir("build", 0777);
    mkdir("build/engine_depth", 0777);
    for (ti = 0; ti < NCOMBO; ++ti) {
        const combo *cb = &g_combos[ti];
        fogvol_context_desc cd;
        fogvol_context *fv = NULL;
        fogvol_mesh_desc md;
        fogvol_mesh *m[3];
        fogvol_ramp_desc rd;
        fogvol_ramp *ramp;
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.logger.func = logger;
        cd.tier = cb->tier;
        cd.variants = cb->variants;
        cd.disable_dither = 1;
        cd.disable_speedups = cb->speedups_off;
        cd.gl.software = 1; /* the depth-tested frames on any GL (on a GPU's the faces would read the depth) */
        assert_int_equal(fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &g_inner), FOGVOL_SUCCESS);
        cd.backend = g_inner;
        cd.backend.create_program = watch_program;
        cd.backend.begin_pass = watch_pass;
        g_nfrom_z = 0;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        memset(&md, 0, sizeof md);
        md.positions = box.pos;
        md.vertex_count = box.vcount;
        md.indices = box.idx;
        md.index_count = box.icount;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m[0], NULL), FOGVOL_SUCCESS);
        md.positions = quad.pos;
        md.vertex_count = quad.vcount;
        md.indices = quad.idx;
        md.index_count = quad.icount;
        md.allow_open = 1;
        assert_int_equal(fogvol_create_mesh(fv, &md, &m[1], NULL), FOGVOL_SUCCESS);
        m[2] = m[1];
        memset(&rd, 0, sizeof rd);
        rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
        rd.density = (float)DENSITY;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
        g_frames_drawn = g_frames_exact = g_frames_tested = g_frames_borderline = 0;
        for (ci = 0; ci < NCONV; ++ci) {
            const conv *c = &g_convs[ci];
            char png[128], name[96], where[200];
            seqrun sr;
            sq_totals t;
            /* COUNT needs the camera outside the volumes (documented); NEAR_CLAMP snaps
               vertices behind the eye onto the near plane, which distorts a box reaching
               behind the camera under every convention (standard GL included) */
            if (c->inside && (cb->variants & (FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_NEAR_CLAMP))) continue;
            snprintf(png, sizeof png, "build/engine_depth/%s_%02d.png", cb->name, ci);
            snprintf(name, sizeof name, "%s %s", cb->name, c->name);
            memset(&sr, 0, sizeof sr);
            sr.e = &e;
            sr.c = c;
            sr.cb = cb;
            sr.meshes = (const fogvol_mesh **)m;
            sr.fv = fv;
            sr.ramp = ramp;
            sr.png = ti < 5 ? png : NULL; /* (PS20, FLOAT, both FLOAT + engine depth, PS20 + engine depth) */
            /* the camera stays outside the volume where COUNT or NEAR_CLAMP need it there (and the
               volume clear of the orthographic near plane); MRT: the engine writes O at the viewport's pixels, so
               the viewport stays at the origin */
            sr.walk_scale = (cb->variants & (FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_NEAR_CLAMP)) ? 0.2 : 1.0;
            /* the oblique near plane (view depth 2.5, tilted) clips the engine's occluders when the
               camera comes closer, which the truth's rays do not model: it keeps its distance */
            if (c->proj == P_OBLIQUE) sr.walk_scale = 0.3;
            t = sq_play(name, W, H, sq_default_script, SQ_DEFAULT_FRAMES,
                        cb->tier == FOGVOL_TIER_MRT ? SQ_CAMERA | SQ_OCCLUDER | SQ_CANCEL : SQ_ALL, seq_view,
                        seq_cancel, &sr, where);
            if (t.wrong) printf("#   FAIL: the first wrong pixel in %s\n", where);
            failures += t.wrong != 0;
            views += t.views;
        }
        if (cb->tier == FOGVOL_TIER_PS20 && (cb->variants & FOGVOL_VARIANT_ENGINE_DEPTH)) {
            /* every frame of PS20 + engine depth summed in integers where the GL has framebuffer
               fetch (Mesa), none where it has not (NVIDIA's desktop driver) */
            printf("# %s: %d of %d frames summed in integers\n", cb->name, g_frames_exact, g_frames_drawn);
            assert_true(g_frames_drawn > 0);
            assert_int_equal(g_frames_exact, glu_has_fetch() ? g_frames_drawn : 0);
        }
        if (cb->tier == FOGVOL_TIER_FLOAT && (cb->variants & FOGVOL_VARIANT_ENGINE_DEPTH)) {
            /* both kinds of frame in the sequences: depth-tested and reading the depth per face (every
               frame reads it with the depth test off) */
            printf("# %s: %d of %d frames depth-tested (%d with the near plane within 1/100 of the box's faces: "
                   "not asserted)\n", cb->name, g_frames_tested, g_frames_drawn, g_frames_borderline);
            if (cb->speedups_off & FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST)
                assert_int_equal(g_frames_tested, 0);
            else
                assert_true(g_frames_tested > 0 && g_frames_tested < g_frames_drawn);
        }
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_mesh(fv, m[0]);
        fogvol_destroy_mesh(fv, m[1]);
        fogvol_destroy_context(fv);
        g_inner.destroy(g_inner.user_data);
    }
    engine_free(&e);
    glu_destroy(&g);
    shp_free(&box);
    shp_free(&quad);
    printf("# conventions: %d views in sequences of %d frames, %d sequences failed; %d views' truths traced\n", views,
           SQ_DEFAULT_FRAMES, failures, g_nviews);
    free_truths();
    assert_int_equal(failures, 0);
}

/* ---- the projection helper and refusals (no GPU) ---- */
static void check_planes(int kind, int zero_to_one, double n, double f, int ortho, int rev, int inf)
{
    scene s;
    float p[16];
    fogvol_projection_info pi;
    memset(&s, 0, sizeof s);
    s.znear = n;
    s.zfar = f;
    make_projection(kind, &s, p);
    assert_int_equal(fogvol_projection_planes(p, zero_to_one, &pi), FOGVOL_SUCCESS);
    assert_true(fabs(pi.znear - n) <= 1e-5 * n);
    /* the far plane of a float matrix is known to about 2^-24 f/n relative */
    if (inf) assert_true(pi.zfar == 0.0f);
    else assert_true(fabs(pi.zfar - f) <= (1e-6 + 4.0 * f / n / 16777216.0) * f);
    assert_int_equal(pi.orthographic, ortho);
    assert_int_equal(pi.reversed, rev);
    assert_int_equal(pi.infinite, inf);
}

static void test_projection_planes(void **state)
{
    float p[16];
    fogvol_projection_info pi;
    scene s;
    (void)state;
    check_planes(P_GL, 0, 0.5, 200.0, 0, 0, 0);
    check_planes(P_GL_REV, 0, 0.5, 200.0, 0, 1, 0);
    check_planes(P_D3D, 1, 0.1, 1000.0, 0, 0, 0);
    check_planes(P_D3D_REV, 1, 0.1, 1000.0, 0, 1, 0);
    check_planes(P_INF, 0, 0.25, 0.0, 0, 0, 1);
    check_planes(P_INF_REV01, 1, 0.25, 0.0, 0, 1, 1);
    check_planes(P_JITTER, 0, 1.0, 50.0, 0, 0, 0);
    check_planes(P_ORTHO, 0, 4.0, 8.0, 1, 0, 0);
    check_planes(P_ORTHO_REV01, 1, 4.0, 8.0, 1, 1, 0);
    /* a D3D-style [0,1] projection read as [-1,1]: near comes out where z_ndc = -1 (not n) */
    memset(&s, 0, sizeof s);
    s.znear = 1.0;
    s.zfar = 10.0;
    make_projection(P_D3D, &s, p);
    assert_int_equal(fogvol_projection_planes(p, 0, &pi), FOGVOL_SUCCESS);
    assert_true(fabs(pi.znear - 10.0 / 19.0) < 1e-5); /* by hand: z_ndc = -1 at e = fn / (2f - n) = 10/19 */
    /* refused: w depends on x; w = 0; NULL */
    make_projection(P_GL, &s, p);
    p[3] = 0.5f;
    assert_int_equal(fogvol_projection_planes(p, 0, &pi), FOGVOL_ERROR_INVALID_ARGUMENT);
    make_projection(P_GL, &s, p);
    p[11] = 0.0f;
    assert_int_equal(fogvol_projection_planes(p, 0, &pi), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_projection_planes(NULL, 0, &pi), FOGVOL_ERROR_INVALID_ARGUMENT);
}

static int g_logged;
static void count_log(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    (void)m;
    if (l == FOGVOL_LOG_ERROR) g_logged++;
}

static void test_camera_refused(void **state)
{
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_frame_desc fd;
    scene s;
    (void)state;
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    cd.logger.func = count_log;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    memset(&s, 0, sizeof s);
    s.znear = 1.0;
    s.zfar = 10.0;
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    make_projection(P_GL, &s, fd.projection);
    fd.znear = 1.0f;
    fd.zfar = 10.0f;
    fd.viewport[2] = fd.viewport[3] = 8;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    g_logged = 0;
    fd.projection[3] = 0.3f; /* w depends on x: neither perspective nor orthographic */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(g_logged, 1);
    fd.projection[3] = 0.0f;
    fd.projection[11] = 1.0f; /* w = -view depth: everything in front is behind */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.projection[11] = -1.0f;
    fd.projection[0] = 0.0f; /* x collapses */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    make_projection(P_GL, &s, fd.projection);
    fd.view[10] = 0.0f; /* singular view */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    glu_identity(fd.view);
    /* view-projection input: zero forward; eye and forward that do not match the w row */
    fd.camera = FOGVOL_CAMERA_VIEW_PROJECTION;
    memcpy(fd.view_projection, fd.projection, sizeof fd.view_projection);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT); /* forward 0 */
    fd.forward[2] = -1.0f;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    fd.forward[0] = 1.0f; /* looks sideways: w is not the depth along forward */
    g_logged = 0;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(g_logged, 1);
    /* an engine that only has P V and passes it as the projection with view = I: the w row
       is the view depth of the real camera, not of the identity view; refused, not guessed */
    fd.camera = FOGVOL_CAMERA_VIEW_AND_PROJECTION;
    {
        const double at[3] = {0.0, 0.0, -6.0}, up[3] = {0.0, 1.0, 0.0};
        double a[16], b[16], m[16];
        float v[16];
        int i;
        glu_look_at(v, g_eye, at, up);
        make_projection(P_GL, &s, fd.projection);
        for (i = 0; i < 16; ++i) {
            a[i] = fd.projection[i];
            b[i] = v[i];
        }
        mul4d(m, a, b);
        for (i = 0; i < 16; ++i) fd.projection[i] = (float)m[i];
        g_logged = 0;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(g_logged, 1);
        make_projection(P_GL, &s, fd.projection);
    }
    fd.camera = (fogvol_camera)7;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.camera = FOGVOL_CAMERA_VIEW_AND_PROJECTION;
    fd.engine_depth_zero_to_one = 2;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fogvol_destroy_context(fv);
}

/* ---- FLOAT + engine depth drawn depth-tested: its inputs ---- */
typedef struct tested_run {
    engine *e;
    fogvol_context *fv;
    fogvol_mesh *m[3];
    fogvol_ramp *ramp;
} tested_run;

/* One FLOAT + engine depth sequence of convention ci; returns 1 if a view was wrong (printed). */
static int tested_sequence(tested_run *t, int ci, const sq_step *script, int n, unsigned allow, const char *what)
{
    seqrun sr;
    sq_totals tot;
    char name[160], where[200];
    snprintf(name, sizeof name, "FLOAT+enginedepth %s, %s", g_convs[ci].name, what);
    memset(&sr, 0, sizeof sr);
    sr.e = t->e;
    sr.c = &g_convs[ci];
    sr.cb = &g_combos[2];
    sr.meshes = (const fogvol_mesh **)t->m;
    sr.fv = t->fv;
    sr.ramp = t->ramp;
    sr.walk_scale = 1.0;
    tot = sq_play(name, W, H, script, n, allow, seq_view, seq_cancel, &sr, where);
    if (tot.wrong) printf("#   FAIL: the first wrong pixel in %s\n", where);
    return tot.wrong != 0;
}

/* FLOAT + engine depth (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST where the frame fits, the per-face read where it
   does not, each view checked against its ray cast and its stats against the scene, as in
   test_conventions) for every depth format the engine's texture or framebuffer may have (DEPTH24,
   DEPTH32F, DEPTH24_STENCIL8: the texture attached, or fogvol's copy of that format) and every
   source (the texture, the bound framebuffer, the framebuffer by name), under [-1,1] and [0,1]
   depth, reversed-Z by clip control, by depth range and by matrix; an occluder exactly on the box's
   back face and exactly on its front face (the faces there tie with the engine's depth); and a
   sequence in which the camera walks into the volume (the frames stop fitting) and out again. */
static void test_engine_tested_inputs(void **state)
{
    static const GLenum formats[3] = {GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT32F, GL_DEPTH24_STENCIL8};
    static const char *const fnames[3] = {"DEPTH24", "DEPTH32F", "DEPTH24_STENCIL8"};
    static const fogvol_depth_source sources[3] = {FOGVOL_DEPTH_SOURCE_TEXTURE, FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER,
                                                   FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT};
    static const char *const snames[3] = {"texture", "bound framebuffer", "framebuffer by name"};
    static const int convs[5] = {0, 1, 2, 5, 6}; /* GL, ZERO_TO_ONE reversed, ZERO_TO_ONE, range (1,0), reversed matrix */
    /* the camera walks in (0.77: the near plane cuts the box's front face; 0.9 and 1: the camera inside,
       the near plane's rectangle inside the box) and out, full viewport */
    static const sq_step walk[6] = {{{0.0, 0.0}, 1, 1, 0, 0}, {{0.77, 0.0}, 1, 1, 0, 0}, {{0.9, 0.0}, 1, 1, 0, 0},
                                    {{1.0, 0.0}, 1, 1, 0, 0}, {{0.5, 0.0}, 0, 1, 0, 0}, {{0.0, 0.0}, 1, 1, 0, 0}};
    glu_ctx g;
    engine e;
    tested_run t;
    fogvol_context_desc cd;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    shp_mesh box = shp_box(1.0f, 1.0f, 1.0f), quad = shp_grid_plane(1.0f, 1.0f, 1);
    int fi, si, ci, k, failures = 0;
    char what[96];
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    engine_init(&e);
    engine_mesh(&e, 0, &box);
    engine_mesh(&e, 1, &quad);
    engine_mesh(&e, 2, &quad);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_FLOAT;
    cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    cd.gl.software = 1; /* (as above) */
    assert_int_equal(fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &g_inner), FOGVOL_SUCCESS);
    cd.backend = g_inner;
    cd.backend.create_program = watch_program;
    cd.backend.begin_pass = watch_pass;
    g_nfrom_z = 0;
    memset(&t, 0, sizeof t);
    t.e = &e;
    assert_int_equal(fogvol_create_context(&cd, &t.fv), FOGVOL_SUCCESS);
    fx_mesh_desc(&md, &box, 0);
    assert_int_equal(fogvol_create_mesh(t.fv, &md, &t.m[0], NULL), FOGVOL_SUCCESS);
    fx_mesh_desc(&md, &quad, 1);
    assert_int_equal(fogvol_create_mesh(t.fv, &md, &t.m[1], NULL), FOGVOL_SUCCESS);
    t.m[2] = t.m[1];
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
    rd.density = (float)DENSITY;
    assert_int_equal(fogvol_create_ramp(t.fv, &rd, &t.ramp), FOGVOL_SUCCESS);
    for (fi = 0; fi < 3; ++fi) {
        engine_depth_format(&e, formats[fi]);
        for (si = 0; si < 3; ++si) {
            g_source = sources[si];
            for (ci = 0; ci < 5; ++ci) {
                snprintf(what, sizeof what, "%s %s", fnames[fi], snames[si]);
                failures += tested_sequence(&t, convs[ci], sq_default_script, SQ_DEFAULT_FRAMES, SQ_ALL, what);
            }
        }
        g_source = FOGVOL_DEPTH_SOURCE_TEXTURE;
        for (k = 1; k <= 2; ++k) { /* the cut occluder on the box's back, then front face */
            g_coplanar = k;
            for (ci = 0; ci < 2; ++ci) {
                snprintf(what, sizeof what, "%s, occluder on the box's %s face", fnames[fi], k == 1 ? "back" : "front");
                failures += tested_sequence(&t, convs[ci], sq_default_script, SQ_DEFAULT_FRAMES, SQ_ALL, what);
            }
        }
        g_coplanar = 0;
        for (k = 0; k < 3 && fi == 0; k += 2) { /* two volumes, a volume and its negative, walking in */
            g_copies = k;
            for (ci = 0; ci < 2; ++ci) {
                snprintf(what, sizeof what, "%s, %s, walking in", fnames[fi], k ? "the box twice" : "the box and its negative");
                memset(g_tested_seq, 0, sizeof g_tested_seq);
                failures += tested_sequence(&t, convs[ci], walk, 6, SQ_CAMERA | SQ_OCCLUDER, what);
                assert_true(g_tested_seq[0] && !g_tested_seq[1] && g_tested_seq[2] && g_tested_seq[3]);
            }
        }
        g_copies = 1;
        for (ci = 0; ci < 2; ++ci) {
            snprintf(what, sizeof what, "%s, walking into the box and out", fnames[fi]);
            memset(g_tested_seq, 0, sizeof g_tested_seq);
            failures += tested_sequence(&t, convs[ci], walk, 6, SQ_CAMERA | SQ_OCCLUDER, what);
            /* fits, stops fitting (the near plane cuts the box), fits again with the camera inside the box
               (the near plane clips its front faces on every pixel: r - o (g - 1)), and outside it */
            assert_true(g_tested_seq[0] && !g_tested_seq[1] && g_tested_seq[2] && g_tested_seq[3] && g_tested_seq[4] &&
                        g_tested_seq[5]);
        }
    }
    fogvol_destroy_ramp(t.fv, t.ramp);
    fogvol_destroy_mesh(t.fv, t.m[0]);
    fogvol_destroy_mesh(t.fv, t.m[1]);
    fogvol_destroy_context(t.fv);
    g_inner.destroy(g_inner.user_data);
    engine_free(&e);
    glu_destroy(&g);
    shp_free(&box);
    shp_free(&quad);
    assert_int_equal(failures, 0);
}

/* The camera near a convex volume, the projection's near plane beyond fogvol's znear (here 1 and 0.1):
   where the volume holds that plane's whole rectangle but begins after znear, its front face lies
   between the two planes on every pixel's ray. The per-face read keeps it (thickness from the face);
   the depth-tested sum, whose count c places the clipped face at znear, would add the gap before it.
   Frames in one context: a box 10 x 10 wide and 3 deep with its front face at view depth 0.5 (between
   the planes), at -1 (the camera inside), at 0.05 (before znear), at 0.5 again, then with the
   projection's near plane at 0.1 and 0.3 (the box clear of both planes); in standard GL, ZERO_TO_ONE
   reversed-Z, a reversed-Z matrix and orthographic. Every pixel against the box's depth extent from
   max(front, znear) to its back at 3.5, and the composite against 1 - exp(-density t). (Before the
   rectangle at znear was asked for too, the frames at 0.5 drew 3.4 for 3.) */
static void test_near_plane_beyond_znear(void **state)
{
    static const struct { double front, pn; int tested; } fr[6] = {
        {0.5, 1.0, 0}, {-1.0, 1.0, 1}, {0.05, 1.0, 1}, {0.5, 1.0, 0}, {0.5, 0.1, 1}, {0.5, 0.3, 1}};
    static const int convs[4] = {0, 1, 6, 7};
    static float thick[W * H];
    static unsigned char px[W * H * 4];
    const double back = 3.5, znear = 0.1;
    glu_ctx g;
    engine e;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh_desc md;
    fogvol_mesh *mesh;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_frame_stats st;
    scene s;
    int f, i, ch, k;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    engine_init(&e);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.gl.software = 1; /* the depth-tested faces wherever a frame fits them, on any GL */
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_FLOAT;
    cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
    rd.density = (float)DENSITY;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    g_vw = W;
    g_vh = H;
    for (k = 0; k < 4; ++k)
        for (f = 0; f < 6; ++f) {
            const conv *c = &g_convs[convs[k]];
            const GLfloat zclear = c->greater ? 0.0f : 1.0f;
            shp_mesh box = shp_box(5.0f, 5.0f, (float)(0.5 * (back - fr[f].front)));
            double want = back - (fr[f].front > znear ? fr[f].front : znear), a = 1.0 - exp(-DENSITY * want);
            double terr = 0, cerr = 0;
            fx_mesh_desc(&md, &box, 0);
            assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, NULL), FOGVOL_SUCCESS);
            e.clip_control(GL_LOWER_LEFT, c->zero_to_one ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
            glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
            glViewport(0, 0, W, H);
            glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT);
            glClearBufferfv(GL_DEPTH, 0, &zclear);
            memset(&s, 0, sizeof s);
            s.znear = fr[f].pn;
            s.zfar = 100.0;
            memset(&fd, 0, sizeof fd);
            glu_identity(fd.view);
            make_projection(c->proj, &s, fd.projection);
            fd.znear = (float)znear;
            fd.zfar = 100.0f;
            fd.viewport[2] = W;
            fd.viewport[3] = H;
            fd.engine_depth_texture = e.depth;
            fd.debug_thickness = thick;
            memset(&vd, 0, sizeof vd);
            vd.mesh = mesh;
            vd.ramp = ramp;
            glu_identity(vd.model);
            vd.model[14] = (float)(-0.5 * (back + fr[f].front));
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
            e.clip_control(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
            glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
            assert_int_equal(glGetError(), GL_NO_ERROR);
            for (i = 0; i < W * H; ++i) {
                if (fabs(thick[i] - want) > terr) terr = fabs(thick[i] - want);
                for (ch = 0; ch < 3; ++ch) {
                    double base = ch == 0 ? 0.2 : ch == 1 ? 0.3 : 0.4;
                    double d = fabs(px[4 * i + ch] / 255.0 - (base + (0.8 - base) * a));
                    if (d > cerr) cerr = d;
                }
            }
            print_message("  %-36s front face at %5.2f, near plane %.1f: thickness %.2f (max |error| %.2g), composite "
                          "%.1f/255, %s\n", c->name, fr[f].front, fr[f].pn, want, terr, cerr * 255.0,
                          st.engine_depth_tested ? "depth-tested" : "read per face");
            assert_true(terr <= 3e-5 * (100.0 - znear));
            assert_true(cerr <= 2.0 / 255.0);
            assert_int_equal(st.engine_depth_tested, fr[f].tested);
            fogvol_destroy_mesh(fv, mesh);
            shp_free(&box);
        }
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    engine_free(&e);
    glu_destroy(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_projection_planes),
        cmocka_unit_test(test_camera_refused),
        cmocka_unit_test(test_conventions),
        cmocka_unit_test(test_engine_tested_inputs),
        cmocka_unit_test(test_near_plane_beyond_znear),
    };
    if (getenv("FV_TEST_FILTER")) cmocka_set_test_filter(getenv("FV_TEST_FILTER")); /* e.g. "*sequence*" */
    return cmocka_run_group_tests(tests, NULL, NULL);
}
