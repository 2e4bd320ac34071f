/* libFuzzer target: sequences of fogvol API calls on the recording null backend or on the GL
   backend (OSMesa, one GL context per process), made from the input's bytes:
     byte 0       bits 0 and 1 both set: GL backend (else null); bit 2: the objects alive at the end
                  are left to fogvol_destroy_context; bit 3: allocation 1 + 2 k fails, k the next byte
     then         the context desc (tier, variants, overflow policy, MSAA, encoding bits, speed-ups,
                  dither; null backend: caps, dialect, queries, samples)
     then ops     one byte each (its low 5 bits pick the call) and the bytes the call takes: create
                  and destroy meshes (boxes, 16-bit, interleaved, unindexed, welded per-face cubes,
                  spheres, tori, garbage), ramps, volume textures; begin_frame (cameras perspective,
                  orthographic, reversed, infinite, view-projection, transposed, zero, NaN; odd
                  viewports), add_volume / add_occluder / add_occluder_callback / add_light,
                  end_frame (with or without the debug read-back), cancel_frame, occluder_prepare,
                  mrt_prepare, occluder_transform, the three post effects, set_dither, validate_mesh.
   Past the end of the input every read gives 0.
   Checks, besides ASan, UBSan (float-cast-overflow on) and LSan: every call that a context refuses
   logs an error or a warning; after fogvol_destroy_context no allocation of its allocator is live
   and (null backend) every backend object it created is destroyed. */
#ifndef FOGVOL_TEST_LINKED /* make test links fogvol's implementation built once (Makefile: FUZZ_IMPL) */
#define FOGVOL_IMPLEMENTATION
#endif
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- input ---- */
typedef struct rd {
    const uint8_t *p;
    size_t n;
} rd;

static unsigned u8(rd *r)
{
    if (!r->n) return 0;
    r->n--;
    return *r->p++;
}

static unsigned u16(rd *r) { return u8(r) | u8(r) << 8; }

static uint32_t u32(rd *r) { return (uint32_t)u16(r) | (uint32_t)u16(r) << 16; }

/* a float: small integers and fractions mostly, then the edges of float and any bit pattern */
static float fval(rd *r)
{
    static const float special[16] = {0.0f,    -0.0f,   1.0f,    -1.0f,  0.5f,     1e-45f,  1e-30f,  1e-6f,
                                      1e9f,    -1e9f,   1e30f,   3.4e38f, -3.4e38f, INFINITY, -INFINITY, NAN};
    unsigned s = u8(r);
    uint32_t b;
    float f;
    if (s < 128) return ((float)(int)(s & 31) - 16.0f) * ((s & 32) ? 0.25f : 1.0f) * ((s & 64) ? 0.1f : 1.0f);
    if (s < 192) return special[s & 15];
    b = u32(r);
    memcpy(&f, &b, sizeof f);
    return f;
}

/* ---- the run's state ---- */
#define NM 6
#define NR 4
#define NT 3

typedef struct counting {
    long live, calls, fail_at;
} counting;

typedef struct run {
    rd in;
    fogvol_context *ctx;
    fogvol_null_backend nb;
    int gl, errors;
    counting cnt;
    fogvol_mesh *mesh[NM];
    fogvol_ramp *ramp[NR];
    fogvol_volume_texture *tex[NT];
    fogvol_frame_desc fd; /* the last frame's desc (post effects take it) */
    float *debug;
} run;

/* what the inputs reached (for a look at a corpus: see tests/fuzz/README or a debugger) */
static long g_runs, g_gl_runs, g_contexts, g_frames, g_refused;

static glu_ctx g_gl;
static int g_gl_ok = -1; /* -1: not tried */
static GLuint g_depth_tex, g_color_tex;

static void *cnt_alloc(size_t size, void *u)
{
    counting *c = (counting *)u;
    void *p;
    if (++c->calls == c->fail_at) return NULL;
    p = malloc(size);
    if (p) c->live++;
    return p;
}

static void cnt_free(void *p, void *u)
{
    ((counting *)u)->live--;
    free(p);
}

static void logger(void *u, fogvol_log_level level, const char *message)
{
    run *R = (run *)u;
    if (!message) abort();
    if (level == FOGVOL_LOG_ERROR || level == FOGVOL_LOG_WARNING) R->errors++;
}

/* a refusal by a context says why in its log */
static void expect_logged(run *R, fogvol_result res, int errors_before)
{
    if (res != FOGVOL_SUCCESS && R->errors == errors_before) abort();
    g_refused += res != FOGVOL_SUCCESS;
}

static int gl_ready(void)
{
    if (g_gl_ok < 0) {
        g_gl_ok = glu_create(&g_gl, 64, 64, 1);
        if (g_gl_ok) {
            glGenTextures(1, &g_depth_tex);
            glBindTexture(GL_TEXTURE_2D, g_depth_tex);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, 64, 64, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glGenTextures(1, &g_color_tex);
            glBindTexture(GL_TEXTURE_2D, g_color_tex);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 64, 64, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glBindTexture(GL_TEXTURE_2D, 0);
        }
    }
    return g_gl_ok;
}

/* ---- the context ---- */
static fogvol_gl_proc plain_proc(const char *name) { return glu_proc(name, NULL); }

static void *plain_pointer(const char *name)
{
    fogvol_gl_proc f = glu_proc(name, NULL);
    void *p = NULL;
    memcpy(&p, &f, sizeof p < sizeof f ? sizeof p : sizeof f); /* (POSIX: the same size) */
    return p;
}

static void make_context(run *R)
{
    static const unsigned caps[8] = {
        0u,
        FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE | FOGVOL_CAP_MESH_LAYOUT,
        FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE,
        FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE |
            FOGVOL_CAP_MULTISAMPLE | FOGVOL_CAP_FILTER_FLOAT | FOGVOL_CAP_BLEND_CONSTANT,
        FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_FLOAT_TARGET | FOGVOL_CAP_FRAMEBUFFER_FETCH | FOGVOL_CAP_MRT,
        FOGVOL_CAP_MRT,
        0x3ffu,
        0xffffu};
    fogvol_context_desc cd;
    rd *in = &R->in;
    int e;
    fogvol_result res;
    memset(&cd, 0, sizeof cd);
    cd.allocator.alloc = cnt_alloc;
    cd.allocator.free = cnt_free;
    cd.allocator.user_data = &R->cnt;
    cd.logger.func = logger;
    cd.logger.user_data = R;
    cd.tier = (fogvol_tier)(u8(in) % 6);
    cd.variants = u8(in);
    e = (int)u8(in);
    if (e & 1) cd.variants &= FOGVOL_VARIANT_ALU | FOGVOL_VARIANT_NEAR_CLAMP | FOGVOL_VARIANT_ENGINE_DEPTH;
    if (e & 2) cd.preferred_variants = u8(in);
    cd.overflow_policy = (fogvol_overflow_policy)(u8(in) % 5);
    cd.msaa = (fogvol_msaa)(u8(in) % 3);
    cd.encoding_bits = (int)(u8(in) % 11) - 1;
    cd.disable_speedups = (u8(in) & 1) ? u32(in) : 0u;
    cd.disable_dither = (int)(u8(in) & 1);
    cd.engine_mrt = (int)(u8(in) & 1);
    if (R->gl) {
        cd.gl.dialect = (fogvol_dialect)(u8(in) % 10 == 9 ? 0 : u8(in) % (FOGVOL_GLSL_COUNT + 1)); /* (+ 1: unknown) */
        e = (int)u8(in);
        cd.gl.mrt_highp = e & 1;
        if ((e >> 1) % 3 == 0) cd.gl.get_proc_address = glu_proc; /* the three kinds of loader */
        else if ((e >> 1) % 3 == 1) cd.gl.get_proc = plain_proc;
        else cd.gl.get_proc_pointer = plain_pointer;
    } else {
        fogvol_null_backend_init(&R->nb, &cd.backend);
        cd.backend.caps = caps[u8(in) & 7];
        cd.backend.dialect = (fogvol_dialect)(u8(in) % (FOGVOL_GLSL_COUNT + 1));
        R->nb.queries = (int)(u8(in) & 1);
        R->nb.query_not_ready = (int)(u8(in) % 6);
        R->nb.query_samples = u8(in);
        R->nb.samples = (int)(u8(in) % 5);
        R->nb.fail_create_at = (int)(u8(in) % 24);
    }
    e = R->errors;
    res = fogvol_create_context(&cd, &R->ctx);
    if (res != FOGVOL_SUCCESS && (R->ctx || R->errors == e)) abort();
}

/* ---- meshes ---- */
static void transform_pos(rd *in, float *pos, int n)
{
    int i;
    float s, t;
    if (!(u8(in) & 3)) {
        s = fval(in);
        t = fval(in);
        for (i = 0; i < 3 * n; ++i) pos[i] = pos[i] * s + t;
    }
}

/* a mesh desc from the input into md; buffers in *keep (freed by the caller) */
static void mesh_desc(rd *in, fogvol_mesh_desc *md, void **keep)
{
    unsigned kind = u8(in) % 9;
    shp_mesh m;
    int i;
    memset(md, 0, sizeof *md);
    keep[0] = keep[1] = keep[2] = NULL;
    switch (kind) {
    case 0: m = shp_box(1.0f, 0.5f + (float)(u8(in) % 4), 1.0f); break;
    case 1: m = shp_sphere(1.0f, 3 + (int)(u8(in) % 8), 2 + (int)(u8(in) % 5)); break;
    case 2: m = shp_cube_faces(1.0f, 1 + (int)(u8(in) % 4)); break;
    case 3: m = shp_torus(1.0f, 0.3f, 4 + (int)(u8(in) % 6), 3 + (int)(u8(in) % 4)); break;
    default: m = shp_box(1.0f, 1.0f, 1.0f); break;
    }
    if (!m.pos) abort();
    transform_pos(in, m.pos, m.vcount);
    if (kind == 4) { /* no index array: the triangles' corners in order */
        float *flat = (float *)malloc(sizeof(float) * 3 * (size_t)m.icount);
        for (i = 0; i < m.icount; ++i) memcpy(flat + 3 * i, m.pos + 3 * m.idx[i], 3 * sizeof(float));
        md->positions = flat;
        md->vertex_count = m.icount - (int)(u8(in) % 2);
        keep[0] = flat;
        shp_free(&m);
    } else if (kind == 5 || kind == 6) { /* interleaved, maybe 16-bit */
        int stride = 12 + 4 * (int)(u8(in) % 6), off = 4 * (int)(u8(in) % 4);
        unsigned char *buf = (unsigned char *)calloc((size_t)m.vcount, (size_t)stride + 16);
        uint16_t *i16 = (uint16_t *)malloc(sizeof(uint16_t) * (size_t)m.icount);
        for (i = 0; i < m.vcount; ++i)
            memcpy(buf + (size_t)i * (size_t)stride + (off + 12 <= stride ? off : 0), m.pos + 3 * i, 12);
        for (i = 0; i < m.icount; ++i) i16[i] = (uint16_t)m.idx[i];
        md->positions = (const float *)(const void *)buf;
        md->vertex_count = m.vcount;
        md->stride = (u8(in) % 8) ? stride : (int)(u8(in) % 16);
        md->offset = (u8(in) % 8) ? (off + 12 <= stride ? off : 0) : (int)(u8(in) % 40) - 4;
        md->index_count = m.icount;
        if (kind == 6) {
            md->index_type = FOGVOL_INDEX_UINT16;
            md->indices16 = i16;
        } else {
            md->indices = m.idx;
            keep[2] = m.idx;
            m.idx = NULL;
        }
        keep[0] = buf;
        keep[1] = i16;
        shp_free(&m);
    } else if (kind == 7) { /* garbage */
        int nv = 1 + (int)(u8(in) % 48), ni = (int)(u8(in) % 96);
        float *pos = (float *)malloc(sizeof(float) * 3 * (size_t)nv);
        uint32_t *idx = (uint32_t *)malloc(sizeof(uint32_t) * (size_t)(ni + 1));
        for (i = 0; i < 3 * nv; ++i) pos[i] = fval(in);
        for (i = 0; i < ni; ++i) idx[i] = u8(in) % (unsigned)(nv + 2);
        md->positions = pos;
        md->vertex_count = nv;
        md->indices = idx;
        md->index_count = ni;
        keep[0] = pos;
        keep[1] = idx;
        shp_free(&m);
    } else {
        md->positions = m.pos;
        md->vertex_count = m.vcount;
        md->indices = m.idx;
        md->index_count = m.icount;
        keep[0] = m.pos;
        keep[1] = m.idx;
    }
    md->allow_open = (int)(u8(in) % 4 == 0);
    switch (u8(in) % 8) {
    case 0: md->weld_distance = 1e-5f; break;
    case 1: md->weld_distance = fval(in); break;
    case 2: md->weld_distance = kind == 2 || kind == 4 ? 1e-4f : 0.0f; break;
    default: md->weld_distance = kind == 2 || kind == 4 ? 1e-5f : 0.0f; break;
    }
    if (u8(in) % 16 == 0) md->index_type = (fogvol_index_type)(u8(in) % 4);
}

static void op_mesh(run *R, int create)
{
    unsigned slot = u8(&R->in) % NM;
    if (create) {
        fogvol_mesh_desc md;
        fogvol_mesh_report rep;
        void *keep[3];
        int e = R->errors;
        fogvol_result res;
        if (R->mesh[slot]) fogvol_destroy_mesh(R->ctx, R->mesh[slot]);
        R->mesh[slot] = NULL;
        mesh_desc(&R->in, &md, keep);
        res = fogvol_create_mesh(R->ctx, &md, &R->mesh[slot], (u8(&R->in) & 1) ? &rep : NULL);
        expect_logged(R, res, e);
        if ((res == FOGVOL_SUCCESS) != (R->mesh[slot] != NULL)) abort();
        free(keep[0]);
        free(keep[1]);
        free(keep[2]);
    } else if (R->mesh[slot]) {
        fogvol_destroy_mesh(R->ctx, R->mesh[slot]);
        R->mesh[slot] = NULL;
    }
}

static void op_validate(run *R)
{
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    void *keep[3];
    fogvol_result res;
    mesh_desc(&R->in, &md, keep);
    res = fogvol_validate_mesh(&md, NULL, &rep);
    if (res == FOGVOL_SUCCESS && (!rep.valid || !rep.closed)) abort();
    free(keep[0]);
    free(keep[1]);
    free(keep[2]);
}

/* ---- ramps and volume textures ---- */
static void op_ramp(run *R, int create)
{
    rd *in = &R->in;
    unsigned slot = u8(in) % NR;
    if (create) {
        fogvol_ramp_desc d;
        fogvol_color_key keys[4];
        int i, k, e = R->errors;
        fogvol_result res;
        memset(&d, 0, sizeof d);
        d.model = (fogvol_ramp_model)(u8(in) % 4);
        for (k = 0; k < 3; ++k) d.color[k] = (u8(in) & 1) ? fval(in) : 0.6f;
        d.density = (u8(in) & 3) ? 0.25f * (float)(1 + u8(in) % 16) : fval(in);
        d.max_thickness = (u8(in) & 3) ? 0.0f : fval(in);
        d.key_count = (int)(u8(in) % 5);
        for (i = 0; i < d.key_count; ++i) {
            keys[i].thickness = (u8(in) & 1) ? (float)i : fval(in);
            for (k = 0; k < 4; ++k) keys[i].rgba[k] = (u8(in) & 1) ? 0.5f : fval(in);
        }
        d.keys = (u8(in) % 8) ? keys : NULL;
        d.width = (u8(in) & 1) ? (int)(u16(in) % 5000) - 2 : 0;
        d.blend = (fogvol_blend)(u8(in) % 3);
        for (k = 0; k < 3; ++k) d.extinction_color[k] = (u8(in) & 3) ? 0.0f : fval(in);
        if (R->ramp[slot]) fogvol_destroy_ramp(R->ctx, R->ramp[slot]);
        R->ramp[slot] = NULL;
        res = fogvol_create_ramp(R->ctx, &d, &R->ramp[slot]);
        expect_logged(R, res, e);
    } else if (R->ramp[slot]) {
        fogvol_destroy_ramp(R->ctx, R->ramp[slot]);
        R->ramp[slot] = NULL;
    }
}

static void op_texture(run *R, int create)
{
    rd *in = &R->in;
    unsigned slot = u8(in) % NT;
    if (create) {
        fogvol_texture_desc td;
        unsigned char *px;
        int i, e = R->errors;
        fogvol_result res;
        memset(&td, 0, sizeof td);
        td.width = (int)(u8(in) % 6);
        td.height = (int)(u8(in) % 6);
        if (u8(in) % 16 == 0) td.width = 5000;
        px = (unsigned char *)malloc((size_t)(td.width > 0 && td.width <= 8 ? td.width : 1) *
                                     (size_t)(td.height > 0 ? td.height : 1) * 4u);
        for (i = 0; i < (td.width > 0 && td.width <= 8 ? td.width : 1) * (td.height > 0 ? td.height : 1) * 4; ++i)
            px[i] = (unsigned char)u8(in);
        td.pixels = (u8(in) % 8) ? px : NULL;
        if (td.width > 8) td.height = 0; /* (refused for its width before its pixels are read) */
        td.filter = (fogvol_filter)(u8(in) % 3);
        td.wrap = (fogvol_wrap)(u8(in) % 3);
        if (R->tex[slot]) fogvol_destroy_volume_texture(R->ctx, R->tex[slot]);
        R->tex[slot] = NULL;
        res = fogvol_create_volume_texture(R->ctx, &td, &R->tex[slot]);
        expect_logged(R, res, e);
        free(px);
    } else if (R->tex[slot]) {
        fogvol_destroy_volume_texture(R->ctx, R->tex[slot]);
        R->tex[slot] = NULL;
    }
}

/* ---- matrices and cameras ---- */
static void matrix(rd *in, float m[16])
{
    unsigned kind = u8(in) % 8;
    int i;
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
    if (kind < 4) { /* translate and scale */
        float s = kind == 3 ? fval(in) : 0.25f * (float)(1 + u8(in) % 8);
        m[0] = m[5] = m[10] = s;
        m[12] = fval(in);
        m[13] = fval(in);
        m[14] = fval(in) - 2.0f;
    } else if (kind == 4) { /* rotation about z with a mirror maybe */
        float a = (float)u8(in) * 0.05f;
        m[0] = m[5] = cosf(a);
        m[1] = sinf(a);
        m[4] = -m[1];
        if (u8(in) & 1) m[10] = -1.0f;
    } else if (kind == 5) {
        memset(m, 0, 16 * sizeof(float));
    } else if (kind == 6) {
        for (i = 0; i < 16; ++i) m[i] = fval(in);
    } /* 7: identity */
}

static void camera(rd *in, fogvol_frame_desc *fd)
{
    double eye[3], at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    float n = 0.1f * (float)(1 + u8(in) % 10), f = n + 1.0f + (float)(u8(in) % 200), t[16];
    unsigned kind = u8(in) % 10;
    int i, j;
    eye[0] = (double)((int)(u8(in) % 9) - 4);
    eye[1] = (double)((int)(u8(in) % 9) - 4);
    eye[2] = (double)((int)(u8(in) % 9) - 4) + 0.5;
    if (u8(in) % 8 == 0) eye[0] = fval(in);
    glu_look_at(fd->view, eye, at, up);
    glu_perspective(fd->projection, 20.0 + (double)(u8(in) % 120), 0.5 + (double)(u8(in) % 4), n, f);
    fd->znear = n;
    fd->zfar = f;
    switch (kind) {
    case 0: /* orthographic */
        memset(fd->projection, 0, sizeof fd->projection);
        fd->projection[0] = fd->projection[5] = 0.2f;
        fd->projection[10] = -2.0f / (f - n);
        fd->projection[14] = -(f + n) / (f - n);
        fd->projection[15] = 1.0f;
        break;
    case 1: /* reversed-Z, infinite far */
        fd->projection[10] = 0.0f;
        fd->projection[14] = n;
        break;
    case 2: /* transposed (a row-major matrix copied raw) */
        memcpy(t, fd->projection, sizeof t);
        for (i = 0; i < 4; ++i)
            for (j = 0; j < 4; ++j) fd->projection[i * 4 + j] = t[j * 4 + i];
        break;
    case 3: matrix(in, fd->view); break;
    case 4: matrix(in, fd->projection); break;
    case 5: /* view-projection, eye and forward */
        fd->camera = FOGVOL_CAMERA_VIEW_PROJECTION;
        for (i = 0; i < 4; ++i)
            for (j = 0; j < 4; ++j) {
                double s = 0;
                int k;
                for (k = 0; k < 4; ++k) s += (double)fd->projection[k * 4 + i] * fd->view[j * 4 + k];
                fd->view_projection[j * 4 + i] = (float)s;
            }
        for (i = 0; i < 3; ++i) {
            fd->eye[i] = (float)eye[i];
            fd->forward[i] = (float)(at[i] - eye[i]);
        }
        if (u8(in) % 4 == 0) fd->forward[u8(in) % 3] = fval(in);
        break;
    case 6:
        fd->znear = fval(in);
        fd->zfar = fval(in);
        break;
    default: break;
    }
}

static void frame(run *R, fogvol_frame_desc *fd)
{
    rd *in = &R->in;
    unsigned v = u8(in);
    memset(fd, 0, sizeof *fd);
    camera(in, fd);
    fd->viewport[2] = 1 + (int)(u8(in) % 96);
    fd->viewport[3] = 1 + (int)(u8(in) % 96);
    fd->viewport[0] = (int)(u8(in) % 16) - 4;
    fd->viewport[1] = (int)(u8(in) % 16) - 4;
    if (v % 16 == 1) { /* extremes: refused (or huge on the null backend) */
        static const int ext[8] = {INT_MAX, INT_MIN, INT_MAX - 7, -32769, 32767, -32768, 16384, 16385};
        fd->viewport[u8(in) % 4] = ext[u8(in) % 8];
        if (R->gl && fd->viewport[2] > 96) fd->viewport[2] = 96;
        if (R->gl && fd->viewport[3] > 96) fd->viewport[3] = 96;
    }
    fd->composite = (fogvol_composite)(u8(in) % 3 == 0);
    if (u8(in) % 32 == 0) fd->composite = (fogvol_composite)5;
    fd->draw_buffer = (u8(in) % 8) ? 0 : (int)(u8(in) % 20) - 2;
    fd->alpha = (fogvol_alpha)(u8(in) % 3 == 0);
    fd->show_overflow = (int)(u8(in) % 4 == 0);
    fd->downsample = (int)(u8(in) % 4) - (u8(in) % 16 == 0 ? 1 : 0);
    if (fd->downsample == 3) fd->downsample = 0;
    fd->engine_depth_texture = (u8(in) & 1) ? (R->gl ? g_depth_tex : 5u) : 0u;
    if (u8(in) % 8 == 0) fd->engine_depth_texture = 999;
    fd->engine_depth_zero_to_one = (int)(u8(in) % 4) - 1;
    fd->engine_depth_source = (fogvol_depth_source)(u8(in) % 4);
    fd->engine_depth_framebuffer = u8(in) % 4 == 0 ? 999u : 0u;
}

static void op_begin(run *R)
{
    int e = R->errors, w, h;
    fogvol_result res;
    free(R->debug); /* (a begin_frame discards the open frame first, so no frame holds it) */
    R->debug = NULL;
    frame(R, &R->fd);
    w = R->fd.viewport[2];
    h = R->fd.viewport[3];
    if (u8(&R->in) % 4 == 0 && w > 0 && h > 0 && w <= 128 && h <= 128) { /* the read-back: w x h floats */
        R->debug = (float *)malloc(sizeof(float) * (size_t)w * (size_t)h);
        R->fd.debug_thickness = R->debug;
        R->fd.debug_ramp = (u8(&R->in) & 1) ? R->ramp[u8(&R->in) % NR] : NULL;
    }
    res = fogvol_begin_frame(R->ctx, &R->fd);
    expect_logged(R, res, e);
}

static void op_add_volume(run *R)
{
    rd *in = &R->in;
    fogvol_volume_desc vd;
    int e = R->errors, i;
    fogvol_result res;
    memset(&vd, 0, sizeof vd);
    vd.mesh = R->mesh[u8(in) % NM];
    vd.ramp = R->ramp[u8(in) % NR];
    matrix(in, vd.model);
    vd.negative = (int)(u8(in) % 4 == 0);
    if (u8(in) % 4 == 0) vd.density = R->tex[u8(in) % NT];
    if (u8(in) % 4 == 0) vd.color = R->tex[u8(in) % NT];
    if (u8(in) % 4 == 0)
        for (i = 0; i < 8; ++i) vd.density_map[i] = fval(in);
    if (u8(in) % 4 == 0)
        for (i = 0; i < 6; ++i) vd.color_map[i] = fval(in);
    res = fogvol_add_volume(R->ctx, &vd);
    expect_logged(R, res, e);
}

static void occluder_cb(fogvol_context *ctx, void *u)
{
    run *R = (run *)u;
    float m[16];
    int e = R->errors;
    fogvol_result res;
    matrix(&R->in, m);
    res = fogvol_occluder_transform(ctx, m);
    expect_logged(R, res, e);
}

static void op_add_occluder(run *R)
{
    rd *in = &R->in;
    float m[16];
    int e = R->errors;
    fogvol_result res;
    if (u8(in) % 4 == 0) {
        res = fogvol_add_occluder_callback(R->ctx, (u8(in) % 8) ? occluder_cb : NULL, R);
    } else {
        fogvol_mesh *mesh = R->mesh[u8(in) % NM];
        matrix(in, m);
        res = fogvol_add_occluder(R->ctx, mesh, (u8(in) % 16) ? m : NULL);
    }
    expect_logged(R, res, e);
}

static void op_add_light(run *R)
{
    rd *in = &R->in;
    fogvol_light_desc ld;
    int e = R->errors;
    fogvol_result res;
    memset(&ld, 0, sizeof ld);
    ld.mesh = R->mesh[u8(in) % NM];
    matrix(in, ld.model);
    ld.color[0] = (u8(in) & 1) ? fval(in) : 0.5f;
    ld.intensity = (u8(in) & 3) ? 0.0f : fval(in);
    res = fogvol_add_light(R->ctx, (u8(in) % 16) ? &ld : NULL);
    expect_logged(R, res, e);
}

static void op_end(run *R)
{
    fogvol_frame_stats st;
    int e = R->errors, want = (int)(u8(&R->in) & 1);
    fogvol_result res = fogvol_end_frame(R->ctx, want ? &st : NULL);
    expect_logged(R, res, e);
    g_frames += res == FOGVOL_SUCCESS;
    if (want && res == FOGVOL_SUCCESS && (st.passes < 0 || st.groups > st.volumes)) abort();
}

static void op_prepare(run *R)
{
    fogvol_mrt_info mi;
    fogvol_occluder_info oi;
    int e = R->errors, which = (int)(u8(&R->in) % 3);
    fogvol_result res;
    if (which == 0) res = fogvol_occluder_prepare(R->ctx, (u8(&R->in) % 16) ? &oi : NULL);
    else if (which == 1) res = fogvol_mrt_prepare(R->ctx, (u8(&R->in) % 16) ? &mi : NULL);
    else {
        float m[16];
        matrix(&R->in, m);
        res = fogvol_occluder_transform(R->ctx, m); /* outside an occluder callback */
    }
    expect_logged(R, res, e);
}

static void op_post(run *R)
{
    rd *in = &R->in;
    fogvol_frame_desc fd = R->fd;
    int e = R->errors, which = (int)(u8(in) % 3), size = (int)(u8(in) % 4);
    fogvol_result res;
    int ts[2];
    fd.debug_thickness = NULL;
    ts[0] = size == 0 ? 0 : size == 1 ? 64 : (int)u16(in) - 100;
    ts[1] = size == 0 ? 0 : size == 1 ? 64 : (int)u16(in) - 100;
    if (which == 0) {
        fogvol_dof_desc d;
        memset(&d, 0, sizeof d);
        d.frame = (u8(in) % 16) ? &fd : NULL;
        d.color_texture = (u8(in) % 8) ? (R->gl ? g_color_tex : 6u) : 0u;
        memcpy(d.texture_size, ts, sizeof ts);
        d.focus_distance = (u8(in) & 1) ? 3.0f : fval(in);
        d.focus_range = (u8(in) & 1) ? 2.0f : fval(in);
        d.max_radius = (u8(in) & 1) ? 0.0f : fval(in);
        d.taps = (int)(u8(in) % 14);
        res = fogvol_post_dof(R->ctx, &d);
    } else if (which == 1) {
        fogvol_outline_desc d;
        memset(&d, 0, sizeof d);
        d.frame = &fd;
        d.normal_texture = (u8(in) & 1) ? (R->gl ? g_color_tex : 7u) : 0u;
        memcpy(d.texture_size, ts, sizeof ts);
        if (u8(in) & 1) d.color[u8(in) % 4] = fval(in);
        d.depth_threshold = (u8(in) & 1) ? 0.0f : fval(in);
        d.normal_threshold = (u8(in) & 1) ? 0.0f : fval(in);
        res = fogvol_post_outlines(R->ctx, &d);
    } else {
        fogvol_distance_fog_desc d;
        memset(&d, 0, sizeof d);
        d.frame = &fd;
        d.ramp = R->ramp[u8(in) % NR];
        memcpy(d.texture_size, ts, sizeof ts);
        d.start = (u8(in) & 1) ? 1.0f : fval(in);
        res = fogvol_post_distance_fog(R->ctx, &d);
    }
    expect_logged(R, res, e);
}

/* one call picked by the op byte */
static void op(run *R, unsigned o)
{
    switch (o % 24) {
    case 0: case 1: op_mesh(R, 1); break;
    case 2: op_mesh(R, 0); break;
    case 3: case 4: op_ramp(R, 1); break;
    case 5: op_ramp(R, 0); break;
    case 6: op_texture(R, 1); break;
    case 7: op_texture(R, 0); break;
    case 8: case 9: op_begin(R); break;
    case 10: case 11: case 12: op_add_volume(R); break;
    case 13: op_add_occluder(R); break;
    case 14: op_add_light(R); break;
    case 15: case 16: op_end(R); break;
    case 17: fogvol_cancel_frame(R->ctx); break;
    case 18: op_prepare(R); break;
    case 19: op_post(R); break;
    case 20: fogvol_set_dither(R->ctx, (int)(u8(&R->in) & 1)); break;
    case 21: op_validate(R); break;
    default: { /* a whole frame in one go: begin, volumes, end */
        int n = (int)(u8(&R->in) % 5), i;
        op_begin(R);
        for (i = 0; i < n; ++i) op_add_volume(R);
        op_end(R);
    } break;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    run *R = (run *)calloc(1, sizeof *R);
    unsigned first;
    int i, steps = 0;
    if (!R) return 0;
    R->in.p = data;
    R->in.n = size;
    first = u8(&R->in);
    R->gl = (first & 3) == 3 && gl_ready();
    R->cnt.fail_at = (first & 8) ? 1 + 2 * (long)u8(&R->in) : 0;
    make_context(R);
    g_runs++;
    g_gl_runs += R->gl;
    g_contexts += R->ctx != NULL;
    while (R->ctx && R->in.n > 0 && steps++ < 400) op(R, u8(&R->in));
    if (R->ctx && !(first & 4)) { /* else fogvol_destroy_context destroys what is alive */
        for (i = 0; i < NM; ++i)
            if (R->mesh[i]) fogvol_destroy_mesh(R->ctx, R->mesh[i]);
        for (i = 0; i < NR; ++i)
            if (R->ramp[i]) fogvol_destroy_ramp(R->ctx, R->ramp[i]);
        for (i = 0; i < NT; ++i)
            if (R->tex[i]) fogvol_destroy_volume_texture(R->ctx, R->tex[i]);
    }
    fogvol_destroy_context(R->ctx);
    if (R->cnt.live != 0) abort();                           /* host memory: every allocation freed */
    if (!R->gl && R->nb.creates != R->nb.destroys) abort(); /* backend objects: every one destroyed */
    if (R->gl)
        while (glGetError() != GL_NO_ERROR) {
        } /* (fogvol's own GL errors are the GL error tests' matter; the next input starts clean) */
    free(R->debug);
    free(R);
    return 0;
}
