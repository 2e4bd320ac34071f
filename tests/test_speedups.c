/* test_speedups.c - the speed-ups fogvol turns on by default (FOGVOL_SPEEDUP_*):
   SKIP_OPAQUE, TEXEL_FETCH and SPECIALIZE
   (programs built per configuration) and ALU (PS20 encodes by arithmetic) give the same pixels as with them off, frame after frame
   while occluders come and go (O kept from an earlier frame must be the far plane, and redrawn
   when occluders return); SKIP_OPAQUE draws one pass less from the second frame on;
   EXP_COMPOSITE (alpha = 1 - exp(-density t) computed instead of read from the 8-bit ramp)
   differs from the ramp by at most 1/255 per channel, and FAST_EXP (its exp() by a polynomial) from
   exp() by at most 1/255; the sums themselves (debug_thickness) are bit-identical throughout.
   DEPTH_TEST draws the PS20 and PS13 frames with occluders as COUNT (faces depth-tested against the
   occluders, fogvol_frame_stats.depth_tested): the same bytes and sums as the min compare.
   A viewport away from the window origin gives the same pixels, shifted, as one at the origin (the
   composite reads fogvol's targets with the offset there, without it at the origin).
   PS20 + WIDE with FOGVOL_VARIANT_ALU gives the lookup textures' sums bit for bit (the integer
   dither row of the wide encode). The encode with the encoding's constants compiled in
   (FOGVOL_SPECIALIZE_ENCODING; PS13 too, on the ALU encode in GLSL 330) gives the bytes of the
   uniform-driven encode and of the lookup textures for every L. PS13 resolving B - F in its
   composite (INLINE_RESOLVE) gives the resolve pass's bytes, sums and overflow counts. The MRT
   snippet's encode, in integers (GLSL 330) and in floats, gives fogvol_encode_depth's bytes. FLOAT_O
   (PS20 keeps O as R32F and compares instead of counting) gives the bytes of the RGBA8 O.
   FRAMEBUFFER_FETCH (the faces read O from a write-masked colour attachment beside the sum) gives
   the bytes and sums of the texture read, on FLOAT, PS20 and PS13 comparing, with the backend's cap
   off and with a backend whose fetching programs fail; O itself is never written there, and the
   engine's per-buffer colour masks survive. EXACT_SUM (PS20's faces add their depth into B as a 32-bit
   integer by framebuffer fetch) gives the FLOAT tier's sums within 2^-24 of the range per face and
   the ray-cast fog, in one sum pass without F; without the cap, or when its programs fail, the digits.
   Accuracy against ray-cast ground truth with the defaults is tested in test_render.c,
   test_tiers.c and test_engine_depth.c. */
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

#define NFRAMES 4
/* frame f draws the occluders: frames 0, 1 and 3 without, frame 2 with (unless a test says otherwise) */
static unsigned g_occluder_frames = 1u << 2; /* test_blend_color's failing backend: frames 2 and 3 */
static int with_occluders(int f) { return (g_occluder_frames >> f) & 1u; }

static int g_shader_filtered; /* INFO messages: the half-resolution sum filtered in the shader */
static void logger(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l == FOGVOL_LOG_INFO && strstr(m, "four texels")) g_shader_filtered++;
    if (l <= FOGVOL_LOG_WARNING) print_message("  [fogvol %s] %s\n", l == 0 ? "error" : "warning", m);
}

typedef struct run_out {
    unsigned char px[NFRAMES][W * H * 4];
    float th[NFRAMES][W * H]; /* fogvol_frame_desc.debug_thickness: the sums read back and decoded */
    int passes[NFRAMES];
    int depth_tested[NFRAMES]; /* fogvol_frame_stats.depth_tested */
    int inline_resolved[NFRAMES]; /* fogvol_frame_stats.inline_resolved */
    int late[NFRAMES];         /* fogvol_frame_stats.overflow_pixels_late */
    unsigned variants;         /* fogvol_context_tier: the variants the context ran */
    int enc_programs;          /* programs built with the encoding compiled in (FOGVOL_SPECIALIZE_ENCODING) */
    int targets;               /* render targets the context created */
    int o_format;              /* the format of the O target (-1: none made) */
    int blend_constant[NFRAMES]; /* passes with fogvol_pass.blend_constant (FOGVOL_SPEEDUP_BLEND_COLOR) */
    int fetched[NFRAMES];        /* fogvol_frame_stats.fetched_o */
    int read_passes[NFRAMES];    /* passes with fogvol_pass.read_target (FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH) */
    int fetch_programs;          /* programs built reading O from the framebuffer */
    int exact[NFRAMES];          /* fogvol_frame_stats.exact_sum */
} run_out;

/* NFRAMES frames of scene s on tier t with these speed-ups off, into out; the viewport starts at
   (g_x0, g_y0) of g's buffer, whose pixels outside it must keep the clear colour */
static int g_x0, g_y0;
static unsigned g_variants; /* fogvol_context_desc.variants */
static int g_downsample;    /* fogvol_frame_desc.downsample */
static int g_w = W, g_h = H; /* the viewport's size (out's pixels: rows of g_w) */
static int g_no_linear;     /* 1: the GL backend's create_target refuses linear targets (filtering in the shader) */
static int g_bits;          /* fogvol_context_desc.encoding_bits */
static int g_no_highp;      /* 1: the backend reports no FOGVOL_CAP_HIGHP_FRAGMENT (a mediump GPU) */
static int g_no_blend_constant; /* 1: the backend reports no FOGVOL_CAP_BLEND_CONSTANT */
static int g_light;             /* 1: the ramp blends as FOGVOL_BLEND_LIGHT */
static int g_fail_blend_color;  /* 1: the backend fails to build FOGVOL_SPECIALIZE_BLEND_COLOR programs */
static int g_no_fetch_cap;      /* 1: the backend reports no FOGVOL_CAP_FRAMEBUFFER_FETCH */
static int g_fail_fetch;        /* 1: the backend fails to build FOGVOL_SPECIALIZE_FETCH_O programs */
static int g_fail_exact;        /* 1: the backend fails to build FOGVOL_SPECIALIZE_EXACT_SUM programs; 2: only
                                   the composite (frame 0 then reports FOGVOL_ERROR_BACKEND) */
static int g_show_overflow; /* fogvol_frame_desc.show_overflow */
static fogvol_backend g_inner;
/* counts the targets the context creates; refuses linear ones with g_no_linear */
static int g_targets, g_o_format;
static fogvol_handle g_o_target;
static fogvol_result watch_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    if (d->linear && g_no_linear) return FOGVOL_ERROR_UNSUPPORTED; /* as a backend that cannot filter R32F */
    fogvol_result r;
    g_targets++;
    r = g_inner.create_target(u, d, out);
    if (d->label && strncmp(d->label, "fogvol O ", 9) == 0) {
        g_o_format = (int)d->format;
        g_o_target = r == FOGVOL_SUCCESS ? *out : 0;
    }
    return r;
}
/* counts the programs whose fragment shader has this context's encoding compiled in; with
   g_fail_blend_color fails those that take their colour from the blend unit */
static int g_enc_programs, g_fetch_programs;
static fogvol_result watch_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    int i;
    for (i = 0; i < d->fs_count; ++i) {
        if (g_fail_exact && strcmp(d->fs[i], "#define FV_XSUM\n") == 0 &&
            (g_fail_exact == 1 || strcmp(d->label, "fogvol composite") == 0))
            return FOGVOL_ERROR_BACKEND;
        if (strstr(d->fs[i], "#define FV_FETCH_O\n")) {
            if (g_fail_fetch) return FOGVOL_ERROR_BACKEND;
            g_fetch_programs++;
        }
        g_enc_programs += strncmp(d->fs[i], "#define FV_ENC_LN ", 18) == 0 && atoi(d->fs[i] + 18) == (g_bits ? g_bits : 4);
        if (g_fail_blend_color && strcmp(d->fs[i], "#define FV_BLEND_COLOR\n") == 0) return FOGVOL_ERROR_BACKEND;
    }
    return g_inner.create_program(u, d, out);
}
/* counts the passes that blend a constant colour, and those that read a target from the framebuffer
   (which must be O, beside a sum target, and not sampled as well) */
static int g_blend_constant, g_read_passes;
static void watch_pass(void *u, const fogvol_pass *p)
{
    g_blend_constant += p->blend_constant != 0;
    if (p->read_target) {
        int i;
        g_read_passes++;
        assert_true(p->target != 0 && p->target != p->read_target);
        assert_true(p->read_target == g_o_target);
        for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) assert_true(p->textures[i] != p->read_target);
    }
    g_inner.begin_pass(u, p);
}
static void run_frames(const tscene *s, fogvol_tier t, unsigned off, glu_ctx *g, run_out *out)
{
    fogvol_context_desc cd;
    fogvol_ramp_desc rd;
    fogvol_context *fv;
    fogvol_mesh *meshes[MAX_OBJ];
    fogvol_ramp *ramp;
    fogvol_frame_stats st;
    fogvol_result r;
    int f, i, x, y;
    unsigned char clear[4];
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = logger;
    assert_int_equal(fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &g_inner), FOGVOL_SUCCESS);
    cd.backend = g_inner;
    cd.backend.create_target = watch_target;
    g_targets = 0;
    g_o_format = -1;
    cd.backend.create_program = watch_program;
    cd.backend.begin_pass = watch_pass;
    if (g_no_highp) cd.backend.caps &= ~(unsigned)FOGVOL_CAP_HIGHP_FRAGMENT;
    if (g_no_blend_constant) cd.backend.caps &= ~(unsigned)FOGVOL_CAP_BLEND_CONSTANT;
    if (g_no_fetch_cap) cd.backend.caps &= ~(unsigned)FOGVOL_CAP_FRAMEBUFFER_FETCH;
    g_enc_programs = g_fetch_programs = 0;
    cd.tier = t;
    cd.disable_speedups = off;
    cd.variants = g_variants;
    cd.encoding_bits = g_bits;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    fogvol_context_tier(fv, &out->variants);
    upload_meshes(fv, s, meshes);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f;
    rd.color[1] = 0.6f;
    rd.color[2] = 0.3f;
    rd.density = s->density;
    rd.blend = g_light ? FOGVOL_BLEND_LIGHT : FOGVOL_BLEND_FOG;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    g_blend_constant = g_read_passes = 0;
    for (f = 0; f < NFRAMES; ++f) {
        fogvol_frame_desc fd;
        memset(&fd, 0, sizeof fd);
        rc_camera_matrices(&s->cam, fd.view, fd.projection);
        fd.znear = (float)s->cam.znear;
        fd.zfar = (float)s->cam.zfar;
        fd.viewport[0] = g_x0;
        fd.viewport[1] = g_y0;
        fd.viewport[2] = g_w;
        fd.viewport[3] = g_h;
        fd.debug_thickness = out->th[f];
        fd.downsample = g_downsample;
        fd.show_overflow = g_show_overflow;
        glClearColor(0.2f, 0.5f, 0.8f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, clear); /* 0.5 -> 127 or 128: the GL's rounding */
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        add_scene(fv, s, meshes, ramp, with_occluders(f));
        r = fogvol_end_frame(fv, &st);
        if (g_bits == 8 && r == FOGVOL_ERROR_DEPTH_OVERFLOW) /* L = 8 sums one face per target */
            assert_true(st.overflow_pixels > 0);
        else if (g_fail_exact == 2 && f == 0) /* the integer sums' composite failed: the group is not drawn */
            assert_int_equal(r, FOGVOL_ERROR_BACKEND);
        else
            assert_int_equal(r, FOGVOL_SUCCESS);
        glu_pixels(g);
        out->blend_constant[f] = g_blend_constant;
        out->read_passes[f] = g_read_passes;
        g_blend_constant = g_read_passes = 0;
        out->fetched[f] = st.fetched_o;
        out->exact[f] = st.exact_sum;
        for (y = 0; y < g->height; ++y)
            for (x = 0; x < g->width; ++x) {
                const unsigned char *p = g->pixels + 4 * ((size_t)y * g->width + x);
                if (x >= g_x0 && x < g_x0 + g_w && y >= g_y0 && y < g_y0 + g_h)
                    memcpy(out->px[f] + 4 * ((y - g_y0) * g_w + (x - g_x0)), p, 4);
                else /* outside the viewport: the clear colour, untouched */
                    assert_memory_equal(p, clear, 4);
            }
        out->passes[f] = st.passes;
        out->depth_tested[f] = st.depth_tested;
        out->inline_resolved[f] = st.inline_resolved;
        out->late[f] = st.overflow_pixels_late;
    }
    for (i = 0; i < s->n; ++i) fogvol_destroy_mesh(fv, meshes[i]);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    g_inner.destroy(g_inner.user_data);
    out->enc_programs = g_enc_programs;
    out->fetch_programs = g_fetch_programs;
    out->targets = g_targets;
    out->o_format = g_o_format;
}

static int max_diff(const unsigned char *a, const unsigned char *b, int *count)
{
    int i, m = 0;
    *count = 0;
    for (i = 0; i < W * H * 4; ++i) {
        int d = abs((int)a[i] - (int)b[i]);
        if (d > m) m = d;
        *count += d != 0;
    }
    return m;
}

static void write_png(const char *name, const unsigned char *px)
{
    char path[128];
    mkdir("build", 0755);
    snprintf(path, sizeof path, "build/speedups_%s.png", name);
    stbi_flip_vertically_on_write(1);
    assert_true(stbi_write_png(path, W, H, 4, px, W * 4) != 0);
}

/* The largest byte error of pixel px against mix(background, fog colour, 1 - exp(-density t)), or
   with g_light (a FOGVOL_BLEND_LIGHT ramp) background + fog colour (1 - exp(-density t)), clamped */
static int fog_error(const tscene *s, const unsigned char *px, double t)
{
    static const float bg[3] = {0.2f, 0.5f, 0.8f}, fog[3] = {0.9f, 0.6f, 0.3f};
    double a = t > 0.0 ? 1.0 - exp(-(double)s->density * t) : 0.0;
    int c, worst = 0;
    for (c = 0; c < 3; ++c) {
        double fog8 = floor(fog[c] * 255.0 + 0.5), bg8 = floor(bg[c] * 255.0 + 0.5);
        double v = g_light ? fmin(bg8 + fog8 * a, 255.0) : bg8 * (1.0 - a) + fog8 * a;
        int want = (int)floor(v + 0.5), d = abs(want - (int)px[c]);
        if (d > worst) worst = d;
    }
    return worst;
}

/* FLOAT, frame with occluders: every interior pixel against the ray-cast thickness through the
   extinction law (fog_error); returns the max error */
static int check_ground_truth(const tscene *s, const unsigned char *px)
{
    static double gt[W * H], tmax;
    static int pairs[W * H], maxf;
    static unsigned char interior[W * H], covered[W * H];
    int i, e, worst = 0, n = 0;
    ground_truth(s, gt, pairs, interior, covered, &maxf, &tmax, NULL);
    for (i = 0; i < W * H; ++i) {
        if (!interior[i]) continue;
        ++n;
        if ((e = fog_error(s, px + 4 * i, gt[i])) > worst) worst = e;
    }
    assert_true(n > W * H / 4);
    return worst;
}

static const fogvol_tier g_tiers[] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_PS20, FOGVOL_TIER_PS13};
static const char *const g_tier_names[] = {"FLOAT", "PS20", "PS13"};
#define ALL_OFF \
    (FOGVOL_SPEEDUP_SKIP_OPAQUE | FOGVOL_SPEEDUP_TEXEL_FETCH | FOGVOL_SPEEDUP_EXP_COMPOSITE | \
     FOGVOL_SPEEDUP_SPECIALIZE | FOGVOL_SPEEDUP_ALU | FOGVOL_SPEEDUP_OVERFLOW_BANDS | FOGVOL_SPEEDUP_FAST_EXP | \
     FOGVOL_SPEEDUP_DEPTH_TEST | FOGVOL_SPEEDUP_INLINE_RESOLVE | FOGVOL_SPEEDUP_BLEND_COLOR | FOGVOL_SPEEDUP_FLOAT_O | \
     FOGVOL_SPEEDUP_SKIP_CHECK | FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH | FOGVOL_SPEEDUP_EXACT_SUM)
#define XS FOGVOL_SPEEDUP_EXACT_SUM /* off where a test compares PS20's digits (test_exact_sum) */
#define FO FOGVOL_SPEEDUP_FLOAT_O /* off where a test looks at DEPTH_TEST's count, which PS20 with an R32F O
                                     does not take (test_float_o) */

static void test_same_pixels_and_exp(void **state)
{
    static run_out def, exact, noexp, off;
    const char *names[2] = {"plane_cuts_sphere", "layers_opaque_between"};
    glu_ctx g;
    int ti, si, f, n;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (ti = 0; ti < 3; ++ti)
        for (si = 0; si < 2; ++si) {
            const tscene *s = &g_scenes[scene_index(names[si])];
            int exp_max = 0, exp_n = 0, fast_max = 0, fast_n = 0, occluded = 0;
            run_frames(s, g_tiers[ti], FO, &g, &def);
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_FAST_EXP | FO, &g, &exact);
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_EXP_COMPOSITE | FO, &g, &noexp);
            run_frames(s, g_tiers[ti], ALL_OFF, &g, &off);
            for (f = 0; f < NFRAMES; ++f) {
                int m;
                /* SKIP_OPAQUE, TEXEL_FETCH, SPECIALIZE, ALU: the same bytes as with every speed-up off */
                assert_int_equal(max_diff(noexp.px[f], off.px[f], &n), 0);
                /* ... and the same sums: the encoded bytes (PS20: the integer ALU encode against the
                   lookup textures), decoded; the exp() speed-ups change only the composite */
                assert_memory_equal(noexp.th[f], off.th[f], sizeof off.th[f]);
                assert_memory_equal(def.th[f], off.th[f], sizeof off.th[f]);
                assert_memory_equal(exact.th[f], off.th[f], sizeof off.th[f]);
                m = max_diff(exact.px[f], noexp.px[f], &n);
                if (m > exp_max) exp_max = m;
                exp_n += n;
                /* FAST_EXP: the transmittance within 0.27% of exp(): at most 0.69/255 + rounding */
                m = max_diff(def.px[f], exact.px[f], &n);
                if (m > fast_max) fast_max = m;
                fast_n += n;
                /* one O pass drawn with speed-ups off in every frame; on: only in the first frame
                   and where occluders come (or leave: O must become the far plane again); PS13:
                   no resolve pass (INLINE_RESOLVE, this context has fp32 fragment shaders) */
                assert_int_equal(def.inline_resolved[f], g_tiers[ti] == FOGVOL_TIER_PS13);
                assert_int_equal(off.inline_resolved[f], 0);
                assert_int_equal(def.passes[f], off.passes[f] - (f == 1 ? 1 : 0) - def.inline_resolved[f]);
                /* DEPTH_TEST: PS20 and PS13 frames with occluders (both scenes lie between the planes)
                   are drawn as COUNT, faces depth-tested; the bytes above are the same */
                assert_int_equal(def.depth_tested[f], g_tiers[ti] != FOGVOL_TIER_FLOAT && with_occluders(f));
                assert_int_equal(off.depth_tested[f], 0);
            }
            write_png(g_tier_names[ti], def.px[2]);
            if (g_tiers[ti] == FOGVOL_TIER_FLOAT) {
                int e = check_ground_truth(s, def.px[2]);
                print_message("# FLOAT %-22s with occluders: composite vs ray-cast extinction max %d/255\n", names[si], e);
                assert_true(e <= 2);
            }
            /* the occluders change the picture, and frame 3 (no occluders) is frame 0 again */
            occluded = max_diff(def.px[2], def.px[0], &n);
            assert_true(occluded > 8);
            assert_int_equal(max_diff(def.px[3], def.px[0], &n), 0);
            print_message("# %-5s %-22s exp() composite vs 8-bit ramp: max %d/255 over %d channel values of %d "
                          "frames; fast exp vs exp(): max %d/255 over %d; other speed-ups: identical bytes; "
                          "passes %d %d %d %d (off: %d %d %d %d)\n",
                          g_tier_names[ti], names[si], exp_max, exp_n, NFRAMES, fast_max, fast_n, def.passes[0],
                          def.passes[1], def.passes[2], def.passes[3], off.passes[0], off.passes[1], off.passes[2],
                          off.passes[3]);
            assert_true(exp_max <= 1);
            assert_true(fast_max <= 1);
        }
    glu_destroy(&g);
}

/* A viewport away from the window origin (an editor pane, split screen): the composite reads
   fogvol's targets with the offset (the program without SPECIALIZE_ORIGIN) and must give the same
   pixels, shifted, as the viewport at the origin; nothing outside the viewport changes. */
static void test_viewport_offset(void **state)
{
    static run_out at0, moved;
    const tscene *s = &g_scenes[scene_index("layers_opaque_between")];
    glu_ctx g;
    int ti, f, n, fogged;
    (void)state;
    assert_true(glu_create(&g, W + 13, H + 7, 1));
    for (ti = 0; ti < 3; ++ti) {
        g_x0 = g_y0 = 0;
        run_frames(s, g_tiers[ti], 0, &g, &at0);
        g_x0 = 13;
        g_y0 = 7;
        run_frames(s, g_tiers[ti], 0, &g, &moved);
        g_x0 = g_y0 = 0;
        for (f = 0; f < NFRAMES; ++f) {
            assert_int_equal(max_diff(moved.px[f], at0.px[f], &n), 0);
            assert_memory_equal(moved.th[f], at0.th[f], sizeof at0.th[f]);
        }
        fogged = 0;
        for (n = 0; n < W * H; ++n) fogged += at0.px[2][4 * n] != 51 || at0.px[2][4 * n + 2] != 204;
        print_message("# %-5s viewport at (13, 7): the same pixels as at (0, 0), %d of them fogged\n",
                      g_tier_names[ti], fogged);
        assert_true(fogged > W * H / 8);
    }
    glu_destroy(&g);
}

/* FOGVOL_VARIANT_ALU with WIDE (asked for explicitly; the ALU speed-up leaves WIDE alone): the
   18-bit sums by arithmetic, the dither row included, are the lookup textures' bytes. */
static void test_wide_alu(void **state)
{
    static run_out tex, alu;
    const tscene *s = &g_scenes[scene_index("layers_opaque_between")];
    glu_ctx g;
    int f, n, covered = 0;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    g_variants = FOGVOL_VARIANT_WIDE;
    run_frames(s, FOGVOL_TIER_PS20, 0, &g, &tex);
    g_variants = FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_ALU;
    run_frames(s, FOGVOL_TIER_PS20, 0, &g, &alu);
    g_variants = 0;
    for (f = 0; f < NFRAMES; ++f) {
        assert_memory_equal(alu.th[f], tex.th[f], sizeof tex.th[f]);
        assert_int_equal(max_diff(alu.px[f], tex.px[f], &n), 0);
    }
    for (n = 0; n < W * H; ++n) covered += tex.th[2][n] > 0.0f;
    print_message("# PS20+wide: ALU = lookup textures bit for bit, %d pixels with thickness\n", covered);
    assert_true(covered > W * H / 8);
    glu_destroy(&g);
}

/* FOGVOL_SPECIALIZE_ENCODING: the encode with the encoding's N and D compiled in gives, for every L,
   the bytes of the general program that reads them from uniforms and of the lookup textures (PS20
   and PS13, whose ALU encode needs GLSL 330: this context), with and without occluders (COUNT, O
   RGBA8; and PS20 with an R32F O, FOGVOL_SPEEDUP_FLOAT_O, the compare) */
static void test_encoding_constants(void **state)
{
    static run_out spec, uni, tex, fo, mc;
    const tscene *s = &g_scenes[scene_index("layers_opaque_between")];
    glu_ctx g;
    int ti, f, n, L;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (ti = 1; ti < 3; ++ti)
        for (L = 1; L <= 8; ++L) {
            int covered = 0;
            g_bits = L;
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_FAST_EXP | FO, &g, &spec); /* exp(): the general composite's */
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_SPECIALIZE | FO, &g, &uni); /* N and D from the uniforms */
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_SPECIALIZE | FOGVOL_SPEEDUP_ALU | FO, &g, &tex); /* ramps */
            if (g_tiers[ti] == FOGVOL_TIER_PS20) { /* the R32F O, compiled in; against the RGBA8 O's compare
                                                      (at L = 8 the count saturates apart from it) */
                run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_FAST_EXP | XS, &g, &fo);
                run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_FAST_EXP | FOGVOL_SPEEDUP_DEPTH_TEST | FO, &g, &mc);
                assert_true(fo.enc_programs >= 2 && fo.o_format == FOGVOL_FORMAT_R32F);
                for (f = 0; f < NFRAMES; ++f) {
                    assert_memory_equal(mc.th[f], fo.th[f], sizeof fo.th[f]);
                    assert_int_equal(max_diff(mc.px[f], fo.px[f], &n), 0);
                    assert_int_equal(fo.depth_tested[f], 0);
                }
            }
            for (f = 0; f < NFRAMES; ++f) {
                assert_memory_equal(spec.th[f], uni.th[f], sizeof uni.th[f]);
                assert_memory_equal(spec.th[f], tex.th[f], sizeof tex.th[f]);
                assert_int_equal(max_diff(spec.px[f], uni.px[f], &n), 0);
                assert_int_equal(max_diff(spec.px[f], tex.px[f], &n), 0);
                assert_int_equal(spec.depth_tested[f], with_occluders(f));
            }
            /* the three ran what they stand for: the ALU encode with L compiled into its ENCODE and
               FACE programs (min compare and COUNT), the ALU encode on uniforms, the lookup textures */
            assert_true((spec.variants & FOGVOL_VARIANT_ALU) && spec.enc_programs >= 3);
            assert_true((uni.variants & FOGVOL_VARIANT_ALU) && uni.enc_programs == 0);
            assert_true(!(tex.variants & FOGVOL_VARIANT_ALU) && tex.enc_programs == 0);
            assert_int_equal(spec.o_format, FOGVOL_FORMAT_RGBA8);
            for (n = 0; n < W * H; ++n) covered += spec.th[0][n] > 0.0f;
            print_message("# %-5s L = %d: encoding compiled in = uniforms = lookup textures%s, bit for bit; "
                          "%d pixels with thickness\n", g_tier_names[ti], L,
                          g_tiers[ti] == FOGVOL_TIER_PS20 ? "; R32F O = RGBA8 O" : "", covered);
            assert_true(covered > W * H / 8);
        }
    g_bits = 0;
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_FLOAT_O on PS20 (this context renders R32F targets and has fp32 fragment shaders):
   O is R32F, and the faces encode the lesser of their depth and O, as the O pass would have encoded
   O. Frames with occluders take that compare instead of the face count (FOGVOL_SPEEDUP_DEPTH_TEST,
   which the speed-up switched off draws them with): the same bytes and sums as the RGBA8 O
   (counted), and the sums of every speed-up off (compared), in every frame. PS13 keeps its RGBA8 O
   and the count either way. (Integer sums off: they take the R32F O for PS13 too, test_exact_sum.) */
static void test_float_o(void **state)
{
    static run_out on, rgba, off;
    const char *names[2] = {"plane_cuts_sphere", "layers_opaque_between"};
    glu_ctx g;
    int ti, si, f, n, covered;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (ti = 1; ti < 3; ++ti)
        for (si = 0; si < 2; ++si) {
            const tscene *s = &g_scenes[scene_index(names[si])];
            run_frames(s, g_tiers[ti], XS, &g, &on);
            run_frames(s, g_tiers[ti], FO, &g, &rgba);
            run_frames(s, g_tiers[ti], ALL_OFF, &g, &off);
            int ps20 = g_tiers[ti] == FOGVOL_TIER_PS20;
            assert_int_equal(on.o_format, ps20 ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8);
            assert_int_equal(rgba.o_format, FOGVOL_FORMAT_RGBA8);
            assert_int_equal(off.o_format, FOGVOL_FORMAT_RGBA8);
            for (f = 0; f < NFRAMES; ++f) {
                assert_int_equal(on.depth_tested[f], ps20 ? 0 : with_occluders(f));
                assert_int_equal(rgba.depth_tested[f], with_occluders(f));
                assert_int_equal(max_diff(on.px[f], rgba.px[f], &n), 0);
                assert_memory_equal(on.th[f], rgba.th[f], sizeof on.th[f]); /* (off: the 8-bit ramp's pixels) */
                assert_memory_equal(on.th[f], off.th[f], sizeof on.th[f]);
            }
            for (n = 0, covered = 0; n < W * H; ++n) covered += on.th[2][n] > 0.0f;
            print_message("# %-5s %-22s %s O: the bytes and sums of the RGBA8 O (counted), the sums of every "
                          "speed-up off, %d frames; %d pixels with thickness in the occluders' frame\n",
                          g_tier_names[ti], names[si], ps20 ? "R32F" : "RGBA8", NFRAMES, covered);
            assert_true(covered > W * H / 8);
        }
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH (this OSMesa context has EXT_shader_framebuffer_fetch): the faces of
   frames with occluders read O from the framebuffer, FLOAT and PS20 (its R32F O) and PS13 comparing
   with its RGBA8 O (DEPTH_TEST off: no face count), and give the bytes and sums of the same frames
   reading O as a texture, of a backend without the cap and of one whose fetching programs fail (a
   warning; the faces sample O again and no later frame asks for the program). Frames without
   occluders read no O. The engine's colour mask of draw buffer 1, which the passes change, is its
   own again after every frame. */
static void test_framebuffer_fetch(void **state)
{
    static run_out on, off, nocap, fail;
    const char *names[2] = {"plane_cuts_sphere", "layers_opaque_between"};
    glu_ctx g;
    int ti, si, f, n;
    GLboolean mask[4];
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    if (!glu_has_fetch()) { /* (NVIDIA's desktop driver) */
        print_message("  this GL has no EXT_shader_framebuffer_fetch: skipped\n");
        glu_destroy(&g);
        skip();
    }
    glColorMaski(1, GL_TRUE, GL_FALSE, GL_TRUE, GL_FALSE);
    for (ti = 0; ti < 3; ++ti)
        for (si = 0; si < 2; ++si) {
            const tscene *s = &g_scenes[scene_index(names[si])];
            unsigned keep = (g_tiers[ti] == FOGVOL_TIER_PS13 ? (unsigned)FOGVOL_SPEEDUP_DEPTH_TEST : 0u) | XS;
            int faces = g_tiers[ti] == FOGVOL_TIER_FLOAT ? 1 : 2; /* sum passes reading O */
            run_frames(s, g_tiers[ti], keep, &g, &on);
            run_frames(s, g_tiers[ti], keep | FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH, &g, &off);
            g_no_fetch_cap = 1;
            run_frames(s, g_tiers[ti], keep, &g, &nocap);
            g_no_fetch_cap = 0;
            g_fail_fetch = 1;
            run_frames(s, g_tiers[ti], keep, &g, &fail);
            g_fail_fetch = 0;
            assert_int_equal(on.fetch_programs, 1);
            assert_int_equal(off.fetch_programs + nocap.fetch_programs + fail.fetch_programs, 0);
            for (f = 0; f < NFRAMES; ++f) {
                assert_int_equal(on.fetched[f], with_occluders(f));
                assert_int_equal(on.read_passes[f], with_occluders(f) ? faces : 0);
                assert_int_equal(off.fetched[f] + nocap.fetched[f] + fail.fetched[f], 0);
                assert_int_equal(off.read_passes[f] + nocap.read_passes[f] + fail.read_passes[f], 0);
                assert_int_equal(on.depth_tested[f], 0);
                assert_int_equal(max_diff(on.px[f], off.px[f], &n), 0);
                assert_int_equal(max_diff(nocap.px[f], off.px[f], &n), 0);
                assert_int_equal(max_diff(fail.px[f], off.px[f], &n), 0);
                assert_memory_equal(on.th[f], off.th[f], sizeof on.th[f]);
                assert_memory_equal(nocap.th[f], off.th[f], sizeof on.th[f]);
                assert_memory_equal(fail.th[f], off.th[f], sizeof on.th[f]);
            }
            /* the occluders cut the volumes: O matters in the frame that reads it */
            assert_true(max_diff(on.px[2], on.px[0], &n) > 8);
            glGetBooleani_v(GL_COLOR_WRITEMASK, 1, mask);
            assert_true(mask[0] && !mask[1] && mask[2] && !mask[3]);
            print_message("# %-5s %-22s O read from the framebuffer in %d sum pass(es) of the occluders' frame: "
                          "the bytes and sums of the texture read, without the cap and with its program "
                          "failing\n",
                          g_tier_names[ti], names[si], on.read_passes[2]);
        }
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_EXACT_SUM (this GL has framebuffer fetch and fp32): PS20 and PS13 (whose O is then
   R32F too) sum every face of a group
   into B as a 32-bit integer in one pass. Its sums are the FLOAT tier's within 2^-24 of the range per
   face plus FLOAT's own rounding, with and without occluders; its fog is the ray-cast fog's within
   2/255; it draws one sum pass instead of B and F; a backend without the cap, or whose integer-sum
   programs fail (a warning), draws the digits (their bytes); one whose integer-sum composite alone
   fails reports FOGVOL_ERROR_BACKEND for that frame and draws the digits from the next. */
static void test_exact_sum(void **state)
{
    static run_out on, flt, digits, nocap, fail, failc;
    const char *names[2] = {"plane_cuts_sphere", "layers_opaque_between"};
    glu_ctx g;
    int si, f, n, i, ti;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    if (!glu_has_fetch()) { /* (NVIDIA's desktop driver) */
        print_message("  this GL has no EXT_shader_framebuffer_fetch: skipped\n");
        glu_destroy(&g);
        skip();
    }
    for (ti = 1; ti < 3; ++ti)
        for (si = 0; si < 2; ++si) {
            const tscene *s = &g_scenes[scene_index(names[si])];
            const fogvol_tier tier = g_tiers[ti];
            double range = s->cam.zfar - s->cam.znear, worst = 0.0;
            int e;
            run_frames(s, tier, 0, &g, &on);
            run_frames(s, FOGVOL_TIER_FLOAT, 0, &g, &flt);
            run_frames(s, tier, XS, &g, &digits);
            g_no_fetch_cap = 1;
            run_frames(s, tier, 0, &g, &nocap);
            g_no_fetch_cap = 0;
            g_fail_exact = 1;
            run_frames(s, tier, 0, &g, &fail);
            g_fail_exact = 2;
            run_frames(s, tier, 0, &g, &failc);
            g_fail_exact = 0;
            assert_int_equal(failc.exact[0], 1); /* summed, then not composited; the digits from then on */
            for (f = 0; f < NFRAMES; ++f) {
                assert_int_equal(on.exact[f], 1);
                assert_int_equal(digits.exact[f] + nocap.exact[f] + fail.exact[f], 0);
                assert_int_equal(on.passes[f], digits.passes[f] - 1); /* one sum pass for B and F */
                for (i = 0; i < W * H; ++i) {
                    double d = fabs((double)on.th[f][i] - (double)flt.th[f][i]);
                    if (d > worst) worst = d;
                }
                assert_int_equal(max_diff(nocap.px[f], digits.px[f], &n), 0);
                assert_int_equal(max_diff(fail.px[f], digits.px[f], &n), 0);
                assert_memory_equal(nocap.th[f], digits.th[f], sizeof on.th[f]);
                assert_memory_equal(fail.th[f], digits.th[f], sizeof on.th[f]);
                if (f == 0) continue;
                assert_int_equal(failc.exact[f], 0);
                assert_int_equal(max_diff(failc.px[f], digits.px[f], &n), 0);
            }
            e = check_ground_truth(s, on.px[2]);
            print_message("# %-5s %-22s integer sums: max |sum - FLOAT's| %.2e of the range over %d frames; fog "
                          "with occluders vs ray-cast %d/255; passes %d (digits %d)\n",
                          g_tier_names[ti], names[si], worst / range, NFRAMES, e, on.passes[2], digits.passes[2]);
            assert_true(worst <= 4e-7 * range);
            assert_true(e <= 2);
            write_png(ti == 1 ? "PS20_exact" : "PS13_exact", on.px[2]);
        }
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_INLINE_RESOLVE: PS13's composite and overflow check resolve B - F themselves
   (this context has fp32 fragment shaders): the bytes, sums and GPU overflow counts of the resolve
   pass into T, with one pass and one target fewer, with and without occluders (COUNT frames add
   O's digits), and at L = 8, where the sums saturate, with and without show_overflow's magenta. A
   backend without FOGVOL_CAP_HIGHP_FRAGMENT keeps the resolve pass (exact in mediump). */
static int magenta(const unsigned char *px)
{
    int i, n = 0;
    for (i = 0; i < W * H; ++i) n += px[4 * i] == 255 && px[4 * i + 1] == 0 && px[4 * i + 2] == 255;
    return n;
}
static void test_inline_resolve(void **state)
{
    static run_out in, res, mediump;
    const char *names[2] = {"layers_opaque_between", "plane_cuts_sphere"};
    glu_ctx g;
    int si, k, f, n;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (si = 0; si < 2; ++si)
        for (k = 0; k < 3; ++k) { /* k = 1: L = 8, k = 2: L = 8 with show_overflow */
            const tscene *s = &g_scenes[scene_index(names[si])];
            int covered = 0, shown = 0, late = 0;
            g_bits = k ? 8 : 0;
            g_show_overflow = k == 2;
            run_frames(s, FOGVOL_TIER_PS13, XS, &g, &in); /* (the digits: their resolve) */
            run_frames(s, FOGVOL_TIER_PS13, FOGVOL_SPEEDUP_INLINE_RESOLVE | XS, &g, &res);
            g_no_highp = 1;
            run_frames(s, FOGVOL_TIER_PS13, XS, &g, &mediump);
            g_no_highp = 0;
            for (f = 0; f < NFRAMES; ++f) {
                assert_int_equal(max_diff(in.px[f], res.px[f], &n), 0);
                assert_memory_equal(in.th[f], res.th[f], sizeof res.th[f]);
                assert_int_equal(in.late[f], res.late[f]);
                assert_int_equal(max_diff(mediump.px[f], res.px[f], &n), 0);
                assert_int_equal(in.inline_resolved[f], 1);
                assert_int_equal(res.inline_resolved[f], 0);
                assert_int_equal(mediump.inline_resolved[f], 0);
                assert_int_equal(in.passes[f], res.passes[f] - 1);
                assert_int_equal(mediump.passes[f], res.passes[f]);
                assert_int_equal(in.depth_tested[f], with_occluders(f));
                shown += magenta(in.px[f]);
                if (in.late[f] > late) late = in.late[f];
            }
            assert_int_equal(in.targets, res.targets - 1); /* no T */
            assert_int_equal(mediump.targets, res.targets);
            for (n = 0; n < W * H; ++n) covered += in.th[2][n] > 0.0f;
            print_message("# PS13 %-22s L = %d%s: resolved in the composite = resolve pass, bit for bit, one pass "
                          "fewer; %d pixels with thickness, %d magenta pixel-frames, overflow_pixels_late up to %d\n",
                          names[si], k ? 8 : 4, k == 2 ? " show_overflow" : "", covered, shown, late);
            assert_true(covered > W * H / 8);
            if (k) assert_true(late > 0); /* the GPU counts the saturated sums */
            if (k == 2) assert_true(shown > 100); /* and they show */
            else assert_int_equal(shown, 0);
        }
    g_bits = 0;
    g_show_overflow = 0;
    glu_destroy(&g);
}

/* FOGVOL_SPEEDUP_BLEND_COLOR: the composite's colour from the blend unit (GL: CONSTANT_COLOR) and
   only its alpha from the program. Fog and light ramps, every tier here: the same bytes as the
   colour written by the program (speed-up off, or a backend without FOGVOL_CAP_BLEND_CONSTANT),
   one such pass per frame, none with show_overflow (its magenta comes from the program), none where
   the backend fails to build the program (the same program without the speed-up draws: the same
   bytes, and the face count of PS20 and PS13 stays on in the frame after, which draws the occluders
   again and must be frame 2's picture); the FLOAT pictures
   against the ray-cast thickness through the extinction law. The fog colour (0.9, 0.6, 0.3) is not
   a whole number of 255ths in red and blue, so both ways round it. */
static void test_blend_color(void **state)
{
    static run_out bc, off, nocap, failed;
    const tscene *s = &g_scenes[scene_index("plane_cuts_sphere")];
    glu_ctx g;
    int ti, k, f, n;
    (void)state;
    assert_true(glu_create(&g, W, H, 1));
    for (ti = 0; ti < 3; ++ti)
        for (k = 0; k < 3; ++k) { /* fog, light, fog with show_overflow */
            int fogged = 0, e = -1;
            g_light = k == 1;
            g_show_overflow = k == 2;
            run_frames(s, g_tiers[ti], 0, &g, &bc);
            run_frames(s, g_tiers[ti], FOGVOL_SPEEDUP_BLEND_COLOR, &g, &off);
            g_no_blend_constant = 1;
            run_frames(s, g_tiers[ti], 0, &g, &nocap);
            g_no_blend_constant = 0;
            g_fail_blend_color = 1;
            g_occluder_frames = 3u << 2;
            run_frames(s, g_tiers[ti], 0, &g, &failed);
            g_occluder_frames = 1u << 2;
            g_fail_blend_color = 0;
            for (f = 0; f < NFRAMES; ++f) {
                int same = f == 3 ? 2 : f; /* failed's frame 3 has the occluders of frame 2 */
                assert_int_equal(max_diff(bc.px[f], off.px[f], &n), 0);
                assert_int_equal(max_diff(nocap.px[f], off.px[f], &n), 0);
                assert_int_equal(max_diff(failed.px[f], off.px[same], &n), 0);
                assert_int_equal(failed.blend_constant[f], 0);
                assert_int_equal(failed.depth_tested[f], bc.depth_tested[same]);
                assert_memory_equal(bc.th[f], off.th[f], sizeof off.th[f]);
                assert_int_equal(bc.blend_constant[f], k < 2);
                assert_int_equal(off.blend_constant[f], 0);
                assert_int_equal(nocap.blend_constant[f], 0);
            }
            for (n = 0; n < W * H; ++n) fogged += bc.th[2][n] > 0.0f;
            if (g_tiers[ti] == FOGVOL_TIER_FLOAT) {
                e = check_ground_truth(s, bc.px[2]);
                assert_true(e <= 2);
            }
            if (k == 1) write_png("light_blend_color", bc.px[2]);
            print_message("# %-5s %s%s: blend colour = program colour, bit for bit, %d fogged pixels; vs ray cast "
                          "%d/255 (-1: not FLOAT)\n", g_tier_names[ti], k == 1 ? "light" : "fog",
                          k == 2 ? " show_overflow" : "", fogged, e);
            assert_true(fogged > W * H / 8);
        }
    g_light = 0;
    g_show_overflow = 0;
    glu_destroy(&g);
}

/* The MRT snippet's encode, fogvol_encode_view_depth, in integers (GLSL 330) and in floats (the
   same snippet under #version 150), against the CPU reference fogvol_encode_depth: for L = 1..8,
   dither on and off, 16384 depths from -0.125 to 1.125 (exact in fp32: one per pixel, so each of
   the 64 dither cells sees 256 of them), byte for byte. The dither row of a pixel is the red of
   fogvol_make_dither_index's 8x8 texel there, 0 without dither. */
static void test_mrt_snippet_encode(void **state)
{
    static const char *vs[1] = {"#version 150\nvoid main() {\n"
                                "    gl_Position = vec4(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0, 0.0, 1.0);\n}\n"};
    static const char *main_fs = "out vec4 o;\nvoid main() {\n"
                                 "    float i = (gl_FragCoord.x - 0.5) + (gl_FragCoord.y - 0.5) * 128.0;\n"
                                 "    o = fogvol_encode_view_depth(i * (1.25 / 16384.0) - 0.125);\n"
                                 "#ifdef INTEGER\n" /* the integer encode must be there: this fails to compile without it */
                                 "    if (o.a > 2.0) o = fogvol_encode_int(0, 4, 5, 16);\n"
                                 "#endif\n}\n";
    const char *versions[2] = {"#version 330 core\n#define INTEGER\n", "#version 150\n"};
    unsigned char index[8 * 8 * 4];
    glu_ctx g;
    GLuint vao, prog[2];
    int k, L, dither, i, checked = 0;
    (void)state;
    assert_true(W == 128 && H == 128); /* the shader's pixel index and depth step */
    assert_true(glu_create(&g, W, H, 1));
    for (k = 0; k < 2; ++k) {
        const char *fs[3];
        fs[0] = versions[k];
        fs[1] = fogvol_mrt_snippet();
        fs[2] = main_fs;
        prog[k] = fx_program(vs, 1, fs, 3);
    }
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    for (L = 1; L <= 8; ++L)
        for (dither = 0; dither < 2; ++dither)
            for (k = 0; k < 2; ++k) {
                fogvol_encoding enc;
                fogvol_constants c;
                fogvol_image img;
                float u[8];
                unsigned char *px;
                assert_int_equal(fogvol_encoding_init(L, &enc), FOGVOL_SUCCESS);
                assert_int_equal(fogvol_make_dither_index(&enc, index, sizeof index, &img), FOGVOL_SUCCESS);
                fogvol_compute_constants(&enc, 0.0f, 1.0f, 0.0f, &c);
                u[0] = 1.0f; /* d = view depth: near 0, far 1 */
                u[1] = 0.0f;
                u[2] = (float)enc.levels;
                u[3] = (float)enc.levels * (float)enc.levels;
                u[4] = c.depth_offset;
                u[5] = c.depth_max;
                u[6] = (float)enc.dither_steps;
                u[7] = (float)dither;
                glUseProgram(prog[k]);
                glUniform4fv(glGetUniformLocation(prog[k], "fogvol_mrt"), 2, u);
                glDrawArrays(GL_TRIANGLES, 0, 3);
                px = glu_pixels(&g);
                for (i = 0; i < W * H; ++i) {
                    int x = i % W, y = i / W, row = 0;
                    unsigned char want[4];
                    if (dither) row = index[4 * ((y % 8) * 8 + x % 8)];
                    assert_int_equal(fogvol_encode_depth(&enc, i * (1.25 / 16384.0) - 0.125, row, want), FOGVOL_SUCCESS);
                    if (memcmp(px + 4 * i, want, 4) != 0)
                        fail_msg("%s, L = %d, dither %d, pixel (%d, %d): %d %d %d %d, want %d %d %d %d", versions[k], L,
                                 dither, x, y, px[4 * i], px[4 * i + 1], px[4 * i + 2], px[4 * i + 3], want[0], want[1],
                                 want[2], want[3]);
                    ++checked;
                }
            }
    print_message("# MRT snippet: integer (GLSL 330) and float (GLSL 150) encodes = fogvol_encode_depth, %d values "
                  "byte for byte (L = 1..8, dither on and off)\n", checked);
    glDeleteVertexArrays(1, &vao);
    glDeleteProgram(prog[0]);
    glDeleteProgram(prog[1]);
    glu_destroy(&g);
}

/* The composite against the thickness the frame read back (debug_thickness): each of the n pixels,
   mix(background, fog colour, 1 - exp(-density t)) in bytes; returns the largest error */
static int check_composite(const tscene *s, const unsigned char *px, const float *th, int n)
{
    int i, e, worst = 0;
    for (i = 0; i < n; ++i)
        if ((e = fog_error(s, px + 4 * i, th[i])) > worst) worst = e;
    return worst;
}

/* max - min of four taps */
static double tap_spread(double a, double b, double c, double d)
{
    double lo = a < b ? a : b, hi = a < b ? b : a;
    lo = c < lo ? c : lo;
    hi = c > hi ? c : hi;
    lo = d < lo ? d : lo;
    hi = d > hi ? d : hi;
    return hi - lo;
}

/* One frame f of test_half_resolution: scene s (its camera at the viewport's size vw x vh) drawn at
   full and half resolution, checked against the ray cast */
static void half_check(const tscene *s, const char *name, int f, int vw, int vh, int x0, int y0, int shader_filter,
                       const run_out *full, const run_out *half)
{
    static double tap[(H / 2 + 1) * (W / 2 + 1)], gt[W * H];
    static unsigned sig[(H / 2 + 1) * (W / 2 + 1)];
    const int tw = (vw + 1) / 2, th = (vh + 1) / 2, n = vw * vh;
    double range = s->cam.zfar - s->cam.znear, snap = snap_pixels();
    double worst = 0.0, tmax = 0.0, sum_all = 0.0, worst_all = 0.0, cmean = 0.0;
    int x, y, i, n_smooth = 0, n_fog = 0, n_cov = 0, cmax = 0, n_c4 = 0, ce;
    rc_scene rs;
    scene_raycaster(s, with_occluders(f), &rs);
    for (y = 0; y < th; ++y) /* the low-resolution texel centres: (i + 0.5) * vw / tw */
        for (x = 0; x < tw; ++x) {
            rc_result r = rc_trace(&rs, &s->cam, (x + 0.5) * vw / tw, (y + 0.5) * vh / th);
            tap[y * tw + x] = r.thickness;
            sig[y * tw + x] = r.signature;
        }
    for (y = 0; y < vh; ++y)
        for (x = 0; x < vw; ++x) {
            double py = (y + 0.5) * th / vh - 0.5, px = (x + 0.5) * tw / vw - 0.5, fy, fx, want, e, tol;
            int iy = (int)floor(py), ix = (int)floor(px), ya, yb, xa, xb, k = y * vw + x;
            rc_result r = rc_trace(&rs, &s->cam, x + 0.5, y + 0.5);
            fy = py - iy;
            fx = px - ix;
            ya = iy < 0 ? 0 : iy;
            yb = iy + 1 > th - 1 ? th - 1 : iy + 1;
            xa = ix < 0 ? 0 : ix;
            xb = ix + 1 > tw - 1 ? tw - 1 : ix + 1;
            gt[k] = r.thickness;
            if (r.thickness > tmax) tmax = r.thickness;
            if (r.faces_front + r.faces_back > 0 || half->th[f][k] != 0.0f) { /* covered (or fogged) pixels */
                e = fabs(half->th[f][k] - gt[k]);
                n_cov++;
                sum_all += e;
                if (e > worst_all) worst_all = e;
            }
            if (r.signature != sig[ya * tw + xa] || r.signature != sig[ya * tw + xb] ||
                r.signature != sig[yb * tw + xa] || r.signature != sig[yb * tw + xb] || !rc_interior(&rs, &s->cam, x, y))
                continue;
            want = (tap[ya * tw + xa] * (1 - fx) + tap[ya * tw + xb] * fx) * (1 - fy) +
                   (tap[yb * tw + xa] * (1 - fx) + tap[yb * tw + xb] * fx) * fy;
            e = fabs(half->th[f][k] - want);
            /* + the taps' snapping (half-resolution pixels: twice the slope) + the filter's weights: the
               GL computes them in fixed point (NVIDIA: 8 bits of the sub-texel position; the spec leaves
               it open), up to 2^-8 off in each direction if truncated: 2^-7 of the taps' spread (on an
               H200 a pixel 0.0036 off with taps 0.444 apart, which llvmpipe draws 0.00001 off) */
            tol = 3e-5 * range * (1 + r.faces_back) + 2.0 * rc_depth_slope(&rs, &s->cam, x, y) * snap +
                  ldexp(tap_spread(tap[ya * tw + xa], tap[ya * tw + xb], tap[yb * tw + xa], tap[yb * tw + xb]), -7);
            if (e > tol)
                fail_msg("%s frame %d pixel (%d,%d): half-resolution thickness %.6f, bilinear ray cast %.6f (bound %.2g; "
                         "taps %.5f %.5f %.5f %.5f, depth slope %.4f per pixel)",
                         name, f, x, y, (double)half->th[f][k], want, tol, tap[ya * tw + xa], tap[ya * tw + xb],
                         tap[yb * tw + xa], tap[yb * tw + xb], rc_depth_slope(&rs, &s->cam, x, y));
            if (e / range > worst) worst = e / range;
            n_smooth++;
            n_fog += want > 0.0;
        }
    rc_scene_free(&rs);
    for (i = 0; i < n; ++i) { /* the composite against the full-resolution one */
        int c, m = 0;
        for (c = 0; c < 3; ++c) {
            int d = abs((int)half->px[f][4 * i + c] - (int)full->px[f][4 * i + c]);
            if (d > m) m = d;
        }
        if (m > cmax) cmax = m;
        cmean += m;
        n_c4 += m > 4;
    }
    ce = check_composite(s, half->px[f], half->th[f], n);
    print_message("# half resolution, %-21s %s, %dx%d at (%d,%d), %s: %d smooth pixels (%d fogged) within %.2g of the "
                  "range of the bilinear ray cast, composite within %d/255 of the read-back thickness; against full "
                  "resolution (silhouettes included): thickness max %.3f / mean %.4f of the thickest ray (%d px), "
                  "composite max %d/255, mean %.2f/255, %.1f%% of pixels over 4/255\n",
                  name, with_occluders(f) ? "with occluders" : "no occluders", vw, vh, x0, y0,
                  shader_filter ? "four reads in the shader" : "filtered by the GL", n_smooth, n_fog, worst, ce,
                  worst_all / tmax, sum_all / (n_cov ? n_cov : 1) / tmax, n_cov, cmax, cmean / n, 100.0 * n_c4 / n);
    assert_true(n_fog > n / 8);                              /* the interpolated thickness checked where there is fog */
    assert_true(ce <= 2);                                    /* FAST_EXP 0.69/255 + rounding, the filter's weights */
    assert_true(cmean / n <= 1.0);                           /* on average under 1/255 of full resolution */
    assert_true(sum_all / (n_cov ? n_cov : 1) / tmax <= 0.01); /* mean under 1% of the thickest ray */
}

/* fogvol_frame_desc.downsample 2 (FLOAT): the sums at half width and height, upsampled bilinearly.
   Independent truth: the ray cast at the low-resolution texel centres ((i + 0.5) w / tw: the tw texels
   span the w pixels), interpolated bilinearly, at every pixel whose four taps and own centre see the
   same hit topology (within the FLOAT bound of test_tiers, 3e-5 of the depth range per face pair, plus
   what vertex snapping at half resolution moves: twice the pixel's depth slope times the snap grid).
   The composite, filtered by the GL (fogvol_target_desc.linear) or by four reads where the backend
   refuses that, against the read-back thickness (the same bilinear values) at every pixel. Then the
   error of the method itself against the full-resolution ray cast and composite, silhouettes included,
   measured and bounded. Viewports at the origin, away from it, and of odd width and height; frames
   with and without occluders. */
static void test_half_resolution(void **state)
{
    static run_out full, half;
    static const struct {
        int w, h, x0, y0, shader_filter;
    } vc[4] = {{W, H, 0, 0, 0}, {W, H, 13, 7, 0}, {W, H, 0, 0, 1}, {W - 1, H - 3, 0, 0, 0}};
    const char *names[3] = {"plane_cuts_sphere", "layers_opaque_between", "negative_pokes_out"};
    glu_ctx g;
    int si, f, k;
    (void)state;
    assert_true(glu_create(&g, W + 13, H + 7, 1));
    for (k = 0; k < 4; ++k)
        for (si = 0; si < 3; ++si) {
            tscene sc = g_scenes[scene_index(names[si])]; /* the camera at the viewport's size */
            sc.cam.width = vc[k].w;
            sc.cam.height = vc[k].h;
            g_w = vc[k].w;
            g_h = vc[k].h;
            g_x0 = vc[k].x0;
            g_y0 = vc[k].y0;
            g_downsample = 0;
            run_frames(&sc, FOGVOL_TIER_FLOAT, 0, &g, &full);
            g_downsample = 2;
            g_no_linear = vc[k].shader_filter;
            g_shader_filtered = 0;
            run_frames(&sc, FOGVOL_TIER_FLOAT, 0, &g, &half);
            assert_int_equal(g_shader_filtered, vc[k].shader_filter); /* llvmpipe filters R32F; the wrapper refuses it */
            g_downsample = g_no_linear = 0;
            g_x0 = g_y0 = 0;
            g_w = W;
            g_h = H;
            for (f = 0; f < 3; f += 2) { /* frame 0 without occluders, frame 2 with */
                half_check(&sc, names[si], f, vc[k].w, vc[k].h, vc[k].x0, vc[k].y0, vc[k].shader_filter, &full, &half);
                if (k == 0 && si == 1 && with_occluders(f)) {
                    write_png("half", half.px[f]);
                    write_png("full", full.px[f]);
                }
            }
        }
    glu_destroy(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_same_pixels_and_exp),
                                       cmocka_unit_test(test_viewport_offset), cmocka_unit_test(test_wide_alu),
                                       cmocka_unit_test(test_encoding_constants),
                                       cmocka_unit_test(test_float_o), cmocka_unit_test(test_framebuffer_fetch),
                                       cmocka_unit_test(test_exact_sum),
                                       cmocka_unit_test(test_inline_resolve),
                                       cmocka_unit_test(test_blend_color),
                                       cmocka_unit_test(test_mrt_snippet_encode),
                                       cmocka_unit_test(test_half_resolution)};
    int r;
    build_scenes();
    r = cmocka_run_group_tests(tests, NULL, NULL);
    free_scenes();
    return r;
}
