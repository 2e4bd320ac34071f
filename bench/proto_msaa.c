/* proto_msaa.c - what MSAA 4x can cost on this renderer (issue 34, target 2: <= 2x single-sample),
   outside the library, on the benchmark's scenes (bench.c included), 640x360, the engine framebuffer of
   bench.c's MSAA section (colour renderbuffer + depth texture, 1 or 4 samples).

     1x tested        the single-sample FLOAT + engine depth design: the engine's depth attached to an
                      RG32F sum, faces (+-d, +-1) depth-tested, composite r - o g (the reference)
     4x ... per sample / per pixel
                      a 4x RG32F sum with the engine's 4x depth attached (the test per sample); the
                      faces shaded per sample or once per pixel; the composite per sample (exact), per
                      pixel averaging the samples' transmittance (exact only where the engine's colour
                      is the same over the pixel), or per pixel without the depth read (a bound)
     4x: depth blit to 1x ...
                      the engine's depth resolved to one sample per pixel (glBlitFramebuffer), the 1x
                      design on it, its composite per pixel into the 4x framebuffer: no per-sample
                      work at all (wrong at every edge: the least a hybrid could cost)
     floor 1x / 4x    the benchmark's floor (faces once with a constant colour, one composite) into a
                      1x and a 4x RGBA8 target
     hybrid           single-sample sums with per-sample work at the pixels whose depth samples differ
                      only: a resolve pass (the four samples' linear depths into RGBA32F, the farthest
                      sample's depth and a stencil bit where they differ into a depth-stencil buffer of
                      fogvol's own), the 1x design against the farthest sample, the faces again at the
                      stencilled pixels adding each sample's +-min(d - o_k, 0), then a per-pixel composite
                      where the samples agree and a per-sample one at the edge pixels: full-screen with a
                      discard, or as points that a vertex shader culls where the samples agree. Its
                      resolved colours are compared with the per-sample design's first (max, channels
                      that differ, mean, /255), and its stages are timed apart (bench/HISTORY.md).

   Fog ms after the engine's opaque pass, medians of interleaved frames; "face pass" a second timing
   of the same frame with a glFinish after the faces.
   usage: proto_msaa [frames]   (make proto-msaa) */
#define main bench_main
#include "bench.c"
#undef main

static const char *FS_TESTED = "#version 330 core\nin float vd; in float d;\nout vec4 o;\n"
                               "void main() { o = gl_FrontFacing ? vec4(-d, -1.0, 0.0, 0.0) : vec4(d, 1.0, 0.0, 0.0); }\n";
static const char *FS_TESTED_SS = "#version 330 core\n#extension GL_ARB_sample_shading : require\nin float vd; in float d;\nout vec4 o;\n"
                               "void main() { float e = float(gl_SampleID) * 0.0; o = gl_FrontFacing ? vec4(-d-e, -1.0, 0.0, 0.0) : vec4(d+e, 1.0, 0.0, 0.0); }\n";
#define LIN "  float w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z), od = (w - lin.w) / lin.z;\n"
static const char *FS_COMP_1 =
    "#version 330 core\nuniform sampler2D s, ez;\nuniform vec4 lin;\nuniform float range;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy);\n  vec2 v = texelFetch(s, c, 0).rg;\n"
    "  if (v == vec2(0.0)) discard;\n  float t = v.x;\n"
    "  if (v.y != 0.0) { float z = texelFetch(ez, c, 0).r;\n" LIN "    t -= min(od, 1.0) * v.y;\n  }\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";
static const char *FS_COMP_SS =
    "#version 330 core\n#extension GL_ARB_sample_shading : require\nuniform sampler2DMS s, ez;\nuniform vec4 lin;\nuniform float range;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy);\n  vec2 v = texelFetch(s, c, gl_SampleID).rg;\n"
    "  if (v == vec2(0.0)) discard;\n  float t = v.x;\n"
    "  if (v.y != 0.0) { float z = texelFetch(ez, c, gl_SampleID).r;\n" LIN "    t -= min(od, 1.0) * v.y;\n  }\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";
static const char *FS_COMP_PP =
    "#version 330 core\nuniform sampler2DMS s, ez;\nuniform vec4 lin;\nuniform float range;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy); float T = 0.0;\n"
    "  for (int i = 0; i < 4; ++i) { vec2 v = texelFetch(s, c, i).rg; float t = v.x;\n"
    "  if (v.y != 0.0) { float z = texelFetch(ez, c, i).r;\n" LIN "    t -= min(od, 1.0) * v.y;\n  }\n"
    "  T += exp(-0.5 * max(t * range, 0.0)); }\n"
    "  if (T == 4.0) discard;\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - 0.25 * T); }\n";
/* per pixel, no depth read at all: lower bound */
static const char *FS_COMP_PP0 =
    "#version 330 core\nuniform sampler2DMS s, ez;\nuniform vec4 lin;\nuniform float range;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy); float T = 0.0;\n"
    "  for (int i = 0; i < 4; ++i) { vec2 v = texelFetch(s, c, i).rg; float t = v.x - 0.5 * v.y;\n"
    "  T += exp(-0.5 * max(t * range, 0.0)); }\n"
    "  if (T == 4.0) discard;\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - 0.25 * T); }\n";

enum { M_1, M_SS_SS, M_PP_SS, M_PP_PP, M_PP_PP0, M_RS, M_FLOOR1, M_FLOOR4, M_HY1, M_HY2, NM };
static const char *const mnames[NM] = {"1x tested", "4x faces per sample, comp per sample", "4x faces per pixel, comp per sample",
    "4x faces per pixel, comp per pixel avg T", "4x faces per pixel, comp per pixel no depth read", "4x: depth blit to 1x, 1x faces, comp per pixel into 4x", "floor 1x", "floor 4x (faces per pixel into 4x RGBA8, comp)",
    "hybrid: 1x sums, edge pixels per sample (full-screen)", "hybrid: 1x sums, edge pixels per sample (points)"};

static GLuint g_ssdepth, g_ssdepth_fbo, floorface, floorcomp, floorcomp4;
static GLuint g_rs_sum, g_rs_fbo, g_fl[4];
static GLuint face_tt, face_ss, comp1, compss, comppp, comppp0;

static void setlin(GLuint prog, const scene *s)
{
    float n = s->znear, f = s->zfar;
    glUniform4f(glGetUniformLocation(prog, "lin"), 2.0f * f * n, f + n, f - n, n);
    glUniform1f(glGetUniformLocation(prog, "range"), f - n);
    glUniform1i(glGetUniformLocation(prog, "s"), 0);
    glUniform1i(glGetUniformLocation(prog, "ez"), 1);
}

/* ---- the hybrid: single-sample sums, per-sample work only at the pixels whose depth samples differ ---- */
#define LINK(zz, oo) "  { float z = " zz "; float w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z); " oo " = (w - lin.w) / lin.z; }\n"
static const char *FS_RESOLVE =
    "#version 330 core\n#extension GL_ARB_shader_stencil_export : require\nuniform sampler2DMS ez;\nuniform vec4 lin;\nout vec4 o;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy);\n"
    "  vec4 z = vec4(texelFetch(ez, c, 0).r, texelFetch(ez, c, 1).r, texelFetch(ez, c, 2).r, texelFetch(ez, c, 3).r);\n"
    "  vec4 w = lin.x / (lin.y - (2.0 * z - 1.0) * lin.z);\n"
    "  o = min((w - lin.w) / lin.z, vec4(1.0));\n"
    "  gl_FragDepth = max(max(z.x, z.y), max(z.z, z.w));\n"
    "  gl_FragStencilRefARB = all(equal(z, z.xxxx)) ? 0 : 1; }\n";
static const char *FS_EDGEFACES =
    "#version 330 core\nin float vd; in float d;\nuniform sampler2D sd;\nout vec4 o;\n"
    "void main() { vec4 od = texelFetch(sd, ivec2(gl_FragCoord.xy), 0);\n"
    "  o = (gl_FrontFacing ? -1.0 : 1.0) * min(vec4(d) - od, vec4(0.0)); }\n";
static const char *FS_HCOMP_A =
    "#version 330 core\nuniform sampler2D s, sd;\nout vec4 o;\nuniform vec4 lin;\nuniform float range;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy);\n  vec2 v = texelFetch(s, c, 0).rg; vec4 od = texelFetch(sd, c, 0);\n"
    "  if (v == vec2(0.0) || any(notEqual(od, od.xxxx))) discard;\n  float t = v.x - od.x * v.y;\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";
static const char *FS_HCOMP_B1 =
    "#version 330 core\n#extension GL_ARB_sample_shading : require\nuniform sampler2D s2, sd;\nout vec4 o;\nuniform vec4 lin;\nuniform float range;\n"
    "void main() { ivec2 c = ivec2(gl_FragCoord.xy); vec4 od = texelFetch(sd, c, 0);\n"
    "  if (all(equal(od, od.xxxx))) discard;\n  float t = texelFetch(s2, c, 0)[gl_SampleID];\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";
static const char *VS_HPOINTS =
    "#version 330 core\nuniform sampler2D sd;\nuniform ivec2 size;\nflat out ivec2 pc;\n"
    "void main() { ivec2 c = ivec2(gl_VertexID % size.x, gl_VertexID / size.x); pc = c;\n"
    "  vec4 od = texelFetch(sd, c, 0);\n"
    "  gl_PointSize = 1.0;\n"
    "  gl_Position = all(equal(od, od.xxxx)) ? vec4(2.0, 2.0, 2.0, 1.0)\n"
    "    : vec4((vec2(c) + 0.5) / vec2(size) * 2.0 - 1.0, 0.0, 1.0); }\n";
static const char *FS_HCOMP_B2 =
    "#version 330 core\n#extension GL_ARB_sample_shading : require\nuniform sampler2D s2;\nflat in ivec2 pc;\nout vec4 o;\nuniform vec4 lin;\nuniform float range;\n"
    "void main() { float t = texelFetch(s2, pc, 0)[gl_SampleID];\n"
    "  o = vec4(0.8, 0.8, 0.8, 1.0 - exp(-0.5 * max(t * range, 0.0))); }\n";

static double h_part[5][64]; static int h_it;
static GLuint h_sd, h_ds, h_s1, h_s2, h_fr, h_f1, h_f2, h_res, h_ef, h_ca, h_cb1, h_cb2, h_vao;

static void hy_setup(int w, int h)
{
    h_sd = tex2d(GL_RGBA32F, w, h, GL_RGBA, GL_FLOAT);
    h_s1 = tex2d(GL_RG32F, w, h, GL_RG, GL_FLOAT);
    h_s2 = tex2d(GL_RGBA32F, w, h, GL_RGBA, GL_FLOAT);
    h_ds = tex2d(GL_DEPTH24_STENCIL8, w, h, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8);
    h_fr = fbo2(h_sd, 0, 0);
    h_f1 = fbo2(h_s1, 0, 0);
    h_f2 = fbo2(h_s2, 0, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, h_fr);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, h_ds, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, h_f1);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, h_ds, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, h_f2);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, h_ds, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("hybrid fbo incomplete");
    if (!h_res) {
        h_res = prog1(VS_FULL, FS_RESOLVE);
        h_ef = prog1(VS_MESH, FS_EDGEFACES);
        h_ca = prog1(VS_FULL, FS_HCOMP_A);
        h_cb1 = prog1(VS_FULL, FS_HCOMP_B1);
        h_cb2 = prog1(VS_HPOINTS, FS_HCOMP_B2);
        glGenVertexArrays(1, &h_vao);
    }
}

static void hy_read(const msaa_fb *fb, GLuint fbo1, int w, int h, unsigned char *px)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fb->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo1);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

static void hy_tex(GLuint prog, const char *name, int unit, GLenum target, GLuint tex)
{
    glUniform1i(glGetUniformLocation(prog, name), unit);
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, tex);
}

/* with tf, a glFinish after each stage and its time in h_part */
#define HY_STAGE(k) do { if (tf) { glFinish(); h_part[k][h_it] = tick_ms(ts, tick_end()); ts = tick_start(); } } while (0)
/* points: 0 = the per-sample part full-screen, 1 = drawn as points at the edge pixels only */
static double hy_frame(int points, const scene *s, const view *vw, const msaa_fb *fb, int w, int h, double *tf)
{
    static const float zero[4] = {0, 0, 0, 0};
    GLuint cb = points ? h_cb2 : h_cb1;
    tick t0, ts;
    msaa_engine_pass(s, vw, fb, w, h);
    t0 = tick_start(); ts = t0;
    glBindFramebuffer(GL_FRAMEBUFFER, h_fr);
    glViewport(0, 0, w, h);
    glDisable(GL_BLEND); glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST); glDepthFunc(GL_ALWAYS); glDepthMask(GL_TRUE);
    glEnable(GL_STENCIL_TEST); glStencilFunc(GL_ALWAYS, 0, 0xff); glStencilOp(GL_REPLACE, GL_REPLACE, GL_REPLACE); glStencilMask(0xff);
    glUseProgram(h_res); setlin(h_res, s);
    hy_tex(h_res, "ez", 1, GL_TEXTURE_2D_MULTISAMPLE, fb->depth);
    glBindVertexArray(P.empty_vao); glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, 0);
    HY_STAGE(0);
    glStencilMask(0); glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    glDisable(GL_STENCIL_TEST);
    glDepthMask(GL_FALSE); glDepthFunc(GL_LESS);
    glEnable(GL_BLEND); glBlendFunc(GL_ONE, GL_ONE);
    /* pass 1: every pixel, single-sample, depth-tested against the farthest sample */
    glBindFramebuffer(GL_FRAMEBUFFER, h_f1);
    glClearBufferfv(GL_COLOR, 0, zero);
    glUseProgram(face_tt);
    draw_insts(s, vw, face_tt, 0);
    HY_STAGE(1);
    /* pass 2: the edge pixels (stencil 1), each sample's own min(d - o_k, 0) */
    glBindFramebuffer(GL_FRAMEBUFFER, h_f2);
    glClearBufferfv(GL_COLOR, 0, zero);
    glEnable(GL_STENCIL_TEST); glStencilFunc(GL_EQUAL, 1, 0xff);
    glUseProgram(h_ef);
    hy_tex(h_ef, "sd", 2, GL_TEXTURE_2D, h_sd);
    draw_insts(s, vw, h_ef, 0);
    glDisable(GL_STENCIL_TEST); glDisable(GL_DEPTH_TEST);
    HY_STAGE(2);
    if (tf) *tf = tick_ms(t0, tick_end());
    /* composite: per pixel where the samples agree, per sample at the edge pixels */
    glBindFramebuffer(GL_FRAMEBUFFER, fb->fbo);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(h_ca); setlin(h_ca, s);
    hy_tex(h_ca, "s", 0, GL_TEXTURE_2D, h_s1);
    hy_tex(h_ca, "sd", 2, GL_TEXTURE_2D, h_sd);
    glBindVertexArray(P.empty_vao); glDrawArrays(GL_TRIANGLES, 0, 3);
    HY_STAGE(3);
    glUseProgram(cb); setlin(cb, s);
    hy_tex(cb, "s2", 3, GL_TEXTURE_2D, h_s2);
    hy_tex(cb, "sd", 2, GL_TEXTURE_2D, h_sd);
    glEnable(GL_SAMPLE_SHADING); glMinSampleShading(1.0f);
    if (points) {
        glUniform2i(glGetUniformLocation(cb, "size"), w, h);
        glBindVertexArray(h_vao); glDrawArrays(GL_POINTS, 0, w * h);
    } else {
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_SAMPLE_SHADING);
    HY_STAGE(4);
    glBindVertexArray(0);
    hy_tex(cb, "s2", 3, GL_TEXTURE_2D, 0);
    hy_tex(cb, "sd", 2, GL_TEXTURE_2D, 0);
    hy_tex(cb, "s", 0, GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND); glDepthMask(GL_TRUE);
    glUseProgram(0);
    return tick_ms(t0, tick_end());
}

static double frame(int m, const scene *s, const view *vw, const msaa_fb *fb, GLuint sumfbo, GLuint sum, int w, int h, double *tf)
{
    static const float zero[4] = {0, 0, 0, 0};
    GLenum tt = (m == M_1 || m == M_FLOOR1) ? GL_TEXTURE_2D : GL_TEXTURE_2D_MULTISAMPLE;
    GLuint comp = m == M_1 ? comp1 : m == M_PP_PP ? comppp : m == M_PP_PP0 ? comppp0 : compss;
    tick t0, t1;
    msaa_engine_pass(s, vw, fb, w, h);
    t0 = tick_start();
    if (m == M_RS) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fb->fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g_ssdepth_fbo);
        glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        tt = GL_TEXTURE_2D; comp = comp1;
    }
    if (m == M_FLOOR1 || m == M_FLOOR4) {
        glBindFramebuffer(GL_FRAMEBUFFER, sumfbo);
        glViewport(0, 0, w, h);
        glClearBufferfv(GL_COLOR, 0, zero);
        glDisable(GL_CULL_FACE); glDisable(GL_DEPTH_TEST);
        glEnable(GL_BLEND); glBlendFunc(GL_ONE, GL_ONE);
        glUseProgram(floorface);
        draw_insts(s, vw, floorface, 0);
        if (tf) { glFinish(); t1 = tick_end(); *tf = tick_ms(t0, t1); }
        glBindFramebuffer(GL_FRAMEBUFFER, fb->fbo);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        comp = m == M_FLOOR1 ? floorcomp : floorcomp4;
        glUseProgram(comp);
        glUniform1i(glGetUniformLocation(comp, "s"), 0);
        glActiveTexture(GL_TEXTURE0); glBindTexture(tt, sum);
        glBindVertexArray(P.empty_vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glBindVertexArray(0);
        glBindTexture(tt, 0);
        glDisable(GL_BLEND);
        glUseProgram(0);
        return tick_ms(t0, tick_end());
    }
    glBindFramebuffer(GL_FRAMEBUFFER, sumfbo);
    glViewport(0, 0, w, h);
    glClearBufferfv(GL_COLOR, 0, zero);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glDepthMask(GL_FALSE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    if (m == M_SS_SS) { glEnable(GL_SAMPLE_SHADING); glMinSampleShading(1.0f); }
    glUseProgram(m == M_SS_SS ? face_ss : face_tt);
    draw_insts(s, vw, m == M_SS_SS ? face_ss : face_tt, 0);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SAMPLE_SHADING);
    if (tf) { glFinish(); t1 = tick_end(); *tf = tick_ms(t0, t1); }
    glBindFramebuffer(GL_FRAMEBUFFER, fb->fbo);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(comp);
    setlin(comp, s);
    glActiveTexture(GL_TEXTURE0); glBindTexture(tt, sum);
    glActiveTexture(GL_TEXTURE1); glBindTexture(tt, m == M_RS ? g_ssdepth : fb->depth);
    if (m == M_SS_SS || m == M_PP_SS) { glEnable(GL_SAMPLE_SHADING); glMinSampleShading(1.0f); }
    glBindVertexArray(P.empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDisable(GL_SAMPLE_SHADING);
    glActiveTexture(GL_TEXTURE1); glBindTexture(tt, 0);
    glActiveTexture(GL_TEXTURE0); glBindTexture(tt, 0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glUseProgram(0);
    return tick_ms(t0, tick_end());
}

int main(int argc, char **argv)
{
    static const int scenes[2] = {6, 0};
    int frames = argc > 1 ? atoi(argv[1]) : 9, sc, it, m, w = 640, h = 360;
    glu_ctx g;
    if (!glu_create(&g, 64, 64, 1)) die(BENCH_CONTEXT);
    clock_init();
    make_progs();
    face_tt = prog1(VS_MESH, FS_TESTED);
    face_ss = prog1(VS_MESH, FS_TESTED_SS);
    comp1 = prog1(VS_FULL, FS_COMP_1);
    compss = prog1(VS_FULL, FS_COMP_SS);
    comppp = prog1(VS_FULL, FS_COMP_PP);
    comppp0 = prog1(VS_FULL, FS_COMP_PP0);
    floorface = prog1(VS_MESH, FS_CONST);
    floorcomp = prog1(VS_FULL, "#version 330 core\nuniform sampler2D s;\nout vec4 o;\nvoid main() { vec4 v = texelFetch(s, ivec2(gl_FragCoord.xy), 0); if (v.r == 0.0) discard; o = vec4(0.8, 0.8, 0.8, v.r); }\n");
    floorcomp4 = prog1(VS_FULL, "#version 330 core\nuniform sampler2DMS s;\nout vec4 o;\nvoid main() { vec4 v = texelFetch(s, ivec2(gl_FragCoord.xy), 0); if (v.r == 0.0) discard; o = vec4(0.8, 0.8, 0.8, v.r); }\n");
    printf("%dx%d on %s\n", w, h, (const char *)glGetString(GL_RENDERER));
    for (sc = 0; sc < 2; ++sc) {
        scene *s = (scene *)calloc(1, sizeof(scene));
        view vw;
        msaa_fb fb[2];
        GLuint sum[2], sfbo[2];
        double t[NM][64], tf[NM][64], hp[2][5][64];
        build_scene(s, scenes[sc]);
        engine_meshes_upload(s);
        make_view(&vw, s, w, h);
        msaa_fb_create(&fb[0], w, h, 1);
        msaa_fb_create(&fb[1], w, h, 4);
        sum[0] = tex2d(GL_RG32F, w, h, GL_RG, GL_FLOAT);
        sfbo[0] = fbo2(sum[0], fb[0].depth, 0);
        glGenTextures(1, &sum[1]);
        glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, sum[1]);
        glTexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, 4, GL_RG32F, w, h, GL_TRUE);
        glGenFramebuffers(1, &sfbo[1]);
        glBindFramebuffer(GL_FRAMEBUFFER, sfbo[1]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D_MULTISAMPLE, sum[1], 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D_MULTISAMPLE, fb[1].depth, 0);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("ms sum incomplete");
        {
            GLuint c1, c4, f1, f4;
            g_ssdepth = fb[0].depth; /* stands in for fogvol's resolved copy (same format) */
            glGenTextures(1, &g_ssdepth);
            glBindTexture(GL_TEXTURE_2D, g_ssdepth);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, w, h, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, NULL);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            g_rs_sum = tex2d(GL_RG32F, w, h, GL_RG, GL_FLOAT);
            g_rs_fbo = fbo2(g_rs_sum, g_ssdepth, 0);
            glGenFramebuffers(1, &g_ssdepth_fbo);
            g_ssdepth_fbo = g_rs_fbo;
            c1 = tex2d(GL_RGBA8, w, h, GL_RGBA, GL_UNSIGNED_BYTE);
            f1 = fbo2(c1, 0, 0);
            glGenTextures(1, &c4);
            glBindTexture(GL_TEXTURE_2D_MULTISAMPLE, c4);
            glTexImage2DMultisample(GL_TEXTURE_2D_MULTISAMPLE, 4, GL_RGBA8, w, h, GL_TRUE);
            glGenFramebuffers(1, &f4);
            glBindFramebuffer(GL_FRAMEBUFFER, f4);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D_MULTISAMPLE, c4, 0);
            g_fl[0] = c1; g_fl[1] = f1; g_fl[2] = c4; g_fl[3] = f4;
            if (glGetError() != GL_NO_ERROR) die("GL error (setup)");
        }
        hy_setup(w, h);
        {   /* the hybrid against the per-sample design: resolved colours */
            unsigned char *ref = (unsigned char *)malloc((size_t)w * h * 4), *got = (unsigned char *)malloc((size_t)w * h * 4);
            int q, mx = 0, nd = 0, pts;
            long acc = 0;
            for (pts = 0; pts < 2; ++pts) {
                frame(M_PP_SS, s, &vw, &fb[1], sfbo[1], sum[1], w, h, NULL);
                hy_read(&fb[1], g_fl[1], w, h, ref);
                hy_frame(pts, s, &vw, &fb[1], w, h, NULL);
                hy_read(&fb[1], g_fl[1], w, h, got);
                mx = 0; nd = 0; acc = 0;
                for (q = 0; q < w * h * 4; ++q) {
                    int dd = abs(ref[q] - got[q]);
                    if (dd > mx) mx = dd;
                    if (dd) ++nd;
                    acc += dd;
                }
                printf("%s hybrid (%s) vs per-sample: max %d/255, %d channels differ, mean %.4f\n", s->name, pts ? "points" : "full-screen", mx, nd, (double)acc / (w * h * 4));
            }
            free(ref); free(got);
        }
        for (it = 0; it < frames + 1; ++it)
            for (m = 0; m < NM; ++m) {
                int k2 = (m == M_1 || m == M_FLOOR1) ? 0 : 1;
                GLuint sf = sfbo[k2], su = sum[k2];
                double a, b, fpass;
                if (m == M_RS) { sf = g_rs_fbo; su = g_rs_sum; }
                if (m == M_FLOOR1) { sf = g_fl[1]; su = g_fl[0]; }
                if (m == M_FLOOR4) { sf = g_fl[3]; su = g_fl[2]; }
                if (m >= M_HY1) {
                    a = hy_frame(m == M_HY2, s, &vw, &fb[1], w, h, NULL);
                    h_it = it ? it - 1 : 0;
                    b = hy_frame(m == M_HY2, s, &vw, &fb[1], w, h, &fpass);
                    if (it) { int q; for (q = 0; q < 5; ++q) hp[m - M_HY1][q][it - 1] = h_part[q][it - 1]; }
                } else {
                    a = frame(m, s, &vw, &fb[k2], sf, su, w, h, NULL);
                    b = frame(m, s, &vw, &fb[k2], sf, su, w, h, &fpass);
                }
                (void)b;
                if (it) { t[m][it - 1] = a; tf[m][it - 1] = fpass; }
                if (glGetError() != GL_NO_ERROR) { fprintf(stderr, "method %d\n", m); die("GL error (frame)"); }
            }
        for (m = 0; m < NM; ++m) {
            double a = median(t[m], frames), fp = median(tf[m], frames);
            printf("| %s | %s | %.2f ms | face pass %.2f | x1 %.2f |\n", m ? "" : s->name, mnames[m], a, fp, a / median(t[M_1], frames));
            if (m >= M_HY1)
                printf("|  |   stages: resolve %.2f, 1x faces %.2f, edge faces %.2f, composite per pixel %.2f, per sample %.2f |\n",
                       median(hp[m - M_HY1][0], frames), median(hp[m - M_HY1][1], frames), median(hp[m - M_HY1][2], frames),
                       median(hp[m - M_HY1][3], frames), median(hp[m - M_HY1][4], frames));
        }
        if (glGetError() != GL_NO_ERROR) die("GL error");
        engine_meshes_free(s);
        free(s);
    }
    return 0;
}
