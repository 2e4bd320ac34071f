#define _POSIX_C_SOURCE 200809L
/* bench.c - fogvol.h benchmark: fixed scenes rendered headless (OSMesa) at
   1280x720 and 640x360, every tier against two references measured in the
   same run, interleaved frame by frame:

     floor    the volume triangles drawn once (constant colour, additive, no
              culling) into an R32F target + one full-screen composite pass
              (texelFetch, discard where empty, blend): the least any
              technique that rasterises every face once can cost
     peeling  exact thickness by depth peeling: an opaque pre-pass (linear
              depth), then one geometry pass per layer until an occlusion query
              reports no fragment, then one full-screen composite. Each peel
              keeps the nearest fragment behind the previous layer (depth
              test LESS on a fresh depth buffer, discard if z <= previous z +
              eps) and writes (running sum + its signed depth clamped to the
              opaque depth, layer count) into one of two RG32F targets in
              turn, reading the running sum from the other: additive blending
              inside a peel would add every fragment that passes the depth
              test on its way, not just the nearest one. The target with the
              higher count holds a pixel's whole sum.

   Fog time per frame = glFinish .. fog work .. glFinish (the engine's opaque
   pass is drawn before the clock starts; for MRT it is the engine pass that
   writes O, so the MRT time is the whole frame minus the median plain engine
   pass of the same scene). Medians of many frames after warm-up. Under OSMesa
   the clock is the wall clock; built with -DGLU_EGL (make bench-egl, for a
   GPU driver through EGL) it is GPU timestamps taken at the same points.

   usage: bench [--quick]     (--quick: smallest scene, 640x360, few frames;
                               prints only; --scene I: scene I alone, prints only;
                               --cpu: the scale and lifetime figures of the CPU section
                               alone, on the null backend, no GL, prints only;
                               --large: the GPU-scale scenes, 64 volumes, shells k=16 and
                               floor + pillars at 2560x1440 and 3840x2160, few frames,
                               into bench/RESULTS-large.md (GLU_EGL: RESULTS-gpu-large.md))
   full run: prints the tables, writes bench/RESULTS.md and bench/plot.png
   (GLU_EGL: bench/RESULTS-gpu.md and bench/plot-gpu.png) */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#define GL_GLEXT_PROTOTYPES /* libOSMesa (or, with GLU_EGL, libOpenGL) exports the GL entry points */
#include "tests/gl_util.h"
#include <GL/glext.h>
#include "tests/shapes.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stb/stb_easy_font.h>
#include <stdarg.h>
#include <time.h>
#include <sys/utsname.h>

#define NTIER 11
#define NDEFAULT 5 /* the first NDEFAULT tiers: fogvol's default configuration (every speed-up on) */
#define M_FLOOR NTIER
#define M_OCCFLOOR (NTIER + 1)
#define M_SCFLOOR (NTIER + 2)
#define M_PEEL (NTIER + 3)
#define NMETH (NTIER + 4)
#define SPEEDUPS_ALL                                                                                              \
    (FOGVOL_SPEEDUP_SKIP_OPAQUE | FOGVOL_SPEEDUP_TEXEL_FETCH | FOGVOL_SPEEDUP_EXP_COMPOSITE | \
     FOGVOL_SPEEDUP_SPECIALIZE | FOGVOL_SPEEDUP_ALU | FOGVOL_SPEEDUP_OVERFLOW_BANDS | FOGVOL_SPEEDUP_FAST_EXP | \
     FOGVOL_SPEEDUP_DEPTH_TEST | FOGVOL_SPEEDUP_INLINE_RESOLVE | FOGVOL_SPEEDUP_BLEND_COLOR | FOGVOL_SPEEDUP_FLOAT_O | \
     FOGVOL_SPEEDUP_SKIP_CHECK | FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH | FOGVOL_SPEEDUP_EXACT_SUM | \
     FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST)
#define MAXI 72 /* instances per scene */
#define MAXMESH 24
#define MAXLAYERS 96
#define MAXSCENE 12

typedef struct tier_cfg {
    const char *name;
    fogvol_tier tier;
    unsigned variants;
    unsigned speedups_off; /* fogvol_context_desc.disable_speedups */
    int downsample;        /* fogvol_frame_desc.downsample */
    int software;          /* fogvol_gl_desc.software (1: depth-tested engine depth on any GL) */
} tier_cfg;
static const tier_cfg g_tiers[NTIER] = {{"PS13", FOGVOL_TIER_PS13, 0, 0, 0, 0},
                                        {"PS20", FOGVOL_TIER_PS20, 0, 0, 0, 0},
                                        {"MRT", FOGVOL_TIER_MRT, 0, 0, 0, 0},
                                        {"FLOAT", FOGVOL_TIER_FLOAT, 0, 0, 0, 0},
                                        {"FLOAT+engine depth", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, 0, 0, 0},
                                        {"FLOAT, speed-ups off", FOGVOL_TIER_FLOAT, 0, SPEEDUPS_ALL, 0, 0},
                                        {"PS20, speed-ups off", FOGVOL_TIER_PS20, 0, SPEEDUPS_ALL, 0, 0},
                                        {"FLOAT, half resolution", FOGVOL_TIER_FLOAT, 0, 0, 2, 0},
                                        {"PS20+engine depth", FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, 0, 0, 0},
                                        {"FLOAT+engine depth, depth-tested", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, 0,
                                         0, 1},
                                        {"FLOAT+engine depth, per-face read", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH,
                                         FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST, 0, 0}};
#define M_FLOAT 3
#define M_FLOAT_ED 4 /* FLOAT + ENGINE_DEPTH */
#define M_PS20 1
#define M_PS20_ED 8 /* PS20 + ENGINE_DEPTH */
static const char *const g_meth_names[NMETH] = {
    "PS13", "PS20", "MRT", "FLOAT", "FLOAT+engine depth", "FLOAT, speed-ups off", "PS20, speed-ups off",
    "FLOAT, half resolution", "PS20+engine depth", "FLOAT+engine depth, depth-tested",
    "FLOAT+engine depth, per-face read", "floor", "occluder floor", "scissored floor", "depth peeling"};

/* ---- small utilities -------------------------------------------------------- */
static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

/* output files and frames: OSMesa (llvmpipe), or built with -DGLU_EGL (tests/gl_util.h) any EGL
   device, a GPU driver through glvnd */
#ifdef GLU_EGL
#define BENCH_MD "bench/RESULTS-gpu.md"
#define BENCH_MD_LARGE "bench/RESULTS-gpu-large.md"
#define BENCH_PNG "bench/plot-gpu.png"
#define BENCH_FRAMES 41 /* GPU frames are short: more of them for the medians */
#define BENCH_CONTEXT "EGL context (OpenGL 3.3 core on an EGL device)"
#else
#define BENCH_MD "bench/RESULTS.md"
#define BENCH_MD_LARGE "bench/RESULTS-large.md"
#define BENCH_PNG "bench/plot.png"
#define BENCH_FRAMES 15
#define BENCH_CONTEXT "OSMesa context"
#endif

/* The clock of the GPU work. Under OSMesa the GL runs on the CPU and a
   reading is the wall clock after glFinish. On a GPU (g_gpu_clock) a reading
   is a GL_TIMESTAMP query, resolved later: a start is issued after a glFinish
   (the GPU idle), an end before one (the GPU stamps it once every command
   before it is done), so an interval is the GPU timeline of the work between,
   without glFinish's round trip. */
typedef struct tick {
    double ms;
    GLuint q;
} tick;
#define NQUERY 64
static int g_gpu_clock;
static GLuint g_query[NQUERY];
static unsigned g_nquery;

static tick tick_at(int end)
{
    tick t;
    t.q = 0;
    if (g_gpu_clock && end) {
        t.q = g_query[g_nquery++ % NQUERY];
        glQueryCounter(t.q, GL_TIMESTAMP);
    }
    glFinish();
    t.ms = now_ms();
    if (g_gpu_clock && !end) {
        t.q = g_query[g_nquery++ % NQUERY];
        glQueryCounter(t.q, GL_TIMESTAMP);
    }
    return t;
}
#define tick_start() tick_at(0)
#define tick_end() tick_at(1)

static double tick_ms(tick a, tick b)
{
    GLuint64 x = 0, y = 0;
    if (!g_gpu_clock) return b.ms - a.ms;
    glGetQueryObjectui64v(a.q, GL_QUERY_RESULT, &x);
    glGetQueryObjectui64v(b.q, GL_QUERY_RESULT, &y);
    return (double)(y - x) / 1e6;
}

/* GPU timestamps where the context has them (GL_TIMESTAMP counter bits > 0), GLU_EGL builds only */
static void clock_init(void)
{
#ifdef GLU_EGL
    GLint bits = 0;
    glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
    g_gpu_clock = bits > 0 && getenv("FOGVOL_BENCH_WALL_CLOCK") == NULL;
    if (g_gpu_clock) glGenQueries(NQUERY, g_query);
#endif
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(const double *v, int n)
{
    double tmp[512];
    if (n <= 0) return 0;
    if (n > 512) n = 512;
    memcpy(tmp, v, sizeof(double) * (size_t)n);
    qsort(tmp, (size_t)n, sizeof(double), cmp_d);
    return n % 2 ? tmp[n / 2] : 0.5 * (tmp[n / 2 - 1] + tmp[n / 2]);
}

static void die(const char *what)
{
    fprintf(stderr, "bench: %s\n", what);
    exit(1);
}

static void fv_log(void *u, fogvol_log_level l, const char *m)
{
    (void)u;
    if (l == FOGVOL_LOG_ERROR) fprintf(stderr, "[fogvol] %s\n", m);
}

/* output goes to stdout and, in the full run, into RESULTS.md */
static FILE *g_md;
static void out(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    if (g_md) {
        va_start(ap, fmt);
        vfprintf(g_md, fmt, ap);
        va_end(ap);
    }
    fflush(stdout);
}

/* ---- GL helpers ------------------------------------------------------------- */
static GLuint program(const char *const *vs, int nvs, const char *const *fs, int nfs)
{
    GLuint p = glCreateProgram(), s[2];
    GLint ok = 0;
    char log[2048];
    int i;
    for (i = 0; i < 2; ++i) {
        s[i] = glCreateShader(i ? GL_FRAGMENT_SHADER : GL_VERTEX_SHADER);
        glShaderSource(s[i], i ? nfs : nvs, i ? fs : vs, NULL);
        glCompileShader(s[i]);
        glGetShaderiv(s[i], GL_COMPILE_STATUS, &ok);
        if (!ok) {
            glGetShaderInfoLog(s[i], sizeof log, NULL, log);
            fprintf(stderr, "%s\n", log);
            die("shader compile");
        }
        glAttachShader(p, s[i]);
    }
    glLinkProgram(p);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) die("shader link");
    glDeleteShader(s[0]);
    glDeleteShader(s[1]);
    return p;
}

static GLuint prog1(const char *vs, const char *fs) { return program(&vs, 1, &fs, 1); }

static GLuint tex2d(GLenum ifmt, int w, int h, GLenum fmt, GLenum type)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexImage2D(GL_TEXTURE_2D, 0, (GLint)ifmt, w, h, 0, fmt, type, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

static GLuint fbo2(GLuint color, GLuint depth_tex, GLuint depth_rb)
{
    GLuint f;
    glGenFramebuffers(1, &f);
    glBindFramebuffer(GL_FRAMEBUFFER, f);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, 0);
    if (depth_tex) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_tex, 0);
    if (depth_rb) glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("framebuffer incomplete");
    return f;
}

/* ---- shaders of the engine, the floor and the peeling ------------------------- */
static const char *VS_MESH =
    "#version 330 core\nlayout(location = 0) in vec3 p;\nuniform mat4 mvp, mv;\nuniform vec2 nf;\n"
    "out float vd; out float d;\n"
    "void main() { vd = -(mv * vec4(p, 1.0)).z; d = vd * nf.x + nf.y; gl_Position = mvp * vec4(p, 1.0); }\n";
static const char *VS_FULL = "#version 330 core\nvoid main() {\n"
                             "  vec2 v = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
                             "  gl_Position = vec4(v, 0.0, 1.0); }\n";
static const char *FS_ENGINE = "#version 330 core\nin float vd; in float d;\nuniform vec4 col;\n"
                               "layout(location = 0) out vec4 o;\nvoid main() { o = col; }\n";
static const char *FS_ENGINE_MRT =
    "in float vd; in float d;\nuniform vec4 col;\nlayout(location = 0) out vec4 o;\n"
    "layout(location = 1) out vec4 fogvol_o;\n"
    "void main() { o = col; fogvol_o = fogvol_encode_view_depth(vd); }\n";
static const char *FS_CONST = "#version 330 core\nout vec4 o;\nvoid main() { o = vec4(1.0 / 255.0); }\n";
static const char *FS_FLOOR_COMP = "#version 330 core\nuniform sampler2D s;\nout vec4 o;\n"
                                   "void main() { float v = texelFetch(s, ivec2(gl_FragCoord.xy), 0).r;\n"
                                   "  if (v == 0.0) discard;\n  o = vec4(0.8, 0.8, 0.8, v); }\n";
static const char *FS_LINDEPTH = "#version 330 core\nin float vd; in float d;\nout vec4 o;\n"
                                 "void main() { o = vec4(clamp(d, 0.0, 1.0), 0.0, 0.0, 0.0); }\n";
/* one peel: the nearest fragment behind the previous layer writes (running
   sum + its signed clamped depth, layer count); ping-pong targets */
static const char *FS_PEEL =
    "#version 330 core\nin float vd; in float d;\nuniform sampler2D prevc, prevz, opq;\nuniform float first, eps;\n"
    "out vec4 o;\n"
    "void main() {\n  ivec2 c = ivec2(gl_FragCoord.xy);\n"
    "  if (first < 0.5 && gl_FragCoord.z <= texelFetch(prevz, c, 0).r + eps) discard;\n"
    "  vec2 pr = texelFetch(prevc, c, 0).rg;\n"
    "  float v = min(max(d, 0.0), texelFetch(opq, c, 0).r);\n"
    "  o = vec4(pr.x + (gl_FrontFacing ? -v : v), pr.y + 1.0, 0.0, 0.0);\n}\n";
static const char *FS_PEEL_COMP =
    "#version 330 core\nuniform sampler2D a, b;\nuniform vec4 fog;\nuniform float range;\nout vec4 o;\n"
    "void main() {\n  ivec2 c = ivec2(gl_FragCoord.xy);\n"
    "  vec2 x = texelFetch(a, c, 0).rg, y = texelFetch(b, c, 0).rg, s = x.y > y.y ? x : y;\n"
    "  if (s.y == 0.0) discard;\n"
    "  o = vec4(fog.rgb, 1.0 - exp(-fog.w * max(s.x * range, 0.0))); }\n";

typedef struct progs {
    GLuint engine, engine_mrt, cnst, floor_comp, lindepth, peel, peel_comp, empty_vao;
} progs;
static progs P;

static void make_progs(void)
{
    const char *fs[3];
    P.engine = prog1(VS_MESH, FS_ENGINE);
    fs[0] = "#version 330 core\n";
    fs[1] = fogvol_mrt_snippet();
    fs[2] = FS_ENGINE_MRT;
    P.engine_mrt = program(&VS_MESH, 1, fs, 3);
    P.cnst = prog1(VS_MESH, FS_CONST);
    P.floor_comp = prog1(VS_FULL, FS_FLOOR_COMP);
    P.lindepth = prog1(VS_MESH, FS_LINDEPTH);
    P.peel = prog1(VS_MESH, FS_PEEL);
    P.peel_comp = prog1(VS_FULL, FS_PEEL_COMP);
    glGenVertexArrays(1, &P.empty_vao);
}

/* ---- scenes ------------------------------------------------------------------ */
typedef struct gmesh {
    shp_mesh m;
    float bmin[3], bmax[3]; /* bounding box */
    GLuint vao, vbo, ibo;
    fogvol_mesh *fm[NTIER];
} gmesh;

typedef struct inst {
    int mesh;
    float model[16];
    int occluder;
    float col[3];
} inst;

typedef struct scene {
    char name[48];
    double eye[3], at[3];
    float fovy, znear, zfar;
    gmesh mesh[MAXMESH];
    int nmesh;
    int occluders; /* occluder instances */
    inst in[MAXI];
    int n;
    int k;        /* depth complexity of a shell scene (0: other) */
    int triangles; /* volume triangles drawn per frame */
} scene;

static int add_mesh(scene *s, shp_mesh m)
{
    if (!m.pos) die("mesh generation");
    s->mesh[s->nmesh].m = m;
    return s->nmesh++;
}

static void add_inst(scene *s, int mesh, const float model[16], int occluder)
{
    inst *i = &s->in[s->n++];
    i->mesh = mesh;
    memcpy(i->model, model, sizeof i->model);
    i->occluder = occluder;
    s->occluders += occluder != 0;
    i->col[0] = 0.55f;
    i->col[1] = 0.5f;
    i->col[2] = 0.45f;
    if (!occluder) s->triangles += s->mesh[mesh].m.icount / 3;
}

static void trs(float m[16], float tx, float ty, float tz, float ang, float ax, float ay, float az, float sx,
                float sy, float sz)
{
    float t[16], r[16], sc[16];
    shp_mat_translate(t, tx, ty, tz);
    shp_mat_rotate(r, ang, ax, ay, az);
    shp_mat_scale(sc, sx, sy, sz);
    shp_mat_mul(r, r, sc);
    shp_mat_mul(m, t, r);
}

static void set_cam(scene *s, double ex, double ey, double ez, double ax, double ay, double az, float zn, float zf)
{
    s->eye[0] = ex;
    s->eye[1] = ey;
    s->eye[2] = ez;
    s->at[0] = ax;
    s->at[1] = ay;
    s->at[2] = az;
    s->fovy = 50.0f;
    s->znear = zn;
    s->zfar = zf;
}

/* which: 0 16 spheres, 1 concave tori, 2..5 shells k = 2, 4, 8, 16, 6 floor and
   pillars cutting volumes, 7 camera inside a volume; 8 64 spheres (--large only) */
#define NSCENES 8
static void build_scene(scene *s, int which)
{
    float m[16];
    int i, j, a;
    memset(s, 0, sizeof *s);
    if (which == 0) {
        strcpy(s->name, "16 spheres");
        set_cam(s, 0, 0.5, 9.5, 0, 0, 0, 0.5f, 30);
        a = add_mesh(s, shp_sphere(0.85f, 48, 24));
        for (i = 0; i < 4; ++i)
            for (j = 0; j < 4; ++j) {
                shp_mat_translate(m, -3.3f + 2.2f * (float)j, -2.4f + 1.6f * (float)i, -1.5f + 0.7f * (float)((i + j) % 4));
                add_inst(s, a, m, 0);
            }
    } else if (which == 1) {
        strcpy(s->name, "concave tori");
        set_cam(s, 0, 1.2, 7.5, 0, 0, 0, 0.5f, 30);
        a = add_mesh(s, shp_torus(1.7f, 0.55f, 96, 32));
        for (i = 0; i < 3; ++i) {
            trs(m, -1.6f + 1.6f * (float)i, 0, 0, i % 2 ? 90.0f : 20.0f, 1, 0.2f * (float)i, 0, 1, 1, 1);
            add_inst(s, a, m, 0);
        }
        a = add_mesh(s, shp_torus(1.2f, 0.45f, 96, 32));
        trs(m, 0, 1.6f, -1.0f, 60, 0, 1, 0.3f, 1, 1, 1);
        add_inst(s, a, m, 0);
    } else if (which >= 2 && which <= 5) {
        int k = 2 << (which - 2);
        shp_mesh all = shp_sphere(0.8f, 48, 24);
        s->k = k;
        snprintf(s->name, sizeof s->name, "shells k=%d", k);
        set_cam(s, 0, 0, 8.0, 0, 0, 0, 0.5f, 30);
        for (i = 1; i < k; ++i) { /* k nested spheres in one mesh: k back faces on the centre ray */
            shp_mesh one = shp_sphere(0.8f + 1.7f * (float)i / (float)(k - 1), 48, 24);
            if (!shp_append(&all, &one)) die("append");
            shp_free(&one);
        }
        a = add_mesh(s, all);
        shp_mat_identity(m);
        add_inst(s, a, m, 0);
    } else if (which == 6) {
        static const float pp[6][2] = {{-3, -1}, {0.3f, -2.2f}, {2.6f, 0.8f}, {-0.8f, 2.0f}, {3.5f, -3}, {-3.6f, 2.5f}};
        strcpy(s->name, "cut by floor+pillars");
        set_cam(s, 0.5, 4.0, 10.0, 0, -0.2, 0, 0.5f, 40);
        a = add_mesh(s, shp_box(14, 0.1f, 14));
        shp_mat_translate(m, 0, -1.1f, 0);
        add_inst(s, a, m, 1);
        a = add_mesh(s, shp_box(0.3f, 2.5f, 0.3f));
        for (i = 0; i < 6; ++i) {
            shp_mat_translate(m, pp[i][0], 1.0f, pp[i][1]);
            add_inst(s, a, m, 1);
        }
        a = add_mesh(s, shp_box(9, 0.8f, 9)); /* ground fog bank, half below the floor */
        shp_mat_translate(m, 0, -1.0f, 0);
        add_inst(s, a, m, 0);
        a = add_mesh(s, shp_sphere(1.4f, 64, 32));
        shp_mat_translate(m, -1.5f, -0.2f, 0.5f);
        add_inst(s, a, m, 0);
        a = add_mesh(s, shp_torus(1.4f, 0.5f, 96, 32));
        trs(m, 2.0f, 0.2f, -1.0f, 70, 1, 0, 0.2f, 1, 1, 1);
        add_inst(s, a, m, 0);
        a = add_mesh(s, shp_box(0.7f, 3.0f, 0.7f)); /* light beam through the floor */
        trs(m, 0.3f, 1.0f, 2.0f, 15, 0, 0, 1, 1, 1, 1);
        add_inst(s, a, m, 0);
    } else if (which == 8) { /* 4 x 4 x 4 spheres, each layer shifted: rays through up to 4 of them */
        strcpy(s->name, "64 spheres");
        set_cam(s, 0, 0.5, 10.0, 0, 0, 0, 0.5f, 30);
        a = add_mesh(s, shp_sphere(0.75f, 32, 16));
        for (i = 0; i < 64; ++i) {
            int x = i % 4, y = (i / 4) % 4, z = i / 16;
            shp_mat_translate(m, -2.7f + 1.6f * (float)x + 0.45f * (float)z, -2.2f + 1.3f * (float)y + 0.3f * (float)z,
                              1.5f - 1.4f * (float)z);
            add_inst(s, a, m, 0);
        }
    } else {
        strcpy(s->name, "camera inside a volume");
        set_cam(s, 0, 0.3, 0, 0.4, 0.1, -5, 0.3f, 40);
        a = add_mesh(s, shp_sphere(12.0f, 64, 32));
        shp_mat_identity(m);
        add_inst(s, a, m, 0);
        a = add_mesh(s, shp_box(6, 1.2f, 6)); /* a fog bank the camera stands in too */
        shp_mat_translate(m, 0, 0.0f, -2.0f);
        add_inst(s, a, m, 0);
        a = add_mesh(s, shp_sphere(1.2f, 48, 24));
        for (i = 0; i < 5; ++i) {
            shp_mat_translate(m, -4.0f + 2.0f * (float)i, 0.5f * (float)(i % 2), -6.0f - 1.5f * (float)(i % 3));
            add_inst(s, a, m, 0);
        }
    }
}

/* ---- per-resolution GL resources ---------------------------------------------- */
typedef struct rt {
    int w, h;
    GLuint eng_color, eng_depth, eng_fbo;   /* the engine framebuffer (colour + depth texture) */
    GLuint floor_tex, floor_fbo;            /* the floor's R32F sum */
    GLuint floor_rb, floor_occ_fbo;         /* the occluder floor: the same sum with a depth buffer */
    GLuint po_tex, po_rb, po_fbo;           /* peeling: opaque linear depth */
    GLuint pc[2], pz[2], pfbo[2];           /* peeling: ping-pong (sum, count) + depth */
    GLuint query;
} rt;

static void rt_create(rt *r, int w, int h)
{
    int i;
    memset(r, 0, sizeof *r);
    r->w = w;
    r->h = h;
    r->eng_color = tex2d(GL_RGBA8, w, h, GL_RGBA, GL_UNSIGNED_BYTE);
    r->eng_depth = tex2d(GL_DEPTH_COMPONENT24, w, h, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT);
    r->eng_fbo = fbo2(r->eng_color, r->eng_depth, 0);
    r->floor_tex = tex2d(GL_R32F, w, h, GL_RED, GL_FLOAT);
    r->floor_fbo = fbo2(r->floor_tex, 0, 0);
    glGenRenderbuffers(1, &r->floor_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, r->floor_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    r->floor_occ_fbo = fbo2(r->floor_tex, 0, r->floor_rb);
    r->po_tex = tex2d(GL_R32F, w, h, GL_RED, GL_FLOAT);
    glGenRenderbuffers(1, &r->po_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, r->po_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    r->po_fbo = fbo2(r->po_tex, 0, r->po_rb);
    for (i = 0; i < 2; ++i) {
        r->pc[i] = tex2d(GL_RG32F, w, h, GL_RG, GL_FLOAT);
        r->pz[i] = tex2d(GL_DEPTH_COMPONENT32F, w, h, GL_DEPTH_COMPONENT, GL_FLOAT);
        r->pfbo[i] = fbo2(r->pc[i], r->pz[i], 0);
    }
    glGenQueries(1, &r->query);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void rt_free(rt *r)
{
    GLuint t[9] = {r->eng_color, r->eng_depth, r->floor_tex, r->po_tex, r->pc[0], r->pc[1], r->pz[0], r->pz[1], 0};
    GLuint f[6] = {r->eng_fbo, r->floor_fbo, r->po_fbo, r->pfbo[0], r->pfbo[1], r->floor_occ_fbo};
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(6, f);
    glDeleteTextures(8, t);
    glDeleteRenderbuffers(1, &r->po_rb);
    glDeleteRenderbuffers(1, &r->floor_rb);
    glDeleteQueries(1, &r->query);
}

/* ---- drawing ------------------------------------------------------------------ */
typedef struct view {
    float v[16], p[16], vp[16];
    float nf[2]; /* view depth -> d in [0,1] between near and far */
} view;

static void make_view(view *vw, const scene *s, int w, int h)
{
    static const double up[3] = {0, 1, 0};
    glu_look_at(vw->v, s->eye, s->at, up);
    glu_perspective(vw->p, s->fovy, (double)w / h, s->znear, s->zfar);
    shp_mat_mul(vw->vp, vw->p, vw->v);
    vw->nf[0] = 1.0f / (s->zfar - s->znear);
    vw->nf[1] = -s->znear / (s->zfar - s->znear);
}

/* draw instances (occluders or volumes) with program prog (mvp, mv, nf, col uniforms) */
static void draw_insts(const scene *s, const view *vw, GLuint prog, int occluders)
{
    GLint u_mvp = glGetUniformLocation(prog, "mvp"), u_mv = glGetUniformLocation(prog, "mv");
    GLint u_col = glGetUniformLocation(prog, "col");
    int i;
    glUniform2fv(glGetUniformLocation(prog, "nf"), 1, vw->nf);
    for (i = 0; i < s->n; ++i) {
        const inst *in = &s->in[i];
        const gmesh *g = &s->mesh[in->mesh];
        float mv[16], mvp[16];
        if (in->occluder != occluders) continue;
        shp_mat_mul(mv, vw->v, in->model);
        shp_mat_mul(mvp, vw->p, mv);
        glUniformMatrix4fv(u_mvp, 1, GL_FALSE, mvp);
        glUniformMatrix4fv(u_mv, 1, GL_FALSE, mv);
        if (u_col >= 0) glUniform4f(u_col, in->col[0], in->col[1], in->col[2], 1.0f);
        glBindVertexArray(g->vao);
        glDrawElements(GL_TRIANGLES, g->m.icount, GL_UNSIGNED_INT, NULL);
    }
    glBindVertexArray(0);
}

/* The engine's opaque pass into its framebuffer; with mrt also O as colour attachment 1. */
static void engine_pass(const scene *s, const view *vw, const rt *r, const fogvol_mrt_info *mrt)
{
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    static const float bg[4] = {0.2f, 0.35f, 0.55f, 1.0f};
    GLuint prog = mrt ? P.engine_mrt : P.engine;
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo);
    if (mrt) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, (GLuint)mrt->texture, 0);
    glDrawBuffers(mrt ? 2 : 1, bufs);
    glViewport(0, 0, r->w, r->h);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_TRUE);
    glClearBufferfv(GL_COLOR, 0, bg);
    if (mrt) glClearBufferfv(GL_COLOR, 1, mrt->clear_color);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(prog);
    if (mrt) glUniform4fv(glGetUniformLocation(prog, "fogvol_mrt"), 2, mrt->uniforms);
    draw_insts(s, vw, prog, 1);
    glDisable(GL_DEPTH_TEST);
    if (mrt) {
        glDrawBuffers(1, bufs); /* fogvol composites into attachment 0 only */
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
    }
    glUseProgram(0);
}

/* Pass timer: the GL backend's table with begin_pass/end_pass wrapped; when
   on, every fogvol pass is bracketed by glFinish and timed (the breakdown). */
#define MAXPASS 12
typedef struct pass_timer {
    void (*begin_pass)(void *, const fogvol_pass *);
    void (*end_pass)(void *);
    int on, pass;
    tick t0;
    double ms[MAXPASS], engine_ms;
} pass_timer;
static pass_timer g_pt;

static void pt_begin_pass(void *u, const fogvol_pass *p)
{
    if (g_pt.on) g_pt.t0 = tick_start();
    g_pt.begin_pass(u, p);
}

static void pt_end_pass(void *u)
{
    if (g_pt.end_pass) g_pt.end_pass(u);
    if (g_pt.on && g_pt.pass < MAXPASS) g_pt.ms[g_pt.pass++] = tick_ms(g_pt.t0, tick_end());
}

typedef struct fogs {
    fogvol_context *ctx[NTIER];
    fogvol_ramp *ramp[NTIER];
    fogvol_backend be[NTIER];
} fogs;

/* One fogvol frame of tier t; the engine framebuffer holds the opaque scene
   (MRT: the engine pass runs inside, after fogvol_mrt_prepare). */
static fogvol_result fog_frame(fogs *F, int t, const scene *s, const view *vw, const rt *r, float *debug,
                               fogvol_frame_stats *st)
{
    fogvol_context *c = F->ctx[t];
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_result res;
    int i, mrt = g_tiers[t].tier == FOGVOL_TIER_MRT, ed = (g_tiers[t].variants & FOGVOL_VARIANT_ENGINE_DEPTH) != 0;
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, vw->v, sizeof fd.view);
    memcpy(fd.projection, vw->p, sizeof fd.projection);
    fd.znear = s->znear;
    fd.zfar = s->zfar;
    fd.viewport[2] = r->w;
    fd.viewport[3] = r->h;
    fd.debug_thickness = debug;
    fd.downsample = g_tiers[t].downsample;
    fd.engine_depth_texture = ed ? r->eng_depth : 0;
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo);
    if ((res = fogvol_begin_frame(c, &fd)) != FOGVOL_SUCCESS) return res;
    if (mrt) {
        fogvol_mrt_info mi;
        tick t0;
        if ((res = fogvol_mrt_prepare(c, &mi)) != FOGVOL_SUCCESS) return res;
        if (g_pt.on) t0 = tick_start();
        engine_pass(s, vw, r, &mi);
        if (g_pt.on) g_pt.engine_ms = tick_ms(t0, tick_end());
    }
    memset(&vd, 0, sizeof vd);
    vd.ramp = F->ramp[t];
    for (i = 0; i < s->n; ++i) {
        const inst *in = &s->in[i];
        if (in->occluder) {
            if (!mrt && !ed) fogvol_add_occluder(c, s->mesh[in->mesh].fm[t], in->model);
            continue;
        }
        vd.mesh = s->mesh[in->mesh].fm[t];
        memcpy(vd.model, in->model, sizeof vd.model);
        fogvol_add_volume(c, &vd);
    }
    return fogvol_end_frame(c, st);
}

/* The window rectangle holding the volumes' bounding boxes projected (the whole viewport when a
   corner lies behind the near plane), for the scissored floor. */
static void vol_rect(const scene *s, const view *vw, int w, int h, int rect[4])
{
    double lo[2] = {1e30, 1e30}, hi[2] = {-1e30, -1e30};
    int i, k, c;
    rect[0] = rect[1] = 0;
    rect[2] = w;
    rect[3] = h;
    for (i = 0; i < s->n; ++i) {
        const inst *in = &s->in[i];
        const gmesh *g = &s->mesh[in->mesh];
        float mvp[16];
        if (in->occluder) continue;
        shp_mat_mul(mvp, vw->vp, in->model);
        for (k = 0; k < 8; ++k) {
            double p[3], cl[4];
            for (c = 0; c < 3; ++c) p[c] = (k >> c & 1) ? g->bmax[c] : g->bmin[c];
            for (c = 0; c < 4; ++c) cl[c] = mvp[c] * p[0] + mvp[4 + c] * p[1] + mvp[8 + c] * p[2] + mvp[12 + c];
            if (cl[3] < s->znear * 0.999) return;
            for (c = 0; c < 2; ++c) {
                double win = (cl[c] / cl[3] * 0.5 + 0.5) * (c ? h : w);
                if (win < lo[c]) lo[c] = win;
                if (win > hi[c]) hi[c] = win;
            }
        }
    }
    for (c = 0; c < 2; ++c) {
        double a = floor(lo[c]) - 1, b = floor(hi[c]) + 2, lim = c ? h : w;
        if (a < 0) a = 0;
        if (b > lim) b = lim;
        rect[c] = (int)a;
        rect[c + 2] = b > a ? (int)(b - a) : 1;
    }
}

/* The floor: volume triangles once, constant colour, additive, + one full-screen composite.
   mode 1 (occluder floor): the occluders first, depth only, and the volume triangles depth-tested
   against them; mode 2 (scissored floor): the composite scissored to the volumes' rectangle. */
static void floor_frame(const scene *s, const view *vw, const rt *r, int mode)
{
    glBindFramebuffer(GL_FRAMEBUFFER, mode == 1 ? r->floor_occ_fbo : r->floor_fbo);
    glViewport(0, 0, r->w, r->h);
    glClearColor(0, 0, 0, 0);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(mode == 1 ? GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT : GL_COLOR_BUFFER_BIT);
    glDisable(GL_CULL_FACE);
    glUseProgram(P.cnst);
    if (mode == 1) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        draw_insts(s, vw, P.cnst, 1);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glDepthMask(GL_FALSE);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    draw_insts(s, vw, P.cnst, 0);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    if (mode == 2) {
        int rc[4];
        vol_rect(s, vw, r->w, r->h, rc);
        glEnable(GL_SCISSOR_TEST);
        glScissor(rc[0], rc[1], rc[2], rc[3]);
    }
    if (g_pt.on) {
        g_pt.ms[g_pt.pass] = tick_ms(g_pt.t0, tick_end());
        g_pt.pass++;
        g_pt.t0 = tick_start();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(P.floor_comp);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->floor_tex);
    glUniform1i(glGetUniformLocation(P.floor_comp, "s"), 0);
    glBindVertexArray(P.empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glUseProgram(0);
    if (g_pt.on) g_pt.ms[g_pt.pass++] = tick_ms(g_pt.t0, tick_end());
}

static void bind_tex(int unit, GLuint t)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    glBindTexture(GL_TEXTURE_2D, t);
}

/* Depth peeling; returns the number of layers found. known = 0: an occlusion query after every
   layer finds the count (geometry passes = layers + 1); known > 0: exactly that many layers, no
   query (the timed frames, once the debug frame found the count). */
static int peel_frame(const scene *s, const view *vw, const rt *r, int known)
{
    static const float zero[4] = {0, 0, 0, 0};
    GLint u_first = glGetUniformLocation(P.peel, "first");
    int k;
    /* opaque pre-pass: linear depth d of the nearest opaque surface (1 = none) */
    glBindFramebuffer(GL_FRAMEBUFFER, r->po_fbo);
    glViewport(0, 0, r->w, r->h);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glClearColor(1, 1, 1, 1);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(P.lindepth);
    draw_insts(s, vw, P.lindepth, 1);
    /* layers */
    glBindFramebuffer(GL_FRAMEBUFFER, r->pfbo[0]);
    glClearBufferfv(GL_COLOR, 0, zero);
    glBindFramebuffer(GL_FRAMEBUFFER, r->pfbo[1]);
    glClearBufferfv(GL_COLOR, 0, zero);
    glUseProgram(P.peel);
    glUniform1i(glGetUniformLocation(P.peel, "prevc"), 0);
    glUniform1i(glGetUniformLocation(P.peel, "prevz"), 1);
    glUniform1i(glGetUniformLocation(P.peel, "opq"), 2);
    glUniform1f(glGetUniformLocation(P.peel, "eps"), 1e-7f);
    bind_tex(2, r->po_tex);
    for (k = 0; k < (known > 0 ? known : MAXLAYERS); ++k) {
        GLuint any = 0;
        glBindFramebuffer(GL_FRAMEBUFFER, r->pfbo[k & 1]);
        glClear(GL_DEPTH_BUFFER_BIT); /* a fresh depth buffer per layer */
        bind_tex(0, r->pc[(k + 1) & 1]);
        bind_tex(1, r->pz[(k + 1) & 1]);
        glUniform1f(u_first, k == 0 ? 1.0f : 0.0f);
        if (known > 0) {
            draw_insts(s, vw, P.peel, 0);
            continue;
        }
        glBeginQuery(GL_ANY_SAMPLES_PASSED, r->query);
        draw_insts(s, vw, P.peel, 0);
        glEndQuery(GL_ANY_SAMPLES_PASSED);
        glGetQueryObjectuiv(r->query, GL_QUERY_RESULT, &any);
        if (!any) break;
    }
    glDisable(GL_DEPTH_TEST);
    bind_tex(0, 0);
    bind_tex(1, 0);
    bind_tex(2, 0);
    /* composite: the target with the higher layer count holds the whole sum */
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(P.peel_comp);
    glUniform1i(glGetUniformLocation(P.peel_comp, "a"), 0);
    glUniform1i(glGetUniformLocation(P.peel_comp, "b"), 1);
    glUniform4f(glGetUniformLocation(P.peel_comp, "fog"), 0.8f, 0.8f, 0.8f, 0.5f);
    glUniform1f(glGetUniformLocation(P.peel_comp, "range"), s->zfar - s->znear);
    bind_tex(0, r->pc[0]);
    bind_tex(1, r->pc[1]);
    glBindVertexArray(P.empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    bind_tex(0, 0);
    bind_tex(1, 0);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND);
    glUseProgram(0);
    return k;
}

/* peeled thickness (world units) and layer count per pixel, rows bottom to top */
static void peel_read(const scene *s, const rt *r, float *thick, int *count)
{
    size_t n = (size_t)r->w * r->h, i;
    float *a = (float *)malloc(n * 2 * sizeof(float)), *b = (float *)malloc(n * 2 * sizeof(float));
    if (!a || !b) die("out of memory");
    glBindFramebuffer(GL_FRAMEBUFFER, r->pfbo[0]);
    glReadPixels(0, 0, r->w, r->h, GL_RG, GL_FLOAT, a);
    glBindFramebuffer(GL_FRAMEBUFFER, r->pfbo[1]);
    glReadPixels(0, 0, r->w, r->h, GL_RG, GL_FLOAT, b);
    for (i = 0; i < n; ++i) {
        const float *x = a[2 * i + 1] > b[2 * i + 1] ? a + 2 * i : b + 2 * i;
        thick[i] = x[0] * (s->zfar - s->znear);
        count[i] = (int)(x[1] + 0.5f);
    }
    free(a);
    free(b);
}

/* ---- uploading a scene ----------------------------------------------------------- */
/* a mesh's vertex array for the engine's and the references' draws */
static void gmesh_upload(gmesh *g)
{
    glGenVertexArrays(1, &g->vao);
    glBindVertexArray(g->vao);
    glGenBuffers(1, &g->vbo);
    glGenBuffers(1, &g->ibo);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(12 * (size_t)g->m.vcount), g->m.pos, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, NULL);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(4 * (size_t)g->m.icount), g->m.idx, GL_STATIC_DRAW);
    glBindVertexArray(0);
}

static void scene_upload(scene *s, fogs *F)
{
    int i, t;
    for (i = 0; i < s->nmesh; ++i) {
        gmesh *g = &s->mesh[i];
        int occ = 0, j;
        fogvol_mesh_desc md;
        for (j = 0; j < s->n; ++j) occ |= s->in[j].mesh == i && s->in[j].occluder;
        for (j = 0; j < 3; ++j) g->bmin[j] = 1e30f, g->bmax[j] = -1e30f;
        for (j = 0; j < 3 * g->m.vcount; ++j) {
            if (g->m.pos[j] < g->bmin[j % 3]) g->bmin[j % 3] = g->m.pos[j];
            if (g->m.pos[j] > g->bmax[j % 3]) g->bmax[j % 3] = g->m.pos[j];
        }
        gmesh_upload(g);
        memset(&md, 0, sizeof md);
        md.positions = g->m.pos;
        md.vertex_count = g->m.vcount;
        md.indices = (const uint32_t *)g->m.idx;
        md.index_count = g->m.icount;
        md.allow_open = occ;
        for (t = 0; t < NTIER; ++t)
            if (fogvol_create_mesh(F->ctx[t], &md, &g->fm[t], NULL) != FOGVOL_SUCCESS) die("fogvol_create_mesh");
    }
}

static void scene_free(scene *s, fogs *F)
{
    int i, t;
    for (i = 0; i < s->nmesh; ++i) {
        gmesh *g = &s->mesh[i];
        for (t = 0; t < NTIER; ++t) fogvol_destroy_mesh(F->ctx[t], g->fm[t]);
        glDeleteVertexArrays(1, &g->vao);
        glDeleteBuffers(1, &g->vbo);
        glDeleteBuffers(1, &g->ibo);
        shp_free(&g->m);
    }
}

/* ---- results ------------------------------------------------------------------- */
typedef struct result {
    char scene[48];
    int w, h, k, triangles;
    double ms[NMETH];      /* median fog ms per frame */
    double first_ms[NMETH];/* first frame (the driver compiles shaders on first use) */
    int passes[NMETH];
    int layers;            /* peeling */
    long fogged;           /* pixels with nonzero thickness */
    double dmax[NTIER], dmean[NTIER]; /* vs peeling: LSB (RGBA8) or world units (FLOAT) */
    long dn[NTIER];
    int overflow[NTIER];
    int frames;
    /* breakdown (glFinish around every pass; medians): per-pass ms, whole frame, plain engine pass */
    int occluders;         /* occluder instances in the scene */
    int bd, bd_np[NMETH];
    double bd_ms[NMETH][MAXPASS], bd_frame[NMETH], engine_ms, bd_engine_mrt;
    double cpu_us[NTIER]; /* fogvol_begin_frame .. fogvol_end_frame on the null backend */
} result;

static result g_res[2 * MAXSCENE];
static int g_nres;

/* compare fogvol's debug thickness with the peeled one over non-silhouette pixels */
static void compare(const rt *r, const float *fv, const float *pt, const int *pc, double unit, double *dmax,
                    double *dmean, long *dn)
{
    int x, y, dx, dy;
    double sum = 0, mx = 0;
    long n = 0;
    for (y = 1; y < r->h - 1; ++y)
        for (x = 1; x < r->w - 1; ++x) {
            int i = y * r->w + x, same = 1;
            double e;
            if (fv[i] == 0.0f || pt[i] == 0.0f) continue;
            for (dy = -1; dy <= 1 && same; ++dy)
                for (dx = -1; dx <= 1; ++dx) same &= pc[i + dy * r->w + dx] == pc[i];
            if (!same) continue;
            e = fabs((double)fv[i] - pt[i]) / unit;
            sum += e;
            if (e > mx) mx = e;
            ++n;
        }
    *dmax = mx;
    *dmean = n ? sum / n : 0;
    *dn = n;
}

/* fogvol's own CPU cost per frame: the same frame on the recording null backend */
static fogvol_native null_native(void *u, fogvol_handle h)
{
    (void)u;
    return (fogvol_native)h;
}

static double null_frame_us(const scene *s, int t, int w, int h)
{
    enum { NR = 41 };
    fogvol_null_backend nb;
    fogvol_context_desc cd;
    fogvol_context *c;
    fogvol_mesh *fm[MAXMESH];
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_mrt_info mi;
    view vw;
    double v[NR];
    int i, rep;
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(&nb, &cd.backend);
    cd.backend.caps |= FOGVOL_CAP_FLOAT_BLEND;
    cd.backend.native_texture = null_native;
    cd.tier = g_tiers[t].tier;
    cd.variants = g_tiers[t].variants;
    cd.engine_mrt = 1;
    if (fogvol_create_context(&cd, &c) != FOGVOL_SUCCESS) die("null context");
    for (i = 0; i < s->nmesh; ++i) {
        fogvol_mesh_desc md;
        memset(&md, 0, sizeof md);
        md.positions = s->mesh[i].m.pos;
        md.vertex_count = s->mesh[i].m.vcount;
        md.indices = (const uint32_t *)s->mesh[i].m.idx;
        md.index_count = s->mesh[i].m.icount;
        md.allow_open = 1;
        if (fogvol_create_mesh(c, &md, &fm[i], NULL) != FOGVOL_SUCCESS) die("null mesh");
    }
    memset(&rd, 0, sizeof rd);
    rd.density = 0.5f;
    if (fogvol_create_ramp(c, &rd, &ramp) != FOGVOL_SUCCESS) die("null ramp");
    make_view(&vw, s, w, h);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, vw.v, sizeof fd.view);
    memcpy(fd.projection, vw.p, sizeof fd.projection);
    fd.znear = s->znear;
    fd.zfar = s->zfar;
    fd.viewport[2] = w;
    fd.viewport[3] = h;
    fd.engine_depth_texture = 1;
    memset(&vd, 0, sizeof vd);
    vd.ramp = ramp;
    for (rep = 0; rep < NR; ++rep) {
        double t0 = now_ms();
        fogvol_begin_frame(c, &fd);
        if (g_tiers[t].tier == FOGVOL_TIER_MRT) fogvol_mrt_prepare(c, &mi);
        for (i = 0; i < s->n; ++i) {
            if (s->in[i].occluder) {
                fogvol_add_occluder(c, fm[s->in[i].mesh], s->in[i].model);
                continue;
            }
            vd.mesh = fm[s->in[i].mesh];
            memcpy(vd.model, s->in[i].model, sizeof vd.model);
            fogvol_add_volume(c, &vd);
        }
        if (fogvol_end_frame(c, NULL) != FOGVOL_SUCCESS) die("null frame");
        v[rep] = (now_ms() - t0) * 1e3;
    }
    for (i = 0; i < s->nmesh; ++i) fogvol_destroy_mesh(c, fm[i]);
    fogvol_destroy_ramp(c, ramp);
    fogvol_destroy_context(c);
    return median(v, NR);
}

/* ---- one scene at one resolution ------------------------------------------------- */
/* One frame of a reference method (a floor or the peeling); returns its passes. */
static int ref_frame(int m, const scene *s, const view *vw, const rt *r, int layers)
{
    if (m == M_PEEL) return 1 + peel_frame(s, vw, r, layers) + 1;
    floor_frame(s, vw, r, m == M_OCCFLOOR ? 1 : m == M_SCFLOOR ? 2 : 0);
    return 2;
}

static void run_scene(fogs *F, scene *s, int w, int h, int warm, int frames, result *res)
{
    rt r;
    view vw;
    double t[NMETH][512], te[512];
    int ne = 0, it, mi, i, nt[NMETH];
    size_t npx = (size_t)w * h;
    float *dbg[NTIER], *pt = (float *)malloc(npx * sizeof(float));
    int *pc = (int *)malloc(npx * sizeof(int));
    fogvol_frame_stats st;
    if (frames > 512) frames = 512;
    i = res->bd;
    memset(res, 0, sizeof *res);
    res->bd = i;
    memset(nt, 0, sizeof nt);
    snprintf(res->scene, sizeof res->scene, "%s", s->name);
    res->w = w;
    res->h = h;
    res->k = s->k;
    res->occluders = s->occluders;
    res->triangles = s->triangles;
    res->frames = frames;
    rt_create(&r, w, h);
    make_view(&vw, s, w, h);
    for (i = 0; i < NTIER; ++i) res->cpu_us[i] = null_frame_us(s, i, w, h);

    /* first frame of every method (drivers compile shader variants on first use: llvmpipe JITs them) */
    for (i = 0; i < NMETH; ++i) {
        double t0;
        if (i >= NTIER || g_tiers[i].tier != FOGVOL_TIER_MRT) engine_pass(s, &vw, &r, NULL);
        glFinish();
        t0 = now_ms();
        if (i < NTIER) fog_frame(F, i, s, &vw, &r, NULL, &st);
        else ref_frame(i, s, &vw, &r, 0);
        glFinish();
        res->first_ms[i] = now_ms() - t0;
    }

    /* debug frames: thickness of every tier and of the peeling, fogged pixels */
    for (i = 0; i < NTIER; ++i) {
        fogvol_result fr;
        dbg[i] = (float *)calloc(npx, sizeof(float));
        if (!dbg[i]) die("out of memory");
        if (g_tiers[i].tier != FOGVOL_TIER_MRT) engine_pass(s, &vw, &r, NULL);
        fr = fog_frame(F, i, s, &vw, &r, dbg[i], &st);
        if (fr != FOGVOL_SUCCESS && fr != FOGVOL_ERROR_DEPTH_OVERFLOW) die(fogvol_result_string(fr));
        res->overflow[i] = st.overflow_pixels;
    }
    engine_pass(s, &vw, &r, NULL);
    res->layers = peel_frame(s, &vw, &r, 0);
    peel_read(s, &r, pt, pc);
    for (i = 0; i < (int)npx; ++i) res->fogged += dbg[3][i] != 0.0f;
    for (i = 0; i < NTIER; ++i) {
        double unit;
        if (g_tiers[i].tier == FOGVOL_TIER_FLOAT) {
            unit = 1.0;
        } else {
            fogvol_constants k;
            fogvol_compute_constants(fogvol_context_encoding(F->ctx[i]), s->znear, s->zfar, 0.0f, &k);
            unit = k.lsb;
        }
        compare(&r, dbg[i], pt, pc, unit, &res->dmax[i], &res->dmean[i], &res->dn[i]);
        free(dbg[i]);
    }

    /* timed frames, interleaved: every iteration runs every method once, in rotating order */
    for (it = 0; it < warm + frames; ++it) {
        for (mi = 0; mi < NMETH; ++mi) {
            int m = (mi + it) % NMETH, mrt = m < NTIER && g_tiers[m].tier == FOGVOL_TIER_MRT;
            tick t0, e0, e1;
            int passes = 0;
            if (!mrt) {
                e0 = tick_start();
                engine_pass(s, &vw, &r, NULL);
                e1 = tick_end();
            }
            t0 = tick_start();
            if (m < NTIER) {
                fogvol_result fr = fog_frame(F, m, s, &vw, &r, NULL, &st);
                if (fr != FOGVOL_SUCCESS) die(fogvol_result_string(fr));
                passes = st.passes;
            } else {
                passes = ref_frame(m, s, &vw, &r, res->layers);
            }
            res->passes[m] = passes;
            if (it >= warm) {
                t[m][nt[m]++] = tick_ms(t0, tick_end());
                if (!mrt) te[ne++] = tick_ms(e0, e1);
            }
        }
    }
    {
        double eng = median(te, ne);
        int m;
        for (m = 0; m < NMETH; ++m) {
            if (m < NTIER && g_tiers[m].tier == FOGVOL_TIER_MRT) /* the engine pass writes O: count what it adds */
                for (i = 0; i < nt[m]; ++i) t[m][i] -= eng;
            res->ms[m] = median(t[m], nt[m]);
        }
    }
    if (res->bd) { /* where the time goes: every pass bracketed by glFinish */
        enum { NB = 7 };
        double bt[NMETH][MAXPASS][NB], bf[NMETH][NB], be[NB];
        int m, b, p;
        res->engine_ms = median(te, ne);
        for (b = 0; b < NB; ++b)
            for (m = 0; m <= M_FLOOR; ++m) {
                tick t0;
                if (m >= NTIER || g_tiers[m].tier != FOGVOL_TIER_MRT) engine_pass(s, &vw, &r, NULL);
                memset(g_pt.ms, 0, sizeof g_pt.ms);
                g_pt.pass = 0;
                g_pt.on = 1;
                t0 = g_pt.t0 = tick_start();
                if (m < NTIER) fog_frame(F, m, s, &vw, &r, NULL, &st);
                else floor_frame(s, &vw, &r, 0);
                bf[m][b] = tick_ms(t0, tick_end());
                g_pt.on = 0;
                res->bd_np[m] = g_pt.pass;
                for (p = 0; p < MAXPASS; ++p) bt[m][p][b] = g_pt.ms[p];
                if (m < NTIER && g_tiers[m].tier == FOGVOL_TIER_MRT) be[b] = g_pt.engine_ms;
            }
        for (m = 0; m <= M_FLOOR; ++m) {
            res->bd_frame[m] = median(bf[m], NB);
            for (p = 0; p < MAXPASS; ++p) res->bd_ms[m][p] = median(bt[m][p], NB);
        }
        res->bd_engine_mrt = median(be, NB);
    }
    if (glGetError() != GL_NO_ERROR) die("GL error");
    rt_free(&r);
    free(pt);
    free(pc);
}

/* ---- CPU figures ------------------------------------------------------------------ */
typedef struct cpu_figs {
    double rg_us, blue_us, color_us;
    int rg_w, rg_h, blue_w, blue_h, color_w;
    double validate_ms, validate_mtris;
    int validate_tris;
    double create_ms[NTIER];
} cpu_figs;

static double time_ramp(int which, const fogvol_encoding *e, unsigned char *buf, size_t cap, int reps,
                        fogvol_image *info)
{
    double v[15];
    int r, i;
    fogvol_ramp_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
    rd.density = 0.5f;
    for (r = 0; r < 15; ++r) {
        double t0 = now_ms();
        for (i = 0; i < reps; ++i) {
            fogvol_result fr = which == 0   ? fogvol_make_rg_ramp(e, buf, cap, info)
                               : which == 1 ? fogvol_make_blue_ramp(e, buf, cap, info)
                                            : fogvol_make_color_ramp(&rd, buf, cap, info, NULL);
            if (fr != FOGVOL_SUCCESS) die("ramp");
        }
        v[r] = (now_ms() - t0) * 1e3 / reps;
    }
    return median(v, 15);
}

static void cpu_measure(cpu_figs *c, int quick)
{
    fogvol_encoding e;
    fogvol_image info;
    static unsigned char buf[1 << 20];
    shp_mesh big = quick ? shp_sphere(1.0f, 128, 64) : shp_sphere(1.0f, 512, 256);
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    double v[7];
    int i, reps = quick ? 3 : 7;
    fogvol_encoding_init(FOGVOL_DEFAULT_BITS, &e);
    c->rg_us = time_ramp(0, &e, buf, sizeof buf, 200, &info);
    c->rg_w = info.width;
    c->rg_h = info.height;
    c->blue_us = time_ramp(1, &e, buf, sizeof buf, 50, &info);
    c->blue_w = info.width;
    c->blue_h = info.height;
    c->color_us = time_ramp(2, &e, buf, sizeof buf, 200, &info);
    c->color_w = info.width;
    memset(&md, 0, sizeof md);
    md.positions = big.pos;
    md.vertex_count = big.vcount;
    md.indices = (const uint32_t *)big.idx;
    md.index_count = big.icount;
    for (i = 0; i < reps; ++i) {
        double t0 = now_ms();
        if (fogvol_validate_mesh(&md, NULL, &rep) != FOGVOL_SUCCESS) die("validate");
        v[i] = now_ms() - t0;
    }
    c->validate_tris = big.icount / 3;
    c->validate_ms = median(v, reps);
    c->validate_mtris = c->validate_tris / c->validate_ms / 1e3;
    shp_free(&big);
}

/* ---- scale and lifetime: fogvol's CPU work at large counts, on the recording null backend ------ */
typedef struct scale_figs {
    int ramps;                 /* end_frame of a frame with one volume per ramp */
    double ramps_ms;
    int ramps_passes;
    int colors;                /* end_frame, FOGVOL_VARIANT_COLORS + the GEOMETRY composite, one ramp */
    double colors_ms;
    int weld_n, weld_v, weld_kept; /* per-face subdivided cube: n x n quads a face, 6 (n+1)^2 vertices */
    double weld_ms, weld_total_ms; /* the weld alone (fogvol__weld); fogvol_validate_mesh with the weld */
    int life_n;                /* live meshes, ramps and volume textures each at fogvol_destroy_context */
    long life_host;            /* allocations of the context's allocator still live after it */
    int life_gpu;              /* backend objects created and never destroyed */
    double life_ms;
} scale_figs;

typedef struct scale_alloc {
    long live;
} scale_alloc;

static void *scale_alloc_fn(size_t size, void *u)
{
    void *p = malloc(size);
    if (p) ((scale_alloc *)u)->live++;
    return p;
}

static void scale_free_fn(void *p, void *u)
{
    ((scale_alloc *)u)->live--;
    free(p);
}

static fogvol_context *scale_context(fogvol_null_backend *nb, fogvol_tier tier, unsigned variants, scale_alloc *a)
{
    fogvol_context_desc cd;
    fogvol_context *c = NULL;
    memset(&cd, 0, sizeof cd);
    fogvol_null_backend_init(nb, &cd.backend);
    cd.backend.caps |= FOGVOL_CAP_FLOAT_BLEND;
    cd.tier = tier;
    cd.variants = variants;
    if (a) {
        cd.allocator.alloc = scale_alloc_fn;
        cd.allocator.free = scale_free_fn;
        cd.allocator.user_data = a;
    }
    if (fogvol_create_context(&cd, &c) != FOGVOL_SUCCESS) die("fogvol_create_context (null backend)");
    return c;
}

static void scale_frame_desc(fogvol_frame_desc *fd, int composite)
{
    double eye[3] = {0, 0, 30}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    memset(fd, 0, sizeof *fd);
    glu_look_at(fd->view, eye, at, up);
    glu_perspective(fd->projection, 60.0, 16.0 / 9.0, 0.5, 100.0);
    fd->znear = 0.5f;
    fd->zfar = 100.0f;
    fd->viewport[2] = 1280;
    fd->viewport[3] = 720;
    fd->composite = (fogvol_composite)composite;
}

/* n volumes (boxes on a grid in front of the camera), each with its own ramp (per_ramp) or all
   with one; the time of fogvol_end_frame alone, median of reps */
static double scale_end_frame(fogvol_context *c, fogvol_mesh *mesh, fogvol_ramp **ramps, int n, int per_ramp,
                              int composite, int reps, int *passes)
{
    double v[9];
    int r, i, side = (int)ceil(sqrt((double)n));
    for (r = 0; r < reps; ++r) {
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        double t0;
        scale_frame_desc(&fd, composite);
        if (fogvol_begin_frame(c, &fd) != FOGVOL_SUCCESS) die("begin_frame (scale)");
        for (i = 0; i < n; ++i) {
            fogvol_volume_desc vd;
            memset(&vd, 0, sizeof vd);
            vd.mesh = mesh;
            vd.ramp = ramps[per_ramp ? i : 0];
            trs(vd.model, 20.0f * ((float)(i % side) / side - 0.5f), 12.0f * ((float)(i / side) / side - 0.5f), 0.0f,
                0, 0, 1, 0, 0.02f, 0.02f, 0.02f);
            if (fogvol_add_volume(c, &vd) != FOGVOL_SUCCESS) die("add_volume (scale)");
        }
        t0 = now_ms();
        if (fogvol_end_frame(c, &st) != FOGVOL_SUCCESS) die("end_frame (scale)");
        v[r] = now_ms() - t0;
        *passes = st.passes;
    }
    return median(v, reps);
}

static void scale_ramp_desc(fogvol_ramp_desc *rd, int i)
{
    memset(rd, 0, sizeof *rd);
    rd->color[0] = (float)(i % 7) / 6.0f;
    rd->color[1] = 0.5f;
    rd->color[2] = 0.8f;
    rd->density = 0.5f + 0.001f * (float)(i % 1000);
    rd->width = 16;
}

static void scale_frames(scale_figs *s, int quick)
{
    fogvol_null_backend nb;
    fogvol_context *c;
    fogvol_mesh *mesh;
    fogvol_ramp **ramps;
    fogvol_mesh_desc md;
    shp_mesh box = shp_box(1.0f, 1.0f, 1.0f);
    int i, p;
    s->ramps = quick ? 2000 : 20000;
    s->colors = quick ? 1000 : 10000;
    ramps = (fogvol_ramp **)malloc(sizeof *ramps * (size_t)s->ramps);
    if (!ramps) die("out of memory");
    memset(&md, 0, sizeof md);
    md.positions = box.pos;
    md.vertex_count = box.vcount;
    md.indices = box.idx;
    md.index_count = box.icount;
    c = scale_context(&nb, FOGVOL_TIER_PS20, 0, NULL);
    if (fogvol_create_mesh(c, &md, &mesh, NULL) != FOGVOL_SUCCESS) die("mesh (scale)");
    for (i = 0; i < s->ramps; ++i) {
        fogvol_ramp_desc rd;
        scale_ramp_desc(&rd, i);
        if (fogvol_create_ramp(c, &rd, &ramps[i]) != FOGVOL_SUCCESS) die("ramp (scale)");
    }
    s->ramps_ms = scale_end_frame(c, mesh, ramps, s->ramps, 1, FOGVOL_COMPOSITE_FULLSCREEN, quick ? 1 : 3,
                                  &s->ramps_passes);
    for (i = 0; i < s->ramps; ++i) fogvol_destroy_ramp(c, ramps[i]);
    fogvol_destroy_mesh(c, mesh);
    fogvol_destroy_context(c);
    c = scale_context(&nb, FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, NULL);
    if (fogvol_create_mesh(c, &md, &mesh, NULL) != FOGVOL_SUCCESS) die("mesh (scale, colours)");
    {
        fogvol_ramp_desc rd;
        scale_ramp_desc(&rd, 0);
        if (fogvol_create_ramp(c, &rd, &ramps[0]) != FOGVOL_SUCCESS) die("ramp (scale, colours)");
    }
    s->colors_ms = scale_end_frame(c, mesh, ramps, s->colors, 0, FOGVOL_COMPOSITE_GEOMETRY, quick ? 1 : 3, &p);
    fogvol_destroy_ramp(c, ramps[0]);
    fogvol_destroy_mesh(c, mesh);
    fogvol_destroy_context(c);
    free(ramps);
    shp_free(&box);
}

/* the weld of a per-face subdivided cube (6 x 257^2 vertices at 1e-5): alone (fogvol__weld, the
   implementation is in this file), and inside
   fogvol_validate_mesh (weld + the checks of the welded mesh) */
static void scale_weld(scale_figs *s, int quick)
{
    shp_mesh m;
    fogvol_mesh_desc md;
    fogvol_mesh_report rep;
    uint32_t *rep_idx;
    double t0;
    s->weld_n = quick ? 64 : 256;
    m = shp_cube_faces(1.0f, s->weld_n);
    s->weld_v = m.vcount;
    rep_idx = (uint32_t *)malloc(sizeof *rep_idx * (size_t)m.vcount);
    if (!m.pos || !rep_idx) die("out of memory");
    t0 = now_ms();
    s->weld_kept = m.vcount - fogvol__weld((const unsigned char *)m.pos, 12, m.vcount, 1e-5f, NULL, rep_idx);
    s->weld_ms = now_ms() - t0;
    memset(&md, 0, sizeof md);
    md.positions = m.pos;
    md.vertex_count = m.vcount;
    md.indices = m.idx;
    md.index_count = m.icount;
    md.weld_distance = 1e-5f;
    t0 = now_ms();
    if (fogvol_validate_mesh(&md, NULL, &rep) != FOGVOL_SUCCESS) die("validate (weld)");
    s->weld_total_ms = now_ms() - t0;
    if (rep.vertices != s->weld_kept) die("weld: the validation welded another count");
    free(rep_idx);
    shp_free(&m);
}

/* fogvol_destroy_context with n live meshes, ramps and volume textures the caller forgot */
static void scale_lifetime(scale_figs *s, int quick)
{
    fogvol_null_backend nb;
    scale_alloc a;
    fogvol_context *c;
    fogvol_mesh_desc md;
    fogvol_texture_desc td;
    shp_mesh box = shp_box(1.0f, 1.0f, 1.0f);
    unsigned char px[4] = {255, 255, 255, 255};
    int i;
    double t0;
    s->life_n = quick ? 100 : 1000;
    memset(&a, 0, sizeof a);
    c = scale_context(&nb, FOGVOL_TIER_PS20, 0, &a);
    memset(&md, 0, sizeof md);
    md.positions = box.pos;
    md.vertex_count = box.vcount;
    md.indices = box.idx;
    md.index_count = box.icount;
    memset(&td, 0, sizeof td);
    td.width = td.height = 1;
    td.pixels = px;
    for (i = 0; i < s->life_n; ++i) {
        fogvol_mesh *m;
        fogvol_ramp *r;
        fogvol_volume_texture *t;
        fogvol_ramp_desc rd;
        scale_ramp_desc(&rd, i);
        if (fogvol_create_mesh(c, &md, &m, NULL) != FOGVOL_SUCCESS || fogvol_create_ramp(c, &rd, &r) != FOGVOL_SUCCESS ||
            fogvol_create_volume_texture(c, &td, &t) != FOGVOL_SUCCESS)
            die("lifetime objects");
    }
    t0 = now_ms();
    fogvol_destroy_context(c);
    s->life_ms = now_ms() - t0;
    s->life_host = a.live;
    s->life_gpu = nb.creates - nb.destroys;
    shp_free(&box);
}

static void scale_measure(scale_figs *s, int quick)
{
    scale_frames(s, quick);
    scale_weld(s, quick);
    scale_lifetime(s, quick);
}

static void print_scale(const scale_figs *s)
{
    out("| fogvol_end_frame, %d volumes of %d ramps, PS20, null backend (%d passes) | %.1f ms |\n", s->ramps,
        s->ramps, s->ramps_passes, s->ramps_ms);
    out("| fogvol_end_frame, %d volumes of one ramp, FLOAT + COLORS + GEOMETRY composite, null backend | %.1f ms |\n",
        s->colors, s->colors_ms);
    out("| weld of a per-face subdivided cube, %d vertices (6 x %d^2) at 1e-5 -> %d | %.1f ms |\n", s->weld_v,
        s->weld_n + 1, s->weld_kept, s->weld_ms);
    out("| fogvol_validate_mesh of that cube with weld_distance 1e-5 (weld + checks) | %.1f ms |\n", s->weld_total_ms);
    out("| fogvol_destroy_context with %d meshes, %d ramps and %d volume textures alive | %.1f ms, %ld allocations "
        "and %d backend objects left |\n",
        s->life_n, s->life_n, s->life_n, s->life_ms, s->life_host, s->life_gpu);
}

/* the scale figures for the summary line */
static void scale_summary(const scale_figs *s, char *buf, size_t size)
{
    snprintf(buf, size, "end_frame %d ramps %.1f ms, colours %d volumes %.1f ms, weld %dk vertices %.1f ms, "
             "destroy_context leaves %ld allocations %d objects",
             s->ramps, s->ramps_ms, s->colors, s->colors_ms, s->weld_v / 1000, s->weld_ms, s->life_host, s->life_gpu);
}

/* the GL backend (wrapped by the pass timer) + fogvol_create_context, timed together */
static fogvol_context *create_tier(int t, double *ms, fogvol_backend *be)
{
    fogvol_context_desc cd;
    fogvol_context *c = NULL;
    double t0;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = fv_log;
    cd.tier = g_tiers[t].tier;
    cd.variants = g_tiers[t].variants;
    cd.engine_mrt = g_tiers[t].tier == FOGVOL_TIER_MRT;
    cd.disable_speedups = g_tiers[t].speedups_off;
    cd.gl.software = g_tiers[t].software;
    glFinish();
    t0 = now_ms();
    if (fogvol_gl_backend_create(&cd.gl, NULL, &cd.logger, be) != FOGVOL_SUCCESS) die("fogvol_gl_backend_create");
    g_pt.begin_pass = be->begin_pass;
    g_pt.end_pass = be->end_pass;
    be->begin_pass = pt_begin_pass;
    be->end_pass = pt_end_pass;
    cd.backend = *be;
    if (fogvol_create_context(&cd, &c) != FOGVOL_SUCCESS) die("fogvol_create_context");
    glFinish();
    *ms = now_ms() - t0;
    return c;
}

/* a FLOAT context on the GL backend with the given variants (the MSAA and colour sections) */
static fogvol_context *float_context_ex(unsigned variants, int software, unsigned speedups_off, const char *what)
{
    fogvol_context_desc cd;
    fogvol_context *c = NULL;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.gl.software = software;
    cd.logger.func = fv_log;
    cd.tier = FOGVOL_TIER_FLOAT;
    cd.variants = variants;
    cd.disable_speedups = speedups_off;
    if (fogvol_create_context(&cd, &c) != FOGVOL_SUCCESS) die(what);
    return c;
}

static fogvol_context *float_context(unsigned variants, const char *what)
{
    return float_context_ex(variants, 0, 0u, what);
}

static void destroy_tier(fogvol_context *c, fogvol_backend *be)
{
    fogvol_destroy_context(c);
    be->destroy(be->user_data); /* a table handed in is not owned by the context */
}

/* ---- plot: cost against depth complexity, drawn into an RGBA buffer ---------------- */
typedef struct canvas {
    unsigned char *px;
    int w, h;
} canvas;

static void fill(canvas *c, int x0, int y0, int x1, int y1, const unsigned char *rgb)
{
    int x, y;
    for (y = y0 < 0 ? 0 : y0; y < y1 && y < c->h; ++y)
        for (x = x0 < 0 ? 0 : x0; x < x1 && x < c->w; ++x) memcpy(c->px + 4 * ((size_t)y * c->w + x), rgb, 3);
}

static void line(canvas *c, double x0, double y0, double x1, double y1, int th, const unsigned char *rgb, int dash)
{
    double len = sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)), s;
    for (s = 0; s <= len; s += 0.5) {
        int x = (int)(x0 + (x1 - x0) * s / (len + 1e-9)), y = (int)(y0 + (y1 - y0) * s / (len + 1e-9));
        if (dash && ((int)s / dash) % 2) continue;
        fill(c, x - th / 2, y - th / 2, x - th / 2 + th, y - th / 2 + th, rgb);
    }
}

static void text(canvas *c, int x, int y, const char *str, int scale, const unsigned char *rgb)
{
    static char vb[60000];
    char s[256];
    int q, n;
    snprintf(s, sizeof s, "%s", str);
    n = stb_easy_font_print(0, 0, s, NULL, vb, sizeof vb);
    for (q = 0; q < n; ++q) {
        const float *v0 = (const float *)(void *)(vb + 64 * q), *v2 = (const float *)(void *)(vb + 64 * q + 32);
        fill(c, x + (int)(v0[0] * scale), y + (int)(v0[1] * scale), x + (int)(v2[0] * scale), y + (int)(v2[1] * scale),
             rgb);
    }
}

static int text_w(const char *str, int scale)
{
    char s[256];
    snprintf(s, sizeof s, "%s", str);
    return stb_easy_font_width(s) * scale + 0 * stb_easy_font_height(s); /* both used: -Werror=unused-function */
}

/* 1-2-5 steps: the largest step value <= v (up = 0) or the smallest >= v (up = 1) */
static double step125(double v, int up)
{
    static const double f[4] = {1, 2, 5, 10};
    double e = pow(10.0, floor(log10(v))), r = up ? 10 * e : e;
    int j;
    for (j = 0; j < 4; ++j) {
        double x = f[j] * e;
        if (up ? x >= v * (1 - 1e-9) && x < r : x <= v * (1 + 1e-9)) r = x;
    }
    return r;
}

/* the plot shows the default tiers, the floor and the peeling */
static int plotted(int m) { return m < NDEFAULT || m == M_FLOOR || m == M_PEEL; }

static void plot(const char *path, const result *rs, int n, int w, int h)
{
    static const unsigned char col[NMETH][3] = {{214, 39, 40},  {255, 127, 14}, {148, 103, 189}, {31, 119, 180},
                                                {23, 190, 207}, {140, 86, 75},  {227, 119, 194}, {60, 60, 60},
                                                {200, 160, 40},  {127, 127, 127}, {188, 189, 34}, {44, 160, 44}};
    static const unsigned char black[3] = {0, 0, 0}, grid[3] = {225, 225, 225};
    static const char *xlabel = "depth complexity k (back faces per ray at the centre, log2 scale)";
    const char *renderer = (const char *)glGetString(GL_RENDERER);
    canvas c;
    const result *pts[8];
    int np = 0, i, m, L = 80, R = 40, T = 80, B = 130, lx, ly;
    double lo = 1e30, hi = 0, v, k0, k1;
    char s[160];
    c.w = 1000;
    c.h = 680;
    c.px = (unsigned char *)malloc((size_t)c.w * c.h * 4);
    if (!c.px) die("out of memory");
    memset(c.px, 255, (size_t)c.w * c.h * 4);
    for (i = 0; i < n && np < 8; ++i)
        if (rs[i].k > 0 && rs[i].w == w && rs[i].h == h) pts[np++] = &rs[i];
    for (i = 0; i < np; ++i)
        for (m = 0; m < NMETH; ++m) {
            if (pts[i]->ms[m] > 0 && pts[i]->ms[m] < lo) lo = pts[i]->ms[m];
            if (pts[i]->ms[m] > hi) hi = pts[i]->ms[m];
        }
    if (np < 2 || !(lo > 0)) {
        free(c.px);
        return;
    }
    lo = step125(lo, 0);
    hi = step125(hi, 1);
    k0 = log2((double)pts[0]->k);
    k1 = log2((double)pts[np - 1]->k);
#define PX(kk) (L + (log2((double)(kk)) - k0) / (k1 - k0) * (c.w - L - R))
#define PY(v) (c.h - B - log10((v) / lo) / log10(hi / lo) * (c.h - T - B))
    stb_easy_font_spacing(0.5f);
    for (v = lo; v <= hi * 1.0001; v = step125(v * 1.01, 1)) { /* grid and y labels, 1-2-5 */
        line(&c, L, PY(v), c.w - R, PY(v), 1, grid, 0);
        snprintf(s, sizeof s, v < 1 ? "%g" : "%.0f", v); /* (0.05, not 0.1 twice) */
        text(&c, L - 10 - text_w(s, 2), (int)PY(v) - 6, s, 2, black);
    }
    for (i = 0; i < np; ++i) { /* x ticks at the measured k */
        line(&c, PX(pts[i]->k), T, PX(pts[i]->k), c.h - B, 1, grid, 0);
        snprintf(s, sizeof s, "%d", pts[i]->k);
        text(&c, (int)PX(pts[i]->k) - text_w(s, 2) / 2, c.h - B + 10, s, 2, black);
    }
    line(&c, L, T, L, c.h - B, 2, black, 0);
    line(&c, L, c.h - B, c.w - R, c.h - B, 2, black, 0);
    snprintf(s, sizeof s, "fogvol.h: fog cost vs depth complexity (nested shells, %dx%d, %.*s)", w, h,
             (int)strcspn(renderer, "/("), renderer); /* "llvmpipe", "NVIDIA H100 80GB HBM3" */
    i = text_w(s, 2) <= c.w - 20 ? 2 : 1; /* a long renderer name: the small font */
    text(&c, c.w / 2 - text_w(s, i) / 2, 16, s, i, black);
    text(&c, L - 60, T - 30, "ms per frame (median, log scale)", 2, black);
    text(&c, L + (c.w - L - R) / 2 - text_w(xlabel, 2) / 2, c.h - B + 38, xlabel, 2, black);
    for (m = 0; m < NMETH; ++m) {
        int dash = m == M_FLOOR ? 8 : 0;
        if (!plotted(m)) continue;
        for (i = 0; i < np; ++i) {
            double x = PX(pts[i]->k), y = PY(pts[i]->ms[m]);
            if (i) line(&c, PX(pts[i - 1]->k), PY(pts[i - 1]->ms[m]), x, y, 3, col[m], dash);
            fill(&c, (int)x - 5, (int)y - 5, (int)x + 6, (int)y + 6, col[m]);
        }
    }
    lx = L; /* legend below the axes, flowing */
    ly = c.h - 58;
    for (m = 0; m < NMETH; ++m) {
        int tw;
        if (!plotted(m)) continue;
        snprintf(s, sizeof s, "%s", m < NTIER ? g_meth_names[m] : m == M_FLOOR ? "floor (1 geometry + 1 full-screen pass)"
                                                                                 : "depth peeling (exact)");
        tw = text_w(s, 2);
        if (lx + 50 + tw > c.w - 10) {
            lx = L;
            ly += 26;
        }
        line(&c, lx, ly + 6, lx + 40, ly + 6, 3, col[m], m == M_FLOOR ? 8 : 0);
        fill(&c, lx + 15, ly + 1, lx + 26, ly + 12, col[m]);
        text(&c, lx + 48, ly, s, 2, black);
        lx += 48 + tw + 28;
    }
    stbi_flip_vertically_on_write(0);
    if (!stbi_write_png(path, c.w, c.h, 4, c.px, c.w * 4)) fprintf(stderr, "bench: cannot write %s\n", path);
#undef PX
#undef PY
    free(c.px);
}

/* ---- tables ------------------------------------------------------------------------ */
/* CPU model and count from /proc/cpuinfo (Linux) */
static void cpu_info(char *model, size_t cap, int *count)
{
    char line[512];
    FILE *f = fopen("/proc/cpuinfo", "r");
    *count = 0;
    snprintf(model, cap, "unknown CPU");
    if (!f) return;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "model name", 10) == 0) {
            char *p = strchr(line, ':');
            if (p && *count == 0) {
                snprintf(model, cap, "%s", p + 2);
                model[strcspn(model, "\n")] = 0;
            }
            ++*count;
        }
    fclose(f);
}

static void loadavg(char *buf, size_t cap)
{
    FILE *f = fopen("/proc/loadavg", "r");
    snprintf(buf, cap, "?");
    if (f) {
        if (fgets(buf, (int)cap, f)) buf[strcspn(buf, " ")] = 0; /* the 1-minute average */
        fclose(f);
    }
}

static const char *pf(int ok) { return ok ? "PASS" : "MISS"; }

/* The issue's target for tier row m in scene r: limit x the reference floor (the occluder floor
   where the scene has occluders); 0: no target (the rows with speed-ups off). The engine's depth
   (issue 34): FLOAT + engine depth <= 1.15x the floor without occluders and <= plain FLOAT (which
   draws the occluders itself) with them; PS20 + engine depth likewise against PS20. */
static double target(int m, const result *r, double *ref, const char **refname)
{
    fogvol_tier t = g_tiers[m].tier;
    *ref = r->occluders ? r->ms[M_OCCFLOOR] : r->ms[M_FLOOR];
    *refname = r->occluders ? "occluder floor" : "floor";
    if (m == M_FLOAT_ED && r->occluders) {
        *ref = r->ms[M_FLOAT];
        *refname = "FLOAT";
        return 1.0;
    }
    if (m == M_FLOAT_ED) return 1.15;
    if (m == M_PS20_ED) {
        *ref = r->ms[M_PS20];
        *refname = "PS20";
        return r->occluders ? 1.0 : 1.15;
    }
    if (m >= NDEFAULT) return 0;
    if (t == FOGVOL_TIER_FLOAT) return r->occluders ? 1.5 : 1.2;
    return t == FOGVOL_TIER_PS13 ? 2.5 : 2.0;
}

static void print_results(const result *rs, int n)
{
    int i, m;
    out("| scene | size | method | passes | ms/frame | x floor | x occluder floor | x scissored floor | ours/peel | "
        "fog Mpx/s | vs peeling: max / mean | targets |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|\n");
    for (i = 0; i < n; ++i) {
        const result *r = &rs[i];
        for (m = 0; m < NMETH; ++m) {
            char tgt[128] = "", diff[64] = "", ratio[32] = "";
            double floor_ms = r->ms[M_FLOOR];
            if (m < NTIER) {
                int is_float = g_tiers[m].tier == FOGVOL_TIER_FLOAT;
                const char *rn;
                double ref, lim = target(m, r, &ref, &rn);
                if (lim > 0) snprintf(tgt, sizeof tgt, "<=%.4gx %s %s", lim, rn, pf(r->ms[m] <= lim * ref));
                if (lim > 0 && r->layers >= 6)
                    snprintf(tgt + strlen(tgt), sizeof tgt - strlen(tgt), "; peeling >=6x slower %s",
                             pf(r->ms[M_PEEL] >= 6.0 * r->ms[m]));
                snprintf(diff, sizeof diff, is_float ? "%.2g / %.2g units" : "%.2f / %.3f LSB", r->dmax[m], r->dmean[m]);
                if (r->overflow[m]) snprintf(diff + strlen(diff), sizeof diff - strlen(diff), " (%d ovf)", r->overflow[m]);
                snprintf(ratio, sizeof ratio, "%.3f", r->ms[m] / r->ms[M_PEEL]);
            } else if (m == M_PEEL) {
                snprintf(diff, sizeof diff, "(%d layers)", r->layers);
            }
            out("| %s | %dx%d | %s | %d | %.2f | %.2f | %.2f | %.2f | %s | %.1f | %s | %s |\n", m == 0 ? r->scene : "",
                r->w, r->h, g_meth_names[m], r->passes[m], r->ms[m], r->ms[m] / floor_ms, r->ms[m] / r->ms[M_OCCFLOOR],
                r->ms[m] / r->ms[M_SCFLOOR], ratio, r->fogged / r->ms[m] / 1e3, diff, tgt);
        }
    }
}

/* name of pass p of method m in a scene with or without occluders that ran np passes: the
   default tiers skip O in scenes without occluders; RGBA8 tiers run an overflow check pass
   before the composite while they count overflow; PS13 resolves B - F in its composite
   (FOGVOL_SPEEDUP_INLINE_RESOLVE: every GL here has fp32 fragment shaders) */
static const char *pass_name(int m, int p, int np, int occluders)
{
    static const char *const pn[][6] = {{"O", "B", "F", "check", "composite", ""},
                                        {"O", "B", "F", "check", "composite", ""},
                                        {"B", "F", "check", "composite", "", ""},
                                        {"O", "B-F", "composite", "", "", ""},
                                        {"B-F", "composite", "", "", "", ""},
                                        {"O", "B-F", "composite", "", "", ""},
                                        {"O", "B", "F", "check", "composite", ""},
                                        {"O", "B-F", "composite", "", "", ""},
                                        {"O", "B", "F", "check", "composite", ""},
                                        {"B-F", "composite", "", "", "", ""},
                                        {"B-F", "composite", "", "", "", ""},
                                        {"geometry", "composite", "", "", "", ""}};
    const char *names[6];
    int full = 0, i, k = 0;
    const char *const *src = pn[m < NTIER ? m : NTIER];
    typedef char one_row_per_tier_and_the_floor[sizeof pn / sizeof pn[0] == NTIER + 1 ? 1 : -1];
    (void)sizeof(one_row_per_tier_and_the_floor);
    while (full < 6 && src[full][0]) ++full;
    for (i = 0; i < full; ++i) {
        if (strcmp(src[i], "O") == 0 && m < NTIER && !g_tiers[m].speedups_off && !occluders &&
            !(g_tiers[m].variants & FOGVOL_VARIANT_ENGINE_DEPTH)) /* (PS20 + engine depth: O from it, always) */
            continue;
        names[k++] = src[i];
    }
    if (np < k) /* no check pass this frame */
        for (i = 0; i < k; ++i)
            if (strcmp(names[i], "check") == 0) {
                memmove(names + i, names + i + 1, (size_t)(k - i - 1) * sizeof names[0]);
                --k;
                break;
            }
    if (np < k) /* B and F in one pass: the integer sum (FOGVOL_SPEEDUP_EXACT_SUM) */
        for (i = 0; i + 1 < k; ++i)
            if (strcmp(names[i], "B") == 0 && strcmp(names[i + 1], "F") == 0) {
                names[i] = "B+F (one sum)";
                memmove(names + i + 1, names + i + 2, (size_t)(k - i - 2) * sizeof names[0]);
                --k;
                break;
            }
    return p < k ? names[p] : "?";
}

static void print_breakdown(const result *rs, int n)
{
    int i, m, p;
    out("\n### Where the time goes (1280x720; every pass bracketed by glFinish, medians of 7 frames)\n\n"
        "Passes serialised by glFinish, so the frame is slower than in the main table (no overlap of vertex work "
        "on the calling thread with the rasteriser threads). outside = frame - passes: fogvol's CPU work, GL state "
        "save/restore and the calls between passes. CPU (null): the same frame on fogvol's recording null backend "
        "(the library's own CPU cost). The rows with speed-ups off are the configuration before the speed-ups "
        "(an O pass in every frame, filtered target reads, ramp lookup, full-screen composite).\n\n"
        "| scene | method | passes (ms) | sum | frame | outside | CPU (null) |\n|---|---|---|---:|---:|---:|---:|\n");
    for (i = 0; i < n; ++i) {
        const result *r = &rs[i];
        if (!r->bd) continue;
        for (m = 0; m <= M_FLOOR; ++m) {
            char cells[256] = "";
            double sum = 0;
            if (m < NTIER && g_tiers[m].tier == FOGVOL_TIER_MRT) {
                snprintf(cells, sizeof cells, "engine pass writing O %.2f (plain engine pass %.2f), ", r->bd_engine_mrt,
                         r->engine_ms);
                sum += r->bd_engine_mrt - r->engine_ms;
            }
            for (p = 0; p < r->bd_np[m] && p < 6; ++p) {
                snprintf(cells + strlen(cells), sizeof cells - strlen(cells), "%s%s %.2f", p ? ", " : "",
                         pass_name(m, p, r->bd_np[m], r->occluders), r->bd_ms[m][p]);
                sum += r->bd_ms[m][p];
            }
            if (m < NTIER && g_tiers[m].tier == FOGVOL_TIER_MRT) {
                out("| %s | %s | %s | %.2f | %.2f | %.2f | %.1f us |\n", m ? "" : r->scene, g_meth_names[m], cells, sum,
                    r->bd_frame[m] - r->engine_ms, r->bd_frame[m] - r->engine_ms - sum, r->cpu_us[m]);
            } else {
                char cpu[32] = "-";
                if (m < NTIER) snprintf(cpu, sizeof cpu, "%.1f us", r->cpu_us[m]);
                out("| %s | %s | %s | %.2f | %.2f | %.2f | %s |\n", m ? "" : r->scene, g_meth_names[m], cells, sum,
                    r->bd_frame[m], r->bd_frame[m] - sum, cpu);
            }
        }
    }
}

/* The worst ratio of tier m to its target's reference over the scenes (occluders: 0 without, 1
   with, -1 all), and the scene it is in. */
static double worst_ratio(const result *rs, int n, int m, int occluders, const char **where)
{
    double worst = 0, ref;
    const char *rn;
    int i;
    *where = "-";
    for (i = 0; i < n; ++i) {
        const result *r = &rs[i];
        if (occluders >= 0 && (r->occluders > 0) != occluders) continue;
        target(m, r, &ref, &rn);
        if (r->ms[m] / ref > worst) {
            worst = r->ms[m] / ref;
            *where = r->scene;
        }
    }
    return worst;
}

/* the smallest peeling / tier time over the default tiers and the scenes with >= 6 layers */
static double peel_min(const result *rs, int n)
{
    double lo = 1e30;
    int i, m;
    for (i = 0; i < n; ++i)
        for (m = 0; m < NDEFAULT && rs[i].layers >= 6; ++m)
            if (rs[i].ms[M_PEEL] / rs[i].ms[m] < lo) lo = rs[i].ms[M_PEEL] / rs[i].ms[m];
    return lo < 1e30 ? lo : 0;
}

static void print_summary(const result *rs, int n)
{
    static const struct {
        int m, occ;
        double lim;
        const char *what;
    } rows[] = {{3, 0, 1.2, "FLOAT, scenes without occluders, x floor"},
                {3, 1, 1.5, "FLOAT, scenes with occluders, x occluder floor"},
                {M_FLOAT_ED, 0, 1.15, "FLOAT+engine depth, scenes without occluders, x floor"},
                {M_FLOAT_ED, 1, 1.0, "FLOAT+engine depth, scenes with occluders, x plain FLOAT"},
                {M_PS20_ED, 0, 1.15, "PS20+engine depth, scenes without occluders, x PS20"},
                {M_PS20_ED, 1, 1.0, "PS20+engine depth, scenes with occluders, x PS20"},
                {1, -1, 2.0, "PS20 (x floor / occluder floor)"},
                {2, -1, 2.0, "MRT (x floor / occluder floor)"},
                {0, -1, 2.5, "PS13 (x floor / occluder floor)"},
                {5, 0, 1.2, "FLOAT, speed-ups off, without occluders (for comparison)"},
                {6, -1, 2.0, "PS20, speed-ups off (for comparison)"},
                {7, -1, 1.2, "FLOAT, half resolution (x floor / occluder floor)"}};
    int j;
    double pm = peel_min(rs, n);
    out("\n### Targets (worst over scenes and sizes)\n\n| configuration | worst | scene | target |\n|---|---:|---|---|\n");
    for (j = 0; j < (int)(sizeof rows / sizeof rows[0]); ++j) {
        const char *w;
        double x = worst_ratio(rs, n, rows[j].m, rows[j].occ, &w);
        out("| %s | %.2fx | %s | <=%.4gx %s |\n", rows[j].what, x, w, rows[j].lim,
            rows[j].m < NDEFAULT || rows[j].m == M_PS20_ED ? pf(x <= rows[j].lim) : "(info)");
    }
    out("| depth peeling / fogvol, smallest over the default tiers at >= 6 layers | %.2fx | | >=6x %s |\n", pm,
        pf(pm >= 6.0));
}

/* The analytic fog's figures: the end of the "summary: analytic ..." line that bench_analytic
   wrote to the file named by FOGVOL_BENCH_ANALYTIC (make bench runs it first), else "analytic n/a". */
static void analytic_figures(char *buf, size_t size)
{
    const char *path = getenv("FOGVOL_BENCH_ANALYTIC");
    char line[256];
    FILE *f = path ? fopen(path, "r") : NULL;
    snprintf(buf, size, "analytic n/a");
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "summary: analytic", 17) == 0) {
            line[strcspn(line, "\r\n")] = 0;
            snprintf(buf, size, "%s", line + 9);
        }
    if (f) fclose(f);
}

/* The Vulkan backend (examples/vulkan_backend.c on lavapipe) beside the GL backend (llvmpipe) on
   the same scene in one run: the lines of vulkan_backend --bench, which make bench runs first into
   the file named by FOGVOL_BENCH_VULKAN (left out where it is not set or not there). */
static void vulkan_figures(void)
{
    const char *path = getenv("FOGVOL_BENCH_VULKAN");
    char line[512];
    FILE *f = path ? fopen(path, "r") : NULL;
    int n = 0;
    while (f && fgets(line, sizeof line, f)) {
        if (!n++)
            out("\n## Vulkan (lavapipe) beside GL (llvmpipe)\n\nexamples/vulkan_backend.c --bench, run by make bench "
                "just before this program (the same fogvol frames through the Vulkan example backend on lavapipe and "
                "through the GL backend on llvmpipe, one scene, in one run):\n\n");
        out("    %s", line);
    }
    if (f) fclose(f);
}

/* the last line of the output: the figures to compare between runs */
static void print_summary_line(const result *rs, int n, const scale_figs *sc, double msaa)
{
    const char *w;
    char an[256], sf[256], ms[32] = "n/a";
    analytic_figures(an, sizeof an);
    scale_summary(sc, sf, sizeof sf);
    if (msaa > 0) snprintf(ms, sizeof ms, "%.2fx", msaa);
    out("\nsummary: FLOAT worst %.2fx floor, FLOAT occluders %.2fx occluder floor, PS20 worst %.2fx, MRT worst %.2fx, "
        "PS13 worst %.2fx, peeling/ours at k>=6 %.1fx, %s, %s, engine depth worst %.2fx floor, engine depth "
        "occluders %.2fx plain FLOAT, MSAA 4x %s single-sample\n",
        worst_ratio(rs, n, 3, 0, &w), worst_ratio(rs, n, 3, 1, &w), worst_ratio(rs, n, 1, -1, &w),
        worst_ratio(rs, n, 2, -1, &w), worst_ratio(rs, n, 0, -1, &w), peel_min(rs, n), an, sf,
        worst_ratio(rs, n, M_FLOAT_ED, 0, &w), worst_ratio(rs, n, M_FLOAT_ED, 1, &w), ms);
}

/* ---- MSAA: fog on a 4x multisampled engine framebuffer against a single-sample one ---------- */
/* An engine framebuffer of 1 or 4 samples: an RGBA8 colour renderbuffer and a depth texture
   (GL_TEXTURE_2D_MULTISAMPLE with 4 samples), as an engine that hands fogvol its depth has. */
typedef struct msaa_fb {
    GLuint fbo, color, depth;
    int samples;
} msaa_fb;

static void msaa_fb_create(msaa_fb *f, int w, int h, int samples)
{
    GLenum target = samples > 1 ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
    memset(f, 0, sizeof *f);
    f->samples = samples;
    glGenRenderbuffers(1, &f->color);
    glBindRenderbuffer(GL_RENDERBUFFER, f->color);
    if (samples > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    else glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glGenTextures(1, &f->depth);
    glBindTexture(target, f->depth);
    if (samples > 1) {
        glTexImage2DMultisample(target, samples, GL_DEPTH_COMPONENT24, w, h, GL_TRUE);
    } else {
        glTexImage2D(target, 0, GL_DEPTH_COMPONENT24, w, h, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
        glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glBindTexture(target, 0);
    glGenFramebuffers(1, &f->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, f->color);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, target, f->depth, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("MSAA framebuffer incomplete");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void msaa_fb_free(msaa_fb *f)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &f->fbo);
    glDeleteRenderbuffers(1, &f->color);
    glDeleteTextures(1, &f->depth);
}

/* the engine's opaque pass (the occluders) into an engine framebuffer of its own */
static void msaa_engine_pass(const scene *s, const view *vw, const msaa_fb *f, int w, int h)
{
    static const float bg[4] = {0.2f, 0.35f, 0.55f, 1.0f};
    glBindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    glViewport(0, 0, w, h);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_TRUE);
    glClearBufferfv(GL_COLOR, 0, bg);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(P.engine);
    draw_insts(s, vw, P.engine, 1);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(0);
}

/* The engine's vertex arrays of s's meshes (scene_upload without fogvol's meshes), and their release
   with the meshes (the MSAA section and the prototypes that include this file). */
static void engine_meshes_upload(scene *s)
{
    int k;
    for (k = 0; k < s->nmesh; ++k) gmesh_upload(&s->mesh[k]);
}

static void engine_meshes_free(scene *s)
{
    int k;
    for (k = 0; k < s->nmesh; ++k) {
        glDeleteVertexArrays(1, &s->mesh[k].vao);
        glDeleteBuffers(1, &s->mesh[k].vbo);
        glDeleteBuffers(1, &s->mesh[k].ibo);
        shp_free(&s->mesh[k].m);
    }
}

/* FLOAT (fogvol draws the occluders), FLOAT + engine depth as the renderer chooses (the summary's two),
   and FLOAT + engine depth both ways whatever the renderer: depth-tested per sample with the faces
   shaded per pixel (fogvol_gl_desc.software 1), and the engine's depth read per sample */
#define NMSAA 4
#define NMSAA_SUMMARY 2
typedef struct msaa_method {
    const char *name;
    unsigned variants, speedups_off;
    int software;
} msaa_method;
static const msaa_method g_msaa[NMSAA] = {
    {"FLOAT", 0u, 0u, 0},
    {"FLOAT+engine depth", FOGVOL_VARIANT_ENGINE_DEPTH, 0u, 0},
    {"FLOAT+engine depth, depth-tested", FOGVOL_VARIANT_ENGINE_DEPTH, 0u, 1},
    {"FLOAT+engine depth, per-sample read", FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST, 0}};
typedef struct msaa_ctx {
    fogvol_context *ctx;
    fogvol_ramp *ramp;
    fogvol_mesh *fm[MAXMESH];
} msaa_ctx;

static void msaa_ctx_init(msaa_ctx *m, const scene *s, const msaa_method *mm)
{
    fogvol_ramp_desc rd;
    int i;
    memset(m, 0, sizeof *m);
    m->ctx = float_context_ex(mm->variants, mm->software, mm->speedups_off, "fogvol_create_context (MSAA)");
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
    rd.density = 0.5f;
    if (fogvol_create_ramp(m->ctx, &rd, &m->ramp) != FOGVOL_SUCCESS) die("ramp (MSAA)");
    for (i = 0; i < s->nmesh; ++i) {
        fogvol_mesh_desc md;
        int j, occ = 0;
        for (j = 0; j < s->n; ++j) occ |= s->in[j].mesh == i && s->in[j].occluder;
        memset(&md, 0, sizeof md);
        md.positions = s->mesh[i].m.pos;
        md.vertex_count = s->mesh[i].m.vcount;
        md.indices = (const uint32_t *)s->mesh[i].m.idx;
        md.index_count = s->mesh[i].m.icount;
        md.allow_open = occ;
        if (fogvol_create_mesh(m->ctx, &md, &m->fm[i], NULL) != FOGVOL_SUCCESS) die("mesh (MSAA)");
    }
}

static void msaa_ctx_free(msaa_ctx *m, const scene *s)
{
    int i;
    for (i = 0; i < s->nmesh; ++i) fogvol_destroy_mesh(m->ctx, m->fm[i]);
    fogvol_destroy_ramp(m->ctx, m->ramp);
    fogvol_destroy_context(m->ctx);
}

/* one fog frame on engine framebuffer f (its opaque pass drawn before the clock starts); fog ms */
static double msaa_frame(msaa_ctx *m, int ed, const scene *s, const view *vw, const msaa_fb *f, int w, int h)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_frame_stats st;
    fogvol_result res;
    tick t0;
    int i;
    msaa_engine_pass(s, vw, f, w, h);
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, vw->v, sizeof fd.view);
    memcpy(fd.projection, vw->p, sizeof fd.projection);
    fd.znear = s->znear;
    fd.zfar = s->zfar;
    fd.viewport[2] = w;
    fd.viewport[3] = h;
    fd.engine_depth_texture = ed ? f->depth : 0;
    t0 = tick_start();
    if (fogvol_begin_frame(m->ctx, &fd) != FOGVOL_SUCCESS) die("begin_frame (MSAA)");
    memset(&vd, 0, sizeof vd);
    vd.ramp = m->ramp;
    for (i = 0; i < s->n; ++i) {
        const inst *in = &s->in[i];
        if (in->occluder) {
            if (!ed) fogvol_add_occluder(m->ctx, m->fm[in->mesh], in->model);
            continue;
        }
        vd.mesh = m->fm[in->mesh];
        memcpy(vd.model, in->model, sizeof vd.model);
        fogvol_add_volume(m->ctx, &vd);
    }
    res = fogvol_end_frame(m->ctx, &st);
    if (res != FOGVOL_SUCCESS) die(fogvol_result_string(res));
    if (f->samples > 1 && st.samples != f->samples) die("MSAA: the frame was not drawn per sample");
    return tick_ms(t0, tick_end());
}

/* The MSAA cost: FLOAT and FLOAT + engine depth on a 4x multisampled engine framebuffer against
   the same on a single-sample one (fogvol shades its passes per sample on the 4x one), frames
   interleaved, medians; the worst 4x / single-sample ratio goes to the summary line. */
static double bench_msaa(int quick)
{
    static const int scenes[2] = {6, 0}; /* floor + pillars (occluder edges inside fog), 16 spheres */
    int sc, mi, f, frames = quick ? 3 : 9, w = quick ? 320 : 640, h = quick ? 180 : 360;
    double worst = 0;
    out("\n## MSAA 4x against single-sample\n\nFog ms per frame on a 4x multisampled engine framebuffer (colour "
        "renderbuffer + multisample depth texture; fogvol's targets get 4 samples) and on a single-sample one, "
        "%dx%d, medians of %d interleaved frames. FLOAT draws the occluders itself, its passes shaded per sample. "
        "FLOAT+engine depth uses the engine's depth texture as this renderer's backend chooses: on a software "
        "renderer the faces depth-tested against it per sample and shaded once per pixel, elsewhere the depth read "
        "per sample; the two rows after it take each way on any renderer. The summary's MSAA 4x is the worst of "
        "the first two rows.\n\n"
        "| scene | method | single-sample ms | 4x ms | 4x / single |\n|---|---|---:|---:|---:|\n",
        w, h, frames);
    for (sc = 0; sc < 2; ++sc) {
        scene *s = (scene *)calloc(1, sizeof(scene));
        msaa_fb fb[2];
        msaa_ctx mc[NMSAA][2];
        view vw;
        double t[NMSAA][2][32];
        int k;
        if (!s) die("out of memory");
        build_scene(s, scenes[sc]);
        engine_meshes_upload(s);
        make_view(&vw, s, w, h);
        msaa_fb_create(&fb[0], w, h, 1);
        msaa_fb_create(&fb[1], w, h, 4);
        for (mi = 0; mi < NMSAA; ++mi)
            for (k = 0; k < 2; ++k) {
                msaa_ctx_init(&mc[mi][k], s, &g_msaa[mi]);
                msaa_frame(&mc[mi][k], mi > 0, s, &vw, &fb[k], w, h); /* warm-up: targets, shader JIT */
            }
        for (f = 0; f < frames; ++f)
            for (mi = 0; mi < NMSAA; ++mi)
                for (k = 0; k < 2; ++k) t[mi][k][f] = msaa_frame(&mc[mi][k], mi > 0, s, &vw, &fb[k], w, h);
        for (mi = 0; mi < NMSAA; ++mi) {
            double a = median(t[mi][0], frames), b = median(t[mi][1], frames);
            out("| %s | %s | %.2f | %.2f | %.2f |\n", mi ? "" : s->name, g_msaa[mi].name, a, b, b / a);
            if (mi < NMSAA_SUMMARY && b / a > worst) worst = b / a;
            for (k = 0; k < 2; ++k) msaa_ctx_free(&mc[mi][k], s);
        }
        for (k = 0; k < 2; ++k) msaa_fb_free(&fb[k]);
        engine_meshes_free(s);
        free(s);
    }
    if (glGetError() != GL_NO_ERROR) die("GL error (MSAA)");
    return worst;
}

/* ---- 16 coloured volumes: per-ramp groups against one pass (FOGVOL_VARIANT_COLORS) ------ */
#define NCOL 16
typedef struct colbench {
    fogvol_context *ctx;
    fogvol_backend be;
    fogvol_mesh *mesh;
    fogvol_ramp *ramp[NCOL];
} colbench;

static void colbench_init(colbench *b, unsigned variants, const shp_mesh *m)
{
    fogvol_mesh_desc md;
    int i;
    memset(b, 0, sizeof *b);
    b->ctx = float_context(variants, "fogvol_create_context (colours)");
    memset(&md, 0, sizeof md);
    md.positions = m->pos;
    md.vertex_count = m->vcount;
    md.indices = m->idx;
    md.index_count = m->icount;
    if (fogvol_create_mesh(b->ctx, &md, &b->mesh, NULL) != FOGVOL_SUCCESS) die("mesh (colours)");
    for (i = 0; i < NCOL; ++i) {
        fogvol_ramp_desc rd;
        memset(&rd, 0, sizeof rd);
        rd.color[0] = 0.2f + 0.8f * (float)(i % 4) / 3.0f;
        rd.color[1] = 0.2f + 0.8f * (float)(i / 4) / 3.0f;
        rd.color[2] = 1.0f - 0.05f * (float)i;
        rd.density = 0.3f + 0.15f * (float)i;
        if (fogvol_create_ramp(b->ctx, &rd, &b->ramp[i]) != FOGVOL_SUCCESS) die("ramp (colours)");
    }
}

/* One frame of the 16 volumes (4x4 grid of spheres filling most of the view); fog time in ms. */
static double colbench_frame(colbench *b, int w, int h, int *passes)
{
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    double eye[3] = {0, 0, 7}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    tick t0;
    int i;
    memset(&fd, 0, sizeof fd);
    glu_look_at(fd.view, eye, at, up);
    glu_perspective(fd.projection, 45.0, (double)w / h, 0.5, 50.0);
    fd.znear = 0.5f;
    fd.zfar = 50.0f;
    fd.viewport[2] = w;
    fd.viewport[3] = h;
    glClear(GL_COLOR_BUFFER_BIT);
    t0 = tick_start();
    fogvol_begin_frame(b->ctx, &fd);
    for (i = 0; i < NCOL; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = b->mesh;
        vd.ramp = b->ramp[i];
        trs(vd.model, 1.3f * (float)(i % 4) - 1.95f, 0.75f * (float)(i / 4) - 1.1f, 0.0f, 0, 0, 1, 0, 0.6f, 0.6f,
            0.6f);
        fogvol_add_volume(b->ctx, &vd);
    }
    if (fogvol_end_frame(b->ctx, &st) != FOGVOL_SUCCESS) die("end_frame (colours)");
    *passes = st.passes;
    return tick_ms(t0, tick_end());
}

static void colbench_free(colbench *b)
{
    int i;
    for (i = 0; i < NCOL; ++i) fogvol_destroy_ramp(b->ctx, b->ramp[i]);
    fogvol_destroy_mesh(b->ctx, b->mesh);
    fogvol_destroy_context(b->ctx);
}

/* Per-ramp groups (one sum and one composite pass per colour) against the one-pass colour group,
   frames interleaved, medians. */
static void bench_colors(int quick)
{
    static const int sizes[2][2] = {{1280, 720}, {640, 360}};
    shp_mesh m = shp_sphere(1.0f, 64, 32);
    colbench per, one;
    int si, f, frames = quick ? 3 : 21, np = 0, no = 0;
    out("\n## 16 coloured volumes: per-ramp groups vs one pass\n\n16 spheres (64x32 segments), 16 extinction ramps "
        "of different colours and densities, FLOAT tier; one-pass = FOGVOL_VARIANT_COLORS (one sum pass into two "
        "RGBA32F targets, one composite). Medians of %d interleaved frames.\n\n"
        "| size | per-ramp passes | per-ramp ms | one-pass passes | one-pass ms | one pass / per-ramp |\n"
        "|---|---:|---:|---:|---:|---:|\n", frames);
    colbench_init(&per, 0, &m);
    colbench_init(&one, FOGVOL_VARIANT_COLORS, &m);
    for (si = quick ? 1 : 0; si < 2; ++si) {
        int w = sizes[si][0], h = sizes[si][1];
        GLuint col = tex2d(GL_RGBA8, w, h, GL_RGBA, GL_UNSIGNED_BYTE), fb = fbo2(col, 0, 0);
        double tp[32], to[32];
        glViewport(0, 0, w, h);
        colbench_frame(&per, w, h, &np); /* warm-up: targets, shader JIT */
        colbench_frame(&one, w, h, &no);
        for (f = 0; f < frames; ++f) {
            tp[f] = colbench_frame(&per, w, h, &np);
            to[f] = colbench_frame(&one, w, h, &no);
        }
        out("| %dx%d | %d | %.2f | %d | %.2f | %.2f |\n", w, h, np, median(tp, frames), no, median(to, frames),
            median(to, frames) / median(tp, frames));
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fb);
        glDeleteTextures(1, &col);
    }
    colbench_free(&per);
    colbench_free(&one);
    shp_free(&m);
}

int main(int argc, char **argv)
{
    static const int sizes[2][2] = {{1280, 720}, {640, 360}};
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0, si, sc, t;
    int only = argc > 2 && strcmp(argv[1], "--scene") == 0 ? atoi(argv[2]) : -1; /* diagnosis: one scene */
    int cpu_only = argc > 1 && strcmp(argv[1], "--cpu") == 0; /* the scale figures alone, no GL */
    int large = argc > 1 && strcmp(argv[1], "--large") == 0; /* the GPU-scale scenes */
    int msaa_only = argc > 1 && strcmp(argv[1], "--msaa") == 0; /* diagnosis: the MSAA section alone */
    static const int large_sizes[2][2] = {{2560, 1440}, {3840, 2160}}, large_scenes[3] = {8, 5, 6};
    double t_start = now_ms(), v[5], msaa = 0;
    glu_ctx g;
    fogs F;
    cpu_figs cpu;
    scale_figs scale;
    struct utsname un;
    char cpu_model[256], load0[64], load1[64], line[256];
    int ncpu;
    if (argc > 1 && !quick && !cpu_only && !large && !msaa_only && (only < 0 || only >= NSCENES)) {
        fprintf(stderr, "usage: %s [--quick | --cpu | --large | --msaa | --scene 0..%d]\n", argv[0], NSCENES - 1);
        return 2;
    }
    memset(&scale, 0, sizeof scale);
    if (cpu_only) {
        scale_measure(&scale, 0);
        out("| what | figure |\n|---|---:|\n");
        print_scale(&scale);
        scale_summary(&scale, line, sizeof line);
        out("\nsummary: %s\n", line);
        return 0;
    }
    /* cold shader compiles for the startup figures (no Mesa disk cache) */
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
    setenv("__GL_SHADER_DISK_CACHE", "0", 1); /* NVIDIA's driver */
    if (!glu_create(&g, 64, 64, 1)) die(BENCH_CONTEXT);
    clock_init();
    make_progs();
    if (msaa_only) { /* (standard output only: RESULTS.md is opened below) */
        printf("\nsummary: MSAA 4x %.2fx single-sample\n", bench_msaa(0));
        glu_destroy(&g);
        return 0;
    }
    memset(&F, 0, sizeof F);
    memset(&cpu, 0, sizeof cpu);
    for (t = 0; t < NTIER; ++t) {
        int r, reps = quick ? 1 : 5;
        fogvol_ramp_desc rd;
        for (r = 0; r < reps; ++r) {
            fogvol_context *c = create_tier(t, &v[r], &F.be[t]);
            if (r < reps - 1) destroy_tier(c, &F.be[t]);
            else F.ctx[t] = c;
        }
        cpu.create_ms[t] = median(v, reps);
        memset(&rd, 0, sizeof rd);
        rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
        rd.density = 0.5f;
        if (fogvol_create_ramp(F.ctx[t], &rd, &F.ramp[t]) != FOGVOL_SUCCESS) die("ramp");
    }
    cpu_measure(&cpu, quick);
    scale_measure(&scale, quick);
    if (!quick && only < 0) {
        g_md = fopen(large ? BENCH_MD_LARGE : BENCH_MD, "w");
        if (!g_md) die("cannot write the results file (run from the repository root)");
    }
    uname(&un);
    cpu_info(cpu_model, sizeof cpu_model, &ncpu);
    loadavg(load0, sizeof load0);
    out("# fogvol.h benchmark%s\n\nRenderer: %s (%s), %s %s, %d x %s. Fog volumes: extinction ramp, dither on, "
        "L = 4 (12-bit, 16 faces per target).\n\n",
        quick ? " (--quick smoke run)" : "", (const char *)glGetString(GL_RENDERER),
        (const char *)glGetString(GL_VERSION), un.sysname, un.machine, ncpu, cpu_model);

    for (si = quick ? 1 : 0; si < 2; ++si) {
        int w = large ? large_sizes[si][0] : sizes[si][0], h = large ? large_sizes[si][1] : sizes[si][1];
        for (sc = 0; sc < (large ? 3 : NSCENES); ++sc) {
            scene *s = (scene *)calloc(1, sizeof(scene));
            int frames, warm = quick || large ? 1 : 3;
            if ((quick && sc != 2) || (only >= 0 && sc != only)) {
                free(s);
                continue;
            }
            build_scene(s, large ? large_scenes[sc] : sc);
            scene_upload(s, &F);
            frames = quick || large ? 3 : BENCH_FRAMES;
            g_res[g_nres].bd = !quick && !large && w > 640;
            run_scene(&F, s, w, h, warm, frames, &g_res[g_nres]);
            fprintf(stderr, "  %-24s %4dx%-4d %3d layers  %6.1f s\n", s->name, w, h, g_res[g_nres].layers,
                    (now_ms() - t_start) / 1e3);
            g_nres++;
            scene_free(s, &F);
            free(s);
        }
    }
    out("## GPU: fog work per frame\n\nMedians over %d interleaved frames per scene after %d warm-up "
        "frames; %s. x floor: time / floor time. ours/peel: "
        "time / depth-peeling time. Mpx/s: pixels with nonzero thickness (FLOAT debug read-back) per second. "
        "vs peeling: |fogvol debug thickness - peeled thickness| over pixels where both are nonzero and the 3x3 "
        "neighbourhood has one layer count (no silhouettes); LSB = (far - near) / 4096 for the RGBA8 tiers, world "
        "units for FLOAT. References: floor = the volume triangles once + one full-screen composite; occluder floor = "
        "the same with the occluders drawn once depth-only first and the volume triangles depth-tested against them "
        "(the least a method can do that does not read the engine's depth); scissored floor = the floor with the "
        "composite scissored to the volumes' screen rectangle. Depth peeling: the timed frames draw the layer count "
        "the debug frame found, without an occlusion query per layer. Targets: FLOAT <= 1.2x floor (<= 1.5x the "
        "occluder floor in scenes with occluders), PS20 and MRT <= 2.0x, PS13 <= 2.5x (against the occluder floor "
        "in scenes with occluders), depth peeling >= 6x slower at >= 6 layers. The rows \"speed-ups off\" run with "
        "fogvol_context_desc.disable_speedups = every FOGVOL_SPEEDUP_* bit (the configuration before them).\n\n",
        quick || large ? 3 : BENCH_FRAMES, quick || large ? 1 : 3,
        g_gpu_clock ? "clock: GPU timestamps (GL_TIMESTAMP queries), one issued after a glFinish before the fog "
                      "work, one after fogvol_end_frame before a glFinish"
                    : "clock: the wall clock after a glFinish, before the fog work and after fogvol_end_frame");
    print_results(g_res, g_nres);
    print_summary(g_res, g_nres);
    if (large) { /* the GPU-scale scenes: the tables and the summary line alone */
        loadavg(load1, sizeof load1);
        out("\nTotal run time %.0f s; 1-minute load average %s at the start, %s at the end.\n",
            (now_ms() - t_start) / 1e3, load0, load1);
        print_summary_line(g_res, g_nres, &scale, 0);
        if (g_md) fclose(g_md);
        g_md = NULL;
    }
    if (!large) { /* the default run: breakdown, colours, MSAA, CPU, summary, plot */
        print_breakdown(g_res, g_nres);
        if (only < 0) bench_colors(quick);
        if (only < 0) msaa = bench_msaa(quick);
        if (only < 0) vulkan_figures();
        out("\n## CPU\n\n| what | figure |\n|---|---:|\n");
        out("| fogvol_make_rg_ramp (%dx%d) | %.2f us |\n", cpu.rg_w, cpu.rg_h, cpu.rg_us);
        out("| fogvol_make_blue_ramp (%dx%d) | %.2f us |\n", cpu.blue_w, cpu.blue_h, cpu.blue_us);
        out("| fogvol_make_color_ramp (%d texels, extinction) | %.2f us |\n", cpu.color_w, cpu.color_us);
        out("| fogvol_validate_mesh (%d triangles) | %.1f ms = %.2f M triangles/s |\n", cpu.validate_tris,
            cpu.validate_ms, cpu.validate_mtris);
        print_scale(&scale);
        for (t = 0; t < NTIER; ++t)
            out("| fogvol_gl_backend_create + fogvol_create_context, %s (shader compile + link, textures; median of %d) | %.1f ms |\n",
                g_tiers[t].name, quick ? 1 : 5, cpu.create_ms[t]);
        for (t = 0; t < NMETH; ++t)
            out("| first frame of %s, %s %dx%d (target allocation + the driver's shader compiles on first use; wall clock) | %.1f ms |\n", g_meth_names[t],
                g_res[0].scene, g_res[0].w, g_res[0].h, g_res[0].first_ms[t]);
        loadavg(load1, sizeof load1);
        out("\nTotal run time %.0f s; 1-minute load average %s at the start, %s at the end (other processes share the "
            "%d CPUs: absolute times move with the load, ratios less so since every method runs in every iteration).\n",
            (now_ms() - t_start) / 1e3, load0, load1, ncpu);
        print_summary_line(g_res, g_nres, &scale, msaa);
        if (g_md) {
            fclose(g_md);
            plot(BENCH_PNG, g_res, g_nres, 1280, 720);
        }
    }
    for (t = 0; t < NTIER; ++t) {
        fogvol_destroy_ramp(F.ctx[t], F.ramp[t]);
        destroy_tier(F.ctx[t], &F.be[t]);
    }
    glu_destroy(&g);
    return 0;
}
