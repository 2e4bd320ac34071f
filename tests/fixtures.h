/* fixtures.h - GL helpers the cmocka test programs share: the engine's shaders and
 * program, its colour + depth framebuffer, a mesh desc of a generated shape, a frame
 * looking through a test camera, and the sequence runner (tests/sequence.h: a test as
 * frames in which the camera, occluders, viewport and views change, each checked).
 * Include after <cmocka.h>, fogvol.h and tests/gl_util.h. A failure
 * fails the running cmocka test (fail_msg / assert_*). The GL helpers are there when
 * the program has the GL 3 prototypes (GL_GLEXT_PROTOTYPES and <GL/glext.h>); the shader
 * helpers also with the GLES headers. */
#ifndef FOGVOL_TESTS_FIXTURES_H
#define FOGVOL_TESTS_FIXTURES_H

#include <string.h>
#include "tests/raycast.h"
#include "tests/shapes.h"
#include "tests/sequence.h"

#if (defined(GL_GLEXT_PROTOTYPES) && defined(GL_GLEXT_VERSION)) || defined(GL_ES_VERSION_2_0)
/* one shader stage from n strings; the test fails with the info log when it does not compile */
static inline GLuint fx_compile(GLenum type, const char *const *src, int n)
{
    GLint ok = 0;
    GLuint sh = glCreateShader(type);
    glShaderSource(sh, n, src, NULL);
    glCompileShader(sh);
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024];
        glGetShaderInfoLog(sh, sizeof log, NULL, log);
        fail_msg("engine shader: %s", log);
    }
    return sh;
}

/* a program of a vertex shader (nvs strings) and a fragment shader (nfs strings); the test fails
   when it does not link */
static inline GLuint fx_program(const char *const *vs, int nvs, const char *const *fs, int nfs)
{
    GLint ok = 0;
    GLuint prog = glCreateProgram();
    glAttachShader(prog, fx_compile(GL_VERTEX_SHADER, vs, nvs));
    glAttachShader(prog, fx_compile(GL_FRAGMENT_SHADER, fs, nfs));
    glLinkProgram(prog);
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    assert_true(ok);
    return prog;
}
#endif

#if defined(GL_GLEXT_PROTOTYPES) && defined(GL_GLEXT_VERSION)

/* an RGBA8 colour texture and a depth texture (depth_format, read as depth_type), both nearest-
   filtered, attached to a new framebuffer, which is left bound; the test fails when it is incomplete */
static inline void fx_color_depth_fbo(int w, int h, GLenum depth_format, GLenum depth_type, GLuint *color,
                                      GLuint *depth, GLuint *fbo)
{
    glGenTextures(1, color);
    glBindTexture(GL_TEXTURE_2D, *color);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glGenTextures(1, depth);
    glBindTexture(GL_TEXTURE_2D, *depth);
    glTexImage2D(GL_TEXTURE_2D, 0, (GLint)depth_format, w, h, 0, GL_DEPTH_COMPONENT, depth_type, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, *color, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, *depth, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
}
#endif

/* a mesh desc of the shape's positions and indices (allow_open as given); every other field 0 */
static inline void fx_mesh_desc(fogvol_mesh_desc *md, const shp_mesh *m, int allow_open)
{
    memset(md, 0, sizeof *md);
    md->positions = m->pos;
    md->vertex_count = m->vcount;
    md->indices = (const uint32_t *)m->idx;
    md->index_count = m->icount;
    md->allow_open = allow_open;
}

/* a frame through the camera (its matrices, near and far planes) over a w x h viewport at 0,0;
   every other field 0 */
static inline void fx_frame_desc(fogvol_frame_desc *fd, const rc_camera *cam, int w, int h)
{
    memset(fd, 0, sizeof *fd);
    rc_camera_matrices(cam, fd->view, fd->projection);
    fd->znear = (float)cam->znear;
    fd->zfar = (float)cam->zfar;
    fd->viewport[2] = w;
    fd->viewport[3] = h;
}

#endif
