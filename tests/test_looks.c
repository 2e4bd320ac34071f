/* test_looks.c - fog that looks like fog: soft edges (fogvol_ramp_desc.softness), fading light shafts
   (softness with a density texture along the shaft) and the dither's frame index
   (fogvol_frame_desc.dither_frame), under OSMesa against CPU references written here:
   - soft edges: per pixel the chords of the drawn triangles are ray-cast (tests/raycast.h, the
     opaque floor cutting them included), the density model of the header (rising linearly over s
     from both ends of every chord) is integrated numerically along each chord (midpoint rule,
     4000 steps; not the closed form f the composite uses), and the composite is
     mix(scene, fog, 1 - exp(-density * optical thickness)). A convex volume must match within
     1/255 on the FLOAT tier and 2/255 on the RGBA8 tiers (their thickness is 1 LSB per pair of
     faces off); a concave volume and two overlapping volumes of one ramp get f(sum of chords)
     instead of sum f(chord): the header says it is denser by at most (k - 1) s of thickness for k
     chords, measured here. Hard edges (softness 0) differ from the soft model by much more.
   - a light shaft: a cylinder of a LIGHT ramp with softness and a density gradient along its axis
     (a 1D texture, linear, clamped): against numeric integration of the gradient along each
     chord, within the two-point rule's bound the header states for density textures.
   - the dither's frame index: the decoded thickness of a PS20 frame (L = 4, dithered) averaged
     over 4 and 8 frames with dither_frame 1..8, per 8x8 block against the FLOAT tier's thickness
     of the same frame; frame index 0 keeps today's fixed pattern (byte-equal frames).
   Pictures: build/looks/<name>.png. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include "tests/raycast.h"
#include "tests/shapes.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define LW 128
#define LH 128
#define MAXV 4

/* (bytes: the scene is cleared to exactly these values) */
static const float g_scene[3] = {64 / 255.0f, 77 / 255.0f, 89 / 255.0f}, g_fog[3] = {217 / 255.0f, 222 / 255.0f, 230 / 255.0f};

static void logger(void *user, fogvol_log_level level, const char *msg)
{
    (void)user;
    if (level <= FOGVOL_LOG_WARNING) print_message("# [fogvol] %s\n", msg);
}

static void save_png(const char *name, const unsigned char *rgba, int w, int h)
{
    char path[256];
    mkdir("build", 0755);
    mkdir("build/looks", 0755);
    snprintf(path, sizeof path, "build/looks/%s.png", name);
    stbi_flip_vertically_on_write(1);
    stbi_write_png(path, w, h, 4, rgba, w * 4);
}

/* A scene of up to MAXV volumes of one ramp (and an optional opaque floor), its camera. */
typedef struct lscene {
    const char *name;
    rc_camera cam;
    shp_mesh mesh[MAXV];
    float model[MAXV][16];
    int nvol;
    int floor;        /* 1: an opaque slab with its top at floor_y cuts the volumes */
    float floor_y;
    shp_mesh floor_mesh;
    float floor_model[16];
} lscene;

static void scene_camera(lscene *s, double ex, double ey, double ez)
{
    s->cam.eye[0] = ex;
    s->cam.eye[1] = ey;
    s->cam.eye[2] = ez;
    s->cam.target[0] = s->cam.target[1] = s->cam.target[2] = 0.0;
    s->cam.up[1] = 1.0;
    s->cam.fovy_deg = 45.0;
    s->cam.aspect = 1.0;
    s->cam.znear = 0.5;
    s->cam.zfar = 12.0;
    s->cam.width = LW;
    s->cam.height = LH;
}

static void scene_floor(lscene *s, float y)
{
    s->floor = 1;
    s->floor_y = y;
    s->floor_mesh = shp_box(4.0f, 0.05f, 4.0f);
    shp_mat_translate(s->floor_model, 0.0f, y - 0.05f, 0.0f);
}

static void scene_free(lscene *s)
{
    int i;
    for (i = 0; i < s->nvol; ++i) shp_free(&s->mesh[i]);
    if (s->floor) shp_free(&s->floor_mesh);
}

/* convex: a sphere cut by the floor; concave: a torus seen at an angle (rays cross its tube twice);
   overlap: two spheres of one ramp overlapping on screen and in space */
static void build(lscene *s, int kind)
{
    memset(s, 0, sizeof *s);
    if (kind == 0) {
        s->name = "convex";
        scene_camera(s, 0.4, 1.1, 4.2);
        s->mesh[0] = shp_sphere(1.0f, 96, 48);
        shp_mat_identity(s->model[0]);
        s->nvol = 1;
        scene_floor(s, -0.45f);
    } else if (kind == 1) {
        float r[16], t[16];
        s->name = "concave";
        scene_camera(s, 0.2, 0.6, 4.4);
        s->mesh[0] = shp_torus(1.0f, 0.4f, 96, 32);
        shp_mat_rotate(r, 78.0f, 1.0f, 0.0f, 0.0f);
        shp_mat_translate(t, 0.0f, 0.1f, 0.0f);
        shp_mat_mul(s->model[0], t, r);
        s->nvol = 1;
    } else {
        s->name = "overlap";
        scene_camera(s, 0.0, 0.5, 4.6);
        s->mesh[0] = shp_sphere(0.8f, 64, 32);
        s->mesh[1] = shp_sphere(0.7f, 64, 32);
        shp_mat_translate(s->model[0], -0.45f, 0.0f, -0.3f);
        shp_mat_translate(s->model[1], 0.5f, 0.15f, 0.35f);
        s->nvol = 2;
    }
}

static int scene_objects(const lscene *s, rc_object *o)
{
    int i, n = 0;
    for (i = 0; i < s->nvol; ++i, ++n) {
        memset(&o[n], 0, sizeof o[n]);
        o[n].pos = s->mesh[i].pos;
        o[n].vcount = s->mesh[i].vcount;
        o[n].idx = s->mesh[i].idx;
        o[n].icount = s->mesh[i].icount;
        memcpy(o[n].model, s->model[i], sizeof o[n].model);
        o[n].sign = 1;
    }
    if (s->floor) {
        memset(&o[n], 0, sizeof o[n]);
        o[n].pos = s->floor_mesh.pos;
        o[n].vcount = s->floor_mesh.vcount;
        o[n].idx = s->floor_mesh.idx;
        o[n].icount = s->floor_mesh.icount;
        memcpy(o[n].model, s->floor_model, sizeof o[n].model);
        o[n].sign = 0;
        ++n;
    }
    return n;
}

/* The optical thickness of one chord of length len under the model, by the midpoint rule over the
   density min(1, x / s, (len - x) / s) (not the closed form) */
static double soft_chord(double len, double s)
{
    const int n = 4000;
    double sum = 0.0, h = len / n;
    int i;
    if (s <= 0.0) return len;
    for (i = 0; i < n; ++i) {
        double x = (i + 0.5) * h, r = fmin(1.0, fmin(x / s, (len - x) / s));
        sum += r * h;
    }
    return sum;
}

/* Per pixel: the model's optical thickness (sum over chords), the summed chord length, the chord
   count and whether the pixel is interior (rc_interior). */
typedef struct lref {
    double *model, *sum;
    int *chords;
    unsigned char *interior;
} lref;

static void reference(const lscene *s, double soft, lref *r)
{
    rc_object o[MAXV + 1];
    rc_scene sc;
    int n = scene_objects(s, o), px, py;
    r->model = (double *)calloc(LW * LH, sizeof(double));
    r->sum = (double *)calloc(LW * LH, sizeof(double));
    r->chords = (int *)calloc(LW * LH, sizeof(int));
    r->interior = (unsigned char *)calloc(LW * LH, 1);
    assert_true(r->model && r->sum && r->chords && r->interior);
    assert_true(rc_scene_init(&sc, o, n));
    for (py = 0; py < LH; ++py)
        for (px = 0; px < LW; ++px) {
            double ab[32];
            int k = py * LW + px, c, nc = rc_chords(&sc, &s->cam, px + 0.5, py + 0.5, ab, NULL, 16);
            assert_true(nc >= 0);
            for (c = 0; c < nc; ++c) {
                r->model[k] += soft_chord(ab[2 * c + 1] - ab[2 * c], soft);
                r->sum[k] += ab[2 * c + 1] - ab[2 * c];
            }
            r->chords[k] = nc;
            r->interior[k] = (unsigned char)rc_interior(&sc, &s->cam, px, py);
        }
    rc_scene_free(&sc);
}

static void ref_free(lref *r)
{
    free(r->model);
    free(r->sum);
    free(r->chords);
    free(r->interior);
}

static double fog_channel(int c, double tau) { return g_scene[c] + (g_fog[c] - g_scene[c]) * (1.0 - exp(-tau)); }

/* The engine's framebuffer: the default one (RGBA8, llvmpipe blends in 8 bits) or, float_fb, an
   RGBA32F texture bound as the draw framebuffer (blending in float: what is left is fogvol's own
   error). pixels() reads it back as rgb in [0, 1] per pixel. */
typedef struct lfb {
    glu_ctx g;
    int float_fb;
    GLuint fbo, tex;
} lfb;

static void fb_open(lfb *f, int float_fb)
{
    memset(f, 0, sizeof *f);
    assert_true(glu_create(&f->g, LW, LH, 1));
    f->float_fb = float_fb;
    if (float_fb) {
        glGenTextures(1, &f->tex);
        glBindTexture(GL_TEXTURE_2D, f->tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, LW, LH, 0, GL_RGBA, GL_FLOAT, NULL);
        glBindTexture(GL_TEXTURE_2D, 0);
        glGenFramebuffers(1, &f->fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, f->tex, 0);
        assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    }
    glViewport(0, 0, LW, LH);
    glClearColor(g_scene[0], g_scene[1], g_scene[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
}

/* rgb in [0,1] (3 per pixel) and, for pictures, RGBA8 bytes */
static void fb_read(lfb *f, double *rgb, unsigned char *bytes)
{
    int k, c;
    if (f->float_fb) {
        float *fl = (float *)malloc(sizeof(float) * 4 * LW * LH);
        assert_non_null(fl);
        glFinish();
        glReadPixels(0, 0, LW, LH, GL_RGBA, GL_FLOAT, fl);
        for (k = 0; k < LW * LH; ++k)
            for (c = 0; c < 4; ++c) {
                double v = fl[4 * k + c] < 0 ? 0 : fl[4 * k + c] > 1 ? 1 : fl[4 * k + c];
                if (c < 3) rgb[3 * k + c] = fl[4 * k + c];
                bytes[4 * k + c] = (unsigned char)(v * 255.0 + 0.5);
            }
        free(fl);
        return;
    }
    memcpy(bytes, glu_pixels(&f->g), (size_t)LW * LH * 4);
    for (k = 0; k < LW * LH; ++k)
        for (c = 0; c < 3; ++c) rgb[3 * k + c] = bytes[4 * k + c] / 255.0;
}

static void fb_close(lfb *f)
{
    if (f->float_fb) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &f->fbo);
        glDeleteTextures(1, &f->tex);
    }
    glu_destroy(&f->g);
}

static fogvol_context *make_ctx(fogvol_tier tier, unsigned variants, int dither)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = tier;
    cd.variants = variants;
    cd.disable_dither = !dither;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    return fv;
}

static fogvol_mesh *make_mesh(fogvol_context *fv, const shp_mesh *sm)
{
    fogvol_mesh_desc md;
    fogvol_mesh *m = NULL;
    memset(&md, 0, sizeof md);
    md.positions = sm->pos;
    md.vertex_count = sm->vcount;
    md.indices = sm->idx;
    md.index_count = sm->icount;
    assert_int_equal(fogvol_create_mesh(fv, &md, &m, NULL), FOGVOL_SUCCESS);
    return m;
}

static void frame_desc(const rc_camera *cam, fogvol_frame_desc *fd)
{
    memset(fd, 0, sizeof *fd);
    rc_camera_matrices(cam, fd->view, fd->projection);
    fd->znear = (float)cam->znear;
    fd->zfar = (float)cam->zfar;
    fd->viewport[2] = LW;
    fd->viewport[3] = LH;
}

/* One frame of the scene with the fog ramp (density, softness) on a tier: rgb per pixel, bytes. */
static void render(const lscene *s, fogvol_tier tier, unsigned variants, float density, float soft, int float_fb,
                   double *rgb, unsigned char *bytes)
{
    lfb f;
    fogvol_context *fv;
    fogvol_mesh *m[MAXV + 1];
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    int i;
    fb_open(&f, float_fb);
    fv = make_ctx(tier, variants, 0);
    for (i = 0; i < s->nvol; ++i) m[i] = make_mesh(fv, &s->mesh[i]);
    if (s->floor) m[s->nvol] = make_mesh(fv, &s->floor_mesh);
    memset(&rd, 0, sizeof rd);
    memcpy(rd.color, g_fog, sizeof rd.color);
    rd.density = density;
    rd.softness = soft;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    frame_desc(&s->cam, &fd);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    if (s->floor) assert_int_equal(fogvol_add_occluder(fv, m[s->nvol], s->floor_model), FOGVOL_SUCCESS);
    for (i = 0; i < s->nvol; ++i) {
        memset(&vd, 0, sizeof vd);
        vd.mesh = m[i];
        vd.ramp = ramp;
        memcpy(vd.model, s->model[i], sizeof vd.model);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    fb_read(&f, rgb, bytes);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    fogvol_destroy_ramp(fv, ramp);
    for (i = 0; i < s->nvol + s->floor; ++i) fogvol_destroy_mesh(fv, m[i]);
    fogvol_destroy_context(fv);
    fb_close(&f);
}

/* max |GPU - expected| /255 over the pixels (interior only, or all), expected from tau per pixel */
static double max_err(const double *rgb, const double *tau, double density, const lref *r, int interior_only)
{
    double mx = 0.0;
    int k, c;
    for (k = 0; k < LW * LH; ++k) {
        if (interior_only && !r->interior[k]) continue;
        for (c = 0; c < 3; ++c) {
            double d = 255.0 * fabs(rgb[3 * k + c] - fog_channel(c, density * tau[k]));
            if (d > mx) mx = d;
        }
    }
    return mx;
}

#define SOFT 0.35
#define DENSITY 1.6

/* A convex volume: the composite against numeric integration of the model on every tier, in a
   float framebuffer (the bound: 1/255 on FLOAT, 2/255 on the RGBA8 tiers, whose thickness is 1 LSB
   per pair of faces off) and in the RGBA8 default framebuffer (llvmpipe's 8-bit blend rounds alpha
   and the result down: about 1.3/255 more, measured on hard edges against the uniform model too). */
static void test_soft_convex(void **state)
{
    static const struct {
        fogvol_tier tier;
        unsigned variants;
        const char *name;
        double bound;
    } tiers[] = {{FOGVOL_TIER_FLOAT, 0, "FLOAT", 1.0},
                 {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, "FLOAT+colors (own group)", 1.0},
                 {FOGVOL_TIER_PS20, 0, "PS20", 2.0},
                 {FOGVOL_TIER_PS13, 0, "PS13", 2.0},
                 {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_ALU, "PS20+single+alu", 2.0}};
    lscene s;
    lref r;
    unsigned char *px = (unsigned char *)malloc((size_t)LW * LH * 4), *side = (unsigned char *)malloc((size_t)LW * LH * 8);
    double *rgb = (double *)malloc(sizeof(double) * 3 * LW * LH), e_hard, e_hard_uniform, e8, e8_hard;
    int t, covered = 0, k, y;
    (void)state;
    assert_true(px && side && rgb);
    build(&s, 0);
    reference(&s, SOFT, &r);
    for (k = 0; k < LW * LH; ++k) covered += r.chords[k] > 0 && r.interior[k];
    assert_true(covered > 3000);
    for (k = 0; k < LW * LH; ++k) assert_true(r.chords[k] <= 1); /* convex: one chord a ray */
    for (t = 0; t < (int)(sizeof tiers / sizeof tiers[0]); ++t) {
        double e_int, e_all;
        render(&s, tiers[t].tier, tiers[t].variants, (float)DENSITY, (float)SOFT, 1, rgb, px);
        e_int = max_err(rgb, r.model, DENSITY, &r, 1);
        e_all = max_err(rgb, r.model, DENSITY, &r, 0);
        print_message("# soft edges, convex (s = %.2f, density %.1f), %s, float framebuffer: max |composite - "
                      "model| %.2f/255 over %d interior pixels, %.2f/255 over every pixel (silhouettes "
                      "included)\n", SOFT, DENSITY, tiers[t].name, e_int, covered, e_all);
        assert_true(e_int <= tiers[t].bound);
        if (t == 0) {
            assert_true(e_all <= tiers[t].bound); /* soft silhouettes: no pixel band to exclude */
            for (y = 0; y < LH; ++y) memcpy(side + ((size_t)y * 2 * LW + LW) * 4, px + (size_t)y * LW * 4, LW * 4);
        }
    }
    /* softness 0: the old hard-edged picture, exact for the uniform model, far from the soft one */
    render(&s, FOGVOL_TIER_FLOAT, 0, (float)DENSITY, 0.0f, 1, rgb, px);
    for (y = 0; y < LH; ++y) memcpy(side + (size_t)y * 2 * LW * 4, px + (size_t)y * LW * 4, LW * 4);
    save_png("soft_convex_hard_soft", side, 2 * LW, LH);
    e_hard = max_err(rgb, r.model, DENSITY, &r, 1);
    e_hard_uniform = max_err(rgb, r.sum, DENSITY, &r, 1);
    /* the RGBA8 framebuffer: the same within the 8-bit blend's rounding, soft and hard alike */
    render(&s, FOGVOL_TIER_FLOAT, 0, (float)DENSITY, (float)SOFT, 0, rgb, px);
    e8 = max_err(rgb, r.model, DENSITY, &r, 1);
    render(&s, FOGVOL_TIER_FLOAT, 0, (float)DENSITY, 0.0f, 0, rgb, px);
    e8_hard = max_err(rgb, r.sum, DENSITY, &r, 1);
    print_message("# soft edges, convex: softness 0 against the soft model: max %.1f/255 (against the uniform "
                  "model: %.2f/255); RGBA8 framebuffer, FLOAT tier: soft %.2f/255 from the soft model, hard "
                  "%.2f/255 from the uniform model\n", e_hard, e_hard_uniform, e8, e8_hard);
    assert_true(e_hard > 30.0);
    assert_true(e_hard_uniform <= 1.0);
    assert_true(e8 <= 2.0 && e8_hard <= 2.0);
    ref_free(&r);
    scene_free(&s);
    free(px);
    free(side);
    free(rgb);
}

/* Concave and overlapping volumes: f(sum) instead of sum f, denser by at most (k - 1) s of thickness. */
static void test_soft_concave_overlap(void **state)
{
    int kind;
    (void)state;
    for (kind = 1; kind <= 2; ++kind) {
        lscene s;
        lref r;
        unsigned char *px = (unsigned char *)malloc((size_t)LW * LH * 4);
        double *rgb = (double *)malloc(sizeof(double) * 3 * LW * LH);
        double e_one = 0.0, e_multi = 0.0, sum_multi = 0.0, worst_excess = 0.0;
        int k, c, multi = 0, outside = 0;
        assert_true(px && rgb);
        build(&s, kind);
        reference(&s, SOFT, &r);
        render(&s, FOGVOL_TIER_FLOAT, 0, (float)DENSITY, (float)SOFT, 1, rgb, px);
        for (k = 0; k < LW * LH; ++k) {
            double hi_tau, dk = 0.0, f_sum;
            if (!r.interior[k]) continue;
            /* what f(sum) exceeds the model by (f's closed form here only to measure that) */
            f_sum = r.sum[k] < 2 * SOFT ? r.sum[k] * r.sum[k] / (4 * SOFT) : r.sum[k] - SOFT;
            if (f_sum - r.model[k] > worst_excess) worst_excess = f_sum - r.model[k];
            hi_tau = r.model[k] + (r.chords[k] > 1 ? (r.chords[k] - 1) * SOFT : 0.0);
            for (c = 0; c < 3; ++c) {
                double got = 255.0 * rgb[3 * k + c], want = 255.0 * fog_channel(c, DENSITY * r.model[k]);
                double hi = 255.0 * fog_channel(c, DENSITY * hi_tau);
                dk = fmax(dk, fabs(got - want));
                if (got < fmin(want, hi) - 1.0 || got > fmax(want, hi) + 1.0) ++outside;
            }
            if (r.chords[k] > 1) {
                ++multi;
                sum_multi += dk;
                if (dk > e_multi) e_multi = dk;
            } else if (dk > e_one) {
                e_one = dk;
            }
        }
        print_message("# soft edges, %s (s = %.2f, float framebuffer): one chord: max %.2f/255 from the model; %d "
                      "interior pixels cross 2 or more chords: max %.1f/255, mean %.1f/255 from the per-chord "
                      "model (f(sum) - sum f up to %.3f of thickness; the header's bound (k - 1) s = %.2f for k = "
                      "2); %d channel values outside [model, model + (k - 1) s] +- 1/255\n",
                      s.name, SOFT, e_one, multi, e_multi, multi ? sum_multi / multi : 0.0, worst_excess, SOFT,
                      outside);
        save_png(s.name, px, LW, LH);
        assert_true(multi > 300);
        assert_true(e_one <= 1.0);
        assert_int_equal(outside, 0);
        assert_true(worst_excess <= SOFT + 1e-9);
        ref_free(&r);
        scene_free(&s);
        free(px);
        free(rgb);
    }
}

/* ---- a light shaft: softness across it, a density texture along it ----------------------------- */
#define SHAFT_R 0.35
#define SHAFT_HY 1.6
#define SHAFT_TILT 20.0 /* degrees about z */
#define SHAFT_SOFT 0.25
#define SHAFT_DENSITY 1.4
#define SHAFT_TEX 16
static const float g_beam[3] = {1.0f, 0.85f, 0.55f};

/* the texels: full at the top of the shaft, fading to nothing at its base */
static unsigned char shaft_texel(int i)
{
    double u = (i + 0.5) / SHAFT_TEX;
    return (unsigned char)floor(255.0 * u * u * (3.0 - 2.0 * u) + 0.5);
}

/* the density factor at texture coordinate u as GL filters the texture (linear, clamped) */
static double shaft_rho(double u)
{
    double x = u * SHAFT_TEX - 0.5, f;
    int i;
    if (x < 0) x = 0;
    if (x > SHAFT_TEX - 1) x = SHAFT_TEX - 1;
    i = (int)floor(x);
    if (i > SHAFT_TEX - 2) i = SHAFT_TEX - 2;
    f = x - i;
    return (shaft_texel(i) + (shaft_texel(i + 1) - shaft_texel(i)) * f) / 255.0;
}

static void shaft_model(float m[16])
{
    float r[16], t[16];
    shp_mat_rotate(r, (float)SHAFT_TILT, 0.0f, 0.0f, 1.0f);
    shp_mat_translate(t, 0.1f, 0.2f, 0.0f);
    shp_mat_mul(m, t, r);
}

/* texture coordinate u = (model y + hy) / (2 hy) of world point p (the inverse of shaft_model) */
static double shaft_u(const double p[3])
{
    double a = SHAFT_TILT * 3.14159265358979 / 180.0, x = p[0] - 0.1, y = p[1] - 0.2;
    double my = -sin(a) * x + cos(a) * y;
    return (my + SHAFT_HY) / (2.0 * SHAFT_HY);
}

/* One frame of the shaft (soft: softness and the density texture; else a plain hard volume) over
   the scene colour, a floor cutting its base; rgb per pixel and bytes. */
static void render_shaft(const lscene *s, int soft, double *rgb, unsigned char *bytes)
{
    lfb f;
    fogvol_context *fv;
    fogvol_mesh *m, *fl;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_texture_desc td;
    fogvol_volume_texture *tex;
    unsigned char tx[SHAFT_TEX * 4];
    int i;
    fb_open(&f, 1);
    fv = make_ctx(FOGVOL_TIER_FLOAT, 0, 0);
    m = make_mesh(fv, &s->mesh[0]);
    fl = make_mesh(fv, &s->floor_mesh);
    for (i = 0; i < SHAFT_TEX; ++i) {
        tx[4 * i] = shaft_texel(i);
        tx[4 * i + 1] = tx[4 * i + 2] = 0;
        tx[4 * i + 3] = 255;
    }
    memset(&td, 0, sizeof td);
    td.width = SHAFT_TEX;
    td.height = 1;
    td.pixels = tx;
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = FOGVOL_WRAP_CLAMP;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &tex), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    memcpy(rd.color, g_beam, sizeof rd.color);
    rd.density = (float)SHAFT_DENSITY;
    rd.blend = FOGVOL_BLEND_LIGHT;
    rd.softness = soft ? (float)SHAFT_SOFT : 0.0f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    frame_desc(&s->cam, &fd);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, fl, s->floor_model), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = m;
    vd.ramp = ramp;
    memcpy(vd.model, s->model[0], sizeof vd.model);
    if (soft) { /* s = (y + hy) / (2 hy) along the axis */
        vd.density = tex;
        vd.density_map[1] = (float)(1.0 / (2.0 * SHAFT_HY));
        vd.density_map[3] = 0.5f;
        vd.density_map[7] = 0.5f;
    }
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    fb_read(&f, rgb, bytes);
    fogvol_destroy_volume_texture(fv, tex);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, m);
    fogvol_destroy_mesh(fv, fl);
    fogvol_destroy_context(fv);
    fb_close(&f);
}

/* f of the model's soft edge (closed form: only to turn a thickness bound into a colour bound) */
static double soft_f(double t, double s) { return t <= 0 ? 0 : t < 2 * s ? t * t / (4 * s) : t - s; }

/* The shaft against numeric integration along each chord of its density factor (the texture as
   filtered), softened: scene + beam * (1 - exp(-density f(integral))); within what the density
   texture's two-point rule may add (the header: contrast along the chord * (|a - c| + |b - c|)). */
static void test_shaft(void **state)
{
    lscene s;
    rc_object o[2];
    rc_scene sc;
    unsigned char *px = (unsigned char *)malloc((size_t)LW * LH * 4), *side = (unsigned char *)malloc((size_t)LW * LH * 8);
    double *rgb = (double *)malloc(sizeof(double) * 3 * LW * LH), cdepth = 0.0, e_max = 0.0, e_over = 0.0;
    double worst_ratio = 0.0;
    int k, c, y, covered = 0, corner;
    (void)state;
    assert_true(px && side && rgb);
    memset(&s, 0, sizeof s);
    s.name = "shaft";
    scene_camera(&s, 0.0, 0.4, 4.6);
    s.mesh[0] = shp_cylinder((float)SHAFT_R, (float)SHAFT_HY, 64);
    shaft_model(s.model[0]);
    s.nvol = 1;
    scene_floor(&s, -1.1f);
    assert_int_equal(scene_objects(&s, o), 2);
    assert_true(rc_scene_init(&sc, o, 2));
    /* c: the view depth of the centre of the mesh's bounds (the mean of its 8 corners') */
    for (corner = 0; corner < 8; ++corner) {
        double p[3] = {corner & 1 ? SHAFT_R : -SHAFT_R, corner & 2 ? SHAFT_HY : -SHAFT_HY, corner & 4 ? SHAFT_R : -SHAFT_R};
        double w[3], f[3], sd[3], u[3];
        int j;
        for (j = 0; j < 3; ++j)
            w[j] = s.model[0][j] * p[0] + s.model[0][4 + j] * p[1] + s.model[0][8 + j] * p[2] + s.model[0][12 + j];
        rc_camera_basis(&s.cam, f, sd, u);
        cdepth += ((w[0] - s.cam.eye[0]) * f[0] + (w[1] - s.cam.eye[1]) * f[1] + (w[2] - s.cam.eye[2]) * f[2]) / 8.0;
    }
    render_shaft(&s, 1, rgb, px);
    for (k = 0; k < LW * LH; ++k) {
        double ab[8], org[3], dir[3], tau = 0.0, slack = 0.0;
        int nc = rc_chords(&sc, &s.cam, k % LW + 0.5, k / LW + 0.5, ab, NULL, 4), ch;
        rc_result rr = rc_trace(&sc, &s.cam, k % LW + 0.5, k / LW + 0.5);
        assert_true(nc >= 0 && nc <= 1);
        rc_camera_ray(&s.cam, k % LW + 0.5, k / LW + 0.5, org, dir);
        for (ch = 0; ch < nc; ++ch) {
            double a = ab[0], b = ab[1], sum = 0.0, lo = 1.0, hi = 0.0, cc = fmin(rr.opaque_w, cdepth);
            int i, n = 2000;
            for (i = 0; i < n; ++i) {
                double w = a + (b - a) * (i + 0.5) / n, p[3], r;
                int j;
                for (j = 0; j < 3; ++j) p[j] = org[j] + w * dir[j];
                r = shaft_rho(shaft_u(p));
                sum += r * (b - a) / n;
                lo = fmin(lo, r);
                hi = fmax(hi, r);
            }
            tau += sum;
            slack += (hi - lo) * (fabs(a - cc) + fabs(b - cc));
        }
        if (nc) ++covered;
        for (c = 0; c < 3; ++c) {
            double want = g_scene[c] + g_beam[c] * (1.0 - exp(-SHAFT_DENSITY * soft_f(tau, SHAFT_SOFT)));
            double lo = g_scene[c] + g_beam[c] * (1.0 - exp(-SHAFT_DENSITY * soft_f(fmax(tau - slack, 0.0), SHAFT_SOFT)));
            double hi = g_scene[c] + g_beam[c] * (1.0 - exp(-SHAFT_DENSITY * soft_f(tau + slack, SHAFT_SOFT)));
            double d = 255.0 * fabs(rgb[3 * k + c] - want), allow = 255.0 * fmax(hi - want, want - lo) + 1.0;
            e_max = fmax(e_max, d);
            if (d - allow > e_over) e_over = d - allow;
            if (d / allow > worst_ratio) worst_ratio = d / allow;
        }
    }
    for (y = 0; y < LH; ++y) memcpy(side + ((size_t)y * 2 * LW + LW) * 4, px + (size_t)y * LW * 4, LW * 4);
    render_shaft(&s, 0, rgb, px);
    for (y = 0; y < LH; ++y) memcpy(side + (size_t)y * 2 * LW * 4, px + (size_t)y * LW * 4, LW * 4);
    save_png("shaft_hard_soft", side, 2 * LW, LH);
    print_message("# light shaft (FLOAT, float framebuffer, softness %.2f, density texture along the axis): %d "
                  "pixels covered; max |composite - model| %.2f/255 over every pixel; worst error / (two-point "
                  "rule's bound + 1/255) %.3f\n", SHAFT_SOFT, covered, e_max, worst_ratio);
    assert_true(covered > 2000);
    assert_true(worst_ratio <= 1.0);
    rc_scene_free(&sc);
    scene_free(&s);
    free(px);
    free(side);
    free(rgb);
}

/* ---- the dither's frame index --------------------------------------------------------------------- */

/* The header's rule, written here: frame n rotates the rounding threshold of dither row r,
   k = (r + D/2) mod D, by bitrev3(n mod 8) / 8 of an LSB, i.e. k + bitrev3(n mod 8) D / 8 (mod D). The
   rows come from fogvol_make_dither_index (today's 8x8 pattern). */
static int g_rows[8][8];
static int dither_k(const fogvol_encoding *e, int px, int py, int frame)
{
    int d = e->dither_steps, n = frame & 7, rev = ((n & 1) << 2) | (n & 2) | (n >> 2);
    return (g_rows[py & 7][px & 7] + d / 2 + rev * d / 8) % d;
}

/* A face's error (LSB) at depth x (LSB units): the blue ramp's texel floor(x D), then the threshold k/D
   (white paper: V = floor(Q + k / D), Q the texel's value). */
static double face_err(const fogvol_encoding *e, double x, int k)
{
    double dd = e->dither_steps;
    return floor((floor(x * dd) + k) / dd) - x;
}

/* The 8x8 block mean error of a pair of faces (B - F) on linear depth gradients b = r0 + r1 x + r2 y,
   f = r3 + r4 x + r5 y (LSB units, pixels of the block at (bx, by)), averaged over frames f0 .. f0+nf-1. */
static double pair_block(const fogvol_encoding *e, const double *r, int bx, int by, int f0, int nf, int pair)
{
    double sum = 0.0;
    int f, i, j;
    for (f = f0; f < f0 + nf; ++f)
        for (j = 0; j < 8; ++j)
            for (i = 0; i < 8; ++i) {
                int k = dither_k(e, bx + i, by + j, f);
                double xb = r[0] + r[1] * (bx + i) + r[2] * (by + j), xf = r[3] + r[4] * (bx + i) + r[5] * (by + j);
                sum += face_err(e, xb, k) - (pair ? face_err(e, xf, k) : 0.0);
            }
    return sum / (64.0 * nf);
}

static double g_rng = 0.0;
static double rnd01(void) /* a fixed sequence (golden-ratio steps mixed by a sine hash): reproducible */
{
    g_rng += 1.0;
    return fmod(fabs(sin(g_rng * 12.9898 + 78.233) * 43758.5453), 1.0);
}

/* worst |block mean| over random gradients (slopes -2 .. 2 LSB per pixel, any offset, any block position),
   each found worst refined by local search; nf frames starting at a multiple of nf (nf = 8: any start) */
static double worst_block(const fogvol_encoding *e, int nf, int pair, int samples)
{
    double worst = 0.0;
    int n, i, it;
    g_rng = 0.0;
    for (n = 0; n < samples; ++n) {
        double r[6], best[6], v;
        int bx = (int)(rnd01() * 8), by = (int)(rnd01() * 8), f0 = (int)(rnd01() * 8);
        f0 = nf == 8 ? f0 : nf == 4 ? f0 & 4 : 0;
        for (i = 0; i < 6; ++i) r[i] = i == 0 || i == 3 ? rnd01() * 4.0 : rnd01() * 4.0 - 2.0;
        v = fabs(pair_block(e, r, bx, by, f0, nf, pair));
        if (v <= worst) continue;
        worst = v;
        memcpy(best, r, sizeof r);
        for (it = 0; it < 400; ++it) {
            double r2[6], v2;
            for (i = 0; i < 6; ++i) r2[i] = best[i] + (rnd01() - 0.5) * 0.02;
            v2 = fabs(pair_block(e, r2, bx, by, f0, nf, pair));
            if (v2 > worst) {
                worst = v2;
                memcpy(best, r2, sizeof r2);
            }
        }
    }
    return worst;
}

/* The sweep of issue 11 (the fixed pattern cannot bring the 8x8 block mean below ~0.25 LSB on every
   depth gradient) with the frame index: averaged over 4 and 8 frames. */
static void test_dither_sweep(void **state)
{
    fogvol_encoding e;
    unsigned char px[8 * 8 * 4];
    fogvol_image info;
    double w[2][3];
    int x, y, a, pair;
    static const int nfs[3] = {1, 4, 8};
    (void)state;
    assert_int_equal(fogvol_encoding_init(4, &e), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_make_dither_index(&e, px, sizeof px, &info), FOGVOL_SUCCESS);
    for (y = 0; y < 8; ++y)
        for (x = 0; x < 8; ++x) g_rows[y][x] = px[(y * 8 + x) * 4];
    /* the rule against the library's CPU encode: fogvol_encode_depth with the rotated row */
    for (a = 0; a < 2000; ++a) {
        double n3 = (double)e.levels * e.levels * e.levels, d = rnd01() * 0.9, got, want;
        int f = a % 8, kk = dither_k(&e, a % 8, a / 8 % 8, f), row = (kk - e.dither_steps / 2 + e.dither_steps) % e.dither_steps;
        unsigned char enc[4];
        assert_int_equal(fogvol_encode_depth(&e, d, row, enc), FOGVOL_SUCCESS);
        got = fogvol_decode(&e, enc) * n3; /* LSB units; the encode adds one LSB and its digits take it off */
        want = face_err(&e, d * n3 + 1.0, kk) + d * n3;
        if (fabs(got - want) > 1e-6) print_message("# d %.9f row %d k %d: decode %.6f, the rule %.6f LSB\n", d, row, kk, got, want);
        assert_true(fabs(got - want) < 1e-6);
    }
    for (pair = 0; pair < 2; ++pair)
        for (a = 0; a < 3; ++a) w[pair][a] = worst_block(&e, nfs[a], pair, nfs[a] == 1 ? 8000 : 16000);
    print_message("# dither frame index (L = 4, D = %d): worst |8x8 block mean| on depth gradients (slopes -2..2 "
                  "LSB/pixel, any offset and block position): one face %.3f / %.3f / %.3f LSB, a pair of faces "
                  "%.3f / %.3f / %.3f LSB for 1 / 4 / 8 frames (4: frames 4k .. 4k+3; 8: any 8 in a row)\n",
                  e.dither_steps, w[0][0], w[0][1], w[0][2], w[1][0], w[1][1], w[1][2]);
    assert_true(w[0][0] > 0.25);  /* one frame: the fixed pattern's bias (issue 11: 0.252 for Bayer) */
    assert_true(w[1][1] <= 0.1);  /* 4 frames */
    assert_true(w[1][2] <= 0.05); /* 8 frames: the target per pair of faces */
    assert_true(w[0][2] <= 0.05);
}

/* The GPU's dither over frames: a sphere and a tilted box (depth gradients in every direction) on the
   RGBA8 tiers with dithering on, dither_frame 1 .. 8; the decoded thickness averaged over 1, 4 (frames
   4 .. 7) and 8 frames against the FLOAT tier's thickness of the same frame, per fully covered 8x8
   block (one pair of faces a ray). */
static void dither_frames_case(fogvol_tier tier, unsigned variants, fogvol_dialect dialect, const char *name,
                               double *out)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv[2];
    fogvol_mesh *m[2];
    fogvol_ramp *ramp[2];
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    shp_mesh sm[2];
    float model[2][16], rot[16], tr[16];
    rc_camera cam;
    float *ref = (float *)calloc(LW * LH, sizeof(float)), *fr[10];
    double lsb = 1.0, worst[3] = {0, 0, 0};
    int i, c, f, bx, by, blocks = 0, differ = 0;
    assert_non_null(ref);
    for (f = 0; f < 10; ++f) assert_non_null(fr[f] = (float *)calloc(LW * LH, sizeof(float)));
    memset(&cam, 0, sizeof cam);
    cam.eye[0] = 0.3, cam.eye[1] = 0.9, cam.eye[2] = 5.0;
    cam.up[1] = 1.0;
    cam.fovy_deg = 45.0, cam.aspect = 1.0, cam.znear = 0.5, cam.zfar = 12.0, cam.width = LW, cam.height = LH;
    sm[0] = shp_sphere(0.9f, 64, 32);
    sm[1] = shp_box(0.6f, 0.7f, 0.5f);
    shp_mat_translate(model[0], -0.8f, 0.0f, 0.0f);
    shp_mat_rotate(rot, 35.0f, 0.4f, 1.0f, 0.3f);
    shp_mat_translate(tr, 1.0f, 0.1f, -0.2f);
    shp_mat_mul(model[1], tr, rot);
    assert_true(glu_create(&g, LW, LH, 1));
    for (c = 0; c < 2; ++c) { /* 0: FLOAT, the reference; 1: the tier under test, dithered */
        memset(&cd, 0, sizeof cd);
        cd.gl.get_proc_address = glu_proc;
        cd.gl.dialect = c ? dialect : FOGVOL_GLSL_AUTO;
        cd.logger.func = logger;
        cd.tier = c ? tier : FOGVOL_TIER_FLOAT;
        cd.variants = c ? variants : 0;
        cd.disable_speedups = FOGVOL_SPEEDUP_EXACT_SUM; /* the digit path (Mesa's framebuffer fetch sums exactly) */
        assert_int_equal(fogvol_create_context(&cd, &fv[c]), FOGVOL_SUCCESS);
        for (i = 0; i < 2; ++i) m[i] = make_mesh(fv[c], &sm[i]);
        memset(&rd, 0, sizeof rd);
        rd.density = 1.0f;
        memcpy(rd.color, g_fog, sizeof rd.color);
        assert_int_equal(fogvol_create_ramp(fv[c], &rd, &ramp[c]), FOGVOL_SUCCESS);
        for (f = 0; f < (c ? 10 : 1); ++f) { /* frames 1..8, then 0 twice */
            frame_desc(&cam, &fd);
            fd.debug_thickness = c ? fr[f] : ref;
            fd.dither_frame = f < 8 ? f + 1 : 0;
            assert_int_equal(fogvol_begin_frame(fv[c], &fd), FOGVOL_SUCCESS);
            for (i = 0; i < 2; ++i) {
                memset(&vd, 0, sizeof vd);
                vd.mesh = m[i];
                vd.ramp = ramp[c];
                memcpy(vd.model, model[i], sizeof vd.model);
                assert_int_equal(fogvol_add_volume(fv[c], &vd), FOGVOL_SUCCESS);
            }
            assert_int_equal(fogvol_end_frame(fv[c], NULL), FOGVOL_SUCCESS);
        }
        if (c) {
            const fogvol_encoding *e = fogvol_context_encoding(fv[c]);
            lsb = (cam.zfar - cam.znear) / ((double)e->levels * e->levels * e->levels);
        }
        fogvol_destroy_ramp(fv[c], ramp[c]);
        for (i = 0; i < 2; ++i) fogvol_destroy_mesh(fv[c], m[i]);
        fogvol_destroy_context(fv[c]);
    }
    for (by = 0; by + 8 <= LH; by += 8)
        for (bx = 0; bx + 8 <= LW; bx += 8) {
            double s1 = 0, s4 = 0, s8 = 0;
            int full = 1, x, y;
            for (y = by; y < by + 8; ++y)
                for (x = bx; x < bx + 8; ++x) {
                    int k = y * LW + x;
                    full &= ref[k] > 0.05f;
                    s1 += fr[0][k] - ref[k];
                    for (f = 0; f < 8; ++f) {
                        s8 += fr[f][k] - ref[k];
                        if (f >= 3 && f < 7) s4 += fr[f][k] - ref[k]; /* dither_frame 4 .. 7 */
                    }
                }
            if (!full) continue;
            ++blocks;
            worst[0] = fmax(worst[0], fabs(s1 / 64.0) / lsb);
            worst[1] = fmax(worst[1], fabs(s4 / 256.0) / lsb);
            worst[2] = fmax(worst[2], fabs(s8 / 512.0) / lsb);
        }
    for (i = 0; i < LW * LH; ++i) differ += fr[0][i] != fr[1][i];
    print_message("# dither frames (%s, L = 4): %d covered 8x8 blocks; worst |block mean - FLOAT| per pair of faces "
                  "%.3f / %.3f / %.3f LSB over 1 / 4 / 8 frames; frames 1 and 2 differ on %d pixels\n",
                  name, blocks, worst[0], worst[1], worst[2], differ);
    assert_true(blocks >= 20);
    assert_true(differ > 500); /* the pattern moves */
    assert_memory_equal(fr[8], fr[9], sizeof(float) * LW * LH); /* frame index 0: the fixed pattern */
    memcpy(out, worst, sizeof worst);
    assert_true(worst[1] <= 0.1 && worst[2] <= 0.05);
    for (f = 0; f < 10; ++f) free(fr[f]);
    free(ref);
    shp_free(&sm[0]);
    shp_free(&sm[1]);
    glu_destroy(&g);
}

static void test_dither_frames(void **state)
{
    double w[3];
    (void)state;
    dither_frames_case(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_AUTO, "PS20, ramp textures", w);
    dither_frames_case(FOGVOL_TIER_PS20, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_AUTO, "PS20 + ALU, integers", w);
    dither_frames_case(FOGVOL_TIER_PS20, FOGVOL_VARIANT_ALU, FOGVOL_GLSL_120, "PS20 + ALU, GLSL 120 floats", w);
    dither_frames_case(FOGVOL_TIER_PS13, 0, FOGVOL_GLSL_AUTO, "PS13", w);
}

/* Bad softness values are refused; a soft ramp keeps its own group under FOGVOL_VARIANT_COLORS. */
static void test_soft_refusals(void **state)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp = NULL;
    (void)state;
    assert_true(glu_create(&g, LW, LH, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.density = 1.0f;
    rd.softness = -0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.softness = (float)INFINITY;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.softness = (float)NAN;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(ramp);
    rd.softness = 0.25f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_soft_convex),
        cmocka_unit_test(test_soft_concave_overlap),
        cmocka_unit_test(test_shaft),
        cmocka_unit_test(test_dither_sweep),
        cmocka_unit_test(test_dither_frames),
        cmocka_unit_test(test_soft_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
