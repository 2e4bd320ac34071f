#define _POSIX_C_SOURCE 199309L
/* demo_headless.c - fogvol.h without a window. OSMesa (built with -DGLU_EGL: any
   EGL device, make gpu-test) renders the demo's place
   (examples/demo_scene.h: a sunlit courtyard with a cobbled path, a house,
   columns, an arch gate, rocks, pine trees and a lamp post, drawn by the demo's
   own shaders as the engine's opaque pass), and fogvol adds the fog volumes
   placed in it: a fog sphere around the rocks, a ring standing in the arch, a
   drifting cloud, a low mist bank the camera can stand in with a clearing
   carved by a negative sphere, a sunbeam and the lamp's cone of light. The
   opaque objects cut the volumes. The fog has soft edges (fogvol_ramp_desc.softness),
   the lights fade along their length (a density texture) and, by compare, with
   distance (fogvol_light_desc.falloff_radius, edge_softness). It writes PNGs:
     scene_overview.png, scene_low.png, scene_inside_fog_bank.png  three viewpoints
     tiers.png        the same frame per tier: PS13 | PS20 | FLOAT (the RGBA8 tiers on their
                      classic digit path: FOGVOL_SPEEDUP_EXACT_SUM off)
     dither.png       L = 2 bits per channel (6-bit depth precision), close to the fog sphere,
                      dithering off | on | on, the mean of 8 frames with dither_frame 1..8
                      (the banding, its cure, and the pattern averaged away as TAA would; the
                      digit path too)
     soft_edges.png   close to the fog sphere: softness 0 | the demo's softness
     ramps.png        colour ramps: extinction | linear | artist gradient
     thickness.png    the raw thickness of the fog group as false colour
     dof.png, outlines.png, distance_fog.png  the overview with the image-space effects
     textured_fog.png, light_compare.png  density and colour textures; lights by compare
     before_after.png hard edges and flat lights (softness 0, no fades, no falloff) | this
                      version: the fog sphere, the sunbeam, the lights by compare
   and prints where they went, the tier, the pass count and the frame time.

   usage: demo_headless [output-dir] [--check]    (default dir: build/demo)
   --check: also verifies the pictures (fog where volumes are, none
   elsewhere, the inside view fogged everywhere) and prints TAP lines. */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "examples/demo_scene.h"
#include "examples/example_gl.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>
#include <time.h>

#define DW 640
#define DH 360

/* the demo's volumes must all be accepted: exit on a refused mesh */
static fogvol_mesh *upload(fogvol_context *fv, const shp_mesh *m)
{
    fogvol_mesh *out = exm_fog_mesh(fv, m, 0);
    if (!out) exit(1);
    return out;
}

static void log_cb(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l <= FOGVOL_LOG_WARNING) fprintf(stderr, "%s\n", m);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}


typedef struct demo {
    glu_ctx g;
    ds_scene scene; /* examples/demo_scene.h: the place, its opaque objects and fog volumes */
    ds_gl gl;
} demo;

typedef struct settings {
    fogvol_tier tier;
    int bits, dither, ramp; /* ramp: 0 extinction, 1 linear, 2 gradient */
    int w, h, view;
    float fog_scale;         /* density multiplier of the fog group */
    unsigned speedups_off;   /* fogvol_context_desc.disable_speedups */
    int before;              /* 1: as fogvol 0.2 drew it: hard edges, lights that do not fade */
    int frames;              /* > 1: the mean of that many frames, dither_frame 1 .. frames (TAA) */
} settings;

typedef struct shot {
    unsigned char *rgba;
    float *thick[3]; /* per group: fog, bank, light (debug read-back), may be NULL */
    fogvol_frame_stats st;
    fogvol_tier tier;
    double ms;
} shot;

static void camera(int view, int w, int h, float v[16], float p[16])
{
    /* overview, low, inside the mist bank, close to the fog sphere (for dither.png) */
    static const double eye[4][3] = {{1.0, 5.2, 13.5}, {-7.0, 1.7, 8.0}, {-7.0, 0.5, -1.5}, {2.8, 1.4, 5.4}};
    static const double at[4][3] = {{0.0, 1.0, -2.5}, {1.0, 1.4, -3.0}, {2.0, 1.4, -6.0}, {5.3, 0.5, 0.6}};
    static const double up[3] = {0, 1, 0};
    glu_look_at(v, eye[view], at[view], up);
    glu_perspective(p, 55.0, (double)w / h, 0.1, 40.0);
}

/* soft edges of the three groups (fogvol_ramp_desc.softness, world units): fog, mist bank, light */
static const float g_soft[3] = {0.6f, 0.5f, 0.2f};

/* the three colour ramps: the fog group (model and density from the settings), the mist bank, the light */
static void make_ramps(fogvol_context *fv, const settings *s, fogvol_ramp *ramp[3])
{
    fogvol_ramp_desc rd;
    fogvol_color_key keys[4];
    memset(&rd, 0, sizeof rd);
    rd.softness = s->before ? 0.0f : g_soft[0];
    rd.color[0] = 0.70f, rd.color[1] = 0.78f, rd.color[2] = 0.90f, rd.density = (s->before ? 1.1f : 1.4f) * s->fog_scale;
    rd.model = s->ramp == 1 ? FOGVOL_RAMP_LINEAR : s->ramp == 2 ? FOGVOL_RAMP_GRADIENT : FOGVOL_RAMP_EXTINCTION;
    if (s->ramp == 1) rd.density = 0.45f * s->fog_scale;
    keys[0].thickness = 0.0f, keys[0].rgba[0] = 0.2f, keys[0].rgba[1] = 0.9f, keys[0].rgba[2] = 0.7f, keys[0].rgba[3] = 0.0f;
    keys[1].thickness = 0.8f, keys[1].rgba[0] = 0.3f, keys[1].rgba[1] = 0.8f, keys[1].rgba[2] = 1.0f, keys[1].rgba[3] = 0.45f;
    keys[2].thickness = 1.8f, keys[2].rgba[0] = 0.9f, keys[2].rgba[1] = 0.4f, keys[2].rgba[2] = 0.9f, keys[2].rgba[3] = 0.75f;
    keys[3].thickness = 3.0f, keys[3].rgba[0] = 1.0f, keys[3].rgba[1] = 0.9f, keys[3].rgba[2] = 0.5f, keys[3].rgba[3] = 0.95f;
    rd.keys = keys;
    rd.key_count = 4;
    fogvol_create_ramp(fv, &rd, &ramp[0]);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.74f, rd.color[1] = 0.80f, rd.color[2] = 0.86f, rd.density = 0.35f;
    rd.softness = s->before ? 0.0f : g_soft[1];
    fogvol_create_ramp(fv, &rd, &ramp[1]);
    rd.color[0] = 1.0f, rd.color[1] = 0.78f, rd.color[2] = 0.42f, rd.density = 0.30f, rd.blend = FOGVOL_BLEND_LIGHT;
    rd.softness = s->before ? 0.0f : g_soft[2];
    if (!s->before) rd.density = 0.8f; /* (the fade thins it) */
    fogvol_create_ramp(fv, &rd, &ramp[2]);
}

/* the lights' fade along their axis (demo_scene.h: ds_fade_texels) */
static fogvol_volume_texture *fade_texture(fogvol_context *fv)
{
    unsigned char px[DS_FADE_TEXELS * 4];
    fogvol_texture_desc td;
    fogvol_volume_texture *t = NULL;
    ds_fade_texels(px);
    memset(&td, 0, sizeof td);
    td.width = DS_FADE_TEXELS;
    td.height = 1;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = FOGVOL_WRAP_CLAMP;
    if (fogvol_create_volume_texture(fv, &td, &t) != FOGVOL_SUCCESS) t = NULL;
    return t;
}

/* fogvol's part of a frame: the opaque objects as occluders, the volumes by group (fade: the lights'
   density texture, NULL: no fade) */
static void add_scene(fogvol_context *fv, const ds_scene *sc, fogvol_mesh *const *fm, fogvol_ramp *const *ramp,
                      const fogvol_volume_texture *fade)
{
    int i;
    for (i = 0; i < sc->count; ++i) {
        const ds_object *o = &sc->obj[i];
        fogvol_volume_desc vd;
        if (o->kind == DS_OPAQUE) {
            fogvol_add_occluder(fv, fm[o->mesh], o->model);
            continue;
        }
        memset(&vd, 0, sizeof vd);
        vd.mesh = fm[o->mesh];
        vd.ramp = ramp[ds_group(o->kind)];
        vd.negative = o->kind == DS_HOLE;
        memcpy(vd.model, o->model, sizeof vd.model);
        if (o->fade && fade) {
            vd.density = fade;
            memcpy(vd.density_map, o->fade_map, sizeof vd.density_map);
        }
        fogvol_add_volume(fv, &vd);
    }
}

/* One frame: the engine's opaque pass (ds_draw), then fogvol with these settings.
   Returns 0 if the context could not be created (tier not available). */
static int render(demo *d, const settings *s, int with_fog, shot *out)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *fm[DS_MAX_MESHES];
    fogvol_ramp *ramp[3];
    fogvol_volume_texture *fade;
    float v[16], p[16];
    unsigned *sum = NULL;
    int i, grp, captures, f;
    if (!glu_create(&d->g, s->w, s->h, 1)) return 0;
    ds_gl_init(&d->gl, &d->scene);
    camera(s->view, s->w, s->h, v, p);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    cd.tier = s->tier;
    cd.encoding_bits = s->bits;
    cd.disable_dither = !s->dither;
    cd.disable_speedups = s->speedups_off;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        ds_gl_free(&d->gl);
        glu_destroy(&d->g);
        return 0;
    }
    out->tier = fogvol_context_tier(fv, NULL);
    for (i = 0; i < d->scene.mesh_count; ++i) fm[i] = upload(fv, &d->scene.mesh[i]);
    make_ramps(fv, s, ramp);
    fade = s->before || out->tier == FOGVOL_TIER_PS13 ? NULL : fade_texture(fv); /* (PS13: no density textures) */

    /* one frame per group whose thickness is read back, the first one timed; with s->frames > 1 the
       frames 2 .. frames follow (dither_frame = frame), their mean the picture */
    captures = with_fog ? 3 : 1;
    if (with_fog && s->frames > 1) sum = (unsigned *)calloc((size_t)s->w * s->h * 4, sizeof(unsigned));
    for (grp = 0, f = 1; grp < captures || (sum && f <= s->frames); ++grp) {
        fogvol_frame_desc fd;
        double t0;
        ds_draw(&d->gl, &d->scene, v, p, s->w, s->h);
        if (!with_fog) break;
        memset(&fd, 0, sizeof fd);
        memcpy(fd.view, v, sizeof v);
        memcpy(fd.projection, p, sizeof p);
        fd.znear = 0.1f;
        fd.zfar = 40.0f;
        fd.viewport[2] = s->w;
        fd.viewport[3] = s->h;
        fd.debug_thickness = grp < captures ? out->thick[grp] : NULL;
        fd.debug_ramp = grp < captures ? ramp[grp] : NULL;
        fd.dither_frame = sum && grp >= captures - 1 ? f++ : sum ? 1 : 0;
        glFinish();
        t0 = now_ms();
        fogvol_begin_frame(fv, &fd);
        add_scene(fv, &d->scene, fm, ramp, fade);
        fogvol_end_frame(fv, grp == 0 ? &out->st : NULL);
        glFinish();
        if (grp == 0) out->ms = now_ms() - t0;
        if (grp == 0) memcpy(out->rgba, glu_pixels(&d->g), (size_t)s->w * s->h * 4);
        if (sum && grp >= captures - 1)
            for (i = 0; i < s->w * s->h * 4; ++i) sum[i] += d->g.pixels[i];
    }
    if (!with_fog) memcpy(out->rgba, glu_pixels(&d->g), (size_t)s->w * s->h * 4);
    for (i = 0; sum && i < s->w * s->h * 4; ++i) out->rgba[i] = (unsigned char)((sum[i] + s->frames / 2) / s->frames);
    free(sum);
    if (fade) fogvol_destroy_volume_texture(fv, fade);
    for (i = 0; i < d->scene.mesh_count; ++i) fogvol_destroy_mesh(fv, fm[i]);
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    fogvol_destroy_context(fv);
    ds_gl_free(&d->gl);
    glu_destroy(&d->g);
    return 1;
}

static shot new_shot(int w, int h)
{
    shot s;
    int i;
    memset(&s, 0, sizeof s);
    s.rgba = (unsigned char *)calloc((size_t)w * h, 4);
    for (i = 0; i < 3; ++i) s.thick[i] = (float *)calloc((size_t)w * h, sizeof(float));
    return s;
}

static void free_shot(shot *s)
{
    int i;
    free(s->rgba);
    for (i = 0; i < 3; ++i) free(s->thick[i]);
}

/* write n images of w x h side by side (rows bottom to top in, PNG top to bottom out) */
static void save_row(const char *dir, const char *name, unsigned char **imgs, int n, int w, int h)
{
    unsigned char *row = (unsigned char *)malloc((size_t)w * n * h * 4);
    char path[512];
    int k, y;
    for (k = 0; k < n; ++k)
        for (y = 0; y < h; ++y) memcpy(row + ((size_t)(h - 1 - y) * w * n + (size_t)k * w) * 4, imgs[k] + (size_t)y * w * 4, (size_t)w * 4);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    stbi_write_png(path, w * n, h, 4, row, w * n * 4);
    free(row);
    printf("%s\n", path);
}

static void report(const char *what, const shot *s)
{
    printf("  %-34s tier %-5s %2d passes, %d groups, fog %.1f ms (llvmpipe)\n", what, fogvol_tier_name(s->tier),
           s->st.passes, s->st.groups, s->ms);
}

/* false colour: black -> blue -> cyan -> yellow -> white over [0, tmax] */
static void false_colour(const float *t, unsigned char *out, int n, float tmax)
{
    int i;
    for (i = 0; i < n; ++i) {
        float x = t[i] <= 0 ? 0 : t[i] >= tmax ? 1 : t[i] / tmax;
        float r = x < 0.5f ? 0 : (x - 0.5f) * 2, g = x < 0.25f ? 0 : x < 0.75f ? (x - 0.25f) * 2 : 1,
              b = x < 0.5f ? x * 2 : (x < 0.75f ? 1 - (x - 0.5f) * 4 : (x - 0.75f) * 4);
        out[4 * i] = (unsigned char)(r * 255), out[4 * i + 1] = (unsigned char)(g * 255);
        out[4 * i + 2] = (unsigned char)(b * 255), out[4 * i + 3] = 255;
    }
}

/* n renders with these settings side by side; a setting whose context cannot
   be created (tier not available) is left out; report: print each one's tier */
/* Renders n settings side by side into one PNG; returns the fewest pixels in which an earlier panel
   differs from the last (0 when a panel is missing). */
static int row(demo *d, const char *dir, const char *name, const settings *v, int n, int report_each)
{
    shot sh[3];
    unsigned char *imgs[3];
    int k, i, got = 0, fewest = -1;
    for (k = 0; k < n; ++k) {
        sh[got] = new_shot(v[k].w, v[k].h);
        if (render(d, &v[k], 1, &sh[got])) {
            imgs[got] = sh[got].rgba;
            ++got;
        } else {
            free_shot(&sh[got]);
        }
    }
    save_row(dir, name, imgs, got, v[0].w, v[0].h);
    for (k = 0; k + 1 < got; ++k) {
        int differ = 0;
        for (i = 0; i < v[0].w * v[0].h; ++i) differ += memcmp(imgs[got - 1] + 4 * i, imgs[k] + 4 * i, 3) != 0;
        if (fewest < 0 || differ < fewest) fewest = differ;
    }
    for (k = 0; k < got; ++k) {
        if (report_each) report(fogvol_tier_name(sh[k].tier), &sh[k]);
        free_shot(&sh[k]);
    }
    return got == n && fewest > 0 ? fewest : 0;
}

/* ---- image-space effects on the overview: the scene (opaque + fog volumes) goes into a framebuffer
   with colour and depth textures, as an engine would keep it, then each effect writes the window */
/* the overview into the engine's colour and depth textures (fbo): the opaque scene, then its fog */
static void scene_to_textures(demo *d, fogvol_context *fv, const float v[16], const float p[16], GLuint fbo)
{
    fogvol_mesh *fm[DS_MAX_MESHES];
    fogvol_ramp *ramp[3];
    fogvol_volume_texture *fade;
    fogvol_frame_desc fd;
    settings s;
    int i;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    ds_draw(&d->gl, &d->scene, v, p, DW, DH);
    memset(&s, 0, sizeof s);
    s.fog_scale = 1.0f;
    make_ramps(fv, &s, ramp);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, v, sizeof fd.view);
    memcpy(fd.projection, p, sizeof fd.projection);
    fd.znear = 0.1f;
    fd.zfar = 40.0f;
    fd.viewport[2] = DW;
    fd.viewport[3] = DH;
    for (i = 0; i < d->scene.mesh_count; ++i) fm[i] = upload(fv, &d->scene.mesh[i]);
    fade = fade_texture(fv);
    fogvol_begin_frame(fv, &fd);
    add_scene(fv, &d->scene, fm, ramp, fade);
    fogvol_end_frame(fv, NULL);
    if (fade) fogvol_destroy_volume_texture(fv, fade);
    for (i = 0; i < d->scene.mesh_count; ++i) fogvol_destroy_mesh(fv, fm[i]);
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static GLuint demo_texture(GLenum internal, GLenum format, GLenum type)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, (GLint)internal, DW, DH, 0, format, type, NULL);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

/* the window gets the scene back (for the blended effects), then effect k, then a PNG */
static int post_effect(demo *d, fogvol_context *fv, const fogvol_frame_desc *fd, GLuint fbo, GLuint color, int k,
                       const char *dir, const fogvol_ramp *ramp)
{
    static const char *const names[3] = {"dof.png", "outlines.png", "distance_fog.png"};
    fogvol_dof_desc dd;
    fogvol_outline_desc od;
    fogvol_distance_fog_desc gd;
    fogvol_result r;
    unsigned char *img = d->g.pixels;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, DW, DH, 0, 0, DW, DH, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    memset(&dd, 0, sizeof dd);
    memset(&od, 0, sizeof od);
    memset(&gd, 0, sizeof gd);
    dd.frame = od.frame = gd.frame = fd;
    dd.color_texture = color;
    dd.focus_distance = 9.0f; /* the pillars in the middle sharp, the front and the back blurred */
    dd.focus_range = 5.0f;
    dd.max_radius = 5.0f;
    dd.taps = 24;
    od.color[0] = 0.05f, od.color[1] = 0.04f, od.color[2] = 0.08f, od.color[3] = 0.9f;
    gd.ramp = ramp;
    gd.start = 4.0f;
    r = k == 0 ? fogvol_post_dof(fv, &dd) : k == 1 ? fogvol_post_outlines(fv, &od) : fogvol_post_distance_fog(fv, &gd);
    if (r != FOGVOL_SUCCESS) {
        fprintf(stderr, "%s: %s\n", names[k], fogvol_result_string(r));
        return 0;
    }
    glu_pixels(&d->g);
    save_row(dir, names[k], &img, 1, DW, DH);
    return 1;
}

/* dof.png, outlines.png, distance_fog.png: the overview with each image-space effect */
static int post_effects(demo *d, const char *dir)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_frame_desc fd;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    GLuint fbo, color, depth;
    int k, ok = 1;
    if (!glu_create(&d->g, DW, DH, 1)) return 0;
    ds_gl_init(&d->gl, &d->scene);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) return 0;
    color = demo_texture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE);
    depth = demo_texture(GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    memset(&fd, 0, sizeof fd);
    camera(0, DW, DH, fd.view, fd.projection);
    scene_to_textures(d, fv, fd.view, fd.projection, fbo);
    fd.znear = 0.1f;
    fd.zfar = 40.0f;
    fd.viewport[2] = DW;
    fd.viewport[3] = DH;
    fd.engine_depth_texture = depth;
    memset(&rd, 0, sizeof rd); /* distance fog: a hazy blue that swallows the far end */
    rd.color[0] = 0.62f, rd.color[1] = 0.70f, rd.color[2] = 0.80f, rd.density = 0.12f;
    fogvol_create_ramp(fv, &rd, &ramp);
    for (k = 0; k < 3; ++k) ok &= post_effect(d, fv, &fd, fbo, color, k, dir, ramp);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &color);
    glDeleteTextures(1, &depth);
    ds_gl_free(&d->gl);
    glu_destroy(&d->g);
    return ok;
}

/* ---- textured fog and volume light by compare (fogvol_volume_desc.density / color, fogvol_add_light) ---- */

static fogvol_volume_texture *demo_volume_texture(fogvol_context *fv, int kind, int n)
{
    unsigned char *px = (unsigned char *)malloc((size_t)n * n * 4);
    fogvol_texture_desc td;
    fogvol_volume_texture *t = NULL;
    int x, y, k;
    for (y = 0; y < n; ++y)
        for (x = 0; x < n; ++x) {
            unsigned char *q = px + 4 * (y * n + x);
            float u = 6.2831853f * x / n, v = 6.2831853f * y / n, f = 0.0f;
            for (k = 1; k <= 4; ++k) /* tileable sum of waves: soft cloudy noise */
                f += sinf(k * u + 1.7f * k + cosf(k * v * 1.3f)) * sinf(k * v + 0.9f * k + sinf(u * k)) / (float)k;
            f = 0.5f + 0.45f * f;
            f = f < 0 ? 0 : f > 1 ? 1 : f;
            if (kind == 0) { /* density noise */
                q[0] = q[1] = q[2] = (unsigned char)(255 * f);
            } else if (kind == 1) { /* shaft gradient (1 texel high): thin at the base */
                q[0] = q[1] = q[2] = (unsigned char)(255.0f * powf((float)x / (n - 1), 1.5f));
            } else { /* colour: warm and cold patches */
                q[0] = (unsigned char)(255 * (0.7f + 0.3f * f));
                q[1] = (unsigned char)(255 * (0.75f + 0.2f * sinf(u)));
                q[2] = (unsigned char)(255 * (1.0f - 0.45f * f));
            }
            q[3] = 255;
        }
    memset(&td, 0, sizeof td);
    td.width = n;
    td.height = kind == 1 ? 1 : n;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = kind == 1 ? FOGVOL_WRAP_CLAMP : FOGVOL_WRAP_REPEAT;
    if (fogvol_create_volume_texture(fv, &td, &t) != FOGVOL_SUCCESS) t = NULL;
    free(px);
    return t;
}

/* A frustum-shaped light shaft: a box whose top face is shrunk (convex). */
static shp_mesh demo_shaft(void)
{
    shp_mesh m = shp_box(1.4f, 2.6f, 1.0f);
    int i;
    for (i = 0; i < m.vcount; ++i)
        if (m.pos[3 * i + 1] > 0) m.pos[3 * i] *= 0.35f, m.pos[3 * i + 2] *= 0.35f;
    return m;
}

/* Two light shafts by compare, each falling off from its top (fogvol_light_desc.falloff_radius) and
   fading where the ground meets its walls (edge_softness); unless before, each also glows as a soft
   volume of its light ramp (ramp[k]; NULL = no glow) fading along its length. */
static fogvol_mesh *demo_tl_lights(fogvol_context *fv, int before, fogvol_ramp *const *ramp,
                                   const fogvol_volume_texture *fade)
{
    static const float rot[2][4] = {{15, 0, 0, 1}, {-25, 0, 1, 0}}, pos[2][3] = {{-5.2f, 1.6f, -0.8f}, {2.6f, 1.2f, -4.3f}};
    static const float rgb[2][3] = {{1.0f, 0.72f, 0.38f}, {0.45f, 0.62f, 1.0f}}, old_rgb[2][3] = {{0.9f, 0.65f, 0.3f},
                                                                                             {0.2f, 0.45f, 0.8f}};
    fogvol_mesh *shaft;
    fogvol_light_desc ld;
    fogvol_volume_desc vd;
    float r[16], t[16];
    shp_mesh sm = demo_shaft();
    int k;
    shaft = upload(fv, &sm);
    shp_free(&sm);
    for (k = 0; k < 2; ++k) { /* a warm shaft over the column at (-5.5, -0.8), a cold one through the arch gate */
        memset(&ld, 0, sizeof ld);
        ld.mesh = shaft;
        shp_mat_rotate(r, rot[k][0], rot[k][1], rot[k][2], rot[k][3]);
        shp_mat_translate(t, pos[k][0], pos[k][1], pos[k][2]);
        shp_mat_mul(ld.model, t, r);
        memcpy(ld.color, before ? old_rgb[k] : rgb[k], sizeof ld.color);
        if (!before) { /* from the shaft's top (model y 2.6), reaching past its base */
            ld.position[0] = ld.model[4] * 2.9f + ld.model[12];
            ld.position[1] = ld.model[5] * 2.9f + ld.model[13];
            ld.position[2] = ld.model[6] * 2.9f + ld.model[14];
            ld.falloff_radius = 6.5f;
            ld.edge_softness = 0.35f;
            ld.intensity = 1.35f;
        }
        if (fogvol_add_light(fv, &ld) != FOGVOL_SUCCESS) fprintf(stderr, "demo: light refused\n");
        if (before || !ramp[k]) continue;
        memset(&vd, 0, sizeof vd);
        vd.mesh = shaft;
        vd.ramp = ramp[k];
        memcpy(vd.model, ld.model, sizeof vd.model);
        vd.density = fade;
        vd.density_map[1] = 1.0f / 5.2f; /* s from the base (y -2.6) to the top (2.6) */
        vd.density_map[3] = 0.5f;
        vd.density_map[7] = 0.5f;
        fogvol_add_volume(fv, &vd);
    }
    return shaft;
}

/* textured: fog groups with density noise (the bank scrolled, the shaft thinning towards its
   base), a colour texture on the floating fog; lights: two convex light volumes lighting the
   scene by compare, no fog. */

/* the scene's volumes with textures: noise density (scrolled), the light shafts' gradient, a colour */
static void demo_tl_volumes(demo *d, fogvol_context *fv, fogvol_mesh **fm, fogvol_ramp **ramp,
                            fogvol_volume_texture **tex, int lights)
{
    fogvol_volume_texture *noise = tex[0], *grad = tex[1], *colour = tex[2];
    int i;
    for (i = 0; i < d->scene.count; ++i) {
        const ds_object *o = &d->scene.obj[i];
        fogvol_volume_desc vd;
        if (o->kind == DS_OPAQUE) {
            fogvol_add_occluder(fv, fm[o->mesh], o->model);
            continue;
        }
        if (lights) continue;
        memset(&vd, 0, sizeof vd);
        vd.mesh = fm[o->mesh];
        vd.ramp = ramp[ds_group(o->kind)];
        vd.negative = o->kind == DS_HOLE;
        memcpy(vd.model, o->model, sizeof vd.model);
        if (o->fade) { /* s along the axis (demo_scene.h's fade_map), thin at the base */
            vd.density = grad;
            memcpy(vd.density_map, o->fade_map, sizeof vd.density_map);
        } else if (!vd.negative) { /* noise in the horizontal plane, scrolled (time 1.5 s, 0.2 units/s) */
            vd.density = noise;
            vd.density_map[0] = o->kind == DS_BANK ? 0.12f : 0.35f;
            vd.density_map[6] = o->kind == DS_BANK ? 0.12f : 0.35f;
            vd.density_map[3] = 0.2f * 1.5f;
            if (o->kind == DS_FOG) vd.color = colour;
        }
        fogvol_add_volume(fv, &vd);
    }
}

/* textured: fog groups with density noise (the bank scrolled, the light shafts thinning towards
   their base), a colour texture on the fog group; lights: two convex light volumes lighting the
   scene by compare, falling off and glowing (before: flat, as fogvol 0.2 drew them), no fog.
   Writes name (NULL: none) and returns the picture (malloc'ed, rows bottom to top; NULL on failure). */
static unsigned char *demo_texlight(demo *d, const char *dir, int lights, int before, const char *name)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *fm[DS_MAX_MESHES], *shaft = NULL;
    fogvol_ramp *ramp[3], *glow[2] = {NULL, NULL};
    fogvol_ramp_desc rd;
    fogvol_volume_texture *tex[3], *fade;
    fogvol_frame_desc fd;
    float v[16], p[16];
    unsigned char *imgs[1], *out;
    int i;
    if (!glu_create(&d->g, DW, DH, 1)) return NULL;
    ds_gl_init(&d->gl, &d->scene);
    camera(0, DW, DH, v, p);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        ds_gl_free(&d->gl);
        glu_destroy(&d->g);
        return NULL;
    }
    for (i = 0; i < d->scene.mesh_count; ++i) fm[i] = upload(fv, &d->scene.mesh[i]);
    for (i = 0; i < 3; ++i) tex[i] = demo_volume_texture(fv, i, i == 1 ? 32 : 64);
    fade = fade_texture(fv);
    for (i = 0; i < 2 && lights && !before; ++i) { /* the shafts' glow: faint, soft, their own colours */
        memset(&rd, 0, sizeof rd);
        rd.color[0] = i ? 0.45f : 1.0f, rd.color[1] = i ? 0.62f : 0.72f, rd.color[2] = i ? 1.0f : 0.38f;
        rd.density = 0.45f, rd.softness = 0.6f, rd.blend = FOGVOL_BLEND_LIGHT;
        fogvol_create_ramp(fv, &rd, &glow[i]);
    }
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f, rd.color[1] = 0.92f, rd.color[2] = 0.97f, rd.density = 1.1f, rd.softness = g_soft[0];
    fogvol_create_ramp(fv, &rd, &ramp[0]);
    rd.color[0] = 0.55f, rd.color[1] = 0.62f, rd.color[2] = 0.70f, rd.density = 0.45f, rd.softness = g_soft[1];
    fogvol_create_ramp(fv, &rd, &ramp[1]);
    rd.color[0] = 1.0f, rd.color[1] = 0.75f, rd.color[2] = 0.35f, rd.density = 0.8f, rd.blend = FOGVOL_BLEND_LIGHT;
    rd.softness = g_soft[2];
    fogvol_create_ramp(fv, &rd, &ramp[2]);
    ds_draw(&d->gl, &d->scene, v, p, DW, DH);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, v, sizeof v);
    memcpy(fd.projection, p, sizeof p);
    fd.znear = 0.1f;
    fd.zfar = 40.0f;
    fd.viewport[2] = DW;
    fd.viewport[3] = DH;
    fogvol_begin_frame(fv, &fd);
    demo_tl_volumes(d, fv, fm, ramp, tex, lights);
    if (lights) shaft = demo_tl_lights(fv, before, glow, fade);
    fogvol_end_frame(fv, NULL);
    imgs[0] = glu_pixels(&d->g);
    if (name) {
        save_row(dir, name, imgs, 1, DW, DH);
        printf("  %-34s tier %s\n", name, fogvol_tier_name(fogvol_context_tier(fv, NULL)));
    }
    out = (unsigned char *)malloc((size_t)DW * DH * 4);
    if (out) memcpy(out, imgs[0], (size_t)DW * DH * 4);
    for (i = 0; i < d->scene.mesh_count; ++i) fogvol_destroy_mesh(fv, fm[i]);
    if (shaft) fogvol_destroy_mesh(fv, shaft);
    for (i = 0; i < 3; ++i) fogvol_destroy_volume_texture(fv, tex[i]);
    if (fade) fogvol_destroy_volume_texture(fv, fade);
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    for (i = 0; i < 2; ++i) fogvol_destroy_ramp(fv, glow[i]);
    fogvol_destroy_context(fv);
    ds_gl_free(&d->gl);
    glu_destroy(&d->g);
    return out;
}

/* A w x h crop at (x, y) (from the top left) of a DW x DH picture (rows bottom to top) into dst (rows top
   to bottom, stride pixels a row) */
static void crop_into(unsigned char *dst, int stride, const unsigned char *src, int x, int y, int w, int h)
{
    int r;
    for (r = 0; r < h; ++r) memcpy(dst + (size_t)r * stride * 4, src + ((size_t)(DH - 1 - (y + r)) * DW + x) * 4, (size_t)w * 4);
}

/* before_after.png: fogvol 0.2's look (left) and this version's (right): the fog sphere, the sunbeam
   (overview) and the lights by compare (light_compare) */
static int before_after(demo *d, const char *dir, const settings *base)
{
    enum { CW = 230, CH = 150 };
    static const int at[3][2] = {{375, 125}, {215, 50}, {150, 90}}; /* crops: sphere, sunbeam, lights */
    unsigned char *pic[2][2], *out = (unsigned char *)calloc((size_t)2 * CW * 3 * CH, 4);
    char path[512];
    int k, i, ok = out != NULL;
    for (k = 0; k < 2 && ok; ++k) {
        settings s = *base;
        shot sh = new_shot(DW, DH);
        s.before = !k;
        s.view = 0;
        ok = render(d, &s, 1, &sh);
        pic[k][0] = sh.rgba;
        sh.rgba = NULL;
        free_shot(&sh);
        pic[k][1] = demo_texlight(d, dir, 1, !k, NULL);
        ok = ok && pic[k][0] && pic[k][1];
    }
    for (i = 0; i < 3 && ok; ++i)
        for (k = 0; k < 2; ++k)
            crop_into(out + ((size_t)i * CH * 2 * CW + (size_t)k * CW) * 4, 2 * CW, pic[k][i == 2], at[i][0], at[i][1], CW, CH);
    if (ok) {
        snprintf(path, sizeof path, "%s/before_after.png", dir);
        stbi_write_png(path, 2 * CW, 3 * CH, 4, out, 2 * CW * 4);
        printf("%s\n", path);
    }
    for (k = 0; k < 2; ++k) {
        free(pic[k][0]);
        free(pic[k][1]);
    }
    free(out);
    return ok;
}

static int g_tap;
static int check(int ok, const char *what)
{
    printf("%s %d - %s\n", ok ? "ok" : "not ok", ++g_tap, what);
    return ok;
}

int main(int argc, char **argv)
{
    const char *dir = "build/demo";
    int do_check = 0, i, k, failures = 0;
    demo d;
    settings s;
    shot sh[3], plain;
    unsigned char *imgs[3];
    static const char *const view_names[3] = {"scene_overview.png", "scene_low.png", "scene_inside_fog_bank.png"};
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--check") == 0) do_check = 1;
        else dir = argv[i];
    }
    mkdir("build", 0777);
    mkdir(dir, 0777);
    memset(&d, 0, sizeof d);
    ds_scene_build(&d.scene);
    ds_scene_animate(&d.scene, 0.7);
    stbi_flip_vertically_on_write(0);
    memset(&s, 0, sizeof s);
    s.w = DW;
    s.h = DH;
    s.dither = 1;
    s.fog_scale = 1.0f;
    printf("fogvol %s demo, %dx%d, images in %s:\n", FOGVOL_VERSION_STRING, DW, DH, dir);

    /* three viewpoints (automatic tier), the third inside the fog bank */
    for (k = 0; k < 3; ++k) {
        sh[k] = new_shot(DW, DH);
        s.view = k;
        if (!render(&d, &s, 1, &sh[k])) return 1;
        imgs[0] = sh[k].rgba;
        save_row(dir, view_names[k], imgs, 1, DW, DH);
        report(view_names[k], &sh[k]);
    }
    if (do_check) {
        /* fog only where some group has thickness; the inside view fogged everywhere */
        int n = DW * DH, same_outside = 0, outside = 0, changed_inside = 0, inside = 0, bank_everywhere = 1;
        plain = new_shot(DW, DH);
        s.view = 0;
        render(&d, &s, 0, &plain);
        for (i = 0; i < n; ++i) {
            int fogged = sh[0].thick[0][i] != 0 || sh[0].thick[1][i] != 0 || sh[0].thick[2][i] != 0;
            int diff = memcmp(sh[0].rgba + 4 * i, plain.rgba + 4 * i, 3) != 0;
            if (!fogged) {
                ++outside;
                same_outside += !diff;
            } else if (sh[0].thick[0][i] > 0.5f || sh[0].thick[1][i] > 2.0f) {
                ++inside;
                changed_inside += diff;
            }
            if (!(sh[2].thick[1][i] > 0)) bank_everywhere = 0;
        }
        printf("# overview: %d pixels without fog, %d of them unchanged; %d thickly fogged, %d of them changed\n",
               outside, same_outside, inside, changed_inside);
        failures += !check(outside > 1000 && same_outside == outside, "no fog where no volume is");
        failures += !check(inside > 1000 && changed_inside == inside, "fog where the volumes are");
        failures += !check(bank_everywhere, "inside the fog bank every pixel is fogged");
        free_shot(&plain);
    }
    /* the raw thickness of the fog group, false colour (0 .. 3 world units) */
    {
        unsigned char *fc = (unsigned char *)malloc((size_t)DW * DH * 4);
        false_colour(sh[0].thick[0], fc, DW * DH, 3.0f);
        imgs[0] = fc;
        save_row(dir, "thickness.png", imgs, 1, DW, DH);
        free(fc);
    }
    for (k = 0; k < 3; ++k) free_shot(&sh[k]);

    /* side by side at half size: the tiers, dithering at L = 2 (6-bit depth), the colour ramps. The
       tiers and the dithering on the classic RGBA8 digit path, as GPUs without framebuffer fetch run
       it: where the GL has it (Mesa), PS20 and PS13 sum 32-bit integers instead
       (FOGVOL_SPEEDUP_EXACT_SUM), which have no digits to dither and look like FLOAT */
    {
        settings v[3];
        int differ;
        for (k = 0; k < 3; ++k) {
            v[k] = s;
            v[k].w = DW / 2;
            v[k].h = DH / 2;
            v[k].view = 1;
            v[k].speedups_off = FOGVOL_SPEEDUP_EXACT_SUM;
        }
        v[0].tier = FOGVOL_TIER_PS13;
        v[1].tier = FOGVOL_TIER_PS20;
        v[2].tier = FOGVOL_TIER_FLOAT;
        differ = row(&d, dir, "tiers.png", v, 3, 1);
        printf("# tiers.png: the RGBA8 tiers' digits differ from FLOAT in at least %d pixels\n", differ);
        if (do_check) failures += !check(differ > 100, "tiers.png: the RGBA8 panels show their digits (differ from FLOAT)");
        for (k = 0; k < 3; ++k) { /* banding at low precision (close to the fog sphere) and its cure; the
                                     mean of 8 frames of the rotating pattern (fogvol_frame_desc.dither_frame) */
            v[k].tier = FOGVOL_TIER_PS20;
            v[k].bits = 2;
            v[k].view = 3;
            v[k].dither = k > 0;
            v[k].frames = k == 2 ? 8 : 0;
        }
        differ = row(&d, dir, "dither.png", v, 3, 0);
        printf("# dither.png: %d pixels differ between dithering off or on and the mean of 8 dithered frames\n", differ);
        if (do_check) failures += !check(differ > 100, "dither.png: dithering changes the picture");
        for (k = 0; k < 2; ++k) { /* soft edges: softness 0 | the demo's */
            v[k] = s;
            v[k].w = DW / 2;
            v[k].h = DH / 2;
            v[k].view = 3;
            v[k].before = !k;
        }
        differ = row(&d, dir, "soft_edges.png", v, 2, 0);
        if (do_check) failures += !check(differ > 1000, "soft_edges.png: soft edges change the fog");
        for (k = 0; k < 3; ++k) {
            v[k] = v[2];
            v[k].tier = FOGVOL_TIER_AUTO;
            v[k].speedups_off = 0;
            v[k].ramp = k;
        }
        row(&d, dir, "ramps.png", v, 3, 0);
    }
    k = post_effects(&d, dir);
    if (do_check) failures += !check(k, "image-space effects: dof.png, outlines.png, distance_fog.png");
    else failures += !k;
    free(demo_texlight(&d, dir, 0, 0, "textured_fog.png"));
    free(demo_texlight(&d, dir, 1, 0, "light_compare.png"));
    k = before_after(&d, dir, &s);
    if (do_check) failures += !check(k, "before_after.png");
    else failures += !k;
    ds_scene_free(&d.scene);
    if (do_check) printf("1..%d\n", g_tap);
    return failures ? 1 : 0;
}
