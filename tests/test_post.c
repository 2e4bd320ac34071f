/* test_post.c - the image-space effects: depth of field, outlines, distance fog.

   The test plays an engine that has its scene's depth in a 32-bit float depth
   texture (filled here from view depths chosen analytically, through the
   test's own projection and depth convention), its colour in an RGBA8
   texture and optionally its normals, and calls fogvol_post_* into the
   OSMesa framebuffer. Each picture is compared pixel by pixel with a CPU
   reference of the same formula written here from the analytic view depths
   (not from fogvol's linearisation):
   - depth of field: taps on a golden-angle spiral turned and jittered per pixel and per frame
     (fogvol_frame_desc.dither_frame), each tap entering as mix(C0, Ck, c(ek)), c(e) =
     clamp(|e - focus| / range, 0, 1): against continuous disc blurs computed here by area (the
     weighted one, and an unweighted one that halos), for 3 ... 48 taps: an in-focus square keeps its
     colour exactly, the blurred background next to it takes none of it on average (the unweighted
     blur brings in +24/255 of its red), and a fully blurred checkerboard stays within stated bounds of
     the disc blur: one frame's 4x4 block means, and the mean of 64 frames per pixel (the kernel's
     expectation, where fogvol 0.2's fixed kernel kept its copies: 67/255 and 32/255 off);
   - outlines: second differences of 1/e over lines of three pixels and
     normal deltas over the 3x3 neighbourhood, thresholded; outlines exactly
     where the depth jumps or the normals crease, none on a sloped plane;
   - distance fog: the extinction ramp 1 - exp(-density t) at t = e - start,
     interpolated between ramp texels like the filtered lookup, blended over
     the framebuffer's colour; for GL [-1,1] depth, reversed-Z zero-to-one
     with an infinite far plane, glDepthRange(1, 0), and a viewport offset
     inside the framebuffer (pixels outside it untouched).
   Bad input (NULL desc, NULL frame, no depth texture, inside a frame, a
   backend without highp or with an unknown dialect) gives result codes and a
   logged message; the engine's GL state is the same before and after. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define W 64
#define H 48
#define ZNEAR 0.5
#define ZFAR 100.0

enum { CONV_GL = 0, CONV_REVERSED_01 = 1, CONV_RANGE_REVERSED = 2 };

typedef struct fx {
    glu_ctx g;
    fogvol_context *fv;
    int logged;
    GLuint vao;
} fx;

static void fv_log(void *user, fogvol_log_level level, const char *message)
{
    (void)level;
    (void)message;
    ((fx *)user)->logged++;
}

/* camera looking down -z from the origin; projection and depth convention of the engine */
static void camera(int conv, fogvol_frame_desc *fd)
{
    memset(fd, 0, sizeof *fd);
    glu_identity(fd->view);
    glu_perspective(fd->projection, 60.0, (double)W / H, ZNEAR, ZFAR);
    if (conv == CONV_REVERSED_01) { /* reversed-Z, infinite far: z_clip = near, window depth = near / e */
        fd->projection[10] = 0.0f;
        fd->projection[14] = (float)ZNEAR;
        fd->engine_depth_zero_to_one = 1;
    } else {
        fd->engine_depth_zero_to_one = -1;
    }
    if (conv == CONV_RANGE_REVERSED) {
        fd->engine_depth_range[0] = 1.0f;
        fd->engine_depth_range[1] = 0.0f;
    }
    fd->znear = (float)ZNEAR;
    fd->zfar = (float)ZFAR;
    fd->viewport[2] = W;
    fd->viewport[3] = H;
}

/* window depth of view depth e under the frame's projection and convention (double) */
static float window_depth(const fogvol_frame_desc *fd, double e)
{
    double ndc = ((double)fd->projection[10] * -e + fd->projection[14]) / e, r0 = 0.0, r1 = 1.0;
    if (fd->engine_depth_range[0] != 0.0f || fd->engine_depth_range[1] != 0.0f) {
        r0 = fd->engine_depth_range[0];
        r1 = fd->engine_depth_range[1];
    }
    if (fd->engine_depth_zero_to_one > 0) return (float)(r0 + (r1 - r0) * ndc);
    return (float)(r0 + (r1 - r0) * (ndc + 1.0) * 0.5);
}

static GLuint depth_texture(const fogvol_frame_desc *fd, const double *e)
{
    float *z = (float *)malloc(sizeof(float) * W * H);
    GLuint t;
    int i;
    for (i = 0; i < W * H; ++i) z[i] = window_depth(fd, e[i]);
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, W, H, 0, GL_DEPTH_COMPONENT, GL_FLOAT, z);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(z);
    return t;
}

static GLuint rgba_texture(const unsigned char *px, int linear)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, linear ? GL_LINEAR : GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

static void clear_fb(float r, float g, float b)
{
    glViewport(0, 0, W, H);
    glClearColor(r, g, b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
}

static void save_png(const char *name, const unsigned char *px)
{
    char path[256];
    mkdir("build", 0777);
    mkdir("build/post", 0777);
    snprintf(path, sizeof path, "build/post/%s", name);
    stbi_flip_vertically_on_write(1);
    stbi_write_png(path, W, H, 4, px, W * 4);
}

static int setup(void **state)
{
    fx *x = (fx *)calloc(1, sizeof *x);
    fogvol_context_desc cd;
    if (!x || !glu_create(&x->g, W, H, 1)) return -1;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = fv_log;
    cd.logger.user_data = x;
    if (fogvol_create_context(&cd, &x->fv) != FOGVOL_SUCCESS) return -1;
    glGenVertexArrays(1, &x->vao);
    if (glGetError() != GL_NO_ERROR) return -1;
    *state = x;
    return 0;
}

static int teardown(void **state)
{
    fx *x = (fx *)*state;
    fogvol_destroy_context(x->fv);
    glDeleteVertexArrays(1, &x->vao);
    glu_destroy(&x->g);
    free(x);
    return 0;
}

/* ---- depth of field ----------------------------------------------------------------------------- */
#define FOCUS 6.0
#define RANGE 4.0
#define RADIUS 4.0
#define RADIUS_DISC 6.0

static int in_square(int px, int py) { return px >= 24 && px < 40 && py >= 14 && py < 30; }

/* background at 30 (fully blurred), an in-focus square at 6, a strip at the bottom whose depth
   goes through the focus (partial blur) */
static double dof_depth(int px, int py)
{
    if (in_square(px, py)) return FOCUS;
    if (py < 8) return 3.1 + 0.23 * px;
    return 30.0;
}

static double coc(double e)
{
    double c = fabs(e - FOCUS) / RANGE;
    return c > 1.0 ? 1.0 : c;
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

/* The continuous references. The GPU samples the image at whole-pixel offsets round(o) from a
   pixel centre, i.e. the image as piecewise constant over pixel squares at the exact point p + o.
   Over the rotations of its spiral a tap averages the image over a circle, and the taps' radii
   sqrt((k + 0.5) / taps) R average the circles over the disc: in expectation the disc blur
   (1/(pi r^2)) integral over |q| < r of mix(C0, C(p + q), c(e(p + q))) dq, computed here by the area
   each pixel square shares with the disc (a 16 x 16 grid per square), image clamped at its edges.
   weighted = 0: every point with weight 1 (the halo-prone blur of the in-focus square). */
static void disc_blur(const unsigned char *src, const double *e, double radius_of_coc, int weighted, double *out)
{
    int px, py, c;
    for (py = 0; py < H; ++py)
        for (px = 0; px < W; ++px) {
            int i = py * W + px, dx, dy, ext;
            double r = coc(e[i]) * radius_of_coc, sum[4] = {0, 0, 0, 0}, wsum = 0;
            if (r <= 0) {
                for (c = 0; c < 4; ++c) out[4 * i + c] = src[4 * i + c];
                continue;
            }
            ext = (int)ceil(r + 0.5);
            for (dy = -ext; dy <= ext; ++dy)
                for (dx = -ext; dx <= ext; ++dx) {
                    int j = clampi(py + dy, 0, H - 1) * W + clampi(px + dx, 0, W - 1), su, sv, inside = 0;
                    double w;
                    for (sv = 0; sv < 16; ++sv)
                        for (su = 0; su < 16; ++su) {
                            double qx = dx - 0.5 + (su + 0.5) / 16.0, qy = dy - 0.5 + (sv + 0.5) / 16.0;
                            inside += qx * qx + qy * qy < r * r;
                        }
                    if (!inside) continue;
                    w = inside / 256.0;
                    wsum += w;
                    for (c = 0; c < 4; ++c) {
                        double k = weighted ? coc(e[j]) : 1.0;
                        sum[c] += w * (src[4 * i + c] + (src[4 * j + c] - src[4 * i + c]) * k);
                    }
                }
            for (c = 0; c < 4; ++c) out[4 * i + c] = sum[c] / wsum;
        }
}

/* fogvol 0.2's kernel, for the figures of what it did: fixed directions (3: a triangle, 6: + the
   opposite one, 12: + a half-radius hexagon) at round(r dir_k), out = (C0 + sum_k ...) / (taps + 1) */
static void old_kernel(const unsigned char *src, const double *e, int taps, double radius, double *out)
{
    static const double dir[12][2] = {{0.0, 1.0},   {-0.8660254, -0.5}, {0.8660254, -0.5}, {0.0, -1.0},
                                      {0.8660254, 0.5}, {-0.8660254, 0.5}, {0.5, 0.0},     {0.25, 0.4330127},
                                      {-0.25, 0.4330127}, {-0.5, 0.0},   {-0.25, -0.4330127}, {0.25, -0.4330127}};
    int px, py, k, c;
    for (py = 0; py < H; ++py)
        for (px = 0; px < W; ++px) {
            int i = py * W + px;
            double r = coc(e[i]) * radius, sum[4];
            for (c = 0; c < 4; ++c) sum[c] = src[4 * i + c];
            for (k = 0; k < taps; ++k) {
                int qx = clampi(px + (int)floor(dir[k][0] * r + 0.5), 0, W - 1);
                int qy = clampi(py + (int)floor(dir[k][1] * r + 0.5), 0, H - 1), j = qy * W + qx;
                for (c = 0; c < 4; ++c) sum[c] += src[4 * i + c] + (src[4 * j + c] - src[4 * i + c]) * coc(e[j]);
            }
            for (c = 0; c < 4; ++c) out[4 * i + c] = sum[c] / (taps + 1);
        }
}

/* error figures of an RGBA picture against a reference over the pixels at least m from the edges:
   per-pixel max and RMS, and the max of 4x4 block means (what the eye takes in at a glance) */
typedef struct dof_err {
    double max, rms, block;
} dof_err;

static dof_err dof_compare(const double *got, const double *ref, int m)
{
    dof_err r = {0, 0, 0};
    int px, py, c, n = 0;
    for (py = m; py < H - m; ++py)
        for (px = m; px < W - m; ++px)
            for (c = 0; c < 3; ++c) {
                double d = got[4 * (py * W + px) + c] - ref[4 * (py * W + px) + c];
                r.max = fmax(r.max, fabs(d));
                r.rms += d * d;
                ++n;
            }
    r.rms = sqrt(r.rms / n);
    for (py = m; py + 4 <= H - m; py += 2)
        for (px = m; px + 4 <= W - m; px += 2)
            for (c = 0; c < 3; ++c) {
                double sum = 0;
                int u, v;
                for (v = 0; v < 4; ++v)
                    for (u = 0; u < 4; ++u) sum += got[4 * ((py + v) * W + px + u) + c] - ref[4 * ((py + v) * W + px + u) + c];
                r.block = fmax(r.block, fabs(sum / 16.0));
            }
    return r;
}

static void dof_scene(unsigned char *src, double *e)
{
    int px, py;
    for (py = 0; py < H; ++py)
        for (px = 0; px < W; ++px) {
            unsigned char *p = src + 4 * (py * W + px);
            e[py * W + px] = dof_depth(px, py);
            if (in_square(px, py)) {
                p[0] = 250, p[1] = 30, p[2] = 20;
            } else { /* a busy background: blurring shows */
                p[0] = (unsigned char)((px * 37 + py * 11) % 200);
                p[1] = (unsigned char)(((px / 2 + py / 2) % 2) * 180 + 40);
                p[2] = (unsigned char)((px * 7 + py * 29) % 256);
            }
            p[3] = 255;
        }
}

/* The GPU's picture of fogvol_post_dof: one frame (dither_frame = frame) into px (bytes as doubles);
   with frames > 1 the mean of dither_frame 1 .. frames (what an engine accumulating frames sees) */
static void dof_run(fx *x, fogvol_dof_desc *dd, fogvol_frame_desc *fd, int frames, double *px)
{
    int f, i;
    for (i = 0; i < 4 * W * H; ++i) px[i] = 0.0;
    for (f = frames > 1 ? 1 : 0; f <= (frames > 1 ? frames : 0); ++f) {
        fd->dither_frame = f;
        clear_fb(0, 0, 0);
        assert_int_equal(fogvol_post_dof(x->fv, dd), FOGVOL_SUCCESS);
        glu_pixels(&x->g);
        for (i = 0; i < 4 * W * H; ++i) px[i] += x->g.pixels[i] / (double)(frames > 1 ? frames : 1);
    }
    fd->dither_frame = 0;
}

/* Edge preservation: an in-focus square keeps its colour exactly, and the blurred background next to it
   takes none of it: the GPU (one frame; the mean of 8) follows the weighted disc blur, which an
   unweighted blur misses by > 40/255 there (a halo of the square's red). */
static void test_dof(void **state)
{
    fx *x = (fx *)*state;
    static const int tapset[5] = {3, 6, 12, 24, 48};
    unsigned char *src = (unsigned char *)malloc(4 * W * H);
    double *e = (double *)malloc(sizeof(double) * W * H), *ref = (double *)malloc(sizeof(double) * 4 * W * H),
           *naive = (double *)malloc(sizeof(double) * 4 * W * H), *px = (double *)malloc(sizeof(double) * 4 * W * H);
    fogvol_frame_desc fd;
    fogvol_dof_desc dd;
    GLuint tc, tdep;
    int t, i, c, frames;
    dof_scene(src, e);
    camera(CONV_GL, &fd);
    tc = rgba_texture(src, 1); /* a filtered texture: the taps land on texel centres */
    tdep = depth_texture(&fd, e);
    fd.engine_depth_texture = tdep;
    disc_blur(src, e, RADIUS, 1, ref);
    disc_blur(src, e, RADIUS, 0, naive);
    for (t = 0; t < 5; ++t)
        for (frames = 1; frames <= 8; frames += 7) {
            double halo_naive = 0.0, halo_gpu = 0.0, near_err = 0.0;
            int square_exact = 1, near_edge = 0;
            memset(&dd, 0, sizeof dd);
            dd.frame = &fd;
            dd.color_texture = tc;
            dd.focus_distance = (float)FOCUS;
            dd.focus_range = (float)RANGE;
            dd.max_radius = (float)RADIUS;
            dd.taps = tapset[t];
            dof_run(x, &dd, &fd, frames, px);
            for (i = 0; i < W * H; ++i) {
                int pxl = i % W, py = i / W;
                int bg_near = !in_square(pxl, py) && py >= 8 && pxl >= 20 && pxl < 44 && py >= 10 && py < 34;
                for (c = 0; c < 4; ++c) {
                    if (in_square(pxl, py) && px[4 * i + c] != src[4 * i + c]) square_exact = 0;
                    if (!bg_near || c == 3) continue;
                    /* the red channel: how much of the square's colour came in, on average */
                    if (c == 0) {
                        halo_naive += naive[4 * i] - ref[4 * i];
                        halo_gpu += px[4 * i] - ref[4 * i];
                    }
                    near_err += fabs(px[4 * i + c] - ref[4 * i + c]);
                }
                near_edge += bg_near;
            }
            halo_naive /= near_edge;
            halo_gpu /= near_edge;
            print_message("# dof %2d taps, %d frame%s: in-focus square exact %d; next to it (%d pixels) red above the "
                          "weighted disc blur, mean: GPU %+.1f/255, an unweighted blur %+.1f/255; mean |GPU - weighted| "
                          "%.1f/255\n", tapset[t], frames, frames > 1 ? "s" : "", square_exact, near_edge,
                          halo_gpu, halo_naive, near_err / (3.0 * near_edge));
            assert_true(square_exact);                        /* in focus: untouched */
            assert_true(near_edge > 100 && halo_naive > 20.0); /* the weighting is what keeps the edge clean */
            assert_true(fabs(halo_gpu) < 3.0);
            if (t == 2 && frames == 1) {
                unsigned char *b = (unsigned char *)malloc(4 * W * H);
                for (i = 0; i < 4 * W * H; ++i) b[i] = (unsigned char)(px[i] + 0.5);
                save_png("dof.png", b);
                free(b);
            }
        }
    save_png("dof_source.png", src);
    glDeleteTextures(1, &tc);
    glDeleteTextures(1, &tdep);
    free(src);
    free(e);
    free(ref);
    free(naive);
    free(px);
}

/* Against a continuous disc blur: a fully blurred plane (c = 1, radius RADIUS_DISC) with a
   high-contrast checkerboard and a diagonal edge. Per tap count: one frame's grain (RMS), the largest
   4x4 block-mean error (copies of the taps or a pattern would show there), and the mean of 8 frames;
   fogvol 0.2's fixed kernel (computed here) for comparison. */
static void test_dof_disc(void **state)
{
    fx *x = (fx *)*state;
    static const int tapset[4] = {6, 12, 24, 48};
    /* bounds (/255): the mean of 64 frames (the kernel's expectation: copies of taps would stay there)
       per pixel, and one frame's 4x4 block means (grain averaged as the eye does at a glance) */
    static const double mean64_bound[4] = {12.0, 9.0, 5.0, 3.0}, block_bound[4] = {22.0, 14.0, 8.0, 5.0};
    unsigned char *src = (unsigned char *)malloc(4 * W * H), *b = (unsigned char *)malloc(4 * W * H * 3);
    double *e = (double *)malloc(sizeof(double) * W * H), *ref = (double *)malloc(sizeof(double) * 4 * W * H),
           *px = (double *)malloc(sizeof(double) * 4 * W * H), *old = (double *)malloc(sizeof(double) * 4 * W * H);
    fogvol_frame_desc fd;
    fogvol_dof_desc dd;
    GLuint tc, tdep;
    int t, i, k, m = (int)RADIUS_DISC + 1;
    dof_err e1, e8, e64, eo[2];
    for (i = 0; i < W * H; ++i) {
        int px_ = i % W, py = i / W, on = ((px_ / 6) + (py / 6)) % 2, edge = px_ + 2 * py > 80;
        e[i] = 30.0;
        src[4 * i + 0] = (unsigned char)(on ? 220 : 35);
        src[4 * i + 1] = (unsigned char)(edge ? 200 : 60);
        src[4 * i + 2] = (unsigned char)(on != edge ? 180 : 50);
        src[4 * i + 3] = 255;
    }
    camera(CONV_GL, &fd);
    tc = rgba_texture(src, 0);
    tdep = depth_texture(&fd, e);
    fd.engine_depth_texture = tdep;
    disc_blur(src, e, RADIUS_DISC, 1, ref);
    for (k = 0; k < 2; ++k) {
        old_kernel(src, e, k ? 12 : 6, RADIUS_DISC, old);
        eo[k] = dof_compare(old, ref, m);
    }
    print_message("# dof against a continuous disc blur (radius %.0f px, every pixel fully blurred): fogvol 0.2's "
                  "fixed kernel: 6 taps max %.1f, RMS %.1f, 4x4 blocks %.1f; 12 taps max %.1f, RMS %.1f, 4x4 blocks "
                  "%.1f (/255)\n", RADIUS_DISC, eo[0].max, eo[0].rms, eo[0].block, eo[1].max, eo[1].rms, eo[1].block);
    for (t = 0; t < 4; ++t) {
        memset(&dd, 0, sizeof dd);
        dd.frame = &fd;
        dd.color_texture = tc;
        dd.focus_distance = (float)FOCUS;
        dd.focus_range = (float)RANGE;
        dd.max_radius = (float)RADIUS_DISC;
        dd.taps = tapset[t];
        dof_run(x, &dd, &fd, 1, px);
        e1 = dof_compare(px, ref, m);
        if (t == 1)
            for (i = 0; i < 4 * W * H; ++i) b[i] = (unsigned char)(px[i] + 0.5);
        dof_run(x, &dd, &fd, 8, px);
        e8 = dof_compare(px, ref, m);
        dof_run(x, &dd, &fd, 64, px);
        e64 = dof_compare(px, ref, m);
        print_message("# dof %2d taps: one frame: max %.1f, RMS %.1f (grain), 4x4 blocks %.1f; mean of 8 frames "
                      "(dither_frame 1..8): max %.1f, RMS %.1f, 4x4 blocks %.1f; of 64: max %.1f, RMS %.1f, 4x4 "
                      "blocks %.1f (/255; bounds: one frame's blocks %.0f, 64 frames' max %.0f)\n",
                      tapset[t], e1.max, e1.rms, e1.block, e8.max, e8.rms, e8.block, e64.max, e64.rms, e64.block,
                      block_bound[t], mean64_bound[t]);
        assert_true(e1.block <= block_bound[t]);
        assert_true(e64.max <= mean64_bound[t]);
        if (t <= 1) assert_true(eo[t].max > mean64_bound[t]); /* the old kernel's copies never average away */
    }
    { /* source | reference | 12 taps, one frame */
        unsigned char *row = (unsigned char *)malloc(4 * W * H * 3);
        int y;
        for (y = 0; y < H; ++y)
            for (i = 0; i < W; ++i)
                for (k = 0; k < 4; ++k) {
                    row[4 * (y * 3 * W + i) + k] = src[4 * (y * W + i) + k];
                    row[4 * (y * 3 * W + W + i) + k] = (unsigned char)(ref[4 * (y * W + i) + k] + 0.5);
                    row[4 * (y * 3 * W + 2 * W + i) + k] = b[4 * (y * W + i) + k];
                }
        mkdir("build", 0777);
        mkdir("build/post", 0777);
        stbi_flip_vertically_on_write(1);
        stbi_write_png("build/post/dof_disc.png", 3 * W, H, 4, row, 3 * W * 4);
        free(row);
    }
    glDeleteTextures(1, &tc);
    glDeleteTextures(1, &tdep);
    free(src);
    free(b);
    free(e);
    free(ref);
    free(px);
    free(old);
}

/* ---- outlines ----------------------------------------------------------------------------------- */
#define DEPTH_THR 0.05
#define NORMAL_THR 0.3

/* a sloped plane (1/e linear across the screen: 1/e = 0.05 + 0.0011 x + 0.0007 y, e 20 .. 9.5) with
   a box at e = 5 in front of it */
static int in_box(int px, int py) { return px >= 20 && px < 36 && py >= 12 && py < 30; }
static double outline_depth(int px, int py)
{
    return in_box(px, py) ? 5.0 : 1.0 / (0.05 + 0.0011 * (px + 0.5) + 0.0007 * (py + 0.5));
}

/* the CPU reference: 1 where an outline goes (depth; normals when n is given) */
static void outline_reference(const double *e, const double (*n)[3], unsigned char *mask)
{
    static const int line[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
    int px, py, k, i, j;
    for (py = 0; py < H; ++py)
        for (px = 0; px < W; ++px) {
            double g0 = 1.0 / e[py * W + px], d = 0.0, m = 0.0;
            for (k = 0; k < 4; ++k) {
                int ax = px + line[k][0], ay = py + line[k][1], bx = px - line[k][0], by = py - line[k][1];
                if (ax < 0 || bx < 0 || ay < 0 || by < 0 || ax >= W || bx >= W || ay >= H || by >= H) continue;
                d = fmax(d, fabs(1.0 / e[ay * W + ax] + 1.0 / e[by * W + bx] - 2.0 * g0));
            }
            if (n)
                for (j = -1; j <= 1; ++j)
                    for (i = -1; i <= 1; ++i) {
                        const double *a = n[py * W + px], *b = n[clampi(py + j, 0, H - 1) * W + clampi(px + i, 0, W - 1)];
                        m = fmax(m, 1.0 - (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]));
                    }
            mask[py * W + px] = d > DEPTH_THR * g0 || m > NORMAL_THR;
        }
}

/* outlines drawn black over white: returns the number of pixels where GPU and CPU disagree */
static int outline_run(fx *x, const fogvol_frame_desc *fd, fogvol_native normals, const unsigned char *mask)
{
    fogvol_outline_desc od;
    int i, bad = 0;
    memset(&od, 0, sizeof od);
    od.frame = fd;
    od.normal_texture = normals;
    od.depth_threshold = (float)DEPTH_THR;
    od.normal_threshold = (float)NORMAL_THR;
    clear_fb(1, 1, 1);
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_SUCCESS);
    glu_pixels(&x->g);
    for (i = 0; i < W * H; ++i) {
        const unsigned char *p = x->g.pixels + 4 * i;
        int black = p[0] == 0 && p[1] == 0 && p[2] == 0, white = p[0] == 255 && p[1] == 255 && p[2] == 255;
        if (!(mask[i] ? black : white)) ++bad;
    }
    return bad;
}

static void test_outlines_depth(void **state)
{
    fx *x = (fx *)*state;
    double *e = (double *)malloc(sizeof(double) * W * H);
    unsigned char mask[W * H];
    fogvol_frame_desc fd;
    GLuint tdep;
    int i, bad, lines = 0, off_edge = 0, edge_missed = 0;
    for (i = 0; i < W * H; ++i) e[i] = outline_depth(i % W, i / W);
    camera(CONV_GL, &fd);
    tdep = depth_texture(&fd, e);
    fd.engine_depth_texture = tdep;
    outline_reference(e, NULL, mask);
    for (i = 0; i < W * H; ++i) { /* the reference itself: outlines exactly on the box's border pixels */
        int px = i % W, py = i / W, border = 0, dx, dy;
        for (dy = -1; dy <= 1; ++dy)
            for (dx = -1; dx <= 1; ++dx)
                if (px + dx >= 0 && px + dx < W && py + dy >= 0 && py + dy < H &&
                    in_box(px + dx, py + dy) != in_box(px, py))
                    border = 1;
        lines += mask[i];
        off_edge += mask[i] && !border;
        edge_missed += border && !mask[i] && (px > 0 && py > 0 && px < W - 1 && py < H - 1);
    }
    assert_int_equal(off_edge, 0);
    assert_int_equal(edge_missed, 0);
    bad = outline_run(x, &fd, 0, mask);
    printf("# outlines (depth): %d outline pixels, %d pixels where GPU and CPU differ, none on the slope\n", lines,
           bad);
    save_png("outlines_depth.png", x->g.pixels);
    assert_true(lines > 60);
    assert_int_equal(bad, 0);
    glDeleteTextures(1, &tdep);
    free(e);
}

/* a flat plane at e = 10 whose normals crease along x = 32 (facing +z left, tilted right), and a
   smooth normal ramp at the top that stays below the threshold */
static void test_outlines_normals(void **state)
{
    fx *x = (fx *)*state;
    double *e = (double *)malloc(sizeof(double) * W * H), (*n)[3] = (double (*)[3])malloc(sizeof(double) * 3 * W * H);
    unsigned char mask[W * H], *np = (unsigned char *)malloc(4 * W * H);
    fogvol_frame_desc fd;
    GLuint tdep, tn;
    int i, c, bad, lines = 0;
    for (i = 0; i < W * H; ++i) {
        int px = i % W, py = i / W;
        double a = py >= 36 ? 0.02 * px : px < 32 ? 0.0 : 1.0; /* angle about y (radians) */
        double v[3] = {sin(a), 0.0, cos(a)};
        e[i] = 10.0;
        for (c = 0; c < 3; ++c) {
            np[4 * i + c] = (unsigned char)floor((v[c] * 0.5 + 0.5) * 255.0 + 0.5);
            n[i][c] = np[4 * i + c] / 255.0 * 2.0 - 1.0; /* what the texture holds */
        }
        np[4 * i + 3] = 255;
        {
            double l = sqrt(n[i][0] * n[i][0] + n[i][1] * n[i][1] + n[i][2] * n[i][2]);
            for (c = 0; c < 3; ++c) n[i][c] /= l;
        }
    }
    camera(CONV_GL, &fd);
    tdep = depth_texture(&fd, e);
    tn = rgba_texture(np, 0);
    fd.engine_depth_texture = tdep;
    outline_reference(e, (const double (*)[3])n, mask);
    for (i = 0; i < W * H; ++i) {
        int px = i % W, py = i / W;
        lines += mask[i];
        if (py < 35) assert_int_equal(mask[i], px == 31 || px == 32); /* the crease, both sides */
        else if (py > 36) assert_int_equal(mask[i], 0);              /* the smooth ramp */
    }
    bad = outline_run(x, &fd, tn, mask);
    printf("# outlines (normals): %d outline pixels, %d pixels where GPU and CPU differ\n", lines, bad);
    save_png("outlines_normals.png", x->g.pixels);
    assert_int_equal(bad, 0);
    glDeleteTextures(1, &tdep);
    glDeleteTextures(1, &tn);
    free(e);
    free(n);
    free(np);
}

/* ---- distance fog ------------------------------------------------------------------------------- */
#define FOG_DENSITY 0.06
#define FOG_START 3.0
#define RAMP_W 256

/* view depth across the picture: 1.5 .. 63 (beyond the ramp's end at 7 / density + start) */
static double fog_depth(int px, int py) { return 1.5 + 0.8 * px + 0.25 * py; }

/* the ramp's alpha at thickness t: the analytic extinction at the texels, rounded to bytes, and
   interpolated linearly between them like the filtered lookup */
static double ramp_alpha(double t)
{
    double tmax = 7.0 / FOG_DENSITY, u = t / tmax * (RAMP_W - 1), f;
    int i;
    if (u >= RAMP_W - 1) u = RAMP_W - 1;
    i = (int)floor(u);
    if (i >= RAMP_W - 1) i = RAMP_W - 2;
    f = u - i;
    return floor((1.0 - exp(-FOG_DENSITY * i / (RAMP_W - 1.0) * tmax)) * 255.0 + 0.5) * (1.0 - f) +
           floor((1.0 - exp(-FOG_DENSITY * (i + 1) / (RAMP_W - 1.0) * tmax)) * 255.0 + 0.5) * f;
}

static void fog_case(fx *x, fogvol_ramp *ramp, int conv, int offset, double *maxerr)
{
    static const double fogc[3] = {0.8, 0.85, 0.9}, bg[3] = {0.2, 0.4, 0.1};
    double *e = (double *)malloc(sizeof(double) * W * H);
    fogvol_frame_desc fd;
    fogvol_distance_fog_desc dd;
    GLuint tdep;
    int i, c, outside_changed = 0;
    unsigned char bgpx[4];
    for (i = 0; i < W * H; ++i) e[i] = fog_depth(i % W, i / W);
    camera(conv, &fd);
    tdep = depth_texture(&fd, e);
    fd.engine_depth_texture = tdep;
    if (offset) { /* a viewport inside the framebuffer: its own NDC, the same texels */
        double fy = 1.0 / tan(30.0 * 3.14159265358979323846 / 180.0);
        fd.viewport[0] = 8, fd.viewport[1] = 4, fd.viewport[2] = 48, fd.viewport[3] = 40;
        fd.projection[0] = (float)(fy * 40.0 / 48.0);
    }
    memset(&dd, 0, sizeof dd);
    dd.frame = &fd;
    dd.ramp = ramp;
    dd.start = (float)FOG_START;
    if (offset) dd.texture_size[0] = W, dd.texture_size[1] = H;
    clear_fb((float)bg[0], (float)bg[1], (float)bg[2]);
    memcpy(bgpx, glu_pixels(&x->g), 4); /* the engine's picture as the framebuffer stores it */
    assert_int_equal(fogvol_post_distance_fog(x->fv, &dd), FOGVOL_SUCCESS);
    glu_pixels(&x->g);
    *maxerr = 0.0;
    for (i = 0; i < W * H; ++i) {
        int px = i % W, py = i / W, inside = px >= fd.viewport[0] && px < fd.viewport[0] + fd.viewport[2] &&
                                             py >= fd.viewport[1] && py < fd.viewport[1] + fd.viewport[3];
        double t = e[i] - FOG_START, a = ramp_alpha(t < 0.0 ? 0.0 : t) / 255.0;
        for (c = 0; c < 3; ++c) {
            double bgb = bgpx[c], fb = floor((double)(float)fogc[c] * 255.0 + 0.5); /* the ramp's float colour */
            double want = inside ? bgb + (fb - bgb) * a : bgb;
            double d = fabs(x->g.pixels[4 * i + c] - want);
            if (d > *maxerr) *maxerr = d;
            if (!inside && d != 0.0) ++outside_changed;
        }
    }
    if (conv == CONV_REVERSED_01) save_png("distance_fog.png", x->g.pixels);
    assert_int_equal(outside_changed, 0);
    glDeleteTextures(1, &tdep);
    free(e);
}

static void test_distance_fog(void **state)
{
    fx *x = (fx *)*state;
    static const char *const names[4] = {"GL [-1,1]", "reversed-Z [0,1], infinite far", "glDepthRange(1, 0)",
                                         "GL [-1,1], viewport (8,4,48,40)"};
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    double err;
    int k;
    memset(&rd, 0, sizeof rd);
    rd.model = FOGVOL_RAMP_EXTINCTION;
    rd.color[0] = 0.8f, rd.color[1] = 0.85f, rd.color[2] = 0.9f;
    rd.density = (float)FOG_DENSITY;
    rd.width = RAMP_W;
    assert_int_equal(fogvol_create_ramp(x->fv, &rd, &ramp), FOGVOL_SUCCESS);
    for (k = 0; k < 4; ++k) {
        fog_case(x, ramp, k == 3 ? CONV_GL : k, k == 3, &err);
        printf("# distance fog, %-32s max |GPU - CPU| = %.3f /255\n", names[k], err);
        assert_true(err <= 1.5);
    }
    fogvol_destroy_ramp(x->fv, ramp);
}

/* ---- bad input ---------------------------------------------------------------------------------- */
static void test_bad_input(void **state)
{
    fx *x = (fx *)*state;
    fogvol_frame_desc fd;
    fogvol_dof_desc dd;
    fogvol_outline_desc od;
    fogvol_distance_fog_desc gd;
    int before;
    camera(CONV_GL, &fd);
    memset(&dd, 0, sizeof dd);
    memset(&od, 0, sizeof od);
    memset(&gd, 0, sizeof gd);
    dd.frame = od.frame = gd.frame = &fd;
    dd.color_texture = 1;
    dd.focus_distance = 5.0f;
    dd.focus_range = 1.0f;
    before = x->logged;
    assert_int_equal(fogvol_post_dof(NULL, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_post_dof(x->fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_post_outlines(x->fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_post_distance_fog(x->fv, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* no depth texture */
    assert_int_equal(fogvol_post_dof(x->fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.engine_depth_texture = 1;
    assert_int_equal(fogvol_post_distance_fog(x->fv, &gd), FOGVOL_ERROR_INVALID_ARGUMENT); /* no ramp */
    dd.taps = 5;
    assert_int_equal(fogvol_post_dof(x->fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    dd.taps = 96;
    assert_int_equal(fogvol_post_dof(x->fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    dd.taps = 0;
    dd.focus_range = 0.0f;
    assert_int_equal(fogvol_post_dof(x->fv, &dd), FOGVOL_ERROR_INVALID_ARGUMENT);
    od.texture_size[0] = W - 1; /* smaller than the viewport */
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_ERROR_INVALID_ARGUMENT);
    od.texture_size[0] = 0;
    od.frame = NULL;
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_ERROR_INVALID_ARGUMENT);
    od.frame = &fd;
    fd.zfar = fd.znear;
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.zfar = (float)ZFAR;
    assert_int_equal(fogvol_begin_frame(x->fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_post_outlines(x->fv, &od), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_cancel_frame(x->fv), FOGVOL_SUCCESS);
    assert_true(x->logged - before >= 11); /* every refusal with a context says why */
    assert_int_equal(glGetError(), GL_NO_ERROR);
    { /* a multisample depth texture (a 4x framebuffer's), with a 2D texture of the engine's left on a unit:
         refused before drawing, nothing drawn, no GL error left (the pass bound neither, drew fog from the
         texture left on the unit, then failed) */
        static const float left_depth = 0.999f;
        unsigned char *a = (unsigned char *)malloc((size_t)W * H * 4), *b = (unsigned char *)malloc((size_t)W * H * 4);
        fogvol_ramp_desc rd;
        fogvol_ramp *ramp;
        GLuint ms, t2;
        int u;
        memset(&rd, 0, sizeof rd);
        rd.color[0] = 1.0f;
        rd.density = 0.5f;
        assert_int_equal(fogvol_create_ramp(x->fv, &rd, &ramp), FOGVOL_SUCCESS);
        glGenTextures(1, &ms);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, ms);
        glTexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, 4, GL_DEPTH_COMPONENT24, W, H, GL_TRUE);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
        glGenTextures(1, &t2);
        for (u = 0; u < 4; ++u) { /* (on every unit fogvol might use) */
            glActiveTexture((GLenum)(GL_TEXTURE0 + u));
            glBindTexture(GL_TEXTURE_2D, t2);
        }
        glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, 1, 1, 0, GL_RED, GL_FLOAT, &left_depth);
        glActiveTexture(GL_TEXTURE0);
        fd.engine_depth_texture = ms;
        gd.ramp = ramp;
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, a);
        before = x->logged;
        assert_int_equal(fogvol_post_distance_fog(x->fv, &gd), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_true(x->logged > before);
        assert_int_equal(glGetError(), GL_NO_ERROR);
        glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, b);
        assert_memory_equal(a, b, (size_t)W * H * 4);
        glDeleteTextures(1, &ms);
        glDeleteTextures(1, &t2);
        fogvol_destroy_ramp(x->fv, ramp);
        free(a);
        free(b);
    }
}

/* backends that cannot: no highp fragment shaders, no depth textures, an unknown dialect */
static void test_unsupported(void **state)
{
    static const unsigned caps[3] = {FOGVOL_CAP_DEPTH_TEXTURE, FOGVOL_CAP_HIGHP_FRAGMENT,
                                     FOGVOL_CAP_DEPTH_TEXTURE | FOGVOL_CAP_HIGHP_FRAGMENT};
    fx *x = (fx *)*state;
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *ctx;
    fogvol_frame_desc fd;
    fogvol_outline_desc od;
    int k, before;
    camera(CONV_GL, &fd);
    fd.engine_depth_texture = 1;
    memset(&od, 0, sizeof od);
    od.frame = &fd;
    for (k = 0; k < 3; ++k) {
        memset(&cd, 0, sizeof cd);
        fogvol_null_backend_init(&nb, &cd.backend);
        cd.backend.caps = caps[k];
        cd.tier = FOGVOL_TIER_PS13;
        cd.logger.func = fv_log;
        cd.logger.user_data = x;
        assert_int_equal(fogvol_create_context(&cd, &ctx), FOGVOL_SUCCESS);
        if (k == 2) ctx->be.dialect = (fogvol_dialect)42; /* a backend that reports no known dialect */
        before = x->logged;
        assert_int_equal(fogvol_post_outlines(ctx, &od), FOGVOL_ERROR_UNSUPPORTED);
        assert_int_equal(x->logged, before + 1);
        assert_int_equal(nb.pass_count, 0);
        ctx->be.dialect = FOGVOL_GLSL_330;
        fogvol_destroy_context(ctx);
    }
    /* the same null backend with both caps draws one full-screen pass into the engine framebuffer */
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    assert_int_equal(fogvol_create_context(&cd, &ctx), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_post_outlines(ctx, &od), FOGVOL_SUCCESS);
    assert_int_equal(nb.pass_count, 1);
    assert_int_equal(nb.fullscreen[0], 1);
    assert_true(nb.passes[0].target == 0 && nb.passes[0].native_textures[1] == 1);
    assert_int_equal(nb.frames_begun, nb.frames_ended);
    fogvol_destroy_context(ctx);
    assert_int_equal(nb.creates, nb.destroys);
}

/* ---- engine GL state ---------------------------------------------------------------------------- */
typedef struct snap {
    GLint v[40];
} snap;

static void snapshot(snap *s)
{
    static const GLenum ints[] = {GL_CURRENT_PROGRAM, GL_ACTIVE_TEXTURE, GL_DRAW_FRAMEBUFFER_BINDING,
                                  GL_READ_FRAMEBUFFER_BINDING, GL_VERTEX_ARRAY_BINDING, GL_ARRAY_BUFFER_BINDING,
                                  GL_BLEND_SRC_RGB, GL_BLEND_DST_RGB, GL_BLEND_SRC_ALPHA, GL_BLEND_DST_ALPHA,
                                  GL_BLEND_EQUATION_RGB, GL_DEPTH_FUNC, GL_DEPTH_WRITEMASK, GL_CULL_FACE_MODE,
                                  GL_FRONT_FACE};
    static const GLenum caps[] = {GL_BLEND, GL_DEPTH_TEST, GL_CULL_FACE, GL_SCISSOR_TEST, GL_STENCIL_TEST,
                                  GL_DITHER};
    GLint u;
    int n = 0, i;
    memset(s, 0, sizeof *s);
    for (i = 0; i < (int)(sizeof ints / sizeof ints[0]); ++i) glGetIntegerv(ints[i], &s->v[n++]);
    for (i = 0; i < (int)(sizeof caps / sizeof caps[0]); ++i) s->v[n++] = glIsEnabled(caps[i]);
    glGetIntegerv(GL_VIEWPORT, &s->v[n]);
    n += 4;
    glGetIntegerv(GL_SCISSOR_BOX, &s->v[n]);
    n += 4;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &u);
    for (i = 0; i < 4; ++i) { /* the textures bound on units 0..3 */
        glActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &s->v[n++]);
    }
    glActiveTexture((GLenum)u);
    {
        GLboolean cm[4];
        glGetBooleanv(GL_COLOR_WRITEMASK, cm);
        s->v[n++] = cm[0] | cm[1] << 1 | cm[2] << 2 | cm[3] << 3;
    }
}

/* the engine's state: none of it fogvol's choice */
static void engine_state_set(const GLuint tex[3], GLuint buf, GLuint vao)
{
    int i;
    for (i = 0; i < 3; ++i) {
        glActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glBindTexture(GL_TEXTURE_2D, tex[i]);
    }
    glActiveTexture(GL_TEXTURE3);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, buf);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_SRC_COLOR, GL_DST_ALPHA, GL_ZERO);
    glBlendEquation(GL_MAX);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    glFrontFace(GL_CW);
    glEnable(GL_SCISSOR_TEST);
    glScissor(3, 4, 20, 21);
    glViewport(1, 2, 30, 31);
    glColorMask(1, 0, 1, 1);
    glDisable(GL_DITHER);
    glEnable(GL_STENCIL_TEST);
}

static void engine_state_reset(void)
{
    int i;
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ZERO);
    glDisable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
    glColorMask(1, 1, 1, 1);
    glEnable(GL_DITHER);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    for (i = 0; i < 4; ++i) {
        glActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glBindTexture(GL_TEXTURE_2D, 0);
    }
}

static void test_gl_state(void **state)
{
    fx *x = (fx *)*state;
    unsigned char src[4 * W * H];
    double *e = (double *)malloc(sizeof(double) * W * H);
    fogvol_frame_desc fd;
    fogvol_dof_desc dd;
    fogvol_outline_desc od;
    fogvol_distance_fog_desc gd;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    snap a, b;
    GLuint tex[3], tdep, buf, tc;
    int i, k;
    dof_scene(src, e);
    camera(CONV_GL, &fd);
    tdep = depth_texture(&fd, e);
    tc = rgba_texture(src, 0);
    fd.engine_depth_texture = tdep;
    memset(&rd, 0, sizeof rd);
    rd.density = 0.1f;
    assert_int_equal(fogvol_create_ramp(x->fv, &rd, &ramp), FOGVOL_SUCCESS);
    glGenTextures(3, tex);
    glGenBuffers(1, &buf);
    engine_state_set(tex, buf, x->vao);
    snapshot(&a);
    for (k = 0; k < 3; ++k) {
        fogvol_result r;
        memset(&dd, 0, sizeof dd);
        memset(&od, 0, sizeof od);
        memset(&gd, 0, sizeof gd);
        dd.frame = od.frame = gd.frame = &fd;
        dd.color_texture = tc;
        dd.focus_distance = 6.0f;
        dd.focus_range = 2.0f;
        gd.ramp = ramp;
        r = k == 0 ? fogvol_post_dof(x->fv, &dd) : k == 1 ? fogvol_post_outlines(x->fv, &od)
                                                            : fogvol_post_distance_fog(x->fv, &gd);
        assert_int_equal(r, FOGVOL_SUCCESS);
        snapshot(&b);
        for (i = 0; i < 40; ++i)
            if (a.v[i] != b.v[i]) printf("# effect %d: state %d was %d, is %d\n", k, i, a.v[i], b.v[i]);
        assert_memory_equal(&a, &b, sizeof a);
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    engine_state_reset();
    glActiveTexture(GL_TEXTURE0);
    glDeleteTextures(3, tex);
    glDeleteTextures(1, &tdep);
    glDeleteTextures(1, &tc);
    glDeleteBuffers(1, &buf);
    fogvol_destroy_ramp(x->fv, ramp);
    free(e);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dof),
        cmocka_unit_test(test_dof_disc),
        cmocka_unit_test(test_outlines_depth),
        cmocka_unit_test(test_outlines_normals),
        cmocka_unit_test(test_distance_fog),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_unsupported),
        cmocka_unit_test(test_gl_state),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
