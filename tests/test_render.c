/* test_render.c - fogvol's PS20 renderer and GL backend under OSMesa, against
   ground truth ray-cast in the test (tests/raycast.h) from the very triangles
   that are drawn: per pixel, the w-extent inside the meshes between the near
   plane and the nearest opaque surface.

   Every scene runs in a 3.3 core context and in a compatibility context
   treated as GL 2.1 (GLSL 120, no VAO), with dithering off and on.
   Errors are in LSBs of the encoding ((far - near) / 2^(3L)) over interior
   pixels (the one-pixel silhouette band excluded by rc_interior).
   Images go to build/render/<scene>_<profile>.png: composite | thickness | error map. */
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
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#include "tests/scenes.h"
#include "tests/fixtures.h"

typedef struct tcase {
    int scene;
    int core;
} tcase;

/* measured per scene/profile for the closing table */
typedef struct tstats {
    double max_err, mean_abs, mean_per_pair, block_max;
    double max_comp;
    int interior, max_faces;
} tstats;

static tstats g_stats[28][2];

static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l <= FOGVOL_LOG_WARNING) print_message("  [fogvol %s] %s\n", l == 0 ? "error" : "warning", m);
}

typedef struct frame_out {
    float *thick;          /* decoded thickness (debug read-back) */
    unsigned char *pixels; /* engine framebuffer after the composite */
    fogvol_result result;
    fogvol_frame_stats stats;
} frame_out;

static const float g_scene_rgb[3] = {0.2f, 0.5f, 0.8f};
static const float g_fog_rgb[3] = {0.9f, 0.6f, 0.3f};

/* An OSMesa context, a fogvol context with the scene's encoding, its meshes
   uploaded, and an extinction ramp blended as fog or light. core = 0: a
   compatibility context treated as GL 2.1 (GLSL 120, no VAO). */
static void setup(const tscene *s, int core, fogvol_blend blend, glu_ctx *g, fogvol_context **fv,
                  fogvol_mesh **meshes, fogvol_ramp **ramp)
{
    fogvol_context_desc cd;
    fogvol_ramp_desc rd;
    assert_true(glu_create(g, W, H, core));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.encoding_bits = s->bits;
    cd.tier = FOGVOL_TIER_PS20; /* the other tiers: test_tiers.c */
    cd.disable_speedups = FOGVOL_SPEEDUP_EXACT_SUM; /* the digits and their dither (integer sums: test_overflow,
                                                       test_speedups, test_tiers) */
    if (!core) {
        cd.gl.version_major = 2;
        cd.gl.version_minor = 1;
    }
    assert_int_equal(fogvol_create_context(&cd, fv), FOGVOL_SUCCESS);
    upload_meshes(*fv, s, meshes);
    memset(&rd, 0, sizeof rd);
    memcpy(rd.color, g_fog_rgb, sizeof rd.color);
    rd.density = s->density;
    rd.width = 1024;
    rd.blend = blend;
    assert_int_equal(fogvol_create_ramp(*fv, &rd, ramp), FOGVOL_SUCCESS);
}

static void teardown(const tscene *s, glu_ctx *g, fogvol_context *fv, fogvol_mesh **meshes, fogvol_ramp *ramp)
{
    int i;
    for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(g);
}

/* Render the scene with fogvol into the current OSMesa framebuffer. */
static void render(fogvol_context *fv, const tscene *s, fogvol_mesh **meshes, fogvol_ramp *ramp, int dither,
                   fogvol_composite comp, int show_overflow, glu_ctx *g, frame_out *out)
{
    fogvol_frame_desc fd;
    fx_frame_desc(&fd, &s->cam, W, H);
    fd.composite = comp;
    fd.show_overflow = show_overflow;
    fd.debug_thickness = out->thick;
    glClearColor(g_scene_rgb[0], g_scene_rgb[1], g_scene_rgb[2], 1.0f);
    glClearStencil(0);
    glClear(GL_COLOR_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    fogvol_set_dither(fv, dither);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_scene(fv, s, meshes, ramp, 1);
    out->result = fogvol_end_frame(fv, &out->stats);
    memcpy(out->pixels, glu_pixels(g), (size_t)W * H * 4);
}

/* The scene's thickness through the FLOAT tier on the current GL context (dither has no meaning
   there): the same rasterised depths as the PS20 frame, without its quantisation. */
static void float_reference(const tscene *s, float *thick)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    int i;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_FLOAT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    upload_meshes(fv, s, meshes);
    memset(&rd, 0, sizeof rd);
    rd.density = s->density;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    fx_frame_desc(&fd, &s->cam, W, H);
    fd.debug_thickness = thick;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    add_scene(fv, s, meshes, ramp, 1);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
}

static unsigned char to8(double v) { return (unsigned char)(v < 0 ? 0 : v > 1 ? 255 : v * 255.0 + 0.5); }

static void write_png(const char *name, const char *profile, const frame_out *f, const double *gt,
                      const unsigned char *interior, double lsb, double tmax)
{
    unsigned char *img = (unsigned char *)calloc((size_t)W * 3 * H, 4);
    char path[256];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            int i = y * W + x, row = H - 1 - y; /* PNG rows top to bottom */
            unsigned char *a = img + ((size_t)row * W * 3 + x) * 4, *b = a + W * 4, *c = b + W * 4;
            double e = (f->thick[i] - gt[i]) / lsb;
            memcpy(a, f->pixels + i * 4, 4);
            a[3] = 255;
            b[0] = b[1] = b[2] = to8(f->thick[i] / tmax);
            b[3] = 255;
            if (!interior[i]) {
                c[0] = c[1] = c[2] = 40;
            } else {
                c[0] = to8(e / 2.0);
                c[1] = to8(1.0 - fabs(e) / 2.0) / 2;
                c[2] = to8(-e / 2.0);
            }
            c[3] = 255;
        }
    mkdir("build", 0777);
    mkdir("build/render", 0777);
    snprintf(path, sizeof path, "build/render/%s_%s.png", name, profile);
    stbi_write_png(path, W * 3, H, 4, img, W * 3 * 4);
    free(img);
}

static void run_case(void **state)
{
    const tcase *tc = (const tcase *)*state;
    const tscene *s = &g_scenes[tc->scene];
    const char *profile = tc->core ? "core33" : "gl21";
    glu_ctx g;
    fogvol_context *fv = NULL;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp *ramp = NULL;
    double *gt = (double *)calloc((size_t)W * H, sizeof(double)), lsb, sum_abs = 0, sum_pp = 0, max_err = 0,
           block_max = 0,
           max_comp = 0, tmax = 0, snap;
    double *slope = (double *)calloc((size_t)W * H, sizeof(double)); /* the bound's vertex-snapping term */
    float *fl = (float *)calloc((size_t)W * H, sizeof(float));       /* FLOAT tier's thickness, same GL */
    int *pairs = (int *)calloc((size_t)W * H, sizeof(int)), i, x, y, ninterior = 0, max_faces = 0, bad = 0;
    unsigned char *interior = (unsigned char *)calloc((size_t)W * H, 1);
    unsigned char *covered = (unsigned char *)calloc((size_t)W * H, 1); /* a volume face on the ray */
    frame_out f0, f1, fg;
    tstats *st = &g_stats[tc->scene][tc->core];

    f0.thick = (float *)calloc((size_t)W * H, sizeof(float));
    f1.thick = (float *)calloc((size_t)W * H, sizeof(float));
    fg.thick = (float *)calloc((size_t)W * H, sizeof(float));
    f0.pixels = (unsigned char *)malloc((size_t)W * H * 4);
    f1.pixels = (unsigned char *)malloc((size_t)W * H * 4);
    fg.pixels = (unsigned char *)malloc((size_t)W * H * 4);

    ground_truth(s, gt, pairs, interior, covered, &max_faces, &tmax, slope);
    lsb = (s->cam.zfar - s->cam.znear) / pow(2.0, 3.0 * s->bits);

    /* fogvol */
    setup(s, tc->core, FOGVOL_BLEND_FOG, &g, &fv, meshes, &ramp);

    render(fv, s, meshes, ramp, 0, FOGVOL_COMPOSITE_FULLSCREEN, 0, &g, &f0);
    render(fv, s, meshes, ramp, 1, FOGVOL_COMPOSITE_FULLSCREEN, 0, &g, &f1);
    render(fv, s, meshes, ramp, 1, FOGVOL_COMPOSITE_GEOMETRY, s->expect_overflow, &g, &fg);
    snap = snap_pixels();

    if (s->expect_overflow) {
        /* the saturated pixels are reported, and painted magenta when asked */
        int magenta = 0, deep = 0;
        assert_int_equal(f0.result, FOGVOL_ERROR_DEPTH_OVERFLOW);
        assert_true(f0.stats.overflow_pixels > 0);
        for (i = 0; i < W * H; ++i) {
            const unsigned char *p = fg.pixels + 4 * i;
            magenta += p[0] == 255 && p[1] == 0 && p[2] == 255;
        }
        for (i = 0; i < W * H; ++i) deep += pairs[i] > 16;
        print_message("  %s/%s: %d pixels cross > 16 faces, %d reported saturated, %d painted magenta\n", s->name,
                      profile, deep, f0.stats.overflow_pixels, magenta);
        assert_true(magenta > 0);
        assert_int_equal(magenta, f0.stats.overflow_pixels);
        /* not silently wrong: every pixel that is not flagged is within the error bound */
        for (i = 0; i < W * H; ++i) {
            const unsigned char *p = fg.pixels + 4 * i;
            int flagged = p[0] == 255 && p[1] == 0 && p[2] == 255;
            if (!interior[i] || flagged) continue;
            if (fabs(f0.thick[i] - gt[i]) / lsb > pairs[i] + 1e-3 + slope[i] * snap / lsb) ++bad;
            if (pairs[i] > 16) ++max_faces; /* reused as: deep pixels that stayed exact */
        }
        print_message("  %s/%s: %d unflagged pixels beyond 16 faces, all exact; %d unflagged pixels off\n", s->name,
                      profile, max_faces, bad);
        assert_int_equal(bad, 0);
        write_png(s->name, profile, &fg, gt, interior, lsb, tmax > 0 ? tmax : 1);
        goto cleanup;
    }
    assert_int_equal(f0.result, FOGVOL_SUCCESS);
    assert_int_equal(f1.result, FOGVOL_SUCCESS);
    assert_int_equal(fg.result, FOGVOL_SUCCESS);

    /* dither off: |err| <= 1 LSB per pair of faces everywhere, mean |err| <= 0.5 LSB
       over the interior pixels that a volume covers */
    for (i = 0; i < W * H; ++i) {
        double e;
        if (!interior[i]) continue;
        e = fabs(f0.thick[i] - gt[i]) / lsb;
        if (covered[i]) {
            ++ninterior;
            sum_abs += e;
            sum_pp += e / pairs[i];
        }
        if (e > max_err) max_err = e;
        if (e > pairs[i] + 1e-3 + slope[i] * snap / lsb) { /* + what vertex snapping may move */
            if (bad < 5)
                print_message("  %s/%s pixel (%d,%d): %.4f vs %.4f = %.2f LSB with %d pairs, snapping %.2f LSB\n",
                              s->name, profile, i % W, i / W, f0.thick[i], gt[i], e, pairs[i], slope[i] * snap / lsb);
            ++bad;
        }
    }
    /* dither on: signed error averaged over fully interior 8x8 blocks <= 0.25 LSB per pair of faces
       (the block's most), against the FLOAT tier's thickness of the same frame on the same GL (the
       same rasterised depths, not quantised: a snapped triangle moves a whole block the same way,
       which is not the dither's bias). Per pair: the 8x8 ordered dither of a sloped face keeps a
       block bias of up to 0.25 LSB (0.25 at a slope of 0.5 LSB per pixel, 0.06-0.21 at others
       from 0.05 to 4), so faces add theirs; stack8_L5 reads 0.23 on llvmpipe, 0.30 on NVIDIA. */
    float_reference(s, fl);
    for (y = 0; y + 8 <= H; y += 8)
        for (x = 0; x + 8 <= W; x += 8) {
            double acc = 0;
            int full = 1, xx, yy, nonzero = 0, pmax = 1;
            for (yy = y; yy < y + 8; ++yy)
                for (xx = x; xx < x + 8; ++xx) {
                    int k = yy * W + xx;
                    full &= interior[k];
                    nonzero |= covered[k];
                    acc += (f1.thick[k] - fl[k]) / lsb;
                    if (pairs[k] > pmax) pmax = pairs[k];
                }
            if (full && nonzero && fabs(acc / 64) / pmax > block_max) block_max = fabs(acc / 64) / pmax;
        }
    /* composite: colour = mix(scene, fog, 1 - exp(-density * t)) within 2/255 (dither on) */
    for (i = 0; i < W * H; ++i) {
        double a = 1.0 - exp(-(double)s->density * (gt[i] > 0 ? gt[i] : 0)), worst = 0;
        int c;
        if (!interior[i] || gt[i] <= 0) continue;
        for (c = 0; c < 3; ++c) {
            double want = g_scene_rgb[c] + (g_fog_rgb[c] - g_scene_rgb[c]) * a;
            double got = f1.pixels[4 * i + c] / 255.0, d = fabs(got - want);
            if (d > worst) worst = d;
        }
        if (worst > max_comp) max_comp = worst;
    }
    /* geometry composite (stencil guard: one blend per pixel) gives the same picture */
    {
        int diff = 0;
        for (i = 0; i < W * H * 4; ++i)
            if (abs((int)fg.pixels[i] - (int)f1.pixels[i]) > 0) ++diff;
        print_message("  %s/%s: geometry vs full-screen composite: %d differing bytes\n", s->name, profile, diff);
        assert_int_equal(diff, 0);
    }

    /* dithering is really on in f1: its per-pixel values differ from the rounded ones
       on a large share of the covered pixels (the block means above stay unbiased) */
    {
        int differ = 0;
        for (i = 0; i < W * H; ++i) differ += covered[i] && interior[i] && f1.thick[i] != f0.thick[i];
        print_message("  %s/%s: dithered differs from rounded on %d of %d covered pixels\n", s->name, profile, differ,
                      ninterior);
        assert_true(differ * 10 > ninterior); /* about 1/4 per face (E|p - 1/2|); 0 with dithering off */
    }
    st->max_err = max_err;
    st->mean_abs = ninterior ? sum_abs / ninterior : 0;
    st->mean_per_pair = ninterior ? sum_pp / ninterior : 0;
    st->block_max = block_max;
    st->max_comp = max_comp * 255.0;
    st->interior = ninterior;
    st->max_faces = max_faces;
    print_message("  %-24s %-6s L=%d covered %5d max faces %2d | no dither: max %.3f LSB mean %.3f LSB "
                  "(%.3f per pair) | dither 8x8 max |mean| %.3f LSB per pair | composite max %.2f/255\n",
                  s->name, profile, s->bits, ninterior, max_faces, max_err, st->mean_abs, st->mean_per_pair,
                  block_max, st->max_comp);
    write_png(s->name, profile, &f1, gt, interior, lsb, tmax > 0 ? tmax : 1);
    assert_true(ninterior > 200);
    assert_int_equal(bad, 0);
    assert_true(st->mean_per_pair <= 0.5); /* the raw mean when every ray crosses one pair */
    assert_true(block_max <= 0.25);
    assert_true(max_comp <= 2.0 / 255.0);

cleanup:
    teardown(s, &g, fv, meshes, ramp);
    free(gt);
    free(slope);
    free(fl);
    free(pairs);
    free(interior);
    free(covered);
    free(f0.thick);
    free(f1.thick);
    free(fg.thick);
    free(f0.pixels);
    free(f1.pixels);
    free(fg.pixels);
}

/* The engine draws the occluder itself, from its own VAO and element buffer,
   inside fogvol's O pass. */
typedef struct engine_occluder {
    GLuint vao, vbo, ibo;
    GLsizei count;
    const float *model;
    int calls;
} engine_occluder;

static void draw_engine_occluder(fogvol_context *fv, void *user)
{
    engine_occluder *eo = (engine_occluder *)user;
    eo->calls++;
    assert_int_equal(fogvol_occluder_transform(fv, eo->model), FOGVOL_SUCCESS);
    glBindVertexArray(eo->vao);
    glDrawElements(GL_TRIANGLES, eo->count, GL_UNSIGNED_INT, NULL);
}

/* Occluders through the engine callback give the same thickness, bit for bit,
   as the same occluder mesh handed to fogvol; and the light blend adds
   colour * (1 - exp(-density * t)) to the scene within 2/255. */
static void test_callback_and_light(void **state)
{
    const tscene *s = &g_scenes[scene_index("plane_cuts_sphere")];
    glu_ctx g;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp *ramp;
    frame_out a, b;
    engine_occluder eo;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    double *gt = (double *)calloc((size_t)W * H, sizeof(double)), tmax, worst = 0;
    int *pairs = (int *)calloc((size_t)W * H, sizeof(int)), i, max_faces, n = 0, diff = 0, occ = -1, vol = -1;
    unsigned char *interior = (unsigned char *)calloc((size_t)W * H, 1);
    unsigned char *covered = (unsigned char *)calloc((size_t)W * H, 1);
    (void)state;
    a.thick = (float *)calloc((size_t)W * H, sizeof(float));
    b.thick = (float *)calloc((size_t)W * H, sizeof(float));
    a.pixels = (unsigned char *)malloc((size_t)W * H * 4);
    b.pixels = (unsigned char *)malloc((size_t)W * H * 4);
    ground_truth(s, gt, pairs, interior, covered, &max_faces, &tmax, NULL);
    setup(s, 1, FOGVOL_BLEND_LIGHT, &g, &fv, meshes, &ramp);
    render(fv, s, meshes, ramp, 1, FOGVOL_COMPOSITE_FULLSCREEN, 0, &g, &a);
    assert_int_equal(a.result, FOGVOL_SUCCESS);

    for (i = 0; i < s->n; ++i) {
        if (s->obj[i].sign == 0) occ = i;
        else vol = i;
    }
    memset(&eo, 0, sizeof eo);
    eo.model = s->obj[occ].model;
    eo.count = s->obj[occ].mesh.icount;
    glGenVertexArrays(1, &eo.vao);
    glBindVertexArray(eo.vao);
    glGenBuffers(1, &eo.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, eo.vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * (size_t)s->obj[occ].mesh.vcount),
                 s->obj[occ].mesh.pos, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
    glEnableVertexAttribArray(0);
    glGenBuffers(1, &eo.ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, eo.ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(unsigned) * (size_t)eo.count), s->obj[occ].mesh.idx,
                 GL_STATIC_DRAW);
    glBindVertexArray(0);

    fx_frame_desc(&fd, &s->cam, W, H);
    fd.debug_thickness = b.thick;
    glClearColor(g_scene_rgb[0], g_scene_rgb[1], g_scene_rgb[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder_callback(fv, draw_engine_occluder, &eo), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = meshes[vol];
    vd.ramp = ramp;
    memcpy(vd.model, s->obj[vol].model, sizeof vd.model);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    memcpy(b.pixels, glu_pixels(&g), (size_t)W * H * 4);
    assert_int_equal(eo.calls, 1);
    assert_int_equal(fogvol_occluder_transform(fv, eo.model), FOGVOL_ERROR_INVALID_STATE); /* outside the pass */

    for (i = 0; i < W * H; ++i) diff += a.thick[i] != b.thick[i];
    for (i = 0; i < W * H; ++i) {
        double al;
        int c;
        if (!interior[i] || !covered[i]) continue;
        al = 1.0 - exp(-(double)s->density * (gt[i] > 0 ? gt[i] : 0));
        for (c = 0; c < 3; ++c) {
            double want = g_scene_rgb[c] + g_fog_rgb[c] * al, got = a.pixels[4 * i + c] / 255.0;
            if (want > 1) want = 1;
            if (fabs(got - want) > worst) worst = fabs(got - want);
        }
        ++n;
    }
    print_message("  engine-callback occluder: %d pixels differ from the fogvol-mesh occluder; "
                  "light blend over %d pixels: max error %.2f/255\n", diff, n, worst * 255);
    assert_int_equal(diff, 0);
    assert_true(n > 1000);
    assert_true(worst <= 2.0 / 255.0);
    glDeleteBuffers(1, &eo.vbo);
    glDeleteBuffers(1, &eo.ibo);
    glDeleteVertexArrays(1, &eo.vao);
    teardown(s, &g, fv, meshes, ramp);
    free(gt);
    free(pairs);
    free(interior);
    free(covered);
    free(a.thick);
    free(b.thick);
    free(a.pixels);
    free(b.pixels);
}

int main(void)
{
    static tcase cases[40];
    static struct CMUnitTest tests[40]; /* zeroed: the unused entries are skipped */
    char names[40][64];
    int i, n = 0, rc;
    build_scenes();
    for (i = 0; i < g_nscenes; ++i) {
        int core;
        for (core = 1; core >= 0; --core) {
            cases[n].scene = i;
            cases[n].core = core;
            snprintf(names[n], sizeof names[n], "%s_%s", g_scenes[i].name, core ? "core33" : "gl21");
            memset(&tests[n], 0, sizeof tests[n]);
            tests[n].name = names[n];
            tests[n].test_func = run_case;
            tests[n].initial_state = &cases[n];
            ++n;
        }
    }
    memset(&tests[n], 0, sizeof tests[n]);
    tests[n].name = "callback_occluder_and_light_blend";
    tests[n].test_func = test_callback_and_light;
    ++n;
    rc = cmocka_run_group_tests_name("render", tests, NULL, NULL);
    free_scenes();
    return rc;
}
