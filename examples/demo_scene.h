/* demo_scene.h - the place the fogvol demos are set in, shared by demo_headless.c
   and demo_glfw.c: a ruined courtyard on a grassy plain with a cobbled path, a
   stone house with a tiled roof, a colonnade (one column broken, one drum
   fallen), an arch gate, a low wall, rocks, pine trees and a lamp post, under a
   sky with a horizon-to-zenith gradient and soft clouds. It is lit by a low sun
   and the sky; every surface has a procedural texture computed in the fragment
   shader (grass, cobbles, masonry, plaster, roof tiles, rock, bark, needles),
   with flat normals taken from screen-space derivatives.

   Fog volumes placed in it, in three colour-ramp groups:
     DS_FOG    a fog sphere swallowing the rocks and tree feet on the right, a
               ring (torus) standing in the arch gate, a drifting cloud (a
               deformed sphere, animated) between the columns;
     DS_BANK   a low mist bank over the back of the courtyard, with DS_HOLE, a
               negative sphere, carving a clearing into it;
     DS_LIGHT  a sunbeam slanting onto the path and the cone of the lamp post,
               blended additively; each fades along its length (ds_object.fade:
               a density texture of ds_fade_texels along its axis, fogvol_volume_desc.density).

   Use:  ds_scene s; ds_scene_build(&s); ds_scene_animate(&s, t);
         ds_gl g; ds_gl_init(&g, &s);        once per GL 3.3 context
         ds_draw(&g, &s, view, proj, w, h);  sky + opaque scene: colour and depth
         ... fogvol: ds_group(kind) and ds_object.negative for each volume ...
         ds_gl_free(&g); ds_scene_free(&s);
   The GL 3.3 entry points must be declared before this file is included. */
#ifndef DEMO_SCENE_H
#define DEMO_SCENE_H

#include "tests/shapes.h"
#include "examples/example_gl.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DS_MAX_MESHES 32
#define DS_MAX_OBJECTS 96

enum ds_kind { DS_OPAQUE, DS_FOG, DS_BANK, DS_HOLE, DS_LIGHT };
enum ds_material { DS_GROUND, DS_STONE, DS_PLASTER, DS_ROOF, DS_ROCK, DS_BARK, DS_NEEDLES, DS_LAMP, DS_WOOD };

typedef struct ds_object {
    int mesh, kind, material;
    float color[3];
    float model[16];
    int fade;          /* 1: light that fades along its axis: density texture of ds_fade_texels with */
    float fade_map[8]; /*    these texture-coordinate rows (fogvol_volume_desc.density_map) */
} ds_object;

typedef struct ds_scene {
    shp_mesh mesh[DS_MAX_MESHES];
    int mesh_count;
    ds_object obj[DS_MAX_OBJECTS];
    int count;
    int blob_mesh, blob_obj, ring_obj, hole_obj; /* the animated ones */
    float *blob_base;                            /* the cloud's sphere before deformation */
} ds_scene;

/* sun direction (towards the sun) and the sky colours, shared by the sky and the surfaces */
#define DS_SUN_X 0.72
#define DS_SUN_Y 0.52
#define DS_SUN_Z 0.46
#define DS__STR2(x) #x
#define DS__STR(x) DS__STR2(x)
#define DS_SUN "vec3(" DS__STR(DS_SUN_X) ", " DS__STR(DS_SUN_Y) ", " DS__STR(DS_SUN_Z) ")"

/* ---- meshes -------------------------------------------------------------------- */

/* Frustum of a cone around +y from y = 0 to h, radii rb (bottom) and rt (top, > 0),
   n sides, closed by two caps; counter-clockwise seen from outside. */
static inline shp_mesh ds_frustum(float rb, float rt, float h, int n)
{
    shp_mesh m = shp__alloc(2.0 * n + 2, 12.0 * n);
    unsigned *p = m.idx;
    int i, bc = 2 * n, tc = 2 * n + 1;
    if (!m.pos) return m;
    for (i = 0; i < n; ++i) {
        double a = 2.0 * SHP__PI * i / n;
        shp__setv(&m, i, rb * cos(a), 0, rb * sin(a));
        shp__setv(&m, n + i, rt * cos(a), h, rt * sin(a));
    }
    shp__setv(&m, bc, 0, 0, 0);
    shp__setv(&m, tc, 0, h, 0);
    for (i = 0; i < n; ++i) {
        int j = (i + 1) % n;
        shp__tri(&p, i, n + i, n + j);
        shp__tri(&p, i, n + j, j);
        shp__tri(&p, tc, n + j, n + i);
        shp__tri(&p, bc, i, j);
    }
    return m;
}

/* A rock: a coarse sphere whose radius varies with direction (star-shaped: still closed). */
static inline shp_mesh ds_rock(unsigned seed)
{
    shp_mesh m = shp_sphere(1.0f, 11, 7);
    int i;
    for (i = 0; i < m.vcount; ++i) {
        float *q = m.pos + 3 * i;
        double r = 0.78 + 0.22 * sin(3.1 * q[0] + seed) * cos(2.3 * q[1] - 0.7 * seed) + 0.1 * sin(5.0 * q[2] + 2.0 * seed);
        q[0] = (float)(q[0] * r), q[1] = (float)(q[1] * r), q[2] = (float)(q[2] * r * 0.7);
    }
    return m;
}

static inline int ds__mesh(ds_scene *s, shp_mesh m)
{
    if (s->mesh_count == DS_MAX_MESHES || !m.pos) {
        fprintf(stderr, "demo scene: mesh table full or out of memory\n");
        exit(1);
    }
    s->mesh[s->mesh_count] = m;
    return s->mesh_count++;
}

/* model = translate(t) * rotate(angle about axis) * scale(sc) */
static inline void ds_trs(float out[16], float tx, float ty, float tz, float angle, float ax, float ay, float az, float sx,
                   float sy, float sz)
{
    float t[16], r[16], sc[16];
    shp_mat_translate(t, tx, ty, tz);
    shp_mat_rotate(r, angle, ax, ay, az);
    shp_mat_scale(sc, sx, sy, sz);
    shp_mat_mul(out, r, sc);
    shp_mat_mul(out, t, out);
}

static inline int ds__add(ds_scene *s, int mesh, int kind, int material, float r, float g, float b, const float model[16])
{
    ds_object *o;
    if (s->count == DS_MAX_OBJECTS) {
        fprintf(stderr, "demo scene: more than DS_MAX_OBJECTS objects\n");
        exit(1);
    }
    o = &s->obj[s->count];
    o->mesh = mesh, o->kind = kind, o->material = material;
    o->color[0] = r, o->color[1] = g, o->color[2] = b;
    memcpy(o->model, model, sizeof o->model);
    return s->count++;
}

/* colour ramp group of a volume kind: 0 fog, 1 bank (and its hole), 2 light; -1 opaque */
static inline int ds_group(int kind)
{
    return kind == DS_FOG ? 0 : kind == DS_BANK || kind == DS_HOLE ? 1 : kind == DS_LIGHT ? 2 : -1;
}

/* the house, the colonnade and the arch gate */
static inline void ds__buildings(ds_scene *s, int box, int column)
{
    static const float cols[5][3] = {{-5.5f, -3.0f, 3.0f}, {-5.5f, -0.8f, 3.0f}, {-5.5f, 1.4f, 1.3f},
                                     {-5.5f, 3.6f, 3.0f}, {-7.6f, -3.0f, 3.0f}}; /* x, z, height */
    float m[16];
    int i;
    ds_trs(m, -4.2f, 1.3f, -7.2f, 0, 0, 1, 0, 2.2f, 1.3f, 1.6f); /* house body and roof ridge */
    ds__add(s, box, DS_OPAQUE, DS_PLASTER, 0.86f, 0.80f, 0.68f, m);
    ds_trs(m, -4.2f, 2.6f, -7.2f, 45, 1, 0, 0, 2.45f, 1.35f, 1.35f);
    ds__add(s, box, DS_OPAQUE, DS_ROOF, 0.62f, 0.28f, 0.20f, m);
    ds_trs(m, -3.1f, 0.75f, -5.58f, 0, 0, 1, 0, 0.45f, 0.75f, 0.05f); /* door */
    ds__add(s, box, DS_OPAQUE, DS_WOOD, 0.42f, 0.27f, 0.15f, m);
    ds_trs(m, -5.3f, 1.5f, -5.58f, 0, 0, 1, 0, 0.4f, 0.35f, 0.05f); /* window */
    ds__add(s, box, DS_OPAQUE, DS_WOOD, 0.20f, 0.15f, 0.10f, m);
    for (i = 0; i < 5; ++i) { /* colonnade: base, shaft, capital */
        ds_trs(m, cols[i][0], 0.12f, cols[i][1], 0, 0, 1, 0, 0.42f, 0.12f, 0.42f);
        ds__add(s, box, DS_OPAQUE, DS_STONE, 0.78f, 0.74f, 0.66f, m);
        ds_trs(m, cols[i][0], 0.24f, cols[i][1], 0, 0, 1, 0, 1, cols[i][2], 1);
        ds__add(s, column, DS_OPAQUE, DS_STONE, 0.82f, 0.78f, 0.70f, m);
        if (cols[i][2] < 2.0f) continue; /* the broken one has no capital */
        ds_trs(m, cols[i][0], 0.24f + cols[i][2] + 0.1f, cols[i][1], 0, 0, 1, 0, 0.4f, 0.1f, 0.4f);
        ds__add(s, box, DS_OPAQUE, DS_STONE, 0.78f, 0.74f, 0.66f, m);
    }
    ds_trs(m, -6.55f, 3.44f, -3.0f, 0, 0, 1, 0, 1.5f, 0.16f, 0.45f); /* lintel over the corner */
    ds__add(s, box, DS_OPAQUE, DS_STONE, 0.78f, 0.74f, 0.66f, m);
    ds_trs(m, -4.3f, 0.3f, 2.3f, 80, 0, 0, 1, 1, 0.9f, 1); /* a fallen drum */
    ds__add(s, column, DS_OPAQUE, DS_STONE, 0.80f, 0.76f, 0.68f, m);
    for (i = 0; i < 2; ++i) { /* arch gate: two posts and nine voussoirs */
        ds_trs(m, 1.5f + (i ? 1.9f : -1.9f), 1.1f, -4.5f, 0, 0, 1, 0, 0.32f, 1.1f, 0.38f);
        ds__add(s, box, DS_OPAQUE, DS_STONE, 0.74f, 0.70f, 0.63f, m);
    }
    for (i = 0; i < 9; ++i) {
        float a = (float)(SHP__PI * (i + 0.5) / 9);
        ds_trs(m, 1.5f + 1.9f * cosf(a), 2.2f + 1.9f * sinf(a), -4.5f, a * 57.29578f, 0, 0, 1, 0.32f, 0.35f, 0.38f);
        ds__add(s, box, DS_OPAQUE, DS_STONE, 0.74f, 0.70f, 0.63f, m);
    }
    for (i = 0; i < 3; ++i) { /* a low wall on the right, partly tumbled */
        ds_trs(m, 5.0f + 0.2f * i, 0.35f - 0.12f * i, -4.0f + 1.9f * i, 8.0f * i, 0, 1, 0, 0.3f, 0.35f - 0.12f * i, 0.9f);
        ds__add(s, box, DS_OPAQUE, DS_STONE, 0.66f, 0.63f, 0.57f, m);
    }
}

/* rocks, pine trees and the lamp post */
static inline void ds__nature(ds_scene *s, int box, int trunk, int cone)
{
    static const float trees[4][4] = {{7.0f, -6.5f, 1.2f, 0}, {8.6f, -3.8f, 1.0f, 0}, {5.6f, -9.0f, 1.4f, 0},
                                      {9.5f, -8.5f, 1.1f, 0}}; /* x, z, size */
    static const float rocks[6][6] = {{4.6f, 1.0f, 0.9f, 0.7f, 0.8f, 10}, {5.7f, 0.2f, 0.55f, 0.45f, 0.6f, 70},
                                      {3.9f, 2.2f, 0.35f, 0.3f, 0.4f, 130}, {-2.6f, 5.0f, 0.5f, 0.35f, 0.45f, 40},
                                      {2.6f, -6.8f, 0.6f, 0.5f, 0.5f, 200}, {-8.5f, 1.0f, 0.8f, 0.6f, 0.7f, 300}};
    float m[16];
    int i, k, rock[3];
    for (i = 0; i < 3; ++i) rock[i] = ds__mesh(s, ds_rock((unsigned)(i * 7 + 3)));
    for (i = 0; i < 6; ++i) {
        ds_trs(m, rocks[i][0], rocks[i][3] * 0.55f, rocks[i][1], rocks[i][5], 0, 1, 0, rocks[i][2], rocks[i][3], rocks[i][4]);
        ds__add(s, rock[i % 3], DS_OPAQUE, DS_ROCK, 0.55f, 0.53f, 0.50f, m);
    }
    for (i = 0; i < 4; ++i) {
        float sz = trees[i][2];
        ds_trs(m, trees[i][0], 0, trees[i][1], 0, 0, 1, 0, sz, sz, sz);
        ds__add(s, trunk, DS_OPAQUE, DS_BARK, 0.38f, 0.26f, 0.16f, m);
        for (k = 0; k < 3; ++k) {
            float r = sz * (1.25f - 0.3f * k);
            ds_trs(m, trees[i][0], sz * (0.7f + 0.85f * k), trees[i][1], 20.0f * k, 0, 1, 0, r, sz * 1.5f, r);
            ds__add(s, cone, DS_OPAQUE, DS_NEEDLES, 0.16f, 0.36f, 0.16f, m);
        }
    }
    ds_trs(m, 1.6f, 0, 2.6f, 0, 0, 1, 0, 0.5f, 2.7f, 0.5f); /* lamp post and its lantern */
    ds__add(s, trunk, DS_OPAQUE, DS_WOOD, 0.22f, 0.20f, 0.18f, m);
    ds_trs(m, 1.6f, 2.75f, 2.6f, 0, 0, 1, 0, 0.16f, 0.14f, 0.16f);
    ds__add(s, box, DS_OPAQUE, DS_LAMP, 1.0f, 0.85f, 0.55f, m);
    ds_trs(m, 1.6f, 2.92f, 2.6f, 45, 0, 1, 0, 0.24f, 0.04f, 0.24f);
    ds__add(s, box, DS_OPAQUE, DS_WOOD, 0.22f, 0.20f, 0.18f, m);
}

/* The density of a light fading along its axis, 1 texel high (RGBA8, red): s in [0, 1] from its
   base to its top; faint where it meets the ground, full in the middle, gone at the top end. */
#define DS_FADE_TEXELS 64
static inline void ds_fade_texels(unsigned char *rgba)
{
    int i;
    for (i = 0; i < DS_FADE_TEXELS; ++i) {
        double u = (i + 0.5) / DS_FADE_TEXELS, a = u > 0.4 ? 1 : u / 0.4;
        double b = u < 0.72 ? 0 : u > 1.0 ? 1 : (u - 0.72) / 0.28;
        double f = (0.4 + 0.6 * a * a * (3 - 2 * a)) * (1 - b * b * (3 - 2 * b));
        rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = (unsigned char)(255.0 * f + 0.5);
        rgba[4 * i + 3] = 255;
    }
}

/* fade_map for a light whose model-space axis is y from y0 to y1, the texture's s from s0 to s1 */
static inline void ds__fade(ds_object *o, float y0, float y1, float s0, float s1)
{
    memset(o->fade_map, 0, sizeof o->fade_map);
    o->fade = 1;
    o->fade_map[1] = (s1 - s0) / (y1 - y0);
    o->fade_map[3] = s0 - o->fade_map[1] * y0;
    o->fade_map[7] = 0.5f;
}

/* the fog volumes */
static inline void ds__volumes(ds_scene *s)
{
    float m[16];
    int sphere = ds__mesh(s, shp_sphere(1.0f, 64, 32)), ring = ds__mesh(s, shp_torus(1.25f, 0.42f, 96, 32));
    int box = ds__mesh(s, shp_box(1, 1, 1)), lamp = ds__mesh(s, ds_frustum(1.0f, 0.12f, 2.6f, 48));
    int beam = ds__mesh(s, ds_frustum(1.0f, 1.0f, 2.0f, 48)), k;
    s->blob_mesh = ds__mesh(s, shp_sphere(0.9f, 48, 24));
    s->blob_base = (float *)malloc(sizeof(float) * 3 * (size_t)s->mesh[s->blob_mesh].vcount);
    memcpy(s->blob_base, s->mesh[s->blob_mesh].pos, sizeof(float) * 3 * (size_t)s->mesh[s->blob_mesh].vcount);
    ds_trs(m, 5.3f, 0.5f, 0.6f, 0, 0, 1, 0, 1.9f, 1.5f, 1.9f);
    ds__add(s, sphere, DS_FOG, 0, 0, 0, 0, m);
    s->ring_obj = ds__add(s, ring, DS_FOG, 0, 0, 0, 0, m);
    s->blob_obj = ds__add(s, s->blob_mesh, DS_FOG, 0, 0, 0, 0, m);
    ds_trs(m, 0, 0.25f, -7.0f, 0, 0, 1, 0, 12.0f, 0.55f, 6.0f); /* the mist bank: y -0.3 .. 0.8, z -13 .. -1 */
    ds__add(s, box, DS_BANK, 0, 0, 0, 0, m);
    s->hole_obj = ds__add(s, sphere, DS_HOLE, 0, 0, 0, 0, m);
    for (k = 0; k < s->mesh[beam].vcount; ++k) s->mesh[beam].pos[3 * k + 1] -= 1.0f; /* a cylinder, y -1 .. 1 */
    ds_trs(m, -0.6f, 2.6f, -1.6f, -22, 0.3f, 0, 1, 0.45f, 3.6f, 0.45f); /* sunbeam */
    ds__fade(&s->obj[ds__add(s, beam, DS_LIGHT, 0, 0, 0, 0, m)], -1.0f, 1.0f, 0.0f, 1.0f);
    ds_trs(m, 1.6f, 0, 2.6f, 0, 0, 1, 0, 1, 1, 1); /* the lamp's cone, from the ground up to the lantern */
    ds__fade(&s->obj[ds__add(s, lamp, DS_LIGHT, 0, 0, 0, 0, m)], 0.0f, 2.6f, 0.08f, 0.5f);
}

/* Pose the animated volumes at time t (seconds): the ring turns in the gate, the
   cloud writhes (a sphere twisted about y and wobbled radially: star-shaped, so
   it stays a closed, consistently oriented hull), the clearing drifts. */
static inline void ds_scene_animate(ds_scene *s, double t)
{
    shp_mesh *b = &s->mesh[s->blob_mesh];
    int i;
    ds_trs(s->obj[s->ring_obj].model, 1.5f, 2.05f, -4.5f, 25.0f * (float)sin(0.5 * t), 0, 1, 0, 1, 1, 1);
    ds_trs(s->obj[s->blob_obj].model, -2.6f, 1.7f + 0.2f * (float)sin(0.8 * t), -0.6f, 0, 0, 1, 0, 1.2f, 1.0f, 1.2f);
    ds_trs(s->obj[s->hole_obj].model, 1.5f + 3.0f * (float)sin(0.4 * t), 0.25f, -6.0f, 0, 0, 1, 0, 1.8f, 0.5f, 1.8f);
    for (i = 0; i < b->vcount; ++i) {
        const float *p = s->blob_base + 3 * i;
        double x = p[0], y = p[2] * 1.5, z = -p[1]; /* the sphere's pole axis z becomes y, stretched */
        double w = 1.0 + 0.22 * sin(3.0 * x + 2.1 * t) * sin(2.5 * y + 1.3 * t) + 0.12 * cos(4.0 * z - 1.7 * t);
        double ang = 0.9 * sin(0.7 * t) * y, c = cos(ang), sn = sin(ang);
        x *= w, y *= w, z *= w;
        b->pos[3 * i + 0] = (float)(c * x + sn * z);
        b->pos[3 * i + 1] = (float)y;
        b->pos[3 * i + 2] = (float)(-sn * x + c * z);
    }
}

static inline void ds_scene_build(ds_scene *s)
{
    float m[16];
    int box, column, trunk, cone;
    memset(s, 0, sizeof *s);
    box = ds__mesh(s, shp_box(1, 1, 1));
    column = ds__mesh(s, ds_frustum(0.3f, 0.26f, 1.0f, 24));
    trunk = ds__mesh(s, ds_frustum(0.12f, 0.09f, 1.0f, 10));
    cone = ds__mesh(s, ds_frustum(1.0f, 0.02f, 1.0f, 14));
    ds_trs(m, 0, -0.1f, 0, 0, 0, 1, 0, 60.0f, 0.1f, 60.0f); /* the ground: top at y = 0 */
    ds__add(s, box, DS_OPAQUE, DS_GROUND, 1, 1, 1, m);
    ds__buildings(s, box, column);
    ds__nature(s, box, trunk, cone);
    ds__volumes(s);
    ds_scene_animate(s, 0.0);
}

static inline void ds_scene_free(ds_scene *s)
{
    int i;
    for (i = 0; i < s->mesh_count; ++i) shp_free(&s->mesh[i]);
    free(s->blob_base);
    memset(s, 0, sizeof *s);
}

/* The shaders' shared functions (noise, the sky) and the surfaces' albedos, in the GLSL that GLSL 330
   core and GLSL ES 1.00 share (the browser demo draws the place with them too); DS_GLSL_ALBEDO reads
   wp (world position), color and material. */
#define DS_GLSL_FUNCS                                                                                               \
    "const vec3 sun = normalize(" DS_SUN ");\n"                                                                     \
    "float hash(vec2 p) { return fract(sin(dot(p, vec2(127.1, 311.7))) * 43758.5453); }\n"                        \
    "float noise(vec2 p) { vec2 i = floor(p), f = fract(p); f = f * f * (3.0 - 2.0 * f);\n"                       \
    "  return mix(mix(hash(i), hash(i + vec2(1, 0)), f.x), mix(hash(i + vec2(0, 1)), hash(i + vec2(1, 1)), f.x), f.y); }\n" \
    "float fbm(vec2 p) { return 0.5 * noise(p) + 0.25 * noise(2.03 * p) + 0.125 * noise(4.01 * p)\n"              \
    "  + 0.0625 * noise(8.05 * p); }\n"                                                                             \
    "vec3 sky_color(vec3 d) {\n"                                                                                    \
    "  float h = d.y;\n"                                                                                            \
    "  vec3 c = mix(vec3(0.86, 0.83, 0.76), vec3(0.24, 0.44, 0.76), pow(clamp(h, 0.0, 1.0), 0.55));\n"          \
    "  c = mix(c, vec3(0.62, 0.64, 0.60), clamp(-h * 6.0, 0.0, 1.0));\n"                                          \
    "  if (h > 0.0) { float k = fbm(d.xz / (h + 0.12) * 1.6 + vec2(3.0, 1.0));\n"                                \
    "    c = mix(c, vec3(0.97, 0.95, 0.92), smoothstep(0.5, 0.8, k) * 0.75 * smoothstep(0.0, 0.25, h)); }\n"      \
    "  return c + vec3(1.0, 0.8, 0.5) * 0.5 * pow(max(dot(d, sun), 0.0), 24.0);\n"                                \
    "}\n"

#define DS_GLSL_ALBEDO \
    "vec3 ground() {\n" \
    "  vec2 q = wp.xz; float g = fbm(q * 1.7);\n" \
    "  vec3 c = mix(vec3(0.17, 0.30, 0.08), vec3(0.38, 0.48, 0.15), g);\n" \
    "  c = mix(c, vec3(0.40, 0.33, 0.22), 0.8 * smoothstep(0.58, 0.72, fbm(q * 0.22 + 7.0)));\n" \
    "  float px = abs(q.x - 1.0 - 1.2 * sin(q.y * 0.28)), plaza = length((q - vec2(-1.0, -3.2)) * vec2(0.55, 0.8));\n" \
    "  float path = max(smoothstep(1.05, 0.9, px), smoothstep(3.1, 2.9, plaza));\n" \
    "  vec2 b = q / vec2(0.5, 0.36); b.x += 0.5 * mod(floor(b.y), 2.0); vec2 f = fract(b) - 0.5;\n" \
    "  float e = smoothstep(0.5, 0.36, max(abs(f.x), abs(f.y)));\n" \
    "  vec3 st = mix(vec3(0.40, 0.38, 0.35), vec3(0.62, 0.58, 0.52), hash(floor(b))) * (0.45 + 0.55 * e);\n" \
    "  return mix(c, st * (0.85 + 0.3 * g), path * smoothstep(0.15, 0.4, fbm(q * 0.9 + 2.0) + 0.3));\n" \
    "}\n" \
    "vec2 face_uv(vec3 n) { return abs(n.x) > 0.7 ? wp.zy : abs(n.y) > 0.7 ? wp.xz : wp.xy; }\n" \
    "vec3 albedo(vec3 n) {\n" \
    "  vec2 uv = face_uv(n);\n" \
    "  if (material == 0) return ground();\n" \
    "  if (material == 1) { vec2 b = uv / vec2(0.7, 0.35); b.x += 0.5 * mod(floor(b.y), 2.0); vec2 f = fract(b);\n" \
    "    float m = smoothstep(0.0, 0.05, f.x) * smoothstep(1.0, 0.95, f.x) * smoothstep(0.0, 0.09, f.y)\n" \
    "      * smoothstep(1.0, 0.91, f.y);\n" \
    "    return color * (0.82 + 0.3 * hash(floor(b))) * mix(0.6, 1.0, m) * (0.85 + 0.3 * fbm(uv * 5.0)); }\n" \
    "  if (material == 2) return color * (0.8 + 0.3 * fbm(uv * 3.0)) * (0.9 + 0.1 * smoothstep(0.3, 0.6, wp.y));\n" \
    "  if (material == 3) { float r = fract(dot(wp, vec3(0.0, 4.0, 4.0))), c = fract(wp.x * 3.0 + 0.5 * floor(dot(wp, vec3(0.0, 4.0, 4.0))));\n" \
    "    return color * (0.75 + 0.3 * hash(floor(vec2(wp.x * 3.0, dot(wp, vec3(0.0, 4.0, 4.0)))))) * mix(0.55, 1.0, smoothstep(0.0, 0.15, r))\n" \
    "      * mix(0.8, 1.0, smoothstep(0.0, 0.06, c)); }\n" \
    "  if (material == 4) return color * (0.6 + 0.6 * fbm(uv * 2.5 + wp.y)) * mix(vec3(1.0), vec3(0.75, 0.85, 0.6),\n" \
    "    smoothstep(0.3, 0.9, n.y) * 0.8);\n" \
    "  if (material == 5) return color * (0.7 + 0.4 * noise(vec2(atan(n.z, n.x) * 6.0, wp.y * 3.0)));\n" \
    "  if (material == 6) return color * (0.65 + 0.6 * fbm(vec2(atan(n.z, n.x) * 3.0, wp.y * 6.0)));\n" \
    "  if (material == 8) return color * (0.75 + 0.35 * noise(vec2(uv.x * 14.0, uv.y * 1.5)));\n" \
    "  return color;\n" \
    "}\n"

/* general 4x4 inverse (column-major); returns 0 for a singular matrix */
static inline int ds_invert(float out[16], const float m[16])
{
    double a[4][8], t;
    int c, r, k, piv;
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 8; ++c) a[r][c] = c < 4 ? m[c * 4 + r] : (c - 4 == r);
    for (c = 0; c < 4; ++c) {
        for (piv = c, r = c + 1; r < 4; ++r)
            if (fabs(a[r][c]) > fabs(a[piv][c])) piv = r;
        if (fabs(a[piv][c]) < 1e-30) return 0;
        for (k = 0; k < 8; ++k) t = a[c][k], a[c][k] = a[piv][k], a[piv][k] = t;
        for (t = a[c][c], k = 0; k < 8; ++k) a[c][k] /= t;
        for (r = 0; r < 4; ++r)
            if (r != c)
                for (t = a[r][c], k = 0; k < 8; ++k) a[r][k] -= t * a[c][k];
    }
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 4; ++c) out[c * 4 + r] = (float)a[r][c + 4];
    return 1;
}

/* ---- the opaque renderer (GL 3.3 core; left out with DS_SCENE_ONLY) ----------------- */
#ifndef DS_SCENE_ONLY

typedef struct ds_gl {
    GLuint prog, sky, vao[DS_MAX_MESHES], vbo[DS_MAX_MESHES], ebo[DS_MAX_MESHES], empty_vao;
    GLuint shadow_prog, shadow_fbo, shadow_tex; /* the sun's shadow map, rendered once */
    GLint u_mvp, u_model, u_color, u_material, u_eye, u_sky_inv, u_shadow_vp, u_shadow_map, u_shadow_mvp;
    int count[DS_MAX_MESHES];
    float shadow_vp[16];
} ds_gl;

#define DS_SHADOW_SIZE 2048

#define DS_GLSL_COMMON "#version 330 core\n" DS_GLSL_FUNCS

static const char *const ds__vs = "#version 330 core\n"
                            "layout(location = 0) in vec3 p;\n"
                            "uniform mat4 mvp, model; out vec3 wp;\n"
                            "void main() { wp = (model * vec4(p, 1.0)).xyz; gl_Position = mvp * vec4(p, 1.0); }\n";

static const char *const ds__fs_albedo =
    "in vec3 wp; uniform vec3 color, eye; uniform int material; out vec4 o;\n" DS_GLSL_ALBEDO;

static const char *const ds__fs_main =
    "uniform mat4 shadow_vp; uniform sampler2DShadow shadow_map;\n"
    "float sunlight(vec3 n) {\n"
    "  vec4 s = shadow_vp * vec4(wp + n * 0.04, 1.0); vec3 q = s.xyz / s.w * 0.5 + 0.5; float l = 0.0;\n"
    "  for (int i = 0; i < 4; ++i) {\n"
    "    vec2 o = (vec2(i & 1, i >> 1) - 0.5) * (1.5 / " DS__STR(DS_SHADOW_SIZE) ".0);\n"
    "    l += texture(shadow_map, vec3(q.xy + o, q.z - 0.0015)); }\n"
    "  return 0.25 * l * max(dot(n, sun), 0.0);\n"
    "}\n"
    "void main() {\n"
    "  vec3 n = normalize(cross(dFdx(wp), dFdy(wp)));\n"
    "  vec3 a = albedo(n);\n"
    "  float d = sunlight(n);\n"
    "  vec3 amb = mix(vec3(0.26, 0.23, 0.18), vec3(0.42, 0.52, 0.68), 0.5 + 0.5 * n.y);\n"
    "  vec3 c = material == 7 ? color * 1.4 : a * (amb * 0.85 + vec3(1.15, 1.0, 0.8) * d);\n"
    "  vec3 v = wp - eye; float dist = length(v);\n"
    "  c = mix(c, sky_color(normalize(vec3(v.x, 0.02 * dist, v.z))), 1.0 - exp(-0.018 * dist));\n"
    "  o = vec4(c, 1.0);\n"
    "}\n";

static const char *const ds__shadow_vs = "#version 330 core\n"
                                   "layout(location = 0) in vec3 p; uniform mat4 mvp;\n"
                                   "void main() { gl_Position = mvp * vec4(p, 1.0); }\n";
static const char *const ds__shadow_fs = "void main() { }\n";

static const char *const ds__sky_vs = "#version 330 core\n"
                                "uniform mat4 inv_vp; out vec3 dir;\n"
                                "void main() {\n"
                                "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
                                "  vec4 a = inv_vp * vec4(p, -1.0, 1.0), b = inv_vp * vec4(p, 1.0, 1.0);\n"
                                "  dir = b.xyz / b.w - a.xyz / a.w; gl_Position = vec4(p, 1.0, 1.0);\n"
                                "}\n";

static const char *const ds__sky_fs = "in vec3 dir; out vec4 o;\n"
                                "void main() { o = vec4(sky_color(normalize(dir)), 1.0); }\n";

static inline GLuint ds__program(const char *vs, const char *fs_a, const char *fs_b, const char *fs_c)
{
    const char *fs[3];
    GLuint p;
    fs[0] = fs_a, fs[1] = fs_b, fs[2] = fs_c;
    p = exm_program("demo scene", vs, fs, fs_c ? 3 : 2, NULL);
    if (!p) exit(1);
    return p;
}

/* The sun's view: orthographic, looking down -sun onto the courtyard. */
static inline void ds__sun_matrix(float vp[16])
{
    static const double sun[3] = {DS_SUN_X, DS_SUN_Y, DS_SUN_Z}, c[3] = {0.0, 0.0, -2.5};
    double l = sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]), f[3], r[3], u[3], e[3], n;
    float v[16], p[16];
    int k;
    for (k = 0; k < 3; ++k) f[k] = -sun[k] / l, e[k] = c[k] - 30.0 * f[k];
    r[0] = f[2], r[1] = 0, r[2] = -f[0]; /* f x (0,1,0), normalised */
    n = sqrt(r[0] * r[0] + r[2] * r[2]), r[0] /= n, r[2] /= n;
    u[0] = r[1] * f[2] - r[2] * f[1], u[1] = r[2] * f[0] - r[0] * f[2], u[2] = r[0] * f[1] - r[1] * f[0];
    shp_mat_identity(v);
    for (k = 0; k < 3; ++k) v[4 * k] = (float)r[k], v[4 * k + 1] = (float)u[k], v[4 * k + 2] = (float)-f[k];
    v[12] = (float)-(r[0] * e[0] + r[1] * e[1] + r[2] * e[2]);
    v[13] = (float)-(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]);
    v[14] = (float)(f[0] * e[0] + f[1] * e[1] + f[2] * e[2]);
    shp_mat_scale(p, 1.0f / 15.0f, 1.0f / 15.0f, -2.0f / 50.0f); /* x, y in [-15, 15], depth 5 .. 55 */
    p[14] = -60.0f / 50.0f;
    shp_mat_mul(vp, p, v);
}

/* Render the shadow map once (the opaque scene does not move); the framebuffer
   binding and viewport are restored. */
static inline void ds__shadow_map(ds_gl *g, const ds_scene *s)
{
    GLint fb = 0, vpt[4];
    float mvp[16];
    int i;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fb);
    glGetIntegerv(GL_VIEWPORT, vpt);
    glGenTextures(1, &g->shadow_tex);
    glBindTexture(GL_TEXTURE_2D, g->shadow_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, DS_SHADOW_SIZE, DS_SHADOW_SIZE, 0, GL_DEPTH_COMPONENT,
                 GL_UNSIGNED_INT, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &g->shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, g->shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g->shadow_tex, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glViewport(0, 0, DS_SHADOW_SIZE, DS_SHADOW_SIZE);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    ds__sun_matrix(g->shadow_vp);
    glUseProgram(g->shadow_prog);
    for (i = 0; i < s->count; ++i) {
        if (s->obj[i].kind != DS_OPAQUE) continue;
        shp_mat_mul(mvp, g->shadow_vp, s->obj[i].model);
        glUniformMatrix4fv(g->u_shadow_mvp, 1, GL_FALSE, mvp);
        glBindVertexArray(g->vao[s->obj[i].mesh]);
        glDrawElements(GL_TRIANGLES, g->count[s->obj[i].mesh], GL_UNSIGNED_INT, (void *)0);
    }
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, (GLuint)fb);
    glViewport(vpt[0], vpt[1], vpt[2], vpt[3]);
}

/* compile the programs, upload the opaque meshes (positions and indices as they are),
   render the shadow map */
static inline void ds_gl_init(ds_gl *g, const ds_scene *s)
{
    int i;
    memset(g, 0, sizeof *g);
    g->prog = ds__program(ds__vs, DS_GLSL_COMMON, ds__fs_albedo, ds__fs_main);
    g->sky = ds__program(ds__sky_vs, DS_GLSL_COMMON, ds__sky_fs, NULL);
    g->u_mvp = glGetUniformLocation(g->prog, "mvp");
    g->u_model = glGetUniformLocation(g->prog, "model");
    g->u_color = glGetUniformLocation(g->prog, "color");
    g->u_material = glGetUniformLocation(g->prog, "material");
    g->u_eye = glGetUniformLocation(g->prog, "eye");
    g->u_sky_inv = glGetUniformLocation(g->sky, "inv_vp");
    g->u_shadow_vp = glGetUniformLocation(g->prog, "shadow_vp");
    g->u_shadow_map = glGetUniformLocation(g->prog, "shadow_map");
    g->shadow_prog = ds__program(ds__shadow_vs, "#version 330 core\n", ds__shadow_fs, NULL);
    g->u_shadow_mvp = glGetUniformLocation(g->shadow_prog, "mvp");
    glGenVertexArrays(1, &g->empty_vao);
    for (i = 0; i < s->mesh_count; ++i) {
        const shp_mesh *m = &s->mesh[i];
        glGenVertexArrays(1, &g->vao[i]);
        glGenBuffers(1, &g->vbo[i]);
        glGenBuffers(1, &g->ebo[i]);
        glBindVertexArray(g->vao[i]);
        glBindBuffer(GL_ARRAY_BUFFER, g->vbo[i]);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(sizeof(float) * 3 * (size_t)m->vcount), m->pos, GL_STATIC_DRAW);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo[i]);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(sizeof(unsigned) * (size_t)m->icount), m->idx, GL_STATIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, (void *)0);
        glEnableVertexAttribArray(0);
        g->count[i] = m->icount;
    }
    glBindVertexArray(0);
    ds__shadow_map(g, s);
}

static inline void ds_gl_free(ds_gl *g)
{
    int i;
    for (i = 0; i < DS_MAX_MESHES; ++i)
        if (g->vao[i]) {
            glDeleteVertexArrays(1, &g->vao[i]);
            glDeleteBuffers(1, &g->vbo[i]);
            glDeleteBuffers(1, &g->ebo[i]);
        }
    glDeleteVertexArrays(1, &g->empty_vao);
    glDeleteFramebuffers(1, &g->shadow_fbo);
    glDeleteTextures(1, &g->shadow_tex);
    glDeleteProgram(g->shadow_prog);
    glDeleteProgram(g->prog);
    glDeleteProgram(g->sky);
    memset(g, 0, sizeof *g);
}

/* The engine's opaque pass: clears the bound framebuffer's colour and depth to the
   viewport, draws the sky and the opaque objects (colour + depth). Leaves depth test,
   culling and blending disabled, program and vertex array 0. */
static inline void ds_draw(ds_gl *g, const ds_scene *s, const float view[16], const float proj[16], int w, int h)
{
    float vp[16], inv[16], iv[16], mvp[16];
    int i;
    shp_mat_mul(vp, proj, view);
    glViewport(0, 0, w, h);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_DEPTH_TEST); /* the sky: a full-screen triangle behind everything */
    if (ds_invert(inv, vp)) {
        glUseProgram(g->sky);
        glUniformMatrix4fv(g->u_sky_inv, 1, GL_FALSE, inv);
        glBindVertexArray(g->empty_vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(g->prog);
    if (ds_invert(iv, view)) glUniform3f(g->u_eye, iv[12], iv[13], iv[14]);
    glUniformMatrix4fv(g->u_shadow_vp, 1, GL_FALSE, g->shadow_vp);
    glUniform1i(g->u_shadow_map, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->shadow_tex);
    for (i = 0; i < s->count; ++i) {
        const ds_object *o = &s->obj[i];
        if (o->kind != DS_OPAQUE) continue;
        shp_mat_mul(mvp, vp, o->model);
        glUniformMatrix4fv(g->u_mvp, 1, GL_FALSE, mvp);
        glUniformMatrix4fv(g->u_model, 1, GL_FALSE, o->model);
        glUniform3f(g->u_color, o->color[0], o->color[1], o->color[2]);
        glUniform1i(g->u_material, o->material);
        glBindVertexArray(g->vao[o->mesh]);
        glDrawElements(GL_TRIANGLES, g->count[o->mesh], GL_UNSIGNED_INT, (void *)0);
    }
    glDisable(GL_DEPTH_TEST);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    glBindVertexArray(0);
}

#endif /* DS_SCENE_ONLY */
#endif /* DEMO_SCENE_H */
