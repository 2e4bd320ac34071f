#define _POSIX_C_SOURCE 199309L
/* demo_headless.c - fogvol.h without a window: OSMesa renders a small scene
   (a floor and pillars cutting through fog volumes: a sphere, a torus, a long
   fog bank, a negative sphere carving a hole, a light beam) and writes PNGs.

   usage: demo_headless [output-dir]      (default: build/demo) */
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

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "build/demo";
    glu_ctx g;
    engine e;
    fogvol_context_desc cd;
    fogvol_context *fv;
    shp_mesh floor_m = shp_box(12, 0.1f, 12), pillar = shp_box(0.25f, 2.0f, 0.25f);
    shp_mesh sphere = shp_sphere(1.3f, 64, 32), torus = shp_torus(1.3f, 0.45f, 96, 32);
    shp_mesh bank = shp_box(12, 0.7f, 12), hole = shp_sphere(1.1f, 48, 24), beam = shp_box(0.6f, 3.0f, 0.6f);
    fogvol_mesh *m_floor, *m_pillar, *m_sphere, *m_torus, *m_bank, *m_hole, *m_beam;
    fogvol_ramp *r_fog, *r_bank, *r_light;
    fogvol_ramp_desc rd;
    float pillar_pos[4][2] = {{-2.5f, -1.0f}, {0.3f, -2.2f}, {2.4f, 0.8f}, {-0.6f, 2.4f}};
    int view;
    char path[512];
    mkdir("build", 0777);
    mkdir(dir, 0777);
    if (!glu_create(&g, DW, DH, 1)) {
        fprintf(stderr, "OSMesa context failed\n");
        return 1;
    }
    engine_init(&e);
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = log_cb;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) return 1;
    m_floor = upload(fv, &floor_m, 0);
    m_pillar = upload(fv, &pillar, 0);
    m_sphere = upload(fv, &sphere, 0);
    m_torus = upload(fv, &torus, 0);
    m_bank = upload(fv, &bank, 0);
    m_hole = upload(fv, &hole, 0);
    m_beam = upload(fv, &beam, 0);

    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.85f, rd.color[1] = 0.88f, rd.color[2] = 0.95f, rd.density = 0.55f;
    fogvol_create_ramp(fv, &rd, &r_fog);
    rd.color[0] = 0.55f, rd.color[1] = 0.62f, rd.color[2] = 0.70f, rd.density = 0.18f;
    fogvol_create_ramp(fv, &rd, &r_bank);
    rd.color[0] = 1.0f, rd.color[1] = 0.75f, rd.color[2] = 0.35f, rd.density = 0.35f, rd.blend = FOGVOL_BLEND_LIGHT;
    fogvol_create_ramp(fv, &rd, &r_light);

    for (view = 0; view < 2; ++view) {
        {
            float v[16], p[16], vp[16], m[16], id[16];
            double eye[2][3] = {{0.0, 3.2, 9.5}, {1.5, -0.3, 5.5}}, at[2][3] = {{0, 0.3, 0}, {0, 0.6, -3}};
            double up[3] = {0, 1, 0};
            const float grey[3] = {0.55f, 0.52f, 0.48f}, stone[3] = {0.7f, 0.66f, 0.6f};
            fogvol_frame_desc fd;
            fogvol_volume_desc vd;
            fogvol_frame_stats st;
            double t0, t1;
            int i;
            glu_look_at(v, eye[view], at[view], up);
            glu_perspective(p, 55.0, (double)DW / DH, 0.1, 40.0);
            shp_mat_mul(vp, p, v);
            glViewport(0, 0, DW, DH);
            glEnable(GL_DEPTH_TEST);
            glClearColor(0.32f, 0.45f, 0.62f, 1);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            shp_mat_identity(id);
            shp_mat_translate(m, 0, -1.0f, 0);
            engine_draw(&e, &floor_m, m, vp, grey);
            for (i = 0; i < 4; ++i) {
                float pm[16];
                shp_mat_translate(pm, pillar_pos[i][0], 1.0f, pillar_pos[i][1]);
                engine_draw(&e, &pillar, pm, vp, stone);
            }

            memset(&fd, 0, sizeof fd);
            memcpy(fd.view, v, sizeof v);
            memcpy(fd.projection, p, sizeof p);
            fd.znear = 0.1f;
            fd.zfar = 40.0f;
            fd.viewport[2] = DW;
            fd.viewport[3] = DH;
            t0 = now_ms();
            fogvol_begin_frame(fv, &fd);
            fogvol_add_occluder(fv, m_floor, m);
            for (i = 0; i < 4; ++i) {
                float pm[16];
                shp_mat_translate(pm, pillar_pos[i][0], 1.0f, pillar_pos[i][1]);
                fogvol_add_occluder(fv, m_pillar, pm);
            }
            memset(&vd, 0, sizeof vd);
            vd.ramp = r_fog;
            vd.mesh = m_sphere;
            shp_mat_translate(vd.model, -2.2f, 0.4f, -0.8f);
            fogvol_add_volume(fv, &vd);
            vd.mesh = m_torus;
            {
                float r[16], t[16];
                shp_mat_rotate(r, 70, 1, 0, 0.3f);
                shp_mat_translate(t, 2.0f, 0.5f, -1.2f);
                shp_mat_mul(vd.model, t, r);
            }
            fogvol_add_volume(fv, &vd);
            vd.ramp = r_bank;
            vd.mesh = m_bank;
            shp_mat_translate(vd.model, 0, -0.6f, -3.0f);
            fogvol_add_volume(fv, &vd);
            vd.mesh = m_hole;
            vd.negative = 1;
            shp_mat_translate(vd.model, 0.2f, -0.6f, 1.0f);
            fogvol_add_volume(fv, &vd);
            vd.negative = 0;
            vd.ramp = r_light;
            vd.mesh = m_beam;
            {
                float r[16], t[16];
                shp_mat_rotate(r, 18, 0, 0, 1);
                shp_mat_translate(t, 0.2f, 1.2f, -2.5f);
                shp_mat_mul(vd.model, t, r);
            }
            fogvol_add_volume(fv, &vd);
            fogvol_end_frame(fv, &st);
            glFinish();
            t1 = now_ms();
            snprintf(path, sizeof path, "%s/scene_%s.png", dir, view == 0 ? "overview" : "inside_fog_bank");
            stbi_flip_vertically_on_write(1);
            stbi_write_png(path, DW, DH, 4, g.pixels, DW * 4);
            printf("%s  (tier PS20, %d passes, %d groups, fog %.1f ms on llvmpipe)\n", path, st.passes, st.groups,
                   t1 - t0);
            (void)id;
        }
    }
    fogvol_destroy_mesh(fv, m_floor);
    fogvol_destroy_mesh(fv, m_pillar);
    fogvol_destroy_mesh(fv, m_sphere);
    fogvol_destroy_mesh(fv, m_torus);
    fogvol_destroy_mesh(fv, m_bank);
    fogvol_destroy_mesh(fv, m_hole);
    fogvol_destroy_mesh(fv, m_beam);
    fogvol_destroy_ramp(fv, r_fog);
    fogvol_destroy_ramp(fv, r_bank);
    fogvol_destroy_ramp(fv, r_light);
    fogvol_destroy_context(fv);
    shp_free(&floor_m);
    shp_free(&pillar);
    shp_free(&sphere);
    shp_free(&torus);
    shp_free(&bank);
    shp_free(&hole);
    shp_free(&beam);
    glu_destroy(&g);
    return 0;
}
