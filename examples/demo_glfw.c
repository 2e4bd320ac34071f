/* demo_glfw.c - fogvol.h in a window (GLFW, OpenGL 3.3 core).

   The demo's place (examples/demo_scene.h, shared with demo_headless.c): a
   sunlit courtyard with a cobbled path, a house, columns, an arch gate, rocks,
   pine trees and a lamp post, drawn by the demo's own shaders. fogvol adds the
   fog volumes placed in it: a fog sphere around the rocks, a ring turning in the
   arch, a writhing cloud (deformed on the CPU and re-uploaded every frame), a
   low mist bank with a drifting clearing carved by a negative sphere, and a
   sunbeam and the lamp's cone blended additively (FOGVOL_BLEND_LIGHT).

   Controls
     mouse          look around (click into the window to capture the mouse, Tab releases it)
     W A S D        fly (Space / C: up / down, Shift: faster); the camera may enter the fog
     T              cycle tier PS13 -> PS20 -> FLOAT (tiers the context refuses are skipped)
     B              cycle encoding bits per channel 3, 4, 5, 6 (precision vs. faces per pixel)
     G              dithering on / off            R   colour ramp: extinction, linear, gradient
     L              fog / light blend of the main group (sphere, ring, cloud)
     O              paint pixels whose face sums overflowed in magenta
     P              pause the animation           Esc quit
   The window title shows the frame time and the current settings.

   usage: demo_glfw [--frames N] [--screenshot FILE.png] [--size WxH] [--tier ps13|ps20|float] [--bits L]
                    [--camera x,y,z,yaw,pitch] [--keys KEYS]
     --frames N      render N frames (fixed 1/60 s animation steps) and exit
     --screenshot F  write the last frame to F as PNG
     --size WxH      window size (default 960x540)
     --tier T        start with this tier (default: the best the context has)
     --bits L        start with L bits per channel (default 4)
     --camera ...    start position and yaw / pitch in degrees (yaw 0 looks down -z)
     --keys KEYS     press these keys, one per frame from the first (e.g. TTB: two tiers on, then bits)

   build: cc -std=c99 -I. examples/demo_glfw.c -o demo_glfw -lglfw -lGL -lm */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES
#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>
#include "examples/demo_scene.h"
#include "examples/example_gl.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#define ZNEAR 0.1f
#define ZFAR 60.0f

static const fogvol_tier k_tiers[3] = {FOGVOL_TIER_PS13, FOGVOL_TIER_PS20, FOGVOL_TIER_FLOAT};
static const int k_bits[4] = {3, 4, 5, 6};
static const char *const k_ramp_names[3] = {"extinction", "linear", "gradient"};

enum { R_MAIN, R_BANK, R_LIGHT, R_COUNT }; /* colour ramps, in the order of ds_group() */

typedef struct app {
    GLFWwindow *win;
    ds_scene scene; /* the place: meshes, opaque objects, volumes */
    ds_gl gl;       /* its opaque renderer */
    /* fogvol objects: they belong to the context and are rebuilt with it */
    fogvol_context *fv;
    fogvol_mesh *vol[DS_MAX_MESHES]; /* one per scene mesh */
    fogvol_ramp *ramp[R_COUNT];
    fogvol_volume_texture *fade; /* the lights' fade along their length (NULL on PS13) */
    /* settings */
    int tier_i, bits_i, dither, ramp_model, main_light, paused, show_overflow, soft;
    /* camera and time */
    float cam[3], yaw, pitch;
    double anim_t, last_x, last_y;
    int captured, have_mouse;
} app;

static void log_cb(void *u, fogvol_log_level level, const char *msg)
{
    (void)u;
    if (level <= FOGVOL_LOG_WARNING) fprintf(stderr, "%s\n", msg);
}

/* The main group's colour ramp: the model R cycles, the blend L toggles. */
static void make_main_ramp(app *a)
{
    static const fogvol_color_key keys[4] = {{0.0f, {0.2f, 0.9f, 0.8f, 0.0f}},
                                             {0.8f, {0.3f, 0.8f, 1.0f, 0.45f}},
                                             {2.0f, {0.9f, 0.3f, 0.8f, 0.75f}},
                                             {3.5f, {1.0f, 0.7f, 0.2f, 0.95f}}};
    fogvol_ramp_desc rd;
    fogvol_destroy_ramp(a->fv, a->ramp[R_MAIN]); /* (NULL is fine) */
    a->ramp[R_MAIN] = NULL;
    memset(&rd, 0, sizeof rd);
    rd.model = (fogvol_ramp_model)a->ramp_model;
    rd.color[0] = 0.70f, rd.color[1] = 0.78f, rd.color[2] = 0.90f;
    rd.density = a->ramp_model == FOGVOL_RAMP_LINEAR ? 0.45f : 1.1f;
    rd.keys = keys;
    rd.key_count = 4;
    rd.blend = a->main_light ? FOGVOL_BLEND_LIGHT : FOGVOL_BLEND_FOG;
    rd.softness = a->soft ? 0.6f : 0.0f; /* soft edges: the density rises over 0.6 units from each end */
    if (a->soft && a->ramp_model == FOGVOL_RAMP_EXTINCTION) rd.density = 1.4f;
    if (fogvol_create_ramp(a->fv, &rd, &a->ramp[R_MAIN]) != FOGVOL_SUCCESS) fprintf(stderr, "fogvol: ramp refused\n");
}

/* a 1-texel-high density texture fading the lights along their length (demo_scene.h) */
static fogvol_volume_texture *make_fade(fogvol_context *fv)
{
    unsigned char px[DS_FADE_TEXELS * 4];
    fogvol_texture_desc td;
    fogvol_volume_texture *t = NULL;
    if (fogvol_context_tier(fv, NULL) == FOGVOL_TIER_PS13) return NULL; /* (no density textures) */
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

static void destroy_fog(app *a)
{
    int i;
    if (!a->fv) return;
    for (i = 0; i < DS_MAX_MESHES; ++i) fogvol_destroy_mesh(a->fv, a->vol[i]), a->vol[i] = NULL;
    for (i = 0; i < R_COUNT; ++i) fogvol_destroy_ramp(a->fv, a->ramp[i]), a->ramp[i] = NULL;
    fogvol_destroy_volume_texture(a->fv, a->fade);
    a->fade = NULL;
    fogvol_destroy_context(a->fv);
    a->fv = NULL;
}

/* (Re-)create the context with this tier and encoding, and everything it owns.
   Returns 0 (keeping the current context) when fogvol_create_context refuses. */
static int build_fog(app *a, fogvol_tier tier, int bits)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_ramp_desc rd;
    int i;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc = glfwGetProcAddress; /* GLFWglproc and fogvol_gl_proc are both void (*)(void) */
    cd.logger.func = log_cb;
    cd.tier = tier;
    cd.encoding_bits = bits;
    cd.disable_dither = !a->dither;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) return 0;
    destroy_fog(a);
    a->fv = fv;
    for (i = 0; i < 3; ++i)
        if (k_tiers[i] == fogvol_context_tier(fv, NULL)) a->tier_i = i;
    for (i = 0; i < 4; ++i)
        if (k_bits[i] == fogvol_context_encoding(fv)->bits) a->bits_i = i;
    for (i = 0; i < a->scene.mesh_count; ++i) a->vol[i] = exm_fog_mesh(fv, &a->scene.mesh[i], 0);
    make_main_ramp(a);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.74f, rd.color[1] = 0.80f, rd.color[2] = 0.86f, rd.density = 0.35f;
    rd.softness = a->soft ? 0.5f : 0.0f;
    fogvol_create_ramp(fv, &rd, &a->ramp[R_BANK]);
    rd.color[0] = 1.0f, rd.color[1] = 0.78f, rd.color[2] = 0.42f, rd.density = 0.30f, rd.blend = FOGVOL_BLEND_LIGHT;
    if (a->soft) rd.density = 0.8f, rd.softness = 0.2f; /* (the fade thins it) */
    fogvol_create_ramp(fv, &rd, &a->ramp[R_LIGHT]);
    a->fade = a->soft ? make_fade(fv) : NULL;
    return 1;
}

static void cycle_tier(app *a)
{
    int k;
    for (k = 1; k <= 3; ++k) {
        int i = (a->tier_i + k) % 3;
        if (build_fog(a, k_tiers[i], k_bits[a->bits_i])) return;
        fprintf(stderr, "demo: tier %s refused by this context, skipped\n", fogvol_tier_name(k_tiers[i]));
    }
}

/* ---- input --------------------------------------------------------------------- */
static void press(app *a, int key)
{
    GLFWwindow *w = a->win;
    switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_TAB:
        a->captured = 0;
        glfwSetInputMode(w, GLFW_CURSOR, GLFW_CURSOR_NORMAL);
        break;
    case GLFW_KEY_T: cycle_tier(a); break;
    case GLFW_KEY_B:
        if (!build_fog(a, k_tiers[a->tier_i], k_bits[(a->bits_i + 1) % 4]))
            fprintf(stderr, "demo: %d-bit encoding refused\n", k_bits[(a->bits_i + 1) % 4]);
        break;
    case GLFW_KEY_G:
        a->dither = !a->dither;
        fogvol_set_dither(a->fv, a->dither);
        break;
    case GLFW_KEY_R:
        a->ramp_model = (a->ramp_model + 1) % 3;
        make_main_ramp(a);
        break;
    case GLFW_KEY_L:
        a->main_light = !a->main_light;
        make_main_ramp(a);
        break;
    case GLFW_KEY_K:
        a->soft = !a->soft;
        build_fog(a, k_tiers[a->tier_i], k_bits[a->bits_i]);
        break;
    case GLFW_KEY_O: a->show_overflow = !a->show_overflow; break;
    case GLFW_KEY_P: a->paused = !a->paused; break;
    default: break;
    }
}

static void key_cb(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode, (void)mods;
    if (action == GLFW_PRESS) press((app *)glfwGetWindowUserPointer(w), key);
}

static void button_cb(GLFWwindow *w, int button, int action, int mods)
{
    app *a = (app *)glfwGetWindowUserPointer(w);
    (void)button, (void)mods;
    if (action == GLFW_PRESS && !a->captured) {
        a->captured = 1;
        a->have_mouse = 0;
        glfwSetInputMode(w, GLFW_CURSOR, GLFW_CURSOR_DISABLED);
    }
}

static void cursor_cb(GLFWwindow *w, double x, double y)
{
    app *a = (app *)glfwGetWindowUserPointer(w);
    if (a->captured && a->have_mouse) {
        a->yaw += (float)(x - a->last_x) * 0.15f;
        a->pitch -= (float)(y - a->last_y) * 0.15f;
        if (a->pitch > 89.0f) a->pitch = 89.0f;
        if (a->pitch < -89.0f) a->pitch = -89.0f;
    }
    a->last_x = x, a->last_y = y, a->have_mouse = 1;
}

/* forward vector from yaw (0 = -z) and pitch, in degrees */
static void cam_dir(const app *a, float f[3])
{
    double y = a->yaw * 3.14159265358979 / 180.0, p = a->pitch * 3.14159265358979 / 180.0;
    f[0] = (float)(sin(y) * cos(p));
    f[1] = (float)sin(p);
    f[2] = (float)(-cos(y) * cos(p));
}

static int down(const app *a, int key) { return glfwGetKey(a->win, key) == GLFW_PRESS; }

static void fly(app *a, float dt)
{
    float f[3], r[3], speed = 3.0f * dt * (down(a, GLFW_KEY_LEFT_SHIFT) ? 4.0f : 1.0f), l;
    int k;
    cam_dir(a, f);
    l = sqrtf(f[0] * f[0] + f[2] * f[2]) + 1e-6f;
    r[0] = -f[2] / l, r[1] = 0.0f, r[2] = f[0] / l; /* right = forward x up, normalised */
    for (k = 0; k < 3; ++k)
        a->cam[k] += speed * (f[k] * (float)(down(a, GLFW_KEY_W) - down(a, GLFW_KEY_S)) +
                              r[k] * (float)(down(a, GLFW_KEY_D) - down(a, GLFW_KEY_A)));
    a->cam[1] += speed * (float)(down(a, GLFW_KEY_SPACE) - down(a, GLFW_KEY_C));
}

/* ---- matrices -------------------------------------------------------------------- */
static void view_matrix(const app *a, float m[16])
{
    float f[3], s[3], u[3], l;
    cam_dir(a, f);
    s[0] = -f[2], s[1] = 0.0f, s[2] = f[0]; /* f x (0,1,0) */
    l = sqrtf(s[0] * s[0] + s[2] * s[2]);
    s[0] /= l, s[2] /= l;
    u[0] = s[1] * f[2] - s[2] * f[1], u[1] = s[2] * f[0] - s[0] * f[2], u[2] = s[0] * f[1] - s[1] * f[0];
    shp_mat_identity(m);
    m[0] = s[0], m[4] = s[1], m[8] = s[2];
    m[1] = u[0], m[5] = u[1], m[9] = u[2];
    m[2] = -f[0], m[6] = -f[1], m[10] = -f[2];
    m[12] = -(s[0] * a->cam[0] + s[1] * a->cam[1] + s[2] * a->cam[2]);
    m[13] = -(u[0] * a->cam[0] + u[1] * a->cam[1] + u[2] * a->cam[2]);
    m[14] = f[0] * a->cam[0] + f[1] * a->cam[1] + f[2] * a->cam[2];
}

static void perspective(float m[16], float fovy_deg, float aspect, float n, float f)
{
    float t = 1.0f / tanf(fovy_deg * 3.14159265f / 360.0f);
    memset(m, 0, 16 * sizeof(float));
    m[0] = t / aspect;
    m[5] = t;
    m[10] = (f + n) / (n - f);
    m[11] = -1.0f;
    m[14] = 2.0f * f * n / (n - f);
}

/* ---- one frame ------------------------------------------------------------------- */
static fogvol_frame_stats render(app *a, int w, int h)
{
    float view[16], proj[16];
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    int i;
    memset(&st, 0, sizeof st);
    view_matrix(a, view);
    perspective(proj, 60.0f, (float)w / (float)h, ZNEAR, ZFAR);
    ds_scene_animate(&a->scene, a->anim_t);
    ds_draw(&a->gl, &a->scene, view, proj, w, h); /* the opaque scene: sky, ground, buildings ... */
    if (!a->fv) return st;

    /* the cloud's new shape: one fogvol mesh per frame, re-created before the frame opens
       (fogvol_destroy_mesh inside an open frame would take it out of the frame) */
    if (!a->paused || !a->vol[a->scene.blob_mesh]) {
        fogvol_destroy_mesh(a->fv, a->vol[a->scene.blob_mesh]);
        a->vol[a->scene.blob_mesh] = exm_fog_mesh(a->fv, &a->scene.mesh[a->scene.blob_mesh], 0);
    }

    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, view, sizeof view);
    memcpy(fd.projection, proj, sizeof proj);
    fd.znear = ZNEAR;
    fd.zfar = ZFAR;
    fd.viewport[2] = w;
    fd.viewport[3] = h;
    fd.show_overflow = a->show_overflow;
    fogvol_begin_frame(a->fv, &fd);
    for (i = 0; i < a->scene.count; ++i) {
        const ds_object *o = &a->scene.obj[i];
        fogvol_volume_desc vd;
        if (!a->vol[o->mesh]) continue;
        if (o->kind == DS_OPAQUE) { /* opaque things cut the fog */
            fogvol_add_occluder(a->fv, a->vol[o->mesh], o->model);
            continue;
        }
        memset(&vd, 0, sizeof vd);
        vd.mesh = a->vol[o->mesh];
        vd.ramp = a->ramp[ds_group(o->kind)]; /* main group, mist bank, light */
        vd.negative = o->kind == DS_HOLE;     /* the clearing in the mist */
        memcpy(vd.model, o->model, sizeof vd.model);
        if (o->fade && a->fade) { /* the sunbeam and the lamp's cone fade along their length */
            vd.density = a->fade;
            memcpy(vd.density_map, o->fade_map, sizeof vd.density_map);
        }
        fogvol_add_volume(a->fv, &vd);
    }
    fogvol_end_frame(a->fv, &st); /* renders, composites, restores the GL state */
    return st;
}

static const char *set_title(app *a, double ms)
{
    static char title[256];
    const fogvol_encoding *e = fogvol_context_encoding(a->fv);
    fogvol_tier tier = fogvol_context_tier(a->fv, NULL);
    snprintf(title, sizeof title,
             "fogvol demo | %.1f ms | [T] %s | [B] %d bits/ch (%d-bit, %d faces%s) | [G] dither %s | [R] %s | "
             "[L] %s | [K] soft edges %s%s%s",
             ms, fogvol_tier_name(tier), e->bits, e->precision_bits, e->max_faces,
             tier == FOGVOL_TIER_FLOAT ? ", unused by FLOAT" : "", /* R32F sums: no RGB encoding */
             a->dither ? "on" : "off", k_ramp_names[a->ramp_model], a->main_light ? "light" : "fog",
             a->soft ? "on" : "off", a->paused ? " | [P] paused" : "", a->show_overflow ? " | [O] overflow" : "");
    glfwSetWindowTitle(a->win, title);
    return title;
}

static int write_png(const char *path, int w, int h)
{
    unsigned char *px = (unsigned char *)malloc((size_t)w * (size_t)h * 4);
    int ok;
    if (!px) return 0;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    stbi_flip_vertically_on_write(1); /* GL rows go bottom to top */
    ok = stbi_write_png(path, w, h, 4, px, w * 4);
    free(px);
    return ok;
}

int main(int argc, char **argv)
{
    app a;
    int frames = 0, max_frames = 0, width = 960, height = 540, i, bits = 0, rc = 0, w = 0, h = 0;
    fogvol_tier tier = FOGVOL_TIER_AUTO;
    const char *shot = NULL, *keys = "";
    double t_prev, t_title, ms_acc = 0.0;
    int ms_n = 0, cam_n = 0;
    float cam[5];
    fogvol_frame_stats st;

    memset(&a, 0, sizeof a);
    memset(&st, 0, sizeof st);
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc) max_frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--screenshot") && i + 1 < argc) shot = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) sscanf(argv[++i], "%dx%d", &width, &height);
        else if (!strcmp(argv[i], "--bits") && i + 1 < argc) bits = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--keys") && i + 1 < argc) keys = argv[++i];
        else if (!strcmp(argv[i], "--camera") && i + 1 < argc)
            cam_n = sscanf(argv[++i], "%f,%f,%f,%f,%f", &cam[0], &cam[1], &cam[2], &cam[3], &cam[4]);
        else if (!strcmp(argv[i], "--tier") && i + 1 < argc) {
            ++i;
            tier = !strcmp(argv[i], "ps13") ? FOGVOL_TIER_PS13 : !strcmp(argv[i], "ps20") ? FOGVOL_TIER_PS20
                 : !strcmp(argv[i], "float") ? FOGVOL_TIER_FLOAT : FOGVOL_TIER_AUTO;
        } else {
            fprintf(stderr, "usage: %s [--frames N] [--screenshot FILE.png] [--size WxH] [--tier ps13|ps20|float] "
                            "[--bits 3..6] [--camera x,y,z,yaw,pitch] [--keys TBGRLOP]\n", argv[0]);
            return 2;
        }
    }
    if (!glfwInit()) {
        fprintf(stderr, "demo: glfwInit failed (no display? try xvfb-run -a)\n");
        return 1;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    a.win = glfwCreateWindow(width, height, "fogvol demo", NULL, NULL);
    if (!a.win) {
        fprintf(stderr, "demo: no OpenGL 3.3 core window\n");
        glfwTerminate();
        return 1;
    }
    glfwMakeContextCurrent(a.win);
    glfwSwapInterval(max_frames ? 0 : 1);
    glfwSetWindowUserPointer(a.win, &a);
    glfwSetKeyCallback(a.win, key_cb);
    glfwSetMouseButtonCallback(a.win, button_cb);
    glfwSetCursorPosCallback(a.win, cursor_cb);

    ds_scene_build(&a.scene);
    ds_gl_init(&a.gl, &a.scene);

    a.dither = 1;
    a.soft = 1;
    a.cam[0] = 1.0f, a.cam[1] = 5.2f, a.cam[2] = 13.5f, a.yaw = -3.5f, a.pitch = -14.5f;
    if (cam_n == 5) a.cam[0] = cam[0], a.cam[1] = cam[1], a.cam[2] = cam[2], a.yaw = cam[3], a.pitch = cam[4];
    if (!build_fog(&a, tier, bits)) {
        fprintf(stderr, "demo: fogvol_create_context failed\n");
        return 1;
    }

    t_prev = t_title = glfwGetTime();
    while (!glfwWindowShouldClose(a.win)) {
        double now = glfwGetTime(), dt = now - t_prev;
        t_prev = now;
        if (dt > 0.1) dt = 0.1;
        if (*keys) press(&a, *keys++); /* --keys: one scripted key press per frame (GLFW key codes are ASCII) */
        fly(&a, (float)dt);
        if (!a.paused) a.anim_t += max_frames ? 1.0 / 60.0 : dt; /* --frames: reproducible */
        glfwGetFramebufferSize(a.win, &w, &h);
        if (w > 0 && h > 0) {
            st = render(&a, w, h);
            if (shot && max_frames && frames + 1 >= max_frames) {
                if (!write_png(shot, w, h)) fprintf(stderr, "demo: cannot write %s\n", shot), rc = 1;
                else printf("demo: wrote %s (%dx%d)\n", shot, w, h);
            }
        }
        glfwSwapBuffers(a.win);
        glfwPollEvents();
        ms_acc += (glfwGetTime() - now) * 1000.0, ++ms_n;
        if (glfwGetTime() - t_title > 0.25 || (max_frames && frames + 1 >= max_frames)) {
            const char *title = set_title(&a, ms_acc / ms_n);
            t_title = glfwGetTime();
            if (max_frames && frames + 1 >= max_frames)
                printf("demo: %d frames; %s; last frame: %d passes, %d volumes, %d groups\n", frames + 1, title,
                       st.passes, st.volumes, st.groups);
            ms_acc = 0.0, ms_n = 0;
        }
        if (max_frames && ++frames >= max_frames) break;
    }
    if (shot && !max_frames && w > 0 && h > 0) { /* interactive: the frame on screen when the window closed */
        render(&a, w, h);
        if (!write_png(shot, w, h)) fprintf(stderr, "demo: cannot write %s\n", shot), rc = 1;
    }

    destroy_fog(&a);
    ds_gl_free(&a.gl);
    ds_scene_free(&a.scene);
    glfwDestroyWindow(a.win);
    glfwTerminate();
    return rc;
}
