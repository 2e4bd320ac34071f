/* gl_util.h - GL contexts, matrices and PNG output for fogvol tests and examples.
   Header-only. Contexts come from OSMesa (llvmpipe; link -lOSMesa, not -lGL:
   direct gl* calls must reach OSMesa) or, built with -DGLU_EGL, from any EGL
   device through glvnd (a GPU driver; link -lEGL -lOpenGL): the same
   glu_ctx, whose framebuffer 0 is then a pbuffer of the same size. Read the
   framebuffer's pixels through glu_pixels, which works with both. */
#ifndef GL_UTIL_H
#define GL_UTIL_H

#ifdef GLU_EGL
#include <EGL/egl.h>
#include <EGL/eglext.h>
#else
#include <GL/osmesa.h>
#endif
#include <GL/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct glu_ctx {
#ifdef GLU_EGL
    EGLDisplay dpy;
    EGLContext ctx;
    EGLSurface surf;
#else
    OSMesaContext ctx;
#endif
    unsigned char *pixels; /* RGBA, first row = bottom (OSMesa renders into it; EGL: glu_pixels fills it) */
    int width, height;
} glu_ctx;

#ifdef GLU_EGL
/* The display of EGL device FOGVOL_EGL_DEVICE (default 0; EGL_EXT_platform_device), else the
   default display; initialised once per process and kept. */
static inline EGLDisplay glu_egl_display(void)
{
    static EGLDisplay dpy = EGL_NO_DISPLAY;
    PFNEGLQUERYDEVICESEXTPROC query;
    PFNEGLGETPLATFORMDISPLAYEXTPROC get;
    EGLDeviceEXT dev[16];
    EGLint n = 0, major, minor;
    const char *pick = getenv("FOGVOL_EGL_DEVICE");
    int want = pick ? atoi(pick) : 0;
    if (dpy != EGL_NO_DISPLAY) return dpy;
    query = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    get = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (query && get && query(16, dev, &n) && n > 0)
        dpy = get(EGL_PLATFORM_DEVICE_EXT, dev[want >= 0 && want < n ? want : 0], NULL);
    if (dpy == EGL_NO_DISPLAY) dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (dpy != EGL_NO_DISPLAY && !eglInitialize(dpy, &major, &minor)) dpy = EGL_NO_DISPLAY;
    return dpy;
}

/* core = 1: the highest core profile from 4.6 down to 3.3 (as Mesa gives 4.5 core for 3.3 where a
   driver may give exactly 3.3), or exactly the version FOGVOL_EGL_CORE names ("3.3": what many
   engines ask for); 0: compatibility profile. Framebuffer 0: a width x height pbuffer, RGBA8 +
   depth 24 + stencil 8, single-sample, like the OSMesa buffer. */
static inline int glu_create(glu_ctx *c, int width, int height, int core)
{
    static const EGLint cfg_attr[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                      EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                                      EGL_DEPTH_SIZE, 24, EGL_STENCIL_SIZE, 8, EGL_SAMPLE_BUFFERS, 0, EGL_NONE};
    static const int versions[][2] = {{4, 6}, {4, 5}, {4, 3}, {4, 1}, {4, 0}, {3, 3}};
    EGLint core_attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                          EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    const char *want = getenv("FOGVOL_EGL_CORE");
    int v, first = 0, count = (int)(sizeof versions / sizeof versions[0]);
    const EGLint compat_attr[] = {EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT,
                                  EGL_NONE};
    const EGLint pb_attr[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
    EGLConfig cfg;
    EGLint n = 0;
    memset(c, 0, sizeof *c);
    c->width = width;
    c->height = height;
    c->dpy = glu_egl_display();
    if (c->dpy == EGL_NO_DISPLAY || !eglBindAPI(EGL_OPENGL_API)) return 0;
    if (!eglChooseConfig(c->dpy, cfg_attr, &cfg, 1, &n) || n < 1) return 0;
    if ((c->surf = eglCreatePbufferSurface(c->dpy, cfg, pb_attr)) == EGL_NO_SURFACE) return 0;
    if (want) /* exactly this one */
        for (v = 0; v < count; ++v)
            if (want[0] - '0' == versions[v][0] && want[1] == '.' && want[2] - '0' == versions[v][1]) {
                first = v;
                count = v + 1;
            }
    for (v = first; v < count && c->ctx == EGL_NO_CONTEXT; ++v) {
        core_attr[1] = versions[v][0];
        core_attr[3] = versions[v][1];
        c->ctx = eglCreateContext(c->dpy, cfg, EGL_NO_CONTEXT, core ? core_attr : compat_attr);
        if (!core) break;
    }
    if (c->ctx == EGL_NO_CONTEXT) return 0;
    c->pixels = (unsigned char *)calloc((size_t)width * height, 4);
    return c->pixels && eglMakeCurrent(c->dpy, c->surf, c->surf, c->ctx);
}

static inline void glu_destroy(glu_ctx *c)
{
    if (c->dpy != EGL_NO_DISPLAY) {
        eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (c->ctx != EGL_NO_CONTEXT) eglDestroyContext(c->dpy, c->ctx);
        if (c->surf != EGL_NO_SURFACE) eglDestroySurface(c->dpy, c->surf);
    }
    free(c->pixels);
    memset(c, 0, sizeof *c);
}

static inline void (*glu_proc(const char *name, void *user))(void)
{
    (void)user;
    return (void (*)(void))eglGetProcAddress(name);
}

/* Makes c current (several contexts in one test); the current context as an opaque id
   (fogvol_gl_desc.current_context). */
static inline int glu_make_current(glu_ctx *c) { return eglMakeCurrent(c->dpy, c->surf, c->surf, c->ctx) != 0; }
static inline void *glu_current_context(void *user)
{
    (void)user;
    return (void *)eglGetCurrentContext();
}

/* Framebuffer 0's pixels after glFinish: read back into c->pixels with the GL state the read
   touches (read framebuffer, pack buffer, pack alignment and row length) put back as it was. */
static inline unsigned char *glu_pixels(glu_ctx *c)
{
    typedef void (*bind_fn)(GLenum, GLuint);
    bind_fn bind_fb = (bind_fn)eglGetProcAddress("glBindFramebuffer"),
            bind_buf = (bind_fn)eglGetProcAddress("glBindBuffer");
    GLint fb = 0, buf = 0, align = 4, row = 0;
    glFinish();
    glGetIntegerv(0x8CAA /* GL_READ_FRAMEBUFFER_BINDING */, &fb);
    glGetIntegerv(0x88ED /* GL_PIXEL_PACK_BUFFER_BINDING */, &buf);
    glGetIntegerv(GL_PACK_ALIGNMENT, &align);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &row);
    bind_fb(0x8CA8 /* GL_READ_FRAMEBUFFER */, 0);
    bind_buf(0x88EB /* GL_PIXEL_PACK_BUFFER */, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glReadPixels(0, 0, c->width, c->height, GL_RGBA, GL_UNSIGNED_BYTE, c->pixels);
    bind_fb(0x8CA8, (GLuint)fb);
    bind_buf(0x88EB, (GLuint)buf);
    glPixelStorei(GL_PACK_ALIGNMENT, align);
    glPixelStorei(GL_PACK_ROW_LENGTH, row);
    return c->pixels;
}
#else
/* core = 1: 3.3 core profile; 0: compatibility profile (Mesa gives 4.5 compat either way). */
static inline int glu_create(glu_ctx *c, int width, int height, int core)
{
    int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                     OSMESA_PROFILE, core ? OSMESA_CORE_PROFILE : OSMESA_COMPAT_PROFILE,
                     OSMESA_CONTEXT_MAJOR_VERSION, core ? 3 : 2, OSMESA_CONTEXT_MINOR_VERSION, core ? 3 : 1, 0};
    memset(c, 0, sizeof *c);
    c->ctx = OSMesaCreateContextAttribs(attribs, NULL);
    if (!c->ctx) return 0;
    c->pixels = (unsigned char *)calloc((size_t)width * height, 4);
    c->width = width;
    c->height = height;
    if (!c->pixels || !OSMesaMakeCurrent(c->ctx, c->pixels, GL_UNSIGNED_BYTE, width, height)) return 0;
    OSMesaPixelStore(OSMESA_Y_UP, 1);
    return 1;
}

static inline void glu_destroy(glu_ctx *c)
{
    if (c->ctx) OSMesaDestroyContext(c->ctx);
    free(c->pixels);
    memset(c, 0, sizeof *c);
}

static inline void (*glu_proc(const char *name, void *user))(void)
{
    (void)user;
    return (void (*)(void))OSMesaGetProcAddress(name);
}

/* Makes c current (several contexts in one test); the current context as an opaque id
   (fogvol_gl_desc.current_context). */
static inline int glu_make_current(glu_ctx *c)
{
    return OSMesaMakeCurrent(c->ctx, c->pixels, GL_UNSIGNED_BYTE, c->width, c->height) != 0;
}
static inline void *glu_current_context(void *user)
{
    (void)user;
    return (void *)OSMesaGetCurrentContext();
}

/* Framebuffer 0's pixels after glFinish (OSMesa renders into c->pixels) */
static inline unsigned char *glu_pixels(glu_ctx *c)
{
    glFinish();
    return c->pixels;
}
#endif

/* 1 when the current context lists extension name (GL 3+: glGetStringi; before: the one string) */
static inline int glu_has_ext(const char *name)
{
    typedef const GLubyte *(*stringi_fn)(GLenum, GLuint);
    stringi_fn stringi = (stringi_fn)glu_proc("glGetStringi", NULL);
    const char *all;
    GLint n = 0, i;
    glGetIntegerv(0x821D /* GL_NUM_EXTENSIONS */, &n);
    if (stringi && glGetError() == GL_NO_ERROR && n > 0) {
        for (i = 0; i < n; ++i)
            if (strcmp((const char *)stringi(GL_EXTENSIONS, (GLuint)i), name) == 0) return 1;
        return 0;
    }
    all = (const char *)glGetString(GL_EXTENSIONS);
    if (!all) return 0;
    for (; (all = strstr(all, name)) != NULL; all += strlen(name))
        if (all[strlen(name)] == ' ' || all[strlen(name)] == '\0') return 1;
    return 0;
}

/* 1 when the current context has framebuffer fetch (EXT_shader_framebuffer_fetch: what fogvol's
   FRAMEBUFFER_FETCH and EXACT_SUM speed-ups need; Mesa has it, NVIDIA's desktop driver does not) */
static inline int glu_has_fetch(void) { return glu_has_ext("GL_EXT_shader_framebuffer_fetch"); }

/* column-major matrices, OpenGL conventions */
static inline void glu_identity(float m[16])
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
}

static inline void glu_translate_scale(float m[16], float tx, float ty, float tz, float s)
{
    glu_identity(m);
    m[0] = m[5] = m[10] = s;
    m[12] = tx;
    m[13] = ty;
    m[14] = tz;
}

static inline void glu_look_at(float m[16], const double eye[3], const double at[3], const double up[3])
{
    double f[3], s[3], u[3], n;
    int i;
    for (i = 0; i < 3; ++i) f[i] = at[i] - eye[i];
    n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (i = 0; i < 3; ++i) f[i] /= n;
    s[0] = f[1] * up[2] - f[2] * up[1];
    s[1] = f[2] * up[0] - f[0] * up[2];
    s[2] = f[0] * up[1] - f[1] * up[0];
    n = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (i = 0; i < 3; ++i) s[i] /= n;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    glu_identity(m);
    for (i = 0; i < 3; ++i) {
        m[i * 4 + 0] = (float)s[i];
        m[i * 4 + 1] = (float)u[i];
        m[i * 4 + 2] = (float)-f[i];
    }
    m[12] = (float)-(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    m[13] = (float)-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    m[14] = (float)(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
}

static inline void glu_perspective(float m[16], double fovy_deg, double aspect, double n, double f)
{
    double t = 1.0 / tan(fovy_deg * 3.14159265358979323846 / 360.0);
    memset(m, 0, 16 * sizeof(float));
    m[0] = (float)(t / aspect);
    m[5] = (float)t;
    m[10] = (float)((f + n) / (n - f));
    m[11] = -1.0f;
    m[14] = (float)(2.0 * f * n / (n - f));
}
#endif
