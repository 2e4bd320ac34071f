/* example_mesh.h - the mesh helpers fogvol's examples share (header-only, C99 / C++11).

   Include it after fogvol.h, tests/shapes.h and the program's GL header (desktop GL with
   GL_GLEXT_PROTOTYPES, OSMesa, or GLES2/WebGL): the GL helper is compiled only where
   GL_ARRAY_BUFFER is declared.

     exm_fog_mesh     a shp_mesh handed to fogvol_create_mesh (shared vertices and
                      indices, as they are); NULL and a message on stderr when refused
     exm_upload_flat  a shp_mesh expanded to flat-shaded triangles (position, face normal:
                      shp_flat_vertices) and uploaded into the bound engine's buffer */
#ifndef EXAMPLE_MESH_H
#define EXAMPLE_MESH_H

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
#endif

#endif
