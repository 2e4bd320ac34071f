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

enum { M_1, M_SS_SS, M_PP_SS, M_PP_PP, M_PP_PP0, M_RS, M_FLOOR1, M_FLOOR4, NM };
static const char *const mnames[NM] = {"1x tested", "4x faces per sample, comp per sample", "4x faces per pixel, comp per sample",
    "4x faces per pixel, comp per pixel avg T", "4x faces per pixel, comp per pixel no depth read", "4x: depth blit to 1x, 1x faces, comp per pixel into 4x", "floor 1x", "floor 4x (faces per pixel into 4x RGBA8, comp)"};

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
        double t[NM][64], tf[NM][64];
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
        for (it = 0; it < frames + 1; ++it)
            for (m = 0; m < NM; ++m) {
                int k2 = (m == M_1 || m == M_FLOOR1) ? 0 : 1;
                GLuint sf = sfbo[k2], su = sum[k2];
                double a, b, fpass;
                if (m == M_RS) { sf = g_rs_fbo; su = g_rs_sum; }
                if (m == M_FLOOR1) { sf = g_fl[1]; su = g_fl[0]; }
                if (m == M_FLOOR4) { sf = g_fl[3]; su = g_fl[2]; }
                a = frame(m, s, &vw, &fb[k2], sf, su, w, h, NULL);
                b = frame(m, s, &vw, &fb[k2], sf, su, w, h, &fpass);
                (void)b;
                if (it) { t[m][it - 1] = a; tf[m][it - 1] = fpass; }
                if (glGetError() != GL_NO_ERROR) { fprintf(stderr, "method %d\n", m); die("GL error (frame)"); }
            }
        for (m = 0; m < NM; ++m) {
            double a = median(t[m], frames), fp = median(tf[m], frames);
            printf("| %s | %s | %.2f ms | face pass %.2f | x1 %.2f |\n", m ? "" : s->name, mnames[m], a, fp, a / median(t[M_1], frames));
        }
        if (glGetError() != GL_NO_ERROR) die("GL error");
        engine_meshes_free(s);
        free(s);
    }
    return 0;
}
