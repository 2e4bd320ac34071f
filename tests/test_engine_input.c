/* test_engine_input.c - the engine's own depth and geometry, against ground
   truth computed without fogvol (tests/raycast.h ray-casts the very triangles,
   or the analytic ray/box chord):

   1. ENGINE_DEPTH from depth buffers that are not textures: the default
      framebuffer, a 4x multisampled DEPTH24_STENCIL8 renderbuffer (viewport at
      an offset), DEPTH_COMPONENT32F and DEPTH_COMPONENT16 renderbuffers; fogvol
      blits them into its own depth texture. Bound: 1e-4 (far - near) + the
      depth quantum of the format at the farthest occluder. The engine's depth
      and framebuffer bindings are unchanged afterwards.
   2. Occluders drawn by the engine with its own program, attribute location,
      interleaved layout and VAO (fogvol_occluder_prepare + fogvol_occluder_snippet)
      on PS20 and FLOAT: the same thickness as fogvol-drawn occluders and the truth.
   3. Meshes as engines store them: a UV sphere with a seam and a cube with
      per-face vertices are refused without weld_distance and accepted with it
      (merged counts computed by hand), rendered against the truth / the
      analytic chord; an interleaved buffer (stride 32, offset 12) with 16-bit
      indices renders bit-identically to the packed mesh, through the GL
      backend's in-place upload and through the repacking path; bad layouts
      give result codes and logged reasons. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/raycast.h"
#include "tests/shapes.h"
#include "tests/fixtures.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define W 128
#define H 128
#define OX 16 /* viewport origin of the offset case */
#define OY 8

static char g_log[1024];
static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l == FOGVOL_LOG_ERROR) snprintf(g_log, sizeof g_log, "%s", m);
    if (l == FOGVOL_LOG_ERROR && getenv("FV_VERBOSE")) print_message("  [fogvol error] %s\n", m);
}

typedef struct tobj {
    shp_mesh m;
    float model[16];
    int sign; /* +1 volume, 0 occluder */
} tobj;

static rc_camera camera(void)
{
    rc_camera c;
    memset(&c, 0, sizeof c);
    c.eye[0] = 2.0;
    c.eye[1] = 1.5;
    c.eye[2] = 6.0;
    c.up[1] = 1.0;
    c.fovy_deg = 50.0;
    c.aspect = 1.0;
    c.znear = 1.0;
    c.zfar = 20.0;
    c.width = W;
    c.height = H;
    return c;
}

/* a sphere volume cut by a tilted slab occluder */
static int scene(tobj *o)
{
    float r[16], t[16];
    o[0].m = shp_sphere(1.5f, 48, 24);
    shp_mat_identity(o[0].model);
    o[0].sign = 1;
    o[1].m = shp_box(1.0f, 2.2f, 0.25f);
    shp_mat_rotate(r, 25.0f, 0.0f, 1.0f, 0.0f);
    shp_mat_translate(t, 0.9f, 0.0f, 0.1f);
    shp_mat_mul(o[1].model, t, r);
    o[1].sign = 0;
    return 2;
}

static void free_objs(tobj *o, int n)
{
    int i;
    for (i = 0; i < n; ++i) shp_free(&o[i].m);
}

static void truth(const rc_camera *c, const tobj *o, int n, double *gt, unsigned char *interior)
{
    rc_object ro[4];
    rc_scene rs;
    int i, x, y;
    for (i = 0; i < n; ++i) {
        ro[i].pos = o[i].m.pos;
        ro[i].vcount = o[i].m.vcount;
        ro[i].idx = o[i].m.idx;
        ro[i].icount = o[i].m.icount;
        memcpy(ro[i].model, o[i].model, sizeof ro[i].model);
        ro[i].sign = o[i].sign;
    }
    assert_true(rc_scene_init(&rs, ro, n));
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            gt[y * W + x] = rc_trace(&rs, c, x + 0.5, y + 0.5).thickness;
            interior[y * W + x] = (unsigned char)rc_interior(&rs, c, x, y);
        }
    rc_scene_free(&rs);
}

/* per pixel, how far the nearest occluder's view depth moves between the
   pixel's centre and its corners: a multisampled depth resolved to one of its
   samples (not the centre) moves the clamped thickness by at most that much */
static void opaque_spread(const rc_camera *c, const tobj *o, int n, double *spread)
{
    rc_object ro[4];
    rc_scene rs;
    double *cg = (double *)malloc(sizeof(double) * (W + 1) * (H + 1));
    int i, x, y;
    for (i = 0; i < n; ++i) {
        ro[i].pos = o[i].m.pos;
        ro[i].vcount = o[i].m.vcount;
        ro[i].idx = o[i].m.idx;
        ro[i].icount = o[i].m.icount;
        memcpy(ro[i].model, o[i].model, sizeof ro[i].model);
        ro[i].sign = o[i].sign;
    }
    assert_true(rc_scene_init(&rs, ro, n));
    for (y = 0; y <= H; ++y)
        for (x = 0; x <= W; ++x) cg[y * (W + 1) + x] = rc_trace(&rs, c, x, y).opaque_w;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            double ctr = rc_trace(&rs, c, x + 0.5, y + 0.5).opaque_w, v[4], m = 0;
            v[0] = cg[y * (W + 1) + x];
            v[1] = cg[y * (W + 1) + x + 1];
            v[2] = cg[(y + 1) * (W + 1) + x];
            v[3] = cg[(y + 1) * (W + 1) + x + 1];
            for (i = 0; i < 4; ++i) {
                double d = isinf(v[i]) && isinf(ctr) ? 0.0 : fabs(v[i] - ctr);
                if (!(d <= m)) m = d;
            }
            spread[y * W + x] = m;
        }
    rc_scene_free(&rs);
    free(cg);
}

static double max_err(const float *t, const double *gt, const unsigned char *interior, int *pixels)
{
    double m = 0;
    int i, n = 0;
    for (i = 0; i < W * H; ++i) {
        if (!interior[i]) continue;
        if (fabs(t[i] - gt[i]) > m) m = fabs(t[i] - gt[i]);
        n += gt[i] > 0;
    }
    if (pixels) *pixels = n;
    return m;
}

static unsigned g_speedups_off; /* fogvol_context_desc.disable_speedups of make_ctx */
static fogvol_context *make_ctx(fogvol_tier tier, unsigned variants)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = tier;
    cd.variants = variants;
    cd.disable_dither = 1;
    cd.disable_speedups = g_speedups_off;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    return fv;
}

static fogvol_mesh *mesh_of(fogvol_context *fv, const shp_mesh *m, int open)
{
    fogvol_mesh_desc md;
    fogvol_mesh *out = NULL;
    fx_mesh_desc(&md, m, open);
    assert_int_equal(fogvol_create_mesh(fv, &md, &out, NULL), FOGVOL_SUCCESS);
    return out;
}

static fogvol_ramp *ramp_of(fogvol_context *fv)
{
    fogvol_ramp_desc rd;
    fogvol_ramp *r = NULL;
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f;
    rd.color[1] = 0.8f;
    rd.color[2] = 0.6f;
    rd.density = 0.6f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &r), FOGVOL_SUCCESS);
    return r;
}

static void frame_of(fogvol_frame_desc *fd, const rc_camera *c, float *thick)
{
    fx_frame_desc(fd, c, W, H);
    fd->debug_thickness = thick;
}

static void add_volume(fogvol_context *fv, fogvol_mesh *m, const float model[16], fogvol_ramp *ramp)
{
    fogvol_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.mesh = m;
    vd.ramp = ramp;
    memcpy(vd.model, model, sizeof vd.model);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
}

static void save_png(const char *name, int w, int h)
{
    unsigned char *px = (unsigned char *)malloc((size_t)w * h * 4);
    char path[256];
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    mkdir("build", 0777);
    mkdir("build/engine_input", 0777);
    snprintf(path, sizeof path, "build/engine_input/%s.png", name);
    stbi_flip_vertically_on_write(1);
    stbi_write_png(path, w, h, 4, px, w * 4);
    free(px);
}

/* ---- the engine: its own program, attribute location 3, interleaved vertices
   (uv 2 floats, position 3, pad 3: stride 32, position at byte 8), own VAO ---- */
typedef struct engine {
    GLuint prog;
    GLint u_mvp, u_mv, u_fv;
} engine;

static void engine_init(engine *e)
{
    static const char *vs = "#version 330 core\nlayout(location = 3) in vec3 e_pos;\n"
                            "layout(location = 1) in vec2 e_uv;\n"
                            "uniform mat4 e_mvp;\nuniform mat4 e_mv;\nout float e_vd;\nout vec2 e_t;\n"
                            "void main() { e_vd = -(e_mv * vec4(e_pos, 1.0)).z; e_t = e_uv;\n"
                            "    gl_Position = e_mvp * vec4(e_pos, 1.0); }\n";
    const char *fs[3];
    fs[0] = "#version 330 core\n";
    fs[1] = fogvol_occluder_snippet();
    fs[2] = "in float e_vd;\nin vec2 e_t;\nout vec4 e_color;\n"
            "void main() { e_color = fogvol_occluder_color(e_vd) + vec4(0.0 * e_t.x); }\n";
    e->prog = fx_program(&vs, 1, fs, 3);
    e->u_mvp = glGetUniformLocation(e->prog, "e_mvp");
    e->u_mv = glGetUniformLocation(e->prog, "e_mv");
    e->u_fv = glGetUniformLocation(e->prog, "fogvol_mrt");
}

/* draws the occluders with the engine's program into the bound framebuffer */
static void engine_draw(const engine *e, const tobj *o, int n, const float view[16], const float proj[16],
                        const float *fv_uniforms)
{
    GLuint vao, vbo, ibo;
    int i, k;
    glUseProgram(e->prog);
    if (fv_uniforms) glUniform4fv(e->u_fv, 2, fv_uniforms);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ibo);
    for (i = 0; i < n; ++i) {
        float mv[16], mvp[16], *vb;
        if (o[i].sign != 0) continue;
        shp_mat_mul(mv, view, o[i].model);
        shp_mat_mul(mvp, proj, mv);
        glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, mvp);
        glUniformMatrix4fv(e->u_mv, 1, GL_FALSE, mv);
        vb = (float *)calloc((size_t)o[i].m.vcount * 8, sizeof(float));
        for (k = 0; k < o[i].m.vcount; ++k) {
            vb[8 * k] = 0.25f;
            vb[8 * k + 1] = 0.75f;
            memcpy(vb + 8 * k + 2, o[i].m.pos + 3 * k, 12);
        }
        glBindBuffer(GL_ARRAY_BUFFER, vbo);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(32 * (size_t)o[i].m.vcount), vb, GL_STREAM_DRAW);
        free(vb);
        glVertexAttribPointer(3, 3, GL_FLOAT, GL_FALSE, 32, (const void *)8);
        glEnableVertexAttribArray(3);
        glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 32, (const void *)0);
        glEnableVertexAttribArray(1);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(4 * (size_t)o[i].m.icount), o[i].m.idx, GL_STREAM_DRAW);
        glDrawElements(GL_TRIANGLES, o[i].m.icount, GL_UNSIGNED_INT, NULL);
    }
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ibo);
    glUseProgram(0);
}

/* ==== 1. the engine's depth from depth buffers that are not textures ========= */

typedef struct depth_case {
    const char *name;
    GLenum format; /* 0: the default framebuffer */
    int samples, offset, by_name;
    int bits;      /* depth quantum 2^-bits (0: float, negligible) */
    fogvol_tier tier;  /* 0: FLOAT */
    unsigned variants; /* besides ENGINE_DEPTH */
    int texture;       /* 1: a depth texture of this format (FOGVOL_DEPTH_SOURCE_TEXTURE) */
} depth_case;

static void run_depth_case(const depth_case *dc, tobj *o, int n, const double *gt, const double *spread,
                           const unsigned char *interior, double *err_out)
{
    rc_camera c = camera();
    engine e;
    fogvol_tier tier = dc->tier ? dc->tier : FOGVOL_TIER_FLOAT;
    fogvol_context *fv = make_ctx(tier, FOGVOL_VARIANT_ENGINE_DEPTH | dc->variants);
    fogvol_frame_stats st;
    fogvol_tier_info ti;
    fogvol_mesh *vol = mesh_of(fv, &o[0].m, 0);
    fogvol_ramp *ramp = ramp_of(fv);
    fogvol_frame_desc fd;
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    size_t zbytes = sizeof(float) * (W + OX) * (H + OY);
    float *zb = (float *)malloc(zbytes), *za = (float *)malloc(zbytes);
    GLuint fbo = 0, rb[2] = {0, 0}, dtex = 0;
    GLint draw_before = 0, read_before = 0, draw_after = -1, read_after = -1;
    int fw = W + (dc->offset ? OX : 0), fh = H + (dc->offset ? OY : 0), x0 = dc->offset ? OX : 0,
        y0 = dc->offset ? OY : 0, i, pixels;
    double range = c.zfar - c.znear, bound, wmax = 9.0, err;
    engine_init(&e);
    if (dc->format) {
        glGenFramebuffers(1, &fbo);
        glGenRenderbuffers(2, rb);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, dc->samples, GL_RGBA8, fw, fh);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
        if (dc->texture) { /* a depth texture, sampled directly */
            glGenTextures(1, &dtex);
            glBindTexture(GL_TEXTURE_2D, dtex);
            glTexImage2D(GL_TEXTURE_2D, 0, (GLint)dc->format, fw, fh, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glBindTexture(GL_TEXTURE_2D, 0);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, dtex, 0);
        } else {
            glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
            glRenderbufferStorageMultisample(GL_RENDERBUFFER, dc->samples, dc->format, fw, fh);
            glFramebufferRenderbuffer(GL_FRAMEBUFFER,
                                      dc->format == GL_DEPTH24_STENCIL8 ? GL_DEPTH_STENCIL_ATTACHMENT
                                                                       : GL_DEPTH_ATTACHMENT,
                                      GL_RENDERBUFFER, rb[1]);
        }
        glBindRenderbuffer(GL_RENDERBUFFER, 0);
        assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    } else {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
    glViewport(0, 0, fw, fh);
    glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glViewport(x0, y0, W, H);
    frame_of(&fd, &c, thick);
    fd.viewport[0] = x0;
    fd.viewport[1] = y0;
    engine_draw(&e, o, n, fd.view, fd.projection, NULL);
    if (dc->samples == 0) glReadPixels(0, 0, fw, fh, GL_DEPTH_COMPONENT, GL_FLOAT, zb);
    if (dc->texture) {
        fd.engine_depth_texture = dtex;
    } else if (dc->by_name) {
        fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT;
        fd.engine_depth_framebuffer = fbo;
        glBindFramebuffer(GL_FRAMEBUFFER, 0); /* another framebuffer bound: the name decides */
    } else {
        fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
    }
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_before);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_before);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_volume(fv, vol, o[0].model, ramp);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_tier_costs(tier, FOGVOL_VARIANT_ENGINE_DEPTH | dc->variants, &ti), FOGVOL_SUCCESS);
    /* PS20 sums B and F in one pass where it sums in integers (the engine's depth as an R32F O) */
    assert_int_equal(st.passes, ti.library_passes - st.exact_sum);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_after);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_after);
    assert_int_equal(draw_after, draw_before);
    assert_int_equal(read_after, read_before);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    if (dc->samples == 0) { /* the engine's depth buffer is untouched */
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glReadPixels(0, 0, fw, fh, GL_DEPTH_COMPONENT, GL_FLOAT, za);
        assert_memory_equal(za, zb, sizeof(float) * (size_t)fw * fh);
    }
    if (!dc->format)
        save_png(tier == FOGVOL_TIER_FLOAT ? "engine_depth_default_fb_float" : "engine_depth_default_fb_ps20", W, H);
    /* FLOAT: fp32 sums (1e-4 of the range, as the tier's other tests); PS20: 1 LSB of the 12-bit encoding
       per pair of faces (one pair here); + the depth quantum at the farthest occluder */
    bound = (tier == FOGVOL_TIER_FLOAT ? 1e-4 * range : range / 4096.0) +
            (dc->bits ? ldexp(1.0, -dc->bits) * wmax * wmax * range / (c.zfar * c.znear) : 0.0);
    err = max_err(thick, gt, interior, &pixels);
    if (dc->samples) { /* one of the pixel's samples: the error beyond the occluder's depth spread over the pixel */
        double centre = err;
        err = 0;
        for (i = 0; i < W * H; ++i) {
            double out = fabs(thick[i] - gt[i]) - spread[i];
            if (interior[i] && out > err) err = out;
        }
        print_message("  %-5s %-34s (vs the pixel centre %.3g of the range: the resolve keeps one sample)\n",
                      fogvol_tier_name(tier), dc->name, centre / range);
    }
    print_message("  %-5s %-34s max |error| %.3g units = %.3g of the range (bound %.3g), %d fogged pixels\n",
                  fogvol_tier_name(tier), dc->name, err, err / range, bound / range, pixels);
    assert_true(pixels > 1000);
    assert_true(err <= bound);
    *err_out = err / range;
    for (i = 0; i < 2; ++i)
        if (rb[i]) glDeleteRenderbuffers(1, &rb[i]);
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (dtex) glDeleteTextures(1, &dtex);
    glDeleteProgram(e.prog);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    free(thick);
    free(zb);
    free(za);
}

static void test_engine_depth_buffers(void **state)
{
    static const depth_case cases[] = {
        {"default framebuffer (D24S8)", 0, 0, 0, 0, 24, FOGVOL_TIER_FLOAT, 0, 0},
        {"4x MSAA D24S8 renderbuffer, offset", GL_DEPTH24_STENCIL8, 4, 1, 1, 24, FOGVOL_TIER_FLOAT, 0, 0},
        {"DEPTH_COMPONENT32F renderbuffer", GL_DEPTH_COMPONENT32F, 0, 0, 0, 0, FOGVOL_TIER_FLOAT, 0, 0},
        {"DEPTH_COMPONENT16 renderbuffer", GL_DEPTH_COMPONENT16, 0, 1, 0, 16, FOGVOL_TIER_FLOAT, 0, 0},
        /* PS20: a full-screen pass encodes the engine's depth into O */
        {"default framebuffer (D24S8)", 0, 0, 0, 0, 24, FOGVOL_TIER_PS20, 0, 0},
        {"4x MSAA D24S8 renderbuffer, offset", GL_DEPTH24_STENCIL8, 4, 1, 1, 24, FOGVOL_TIER_PS20, 0, 0},
        {"DEPTH_COMPONENT24 texture, offset", GL_DEPTH_COMPONENT24, 0, 1, 0, 24, FOGVOL_TIER_PS20, 0, 1},
        {"DEPTH_COMPONENT32F texture, ALU+single", GL_DEPTH_COMPONENT32F, 0, 0, 0, 0, FOGVOL_TIER_PS20,
         FOGVOL_VARIANT_ALU | FOGVOL_VARIANT_SINGLE_TARGET, 1},
    };
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o), i;
    double *gt = (double *)malloc(sizeof(double) * W * H), err, before;
    double *spread = (double *)malloc(sizeof(double) * W * H);
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W + OX, H + OY, 1));
    truth(&c, o, n, gt, interior);
    opaque_spread(&c, o, n, spread);
    { /* before: without the engine's depth the fog runs through the occluder */
        fogvol_context *fv = make_ctx(FOGVOL_TIER_FLOAT, 0);
        fogvol_mesh *vol = mesh_of(fv, &o[0].m, 0);
        fogvol_ramp *ramp = ramp_of(fv);
        fogvol_frame_desc fd;
        frame_of(&fd, &c, thick);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        add_volume(fv, vol, o[0].model, ramp);
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
        before = max_err(thick, gt, interior, NULL) / (c.zfar - c.znear);
        print_message("  without the engine's depth: max |error| %.3g of the range\n", before);
        fogvol_destroy_mesh(fv, vol);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
    }
    for (i = 0; i < (int)(sizeof cases / sizeof cases[0]); ++i) {
        run_depth_case(&cases[i], o, n, gt, spread, interior, &err);
        assert_true(err < before / 100);
    }
    glu_destroy(&g);
    free_objs(o, n);
    free(gt);
    free(spread);
    free(interior);
    free(thick);
}

/* A copy of the engine's depth that the GL refuses fails its frame, logged, and keeps nothing: the
   frames after it copy again. Frame 1 of five has its viewport's far corner past GL_MAX_TEXTURE_SIZE
   (the copy keeps the engine's texel coordinates, so its texture is that wide); the others, the whole
   framebuffer, each against the ray-cast thickness. (A refused texture kept as if made failed every
   later copy: the frames after it returned FOGVOL_ERROR_BACKEND and drew no fog.) */
static void test_engine_depth_copy_recovers(void **state)
{
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o), f, i, pixels;
    double *gt = (double *)malloc(sizeof(double) * W * H), range = c.zfar - c.znear, err, bound;
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    glu_ctx g;
    engine e;
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_result r;
    GLint maxtex = 0;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    truth(&c, o, n, gt, interior);
    engine_init(&e);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxtex);
    fv = make_ctx(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH);
    vol = mesh_of(fv, &o[0].m, 0);
    ramp = ramp_of(fv);
    /* the default framebuffer's 24-bit depth: its quantum at the farthest occluder (as run_depth_case) */
    bound = 1e-4 * range + ldexp(1.0, -24) * 81.0 * range / (c.zfar * c.znear);
    for (f = 0; f < 5; ++f) {
        int refused = f == 1 && maxtex <= 32767;
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, W, H);
        glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
        frame_of(&fd, &c, refused ? NULL : thick);
        engine_draw(&e, o, n, fd.view, fd.projection, NULL);
        fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
        if (refused) fd.viewport[0] = maxtex;
        for (i = 0; i < W * H; ++i) thick[i] = -1.0f;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        add_volume(fv, vol, o[0].model, ramp);
        g_log[0] = 0;
        r = fogvol_end_frame(fv, NULL);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        if (refused) {
            assert_int_equal(r, FOGVOL_ERROR_BACKEND);
            assert_non_null(strstr(g_log, "copy the engine's depth"));
            print_message("  frame %d, viewport at x = %d: %s\n", f, maxtex, g_log);
            continue;
        }
        assert_int_equal(r, FOGVOL_SUCCESS);
        err = max_err(thick, gt, interior, &pixels);
        print_message("  frame %d: max |error| %.3g of the range (bound %.3g), %d fogged pixels\n", f, err / range,
                      bound / range, pixels);
        assert_true(pixels > 1000);
        assert_true(err <= bound);
    }
    glDeleteProgram(e.prog);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    free_objs(o, n);
    free(gt);
    free(interior);
    free(thick);
}

/* A mirrored view matrix (a planar reflection's, its x row negated) given as view + projection: the
   thickness is the unmirrored ray cast read at the mirrored pixel, on FLOAT and PS20, the occluder drawn
   by fogvol. (Front and back faces were swapped: the thickness came out negated, the fog gone.) */
static void test_mirrored_view(void **state)
{
    static const fogvol_tier tiers[2] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_PS20};
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o), k, x, y, pixels;
    double *gt = (double *)malloc(sizeof(double) * W * H), range = c.zfar - c.znear, err, bound;
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    truth(&c, o, n, gt, interior);
    for (k = 0; k < 2; ++k) {
        fogvol_context *fv = make_ctx(tiers[k], 0);
        fogvol_mesh *vol = mesh_of(fv, &o[0].m, 0), *occ = mesh_of(fv, &o[1].m, 1);
        fogvol_ramp *ramp = ramp_of(fv);
        fogvol_frame_desc fd;
        frame_of(&fd, &c, thick);
        for (x = 0; x < 4; ++x) fd.view[x * 4] = -fd.view[x * 4]; /* view-space x negated */
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        add_volume(fv, vol, o[0].model, ramp);
        assert_int_equal(fogvol_add_occluder(fv, occ, o[1].model), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
        for (err = 0.0, pixels = 0, y = 0; y < H; ++y)
            for (x = 0; x < W; ++x) {
                int m = y * W + (W - 1 - x);
                if (!interior[m]) continue;
                if (fabs(thick[y * W + x] - gt[m]) > err) err = fabs(thick[y * W + x] - gt[m]);
                pixels += gt[m] > 0.0;
            }
        bound = tiers[k] == FOGVOL_TIER_FLOAT ? 1e-4 * range : 2.0 * range / 4096.0;
        print_message("  %s, mirrored view: max |error| %.3g of the range (bound %.3g), %d fogged pixels\n",
                      fogvol_tier_name(tiers[k]), err / range, bound / range, pixels);
        assert_true(pixels > 1000);
        assert_true(err <= bound);
        fogvol_destroy_mesh(fv, vol);
        fogvol_destroy_mesh(fv, occ);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
    }
    glu_destroy(&g);
    free_objs(o, n);
    free(gt);
    free(interior);
    free(thick);
}

/* refusals: no depth buffer, unknown source, a texture source without a texture */
static void test_engine_depth_refusals(void **state)
{
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o);
    glu_ctx g;
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_context_desc cd;
    GLuint fbo, tex;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    fv = make_ctx(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH);
    vol = mesh_of(fv, &o[0].m, 0);
    ramp = ramp_of(fv);
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    frame_of(&fd, &c, NULL);
    fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_volume(fv, vol, o[0].model, ramp);
    g_log[0] = 0;
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(g_log, "depth"));
    print_message("  no depth buffer: %s\n", g_log);
    fd.engine_depth_source = (fogvol_depth_source)7;
    g_log[0] = 0;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(g_log, "engine_depth_source"));
    fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_TEXTURE;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    { /* a backend without copy_depth: depth buffers refused, depth textures still fine */
        fogvol_gl_desc gd;
        fogvol_backend table;
        memset(&gd, 0, sizeof gd);
        gd.get_proc_address = glu_proc;
        assert_int_equal(fogvol_gl_backend_create(&gd, NULL, NULL, &table), FOGVOL_SUCCESS);
        table.copy_depth = NULL;
        memset(&cd, 0, sizeof cd);
        cd.backend = table;
        cd.logger.func = logger;
        cd.tier = FOGVOL_TIER_FLOAT;
        cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        g_log[0] = 0;
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_UNSUPPORTED);
        assert_non_null(strstr(g_log, "copy_depth"));
        fogvol_destroy_context(fv);
        table.destroy(table.user_data);
    }
    /* the engine's depth where no shader reads it: MRT (the engine writes O), PS20 with COUNT
       or in GLSL 120 (no texelFetch), PS13 */
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_MRT;
    cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    cd.tier = FOGVOL_TIER_PS13;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    cd.tier = FOGVOL_TIER_PS20;
    cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH | FOGVOL_VARIANT_COUNT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    cd.gl.dialect = FOGVOL_GLSL_120;
    g_log[0] = 0;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_non_null(strstr(g_log, "fogvol"));
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    glu_destroy(&g);
    free_objs(o, n);
}

/* ==== 1b. the engine's depth over a camera walk, frame after frame (issue 31) ==
   Each source of the engine's depth through a 60-frame walk (tests/sequence.h's walk script:
   into the fog box and out again, the occluders leaving and coming back, split-screen frames
   whose two views have their own cameras and depth, frames after a cancelled one, a smaller
   viewport now and then). The engine clears and draws its occluders into the view's viewport
   of its framebuffer every frame; fogvol must read that depth as it is at each end_frame. Each
   view's thickness (debug read-back) is compared with the ray cast of that view's camera and
   occluders; a wrong pixel is an interior pixel off by more than the bound of
   test_engine_depth_buffers. The engine's other depth buffers must come back unchanged. */

#define SW 64 /* the walk's framebuffer */
#define SH 64
#define WALK_FRAMES 60

typedef struct walk_src {
    const char *name;
    GLenum format;              /* 0: the default framebuffer */
    int samples, texture, bits; /* texture: the depth is a texture attachment; bits: depth quantum 2^-bits */
    fogvol_depth_source source; /* FRAMEBUFFER_OBJECT: the engine's FBO by name, the default framebuffer bound */
} walk_src;

static const walk_src g_walk_srcs[] = {
    {"default framebuffer", 0, 0, 0, 24, FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER},
    {"bound FBO, D24S8 renderbuffer", GL_DEPTH24_STENCIL8, 0, 0, 24, FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER},
    {"FBO by name, DEPTH32F renderbuffer", GL_DEPTH_COMPONENT32F, 0, 0, 0, FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT},
    {"FBO by name, DEPTH24 texture", GL_DEPTH_COMPONENT24, 0, 1, 24, FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT},
    {"FBO by name, 4x MSAA D24S8", GL_DEPTH24_STENCIL8, 4, 0, 24, FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT},
    {"depth texture (no copy)", GL_DEPTH_COMPONENT24, 0, 1, 24, FOGVOL_DEPTH_SOURCE_TEXTURE},
};
#define NWALK ((int)(sizeof g_walk_srcs / sizeof g_walk_srcs[0]))

typedef struct walk {
    const walk_src *src;
    fogvol_tier tier;
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    engine e;
    GLuint fbo, rb[2], dtex; /* the engine's framebuffer (fbo 0: the default one) */
    tobj o[3];               /* the fog box, a column and a wall */
    float *thick, *zb, *za;
    double *gt, *spread, *slope; /* slope: rc_depth_slope of interior pixels (the GL's vertex snapping) */
    unsigned char *interior;
    long depth_changed;      /* depth values of the engine's buffers fogvol changed */
    int failed, gl_errors;   /* views whose end_frame failed, that left a GL error */
    unsigned char *sheet;    /* 10 frames x (rendered, truth), RGB */
} walk;

/* the camera of a walk position: from outside the box (w = 0) to inside it (w = 1), turning a little */
static rc_camera walk_camera(double w, const int vp[4])
{
    rc_camera c;
    static const double e0[3] = {1.6, 1.1, 9.0}, e1[3] = {0.3, 0.2, 0.6};
    int i;
    memset(&c, 0, sizeof c);
    for (i = 0; i < 3; ++i) c.eye[i] = e0[i] + (e1[i] - e0[i]) * w;
    c.target[0] = c.eye[0] - 0.25 + 0.2 * w;
    c.target[1] = c.eye[1] - 0.15;
    c.target[2] = c.eye[2] - 1.0;
    c.up[1] = 1.0;
    c.fovy_deg = 60.0;
    c.aspect = (double)vp[2] / vp[3];
    c.znear = 0.25;
    c.zfar = 30.0;
    c.width = vp[2];
    c.height = vp[3];
    return c;
}

static void walk_scene(tobj *o)
{
    o[0].m = shp_box(2.0f, 1.2f, 2.0f); /* the fog, around the walk's end */
    shp_mat_identity(o[0].model);
    o[0].sign = 1;
    o[1].m = shp_box(0.25f, 1.5f, 0.25f); /* a column inside the fog */
    shp_mat_translate(o[1].model, 0.9f, -0.2f, -0.6f);
    o[1].sign = 0;
    o[2].m = shp_box(1.5f, 2.0f, 0.15f); /* a wall cutting the fog's far part */
    shp_mat_translate(o[2].model, -1.3f, 0.0f, -1.5f);
    o[2].sign = 0;
}

/* The ray casts of the walk's views, made once for all sources and tiers (slot frame * 2 + view). */
static struct {
    int have[WALK_FRAMES * 2];
    double *gt, *spread, *slope;
    unsigned char *interior;
} g_walk_truth;

/* the ray cast of view v: thickness, interior pixels, and how far the nearest occluder's depth moves
   across each pixel (a multisampled source's resolve keeps one sample) */
static void walk_truth(walk *wk, const rc_camera *c, const sq_view *v)
{
    rc_object ro[3];
    rc_scene rs;
    int i, x, y, n = v->occluders ? 3 : 1, slot = v->frame * 2 + v->view;
    size_t off = (size_t)slot * SW * SH, np = (size_t)c->width * c->height;
    if (!g_walk_truth.gt) {
        g_walk_truth.gt = (double *)calloc((size_t)WALK_FRAMES * 2 * SW * SH, sizeof(double));
        g_walk_truth.spread = (double *)calloc((size_t)WALK_FRAMES * 2 * SW * SH, sizeof(double));
        g_walk_truth.slope = (double *)calloc((size_t)WALK_FRAMES * 2 * SW * SH, sizeof(double));
        g_walk_truth.interior = (unsigned char *)calloc((size_t)WALK_FRAMES * 2 * SW * SH, 1);
    }
    if (g_walk_truth.have[slot]) {
        memcpy(wk->gt, g_walk_truth.gt + off, np * sizeof(double));
        memcpy(wk->spread, g_walk_truth.spread + off, np * sizeof(double));
        memcpy(wk->slope, g_walk_truth.slope + off, np * sizeof(double));
        memcpy(wk->interior, g_walk_truth.interior + off, np);
        return;
    }
    for (i = 0; i < n; ++i) {
        ro[i].pos = wk->o[i].m.pos;
        ro[i].vcount = wk->o[i].m.vcount;
        ro[i].idx = wk->o[i].m.idx;
        ro[i].icount = wk->o[i].m.icount;
        memcpy(ro[i].model, wk->o[i].model, sizeof ro[i].model);
        ro[i].sign = wk->o[i].sign;
    }
    assert_true(rc_scene_init(&rs, ro, n));
    for (y = 0; y < c->height; ++y)
        for (x = 0; x < c->width; ++x) {
            int p = y * c->width + x, k;
            double ctr;
            rc_result r = rc_trace(&rs, c, x + 0.5, y + 0.5);
            wk->gt[p] = r.thickness;
            wk->interior[p] = (unsigned char)rc_interior(&rs, c, x, y);
            wk->spread[p] = wk->slope[p] = 0.0;
            if (!wk->interior[p]) continue;
            wk->slope[p] = rc_depth_slope(&rs, c, x, y);
            ctr = r.opaque_w;
            for (k = 0; k < 4; ++k) {
                double o = rc_trace(&rs, c, x + (k & 1), y + (k >> 1)).opaque_w;
                double d = isinf(o) && isinf(ctr) ? 0.0 : fabs(o - ctr);
                if (!(d <= wk->spread[p])) wk->spread[p] = d;
            }
        }
    rc_scene_free(&rs);
    memcpy(g_walk_truth.gt + off, wk->gt, np * sizeof(double));
    memcpy(g_walk_truth.spread + off, wk->spread, np * sizeof(double));
    memcpy(g_walk_truth.slope + off, wk->slope, np * sizeof(double));
    memcpy(g_walk_truth.interior + off, wk->interior, np);
    g_walk_truth.have[slot] = 1;
}

/* the engine's depth buffer that fogvol must leave alone: the draw framebuffer's at end_frame */
static void walk_read_depth(float *z)
{
    glReadPixels(0, 0, SW, SH, GL_DEPTH_COMPONENT, GL_FLOAT, z);
}

/* the engine's frame for view v: clear the viewport, draw the occluders into it */
static void walk_engine(walk *wk, const sq_view *v, const fogvol_frame_desc *fd)
{
    glBindFramebuffer(GL_FRAMEBUFFER, wk->fbo);
    glViewport(v->viewport[0], v->viewport[1], v->viewport[2], v->viewport[3]);
    glScissor(v->viewport[0], v->viewport[1], v->viewport[2], v->viewport[3]);
    glEnable(GL_SCISSOR_TEST);
    glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    if (v->occluders) engine_draw(&wk->e, wk->o + 1, 2, fd->view, fd->projection, NULL);
    glDisable(GL_DEPTH_TEST);
}

static void walk_desc(walk *wk, const sq_view *v, const rc_camera *c, fogvol_frame_desc *fd)
{
    fx_frame_desc(fd, c, v->viewport[2], v->viewport[3]);
    fd->viewport[0] = v->viewport[0];
    fd->viewport[1] = v->viewport[1];
    fd->debug_thickness = wk->thick;
    fd->engine_depth_source = wk->src->source;
    if (wk->src->source == FOGVOL_DEPTH_SOURCE_TEXTURE) fd->engine_depth_texture = wk->dtex;
    if (wk->src->source == FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT) fd->engine_depth_framebuffer = wk->fbo;
}

/* a frame begun with this view's input (a volume, the whole fog) and cancelled */
static void walk_cancel(void *user, const sq_view *v)
{
    walk *wk = (walk *)user;
    rc_camera c = walk_camera(1.0 - v->walk, v->viewport);
    fogvol_frame_desc fd;
    walk_desc(wk, v, &c, &fd);
    assert_int_equal(fogvol_begin_frame(wk->fv, &fd), FOGVOL_SUCCESS);
    add_volume(wk->fv, wk->vol, wk->o[0].model, wk->ramp);
    assert_int_equal(fogvol_cancel_frame(wk->fv), FOGVOL_SUCCESS);
}

/* every 6th frame of the walk (one view, full viewport) into the contact sheet: rendered thickness
   above, the ray cast below, 0..4 units black to white */
static void walk_sheet(walk *wk, const sq_view *v)
{
    int col = v->frame / 6, x, y, k;
    if (v->frame % 6 || v->views != 1 || v->viewport[2] != SW || v->viewport[3] != SH || col >= 10) return;
    for (y = 0; y < SH; ++y)
        for (x = 0; x < SW; ++x)
            for (k = 0; k < 2; ++k) {
                double t = k ? wk->gt[y * SW + x] : wk->thick[y * SW + x];
                unsigned char *o = wk->sheet + (((size_t)(SH - 1 - y + k * SH) * SW * 10) + col * SW + x) * 3;
                o[0] = o[1] = o[2] = (unsigned char)(t <= 0 ? 0 : t >= 4 ? 255 : t * 63.75);
                if (k == 0 && wk->interior[y * SW + x] && fabs(wk->thick[y * SW + x] - wk->gt[y * SW + x]) > 0.05)
                    o[1] = o[2] = 0; /* wrong: red */
            }
}

static void walk_view(void *user, const sq_view *v, sq_check *out)
{
    walk *wk = (walk *)user;
    rc_camera c = walk_camera(v->walk, v->viewport);
    fogvol_frame_desc fd;
    double range = c.zfar - c.znear, wmax = 12.0, snap = snap_pixels();
    int i, npx = v->viewport[2] * v->viewport[3];
    fogvol_result r;
    walk_desc(wk, v, &c, &fd);
    walk_engine(wk, v, &fd);
    if (wk->src->source == FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT) glBindFramebuffer(GL_FRAMEBUFFER, 0);
    walk_read_depth(wk->zb); /* (the draw framebuffer is single-sample) */
    for (i = 0; i < npx; ++i) wk->thick[i] = -1.0f;
    assert_int_equal(fogvol_begin_frame(wk->fv, &fd), FOGVOL_SUCCESS);
    add_volume(wk->fv, wk->vol, wk->o[0].model, wk->ramp);
    r = fogvol_end_frame(wk->fv, NULL);
    if (r != FOGVOL_SUCCESS && !wk->failed++) print_message("#   end_frame: %s\n", fogvol_result_string(r));
    wk->gl_errors += glGetError() != GL_NO_ERROR;
    walk_read_depth(wk->za); /* the depth buffer bound for drawing: the engine's, untouched */
    for (i = 0; i < SW * SH; ++i) wk->depth_changed += wk->za[i] != wk->zb[i];
    walk_truth(wk, &c, v);
    /* as test_engine_depth_buffers: FLOAT 1e-4 of the range, PS20 1 LSB of the 12-bit encoding
       (one pair of faces), + the depth quantum at the farthest occluder; a multisampled source's
       resolve keeps one of the pixel's samples: + the occluder's depth spread over the pixel; + the
       depths' slope times the GL's vertex snapping grid (snap_pixels: 1/256 pixel on NVIDIA) */
    out->bound = (wk->tier == FOGVOL_TIER_FLOAT ? 1e-4 * range : range / 4096.0) +
                 (wk->src->bits ? ldexp(1.0, -wk->src->bits) * wmax * wmax * range / (c.zfar * c.znear) : 0.0);
    for (i = 0; i < npx; ++i) {
        double err;
        if (!wk->interior[i]) continue;
        err = fabs(wk->thick[i] - wk->gt[i]) - (wk->src->samples ? wk->spread[i] : 0.0);
        err *= out->bound / (out->bound + wk->slope[i] * snap); /* (scaled to the bound without it) */
        out->pixels++;
        if (r != FOGVOL_SUCCESS) { /* no fog drawn: the whole view is wrong */
            out->wrong++;
            continue;
        }
        if (err > out->max_err) out->max_err = err;
        out->wrong += err > out->bound;
    }
    walk_sheet(wk, v);
}

static void walk_setup(walk *wk, const walk_src *src, fogvol_tier tier)
{
    GLenum att;
    memset(wk, 0, sizeof *wk);
    wk->src = src;
    wk->tier = tier;
    walk_scene(wk->o);
    wk->fv = make_ctx(tier, FOGVOL_VARIANT_ENGINE_DEPTH);
    wk->vol = mesh_of(wk->fv, &wk->o[0].m, 0);
    wk->ramp = ramp_of(wk->fv);
    engine_init(&wk->e);
    wk->thick = (float *)calloc((size_t)SW * SH, sizeof(float));
    wk->zb = (float *)calloc((size_t)SW * SH, sizeof(float));
    wk->za = (float *)calloc((size_t)SW * SH, sizeof(float));
    wk->gt = (double *)calloc((size_t)SW * SH, sizeof(double));
    wk->spread = (double *)calloc((size_t)SW * SH, sizeof(double));
    wk->slope = (double *)calloc((size_t)SW * SH, sizeof(double));
    wk->interior = (unsigned char *)calloc((size_t)SW * SH, 1);
    wk->sheet = (unsigned char *)calloc((size_t)SW * 10 * SH * 2, 3);
    if (!src->format) return;
    att = src->format == GL_DEPTH24_STENCIL8 ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT;
    glGenFramebuffers(1, &wk->fbo);
    glGenRenderbuffers(2, wk->rb);
    glBindFramebuffer(GL_FRAMEBUFFER, wk->fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, wk->rb[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, src->samples, GL_RGBA8, SW, SH);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, wk->rb[0]);
    if (src->texture) {
        glGenTextures(1, &wk->dtex);
        glBindTexture(GL_TEXTURE_2D, wk->dtex);
        glTexImage2D(GL_TEXTURE_2D, 0, (GLint)src->format, SW, SH, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glBindTexture(GL_TEXTURE_2D, 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, att, GL_TEXTURE_2D, wk->dtex, 0);
    } else {
        glBindRenderbuffer(GL_RENDERBUFFER, wk->rb[1]);
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, src->samples, src->format, SW, SH);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, att, GL_RENDERBUFFER, wk->rb[1]);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
}

static void walk_teardown(walk *wk)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (wk->fbo) glDeleteFramebuffers(1, &wk->fbo);
    glDeleteRenderbuffers(2, wk->rb);
    if (wk->dtex) glDeleteTextures(1, &wk->dtex);
    glDeleteProgram(wk->e.prog);
    fogvol_destroy_mesh(wk->fv, wk->vol);
    fogvol_destroy_ramp(wk->fv, wk->ramp);
    fogvol_destroy_context(wk->fv);
    free_objs(wk->o, 3);
    free(wk->thick);
    free(wk->zb);
    free(wk->za);
    free(wk->gt);
    free(wk->spread);
    free(wk->slope);
    free(wk->interior);
    free(wk->sheet);
}

static void test_engine_depth_walk(void **state)
{
    /* FLOAT as this renderer draws it (llvmpipe: depth-tested), FLOAT as a GPU draws it (every face
       reads the depth: FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST off), PS20 */
    static const fogvol_tier tiers[3] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_FLOAT, FOGVOL_TIER_PS20};
    static const char *const tnames[3] = {"FLOAT", "FLOAT (read)", "PS20"};
    sq_step steps[WALK_FRAMES];
    glu_ctx g;
    long wrong = 0, changed = 0;
    int s, t, failed = 0;
    (void)state;
    assert_true(glu_create(&g, SW, SH, 1));
    sq_walk_script(steps, WALK_FRAMES);
    for (t = 0; t < 3; ++t)
        for (s = 0; s < NWALK; ++s) {
            walk wk;
            char name[96], where[200], png[128];
            sq_totals tot;
            g_speedups_off = t == 1 ? FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST : 0u;
            walk_setup(&wk, &g_walk_srcs[s], tiers[t]);
            g_speedups_off = 0;
            snprintf(name, sizeof name, "%s %s", tnames[t], g_walk_srcs[s].name);
            tot = sq_play(name, SW, SH, steps, WALK_FRAMES, SQ_ALL, walk_view, walk_cancel, &wk, where);
            if (tot.wrong) print_message("#   first wrong pixel: %s\n", where);
            if (wk.depth_changed || wk.failed || wk.gl_errors)
                print_message("#   %ld depth values of the engine's buffers changed; %d views failed, %d left a GL "
                              "error\n", wk.depth_changed, wk.failed, wk.gl_errors);
            mkdir("build", 0777);
            mkdir("build/engine_input", 0777);
            snprintf(png, sizeof png, "build/engine_input/walk_%s%s_%d.png", fogvol_tier_name(tiers[t]),
                     t == 1 ? "_read" : "", s);
            stbi_flip_vertically_on_write(0);
            stbi_write_png(png, SW * 10, SH * 2, 3, wk.sheet, SW * 10 * 3);
            wrong += tot.wrong;
            changed += wk.depth_changed;
            failed += wk.failed + wk.gl_errors;
            walk_teardown(&wk);
        }
    glu_destroy(&g);
    free(g_walk_truth.gt);
    free(g_walk_truth.spread);
    free(g_walk_truth.slope);
    free(g_walk_truth.interior);
    memset(&g_walk_truth, 0, sizeof g_walk_truth);
    print_message("# walk: %ld wrong pixels, %ld engine depth values changed, %d failed views\n", wrong, changed,
                  failed);
    assert_int_equal(wrong, 0);
    assert_int_equal(changed, 0);
    assert_int_equal(failed, 0);
}

/* ==== 2. occluders drawn by the engine's own program ========================= */

static void render_occluders(fogvol_tier tier, int by_engine, const tobj *o, int n, float *thick)
{
    rc_camera c = camera();
    engine e;
    fogvol_context *fv = make_ctx(tier, 0);
    fogvol_mesh *vol = mesh_of(fv, &o[0].m, 0), *occ = mesh_of(fv, &o[1].m, 1);
    fogvol_ramp *ramp = ramp_of(fv);
    fogvol_frame_desc fd;
    fogvol_occluder_info oi;
    GLuint fbo = 0, depth = 0;
    engine_init(&e);
    frame_of(&fd, &c, thick);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    if (by_engine) {
        assert_int_equal(fogvol_occluder_prepare(fv, &oi), FOGVOL_SUCCESS);
        assert_int_equal(oi.width, W);
        assert_int_equal(oi.height, H);
        /* PS20: R32F with FOGVOL_SPEEDUP_FLOAT_O (this context renders float targets), else RGBA8 */
        assert_int_equal(oi.format, tier == FOGVOL_TIER_FLOAT || !(g_speedups_off & FOGVOL_SPEEDUP_FLOAT_O)
                                        ? FOGVOL_FORMAT_R32F
                                        : FOGVOL_FORMAT_RGBA8);
        glGenFramebuffers(1, &fbo);
        glGenRenderbuffers(1, &depth);
        glBindRenderbuffer(GL_RENDERBUFFER, depth);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, oi.width, oi.height);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, (GLuint)oi.texture, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
        assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
        glViewport(0, 0, oi.width, oi.height);
        glClearBufferfv(GL_COLOR, 0, oi.clear_color);
        glClear(GL_DEPTH_BUFFER_BIT);
        engine_draw(&e, o, n, fd.view, fd.projection, oi.uniforms);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        /* fogvol's own occluder list is closed for this frame */
        assert_int_equal(fogvol_add_occluder(fv, occ, o[1].model), FOGVOL_ERROR_INVALID_STATE);
    } else {
        assert_int_equal(fogvol_add_occluder(fv, occ, o[1].model), FOGVOL_SUCCESS);
    }
    add_volume(fv, vol, o[0].model, ramp);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    if (by_engine && tier == FOGVOL_TIER_PS20 && g_speedups_off) save_png("engine_occluders_ps20", W, H);
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (depth) glDeleteRenderbuffers(1, &depth);
    glDeleteProgram(e.prog);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_mesh(fv, occ);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
}

static void test_engine_occluders(void **state)
{
    static const fogvol_tier tiers[3] = {FOGVOL_TIER_PS20, FOGVOL_TIER_PS20, FOGVOL_TIER_FLOAT};
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o), t, i, pixels;
    double *gt = (double *)malloc(sizeof(double) * W * H), range = c.zfar - c.znear;
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *te = (float *)calloc((size_t)W * H, sizeof(float)), *tf = (float *)calloc((size_t)W * H, sizeof(float));
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    truth(&c, o, n, gt, interior);
    for (t = 0; t < 3; ++t) {
        /* PS20: 12-bit encoding, 1 LSB per pair of faces (one pair here); FLOAT: 1e-4 of the range */
        double lsb = tiers[t] == FOGVOL_TIER_FLOAT ? 1e-4 * range : range / 4096.0, ee, ef, diff = 0;
        g_speedups_off = t == 1 ? FOGVOL_SPEEDUP_FLOAT_O : 0u; /* PS20 with an RGBA8 O, then an R32F one */
        render_occluders(tiers[t], 1, o, n, te);
        render_occluders(tiers[t], 0, o, n, tf);
        ee = max_err(te, gt, interior, &pixels);
        ef = max_err(tf, gt, interior, NULL);
        for (i = 0; i < W * H; ++i)
            if (interior[i] && fabs(te[i] - tf[i]) > diff) diff = fabs(te[i] - tf[i]);
        print_message("  %s%s: engine-drawn occluders max |error| %.3f LSB, fogvol-drawn %.3f LSB, "
                      "engine vs fogvol %.3f LSB (%d fogged pixels)\n",
                      fogvol_tier_name(tiers[t]), t == 1 ? " (RGBA8 O)" : "", ee / lsb, ef / lsb, diff / lsb, pixels);
        assert_true(pixels > 1000);
        assert_true(ee <= lsb);
        assert_true(ef <= lsb);
        assert_true(diff <= lsb);
    }
    g_speedups_off = 0;
    glu_destroy(&g);
    free_objs(o, n);
    free(gt);
    free(interior);
    free(te);
    free(tf);
}

/* The engine-drawn occluders as a sequence (tests/sequence.h's default script): the camera walks
   into the sphere and out, the engine draws its occluders into fogvol's O in the frames that have
   them and does not call fogvol_occluder_prepare in the others (fogvol's own O, the far plane, must
   take over), the viewport shrinks and splits (O has the viewport's size), a cancelled frame in
   which the engine drew its occluders comes in between. Each view against the ray cast of its own
   camera and occluders, 1 LSB per pair of faces (FLOAT 1e-4 of the range) on interior pixels. */
typedef struct occseq {
    fogvol_tier tier;
    engine e;
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    tobj *o;
    float *thick;
    GLuint fbo, depth;
} occseq;

/* The camera of walk position w: up to 0.5 it circles the sphere (60 degrees about y, looking at its
   centre), so an O left from another frame would cut the sphere somewhere else; then it moves into
   the sphere (radius 1.5 at the origin), looking the same way. */
static rc_camera occseq_camera(double w, const int vp[4])
{
    rc_camera c = camera();
    static const double in[3] = {0.3, 0.2, 0.5};
    double a = (w < 0.5 ? w : 0.5) * 2.0 * 1.0471975511965976, e[3], u = w > 0.5 ? (w - 0.5) * 2.0 : 0.0;
    int i;
    e[0] = c.eye[0] * cos(a) + c.eye[2] * sin(a);
    e[1] = c.eye[1];
    e[2] = -c.eye[0] * sin(a) + c.eye[2] * cos(a);
    for (i = 0; i < 3; ++i) {
        c.eye[i] = e[i] + (in[i] - e[i]) * u;
        c.target[i] = c.eye[i] - e[i]; /* towards the centre from the orbit point */
    }
    c.aspect = (double)vp[2] / vp[3];
    c.width = vp[2];
    c.height = vp[3];
    return c;
}

static void occseq_engine_o(occseq *q, const fogvol_frame_desc *fd)
{
    fogvol_occluder_info oi;
    assert_int_equal(fogvol_occluder_prepare(q->fv, &oi), FOGVOL_SUCCESS);
    assert_int_equal(oi.width, fd->viewport[2]);
    assert_int_equal(oi.height, fd->viewport[3]);
    glBindRenderbuffer(GL_RENDERBUFFER, q->depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, oi.width, oi.height);
    glBindFramebuffer(GL_FRAMEBUFFER, q->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, (GLuint)oi.texture, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, q->depth);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glViewport(0, 0, oi.width, oi.height);
    glClearBufferfv(GL_COLOR, 0, oi.clear_color);
    glClear(GL_DEPTH_BUFFER_BIT);
    engine_draw(&q->e, q->o, 2, fd->view, fd->projection, oi.uniforms);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void occseq_cancel(void *user, const sq_view *v)
{
    occseq *q = (occseq *)user;
    rc_camera c = occseq_camera(0.5 - v->walk * 0.5, v->viewport); /* (another view than the next frame's) */
    fogvol_frame_desc fd;
    frame_of(&fd, &c, NULL);
    memcpy(fd.viewport, v->viewport, sizeof fd.viewport);
    assert_int_equal(fogvol_begin_frame(q->fv, &fd), FOGVOL_SUCCESS);
    occseq_engine_o(q, &fd); /* the engine's occluders of a frame that is given up */
    add_volume(q->fv, q->vol, q->o[0].model, q->ramp);
    assert_int_equal(fogvol_cancel_frame(q->fv), FOGVOL_SUCCESS);
}

static void occseq_view(void *user, const sq_view *v, sq_check *out)
{
    occseq *q = (occseq *)user;
    rc_camera c = occseq_camera(v->walk, v->viewport);
    fogvol_frame_desc fd;
    rc_object ro[2];
    rc_scene rs;
    int i, x, y, n = v->occluders ? 2 : 1;
    double range = c.zfar - c.znear, snap = snap_pixels();
    frame_of(&fd, &c, q->thick);
    memcpy(fd.viewport, v->viewport, sizeof fd.viewport);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    assert_int_equal(fogvol_begin_frame(q->fv, &fd), FOGVOL_SUCCESS);
    if (v->occluders) occseq_engine_o(q, &fd); /* the engine's pass into fogvol's O, its own depth buffer */
    add_volume(q->fv, q->vol, q->o[0].model, q->ramp);
    assert_int_equal(fogvol_end_frame(q->fv, NULL), FOGVOL_SUCCESS);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    for (i = 0; i < n; ++i) {
        ro[i].pos = q->o[i].m.pos;
        ro[i].vcount = q->o[i].m.vcount;
        ro[i].idx = q->o[i].m.idx;
        ro[i].icount = q->o[i].m.icount;
        memcpy(ro[i].model, q->o[i].model, sizeof ro[i].model);
        ro[i].sign = q->o[i].sign;
    }
    assert_true(rc_scene_init(&rs, ro, n));
    out->bound = q->tier == FOGVOL_TIER_FLOAT ? 1e-4 * range : range / 4096.0; /* + the snapping term */
    for (y = 0; y < c.height; ++y)
        for (x = 0; x < c.width; ++x) {
            double err;
            if (!rc_interior(&rs, &c, x, y)) continue;
            err = fabs(q->thick[y * c.width + x] - rc_trace(&rs, &c, x + 0.5, y + 0.5).thickness) * out->bound /
                  (out->bound + rc_depth_slope(&rs, &c, x, y) * snap); /* (scaled to the bound without it) */
            out->pixels++;
            out->wrong += err > out->bound;
            if (err > out->max_err) out->max_err = err;
        }
    rc_scene_free(&rs);
}

static void test_engine_occluders_sequence(void **state)
{
    static const fogvol_tier tiers[3] = {FOGVOL_TIER_PS20, FOGVOL_TIER_PS20, FOGVOL_TIER_FLOAT};
    tobj o[2];
    int t;
    glu_ctx g;
    (void)state;
    scene(o);
    assert_true(glu_create(&g, W, H, 1));
    for (t = 0; t < 3; ++t) {
        occseq q;
        char name[64];
        memset(&q, 0, sizeof q);
        q.tier = tiers[t];
        q.o = o;
        g_speedups_off = t == 1 ? FOGVOL_SPEEDUP_FLOAT_O : 0u; /* PS20 with an R32F O, then an RGBA8 one */
        q.fv = make_ctx(q.tier, 0);
        q.vol = mesh_of(q.fv, &o[0].m, 0);
        q.ramp = ramp_of(q.fv);
        q.thick = (float *)calloc((size_t)W * H, sizeof(float));
        engine_init(&q.e);
        glGenFramebuffers(1, &q.fbo);
        glGenRenderbuffers(1, &q.depth);
        snprintf(name, sizeof name, "engine occluders %s%s", fogvol_tier_name(q.tier), t == 1 ? " (RGBA8 O)" : "");
        sq_run(name, W, H, sq_default_script, SQ_DEFAULT_FRAMES, SQ_ALL, occseq_view, occseq_cancel, &q);
        glDeleteFramebuffers(1, &q.fbo);
        glDeleteRenderbuffers(1, &q.depth);
        glDeleteProgram(q.e.prog);
        fogvol_destroy_mesh(q.fv, q.vol);
        fogvol_destroy_ramp(q.fv, q.ramp);
        fogvol_destroy_context(q.fv);
        free(q.thick);
    }
    g_speedups_off = 0;
    glu_destroy(&g);
    free_objs(o, 2);
}

static void test_engine_occluder_refusals(void **state)
{
    static const struct {
        fogvol_tier tier;
        unsigned variants;
        fogvol_result want;
    } cases[] = {{FOGVOL_TIER_MRT, 0, FOGVOL_ERROR_UNSUPPORTED},
                 {FOGVOL_TIER_PS13, 0, FOGVOL_ERROR_UNSUPPORTED},
                 {FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, FOGVOL_ERROR_UNSUPPORTED},
                 {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_ERROR_UNSUPPORTED}};
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o), i;
    glu_ctx g;
    fogvol_frame_desc fd;
    fogvol_occluder_info oi;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    frame_of(&fd, &c, NULL);
    for (i = 0; i < 4; ++i) {
        fogvol_context *fv = make_ctx(cases[i].tier, cases[i].variants);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        g_log[0] = 0;
        assert_int_equal(fogvol_occluder_prepare(fv, &oi), cases[i].want);
        assert_true(strlen(g_log) > 0);
        fogvol_cancel_frame(fv);
        fogvol_destroy_context(fv);
    }
    { /* outside a frame, and after fogvol_add_occluder */
        fogvol_context *fv = make_ctx(FOGVOL_TIER_PS20, 0);
        fogvol_mesh *occ = mesh_of(fv, &o[1].m, 1);
        assert_int_equal(fogvol_occluder_prepare(fv, &oi), FOGVOL_ERROR_INVALID_STATE);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_occluder(fv, occ, o[1].model), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_occluder_prepare(fv, &oi), FOGVOL_ERROR_INVALID_STATE);
        fogvol_cancel_frame(fv);
        fogvol_destroy_mesh(fv, occ);
        fogvol_destroy_context(fv);
    }
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glu_destroy(&g);
    free_objs(o, n);
}

/* Issue 31 3d: what a cancelled frame leaves behind. fogvol_occluder_prepare hands O to the engine;
   the engine writes it (here: cleared to the near plane, which hides every volume), and the frame
   is cancelled. The next frame has no occluders: O must be the far plane again, so the sphere's
   thickness is its ray-cast chord (before: the previous frame without occluders had left "O holds
   the far plane" set, the cleared O was reused and the thickness was 0). MRT: after mrt_prepare
   and cancel_frame, the next frame without mrt_prepare is refused (before: drawn with the
   cancelled frame's O). */
static void cancelled_frame(fogvol_tier tier, unsigned speedups_off, const tobj *o, const double *gt,
                            const unsigned char *interior, float *thick)
{
    static const float near_plane[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    rc_camera c = camera();
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_occluder_info oi;
    GLuint fbo = 0;
    double lsb = tier == FOGVOL_TIER_FLOAT ? 1e-4 * (c.zfar - c.znear) : (c.zfar - c.znear) / 4096.0, e;
    int frame, pixels;
    g_speedups_off = speedups_off;
    fv = make_ctx(tier, 0);
    g_speedups_off = 0;
    vol = mesh_of(fv, &o[0].m, 0);
    ramp = ramp_of(fv);
    frame_of(&fd, &c, thick);
    glGenFramebuffers(1, &fbo);
    for (frame = 0; frame < 3; ++frame) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        if (frame == 1) { /* the engine draws O (cleared to the near plane), then the frame is cancelled */
            assert_int_equal(fogvol_occluder_prepare(fv, &oi), FOGVOL_SUCCESS);
            glBindFramebuffer(GL_FRAMEBUFFER, fbo);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, (GLuint)oi.texture, 0);
            assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
            glClearBufferfv(GL_COLOR, 0, near_plane);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
            continue;
        }
        add_volume(fv, vol, o[0].model, ramp);
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
        e = max_err(thick, gt, interior, &pixels);
        print_message("  %s, speed-ups off 0x%x, frame %d%s: max |thickness - ray cast| %.3f LSB (%d fogged pixels)\n",
                      fogvol_tier_name(tier), speedups_off, frame, frame == 2 ? " (after the cancelled frame)" : "",
                      e / lsb, pixels);
        assert_true(pixels > 1000);
        assert_true(e <= lsb);
    }
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glDeleteFramebuffers(1, &fbo);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
}

static void test_cancelled_frames(void **state)
{
    rc_camera c = camera();
    tobj o[2];
    int n = scene(o);
    double *gt = (double *)malloc(sizeof(double) * W * H);
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    fogvol_context *fv;
    fogvol_mesh *vol;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_mrt_info mi;
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    truth(&c, o, 1, gt, interior); /* the sphere alone */
    cancelled_frame(FOGVOL_TIER_PS20, FOGVOL_SPEEDUP_SPECIALIZE, o, gt, interior, thick);
    cancelled_frame(FOGVOL_TIER_PS20, FOGVOL_SPEEDUP_SPECIALIZE | FOGVOL_SPEEDUP_FLOAT_O, o, gt, interior, thick);
    cancelled_frame(FOGVOL_TIER_FLOAT, FOGVOL_SPEEDUP_SPECIALIZE, o, gt, interior, thick);
    cancelled_frame(FOGVOL_TIER_PS20, 0, o, gt, interior, thick);
    /* MRT: the engine's O of a cancelled frame is not this frame's */
    fv = make_ctx(FOGVOL_TIER_MRT, 0);
    vol = mesh_of(fv, &o[0].m, 0);
    ramp = ramp_of(fv);
    frame_of(&fd, &c, NULL);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_mrt_prepare(fv, &mi), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_volume(fv, vol, o[0].model, ramp);
    g_log[0] = 0;
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_STATE);
    assert_non_null(strstr(g_log, "mrt_prepare"));
    /* ... nor is an ended frame's */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_mrt_prepare(fv, &mi), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_volume(fv, vol, o[0].model, ramp);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    fogvol_destroy_mesh(fv, vol);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    free_objs(o, n);
    free(gt);
    free(interior);
    free(thick);
}

/* ==== 3. meshes as engines store them ======================================== */

/* An engine's UV sphere: (slices + 1) x (stacks + 1) vertices, the seam column
   and each pole repeated per slice; poles at +-z. */
static shp_mesh seam_sphere(float r, int slices, int stacks)
{
    shp_mesh m;
    unsigned *p;
    int i, j;
    m.vcount = (slices + 1) * (stacks + 1);
    m.icount = 6 * slices * (stacks - 1);
    m.pos = (float *)malloc(sizeof(float) * 3 * (size_t)m.vcount);
    m.idx = (unsigned *)malloc(sizeof(unsigned) * (size_t)m.icount);
    for (i = 0; i <= stacks; ++i)
        for (j = 0; j <= slices; ++j) {
            double th = 3.14159265358979323846 * i / stacks, ph = 2.0 * 3.14159265358979323846 * j / slices;
            float *v = m.pos + 3 * (i * (slices + 1) + j);
            v[0] = (float)(r * sin(th) * cos(ph));
            v[1] = (float)(r * sin(th) * sin(ph));
            v[2] = (float)(r * cos(th));
        }
#define SV(i, j) (unsigned)((i) * (slices + 1) + (j))
    p = m.idx;
    for (i = 0; i < stacks; ++i)
        for (j = 0; j < slices; ++j) {
            if (i != 0) { /* the triangle at the top pole has no area: engines skip it */
                *p++ = SV(i, j);
                *p++ = SV(i + 1, j);
                *p++ = SV(i, j + 1);
            }
            if (i != stacks - 1) {
                *p++ = SV(i, j + 1);
                *p++ = SV(i + 1, j);
                *p++ = SV(i + 1, j + 1);
            }
        }
#undef SV
    m.icount = (int)(p - m.idx);
    return m;
}

/* A cube with per-face vertices (4 per face, 24), as engines store it for normals. */
static shp_mesh face_cube(float h)
{
    shp_mesh box = shp_box(h, h, h), m;
    int f, k;
    m.vcount = 24;
    m.icount = 36;
    m.pos = (float *)malloc(sizeof(float) * 72);
    m.idx = (unsigned *)malloc(sizeof(unsigned) * 36);
    for (f = 0; f < 6; ++f) { /* shp_box's quads: triangles (a,b,c), (a,c,d) */
        unsigned q[4];
        q[0] = box.idx[6 * f];
        q[1] = box.idx[6 * f + 1];
        q[2] = box.idx[6 * f + 2];
        q[3] = box.idx[6 * f + 5];
        for (k = 0; k < 4; ++k) memcpy(m.pos + 3 * (4 * f + k), box.pos + 3 * q[k], 12);
        for (k = 0; k < 6; ++k) {
            unsigned v = box.idx[6 * f + k];
            int c = v == q[0] ? 0 : v == q[1] ? 1 : v == q[2] ? 2 : 3;
            m.idx[6 * f + k] = (unsigned)(4 * f + c);
        }
    }
    shp_free(&box);
    return m;
}

/* FLOAT-tier thickness of one volume mesh (no occluder) */
static void render_volume(fogvol_context *fv, const fogvol_mesh *m, const float model[16], float *thick)
{
    rc_camera c = camera();
    fogvol_frame_desc fd;
    fogvol_ramp *ramp = ramp_of(fv);
    frame_of(&fd, &c, thick);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glClearColor(0.2f, 0.3f, 0.4f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_volume(fv, (fogvol_mesh *)m, model, ramp);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    fogvol_destroy_ramp(fv, ramp);
}

static void test_weld_seam_sphere(void **state)
{
    enum { S = 24, T = 12 };
    rc_camera c = camera();
    tobj o[1];
    shp_mesh m = seam_sphere(1.4f, S, T);
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    fogvol_mesh *mesh = NULL;
    fogvol_context *fv;
    double *gt = (double *)malloc(sizeof(double) * W * H), err, range = c.zfar - c.znear;
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    int pixels;
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    fv = make_ctx(FOGVOL_TIER_FLOAT, 0);
    memset(&md, 0, sizeof md);
    md.positions = m.pos;
    md.vertex_count = m.vcount;
    md.indices = (const uint32_t *)m.idx;
    md.index_count = m.icount;
    g_log[0] = 0;
    assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_null(mesh);
    /* by hand: 2 open edges per pole triangle (2S per pole) + both seam columns between the pole rows (2(T-2)) */
    assert_int_equal(rep.open_edges, 4 * S + 2 * (T - 2));
    assert_int_equal(rep.welded_vertices, 0);
    assert_non_null(strstr(g_log, "weld_distance"));
    print_message("  seam sphere %dx%d without weld: %d open edges; log: %s\n", S, T, rep.open_edges, g_log);
    md.weld_distance = 1e-5f;
    assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, &rep), FOGVOL_SUCCESS);
    /* (S+1)(T+1) stored, S(T-1) + 2 distinct positions */
    assert_int_equal(rep.welded_vertices, (S + 1) * (T + 1) - (S * (T - 1) + 2));
    assert_int_equal(rep.vertices, S * (T - 1) + 2);
    assert_int_equal(rep.triangles, 2 * S * (T - 1));
    assert_int_equal(rep.open_edges, 0);
    assert_true(rep.valid && rep.closed && rep.consistent);
    assert_int_equal(fogvol_validate_mesh(&md, NULL, &rep), FOGVOL_SUCCESS); /* the same through validate */
    assert_int_equal(rep.welded_vertices, 59);
    o[0].m = m;
    shp_mat_identity(o[0].model);
    o[0].sign = 1;
    truth(&c, o, 1, gt, interior);
    render_volume(fv, mesh, o[0].model, thick);
    save_png("welded_seam_sphere", W, H);
    err = max_err(thick, gt, interior, &pixels);
    print_message("  welded: %d merged, rendered vs ray-cast chord max |error| %.3g of the range (%d pixels)\n",
                  rep.welded_vertices, err / range, pixels);
    assert_true(pixels > 1000);
    assert_true(err <= 1e-4 * range);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    shp_free(&m);
    free(gt);
    free(interior);
    free(thick);
}

/* analytic chord of the box [-h,h]^3 under model = translate(t) * rotate(r), in view depth */
static double box_chord(const rc_camera *c, const float rot[16], const float t[3], float h, double sx, double sy)
{
    double org[3], dir[3], o[3], d[3], t0 = c->znear, t1 = c->zfar;
    int i, k;
    rc_camera_ray(c, sx, sy, org, dir);
    for (i = 0; i < 3; ++i) { /* into box space: R^T (p - t) */
        o[i] = d[i] = 0;
        for (k = 0; k < 3; ++k) {
            o[i] += rot[i * 4 + k] * (org[k] - t[k]);
            d[i] += rot[i * 4 + k] * dir[k];
        }
    }
    for (i = 0; i < 3; ++i) {
        double a, b;
        if (d[i] == 0) {
            if (fabs(o[i]) > h) return 0;
            continue;
        }
        a = (-h - o[i]) / d[i];
        b = (h - o[i]) / d[i];
        if (a > b) {
            double s = a;
            a = b;
            b = s;
        }
        if (a > t0) t0 = a;
        if (b < t1) t1 = b;
    }
    return t1 > t0 ? t1 - t0 : 0;
}

static void test_weld_face_cube(void **state)
{
    const float h = 1.1f, tr[3] = {0.2f, -0.1f, 0.3f};
    rc_camera c = camera();
    shp_mesh m = face_cube(h);
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    fogvol_mesh *mesh = NULL;
    fogvol_context *fv;
    tobj o[1];
    float rot[16], tm[16], model[16];
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    double *gt = (double *)malloc(sizeof(double) * W * H), range = c.zfar - c.znear, err = 0;
    unsigned char *interior = (unsigned char *)malloc((size_t)W * H);
    int i, pixels = 0;
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    fv = make_ctx(FOGVOL_TIER_FLOAT, 0);
    memset(&md, 0, sizeof md);
    md.positions = m.pos;
    md.vertex_count = 24;
    md.indices = (const uint32_t *)m.idx;
    md.index_count = 36;
    assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.open_edges, 24); /* every face's 4 edges */
    assert_int_equal(rep.vertices, 24);
    md.weld_distance = 1e-6f;
    assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, &rep), FOGVOL_SUCCESS);
    assert_int_equal(rep.welded_vertices, 16);
    assert_int_equal(rep.vertices, 8);
    assert_int_equal(rep.open_edges, 0);
    assert_true(fabs(rep.volume - 8.0 * h * h * h) < 1e-5);
    shp_mat_rotate(rot, 30.0f, 1.0f, 1.0f, 0.0f);
    shp_mat_translate(tm, tr[0], tr[1], tr[2]);
    shp_mat_mul(model, tm, rot);
    o[0].m = m;
    memcpy(o[0].model, model, sizeof model);
    o[0].sign = 1;
    truth(&c, o, 1, gt, interior); /* for the interior mask */
    render_volume(fv, mesh, model, thick);
    for (i = 0; i < W * H; ++i) {
        double a = box_chord(&c, rot, tr, h, i % W + 0.5, i / W + 0.5);
        if (!interior[i]) continue;
        pixels += a > 0;
        if (fabs(thick[i] - a) > err) err = fabs(thick[i] - a);
    }
    print_message("  per-face cube: 24 -> 8 vertices, rendered vs analytic chord max |error| %.3g of the range "
                  "(%d pixels)\n", err / range, pixels);
    assert_true(pixels > 1000);
    assert_true(err <= 1e-4 * range);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    shp_free(&m);
    free(gt);
    free(interior);
    free(thick);
}

/* the backend table without FOGVOL_CAP_MESH_LAYOUT: fogvol repacks (the
   caller's table: destroyed by the caller after the context) */
static fogvol_backend g_table;
static fogvol_context *make_ctx_repacking(fogvol_tier tier)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    fogvol_gl_desc gd;
    memset(&cd, 0, sizeof cd);
    memset(&gd, 0, sizeof gd);
    gd.get_proc_address = glu_proc;
    assert_int_equal(fogvol_gl_backend_create(&gd, NULL, NULL, &cd.backend), FOGVOL_SUCCESS);
    cd.backend.caps &= ~(unsigned)FOGVOL_CAP_MESH_LAYOUT;
    g_table = cd.backend;
    cd.logger.func = logger;
    cd.tier = tier;
    cd.disable_dither = 1;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    return fv;
}

static void test_interleaved_16bit(void **state)
{
    static const fogvol_tier tiers[2] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_PS20};
    shp_mesh m = shp_sphere(1.3f, 40, 20);
    float *inter = (float *)calloc((size_t)m.vcount * 8, sizeof(float)), model[16];
    uint16_t *i16 = (uint16_t *)malloc(sizeof(uint16_t) * (size_t)m.icount);
    float *packed = (float *)calloc((size_t)W * H, sizeof(float)), *t2 = (float *)calloc((size_t)W * H, sizeof(float));
    int i, t, pass, covered = 0;
    glu_ctx g;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (i = 0; i < m.vcount; ++i) {
        inter[8 * i] = 7.0f; /* engine data around the position: normal, uv */
        memcpy(inter + 8 * i + 3, m.pos + 3 * i, 12);
        inter[8 * i + 6] = -1.0f;
    }
    for (i = 0; i < m.icount; ++i) i16[i] = (uint16_t)m.idx[i];
    shp_mat_rotate(model, 20.0f, 1.0f, 0.0f, 0.0f);
    for (t = 0; t < 2; ++t)
        for (pass = 0; pass < 2; ++pass) { /* 0: GL backend in place, 1: repacked for a backend without the cap */
            fogvol_context *fv = pass ? make_ctx_repacking(tiers[t]) : make_ctx(tiers[t], 0);
            fogvol_mesh *a = mesh_of(fv, &m, 0), *b = NULL;
            fogvol_mesh_desc md;
            fogvol_mesh_report rep;
            memset(&md, 0, sizeof md);
            md.positions = inter;
            md.vertex_count = m.vcount;
            md.stride = 32;
            md.offset = 12;
            md.index_type = FOGVOL_INDEX_UINT16;
            md.indices16 = i16;
            md.index_count = m.icount;
            assert_int_equal(fogvol_create_mesh(fv, &md, &b, &rep), FOGVOL_SUCCESS);
            assert_true(rep.valid);
            assert_int_equal(rep.vertices, m.vcount);
            render_volume(fv, a, model, packed);
            render_volume(fv, b, model, t2);
            for (i = 0, covered = 0; i < W * H; ++i) covered += packed[i] > 0;
            assert_true(covered > 1000);
            assert_memory_equal(packed, t2, sizeof(float) * W * H);
            fogvol_destroy_mesh(fv, a);
            fogvol_destroy_mesh(fv, b);
            fogvol_destroy_context(fv);
            if (pass) g_table.destroy(g_table.user_data);
        }
    print_message("  stride 32 / offset 12 / 16-bit indices: bit-identical to the packed mesh on FLOAT and PS20, "
                  "in place and repacked (%d covered pixels)\n", covered);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    glu_destroy(&g);
    shp_free(&m);
    free(inter);
    free(i16);
    free(packed);
    free(t2);
}

static void test_mesh_bad_layouts(void **state)
{
    shp_mesh m = shp_box(1, 1, 1);
    float inter[8 * 8];
    uint16_t i16[36];
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh_desc md, base;
    fogvol_mesh_report rep;
    fogvol_mesh *out = NULL;
    int i;
    (void)state;
    for (i = 0; i < 8; ++i) memcpy(inter + 8 * i + 3, m.pos + 3 * i, 12);
    for (i = 0; i < 36; ++i) i16[i] = (uint16_t)m.idx[i];
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_PS20;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    memset(&base, 0, sizeof base);
    base.positions = inter;
    base.vertex_count = 8;
    base.stride = 32;
    base.offset = 12;
    base.index_type = FOGVOL_INDEX_UINT16;
    base.indices16 = i16;
    base.index_count = 36;
    /* the null backend takes the layout fields as they are */
    assert_int_equal(fogvol_create_mesh(fv, &base, &out, &rep), FOGVOL_SUCCESS);
    assert_true(rep.valid);
    fogvol_destroy_mesh(fv, out);
    {
        struct {
            const char *what, *log;
            int stride, offset, type, null16;
            float weld;
        } bad[] = {{"stride 8", "stride", 8, 0, 1, 0, 0},
                   {"stride -4", "stride", -4, 0, 1, 0, 0},
                   {"offset 24 with stride 32", "offset", 32, 24, 1, 0, 0},
                   {"offset -4", "offset", 32, -4, 1, 0, 0},
                   {"offset 4 with stride 0 (12)", "offset", 0, 4, 1, 0, 0},
                   {"index type 7", "index_type", 32, 12, 7, 0, 0},
                   {"16-bit without indices16", "index", 32, 12, 1, 1, 0},
                   {"weld -1", "weld", 32, 12, 1, 0, -1.0f},
                   {"weld NaN", "weld", 32, 12, 1, 0, (float)NAN}};
        for (i = 0; i < (int)(sizeof bad / sizeof bad[0]); ++i) {
            md = base;
            md.stride = bad[i].stride;
            md.offset = bad[i].offset;
            md.index_type = (fogvol_index_type)bad[i].type;
            if (bad[i].null16) md.indices16 = NULL;
            md.weld_distance = bad[i].weld;
            g_log[0] = 0;
            assert_int_equal(fogvol_create_mesh(fv, &md, &out, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
            assert_null(out);
            assert_non_null(strstr(g_log, bad[i].log));
            assert_int_equal(fogvol_validate_mesh(&md, NULL, &rep), FOGVOL_ERROR_INVALID_ARGUMENT);
            print_message("  %-28s -> %s\n", bad[i].what, g_log);
        }
    }
    /* a 16-bit index past the vertices: counted, refused */
    memcpy(i16, (uint16_t[3]){0, 9, 1}, sizeof(uint16_t) * 3);
    assert_int_equal(fogvol_create_mesh(fv, &base, &out, &rep), FOGVOL_ERROR_INVALID_MESH);
    assert_int_equal(rep.out_of_range_indices, 1);
    /* a backend that does not read layouts gets packed xyz and 32-bit indices */
    fogvol_destroy_context(fv);
    cd.backend.caps &= ~(unsigned)FOGVOL_CAP_MESH_LAYOUT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    for (i = 0; i < 3; ++i) i16[i] = (uint16_t)m.idx[i];
    assert_int_equal(fogvol_create_mesh(fv, &base, &out, &rep), FOGVOL_SUCCESS);
    fogvol_destroy_mesh(fv, out);
    fogvol_destroy_context(fv);
    shp_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_engine_depth_buffers),     cmocka_unit_test(test_engine_depth_refusals),
        cmocka_unit_test(test_engine_depth_copy_recovers),
        cmocka_unit_test(test_mirrored_view),
        cmocka_unit_test(test_engine_depth_walk),
        cmocka_unit_test(test_engine_occluders),         cmocka_unit_test(test_engine_occluders_sequence),
        cmocka_unit_test(test_engine_occluder_refusals), cmocka_unit_test(test_cancelled_frames),
        cmocka_unit_test(test_weld_seam_sphere),         cmocka_unit_test(test_weld_face_cube),
        cmocka_unit_test(test_interleaved_16bit),        cmocka_unit_test(test_mesh_bad_layouts),
    };
    if (getenv("FV_TEST_FILTER")) cmocka_set_test_filter(getenv("FV_TEST_FILTER")); /* e.g. "*sequence*" */
    return cmocka_run_group_tests_name("engine input (depth buffers, engine occluders, engine meshes)", tests, NULL,
                                       NULL);
}
