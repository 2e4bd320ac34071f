/* test_colors.c - FOGVOL_VARIANT_COLORS: per-volume colours and densities in one pass on the
   FLOAT tier, under OSMesa, against a CPU reference computed here: the thickness of every volume
   per pixel ray-cast from the drawn triangles (tests/raycast.h, one scene per volume) and
   Beer-Lambert per colour channel,
     tau_c = sum_i sigma_ic t_i,  E_c = sum_i sigma_ic t_i L_ic,  T_c = exp(-tau_c),
     colour_c = scene_c T_c + (E_c / tau_c) (1 - T_c),
   which is the exact radiative transfer for homogeneous volumes where at most one volume lies on
   a ray (and where overlapping volumes share a colour). Also against the per-ramp groups (one
   sum and one composite pass per ramp), and the pass counts on the null backend.
   Images: build/colors/<scene>.png = per-ramp | one pass | |difference| x 16. */
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

#define CW 160
#define CH 160
#define NV 16

static const float g_scene_rgb[3] = {0.20f, 0.30f, 0.45f};

static void logger(void *user, fogvol_log_level level, const char *msg)
{
    (void)user;
    if (level <= FOGVOL_LOG_WARNING) print_message("# [fogvol] %s\n", msg);
}

/* 16 volumes: colour, density and, for the coloured-extinction scene, an extinction colour */
typedef struct cscene {
    const char *name;
    rc_camera cam;
    float model[NV][16];
    float color[NV][3], ext[NV][3], density[NV];
    int coloured_ext; /* 1: extinction colours that are not grey */
    int overlap;      /* 1: rays cross two volumes of different colours */
    int opaque;       /* 1: every volume opaque (then the extinction's colour does not show) */
} cscene;

static void hsv(double h, float out[3])
{
    int c;
    for (c = 0; c < 3; ++c) {
        double k = fmod(5.0 - 2.0 * c + h * 6.0, 6.0), v = 1.0 - fmax(0.0, fmin(fmin(k, 4.0 - k), 1.0));
        out[c] = (float)(0.15 + 0.8 * v);
    }
}

/* non-overlapping: a 4x4 grid of spheres (radius 0.42, 1.0 apart, camera 6 away: no ray meets
   two); overlapping: two layers of 8, the back layer (volumes 0-7, added first) shifted by about
   half a sphere, 0.885 between the centres of neighbours (> 2 radii: the spheres themselves are
   disjoint, so a ray crosses the back one, then the front one, and compositing them back to front
   in volume order is the exact transfer) */
static void build_scene(cscene *s, const char *name, int overlap, int coloured_ext)
{
    int i;
    memset(s, 0, sizeof *s);
    s->name = name;
    s->overlap = overlap;
    s->coloured_ext = coloured_ext;
    s->cam.eye[2] = 6.0;
    s->cam.up[1] = 1.0;
    s->cam.fovy_deg = 45.0;
    s->cam.aspect = 1.0;
    s->cam.znear = 0.5;
    s->cam.zfar = 20.0;
    s->cam.width = CW;
    s->cam.height = CH;
    for (i = 0; i < NV; ++i) {
        float x, y, z = 0.0f;
        if (!overlap) {
            x = (float)(i % 4) - 1.5f;
            y = (float)(i / 4) - 1.5f;
        } else {
            int j = i % 8, back = i < 8;
            x = (float)(j % 4) - 1.5f + (back ? 0.45f : 0.0f);
            y = (float)(j / 4) - 0.5f + (back ? 0.3f : 0.0f);
            z = back ? -0.7f : 0.0f;
        }
        shp_mat_translate(s->model[i], x, y, z);
        hsv(i / (double)NV, s->color[i]);
        s->density[i] = 0.6f + 0.3f * (float)((i * 7) % NV);
        s->ext[i][0] = s->ext[i][1] = s->ext[i][2] = 0.0f;
        if (coloured_ext) { /* per-channel extinction, each channel different */
            s->ext[i][0] = 0.3f + 0.7f * (float)((i * 5) % 7) / 6.0f;
            s->ext[i][1] = 0.2f + 0.8f * (float)((i * 3) % 5) / 4.0f;
            s->ext[i][2] = 1.0f - 0.6f * (float)(i % 4) / 3.0f;
        }
    }
}

typedef struct cgpu {
    glu_ctx g;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp[NV];
    shp_mesh sphere;
} cgpu;

static void ramp_desc(const cscene *s, int i, fogvol_ramp_desc *rd)
{
    memset(rd, 0, sizeof *rd);
    memcpy(rd->color, s->color[i], sizeof rd->color);
    memcpy(rd->extinction_color, s->ext[i], sizeof rd->extinction_color);
    rd->density = s->density[i];
    rd->width = 1024;
}

static void gpu_setup(cgpu *c, const cscene *s, unsigned variants)
{
    fogvol_context_desc cd;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    int i;
    memset(c, 0, sizeof *c);
    assert_true(glu_create(&c->g, CW, CH, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    cd.tier = FOGVOL_TIER_FLOAT;
    cd.variants = variants;
    assert_int_equal(fogvol_create_context(&cd, &c->fv), FOGVOL_SUCCESS);
    c->sphere = shp_sphere(0.42f, 48, 24);
    memset(&md, 0, sizeof md);
    md.positions = c->sphere.pos;
    md.vertex_count = c->sphere.vcount;
    md.indices = c->sphere.idx;
    md.index_count = c->sphere.icount;
    assert_int_equal(fogvol_create_mesh(c->fv, &md, &c->mesh, NULL), FOGVOL_SUCCESS);
    for (i = 0; i < NV; ++i) {
        ramp_desc(s, i, &rd);
        assert_int_equal(fogvol_create_ramp(c->fv, &rd, &c->ramp[i]), FOGVOL_SUCCESS);
    }
}

static void gpu_teardown(cgpu *c)
{
    int i;
    for (i = 0; i < NV; ++i) fogvol_destroy_ramp(c->fv, c->ramp[i]);
    fogvol_destroy_mesh(c->fv, c->mesh);
    fogvol_destroy_context(c->fv);
    shp_free(&c->sphere);
    glu_destroy(&c->g);
}

static void gpu_render(cgpu *c, const cscene *s, fogvol_composite comp, unsigned char *out, fogvol_frame_stats *st)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    int i;
    memset(&fd, 0, sizeof fd);
    rc_camera_matrices(&s->cam, fd.view, fd.projection);
    fd.znear = (float)s->cam.znear;
    fd.zfar = (float)s->cam.zfar;
    fd.viewport[2] = CW;
    fd.viewport[3] = CH;
    fd.composite = comp;
    glClearColor(g_scene_rgb[0], g_scene_rgb[1], g_scene_rgb[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(c->fv, &fd), FOGVOL_SUCCESS);
    for (i = 0; i < NV; ++i) {
        memset(&vd, 0, sizeof vd);
        vd.mesh = c->mesh;
        vd.ramp = c->ramp[i];
        memcpy(vd.model, s->model[i], sizeof vd.model);
        assert_int_equal(fogvol_add_volume(c->fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(c->fv, st), FOGVOL_SUCCESS);
    memcpy(out, glu_pixels(&c->g), (size_t)CW * CH * 4);
    assert_int_equal(glGetError(), GL_NO_ERROR);
}

/* The CPU reference per pixel (rgb in [0,1]): the one-pass model (rgb) and the exact transfer
   (exact: the volumes composited one after the other in volume order, back to front in these
   scenes); the number of volumes the pixel's ray crosses, and whether the pixel is interior (off
   every silhouette). */
static void reference(const cscene *s, double *rgb, double *exact, int *nhit, unsigned char *interior)
{
    shp_mesh m = shp_sphere(0.42f, 48, 24);
    rc_scene sc[NV], all;
    rc_object o[NV];
    int i, px, py, c;
    for (i = 0; i < NV; ++i) {
        memset(&o[i], 0, sizeof o[i]);
        o[i].pos = m.pos;
        o[i].vcount = m.vcount;
        o[i].idx = m.idx;
        o[i].icount = m.icount;
        memcpy(o[i].model, s->model[i], sizeof o[i].model);
        o[i].sign = 1;
        assert_true(rc_scene_init(&sc[i], &o[i], 1));
    }
    assert_true(rc_scene_init(&all, o, NV));
    for (py = 0; py < CH; ++py)
        for (px = 0; px < CW; ++px) {
            double tau[3] = {0, 0, 0}, e[3] = {0, 0, 0}, x[3];
            int k = py * CW + px, n = 0;
            for (c = 0; c < 3; ++c) x[c] = g_scene_rgb[c];
            for (i = 0; i < NV; ++i) {
                double t = rc_trace(&sc[i], &s->cam, px + 0.5, py + 0.5).thickness;
                int grey = s->ext[i][0] == 0 && s->ext[i][1] == 0 && s->ext[i][2] == 0;
                if (t <= 0) continue;
                ++n;
                for (c = 0; c < 3; ++c) {
                    double sigma = s->density[i] * (grey ? 1.0 : s->ext[i][c]);
                    tau[c] += sigma * t;
                    e[c] += sigma * t * s->color[i][c];
                    x[c] = x[c] * exp(-sigma * t) + s->color[i][c] * (1.0 - exp(-sigma * t));
                }
            }
            for (c = 0; c < 3; ++c) {
                double tr = exp(-tau[c]);
                rgb[k * 3 + c] = g_scene_rgb[c] * tr + (tau[c] > 0 ? e[c] / tau[c] : 0.0) * (1.0 - tr);
                exact[k * 3 + c] = x[c];
            }
            nhit[k] = n;
            interior[k] = (unsigned char)rc_interior(&all, &s->cam, px, py);
        }
    for (i = 0; i < NV; ++i) rc_scene_free(&sc[i]);
    rc_scene_free(&all);
    shp_free(&m);
}

/* max |a - b| over interior pixels, in 1/255 (b: bytes or, with ref, reference colours) */
static double max_diff(const unsigned char *a, const unsigned char *b, const double *ref, const unsigned char *interior)
{
    double mx = 0;
    int k, c;
    for (k = 0; k < CW * CH; ++k) {
        if (!interior[k]) continue;
        for (c = 0; c < 3; ++c) {
            double d = fabs(a[k * 4 + c] - (ref ? ref[k * 3 + c] * 255.0 : (double)b[k * 4 + c]));
            if (d > mx) mx = d;
        }
    }
    return mx;
}

static void write_png(const char *name, const unsigned char *a, const unsigned char *b)
{
    unsigned char *img = (unsigned char *)malloc((size_t)CW * 3 * CH * 4);
    char path[256];
    int x, y, c;
    assert_non_null(img);
    for (y = 0; y < CH; ++y)
        for (x = 0; x < CW; ++x) {
            const unsigned char *pa = a + ((size_t)(CH - 1 - y) * CW + x) * 4;
            const unsigned char *pb = b + ((size_t)(CH - 1 - y) * CW + x) * 4;
            unsigned char *row = img + (size_t)y * CW * 3 * 4;
            for (c = 0; c < 4; ++c) {
                int d = abs((int)pa[c] - (int)pb[c]) * 16;
                row[x * 4 + c] = pa[c];
                row[(CW + x) * 4 + c] = pb[c];
                row[(2 * CW + x) * 4 + c] = c == 3 ? 255 : (unsigned char)(d > 255 ? 255 : d);
            }
        }
    mkdir("build", 0755);
    mkdir("build/colors", 0755);
    snprintf(path, sizeof path, "build/colors/%s.png", name);
    stbi_write_png(path, CW * 3, CH, 4, img, CW * 3 * 4);
    free(img);
}

static void run_scene(const cscene *s, fogvol_composite comp)
{
    unsigned char *ramps = (unsigned char *)malloc((size_t)CW * CH * 4);
    unsigned char *one = (unsigned char *)malloc((size_t)CW * CH * 4);
    unsigned char *geo = (unsigned char *)malloc((size_t)CW * CH * 4);
    unsigned char *interior = (unsigned char *)malloc((size_t)CW * CH);
    double *ref = (double *)malloc(sizeof(double) * 3 * CW * CH);
    double *exact = (double *)malloc(sizeof(double) * 3 * CW * CH);
    int *nhit = (int *)malloc(sizeof(int) * CW * CH), k, multi = 0, covered = 0;
    fogvol_frame_stats st_ramps, st_one, st_geo;
    double d_ramps_ref, d_one_ref, d_one_ramps, d_one_exact, d_ramps_exact, d_model_exact;
    cgpu c;
    assert_true(ramps && one && geo && interior && ref && exact && nhit);
    reference(s, ref, exact, nhit, interior);
    for (k = 0; k < CW * CH; ++k) {
        multi += nhit[k] > 1 && interior[k];
        covered += nhit[k] > 0 && interior[k];
    }
    assert_true(covered > CW * CH / 8);
    if (s->overlap) assert_true(multi > 500); /* the scene does what it says */
    else assert_int_equal(multi, 0);
    gpu_setup(&c, s, 0); /* per-ramp groups */
    gpu_render(&c, s, comp, ramps, &st_ramps);
    gpu_teardown(&c);
    gpu_setup(&c, s, FOGVOL_VARIANT_COLORS);
    gpu_render(&c, s, comp, one, &st_one);
    gpu_render(&c, s, comp == FOGVOL_COMPOSITE_FULLSCREEN ? FOGVOL_COMPOSITE_GEOMETRY : FOGVOL_COMPOSITE_FULLSCREEN,
               geo, &st_geo);
    gpu_teardown(&c);
    d_ramps_ref = max_diff(ramps, NULL, ref, interior);
    d_one_ref = max_diff(one, NULL, ref, interior);
    d_one_ramps = max_diff(one, ramps, NULL, interior);
    d_one_exact = max_diff(one, NULL, exact, interior);
    d_ramps_exact = max_diff(ramps, NULL, exact, interior);
    d_model_exact = 0;
    for (k = 0; k < CW * CH * 3; ++k)
        if (interior[k / 3] && fabs(ref[k] - exact[k]) * 255.0 > d_model_exact) d_model_exact = fabs(ref[k] - exact[k]) * 255.0;
    if (multi) {
        double sum = 0;
        for (k = 0; k < CW * CH * 3; ++k)
            if (interior[k / 3] && nhit[k / 3] > 1) sum += fabs(one[k / 3 * 4 + k % 3] - exact[k] * 255.0);
        print_message("# %s: mean |one pass - exact| over the pixels crossing two volumes: %.2f/255\n", s->name,
                      sum / (3.0 * multi));
    }
    print_message("# %s: passes per-ramp %d, one pass %d; max over interior pixels, /255: one pass - its model "
                  "(CPU) %.2f, one pass - exact transfer %.2f, per-ramp - exact %.2f, per-ramp - model %.2f, "
                  "one pass - per-ramp %.2f, model - exact (CPU, double) %.2f; %d interior pixels cross two "
                  "volumes\n",
                  s->name, st_ramps.passes, st_one.passes, d_one_ref, d_one_exact, d_ramps_exact, d_ramps_ref,
                  d_one_ramps, d_model_exact, multi);
    write_png(s->name, ramps, one);
    /* one sum pass and one composite (two blend draws with coloured extinction) after the O pass */
    assert_int_equal(st_one.passes, s->coloured_ext ? 4 : 3);
    assert_int_equal(st_ramps.passes, 1 + 2 * NV);
    assert_int_equal(st_one.groups, 1);
    assert_int_equal(st_one.volumes, NV);
    assert_true(d_one_ref <= 2.0); /* the model, computed here */
    /* the geometry composite writes the same bytes */
    assert_memory_equal(one, geo, (size_t)CW * CH * 4);
    assert_true(d_one_exact <= 2.0 + d_model_exact); /* exact where the model is */
    if (!s->overlap) assert_true(d_model_exact < 1e-9);  /* one volume per ray: the model is exact */
    if (!s->coloured_ext) {
        assert_true(d_ramps_exact <= 2.0); /* grey extinction, back to front: the per-ramp groups are exact */
        if (!s->overlap) assert_true(d_one_ramps <= 2.0); /* exact case: the same picture */
    } else if (!s->opaque) {
        assert_true(d_ramps_exact > 2.0); /* the per-ramp path cannot colour the extinction */
    }
    free(ramps);
    free(one);
    free(geo);
    free(interior);
    free(ref);
    free(exact);
    free(nhit);
}

static void test_separate(void **state)
{
    cscene s;
    (void)state;
    build_scene(&s, "separate_16", 0, 0);
    run_scene(&s, FOGVOL_COMPOSITE_FULLSCREEN);
}

static void test_overlapping(void **state)
{
    cscene s;
    (void)state;
    build_scene(&s, "overlapping_16", 1, 0);
    run_scene(&s, FOGVOL_COMPOSITE_FULLSCREEN);
}

static void test_coloured_extinction(void **state)
{
    cscene s;
    (void)state;
    build_scene(&s, "coloured_extinction_16", 1, 1);
    run_scene(&s, FOGVOL_COMPOSITE_GEOMETRY);
}

/* Densities that pass FLT_MAX times an extinction colour or times the depth range (1e38 and 1e36 per
   unit), each ramp's extinction colours different, the volumes apart: every volume is
   opaque, its colour its own emission, against the same model in double precision. (The one-pass
   colour group's float optical depths overflowed to inf and their signed sums to NaN: the volumes
   vanished.) */
static void test_huge_densities(void **state)
{
    cscene s;
    int i;
    (void)state;
    build_scene(&s, "huge_density_16", 0, 1); /* (apart: one pass is exact where volumes do not overlap) */
    for (i = 0; i < NV; ++i) s.density[i] = i % 2 ? 1e36f : 1e38f;
    s.opaque = 1;
    run_scene(&s, FOGVOL_COMPOSITE_FULLSCREEN);
}

/* The thickness of volume i of the scene per pixel, ray-cast (rows bottom to top). */
static void trace_volume(const cscene *s, int i, double *t)
{
    shp_mesh m = shp_sphere(0.42f, 48, 24);
    rc_scene sc;
    rc_object o;
    int px, py;
    memset(&o, 0, sizeof o);
    o.pos = m.pos;
    o.vcount = m.vcount;
    o.idx = m.idx;
    o.icount = m.icount;
    memcpy(o.model, s->model[i], sizeof o.model);
    o.sign = 1;
    assert_true(rc_scene_init(&sc, &o, 1));
    for (py = 0; py < CH; ++py)
        for (px = 0; px < CW; ++px) t[py * CW + px] = rc_trace(&sc, &s->cam, px + 0.5, py + 0.5).thickness;
    rc_scene_free(&sc);
    shp_free(&m);
}

/* max |dbg - t| over the interior pixels */
static double max_thickness_diff(const float *dbg, const double *t, const unsigned char *interior)
{
    double mx = 0;
    int k;
    for (k = 0; k < CW * CH; ++k)
        if (interior[k] && fabs(dbg[k] - t[k]) > mx) mx = fabs(dbg[k] - t[k]);
    return mx;
}

/* A frame of the scene's 16 volumes in volume order; volumes below 'dens_below' get the density
   texture, those from 'col_from' on the colour texture; debug read-back of debug_ramp. */
static fogvol_result textured_frame(cgpu *c, const cscene *s, const fogvol_volume_texture *dens, int dens_below,
                                    const fogvol_volume_texture *col, int col_from, int nvol, float *dbg,
                                    const fogvol_ramp *debug_ramp, unsigned char *out)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_result r;
    int i;
    memset(&fd, 0, sizeof fd);
    rc_camera_matrices(&s->cam, fd.view, fd.projection);
    fd.znear = (float)s->cam.znear;
    fd.zfar = (float)s->cam.zfar;
    fd.viewport[2] = CW;
    fd.viewport[3] = CH;
    fd.debug_thickness = dbg;
    fd.debug_ramp = debug_ramp;
    glClearColor(g_scene_rgb[0], g_scene_rgb[1], g_scene_rgb[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(c->fv, &fd), FOGVOL_SUCCESS);
    for (i = 0; i < nvol; ++i) {
        memset(&vd, 0, sizeof vd);
        vd.mesh = c->mesh;
        vd.ramp = c->ramp[i];
        memcpy(vd.model, s->model[i], sizeof vd.model);
        if (i < dens_below) vd.density = dens;
        if (i >= col_from) vd.color = col;
        assert_int_equal(fogvol_add_volume(c->fv, &vd), FOGVOL_SUCCESS);
    }
    r = fogvol_end_frame(c->fv, NULL);
    memcpy(out, glu_pixels(&c->g), (size_t)CW * CH * 4);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    return r;
}

/* Issue 31 3b and 3g: FOGVOL_VARIANT_COLORS drew textured volumes as if untextured (a density
   texture of 0 gave full fog, a colour texture was ignored) and never wrote the debug read-back;
   a debug_ramp with no volume in the frame left the buffer untouched. Ground truth: density 0
   draws nothing, the colour texture (1, 128/255, 0) multiplies the ramp colours (the Beer-Lambert
   model of reference() with those colours and densities), the ray-cast thickness of one volume,
   and 0 where the frame has no volume of the ramp. */
static void test_textures_and_debug(void **state)
{
    static const unsigned char zero[4] = {0, 0, 0, 255}, orange[4] = {255, 128, 0, 255};
    unsigned char *img = (unsigned char *)malloc((size_t)CW * CH * 4), *interior = (unsigned char *)malloc(CW * CH);
    double *ref = (double *)malloc(sizeof(double) * 3 * CW * CH), *exact = (double *)malloc(sizeof(double) * 3 * CW * CH);
    double *t = (double *)malloc(sizeof(double) * CW * CH), d;
    float *dbg = (float *)malloc(sizeof(float) * CW * CH);
    int *nhit = (int *)malloc(sizeof(int) * CW * CH), i, k, untouched;
    fogvol_texture_desc td;
    fogvol_volume_texture *dens, *col;
    cscene s, m;
    cgpu c;
    (void)state;
    assert_true(img && interior && ref && exact && t && dbg && nhit);
    build_scene(&s, "textured_16", 0, 0);
    m = s; /* the model: volumes 0-7 without density, 8-15 coloured by the texture */
    for (i = 0; i < NV; ++i) {
        if (i < 8) m.density[i] = 0.0f;
        else {
            m.color[i][1] = (float)(m.color[i][1] * 128.0 / 255.0);
            m.color[i][2] = 0.0f;
        }
    }
    reference(&m, ref, exact, nhit, interior);
    gpu_setup(&c, &s, FOGVOL_VARIANT_COLORS);
    memset(&td, 0, sizeof td);
    td.width = td.height = 1;
    td.pixels = zero;
    assert_int_equal(fogvol_create_volume_texture(c.fv, &td, &dens), FOGVOL_SUCCESS);
    td.pixels = orange;
    assert_int_equal(fogvol_create_volume_texture(c.fv, &td, &col), FOGVOL_SUCCESS);
    /* the textures drawn, the thickness of volume 9 (a coloured-texture ramp) read back */
    for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
    assert_int_equal(textured_frame(&c, &s, dens, 8, col, 8, NV, dbg, c.ramp[9], img), FOGVOL_SUCCESS);
    write_png("textured_16", img, img);
    d = max_diff(img, NULL, ref, interior);
    print_message("# COLORS with textures: max |picture - model| %.2f/255 over interior pixels\n", d);
    assert_true(d <= 2.0);
    trace_volume(&s, 9, t);
    d = max_thickness_diff(dbg, t, interior);
    print_message("# COLORS, debug_ramp of volume 9: max |read-back - ray cast| %.3g (range %.1f)\n", d,
                  s.cam.zfar - s.cam.znear);
    assert_true(d <= 3e-5 * (s.cam.zfar - s.cam.znear));
    /* no texture: the one-pass colour group; debug_ramp NULL: its first volume's ramp (volume 0) */
    for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
    assert_int_equal(textured_frame(&c, &s, NULL, 0, NULL, NV, NV, dbg, NULL, img), FOGVOL_SUCCESS);
    trace_volume(&s, 0, t);
    d = max_thickness_diff(dbg, t, interior);
    print_message("# COLORS, debug_ramp NULL: max |read-back - ray cast of volume 0| %.3g\n", d);
    assert_true(d <= 3e-5 * (s.cam.zfar - s.cam.znear));
    /* debug_ramp with no volume in the frame (volume 15 left out): thickness 0 everywhere */
    for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
    assert_int_equal(textured_frame(&c, &s, NULL, 0, NULL, NV, NV - 1, dbg, c.ramp[NV - 1], img), FOGVOL_SUCCESS);
    for (untouched = 0, k = 0; k < CW * CH; ++k) untouched += dbg[k] != 0.0f;
    assert_int_equal(untouched, 0);
    /* debug_ramp destroyed inside the frame (volume 3's): its volume is dropped, the read-back is 0
       everywhere (the frame draws nothing of that ramp) and the picture is the model without volume 3
       (the colour group read the destroyed ramp: a use-after-free under ASan) */
    {
        fogvol_frame_desc fd;
        fogvol_volume_desc vd;
        cscene m3 = s;
        m3.density[3] = 0.0f;
        reference(&m3, ref, exact, nhit, interior);
        memset(&fd, 0, sizeof fd);
        rc_camera_matrices(&s.cam, fd.view, fd.projection);
        fd.znear = (float)s.cam.znear;
        fd.zfar = (float)s.cam.zfar;
        fd.viewport[2] = CW;
        fd.viewport[3] = CH;
        fd.debug_thickness = dbg;
        fd.debug_ramp = c.ramp[3];
        for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
        glClearColor(g_scene_rgb[0], g_scene_rgb[1], g_scene_rgb[2], 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        assert_int_equal(fogvol_begin_frame(c.fv, &fd), FOGVOL_SUCCESS);
        for (i = 0; i < NV; ++i) {
            memset(&vd, 0, sizeof vd);
            vd.mesh = c.mesh;
            vd.ramp = c.ramp[i];
            memcpy(vd.model, s.model[i], sizeof vd.model);
            assert_int_equal(fogvol_add_volume(c.fv, &vd), FOGVOL_SUCCESS);
        }
        fogvol_destroy_ramp(c.fv, c.ramp[3]);
        c.ramp[3] = NULL;
        assert_int_equal(fogvol_end_frame(c.fv, NULL), FOGVOL_SUCCESS);
        memcpy(img, glu_pixels(&c.g), (size_t)CW * CH * 4);
        for (untouched = 0, k = 0; k < CW * CH; ++k) untouched += dbg[k] != 0.0f;
        assert_int_equal(untouched, 0);
        d = max_diff(img, NULL, ref, interior);
        print_message("# COLORS, debug_ramp destroyed in the frame: read-back 0, max |picture - model without it| "
                      "%.2f/255\n", d);
        assert_true(d <= 2.0);
        /* the next frame's debug_ramp is read back again (nothing of the destroyed one is kept) */
        fd.debug_ramp = c.ramp[9];
        for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
        assert_int_equal(fogvol_begin_frame(c.fv, &fd), FOGVOL_SUCCESS);
        for (i = 0; i < NV; ++i) {
            if (i == 3) continue;
            memset(&vd, 0, sizeof vd);
            vd.mesh = c.mesh;
            vd.ramp = c.ramp[i];
            memcpy(vd.model, s.model[i], sizeof vd.model);
            assert_int_equal(fogvol_add_volume(c.fv, &vd), FOGVOL_SUCCESS);
        }
        assert_int_equal(fogvol_end_frame(c.fv, NULL), FOGVOL_SUCCESS);
        trace_volume(&s, 9, t);
        reference(&s, ref, exact, nhit, interior); /* (the interior mask of the scene) */
        d = max_thickness_diff(dbg, t, interior);
        print_message("# COLORS, the frame after: debug_ramp of volume 9 read back, max |read-back - ray cast| %.3g\n", d);
        assert_true(d <= 3e-5 * (s.cam.zfar - s.cam.znear));
    }
    fogvol_destroy_volume_texture(c.fv, dens);
    fogvol_destroy_volume_texture(c.fv, col);
    gpu_teardown(&c);
    /* the same without COLORS: the empty debug ramp is 0 too */
    gpu_setup(&c, &s, 0);
    for (k = 0; k < CW * CH; ++k) dbg[k] = -1.0f;
    assert_int_equal(textured_frame(&c, &s, NULL, 0, NULL, NV, NV - 1, dbg, c.ramp[NV - 1], img), FOGVOL_SUCCESS);
    for (untouched = 0, k = 0; k < CW * CH; ++k) untouched += dbg[k] != 0.0f;
    assert_int_equal(untouched, 0);
    gpu_teardown(&c);
    free(img);
    free(interior);
    free(ref);
    free(exact);
    free(t);
    free(dbg);
    free(nhit);
}

/* Null backend: pass counts, groups kept apart, refusals. */
static void null_context(fogvol_null_backend *nb, unsigned caps, fogvol_tier tier, unsigned variants,
                         fogvol_context **fv, fogvol_result expect)
{
    fogvol_context_desc cd;
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(nb, &cd.backend);
    cd.backend.caps = caps;
    cd.backend.dialect = FOGVOL_GLSL_330;
    cd.tier = tier;
    cd.variants = variants;
    cd.logger.func = logger;
    assert_int_equal(fogvol_create_context(&cd, fv), expect);
}

static void test_null_passes(void **state)
{
    static const float box[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
    static const uint32_t idx[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                     1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    unsigned all = FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_MRT | FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_DEPTH_TEXTURE;
    fogvol_color_key key = {1.0f, {1, 0, 0, 1}};
    int v, mode;
    (void)state;
    for (mode = 0; mode < 2; ++mode) {
        fogvol_null_backend nb;
        fogvol_context *fv;
        fogvol_mesh *mesh;
        fogvol_ramp *ramps[NV + 2];
        fogvol_mesh_desc md;
        fogvol_ramp_desc rd;
        fogvol_frame_desc fd;
        fogvol_volume_desc vd;
        fogvol_frame_stats st;
        null_context(&nb, all, FOGVOL_TIER_FLOAT, mode ? FOGVOL_VARIANT_COLORS : 0, &fv, FOGVOL_SUCCESS);
        memset(&md, 0, sizeof md);
        md.positions = box;
        md.vertex_count = 8;
        md.indices = idx;
        md.index_count = 36;
        assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, NULL), FOGVOL_SUCCESS);
        for (v = 0; v < NV + 2; ++v) {
            memset(&rd, 0, sizeof rd);
            rd.color[0] = (float)v / NV;
            rd.density = 1.0f + (float)v;
            if (v == NV) { /* a gradient keeps its own group */
                rd.model = FOGVOL_RAMP_GRADIENT;
                rd.keys = &key;
                rd.key_count = 1;
            }
            if (v == NV + 1) rd.blend = FOGVOL_BLEND_LIGHT; /* light keeps its own group */
            assert_int_equal(fogvol_create_ramp(fv, &rd, &ramps[v]), FOGVOL_SUCCESS);
        }
        memset(&fd, 0, sizeof fd);
        fd.view[0] = fd.view[5] = fd.view[10] = fd.view[15] = 1.0f;
        fd.projection[0] = fd.projection[5] = 1.0f;
        fd.projection[10] = -1.0f;
        fd.projection[11] = -1.0f;
        fd.projection[14] = -0.2f;
        fd.znear = 0.1f;
        fd.zfar = 100.0f;
        fd.viewport[2] = fd.viewport[3] = 64;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        for (v = 0; v < NV + 2; ++v) {
            memset(&vd, 0, sizeof vd);
            vd.mesh = mesh;
            vd.ramp = ramps[v];
            vd.model[0] = vd.model[5] = vd.model[10] = vd.model[15] = 1.0f;
            vd.model[14] = -5.0f - (float)v;
            assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        }
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        /* O, then per group one sum pass and one composite: 18 groups, or the colour group + 2 */
        print_message("# null backend, 16 extinction ramps + a gradient + a light: %d passes (%s)\n", st.passes,
                      mode ? "one-pass colours" : "per-ramp groups");
        assert_int_equal(st.passes, mode ? 1 + 2 + 2 * 2 : 1 + 2 * (NV + 2));
        assert_int_equal(st.groups, mode ? 3 : NV + 2);
        assert_int_equal(st.volumes, NV + 2);
        if (mode) { /* the colour sum pass draws the 16 members into the two-attachment target */
            assert_int_equal(nb.draws[1], NV);
            assert_int_equal(nb.passes[1].blend, FOGVOL_PASS_BLEND_ADD);
            assert_int_equal(nb.passes[2].blend, FOGVOL_PASS_BLEND_FOG);
            assert_int_equal(nb.fullscreen[2], 1);
        }
        for (v = 0; v < NV + 2; ++v) fogvol_destroy_ramp(fv, ramps[v]);
        fogvol_destroy_mesh(fv, mesh);
        fogvol_destroy_context(fv);
        assert_int_equal(nb.creates, nb.destroys);
    }
}

static void test_refused(void **state)
{
    fogvol_null_backend nb;
    fogvol_context *fv = NULL;
    fogvol_ramp_desc rd;
    fogvol_ramp *r;
    unsigned all = FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_MRT | FOGVOL_CAP_HIGHP_FRAGMENT;
    (void)state;
    /* RGBA8 tiers, no float blending, no MRT: refused at creation */
    null_context(&nb, all, FOGVOL_TIER_PS20, FOGVOL_VARIANT_COLORS, &fv, FOGVOL_ERROR_UNSUPPORTED);
    null_context(&nb, all & ~(unsigned)FOGVOL_CAP_FLOAT_BLEND, FOGVOL_TIER_AUTO, FOGVOL_VARIANT_COLORS, &fv,
                 FOGVOL_ERROR_UNSUPPORTED);
    null_context(&nb, all & ~(unsigned)FOGVOL_CAP_MRT, FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, &fv,
                 FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_combination_supported(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, FOGVOL_GLSL_120),
                     FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(fogvol_msaa_supported(FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, FOGVOL_GLSL_330),
                     FOGVOL_ERROR_UNSUPPORTED);
    /* AUTO picks FLOAT when it can */
    null_context(&nb, all, FOGVOL_TIER_AUTO, FOGVOL_VARIANT_COLORS, &fv, FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_FLOAT);
    /* extinction colours: negative or non-finite refused */
    memset(&rd, 0, sizeof rd);
    rd.density = 1.0f;
    rd.extinction_color[1] = -0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &r), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.extinction_color[1] = (float)INFINITY;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &r), FOGVOL_ERROR_INVALID_ARGUMENT);
    fogvol_destroy_context(fv);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_null_passes),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_separate),
        cmocka_unit_test(test_overlapping),
        cmocka_unit_test(test_coloured_extinction), cmocka_unit_test(test_huge_densities),
        cmocka_unit_test(test_textures_and_debug),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
