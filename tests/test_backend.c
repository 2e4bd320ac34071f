/* test_backend.c - fogvol's renderer seen through its backend table: the recording
 * null backend (no GL at all) and the GL backend under OSMesa.
 *
 * The null backend (every expectation below is worked out by hand from the
 * PS20 pass sequence of the seed, not read back from the code; the contexts ask for
 * FOGVOL_TIER_PS20 explicitly, since AUTO picks a tier from the backend's caps):
 *   The passes of one frame (test_passes_of_a_frame_*): occluders and volumes of two colour ramps, one
 *      group with a negative volume. Pass 0 = O (depth test+write, clear (N-1)/255
 *      RGB / 0 alpha, encode program, lookup textures on units 0..2), then per ramp
 *      group in order of first appearance: B (ADD, cull FRONT, clear), [B without
 *      clear, cull BACK, negatives], F (cull BACK, clear), [F cull FRONT, negatives],
 *      composite into target 0 (FOG or LIGHT blend; full-screen: one draw_fullscreen;
 *      geometry: the full-screen triangle under the group's scissor).
 *      Draw lists per pass, frame stats, viewports, fv_screen, fv_enc, fv_dith,
 *      fv_dec, fv_rampmap, per-draw depth rows (d = (w - near)/(far - near) at hand
 *      computed points), clip w, mirror winding (front_cw).
 *   A ramp group with only negative volumes renders nothing and counts nothing.
 *   The order of calls in a frame: add_* outside a frame, begin_frame twice, end_frame without
 *      begin, cancel_frame, fogvol_occluder_transform outside/inside the O pass.
 *   Bad input: the documented code, an error in the logger, no crash.
 *   Fault injection: n-th backend create failing, k-th allocation failing
 *      (context, mesh, ramp, frame lists), target creation failing in end_frame.
 * The GL backend under OSMesa (test_gl_*):
 *   Every required entry point missing in turn, the sets taken from the header's
 *      own X-macro lists (3.3 core: BASE, FBO, VAO, SAMPLER, GL_3 when the header has
 *      it, DESKTOP; GL 2.1 override in the compatibility context, whose extension
 *      string has ARB_framebuffer_object: BASE, FBO, DESKTOP) ->
 *      FOGVOL_ERROR_MISSING_FUNCTION, the name in the log, no memory and no GL
 *      object left (Gen/Delete and Create/Delete counted through the loader); the
 *      VAO, sampler, GL 3 and ES entries missing do not matter on GL 2.1 (the
 *      context renders); a loader that finds nothing -> glGetString named.
 *   The GLSL dialect from the context version and the overrides (through
 *      fogvol_gl_backend_create); GLSL ES 1.00 in the core context and the 2.1
 *      override compile (every program's first line checked) and render a sphere
 *      whose centre thickness is the analytic chord within 1%.
 *   A fragment shader that fails to compile -> FOGVOL_ERROR_SHADER_COMPILE with
 *      the driver's info log in the logger, no leak, backend still usable.
 *   plus allocation failures during GL context creation (no memory, no GL object left).
 *
 * Build (from the repository root):
 *   gcc -std=c99 -Wall -Wextra -pedantic -Werror -I. tests/test_backend.c -o build/test_backend \
 *       -lcmocka -lOSMesa -lm
 *   add -fsanitize=address,undefined and run with
 *   LSAN_OPTIONS=suppressions=tests/lsan.supp (OSMesa keeps a few hundred bytes).
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
#include <math.h>

/* ==== shared helpers =================================================== */

/* ---- logger capture ---- */
#define LOG_MAX 64
typedef struct logcap {
    int count, errors, warnings;
    fogvol_log_level level[LOG_MAX];
    char msg[LOG_MAX][1100];
} logcap;

static void cap_log(void *u, fogvol_log_level l, const char *m)
{
    logcap *c = (logcap *)u;
    assert_non_null(m);
    if (c->count < LOG_MAX) {
        c->level[c->count] = l;
        snprintf(c->msg[c->count], sizeof c->msg[0], "%s", m);
    }
    c->count++;
    if (l == FOGVOL_LOG_ERROR) c->errors++;
    if (l == FOGVOL_LOG_WARNING) c->warnings++;
}

static void log_reset(logcap *c) { memset(c, 0, sizeof *c); }

static fogvol_logger cap_logger(logcap *c)
{
    fogvol_logger lg;
    lg.func = cap_log;
    lg.user_data = c;
    return lg;
}

/* an error-level message containing needle (NULL: any) */
static int log_error_has(const logcap *c, const char *needle)
{
    int i;
    for (i = 0; i < c->count && i < LOG_MAX; ++i)
        if (c->level[i] == FOGVOL_LOG_ERROR && (!needle || strstr(c->msg[i], needle))) return 1;
    return 0;
}

static void log_dump(const logcap *c)
{
    int i;
    for (i = 0; i < c->count && i < LOG_MAX; ++i) print_message("    log[%d] level %d: %s\n", i, (int)c->level[i], c->msg[i]);
}

/* ---- counting allocator, optionally failing at the k-th call ---- */
typedef struct counting {
    long live, calls, frees, fail_at; /* fail_at: absolute call number that returns NULL (0 = never) */
} counting;

static void *cnt_alloc(size_t size, void *u)
{
    counting *c = (counting *)u;
    void *p;
    c->calls++;
    if (c->fail_at > 0 && c->calls == c->fail_at) return NULL;
    p = malloc(size);
    if (p) c->live++;
    return p;
}

static void cnt_free(void *p, void *u)
{
    counting *c = (counting *)u;
    assert_non_null(p); /* fogvol__free never passes NULL */
    c->live--;
    c->frees++;
    free(p);
}

static fogvol_allocator cnt_allocator(counting *c)
{
    fogvol_allocator a;
    a.alloc = cnt_alloc;
    a.free = cnt_free;
    a.user_data = c;
    return a;
}

/* ---- matrices ---- */
static void mat_identity(float m[16]) { shp_mat_identity(m); }

/* T(tx,ty,tz) * S(sx,sy,sz) */
static void mat_ts(float m[16], float tx, float ty, float tz, float sx, float sy, float sz)
{
    mat_identity(m);
    m[0] = sx;
    m[5] = sy;
    m[10] = sz;
    m[12] = tx;
    m[13] = ty;
    m[14] = tz;
}

/* dot of row r of a column-major matrix with (p, 1) */
static double mat_row_dot(const float m[16], int r, const double p[3])
{
    return (double)m[r] * p[0] + (double)m[4 + r] * p[1] + (double)m[8 + r] * p[2] + (double)m[12 + r];
}

static double vec4_dot_p1(const float v[4], const double p[3])
{
    return (double)v[0] * p[0] + (double)v[1] * p[1] + (double)v[2] * p[2] + (double)v[3];
}

/* relative float comparison for uniforms */
static void assert_close(double got, double want, double rel, const char *what)
{
    double tol = rel * (fabs(want) > 1e-30 ? fabs(want) : 1.0);
    if (!(fabs(got - want) <= tol)) fail_msg("%s: got %.9g, want %.9g", what, got, want);
}

static shp_mesh box_mesh(void) { return shp_box(0.5f, 0.5f, 0.5f); }

static fogvol_result make_mesh(fogvol_context *fv, const shp_mesh *s, int allow_open, int stride_floats,
                               fogvol_mesh **out)
{
    fogvol_mesh_desc md;
    float *strided = NULL;
    fogvol_result r;
    fx_mesh_desc(&md, s, allow_open);
    if (stride_floats > 3) { /* interleave with padding: exercises the repacking path */
        int i;
        strided = (float *)calloc((size_t)s->vcount * (size_t)stride_floats, sizeof(float));
        assert_non_null(strided);
        for (i = 0; i < s->vcount; ++i) memcpy(strided + (size_t)i * stride_floats, s->pos + 3 * i, 12);
        md.positions = strided;
        md.stride = stride_floats * (int)sizeof(float);
    }
    r = fogvol_create_mesh(fv, &md, out, NULL);
    free(strided);
    return r;
}

static fogvol_result make_ramp(fogvol_context *fv, fogvol_blend blend, fogvol_ramp **out)
{
    fogvol_ramp_desc rd;
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.9f;
    rd.color[1] = 0.7f;
    rd.color[2] = 0.5f;
    rd.density = 0.5f; /* extinction: max_thickness auto = 7 / density = 14 */
    rd.width = 256;
    rd.blend = blend;
    return fogvol_create_ramp(fv, &rd, out);
}

/* ==== the null backend, behind a recording wrapper ===================== */

#define REC_MAX_DRAWS 256
#define REC_MAX_RES 64

typedef struct rec_draw {
    int pass; /* index of the pass it was issued in */
    fogvol_handle mesh;
    fogvol_draw d;
} rec_draw;

typedef struct rec {
    fogvol_null_backend nb;
    fogvol_backend inner; /* the null table */
    fogvol_backend table; /* the wrapper handed to fogvol */
    /* resources */
    int ntex, ntgt, nprog;
    struct { fogvol_handle h; int w, hgt; fogvol_filter filter; fogvol_wrap wrap; } tex[REC_MAX_RES];
    struct { fogvol_handle h; int w, hgt, depth; } tgt[REC_MAX_RES];
    struct { fogvol_handle h; int kind; } prog[REC_MAX_RES];
    /* per frame */
    int in_frame, begin_pass_calls, end_pass_calls, protocol_errors;
    rec_draw draws[REC_MAX_DRAWS];
    int ndraws;
    fogvol_draw set_draws[16];
    int set_draw_pass[16];
    int nset;
} rec;

/* The program kind whose sources (every string of both stages) equal desc's. */
/* A program's kind: its fogvol_program, plus its fogvol_shader_desc.specialize bits times 256. */
#define KIND(p, spec) ((int)(p) | (int)(spec) << 8)
/* the encoding of FOGVOL_SPECIALIZE_ENCODING compiled into the default context's ENCODE and FACE
   programs: L = 4 (fogvol_context_desc.encoding_bits 0) */
#define ENC4 FOGVOL_SPECIALIZE_ENCODING(4)
static int program_kind(const fogvol_program_desc *d, fogvol_dialect dialect)
{
    int k, found = -1;
    unsigned enc = 0;
    for (k = 0; k < d->fs_count; ++k) /* FOGVOL_SPECIALIZE_ENCODING(L): "#define FV_ENC_LN L" */
        if (strncmp(d->fs[k], "#define FV_ENC_LN ", 18) == 0) enc = FOGVOL_SPECIALIZE_ENCODING(atoi(d->fs[k] + 18));
    for (k = 0; k < FOGVOL_PROGRAM_COUNT * 8192; ++k) { /* every program, every set of the other bits */
        const char *vs[FOGVOL_MAX_SHADER_STRINGS], *fs[FOGVOL_MAX_SHADER_STRINGS];
        int nv = 0, nf = 0, i, same, p = k % FOGVOL_PROGRAM_COUNT;
        fogvol_shader_desc sd;
        memset(&sd, 0, sizeof sd);
        sd.tier = FOGVOL_TIER_PS20;
        sd.variants = FOGVOL_VARIANT_ALU; /* the PS20 default (FOGVOL_SPEEDUP_ALU) */
        sd.program = (fogvol_program)p;
        sd.dialect = dialect;
        sd.specialize = (unsigned)(k / FOGVOL_PROGRAM_COUNT) | enc;
        if (fogvol_shader_strings(&sd, vs, &nv) != FOGVOL_SUCCESS) continue;
        sd.stage = FOGVOL_STAGE_FRAGMENT;
        if (fogvol_shader_strings(&sd, fs, &nf) != FOGVOL_SUCCESS) continue;
        same = nv == d->vs_count && nf == d->fs_count;
        for (i = 0; same && i < nv; ++i) same = strcmp(vs[i], d->vs[i]) == 0;
        for (i = 0; same && i < nf; ++i) same = strcmp(fs[i], d->fs[i]) == 0;
        if (same) {
            assert_int_equal(found, -1); /* the programs must differ */
            found = KIND(p, sd.specialize);
        }
    }
    return found;
}

/* What the recording wrapper checks (the call order fogvol must keep: counted in protocol_errors) and
   records before it forwards a call, and what it records of a call that succeeded. */
static void rec_frame_begun(rec *r)
{
    if (r->in_frame) r->protocol_errors++;
    r->in_frame = 1;
    r->ndraws = r->nset = 0;
    r->begin_pass_calls = r->end_pass_calls = 0;
}
static void rec_frame_ended(rec *r)
{
    if (!r->in_frame || r->nb.in_pass) r->protocol_errors++;
    r->in_frame = 0;
}
static void rec_pass_begun(rec *r)
{
    if (!r->in_frame || r->nb.in_pass) r->protocol_errors++;
    r->begin_pass_calls++;
}
static void rec_pass_ended(rec *r)
{
    if (!r->nb.in_pass) r->protocol_errors++;
    r->end_pass_calls++;
}
static void rec_in_pass(rec *r)
{
    if (!r->nb.in_pass) r->protocol_errors++;
}
static void rec_handle_given(rec *r, fogvol_handle h)
{
    if (!h) r->protocol_errors++; /* fogvol never hands back a handle it did not get */
}
static void rec_set_draw_call(rec *r, const fogvol_draw *d)
{
    rec_in_pass(r);
    if (r->nset < 16) {
        r->set_draws[r->nset] = *d;
        r->set_draw_pass[r->nset] = r->nb.pass_count - 1;
        r->nset++;
    }
}
static void rec_draw_call(rec *r, fogvol_handle m, const fogvol_draw *d)
{
    rec_in_pass(r);
    if (r->ndraws < REC_MAX_DRAWS) {
        r->draws[r->ndraws].pass = r->nb.pass_count - 1;
        r->draws[r->ndraws].mesh = m;
        r->draws[r->ndraws].d = *d;
        r->ndraws++;
    }
}
static void rec_layout_given(rec *r, const fogvol_program_desc *d)
{
    fogvol_uniform_layout want;
    (void)fogvol_dialect_layout(r->table.dialect, &want); /* Vulkan: where the values are; GL: all -1 */
    if (memcmp(&d->layout, &want, sizeof want) != 0) r->protocol_errors++;
}
static void rec_texture_made(rec *r, const fogvol_texture_desc *d, fogvol_handle h)
{
    if (r->ntex >= REC_MAX_RES) return;
    r->tex[r->ntex].h = h;
    r->tex[r->ntex].w = d->width;
    r->tex[r->ntex].hgt = d->height;
    r->tex[r->ntex].filter = d->filter;
    r->tex[r->ntex].wrap = d->wrap;
    r->ntex++;
}
static void rec_target_made(rec *r, const fogvol_target_desc *d, fogvol_handle h)
{
    if (r->ntgt >= REC_MAX_RES) return;
    r->tgt[r->ntgt].h = h;
    r->tgt[r->ntgt].w = d->width;
    r->tgt[r->ntgt].hgt = d->height;
    r->tgt[r->ntgt].depth = d->depth;
    r->ntgt++;
}
static void rec_program_made(rec *r, const fogvol_program_desc *d, fogvol_handle h)
{
    if (r->nprog >= REC_MAX_RES) return;
    r->prog[r->nprog].h = h;
    r->prog[r->nprog].kind = program_kind(d, r->table.dialect);
    r->nprog++;
}

/* The wrapper, one line a backend entry: RESULT(entry, parameters, the arguments forwarded (REC_U: the
   null backend's user_data), before: checked and recorded before forwarding, after: recorded when
   the call succeeded) for the entries that return a fogvol_result, VOID(entry, parameters, arguments,
   before) for the others. REC_NONE: nothing. */
#define REC_CALLS(RESULT, VOID)                                                                                      \
    RESULT(begin_frame, (void *u, fogvol_frame_info *info), (REC_U, info), rec_frame_begun(r), REC_NONE)             \
    VOID(end_frame, (void *u), (REC_U), rec_frame_ended(r))                                                          \
    RESULT(create_texture, (void *u, const fogvol_texture_desc *d, fogvol_handle *out), (REC_U, d, out), REC_NONE,   \
           rec_texture_made(r, d, *out))                                                                             \
    VOID(destroy_texture, (void *u, fogvol_handle h), (REC_U, h), rec_handle_given(r, h))                            \
    RESULT(create_target, (void *u, const fogvol_target_desc *d, fogvol_handle *out), (REC_U, d, out), REC_NONE,     \
           rec_target_made(r, d, *out))                                                                              \
    VOID(destroy_target, (void *u, fogvol_handle h), (REC_U, h), rec_handle_given(r, h))                             \
    RESULT(create_program, (void *u, const fogvol_program_desc *d, fogvol_handle *out), (REC_U, d, out),             \
           rec_layout_given(r, d), rec_program_made(r, d, *out))                                                     \
    VOID(destroy_program, (void *u, fogvol_handle h), (REC_U, h), rec_handle_given(r, h))                            \
    RESULT(create_mesh, (void *u, const fogvol_mesh_data *d, fogvol_handle *out), (REC_U, d, out), REC_NONE,         \
           REC_NONE)                                                                                                 \
    VOID(destroy_mesh, (void *u, fogvol_handle h), (REC_U, h), rec_handle_given(r, h))                               \
    VOID(begin_pass, (void *u, const fogvol_pass *p), (REC_U, p), rec_pass_begun(r))                                 \
    VOID(set_draw, (void *u, const fogvol_draw *d), (REC_U, d), rec_set_draw_call(r, d))                             \
    VOID(draw_mesh, (void *u, fogvol_handle m, const fogvol_draw *d), (REC_U, m, d), rec_draw_call(r, m, d))         \
    VOID(draw_fullscreen, (void *u), (REC_U), rec_in_pass(r))                                                        \
    VOID(end_pass, (void *u), (REC_U), rec_pass_ended(r))                                                            \
    RESULT(read_target, (void *u, fogvol_handle t, unsigned char *rgba, size_t size), (REC_U, t, rgba, size),        \
           REC_NONE, REC_NONE)

#define REC_U r->inner.user_data
#define REC_NONE (void)0
#define REC_RESULT_FN(entry, params, args, before, after)                                                            \
    static fogvol_result rec_##entry params                                                                          \
    {                                                                                                                \
        rec *r = (rec *)u;                                                                                           \
        fogvol_result res;                                                                                           \
        before;                                                                                                      \
        res = r->inner.entry args;                                                                                   \
        if (res == FOGVOL_SUCCESS) after;                                                                            \
        return res;                                                                                                  \
    }
#define REC_VOID_FN(entry, params, args, before)                                                                     \
    static void rec_##entry params                                                                                   \
    {                                                                                                                \
        rec *r = (rec *)u;                                                                                           \
        before;                                                                                                      \
        r->inner.entry args;                                                                                         \
    }
REC_CALLS(REC_RESULT_FN, REC_VOID_FN)

static void rec_init(rec *r)
{
    memset(r, 0, sizeof *r);
    fogvol_null_backend_init(&r->nb, &r->inner);
    r->table = r->inner;
    r->table.user_data = r;
#define REC_INSTALL_RESULT(entry, params, args, before, after) r->table.entry = rec_##entry;
#define REC_INSTALL_VOID(entry, params, args, before) r->table.entry = rec_##entry;
    REC_CALLS(REC_INSTALL_RESULT, REC_INSTALL_VOID)
#undef REC_INSTALL_RESULT
#undef REC_INSTALL_VOID
}

static fogvol_handle rec_program(const rec *r, int kind)
{
    int i;
    fogvol_handle h = 0;
    for (i = 0; i < r->nprog; ++i)
        if (r->prog[i].kind == (int)kind) {
            assert_int_equal(h, 0); /* one of each */
            h = r->prog[i].h;
        }
    assert_int_not_equal(h, 0);
    return h;
}

static fogvol_handle rec_texture_sized(const rec *r, int w, int h)
{
    int i;
    fogvol_handle t = 0;
    for (i = 0; i < r->ntex; ++i)
        if (r->tex[i].w == w && r->tex[i].hgt == h) {
            assert_int_equal(t, 0);
            t = r->tex[i].h;
        }
    assert_int_not_equal(t, 0);
    return t;
}

static unsigned g_rec_speedups_off; /* rec_context's fogvol_context_desc.disable_speedups */

static fogvol_context *rec_context(rec *r, logcap *lc, counting *cnt)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    memset(&cd, 0, sizeof cd);
    cd.backend = r->table;
    cd.disable_speedups = g_rec_speedups_off;
    cd.tier = FOGVOL_TIER_PS20; /* the null backend reports no caps: AUTO would pick PS13 */
    if (lc) cd.logger = cap_logger(lc);
    if (cnt) cd.allocator = cnt_allocator(cnt);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_non_null(fv);
    return fv;
}

/* The camera of the null-backend tests, worked out by hand: eye at (5,0,0) looking down -x, up +y.
   View rows: x_v = -z, y_v = y, z_v = x - 5, so the view depth is w = 5 - x (world).
   near 0.5, far 10.5: d = (w - 0.5) / 10. Viewport at (10, 20), 64 x 48. */
#define A_W 64
#define A_H 48
#define A_X0 10
#define A_Y0 20
#define A_NEAR 0.5f
#define A_FAR 10.5f

static void a_frame_desc(fogvol_frame_desc *fd)
{
    static const float view[16] = {0, 0, 1, 0, /* column 0 */
                                   0, 1, 0, 0, /* column 1 */
                                   -1, 0, 0, 0, /* column 2 */
                                   0, 0, -5, 1};
    memset(fd, 0, sizeof *fd);
    memcpy(fd->view, view, sizeof view);
    glu_perspective(fd->projection, 60.0, (double)A_W / A_H, A_NEAR, A_FAR);
    fd->znear = A_NEAR;
    fd->zfar = A_FAR;
    fd->viewport[0] = A_X0;
    fd->viewport[1] = A_Y0;
    fd->viewport[2] = A_W;
    fd->viewport[3] = A_H;
}

/* ---- expected pass, filled by hand in the tests ---- */
typedef struct xpass {
    fogvol_handle target;
    int vp[4];
    int clear;
    float clear_color[4];
    fogvol_pass_blend blend;
    fogvol_cull cull;
    int depth_test, depth_write;
    fogvol_handle program;
    fogvol_handle tex[FOGVOL_MAX_TEXTURE_UNITS];
    float screen[4];
    int fullscreen;
    int ndraw;
    fogvol_handle draws[8];
} xpass;

static void x_target_pass(xpass *x, fogvol_handle target, int clear, fogvol_cull cull, fogvol_handle program,
                          const fogvol_handle tex[FOGVOL_MAX_TEXTURE_UNITS])
{
    memset(x, 0, sizeof *x);
    x->target = target;
    x->vp[2] = A_W;
    x->vp[3] = A_H;
    x->clear = clear;
    x->blend = FOGVOL_PASS_BLEND_ADD;
    x->cull = cull;
    x->program = program;
    memcpy(x->tex, tex, sizeof x->tex);
    x->screen[0] = 1.0f / A_W;
    x->screen[1] = 1.0f / A_H;
}

static void x_composite(xpass *x, fogvol_pass_blend blend, int geometry, fogvol_handle program, fogvol_handle b,
                        fogvol_handle f, fogvol_handle ramp_tex)
{
    memset(x, 0, sizeof *x);
    x->vp[0] = A_X0;
    x->vp[1] = A_Y0;
    x->vp[2] = A_W;
    x->vp[3] = A_H;
    x->blend = blend;
    (void)geometry; /* both composites: the full-screen program (geometry adds a scissor) */
    x->cull = FOGVOL_CULL_NONE;
    x->program = program;
    x->tex[0] = b;
    x->tex[1] = f;
    x->tex[2] = ramp_tex;
    x->screen[0] = 1.0f / A_W;
    x->screen[1] = 1.0f / A_H;
    x->screen[2] = -(float)A_X0;
    x->screen[3] = -(float)A_Y0;
    x->fullscreen = 1;
}

static void x_add_draw(xpass *x, fogvol_handle m) { x->draws[x->ndraw++] = m; }

static void check_pass(const rec *r, int i, const xpass *x, const char *what)
{
    const fogvol_pass *p = &r->nb.passes[i];
    int k, n = 0;
    char w[128];
    snprintf(w, sizeof w, "%s pass %d", what, i);
    if (p->target != x->target) fail_msg("%s: target %lu, want %lu", w, (unsigned long)p->target, (unsigned long)x->target);
    for (k = 0; k < 4; ++k)
        if (p->viewport[k] != x->vp[k])
            fail_msg("%s: viewport (%d,%d,%d,%d), want (%d,%d,%d,%d)", w, p->viewport[0], p->viewport[1],
                     p->viewport[2], p->viewport[3], x->vp[0], x->vp[1], x->vp[2], x->vp[3]);
    if ((p->clear != 0) != (x->clear != 0)) fail_msg("%s: clear %d, want %d", w, p->clear, x->clear);
    if (x->clear)
        for (k = 0; k < 4; ++k) assert_close(p->clear_color[k], x->clear_color[k], 1e-6, w);
    if (p->blend != x->blend) fail_msg("%s: blend %d, want %d", w, (int)p->blend, (int)x->blend);
    if (p->cull != x->cull) fail_msg("%s: cull %d, want %d", w, (int)p->cull, (int)x->cull);
    if ((p->depth_test != 0) != (x->depth_test != 0)) fail_msg("%s: depth_test %d", w, p->depth_test);
    if ((p->depth_write != 0) != (x->depth_write != 0)) fail_msg("%s: depth_write %d", w, p->depth_write);
    if (p->program != x->program) fail_msg("%s: program %lu, want %lu", w, (unsigned long)p->program, (unsigned long)x->program);
    for (k = 0; k < FOGVOL_MAX_TEXTURE_UNITS; ++k)
        if (x->tex[k] && p->textures[k] != x->tex[k])
            fail_msg("%s: unit %d texture %lu, want %lu", w, k, (unsigned long)p->textures[k], (unsigned long)x->tex[k]);
    for (k = 0; k < FOGVOL_MAX_TEXTURE_UNITS; ++k) /* no pass samples the target it renders into */
        if (p->target && p->textures[k] == p->target) fail_msg("%s: unit %d samples the pass's own target", w, k);
    for (k = 0; k < 4; ++k) assert_close(p->uniforms[FOGVOL_U_SCREEN][k], x->screen[k], 1e-6, w);
    if (r->nb.fullscreen[i] != x->fullscreen) fail_msg("%s: %d full-screen draws, want %d", w, r->nb.fullscreen[i], x->fullscreen);
    if (r->nb.draws[i] != x->ndraw) fail_msg("%s: %d mesh draws, want %d", w, r->nb.draws[i], x->ndraw);
    for (k = 0; k < r->ndraws; ++k) {
        if (r->draws[k].pass != i) continue;
        if (n >= x->ndraw || r->draws[k].mesh != x->draws[n])
            fail_msg("%s: draw %d is mesh %lu, want %lu", w, n, (unsigned long)r->draws[k].mesh,
                     n < x->ndraw ? (unsigned long)x->draws[n] : 0ul);
        ++n;
    }
    assert_int_equal(n, x->ndraw);
}

/* Uniforms every pass carries, from the encoding worked out by hand for L = 4. */
static void check_common_uniforms(const fogvol_pass *p, const fogvol_constants *k, int dither, int count,
                                  const char *what)
{
    const double N = 16.0, D = 32.0, lsb3 = 1.0 / 4096.0, range = A_FAR - A_NEAR, scale = range * 255.0 / N;
    int j;
    /* fv_enc (N, N^2, depth_offset = 2^-3L, depth_max = 1 - 1.5 * 2^-3L) */
    assert_close(p->uniforms[FOGVOL_U_ENC][0], N, 1e-7, what);
    assert_close(p->uniforms[FOGVOL_U_ENC][1], N * N, 1e-7, what);
    assert_close(p->uniforms[FOGVOL_U_ENC][2], lsb3, 1e-6, what);
    assert_close(p->uniforms[FOGVOL_U_ENC][3], 1.0 - 1.5 * lsb3, 1e-7, what);
    /* fv_dith (255 or 0, 1/D) */
    assert_close(p->uniforms[FOGVOL_U_DITHER][0], dither ? 255.0 : 0.0, 1e-7, what);
    assert_close(p->uniforms[FOGVOL_U_DITHER][1], 1.0 / D, 1e-7, what);
    /* fv_dec = scale * (1, 2^-L, 2^-2L, -2^-L), and equal to fogvol_compute_constants' */
    assert_close(p->uniforms[FOGVOL_U_DECODE][0], scale, 1e-6, what);
    assert_close(p->uniforms[FOGVOL_U_DECODE][1], scale / N, 1e-6, what);
    assert_close(p->uniforms[FOGVOL_U_DECODE][2], scale / (N * N), 1e-6, what);
    /* alpha: the borrow of the blue digit; with face counts in alpha (COUNT) not decoded */
    assert_close(p->uniforms[FOGVOL_U_DECODE][3], count ? 0.0 : -scale / N, 1e-6, what);
    for (j = 0; j < 4; ++j) assert_close(p->uniforms[FOGVOL_U_DECODE][j], count && j == 3 ? 0.0 : k->decode[j], 1e-7, what);
}

static void check_depth_row(const fogvol_draw *d, const double p[3], double w, const char *what)
{
    double want = (w - A_NEAR) / (A_FAR - A_NEAR);
    double got = vec4_dot_p1(d->depth, p);
    if (fabs(got - want) > 1e-6)
        fail_msg("%s: depth row at (%g,%g,%g) gives %.8f, want (w=%g - near)/(far - near) = %.8f", what, p[0], p[1],
                 p[2], got, w, want);
    /* clip w = view depth (row 3 of the mvp) */
    got = mat_row_dot(d->mvp, 3, p);
    if (fabs(got - w) > 1e-5) fail_msg("%s: clip w at (%g,%g,%g) = %.7f, want %g", what, p[0], p[1], p[2], got, w);
}

/* ---- the passes of one frame ---- */

typedef struct pass_scene {
    rec r;
    logcap lc;
    fogvol_context *fv;
    shp_mesh box, plane;
    fogvol_mesh *vol[5], *occ[2];
    fogvol_ramp *fog, *light;
    float vmodel[5][16], omodel[2][16];
} pass_scene;

/* Volumes in submission order:
     V0 light +  T(1,2,-3) S(2)     (its depth row is checked at hand-computed points)
     V1 fog   +  T(0,0,1)
     V2 light -  identity
     V3 light +  T(0,1,0) S(-1,1,1) (mirror: front_cw = 1)
     V4 fog   +  T(0,-1,0)
   Occluders: O0 open plane T(0,0,-2), O1 box T(-2,0,0). */
static void pass_scene_build(pass_scene *s)
{
    int i;
    memset(s, 0, sizeof *s);
    rec_init(&s->r);
    s->fv = rec_context(&s->r, &s->lc, NULL);
    s->box = box_mesh();
    s->plane = shp_grid_plane(1, 1, 2);
    for (i = 0; i < 5; ++i) assert_int_equal(make_mesh(s->fv, &s->box, 0, 0, &s->vol[i]), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(s->fv, &s->plane, 1, 0, &s->occ[0]), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(s->fv, &s->box, 0, 0, &s->occ[1]), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(s->fv, FOGVOL_BLEND_FOG, &s->fog), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(s->fv, FOGVOL_BLEND_LIGHT, &s->light), FOGVOL_SUCCESS);
    mat_ts(s->vmodel[0], 1, 2, -3, 2, 2, 2);
    mat_ts(s->vmodel[1], 0, 0, 1, 1, 1, 1);
    mat_ts(s->vmodel[2], 0, 0, 0, 1, 1, 1);
    mat_ts(s->vmodel[3], 0, 1, 0, -1, 1, 1);
    mat_ts(s->vmodel[4], 0, -1, 0, 1, 1, 1);
    mat_ts(s->omodel[0], 0, 0, -2, 1, 1, 1);
    mat_ts(s->omodel[1], -2, 0, 0, 1, 1, 1);
}

static void pass_scene_submit(pass_scene *s, fogvol_composite comp, fogvol_frame_stats *st)
{
    static const int ramp_of[5] = {1, 0, 1, 1, 0}; /* 1 = light */
    static const int neg[5] = {0, 0, 1, 0, 0};
    fogvol_frame_desc fd;
    int i;
    a_frame_desc(&fd);
    fd.composite = comp;
    assert_int_equal(fogvol_begin_frame(s->fv, &fd), FOGVOL_SUCCESS);
    for (i = 0; i < 2; ++i) assert_int_equal(fogvol_add_occluder(s->fv, s->occ[i], s->omodel[i]), FOGVOL_SUCCESS);
    for (i = 0; i < 5; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = s->vol[i];
        vd.ramp = ramp_of[i] ? s->light : s->fog;
        vd.negative = neg[i];
        memcpy(vd.model, s->vmodel[i], sizeof vd.model);
        assert_int_equal(fogvol_add_volume(s->fv, &vd), FOGVOL_SUCCESS);
    }
    assert_int_equal(fogvol_end_frame(s->fv, st), FOGVOL_SUCCESS);
}

static void pass_scene_free(pass_scene *s)
{
    int i;
    for (i = 0; i < 5; ++i) fogvol_destroy_mesh(s->fv, s->vol[i]);
    for (i = 0; i < 2; ++i) fogvol_destroy_mesh(s->fv, s->occ[i]);
    fogvol_destroy_ramp(s->fv, s->fog);
    fogvol_destroy_ramp(s->fv, s->light);
    fogvol_destroy_context(s->fv);
    assert_int_equal(s->r.nb.creates, s->r.nb.destroys);
    assert_int_equal(s->r.protocol_errors, 0);
    shp_free(&s->box);
    shp_free(&s->plane);
}

/* The backend handle of every mesh: learnt by drawing each as the only occluder of a frame. */
static fogvol_handle g_mh_handles[16];
static const fogvol_mesh *g_mh_meshes[16];
static int g_mh_n;

static void learn_handles(rec *r, fogvol_context *fv, fogvol_mesh *const *meshes, int n)
{
    fogvol_frame_desc fd;
    float id[16];
    int i;
    a_frame_desc(&fd);
    mat_identity(id);
    g_mh_n = 0;
    for (i = 0; i < n; ++i) {
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_occluder(fv, meshes[i], id), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, NULL), FOGVOL_SUCCESS);
        assert_int_equal(r->ndraws, 1);
        g_mh_meshes[g_mh_n] = meshes[i];
        g_mh_handles[g_mh_n++] = r->draws[0].mesh;
    }
}

static fogvol_handle mh(const fogvol_mesh *m)
{
    int i;
    for (i = 0; i < g_mh_n; ++i)
        if (g_mh_meshes[i] == m) return g_mh_handles[i];
    fail_msg("mesh handle not learnt");
    return 0;
}

static void pass_scene_check(pass_scene *s, int geometry)
{
    rec *r = &s->r;
    fogvol_frame_stats st;
    fogvol_constants k;
    fogvol_handle enc, face, comp, rg, blue, dith, O = 0, B, F, tl, tf;
    fogvol_handle lookup[FOGVOL_MAX_TEXTURE_UNITS] = {0}, faces[FOGVOL_MAX_TEXTURE_UNITS] = {0};
    fogvol_encoding e;
    xpass x[9];
    int i, n_depth = 0, n_plain = 0;
    fogvol_mesh *all[7];
    /* FOGVOL_SPEEDUP_DEPTH_TEST: every box lies between the planes (w from 2 to 6, near 0.5, far 10.5), so
       the frame is drawn as COUNT: programs with FOGVOL_SPECIALIZE_COUNT, faces depth-tested against the
       occluders' depth, the composite reads O's counts (unit 3) */
    int count = !(g_rec_speedups_off & FOGVOL_SPEEDUP_DEPTH_TEST);
    unsigned cbit = count ? (unsigned)FOGVOL_SPECIALIZE_COUNT : 0u;

    for (i = 0; i < 5; ++i) all[i] = s->vol[i];
    all[5] = s->occ[0];
    all[6] = s->occ[1];
    learn_handles(r, s->fv, all, 7);
    for (i = 0; i < 7; ++i) {
        int j;
        for (j = 0; j < i; ++j) assert_int_not_equal(mh(all[i]), mh(all[j])); /* distinct meshes, distinct handles */
    }

    log_reset(&s->lc);
    pass_scene_submit(s, geometry ? FOGVOL_COMPOSITE_GEOMETRY : FOGVOL_COMPOSITE_FULLSCREEN, &st);
    assert_int_equal(s->lc.errors + s->lc.warnings, 0);
    assert_int_equal(r->protocol_errors, 0);

    /* stats: 1 (O) + light group (B, B-, F, F-, composite) + fog group (B, F, composite) */
    assert_int_equal(st.passes, 9);
    assert_int_equal(r->nb.pass_count, 9);
    assert_int_equal(r->begin_pass_calls, 9);
    assert_int_equal(r->end_pass_calls, 9);
    assert_int_equal(st.groups, 2);
    assert_int_equal(st.volumes, 5);
    assert_int_equal(st.occluders, 2);
    assert_int_equal(st.overflow_pixels, 0);
    assert_int_equal(r->nb.frames_begun, r->nb.frames_ended);

    /* resources identified by what they are, not by creation order */
    enc = rec_program(r, KIND(FOGVOL_PROGRAM_ENCODE, FOGVOL_SPECIALIZE_DITHER | ENC4 | cbit)); /* the ALU encode, dither on */
    /* the passes run programs built for their configuration: occluders, so the faces read O, no density
       texture; extinction ramps reaching 7 / density: the exp() composite (FAST_EXP), no colour
       texture, no show_overflow; the viewport starts at (A_X0, A_Y0): reads with the offset (no ORIGIN) */
    face = rec_program(r, KIND(FOGVOL_PROGRAM_FACE, FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_DITHER | ENC4 | cbit));
    comp = rec_program(r, KIND(FOGVOL_PROGRAM_COMPOSITE, FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_FAST_EXP |
                                                             FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                                             FOGVOL_SPECIALIZE_NO_OVERFLOW | cbit));
    rg = blue = 0; /* PS20 encodes by arithmetic by default (FOGVOL_SPEEDUP_ALU): no rg or blue ramp */
    for (i = 0; i < r->ntex; ++i) assert_true(r->tex[i].w != 16 * 32 && !(r->tex[i].w == 16 && r->tex[i].hgt == 16));
    dith = rec_texture_sized(r, 8, 8);          /* 8 x 8 */
    for (i = 0; i < r->ntex; ++i) /* the two colour ramps: 256 x 1, LINEAR, CLAMP */
        if (r->tex[i].hgt == 1) {
            assert_int_equal(r->tex[i].w, 256);
            assert_int_equal(r->tex[i].filter, FOGVOL_FILTER_LINEAR);
            assert_int_equal(r->tex[i].wrap, FOGVOL_WRAP_CLAMP);
        }
    /* targets: created once, at the first end_frame, at the viewport size; one with depth (O) */
    assert_int_equal(r->ntgt, 3);
    for (i = 0; i < r->ntgt; ++i) {
        assert_int_equal(r->tgt[i].w, A_W);
        assert_int_equal(r->tgt[i].hgt, A_H);
        if (r->tgt[i].depth) {
            O = r->tgt[i].h;
            n_depth++;
        } else {
            n_plain++;
        }
    }
    assert_int_equal(n_depth, 1);
    assert_int_equal(n_plain, 2);
    /* B and F: what the composite samples as fv_back (unit 0) and fv_front (unit 1) */
    B = r->nb.passes[5].textures[0];
    F = r->nb.passes[5].textures[1];
    assert_int_not_equal(B, F);
    for (i = 0; i < 2; ++i) {
        fogvol_handle t = i ? F : B;
        int j, ok = 0;
        for (j = 0; j < r->ntgt; ++j) ok |= r->tgt[j].h == t && !r->tgt[j].depth;
        assert_true(ok);
    }
    /* colour ramp textures: the light ramp was created second */
    {
        int j, nr = 0;
        fogvol_handle ramps[2] = {0, 0};
        for (j = 0; j < r->ntex; ++j)
            if (r->tex[j].hgt == 1) ramps[nr++] = r->tex[j].h;
        assert_int_equal(nr, 2);
        tf = ramps[0];
        tl = ramps[1];
    }
    lookup[0] = rg;
    lookup[1] = blue;
    lookup[2] = dith;
    lookup[3] = 0;
    faces[0] = rg;
    faces[1] = blue;
    faces[2] = dith;
    faces[3] = O;

    /* pass 0: O */
    memset(&x[0], 0, sizeof x[0]);
    x_target_pass(&x[0], O, 1, FOGVOL_CULL_NONE, enc, lookup);
    x[0].blend = FOGVOL_PASS_BLEND_NONE;
    x[0].depth_test = x[0].depth_write = 1;
    x[0].clear_color[0] = x[0].clear_color[1] = x[0].clear_color[2] = 15.0f / 255.0f;
    x[0].clear_color[3] = 0.0f;
    x_add_draw(&x[0], mh(s->occ[0]));
    x_add_draw(&x[0], mh(s->occ[1]));
    /* light group (V0 first): positives V0, V3; negative V2 */
    x_target_pass(&x[1], B, 1, FOGVOL_CULL_FRONT, face, faces);
    x_add_draw(&x[1], mh(s->vol[0]));
    x_add_draw(&x[1], mh(s->vol[3]));
    x_target_pass(&x[2], B, 0, FOGVOL_CULL_BACK, face, faces);
    x_add_draw(&x[2], mh(s->vol[2]));
    x_target_pass(&x[3], F, 1, FOGVOL_CULL_BACK, face, faces);
    x_add_draw(&x[3], mh(s->vol[0]));
    x_add_draw(&x[3], mh(s->vol[3]));
    x_target_pass(&x[4], F, 0, FOGVOL_CULL_FRONT, face, faces);
    x_add_draw(&x[4], mh(s->vol[2]));
    x_composite(&x[5], FOGVOL_PASS_BLEND_LIGHT, geometry, comp, B, F, tl);
    /* fog group: V1, V4 */
    x_target_pass(&x[6], B, 1, FOGVOL_CULL_FRONT, face, faces);
    x_add_draw(&x[6], mh(s->vol[1]));
    x_add_draw(&x[6], mh(s->vol[4]));
    x_target_pass(&x[7], F, 1, FOGVOL_CULL_BACK, face, faces);
    x_add_draw(&x[7], mh(s->vol[1]));
    x_add_draw(&x[7], mh(s->vol[4]));
    x_composite(&x[8], FOGVOL_PASS_BLEND_FOG, geometry, comp, B, F, tf);
    for (i = 1; i < 9 && count; ++i) {
        if (i == 5 || i == 8) x[i].tex[3] = O; /* the composite: O's counts */
        else x[i].depth_test = 1;              /* the faces: against the occluders' depth, not written */
    }
    for (i = 0; i < 9; ++i) check_pass(r, i, &x[i], geometry ? "geometry" : "fullscreen");
    for (i = 1; i < 9; ++i) { /* B/F clear to zero */
        if (r->nb.passes[i].clear) {
            int c;
            for (c = 0; c < 4; ++c) assert_close(r->nb.passes[i].clear_color[c], 0.0, 1e-7, "B/F clear colour");
        }
    }
    for (i = 5; i < 9; i += 3) { /* a scissor inside the viewport (full-screen too: every composite is scissored) */
        const int *sc = r->nb.passes[i].scissor;
        (void)geometry;
        assert_true(sc[2] > 0 && sc[3] > 0);
        assert_true(sc[0] >= A_X0 && sc[1] >= A_Y0 && sc[0] + sc[2] <= A_X0 + A_W && sc[1] + sc[3] <= A_Y0 + A_H);
    }

    /* uniforms */
    assert_int_equal(fogvol_encoding_init(4, &e), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_compute_constants(&e, A_NEAR, A_FAR, 0.0f, &k), FOGVOL_SUCCESS);
    for (i = 0; i < 9; ++i) check_common_uniforms(&r->nb.passes[i], &k, 1, count, "pass uniforms");
    for (i = 5; i < 9; i += 3) {
        /* fv_rampmap: t = 0 -> centre of texel 0, t = max_thickness (7/density = 14) -> centre of the last */
        const float *rm = r->nb.passes[i].uniforms[FOGVOL_U_RAMP];
        assert_close(rm[1], 0.5 / 256.0, 1e-6, "ramp offset");
        assert_close(rm[0] * 14.0 + rm[1], 1.0 - 0.5 / 256.0, 1e-6, "ramp slope");
        assert_close(rm[2], 0.0, 0.0, "overflow flag off");
    }

    /* draws: depth rows and winding */
    for (i = 0; i < r->ndraws; ++i) {
        const rec_draw *d = &r->draws[i];
        if (d->mesh == mh(s->vol[0])) {
            /* world = (1 + 2px, 2 + 2py, -3 + 2pz): w = 5 - x = 4 - 2 px */
            static const double p0[3] = {0, 0, 0}, p1[3] = {1, 0, 0}, p2[3] = {-1, 5, 7}, p3[3] = {0.25, -0.5, 0.5};
            check_depth_row(&d->d, p0, 4.0, "V0");
            check_depth_row(&d->d, p1, 2.0, "V0");
            check_depth_row(&d->d, p2, 6.0, "V0");
            check_depth_row(&d->d, p3, 3.5, "V0");
            assert_int_equal(d->d.front_cw, 0);
        } else if (d->mesh == mh(s->vol[3])) {
            /* mirror S(-1,1,1): world x = -px, w = 5 + px */
            static const double p0[3] = {0, 0, 0}, p1[3] = {1, 0, 0}, p2[3] = {-2, 3, 3};
            check_depth_row(&d->d, p0, 5.0, "V3");
            check_depth_row(&d->d, p1, 6.0, "V3");
            check_depth_row(&d->d, p2, 3.0, "V3");
            assert_int_equal(d->d.front_cw, 1);
        } else if (d->mesh == mh(s->occ[1])) {
            static const double p0[3] = {0, 0, 0}, p1[3] = {-1, 0, 0};
            check_depth_row(&d->d, p0, 7.0, "O1");
            check_depth_row(&d->d, p1, 8.0, "O1");
            assert_int_equal(d->d.front_cw, 0);
        } else {
            /* every other model is a translation: w = 5 - (px + tx) */
            static const double p0[3] = {0.5, 0.5, 0.5};
            double w = 5.0 - 0.5;
            assert_int_equal(d->d.front_cw, 0);
            check_depth_row(&d->d, p0, w, "translated"); /* tx = 0 for V1, V2, V4 and O0 */
        }
    }
}

static void test_passes_of_a_frame_fullscreen(void **state)
{
    pass_scene *s = (pass_scene *)calloc(1, sizeof *s);
    (void)state;
    pass_scene_build(s);
    pass_scene_check(s, 0);
    pass_scene_free(s);
    free(s);
}

/* A context of tier t and variants on the recording backend (extra caps, speed-ups off) with a box volume of
   half-size 0.5 (model: at the origin) and an open plane occluder at x = 0, z = -2 (om). */
typedef struct box_scene {
    rec r;
    fogvol_context *fv;
    fogvol_mesh *box, *plane;
    fogvol_ramp *ramp;
    shp_mesh bm, pm;
    fogvol_volume_desc vd;
    float om[16];
} box_scene;

static void box_scene_open(box_scene *b, fogvol_tier t, unsigned variants, unsigned caps, unsigned off, logcap *lc)
{
    fogvol_context_desc cd;
    rec_init(&b->r);
    b->r.table.caps |= caps;
    memset(&cd, 0, sizeof cd);
    cd.backend = b->r.table;
    cd.tier = t;
    cd.variants = variants;
    cd.disable_speedups = off;
    if (lc) cd.logger = cap_logger(lc);
    b->fv = NULL;
    assert_int_equal(fogvol_create_context(&cd, &b->fv), FOGVOL_SUCCESS);
    b->bm = box_mesh();
    b->pm = shp_grid_plane(1, 1, 2);
    assert_int_equal(make_mesh(b->fv, &b->bm, 0, 0, &b->box), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(b->fv, &b->pm, 1, 0, &b->plane), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(b->fv, FOGVOL_BLEND_FOG, &b->ramp), FOGVOL_SUCCESS);
    memset(&b->vd, 0, sizeof b->vd);
    b->vd.mesh = b->box;
    b->vd.ramp = b->ramp;
    mat_ts(b->vd.model, 0, 0, 0, 1, 1, 1);
    mat_ts(b->om, 0, 0, -2, 1, 1, 1);
}

static void box_scene_close(box_scene *b)
{
    fogvol_destroy_mesh(b->fv, b->box);
    fogvol_destroy_mesh(b->fv, b->plane);
    fogvol_destroy_ramp(b->fv, b->ramp);
    fogvol_destroy_context(b->fv);
    assert_int_equal(b->r.nb.creates, b->r.nb.destroys);
    shp_free(&b->bm);
    shp_free(&b->pm);
}

/* FOGVOL_SPEEDUP_DEPTH_TEST takes a frame only where the face count holds: occluders drawn by fogvol,
   and every volume's box wholly between the planes or wholly outside them, on PS20 and PS13 (FLOAT
   keeps the min compare). The camera of the null-backend tests (w = 5 - x, near 0.5, far 10.5) and a box of
   half-size 0.5 at x = tx: w from 4.5 - tx to 5.5 - tx. */
static void test_depth_test_only_where_count_holds(void **state)
{
    static const struct {
        float tx;
        int occluders, off, tested;
        const char *what;
    } c[] = {{0.0f, 1, 0, 1, "between the planes"},
             {7.0f, 1, 0, 1, "behind the eye (w -2.5 .. -1.5)"},
             {-7.0f, 1, 0, 1, "beyond the far plane (w 11.5 .. 12.5)"},
             {5.0f, 1, 0, 0, "the eye inside (w -0.5 .. 0.5)"},
             {4.3f, 1, 0, 0, "cut by the near plane (w 0.2 .. 1.2)"},
             {-5.3f, 1, 0, 0, "cut by the far plane (w 9.8 .. 10.8)"},
             {0.0f, 0, 0, 0, "no occluder"},
             {0.0f, 1, 1, 0, "FOGVOL_SPEEDUP_DEPTH_TEST off"}};
    static const fogvol_tier tiers[3] = {FOGVOL_TIER_PS20, FOGVOL_TIER_PS13, FOGVOL_TIER_FLOAT};
    int t, i;
    (void)state;
    for (t = 0; t < 3; ++t)
        for (i = 0; i < (int)(sizeof c / sizeof c[0]); ++i) {
            static box_scene b;
            fogvol_frame_desc fd;
            fogvol_frame_stats st;
            int k, face_passes = 0, want = tiers[t] == FOGVOL_TIER_FLOAT ? 0 : c[i].tested;
            box_scene_open(&b, tiers[t], 0u, FOGVOL_CAP_FLOAT_BLEND, c[i].off ? FOGVOL_SPEEDUP_DEPTH_TEST : 0u, NULL);
            a_frame_desc(&fd);
            assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
            if (c[i].occluders) assert_int_equal(fogvol_add_occluder(b.fv, b.plane, b.om), FOGVOL_SUCCESS);
            mat_ts(b.vd.model, c[i].tx, 0, 0, 1, 1, 1);
            assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_end_frame(b.fv, &st), FOGVOL_SUCCESS);
            if (st.depth_tested != want)
                fail_msg("%s, %s: depth_tested %d, want %d", fogvol_tier_name(tiers[t]), c[i].what, st.depth_tested,
                         want);
            for (k = 0; k < b.r.nb.pass_count; ++k) /* the face passes: depth-tested exactly then */
                if (b.r.nb.passes[k].target && b.r.nb.passes[k].blend != FOGVOL_PASS_BLEND_NONE) {
                    assert_int_equal(b.r.nb.passes[k].depth_test != 0, want);
                    assert_int_equal(b.r.nb.passes[k].depth_write, 0);
                    face_passes++;
                }
            assert_int_equal(face_passes, tiers[t] == FOGVOL_TIER_FLOAT ? 1 : 2);
            box_scene_close(&b);
        }
}

/* A backend of the Vulkan dialect (the recording backend says FOGVOL_GLSL_VULKAN): every tier builds its
   programs from Vulkan strings and hands each one the dialect's layout (fogvol_program_desc.layout),
   and a frame with an occluder, a volume and the overflow check runs through the same passes. */
static void test_vulkan_dialect_programs_and_passes(void **state)
{
    static const fogvol_tier tiers[4] = {FOGVOL_TIER_PS13, FOGVOL_TIER_PS20, FOGVOL_TIER_MRT, FOGVOL_TIER_FLOAT};
    int t;
    (void)state;
    for (t = 0; t < 4; ++t) {
        static box_scene b;
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        fogvol_context_desc cd;
        fogvol_uniform_layout want;
        rec_init(&b.r);
        b.r.table.dialect = FOGVOL_GLSL_VULKAN;
        b.r.table.caps |= FOGVOL_CAP_FLOAT_BLEND;
        memset(&cd, 0, sizeof cd);
        cd.backend = b.r.table;
        cd.tier = tiers[t];
        assert_int_equal(fogvol_create_context(&cd, &b.fv), FOGVOL_SUCCESS);
        b.bm = box_mesh();
        b.pm = shp_grid_plane(1, 1, 2);
        assert_int_equal(make_mesh(b.fv, &b.bm, 0, 0, &b.box), FOGVOL_SUCCESS);
        assert_int_equal(make_mesh(b.fv, &b.pm, 1, 0, &b.plane), FOGVOL_SUCCESS);
        assert_int_equal(make_ramp(b.fv, FOGVOL_BLEND_FOG, &b.ramp), FOGVOL_SUCCESS);
        memset(&b.vd, 0, sizeof b.vd);
        b.vd.mesh = b.box;
        b.vd.ramp = b.ramp;
        mat_ts(b.vd.model, 0, 0, 0, 1, 1, 1);
        mat_ts(b.om, 0, 0, -2, 1, 1, 1);
        a_frame_desc(&fd);
        assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
        if (tiers[t] == FOGVOL_TIER_MRT) {
            fogvol_mrt_info mi;
            assert_int_equal(fogvol_mrt_prepare(b.fv, &mi), FOGVOL_SUCCESS);
        } else {
            assert_int_equal(fogvol_add_occluder(b.fv, b.plane, b.om), FOGVOL_SUCCESS);
        }
        assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(b.fv, &st), FOGVOL_SUCCESS);
        assert_true(st.passes >= 2);
        assert_true(b.r.nprog >= 2);
        assert_int_equal(b.r.protocol_errors, 0); /* every program got the Vulkan layout */
        assert_int_equal(fogvol_dialect_layout(FOGVOL_GLSL_VULKAN, &want), FOGVOL_SUCCESS);
        box_scene_close(&b);
    }
}

/* The same frame drawn with the min compare (FOGVOL_SPEEDUP_DEPTH_TEST off): the faces read O. */
static void test_passes_of_a_frame_min_compare(void **state)
{
    pass_scene *s = (pass_scene *)calloc(1, sizeof *s);
    (void)state;
    g_rec_speedups_off = FOGVOL_SPEEDUP_DEPTH_TEST;
    pass_scene_build(s);
    pass_scene_check(s, 0);
    pass_scene_free(s);
    free(s);
    g_rec_speedups_off = 0;
}

static void test_passes_of_a_frame_geometry(void **state)
{
    pass_scene *s = (pass_scene *)calloc(1, sizeof *s);
    (void)state;
    pass_scene_build(s);
    pass_scene_check(s, 1);
    pass_scene_free(s);
    free(s);
}

/* A geometry composite: no warning, the full-screen triangle under a scissor. */
static void test_geometry_composite_under_scissor(void **state)
{
    pass_scene *s = (pass_scene *)calloc(1, sizeof *s);
    fogvol_frame_stats st;
    (void)state;
    pass_scene_build(s);
    log_reset(&s->lc);
    pass_scene_submit(s, FOGVOL_COMPOSITE_GEOMETRY, &st);
    assert_int_equal(st.passes, 9);
    assert_int_equal(s->lc.warnings, 0);
    assert_true(s->r.nb.passes[5].scissor[2] > 0);
    assert_int_equal(s->r.nb.fullscreen[5], 1);
    assert_int_equal(s->r.nb.draws[5], 0);
    assert_int_equal(s->r.nb.fullscreen[8], 1);
    pass_scene_free(s);
    free(s);
}

/* ---- a group of negative volumes only ---- */
static void test_negative_only_group_draws_nothing(void **state)
{
    rec r;
    logcap lc;
    fogvol_context *fv;
    shp_mesh box = box_mesh();
    fogvol_mesh *m[3];
    fogvol_ramp *fog, *light;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_volume_desc vd;
    int i, volumes1, volumes2;
    (void)state;
    log_reset(&lc);
    rec_init(&r);
    fv = rec_context(&r, &lc, NULL);
    for (i = 0; i < 3; ++i) assert_int_equal(make_mesh(fv, &box, 0, 0, &m[i]), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &fog), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_LIGHT, &light), FOGVOL_SUCCESS);
    a_frame_desc(&fd);

    /* frame 1: light group = one negative volume (first), fog group = one positive volume.
       Expected: O, then the fog group only (B, F, composite): 4 passes, 1 group, 1 volume drawn. */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    mat_identity(vd.model);
    vd.mesh = m[0];
    vd.ramp = light;
    vd.negative = 1;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    vd.mesh = m[1];
    vd.ramp = fog;
    vd.negative = 0;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(r.nb.pass_count, 4);
    assert_int_equal(st.passes, 4);
    assert_int_equal(st.groups, 1);
    assert_int_equal(r.nb.passes[3].blend, FOGVOL_PASS_BLEND_FOG);
    assert_int_equal(r.nb.passes[3].target, 0);
    /* the negative volume is drawn nowhere */
    assert_int_equal(r.ndraws, 2); /* m[1] into B and into F */
    for (i = 0; i < r.ndraws; ++i) assert_int_equal(r.draws[i].mesh, r.draws[0].mesh);
    volumes1 = st.volumes; /* checked after the clean-up, so that a failure leaks nothing */

    /* frame 2: only a negative group: nothing composited, nothing drawn; no O pass either (no
       occluder: O still holds frame 1's far plane, FOGVOL_SPEEDUP_SKIP_OPAQUE) */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    vd.mesh = m[0];
    vd.ramp = light;
    vd.negative = 1;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    vd.mesh = m[2];
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(r.nb.pass_count, 0);
    assert_int_equal(st.passes, 0);
    assert_int_equal(st.groups, 0);
    assert_int_equal(r.ndraws, 0);
    assert_int_equal(r.nb.fullscreen[0], 0);
    volumes2 = st.volumes;

    for (i = 0; i < 3; ++i) fogvol_destroy_mesh(fv, m[i]);
    fogvol_destroy_ramp(fv, fog);
    fogvol_destroy_ramp(fv, light);
    fogvol_destroy_context(fv);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    assert_int_equal(r.protocol_errors, 0);
    shp_free(&box);
    /* frame_stats.volumes counts the volumes drawn: the negative-only group drew nothing */
    if (volumes1 != 1 || volumes2 != 0)
        fail_msg("frame_stats.volumes = %d and %d, want 1 and 0: volumes of a negative-only ramp group are "
                 "counted although that group is skipped (fogvol_end_frame counts st.volumes before the "
                 "'if (!has_pos) continue;')",
                 volumes1, volumes2);
}

/* ---- the order of calls in a frame ---- */
typedef struct occ_cb {
    rec *r;
    int calls, pass_count_at_call, in_pass_at_call;
    fogvol_handle program_at_call;
    fogvol_result transform_result, nan_result;
    int nset_after;
    float model[16];
} occ_cb;

static void occluder_callback(fogvol_context *ctx, void *user)
{
    occ_cb *c = (occ_cb *)user;
    float bad[16];
    c->calls++;
    c->pass_count_at_call = c->r->nb.pass_count;
    c->in_pass_at_call = c->r->nb.in_pass;
    c->program_at_call = c->r->nb.passes[0].program;
    c->transform_result = fogvol_occluder_transform(ctx, c->model);
    c->nset_after = c->r->nset;
    memcpy(bad, c->model, sizeof bad);
    bad[5] = NAN;
    c->nan_result = fogvol_occluder_transform(ctx, bad);
}

static void test_frame_call_order(void **state)
{
    rec r;
    logcap lc;
    fogvol_context *fv;
    shp_mesh box = box_mesh();
    fogvol_mesh *m[2];
    fogvol_ramp *fog, *light;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_volume_desc vd;
    float id[16];
    occ_cb cb;
    int i;
    (void)state;
    log_reset(&lc);
    rec_init(&r);
    fv = rec_context(&r, &lc, NULL);
    for (i = 0; i < 2; ++i) assert_int_equal(make_mesh(fv, &box, 0, 0, &m[i]), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &fog), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_LIGHT, &light), FOGVOL_SUCCESS);
    a_frame_desc(&fd);
    mat_identity(id);
    memset(&vd, 0, sizeof vd);
    mat_identity(vd.model);
    vd.mesh = m[0];
    vd.ramp = fog;

    /* outside a frame */
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_add_occluder(fv, m[1], id), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_add_occluder_callback(fv, occluder_callback, &cb), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_occluder_transform(fv, id), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(st.passes, 0);
    assert_int_equal(r.nb.frames_begun, 0); /* nothing reached the backend */
    assert_int_equal(r.nb.pass_count, 0);

    /* begin_frame twice: the first frame (a fog volume) is discarded, with a warning */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, m[1], id), FOGVOL_SUCCESS);
    log_reset(&lc);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(lc.warnings, 1);
    assert_int_equal(r.nb.frames_begun, 0);
    vd.mesh = m[1];
    vd.ramp = light;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    /* only the second frame's light volume: O (no occluder), B, F, composite (LIGHT) */
    assert_int_equal(st.passes, 4);
    assert_int_equal(st.groups, 1);
    assert_int_equal(st.volumes, 1);
    assert_int_equal(st.occluders, 0);
    assert_int_equal(r.nb.draws[0], 0);
    assert_int_equal(r.nb.passes[3].blend, FOGVOL_PASS_BLEND_LIGHT);
    assert_int_equal(r.ndraws, 2);
    assert_int_equal(r.draws[0].mesh, r.draws[1].mesh);
    assert_int_equal(r.nb.frames_begun, 1);
    assert_int_equal(r.nb.frames_ended, 1);
    /* the frame is closed now */
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_ERROR_INVALID_STATE);

    /* cancel_frame: nothing rendered, the frame is closed */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_ERROR_INVALID_STATE);
    assert_int_equal(r.nb.frames_begun, 1);
    assert_int_equal(fogvol_cancel_frame(NULL), FOGVOL_ERROR_INVALID_ARGUMENT);

    /* occluder transform: INVALID_STATE inside a frame but outside the O pass */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_occluder_transform(fv, id), FOGVOL_ERROR_INVALID_STATE);
    memset(&cb, 0, sizeof cb);
    cb.r = &r;
    mat_ts(cb.model, 1, 0, 0, 1, 1, 1); /* w = 5 - (px + 1) */
    assert_int_equal(fogvol_add_occluder_callback(fv, occluder_callback, &cb), FOGVOL_SUCCESS);
    assert_int_equal(cb.calls, 0); /* nothing runs before end_frame */
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(cb.calls, 1);
    assert_int_equal(cb.pass_count_at_call, 1); /* inside pass 0 ... */
    assert_int_equal(cb.in_pass_at_call, 1);
    /* (drawn as COUNT: FOGVOL_SPEEDUP_DEPTH_TEST, the box between the planes) */
    assert_int_equal(cb.program_at_call, rec_program(&r, KIND(FOGVOL_PROGRAM_ENCODE, FOGVOL_SPECIALIZE_DITHER | ENC4 |
                                                                                       FOGVOL_SPECIALIZE_COUNT)));
    assert_int_equal(cb.transform_result, FOGVOL_SUCCESS);
    assert_int_equal(cb.nan_result, FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(cb.nset_after, 1); /* the transform reached the backend as set_draw */
    assert_int_equal(r.set_draw_pass[0], 0);
    {
        static const double p0[3] = {0, 0, 0}, p1[3] = {-2, 1, 1};
        check_depth_row(&r.set_draws[0], p0, 4.0, "occluder_transform");
        check_depth_row(&r.set_draws[0], p1, 6.0, "occluder_transform");
        assert_int_equal(r.set_draws[0].front_cw, 0);
    }
    assert_int_equal(st.occluders, 1);
    assert_int_equal(r.nb.draws[0], 0); /* the callback draws, fogvol does not */
    assert_int_equal(fogvol_occluder_transform(fv, id), FOGVOL_ERROR_INVALID_STATE); /* after the frame */

    for (i = 0; i < 2; ++i) fogvol_destroy_mesh(fv, m[i]);
    fogvol_destroy_ramp(fv, fog);
    fogvol_destroy_ramp(fv, light);
    fogvol_destroy_context(fv);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    assert_int_equal(r.nb.frames_begun, r.nb.frames_ended);
    assert_int_equal(r.protocol_errors, 0);
    shp_free(&box);
}

/* ---- bad input ---- */
#define EXPECT_LOGGED(call, code)                                                                        \
    do {                                                                                                             \
        fogvol_result res_;                                                                                          \
        log_reset(&lc);                                                                                              \
        res_ = (call);                                                                                               \
        if (res_ != (code)) fail_msg("%s returned %d (%s), want %d", #call, (int)res_, fogvol_result_string(res_), (int)(code)); \
        if (!log_error_has(&lc, NULL)) fail_msg("%s: no error message was logged", #call);                           \
    } while (0)

/* A mesh or ramp destroyed inside a frame drops only what uses it: the rest of
   the frame renders (a streamed-out asset must not kill the fog). */
static void test_destroy_inside_frame_drops_its_users(void **state)
{
    rec r;
    logcap lc;
    fogvol_context *fv;
    shp_mesh box = box_mesh();
    fogvol_mesh *m[3];
    fogvol_ramp *fog, *light;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_volume_desc vd;
    float id[16];
    int i;
    (void)state;
    log_reset(&lc);
    rec_init(&r);
    fv = rec_context(&r, &lc, NULL);
    for (i = 0; i < 3; ++i) assert_int_equal(make_mesh(fv, &box, 0, 0, &m[i]), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &fog), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_LIGHT, &light), FOGVOL_SUCCESS);
    a_frame_desc(&fd);
    mat_identity(id);
    memset(&vd, 0, sizeof vd);
    mat_identity(vd.model);

    /* a mesh the frame does not use: nothing dropped, nothing logged */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    vd.mesh = m[0];
    vd.ramp = fog;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    log_reset(&lc);
    fogvol_destroy_mesh(fv, m[2]);
    assert_int_equal(lc.count, 0);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.volumes, 1);
    assert_int_equal(st.groups, 1);

    /* a mesh used by one volume and one occluder: those two go, with a warning; the other volume renders */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_occluder(fv, m[1], id), FOGVOL_SUCCESS);
    vd.mesh = m[0];
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    vd.mesh = m[1];
    vd.ramp = light;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    log_reset(&lc);
    fogvol_destroy_mesh(fv, m[1]);
    assert_int_equal(lc.warnings, 1);
    assert_non_null(strstr(lc.msg[0], "1 volumes and 1 occluders"));
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.volumes, 1);
    assert_int_equal(st.occluders, 0);
    assert_int_equal(st.groups, 1);
    assert_int_equal(r.nb.passes[r.nb.pass_count - 1].blend, FOGVOL_PASS_BLEND_FOG); /* the fog group stayed */

    /* a ramp: its group goes, the other group renders */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    vd.mesh = m[0];
    vd.ramp = light;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    vd.ramp = fog;
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    log_reset(&lc);
    fogvol_destroy_ramp(fv, light);
    assert_int_equal(lc.warnings, 1);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.groups, 1);
    assert_int_equal(st.volumes, 1);
    assert_int_equal(r.nb.passes[r.nb.pass_count - 1].blend, FOGVOL_PASS_BLEND_FOG);
    fogvol_destroy_mesh(fv, m[0]);
    fogvol_destroy_ramp(fv, fog);
    fogvol_destroy_context(fv);
    shp_free(&box);
    assert_int_equal(r.nb.creates, r.nb.destroys);
}

/* Encoding settings that cannot sum correctly are refused; WIDE's default is its exact setting. */
static void test_encoding_refuses_inexact_sums(void **state)
{
    rec r;
    logcap lc;
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    (void)state;
    rec_init(&r);
    r.table.caps |= FOGVOL_CAP_MRT; /* WIDE draws two targets */
    memset(&cd, 0, sizeof cd);
    cd.backend = r.table;
    cd.tier = FOGVOL_TIER_PS20;
    cd.logger = cap_logger(&lc);
    /* SINGLE_TARGET, L = 8: 2^(7-8) faces, none; L = 7 sums one face */
    cd.variants = FOGVOL_VARIANT_SINGLE_TARGET;
    cd.encoding_bits = 8;
    log_reset(&lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_null(fv);
    assert_true(log_error_has(&lc, "SINGLE_TARGET"));
    cd.encoding_bits = 7;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_encoding(fv)->max_faces_single, 1);
    fogvol_destroy_context(fv);
    /* WIDE: 0 = L 3 (18 exact bits); L 4 (24 bits, beyond fp32) refused; L 2 kept */
    cd.variants = FOGVOL_VARIANT_WIDE;
    cd.encoding_bits = 0;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_encoding(fv)->bits, 3);
    fogvol_destroy_context(fv);
    cd.encoding_bits = 4;
    log_reset(&lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_null(fv);
    assert_true(log_error_has(&lc, "WIDE"));
    cd.encoding_bits = 2;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_encoding(fv)->bits, 2);
    fogvol_destroy_context(fv);
    /* without WIDE the default stays 4 */
    cd.variants = 0;
    cd.encoding_bits = 0;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_encoding(fv)->bits, FOGVOL_DEFAULT_BITS);
    fogvol_destroy_context(fv);
    assert_int_equal(r.nb.creates, r.nb.destroys);
}

/* FOGVOL_TIER_AUTO takes the best tier that runs the required variants (fogvol_context_desc.variants)
   and adds the preferred ones (preferred_variants) where that tier, the dialect and the backend take
   them; a required variant no tier runs is refused with a log that names preferred_variants. The
   expected tiers are the white paper's order (float blending, MRT, ps.2.0, ps.1.3) by hand. */
static int log_has(const logcap *c, fogvol_log_level level, const char *needle)
{
    int i;
    for (i = 0; i < c->count && i < LOG_MAX; ++i)
        if (c->level[i] == level && strstr(c->msg[i], needle)) return 1;
    return 0;
}

static void tier_choice(rec *r, fogvol_dialect dialect, unsigned caps, unsigned required, unsigned preferred,
                        fogvol_result want, fogvol_tier tier, unsigned want_on, unsigned want_off, logcap *lc)
{
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    unsigned v = 0;
    rec_init(r);
    r->table.dialect = dialect;
    r->table.caps = caps;
    memset(&cd, 0, sizeof cd);
    cd.backend = r->table;
    cd.logger = cap_logger(lc);
    cd.variants = required;
    cd.preferred_variants = preferred;
    log_reset(lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), want);
    if (want != FOGVOL_SUCCESS) {
        assert_null(fv);
        assert_true(log_error_has(lc, "preferred_variants"));
        return;
    }
    assert_int_equal(fogvol_context_tier(fv, &v), tier);
    assert_int_equal(v & want_on, want_on);
    assert_int_equal(v & want_off, 0);
    fogvol_destroy_context(fv);
    assert_int_equal(r->nb.creates, r->nb.destroys);
}

static void test_tier_choice_required_and_preferred(void **state)
{
    const unsigned ed = FOGVOL_VARIANT_ENGINE_DEPTH, st = FOGVOL_VARIANT_SINGLE_TARGET;
    const unsigned hp = FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_DEPTH_TEXTURE, fl = hp | FOGVOL_CAP_FLOAT_BLEND;
    rec r;
    logcap lc;
    (void)state;
    /* GL 2.1 (GLSL 120): no tier reads the engine's depth (it needs texelFetch) */
    tier_choice(&r, FOGVOL_GLSL_120, hp, ed, 0, FOGVOL_ERROR_UNSUPPORTED, FOGVOL_TIER_AUTO, 0, 0, &lc);
    tier_choice(&r, FOGVOL_GLSL_120, hp, 0, ed, FOGVOL_SUCCESS, FOGVOL_TIER_PS20, 0, ed, &lc);
    assert_true(log_has(&lc, FOGVOL_LOG_INFO, "preferred variant 0x10 left out"));
    assert_int_equal(lc.errors + lc.warnings, 0);
    /* GLSL 330 without float blending: PS20 takes it; with float blending FLOAT does */
    tier_choice(&r, FOGVOL_GLSL_330, hp, 0, ed, FOGVOL_SUCCESS, FOGVOL_TIER_PS20, ed, 0, &lc);
    tier_choice(&r, FOGVOL_GLSL_330, fl, 0, ed, FOGVOL_SUCCESS, FOGVOL_TIER_FLOAT, ed, 0, &lc);
    tier_choice(&r, FOGVOL_GLSL_330, fl, ed, 0, FOGVOL_SUCCESS, FOGVOL_TIER_FLOAT, ed, 0, &lc);
    /* FLOAT has no single target: required, the next tier that has one (PS20); preferred, FLOAT without it */
    tier_choice(&r, FOGVOL_GLSL_330, fl, st, 0, FOGVOL_SUCCESS, FOGVOL_TIER_PS20, st, 0, &lc);
    tier_choice(&r, FOGVOL_GLSL_330, fl, 0, st, FOGVOL_SUCCESS, FOGVOL_TIER_FLOAT, 0, st, &lc);
    /* without highp fragment shaders AUTO ends at PS13, which has no engine depth */
    tier_choice(&r, FOGVOL_GLSL_100, FOGVOL_CAP_DEPTH_TEXTURE, 0, ed, FOGVOL_SUCCESS, FOGVOL_TIER_PS13, 0, ed, &lc);
    tier_choice(&r, FOGVOL_GLSL_100, FOGVOL_CAP_DEPTH_TEXTURE, ed, 0, FOGVOL_ERROR_UNSUPPORTED, FOGVOL_TIER_AUTO, 0,
                0, &lc);
}

static void test_bad_input_code_and_log(void **state)
{
    rec r;
    logcap lc;
    counting cnt;
    fogvol_context_desc cd;
    fogvol_context *fv = (fogvol_context *)&cd, *good;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_mesh_desc md;
    fogvol_mesh *mesh = NULL, *open_mesh, *closed;
    fogvol_ramp *ramp;
    fogvol_ramp_desc rd;
    shp_mesh box = box_mesh(), plane = shp_grid_plane(1, 1, 2), bad;
    float id[16];
    int creates0;
    (void)state;
    log_reset(&lc);
    rec_init(&r);
    memset(&cnt, 0, sizeof cnt);
    mat_identity(id);

    /* ---- context creation ---- */
    memset(&cd, 0, sizeof cd);
    cd.backend = r.table;
    cd.tier = FOGVOL_TIER_PS20;
    cd.logger = cap_logger(&lc);
    assert_int_equal(fogvol_create_context(NULL, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv);
    assert_int_equal(fogvol_create_context(&cd, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.encoding_bits = 9;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv);
    cd.encoding_bits = -1;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.encoding_bits = 0;
    cd.allocator.alloc = cnt_alloc; /* alloc without free */
    cd.allocator.user_data = &cnt;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(fv);
    assert_int_equal(cnt.calls, 0);
    cd.allocator.alloc = NULL; /* free without alloc */
    cd.allocator.free = cnt_free;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    memset(&cd.allocator, 0, sizeof cd.allocator);
    /* every required backend entry, left out in turn (the optional ones are marked in the header:
       begin_frame, end_frame, end_pass, destroy) */
    {
        fogvol_backend t;
        size_t offs[] = {offsetof(fogvol_backend, destroy_texture), offsetof(fogvol_backend, create_target),
                         offsetof(fogvol_backend, destroy_target),  offsetof(fogvol_backend, create_program),
                         offsetof(fogvol_backend, destroy_program), offsetof(fogvol_backend, create_mesh),
                         offsetof(fogvol_backend, destroy_mesh),    offsetof(fogvol_backend, begin_pass),
                         offsetof(fogvol_backend, set_draw),        offsetof(fogvol_backend, draw_mesh),
                         offsetof(fogvol_backend, draw_fullscreen)};
        size_t i;
        for (i = 0; i < sizeof offs / sizeof offs[0]; ++i) {
            t = r.table;
            memset((char *)&t + offs[i], 0, sizeof(void (*)(void)));
            cd.backend = t;
            EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
            assert_null(fv);
        }
        /* no create_texture: the table counts as empty and the GL backend is asked for,
           which needs a loader */
        t = r.table;
        t.create_texture = NULL;
        cd.backend = t;
        EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
        assert_int_equal(r.nb.create_calls, 0); /* nothing was created on a rejected table */
        /* the optional entries may be NULL */
        t = r.table;
        t.begin_frame = NULL;
        t.end_frame = NULL;
        t.end_pass = NULL;
        t.destroy = NULL;
        cd.backend = t;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        fogvol_destroy_context(fv);
        assert_int_equal(r.nb.creates, r.nb.destroys);
    }
    cd.backend = r.table;
    cd.tier = (fogvol_tier)7; /* no such tier */
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.tier = (fogvol_tier)-1;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.tier = FOGVOL_TIER_PS20;
    cd.variants = 1u << 7; /* no such variant */
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    cd.variants = 0;
    /* tiers that exist but that a backend without the caps cannot run */
    cd.backend.caps = 0;
    cd.tier = FOGVOL_TIER_FLOAT;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_null(fv);
    cd.tier = FOGVOL_TIER_MRT;
    EXPECT_LOGGED(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    cd.backend = r.table;
    cd.tier = FOGVOL_TIER_PS20;
    assert_int_equal(fogvol_create_context(&cd, &good), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_context_encoding(good)->bits, FOGVOL_DEFAULT_BITS);

    /* ---- meshes ---- */
    creates0 = r.nb.creates;
    memset(&md, 0, sizeof md);
    md.positions = box.pos;
    md.vertex_count = box.vcount;
    md.indices = (const uint32_t *)box.idx;
    md.index_count = box.icount;
    assert_int_equal(fogvol_create_mesh(good, NULL, &mesh, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(mesh);
    assert_int_equal(fogvol_create_mesh(good, &md, NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_create_mesh(NULL, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* open: the last triangle left out */
    md.index_count = box.icount - 3;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    assert_null(mesh);
    md.index_count = box.icount;
    /* flipped: one triangle reversed */
    bad = box_mesh();
    {
        unsigned t = bad.idx[1];
        bad.idx[1] = bad.idx[2];
        bad.idx[2] = t;
    }
    md.indices = (const uint32_t *)bad.idx;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    /* inside out: every triangle reversed */
    shp_flip(&bad);
    {
        unsigned t = bad.idx[1]; /* undo the single flip: now all are reversed */
        bad.idx[1] = bad.idx[2];
        bad.idx[2] = t;
    }
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    shp_free(&bad);
    /* NaN vertex: rejected even for occluders */
    bad = box_mesh();
    bad.pos[4] = NAN;
    md.indices = (const uint32_t *)bad.idx;
    md.positions = bad.pos;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    md.allow_open = 1;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    md.allow_open = 0;
    shp_free(&bad);
    /* index out of range: rejected even for occluders */
    bad = box_mesh();
    bad.idx[7] = (unsigned)bad.vcount;
    md.indices = (const uint32_t *)bad.idx;
    md.positions = bad.pos;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    md.allow_open = 1;
    EXPECT_LOGGED(fogvol_create_mesh(good, &md, &mesh, NULL), FOGVOL_ERROR_INVALID_MESH);
    assert_null(mesh);
    shp_free(&bad);
    assert_int_equal(r.nb.creates, creates0); /* nothing uploaded */
    /* the good ones */
    assert_int_equal(make_mesh(good, &plane, 1, 0, &open_mesh), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(good, &box, 0, 0, &closed), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    assert_int_equal(fogvol_create_ramp(good, NULL, &ramp), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_create_ramp(good, &rd, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    rd.density = -1.0f; /* extinction needs density > 0 */
    EXPECT_LOGGED(fogvol_create_ramp(good, &rd, &ramp), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_null(ramp);
    assert_int_equal(make_ramp(good, FOGVOL_BLEND_FOG, &ramp), FOGVOL_SUCCESS);

    /* ---- frame description ---- */
    assert_int_equal(fogvol_begin_frame(good, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_begin_frame(NULL, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.viewport[2] = fd.viewport[3] = 0;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.viewport[2] = 16385;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.viewport[3] = 16385;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.viewport[2] = -4;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.viewport[2] = 16384; /* the largest accepted */
    fd.viewport[3] = 1;
    assert_int_equal(fogvol_begin_frame(good, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(good), FOGVOL_SUCCESS);
    a_frame_desc(&fd);
    fd.znear = 0.0f;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.znear = -1.0f;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.znear = fd.zfar;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.znear = fd.zfar + 1.0f;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.znear = NAN;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.zfar = INFINITY;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.view[6] = NAN;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.projection[11] = NAN;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    a_frame_desc(&fd);
    fd.projection[0] = -INFINITY;
    EXPECT_LOGGED(fogvol_begin_frame(good, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);

    /* ---- adds ---- */
    a_frame_desc(&fd);
    assert_int_equal(fogvol_begin_frame(good, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    mat_identity(vd.model);
    vd.mesh = closed;
    vd.ramp = ramp;
    assert_int_equal(fogvol_add_volume(good, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    vd.mesh = NULL;
    assert_int_equal(fogvol_add_volume(good, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    vd.mesh = closed;
    vd.ramp = NULL;
    assert_int_equal(fogvol_add_volume(good, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    vd.ramp = ramp;
    vd.mesh = open_mesh; /* accepted as an occluder, never as a volume */
    EXPECT_LOGGED(fogvol_add_volume(good, &vd), FOGVOL_ERROR_INVALID_MESH);
    vd.mesh = closed;
    vd.model[13] = NAN;
    EXPECT_LOGGED(fogvol_add_volume(good, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    id[2] = INFINITY;
    EXPECT_LOGGED(fogvol_add_occluder(good, open_mesh, id), FOGVOL_ERROR_INVALID_ARGUMENT);
    mat_identity(id);
    assert_int_equal(fogvol_add_occluder(good, NULL, id), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_add_occluder(good, open_mesh, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_int_equal(fogvol_add_occluder_callback(good, NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* none of the rejected adds is in the frame: only the valid occluder below is drawn */
    assert_int_equal(fogvol_add_occluder(good, open_mesh, id), FOGVOL_SUCCESS);
    {
        fogvol_frame_stats st;
        assert_int_equal(fogvol_end_frame(good, &st), FOGVOL_SUCCESS);
        assert_int_equal(st.passes, 1);
        assert_int_equal(st.volumes, 0);
        assert_int_equal(st.occluders, 1);
    }
    assert_int_equal(fogvol_end_frame(NULL, NULL), FOGVOL_ERROR_INVALID_ARGUMENT);

    fogvol_destroy_mesh(good, open_mesh);
    fogvol_destroy_mesh(good, closed);
    fogvol_destroy_ramp(good, ramp);
    fogvol_destroy_mesh(good, NULL); /* no-ops */
    fogvol_destroy_ramp(good, NULL);
    fogvol_destroy_context(good);
    fogvol_destroy_context(NULL);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    assert_int_equal(r.protocol_errors, 0);
    shp_free(&box);
    shp_free(&plane);
}

static void transposed(float out[16], const float m[16])
{
    int c, k;
    for (c = 0; c < 4; ++c)
        for (k = 0; k < 4; ++k) out[c * 4 + k] = m[k * 4 + c];
}

/* Issue 31 3e and 3f: row-major engine matrices copied as they are (raylib's Matrix, DirectXMath)
   and degenerate model matrices were accepted and drew nothing (or the wrong thing). What can be
   told is refused with INVALID_ARGUMENT and a log that says "transposed?": a view or model matrix
   whose bottom row is not (0, 0, 0, 1) (its translation went there), a projection whose w row is
   in the wrong place (the -1 that makes clip w from view depth at m[14], not m[11]), a
   view-projection whose transpose is the camera that was meant. A volume or light model matrix
   that is singular (all zero, a zero scale) has no volume: refused; an occluder flattened to a
   plane still hides, an all-zero one does not. */
static void test_transposed_and_singular_matrices(void **state)
{
    rec r;
    logcap lc;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_frame_desc fd, t;
    fogvol_volume_desc vd;
    fogvol_light_desc ld;
    fogvol_mesh *closed, *open_mesh;
    fogvol_ramp *ramp;
    fogvol_frame_stats st;
    shp_mesh box = box_mesh(), plane = shp_grid_plane(1, 1, 2);
    float m[16], zero[16], tr[16];
    (void)state;
    log_reset(&lc);
    rec_init(&r);
    memset(&cd, 0, sizeof cd);
    cd.backend = r.table;
    cd.tier = FOGVOL_TIER_PS20;
    cd.logger = cap_logger(&lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(fv, &box, 0, 0, &closed), FOGVOL_SUCCESS);
    assert_int_equal(make_mesh(fv, &plane, 1, 0, &open_mesh), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &ramp), FOGVOL_SUCCESS);
    memset(zero, 0, sizeof zero);

    /* ---- camera ---- */
    a_frame_desc(&fd);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    t = fd; /* the view transposed: its translation (0, 0, -5) in the bottom row */
    transposed(t.view, fd.view);
    EXPECT_LOGGED(fogvol_begin_frame(fv, &t), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));
    assert_true(log_error_has(&lc, "bottom row"));
    t = fd; /* the projection transposed */
    transposed(t.projection, fd.projection);
    EXPECT_LOGGED(fogvol_begin_frame(fv, &t), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));
    transposed(t.view, fd.view); /* both (a raylib Matrix copied with memcpy) */
    EXPECT_LOGGED(fogvol_begin_frame(fv, &t), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));
    t = fd; /* a view whose bottom row is (0, 0, 0, 2): view depth would be off by 2 */
    t.view[15] = 2.0f;
    EXPECT_LOGGED(fogvol_begin_frame(fv, &t), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "bottom row"));
    /* the view-projection camera: P V with the eye and forward of a_frame_desc's view (the camera at
       (5, 0, 0) looking down -x), then transposed */
    t = fd;
    t.camera = FOGVOL_CAMERA_VIEW_PROJECTION;
    shp_mat_mul(t.view_projection, fd.projection, fd.view);
    t.eye[0] = 5.0f;
    t.forward[0] = -1.0f;
    assert_int_equal(fogvol_begin_frame(fv, &t), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_cancel_frame(fv), FOGVOL_SUCCESS);
    memcpy(m, t.view_projection, sizeof m);
    transposed(t.view_projection, m);
    EXPECT_LOGGED(fogvol_begin_frame(fv, &t), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));

    /* ---- model matrices ---- */
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    memset(&vd, 0, sizeof vd);
    vd.mesh = closed;
    vd.ramp = ramp;
    memcpy(vd.model, zero, sizeof zero);
    EXPECT_LOGGED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "all zero"));
    mat_ts(m, 0.5f, 0.25f, -0.5f, 1.0f, 1.0f, 1.0f); /* a translation, transposed */
    transposed(vd.model, m);
    EXPECT_LOGGED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));
    mat_ts(vd.model, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.0f); /* y scaled to 0: flat, no volume */
    EXPECT_LOGGED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "singular"));
    mat_ts(vd.model, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f); /* y along x: rank 2 */
    vd.model[4] = 1.0f;
    vd.model[5] = 0.0f;
    EXPECT_LOGGED(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* occluders: all zero and transposed refused, flattened to a plane accepted */
    EXPECT_LOGGED(fogvol_add_occluder(fv, closed, zero), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "all zero"));
    mat_ts(m, 0.5f, 0.25f, -0.5f, 1.0f, 1.0f, 1.0f);
    transposed(tr, m);
    EXPECT_LOGGED(fogvol_add_occluder(fv, closed, tr), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, "transposed?"));
    mat_ts(m, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.0f);
    assert_int_equal(fogvol_add_occluder(fv, closed, m), FOGVOL_SUCCESS);
    /* lights: a singular model refused */
    memset(&ld, 0, sizeof ld);
    ld.mesh = closed;
    ld.color[0] = 1.0f;
    memcpy(ld.model, zero, sizeof zero);
    EXPECT_LOGGED(fogvol_add_light(fv, &ld), FOGVOL_ERROR_INVALID_ARGUMENT);
    mat_ts(ld.model, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f);
    EXPECT_LOGGED(fogvol_add_light(fv, &ld), FOGVOL_ERROR_INVALID_ARGUMENT);
    /* what is fine: a small uniform scale, a mirror, a translation */
    mat_ts(vd.model, 0.5f, 0.25f, -0.5f, 1e-3f, 1e-3f, 1e-3f);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    mat_ts(vd.model, 0.0f, 0.0f, 0.0f, -1.0f, 1.0f, 1.0f);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    assert_int_equal(st.volumes, 2);
    assert_int_equal(st.occluders, 1);
    assert_int_equal(st.lights, 0);
    fogvol_destroy_mesh(fv, closed);
    fogvol_destroy_mesh(fv, open_mesh);
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_context(fv);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    shp_free(&box);
    shp_free(&plane);
}

/* a warning-level message containing needle */
static int log_warning_has(const logcap *c, const char *needle)
{
    int i;
    for (i = 0; i < c->count && i < LOG_MAX; ++i)
        if (c->level[i] == FOGVOL_LOG_WARNING && strstr(c->msg[i], needle)) return 1;
    return 0;
}

/* Issue 31 3h: RGBA8 digits over near 1e-4 / far 1e5 quantise the thickness in steps of
   1e5 / 2^12 = 24.4 units, ten times a 2-unit box (PS20 + COUNT drew fog in 30 of its 484
   pixels), and nothing said so. Now: fogvol_frame_stats.depth_lsb is the step (hand-computed:
   (far - near) / 2^(3L)) and a warning is logged when it is coarser than 1/16 of the depth extent
   of the frame's smallest volume, once until a frame is fine again. */
static void test_coarse_depth_lsb_warned(void **state)
{
    rec r;
    logcap lc;
    fogvol_context_desc cd;
    fogvol_context *fv;
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    fogvol_mesh *box;
    fogvol_ramp *ramp;
    fogvol_frame_stats st;
    shp_mesh b = shp_box(1.0f, 1.0f, 1.0f); /* 2 units across */
    int frame, tier;
    (void)state;
    for (tier = 0; tier < 2; ++tier) {
        log_reset(&lc);
        rec_init(&r);
        memset(&cd, 0, sizeof cd);
        cd.backend = r.table;
        if (tier) cd.backend.caps |= FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_FLOAT_TARGET;
        cd.tier = tier ? FOGVOL_TIER_FLOAT : FOGVOL_TIER_PS20;
        cd.variants = tier ? 0u : (unsigned)FOGVOL_VARIANT_COUNT;
        cd.logger = cap_logger(&lc);
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        assert_int_equal(make_mesh(fv, &b, 0, 0, &box), FOGVOL_SUCCESS);
        assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &ramp), FOGVOL_SUCCESS);
        for (frame = 0; frame < 4; ++frame) {
            int coarse = frame != 2; /* frame 2: near 0.5, far 10.5: a step of 10 / 4096 */
            a_frame_desc(&fd);
            if (coarse) {
                glu_perspective(fd.projection, 60.0, (double)A_W / A_H, 1e-4, 1e5);
                fd.znear = 1e-4f;
                fd.zfar = 1e5f;
            }
            assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
            memset(&vd, 0, sizeof vd);
            vd.mesh = box;
            vd.ramp = ramp;
            mat_identity(vd.model); /* 5 units in front of the camera */
            assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
            lc.count = lc.warnings = 0;
            assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
            if (tier) { /* float sums: no step, no warning */
                assert_true(st.depth_lsb == 0.0f);
                assert_false(log_warning_has(&lc, "LSB"));
                continue;
            }
            assert_close(st.depth_lsb, ((double)fd.zfar - fd.znear) / 4096.0, 1e-6, "depth_lsb");
            /* warned on frames 0 and 3 (the first coarse frame, and again after a fine one) */
            if (frame == 0 || frame == 3) assert_true(log_warning_has(&lc, "LSB"));
            else assert_false(log_warning_has(&lc, "LSB"));
        }
        fogvol_destroy_mesh(fv, box);
        fogvol_destroy_ramp(fv, ramp);
        fogvol_destroy_context(fv);
    }
    shp_free(&b);
}

/* ---- fault injection ---- */

/* n-th backend create call failing during context creation: PS20 encodes by arithmetic by default
   (FOGVOL_SPEEDUP_ALU): 1 lookup texture (dither index) and 3 programs (encode, face, composite) = 4
   creates, so n = 1..4 fail and n = 5 succeeds. */
static void test_backend_create_faults(void **state)
{
    int n;
    (void)state;
    for (n = 1;; ++n) {
        rec r;
        logcap lc;
        counting cnt;
        fogvol_context_desc cd;
        fogvol_context *fv = (fogvol_context *)&cd;
        fogvol_result res;
        rec_init(&r);
        log_reset(&lc);
        memset(&cnt, 0, sizeof cnt);
        r.nb.fail_create_at = n;
        memset(&cd, 0, sizeof cd);
        cd.backend = r.table;
        cd.tier = FOGVOL_TIER_PS20;
        cd.logger = cap_logger(&lc);
        cd.allocator = cnt_allocator(&cnt);
        res = fogvol_create_context(&cd, &fv);
        if (res == FOGVOL_SUCCESS) {
            assert_int_equal(n, 5);
            assert_int_equal(r.nb.creates, 4);
            fogvol_destroy_context(fv);
            assert_int_equal(r.nb.creates, r.nb.destroys);
            assert_int_equal(cnt.live, 0);
            break;
        }
        assert_true(n <= 4);
        assert_int_equal(res, FOGVOL_ERROR_BACKEND);
        assert_null(fv);
        assert_true(log_error_has(&lc, NULL));
        assert_int_equal(r.nb.creates, n - 1);
        assert_int_equal(r.nb.creates, r.nb.destroys); /* everything created before the failure released */
        assert_int_equal(cnt.live, 0);
        assert_int_equal(r.protocol_errors, 0);
    }
}

/* k-th allocation failing in context creation, for every k until creation succeeds. */
static void test_alloc_faults_context(void **state)
{
    long k;
    (void)state;
    for (k = 1;; ++k) {
        rec r;
        logcap lc;
        counting cnt;
        fogvol_context_desc cd;
        fogvol_context *fv = (fogvol_context *)&cd;
        fogvol_result res;
        rec_init(&r);
        log_reset(&lc);
        memset(&cnt, 0, sizeof cnt);
        cnt.fail_at = k;
        memset(&cd, 0, sizeof cd);
        cd.backend = r.table;
        cd.tier = FOGVOL_TIER_PS20;
        cd.logger = cap_logger(&lc);
        cd.allocator = cnt_allocator(&cnt);
        res = fogvol_create_context(&cd, &fv);
        if (res == FOGVOL_SUCCESS) {
            print_message("  context creation: %ld failing allocation points, all clean\n", k - 1);
            assert_true(k >= 2); /* at least the context itself */
            assert_true(cnt.live >= 1);
            fogvol_destroy_context(fv);
            assert_int_equal(cnt.live, 0);
            assert_int_equal(r.nb.creates, r.nb.destroys);
            break;
        }
        assert_true(k < 64);
        assert_int_equal(res, FOGVOL_ERROR_OUT_OF_MEMORY);
        assert_null(fv);
        assert_true(log_error_has(&lc, NULL));
        assert_int_equal(cnt.live, 0);
        assert_int_equal(r.nb.creates, r.nb.destroys);
    }
}

/* k-th allocation failing in mesh creation (validation scratch, the mesh, and the
   repacked positions when stride != 12) and in ramp creation (pixels, the ramp). */
static void test_alloc_faults_mesh_ramp(void **state)
{
    rec r;
    logcap lc;
    counting cnt;
    fogvol_context *fv;
    shp_mesh box = box_mesh();
    int stride, fails;
    long k, base;
    (void)state;
    rec_init(&r);
    log_reset(&lc);
    memset(&cnt, 0, sizeof cnt);
    fv = rec_context(&r, &lc, &cnt);
    base = cnt.live;
    for (stride = 3; stride <= 4; ++stride) {
        fails = 0;
        for (k = 1;; ++k) {
            fogvol_mesh *m = (fogvol_mesh *)&cnt;
            int creates = r.nb.creates;
            fogvol_result res;
            cnt.fail_at = cnt.calls + k;
            log_reset(&lc);
            res = make_mesh(fv, &box, 0, stride, &m);
            cnt.fail_at = 0;
            if (res == FOGVOL_SUCCESS) {
                assert_non_null(m);
                assert_int_equal(r.nb.creates, creates + 1);
                fogvol_destroy_mesh(fv, m);
                assert_int_equal(cnt.live, base);
                break;
            }
            fails++;
            assert_true(k < 64);
            assert_int_equal(res, FOGVOL_ERROR_OUT_OF_MEMORY);
            assert_null(m);
            assert_int_equal(cnt.live, base);
            assert_int_equal(r.nb.creates, creates);
        }
        print_message("  mesh (stride %d floats): %d failing allocation points, all clean\n", stride, fails);
        assert_true(fails >= 1);
    }
    fails = 0;
    for (k = 1;; ++k) {
        fogvol_ramp *rp = (fogvol_ramp *)&cnt;
        int creates = r.nb.creates;
        fogvol_result res;
        cnt.fail_at = cnt.calls + k;
        res = make_ramp(fv, FOGVOL_BLEND_FOG, &rp);
        cnt.fail_at = 0;
        if (res == FOGVOL_SUCCESS) {
            fogvol_destroy_ramp(fv, rp);
            assert_int_equal(cnt.live, base);
            break;
        }
        fails++;
        assert_true(k < 64);
        assert_int_equal(res, FOGVOL_ERROR_OUT_OF_MEMORY);
        assert_null(rp);
        assert_int_equal(cnt.live, base);
        assert_int_equal(r.nb.creates, creates);
    }
    print_message("  ramp: %d failing allocation points, all clean\n", fails);
    assert_true(fails >= 1);
    /* backend failures in mesh and ramp creation: the error comes back, nothing leaks */
    {
        fogvol_mesh *m = (fogvol_mesh *)&cnt;
        fogvol_ramp *rp = (fogvol_ramp *)&cnt;
        r.nb.fail_create_at = r.nb.create_calls + 1;
        assert_int_equal(make_mesh(fv, &box, 0, 4, &m), FOGVOL_ERROR_BACKEND);
        assert_null(m);
        assert_int_equal(cnt.live, base);
        r.nb.fail_create_at = r.nb.create_calls + 1;
        assert_int_equal(make_ramp(fv, FOGVOL_BLEND_LIGHT, &rp), FOGVOL_ERROR_BACKEND);
        assert_null(rp);
        assert_int_equal(cnt.live, base);
        r.nb.fail_create_at = 0;
    }
    /* the frame lists: an add that cannot grow its list fails alone, the frame goes on */
    {
        fogvol_mesh *m;
        fogvol_ramp *rp;
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        fogvol_volume_desc vd;
        float id[16];
        int i;
        assert_int_equal(make_mesh(fv, &box, 0, 0, &m), FOGVOL_SUCCESS);
        assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &rp), FOGVOL_SUCCESS);
        a_frame_desc(&fd);
        mat_identity(id);
        memset(&vd, 0, sizeof vd);
        mat_identity(vd.model);
        vd.mesh = m;
        vd.ramp = rp;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        cnt.fail_at = cnt.calls + 1;
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_OUT_OF_MEMORY);
        cnt.fail_at = cnt.calls + 1;
        assert_int_equal(fogvol_add_occluder(fv, m, id), FOGVOL_ERROR_OUT_OF_MEMORY);
        cnt.fail_at = 0;
        for (i = 0; i < 3; ++i) assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(st.volumes, 3);
        assert_int_equal(st.occluders, 0);
        assert_int_equal(st.passes, 4);
        fogvol_destroy_mesh(fv, m);
        fogvol_destroy_ramp(fv, rp);
    }
    fogvol_destroy_context(fv);
    assert_int_equal(cnt.live, 0);
    assert_int_equal(r.nb.creates, r.nb.destroys);
    assert_int_equal(r.protocol_errors, 0);
    shp_free(&box);
}

/* The first end_frame creates the three targets; each of them failing in turn. */
static void test_target_create_faults(void **state)
{
    int which;
    (void)state;
    for (which = 1; which <= 3; ++which) {
        rec r;
        logcap lc;
        counting cnt;
        fogvol_context *fv;
        shp_mesh box = box_mesh();
        fogvol_mesh *m;
        fogvol_ramp *rp;
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        fogvol_volume_desc vd;
        int live;
        rec_init(&r);
        log_reset(&lc);
        memset(&cnt, 0, sizeof cnt);
        fv = rec_context(&r, &lc, &cnt);
        assert_int_equal(make_mesh(fv, &box, 0, 0, &m), FOGVOL_SUCCESS);
        assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &rp), FOGVOL_SUCCESS);
        live = r.nb.creates - r.nb.destroys;
        a_frame_desc(&fd);
        memset(&vd, 0, sizeof vd);
        mat_identity(vd.model);
        vd.mesh = m;
        vd.ramp = rp;
        r.nb.fail_create_at = r.nb.create_calls + which;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        log_reset(&lc);
        st.passes = -1;
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_ERROR_BACKEND);
        assert_true(log_error_has(&lc, NULL));
        assert_int_equal(st.passes, 0);
        assert_int_equal(r.nb.pass_count, 0); /* nothing drawn */
        assert_int_equal(r.nb.frames_begun, 1);
        assert_int_equal(r.nb.frames_ended, 1); /* the engine state was handed back */
        assert_int_equal(r.nb.creates - r.nb.destroys, live); /* the targets made before the failure are gone */
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_ERROR_INVALID_STATE); /* the frame is closed */
        /* the fault removed: the next frame creates the targets and renders O, B, F, composite */
        r.nb.fail_create_at = 0;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(st.passes, 4);
        assert_int_equal(st.volumes, 1);
        assert_int_equal(r.nb.pass_count, 4);
        /* three targets, and the three programs built on first use for this configuration (the O
           pass's encode with the dither on, faces without occluders or density texture, exp()
           composite without colour texture) */
        assert_int_equal(r.nb.creates - r.nb.destroys, live + 6);
        live += 3;
        assert_int_equal(r.nb.frames_begun, 2);
        assert_int_equal(r.nb.frames_ended, 2);
        /* and a target failure on a resize is handled the same way */
        fd.viewport[2] = 32;
        r.nb.fail_create_at = r.nb.create_calls + which;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_ERROR_BACKEND);
        assert_int_equal(r.nb.frames_begun, r.nb.frames_ended);
        assert_int_equal(r.nb.creates - r.nb.destroys, live);
        r.nb.fail_create_at = 0;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(r.nb.passes[1].viewport[2], 32);
        fogvol_destroy_mesh(fv, m);
        fogvol_destroy_ramp(fv, rp);
        fogvol_destroy_context(fv);
        assert_int_equal(r.nb.creates, r.nb.destroys);
        assert_int_equal(cnt.live, 0);
        assert_int_equal(r.protocol_errors, 0);
        shp_free(&box);
    }
}

/* ==== the GL backend under OSMesa ======================================== */

#define G_W 64
#define G_H 64

/* ---- GL object accounting through the loader ---- */
enum { OBJ_TEX, OBJ_BUF, OBJ_FBO, OBJ_RBO, OBJ_VAO, OBJ_SHADER, OBJ_PROGRAM, OBJ_KINDS };
static const char *const g_obj_name[OBJ_KINDS] = {"textures", "buffers", "framebuffers", "renderbuffers",
                                                  "vertex arrays", "shaders", "programs"};
#define OBJ_MAX 1024

/* The GL objects fogvol makes, one line a kind: GEN(kind, Name) for glGen<Name> / glDelete<Name>,
   CREATE(kind, Name, parameters, arguments) for glCreate<Name> / glDelete<Name>. The loader hands fogvol
   a wrapper of each that records the names made and deleted and forwards the call. */
#define OBJ_CALLS(GEN, CREATE)                                                                                       \
    GEN(OBJ_TEX, Textures)                                                                                           \
    GEN(OBJ_BUF, Buffers)                                                                                            \
    GEN(OBJ_FBO, Framebuffers)                                                                                       \
    GEN(OBJ_RBO, Renderbuffers)                                                                                      \
    GEN(OBJ_VAO, VertexArrays)                                                                                       \
    CREATE(OBJ_SHADER, Shader, (GLenum type), (type))                                                                \
    CREATE(OBJ_PROGRAM, Program, (void), ())

typedef void (*gen_fn)(GLsizei, GLuint *);
typedef void (*del_fn)(GLsizei, const GLuint *);
typedef void (*delete_one_fn)(GLuint);
#define OBJ_NONE(...)
#define OBJ_CREATE_TYPEDEF(kind, Name, params, args) typedef GLuint(*create_##Name##_fn) params;
OBJ_CALLS(OBJ_NONE, OBJ_CREATE_TYPEDEF)
#define OBJ_GEN_FIELDS(kind, Name)                                                                                   \
    gen_fn gen_##Name;                                                                                               \
    del_fn delete_##Name;
#define OBJ_CREATE_FIELDS(kind, Name, params, args)                                                                  \
    create_##Name##_fn create_##Name;                                                                                \
    delete_one_fn delete_##Name;
static struct {
    OBJ_CALLS(OBJ_GEN_FIELDS, OBJ_CREATE_FIELDS)
    GLuint live[OBJ_KINDS][OBJ_MAX];
    int nlive[OBJ_KINDS];
    int bad_deletes;
} g_obj;

static void obj_add(int kind, GLuint id)
{
    if (!id) return;
    if (g_obj.nlive[kind] < OBJ_MAX) g_obj.live[kind][g_obj.nlive[kind]++] = id;
}
static void obj_del(int kind, GLuint id)
{
    int i;
    if (!id) return;
    for (i = 0; i < g_obj.nlive[kind]; ++i)
        if (g_obj.live[kind][i] == id) {
            g_obj.live[kind][i] = g_obj.live[kind][--g_obj.nlive[kind]];
            return;
        }
    g_obj.bad_deletes++; /* deleting a name fogvol did not create (or twice) */
}

#define OBJ_GEN_WRAP(kind, Name)                                                                                     \
    static void w_Gen##Name(GLsizei n, GLuint *ids)                                                                  \
    {                                                                                                                \
        GLsizei i;                                                                                                   \
        g_obj.gen_##Name(n, ids);                                                                                    \
        for (i = 0; i < n; ++i) obj_add(kind, ids[i]);                                                               \
    }                                                                                                                \
    static void w_Delete##Name(GLsizei n, const GLuint *ids)                                                         \
    {                                                                                                                \
        GLsizei i;                                                                                                   \
        for (i = 0; i < n; ++i) obj_del(kind, ids[i]);                                                               \
        g_obj.delete_##Name(n, ids);                                                                                 \
    }
#define OBJ_CREATE_WRAP(kind, Name, params, args)                                                                    \
    static GLuint w_Create##Name params                                                                              \
    {                                                                                                                \
        GLuint id = g_obj.create_##Name args;                                                                        \
        obj_add(kind, id);                                                                                           \
        return id;                                                                                                   \
    }                                                                                                                \
    static void w_Delete##Name(GLuint id)                                                                            \
    {                                                                                                                \
        obj_del(kind, id);                                                                                           \
        g_obj.delete_##Name(id);                                                                                     \
    }
OBJ_CALLS(OBJ_GEN_WRAP, OBJ_CREATE_WRAP)

/* the driver's functions behind the wrappers */
static void obj_init(void)
{
    memset(&g_obj, 0, sizeof g_obj);
#define OBJ_GEN_LOAD(kind, Name)                                                                                     \
    g_obj.gen_##Name = (gen_fn)glu_proc("glGen" #Name, NULL);                                                        \
    g_obj.delete_##Name = (del_fn)glu_proc("glDelete" #Name, NULL);                                                  \
    assert_non_null(g_obj.gen_##Name);                                                                               \
    assert_non_null(g_obj.delete_##Name);
#define OBJ_CREATE_LOAD(kind, Name, params, args)                                                                    \
    g_obj.create_##Name = (create_##Name##_fn)glu_proc("glCreate" #Name, NULL);                                      \
    g_obj.delete_##Name = (delete_one_fn)glu_proc("glDelete" #Name, NULL);                                           \
    assert_non_null(g_obj.create_##Name);                                                                            \
    assert_non_null(g_obj.delete_##Name);
    OBJ_CALLS(OBJ_GEN_LOAD, OBJ_CREATE_LOAD)
#undef OBJ_GEN_LOAD
#undef OBJ_CREATE_LOAD
}

static int obj_live_total(void)
{
    int k, n = 0;
    for (k = 0; k < OBJ_KINDS; ++k) n += g_obj.nlive[k];
    return n;
}

static void obj_expect_none(const char *where)
{
    int k;
    for (k = 0; k < OBJ_KINDS; ++k)
        if (g_obj.nlive[k]) fail_msg("%s: %d GL %s left alive", where, g_obj.nlive[k], g_obj_name[k]);
    if (g_obj.bad_deletes) fail_msg("%s: %d deletes of names never created", where, g_obj.bad_deletes);
}

/* ---- the loader handed to fogvol ---- */
typedef struct loader {
    const char *missing; /* this name resolves to NULL */
    int nothing;         /* every name resolves to NULL */
    int asked_for_missing;
} loader;

static fogvol_gl_proc test_loader(const char *name, void *user)
{
    loader *l = (loader *)user;
    static const struct {
        const char *name;
        fogvol_gl_proc fn;
    } wrapped[] = {
#define OBJ_GEN_ENTRY(kind, Name)                                                                                    \
    {"glGen" #Name, (fogvol_gl_proc)w_Gen##Name}, {"glDelete" #Name, (fogvol_gl_proc)w_Delete##Name},
#define OBJ_CREATE_ENTRY(kind, Name, params, args)                                                                   \
    {"glCreate" #Name, (fogvol_gl_proc)w_Create##Name}, {"glDelete" #Name, (fogvol_gl_proc)w_Delete##Name},
        OBJ_CALLS(OBJ_GEN_ENTRY, OBJ_CREATE_ENTRY)
#undef OBJ_GEN_ENTRY
#undef OBJ_CREATE_ENTRY
    };
    size_t i;
    if (l->nothing) return NULL;
    if (l->missing && strcmp(name, l->missing) == 0) {
        l->asked_for_missing++;
        return NULL;
    }
    for (i = 0; i < sizeof wrapped / sizeof wrapped[0]; ++i)
        if (strcmp(name, wrapped[i].name) == 0) return wrapped[i].fn;
    return glu_proc(name, NULL);
}

/* every required name, from the header's own lists */
#define NAME_OF(ret, name, params) "gl" #name,
static const char *const g_base_names[] = {FOGVOL__GL_BASE(NAME_OF)};
static const char *const g_fbo_names[] = {FOGVOL__GL_FBO(NAME_OF)};
static const char *const g_vao_names[] = {FOGVOL__GL_VAO(NAME_OF)};
static const char *const g_sampler_names[] = {FOGVOL__GL_SAMPLER(NAME_OF)};
static const char *const g_desktop_names[] = {FOGVOL__GL_DESKTOP(NAME_OF)};
#ifdef FOGVOL__GL_3 /* GL 3.0 / GLES 3.0 entry points (glGetStringi) */
static const char *const g_gl3_names[] = {FOGVOL__GL_3(NAME_OF)};
#else
static const char *const g_gl3_names[] = {NULL};
#define G_GL3_NONE 1
#endif
static const char *const g_es_names[] = {FOGVOL__GL_ES(NAME_OF)};
#undef NAME_OF
#define COUNT_OF(a) ((int)(sizeof(a) / sizeof((a)[0])))

typedef struct gfx {
    glu_ctx g;
    int core;
} gfx;

static int setup_core(void **state)
{
    gfx *f = (gfx *)calloc(1, sizeof *f);
    if (!f || !glu_create(&f->g, G_W, G_H, 1)) return -1;
    f->core = 1;
    obj_init();
    *state = f;
    return 0;
}

static int setup_compat(void **state)
{
    gfx *f = (gfx *)calloc(1, sizeof *f);
    if (!f || !glu_create(&f->g, G_W, G_H, 0)) return -1;
    obj_init();
    *state = f;
    return 0;
}

static int teardown_gl(void **state)
{
    gfx *f = (gfx *)*state;
    glu_destroy(&f->g);
    free(f);
    return 0;
}

static void gl_desc(fogvol_context_desc *cd, loader *l, logcap *lc, counting *cnt, int v_major, int v_minor)
{
    memset(cd, 0, sizeof *cd);
    cd->gl.get_proc_address = test_loader;
    cd->gl.user_data = l;
    cd->gl.version_major = v_major;
    cd->gl.version_minor = v_minor;
    cd->logger = cap_logger(lc);
    cd->allocator = cnt_allocator(cnt);
}

/* One missing name: MISSING_FUNCTION, the name in the log, nothing left behind. */
static void expect_missing(const char *name, int v_major, int v_minor)
{
    loader l;
    logcap lc;
    counting cnt;
    fogvol_context_desc cd;
    fogvol_context *fv = (fogvol_context *)&cd;
    fogvol_result res;
    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    l.missing = name;
    gl_desc(&cd, &l, &lc, &cnt, v_major, v_minor);
    res = fogvol_create_context(&cd, &fv);
    if (res != FOGVOL_ERROR_MISSING_FUNCTION) {
        log_dump(&lc);
        fail_msg("%s missing (GL %d.%d): fogvol_create_context returned %d (%s), want MISSING_FUNCTION", name, v_major,
                 v_minor, (int)res, fogvol_result_string(res));
    }
    assert_null(fv);
    assert_true(l.asked_for_missing >= 1);
    if (!log_error_has(&lc, name)) {
        log_dump(&lc);
        fail_msg("%s missing: the logged error does not name it", name);
    }
    if (cnt.live != 0) fail_msg("%s missing: %ld allocations leaked", name, cnt.live);
    obj_expect_none(name);
}

/* One optional name missing: the context still comes up and renders a frame. */
static void expect_not_needed(const char *name, int v_major, int v_minor)
{
    loader l;
    logcap lc;
    counting cnt;
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    fogvol_result res;
    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    l.missing = name;
    gl_desc(&cd, &l, &lc, &cnt, v_major, v_minor);
    res = fogvol_create_context(&cd, &fv);
    if (res != FOGVOL_SUCCESS) {
        log_dump(&lc);
        fail_msg("%s missing (GL %d.%d): fogvol_create_context returned %d (%s), want success", name, v_major, v_minor,
                 (int)res, fogvol_result_string(res));
    }
    {
        fogvol_frame_desc fd;
        fogvol_frame_stats st;
        a_frame_desc(&fd);
        fd.viewport[0] = fd.viewport[1] = 0;
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(st.passes, 1);
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    fogvol_destroy_context(fv);
    assert_int_equal(cnt.live, 0);
    obj_expect_none(name);
}

static void test_gl_missing_entry_core33(void **state)
{
    int i, n = 0;
    (void)state;
    for (i = 0; i < COUNT_OF(g_base_names); ++i, ++n) expect_missing(g_base_names[i], 0, 0);
    for (i = 0; i < COUNT_OF(g_fbo_names); ++i, ++n) expect_missing(g_fbo_names[i], 0, 0);
    for (i = 0; i < COUNT_OF(g_vao_names); ++i, ++n) expect_missing(g_vao_names[i], 0, 0);
    for (i = 0; i < COUNT_OF(g_sampler_names); ++i, ++n) expect_missing(g_sampler_names[i], 0, 0);
#ifndef G_GL3_NONE
    for (i = 0; i < COUNT_OF(g_gl3_names); ++i, ++n) expect_missing(g_gl3_names[i], 0, 0);
#endif
    for (i = 0; i < COUNT_OF(g_desktop_names); ++i, ++n) expect_missing(g_desktop_names[i], 0, 0);
    print_message("  3.3 core: %d required entry points, each one missing in turn\n", n);
    /* the GLES-only entry is not needed on desktop */
    for (i = 0; i < COUNT_OF(g_es_names); ++i) expect_not_needed(g_es_names[i], 0, 0);
}

static void test_gl_missing_entry_gl21(void **state)
{
    int i, n = 0;
    const char *ext = (const char *)glGetString(GL_EXTENSIONS);
    (void)state;
    /* with ARB_framebuffer_object the FBO entry points have no suffix */
    assert_non_null(ext);
    assert_non_null(strstr(ext, "GL_ARB_framebuffer_object"));
    for (i = 0; i < COUNT_OF(g_base_names); ++i, ++n) expect_missing(g_base_names[i], 2, 1);
    for (i = 0; i < COUNT_OF(g_fbo_names); ++i, ++n) expect_missing(g_fbo_names[i], 2, 1);
    for (i = 0; i < COUNT_OF(g_desktop_names); ++i, ++n) expect_missing(g_desktop_names[i], 2, 1);
    print_message("  GL 2.1: %d required entry points, each one missing in turn\n", n);
    /* not part of GL 2.1: a missing VAO, sampler or ES entry point does not matter */
    for (i = 0; i < COUNT_OF(g_vao_names); ++i) expect_not_needed(g_vao_names[i], 2, 1);
    for (i = 0; i < COUNT_OF(g_sampler_names); ++i) expect_not_needed(g_sampler_names[i], 2, 1);
    for (i = 0; i < COUNT_OF(g_es_names); ++i) expect_not_needed(g_es_names[i], 2, 1);
#ifndef G_GL3_NONE
    for (i = 0; i < COUNT_OF(g_gl3_names); ++i) expect_not_needed(g_gl3_names[i], 2, 1);
#endif
}

static void test_gl_loader_finds_nothing(void **state)
{
    loader l;
    logcap lc;
    counting cnt;
    fogvol_context_desc cd;
    fogvol_context *fv = (fogvol_context *)&cd;
    (void)state;
    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    l.nothing = 1;
    gl_desc(&cd, &l, &lc, &cnt, 0, 0);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_MISSING_FUNCTION);
    assert_null(fv);
    assert_string_equal(g_base_names[0], "glGetString");
    assert_true(log_error_has(&lc, "glGetString"));
    assert_int_equal(cnt.live, 0);
    /* no loader at all */
    cd.gl.get_proc_address = NULL;
    log_reset(&lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_INVALID_ARGUMENT);
    assert_true(log_error_has(&lc, NULL));
    assert_int_equal(cnt.live, 0);
}

/* The plain loaders of fogvol_gl_desc, as GLFW, EGL and SDL hand them out, with no wrapper:
   get_proc (a function pointer back) and get_proc_pointer (void * back). Each must be the one asked
   (it counts the names) and give a context that draws as with get_proc_address. */
static int g_plain_calls;
static fogvol_gl_proc plain_proc(const char *name)
{
    g_plain_calls++;
    return (fogvol_gl_proc)glu_proc(name, NULL);
}
static void *plain_pointer(const char *name)
{
    fogvol_gl_proc f = plain_proc(name);
    void *p = NULL;
    memcpy(&p, &f, sizeof p); /* (as SDL2's loader hands a function over) */
    return p;
}

static void test_gl_plain_loaders(void **state)
{
    int k;
    (void)state;
    for (k = 0; k < 2; ++k) {
        logcap lc;
        counting cnt;
        fogvol_context_desc cd;
        fogvol_context *fv = NULL;
        fogvol_frame_stats st;
        fogvol_frame_desc fd;
        memset(&cnt, 0, sizeof cnt);
        log_reset(&lc);
        memset(&cd, 0, sizeof cd);
        cd.logger = cap_logger(&lc);
        cd.allocator = cnt_allocator(&cnt);
        if (k == 0) cd.gl.get_proc = plain_proc;
        else cd.gl.get_proc_pointer = plain_pointer;
        g_plain_calls = 0;
        assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
        assert_true(g_plain_calls > 20); /* every entry point came through it */
        a_frame_desc(&fd);
        assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(lc.errors + lc.warnings, 0);
        fogvol_destroy_context(fv);
        assert_int_equal(cnt.live, 0);
    }
}

/* ---- GLSL dialects ---- */
static void expect_dialect(const fogvol_gl_desc *in, fogvol_dialect want, const char *what)
{
    fogvol_backend be;
    logcap lc;
    counting cnt;
    fogvol_allocator a;
    fogvol_logger lg;
    fogvol_result res;
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    a = cnt_allocator(&cnt);
    lg = cap_logger(&lc);
    res = fogvol_gl_backend_create(in, &a, &lg, &be);
    if (res != FOGVOL_SUCCESS) {
        log_dump(&lc);
        fail_msg("%s: fogvol_gl_backend_create returned %d (%s)", what, (int)res, fogvol_result_string(res));
    }
    if (be.dialect != want)
        fail_msg("%s: dialect %s, want %s", what, fogvol_dialect_name(be.dialect), fogvol_dialect_name(want));
    assert_non_null(be.destroy);
    be.destroy(be.user_data);
    assert_int_equal(cnt.live, 0);
    obj_expect_none(what);
    while (glGetError() != GL_NO_ERROR) {
    }
}

static void test_gl_dialect_choice_core(void **state)
{
    fogvol_gl_desc d;
    loader l;
    (void)state;
    memset(&l, 0, sizeof l);
    memset(&d, 0, sizeof d);
    d.get_proc_address = test_loader;
    d.user_data = &l;
    expect_dialect(&d, FOGVOL_GLSL_330, "core context, no override");
    d.version_major = 3;
    d.version_minor = 0;
    expect_dialect(&d, FOGVOL_GLSL_130, "override 3.0");
    d.version_minor = 1;
    expect_dialect(&d, FOGVOL_GLSL_130, "override 3.1");
    d.version_minor = 2;
    expect_dialect(&d, FOGVOL_GLSL_150, "override 3.2");
    d.version_minor = 3;
    expect_dialect(&d, FOGVOL_GLSL_330, "override 3.3");
    d.version_major = 0;
    d.version_minor = 0;
    d.dialect = FOGVOL_GLSL_100;
    expect_dialect(&d, FOGVOL_GLSL_100, "dialect override 100");
    { /* SPIR-V is no GL dialect: refused, and no GL context picks it */
        fogvol_backend be;
        fogvol_allocator a;
        counting cnt;
        memset(&cnt, 0, sizeof cnt);
        a = cnt_allocator(&cnt);
        d.dialect = FOGVOL_GLSL_VULKAN;
        assert_int_equal(fogvol_gl_backend_create(&d, &a, NULL, &be), FOGVOL_ERROR_UNSUPPORTED);
        assert_int_equal(cnt.live, 0);
    }
}

static void test_gl_dialect_choice_compat(void **state)
{
    fogvol_gl_desc d;
    loader l;
    (void)state;
    memset(&l, 0, sizeof l);
    memset(&d, 0, sizeof d);
    d.get_proc_address = test_loader;
    d.user_data = &l;
    d.version_major = 2;
    d.version_minor = 1;
    expect_dialect(&d, FOGVOL_GLSL_120, "override 2.1");
    d.version_minor = 0;
    expect_dialect(&d, FOGVOL_GLSL_110, "override 2.0");
    d.version_minor = 0;
    d.gles = 1;
    expect_dialect(&d, FOGVOL_GLSL_100, "override GLES 2.0");
    d.version_major = 3;
    expect_dialect(&d, FOGVOL_GLSL_300ES, "override GLES 3.0");
}

/* FOGVOL_CAP_SOFTWARE_RENDERER: from GL_RENDERER by fogvol_renderer_is_software (llvmpipe: set; a GPU
   driver: not), or as fogvol_gl_desc.software says (1: set, -1: not, whatever the renderer) */
static void test_gl_software_renderer(void **state)
{
    fogvol_gl_desc d;
    fogvol_backend be;
    loader l;
    const char *renderer = (const char *)glGetString(GL_RENDERER);
    int k;
    (void)state;
    for (k = -1; k <= 1; ++k) {
        memset(&l, 0, sizeof l);
        memset(&d, 0, sizeof d);
        d.get_proc_address = test_loader;
        d.user_data = &l;
        d.software = k;
        assert_int_equal(fogvol_gl_backend_create(&d, NULL, NULL, &be), FOGVOL_SUCCESS);
        assert_int_equal((be.caps & FOGVOL_CAP_SOFTWARE_RENDERER) != 0,
                         k ? k > 0 : fogvol_renderer_is_software(renderer));
        be.destroy(be.user_data);
    }
    print_message("  GL_RENDERER \"%s\": %s\n", renderer,
                  fogvol_renderer_is_software(renderer) ? "software (engine depth depth-tested)"
                                                        : "a GPU (engine depth read per face)");
}

/* ---- rendering a sphere for the thickness checks ---- */

/* w-extent of a ray through the pixel centre (px, py) inside a sphere of radius r whose
   centre is at view depth dist on the axis (perspective fovy, square viewport). */
static double analytic_chord_w(double fovy_deg, int w, int h, double px, double py, double dist, double r)
{
    double t = tan(fovy_deg * 3.14159265358979323846 / 360.0);
    double v[3], c[3] = {0, 0, -dist}, vv, vc, cc, disc;
    v[0] = (2.0 * px / w - 1.0) * t * ((double)w / h);
    v[1] = (2.0 * py / h - 1.0) * t;
    v[2] = -1.0; /* ray p = s * v: view depth w = s */
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    vc = v[0] * c[0] + v[1] * c[1] + v[2] * c[2];
    cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    disc = vc * vc - vv * (cc - r * r);
    return disc > 0 ? 2.0 * sqrt(disc) / vv : 0.0;
}

/* Renders a unit sphere 4 units in front of the camera; returns the decoded thickness at
   the centre pixel (and checks it against the chord within rel_tol). */
static double render_sphere(fogvol_context *fv, double rel_tol, const char *what)
{
    shp_mesh sph = shp_sphere(1.0f, 64, 32);
    fogvol_mesh *m;
    fogvol_ramp *rp;
    fogvol_frame_desc fd;
    fogvol_frame_stats st;
    fogvol_volume_desc vd;
    float *thick = (float *)calloc((size_t)G_W * G_H, sizeof(float));
    double got, want;
    int cx = G_W / 2, cy = G_H / 2;
    assert_non_null(thick);
    assert_int_equal(make_mesh(fv, &sph, 0, 0, &m), FOGVOL_SUCCESS);
    assert_int_equal(make_ramp(fv, FOGVOL_BLEND_FOG, &rp), FOGVOL_SUCCESS);
    memset(&fd, 0, sizeof fd);
    mat_ts(fd.view, 0, 0, -4, 1, 1, 1); /* camera at z = 4 looking down -z */
    glu_perspective(fd.projection, 50.0, 1.0, 0.5, 10.0);
    fd.znear = 0.5f;
    fd.zfar = 10.0f;
    fd.viewport[2] = G_W;
    fd.viewport[3] = G_H;
    fd.debug_thickness = thick;
    memset(&vd, 0, sizeof vd);
    mat_identity(vd.model);
    vd.mesh = m;
    vd.ramp = rp;
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, &st), FOGVOL_SUCCESS);
    if (fogvol_context_tier(fv, NULL) == FOGVOL_TIER_PS20) assert_int_equal(st.passes, 4); /* O, B, F, composite */
    assert_int_equal(st.groups, 1);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    got = thick[cy * G_W + cx];
    want = analytic_chord_w(50.0, G_W, G_H, cx + 0.5, cy + 0.5, 4.0, 1.0);
    print_message("  %s, tier %s: centre thickness %.5f, analytic chord %.5f (%.3f%%)\n", what,
                  fogvol_tier_name(fogvol_context_tier(fv, NULL)), got, want, 100.0 * (got - want) / want);
    if (!(fabs(got - want) <= rel_tol * want)) fail_msg("%s: thickness %.5f vs chord %.5f", what, got, want);
    /* a corner pixel sees no fog */
    assert_true(fabs(thick[0]) < 1e-3);
    /* the composite reached the engine framebuffer (black): the centre is the fog colour
       (0.9, 0.7, 0.5) at alpha 1 - exp(-density * t), the corner stays black */
    {
        unsigned char px[4], corner[4];
        double alpha = 1.0 - exp(-0.5 * want);
        const double fog[3] = {0.9, 0.7, 0.5};
        int c;
        glFinish();
        glReadPixels(cx, cy, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, corner);
        for (c = 0; c < 3; ++c) {
            if (fabs(px[c] - 255.0 * fog[c] * alpha) > 3.0)
                fail_msg("%s: composite channel %d = %d, want %.1f", what, c, px[c], 255.0 * fog[c] * alpha);
            assert_int_equal(corner[c], 0);
        }
    }
    fogvol_destroy_mesh(fv, m);
    fogvol_destroy_ramp(fv, rp);
    shp_free(&sph);
    free(thick);
    return got;
}

/* wraps create_program to see the GLSL version line the backend compiles */
static fogvol_backend g_inner_gl;
static int g_version_ok, g_programs_seen;
static const char *g_want_version;
static const char *g_broken_fs;

static int starts_with_version(const char *const *s, int n, const char *want)
{
    /* the first line of the concatenated strings */
    char buf[64];
    size_t len = 0;
    int i;
    for (i = 0; i < n && len < sizeof buf - 1; ++i) {
        size_t k;
        for (k = 0; s[i][k] && len < sizeof buf - 1; ++k) buf[len++] = s[i][k];
    }
    buf[len] = 0;
    return strncmp(buf, want, strlen(want)) == 0;
}

static fogvol_result version_check_create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    g_programs_seen++;
    if (starts_with_version(d->vs, d->vs_count, g_want_version) &&
        starts_with_version(d->fs, d->fs_count, g_want_version))
        g_version_ok++;
    return g_inner_gl.create_program(u, d, out);
}

static void test_gl_glsl100_renders_in_core(void **state)
{
    fogvol_gl_desc gd;
    loader l;
    logcap lc;
    counting cnt;
    fogvol_allocator a;
    fogvol_logger lg;
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    (void)state;
    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    a = cnt_allocator(&cnt);
    lg = cap_logger(&lc);

    /* reference: the default dialect of the core context */
    gl_desc(&cd, &l, &lc, &cnt, 0, 0);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    render_sphere(fv, 0.01, "GLSL 330 core (default)");
    fogvol_destroy_context(fv);
    assert_int_equal(cnt.live, 0);
    obj_expect_none("330 context");

    /* GLSL ES 1.00 in the desktop core context */
    memset(&gd, 0, sizeof gd);
    gd.get_proc_address = test_loader;
    gd.user_data = &l;
    gd.dialect = FOGVOL_GLSL_100;
    assert_int_equal(fogvol_gl_backend_create(&gd, &a, &lg, &g_inner_gl), FOGVOL_SUCCESS);
    assert_int_equal(g_inner_gl.dialect, FOGVOL_GLSL_100);
    memset(&cd, 0, sizeof cd);
    cd.backend = g_inner_gl;
    cd.backend.create_program = version_check_create_program;
    cd.logger = lg;
    cd.allocator = a;
    g_want_version = "#version 100\n";
    g_version_ok = g_programs_seen = 0;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        log_dump(&lc);
        fail_msg("GLSL 100 context creation failed");
    }
    assert_int_equal(fogvol_context_tier(fv, NULL), FOGVOL_TIER_PS20); /* no float targets in GLSL ES 1.00 */
    assert_int_equal(g_programs_seen, 3); /* PS20: encode, face, composite (the geometry composite uses it too) */
    assert_int_equal(g_version_ok, g_programs_seen);
    render_sphere(fv, 0.01, "GLSL ES 1.00 in the core context");
    fogvol_destroy_context(fv);
    g_inner_gl.destroy(g_inner_gl.user_data);
    assert_int_equal(cnt.live, 0);
    obj_expect_none("100 context");
}

/* Each version override compiles its dialect and renders (2.1 in the compatibility
   context, which has the extension string it reads; 3.x in the core context). */
static void override_renders(int major, int minor, const char *version_line)
{
    fogvol_gl_desc gd;
    loader l;
    logcap lc;
    counting cnt;
    fogvol_allocator a;
    fogvol_logger lg;
    fogvol_context_desc cd;
    fogvol_context *fv = NULL;
    char what[64];
    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    a = cnt_allocator(&cnt);
    lg = cap_logger(&lc);
    memset(&gd, 0, sizeof gd);
    gd.get_proc_address = test_loader;
    gd.user_data = &l;
    gd.version_major = major;
    gd.version_minor = minor;
    assert_int_equal(fogvol_gl_backend_create(&gd, &a, &lg, &g_inner_gl), FOGVOL_SUCCESS);
    memset(&cd, 0, sizeof cd);
    cd.backend = g_inner_gl;
    cd.backend.create_program = version_check_create_program;
    cd.logger = lg;
    cd.allocator = a;
    g_want_version = version_line;
    g_version_ok = g_programs_seen = 0;
    if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) {
        log_dump(&lc);
        fail_msg("override %d.%d: context creation failed", major, minor);
    }
    assert_true(g_programs_seen >= 3);
    assert_int_equal(g_version_ok, g_programs_seen);
    snprintf(what, sizeof what, "override %d.%d (%.12s)", major, minor, version_line);
    render_sphere(fv, 0.01, what);
    fogvol_destroy_context(fv);
    g_inner_gl.destroy(g_inner_gl.user_data);
    assert_int_equal(cnt.live, 0);
    obj_expect_none(what);
}

static void test_gl_override21_renders(void **state)
{
    (void)state;
    override_renders(2, 1, "#version 120\n");
}

/* ---- a shader that does not compile ---- */
static fogvol_result broken_create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    fogvol_program_desc b = *d;
    g_programs_seen++;
    b.fs[0] = g_broken_fs;
    b.fs_count = 1;
    return g_inner_gl.create_program(u, &b, out);
}

/* The driver's own info log for a fragment shader, compiled here directly. */
static void driver_info_log(const char *src, char *log, size_t cap)
{
    PFNGLCREATESHADERPROC create = (PFNGLCREATESHADERPROC)glu_proc("glCreateShader", NULL);
    PFNGLSHADERSOURCEPROC source = (PFNGLSHADERSOURCEPROC)glu_proc("glShaderSource", NULL);
    PFNGLCOMPILESHADERPROC compile = (PFNGLCOMPILESHADERPROC)glu_proc("glCompileShader", NULL);
    PFNGLGETSHADERIVPROC getiv = (PFNGLGETSHADERIVPROC)glu_proc("glGetShaderiv", NULL);
    PFNGLGETSHADERINFOLOGPROC infolog = (PFNGLGETSHADERINFOLOGPROC)glu_proc("glGetShaderInfoLog", NULL);
    PFNGLDELETESHADERPROC del = (PFNGLDELETESHADERPROC)glu_proc("glDeleteShader", NULL);
    GLuint sh;
    GLint ok = 1;
    GLsizei got = 0;
    sh = create(GL_FRAGMENT_SHADER);
    source(sh, 1, &src, NULL);
    compile(sh);
    getiv(sh, GL_COMPILE_STATUS, &ok);
    assert_int_equal(ok, 0);
    log[0] = 0;
    infolog(sh, (GLsizei)cap, &got, log);
    del(sh);
    assert_true(got > 0);
}

static void test_gl_shader_compile_failure(void **state)
{
    static const char broken[] = "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(fogvol_undeclared); }\n";
    fogvol_gl_desc gd;
    loader l;
    logcap lc;
    counting cnt;
    fogvol_allocator a;
    fogvol_logger lg;
    fogvol_context_desc cd;
    fogvol_context *fv = (fogvol_context *)&cd;
    char info[512];
    long live_backend;
    int objs_backend, i, found = 0;
    (void)state;
    driver_info_log(broken, info, sizeof info);
    assert_true(strlen(info) > 10);

    memset(&l, 0, sizeof l);
    memset(&cnt, 0, sizeof cnt);
    log_reset(&lc);
    a = cnt_allocator(&cnt);
    lg = cap_logger(&lc);
    memset(&gd, 0, sizeof gd);
    gd.get_proc_address = test_loader;
    gd.user_data = &l;
    assert_int_equal(fogvol_gl_backend_create(&gd, &a, &lg, &g_inner_gl), FOGVOL_SUCCESS);
    live_backend = cnt.live;
    objs_backend = obj_live_total();

    memset(&cd, 0, sizeof cd);
    cd.backend = g_inner_gl;
    cd.backend.create_program = broken_create_program;
    cd.logger = lg;
    cd.allocator = a;
    g_broken_fs = broken;
    g_programs_seen = 0;
    log_reset(&lc);
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_ERROR_SHADER_COMPILE);
    assert_null(fv);
    assert_true(g_programs_seen >= 1);
    for (i = 0; i < lc.count && i < LOG_MAX; ++i)
        if (lc.level[i] == FOGVOL_LOG_ERROR && strstr(lc.msg[i], info)) found = 1;
    if (!found) {
        log_dump(&lc);
        fail_msg("the driver's info log \"%s\" is not in any logged error", info);
    }
    /* nothing of the failed context is left: only the backend's own memory and objects */
    assert_int_equal(cnt.live, live_backend);
    assert_int_equal(obj_live_total(), objs_backend);
    assert_int_equal(g_obj.bad_deletes, 0);
    assert_int_equal(glGetError(), GL_NO_ERROR);

    /* the backend is intact: the same table without the fault gives a working context */
    cd.backend.create_program = g_inner_gl.create_program;
    assert_int_equal(fogvol_create_context(&cd, &fv), FOGVOL_SUCCESS);
    render_sphere(fv, 0.01, "backend reused after the compile failure");
    fogvol_destroy_context(fv);
    assert_int_equal(cnt.live, live_backend); /* a table it does not own is not destroyed */
    g_inner_gl.destroy(g_inner_gl.user_data);
    assert_int_equal(cnt.live, 0);
    obj_expect_none("after backend destroy");
}

/* ---- allocation failures while the GL backend and context come up ---- */
static void test_gl_alloc_faults(void **state)
{
    long k;
    int fails = 0;
    (void)state;
    for (k = 1;; ++k) {
        loader l;
        logcap lc;
        counting cnt;
        fogvol_context_desc cd;
        fogvol_context *fv = (fogvol_context *)&cd;
        fogvol_result res;
        memset(&l, 0, sizeof l);
        memset(&cnt, 0, sizeof cnt);
        log_reset(&lc);
        gl_desc(&cd, &l, &lc, &cnt, 0, 0);
        cnt.fail_at = k;
        res = fogvol_create_context(&cd, &fv);
        if (res == FOGVOL_SUCCESS) {
            fogvol_destroy_context(fv);
            assert_int_equal(cnt.live, 0);
            obj_expect_none("GL context");
            break;
        }
        fails++;
        assert_true(k < 100);
        if (res != FOGVOL_ERROR_OUT_OF_MEMORY) fail_msg("allocation %ld failing: %s", k, fogvol_result_string(res));
        assert_null(fv);
        if (cnt.live != 0) fail_msg("allocation %ld failing: %ld allocations leaked", k, cnt.live);
        obj_expect_none("failed GL context");
        assert_int_equal(glGetError(), GL_NO_ERROR);
    }
    print_message("  GL context creation: %d failing allocation points, all clean\n", fails);
    assert_true(fails >= 2);
}

/* fogvol_frame_desc.downsample: 2 puts the FLOAT sums at half the viewport (rounded up), the O and
   face passes in that target space, the composite at the viewport with a program of its own
   (FOGVOL_SPECIALIZE_DOWNSAMPLE); other values and the configurations it does not cover are refused. */
static void test_downsample_half_resolution(void **state)
{
    static box_scene b;
    logcap lc;
    fogvol_frame_desc fd;
    fogvol_light_desc ld;
    fogvol_frame_stats st;
    fogvol_handle comp_half = 0, comp_full = 0;
    rec *r = &b.r;
    int pass, round, k, begun;
    (void)state;
    box_scene_open(&b, FOGVOL_TIER_FLOAT, 0u, FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_MULTISAMPLE, 0u, &lc);
    a_frame_desc(&fd);
    fd.viewport[2] = 63; /* odd: the half-resolution targets round up to 32 x 24 */
    fd.viewport[3] = 47;
    fd.downsample = 3;
    EXPECT_LOGGED(fogvol_begin_frame(b.fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    fd.downsample = -1;
    EXPECT_LOGGED(fogvol_begin_frame(b.fv, &fd), FOGVOL_ERROR_INVALID_ARGUMENT);
    for (round = 0; round < 3; ++round) { /* half, full, half again: the targets follow */
        int half = round != 1, tw = half ? 32 : 63, thh = half ? 24 : 47;
        fd.downsample = half ? 2 : 0;
        assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_occluder(b.fv, b.plane, b.om), FOGVOL_SUCCESS);
        assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
        log_reset(&lc);
        assert_int_equal(fogvol_end_frame(b.fv, &st), FOGVOL_SUCCESS);
        assert_int_equal(lc.errors + lc.warnings, 0);
        assert_int_equal(st.passes, 3);                 /* O, the signed sum, the composite */
        assert_int_equal(r->ntgt, 2 * (round + 1));     /* O and the sum, made again when the size changes */
        for (k = r->ntgt - 2; k < r->ntgt; ++k) {
            assert_int_equal(r->tgt[k].w, tw);
            assert_int_equal(r->tgt[k].hgt, thh);
        }
        for (pass = 0; pass < 2; ++pass) { /* O and the faces: target space at the targets' size */
            const fogvol_pass *p = &r->nb.passes[pass];
            assert_int_equal(p->viewport[0], 0);
            assert_int_equal(p->viewport[1], 0);
            assert_int_equal(p->viewport[2], tw);
            assert_int_equal(p->viewport[3], thh);
            assert_close(p->uniforms[FOGVOL_U_SCREEN][0], 1.0 / tw, 1e-7, "target-space 1 / width");
            assert_close(p->uniforms[FOGVOL_U_SCREEN][1], 1.0 / thh, 1e-7, "target-space 1 / height");
        }
        { /* the composite: the engine's viewport, window-space 1 / size, its own program */
            const fogvol_pass *p = &r->nb.passes[2];
            assert_int_equal(p->target, 0);
            assert_int_equal(p->viewport[2], 63);
            assert_int_equal(p->viewport[3], 47);
            assert_close(p->uniforms[FOGVOL_U_SCREEN][0], 1.0 / 63, 1e-7, "window 1 / width");
            assert_close(p->uniforms[FOGVOL_U_SCREEN][1], 1.0 / 47, 1e-7, "window 1 / height");
            if (half) {
                if (comp_half) assert_int_equal(p->program, comp_half);
                comp_half = p->program;
            } else {
                comp_full = p->program;
            }
        }
    }
    assert_int_not_equal(comp_half, comp_full);
    { /* the program is the documented one: FLOAT composite with DOWNSAMPLE, and only there */
        fogvol_shader_desc sd;
        const char *strs[FOGVOL_MAX_SHADER_STRINGS];
        int n;
        memset(&sd, 0, sizeof sd);
        sd.tier = FOGVOL_TIER_FLOAT;
        sd.program = FOGVOL_PROGRAM_COMPOSITE;
        sd.dialect = FOGVOL_GLSL_330;
        sd.stage = FOGVOL_STAGE_FRAGMENT;
        sd.specialize = FOGVOL_SPECIALIZE_DOWNSAMPLE;
        assert_int_equal(fogvol_shader_strings(&sd, strs, &n), FOGVOL_SUCCESS);
        sd.specialize = FOGVOL_SPECIALIZE_FILTERED; /* only with DOWNSAMPLE */
        assert_int_equal(fogvol_shader_strings(&sd, strs, &n), FOGVOL_ERROR_UNSUPPORTED);
        sd.specialize = FOGVOL_SPECIALIZE_DOWNSAMPLE;
        sd.samples = 4;
        assert_int_equal(fogvol_shader_strings(&sd, strs, &n), FOGVOL_ERROR_UNSUPPORTED);
        sd.samples = 0;
        sd.program = FOGVOL_PROGRAM_FACE;
        assert_int_equal(fogvol_shader_strings(&sd, strs, &n), FOGVOL_ERROR_UNSUPPORTED);
        sd.program = FOGVOL_PROGRAM_COMPOSITE;
        sd.tier = FOGVOL_TIER_PS20;
        assert_int_equal(fogvol_shader_strings(&sd, strs, &n), FOGVOL_ERROR_UNSUPPORTED);
    }
    /* refused at end_frame, nothing drawn: a light, a multisampled framebuffer drawn per sample */
    fd.downsample = 2;
    memset(&ld, 0, sizeof ld);
    ld.mesh = b.box;
    mat_ts(ld.model, 0, 0, 0, 1, 1, 1);
    ld.color[0] = ld.color[1] = ld.color[2] = 1.0f;
    begun = r->nb.frames_begun;
    assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_light(b.fv, &ld), FOGVOL_SUCCESS);
    EXPECT_LOGGED(fogvol_end_frame(b.fv, &st), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(r->nb.frames_begun, begun);
    r->nb.samples = 4;
    assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
    EXPECT_LOGGED(fogvol_end_frame(b.fv, &st), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(r->nb.frames_begun, r->nb.frames_ended);
    r->nb.samples = 0;
    box_scene_close(&b);
    /* another tier: refused before the backend is touched */
    box_scene_open(&b, FOGVOL_TIER_PS20, 0u, 0u, 0u, &lc);
    begun = r->nb.frames_begun;
    assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
    EXPECT_LOGGED(fogvol_end_frame(b.fv, &st), FOGVOL_ERROR_UNSUPPORTED);
    assert_int_equal(r->nb.frames_begun, begun);
    box_scene_close(&b);
}

/* fogvol's targets are made once per size: FLOAT + ENGINE_DEPTH, which has no O target, kept making
   its sum target again in every frame (found in review). Every tier and the variants that change the
   set of targets, three frames each: targets only at the first. */
static void test_targets_made_once_per_size(void **state)
{
    static const struct {
        fogvol_tier t;
        unsigned v;
    } c[] = {{FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH}, {FOGVOL_TIER_FLOAT, 0}, {FOGVOL_TIER_PS20, 0},
             {FOGVOL_TIER_PS13, 0}, {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET}};
    int i, f, made = 0;
    (void)state;
    for (i = 0; i < (int)(sizeof c / sizeof c[0]); ++i) {
        static box_scene b;
        fogvol_frame_desc fd;
        box_scene_open(&b, c[i].t, c[i].v, FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_DEPTH_TEXTURE, 0u, NULL);
        a_frame_desc(&fd);
        fd.engine_depth_texture = 77; /* ENGINE_DEPTH: any native texture name (the null backend draws nothing) */
        for (f = 0; f < 3; ++f) {
            assert_int_equal(fogvol_begin_frame(b.fv, &fd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_add_volume(b.fv, &b.vd), FOGVOL_SUCCESS);
            assert_int_equal(fogvol_end_frame(b.fv, NULL), FOGVOL_SUCCESS);
            if (f == 0) made = b.r.ntgt;
            if (b.r.ntgt != made)
                fail_msg("%s variants 0x%x: %d targets made by frame %d, %d after the first", fogvol_tier_name(c[i].t),
                         c[i].v, b.r.ntgt, f, made);
        }
        assert_true(made >= 1);
        box_scene_close(&b);
    }
}

/* One FLOAT + ENGINE_DEPTH frame on the null backend: the camera of a_frame_desc, the viewport at the
   origin unless offset, a box of half-size h at the origin (view depth 5 - h .. 5 + h), engine depth
   texture 77, depth range r (both 0: as reported); the passes and stats in *nb and *st. */
static void ed_frame(fogvol_context *fv, const fogvol_mesh *box, const fogvol_ramp *ramp, float h, int offset,
                     float r0, float r1, fogvol_frame_stats *st)
{
    fogvol_frame_desc fd;
    fogvol_volume_desc vd;
    a_frame_desc(&fd);
    fd.viewport[0] = offset ? A_X0 : 0;
    fd.viewport[1] = offset ? A_Y0 : 0;
    fd.engine_depth_texture = 77;
    fd.engine_depth_range[0] = r0;
    fd.engine_depth_range[1] = r1;
    memset(&vd, 0, sizeof vd);
    vd.mesh = box;
    vd.ramp = ramp;
    glu_translate_scale(vd.model, 0.0f, 0.0f, 0.0f, h);
    assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
    assert_int_equal(fogvol_end_frame(fv, st), FOGVOL_SUCCESS);
}

/* A FLOAT + ENGINE_DEPTH context on backend table be (logger lg: may be NULL), with the box s as a mesh
   and one ramp; ed_free frees them. ed_context_v: FLOAT with other variants. */
static void ed_context_v(const fogvol_backend *be, const fogvol_logger *lg, unsigned variants, const shp_mesh *s,
                         fogvol_context **fv, fogvol_mesh **box, fogvol_ramp **ramp)
{
    fogvol_context_desc cd;
    fogvol_mesh_desc md;
    fogvol_ramp_desc rd;
    memset(&cd, 0, sizeof cd);
    cd.backend = *be;
    if (lg) cd.logger = *lg;
    cd.tier = FOGVOL_TIER_FLOAT;
    cd.variants = variants;
    assert_int_equal(fogvol_create_context(&cd, fv), FOGVOL_SUCCESS);
    fx_mesh_desc(&md, s, 0);
    assert_int_equal(fogvol_create_mesh(*fv, &md, box, NULL), FOGVOL_SUCCESS);
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 1.0f;
    rd.density = 0.5f;
    assert_int_equal(fogvol_create_ramp(*fv, &rd, ramp), FOGVOL_SUCCESS);
}

static void ed_context(const fogvol_backend *be, const fogvol_logger *lg, const shp_mesh *s, fogvol_context **fv,
                       fogvol_mesh **box, fogvol_ramp **ramp)
{
    ed_context_v(be, lg, FOGVOL_VARIANT_ENGINE_DEPTH, s, fv, box, ramp);
}

static void ed_free(fogvol_context *fv, fogvol_mesh *box, fogvol_ramp *ramp)
{
    fogvol_destroy_ramp(fv, ramp);
    fogvol_destroy_mesh(fv, box);
    fogvol_destroy_context(fv);
}

/* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST on the null backend (FOGVOL_CAP_ATTACH_DEPTH): a frame that fits draws
   its faces into a target of fogvol's with the engine's depth texture as its depth buffer (tested,
   not written; GREATER where the depth range reverses it) reading no depth, and the composite reads
   that texture; at an offset viewport the faces draw at the engine's own viewport into a target in
   window coordinates (the texture's), so the depth lines up; a box around the camera that also crosses
   the far plane, a backend without the capability, or one on a GPU (without
   FOGVOL_CAP_SOFTWARE_RENDERER: per-face reads are the faster there): the faces read the engine's depth
   as before, nothing attached. */
static void test_engine_depth_attached(void **state)
{
    fogvol_null_backend nb;
    fogvol_backend be;
    fogvol_context *fv;
    fogvol_mesh *box;
    fogvol_ramp *ramp;
    fogvol_frame_stats st;
    shp_mesh s = shp_box(1.0f, 1.0f, 1.0f); /* half-size 0.5 */
    int caps, i, k;
    (void)state;
    for (caps = 0; caps < 3; ++caps) { /* 0: no ATTACH_DEPTH; 1: a GPU's; 2: a software renderer's */
        fogvol_null_backend_init(&nb, &be);
        be.caps |= FOGVOL_CAP_FLOAT_BLEND;
        if (!caps) be.caps &= ~(unsigned)FOGVOL_CAP_ATTACH_DEPTH;
        if (caps == 2) be.caps |= FOGVOL_CAP_SOFTWARE_RENDERER;
        ed_context(&be, NULL, &s, &fv, &box, &ramp);
        for (k = 0; k < 5; ++k) {
            /* 0: fits; 1: fits, depth range (1, 0); 2: the camera inside (half-size 8: it also crosses the
               far plane); 3: offset viewport; 4: fits again */
            int fits = caps == 2 && k != 2;
            ed_frame(fv, box, ramp, k == 2 ? 16.0f : 1.0f, k == 3, k == 1 ? 1.0f : 0.0f, 0.0f, &st);
            assert_int_equal(st.engine_depth_tested, fits);
            assert_int_equal(nb.pass_count, 2); /* faces, composite */
            assert_int_equal(nb.draws[0], 1);
            assert_int_equal(nb.fullscreen[1], 1);
            assert_true(nb.passes[0].target != 0);
            assert_int_equal(nb.passes[0].blend, FOGVOL_PASS_BLEND_ADD);
            assert_int_equal(nb.passes[0].depth_write, 0);
            assert_true(nb.passes[1].target == 0);
            for (i = 0; i < 2; ++i) assert_true(nb.passes[i].depth_texture == (fits && i == 0 ? 77u : 0u));
            assert_int_equal(nb.passes[0].depth_test, fits);
            assert_int_equal(nb.passes[0].depth_greater, fits && k == 1);
            /* the faces read the engine's depth only when not depth-tested; the composite only when */
            assert_true(nb.passes[0].native_textures[3] == (fits ? 0u : 77u));
            assert_true(nb.passes[1].native_textures[3] == (fits ? 77u : 0u));
            assert_true(nb.passes[1].textures[0] == nb.passes[0].target);
            if (fits) { /* the faces at the engine's viewport (window coordinates), or the target's own */
                assert_int_equal(nb.passes[0].viewport[0], k == 3 ? A_X0 : 0);
                assert_int_equal(nb.passes[0].viewport[1], k == 3 ? A_Y0 : 0);
                assert_int_equal(nb.passes[0].viewport[2], A_W);
                assert_int_equal(nb.passes[0].viewport[3], A_H);
            }
        }
        if (caps == 2) { /* a split screen: the two views alternate, each depth-tested into one sum in window
                       coordinates; after the first pair nothing is created again */
            int creates = 0;
            fogvol_handle e = 0;
            for (k = 0; k < 6; ++k) {
                ed_frame(fv, box, ramp, 1.0f, k & 1, 0.0f, 0.0f, &st);
                assert_int_equal(st.engine_depth_tested, 1);
                if (k == 1) {
                    creates = nb.creates;
                    e = nb.passes[0].target;
                }
                if (k > 1) assert_int_equal(nb.creates, creates);
                if (k > 0) assert_true(nb.passes[0].target == e);
            }
        }
        ed_free(fv, box, ramp);
        assert_int_equal(nb.creates, nb.destroys);
    }
    shp_free(&s);
}

/* A backend that makes no RG32F target (its create_target refuses them: all, or the multisampled ones)
   for FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST's sum E. Single-sample: the frame still draws, reading the
   engine's depth per face, the speed-up goes off (one warning) and no later frame asks again.
   Multisampled: those frames read it per sample, asked once (one INFO), while single-sample frames in
   between still draw depth-tested; a change of the sample count asks once more. */
static fogvol_backend g_rg_inner;
static int g_rg_refuse_ms_only, g_rg_refused;
static fogvol_result refuse_rg32f(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    if (d->format == FOGVOL_FORMAT_RG32F && (!g_rg_refuse_ms_only || d->samples > 1)) {
        g_rg_refused++;
        *out = 0;
        return FOGVOL_ERROR_BACKEND;
    }
    return g_rg_inner.create_target(u, d, out);
}

static void test_engine_depth_no_rg32f(void **state)
{
    shp_mesh s = shp_box(1.0f, 1.0f, 1.0f);
    int ms, k;
    (void)state;
    for (ms = 0; ms < 2; ++ms) {
        /* the frames' sample counts (0: single-sample), whether each is depth-tested, refusals so far */
        static const int samples[2][6] = {{0, 0, 0, 0, 0, 0}, {4, 4, 0, 4, 0, 2}};
        static const int tested[2][6] = {{0, 0, 0, 0, 0, 0}, {0, 0, 1, 0, 1, 0}};
        static const int refused[2][6] = {{1, 1, 1, 1, 1, 1}, {1, 1, 1, 2, 2, 3}};
        fogvol_null_backend nb;
        fogvol_backend be;
        fogvol_logger lg;
        fogvol_context *fv;
        fogvol_mesh *box;
        fogvol_ramp *ramp;
        fogvol_frame_stats st;
        logcap lc;
        log_reset(&lc);
        lg = cap_logger(&lc);
        fogvol_null_backend_init(&nb, &g_rg_inner);
        be = g_rg_inner;
        be.caps |= FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_SOFTWARE_RENDERER | FOGVOL_CAP_MULTISAMPLE |
                   FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE;
        be.create_target = refuse_rg32f;
        g_rg_refuse_ms_only = ms;
        g_rg_refused = 0;
        ed_context(&be, &lg, &s, &fv, &box, &ramp);
        for (k = 0; k < 6; ++k) {
            nb.samples = samples[ms][k];
            ed_frame(fv, box, ramp, 1.0f, 0, 0.0f, 0.0f, &st); /* (a frame that fits) */
            assert_int_equal(st.engine_depth_tested, tested[ms][k]);
            assert_int_equal(g_rg_refused, refused[ms][k]);
            /* the faces read the engine's depth exactly when not depth-tested */
            assert_true(nb.passes[0].native_textures[3] == (tested[ms][k] ? 0u : 77u));
        }
        if (ms) {
            assert_true(log_has(&lc, FOGVOL_LOG_INFO, "multisample RG32F"));
            assert_int_equal(lc.warnings, 0);
        } else {
            assert_int_equal(lc.warnings, 1);
            assert_true(log_has(&lc, FOGVOL_LOG_WARNING, "RG32F"));
        }
        assert_int_equal(lc.errors, 0);
        ed_free(fv, box, ramp);
        assert_int_equal(nb.creates, nb.destroys);
    }
    shp_free(&s);
}

/* A program the backend does not build once, in the first frame: that frame fails with an error logged,
   and every later frame draws again, each of its passes with a program. FLOAT + ENGINE_DEPTH on the null
   backend in three configurations: 4x frames (the per-sample programs), single-sample frames that fit
   FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST (its faces and composite; later frames may read the depth per face),
   and half-resolution frames (the half-resolution composite, built again); the k-th create call of the
   first frame fails, for every k. (The per-sample set kept its gap and drew with program 0, with no
   error logged; a depth-tested or half-resolution composite that failed once failed every later frame.)
   The half-resolution frames: plain FLOAT (downsample takes no ENGINE_DEPTH). */
static void test_failed_builds_recover(void **state)
{
    static const char *const names[3] = {"4x", "depth-tested", "half resolution"};
    shp_mesh s = shp_box(1.0f, 1.0f, 1.0f);
    int cfg, k, f, i, failed, nfailed;
    (void)state;
    for (cfg = 0; cfg < 3; ++cfg) {
        for (k = 1, nfailed = 0; k <= 12; ++k) {
            fogvol_null_backend nb;
            fogvol_backend be;
            fogvol_logger lg;
            fogvol_context *fv;
            fogvol_mesh *box;
            fogvol_ramp *ramp;
            logcap lc;
            log_reset(&lc);
            lg = cap_logger(&lc);
            fogvol_null_backend_init(&nb, &be);
            be.caps |= FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_SOFTWARE_RENDERER | FOGVOL_CAP_MULTISAMPLE |
                       FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE;
            /* (half resolution: FLOAT without ENGINE_DEPTH) */
            ed_context_v(&be, &lg, cfg < 2 ? (unsigned)FOGVOL_VARIANT_ENGINE_DEPTH : 0u, &s, &fv, &box, &ramp);
            for (f = 0; f < 4; ++f) {
                fogvol_frame_desc fd;
                fogvol_volume_desc vd;
                fogvol_result r;
                a_frame_desc(&fd);
                fd.viewport[0] = fd.viewport[1] = 0;
                fd.engine_depth_texture = cfg < 2 ? 77 : 0;
                fd.downsample = cfg == 2 ? 2 : 0;
                nb.samples = cfg == 0 ? 4 : 0;
                memset(&vd, 0, sizeof vd);
                vd.mesh = box;
                vd.ramp = ramp;
                glu_identity(vd.model);
                assert_int_equal(fogvol_begin_frame(fv, &fd), FOGVOL_SUCCESS);
                assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
                nb.fail_create_at = f == 0 ? nb.create_calls + k : 0;
                lc.errors = 0;
                r = fogvol_end_frame(fv, NULL);
                if (f == 0) {
                    failed = r != FOGVOL_SUCCESS;
                    nfailed += failed;
                    if (failed && !lc.errors) fail_msg("%s, create %d: frame 0 %s, no error logged", names[cfg], k,
                                                      fogvol_result_string(r));
                    continue;
                }
                if (r != FOGVOL_SUCCESS || nb.pass_count < 2)
                    fail_msg("%s, create %d failed in frame 0: frame %d %s, %d passes (%s)", names[cfg], k, f,
                             fogvol_result_string(r), nb.pass_count, lc.count ? lc.msg[lc.count - 1] : "");
                for (i = 0; i < nb.pass_count; ++i)
                    if (!nb.passes[i].program)
                        fail_msg("%s, create %d failed in frame 0: frame %d pass %d has no program", names[cfg], k, f, i);
            }
            ed_free(fv, box, ramp);
            assert_int_equal(nb.creates, nb.destroys);
        }
        print_message("# %s: creates 1 .. 12 of the first frame failed in turn (%d of them failed the frame), every "
                      "later frame drawn\n", names[cfg], nfailed);
        assert_true(nfailed >= 2);
    }
    shp_free(&s);
}

int main(void)
{
    const struct CMUnitTest null_tests[] = {
        cmocka_unit_test(test_passes_of_a_frame_fullscreen),
        cmocka_unit_test(test_passes_of_a_frame_min_compare),
        cmocka_unit_test(test_depth_test_only_where_count_holds),
        cmocka_unit_test(test_vulkan_dialect_programs_and_passes),
        cmocka_unit_test(test_passes_of_a_frame_geometry),
        cmocka_unit_test(test_geometry_composite_under_scissor),
        cmocka_unit_test(test_negative_only_group_draws_nothing),
        cmocka_unit_test(test_frame_call_order),
        cmocka_unit_test(test_destroy_inside_frame_drops_its_users),
        cmocka_unit_test(test_encoding_refuses_inexact_sums),
        cmocka_unit_test(test_tier_choice_required_and_preferred),
        cmocka_unit_test(test_bad_input_code_and_log),
        cmocka_unit_test(test_transposed_and_singular_matrices),
        cmocka_unit_test(test_coarse_depth_lsb_warned),
        cmocka_unit_test(test_backend_create_faults),
        cmocka_unit_test(test_alloc_faults_context),
        cmocka_unit_test(test_alloc_faults_mesh_ramp),
        cmocka_unit_test(test_target_create_faults),
        cmocka_unit_test(test_downsample_half_resolution),
        cmocka_unit_test(test_targets_made_once_per_size),
        cmocka_unit_test(test_engine_depth_attached),
        cmocka_unit_test(test_engine_depth_no_rg32f),
        cmocka_unit_test(test_failed_builds_recover),
    };
    const struct CMUnitTest gl_tests[] = {
        cmocka_unit_test_setup_teardown(test_gl_missing_entry_core33, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_missing_entry_gl21, setup_compat, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_loader_finds_nothing, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_plain_loaders, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_dialect_choice_core, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_dialect_choice_compat, setup_compat, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_software_renderer, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_glsl100_renders_in_core, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_override21_renders, setup_compat, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_shader_compile_failure, setup_core, teardown_gl),
        cmocka_unit_test_setup_teardown(test_gl_alloc_faults, setup_core, teardown_gl),
    };
    int fails = 0;
    fails += cmocka_run_group_tests_name("null backend", null_tests, NULL, NULL);
    fails += cmocka_run_group_tests_name("GL backend (OSMesa)", gl_tests, NULL, NULL);
    return fails ? 1 : 0;
}
