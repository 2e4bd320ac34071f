/* courtyard.h - the browser demo's interactive page (included by demo_web.c): the demos' courtyard
   (examples/demo_scene.h) drawn in WebGL1 or WebGL2 by a light renderer of its own (GLSL ES 1.00:
   the place's procedural surfaces lit by the sun and the sky, no shadows), fogvol's volumes in it
   (the fog sphere, ring and drifting cloud, the mist bank with its clearing, the sunbeam and the
   lamp's cone), a camera to fly, and the page's controls:
     tier (auto, FLOAT, PS20, PS13; the WebGL version is the page's: ?webgl1 / ?webgl2), encoding
     bits, dithering, softness, density, colour ramp, fog on/off, animation; the frame time shown.
   Input: drag with the mouse or a finger to look; W A S D to move, Space / C up and down, Shift
   faster. The page's script calls the exported cy_* functions (EMSCRIPTEN_KEEPALIVE); with ?drive it
   drives them itself with synthetic events and checks the pictures (shell.html). */
#define DS_SCENE_ONLY
#include "examples/demo_scene.h"

enum { CY_TIER, CY_BITS, CY_DITHER, CY_SOFT, CY_DENSITY, CY_RAMP, CY_FOG, CY_PAUSE }; /* cy_set's what */
enum { CY_KEY_W, CY_KEY_A, CY_KEY_S, CY_KEY_D, CY_KEY_UP, CY_KEY_DOWN, CY_KEY_FAST, CY_KEYS };

typedef struct court {
    int version, width, height;
    ds_scene scene;
    GLuint prog, sky, sky_vbo, vbo[DS_MAX_OBJECTS], flat;
    GLint u_vp, u_model, u_color, u_material, u_eye, u_sky_inv, u_flat_vp, u_flat_model;
    /* fogvol */
    fogvol_context *fv;
    fogvol_mesh *fm[DS_MAX_MESHES];
    fogvol_ramp *ramp[3];
    fogvol_volume_texture *fade;
    /* settings */
    int tier, bits, dither, ramp_model, fog, paused;
    float soft, density;
    /* camera, input, time */
    float pos[3], yaw, pitch;
    int keys[CY_KEYS];
    double t, last_ms, frame_ms;
    int frames;
    unsigned char *snap;
    char status[256];
} court;

static court g_cy;

/* ---- the engine: the courtyard in GLSL ES 1.00 ------------------------------------------------- */
static const char *const cy_vs = "attribute vec3 p; attribute vec3 n; uniform mat4 vp, model; varying vec3 wp; varying vec3 vn;\n"
                                 "void main() { wp = (model * vec4(p, 1.0)).xyz; vn = n; gl_Position = vp * vec4(wp, 1.0); }\n";
static const char *const cy_fs_head = "#ifdef GL_FRAGMENT_PRECISION_HIGH\nprecision highp float;\n#else\n"
                                      "precision mediump float;\n#endif\n"
                                      "varying vec3 wp; varying vec3 vn; uniform vec3 color, eye; uniform int material;\n";
static const char *const cy_fs_main =
    "void main() {\n"
    "  vec3 n = normalize(vn), a = albedo(n);\n"
    "  vec3 amb = mix(vec3(0.26, 0.23, 0.18), vec3(0.42, 0.52, 0.68), 0.5 + 0.5 * n.y);\n"
    "  vec3 c = material == 7 ? color * 1.4 : a * (amb * 0.85 + vec3(1.1, 0.96, 0.78) * max(dot(n, sun), 0.0));\n"
    "  vec3 v = wp - eye; float dist = length(v);\n"
    "  c = mix(c, sky_color(normalize(vec3(v.x, 0.02 * dist, v.z))), 1.0 - exp(-0.018 * dist));\n"
    "  gl_FragColor = vec4(c, 1.0);\n"
    "}\n";
static const char *const cy_sky_vs = "attribute vec2 p; uniform mat4 inv_vp; varying vec3 dir;\n"
                                     "void main() {\n"
                                     "  vec4 a = inv_vp * vec4(p, -1.0, 1.0), b = inv_vp * vec4(p, 1.0, 1.0);\n"
                                     "  dir = b.xyz / b.w - a.xyz / a.w; gl_Position = vec4(p, 1.0, 1.0);\n"
                                     "}\n";
static const char *const cy_sky_fs = "varying vec3 dir;\n"
                                     "void main() { gl_FragColor = vec4(sky_color(normalize(dir)), 1.0); }\n";
/* the volumes' footprint (cy_footprint): the meshes in white */
static const char *const cy_flat_vs = "attribute vec3 p; uniform mat4 vp, model;\n"
                                      "void main() { gl_Position = vp * model * vec4(p, 1.0); }\n";
static const char *const cy_flat_fs = "precision mediump float; void main() { gl_FragColor = vec4(1.0); }\n";

static void cy_engine_init(court *c)
{
    static const char *const attribs[] = {"p", "n", NULL}, *const sky_attribs[] = {"p", NULL};
    static const float tri[6] = {-1, -1, 3, -1, -1, 3};
    const char *fs[4];
    int i;
    fs[0] = cy_fs_head, fs[1] = DS_GLSL_FUNCS, fs[2] = DS_GLSL_ALBEDO, fs[3] = cy_fs_main;
    c->prog = exm_program("courtyard", cy_vs, fs, 4, attribs);
    fs[0] = cy_fs_head, fs[2] = cy_sky_fs;
    c->sky = exm_program("courtyard sky", cy_sky_vs, fs, 3, sky_attribs);
    c->flat = exm_program("courtyard footprint", cy_flat_vs, &cy_flat_fs, 1, attribs);
    c->u_flat_vp = glGetUniformLocation(c->flat, "vp");
    c->u_flat_model = glGetUniformLocation(c->flat, "model");
    c->u_vp = glGetUniformLocation(c->prog, "vp");
    c->u_model = glGetUniformLocation(c->prog, "model");
    c->u_color = glGetUniformLocation(c->prog, "color");
    c->u_material = glGetUniformLocation(c->prog, "material");
    c->u_eye = glGetUniformLocation(c->prog, "eye");
    c->u_sky_inv = glGetUniformLocation(c->sky, "inv_vp");
    glGenBuffers(1, &c->sky_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, c->sky_vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof tri, tri, GL_STATIC_DRAW);
    for (i = 0; i < c->scene.count; ++i) { /* the opaque objects as flat triangles (world-space normals) */
        const ds_object *o = &c->scene.obj[i];
        if (o->kind != DS_OPAQUE) continue;
        glGenBuffers(1, &c->vbo[i]);
        exm_upload_flat(c->vbo[i], &c->scene.mesh[o->mesh], o->model, GL_STATIC_DRAW);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* the camera: position, yaw about y (0 looks down -z), pitch */
static void cy_camera(const court *c, float view[16], float proj[16], float eye[3])
{
    rc_camera cam;
    memset(&cam, 0, sizeof cam);
    cam.eye[0] = c->pos[0], cam.eye[1] = c->pos[1], cam.eye[2] = c->pos[2];
    cam.target[0] = c->pos[0] + sin(c->yaw) * cos(c->pitch);
    cam.target[1] = c->pos[1] + sin(c->pitch);
    cam.target[2] = c->pos[2] - cos(c->yaw) * cos(c->pitch);
    cam.up[1] = 1.0;
    cam.fovy_deg = 55.0, cam.aspect = (double)c->width / c->height, cam.znear = 0.1, cam.zfar = 40.0;
    cam.width = c->width, cam.height = c->height;
    rc_camera_matrices(&cam, view, proj);
    memcpy(eye, c->pos, sizeof c->pos);
}

/* the engine's opaque pass: sky, then the place (colour and depth) */
static void cy_engine_draw(court *c, const float view[16], const float proj[16], const float eye[3])
{
    float vp[16], inv[16];
    int i;
    shp_mat_mul(vp, proj, view);
    glViewport(0, 0, c->width, c->height);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_DEPTH_TEST);
    glEnableVertexAttribArray(0);
    if (ds_invert(inv, vp)) {
        glUseProgram(c->sky);
        glUniformMatrix4fv(c->u_sky_inv, 1, GL_FALSE, inv);
        glBindBuffer(GL_ARRAY_BUFFER, c->sky_vbo);
        glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 8, (void *)0);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(c->prog);
    glUniformMatrix4fv(c->u_vp, 1, GL_FALSE, vp);
    glUniform3f(c->u_eye, eye[0], eye[1], eye[2]);
    glEnableVertexAttribArray(1);
    for (i = 0; i < c->scene.count; ++i) {
        const ds_object *o = &c->scene.obj[i];
        if (o->kind != DS_OPAQUE) continue;
        glUniformMatrix4fv(c->u_model, 1, GL_FALSE, o->model);
        glUniform3f(c->u_color, o->color[0], o->color[1], o->color[2]);
        glUniform1i(c->u_material, o->material);
        glBindBuffer(GL_ARRAY_BUFFER, c->vbo[i]);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 24, (void *)12);
        glDrawArrays(GL_TRIANGLES, 0, c->scene.mesh[o->mesh].icount);
    }
    glDisableVertexAttribArray(1);
    glDisable(GL_DEPTH_TEST);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

/* ---- fogvol ------------------------------------------------------------------------------------- */

/* the three ramps from the settings: the fog group (model, density, softness s), the mist bank
   (a quarter of the density, 0.8 s), the light (the sunbeam and the lamp's cone: 0.6 of the density,
   s / 3, blended as light) */
static void cy_ramps(court *c)
{
    static const fogvol_color_key keys[4] = {{0.0f, {0.2f, 0.9f, 0.8f, 0.0f}},
                                             {0.8f, {0.3f, 0.8f, 1.0f, 0.45f}},
                                             {2.0f, {0.9f, 0.3f, 0.8f, 0.75f}},
                                             {3.5f, {1.0f, 0.7f, 0.2f, 0.95f}}};
    fogvol_ramp_desc rd;
    int i;
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(c->fv, c->ramp[i]), c->ramp[i] = NULL;
    memset(&rd, 0, sizeof rd);
    rd.model = (fogvol_ramp_model)c->ramp_model;
    rd.color[0] = 0.70f, rd.color[1] = 0.78f, rd.color[2] = 0.90f;
    rd.density = c->ramp_model == FOGVOL_RAMP_LINEAR ? 0.45f * c->density : 1.4f * c->density;
    rd.keys = keys;
    rd.key_count = 4;
    rd.softness = c->soft;
    fogvol_create_ramp(c->fv, &rd, &c->ramp[0]);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.74f, rd.color[1] = 0.80f, rd.color[2] = 0.86f, rd.density = 0.35f * c->density;
    rd.softness = 0.8f * c->soft;
    fogvol_create_ramp(c->fv, &rd, &c->ramp[1]);
    rd.color[0] = 1.0f, rd.color[1] = 0.78f, rd.color[2] = 0.42f, rd.density = 0.8f * c->density;
    rd.blend = FOGVOL_BLEND_LIGHT;
    rd.softness = c->soft / 3.0f;
    fogvol_create_ramp(c->fv, &rd, &c->ramp[2]);
}

static void cy_fog_free(court *c)
{
    int i;
    if (!c->fv) return;
    for (i = 0; i < DS_MAX_MESHES; ++i) fogvol_destroy_mesh(c->fv, c->fm[i]), c->fm[i] = NULL;
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(c->fv, c->ramp[i]), c->ramp[i] = NULL;
    fogvol_destroy_volume_texture(c->fv, c->fade);
    c->fade = NULL;
    fogvol_destroy_context(c->fv);
    c->fv = NULL;
}

/* the context for the tier and bits asked (0: automatic), its meshes, ramps and the lights' fade;
   on a refusal the automatic tier */
static void cy_fog_build(court *c)
{
    fogvol_context_desc cd;
    unsigned char px[DS_FADE_TEXELS * 4];
    fogvol_texture_desc td;
    int i;
    cy_fog_free(c);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = get_proc;
    cd.logger.func = log_cb;
    cd.tier = (fogvol_tier)c->tier;
    cd.encoding_bits = c->bits;
    cd.disable_dither = !c->dither;
    if (fogvol_create_context(&cd, &c->fv) != FOGVOL_SUCCESS) {
        printf("# tier %s with %d bits refused: automatic\n", fogvol_tier_name((fogvol_tier)c->tier), c->bits);
        cd.tier = FOGVOL_TIER_AUTO;
        cd.encoding_bits = 0;
        if (fogvol_create_context(&cd, &c->fv) != FOGVOL_SUCCESS) return;
    }
    for (i = 0; i < c->scene.mesh_count; ++i) c->fm[i] = exm_fog_mesh(c->fv, &c->scene.mesh[i], 0);
    cy_ramps(c);
    ds_fade_texels(px);
    memset(&td, 0, sizeof td);
    td.width = DS_FADE_TEXELS, td.height = 1, td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR, td.wrap = FOGVOL_WRAP_CLAMP;
    if (fogvol_context_tier(c->fv, NULL) != FOGVOL_TIER_PS13) fogvol_create_volume_texture(c->fv, &td, &c->fade);
}

/* fogvol's part of the frame: the opaque objects cut the volumes */
static fogvol_result cy_fog_draw(court *c, const float view[16], const float proj[16])
{
    fogvol_frame_desc fd;
    int i;
    if (!c->fv) return FOGVOL_ERROR_INVALID_STATE;
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, view, sizeof fd.view);
    memcpy(fd.projection, proj, sizeof fd.projection);
    fd.znear = 0.1f, fd.zfar = 40.0f;
    fd.viewport[2] = c->width, fd.viewport[3] = c->height;
    fogvol_begin_frame(c->fv, &fd);
    for (i = 0; i < c->scene.count; ++i) {
        const ds_object *o = &c->scene.obj[i];
        fogvol_volume_desc vd;
        if (!c->fm[o->mesh]) continue;
        if (o->kind == DS_OPAQUE) {
            fogvol_add_occluder(c->fv, c->fm[o->mesh], o->model);
            continue;
        }
        memset(&vd, 0, sizeof vd);
        vd.mesh = c->fm[o->mesh];
        vd.ramp = c->ramp[ds_group(o->kind)];
        vd.negative = o->kind == DS_HOLE;
        memcpy(vd.model, o->model, sizeof vd.model);
        if (o->fade && c->fade) {
            vd.density = c->fade;
            memcpy(vd.density_map, o->fade_map, sizeof vd.density_map);
        }
        fogvol_add_volume(c->fv, &vd);
    }
    return fogvol_end_frame(c->fv, NULL);
}

/* ---- the page ------------------------------------------------------------------------------------ */

/* one frame: dt seconds of movement and animation */
static void cy_step(court *c, double dt)
{
    float view[16], proj[16], eye[3], speed = (c->keys[CY_KEY_FAST] ? 8.0f : 2.5f) * (float)dt;
    float fx = sinf(c->yaw), fz = -cosf(c->yaw);
    double t0 = emscripten_get_now();
    int i;
    c->pos[0] += speed * (fx * (c->keys[CY_KEY_W] - c->keys[CY_KEY_S]) - fz * (c->keys[CY_KEY_A] - c->keys[CY_KEY_D]));
    c->pos[2] += speed * (fz * (c->keys[CY_KEY_W] - c->keys[CY_KEY_S]) + fx * (c->keys[CY_KEY_A] - c->keys[CY_KEY_D]));
    c->pos[1] += speed * (c->keys[CY_KEY_UP] - c->keys[CY_KEY_DOWN]);
    if (!c->paused) {
        c->t += dt;
        ds_scene_animate(&c->scene, c->t);
        if (c->fv) { /* the cloud's vertices moved */
            fogvol_destroy_mesh(c->fv, c->fm[c->scene.blob_mesh]);
            c->fm[c->scene.blob_mesh] = exm_fog_mesh(c->fv, &c->scene.mesh[c->scene.blob_mesh], 0);
        }
    }
    cy_camera(c, view, proj, eye);
    cy_engine_draw(c, view, proj, eye);
    if (c->fog) cy_fog_draw(c, view, proj);
    ++c->frames;
    i = snprintf(c->status, sizeof c->status, "WebGL%d | %s | GLSL %s | ", c->version,
                 c->fv ? fogvol_tier_name(fogvol_context_tier(c->fv, NULL)) : "no context",
                 fogvol_dialect_name(c->version == 2 ? FOGVOL_GLSL_300ES : FOGVOL_GLSL_100));
    if (c->fv && fogvol_context_tier(c->fv, NULL) != FOGVOL_TIER_FLOAT)
        i += snprintf(c->status + i, sizeof c->status - (size_t)i, "%d bits/ch | ", fogvol_context_encoding(c->fv)->bits);
    glFinish(); /* (the frame's GL work done: the time is the frame's) */
    c->frame_ms = c->frames == 1 ? emscripten_get_now() - t0 : c->frame_ms * 0.9 + (emscripten_get_now() - t0) * 0.1;
    snprintf(c->status + i, sizeof c->status - (size_t)i, "%.1f ms a frame", c->frame_ms);
    { /* the page's status line (the status has no quote or backslash) */
        char js[320];
        snprintf(js, sizeof js, "var e = document.getElementById('stats'); if (e) e.textContent = '%s';", c->status);
        emscripten_run_script(js);
    }
}

static void cy_loop(void)
{
    double now = emscripten_get_now(), dt = g_cy.last_ms > 0 ? (now - g_cy.last_ms) / 1000.0 : 1.0 / 60.0;
    g_cy.last_ms = now;
    cy_step(&g_cy, dt > 0.1 ? 0.1 : dt);
}

/* the page's controls (shell.html): what = CY_TIER ..., v its value */
EMSCRIPTEN_KEEPALIVE void cy_set(int what, double v)
{
    court *c = &g_cy;
    switch (what) {
    case CY_TIER: c->tier = (int)v, cy_fog_build(c); break;
    case CY_BITS: c->bits = (int)v, cy_fog_build(c); break;
    case CY_DITHER:
        c->dither = v != 0;
        if (c->fv) fogvol_set_dither(c->fv, c->dither);
        break;
    case CY_SOFT: c->soft = (float)v, cy_ramps(c); break;
    case CY_DENSITY: c->density = (float)v, cy_ramps(c); break;
    case CY_RAMP: c->ramp_model = (int)v, cy_ramps(c); break;
    case CY_FOG: c->fog = v != 0; break;
    case CY_PAUSE: c->paused = v != 0; break;
    default: break;
    }
}

EMSCRIPTEN_KEEPALIVE void cy_key(int key, int down)
{
    if (key >= 0 && key < CY_KEYS) g_cy.keys[key] = down != 0;
}

/* look: a drag of (dx, dy) pixels */
EMSCRIPTEN_KEEPALIVE void cy_look(double dx, double dy)
{
    g_cy.yaw += (float)dx * 0.005f;
    g_cy.pitch -= (float)dy * 0.005f;
    if (g_cy.pitch > 1.4f) g_cy.pitch = 1.4f;
    if (g_cy.pitch < -1.4f) g_cy.pitch = -1.4f;
}

/* the page's own check (?drive): one frame of 1/30 s; the canvas read back (RGBA, bottom row first);
   the camera (x, y, z, yaw, pitch) */
EMSCRIPTEN_KEEPALIVE void cy_frame(void) { cy_step(&g_cy, 1.0 / 30.0); }
EMSCRIPTEN_KEEPALIVE unsigned char *cy_snapshot(void)
{
    glReadPixels(0, 0, g_cy.width, g_cy.height, GL_RGBA, GL_UNSIGNED_BYTE, g_cy.snap);
    return g_cy.snap;
}
EMSCRIPTEN_KEEPALIVE double cy_camera_value(int i)
{
    return i < 3 ? g_cy.pos[i] : i == 3 ? g_cy.yaw : g_cy.pitch;
}

/* The page's own check (?drive): the volumes' footprint, every fog, mist, hole and light mesh drawn in
   white on black by the courtyard's camera with no depth test (the opaque objects do not hide them), read
   back like cy_snapshot: where it is black no volume can change the picture. The next frame draws as
   usual. */
EMSCRIPTEN_KEEPALIVE unsigned char *cy_footprint(void)
{
    court *c = &g_cy;
    float view[16], proj[16], eye[3], vp[16];
    GLuint vbo;
    int i, n;
    cy_camera(c, view, proj, eye);
    shp_mat_mul(vp, proj, view);
    glViewport(0, 0, c->width, c->height);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    glUseProgram(c->flat);
    glUniformMatrix4fv(c->u_flat_vp, 1, GL_FALSE, vp);
    glGenBuffers(1, &vbo);
    glEnableVertexAttribArray(0);
    for (i = 0; i < c->scene.count; ++i) {
        const ds_object *o = &c->scene.obj[i];
        if (o->kind == DS_OPAQUE) continue;
        n = exm_upload_flat(vbo, &c->scene.mesh[o->mesh], o->model, GL_STREAM_DRAW);
        glUniformMatrix4fv(c->u_flat_model, 1, GL_FALSE, o->model);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
        glDrawArrays(GL_TRIANGLES, 0, n);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glDeleteBuffers(1, &vbo);
    glUseProgram(0);
    return cy_snapshot();
}

/* the interactive page: the canvas's context is made; drive: the page's script runs the frames */
static int cy_main(int version, int width, int height, int drive)
{
    court *c = &g_cy;
    memset(c, 0, sizeof *c);
    c->version = version, c->width = width, c->height = height;
    c->bits = 0, c->dither = 1, c->ramp_model = 0, c->fog = 1, c->soft = 0.6f, c->density = 1.0f;
    c->pos[0] = 1.0f, c->pos[1] = 5.2f, c->pos[2] = 13.5f, c->yaw = -0.067f, c->pitch = -0.25f;
    c->snap = (unsigned char *)malloc((size_t)width * height * 4);
    ds_scene_build(&c->scene);
    ds_scene_animate(&c->scene, 0.7);
    c->t = 0.7;
    cy_engine_init(c);
    cy_fog_build(c);
    if (!c->fv || !c->prog || !c->sky || !c->flat) {
        printf("not ok - the courtyard could not start (see above)\n");
        return 0;
    }
    if (drive) {
        c->paused = 1;
        emscripten_run_script("fvDrive()");
    } else {
        emscripten_set_main_loop(cy_loop, 0, 0);
    }
    return 1;
}
