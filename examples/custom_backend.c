/* custom_backend.c - an engine that gives fogvol its own backend table.

   fogvol's renderer reaches the GPU only through fogvol_backend, a table of
   function pointers whose first argument is the table's user_data. This
   example fills that table with a RECORDING backend: every entry counts its
   calls, logs the passes (target, clear, blend, cull, depth, program, draws)
   and forwards to the default GL backend, made with fogvol_gl_backend_create
   and kept inside the recorder (the table's user_data). Each entry carries its
   contract: what it must do and what it must leave unchanged. An engine with
   its own rendering layer (Vulkan-style command lists, a GL wrapper with a
   state cache, a console API) implements the same entries natively.

   The recorder also checks the frame contract on the fly: the engine's GL
   program, framebuffer, viewport, blend and depth-test state must be the same
   after end_frame as before begin_frame. And the picture must be the picture
   the default backend makes on its own: the frame is rendered a second time
   through a context without the recorder and compared pixel for pixel.

   Headless (OSMesa, GL 3.3 core): renders one frame, prints the call log,
   writes a PNG, exits 0 (1 on any contract violation or pixel difference).

   usage: custom_backend [--tier ps13|ps20|float] [OUTPUT.png]    (default build/custom_backend.png)
   build: cc -std=c99 -I. examples/custom_backend.c -o custom_backend -lOSMesa -lm   (not -lGL) */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#include "examples/example_gl.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>

#define W 480
#define H 270
#define MAX_PASSES 64
#define MAX_NAMES 64

/* ---- the recorder ---------------------------------------------------------------- */
enum {
    E_BEGIN_FRAME, E_END_FRAME, E_CREATE_TEXTURE, E_DESTROY_TEXTURE, E_CREATE_TARGET, E_DESTROY_TARGET,
    E_CREATE_PROGRAM, E_DESTROY_PROGRAM, E_CREATE_MESH, E_DESTROY_MESH, E_BEGIN_PASS, E_SET_DRAW, E_DRAW_MESH,
    E_DRAW_FULLSCREEN, E_END_PASS, E_READ_TARGET, E_DESTROY, E_NATIVE_TEXTURE, E_TARGET_ATTACHMENT, E_TAKE_ERROR,
    E_COPY_DEPTH, E_CREATE_QUERY, E_DESTROY_QUERY, E_BEGIN_QUERY, E_END_QUERY, E_QUERY_RESULT, E_COUNT
};
static const char *const k_entry[E_COUNT] = {
    "begin_frame", "end_frame", "create_texture", "destroy_texture", "create_target", "destroy_target",
    "create_program", "destroy_program", "create_mesh", "destroy_mesh", "begin_pass", "set_draw", "draw_mesh",
    "draw_fullscreen", "end_pass", "read_target", "destroy", "native_texture", "target_attachment", "take_error",
    "copy_depth", "create_query", "destroy_query", "begin_query", "end_query", "query_result"};

typedef struct rec_pass {
    fogvol_pass pass; /* a copy of what begin_pass received */
    int meshes, fullscreens;
} rec_pass;

typedef struct recorder {
    fogvol_backend inner; /* the wrapped table: the default GL backend */
    int calls[E_COUNT];
    rec_pass passes[MAX_PASSES];
    int npass;
    struct {
        fogvol_handle handle;
        const char *label; /* labels are string literals inside fogvol */
    } names[MAX_NAMES];
    int nnames;
    GLint saved[8];       /* engine state seen at begin_frame, compared after end_frame */
    int violations;
} recorder;

static void name_add(recorder *r, fogvol_handle h, const char *label)
{
    if (h && r->nnames < MAX_NAMES) r->names[r->nnames].handle = h, r->names[r->nnames++].label = label;
}

static void name_remove(recorder *r, fogvol_handle h)
{
    int i;
    for (i = 0; i < r->nnames; ++i)
        if (r->names[i].handle == h) r->names[i] = r->names[--r->nnames];
}

static const char *name_of(const recorder *r, fogvol_handle h)
{
    int i;
    if (!h) return "engine framebuffer";
    for (i = 0; i < r->nnames; ++i)
        if (r->names[i].handle == h) return r->names[i].label ? r->names[i].label : "(unlabelled)";
    return "(unknown)";
}

static void engine_state(GLint s[8])
{
    glGetIntegerv(GL_CURRENT_PROGRAM, &s[0]);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s[1]);
    glGetIntegerv(GL_VIEWPORT, &s[2]); /* s[2..5] */
    s[6] = glIsEnabled(GL_BLEND);
    s[7] = glIsEnabled(GL_DEPTH_TEST);
}

/* begin_frame (optional). Called first by fogvol_end_frame (and fogvol_mrt_prepare,
   fogvol_occluder_prepare), before any pass. Must save every piece of engine state the passes will
   change and report the engine framebuffer (the one bound now, "target 0" of the passes) in info (its
   samples and depth conventions). info->draw_buffer is an input: the engine draw buffer the composite
   writes; a backend that cannot write that one returns an error. On failure it must leave everything
   unchanged: the frame is dropped and end_frame is not called. */
static fogvol_result rec_begin_frame(void *u, fogvol_frame_info *info)
{
    recorder *r = (recorder *)u;
    r->calls[E_BEGIN_FRAME]++;
    r->npass = 0;
    engine_state(r->saved);
    return r->inner.begin_frame ? r->inner.begin_frame(r->inner.user_data, info) : FOGVOL_SUCCESS;
}

/* end_frame (optional). Last call of the frame: restore what begin_frame saved. When
   it returns, the engine's state must be exactly as it was when begin_frame ran. */
static void rec_end_frame(void *u)
{
    recorder *r = (recorder *)u;
    GLint now[8];
    int i;
    r->calls[E_END_FRAME]++;
    if (r->inner.end_frame) r->inner.end_frame(r->inner.user_data);
    engine_state(now);
    for (i = 0; i < 8; ++i)
        if (now[i] != r->saved[i]) {
            printf("contract violation: engine state item %d is %d after end_frame, was %d\n", i, now[i], r->saved[i]);
            r->violations++;
        }
}

/* create_texture. An RGBA8 2D texture of desc->width x desc->height from desc->pixels
   (rows bottom to top), with desc->filter and desc->wrap; *out = a non-zero handle.
   Outside a frame it must leave the engine's state unchanged (bindings included). */
static fogvol_result rec_create_texture(void *u, const fogvol_texture_desc *d, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    fogvol_result res = r->inner.create_texture(r->inner.user_data, d, out);
    r->calls[E_CREATE_TEXTURE]++;
    if (res == FOGVOL_SUCCESS) name_add(r, *out, d->label);
    return res;
}

/* destroy_texture. Release it (never called with a texture a pass still uses);
   no other state changes. */
static void rec_destroy_texture(void *u, fogvol_handle h)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY_TEXTURE]++;
    name_remove(r, h);
    r->inner.destroy_texture(r->inner.user_data, h);
}

/* create_target. A render target: a colour texture (NEAREST, CLAMP; LINEAR when desc->linear, with
   FOGVOL_CAP_FILTER_FLOAT) in desc->format (RGBA8; R32F and RGBA32F that additive blending must work on;
   RG32F with FOGVOL_CAP_ATTACH_DEPTH), two colour attachments drawn together when desc->color_count == 2,
   desc->samples per pixel (multisampled, with FOGVOL_CAP_MULTISAMPLE), a depth buffer when desc->depth,
   or the depth buffer of desc->share_depth. The handle must also work as a texture in
   fogvol_pass.textures (sampled as its colour texture). A format or sample count it cannot make is
   FOGVOL_ERROR_UNSUPPORTED (the core then takes another way where it has one); an incomplete
   framebuffer is FOGVOL_ERROR_FRAMEBUFFER. Engine state unchanged outside a frame. The header's
   "backend table" section is the whole contract; this wrapper forwards to a backend that keeps it. */
static fogvol_result rec_create_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    fogvol_result res = r->inner.create_target(r->inner.user_data, d, out);
    r->calls[E_CREATE_TARGET]++;
    if (res == FOGVOL_SUCCESS) name_add(r, *out, d->label);
    return res;
}

/* destroy_target. Release it; targets that share another's depth are destroyed first. */
static void rec_destroy_target(void *u, fogvol_handle h)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY_TARGET]++;
    name_remove(r, h);
    r->inner.destroy_target(r->inner.user_data, h);
}

/* create_program. Compile desc->vs / desc->fs (string arrays in the table's dialect)
   and link them, attribute 0 bound to "fv_position" (and fragment output "fv_frag" to
   location 0 where outputs are named); set sampler desc->samplers[i] to unit i; find
   the uniforms fv_mvp, fv_depth, fv_sign and the FOGVOL_U_* names (absent ones are
   fine). Errors: FOGVOL_ERROR_SHADER_COMPILE / _LINK with the log to the logger.
   Engine state unchanged outside a frame (the current program included). */
static fogvol_result rec_create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    fogvol_result res = r->inner.create_program(r->inner.user_data, d, out);
    r->calls[E_CREATE_PROGRAM]++;
    if (res == FOGVOL_SUCCESS) name_add(r, *out, d->label);
    return res;
}

/* destroy_program. Release it; must not disturb the engine's current program. */
static void rec_destroy_program(void *u, fogvol_handle h)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY_PROGRAM]++;
    name_remove(r, h);
    r->inner.destroy_program(r->inner.user_data, h);
}

/* create_mesh. Upload data->positions (xyz floats; with FOGVOL_CAP_MESH_LAYOUT at data's stride and
   offset) and data->indices (uint32 triangles, or 16-bit with the layout cap; NULL = non-indexed) for
   drawing with the position in attribute 0. The data is only valid during the call. Engine vertex state
   unchanged. */
static fogvol_result rec_create_mesh(void *u, const fogvol_mesh_data *d, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    r->calls[E_CREATE_MESH]++;
    return r->inner.create_mesh(r->inner.user_data, d, out);
}

/* destroy_mesh. Release it; may come between frames at any time (an animated mesh is
   re-created every frame). */
static void rec_destroy_mesh(void *u, fogvol_handle h)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY_MESH]++;
    r->inner.destroy_mesh(r->inner.user_data, h);
}

/* begin_pass. Make the pass current: render into pass->target (0 = the framebuffer that
   was bound at begin_frame, at info->draw_buffer), viewport, the scissor rectangle when
   pass->scissor[2] > 0, clear colour (and depth to 1 when the target has its own depth) if
   pass->clear, blend mode (the blend constant when pass->blend_constant), culling (front faces
   counter-clockwise), depth test LESS (GREATER with pass->depth_greater) and depth writes as given,
   pass->depth_texture attached as the depth buffer (FOGVOL_CAP_ATTACH_DEPTH), pass->read_target at
   colour attachment 1 for framebuffer fetch, per-sample shading for pass->per_sample 1 (2: tested
   per sample, shaded once per pixel), no stencil test, pass->program with the pass->uniforms,
   textures[i] (or native_textures[i]) on unit i. Everything else in a neutral state: full colour mask,
   no dithering, filled polygons. The fields a backend's caps do not announce never come set. */
static void rec_begin_pass(void *u, const fogvol_pass *p)
{
    recorder *r = (recorder *)u;
    r->calls[E_BEGIN_PASS]++;
    if (r->npass < MAX_PASSES) {
        memset(&r->passes[r->npass], 0, sizeof r->passes[r->npass]);
        r->passes[r->npass++].pass = *p;
    }
    r->inner.begin_pass(r->inner.user_data, p);
}

/* set_draw. Per-draw uniforms of the current program: fv_mvp, fv_depth, fv_sign (fv_ext and
   fv_emit for the colour programs of FOGVOL_VARIANT_COLORS), and the front-face winding (d->front_cw). fogvol calls it for the engine's own draws in
   an occluder callback: it must not touch the engine's vertex state. */
static void rec_set_draw(void *u, const fogvol_draw *d)
{
    recorder *r = (recorder *)u;
    r->calls[E_SET_DRAW]++;
    r->inner.set_draw(r->inner.user_data, d);
}

/* draw_mesh. set_draw(d), then draw the mesh's triangles into the current pass. */
static void rec_draw_mesh(void *u, fogvol_handle mesh, const fogvol_draw *d)
{
    recorder *r = (recorder *)u;
    r->calls[E_DRAW_MESH]++;
    if (r->npass) r->passes[r->npass - 1].meshes++;
    r->inner.draw_mesh(r->inner.user_data, mesh, d);
}

/* draw_fullscreen. One triangle covering the pass viewport (clip-space corners
   (-1,-1), (3,-1), (-1,3)), position in attribute 0. */
static void rec_draw_fullscreen(void *u)
{
    recorder *r = (recorder *)u;
    r->calls[E_DRAW_FULLSCREEN]++;
    if (r->npass) r->passes[r->npass - 1].fullscreens++;
    r->inner.draw_fullscreen(r->inner.user_data);
}

/* end_pass (optional). The pass's draws are done (a backend that records into command
   buffers ends its render pass here). */
static void rec_end_pass(void *u)
{
    recorder *r = (recorder *)u;
    r->calls[E_END_PASS]++;
    if (r->inner.end_pass) r->inner.end_pass(r->inner.user_data);
}

/* read_target (optional: debug read-back). The whole target into rgba, rows bottom to
   top: RGBA8 bytes, one float per pixel for R32F (size >= w*h*4), four for RGBA32F (w*h*16). May be
   called inside a frame between passes; engine state unchanged. */
static fogvol_result rec_read_target(void *u, fogvol_handle t, unsigned char *rgba, size_t size)
{
    recorder *r = (recorder *)u;
    r->calls[E_READ_TARGET]++;
    return r->inner.read_target ? r->inner.read_target(r->inner.user_data, t, rgba, size)
                                : FOGVOL_ERROR_UNSUPPORTED;
}

/* destroy (optional). fogvol_destroy_context calls it only for a backend the context
   made itself (the default GL backend); a table handed in through
   fogvol_context_desc.backend belongs to its engine, which destroys it. */
static void rec_destroy(void *u)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY]++;
    if (r->inner.destroy) r->inner.destroy(r->inner.user_data);
}

/* native_texture (optional, MRT tier). The API object behind a texture or target
   handle (GL: the texture name), for the engine to attach. */
static fogvol_native rec_native_texture(void *u, fogvol_handle h)
{
    recorder *r = (recorder *)u;
    r->calls[E_NATIVE_TEXTURE]++;
    return r->inner.native_texture ? r->inner.native_texture(r->inner.user_data, h) : 0;
}

/* target_attachment (optional, WIDE variant). The second colour attachment of a
   two-attachment target as a target handle of its own (sampled, read back). */
static fogvol_handle rec_target_attachment(void *u, fogvol_handle h, int index)
{
    recorder *r = (recorder *)u;
    r->calls[E_TARGET_ATTACHMENT]++;
    return r->inner.target_attachment ? r->inner.target_attachment(r->inner.user_data, h, index) : 0;
}

/* take_error (optional). The first failure of the backend's own calls since the last
   take_error (GL: a GL error fogvol's own calls raised, read before the engine's pending
   errors are raised again; an engine texture name that is no texture; another context
   current), logged by the backend, and forgotten; FOGVOL_SUCCESS when none. fogvol calls it
   after the backend calls of each public call and returns it when the call had no error
   of its own. Without it, failures the void entries meet cannot reach the result. */
static fogvol_result rec_take_error(void *u)
{
    recorder *r = (recorder *)u;
    r->calls[E_TAKE_ERROR]++;
    return r->inner.take_error ? r->inner.take_error(r->inner.user_data) : FOGVOL_SUCCESS;
}

/* copy_depth (ENGINE_DEPTH from a framebuffer's depth buffer) and the occlusion queries (overflow counts):
   forwarded as they are, each call counted; a wrapper that left them out would switch those features off
   (the core tests for the entries, not the caps). */
static fogvol_result rec_copy_depth(void *u, fogvol_native framebuffer, int bound, const int rect[4], int samples,
                                   fogvol_native *texture)
{
    recorder *r = (recorder *)u;
    r->calls[E_COPY_DEPTH]++;
    return r->inner.copy_depth(r->inner.user_data, framebuffer, bound, rect, samples, texture);
}

static fogvol_result rec_create_query(void *u, fogvol_handle *out)
{
    recorder *r = (recorder *)u;
    r->calls[E_CREATE_QUERY]++;
    return r->inner.create_query(r->inner.user_data, out);
}

static void rec_destroy_query(void *u, fogvol_handle q)
{
    recorder *r = (recorder *)u;
    r->calls[E_DESTROY_QUERY]++;
    r->inner.destroy_query(r->inner.user_data, q);
}

static int rec_begin_query(void *u, fogvol_handle q)
{
    recorder *r = (recorder *)u;
    r->calls[E_BEGIN_QUERY]++;
    return r->inner.begin_query(r->inner.user_data, q);
}

static void rec_end_query(void *u, fogvol_handle q)
{
    recorder *r = (recorder *)u;
    r->calls[E_END_QUERY]++;
    r->inner.end_query(r->inner.user_data, q);
}

static int rec_query_result(void *u, fogvol_handle q, uint64_t *samples)
{
    recorder *r = (recorder *)u;
    r->calls[E_QUERY_RESULT]++;
    return r->inner.query_result(r->inner.user_data, q, samples);
}

/* The table: the recorder's entries, the wrapped backend's dialect and capabilities; the optional entries
   the wrapped backend lacks stay NULL here too. */
static fogvol_backend recorder_table(recorder *r)
{
    fogvol_backend t;
    memset(&t, 0, sizeof t);
    t.user_data = r;
    t.dialect = r->inner.dialect;
    t.caps = r->inner.caps;
    t.begin_frame = rec_begin_frame;
    t.end_frame = rec_end_frame;
    t.create_texture = rec_create_texture;
    t.destroy_texture = rec_destroy_texture;
    t.create_target = rec_create_target;
    t.destroy_target = rec_destroy_target;
    t.create_program = rec_create_program;
    t.destroy_program = rec_destroy_program;
    t.create_mesh = rec_create_mesh;
    t.destroy_mesh = rec_destroy_mesh;
    t.begin_pass = rec_begin_pass;
    t.set_draw = rec_set_draw;
    t.draw_mesh = rec_draw_mesh;
    t.draw_fullscreen = rec_draw_fullscreen;
    t.end_pass = rec_end_pass;
    t.read_target = rec_read_target;
    t.destroy = rec_destroy;
    t.native_texture = rec_native_texture;
    t.target_attachment = rec_target_attachment;
    t.take_error = rec_take_error;
    if (r->inner.copy_depth) t.copy_depth = rec_copy_depth;
    if (r->inner.create_query && r->inner.destroy_query && r->inner.begin_query && r->inner.end_query &&
        r->inner.query_result) {
        t.create_query = rec_create_query;
        t.destroy_query = rec_destroy_query;
        t.begin_query = rec_begin_query;
        t.end_query = rec_end_query;
        t.query_result = rec_query_result;
    }
    return t;
}

static void print_log(const recorder *r, fogvol_context *fv)
{
    static const char *const blend[7] = {"none", "add", "fog", "light", "subtract", "multiply", "emit"};
    static const char *const cull[3] = {"none", "back", "front"};
    int i;
    printf("call counts (tier %s, GLSL %s):\n", fogvol_tier_name(fogvol_context_tier(fv, NULL)),
           fogvol_dialect_name(r->inner.dialect));
    for (i = 0; i < E_COUNT; ++i) printf("  %-18s %4d\n", k_entry[i], r->calls[i]);
    printf("pass sequence of the frame:\n");
    printf("  %-2s  %-32s %-5s %-8s %-5s %-10s %-28s %s\n", "#", "target", "clear", "blend", "cull", "depth", "program",
           "draws");
    for (i = 0; i < r->npass; ++i) {
        const fogvol_pass *p = &r->passes[i].pass;
        char draws[32];
        if (r->passes[i].fullscreens) snprintf(draws, sizeof draws, "%d full-screen", r->passes[i].fullscreens);
        else snprintf(draws, sizeof draws, "%d mesh%s", r->passes[i].meshes, r->passes[i].meshes == 1 ? "" : "es");
        printf("  %-2d  %-32s %-5s %-8s %-5s %-10s %-28s %s\n", i, name_of(r, p->target), p->clear ? "yes" : "no",
               (unsigned)p->blend < 7 ? blend[p->blend] : "?", (unsigned)p->cull < 3 ? cull[p->cull] : "?",
               p->depth_test ? (p->depth_write ? "test+write" : "test") : "-", name_of(r, p->program), draws);
    }
}

/* ---- a minimal engine: flat-shaded floor and pillars --------------------------- */
typedef struct engine {
    GLuint prog, vao, vbo;
    GLint u_mvp, u_color;
} engine;

static void engine_init(engine *e)
{
    static const char *vs = "#version 330 core\nlayout(location = 0) in vec3 p; layout(location = 1) in vec3 n;\n"
                            "uniform mat4 mvp; out vec3 vn; void main() { vn = n; gl_Position = mvp * vec4(p, 1.0); }\n";
    static const char *fs = "#version 330 core\nin vec3 vn; uniform vec3 color; out vec4 o;\n"
                            "void main() { o = vec4(color * (0.4 + 0.6 * max(dot(normalize(vn), "
                            "normalize(vec3(0.4, 0.8, 0.45))), 0.0)), 1.0); }\n";
    e->prog = exm_program("engine", vs, &fs, 1, NULL);
    if (!e->prog) exit(1);
    e->u_mvp = glGetUniformLocation(e->prog, "mvp");
    e->u_color = glGetUniformLocation(e->prog, "color");
    glGenVertexArrays(1, &e->vao);
    glGenBuffers(1, &e->vbo);
}

static void engine_draw(engine *e, const shp_mesh *m, const float model[16], const float vp[16], float r, float g,
                        float b)
{
    float mvp[16];
    shp_mat_mul(mvp, vp, model);
    glUseProgram(e->prog);
    glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, mvp);
    glUniform3f(e->u_color, r, g, b);
    glBindVertexArray(e->vao);
    exm_upload_flat(e->vbo, m, NULL, GL_STREAM_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 24, (void *)12);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glDrawArrays(GL_TRIANGLES, 0, m->icount);
}

/* ---- the scene, rendered through a given context ---------------------------------- */
typedef struct scene {
    shp_mesh floor, pillar, sphere, torus, bank, hole, beam;
} scene;

static const float k_pillars[3][2] = {{-2.0f, -0.5f}, {0.6f, -1.8f}, {2.2f, 0.6f}};

/* Draws the opaque scene, then the fog through fv; returns fogvol_end_frame's result. */
static fogvol_result render(engine *e, const scene *s, fogvol_context *fv, fogvol_frame_stats *st)
{
    fogvol_mesh *floor_v = exm_fog_mesh(fv, &s->floor, 0), *pillar_v = exm_fog_mesh(fv, &s->pillar, 0);
    fogvol_mesh *sphere_v = exm_fog_mesh(fv, &s->sphere, 0), *torus_v = exm_fog_mesh(fv, &s->torus, 0);
    fogvol_mesh *bank_v = exm_fog_mesh(fv, &s->bank, 0), *hole_v = exm_fog_mesh(fv, &s->hole, 0);
    fogvol_mesh *beam_v = exm_fog_mesh(fv, &s->beam, 0);
    fogvol_ramp *fog, *bank, *light;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_result res;
    float view[16], proj[16], vp[16], m[16], rot[16];
    double eye[3] = {0.0, 3.0, 8.5}, at[3] = {0.0, 0.3, 0.0}, up[3] = {0.0, 1.0, 0.0};
    int i;

    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.85f, rd.color[1] = 0.88f, rd.color[2] = 0.95f, rd.density = 0.55f;
    fogvol_create_ramp(fv, &rd, &fog);
    rd.color[0] = 0.6f, rd.color[1] = 0.66f, rd.color[2] = 0.74f, rd.density = 0.5f;
    fogvol_create_ramp(fv, &rd, &bank);
    rd.color[0] = 1.0f, rd.color[1] = 0.75f, rd.color[2] = 0.35f, rd.density = 0.35f, rd.blend = FOGVOL_BLEND_LIGHT;
    fogvol_create_ramp(fv, &rd, &light);

    glu_look_at(view, eye, at, up);
    glu_perspective(proj, 55.0, (double)W / H, 0.1, 40.0);
    shp_mat_mul(vp, proj, view);
    glViewport(0, 0, W, H);
    glEnable(GL_DEPTH_TEST);
    glClearColor(0.32f, 0.45f, 0.62f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    shp_mat_translate(m, 0.0f, -1.0f, 0.0f);
    engine_draw(e, &s->floor, m, vp, 0.55f, 0.52f, 0.48f);
    for (i = 0; i < 3; ++i) {
        shp_mat_translate(m, k_pillars[i][0], 1.0f, k_pillars[i][1]);
        engine_draw(e, &s->pillar, m, vp, 0.7f, 0.66f, 0.6f);
    }

    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, view, sizeof view);
    memcpy(fd.projection, proj, sizeof proj);
    fd.znear = 0.1f, fd.zfar = 40.0f, fd.viewport[2] = W, fd.viewport[3] = H;
    fogvol_begin_frame(fv, &fd);
    shp_mat_translate(m, 0.0f, -1.0f, 0.0f);
    fogvol_add_occluder(fv, floor_v, m);
    for (i = 0; i < 3; ++i) {
        shp_mat_translate(m, k_pillars[i][0], 1.0f, k_pillars[i][1]);
        fogvol_add_occluder(fv, pillar_v, m);
    }
    memset(&vd, 0, sizeof vd);
    vd.ramp = fog;
    vd.mesh = sphere_v;
    shp_mat_translate(vd.model, -1.8f, 0.4f, 0.3f);
    fogvol_add_volume(fv, &vd);
    vd.mesh = torus_v;
    shp_mat_rotate(rot, 70.0f, 1.0f, 0.0f, 0.3f);
    shp_mat_translate(m, 1.8f, 0.5f, -0.6f);
    shp_mat_mul(vd.model, m, rot);
    fogvol_add_volume(fv, &vd);
    vd.ramp = bank; /* fog bank with a hole carved by a negative sphere */
    vd.mesh = bank_v;
    shp_mat_translate(vd.model, 0.0f, -0.6f, -2.5f);
    fogvol_add_volume(fv, &vd);
    vd.mesh = hole_v;
    vd.negative = 1;
    shp_mat_translate(vd.model, -0.6f, 0.0f, -2.0f);
    fogvol_add_volume(fv, &vd);
    vd.negative = 0;
    vd.ramp = light;
    vd.mesh = beam_v;
    shp_mat_rotate(rot, 18.0f, 0.0f, 0.0f, 1.0f);
    shp_mat_translate(m, 0.2f, 1.2f, -1.5f);
    shp_mat_mul(vd.model, m, rot);
    fogvol_add_volume(fv, &vd);
    res = fogvol_end_frame(fv, st);
    glFinish();

    fogvol_destroy_ramp(fv, fog);
    fogvol_destroy_ramp(fv, bank);
    fogvol_destroy_ramp(fv, light);
    fogvol_destroy_mesh(fv, floor_v), fogvol_destroy_mesh(fv, pillar_v), fogvol_destroy_mesh(fv, sphere_v);
    fogvol_destroy_mesh(fv, torus_v), fogvol_destroy_mesh(fv, bank_v), fogvol_destroy_mesh(fv, hole_v);
    fogvol_destroy_mesh(fv, beam_v);
    return res;
}

static void log_cb(void *u, fogvol_log_level level, const char *msg)
{
    (void)u;
    if (level <= FOGVOL_LOG_WARNING) fprintf(stderr, "%s\n", msg);
}

int main(int argc, char **argv)
{
    const char *out = "build/custom_backend.png";
    fogvol_tier tier = FOGVOL_TIER_PS20;
    glu_ctx g;
    engine e;
    scene s;
    recorder rec;
    fogvol_context_desc cd;
    fogvol_context *fv_rec, *fv_direct;
    fogvol_frame_stats st;
    fogvol_result res;
    fogvol_logger logger;
    unsigned char *recorded;
    long differ = 0;
    int i;

    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--tier") && i + 1 < argc) {
            ++i;
            tier = !strcmp(argv[i], "ps13") ? FOGVOL_TIER_PS13 : !strcmp(argv[i], "float") ? FOGVOL_TIER_FLOAT
                                                                                            : FOGVOL_TIER_PS20;
        } else if (argv[i][0] != '-') {
            out = argv[i];
        } else {
            fprintf(stderr, "usage: %s [--tier ps13|ps20|float] [OUTPUT.png]\n", argv[0]);
            return 2;
        }
    }
    if (!glu_create(&g, W, H, 1)) {
        fprintf(stderr, "OSMesa context failed\n");
        return 1;
    }
    engine_init(&e);
    s.floor = shp_box(8.0f, 0.1f, 8.0f);
    s.pillar = shp_box(0.25f, 2.0f, 0.25f);
    s.sphere = shp_sphere(1.2f, 48, 24);
    s.torus = shp_torus(1.2f, 0.4f, 64, 24);
    s.bank = shp_box(7.0f, 0.6f, 1.6f);
    s.hole = shp_sphere(1.0f, 32, 16);
    s.beam = shp_box(0.5f, 2.6f, 0.5f);
    memset(&logger, 0, sizeof logger);
    logger.func = log_cb;

    /* 1. the engine makes the default GL backend itself and wraps it */
    memset(&rec, 0, sizeof rec);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    if (fogvol_gl_backend_create(&cd.gl, NULL, &logger, &rec.inner) != FOGVOL_SUCCESS) return 1;
    cd.backend = recorder_table(&rec); /* a table with create_texture set replaces the GL backend */
    cd.tier = tier;
    cd.logger = logger;
    if ((res = fogvol_create_context(&cd, &fv_rec)) != FOGVOL_SUCCESS) {
        fprintf(stderr, "fogvol_create_context: %s\n", fogvol_result_string(res));
        return 1;
    }
    res = render(&e, &s, fv_rec, &st);
    printf("frame through the recording backend: %s, %d passes, %d volumes, %d groups\n", fogvol_result_string(res),
           st.passes, st.volumes, st.groups);
    recorded = (unsigned char *)malloc((size_t)W * H * 4);
    memcpy(recorded, g.pixels, (size_t)W * H * 4);
    print_log(&rec, fv_rec);
    mkdir("build", 0777);
    stbi_flip_vertically_on_write(1);
    if (!stbi_write_png(out, W, H, 4, recorded, W * 4)) {
        fprintf(stderr, "cannot write %s\n", out);
        return 1;
    }
    printf("wrote %s\n", out);

    /* 2. the same frame through the default backend alone: the recorder must not change a pixel */
    memset(&cd.backend, 0, sizeof cd.backend);
    if (fogvol_create_context(&cd, &fv_direct) != FOGVOL_SUCCESS) return 1;
    render(&e, &s, fv_direct, &st);
    for (i = 0; i < W * H; ++i) differ += memcmp(recorded + 4 * i, g.pixels + 4 * i, 4) != 0;
    printf("same frame through the default GL backend directly: %ld of %d pixels differ\n", differ, W * H);

    fogvol_destroy_context(fv_direct);
    fogvol_destroy_context(fv_rec);
    rec.inner.destroy(rec.inner.user_data); /* the engine's table: the engine destroys it */
    {
        int made = rec.calls[E_CREATE_TEXTURE] + rec.calls[E_CREATE_TARGET] + rec.calls[E_CREATE_PROGRAM] +
                   rec.calls[E_CREATE_MESH];
        int freed = rec.calls[E_DESTROY_TEXTURE] + rec.calls[E_DESTROY_TARGET] + rec.calls[E_DESTROY_PROGRAM] +
                    rec.calls[E_DESTROY_MESH];
        printf("after fogvol_destroy_context: %d objects created through the recorder, %d destroyed\n", made, freed);
        if (made != freed) rec.violations++;
    }
    printf("contract violations seen by the recorder: %d\n", rec.violations);
    free(recorded);
    shp_free(&s.floor), shp_free(&s.pillar), shp_free(&s.sphere), shp_free(&s.torus);
    shp_free(&s.bank), shp_free(&s.hole), shp_free(&s.beam);
    glu_destroy(&g);
    return differ != 0 || rec.violations != 0 || res != FOGVOL_SUCCESS;
}
