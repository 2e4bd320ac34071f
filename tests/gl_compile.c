/* gl_compile.c - compiles and links every shader that dump_shaders wrote with a
   real GL driver through EGL (glslangValidator checks the language; a driver
   also checks its own limits and quirks). Desktop dialects (110 .. 330) go to a
   compatibility-profile context, 100 and 300es to an OpenGL ES 3.x context, both
   on EGL device FOGVOL_EGL_DEVICE (default 0, tests/gl_util.h). GL is reached
   only through eglGetProcAddress.

   usage: gl_compile DIR   (DIR as written by dump_shaders). Every X.frag is
   linked with X.vert, or for a per-sample X_ms.frag with the vertex shader of
   the same name without _ms. One TAP line a program (a failure with the
   driver's log), the first logs of programs that linked with a message, and a
   last line "N passed, M failed" (exit status 1 when M > 0). make test runs it
   on Mesa's EGL device (llvmpipe); on a GPU machine: make gl-compile. Programs
   that read O by framebuffer fetch (FOGVOL_SPECIALIZE_FETCH_O) are skipped, as a
   TAP SKIP, by a context without EXT_shader_framebuffer_fetch (fogvol's GL
   backend does not ask for them there). A program whose two texts (and context) another one
   already had is not linked again: it gets that one's result (many files are the same text). */
#define _POSIX_C_SOURCE 200809L
#define GLU_EGL
#include "tests/gl_util.h" /* glu_egl_display */
#include <GL/glext.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GLC_FUNCS(X)                                                                                          \
    X(PFNGLCREATESHADERPROC, CreateShader)                                                                    \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                                    \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                                                  \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                                      \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                            \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                                                    \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                                  \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                                                    \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                                      \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                                    \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                                          \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)

typedef const GLubyte *(APIENTRYP glc_getstring_fn)(GLenum);
typedef const GLubyte *(APIENTRYP glc_getstringi_fn)(GLenum, GLuint);
typedef void(APIENTRYP glc_getintegerv_fn)(GLenum, GLint *);
typedef struct glc_gl {
#define GLC_MEMBER(type, name) type name;
    GLC_FUNCS(GLC_MEMBER)
#undef GLC_MEMBER
    glc_getstring_fn GetString;
    glc_getstringi_fn GetStringi;
    glc_getintegerv_fn GetIntegerv;
} glc_gl;

typedef struct glc_ctx {
    EGLContext ctx;
    glc_gl gl;
    const char *what;
    int fetch; /* the context has EXT_shader_framebuffer_fetch */
} glc_ctx;

static EGLDisplay g_dpy = EGL_NO_DISPLAY;
static EGLSurface g_surf = EGL_NO_SURFACE;

static int glc_fail(const char *what)
{
    fprintf(stderr, "gl_compile: %s failed (EGL error 0x%x)\n", what, (unsigned)eglGetError());
    return 0;
}

/* es: 0 = desktop GL, compatibility profile (every desktop GLSL version); 1 = OpenGL ES 3.x */
static int glc_context(glc_ctx *c, int es, EGLConfig cfg)
{
    static const EGLint es_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_NONE};
    static const EGLint gl_attr[] = {EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT,
                                     EGL_NONE};
    memset(c, 0, sizeof *c);
    c->what = es ? "OpenGL ES" : "OpenGL (compatibility profile)";
    if (!eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API)) return glc_fail("eglBindAPI");
    c->ctx = eglCreateContext(g_dpy, cfg, EGL_NO_CONTEXT, es ? es_attr : gl_attr);
    if (c->ctx == EGL_NO_CONTEXT) return glc_fail(c->what);
    if (!eglMakeCurrent(g_dpy, g_surf, g_surf, c->ctx)) return glc_fail("eglMakeCurrent");
#define GLC_LOAD(type, name)                                                          \
    if (!(c->gl.name = (type)eglGetProcAddress("gl" #name))) {                        \
        fprintf(stderr, "gl_compile: no gl" #name " in the %s context\n", c->what); \
        return 0;                                                                     \
    }
    GLC_FUNCS(GLC_LOAD)
    GLC_LOAD(glc_getstring_fn, GetString)
    GLC_LOAD(glc_getstringi_fn, GetStringi)
    GLC_LOAD(glc_getintegerv_fn, GetIntegerv)
#undef GLC_LOAD
    {
        GLint n = 0, i;
        c->gl.GetIntegerv(GL_NUM_EXTENSIONS, &n);
        for (i = 0; i < n; ++i) {
            const char *e = (const char *)c->gl.GetStringi(GL_EXTENSIONS, (GLuint)i);
            if (e && strcmp(e, "GL_EXT_shader_framebuffer_fetch") == 0) c->fetch = 1;
        }
    }
    printf("%s: %s, %s%s\n", c->what, (const char *)c->gl.GetString(GL_RENDERER),
           (const char *)c->gl.GetString(GL_VERSION), c->fetch ? ", EXT_shader_framebuffer_fetch" : "");
    return 1;
}

static char *glc_read(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *s;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = (char *)malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s) s[n] = 0;
    fclose(f);
    return s;
}

/* compiles one stage; returns the shader (0 on failure, log in buf) */
static GLuint glc_shader(const glc_gl *gl, GLenum stage, const char *src, char *log, int cap, int *logged)
{
    GLuint sh = gl->CreateShader(stage);
    GLint ok = 0, len = 0;
    gl->ShaderSource(sh, 1, &src, NULL);
    gl->CompileShader(sh);
    gl->GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    gl->GetShaderiv(sh, GL_INFO_LOG_LENGTH, &len);
    if (len > 1) {
        gl->GetShaderInfoLog(sh, cap, NULL, log);
        *logged = 1;
    }
    if (!ok) {
        gl->DeleteShader(sh);
        return 0;
    }
    return sh;
}

/* 1 = linked; *logged = the driver said something */
static int glc_program(const glc_gl *gl, const char *vs, const char *fs, char *log, int cap, int *logged)
{
    GLuint v, f, p;
    GLint ok = 0, len = 0;
    log[0] = 0;
    *logged = 0;
    if (!(v = glc_shader(gl, GL_VERTEX_SHADER, vs, log, cap, logged))) return 0;
    if (!(f = glc_shader(gl, GL_FRAGMENT_SHADER, fs, log, cap, logged))) {
        gl->DeleteShader(v);
        return 0;
    }
    p = gl->CreateProgram();
    gl->AttachShader(p, v);
    gl->AttachShader(p, f);
    gl->LinkProgram(p);
    gl->GetProgramiv(p, GL_LINK_STATUS, &ok);
    gl->GetProgramiv(p, GL_INFO_LOG_LENGTH, &len);
    if (len > 1) {
        gl->GetProgramInfoLog(p, cap, NULL, log);
        *logged = 1;
    }
    gl->DeleteProgram(p);
    gl->DeleteShader(v);
    gl->DeleteShader(f);
    return ok != 0;
}

/* Programs already linked: their texts (vertex, fragment) and context, with the result. */
typedef struct glc_seen {
    char *vs, *fs;
    int es, ok, logged;
    char *log;
} glc_seen;
static glc_seen *g_seen;
static size_t g_nseen, g_capseen;
static size_t *g_hash; /* open addressing over g_seen, 0 = empty, else index + 1; size 2 * g_capseen */

static size_t glc_text_hash(const char *vs, const char *fs, int es)
{
    size_t h = 1469598103u + (size_t)es;
    for (; *vs; ++vs) h = (h ^ (unsigned char)*vs) * 16777619u;
    for (; *fs; ++fs) h = (h ^ (unsigned char)*fs) * 16777619u;
    return h;
}

/* the earlier program with these texts, or NULL */
static glc_seen *glc_find(const char *vs, const char *fs, int es, size_t *slot)
{
    size_t n = 2 * g_capseen, i;
    if (!n) return NULL;
    for (i = glc_text_hash(vs, fs, es) % n; g_hash[i]; i = (i + 1) % n) {
        glc_seen *e = &g_seen[g_hash[i] - 1];
        if (e->es == es && strcmp(e->vs, vs) == 0 && strcmp(e->fs, fs) == 0) return e;
    }
    *slot = i;
    return NULL;
}

/* keeps the texts (taken over) and the result; grows the table at half load */
static void glc_remember(char *vs, char *fs, int es, int ok, int logged, const char *log)
{
    size_t slot = 0, i;
    if (2 * (g_nseen + 1) > g_capseen) {
        size_t cap = g_capseen ? 2 * g_capseen : 1024;
        g_seen = (glc_seen *)realloc(g_seen, cap * sizeof *g_seen);
        free(g_hash);
        g_hash = (size_t *)calloc(2 * cap, sizeof *g_hash);
        g_capseen = cap;
        for (i = 0; i < g_nseen; ++i) {
            glc_find(g_seen[i].vs, g_seen[i].fs, g_seen[i].es, &slot);
            g_hash[slot] = i + 1;
        }
    }
    glc_find(vs, fs, es, &slot);
    g_seen[g_nseen].vs = vs;
    g_seen[g_nseen].fs = fs;
    g_seen[g_nseen].es = es;
    g_seen[g_nseen].ok = ok;
    g_seen[g_nseen].logged = logged;
    g_seen[g_nseen].log = strdup(log);
    g_hash[slot] = ++g_nseen;
}

static int glc_is_es(const char *name)
{
    return strstr(name, "_100.") || strstr(name, "_100_") || strstr(name, "_300es");
}

/* the vertex shader of X.frag: X.vert, or without "_ms" for a per-sample program */
static char *glc_vertex(const char *dir, const char *frag)
{
    char path[1024], base[512];
    const char *ms;
    char *s;
    size_t n = strlen(frag) - 5; /* without ".frag" */
    if (n >= sizeof base) return NULL;
    memcpy(base, frag, n);
    base[n] = 0;
    snprintf(path, sizeof path, "%s/%s.vert", dir, base);
    if ((s = glc_read(path)) != NULL) return s;
    if ((ms = strstr(base, "_ms")) == NULL) return NULL;
    snprintf(path, sizeof path, "%s/%.*s%s.vert", dir, (int)(ms - base), base, ms + 3);
    return glc_read(path);
}

int main(int argc, char **argv)
{
    static const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT | EGL_OPENGL_ES3_BIT, EGL_NONE};
    static const EGLint pb_attr[] = {EGL_WIDTH, 16, EGL_HEIGHT, 16, EGL_NONE};
    static char log[8192];
    glc_ctx ctx[2];
    EGLConfig cfg;
    EGLint n = 0;
    DIR *d;
    struct dirent *e;
    int passed = 0, failed = 0, skipped = 0, logs = 0, cur = -1, reused = 0;
    if (argc != 2) {
        fprintf(stderr, "usage: %s DIR (the shaders dump_shaders wrote)\n", argv[0]);
        return 2;
    }
    g_dpy = glu_egl_display();
    if (g_dpy == EGL_NO_DISPLAY) return !glc_fail("eglInitialize");
    if (!eglChooseConfig(g_dpy, cfg_attr, &cfg, 1, &n) || n < 1) return !glc_fail("eglChooseConfig");
    if ((g_surf = eglCreatePbufferSurface(g_dpy, cfg, pb_attr)) == EGL_NO_SURFACE)
        return !glc_fail("eglCreatePbufferSurface");
    if (!glc_context(&ctx[0], 0, cfg) || !glc_context(&ctx[1], 1, cfg)) return 1;
    if (!(d = opendir(argv[1]))) {
        fprintf(stderr, "gl_compile: cannot open %s\n", argv[1]);
        return 1;
    }
    while ((e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        char path[1024], *fs, *vs;
        int es, logged = 0, ok;
        if (len < 6 || strcmp(e->d_name + len - 5, ".frag") != 0) continue;
        es = glc_is_es(e->d_name) != 0;
        if (cur != es) {
            eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API);
            if (!eglMakeCurrent(g_dpy, g_surf, g_surf, ctx[es].ctx)) return !glc_fail("eglMakeCurrent");
            cur = es;
        }
        snprintf(path, sizeof path, "%s/%s", argv[1], e->d_name);
        fs = glc_read(path);
        if (fs && !ctx[es].fetch && strstr(fs, "#extension GL_EXT_shader_framebuffer_fetch")) {
            printf("ok %d - %s # SKIP %s: no EXT_shader_framebuffer_fetch\n", passed + failed + skipped + 1,
                   e->d_name, ctx[es].what);
            ++skipped;
            free(fs);
            continue;
        }
        vs = glc_vertex(argv[1], e->d_name);
        if (fs && vs) {
            size_t slot;
            const glc_seen *seen = glc_find(vs, fs, es, &slot);
            if (seen) { /* the same program as an earlier file: its result */
                ok = seen->ok;
                logged = seen->logged;
                snprintf(log, sizeof log, "%s", seen->log);
                ++reused;
                free(vs);
                free(fs);
            } else {
                ok = glc_program(&ctx[es].gl, vs, fs, log, (int)sizeof log, &logged);
                glc_remember(vs, fs, es, ok, logged, log);
            }
            vs = fs = NULL; /* (kept by the table, or freed) */
        } else {
            ok = 0;
            snprintf(log, sizeof log, "missing %s shader file", fs ? "vertex" : "fragment");
        }
        if (ok) {
            printf("ok %d - %s\n", passed + failed + skipped + 1, e->d_name);
            ++passed;
        } else {
            printf("not ok %d - %s (%s): %s\n", passed + failed + skipped + 1, e->d_name, ctx[es].what, log);
            ++failed;
        }
        if (ok && logged && logs++ < 5) printf("log - %s: %s\n", e->d_name, log);
        free(fs);
        free(vs);
    }
    closedir(d);
    printf("%d of the programs that linked had a non-empty driver log; %d skipped; %d linked, %d the same texts "
           "as an earlier file\n", logs, skipped, (int)g_nseen, reused);
    while (g_nseen > 0) {
        --g_nseen;
        free(g_seen[g_nseen].vs);
        free(g_seen[g_nseen].fs);
        free(g_seen[g_nseen].log);
    }
    free(g_seen);
    free(g_hash);
    printf("%d passed, %d failed\n", passed, failed);
    eglMakeCurrent(g_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglTerminate(g_dpy);
    return failed > 0;
}
