/* scenes.h - the test scenes (camera, meshes, model matrices, signs) and their
   ground truth, ray-cast per pixel from the very triangles fogvol draws
   (tests/raycast.h). Shared by test_render.c and test_tiers.c. Needs cmocka,
   fogvol.h, tests/shapes.h and tests/raycast.h included first. */
#ifndef SCENES_H
#define SCENES_H

#define W 128
#define H 128
#define MAX_OBJ 24

typedef struct tobj {
    shp_mesh mesh;
    float model[16];
    int sign; /* +1 volume, -1 negative volume, 0 occluder */
} tobj;

typedef struct tscene {
    const char *name;
    rc_camera cam;
    tobj obj[MAX_OBJ];
    int n;
    int bits;
    float density; /* extinction ramp density for the composite check */
    int expect_overflow;
} tscene;

static tscene g_scenes[28];
static int g_nscenes;

static int mirrored(const float m[16])
{
    double d = (double)m[0] * (m[5] * m[10] - m[9] * m[6]) - (double)m[4] * (m[1] * m[10] - m[9] * m[2]) +
               (double)m[8] * (m[1] * m[6] - m[5] * m[2]);
    return d < 0;
}

static void mat_trs(float m[16], float tx, float ty, float tz, float ang, float ax, float ay, float az, float s)
{
    float t[16], r[16], sc[16], tmp[16];
    shp_mat_translate(t, tx, ty, tz);
    shp_mat_rotate(r, ang, ax, ay, az);
    shp_mat_scale(sc, s, s, s);
    shp_mat_mul(tmp, r, sc);
    shp_mat_mul(m, t, tmp);
}

static tscene *new_scene(const char *name, double ex, double ey, double ez, double tx, double ty, double tz,
                         double znear, double zfar)
{
    tscene *s = &g_scenes[g_nscenes++];
    memset(s, 0, sizeof *s);
    s->name = name;
    s->cam.eye[0] = ex;
    s->cam.eye[1] = ey;
    s->cam.eye[2] = ez;
    s->cam.target[0] = tx;
    s->cam.target[1] = ty;
    s->cam.target[2] = tz;
    s->cam.up[1] = 1.0;
    s->cam.fovy_deg = 50.0;
    s->cam.aspect = (double)W / H;
    s->cam.znear = znear;
    s->cam.zfar = zfar;
    s->cam.width = W;
    s->cam.height = H;
    s->bits = 4;
    s->density = 0.8f;
    return s;
}

static void add(tscene *s, shp_mesh m, int sign, const float model[16])
{
    tobj *o = &s->obj[s->n++];
    o->mesh = m;
    o->sign = sign;
    memcpy(o->model, model, sizeof o->model);
}

static void build_scenes(void)
{
    float m[16];
    tscene *s;
    int i;

    s = new_scene("sphere", 0, 0, 4, 0, 0, 0, 0.5, 10);
    shp_mat_identity(m);
    add(s, shp_sphere(1.0f, 64, 32), 1, m);

    s = new_scene("box", 0, 0, 4, 0, 0, 0, 0.5, 10);
    mat_trs(m, 0, 0, 0, 35, 0.3f, 1, 0.2f, 1);
    add(s, shp_box(0.9f, 0.6f, 0.8f), 1, m);

    s = new_scene("torus_edge_on", 0, 0.15, 4.5, 0, 0, 0, 0.5, 10);
    mat_trs(m, 0, 0, 0, 90, 1, 0, 0, 1); /* ring in the xz plane: seen edge-on */
    add(s, shp_torus(1.1f, 0.35f, 96, 32), 1, m);

    s = new_scene("two_spheres", 0, 0, 4, 0, 0, 0, 0.5, 10);
    shp_mat_translate(m, -0.45f, 0, 0);
    add(s, shp_sphere(0.85f, 64, 32), 1, m);
    shp_mat_translate(m, 0.45f, 0.1f, -0.2f);
    add(s, shp_sphere(0.85f, 64, 32), 1, m);

    s = new_scene("torus_knot_L5", 0, 0.3, 4.2, 0, 0, 0, 0.5, 10);
    s->bits = 5;
    mat_trs(m, 0, 0, 0, 10, 1, 0, 0, 1);
    add(s, shp_torus_knot(3, 4, 1.0f, 0.45f, 0.22f, 480, 20), 1, m);

    /* one concave mesh (8 spheres along the view axis) whose central rays
       cross 8 back and 8 front faces: the limit of the 15-bit encoding,
       placed deep (d up to 0.93) so the channel sums come close to 255 */
    s = new_scene("stack8_L5", 0, 0, 3.0, 0, 0, -6, 0.5, 14);
    s->bits = 5;
    s->density = 0.5f;
    s->cam.fovy_deg = 12.0; /* the far spheres stay large on screen */
    {
        shp_mesh all = shp_sphere(0.3f, 32, 16);
        for (i = 1; i < 8; ++i) {
            shp_mesh one = shp_sphere(0.3f, 32, 16);
            float t[16];
            shp_mat_translate(t, 0, 0, -1.05f * (float)i);
            shp_transform(&one, t);
            shp_append(&all, &one);
            shp_free(&one);
        }
        shp_mat_translate(m, 0, 0, -2.0f);
        add(s, all, 1, m);
    }

    s = new_scene("plane_cuts_sphere", 0, 1.6, 3.6, 0, 0, 0, 0.5, 10);
    shp_mat_identity(m);
    add(s, shp_sphere(1.0f, 64, 32), 1, m);
    mat_trs(m, 0, -0.25f, 0, -90, 1, 0, 0, 1); /* xy plane turned into a floor at y = -0.25 */
    add(s, shp_grid_plane(3, 3, 4), 0, m);

    s = new_scene("cube_inside_volume", 0.5, 0.8, 4, 0, 0, 0, 0.5, 10);
    mat_trs(m, 0, 0, 0, 20, 0, 1, 0, 1);
    add(s, shp_box(1.1f, 0.9f, 1.0f), 1, m);
    mat_trs(m, 0.1f, 0.05f, 0.1f, 40, 1, 1, 0, 1);
    add(s, shp_box(0.35f, 0.35f, 0.35f), 0, m);

    s = new_scene("negative_sphere_in_box", 0, 0.4, 4, 0, 0, 0, 0.5, 10);
    mat_trs(m, 0, 0, 0, 15, 0, 1, 0, 1);
    add(s, shp_box(1.0f, 1.0f, 1.0f), 1, m);
    shp_mat_translate(m, 0.1f, 0, 0);
    add(s, shp_sphere(0.6f, 64, 32), -1, m);

    /* a mirroring model matrix (negative determinant) flips the winding: fogvol
       must flip its face culling, the solid is the same */
    s = new_scene("mirrored_box", 0, 0.3, 4, 0, 0, 0, 0.5, 10);
    {
        float r[16], sc[16];
        shp_mat_rotate(r, 30, 0.2f, 1, 0);
        shp_mat_scale(sc, -1.0f, 1.0f, 1.0f);
        shp_mat_mul(m, r, sc);
    }
    add(s, shp_box(0.9f, 0.6f, 0.7f), 1, m);

    /* a negative sphere poking out of its box: where it leaves the box the
       sum goes below zero, which must show as no fog (and no false overflow) */
    s = new_scene("negative_pokes_out", 0, 0.4, 4, 0, 0, 0, 0.5, 10);
    mat_trs(m, 0, 0, 0, 15, 0, 1, 0, 1);
    add(s, shp_box(0.9f, 0.9f, 0.9f), 1, m);
    shp_mat_translate(m, 0.85f, 0.1f, 0);
    add(s, shp_sphere(0.6f, 64, 32), -1, m);

    /* seeds/001: the ray enters layer 1 (A1), leaves it (B1), enters layer 2
       (A2) and hits an opaque object (C) before layer 2's back face B2:
       thickness = (B1 - A1) + (C - A2) */
    s = new_scene("layers_opaque_between", 0.3, 0.5, 4.5, 0, 0, -0.5, 0.5, 10);
    shp_mat_translate(m, 0, 0, 0.9f);
    add(s, shp_box(1.2f, 1.0f, 0.35f), 1, m);
    shp_mat_translate(m, 0, 0, -0.6f);
    add(s, shp_box(1.2f, 1.0f, 0.6f), 1, m);
    mat_trs(m, 0.1f, 0, -0.55f, 25, 0, 1, 0.2f, 1);
    add(s, shp_box(0.45f, 0.45f, 0.45f), 0, m);

    s = new_scene("camera_inside_sphere", 0, 0, 0.6, 0, 0, -1, 0.2, 8);
    shp_mat_identity(m);
    add(s, shp_sphere(2.5f, 64, 32), 1, m);

    s = new_scene("camera_half_inside_box", 1.0, 0.05, 0.4, 1.0, 0.05, -1, 0.2, 8);
    shp_mat_identity(m);
    add(s, shp_box(1.0f, 1.0f, 1.5f), 1, m);

    /* 20 nested shells far from the camera: 20 back faces > 16 at L = 4, and
       with depths near the far end the red channel saturates. */
    s = new_scene("overflow_shells", 0, 0, 9, 0, 0, 0, 0.5, 10);
    s->expect_overflow = 1;
    for (i = 0; i < 20; ++i) {
        shp_mat_identity(m);
        add(s, shp_sphere(0.3f + 0.03f * (float)i, 32, 16), 1, m);
    }
}

static int scene_index(const char *name)
{
    int i;
    for (i = 0; i < g_nscenes; ++i)
        if (strcmp(g_scenes[i].name, name) == 0) return i;
    fail_msg("no scene %s", name);
    return 0;
}

/* Upload every object of the scene (occluders may be open meshes). */
static void upload_meshes(fogvol_context *fv, const tscene *s, fogvol_mesh **meshes)
{
    int i;
    for (i = 0; i < s->n; ++i) {
        fogvol_mesh_desc md;
        memset(&md, 0, sizeof md);
        md.positions = s->obj[i].mesh.pos;
        md.vertex_count = s->obj[i].mesh.vcount;
        md.indices = (const uint32_t *)s->obj[i].mesh.idx;
        md.index_count = s->obj[i].mesh.icount;
        md.allow_open = s->obj[i].sign == 0;
        assert_int_equal(fogvol_create_mesh(fv, &md, &meshes[i], NULL), FOGVOL_SUCCESS);
    }
}

/* Add the scene to the open frame: volumes with their sign, occluders unless
   the engine draws them itself (MRT). */
static void add_scene(fogvol_context *fv, const tscene *s, fogvol_mesh **meshes, const fogvol_ramp *ramp,
                      int with_occluders)
{
    int i;
    for (i = 0; i < s->n; ++i) {
        if (s->obj[i].sign == 0) {
            if (with_occluders)
                assert_int_equal(fogvol_add_occluder(fv, meshes[i], s->obj[i].model), FOGVOL_SUCCESS);
        } else {
            fogvol_volume_desc vd;
            memset(&vd, 0, sizeof vd);
            vd.mesh = meshes[i];
            vd.ramp = ramp;
            vd.negative = s->obj[i].sign < 0;
            memcpy(vd.model, s->obj[i].model, sizeof vd.model);
            assert_int_equal(fogvol_add_volume(fv, &vd), FOGVOL_SUCCESS);
        }
    }
}

static void free_scenes(void)
{
    int i, j;
    for (i = 0; i < g_nscenes; ++i)
        for (j = 0; j < g_scenes[i].n; ++j) shp_free(&g_scenes[i].obj[j].mesh);
}

/* The ray caster's scene of s (with_occluders 0: without its occluders); free with rc_scene_free. */
static void scene_raycaster(const tscene *s, int with_occluders, rc_scene *rs)
{
    rc_object ro[MAX_OBJ] = {{0}};
    unsigned *reversed[MAX_OBJ] = {0};
    int i, n = 0;
    /* a mirrored instance is the same solid, so its triangles are reversed for the ray caster, which
       reads orientation from the winding */
    for (i = 0; i < s->n; ++i) {
        rc_object *o = &ro[n];
        if (!with_occluders && s->obj[i].sign == 0) continue;
        o->pos = s->obj[i].mesh.pos;
        o->vcount = s->obj[i].mesh.vcount;
        o->idx = s->obj[i].mesh.idx;
        if (mirrored(s->obj[i].model)) {
            unsigned *rev = (unsigned *)malloc(sizeof(unsigned) * (size_t)s->obj[i].mesh.icount);
            int t;
            for (t = 0; t < s->obj[i].mesh.icount; t += 3) {
                rev[t] = s->obj[i].mesh.idx[t];
                rev[t + 1] = s->obj[i].mesh.idx[t + 2];
                rev[t + 2] = s->obj[i].mesh.idx[t + 1];
            }
            o->idx = rev;
            reversed[n] = rev;
        }
        o->icount = s->obj[i].mesh.icount;
        memcpy(o->model, s->obj[i].model, sizeof o->model);
        o->sign = s->obj[i].sign;
        n++;
    }
    assert_true(rc_scene_init(rs, ro, n));
    for (i = 0; i < n; ++i) free(reversed[i]);
}

/* Ground truth for every pixel centre: thickness, pairs of faces crossed,
   interior mask (rc_interior), covered mask (a volume face on the ray) and, where slope is not
   NULL, the interior pixels' depth slopes (rc_depth_slope; 0 elsewhere): a test adds
   slope * snap_pixels() to its bound for what the GL's vertex snapping moves the faces. */
static void ground_truth(const tscene *s, double *gt, int *pairs, unsigned char *interior, unsigned char *covered,
                         int *max_faces, double *tmax, double *slope)
{
    rc_scene rs;
    int x, y;
    *max_faces = 0;
    *tmax = 0;
    scene_raycaster(s, 1, &rs);
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            rc_result r = rc_trace(&rs, &s->cam, x + 0.5, y + 0.5);
            int k = y * W + x;
            gt[k] = r.thickness;
            pairs[k] = r.faces_front > r.faces_back ? r.faces_front : r.faces_back;
            covered[k] = r.faces_front + r.faces_back > 0;
            if (pairs[k] < 1) pairs[k] = 1;
            interior[k] = (unsigned char)rc_interior(&rs, &s->cam, x, y);
            if (slope) slope[k] = interior[k] ? rc_depth_slope(&rs, &s->cam, x, y) : 0.0;
            if (r.faces_back > *max_faces) *max_faces = r.faces_back;
            if (r.faces_front > *max_faces) *max_faces = r.faces_front;
            if (gt[k] > *tmax) *tmax = gt[k];
        }
    rc_scene_free(&rs);
}

/* Every tier and variant combination the GL tests render (test_tiers on desktop dialects,
   test_gles on OpenGL ES), and the scenes they compare against the ray cast. */
typedef struct tier_combo {
    fogvol_tier tier;
    unsigned variants;
    const char *name;
    int bits; /* 0: the scene's */
} tier_combo;

static const tier_combo g_tier_combos[] = {
    {FOGVOL_TIER_PS13, 0, "PS13", 0},
    {FOGVOL_TIER_PS13, FOGVOL_VARIANT_COUNT, "PS13+count", 0},
    {FOGVOL_TIER_PS13, FOGVOL_VARIANT_NEAR_CLAMP, "PS13+nearclamp", 0},
    {FOGVOL_TIER_PS20, 0, "PS20", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_SINGLE_TARGET, "PS20+single", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_COUNT, "PS20+count", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ALU, "PS20+alu", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ALU | FOGVOL_VARIANT_SINGLE_TARGET, "PS20+alu+single", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_NEAR_CLAMP, "PS20+nearclamp", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_ENGINE_DEPTH, "PS20+enginedepth", 0},
    {FOGVOL_TIER_PS20, FOGVOL_VARIANT_WIDE, "PS20+wide (L=3, 18 bits)", 3},
    {FOGVOL_TIER_MRT, 0, "MRT", 0},
    {FOGVOL_TIER_MRT, FOGVOL_VARIANT_ALU, "MRT+alu", 0},
    {FOGVOL_TIER_MRT, FOGVOL_VARIANT_SINGLE_TARGET, "MRT+single", 0},
    {FOGVOL_TIER_FLOAT, 0, "FLOAT", 0},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_ENGINE_DEPTH, "FLOAT+enginedepth", 0},
    {FOGVOL_TIER_FLOAT, FOGVOL_VARIANT_NEAR_CLAMP, "FLOAT+nearclamp", 0},
};
#define NTIER_COMBO ((int)(sizeof g_tier_combos / sizeof g_tier_combos[0]))

static const char *const g_scene_names[] = {"sphere",
                                            "two_spheres",
                                            "plane_cuts_sphere",
                                            "negative_sphere_in_box",
                                            "negative_pokes_out",
                                            "layers_opaque_between",
                                            "camera_inside_sphere"};
#define NSCENE ((int)(sizeof g_scene_names / sizeof g_scene_names[0]))

#endif
