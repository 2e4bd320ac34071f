/* test_tiers.c - every tier and variant that this GL context supports, in
   every GLSL dialect, on the same scenes, against ray-cast ground truth
   (tests/scenes.h). Prints the table tier x variant x dialect -> max/mean
   error.

   The test plays the engine: it renders its opaque occluders into its own
   framebuffer (colour texture + depth texture), for MRT also the encoded
   depth into fogvol's O texture through fogvol_mrt_snippet(), and hands
   fogvol its depth texture for FLOAT + ENGINE_DEPTH. The other tiers get
   the occluders through fogvol_add_occluder.

   Bounds: RGBA8 tiers, dither off: |error| <= 1 LSB per pair of faces on
   the ray (+ 1e-6 (far - near) for fp32 geometry, 0.26 LSB at WIDE's 18 bits),
   mean |error| <= 0.5 LSB per pair; FLOAT: |error| <= 3e-5 (far - near). Interior pixels only (silhouette band excluded). */
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
#include "tests/scene_gt.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>


/* dialects and the context that compiles them: desktop 110..130 in the
   compatibility context, the rest in the core context */
static const fogvol_dialect g_dialects[] = {FOGVOL_GLSL_110, FOGVOL_GLSL_120,   FOGVOL_GLSL_130, FOGVOL_GLSL_150,
                                            FOGVOL_GLSL_330, FOGVOL_GLSL_100, FOGVOL_GLSL_300ES};
#define NDIALECT ((int)(sizeof g_dialects / sizeof g_dialects[0]))

static double g_max[NTIER_COMBO][NDIALECT], g_mean[NTIER_COMBO][NDIALECT], g_comp[NTIER_COMBO][NDIALECT];
static int g_ran[NTIER_COMBO][NDIALECT];

static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l == FOGVOL_LOG_ERROR) print_message("  [fogvol error] %s\n", m);
}

/* ---- the engine ---------------------------------------------------------- */
typedef struct engine {
    GLuint fbo, color, depth, prog;
    GLint u_mvp, u_view, u_mrt;
} engine;

static void engine_init(engine *e)
{
    static const char *vs =
        "#version 330 core\nlayout(location = 0) in vec3 p;\nuniform mat4 mvp;\nuniform mat4 mv;\n"
        "out float view_depth;\n"
        "void main() { view_depth = -(mv * vec4(p, 1.0)).z; gl_Position = mvp * vec4(p, 1.0); }\n";
    const char *fs[3];
    fs[0] = "#version 330 core\n";
    fs[1] = fogvol_mrt_snippet();
    fs[2] = "in float view_depth;\nlayout(location = 0) out vec4 color;\nlayout(location = 1) out vec4 fogvol_o;\n"
            "void main() { color = vec4(0.35, 0.3, 0.25, 1.0); fogvol_o = fogvol_encode_view_depth(view_depth); }\n";
    e->prog = fx_program(&vs, 1, fs, 3);
    e->u_mvp = glGetUniformLocation(e->prog, "mvp");
    e->u_view = glGetUniformLocation(e->prog, "mv");
    e->u_mrt = glGetUniformLocation(e->prog, "fogvol_mrt");
    fx_color_depth_fbo(W, H, GL_DEPTH_COMPONENT24, GL_UNSIGNED_INT, &e->color, &e->depth, &e->fbo);
}

static void engine_free(engine *e)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &e->fbo);
    glDeleteTextures(1, &e->color);
    glDeleteTextures(1, &e->depth);
    glDeleteProgram(e->prog);
}

/* The engine's opaque pass: its occluders into colour + depth, and with mrt
   the encoded depth into fogvol's O texture as colour attachment 1. */
static void engine_draw(engine *e, const tscene *s, const float view[16], const float proj[16],
                        const fogvol_mrt_info *mrt)
{
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    const float bg[4] = {0.2f, 0.5f, 0.8f, 1.0f};
    GLuint vao, vbo, ibo;
    int i;
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, mrt ? (GLuint)mrt->texture : 0, 0);
    glDrawBuffers(mrt ? 2 : 1, bufs);
    glViewport(0, 0, W, H);
    glClearBufferfv(GL_COLOR, 0, bg);
    if (mrt) glClearBufferfv(GL_COLOR, 1, mrt->clear_color);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(e->prog);
    if (mrt) glUniform4fv(e->u_mrt, 2, mrt->uniforms);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ibo);
    for (i = 0; i < s->n; ++i) {
        float mv[16], mvp[16];
        if (s->obj[i].sign != 0) continue;
        shp_mat_mul(mv, view, s->obj[i].model);
        shp_mat_mul(mvp, proj, mv);
        glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, mvp);
        glUniformMatrix4fv(e->u_view, 1, GL_FALSE, mv);
        glBindBuffer(GL_ARRAY_BUFFER, vbo);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(12 * (size_t)s->obj[i].mesh.vcount), s->obj[i].mesh.pos,
                     GL_STREAM_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(4 * (size_t)s->obj[i].mesh.icount), s->obj[i].mesh.idx,
                     GL_STREAM_DRAW);
        glDrawElements(GL_TRIANGLES, s->obj[i].mesh.icount, GL_UNSIGNED_INT, NULL);
    }
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ibo);
    glDisable(GL_DEPTH_TEST);
    glDrawBuffers(1, bufs); /* fogvol composites into attachment 0 only */
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
}

static int first_dialect(int ci)
{
    int di;
    for (di = 0; di < NDIALECT; ++di)
        if (fogvol_combination_supported(g_tier_combos[ci].tier, g_tier_combos[ci].variants, g_dialects[di]) == 0) return di;
    return -1;
}

/* ---- one tier/variant/dialect on every scene ------------------------------ */
static void run(int ci, int di)
{
    const tier_combo *c = &g_tier_combos[ci];
    fogvol_dialect dialect = g_dialects[di];
    int core = dialect != FOGVOL_GLSL_110 && dialect != FOGVOL_GLSL_120 && dialect != FOGVOL_GLSL_130;
    int sc, i, j, bad = 0, n = 0;
    double max_lsb = 0, sum_pp = 0, comp_max = 0, snap, slack_pp = 0;
    unsigned char *base = (unsigned char *)malloc((size_t)W * H * 4), *fogged = (unsigned char *)malloc((size_t)W * H * 4);
    glu_ctx g;
    engine e;
    assert_true(glu_create(&g, W, H, core));
    snap = snap_pixels();
    engine_init(&e);
    for (sc = 0; sc < NSCENE; ++sc) {
        const tscene *s = &g_scenes[scene_index(g_scene_names[sc])];
        const gt_cache *t = &g_gt[sc];
        fogvol_context_desc cd;
        fogvol_context *fv;
        fogvol_mesh *meshes[MAX_OBJ];
        fogvol_ramp *ramp;
        fogvol_ramp_desc rd;
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        fogvol_mrt_info mrt;
        fogvol_tier_info ti;
        fogvol_result r;
        float *thick = (float *)calloc((size_t)W * H, sizeof(float));
        double range = s->cam.zfar - s->cam.znear;
        int bits = c->bits ? c->bits : s->bits;
        double lsb = c->tier == FOGVOL_TIER_FLOAT ? 3e-5 * range
                     : range / pow(2.0, ((c->variants & FOGVOL_VARIANT_WIDE) ? 6.0 : 3.0) * bits);
        int has_neg = 0, count = (c->variants & FOGVOL_VARIANT_COUNT) != 0;
        /* Baker's count needs the camera outside the volumes: with it inside, end_frame refuses
           the frame and draws nothing (the image stays the engine's, never a wrong fog) */
        int refused = count && strcmp(s->name, "camera_inside_sphere") == 0;
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.gl.dialect = dialect;
        cd.logger.func = logger;
        cd.tier = c->tier;
        cd.variants = c->variants;
        cd.encoding_bits = bits;
        cd.disable_dither = 1;
        r = fogvol_create_context(&cd, &fv);
        assert_int_equal(r, FOGVOL_SUCCESS);
        upload_meshes(fv, s, meshes);
        for (i = 0; i < s->n; ++i) has_neg |= s->obj[i].sign < 0;
        memset(&rd, 0, sizeof rd);
        rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
        rd.density = s->density;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);

        fx_frame_desc(&fd, &s->cam, W, H);
        fd.debug_thickness = thick;
        fd.engine_depth_texture = e.depth;
        fd.show_overflow = 1; /* nothing overflows here: a magenta pixel fails the composite check */
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        if (c->tier == FOGVOL_TIER_MRT) {
            assert_int_equal(fogvol_mrt_prepare(fv, &mrt), FOGVOL_SUCCESS);
            engine_draw(&e, s, fd.view, fd.projection, &mrt);
        } else {
            engine_draw(&e, s, fd.view, fd.projection, NULL);
        }
        add_scene(fv, s, meshes, ramp, c->tier != FOGVOL_TIER_MRT);
        /* the engine's picture before the fog, to check the composite against */
        glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, base);
        r = fogvol_end_frame(fv, &st);
        glFinish();
        glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, fogged);
        if (refused) {
            assert_int_equal(r, FOGVOL_ERROR_UNSUPPORTED);
            assert_int_equal(st.passes, 0);
            assert_memory_equal(base, fogged, (size_t)W * H * 4);
            for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
            fogvol_destroy_ramp(fv, ramp);
            fogvol_destroy_context(fv);
            free(thick);
            continue;
        }
        assert_int_equal(r, FOGVOL_SUCCESS);
        /* composite: mix(engine, fog, 1 - exp(-density t)) within 2/255 where the
           tier's own GPU decode did the work (interior, covered, inside the ramp) */
        for (i = 0; i < W * H; ++i) {
            double a, want, got;
            int ch;
            if (!t->interior[i] || !t->covered[i]) continue;
            a = 1.0 - exp(-(double)s->density * (t->gt[i] > 0 ? t->gt[i] : 0));
            for (ch = 0; ch < 3; ++ch) {
                want = base[4 * i + ch] / 255.0 + (0.8 - base[4 * i + ch] / 255.0) * a;
                got = fogged[4 * i + ch] / 255.0;
                if (fabs(got - want) > comp_max) comp_max = fabs(got - want);
            }
        }
        if (di == first_dialect(ci) && strcmp(s->name, "layers_opaque_between") == 0) {
            /* what the tier shows: build/tiers/<combo>.png (engine colour after the composite) */
            unsigned char *px = (unsigned char *)malloc((size_t)W * H * 4);
            char path[256], *q;
            glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
            glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
            mkdir("build", 0777);
            mkdir("build/tiers", 0777);
            snprintf(path, sizeof path, "build/tiers/%s.png", c->name);
            for (q = path + 12; *q; ++q)
                if (*q == ' ' || *q == '(' || *q == ')' || *q == ',' || *q == '=' || *q == '+') *q = '_';
            stbi_flip_vertically_on_write(1);
            stbi_write_png(path, W, H, 4, px, W * 4);
            free(px);
        }
        assert_int_equal(glGetError(), GL_NO_ERROR);
        /* passes as the tier info says: +1 per sum pass for the negative volumes */
        assert_int_equal(fogvol_tier_costs(c->tier, c->variants, &ti), FOGVOL_SUCCESS);
        j = ti.library_passes;
        /* PS20, MRT and PS13 summing in integers (FOGVOL_SPEEDUP_EXACT_SUM: this GL has framebuffer fetch
           in GLSL 330 and 300 es where the GL has it: Mesa, not NVIDIA's desktop driver): one sum pass
           for every face, negative volumes' too; PS20 with the engine's depth too (its O an R32F texture,
           FOGVOL_SPEEDUP_FLOAT_O) */
        assert_int_equal(st.exact_sum, c->tier != FOGVOL_TIER_FLOAT &&
                                           !(c->variants & (FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_WIDE |
                                                            FOGVOL_VARIANT_COUNT)) &&
                                           (dialect == FOGVOL_GLSL_330 || dialect == FOGVOL_GLSL_300ES) &&
                                           glu_has_fetch());
        j -= st.exact_sum;
        if (has_neg && c->tier != FOGVOL_TIER_FLOAT && !st.exact_sum) j += 2;
        /* PS13 on a backend with fp32 fragment shaders (the GL backend on desktop GL: every dialect
           here) resolves B - F in its composite: no resolve pass (FOGVOL_SPEEDUP_INLINE_RESOLVE) */
        assert_int_equal(st.inline_resolved, c->tier == FOGVOL_TIER_PS13);
        j -= st.inline_resolved;
        if (c->variants & FOGVOL_VARIANT_SINGLE_TARGET) j += 0; /* S+, S- replace B, F */
        assert_int_equal(st.passes, j);

        for (i = 0; i < W * H; ++i) {
            double err;
            if (!t->interior[i]) continue;
            err = fabs(thick[i] - t->gt[i]) / lsb;
            if (err > max_lsb) max_lsb = err;
            if (t->covered[i]) {
                sum_pp += err / t->pairs[i];
                slack_pp += t->slope[i] * snap / lsb / t->pairs[i];
                ++n;
            }
            /* + 1e-6 (far - near): fp32 vertex transforms move a grazing face's depth (visible at 18 bits);
               + what the GL's vertex snapping may move the faces (rc_depth_slope) */
            if (err > (c->tier == FOGVOL_TIER_FLOAT ? 1.0 : t->pairs[i] + 1e-6 * range / lsb) +
                          t->slope[i] * snap / lsb) {
                if (bad < 3)
                    print_message("  %s/%s/%s pixel (%d,%d): %.5f vs %.5f (%.2f units; %d pairs, snapping %.2f)\n",
                                  c->name, fogvol_dialect_name(dialect), s->name, i % W, i / W, thick[i], t->gt[i], err,
                                  t->pairs[i], t->slope[i] * snap / lsb);
                ++bad;
            }
        }
        for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
        free(thick);
    }
    engine_free(&e);
    glu_destroy(&g);
    free(base);
    free(fogged);
    g_comp[ci][di] = comp_max * 255.0;
    g_max[ci][di] = max_lsb;
    g_mean[ci][di] = n ? sum_pp / n : 0;
    g_ran[ci][di] = 1;
    if (comp_max > 2.0 / 255.0)
        print_message("  %s/%s: composite off by %.2f/255\n", c->name, fogvol_dialect_name(dialect), comp_max * 255);
    assert_int_equal(bad, 0);
    assert_true(g_mean[ci][di] <= 0.5 + (n ? slack_pp / n : 0)); /* + the mean vertex-snapping allowance */
    assert_true(comp_max <= 2.0 / 255.0);
}

typedef struct tcase {
    int combo, dialect;
} tcase;

static void run_case(void **state)
{
    const tcase *t = (const tcase *)*state;
    run(t->combo, t->dialect);
}

/* AUTO picks from the backend's caps; unsupported combinations give a code. */
static void test_choice_and_support(void **state)
{
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *fv;
    glu_ctx g;
    const char *s[FOGVOL_MAX_SHADER_STRINGS];
    int n = 5;
    (void)state;
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    cd.backend.caps = FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_FLOAT);
    fogvol_destroy_context(fv);
    cd.backend.caps = FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_PS20);
    fogvol_destroy_context(fv);
    cd.engine_mrt = 1;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_MRT);
    fogvol_destroy_context(fv);
    cd.engine_mrt = 0;
    cd.backend.caps = 0; /* lowp/mediump fragment shaders only */
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_PS13);
    fogvol_destroy_context(fv);
    cd.tier = FOGVOL_TIER_FLOAT; /* asked for, but the backend cannot */
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(nb.creates, nb.destroys);
    cd.backend.dialect = FOGVOL_GLSL_100; /* GLES2 has no float targets: FLOAT does not exist there */
    cd.backend.caps = FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_HIGHP_FRAGMENT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_shader_source(FOGVOL_TIER_FLOAT, FOGVOL_PROGRAM_FACE, FOGVOL_GLSL_100,
                                          FOGVOL_STAGE_FRAGMENT, s, &n),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(n, 0);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_MRT, 0, FOGVOL_GLSL_120), FOGVOL_ERROR_UNSUPPORTED);
    /* PS13 encodes by integer arithmetic only where the dialect guarantees highp integers */
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_PS13, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_330),
                     FOGVOL_SUCCESS);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_PS13, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_300ES),
                     FOGVOL_SUCCESS);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_PS13, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_100),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_PS13, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_150),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET |
                                                  FOGVOL_VARIANT_COUNT, FOGVOL_GLSL_330), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_tier_uses_program(FOGVOL_TIER_PS20, 0, FOGVOL_PROGRAM_RESOLVE), 0);
    assert_int_equal(fogvol_shader_source(FOGVOL_TIER_PS20, FOGVOL_PROGRAM_RESOLVE, FOGVOL_GLSL_330,
                                          FOGVOL_STAGE_FRAGMENT, s, &n), FOGVOL_ERROR_UNSUPPORTED);

    /* the GL backend in Mesa's core context: float blending -> FLOAT; as GL 2.1 -> PS20 */
    assert_true(glu_create(&g, 16, 16, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_FLOAT);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    assert_true(glu_create(&g, 16, 16, 0));
    cd.gl.version_major = 2;
    cd.gl.version_minor = 1;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_PS20);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

/* A shape as a closed fogvol mesh. */
static fogvol_mesh *upload_shape(fogvol_context *fv, const shp_mesh *m)
{
    fogvol_mesh_desc md;
    fogvol_mesh *out = NULL;
    memset(&md, 0, sizeof md);
    md.positions = m->pos;
    md.vertex_count = m->vcount;
    md.indices = (const uint32_t *)m->idx;
    md.index_count = m->icount;
    assert_int_equal(fogvol_create_mesh(fv, &md, &out, NULL), FOGVOL_SUCCESS);
    return out;
}

/* The single-target variant sums on top of 128: half the faces fit. k nested
   shells near the far plane (digits up to 15 at L = 4): 8 per sign still sum
   exactly, 12 saturate and are reported, while the two-target PS20 holds 12. */
static void shells(int k, unsigned variants, fogvol_result *result, int *overflow, double *max_err)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_volume_desc vd;
    rc_camera cam;
    float *thick = (float *)calloc((size_t)W * H, sizeof(float));
    shp_mesh all = shp_sphere(0.25f, 32, 16);
    int i;
    double r0;
    for (i = 1; i < k; ++i) { /* one mesh: k concentric spheres */
        shp_mesh one = shp_sphere(0.25f + 0.02f * (float)i, 32, 16);
        shp_append(&all, &one);
        shp_free(&one);
    }
    memset(&cam, 0, sizeof cam);
    cam.eye[2] = 9.2;
    cam.up[1] = 1;
    cam.fovy_deg = 10;
    cam.aspect = 1;
    cam.znear = 0.5;
    cam.zfar = 10;
    cam.width = W;
    cam.height = H;
    assert_true(glu_create(&g, W, H, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.tier = FOGVOL_TIER_PS20;
    cd.variants = variants;
    cd.disable_dither = 1;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    mesh = upload_shape(fv, &all);
    memset(&rd, 0, sizeof rd);
    rd.density = 1;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    rc_camera_matrices(&cam, fd.view, fd.projection);
    fd.znear = 0.5f;
    fd.zfar = 10;
    fd.viewport[2] = W;
    fd.viewport[3] = H;
    fd.debug_thickness = thick;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = mesh;
    vd.ramp = ramp;
    shp_mat_identity(vd.model);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    *result = fogvol_end_frame(fv, &st);
    *overflow = st.overflow_pixels;
    /* the centre ray: every shell adds its diameter; analytic within the tessellation of the poles
       (the ray runs pole to pole, where the mesh has vertices: exact) */
    r0 = 0;
    for (i = 0; i < k; ++i) r0 += 2.0 * (0.25 + 0.02 * i);
    *max_err = fabs(thick[(H / 2) * W + W / 2] - r0) / (9.5 / 4096.0);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    shp_free(&all);
    free(thick);
}

static void test_single_target_limit(void **state)
{
    fogvol_result r;
    int ov;
    double err;
    fogvol_encoding e;
    (void)state;
    fogvol_encoding_init(4, &e);
    assert_int_equal(e.max_faces_single, e.max_faces / 2);
    shells(8, FOGVOL_VARIANT_SINGLE_TARGET, &r, &ov, &err);
    print_message("  single target, 8 shells: %s, %d saturated pixels, centre error %.2f LSB\n",
                  fogvol_result_string(r), ov, err);
    assert_int_equal(r, FOGVOL_SUCCESS);
    assert_int_equal(ov, 0);
    assert_true(err <= 8.0);
    shells(12, FOGVOL_VARIANT_SINGLE_TARGET, &r, &ov, &err);
    print_message("  single target, 12 shells: %s, %d saturated pixels\n", fogvol_result_string(r), ov);
    assert_int_equal(r, FOGVOL_ERROR_DEPTH_OVERFLOW);
    assert_true(ov > 0);
    shells(12, 0, &r, &ov, &err);
    print_message("  two targets, 12 shells: %s, %d saturated pixels, centre error %.2f LSB\n",
                  fogvol_result_string(r), ov, err);
    assert_int_equal(r, FOGVOL_SUCCESS);
    assert_true(err <= 12.0);
}

/* FOGVOL_SPEEDUP_FLOAT_O: O as R32F (MRT: written by the same snippet; PS20: by fogvol's O pass
   over the scene's occluders), read by faces that encode min(own depth, O), gives the bytes of the
   RGBA8 O (the speed-up switched off, and a backend without FOGVOL_CAP_FLOAT_TARGET): every pixel of
   the engine's colour after the composite and every debug thickness, dither on, with a
   density-textured volume and a light, whose faces decode O's digits (FV_O_DIGITS); these frames
   take the min compare (test_speedups test_float_o: COUNT frames). Camera inside: O is the far
   plane everywhere. A backend that cannot build the face programs for an R32F O (mode 3) gets the
   RGBA8 O and the same bytes, and a warning; with SPECIALIZE off (mode 4, the same sums) the frame
   uses the general programs, PS20's O pass's among them, which was built for the R32F O before the
   face's failed and must be built again. */
static fogvol_backend g_fo_inner;
static int g_fo_warnings, g_fo_format;
/* modes 3 and 4: the face programs for an R32F O fail to build (PS20 has made its O pass's by then) */
static fogvol_result fo_fail_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    int i;
    for (i = 0; i < d->fs_count; ++i)
        if (strcmp(d->fs[i], "#define FV_O_FLOAT\n") == 0 && d->label && strcmp(d->label, "fogvol face") == 0)
            return FOGVOL_ERROR_BACKEND;
    return g_fo_inner.create_program(u, d, out);
}
static fogvol_result fo_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    if (d->label && strncmp(d->label, "fogvol O ", 9) == 0) g_fo_format = (int)d->format;
    return g_fo_inner.create_target(u, d, out);
}
static void fo_logger(void *u, fogvol_log_level l, const char *m)
{
    g_fo_warnings += l == FOGVOL_LOG_WARNING && strstr(m, "O stays RGBA8") != NULL;
    logger(u, l, m);
}
static void float_o_frame(const tscene *s, fogvol_tier tier, int mode, int light, unsigned char *px, float *thick)
{
    static const char *const names[5] = {"float O", "speed-up off", "no FOGVOL_CAP_FLOAT_TARGET",
                                         "R32F programs fail to build",
                                         "R32F programs fail to build, SPECIALIZE off"};
    fogvol_context_desc cd;
    fogvol_backend be;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ], *lbox;
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_mrt_info mrt;
    fogvol_volume_desc vd;
    fogvol_light_desc ld;
    fogvol_volume_texture *tex;
    fogvol_texture_desc td;
    shp_mesh box = shp_box(0.8f, 0.8f, 0.8f);
    unsigned char dens[16 * 16 * 4];
    GLint fmt = 0;
    engine e;
    int i;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = fo_logger;
    cd.tier = tier;
    g_fo_warnings = 0;
    g_fo_format = -1;
    if (mode == 1) cd.disable_speedups = FOGVOL_SPEEDUP_FLOAT_O;
    assert_int_equal(fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &be), FOGVOL_SUCCESS);
    assert_true(be.caps & FOGVOL_CAP_FLOAT_TARGET); /* desktop GL 3.0+ */
    g_fo_inner = be;
    be.create_target = fo_target;
    if (mode == 2) be.caps &= ~(unsigned)FOGVOL_CAP_FLOAT_TARGET;
    if (mode >= 3) be.create_program = fo_fail_program;
    if (mode == 4) cd.disable_speedups = FOGVOL_SPEEDUP_SPECIALIZE; /* the general programs: made first */
    cd.backend = be;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(g_fo_warnings, mode >= 3);
    engine_init(&e);
    upload_meshes(fv, s, meshes);
    lbox = upload_shape(fv, &box);
    for (i = 0; i < 16 * 16; ++i) {
        dens[4 * i] = (unsigned char)(40 + (i * 53) % 216);
        dens[4 * i + 1] = dens[4 * i + 2] = 0;
        dens[4 * i + 3] = 255;
    }
    memset(&td, 0, sizeof td);
    td.width = td.height = 16;
    td.pixels = dens;
    td.filter = FOGVOL_FILTER_NEAREST;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &tex), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f, rd.color[1] = 0.6f, rd.color[2] = 0.3f;
    rd.density = s->density;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    fx_frame_desc(&fd, &s->cam, W, H);
    fd.debug_thickness = thick;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    if (tier == FOGVOL_TIER_MRT) {
        assert_int_equal(fogvol_mrt_prepare(fv, &mrt), FOGVOL_SUCCESS);
        glBindTexture(GL_TEXTURE_2D, (GLuint)mrt.texture);
        glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_INTERNAL_FORMAT, &fmt);
        glBindTexture(GL_TEXTURE_2D, 0);
        assert_int_equal(fmt, mode == 0 ? GL_R32F : GL_RGBA8);
        assert_int_equal(mrt.format, mode == 0 ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8);
        engine_draw(&e, s, fd.view, fd.projection, &mrt);
    } else {
        engine_draw(&e, s, fd.view, fd.projection, NULL); /* the occluders: fogvol's O pass draws them */
    }
    add_scene(fv, s, meshes, ramp, tier != FOGVOL_TIER_MRT);
    memset(&vd, 0, sizeof vd); /* the first volume's mesh once more, shifted, density-textured across x and y */
    for (i = 0; s->obj[i].sign == 0; ++i) continue;
    vd.mesh = meshes[i];
    vd.ramp = ramp;
    glu_translate_scale(vd.model, 0.15f, -0.1f, 0.05f, 0.9f);
    vd.density = tex;
    vd.density_map[0] = 0.4f, vd.density_map[3] = 0.5f, vd.density_map[5] = 0.4f, vd.density_map[7] = 0.5f;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    memset(&ld, 0, sizeof ld);
    ld.mesh = lbox;
    glu_translate_scale(ld.model, 0.1f, -0.2f, -0.3f, 1);
    ld.color[0] = 0.3f, ld.color[1] = 0.25f, ld.color[2] = 0.1f;
    if (light) assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.lights, light);
    assert_int_equal(st.depth_tested, 0); /* (a density-textured volume: the min compare) */
    assert_int_equal(g_fo_format, mode == 0 ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8);
    glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    if (strcmp(s->name, "plane_cuts_sphere") == 0 && mode == 0 && light && tier == FOGVOL_TIER_MRT) {
        mkdir("build", 0777);
        mkdir("build/tiers", 0777); /* (this test runs before the tier cases that also make it) */
        stbi_flip_vertically_on_write(1);
        stbi_write_png("build/tiers/mrt_float_o.png", W, H, 4, px, W * 4);
    }
    print_message("  %s %s, %s%s: O %s\n", fogvol_tier_name(tier), names[mode], s->name, light ? "" : " (no light)",
                  mode == 0 ? "R32F" : "RGBA8");
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_volume_texture(fv, tex);
    fogvol_destroy_mesh(fv, lbox);
    for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
    fogvol_destroy_context(fv);
    be.destroy(be.user_data); /* (a backend table passed in stays the caller's) */
    engine_free(&e);
    shp_free(&box);
}

static void test_float_o(void **state)
{
    static const char *const scenes[] = {"plane_cuts_sphere", "layers_opaque_between", "camera_inside_sphere"};
    static const fogvol_tier tiers[2] = {FOGVOL_TIER_MRT, FOGVOL_TIER_PS20};
    unsigned char *px[6];
    float *thick[6];
    glu_ctx g;
    int sc, m, i, t, lit = 0, differ;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (m = 0; m < 6; ++m) {
        px[m] = (unsigned char *)malloc((size_t)W * H * 4);
        thick[m] = (float *)malloc((size_t)W * H * sizeof(float));
    }
    for (t = 0; t < 2; ++t)
        for (sc = 0; sc < 3; ++sc) {
            const tscene *s = &g_scenes[scene_index(scenes[sc])];
            for (m = 0; m < 5; ++m) float_o_frame(s, tiers[t], m, 1, px[m], thick[m]);
            float_o_frame(s, tiers[t], 0, 0, px[5], thick[5]);
            for (m = 1; m < 5; ++m) {
                /* (mode 4's general composite takes exp() instead of FAST_EXP: its sums alone) */
                for (i = 0, differ = 0; i < W * H * 4 && m < 4; ++i) differ += px[0][i] != px[m][i];
                if (differ) print_message("  %s: %d bytes differ from the RGBA8 O (mode %d)\n", s->name, differ, m);
                assert_int_equal(differ, 0);
                assert_memory_equal(thick[0], thick[m], (size_t)W * H * sizeof(float));
            }
            /* the light lit occluder pixels (its back faces read O) where the scene has occluders */
            for (i = 0, differ = 0; i < W * H; ++i) differ += memcmp(px[0] + 4 * i, px[5] + 4 * i, 4) != 0;
            print_message("  %s: %d pixels lit\n", s->name, differ);
            if (s->n > 1) assert_true(differ > 50);
            lit += differ;
        }
    print_message("  FLOAT_O: the same bytes in 2 tiers x 3 scenes x 4 ways (the same sums 5 ways); %d pixels lit\n",
                  lit);
    for (m = 0; m < 6; ++m) {
        free(px[m]);
        free(thick[m]);
    }
    glu_destroy(&g);
}

/* The pass counts of the seed (engine pass included) and fogvol's own. */
static void test_pass_counts(void **state)
{
    fogvol_tier_info ti;
    (void)state;
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_PS13, 0, &ti), 0);
    assert_int_equal(ti.paper_passes, 6);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_PS20, 0, &ti), 0);
    assert_int_equal(ti.paper_passes, 5);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_MRT, 0, &ti), 0);
    assert_int_equal(ti.paper_passes, 4);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_FLOAT, 0, &ti), 0);
    assert_int_equal(ti.paper_passes, 3);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, &ti), 0);
    assert_int_equal(ti.library_passes, 2);
    /* targets: O, B, F (+ T for PS13's resolve); one sum target S when single; FLOAT: O and the float sum */
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_PS13, 0, &ti), 0);
    assert_int_equal(ti.targets, 4);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_PS20, 0, &ti), 0);
    assert_int_equal(ti.targets, 3);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, &ti), 0);
    assert_int_equal(ti.targets, 2);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_FLOAT, 0, &ti), 0);
    assert_int_equal(ti.targets, 2);
    assert_int_equal(fogvol_tier_costs(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, &ti), 0);
    assert_int_equal(ti.targets, 1);
    print_message("  passes (seed / fogvol): PS13 6/5, PS20 5/4, MRT 4/3, FLOAT 3/3, FLOAT+engine depth -/2\n");
}

static int print_table(void **state)
{
    int ci, di;
    (void)state;
    print_message("\n| tier + variants | ");
    for (di = 0; di < NDIALECT; ++di) print_message("%s | ", fogvol_dialect_name(g_dialects[di]));
    print_message("\n|---|");
    for (di = 0; di < NDIALECT; ++di) print_message("---|");
    print_message("\n");
    for (ci = 0; ci < NTIER_COMBO; ++ci) {
        print_message("| %s (%s) | ", g_tier_combos[ci].name, g_tier_combos[ci].tier == FOGVOL_TIER_FLOAT ? "3e-5 range" : "LSB");
        for (di = 0; di < NDIALECT; ++di) {
            if (g_ran[ci][di]) print_message("%.2f / %.3f / %.1f | ", g_max[ci][di], g_mean[ci][di], g_comp[ci][di]);
            else print_message("n/a | ");
        }
        print_message("\n");
    }
    print_message("(max error / mean error per pair of faces over interior pixels of %d scenes / max composite "
                  "colour error in 1/255; n/a: the combination does not exist in that dialect)\n\n", NSCENE);
    gt_teardown();
    return 0;
}

static int supported(int ci, int di)
{
    return fogvol_combination_supported(g_tier_combos[ci].tier, g_tier_combos[ci].variants, g_dialects[di]) == 0;
}

/* The cases of the sanitizer build (make test sets FOGVOL_TEST_SUBSET there; the plain build runs every
   case): each combination in the first and the last dialect that has it, and each dialect in the first
   combination that it has. With them the same lines of fogvol.h run as with every case (gcov). */
static int in_subset(int ci, int di)
{
    int d, c, first = -1, last = -1;
    for (d = 0; d < NDIALECT; ++d)
        if (supported(ci, d)) {
            if (first < 0) first = d;
            last = d;
        }
    if (di == first || di == last) return 1;
    for (c = 0; c < NTIER_COMBO && !supported(c, di); ++c) {
    }
    return c == ci;
}

int main(void)
{
    static tcase cases[NTIER_COMBO * NDIALECT];
    static struct CMUnitTest tests[NTIER_COMBO * NDIALECT + 4];
    static char names[NTIER_COMBO * NDIALECT][64];
    int ci, di, n = 0, all = 0;
    const char *subset = getenv("FOGVOL_TEST_SUBSET");
    tests[n].name = "choice_and_support";
    tests[n].test_func = test_choice_and_support;
    ++n;
    tests[n].name = "pass_counts";
    tests[n].test_func = test_pass_counts;
    ++n;
    tests[n].name = "single_target_limit";
    tests[n].test_func = test_single_target_limit;
    ++n;
    tests[n].name = "float_o";
    tests[n].test_func = test_float_o;
    ++n;
    for (ci = 0; ci < NTIER_COMBO; ++ci)
        for (di = 0; di < NDIALECT; ++di) {
            tcase *t = &cases[n - 4];
            if (!supported(ci, di)) continue;
            ++all;
            if (subset && *subset && !in_subset(ci, di)) continue;
            t->combo = ci;
            t->dialect = di;
            snprintf(names[n - 4], sizeof names[n - 4], "%s_glsl_%s", g_tier_combos[ci].name,
                     fogvol_dialect_name(g_dialects[di]));
            tests[n].name = names[n - 4];
            tests[n].test_func = run_case;
            tests[n].initial_state = t;
            ++n;
        }
    if (n - 4 < all) printf("# FOGVOL_TEST_SUBSET: %d of the %d tier cases (the plain build runs them all)\n", n - 4, all);
    return cmocka_run_group_tests_name("tiers", tests, gt_group_setup, print_table); /* zeroed entries are skipped */
}
