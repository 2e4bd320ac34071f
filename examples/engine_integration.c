/* engine_integration.c - fogvol.h added to an existing renderer.

   The "engine" below is an ordinary GLFW + OpenGL 3.3 core program: its own
   shaders, VAOs, sampler objects, an offscreen framebuffer with a colour
   texture and a depth TEXTURE, a post-processing pass to the window, and GL
   state it sets once at start-up and relies on afterwards (depth function,
   blend function, sampler bindings, pack alignment, ...).

   Fog volumes are added with the lines marked "fogvol" at their end
   (count them: grep -c 'fogvol [*]/' examples/engine_integration.c). fogvol
   gets the engine's own loader (glfwGetProcAddress) and, where the context has
   float blending, the engine's depth texture (tier FLOAT + ENGINE_DEPTH: two
   library passes, no occluder drawing at all). Otherwise it falls back to PS20
   and the engine draws its own VAOs as occluders through a callback. The
   choice is made once, by trying fogvol_create_context.

   usage: engine_integration [--frames N] [--screenshot FILE.png] [--no-fog] [--ps20] [--size WxH] [--check]
     --no-fog   never create the fogvol context (the engine alone)
     --ps20     skip the FLOAT attempt (exercises the fallback)
     --check    render one frame without and with fog and compare every pixel
                where fogvol's debug thickness is exactly 0, and the GL state the
                engine relies on; prints the differences, exits 1 if any (sets
                LP_NUM_THREADS=1 unless set: llvmpipe's threaded rasteriser does
                not repeat a frame bit for bit, fogvol or not)

   build: cc -std=c99 -I. examples/engine_integration.c -o engine_integration -lglfw -lGL -lm */
#define _POSIX_C_SOURCE 200112L /* setenv */
#define FOGVOL_IMPLEMENTATION /* fogvol */
#include "fogvol.h"           /* fogvol */
#define GL_GLEXT_PROTOTYPES
#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>
#include "tests/shapes.h"
#include "examples/example_gl.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ZNEAR 0.1f
#define ZFAR 80.0f
#define MAX_OBJ 16

/* ================================ the engine ===================================== */
typedef struct gpu_mesh {
    GLuint vao, vbo;
    GLsizei count; /* vertices (flat triangles, position in attribute 0, normal in 1) */
} gpu_mesh;

typedef struct object {
    const gpu_mesh *mesh;
    float model[16];
    float albedo[3];
} object;

typedef struct fog_entity { /* the engine's fog volume entities: a shape, a look and a transform */
    int ball;                /* 0: box, 1: sphere */
    int light;               /* 0: mist, 1: glow (added light) */
    float model[16];
} fog_entity;

typedef struct engine {
    GLFWwindow *win;
    int w, h;
    GLuint fbo, color_tex, depth_tex, detail_tex, detail_sampler, post_sampler, post_vao;
    GLuint lit_prog, post_prog;
    GLint u_mvp, u_model, u_albedo, u_inv_size;
    gpu_mesh box, ball, knot;
    object obj[MAX_OBJ];
    int nobj;
    fog_entity fog[4];
    int nfog;
    shp_mesh cpu_box, cpu_ball;
    float view[16], proj[16];
    float *debug_thickness; /* --check: where fogvol writes the thickness per pixel */
    int debug_ramp;         /* --check: which fog group it reports (0 mist, 1 glow) */
    fogvol_context *fv; fogvol_mesh *fv_box, *fv_ball; fogvol_ramp *mist, *glow; int engine_depth; /* fogvol */
} engine;

static gpu_mesh upload_mesh(const shp_mesh *m)
{
    gpu_mesh g;
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    glGenBuffers(1, &g.vbo);
    g.count = exm_upload_flat(g.vbo, m, NULL, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 24, (void *)12);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    return g;
}

/* the offscreen target: RGBA8 colour texture + 24-bit depth texture */
static void make_framebuffer(engine *e)
{
    glGenTextures(1, &e->color_tex);
    glBindTexture(GL_TEXTURE_2D, e->color_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, e->w, e->h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenTextures(1, &e->depth_tex);
    glBindTexture(GL_TEXTURE_2D, e->depth_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, e->w, e->h, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glGenFramebuffers(1, &e->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, e->color_tex, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, e->depth_tex, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "engine: framebuffer incomplete\n");
        exit(1);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void engine_init(engine *e)
{
    static const char *lit_vs =
        "#version 330 core\n"
        "layout(location = 0) in vec3 a_pos; layout(location = 1) in vec3 a_nrm;\n"
        "uniform mat4 u_mvp, u_model; out vec3 v_n, v_w;\n"
        "void main() { v_n = mat3(u_model) * a_nrm; v_w = (u_model * vec4(a_pos, 1.0)).xyz;\n"
        "              gl_Position = u_mvp * vec4(a_pos, 1.0); }\n";
    static const char *lit_fs =
        "#version 330 core\n"
        "in vec3 v_n, v_w; uniform vec3 u_albedo; uniform sampler2D u_detail; out vec4 o;\n"
        "void main() {\n"
        "  vec3 n = normalize(v_n), sun = normalize(vec3(-0.4, 0.8, 0.45));\n"
        "  vec3 amb = mix(vec3(0.22, 0.2, 0.18), vec3(0.3, 0.4, 0.55), 0.5 + 0.5 * n.y);\n"
        "  float d = texture(u_detail, v_w.xz * 0.35 + v_w.y * 0.2).r;\n"
        "  o = vec4(u_albedo * (amb + max(dot(n, sun), 0.0) * vec3(1.0, 0.93, 0.8)) * (0.75 + 0.35 * d), 1.0);\n"
        "}\n";
    static const char *post_vs = /* full-screen triangle from gl_VertexID, no buffers */
        "#version 330 core\n"
        "void main() { gl_Position = vec4(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0, 0.0, 1.0); }\n";
    static const char *post_fs = /* exposure, filmic-ish curve, vignette, per pixel */
        "#version 330 core\n"
        "uniform sampler2D u_scene; uniform vec2 u_inv_size; out vec4 o;\n"
        "void main() {\n"
        "  vec3 c = texelFetch(u_scene, ivec2(gl_FragCoord.xy), 0).rgb * 1.25;\n"
        "  c = c * (1.0 + c * 0.15) / (1.0 + c);\n"
        "  vec2 q = gl_FragCoord.xy * u_inv_size - 0.5;\n"
        "  o = vec4(sqrt(c) * (1.0 - 0.5 * dot(q, q)), 1.0);\n"
        "}\n";
    unsigned char detail[16 * 16 * 4];
    int i;
    for (i = 0; i < 16 * 16; ++i) { /* a little value noise for the surfaces */
        unsigned h = (unsigned)i * 2654435761u;
        detail[4 * i] = detail[4 * i + 1] = detail[4 * i + 2] = (unsigned char)(h >> 24), detail[4 * i + 3] = 255;
    }
    e->lit_prog = exm_program("engine", lit_vs, &lit_fs, 1, NULL);
    e->post_prog = exm_program("engine", post_vs, &post_fs, 1, NULL);
    if (!e->lit_prog || !e->post_prog) exit(1);
    e->u_mvp = glGetUniformLocation(e->lit_prog, "u_mvp");
    e->u_model = glGetUniformLocation(e->lit_prog, "u_model");
    e->u_albedo = glGetUniformLocation(e->lit_prog, "u_albedo");
    e->u_inv_size = glGetUniformLocation(e->post_prog, "u_inv_size");
    glUseProgram(e->lit_prog);
    glUniform1i(glGetUniformLocation(e->lit_prog, "u_detail"), 3); /* the engine's texture units */
    glUseProgram(e->post_prog);
    glUniform1i(glGetUniformLocation(e->post_prog, "u_scene"), 0);

    glGenTextures(1, &e->detail_tex);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, e->detail_tex); /* stays bound on unit 3 for good */
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 16, 16, 0, GL_RGBA, GL_UNSIGNED_BYTE, detail);
    glGenSamplers(1, &e->detail_sampler);
    glSamplerParameteri(e->detail_sampler, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glSamplerParameteri(e->detail_sampler, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindSampler(3, e->detail_sampler);
    glGenSamplers(1, &e->post_sampler);
    glSamplerParameteri(e->post_sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glSamplerParameteri(e->post_sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindSampler(0, e->post_sampler);
    glGenVertexArrays(1, &e->post_vao);

    e->cpu_box = shp_box(1.0f, 1.0f, 1.0f);
    e->cpu_ball = shp_sphere(1.0f, 48, 24);
    {
        shp_mesh knot = shp_torus_knot(2, 3, 1.0f, 0.4f, 0.16f, 256, 16);
        e->knot = upload_mesh(&knot);
        shp_free(&knot);
    }
    e->box = upload_mesh(&e->cpu_box);
    e->ball = upload_mesh(&e->cpu_ball);
    make_framebuffer(e);

    /* state set once and relied upon by every frame */
    glEnable(GL_CULL_FACE);
    glDepthFunc(GL_LEQUAL);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glClearColor(0.55f, 0.62f, 0.72f, 1.0f);
}

static void mat_trs(float m[16], float tx, float ty, float tz, float sx, float sy, float sz, float angle_y)
{
    float r[16], s[16], t[16];
    shp_mat_scale(s, sx, sy, sz);
    shp_mat_rotate(r, angle_y, 0.0f, 1.0f, 0.0f);
    shp_mat_translate(t, tx, ty, tz);
    shp_mat_mul(m, r, s);
    shp_mat_mul(m, t, m);
}

static void add_object(engine *e, const gpu_mesh *mesh, const float model[16], float r, float g, float b)
{
    object *o = &e->obj[e->nobj++];
    o->mesh = mesh;
    memcpy(o->model, model, sizeof o->model);
    o->albedo[0] = r, o->albedo[1] = g, o->albedo[2] = b;
}

/* the world at time t: objects and camera */
static void engine_update(engine *e, double t)
{
    float m[16], eye[3], f[3], s[3], u[3], l, a = (float)(0.55 + 0.12 * t), tn;
    int i, k;
    e->nobj = 0;
    mat_trs(m, 0.0f, -0.1f, 0.0f, 12.0f, 0.1f, 12.0f, 0.0f);
    add_object(e, &e->box, m, 0.55f, 0.5f, 0.42f);
    for (i = 0; i < 6; ++i) {
        float ang = (float)i * 1.047f;
        mat_trs(m, 4.2f * cosf(ang), 1.0f, 4.2f * sinf(ang), 0.3f, 1.0f + 0.25f * (float)(i % 3), 0.3f, 20.0f * i);
        add_object(e, &e->box, m, 0.62f, 0.6f, 0.56f);
    }
    mat_trs(m, 0.0f, 1.5f, 0.0f, 1.0f, 1.0f, 1.0f, (float)(40.0 * t));
    add_object(e, &e->knot, m, 0.75f, 0.25f, 0.2f);
    mat_trs(m, 2.2f, 1.1f, 2.0f, 0.06f, 1.1f, 0.06f, 0.0f); /* a lamp post and its bulb */
    add_object(e, &e->box, m, 0.2f, 0.2f, 0.22f);
    mat_trs(m, 2.2f, 2.25f, 2.0f, 0.12f, 0.12f, 0.12f, 0.0f);
    add_object(e, &e->ball, m, 1.0f, 0.9f, 0.6f);
    e->nfog = 3; /* a ground mist layer, a mist ball around the knot, the lamp's glow */
    e->fog[0].ball = 0, e->fog[0].light = 0;
    mat_trs(e->fog[0].model, 0.0f, 0.0f, 0.0f, 6.5f, 0.45f, 6.5f, 0.0f);
    e->fog[1].ball = 1, e->fog[1].light = 0;
    mat_trs(e->fog[1].model, 0.0f, 1.5f, 0.0f, 1.9f, 1.5f, 1.9f, (float)t);
    e->fog[2].ball = 1, e->fog[2].light = 1;
    mat_trs(e->fog[2].model, 2.2f, 1.6f, 2.0f, 0.7f, 1.2f, 0.7f, 0.0f);

    eye[0] = 8.5f * cosf(a), eye[1] = 3.6f, eye[2] = 8.5f * sinf(a);
    f[0] = -eye[0], f[1] = 0.9f - eye[1], f[2] = -eye[2];
    l = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (k = 0; k < 3; ++k) f[k] /= l;
    s[0] = -f[2], s[1] = 0.0f, s[2] = f[0];
    l = sqrtf(s[0] * s[0] + s[2] * s[2]);
    s[0] /= l, s[2] /= l;
    u[0] = s[1] * f[2] - s[2] * f[1], u[1] = s[2] * f[0] - s[0] * f[2], u[2] = s[0] * f[1] - s[1] * f[0];
    shp_mat_identity(e->view);
    for (k = 0; k < 3; ++k) e->view[4 * k] = s[k], e->view[4 * k + 1] = u[k], e->view[4 * k + 2] = -f[k];
    e->view[12] = -(s[0] * eye[0] + s[2] * eye[2]);
    e->view[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    e->view[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    tn = 1.0f / tanf(55.0f * 3.14159265f / 360.0f);
    memset(e->proj, 0, sizeof e->proj);
    e->proj[0] = tn * (float)e->h / (float)e->w;
    e->proj[5] = tn;
    e->proj[10] = (ZFAR + ZNEAR) / (ZNEAR - ZFAR);
    e->proj[11] = -1.0f;
    e->proj[14] = 2.0f * ZFAR * ZNEAR / (ZNEAR - ZFAR);
}

static void draw_mesh(const gpu_mesh *m)
{
    glBindVertexArray(m->vao);
    glDrawArrays(GL_TRIANGLES, 0, m->count);
}

static void draw_objects(const engine *e)
{
    float vp[16], mvp[16];
    int i;
    shp_mat_mul(vp, e->proj, e->view);
    for (i = 0; i < e->nobj; ++i) {
        shp_mat_mul(mvp, vp, e->obj[i].model);
        glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, mvp);
        glUniformMatrix4fv(e->u_model, 1, GL_FALSE, e->obj[i].model);
        glUniform3fv(e->u_albedo, 1, e->obj[i].albedo);
        draw_mesh(e->obj[i].mesh);
    }
}

/* ================================ fogvol ========================================= */
static fogvol_gl_proc fv_proc(const char *name, void *u) { (void)u; return glfwGetProcAddress(name); } /* fogvol */
static fogvol_mesh *fv_mesh(fogvol_context *fv, const shp_mesh *m) { /* fogvol */
    fogvol_mesh_desc md; fogvol_mesh *out = NULL; memset(&md, 0, sizeof md); /* fogvol */
    md.positions = m->pos; md.vertex_count = m->vcount; /* fogvol */
    md.indices = (const uint32_t *)m->idx; md.index_count = m->icount; /* fogvol */
    fogvol_create_mesh(fv, &md, &out, NULL); return out; } /* fogvol */

/* PS20 fallback: the engine draws its own VAOs (position in attribute 0) into fogvol's opaque-depth pass */
static void fv_occluders(fogvol_context *fv, void *user) { /* fogvol */
    const engine *e = (const engine *)user; int i; /* fogvol */
    for (i = 0; i < e->nobj; ++i) fogvol_occluder_transform(fv, e->obj[i].model), draw_mesh(e->obj[i].mesh); /* fogvol */
} /* fogvol */

static int fog_init(engine *e, int force_ps20)
{
    fogvol_context_desc cd; fogvol_ramp_desc rd; memset(&cd, 0, sizeof cd); memset(&rd, 0, sizeof rd); /* fogvol */
    cd.gl.get_proc_address = fv_proc; cd.tier = FOGVOL_TIER_FLOAT; cd.variants = FOGVOL_VARIANT_ENGINE_DEPTH; /* fogvol */
    e->engine_depth = !force_ps20 && fogvol_create_context(&cd, &e->fv) == FOGVOL_SUCCESS; /* fogvol */
    cd.tier = FOGVOL_TIER_PS20; cd.variants = 0; /* fogvol */
    if (!e->engine_depth && fogvol_create_context(&cd, &e->fv) != FOGVOL_SUCCESS) return 0; /* fogvol */
    e->fv_box = fv_mesh(e->fv, &e->cpu_box); e->fv_ball = fv_mesh(e->fv, &e->cpu_ball); /* fogvol */
    rd.color[0] = 0.78f; rd.color[1] = 0.82f; rd.color[2] = 0.88f; rd.density = 0.4f; /* fogvol */
    fogvol_create_ramp(e->fv, &rd, &e->mist); /* fogvol */
    rd.color[0] = 1.0f; rd.color[1] = 0.7f; rd.color[2] = 0.35f; rd.density = 0.9f; /* fogvol */
    rd.blend = FOGVOL_BLEND_LIGHT; return fogvol_create_ramp(e->fv, &rd, &e->glow) == FOGVOL_SUCCESS; /* fogvol */
}

/* after the opaque pass, with the engine's framebuffer bound */
static void fog_render(engine *e)
{
    fogvol_frame_desc fd; fogvol_volume_desc vd; int i; memset(&fd, 0, sizeof fd); memset(&vd, 0, sizeof vd); /* fogvol */
    memcpy(fd.view, e->view, 64); memcpy(fd.projection, e->proj, 64); /* fogvol */
    fd.znear = ZNEAR; fd.zfar = ZFAR; fd.viewport[2] = e->w; fd.viewport[3] = e->h; /* fogvol */
    fd.engine_depth_texture = e->depth_tex; /* (PS20 ignores it) */ /* fogvol */
    fd.debug_thickness = e->debug_thickness; fd.debug_ramp = e->debug_ramp ? e->glow : e->mist; /* fogvol */
    fogvol_begin_frame(e->fv, &fd); /* fogvol */
    if (!e->engine_depth) fogvol_add_occluder_callback(e->fv, fv_occluders, e); /* fogvol */
    for (i = 0; i < e->nfog; ++i) { /* fogvol */
        vd.mesh = e->fog[i].ball ? e->fv_ball : e->fv_box; vd.ramp = e->fog[i].light ? e->glow : e->mist; /* fogvol */
        memcpy(vd.model, e->fog[i].model, 64); fogvol_add_volume(e->fv, &vd); } /* fogvol */
    fogvol_end_frame(e->fv, NULL); /* fogvol */
}

static void fog_shutdown(engine *e)
{
    fogvol_destroy_mesh(e->fv, e->fv_box); fogvol_destroy_mesh(e->fv, e->fv_ball); /* fogvol */
    fogvol_destroy_ramp(e->fv, e->mist); fogvol_destroy_ramp(e->fv, e->glow); fogvol_destroy_context(e->fv); /* fogvol */
}

/* ============================== the engine's frame ================================ */
typedef struct gl_snapshot {
    int n;
    double v[256];
    const char *name[256];
} gl_snapshot;

static void snap(gl_snapshot *s);

static void engine_frame(engine *e, double t, gl_snapshot *after_fog)
{
    engine_update(e, t);
    /* scene pass into the offscreen framebuffer */
    glBindFramebuffer(GL_FRAMEBUFFER, e->fbo);
    glViewport(0, 0, e->w, e->h);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(e->lit_prog);
    glActiveTexture(GL_TEXTURE3);
    draw_objects(e);
    if (e->fv) fog_render(e); /* fogvol */
    if (after_fog) snap(after_fog);
    /* post pass into the window */
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(e->post_prog);
    glUniform2f(e->u_inv_size, 1.0f / (float)e->w, 1.0f / (float)e->h);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->color_tex);
    glBindVertexArray(e->post_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTexture(GL_TEXTURE_2D, 0); /* the colour texture is a render target again next frame */
}

/* ============================== --check support =================================== */
/* The GL state this engine relies on, read back without changing anything visible. */
static void snap(gl_snapshot *s)
{
    static const struct { const char *name; GLenum e; int n; int enabled; } items[] = {
        {"CURRENT_PROGRAM", GL_CURRENT_PROGRAM, 1, 0}, {"VERTEX_ARRAY_BINDING", GL_VERTEX_ARRAY_BINDING, 1, 0},
        {"ARRAY_BUFFER_BINDING", GL_ARRAY_BUFFER_BINDING, 1, 0},
        {"ELEMENT_ARRAY_BUFFER_BINDING", GL_ELEMENT_ARRAY_BUFFER_BINDING, 1, 0},
        {"DRAW_FRAMEBUFFER_BINDING", GL_DRAW_FRAMEBUFFER_BINDING, 1, 0},
        {"READ_FRAMEBUFFER_BINDING", GL_READ_FRAMEBUFFER_BINDING, 1, 0},
        {"RENDERBUFFER_BINDING", GL_RENDERBUFFER_BINDING, 1, 0}, {"VIEWPORT", GL_VIEWPORT, 4, 0},
        {"SCISSOR_BOX", GL_SCISSOR_BOX, 4, 0}, {"ACTIVE_TEXTURE", GL_ACTIVE_TEXTURE, 1, 0},
        {"DEPTH_FUNC", GL_DEPTH_FUNC, 1, 0}, {"DEPTH_WRITEMASK", GL_DEPTH_WRITEMASK, 1, 0},
        {"DEPTH_CLEAR_VALUE", GL_DEPTH_CLEAR_VALUE, 1, 0}, {"DEPTH_RANGE", GL_DEPTH_RANGE, 2, 0},
        {"BLEND_SRC_RGB", GL_BLEND_SRC_RGB, 1, 0}, {"BLEND_DST_RGB", GL_BLEND_DST_RGB, 1, 0},
        {"BLEND_SRC_ALPHA", GL_BLEND_SRC_ALPHA, 1, 0}, {"BLEND_DST_ALPHA", GL_BLEND_DST_ALPHA, 1, 0},
        {"BLEND_EQUATION_RGB", GL_BLEND_EQUATION_RGB, 1, 0}, {"BLEND_EQUATION_ALPHA", GL_BLEND_EQUATION_ALPHA, 1, 0},
        {"BLEND_COLOR", GL_BLEND_COLOR, 4, 0}, {"COLOR_WRITEMASK", GL_COLOR_WRITEMASK, 4, 0},
        {"COLOR_CLEAR_VALUE", GL_COLOR_CLEAR_VALUE, 4, 0}, {"CULL_FACE_MODE", GL_CULL_FACE_MODE, 1, 0},
        {"FRONT_FACE", GL_FRONT_FACE, 1, 0}, {"POLYGON_MODE", GL_POLYGON_MODE, 1, 0},
        {"POLYGON_OFFSET_FACTOR", GL_POLYGON_OFFSET_FACTOR, 1, 0}, {"POLYGON_OFFSET_UNITS", GL_POLYGON_OFFSET_UNITS, 1, 0},
        {"LINE_WIDTH", GL_LINE_WIDTH, 1, 0}, {"STENCIL_FUNC", GL_STENCIL_FUNC, 1, 0},
        {"STENCIL_REF", GL_STENCIL_REF, 1, 0}, {"STENCIL_VALUE_MASK", GL_STENCIL_VALUE_MASK, 1, 0},
        {"STENCIL_WRITEMASK", GL_STENCIL_WRITEMASK, 1, 0}, {"STENCIL_FAIL", GL_STENCIL_FAIL, 1, 0},
        {"STENCIL_PASS_DEPTH_PASS", GL_STENCIL_PASS_DEPTH_PASS, 1, 0},
        {"STENCIL_BACK_FUNC", GL_STENCIL_BACK_FUNC, 1, 0}, {"STENCIL_BACK_WRITEMASK", GL_STENCIL_BACK_WRITEMASK, 1, 0},
        {"STENCIL_CLEAR_VALUE", GL_STENCIL_CLEAR_VALUE, 1, 0}, {"PACK_ALIGNMENT", GL_PACK_ALIGNMENT, 1, 0},
        {"UNPACK_ALIGNMENT", GL_UNPACK_ALIGNMENT, 1, 0}, {"PACK_ROW_LENGTH", GL_PACK_ROW_LENGTH, 1, 0},
        {"UNPACK_ROW_LENGTH", GL_UNPACK_ROW_LENGTH, 1, 0},
        {"PIXEL_PACK_BUFFER_BINDING", GL_PIXEL_PACK_BUFFER_BINDING, 1, 0},
        {"PIXEL_UNPACK_BUFFER_BINDING", GL_PIXEL_UNPACK_BUFFER_BINDING, 1, 0},
        {"UNIFORM_BUFFER_BINDING", GL_UNIFORM_BUFFER_BINDING, 1, 0}, {"DRAW_BUFFER", GL_DRAW_BUFFER, 1, 0},
        {"READ_BUFFER", GL_READ_BUFFER, 1, 0}, {"BLEND", GL_BLEND, 1, 1}, {"DEPTH_TEST", GL_DEPTH_TEST, 1, 1},
        {"CULL_FACE", GL_CULL_FACE, 1, 1}, {"SCISSOR_TEST", GL_SCISSOR_TEST, 1, 1},
        {"STENCIL_TEST", GL_STENCIL_TEST, 1, 1}, {"DITHER", GL_DITHER, 1, 1},
        {"POLYGON_OFFSET_FILL", GL_POLYGON_OFFSET_FILL, 1, 1}, {"SAMPLE_ALPHA_TO_COVERAGE", GL_SAMPLE_ALPHA_TO_COVERAGE, 1, 1},
        {"MULTISAMPLE", GL_MULTISAMPLE, 1, 1}, {"FRAMEBUFFER_SRGB", GL_FRAMEBUFFER_SRGB, 1, 1},
        {"DEPTH_CLAMP", GL_DEPTH_CLAMP, 1, 1}, {"RASTERIZER_DISCARD", GL_RASTERIZER_DISCARD, 1, 1},
        {"COLOR_LOGIC_OP", GL_COLOR_LOGIC_OP, 1, 1}, {"PRIMITIVE_RESTART", GL_PRIMITIVE_RESTART, 1, 1},
        {"PROGRAM_POINT_SIZE", GL_PROGRAM_POINT_SIZE, 1, 1}};
    static const char *unit_names[8][2] = {{"unit 0 TEXTURE_BINDING_2D", "unit 0 SAMPLER_BINDING"},
                                           {"unit 1 TEXTURE_BINDING_2D", "unit 1 SAMPLER_BINDING"},
                                           {"unit 2 TEXTURE_BINDING_2D", "unit 2 SAMPLER_BINDING"},
                                           {"unit 3 TEXTURE_BINDING_2D", "unit 3 SAMPLER_BINDING"},
                                           {"unit 4 TEXTURE_BINDING_2D", "unit 4 SAMPLER_BINDING"},
                                           {"unit 5 TEXTURE_BINDING_2D", "unit 5 SAMPLER_BINDING"},
                                           {"unit 6 TEXTURE_BINDING_2D", "unit 6 SAMPLER_BINDING"},
                                           {"unit 7 TEXTURE_BINDING_2D", "unit 7 SAMPLER_BINDING"}};
    static const char *attr_names[2][4] = {{"attrib 0 ENABLED", "attrib 0 SIZE", "attrib 0 STRIDE", "attrib 0 BUFFER"},
                                           {"attrib 1 ENABLED", "attrib 1 SIZE", "attrib 1 STRIDE", "attrib 1 BUFFER"}};
    static const GLenum attr_q[4] = {GL_VERTEX_ATTRIB_ARRAY_ENABLED, GL_VERTEX_ATTRIB_ARRAY_SIZE,
                                     GL_VERTEX_ATTRIB_ARRAY_STRIDE, GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING};
    GLint active = 0, v = 0;
    GLfloat f[4];
    int i, k;
    s->n = 0;
    for (i = 0; i < (int)(sizeof items / sizeof items[0]); ++i) {
        if (items[i].enabled) {
            s->name[s->n] = items[i].name;
            s->v[s->n++] = glIsEnabled(items[i].e);
            continue;
        }
        glGetFloatv(items[i].e, f);
        for (k = 0; k < items[i].n; ++k) s->name[s->n] = items[i].name, s->v[s->n++] = f[k];
    }
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    for (i = 0; i < 8; ++i) { /* (the unit switching is put back before anything else runs) */
        glActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &v);
        s->name[s->n] = unit_names[i][0], s->v[s->n++] = v;
        glGetIntegerv(GL_SAMPLER_BINDING, &v);
        s->name[s->n] = unit_names[i][1], s->v[s->n++] = v;
    }
    glActiveTexture((GLenum)active);
    for (i = 0; i < 2; ++i)
        for (k = 0; k < 4; ++k) {
            glGetVertexAttribiv((GLuint)i, attr_q[k], &v);
            s->name[s->n] = attr_names[i][k], s->v[s->n++] = v;
        }
}

static unsigned char *read_window(const engine *e)
{
    unsigned char *px = (unsigned char *)malloc((size_t)e->w * (size_t)e->h * 4);
    glReadPixels(0, 0, e->w, e->h, GL_RGBA, GL_UNSIGNED_BYTE, px); /* PACK_ALIGNMENT is 1 (engine state) */
    return px;
}

static int run_check(engine *e, int force_ps20)
{
    const double t = 2.0;
    size_t n = (size_t)e->w * (size_t)e->h, i;
    unsigned char *plain, *fogged = NULL, *fog_mask = (unsigned char *)calloc(n, 1);
    gl_snapshot s0, s1;
    long differ = 0, fog_px = 0, changed = 0, compared = 0;
    int k, state_differ = 0, g;
    engine_frame(e, t, NULL); /* warm-up: every frame then starts from the state a frame leaves */
    engine_frame(e, t, &s0);  /* without fogvol: no context exists yet */
    plain = read_window(e);
    engine_frame(e, t, NULL); /* the engine alone must repeat itself bit for bit, or nothing can be compared */
    fogged = read_window(e);
    for (i = 0; i < n; ++i) differ += memcmp(plain + 4 * i, fogged + 4 * i, 4) != 0;
    printf("check: the same frame twice without fogvol: %ld pixels differ\n", differ);
    if (differ) {
        printf("check: this driver does not repeat frames exactly (llvmpipe: run with LP_NUM_THREADS=1)\n");
        return 1;
    }
    free(fogged);
    if (!fog_init(e, force_ps20)) {
        fprintf(stderr, "check: fogvol_create_context failed\n");
        return 1;
    }
    e->debug_thickness = (float *)malloc(n * sizeof(float));
    for (g = 0; g < 2; ++g) { /* debug thickness comes per fog group: one frame per group */
        e->debug_ramp = g;
        engine_frame(e, t, &s1);
        for (i = 0; i < n; ++i) fog_mask[i] |= e->debug_thickness[i] != 0.0f;
        for (k = 0; k < s0.n; ++k)
            if (s0.v[k] != s1.v[k]) {
                printf("check: GL state %s differs: %g without fogvol, %g after fogvol_end_frame\n", s0.name[k],
                       s0.v[k], s1.v[k]);
                ++state_differ;
            }
    }
    fogged = read_window(e);
    for (i = 0; i < n; ++i) {
        int d = memcmp(plain + 4 * i, fogged + 4 * i, 4) != 0;
        if (fog_mask[i]) fog_px++, changed += d;
        else compared++, differ += d;
    }
    printf("check: tier %s%s; fog (debug thickness != 0) covers %ld of %ld pixels, %ld of them changed\n",
           fogvol_tier_name(fogvol_context_tier(e->fv, NULL)), e->engine_depth ? " + ENGINE_DEPTH" : " (occluder callback)",
           fog_px, (long)n, changed);
    printf("check: %ld pixels outside the fog compared, %ld differ\n", compared, differ);
    printf("check: %d GL state values compared after fogvol_end_frame, %d differ\n", s0.n, state_differ);
    free(plain);
    free(fogged);
    free(fog_mask);
    free(e->debug_thickness);
    e->debug_thickness = NULL;
    if (changed == 0) printf("check: the fog changed no pixel: nothing was tested\n");
    return differ != 0 || state_differ != 0 || changed == 0;
}

int main(int argc, char **argv)
{
    engine e;
    int i, frames = 0, max_frames = 0, no_fog = 0, check = 0, force_ps20 = 0, rc = 0;
    const char *shot = NULL;
    memset(&e, 0, sizeof e);
    e.w = 800, e.h = 450;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--frames") && i + 1 < argc) max_frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--screenshot") && i + 1 < argc) shot = argv[++i];
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) sscanf(argv[++i], "%dx%d", &e.w, &e.h);
        else if (!strcmp(argv[i], "--no-fog")) no_fog = 1;
        else if (!strcmp(argv[i], "--ps20")) force_ps20 = 1;
        else if (!strcmp(argv[i], "--check")) check = 1;
        else {
            fprintf(stderr, "usage: %s [--frames N] [--screenshot FILE.png] [--no-fog] [--ps20] [--size WxH] [--check]\n",
                    argv[0]);
            return 2;
        }
    }
    /* --check compares frames bit for bit; Mesa's llvmpipe only repeats them exactly with one thread */
    if (check) setenv("LP_NUM_THREADS", "1", 0);
    if (!glfwInit()) {
        fprintf(stderr, "engine: glfwInit failed (no display? try xvfb-run -a)\n");
        return 1;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    e.win = glfwCreateWindow(e.w, e.h, "engine + fogvol", NULL, NULL);
    if (!e.win) {
        fprintf(stderr, "engine: no OpenGL 3.3 core window\n");
        return 1;
    }
    glfwMakeContextCurrent(e.win);
    glfwGetFramebufferSize(e.win, &e.w, &e.h);
    glfwSwapInterval(max_frames || check ? 0 : 1);
    engine_init(&e);

    if (check) {
        rc = run_check(&e, force_ps20);
    } else {
        if (!no_fog && !fog_init(&e, force_ps20)) { /* fogvol */
            fprintf(stderr, "engine: fogvol_create_context failed\n");
            return 1;
        }
        if (e.fv) printf("engine: fog volumes with tier %s%s\n", fogvol_tier_name(fogvol_context_tier(e.fv, NULL)),
                         e.engine_depth ? " + the engine's depth texture" : " + the engine's meshes as occluders");
        while (!glfwWindowShouldClose(e.win)) {
            engine_frame(&e, max_frames ? frames / 60.0 : glfwGetTime(), NULL);
            if (shot && max_frames && frames + 1 == max_frames) {
                unsigned char *px = read_window(&e);
                stbi_flip_vertically_on_write(1);
                if (stbi_write_png(shot, e.w, e.h, 4, px, e.w * 4)) printf("engine: wrote %s\n", shot);
                else rc = 1;
                free(px);
            }
            glfwSwapBuffers(e.win);
            glfwPollEvents();
            if (glfwGetKey(e.win, GLFW_KEY_ESCAPE) == GLFW_PRESS) break;
            if (max_frames && ++frames >= max_frames) break;
        }
    }
    if (e.fv) fog_shutdown(&e); /* fogvol */
    shp_free(&e.cpu_box);
    shp_free(&e.cpu_ball);
    glfwDestroyWindow(e.win);
    glfwTerminate();
    return rc;
}
