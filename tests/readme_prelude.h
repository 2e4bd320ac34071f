/* readme_prelude.h - the stand-ins README.md's code blocks use, so that
   tests/readme_blocks.sh can compile every block as written (declarations only:
   the blocks are compiled, not linked). Included after the block's own
   #define/#include lines. */
#ifndef README_PRELUDE_H
#define README_PRELUDE_H
#include <string.h>
#include <stdint.h>
#include "fogvol.h"
#ifdef __cplusplus
extern "C" {
#endif
fogvol_gl_proc my_get_proc(const char *name, void *user_data); /* your GL loader */
fogvol_gl_proc glfwGetProcAddress(const char *procname); /* GLFW's (GLFWglproc is void (*)(void)) */
extern const float verts[];       /* xyz per vertex */
extern const uint32_t idx[];      /* 3 per triangle */
extern const int nv, ni;          /* vertex and index counts */
extern float view[16], proj[16], model[16], ground_model[16];
extern int w, h;                  /* framebuffer size */
extern fogvol_mesh *ground;       /* an occluder mesh */
#ifdef __cplusplus
}
#endif
#endif
