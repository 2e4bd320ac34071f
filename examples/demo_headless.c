#define _POSIX_C_SOURCE 199309L
/* demo_headless.c - fogvol.h without a window. OSMesa renders a floor and
   pillars (opaque, drawn by this program's own shader) cutting through fog
   volumes: a sphere, a torus, a wobbling blob, a long fog bank the camera can
   stand in, a negative sphere carving a hole into the bank, and a beam of
   light. It writes PNGs:
     scene_overview.png, scene_low.png, scene_inside_fog_bank.png  three viewpoints
     tiers.png        the same frame per tier: PS13 | PS20 | FLOAT
     dither.png       6-bit encoding, dithering off | on (the banding and its cure)
     ramps.png        colour ramps: extinction | linear | artist gradient
     thickness.png    the raw thickness of the fog group as false colour
   and prints where they went, the tier, the pass count and the frame time.

   usage: demo_headless [output-dir] [--check]    (default dir: build/demo)
   --check: also verifies the pictures (fog where volumes are, none
   elsewhere, the inside view fogged everywhere) and prints TAP lines. */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <sys/stat.h>
#include <time.h>

#define DW 640
#define DH 360

/* A tiny opaque renderer standing in for the engine: flat-shaded meshes, GLSL 330. */
typedef struct engine {
    GLuint prog, vao, vbo;
    GLint u_mvp, u_color, u_light;
} engine;

static void engine_init(engine *e)
{
    static const char *vs = "#version 330 core\nlayout(location=0) in vec3 p; layout(location=1) in vec3 n;\n"
                            "uniform mat4 mvp; out vec3 vn; void main(){ vn = n; gl_Position = mvp*vec4(p,1.0); }\n";
    static const char *fs = "#version 330 core\nin vec3 vn; uniform vec4 color; uniform vec4 light; out vec4 o;\n"
                            "void main(){ float l = 0.35 + 0.65*max(dot(normalize(vn), light.xyz), 0.0);\n"
                            " o = vec4(color.rgb*l, 1.0); }\n";
    GLuint v, f;
    v = glCreateShader(GL_VERTEX_SHADER);
    glShaderSource(v, 1, &vs, NULL);
    glCompileShader(v);
    f = glCreateShader(GL_FRAGMENT_SHADER);
    glShaderSource(f, 1, &fs, NULL);
    glCompileShader(f);
    e->prog = glCreateProgram();
    glAttachShader(e->prog, v);
    glAttachShader(e->prog, f);
    glLinkProgram(e->prog);
    e->u_mvp = glGetUniformLocation(e->prog, "mvp");
    e->u_color = glGetUniformLocation(e->prog, "color");
    e->u_light = glGetUniformLocation(e->prog, "light");
    glGenVertexArrays(1, &e->vao);
    glGenBuffers(1, &e->vbo);
}

/* draw a mesh as flat triangles (expanded, face normals) */
static void engine_draw(engine *e, const shp_mesh *m, const float model[16], const float vp[16], const float rgb[3])
{
    float *buf = (float *)malloc(sizeof(float) * 18 * (size_t)(m->icount / 3)), mvp[16];
    int t, k;
    for (t = 0; t < m->icount / 3; ++t) {
        const float *a = m->pos + 3 * m->idx[3 * t], *b = m->pos + 3 * m->idx[3 * t + 1], *c = m->pos + 3 * m->idx[3 * t + 2];
        float e1[3], e2[3], n[3], l, wn[3];
        for (k = 0; k < 3; ++k) {
            e1[k] = b[k] - a[k];
            e2[k] = c[k] - a[k];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (k = 0; k < 3; ++k) wn[k] = model[k] * n[0] + model[4 + k] * n[1] + model[8 + k] * n[2];
        l = sqrtf(wn[0] * wn[0] + wn[1] * wn[1] + wn[2] * wn[2]) + 1e-20f;
        for (k = 0; k < 3; ++k) {
            float *o = buf + 18 * t + 6 * k;
            const float *p = k == 0 ? a : k == 1 ? b : c;
            o[0] = p[0];
            o[1] = p[1];
            o[2] = p[2];
            o[3] = wn[0] / l;
            o[4] = wn[1] / l;
            o[5] = wn[2] / l;
        }
    }
    shp_mat_mul(mvp, vp, model);
    glUseProgram(e->prog);
    glUniformMatrix4fv(e->u_mvp, 1, GL_FALSE, mvp);
    glUniform4f(e->u_color, rgb[0], rgb[1], rgb[2], 1);
    glUniform4f(e->u_light, 0.38f, 0.83f, 0.41f, 0);
    glBindVertexArray(e->vao);
    glBindBuffer(GL_ARRAY_BUFFER, e->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 18 * (size_t)(m->icount / 3)), buf, GL_STREAM_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 24, (void *)12);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glDrawArrays(GL_TRIANGLES, 0, m->icount);
    free(buf);
}

static fogvol_mesh *upload(fogvol_context *fv, const shp_mesh *m, int occluder)
{
    fogvol_mesh_desc md;
    fogvol_mesh *out = NULL;
    fogvol_result r;
    memset(&md, 0, sizeof md);
    md.positions = m->pos;
    md.vertex_count = m->vcount;
    md.indices = (const uint32_t *)m->idx;
    md.index_count = m->icount;
    md.allow_open = occluder;
    r = fogvol_create_mesh(fv, &md, &out, NULL);
    if (r != FOGVOL_SUCCESS) {
        fprintf(stderr, "mesh: %s\n", fogvol_result_string(r));
        exit(1);
    }
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


#define NOBJ 12

typedef struct demo {
    glu_ctx g;
    engine e;
    shp_mesh mesh[NOBJ];
    float model[NOBJ][16];
    int kind[NOBJ]; /* 0 occluder, 1 fog, 2 bank, 3 bank hole (negative), 4 light */
    int n;
} demo;

typedef struct settings {
    fogvol_tier tier;
    int bits, dither, ramp; /* ramp: 0 extinction, 1 linear, 2 gradient */
    int w, h, view;
    float fog_scale;         /* density multiplier of the fog group */
} settings;

typedef struct shot {
    unsigned char *rgba;
    float *thick[3]; /* per group: fog, bank, light (debug read-back), may be NULL */
    fogvol_frame_stats st;
    fogvol_tier tier;
    double ms;
} shot;

static void add_obj(demo *d, shp_mesh m, int kind, const float model[16])
{
    if (d->n == NOBJ) {
        fprintf(stderr, "demo: more than NOBJ objects\n");
        exit(1);
    }
    d->mesh[d->n] = m;
    d->kind[d->n] = kind;
    memcpy(d->model[d->n], model, sizeof d->model[0]);
    d->n++;
}

/* a sphere whose radius wobbles with direction: still closed and outward */
static shp_mesh blob(float t)
{
    shp_mesh m = shp_sphere(1.0f, 64, 32);
    int i;
    for (i = 0; i < m.vcount; ++i) {
        float *p = m.pos + 3 * i;
        float th = atan2f(p[1], p[0]), ph = acosf(p[2] < -1 ? -1 : p[2] > 1 ? 1 : p[2]);
        float r = 0.8f + 0.22f * sinf(3 * th + t) * sinf(2 * ph) + 0.08f * sinf(5 * ph - t);
        p[0] *= r, p[1] *= r, p[2] *= r;
    }
    return m;
}

static void build(demo *d)
{
    static const float pillars[4][2] = {{-2.5f, -1.0f}, {0.3f, -2.2f}, {2.4f, 0.8f}, {-0.6f, 2.4f}};
    float m[16], r[16], t[16];
    int i;
    shp_mat_translate(m, 0, -1.0f, 0);
    add_obj(d, shp_box(12, 0.1f, 12), 0, m);
    for (i = 0; i < 4; ++i) {
        shp_mat_translate(m, pillars[i][0], 1.0f, pillars[i][1]);
        add_obj(d, shp_box(0.25f, 2.0f, 0.25f), 0, m);
    }
    shp_mat_translate(m, -2.2f, 0.4f, -0.8f);
    add_obj(d, shp_sphere(1.3f, 64, 32), 1, m);
    shp_mat_rotate(r, 70, 1, 0, 0.3f);
    shp_mat_translate(t, 2.0f, 0.5f, -1.2f);
    shp_mat_mul(m, t, r);
    add_obj(d, shp_torus(1.3f, 0.45f, 96, 32), 1, m);
    shp_mat_translate(m, 0.3f, 1.6f, 1.2f);
    add_obj(d, blob(0.7f), 1, m);
    shp_mat_translate(m, 0, -0.6f, -3.0f);
    add_obj(d, shp_box(12, 0.7f, 12), 2, m);
    shp_mat_translate(m, 0.2f, -0.6f, 1.0f);
    add_obj(d, shp_sphere(1.1f, 48, 24), 3, m);
    shp_mat_rotate(r, 18, 0, 0, 1);
    shp_mat_translate(t, 0.2f, 1.2f, -2.5f);
    shp_mat_mul(m, t, r);
    add_obj(d, shp_box(0.6f, 3.0f, 0.6f), 4, m);
}

static void camera(int view, int w, int h, float v[16], float p[16])
{
    static const double eye[3][3] = {{0.0, 3.2, 9.5}, {-4.5, 0.9, 6.0}, {1.5, -0.3, 5.5}};
    static const double at[3][3] = {{0, 0.3, 0}, {0.5, 0.2, -1.0}, {0, 0.6, -3}};
    static const double up[3] = {0, 1, 0};
    glu_look_at(v, eye[view], at[view], up);
    glu_perspective(p, 55.0, (double)w / h, 0.1, 40.0);
}

/* One frame: the engine's opaque pass, then fogvol with these settings.
   Returns 0 if the context could not be created (tier not available). */
static int render(demo *d, const settings *s, int with_fog, shot *out)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *fm[NOBJ];
    fogvol_ramp *ramp[3];
    fogvol_ramp_desc rd;
    fogvol_color_key keys[4];
    float v[16], p[16], vp[16];
    int i, grp, captures;
    static const float grey[3] = {0.55f, 0.52f, 0.48f}, stone[3] = {0.7f, 0.66f, 0.6f};
    if (!glu_create(&d->g, s->w, s->h, 1)) return 0;
    engine_init(&d->e);
    camera(s->view, s->w, s->h, v, p);
    shp_mat_mul(vp, p, v);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    cd.tier = s->tier;
    cd.encoding_bits = s->bits;
    cd.disable_dither = !s->dither;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        glu_destroy(&d->g);
        return 0;
    }
    out->tier = fogvol_context_tier(fv, NULL);
    for (i = 0; i < d->n; ++i) fm[i] = upload(fv, &d->mesh[i], d->kind[i] == 0);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.85f, rd.color[1] = 0.88f, rd.color[2] = 0.95f, rd.density = 0.55f * s->fog_scale;
    rd.model = s->ramp == 1 ? FOGVOL_RAMP_LINEAR : s->ramp == 2 ? FOGVOL_RAMP_GRADIENT : FOGVOL_RAMP_EXTINCTION;
    if (s->ramp == 1) rd.density = 0.3f * s->fog_scale;
    keys[0].thickness = 0.0f, keys[0].rgba[0] = 0.2f, keys[0].rgba[1] = 0.9f, keys[0].rgba[2] = 0.7f, keys[0].rgba[3] = 0.0f;
    keys[1].thickness = 0.8f, keys[1].rgba[0] = 0.3f, keys[1].rgba[1] = 0.8f, keys[1].rgba[2] = 1.0f, keys[1].rgba[3] = 0.45f;
    keys[2].thickness = 1.8f, keys[2].rgba[0] = 0.9f, keys[2].rgba[1] = 0.4f, keys[2].rgba[2] = 0.9f, keys[2].rgba[3] = 0.75f;
    keys[3].thickness = 3.0f, keys[3].rgba[0] = 1.0f, keys[3].rgba[1] = 0.9f, keys[3].rgba[2] = 0.5f, keys[3].rgba[3] = 0.95f;
    rd.keys = keys;
    rd.key_count = 4;
    fogvol_create_ramp(fv, &rd, &ramp[0]);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.55f, rd.color[1] = 0.62f, rd.color[2] = 0.70f, rd.density = 0.18f;
    fogvol_create_ramp(fv, &rd, &ramp[1]);
    rd.color[0] = 1.0f, rd.color[1] = 0.75f, rd.color[2] = 0.35f, rd.density = 0.35f, rd.blend = FOGVOL_BLEND_LIGHT;
    fogvol_create_ramp(fv, &rd, &ramp[2]);

    captures = with_fog ? 3 : 1; /* one frame per group whose thickness is read back, the first one timed */
    for (grp = 0; grp < captures; ++grp) {
        fogvol_frame_desc fd;
        double t0;
        glViewport(0, 0, s->w, s->h);
        glEnable(GL_DEPTH_TEST);
        glClearColor(0.32f, 0.45f, 0.62f, 1);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        for (i = 0; i < d->n; ++i)
            if (d->kind[i] == 0) engine_draw(&d->e, &d->mesh[i], d->model[i], vp, i == 0 ? grey : stone);
        glDisable(GL_DEPTH_TEST);
        if (!with_fog) break;
        memset(&fd, 0, sizeof fd);
        memcpy(fd.view, v, sizeof v);
        memcpy(fd.projection, p, sizeof p);
        fd.znear = 0.1f;
        fd.zfar = 40.0f;
        fd.viewport[2] = s->w;
        fd.viewport[3] = s->h;
        fd.debug_thickness = out->thick[grp];
        fd.debug_ramp = ramp[grp];
        glFinish();
        t0 = now_ms();
        fogvol_begin_frame(fv, &fd);
        for (i = 0; i < d->n; ++i) {
            fogvol_volume_desc vd;
            if (d->kind[i] == 0) {
                fogvol_add_occluder(fv, fm[i], d->model[i]);
                continue;
            }
            memset(&vd, 0, sizeof vd);
            vd.mesh = fm[i];
            vd.ramp = ramp[d->kind[i] == 1 ? 0 : d->kind[i] == 4 ? 2 : 1];
            vd.negative = d->kind[i] == 3;
            memcpy(vd.model, d->model[i], sizeof vd.model);
            fogvol_add_volume(fv, &vd);
        }
        fogvol_end_frame(fv, grp == 0 ? &out->st : NULL);
        glFinish();
        if (grp == 0) out->ms = now_ms() - t0;
        if (grp == 0) memcpy(out->rgba, d->g.pixels, (size_t)s->w * s->h * 4);
    }
    if (!with_fog) {
        glFinish();
        memcpy(out->rgba, d->g.pixels, (size_t)s->w * s->h * 4);
    }
    for (i = 0; i < d->n; ++i) fogvol_destroy_mesh(fv, fm[i]);
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    fogvol_destroy_context(fv);
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
static void row(demo *d, const char *dir, const char *name, const settings *v, int n, int report_each)
{
    shot sh[3];
    unsigned char *imgs[3];
    int k, got = 0;
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
    for (k = 0; k < got; ++k) {
        if (report_each) report(fogvol_tier_name(sh[k].tier), &sh[k]);
        free_shot(&sh[k]);
    }
}

/* ---- textured fog and volume light by compare (fogvol_volume_desc.density / color, fogvol_add_light) ---- */

static fogvol_volume_texture *demo_texture(fogvol_context *fv, int kind, int n)
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

/* the scene's volumes with textures: noise density (scrolled), the shaft's gradient, a colour */
static void demo_tl_volumes(demo *d, fogvol_context *fv, fogvol_mesh **fm, fogvol_ramp **ramp,
                            fogvol_volume_texture **tex, int lights)
{
    fogvol_volume_texture *noise = tex[0], *grad = tex[1], *colour = tex[2];
    int i;
    for (i = 0; i < d->n; ++i) {
        fogvol_volume_desc vd;
        if (d->kind[i] == 0) {
            fogvol_add_occluder(fv, fm[i], d->model[i]);
            continue;
        }
        if (lights) continue;
        memset(&vd, 0, sizeof vd);
        vd.mesh = fm[i];
        vd.ramp = ramp[d->kind[i] == 1 ? 0 : d->kind[i] == 4 ? 2 : 1];
        vd.negative = d->kind[i] == 3;
        memcpy(vd.model, d->model[i], sizeof vd.model);
        if (d->kind[i] == 4) { /* shaft: s along its axis (model y in [-3, 3]), thin at the base */
            vd.density = grad;
            vd.density_map[1] = 1.0f / 6.0f;
            vd.density_map[3] = 0.5f;
            vd.density_map[7] = 0.5f;
        } else if (!vd.negative) { /* noise in the horizontal plane, scrolled (time 1.5 s, 0.2 units/s) */
            vd.density = noise;
            vd.density_map[0] = d->kind[i] == 2 ? 0.12f : 0.35f;
            vd.density_map[6] = d->kind[i] == 2 ? 0.12f : 0.35f;
            vd.density_map[3] = 0.2f * 1.5f;
            if (d->kind[i] == 1) vd.color = colour;
        }
        fogvol_add_volume(fv, &vd);
    }
}

/* two convex light volumes (frustum-shaped shafts) lighting the scene by compare */
static fogvol_mesh *demo_tl_lights(fogvol_context *fv)
{
    fogvol_mesh *shaft;
    fogvol_light_desc ld;
    float r[16], t[16];
    shp_mesh sm = demo_shaft();
    shaft = upload(fv, &sm, 0);
    shp_free(&sm);
    memset(&ld, 0, sizeof ld);
    ld.mesh = shaft;
    shp_mat_rotate(r, 15, 0, 0, 1);
    shp_mat_translate(t, -1.2f, 1.4f, -0.6f);
    shp_mat_mul(ld.model, t, r);
    ld.color[0] = 0.9f, ld.color[1] = 0.65f, ld.color[2] = 0.3f;
    if (fogvol_add_light(fv, &ld) != FOGVOL_SUCCESS) fprintf(stderr, "demo: light refused\n");
    shp_mat_rotate(r, -25, 0, 1, 0);
    shp_mat_translate(t, 2.2f, 0.0f, 0.8f);
    shp_mat_mul(ld.model, t, r);
    ld.color[0] = 0.2f, ld.color[1] = 0.45f, ld.color[2] = 0.8f;
    if (fogvol_add_light(fv, &ld) != FOGVOL_SUCCESS) fprintf(stderr, "demo: light refused\n");
    return shaft;
}

/* textured: fog groups with density noise (the bank scrolled, the shaft thinning towards its
   base), a colour texture on the floating fog; lights: two convex light volumes lighting the
   scene by compare, no fog. */
static void demo_texlight(demo *d, const char *dir, int lights)
{
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *fm[NOBJ], *shaft = NULL;
    fogvol_ramp *ramp[3];
    fogvol_ramp_desc rd;
    fogvol_volume_texture *tex[3];
    fogvol_frame_desc fd;
    float v[16], p[16], vp[16];
    unsigned char *imgs[1];
    int i;
    static const float grey[3] = {0.55f, 0.52f, 0.48f}, stone[3] = {0.7f, 0.66f, 0.6f};
    if (!glu_create(&d->g, DW, DH, 1)) return;
    engine_init(&d->e);
    camera(0, DW, DH, v, p);
    shp_mat_mul(vp, p, v);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        glu_destroy(&d->g);
        return;
    }
    for (i = 0; i < d->n; ++i) fm[i] = upload(fv, &d->mesh[i], d->kind[i] == 0);
    for (i = 0; i < 3; ++i) tex[i] = demo_texture(fv, i, i == 1 ? 32 : 64);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f, rd.color[1] = 0.92f, rd.color[2] = 0.97f, rd.density = 0.9f;
    fogvol_create_ramp(fv, &rd, &ramp[0]);
    rd.color[0] = 0.55f, rd.color[1] = 0.62f, rd.color[2] = 0.70f, rd.density = 0.45f;
    fogvol_create_ramp(fv, &rd, &ramp[1]);
    rd.color[0] = 1.0f, rd.color[1] = 0.75f, rd.color[2] = 0.35f, rd.density = 0.6f, rd.blend = FOGVOL_BLEND_LIGHT;
    fogvol_create_ramp(fv, &rd, &ramp[2]);
    glViewport(0, 0, DW, DH);
    glEnable(GL_DEPTH_TEST);
    glClearColor(0.32f, 0.45f, 0.62f, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    for (i = 0; i < d->n; ++i)
        if (d->kind[i] == 0) engine_draw(&d->e, &d->mesh[i], d->model[i], vp, i == 0 ? grey : stone);
    glDisable(GL_DEPTH_TEST);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, v, sizeof v);
    memcpy(fd.projection, p, sizeof p);
    fd.znear = 0.1f;
    fd.zfar = 40.0f;
    fd.viewport[2] = DW;
    fd.viewport[3] = DH;
    fogvol_begin_frame(fv, &fd);
    demo_tl_volumes(d, fv, fm, ramp, tex, lights);
    if (lights) shaft = demo_tl_lights(fv);
    fogvol_end_frame(fv, NULL);
    glFinish();
    imgs[0] = d->g.pixels;
    save_row(dir, lights ? "light_compare.png" : "textured_fog.png", imgs, 1, DW, DH);
    printf("  %-34s tier %s\n", lights ? "light_compare.png" : "textured_fog.png",
           fogvol_tier_name(fogvol_context_tier(fv, NULL)));
    for (i = 0; i < d->n; ++i) fogvol_destroy_mesh(fv, fm[i]);
    if (shaft) fogvol_destroy_mesh(fv, shaft);
    for (i = 0; i < 3; ++i) fogvol_destroy_volume_texture(fv, tex[i]);
    for (i = 0; i < 3; ++i) fogvol_destroy_ramp(fv, ramp[i]);
    fogvol_destroy_context(fv);
    glu_destroy(&d->g);
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
    build(&d);
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

    /* side by side at half size: the tiers, dithering at 6 bits, the colour ramps */
    {
        settings v[3];
        for (k = 0; k < 3; ++k) {
            v[k] = s;
            v[k].w = DW / 2;
            v[k].h = DH / 2;
            v[k].view = 1;
        }
        v[0].tier = FOGVOL_TIER_PS13;
        v[1].tier = FOGVOL_TIER_PS20;
        v[2].tier = FOGVOL_TIER_FLOAT;
        row(&d, dir, "tiers.png", v, 3, 1);
        for (k = 0; k < 2; ++k) { /* banding at low precision (dense fog) and its cure */
            v[k].tier = FOGVOL_TIER_PS20;
            v[k].bits = 2;
            v[k].fog_scale = 4.0f;
            v[k].dither = k;
        }
        row(&d, dir, "dither.png", v, 2, 0);
        for (k = 0; k < 3; ++k) {
            v[k] = v[2];
            v[k].tier = FOGVOL_TIER_AUTO;
            v[k].ramp = k;
        }
        row(&d, dir, "ramps.png", v, 3, 0);
    }
    demo_texlight(&d, dir, 0);
    demo_texlight(&d, dir, 1);
    for (i = 0; i < d.n; ++i) shp_free(&d.mesh[i]);
    if (do_check) printf("1..%d\n", g_tap);
    return failures ? 1 : 0;
}
