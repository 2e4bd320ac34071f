/* demo_web.c - fogvol.h in the browser (emscripten, WebGL1 or WebGL2): the demos' courtyard to fly
   through with the page's controls (examples/web/courtyard.h), and, with ?test, the page's own check:

   A ground and a pillar (opaque, drawn by this program's GLSL ES 1.00 shader) and four fog
   volumes: a sphere the pillar cuts through, a turned box, a torus and a flat slab lying on
   the ground. The page renders the scene once without fog and once with it into the canvas,
   reads both back with glReadPixels and checks them against a ray caster written
   independently of fogvol (tests/raycast.h, the triangles drawn) and against closed-form
   chords (ray/box, ray/sphere) at the centre pixels of the box and the sphere:
     - the context is the WebGL version asked for, fogvol picked the tier and GLSL dialect
       that this context's features call for;
     - where a volume is, the colour is mix(scene, fog colour, 1 - exp(-density * t)) with t
       the ray-cast thickness, within 2/255 (interior pixels, silhouettes left out);
     - where no volume face is on a pixel's ray (nor its neighbours'), the pixel is
       byte-equal to the fog-free render.
   It prints TAP lines, the figures, and the fogged picture as a base64 PNG line into the
   page (tests/web_test.sh reads them with chromium --dump-dom) and sets document.title to
   "fogvol-web: PASS" or "fogvol-web: FAIL".

   Build: make web (build/web/demo_web.html). Open demo_web.html (WebGL2) or demo_web.html?webgl1;
   demo_web.html?test&webgl1 or ?test&webgl2 for the check. */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#include <GLES2/gl2.h>
#include <emscripten.h>
#include <emscripten/html5.h>
#include "tests/raycast.h"
#include "tests/shapes.h"
#include "examples/example_gl.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb_image_write.h>
#include <stdio.h>

#define WW 640
#define WH 360
#define NOBJ 6
#define DENSITY 0.9
static const float k_fog[3] = {0.85f, 0.88f, 0.95f};

typedef struct object {
    shp_mesh mesh;
    float model[16];
    int sign; /* 0 occluder, 1 fog */
    float rgb[3];
    GLuint vbo; /* flat-shaded triangles: position, normal */
} object;

typedef struct web {
    EMSCRIPTEN_WEBGL_CONTEXT_HANDLE ctx;
    int version; /* 1 or 2, as asked */
    GLuint prog;
    GLint u_mvp, u_color;
    object obj[NOBJ];
    int n;
    rc_camera cam;
    float view[16], proj[16];
    unsigned char *plain, *fogged; /* glReadPixels of the canvas: rows bottom to top */
    double *gt;                    /* ray-cast thickness per pixel centre */
    unsigned char *interior, *clear;
    int tap, failed;
} web;

static int check(web *w, int ok, const char *what)
{
    printf("%s %d - WebGL%d: %s\n", ok ? "ok" : "not ok", ++w->tap, w->version, what);
    if (!ok) w->failed = 1;
    return ok;
}

static fogvol_gl_proc get_proc(const char *name, void *user)
{
    (void)user;
    return (fogvol_gl_proc)emscripten_webgl_get_proc_address(name);
}

static void log_cb(void *user, fogvol_log_level level, const char *msg)
{
    (void)user;
    if (level <= FOGVOL_LOG_WARNING) printf("# fogvol: %s\n", msg);
}

/* the engine: flat-shaded opaque meshes, GLSL ES 1.00 (valid in WebGL1 and WebGL2) */
static void engine_init(web *w)
{
    static const char *vs = "attribute vec3 p; attribute vec3 n; uniform mat4 mvp; varying vec3 vn;\n"
                            "void main(){ vn = n; gl_Position = mvp * vec4(p, 1.0); }\n";
    static const char *fs = "precision mediump float; varying vec3 vn; uniform vec4 color;\n"
                            "void main(){ float l = 0.35 + 0.65 * max(dot(normalize(vn), vec3(0.38, 0.83, 0.41)), 0.0);\n"
                            " gl_FragColor = vec4(color.rgb * l, 1.0); }\n";
    static const char *const attribs[] = {"p", "n", NULL};
    w->prog = exm_program("engine", vs, &fs, 1, attribs);
    w->u_mvp = glGetUniformLocation(w->prog, "mvp");
    w->u_color = glGetUniformLocation(w->prog, "color");
}

/* the mesh as flat triangles with world-space face normals, into its own buffer */
static void engine_upload(object *o)
{
    glGenBuffers(1, &o->vbo);
    exm_upload_flat(o->vbo, &o->mesh, o->model, GL_STATIC_DRAW);
}

/* the engine's opaque pass into the canvas */
static void engine_draw(web *w)
{
    float vp[16], mvp[16];
    int i;
    shp_mat_mul(vp, w->proj, w->view);
    glViewport(0, 0, WW, WH);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glClearColor(0.32f, 0.45f, 0.62f, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(w->prog);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    for (i = 0; i < w->n; ++i) {
        const object *o = &w->obj[i];
        if (o->sign) continue;
        shp_mat_mul(mvp, vp, o->model);
        glUniformMatrix4fv(w->u_mvp, 1, GL_FALSE, mvp);
        glUniform4f(w->u_color, o->rgb[0], o->rgb[1], o->rgb[2], 1);
        glBindBuffer(GL_ARRAY_BUFFER, o->vbo);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 24, (void *)0);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 24, (void *)12);
        glDrawArrays(GL_TRIANGLES, 0, o->mesh.icount);
    }
    glDisableVertexAttribArray(1);
    glDisable(GL_DEPTH_TEST);
}

static void add(web *w, shp_mesh m, int sign, const float model[16], float r, float g, float b)
{
    object *o = &w->obj[w->n++];
    o->mesh = m;
    o->sign = sign;
    memcpy(o->model, model, sizeof o->model);
    o->rgb[0] = r, o->rgb[1] = g, o->rgb[2] = b;
}

/* object 2 is the fog sphere, object 3 the fog box (the closed-form checks use them) */
#define SPHERE_C (-1.7f), 0.35f, 0.0f
#define SPHERE_R 1.0f
#define BOX_C 0.4f, 0.25f, -0.6f
#define BOX_H 0.7f, 0.6f, 0.5f
#define BOX_ANGLE 30.0f
static void build(web *w)
{
    float m[16], r[16], t[16];
    shp_mat_translate(m, 0, -1.0f, 0);
    add(w, shp_box(6, 0.1f, 6), 0, m, 0.55f, 0.52f, 0.48f);
    shp_mat_translate(m, -1.25f, 0.4f, 0.5f);
    add(w, shp_box(0.18f, 1.4f, 0.18f), 0, m, 0.7f, 0.66f, 0.6f);
    shp_mat_translate(m, SPHERE_C);
    add(w, shp_sphere(SPHERE_R, 64, 32), 1, m, 0, 0, 0);
    shp_mat_rotate(r, BOX_ANGLE, 0, 1, 0);
    shp_mat_translate(t, BOX_C);
    shp_mat_mul(m, t, r);
    add(w, shp_box(BOX_H), 1, m, 0, 0, 0);
    shp_mat_rotate(r, 65, 1, 0, 0);
    shp_mat_translate(t, 2.3f, 0.5f, 0.3f);
    shp_mat_mul(m, t, r);
    add(w, shp_torus(0.75f, 0.28f, 96, 32), 1, m, 0, 0, 0);
    shp_mat_translate(m, 0.2f, -1.0f, 2.0f);
    add(w, shp_box(1.6f, 0.35f, 1.0f), 1, m, 0, 0, 0);
}

/* The tier and dialect this context calls for, from what WebGL reports (the rule of
   fogvol_context_desc.tier = 0): WebGL2 with EXT_color_buffer_float and EXT_float_blend:
   FLOAT (300 es); else highp fragment shaders: PS20; else PS13. WebGL2 speaks 300 es,
   WebGL1 GLSL ES 1.00. */
static fogvol_tier expected_tier(const web *w, fogvol_dialect *dialect)
{
    const char *ext = emscripten_webgl_get_supported_extensions();
    GLint range[2] = {0, 0}, precision = 0;
    int float_blend = strstr(ext, "EXT_color_buffer_float") && strstr(ext, "EXT_float_blend");
    glGetShaderPrecisionFormat(GL_FRAGMENT_SHADER, GL_HIGH_FLOAT, range, &precision);
    *dialect = w->version == 2 ? FOGVOL_GLSL_300ES : FOGVOL_GLSL_100;
    if (w->version == 2 && float_blend) return FOGVOL_TIER_FLOAT;
    return precision > 0 ? FOGVOL_TIER_PS20 : FOGVOL_TIER_PS13;
}

/* The scene with fog into the canvas; checks the tier and dialect fogvol chose. */
static void render_fog(web *w)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    fogvol_mesh *fm[NOBJ];
    fogvol_ramp *ramp = NULL;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_dialect want_dialect;
    fogvol_tier want = expected_tier(w, &want_dialect), got;
    fogvol_result r;
    char line[160];
    int i;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = get_proc;
    cd.logger.func = log_cb;
    r = fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, &cd.backend);
    if (!check(w, r == FOGVOL_SUCCESS, "fogvol_gl_backend_create")) return;
    snprintf(line, sizeof line, "GLSL dialect %s (expected %s)", fogvol_dialect_name(cd.backend.dialect),
             fogvol_dialect_name(want_dialect));
    check(w, cd.backend.dialect == want_dialect, line);
    r = fogvol_create_context(&cd, &fv); /* the backend stays ours: destroyed after the context */
    if (!check(w, r == FOGVOL_SUCCESS, "fogvol_create_context")) {
        cd.backend.destroy(cd.backend.user_data);
        return;
    }
    got = fogvol_context_tier(fv, NULL);
    snprintf(line, sizeof line, "tier %s (expected %s)", fogvol_tier_name(got), fogvol_tier_name(want));
    check(w, got == want, line);
    memset(&rd, 0, sizeof rd);
    memcpy(rd.color, k_fog, sizeof k_fog);
    rd.density = (float)DENSITY;
    r = fogvol_create_ramp(fv, &rd, &ramp);
    for (i = 0; i < w->n && r == FOGVOL_SUCCESS; ++i)
        if (!(fm[i] = exm_fog_mesh(fv, &w->obj[i].mesh, 0))) r = FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!check(w, r == FOGVOL_SUCCESS, "ramp and meshes created")) return;
    engine_draw(w);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, w->view, sizeof fd.view);
    memcpy(fd.projection, w->proj, sizeof fd.projection);
    fd.znear = (float)w->cam.znear;
    fd.zfar = (float)w->cam.zfar;
    fd.viewport[2] = WW;
    fd.viewport[3] = WH;
    fogvol_begin_frame(fv, &fd);
    for (i = 0; i < w->n; ++i) {
        fogvol_volume_desc vd;
        if (!w->obj[i].sign) {
            fogvol_add_occluder(fv, fm[i], w->obj[i].model);
            continue;
        }
        memset(&vd, 0, sizeof vd);
        vd.mesh = fm[i];
        vd.ramp = ramp;
        memcpy(vd.model, w->obj[i].model, sizeof vd.model);
        fogvol_add_volume(fv, &vd);
    }
    r = fogvol_end_frame(fv, &st);
    snprintf(line, sizeof line, "fogvol_end_frame: %s, %d passes", fogvol_result_string(r), st.passes);
    check(w, r == FOGVOL_SUCCESS, line);
    glReadPixels(0, 0, WW, WH, GL_RGBA, GL_UNSIGNED_BYTE, w->fogged);
    check(w, glGetError() == GL_NO_ERROR, "no GL error");
    for (i = 0; i < w->n; ++i) fogvol_destroy_mesh(fv, fm[i]);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    cd.backend.destroy(cd.backend.user_data);
}

/* what the composite should give: mix(scene, fog colour, 1 - exp(-density * t)), per channel, in [0, 1] */
static double want_channel(const unsigned char *plain, int ch, double t)
{
    double a = 1.0 - exp(-DENSITY * (t > 0 ? t : 0));
    return plain[ch] / 255.0 + (k_fog[ch] - plain[ch] / 255.0) * a;
}

/* largest |fogged - expected| over the RGB channels of pixel i, in 1/255 */
static double pixel_error(const web *w, int i, double t)
{
    double e = 0;
    int ch;
    for (ch = 0; ch < 3; ++ch) {
        double d = fabs(w->fogged[4 * i + ch] / 255.0 - want_channel(w->plain + 4 * i, ch, t)) * 255.0;
        if (d > e) e = d;
    }
    return e;
}

/* one ray-cast sample: its hit topology and whether a volume face is on the ray */
typedef struct sample {
    unsigned sig;
    int covered;
} sample;

/* Ground truth per pixel: thickness at the centre, "interior" (the hit topology at the
   centre equals that at the 4 corners and the 8 neighbouring centres, as rc_interior) and
   "clear" (no volume face on any of those 13 rays). Centres and corners are traced once each. */
static void ground_truth(const web *w, double *gt, unsigned char *interior, unsigned char *clear)
{
    rc_object ro[NOBJ];
    rc_scene rs;
    sample *cen = (sample *)malloc(sizeof(sample) * (WW + 2) * (WH + 2));
    sample *cor = (sample *)malloc(sizeof(sample) * (WW + 1) * (WH + 1));
    int i, x, y, dx, dy;
    for (i = 0; i < w->n; ++i) {
        ro[i].pos = w->obj[i].mesh.pos;
        ro[i].vcount = w->obj[i].mesh.vcount;
        ro[i].idx = w->obj[i].mesh.idx;
        ro[i].icount = w->obj[i].mesh.icount;
        memcpy(ro[i].model, w->obj[i].model, sizeof ro[i].model);
        ro[i].sign = w->obj[i].sign;
    }
    rc_scene_init(&rs, ro, w->n);
    for (y = -1; y <= WH; ++y)
        for (x = -1; x <= WW; ++x) {
            rc_result r = rc_trace(&rs, &w->cam, x + 0.5, y + 0.5);
            sample *s = &cen[(y + 1) * (WW + 2) + x + 1];
            s->sig = r.signature, s->covered = r.faces_front + r.faces_back > 0;
            if (x >= 0 && y >= 0 && x < WW && y < WH) gt[y * WW + x] = r.thickness;
        }
    for (y = 0; y <= WH; ++y)
        for (x = 0; x <= WW; ++x) {
            rc_result r = rc_trace(&rs, &w->cam, x, y);
            cor[y * (WW + 1) + x].sig = r.signature, cor[y * (WW + 1) + x].covered = r.faces_front + r.faces_back > 0;
        }
    rc_scene_free(&rs);
    for (y = 0; y < WH; ++y)
        for (x = 0; x < WW; ++x) {
            const sample *c = &cen[(y + 1) * (WW + 2) + x + 1];
            int same = 1, none = 1;
            for (dy = -1; dy <= 1; ++dy)
                for (dx = -1; dx <= 1; ++dx) {
                    const sample *s = &cen[(y + 1 + dy) * (WW + 2) + x + 1 + dx];
                    same &= s->sig == c->sig, none &= !s->covered;
                }
            for (dy = 0; dy <= 1; ++dy)
                for (dx = 0; dx <= 1; ++dx) {
                    const sample *s = &cor[(y + dy) * (WW + 1) + x + dx];
                    same &= s->sig == c->sig, none &= !s->covered;
                }
            interior[y * WW + x] = (unsigned char)same;
            clear[y * WW + x] = (unsigned char)none;
        }
    free(cen);
    free(cor);
}

/* the pixel a world point projects to, and that pixel's ray (t = view depth w) */
static int pixel_of(const web *w, const float p[3], double org[3], double dir[3])
{
    float vp[16];
    double c[4];
    int k, px, py;
    shp_mat_mul(vp, w->proj, w->view);
    for (k = 0; k < 4; ++k) c[k] = vp[k] * p[0] + vp[4 + k] * p[1] + vp[8 + k] * p[2] + vp[12 + k];
    px = (int)floor((c[0] / c[3] + 1) * 0.5 * WW);
    py = (int)floor((c[1] / c[3] + 1) * 0.5 * WH);
    rc_camera_ray(&w->cam, px + 0.5, py + 0.5, org, dir);
    return py * WW + px;
}

/* closed-form chords (w-extent: the ray parameter is w) */
static double chord_box(const double org[3], const double dir[3], const float c[3], const float h[3], double deg)
{
    double a = deg * RC__PI / 180.0, o[3], d[3], t0 = -1e30, t1 = 1e30;
    double p[3] = {org[0] - c[0], org[1] - c[1], org[2] - c[2]};
    int k;
    /* into the box frame: the inverse of a rotation by a about +y */
    o[0] = cos(a) * p[0] - sin(a) * p[2], o[1] = p[1], o[2] = sin(a) * p[0] + cos(a) * p[2];
    d[0] = cos(a) * dir[0] - sin(a) * dir[2], d[1] = dir[1], d[2] = sin(a) * dir[0] + cos(a) * dir[2];
    for (k = 0; k < 3; ++k) {
        double ta = (-h[k] - o[k]) / d[k], tb = (h[k] - o[k]) / d[k];
        if (ta > tb) {
            double s = ta;
            ta = tb, tb = s;
        }
        if (ta > t0) t0 = ta;
        if (tb < t1) t1 = tb;
    }
    return t1 > t0 ? t1 - t0 : 0;
}

static double chord_sphere(const double org[3], const double dir[3], const float c[3], double r)
{
    double oc[3] = {org[0] - c[0], org[1] - c[1], org[2] - c[2]};
    double a = rc__dot(dir, dir), b = 2 * rc__dot(dir, oc), q = rc__dot(oc, oc) - r * r, disc = b * b - 4 * a * q;
    return disc > 0 ? sqrt(disc) / a : 0;
}

/* the centre pixel of a box / sphere volume: ray-cast and closed-form thickness agree
   within tol, and the colour is the composite of the closed-form thickness within bound */
static void check_centre(web *w, const char *name, int i, double closed, double tol, double bound)
{
    char line[200];
    double cast = w->gt[i], err = pixel_error(w, i, closed);
    snprintf(line, sizeof line, "%s centre pixel (%d,%d): thickness %.5f closed form, %.5f ray-cast (tolerance %.4f)",
             name, i % WW, i / WW, closed, cast, tol);
    check(w, fabs(cast - closed) <= tol, line);
    snprintf(line, sizeof line, "%s centre pixel: colour off by %.2f/255 from the composite (bound %.2f), "
             "fog moved it by %d/255", name, err, bound,
             abs(w->fogged[4 * i] - w->plain[4 * i]) + abs(w->fogged[4 * i + 2] - w->plain[4 * i + 2]));
    check(w, err <= bound && memcmp(w->fogged + 4 * i, w->plain + 4 * i, 3) != 0, line);
}

/* the whole picture against the ray caster: composite where volumes are, untouched elsewhere */
static void check_picture(web *w)
{
    char line[200];
    double max_err = 0, sum_err = 0;
    int i, n_in = 0, n_clear = 0, same = 0, thick = 0, moved = 0, worst = 0;
    for (i = 0; i < WW * WH; ++i) {
        if (w->clear[i]) {
            ++n_clear;
            same += memcmp(w->fogged + 4 * i, w->plain + 4 * i, 4) == 0;
        } else if (w->interior[i]) {
            double e = pixel_error(w, i, w->gt[i]);
            ++n_in;
            sum_err += e;
            if (e > max_err) max_err = e, worst = i;
            if (w->gt[i] > 0.3) {
                ++thick;
                moved += memcmp(w->fogged + 4 * i, w->plain + 4 * i, 3) != 0;
            }
        }
    }
    snprintf(line, sizeof line, "%d pixels with no volume near, %d of them byte-equal to the fog-free render",
             n_clear, same);
    check(w, n_clear > 20000 && same == n_clear, line);
    snprintf(line, sizeof line, "%d interior pixels under volumes: composite off by max %.2f/255, mean %.3f/255 "
             "(bound 2/255)", n_in, max_err, n_in ? sum_err / n_in : 0);
    if (!check(w, n_in > 20000 && max_err <= 2.0, line))
        printf("# worst pixel (%d,%d): thickness %.4f, fog-free %d %d %d, fogged %d %d %d\n", worst % WW, worst / WW,
               w->gt[worst], w->plain[4 * worst], w->plain[4 * worst + 1], w->plain[4 * worst + 2],
               w->fogged[4 * worst], w->fogged[4 * worst + 1], w->fogged[4 * worst + 2]);
    snprintf(line, sizeof line, "fog is there: %d of %d pixels thicker than 0.3 changed", moved, thick);
    check(w, thick > 5000 && moved == thick, line);
}

/* the closed-form checks: the box's centre (exact mesh) and the sphere's (a 64 x 32 mesh
   inside the sphere: every point of the surface within r (1 - cos(pi/32)) of it, so the
   chord differs by at most twice that, and the colour by density * exp(-density t) times as
   much more than the 2/255 of the composite) */
static void check_closed_form(web *w)
{
    static const float bc[3] = {BOX_C}, bh[3] = {BOX_H}, sc[3] = {SPHERE_C};
    double org[3], dir[3], t, tess = 2 * SPHERE_R * (1 - cos(RC__PI / 32)), fog_shift;
    int i = pixel_of(w, bc, org, dir);
    check_centre(w, "box", i, chord_box(org, dir, bc, bh, BOX_ANGLE), 1e-4, 2.0);
    i = pixel_of(w, sc, org, dir);
    t = chord_sphere(org, dir, sc, SPHERE_R);
    fog_shift = 255.0 * DENSITY * exp(-DENSITY * (t - tess)) * tess;
    check_centre(w, "sphere", i, t, tess, 2.0 + fog_shift);
}

/* a picture as a PNG, base64, on one line "png <tag> <data>" (top row first) */
typedef struct bytes {
    unsigned char *p;
    size_t n, cap;
} bytes;

static void bytes_put(void *user, void *data, int size)
{
    bytes *b = (bytes *)user;
    if (b->n + (size_t)size > b->cap) {
        b->cap = (b->n + (size_t)size) * 2;
        b->p = (unsigned char *)realloc(b->p, b->cap);
    }
    memcpy(b->p + b->n, data, (size_t)size);
    b->n += (size_t)size;
}

static void print_png(const char *tag, const unsigned char *rgba)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    bytes b = {NULL, 0, 0};
    char *out;
    size_t i, o = 0;
    stbi_flip_vertically_on_write(1);
    stbi_write_png_to_func(bytes_put, &b, WW, WH, 4, rgba, WW * 4);
    out = (char *)malloc((b.n + 2) / 3 * 4 + 1);
    for (i = 0; i < b.n; i += 3) {
        unsigned v = (unsigned)b.p[i] << 16 | (i + 1 < b.n ? (unsigned)b.p[i + 1] << 8 : 0) |
                     (i + 2 < b.n ? b.p[i + 2] : 0);
        out[o++] = b64[v >> 18 & 63];
        out[o++] = b64[v >> 12 & 63];
        out[o++] = i + 1 < b.n ? b64[v >> 6 & 63] : '=';
        out[o++] = i + 2 < b.n ? b64[v & 63] : '=';
    }
    out[o] = 0;
    printf("png %s %s\n", tag, out);
    free(out);
    free(b.p);
}

/* where the checks looked: pixels with no volume near (checked byte-equal) dark blue, or red
   where they differ; interior pixels under volumes grey, brighter with the composite error
   (white = 2/255), red over 2/255; unchecked pixels (silhouettes) black */
static void print_error_map(web *w)
{
    unsigned char *m = (unsigned char *)calloc(WW * WH, 4);
    int i;
    for (i = 0; i < WW * WH; ++i) {
        unsigned char *p = m + 4 * i;
        p[3] = 255;
        if (w->clear[i]) {
            int same = memcmp(w->fogged + 4 * i, w->plain + 4 * i, 4) == 0;
            p[0] = same ? 0 : 255, p[2] = same ? 90 : 0;
        } else if (w->interior[i]) {
            double e = pixel_error(w, i, w->gt[i]);
            if (e > 2.0) p[0] = 255;
            else p[0] = p[1] = p[2] = (unsigned char)(60 + e / 2.0 * 195);
        }
    }
    print_png("error", m);
    free(m);
}

#include "examples/web/courtyard.h"

/* the canvas's WebGL context of the version asked for; checks it is that version (quiet: only say so
   when it is not) */
static int create_context(web *w, int quiet)
{
    EmscriptenWebGLContextAttributes a;
    const char *ver, *ren;
    char line[300];
    int ok;
    emscripten_webgl_init_context_attributes(&a);
    a.alpha = 0;
    a.depth = 1;
    a.stencil = 0;
    a.antialias = 0; /* fogvol refuses a multisampled canvas on WebGL (no per-sample shading) */
    a.preserveDrawingBuffer = 1;
    a.majorVersion = w->version;
    emscripten_set_canvas_element_size("#canvas", WW, WH);
    w->ctx = emscripten_webgl_create_context("#canvas", &a);
    if (!(w->ctx > 0)) return check(w, 0, "WebGL context created");
    if (!quiet) check(w, 1, "WebGL context created");
    emscripten_webgl_make_context_current(w->ctx);
    emscripten_webgl_enable_extension(w->ctx, "WEBGL_debug_renderer_info");
    ver = (const char *)glGetString(GL_VERSION);
    ren = (const char *)glGetString(0x9246 /* UNMASKED_RENDERER_WEBGL */);
    printf("# renderer: %s\n", ren ? ren : (const char *)glGetString(GL_RENDERER));
    snprintf(line, sizeof line, "context is \"%s\"", ver ? ver : "(null)");
    ok = ver && strncmp(ver, w->version == 2 ? "OpenGL ES 3.0" : "OpenGL ES 2.0", 13) == 0 &&
         strstr(ver, w->version == 2 ? "WebGL 2.0" : "WebGL 1.0");
    return quiet && ok ? 1 : check(w, ok, line);
}

/* The self-test (?test): the checks above, TAP lines and the title. */
static void self_test(web *w)
{
    int i;
    w->cam.eye[1] = 2.2, w->cam.eye[2] = 7.5, w->cam.target[1] = 0.2, w->cam.up[1] = 1;
    w->cam.fovy_deg = 50, w->cam.aspect = (double)WW / WH, w->cam.znear = 0.1, w->cam.zfar = 40;
    w->cam.width = WW, w->cam.height = WH;
    rc_camera_matrices(&w->cam, w->view, w->proj);
    w->plain = (unsigned char *)calloc(WW * WH, 4);
    w->fogged = (unsigned char *)calloc(WW * WH, 4);
    w->gt = (double *)malloc(sizeof(double) * WW * WH);
    w->interior = (unsigned char *)malloc(WW * WH);
    w->clear = (unsigned char *)malloc(WW * WH);
    if (create_context(w, 0)) {
        build(w);
        engine_init(w);
        for (i = 0; i < w->n; ++i)
            if (!w->obj[i].sign) engine_upload(&w->obj[i]);
        engine_draw(w);
        glReadPixels(0, 0, WW, WH, GL_RGBA, GL_UNSIGNED_BYTE, w->plain);
        render_fog(w);
        ground_truth(w, w->gt, w->interior, w->clear);
        check_picture(w);
        check_closed_form(w);
        print_png("canvas", w->fogged);
        print_error_map(w);
    }
    printf("1..%d\n", w->tap);
    emscripten_run_script(w->failed ? "document.title = 'fogvol-web: FAIL'" : "document.title = 'fogvol-web: PASS'");
}

/* The page's query (location.search without '?'): webgl1 or webgl2 (the default) picks the context;
   test: the self-test; drive: the interactive page driven by its own script (tests/web_test.sh);
   otherwise the interactive page. */
int main(int argc, char **argv)
{
    static web w;
    const char *q = argc > 1 ? argv[1] : "";
    w.version = strstr(q, "webgl1") ? 1 : 2;
    if (strstr(q, "test")) {
        self_test(&w);
        return 0;
    }
    emscripten_run_script("document.body.className = 'demo'");
    if (!create_context(&w, 1) || !cy_main(w.version, WW, WH, strstr(q, "drive") != NULL)) {
        printf("1..%d\n", w.tap + 1);
        emscripten_run_script("document.title = 'fogvol-web: FAIL'");
    }
    return 0;
}
