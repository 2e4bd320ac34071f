/* proto_engine_depth.c - the FLOAT + engine depth face pass as it is against a depth-tested design
   (issue 34), outside the library, on the benchmark's scenes and engine pass (bench.c included).

     read      as fogvol draws it: every face fragment reads the engine's depth (texelFetch of
               the depth texture) and linearises it, then adds +-min(d, o) into an R32F sum
     tested    the engine's depth texture attached as the depth buffer of the sum's framebuffer
               (depth test LESS, no depth writes): only the faces in front of the opaque surface
               are shaded, adding (+-d, +-1) into an RG32F sum; the composite reads the engine's
               depth once per pixel where the sum is not empty and takes
               thickness = sum.r - o sum.g (the faces behind the opaque surface add +-o each, and
               their signs sum to -sum.g where every volume lies between the near and far planes)
     none      no opaque depth at all (plain FLOAT without occluders: the least the faces can cost)
     two       the faces twice against the attached depth: LESS adding +-d into an R32F sum, then
               GEQUAL adding +-o (read per fragment) for those behind the surface; the composite
               reads the sum alone (no depth read, no count; no closed-volume assumption)

   Each: one face pass + one full-screen composite (exp) into the engine framebuffer. Frames
   interleaved, medians; the thickness of "tested" against "read" over every pixel.
   usage: proto_engine_depth [frames]   (make proto-engine-depth) */
#define main bench_main
#include "bench.c"
#undef main

static const char *FS_READ =
    "#version 330 core\nin float vd; in float d;\nuniform sampler2D ez;\nuniform vec4 lin;\nout vec4 o;\n"
    "void main() { float z = texelFetch(ez, ivec2(gl_FragCoord.xy), 0).r;\n"
    "  float w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z), od = (w - lin.w) / lin.z;\n"
    "  float v = min(max(d, 0.0), od);\n"
    "  o = vec4(gl_FrontFacing ? -v : v, 0.0, 0.0, 0.0); }\n";
static const char *FS_TESTED = "#version 330 core\nin float vd; in float d;\nout vec4 o;\n"
                               "void main() { o = gl_FrontFacing ? vec4(-d, -1.0, 0.0, 0.0) : vec4(d, 1.0, 0.0, 0.0); }\n";
static const char *FS_NONE = "#version 330 core\nin float vd; in float d;\nout vec4 o;\n"
                             "void main() { o = vec4(gl_FrontFacing ? -d : d, 0.0, 0.0, 0.0); }\n";
static const char *FS_FAIL =
    "#version 330 core\nin float vd; in float d;\nuniform sampler2D ez;\nuniform vec4 lin;\nout vec4 o;\n"
    "void main() { float z = texelFetch(ez, ivec2(gl_FragCoord.xy), 0).r;\n"
    "  float w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z), od = (w - lin.w) / lin.z;\n"
    "  o = vec4(gl_FrontFacing ? -od : od, 0.0, 0.0, 0.0); }\n";
static const char *FS_COMP_R = "#version 330 core\nuniform sampler2D s;\nuniform float range;\nout vec4 o;\n"
                               "void main() { float t = texelFetch(s, ivec2(gl_FragCoord.xy), 0).r;\n"
                               "  if (t == 0.0) discard;\n"
                               "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";
static const char *FS_COMP_RG =
    "#version 330 core\nuniform sampler2D s, ez;\nuniform vec4 lin;\nuniform float range;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy);\n  vec2 v = texelFetch(s, c, 0).rg;\n"
    "  if (v == vec2(0.0)) discard;\n  float t = v.x;\n"
    "  if (v.y != 0.0) {\n" /* the engine's depth only where faces lie behind it */
    "    float z = texelFetch(ez, c, 0).r;\n"
    "    float w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z), od = (w - lin.w) / lin.z;\n"
    "    t -= min(od, 1.0) * v.y;\n  }\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";

enum { PM_READ, PM_TESTED, PM_NONE, PM_TWO, NPM };
static const char *const pm_names[NPM] = {"read per fragment (as now)", "depth-tested (proposed)",
                                          "no opaque depth (plain FLOAT, no occluders)", "two passes: LESS +-d, GEQUAL +-o read"};

typedef struct proto {
    GLuint face[NPM], comp_r, comp_rg, fail, fbo_rd;
    GLuint sum_r, sum_rg, fbo_r, fbo_rg;
} proto;

/* lin = (2 f n, f + n, f - n, n): w = lin.x / (lin.y - z_ndc lin.z); d = (w - n) / (f - n) */
static void set_lin(GLuint prog, const scene *s)
{
    float n = s->znear, f = s->zfar;
    glUniform4f(glGetUniformLocation(prog, "lin"), 2.0f * f * n, f + n, f - n, n);
    glUniform1f(glGetUniformLocation(prog, "range"), f - n);
}

static void proto_frame(proto *p, int m, const scene *s, const view *vw, const rt *r)
{
    static const float zero[4] = {0, 0, 0, 0};
    GLuint fbo = m == PM_TESTED ? p->fbo_rg : m == PM_TWO ? p->fbo_rd : p->fbo_r, comp = m == PM_TESTED ? p->comp_rg : p->comp_r;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, r->w, r->h);
    glClearBufferfv(GL_COLOR, 0, zero);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glDepthMask(GL_FALSE);
    if (m == PM_TESTED || m == PM_TWO) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
    }
    glUseProgram(p->face[m]);
    if (m == PM_READ) {
        bind_tex(0, r->eng_depth);
        glUniform1i(glGetUniformLocation(p->face[m], "ez"), 0);
        set_lin(p->face[m], s);
    }
    draw_insts(s, vw, p->face[m], 0);
    if (m == PM_TWO) {
        glDepthFunc(GL_GEQUAL);
        glUseProgram(p->fail);
        bind_tex(0, r->eng_depth); /* (read while attached, not written: fine on desktop GL) */
        glUniform1i(glGetUniformLocation(p->fail, "ez"), 0);
        set_lin(p->fail, s);
        draw_insts(s, vw, p->fail, 0);
        bind_tex(0, 0);
    }
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo); /* (its depth attachment: no depth test, no writes) */
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(comp);
    bind_tex(0, m == PM_TESTED ? p->sum_rg : p->sum_r);
    glUniform1i(glGetUniformLocation(comp, "s"), 0);
    if (m == PM_TESTED) {
        bind_tex(1, r->eng_depth);
        glUniform1i(glGetUniformLocation(comp, "ez"), 1);
    }
    set_lin(comp, s);
    glBindVertexArray(P.empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    bind_tex(1, 0);
    bind_tex(0, 0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glUseProgram(0);
}

/* thickness (units of the depth range) of "read" and of "tested" after their last frames */
static double proto_compare(proto *p, const scene *s, const rt *r, long *nonzero)
{
    size_t n = (size_t)r->w * r->h, i;
    float *a = (float *)malloc(n * 4), *b = (float *)malloc(n * 8), *z = (float *)malloc(n * 4);
    double mx = 0, fn = s->zfar, nn = s->znear;
    if (!a || !b || !z) die("out of memory");
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo_r);
    glReadPixels(0, 0, r->w, r->h, GL_RED, GL_FLOAT, a);
    glBindFramebuffer(GL_FRAMEBUFFER, p->fbo_rg);
    glReadPixels(0, 0, r->w, r->h, GL_RG, GL_FLOAT, b);
    glBindFramebuffer(GL_FRAMEBUFFER, r->eng_fbo);
    glReadPixels(0, 0, r->w, r->h, GL_DEPTH_COMPONENT, GL_FLOAT, z);
    *nonzero = 0;
    for (i = 0; i < n; ++i) {
        double w = 2 * fn * nn / (fn + nn - (2.0 * z[i] - 1.0) * (fn - nn)), od = (w - nn) / (fn - nn);
        double t = b[2 * i] - (od < 1 ? od : 1) * b[2 * i + 1], e = fabs(t - a[i]);
        *nonzero += a[i] != 0.0f;
        if (e > mx) mx = e;
    }
    free(a);
    free(b);
    free(z);
    return mx;
}

int main(int argc, char **argv)
{
    static const int scenes[5] = {0, 1, 5, 6, 7};
    int frames = argc > 1 ? atoi(argv[1]) : 9, sc, it, m, w = 1280, h = 720;
    glu_ctx g;
    proto p;
    if (frames < 1 || frames > 64) frames = 9;
    if (!glu_create(&g, 64, 64, 1)) die(BENCH_CONTEXT);
    clock_init();
    make_progs();
    p.face[PM_READ] = prog1(VS_MESH, FS_READ);
    p.face[PM_TESTED] = prog1(VS_MESH, FS_TESTED);
    p.face[PM_NONE] = prog1(VS_MESH, FS_NONE);
    p.face[PM_TWO] = prog1(VS_MESH, FS_NONE);
    p.fail = prog1(VS_MESH, FS_FAIL);
    p.comp_r = prog1(VS_FULL, FS_COMP_R);
    p.comp_rg = prog1(VS_FULL, FS_COMP_RG);
    printf("%dx%d on %s, medians of %d interleaved frames; fog ms = face pass + composite, after the engine's "
           "opaque pass\n\n| scene | method | fog ms | x no opaque depth | tested vs read: max |thickness diff| "
           "|\n|---|---|---:|---:|---|\n",
           w, h, (const char *)glGetString(GL_RENDERER), frames);
    for (sc = 0; sc < 5; ++sc) {
        scene *s = (scene *)calloc(1, sizeof(scene));
        rt r;
        view vw;
        double t[NPM][64], med[NPM], diff;
        char cell[64];
        long nz;
        if (!s) die("out of memory");
        build_scene(s, scenes[sc]);
        engine_meshes_upload(s);
        rt_create(&r, w, h);
        make_view(&vw, s, w, h);
        p.sum_r = tex2d(GL_R32F, w, h, GL_RED, GL_FLOAT);
        p.sum_rg = tex2d(GL_RG32F, w, h, GL_RG, GL_FLOAT);
        p.fbo_r = fbo2(p.sum_r, 0, 0);
        p.fbo_rg = fbo2(p.sum_rg, r.eng_depth, 0); /* the engine's depth texture as the depth buffer */
        p.fbo_rd = fbo2(p.sum_r, r.eng_depth, 0);
        for (it = 0; it < frames + 1; ++it)
            for (m = 0; m < NPM; ++m) {
                int mm = (m + it) % NPM;
                tick t0;
                engine_pass(s, &vw, &r, NULL);
                t0 = tick_start();
                proto_frame(&p, mm, s, &vw, &r);
                if (it) t[mm][it - 1] = tick_ms(t0, tick_end());
            }
        engine_pass(s, &vw, &r, NULL);
        proto_frame(&p, PM_READ, s, &vw, &r);
        proto_frame(&p, PM_TESTED, s, &vw, &r);
        diff = proto_compare(&p, s, &r, &nz);
        for (m = 0; m < NPM; ++m) med[m] = median(t[m], frames);
        snprintf(cell, sizeof cell, "%.2g of the depth range (%ld fogged pixels)", diff, nz);
        for (m = 0; m < NPM; ++m)
            printf("| %s | %s | %.2f | %.2f | %s |\n", m ? "" : s->name, pm_names[m], med[m], med[m] / med[PM_NONE],
                   m == PM_TESTED ? cell : "");
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &p.fbo_r);
        glDeleteFramebuffers(1, &p.fbo_rg);
        glDeleteFramebuffers(1, &p.fbo_rd);
        glDeleteTextures(1, &p.sum_r);
        glDeleteTextures(1, &p.sum_rg);
        rt_free(&r);
        engine_meshes_free(s);
        free(s);
    }
    if (glGetError() != GL_NO_ERROR) die("GL error");
    glu_destroy(&g);
    return 0;
}
