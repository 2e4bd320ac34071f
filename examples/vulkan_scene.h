/* vulkan_scene.h - the scene of examples/vulkan_backend.c, its picture, its self-check and its timing
   (included by vulkan_backend.c after the engine; not an example of anything an engine needs).

   The scene: two interlocked tori (concave volumes) and a sphere of fog, one colour ramp; a pillar
   that cuts the first torus and a ground slab as the engine's opaque scene. NFRAMES frames: the
   camera moves round and the pillar moves through the torus; in the last two the camera stands
   inside the sphere of fog, then inside the second torus's tube, its wall just past the near plane.

   The check, for every tier and variant the Vulkan backend runs (CONFIGS) and every frame:
     thickness  fogvol's debug read-back (fogvol_frame_desc.debug_thickness) against the ray caster
                (tests/raycast.h) at interior pixels: RGBA8 tiers within 1 LSB per pair of faces on
                the ray, FLOAT within 3e-5 of the depth range, plus what vertex snapping to
                the device's sub-pixel grid may move the faces (rc_depth_slope), as test_tiers does
     composite  the Vulkan picture against the GL backend's (OSMesa, llvmpipe) picture of the same
                frame, drawn over the same scene (the Vulkan engine's colour, and for ENGINE_DEPTH its
                depth, uploaded into GL): every pixel within 2/255
     outside    pixels whose rays meet no volume, and none near them: byte-equal to the scene
                without fog
   and the validation layers' messages: 0. */
#define GL_GLEXT_PROTOTYPES
#include "tests/gl_util.h"
#include "tests/raycast.h"

#define NFRAMES 5
enum { OBJ_TORUS_A, OBJ_TORUS_B, OBJ_SPHERE, OBJ_PILLAR, OBJ_GROUND, NOBJ };
#define NVOLUMES 3 /* the first three objects */

typedef struct scene {
    shp_mesh mesh[NOBJ];
    float model[NOBJ][16];
    rc_camera cam;
    float view[16], proj_vk[16], proj_01[16];
} scene;

static const float g_sky[4] = {0.35f, 0.45f, 0.6f, 1.0f};
static const float g_colors[NOBJ][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0.7f, 0.3f, 0.2f, 1.0f},
                                        {0.3f, 0.5f, 0.3f, 1.0f}};

static void scene_init(scene *s)
{
    memset(s, 0, sizeof *s);
    s->mesh[OBJ_TORUS_A] = shp_torus(1.1f, 0.4f, 48, 24);
    s->mesh[OBJ_TORUS_B] = shp_torus(0.8f, 0.3f, 40, 20);
    s->mesh[OBJ_SPHERE] = shp_sphere(1.6f, 32, 16);
    s->mesh[OBJ_PILLAR] = shp_box(0.25f, 1.5f, 0.25f);
    s->mesh[OBJ_GROUND] = shp_box(8.0f, 0.05f, 8.0f);
}

static void scene_free(scene *s)
{
    int i;
    for (i = 0; i < NOBJ; ++i) shp_free(&s->mesh[i]);
}

/* Frame k's camera and models; the picture is w x h. */
static void scene_frame(scene *s, int k, int w, int h)
{
    /* the last two: inside the sphere of fog; inside torus B's tube, whose wall is 0.3 ahead, between
       the near plane (0.2) and twice its distance */
    static const double eye[NFRAMES][3] = {
        {0.3, 2.4, 6.5}, {3.8, 2.6, 4.8}, {-4.2, 1.6, 4.4}, {-2.5, 1.35, 1.3}, {1.9, 1.2, 0.0}};
    static const float pillar_x[NFRAMES] = {-0.35f, 0.3f, 0.85f, 0.1f, 0.5f};
    float rot[16], tr[16];
    int i;
    shp_mat_rotate(rot, 90.0f, 1.0f, 0.0f, 0.0f); /* torus A lies flat (shp_torus is in the xy plane) */
    shp_mat_translate(tr, 0.0f, 1.2f, 0.0f);
    shp_mat_mul(s->model[OBJ_TORUS_A], tr, rot);
    shp_mat_translate(s->model[OBJ_TORUS_B], 1.1f, 1.2f, 0.0f); /* upright, through A's hole, round its tube */
    shp_mat_translate(s->model[OBJ_SPHERE], -2.6f, 1.2f, 1.0f);
    shp_mat_translate(s->model[OBJ_PILLAR], pillar_x[k], 1.5f, 0.1f);
    shp_mat_translate(s->model[OBJ_GROUND], 0.0f, -0.05f, 0.0f);
    memset(&s->cam, 0, sizeof s->cam);
    for (i = 0; i < 3; ++i) s->cam.eye[i] = eye[k][i];
    s->cam.target[0] = 0.2;
    s->cam.target[1] = k == NFRAMES - 1 ? 1.2 : 0.9;
    s->cam.up[1] = 1.0;
    s->cam.fovy_deg = 55.0;
    s->cam.aspect = (double)w / h;
    s->cam.znear = 0.2;
    s->cam.zfar = 20.0;
    s->cam.width = w;
    s->cam.height = h;
    rc_camera_matrices(&s->cam, s->view, s->proj_vk); /* (the GL projection, replaced below) */
    perspective01(s->proj_vk, (float)s->cam.fovy_deg, (float)s->cam.aspect, (float)s->cam.znear, (float)s->cam.zfar,
                  1);
    perspective01(s->proj_01, (float)s->cam.fovy_deg, (float)s->cam.aspect, (float)s->cam.znear, (float)s->cam.zfar,
                  0);
}

/* ---- fogvol on either backend ---- */

typedef struct config {
    const char *name;
    fogvol_tier tier;
    unsigned variants;
    fogvol_tier gl_tier; /* the GL picture's tier (0: the same; MRT: PS20, the GL engine here writes no O) */
    int depth_texture;   /* ENGINE_DEPTH from the engine's depth image as a texture (its view), not copied */
    int no_thickness;    /* no debug read-back (COLORS: one colour group, no thickness to read) */
    int refuse_inside;   /* COUNT: the frames with the camera inside a volume are refused, nothing drawn */
} config;

static const config g_configs[] = {
    {"FLOAT", FOGVOL_TIER_FLOAT, 0, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"FLOAT+engine depth (copy_depth)", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"FLOAT+engine depth (the engine's view)", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_TIER_AUTO, 1, 0, 0},
    {"FLOAT+colours (two RGBA32F targets)", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_COLORS, FOGVOL_TIER_AUTO, 0, 1, 0},
    {"PS20", FOGVOL_TIER_PS20, 0, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"PS20+engine depth (copy_depth)", FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"PS20+single target", FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"PS20+count (Baker's face count)", FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, FOGVOL_TIER_AUTO, 0, 0, 1},
    {"PS20+wide", FOGVOL_TIER_PS20, FOGVOL_VARIANT_WIDE, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"PS13", FOGVOL_TIER_PS13, 0, FOGVOL_TIER_AUTO, 0, 0, 0},
    {"MRT (the engine's pass writes O)", FOGVOL_TIER_MRT, 0, FOGVOL_TIER_PS20, 0, 0, 0},
    {"MRT+the engine's depth left read-only after its pass", FOGVOL_TIER_MRT, 0, FOGVOL_TIER_PS20, 1, 0, 0},
};
#define NCONFIGS ((int)(sizeof g_configs / sizeof g_configs[0]))

typedef struct fog {
    fogvol_context *fv;
    fogvol_mesh *mesh[NOBJ];
    fogvol_ramp *ramp;
} fog;

static int fog_create(fog *f, fogvol_context_desc *cd, const config *c, const scene *s)
{
    fogvol_ramp_desc rd;
    int i;
    memset(f, 0, sizeof *f);
    cd->tier = c->tier;
    cd->engine_mrt = c->tier == FOGVOL_TIER_MRT;
    cd->variants = c->variants;
    cd->disable_dither = 1; /* the thickness bound of test_tiers is for undithered sums */
    cd->logger.func = on_fogvol_log;
    if (fogvol_create_context(cd, &f->fv) != FOGVOL_SUCCESS) return 0;
    for (i = 0; i < NOBJ; ++i) {
        fogvol_mesh_desc md;
        memset(&md, 0, sizeof md);
        md.positions = s->mesh[i].pos;
        md.vertex_count = s->mesh[i].vcount;
        md.indices = (const uint32_t *)s->mesh[i].idx;
        md.index_count = s->mesh[i].icount;
        if (fogvol_create_mesh(f->fv, &md, &f->mesh[i], NULL) != FOGVOL_SUCCESS) return 0;
    }
    memset(&rd, 0, sizeof rd);
    rd.color[0] = 0.82f;
    rd.color[1] = 0.86f;
    rd.color[2] = 0.92f;
    rd.density = 0.7f;
    return fogvol_create_ramp(f->fv, &rd, &f->ramp) == FOGVOL_SUCCESS;
}

static void fog_destroy(fog *f)
{
    int i;
    for (i = 0; f->fv && i < NOBJ; ++i)
        if (f->mesh[i]) fogvol_destroy_mesh(f->fv, f->mesh[i]);
    if (f->ramp) fogvol_destroy_ramp(f->fv, f->ramp);
    if (f->fv) fogvol_destroy_context(f->fv);
    memset(f, 0, sizeof *f);
}

/* fogvol_begin_frame and the occluders: proj is the engine's projection; depth_texture non-zero: the
   engine's depth as a texture (GL), else with ENGINE_DEPTH the bound framebuffer's (Vulkan). The MRT
   tier draws no occluders: the engine's pass writes O. */
static fogvol_result fog_begin(fog *f, const scene *s, const float proj[16], fogvol_native depth_texture,
                               float *thickness)
{
    fogvol_frame_desc fd;
    unsigned variants = 0;
    fogvol_tier tier = fogvol_context_tier(f->fv, &variants);
    int i;
    fogvol_result r;
    memset(&fd, 0, sizeof fd);
    memcpy(fd.view, s->view, 64);
    memcpy(fd.projection, proj, 64);
    fd.znear = (float)s->cam.znear;
    fd.zfar = (float)s->cam.zfar;
    fd.viewport[2] = s->cam.width;
    fd.viewport[3] = s->cam.height;
    fd.debug_thickness = thickness;
    fogvol_context_tier(f->fv, &variants);
    if (variants & FOGVOL_VARIANT_ENGINE_DEPTH) {
        fd.engine_depth_texture = depth_texture;
        fd.engine_depth_source = depth_texture ? FOGVOL_DEPTH_SOURCE_TEXTURE : FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;
        fd.engine_depth_zero_to_one = 1; /* the engine's projection maps depth to [0, 1] */
    }
    r = fogvol_begin_frame(f->fv, &fd);
    for (i = OBJ_PILLAR; r == FOGVOL_SUCCESS && i < NOBJ && !(variants & FOGVOL_VARIANT_ENGINE_DEPTH) &&
                         tier != FOGVOL_TIER_MRT;
         ++i)
        r = fogvol_add_occluder(f->fv, f->mesh[i], s->model[i]);
    return r;
}

/* The volumes and fogvol_end_frame. */
static fogvol_result fog_finish(fog *f, const scene *s, fogvol_frame_stats *st)
{
    fogvol_result r = FOGVOL_SUCCESS;
    int i;
    for (i = 0; r == FOGVOL_SUCCESS && i < NVOLUMES; ++i) {
        fogvol_volume_desc vd;
        memset(&vd, 0, sizeof vd);
        vd.mesh = f->mesh[i];
        vd.ramp = f->ramp;
        memcpy(vd.model, s->model[i], 64);
        r = fogvol_add_volume(f->fv, &vd);
    }
    return r == FOGVOL_SUCCESS ? fogvol_end_frame(f->fv, st) : r;
}

/* ---- the Vulkan engine's frame ---- */

typedef struct vk_side {
    engine e;
    fogvol_backend be;
    engine_mesh mesh[NOBJ];
    int depth_texture; /* hand fogvol the engine's depth image view (config.depth_texture) */
} vk_side;

static int vk_side_init(vk_side *v, int w, int h, int validation, const scene *s)
{
    fogvk_desc d;
    int i;
    memset(v, 0, sizeof *v); /* (depth_texture 0: the picture and the timing set nothing else) */
    engine_init(&v->e, w, h, validation);
    memset(&d, 0, sizeof d);
    d.instance = v->e.instance;
    d.physical_device = v->e.pd;
    d.device = v->e.dev;
    d.frames_in_flight = FRAMES_IN_FLIGHT;
    d.logger.func = on_fogvol_log;
    if (fogvk_create(&d, &v->be) != FOGVOL_SUCCESS) return 0;
    for (i = OBJ_PILLAR; i < NOBJ; ++i) engine_mesh_upload(&v->e, &s->mesh[i], &v->mesh[i]);
    return 1;
}

static void vk_side_free(vk_side *v)
{
    int i;
    vkDeviceWaitIdle(v->e.dev);
    for (i = OBJ_PILLAR; i < NOBJ; ++i) engine_mesh_free(&v->e, &v->mesh[i]);
    v->be.destroy(v->be.user_data);
    engine_destroy(&v->e);
}

/* The engine's frame: its scene (copied to read-back region 0, with its depth), then fogvol (f NULL:
   no fog), then the picture (region 1); submitted and, with wait, waited for (else up to
   FRAMES_IN_FLIGHT frames run at once). The MRT tier: fogvol_begin_frame and fogvol_mrt_prepare come
   before the engine's pass, which writes fogvol's O as its second output.
   fogvk_set_frame once, first: it starts the frame in its slot (frees what fogvol let go of in the
   slot's previous frame, rewinds its uniforms), and fogvol_mrt_prepare already records into cmd (the
   textures' uploads, whose staging buffers this frame's commands read); so the frame's description
   says from the start the layouts the engine's images will be in when fogvol_end_frame records. */
static fogvol_result vk_frame_async(vk_side *v, fog *f, const scene *s, float *thickness, fogvol_frame_stats *st,
                                    int wait)
{
    engine *e = &v->e;
    VkCommandBuffer cmd = engine_begin(e);
    engine_draw draws[2];
    engine_mrt mrt;
    fogvk_frame fr;
    fogvol_result r = FOGVOL_SUCCESS;
    int i, is_mrt = f && fogvol_context_tier(f->fv, NULL) == FOGVOL_TIER_MRT;
    for (i = 0; i < 2; ++i) {
        float vp[16], mv[16];
        draws[i].mesh = &v->mesh[OBJ_PILLAR + i];
        shp_mat_mul(vp, s->proj_vk, s->view);
        shp_mat_mul(draws[i].mvp, vp, s->model[OBJ_PILLAR + i]);
        shp_mat_mul(mv, s->view, s->model[OBJ_PILLAR + i]);
        draws[i].view_z[0] = mv[2];
        draws[i].view_z[1] = mv[6];
        draws[i].view_z[2] = mv[10];
        draws[i].view_z[3] = mv[14];
        memcpy(draws[i].color, g_colors[OBJ_PILLAR + i], 16);
    }
    if (f) {
        engine_frame_desc(e, cmd, &fr);
        if (v->depth_texture) fr.depth_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL; /* (the barrier below) */
        fogvk_set_frame(&v->be, &fr); /* fogvol records into cmd */
    }
    if (is_mrt) {
        fogvol_mrt_info mi;
        r = fog_begin(f, s, s->proj_vk, 0, thickness);
        if (r == FOGVOL_SUCCESS) r = fogvol_mrt_prepare(f->fv, &mi);
        if (r == FOGVOL_SUCCESS) r = fogvk_engine_attachment(&v->be, cmd, mi.texture);
        if (r != FOGVOL_SUCCESS) return r;
        mrt.view = (VkImageView)mi.texture;
        mrt.format = fogvol_vk_format(mi.format);
        memcpy(mrt.clear, mi.clear_color, sizeof mrt.clear);
        memcpy(mrt.uniforms, mi.uniforms, sizeof mrt.uniforms);
    }
    engine_draw_scene(e, cmd, draws, 2, g_sky, is_mrt ? &mrt : NULL);
    engine_record_readback(e, cmd, 0, 1);
    if (f && v->depth_texture) { /* the engine's depth as a texture: sampled, its writes visible */
        barrier(cmd, e->depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                VK_ACCESS_SHADER_READ_BIT);
    }
    if (f) {
        if (!is_mrt) r = fog_begin(f, s, s->proj_vk, v->depth_texture ? (fogvol_native)e->depth_view : 0, thickness);
        if (r == FOGVOL_SUCCESS) r = fog_finish(f, s, st);
        cmd = fogvk_frame_command(&v->be); /* (the debug read-back flushed the first one) */
    }
    engine_record_readback(e, cmd, 1, 0);
    engine_submit(e, cmd);
    if (wait) engine_wait(e);
    return r;
}

static fogvol_result vk_frame(vk_side *v, fog *f, const scene *s, float *thickness, fogvol_frame_stats *st)
{
    return vk_frame_async(v, f, s, thickness, st, 1);
}

/* ---- the GL backend's picture of the same frame (OSMesa) ---- */

/* Framebuffer 0 = the Vulkan scene's colour (rows flipped: GL's row 0 is the bottom); with depth,
   a depth texture of the Vulkan engine's depth for ENGINE_DEPTH. Returns that texture (or 0). */
static GLuint gl_engine_scene(const unsigned char *color, const float *depth, int w, int h)
{
    GLuint tex, fbo, dtex = 0;
    unsigned char *c = (unsigned char *)malloc((size_t)w * h * 4);
    float *d = depth ? (float *)malloc((size_t)w * h * 4) : NULL;
    int y;
    for (y = 0; y < h; ++y) {
        memcpy(c + (size_t)(h - 1 - y) * w * 4, color + (size_t)y * w * 4, (size_t)w * 4);
        if (d) memcpy(d + (size_t)(h - 1 - y) * w, depth + (size_t)y * w, (size_t)w * 4);
    }
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, c);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    if (d) {
        glGenTextures(1, &dtex);
        glBindTexture(GL_TEXTURE_2D, dtex);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, w, h, 0, GL_DEPTH_COMPONENT, GL_FLOAT, d);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    free(c);
    free(d);
    return dtex;
}

/* The GL picture in the Vulkan picture's row order (row 0 at the top of the view). */
static fogvol_result gl_frame(glu_ctx *g, fog *f, const scene *s, const unsigned char *color, const float *depth,
                              unsigned char *out)
{
    unsigned variants = 0;
    GLuint dtex;
    fogvol_result r;
    int y, w = s->cam.width, h = s->cam.height;
    const unsigned char *px;
    fogvol_context_tier(f->fv, &variants);
    dtex = gl_engine_scene(color, (variants & FOGVOL_VARIANT_ENGINE_DEPTH) ? depth : NULL, w, h);
    r = fog_begin(f, s, s->proj_01, dtex, NULL); /* GL's rows: the projection does not flip y */
    if (r == FOGVOL_SUCCESS) r = fog_finish(f, s, NULL);
    px = glu_pixels(g);
    for (y = 0; y < h; ++y) memcpy(out + (size_t)y * w * 4, px + (size_t)(h - 1 - y) * w * 4, (size_t)w * 4);
    if (dtex) glDeleteTextures(1, &dtex);
    return r;
}

/* ---- ground truth ---- */

typedef struct truth {
    double *gt, *slope;
    int *pairs;
    unsigned char *interior, *covered;
} truth;

/* Per pixel of GL's row order (py = 0 at the bottom): thickness, pairs, interior, covered, slope. */
static void truth_compute(truth *t, const scene *s)
{
    rc_object o[NOBJ];
    rc_scene rs;
    int i, x, y, w = s->cam.width, h = s->cam.height;
    for (i = 0; i < NOBJ; ++i) {
        o[i].pos = s->mesh[i].pos;
        o[i].vcount = s->mesh[i].vcount;
        o[i].idx = s->mesh[i].idx;
        o[i].icount = s->mesh[i].icount;
        memcpy(o[i].model, s->model[i], 64);
        o[i].sign = i < NVOLUMES ? 1 : 0;
    }
    if (!rc_scene_init(&rs, o, NOBJ)) exit(1);
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            rc_result r = rc_trace(&rs, &s->cam, x + 0.5, y + 0.5);
            int k = y * w + x;
            t->gt[k] = r.thickness;
            t->pairs[k] = r.faces_front > r.faces_back ? r.faces_front : r.faces_back;
            if (t->pairs[k] < 1) t->pairs[k] = 1;
            t->covered[k] = r.faces_front + r.faces_back > 0;
            t->interior[k] = (unsigned char)rc_interior(&rs, &s->cam, x, y);
            t->slope[k] = t->interior[k] ? rc_depth_slope(&rs, &s->cam, x, y) : 0.0;
        }
    rc_scene_free(&rs);
}

/* ---- the check ---- */

typedef struct result {
    double max_err, sum_err;  /* thickness error in bound units (LSB per pair, or 3e-5 of the range) */
    int compared, bad;        /* interior pixels compared; over the bound */
    int comp_max, comp_over;  /* composite vs GL: largest byte difference, pixels over 2 */
    int outside, outside_bad; /* pixels away from every volume; not byte-equal to the scene */
    int frames_failed;
    int depth_tested, refused; /* frames drawn with the faces depth-tested; refused as documented */
} result;

static void compare_frame(result *res, const config *c, const scene *s, const truth *t, const float *thick,
                          const unsigned char *scene_px, const unsigned char *vk_px, const unsigned char *gl_px,
                          double snap)
{
    int w = s->cam.width, h = s->cam.height, x, y, ch;
    double range = s->cam.zfar - s->cam.znear, lsb;
    fogvol_encoding enc;
    fogvol_encoding_init(FOGVOL_DEFAULT_BITS, &enc);
    lsb = c->tier == FOGVOL_TIER_FLOAT ? 3e-5 * range
          : range / pow(2.0, ((c->variants & FOGVOL_VARIANT_WIDE) ? 6.0 : 3.0) *
                                  ((c->variants & FOGVOL_VARIANT_WIDE) ? FOGVOL_WIDE_EXACT_BITS : enc.bits));
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) {
            int k = (h - 1 - y) * w + x; /* the ray caster's pixel of Vulkan row y */
            int i = y * w + x, d = 0;
            for (ch = 0; ch < 4; ++ch) {
                int dd = abs((int)vk_px[i * 4 + ch] - (int)gl_px[i * 4 + ch]);
                if (dd > d) d = dd;
            }
            if (d > res->comp_max) res->comp_max = d;
            res->comp_over += d > 2;
            if (t->interior[k] && !t->covered[k]) {
                res->outside++;
                res->outside_bad += memcmp(vk_px + i * 4, scene_px + i * 4, 4) != 0;
            }
            if (t->interior[k] && thick) {
                double err = fabs(thick[i] - t->gt[k]) / lsb;
                double bound = (c->tier == FOGVOL_TIER_FLOAT ? 1.0 : t->pairs[k] + 1e-6 * range / lsb) +
                               t->slope[k] * snap / lsb;
                double per = c->tier == FOGVOL_TIER_FLOAT ? err : err / t->pairs[k];
                if (per > res->max_err) res->max_err = per;
                res->sum_err += per;
                res->compared++;
                if (err > bound) {
                    if (res->bad < 3)
                        printf("#   %s pixel (%d,%d): %.5f, ray cast %.5f (%.2f units, bound %.2f)\n", c->name, x, y,
                               thick[i], t->gt[k], err, bound);
                    res->bad++;
                }
            }
        }
}

static int run_check(void)
{
    enum { CW = 160, CH = 120 };
    scene s;
    vk_side v;
    glu_ctx g;
    truth t[NFRAMES];
    unsigned char *vk_px = (unsigned char *)malloc(CW * CH * 4), *gl_px = (unsigned char *)malloc(CW * CH * 4);
    unsigned char *scene_px = (unsigned char *)malloc(CW * CH * 4);
    float *depth = (float *)malloc(CW * CH * 4), *thick = (float *)malloc(CW * CH * 4);
    VkPhysicalDeviceProperties props;
    int ci, k, failed = 0, n = 0, messages;
    double snap;
    scene_init(&s);
    if (!vk_side_init(&v, CW, CH, 1, &s) || !glu_create(&g, CW, CH, 1)) {
        printf("not ok 1 - Vulkan device or OSMesa context\n");
        return 1;
    }
    vkGetPhysicalDeviceProperties(v.e.pd, &props);
    snap = ldexp(1.0, -(int)props.limits.subPixelPrecisionBits);
    printf("# %s, Vulkan %u.%u, %dx%d, %d frames; validation layers %s\n", props.deviceName,
           VK_API_VERSION_MAJOR(props.apiVersion), VK_API_VERSION_MINOR(props.apiVersion), CW, CH, NFRAMES,
           v.e.validation ? "on" : "NOT INSTALLED");
    for (k = 0; k < NFRAMES; ++k) {
        t[k].gt = (double *)calloc(CW * CH, sizeof(double));
        t[k].slope = (double *)calloc(CW * CH, sizeof(double));
        t[k].pairs = (int *)calloc(CW * CH, sizeof(int));
        t[k].interior = (unsigned char *)calloc(CW * CH, 1);
        t[k].covered = (unsigned char *)calloc(CW * CH, 1);
        scene_frame(&s, k, CW, CH);
        truth_compute(&t[k], &s);
    }
    for (ci = 0; ci < NCONFIGS; ++ci) {
        const config *c = &g_configs[ci];
        fogvol_context_desc vcd, gcd;
        fog fv, fg;
        result res;
        config gl_c;
        fogvol_frame_stats last;
        unsigned variants = 0;
        int in_flight_diff = 0;
        fogvol_tier tier;
        memset(&res, 0, sizeof res);
        memset(&last, 0, sizeof last);
        memset(&vcd, 0, sizeof vcd);
        vcd.backend = v.be;
        memset(&gcd, 0, sizeof gcd);
        gcd.gl.get_proc_address = glu_proc;
        v.depth_texture = c->depth_texture;
        gl_c = *c;
        if (c->gl_tier) gl_c.tier = c->gl_tier;
        if (!fog_create(&fv, &vcd, c, &s) || !fog_create(&fg, &gcd, &gl_c, &s)) {
            printf("not ok %d - %s: context\n", ++n, c->name);
            failed++;
            fog_destroy(&fv);
            fog_destroy(&fg);
            continue;
        }
        for (k = 0; k < NFRAMES; ++k) { /* one context each, over the whole sequence */
            fogvol_frame_stats st;
            fogvol_result rv, rg;
            int before = res.bad + res.comp_over + res.outside_bad;
            scene_frame(&s, k, CW, CH);
            memset(&st, 0, sizeof st);
            rv = vk_frame(&v, &fv, &s, c->no_thickness ? NULL : thick, &st);
            memcpy(scene_px, v.e.readback_map, CW * CH * 4);
            memcpy(vk_px, v.e.readback_map + CW * CH * 4, CW * CH * 4);
            memcpy(depth, v.e.readback_map + CW * CH * 8, CW * CH * 4);
            rg = gl_frame(&g, &fg, &s, scene_px, depth, gl_px);
            if (c->refuse_inside && k >= NFRAMES - 2) { /* refused on both backends, nothing drawn */
                if (rv != FOGVOL_ERROR_UNSUPPORTED || rg != FOGVOL_ERROR_UNSUPPORTED ||
                    memcmp(vk_px, scene_px, CW * CH * 4) != 0)
                    res.frames_failed++;
                res.refused++;
                continue;
            }
            if (rv != FOGVOL_SUCCESS || rg != FOGVOL_SUCCESS) {
                printf("#   %s frame %d: Vulkan %s, GL %s\n", c->name, k, fogvol_result_string(rv),
                       fogvol_result_string(rg));
                res.frames_failed++;
                continue;
            }
            compare_frame(&res, c, &s, &t[k], c->no_thickness ? NULL : thick, scene_px, vk_px, gl_px, snap);
            last = st;
            res.depth_tested += st.depth_tested;
            if (res.bad + res.comp_over + res.outside_bad > before) res.frames_failed++;
        }
        /* the same sequence again with FRAMES_IN_FLIGHT frames running at once (no debug read-back): the
           last picture byte-equal to the one drawn waiting for each frame */
        for (k = 0; k < NFRAMES && !res.frames_failed; ++k) {
            scene_frame(&s, k, CW, CH);
            if (vk_frame_async(&v, &fv, &s, NULL, NULL, 0) != FOGVOL_SUCCESS && !(c->refuse_inside && k >= NFRAMES - 2))
                res.frames_failed++;
        }
        engine_wait(&v.e);
        in_flight_diff = memcmp(vk_px, v.e.readback_map + CW * CH * 4, CW * CH * 4) != 0;
        res.frames_failed += in_flight_diff;
        tier = fogvol_context_tier(fv.fv, &variants);
        if (tier != c->tier || (variants & c->variants) != c->variants) res.frames_failed++;
        printf("#   %s: tier %s, variants 0x%x, %d passes in the last frame drawn, %d frames with the faces "
               "depth-tested, %d refused (camera inside: COUNT), overflow count %d (occlusion queries, frame %d)\n",
               c->name, fogvol_tier_name(tier), variants, last.passes, res.depth_tested, res.refused,
               last.overflow_pixels_late, (int)last.overflow_frame);
        fog_destroy(&fv);
        fog_destroy(&fg);
        printf("%s %d - %s: %d frames; thickness vs ray cast: max %.3f, mean %.3f %s (%d interior pixels, %d over "
               "the bound); composite vs GL: max %d/255, %d pixels over 2; outside the volumes: %d of %d pixels "
               "differ from the scene; %d frames in flight: last picture %s\n",
               res.frames_failed ? "not ok" : "ok", ++n, c->name, NFRAMES, res.max_err,
               res.compared ? res.sum_err / res.compared : 0.0,
               c->no_thickness                ? "(no read-back: one colour group)"
               : c->tier == FOGVOL_TIER_FLOAT ? "x 3e-5 of the range"
                                              : "LSB per pair of faces",
               res.compared, res.bad,
               res.comp_max, res.comp_over, res.outside_bad, res.outside, FRAMES_IN_FLIGHT,
               in_flight_diff ? "DIFFERS" : "the same");
        failed += res.frames_failed != 0;
    }
    vk_side_free(&v);
    glu_destroy(&g);
    messages = report_validation_count();
    printf("%s %d - validation layers: %d messages\n", messages || !v.e.validation ? "not ok" : "ok", ++n, messages);
    failed += messages != 0 || !v.e.validation;
    printf("1..%d\n", n);
    for (k = 0; k < NFRAMES; ++k) {
        free(t[k].gt);
        free(t[k].slope);
        free(t[k].pairs);
        free(t[k].interior);
        free(t[k].covered);
    }
    free(vk_px);
    free(gl_px);
    free(scene_px);
    free(depth);
    free(thick);
    scene_free(&s);
    return failed != 0;
}

/* ---- the picture (make vulkan) ---- */

static int render_picture(fogvol_tier tier, const char *path)
{
    scene s;
    vk_side v;
    fog f;
    fogvol_context_desc cd;
    config c = {"picture", FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_TIER_AUTO, 0, 0, 0};
    int rc, messages;
    c.tier = tier;
    if (tier != FOGVOL_TIER_FLOAT && tier != FOGVOL_TIER_PS20) c.variants = 0;
    scene_init(&s);
    scene_frame(&s, 0, 640, 360);
    if (!vk_side_init(&v, 640, 360, 1, &s)) return 1;
    memset(&cd, 0, sizeof cd);
    cd.backend = v.be;
    rc = !fog_create(&f, &cd, &c, &s);
    if (!rc) rc = vk_frame(&v, &f, &s, NULL, NULL) != FOGVOL_SUCCESS;
    if (!rc) rc = stbi_write_png(path, 640, 360, 4, v.e.readback_map + 640 * 360 * 4, 640 * 4) ? 0 : 1;
    fog_destroy(&f);
    vk_side_free(&v);
    messages = report_validation_count();
    printf("vulkan: %s %s, %d validation messages\n", fogvol_tier_name(tier), rc ? "failed" : path, messages);
    scene_free(&s);
    return rc || messages;
}

/* ---- timing: this backend on lavapipe beside the GL backend on llvmpipe ---- */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int run_bench(void)
{
    enum { BW = 640, BH = 360, FRAMES = 20 };
    static const int which[2] = {0, 2}; /* FLOAT, PS20 */
    scene s;
    vk_side v;
    glu_ctx g;
    unsigned char *px = (unsigned char *)malloc(BW * BH * 4), *gl_px = (unsigned char *)malloc(BW * BH * 4);
    float *depth = (float *)malloc(BW * BH * 4);
    int i, k;
    scene_init(&s);
    scene_frame(&s, 0, BW, BH);
    if (!vk_side_init(&v, BW, BH, 0, &s) || !glu_create(&g, BW, BH, 1)) return 1;
    printf("%dx%d, frame 0 of the check's scene, %d frames each, milliseconds per frame (median of 3 runs)\n", BW, BH,
           FRAMES);
    for (i = 0; i < 2; ++i) {
        const config *c = &g_configs[which[i]];
        fogvol_context_desc vcd, gcd;
        fog fv, fg;
        double tv[3], tg[3], tv0[3], tg0[3], t0;
        int run;
        memset(&vcd, 0, sizeof vcd);
        vcd.backend = v.be;
        memset(&gcd, 0, sizeof gcd);
        gcd.gl.get_proc_address = glu_proc;
        if (!fog_create(&fv, &vcd, c, &s) || !fog_create(&fg, &gcd, c, &s)) return 1;
        vk_frame(&v, &fv, &s, NULL, NULL); /* warm-up: programs, pipelines */
        memcpy(px, v.e.readback_map, BW * BH * 4);
        gl_frame(&g, &fg, &s, px, depth, gl_px);
        for (run = 0; run < 3; ++run) {
            t0 = now_ms();
            for (k = 0; k < FRAMES; ++k) vk_frame(&v, NULL, &s, NULL, NULL);
            tv0[run] = (now_ms() - t0) / FRAMES;
            t0 = now_ms();
            for (k = 0; k < FRAMES; ++k) vk_frame(&v, &fv, &s, NULL, NULL);
            tv[run] = (now_ms() - t0) / FRAMES;
            t0 = now_ms();
            for (k = 0; k < FRAMES; ++k) { /* the scene upload alone (gl_frame's first step) */
                gl_engine_scene(px, NULL, BW, BH);
                glFinish();
            }
            tg0[run] = (now_ms() - t0) / FRAMES;
            t0 = now_ms();
            for (k = 0; k < FRAMES; ++k) gl_frame(&g, &fg, &s, px, depth, gl_px);
            tg[run] = (now_ms() - t0) / FRAMES;
        }
#define MED3(a) ((a)[0] + (a)[1] + (a)[2] - fmin(fmin((a)[0], (a)[1]), (a)[2]) - fmax(fmax((a)[0], (a)[1]), (a)[2]))
        printf("%s: Vulkan (lavapipe) %.2f ms, of which the engine's scene and read-back %.2f: fog %.2f ms | "
               "GL (llvmpipe) %.2f ms, of which the scene upload %.2f: fog %.2f ms | Vulkan/GL fog %.2f\n",
               c->name, MED3(tv), MED3(tv0), MED3(tv) - MED3(tv0), MED3(tg), MED3(tg0), MED3(tg) - MED3(tg0),
               (MED3(tv) - MED3(tv0)) / (MED3(tg) - MED3(tg0)));
        fog_destroy(&fv);
        fog_destroy(&fg);
    }
    vk_side_free(&v);
    glu_destroy(&g);
    free(px);
    free(gl_px);
    free(depth);
    scene_free(&s);
    return 0;
}
