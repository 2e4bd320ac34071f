/* egl_util.h - headless OpenGL ES contexts for fogvol tests: Mesa's EGL
   surfaceless platform (llvmpipe), no window, no display. The context renders
   into a framebuffer object the helper creates (RGBA8 colour texture + depth /
   stencil), which stays bound as "the engine's framebuffer".

   A real OpenGL ES 2.0 context comes from Mesa through
   MESA_GLES_VERSION_OVERRIDE=2.0, which Mesa reads when it loads its driver
   (at the first eglInitialize of the process). Header-only, one translation
   unit per program (it defines dlclose); needs _POSIX_C_SOURCE >= 200112L (setenv) and
   links -lEGL -lGLESv2. */
#ifndef EGL_UTIL_H
#define EGL_UTIL_H

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <GLES2/gl2ext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct eglu_ctx {
    EGLDisplay dpy;
    EGLContext ctx;
    int major, minor;    /* from GL_VERSION */
    GLuint fbo, color;   /* the engine framebuffer and its RGBA8 colour texture */
    GLuint depth_tex;    /* ES 3: DEPTH24_STENCIL8 texture (depth + stencil attachments) */
    GLuint depth_rb;     /* ES 2: DEPTH24_STENCIL8_OES renderbuffer */
    int width, height;
    char error[256];     /* why eglu_create failed */
} eglu_ctx;

/* Mesa loads its driver on eglInitialize and unloads it on eglTerminate, so
   the few hundred bytes the driver never frees would reach LeakSanitizer from
   an unknown module (no name to suppress). Modules stay loaded instead: every
   dlclose in the process (Mesa's included) resolves to this one. Mesa's
   driver reads MESA_GLES_VERSION_OVERRIDE once per load, so a process then
   gets contexts of one kind only: run ES 2.0 and ES 3.x in separate processes. */
int dlclose(void *handle);
int dlclose(void *handle)
{
    (void)handle;
    return 0;
}

static inline void (*eglu_proc(const char *name, void *user))(void)
{
    (void)user;
    return (void (*)(void))eglGetProcAddress(name);
}

static inline int eglu_fail(eglu_ctx *c, const char *what)
{
    snprintf(c->error, sizeof c->error, "%s failed (EGL error 0x%x, GL error 0x%x)", what, (unsigned)eglGetError(),
             c->ctx ? (unsigned)glGetError() : 0u);
    return 0;
}

/* The engine framebuffer: colour texture + packed depth/stencil, bound. */
static inline int eglu_framebuffer(eglu_ctx *c)
{
    glGenTextures(1, &c->color);
    glBindTexture(GL_TEXTURE_2D, c->color);
    glTexImage2D(GL_TEXTURE_2D, 0, c->major >= 3 ? GL_RGBA8 : GL_RGBA, c->width, c->height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glGenFramebuffers(1, &c->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, c->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, c->color, 0);
    if (c->major >= 3) {
        glGenTextures(1, &c->depth_tex);
        glBindTexture(GL_TEXTURE_2D, c->depth_tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH24_STENCIL8, c->width, c->height, 0, GL_DEPTH_STENCIL,
                     GL_UNSIGNED_INT_24_8, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, c->depth_tex, 0);
    } else {
        glGenRenderbuffers(1, &c->depth_rb);
        glBindRenderbuffer(GL_RENDERBUFFER, c->depth_rb);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8_OES, c->width, c->height);
        glBindRenderbuffer(GL_RENDERBUFFER, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, c->depth_rb);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_STENCIL_ATTACHMENT, GL_RENDERBUFFER, c->depth_rb);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) return eglu_fail(c, "engine framebuffer");
    glViewport(0, 0, c->width, c->height);
    return 1;
}

/* es_version: "2.0" for a real ES 2.0 context (Mesa's override), NULL for the
   highest ES 3.x the driver offers, or "3.0"/"3.1" to cap it. Returns 0 with
   c->error set when there is no EGL device or no such context. */
static inline int eglu_create(eglu_ctx *c, const char *es_version, int width, int height)
{
    EGLint major = 0, minor = 0;
    EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION, 2, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
    const char *ver;
    memset(c, 0, sizeof *c);
    c->width = width;
    c->height = height;
    if (es_version) setenv("MESA_GLES_VERSION_OVERRIDE", es_version, 1);
    else unsetenv("MESA_GLES_VERSION_OVERRIDE");
    c->dpy = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, (void *)EGL_DEFAULT_DISPLAY, NULL);
    if (c->dpy == EGL_NO_DISPLAY) return eglu_fail(c, "eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA)");
    if (!eglInitialize(c->dpy, &major, &minor)) {
        c->dpy = EGL_NO_DISPLAY;
        return eglu_fail(c, "eglInitialize (surfaceless)");
    }
    unsetenv("MESA_GLES_VERSION_OVERRIDE");
    if (!strstr(eglQueryString(c->dpy, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
        return eglu_fail(c, "EGL_KHR_surfaceless_context");
    if (!eglBindAPI(EGL_OPENGL_ES_API)) return eglu_fail(c, "eglBindAPI(EGL_OPENGL_ES_API)");
    if (!es_version || es_version[0] != '2') attr[1] = 3;
    c->ctx = eglCreateContext(c->dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attr);
    if (c->ctx == EGL_NO_CONTEXT) return eglu_fail(c, "eglCreateContext (no config)");
    if (!eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, c->ctx)) return eglu_fail(c, "eglMakeCurrent");
    ver = (const char *)glGetString(GL_VERSION);
    if (!ver || sscanf(ver, "OpenGL ES %d.%d", &c->major, &c->minor) != 2) return eglu_fail(c, "GL_VERSION");
    return eglu_framebuffer(c);
}

static inline void eglu_destroy(eglu_ctx *c)
{
    if (c->ctx != EGL_NO_CONTEXT && c->dpy != EGL_NO_DISPLAY) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        if (c->fbo) glDeleteFramebuffers(1, &c->fbo);
        if (c->color) glDeleteTextures(1, &c->color);
        if (c->depth_tex) glDeleteTextures(1, &c->depth_tex);
        if (c->depth_rb) glDeleteRenderbuffers(1, &c->depth_rb);
        eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c->dpy, c->ctx);
    }
    if (c->dpy != EGL_NO_DISPLAY) eglTerminate(c->dpy);
    eglReleaseThread();
    memset(c, 0, sizeof *c);
}
#endif
