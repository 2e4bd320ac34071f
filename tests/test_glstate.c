/* test_glstate.c - the GL backend leaves the engine's GL state exactly as it found it.
 *
 * Issue: "GL state: every item is set to non-default values before a frame and read
 * back equal after it". Every item listed below is set to a non-default value (a
 * self-check proves each one really differs from a fresh context), fogvol runs, and
 * the state is read back and compared field by field:
 *   framebuffer bindings (draw and read separately; the draw FBO is the engine's, with
 *   a colour texture and a depth-stencil renderbuffer), renderbuffer binding, viewport,
 *   program, VAO, array buffer, element buffer, attribute 0 (enabled, size, type,
 *   normalized, stride, buffer, pointer), active texture (GL_TEXTURE5), the 2D texture
 *   and sampler bindings of units 0..5, blend enable / func (separate) / equation
 *   (separate), depth test / func / mask, cull enable / mode, front face, colour mask,
 *   scissor enable / box, stencil test, stencil func / ref / value mask / ops / write
 *   mask for front and back, clear colour / depth / stencil, pack and unpack alignment,
 *   row length, skip rows / pixels, pixel pack / unpack buffers, dither, polygon offset
 *   fill, polygon mode, sample alpha-to-coverage, sample coverage, colour logic op (and
 *   its mode), rasterizer discard (its own case), alpha test (compatibility).
 *
 * Cases:
 *   (a) 4.5/3.3 core context: geometry composite and full-screen composite, with an
 *       occluder, a negative volume and a second (light) ramp group, two frames each;
 *   (b) compatibility context treated as GL 2.1 (no VAO: attribute 0 saved/restored,
 *       alpha test), both composites, plus separate read/draw FBO bindings there
 *       (GL_ARB_framebuffer_object gives GL 2.1 both bindings);
 *   (c) resource creation outside a frame (context, meshes, ramps), the first frame
 *       that creates the targets, a resize that recreates them, and destruction;
 *   (d) the engine's stencil (0x35, bits other than the guard bit 0x80) survives a
 *       geometry-composite frame and fog reached the engine colour buffer;
 *   rasterizer discard on before a frame: restored, and fogvol still rendered fog.
 * Every frame must leave glGetError() == GL_NO_ERROR.
 *
 * Build (from the repository root):
 *   gcc -std=c99 -Wall -Wextra -pedantic -Werror -I. tests/test_glstate.c -o build/test_glstate \
 *       -lcmocka -lOSMesa -lm
 *   add -fsanitize=address,undefined and run with
 *   LSAN_OPTIONS=suppressions=tests/lsan.supp (OSMesa leaks a few hundred bytes).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include "tests/fogvol_test.h"
#include "tests/gl_util.h"
#include "tests/shapes.h"
#include "tests/fixtures.h"
#include <GL/glext.h>

#define W 64
#define H 64
#define NUNITS 6 /* texture units checked: fogvol uses 0..3, the engine's active one is 5 */

/* ---- GL entry points above 1.1, loaded through OSMesaGetProcAddress ------ */
#define GLFNS(X) \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers) \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer) \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D) \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer) \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus) \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers) \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer) \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage) \
    X(PFNGLGENBUFFERSPROC, GenBuffers) \
    X(PFNGLBINDBUFFERPROC, BindBuffer) \
    X(PFNGLBUFFERDATAPROC, BufferData) \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray) \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer) \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
    X(PFNGLGETVERTEXATTRIBIVPROC, GetVertexAttribiv) \
    X(PFNGLGETVERTEXATTRIBPOINTERVPROC, GetVertexAttribPointerv) \
    X(PFNGLCREATESHADERPROC, CreateShader) \
    X(PFNGLSHADERSOURCEPROC, ShaderSource) \
    X(PFNGLCOMPILESHADERPROC, CompileShader) \
    X(PFNGLGETSHADERIVPROC, GetShaderiv) \
    X(PFNGLDELETESHADERPROC, DeleteShader) \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram) \
    X(PFNGLATTACHSHADERPROC, AttachShader) \
    X(PFNGLBINDATTRIBLOCATIONPROC, BindAttribLocation) \
    X(PFNGLLINKPROGRAMPROC, LinkProgram) \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv) \
    X(PFNGLUSEPROGRAMPROC, UseProgram) \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram) \
    X(PFNGLISPROGRAMPROC, IsProgram) \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture) \
    X(PFNGLGENSAMPLERSPROC, GenSamplers) \
    X(PFNGLBINDSAMPLERPROC, BindSampler) \
    X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate) \
    X(PFNGLBLENDEQUATIONSEPARATEPROC, BlendEquationSeparate) \
    X(PFNGLSTENCILFUNCSEPARATEPROC, StencilFuncSeparate) \
    X(PFNGLSTENCILOPSEPARATEPROC, StencilOpSeparate) \
    X(PFNGLSTENCILMASKSEPARATEPROC, StencilMaskSeparate)

typedef struct glfns {
#define GLFN_MEMBER(type, name) type name;
    GLFNS(GLFN_MEMBER)
#undef GLFN_MEMBER
} glfns;

static glfns gf;

static void load_gl(void)
{
#define GLFN_LOAD(type, name) \
    gf.name = (type)glu_proc("gl" #name, NULL); \
    if (!gf.name) fail_msg("GL entry point gl%s not found", #name);
    GLFNS(GLFN_LOAD)
#undef GLFN_LOAD
}

static void expect_no_gl_error(const char *where)
{
    GLenum e = glGetError(), first = e;
    int n = 0;
    while (e != GL_NO_ERROR && n < 16) { /* drain, so one failure does not cascade */
        ++n;
        e = glGetError();
    }
    if (first != GL_NO_ERROR) fail_msg("%s: glGetError() = 0x%04x (GL errors left behind)", where, first);
}

/* ---- the snapshot ------------------------------------------------------- */
typedef struct snap {
    GLint draw_fbo, read_fbo, renderbuffer, viewport[4], program, vao, array_buffer, element_buffer;
    GLint attr0_enabled, attr0_size, attr0_type, attr0_normalized, attr0_stride, attr0_buffer;
    void *attr0_pointer;
    GLint active_texture, texture_2d[NUNITS], sampler[NUNITS];
    GLint blend, blend_src_rgb, blend_dst_rgb, blend_src_alpha, blend_dst_alpha, blend_eq_rgb, blend_eq_alpha;
    GLint depth_test, depth_func, depth_mask;
    GLint cull_face, cull_mode, front_face, polygon_mode[2];
    GLint color_mask[4];
    GLint scissor_test, scissor_box[4];
    GLint stencil_test;
    GLint stencil_func, stencil_ref, stencil_value_mask, stencil_fail, stencil_zfail, stencil_zpass,
        stencil_writemask;
    GLint stencil_back_func, stencil_back_ref, stencil_back_value_mask, stencil_back_fail, stencil_back_zfail,
        stencil_back_zpass, stencil_back_writemask;
    GLfloat clear_color[4], clear_depth, blend_color[4];
    GLint clear_stencil;
    GLint unpack_alignment, unpack_row_length, unpack_skip_rows, unpack_skip_pixels;
    GLint pack_alignment, pack_row_length, pack_skip_rows, pack_skip_pixels;
    GLint pixel_unpack_buffer, pixel_pack_buffer;
    GLint dither, polygon_offset_fill, sample_alpha_to_coverage, sample_coverage, color_logic_op, logic_op_mode;
    GLint rasterizer_discard, alpha_test;
} snap;

/* Reads every item; the queries themselves change nothing (the active texture unit
   is put back). compat: the context is a compatibility profile (alpha test exists). */
static void snapshot(snap *s, int compat)
{
    GLint i;
    GLboolean b[4];
    memset(s, 0, sizeof *s);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s->draw_fbo);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s->read_fbo);
    glGetIntegerv(GL_RENDERBUFFER_BINDING, &s->renderbuffer);
    glGetIntegerv(GL_VIEWPORT, s->viewport);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s->vao);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &s->array_buffer);
    glGetIntegerv(GL_ELEMENT_ARRAY_BUFFER_BINDING, &s->element_buffer);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_ENABLED, &s->attr0_enabled);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_SIZE, &s->attr0_size);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_TYPE, &s->attr0_type);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_NORMALIZED, &s->attr0_normalized);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_STRIDE, &s->attr0_stride);
    gf.GetVertexAttribiv(0, GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING, &s->attr0_buffer);
    gf.GetVertexAttribPointerv(0, GL_VERTEX_ATTRIB_ARRAY_POINTER, &s->attr0_pointer);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &s->active_texture);
    for (i = 0; i < NUNITS; ++i) {
        gf.ActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &s->texture_2d[i]);
        glGetIntegerv(GL_SAMPLER_BINDING, &s->sampler[i]);
    }
    gf.ActiveTexture((GLenum)s->active_texture);
    s->blend = glIsEnabled(GL_BLEND);
    glGetIntegerv(GL_BLEND_SRC_RGB, &s->blend_src_rgb);
    glGetIntegerv(GL_BLEND_DST_RGB, &s->blend_dst_rgb);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &s->blend_src_alpha);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &s->blend_dst_alpha);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &s->blend_eq_rgb);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &s->blend_eq_alpha);
    s->depth_test = glIsEnabled(GL_DEPTH_TEST);
    glGetIntegerv(GL_DEPTH_FUNC, &s->depth_func);
    glGetBooleanv(GL_DEPTH_WRITEMASK, b);
    s->depth_mask = b[0];
    s->cull_face = glIsEnabled(GL_CULL_FACE);
    glGetIntegerv(GL_CULL_FACE_MODE, &s->cull_mode);
    glGetIntegerv(GL_FRONT_FACE, &s->front_face);
    s->polygon_mode[1] = -1;
    glGetIntegerv(GL_POLYGON_MODE, s->polygon_mode);
    if (!compat && s->polygon_mode[1] == -1) /* a core profile has one mode for both sides: some GLs return one value */
        s->polygon_mode[1] = s->polygon_mode[0];
    glGetBooleanv(GL_COLOR_WRITEMASK, b);
    for (i = 0; i < 4; ++i) s->color_mask[i] = b[i];
    s->scissor_test = glIsEnabled(GL_SCISSOR_TEST);
    glGetIntegerv(GL_SCISSOR_BOX, s->scissor_box);
    s->stencil_test = glIsEnabled(GL_STENCIL_TEST);
    glGetIntegerv(GL_STENCIL_FUNC, &s->stencil_func);
    glGetIntegerv(GL_STENCIL_REF, &s->stencil_ref);
    glGetIntegerv(GL_STENCIL_VALUE_MASK, &s->stencil_value_mask);
    glGetIntegerv(GL_STENCIL_FAIL, &s->stencil_fail);
    glGetIntegerv(GL_STENCIL_PASS_DEPTH_FAIL, &s->stencil_zfail);
    glGetIntegerv(GL_STENCIL_PASS_DEPTH_PASS, &s->stencil_zpass);
    glGetIntegerv(GL_STENCIL_WRITEMASK, &s->stencil_writemask);
    glGetIntegerv(GL_STENCIL_BACK_FUNC, &s->stencil_back_func);
    glGetIntegerv(GL_STENCIL_BACK_REF, &s->stencil_back_ref);
    glGetIntegerv(GL_STENCIL_BACK_VALUE_MASK, &s->stencil_back_value_mask);
    glGetIntegerv(GL_STENCIL_BACK_FAIL, &s->stencil_back_fail);
    glGetIntegerv(GL_STENCIL_BACK_PASS_DEPTH_FAIL, &s->stencil_back_zfail);
    glGetIntegerv(GL_STENCIL_BACK_PASS_DEPTH_PASS, &s->stencil_back_zpass);
    glGetIntegerv(GL_STENCIL_BACK_WRITEMASK, &s->stencil_back_writemask);
    glGetFloatv(GL_COLOR_CLEAR_VALUE, s->clear_color);
    glGetFloatv(GL_BLEND_COLOR, s->blend_color);
    glGetFloatv(GL_DEPTH_CLEAR_VALUE, &s->clear_depth);
    glGetIntegerv(GL_STENCIL_CLEAR_VALUE, &s->clear_stencil);
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &s->unpack_alignment);
    glGetIntegerv(GL_UNPACK_ROW_LENGTH, &s->unpack_row_length);
    glGetIntegerv(GL_UNPACK_SKIP_ROWS, &s->unpack_skip_rows);
    glGetIntegerv(GL_UNPACK_SKIP_PIXELS, &s->unpack_skip_pixels);
    glGetIntegerv(GL_PACK_ALIGNMENT, &s->pack_alignment);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &s->pack_row_length);
    glGetIntegerv(GL_PACK_SKIP_ROWS, &s->pack_skip_rows);
    glGetIntegerv(GL_PACK_SKIP_PIXELS, &s->pack_skip_pixels);
    glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &s->pixel_unpack_buffer);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &s->pixel_pack_buffer);
    s->dither = glIsEnabled(GL_DITHER);
    s->polygon_offset_fill = glIsEnabled(GL_POLYGON_OFFSET_FILL);
    s->sample_alpha_to_coverage = glIsEnabled(GL_SAMPLE_ALPHA_TO_COVERAGE);
    s->sample_coverage = glIsEnabled(GL_SAMPLE_COVERAGE);
    s->color_logic_op = glIsEnabled(GL_COLOR_LOGIC_OP);
    glGetIntegerv(GL_LOGIC_OP_MODE, &s->logic_op_mode);
    s->rasterizer_discard = glIsEnabled(GL_RASTERIZER_DISCARD);
    if (compat) s->alpha_test = glIsEnabled(GL_ALPHA_TEST);
    expect_no_gl_error("snapshot queries");
}

/* ---- field-by-field comparison ------------------------------------------
   SNAP_DIFF: report every field whose values differ (a = before, b = after).
   SNAP_SAME: report every field still equal to its default (a = fresh context,
   b = engine state), except those named in allow (a space-separated list). */
enum { SNAP_DIFF, SNAP_SAME };
typedef struct snap_cmp {
    int mode;
    const char *allow;
    int count;
    size_t len;
    char msg[6000];
} snap_cmp;

static void cmp_note(snap_cmp *c, const char *fmt, ...)
{
    va_list ap;
    int n;
    ++c->count;
    if (c->len >= sizeof c->msg - 1) return;
    va_start(ap, fmt);
    n = vsnprintf(c->msg + c->len, sizeof c->msg - c->len, fmt, ap);
    va_end(ap);
    if (n > 0) c->len += (size_t)n;
    if (c->len > sizeof c->msg - 1) c->len = sizeof c->msg - 1;
}

static int cmp_allowed(const snap_cmp *c, const char *name)
{
    size_t n = strlen(name);
    const char *p = c->allow;
    if (!p) return 0;
    while ((p = strstr(p, name)) != NULL) {
        if ((p == c->allow || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
        p += n;
    }
    return 0;
}

static void cmp_int(snap_cmp *c, const char *name, int idx, long a, long b)
{
    char full[64];
    if (idx >= 0) snprintf(full, sizeof full, "%s[%d]", name, idx);
    else snprintf(full, sizeof full, "%s", name);
    /* enums and masks read better in hex */
    if (c->mode == SNAP_DIFF && a != b) {
        if (a > 255 || b > 255 || a < 0 || b < 0)
            cmp_note(c, "\n  %s: 0x%lx before, 0x%lx after", full, (unsigned long)a, (unsigned long)b);
        else
            cmp_note(c, "\n  %s: %ld before, %ld after", full, a, b);
    }
    if (c->mode == SNAP_SAME && a == b && !cmp_allowed(c, name))
        cmp_note(c, "\n  %s: still the default 0x%lx", full, (unsigned long)a);
}

static void cmp_float(snap_cmp *c, const char *name, int idx, double a, double b)
{
    char full[64];
    if (idx >= 0) snprintf(full, sizeof full, "%s[%d]", name, idx);
    else snprintf(full, sizeof full, "%s", name);
    if (c->mode == SNAP_DIFF && a != b) cmp_note(c, "\n  %s: %.9g before, %.9g after", full, a, b);
    if (c->mode == SNAP_SAME && a == b && !cmp_allowed(c, name))
        cmp_note(c, "\n  %s: still the default %.9g", full, a);
}

#define CMP_I(f) cmp_int(c, #f, -1, (long)a->f, (long)b->f)
#define CMP_IA(f, n) \
    for (i = 0; i < (n); ++i) cmp_int(c, #f, i, (long)a->f[i], (long)b->f[i])
/* an array counts as non-default when any element differs (colour mask 1,0,1,0) */
#define CMP_IA_WHOLE(f, n) \
    do { \
        int d_ = 0; \
        for (i = 0; i < (n); ++i) d_ |= a->f[i] != b->f[i]; \
        if (c->mode == SNAP_DIFF || !d_) CMP_IA(f, n); \
    } while (0)
#define CMP_F(f) cmp_float(c, #f, -1, (double)a->f, (double)b->f)
#define CMP_FA(f, n) \
    for (i = 0; i < (n); ++i) cmp_float(c, #f, i, (double)a->f[i], (double)b->f[i])

static void snap_walk(snap_cmp *c, const snap *a, const snap *b)
{
    int i;
    CMP_I(draw_fbo); CMP_I(read_fbo); CMP_I(renderbuffer); CMP_IA(viewport, 4);
    CMP_I(program); CMP_I(vao); CMP_I(array_buffer); CMP_I(element_buffer);
    CMP_I(attr0_enabled); CMP_I(attr0_size); CMP_I(attr0_type); CMP_I(attr0_normalized);
    CMP_I(attr0_stride); CMP_I(attr0_buffer);
    cmp_int(c, "attr0_pointer", -1, (long)(intptr_t)a->attr0_pointer, (long)(intptr_t)b->attr0_pointer);
    CMP_I(active_texture); CMP_IA(texture_2d, NUNITS); CMP_IA(sampler, NUNITS);
    CMP_I(blend); CMP_I(blend_src_rgb); CMP_I(blend_dst_rgb); CMP_I(blend_src_alpha); CMP_I(blend_dst_alpha);
    CMP_I(blend_eq_rgb); CMP_I(blend_eq_alpha);
    CMP_I(depth_test); CMP_I(depth_func); CMP_I(depth_mask);
    CMP_I(cull_face); CMP_I(cull_mode); CMP_I(front_face); CMP_IA(polygon_mode, 2);
    CMP_IA_WHOLE(color_mask, 4);
    CMP_I(scissor_test); CMP_IA(scissor_box, 4);
    CMP_I(stencil_test);
    CMP_I(stencil_func); CMP_I(stencil_ref); CMP_I(stencil_value_mask); CMP_I(stencil_fail);
    CMP_I(stencil_zfail); CMP_I(stencil_zpass); CMP_I(stencil_writemask);
    CMP_I(stencil_back_func); CMP_I(stencil_back_ref); CMP_I(stencil_back_value_mask); CMP_I(stencil_back_fail);
    CMP_I(stencil_back_zfail); CMP_I(stencil_back_zpass); CMP_I(stencil_back_writemask);
    CMP_FA(clear_color, 4); CMP_F(clear_depth); CMP_I(clear_stencil); CMP_FA(blend_color, 4);
    CMP_I(unpack_alignment); CMP_I(unpack_row_length); CMP_I(unpack_skip_rows); CMP_I(unpack_skip_pixels);
    CMP_I(pack_alignment); CMP_I(pack_row_length); CMP_I(pack_skip_rows); CMP_I(pack_skip_pixels);
    CMP_I(pixel_unpack_buffer); CMP_I(pixel_pack_buffer);
    CMP_I(dither); CMP_I(polygon_offset_fill); CMP_I(sample_alpha_to_coverage); CMP_I(sample_coverage);
    CMP_I(color_logic_op); CMP_I(logic_op_mode);
    CMP_I(rasterizer_discard); CMP_I(alpha_test);
}

/* Fails (naming every differing field) unless after == before. */
static void expect_same_state(const snap *before, const snap *after, const char *where)
{
    snap_cmp c;
    memset(&c, 0, sizeof c);
    c.mode = SNAP_DIFF;
    snap_walk(&c, before, after);
    if (c.count > 12) print_message("# %s: every changed item:%s\n", where, c.msg); /* fail_msg truncates */
    if (c.count) fail_msg("%s: %d GL state item(s) changed:%s", where, c.count, c.msg);
}

/* Fails unless every field of engine differs from the fresh-context defaults (allow lists the exceptions). */
static void expect_all_nondefault(const snap *defaults, const snap *engine, const char *allow)
{
    snap_cmp c;
    memset(&c, 0, sizeof c);
    c.mode = SNAP_SAME;
    c.allow = allow;
    snap_walk(&c, defaults, engine);
    if (c.count) fail_msg("test setup: %d item(s) not set to a non-default value:%s", c.count, c.msg);
}

/* ---- fixture: GL context, engine objects, fogvol objects ----------------- */
typedef struct fx {
    glu_ctx g;
    int compat; /* compatibility context treated as GL 2.1 by fogvol */
    snap defaults;
    GLuint fbo, fbo_color, fbo_ds;    /* engine draw framebuffer: RGBA8 texture + DEPTH24_STENCIL8 */
    GLuint rfbo, rfbo_color;          /* engine read framebuffer */
    GLuint rb;                        /* the bound renderbuffer (none of the above) */
    GLuint prog, vao, attr_buf, array_buf, elem_buf, unpack_buf, pack_buf;
    GLuint tex[NUNITS], samp[NUNITS];
    fogvol_context *fv;
    shp_mesh s_big, s_small, s_light, s_box;
    fogvol_mesh *m_big, *m_small, *m_light, *m_box;
    fogvol_ramp *r_fog, *r_light;
    float thick[W * H];
    int warnings;
    unsigned variants; /* FOGVOL_VARIANT_ENGINE_DEPTH: FLOAT with the engine's depth, depth-tested (else PS20) */
} fx;

static void fv_log(void *user, fogvol_log_level level, const char *message)
{
    fx *x = (fx *)user;
    if (level <= FOGVOL_LOG_WARNING) {
        ++x->warnings;
        print_message("# fogvol: %s\n", message);
    }
}

static GLuint compile_engine_program(int compat)
{
    static const char *vs330 = "#version 330 core\nlayout(location = 0) in vec3 p;\n"
                               "void main() { gl_Position = vec4(p, 1.0); }\n";
    static const char *fs330 = "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n";
    static const char *vs120 = "#version 120\nattribute vec3 p;\nvoid main() { gl_Position = vec4(p, 1.0); }\n";
    static const char *fs120 = "#version 120\nvoid main() { gl_FragColor = vec4(1.0); }\n";
    GLuint vs = gf.CreateShader(GL_VERTEX_SHADER), fs = gf.CreateShader(GL_FRAGMENT_SHADER), p;
    GLint ok = 0;
    gf.ShaderSource(vs, 1, compat ? &vs120 : &vs330, NULL);
    gf.ShaderSource(fs, 1, compat ? &fs120 : &fs330, NULL);
    gf.CompileShader(vs);
    gf.GetShaderiv(vs, GL_COMPILE_STATUS, &ok);
    assert_true(ok);
    gf.CompileShader(fs);
    gf.GetShaderiv(fs, GL_COMPILE_STATUS, &ok);
    assert_true(ok);
    p = gf.CreateProgram();
    gf.AttachShader(p, vs);
    gf.AttachShader(p, fs);
    gf.BindAttribLocation(p, 0, "p");
    gf.LinkProgram(p);
    gf.GetProgramiv(p, GL_LINK_STATUS, &ok);
    assert_true(ok);
    gf.DeleteShader(vs);
    gf.DeleteShader(fs);
    return p;
}

static void create_engine_objects(fx *x)
{
    int i;
    unsigned char texel[4] = {1, 2, 3, 4};
    glGenTextures(1, &x->fbo_color);
    glBindTexture(GL_TEXTURE_2D, x->fbo_color);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gf.GenRenderbuffers(1, &x->fbo_ds);
    gf.BindRenderbuffer(GL_RENDERBUFFER, x->fbo_ds);
    gf.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, W, H);
    gf.GenFramebuffers(1, &x->fbo);
    gf.BindFramebuffer(GL_FRAMEBUFFER, x->fbo);
    gf.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, x->fbo_color, 0);
    gf.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, x->fbo_ds);
    assert_int_equal(gf.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);

    glGenTextures(1, &x->rfbo_color);
    glBindTexture(GL_TEXTURE_2D, x->rfbo_color);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 8, 8, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gf.GenFramebuffers(1, &x->rfbo);
    gf.BindFramebuffer(GL_FRAMEBUFFER, x->rfbo);
    gf.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, x->rfbo_color, 0);
    assert_int_equal(gf.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gf.BindFramebuffer(GL_FRAMEBUFFER, 0);

    gf.GenRenderbuffers(1, &x->rb);
    gf.BindRenderbuffer(GL_RENDERBUFFER, x->rb);
    gf.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 4, 4);
    gf.BindRenderbuffer(GL_RENDERBUFFER, 0);

    for (i = 0; i < NUNITS; ++i) {
        glGenTextures(1, &x->tex[i]);
        glBindTexture(GL_TEXTURE_2D, x->tex[i]);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, texel);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    if (!x->compat) gf.GenSamplers(NUNITS, x->samp);

    x->prog = compile_engine_program(x->compat);
    gf.GenBuffers(1, &x->attr_buf);
    gf.GenBuffers(1, &x->array_buf);
    gf.GenBuffers(1, &x->elem_buf);
    gf.GenBuffers(1, &x->unpack_buf);
    gf.GenBuffers(1, &x->pack_buf);
    gf.BindBuffer(GL_ARRAY_BUFFER, x->attr_buf);
    gf.BufferData(GL_ARRAY_BUFFER, 256, NULL, GL_STATIC_DRAW);
    gf.BindBuffer(GL_ARRAY_BUFFER, x->array_buf);
    gf.BufferData(GL_ARRAY_BUFFER, 64, NULL, GL_STATIC_DRAW);
    gf.BindBuffer(GL_ARRAY_BUFFER, 0);
    gf.BindBuffer(GL_PIXEL_UNPACK_BUFFER, x->unpack_buf);
    gf.BufferData(GL_PIXEL_UNPACK_BUFFER, 64, NULL, GL_STATIC_DRAW);
    gf.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    gf.BindBuffer(GL_PIXEL_PACK_BUFFER, x->pack_buf);
    gf.BufferData(GL_PIXEL_PACK_BUFFER, 64, NULL, GL_STREAM_READ);
    gf.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    if (!x->compat) gf.GenVertexArrays(1, &x->vao);
    expect_no_gl_error("creating the engine objects");
}

/* Clears the engine framebuffer: colour (0.1, 0.2, 0.3, 1), depth 1, stencil 0x35. */
static void engine_clear(fx *x)
{
    gf.BindFramebuffer(GL_FRAMEBUFFER, x->fbo);
    glViewport(0, 0, W, H);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_RASTERIZER_DISCARD);
    glColorMask(1, 1, 1, 1);
    glDepthMask(1);
    glStencilMask(0xFF);
    glClearColor(0.1f, 0.2f, 0.3f, 1.0f);
    glClearDepth(1.0);
    glClearStencil(0x35);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    expect_no_gl_error("clearing the engine framebuffer");
}

/* Every item to a non-default value. split_read: a read framebuffer other than the draw one. */
static void apply_engine_state(fx *x, int split_read, int discard)
{
    int i;
    if (split_read) {
        gf.BindFramebuffer(GL_DRAW_FRAMEBUFFER, x->fbo);
        gf.BindFramebuffer(GL_READ_FRAMEBUFFER, x->rfbo);
    } else {
        gf.BindFramebuffer(GL_FRAMEBUFFER, x->fbo);
    }
    gf.BindRenderbuffer(GL_RENDERBUFFER, x->rb);
    glViewport(1, 2, 30, 40);
    gf.UseProgram(x->prog);

    /* vertex input: engine VAO (core) or the default one (GL 2.1), with attribute 0 in
       the engine's attribute buffer, its own element buffer and another array buffer bound */
    if (!x->compat) gf.BindVertexArray(x->vao);
    gf.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, x->elem_buf);
    gf.BindBuffer(GL_ARRAY_BUFFER, x->attr_buf);
    gf.VertexAttribPointer(0, 2, GL_UNSIGNED_SHORT, GL_TRUE, 24, (const void *)(uintptr_t)16);
    gf.EnableVertexAttribArray(0);
    gf.BindBuffer(GL_ARRAY_BUFFER, x->array_buf);

    for (i = 0; i < NUNITS; ++i) {
        gf.ActiveTexture((GLenum)(GL_TEXTURE0 + i));
        glBindTexture(GL_TEXTURE_2D, x->tex[i]);
        if (!x->compat) gf.BindSampler((GLuint)i, x->samp[i]);
    }
    gf.ActiveTexture(GL_TEXTURE5);

    glEnable(GL_BLEND);
    gf.BlendFuncSeparate(GL_DST_COLOR, GL_SRC_COLOR, GL_ONE_MINUS_DST_ALPHA, GL_CONSTANT_ALPHA);
    gf.BlendEquationSeparate(GL_FUNC_SUBTRACT, GL_MAX);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_FRONT);
    glFrontFace(GL_CW);
    glColorMask(1, 0, 1, 0);
    glEnable(GL_SCISSOR_TEST);
    glScissor(3, 5, 17, 19);
    glEnable(GL_STENCIL_TEST);
    gf.StencilFuncSeparate(GL_FRONT, GL_GREATER, 0x12, 0x3C);
    gf.StencilOpSeparate(GL_FRONT, GL_INCR, GL_DECR_WRAP, GL_INVERT);
    gf.StencilMaskSeparate(GL_FRONT, 0x5A);
    gf.StencilFuncSeparate(GL_BACK, GL_LEQUAL, 0x21, 0xC3);
    gf.StencilOpSeparate(GL_BACK, GL_ZERO, GL_INCR_WRAP, GL_DECR);
    gf.StencilMaskSeparate(GL_BACK, 0xA5);
    glClearColor(0.25f, 0.5f, 0.75f, 0.125f);
    glBlendColor(0.625f, 0.375f, 0.875f, 0.25f); /* fogvol's composite blends a constant colour */
    glClearDepth(0.375);
    glClearStencil(0x47);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 7);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 1);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 2);
    glPixelStorei(GL_PACK_ALIGNMENT, 8);
    glPixelStorei(GL_PACK_ROW_LENGTH, 9);
    glPixelStorei(GL_PACK_SKIP_ROWS, 3);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 4);
    gf.BindBuffer(GL_PIXEL_UNPACK_BUFFER, x->unpack_buf);
    gf.BindBuffer(GL_PIXEL_PACK_BUFFER, x->pack_buf);
    glDisable(GL_DITHER);
    glEnable(GL_POLYGON_OFFSET_FILL);
    if (x->compat) {
        glPolygonMode(GL_FRONT, GL_LINE);
        glPolygonMode(GL_BACK, GL_POINT);
    } else {
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    }
    glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glEnable(GL_SAMPLE_COVERAGE);
    glEnable(GL_COLOR_LOGIC_OP);
    glLogicOp(GL_XOR);
    if (discard) glEnable(GL_RASTERIZER_DISCARD);
    if (x->compat) glEnable(GL_ALPHA_TEST);
    expect_no_gl_error("setting the engine state");
}

/* Items a given case leaves at their defaults on purpose. */
static const char *allowed_defaults(const fx *x, int discard)
{
    if (x->compat) /* GL 2.1: no VAO, no sampler objects, no rasterizer discard */
        return "vao sampler rasterizer_discard";
    return discard ? "alpha_test" : "alpha_test rasterizer_discard";
}

/* Sets the engine state and checks that it is all non-default. */
static void set_engine_state(fx *x, int split_read, int discard, snap *out)
{
    apply_engine_state(x, split_read, discard);
    snapshot(out, x->compat);
    expect_all_nondefault(&x->defaults, out, allowed_defaults(x, discard));
}

/* Reading the engine framebuffer after the checks: a plain pack state. */
static void read_engine(fx *x, GLenum format, GLenum type, void *pixels)
{
    gf.BindFramebuffer(GL_READ_FRAMEBUFFER, x->fbo);
    gf.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    glReadPixels(0, 0, W, H, format, type, pixels);
    expect_no_gl_error("reading the engine framebuffer");
}

static void upload_mesh(fx *x, const shp_mesh *s, fogvol_mesh **out)
{
    fogvol_mesh_desc md;
    fogvol_result r;
    assert_non_null(s->pos);
    fx_mesh_desc(&md, s, 0);
    r = fogvol_create_mesh(x->fv, &md, out, NULL);
    if (r != FOGVOL_SUCCESS) fail_msg("fogvol_create_mesh: %s", fogvol_result_string(r));
}

/* Creates the fogvol context, meshes and ramps. With check != NULL the GL state is
   compared with *check after every call (resource creation outside a frame). */
static void fv_create(fx *x, const snap *check)
{
    fogvol_context_desc cd;
    fogvol_ramp_desc rd;
    fogvol_result r;
    snap now;
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.tier = x->variants ? FOGVOL_TIER_FLOAT : FOGVOL_TIER_PS20; /* pass counts below are those of PS20 */
    cd.variants = x->variants;
    cd.gl.software = 1; /* (FLOAT + ENGINE_DEPTH: depth-tested on any GL) */
    cd.logger.func = fv_log;
    cd.logger.user_data = x;
    if (x->compat) {
        cd.gl.version_major = 2;
        cd.gl.version_minor = 1;
    }
    r = fogvol_create_context(&cd, &x->fv);
    if (r != FOGVOL_SUCCESS) fail_msg("fogvol_create_context: %s", fogvol_result_string(r));
    if (check) {
        expect_no_gl_error("fogvol_create_context");
        snapshot(&now, x->compat);
        expect_same_state(check, &now, "fogvol_create_context");
    }
    x->s_big = shp_sphere(1.0f, 32, 16);
    x->s_small = shp_sphere(0.4f, 16, 8);
    x->s_light = shp_sphere(0.5f, 16, 8);
    x->s_box = shp_box(0.3f, 0.3f, 0.3f);
    upload_mesh(x, &x->s_big, &x->m_big);
    upload_mesh(x, &x->s_small, &x->m_small);
    upload_mesh(x, &x->s_light, &x->m_light);
    upload_mesh(x, &x->s_box, &x->m_box);
    if (check) {
        expect_no_gl_error("fogvol_create_mesh");
        snapshot(&now, x->compat);
        expect_same_state(check, &now, "fogvol_create_mesh");
    }
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 1.0f;
    rd.color[1] = 0.8f;
    rd.color[2] = 0.5f;
    rd.density = 0.8f;
    r = fogvol_create_ramp(x->fv, &rd, &x->r_fog);
    if (r != FOGVOL_SUCCESS) fail_msg("fogvol_create_ramp: %s", fogvol_result_string(r));
    rd.color[0] = 0.2f;
    rd.color[1] = 0.4f;
    rd.color[2] = 1.0f;
    rd.density = 1.0f;
    rd.blend = FOGVOL_BLEND_LIGHT;
    r = fogvol_create_ramp(x->fv, &rd, &x->r_light);
    if (r != FOGVOL_SUCCESS) fail_msg("fogvol_create_ramp: %s", fogvol_result_string(r));
    if (check) {
        expect_no_gl_error("fogvol_create_ramp");
        snapshot(&now, x->compat);
        expect_same_state(check, &now, "fogvol_create_ramp");
    }
}

static void fv_destroy(fx *x)
{
    if (x->fv) {
        if (x->m_big) fogvol_destroy_mesh(x->fv, x->m_big);
        if (x->m_small) fogvol_destroy_mesh(x->fv, x->m_small);
        if (x->m_light) fogvol_destroy_mesh(x->fv, x->m_light);
        if (x->m_box) fogvol_destroy_mesh(x->fv, x->m_box);
        if (x->r_fog) fogvol_destroy_ramp(x->fv, x->r_fog);
        if (x->r_light) fogvol_destroy_ramp(x->fv, x->r_light);
        fogvol_destroy_context(x->fv);
    }
    x->fv = NULL;
    x->m_big = x->m_small = x->m_light = x->m_box = NULL;
    x->r_fog = x->r_light = NULL;
    shp_free(&x->s_big);
    shp_free(&x->s_small);
    shp_free(&x->s_light);
    shp_free(&x->s_box);
}

/* One frame: a fog sphere (r 1) with a negative sphere (r 0.4) inside, an occluder box,
   and a light sphere in a second ramp group. Viewport (0, 0, w, h). */
static void run_frame(fx *x, fogvol_composite composite, int w, int h)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_frame_stats st;
    fogvol_result r;
    int i;
    float box_model[16];
    double eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    memset(&fd, 0, sizeof fd);
    glu_look_at(fd.view, eye, at, up);
    glu_perspective(fd.projection, 60, (double)w / h, 0.5, 20);
    fd.znear = 0.5f;
    fd.zfar = 20.0f;
    fd.viewport[2] = w;
    fd.viewport[3] = h;
    fd.composite = composite;
    for (i = 0; i < W * H; ++i) x->thick[i] = -1.0f;
    fd.debug_thickness = x->thick;
    if (x->variants) /* the engine's depth (cleared to the far plane), copied from the bound framebuffer */
        fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
    assert_int_equal(fogvol_begin_frame(x->fv, &fd), FOGVOL_SUCCESS);
    glu_translate_scale(box_model, 0.8f, -0.6f, 1.2f, 1.0f);
    if (!x->variants) assert_int_equal(fogvol_add_occluder(x->fv, x->m_box, box_model), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = x->m_big;
    vd.ramp = x->r_fog;
    glu_identity(vd.model);
    assert_int_equal(fogvol_add_volume(x->fv, &vd), FOGVOL_SUCCESS);
    vd.mesh = x->m_small;
    vd.negative = 1;
    assert_int_equal(fogvol_add_volume(x->fv, &vd), FOGVOL_SUCCESS);
    vd.mesh = x->m_light;
    vd.ramp = x->r_light;
    vd.negative = 0;
    glu_translate_scale(vd.model, -0.6f, 0.6f, 0.0f, 1.0f);
    assert_int_equal(fogvol_add_volume(x->fv, &vd), FOGVOL_SUCCESS);
    r = fogvol_end_frame(x->fv, &st);
    if (r != FOGVOL_SUCCESS) fail_msg("fogvol_end_frame: %s", fogvol_result_string(r));
    if (x->variants) { /* each group: its faces depth-tested against the engine's depth, its composite */
        assert_int_equal(st.engine_depth_tested, 1);
        assert_int_equal(st.passes, 4);
        assert_int_equal(st.groups, 2);
        return;
    }
    /* O; fog group: B, B negative, F, F negative, composite; light group: B, F, composite. Summed as
       integers (FOGVOL_SPEEDUP_EXACT_SUM, GL 3.3 here): one sum pass a group, negative volumes in it */
    assert_int_equal(st.exact_sum, x->compat || !glu_has_fetch() ? 0 : 2);
    assert_int_equal(st.passes, st.exact_sum ? 5 : 9);
    assert_int_equal(st.groups, 2);
    assert_int_equal(st.occluders, 1);
    assert_int_equal(st.volumes, 3);
}

/* The fog group's thickness at the image centre: 2 - 2 * 0.4 (sphere minus the negative one). */
static void expect_fog_thickness(const fx *x, int w, int h)
{
    float t = x->thick[(h / 2) * w + w / 2];
    if (!(t > 1.1f && t < 1.3f))
        fail_msg("thickness at the centre %.4f, expected about 1.2 (fogvol rendered no or wrong fog)", (double)t);
}

static int setup_ctx(void **state, int compat)
{
    fx *x = (fx *)calloc(1, sizeof *x);
    if (!x) return -1;
    *state = x;
    x->compat = compat;
    if (!glu_create(&x->g, W, H, compat ? 0 : 1)) {
        print_error("no OSMesa context\n");
        return -1;
    }
    load_gl();
    snapshot(&x->defaults, compat);
    create_engine_objects(x);
    return 0;
}

static int setup_core(void **state) { return setup_ctx(state, 0); }
static int setup_compat(void **state) { return setup_ctx(state, 1); }

static int teardown(void **state)
{
    fx *x = (fx *)*state;
    if (!x) return 0;
    fv_destroy(x);
    glu_destroy(&x->g);
    free(x);
    return 0;
}

/* ---- cases --------------------------------------------------------------- */

/* (a), (b), (d): two frames with every item non-default; state, errors, fog, stencil. */
static void frame_case(fx *x, fogvol_composite composite, int split_read)
{
    snap before, after;
    static unsigned char color0[W * H * 4], color1[W * H * 4], stencil[W * H];
    int i, changed = 0, bad = 0, first_bad = -1;
    char where[128];
    fv_create(x, NULL);
    engine_clear(x);
    read_engine(x, GL_RGBA, GL_UNSIGNED_BYTE, color0);
    set_engine_state(x, split_read, 0, &before);
    for (i = 0; i < 2; ++i) {
        snprintf(where, sizeof where, "%s composite, frame %d%s",
                 composite == FOGVOL_COMPOSITE_GEOMETRY ? "geometry" : "full-screen", i + 1,
                 i == 0 ? " (creates the targets)" : "");
        run_frame(x, composite, W, H);
        expect_no_gl_error(where);
        snapshot(&after, x->compat);
        expect_same_state(&before, &after, where);
        expect_fog_thickness(x, W, H);
    }
    /* fog reached the engine colour buffer */
    read_engine(x, GL_RGBA, GL_UNSIGNED_BYTE, color1);
    for (i = 0; i < W * H * 4; i += 4) changed += memcmp(color0 + i, color1 + i, 4) != 0;
    if (changed < 100) fail_msg("only %d engine pixels changed: the fog was not composited", changed);
    /* (d) the engine's stencil values (0x35) survive, whatever the composite */
    read_engine(x, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, stencil);
    for (i = 0; i < W * H; ++i)
        if (stencil[i] != 0x35) {
            if (first_bad < 0) first_bad = i;
            ++bad;
        }
    if (bad)
        fail_msg("%d engine stencil values changed; first at (%d, %d): 0x%02x, expected 0x35", bad, first_bad % W,
                 first_bad / W, stencil[first_bad]);
    assert_int_equal(x->warnings, 0);
}

static void test_core_geometry(void **state) { frame_case((fx *)*state, FOGVOL_COMPOSITE_GEOMETRY, 1); }
/* FLOAT + ENGINE_DEPTH drawn depth-tested: the copy of the engine's depth attached to fogvol's sum target
   (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST), GREATER or LESS, and detached */
static void test_core_engine_depth_tested(void **state)
{
    ((fx *)*state)->variants = FOGVOL_VARIANT_ENGINE_DEPTH;
    frame_case((fx *)*state, FOGVOL_COMPOSITE_FULLSCREEN, 1);
}
static void test_core_fullscreen(void **state) { frame_case((fx *)*state, FOGVOL_COMPOSITE_FULLSCREEN, 1); }
static void test_compat21_geometry(void **state) { frame_case((fx *)*state, FOGVOL_COMPOSITE_GEOMETRY, 0); }
static void test_compat21_fullscreen(void **state) { frame_case((fx *)*state, FOGVOL_COMPOSITE_FULLSCREEN, 0); }

/* (b) GL 2.1 with GL_ARB_framebuffer_object has separate draw and read bindings too. */
static void test_compat21_read_framebuffer(void **state)
{
    fx *x = (fx *)*state;
    const char *ext = (const char *)glGetString(GL_EXTENSIONS);
    if (!ext || !strstr(ext, "GL_ARB_framebuffer_object")) skip();
    frame_case(x, FOGVOL_COMPOSITE_GEOMETRY, 1);
}

/* Rasterizer discard on: fogvol must turn it off for its passes and turn it back on. */
static void test_core_rasterizer_discard(void **state)
{
    fx *x = (fx *)*state;
    snap before, after;
    fv_create(x, NULL);
    engine_clear(x);
    set_engine_state(x, 1, 1, &before);
    assert_true(before.rasterizer_discard);
    run_frame(x, FOGVOL_COMPOSITE_GEOMETRY, W, H);
    expect_no_gl_error("frame with rasterizer discard on");
    snapshot(&after, x->compat);
    expect_same_state(&before, &after, "frame with rasterizer discard on");
    expect_fog_thickness(x, W, H);
}

/* The engine deleted the program it has current (GL keeps it until it is no longer current): fogvol
   binds its own, which frees it, so it restores program 0 instead of the freed name (glUseProgram of
   a freed name would raise GL_INVALID_VALUE in the engine's error queue). Every other item of state
   comes back. */
static void deleted_program_case(fx *x)
{
    snap before, after;
    GLuint p;
    GLint cur = -1;
    fv_create(x, NULL);
    engine_clear(x);
    set_engine_state(x, !x->compat, 0, &before);
    p = compile_engine_program(x->compat);
    gf.UseProgram(p);
    gf.DeleteProgram(p);
    glGetIntegerv(GL_CURRENT_PROGRAM, &cur);
    assert_int_equal(cur, (GLint)p); /* deleted, still current */
    run_frame(x, FOGVOL_COMPOSITE_FULLSCREEN, W, H);
    expect_no_gl_error("frame after the engine deleted its current program");
    glGetIntegerv(GL_CURRENT_PROGRAM, &cur);
    assert_int_equal(cur, 0);
    /* (whether the name is gone now is the driver's: Mesa frees it, NVIDIA's compatibility profile
       keeps it; fogvol's part is that it is not current again) */
    gf.UseProgram((GLuint)before.program); /* the rest of the engine's state is untouched */
    snapshot(&after, x->compat);
    expect_same_state(&before, &after, "frame after the engine deleted its current program");
    expect_fog_thickness(x, W, H);
}
static void test_core_deleted_program(void **state) { deleted_program_case((fx *)*state); }
static void test_compat21_deleted_program(void **state) { deleted_program_case((fx *)*state); }

/* (c) resource creation outside a frame, target creation, resize, destruction. */
static void resources_case(fx *x)
{
    snap before, after;
    const int split = !x->compat;
    engine_clear(x);
    set_engine_state(x, split, 0, &before);
    fv_create(x, &before); /* context, meshes, ramps: checked after each */
    run_frame(x, FOGVOL_COMPOSITE_GEOMETRY, W, H);
    expect_no_gl_error("first frame (creates the targets)");
    snapshot(&after, x->compat);
    expect_same_state(&before, &after, "first frame (creates the targets)");
    expect_fog_thickness(x, W, H);
    run_frame(x, FOGVOL_COMPOSITE_FULLSCREEN, 48, 40);
    expect_no_gl_error("resized frame (recreates the targets)");
    snapshot(&after, x->compat);
    expect_same_state(&before, &after, "resized frame (recreates the targets)");
    expect_fog_thickness(x, 48, 40);
    fv_destroy(x);
    expect_no_gl_error("destroying the fogvol objects");
    snapshot(&after, x->compat);
    expect_same_state(&before, &after, "destroying the fogvol objects");
    assert_int_equal(x->warnings, 0);
}

static void test_core_resources(void **state) { resources_case((fx *)*state); }
static void test_compat21_resources(void **state) { resources_case((fx *)*state); }

/* (e) Engine state beyond the GL 2.0 list that changes what fogvol draws, set by an engine and left
   set: GL_SAMPLE_ALPHA_TO_ONE on a 4x framebuffer (the fragment alpha forced to 1 before blending:
   opaque fog), a colour clamp in a compatibility profile (glClampColor(GL_CLAMP_FRAGMENT_COLOR,
   GL_TRUE): the signed float sums clamped), and viewport, scissor and depth-range arrays (index 1,
   which glViewport, glScissor, glDepthRange and glDisable(GL_SCISSOR_TEST) would overwrite). A sphere
   of radius 1 at view depth 5 (the centre pixel's thickness 2, analytic), its centre pixel against
   rgb (1 - a) + fog a with a = 1 - exp(-density t); every piece of that state the same after the
   frame. (Before: opaque fog, 255 for 152 and 255 for 152, and index 1 rewritten.) */
typedef void (*pfn_viewport_indexedf)(GLuint, GLfloat, GLfloat, GLfloat, GLfloat);
typedef void (*pfn_scissor_indexed)(GLuint, GLint, GLint, GLsizei, GLsizei);
typedef void (*pfn_depth_range_indexed)(GLuint, GLdouble, GLdouble);
typedef void (*pfn_enablei)(GLenum, GLuint);
typedef GLboolean (*pfn_is_enabledi)(GLenum, GLuint);
typedef void (*pfn_get_integeri_v)(GLenum, GLuint, GLint *);
typedef void (*pfn_get_doublei_v)(GLenum, GLuint, GLdouble *);
typedef void (*pfn_clamp_color)(GLenum, GLenum);
typedef void (*pfn_rb_storage_ms)(GLenum, GLsizei, GLenum, GLsizei, GLsizei);
typedef void (*pfn_blit)(GLint, GLint, GLint, GLint, GLint, GLint, GLint, GLint, GLbitfield, GLenum);

static void extras_centre(int compat, int samples, int clamp, int arrays)
{
    glu_ctx g;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_mesh *mesh;
    fogvol_ramp_desc rd;
    fogvol_ramp *ramp;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    shp_mesh sph = shp_sphere(1.0f, 48, 96);
    GLuint fbo, rb[2], rfbo, rrb;
    unsigned char px[4];
    const double density = 0.5, t = 2.0, a = 1.0 - exp(-density * t), bg[3] = {0.2, 0.3, 0.4};
    int ch, maxd = 0;
    assert_true(glu_create(&g, W, H, compat ? 0 : 1));
    load_gl();
    gf.GenRenderbuffers(2, rb);
    gf.GenFramebuffers(1, &fbo);
    gf.BindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    ((pfn_rb_storage_ms)glu_proc("glRenderbufferStorageMultisample", NULL))(GL_RENDERBUFFER, samples, GL_RGBA8, W, H);
    gf.BindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    ((pfn_rb_storage_ms)glu_proc("glRenderbufferStorageMultisample", NULL))(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8,
                                                                         W, H);
    gf.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gf.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    gf.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    assert_int_equal(gf.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glViewport(0, 0, W, H);
    glClearColor((float)bg[0], (float)bg[1], (float)bg[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (samples > 1) glEnable(GL_SAMPLE_ALPHA_TO_ONE);
    if (clamp) ((pfn_clamp_color)glu_proc("glClampColor", NULL))(GL_CLAMP_FRAGMENT_COLOR, GL_TRUE);
    if (arrays) {
        ((pfn_viewport_indexedf)glu_proc("glViewportIndexedf", NULL))(1, 32.0f, 0.0f, 32.0f, 64.0f);
        ((pfn_scissor_indexed)glu_proc("glScissorIndexed", NULL))(1, 5, 6, 7, 8);
        ((pfn_enablei)glu_proc("glEnablei", NULL))(GL_SCISSOR_TEST, 1);
        ((pfn_depth_range_indexed)glu_proc("glDepthRangeIndexed", NULL))(1, 0.25, 0.75);
    }
    memset(&cd, 0, sizeof cd);
    cd.gl.get_proc_address = glu_proc;
    cd.logger.func = fv_log;
    cd.tier = FOGVOL_TIER_FLOAT;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    {
        fogvol_mesh_desc md;
        fx_mesh_desc(&md, &sph, 0);
        assert_int_equal(fogvol_create_mesh(fv, &md, &mesh, NULL), FOGVOL_SUCCESS);
    }
    memset(&rd, 0, sizeof rd);
    rd.color[0] = rd.color[1] = rd.color[2] = 0.8f;
    rd.density = (float)density;
    assert_int_equal(fogvol_create_ramp(fv, &rd, &ramp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    glu_identity(fd.view);
    glu_perspective(fd.projection, 45.0, 1.0, 0.5, 50.0);
    fd.znear = 0.5f;
    fd.zfar = 50.0f;
    fd.viewport[2] = W;
    fd.viewport[3] = H;
    memset(&vd, 0, sizeof vd);
    vd.mesh = mesh;
    vd.ramp = ramp;
    glu_identity(vd.model);
    vd.model[14] = -5.0f;
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
    expect_no_gl_error("the frame");
    /* the engine's state, as it set it */
    if (samples > 1) assert_true(glIsEnabled(GL_SAMPLE_ALPHA_TO_ONE));
    if (clamp) {
        GLint v = 0;
        glGetIntegerv(GL_CLAMP_FRAGMENT_COLOR, &v);
        assert_int_equal(v, GL_TRUE);
        ((pfn_clamp_color)glu_proc("glClampColor", NULL))(GL_CLAMP_FRAGMENT_COLOR, GL_FIXED_ONLY);
    }
    if (arrays) {
        GLint v[4];
        GLdouble d[2];
        ((pfn_get_integeri_v)glu_proc("glGetIntegeri_v", NULL))(GL_VIEWPORT, 1, v);
        assert_true(v[0] == 32 && v[1] == 0 && v[2] == 32 && v[3] == 64);
        ((pfn_get_integeri_v)glu_proc("glGetIntegeri_v", NULL))(GL_SCISSOR_BOX, 1, v);
        assert_true(v[0] == 5 && v[1] == 6 && v[2] == 7 && v[3] == 8);
        assert_true(((pfn_is_enabledi)glu_proc("glIsEnabledi", NULL))(GL_SCISSOR_TEST, 1));
        ((pfn_get_doublei_v)glu_proc("glGetDoublei_v", NULL))(GL_DEPTH_RANGE, 1, d);
        assert_true(d[0] == 0.25 && d[1] == 0.75);
        glGetIntegerv(GL_VIEWPORT, v);
        assert_true(v[0] == 0 && v[1] == 0 && v[2] == W && v[3] == H);
    }
    if (samples > 1) glDisable(GL_SAMPLE_ALPHA_TO_ONE);
    /* the centre pixel, resolved */
    gf.GenFramebuffers(1, &rfbo);
    gf.GenRenderbuffers(1, &rrb);
    gf.BindRenderbuffer(GL_RENDERBUFFER, rrb);
    gf.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    gf.BindFramebuffer(GL_DRAW_FRAMEBUFFER, rfbo);
    gf.FramebufferRenderbuffer(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rrb);
    gf.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    if (arrays) ((pfn_enablei)glu_proc("glDisablei", NULL))(GL_SCISSOR_TEST, 1);
    ((pfn_blit)glu_proc("glBlitFramebuffer", NULL))(0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gf.BindFramebuffer(GL_READ_FRAMEBUFFER, rfbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(W / 2, H / 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    for (ch = 0; ch < 3; ++ch) {
        int want = (int)((bg[ch] * (1.0 - a) + 0.8 * a) * 255.0 + 0.5), d = abs((int)px[ch] - want);
        if (d > maxd) maxd = d;
    }
    print_message("# %s, %d samples: centre %d %d %d, want %d (%s%s%s)\n", compat ? "compatibility" : "core", samples, px[0],
                  px[1], px[2], (int)((bg[0] * (1.0 - a) + 0.8 * a) * 255.0 + 0.5), samples > 1 ? "alpha to one " : "",
                  clamp ? "colour clamp " : "", arrays ? "viewport arrays" : "");
    assert_true(maxd <= 3); /* (the sphere's tessellation: its chord at the centre is 2 within 0.1%) */
    expect_no_gl_error("the checks");
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, mesh);
    fogvol_destroy_context(fv);
    glu_destroy(&g);
    shp_free(&sph);
}

static void test_core_engine_extras(void **state)
{
    (void)state;
    extras_centre(0, 4, 0, 1);
    extras_centre(0, 0, 0, 1);
}

static void test_compat_colour_clamp(void **state)
{
    (void)state;
    extras_centre(1, 0, 1, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_core_geometry, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_core_fullscreen, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_core_engine_depth_tested, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_core_rasterizer_discard, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_core_resources, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_core_deleted_program, setup_core, teardown),
        cmocka_unit_test_setup_teardown(test_compat21_deleted_program, setup_compat, teardown),
        cmocka_unit_test_setup_teardown(test_compat21_geometry, setup_compat, teardown),
        cmocka_unit_test_setup_teardown(test_compat21_fullscreen, setup_compat, teardown),
        cmocka_unit_test_setup_teardown(test_compat21_read_framebuffer, setup_compat, teardown),
        cmocka_unit_test_setup_teardown(test_compat21_resources, setup_compat, teardown),
        cmocka_unit_test(test_core_engine_extras),
        cmocka_unit_test(test_compat_colour_clamp),
    };
    cmocka_set_message_output(CM_OUTPUT_TAP);
    return cmocka_run_group_tests_name("fogvol GL state", tests, NULL, NULL);
}
