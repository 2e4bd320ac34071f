/* test_texlight.c - density and colour textures on volumes, and volume light by compare, under
   OSMesa against CPU references written here independently of fogvol:
   - density constant along the rays (orthographic camera looking along the texture's projection
     axis, an opaque slab cutting the volume): thickness = rho(x, y) * chord, rho looked up in the
     texture's texels here; FLOAT and PS20 (dither off);
   - density varying along the rays (perspective camera, a gradient along the view axis): the
     thickness against numeric integration of the density along each ray, within the error bound
     the header states (contrast * (|a - c| + |b - c|));
   - colour texture: a saturated fog volume composited over black shows the texture's texels;
   - volume light by compare: scene pixels whose ray-cast surface point lies inside a rotated box
     (analytic point-in-box test) are lit, the others untouched; FLOAT, PS20 (+ COUNT in GLSL ES
     100, + SINGLE_TARGET + ALU in GLSL 120);
   - refusals: concave light meshes, tiers without the features. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#include "tests/gl_util.h"
#include "tests/shapes.h"
#include "tests/raycast.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define TW 128
#define TH 128
#define DT 16 /* density texture size */

static char g_last_error[512];
static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l == FOGVOL_LOG_ERROR) snprintf(g_last_error, sizeof g_last_error, "%s", m);
}

static void png(const char *name, const unsigned char *rgba)
{
    char path[256];
    mkdir("build", 0755);
    snprintf(path, sizeof path, "build/texlight_%s.png", name);
    stbi_flip_vertically_on_write(1);
    stbi_write_png(path, TW, TH, 4, rgba, TW * 4);
}

static fogvol_context *make_ctx(glu_ctx *g, fogvol_tier tier, unsigned variants, fogvol_dialect dialect)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    assert_true(glu_create(g, TW, TH, 1));
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.gl.dialect = dialect;
    cd.logger.func = logger;
    cd.tier = tier;
    cd.variants = variants;
    cd.disable_dither = 1;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    return fv;
}

static fogvol_mesh *mesh_of(fogvol_context *fv, shp_mesh m, fogvol_mesh_report *rep)
{
    fogvol_mesh_desc md;
    fogvol_mesh *out = NULL;
    memset(&md, 0, sizeof md);
    md.positions = m.pos;
    md.vertex_count = m.vcount;
    md.indices = m.idx;
    md.index_count = m.icount;
    assert_int_equal(fogvol_create_mesh(fv, &md, &out, rep), FOGVOL_SUCCESS);
    shp_free(&m);
    return out;
}

/* the density texels: a pattern with neighbours far apart, values 20..250 */
static unsigned char texel(int i, int j) { return (unsigned char)(20 + (i * 37 + j * 91) % 231); }

static fogvol_volume_texture *density_texture(fogvol_context *fv)
{
    unsigned char px[DT * DT * 4];
    fogvol_texture_desc td;
    fogvol_volume_texture *t = NULL;
    int i, j;
    for (j = 0; j < DT; ++j)
        for (i = 0; i < DT; ++i) {
            unsigned char *p = px + 4 * (j * DT + i);
            p[0] = texel(i, j);
            p[1] = p[2] = 0;
            p[3] = 255;
        }
    memset(&td, 0, sizeof td);
    td.width = td.height = DT;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_NEAREST;
    td.wrap = FOGVOL_WRAP_CLAMP;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &t), FOGVOL_SUCCESS);
    return t;
}

static void ortho(float p[16], double h, double n, double f)
{
    memset(p, 0, 16 * sizeof(float));
    p[0] = p[5] = (float)(1.0 / h);
    p[10] = (float)(-2.0 / (f - n));
    p[14] = (float)(-(f + n) / (f - n));
    p[15] = 1.0f;
}

/* Orthographic camera at the origin looking down -z over [-1.5, 1.5]^2, near 1, far 11; a box
   [-1,1]^3 at z = -5 (view depth 4..6) with density s = (x+1)/2, t = (y+1)/2; an opaque slab
   at view depth 4.5 over x < 0. Exact case: rho(x, y) * (chord), chord 2 or 0.5. */
static void density_exact(fogvol_tier tier, unsigned variants, double bound, const char *name)
{
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, tier, variants, FOGVOL_GLSL_AUTO);
    fogvol_mesh *box = mesh_of(fv, shp_box(1, 1, 1), NULL), *slab = mesh_of(fv, shp_box(1.5f, 2, 0.25f), NULL);
    fogvol_volume_texture *tex = density_texture(fv);
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    float slab_m[16], *thick = (float *)calloc(TW * TH, sizeof(float));
    double maxerr = 0.0;
    int x, y, checked = 0;
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 1.0f;
    rd.density = 0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    ortho(fd.projection, 1.5, 1.0, 11.0);
    fd.znear = 1.0f;
    fd.zfar = 11.0f;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    fd.debug_thickness = thick;
    glu_translate_scale(slab_m, -1.5f, 0.0f, -4.75f, 1.0f); /* x in [-3, 0], z in [-5, -4.5] */
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, slab, slab_m), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = box;
    vd.ramp = ramp;
    glu_translate_scale(vd.model, 0, 0, -5, 1);
    vd.density = tex;
    vd.density_map[0] = 0.5f;
    vd.density_map[3] = 0.5f;
    vd.density_map[5] = 0.5f;
    vd.density_map[7] = 0.5f;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    png(name, glu_pixels(&g));
    for (y = 0; y < TH; ++y)
        for (x = 0; x < TW; ++x) {
            double wx = -1.5 + 3.0 * (x + 0.5) / TW, wy = -1.5 + 3.0 * (y + 0.5) / TH;
            double s = (wx + 1) * 0.5 * DT, t = (wy + 1) * 0.5 * DT, ref, err;
            if (fabs(wx) > 0.97 || fabs(wy) > 0.97 || fabs(wx) < 0.03) continue; /* silhouettes, slab edge */
            if (fabs(s - floor(s + 0.5)) < 0.05 || fabs(t - floor(t + 0.5)) < 0.05) continue; /* texel edges */
            ref = texel((int)s, (int)t) / 255.0 * (wx < 0 ? 0.5 : 2.0);
            err = fabs(thick[y * TW + x] - ref);
            if (err > maxerr) maxerr = err;
            ++checked;
        }
    print_message("# density exact (%s): %d pixels, max |error| %.3g view units (bound %.3g)\n", name, checked,
                  maxerr, bound);
    assert_true(checked > TW * TH / 4);
    assert_true(maxerr <= bound);
    free(thick);
    fogvol_destroy_volume_texture(fv, tex);
    fogvol_destroy_mesh(fv, box);
    fogvol_destroy_mesh(fv, slab);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

static void test_density_exact_float(void **state)
{
    (void)state;
    density_exact(FOGVOL_TIER_FLOAT, 0, 3e-5 * 10.0, "density_float");
}

/* RGBA8: v re-encoded per face (1 LSB each, 2 faces) + the opaque depth's own LSB */
static void test_density_exact_ps20(void **state)
{
    double lsb = 10.0 / 4096.0;
    (void)state;
    density_exact(FOGVOL_TIER_PS20, 0, 3.0 * lsb, "density_ps20");
    density_exact(FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_ALU, 3.0 * lsb,
                  "density_ps20_single_alu");
}

/* rho(z) = 0.2 + 0.7 (z_model + 1) / 2 along the box's z (the view axis), from a 64-texel gradient
   with LINEAR filtering; perspective camera at the origin, the box at z = -5, rotated so that the
   chords are not centred on the reference depth. */
static double grad_rho(double s) /* s in texels' [0,1], the texture as GL filters it */
{
    double u = s * 64.0 - 0.5, f, a, b;
    int i;
    if (u < 0) u = 0;
    if (u > 63) u = 63;
    i = (int)floor(u);
    if (i > 62) i = 62;
    f = u - i;
    a = floor(255.0 * (0.2 + 0.7 * (i + 0.5) / 64.0) + 0.5) / 255.0;
    b = floor(255.0 * (0.2 + 0.7 * (i + 1.5) / 64.0) + 0.5) / 255.0;
    return a + (b - a) * f;
}

static void test_density_along_ray(void **state)
{
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO);
    fogvol_mesh *box = mesh_of(fv, shp_box(1, 1, 1), NULL);
    unsigned char px[64 * 4];
    fogvol_texture_desc td;
    fogvol_volume_texture *tex;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    float *thick = (float *)calloc(TW * TH, sizeof(float));
    double maxerr = 0.0, maxratio = 0.0, c = 5.0, tanh_ = tan(50.0 * 3.14159265358979 / 360.0);
    int x, y, i, checked = 0;
    (void)state;
    for (i = 0; i < 64; ++i) {
        px[4 * i] = (unsigned char)floor(255.0 * (0.2 + 0.7 * (i + 0.5) / 64.0) + 0.5);
        px[4 * i + 1] = px[4 * i + 2] = 0;
        px[4 * i + 3] = 255;
    }
    memset(&td, 0, sizeof td);
    td.width = 64;
    td.height = 1;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = FOGVOL_WRAP_CLAMP;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &tex), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.density = 0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    glu_perspective(fd.projection, 50.0, 1.0, 1.0, 11.0);
    fd.znear = 1.0f;
    fd.zfar = 11.0f;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    fd.debug_thickness = thick;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = box;
    vd.ramp = ramp;
    glu_translate_scale(vd.model, 0, 0, -5, 1);
    vd.density = tex;
    vd.density_map[2] = 0.5f; /* s = (z + 1) / 2 */
    vd.density_map[3] = 0.5f;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    for (y = 0; y < TH; ++y)
        for (x = 0; x < TW; ++x) { /* ray (dx, dy, -1) per unit view depth; the box [-1,1]^2 x [-6,-4] */
            double dx = (2.0 * (x + 0.5) / TW - 1.0) * tanh_, dy = (2.0 * (y + 0.5) / TH - 1.0) * tanh_;
            double a = 4.0, b = 6.0, ref = 0.0, comp, bound, ra, rb, lo = 1, hi = 0, e;
            int k, n = 2000;
            /* |e dx| <= 1, |e dy| <= 1 */
            if (fabs(dx) > 1e-9) b = fmin(b, 1.0 / fabs(dx));
            if (fabs(dy) > 1e-9) b = fmin(b, 1.0 / fabs(dy));
            if (b - a < 0.05 || fabs(fabs(dx) * b - 1) < 0.02 || fabs(fabs(dy) * b - 1) < 0.02) continue;
            for (k = 0; k < n; ++k) { /* midpoint rule over view depth e; model z = 5 - e */
                double r;
                e = a + (b - a) * (k + 0.5) / n;
                r = grad_rho((5.0 - e + 1.0) * 0.5);
                ref += r * (b - a) / n;
                if (r < lo) lo = r;
                if (r > hi) hi = r;
            }
            ra = grad_rho((5.0 - a + 1.0) * 0.5);
            rb = grad_rho((5.0 - b + 1.0) * 0.5);
            comp = thick[y * TW + x];
            bound = (hi - lo) * (fabs(a - c) + fabs(b - c)) + 1e-4;
            (void)ra;
            (void)rb;
            if (fabs(comp - ref) > maxerr) maxerr = fabs(comp - ref);
            if (fabs(comp - ref) / bound > maxratio) maxratio = fabs(comp - ref) / bound;
            ++checked;
        }
    print_message("# density along the ray (FLOAT, perspective): %d pixels, max |error| %.4f view units, "
                  "max error / stated bound %.3f\n", checked, maxerr, maxratio);
    assert_true(checked > 1000);
    assert_true(maxratio <= 1.0);
    assert_true(maxerr > 1e-3); /* the approximation does show (chords off-centre) */
    free(thick);
    fogvol_destroy_volume_texture(fv, tex);
    fogvol_destroy_mesh(fv, box);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

/* A saturated fog box (linear ramp reaching 1 at 0.1 units) over black through a 2x2 colour
   texture mapped to the screen: each quadrant shows its texel's colour. */
static void test_color_texture(void **state)
{
    static const unsigned char tx[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 0, 255};
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO);
    fogvol_mesh *box = mesh_of(fv, shp_box(2, 2, 1), NULL);
    fogvol_texture_desc td;
    fogvol_volume_texture *tex, *other;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    int x, y, c, maxerr = 0, checked = 0;
    (void)state;
    memset(&td, 0, sizeof td);
    td.width = td.height = 2;
    td.pixels = tx;
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &tex), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_create_volume_texture(fv, &td, &other), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_LINEAR;
    rd.color[0] = rd.color[1] = rd.color[2] = 1.0f;
    rd.density = 10.0f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    ortho(fd.projection, 1.5, 1.0, 11.0);
    fd.znear = 1.0f;
    fd.zfar = 11.0f;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = box;
    vd.ramp = ramp;
    glu_translate_scale(vd.model, 0, 0, -5, 1);
    vd.color = tex;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    vd.color = other; /* one colour texture per ramp group */
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_non_null(strstr(g_last_error, "colour texture"));
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    png("color_texture", glu_pixels(&g));
    for (y = 0; y < TH; ++y)
        for (x = 0; x < TW; ++x) {
            const unsigned char *p = g.pixels + 4 * (y * TW + x), *t;
            if (abs(2 * x + 1 - TW) < 4 || abs(2 * y + 1 - TH) < 4) continue;
            t = tx + 4 * ((y >= TH / 2) * 2 + (x >= TW / 2));
            for (c = 0; c < 3; ++c)
                if (abs(p[c] - t[c]) > maxerr) maxerr = abs(p[c] - t[c]);
            ++checked;
        }
    print_message("# colour texture: %d pixels, max |error| %d/255\n", checked, maxerr);
    assert_true(maxerr <= 1);
    fogvol_destroy_volume_texture(fv, tex);
    fogvol_destroy_volume_texture(fv, other);
    fogvol_destroy_mesh(fv, box);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

/* ---- volume light by compare -------------------------------------------- */

/* Scene: ground slab top at y = 0 (x, z in [-6, 6]), sphere r 1 at (0.8, 1, -0.5); camera at
   (0, 3, 7) looking at (0, 0.5, 0); light: box half (1.2, 2, 1) rotated 30 degrees about y at
   (-0.3, 1, 0). Lit: the ray's first surface point inside the light box. */
static const double g_eye[3] = {0, 3, 7}, g_at[3] = {0, 0.5, 0}, g_sph[4] = {0.8, 1, -0.5, 1};
static const double g_half[3] = {1.2, 2, 1}, g_lpos[3] = {-0.3, 1, 0}, g_ang = 30.0;

static void light_model(float m[16])
{
    double a = g_ang * 3.14159265358979 / 180.0;
    glu_identity(m);
    m[0] = (float)cos(a);
    m[2] = (float)-sin(a);
    m[8] = (float)sin(a);
    m[10] = (float)cos(a);
    m[12] = (float)g_lpos[0];
    m[13] = (float)g_lpos[1];
    m[14] = (float)g_lpos[2];
}

/* signed distance-like margin of p to the light box (negative inside) */
static double box_margin(const double p[3])
{
    double a = g_ang * 3.14159265358979 / 180.0, d[3], q[3], m = -1e9;
    int k;
    for (k = 0; k < 3; ++k) d[k] = p[k] - g_lpos[k];
    q[0] = cos(a) * d[0] - sin(a) * d[2]; /* inverse rotation (model x column = (cos, 0, -sin)) */
    q[1] = d[1];
    q[2] = sin(a) * d[0] + cos(a) * d[2];
    for (k = 0; k < 3; ++k) m = fmax(m, fabs(q[k]) - g_half[k]);
    return m;
}

/* 1 lit, 0 unlit, -1 ambiguous (near a boundary or a silhouette) */
static int light_reference(const float view[16], const float proj[16], int x, int y)
{
    double ndc[2] = {2.0 * (x + 0.5) / TW - 1.0, 2.0 * (y + 0.5) / TH - 1.0}, dir[3], t = 1e30, p[3], oc[3], b, c, h;
    double eye[3];
    int k, ortho = proj[15] == 1.0f;
    /* view-space ray (ndc.x / P0, ndc.y / P5, -1) from the eye, or orthographic (0, 0, -1) from
       (ndc.x / P0, ndc.y / P5, 0); to world through the view's rotation (rows) */
    double v[3] = {ndc[0] / proj[0], ndc[1] / proj[5], -1.0};
    for (k = 0; k < 3; ++k) {
        dir[k] = ortho ? -view[k * 4 + 2] : view[k * 4 + 0] * v[0] + view[k * 4 + 1] * v[1] + view[k * 4 + 2] * v[2];
        eye[k] = g_eye[k] + (ortho ? view[k * 4 + 0] * v[0] + view[k * 4 + 1] * v[1] : 0.0);
    }
    if (dir[1] < 0) t = -eye[1] / dir[1]; /* ground y = 0 */
    for (k = 0; k < 3; ++k) p[k] = eye[k] + t * dir[k];
    if (t < 1e29 && (fabs(p[0]) > 6 || fabs(p[2]) > 6)) t = 1e30;
    for (k = 0; k < 3; ++k) oc[k] = eye[k] - g_sph[k];
    b = oc[0] * dir[0] + oc[1] * dir[1] + oc[2] * dir[2];
    c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - g_sph[3] * g_sph[3];
    h = b * b - c * (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (fabs(h) < 0.05) return -1; /* sphere silhouette */
    if (h > 0) {
        double ts = (-b - sqrt(h)) / (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        if (ts > 0 && ts < t) t = ts;
    }
    if (t > 1e29) return 0;
    for (k = 0; k < 3; ++k) p[k] = eye[k] + t * dir[k];
    if (fabs(box_margin(p)) < 0.03) return -1;
    return box_margin(p) < 0;
}

/* ortho: an orthographic camera, with a small fog volume off screen 2 units from the eye (so that
   fogvol's clip-z scale, from the volumes alone, clipped the lights and occluders beyond it) */
static void light_case_ex(fogvol_tier tier, unsigned variants, fogvol_dialect dialect, const char *name, int ortho)
{
    static const float rgb[3] = {0.8f, 0.6f, 0.2f};
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, tier, variants, dialect);
    fogvol_mesh_report rep;
    fogvol_mesh *ground = mesh_of(fv, shp_box(6, 0.5f, 6), NULL), *sphere = mesh_of(fv, shp_sphere(1, 48, 24), NULL);
    fogvol_mesh *lbox = mesh_of(fv, shp_box((float)g_half[0], (float)g_half[1], (float)g_half[2]), &rep);
    fogvol_mesh *fog = mesh_of(fv, shp_box(0.25f, 0.25f, 0.25f), NULL);
    fogvol_ramp *ramp = NULL;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_light_desc ld;
    fogvol_frame_stats st;
    float gm[16], sm[16];
    int x, y, lit = 0, wrong = 0, checked = 0;
    assert_int_equal(rep.convex, 1);
    memset(&rd, 0, sizeof rd);
    rd.density = 0.5f;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    glu_look_at(fd.view, g_eye, g_at, (const double[3]){0, 1, 0});
    glu_perspective(fd.projection, 55.0, 1.0, 0.5, 30.0);
    fd.znear = 0.5f;
    fd.zfar = 30.0f;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    if (ortho) {
        memset(fd.projection, 0, sizeof fd.projection);
        fd.projection[0] = fd.projection[5] = 1.0f / 4.0f;
        fd.projection[10] = -2.0f / (30.0f - 0.5f);
        fd.projection[14] = -(30.0f + 0.5f) / (30.0f - 0.5f);
        fd.projection[15] = 1.0f;
    }
    glu_translate_scale(gm, 0, -0.5f, 0, 1);
    glu_translate_scale(sm, (float)g_sph[0], (float)g_sph[1], (float)g_sph[2], (float)g_sph[3]);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, ground, gm), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, sphere, sm), FOGVOL_SUCCESS);
    memset(&ld, 0, sizeof ld);
    ld.mesh = lbox;
    light_model(ld.model);
    memcpy(ld.color, rgb, sizeof rgb);
    assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_SUCCESS);
    if (ortho) { /* 2 units from the eye, 10 to its left along the view's x: off screen */
        fogvol_volume_desc vd;
        int k;
        memset(&vd, 0, sizeof vd);
        vd.mesh = fog;
        vd.ramp = ramp;
        glu_identity(vd.model);
        for (k = 0; k < 3; ++k)
            vd.model[12 + k] = (float)(g_eye[k] - 2.0 * fd.view[k * 4 + 2] - 10.0 * fd.view[k * 4 + 0]);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.lights, 1);
    png(name, glu_pixels(&g));
    for (y = 0; y < TH; ++y)
        for (x = 0; x < TW; ++x) {
            int ref = light_reference(fd.view, fd.projection, x, y);
            const unsigned char *p = g.pixels + 4 * (y * TW + x);
            int got = p[0] > 0 || p[1] > 0 || p[2] > 0;
            if (ref < 0) continue;
            ++checked;
            lit += ref;
            if (got != ref) ++wrong;
            if (got && (abs(p[0] - 204) > 1 || abs(p[1] - 153) > 1 || abs(p[2] - 51) > 1)) ++wrong;
        }
    print_message("# light by compare (%s): %d pixels classified, %d lit, %d wrong\n", name, checked, lit, wrong);
    assert_true(lit > 500);
    assert_int_equal(wrong, 0);
    fogvol_destroy_mesh(fv, ground);
    fogvol_destroy_mesh(fv, sphere);
    fogvol_destroy_mesh(fv, lbox);
    fogvol_destroy_mesh(fv, fog);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

static void light_case(fogvol_tier tier, unsigned variants, fogvol_dialect dialect, const char *name)
{
    light_case_ex(tier, variants, dialect, name, 0);
}

static void test_light_float(void **state)
{
    (void)state;
    light_case(FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, "light_float");
    light_case_ex(FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO, "light_float_ortho", 1);
}

static void test_light_ps20(void **state)
{
    (void)state;
    light_case(FOGVOL_TIER_PS20, 0, FOGVOL_GLSL_AUTO, "light_ps20");
    light_case(FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, FOGVOL_GLSL_100, "light_ps20_count_es100");
    light_case(FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_ALU, FOGVOL_GLSL_120,
               "light_ps20_single_alu_120");
}

/* ---- light falloff and soft edge ----------------------------------------------------------------- */
static const double g_fpos[3] = {-0.3, 1.6, 0.0}, g_frad = 2.6, g_fedge = 0.4;

/* the view ray of pixel (x, y): origin the eye, direction with view-axis component 1 (t = view depth) */
static void pixel_ray(const float view[16], const float proj[16], int x, int y, double dir[3])
{
    double v[3] = {(2.0 * (x + 0.5) / TW - 1.0) / proj[0], (2.0 * (y + 0.5) / TH - 1.0) / proj[5], -1.0};
    int k;
    for (k = 0; k < 3; ++k) dir[k] = view[k * 4 + 0] * v[0] + view[k * 4 + 1] * v[1] + view[k * 4 + 2] * v[2];
}

/* the light box's entry and exit view depths on the ray (slabs in its own frame) */
static void box_span(const double dir[3], double *t0, double *t1)
{
    double a = g_ang * 3.14159265358979 / 180.0, o[3], d[3], lo = -1e30, hi = 1e30;
    int k;
    for (k = 0; k < 3; ++k) o[k] = g_eye[k] - g_lpos[k];
    { /* inverse rotation, as box_margin */
        double ox = cos(a) * o[0] - sin(a) * o[2], oz = sin(a) * o[0] + cos(a) * o[2];
        double dx = cos(a) * dir[0] - sin(a) * dir[2], dz = sin(a) * dir[0] + cos(a) * dir[2];
        o[0] = ox, o[2] = oz, d[0] = dx, d[1] = dir[1], d[2] = dz;
    }
    for (k = 0; k < 3; ++k) {
        double u = (-g_half[k] - o[k]) / d[k], v = (g_half[k] - o[k]) / d[k];
        lo = fmax(lo, fmin(u, v));
        hi = fmin(hi, fmax(u, v));
    }
    *t0 = lo;
    *t1 = hi;
}

/* the lit colour's factor at scene depth t with the light's front and back depths tf, tb */
static double falloff_weight(const double dir[3], double t, double tf, double tb)
{
    double p[3], r2 = 0.0, w, m;
    int k;
    for (k = 0; k < 3; ++k) {
        p[k] = g_eye[k] + t * dir[k];
        r2 += (p[k] - g_fpos[k]) * (p[k] - g_fpos[k]);
    }
    r2 /= g_frad * g_frad;
    w = r2 < 1.0 ? (1.0 - r2) * (1.0 - r2) : 0.0;
    m = fmin(t - tf, tb - t) / g_fedge;
    return w * (m < 0 ? 0 : m > 1 ? 1 : m);
}

/* The light with falloff and a soft edge against the reference: colour * w(|p - position|) *
   clamp(m / edge, 0, 1) with p the ray-cast scene point and m its depth margin to the box's faces;
   the GPU's depths may be off by depth_err (view units: the encoding's LSB on RGBA8), so each pixel
   is checked against the reference's range over those perturbations, +-1/255. */
static void light_falloff_case(fogvol_tier tier, unsigned variants, double depth_err, const char *name)
{
    static const float rgb[3] = {0.8f, 0.6f, 0.2f};
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, tier, variants, FOGVOL_GLSL_AUTO);
    fogvol_mesh *ground = mesh_of(fv, shp_box(6, 0.5f, 6), NULL), *sphere = mesh_of(fv, shp_sphere(1, 48, 24), NULL);
    fogvol_mesh *lbox = mesh_of(fv, shp_box((float)g_half[0], (float)g_half[1], (float)g_half[2]), NULL);
    fogvol_frame_desc fd;
    fogvol_light_desc ld;
    float gm[16], sm[16];
    double emax = 0.0, over = 0.0;
    int x, y, k, checked = 0, faded = 0;
    shp_mesh mg = shp_box(6, 0.5f, 6), ms = shp_sphere(1, 48, 24);
    rc_object ro[2];
    rc_scene sc;
    rc_camera cam;
    memset(&cam, 0, sizeof cam);
    memcpy(cam.eye, g_eye, sizeof cam.eye);
    memcpy(cam.target, g_at, sizeof cam.target);
    cam.up[1] = 1.0;
    cam.fovy_deg = 55.0;
    cam.aspect = 1.0;
    cam.znear = 0.5;
    cam.zfar = 30.0;
    cam.width = TW;
    cam.height = TH;
    memset(&fd, 0, sizeof fd);
    rc_camera_matrices(&cam, fd.view, fd.projection);
    fd.znear = 0.5f;
    fd.zfar = 30.0f;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    glu_translate_scale(gm, 0, -0.5f, 0, 1);
    glu_translate_scale(sm, (float)g_sph[0], (float)g_sph[1], (float)g_sph[2], (float)g_sph[3]);
    memset(ro, 0, sizeof ro);
    ro[0].pos = mg.pos, ro[0].vcount = mg.vcount, ro[0].idx = mg.idx, ro[0].icount = mg.icount;
    ro[1].pos = ms.pos, ro[1].vcount = ms.vcount, ro[1].idx = ms.idx, ro[1].icount = ms.icount;
    memcpy(ro[0].model, gm, sizeof gm);
    memcpy(ro[1].model, sm, sizeof sm);
    assert_true(rc_scene_init(&sc, ro, 2));
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, ground, gm), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, sphere, sm), FOGVOL_SUCCESS);
    memset(&ld, 0, sizeof ld);
    ld.mesh = lbox;
    light_model(ld.model);
    memcpy(ld.color, rgb, sizeof rgb);
    for (k = 0; k < 3; ++k) ld.position[k] = (float)g_fpos[k];
    ld.falloff_radius = (float)g_frad;
    ld.edge_softness = (float)g_fedge;
    assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    png(name, glu_pixels(&g));
    for (y = 0; y < TH; ++y)
        for (x = 0; x < TW; ++x) {
            int ref = light_reference(fd.view, fd.projection, x, y), c, sgn;
            const unsigned char *p = g.pixels + 4 * (y * TW + x);
            double dir[3], t = 0.0, tf, tb, lo = 1e30, hi = -1e30;
            if (ref < 0) continue;
            ++checked;
            if (!ref) {
                if (p[0] || p[1] || p[2]) over = fmax(over, 255.0);
                continue;
            }
            pixel_ray(fd.view, fd.projection, x, y, dir);
            t = rc_trace(&sc, &cam, x + 0.5, y + 0.5).opaque_w; /* the drawn triangles' depth */
            box_span(dir, &tf, &tb);
            for (sgn = 0; sgn < 8; ++sgn) {
                double v = falloff_weight(dir, t + (sgn & 1 ? depth_err : -depth_err), tf + (sgn & 2 ? depth_err : -depth_err),
                                          tb + (sgn & 4 ? depth_err : -depth_err));
                lo = fmin(lo, v);
                hi = fmax(hi, v);
            }
            faded += falloff_weight(dir, t, tf, tb) < 0.9;
            for (c = 0; c < 3; ++c) {
                double want = 255.0 * rgb[c] * falloff_weight(dir, t, tf, tb);
                double a = 255.0 * rgb[c] * lo - 1.0, b = 255.0 * rgb[c] * hi + 1.0;
                emax = fmax(emax, fabs(p[c] - want));
                if (p[c] < a) over = fmax(over, a - p[c]);
                if (p[c] > b) over = fmax(over, p[c] - b);
            }
        }
    print_message("# light falloff and soft edge (%s): %d pixels classified, %d lit pixels faded below 0.9; max "
                  "|GPU - reference| %.2f/255 (depths exact), beyond the depth-error range + 1/255 by %.2f/255\n",
                  name, checked, faded, emax, over);
    assert_true(faded > 300);
    assert_true(over == 0.0);
    rc_scene_free(&sc);
    shp_free(&mg);
    shp_free(&ms);
    fogvol_destroy_mesh(fv, ground);
    fogvol_destroy_mesh(fv, sphere);
    fogvol_destroy_mesh(fv, lbox);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
}

static void test_light_falloff(void **state)
{
    (void)state;
    light_falloff_case(FOGVOL_TIER_FLOAT, 0, 1e-4, "light_falloff_float");
    light_falloff_case(FOGVOL_TIER_PS20, 0, 1.5 * 29.5 / 4096.0, "light_falloff_ps20");
}

/* Concave light meshes and tiers without the features are refused, with a logged reason. */
static void test_refusals(void **state)
{
    glu_ctx g;
    fogvol_context *fv = make_ctx(&g, FOGVOL_TIER_FLOAT, 0, FOGVOL_GLSL_AUTO);
    fogvol_mesh_report rep;
    fogvol_mesh *torus = mesh_of(fv, shp_torus(1.0f, 0.3f, 24, 12), &rep);
    fogvol_frame_desc fd;
    fogvol_light_desc ld;
    (void)state;
    assert_int_equal(rep.convex, 0);
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    glu_perspective(fd.projection, 50.0, 1.0, 1.0, 11.0);
    fd.znear = 1;
    fd.zfar = 11;
    fd.viewport[2] = TW;
    fd.viewport[3] = TH;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&ld, 0, sizeof ld);
    ld.mesh = torus;
    glu_identity(ld.model);
    g_last_error[0] = 0;
    assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_ERROR_INVALID_MESH);
    assert_non_null(strstr(g_last_error, "concave"));
    fogvol_cancel_frame(fv);
    fogvol_destroy_mesh(fv, torus);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    { /* PS13: neither density textures nor lights */
        fogvol_mesh *box;
        fogvol_volume_texture *tex;
        fogvol_ramp_desc rd;
        fogvol_ramp *ramp;
        fogvol_volume_desc vd;
        fv = make_ctx(&g, FOGVOL_TIER_PS13, 0, FOGVOL_GLSL_AUTO);
        box = mesh_of(fv, shp_box(1, 1, 1), &rep);
        assert_int_equal(rep.convex, 1);
        tex = density_texture(fv);
        memset(&rd, 0, sizeof rd);
        rd.density = 1;
        assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        ld.mesh = box;
        g_last_error[0] = 0;
        assert_int_equal(fogvol_add_light(fv, &ld), FOGVOL_ERROR_UNSUPPORTED);
        assert_non_null(strstr(g_last_error, "volume lights"));
        memset(&vd, 0, sizeof vd);
        vd.mesh = box;
        vd.ramp = ramp;
        glu_identity(vd.model);
        vd.density = tex;
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_UNSUPPORTED);
        assert_non_null(strstr(g_last_error, "density"));
        fogvol_cancel_frame(fv);
        fogvol_destroy_volume_texture(fv, tex);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_mesh(fv, box);
        fogvol_destroy_context(fv);
        glu_destroy(&g);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_density_exact_float), cmocka_unit_test(test_density_exact_ps20),
        cmocka_unit_test(test_density_along_ray),   cmocka_unit_test(test_color_texture),
        cmocka_unit_test(test_light_float),         cmocka_unit_test(test_light_ps20),
        cmocka_unit_test(test_light_falloff),       cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
