/* example_gl.h - the helpers fogvol's examples share (header-only, C99 / C++11).

   Include it after fogvol.h, tests/shapes.h and the program's GL header (desktop GL with
   GL_GLEXT_PROTOTYPES, OSMesa, or GLES2/WebGL): the GL helpers are compiled only where
   GL_ARRAY_BUFFER is declared.

     exm_fog_mesh     a shp_mesh handed to fogvol_create_mesh (shared vertices and
                      indices, as they are); NULL and a message on stderr when refused
     exm_upload_flat  a shp_mesh expanded to flat-shaded triangles (position, face normal:
                      shp_flat_vertices) and uploaded into an engine's buffer
     exm_program      an engine's GLSL program; 0 and the info log on stderr on failure */
#ifndef EXAMPLE_GL_H
#define EXAMPLE_GL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* allow_open: 1 for occluder meshes that need not be closed (fogvol_mesh_desc.allow_open) */
static inline fogvol_mesh *exm_fog_mesh(fogvol_context *fv, const shp_mesh *m, int allow_open)
{
    fogvol_mesh_desc md;
    fogvol_mesh *out = NULL;
    fogvol_result r;
    memset(&md, 0, sizeof md);
    md.positions = m->pos;
    md.vertex_count = m->vcount;
    md.indices = (const uint32_t *)m->idx;
    md.index_count = m->icount;
    md.allow_open = allow_open;
    r = fogvol_create_mesh(fv, &md, &out, NULL);
    if (r != FOGVOL_SUCCESS) fprintf(stderr, "fogvol: mesh refused: %s\n", fogvol_result_string(r));
    return out;
}

#ifdef GL_ARRAY_BUFFER
/* Fills buffer vbo with m's flat-shaded triangles (6 floats a corner: position, then the
   face normal; world space when model != NULL, see shp_flat_vertices) and leaves it bound
   to GL_ARRAY_BUFFER. usage: GL_STATIC_DRAW, GL_STREAM_DRAW, ... Returns the number of
   vertices to draw (m->icount), 0 on allocation failure (the buffer is then untouched). */
static inline int exm_upload_flat(GLuint vbo, const shp_mesh *m, const float *model, GLenum usage)
{
    float *v = shp_flat_vertices(m, model);
    if (!v) return 0;
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 6 * (size_t)m->icount), v, usage);
    free(v);
    return m->icount;
}

/* A program of a vertex shader and a fragment shader made of nfs strings (compiled as one
   source, e.g. a shared prelude and a body); attribs (NULL-terminated, or NULL) are bound
   to locations 0, 1, ... before linking, for GLSL without layout qualifiers. On a compile
   or link failure the info logs go to stderr after "who: " and 0 is returned. */
static inline GLuint exm_program(const char *who, const char *vs, const char *const *fs, int nfs,
                                 const char *const *attribs)
{
    GLuint p = glCreateProgram(), sh[2];
    GLint ok = 1, part;
    char log[2048];
    int i;
    sh[0] = glCreateShader(GL_VERTEX_SHADER);
    sh[1] = glCreateShader(GL_FRAGMENT_SHADER);
    glShaderSource(sh[0], 1, &vs, NULL);
    glShaderSource(sh[1], nfs, fs, NULL);
    for (i = 0; i < 2; ++i) {
        glCompileShader(sh[i]);
        glGetShaderiv(sh[i], GL_COMPILE_STATUS, &part);
        if (!part) {
            glGetShaderInfoLog(sh[i], sizeof log, NULL, log);
            fprintf(stderr, "%s: %s shader: %s\n", who, i ? "fragment" : "vertex", log);
            ok = 0;
        }
        glAttachShader(p, sh[i]);
    }
    for (i = 0; attribs && attribs[i]; ++i) glBindAttribLocation(p, (GLuint)i, attribs[i]);
    glLinkProgram(p);
    glDeleteShader(sh[0]);
    glDeleteShader(sh[1]);
    glGetProgramiv(p, GL_LINK_STATUS, &part);
    if (ok && !part) {
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        fprintf(stderr, "%s: program: %s\n", who, log);
    }
    if (!ok || !part) {
        glDeleteProgram(p);
        return 0;
    }
    return p;
}
#endif

#endif
