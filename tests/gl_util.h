/* gl_util.h - OSMesa contexts, matrices and PNG output for fogvol tests and examples.
   Header-only; link -lOSMesa (not -lGL: direct gl* calls must reach OSMesa). */
#ifndef GL_UTIL_H
#define GL_UTIL_H

#include <GL/osmesa.h>
#include <GL/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct glu_ctx {
    OSMesaContext ctx;
    unsigned char *pixels; /* RGBA, first row = bottom */
    int width, height;
} glu_ctx;

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
