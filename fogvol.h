/* fogvol.h - v0.2.0 - mesh-shaped fog and light volumes for real-time engines
   MIT or public domain (see the end of this file).

   fogvol.h renders ordinary closed polygon meshes (convex or concave, animated,
   any number of them) as thick volumes of fog or light, with exact edges,
   opaque objects cutting through, and the camera free to stand inside. It is
   the technique of the NVIDIA SDK white paper "Fog Polygon Volumes" (2004) and
   Dan Baker's DirectX 8.1 "VolumeFog" sample, made into a drop-in library.

   For every pixel:  thickness = sum(depth of back faces) - sum(depth of front
   faces), with depth = view-space w mapped to [0,1] from the near to the far
   plane, and each face's depth clamped to the depth of the nearest opaque
   object. On RGBA8 targets depths are "RGB-encoded" (L low bits per channel,
   8-L carry bits on top) so that additive blending sums up to 2^(8-L) faces
   exactly; a colour ramp maps thickness to colour, blended over the scene.

   WHERE TO FIND WHAT (the declarations, in this order; search for "---- NAME")
   ==================
       basic types          result codes, logger, allocator, texture desc, formats
       context              handles, tiers, variants, dialects, fogvol_gl_desc,
                            fogvol_create_context
       meshes               fogvol_mesh_desc, the validation report, create/destroy
       ramps                thickness -> colour ramps, blend modes
       frames               fogvol_frame_desc, begin/add/end frame, volume textures,
                            lights, MRT and engine-drawn occluders
       image-space effects  depth of field, outlines, distance fog
       backend table        the contract of a custom backend, the null backend, the
                            GL backend on its own
       context desc         fogvol_context_desc (after the table, which it holds)
       encoding             the RGB encoding of depths, fogvol_context_encoding
       textures             the lookup textures and colour ramps on the CPU
       shaders              the GLSL strings of each tier, variant and dialect
       tuning               the speed-ups (on by default) and disable_speedups
       analytic fog         the analytic volumes (left out by FOGVOL_NO_ANALYTIC)
       CPU reference        the GPU arithmetic on the CPU, for tests and tools

   API INDEX (every public function, one line each, by task)
   =========
   context      fogvol_create_context        make a context: backend, tier, variants, encoding
                fogvol_destroy_context       free it and everything it owns
                fogvol_context_tier          the tier and variants it chose
                fogvol_context_encoding      its encoding (bits, faces it sums)
                fogvol_set_dither            dithering on or off
   meshes       fogvol_create_mesh           upload a closed mesh (validated, optionally welded)
                fogvol_destroy_mesh          free it
                fogvol_validate_mesh         check a mesh without a context (the report)
   ramps        fogvol_create_ramp           thickness -> colour and alpha (extinction or table)
                fogvol_destroy_ramp          free it
   frames       fogvol_begin_frame           start a frame: camera, viewport, planes, debug read-back
                fogvol_add_volume            a volume: mesh, model matrix, ramp, sign, textures
                fogvol_add_occluder          an opaque mesh that cuts the volumes
                fogvol_add_occluder_callback the engine draws an occluder itself
                fogvol_occluder_transform    inside that callback: the model matrix to draw with
                fogvol_add_light             a volume light by compare
                fogvol_end_frame             draw and composite; the engine's state restored
                fogvol_cancel_frame          drop the frame
                fogvol_projection_planes     near and far planes from a projection matrix
   textures     fogvol_create_volume_texture a density or colour texture for volumes
                fogvol_destroy_volume_texture  free it
   engine       fogvol_mrt_prepare           MRT: the O texture and uniforms for the engine's pass
                fogvol_mrt_snippet           MRT: the GLSL to paste into the engine's opaque shader
                fogvol_occluder_prepare      occluders drawn by the engine's own shaders into O
                fogvol_occluder_snippet      the GLSL for those shaders
   effects      fogvol_post_dof              depth of field (edge-preserving)
                fogvol_post_outlines         outlines from depth (and normals)
                fogvol_post_distance_fog     distance fog from depth
   questions    fogvol_result_string         a result code's name
                fogvol_tier_name             a tier's name
                fogvol_dialect_name          a GLSL dialect's name
                fogvol_combination_supported does a tier with these variants exist in a dialect
                fogvol_msaa_supported        ... per sample on multisampled framebuffers
                fogvol_tier_costs            passes and targets of a tier
                fogvol_tier_uses_program     which programs a tier draws with
   backends     fogvol_gl_backend_create     the GL backend on its own
                fogvol_renderer_is_software  does a GL_RENDERER name a CPU renderer (a backend's caps)
                fogvol_null_backend_init     a recording backend without a GPU (tests)
                fogvol_uniform_name          the GLSL name of a uniform slot
                fogvol_dialect_layout        where the Vulkan dialect puts uniforms, per-draw values, samplers
   shaders      fogvol_shader_strings        the GLSL of a program (tier, variants, dialect, stage)
                fogvol_shader_source         the same with no variant
                fogvol_post_shader_strings   the GLSL of an image-space effect
   encoding     fogvol_encoding_init         the encoding with L bits per digit
                fogvol_encoding_from_faces   ... that sums at least n faces
                fogvol_encoding_from_precision ... with at least n bits
                fogvol_encoding_table        every encoding (bits, faces, precision)
                fogvol_compute_constants     the shaders' constants for near/far planes
                fogvol_encode_depth          a depth as RGBA8 digits (CPU reference)
                fogvol_sum_rgba8             saturating 8-bit sums (CPU reference)
                fogvol_sum_encoded           sums of encoded depths (CPU reference)
                fogvol_decode                digits -> depth (CPU reference)
                fogvol_decode_difference     decode(a) - decode(b) (CPU reference)
                fogvol_make_rg_ramp          the red+green lookup texture
                fogvol_make_blue_ramp        the dithered blue lookup texture
                fogvol_make_dither_index     the 8x8 dither pattern texture
                fogvol_dither_threshold      a dither row's rounding threshold
                fogvol_make_color_ramp       a colour ramp texture on the CPU
   analytic     fogvol_analytic_prepare      analytic volumes (JCAB): prepare a set
                fogvol_analytic_segment      one volume's entry and exit on a ray
                fogvol_analytic_eval         fog of one eye-to-point ray
                fogvol_analytic_batch        fog of many vertices (SIMD kernels)
                fogvol_analytic_kernel_resolve  which kernel a batch runs
                fogvol_fold_fog              fold fog into diffuse and specular
                fogvol_analytic_pack_uniforms  the uniforms of the analytic GLSL
                fogvol_analytic_shader_strings the analytic fog's GLSL
                fogvol_analytic_snippet      its function for the engine's shaders

   BUILDING
   ========
   In exactly one C or C++ file:

       #define FOGVOL_IMPLEMENTATION
       #include "fogvol.h"

   Everywhere else just #include "fogvol.h". Nothing to link but the C library
   (and libm). The GL backend reaches OpenGL only through function pointers that
   your loader hands it; fogvol.h includes no GL header and links no GL library.

   CONFIGURATION MACROS (define before the #include that has the implementation)
   ====================
     FOGVOL_STATIC          all functions static (implementation private to one TU)
     FOGVOL_API             decoration of every public function (default extern)
     FOGVOL_NO_GL           leave out the GL backend (math, textures, shaders,
                            renderer and the null backend remain)
     FOGVOL_NO_ANALYTIC     leave out the analytic fog volumes (they share
                            nothing with the renderer)
     FOGVOL_ASSERT(x)       assertion (default: assert from <assert.h>)
     FOGVOL_SQRT, FOGVOL_EXP, FOGVOL_FLOOR, FOGVOL_FABS, FOGVOL_POW
                            maths hooks (default: <math.h>)
     FOGVOL_MALLOC, FOGVOL_FREE
                            default allocator when a desc leaves it empty
     FOGVOL_GLAPIENTRY      calling convention of GL entry points
                            (default __stdcall on _WIN32, nothing elsewhere)

   QUICK START (default GL backend, any GL 2.1+ / 3.x core / GLES2+ context)
   ===========
       fogvol_context_desc cd;  memset(&cd, 0, sizeof cd);   // 0 = default
       cd.gl.get_proc = glfwGetProcAddress;                   // or SDL/EGL/GLX/your own loader
       fogvol_context *fv;
       if (fogvol_create_context(&cd, &fv) != FOGVOL_SUCCESS) ...;

       fogvol_mesh_desc md;  memset(&md, 0, sizeof md);
       md.positions = verts; md.vertex_count = nv;            // xyz floats
       md.indices = idx;     md.index_count = ni;             // CCW seen from outside
       fogvol_mesh *blob;   fogvol_create_mesh(fv, &md, &blob, NULL);

       fogvol_ramp_desc rd;  memset(&rd, 0, sizeof rd);       // extinction model
       rd.color[0] = rd.color[1] = rd.color[2] = 0.8f; rd.density = 0.5f;
       fogvol_ramp *fog;    fogvol_create_ramp(fv, &rd, &fog);

       // every frame, after the engine drew its opaque scene into the bound framebuffer:
       fogvol_frame_desc fd;  memset(&fd, 0, sizeof fd);
       memcpy(fd.view, view, 64); memcpy(fd.projection, proj, 64);
       fd.znear = 0.1f; fd.zfar = 100.0f;
       fd.viewport[2] = width; fd.viewport[3] = height;
       fogvol_begin_frame(fv, &fd);
       fogvol_add_occluder(fv, ground_mesh, ground_model);    // opaque things that cut fog
       fogvol_volume_desc vd;  memset(&vd, 0, sizeof vd);
       vd.mesh = blob; vd.ramp = fog; memcpy(vd.model, model, 64);
       fogvol_add_volume(fv, &vd);
       fogvol_end_frame(fv, NULL);     // renders and composites; GL state restored

   Matrices are column-major float[16] (m[col*4+row]), OpenGL conventions: the
   camera looks down -z in view space, clip w = view depth (perspective) or a
   constant (orthographic). The projection's depth convention does not matter:
   reversed-Z, [0,1] or [-1,1] depth, infinite far plane, TAA jitter, oblique
   near plane and mirrored x/y all work, since fogvol computes its own clip depth
   from znear/zfar and takes the winding from how the projection orients the
   screen. The GL backend reads the engine's glClipControl and glDepthRange, draws
   with NEGATIVE_ONE_TO_ONE and depth range (0,1) (same origin) and restores them.
   A camera known only as a view-projection matrix goes in with
   fogvol_frame_desc.camera = FOGVOL_CAMERA_VIEW_PROJECTION plus eye and forward;
   fogvol_projection_planes() recovers znear/zfar from a projection.

   RESULT CODES AND LOGGING
   ========================
   Every function that can fail returns fogvol_result (0 success, negative
   errors); fogvol_result_string() names them. Details go to the logger of the
   desc (shader info logs included). The library never prints by itself.

   CUSTOM BACKENDS
   ===============
   The renderer talks to the GPU only through fogvol_backend, a table of
   function pointers whose first argument is the table's user_data. Fill the
   table yourself to render through your own engine layer; see the contract
   next to the struct declaration below. fogvol_null_backend_init() gives a
   recording backend that needs no GPU.

   GL <-> GLSL (dialect chosen from the context, overridable)
   ============
       GL 2.0 -> 110   GL 2.1 -> 120   GL 3.0/3.1 -> 130   GL 3.2 -> 150
       GL 3.3+ -> 330 core   GLES 2 / WebGL 1 -> 100   GLES 3 / WebGL 2 -> 300 es

   TIERS (fogvol_context_desc.tier; 0 = automatic, in this order)
   =====
       context has                          tier    passes (white paper / fogvol)
       R32F + float blending (GL 3.0,       FLOAT   3 / 3  (2 with the engine's
         GLES3 + EXT_color_buffer_float                     depth texture)
         + EXT_float_blend)
       MRT and desc.engine_mrt = 1          MRT     4 / 3  (the engine writes O)
       highp fragment shaders               PS20    5 / 4
       lowp/mediump only (GLES2)            PS13    6 / 5
   Variants combine with tiers (FOGVOL_VARIANT_*): single target, Baker's
   inside/outside count, ALU encoding, near-plane vertex clamping, engine depth
   (FLOAT, PS20), two-target precision (WIDE); fogvol_combination_supported()
   says which exist in a dialect. FLOAT and MRT need GLSL 130+ or 300 es.

   MRT TIER (the engine's opaque pass writes the opaque depth as a 2nd output)
   ========
       fogvol_begin_frame(fv, &fd);
       fogvol_mrt_info mi; fogvol_mrt_prepare(fv, &mi);   // O texture (RGBA8, or R32F: FOGVOL_SPEEDUP_FLOAT_O),
                                                           // clear colour, uniforms
       glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, (GLuint)mi.texture, 0);
       glDrawBuffers(2, bufs); glClearBufferfv(GL_COLOR, 1, mi.clear_color);
       // opaque shader: fogvol_mrt_snippet() pasted in, uniform fogvol_mrt[2] = mi.uniforms,
       //                second output = fogvol_encode_view_depth(-view_space_z)
       glDrawBuffers(1, bufs);                             // before fogvol composites
       ... fogvol_add_volume ...; fogvol_end_frame(fv, NULL);

   THE ENGINE'S OWN DEPTH, OCCLUDERS AND MESHES
   ============================================
       // depth buffers that are not textures (FLOAT + ENGINE_DEPTH): fogvol blits them
       fd.engine_depth_source = FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER;  // or _FRAMEBUFFER_OBJECT + name
       // occluders drawn by the engine's own pipelines (PS20, FLOAT)
       fogvol_occluder_info oi; fogvol_occluder_prepare(fv, &oi); // O texture, size, clear colour, uniforms
       // engine FBO: colour oi.texture + its own depth; shader: fogvol_occluder_snippet(),
       // fogvol_mrt[2] = oi.uniforms, colour = fogvol_occluder_color(-view_space_z)
       // meshes: fogvol_mesh_desc.stride/offset (interleaved), index_type + indices16 or no
       //         index array (triangles in vertex order), weld_distance > 0 for seams and per-face vertices

   ANALYTIC FOG VOLUMES (no render passes; FOGVOL_NO_ANALYTIC leaves them out)
   ====================
   After JCAB, "Implementing Volumetric Fog Without Using Texture Stages" (GDC 2001).
   Per-vertex or per-pixel fog from distance fog, half-spaces, spheres and
   affine transforms of the unit sphere, cube and cylinder, each with density
   and colour; separate volumes front to back or interpenetrating volumes by the
   paper's sorted event list; linear or exponential law. fogvol_analytic_prepare
   once, then fogvol_analytic_batch over vertex arrays (no allocation, order
   carried between frames) or the GLSL of fogvol_analytic_shader_strings with
   the uniforms of fogvol_analytic_pack_uniforms; fogvol_fold_fog folds fog into
   diffuse/specular. Details next to the declarations.

   SECTIONS (search for the markers; the implementation in this order)
   ========
       >>declarations   the public API (its parts are listed under WHERE TO FIND WHAT)
       >>cpu            results, allocation, logging; encoding; lookup textures; mesh validation
       >>dialects       the GLSL dialect table and the preludes
       >>analytic       analytic fog volumes (JCAB): prepare, evaluate, batch, GLSL
       >>tiers          what each tier supports (variants, speed-ups, features) and costs
       >>shaders        the GLSL bodies of every program, shader strings, engine snippets
       >>null backend   the recording backend (no GPU)
       >>context        the renderer's objects and the context: configuration, targets, programs
       >>resources      meshes (upload, bounds, convexity), colour ramps, volume textures
       >>frame input    camera, begin_frame, volumes, occluders, MRT and engine-drawn O, matrices
       >>passes         opaque O, the face sums, composite, debug read-back
       >>overflow       overflow check passes, occlusion queries, what a count changes
       >>lights         volume lights by compare
       >>colour groups  one-pass colours (FOGVOL_VARIANT_COLORS)
       >>end frame      fogvol_end_frame: set-up, groups in turn, lights, stats
       >>post effects   image-space effects: depth of field, outlines, distance fog
       >>gl backend     the default backend on OpenGL / GLES through function pointers
*/

#ifndef FOGVOL_H
#define FOGVOL_H

#define FOGVOL_VERSION_MAJOR 0
#define FOGVOL_VERSION_MINOR 2
#define FOGVOL_VERSION_PATCH 0
#define FOGVOL_VERSION_STRING "0.2.0"

#include <stddef.h>
#include <stdint.h>

#ifndef FOGVOL_API
#  ifdef FOGVOL_STATIC
#    if defined(__GNUC__) || defined(__clang__)
#      define FOGVOL_API static __attribute__((unused))
#    else
#      define FOGVOL_API static
#    endif
#  else
#    define FOGVOL_API extern
#  endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* >>declarations ========================================================== */

/* ---- basic types: result codes, logging, allocation -------------------- */
typedef enum fogvol_result {
    FOGVOL_SUCCESS = 0,
    FOGVOL_ERROR_INVALID_ARGUMENT = -1,   /* NULL, out of range, non-finite, near >= far ... */
    FOGVOL_ERROR_OUT_OF_MEMORY = -2,      /* the allocator returned NULL */
    FOGVOL_ERROR_BUFFER_TOO_SMALL = -3,   /* caller buffer smaller than the size reported */
    FOGVOL_ERROR_UNSUPPORTED = -4,        /* the combination or the context cannot do it */
    FOGVOL_ERROR_INVALID_MESH = -5,       /* mesh is not a closed, consistently oriented hull */
    FOGVOL_ERROR_INVALID_STATE = -6,      /* call out of order (e.g. add outside a frame) */
    FOGVOL_ERROR_MISSING_FUNCTION = -7,   /* a required GL entry point was not found */
    FOGVOL_ERROR_SHADER_COMPILE = -8,     /* info log went to the logger */
    FOGVOL_ERROR_SHADER_LINK = -9,        /* info log went to the logger */
    FOGVOL_ERROR_FRAMEBUFFER = -10,       /* render target format refused by the driver */
    FOGVOL_ERROR_BACKEND = -11,           /* the backend reported another failure */
    FOGVOL_ERROR_DEPTH_OVERFLOW = -12,    /* more faces along a ray than the encoding holds */
    FOGVOL_RESULT_MAX_ENUM = 0x7fffffff
} fogvol_result;

FOGVOL_API const char *fogvol_result_string(fogvol_result result);

typedef enum fogvol_log_level {
    FOGVOL_LOG_ERROR = 0,
    FOGVOL_LOG_WARNING = 1,
    FOGVOL_LOG_INFO = 2,
    FOGVOL_LOG_DEBUG = 3,
    FOGVOL_LOG_MAX_ENUM = 0x7fffffff
} fogvol_log_level;

/* Allocator: alloc == NULL means FOGVOL_MALLOC/FOGVOL_FREE (malloc/free). */
typedef struct fogvol_allocator {
    void *(*alloc)(size_t size, void *user_data);
    void (*free)(void *ptr, void *user_data);
    void *user_data;
} fogvol_allocator;

/* Logger: func == NULL means silent. message is NUL-terminated, no newline. */
typedef struct fogvol_logger {
    void (*func)(void *user_data, fogvol_log_level level, const char *message);
    void *user_data;
} fogvol_logger;

/* Declared here, not with the backend table, because the frames section uses them
   (fogvol_create_volume_texture, fogvol_occluder_info) and C declares before use. */
typedef enum fogvol_filter { FOGVOL_FILTER_NEAREST = 0, FOGVOL_FILTER_LINEAR = 1 } fogvol_filter;
typedef enum fogvol_wrap { FOGVOL_WRAP_REPEAT = 0, FOGVOL_WRAP_CLAMP = 1 } fogvol_wrap;

typedef struct fogvol_texture_desc {
    int width, height;
    const unsigned char *pixels; /* RGBA8, rows bottom to top */
    fogvol_filter filter;
    fogvol_wrap wrap;
    const char *label;
} fogvol_texture_desc;

typedef enum fogvol_format {
    FOGVOL_FORMAT_RGBA8 = 0,
    FOGVOL_FORMAT_R32F = 1,  /* FLOAT tier; renderable and blendable (FOGVOL_CAP_FLOAT_BLEND). The O of
                                MRT and PS20 with FOGVOL_SPEEDUP_FLOAT_O: renderable
                                (FOGVOL_CAP_FLOAT_TARGET) */
    FOGVOL_FORMAT_RGBA32F = 2, /* FOGVOL_VARIANT_COLORS (two attachments); renderable and blendable
                                 wherever R32F is (FOGVOL_CAP_FLOAT_BLEND: GL 3.0, GLES 3 +
                                 EXT_color_buffer_float + EXT_float_blend) */
    FOGVOL_FORMAT_RG32F = 3   /* FLOAT + ENGINE_DEPTH drawn depth-tested (FOGVOL_CAP_ATTACH_DEPTH): the
                                 signed depth sum and the signed face count; asked only of backends
                                 reporting that capability */
} fogvol_format;

/* An object of the backend's graphics API that the engine and fogvol hand each other (engine depth
   textures and framebuffers, fogvol's O texture for the engine's MRT and occluder passes, the post
   effects' inputs): GL a texture or framebuffer name, Vulkan a non-dispatchable handle such as a
   VkImageView (64 bits on every platform), D3D12 or Metal a pointer or descriptor handle. */
typedef uint64_t fogvol_native;

/* ---- context: handles, tiers, variants, dialects, the GL backend's desc ---- */
typedef struct fogvol_context fogvol_context;
typedef struct fogvol_mesh fogvol_mesh;
typedef struct fogvol_ramp fogvol_ramp;

/* A new dialect: its value here before FOGVOL_GLSL_COUNT and its row in
   fogvol__dialects (the >>dialects section says what a row holds). */
typedef enum fogvol_dialect {
    FOGVOL_GLSL_AUTO = 0,
    FOGVOL_GLSL_110 = 1,
    FOGVOL_GLSL_120 = 2,
    FOGVOL_GLSL_130 = 3,
    FOGVOL_GLSL_150 = 4,
    FOGVOL_GLSL_330 = 5, /* 330 core */
    FOGVOL_GLSL_100 = 6, /* GLSL ES 1.00 (GLES2, WebGL1) */
    FOGVOL_GLSL_300ES = 7,
    /* GLSL 450 for SPIR-V (glslangValidator -V, shaderc): samplers at layout(set = 0, binding = unit),
       the pass uniforms in one std140 block at (set 0, binding FOGVOL_MAX_TEXTURE_UNITS), the
       per-draw values in push constants, explicit locations; gl_FragCoord and rows as stored (row 0
       first), depth [0, 1]. Where a backend finds each value: fogvol_program_desc.layout. No context
       picks it: a Vulkan backend names it in fogvol_backend.dialect. */
    FOGVOL_GLSL_VULKAN = 8,
    FOGVOL_GLSL_COUNT = 9,
    FOGVOL_GLSL_MAX_ENUM = 0x7fffffff
} fogvol_dialect;

/* Tiers: the shader-model tiers of the "Fog Polygon Volumes" white paper (ps.1.3, ps.2.0,
   MRT, float blending), in GLSL terms.
   passes = screen passes per frame for one colour-ramp group as the white paper
   counts them (the engine's own opaque pass included):
     PS13   6  RGBA8; engine, O, B, F, resolve B-F to an encoded thickness,
              composite decoding by dependent lookup; per-channel compare
              (works with lowp/mediump fragment precision)
     PS20   5  RGBA8; engine, O, B, F, composite; decoded compare
     MRT    4  RGBA8; the engine's opaque pass writes O as a second colour
              target (fogvol_mrt_prepare + fogvol_mrt_snippet), B, F, composite
     FLOAT  3  R32F with signed additive float blending; engine, O, one pass for
              all faces (sign from gl_FrontFacing), composite; 2 library passes
              with FOGVOL_VARIANT_ENGINE_DEPTH (O comes from the engine's depth
              texture) */
typedef enum fogvol_tier {
    FOGVOL_TIER_AUTO = 0,
    FOGVOL_TIER_PS13 = 1,
    FOGVOL_TIER_PS20 = 2,
    FOGVOL_TIER_MRT = 3,
    FOGVOL_TIER_FLOAT = 4,
    FOGVOL_TIER_COUNT = 5,
    FOGVOL_TIER_MAX_ENUM = 0x7fffffff
} fogvol_tier;

/* Variants (bit flags) that combine with tiers; fogvol_combination_supported()
   says which combinations exist. A new variant: its bit at the end here,
   FOGVOL_VARIANT_ALL, and its #define line in fogvol__variant_define (the
   >>shaders section). */
enum {
    /* RGBA8 tiers: one sum target starting from mid-range (128), back faces
       added, front faces subtracted by reverse-subtract blending; half the
       face limit (fogvol_encoding.max_faces_single). */
    FOGVOL_VARIANT_SINGLE_TARGET = 1u << 0,
    /* PS20/PS13: Baker's inside/outside count in alpha instead of the min
       compare: faces are depth-tested against the opaque depth, and the
       opaque depth is added once per missing back face. The camera must be
       outside the volumes, and the near plane must not cut them: fogvol_end_frame
       checks each volume's bounds and refuses such a frame
       (FOGVOL_ERROR_UNSUPPORTED, logged, nothing drawn). Asked for, COUNT is
       required of every frame; FOGVOL_SPEEDUP_DEPTH_TEST (on by default) draws
       each frame that meets these conditions this way by itself and the others
       with the min compare, so most engines should leave COUNT out. */
    FOGVOL_VARIANT_COUNT = 1u << 1,
    /* PS20/MRT, and PS13 in GLSL 330 / 300 es (highp integers): RGB-encode by
       arithmetic in the fragment shader instead of ramp textures ("newer
       hardware can calculate the ramp values"). Same bytes. FOGVOL_SPEEDUP_ALU
       (on by default) adds this variant wherever the dialect takes it, so asking
       for it only makes a context that cannot have it fail. */
    FOGVOL_VARIANT_ALU = 1u << 2,
    /* Snap vertices behind the near plane onto it (Baker) instead of relying
       on near-plane clipping for a camera partly inside a volume. */
    FOGVOL_VARIANT_NEAR_CLAMP = 1u << 3,
    /* FLOAT: the opaque depth comes from the engine's depth texture
       (fogvol_frame_desc.engine_depth_texture, or a depth buffer it names),
       linearised; no O pass. PS20 (GLSL 130+ / 300 es, not with COUNT or
       WIDE): a full-screen pass linearises and encodes it into O instead of
       drawing occluders. fogvol_add_occluder* calls are not drawn. */
    FOGVOL_VARIANT_ENGINE_DEPTH = 1u << 4,
    /* PS20: more precision by spreading the encoding over two RGBA8 targets
       per sum (MRT): six L-bit digits, 6L bits, the same face limit. Encoded by
       arithmetic; fp32 fragment maths bounds it to about 23 bits, so only
       L <= FOGVOL_WIDE_EXACT_BITS (3: 18 bits with 32 faces) is exact:
       encoding_bits 0 picks 3 and larger values are refused
       (FOGVOL_ERROR_UNSUPPORTED). Needs GLSL 110-330 or 300 es. */
    FOGVOL_VARIANT_WIDE = 1u << 5,
    /* FLOAT: per-volume colours and densities in one pass. Every volume whose ramp has the
       EXTINCTION model and the FOG blend joins one group: its faces add their optical depth per
       colour channel (extinction density * extinction_color times signed depth) and their
       emission (that optical depth times the ramp colour) into two RGBA32F targets in one sum
       pass, and one composite pass blends them all (two full-screen draws, multiply then add,
       when some extinction colour is not grey). Other ramps keep their own group, and so does,
       for a frame, a ramp one of whose volumes has a density or colour texture in it (drawn as
       without COLORS: the group's programs draw no texture). Model and
       error: "One-pass colours" in docs/FEATURES.md. Needs the FLOAT tier, FOGVOL_CAP_MRT and
       target_attachment (else the context is refused, FOGVOL_ERROR_UNSUPPORTED, logged); not
       per sample on multisampled framebuffers (fogvol_msaa_supported: use
       FOGVOL_MSAA_SINGLE_SAMPLE). */
    FOGVOL_VARIANT_COLORS = 1u << 6,
    FOGVOL_VARIANT_ALL = (1u << 7) - 1u
};

/* FOGVOL_SUCCESS if the tier with these variants exists in this dialect,
   else FOGVOL_ERROR_UNSUPPORTED (FLOAT and MRT need GLSL 130+ or 300 es, and
   so on; the table in docs/ACCURACY.md). */
FOGVOL_API fogvol_result fogvol_combination_supported(fogvol_tier tier, unsigned variants, fogvol_dialect dialect);
/* FOGVOL_SUCCESS if the tier with these variants can render into a
   multisampled engine framebuffer per sample (fogvol_shader_desc.samples > 1):
   GLSL 150 or 330 (with GL_ARB_sample_shading, core in GL 4.0) and tier FLOAT,
   PS20 or PS13 (with ENGINE_DEPTH: the engine's depth read per sample), not WIDE
   or COLORS. GLSL 110/120/130 and ES 100/300 es have no multisample textures
   with gl_SampleID: FOGVOL_ERROR_UNSUPPORTED. */
FOGVOL_API fogvol_result fogvol_msaa_supported(fogvol_tier tier, unsigned variants, fogvol_dialect dialect);

typedef struct fogvol_tier_info {
    int paper_passes;    /* as the white paper counts them, the engine's opaque pass included */
    int library_passes; /* passes fogvol issues per frame for one colour-ramp group
                           (+1 per negative group pass in the RGBA8 tiers; PS13: 1 fewer with
                           FOGVOL_SPEEDUP_INLINE_RESOLVE, fogvol_frame_stats.inline_resolved; PS20
                           and MRT: 1 fewer with FOGVOL_SPEEDUP_EXACT_SUM, fogvol_frame_stats.exact_sum,
                           whose one sum pass draws the negative volumes too) */
    int targets;        /* render targets fogvol allocates (PS13: T not with INLINE_RESOLVE) */
    const char *name;
} fogvol_tier_info;
FOGVOL_API fogvol_result fogvol_tier_costs(fogvol_tier tier, unsigned variants, fogvol_tier_info *out);
FOGVOL_API const char *fogvol_tier_name(fogvol_tier tier);

FOGVOL_API const char *fogvol_dialect_name(fogvol_dialect dialect);

typedef void (*fogvol_gl_proc)(void);
typedef fogvol_gl_proc (*fogvol_gl_get_proc_fn)(const char *name, void *user_data);

/* The GL backend's loader: one of the three (get_proc_address first where several are set). */
typedef struct fogvol_gl_desc {
    fogvol_gl_get_proc_fn get_proc_address; /* a loader that takes user_data */
    void *user_data;
    fogvol_gl_proc (*get_proc)(const char *name); /* a plain loader returning a function pointer, as it
                                 is: glfwGetProcAddress, eglGetProcAddress, SDL3's SDL_GL_GetProcAddress */
    void *(*get_proc_pointer)(const char *name); /* a plain loader returning void *, as it is: SDL2's
                                 SDL_GL_GetProcAddress, glad-style loaders (GLADloadproc) */
    fogvol_dialect dialect;   /* 0 = from the context */
    int version_major;        /* 0 = from the context; else treat the context as this GL version */
    int version_minor;
    int gles;                 /* with version_major: 1 = treat as OpenGL ES */
    int software;             /* 0 = from GL_RENDERER (fogvol_renderer_is_software); 1 = treat the
                                 renderer as drawing on the CPU, -1 = as a GPU: the backend's
                                 FOGVOL_CAP_SOFTWARE_RENDERER, which picks how FLOAT + ENGINE_DEPTH
                                 reads the engine's depth (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST) */
    int mrt_highp;            /* OpenGL ES: 1 = the engine declares the output it writes fogvol's O with
                                 highp (layout(location = 1) out highp vec4, or precision highp float):
                                 on GLES 3 with EXT_color_buffer_float the backend then reports
                                 FOGVOL_CAP_FLOAT_TARGET and the MRT tier keeps O as R32F
                                 (FOGVOL_SPEEDUP_FLOAT_O; PS20 too, whose occluders the engine may
                                 draw with its own shaders, fogvol_occluder_prepare: their output
                                 must be highp as well). Left 0, a mediump output could round
                                 the depth to fp16, so O stays RGBA8. Desktop GL: ignored (always full
                                 precision). */
    /* optional: the window system's current context as an opaque id (user_data as above), e.g.
       eglGetCurrentContext, glfwGetCurrentContext, SDL_GL_GetCurrentContext, wglGetCurrentContext.
       fogvol keeps what it returns at creation and refuses every call that would touch GL while it
       returns something else (FOGVOL_ERROR_INVALID_STATE, logged; nothing is touched). Without it,
       fogvol tells another context by its own vertex array object (GL 3 / GLES 3; on GL 2 / GLES 2 a
       framebuffer object) not being there, which a context that does not share objects with
       fogvol's always shows, and a context sharing them too (those objects are never shared). */
    void *(*current_context)(void *user_data);
} fogvol_gl_desc;

/* Multisampled engine framebuffers (GL_SAMPLES > 1 on the framebuffer bound at
   fogvol_end_frame). AUTO: fogvol's targets get the engine's sample count and
   every pass is shaded per sample, so each sample of the engine framebuffer
   gets the fog of its own ray and the engine's resolve averages them; where
   the tier, variants or GLSL dialect cannot (fogvol_msaa_supported) or the
   backend lacks FOGVOL_CAP_MULTISAMPLE, end_frame logs why and returns
   FOGVOL_ERROR_UNSUPPORTED without drawing. SINGLE_SAMPLE (opt-in): single-
   sample targets, one fog value per pixel for all its samples (edges of
   occluders inside fog come out wrong by up to the full fog contrast); logged
   as a warning once and reported in fogvol_frame_stats.msaa_fallback.
   Cost: the per-sample passes shade every sample: 4x MSAA is about 4x the
   fragment work and 4x the target memory of fogvol's passes (measured by
   fogvol's MSAA test, FLOAT at 640x480 on llvmpipe: 4x per sample took
   3.9-4.6x the time of the same scene on a single-sample framebuffer, one
   run each). FLOAT + ENGINE_DEPTH on a software renderer's backend with
   FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE (the GL backend with per-sample
   shading on llvmpipe) shades its faces once per pixel, depth-tested per sample against
   the engine's multisample depth (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST), and only
   its composite per sample. Error at occluder edges inside fog, 4x, resolved, /255: mean
   29.7, max 60 with single-sample targets; mean 1.0, max 2 per sample; with
   ENGINE_DEPTH (its depth copied or read per sample) mean 0.8, max 2, where
   the single-sample fallback's resolved depth gives mean 35.6, max 100. */
typedef enum fogvol_msaa {
    FOGVOL_MSAA_AUTO = 0,
    FOGVOL_MSAA_SINGLE_SAMPLE = 1,
    FOGVOL_MSAA_MAX_ENUM = 0x7fffffff
} fogvol_msaa;
/* What fogvol does when its per-frame overflow count (fogvol_frame_stats.overflow_pixels_late)
   reports pixels with more faces along the ray than the encoding sums. The count needs the backend's
   occlusion queries (GL 1.5+, GLES 3.0; else it stays -1); FLOAT cannot overflow. Its cost: one
   check pass per colour-ramp group (two with SINGLE_TARGET) over an eighth of the group's screen
   rectangle (FOGVOL_SPEEDUP_OVERFLOW_BANDS; over all of it, about what the composite costs, without
   it); FOGVOL_OVERFLOW_OFF removes them (SINGLE_TARGET keeps one for show_overflow). */
typedef enum fogvol_overflow_policy {
    FOGVOL_OVERFLOW_WARN_ONCE = 0,  /* count every frame; log a warning the first time only */
    FOGVOL_OVERFLOW_COUNT_ONLY = 1, /* count every frame; never log */
    FOGVOL_OVERFLOW_LOWER_BITS = 2, /* count; on overflow lower the encoding's L by one (twice the faces,
                                       3 bits less precision: fogvol_context_encoding changes, the lookup
                                       textures are rebuilt after the frame), logged as a warning each
                                       time; the next frame uses it (MRT: the engine takes the new snippet
                                       uniforms from fogvol_mrt_prepare). Counts of frames drawn before the
                                       change do not lower it again. At L = 1 it warns once */
    FOGVOL_OVERFLOW_OFF = 3,        /* no check passes, no queries: overflow_pixels_late stays -1 */
    FOGVOL_OVERFLOW_MAX_ENUM = 0x7fffffff
} fogvol_overflow_policy;

/* fogvol_context_desc holds a fogvol_backend by value, so its fields come after the backend
   table (search "---- context desc"). */
typedef struct fogvol_context_desc fogvol_context_desc;


FOGVOL_API fogvol_result fogvol_create_context(const fogvol_context_desc *desc, fogvol_context **out);
/* Frees everything the context owns, host memory and backend objects: its targets, programs and
   lookup textures, and the meshes, ramps and volume textures made with it that are still alive
   (destroyed with it; a warning in the log counts them: destroy them first). An open frame is
   dropped. */
FOGVOL_API void fogvol_destroy_context(fogvol_context *ctx);
FOGVOL_API fogvol_result fogvol_set_dither(fogvol_context *ctx, int enabled);
FOGVOL_API fogvol_tier fogvol_context_tier(const fogvol_context *ctx, unsigned *variants);

/* ---- meshes --------------------------------------------------------------
   Volumes are closed hulls: every undirected edge used by exactly two
   triangles, in opposite directions; triangles counter-clockwise seen from
   outside. */
typedef enum fogvol_index_type {
    FOGVOL_INDEX_UINT32 = 0, /* fogvol_mesh_desc.indices */
    FOGVOL_INDEX_UINT16 = 1, /* fogvol_mesh_desc.indices16 */
    FOGVOL_INDEX_MAX_ENUM = 0x7fffffff
} fogvol_index_type;

typedef struct fogvol_mesh_desc {
    const float *positions;    /* x, y, z floats per vertex (with offset: the start of the vertex buffer) */
    int vertex_count;
    int stride;                /* bytes between vertices, 0 = 12; at least 12 */
    const uint32_t *indices;   /* 3 per triangle. No index array (indices and indices16 NULL, index_count
                                  0): the triangles are the vertices in order, (0, 1, 2), (3, 4, 5), ...
                                  (vertex_count a multiple of 3: glDrawArrays order, raylib's Mesh
                                  without indices); usually with weld_distance, as its corners repeat */
    int index_count;
    int allow_open;            /* 1: accept open or inconsistent meshes (occluders only) */
    /* Engine vertex buffers as they are: offset is the byte offset of x inside
       each vertex (0 = 0; 0 <= offset, offset + 12 <= stride), so an interleaved
       buffer goes in without copying (backends with FOGVOL_CAP_MESH_LAYOUT,
       the GL backend among them, upload the bytes and read them in place). */
    int offset;
    fogvol_index_type index_type; /* 0 = 32-bit indices; FOGVOL_INDEX_UINT16: indices16 instead */
    const uint16_t *indices16;    /* 3 per triangle, with FOGVOL_INDEX_UINT16 */
    /* > 0: weld before validation: a vertex whose x, y and z each differ by at
       most weld_distance from an earlier kept vertex is merged into it (seams of
       UV spheres, per-face vertices of cubes); the validation, the report and
       the uploaded indices then describe the welded mesh. 0 = off (indices as
       given); negative or non-finite: FOGVOL_ERROR_INVALID_ARGUMENT. */
    float weld_distance;
} fogvol_mesh_desc;

typedef struct fogvol_mesh_report {
    int vertices, triangles;
    int open_edges;            /* undirected edges used by one triangle */
    int nonmanifold_edges;     /* used by more than two */
    int inconsistent_edges;    /* used by two triangles in the same direction */
    int flipped_faces;         /* triangles whose winding disagrees with the majority of their part */
    int degenerate_triangles;  /* repeated index or (near) zero area */
    int nonfinite_vertices;    /* NaN or infinite coordinate */
    int out_of_range_indices;  /* index >= vertex_count */
    int components;            /* edge-connected parts */
    double volume;             /* signed volume (positive for outward winding) */
    int closed;                /* no open and no non-manifold edges */
    int consistent;            /* no inconsistent edge, no flipped face */
    int inverted;              /* closed, consistent, but wound inward (volume < 0) */
    int inward_components;     /* components whose own signed volume is negative: harmless inside
                                  another part (a cavity), refused where nothing encloses them */
    int negative_winding;      /* probes that found a region of negative winding number (entered fewer
                                  times than left): a part wound inward that no other part encloses,
                                  or an inverted lobe of a self-intersecting hull; it would render
                                  negative thickness and subtract from its ramp's other volumes */
    int negative_triangle;     /* a triangle bounding such a region (index / 3 into the indices), -1: none */
    int valid;                 /* usable as a fog volume */
    int welded_vertices;       /* vertices merged into others by the weld (weld_distance > 0), else 0;
                                  vertices counts the rest */
    /* Filled by fogvol_create_mesh for valid volume hulls (fogvol_validate_mesh leaves 0): 1 when
       every vertex the triangles use lies on the inner side of the plane of every non-degenerate
       triangle (both after the weld: triangles it collapses have no plane; vertices of a shared
       buffer that no triangle uses do not count), within 1e-5 of the used vertices' bounding box
       diagonal (a convex hull: usable by fogvol_add_light); 0 when some vertex lies outside some face
       plane (concave); -1 not checked (not a valid hull, or more than 2^26 triangle x vertex
       pairs). */
    int convex;
} fogvol_mesh_report;

/* Checks the mesh; fills *report. Returns FOGVOL_SUCCESS for a valid volume
   hull, FOGVOL_ERROR_INVALID_MESH otherwise (report says why). Scratch memory
   (about 40 bytes per triangle, + 4 per index with 16-bit indices, without an
   index array or when welding, + about 26 per vertex when welding; the weld takes
   O(n) time) comes from alloc (NULL = default). Never reads outside
   the vertex_count vertices (stride, offset) or indices[0 .. index_count).
   FOGVOL_ERROR_INVALID_ARGUMENT for a bad layout (stride < 12, offset + 12 >
   stride, unknown index_type, missing arrays, bad weld_distance). */
FOGVOL_API fogvol_result fogvol_validate_mesh(const fogvol_mesh_desc *desc, const fogvol_allocator *alloc,
                                              fogvol_mesh_report *report);

/* Validates (fogvol_validate_mesh) and uploads. Occluder-only meshes may be
   open (desc->allow_open). *report (may be NULL) receives the check. */
FOGVOL_API fogvol_result fogvol_create_mesh(fogvol_context *ctx, const fogvol_mesh_desc *desc, fogvol_mesh **out,
                                            fogvol_mesh_report *report);
FOGVOL_API void fogvol_destroy_mesh(fogvol_context *ctx, fogvol_mesh *mesh);

/* ---- ramps ---------------------------------------------------------------- */
/* Thickness -> colour ramps. */
typedef enum fogvol_ramp_model {
    FOGVOL_RAMP_EXTINCTION = 0, /* rgb = color, a = 1 - exp(-density * t) */
    FOGVOL_RAMP_LINEAR = 1,     /* rgb = color, a = clamp01(t * density) (fog = 1 - a, the GDC 2001 analytic fog law) */
    FOGVOL_RAMP_GRADIENT = 2,   /* artist keys, linear interpolation of RGBA */
    FOGVOL_RAMP_MODEL_MAX_ENUM = 0x7fffffff
} fogvol_ramp_model;

/* Colour space. Ramp colours are used as given: the texel bytes are the
   fragment colour the composite outputs, and GL blends it with the engine's
   target like any draw. So
   - an sRGB engine target (e.g. GL_SRGB8_ALPHA8) with GL_FRAMEBUFFER_SRGB
     enabled: the colours are linear; GL decodes the target, blends in linear
     light and encodes the result (fogvol leaves FRAMEBUFFER_SRGB as the
     engine set it);
   - a linear-format target (RGBA8, the default framebuffer), or
     FRAMEBUFFER_SRGB disabled: colours and blending are in the space of the
     stored values (usually sRGB-encoded: give sRGB colours).
   The gradient model interpolates the keys in the space they are given in.
   fogvol's own RGBA8 and R32F targets are linear formats, which
   FRAMEBUFFER_SRGB does not affect. */
typedef enum fogvol_blend {
    FOGVOL_BLEND_FOG = 0,   /* scene = mix(scene, rgb, a) */
    FOGVOL_BLEND_LIGHT = 1, /* scene += rgb * a (volume light, Baker's "Image-Space Rendering Techniques") */
    FOGVOL_BLEND_MAX_ENUM = 0x7fffffff
} fogvol_blend;

typedef struct fogvol_color_key {
    float thickness; /* world units */
    float rgba[4];   /* [0,1] */
} fogvol_color_key;

typedef struct fogvol_ramp_desc {
    fogvol_ramp_model model;
    float color[3];
    float density;               /* per world unit (extinction, linear) */
    float max_thickness;         /* thickness of the last texel; 0 = auto: extinction 7/density,
                                    linear 1/density, gradient the last key */
    const fogvol_color_key *keys; /* gradient: key_count >= 1, any order */
    int key_count;
    int width;                   /* texels, 0 = 256, 2..4096 */
    fogvol_blend blend;          /* used by the renderer */
    /* EXTINCTION with FOGVOL_VARIANT_COLORS: the extinction per colour channel is
       density * extinction_color (all 0 = (1, 1, 1): grey, the same in every channel); each
       component finite and >= 0. Only the one-pass colour group can use a colour that is not
       grey: the colour ramp texture (and so every other path) has one alpha per pixel and uses
       density alone (create_ramp logs a warning for a non-grey colour without the variant). */
    float extinction_color[3];
    /* Soft edges (0 = off: uniform density up to the boundary, the old behaviour; else finite, > 0;
       in the units of thickness: view depth, world units for a view matrix without scale). The
       density rises linearly from 0 over a distance s = softness from both ends of every chord of
       the fog along a ray (entry and exit: the volume's faces, the opaque surface that cuts it, the
       near plane), so silhouettes and the places where fog meets opaque geometry fade:
           density(x) = density * min(1, (x - a) / s, (b - x) / s)   on a chord [a, b]
       whose optical thickness is f(b - a), f(t) = t^2 / (4 s) for t < 2 s, t - s for t >= 2 s.
       The composite applies f to the group's summed thickness t and looks the ramp up at f(t)
       (every model: the gradient's keys are at the softened thickness). Exact where a ray
       crosses one chord of the group's volumes (one convex volume, or volumes apart on screen).
       Where it crosses k > 1 chords (a concave volume, overlapping volumes of one ramp) f(sum)
       >= sum f (f is convex, f(0) = 0): the fog is denser than the model by at most (k - 1) s
       of thickness (each inner end counts as inside); negative volumes subtract their chord
       before f. A density-textured volume sums rho * chord (see fogvol_volume_desc.density):
       f(rho t) = rho f_{s/rho}(t), its edge ramp is s / rho long where the density factor is rho.
       Every tier and variant (the composite does it); a soft ramp does not join the one-pass
       colour group of FOGVOL_VARIANT_COLORS (it keeps a group of its own). The debug read-back
       (fogvol_frame_desc.debug_thickness) gives t, not f(t). README: "Soft edges". */
    float softness;
} fogvol_ramp_desc;

FOGVOL_API fogvol_result fogvol_create_ramp(fogvol_context *ctx, const fogvol_ramp_desc *desc, fogvol_ramp **out);
FOGVOL_API void fogvol_destroy_ramp(fogvol_context *ctx, fogvol_ramp *ramp);

/* ---- frames: camera, occluders, volumes, lights; MRT and engine-drawn occluders ---- */
/* Since 0.2 the two values draw the same: one full-screen triangle per ramp group, scissored to the
   window rectangle of the group's volumes (the 8 corners of each mesh's bounding box projected; the
   whole viewport when a box reaches behind the near plane), which saves fill rate when the volumes
   cover little of the screen; the engine's stencil buffer is left alone. (0.1 scissored FULLSCREEN
   only with FOGVOL_SPEEDUP_SCISSOR, which is gone; GEOMETRY stays for source compatibility.) */
typedef enum fogvol_composite {
    FOGVOL_COMPOSITE_FULLSCREEN = 0, /* the default */
    FOGVOL_COMPOSITE_GEOMETRY = 1    /* the same as FULLSCREEN */
} fogvol_composite;

/* What the composite does to the alpha of the engine's colour target. */
typedef enum fogvol_alpha {
    FOGVOL_ALPHA_KEEP = 0,    /* dst.a unchanged (RGB blended with the ramp's alpha a) */
    FOGVOL_ALPHA_COVERAGE = 1 /* dst.a = a + dst.a * (1 - a): the fog's coverage, "over" operator */
} fogvol_alpha;

typedef struct fogvol_frame_stats {
    int passes;             /* passes issued this frame */
    int volumes, occluders; /* drawn */
    int groups;             /* colour-ramp groups composited */
    int overflow_pixels;    /* pixels whose sums saturated (only counted when debug_thickness is set) */
    int samples;            /* samples per pixel of fogvol's targets this frame (1: single-sample) */
    int msaa_fallback;      /* 1: the engine framebuffer was multisampled and FOGVOL_MSAA_SINGLE_SAMPLE
                               drew one fog value per pixel */
    /* Overflow counted on the GPU every frame, no read-back, no stall: a full-screen check pass per
       colour-ramp group (two with SINGLE_TARGET: after the additions and after the subtractions)
       discards the pixels whose sums did not saturate, and an occlusion query counts the rest; the
       result is read a frame or more later, when the GPU has it (up to 4 frames in flight; a frame
       that finds all 4 still waiting, or with more than 32 check passes, is not counted).
       overflow_pixels_late: pixels with a saturated sum in frame overflow_frame (multisampled: its
       saturated samples over the sample count, rounded up), summed over the
       colour-ramp groups (GLES 3: 1 = some), -1 = none known yet or no queries (FOGVOL_OVERFLOW_OFF,
       or a backend without them); FLOAT: always 0 for this frame. With FOGVOL_SPEEDUP_OVERFLOW_BANDS
       (the default) a frame checks one of FOGVOL_OVERFLOW_BANDS horizontal bands of each group's
       rectangle, in turn, and the count is the sum of each band's newest count (frame
       overflow_frame holds the newest band): the whole picture once every 8 frames. */
    int overflow_pixels_late;
    int64_t overflow_frame;  /* the frame overflow_pixels_late counts (-1 = none) */
    int64_t frame;           /* this frame's number: 0, 1, ... per context (end_frame calls) */
    int overflow_passes;     /* check passes issued this frame (not included in passes) */
    int lights;              /* light volumes drawn (fogvol_add_light), 2 passes each */
    int depth_tested;        /* 1: the faces were depth-tested against the occluders and counted (the
                                COUNT variant, or FOGVOL_SPEEDUP_DEPTH_TEST took this frame) */
    int fetched_o;           /* 1: a face pass read O from the framebuffer (FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH) */
    int engine_depth_tested; /* 1: FLOAT + ENGINE_DEPTH drew this frame's faces depth-tested against the
                                engine's depth (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST) */
    int exact_sum;           /* groups summed as 32-bit integers (FOGVOL_SPEEDUP_EXACT_SUM) */
    int inline_resolved;     /* 1: PS13 resolved B - F in its composite (FOGVOL_SPEEDUP_INLINE_RESOLVE): one
                                pass per group fewer than fogvol_tier_costs counts */
    /* The thickness step of this frame's RGBA8 digit sums, in view depth: (zfar - znear) / 2^(3L)
       (WIDE: 2^(6L)); every pixel's thickness is within about one step per pair of faces. 0 when no
       group summed in digits (FLOAT, FOGVOL_SPEEDUP_EXACT_SUM). When it is coarser than 1/16 of the
       view-depth extent of the bounds of the frame's smallest volume, a warning is logged (on the
       first such frame, and again after a frame that was not): move znear out or zfar in, or use
       fewer faces per target (fogvol_context_desc.encoding_bits) or the FLOAT tier. */
    float depth_lsb;
} fogvol_frame_stats;

typedef enum fogvol_depth_source {
    FOGVOL_DEPTH_SOURCE_TEXTURE = 0,            /* fogvol_frame_desc.engine_depth_texture */
    FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER = 1,  /* the depth buffer of the draw framebuffer bound at end_frame */
    FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT = 2, /* the depth buffer of engine_depth_framebuffer */
    FOGVOL_DEPTH_SOURCE_MAX_ENUM = 0x7fffffff
} fogvol_depth_source;

/* What the frame's camera is given as (fogvol_frame_desc.camera). */
typedef enum fogvol_camera {
    FOGVOL_CAMERA_VIEW_AND_PROJECTION = 0, /* view and projection */
    FOGVOL_CAMERA_VIEW_PROJECTION = 1      /* view_projection (clip from world), eye and forward */
} fogvol_camera;

/* Derives the planes of a projection (perspective, reversed, infinite or orthographic).
   zero_to_one: 1 if the projection maps the depth range to NDC z in [0,1] (D3D style, for
   glClipControl ZERO_TO_ONE), 0 for [-1,1]; reversed projections (z_ndc high at near) are
   recognised. Perspective projections need w = -s * z_view (s > 0), orthographic ones w
   constant > 0; anything else, or planes that are not 0 < near < far (near > 0 for
   perspective), is FOGVOL_ERROR_INVALID_ARGUMENT. An infinite far plane gives infinite = 1
   and zfar = 0: choose the far limit of the thickness range yourself. */
typedef struct fogvol_projection_info {
    float znear, zfar;
    int orthographic; /* 1: w constant */
    int reversed;     /* 1: NDC z decreases with distance */
    int infinite;     /* 1: no far plane */
} fogvol_projection_info;
FOGVOL_API fogvol_result fogvol_projection_planes(const float projection[16], int zero_to_one,
                                                  fogvol_projection_info *out);

/* Camera: any projection whose clip w is the view depth times a positive constant
   (perspective: standard, reversed-Z, [0,1] or [-1,1] depth, infinite far, jittered,
   oblique near plane) or a positive constant (orthographic); others are refused with
   FOGVOL_ERROR_INVALID_ARGUMENT. fogvol computes its own clip depth from znear and zfar,
   so the projection's depth convention does not matter to it (only to the engine depth
   texture, see fogvol_frame_info), and decides the winding from how the projection
   orients the screen (mirrored x or y flip it). Matrices are column-major (m[column * 4 +
   row], as glUniformMatrix4fv with transpose = GL_FALSE): a view matrix must be affine
   (bottom row m[3], m[7], m[11], m[15] = 0, 0, 0, 1), and a perspective projection whose
   w row stands in column 3 (m[14] = +-1, m[11] not) is taken for a transposed one; both
   are refused (FOGVOL_ERROR_INVALID_ARGUMENT), and the log says "transposed?" with the
   matrices that transposed would be accepted. Row-major engine matrices (raylib's Matrix,
   DirectXMath's XMFLOAT4X4 in a row-vector convention) must be transposed when copied
   (raylib: MatrixToFloat gives the column-major order). */
typedef struct fogvol_frame_desc {
    float view[16];
    float projection[16];
    float znear, zfar;      /* the planes the thickness is measured between; 0 < znear < zfar (view
                               depth from the eye; fogvol clips at znear, counts beyond zfar as at zfar) */
    int viewport[4];        /* x, y, width, height in the engine framebuffer: x and y within -32768..32767,
                               width and height 1..16384 (else FOGVOL_ERROR_INVALID_ARGUMENT) */
    fogvol_composite composite;
    /* The engine's draw buffer the composite writes (index into its
       glDrawBuffers list; 0 = the first, the only one for most engines); the
       other draw buffers stay byte-identical. GL: an index past
       GL_MAX_DRAW_BUFFERS, one whose buffer is GL_NONE, or > 0 on the default
       framebuffer or on OpenGL ES (where list position i can only name
       COLOR_ATTACHMENTi) makes end_frame fail with FOGVOL_ERROR_UNSUPPORTED. */
    int draw_buffer;
    fogvol_alpha alpha;     /* 0 = FOGVOL_ALPHA_KEEP */
    int show_overflow;      /* 1: paint pixels whose face sums saturated in magenta (every RGBA8 tier and
                               variant; SINGLE_TARGET runs one check pass after its additions for it,
                               into the overflow mask V); FLOAT cannot saturate */
    /* Debug read-back of the decoded thickness per pixel of the viewport, rows
       bottom to top, for the group of debug_ramp (NULL = the first group). Set
       debug_thickness to a width*height float buffer. Units: view-space w (the
       distance along the view axis, world units when the view matrix has no
       scale), between znear and zfar; this read-back stalls, for debugging only.
       A frame that draws no volume of debug_ramp (or none at all) writes 0
       everywhere. The one-pass colour group (FOGVOL_VARIANT_COLORS) sums optical
       depths of all its ramps: its read-back is the thickness of debug_ramp's
       volumes alone (NULL: the ramp of the group's first volume), summed in one
       more pass. */
    float *debug_thickness;
    const fogvol_ramp *debug_ramp; /* (not with a multisampled engine framebuffer drawn per
                                      sample: end_frame returns FOGVOL_ERROR_UNSUPPORTED) */
    /* FOGVOL_VARIANT_ENGINE_DEPTH: the engine's depth texture (backend API
       object, GL: texture name), sampled with its .r; its window depth is mapped back
       to view depth through the inverse of projection * view (any projection above) and
       the depth conventions the backend reports (fogvol_frame_info) unless overridden by
       the two fields below. In a frame drawn per sample (a multisampled engine
       framebuffer, FOGVOL_MSAA_AUTO) it is a multisample texture of the framebuffer's
       sample count (GL: GL_TEXTURE_2D_MULTISAMPLE), read at each sample. It is read as
       it is at each end_frame. */
    fogvol_native engine_depth_texture;
    int engine_depth_zero_to_one; /* 0 = as reported; 1: NDC z in [0,1]; -1: NDC z in [-1,1] */
    float engine_depth_range[2];  /* both 0 = as reported; else the glDepthRange it was drawn with */
    /* camera input: FOGVOL_CAMERA_VIEW_PROJECTION reads view_projection, eye and forward
       (world-space direction the camera looks, any length) instead of view and projection;
       view depth is then measured along forward from eye */
    fogvol_camera camera;
    float view_projection[16];
    float eye[3], forward[3];
    /* FOGVOL_VARIANT_ENGINE_DEPTH: where the depth comes from (0 = engine_depth_texture).
       The other sources are depth buffers that cannot be sampled (the default
       framebuffer's, renderbuffers, multisampled ones): at every end_frame fogvol
       copies the viewport's depth as it is then into a depth texture of its own
       (GL: glBlitFramebuffer into a texture of the source's exact depth/stencil
       format; needs GL 3.0 / GLES 3.0 / ARB_framebuffer_object, else
       FOGVOL_ERROR_UNSUPPORTED), so every frame and every view of a frame (split
       screen: one begin/end_frame per viewport) reads its own depth. Single-sample
       frames: a multisampled source is resolved to one sample per pixel. Frames drawn
       per sample: every sample is copied, from a source of the engine framebuffer's
       sample count (the bound framebuffer, or that framebuffer by name); a single-sample
       source gives each pixel's depth to all its samples (desktop GL; OpenGL ES:
       FOGVOL_ERROR_UNSUPPORTED); another sample count: FOGVOL_ERROR_INVALID_ARGUMENT. */
    fogvol_depth_source engine_depth_source;
    fogvol_native engine_depth_framebuffer; /* FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT: its API object
                                           (GL: framebuffer name, 0 = the default framebuffer) */
    /* 0 or 1: fogvol's sums at the viewport's resolution. 2: at half its width and height
       (rounded up): the O and face passes shade a quarter of the fragments and the composite
       upsamples the thickness bilinearly (FOGVOL_SPECIALIZE_DOWNSAMPLE); debug_thickness gets
       the same upsampled values. The edges of volumes and occluders blur over a low-resolution
       pixel (docs/FEATURES.md, "half resolution", gives the measured error). FLOAT tier without
       ENGINE_DEPTH or COLORS, single-sample, no fogvol_add_light, no fogvol_occluder_prepare;
       otherwise end_frame returns FOGVOL_ERROR_UNSUPPORTED (logged). Other values:
       FOGVOL_ERROR_INVALID_ARGUMENT. */
    int downsample;
    /* The dither pattern's frame (RGBA8 tiers with dithering on; engines that accumulate frames,
       e.g. TAA): 0 = the fixed 8x8 ordered pattern, the same every frame. Any other value n rotates
       every pixel's rounding threshold by bitrev3(n mod 8) / 8 of an LSB (n mod 8 = 0, 1, 2, ... ->
       0, 1/2, 1/4, 3/4, 1/8, 5/8, 3/8, 7/8: period 8, each run of 2, 4, 8 frames stratified), so a
       pixel's values over 8 consecutive frames average to within 1/8 LSB of the exact depth and the
       block bias of the fixed pattern on depth gradients averages away: pass the engine's frame
       counter. Measured (test_looks: linear depth gradients of slopes -2..2 LSB per pixel, any
       offset and block position, L = 4): the worst 8x8 block mean of a pair of faces (B - F) over
       1 / 4 (frames 4k..4k+3) / 8 frames is 0.44 / 0.068 / 0.042 LSB (a longer search: 0.50 / 0.088 /
       0.045); on a rendered sphere and box against FLOAT 0.122 / 0.028 / 0.016 LSB. The MRT and
       occluder snippets' uniforms carry it (fogvol_mrt_prepare, fogvol_occluder_prepare after
       begin_frame). FLOAT: no effect. */
    int dither_frame;
} fogvol_frame_desc;

/* Frames: begin_frame, any number of add_* calls, end_frame. Nothing touches
   the GPU before end_frame. A begin_frame while a frame is open discards the
   open frame (logged as a warning).
   GL backend, the engine's state (restored, or set for fogvol's passes and
   restored: the list is at FOGVOL__GL_ENABLES in the GL backend): GL errors
   the engine left pending are still pending after every fogvol call, and
   nothing else (out-of-memory and context-loss codes cannot be raised again:
   logged as a warning); they are raised again with GL_DEBUG_OUTPUT switched off
   where the context has KHR_debug (GL 4.3, GLES 3.2 or the extension), so the
   engine's debug callback and message log get no message for them (without
   KHR_debug, e.g. ARB_debug_output alone, each raise reaches its callback as
   one message). GL errors fogvol's own calls raise are the call's result
   (FOGVOL_ERROR_BACKEND), logged, never left pending. fogvol must be called
   with the GL context current that it was created in (a context sharing its
   objects is not enough: vertex array and framebuffer objects are never
   shared); with another current every call that would touch GL returns
   FOGVOL_ERROR_INVALID_STATE, logged, and touches nothing (see
   fogvol_gl_desc.current_context); an active transform feedback is paused
   during the call (GL 4.0 / GLES 3.0; on GL 3.x, where it cannot be queried,
   do not call fogvol inside one); an occlusion or PRIMITIVES_GENERATED query the engine has running
   counts fogvol's draws too (GL cannot pause those; fogvol then skips its
   own overflow query for the frame); fogvol must not be called between
   glBeginConditionalRender and glEndConditionalRender (not queryable: its
   passes could be skipped). */
FOGVOL_API fogvol_result fogvol_begin_frame(fogvol_context *ctx, const fogvol_frame_desc *desc);
FOGVOL_API fogvol_result fogvol_add_occluder(fogvol_context *ctx, const fogvol_mesh *mesh, const float model[16]);
/* The callback runs inside the O pass with the depth-encode program bound:
   for each engine draw call fogvol_occluder_transform(ctx, model) first and
   keep the position in vertex attribute 0; change no other state. */
typedef void (*fogvol_occluder_fn)(fogvol_context *ctx, void *user_data);
FOGVOL_API fogvol_result fogvol_add_occluder_callback(fogvol_context *ctx, fogvol_occluder_fn fn, void *user_data);
FOGVOL_API fogvol_result fogvol_occluder_transform(fogvol_context *ctx, const float model[16]);

typedef struct fogvol_volume_texture fogvol_volume_texture; /* fogvol_create_volume_texture */
typedef struct fogvol_volume_desc {
    const fogvol_mesh *mesh;
    float model[16];          /* column-major, affine (bottom row 0, 0, 0, 1), not singular (a zero
                                 scale leaves no volume): else FOGVOL_ERROR_INVALID_ARGUMENT, logged
                                 ("transposed?" when its transpose is affine). Occluder and light
                                 model matrices: the same (an occluder may be flat, not all zero) */
    const fogvol_ramp *ramp;  /* volumes sharing a ramp sum their thickness */
    int negative;             /* 1: subtracts thickness from the volumes of its ramp */
    /* Density texture (NULL = none: uniform density, the old behaviour). Its red channel is a
       density factor rho in [0,1] sampled on every face fragment at the surface point, with
       texture coordinates s = dot(density_map[0..3], (p, 1)), t = dot(density_map[4..7], (p, 1))
       from the model-space position p (all 8 zero: s = x, t = y). Scroll it for drifting fog by
       adding velocity * time to density_map[3] and [7] every frame; a 1-texel-high gradient with
       FOGVOL_WRAP_CLAMP and s along a shaft's axis thins a light shaft towards its base.
       What is summed: each face adds v = c + rho * (min(d, o) - c) instead of min(d, o) (d the
       face's depth, o the opaque depth, c = min(o, depth of the centre of the volume's bounds),
       c = 0 when the bounds reach nearer than znear). A closed hull's faces enter and leave
       every ray equally often, so the c terms cancel and each chord [a, b] of the volume (b
       clamped to o) contributes  rho_b (b - c) - rho_a (a - c)  (rho_a, rho_b: the density at
       the entry and exit faces' surface points, also where the exit face is hidden behind o).
       Exact (= rho * (b - a)) when the density is the same at both ends of every chord: a
       density that does not vary along the rays (a 2D texture projected along the view
       direction, e.g. an orthographic camera looking along the texture's projection axis, or a
       density varying only across the screen). A chord hidden behind o entirely adds nothing
       when o <= the centre depth (both faces add o). Otherwise an approximation, a two-point
       rule: with rho_m the mean density along the chord the error per chord is
       (rho_b - rho_m) (b - c) - (rho_a - rho_m) (a - c), at most the density contrast along the
       chord times (|a - c| + |b - c|), i.e. about the contrast times the volume's depth extent.
       RGBA8 tiers encode v like any depth (1 LSB per face). Tiers FLOAT, PS20 and MRT (with
       SINGLE_TARGET, ALU, NEAR_CLAMP, ENGINE_DEPTH); PS13 (mediump cannot re-encode), COUNT
       (the opaque depth it adds per missing back face carries no density) and WIDE:
       fogvol_add_volume returns FOGVOL_ERROR_UNSUPPORTED, logged. A textured volume costs one
       more pass per sum pass. */
    const fogvol_volume_texture *density;
    float density_map[8];
    /* Colour texture (NULL = none): the composite multiplies the ramp colour's rgb by the
       texture's rgb at s = dot(color_map[0..2], (x, y, 1)), t = dot(color_map[3..5], (x, y, 1)),
       (x, y) the pixel's position across the viewport in [0,1] (all 6 zero = s = x, t = y).
       The composite draws one colour-ramp group at a time, so the volumes of one ramp share one
       colour texture: a volume whose colour texture or map differs from an earlier volume of
       its ramp in this frame is refused (FOGVOL_ERROR_INVALID_ARGUMENT, logged); volumes
       without one take the group's. Every tier and dialect. */
    const fogvol_volume_texture *color;
    float color_map[6];
} fogvol_volume_desc;
FOGVOL_API fogvol_result fogvol_add_volume(fogvol_context *ctx, const fogvol_volume_desc *desc);

/* Textures for volumes (density, colour): RGBA8, rows bottom to top, desc->filter and wrap
   as given (width, height 1..4096; pixels required). */
FOGVOL_API fogvol_result fogvol_create_volume_texture(fogvol_context *ctx, const fogvol_texture_desc *desc,
                                                      fogvol_volume_texture **out);
/* Inside a frame, the volumes that use it are dropped from the frame (logged). */
FOGVOL_API void fogvol_destroy_volume_texture(fogvol_context *ctx, fogvol_volume_texture *texture);

/* Volume light by compare: the scene pixels whose opaque depth (fogvol's occluders, the MRT
   target or the engine's depth texture: whatever the tier's O is) lies between the depth of
   the light volume's front face and its back face are lit: colour * intensity is added to
   them (the engine framebuffer's RGB; alpha kept); pixels outside the volume, in front of it
   or behind it, are untouched. A scene point is inside a convex volume exactly when its depth
   lies between the one front and the one back face on its ray, so the mesh must be convex
   (fogvol_mesh_report.convex == 1); a concave mesh is refused with FOGVOL_ERROR_INVALID_MESH
   and a logged message. A camera inside the light works (no front face: from the near plane).
   Lights are drawn after the opaque depth and before the fog groups, so fog covers lit pixels.
   RGBA8 tiers compare depths decoded from the encoding (12 bits by default: a pixel within
   about one encoding LSB of the volume's surface may fall either way). Tiers FLOAT, PS20 (not
   WIDE) and MRT; PS13 and WIDE: FOGVOL_ERROR_UNSUPPORTED, logged. Two passes per light. */
typedef struct fogvol_light_desc {
    const fogvol_mesh *mesh;  /* closed, convex */
    float model[16];
    float color[3];           /* added to lit pixels */
    float intensity;          /* 0 = 1 */
    /* Falloff with distance (falloff_radius 0 = none: the same colour on every lit pixel, the old
       behaviour; else finite, > 0): each lit pixel gets colour * intensity * w(r), r the world
       distance from its scene point to position (world space), w(r) = (1 - (r / R)^2)^2 for
       r < R = falloff_radius and 0 beyond (a smooth window: 1 at the light, no slope at R). The
       scene point is rebuilt from the pixel's ray and its opaque depth (any camera fogvol_frame_desc
       accepts; RGBA8 tiers: the decoded depth, 12 bits by default). */
    float position[3];
    float falloff_radius;
    /* Soft edge (0 = none; else finite, > 0, view depth units): the lit colour is also multiplied by
       clamp(m / edge_softness, 0, 1), m the distance along the view axis from the scene point to the
       nearer of the light volume's front and back faces on its ray (only the back face for a camera
       inside the light), so the lit region fades where the scene surface meets the light's walls. */
    float edge_softness;
} fogvol_light_desc;
FOGVOL_API fogvol_result fogvol_add_light(fogvol_context *ctx, const fogvol_light_desc *desc);
FOGVOL_API fogvol_result fogvol_end_frame(fogvol_context *ctx, fogvol_frame_stats *stats);
FOGVOL_API fogvol_result fogvol_cancel_frame(fogvol_context *ctx);

/* MRT tier, after fogvol_begin_frame and before the engine's opaque pass:
   makes the O texture the size of the frame's viewport (this touches the GPU,
   state restored) and returns what the engine needs: the texture to attach as
   its second colour target (backend API object, GL: texture name), the colour
   to clear that attachment to before drawing ("far"), the values of the
   snippet's uniform vec4 fogvol_mrt[2], and the texture's format: RGBA8 (the
   encoded depth) or, with FOGVOL_SPEEDUP_FLOAT_O, R32F (the normalised view
   depth; the snippet writes it when its uniforms say so, the engine changes
   nothing). The engine's framebuffer must be viewport-sized with origin (0,0),
   and its pass must not blend into the attachment. */
typedef struct fogvol_mrt_info {
    fogvol_native texture;
    float clear_color[4];
    float uniforms[8];
    fogvol_format format;
} fogvol_mrt_info;
FOGVOL_API fogvol_result fogvol_mrt_prepare(fogvol_context *ctx, fogvol_mrt_info *info);
/* MRT tier: GLSL for the engine's opaque fragment shader. It declares
   uniform vec4 fogvol_mrt[2] (values from fogvol_mrt_prepare) and
   vec4 fogvol_encode_view_depth(float view_depth), whose result the engine
   writes to its second colour output (fogvol_encode_depth's bytes; computed in
   integers where the engine's GLSL has bit operations and floatBitsToInt: 330+,
   300 es; with an R32F O, fogvol_mrt[0].z = 0: the normalised view depth in
   red). Insert after the #version line and the engine's precision statements.
   GLSL for Vulkan (no loose uniforms): declare vec4 fogvol_mrt[2] in one of the engine's own
   uniform blocks or push constants and #define FOGVOL_MRT_IN_BLOCK before the snippet. */
FOGVOL_API const char *fogvol_mrt_snippet(void);

/* Occluders drawn by the engine with its own programs, pipelines and vertex
   layouts (PS20 without COUNT/WIDE, and FLOAT without ENGINE_DEPTH; other
   configurations: FOGVOL_ERROR_UNSUPPORTED). After fogvol_begin_frame and
   before fogvol_end_frame: makes fogvol's O target the size of the viewport
   (touches the GPU, state restored) and returns what the engine needs to draw
   its occluders into it: attach texture as the only colour target of a
   framebuffer of width x height with the engine's own depth buffer (of
   info.samples samples: multisampled where the engine framebuffer bound now
   is drawn per sample, and bound again for end_frame), clear
   colour to clear_color and depth to "far", draw with a depth test that keeps
   the nearest surface, and write fogvol_occluder_color(view_depth) from
   fogvol_occluder_snippet() (view_depth: the distance along the view axis,
   -z in view space) as the fragment colour, with fogvol_mrt[2] set to
   uniforms. end_frame then uses what the engine drew instead of its own O
   pass; fogvol_add_occluder* in the same frame is refused. */
typedef struct fogvol_occluder_info {
    fogvol_native texture;        /* backend API object (GL: texture name) */
    int width, height;
    int samples;              /* 0: a single-sample texture (GL_TEXTURE_2D); n > 1: the engine
                                 framebuffer bound now has n samples and fogvol draws per sample, so
                                 texture is multisampled (GL_TEXTURE_2D_MULTISAMPLE), to be drawn with
                                 a depth buffer of n samples; end_frame must find the same count */
    fogvol_format format;     /* RGBA8 (PS20: encoded depth) or R32F (FLOAT, and PS20 with
                                 FOGVOL_SPEEDUP_FLOAT_O: d = (view depth - near)/(far - near)) */
    float clear_color[4];
    float uniforms[8];        /* uniform vec4 fogvol_mrt[2] of the snippet */
} fogvol_occluder_info;
FOGVOL_API fogvol_result fogvol_occluder_prepare(fogvol_context *ctx, fogvol_occluder_info *info);
/* GLSL for the engine's occluder fragment shader (any dialect): fogvol_mrt_snippet()
   plus vec4 fogvol_occluder_color(float view_depth). Insert after the #version
   line and the engine's precision statements. */
FOGVOL_API const char *fogvol_occluder_snippet(void);

/* ---- image-space effects ---------------------------------------------------
   Screen-space passes over the engine's depth (and colour, normals), drawn
   into the framebuffer bound when they are called, GL state restored like a
   frame. Call them outside a frame (not between fogvol_begin_frame and
   fogvol_end_frame: FOGVOL_ERROR_INVALID_STATE). Each desc points at a
   fogvol_frame_desc that supplies the camera (view and projection, or
   view_projection + eye + forward), znear < zfar (validated as for a frame;
   not used otherwise), the viewport written, draw_buffer, alpha (outlines,
   distance fog) and the engine depth texture with its conventions:
   engine_depth_texture (required: FOGVOL_ERROR_INVALID_ARGUMENT without it),
   engine_depth_zero_to_one and engine_depth_range (0 = as the backend reports
   the context's clip control and depth range). View depth e is the distance
   along the view axis, recovered from window depth exactly as the
   ENGINE_DEPTH variant does (any projection fogvol_frame_desc accepts:
   reversed-Z, [0,1] depth, infinite far, orthographic).
   Engine textures (GL texture names) are read at texel centres, texel =
   framebuffer pixel (the texture covers the framebuffer from its origin);
   texture_size 0 = (viewport x + width, viewport y + height). Taps outside
   the viewport are clamped to its edge pixels. A texture sampled must not be
   attached to the framebuffer written. Needs FOGVOL_CAP_DEPTH_TEXTURE and
   FOGVOL_CAP_HIGHP_FRAGMENT (view depth from window depth in mediump is
   useless): else FOGVOL_ERROR_UNSUPPORTED. Every GLSL dialect fogvol has
   (110 ... 330 core, ES 100 with highp, ES 300) compiles every effect. */
typedef enum fogvol_post_effect {
    FOGVOL_POST_DOF = 0,          /* depth of field */
    FOGVOL_POST_OUTLINES = 1,     /* edges from depth (and normal) deltas */
    FOGVOL_POST_DISTANCE_FOG = 2, /* a colour ramp of view depth */
    FOGVOL_POST_EFFECT_COUNT = 3
} fogvol_post_effect;

/* Depth of field with the edge-preserving moving kernel (Baker, "Image-Space
   Rendering Techniques"), gathered over the whole circle of confusion.
   Out-of-focus amount c(e) = clamp(|e - focus_distance| / focus_range, 0, 1);
   the centre pixel's radius r = c(e0) * max_radius; taps k = 0 .. taps-1 on a
   golden-angle spiral that covers the disc of radius r evenly: at offsets
   round(r sqrt((k + u) / taps) (cos t_k, sin t_k)) pixels, t_k = 2.39996 k + a,
   the spiral turned and its radii jittered per pixel by a = 2 pi IGN(p),
   u = IGN(p.yx + (37, 91)), p = pixel + 5.588238 (dither_frame mod 64)
   (interleaved gradient noise): neighbouring pixels' taps never line up, so
   blurred regions show fine grain instead of copies of the taps or a pattern,
   and an engine that accumulates frames (TAA) averages the grain away by passing
   its frame counter in frame->dither_frame. Each tap enters as mix(C0, Ck, c(ek)),
   weighted by its own out-of-focus amount so in-focus pixels never bleed into
   blurred ones, and out = sum_k mix(C0, Ck, c(ek)) / taps on RGBA, written without
   blending (in-focus pixels keep their colour exactly). Against a continuous disc
   blur (README "Depth of field": measured by test_post): the grain's RMS and the
   error of 4x4 block means, one frame and 8 frames. */
typedef struct fogvol_dof_desc {
    const fogvol_frame_desc *frame;
    fogvol_native color_texture; /* the scene's colour (GL texture name), required */
    int texture_size[2];     /* of the colour and depth textures; 0 = from the viewport */
    float focus_distance;    /* view depth in focus (> 0) */
    float focus_range;       /* distance from focus_distance at which the blur is full (> 0) */
    float max_radius;        /* pixels, 0 = 4, at most 64 */
    int taps;                /* 0 = 24; 3, 6, 12, 24 or 48 (more taps: less grain, more time) */
} fogvol_dof_desc;
FOGVOL_API fogvol_result fogvol_post_dof(fogvol_context *ctx, const fogvol_dof_desc *desc);

/* Outlines (cel-shading look) by a 3x3 moving kernel. Depth: with g = 1/e
   (perspective; e for orthographic), which is linear across the screen on any
   plane, an edge is where a line of three pixels through the centre
   (horizontal, vertical, both diagonals, both ends inside the viewport) has
   |g(-o) + g(+o) - 2 g0| > depth_threshold * |g0|: depth discontinuities and
   creases, never a flat slope. Normals (optional): n = 2 rgb - 1 normalised,
   an edge where 1 - dot(n0, nk) > normal_threshold for one of the 8
   neighbours. Edge pixels get color blended like the fog composite
   (rgb = mix(rgb, color.rgb, color.a)); the others are untouched. */
typedef struct fogvol_outline_desc {
    const fogvol_frame_desc *frame;
    fogvol_native normal_texture; /* 0 = depth only; else rgb = normal * 0.5 + 0.5 (any space) */
    int texture_size[2];      /* of the depth (and normal) texture; 0 = from the viewport */
    float color[4];           /* rgb, a = opacity; all 0 = opaque black */
    float depth_threshold;    /* relative second difference, 0 = 0.05 */
    float normal_threshold;   /* 1 - cos(angle), 0 = 0.3 */
} fogvol_outline_desc;
FOGVOL_API fogvol_result fogvol_post_outlines(fogvol_context *ctx, const fogvol_outline_desc *desc);

/* Image-space distance fog: thickness t = max(e - start, 0) looked up in a
   colour ramp exactly as the volume composite does (texel i holds
   i / (width - 1) * max_thickness, linear filtering, clamped at the ends) and
   blended by the ramp's blend (FOG: rgb = mix(rgb, ramp.rgb, ramp.a); LIGHT:
   rgb += ramp.rgb * ramp.a) over the viewport. Pixels at the far plane (sky)
   get the fog of e = zfar of the projection (infinite: the ramp's end). */
typedef struct fogvol_distance_fog_desc {
    const fogvol_frame_desc *frame;
    const fogvol_ramp *ramp;  /* required */
    int texture_size[2];      /* of the depth texture; 0 = from the viewport */
    float start;              /* view depth where the fog begins (>= 0) */
} fogvol_distance_fog_desc;
FOGVOL_API fogvol_result fogvol_post_distance_fog(fogvol_context *ctx, const fogvol_distance_fog_desc *desc);

/* ---- backend table -------------------------------------------------------
   Contract. Every entry gets the table's user_data first. Handles are
   non-zero on success; 0 means "none". The renderer calls begin_frame, then
   passes (begin_pass, draws, end_pass), then end_frame; create/destroy calls
   may come inside or outside a frame. A backend must leave the engine's
   state as it found it at begin_frame when end_frame returns, and resource
   entries called outside a frame must not change engine state either.
   NULL optional entries (marked) are skipped.
   Any graphics API: the table asks for no GL concept. Programs come as GLSL of
   the backend's dialect (fogvol_backend.dialect: a GL dialect, whose uniforms a
   backend sets by name, or FOGVOL_GLSL_VULKAN, SPIR-V-ready GLSL whose uniforms,
   per-draw values and samplers sit where fogvol_program_desc.layout says); the
   objects the engine and fogvol hand each other are fogvol_native values (GL
   names, Vulkan handles, pointers); rows of targets and read-backs are in the
   order the API stores them, row 0 at framebuffer y 0 (GL: the bottom; Vulkan
   with a positive viewport height: the top row of memory), and fogvol's clip z
   is GL's [-w, w] (the Vulkan dialect maps it to [0, w]: the same window
   depth). examples/fogvol_vulkan.h is a complete backend on Vulkan,
   examples/custom_backend.c wraps the GL one; docs/BACKENDS.md says what
   each entry must do. */
typedef uintptr_t fogvol_handle;

/* The vec4 uniforms of fogvol's programs, X(FOGVOL_U_ suffix, GLSL name), in
   the order of their fogvol_uniform values (0, 1, ...); add new ones at the
   end. fogvol_uniform_name gives the name.
   ENC      fv_enc:     (N, N^2, depth_offset, depth_max)
   DITHER   fv_dith:    (255 or 0 = dither off, 1/D, D, row offset of the frame: fogvol__dither_offset)
   SCREEN   fv_screen:  (1/w, 1/h, -x0, -y0): gl_FragCoord + zw = pixel of fogvol's targets,
                        (gl_FragCoord + zw) * xy in [0,1]
   DECODE   fv_dec:     decode weights (world units)
   RAMP     fv_rampmap: (slope, offset, overflow flag, 0): thickness -> ramp s
   MISC     fv_misc:    (z scale k, 1 = replace clip z, near-clamp w, 1 = NEAR_CLAMP in the face programs;
                        in the depth-tested (ENGINE_TEST) composite the near plane's count c:
                        fogvol__engine_test_sources)
   LINEAR   fv_lin:     engine depth texture -> view depth, numerator row:
                        view depth = dot(fv_lin, q) / dot(fv_lin2, q), q = (s, t, window depth, 1),
                        (s, t) in [0,1] across the viewport (fv_engine_view_depth in the shaders)
   NEARFAR  fv_nf:      (1/(far-near), -near/(far-near), viewport x, viewport y): view depth -> d;
                        zw: offset of the engine depth texel (ENGINE_DEPTH)
   LINEAR_W fv_lin2:    the denominator row of fv_lin
   image-space effects (fogvol_post_*):
   POST_TEXEL  fv_ptexel:  (1/texture width, 1/texture height, 1 = perspective, 0)
   POST_RECT   fv_prect:   centres of the viewport's first and last pixels (x0, y0, x1, y1)
   POST_PARAMS fv_pparams: per effect (see fogvol__post_* in the implementation)
   POST_COLOR  fv_pcolor:  outline colour
   density and colour textures on volumes, volume light by compare:
   DENSITY_U fv_dens_u: density texture s = dot(fv_dens_u, (model-space position, 1))
   DENSITY_V fv_dens_v: density texture t, likewise
   DENSITY   fv_dens:   (reference depth c, 1 = density texture on, 1/(far-near), 0)
   COLOR_U   fv_ctex_u: colour texture s = dot(xyz, (screen s, t, 1)), w: 1 = on
   COLOR_V   fv_ctex_v: colour texture t = dot(xyz, (screen s, t, 1))
   LIGHT     fv_light:  (light rgb, 0 = front-depth pass, 1 = compare pass)
   SPEEDUP   fv_speed:  FACE (FLOAT): x = 1: no opaque depth (O is the far plane, not read);
                        COMPOSITE: (ramp rgb, density): density > 0: c = (rgb, 1 - exp(-density t)),
                        not the ramp texture
   SOFT      fv_soft:   COMPOSITE: (s, 1/(4s), 2s, 0), s the ramp's softness (0: off): the thickness t
                        looked up is t^2/(4s) below 2s, t - s above (fogvol_ramp_desc.softness)
   LIGHT_Q0..5 fv_lq0..5: LIGHT compare pass: the lit point relative to the light's falloff sphere,
                        q = (P - position) / radius = lq0 + lq1 s + lq2 t + o (lq3 + lq4 s + lq5 t),
                        (s, t) = fv_st(), o the normalised opaque depth; lq0.w = 1: falloff on;
                        lq1.w = (far - near) / edge_softness (0: no soft edge) */
#define FOGVOL_UNIFORMS(X) \
    X(ENC, fv_enc) \
    X(DITHER, fv_dith) \
    X(SCREEN, fv_screen) \
    X(DECODE, fv_dec) \
    X(RAMP, fv_rampmap) \
    X(MISC, fv_misc) \
    X(LINEAR, fv_lin) \
    X(NEARFAR, fv_nf) \
    X(LINEAR_W, fv_lin2) \
    X(POST_TEXEL, fv_ptexel) \
    X(POST_RECT, fv_prect) \
    X(POST_PARAMS, fv_pparams) \
    X(POST_COLOR, fv_pcolor) \
    X(DENSITY_U, fv_dens_u) \
    X(DENSITY_V, fv_dens_v) \
    X(DENSITY, fv_dens) \
    X(COLOR_U, fv_ctex_u) \
    X(COLOR_V, fv_ctex_v) \
    X(LIGHT, fv_light) \
    X(SPEEDUP, fv_speed) \
    X(SOFT, fv_soft) \
    X(LIGHT_Q0, fv_lq0) \
    X(LIGHT_Q1, fv_lq1) \
    X(LIGHT_Q2, fv_lq2) \
    X(LIGHT_Q3, fv_lq3) \
    X(LIGHT_Q4, fv_lq4) \
    X(LIGHT_Q5, fv_lq5)

typedef enum fogvol_uniform {
#define FOGVOL__UNIFORM_ENUM(id, name) FOGVOL_U_##id,
    FOGVOL_UNIFORMS(FOGVOL__UNIFORM_ENUM)
#undef FOGVOL__UNIFORM_ENUM
    FOGVOL_U_COUNT
} fogvol_uniform;
FOGVOL_API const char *fogvol_uniform_name(fogvol_uniform u);

/* Sampler units, fixed per program:
   ENCODE, FACE:  fv_rg 0, fv_blue 1, fv_dither 2, fv_opaque 3, fv_opaque2 4 (FACE only)
   COMPOSITE*, RESOLVE: fv_back 0, fv_front 1, fv_colors 2, fv_opaque 3, fv_back2 4, fv_front2 5
   (the "2" samplers: second attachments of WIDE targets); FACE: fv_density 6 (density
   texture); COMPOSITE*: fv_ctex 6 (colour texture); LIGHT: fv_rg 0, fv_blue 1, fv_dither 2,
   fv_opaque 3, fv_lfront 7 (the light's front depth L). Fragment outputs:
   fv_fragcolor, or the array fv_frag[2] for WIDE (bind it to location 0).
   Per-draw uniforms: "fv_mvp" (mat4), "fv_depth" (vec4: d = dot(fv_depth, vec4(p,1))),
   "fv_sign" (float, FLOAT tier: -1 for negative volumes), "fv_ext" and "fv_emit" (vec4,
   FOGVOL_PROGRAM_COLOR_FACE: fogvol_draw.extinction and .emission).
   Vertex attribute 0: "fv_position" (vec3).
   FOGVOL_GLSL_VULKAN: the same units as bindings of set 0, the uniforms above in one std140 block
   and push constants, not names: fogvol_program_desc.layout (fogvol_dialect_layout). */
#define FOGVOL_MAX_TEXTURE_UNITS 8

typedef struct fogvol_target_desc {
    int width, height;        /* colour texture, NEAREST (see linear), CLAMP */
    int color_count;          /* 0 or 1: one colour attachment; 2: two (WIDE, COLORS), drawn together,
                                 both of the format */
    fogvol_format format;
    int samples;              /* 0 or 1: single-sample; > 1: multisample colour texture(s) (GL: texture
                                 2D multisample, fixed sample locations) and depth renderbuffer */
    int depth;                /* 1: with a depth buffer */
    fogvol_handle share_depth;/* non-zero: use this target's depth buffer instead */
    const char *label;
    int linear;               /* 1: sampled with bilinear filtering (R32F, single-sample: the sum of
                                 fogvol_frame_desc.downsample 2). Asked only of backends reporting
                                 FOGVOL_CAP_FILTER_FLOAT; one that then cannot filter returns
                                 FOGVOL_ERROR_UNSUPPORTED, and fogvol makes the target without it and
                                 filters in the shader (four reads), as for the other backends */
} fogvol_target_desc;

#define FOGVOL_MAX_SHADER_STRINGS 20

/* The per-draw values of fogvol_draw as a program reads them (fogvol_uniform_layout.draw_offsets). */
typedef enum fogvol_draw_value {
    FOGVOL_DRAW_MVP = 0,        /* mat4 fv_mvp: fogvol_draw.mvp */
    FOGVOL_DRAW_DEPTH = 1,      /* vec4 fv_depth: .depth */
    FOGVOL_DRAW_EXTINCTION = 2, /* vec4 fv_ext: .extinction */
    FOGVOL_DRAW_EMISSION = 3,   /* vec4 fv_emit: .emission */
    FOGVOL_DRAW_SIGN = 4,       /* float fv_sign: .sign */
    FOGVOL_DRAW_VALUE_COUNT = 5
} fogvol_draw_value;

/* Where a program's inputs live, for backends that bind by number instead of by name (the Vulkan
   dialect; fogvol_dialect_layout). Pass uniforms: one std140 uniform block of pass_size bytes at
   (descriptor set 0, binding pass_binding) holding fogvol_pass.uniforms exactly as the struct holds
   them (uniform u at pass_offsets[u] = 16 u: copy the array as it is). Per-draw values: draw_size
   bytes of push constants, visible to the vertex and fragment stages, value i at draw_offsets[i]
   (mvp 16 floats, column-major; depth, extinction, emission 4 floats; sign 1 float). Samplers:
   texture unit i (fogvol_pass.textures[i]) is the combined image sampler at (set 0,
   sampler_bindings[i] = i). Vertex input: fv_position at location 0 (3 floats). Fragment outputs
   from location 0 (two-attachment targets: locations 0 and 1). GL dialects: all -1 (by name). */
typedef struct fogvol_uniform_layout {
    int pass_binding, pass_size;
    int pass_offsets[FOGVOL_U_COUNT];
    int draw_size;
    int draw_offsets[FOGVOL_DRAW_VALUE_COUNT];
    int sampler_bindings[FOGVOL_MAX_TEXTURE_UNITS];
} fogvol_uniform_layout;
/* The layout of a dialect's programs: FOGVOL_SUCCESS for FOGVOL_GLSL_VULKAN; the GL dialects
   (uniforms by name) fill every field with -1 and return FOGVOL_ERROR_UNSUPPORTED. */
FOGVOL_API fogvol_result fogvol_dialect_layout(fogvol_dialect dialect, fogvol_uniform_layout *out);

typedef struct fogvol_program_desc {
    const char *vs[FOGVOL_MAX_SHADER_STRINGS];
    int vs_count;
    const char *fs[FOGVOL_MAX_SHADER_STRINGS];
    int fs_count;
    const char *samplers[FOGVOL_MAX_TEXTURE_UNITS]; /* name bound to unit i, NULL = unused */
    const char *label;
    fogvol_uniform_layout layout; /* the backend's dialect: where the uniforms, per-draw values and samplers
                                     are (Vulkan), or all -1 (GL: by name) */
} fogvol_program_desc;

typedef struct fogvol_mesh_data {
    const float *positions; /* tightly packed xyz (see stride, offset) */
    int vertex_count;
    const uint32_t *indices;
    int index_count;
    /* Only for backends reporting FOGVOL_CAP_MESH_LAYOUT (others always get
       packed xyz and 32-bit indices, these fields 0): vertex i's x is at byte
       offset + i * stride of positions (stride 0 = 12), and with index_type
       FOGVOL_INDEX_UINT16 the indices are indices16 (indices is NULL). */
    int stride, offset;
    fogvol_index_type index_type;
    const uint16_t *indices16;
} fogvol_mesh_data;

typedef enum fogvol_pass_blend {
    FOGVOL_PASS_BLEND_NONE = 0,
    FOGVOL_PASS_BLEND_ADD = 1,   /* ONE, ONE on RGBA */
    FOGVOL_PASS_BLEND_SUBTRACT = 4, /* dst - src on RGBA (reverse subtract, ONE, ONE) */
    FOGVOL_PASS_BLEND_FOG = 2,   /* RGB: SRC_ALPHA, ONE_MINUS_SRC_ALPHA; A: ZERO, ONE */
    FOGVOL_PASS_BLEND_LIGHT = 3, /* RGB: SRC_ALPHA, ONE; A: ZERO, ONE */
    /* FOGVOL_VARIANT_COLORS, per-channel transmittance in two steps (alpha_coverage as for FOG) */
    FOGVOL_PASS_BLEND_MULTIPLY = 5, /* RGB: ZERO, SRC_COLOR; A: ZERO, ONE (coverage: ZERO, SRC_ALPHA) */
    FOGVOL_PASS_BLEND_EMIT = 6      /* RGB: ONE, ONE; A: ZERO, ONE (coverage: ONE, ONE) */
} fogvol_pass_blend;

typedef enum fogvol_cull { FOGVOL_CULL_NONE = 0, FOGVOL_CULL_BACK = 1, FOGVOL_CULL_FRONT = 2 } fogvol_cull;

typedef struct fogvol_pass {
    fogvol_handle target;   /* 0 = the framebuffer bound when begin_frame was called */
    int viewport[4];        /* x, y, w, h */
    int clear;              /* clear colour (and depth to 1 when the target has one) */
    float clear_color[4];
    fogvol_pass_blend blend;
    fogvol_cull cull;       /* front faces are counter-clockwise unless a draw says otherwise */
    int depth_test;         /* LESS (against the target's own or shared depth buffer, or depth_texture) */
    int depth_write;
    /* non-zero (only for backends reporting FOGVOL_CAP_ATTACH_DEPTH): this depth texture of the engine
       (API object: GL a texture name, single-sample, any depth or depth-stencil format; its texel
       (0, 0) at the target's pixel (0, 0)) is the target's depth buffer for this pass, tested as
       depth_test and depth_greater say, never written (depth_write 0) nor cleared; it is detached at
       end_pass (GL: glFramebufferTexture2D on fogvol's own framebuffer object) */
    fogvol_native depth_texture;
    int depth_greater;      /* depth_test: GREATER instead of LESS (a reversed-Z engine depth) */
    int per_sample;         /* 1: the targets are multisampled: rasterise with multisampling and shade
                               every sample (GL: GL_MULTISAMPLE, GL_SAMPLE_SHADING with min 1.0); 2 (only
                               for backends reporting FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE): multisampled
                               targets, rasterised and depth-tested per sample, shaded once per pixel (GL:
                               GL_MULTISAMPLE, no sample shading); a backend that shades such a pass per
                               sample draws the same */
    int scissor[4];         /* scissor[2] > 0: draw only inside this window rectangle (x, y, w, h) */
    int draw_buffer;        /* target 0: write only the engine's draw buffer of this index */
    int alpha_coverage;     /* FOG/LIGHT blends: alpha becomes a + dst.a * (1 - a) instead of dst.a */
    int blend_constant;     /* FOG/LIGHT blends, only on a backend with FOGVOL_CAP_BLEND_CONSTANT: the colour
                               blended in is blend_color.rgb times the shader's alpha, which the shader
                               writes to every channel (GL: RGB source factor CONSTANT_COLOR instead of
                               SRC_ALPHA, glBlendColor(blend_color)) */
    float blend_color[4];
    fogvol_handle read_target; /* non-zero (only with FOGVOL_CAP_FRAMEBUFFER_FETCH): this target's colour
                                  is attached to the pass's target as colour attachment 1, never written
                                  (GL: glColorMaski(1, all false)), for a program that reads it there
                                  (FOGVOL_SPECIALIZE_FETCH_O's fv_ofb); 0: attachment 1 is not there */
    fogvol_handle program;
    fogvol_handle textures[FOGVOL_MAX_TEXTURE_UNITS]; /* texture or target handles (a target is
                                                         sampled as its colour texture) */
    fogvol_native native_textures[FOGVOL_MAX_TEXTURE_UNITS]; /* non-zero: an engine texture in the
                                                            backend's own API (GL: a texture name;
                                                            Vulkan: an image view) */
    float uniforms[FOGVOL_U_COUNT][4];
} fogvol_pass;

typedef struct fogvol_draw {
    float mvp[16];
    float depth[4];
    float sign;   /* +1, or -1 for a negative volume (FLOAT tier) */
    int front_cw; /* 1: front faces are clockwise for this draw (mirroring transform) */
    float extinction[4]; /* COLOR_FACE ("fv_ext"): per-channel extinction * (far - near), 0; else 0 */
    float emission[4];   /* COLOR_FACE ("fv_emit"): extinction * the ramp colour; else 0 */
} fogvol_draw;

/* Capabilities a backend reports (fogvol_backend.caps). */
enum {
    FOGVOL_CAP_FLOAT_BLEND = 1u << 0,     /* R32F targets with additive blending */
    FOGVOL_CAP_MRT = 1u << 1,             /* several colour outputs (engine MRT) */
    FOGVOL_CAP_HIGHP_FRAGMENT = 1u << 2,  /* fp32 in fragment shaders */
    FOGVOL_CAP_DEPTH_TEXTURE = 1u << 3,   /* the engine can sample its depth buffer */
    FOGVOL_CAP_MULTISAMPLE = 1u << 4,     /* multisampled targets and per-sample shading
                                             (GL 4.0, or GL 3.2 + ARB_sample_shading) */
    FOGVOL_CAP_MESH_LAYOUT = 1u << 5,     /* create_mesh reads fogvol_mesh_data's stride, offset, index_type */
    FOGVOL_CAP_FILTER_FLOAT = 1u << 6,    /* create_target honours fogvol_target_desc.linear for R32F */
    FOGVOL_CAP_BLEND_CONSTANT = 1u << 7,  /* begin_pass honours fogvol_pass.blend_constant */
    FOGVOL_CAP_FLOAT_TARGET = 1u << 8,    /* R32F colour targets that fogvol's O pass and the engine's
                                             MRT pass or occluder shaders can write at full precision,
                                             blending not needed (GL 3.0; GLES 3 with
                                             EXT_color_buffer_float where the engine's output is highp:
                                             fogvol_gl_desc.mrt_highp) */
    FOGVOL_CAP_FRAMEBUFFER_FETCH = 1u << 9, /* begin_pass honours fogvol_pass.read_target, and FACE programs
                                              with FOGVOL_SPECIALIZE_FETCH_O build (GL:
                                              EXT_shader_framebuffer_fetch, GLSL 330 or 300 es, per-buffer
                                              colour masks) */
    FOGVOL_CAP_ATTACH_DEPTH = 1u << 10     /* begin_pass honours fogvol_pass.depth_texture and depth_greater,
                                              end_pass detaches it, and create_target makes RG32F targets
                                              (GL 3.0 / GLES 3.0 framebuffer objects and RG32F with
                                              FOGVOL_CAP_FLOAT_BLEND; not WebGL): FLOAT + ENGINE_DEPTH frames drawn
                                              depth-tested (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST) */,
    FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE = 1u << 11 /* with FOGVOL_CAP_ATTACH_DEPTH and FOGVOL_CAP_MULTISAMPLE:
                                              depth_texture may also be a multisample depth texture of a
                                              multisampled target's samples, and per_sample 2 (rasterised
                                              per sample, shaded once per pixel) is honoured: multisampled
                                              FLOAT + ENGINE_DEPTH frames drawn depth-tested (GL 3.2 with
                                              per-sample shading) */,
    FOGVOL_CAP_SOFTWARE_RENDERER = 1u << 12 /* the backend draws on the CPU (llvmpipe, softpipe,
                                              SwiftShader, WARP, Apple's software renderer; the GL backend
                                              tells them by GL_RENDERER: fogvol_renderer_is_software), where
                                              a texture read per fragment costs more than blending a
                                              second float channel: FLOAT + ENGINE_DEPTH frames are drawn
                                              depth-tested (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST) only then. On
                                              a GPU every face reads the engine's depth into an R32F sum
                                              (H200: 0.95-1.00x the floor against 1.7-1.9x depth-tested,
                                              whose RG32F blending costs twice the bandwidth) */
};

/* 1 when a GL_RENDERER (or a similar device name) names a renderer that draws on the CPU: Mesa's
   llvmpipe and softpipe (also under zink or virgl), its old swrast ("Software Rasterizer"),
   SwiftShader (also under ANGLE), Microsoft's WARP ("Basic Render Driver") and GDI renderer, Apple's
   software renderer. The GL backend sets FOGVOL_CAP_SOFTWARE_RENDERER by it (unless
   fogvol_gl_desc.software says otherwise); a backend of an engine's own may too. NULL: 0. */
FOGVOL_API int fogvol_renderer_is_software(const char *renderer);

typedef struct fogvol_frame_info {
    int samples;      /* samples per pixel of the engine framebuffer (GL: GL_SAMPLES when
                         GL_SAMPLE_BUFFERS is 1); 0 or 1 = single-sample */
    /* How the engine maps NDC z to window depth (read for the ENGINE_DEPTH variant; all 0 =
       GL defaults): depth_zero_to_one 1 = clip control ZERO_TO_ONE (NDC z in [0,1]);
       clip_upper_left 1 = clip control origin UPPER_LEFT (NDC y points down the window);
       depth_range = glDepthRange (both 0 = (0, 1)). The GL backend reads them from the
       context and draws its own passes with NEGATIVE_ONE_TO_ONE and depth range (0, 1). */
    int depth_zero_to_one;
    int clip_upper_left;
    float depth_range[2];
    int draw_buffer;  /* in: the engine draw buffer the composite writes (fogvol_frame_desc.draw_buffer);
                         a backend that cannot write it returns an error from begin_frame */
} fogvol_frame_info;

typedef struct fogvol_backend {
    void *user_data;
    fogvol_dialect dialect; /* shader dialect the backend compiles */
    unsigned caps;          /* FOGVOL_CAP_* */
    /* optional: save engine state, report the engine framebuffer */
    fogvol_result (*begin_frame)(void *user_data, fogvol_frame_info *info);
    void (*end_frame)(void *user_data);                      /* optional: restore engine state */
    fogvol_result (*create_texture)(void *user_data, const fogvol_texture_desc *desc, fogvol_handle *out);
    void (*destroy_texture)(void *user_data, fogvol_handle texture);
    fogvol_result (*create_target)(void *user_data, const fogvol_target_desc *desc, fogvol_handle *out);
    void (*destroy_target)(void *user_data, fogvol_handle target);
    fogvol_result (*create_program)(void *user_data, const fogvol_program_desc *desc, fogvol_handle *out);
    void (*destroy_program)(void *user_data, fogvol_handle program);
    fogvol_result (*create_mesh)(void *user_data, const fogvol_mesh_data *data, fogvol_handle *out);
    void (*destroy_mesh)(void *user_data, fogvol_handle mesh);
    void (*begin_pass)(void *user_data, const fogvol_pass *pass);
    void (*set_draw)(void *user_data, const fogvol_draw *draw); /* per-draw uniforms, for engine draws */
    void (*draw_mesh)(void *user_data, fogvol_handle mesh, const fogvol_draw *draw);
    void (*draw_fullscreen)(void *user_data); /* one triangle covering the viewport */
    void (*end_pass)(void *user_data);        /* optional */
    /* optional (debug read-back; may wait for the GPU): the whole target, row 0 first (GL: bottom to top), as RGBA8
       bytes or (R32F targets) floats, size >= w*h*4; RGBA32F targets: 4 floats a pixel, size >= w*h*16 */
    fogvol_result (*read_target)(void *user_data, fogvol_handle target, unsigned char *rgba, size_t size);
    void (*destroy)(void *user_data); /* optional: called by fogvol_destroy_context for owned backends */
    /* optional (MRT tier, fogvol_occluder_prepare): the API object behind a texture or target
       (GL: texture name; Vulkan: image view) */
    fogvol_native (*native_texture)(void *user_data, fogvol_handle texture);
    /* optional (WIDE): the second colour attachment of a two-attachment target,
       as a target handle of its own (sampled and read back like any target) */
    fogvol_handle (*target_attachment)(void *user_data, fogvol_handle target, int index);
    /* optional (ENGINE_DEPTH from a framebuffer), called inside every frame that reads it, before
       the first pass: copies the depth of rect (x, y, w, h) of the engine framebuffer as it is now
       (bound: the one bound at begin_frame; else framebuffer, an API object) into a depth texture
       the backend owns, with the same texel coordinates, and returns that texture's API object in
       *texture. samples 0: a single-sample texture (a multisampled source resolved to one sample
       per pixel); samples > 1 (a frame drawn per sample): a multisample texture of that many
       samples, each sample copied (GL: GL_TEXTURE_2D_MULTISAMPLE). The texture may be reused
       from frame to frame, its contents never: each call copies again. */
    fogvol_result (*copy_depth)(void *user_data, fogvol_native framebuffer, int bound, const int rect[4], int samples,
                                fogvol_native *texture);
    /* optional (overflow counting without read-back; all five or none): occlusion queries that count
       the samples passing between begin_query and end_query, which fogvol calls around the draws of
       one pass (after begin_pass, before end_pass). create_query may be called inside or outside a
       frame and fails where the context has none. begin_query returns 0 when it cannot start one now
       (GL: the engine has an occlusion query active; the frame is then not counted). query_result is
       called in a later frame and never waits: 0 = not available yet, 1 = *samples set (GLES 3: 0 or
       1, "any sample passed"). */
    fogvol_result (*create_query)(void *user_data, fogvol_handle *out);
    void (*destroy_query)(void *user_data, fogvol_handle query);
    int (*begin_query)(void *user_data, fogvol_handle query);
    void (*end_query)(void *user_data, fogvol_handle query);
    int (*query_result)(void *user_data, fogvol_handle query, uint64_t *samples);
    /* optional: the first failure the backend met in its own calls since the last take_error, else
       FOGVOL_SUCCESS, and forget it. fogvol calls it at the end of every public call that used the
       backend and returns it when the call had no error of its own (the backend logs it). GL: a GL
       error fogvol's own calls raised (FOGVOL_ERROR_BACKEND), read before the engine's pending errors
       are raised again; an engine texture name that is no texture (FOGVOL_ERROR_INVALID_ARGUMENT);
       another GL context current (FOGVOL_ERROR_INVALID_STATE). */
    fogvol_result (*take_error)(void *user_data);
} fogvol_backend;

/* Recording null backend: no GPU, every call counted and the passes kept. */
#define FOGVOL_NULL_MAX_PASSES 64
typedef struct fogvol_null_backend {
    int creates, destroys;  /* live handles = creates - destroys */
    int frames_begun, frames_ended;
    int pass_count;         /* passes in the current/last frame */
    fogvol_pass passes[FOGVOL_NULL_MAX_PASSES];
    int draws[FOGVOL_NULL_MAX_PASSES];    /* mesh draws per pass */
    int fullscreen[FOGVOL_NULL_MAX_PASSES];
    int in_pass;
    fogvol_handle next_handle;
    int fail_create_at;     /* >0: the n-th create call fails (fault injection) */
    int create_calls;
    int samples;            /* reported by begin_frame (engine framebuffer samples) */
    /* occlusion queries: with queries = 0 (the default) create_query fails, as on a GPU without them;
       with 1 every query reports query_samples, after query_not_ready polls that answer "not yet" */
    int queries;
    uint64_t query_samples;
    int query_not_ready;
    int queries_begun, queries_ended, query_polls, query_active; /* query_active: begun, not ended */
} fogvol_null_backend;
/* The table reports caps HIGHP_FRAGMENT | MRT | DEPTH_TEXTURE | MESH_LAYOUT | ATTACH_DEPTH (AUTO picks PS20);
   change table->caps before creating a context to test other choices. */
FOGVOL_API void fogvol_null_backend_init(fogvol_null_backend *state, fogvol_backend *table);

#ifndef FOGVOL_NO_GL
/* The default GL backend on its own (fogvol_create_context makes one when the
   desc's backend table is empty). destroy it with table->destroy(table->user_data). */
FOGVOL_API fogvol_result fogvol_gl_backend_create(const fogvol_gl_desc *desc, const fogvol_allocator *alloc,
                                                  const fogvol_logger *logger, fogvol_backend *out);
#endif

/* ---- context desc --------------------------------------------------------
   Here, after the backend table, because it holds a fogvol_backend by value (C99 needs
   the struct complete); fogvol_create_context is in the context section. */
struct fogvol_context_desc {
    /* what most engines set (all 0 = the GL backend, the best tier it runs, default encoding) */
    fogvol_gl_desc gl;     /* the GL backend: its loader (gl.get_proc = glfwGetProcAddress, ...) */
    fogvol_logger logger;  /* where errors, warnings and shader info logs go (0 = nowhere) */
    fogvol_tier tier;      /* 0 = the first of FLOAT, MRT (with engine_mrt), PS20, PS13 that the
                              backend runs with the required variants */
    unsigned variants;     /* FOGVOL_VARIANT_* the engine requires: refused where the tier (AUTO: every
                              tier the backend runs) does not take them */
    unsigned preferred_variants; /* FOGVOL_VARIANT_* used where the chosen tier, dialect and backend take
                              them, left out (logged at INFO) where not; fogvol_context_tier says which */
    int encoding_bits;     /* 0 = FOGVOL_DEFAULT_BITS (4: 12 bits, 16 faces); WIDE: 0 = 3, > 3 refused;
                              SINGLE_TARGET: 8 refused (no face fits beside the bias) */
    /* less often */
    fogvol_allocator allocator; /* 0 = FOGVOL_MALLOC / FOGVOL_FREE */
    int engine_mrt;        /* 1: the engine will write O in its opaque pass (lets AUTO pick MRT) */
    int disable_dither;    /* dithering is on by default */
    fogvol_msaa msaa;      /* multisampled engine framebuffers: 0 = AUTO (per sample, or refused) */
    fogvol_overflow_policy overflow_policy; /* 0 = FOGVOL_OVERFLOW_WARN_ONCE */
    fogvol_backend backend;/* a custom table (backend authors); if create_texture is NULL the GL backend
                              is used */
    unsigned disable_speedups; /* tuning: FOGVOL_SPEEDUP_* bits to turn off (0 = every speed-up on),
                                  to measure what each gives (see "---- tuning") */
};

/* ---- encoding ------------------------------------------------------------
   A depth d in [0,1) becomes D = d * 2^(3L) blue-LSB units, split into three
   L-bit digits: red (most significant), green, blue, each stored in the low L
   bits of an 8-bit channel. Additive blending then sums up to 2^(8-L) encoded
   values with no loss (the 8-L high bits take the carries).

   Dithering (on by default): the blue digit comes from a 2D ramp whose rows
   hold different rounding thresholds; a pixel picks its row from an 8x8
   ordered pattern. Row 0 rounds to nearest (no dither). Where a dithered row
   rounds below the start of a blue period the texel holds blue = 2^L - 1 and
   alpha = 1, meaning "minus one green step"; the alpha channel sums these
   borrows and the decode weights carry -2^-L for alpha, so every channel of a
   single encoded face stays <= 2^L - 1 and the sum stays exact and unbiased.

   decode(RGBA bytes) = R/N + G/N^2 + B/N^3 - A/N^2   (N = 2^L, in units of far-near)
*/
typedef struct fogvol_encoding {
    int bits;             /* L: low bits used per channel, 1..8 */
    int levels;           /* N = 2^L */
    int precision_bits;   /* 3L */
    int max_faces;        /* faces summable without error per target: 2^(8-L) */
    int max_faces_single; /* single-target variant with mid-range bias: 2^(7-L) (0 for L = 8) */
    int dither_steps;     /* D: blue-ramp texels per blue LSB = dither rows (32, fewer for L >= 7) */
} fogvol_encoding;

#define FOGVOL_DEFAULT_BITS 4
#define FOGVOL_WIDE_EXACT_BITS 3 /* largest L the WIDE variant encodes exactly (6L = 18 bits) */
#define FOGVOL_DITHER_PATTERN 8 /* the dither index texture is 8x8 */

/* Fill *out for L = bits (1..8). */
FOGVOL_API fogvol_result fogvol_encoding_init(int bits, fogvol_encoding *out);
/* Most precise encoding that sums at least max_faces faces (1..128).
   max_faces < 1: FOGVOL_ERROR_INVALID_ARGUMENT; > 128: FOGVOL_ERROR_UNSUPPORTED. */
FOGVOL_API fogvol_result fogvol_encoding_from_faces(int max_faces, fogvol_encoding *out);
/* Encoding with the most faces that still gives at least precision_bits (1..24).
   precision_bits < 1: FOGVOL_ERROR_INVALID_ARGUMENT; > 24: FOGVOL_ERROR_UNSUPPORTED. */
FOGVOL_API fogvol_result fogvol_encoding_from_precision(int precision_bits, fogvol_encoding *out);
/* The table of every L = 1..8 (Figure 3 of the "Fog Polygon Volumes" white paper). Returns the row count (8);
   writes min(count, capacity) rows when rows != NULL. */
FOGVOL_API int fogvol_encoding_table(fogvol_encoding *rows, int capacity);
FOGVOL_API const fogvol_encoding *fogvol_context_encoding(const fogvol_context *ctx);

/* Constants a shader needs (all float, ready for uniforms). */
typedef struct fogvol_constants {
    float near_far[2];    /* (1/(far-near), -near/(far-near)): d = w*near_far[0] + near_far[1] */
    float ramp_scale[4];  /* (1, 2^L, 2^2L, 0): texture coordinates of the red, green, blue ramps */
    float depth_offset;   /* 2^-3L: added to the clamped d before the ramp lookups (one blue LSB;
                             it pairs with the "-1" of the blue ramp's borrow convention) */
    float depth_max;      /* d is clamped to [0, depth_max] = 1 - 1.5 * 2^-3L */
    float decode[4];      /* scale * (1, 2^-L, 2^-2L, -2^-L): dot with RGBA normalised to [0,1] */
    float scale;          /* the scale used: default (far-near) * 255 / 2^L (world units) */
    float bias[4];        /* mid-range bias of the single-target variant, normalised (128/255 in RGB) */
    float bias_decoded;   /* dot(bias, decode) */
    float lsb;            /* one blue LSB in decoded units: scale / (255 * 2^2L) (world units by default) */
    float dither_rows;    /* D */
} fogvol_constants;

/* scale == 0 means "decode to world units" ((far-near) * 255 / 2^L). */
FOGVOL_API fogvol_result fogvol_compute_constants(const fogvol_encoding *enc, float znear, float zfar,
                                                  float scale, fogvol_constants *out);

/* ---- textures (caller-owned RGBA8 buffers, rows bottom to top) -----------
   Each generator fills *info (width, height, size in bytes) and writes the
   texels when pixels != NULL. pixels == NULL is a size query. A capacity
   smaller than info->size gives FOGVOL_ERROR_BUFFER_TOO_SMALL. */
typedef struct fogvol_image {
    int width, height;
    size_t size; /* width * height * 4 */
} fogvol_image;

/* N x N: texel (x, y) = (x, y, 0, 0). Sampled NEAREST + REPEAT at (u, u*N). */
FOGVOL_API fogvol_result fogvol_make_rg_ramp(const fogvol_encoding *enc, unsigned char *pixels, size_t capacity,
                                             fogvol_image *info);
/* (N*D) x D: row r, texel x -> blue digit with the dither threshold of row r
   and the borrow in alpha. Sampled NEAREST + REPEAT(x) at (u*N^2, (row+0.5)/D). */
FOGVOL_API fogvol_result fogvol_make_blue_ramp(const fogvol_encoding *enc, unsigned char *pixels, size_t capacity,
                                               fogvol_image *info);
/* 8 x 8: red = blue-ramp row for the pixel (an ordered pattern over the
   thresholds). Sampled NEAREST + REPEAT at gl_FragCoord.xy / 8. */
FOGVOL_API fogvol_result fogvol_make_dither_index(const fogvol_encoding *enc, unsigned char *pixels,
                                                  size_t capacity, fogvol_image *info);
/* Rounding threshold of blue-ramp row r, in blue LSBs (row 0: 0.5). */
FOGVOL_API double fogvol_dither_threshold(const fogvol_encoding *enc, int row);

/* width x 1 texels; texel i holds thickness i/(width-1) * max_thickness.
   *max_thickness_out (may be NULL) receives the resolved max_thickness. */
FOGVOL_API fogvol_result fogvol_make_color_ramp(const fogvol_ramp_desc *desc, unsigned char *pixels,
                                                size_t capacity, fogvol_image *info, float *max_thickness_out);

/* ---- shaders ------------------------------------------------------------- */

typedef enum fogvol_program {
    FOGVOL_PROGRAM_ENCODE = 0,         /* opaque depth into O */
    FOGVOL_PROGRAM_FACE = 1,           /* volume faces into B / F (FLOAT: signed, one target) */
    FOGVOL_PROGRAM_COMPOSITE = 2,      /* full-screen triangle: thickness -> ramp -> blend */
    FOGVOL_PROGRAM_COMPOSITE_MESH = 3, /* the same, driven by the volume geometry */
    FOGVOL_PROGRAM_RESOLVE = 4,        /* PS13: B - F with carries -> encoded thickness */
    FOGVOL_PROGRAM_CHECK = 5,          /* RGBA8 tiers: full-screen triangle over the sums (as COMPOSITE reads
                                          them) that discards every pixel without a saturated channel and
                                          writes 1 into the overflow mask V; counted by occlusion queries */
    FOGVOL_PROGRAM_LIGHT = 6,          /* volume light by compare (fogvol_add_light): front faces write their
                                          depth into L; back faces light the scene pixels whose opaque
                                          depth lies between L and their own depth (FLOAT, PS20, MRT) */
    FOGVOL_PROGRAM_COLOR_FACE = 7,     /* FOGVOL_VARIANT_COLORS: faces add optical depth and emission per
                                          channel into two RGBA32F targets (outputs fv_frag[2]) */
    FOGVOL_PROGRAM_COLOR_COMPOSITE = 8,/* FOGVOL_VARIANT_COLORS: full-screen triangle, Beer-Lambert per channel */
    FOGVOL_PROGRAM_COUNT = 9,
    FOGVOL_PROGRAM_MAX_ENUM = 0x7fffffff
} fogvol_program;

typedef enum fogvol_stage {
    FOGVOL_STAGE_VERTEX = 0,
    FOGVOL_STAGE_FRAGMENT = 1,
    FOGVOL_STAGE_MAX_ENUM = 0x7fffffff
} fogvol_stage;

typedef struct fogvol_shader_desc {
    fogvol_tier tier;      /* not AUTO */
    unsigned variants;     /* FOGVOL_VARIANT_* */
    fogvol_program program;
    fogvol_dialect dialect;/* not AUTO */
    fogvol_stage stage;
    int samples;           /* 0 or 1: single-sample targets; > 1: the fragment shader reads fogvol's
                              targets as multisample textures at gl_SampleID (FV_MSAA; see
                              fogvol_msaa_supported). Vertex shaders are the same either way. */
    unsigned specialize;   /* FOGVOL_SPECIALIZE_* bits (0: the general program, which switches its
                              optional parts on uniforms): a program built for one configuration runs
                              faster where the GPU executes both sides of a uniform branch (llvmpipe). */
} fogvol_shader_desc;

/* fogvol_shader_desc.specialize: parts of a program left out at compile time. FACE: NO_OPAQUE (the
   opaque depth O is the far plane and not read: FLOAT without ENGINE_DEPTH, PS20, PS13, MRT; no
   effect on COUNT, WIDE or ENGINE_DEPTH, which read other sources), OPAQUE (FLOAT: O read at every
   fragment, without the uniform that lets the general program skip it), NO_DENSITY (no density
   texture).
   COMPOSITE and COMPOSITE_MESH: EXP (alpha = 1 - exp(-density t) from fv_speed, no ramp texture) or
   RAMP (the ramp texture only), NO_COLOR_TEXTURE (no fv_ctex), NO_OVERFLOW (no saturation test:
   for frames without show_overflow), FAST_EXP (the exp() of the alpha by a polynomial where the
   dialect has floatBitsToInt, see FOGVOL_SPEEDUP_FAST_EXP; not the same pixels). ENCODE and FACE:
   DITHER (the dither on, fv_dith.x = 255: the integer ALU encode without the test). ENCODE, FACE,
   RESOLVE and COMPOSITE of PS20 and PS13 without COUNT, SINGLE_TARGET, WIDE and ENGINE_DEPTH:
   COUNT (the program of the COUNT variant, FACE only with NO_DENSITY; FOGVOL_SPEEDUP_DEPTH_TEST).
   COMPOSITE of FLOAT (not COLORS; single-sample): DOWNSAMPLE (the sums are at half the viewport's
   width and height: a bilinear read of fv_back at the pixel, four texels; fogvol_frame_desc.downsample),
   with FILTERED (one read: the backend filters fv_back, fogvol_target_desc.linear). Every program:
   ORIGIN (the frame's viewport starts at the window origin: fogvol's targets and the engine's
   depth texture are read at gl_FragCoord, without the offsets fv_screen.zw and fv_nf.zw). ENCODE and
   FACE: FOGVOL_SPECIALIZE_ENCODING(L), L = 1..8 (fogvol_encoding.bits): the RGBA8 encode with that
   encoding's N = 2^L and D (dither_steps) compiled in instead of read from fv_enc.xy and fv_dith.yz,
   so its arithmetic on them folds at compile time (the same bytes for that encoding; no effect on
   FLOAT). COMPOSITE, COMPOSITE_MESH and CHECK of PS13: INLINE_RESOLVE (fv_back and fv_front are B
   and F, and with COUNT fv_opaque is O, resolved in the program as RESOLVE does, instead of fv_back
   being the resolved T; needs fp32 fragment arithmetic, see FOGVOL_SPEEDUP_INLINE_RESOLVE; other
   tiers: FOGVOL_ERROR_UNSUPPORTED). COMPOSITE and COMPOSITE_MESH with EXP, NO_COLOR_TEXTURE and
   NO_OVERFLOW: BLEND_COLOR (the program writes its alpha to all four channels, for a pass whose
   blend takes the colour from fogvol_pass.blend_color: FOGVOL_SPEEDUP_BLEND_COLOR). Every program:
   DEPTH_FROM_Z (the engine's depth is linearised from its window depth alone, without the pixel's
   position: fv_lin.xy and fv_lin2.xy are zero, as for every perspective or orthographic projection,
   jittered, off-centre or mirrored, but not one with an oblique near plane; no effect on programs
   that do not read the engine's depth). ENCODE, FACE and LIGHT of MRT, PS20 and PS13 (not WIDE or
   COUNT, PS13 not ENGINE_DEPTH, nor with FOGVOL_SPECIALIZE_COUNT): FLOAT_O (fv_opaque is an R32F O
   holding the normalised view depth, which ENCODE writes (PS20 + ENGINE_DEPTH: the engine's depth
   linearised), encoded by the program where it needs O's digits;
   see FOGVOL_SPEEDUP_FLOAT_O). FACE, dialects GLSL 330 and 300 es, single-sample, reading O (not
   NO_OPAQUE, COUNT, WIDE, or FLOAT with ENGINE_DEPTH): FETCH_O (O is read from colour location 1,
   "inout vec4 fv_ofb" with EXT_shader_framebuffer_fetch, where the pass binds it:
   fogvol_pass.read_target; the output is at location 0). FACE (with NO_DENSITY), COMPOSITE and
   COMPOSITE_MESH of PS20, MRT and PS13 with FLOAT_O, the same dialects (FACE: single-sample): EXACT_SUM
   (FOGVOL_SPEEDUP_EXACT_SUM: the face reads and writes its target's pixel as a 32-bit integer,
   "inout" at location 0, and adds or subtracts round(d 2^24); the composite decodes that integer
   times fv_rampmap.w = (far - near) / 2^24). Other bits, EXP with RAMP, L > 8, or bits for another
   program: FOGVOL_ERROR_UNSUPPORTED. FACE (with NO_DENSITY; single-sample) and COMPOSITE (also per
   sample) of FLOAT + ENGINE_DEPTH (not COLORS): ENGINE_TEST (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: the
   faces, depth-tested against the engine's depth, add (+-d, +-1) into an RG32F sum without reading
   the engine's depth; the composite reads it once per pixel (per sample) where the count is not c and
   takes thickness r - o (g - c), fv_misc.w = c). */
enum {
    FOGVOL_SPECIALIZE_NO_OPAQUE = 1u << 0,
    FOGVOL_SPECIALIZE_NO_DENSITY = 1u << 1,
    FOGVOL_SPECIALIZE_EXP = 1u << 2,
    FOGVOL_SPECIALIZE_RAMP = 1u << 3,
    FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE = 1u << 4,
    FOGVOL_SPECIALIZE_ORIGIN = 1u << 5,
    FOGVOL_SPECIALIZE_NO_OVERFLOW = 1u << 6,
    FOGVOL_SPECIALIZE_FAST_EXP = 1u << 7,
    FOGVOL_SPECIALIZE_OPAQUE = 1u << 8,
    FOGVOL_SPECIALIZE_DITHER = 1u << 9,
    FOGVOL_SPECIALIZE_COUNT = 1u << 10,
    FOGVOL_SPECIALIZE_DOWNSAMPLE = 1u << 11,
    FOGVOL_SPECIALIZE_FILTERED = 1u << 12,
    FOGVOL_SPECIALIZE_ENCODING_MASK = 15u << 13, /* FOGVOL_SPECIALIZE_ENCODING(bits) */
    FOGVOL_SPECIALIZE_INLINE_RESOLVE = 1u << 17,
    FOGVOL_SPECIALIZE_BLEND_COLOR = 1u << 18,
    FOGVOL_SPECIALIZE_DEPTH_FROM_Z = 1u << 19,
    FOGVOL_SPECIALIZE_FLOAT_O = 1u << 20,
    FOGVOL_SPECIALIZE_FETCH_O = 1u << 21,
    FOGVOL_SPECIALIZE_EXACT_SUM = 1u << 22,
    FOGVOL_SPECIALIZE_ENGINE_TEST = 1u << 23
};
#define FOGVOL_SPECIALIZE_ENCODING(bits) ((unsigned)(bits) << 13)

/* The strings of one shader, ready for glShaderSource(shader, *count, strings, NULL).
   Combinations that do not exist (fogvol_combination_supported) or programs a
   tier does not use return FOGVOL_ERROR_UNSUPPORTED and *count = 0. */
FOGVOL_API fogvol_result fogvol_shader_strings(const fogvol_shader_desc *desc, const char **strings, int *count);
/* Shorthand for variants = 0. */
FOGVOL_API fogvol_result fogvol_shader_source(fogvol_tier tier, fogvol_program program, fogvol_dialect dialect,
                                              fogvol_stage stage, const char **strings, int *count);
/* 1 if the tier runs this program. */
FOGVOL_API int fogvol_tier_uses_program(fogvol_tier tier, unsigned variants, fogvol_program program);

/* The GLSL of an effect for the engine's own use or validation. variant: DOF the
   tap count (3, 6, 12), OUTLINES 1 = with normals, DISTANCE_FOG 0. Samplers:
   fv_pscene (unit 0), fv_pdepth (1), fv_pnormal or fv_colors (2). */
FOGVOL_API fogvol_result fogvol_post_shader_strings(fogvol_post_effect effect, int variant, fogvol_dialect dialect,
                                                    fogvol_stage stage, const char **strings, int *count);

/* ---- tuning: the speed-ups (for measuring them, and for backend authors) ---------
   Every speed-up is on by default wherever the tier, variants, dialect and backend take it (the
   tier table in the >>tiers section says where) and gives the same pixels, or closer ones where
   said; fogvol_context_desc.disable_speedups turns them off one by one, to measure what each gives
   (bench/bench.c) or to rule one out on a driver. The FOGVOL_SPECIALIZE_* bits above are the
   programs some of them draw with. */
/* The speed-ups (bits of fogvol_context_desc.disable_speedups):
   SKIP_OPAQUE   no occluder, no engine depth (no MRT, ENGINE_DEPTH, COUNT or
                 fogvol_occluder_prepare): the opaque depth O is the far plane. FLOAT faces skip
                 their O read; the other tiers keep the O cleared by an earlier frame and draw no
                 O pass (same pixels).
   TEXEL_FETCH   GLSL 130+ and 300 es: fogvol's targets are read with texelFetch at the pixel
                 instead of a filtered lookup at computed coordinates (same pixels).
   EXP_COMPOSITE EXTINCTION ramps whose range reaches 7 / density: the composite computes
                 alpha = 1 - exp(-density t) instead of reading the ramp texture (the ramp holds
                 the same function in 8 bits: alpha differs by at most 1/255 plus the ramp's
                 interpolation error, rgb is the same).
   SPECIALIZE    each pass runs a program built for its configuration (fogvol_shader_desc.specialize:
                 no O read without occluders (and no test for it with them), no density texture
                 outside textured volumes, exp or
                 ramp composite, no colour texture, no overflow test without show_overflow,
                 target and engine-depth reads without the viewport offset where the viewport
                 starts at the window origin) instead of one program that switches on uniforms;
                 built on first use (same pixels).
   ALU           PS20 and MRT (not WIDE), and PS13 in GLSL 330 and 300 es, take FOGVOL_VARIANT_ALU:
                 the depth is encoded and the dither row computed by arithmetic instead of three
                 lookup texture reads per face fragment (same bytes; fogvol_context_tier reports the
                 variant). With SPECIALIZE the encoding's constants are compiled into the programs
                 (FOGVOL_SPECIALIZE_ENCODING).
   OVERFLOW_BANDS the overflow check passes of a frame cover one of FOGVOL_OVERFLOW_BANDS (8)
                 horizontal bands of the group's rectangle, in turn, instead of all of it (an
                 eighth of their cost); fogvol_frame_stats.overflow_pixels_late then sums the
                 newest count of each band: the whole picture over 8 frames, the same count while
                 the picture holds still. Not with show_overflow (same pixels).
   FAST_EXP      the EXP_COMPOSITE alpha from a degree-2 polynomial of 2^x with the exponent added in
                 integer bits, where the dialect has floatBitsToInt (GLSL 330, 300 es), instead of
                 exp() (FOGVOL_SPECIALIZE_FAST_EXP; with SPECIALIZE): the transmittance
                 1 - alpha is within 0.27% of exp(-density t), alpha exactly 0 at t = 0.
   DEPTH_TEST    PS20 and PS13 (not SINGLE_TARGET, WIDE or ENGINE_DEPTH) whose O is RGBA8 (not
                 FLOAT_O, below) in frames with
                 fogvol_add_occluder* calls, no density-textured volume, no fogvol_add_light,
                 and every volume's box either wholly between the near and far planes or wholly
                 outside that range: the frame is drawn as the COUNT variant (Baker's face count,
                 FOGVOL_SPECIALIZE_COUNT): the faces are depth-tested against the occluders, so a
                 fragment behind an occluder is not shaded, and the composite adds the opaque
                 depth once per missing back face. Other frames (a camera inside or near a volume)
                 take the min compare as before. The same sums: B - F equals the min compare's
                 bytes up to the faces that lie within depth-buffer precision of an occluder.
                 FLOAT keeps the min compare: there the count needs a second float channel, and
                 both ways tried measured slower on llvmpipe than the O read per face fragment
                 they save (cut by floor+pillars: an RG32F sum and count with O read by the
                 composite, 19.7 against 18.2 ms; an RGBA32F target holding O in alpha, 17.1
                 against 16.1 ms).
   INLINE_RESOLVE PS13 where the backend has FOGVOL_CAP_HIGHP_FRAGMENT: the composite and the overflow
                 check passes resolve B - F themselves (the RESOLVE program's digit arithmetic, exact
                 in fp32; FOGVOL_SPECIALIZE_INLINE_RESOLVE) instead of reading the resolved target T:
                 one full-screen pass and one target fewer (same bytes). Without highp the tier keeps
                 its resolve pass, which is exact in mediump.
   BLEND_COLOR   composites of one colour (the EXP composite without a colour texture, outside
                 show_overflow) on a backend with FOGVOL_CAP_BLEND_CONSTANT: the blend unit supplies
                 the fog colour (fogvol_pass.blend_constant; GL: CONSTANT_COLOR) and the program
                 writes only its alpha (FOGVOL_SPECIALIZE_BLEND_COLOR), so no colour is carried
                 through the fragment shader (the same blend equation; the same pixels where the
                 blender rounds the constant colour as it rounds a shader's output, as Mesa does).
   FLOAT_O       MRT, and PS20 with FOGVOL_CAP_HIGHP_FRAGMENT (not WIDE or COUNT),
                 on a backend with FOGVOL_CAP_FLOAT_TARGET: O is an R32F
                 texture holding the normalised view depth d = (view depth - near) / (far - near),
                 written by the engine's MRT pass (fogvol_mrt_info.format; the snippet switches on its
                 uniforms), by fogvol's O pass (PS20 + ENGINE_DEPTH: the engine's depth linearised
                 full-screen, so that its faces sum in integers too, EXACT_SUM), or by the engine's
                 occluder shaders
                 (fogvol_occluder_info.format), and the faces encode min(own depth, O)
                 (FOGVOL_SPECIALIZE_FLOAT_O) instead of encoding their own depth and comparing it with
                 O's digits: one encode per fragment and no compare in the faces, and no encode where
                 O is written. PS20 then draws frames with occluders with that compare, not
                 DEPTH_TEST's face count, whose composite would read O's digits (on llvmpipe the
                 compare with the R32F O costs less; PS13's, which normalises its encoding, more:
                 PS13 keeps its RGBA8 O and the count). The
                 same bytes: the faces encode O as the snippet or the O pass did (the same
                 arithmetic on the same float), and the encode is monotonic, so the lesser encoding
                 is the encoding of the lesser depth.
   SKIP_CHECK    RGBA8 tiers (not SINGLE_TARGET or NEAR_CLAMP): a ramp group whose volumes are all
                 convex (fogvol_mesh_report.convex), at most half as many as a target sums
                 (fogvol_encoding.max_faces / 2), draws no overflow check pass: a convex volume puts
                 at most one back and one front face on a ray, so no sum can saturate (the half is
                 a margin for meshes convex only within the convexity test's tolerance, 1e-5 of
                 their box's diagonal, which a ray grazing them could cross more than once), and the
                 frame counts 0 for the group at once (fogvol_frame_stats.overflow_passes leaves it
                 out).
   FRAMEBUFFER_FETCH  on a backend with FOGVOL_CAP_FRAMEBUFFER_FETCH (GL: EXT_shader_framebuffer_fetch
                 with GLSL 330 or 300 es and per-buffer colour masks), the face passes that read fogvol's
                 O (FLOAT, PS20, MRT and PS13 comparing with the occluders' depth; not the face count,
                 WIDE, FLOAT + ENGINE_DEPTH or multisampled targets) read it from the framebuffer: O is
                 bound beside the sum as a write-masked colour attachment (fogvol_pass.read_target)
                 and the program reads its value there (FOGVOL_SPECIALIZE_FETCH_O) instead of a
                 texelFetch. The same value, so the same bytes; on llvmpipe a framebuffer read costs
                 about half a texture read, on tile-based GPUs it comes from tile memory
                 (fogvol_frame_stats.fetched_o). A program that does not build turns it off.
   EXACT_SUM     PS20, MRT and PS13 with FRAMEBUFFER_FETCH and fp32 fragment shaders, and FLOAT_O
                 (PS13 then keeps O as R32F too; not SINGLE_TARGET; single-sample): a ramp group
                 without density-textured volumes sums its faces by programmable blending: one pass
                 over every face reads B's RGBA8 pixel as a 32-bit
                 integer (FOGVOL_SPECIALIZE_EXACT_SUM), adds its depth quantised to 24 bits (the lesser
                 of it and O) for a back face and subtracts it for a front face (sign flipped for
                 negative volumes), and writes the integer back; the composite reads that one target.
                 Modular arithmetic, so the order of the faces does not matter, and the result is exact
                 to 2^-24 of the depth range: no F target, no dither, no digits that saturate, so no
                 overflow check pass: the signed 32-bit integer holds a pixel's summed thickness up
                 to 127 times the depth range, 127 layers each as deep as the whole range (groups of
                 128 volumes or more keep the digits and their check; fogvol_frame_stats.exact_sum).
                 Not the digits' bytes: closer to the true thickness.
   ENGINE_DEPTH_TEST  FLOAT + ENGINE_DEPTH on a backend with FOGVOL_CAP_ATTACH_DEPTH (the GL backend on
                 GL 3.0 / GLES 3.0) that draws on the CPU (FOGVOL_CAP_SOFTWARE_RENDERER: on a GPU the
                 per-face read is the faster), in single-sample frames (and multisampled ones without a
                 debug read-back with FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE: the faces shaded once per pixel,
                 tested per sample against the engine's multisample depth, the composite per sample),
                 at any viewport (the sum is a target in the window's coordinates, grown to the
                 viewports' far corners and shared by the views of a split screen; away from the window
                 origin no colour-textured volume), with every volume clear of the near and far
                 planes or, the camera inside it, convex and holding the projection's whole near
                 plane rectangle and, where that plane lies beyond znear, znear's too (its far side
                 before the far plane), no density-textured volume, no
                 fogvol_add_light, no downsample, not NEAR_CLAMP or COLORS, a projection without an
                 oblique near plane: the engine's depth texture (or fogvol's copy of the framebuffer's
                 depth) is attached as the depth buffer of the sum's target, tested (LESS, GREATER
                 for a reversed depth) and never written, so only the faces in front of the opaque
                 surface are shaded; each adds (+-d, +-1) into an RG32F sum without reading the
                 engine's depth, and the composite reads that depth once per pixel where the count is not c
                 and takes thickness r - o (g - c) (a face behind the surface adds +-o in the min
                 compare; over a closed, unclipped volume their signs sum to -g, and the front face
                 the near plane clips from a volume around the camera makes that c - g, c the
                 number of such volumes in the group, negative ones counted -1). The faces' clip z
                 is the engine's (fogvol_frame_desc.engine_depth_zero_to_one and
                 engine_depth_range), so the test compares the depths the engine's own rasteriser
                 would. The same thickness up to rounding (a face within one depth-buffer step of
                 the surface adds d or o, which differ by less than that step);
                 fogvol_frame_stats.engine_depth_tested. */
enum {
    FOGVOL_SPEEDUP_SKIP_OPAQUE = 1u << 0,
    FOGVOL_SPEEDUP_TEXEL_FETCH = 1u << 1,
    FOGVOL_SPEEDUP_EXP_COMPOSITE = 1u << 2,
    /* 1u << 3 was SCISSOR (0.1): the composites are always scissored now; the bit is ignored */
    FOGVOL_SPEEDUP_SPECIALIZE = 1u << 4,
    FOGVOL_SPEEDUP_ALU = 1u << 5,
    FOGVOL_SPEEDUP_OVERFLOW_BANDS = 1u << 6,
    FOGVOL_SPEEDUP_FAST_EXP = 1u << 7,
    FOGVOL_SPEEDUP_DEPTH_TEST = 1u << 8,
    FOGVOL_SPEEDUP_INLINE_RESOLVE = 1u << 9,
    FOGVOL_SPEEDUP_BLEND_COLOR = 1u << 10,
    FOGVOL_SPEEDUP_FLOAT_O = 1u << 11,
    FOGVOL_SPEEDUP_SKIP_CHECK = 1u << 12,
    FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH = 1u << 13,
    FOGVOL_SPEEDUP_EXACT_SUM = 1u << 14,
    FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST = 1u << 15
};
#define FOGVOL_OVERFLOW_BANDS 8 /* FOGVOL_SPEEDUP_OVERFLOW_BANDS: bands a picture's check is spread over */

#ifndef FOGVOL_NO_ANALYTIC /* the analytic fog shares nothing with the renderer: define it to leave it out */
/* ---- analytic fog volumes (JCAB, GDC 2001) -------------------------------
   Per-vertex (or per-pixel) fog from simple analytic volumes, without render
   passes or textures: for every vertex V the ray X = eye + t (V - eye) is cut
   by each volume into an entry/exit pair t1 <= t2, clamped to [0, 1] (t = 0 at
   the eye, 1 at the vertex). The distance travelled through a volume is
   |V - eye| * (t2 - t1) world units. Shapes: classic distance fog, half-space,
   sphere, and any affine transform of the unit sphere (ellipsoid), of the unit
   cube [-1,1]^3 (box) and of the unit cylinder (radius 1, |z| <= 1) (the ray is
   transformed into the unit shape's space; t is the same there).

   Fog factor f: 1 = no fog, 0 = fully fogged; fog colour C: what the fog adds.
   The fogged colour of a surface is  surface * f + C * (1 - f)  (or fold the
   two into the vertex colours with fogvol_fold_fog, the paper's trick).
     FOGVOL_FOG_LINEAR       f = 1 - clamp01(distance * density)  (the paper's law);
                             several volumes add up: f = 1 - sum, stopped at 0
     FOGVOL_FOG_EXP          f = exp(-distance * density); transmittances multiply
     FOGVOL_FOG_LINEAR_SEED  the linear f with the paper's colour formula verbatim
                             (C = volume colour * f + C * (1 - f), front to back).
                             It is exact when the ray ends fully fogged but
                             otherwise over-weights the volumes further back:
                             two volumes taking a, b of the fog give
                             C = cb (1 - a) + ca a instead of (ca a + cb b)/(a + b).
   LINEAR and EXP use the consistent colour: every stretch of fog contributes its
   colour weighted by how much of the final pixel it covers (1 - f of the stretch
   times the transmittance in front of it), C = sum(colour * weight) / sum(weight).

   Combination (fogvol_fog_mix):
     FOGVOL_MIX_SEPARATE         volumes sorted front to back by t1, each taken
                                 whole (the paper's "several fog volumes"), with
                                 early exit once fully fogged. Right for volumes
                                 that do not overlap along the rays.
     FOGVOL_MIX_INTERPENETRATING the paper's event list: (t1, +colour*density,
                                 +density), (t2, -colour*density, -density) per
                                 volume, sorted by t (ties: entry before exit,
                                 then volume order), and every stretch between
                                 events fogged with the summed density and the
                                 density-weighted mean colour of the volumes it
                                 is in. Exact for overlapping volumes.
   With one volume on a ray the two modes agree; with the LINEAR law they agree
   until the ray is fully fogged. The sort is an insertion sort that starts from
   the order of the previous vertex or the previous frame (fogvol_analytic_order);
   it is skipped where the order cannot matter (one volume on the ray, LINEAR
   before full fog, EXP with a single fog colour). EXP stops once the
   transmittance is below 1e-7; LINEAR and LINEAR_SEED once the fog reaches 0.

   Classic linear distance fog from fog_start to fog_end is a DISTANCE volume with
   min_distance = fog_start, max_distance = fog_end, density = 1 / (end - start)
   and the LINEAR law; max_distance <= 0 means no far bound.

   The GLSL programs (fogvol_analytic_shader_strings, every dialect) evaluate the
   same thing per vertex or per pixel for up to FOGVOL_ANALYTIC_MAX_VOLUMES
   volumes read from one uniform array, filled by fogvol_analytic_pack_uniforms:

       uniform vec4 fv_analytic[FOGVOL_ANALYTIC_UNIFORM_VEC4S];   (42 vec4)
       [0]            (eye.x, eye.y, eye.z, volume count)
       [1]            (law, mix, 0, 0)           (fogvol_fog_law, fogvol_fog_mix)
       [2 + 5i + 0..2] rows of the world -> unit-shape affine map of volume i
                      (DISTANCE: (min, max or 0, 0, 0); HALF_SPACE: the plane
                      with a unit normal)
       [2 + 5i + 3]   (red, green, blue, density)
       [2 + 5i + 4]   (shape, 0, 0, 0)                  (fogvol_analytic_shape)
   Upload all of it with glUniform4fv(location of "fv_analytic", 42, values).
   Programs: vertex attribute 0 "fv_position" (vec3, object space), uniforms
   "fv_mvp" (mat4, clip from object) and "fv_model" (mat4, world from object).
   The fragment shader writes vec4(fog colour, fog factor) to fv_fragcolor /
   gl_FragColor; the per-vertex programs pass it in the varying "fv_fog", the
   per-pixel ones pass the world position in "fv_world". Engines that write
   their own shaders paste the strings of fogvol_analytic_snippet(): the
   uniform, void fogvol_analytic(vec3 world_pos, out float fog, out vec3 color)
   and fogvol_fold_fog(inout vec4 diffuse, inout vec4 specular, float fog,
   vec3 color) (GLSL for Vulkan: declare vec4 fv_analytic[42] in a block of your own and #define
   FOGVOL_ANALYTIC_IN_BLOCK before them). FOGVOL_GLSL_VULKAN's own programs read one std140 block at
   (set 0, binding 0): fv_mvp at byte 0, fv_model at 64, fv_analytic at 128; fv_position at location 0.
   Fragment shaders need highp and 42 uniform vectors (GLES2 promises 16 only).

   Degenerate input never gives NaN: invalid volumes are left out of a set (and
   reported), vertices with a non-finite coordinate get f = 1, C = 0 (counted). */

/* volumes a fogvol_analytic_set holds (the CPU side), at most 128; define it
   identically in every file that uses the set */
#ifndef FOGVOL_ANALYTIC_CAPACITY
#define FOGVOL_ANALYTIC_CAPACITY 32
#endif
#if FOGVOL_ANALYTIC_CAPACITY < 1 || FOGVOL_ANALYTIC_CAPACITY > 128
#error "FOGVOL_ANALYTIC_CAPACITY must be 1..128 (event orders are stored in bytes)"
#endif
#define FOGVOL_ANALYTIC_MAX_VOLUMES 8 /* volumes the shaders read */
#define FOGVOL_ANALYTIC_UNIFORM_VEC4S (2 + 5 * FOGVOL_ANALYTIC_MAX_VOLUMES)
#define FOGVOL_ANALYTIC_UNIFORM_FLOATS (4 * FOGVOL_ANALYTIC_UNIFORM_VEC4S)
/* bytes of fogvol_analytic_order.vertex_orders for `vertices` vertices */
#define FOGVOL_ANALYTIC_ORDER_BYTES(vertices, volumes) ((size_t)(vertices) * 2u * (size_t)(volumes))

typedef enum fogvol_analytic_shape {
    FOGVOL_SHAPE_DISTANCE = 0,   /* min_distance <= |X - eye| <= max_distance (max <= 0: no bound) */
    FOGVOL_SHAPE_HALF_SPACE = 1, /* plane[0] x + plane[1] y + plane[2] z + plane[3] >= 0: the normal
                                    points into the fog (the paper's (X - P).N > 0); negate the
                                    plane for the other side */
    FOGVOL_SHAPE_SPHERE = 2,     /* |X - center| <= radius */
    FOGVOL_SHAPE_ELLIPSOID = 3,  /* transform * unit sphere */
    FOGVOL_SHAPE_BOX = 4,        /* transform * [-1,1]^3 */
    FOGVOL_SHAPE_CYLINDER = 5,   /* transform * {x^2 + y^2 <= 1, |z| <= 1} */
    FOGVOL_SHAPE_COUNT = 6,
    FOGVOL_SHAPE_MAX_ENUM = 0x7fffffff
} fogvol_analytic_shape;

/* A zeroed volume is valid: distance fog of density 0 (no fog). Only the
   fields of the shape are read. */
typedef struct fogvol_analytic_volume {
    fogvol_analytic_shape shape;
    float color[3];
    float density;       /* per world unit, >= 0 */
    float min_distance;  /* DISTANCE: >= 0 */
    float max_distance;  /* DISTANCE: > min_distance, or <= 0 (or >= 1e30) for no far bound */
    float plane[4];      /* HALF_SPACE: (a, b, c, d), any non-zero normal length */
    float center[3];     /* SPHERE */
    float radius;        /* SPHERE: > 0 */
    float transform[16]; /* ELLIPSOID, BOX, CYLINDER: unit shape -> world, column-major, affine
                            (last row 0 0 0 1) and invertible; all 16 zero = identity */
} fogvol_analytic_volume;

typedef enum fogvol_fog_law {
    FOGVOL_FOG_LINEAR = 0,
    FOGVOL_FOG_EXP = 1,
    FOGVOL_FOG_LINEAR_SEED = 2,
    FOGVOL_FOG_LAW_MAX_ENUM = 0x7fffffff
} fogvol_fog_law;

typedef enum fogvol_fog_mix {
    FOGVOL_MIX_SEPARATE = 0,
    FOGVOL_MIX_INTERPENETRATING = 1,
    FOGVOL_FOG_MIX_MAX_ENUM = 0x7fffffff
} fogvol_fog_mix;

/* How fogvol_analytic_batch evaluates its vertices (fogvol_analytic_set.kernel).
   The float kernels work on blocks of 32 vertices in structure-of-arrays float
   loops (8 lanes with AVX2, 4 with SSE2), skip the volumes whose bounding
   sphere no ray of a block can reach, redo grazing rays of spheres,
   ellipsoids and cylinders (and every ray of such a volume seen from further
   than 64 radii) in double, and sort only the events of the volumes a ray
   hits (the exp() of the EXP law's stretches batched over a block's sorted
   vertices, 8 at a time with AVX2); they stay within 1.2e-5 of the double
   kernel in fog and in colour x (1 - fog), except where a chord is the small
   difference of two entry times near the far end of a long ray (a half-space,
   box or cut cylinder seen kilometres away): there the optical depth is off by
   up to about density x length x 6e-8 (7.6e-4 for density 2 at 10 km; under
   1/255 in the colour), and they give the same results bit for bit among
   themselves. AVX2 and SSE2 are chosen at run time (GCC and clang
   on x86; the CPU is asked with __builtin_cpu_supports); a level the compiler
   or the CPU lacks falls back to the next one down
   (fogvol_analytic_kernel_resolve). */
typedef enum fogvol_analytic_kernel {
    FOGVOL_ANALYTIC_KERNEL_AUTO = 0,   /* the best float kernel this CPU runs */
    FOGVOL_ANALYTIC_KERNEL_DOUBLE = 1, /* everything in double (the reference; the batch before 2026-11) */
    FOGVOL_ANALYTIC_KERNEL_FLOAT = 2,  /* the float kernel in plain C (every compiler and architecture) */
    FOGVOL_ANALYTIC_KERNEL_SSE2 = 3,   /* the float kernel, SSE2 square roots, 4 lanes */
    FOGVOL_ANALYTIC_KERNEL_AVX2 = 4,   /* the float kernel compiled for AVX2, 8 lanes, exp() too */
    FOGVOL_ANALYTIC_KERNEL_COUNT = 5,
    FOGVOL_ANALYTIC_KERNEL_MAX_ENUM = 0x7fffffff
} fogvol_analytic_kernel;

/* Prepared volumes (inverse transforms etc.), caller-owned, about 5 KB; a
   zeroed set holds no volume. Fields are filled by fogvol_analytic_prepare. */
typedef struct fogvol_analytic_set {
    int count;            /* usable volumes */
    int ignored;          /* invalid volumes left out */
    int truncated;        /* volumes beyond FOGVOL_ANALYTIC_CAPACITY left out */
    int uniform_color;    /* 1: every volume with density > 0 has the same colour */
    int source[FOGVOL_ANALYTIC_CAPACITY];  /* index of each volume in the array given to prepare */
    int shape[FOGVOL_ANALYTIC_CAPACITY];   /* fogvol_analytic_shape */
    double map[FOGVOL_ANALYTIC_CAPACITY][12]; /* rows of the world -> unit-shape map (see the uniforms) */
    double density[FOGVOL_ANALYTIC_CAPACITY];
    double color[FOGVOL_ANALYTIC_CAPACITY][3];
    int kernel;           /* fogvol_analytic_kernel for fogvol_analytic_batch; prepare sets 0 (AUTO):
                             change it after prepare */
} fogvol_analytic_set;

/* The insertion sorts' starting orders, carried between vertices and calls
   (frame-to-frame coherence). Caller-owned, zero-initialise it. With
   vertex_orders == NULL one order is carried from vertex to vertex and from
   call to call; with a buffer of FOGVOL_ANALYTIC_ORDER_BYTES(vertices,
   set count) bytes, vertex i of a batch keeps its own order there (use one
   struct per vertex array). The contents never change results (ties are
   broken by volume order), only the time the sorts take; any bytes are safe
   (orders that are not permutations are replaced). Only the DOUBLE kernel
   (fogvol_analytic_kernel) reads and writes the orders: the float kernels
   sort the few events of the volumes on each ray, starting from the order of
   the previous sorted vertex of the same call; they still fill
   sorted_vertices and moves. */
typedef struct fogvol_analytic_order {
    unsigned char *vertex_orders; /* optional */
    size_t vertex_orders_size;    /* bytes */
    unsigned char carried[2 * FOGVOL_ANALYTIC_CAPACITY]; /* library-owned */
    int carried_count;            /* library-owned */
    int sorted_vertices;          /* last call: vertices that needed the sort (the others had at
                                     most one volume on their ray, or an order-free law) */
    int64_t moves;                /* last call: insertion-sort moves (0: every order was right) */
} fogvol_analytic_order;

/* Validates and prepares count volumes. Invalid ones (non-finite values,
   density < 0, radius <= 0, max_distance in (0, min_distance], a zero plane
   normal, a matrix that is not affine or is singular: |det| < 1e-6 x the
   product of its column lengths, or a world -> unit map with an entry beyond
   1e30, which the shaders' floats could not hold) are left out and the call
   returns FOGVOL_ERROR_INVALID_ARGUMENT; the others are still usable (a set
   is never left half-written: count, ignored and source say what it holds;
   volumes of density 0 are kept and add nothing). More than
   FOGVOL_ANALYTIC_CAPACITY volumes: the first ones are kept and the call
   returns FOGVOL_ERROR_BUFFER_TOO_SMALL. */
FOGVOL_API fogvol_result fogvol_analytic_prepare(const fogvol_analytic_volume *volumes, int count,
                                                 fogvol_analytic_set *set);
/* Entry/exit of one volume on the ray from eye to p, clamped to [0, 1]. A hit
   gives *t1 < *t2; a miss *t1 = *t2 = 0. Invalid volume or non-finite input:
   FOGVOL_ERROR_INVALID_ARGUMENT (and 0, 0). */
FOGVOL_API fogvol_result fogvol_analytic_segment(const fogvol_analytic_volume *volume, const float eye[3],
                                                 const float p[3], float *t1, float *t2);
/* Fog factor and colour at one point. Non-finite eye or p: fog 1, colour 0,
   FOGVOL_ERROR_INVALID_ARGUMENT. color may be NULL. */
FOGVOL_API fogvol_result fogvol_analytic_eval(const fogvol_analytic_set *set, const float eye[3], const float p[3],
                                              fogvol_fog_law law, fogvol_fog_mix mix, float *fog, float color[3]);
/* The same for count vertices: positions every stride bytes (0 = 12), fog_out
   every fog_stride bytes (0 = 4), color_out (3 floats) every color_stride bytes
   (0 = 12); either output may be NULL. Outputs may sit in the same vertex
   structs as the positions. No allocation; blocks of vertices are evaluated
   in structure-of-arrays loops (set->kernel: float with run-time SIMD
   dispatch by default, or double; see fogvol_analytic_kernel). order may be NULL.
   Vertices with a non-finite coordinate get fog 1, colour 0; *invalid (may be
   NULL) counts them and the call returns FOGVOL_ERROR_INVALID_ARGUMENT when
   there are any (every output is still written). */
FOGVOL_API fogvol_result fogvol_analytic_batch(const fogvol_analytic_set *set, const float eye[3],
                                               const float *positions, int count, int stride, fogvol_fog_law law,
                                               fogvol_fog_mix mix, float *fog_out, int fog_stride, float *color_out,
                                               int color_stride, fogvol_analytic_order *order, int *invalid);
/* The kernel fogvol_analytic_batch runs for a set whose kernel field is
   `requested`: AUTO gives the best this build and CPU have, a level they lack
   the next one down (AVX2 -> SSE2 -> FLOAT); DOUBLE and FLOAT are always
   there. Values outside the enum give FOGVOL_ANALYTIC_KERNEL_COUNT (the batch
   refuses them with FOGVOL_ERROR_INVALID_ARGUMENT). */
FOGVOL_API fogvol_analytic_kernel fogvol_analytic_kernel_resolve(fogvol_analytic_kernel requested);
/* The paper's register trick: new_diffuse = diffuse * fog, new_specular =
   specular * fog + fog_color * (1 - fog), on rgb (alpha unchanged); then
   texture * new_diffuse + new_specular = fogged (texture * diffuse + specular).
   fog is clamped to [0, 1] (NaN: 1). Outputs may alias the inputs; a NULL
   diffuse/specular pair is skipped. */
FOGVOL_API void fogvol_fold_fog(const float diffuse[4], const float specular[4], float fog, const float fog_color[3],
                                float new_diffuse[4], float new_specular[4]);
/* Fills the FOGVOL_ANALYTIC_UNIFORM_FLOATS values of "fv_analytic" (layout
   above). More than FOGVOL_ANALYTIC_MAX_VOLUMES volumes: the first ones are
   packed and the call returns FOGVOL_ERROR_UNSUPPORTED. */
FOGVOL_API fogvol_result fogvol_analytic_pack_uniforms(const fogvol_analytic_set *set, const float eye[3],
                                                       fogvol_fog_law law, fogvol_fog_mix mix,
                                                       float out[FOGVOL_ANALYTIC_UNIFORM_FLOATS]);
/* The strings of the analytic fog program's vertex or fragment shader, per
   vertex (per_pixel = 0) or per pixel (1), ready for glShaderSource. Every
   dialect; AUTO and unknown values: FOGVOL_ERROR_UNSUPPORTED, *count = 0. */
FOGVOL_API fogvol_result fogvol_analytic_shader_strings(fogvol_dialect dialect, fogvol_stage stage, int per_pixel,
                                                        const char **strings, int *count);
/* GLSL for the engine's own shaders (any dialect; after #version and the
   precision statements): the uniform, fogvol_analytic() and fogvol_fold_fog().
   Returns the number of strings (3, to be passed in order); writes
   min(3, capacity) of them when strings != NULL. */
FOGVOL_API int fogvol_analytic_snippet(const char **strings, int capacity);

#endif /* FOGVOL_NO_ANALYTIC */

/* ---- CPU reference ------------------------------------------------------- */
/* CPU reference of the GPU arithmetic. The renderer does not call these: they
   model byte for byte what the encode, blend and decode passes compute, for
   tests (fogvol's own and a custom backend's) and for offline tools. */
/* Reference encoder: exactly the RGBA8 bytes the GPU writes for normalised
   depth d (nearest sampling of the ramps). dither_row in [0, dither_steps);
   row 0 is the undithered (round-to-nearest) row. */
FOGVOL_API fogvol_result fogvol_encode_depth(const fogvol_encoding *enc, double d, int dither_row,
                                             unsigned char out_rgba[4]);
/* Saturating per-channel sum, as RGBA8 additive blending does: acc += value.
   Returns 1 if any channel saturated (the true sum exceeded 255), else 0. */
FOGVOL_API int fogvol_sum_rgba8(const unsigned char value[4], unsigned char acc[4]);
/* Sum count encoded values (count*4 bytes) from zero; *saturated (may be NULL)
   tells whether any channel saturated. */
FOGVOL_API fogvol_result fogvol_sum_encoded(const unsigned char *values, int count, unsigned char out_rgba[4],
                                            int *saturated);
/* Decoded value in units of (far - near): R/N + G/N^2 + B/N^3 - A/N^2. */
FOGVOL_API double fogvol_decode(const fogvol_encoding *enc, const unsigned char rgba[4]);
/* decode(a) - decode(b), computed as decode of the channel differences. */
FOGVOL_API double fogvol_decode_difference(const fogvol_encoding *enc, const unsigned char a[4],
                                           const unsigned char b[4]);

#ifdef __cplusplus
}
#endif
#endif /* FOGVOL_H */

/* ========================================================================== */
/*                              IMPLEMENTATION                                */
/* ========================================================================== */
#ifdef FOGVOL_IMPLEMENTATION
#ifndef FOGVOL_IMPLEMENTATION_DONE
#define FOGVOL_IMPLEMENTATION_DONE

#include <string.h>
#include <stdarg.h>
#include <stdio.h>  /* vsnprintf only: the library never prints */

#ifndef FOGVOL_ASSERT
#include <assert.h>
#define FOGVOL_ASSERT(x) assert(x)
#endif
#if !defined(FOGVOL_SQRT) || !defined(FOGVOL_EXP) || !defined(FOGVOL_FLOOR) || !defined(FOGVOL_FABS) || \
    !defined(FOGVOL_POW)
#include <math.h>
#endif
#ifndef FOGVOL_SQRT
#define FOGVOL_SQRT(x) sqrt(x)
#endif
#ifndef FOGVOL_EXP
#define FOGVOL_EXP(x) exp(x)
#endif
#ifndef FOGVOL_FLOOR
#define FOGVOL_FLOOR(x) floor(x)
#endif
#ifndef FOGVOL_FABS
#define FOGVOL_FABS(x) fabs(x)
#endif
#ifndef FOGVOL_POW
#define FOGVOL_POW(x, y) pow(x, y)
#endif
#if !defined(FOGVOL_MALLOC) || !defined(FOGVOL_FREE)
#include <stdlib.h>
#define FOGVOL_MALLOC(sz) malloc(sz)
#define FOGVOL_FREE(p) free(p)
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* >>cpu =================================================================== */

FOGVOL_API int fogvol_renderer_is_software(const char *renderer)
{
    static const char *const names[] = {"llvmpipe", "softpipe", "Software Rasterizer", "SwiftShader",
                                        "Basic Render Driver", "GDI Generic", "Apple Software Renderer"};
    size_t i;
    if (!renderer) return 0;
    for (i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (strstr(renderer, names[i])) return 1;
    return 0;
}

FOGVOL_API const char *fogvol_result_string(fogvol_result result)
{
    switch (result) {
    case FOGVOL_SUCCESS: return "success";
    case FOGVOL_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case FOGVOL_ERROR_OUT_OF_MEMORY: return "out of memory";
    case FOGVOL_ERROR_BUFFER_TOO_SMALL: return "buffer too small";
    case FOGVOL_ERROR_UNSUPPORTED: return "unsupported";
    case FOGVOL_ERROR_INVALID_MESH: return "invalid mesh";
    case FOGVOL_ERROR_INVALID_STATE: return "invalid state";
    case FOGVOL_ERROR_MISSING_FUNCTION: return "missing GL function";
    case FOGVOL_ERROR_SHADER_COMPILE: return "shader compile failed";
    case FOGVOL_ERROR_SHADER_LINK: return "shader link failed";
    case FOGVOL_ERROR_FRAMEBUFFER: return "framebuffer incomplete";
    case FOGVOL_ERROR_BACKEND: return "backend error";
    case FOGVOL_ERROR_DEPTH_OVERFLOW: return "depth complexity overflow";
    default: return "unknown result";
    }
}

static void *fogvol__alloc(const fogvol_allocator *a, size_t size)
{
    if (size == 0) size = 1;
    if (a && a->alloc) return a->alloc(size, a->user_data);
    return FOGVOL_MALLOC(size);
}

static void fogvol__free(const fogvol_allocator *a, void *p)
{
    if (!p) return;
    if (a && a->alloc) {
        if (a->free) a->free(p, a->user_data);
        return;
    }
    FOGVOL_FREE(p);
}

static void fogvol__log(const fogvol_logger *lg, fogvol_log_level level, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    if (!lg || !lg->func) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    lg->func(lg->user_data, level, buf);
}

static int fogvol__finite(double x) { return x == x && x - x == 0.0; }

static int fogvol__finite_n(const float *v, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (!fogvol__finite(v[i])) return 0;
    return 1;
}

/* ---- encoding ---- */

FOGVOL_API fogvol_result fogvol_encoding_init(int bits, fogvol_encoding *out)
{
    if (!out || bits < 1 || bits > 8) return FOGVOL_ERROR_INVALID_ARGUMENT;
    out->bits = bits;
    out->levels = 1 << bits;
    out->precision_bits = 3 * bits;
    out->max_faces = 1 << (8 - bits);
    out->max_faces_single = bits <= 7 ? 1 << (7 - bits) : 0;
    /* D texels per blue LSB; keep the blue ramp <= 2048 texels wide (GLES2 minimum max size). */
    out->dither_steps = 32;
    while (out->levels * out->dither_steps > 2048 && out->dither_steps > 8) out->dither_steps /= 2;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_encoding_from_faces(int max_faces, fogvol_encoding *out)
{
    int bits;
    if (!out || max_faces < 1) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (max_faces > 128) return FOGVOL_ERROR_UNSUPPORTED;
    for (bits = 8; bits >= 1; --bits)
        if ((1 << (8 - bits)) >= max_faces) return fogvol_encoding_init(bits, out);
    return FOGVOL_ERROR_UNSUPPORTED;
}

FOGVOL_API fogvol_result fogvol_encoding_from_precision(int precision_bits, fogvol_encoding *out)
{
    int bits;
    if (!out || precision_bits < 1) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (precision_bits > 24) return FOGVOL_ERROR_UNSUPPORTED;
    for (bits = 1; bits <= 8; ++bits)
        if (3 * bits >= precision_bits) return fogvol_encoding_init(bits, out);
    return FOGVOL_ERROR_UNSUPPORTED;
}

FOGVOL_API int fogvol_encoding_table(fogvol_encoding *rows, int capacity)
{
    int i;
    for (i = 0; rows && i < 8 && i < capacity; ++i) fogvol_encoding_init(i + 1, &rows[i]);
    return 8;
}

static int fogvol__enc_ok(const fogvol_encoding *e)
{
    fogvol_encoding ref;
    if (!e || fogvol_encoding_init(e->bits, &ref) != FOGVOL_SUCCESS) return 0;
    return ref.levels == e->levels && ref.dither_steps == e->dither_steps;
}

FOGVOL_API fogvol_result fogvol_compute_constants(const fogvol_encoding *enc, float znear, float zfar, float scale,
                                                  fogvol_constants *out)
{
    double n, range;
    if (!out || !fogvol__enc_ok(enc)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!fogvol__finite(znear) || !fogvol__finite(zfar) || !fogvol__finite(scale) || !(zfar > znear) || scale < 0)
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    n = enc->levels;
    range = (double)zfar - (double)znear;
    memset(out, 0, sizeof *out);
    out->near_far[0] = (float)(1.0 / range);
    out->near_far[1] = (float)(-(double)znear / range);
    out->ramp_scale[0] = 1.0f;
    out->ramp_scale[1] = (float)n;
    out->ramp_scale[2] = (float)(n * n);
    out->ramp_scale[3] = 0.0f;
    out->depth_offset = (float)(1.0 / (n * n * n));
    out->depth_max = (float)(1.0 - 1.5 / (n * n * n));
    out->scale = scale > 0 ? scale : (float)(range * 255.0 / n);
    out->decode[0] = out->scale;
    out->decode[1] = (float)(out->scale / n);
    out->decode[2] = (float)(out->scale / (n * n));
    out->decode[3] = (float)(-out->scale / n);
    out->bias[0] = out->bias[1] = out->bias[2] = 128.0f / 255.0f;
    out->bias[3] = 0.0f;
    out->bias_decoded = out->bias[0] * (out->decode[0] + out->decode[1] + out->decode[2]);
    out->lsb = (float)(out->scale / (255.0 * n * n));
    out->dither_rows = (float)enc->dither_steps;
    return FOGVOL_SUCCESS;
}

/* The texel of the blue ramp: x in [0, N*D), row in [0, D). */
static void fogvol__blue_texel(const fogvol_encoding *e, int x, int row, unsigned char out[4])
{
    int d = e->dither_steps;
    int k = (row + d / 2) % d;  /* threshold k/D: row 0 -> 1/2 */
    int q = (x + k) / d - 1;    /* floor(x/D + k/D) - 1, in [-1, N-1] */
    if (q < 0) {
        out[2] = (unsigned char)(q + e->levels);
        out[3] = 1;
    } else {
        out[2] = (unsigned char)q;
        out[3] = 0;
    }
    out[0] = out[1] = 0;
}

FOGVOL_API double fogvol_dither_threshold(const fogvol_encoding *enc, int row)
{
    int d;
    if (!fogvol__enc_ok(enc) || row < 0 || row >= enc->dither_steps) return 0.0;
    d = enc->dither_steps;
    return (double)((row + d / 2) % d) / d;
}

FOGVOL_API fogvol_result fogvol_encode_depth(const fogvol_encoding *enc, double d, int dither_row,
                                             unsigned char out_rgba[4])
{
    double n, n3, u, t1, dmax;
    long long h, x, nd;
    unsigned char b[4];
    if (!fogvol__enc_ok(enc) || !out_rgba || dither_row < 0 || dither_row >= enc->dither_steps ||
        !fogvol__finite(d))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    n = enc->levels;
    n3 = n * n * n;
    dmax = (double)(float)(1.0 - 1.5 / n3); /* the GPU's clamp, fogvol_compute_constants' float (L = 8: 1 - 2^-23) */
    u = d < 0 ? 0 : (d > dmax ? dmax : d);
    u += 1.0 / n3;
    t1 = u * n3;                 /* blue units, exact scaling by a power of two */
    h = (long long)FOGVOL_FLOOR(t1 / n);            /* rg texel: red = h / N, green = h % N */
    nd = (long long)enc->levels * enc->dither_steps;
    x = (long long)FOGVOL_FLOOR(t1 * enc->dither_steps) % nd; /* blue texel column */
    fogvol__blue_texel(enc, (int)x, dither_row, b);
    out_rgba[0] = (unsigned char)((h / enc->levels) % enc->levels);
    out_rgba[1] = (unsigned char)(h % enc->levels);
    out_rgba[2] = b[2];
    out_rgba[3] = b[3];
    return FOGVOL_SUCCESS;
}

FOGVOL_API int fogvol_sum_rgba8(const unsigned char value[4], unsigned char acc[4])
{
    int i, sat = 0;
    for (i = 0; i < 4; ++i) {
        int s = acc[i] + value[i];
        if (s > 255) {
            s = 255;
            sat = 1;
        }
        acc[i] = (unsigned char)s;
    }
    return sat;
}

FOGVOL_API fogvol_result fogvol_sum_encoded(const unsigned char *values, int count, unsigned char out_rgba[4],
                                            int *saturated)
{
    int i, sat = 0;
    if (!out_rgba || count < 0 || (count > 0 && !values)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(out_rgba, 0, 4);
    for (i = 0; i < count; ++i) sat |= fogvol_sum_rgba8(values + 4 * i, out_rgba);
    if (saturated) *saturated = sat;
    return FOGVOL_SUCCESS;
}

static double fogvol__decode_i(const fogvol_encoding *e, double r, double g, double b, double a)
{
    double n = e->levels;
    return r / n + g / (n * n) + b / (n * n * n) - a / (n * n);
}

FOGVOL_API double fogvol_decode(const fogvol_encoding *enc, const unsigned char rgba[4])
{
    if (!fogvol__enc_ok(enc) || !rgba) return 0.0;
    return fogvol__decode_i(enc, rgba[0], rgba[1], rgba[2], rgba[3]);
}

FOGVOL_API double fogvol_decode_difference(const fogvol_encoding *enc, const unsigned char a[4],
                                           const unsigned char b[4])
{
    if (!fogvol__enc_ok(enc) || !a || !b) return 0.0;
    return fogvol__decode_i(enc, (double)a[0] - b[0], (double)a[1] - b[1], (double)a[2] - b[2],
                            (double)a[3] - b[3]);
}

/* ---- textures ---- */

static fogvol_result fogvol__image_check(int w, int h, unsigned char *pixels, size_t capacity, fogvol_image *info)
{
    if (!info) return FOGVOL_ERROR_INVALID_ARGUMENT;
    info->width = w;
    info->height = h;
    info->size = (size_t)w * (size_t)h * 4u;
    if (pixels && capacity < info->size) return FOGVOL_ERROR_BUFFER_TOO_SMALL;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_make_rg_ramp(const fogvol_encoding *enc, unsigned char *pixels, size_t capacity,
                                             fogvol_image *info)
{
    int x, y, n;
    fogvol_result r;
    if (!fogvol__enc_ok(enc)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    n = enc->levels;
    r = fogvol__image_check(n, n, pixels, capacity, info);
    if (r != FOGVOL_SUCCESS || !pixels) return r;
    for (y = 0; y < n; ++y)
        for (x = 0; x < n; ++x) {
            unsigned char *p = pixels + ((size_t)y * n + x) * 4;
            p[0] = (unsigned char)x;
            p[1] = (unsigned char)y;
            p[2] = 0;
            p[3] = 0;
        }
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_make_blue_ramp(const fogvol_encoding *enc, unsigned char *pixels, size_t capacity,
                                               fogvol_image *info)
{
    int x, y, w, h;
    fogvol_result r;
    if (!fogvol__enc_ok(enc)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    w = enc->levels * enc->dither_steps;
    h = enc->dither_steps;
    r = fogvol__image_check(w, h, pixels, capacity, info);
    if (r != FOGVOL_SUCCESS || !pixels) return r;
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x) fogvol__blue_texel(enc, x, y, pixels + ((size_t)y * w + x) * 4);
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_make_dither_index(const fogvol_encoding *enc, unsigned char *pixels,
                                                  size_t capacity, fogvol_image *info)
{
    int x, y, d;
    fogvol_result r;
    if (!fogvol__enc_ok(enc)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    r = fogvol__image_check(FOGVOL_DITHER_PATTERN, FOGVOL_DITHER_PATTERN, pixels, capacity, info);
    if (r != FOGVOL_SUCCESS || !pixels) return r;
    d = enc->dither_steps;
    for (y = 0; y < 8; ++y)
        for (x = 0; x < 8; ++x) {
            /* 8x8 Bayer index by bit interleaving, 0..63 */
            int v = 0, bit, xy = x ^ y, k, row;
            unsigned char *p = pixels + ((size_t)y * 8 + x) * 4;
            for (bit = 0; bit < 3; ++bit) {
                v |= ((xy >> bit) & 1) << (5 - 2 * bit);
                v |= ((y >> bit) & 1) << (4 - 2 * bit);
            }
            k = v * d / 64;          /* wanted threshold k/D */
            row = (k + d / 2) % d;   /* the row holding it */
            p[0] = (unsigned char)row;
            p[1] = p[2] = 0;
            p[3] = 255;
        }
    return FOGVOL_SUCCESS;
}

static unsigned char fogvol__unorm8(double v)
{
    if (!(v > 0)) return 0; /* also NaN */
    if (v > 1) v = 1;
    return (unsigned char)(v * 255.0 + 0.5);
}

static float fogvol__ramp_max_thickness(const fogvol_ramp_desc *d)
{
    int i;
    float m = 0;
    if (d->max_thickness > 0) return d->max_thickness;
    switch (d->model) {
    case FOGVOL_RAMP_EXTINCTION: return 7.0f / d->density; /* 1 - e^-7 = 0.99909 */
    case FOGVOL_RAMP_LINEAR: return 1.0f / d->density;
    case FOGVOL_RAMP_GRADIENT:
        for (i = 0; i < d->key_count; ++i)
            if (d->keys[i].thickness > m) m = d->keys[i].thickness;
        return m > 0 ? m : 1.0f;
    default: return 0;
    }
}

static fogvol_result fogvol__ramp_check(const fogvol_ramp_desc *d)
{
    int i, j;
    if (!d) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (d->width != 0 && (d->width < 2 || d->width > 4096)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!fogvol__finite(d->max_thickness) || d->max_thickness < 0) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (d->blend != FOGVOL_BLEND_FOG && d->blend != FOGVOL_BLEND_LIGHT) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!fogvol__finite(d->softness) || d->softness < 0) return FOGVOL_ERROR_INVALID_ARGUMENT;
    switch (d->model) {
    case FOGVOL_RAMP_EXTINCTION:
    case FOGVOL_RAMP_LINEAR:
        if (!fogvol__finite_n(d->color, 3) || !fogvol__finite(d->density) || !(d->density > 0))
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        for (i = 0; i < 3; ++i)
            if (!fogvol__finite(d->extinction_color[i]) || d->extinction_color[i] < 0)
                return FOGVOL_ERROR_INVALID_ARGUMENT;
        return FOGVOL_SUCCESS;
    case FOGVOL_RAMP_GRADIENT:
        if (!d->keys || d->key_count < 1) return FOGVOL_ERROR_INVALID_ARGUMENT;
        for (i = 0; i < d->key_count; ++i) {
            if (!fogvol__finite(d->keys[i].thickness) || d->keys[i].thickness < 0) return FOGVOL_ERROR_INVALID_ARGUMENT;
            for (j = 0; j < 4; ++j)
                if (!fogvol__finite(d->keys[i].rgba[j])) return FOGVOL_ERROR_INVALID_ARGUMENT;
        }
        return FOGVOL_SUCCESS;
    default: return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
}

/* Gradient at thickness t: keys in any order; below the first / above the last key, clamp. */
static void fogvol__gradient(const fogvol_color_key *keys, int count, double t, double out[4])
{
    int i, j, lo = -1, hi = -1;
    for (i = 0; i < count; ++i) {
        if (keys[i].thickness <= t && (lo < 0 || keys[i].thickness >= keys[lo].thickness)) lo = i;
        if (keys[i].thickness >= t && (hi < 0 || keys[i].thickness < keys[hi].thickness)) hi = i;
    }
    if (lo < 0) lo = hi;
    if (hi < 0) hi = lo;
    for (j = 0; j < 4; ++j) {
        double a = keys[lo].rgba[j], b = keys[hi].rgba[j];
        double span = (double)keys[hi].thickness - keys[lo].thickness;
        double f = span > 0 ? (t - keys[lo].thickness) / span : 0.0;
        out[j] = a + (b - a) * f;
    }
}

FOGVOL_API fogvol_result fogvol_make_color_ramp(const fogvol_ramp_desc *desc, unsigned char *pixels,
                                                size_t capacity, fogvol_image *info, float *max_thickness_out)
{
    int i, w;
    double tmax;
    fogvol_result r = fogvol__ramp_check(desc);
    if (r != FOGVOL_SUCCESS) return r;
    w = desc->width ? desc->width : 256;
    tmax = fogvol__ramp_max_thickness(desc);
    if (!fogvol__finite(tmax) || !(tmax > 0)) return FOGVOL_ERROR_INVALID_ARGUMENT; /* 7/density overflowed */
    if (max_thickness_out) *max_thickness_out = (float)tmax;
    r = fogvol__image_check(w, 1, pixels, capacity, info);
    if (r != FOGVOL_SUCCESS || !pixels) return r;
    for (i = 0; i < w; ++i) {
        double t = tmax * i / (w - 1), c[4];
        unsigned char *p = pixels + (size_t)i * 4;
        if (desc->model == FOGVOL_RAMP_GRADIENT) {
            fogvol__gradient(desc->keys, desc->key_count, t, c);
        } else {
            c[0] = desc->color[0];
            c[1] = desc->color[1];
            c[2] = desc->color[2];
            c[3] = desc->model == FOGVOL_RAMP_EXTINCTION ? 1.0 - FOGVOL_EXP(-(double)desc->density * t)
                                                         : t * desc->density;
        }
        p[0] = fogvol__unorm8(c[0]);
        p[1] = fogvol__unorm8(c[1]);
        p[2] = fogvol__unorm8(c[2]);
        p[3] = fogvol__unorm8(c[3]);
    }
    return FOGVOL_SUCCESS;
}

/* ---- mesh validation ---- */

typedef struct fogvol__edge {
    uint32_t lo, hi; /* vertex indices, lo < hi */
    uint32_t tri;    /* triangle */
    uint32_t fwd;    /* 1: directed lo -> hi in the triangle */
} fogvol__edge;

static int fogvol__edge_less(const fogvol__edge *a, const fogvol__edge *b)
{
    if (a->lo != b->lo) return a->lo < b->lo;
    if (a->hi != b->hi) return a->hi < b->hi;
    return a->tri < b->tri;
}

/* Bottom-up merge sort (no recursion, stable, O(n log n)); tmp has n entries. */
static void fogvol__sort_edges(fogvol__edge *e, fogvol__edge *tmp, size_t n)
{
    size_t width, i;
    fogvol__edge *src = e, *dst = tmp;
    for (width = 1; width < n; width *= 2) {
        for (i = 0; i < n; i += 2 * width) {
            size_t a = i, am = i + width < n ? i + width : n, b = am, bm = i + 2 * width < n ? i + 2 * width : n;
            size_t o = i;
            while (a < am && b < bm) dst[o++] = fogvol__edge_less(&src[b], &src[a]) ? src[b++] : src[a++];
            while (a < am) dst[o++] = src[a++];
            while (b < bm) dst[o++] = src[b++];
        }
        {
            fogvol__edge *t = src;
            src = dst;
            dst = t;
        }
    }
    if (src != e) memcpy(e, src, n * sizeof *e);
}

/* Union-find with parity: parity(t) = orientation of t relative to its root. */
static uint32_t fogvol__uf_find(uint32_t *parent, unsigned char *parity, uint32_t t)
{
    uint32_t root = t, cur = t;
    unsigned acc = 0;
    while (parent[root] != root) {
        acc ^= parity[root];
        root = parent[root];
    }
    /* acc = parity of t relative to root; compress the path, keeping parities relative to root */
    while (parent[cur] != cur) {
        uint32_t next = parent[cur];
        unsigned old = parity[cur];
        parity[cur] = (unsigned char)acc;
        parent[cur] = root;
        acc ^= old;
        cur = next;
    }
    return root;
}

/* fogvol_mesh_desc's defaults: a zero stride means tightly packed xyz. */
static int fogvol__mesh_stride(const fogvol_mesh_desc *d)
{
    return d->stride ? d->stride : 12;
}

/* No index array (fogvol_mesh_desc): the triangles are the vertices 0, 1, 2, then 3, 4, 5, ... */
static int fogvol__non_indexed(const fogvol_mesh_desc *d)
{
    return !d->indices && !d->indices16 && d->index_count == 0;
}

/* Indices the mesh's triangles have (vertex_count without an index array). */
static int fogvol__index_count(const fogvol_mesh_desc *d)
{
    return fogvol__non_indexed(d) ? d->vertex_count : d->index_count;
}

/* NULL for a usable layout, else what is wrong with it. */
static const char *fogvol__mesh_problem(const fogvol_mesh_desc *d)
{
    int stride;
    if (!d || !d->positions) return "no positions";
    if (d->vertex_count <= 0 || fogvol__index_count(d) <= 0 || fogvol__index_count(d) % 3 != 0)
        return fogvol__non_indexed(d) ? "no index array: vertex_count must be a positive multiple of 3"
                                      : "vertex_count must be > 0 and index_count a positive multiple of 3";
    if (d->stride < 0 || (d->stride != 0 && d->stride < 12)) return "stride below the 12 bytes of a position";
    stride = fogvol__mesh_stride(d);
    if (d->offset < 0 || d->offset > stride - 12) return "offset + 12 beyond the stride";
    if (d->index_type != FOGVOL_INDEX_UINT32 && d->index_type != FOGVOL_INDEX_UINT16) return "unknown index_type";
    if (!fogvol__non_indexed(d) && (d->index_type == FOGVOL_INDEX_UINT32 ? !d->indices : !d->indices16))
        return "no index array of index_type (leave both arrays NULL and index_count 0 for none)";
    if (!fogvol__finite(d->weld_distance) || d->weld_distance < 0) return "weld_distance negative or not finite";
    return NULL;
}

/* The weld's sweep order: each vertex's coordinate on the sweep axis as an unsigned key in the order
   of the floats (-0 as +0), with its number. */
typedef struct fogvol__wkey {
    uint32_t key;
    uint32_t i;
} fogvol__wkey;

static uint32_t fogvol__sweep_key(float f)
{
    uint32_t b;
    f += 0.0f; /* -0 -> +0 */
    memcpy(&b, &f, sizeof b);
    return (b & 0x80000000u) ? ~b : b | 0x80000000u;
}

/* Stable LSD radix sort of k by key, 8 bits a pass (tmp: n entries), so that equal keys keep their
   vertices' order: O(n). */
static void fogvol__sort_wkeys(fogvol__wkey *k, fogvol__wkey *tmp, int n)
{
    size_t cnt[256], sum, c;
    fogvol__wkey *src = k, *dst = tmp, *t;
    int pass, i;
    for (pass = 0; pass < 4; ++pass) { /* (an even count: the result ends in k) */
        unsigned sh = 8u * (unsigned)pass;
        memset(cnt, 0, sizeof cnt);
        for (i = 0; i < n; ++i) cnt[(src[i].key >> sh) & 255u]++;
        for (i = 0, sum = 0; i < 256; ++i) {
            c = cnt[i];
            cnt[i] = sum;
            sum += c;
        }
        for (i = 0; i < n; ++i) dst[cnt[(src[i].key >> sh) & 255u]++] = src[i];
        t = src;
        src = dst;
        dst = t;
    }
}

/* The weld's sweep: the kept vertices in a hash of their cells on the two axes across the sweep
   (cells dist wide: floor(coordinate / dist) as a double; the quotient of two floats is exact
   enough in double that coordinates within dist of each other lie in the same or neighbouring
   cells, for any floats), chained newest first (heads: mask + 1 buckets, next: per vertex). */
typedef struct fogvol__weld_grid {
    const unsigned char *base;
    int stride, axis; /* axis: the sweep's */
    float dist;
    uint32_t *heads, *next, mask;
} fogvol__weld_grid;

#define FOGVOL__NONE 0xffffffffu

/* v's cell across the sweep: floor(coordinate / dist) on the two other axes. */
static void fogvol__weld_cell(const fogvol__weld_grid *g, const float v[3], double c[2])
{
    c[0] = FOGVOL_FLOOR((double)v[(g->axis + 1) % 3] / g->dist);
    c[1] = FOGVOL_FLOOR((double)v[(g->axis + 2) % 3] / g->dist);
}

/* The bucket of cell c moved by (du, dv) (-0 made +0; cells beyond 32-bit integers hashed by their
   bits). Neighbours along the second axis land in neighbouring buckets. */
static uint32_t fogvol__weld_bucket(const fogvol__weld_grid *g, const double c[2], int du, int dv)
{
    uint32_t h[2], w[2];
    int k;
    for (k = 0; k < 2; ++k) {
        double x = c[k] + (k ? dv : du) + 0.0;
        if (x > -2147483648.0 && x < 2147483648.0) {
            h[k] = (uint32_t)(int32_t)x;
        } else {
            memcpy(w, &x, sizeof w);
            h[k] = (w[0] ^ w[1]) * 0x9e3779b1u;
        }
    }
    return (h[0] * 0x9e3779b1u + h[1]) & g->mask;
}

/* The lowest-numbered kept vertex within dist of v on every axis among those the sweep has met, from
   the 9 cells around v's cell c across the sweep, FOGVOL__NONE: none. A vertex more than dist behind v
   along the sweep is behind every vertex to come as well: the chain is cut there (it and every older
   entry), so the chains hold the last dist of the sweep only. */
static uint32_t fogvol__weld_find(fogvol__weld_grid *g, const float v[3], const double c[2])
{
    uint32_t best = FOGVOL__NONE, j, *link;
    float w[3];
    int d;
    for (d = 0; d < 9; ++d)
        for (link = &g->heads[fogvol__weld_bucket(g, c, d % 3 - 1, d / 3 - 1)]; (j = *link) != FOGVOL__NONE;
             link = &g->next[j]) {
            memcpy(w, g->base + (size_t)j * g->stride, sizeof w);
            if ((double)v[g->axis] - w[g->axis] > g->dist) {
                *link = FOGVOL__NONE;
                break;
            }
            if (j < best && FOGVOL_FABS((double)w[0] - v[0]) <= g->dist &&
                FOGVOL_FABS((double)w[1] - v[1]) <= g->dist && FOGVOL_FABS((double)w[2] - v[2]) <= g->dist)
                best = j;
        }
    return best;
}

/* The axis of largest extent of the finite vertices (rep[i] = i on the way). */
static int fogvol__weld_axis(const unsigned char *base, int stride, int nv, uint32_t *rep)
{
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, v[3];
    int i, k, axis = 0, any = 0;
    for (i = 0; i < nv; ++i) {
        memcpy(v, base + (size_t)i * stride, sizeof v);
        rep[i] = (uint32_t)i;
        if (!fogvol__finite_n(v, 3)) continue;
        for (k = 0; k < 3; ++k) {
            if (!any || v[k] < lo[k]) lo[k] = v[k];
            if (!any || v[k] > hi[k]) hi[k] = v[k];
        }
        any = 1;
    }
    for (k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    return axis;
}

/* Weld: rep[i] = the lowest-numbered kept vertex within dist of vertex i on every axis among those
   before it in the sweep (i itself when none): the sweep takes the vertices in order of their
   coordinate on the axis of largest extent (then of their number) and keeps a vertex that finds
   none. Non-finite vertices stay alone. The candidates come from fogvol__weld_find, so vertices
   sharing the sweep's coordinate (a face of a subdivided cube) cost no more than others: O(n) but for
   hash collisions. Scratch memory from alloc: 20 bytes per vertex and 4 per hash bucket (one bucket
   per 2 to 4 vertices).
   Returns how many vertices were merged, -1: out of memory. */
static int fogvol__weld(const unsigned char *base, int stride, int nv, float dist, const fogvol_allocator *alloc,
                        uint32_t *rep)
{
    fogvol__weld_grid g;
    fogvol__wkey *keys;
    size_t buckets = 2;
    float v[3];
    int i, merged = 0;
    while (buckets < (size_t)nv / 4u && buckets < ((size_t)1 << 30)) buckets <<= 1; /* (the chains hold the
                                                       sweep's last dist only: small, cached buckets) */
    keys = (fogvol__wkey *)fogvol__alloc(alloc, sizeof(fogvol__wkey) * 2u * (size_t)nv); /* (+ the sort's) */
    g.heads = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * (buckets + (size_t)nv));
    if (!keys || !g.heads) {
        fogvol__free(alloc, keys);
        fogvol__free(alloc, g.heads);
        return -1;
    }
    g.base = base;
    g.stride = stride;
    g.dist = dist;
    g.next = g.heads + buckets;
    g.mask = (uint32_t)(buckets - 1u);
    memset(g.heads, 0xff, sizeof(uint32_t) * buckets);
    g.axis = fogvol__weld_axis(base, stride, nv, rep);
    for (i = 0; i < nv; ++i) {
        memcpy(v, base + (size_t)i * stride, sizeof v);
        keys[i].key = fogvol__sweep_key(fogvol__finite_n(v, 3) ? v[g.axis] : 3.0e38f); /* non-finite: skipped */
        keys[i].i = (uint32_t)i;
    }
    fogvol__sort_wkeys(keys, keys + nv, nv);
    for (i = 0; i < nv; ++i) {
        uint32_t self = keys[i].i, best, h;
        double c[2];
        memcpy(v, base + (size_t)self * stride, sizeof v);
        if (!fogvol__finite_n(v, 3)) continue;
        fogvol__weld_cell(&g, v, c);
        best = fogvol__weld_find(&g, v, c);
        if (best != FOGVOL__NONE) {
            rep[self] = best;
            merged++;
            continue;
        }
        h = fogvol__weld_bucket(&g, c, 0, 0); /* kept: a candidate for the vertices after it */
        g.next[self] = g.heads[h];
        g.heads[h] = self;
    }
    fogvol__free(alloc, keys);
    fogvol__free(alloc, g.heads);
    return merged;
}

/* The desc's indices as 32 bits (0, 1, 2, ... without an index array), welded when asked: *out is NULL
   when the desc's own 32-bit array serves as it is, else an array from alloc. */
static fogvol_result fogvol__mesh_indices(const fogvol_mesh_desc *d, const fogvol_allocator *alloc, uint32_t **out,
                                          int *welded)
{
    const unsigned char *base = (const unsigned char *)d->positions + d->offset;
    int i, stride = fogvol__mesh_stride(d), weld = d->weld_distance > 0, n = fogvol__index_count(d);
    uint32_t *idx, *rep = NULL;
    *out = NULL;
    *welded = 0;
    if (!weld && d->index_type == FOGVOL_INDEX_UINT32 && !fogvol__non_indexed(d)) return FOGVOL_SUCCESS;
    idx = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * (size_t)n);
    if (weld) rep = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * (size_t)d->vertex_count);
    if (weld && rep && idx) *welded = fogvol__weld(base, stride, d->vertex_count, d->weld_distance, alloc, rep);
    if (!idx || (weld && (!rep || *welded < 0))) {
        fogvol__free(alloc, idx);
        fogvol__free(alloc, rep);
        *welded = 0;
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    for (i = 0; i < n; ++i)
        idx[i] = fogvol__non_indexed(d)                 ? (uint32_t)i
                 : d->index_type == FOGVOL_INDEX_UINT16 ? (uint32_t)d->indices16[i]
                                                        : d->indices[i];
    for (i = 0; weld && i < n; ++i)
        if (idx[i] < (uint32_t)d->vertex_count) idx[i] = rep[idx[i]];
    fogvol__free(alloc, rep);
    *out = idx;
    return FOGVOL_SUCCESS;
}

static fogvol_result fogvol__validate(const fogvol_mesh_desc *desc, const uint32_t *indices,
                                      const fogvol_allocator *alloc, fogvol_mesh_report *rep);

/* Validation that hands the (welded, 32-bit) indices to create_mesh when idx_out is set. */
static fogvol_result fogvol__check_mesh(const fogvol_mesh_desc *desc, const fogvol_allocator *alloc,
                                        fogvol_mesh_report *rep, uint32_t **idx_out)
{
    uint32_t *idx = NULL;
    int welded = 0;
    fogvol_result r;
    if (idx_out) *idx_out = NULL;
    if (!rep) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(rep, 0, sizeof *rep);
    if (fogvol__mesh_problem(desc)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    r = fogvol__mesh_indices(desc, alloc, &idx, &welded);
    if (r != FOGVOL_SUCCESS) return r;
    r = fogvol__validate(desc, idx ? idx : desc->indices, alloc, rep);
    rep->welded_vertices = welded;
    rep->vertices -= welded;
    if (idx_out && r != FOGVOL_ERROR_OUT_OF_MEMORY) *idx_out = idx;
    else fogvol__free(alloc, idx);
    return r;
}

FOGVOL_API fogvol_result fogvol_validate_mesh(const fogvol_mesh_desc *desc, const fogvol_allocator *alloc,
                                              fogvol_mesh_report *rep)
{
    return fogvol__check_mesh(desc, alloc, rep, NULL);
}

/* ---- winding number: parts wound inward that nothing encloses ----
   A closed, consistent hull renders sum(back) - sum(front) = the length of the
   ray inside, counted with the winding number of each stretch (entered minus
   left). Regions of winding 1 (or more, overlaps) are fog; a region of negative
   winding renders negative thickness. Two probes find such regions: a point
   just inside every component wound inward (an enclosed cavity has winding 0
   there, an exposed inward part -1), and a grid of rays along each axis whose
   running winding must never drop below 0 (inverted lobes of self-intersecting
   hulls). Rays that touch an edge or a vertex exactly are skipped. */
typedef struct fogvol__wind {
    const unsigned char *base;
    int stride;
    const uint32_t *idx;
    int ntri;
    const unsigned char *ok; /* 2: a triangle with area and finite corners */
} fogvol__wind;

#define FOGVOL__WIND_GRID 32

static void fogvol__wind_tri(const fogvol__wind *w, int t, double p[3][3])
{
    int k, c;
    float v[3];
    for (k = 0; k < 3; ++k) {
        memcpy(v, w->base + (size_t)w->idx[3 * t + k] * (size_t)w->stride, sizeof v);
        for (c = 0; c < 3; ++c) p[k][c] = v[c];
    }
}

/* Winding number at q: signed crossings of the ray q + s d (s > 0), +1 where it
   leaves through a face (normal along d). Returns 0 when the ray touches an edge. */
static int fogvol__winding_at(const fogvol__wind *w, const double q[3], const double d[3], int *wind)
{
    int t, k, n = 0;
    for (t = 0; t < w->ntri; ++t) {
        double p[3][3], e1[3], e2[3], h[3], s[3], qq[3], det, u, v, dist;
        if (w->ok[t] != 2) continue;
        fogvol__wind_tri(w, t, p);
        for (k = 0; k < 3; ++k) {
            e1[k] = p[1][k] - p[0][k];
            e2[k] = p[2][k] - p[0][k];
            s[k] = q[k] - p[0][k];
        }
        h[0] = d[1] * e2[2] - d[2] * e2[1];
        h[1] = d[2] * e2[0] - d[0] * e2[2];
        h[2] = d[0] * e2[1] - d[1] * e2[0];
        det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
        if (det == 0.0) continue; /* parallel to the ray */
        u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
        qq[0] = s[1] * e1[2] - s[2] * e1[1];
        qq[1] = s[2] * e1[0] - s[0] * e1[2];
        qq[2] = s[0] * e1[1] - s[1] * e1[0];
        v = (d[0] * qq[0] + d[1] * qq[1] + d[2] * qq[2]) / det;
        dist = (e2[0] * qq[0] + e2[1] * qq[1] + e2[2] * qq[2]) / det;
        if (dist <= 0.0 || u < 0.0 || v < 0.0 || u + v > 1.0) continue;
        if (u < 1e-9 || v < 1e-9 || u + v > 1.0 - 1e-9) return 0;
        /* det = e1 . (d x e2) = -(e1 x e2) . d: < 0 when the face normal points along d (leaving) */
        n += det < 0.0 ? 1 : -1;
    }
    *wind = n;
    return 1;
}

/* Per component: its signed volume; a component wound inward is probed just
   inside its largest triangle. */
static fogvol_result fogvol__component_winding(const fogvol__wind *w, uint32_t *parent, unsigned char *parity,
                                               double *tvol, fogvol_mesh_report *rep)
{
    static const double dirs[3][3] = {{0.5773, 0.5801, 0.5748}, {-0.3313, 0.8412, 0.4271}, {0.7071, -0.2093, -0.6753}};
    double *cvol = tvol + w->ntri;
    int t, k, c;
    for (t = 0; t < w->ntri; ++t) cvol[t] = 0.0;
    for (t = 0; t < w->ntri; ++t)
        if (w->ok[t] == 2) cvol[fogvol__uf_find(parent, parity, (uint32_t)t)] += tvol[t];
    for (t = 0; t < w->ntri; ++t) {
        double p[3][3], n[3], q[3], len, best = -1.0;
        int r, bt = -1, wind = 0, tries;
        if (!(cvol[t] < 0.0)) continue;
        rep->inward_components++;
        for (r = 0; r < w->ntri; ++r) { /* the component's largest triangle */
            if (w->ok[r] != 2 || fogvol__uf_find(parent, parity, (uint32_t)r) != (uint32_t)t) continue;
            if (-tvol[r] > best || bt < 0) {
                fogvol__wind_tri(w, r, p);
                n[0] = (p[1][1] - p[0][1]) * (p[2][2] - p[0][2]) - (p[1][2] - p[0][2]) * (p[2][1] - p[0][1]);
                n[1] = (p[1][2] - p[0][2]) * (p[2][0] - p[0][0]) - (p[1][0] - p[0][0]) * (p[2][2] - p[0][2]);
                n[2] = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
                len = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
                if (len > best) {
                    best = len;
                    bt = r;
                }
            }
        }
        if (bt < 0) continue;
        fogvol__wind_tri(w, bt, p);
        n[0] = (p[1][1] - p[0][1]) * (p[2][2] - p[0][2]) - (p[1][2] - p[0][2]) * (p[2][1] - p[0][1]);
        n[1] = (p[1][2] - p[0][2]) * (p[2][0] - p[0][0]) - (p[1][0] - p[0][0]) * (p[2][2] - p[0][2]);
        n[2] = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
        len = FOGVOL_SQRT(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        /* a point 1e-4 of the triangle's size in front of it: on the side its normal names */
        for (c = 0; c < 3; ++c) q[c] = (p[0][c] + p[1][c] + p[2][c]) / 3.0 + n[c] / len * 1e-4 * FOGVOL_SQRT(len);
        for (tries = 0, k = 0; k < 3 && !tries; ++k) tries = fogvol__winding_at(w, q, dirs[k], &wind);
        if (tries && wind < 0) {
            rep->negative_winding++;
            if (rep->negative_triangle < 0) rep->negative_triangle = bt;
        }
    }
    return FOGVOL_SUCCESS;
}

typedef struct fogvol__xing {
    double t;
    int sign; /* +1 entering, -1 leaving, travelling along +axis */
    int tri;
} fogvol__xing;

/* Crossings of the triangle with the grid rays of axis a: counted (xs NULL) or stored. */
static void fogvol__grid_tri(double p[3][3], int a, const double lo[3], const double step[3], int tri,
                             uint32_t *count, unsigned char *skip, fogvol__xing *xs, const uint32_t *start)
{
    int u = (a + 1) % 3, v = (a + 2) % 3, i, j, i0, i1, j0, j1, k;
    double area = (p[1][u] - p[0][u]) * (p[2][v] - p[0][v]) - (p[2][u] - p[0][u]) * (p[1][v] - p[0][v]);
    double umin = p[0][u], umax = p[0][u], vmin = p[0][v], vmax = p[0][v];
    /* a ray's offsets in its cell differ in u and v, and do not sum to 1: a ray never lies on a
       diagonal of a quad whose corners are on grid lines (of any whole number of steps) */
    const double offu = 0.5123, offv = 0.4671;
    if (area == 0.0) return;
    for (k = 1; k < 3; ++k) {
        if (p[k][u] < umin) umin = p[k][u];
        if (p[k][u] > umax) umax = p[k][u];
        if (p[k][v] < vmin) vmin = p[k][v];
        if (p[k][v] > vmax) vmax = p[k][v];
    }
    i0 = (int)FOGVOL_FLOOR((umin - lo[u]) / step[u] - offu);
    i1 = (int)FOGVOL_FLOOR((umax - lo[u]) / step[u] - offu) + 1;
    j0 = (int)FOGVOL_FLOOR((vmin - lo[v]) / step[v] - offv);
    j1 = (int)FOGVOL_FLOOR((vmax - lo[v]) / step[v] - offv) + 1;
    if (i0 < 0) i0 = 0;
    if (j0 < 0) j0 = 0;
    if (i1 > FOGVOL__WIND_GRID - 1) i1 = FOGVOL__WIND_GRID - 1;
    if (j1 > FOGVOL__WIND_GRID - 1) j1 = FOGVOL__WIND_GRID - 1;
    for (j = j0; j <= j1; ++j) {
        double qv = lo[v] + (j + offv) * step[v];
        if (qv < vmin || qv > vmax) continue; /* outside the triangle's box: neither inside nor on an edge */
        for (i = i0; i <= i1; ++i) {
            double qu = lo[u] + (i + offu) * step[u], e[3];
            int ray = (a * FOGVOL__WIND_GRID + j) * FOGVOL__WIND_GRID + i;
            if (qu < umin || qu > umax) continue;
            for (k = 0; k < 3; ++k) { /* edge k (corner k to k+1) against q, sign-normalised */
                const double *p0 = p[k], *p1 = p[(k + 1) % 3];
                e[k] = ((p1[u] - p0[u]) * (qv - p0[v]) - (p1[v] - p0[v]) * (qu - p0[u])) * (area > 0 ? 1 : -1);
            }
            if (e[0] < 0 || e[1] < 0 || e[2] < 0) continue;
            if (e[0] == 0 || e[1] == 0 || e[2] == 0) { /* on an edge: this ray cannot be trusted */
                skip[ray] = 1;
                continue;
            }
            if (!xs) {
                count[ray]++;
            } else {
                fogvol__xing *x = &xs[start[ray] + count[ray]++];
                double s = e[0] + e[1] + e[2]; /* = |area| */
                x->t = (e[1] * p[0][a] + e[2] * p[1][a] + e[0] * p[2][a]) / s;
                x->sign = area > 0 ? -1 : 1;
                x->tri = tri;
            }
        }
    }
}

static fogvol_result fogvol__grid_winding(const fogvol__wind *w, const fogvol_allocator *alloc,
                                          fogvol_mesh_report *rep)
{
    enum { NR = 3 * FOGVOL__WIND_GRID * FOGVOL__WIND_GRID };
    double lo[3], hi[3], step[3], p[3][3];
    uint32_t *count, *start, total = 0;
    unsigned char *skip;
    fogvol__xing *xs = NULL;
    int t, a, c, k, r, first = 1;
    for (t = 0; t < w->ntri; ++t) {
        if (w->ok[t] != 2) continue;
        fogvol__wind_tri(w, t, p);
        if (first)
            for (c = 0; c < 3; ++c) lo[c] = hi[c] = p[0][c];
        first = 0;
        for (k = 0; k < 3; ++k)
            for (c = 0; c < 3; ++c) {
                if (p[k][c] < lo[c]) lo[c] = p[k][c];
                if (p[k][c] > hi[c]) hi[c] = p[k][c];
            }
    }
    if (first) return FOGVOL_SUCCESS;
    for (c = 0; c < 3; ++c) step[c] = (hi[c] - lo[c]) / FOGVOL__WIND_GRID;
    if (!(step[0] > 0 && step[1] > 0 && step[2] > 0)) return FOGVOL_SUCCESS; /* flat: nothing enclosed */
    count = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * 2u * NR);
    skip = (unsigned char *)fogvol__alloc(alloc, NR);
    if (!count || !skip) {
        fogvol__free(alloc, count);
        fogvol__free(alloc, skip);
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    start = count + NR;
    memset(count, 0, sizeof(uint32_t) * NR);
    memset(skip, 0, NR);
    for (t = 0; t < w->ntri; ++t)
        if (w->ok[t] == 2) {
            fogvol__wind_tri(w, t, p);
            for (a = 0; a < 3; ++a) fogvol__grid_tri(p, a, lo, step, t, count, skip, NULL, NULL);
        }
    for (r = 0; r < NR; ++r) {
        start[r] = total;
        total += count[r];
        count[r] = 0;
    }
    if (total) xs = (fogvol__xing *)fogvol__alloc(alloc, sizeof(fogvol__xing) * total);
    if (total && !xs) {
        fogvol__free(alloc, count);
        fogvol__free(alloc, skip);
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    for (t = 0; t < w->ntri; ++t)
        if (w->ok[t] == 2) {
            fogvol__wind_tri(w, t, p);
            for (a = 0; a < 3; ++a) fogvol__grid_tri(p, a, lo, step, t, count, skip, xs, start);
        }
    for (r = 0; xs && r < NR; ++r) { /* xs NULL: no ray crossed a face (xs + 0 would be undefined) */
        fogvol__xing *x = xs + start[r];
        int n = (int)count[r], i, j, sum = 0;
        if (skip[r] || n == 0) continue;
        for (i = 1; i < n; ++i) { /* insertion sort by t, entries first at equal t */
            fogvol__xing v = x[i];
            for (j = i - 1; j >= 0 && (x[j].t > v.t || (x[j].t == v.t && x[j].sign < v.sign)); --j) x[j + 1] = x[j];
            x[j + 1] = v;
        }
        for (i = 0; i < n; ++i) {
            sum += x[i].sign;
            if (sum < 0) {
                rep->negative_winding++;
                if (rep->negative_triangle < 0) rep->negative_triangle = x[i].tri;
                break;
            }
        }
    }
    fogvol__free(alloc, xs);
    fogvol__free(alloc, count);
    fogvol__free(alloc, skip);
    return FOGVOL_SUCCESS;
}

/* The working arrays of one mesh validation. */
typedef struct fogvol__vwork {
    const unsigned char *base; /* vertex 0's x */
    const uint32_t *indices;
    int stride, ntri, nvert;
    size_t ne;                 /* edges used */
    fogvol__edge *edges, *tmp; /* 3 per triangle, and the sort's scratch */
    uint32_t *parent, *cnt;    /* union-find of triangles across shared edges; orientation counts */
    unsigned char *parity;     /* orientation relative to the component's root */
    unsigned char *usable;     /* 0: bad indices or degenerate; 1: topology only; 2: finite corners too */
    unsigned char *vbad;       /* per vertex: a non-finite coordinate */
    double *tvol, vol;         /* signed volume per triangle (tetrahedron with the origin), total */
} fogvol__vwork;

static void fogvol__vwork_free(const fogvol_allocator *alloc, fogvol__vwork *w)
{
    fogvol__free(alloc, w->tvol);
    fogvol__free(alloc, w->edges);
    fogvol__free(alloc, w->tmp);
    fogvol__free(alloc, w->parent);
    fogvol__free(alloc, w->cnt);
    fogvol__free(alloc, w->parity);
    fogvol__free(alloc, w->usable);
    fogvol__free(alloc, w->vbad);
}

static fogvol_result fogvol__vwork_alloc(const fogvol_allocator *alloc, fogvol__vwork *w)
{
    size_t nt = (size_t)w->ntri;
    w->edges = (fogvol__edge *)fogvol__alloc(alloc, sizeof(fogvol__edge) * 3u * nt);
    w->tmp = (fogvol__edge *)fogvol__alloc(alloc, sizeof(fogvol__edge) * 3u * nt);
    w->parent = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * nt);
    w->cnt = (uint32_t *)fogvol__alloc(alloc, sizeof(uint32_t) * 2u * nt);
    w->parity = (unsigned char *)fogvol__alloc(alloc, nt);
    w->usable = (unsigned char *)fogvol__alloc(alloc, nt);
    w->vbad = (unsigned char *)fogvol__alloc(alloc, (size_t)w->nvert);
    w->tvol = (double *)fogvol__alloc(alloc, sizeof(double) * 2u * nt);
    if (w->edges && w->tmp && w->parent && w->cnt && w->parity && w->usable && w->vbad && w->tvol)
        return FOGVOL_SUCCESS;
    fogvol__vwork_free(alloc, w);
    return FOGVOL_ERROR_OUT_OF_MEMORY;
}

/* Triangle t with finite corners id: slivers counted as degenerate, its signed volume added. */
static void fogvol__triangle_geometry(fogvol__vwork *w, int t, const uint32_t id[3], fogvol_mesh_report *rep)
{
    float a[3], b[3], c[3];
    double e1[3], e2[3], cr[3], len2, l1, l2, l3;
    int k;
    memcpy(a, w->base + id[0] * (size_t)w->stride, sizeof a);
    memcpy(b, w->base + id[1] * (size_t)w->stride, sizeof b);
    memcpy(c, w->base + id[2] * (size_t)w->stride, sizeof c);
    for (k = 0; k < 3; ++k) {
        e1[k] = (double)b[k] - a[k];
        e2[k] = (double)c[k] - a[k];
    }
    cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
    cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
    cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
    len2 = cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2];
    l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    l3 = (e2[0] - e1[0]) * (e2[0] - e1[0]) + (e2[1] - e1[1]) * (e2[1] - e1[1]) + (e2[2] - e1[2]) * (e2[2] - e1[2]);
    if (l2 > l1) l1 = l2;
    if (l3 > l1) l1 = l3;
    /* area below 1e-6 of the longest edge squared: a sliver that rasterises to nothing */
    if (len2 <= 1e-12 * l1 * l1) rep->degenerate_triangles++;
    w->tvol[t] = (a[0] * cr[0] + a[1] * cr[1] + a[2] * cr[2]) / 6.0;
    w->vol += w->tvol[t];
    w->usable[t] = 2; /* with finite corners: takes part in the winding checks */
}

/* Per vertex: finite or not. Per triangle: indices in range, not degenerate, its geometry, and
   its three edges (for the topology). */
static void fogvol__validate_triangles(fogvol__vwork *w, fogvol_mesh_report *rep)
{
    int t, k;
    for (t = 0; t < w->nvert; ++t) {
        float v[3];
        memcpy(v, w->base + (size_t)t * (size_t)w->stride, sizeof v);
        w->vbad[t] = !fogvol__finite_n(v, 3);
        rep->nonfinite_vertices += w->vbad[t];
    }
    for (t = 0; t < w->ntri; ++t) {
        uint32_t id[3];
        int bad = 0;
        w->parent[t] = (uint32_t)t;
        w->parity[t] = 0;
        w->usable[t] = 0;
        w->tvol[t] = 0.0;
        for (k = 0; k < 3; ++k) {
            id[k] = w->indices[3 * t + k];
            if (id[k] >= (uint32_t)w->nvert) {
                rep->out_of_range_indices++;
                bad = 1;
            }
        }
        if (bad) continue;
        if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2]) {
            rep->degenerate_triangles++;
            continue; /* no area, no edges: left out of the topology */
        }
        w->usable[t] = 1;
        if (!w->vbad[id[0]] && !w->vbad[id[1]] && !w->vbad[id[2]]) fogvol__triangle_geometry(w, t, id, rep);
        for (k = 0; k < 3; ++k) {
            uint32_t u = id[k], v = id[(k + 1) % 3];
            fogvol__edge *e = &w->edges[w->ne++];
            e->lo = u < v ? u : v;
            e->hi = u < v ? v : u;
            e->tri = (uint32_t)t;
            e->fwd = u < v;
        }
    }
}

/* Open, non-manifold and inconsistent edges; the triangles joined into components across shared
   edges, with their orientation relative to the component; flipped faces = each component's
   minority orientation. */
static void fogvol__validate_topology(fogvol__vwork *w, fogvol_mesh_report *rep)
{
    size_t i, j;
    int t;
    fogvol__sort_edges(w->edges, w->tmp, w->ne);
    for (i = 0; i < w->ne; i = j) {
        for (j = i + 1; j < w->ne && w->edges[j].lo == w->edges[i].lo && w->edges[j].hi == w->edges[i].hi; ++j) {
        }
        if (j - i == 1) {
            rep->open_edges++;
        } else if (j - i > 2) {
            rep->nonmanifold_edges++;
        } else {
            uint32_t a = w->edges[i].tri, b = w->edges[i + 1].tri;
            unsigned want = w->edges[i].fwd == w->edges[i + 1].fwd; /* same direction: opposite orientation */
            uint32_t ra = fogvol__uf_find(w->parent, w->parity, a), rb = fogvol__uf_find(w->parent, w->parity, b);
            if (want) rep->inconsistent_edges++;
            if (ra != rb) {
                w->parent[rb] = ra;
                w->parity[rb] = (unsigned char)(w->parity[a] ^ w->parity[b] ^ want);
            }
        }
    }
    memset(w->cnt, 0, sizeof(uint32_t) * 2u * (size_t)w->ntri);
    for (t = 0; t < w->ntri; ++t) {
        uint32_t r;
        if (!w->usable[t]) continue;
        r = fogvol__uf_find(w->parent, w->parity, (uint32_t)t);
        w->cnt[2 * r + w->parity[t]]++;
    }
    for (t = 0; t < w->ntri; ++t) {
        uint32_t c0 = w->cnt[2 * t], c1 = w->cnt[2 * t + 1];
        if (c0 + c1 == 0) continue;
        rep->components++;
        rep->flipped_faces += (int)(c0 < c1 ? c0 : c1);
    }
}

/* The topology and geometry checks on 32-bit indices (layout already checked). */
static fogvol_result fogvol__validate(const fogvol_mesh_desc *desc, const uint32_t *indices,
                                      const fogvol_allocator *alloc, fogvol_mesh_report *rep)
{
    fogvol__vwork w;
    fogvol_result wr = FOGVOL_SUCCESS;
    memset(&w, 0, sizeof w);
    w.stride = fogvol__mesh_stride(desc);
    w.base = (const unsigned char *)desc->positions + desc->offset;
    w.indices = indices;
    w.ntri = fogvol__index_count(desc) / 3;
    w.nvert = desc->vertex_count;
    rep->vertices = desc->vertex_count;
    rep->triangles = w.ntri;
    if (fogvol__vwork_alloc(alloc, &w) != FOGVOL_SUCCESS) return FOGVOL_ERROR_OUT_OF_MEMORY;
    fogvol__validate_triangles(&w, rep);
    fogvol__validate_topology(&w, rep);
    rep->volume = w.vol;
    rep->closed = rep->open_edges == 0 && rep->nonmanifold_edges == 0;
    rep->consistent = rep->inconsistent_edges == 0 && rep->flipped_faces == 0;
    rep->inverted = rep->closed && rep->consistent && w.vol < 0;
    rep->negative_triangle = -1;
    if (rep->closed && rep->consistent && rep->nonfinite_vertices == 0 && rep->out_of_range_indices == 0) {
        fogvol__wind wd;
        wd.base = w.base;
        wd.stride = w.stride;
        wd.idx = indices;
        wd.ntri = w.ntri;
        wd.ok = w.usable;
        wr = fogvol__component_winding(&wd, w.parent, w.parity, w.tvol, rep);
        if (wr == FOGVOL_SUCCESS) wr = fogvol__grid_winding(&wd, alloc, rep);
    }
    rep->valid = rep->closed && rep->consistent && !rep->inverted && rep->nonfinite_vertices == 0 &&
                 rep->out_of_range_indices == 0 && w.vol > 0 && rep->negative_winding == 0;
    fogvol__vwork_free(alloc, &w);
    if (wr != FOGVOL_SUCCESS) return wr;
    return rep->valid ? FOGVOL_SUCCESS : FOGVOL_ERROR_INVALID_MESH;
}

/* >>dialects ============================================================== */
/* One row per GLSL dialect in fogvol__dialects: its #version lines, whether it is
   GLSL ES, whether it is a legacy dialect (attribute/varying, texture2D,
   gl_FragColor: no float targets, engine MRT output or texelFetch), how many
   colour outputs a fragment shader writes, which GL version it belongs to
   (FOGVOL_GLSL_AUTO), and its preludes for the volume programs
   (fogvol_shader_strings) and the analytic fog (fogvol_analytic_shader_strings).
   fogvol_dialect_name, fogvol_combination_supported and fogvol_msaa_supported
   read the same rows.
   To add a dialect: its value at the end of fogvol_dialect (before
   FOGVOL_GLSL_COUNT) and its row here.
   To add a variant: its bit in fogvol_variant (FOGVOL_VARIANT_ALL covers the
   bits in use) and its #define line in fogvol__variant_define; the tiers and
   dialects it combines with go to fogvol_combination_supported. */

static const char fogvol__highp_float[] = "precision highp float;\n";
static const char fogvol__vs_legacy[] = "#define FV_ATTRIB attribute\n#define FV_VARYING_OUT varying\n";
static const char fogvol__vs_modern[] = "#define FV_ATTRIB in\n#define FV_VARYING_OUT out\n";
static const char fogvol__fs_legacy[] =
    "#define FV_VARYING_IN varying\n#define FV_TEXTURE texture2D\n#define FV_FRAGCOLOR gl_FragColor\n";
static const char fogvol__fs_modern[] =
    "#define FV_VARYING_IN in\n#define FV_TEXTURE texture\nout vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";
/* GLES: highp where the GPU has it (samplers too: their default is lowp, which
   would fetch depths at low precision); the PS13 tier is written for mediump */
static const char fogvol__fs_es100[] =
    "#ifdef GL_FRAGMENT_PRECISION_HIGH\nprecision highp float;\nprecision highp sampler2D;\n#else\n"
    "precision mediump float;\nprecision mediump sampler2D;\n#endif\n"
    "#define FV_VARYING_IN varying\n#define FV_TEXTURE texture2D\n#define FV_FRAGCOLOR gl_FragColor\n";
/* FOGVOL_SPECIALIZE_FETCH_O and EXACT_SUM: the extension before any declaration, then (fogvol_shader_strings)
   the output at location 0 (EXACT_SUM: read too) and O read from location 1 (FV_FETCH_O) */
#define FOGVOL__FS_FETCH "#define FV_VARYING_IN in\n#define FV_TEXTURE texture\n"
static const char fogvol__fs_fetch_330[] = "#extension GL_EXT_shader_framebuffer_fetch : require\n" FOGVOL__FS_FETCH;
static const char fogvol__fs_fetch_es300[] = "#extension GL_EXT_shader_framebuffer_fetch : require\n"
                                             "precision highp float;\nprecision highp sampler2D;\n" FOGVOL__FS_FETCH;
#undef FOGVOL__FS_FETCH
static const char fogvol__fs_fetch_out[] = "layout(location = 0) out vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";
static const char fogvol__fs_fetch_sum[] = "layout(location = 0) inout vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";
static const char fogvol__fs_fetch_o[] = "layout(location = 1) inout vec4 fv_ofb;\n#define FV_FETCH_O\n";
static const char fogvol__fs_es300[] =
    "precision highp float;\nprecision highp sampler2D;\n#define FV_VARYING_IN in\n#define FV_TEXTURE texture\n"
    "out vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";
/* WIDE ENCODE/FACE write two targets: gl_FragData or an output array at location 0 */
static const char fogvol__fs_two_legacy[] =
    "#define FV_VARYING_IN varying\n#define FV_TEXTURE texture2D\n#define FV_OUT0 gl_FragData[0]\n"
    "#define FV_OUT1 gl_FragData[1]\n";
static const char fogvol__fs_two_modern[] =
    "#define FV_VARYING_IN in\n#define FV_TEXTURE texture\nout vec4 fv_frag[2];\n#define FV_OUT0 fv_frag[0]\n"
    "#define FV_OUT1 fv_frag[1]\n";
static const char fogvol__fs_two_layout[] =
    "#define FV_VARYING_IN in\n#define FV_TEXTURE texture\nlayout(location = 0) out vec4 fv_frag[2];\n"
    "#define FV_OUT0 fv_frag[0]\n#define FV_OUT1 fv_frag[1]\n";
static const char fogvol__fs_two_es300[] = "precision highp float;\nprecision highp sampler2D;\n";
/* the analytic fog samples no texture */
static const char fogvol__an_fs_es100[] =
    "#ifdef GL_FRAGMENT_PRECISION_HIGH\nprecision highp float;\n#else\nprecision mediump float;\n#endif\n";
static const char fogvol__an_fs_legacy[] = "#define FV_VARYING_IN varying\n#define FV_FRAGCOLOR gl_FragColor\n";
static const char fogvol__an_fs_modern[] =
    "#define FV_VARYING_IN in\nout vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";
/* Per-sample fragment shaders (fogvol_shader_desc.samples > 1): gl_SampleID needs
   GLSL 400 or ARB_sample_shading, declared before any other token. */
#define FOGVOL__SAMPLE_SHADING "#extension GL_ARB_sample_shading : require\n"

/* Declarations the program bodies write through macros, so that one body serves GL and Vulkan:
   FV_UNIFORM(type, name) (a GL uniform; in Vulkan a member of the pass block or of the push
   constants, declared here), FV_BINDING(unit) before a sampler (Vulkan: its binding in set 0),
   FV_LOCATION(n) before a vertex input or a varying (Vulkan: its location). */
static const char fogvol__decl_gl[] =
    "#define FV_UNIFORM(type, name) uniform type name;\n#define FV_BINDING(unit)\n#define FV_LOCATION(n)\n";
#define FOGVOL__VK_MACROS \
    "#define FV_VULKAN\n#define FV_UNIFORM(type, name)\n" \
    "#define FV_BINDING(unit) layout(set = 0, binding = unit)\n#define FV_LOCATION(n) layout(location = n)\n"
/* the pass block: fogvol_pass.uniforms as it is (FOGVOL_UNIFORMS in order, one vec4 each), at binding
   FOGVOL_MAX_TEXTURE_UNITS (8) after the samplers; the per-draw values: fogvol__vk_draw_offsets */
#define FOGVOL__VK_BLOCK_MEMBER(id, name) "    vec4 " #name ";\n"
static const char fogvol__decl_vulkan[] =
    FOGVOL__VK_MACROS
    "precision highp float;\nprecision highp int;\n" /* (no effect in GLSL 450: says what highp in the bodies means) */
    "layout(std140, set = 0, binding = 8) uniform fv_pass_block {\n" FOGVOL_UNIFORMS(FOGVOL__VK_BLOCK_MEMBER) "};\n"
    "layout(push_constant) uniform fv_draw_block {\n"
    "    layout(offset = 0) mat4 fv_mvp;\n"
    "    layout(offset = 64) vec4 fv_depth;\n"
    "    layout(offset = 80) vec4 fv_ext;\n"
    "    layout(offset = 96) vec4 fv_emit;\n"
    "    layout(offset = 112) float fv_sign;\n"
    "};\n";
#undef FOGVOL__VK_BLOCK_MEMBER
/* the analytic fog's block (what the engine fills: fv_mvp at 0, fv_model at 64, then the
   FOGVOL_ANALYTIC_UNIFORM_VEC4S vec4 of fogvol_analytic_pack_uniforms at 128) */
static const char fogvol__an_decl_vulkan[] =
    FOGVOL__VK_MACROS
    "layout(std140, set = 0, binding = 0) uniform fv_analytic_block {\n"
    "    mat4 fv_mvp;\n    mat4 fv_model;\n    vec4 fv_analytic[42];\n};\n#define FOGVOL_ANALYTIC_IN_BLOCK\n";
#undef FOGVOL__VK_MACROS
static const char fogvol__fs_vulkan[] =
    "#define FV_VARYING_IN in\n#define FV_TEXTURE texture\nlayout(location = 0) out vec4 fv_fragcolor;\n"
    "#define FV_FRAGCOLOR fv_fragcolor\n";
static const char fogvol__fs_vulkan_analytic[] =
    "#define FV_VARYING_IN in\nlayout(location = 0) out vec4 fv_fragcolor;\n#define FV_FRAGCOLOR fv_fragcolor\n";

typedef struct fogvol__dialect_info {
    const char *name;                 /* fogvol_dialect_name */
    const char *version;              /* the #version line */
    const char *version_msaa;         /* per-sample fragment shaders; NULL: not in this dialect */
    unsigned char es, legacy;         /* GLSL ES; legacy (see above) */
    unsigned char outputs;            /* colour outputs of a fragment shader */
    unsigned char gl_major, gl_minor; /* the oldest GL (GLES if es) whose newest dialect this is */
    const char *vs[2];                /* vertex prelude (NULL: no string) */
    const char *fs;                   /* fragment prelude, one output */
    const char *fs_two[2];            /* fragment prelude, two outputs (WIDE encode and face) */
    const char *an_vs[2], *an_fs[2];  /* the analytic fog's preludes */
    const char *fs_fetch;             /* fragment prelude of FOGVOL_SPECIALIZE_FETCH_O; NULL: not in this dialect */
    const char *decl, *an_decl;       /* after the prelude: FV_UNIFORM, FV_BINDING, FV_LOCATION (and the Vulkan
                                         blocks) for the volume programs and for the analytic fog */
    unsigned char vulkan;             /* SPIR-V: never chosen for a GL context */
} fogvol__dialect_info;

static const fogvol__dialect_info fogvol__dialects[] = {
    {"auto", "", NULL, 0, 0, 0, 0, 0, {NULL, NULL}, NULL, {NULL, NULL}, {NULL, NULL}, {NULL, NULL}, NULL, NULL, NULL,
     0},
    {"110", "#version 110\n", NULL, 0, 1, 2, 2, 0, {fogvol__vs_legacy, NULL}, fogvol__fs_legacy,
     {fogvol__fs_two_legacy, NULL}, {NULL, fogvol__vs_legacy}, {NULL, fogvol__an_fs_legacy}, NULL, fogvol__decl_gl,
     fogvol__decl_gl, 0},
    {"120", "#version 120\n", NULL, 0, 1, 2, 2, 1, {fogvol__vs_legacy, NULL}, fogvol__fs_legacy,
     {fogvol__fs_two_legacy, NULL}, {NULL, fogvol__vs_legacy}, {NULL, fogvol__an_fs_legacy}, NULL, fogvol__decl_gl,
     fogvol__decl_gl, 0},
    {"130", "#version 130\n", NULL, 0, 0, 2, 3, 0, {fogvol__vs_modern, NULL}, fogvol__fs_modern,
     {fogvol__fs_two_modern, NULL}, {NULL, fogvol__vs_modern}, {NULL, fogvol__an_fs_modern}, NULL, fogvol__decl_gl,
     fogvol__decl_gl, 0},
    {"150", "#version 150\n", "#version 150\n" FOGVOL__SAMPLE_SHADING, 0, 0, 2, 3, 2, {fogvol__vs_modern, NULL},
     fogvol__fs_modern, {fogvol__fs_two_modern, NULL}, {NULL, fogvol__vs_modern}, {NULL, fogvol__an_fs_modern},
     NULL, fogvol__decl_gl, fogvol__decl_gl, 0},
    {"330 core", "#version 330 core\n", "#version 330 core\n" FOGVOL__SAMPLE_SHADING, 0, 0, 2, 3, 3,
     {fogvol__vs_modern, NULL}, fogvol__fs_modern, {fogvol__fs_two_layout, NULL}, {NULL, fogvol__vs_modern},
     {NULL, fogvol__an_fs_modern}, fogvol__fs_fetch_330, fogvol__decl_gl, fogvol__decl_gl, 0},
    {"100", "#version 100\n", NULL, 1, 1, 1, 2, 0, {fogvol__vs_legacy, fogvol__highp_float}, fogvol__fs_es100,
     {NULL, NULL}, {fogvol__highp_float, fogvol__vs_legacy}, {fogvol__an_fs_es100, fogvol__an_fs_legacy}, NULL,
     fogvol__decl_gl, fogvol__decl_gl, 0},
    {"300 es", "#version 300 es\n", NULL, 1, 0, 2, 3, 0, {fogvol__vs_modern, fogvol__highp_float}, fogvol__fs_es300,
     {fogvol__fs_two_es300, fogvol__fs_two_layout}, {fogvol__highp_float, fogvol__vs_modern},
     {fogvol__highp_float, fogvol__an_fs_modern}, fogvol__fs_fetch_es300, fogvol__decl_gl, fogvol__decl_gl, 0},
    {"vulkan", "#version 450\n", NULL, 0, 0, 2, 4, 5, {fogvol__vs_modern, NULL}, fogvol__fs_vulkan,
     {fogvol__fs_two_layout, NULL}, {NULL, fogvol__vs_modern}, {NULL, fogvol__fs_vulkan_analytic}, NULL,
     fogvol__decl_vulkan, fogvol__an_decl_vulkan, 1}};
#undef FOGVOL__SAMPLE_SHADING
/* one row per value of fogvol_dialect */
typedef char
    fogvol__dialect_rows_match[sizeof fogvol__dialects / sizeof fogvol__dialects[0] == FOGVOL_GLSL_COUNT ? 1 : -1];

/* The row of a dialect; NULL for FOGVOL_GLSL_AUTO and values out of range. */
static const fogvol__dialect_info *fogvol__dialect(fogvol_dialect dialect)
{
    if ((int)dialect <= (int)FOGVOL_GLSL_AUTO || (int)dialect >= (int)FOGVOL_GLSL_COUNT) return NULL;
    return &fogvol__dialects[dialect];
}

/* Appends the (up to two) strings of a prelude. */
static int fogvol__prelude(const char **strings, int n, const char *const prelude[2])
{
    if (prelude[0]) strings[n++] = prelude[0];
    if (prelude[1]) strings[n++] = prelude[1];
    return n;
}

FOGVOL_API fogvol_result fogvol_dialect_layout(fogvol_dialect dialect, fogvol_uniform_layout *out)
{
    static const int draw[FOGVOL_DRAW_VALUE_COUNT] = {0, 64, 80, 96, 112}; /* fogvol__decl_vulkan's push constants */
    const fogvol__dialect_info *di = fogvol__dialect(dialect);
    int i;
    if (!out) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(out, 0xff, sizeof *out); /* every field -1 */
    if (!di || !di->vulkan) return FOGVOL_ERROR_UNSUPPORTED;
    out->pass_binding = FOGVOL_MAX_TEXTURE_UNITS;
    out->pass_size = (int)(FOGVOL_U_COUNT * 4 * sizeof(float));
    for (i = 0; i < FOGVOL_U_COUNT; ++i) out->pass_offsets[i] = 16 * i;
    out->draw_size = 116;
    for (i = 0; i < FOGVOL_DRAW_VALUE_COUNT; ++i) out->draw_offsets[i] = draw[i];
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) out->sampler_bindings[i] = i;
    return FOGVOL_SUCCESS;
}
/* fogvol__decl_vulkan names binding 8 for the pass block and fogvol_pass.uniforms is that block */
typedef char fogvol__vk_pass_binding[FOGVOL_MAX_TEXTURE_UNITS == 8 ? 1 : -1];

#ifndef FOGVOL_NO_GL
/* The newest dialect of a GL (gles = 0) or GLES context of this version. */
static fogvol_dialect fogvol__dialect_for_gl(int gles, int major, int minor)
{
    int d, best = FOGVOL_GLSL_AUTO;
    for (d = 1; d < FOGVOL_GLSL_COUNT; ++d) { /* the rows of each family go from old to new */
        const fogvol__dialect_info *di = &fogvol__dialects[d];
        if ((di->es != 0) != (gles != 0) || di->vulkan) continue;
        if (best == FOGVOL_GLSL_AUTO || major > di->gl_major || (major == di->gl_major && minor >= di->gl_minor))
            best = d;
    }
    return (fogvol_dialect)best;
}
#endif

#ifndef FOGVOL_NO_ANALYTIC
/* >>analytic ============================================================== */
/* Analytic fog volumes (JCAB, "Implementing Volumetric Fog Without Using
   Texture Stages", GDC 2001): prepare, entry/exit per shape, the two ways of
   combining volumes, the batch over vertex arrays, and the same maths
   as GLSL. The reference path (eval, segment, the DOUBLE kernel of the batch)
   computes in double: the chord of a grazing ray depends on the square root
   of a small discriminant, which float would get wrong by up to
   sqrt(2^-24) = 2.4e-4 of the chord. The batch's float kernels (below) redo
   those rays in double. The section depends on nothing after it: the
   renderer does not use it. */

#define FOGVOL__AN_BLOCK 32      /* vertices per structure-of-arrays block */
#define FOGVOL__AN_CUTOFF 1e-7   /* EXP: a ray whose transmittance fell below this is done */
/* the per-ray kernels must be inlined into the block loops for those to vectorise */
#if defined(__GNUC__) || defined(__clang__)
#define FOGVOL__AN_INLINE static __inline__ __attribute__((always_inline))
#elif defined(_MSC_VER)
#define FOGVOL__AN_INLINE static __forceinline
#else
#define FOGVOL__AN_INLINE static
#endif

FOGVOL__AN_INLINE double fogvol__an_min(double a, double b) { return a < b ? a : b; }
FOGVOL__AN_INLINE double fogvol__an_max(double a, double b) { return a > b ? a : b; }

/* Validates one volume; writes its shape and the rows of its world ->
   unit-shape map (DISTANCE: min, max or 0; HALF_SPACE: the plane with a unit
   normal). */
static fogvol_result fogvol__an_prepare_one(const fogvol_analytic_volume *v, int *shape, double map[12])
{
    int i;
    for (i = 0; i < 12; ++i) map[i] = 0.0;
    if ((int)v->shape < 0 || (int)v->shape >= (int)FOGVOL_SHAPE_COUNT) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!fogvol__finite(v->density) || v->density < 0.0f || !fogvol__finite_n(v->color, 3))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    *shape = (int)v->shape;
    switch (v->shape) {
    case FOGVOL_SHAPE_DISTANCE:
        if (!fogvol__finite(v->min_distance) || !fogvol__finite(v->max_distance) || v->min_distance < 0.0f ||
            (v->max_distance > 0.0f && v->max_distance <= v->min_distance))
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        map[0] = v->min_distance;
        map[1] = v->max_distance > 0.0f && v->max_distance < 1e30f ? v->max_distance : 0.0; /* huge: no bound */
        break;
    case FOGVOL_SHAPE_HALF_SPACE: {
        double nn;
        if (!fogvol__finite_n(v->plane, 4)) return FOGVOL_ERROR_INVALID_ARGUMENT;
        nn = FOGVOL_SQRT((double)v->plane[0] * v->plane[0] + (double)v->plane[1] * v->plane[1] +
                         (double)v->plane[2] * v->plane[2]);
        if (!(nn > 0.0)) return FOGVOL_ERROR_INVALID_ARGUMENT;
        for (i = 0; i < 4; ++i) map[i] = v->plane[i] / nn;
        break;
    }
    case FOGVOL_SHAPE_SPHERE: {
        double r;
        if (!fogvol__finite_n(v->center, 3) || !fogvol__finite(v->radius) || !(v->radius > 0.0f))
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        r = v->radius;
        map[0] = map[5] = map[10] = 1.0 / r;
        map[3] = -v->center[0] / r;
        map[7] = -v->center[1] / r;
        map[11] = -v->center[2] / r;
        break;
    }
    default: { /* ELLIPSOID, BOX, CYLINDER: invert the affine transform */
        const float *m = v->transform;
        double a00, a01, a02, a10, a11, a12, a20, a21, a22, c00, c01, c02, det, h, id;
        int zero = 1;
        if (!fogvol__finite_n(m, 16)) return FOGVOL_ERROR_INVALID_ARGUMENT;
        for (i = 0; i < 16; ++i)
            if (m[i] != 0.0f) zero = 0;
        if (zero) { /* a zeroed transform means identity */
            map[0] = map[5] = map[10] = 1.0;
            return FOGVOL_SUCCESS;
        }
        if (m[3] != 0.0f || m[7] != 0.0f || m[11] != 0.0f || m[15] != 1.0f) return FOGVOL_ERROR_INVALID_ARGUMENT;
        a00 = m[0], a01 = m[4], a02 = m[8];
        a10 = m[1], a11 = m[5], a12 = m[9];
        a20 = m[2], a21 = m[6], a22 = m[10];
        c00 = a11 * a22 - a12 * a21;
        c01 = a12 * a20 - a10 * a22;
        c02 = a10 * a21 - a11 * a20;
        det = a00 * c00 + a01 * c01 + a02 * c02;
        h = FOGVOL_SQRT(a00 * a00 + a10 * a10 + a20 * a20) * FOGVOL_SQRT(a01 * a01 + a11 * a11 + a21 * a21) *
            FOGVOL_SQRT(a02 * a02 + a12 * a12 + a22 * a22);
        if (!(h > 0.0) || !(FOGVOL_FABS(det) >= 1e-6 * h)) return FOGVOL_ERROR_INVALID_ARGUMENT; /* singular */
        id = 1.0 / det;
        map[0] = c00 * id, map[1] = (a02 * a21 - a01 * a22) * id, map[2] = (a01 * a12 - a02 * a11) * id;
        map[4] = c01 * id, map[5] = (a00 * a22 - a02 * a20) * id, map[6] = (a02 * a10 - a00 * a12) * id;
        map[8] = c02 * id, map[9] = (a01 * a20 - a00 * a21) * id, map[10] = (a00 * a11 - a01 * a10) * id;
        for (i = 0; i < 3; ++i)
            map[i * 4 + 3] = -(map[i * 4] * m[12] + map[i * 4 + 1] * m[13] + map[i * 4 + 2] * m[14]);
        break;
    }
    }
    /* the shaders read the map as float: keep it well inside the float range */
    for (i = 0; i < 12; ++i)
        if (!fogvol__finite(map[i]) || FOGVOL_FABS(map[i]) > 1e30) return FOGVOL_ERROR_INVALID_ARGUMENT;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_analytic_prepare(const fogvol_analytic_volume *volumes, int count,
                                                 fogvol_analytic_set *set)
{
    fogvol_result res = FOGVOL_SUCCESS;
    int i, n = 0, shape = 0, have = 0;
    if (!set || count < 0 || (count > 0 && !volumes)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(set, 0, sizeof *set);
    for (i = 0; i < count; ++i) {
        if (n == FOGVOL_ANALYTIC_CAPACITY) {
            set->truncated = count - i;
            if (res == FOGVOL_SUCCESS) res = FOGVOL_ERROR_BUFFER_TOO_SMALL;
            break;
        }
        if (fogvol__an_prepare_one(&volumes[i], &shape, set->map[n]) != FOGVOL_SUCCESS) {
            memset(set->map[n], 0, sizeof set->map[n]);
            ++set->ignored;
            res = FOGVOL_ERROR_INVALID_ARGUMENT;
            continue;
        }
        set->source[n] = i;
        set->shape[n] = shape;
        set->density[n] = volumes[i].density;
        set->color[n][0] = volumes[i].color[0];
        set->color[n][1] = volumes[i].color[1];
        set->color[n][2] = volumes[i].color[2];
        ++n;
    }
    set->count = n;
    set->uniform_color = 1;
    for (i = 0; i < n; ++i) {
        if (!(set->density[i] > 0.0)) continue;
        if (have && (set->color[i][0] != set->color[have - 1][0] || set->color[i][1] != set->color[have - 1][1] ||
                     set->color[i][2] != set->color[have - 1][2]))
            set->uniform_color = 0;
        if (!have) have = i + 1;
    }
    return res;
}

/* ---- entry/exit per shape ----
   Each kernel gives [lo, hi] inside [0, 1] for the ray eye + t d (hi <= lo: a
   miss). o is the eye in the volume's unit space (per call), d the ray in
   world space. Everything is computed first and then selected (no arithmetic
   or comparison inside a branch, guarded divisions), so that the loops over a
   block of vertices if-convert and vectorise under -ftrapping-math. */

FOGVOL__AN_INLINE void fogvol__an_distance(const double *m, double len, double *lo, double *hi)
{
    double ls = len + (double)(len == 0.0);
    double f = fogvol__an_min(m[1] / ls, 1.0);
    double h = m[1] > 0.0 ? f : 1.0;
    *lo = m[0] / ls;
    *hi = len > 0.0 ? h : -1.0;
}

/* the paper's half-space: fog where s0 + t s1 >= 0 */
FOGVOL__AN_INLINE void fogvol__an_half(const double *m, double s0, double dx, double dy, double dz, double *lo,
                                       double *hi)
{
    double s1 = m[0] * dx + m[1] * dy + m[2] * dz;
    double ss = s1 + (double)(s1 == 0.0), tx = -s0 / ss;
    double txl = fogvol__an_max(tx, 0.0), txh = fogvol__an_min(tx, 1.0);
    double par = s0 >= 0.0 ? 1.0 : -1.0; /* parallel to the plane: all or nothing */
    double h = s1 > 0.0 ? 1.0 : par;
    *lo = s1 > 0.0 ? txl : 0.0;
    *hi = s1 < 0.0 ? txh : h;
}

/* |o + t v| <= 1 along one axis, intersected into [lo, hi] */
FOGVOL__AN_INLINE void fogvol__an_slab(double o, double v, double *lo, double *hi)
{
    double vs = v + (double)(v == 0.0);
    double ta = (-1.0 - o) / vs, tb = (1.0 - o) / vs;
    double mn = fogvol__an_min(ta, tb), mx = fogvol__an_max(ta, tb);
    double par = ((o >= -1.0) & (o <= 1.0)) ? 1.0 : -1.0; /* parallel to the slab */
    double l = v == 0.0 ? 0.0 : mn, h = v == 0.0 ? par : mx;
    *lo = fogvol__an_max(*lo, l);
    *hi = fogvol__an_min(*hi, h);
}

FOGVOL__AN_INLINE void fogvol__an_box(const double *m, const double *o, double dx, double dy, double dz, double *lo,
                                      double *hi)
{
    double l = 0.0, h = 1.0;
    fogvol__an_slab(o[0], m[0] * dx + m[1] * dy + m[2] * dz, &l, &h);
    fogvol__an_slab(o[1], m[4] * dx + m[5] * dy + m[6] * dz, &l, &h);
    fogvol__an_slab(o[2], m[8] * dx + m[9] * dy + m[10] * dz, &l, &h);
    *lo = l;
    *hi = h;
}

/* Unit sphere (kind 0; kind 2: a sphere, whose map is a scale by m[0] = 1/r
   and a translation) or the side of the unit cylinder (kind 1, z left out),
   before the square root: a = v.v, b = o.v, disc = b^2 - a (o.o - 1) written
   as a - |o x v|^2 (Lagrange's identity; no cancellation of two large terms
   when the eye is far away). */
FOGVOL__AN_INLINE void fogvol__an_quad1(const double *m, const double *o, int kind, double dx, double dy, double dz,
                                        double *a, double *b, double *disc, double *vz)
{
    int cyl = kind == 1;
    double v0 = kind == 2 ? m[0] * dx : m[0] * dx + m[1] * dy + m[2] * dz;
    double v1 = kind == 2 ? m[0] * dy : m[4] * dx + m[5] * dy + m[6] * dz;
    double v2 = kind == 2 ? m[0] * dz : m[8] * dx + m[9] * dy + m[10] * dz;
    double w2 = cyl ? 0.0 : v2, o2 = cyl ? 0.0 : o[2];
    double cx = o[1] * w2 - o2 * v1, cy = o2 * v0 - o[0] * w2, cz = o[0] * v1 - o[1] * v0;
    *a = v0 * v0 + v1 * v1 + w2 * w2;
    *b = o[0] * v0 + o[1] * v1 + o2 * w2;
    *disc = *a - (cx * cx + cy * cy + cz * cz);
    *vz = v2;
}

/* The roots from s = sqrt(max(disc, 0)), in the stable form q = -(b + sign(b) s),
   t = q / a and c0 / q (c0 = o.o - 1); a == 0: a ray along the cylinder's axis
   (or of zero length), inside for all t when c0 <= 0. */
FOGVOL__AN_INLINE void fogvol__an_quad2(double a, double b, double disc, double s, double c0, double *lo, double *hi)
{
    double ns = -s, sg = b >= 0.0 ? s : ns;
    double q = -(b + sg);
    double qs = q + (double)(q == 0.0), as = a + (double)(a == 0.0);
    double r1 = q / as, r2 = c0 / qs;
    double l = fogvol__an_max(fogvol__an_min(r1, r2), 0.0), h = fogvol__an_min(fogvol__an_max(r1, r2), 1.0);
    double par = c0 <= 0.0 ? 1.0 : -1.0; /* along the cylinder's axis: all or nothing */
    double hd = disc > 0.0 ? h : -1.0;
    *lo = a > 0.0 ? l : 0.0;
    *hi = a > 0.0 ? hd : par;
}

/* The eye in every volume's unit space (once per call). */
typedef struct fogvol__an_eye {
    double o[FOGVOL_ANALYTIC_CAPACITY][3]; /* HALF_SPACE: o[0] = plane value at the eye */
    double c0[FOGVOL_ANALYTIC_CAPACITY];   /* o.o - 1 (cylinder: x and y only) */
} fogvol__an_eye;

static void fogvol__an_eye_init(const fogvol_analytic_set *s, const double e[3], fogvol__an_eye *pe)
{
    int v, r;
    for (v = 0; v < s->count; ++v) {
        const double *m = s->map[v];
        for (r = 0; r < 3; ++r)
            pe->o[v][r] = m[r * 4] * e[0] + m[r * 4 + 1] * e[1] + m[r * 4 + 2] * e[2] + m[r * 4 + 3];
        pe->c0[v] = pe->o[v][0] * pe->o[v][0] + pe->o[v][1] * pe->o[v][1] - 1.0;
        if (s->shape[v] != FOGVOL_SHAPE_CYLINDER) pe->c0[v] += pe->o[v][2] * pe->o[v][2];
    }
}

/* One volume, one ray (the scalar path of eval and segment; the batch runs the
   same kernels in loops). */
static void fogvol__an_ray(const fogvol_analytic_set *s, const fogvol__an_eye *pe, int v, double dx, double dy,
                           double dz, double len, double *lo, double *hi)
{
    const double *m = s->map[v], *o = pe->o[v];
    double a, b, disc, vz;
    switch (s->shape[v]) {
    case FOGVOL_SHAPE_DISTANCE: fogvol__an_distance(m, len, lo, hi); break;
    case FOGVOL_SHAPE_HALF_SPACE: fogvol__an_half(m, o[0], dx, dy, dz, lo, hi); break;
    case FOGVOL_SHAPE_BOX: fogvol__an_box(m, o, dx, dy, dz, lo, hi); break;
    default:
        if (s->shape[v] == FOGVOL_SHAPE_SPHERE) fogvol__an_quad1(m, o, 2, dx, dy, dz, &a, &b, &disc, &vz);
        else fogvol__an_quad1(m, o, s->shape[v] == FOGVOL_SHAPE_CYLINDER, dx, dy, dz, &a, &b, &disc, &vz);
        fogvol__an_quad2(a, b, disc, FOGVOL_SQRT(disc > 0.0 ? disc : 0.0), pe->c0[v], lo, hi);
        if (s->shape[v] == FOGVOL_SHAPE_CYLINDER) fogvol__an_slab(o[2], vz, lo, hi);
        break;
    }
    if (!(*hi > *lo)) *lo = *hi = 0.0;
}

FOGVOL_API fogvol_result fogvol_analytic_segment(const fogvol_analytic_volume *volume, const float eye[3],
                                                 const float p[3], float *t1, float *t2)
{
    fogvol_analytic_set *s;
    fogvol__an_eye *pe;
    struct {
        fogvol_analytic_set set; /* only slot 0 is used */
        fogvol__an_eye eye;
    } one;
    double e[3], dx, dy, dz, lo, hi;
    if (t1) *t1 = 0.0f;
    if (t2) *t2 = 0.0f;
    if (!volume || !eye || !p || !t1 || !t2 || !fogvol__finite_n(eye, 3) || !fogvol__finite_n(p, 3))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    s = &one.set;
    pe = &one.eye;
    s->count = 1;
    if (fogvol__an_prepare_one(volume, &s->shape[0], s->map[0]) != FOGVOL_SUCCESS)
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    e[0] = eye[0], e[1] = eye[1], e[2] = eye[2];
    fogvol__an_eye_init(s, e, pe);
    dx = (double)p[0] - e[0], dy = (double)p[1] - e[1], dz = (double)p[2] - e[2];
    fogvol__an_ray(s, pe, 0, dx, dy, dz, FOGVOL_SQRT(dx * dx + dy * dy + dz * dz), &lo, &hi);
    *t1 = (float)lo;
    *t2 = (float)hi;
    if (!(*t2 > *t1)) *t1 = *t2 = 0.0f; /* a hit thinner than float */
    return FOGVOL_SUCCESS;
}

/* ---- combining volumes ---- */

/* Running state along one ray, front to back: f = fog factor (LINEAR, the paper's
   "fog") or transmittance (EXP); w = how much of the pixel the fog covers so
   far; num = colour * cover (LINEAR_SEED: the fog colour itself). */
typedef struct fogvol__an_state {
    double f, w, num[3];
    int done;
} fogvol__an_state;

/* One stretch of fog of length l (world units) with density sig and
   premultiplied colour cs = colour * sig (for a mix: the sums over the volumes
   it is in, so cs / sig is the density-weighted mean colour).
   LINEAR: the paper's law, fog -= sig * l until 0. The stretch covers sig * l of
     the pixel (less when it ends the fog), so it adds its colour times that:
     num += cs * l.
   EXP: the physically consistent compositing of transmittances. Behind
     transmittance T the stretch covers T (1 - exp(-sig l)) and T shrinks by
     exp(-sig l); the colour weight is written cs * l * T * phi with
     phi = (1 - exp(-x)) / x (x = sig l) so that no division by a density that
     may be tiny is needed. Then 1 - f = sum of the covers exactly, and the
     result does not depend on how a volume is cut into stretches (the paper's
     colour formula applied to EXP would). Done once T < FOGVOL__AN_CUTOFF.
   LINEAR_SEED: the paper verbatim, C = colour * fog + C * (1 - fog) (the fog
     before the stretch), fog = fog + volFog - 1. Stretches of zero length are
     skipped (the paper would blend their colour in, depending on sort ties). */
FOGVOL__AN_INLINE void fogvol__an_add(fogvol__an_state *st, int law, const double cs[3], double sig, double l)
{
    double tau = sig * l, k;
    int c;
    if (!(tau > 0.0) || st->done) return;
    if (law == FOGVOL_FOG_EXP) {
        double e = FOGVOL_EXP(-tau);
        double phi = tau < 1e-5 ? 1.0 - 0.5 * tau : (1.0 - e) / tau;
        k = l * phi * st->f;
        for (c = 0; c < 3; ++c) st->num[c] += cs[c] * k;
        st->w += sig * k;
        st->f *= e;
        if (st->f < FOGVOL__AN_CUTOFF) st->done = 1;
    } else if (law == FOGVOL_FOG_LINEAR) {
        k = tau >= st->f ? st->f / tau : 1.0; /* the stretch that ends the fog counts in part */
        for (c = 0; c < 3; ++c) st->num[c] += cs[c] * (l * k);
        st->w += tau * k;
        if (tau >= st->f) {
            st->f = 0.0;
            st->done = 1;
        } else {
            st->f -= tau;
        }
    } else {
        for (c = 0; c < 3; ++c) st->num[c] = cs[c] / sig * st->f + st->num[c] * (1.0 - st->f);
        st->f -= tau < 1.0 ? tau : 1.0;
        if (st->f <= 0.0) {
            st->f = 0.0;
            st->done = 1;
        }
    }
}

/* event e of a vertex: 2v = entry into volume v, 2v + 1 = exit; sorted by
   (t, e): a strict total order, so the result never depends on the order the
   insertion sort starts from */
static int fogvol__an_perm_ok(const unsigned char *p, int m)
{
    unsigned char seen[2 * FOGVOL_ANALYTIC_CAPACITY];
    int i;
    memset(seen, 0, (size_t)m);
    for (i = 0; i < m; ++i) {
        if (p[i] >= m || seen[p[i]]) return 0;
        seen[p[i]] = 1;
    }
    return 1;
}

static void fogvol__an_identity(unsigned char *p, int m)
{
    int i;
    for (i = 0; i < m; ++i) p[i] = (unsigned char)i;
}

/* Walks the events perm[0..m) (sorted by key, indexed by event; misses keyed
   2 and last) front to back into st: SEPARATE takes each volume whole at its
   entry, INTERPENETRATING the paper's event list. */
static void fogvol__an_walk(const fogvol_analytic_set *s, int law, int mix, double len, const float *key,
                            const unsigned char *perm, int m, fogvol__an_state *st)
{
    int k, v, c;
    if (mix == FOGVOL_MIX_SEPARATE) {
        /* the entries in order of t1; each volume whole */
        for (k = 0; k < m && !st->done; ++k) {
            int e = perm[k];
            double cs[3];
            if (key[e] > 1.5f) break;
            if (e & 1) continue;
            v = e >> 1;
            for (c = 0; c < 3; ++c) cs[c] = s->color[v][c] * s->density[v];
            fogvol__an_add(st, law, cs, s->density[v], len * ((double)key[e + 1] - (double)key[e]));
        }
    } else {
        /* the event list: sums of (colour * density, density) of the volumes a
           stretch is in; the sums restart from exact zeros whenever no volume
           is open, so that rounding never leaves a ghost density behind. A
           stretch is (t - lastT) * |D| long (the paper's listing divides by
           |D| there, a slip: its one-volume algorithm multiplies) */
        double acc[4] = {0.0, 0.0, 0.0, 0.0}, last = 0.0;
        int open = 0;
        for (k = 0; k < m && !st->done; ++k) {
            int e = perm[k];
            double t = key[e], sgn = (e & 1) ? -1.0 : 1.0;
            if (t > 1.5) break;
            v = e >> 1;
            if (open > 0 && t > last) fogvol__an_add(st, law, acc, acc[3], (t - last) * len);
            for (c = 0; c < 3; ++c) acc[c] += sgn * s->color[v][c] * s->density[v];
            acc[3] += sgn * s->density[v];
            open += (e & 1) ? -1 : 1;
            if (open == 0) acc[0] = acc[1] = acc[2] = acc[3] = 0.0;
            last = t;
        }
    }
}

/* The paper's sorted evaluation of one vertex from its entry/exit pairs (those
   of volume v at t1[v * ts], t2[v * ts]). Misses sort last and end the walk. */
static void fogvol__an_sorted(const fogvol_analytic_set *s, int law, int mix, double len, const float *t1,
                              const float *t2, int ts, unsigned char *perm, int64_t *moves, fogvol__an_state *st)
{
    float key[2 * FOGVOL_ANALYTIC_CAPACITY];
    int n = s->count, m = 2 * s->count, k, j, v;
    int64_t mv = 0;
    for (v = 0; v < n; ++v) {
        float a = t1[v * ts], b = t2[v * ts];
        int hit = b > a && s->density[v] > 0.0;
        key[2 * v] = hit ? a : 2.0f;
        key[2 * v + 1] = hit ? b : 2.0f;
    }
    /* insertion sort from the carried order: O(m) when it is still right */
    for (k = 1; k < m; ++k) {
        unsigned char x = perm[k];
        float kx = key[x];
        for (j = k; j > 0 && (key[perm[j - 1]] > kx || (key[perm[j - 1]] == kx && perm[j - 1] > x)); --j) {
            perm[j] = perm[j - 1];
            ++mv;
        }
        perm[j] = x;
    }
    if (moves) *moves += mv;
    fogvol__an_walk(s, law, mix, len, key, perm, m, st);
}

static void fogvol__an_sorted_vertex(const fogvol_analytic_set *s, int law, int mix, double len, const float *t1,
                                     const float *t2, int ts, unsigned char *perm, int64_t *moves, float *fog,
                                     float col[3])
{
    fogvol__an_state st;
    double inv;
    int c;
    memset(&st, 0, sizeof st);
    st.f = 1.0;
    fogvol__an_sorted(s, law, mix, len, t1, t2, ts, perm, moves, &st);
    inv = st.w > 0.0 ? 1.0 / st.w : 0.0;
    *fog = (float)st.f;
    for (c = 0; c < 3; ++c) col[c] = (float)(law == FOGVOL_FOG_LINEAR_SEED ? st.num[c] : st.num[c] * inv);
}

/* Whenever the order of the volumes cannot matter, the sums over the volumes
   of a vertex are the answer (tau = sum of density * distance, rgb = the same
   weighted by colour): at most one volume on the ray; LINEAR while the ray is
   not fully fogged (the law is additive, in both mixes); EXP with one fog
   colour (transmittances multiply in any order). A vertex with more than one
   volume on its ray needs the sorted path when tau > this limit. */
static double fogvol__an_sort_limit(const fogvol_analytic_set *s, int law)
{
    if (law == FOGVOL_FOG_LINEAR) return 1.0;
    return law == FOGVOL_FOG_EXP && s->uniform_color ? 1e308 : -1.0;
}

static int fogvol__an_args_ok(const fogvol_analytic_set *set, fogvol_fog_law law, fogvol_fog_mix mix)
{
    return set && set->count >= 0 && set->count <= FOGVOL_ANALYTIC_CAPACITY && (int)law >= 0 &&
           (int)law <= (int)FOGVOL_FOG_LINEAR_SEED &&
           (mix == FOGVOL_MIX_SEPARATE || mix == FOGVOL_MIX_INTERPENETRATING);
}

/* One vertex in double from the eye in the volumes' spaces (eval, and the
   float kernels' vertices too far away for float). */
static void fogvol__an_vertex(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3],
                              const float p[3], int law, int mix, float *fog, float col[3])
{
    float t1[FOGVOL_ANALYTIC_CAPACITY], t2[FOGVOL_ANALYTIC_CAPACITY];
    unsigned char perm[2 * FOGVOL_ANALYTIC_CAPACITY];
    double dx, dy, dz, len, tau = 0.0, rgb[3] = {0.0, 0.0, 0.0}, hits = 0.0;
    int v, c;
    dx = (double)p[0] - e[0], dy = (double)p[1] - e[1], dz = (double)p[2] - e[2];
    len = FOGVOL_SQRT(dx * dx + dy * dy + dz * dz);
    for (v = 0; v < set->count; ++v) {
        double lo, hi, tv;
        fogvol__an_ray(set, pe, v, dx, dy, dz, len, &lo, &hi);
        t1[v] = (float)lo;
        t2[v] = (float)hi;
        tv = set->density[v] * (len * (hi - lo));
        tau += tv;
        for (c = 0; c < 3; ++c) rgb[c] += set->color[v][c] * tv;
        hits += (double)(tv > 0.0);
    }
    if (hits > 1.0 && tau > fogvol__an_sort_limit(set, law)) {
        fogvol__an_identity(perm, 2 * set->count);
        fogvol__an_sorted_vertex(set, law, mix, len, t1, t2, 1, perm, NULL, fog, col);
    } else { /* the same expressions as the batch's order-free loop */
        double inv = 1.0 / (tau + (double)(tau == 0.0));
        *fog = (float)(law == FOGVOL_FOG_EXP ? (tau > 0.0 ? FOGVOL_EXP(-tau) : 1.0) : fogvol__an_max(1.0 - tau, 0.0));
        for (c = 0; c < 3; ++c) col[c] = (float)(rgb[c] * inv);
    }
}

FOGVOL_API fogvol_result fogvol_analytic_eval(const fogvol_analytic_set *set, const float eye[3], const float p[3],
                                              fogvol_fog_law law, fogvol_fog_mix mix, float *fog, float color[3])
{
    fogvol__an_eye pe;
    float f = 1.0f, col[3] = {0.0f, 0.0f, 0.0f};
    double e[3];
    fogvol_result res = FOGVOL_SUCCESS;
    if (!fogvol__an_args_ok(set, law, mix) || !fog) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!eye || !p || !fogvol__finite_n(eye, 3) || !fogvol__finite_n(p, 3)) {
        res = FOGVOL_ERROR_INVALID_ARGUMENT;
    } else {
        e[0] = eye[0], e[1] = eye[1], e[2] = eye[2];
        fogvol__an_eye_init(set, e, &pe);
        fogvol__an_vertex(set, &pe, e, p, (int)law, (int)mix, &f, col);
    }
    *fog = f;
    if (color) color[0] = col[0], color[1] = col[1], color[2] = col[2];
    return res;
}

/* A block of vertices in structure-of-arrays form; the loops over i below
   have a constant trip count and no calls but the square roots. */
typedef struct fogvol__an_block {
    double dx[FOGVOL__AN_BLOCK], dy[FOGVOL__AN_BLOCK], dz[FOGVOL__AN_BLOCK], len[FOGVOL__AN_BLOCK];
    double a[FOGVOL__AN_BLOCK], b[FOGVOL__AN_BLOCK], disc[FOGVOL__AN_BLOCK], s[FOGVOL__AN_BLOCK];
    double vz[FOGVOL__AN_BLOCK], lo[FOGVOL__AN_BLOCK], hi[FOGVOL__AN_BLOCK];
    double tau[FOGVOL__AN_BLOCK], r[FOGVOL__AN_BLOCK], g[FOGVOL__AN_BLOCK], bl[FOGVOL__AN_BLOCK];
    double hits[FOGVOL__AN_BLOCK], fog[FOGVOL__AN_BLOCK], need[FOGVOL__AN_BLOCK];
    float t1[FOGVOL_ANALYTIC_CAPACITY][FOGVOL__AN_BLOCK], t2[FOGVOL_ANALYTIC_CAPACITY][FOGVOL__AN_BLOCK];
} fogvol__an_block;

static void fogvol__an_block_eval(const fogvol_analytic_set *set, const fogvol__an_eye *pe, double limit,
                                  fogvol__an_block *k)
{
    int v, i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->len[i] = k->dx[i] * k->dx[i] + k->dy[i] * k->dy[i] + k->dz[i] * k->dz[i];
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->len[i] = FOGVOL_SQRT(k->len[i]);
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->tau[i] = k->r[i] = k->g[i] = k->bl[i] = k->hits[i] = 0.0;
    for (v = 0; v < set->count; ++v) {
        const double *m = set->map[v], *o = pe->o[v];
        const double c0 = pe->c0[v], dens = set->density[v];
        const double cr = set->color[v][0], cg = set->color[v][1], cb = set->color[v][2];
        switch (set->shape[v]) {
        case FOGVOL_SHAPE_DISTANCE:
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) fogvol__an_distance(m, k->len[i], &k->lo[i], &k->hi[i]);
            break;
        case FOGVOL_SHAPE_HALF_SPACE:
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_half(m, o[0], k->dx[i], k->dy[i], k->dz[i], &k->lo[i], &k->hi[i]);
            break;
        case FOGVOL_SHAPE_BOX:
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_box(m, o, k->dx[i], k->dy[i], k->dz[i], &k->lo[i], &k->hi[i]);
            break;
        case FOGVOL_SHAPE_CYLINDER:
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_quad1(m, o, 1, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->s[i] = FOGVOL_SQRT(k->disc[i] > 0.0 ? k->disc[i] : 0.0);
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
                fogvol__an_quad2(k->a[i], k->b[i], k->disc[i], k->s[i], c0, &k->lo[i], &k->hi[i]);
                fogvol__an_slab(o[2], k->vz[i], &k->lo[i], &k->hi[i]);
            }
            break;
        default: /* SPHERE, ELLIPSOID */
            if (set->shape[v] == FOGVOL_SHAPE_SPHERE)
                for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                    fogvol__an_quad1(m, o, 2, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
            else
                for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                    fogvol__an_quad1(m, o, 0, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->s[i] = FOGVOL_SQRT(k->disc[i] > 0.0 ? k->disc[i] : 0.0);
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_quad2(k->a[i], k->b[i], k->disc[i], k->s[i], c0, &k->lo[i], &k->hi[i]);
            break;
        }
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
            double l0 = k->lo[i], h0 = k->hi[i];
            /* a miss: d = 0 (and lo in [-1, 1]; min(l0, 2) would be clearer but stops the
               vectoriser: gcc folds the add below into the select's arms) */
            double d = fogvol__an_max(h0 - l0, 0.0), lo = fogvol__an_min(l0, h0);
            double tv = dens * (k->len[i] * d);
            k->tau[i] += tv;
            k->r[i] += cr * tv;
            k->g[i] += cg * tv;
            k->bl[i] += cb * tv;
            k->hits[i] += (double)(tv > 0.0);
            k->t1[v][i] = (float)lo;
            k->t2[v][i] = (float)(lo + d);
        }
    }
    /* the order-free answer (fogvol__an_sort_limit); EXP fog comes after */
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        double tau = k->tau[i], inv = 1.0 / (tau + (double)(tau == 0.0));
        k->fog[i] = fogvol__an_max(1.0 - tau, 0.0);
        k->r[i] *= inv;
        k->g[i] *= inv;
        k->bl[i] *= inv;
        k->need[i] = (k->hits[i] > 1.0 && tau > limit) ? 1.0 : 0.0;
    }
}

/* ---- the float kernels ----
   The same entry/exit maths in float over blocks of vertices (one volume at a
   time, structure of arrays), compiled once per SIMD level: the block body is
   inlined into one function per level, so the compiler vectorises it for that
   level's registers; the square roots go through a per-level helper (the C
   library's sqrt keeps errno and so stays scalar). Float loses the chord of a
   grazing ray (it depends on the square root of a small discriminant), so the
   lanes whose discriminant is below FOGVOL__AN_GRAZE of a are redone in
   double, and so is every ray of a quadric whose unit space puts the eye
   further than FOGVOL__AN_FAR_EYE from its centre (the cross product o x v
   loses digits there). */

#define FOGVOL__AN_GRAZE 0.015625f
#define FOGVOL__AN_FAR_EYE 64.0
#define FOGVOL__AN_MASKS ((FOGVOL_ANALYTIC_CAPACITY + 31) / 32)

#if (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 5)) && (defined(__x86_64__) || defined(__i386__))
#define FOGVOL__AN_X86 1
#include <immintrin.h>
#else
#define FOGVOL__AN_X86 0
#endif

FOGVOL__AN_INLINE float fogvol__an_fmin(float a, float b) { return a < b ? a : b; }
FOGVOL__AN_INLINE float fogvol__an_fmax(float a, float b) { return a > b ? a : b; }
/* index of the lowest set bit of x != 0 */
FOGVOL__AN_INLINE int fogvol__an_ctz(unsigned int x)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctz(x);
#else
    int n = 0;
    while (!(x & 1u)) x >>= 1, ++n;
    return n;
#endif
}

/* exp(-x) and 1 - exp(-x) for x >= 0 in float, without the C library and
   without branches (the order-free EXP fog of a block, the sorted walk's
   stretches): x clamped to [0, 87], x = n ln2 - r, |r| <= ln2 / 2,
   exp(r) = 1 + r + r^2 P(r) with the minimax P of Cephes' expf (about 1 ulp)
   in Estrin's order (short dependency chains), times 2^-n; 1 - exp(-x) as
   (1 - 2^-n) - (r + r^2 P) 2^-n, which keeps its digits where 1 - e would
   cancel (n = 0 below ln2 / 2). */
FOGVOL__AN_INLINE float fogvol__an_fexp2(float x, float *om)
{
    float xc = fogvol__an_fmin(fogvol__an_fmax(x, 0.0f), 87.0f), r, r2, p, scale;
    int n = (int)(xc * 1.44269504f + 0.5f);
    uint32_t bits = (uint32_t)(127 - n) << 23;
    r = (float)n * 0.693145751953125f - xc + (float)n * 1.42860677e-6f;
    r2 = r * r;
    p = (5.0000001201e-1f + 1.6666665459e-1f * r) + r2 * (4.1665795894e-2f + 8.3334519073e-3f * r) +
        (r2 * r2) * (1.3981999507e-3f + 1.9875691500e-4f * r);
    p = r + r2 * p; /* exp(r) - 1 */
    memcpy(&scale, &bits, sizeof scale);
    *om = (1.0f - scale) - p * scale; /* n = 0: -p exactly */
    return (1.0f + p) * scale;
}

/* one volume as the float kernels read it, the eye already in its unit space */
typedef struct fogvol__an_fvol {
    float m[12], o[3], c0, dens, col[3];
    int shape, dbl; /* dbl: every ray of this volume in double */
    /* a sphere around the volume (bounded: 0 for DISTANCE, HALF_SPACE and an
       eye inside it): the unit direction from the eye to its centre, the
       distance from the eye to its surface, sine and cosine of the half angle
       it subtends from the eye (fogvol__an_fcull) */
    float bu[3], bnear, bsin, bcos;
    int bounded;
} fogvol__an_fvol;

typedef struct fogvol__an_fblock {
    float px[FOGVOL__AN_BLOCK], py[FOGVOL__AN_BLOCK], pz[FOGVOL__AN_BLOCK]; /* the vertices (redos) */
    float dx[FOGVOL__AN_BLOCK], dy[FOGVOL__AN_BLOCK], dz[FOGVOL__AN_BLOCK], len[FOGVOL__AN_BLOCK];
    float a[FOGVOL__AN_BLOCK], b[FOGVOL__AN_BLOCK], disc[FOGVOL__AN_BLOCK], s[FOGVOL__AN_BLOCK];
    float vz[FOGVOL__AN_BLOCK], lo[FOGVOL__AN_BLOCK], hi[FOGVOL__AN_BLOCK], ch[FOGVOL__AN_BLOCK];
    float tau[FOGVOL__AN_BLOCK], r[FOGVOL__AN_BLOCK], g[FOGVOL__AN_BLOCK], bl[FOGVOL__AN_BLOCK];
    float hits[FOGVOL__AN_BLOCK], fog[FOGVOL__AN_BLOCK], need[FOGVOL__AN_BLOCK];
    int redo[FOGVOL__AN_BLOCK];
    unsigned int hit[FOGVOL__AN_MASKS][FOGVOL__AN_BLOCK]; /* bit v & 31 of word v >> 5: volume v is on the ray */
    float t1[FOGVOL_ANALYTIC_CAPACITY][FOGVOL__AN_BLOCK], t2[FOGVOL_ANALYTIC_CAPACITY][FOGVOL__AN_BLOCK];
} fogvol__an_fblock;

typedef void (*fogvol__an_sqrt_fn)(float *out, const float *in); /* FOGVOL__AN_BLOCK values, in >= 0 */

static void fogvol__an_sqrt_c(float *out, const float *in)
{
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) out[i] = (float)FOGVOL_SQRT((double)in[i]);
}

FOGVOL__AN_INLINE void fogvol__an_fdistance(const float *m, float len, float *lo, float *hi)
{
    float ls = len + (float)(len == 0.0f);
    float f = fogvol__an_fmin(m[1] / ls, 1.0f);
    float h = m[1] > 0.0f ? f : 1.0f;
    *lo = m[0] / ls;
    *hi = len > 0.0f ? h : -1.0f;
}

FOGVOL__AN_INLINE void fogvol__an_fhalf(const float *m, float s0, float dx, float dy, float dz, float *lo, float *hi)
{
    float s1 = m[0] * dx + m[1] * dy + m[2] * dz;
    float ss = s1 + (float)(s1 == 0.0f), tx = -s0 / ss;
    float txl = fogvol__an_fmax(tx, 0.0f), txh = fogvol__an_fmin(tx, 1.0f);
    float par = s0 >= 0.0f ? 1.0f : -1.0f;
    float h = s1 > 0.0f ? 1.0f : par;
    *lo = s1 > 0.0f ? txl : 0.0f;
    *hi = s1 < 0.0f ? txh : h;
}

FOGVOL__AN_INLINE void fogvol__an_fslab(float o, float v, float *lo, float *hi)
{
    float iv = 1.0f / (v + (float)(v == 0.0f)); /* one division for both planes */
    float ta = (-1.0f - o) * iv, tb = (1.0f - o) * iv;
    float mn = fogvol__an_fmin(ta, tb), mx = fogvol__an_fmax(ta, tb);
    float par = ((o >= -1.0f) & (o <= 1.0f)) ? 1.0f : -1.0f;
    float l = v == 0.0f ? 0.0f : mn, h = v == 0.0f ? par : mx;
    *lo = fogvol__an_fmax(*lo, l);
    *hi = fogvol__an_fmin(*hi, h);
}

FOGVOL__AN_INLINE void fogvol__an_fbox(const float *m, const float *o, float dx, float dy, float dz, float *lo,
                                       float *hi)
{
    float l = 0.0f, h = 1.0f;
    fogvol__an_fslab(o[0], m[0] * dx + m[1] * dy + m[2] * dz, &l, &h);
    fogvol__an_fslab(o[1], m[4] * dx + m[5] * dy + m[6] * dz, &l, &h);
    fogvol__an_fslab(o[2], m[8] * dx + m[9] * dy + m[10] * dz, &l, &h);
    *lo = l;
    *hi = h;
}

/* fogvol__an_quad1 in float (kind 0 ellipsoid, 1 cylinder side, 2 sphere) */
FOGVOL__AN_INLINE void fogvol__an_fquad1(const float *m, const float *o, int kind, float dx, float dy, float dz,
                                         float *a, float *b, float *disc, float *vz)
{
    int cyl = kind == 1;
    float v0 = kind == 2 ? m[0] * dx : m[0] * dx + m[1] * dy + m[2] * dz;
    float v1 = kind == 2 ? m[0] * dy : m[4] * dx + m[5] * dy + m[6] * dz;
    float v2 = kind == 2 ? m[0] * dz : m[8] * dx + m[9] * dy + m[10] * dz;
    float w2 = cyl ? 0.0f : v2, o2 = cyl ? 0.0f : o[2];
    float cx = o[1] * w2 - o2 * v1, cy = o2 * v0 - o[0] * w2, cz = o[0] * v1 - o[1] * v0;
    *a = v0 * v0 + v1 * v1 + w2 * w2;
    *b = o[0] * v0 + o[1] * v1 + o2 * w2;
    *disc = *a - (cx * cx + cy * cy + cz * cz);
    *vz = v2;
}

FOGVOL__AN_INLINE void fogvol__an_fquad2(float a, float b, float disc, float s, float c0, float *lo, float *hi)
{
    float ns = -s, sg = b >= 0.0f ? s : ns;
    float q = -(b + sg);
    float qs = q + (float)(q == 0.0f), as = a + (float)(a == 0.0f);
    float r1 = q / as, r2 = c0 / qs;
    float l = fogvol__an_fmax(fogvol__an_fmin(r1, r2), 0.0f), h = fogvol__an_fmin(fogvol__an_fmax(r1, r2), 1.0f);
    float par = c0 <= 0.0f ? 1.0f : -1.0f;
    float hd = disc > 0.0f ? h : -1.0f;
    *lo = a > 0.0f ? l : 0.0f;
    *hi = a > 0.0f ? hd : par;
}

/* The lanes of volume v marked in redo (all of them: all != 0) through the
   double kernels, from the vertices themselves. */
static void fogvol__an_redo(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3], int v,
                            int all, fogvol__an_fblock *k)
{
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        double dx, dy, dz, lo, hi;
        if (!all && !k->redo[i]) continue;
        dx = (double)k->px[i] - e[0], dy = (double)k->py[i] - e[1], dz = (double)k->pz[i] - e[2];
        fogvol__an_ray(set, pe, v, dx, dy, dz, FOGVOL_SQRT(dx * dx + dy * dy + dz * dz), &lo, &hi);
        k->lo[i] = (float)lo;
        k->hi[i] = (float)hi;
        k->ch[i] = (float)(hi > lo ? hi - lo : 0.0); /* the chord in double: t near 1 loses digits in float */
    }
}

#if FOGVOL__AN_X86
/* fogvol__an_redo for the lanes base + i of volume v whose bit i is set in mask (the AVX2 kernel). */
static void fogvol__an_redo_lanes(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3], int v,
                                  int mask, int base, fogvol__an_fblock *k)
{
    while (mask) {
        int i = base + fogvol__an_ctz((unsigned int)mask);
        double dx = (double)k->px[i] - e[0], dy = (double)k->py[i] - e[1], dz = (double)k->pz[i] - e[2], lo, hi;
        mask &= mask - 1;
        fogvol__an_ray(set, pe, v, dx, dy, dz, FOGVOL_SQRT(dx * dx + dy * dy + dz * dz), &lo, &hi);
        k->lo[i] = (float)lo;
        k->hi[i] = (float)hi;
        k->ch[i] = (float)(hi > lo ? hi - lo : 0.0);
    }
}
#endif

/* Entry/exit of one quadric (sphere, ellipsoid, cylinder) for the block;
   returns whether some lanes graze it (marked in redo, for fogvol__an_redo). */
FOGVOL__AN_INLINE int fogvol__an_fquadric(const fogvol__an_fvol *f, fogvol__an_sqrt_fn sq, fogvol__an_fblock *k)
{
    const float *m = f->m, *o = f->o, c0 = f->c0;
    int i, any = 0, kind = f->shape == FOGVOL_SHAPE_SPHERE ? 2 : f->shape == FOGVOL_SHAPE_CYLINDER ? 1 : 0;
    if (kind == 2)
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
            fogvol__an_fquad1(m, o, 2, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
    else if (kind == 1)
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
            fogvol__an_fquad1(m, o, 1, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
    else
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
            fogvol__an_fquad1(m, o, 0, k->dx[i], k->dy[i], k->dz[i], &k->a[i], &k->b[i], &k->disc[i], &k->vz[i]);
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        int g = (k->a[i] > 0.0f) & (k->disc[i] < FOGVOL__AN_GRAZE * k->a[i]) & (k->disc[i] > -FOGVOL__AN_GRAZE * k->a[i]);
        k->redo[i] = g;
        any |= g;
        k->s[i] = fogvol__an_fmax(k->disc[i], 0.0f);
    }
    sq(k->s, k->s);
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
        fogvol__an_fquad2(k->a[i], k->b[i], k->disc[i], k->s[i], c0, &k->lo[i], &k->hi[i]);
    if (kind == 1)
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i) fogvol__an_fslab(o[2], k->vz[i], &k->lo[i], &k->hi[i]);
    return any;
}

/* The order-free answer of a block (fogvol__an_sort_limit) and which vertices need the sorted walk. */
FOGVOL__AN_INLINE void fogvol__an_ffinish(float limit, int law, fogvol__an_fblock *k)
{
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        /* (a denormal sum would make 1 / tau infinite: no colour then, fog 1 anyway) */
        float tau = k->tau[i], inv = tau > 1e-30f ? 1.0f / (tau + (float)(tau <= 1e-30f)) : 0.0f, om;
        float ex = fogvol__an_fexp2(tau, &om);
        k->fog[i] = law == FOGVOL_FOG_EXP ? ex : fogvol__an_fmax(1.0f - tau, 0.0f);
        k->r[i] *= inv;
        k->g[i] *= inv;
        k->bl[i] *= inv;
        k->need[i] = (k->hits[i] > 1.0f && tau > limit) ? 1.0f : 0.0f;
    }
}

/* One block: entry/exit per volume, the order-free sums (fogvol__an_sort_limit)
   and which vertices need the sorted walk. Inlined into one function per level. */
FOGVOL__AN_INLINE void fogvol__an_fblock_body(const fogvol_analytic_set *set, const fogvol__an_eye *pe,
                                              const double e[3], const fogvol__an_fvol *fv, const unsigned char *skip,
                                              float limit, int law, fogvol__an_sqrt_fn sq, fogvol__an_fblock *k)
{
    int v, i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->len[i] = k->dx[i] * k->dx[i] + k->dy[i] * k->dy[i] + k->dz[i] * k->dz[i];
    sq(k->len, k->len);
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->tau[i] = k->r[i] = k->g[i] = k->bl[i] = k->hits[i] = 0.0f;
    for (v = 0; v < (set->count + 31) / 32; ++v)
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->hit[v][i] = 0u;
    for (v = 0; v < set->count; ++v) if (!skip[v]) { /* (skip: fogvol__an_fcull) */
        const int w = v >> 5, bit = v & 31;
        const fogvol__an_fvol fl = fv[v], *f = &fl; /* a local copy: the block's stores cannot alias it */
        const float *m = f->m, *o = f->o, dens = f->dens, cr = f->col[0], cg = f->col[1], cb = f->col[2];
        int redo = f->dbl ? -1 : 0;
        if (f->dbl)
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->lo[i] = k->hi[i] = 0.0f;
        else if (f->shape == FOGVOL_SHAPE_DISTANCE)
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i) fogvol__an_fdistance(m, k->len[i], &k->lo[i], &k->hi[i]);
        else if (f->shape == FOGVOL_SHAPE_HALF_SPACE)
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_fhalf(m, o[0], k->dx[i], k->dy[i], k->dz[i], &k->lo[i], &k->hi[i]);
        else if (f->shape == FOGVOL_SHAPE_BOX)
            for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
                fogvol__an_fbox(m, o, k->dx[i], k->dy[i], k->dz[i], &k->lo[i], &k->hi[i]);
        else
            redo = fogvol__an_fquadric(f, sq, k);
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->ch[i] = fogvol__an_fmax(k->hi[i] - k->lo[i], 0.0f);
        if (redo) fogvol__an_redo(set, pe, e, v, redo < 0, k);
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
            float l0 = k->lo[i], h0 = k->hi[i];
            float d = k->ch[i], lo = fogvol__an_fmin(l0, h0);
            float tv = dens * (k->len[i] * d);
            k->tau[i] += tv;
            k->r[i] += cr * tv;
            k->g[i] += cg * tv;
            k->bl[i] += cb * tv;
            k->hits[i] += (float)(tv > 0.0f);
            k->hit[w][i] |= (unsigned int)(tv > 0.0f) << bit;
            k->t1[v][i] = lo;
            k->t2[v][i] = lo + d;
        }
    }
    fogvol__an_ffinish(limit, law, k);
}

typedef void (*fogvol__an_fblock_fn)(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3],
                                     const fogvol__an_fvol *fv, const unsigned char *skip, float limit, int law,
                                     fogvol__an_fblock *k);

static void fogvol__an_fblock_c(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3],
                                const fogvol__an_fvol *fv, const unsigned char *skip, float limit, int law,
                                fogvol__an_fblock *k)
{
    fogvol__an_fblock_body(set, pe, e, fv, skip, limit, law, fogvol__an_sqrt_c, k);
}

#if FOGVOL__AN_X86
__attribute__((target("sse2"))) static void fogvol__an_sqrt_sse2(float *out, const float *in)
{
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 4) _mm_storeu_ps(out + i, _mm_sqrt_ps(_mm_loadu_ps(in + i)));
}
__attribute__((target("sse2"))) static void fogvol__an_fblock_sse2(const fogvol_analytic_set *set,
                                                                    const fogvol__an_eye *pe, const double e[3],
                                                                    const fogvol__an_fvol *fv,
                                                                    const unsigned char *skip, float limit, int law,
                                                                    fogvol__an_fblock *k)
{
    fogvol__an_fblock_body(set, pe, e, fv, skip, limit, law, fogvol__an_sqrt_sse2, k);
}
#endif

#if FOGVOL__AN_X86
/* ---- the AVX2 kernel ----
   The block body above written with AVX2 intrinsics, one pass per volume and
   group of 8 vertices (entry/exit, the sums, the hit mask and t1/t2 at once,
   where the C loops go through memory between the steps), the square roots
   in the same pass. The per-shape maths runs the same operations in the same
   order as the C kernels (the results are the same bit for bit). */
#define FOGVOL__AN_AVX2_FN __attribute__((target("avx2"))) static
#define FOGVOL__AN_AVX2_INL static __inline__ __attribute__((always_inline, target("avx2")))
#define FOGVOL__AN_V8(x) _mm256_set1_ps(x)

/* where is m set, a else b */
FOGVOL__AN_AVX2_INL __m256 fogvol__an_sel8(__m256 m, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, m); }
/* x + (x == 0): a divisor that is never 0 */
FOGVOL__AN_AVX2_INL __m256 fogvol__an_nz8(__m256 x)
{
    return _mm256_add_ps(x, _mm256_and_ps(_mm256_cmp_ps(x, _mm256_setzero_ps(), _CMP_EQ_OQ), FOGVOL__AN_V8(1.0f)));
}
FOGVOL__AN_AVX2_INL __m256 fogvol__an_dot8(const float *m, __m256 dx, __m256 dy, __m256 dz)
{
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(FOGVOL__AN_V8(m[0]), dx), _mm256_mul_ps(FOGVOL__AN_V8(m[1]), dy)),
                         _mm256_mul_ps(FOGVOL__AN_V8(m[2]), dz));
}

/* fogvol__an_fslab on 8 lanes */
FOGVOL__AN_AVX2_INL void fogvol__an_slab8(float o, __m256 v, __m256 *lo, __m256 *hi)
{
    __m256 z = _mm256_cmp_ps(v, _mm256_setzero_ps(), _CMP_EQ_OQ);
    __m256 iv = _mm256_div_ps(FOGVOL__AN_V8(1.0f), v); /* v = 0: infinite, those lanes are replaced below */
    __m256 ta = _mm256_mul_ps(FOGVOL__AN_V8(-1.0f - o), iv), tb = _mm256_mul_ps(FOGVOL__AN_V8(1.0f - o), iv);
    float par = ((o >= -1.0f) & (o <= 1.0f)) ? 1.0f : -1.0f;
    __m256 l = fogvol__an_sel8(z, _mm256_setzero_ps(), _mm256_min_ps(ta, tb));
    __m256 h = fogvol__an_sel8(z, FOGVOL__AN_V8(par), _mm256_max_ps(ta, tb));
    *lo = _mm256_max_ps(*lo, l);
    *hi = _mm256_min_ps(*hi, h);
}

/* fogvol__an_fdistance, fogvol__an_fhalf and fogvol__an_fbox on 8 lanes */
FOGVOL__AN_AVX2_INL void fogvol__an_flat8(const fogvol__an_fvol *f, __m256 dx, __m256 dy, __m256 dz, __m256 len,
                                          __m256 *lo, __m256 *hi)
{
    const float *m = f->m;
    __m256 zero = _mm256_setzero_ps(), one = FOGVOL__AN_V8(1.0f);
    if (f->shape == FOGVOL_SHAPE_DISTANCE) {
        __m256 ls = fogvol__an_nz8(len);
        __m256 h = m[1] > 0.0f ? _mm256_min_ps(_mm256_div_ps(FOGVOL__AN_V8(m[1]), ls), one) : one;
        *lo = _mm256_div_ps(FOGVOL__AN_V8(m[0]), ls);
        *hi = fogvol__an_sel8(_mm256_cmp_ps(len, zero, _CMP_GT_OQ), h, FOGVOL__AN_V8(-1.0f));
    } else if (f->shape == FOGVOL_SHAPE_HALF_SPACE) {
        __m256 s1 = fogvol__an_dot8(m, dx, dy, dz), tx = _mm256_div_ps(FOGVOL__AN_V8(-f->o[0]), fogvol__an_nz8(s1));
        __m256 up = _mm256_cmp_ps(s1, zero, _CMP_GT_OQ), down = _mm256_cmp_ps(s1, zero, _CMP_LT_OQ);
        __m256 h = fogvol__an_sel8(up, one, FOGVOL__AN_V8(f->o[0] >= 0.0f ? 1.0f : -1.0f));
        *lo = fogvol__an_sel8(up, _mm256_max_ps(tx, zero), zero);
        *hi = fogvol__an_sel8(down, _mm256_min_ps(tx, one), h);
    } else { /* BOX */
        *lo = zero, *hi = one;
        fogvol__an_slab8(f->o[0], fogvol__an_dot8(m, dx, dy, dz), lo, hi);
        fogvol__an_slab8(f->o[1], fogvol__an_dot8(m + 4, dx, dy, dz), lo, hi);
        fogvol__an_slab8(f->o[2], fogvol__an_dot8(m + 8, dx, dy, dz), lo, hi);
    }
}

/* fogvol__an_fquad1, the graze test and fogvol__an_fquad2 (and the
   cylinder's slab) on 8 lanes; returns the lanes that graze (a bit each) */
FOGVOL__AN_AVX2_INL int fogvol__an_quadric8(const fogvol__an_fvol *f, __m256 dx, __m256 dy, __m256 dz, __m256 *lo,
                                            __m256 *hi)
{
    const float *m = f->m, *o = f->o;
    __m256 zero = _mm256_setzero_ps(), one = FOGVOL__AN_V8(1.0f), o0 = FOGVOL__AN_V8(o[0]), o1 = FOGVOL__AN_V8(o[1]);
    __m256 v0, v1, v2, w2, o2, cx, cy, cz, a, b, disc, s, sg, q, r1, r2, l, h, pos;
    int cyl = f->shape == FOGVOL_SHAPE_CYLINDER, graze;
    if (f->shape == FOGVOL_SHAPE_SPHERE) {
        __m256 sc = FOGVOL__AN_V8(m[0]);
        v0 = _mm256_mul_ps(sc, dx), v1 = _mm256_mul_ps(sc, dy), v2 = _mm256_mul_ps(sc, dz);
    } else {
        v0 = fogvol__an_dot8(m, dx, dy, dz), v1 = fogvol__an_dot8(m + 4, dx, dy, dz);
        v2 = fogvol__an_dot8(m + 8, dx, dy, dz);
    }
    w2 = cyl ? zero : v2, o2 = FOGVOL__AN_V8(cyl ? 0.0f : o[2]);
    cx = _mm256_sub_ps(_mm256_mul_ps(o1, w2), _mm256_mul_ps(o2, v1));
    cy = _mm256_sub_ps(_mm256_mul_ps(o2, v0), _mm256_mul_ps(o0, w2));
    cz = _mm256_sub_ps(_mm256_mul_ps(o0, v1), _mm256_mul_ps(o1, v0));
    a = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(v0, v0), _mm256_mul_ps(v1, v1)), _mm256_mul_ps(w2, w2));
    b = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(o0, v0), _mm256_mul_ps(o1, v1)), _mm256_mul_ps(o2, w2));
    disc = _mm256_sub_ps(
        a, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(cx, cx), _mm256_mul_ps(cy, cy)), _mm256_mul_ps(cz, cz)));
    pos = _mm256_cmp_ps(a, zero, _CMP_GT_OQ);
    /* |disc| < GRAZE a (false where a = 0: a >= 0) */
    graze = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_andnot_ps(FOGVOL__AN_V8(-0.0f), disc),
                                             _mm256_mul_ps(FOGVOL__AN_V8(FOGVOL__AN_GRAZE), a), _CMP_LT_OQ));
    s = _mm256_sqrt_ps(_mm256_max_ps(disc, zero));
    sg = fogvol__an_sel8(_mm256_cmp_ps(b, zero, _CMP_GE_OQ), s, _mm256_xor_ps(s, FOGVOL__AN_V8(-0.0f)));
    q = _mm256_xor_ps(_mm256_add_ps(b, sg), FOGVOL__AN_V8(-0.0f)); /* -(b + sg), signed zeros included */
    /* a = 0 (those lanes take the blends below) and q = 0 (then disc <= 0: a miss) need no guard here */
    r1 = _mm256_div_ps(q, a), r2 = _mm256_div_ps(FOGVOL__AN_V8(f->c0), q);
    l = _mm256_max_ps(_mm256_min_ps(r1, r2), zero), h = _mm256_min_ps(_mm256_max_ps(r1, r2), one);
    h = fogvol__an_sel8(_mm256_cmp_ps(disc, zero, _CMP_GT_OQ), h, FOGVOL__AN_V8(-1.0f));
    *lo = fogvol__an_sel8(pos, l, zero);
    *hi = fogvol__an_sel8(pos, h, FOGVOL__AN_V8(f->c0 <= 0.0f ? 1.0f : -1.0f));
    if (cyl) fogvol__an_slab8(o[2], v2, lo, hi);
    return graze;
}

/* Volume v for the 8 vertices base .. base + 7 of the block: entry/exit into
   t1/t2; returns the optical depth dens * len * chord (tv). */
FOGVOL__AN_AVX2_INL __m256 fogvol__an_vol8(const fogvol_analytic_set *set, const fogvol__an_eye *pe,
                                           const double e[3], const fogvol__an_fvol *f, int v, int base, __m256 dx,
                                           __m256 dy, __m256 dz, __m256 len, fogvol__an_fblock *k)
{
    const __m256 zero = _mm256_setzero_ps();
    __m256 lo = zero, hi = zero, ch;
    int redo = 0xff;
    if (f->dbl) { /* every lane in double */
    } else if (f->shape == FOGVOL_SHAPE_DISTANCE || f->shape == FOGVOL_SHAPE_HALF_SPACE ||
               f->shape == FOGVOL_SHAPE_BOX) {
        fogvol__an_flat8(f, dx, dy, dz, len, &lo, &hi);
        redo = 0;
    } else {
        redo = fogvol__an_quadric8(f, dx, dy, dz, &lo, &hi);
    }
    ch = _mm256_max_ps(_mm256_sub_ps(hi, lo), zero);
    if (redo) {
        _mm256_storeu_ps(k->lo + base, lo), _mm256_storeu_ps(k->hi + base, hi), _mm256_storeu_ps(k->ch + base, ch);
        fogvol__an_redo_lanes(set, pe, e, v, redo, base, k);
        lo = _mm256_loadu_ps(k->lo + base), hi = _mm256_loadu_ps(k->hi + base), ch = _mm256_loadu_ps(k->ch + base);
    }
    lo = _mm256_min_ps(lo, hi);
    _mm256_storeu_ps(k->t1[v] + base, lo);
    _mm256_storeu_ps(k->t2[v] + base, _mm256_add_ps(lo, ch));
    return _mm256_mul_ps(FOGVOL__AN_V8(f->dens), _mm256_mul_ps(len, ch));
}

/* fogvol__an_fexp2 on 8 lanes */
FOGVOL__AN_AVX2_INL __m256 fogvol__an_fexp8(__m256 x, __m256 *om)
{
    __m256 xc = _mm256_min_ps(_mm256_max_ps(x, _mm256_setzero_ps()), FOGVOL__AN_V8(87.0f)), r, r2, p, scale;
    __m256i n = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_mul_ps(xc, FOGVOL__AN_V8(1.44269504f)), FOGVOL__AN_V8(0.5f)));
    __m256 fn = _mm256_cvtepi32_ps(n), one = FOGVOL__AN_V8(1.0f);
    scale = _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_sub_epi32(_mm256_set1_epi32(127), n), 23));
    r = _mm256_add_ps(_mm256_sub_ps(_mm256_mul_ps(fn, FOGVOL__AN_V8(0.693145751953125f)), xc),
                      _mm256_mul_ps(fn, FOGVOL__AN_V8(1.42860677e-6f)));
    r2 = _mm256_mul_ps(r, r);
    p = _mm256_add_ps(
        _mm256_add_ps(_mm256_add_ps(FOGVOL__AN_V8(5.0000001201e-1f), _mm256_mul_ps(FOGVOL__AN_V8(1.6666665459e-1f), r)),
                      _mm256_mul_ps(r2, _mm256_add_ps(FOGVOL__AN_V8(4.1665795894e-2f),
                                                      _mm256_mul_ps(FOGVOL__AN_V8(8.3334519073e-3f), r)))),
        _mm256_mul_ps(_mm256_mul_ps(r2, r2), _mm256_add_ps(FOGVOL__AN_V8(1.3981999507e-3f),
                                                           _mm256_mul_ps(FOGVOL__AN_V8(1.9875691500e-4f), r))));
    p = _mm256_add_ps(r, _mm256_mul_ps(r2, p));
    *om = _mm256_sub_ps(_mm256_sub_ps(one, scale), _mm256_mul_ps(p, scale));
    return _mm256_mul_ps(_mm256_add_ps(one, p), scale);
}

/* fogvol__an_ffinish on 8 lanes */
FOGVOL__AN_AVX2_INL void fogvol__an_ffinish8(float limit, int law, fogvol__an_fblock *k)
{
    const __m256 zero = _mm256_setzero_ps(), one = FOGVOL__AN_V8(1.0f), tiny = FOGVOL__AN_V8(1e-30f);
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8) {
        __m256 tau = _mm256_loadu_ps(k->tau + i), om, ex, big = _mm256_cmp_ps(tau, tiny, _CMP_GT_OQ);
        __m256 inv = _mm256_div_ps(one, _mm256_add_ps(tau, _mm256_and_ps(_mm256_cmp_ps(tau, tiny, _CMP_LE_OQ), one)));
        __m256 need = _mm256_and_ps(_mm256_cmp_ps(_mm256_loadu_ps(k->hits + i), one, _CMP_GT_OQ),
                                    _mm256_cmp_ps(tau, FOGVOL__AN_V8(limit), _CMP_GT_OQ));
        inv = _mm256_and_ps(big, inv);
        ex = fogvol__an_fexp8(tau, &om);
        _mm256_storeu_ps(k->fog + i, law == FOGVOL_FOG_EXP ? ex : _mm256_max_ps(_mm256_sub_ps(one, tau), zero));
        _mm256_storeu_ps(k->r + i, _mm256_mul_ps(_mm256_loadu_ps(k->r + i), inv));
        _mm256_storeu_ps(k->g + i, _mm256_mul_ps(_mm256_loadu_ps(k->g + i), inv));
        _mm256_storeu_ps(k->bl + i, _mm256_mul_ps(_mm256_loadu_ps(k->bl + i), inv));
        _mm256_storeu_ps(k->need + i, _mm256_and_ps(need, one));
    }
}

/* The block's 4 groups of 8 outside, the volumes inside: a group's sums and
   hit mask stay in registers. */
FOGVOL__AN_AVX2_FN void fogvol__an_fblock_avx2(const fogvol_analytic_set *set, const fogvol__an_eye *pe,
                                                const double e[3], const fogvol__an_fvol *fv,
                                                const unsigned char *skip, float limit, int law, fogvol__an_fblock *k)
{
    int base, v, i;
    for (base = 0; base < FOGVOL__AN_BLOCK; base += 8) {
        __m256 dx = _mm256_loadu_ps(k->dx + base), dy = _mm256_loadu_ps(k->dy + base);
        __m256 dz = _mm256_loadu_ps(k->dz + base), zero = _mm256_setzero_ps();
        __m256 len = _mm256_sqrt_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz)));
        __m256 tau = zero, r = zero, g = zero, bl = zero;
        __m256i hw = _mm256_setzero_si256();
        _mm256_storeu_ps(k->len + base, len);
        for (v = 0; v < set->count; ++v) {
            if (!skip[v]) { /* fogvol__an_fcull */
                const fogvol__an_fvol *f = &fv[v];
                __m256 tv = fogvol__an_vol8(set, pe, e, f, v, base, dx, dy, dz, len, k);
                __m256i bit = _mm256_set1_epi32((int)(1u << (v & 31)));
                tau = _mm256_add_ps(tau, tv);
                r = _mm256_add_ps(r, _mm256_mul_ps(FOGVOL__AN_V8(f->col[0]), tv));
                g = _mm256_add_ps(g, _mm256_mul_ps(FOGVOL__AN_V8(f->col[1]), tv));
                bl = _mm256_add_ps(bl, _mm256_mul_ps(FOGVOL__AN_V8(f->col[2]), tv));
                hw = _mm256_or_si256(hw, _mm256_and_si256(_mm256_castps_si256(_mm256_cmp_ps(tv, zero, _CMP_GT_OQ)), bit));
            }
            if ((v & 31) == 31 || v == set->count - 1) { /* a mask word done */
                _mm256_storeu_si256((__m256i *)(void *)(k->hit[v >> 5] + base), hw);
                hw = _mm256_setzero_si256();
            }
        }
        _mm256_storeu_ps(k->tau + base, tau), _mm256_storeu_ps(k->r + base, r);
        _mm256_storeu_ps(k->g + base, g), _mm256_storeu_ps(k->bl + base, bl);
    }
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) k->hits[i] = 0.0f; /* 2: two volumes or more on the ray */
    for (v = 0; v < (set->count + 31) / 32; ++v)
        for (i = 0; i < FOGVOL__AN_BLOCK; ++i)
            k->hits[i] += (float)(k->hit[v][i] != 0u) + (float)((k->hit[v][i] & (k->hit[v][i] - 1u)) != 0u);
    fogvol__an_ffinish8(limit, law, k);
}
#endif

FOGVOL_API fogvol_analytic_kernel fogvol_analytic_kernel_resolve(fogvol_analytic_kernel requested)
{
    int r = (int)requested;
    if (r < 0 || r >= (int)FOGVOL_ANALYTIC_KERNEL_COUNT) return FOGVOL_ANALYTIC_KERNEL_COUNT;
    if (r == FOGVOL_ANALYTIC_KERNEL_DOUBLE || r == FOGVOL_ANALYTIC_KERNEL_FLOAT) return requested;
#if FOGVOL__AN_X86
    __builtin_cpu_init();
    if ((r == FOGVOL_ANALYTIC_KERNEL_AUTO || r == FOGVOL_ANALYTIC_KERNEL_AVX2) && __builtin_cpu_supports("avx2"))
        return FOGVOL_ANALYTIC_KERNEL_AVX2;
    if (__builtin_cpu_supports("sse2")) return FOGVOL_ANALYTIC_KERNEL_SSE2;
#endif
    return FOGVOL_ANALYTIC_KERNEL_FLOAT;
}

/* A sphere around volume v (world space, radius inflated by 1e-4 for the
   float tests): the unit shape's centre mapped back, the radius from the
   Gram matrix G of the inverse map's columns (|M u|^2 = u^T G u), bounded by
   Gershgorin's rows for the unit ball (largest eigenvalue), by the sum of
   |G| over the unit cube's corners, and by disc + axis for the cylinder.
   Returns 0 for the unbounded shapes and a singular map. */
static int fogvol__an_bound(const fogvol_analytic_set *set, int v, double c[3], double *r)
{
    const double *m = set->map[v];
    double inv[9], g[3][3], det, r2 = 0.0;
    int i, j;
    if (set->shape[v] < FOGVOL_SHAPE_SPHERE) return 0;
    inv[0] = m[5] * m[10] - m[6] * m[9], inv[1] = m[2] * m[9] - m[1] * m[10], inv[2] = m[1] * m[6] - m[2] * m[5];
    inv[3] = m[6] * m[8] - m[4] * m[10], inv[4] = m[0] * m[10] - m[2] * m[8], inv[5] = m[2] * m[4] - m[0] * m[6];
    inv[6] = m[4] * m[9] - m[5] * m[8], inv[7] = m[1] * m[8] - m[0] * m[9], inv[8] = m[0] * m[5] - m[1] * m[4];
    det = m[0] * inv[0] + m[1] * inv[3] + m[2] * inv[6];
    if (!(FOGVOL_FABS(det) > 0.0)) return 0;
    for (i = 0; i < 9; ++i) inv[i] /= det; /* row-major: world = inv (unit - t) */
    for (i = 0; i < 3; ++i) c[i] = -(inv[i * 3] * m[3] + inv[i * 3 + 1] * m[7] + inv[i * 3 + 2] * m[11]);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            g[i][j] = inv[i] * inv[j] + inv[3 + i] * inv[3 + j] + inv[6 + i] * inv[6 + j];
    if (set->shape[v] == FOGVOL_SHAPE_BOX) {
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) r2 += FOGVOL_FABS(g[i][j]);
        *r = FOGVOL_SQRT(r2);
    } else if (set->shape[v] == FOGVOL_SHAPE_CYLINDER) {
        r2 = fogvol__an_max(g[0][0], g[1][1]) + FOGVOL_FABS(g[0][1]);
        *r = FOGVOL_SQRT(r2) + FOGVOL_SQRT(g[2][2]);
    } else {
        for (i = 0; i < 3; ++i)
            r2 = fogvol__an_max(r2, FOGVOL_FABS(g[i][0]) + FOGVOL_FABS(g[i][1]) + FOGVOL_FABS(g[i][2]));
        *r = FOGVOL_SQRT(r2);
    }
    *r = *r * 1.0001 + 1e-6;
    return *r < 1e18;
}

/* fogvol__an_fvol's bounding sphere as seen from the eye e */
static void fogvol__an_fbound(const fogvol_analytic_set *set, const double e[3], int v, fogvol__an_fvol *f)
{
    double c[3], r, d;
    f->bounded = fogvol__an_bound(set, v, c, &r);
    if (!f->bounded) return;
    c[0] -= e[0], c[1] -= e[1], c[2] -= e[2];
    d = FOGVOL_SQRT(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    f->bounded = d > r * 1.0001 && d < 1e18; /* the eye clearly outside */
    if (!f->bounded) return;
    f->bu[0] = (float)(c[0] / d), f->bu[1] = (float)(c[1] / d), f->bu[2] = (float)(c[2] / d);
    f->bnear = (float)(d - r), f->bsin = (float)(r / d), f->bcos = (float)FOGVOL_SQRT(1.0 - (r / d) * (r / d));
}

/* The float kernels' per-call volume table: the eye in each unit space
   (from the double one), and which volumes go to double whole. Returns the
   largest |vertex - eye| coordinate the float loops take (further vertices
   go to double one by one), or 0 when a volume's numbers could overflow
   float sums (density or colour beyond 1e6, an eye 1e12 units away in a
   unit space, a map entry beyond 1e12): the call then runs the DOUBLE kernel. */
static float fogvol__an_fvols(const fogvol_analytic_set *set, const fogvol__an_eye *pe, const double e[3],
                              fogvol__an_fvol *fv)
{
    double mmax = 1.0;
    int v, j;
    for (v = 0; v < set->count; ++v) {
        const double *o = pe->o[v], *m = set->map[v];
        double oo = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
        if (!(set->density[v] <= 1e6) || !(FOGVOL_FABS(set->color[v][0]) <= 1e6) ||
            !(FOGVOL_FABS(set->color[v][1]) <= 1e6) || !(FOGVOL_FABS(set->color[v][2]) <= 1e6))
            return 0.0f;
        if (set->shape[v] != FOGVOL_SHAPE_DISTANCE) {
            if (!(oo <= 1e24)) return 0.0f;
            for (j = 0; j < 12; ++j)
                if ((j & 3) != 3) mmax = fogvol__an_max(mmax, FOGVOL_FABS(m[j]));
        }
        for (j = 0; j < 12; ++j) fv[v].m[j] = (float)m[j];
        for (j = 0; j < 3; ++j) fv[v].o[j] = (float)o[j], fv[v].col[j] = (float)set->color[v][j];
        fv[v].c0 = (float)pe->c0[v];
        fv[v].dens = (float)set->density[v];
        fv[v].shape = set->shape[v];
        fv[v].dbl = set->shape[v] >= FOGVOL_SHAPE_SPHERE && !(oo <= FOGVOL__AN_FAR_EYE * FOGVOL__AN_FAR_EYE);
        fogvol__an_fbound(set, e, v, &fv[v]);
    }
    return mmax > 1e12 ? 0.0f : (float)(1e15 / mmax);
}

#define FOGVOL__AN_EVENTS (2 * FOGVOL_ANALYTIC_CAPACITY)

/* The event order of the last sorted vertex of a call: the next one starts
   from it (neighbouring vertices mostly see their volumes in the same order,
   so the insertion sort then only compares). */
typedef struct fogvol__an_fcarry {
    unsigned char ev[FOGVOL__AN_EVENTS];
    unsigned int hit[FOGVOL__AN_MASKS]; /* the volumes in ev */
    int m;
} fogvol__an_fcarry;

/* The stretches between a ray's sorted events key[0..m) (t bits << 32 |
   event index), front to back: the summed colour * density (rgb) and density
   (sig) of the volumes a stretch is in, and its length in world units
   (INTERPENETRATING, the paper's event list; the sums restart from exact
   zeros whenever no volume is open, so rounding never leaves a ghost density
   behind), or each volume whole at its entry (SEPARATE; t2: the exits, one
   volume every FOGVOL__AN_BLOCK). Stretches outside every volume are left out.
   Returns the stretch count; also each stretch's optical depth tau (for
   fogvol__an_fexpq). The EXP law's; the LINEAR laws walk the events
   themselves (fogvol__an_flinear_events). */
static int fogvol__an_fstretches(const fogvol__an_fvol *fv, int mix, float len, const uint64_t *key, const float *t2,
                                 int m, float (*rgb)[3], float *sig, float *tau)
{
    float ar = 0.0f, ag = 0.0f, ab = 0.0f, ad = 0.0f, last = 0.0f; /* scalars: kept in registers */
    int k, open = 0, n = 0;
    for (k = 0; k < m; ++k) {
        int e = (int)(key[k] & 0xffu);
        const fogvol__an_fvol *f = &fv[e >> 1];
        uint32_t u = (uint32_t)(key[k] >> 32);
        float t, sd = (e & 1) ? -f->dens : f->dens, sg, ln;
        memcpy(&t, &u, sizeof t);
        if (mix == FOGVOL_MIX_SEPARATE) {
            if (e & 1) continue;
            rgb[n][0] = f->col[0] * f->dens, rgb[n][1] = f->col[1] * f->dens, rgb[n][2] = f->col[2] * f->dens;
            sg = f->dens, ln = len * ((t2[(e >> 1) * FOGVOL__AN_BLOCK] + 0.0f) - t);
        } else {
            int was = open;
            rgb[n][0] = ar, rgb[n][1] = ag, rgb[n][2] = ab;
            sg = ad, ln = (t - last) * len;
            open += (e & 1) ? -1 : 1;
            ar += sd * f->col[0], ag += sd * f->col[1], ab += sd * f->col[2], ad += sd;
            if (open == 0) ar = ag = ab = ad = 0.0f;
            last = t;
            if (was == 0) continue; /* outside every volume (the first stretch, gaps): nothing to add */
        }
        sig[n] = sg;
        tau[n] = sg * ln;
        ++n;
    }
    return n;
}

/* The stretches' exp(-tau) and q = (1 - exp(-tau)) / sig (tau = 0: q = 0)
   from tau (in ex on entry) and sig, n of them (the arrays padded to a
   multiple of 8 entries, which the SIMD levels read and write): apart from
   the event walk, where they hang off none of its chains, and over all the
   sorted vertices of a block at once (fogvol__an_fstr), so AVX2 runs them 8
   at a time (the same operations in the same order: the same bits). */
typedef void (*fogvol__an_fexpq_fn)(float *ex, float *q, const float *sig, int n);

static void fogvol__an_fexpq_c(float *ex, float *q, const float *sig, int n)
{
    int k;
    for (k = 0; k < n; ++k) {
        float om, sg = sig[k];
        ex[k] = fogvol__an_fexp2(ex[k], &om);
        q[k] = om / (sg + (float)(sg == 0.0f));
    }
}

/* The EXP law over n stretches: each stretch of optical depth tau covers
   T (1 - exp(-tau)) of the pixel (T: the transmittance in front of it) with
   the mean colour rgb / sig; done once T < FOGVOL__AN_CUTOFF. */
static void fogvol__an_fexp_walk(const float (*rgb)[3], const float *sig, const float *ex, const float *q, int n,
                                 float *fog, float col[3])
{
    float f = 1.0f, w = 0.0f, n0 = 0.0f, n1 = 0.0f, n2 = 0.0f, inv; /* scalars: kept in registers */
    int k;
    for (k = 0; k < n && f >= (float)FOGVOL__AN_CUTOFF; ++k) {
        float a = f * q[k];
        n0 += rgb[k][0] * a, n1 += rgb[k][1] * a, n2 += rgb[k][2] * a;
        w += sig[k] * a;
        f *= ex[k];
    }
    inv = w > 1e-30f ? 1.0f / w : 0.0f;
    *fog = f;
    col[0] = n0 * inv, col[1] = n1 * inv, col[2] = n2 * inv;
}

/* The LINEAR law (each stretch takes tau = sig * l of the fog until none is
   left; colour weighted by the fog taken) and the paper's LINEAR_SEED colour
   formula, in float (fogvol__an_add's arithmetic), over the stretches of the
   sorted events key[0..m) as fogvol__an_fstretches forms them, in the same
   pass: it stops at the stretch that leaves no fog. */
static void fogvol__an_flinear_events(const fogvol__an_fvol *fv, int mix, float len, const uint64_t *key,
                                      const float *t2, int m, int law, float *fog, float col[3])
{
    float ar = 0.0f, ag = 0.0f, ab = 0.0f, ad = 0.0f, last = 0.0f; /* scalars: kept in registers */
    float f = 1.0f, w = 0.0f, n0 = 0.0f, n1 = 0.0f, n2 = 0.0f, inv;
    int k, open = 0;
    for (k = 0; k < m && f > 0.0f; ++k) {
        int e = (int)(key[k] & 0xffu);
        const fogvol__an_fvol *fl = &fv[e >> 1];
        uint32_t u = (uint32_t)(key[k] >> 32);
        float t, sd = (e & 1) ? -fl->dens : fl->dens, sr, sgr, sb, sg, ln, tau, a;
        memcpy(&t, &u, sizeof t);
        if (mix == FOGVOL_MIX_SEPARATE) {
            if (e & 1) continue;
            sr = fl->col[0] * fl->dens, sgr = fl->col[1] * fl->dens, sb = fl->col[2] * fl->dens;
            sg = fl->dens, ln = len * ((t2[(e >> 1) * FOGVOL__AN_BLOCK] + 0.0f) - t);
        } else {
            int was = open;
            sr = ar, sgr = ag, sb = ab;
            sg = ad, ln = (t - last) * len;
            open += (e & 1) ? -1 : 1;
            ar += sd * fl->col[0], ag += sd * fl->col[1], ab += sd * fl->col[2], ad += sd;
            if (open == 0) ar = ag = ab = ad = 0.0f;
            last = t;
            if (was == 0) continue; /* outside every volume (the first stretch, gaps): nothing to add */
        }
        tau = sg * ln;
        if (!(tau > 0.0f)) continue;
        if (law == FOGVOL_FOG_LINEAR_SEED) {
            n0 = sr / sg * f + n0 * (1.0f - f);
            n1 = sgr / sg * f + n1 * (1.0f - f);
            n2 = sb / sg * f + n2 * (1.0f - f);
            f -= tau < 1.0f ? tau : 1.0f;
            f = f > 0.0f ? f : 0.0f;
            continue;
        }
        a = tau >= f ? f / tau : 1.0f;
        n0 += sr * (ln * a), n1 += sgr * (ln * a), n2 += sb * (ln * a);
        w += tau * a;
        f = tau >= f ? 0.0f : f - tau;
    }
    inv = w > 1e-30f ? 1.0f / w : 0.0f;
    *fog = f;
    if (law == FOGVOL_FOG_LINEAR_SEED) inv = 1.0f;
    col[0] = n0 * inv, col[1] = n1 * inv, col[2] = n2 * inv;
}

/* The sort of the float kernels' sorted walk: only the events of the
   volumes on the ray (hit: the block's mask words of the vertex,
   FOGVOL__AN_BLOCK apart) are sorted, by insertion from the order of the
   previous sorted vertex (carry): its events still on the ray in that order,
   then those of the volumes new to the ray in volume order. The keys are
   t bits << 32 | event index (t >= 0, so the integer order is the order of t,
   ties by event index). Returns the event count. */
static int fogvol__an_fsort_events(const fogvol_analytic_set *s, const float *t1, const float *t2,
                                   const unsigned int *hit, fogvol__an_fcarry *carry, int64_t *moves, uint64_t *key)
{
    int m = 0, w, k, j, nw = (s->count + 31) / 32;
    for (k = 0; k < carry->m; ++k) { /* kept without a branch: m advances for the volumes on the ray */
        int e = carry->ev[k], v = e >> 1;
        float t = ((e & 1) ? t2 : t1)[v * FOGVOL__AN_BLOCK] + 0.0f; /* + 0: no -0, whose bits would sort last */
        uint32_t u;
        memcpy(&u, &t, sizeof u);
        key[m] = (uint64_t)u << 32 | (uint64_t)e;
        m += (int)((hit[(v >> 5) * FOGVOL__AN_BLOCK] >> (v & 31)) & 1u);
    }
    for (w = 0; w < nw; ++w) {
        unsigned int bits = hit[w * FOGVOL__AN_BLOCK] & ~carry->hit[w];
        carry->hit[w] = hit[w * FOGVOL__AN_BLOCK];
        while (bits) {
            int v = 32 * w + fogvol__an_ctz(bits);
            float a = t1[v * FOGVOL__AN_BLOCK] + 0.0f, b = t2[v * FOGVOL__AN_BLOCK] + 0.0f;
            uint32_t ua, ub;
            bits &= bits - 1u;
            memcpy(&ua, &a, sizeof ua);
            memcpy(&ub, &b, sizeof ub);
            key[m++] = (uint64_t)ua << 32 | (uint64_t)(2 * v);
            key[m++] = (uint64_t)ub << 32 | (uint64_t)(2 * v + 1);
        }
    }
    for (k = 1; k < m; ++k) {
        uint64_t x = key[k];
        for (j = k; j > 0 && key[j - 1] > x; --j) key[j] = key[j - 1], ++*moves;
        key[j] = x;
    }
    for (k = 0; k < m; ++k) carry->ev[k] = (unsigned char)(key[k] & 0xffu);
    carry->m = m;
    return m;
}

/* The EXP law's stretches of a block's sorted vertices, gathered so that
   their exp() runs in one loop over all of them (fogvol__an_fexpq: 8 at a
   time with AVX2, where one vertex's 3 to 9 would leave the lanes idle and
   wait on the loop's latency); flushed when full and at the end of a block.
   sig, ex and q have room for the padding to a multiple of 8. */
#define FOGVOL__AN_SCAP (FOGVOL__AN_EVENTS + 128)
typedef struct fogvol__an_fstr {
    float rgb[FOGVOL__AN_SCAP][3], sig[FOGVOL__AN_SCAP + 8], ex[FOGVOL__AN_SCAP + 8], q[FOGVOL__AN_SCAP + 8];
    int first[FOGVOL__AN_BLOCK], count[FOGVOL__AN_BLOCK], vert[FOGVOL__AN_BLOCK];
    int n, verts;
} fogvol__an_fstr;

/* exp() of the gathered stretches, then each vertex's walk into fog[vert], col[vert] */
static void fogvol__an_fstr_flush(fogvol__an_fstr *st, fogvol__an_fexpq_fn expq, float *fog, float (*col)[3])
{
    int j;
    for (j = st->n; j & 7; ++j) st->ex[j] = st->sig[j] = 0.0f;
    expq(st->ex, st->q, st->sig, st->n);
    for (j = 0; j < st->verts; ++j) {
        int a = st->first[j];
        fogvol__an_fexp_walk((const float(*)[3])st->rgb + a, st->sig + a, st->ex + a, st->q + a, st->count[j],
                             &fog[st->vert[j]], col[st->vert[j]]);
    }
    st->n = st->verts = 0;
}

/* What a batch call works on, for the float kernels' loop. */
typedef struct fogvol__an_call {
    const fogvol_analytic_set *set;
    const fogvol__an_eye *pe;
    const double *e;
    const unsigned char *src;
    float *fog_out, *color_out;
    fogvol_analytic_order *order;
    unsigned char *carry;
    double limit;
    float dlim; /* |vertex - eye| coordinates beyond this go to double (fogvol__an_fvols) */
    int eye_ok, law, mix, count, stride, fog_stride, color_stride, bad, sorted;
    int64_t moves;
    fogvol__an_fcarry fcarry; /* the float kernels' event order, from sorted vertex to sorted vertex */
} fogvol__an_call;

/* Gathers block `base` (checked: x - x is 0 for finite x only), padded with
   zero-length rays; valid: 0 non-finite, 1 float, 2 double (too far). */
static void fogvol__an_fgather(fogvol__an_call *c, int base, int nb, unsigned char *valid, fogvol__an_fblock *k)
{
    float ex = (float)c->e[0], ey = (float)c->e[1], ez = (float)c->e[2];
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        float x = ex, y = ey, z = ez;
        int ok = 0;
        if (i < nb) {
            const float *p = (const float *)(const void *)(c->src + (size_t)(base + i) * (size_t)c->stride);
            ok = c->eye_ok & (p[0] - p[0] == 0.0f) & (p[1] - p[1] == 0.0f) & (p[2] - p[2] == 0.0f);
            c->bad += !ok;
            /* float could overflow: the vertex goes to double whole */
            if (ok && !(p[0] - ex <= c->dlim && p[0] - ex >= -c->dlim && p[1] - ey <= c->dlim &&
                        p[1] - ey >= -c->dlim && p[2] - ez <= c->dlim && p[2] - ez >= -c->dlim))
                ok = 2;
            if (ok == 1) x = p[0], y = p[1], z = p[2];
        }
        valid[i] = (unsigned char)ok;
        k->px[i] = x, k->py[i] = y, k->pz[i] = z;
        k->dx[i] = x - ex, k->dy[i] = y - ey, k->dz[i] = z - ez;
    }
}

#if FOGVOL__AN_X86
/* fogvol__an_fgather for a whole block with AVX2 gathers (byte offsets: a
   stride up to 1 MB); the same tests and results. */
FOGVOL__AN_AVX2_FN void fogvol__an_fgather_avx2(fogvol__an_call *c, int base, int nb, unsigned char *valid,
                                                 fogvol__an_fblock *k)
{
    const float *src;
    __m256 e8[3], lim = FOGVOL__AN_V8(c->dlim), nlim = FOGVOL__AN_V8(-c->dlim), zero = _mm256_setzero_ps();
    __m256i off;
    int g, j, d;
    if (nb < FOGVOL__AN_BLOCK || c->stride > (1 << 20)) {
        fogvol__an_fgather(c, base, nb, valid, k);
        return;
    }
    src = (const float *)(const void *)(c->src + (size_t)base * (size_t)c->stride);
    for (d = 0; d < 3; ++d) e8[d] = FOGVOL__AN_V8((float)c->e[d]);
    off = _mm256_mullo_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(c->stride));
    for (g = 0; g < FOGVOL__AN_BLOCK; g += 8) {
        __m256 p[3], ok = c->eye_ok ? _mm256_castsi256_ps(_mm256_set1_epi32(-1)) : zero, in = ok;
        int mo, mi;
        for (d = 0; d < 3; ++d) {
            __m256 q;
            p[d] = _mm256_i32gather_ps(src + d, off, 1);
            q = _mm256_sub_ps(p[d], e8[d]);
            ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_sub_ps(p[d], p[d]), zero, _CMP_EQ_OQ));
            in = _mm256_and_ps(in, _mm256_and_ps(_mm256_cmp_ps(q, lim, _CMP_LE_OQ), _mm256_cmp_ps(q, nlim, _CMP_GE_OQ)));
        }
        in = _mm256_and_ps(in, ok); /* valid 1: the float loops take it */
        for (d = 0; d < 3; ++d) {
            float *pk = d == 0 ? k->px : d == 1 ? k->py : k->pz, *dk = d == 0 ? k->dx : d == 1 ? k->dy : k->dz;
            __m256 x = fogvol__an_sel8(in, p[d], e8[d]);
            _mm256_storeu_ps(pk + g, x);
            _mm256_storeu_ps(dk + g, _mm256_sub_ps(x, e8[d]));
        }
        mo = _mm256_movemask_ps(ok), mi = _mm256_movemask_ps(in);
        for (j = 0; j < 8; ++j) valid[g + j] = (unsigned char)(((mo >> j) & 1) + ((mo & ~mi) >> j & 1));
        for (j = 0; j < 8; ++j) c->bad += !((mo >> j) & 1);
        off = _mm256_add_epi32(off, _mm256_set1_epi32(8 * c->stride));
    }
}
#endif

/* The lane loops of fogvol__an_fcull: the sum A of the block's rays and, over
   the rays, the smallest cos^2 of the angle to A (-1 beyond 90 degrees) and
   the largest squared length: out = {Ax, Ay, Az, cos^2 min, length^2 max}.
   8 partial sums / minima / maxima, added up in one fixed order (the SIMD
   levels below run the same operations in the same order). */
typedef void (*fogvol__an_fcone_fn)(const fogvol__an_fblock *k, float out[5]);

FOGVOL__AN_INLINE float fogvol__an_hsum8(const float *p)
{
    return ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]));
}

FOGVOL__AN_INLINE void fogvol__an_fcone_end(const float *px, const float *py, const float *pz, float out[3])
{
    out[0] = fogvol__an_hsum8(px), out[1] = fogvol__an_hsum8(py), out[2] = fogvol__an_hsum8(pz);
}

FOGVOL__AN_INLINE void fogvol__an_fcone_min(const float *pc, const float *pl, float out[5])
{
    int j;
    out[3] = pc[0], out[4] = pl[0];
    for (j = 1; j < 8; ++j) out[3] = fogvol__an_fmin(out[3], pc[j]), out[4] = fogvol__an_fmax(out[4], pl[j]);
}

static void fogvol__an_fcone_c(const fogvol__an_fblock *k, float out[5])
{
    float px[8] = {0}, py[8] = {0}, pz[8] = {0}, pc[8], pl[8] = {0}, ax, ay, az, aa;
    int i, j;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8)
        for (j = 0; j < 8; ++j) px[j] += k->dx[i + j], py[j] += k->dy[i + j], pz[j] += k->dz[i + j];
    fogvol__an_fcone_end(px, py, pz, out);
    ax = out[0], ay = out[1], az = out[2];
    aa = ax * ax + ay * ay + az * az;
    for (j = 0; j < 8; ++j) pc[j] = 1.0f;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8)
        for (j = 0; j < 8; ++j) {
            float x = k->dx[i + j], y = k->dy[i + j], z = k->dz[i + j], d2 = x * x + y * y + z * z;
            float da = x * ax + y * ay + z * az, q = d2 * aa;
            float c2 = (da > 0.0f ? da * da : -q) / (q + (float)(q == 0.0f)); /* cos^2 to A; -1: beyond 90 degrees */
            pc[j] = fogvol__an_fmin(pc[j], d2 > 0.0f ? c2 : 1.0f);
            pl[j] = fogvol__an_fmax(pl[j], d2);
        }
    fogvol__an_fcone_min(pc, pl, out);
}

#if FOGVOL__AN_X86
/* fogvol__an_fcone_c with 4 lanes (two halves of the 8 partial results) */
__attribute__((target("sse2"))) static void fogvol__an_fcone_sse2(const fogvol__an_fblock *k, float out[5])
{
    __m128 px[2], py[2], pz[2], pc[2], pl[2], ax, ay, az, aa, zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    float sx[8], sy[8], sz[8], sc[8], sl[8];
    int i, h;
    for (h = 0; h < 2; ++h) px[h] = py[h] = pz[h] = pl[h] = zero, pc[h] = one;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8)
        for (h = 0; h < 2; ++h) {
            px[h] = _mm_add_ps(px[h], _mm_loadu_ps(k->dx + i + 4 * h));
            py[h] = _mm_add_ps(py[h], _mm_loadu_ps(k->dy + i + 4 * h));
            pz[h] = _mm_add_ps(pz[h], _mm_loadu_ps(k->dz + i + 4 * h));
        }
    for (h = 0; h < 2; ++h)
        _mm_storeu_ps(sx + 4 * h, px[h]), _mm_storeu_ps(sy + 4 * h, py[h]), _mm_storeu_ps(sz + 4 * h, pz[h]);
    fogvol__an_fcone_end(sx, sy, sz, out);
    ax = _mm_set1_ps(out[0]), ay = _mm_set1_ps(out[1]), az = _mm_set1_ps(out[2]);
    aa = _mm_set1_ps(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8)
        for (h = 0; h < 2; ++h) {
            __m128 x = _mm_loadu_ps(k->dx + i + 4 * h), y = _mm_loadu_ps(k->dy + i + 4 * h);
            __m128 z = _mm_loadu_ps(k->dz + i + 4 * h);
            __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z));
            __m128 da = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, ax), _mm_mul_ps(y, ay)), _mm_mul_ps(z, az));
            __m128 q = _mm_mul_ps(d2, aa), pos = _mm_cmpgt_ps(da, zero), in = _mm_cmpgt_ps(d2, zero);
            __m128 num = _mm_or_ps(_mm_and_ps(pos, _mm_mul_ps(da, da)), _mm_andnot_ps(pos, _mm_xor_ps(q, _mm_set1_ps(-0.0f))));
            __m128 c2 = _mm_div_ps(num, _mm_add_ps(q, _mm_and_ps(_mm_cmpeq_ps(q, zero), one)));
            pc[h] = _mm_min_ps(pc[h], _mm_or_ps(_mm_and_ps(in, c2), _mm_andnot_ps(in, one)));
            pl[h] = _mm_max_ps(pl[h], d2);
        }
    for (h = 0; h < 2; ++h) _mm_storeu_ps(sc + 4 * h, pc[h]), _mm_storeu_ps(sl + 4 * h, pl[h]);
    fogvol__an_fcone_min(sc, sl, out);
}

/* fogvol__an_fexpq_c with 8 lanes (the padding included) */
FOGVOL__AN_AVX2_FN void fogvol__an_fexpq_avx2(float *ex, float *q, const float *sig, int n)
{
    int k;
    for (k = 0; k < n; k += 8) {
        __m256 om, e = fogvol__an_fexp8(_mm256_loadu_ps(ex + k), &om);
        _mm256_storeu_ps(ex + k, e);
        _mm256_storeu_ps(q + k, _mm256_div_ps(om, fogvol__an_nz8(_mm256_loadu_ps(sig + k))));
    }
}

/* fogvol__an_fcone_c with 8 lanes */
FOGVOL__AN_AVX2_FN void fogvol__an_fcone_avx2(const fogvol__an_fblock *k, float out[5])
{
    __m256 px = _mm256_setzero_ps(), py = px, pz = px, pl = px, zero = px, one = FOGVOL__AN_V8(1.0f), pc = one;
    __m256 ax, ay, az, aa;
    float sx[8], sy[8], sz[8];
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8) {
        px = _mm256_add_ps(px, _mm256_loadu_ps(k->dx + i));
        py = _mm256_add_ps(py, _mm256_loadu_ps(k->dy + i));
        pz = _mm256_add_ps(pz, _mm256_loadu_ps(k->dz + i));
    }
    _mm256_storeu_ps(sx, px), _mm256_storeu_ps(sy, py), _mm256_storeu_ps(sz, pz);
    fogvol__an_fcone_end(sx, sy, sz, out);
    ax = FOGVOL__AN_V8(out[0]), ay = FOGVOL__AN_V8(out[1]), az = FOGVOL__AN_V8(out[2]);
    aa = FOGVOL__AN_V8(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
    for (i = 0; i < FOGVOL__AN_BLOCK; i += 8) {
        __m256 x = _mm256_loadu_ps(k->dx + i), y = _mm256_loadu_ps(k->dy + i), z = _mm256_loadu_ps(k->dz + i);
        __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)), _mm256_mul_ps(z, z));
        __m256 da = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, ax), _mm256_mul_ps(y, ay)), _mm256_mul_ps(z, az));
        __m256 q = _mm256_mul_ps(d2, aa);
        __m256 num = fogvol__an_sel8(_mm256_cmp_ps(da, zero, _CMP_GT_OQ), _mm256_mul_ps(da, da),
                                     _mm256_xor_ps(q, FOGVOL__AN_V8(-0.0f)));
        __m256 c2 = _mm256_div_ps(num, fogvol__an_nz8(q));
        pc = _mm256_min_ps(pc, fogvol__an_sel8(_mm256_cmp_ps(d2, zero, _CMP_GT_OQ), c2, one));
        pl = _mm256_max_ps(pl, d2);
    }
    _mm256_storeu_ps(sx, pc), _mm256_storeu_ps(sy, pl);
    fogvol__an_fcone_min(sx, sy, out);
}
#endif


/* Which volumes no ray of block k can reach (skip[v] = 1): the rays from
   the eye to the block's vertices (k->dx..dz; zero for the lanes the block
   does not evaluate, which can only be in a volume around the eye, never
   skipped) lie in a cone around their sum A, of half angle theta, and are at
   most lmax long (cone: fogvol__an_fcone_c's out). A volume whose bounding
   sphere (fogvol__an_fvol) is further than lmax or outside that cone widened
   by the sphere's half angle alpha (the angle between A and the sphere's
   centre above theta + alpha) is missed by every ray, and so is a volume of
   density 0. The float tests keep margins of 1e-4. */
static void fogvol__an_fcull(int count, const fogvol__an_fvol *fv, const float cone[5], unsigned char *skip)
{
    float ax = cone[0], ay = cone[1], az = cone[2], aa, ia, c2min = cone[3], l2max = cone[4], cth, sth, lmax;
    int v;
    aa = ax * ax + ay * ay + az * az;
    cth = c2min > 0.0f ? (float)FOGVOL_SQRT((double)c2min) - 1e-4f : -1.0f; /* cos(theta), widened */
    sth = (float)FOGVOL_SQRT(1.0 - (double)cth * cth);
    lmax = (float)FOGVOL_SQRT((double)l2max) * 1.0001f + 1e-6f;
    ia = aa > 0.0f ? 1.0f / (float)FOGVOL_SQRT((double)aa) : 0.0f;
    for (v = 0; v < count; ++v) { /* without branches on the data */
        const fogvol__an_fvol *f = &fv[v];
        float cosa = (ax * f->bu[0] + ay * f->bu[1] + az * f->bu[2]) * ia;
        int far = f->bnear > lmax, out = cosa < cth * f->bcos - sth * f->bsin - 1e-4f, none = f->dens > 0.0f ? 0 : 1;
        skip[v] = (unsigned char)(none | (f->bounded & (far | ((cth > 0.0f) & out))));
    }
}

/* What a resolved float level runs for each block: its gather, the cone of its culling and its kernel. */
typedef void (*fogvol__an_fgather_fn)(fogvol__an_call *c, int base, int nb, unsigned char *valid,
                                      fogvol__an_fblock *k);
typedef struct fogvol__an_flevel {
    fogvol__an_fgather_fn gather;
    fogvol__an_fcone_fn cone;
    fogvol__an_fblock_fn block;
    fogvol__an_fexpq_fn expq;
} fogvol__an_flevel;

/* Returns 0 (nothing written) when the set needs the DOUBLE kernel. */
static int fogvol__an_fbatch(fogvol__an_call *c, const fogvol__an_flevel *lv)
{
    fogvol__an_fblock blk;
    fogvol__an_fstr st;
    fogvol__an_fvol fv[FOGVOL_ANALYTIC_CAPACITY];
    unsigned char valid[FOGVOL__AN_BLOCK], skip[FOGVOL_ANALYTIC_CAPACITY];
    uint64_t key[FOGVOL__AN_EVENTS];
    float bf[FOGVOL__AN_BLOCK], bc[FOGVOL__AN_BLOCK][3]; /* the block's results */
    int base, i;
    float cn[5], limit = c->limit > 1e30 ? 1e30f : (float)c->limit;
    c->dlim = fogvol__an_fvols(c->set, c->pe, c->e, fv);
    if (c->dlim == 0.0f) return 0;
    st.n = st.verts = 0;
    for (base = 0; base < c->count; base += FOGVOL__AN_BLOCK) {
        int nb = c->count - base < FOGVOL__AN_BLOCK ? c->count - base : FOGVOL__AN_BLOCK;
        lv->gather(c, base, nb, valid, &blk);
        lv->cone(&blk, cn);
        fogvol__an_fcull(c->set->count, fv, cn, skip);
        lv->block(c->set, c->pe, c->e, fv, skip, limit, c->law, &blk);
        for (i = 0; i < nb; ++i) {
            float *f = &bf[i], *col = bc[i];
            *f = 1.0f, col[0] = col[1] = col[2] = 0.0f;
            if (!valid[i]) {
                /* fog 1, colour 0 */
            } else if (valid[i] == 2) {
                const float *p = (const float *)(const void *)(c->src + (size_t)(base + i) * (size_t)c->stride);
                fogvol__an_vertex(c->set, c->pe, c->e, p, c->law, c->mix, f, col);
            } else if (blk.need[i] != 0.0f) {
                const float *t2 = (const float *)(const void *)blk.t2 + i;
                int m = fogvol__an_fsort_events(c->set, (const float *)(const void *)blk.t1 + i, t2,
                                                (const unsigned int *)(const void *)blk.hit + i, &c->fcarry,
                                                &c->moves, key);
                ++c->sorted;
                if (c->law != FOGVOL_FOG_EXP) {
                    fogvol__an_flinear_events(fv, c->mix, blk.len[i], key, t2, m, c->law, f, col);
                    continue;
                }
                if (st.n + FOGVOL__AN_EVENTS > FOGVOL__AN_SCAP) fogvol__an_fstr_flush(&st, lv->expq, bf, bc);
                st.first[st.verts] = st.n, st.vert[st.verts] = i; /* fog and colour at the flush */
                st.count[st.verts] = fogvol__an_fstretches(fv, c->mix, blk.len[i], key, t2, m, st.rgb + st.n,
                                                           st.sig + st.n, st.ex + st.n);
                st.n += st.count[st.verts++];
            } else {
                *f = blk.fog[i];
                col[0] = blk.r[i], col[1] = blk.g[i], col[2] = blk.bl[i];
            }
        }
        if (st.verts) fogvol__an_fstr_flush(&st, lv->expq, bf, bc); /* (none: no sorted EXP vertex) */
        for (i = 0; i < nb; ++i) {
            size_t idx = (size_t)(base + i);
            if (c->fog_out) *(float *)(void *)((unsigned char *)c->fog_out + idx * (size_t)c->fog_stride) = bf[i];
            if (c->color_out) {
                float *out = (float *)(void *)((unsigned char *)c->color_out + idx * (size_t)c->color_stride);
                out[0] = bc[i][0], out[1] = bc[i][1], out[2] = bc[i][2];
            }
        }
    }
    return 1;
}

/* The functions of a resolved float level (SSE2 gathers with the C loop). */
static fogvol__an_flevel fogvol__an_flevel_of(fogvol_analytic_kernel k)
{
    fogvol__an_flevel lv;
    lv.gather = fogvol__an_fgather, lv.cone = fogvol__an_fcone_c, lv.block = fogvol__an_fblock_c;
    lv.expq = fogvol__an_fexpq_c;
#if FOGVOL__AN_X86
    if (k == FOGVOL_ANALYTIC_KERNEL_AVX2) {
        lv.gather = fogvol__an_fgather_avx2, lv.cone = fogvol__an_fcone_avx2, lv.block = fogvol__an_fblock_avx2;
        lv.expq = fogvol__an_fexpq_avx2;
    }
    if (k == FOGVOL_ANALYTIC_KERNEL_SSE2) lv.cone = fogvol__an_fcone_sse2, lv.block = fogvol__an_fblock_sse2;
#else
    (void)k;
#endif
    return lv;
}

/* The double kernel's gather of block `base` (checked: x - x is 0 for finite x only), padded with
   zero-length rays; valid[i]: 1 finite. */
static void fogvol__an_dgather(fogvol__an_call *c, int base, int nb, unsigned char *valid, fogvol__an_block *blk)
{
    int i;
    for (i = 0; i < FOGVOL__AN_BLOCK; ++i) {
        float x = 0.0f, y = 0.0f, z = 0.0f;
        int ok = 0;
        if (i < nb) {
            const float *p = (const float *)(const void *)(c->src + (size_t)(base + i) * (size_t)c->stride);
            x = p[0], y = p[1], z = p[2];
            ok = c->eye_ok & (x - x == 0.0f) & (y - y == 0.0f) & (z - z == 0.0f);
            c->bad += !ok;
        }
        valid[i] = (unsigned char)ok;
        blk->dx[i] = ok ? (double)x - c->e[0] : 0.0;
        blk->dy[i] = ok ? (double)y - c->e[1] : 0.0;
        blk->dz[i] = ok ? (double)z - c->e[2] : 0.0;
    }
}

/* Vertex i of a double block: the sorted walk (carrying the event order from vertex to vertex,
   or per vertex in order->vertex_orders), or the block's own result. */
static void fogvol__an_dvertex(fogvol__an_call *c, const fogvol__an_block *blk, int i, size_t idx, float *f,
                               float col[3])
{
    const fogvol_analytic_order *order = c->order;
    int m = 2 * c->set->count;
    unsigned char *perm = c->carry;
    if (blk->need[i] == 0.0) {
        *f = (float)blk->fog[i];
        col[0] = (float)blk->r[i], col[1] = (float)blk->g[i], col[2] = (float)blk->bl[i];
        return;
    }
    if (order && order->vertex_orders && (idx + 1) * (size_t)m <= order->vertex_orders_size) {
        perm = order->vertex_orders + idx * (size_t)m;
        if (!fogvol__an_perm_ok(perm, m)) memcpy(perm, c->carry, (size_t)m);
    }
    fogvol__an_sorted_vertex(c->set, (fogvol_fog_law)c->law, (fogvol_fog_mix)c->mix, blk->len[i],
                             (const float *)(const void *)blk->t1 + i, (const float *)(const void *)blk->t2 + i,
                             FOGVOL__AN_BLOCK, perm, &c->moves, f, col);
    ++c->sorted;
    if (perm != c->carry) memcpy(c->carry, perm, (size_t)m); /* the next vertex starts from it */
}

/* The DOUBLE kernel: blocks of FOGVOL__AN_BLOCK vertices in double, the reference. */
static void fogvol__an_dbatch(fogvol__an_call *c)
{
    fogvol__an_block blk;
    unsigned char valid[FOGVOL__AN_BLOCK];
    int base, i;
    for (base = 0; base < c->count; base += FOGVOL__AN_BLOCK) {
        int nb = c->count - base < FOGVOL__AN_BLOCK ? c->count - base : FOGVOL__AN_BLOCK;
        fogvol__an_dgather(c, base, nb, valid, &blk);
        fogvol__an_block_eval(c->set, c->pe, c->limit, &blk);
        if (c->law == FOGVOL_FOG_EXP)
            for (i = 0; i < nb; ++i)
                if (blk.need[i] == 0.0) blk.fog[i] = blk.tau[i] > 0.0 ? FOGVOL_EXP(-blk.tau[i]) : 1.0;
        for (i = 0; i < nb; ++i) {
            size_t idx = (size_t)(base + i);
            float f = 1.0f, col[3] = {0.0f, 0.0f, 0.0f}; /* invalid: fog 1, colour 0 */
            if (valid[i]) fogvol__an_dvertex(c, &blk, i, idx, &f, col);
            if (c->fog_out) *(float *)(void *)((unsigned char *)c->fog_out + idx * (size_t)c->fog_stride) = f;
            if (c->color_out) {
                float *o = (float *)(void *)((unsigned char *)c->color_out + idx * (size_t)c->color_stride);
                o[0] = col[0], o[1] = col[1], o[2] = col[2];
            }
        }
    }
}

FOGVOL_API fogvol_result fogvol_analytic_batch(const fogvol_analytic_set *set, const float eye[3],
                                               const float *positions, int count, int stride, fogvol_fog_law law,
                                               fogvol_fog_mix mix, float *fog_out, int fog_stride, float *color_out,
                                               int color_stride, fogvol_analytic_order *order, int *invalid)
{
    fogvol__an_eye pe;
    fogvol__an_call c;
    unsigned char local[2 * FOGVOL_ANALYTIC_CAPACITY];
    double e[3];
    int m;
    fogvol_analytic_kernel kern;
    fogvol__an_flevel lv;
    if (invalid) *invalid = 0;
    if (!fogvol__an_args_ok(set, law, mix)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    kern = fogvol_analytic_kernel_resolve((fogvol_analytic_kernel)set->kernel);
    if (kern == FOGVOL_ANALYTIC_KERNEL_COUNT || !eye || count < 0 || (count > 0 && !positions) || stride < 0 ||
        (stride > 0 && stride < 12) || fog_stride < 0 || (fog_stride > 0 && fog_stride < 4) || color_stride < 0 ||
        (color_stride > 0 && color_stride < 12))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(&c, 0, sizeof c);
    m = 2 * set->count;
    c.eye_ok = fogvol__finite_n(eye, 3);
    e[0] = c.eye_ok ? eye[0] : 0.0, e[1] = c.eye_ok ? eye[1] : 0.0, e[2] = c.eye_ok ? eye[2] : 0.0;
    fogvol__an_eye_init(set, e, &pe);
    c.carry = order ? order->carried : local;
    if (!order) {
        fogvol__an_identity(c.carry, m);
    } else if (order->carried_count != set->count || !fogvol__an_perm_ok(c.carry, m)) {
        fogvol__an_identity(c.carry, m);
        order->carried_count = set->count;
    }
    c.set = set, c.pe = &pe, c.e = e, c.src = (const unsigned char *)positions, c.order = order;
    c.limit = fogvol__an_sort_limit(set, law);
    c.law = (int)law, c.mix = (int)mix, c.count = count, c.stride = stride ? stride : 12;
    c.fog_out = fog_out, c.fog_stride = fog_stride ? fog_stride : 4;
    c.color_out = color_out, c.color_stride = color_stride ? color_stride : 12;
    lv = fogvol__an_flevel_of(kern);
    if (kern == FOGVOL_ANALYTIC_KERNEL_DOUBLE || !fogvol__an_fbatch(&c, &lv)) {
        c.bad = c.sorted = 0;
        c.moves = 0;
        fogvol__an_dbatch(&c);
    }
    if (order) {
        order->sorted_vertices = c.sorted;
        order->moves = c.moves;
    }
    if (invalid) *invalid = c.bad;
    return c.bad ? FOGVOL_ERROR_INVALID_ARGUMENT : FOGVOL_SUCCESS;
}

FOGVOL_API void fogvol_fold_fog(const float diffuse[4], const float specular[4], float fog, const float fog_color[3],
                                float new_diffuse[4], float new_specular[4])
{
    float f = fogvol__finite(fog) ? (fog < 0.0f ? 0.0f : fog > 1.0f ? 1.0f : fog) : 1.0f;
    int c;
    if (diffuse && new_diffuse) {
        for (c = 0; c < 3; ++c) new_diffuse[c] = diffuse[c] * f;
        new_diffuse[3] = diffuse[3];
    }
    if (specular && new_specular) {
        for (c = 0; c < 3; ++c) new_specular[c] = specular[c] * f + (fog_color ? fog_color[c] : 0.0f) * (1.0f - f);
        new_specular[3] = specular[3];
    }
}

FOGVOL_API fogvol_result fogvol_analytic_pack_uniforms(const fogvol_analytic_set *set, const float eye[3],
                                                       fogvol_fog_law law, fogvol_fog_mix mix,
                                                       float out[FOGVOL_ANALYTIC_UNIFORM_FLOATS])
{
    int n, v, j;
    if (!fogvol__an_args_ok(set, law, mix) || !eye || !out || !fogvol__finite_n(eye, 3))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    n = set->count < FOGVOL_ANALYTIC_MAX_VOLUMES ? set->count : FOGVOL_ANALYTIC_MAX_VOLUMES;
    memset(out, 0, FOGVOL_ANALYTIC_UNIFORM_FLOATS * sizeof(float));
    out[0] = eye[0], out[1] = eye[1], out[2] = eye[2], out[3] = (float)n;
    out[4] = (float)law, out[5] = (float)mix;
    for (v = 0; v < n; ++v) {
        float *u = out + 8 + 20 * v;
        for (j = 0; j < 12; ++j) u[j] = (float)set->map[v][j];
        u[12] = (float)set->color[v][0], u[13] = (float)set->color[v][1], u[14] = (float)set->color[v][2];
        u[15] = (float)set->density[v];
        u[16] = (float)set->shape[v];
    }
    return set->count > FOGVOL_ANALYTIC_MAX_VOLUMES ? FOGVOL_ERROR_UNSUPPORTED : FOGVOL_SUCCESS;
}

/* ---- GLSL ----
   The same maths in float, for every dialect: only constant-index expressions
   (loop indices) index arrays, loops have constant bounds, so GLSL ES 1.00
   fragment shaders accept it. The event list is sorted by a stable insertion
   sort (adjacent swaps) from the order entry(0), exit(0), entry(1), ... which
   gives the CPU's (t, event) order. Misses get t = 2 and sort to the end. */
static const char fogvol__an_glsl_segment[] =
    "#define FV_AN_MAX 8\n"
    "#ifndef FOGVOL_ANALYTIC_IN_BLOCK\n"       /* (Vulkan: a member of the engine's uniform block) */
    "uniform vec4 fv_analytic[2 + 5 * FV_AN_MAX];\n"
    "#endif\n"
    "vec2 fv_an_slab(vec2 t, float o, float v) {\n"
    "    if (v != 0.0) {\n"
    "        float a = (-1.0 - o) / v, b = (1.0 - o) / v;\n"
    "        return vec2(max(t.x, min(a, b)), min(t.y, max(a, b)));\n"
    "    }\n"
    "    return abs(o) <= 1.0 ? t : vec2(1.0, -1.0);\n"
    "}\n"
    "vec2 fv_an_segment(vec4 r0, vec4 r1, vec4 r2, float shape, vec3 e, vec3 d, float len) {\n"
    "    vec2 t = vec2(0.0, 1.0);\n"
    "    if (shape < 0.5) {\n"
    "        if (len <= 0.0) return vec2(1.0, -1.0);\n"
    "        return vec2(r0.x / len, r0.y > 0.0 ? min(r0.y / len, 1.0) : 1.0);\n"
    "    }\n"
    "    vec3 o = vec3(dot(r0.xyz, e) + r0.w, dot(r1.xyz, e) + r1.w, dot(r2.xyz, e) + r2.w);\n"
    "    vec3 v = vec3(dot(r0.xyz, d), dot(r1.xyz, d), dot(r2.xyz, d));\n"
    "    if (shape < 1.5) {\n"
    "        if (v.x > 0.0) t.x = max(-o.x / v.x, 0.0);\n"
    "        else if (v.x < 0.0) t.y = min(-o.x / v.x, 1.0);\n"
    "        else if (o.x < 0.0) t.y = -1.0;\n"
    "        return t;\n"
    "    }\n"
    "    if (shape > 3.5 && shape < 4.5) return fv_an_slab(fv_an_slab(fv_an_slab(t, o.x, v.x), o.y, v.y), o.z, v.z);\n"
    "    vec3 k = shape > 4.5 ? vec3(1.0, 1.0, 0.0) : vec3(1.0);\n"
    "    vec3 ok = o * k, vk = v * k, x = cross(ok, vk);\n"
    "    float a = dot(vk, vk), b = dot(ok, vk), c = dot(ok, ok) - 1.0, disc = a - dot(x, x);\n"
    "    if (a > 0.0) {\n"
    "        if (disc <= 0.0) return vec2(1.0, -1.0);\n"
    "        float s = sqrt(disc);\n"
    "        float q = -(b + (b >= 0.0 ? s : -s));\n"
    "        float r1 = q / a, r2 = c / q;\n"
    "        t = vec2(max(min(r1, r2), 0.0), min(max(r1, r2), 1.0));\n"
    "    } else if (c > 0.0) return vec2(1.0, -1.0);\n"
    "    return shape > 4.5 ? fv_an_slab(t, o.z, v.z) : t;\n"
    "}\n";
static const char fogvol__an_glsl_add[] =
    /* s = (fog or transmittance, cover, done, 0); cs = colour * density */
    "void fv_an_add(vec3 cs, float sig, float l, float law, inout vec4 s, inout vec3 num) {\n"
    "    float tau = sig * l;\n"
    "    if (tau <= 0.0 || s.z > 0.5) return;\n"
    "    if (law > 0.5 && law < 1.5) {\n"
    "        float e = exp(-tau);\n"
    "        float k = l * s.x * (tau < 1e-3 ? 1.0 - 0.5 * tau : (1.0 - e) / tau);\n"
    "        num += cs * k;\n"
    "        s.y += sig * k;\n"
    "        s.x *= e;\n"
    "        if (s.x < 1e-7) s.z = 1.0;\n"
    "    } else if (law < 0.5) {\n"
    "        float k = tau >= s.x ? s.x / tau : 1.0;\n"
    "        num += cs * (l * k);\n"
    "        s.y += tau * k;\n"
    "        s.x = tau >= s.x ? 0.0 : s.x - tau;\n"
    "        if (s.x <= 0.0) s.z = 1.0;\n"
    "    } else {\n"
    "        num = cs / sig * s.x + num * (1.0 - s.x);\n"
    "        s.x = max(s.x - min(tau, 1.0), 0.0);\n"
    "        if (s.x <= 0.0) s.z = 1.0;\n"
    "    }\n"
    "}\n"
    "void fogvol_fold_fog(inout vec4 diffuse, inout vec4 specular, float fog, vec3 color) {\n"
    "    diffuse.rgb *= fog;\n"
    "    specular.rgb = specular.rgb * fog + color * (1.0 - fog);\n"
    "}\n";
static const char fogvol__an_glsl_main[] =
    "void fogvol_analytic(vec3 p, out float fog, out vec3 color) {\n"
    "    vec3 e = fv_analytic[0].xyz;\n"
    "    float n = fv_analytic[0].w, law = fv_analytic[1].x;\n"
    "    bool sep = fv_analytic[1].y < 0.5;\n"
    "    vec3 d = p - e;\n"
    "    float len = length(d);\n"
    "    float kt[2 * FV_AN_MAX];\n"
    "    vec4 kc[2 * FV_AN_MAX];\n"
    "    float kl[2 * FV_AN_MAX];\n"
    "    for (int i = 0; i < FV_AN_MAX; ++i) {\n"
    "        vec4 cd = fv_analytic[5 * i + 5];\n"
    "        vec2 t = vec2(2.0);\n"
    "        if (float(i) < n) {\n"
    "            t = fv_an_segment(fv_analytic[5 * i + 2], fv_analytic[5 * i + 3], fv_analytic[5 * i + 4],\n"
    "                              fv_analytic[5 * i + 6].x, e, d, len);\n"
    "            if (!(t.y > t.x) || cd.w <= 0.0) t = vec2(2.0);\n"
    "        }\n"
    "        vec4 c = vec4(cd.rgb * cd.w, cd.w);\n"
    "        if (sep) {\n"
    "            kt[i] = t.x;\n"
    "            kc[i] = c;\n"
    "            kl[i] = (t.y - t.x) * len;\n"
    "            kt[i + FV_AN_MAX] = 2.0;\n"
    "            kc[i + FV_AN_MAX] = vec4(0.0);\n"
    "            kl[i + FV_AN_MAX] = 0.0;\n"
    "        } else {\n"
    "            kt[2 * i] = t.x;\n"
    "            kc[2 * i] = c;\n"
    "            kl[2 * i] = 1.0;\n"
    "            kt[2 * i + 1] = t.y;\n"
    "            kc[2 * i + 1] = -c;\n"
    "            kl[2 * i + 1] = -1.0;\n"
    "        }\n"
    "    }\n"
    "    for (int i = 1; i < 2 * FV_AN_MAX; ++i) {\n"
    "        for (int j = 0; j < 2 * FV_AN_MAX; ++j) {\n"
    "            if (j >= i || kt[i - j - 1] <= kt[i - j]) break;\n"
    "            float tt = kt[i - j - 1]; kt[i - j - 1] = kt[i - j]; kt[i - j] = tt;\n"
    "            vec4 tc = kc[i - j - 1]; kc[i - j - 1] = kc[i - j]; kc[i - j] = tc;\n"
    "            float tl = kl[i - j - 1]; kl[i - j - 1] = kl[i - j]; kl[i - j] = tl;\n"
    "        }\n"
    "    }\n"
    "    vec4 s = vec4(1.0, 0.0, 0.0, 0.0), acc = vec4(0.0);\n"
    "    vec3 num = vec3(0.0);\n"
    "    float open = 0.0, last = 0.0;\n"
    "    for (int i = 0; i < 2 * FV_AN_MAX; ++i) {\n"
    "        if (kt[i] > 1.5 || s.z > 0.5) break;\n"
    "        if (sep) {\n"
    "            fv_an_add(kc[i].rgb, kc[i].a, kl[i], law, s, num);\n"
    "        } else {\n"
    "            if (open > 0.5 && kt[i] > last) fv_an_add(acc.rgb, acc.a, (kt[i] - last) * len, law, s, num);\n"
    "            acc += kc[i];\n"
    "            open += kl[i];\n"
    "            if (open < 0.5) acc = vec4(0.0);\n"
    "            last = kt[i];\n"
    "        }\n"
    "    }\n"
    "    fog = s.x;\n"
    "    color = law > 1.5 ? num : (s.y > 0.0 ? num / s.y : vec3(0.0));\n"
    "}\n";
/* fogvol__an_decl_vulkan declares fv_analytic[42] */
typedef char fogvol__an_vk_block[FOGVOL_ANALYTIC_UNIFORM_VEC4S == 42 ? 1 : -1];
static const char *const fogvol__an_glsl[3] = {fogvol__an_glsl_segment, fogvol__an_glsl_add, fogvol__an_glsl_main};

static const char fogvol__an_vs_body[] =
    "FV_LOCATION(0) FV_ATTRIB vec3 fv_position;\n"
    "FV_UNIFORM(mat4, fv_mvp)\n"
    "FV_UNIFORM(mat4, fv_model)\n"
    "#ifdef FV_PER_PIXEL\n"
    "FV_LOCATION(0) FV_VARYING_OUT vec3 fv_world;\n"
    "#else\n"
    "FV_LOCATION(0) FV_VARYING_OUT vec4 fv_fog;\n"
    "#endif\n"
    "void main() {\n"
    "    vec4 p = vec4(fv_position, 1.0);\n"
    "    vec3 w = (fv_model * p).xyz;\n"
    "#ifdef FV_PER_PIXEL\n"
    "    fv_world = w;\n"
    "#else\n"
    "    float f;\n"
    "    vec3 c;\n"
    "    fogvol_analytic(w, f, c);\n"
    "    fv_fog = vec4(c, f);\n"
    "#endif\n"
    "    gl_Position = fv_mvp * p;\n"
    "}\n";

static const char fogvol__an_fs_body[] =
    "#ifdef FV_PER_PIXEL\n"
    "FV_LOCATION(0) FV_VARYING_IN vec3 fv_world;\n"
    "#else\n"
    "FV_LOCATION(0) FV_VARYING_IN vec4 fv_fog;\n"
    "#endif\n"
    "void main() {\n"
    "#ifdef FV_PER_PIXEL\n"
    "    float f;\n"
    "    vec3 c;\n"
    "    fogvol_analytic(fv_world, f, c);\n"
    "    FV_FRAGCOLOR = vec4(c, f);\n"
    "#else\n"
    "    FV_FRAGCOLOR = fv_fog;\n"
    "#endif\n"
    "}\n";

FOGVOL_API fogvol_result fogvol_analytic_shader_strings(fogvol_dialect dialect, fogvol_stage stage, int per_pixel,
                                                        const char **strings, int *count)
{
    const fogvol__dialect_info *di = fogvol__dialect(dialect);
    int n = 0;
    if (!strings || !count) return FOGVOL_ERROR_INVALID_ARGUMENT;
    *count = 0;
    if (!di) return FOGVOL_ERROR_UNSUPPORTED;
    if (stage != FOGVOL_STAGE_VERTEX && stage != FOGVOL_STAGE_FRAGMENT) return FOGVOL_ERROR_UNSUPPORTED;
    strings[n++] = di->version;
    n = fogvol__prelude(strings, n, stage == FOGVOL_STAGE_VERTEX ? di->an_vs : di->an_fs);
    strings[n++] = di->an_decl;
    if (per_pixel) strings[n++] = "#define FV_PER_PIXEL\n";
    if ((stage == FOGVOL_STAGE_VERTEX) != (per_pixel != 0)) {
        strings[n++] = fogvol__an_glsl[0];
        strings[n++] = fogvol__an_glsl[1];
        strings[n++] = fogvol__an_glsl[2];
    }
    strings[n++] = stage == FOGVOL_STAGE_VERTEX ? fogvol__an_vs_body : fogvol__an_fs_body;
    FOGVOL_ASSERT(n <= FOGVOL_MAX_SHADER_STRINGS);
    *count = n;
    return FOGVOL_SUCCESS;
}

FOGVOL_API int fogvol_analytic_snippet(const char **strings, int capacity)
{
    int i;
    for (i = 0; strings && i < capacity && i < 3; ++i) strings[i] = fogvol__an_glsl[i];
    return 3;
}

#endif /* FOGVOL_NO_ANALYTIC */

/* >>tiers ================================================================= */
/* What each tier can do: one row of fogvol__tiers per fogvol_tier, read by every question the library
   asks about a tier (fogvol_combination_supported, fogvol_msaa_supported, fogvol_tier_uses_program,
   fogvol_tier_costs, fogvol_shader_strings, the context's choice of tier and speed-ups, the frame's
   plan). A feature exists on a tier with a set of variants unless the set holds one of its bits in the
   row's off[] (FOGVOL__NEVER there: not on this tier) and it holds all of need[].
   To add a tier: its value in fogvol_tier, its row here, and the passes that differ in the >>passes
   section. To add a speed-up or feature: its FOGVOL__F_ value, its off[] entry in each row, the
   context's switch for it (>>context), its field in the frame's plan (fogvol__plan, filled by
   fogvol__plan_frame in >>end frame) and the one pass function that follows that field. */

enum {
    FOGVOL__F_ENCODE,         /* fogvol draws O itself with the ENCODE program (occluders, or the engine's depth) */
    FOGVOL__F_RESOLVE,        /* B - F is resolved into an encoded thickness T before the composite (PS13) */
    FOGVOL__F_CHECK,          /* the sums can saturate: overflow check passes (FOGVOL_PROGRAM_CHECK) */
    FOGVOL__F_DENSITY,        /* faces weighted by a volume's density texture */
    FOGVOL__F_LIGHT,          /* volume lights by compare (FOGVOL_PROGRAM_LIGHT) */
    FOGVOL__F_COLORS,         /* the one-pass colour group (FOGVOL_PROGRAM_COLOR_FACE, _COMPOSITE) */
    FOGVOL__F_MSAA,           /* per-sample rendering into a multisampled engine framebuffer */
    FOGVOL__F_ALU,            /* FOGVOL_SPEEDUP_ALU: FOGVOL_VARIANT_ALU added where the dialect takes it */
    FOGVOL__F_INLINE_RESOLVE, /* FOGVOL_SPEEDUP_INLINE_RESOLVE: the composite resolves B - F itself */
    FOGVOL__F_FLOAT_O,        /* FOGVOL_SPEEDUP_FLOAT_O: O is R32F (FOGVOL_SPECIALIZE_FLOAT_O) */
    FOGVOL__F_FETCH_O,        /* FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH: faces read O there (FOGVOL_SPECIALIZE_FETCH_O) */
    FOGVOL__F_EXACT_SUM,      /* FOGVOL_SPEEDUP_EXACT_SUM: 32-bit integer sums (FOGVOL_SPECIALIZE_EXACT_SUM) */
    FOGVOL__F_DEPTH_TEST,     /* FOGVOL_SPEEDUP_DEPTH_TEST: frames drawn as COUNT (FOGVOL_SPECIALIZE_COUNT) */
    FOGVOL__F_DOWNSAMPLE,     /* fogvol_frame_desc.downsample 2: the sums at half resolution */
    FOGVOL__F_ENGINE_TEST,    /* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: faces depth-tested against the engine's depth */
    FOGVOL__F_COUNT
};
#define FOGVOL__NEVER 0x80000000u /* in off[]: the tier has no such feature (no variant uses this bit) */

typedef struct fogvol__tier_row {
    const char *name;           /* fogvol_tier_name */
    const char *define;         /* its line in every program (fogvol_shader_strings) */
    unsigned char paper_passes; /* fogvol_tier_costs: as the white paper counts them */
    unsigned char passes;       /* passes fogvol issues for one group, no variant */
    unsigned char targets;      /* targets fogvol allocates, no variant */
    unsigned char modern;       /* needs a dialect with float targets, two outputs and texelFetch */
    unsigned char borrow;       /* RGBA8 sums: the decode's alpha digit borrows (PS13 resolves without) */
    fogvol_format sum_format;   /* the format of the face sums (RGBA8: encoded digits) */
    unsigned caps;              /* backend caps (FOGVOL_CAP_*) it needs */
    unsigned auto_caps;         /* ... for FOGVOL_TIER_AUTO to choose it */
    unsigned variants;          /* the variants it takes */
    unsigned modern_variants;   /* ... those of them that need a modern dialect */
    unsigned int_variants;      /* ... and those that need highp integers (GLSL 330, 300 es) */
    unsigned off[FOGVOL__F_COUNT], need[FOGVOL__F_COUNT];
} fogvol__tier_row;

/* (S single target, C count, A ALU, N near clamp, E engine depth, W wide, K colours) */
#define FOGVOL__S FOGVOL_VARIANT_SINGLE_TARGET
#define FOGVOL__C FOGVOL_VARIANT_COUNT
#define FOGVOL__A FOGVOL_VARIANT_ALU
#define FOGVOL__N FOGVOL_VARIANT_NEAR_CLAMP
#define FOGVOL__E FOGVOL_VARIANT_ENGINE_DEPTH
#define FOGVOL__W FOGVOL_VARIANT_WIDE
#define FOGVOL__K FOGVOL_VARIANT_COLORS
#define FOGVOL__X FOGVOL__NEVER
static const fogvol__tier_row fogvol__tiers[FOGVOL_TIER_COUNT] = {
    {"auto", "", 0, 0, 0, 0, 0, FOGVOL_FORMAT_RGBA8, 0, 0, 0, 0, 0,
     {FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X,
      FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__X},
     {0}},
    /* PS13: O, B, F, T resolved, composite; lowp/mediump (texture ramps, per-channel compare) */
    {"PS13", "#define FV_PS13\n", 6, 5, 4, 0, 0, FOGVOL_FORMAT_RGBA8, 0, 0, FOGVOL__C | FOGVOL__A | FOGVOL__N, 0,
     FOGVOL__A,
     /*       ENCODE RESOLVE CHECK DENSITY LIGHT COLORS MSAA                 ALU */
     {0, 0, 0, FOGVOL__X, FOGVOL__X, FOGVOL__X, FOGVOL__W | FOGVOL__K, FOGVOL__W,
      /* INLINE_RESOLVE FLOAT_O                          FETCH_O */
      0, FOGVOL__W | FOGVOL__E | FOGVOL__C, FOGVOL__C | FOGVOL__W | FOGVOL__K,
      /* EXACT_SUM                                                     DEPTH_TEST */
      FOGVOL__W | FOGVOL__E | FOGVOL__C | FOGVOL__S | FOGVOL__K, FOGVOL__C | FOGVOL__S | FOGVOL__W | FOGVOL__E | FOGVOL__K,
      /* DOWNSAMPLE ENGINE_TEST */
      FOGVOL__X, FOGVOL__X},
     {0}},
    /* PS20: O, B, F, composite */
    {"PS20", "", 5, 4, 3, 0, 1, FOGVOL_FORMAT_RGBA8, 0, FOGVOL_CAP_HIGHP_FRAGMENT,
     FOGVOL__S | FOGVOL__C | FOGVOL__A | FOGVOL__N | FOGVOL__E | FOGVOL__W, FOGVOL__E, 0,
     {0, FOGVOL__X, 0, FOGVOL__C | FOGVOL__W, FOGVOL__W, FOGVOL__X, FOGVOL__W | FOGVOL__K, FOGVOL__W, FOGVOL__X,
      FOGVOL__W | FOGVOL__C, FOGVOL__C | FOGVOL__W | FOGVOL__K,
      FOGVOL__W | FOGVOL__C | FOGVOL__S | FOGVOL__K, FOGVOL__C | FOGVOL__S | FOGVOL__W | FOGVOL__E | FOGVOL__K,
      FOGVOL__X, FOGVOL__X},
     {0}},
    /* MRT: the engine writes O as a second output of its opaque pass; B, F, composite */
    {"MRT", "", 4, 3, 3, 1, 1, FOGVOL_FORMAT_RGBA8, FOGVOL_CAP_MRT, FOGVOL_CAP_MRT, FOGVOL__S | FOGVOL__A | FOGVOL__N, 0, 0,
     {FOGVOL__X, FOGVOL__X, 0, FOGVOL__C | FOGVOL__W, FOGVOL__W, FOGVOL__X, FOGVOL__X, FOGVOL__W, FOGVOL__X,
      FOGVOL__W | FOGVOL__E | FOGVOL__C, FOGVOL__C | FOGVOL__W | FOGVOL__K,
      FOGVOL__W | FOGVOL__E | FOGVOL__C | FOGVOL__S | FOGVOL__K, FOGVOL__X, FOGVOL__X, FOGVOL__X},
     {0}},
    /* FLOAT: O (or the engine's depth texture), one signed pass for every face, composite */
    {"FLOAT", "#define FV_FLOAT\n", 3, 3, 2, 1, 0, FOGVOL_FORMAT_R32F, FOGVOL_CAP_FLOAT_BLEND, FOGVOL_CAP_FLOAT_BLEND,
     FOGVOL__N | FOGVOL__E | FOGVOL__K, 0, 0,
     {FOGVOL__E, FOGVOL__X, FOGVOL__X, 0, 0, 0, FOGVOL__W | FOGVOL__K, FOGVOL__X, FOGVOL__X, FOGVOL__X,
      FOGVOL__C | FOGVOL__W | FOGVOL__K | FOGVOL__E, FOGVOL__X, FOGVOL__X, FOGVOL__E | FOGVOL__K,
      /* ENGINE_TEST: needs E */
      FOGVOL__K | FOGVOL__N},
     {0, 0, 0, 0, 0, FOGVOL__K, 0, 0, 0, 0, 0, 0, 0, 0, FOGVOL__E}}};
#undef FOGVOL__S
#undef FOGVOL__C
#undef FOGVOL__A
#undef FOGVOL__N
#undef FOGVOL__E
#undef FOGVOL__W
#undef FOGVOL__K
#undef FOGVOL__X

/* Variants that cannot go together on any tier, and what a variant needs of every tier's backend. */
static const unsigned fogvol__variant_conflicts[][2] = {
    {FOGVOL_VARIANT_SINGLE_TARGET, FOGVOL_VARIANT_COUNT},
    {FOGVOL_VARIANT_WIDE, FOGVOL_VARIANT_SINGLE_TARGET | FOGVOL_VARIANT_COUNT},
    {FOGVOL_VARIANT_ENGINE_DEPTH, FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_WIDE}};
#define FOGVOL__TWO_OUTPUTS FOGVOL_VARIANT_WIDE /* variants whose programs write two colour outputs */

/* The row of a tier; NULL for values out of range. */
static const fogvol__tier_row *fogvol__tier(fogvol_tier tier)
{
    if ((int)tier < 0 || (int)tier >= FOGVOL_TIER_COUNT) return NULL;
    return &fogvol__tiers[tier];
}

/* Whether feature f (FOGVOL__F_*) exists on the tier with variants v. */
static int fogvol__tier_has(fogvol_tier tier, unsigned v, int f)
{
    const fogvol__tier_row *t = fogvol__tier(tier);
    return t && !(t->off[f] & (v | FOGVOL__NEVER)) && (t->need[f] & v) == t->need[f];
}

FOGVOL_API const char *fogvol_tier_name(fogvol_tier tier)
{
    const fogvol__tier_row *t = fogvol__tier(tier);
    return t ? t->name : "invalid";
}

/* GLSL 330, 300 es and Vulkan's 450 guarantee highp integers and bit operations (PS13's integer ALU
   encode) */
static int fogvol__dialect_integers(fogvol_dialect dialect)
{
    return dialect == FOGVOL_GLSL_330 || dialect == FOGVOL_GLSL_300ES || dialect == FOGVOL_GLSL_VULKAN;
}

FOGVOL_API fogvol_result fogvol_combination_supported(fogvol_tier tier, unsigned v, fogvol_dialect dialect)
{
    const fogvol__dialect_info *di = fogvol__dialect(dialect);
    const fogvol__tier_row *t = fogvol__tier(tier);
    size_t i;
    if (!di || !t || tier == FOGVOL_TIER_AUTO || (v & ~t->variants)) return FOGVOL_ERROR_UNSUPPORTED;
    for (i = 0; i < sizeof fogvol__variant_conflicts / sizeof fogvol__variant_conflicts[0]; ++i)
        if ((v & fogvol__variant_conflicts[i][0]) && (v & fogvol__variant_conflicts[i][1]))
            return FOGVOL_ERROR_UNSUPPORTED;
    if (di->legacy && (t->modern || (v & t->modern_variants))) return FOGVOL_ERROR_UNSUPPORTED;
    if ((v & t->int_variants) && !fogvol__dialect_integers(dialect)) return FOGVOL_ERROR_UNSUPPORTED;
    if ((v & FOGVOL__TWO_OUTPUTS) && di->outputs < 2) return FOGVOL_ERROR_UNSUPPORTED; /* GLES2: one output */
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_msaa_supported(fogvol_tier tier, unsigned v, fogvol_dialect dialect)
{
    if (!fogvol__dialect(dialect) || !fogvol__dialect(dialect)->version_msaa) return FOGVOL_ERROR_UNSUPPORTED;
    if (fogvol_combination_supported(tier, v, dialect) != FOGVOL_SUCCESS) return FOGVOL_ERROR_UNSUPPORTED;
    return fogvol__tier_has(tier, v, FOGVOL__F_MSAA) ? FOGVOL_SUCCESS : FOGVOL_ERROR_UNSUPPORTED;
}

FOGVOL_API int fogvol_tier_uses_program(fogvol_tier tier, unsigned v, fogvol_program program)
{
    /* the feature each program belongs to; -1: every tier's */
    static const signed char feature[FOGVOL_PROGRAM_COUNT] = {
        FOGVOL__F_ENCODE, -1, -1, -1, FOGVOL__F_RESOLVE, FOGVOL__F_CHECK, FOGVOL__F_LIGHT, FOGVOL__F_COLORS,
        FOGVOL__F_COLORS};
    if ((int)program < 0 || (int)program >= FOGVOL_PROGRAM_COUNT || !fogvol__tier(tier) || tier == FOGVOL_TIER_AUTO)
        return 0;
    return feature[program] < 0 || fogvol__tier_has(tier, v, feature[program]);
}

FOGVOL_API fogvol_result fogvol_tier_costs(fogvol_tier tier, unsigned v, fogvol_tier_info *out)
{
    const fogvol__tier_row *t = fogvol__tier(tier);
    /* a tier that draws O itself, in a variant that does not (FLOAT + ENGINE_DEPTH): no O pass, no O */
    int no_o = t && t->off[FOGVOL__F_ENCODE] != FOGVOL__NEVER && !fogvol__tier_has(tier, v, FOGVOL__F_ENCODE);
    if (!out) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    out->name = fogvol_tier_name(tier);
    if (!t || tier == FOGVOL_TIER_AUTO) return FOGVOL_ERROR_INVALID_ARGUMENT;
    out->paper_passes = t->paper_passes;
    out->library_passes = t->passes - no_o;
    out->targets = t->targets - no_o - ((v & FOGVOL_VARIANT_SINGLE_TARGET) ? 1 : 0); /* (S: no F) */
    return FOGVOL_SUCCESS;
}

/* >>shaders =============================================================== */
/* The GLSL of every program: one body per program, the dialect's prelude (>>dialects) and the
   defines of the tier, variant and specialisation in front; the snippets engines paste in. */

/* One body per program, written with small compatibility macros; one prelude
   per dialect defines FV_ATTRIB, FV_VARYING_OUT (vertex), FV_VARYING_IN,
   FV_TEXTURE, FV_FRAGCOLOR (fragment). Tiers and variants select code with
   #defines: FV_PS13, FV_FLOAT, FV_SINGLE, FV_COUNT, FV_ALU, FV_NEAR_CLAMP,
   FV_ENGINE_DEPTH (FV_NORMALIZE follows from PS13 and COUNT). */

/* FV_MSAA: fogvol's targets are sampler2DMS (FV_TARGET_SAMPLER); FV_TEXTURE
   overloads on the sampler type, so a target read fetches this fragment's
   own sample and the ramps keep their filtered lookups. The engine's depth
   (ENGINE_DEPTH) is a multisample texture too, read at this sample. */
static const char fogvol__fs_msaa[] =
    "#define FV_MSAA\n"
    "#define FV_TARGET_SAMPLER sampler2DMS\n"
    "#define FV_ENGINE_Z(s) texelFetch(s, FV_ENGINE_TEXEL, gl_SampleID).r\n"
    "vec4 fv_tex(sampler2D s, vec2 st) { return texture(s, st); }\n"
    "vec4 fv_tex(sampler2DMS s, vec2 st) {\n"
    "    return texelFetch(s, ivec2(floor(st * vec2(textureSize(s)))), gl_SampleID);\n"
    "}\n"
    "#undef FV_TEXTURE\n"
    "#define FV_TEXTURE fv_tex\n";

static const char *const fogvol__variant_define[] = {"#define FV_SINGLE\n", "#define FV_COUNT\n",
                                                      "#define FV_ALU\n", "#define FV_NEAR_CLAMP\n",
                                                      "#define FV_ENGINE_DEPTH\n", "#define FV_WIDE\n",
                                                      "#define FV_COLORS\n"};

#define FOGVOL__VARIANT_COUNT (int)(sizeof fogvol__variant_define / sizeof fogvol__variant_define[0])

/* one #define per bit of FOGVOL_VARIANT_ALL */
typedef char fogvol__variant_defines_match[FOGVOL_VARIANT_ALL == (1u << FOGVOL__VARIANT_COUNT) - 1u ? 1 : -1];

/* Mesh vertex shader: clip position and normalised depth d = (w - near) /
   (far - near). With fv_misc.y = 1 clip z is replaced by k*d - w: the near
   plane still clips exactly (d >= 0) and nothing is clipped at the far plane.
   NEAR_CLAMP snaps vertices behind the near plane onto it instead (Baker). */
static const char fogvol__vs_mesh[] =
    "FV_LOCATION(0) FV_ATTRIB vec3 fv_position;\n"
    "FV_UNIFORM(mat4, fv_mvp)\n"
    "FV_UNIFORM(vec4, fv_depth)\n"
    "FV_UNIFORM(vec4, fv_misc)\n"
    "FV_LOCATION(0) FV_VARYING_OUT float fv_d;\n"
    "#ifdef FV_DENSITY\n"                        /* density texture coordinates from the model-space position */
    "FV_UNIFORM(vec4, fv_dens_u)\n"
    "FV_UNIFORM(vec4, fv_dens_v)\n"
    "FV_LOCATION(1) FV_VARYING_OUT vec2 fv_dtc;\n"
    "#endif\n"
    "void main() {\n"
    "    vec4 p = vec4(fv_position, 1.0);\n"
    "    vec4 c = fv_mvp * p;\n"
    "#ifdef FV_DENSITY\n"
    "    fv_dtc = vec2(dot(fv_dens_u, p), dot(fv_dens_v, p));\n"
    "#endif\n"
    "    float d = dot(fv_depth, p);\n"
    "#ifdef FV_NEAR_CLAMP\n"
    "    if (fv_misc.w > 0.5) {\n"
    "        d = max(d, 0.0);\n"
    "        c.w = max(c.w, fv_misc.z);\n"
    "        c.z = max(c.z, -c.w);\n"
    "    }\n"
    "#endif\n"
    "    fv_d = d;\n"
    "    c.z = mix(c.z, d * fv_misc.x - c.w, fv_misc.y);\n"
    "#ifdef FV_VULKAN\n"                          /* clip z in [0, w]: the same window depth */
    "    c.z = 0.5 * (c.z + c.w);\n"
    "#endif\n"
    "    gl_Position = c;\n"
    "}\n";

static const char fogvol__vs_fullscreen[] =
    "FV_LOCATION(0) FV_ATTRIB vec3 fv_position;\n"
    "void main() {\n"
    "    gl_Position = vec4(fv_position.xy, 0.0, 1.0);\n"
    "}\n";

/* Shared fragment code: uniforms, the RGB encode (ramps or ALU, same bytes),
   the borrow fold (normalised digits, alpha free), screen coordinates. */
static const char fogvol__fs_common[] =
    "#ifndef FV_TARGET_SAMPLER\n#define FV_TARGET_SAMPLER sampler2D\n#endif\n"
    "FV_UNIFORM(vec4, fv_enc)\n"    /* (N, N^2, depth offset, depth max) */
    "FV_UNIFORM(vec4, fv_dith)\n"   /* (255 or 0, 1/D, D, the frame's row offset) */
    "FV_UNIFORM(vec4, fv_screen)\n"
    "FV_UNIFORM(vec4, fv_dec)\n"
    /* FV_PIXEL: the pixel of fogvol's targets; FV_ENGINE_TEXEL: the texel of the engine's depth
       texture (fv_nf.zw: the viewport's origin, declared by the programs that read it); FV_ORIGIN
       (SPECIALIZE_ORIGIN, the viewport at the window origin): both offsets 0, left out */
    "#ifdef FV_ORIGIN\n#define FV_PIXEL gl_FragCoord.xy\n#define FV_ENGINE_TEXEL ivec2(gl_FragCoord.xy)\n#else\n"
    "#define FV_PIXEL (gl_FragCoord.xy + fv_screen.zw)\n"
    "#define FV_ENGINE_TEXEL ivec2(gl_FragCoord.xy + fv_nf.zw)\n#endif\n"
    /* FV_ENGINE_Z(s): the engine's window depth at this pixel (FV_MSAA: at this sample) */
    "#ifndef FV_ENGINE_Z\n#define FV_ENGINE_Z(s) texelFetch(s, FV_ENGINE_TEXEL, 0).r\n#endif\n"
    "vec2 fv_st() { return FV_PIXEL * fv_screen.xy; }\n"
    /* FV_SCREEN(s): fogvol's target s at this pixel; texelFetch where the dialect has it */
    "#if __VERSION__ >= 130 && !defined(FV_MSAA) && !defined(FV_NO_FETCH)\n"
    "#define FV_SCREEN(s) texelFetch(s, ivec2(FV_PIXEL), 0)\n"
    "#else\n"
    "#define FV_SCREEN(s) FV_TEXTURE(s, fv_st())\n"
    "#endif\n"
    /* view depth (distance along the view axis) of an engine depth-buffer sample: st in [0,1]
       across the engine viewport, z its window depth; fv_lin / fv_lin2 hold the inverse
       view-projection rows with the window -> NDC mapping (depth range, clip control) folded in */
    "FV_UNIFORM(vec4, fv_lin)\n"
    "FV_UNIFORM(vec4, fv_lin2)\n"
    "float fv_engine_view_depth(vec2 st, float z) {\n"
    "#ifdef FV_DEPTH_FROM_Z\n"                 /* fv_lin.xy = fv_lin2.xy = 0 (no oblique near plane) */
    "    return (fv_lin.z * z + fv_lin.w) / (fv_lin2.z * z + fv_lin2.w);\n"
    "#else\n"
    "    vec4 q = vec4(st, z, 1.0);\n"
    "    return dot(fv_lin, q) / dot(fv_lin2, q);\n"
    "#endif\n"
    "}\n";

/* The RGBA8 encode in integers, shared by fogvol's programs (FV_IALU) and the engine's MRT and
   occluder snippets, where the dialect has floatBitsToInt and bit operations (GLSL 330+, 300 es): N
   and D are powers of two, so every division is a shift, every mod a mask (the same bytes as the
   float arithmetic, with about a third of its operations).
   fogvol_dither_scaled(D): (v D) >> 6, v the 8x8 index of fogvol_make_dither_index (bits 5..0: x0
   y0 x1 y1 x2 y2 of x = px ^ py, y = py); (b * 73) & 0x54 puts bits 0, 1, 2 of b at 6, 4, 2, so the
   two spread 3-bit values make 4 v.
   fogvol_encode_int: the digits of t = floor(u N^3 D) (u < 1, N = 2^ln, D = 2^ld) with the dither
   offset k added below the blue digit: h = t / (N D) < N^2 gives red and green; q in [-1, N - 1] is
   the blue digit, q & (N - 1) is q + N for the borrow (q = -1), whose flag is the sign bit. */
#define FOGVOL__IALU_TEXT \
    "highp int fogvol_log2i(float p) { return (floatBitsToInt(p) >> 23) - 127; }\n" \
    "highp int fogvol_dither_scaled(highp int dd) {\n" \
    "    highp ivec2 p = ivec2(gl_FragCoord.xy) & 7;\n" \
    "    highp ivec2 s = (ivec2(p.x ^ p.y, p.y) * 73) & 0x54;\n" \
    "    return (((s.x << 1) | s.y) * dd) >> 8;\n" \
    "}\n" \
    "vec4 fogvol_encode_int(highp int t, highp int ln, highp int ld, highp int k) {\n" \
    "    highp int n = 1 << ln, h = t >> (ln + ld), q = (((t & ((n << ld) - 1)) + k) >> ld) - 1;\n" \
    "    return vec4(ivec4(h >> ln, h & (n - 1), q & (n - 1), (q >> 31) & 1)) * (1.0 / 255.0);\n" \
    "}\n"

/* The RGBA8 tiers' encode (lookup textures or ALU, the dither) and the borrow fold: the second
   string of the shared fragment code (one string would pass the 4095 characters C99 guarantees). */
static const char fogvol__fs_encode_common[] =
    /* O as stored (FLOAT: d; RGBA8: digits); FV_O_FLOAT (SPECIALIZE_FLOAT_O): an R32F O, encoded
       as the engine's snippet or the O pass would have */
    "#ifdef FV_O_FLOAT\n#define FV_O_DIGITS(s) fv_encode(FV_SCREEN(s).r)\n"
    "#else\n#define FV_O_DIGITS(s) FV_SCREEN(s)\n#endif\n"
    "#if !defined(FV_FLOAT)\n"
    /* FV_N, FV_DD: the digit base N and the dither steps D; FV_ENC_* (SPECIALIZE_ENCODING): the
       context's encoding compiled in, so the encode's arithmetic on them folds at compile time */
    "#ifdef FV_ENC_LN\n#define FV_N FV_ENC_N\n#define FV_DD FV_ENC_D\n#define FV_RDD (1.0 / FV_ENC_D)\n"
    "#else\n#define FV_N fv_enc.x\n#define FV_DD fv_dith.z\n#define FV_RDD fv_dith.y\n#endif\n"
    "FV_BINDING(2) uniform sampler2D fv_dither;\n"
    "#ifndef FV_ALU\n"
    "FV_BINDING(0) uniform sampler2D fv_rg;\n"
    "FV_BINDING(1) uniform sampler2D fv_blue;\n"
    "#endif\n"
    /* FV_IALU: the ALU encode in integers (FOGVOL__IALU_TEXT) */
    "#if defined(FV_ALU) && (__VERSION__ >= 330 || (defined(GL_ES) && __VERSION__ >= 300))\n"
    "#define FV_IALU\n"
    "#ifdef FV_ENC_LN\n#define FV_DD_I (1 << FV_ENC_LD)\n#else\n#define FV_DD_I int(fv_dith.z)\n#endif\n"
    FOGVOL__IALU_TEXT
    "float fv_dither_row() {\n"
    "    highp int dd = FV_DD_I;\n"
    "    return fv_dith.x > 0.5 ? float((fogvol_dither_scaled(dd) + (dd >> 1) + int(fv_dith.w)) & (dd - 1)) : 0.0;\n"
    "}\n"
    /* the encode's offset (row + D/2) mod D = ((v D) >> 6) + the frame's offset (the dither off: D/2) */
    "highp int fv_dither_offset_i() {\n"
    "#ifdef FV_DITHER_ON\n"                       /* SPECIALIZE_DITHER: fv_dith.x = 255 */
    "    return (fogvol_dither_scaled(FV_DD_I) + int(fv_dith.w)) & (FV_DD_I - 1);\n"
    "#else\n"
    "    return fv_dith.x > 0.5 ? (fogvol_dither_scaled(FV_DD_I) + int(fv_dith.w)) & (FV_DD_I - 1) : FV_DD_I >> 1;\n"
    "#endif\n"
    "}\n"
    "#elif defined(FV_ALU)\n"                 /* the row of fogvol_make_dither_index, by arithmetic */
    "float fv_dither_row() {\n"
    "    vec2 p = mod(floor(gl_FragCoord.xy), 8.0);\n"
    "    vec2 b0 = mod(p, 2.0), b1 = mod(floor(p * 0.5), 2.0), b2 = mod(floor(p * 0.25), 2.0);\n"
    "    float v = abs(b0.x - b0.y) * 32.0 + b0.y * 16.0 + abs(b1.x - b1.y) * 8.0 + b1.y * 4.0 +\n"
    "              abs(b2.x - b2.y) * 2.0 + b2.y;\n"    /* 8x8 Bayer index by bit interleaving */
    "    float dd = FV_DD;\n"
    "    return fv_dith.x > 0.5 ? mod(floor(v * dd / 64.0) + floor(dd * 0.5) + fv_dith.w, dd) : 0.0;\n"
    "}\n"
    "#else\n"
    "float fv_dither_row() {\n"
    "    return mod(floor(FV_TEXTURE(fv_dither, gl_FragCoord.xy * 0.125).r * fv_dith.x + 0.5) + fv_dith.w, FV_DD);\n"
    "}\n"
    "#endif\n"
    "vec4 fv_encode(float d) {\n"
    "    float u = clamp(d, 0.0, fv_enc.w) + fv_enc.z;\n"
    "#ifdef FV_IALU\n"                          /* t: the blue-ramp texel count floor(u N^3 D) */
    "#ifdef FV_ENC_LN\n"
    "    const highp int ln = FV_ENC_LN, ld = FV_ENC_LD;\n"
    "#else\n"
    "    highp int ln = fogvol_log2i(fv_enc.x), ld = fogvol_log2i(fv_dith.z);\n"
    "#endif\n"
    "    highp int t = int(u * (FV_N * FV_N * FV_N * FV_DD));\n" /* powers of two: exact either way */
    "    return fogvol_encode_int(t, ln, ld, fv_dither_offset_i());\n"
    "#else\n"
    "    float row = fv_dither_row();\n"
    "#ifdef FV_ALU\n"
    "    float n = FV_N, dd = FV_DD;\n"
    "    float t = u * n * n * n;\n"            /* blue LSBs; scaling by powers of two is exact */
    "    float h = floor(t / n);\n"
    "    float x = mod(floor(t * dd), n * dd);\n"   /* the blue-ramp texel */
    "    float q = floor((x + mod(row + dd * 0.5, dd)) / dd) - 1.0;\n"
    "    float a = q < 0.0 ? 1.0 : 0.0;\n"
    "    return vec4(mod(floor(h / n), n), mod(h, n), q + a * n, a) * (1.0 / 255.0);\n"
    "#else\n"
    "    vec4 rg = FV_TEXTURE(fv_rg, vec2(u, u * FV_N));\n"
    "    vec4 b = FV_TEXTURE(fv_blue, vec2(u * (FV_N * FV_N), (row + 0.5) * FV_RDD));\n"
    "    return rg + b;\n"
    "#endif\n"
    "#endif\n"
    "}\n"
    "#if defined(FV_PS13) || defined(FV_COUNT)\n"
    "#define FV_NORMALIZE\n"
    "#endif\n"
    "#ifdef FV_WIDE\n"                            /* six digits: V = floor(u N^6 + threshold), no borrow */
    "void fv_encode_wide(float d, out vec4 hi, out vec4 lo) {\n"
    "    float n = FV_N, n3 = FV_N * FV_N * FV_N, dd = FV_DD;\n"
    "    float row = fv_dither_row();\n"
    "    float v = floor(clamp(d, 0.0, fv_enc.w) * n3 * n3 + mod(row + dd * 0.5, dd) / dd);\n"
    "    float a = floor(v / n3), b = v - a * n3;\n"
    "    hi = vec4(floor(a / (n * n)), mod(floor(a / n), n), mod(a, n), 0.0) * (1.0 / 255.0);\n"
    "    lo = vec4(floor(b / (n * n)), mod(floor(b / n), n), mod(b, n), 0.0) * (1.0 / 255.0);\n"
    "}\n"
    "#endif\n"
    "vec4 fv_normalize(vec4 e) {\n"                /* fold the borrow: digits R, G, B in [0, N-1], alpha 0 */
    "    float g = e.g - e.a;\n"
    "    float c = g < -0.5 / 255.0 ? 1.0 : 0.0;\n"
    "    vec4 r = vec4(e.r - c / 255.0, g + c * FV_N / 255.0, e.b, 0.0);\n"
    "    return r.r < -0.5 / 255.0 ? vec4(0.0) : r;\n"
    "}\n"
    "#endif\n";

static const char fogvol__fs_encode[] =
    "#ifdef FV_ENGINE_DEPTH\n"                   /* PS20: O from the engine's depth, full-screen */
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "FV_UNIFORM(vec4, fv_nf)\n"
    "void main() {\n"
    "    float depth = FV_ENGINE_Z(fv_opaque);\n"
    "    float d = fv_engine_view_depth(fv_st(), depth) * fv_nf.x + fv_nf.y;\n"
    "#ifdef FV_O_FLOAT\n"                        /* an R32F O: d itself, as the occluders' O pass writes */
    "    FV_FRAGCOLOR = vec4(clamp(d, 0.0, 1.0), 0.0, 0.0, 0.0);\n"
    "#else\n"
    "    FV_FRAGCOLOR = fv_encode(d);\n"
    "#endif\n"
    "}\n"
    "#else\n"
    "FV_LOCATION(0) FV_VARYING_IN float fv_d;\n"
    "void main() {\n"
    "#if defined(FV_WIDE)\n"
    "    vec4 hi, lo;\n"
    "    fv_encode_wide(fv_d, hi, lo);\n"
    "    FV_OUT0 = hi;\n"
    "    FV_OUT1 = lo;\n"
    "#elif defined(FV_FLOAT) || defined(FV_O_FLOAT)\n" /* (FV_O_FLOAT: PS20 with an R32F O) */
    "    FV_FRAGCOLOR = vec4(clamp(fv_d, 0.0, 1.0), 0.0, 0.0, 0.0);\n"
    "#elif defined(FV_NORMALIZE)\n"
    "    FV_FRAGCOLOR = fv_normalize(fv_encode(fv_d));\n"
    "#else\n"
    "    FV_FRAGCOLOR = fv_encode(fv_d);\n"
    "#endif\n"
    "}\n"
    "#endif\n";

/* Volume faces. RGBA8: keep the lesser of face and opaque depth (a decoded
   compare, or PS13's per-channel saturated compare on normalised digits), or
   with COUNT rely on the depth test and count faces in alpha. FLOAT: signed
   depth of every face in one pass, the sign from gl_FrontFacing. */
static const char fogvol__fs_face[] =
    "FV_LOCATION(0) FV_VARYING_IN float fv_d;\n"
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "#ifdef FV_FETCH_O\n" /* O from the framebuffer (FOGVOL_SPECIALIZE_FETCH_O) */
    "#define FV_OREAD(s) fv_ofb\n"
    "#undef FV_O_DIGITS\n"
    "#ifdef FV_O_FLOAT\n#define FV_O_DIGITS(s) fv_encode(fv_ofb.r)\n#else\n#define FV_O_DIGITS(s) fv_ofb\n#endif\n"
    "#else\n"
    "#define FV_OREAD(s) FV_SCREEN(s)\n"
    "#endif\n"
    "#ifdef FV_DENSITY\n"                        /* v = c + rho (min(d, o) - c), c = min(o, fv_dens.x) */
    "FV_BINDING(6) uniform sampler2D fv_density;\n"
    "FV_UNIFORM(vec4, fv_dens)\n"
    "FV_LOCATION(1) FV_VARYING_IN vec2 fv_dtc;\n"
    "float fv_density_apply(float d, float o) {\n"
    "    return mix(min(o, fv_dens.x), d, FV_TEXTURE(fv_density, fv_dtc).r);\n"
    "}\n"
    "#endif\n"
    "#ifdef FV_FLOAT\n"
    "FV_UNIFORM(float, fv_sign)\n"
    "FV_UNIFORM(vec4, fv_nf)\n"
    "FV_UNIFORM(vec4, fv_speed)\n"
    "void main() {\n"
    "#if defined(FV_ENGINE_TEST)\n"             /* depth-tested against the engine's depth: nothing read */
    "    vec2 v = vec2(max(fv_d, 0.0) * fv_sign, fv_sign);\n"
    "    FV_FRAGCOLOR = vec4(gl_FrontFacing ? -v : v, 0.0, 0.0);\n"
    "}\n"
    "#else\n"
    "#ifdef FV_ENGINE_DEPTH\n"
    "    float z = FV_ENGINE_Z(fv_opaque);\n"
    "    float o = fv_engine_view_depth(fv_st(), z) * fv_nf.x + fv_nf.y;\n"
    "#else\n"
    "    float o = 1.0;\n"                     /* fv_speed.x = 1: no opaque depth, O is the far plane */
    "#if defined(FV_OPAQUE)\n"
    "    o = FV_OREAD(fv_opaque).r;\n"
    "#elif !defined(FV_NO_OPAQUE)\n"
    "    if (fv_speed.x < 0.5) o = FV_OREAD(fv_opaque).r;\n"
    "#endif\n"
    "#endif\n"
    "    float d = min(max(fv_d, 0.0), o);\n"
    "#ifdef FV_DENSITY\n"
    "    if (fv_dens.y > 0.5) d = fv_density_apply(d, o);\n"
    "#endif\n"
    "    FV_FRAGCOLOR = vec4(gl_FrontFacing ? -d * fv_sign : d * fv_sign, 0.0, 0.0, 0.0);\n"
    "}\n"
    "#endif\n"
    "#elif defined(FV_WIDE)\n"
    "FV_BINDING(4) uniform sampler2D fv_opaque2;\n"
    "void main() {\n"
    "    vec4 hi, lo, ohi = FV_SCREEN(fv_opaque), olo = FV_SCREEN(fv_opaque2);\n"
    "    fv_encode_wide(fv_d, hi, lo);\n"
    "    bool behind = dot(hi - ohi, fv_dec) + dot(lo - olo, fv_dec) / (fv_enc.x * fv_enc.y) >= 0.0;\n"
    "    FV_OUT0 = behind ? ohi : hi;\n"
    "    FV_OUT1 = behind ? olo : lo;\n"
    "}\n"
    ;

/* (the face program's second string: C99 compilers need take no string over 4095 characters) */
static const char fogvol__fs_face_rgba8[] =
    "#elif defined(FV_XSUM)\n" /* FOGVOL_SPECIALIZE_EXACT_SUM: the pixel as a 32-bit integer, +- d 2^24 */
    "FV_UNIFORM(float, fv_sign)\n"
    "void main() {\n"
    "    float d = clamp(fv_d, 0.0, 1.0);\n"
    "#ifndef FV_NO_OPAQUE\n"
    "    d = min(d, FV_OREAD(fv_opaque).r);\n"
    "#endif\n"
    "    highp uint q = uint(d * 16777216.0 + 0.5);\n" /* (GLSL ES: ints are mediump by default) */
    "    highp uvec4 c = uvec4(FV_FRAGCOLOR * 255.0 + 0.5);\n"
    "    highp uint u = c.r | (c.g << 8) | (c.b << 16) | (c.a << 24);\n"
    "    u = gl_FrontFacing == (fv_sign > 0.0) ? u - q : u + q;\n"
    "    FV_FRAGCOLOR = vec4(uvec4(u, u >> 8, u >> 16, u >> 24) & 255u) / 255.0;\n"
    "}\n"
    "#else\n"
    "void main() {\n"
    "#ifdef FV_DENSITY\n"                        /* decoded opaque depth, then v re-encoded */
    "    if (fv_dens.y > 0.5) {\n"
    "        float od = dot(FV_O_DIGITS(fv_opaque), fv_dec) * fv_dens.z;\n"
    "        FV_FRAGCOLOR = fv_encode(fv_density_apply(min(max(fv_d, 0.0), od), od));\n"
    "        return;\n"
    "    }\n"
    "#endif\n"
    "#if defined(FV_O_FLOAT) && !defined(FV_NO_OPAQUE)\n" /* the lesser depth's encoding (monotonic) */
    "    vec4 e = fv_encode(min(fv_d, FV_OREAD(fv_opaque).r));\n"
    "#else\n"
    "    vec4 e = fv_encode(fv_d);\n"
    "#endif\n"
    "#ifdef FV_NORMALIZE\n"
    "    e = fv_normalize(e);\n"
    "#endif\n"
    "#ifdef FV_COUNT\n"
    "    FV_FRAGCOLOR = vec4(e.rgb, 1.0 / 255.0);\n"
    "#elif defined(FV_NO_OPAQUE) || defined(FV_O_FLOAT)\n" /* O far, or already in e */
    "    FV_FRAGCOLOR = e;\n"
    "#else\n"
    "    vec4 o = FV_OREAD(fv_opaque);\n"
    "#ifdef FV_PS13\n"
    "    vec3 s = clamp((e.rgb - o.rgb) * 255.0, -1.0, 1.0);\n"
    "    FV_FRAGCOLOR = dot(s, vec3(1.0, 0.66, 0.31)) - 0.01 > 0.0 ? o : e;\n"
    "#else\n"
    "    FV_FRAGCOLOR = dot(e - o, fv_dec) >= 0.0 ? o : e;\n"
    "#endif\n"
    "#endif\n"
    "}\n"
    "#endif\n";

/* PS13: B - F per channel with carries into digits (exact small-integer arithmetic, fine in
   mediump), + the opaque depth's digits once per missing back face with COUNT (o: FV_RESOLVE_O, O
   there, unused otherwise); the digits past the top one are below N after the carries, the top one
   is negative where B - F is. fv_resolve_sat: some channel of B or F at 255 (saturated). Read by
   the RESOLVE program and, with FV_INLINE_RESOLVE (FOGVOL_SPEEDUP_INLINE_RESOLVE), the composite. */
static const char fogvol__fs_resolve_fn[] =
    "#ifdef FV_COUNT\n#define FV_RESOLVE_O(s) FV_SCREEN(s)\n#else\n#define FV_RESOLVE_O(s) vec4(0.0)\n#endif\n"
    "vec3 fv_resolve(vec4 b, vec4 f, vec4 o) {\n"
    "    vec3 d = floor((b.rgb - f.rgb) * 255.0 + 0.5);\n"
    "#ifdef FV_COUNT\n"
    "    d += floor((f.a - b.a) * 255.0 + 0.5) * floor(o.rgb * 255.0 + 0.5);\n"
    "#endif\n"
    "    float n = fv_enc.x, c = floor(d.b / n);\n"
    "    d.b -= c * n;\n"
    "    d.g += c;\n"
    "    c = floor(d.g / n);\n"
    "    d.g -= c * n;\n"
    "    d.r += c;\n"
    "    return d;\n"
    "}\n"
    "float fv_resolve_sat(vec4 b, vec4 f) {\n"
    "    return max(max(b.r, b.g), max(b.b, max(f.r, max(f.g, f.b)))) > 254.5 / 255.0 ? 1.0 : 0.0;\n"
    "}\n";

/* PS13 resolve into T: the digits (0 where B - F < 0), alpha marks covered pixels (2: saturated). */
static const char fogvol__fs_resolve[] =
    "FV_BINDING(0) uniform FV_TARGET_SAMPLER fv_back;\n"
    "FV_BINDING(1) uniform FV_TARGET_SAMPLER fv_front;\n"
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "void main() {\n"
    "    vec4 b = FV_SCREEN(fv_back), f = FV_SCREEN(fv_front);\n"
    "    vec3 d = fv_resolve(b, f, FV_RESOLVE_O(fv_opaque));\n"
    "    float covered = b + f == vec4(0.0) ? 0.0 : 1.0;\n"
    "    FV_FRAGCOLOR = vec4(d.r < 0.0 ? vec3(0.0) : d / 255.0, covered * (1.0 + fv_resolve_sat(b, f)) / 255.0);\n"
    "}\n";

/* Composite: thickness -> colour ramp. PS20/MRT: decode(B - F);
   COUNT adds the opaque depth once per missing back face; SINGLE decodes one
   biased target; PS13 reads the resolved thickness; FLOAT the float sum.
   A channel at 255 means saturation: with at most 2^(8-L) faces a channel sums
   to at most 256 - 2^(8-L). SINGLE also reads the overflow mask V (fv_front),
   where a check pass marked the channels that hit 255 before the subtraction
   brought them down. FV_CHECK (the check pass) keeps only saturated pixels. */
static const char fogvol__fs_composite[] =
    "FV_UNIFORM(vec4, fv_rampmap)\n"
    /* exp(-x), x >= 0; FV_FAST_EXP (FOGVOL_SPEEDUP_FAST_EXP): 2^y = 2^n (1 + g (a + (1 - a) g)),
       n = floor(y), g = y - n, the minimax a with p(0) = 1, p(1) = 2 (relative error 0.0027) */
    "float fv_transmit(float x) {\n"
    "#if defined(FV_FAST_EXP) && (__VERSION__ >= 330 || (defined(GL_ES) && __VERSION__ >= 300))\n"
    "    float y = max(x * -1.442695, -126.0), n = floor(y), g = y - n;\n"
    "    highp int e = int(n) * 8388608;\n"
    "    return intBitsToFloat(floatBitsToInt(1.0 + g * (0.6602 + g * 0.3398)) + e);\n"
    "#else\n"
    "    return exp(-x);\n"
    "#endif\n"
    "}\n"
    "FV_BINDING(0) uniform FV_TARGET_SAMPLER fv_back;\n"
    "FV_BINDING(1) uniform FV_TARGET_SAMPLER fv_front;\n"
    "FV_BINDING(2) uniform sampler2D fv_colors;\n"
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "FV_BINDING(6) uniform sampler2D fv_ctex;\n"              /* colour texture, screen-space coordinates */
    "FV_UNIFORM(vec4, fv_speed)\n"
    "#ifdef FV_ENGINE_TEST\n"
    "FV_UNIFORM(vec4, fv_nf)\n"
    "FV_UNIFORM(vec4, fv_misc)\n"
    "#endif\n"
    "FV_UNIFORM(vec4, fv_ctex_u)\n"
    "FV_UNIFORM(vec4, fv_ctex_v)\n"
    /* soft edges (fogvol_ramp_desc.softness): the optical thickness of a chord t whose density rises
       over s from both ends, fv_soft = (s, 1/(4s), 2s, 0); s = 0: t */
    "FV_UNIFORM(vec4, fv_soft)\n"
    "float fv_soften(float t) {\n"
    "    return fv_soft.x <= 0.0 || t <= 0.0 ? t : t < fv_soft.z ? t * t * fv_soft.y : t - fv_soft.x;\n"
    "}\n"
    "#ifdef FV_WIDE\n"
    "FV_BINDING(4) uniform sampler2D fv_back2;\n"
    "FV_BINDING(5) uniform sampler2D fv_front2;\n"
    "#endif\n"
    /* FV_DOWNSAMPLE (FLOAT, GLSL 130+): the sum at half resolution, bilinear between the four
       nearest low-resolution texel centres, clamped at the edges. The tw texels span the w pixels of
       the viewport: texel i's centre lies at viewport coordinate (i + 0.5) w / tw (2i + 1 where w is
       even), so the texel coordinate of a pixel is st * tw - 0.5 (st = fv_st(): 1 / w in fv_screen) */
    "#ifdef FV_DOWNSAMPLE\n"
    "#ifdef FV_NO_FETCH\n"
    "#define FV_TAP(c, n) FV_TEXTURE(fv_back, (vec2(c) + 0.5) / vec2(n + 1)).r\n"
    "#else\n"
    "#define FV_TAP(c, n) texelFetch(fv_back, c, 0).r\n"
    "#endif\n"
    "float fv_half_sum() {\n"
    "#ifdef FV_FILTERED\n"                   /* the sampler interpolates (fogvol_target_desc.linear) */
    "    return FV_TEXTURE(fv_back, fv_st()).r;\n"
    "#else\n"
    "    vec2 p = fv_st() * vec2(textureSize(fv_back, 0)) - 0.5, i = floor(p), f = p - i;\n"
    "    ivec2 n = textureSize(fv_back, 0) - 1;\n"
    "    ivec2 a = clamp(ivec2(i), ivec2(0), n), c = clamp(ivec2(i) + 1, ivec2(0), n);\n"
    "    return mix(mix(FV_TAP(a, n), FV_TAP(ivec2(c.x, a.y), n), f.x),\n"
    "               mix(FV_TAP(ivec2(a.x, c.y), n), FV_TAP(c, n), f.x), f.y);\n"
    "#endif\n"
    "}\n"
    "#endif\n"
    ;

/* (the composite's main: C99 compilers need take no string over 4095 characters) */
static const char fogvol__fs_composite_main[] =
    "void main() {\n"
    "    vec2 st = fv_st();\n"
    "#ifdef FV_DOWNSAMPLE\n"
    "    vec4 b = vec4(fv_half_sum(), 0.0, 0.0, 0.0);\n"
    "#else\n"
    "    vec4 b = FV_SCREEN(fv_back);\n"
    "#endif\n"
    "    float sat = 0.0, t;\n"
    "#if defined(FV_XSUM)\n" /* FOGVOL_SPECIALIZE_EXACT_SUM: a 32-bit integer, 2^24 per depth range */
    "    highp uvec4 cu = uvec4(b * 255.0 + 0.5);\n"
    "    highp uint u = cu.r | (cu.g << 8) | (cu.b << 16) | (cu.a << 24);\n"
    "    if (u == 0u) discard;\n"
    "    t = float(int(u)) * fv_rampmap.w;\n"
    "#elif defined(FV_FLOAT) && defined(FV_ENGINE_TEST)\n" /* r - o (g - c), o read where faces lay behind it */
    "    float g = b.g - fv_misc.w;\n"             /* c: volumes whose front faces the near plane clips */
    "    if (b.r == 0.0 && g == 0.0) discard;\n"
    "    t = b.r;\n"
    "    if (g != 0.0) t -= min(fv_engine_view_depth(st, FV_ENGINE_Z(fv_opaque)) * fv_nf.x + fv_nf.y, 1.0) * g;\n"
    "    if (fv_rampmap.w > 0.5) {\n"             /* the debug read-back's pass: r - o (g - c) into B */
    "        FV_FRAGCOLOR = vec4(t, 0.0, 0.0, 0.0);\n"
    "        return;\n"
    "    }\n"
    "    t *= fv_dec.x;\n"
    "#elif defined(FV_FLOAT)\n"
    "    if (b.r == 0.0) discard;\n"
    "    t = b.r * fv_dec.x;\n"
    "#elif defined(FV_PS13) && defined(FV_INLINE_RESOLVE)\n"  /* T's digits (clamped to 255) */
    "    vec4 f = FV_SCREEN(fv_front);\n"
    "    if (b + f == vec4(0.0)) discard;\n"
    "    vec3 d = fv_resolve(b, f, FV_RESOLVE_O(fv_opaque));\n"
    "    t = d.r < 0.0 ? 0.0 : dot(min(d, 255.0) / 255.0, fv_dec.xyz);\n"
    "    sat = fv_resolve_sat(b, f);\n"
    "#elif defined(FV_PS13)\n"
    "    if (b.a == 0.0) discard;\n"
    "    t = dot(b.rgb, fv_dec.xyz);\n"
    "    sat = b.a > 1.5 / 255.0 ? 1.0 : 0.0;\n"
    "#elif defined(FV_SINGLE)\n"
    "    vec4 s = b - vec4(128.0 / 255.0);\n"
    "#ifdef FV_CHECK\n"
    "    float peak = 0.0;\n"
    "#else\n"
    "    float peak = FV_SCREEN(fv_front).r;\n"
    "    if (s == vec4(0.0) && peak < 0.5) discard;\n"
    "#endif\n"
    "    t = dot(s, fv_dec);\n"
    "    sat = peak > 0.5 || max(max(b.r, b.g), max(b.b, b.a)) > 254.5 / 255.0 ||"
    " min(min(b.r, b.g), min(b.b, b.a)) < 0.5 / 255.0 ? 1.0 : 0.0;\n"
    "#else\n"
    "    vec4 f = FV_SCREEN(fv_front);\n"
    "#ifndef FV_WIDE\n"
    "    if (b + f == vec4(0.0)) discard;\n"
    "#endif\n"
    "    vec4 m = max(b, f);\n"
    "    sat = max(max(m.r, m.g), max(m.b, m.a)) > 254.5 / 255.0 ? 1.0 : 0.0;\n"
    "#if defined(FV_COUNT)\n"
    "    t = dot(b.rgb - f.rgb, fv_dec.xyz) + (f.a - b.a) * 255.0 * dot(FV_SCREEN(fv_opaque).rgb, fv_dec.xyz);\n"
    "#elif defined(FV_WIDE)\n"
    "    vec4 b2 = FV_SCREEN(fv_back2), f2 = FV_SCREEN(fv_front2);\n"
    "    if (b + f + b2 + f2 == vec4(0.0)) discard;\n"
    "    m = max(m, max(b2, f2));\n"
    "    sat = max(max(m.r, m.g), max(m.b, m.a)) > 254.5 / 255.0 ? 1.0 : 0.0;\n"
    "    t = dot(b - f, fv_dec) + dot(b2 - f2, fv_dec) / (fv_enc.x * fv_enc.y);\n"
    "#else\n"
    "    t = dot(b - f, fv_dec);\n"
    "#endif\n"
    "#endif\n"
    "#ifdef FV_CHECK\n"
    "    if (sat < 0.5) discard;\n"
    "    FV_FRAGCOLOR = vec4(1.0);\n"
    "#else\n"
    "    vec4 c;\n"
    "    t = fv_soften(t);\n"
    "#if defined(FV_EXP) && defined(FV_BLEND_COLOR)\n" /* the colour: fogvol_pass.blend_color */
    "    c = vec4(1.0 - fv_transmit(fv_speed.w * max(t, 0.0)));\n"
    "#elif defined(FV_EXP)\n"
    "    c = vec4(fv_speed.rgb, 1.0 - fv_transmit(fv_speed.w * max(t, 0.0)));\n"
    "#elif defined(FV_RAMP)\n"
    "    c = FV_TEXTURE(fv_colors, vec2(t * fv_rampmap.x + fv_rampmap.y, 0.5));\n"
    "#else\n"
    "    if (fv_speed.w > 0.0) c = vec4(fv_speed.rgb, 1.0 - fv_transmit(fv_speed.w * max(t, 0.0)));\n"
    "    else c = FV_TEXTURE(fv_colors, vec2(t * fv_rampmap.x + fv_rampmap.y, 0.5));\n"
    "#endif\n"
    "#ifndef FV_NO_CTEX\n"
    "    if (fv_ctex_u.w > 0.5)\n"
    "        c.rgb *= FV_TEXTURE(fv_ctex, vec2(dot(fv_ctex_u.xyz, vec3(st, 1.0)), dot(fv_ctex_v.xyz, vec3(st, 1.0)))).rgb;\n"
    "#endif\n"
    "#ifdef FV_NO_SAT\n"                         /* SPECIALIZE_NO_OVERFLOW: show_overflow off */
    "    FV_FRAGCOLOR = c;\n"
    "#else\n"
    "    FV_FRAGCOLOR = fv_rampmap.z * sat > 0.5 ? vec4(1.0, 0.0, 1.0, 1.0) : c;\n"
    "#endif\n"
    "#endif\n"
    "}\n";

/* Volume light by compare. fv_light.w = 0: the light's front faces write their depth d into L
   (FLOAT: d; RGBA8: encoded). 1: its back faces light the pixels whose opaque depth o lies
   between L's front depth and their own depth, in the engine framebuffer. */
static const char fogvol__fs_light[] =
    "FV_LOCATION(0) FV_VARYING_IN float fv_d;\n"
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "FV_BINDING(7) uniform FV_TARGET_SAMPLER fv_lfront;\n"
    "FV_UNIFORM(vec4, fv_light)\n"
    "FV_UNIFORM(vec4, fv_nf)\n"
    "float fv_light_depth(vec4 v) {\n"
    "#ifdef FV_FLOAT\n"
    "    return v.r;\n"
    "#else\n"
    "    return dot(v, fv_dec) * fv_nf.x;\n"
    "#endif\n"
    "}\n"
    "float fv_light_opaque() {\n"
    "#if defined(FV_FLOAT) && defined(FV_ENGINE_DEPTH)\n"
    "    float z = FV_ENGINE_Z(fv_opaque);\n"
    "    return fv_engine_view_depth(fv_st(), z) * fv_nf.x + fv_nf.y;\n"
    "#else\n"
    "    return fv_light_depth(FV_O_DIGITS(fv_opaque));\n"
    "#endif\n"
    "}\n"
    /* falloff with distance and the soft edge (fogvol_light_desc): q the scene point relative to the
       falloff sphere (fv_lq0..5), f and d the light's front and back depths on the ray */
    "FV_UNIFORM(vec4, fv_lq0)\n"
    "FV_UNIFORM(vec4, fv_lq1)\n"
    "FV_UNIFORM(vec4, fv_lq2)\n"
    "FV_UNIFORM(vec4, fv_lq3)\n"
    "FV_UNIFORM(vec4, fv_lq4)\n"
    "FV_UNIFORM(vec4, fv_lq5)\n"
    "float fv_light_weight(float o, float f, float d) {\n"
    "    float w = 1.0;\n"
    "    if (fv_lq0.w > 0.5) {\n"
    "        vec2 st = fv_st();\n"
    "        vec3 q = fv_lq0.xyz + fv_lq1.xyz * st.x + fv_lq2.xyz * st.y +\n"
    "                 o * (fv_lq3.xyz + fv_lq4.xyz * st.x + fv_lq5.xyz * st.y);\n"
    "        float r2 = min(dot(q, q), 1.0);\n"
    "        w = (1.0 - r2) * (1.0 - r2);\n"
    "    }\n"
    "    if (fv_lq1.w > 0.0) w *= clamp((f > 0.0 ? min(o - f, d - o) : d - o) * fv_lq1.w, 0.0, 1.0);\n"
    "    return w;\n"
    "}\n"
    "void main() {\n"
    "    float d = max(fv_d, 0.0);\n"
    "    if (fv_light.w < 0.5) {\n"
    "#if defined(FV_FLOAT)\n"
    "        FV_FRAGCOLOR = vec4(d, 0.0, 0.0, 0.0);\n"
    "#elif defined(FV_NORMALIZE)\n"
    "        FV_FRAGCOLOR = fv_normalize(fv_encode(d));\n"
    "#else\n"
    "        FV_FRAGCOLOR = fv_encode(d);\n"
    "#endif\n"
    "    } else {\n"
    "        float o = fv_light_opaque(), f = fv_light_depth(FV_SCREEN(fv_lfront));\n"
    "        if (o < f || o > d) discard;\n"
    "        FV_FRAGCOLOR = vec4(fv_light.rgb * fv_light_weight(o, f, d), 1.0);\n"
    "    }\n"
    "}\n";

/* Faces of every volume of the colour group: the signed, opaque-clamped depth s (as the FLOAT face
   program) times the volume's per-channel extinction (target 0: optical depth tau) and times its
   extinction * colour (target 1: emission sum E). */
static const char fogvol__fs_color_face[] =
    "FV_LOCATION(0) FV_VARYING_IN float fv_d;\n"
    "FV_BINDING(3) uniform FV_TARGET_SAMPLER fv_opaque;\n"
    "FV_UNIFORM(float, fv_sign)\n"
    "FV_UNIFORM(vec4, fv_nf)\n"
    "FV_UNIFORM(vec4, fv_ext)\n"
    "FV_UNIFORM(vec4, fv_emit)\n"
    "void main() {\n"
    "#ifdef FV_ENGINE_DEPTH\n"
    "    float z = FV_ENGINE_Z(fv_opaque);\n"
    "    float o = fv_engine_view_depth(fv_st(), z) * fv_nf.x + fv_nf.y;\n"
    "#else\n"
    "    float o = FV_TEXTURE(fv_opaque, fv_st()).r;\n"
    "#endif\n"
    "    float d = min(max(fv_d, 0.0), o);\n"
    "    float s = gl_FrontFacing ? -d * fv_sign : d * fv_sign;\n"
    "    FV_OUT0 = s * fv_ext;\n"
    "    FV_OUT1 = s * fv_emit;\n"
    "}\n";

/* Composite of the colour group: transmittance T = exp(-tau) per channel, in-scattered colour
   c = E / tau per channel (the optical-depth-weighted mean of the volumes' colours), result
   scene * T + c * (1 - T). fv_rampmap.z picks the step: 0 one FOG-blended draw (every extinction
   grey: T the same in each channel), 1 the multiply draw (scene * T), 2 the emission draw. */
static const char fogvol__fs_color_composite[] =
    "FV_UNIFORM(vec4, fv_rampmap)\n"
    "FV_BINDING(0) uniform FV_TARGET_SAMPLER fv_back;\n"
    "FV_BINDING(1) uniform FV_TARGET_SAMPLER fv_front;\n"
    "void main() {\n"
    "    vec2 st = fv_st();\n"
    "    vec3 tau = max(FV_TEXTURE(fv_back, st).rgb, vec3(0.0));\n"
    "    if (tau == vec3(0.0)) discard;\n"
    "    vec3 e = max(FV_TEXTURE(fv_front, st).rgb, vec3(0.0));\n"
    "    vec3 tr = exp(-tau);\n"
    "    vec3 c = min(e / max(tau, vec3(1e-30)), vec3(1.0));\n"
    "    float m = dot(tr, vec3(1.0 / 3.0));\n"
    "    if (fv_rampmap.z < 0.5) FV_FRAGCOLOR = vec4(c, 1.0 - m);\n"
    "    else if (fv_rampmap.z < 1.5) FV_FRAGCOLOR = vec4(tr, m);\n"
    "    else FV_FRAGCOLOR = vec4(c * (1.0 - tr), 1.0 - m);\n"
    "}\n";

FOGVOL_API const char *fogvol_dialect_name(fogvol_dialect dialect)
{
    if ((int)dialect < 0 || (int)dialect >= FOGVOL_GLSL_COUNT) return "invalid";
    return fogvol__dialects[dialect].name;
}

/* The fragment or vertex shader's program body and its program's #defines. */
static int fogvol__program_strings(const fogvol_shader_desc *d, const char **strings, int n)
{
    if (d->stage == FOGVOL_STAGE_VERTEX) {
        strings[n++] = (d->program == FOGVOL_PROGRAM_COMPOSITE || d->program == FOGVOL_PROGRAM_RESOLVE ||
                        d->program == FOGVOL_PROGRAM_CHECK || d->program == FOGVOL_PROGRAM_COLOR_COMPOSITE ||
                        (d->program == FOGVOL_PROGRAM_ENCODE && (d->variants & FOGVOL_VARIANT_ENGINE_DEPTH)))
                           ? fogvol__vs_fullscreen
                           : fogvol__vs_mesh;
        return n;
    }
    if (d->program == FOGVOL_PROGRAM_CHECK) strings[n++] = "#define FV_CHECK\n";
    strings[n++] = fogvol__fs_common;
    strings[n++] = fogvol__fs_encode_common;
    if (d->program == FOGVOL_PROGRAM_RESOLVE || (d->specialize & FOGVOL_SPECIALIZE_INLINE_RESOLVE))
        strings[n++] = fogvol__fs_resolve_fn;
    switch (d->program) {
    case FOGVOL_PROGRAM_ENCODE: strings[n++] = fogvol__fs_encode; break;
    case FOGVOL_PROGRAM_FACE:
        strings[n++] = fogvol__fs_face;
        strings[n++] = fogvol__fs_face_rgba8;
        break;
    case FOGVOL_PROGRAM_RESOLVE: strings[n++] = fogvol__fs_resolve; break;
    case FOGVOL_PROGRAM_LIGHT: strings[n++] = fogvol__fs_light; break;
    case FOGVOL_PROGRAM_COLOR_FACE: strings[n++] = fogvol__fs_color_face; break;
    case FOGVOL_PROGRAM_COLOR_COMPOSITE: strings[n++] = fogvol__fs_color_composite; break;
    default:
        strings[n++] = fogvol__fs_composite;
        strings[n++] = fogvol__fs_composite_main;
        break;
    }
    return n;
}

/* fogvol_shader_desc.specialize: the bits a program accepts (FOGVOL_SPECIALIZE_*). */
static int fogvol__specialize_ok(fogvol_program p, unsigned bits)
{
    unsigned face = FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_OPAQUE |
                    FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_ENGINE_TEST;
    unsigned comp = FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                    FOGVOL_SPECIALIZE_NO_OVERFLOW | FOGVOL_SPECIALIZE_FAST_EXP | FOGVOL_SPECIALIZE_EXACT_SUM |
                    FOGVOL_SPECIALIZE_ENGINE_TEST;
    if ((bits & FOGVOL_SPECIALIZE_ENGINE_TEST) &&
        ((p == FOGVOL_PROGRAM_FACE && !(bits & FOGVOL_SPECIALIZE_NO_DENSITY)) || p == FOGVOL_PROGRAM_COMPOSITE_MESH ||
         (bits & (FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_EXACT_SUM | FOGVOL_SPECIALIZE_FETCH_O))))
        return 0; /* (one program pair: the faces without density textures, the full-screen composite) */
    if ((bits & FOGVOL_SPECIALIZE_EXACT_SUM) && (bits & FOGVOL_SPECIALIZE_COUNT)) return 0; /* (one target) */
    if ((bits & FOGVOL_SPECIALIZE_EXP) && (bits & FOGVOL_SPECIALIZE_RAMP)) return 0;
    if ((bits & FOGVOL_SPECIALIZE_OPAQUE) && (bits & FOGVOL_SPECIALIZE_NO_OPAQUE)) return 0;
    if ((bits & FOGVOL_SPECIALIZE_FETCH_O) && (bits & (FOGVOL_SPECIALIZE_NO_OPAQUE | FOGVOL_SPECIALIZE_COUNT)))
        return 0; /* (it reads O) */
    if ((bits & FOGVOL_SPECIALIZE_BLEND_COLOR) &&
        ((p != FOGVOL_PROGRAM_COMPOSITE && p != FOGVOL_PROGRAM_COMPOSITE_MESH) ||
         (~bits & (FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW))))
        return 0; /* one colour for every pixel */
    bits &= ~(unsigned)(FOGVOL_SPECIALIZE_ORIGIN | FOGVOL_SPECIALIZE_DEPTH_FROM_Z | FOGVOL_SPECIALIZE_BLEND_COLOR);
    /* (ORIGIN, DEPTH_FROM_Z: every program) */
    if (p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_ENCODE || p == FOGVOL_PROGRAM_RESOLVE ||
        p == FOGVOL_PROGRAM_COMPOSITE)
        bits &= ~(unsigned)FOGVOL_SPECIALIZE_COUNT; /* the tier and variants decide (fogvol__count_spec_ok) */
    if ((bits & FOGVOL_SPECIALIZE_FILTERED) && !(bits & FOGVOL_SPECIALIZE_DOWNSAMPLE)) return 0;
    if (p == FOGVOL_PROGRAM_COMPOSITE) /* (FLOAT: the caller) */
        bits &= ~(unsigned)(FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED);
    if ((bits & FOGVOL_SPECIALIZE_ENCODING_MASK) > FOGVOL_SPECIALIZE_ENCODING(8)) return 0;
    if (p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_ENCODE)
        bits &= ~(unsigned)(FOGVOL_SPECIALIZE_DITHER | FOGVOL_SPECIALIZE_ENCODING_MASK);
    if (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH || p == FOGVOL_PROGRAM_CHECK)
        bits &= ~(unsigned)FOGVOL_SPECIALIZE_INLINE_RESOLVE; /* PS13 only (fogvol_shader_strings) */
    if (p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_LIGHT || p == FOGVOL_PROGRAM_ENCODE)
        bits &= ~(unsigned)FOGVOL_SPECIALIZE_FLOAT_O; /* the programs that read or write O (tiers and
                                                         variants: fogvol_shader_strings) */
    if (p == FOGVOL_PROGRAM_FACE) return (bits & ~face) == 0;
    if (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH) return (bits & ~comp) == 0;
    return bits == 0;
}

/* The #define strings of fogvol_shader_desc.specialize (NO_DENSITY leaves FV_DENSITY out), appended
   at strings[n]; returns the new count. */
static int fogvol__specialize_defines(const fogvol_shader_desc *d, const char **strings, int n)
{
    static const char *const comp[8] = {"",
                                        "#define FV_EXP\n",
                                        "#define FV_RAMP\n",
                                        "",
                                        "#define FV_NO_CTEX\n",
                                        "#define FV_EXP\n#define FV_NO_CTEX\n",
                                        "#define FV_RAMP\n#define FV_NO_CTEX\n",
                                        ""};
    /* SPECIALIZE_ENCODING(L): L, log2 D, N and D of fogvol_encoding_init(L) */
    static const char *const enc[8] = {
        "#define FV_ENC_LN 1\n#define FV_ENC_LD 5\n#define FV_ENC_N 2.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 2\n#define FV_ENC_LD 5\n#define FV_ENC_N 4.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 3\n#define FV_ENC_LD 5\n#define FV_ENC_N 8.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 4\n#define FV_ENC_LD 5\n#define FV_ENC_N 16.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 5\n#define FV_ENC_LD 5\n#define FV_ENC_N 32.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 6\n#define FV_ENC_LD 5\n#define FV_ENC_N 64.0\n#define FV_ENC_D 32.0\n",
        "#define FV_ENC_LN 7\n#define FV_ENC_LD 4\n#define FV_ENC_N 128.0\n#define FV_ENC_D 16.0\n",
        "#define FV_ENC_LN 8\n#define FV_ENC_LD 3\n#define FV_ENC_N 256.0\n#define FV_ENC_D 8.0\n"};
    unsigned L = (d->specialize & FOGVOL_SPECIALIZE_ENCODING_MASK) >> 13;
    if (d->stage != FOGVOL_STAGE_FRAGMENT) return n;
    if (L && (d->program == FOGVOL_PROGRAM_FACE || d->program == FOGVOL_PROGRAM_ENCODE)) strings[n++] = enc[L - 1];
    if (d->specialize & FOGVOL_SPECIALIZE_ORIGIN) strings[n++] = "#define FV_ORIGIN\n";
    if (d->specialize & FOGVOL_SPECIALIZE_NO_OVERFLOW) strings[n++] = "#define FV_NO_SAT\n";
    if (d->specialize & FOGVOL_SPECIALIZE_FAST_EXP) strings[n++] = "#define FV_FAST_EXP\n";
    if (d->specialize & FOGVOL_SPECIALIZE_DITHER) strings[n++] = "#define FV_DITHER_ON\n";
    if (d->specialize & FOGVOL_SPECIALIZE_DOWNSAMPLE) strings[n++] = "#define FV_DOWNSAMPLE\n";
    if (d->specialize & FOGVOL_SPECIALIZE_FILTERED) strings[n++] = "#define FV_FILTERED\n";
    if (d->specialize & FOGVOL_SPECIALIZE_INLINE_RESOLVE) strings[n++] = "#define FV_INLINE_RESOLVE\n";
    if (d->specialize & FOGVOL_SPECIALIZE_BLEND_COLOR) strings[n++] = "#define FV_BLEND_COLOR\n";
    if (d->specialize & FOGVOL_SPECIALIZE_DEPTH_FROM_Z) strings[n++] = "#define FV_DEPTH_FROM_Z\n";
    if (d->specialize & FOGVOL_SPECIALIZE_FLOAT_O) strings[n++] = "#define FV_O_FLOAT\n";
    if (d->specialize & FOGVOL_SPECIALIZE_EXACT_SUM) strings[n++] = "#define FV_XSUM\n";
    if (d->specialize & FOGVOL_SPECIALIZE_ENGINE_TEST) strings[n++] = "#define FV_ENGINE_TEST\n";
    if (d->program == FOGVOL_PROGRAM_FACE && (d->specialize & FOGVOL_SPECIALIZE_NO_OPAQUE))
        strings[n++] = "#define FV_NO_OPAQUE\n";
    if (d->program == FOGVOL_PROGRAM_FACE && (d->specialize & FOGVOL_SPECIALIZE_OPAQUE))
        strings[n++] = "#define FV_OPAQUE\n";
    if (d->program != FOGVOL_PROGRAM_FACE && comp[(d->specialize >> 2) & 7u][0])
        strings[n++] = comp[(d->specialize >> 2) & 7u];
    return n;
}

FOGVOL_API fogvol_result fogvol_shader_strings(const fogvol_shader_desc *d, const char **strings, int *count)
{
    const fogvol__dialect_info *di;
    int n = 0, i, per_sample;
    unsigned v; /* the variants the strings define: COUNT added by FOGVOL_SPECIALIZE_COUNT */
    if (!strings || !count || !d) return FOGVOL_ERROR_INVALID_ARGUMENT;
    *count = 0;
    if (d->tier <= FOGVOL_TIER_AUTO || d->tier >= FOGVOL_TIER_COUNT) return FOGVOL_ERROR_UNSUPPORTED;
    if (fogvol_combination_supported(d->tier, d->variants, d->dialect) != FOGVOL_SUCCESS)
        return FOGVOL_ERROR_UNSUPPORTED;
    if ((int)d->program < 0 || (int)d->program >= FOGVOL_PROGRAM_COUNT ||
        !fogvol_tier_uses_program(d->tier, d->variants, d->program))
        return FOGVOL_ERROR_UNSUPPORTED;
    if (d->stage != FOGVOL_STAGE_VERTEX && d->stage != FOGVOL_STAGE_FRAGMENT) return FOGVOL_ERROR_UNSUPPORTED;
    if (d->samples > 1 && fogvol_msaa_supported(d->tier, d->variants, d->dialect) != FOGVOL_SUCCESS)
        return FOGVOL_ERROR_UNSUPPORTED;
    if (!fogvol__specialize_ok(d->program, d->specialize)) return FOGVOL_ERROR_UNSUPPORTED;
    v = d->variants;
    if ((d->specialize & FOGVOL_SPECIALIZE_DOWNSAMPLE) &&
        (d->tier != FOGVOL_TIER_FLOAT || (v & FOGVOL_VARIANT_COLORS) || d->samples > 1))
        return FOGVOL_ERROR_UNSUPPORTED;
    if ((d->specialize & FOGVOL_SPECIALIZE_INLINE_RESOLVE) && d->tier != FOGVOL_TIER_PS13)
        return FOGVOL_ERROR_UNSUPPORTED;
    /* (multisampled frames: the faces shaded once per pixel, a single-sample program; the composite per sample) */
    if ((d->specialize & FOGVOL_SPECIALIZE_ENGINE_TEST) &&
        (!fogvol__tier_has(d->tier, v, FOGVOL__F_ENGINE_TEST) || (d->samples > 1 && d->program != FOGVOL_PROGRAM_COMPOSITE)))
        return FOGVOL_ERROR_UNSUPPORTED;
    if (d->specialize & FOGVOL_SPECIALIZE_COUNT) {
        if (!fogvol__tier_has(d->tier, v, FOGVOL__F_DEPTH_TEST) ||
            fogvol_combination_supported(d->tier, v | FOGVOL_VARIANT_COUNT, d->dialect) != FOGVOL_SUCCESS ||
            (d->program == FOGVOL_PROGRAM_FACE && !(d->specialize & FOGVOL_SPECIALIZE_NO_DENSITY)))
            return FOGVOL_ERROR_UNSUPPORTED; /* (COUNT has no density texture) */
        v |= FOGVOL_VARIANT_COUNT;
    }
    if ((d->specialize & FOGVOL_SPECIALIZE_FLOAT_O) && !fogvol__tier_has(d->tier, v, FOGVOL__F_FLOAT_O)) return FOGVOL_ERROR_UNSUPPORTED;
    di = fogvol__dialect(d->dialect);
    if ((d->specialize & FOGVOL_SPECIALIZE_FETCH_O) && (!di->fs_fetch || !fogvol__tier_has(d->tier, v, FOGVOL__F_FETCH_O) || d->samples > 1))
        return FOGVOL_ERROR_UNSUPPORTED;
    if ((d->specialize & FOGVOL_SPECIALIZE_EXACT_SUM) &&
        (!fogvol__tier_has(d->tier, v, FOGVOL__F_EXACT_SUM) || !di->fs_fetch || /* (uint: the framebuffer fetch's dialects) */
         (d->program == FOGVOL_PROGRAM_FACE && (d->samples > 1 || !(d->specialize & FOGVOL_SPECIALIZE_NO_DENSITY)))))
        return FOGVOL_ERROR_UNSUPPORTED;
    per_sample = d->samples > 1 && d->stage == FOGVOL_STAGE_FRAGMENT;
    strings[n++] = per_sample ? di->version_msaa : di->version;
    if (d->stage == FOGVOL_STAGE_VERTEX)
        n = fogvol__prelude(strings, n, di->vs);
    else if (((d->variants & FOGVOL_VARIANT_WIDE) &&
              (d->program == FOGVOL_PROGRAM_ENCODE || d->program == FOGVOL_PROGRAM_FACE)) ||
             d->program == FOGVOL_PROGRAM_COLOR_FACE)
        n = fogvol__prelude(strings, n, di->fs_two);
    else if (d->program == FOGVOL_PROGRAM_FACE && (d->specialize & (FOGVOL_SPECIALIZE_FETCH_O | FOGVOL_SPECIALIZE_EXACT_SUM))) {
        strings[n++] = di->fs_fetch;
        strings[n++] = (d->specialize & FOGVOL_SPECIALIZE_EXACT_SUM) ? fogvol__fs_fetch_sum : fogvol__fs_fetch_out;
        if (d->specialize & FOGVOL_SPECIALIZE_FETCH_O) strings[n++] = fogvol__fs_fetch_o;
    } else
        strings[n++] = di->fs;
    strings[n++] = di->decl;
    if (fogvol__tiers[d->tier].define[0]) strings[n++] = fogvol__tiers[d->tier].define;
    for (i = 0; i < FOGVOL__VARIANT_COUNT; ++i)
        if (v & (1u << i)) strings[n++] = fogvol__variant_define[i];
    if (per_sample) strings[n++] = fogvol__fs_msaa;
    if (d->program == FOGVOL_PROGRAM_FACE && fogvol__tier_has(d->tier, v, FOGVOL__F_DENSITY) &&
        !(d->specialize & FOGVOL_SPECIALIZE_NO_DENSITY))
        strings[n++] = "#define FV_DENSITY\n";
    n = fogvol__specialize_defines(d, strings, n);
    n = fogvol__program_strings(d, strings, n);
    FOGVOL_ASSERT(n <= FOGVOL_MAX_SHADER_STRINGS);
    *count = n;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_shader_source(fogvol_tier tier, fogvol_program program, fogvol_dialect dialect,
                                              fogvol_stage stage, const char **strings, int *count)
{
    fogvol_shader_desc d;
    d.tier = tier;
    d.variants = 0;
    d.program = program;
    d.dialect = dialect;
    d.stage = stage;
    d.samples = 0;
    d.specialize = 0;
    return fogvol_shader_strings(&d, strings, count);
}

/* MRT tier: the engine's copy of the ALU encode, dither pattern by arithmetic
   (the same 8x8 ordered pattern as fogvol_make_dither_index); in integers where the dialect has
   floatBitsToInt and bit operations (GLSL 330+, 300 es), by FV_IALU's FOGVOL__IALU_TEXT. */
#define FOGVOL__MRT_SNIPPET_TEXT \
    "#ifndef FOGVOL_MRT_IN_BLOCK\n" /* Vulkan: vec4 fogvol_mrt[2] is a member of the engine's own block */ \
    "uniform vec4 fogvol_mrt[2]; /* (1/(far-near), -near/(far-near), N, N^2), (offset, max, D, dither) */\n" \
    "#endif\n" \
    "vec4 fogvol_view_depth_r32f(float view_depth) {\n" /* N = 0: an R32F target */ \
    "    return vec4(clamp(view_depth * fogvol_mrt[0].x + fogvol_mrt[0].y, 0.0, 1.0), 0.0, 0.0, 0.0);\n" \
    "}\n" \
    "#if __VERSION__ >= 330 || (defined(GL_ES) && __VERSION__ >= 300)\n" \
    FOGVOL__IALU_TEXT \
    "vec4 fogvol_encode_view_depth(float view_depth) {\n" \
    "    if (fogvol_mrt[0].z == 0.0) return fogvol_view_depth_r32f(view_depth);\n" \
    "    highp int ln = fogvol_log2i(fogvol_mrt[0].z), ld = fogvol_log2i(fogvol_mrt[1].z), dd = 1 << ld;\n" \
    "    highp int k = fogvol_mrt[1].w > 0.5 ? (fogvol_dither_scaled(dd) + int(fogvol_mrt[1].w) - 1) & (dd - 1) : dd >> 1;\n" \
    "    float u = clamp(view_depth * fogvol_mrt[0].x + fogvol_mrt[0].y, 0.0, fogvol_mrt[1].y) + fogvol_mrt[1].x;\n" \
    "    return fogvol_encode_int(int(u * (fogvol_mrt[0].w * fogvol_mrt[0].z * fogvol_mrt[1].z)), ln, ld, k);\n" \
    "}\n" \
    "#else\n" \
    "vec4 fogvol_encode_view_depth(float view_depth) {\n" \
    "    if (fogvol_mrt[0].z == 0.0) return fogvol_view_depth_r32f(view_depth);\n" \
    "    vec2 p = mod(floor(gl_FragCoord.xy), 8.0);\n" \
    "    vec2 b0 = mod(p, 2.0), b1 = mod(floor(p * 0.5), 2.0), b2 = mod(floor(p * 0.25), 2.0);\n" \
    "    float bayer = abs(b0.x - b0.y) * 32.0 + b0.y * 16.0 + abs(b1.x - b1.y) * 8.0 + b1.y * 4.0 +\n" \
    "                  abs(b2.x - b2.y) * 2.0 + b2.y;\n" \
    "    float n = fogvol_mrt[0].z, dd = fogvol_mrt[1].z;\n" \
    "    float k = fogvol_mrt[1].w > 0.5 ? mod(floor(bayer * dd / 64.0) + fogvol_mrt[1].w - 1.0, dd) : dd * 0.5;\n" \
    "    float d = view_depth * fogvol_mrt[0].x + fogvol_mrt[0].y;\n" \
    "    float u = clamp(d, 0.0, fogvol_mrt[1].y) + fogvol_mrt[1].x;\n" \
    "    float t = u * fogvol_mrt[0].w * n;\n" \
    "    float h = floor(t / n);\n" \
    "    float x = mod(floor(t * dd), n * dd);\n" \
    "    float q = floor((x + k) / dd) - 1.0;\n" \
    "    float a = q < 0.0 ? 1.0 : 0.0;\n" \
    "    return vec4(mod(floor(h / n), n), mod(h, n), q + a * n, a) * (1.0 / 255.0);\n" \
    "}\n" \
    "#endif\n"
static const char fogvol__mrt_snippet[] = FOGVOL__MRT_SNIPPET_TEXT;

/* Occluders drawn by the engine: fogvol_mrt[0].z (N) = 0 marks an R32F target (the FLOAT tier's O,
   and PS20's as MRT's with FOGVOL_SPEEDUP_FLOAT_O) */
static const char fogvol__occluder_snippet[] = FOGVOL__MRT_SNIPPET_TEXT
    "vec4 fogvol_occluder_color(float view_depth) { return fogvol_encode_view_depth(view_depth); }\n";

FOGVOL_API const char *fogvol_mrt_snippet(void) { return fogvol__mrt_snippet; }

FOGVOL_API const char *fogvol_occluder_snippet(void) { return fogvol__occluder_snippet; }

FOGVOL_API const char *fogvol_uniform_name(fogvol_uniform u)
{
    static const char *const names[FOGVOL_U_COUNT] = {
#define FOGVOL__UNIFORM_NAME(id, name) #name,
        FOGVOL_UNIFORMS(FOGVOL__UNIFORM_NAME)
#undef FOGVOL__UNIFORM_NAME
    };
    if ((int)u < 0 || (int)u >= FOGVOL_U_COUNT) return "";
    return names[u];
}

/* >>null backend ========================================================== */
/* A recording backend that needs no GPU: every entry counts its calls (tests, tools). */

static fogvol_result fogvol__null_create(void *u, fogvol_handle *out)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    s->create_calls++;
    if (s->fail_create_at > 0 && s->create_calls == s->fail_create_at) return FOGVOL_ERROR_BACKEND;
    *out = ++s->next_handle;
    s->creates++;
    return FOGVOL_SUCCESS;
}

static void fogvol__null_destroy(void *u, fogvol_handle h)
{
    if (h) ((fogvol_null_backend *)u)->destroys++;
}

static fogvol_result fogvol__null_begin_frame(void *u, fogvol_frame_info *info)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    s->frames_begun++;
    s->pass_count = 0;
    info->samples = s->samples;
    return FOGVOL_SUCCESS;
}

static void fogvol__null_end_frame(void *u) { ((fogvol_null_backend *)u)->frames_ended++; }

static fogvol_result fogvol__null_create_texture(void *u, const fogvol_texture_desc *d, fogvol_handle *out)
{
    (void)d;
    return fogvol__null_create(u, out);
}

static fogvol_result fogvol__null_create_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    (void)d;
    return fogvol__null_create(u, out);
}

static fogvol_result fogvol__null_create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    (void)d;
    return fogvol__null_create(u, out);
}

static fogvol_result fogvol__null_create_mesh(void *u, const fogvol_mesh_data *d, fogvol_handle *out)
{
    /* the layout fields as fogvol_create_mesh hands them (FOGVOL_CAP_MESH_LAYOUT) */
    if (!d->positions || d->stride < 0 || (d->stride && d->stride < 12) || d->offset < 0 ||
        d->offset > (d->stride ? d->stride : 12) - 12 ||
        (d->index_type == FOGVOL_INDEX_UINT16 ? !d->indices16 : d->index_type != FOGVOL_INDEX_UINT32 || !d->indices))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    return fogvol__null_create(u, out);
}

static void fogvol__null_begin_pass(void *u, const fogvol_pass *p)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    if (s->pass_count < FOGVOL_NULL_MAX_PASSES) {
        s->passes[s->pass_count] = *p;
        s->draws[s->pass_count] = 0;
        s->fullscreen[s->pass_count] = 0;
    }
    s->pass_count++;
    s->in_pass = 1;
}

static void fogvol__null_set_draw(void *u, const fogvol_draw *d)
{
    (void)u;
    (void)d;
}

static void fogvol__null_draw_mesh(void *u, fogvol_handle m, const fogvol_draw *d)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    (void)m;
    (void)d;
    if (s->pass_count > 0 && s->pass_count <= FOGVOL_NULL_MAX_PASSES) s->draws[s->pass_count - 1]++;
}

static void fogvol__null_draw_fullscreen(void *u)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    if (s->pass_count > 0 && s->pass_count <= FOGVOL_NULL_MAX_PASSES) s->fullscreen[s->pass_count - 1]++;
}

static void fogvol__null_end_pass(void *u) { ((fogvol_null_backend *)u)->in_pass = 0; }

static fogvol_native fogvol__null_native(void *u, fogvol_handle h)
{
    (void)u;
    return (fogvol_native)h;
}

static fogvol_handle fogvol__null_attachment(void *u, fogvol_handle t, int index)
{
    (void)u;
    return t ? t + ((fogvol_handle)index << 20) : 0; /* a distinct handle, never created or destroyed */
}

static fogvol_result fogvol__null_read_target(void *u, fogvol_handle t, unsigned char *rgba, size_t size)
{
    (void)u;
    (void)t;
    if (rgba) memset(rgba, 0, size);
    return FOGVOL_SUCCESS;
}

static fogvol_result fogvol__null_create_query(void *u, fogvol_handle *out)
{
    if (!((fogvol_null_backend *)u)->queries) return FOGVOL_ERROR_UNSUPPORTED;
    return fogvol__null_create(u, out);
}

static int fogvol__null_begin_query(void *u, fogvol_handle q)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    (void)q;
    s->queries_begun++;
    s->query_active++;
    return 1;
}

static void fogvol__null_end_query(void *u, fogvol_handle q)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    (void)q;
    s->queries_ended++;
    s->query_active--;
}

static int fogvol__null_query_result(void *u, fogvol_handle q, uint64_t *samples)
{
    fogvol_null_backend *s = (fogvol_null_backend *)u;
    (void)q;
    s->query_polls++;
    if (s->query_not_ready > 0) {
        s->query_not_ready--;
        return 0;
    }
    *samples = s->query_samples;
    return 1;
}

FOGVOL_API void fogvol_null_backend_init(fogvol_null_backend *state, fogvol_backend *table)
{
    if (!state || !table) return;
    memset(state, 0, sizeof *state);
    memset(table, 0, sizeof *table);
    table->user_data = state;
    table->dialect = FOGVOL_GLSL_330;
    table->caps = FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE | FOGVOL_CAP_MESH_LAYOUT |
                  FOGVOL_CAP_ATTACH_DEPTH;
    table->begin_frame = fogvol__null_begin_frame;
    table->end_frame = fogvol__null_end_frame;
    table->create_texture = fogvol__null_create_texture;
    table->destroy_texture = fogvol__null_destroy;
    table->create_target = fogvol__null_create_target;
    table->destroy_target = fogvol__null_destroy;
    table->create_program = fogvol__null_create_program;
    table->destroy_program = fogvol__null_destroy;
    table->create_mesh = fogvol__null_create_mesh;
    table->destroy_mesh = fogvol__null_destroy;
    table->begin_pass = fogvol__null_begin_pass;
    table->set_draw = fogvol__null_set_draw;
    table->draw_mesh = fogvol__null_draw_mesh;
    table->draw_fullscreen = fogvol__null_draw_fullscreen;
    table->end_pass = fogvol__null_end_pass;
    table->read_target = fogvol__null_read_target;
    table->target_attachment = fogvol__null_attachment;
    table->native_texture = fogvol__null_native;
    table->create_query = fogvol__null_create_query;
    table->destroy_query = fogvol__null_destroy;
    table->begin_query = fogvol__null_begin_query;
    table->end_query = fogvol__null_end_query;
    table->query_result = fogvol__null_query_result;
}

/* >>context =============================================================== */
/* The renderer's objects and the context: resolved configuration, targets, programs. */

/* The objects a context hands out (meshes, ramps, volume textures) are on a list of its own per kind
   (circular, the context's node the head), each object's node its first member, so that
   fogvol_destroy_context destroys those the caller did not. */
typedef struct fogvol__live {
    struct fogvol__live *prev, *next;
} fogvol__live;

struct fogvol_mesh {
    fogvol__live live;
    fogvol_handle handle;
    int vertex_count, index_count;
    int volume; /* 1: a valid closed hull (usable as a volume) */
    int convex; /* fogvol_mesh_report.convex */
    float bmin[3], bmax[3]; /* model-space bounds of the vertices (orthographic clip depth scale,
                               geometry composite's scissor) */
    float *planes;          /* convex == 1: the face planes (unit n, d: n.p <= d inside), 4 floats each, model
                               space, for fogvol__near_inside; NULL otherwise (or out of memory) */
    int nplanes;
    double plane_tol;       /* the convexity test's tolerance (model units) */
};

/* A program built for one configuration (fogvol_shader_desc.specialize) of one sample set; handle 0:
   it failed to build and the general program stands in. */
#define FOGVOL__SPEC_MAX 128

typedef struct fogvol__spec_program {
    fogvol_program program;
    unsigned bits;
    int ms;
    fogvol_handle handle;
    int64_t serial; /* the frame (fogvol__frame_state.serial) it was last built in */
} fogvol__spec_program;

struct fogvol_ramp {
    fogvol__live live;
    fogvol_handle texture;
    int width;
    float max_thickness;
    fogvol_blend blend;
    int colors;          /* EXTINCTION + FOG: may join the one-pass colour group (FOGVOL_VARIANT_COLORS) */
    int grey;            /* the same extinction in every channel */
    float sigma[3];      /* extinction per world unit and channel: density * extinction_color */
    float emit[3];       /* the colour, clamped to [0, 1] as the ramp texture holds it */
    float exp_rgba[4]; /* EXTINCTION over its whole range: the ramp's rgb (8-bit) and density, else 0 */
    float softness;    /* fogvol_ramp_desc.softness (0: hard edges) */
    /* its colour-ramp group in the frame being ended (fogvol__link_groups): valid while stamp is the
       frame's group_stamp; head and tail: its first and last volume in the frame's order */
    int64_t stamp;
    int head, tail;
    int64_t textured;  /* the frame (fogvol__frame_state.serial) in which a volume of it has a density or
                          colour texture: it leaves the one-pass colour group for that frame */
};

struct fogvol_volume_texture {
    fogvol__live live;
    fogvol_handle texture;
};

typedef struct fogvol__volume {
    const fogvol_mesh *mesh;
    const fogvol_ramp *ramp;
    float model[16];
    int negative;
    const fogvol_volume_texture *density, *color; /* NULL: none */
    float density_map[8], color_map[6];
    int next; /* the next volume of the same ramp in the frame's order, -1: none (fogvol__link_groups) */
    int near_inside; /* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST frames: 1 = it holds the projection's whole near
                        plane rectangle (fogvol__near_inside), the camera inside it */
} fogvol__volume;

typedef struct fogvol__light {
    const fogvol_mesh *mesh;
    float model[16];
    float rgb[3];
    float position[3], radius, edge; /* fogvol_light_desc.position, falloff_radius, edge_softness */
} fogvol__light;

typedef struct fogvol__occluder {
    const fogvol_mesh *mesh;
    fogvol_occluder_fn fn;
    void *user_data;
    float model[16];
} fogvol__occluder;

/* image-space effect programs: depth of field with 3, 6, 12, 24, 48 taps; outlines from depth, from
   depth and normals; distance fog */
#define FOGVOL__DOF_TAPSETS 5
#define FOGVOL__POST_PROGRAMS (FOGVOL__DOF_TAPSETS + 3)

/* Overflow counting: the occlusion queries of one frame (one per check pass), read when all are done. */
#define FOGVOL__QFRAMES 4

#define FOGVOL__QPER 32

typedef struct fogvol__qframe {
    fogvol_handle q[FOGVOL__QPER]; /* created on first use, reused */
    int64_t frame;
    int used, ok, pending;
    int band; /* FOGVOL_SPEEDUP_OVERFLOW_BANDS: the band checked, 0 .. FOGVOL_OVERFLOW_BANDS-1; -1: all */
    int samples; /* the frame's samples per pixel (0: single-sample): its check passes count samples */
    int discard; /* the frame is not counted (more check passes than queries, or a query refused), but the
                    queries it began still wait for the GPU before the record and they are used again */
} fogvol__qframe;

/* The configuration resolved at fogvol_create_context (count_broken: learned when a COUNT program
   fails to build). */
typedef struct fogvol__config {
    fogvol_encoding enc;
    fogvol_tier tier;
    unsigned variants;
    int dither;
    fogvol_msaa msaa;
    unsigned speedups_off;  /* fogvol_context_desc.disable_speedups */
    int inline_resolve;     /* FOGVOL_SPEEDUP_INLINE_RESOLVE: no RESOLVE pass, no T */
    int float_o;            /* FOGVOL_SPEEDUP_FLOAT_O: O is R32F (MRT, PS20) */
    int fetch_o;            /* FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH: faces read O from the framebuffer */
    int exact_sum;          /* FOGVOL_SPEEDUP_EXACT_SUM: groups may sum as 32-bit integers */
    fogvol_overflow_policy overflow_policy;
    int count_broken;       /* a COUNT program did not build: no FOGVOL_SPEEDUP_DEPTH_TEST from then on */
    int engine_test;        /* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: frames that fit may be drawn depth-tested (off
                               from then on when its programs or its RG32F target cannot be made) */
} fogvol__config;

/* What the context holds on the GPU: lookup textures, programs, render targets (and what O holds). */
typedef struct fogvol__gpu {
    fogvol_handle tex_rg, tex_blue, tex_dither;
    fogvol_handle prog[FOGVOL_PROGRAM_COUNT];
    fogvol_handle prog_alt[FOGVOL_PROGRAM_COUNT]; /* the other set (single-sample or per-sample), 0 = not built */
    int prog_ms, compile_samples;    /* prog holds the per-sample set; samples for fogvol__make_program */
    fogvol__spec_program spec[FOGVOL__SPEC_MAX];  /* specialised programs (FOGVOL_SPEEDUP_SPECIALIZE), first use */
    int nspec;
    fogvol_handle post_prog[FOGVOL__POST_PROGRAMS]; /* image-space effects, built on first use */
    fogvol_handle tgt_o, tgt_b, tgt_f, tgt_t; /* SINGLE: B is the one sum target; PS13: T resolved;
                                                 FLOAT: B is the float sum */
    fogvol_handle tgt_o2, tgt_b2, tgt_f2;     /* WIDE: the second attachments */
    fogvol_handle tgt_c, tgt_c2;              /* COLORS: optical depth and emission sums (RGBA32F) */
    fogvol_handle tgt_e; /* ENGINE_DEPTH_TEST: the depth sum and face count (RG32F) in the window's (the
                            engine depth's) texel coordinates, e_w x e_h, grown as viewports need (fogvol__window_e) */
    int e_w, e_h, e_samples, e_refused; /* e_refused: a sample count (> 1) the backend made no E of */
    fogvol_handle tgt_v; /* overflow mask written by the check passes (SINGLE: with depth) */
    fogvol_handle tgt_l; /* the lights' front depth L (R32F on FLOAT, else encoded RGBA8) */
    int target_w, target_h;
    int target_half;      /* the targets are for fogvol_frame_desc.downsample 2 (FLOAT: B made linear) */
    int target_filtered;  /* ... and B is filtered by the backend (else the composite reads four texels) */
    int target_samples;   /* the targets' samples per pixel (0: single-sample) */
    int o_far;            /* O holds the far plane only (cleared, nothing drawn since) */
} fogvol__gpu;

/* The frame between fogvol_begin_frame and fogvol_end_frame / fogvol_cancel_frame: its desc, camera,
   volumes, occluders and lights. */
typedef struct fogvol__frame_state {
    int64_t serial; /* fogvol_begin_frame calls (ramps mark the frame their volumes are textured in) */
    int in_frame, in_occluder_pass, mrt_ready;
    int engine_occluders; /* fogvol_occluder_prepare: the engine draws O */
    int debug_gone;       /* frame.debug_ramp was destroyed inside the frame: its read-back writes 0 */
    int prepared_samples; /* the sample count O was made with at fogvol_occluder_prepare / fogvol_mrt_prepare */
    fogvol_frame_desc frame;
    double viewproj[16];
    double eyerow[4];  /* view depth e = dot(eyerow, (world position, 1)) */
    double invvp[16];  /* inverse of viewproj (engine depth texture) */
    double wscale;     /* perspective: clip w = wscale * e; 0 for orthographic */
    double wconst;     /* orthographic: clip w (constant > 0) */
    int mirrored;      /* the projection mirrors the screen: front faces come out clockwise */
    int samples;       /* this frame's samples per pixel (0: single-sample) */
    fogvol__volume *vols;
    int nvol, capvol;
    fogvol__occluder *occ;
    int nocc, capocc;
    fogvol__light *lights;  /* fogvol_add_light, this frame */
    int nlight, caplight;
    int64_t group_stamp;    /* fogvol__link_groups: which end_frame the ramps' group lists belong to */
    int color_first;        /* the first volume of the one-pass colour group, -1: none (FOGVOL_VARIANT_COLORS) */
    int color_pos;          /* the colour group holds a positive volume */
} fogvol__frame_state;

/* Overflow counting across frames: the queries in flight, the last count, the bands. */
typedef struct fogvol__overflow_state {
    int counting, overflow_late, overflow_warned, qcur;
    int coarse;        /* the last ended frame's digit step was coarse (fogvol_frame_stats.depth_lsb) */
    int64_t frame_no, overflow_frame, overflow_epoch; /* epoch: first frame drawn with the current L */
    fogvol__qframe qf[FOGVOL__QFRAMES];
    int64_t band_count[FOGVOL_OVERFLOW_BANDS], band_frame[FOGVOL_OVERFLOW_BANDS]; /* -1: not counted */
} fogvol__overflow_state;

struct fogvol_context {
    fogvol_allocator alloc;
    fogvol_logger log;
    fogvol_backend be;
    int owns_backend;
    fogvol__live meshes, ramps, textures; /* the objects alive (fogvol__live), counted: */
    int live_meshes, live_ramps, live_textures;
    int msaa_warned;
    fogvol__config cfg;       /* resolved configuration */
    fogvol__gpu gpu;          /* GPU resources */
    fogvol__frame_state cur;  /* the frame being built */
    fogvol__overflow_state ovf; /* overflow counters */
};

/* The plan of one fogvol_end_frame: what the frame draws, resolved once (fogvol__plan_frame, >>end
   frame) from the tier's row, the variants, the context's speed-ups and the frame's input. The passes
   follow it; none of them asks which tier, variant or speed-up it is in. */
typedef struct fogvol__plan {
    int float_sums;   /* the row's sums are R32F: one signed pass per group (else RGBA8 digit sums) */
    int single;       /* SINGLE_TARGET: back faces up and front faces down in one biased sum S */
    int wide;         /* WIDE: six digits over two attachments (decoded without offset) */
    int count;        /* faces depth-tested against O, counts in alpha: COUNT, or a DEPTH_TEST frame */
    int own_o;        /* fogvol draws O (not where the engine wrote it: MRT, fogvol_occluder_prepare) */
    int o_engine;     /* ... by encoding the engine's depth full-screen (ENGINE_DEPTH on a tier with O) */
    int engine_read;  /* the faces, lights and colour sums read the engine's depth (ENGINE_DEPTH, no O) */
    int no_opaque;    /* FOGVOL_SPEEDUP_SKIP_OPAQUE: no occluder, O is the far plane */
    int float_o;      /* O is R32F (the FLOAT tier, FOGVOL_SPEEDUP_FLOAT_O) */
    int resolve;      /* B - F resolved into T in a pass of its own (PS13 without INLINE_RESOLVE) */
    int fetch_o;      /* the faces read O from the framebuffer (FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH) */
    int exact_sum;    /* a group may sum in 32-bit integers (EXACT_SUM; fogvol__group decides per group) */
    int borrow;       /* the decode's alpha digit borrows (not with counts in alpha, PS13's or WIDE's) */
    int skip_check;   /* FOGVOL_SPEEDUP_SKIP_CHECK: groups that cannot saturate skip the check pass */
    int colors;       /* FOGVOL_VARIANT_COLORS: the one-pass colour group */
    int engine_test;  /* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: faces depth-tested against the engine's depth into
                         (+-d, +-1), the composite takes r - o g (fogvol__engine_test_frame) */
    int z_greater;    /* ... the test is GREATER (the engine's window depth falls with view depth) */
    double zmap[2];   /* ... the faces' clip z = zmap[0] z + zmap[1] w: the engine's window depth in fogvol's passes */
    int exp_composite, fast_exp, blend_color; /* the composite's speed-ups */
    float near_clamp; /* fv_misc.w: NEAR_CLAMP */
    unsigned origin_bit, dither_bit, count_bit, depth_from_z_bit; /* SPECIALIZE bits of the passes */
} fogvol__plan;

/* One fogvol_end_frame: what its passes share. */
typedef struct fogvol__run {
    fogvol__plan p;
    fogvol_frame_stats st;
    fogvol_frame_info info;
    fogvol_pass base;        /* target-space pass state holding the frame's uniforms and lookup textures */
    fogvol_native engine_depth;  /* ENGINE_DEPTH: the engine's depth texture (or fogvol's copy of it) */
    fogvol_handle e;             /* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: this frame's E (tgt_e) */
    int w, h;
    int counted, checks, fresh; /* overflow: query-counted check passes, any check pass, a new count */
    int captured, overflow;     /* debug read-back done; its overflow pixel count */
    fogvol_result r;            /* the last error that did not stop the frame */
    int xsum;                   /* FOGVOL_SPEEDUP_EXACT_SUM: the current group sums as 32-bit integers */
    int rect[4];                /* the current group's window rectangle; rect[2] = 0: not scissored */
} fogvol__run;

/* The overflow section's entry points, which the context and the passes call before it. */
static void fogvol__overflow_init(fogvol_context *ctx, fogvol_overflow_policy policy);
static fogvol_result fogvol__ensure_checks(fogvol_context *ctx);
static void fogvol__check_pass(fogvol_context *ctx, const fogvol__run *run, const fogvol_pass *base, int first,
                               fogvol_frame_stats *st);

static void fogvol__destroy_targets(fogvol_context *ctx)
{
    /* targets that share O's depth go first */
    if (ctx->gpu.tgt_b) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_b);
    if (ctx->gpu.tgt_f) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_f);
    if (ctx->gpu.tgt_t) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_t);
    if (ctx->gpu.tgt_v) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_v);
    if (ctx->gpu.tgt_l) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_l);
    if (ctx->gpu.tgt_c) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_c);
    if (ctx->gpu.tgt_e) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_e);
    ctx->gpu.tgt_v = ctx->gpu.tgt_l = ctx->gpu.tgt_c = ctx->gpu.tgt_c2 = ctx->gpu.tgt_e = 0;
    ctx->gpu.e_w = ctx->gpu.e_h = ctx->gpu.e_samples = ctx->gpu.e_refused = 0;
    if (ctx->gpu.tgt_o) ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_o);
    ctx->gpu.tgt_o = ctx->gpu.tgt_b = ctx->gpu.tgt_f = ctx->gpu.tgt_t = 0;
    ctx->gpu.tgt_o2 = ctx->gpu.tgt_b2 = ctx->gpu.tgt_f2 = 0;
    ctx->gpu.target_w = ctx->gpu.target_h = 0;
    ctx->gpu.o_far = 0;
}

static int fogvol__has(const fogvol_context *ctx, unsigned variant) { return (ctx->cfg.variants & variant) != 0; }

/* A refusal of a public call: logged (error level) with why, the result returned, so that no refusal
   goes unexplained. */
static fogvol_result fogvol__refuse(const fogvol_context *ctx, fogvol_result r, const char *why)
{
    fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: %s (%s)", why, fogvol_result_string(r));
    return r;
}

/* An object joins (count +1) or leaves (count -1) its kind's list. */
static void fogvol__live_add(fogvol__live *head, fogvol__live *n, int *count)
{
    n->prev = head;
    n->next = head->next;
    head->next->prev = n;
    head->next = n;
    (*count)++;
}

static void fogvol__live_remove(fogvol__live *n, int *count)
{
    n->prev->next = n->next;
    n->next->prev = n->prev;
    n->prev = n->next = n;
    (*count)--;
}

/* After the backend calls of a public call (outside a backend frame, or after its end_frame): the
   backend's own failure since the last take (fogvol_backend.take_error, logged by the backend) is the
   call's result when the call had none of its own. */
static fogvol_result fogvol__be_result(fogvol_context *ctx, fogvol_result r)
{
    fogvol_result e = ctx->be.take_error ? ctx->be.take_error(ctx->be.user_data) : FOGVOL_SUCCESS;
    return r == FOGVOL_SUCCESS ? e : r;
}

/* The FLOAT tier's targets: O (R32F with depth, unless the engine's depth is read), the signed sum B
   (filtered at half resolution where the backend can), COLORS' two RGBA32F sums. */
static fogvol_result fogvol__float_targets(fogvol_context *ctx, fogvol_target_desc td, int half)
{
    fogvol_result r = FOGVOL_SUCCESS;
    td.format = FOGVOL_FORMAT_R32F;
    if (fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_ENCODE)) {
        td.depth = 1;
        td.label = "fogvol O (opaque depth, float)";
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_o);
    }
    td.depth = 0;
    td.label = "fogvol signed depth sum (float)";
    td.linear = half && (ctx->be.caps & FOGVOL_CAP_FILTER_FLOAT); /* downsample 2: read bilinearly */
    if (r == FOGVOL_SUCCESS) r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_b);
    ctx->gpu.target_filtered = r == FOGVOL_SUCCESS && td.linear;
    if (r == FOGVOL_ERROR_UNSUPPORTED && td.linear) {
        fogvol__log(&ctx->log, FOGVOL_LOG_INFO, "fogvol: the backend cannot filter the half-resolution sum: "
                                                "the composite reads four texels instead");
        td.linear = 0;
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_b);
    }
    td.linear = 0;
    if (r == FOGVOL_SUCCESS && fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_COLORS)) {
        td.format = FOGVOL_FORMAT_RGBA32F;
        td.color_count = 2;
        td.label = "fogvol optical depth + emission sums (float, two attachments)";
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_c);
        if (r == FOGVOL_SUCCESS && !(ctx->gpu.tgt_c2 = ctx->be.target_attachment(ctx->be.user_data, ctx->gpu.tgt_c, 1)))
            r = FOGVOL_ERROR_BACKEND;
    }
    return r;
}

/* The RGBA8 tiers' targets: O (its depth shared with the sums where faces are depth-tested), B and F
   (or S), T for PS13's resolve pass, WIDE's second attachments. */
static fogvol_result fogvol__digit_targets(fogvol_context *ctx, fogvol_target_desc td)
{
    fogvol_result r;
    /* O's depth buffer: not where the engine writes O with its own depth (MRT) */
    td.depth = fogvol__tier(ctx->cfg.tier)->off[FOGVOL__F_ENCODE] != FOGVOL__NEVER;
    td.color_count = fogvol__has(ctx, FOGVOL_VARIANT_WIDE) ? 2 : 1;
    td.label = ctx->cfg.float_o ? "fogvol O (opaque depth, float)" : "fogvol O (opaque depth)";
    td.format = ctx->cfg.float_o ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8;
    r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_o);
    td.format = FOGVOL_FORMAT_RGBA8;
    td.depth = 0;
    if (fogvol__has(ctx, FOGVOL_VARIANT_COUNT) || fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_DEPTH_TEST))
        td.share_depth = ctx->gpu.tgt_o; /* faces depth-tested (COUNT, FOGVOL_SPEEDUP_DEPTH_TEST) */
    td.label = fogvol__has(ctx, FOGVOL_VARIANT_SINGLE_TARGET) ? "fogvol S (biased sum)" : "fogvol B (back faces)";
    if (r == FOGVOL_SUCCESS) r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_b);
    td.label = "fogvol F (front faces)";
    if (r == FOGVOL_SUCCESS && !fogvol__has(ctx, FOGVOL_VARIANT_SINGLE_TARGET))
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_f);
    td.share_depth = 0;
    td.color_count = 1;
    td.label = "fogvol T (resolved thickness)";
    if (r == FOGVOL_SUCCESS && fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_RESOLVE) &&
        !ctx->cfg.inline_resolve)
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_t);
    if (r == FOGVOL_SUCCESS && fogvol__has(ctx, FOGVOL_VARIANT_WIDE)) {
        ctx->gpu.tgt_o2 = ctx->be.target_attachment(ctx->be.user_data, ctx->gpu.tgt_o, 1);
        ctx->gpu.tgt_b2 = ctx->be.target_attachment(ctx->be.user_data, ctx->gpu.tgt_b, 1);
        ctx->gpu.tgt_f2 = ctx->be.target_attachment(ctx->be.user_data, ctx->gpu.tgt_f, 1);
        if (!ctx->gpu.tgt_o2 || !ctx->gpu.tgt_b2 || !ctx->gpu.tgt_f2) r = FOGVOL_ERROR_BACKEND;
    }
    return r;
}

static fogvol_result fogvol__ensure_targets(fogvol_context *ctx, int w, int h, int half)
{
    fogvol_target_desc td;
    fogvol_result r;
    if (ctx->gpu.tgt_b && ctx->gpu.target_w == w && ctx->gpu.target_h == h && ctx->gpu.target_samples == ctx->cur.samples &&
        ctx->gpu.target_half == half) /* (B: every tier has it; FLOAT + ENGINE_DEPTH has no O) */
        return FOGVOL_SUCCESS;
    fogvol__destroy_targets(ctx);
    ctx->gpu.target_half = half;
    ctx->gpu.target_filtered = 0;
    memset(&td, 0, sizeof td);
    td.width = w;
    td.height = h;
    td.samples = ctx->cur.samples;
    r = fogvol__tier(ctx->cfg.tier)->sum_format == FOGVOL_FORMAT_R32F ? fogvol__float_targets(ctx, td, half)
                                                                     : fogvol__digit_targets(ctx, td);
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot create %dx%d render targets: %s", w, h,
                    fogvol_result_string(r));
        fogvol__destroy_targets(ctx);
        return r;
    }
    ctx->gpu.target_w = w;
    ctx->gpu.target_h = h;
    ctx->gpu.target_samples = ctx->cur.samples;
    return FOGVOL_SUCCESS;
}

static void fogvol__query_free(fogvol_context *ctx)
{
    int i, k;
    for (i = 0; i < FOGVOL__QFRAMES; ++i)
        for (k = 0; k < FOGVOL__QPER; ++k)
            if (ctx->ovf.qf[i].q[k]) ctx->be.destroy_query(ctx->be.user_data, ctx->ovf.qf[i].q[k]);
}

static void fogvol__release(fogvol_context *ctx)
{
    int i;
    fogvol__query_free(ctx);
    fogvol__destroy_targets(ctx);
    for (i = 0; i < FOGVOL_PROGRAM_COUNT; ++i)
        if (ctx->gpu.prog[i]) ctx->be.destroy_program(ctx->be.user_data, ctx->gpu.prog[i]);
    for (i = 0; i < FOGVOL_PROGRAM_COUNT; ++i)
        if (ctx->gpu.prog_alt[i]) ctx->be.destroy_program(ctx->be.user_data, ctx->gpu.prog_alt[i]);
    for (i = 0; i < ctx->gpu.nspec; ++i)
        if (ctx->gpu.spec[i].handle) ctx->be.destroy_program(ctx->be.user_data, ctx->gpu.spec[i].handle);
    for (i = 0; i < FOGVOL__POST_PROGRAMS; ++i)
        if (ctx->gpu.post_prog[i]) ctx->be.destroy_program(ctx->be.user_data, ctx->gpu.post_prog[i]);
    if (ctx->gpu.tex_rg) ctx->be.destroy_texture(ctx->be.user_data, ctx->gpu.tex_rg);
    if (ctx->gpu.tex_blue) ctx->be.destroy_texture(ctx->be.user_data, ctx->gpu.tex_blue);
    if (ctx->gpu.tex_dither) ctx->be.destroy_texture(ctx->be.user_data, ctx->gpu.tex_dither);
    fogvol__free(&ctx->alloc, ctx->cur.vols);
    fogvol__free(&ctx->alloc, ctx->cur.occ);
    fogvol__free(&ctx->alloc, ctx->cur.lights);
    if (ctx->owns_backend && ctx->be.destroy) ctx->be.destroy(ctx->be.user_data);
}

static fogvol_result fogvol__make_texture(fogvol_context *ctx, int which, fogvol_handle *out)
{
    fogvol_image info;
    fogvol_texture_desc td;
    unsigned char *px;
    fogvol_result r;
    const char *const labels[3] = {"fogvol red+green ramp", "fogvol blue dither ramp", "fogvol dither index"};
    r = which == 0 ? fogvol_make_rg_ramp(&ctx->cfg.enc, NULL, 0, &info)
                   : which == 1 ? fogvol_make_blue_ramp(&ctx->cfg.enc, NULL, 0, &info)
                                : fogvol_make_dither_index(&ctx->cfg.enc, NULL, 0, &info);
    if (r != FOGVOL_SUCCESS) return r;
    px = (unsigned char *)fogvol__alloc(&ctx->alloc, info.size);
    if (!px) return FOGVOL_ERROR_OUT_OF_MEMORY;
    r = which == 0 ? fogvol_make_rg_ramp(&ctx->cfg.enc, px, info.size, &info)
                   : which == 1 ? fogvol_make_blue_ramp(&ctx->cfg.enc, px, info.size, &info)
                                : fogvol_make_dither_index(&ctx->cfg.enc, px, info.size, &info);
    if (r == FOGVOL_SUCCESS) {
        memset(&td, 0, sizeof td);
        td.width = info.width;
        td.height = info.height;
        td.pixels = px;
        td.filter = FOGVOL_FILTER_NEAREST;
        td.wrap = FOGVOL_WRAP_REPEAT;
        td.label = labels[which];
        r = ctx->be.create_texture(ctx->be.user_data, &td, out);
    }
    fogvol__free(&ctx->alloc, px);
    return r;
}

/* Texture units of fogvol's programs, as fogvol__make_program binds their samplers. The encode and
   face programs read the lookup textures and the opaque depth; the resolve, check and composite
   programs read the sums. */
enum {
    FOGVOL__UNIT_RG = 0,      /* fv_rg: red/green ramp of the encoding */
    FOGVOL__UNIT_BLUE = 1,    /* fv_blue: blue ramp (low digits, dithered) */
    FOGVOL__UNIT_DITHER = 2,  /* fv_dither: the dither pattern */
    FOGVOL__UNIT_OPAQUE = 3,  /* fv_opaque: encoded opaque depth O (or the engine's depth texture) */
    FOGVOL__UNIT_OPAQUE2 = 4, /* fv_opaque2: WIDE, O's second attachment */
    FOGVOL__UNIT_DENSITY = 6, /* fv_density: FACE, the volume's density texture */
    FOGVOL__UNIT_LFRONT = 7   /* fv_lfront: LIGHT, the light's front depth L */
};

enum {
    FOGVOL__UNIT_BACK = 0,    /* fv_back: sum of back faces B (PS13: the resolved difference T) */
    FOGVOL__UNIT_FRONT = 1,   /* fv_front: sum of front faces F (SINGLE_TARGET: the overflow mask V) */
    FOGVOL__UNIT_RAMP = 2,    /* fv_colors: the ramp's colour texture */
    FOGVOL__UNIT_COUNTS = 3,  /* fv_opaque: COUNT, the opaque depth O whose alpha holds the counts */
    FOGVOL__UNIT_BACK2 = 4,   /* fv_back2, fv_front2: WIDE, second attachments */
    FOGVOL__UNIT_FRONT2 = 5,
    FOGVOL__UNIT_CTEX = 6     /* fv_ctex: the group's colour texture */
};

/* fogvol_tier_uses_program for this context: no RESOLVE with FOGVOL_SPEEDUP_INLINE_RESOLVE */
static int fogvol__uses_program(const fogvol_context *ctx, fogvol_program p)
{
    return fogvol_tier_uses_program(ctx->cfg.tier, ctx->cfg.variants, p) && !(p == FOGVOL_PROGRAM_RESOLVE && ctx->cfg.inline_resolve);
}

static fogvol_result fogvol__make_program(fogvol_context *ctx, fogvol_program p, unsigned specialize,
                                          fogvol_handle *out)
{
    static const char *const samp_encode[FOGVOL_MAX_TEXTURE_UNITS] = {
        "fv_rg", "fv_blue", "fv_dither", "fv_opaque", "fv_opaque2", NULL, "fv_density", "fv_lfront"};
    static const char *const samp_comp[FOGVOL_MAX_TEXTURE_UNITS] = {"fv_back",   "fv_front", "fv_colors",
                                                                    "fv_opaque", "fv_back2", "fv_front2",
                                                                    "fv_ctex",   NULL};
    static const char *const labels[FOGVOL_PROGRAM_COUNT] = {
        "fogvol encode", "fogvol face", "fogvol composite", "fogvol composite (geometry)", "fogvol resolve",
        "fogvol overflow check", "fogvol light", "fogvol colour face", "fogvol colour composite"};
    fogvol_program_desc pd;
    fogvol_shader_desc sd;
    fogvol_result r;
    int i;
    memset(&pd, 0, sizeof pd);
    sd.tier = ctx->cfg.tier;
    sd.variants = ctx->cfg.variants;
    sd.program = p;
    sd.dialect = ctx->be.dialect;
    sd.samples = ctx->gpu.compile_samples;
    sd.specialize = specialize;
    if (ctx->cfg.inline_resolve && (p == FOGVOL_PROGRAM_COMPOSITE || p == FOGVOL_PROGRAM_COMPOSITE_MESH ||
                                p == FOGVOL_PROGRAM_CHECK))
        sd.specialize |= FOGVOL_SPECIALIZE_INLINE_RESOLVE; /* the general programs too: there is no T */
    if (ctx->cfg.float_o && (p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_LIGHT || p == FOGVOL_PROGRAM_ENCODE))
        sd.specialize |= FOGVOL_SPECIALIZE_FLOAT_O; /* the general programs too: O is R32F */
    sd.stage = FOGVOL_STAGE_VERTEX;
    r = fogvol_shader_strings(&sd, pd.vs, &pd.vs_count);
    sd.stage = FOGVOL_STAGE_FRAGMENT;
    if (r == FOGVOL_SUCCESS) r = fogvol_shader_strings(&sd, pd.fs, &pd.fs_count);
    if (r == FOGVOL_SUCCESS && (ctx->cfg.speedups_off & FOGVOL_SPEEDUP_TEXEL_FETCH) &&
        pd.fs_count < FOGVOL_MAX_SHADER_STRINGS) { /* after the #version line: filtered target reads */
        memmove(pd.fs + 2, pd.fs + 1, (size_t)(pd.fs_count - 1) * sizeof pd.fs[0]);
        pd.fs[1] = "#define FV_NO_FETCH\n";
        pd.fs_count++;
    }
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: no %s shader for tier %s, variants 0x%x, GLSL %s",
                    labels[p], fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants, fogvol_dialect_name(ctx->be.dialect));
        return r;
    }
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i)
        pd.samplers[i] = (p == FOGVOL_PROGRAM_ENCODE || p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_LIGHT ||
                          p == FOGVOL_PROGRAM_COLOR_FACE)
                             ? samp_encode[i]
                             : samp_comp[i];
    if (p == FOGVOL_PROGRAM_ENCODE) pd.samplers[FOGVOL__UNIT_OPAQUE2] = NULL;
    if (p == FOGVOL_PROGRAM_ENCODE && !fogvol__has(ctx, FOGVOL_VARIANT_ENGINE_DEPTH))
        pd.samplers[FOGVOL__UNIT_OPAQUE] = NULL;
    pd.label = labels[p];
    (void)fogvol_dialect_layout(ctx->be.dialect, &pd.layout); /* (GL dialects: all -1) */
    r = ctx->be.create_program(ctx->be.user_data, &pd, out);
    if (r != FOGVOL_SUCCESS) {
        *out = 0;
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the backend did not build the %s program%s: %s", labels[p],
                    sd.samples ? " (per sample)" : "", fogvol_result_string(r));
    }
    return r;
}

/* Whether the backend can run tier t with variants v: the combination exists in its dialect, and it
   has the caps the tier needs (automatic: to be chosen by FOGVOL_TIER_AUTO) and those of the
   variants (two attachments for WIDE and COLORS, a depth texture for ENGINE_DEPTH). */
static int fogvol__backend_runs(const fogvol_context *ctx, fogvol_tier t, unsigned v, int automatic)
{
    const fogvol__tier_row *row = fogvol__tier(t);
    unsigned caps = ctx->be.caps, need = row->caps | (automatic ? row->auto_caps : 0u);
    if (fogvol_combination_supported(t, v, ctx->be.dialect) != FOGVOL_SUCCESS || (caps & need) != need) return 0;
    if ((v & (FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_COLORS)) &&
        (!(caps & FOGVOL_CAP_MRT) || !ctx->be.target_attachment))
        return 0;
    return !(v & FOGVOL_VARIANT_ENGINE_DEPTH) || (caps & FOGVOL_CAP_DEPTH_TEXTURE);
}

/* The tier: AUTO takes the first of FLOAT, MRT (when the engine writes O: desc->engine_mrt), PS20 and
   PS13 that the backend runs with the required variants; an explicit tier must run with them. Then
   each preferred variant joins where the tier, dialect and backend take it, and is left out (logged)
   where not. */
static fogvol_result fogvol__choose_tier(fogvol_context *ctx, const fogvol_context_desc *desc)
{
    static const fogvol_tier order[4] = {FOGVOL_TIER_FLOAT, FOGVOL_TIER_MRT, FOGVOL_TIER_PS20, FOGVOL_TIER_PS13};
    fogvol_tier t = desc->tier;
    unsigned v = desc->variants, bit;
    int i;
    for (i = 0; t == FOGVOL_TIER_AUTO && i < 4; ++i)
        if ((order[i] != FOGVOL_TIER_MRT || desc->engine_mrt) && fogvol__backend_runs(ctx, order[i], v, 1))
            t = order[i];
    if (t == FOGVOL_TIER_AUTO || !fogvol__backend_runs(ctx, t, v, 0)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                    "fogvol: %s%s with variants 0x%x does not run on this backend (GLSL %s, caps 0x%x); "
                    "variants the engine only prefers go in fogvol_context_desc.preferred_variants",
                    desc->tier == FOGVOL_TIER_AUTO ? "no tier" : "tier ",
                    desc->tier == FOGVOL_TIER_AUTO ? "" : fogvol_tier_name(t), v,
                    fogvol_dialect_name(ctx->be.dialect), ctx->be.caps);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    for (bit = 1u; bit & FOGVOL_VARIANT_ALL; bit <<= 1) {
        if (!(desc->preferred_variants & bit) || (v & bit)) continue;
        if (fogvol__backend_runs(ctx, t, v | bit, 0))
            v |= bit;
        else
            fogvol__log(&ctx->log, FOGVOL_LOG_INFO,
                        "fogvol: preferred variant 0x%x left out: tier %s with variants 0x%x does not take it here",
                        bit, fogvol_tier_name(t), v);
    }
    ctx->cfg.tier = t;
    ctx->cfg.variants = v;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_tier fogvol_context_tier(const fogvol_context *ctx, unsigned *variants)
{
    if (variants) *variants = ctx ? ctx->cfg.variants : 0;
    return ctx ? ctx->cfg.tier : FOGVOL_TIER_AUTO;
}

/* encoding_bits: 0 = the default (FOGVOL_DEFAULT_BITS; WIDE: FOGVOL_WIDE_EXACT_BITS, the most precise
   setting its fp32 arithmetic encodes exactly). Combinations that cannot sum correctly are refused. */
static fogvol_result fogvol__resolve_bits(const fogvol_context_desc *desc, int *bits)
{
    int wide = (desc->variants & FOGVOL_VARIANT_WIDE) != 0;
    int b = desc->encoding_bits ? desc->encoding_bits : (wide ? FOGVOL_WIDE_EXACT_BITS : FOGVOL_DEFAULT_BITS);
    if (b < 1 || b > 8) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR, "fogvol: encoding_bits %d outside 1..8", desc->encoding_bits);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (wide && b > FOGVOL_WIDE_EXACT_BITS) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR,
                    "fogvol: WIDE with encoding_bits %d needs %d-bit digits, beyond what fp32 fragment arithmetic "
                    "encodes exactly; use encoding_bits <= %d (0 picks %d)",
                    b, 6 * b, FOGVOL_WIDE_EXACT_BITS, FOGVOL_WIDE_EXACT_BITS);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if ((desc->variants & FOGVOL_VARIANT_SINGLE_TARGET) && b >= 8) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR,
                    "fogvol: SINGLE_TARGET with encoding_bits 8 sums no face (the mid-range bias needs a carry bit); "
                    "use encoding_bits <= 7");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    *bits = b;
    return FOGVOL_SUCCESS;
}

/* The context desc checked and its defaults resolved (encoding bits); logged when refused. */
static fogvol_result fogvol__context_desc(const fogvol_context_desc *desc, int *bits)
{
    const fogvol_allocator *a = &desc->allocator;
    fogvol_result r;
    if ((a->alloc != NULL) != (a->free != NULL)) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR, "fogvol: allocator needs both alloc and free");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if ((int)desc->tier < 0 || (int)desc->tier >= FOGVOL_TIER_COUNT ||
        (desc->variants & ~(unsigned)FOGVOL_VARIANT_ALL) ||
        (desc->msaa != FOGVOL_MSAA_AUTO && desc->msaa != FOGVOL_MSAA_SINGLE_SAMPLE)) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR, "fogvol: unknown tier %d, variants 0x%x or msaa %d",
                    (int)desc->tier, desc->variants, (int)desc->msaa);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__resolve_bits(desc, bits);
    if (r == FOGVOL_SUCCESS && (unsigned)desc->overflow_policy > (unsigned)FOGVOL_OVERFLOW_OFF) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR, "fogvol: unknown overflow_policy %d", (int)desc->overflow_policy);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    return r;
}

/* ctx->be: the engine's backend table (every required entry present) or, without one, the GL backend. */
static fogvol_result fogvol__attach_backend(fogvol_context *ctx, const fogvol_context_desc *desc)
{
    const fogvol_backend *b = &desc->backend;
    if (b->create_texture) {
        if (!b->destroy_texture || !b->create_target || !b->destroy_target || !b->create_program ||
            !b->destroy_program || !b->create_mesh || !b->destroy_mesh || !b->begin_pass || !b->draw_mesh ||
            !b->draw_fullscreen || !b->set_draw) {
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: backend table lacks a required entry");
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        }
        if ((int)b->dialect < 0 || (int)b->dialect >= FOGVOL_GLSL_COUNT) {
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: unknown GLSL dialect %d in the backend table "
                        "(FOGVOL_GLSL_*)", (int)b->dialect);
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        }
        ctx->be = *b;
        return FOGVOL_SUCCESS;
    }
#ifndef FOGVOL_NO_GL
    {
        fogvol_result r = fogvol_gl_backend_create(&desc->gl, &ctx->alloc, &ctx->log, &ctx->be);
        ctx->owns_backend = r == FOGVOL_SUCCESS;
        return r;
    }
#else
    fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: no backend table and FOGVOL_NO_GL is defined");
    return FOGVOL_ERROR_INVALID_ARGUMENT;
#endif
}

/* The tier's lookup textures and programs. COMPOSITE_MESH is for engines only (the geometry composite
   is scissored); CHECK is made when a frame first runs a check pass. */
static fogvol_result fogvol__context_resources(fogvol_context *ctx)
{
    fogvol_result r = FOGVOL_SUCCESS;
    int i;
    if (ctx->cfg.tier != FOGVOL_TIER_FLOAT) {
        if (!fogvol__has(ctx, FOGVOL_VARIANT_ALU | FOGVOL_VARIANT_WIDE)) {
            r = fogvol__make_texture(ctx, 0, &ctx->gpu.tex_rg);
            if (r == FOGVOL_SUCCESS) r = fogvol__make_texture(ctx, 1, &ctx->gpu.tex_blue);
        }
        if (r == FOGVOL_SUCCESS) r = fogvol__make_texture(ctx, 2, &ctx->gpu.tex_dither);
    }
    /* COMPOSITE_MESH: for engines only (the geometry composite is scissored); CHECK: made when a
       frame first runs a check pass; LIGHT: when a frame first draws a light */
    for (i = 0; i < FOGVOL_PROGRAM_COUNT && r == FOGVOL_SUCCESS; ++i)
        if (fogvol__uses_program(ctx, (fogvol_program)i) && i != FOGVOL_PROGRAM_COMPOSITE_MESH &&
            i != FOGVOL_PROGRAM_CHECK && i != FOGVOL_PROGRAM_LIGHT) {
            r = fogvol__make_program(ctx, (fogvol_program)i, 0, &ctx->gpu.prog[i]);
            if (r != FOGVOL_SUCCESS && ctx->cfg.float_o) { /* the programs made so far again, for an RGBA8 O */
                int j;
                fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: a program for an R32F O did not build (%s); "
                                                           "O stays RGBA8 (FOGVOL_SPEEDUP_FLOAT_O off)",
                            fogvol_result_string(r));
                ctx->cfg.float_o = 0; /* (no target exists yet, and no specialised program) */
                for (j = 0; j < i; ++j)
                    if (ctx->gpu.prog[j]) {
                        ctx->be.destroy_program(ctx->be.user_data, ctx->gpu.prog[j]);
                        ctx->gpu.prog[j] = 0;
                    }
                r = FOGVOL_SUCCESS;
                i = -1;
            }
        }
    return r;
}

/* Whether the context runs speed-up sp (FOGVOL_SPEEDUP_*), whose feature f is in the tier's row:
   not turned off (disable_speedups) and on the tier with the context's variants. */
static int fogvol__speedup(const fogvol_context *ctx, unsigned sp, int f)
{
    return !(ctx->cfg.speedups_off & sp) && fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, f);
}

/* The speed-ups the context runs (after the tier): their rows in the tier table, the backend's caps
   and the programs they need (SPECIALIZE for those that are specialised programs). ALU: the variant
   joins where the dialect takes it. INLINE_RESOLVE: with fp32 fragment maths. FLOAT_O: where the
   backend renders R32F targets and the faces can read its float (MRT; PS20 with fp32; PS13 only where
   it sums in integers: its digits measured slower with it). EXACT_SUM: framebuffer fetch and fp32. */
static void fogvol__choose_speedups(fogvol_context *ctx)
{
    unsigned caps = ctx->be.caps, unspecialised = ctx->cfg.speedups_off & FOGVOL_SPEEDUP_SPECIALIZE;
    int highp = (caps & FOGVOL_CAP_HIGHP_FRAGMENT) != 0, fetch = (caps & FOGVOL_CAP_FRAMEBUFFER_FETCH) != 0;
    int exact;
    if (fogvol__speedup(ctx, FOGVOL_SPEEDUP_ALU, FOGVOL__F_ALU) &&
        fogvol_combination_supported(ctx->cfg.tier, ctx->cfg.variants | FOGVOL_VARIANT_ALU, ctx->be.dialect) ==
            FOGVOL_SUCCESS)
        ctx->cfg.variants |= FOGVOL_VARIANT_ALU;
    ctx->cfg.inline_resolve = highp && fogvol__speedup(ctx, FOGVOL_SPEEDUP_INLINE_RESOLVE, FOGVOL__F_INLINE_RESOLVE);
    exact = fetch && highp && !unspecialised && !(ctx->cfg.speedups_off & FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH) &&
            fogvol__speedup(ctx, FOGVOL_SPEEDUP_EXACT_SUM, FOGVOL__F_EXACT_SUM);
    ctx->cfg.float_o = (caps & FOGVOL_CAP_FLOAT_TARGET) &&
                       fogvol__speedup(ctx, FOGVOL_SPEEDUP_FLOAT_O, FOGVOL__F_FLOAT_O) &&
                       (ctx->cfg.tier == FOGVOL_TIER_MRT || highp) && (ctx->cfg.tier != FOGVOL_TIER_PS13 || exact);
    ctx->cfg.fetch_o = fetch && !unspecialised && fogvol__speedup(ctx, FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH, FOGVOL__F_FETCH_O);
    ctx->cfg.exact_sum = ctx->cfg.float_o && exact;
    ctx->cfg.engine_test = (caps & FOGVOL_CAP_ATTACH_DEPTH) && (caps & FOGVOL_CAP_FLOAT_BLEND) &&
                           (caps & FOGVOL_CAP_SOFTWARE_RENDERER) &&
                           fogvol__speedup(ctx, FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST, FOGVOL__F_ENGINE_TEST);
}

FOGVOL_API fogvol_result fogvol_create_context(const fogvol_context_desc *desc, fogvol_context **out)
{
    fogvol_context *ctx;
    fogvol_result r;
    int bits;
    if (!out) return FOGVOL_ERROR_INVALID_ARGUMENT;
    *out = NULL;
    if (!desc) return FOGVOL_ERROR_INVALID_ARGUMENT;
    r = fogvol__context_desc(desc, &bits);
    if (r != FOGVOL_SUCCESS) return r;
    ctx = (fogvol_context *)fogvol__alloc(&desc->allocator, sizeof *ctx);
    if (!ctx) {
        fogvol__log(&desc->logger, FOGVOL_LOG_ERROR, "fogvol: out of memory for the context");
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    memset(ctx, 0, sizeof *ctx);
    ctx->meshes.prev = ctx->meshes.next = &ctx->meshes;
    ctx->ramps.prev = ctx->ramps.next = &ctx->ramps;
    ctx->textures.prev = ctx->textures.next = &ctx->textures;
    ctx->alloc = desc->allocator;
    ctx->log = desc->logger;
    ctx->cfg.dither = !desc->disable_dither;
    ctx->cfg.speedups_off = desc->disable_speedups;
    ctx->cfg.msaa = desc->msaa;
    fogvol_encoding_init(bits, &ctx->cfg.enc);
    r = fogvol__attach_backend(ctx, desc);
    if (r != FOGVOL_SUCCESS) {
        fogvol__free(&desc->allocator, ctx);
        return r;
    }
    r = fogvol__choose_tier(ctx, desc);
    if (r == FOGVOL_SUCCESS) fogvol__choose_speedups(ctx);
    if (r == FOGVOL_SUCCESS) r = fogvol__context_resources(ctx);
    r = fogvol__be_result(ctx, r);
    if (r == FOGVOL_SUCCESS) fogvol__overflow_init(ctx, desc->overflow_policy);
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: context creation failed: %s", fogvol_result_string(r));
        fogvol__release(ctx);
        fogvol__free(&desc->allocator, ctx);
        return r;
    }
    fogvol__log(&ctx->log, FOGVOL_LOG_INFO,
                "fogvol: tier %s, variants 0x%x, %d-bit encoding (%d faces), GLSL %s, dither %s",
                fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants, ctx->cfg.enc.precision_bits,
                fogvol__has(ctx, FOGVOL_VARIANT_SINGLE_TARGET) ? ctx->cfg.enc.max_faces_single : ctx->cfg.enc.max_faces,
                fogvol_dialect_name(ctx->be.dialect), ctx->cfg.dither ? "on" : "off");
    *out = ctx;
    return FOGVOL_SUCCESS;
}

FOGVOL_API void fogvol_destroy_context(fogvol_context *ctx)
{
    fogvol_allocator a;
    if (!ctx) return;
    if (ctx->live_meshes || ctx->live_ramps || ctx->live_textures)
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: context destroyed with %d meshes, %d ramps and %d volume textures alive: destroyed with "
                    "it (destroy them before the context)",
                    ctx->live_meshes, ctx->live_ramps, ctx->live_textures);
    ctx->cur.in_frame = 0; /* (nothing to drop from an open frame: it goes too) */
    while (ctx->meshes.next != &ctx->meshes) fogvol_destroy_mesh(ctx, (fogvol_mesh *)(void *)ctx->meshes.next);
    while (ctx->ramps.next != &ctx->ramps) fogvol_destroy_ramp(ctx, (fogvol_ramp *)(void *)ctx->ramps.next);
    while (ctx->textures.next != &ctx->textures)
        fogvol_destroy_volume_texture(ctx, (fogvol_volume_texture *)(void *)ctx->textures.next);
    a = ctx->alloc;
    fogvol__release(ctx);
    fogvol__free(&a, ctx);
}

FOGVOL_API const fogvol_encoding *fogvol_context_encoding(const fogvol_context *ctx)
{
    return ctx ? &ctx->cfg.enc : NULL;
}

FOGVOL_API fogvol_result fogvol_set_dither(fogvol_context *ctx, int enabled)
{
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    ctx->cfg.dither = enabled != 0;
    return FOGVOL_SUCCESS;
}

/* Make ctx->gpu.prog the per-sample set (ms = 1) or the single-sample set, building its programs on
   first use and any that an earlier frame could not build. */
static fogvol_result fogvol__msaa_programs(fogvol_context *ctx, int ms)
{
    fogvol_handle t[FOGVOL_PROGRAM_COUNT];
    fogvol_result r = FOGVOL_SUCCESS;
    int i;
    if (ms != ctx->gpu.prog_ms) {
        memcpy(t, ctx->gpu.prog, sizeof t);
        memcpy(ctx->gpu.prog, ctx->gpu.prog_alt, sizeof t);
        memcpy(ctx->gpu.prog_alt, t, sizeof t);
        ctx->gpu.prog_ms = ms;
    }
    /* every frame: a program an earlier frame could not build is tried again (not left 0, drawn as none) */
    ctx->gpu.compile_samples = ms ? 2 : 0;
    /* (single-sample: CHECK, LIGHT and the mesh composite are made when first used, as at creation) */
    for (i = 0; i < FOGVOL_PROGRAM_COUNT && r == FOGVOL_SUCCESS; ++i)
        if (!ctx->gpu.prog[i] && fogvol__uses_program(ctx, (fogvol_program)i) &&
            (ms || (i != FOGVOL_PROGRAM_COMPOSITE_MESH && i != FOGVOL_PROGRAM_CHECK && i != FOGVOL_PROGRAM_LIGHT)))
            r = fogvol__make_program(ctx, (fogvol_program)i, 0, &ctx->gpu.prog[i]);
    ctx->gpu.compile_samples = 0;
    return r;
}

/* The program p built for this configuration (fogvol_shader_desc.specialize = bits) in the current
   sample set, made on first use (the GL backend builds programs inside a frame without disturbing
   it); the general program when specialising is off or the build failed (logged once). COUNT and
   DOWNSAMPLE are not options but other programs, built with SPECIALIZE off too. If COUNT cannot
   be, the frame is wrong and FOGVOL_SPEEDUP_DEPTH_TEST is off from the next frame on (logged); if
   DOWNSAMPLE cannot be, 0 (the caller skips the pass). fogvol__program_set: in sample set ms (0:
   single-sample, 1: per sample) rather than the frame's; outside the frame's set there is no general
   stand-in (0). */
static fogvol_handle fogvol__program_set(fogvol_context *ctx, fogvol_program p, unsigned bits, int ms)
{
    /* programs that have no general stand-in: 0 (DOWNSAMPLE: the pass is skipped; BLEND_COLOR: the
       caller asks again without it) */
    const unsigned none = FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_BLEND_COLOR | FOGVOL_SPECIALIZE_ENGINE_TEST;
    fogvol__spec_program *sp;
    fogvol_handle general = ms == ctx->gpu.prog_ms ? ctx->gpu.prog[p] : 0;
    int i;
    if (ctx->cfg.speedups_off & FOGVOL_SPEEDUP_SPECIALIZE) /* COUNT (and a COUNT face's NO_DENSITY), DOWNSAMPLE */
        bits &= ((bits & FOGVOL_SPECIALIZE_COUNT) ? FOGVOL_SPECIALIZE_COUNT | FOGVOL_SPECIALIZE_NO_DENSITY : 0u) |
                FOGVOL_SPECIALIZE_DOWNSAMPLE | FOGVOL_SPECIALIZE_FILTERED |
                ((bits & FOGVOL_SPECIALIZE_ENGINE_TEST) ? FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_NO_DENSITY : 0u);
    else if ((p == FOGVOL_PROGRAM_FACE || p == FOGVOL_PROGRAM_ENCODE) && ctx->cfg.tier != FOGVOL_TIER_FLOAT)
        bits |= FOGVOL_SPECIALIZE_ENCODING(ctx->cfg.enc.bits); /* the context's encoding compiled in */
    if (!bits) return general;
    for (i = 0; i < ctx->gpu.nspec; ++i) {
        sp = &ctx->gpu.spec[i];
        if (sp->program != p || sp->bits != bits || sp->ms != ms) continue;
        if (!sp->handle && (bits & FOGVOL_SPECIALIZE_DOWNSAMPLE) && sp->serial != ctx->cur.serial) {
            sp->serial = ctx->cur.serial; /* no stand-in, no other way: built again in each later frame */
            ctx->gpu.compile_samples = ms ? 2 : 0;
            if (fogvol__make_program(ctx, p, bits, &sp->handle) != FOGVOL_SUCCESS) sp->handle = 0;
            ctx->gpu.compile_samples = 0;
        }
        return sp->handle ? sp->handle : (bits & none) ? 0 : general;
    }
    if (ctx->gpu.nspec == FOGVOL__SPEC_MAX) {
        if ((bits & FOGVOL_SPECIALIZE_COUNT) && !(bits & FOGVOL_SPECIALIZE_BLEND_COLOR)) ctx->cfg.count_broken = 1;
        return (bits & none) ? 0 : general;
    }
    sp = &ctx->gpu.spec[ctx->gpu.nspec++];
    sp->program = p;
    sp->bits = bits;
    sp->ms = ms;
    sp->serial = ctx->cur.serial;
    ctx->gpu.compile_samples = ms ? 2 : 0;
    if (fogvol__make_program(ctx, p, bits, &sp->handle) != FOGVOL_SUCCESS) {
        int retried = (bits & FOGVOL_SPECIALIZE_BLEND_COLOR) != 0;
        sp->handle = 0;
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: the specialised program (0x%x) did not build; %s", bits,
                    retried ? "the composite takes its colour from the program instead of the blend unit"
                    : (bits & FOGVOL_SPECIALIZE_COUNT)
                        ? "the general program draws instead (this frame is wrong; FOGVOL_SPEEDUP_DEPTH_TEST is off "
                          "from now on)"
                        : "the general program draws instead");
        if ((bits & FOGVOL_SPECIALIZE_COUNT) && !retried) ctx->cfg.count_broken = 1;
    }
    ctx->gpu.compile_samples = 0;
    if (!sp->handle && (bits & none)) return 0;
    return sp->handle ? sp->handle : general;
}

static fogvol_handle fogvol__program(fogvol_context *ctx, fogvol_program p, unsigned bits)
{
    return fogvol__program_set(ctx, p, bits, ctx->gpu.prog_ms);
}

/* >>resources ============================================================= */
/* Meshes (upload, bounds, convexity), colour ramps and volume textures. */

/* A mesh destroyed inside a frame: the lights that use it leave the frame. */
static void fogvol__forget_lights(fogvol_context *ctx, const fogvol_mesh *mesh)
{
    int i, n = 0;
    if (!ctx->cur.in_frame) return;
    for (i = 0; i < ctx->cur.nlight; ++i)
        if (ctx->cur.lights[i].mesh != mesh) ctx->cur.lights[n++] = ctx->cur.lights[i];
    if (n != ctx->cur.nlight)
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: mesh destroyed inside a frame: %d lights that use it "
                    "are dropped from the frame", ctx->cur.nlight - n);
    ctx->cur.nlight = n;
}

/* The vertices the triangles use, each once (idx: the validated indices, all in range), in a list
   from ctx's allocator of *count entries; NULL: out of memory. A shared vertex buffer's other
   vertices are no part of the mesh: not in its bounds, not in its convexity. */
static uint32_t *fogvol__referenced(fogvol_context *ctx, const fogvol_mesh_desc *desc, const uint32_t *idx, int *count)
{
    int i, n = 0, ni = fogvol__index_count(desc), nv = desc->vertex_count;
    uint32_t *list = (uint32_t *)fogvol__alloc(&ctx->alloc, (sizeof(uint32_t) + 1u) * (size_t)nv);
    unsigned char *seen;
    *count = 0;
    if (!list) return NULL;
    seen = (unsigned char *)(list + nv);
    memset(seen, 0, (size_t)nv);
    for (i = 0; i < ni; ++i)
        if (!seen[idx[i]]) {
            seen[idx[i]] = 1;
            list[n++] = idx[i];
        }
    *count = n;
    return list;
}

/* The bounding box of the used vertices (finite: validated before). */
static void fogvol__mesh_box(fogvol_mesh *m, const fogvol_mesh_desc *desc, const uint32_t *used, int nused)
{
    size_t stride = (size_t)fogvol__mesh_stride(desc);
    const unsigned char *base = (const unsigned char *)desc->positions + desc->offset;
    int i, c;
    for (i = 0; i < nused; ++i) {
        float p[3];
        memcpy(p, base + (size_t)used[i] * stride, sizeof p);
        for (c = 0; c < 3; ++c) {
            if (i == 0 || p[c] < m->bmin[c]) m->bmin[c] = p[c];
            if (i == 0 || p[c] > m->bmax[c]) m->bmax[c] = p[c];
        }
    }
}

/* Hands the mesh to the backend: the engine's layout as it is to backends with
   FOGVOL_CAP_MESH_LAYOUT, else packed xyz and 32-bit indices (idx: the welded or
   widened indices, NULL = desc->indices). */
static fogvol_result fogvol__upload_mesh(fogvol_context *ctx, const fogvol_mesh_desc *desc, const uint32_t *idx,
                                         fogvol_handle *out)
{
    fogvol_mesh_data md;
    float *packed = NULL;
    fogvol_result r;
    int i, stride = fogvol__mesh_stride(desc);
    memset(&md, 0, sizeof md);
    md.positions = desc->positions;
    md.vertex_count = desc->vertex_count;
    md.indices = idx ? idx : desc->indices;
    md.index_count = fogvol__index_count(desc);
    if (ctx->be.caps & FOGVOL_CAP_MESH_LAYOUT) {
        md.stride = stride;
        md.offset = desc->offset;
        if (desc->index_type == FOGVOL_INDEX_UINT16 && desc->indices16 && desc->weld_distance <= 0) { /* as given */
            md.index_type = FOGVOL_INDEX_UINT16;
            md.indices16 = desc->indices16;
            md.indices = NULL;
        }
    } else if (stride != 12 || desc->offset != 0) {
        packed = (float *)fogvol__alloc(&ctx->alloc, sizeof(float) * 3u * (size_t)desc->vertex_count);
        if (!packed) return FOGVOL_ERROR_OUT_OF_MEMORY;
        for (i = 0; i < desc->vertex_count; ++i)
            memcpy(packed + 3 * i, (const unsigned char *)desc->positions + desc->offset + (size_t)i * stride, 12);
        md.positions = packed;
    }
    r = ctx->be.create_mesh(ctx->be.user_data, &md, out);
    fogvol__free(&ctx->alloc, packed);
    return r;
}

static void fogvol__vertex(const fogvol_mesh_desc *desc, uint32_t i, double p[3])
{
    float f[3];
    size_t stride = (size_t)fogvol__mesh_stride(desc);
    memcpy(f, (const unsigned char *)desc->positions + desc->offset + (size_t)i * stride, sizeof f);
    p[0] = f[0];
    p[1] = f[1];
    p[2] = f[2];
}

/* The convexity test's point tree: the used vertices (3 doubles each) permuted so that node i (root
   1, children 2i and 2i + 1) holds the points its range halving gives (a node of c points: the first
   c / 2 to its first child, the rest to its second), split at the median of its box's widest axis;
   nodes of at most FOGVOL__HULL_LEAF points are leaves. box: lo[3], hi[3] per node. */
#define FOGVOL__HULL_LEAF 8

/* The nodes of the tree over n points (the size of its box array in nodes). */
static size_t fogvol__hull_nodes(int n)
{
    int depth = 0;
    while (n > FOGVOL__HULL_LEAF) {
        n -= n / 2;
        ++depth;
    }
    return (size_t)2 << depth;
}

static void fogvol__pts_swap(double *a, double *b)
{
    double t[3];
    memcpy(t, a, sizeof t);
    memcpy(a, b, sizeof t);
    memcpy(b, t, sizeof t);
}

/* Reorders pts[0 .. n) so that the point of rank m along axis ax is at m, none larger before it and
   none smaller after it (quickselect with a median-of-three pivot). */
static void fogvol__pts_select(double *pts, int n, int m, int ax)
{
    int lo = 0, hi = n - 1;
    while (hi > lo) {
        int i = lo, j = hi;
        double a = pts[3 * lo + ax], b = pts[3 * (lo + (hi - lo) / 2) + ax], c = pts[3 * hi + ax], piv;
        piv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        while (i <= j) {
            while (pts[3 * i + ax] < piv) ++i;
            while (pts[3 * j + ax] > piv) --j;
            if (i <= j) fogvol__pts_swap(pts + 3 * i++, pts + 3 * j--);
        }
        if (m <= j)
            hi = j;
        else if (m >= i)
            lo = i;
        else
            return;
    }
}

static void fogvol__pts_build(double *pts, double *box, size_t node, int first, int count)
{
    double *b = box + 6 * node;
    int i, k, ax = 0;
    for (k = 0; k < 3; ++k) b[k] = b[3 + k] = pts[3 * first + k];
    for (i = first + 1; i < first + count; ++i)
        for (k = 0; k < 3; ++k) {
            if (pts[3 * i + k] < b[k]) b[k] = pts[3 * i + k];
            if (pts[3 * i + k] > b[3 + k]) b[3 + k] = pts[3 * i + k];
        }
    if (count <= FOGVOL__HULL_LEAF) return;
    for (k = 1; k < 3; ++k)
        if (b[3 + k] - b[k] > b[3 + ax] - b[ax]) ax = k;
    fogvol__pts_select(pts + 3 * first, count, count / 2, ax);
    fogvol__pts_build(pts, box, 2 * node, first, count / 2);
    fogvol__pts_build(pts, box, 2 * node + 1, first + count / 2, count - count / 2);
}

/* 1 when some point lies more than tol in front of the plane through a with normal nr (of length
   len): (nr . (p - a)) / len > tol, decided per point in the leaves the plane's side reaches. A node
   whose box lies at most tol / 2 in front of the plane holds no such point (its corners bound every
   point; the rounding of either sum is some 1e-16 of |nr| times the box's size, far below tol / 2 =
   5e-6 of the diagonal), so it is skipped whole: the answer of testing every point, at the cost of
   the points near the plane. */
static int fogvol__pts_outside(const double *pts, const double *box, int n, const double nr[3], const double a[3],
                               double len, double tol)
{
    int stack[3 * 128], sp = 0, i, k;
    stack[sp++] = 1;
    stack[sp++] = 0;
    stack[sp++] = n;
    while (sp > 0) {
        int count = stack[--sp], first = stack[--sp], node = stack[--sp];
        const double *b = box + 6 * (size_t)node;
        double bound = 0.0;
        for (k = 0; k < 3; ++k) {
            double lo = nr[k] * (b[k] - a[k]), hi = nr[k] * (b[3 + k] - a[k]);
            bound += lo > hi ? lo : hi;
        }
        if (bound <= 0.5 * tol * len) continue;
        if (count <= FOGVOL__HULL_LEAF) {
            for (i = first; i < first + count; ++i) {
                const double *p = pts + 3 * i;
                if ((nr[0] * (p[0] - a[0]) + nr[1] * (p[1] - a[1]) + nr[2] * (p[2] - a[2])) / len > tol) return 1;
            }
            continue;
        }
        stack[sp++] = 2 * node; /* depth <= 31: at most 32 pending nodes */
        stack[sp++] = first;
        stack[sp++] = count / 2;
        stack[sp++] = 2 * node + 1;
        stack[sp++] = first + count / 2;
        stack[sp++] = count - count / 2;
    }
    return 0;
}

/* fogvol_mesh_report.convex of a valid hull: every used vertex on the inner side of every face plane
   (outward normals: counter-clockwise seen from outside), within 1e-5 of the used vertices' box
   diagonal; decided on the triangles as validated (idx: welded), where the slivers that a weld closes
   (repeated corners) have no plane. The used vertices are read once into doubles (pts: 3 per used
   vertex, then fogvol__hull_nodes(nused) boxes of 6) and put in a tree of boxes, which each face
   plane tests (fogvol__pts_outside). m->planes (room for a plane a triangle, or NULL) gets the planes,
   a run of coplanar triangles once, and m->plane_tol the tolerance. */
static int fogvol__convexity(const fogvol_mesh_desc *desc, const uint32_t *idx, const uint32_t *used, int nused,
                             double *pts, fogvol_mesh *m)
{
    int t, v, k, tris = fogvol__index_count(desc) / 3;
    double *box = pts + 3 * (size_t)nused, diag = 0.0, tol;
    if ((double)tris * (double)nused > 67108864.0) return -1;
    if (nused == 0) return 1;
    for (v = 0; v < nused; ++v) fogvol__vertex(desc, used[v], pts + 3 * v);
    fogvol__pts_build(pts, box, 1, 0, nused);
    for (k = 0; k < 3; ++k) diag += (box[6 + 3 + k] - box[6 + k]) * (box[6 + 3 + k] - box[6 + k]);
    diag = FOGVOL_SQRT(diag);
    tol = 1e-5 * diag;
    m->plane_tol = tol;
    for (t = 0; t < tris; ++t) {
        double a[3], b[3], c[3], n[3], len;
        fogvol__vertex(desc, idx[3 * t], a);
        fogvol__vertex(desc, idx[3 * t + 1], b);
        fogvol__vertex(desc, idx[3 * t + 2], c);
        for (k = 0; k < 3; ++k) {
            b[k] -= a[k];
            c[k] -= a[k];
        }
        n[0] = b[1] * c[2] - b[2] * c[1];
        n[1] = b[2] * c[0] - b[0] * c[2];
        n[2] = b[0] * c[1] - b[1] * c[0];
        len = FOGVOL_SQRT(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-12 * diag * diag)) continue; /* degenerate: no plane */
        if (fogvol__pts_outside(pts, box, nused, n, a, len, tol)) return 0;
        if (m->planes) {
            float q[4], *last = m->nplanes ? m->planes + 4 * (m->nplanes - 1) : NULL;
            for (k = 0; k < 3; ++k) q[k] = (float)(n[k] / len);
            q[3] = (float)((n[0] * a[0] + n[1] * a[1] + n[2] * a[2]) / len);
            if (!last || memcmp(last, q, sizeof q) != 0) memcpy(m->planes + 4 * m->nplanes++, q, sizeof q);
        }
    }
    return 1;
}

/* fogvol_create_mesh's verdict on fogvol__check_mesh's result r and report: FOGVOL_SUCCESS (warnings
   logged) or the refusal, logged with what is wrong (idx is freed then). */
static fogvol_result fogvol__mesh_verdict(const fogvol_context *ctx, const fogvol_mesh_desc *desc, fogvol_result r,
                                          const fogvol_mesh_report *rep, uint32_t *idx)
{
    if (r == FOGVOL_ERROR_INVALID_ARGUMENT || r == FOGVOL_ERROR_OUT_OF_MEMORY) {
        const char *problem = fogvol__mesh_problem(desc);
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: create_mesh: %s%s%s", fogvol_result_string(r),
                    problem ? ": " : "", problem ? problem : "");
        return r;
    }
    if (rep->nonfinite_vertices || rep->out_of_range_indices || (r != FOGVOL_SUCCESS && !desc->allow_open)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                    "fogvol: mesh rejected: %d open edges, %d non-manifold edges, %d inconsistent edges, "
                    "%d flipped faces, %d non-finite vertices, %d indices out of range, %d probes in regions of "
                    "negative winding (a part wound inward that nothing encloses: triangle %d)%s%s",
                    rep->open_edges, rep->nonmanifold_edges, rep->inconsistent_edges, rep->flipped_faces,
                    rep->nonfinite_vertices, rep->out_of_range_indices, rep->negative_winding, rep->negative_triangle,
                    rep->inverted ? ", wound inward (reverse the triangles)" : "",
                    rep->open_edges && desc->weld_distance <= 0
                        ? " (vertices repeated at seams or per face? set fogvol_mesh_desc.weld_distance)"
                        : "");
        fogvol__free(&ctx->alloc, idx);
        return FOGVOL_ERROR_INVALID_MESH;
    }
    if (rep->degenerate_triangles)
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: mesh has %d degenerate triangles",
                    rep->degenerate_triangles);
    if (rep->welded_vertices)
        fogvol__log(&ctx->log, FOGVOL_LOG_INFO, "fogvol: weld merged %d of %d vertices", rep->welded_vertices,
                    desc->vertex_count);
    return FOGVOL_SUCCESS;
}

/* A new mesh's shape from its used vertices (idx: the validated triangles): bounds, convexity (valid
   hulls) and, convex, its face planes. 0: out of memory (logged, nothing allocated). */
static fogvol_mesh *fogvol__mesh_shape(fogvol_context *ctx, const fogvol_mesh_desc *desc, const uint32_t *idx, int valid)
{
    fogvol_mesh *m = (fogvol_mesh *)fogvol__alloc(&ctx->alloc, sizeof *m);
    uint32_t *used;
    double *pts;
    int nused;
    used = m ? fogvol__referenced(ctx, desc, idx, &nused) : NULL;
    pts = used ? (double *)fogvol__alloc(&ctx->alloc, sizeof(double) * (3u * (size_t)nused + 6u * fogvol__hull_nodes(nused)))
               : NULL;
    if (!m || !used || !pts) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: create_mesh: out of memory");
        fogvol__free(&ctx->alloc, used);
        fogvol__free(&ctx->alloc, m);
        return NULL;
    }
    memset(m, 0, sizeof *m);
    fogvol__mesh_box(m, desc, used, nused);
    if (valid) /* (without room for the planes the mesh is still convex, only never near_inside) */
        m->planes = (float *)fogvol__alloc(&ctx->alloc, sizeof(float) * 4u * (size_t)(fogvol__index_count(desc) / 3 + 1));
    m->convex = valid ? fogvol__convexity(desc, idx, used, nused, pts, m) : -1;
    if (m->convex != 1) {
        fogvol__free(&ctx->alloc, m->planes);
        m->planes = NULL;
        m->nplanes = 0;
    }
    fogvol__free(&ctx->alloc, pts);
    fogvol__free(&ctx->alloc, used);
    return m;
}

FOGVOL_API fogvol_result fogvol_create_mesh(fogvol_context *ctx, const fogvol_mesh_desc *desc, fogvol_mesh **out,
                                            fogvol_mesh_report *report)
{
    fogvol_mesh_report rep;
    fogvol_mesh *m;
    uint32_t *idx = NULL;
    fogvol_result r;
    if (out) *out = NULL;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc || !out) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "create_mesh: desc or out is NULL");
    r = fogvol__check_mesh(desc, &ctx->alloc, &rep, &idx);
    if (report) *report = rep;
    if ((r = fogvol__mesh_verdict(ctx, desc, r, &rep, idx)) != FOGVOL_SUCCESS) return r;
    m = fogvol__mesh_shape(ctx, desc, idx ? idx : desc->indices, rep.valid);
    if (!m) {
        fogvol__free(&ctx->alloc, idx);
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    r = fogvol__be_result(ctx, fogvol__upload_mesh(ctx, desc, idx, &m->handle));
    fogvol__free(&ctx->alloc, idx);
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: mesh upload failed: %s", fogvol_result_string(r));
        if (m->handle) ctx->be.destroy_mesh(ctx->be.user_data, m->handle);
        (void)fogvol__be_result(ctx, r);
        fogvol__free(&ctx->alloc, m->planes);
        fogvol__free(&ctx->alloc, m);
        return r;
    }
    m->vertex_count = desc->vertex_count;
    m->index_count = fogvol__index_count(desc);
    m->volume = rep.valid;
    if (report) report->convex = m->convex;
    fogvol__live_add(&ctx->meshes, &m->live, &ctx->live_meshes);
    *out = m;
    return FOGVOL_SUCCESS;
}

/* An open frame drops the volumes and occluders that use a mesh or ramp being
   destroyed; the rest of the frame stays. */
static void fogvol__forget(fogvol_context *ctx, const fogvol_mesh *mesh, const fogvol_ramp *ramp)
{
    int i, n = 0, dv, doc;
    if (!ctx->cur.in_frame) return;
    for (i = 0; i < ctx->cur.nvol; ++i)
        if (!((mesh && ctx->cur.vols[i].mesh == mesh) || (ramp && ctx->cur.vols[i].ramp == ramp))) ctx->cur.vols[n++] = ctx->cur.vols[i];
    dv = ctx->cur.nvol - n;
    ctx->cur.nvol = n;
    for (i = n = 0; i < ctx->cur.nocc; ++i)
        if (!mesh || ctx->cur.occ[i].fn || ctx->cur.occ[i].mesh != mesh) ctx->cur.occ[n++] = ctx->cur.occ[i];
    doc = ctx->cur.nocc - n;
    ctx->cur.nocc = n;
    if (dv || doc)
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: %s destroyed inside a frame: %d volumes and %d occluders that use it are dropped from "
                    "the frame", mesh ? "mesh" : "ramp", dv, doc);
    if (ramp && ramp == ctx->cur.frame.debug_ramp) { /* (its volumes are gone: the frame draws none of it) */
        ctx->cur.frame.debug_ramp = NULL;
        ctx->cur.debug_gone = 1;
    }
}

FOGVOL_API void fogvol_destroy_mesh(fogvol_context *ctx, fogvol_mesh *mesh)
{
    if (!ctx || !mesh) return;
    fogvol__forget(ctx, mesh, NULL);
    fogvol__forget_lights(ctx, mesh);
    ctx->be.destroy_mesh(ctx->be.user_data, mesh->handle);
    (void)fogvol__be_result(ctx, FOGVOL_SUCCESS); /* (logged by the backend) */
    fogvol__live_remove(&mesh->live, &ctx->live_meshes);
    fogvol__free(&ctx->alloc, mesh->planes);
    fogvol__free(&ctx->alloc, mesh);
}

/* What the one-pass colour group needs of a ramp (FOGVOL_VARIANT_COLORS): EXTINCTION + FOG ramps join
   it with extinction density * extinction_color (all 0: grey) and their colour as the emission. */
static void fogvol__ramp_colors(fogvol_context *ctx, const fogvol_ramp_desc *desc, fogvol_ramp *rp)
{
    const float *ec = desc->extinction_color;
    int c, unset = ec[0] == 0.0f && ec[1] == 0.0f && ec[2] == 0.0f;
    double s[3], top = 0.0;
    rp->colors = desc->model == FOGVOL_RAMP_EXTINCTION && desc->blend == FOGVOL_BLEND_FOG && desc->softness == 0.0f;
    for (c = 0; c < 3; ++c) { /* (in double: a finite density times a finite colour may pass FLT_MAX) */
        s[c] = (double)desc->density * (unset ? 1.0 : (double)ec[c]);
        if (s[c] > top) top = s[c];
    }
    for (c = 0; c < 3; ++c) { /* scaled alike down to 1e30 per unit, opaque at any thickness: same hue */
        rp->sigma[c] = (float)(top > 1e30 ? s[c] * (1e30 / top) : s[c]);
        rp->emit[c] = desc->color[c] < 0.0f ? 0.0f : desc->color[c] > 1.0f ? 1.0f : desc->color[c];
    }
    rp->grey = rp->sigma[0] == rp->sigma[1] && rp->sigma[1] == rp->sigma[2];
    if (!rp->grey && !(rp->colors && fogvol__has(ctx, FOGVOL_VARIANT_COLORS)))
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: extinction_color (%g, %g, %g) needs an EXTINCTION + FOG ramp in a context with "
                    "FOGVOL_VARIANT_COLORS; this ramp uses density alone",
                    (double)ec[0], (double)ec[1], (double)ec[2]);
}

FOGVOL_API fogvol_result fogvol_create_ramp(fogvol_context *ctx, const fogvol_ramp_desc *desc, fogvol_ramp **out)
{
    fogvol_image info;
    fogvol_texture_desc td;
    unsigned char *px;
    fogvol_ramp *rp;
    float tmax;
    fogvol_result r;
    if (out) *out = NULL;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc || !out) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "create_ramp: desc or out is NULL");
    r = fogvol_make_color_ramp(desc, NULL, 0, &info, &tmax);
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: invalid ramp description");
        return r;
    }
    px = (unsigned char *)fogvol__alloc(&ctx->alloc, info.size);
    rp = (fogvol_ramp *)fogvol__alloc(&ctx->alloc, sizeof *rp);
    if (!px || !rp) {
        fogvol__free(&ctx->alloc, px);
        fogvol__free(&ctx->alloc, rp);
        return fogvol__refuse(ctx, FOGVOL_ERROR_OUT_OF_MEMORY, "create_ramp: out of memory");
    }
    memset(rp, 0, sizeof *rp);
    fogvol_make_color_ramp(desc, px, info.size, &info, &tmax);
    memset(&td, 0, sizeof td);
    td.width = info.width;
    td.height = 1;
    td.pixels = px;
    td.filter = FOGVOL_FILTER_LINEAR;
    td.wrap = FOGVOL_WRAP_CLAMP;
    td.label = "fogvol colour ramp";
    r = fogvol__be_result(ctx, ctx->be.create_texture(ctx->be.user_data, &td, &rp->texture));
    fogvol__free(&ctx->alloc, px);
    if (r != FOGVOL_SUCCESS) {
        if (rp->texture) ctx->be.destroy_texture(ctx->be.user_data, rp->texture);
        (void)fogvol__be_result(ctx, r);
        fogvol__free(&ctx->alloc, rp);
        return fogvol__refuse(ctx, r, "create_ramp: the backend could not make its texture");
    }
    rp->width = info.width;
    rp->max_thickness = tmax;
    rp->blend = desc->blend;
    rp->softness = desc->softness;
    fogvol__ramp_colors(ctx, desc, rp);
    if (desc->model == FOGVOL_RAMP_EXTINCTION && (double)tmax * desc->density >= 7.0 * (1.0 - 1e-6))
    {
        rp->exp_rgba[0] = fogvol__unorm8(desc->color[0]) / 255.0f;
        rp->exp_rgba[1] = fogvol__unorm8(desc->color[1]) / 255.0f;
        rp->exp_rgba[2] = fogvol__unorm8(desc->color[2]) / 255.0f;
        rp->exp_rgba[3] = desc->density;
    }
    fogvol__live_add(&ctx->ramps, &rp->live, &ctx->live_ramps);
    *out = rp;
    return FOGVOL_SUCCESS;
}

FOGVOL_API void fogvol_destroy_ramp(fogvol_context *ctx, fogvol_ramp *ramp)
{
    if (!ctx || !ramp) return;
    fogvol__forget(ctx, NULL, ramp);
    ctx->be.destroy_texture(ctx->be.user_data, ramp->texture);
    (void)fogvol__be_result(ctx, FOGVOL_SUCCESS);
    fogvol__live_remove(&ramp->live, &ctx->live_ramps);
    fogvol__free(&ctx->alloc, ramp);
}

FOGVOL_API fogvol_result fogvol_create_volume_texture(fogvol_context *ctx, const fogvol_texture_desc *desc,
                                                      fogvol_volume_texture **out)
{
    fogvol_volume_texture *t;
    fogvol_texture_desc td;
    fogvol_result r;
    if (out) *out = NULL;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc || !out)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "create_volume_texture: desc or out is NULL");
    if (!desc->pixels || desc->width < 1 || desc->height < 1 || desc->width > 4096 || desc->height > 4096) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: volume texture needs pixels and 1..4096 texels a side "
                    "(got %dx%d)", desc->width, desc->height);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if ((desc->filter != FOGVOL_FILTER_NEAREST && desc->filter != FOGVOL_FILTER_LINEAR) ||
        (desc->wrap != FOGVOL_WRAP_REPEAT && desc->wrap != FOGVOL_WRAP_CLAMP)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: volume texture filter %d or wrap %d unknown (FOGVOL_FILTER_*, "
                    "FOGVOL_WRAP_*)", (int)desc->filter, (int)desc->wrap);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    t = (fogvol_volume_texture *)fogvol__alloc(&ctx->alloc, sizeof *t);
    if (!t) return fogvol__refuse(ctx, FOGVOL_ERROR_OUT_OF_MEMORY, "create_volume_texture: out of memory");
    memset(t, 0, sizeof *t); /* (a failed create_texture leaves no handle to destroy) */
    td = *desc;
    if (!td.label) td.label = "fogvol volume texture";
    r = fogvol__be_result(ctx, ctx->be.create_texture(ctx->be.user_data, &td, &t->texture));
    if (r != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: volume texture: %s", fogvol_result_string(r));
        if (t->texture) ctx->be.destroy_texture(ctx->be.user_data, t->texture);
        (void)fogvol__be_result(ctx, r);
        fogvol__free(&ctx->alloc, t);
        return r;
    }
    fogvol__live_add(&ctx->textures, &t->live, &ctx->live_textures);
    *out = t;
    return FOGVOL_SUCCESS;
}

FOGVOL_API void fogvol_destroy_volume_texture(fogvol_context *ctx, fogvol_volume_texture *texture)
{
    int i, n = 0;
    if (!ctx || !texture) return;
    for (i = 0; ctx->cur.in_frame && i < ctx->cur.nvol; ++i)
        if (ctx->cur.vols[i].density != texture && ctx->cur.vols[i].color != texture) ctx->cur.vols[n++] = ctx->cur.vols[i];
    if (ctx->cur.in_frame && n != ctx->cur.nvol) {
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: volume texture destroyed inside a frame: %d volumes "
                    "that use it are dropped from the frame", ctx->cur.nvol - n);
        ctx->cur.nvol = n;
    }
    ctx->be.destroy_texture(ctx->be.user_data, texture->texture);
    (void)fogvol__be_result(ctx, FOGVOL_SUCCESS);
    fogvol__live_remove(&texture->live, &ctx->live_textures);
    fogvol__free(&ctx->alloc, texture);
}

/* >>frame input =========================================================== */
/* One frame's input: the camera, volumes, occluders, the MRT and engine-drawn O; the frame's matrices
   (column-major 4x4 in double) and the per-draw values the passes take from them. */

/* column-major 4x4 helpers in double */
static void fogvol__mul4(double *out, const double *a, const double *b)
{
    int c, r, k;
    double t[16];
    for (c = 0; c < 4; ++c)
        for (r = 0; r < 4; ++r) {
            double s = 0;
            for (k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
            t[c * 4 + r] = s;
        }
    memcpy(out, t, sizeof t);
}

static void fogvol__tod(double *out, const float *m)
{
    int i;
    for (i = 0; i < 16; ++i) out[i] = m[i];
}

static double fogvol__det3(const double *m)
{
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/* inverse of a 4x4 (cofactors; the layout does not matter: inv(A^T) = inv(A)^T);
   0 if singular or not finite. a[r][c] below is m[r * 4 + c]. */
static int fogvol__inv4(const double *m, double *out)
{
#define FOGVOL__A(r, c) m[(r) * 4 + (c)]
    double s0 = FOGVOL__A(0, 0) * FOGVOL__A(1, 1) - FOGVOL__A(1, 0) * FOGVOL__A(0, 1);
    double s1 = FOGVOL__A(0, 0) * FOGVOL__A(1, 2) - FOGVOL__A(1, 0) * FOGVOL__A(0, 2);
    double s2 = FOGVOL__A(0, 0) * FOGVOL__A(1, 3) - FOGVOL__A(1, 0) * FOGVOL__A(0, 3);
    double s3 = FOGVOL__A(0, 1) * FOGVOL__A(1, 2) - FOGVOL__A(1, 1) * FOGVOL__A(0, 2);
    double s4 = FOGVOL__A(0, 1) * FOGVOL__A(1, 3) - FOGVOL__A(1, 1) * FOGVOL__A(0, 3);
    double s5 = FOGVOL__A(0, 2) * FOGVOL__A(1, 3) - FOGVOL__A(1, 2) * FOGVOL__A(0, 3);
    double c5 = FOGVOL__A(2, 2) * FOGVOL__A(3, 3) - FOGVOL__A(3, 2) * FOGVOL__A(2, 3);
    double c4 = FOGVOL__A(2, 1) * FOGVOL__A(3, 3) - FOGVOL__A(3, 1) * FOGVOL__A(2, 3);
    double c3 = FOGVOL__A(2, 1) * FOGVOL__A(3, 2) - FOGVOL__A(3, 1) * FOGVOL__A(2, 2);
    double c2 = FOGVOL__A(2, 0) * FOGVOL__A(3, 3) - FOGVOL__A(3, 0) * FOGVOL__A(2, 3);
    double c1 = FOGVOL__A(2, 0) * FOGVOL__A(3, 2) - FOGVOL__A(3, 0) * FOGVOL__A(2, 2);
    double c0 = FOGVOL__A(2, 0) * FOGVOL__A(3, 1) - FOGVOL__A(3, 0) * FOGVOL__A(2, 1);
    double det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0, b[16];
    int i;
    if (!(det != 0.0) || det - det != 0.0) return 0;
    b[0] = FOGVOL__A(1, 1) * c5 - FOGVOL__A(1, 2) * c4 + FOGVOL__A(1, 3) * c3;
    b[1] = -FOGVOL__A(0, 1) * c5 + FOGVOL__A(0, 2) * c4 - FOGVOL__A(0, 3) * c3;
    b[2] = FOGVOL__A(3, 1) * s5 - FOGVOL__A(3, 2) * s4 + FOGVOL__A(3, 3) * s3;
    b[3] = -FOGVOL__A(2, 1) * s5 + FOGVOL__A(2, 2) * s4 - FOGVOL__A(2, 3) * s3;
    b[4] = -FOGVOL__A(1, 0) * c5 + FOGVOL__A(1, 2) * c2 - FOGVOL__A(1, 3) * c1;
    b[5] = FOGVOL__A(0, 0) * c5 - FOGVOL__A(0, 2) * c2 + FOGVOL__A(0, 3) * c1;
    b[6] = -FOGVOL__A(3, 0) * s5 + FOGVOL__A(3, 2) * s2 - FOGVOL__A(3, 3) * s1;
    b[7] = FOGVOL__A(2, 0) * s5 - FOGVOL__A(2, 2) * s2 + FOGVOL__A(2, 3) * s1;
    b[8] = FOGVOL__A(1, 0) * c4 - FOGVOL__A(1, 1) * c2 + FOGVOL__A(1, 3) * c0;
    b[9] = -FOGVOL__A(0, 0) * c4 + FOGVOL__A(0, 1) * c2 - FOGVOL__A(0, 3) * c0;
    b[10] = FOGVOL__A(3, 0) * s4 - FOGVOL__A(3, 1) * s2 + FOGVOL__A(3, 3) * s0;
    b[11] = -FOGVOL__A(2, 0) * s4 + FOGVOL__A(2, 1) * s2 - FOGVOL__A(2, 3) * s0;
    b[12] = -FOGVOL__A(1, 0) * c3 + FOGVOL__A(1, 1) * c1 - FOGVOL__A(1, 2) * c0;
    b[13] = FOGVOL__A(0, 0) * c3 - FOGVOL__A(0, 1) * c1 + FOGVOL__A(0, 2) * c0;
    b[14] = -FOGVOL__A(3, 0) * s3 + FOGVOL__A(3, 1) * s1 - FOGVOL__A(3, 2) * s0;
    b[15] = FOGVOL__A(2, 0) * s3 - FOGVOL__A(2, 1) * s1 + FOGVOL__A(2, 2) * s0;
#undef FOGVOL__A
    for (i = 0; i < 16; ++i) {
        out[i] = b[i] / det;
        if (out[i] - out[i] != 0.0) return 0;
    }
    return 1;
}

/* Per-draw uniforms for a model matrix: mvp, the depth row d = dot(row, p), winding. */
static void fogvol__draw_for(const fogvol_context *ctx, const float model[16], fogvol_draw *dr)
{
    double m[16], mvp[16], range = (double)ctx->cur.frame.zfar - ctx->cur.frame.znear;
    int j;
    dr->sign = 1.0f;
    memset(dr->extinction, 0, sizeof dr->extinction);
    memset(dr->emission, 0, sizeof dr->emission);
    fogvol__tod(m, model);
    fogvol__mul4(mvp, ctx->cur.viewproj, m);
    for (j = 0; j < 16; ++j) dr->mvp[j] = (float)mvp[j];
    /* view depth e = eyerow . (M p);  d = (e - near) / (far - near) */
    for (j = 0; j < 4; ++j)
        dr->depth[j] = (float)((ctx->cur.eyerow[0] * m[j * 4] + ctx->cur.eyerow[1] * m[j * 4 + 1] +
                                ctx->cur.eyerow[2] * m[j * 4 + 2] + ctx->cur.eyerow[3] * m[j * 4 + 3] -
                                (j == 3 ? ctx->cur.frame.znear : 0.0)) /
                               range);
    /* a mirroring model matrix or projection flips the winding */
    dr->front_cw = (fogvol__det3(m) < 0) != (ctx->cur.mirrored != 0);
}


/* The dither rows' offset of the open frame (fogvol_frame_desc.dither_frame): bitrev3(n mod 8) * D / 8
   (a threshold rotation by bitrev3(n mod 8) / 8 of an LSB; D, a power of two >= 8, divides evenly) */
static float fogvol__dither_offset(const fogvol_context *ctx)
{
    unsigned n = (unsigned)ctx->cur.frame.dither_frame & 7u;
    unsigned r = ((n & 1u) << 2) | (n & 2u) | (n >> 2);
    return (float)(r * (unsigned)ctx->cfg.enc.dither_steps / 8u);
}

/* Nothing of a cancelled frame reaches the next: its lists, the engine's O (MRT, occluder_prepare: the
   next frame prepares it again; what O holds is forgotten in fogvol__prepare_o). */
FOGVOL_API fogvol_result fogvol_cancel_frame(fogvol_context *ctx)
{
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    ctx->cur.in_frame = 0;
    ctx->cur.nvol = ctx->cur.nocc = ctx->cur.nlight = 0;
    ctx->cur.engine_occluders = 0;
    ctx->cur.mrt_ready = 0;
    return FOGVOL_SUCCESS;
}

/* Matrices as fogvol reads them (column-major: m[column * 4 + row]). */
static void fogvol__transpose(float out[16], const float m[16])
{
    int c, k;
    for (c = 0; c < 4; ++c)
        for (k = 0; k < 4; ++k) out[c * 4 + k] = m[k * 4 + c];
}

/* An affine transform: bottom row (m[3], m[7], m[11], m[15]) = (0, 0, 0, 1) within 1e-6 (of the
   largest coefficient of the 3x3 part for the first three). A row-major matrix copied as it is has
   its translation there. */
static int fogvol__affine(const float m[16])
{
    double big = 0.0, tol;
    int c, k;
    for (c = 0; c < 3; ++c)
        for (k = 0; k < 3; ++k)
            if (FOGVOL_FABS(m[c * 4 + k]) > big) big = FOGVOL_FABS(m[c * 4 + k]);
    tol = 1e-6 * big;
    return FOGVOL_FABS(m[3]) <= tol && FOGVOL_FABS(m[7]) <= tol && FOGVOL_FABS(m[11]) <= tol &&
           FOGVOL_FABS(m[15] - 1.0) <= 1e-6;
}

/* A perspective projection transposed: the w row (0, 0, -1, 0) (or +1, w = z) stands in column 3, so
   m[14] is exactly +-1 and m[11] (the near/far term) is not, m[12] = m[13] = m[15] = 0 and the w row
   read where it belongs, (m[3], m[7], m[11], m[15]), has the same (0, 0, c, 0) form. A projection as
   written by glFrustum, gluPerspective, glm or D3D has m[11] = +-1 (reversed and infinite ones too),
   so it is never taken for this. */
static int fogvol__w_at_14(const float p[16])
{
    return FOGVOL_FABS(p[14]) == 1.0f && FOGVOL_FABS(p[11]) != 1.0f && p[11] != 0.0f && p[12] == 0.0f &&
           p[13] == 0.0f && p[15] == 0.0f && p[3] == 0.0f && p[7] == 0.0f;
}

/* Camera axes in world space from the frame's input: eye, right X, up Y, forward F (view
   depth grows along F, X x Y = -F), the view depth row and clip from world. */
static const char *fogvol__camera_axes(fogvol_context *ctx, const fogvol_frame_desc *d, double ax[4][3])
{
    double v[16], p[16], iv[16], l;
    int i;
    if (d->camera == FOGVOL_CAMERA_VIEW_PROJECTION) {
        if (!fogvol__finite_n(d->view_projection, 16) || !fogvol__finite_n(d->eye, 3) ||
            !fogvol__finite_n(d->forward, 3))
            return "non-finite view_projection, eye or forward";
        fogvol__tod(ctx->cur.viewproj, d->view_projection);
        l = FOGVOL_SQRT((double)d->forward[0] * d->forward[0] + (double)d->forward[1] * d->forward[1] +
                        (double)d->forward[2] * d->forward[2]);
        if (!(l > 0.0)) return "forward is zero";
        for (i = 0; i < 3; ++i) {
            ax[0][i] = d->eye[i];
            ax[3][i] = d->forward[i] / l;
        }
        /* X: perpendicular to F (F crossed with the axis it is least aligned with), Y = X x F */
        i = FOGVOL_FABS(ax[3][0]) < 0.5 ? 0 : 1;
        ax[1][0] = i ? -ax[3][2] : 0.0;
        ax[1][1] = i ? 0.0 : ax[3][2];
        ax[1][2] = i ? ax[3][0] : -ax[3][1];
        ax[2][0] = ax[1][1] * ax[3][2] - ax[1][2] * ax[3][1];
        ax[2][1] = ax[1][2] * ax[3][0] - ax[1][0] * ax[3][2];
        ax[2][2] = ax[1][0] * ax[3][1] - ax[1][1] * ax[3][0];
        for (i = 0; i < 3; ++i) ctx->cur.eyerow[i] = ax[3][i];
        ctx->cur.eyerow[3] = -(ax[3][0] * ax[0][0] + ax[3][1] * ax[0][1] + ax[3][2] * ax[0][2]);
        return NULL;
    }
    if (d->camera != FOGVOL_CAMERA_VIEW_AND_PROJECTION) return "unknown camera input";
    if (!fogvol__finite_n(d->view, 16) || !fogvol__finite_n(d->projection, 16))
        return "non-finite view or projection matrix";
    if (!fogvol__affine(d->view)) return "the view matrix's bottom row (m[3], m[7], m[11], m[15]) is not (0, 0, 0, 1)";
    if (fogvol__w_at_14(d->projection))
        return "the projection's clip w takes the view depth from m[14] (the z row), not m[11] (the w row)";
    fogvol__tod(v, d->view);
    fogvol__tod(p, d->projection);
    fogvol__mul4(ctx->cur.viewproj, p, v);
    if (!fogvol__inv4(v, iv) || !(iv[15] != 0.0)) return "the view matrix is singular";
    for (i = 0; i < 3; ++i) {
        ax[0][i] = iv[12 + i] / iv[15];
        ax[1][i] = iv[i];
        ax[2][i] = iv[4 + i];
        ax[3][i] = -iv[8 + i];
        ctx->cur.eyerow[i] = -v[i * 4 + 2];
    }
    ctx->cur.eyerow[3] = -v[14];
    /* a mirrored view (det < 0, a planar reflection's): Y turned so that X, Y, F have the handedness of
       the frame built above (X . (Y x F) < 0), and fogvol__camera_why sees the mirroring on screen */
    if (ax[1][0] * (ax[2][1] * ax[3][2] - ax[2][2] * ax[3][1]) - ax[1][1] * (ax[2][0] * ax[3][2] - ax[2][2] * ax[3][0]) +
            ax[1][2] * (ax[2][0] * ax[3][1] - ax[2][1] * ax[3][0]) > 0.0)
        for (i = 0; i < 3; ++i) ax[2][i] = -ax[2][i];
    return NULL;
}

/* The frame's camera: how clip w relates to view depth (perspective: w = s e, s > 0;
   orthographic: w constant > 0), whether the projection mirrors the screen (orientation
   of a camera-facing triangle, counter-clockwise as seen from the eye, after projection),
   and the inverse view-projection. Returns why it cannot interpret the camera, or NULL. */
static const char *fogvol__camera_why(fogvol_context *ctx, const fogvol_frame_desc *d)
{
    double ax[4][3], q[3][3], wr[4], sc, rr = 0.0, wn = 0.0, e = d->znear, det;
    const char *why = fogvol__camera_axes(ctx, d, ax);
    int i, k;
    for (i = 0; i < 4 && !why; ++i) wr[i] = ctx->cur.viewproj[i * 4 + 3];
    if (!why) {
        sc = (wr[0] * ctx->cur.eyerow[0] + wr[1] * ctx->cur.eyerow[1] + wr[2] * ctx->cur.eyerow[2]) /
             (ctx->cur.eyerow[0] * ctx->cur.eyerow[0] + ctx->cur.eyerow[1] * ctx->cur.eyerow[1] + ctx->cur.eyerow[2] * ctx->cur.eyerow[2]);
        for (i = 0; i < 4; ++i) {
            rr += (wr[i] - sc * ctx->cur.eyerow[i]) * (wr[i] - sc * ctx->cur.eyerow[i]);
            wn += wr[i] * wr[i];
        }
        ctx->cur.wscale = ctx->cur.wconst = 0.0;
        if (sc > 0.0 && rr <= 1e-10 * wn) ctx->cur.wscale = sc;
        else if (wr[3] > 0.0 && wn - wr[3] * wr[3] <= 1e-12 * wr[3] * wr[3]) ctx->cur.wconst = wr[3];
        else why = "the projection's clip w is neither the view depth times a positive constant (perspective) "
                   "nor a positive constant (orthographic)";
    }
    if (!why && !fogvol__inv4(ctx->cur.viewproj, ctx->cur.invvp)) why = "the view-projection is singular";
    if (!why) { /* clip (x, y, w) of eye + F e, + X e, + Y e: the sign of their determinant is the
                   orientation on screen (every w > 0) */
        for (k = 0; k < 3; ++k) {
            double pt[3];
            for (i = 0; i < 3; ++i) pt[i] = ax[0][i] + ax[3][i] * e + (k ? ax[k][i] * e : 0.0);
            for (i = 0; i < 3; ++i) {
                int row = i == 2 ? 3 : i;
                q[k][i] = ctx->cur.viewproj[row] * pt[0] + ctx->cur.viewproj[4 + row] * pt[1] +
                          ctx->cur.viewproj[8 + row] * pt[2] + ctx->cur.viewproj[12 + row];
            }
        }
        det = q[0][0] * (q[1][1] * q[2][2] - q[2][1] * q[1][2]) - q[0][1] * (q[1][0] * q[2][2] - q[2][0] * q[1][2]) +
              q[0][2] * (q[1][0] * q[2][1] - q[2][0] * q[1][1]);
        if (!(det != 0.0) || det - det != 0.0) why = "the projection collapses the screen (zero area)";
        else ctx->cur.mirrored = det < 0.0;
    }
    return why;
}

/* The camera (fogvol__camera_why); a refusal is logged, and says which matrices transposed would be
   accepted: row-major engine matrices (raylib's Matrix, DirectXMath) copied as they are. */
static fogvol_result fogvol__camera(fogvol_context *ctx, const fogvol_frame_desc *d)
{
    static const char *const which[4] = {"", "the view matrix", "the projection", "the view and projection matrices"};
    const char *why = fogvol__camera_why(ctx, d);
    fogvol_frame_desc t;
    int k, hint = 0;
    if (!why) return FOGVOL_SUCCESS;
    for (k = d->camera == FOGVOL_CAMERA_VIEW_PROJECTION ? 3 : 1; k <= 3 && !hint; ++k) {
        t = *d;
        if (d->camera == FOGVOL_CAMERA_VIEW_PROJECTION) fogvol__transpose(t.view_projection, d->view_projection);
        if (k & 1) fogvol__transpose(t.view, d->view);
        if (k & 2) fogvol__transpose(t.projection, d->projection);
        if (!fogvol__camera_why(ctx, &t)) hint = k;
    }
    if (hint && d->camera == FOGVOL_CAMERA_VIEW_PROJECTION)
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: camera refused: %s (transposed? view_projection "
                    "transposed would be accepted: a row-major matrix copied as it is)", why);
    else if (hint)
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: camera refused: %s (transposed? %s transposed would be "
                    "accepted: a row-major matrix copied as it is)", why, which[hint]);
    else fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: camera refused: %s", why);
    return FOGVOL_ERROR_INVALID_ARGUMENT;
}

FOGVOL_API fogvol_result fogvol_projection_planes(const float projection[16], int zero_to_one,
                                                  fogvol_projection_info *out)
{
    /* on the view axis: z_clip = -A e + B and w = s e + c at view depth e; the planes are
       where z_clip / w reaches the ends of the NDC depth range (lo and 1) */
    double a, b, s, c, den, e[2] = {0.0, 0.0};
    int inf[2] = {0, 0}, t, nearest;
    if (out) memset(out, 0, sizeof *out);
    if (!projection || !out || !fogvol__finite_n(projection, 16)) return FOGVOL_ERROR_INVALID_ARGUMENT;
    a = projection[10];
    b = projection[14];
    s = -projection[11];
    c = projection[15];
    if (projection[3] != 0.0f || projection[7] != 0.0f || !((s > 0.0 && c == 0.0) || (s == 0.0 && c > 0.0)))
        return FOGVOL_ERROR_INVALID_ARGUMENT; /* w neither view depth * s nor constant */
    for (t = 0; t < 2; ++t) {
        double ndc = t ? 1.0 : (zero_to_one ? 0.0 : -1.0);
        den = s > 0.0 ? a + ndc * s : a;
        if (den == 0.0) inf[t] = 1;
        else e[t] = s > 0.0 ? b / den : (b - ndc * c) / a;
    }
    if ((inf[0] && inf[1]) || (s == 0.0 && (inf[0] || inf[1])) || (!inf[0] && !inf[1] && e[0] == e[1]))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    nearest = inf[0] ? 1 : inf[1] ? 0 : (e[1] < e[0]);
    out->znear = (float)e[nearest];
    out->zfar = inf[!nearest] ? 0.0f : (float)e[!nearest];
    out->infinite = inf[!nearest];
    out->reversed = nearest == 1;
    out->orthographic = s == 0.0;
    if (!fogvol__finite(out->znear) || !fogvol__finite(out->zfar) || (s > 0.0 && !(out->znear > 0.0f)) ||
        (!out->infinite && !(out->zfar > out->znear))) {
        memset(out, 0, sizeof *out);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    return FOGVOL_SUCCESS;
}

/* A viewport fogvol takes: its origin within -32768..32767 (the least viewport bounds range GL 4.1 /
   ARB_viewport_array reports) and its size 1..16384, so that every sum of them is an int; else a
   reason. */
static const char *fogvol__viewport_problem(const int vp[4])
{
    if (vp[2] <= 0 || vp[3] <= 0 || vp[2] > 16384 || vp[3] > 16384) return "size outside 1..16384";
    if (vp[0] < -32768 || vp[0] > 32767 || vp[1] < -32768 || vp[1] > 32767) return "origin outside -32768..32767";
    return NULL;
}

FOGVOL_API fogvol_result fogvol_begin_frame(fogvol_context *ctx, const fogvol_frame_desc *d)
{
    fogvol_result r;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (ctx->cur.in_frame) {
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: begin_frame without end_frame: the open frame is discarded");
        fogvol_cancel_frame(ctx);
    }
    if (!d) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "begin_frame: desc is NULL");
    if (!fogvol__finite(d->znear) || !fogvol__finite(d->zfar) || !(d->znear > 0) || !(d->zfar > d->znear)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: need 0 < znear < zfar (got %g, %g)", (double)d->znear,
                    (double)d->zfar);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (fogvol__viewport_problem(d->viewport)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: viewport (%d, %d) %dx%d: %s", d->viewport[0], d->viewport[1],
                    d->viewport[2], d->viewport[3], fogvol__viewport_problem(d->viewport));
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (d->composite != FOGVOL_COMPOSITE_FULLSCREEN && d->composite != FOGVOL_COMPOSITE_GEOMETRY)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "begin_frame: unknown composite");
    if (d->downsample < 0 || d->downsample > 2) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: downsample %d is not 0, 1 or 2", d->downsample);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (d->engine_depth_zero_to_one < -1 || d->engine_depth_zero_to_one > 1 ||
        !fogvol__finite_n(d->engine_depth_range, 2)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: engine_depth_zero_to_one not -1, 0 or 1, or "
                                                 "non-finite engine_depth_range");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__camera(ctx, d);
    if (r != FOGVOL_SUCCESS) return r;
    if (d->draw_buffer < 0 || d->draw_buffer > 15 ||
        (d->alpha != FOGVOL_ALPHA_KEEP && d->alpha != FOGVOL_ALPHA_COVERAGE)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: draw_buffer %d outside 0..15 or unknown alpha mode %d",
                    d->draw_buffer, (int)d->alpha);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if ((int)d->engine_depth_source < 0 || d->engine_depth_source > FOGVOL_DEPTH_SOURCE_FRAMEBUFFER_OBJECT) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: unknown engine_depth_source %d", (int)d->engine_depth_source);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    ctx->cur.frame = *d;
    ctx->cur.nvol = ctx->cur.nocc = 0;
    ctx->cur.in_frame = 1;
    ctx->cur.serial++;
    ctx->cur.nlight = 0;
    ctx->cur.mrt_ready = ctx->cur.engine_occluders = ctx->cur.debug_gone = 0;
    return FOGVOL_SUCCESS;
}

static fogvol_result fogvol__grow(fogvol_context *ctx, void **arr, int *cap, int need, size_t elem)
{
    void *n;
    int nc;
    if (need <= *cap) return FOGVOL_SUCCESS;
    nc = *cap ? *cap * 2 : 16;
    while (nc < need) nc *= 2;
    n = fogvol__alloc(&ctx->alloc, (size_t)nc * elem);
    if (!n) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: out of memory for the frame's lists");
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    if (*arr) memcpy(n, *arr, (size_t)*cap * elem);
    fogvol__free(&ctx->alloc, *arr);
    *arr = n;
    *cap = nc;
    return FOGVOL_SUCCESS;
}

/* What makes a model matrix unusable, or NULL: non-finite, all zero, not affine (a row-major matrix
   copied as it is: transposed, told apart by its transpose being affine), and for a volume or a
   light, singular (|det| of the 3x3 part at most 1e-7 of the product of its column lengths: a zero
   scale, or two axes along each other, flattens the mesh to no volume). */
static const char *fogvol__model_problem(const float m[16], int volume)
{
    double d[16], c[3];
    float t[16];
    int i, k, zero = 1;
    if (!fogvol__finite_n(m, 16)) return "is not finite";
    for (i = 0; i < 16; ++i) zero &= m[i] == 0.0f;
    if (zero) return "is all zero";
    if (!fogvol__affine(m)) {
        fogvol__transpose(t, m);
        return fogvol__affine(t) ? "has its bottom row (m[3], m[7], m[11], m[15]) not (0, 0, 0, 1) but its "
                                   "right column is (transposed? a row-major matrix copied as it is)"
                                 : "has its bottom row (m[3], m[7], m[11], m[15]) not (0, 0, 0, 1)";
    }
    if (!volume) return NULL;
    fogvol__tod(d, m);
    for (k = 0; k < 3; ++k) c[k] = FOGVOL_SQRT(d[4 * k] * d[4 * k] + d[4 * k + 1] * d[4 * k + 1] + d[4 * k + 2] * d[4 * k + 2]);
    if (FOGVOL_FABS(fogvol__det3(d)) <= 1e-7 * c[0] * c[1] * c[2])
        return "is singular (a zero scale or two axes along each other flatten the mesh: no volume)";
    return NULL;
}

FOGVOL_API fogvol_result fogvol_add_occluder(fogvol_context *ctx, const fogvol_mesh *mesh, const float model[16])
{
    const char *why;
    fogvol__occluder *o;
    void *arr;
    fogvol_result r;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!mesh || !model) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "add_occluder: mesh or model is NULL");
    if (!ctx->cur.in_frame)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE, "add_occluder outside a frame (after begin_frame only)");
    if (ctx->cur.engine_occluders) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the engine draws this frame's occluders "
                                                 "(fogvol_occluder_prepare): add_occluder refused");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    if ((why = fogvol__model_problem(model, 0)) != NULL) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the occluder's model matrix %s", why);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    arr = ctx->cur.occ;
    r = fogvol__grow(ctx, &arr, &ctx->cur.capocc, ctx->cur.nocc + 1, sizeof *o);
    ctx->cur.occ = (fogvol__occluder *)arr;
    if (r != FOGVOL_SUCCESS) return r;
    o = &ctx->cur.occ[ctx->cur.nocc++];
    memset(o, 0, sizeof *o);
    o->mesh = mesh;
    memcpy(o->model, model, sizeof o->model);
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_add_occluder_callback(fogvol_context *ctx, fogvol_occluder_fn fn, void *user_data)
{
    fogvol__occluder *o;
    void *arr;
    fogvol_result r;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!fn) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "add_occluder_callback: fn is NULL");
    if (!ctx->cur.in_frame)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE,
                              "add_occluder_callback outside a frame (after begin_frame only)");
    if (ctx->cur.engine_occluders) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the engine draws this frame's occluders "
                                                 "(fogvol_occluder_prepare): add_occluder refused");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    arr = ctx->cur.occ;
    r = fogvol__grow(ctx, &arr, &ctx->cur.capocc, ctx->cur.nocc + 1, sizeof *o);
    ctx->cur.occ = (fogvol__occluder *)arr;
    if (r != FOGVOL_SUCCESS) return r;
    o = &ctx->cur.occ[ctx->cur.nocc++];
    memset(o, 0, sizeof *o);
    o->fn = fn;
    o->user_data = user_data;
    return FOGVOL_SUCCESS;
}

static int fogvol__all_zero(const float *v, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (v[i] != 0.0f) return 0;
    return 1;
}

/* fogvol_add_volume: the density texture needs a tier that can weight faces; one colour
   texture (and map) per colour-ramp group. */
/* fogvol_volume_desc.color_map with its default (all zero: s = x, t = y). */
static void fogvol__color_map(const fogvol_volume_desc *desc, float map[6])
{
    memcpy(map, desc->color_map, 6 * sizeof(float));
    if (fogvol__all_zero(map, 6)) map[0] = map[4] = 1.0f;
}

static fogvol_result fogvol__check_textures(fogvol_context *ctx, const fogvol_volume_desc *desc)
{
    int i;
    if (!fogvol__finite_n(desc->density_map, 8) || !fogvol__finite_n(desc->color_map, 6)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: non-finite density_map or color_map");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (desc->density && !fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_DENSITY)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: density textures need tier FLOAT, PS20 or MRT without the "
                    "COUNT and WIDE variants (tier %s, variants 0x%x)", fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    for (i = 0; desc->color && i < ctx->cur.nvol; ++i) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        float map[6];
        fogvol__color_map(desc, map);
        if (v->ramp == desc->ramp && v->color && (v->color != desc->color || memcmp(v->color_map, map, sizeof map))) {
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the volumes of one ramp share one colour texture and "
                        "map (volume %d of this frame has another)", i);
            return FOGVOL_ERROR_INVALID_ARGUMENT;
        }
    }
    return FOGVOL_SUCCESS;
}

static void fogvol__set_textures(fogvol__volume *v, const fogvol_volume_desc *desc)
{
    v->density = desc->density;
    v->color = desc->color;
    memcpy(v->density_map, desc->density_map, sizeof v->density_map);
    if (fogvol__all_zero(v->density_map, 8)) v->density_map[0] = v->density_map[5] = 1.0f; /* s = x, t = y */
    fogvol__color_map(desc, v->color_map);
}

FOGVOL_API fogvol_result fogvol_add_volume(fogvol_context *ctx, const fogvol_volume_desc *desc)
{
    const char *why;
    fogvol__volume *v;
    void *arr;
    fogvol_result r;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc || !desc->mesh || !desc->ramp)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "add_volume: desc, its mesh or its ramp is NULL");
    if (!ctx->cur.in_frame)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE, "add_volume outside a frame (after begin_frame only)");
    if (!desc->mesh->volume) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: an open (occluder-only) mesh cannot be a volume");
        return FOGVOL_ERROR_INVALID_MESH;
    }
    if ((why = fogvol__model_problem(desc->model, 1)) != NULL) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the volume's model matrix %s", why);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__check_textures(ctx, desc);
    if (r != FOGVOL_SUCCESS) return r;
    arr = ctx->cur.vols;
    r = fogvol__grow(ctx, &arr, &ctx->cur.capvol, ctx->cur.nvol + 1, sizeof *v);
    ctx->cur.vols = (fogvol__volume *)arr;
    if (r != FOGVOL_SUCCESS) return r;
    v = &ctx->cur.vols[ctx->cur.nvol++];
    v->mesh = desc->mesh;
    v->ramp = desc->ramp;
    memcpy(v->model, desc->model, sizeof v->model);
    v->negative = desc->negative != 0;
    fogvol__set_textures(v, desc);
    if (desc->density || desc->color) /* (a ramp of this context: its own object) */
        ((fogvol_ramp *)(uintptr_t)desc->ramp)->textured = ctx->cur.serial;
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_occluder_transform(fogvol_context *ctx, const float model[16])
{
    const char *why;
    fogvol_draw dr;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!model) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "occluder_transform: model is NULL");
    if (!ctx->cur.in_occluder_pass)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE,
                              "occluder_transform outside an occluder callback (fogvol_add_occluder_callback)");
    if ((why = fogvol__model_problem(model, 0)) != NULL) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: occluder_transform: the model matrix %s", why);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    fogvol__draw_for(ctx, model, &dr);
    ctx->be.set_draw(ctx->be.user_data, &dr);
    return FOGVOL_SUCCESS;
}

/* The engine framebuffer's samples decide this frame's targets and programs
   (see fogvol_msaa): per sample, the opt-in single-sample fallback, or refused. */
static fogvol_result fogvol__frame_samples(fogvol_context *ctx, const fogvol_frame_info *info,
                                           fogvol_frame_stats *st)
{
    int n = info->samples > 1 ? info->samples : 0;
    const char *why = NULL;
    if (n && ctx->cfg.msaa == FOGVOL_MSAA_SINGLE_SAMPLE) {
        if (!ctx->msaa_warned)
            fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                        "fogvol: %d-sample engine framebuffer drawn with single-sample targets "
                        "(FOGVOL_MSAA_SINGLE_SAMPLE): one fog value per pixel",
                        n);
        ctx->msaa_warned = 1;
        st->msaa_fallback = 1;
        n = 0;
    } else if (n) {
        if (!(ctx->be.caps & FOGVOL_CAP_MULTISAMPLE))
            why = "the backend has no multisample targets with per-sample shading (GL 4.0 or ARB_sample_shading)";
        else if (fogvol_msaa_supported(ctx->cfg.tier, ctx->cfg.variants, ctx->be.dialect) != FOGVOL_SUCCESS)
            why = "no per-sample path for this tier, variants and GLSL dialect (needs GLSL 150/330; not MRT, WIDE "
                  "or COLORS)";
        else if (ctx->cur.frame.debug_thickness)
            why = "debug_thickness cannot read multisampled targets";
        if (why) {
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                        "fogvol: %d-sample engine framebuffer, tier %s, variants 0x%x, GLSL %s: %s; "
                        "FOGVOL_MSAA_SINGLE_SAMPLE draws one fog value per pixel instead",
                        n, fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants, fogvol_dialect_name(ctx->be.dialect), why);
            return FOGVOL_ERROR_UNSUPPORTED;
        }
    }
    ctx->cur.samples = n;
    st->samples = n ? n : 1;
    return fogvol__msaa_programs(ctx, n > 1);
}

static fogvol_result fogvol__begin_backend_frame(fogvol_context *ctx, fogvol_frame_info *info)
{
    fogvol_result r = FOGVOL_SUCCESS;
    memset(info, 0, sizeof *info);
    info->draw_buffer = ctx->cur.frame.draw_buffer;
    if (ctx->be.begin_frame) r = ctx->be.begin_frame(ctx->be.user_data, info);
    if (r != FOGVOL_SUCCESS) {
        (void)fogvol__be_result(ctx, r);
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: backend begin_frame failed: %s", fogvol_result_string(r));
    }
    return r;
}

/* For the *_prepare calls: fogvol's targets sized to the frame (touches the
   GPU, state restored), the frame's constants and O's API object. */
static fogvol_result fogvol__prepare_o(fogvol_context *ctx, fogvol_constants *k, fogvol_native *texture)
{
    fogvol_frame_info fi;
    fogvol_frame_stats st;
    fogvol_result r = fogvol__begin_backend_frame(ctx, &fi);
    if (r != FOGVOL_SUCCESS) return r;
    /* this frame's sample count, as end_frame will find it: O made with an earlier frame's was made
       again at end_frame, and what the engine drew into it lost */
    memset(&st, 0, sizeof st);
    r = fogvol__frame_samples(ctx, &fi, &st);
    ctx->cur.prepared_samples = ctx->cur.samples;
    if (r == FOGVOL_SUCCESS) r = fogvol__ensure_targets(ctx, ctx->cur.frame.viewport[2], ctx->cur.frame.viewport[3], 0);
    if (ctx->be.end_frame) ctx->be.end_frame(ctx->be.user_data);
    r = fogvol__be_result(ctx, r);
    if (r != FOGVOL_SUCCESS) return r;
    fogvol_compute_constants(&ctx->cfg.enc, ctx->cur.frame.znear, ctx->cur.frame.zfar, 0.0f, k);
    *texture = ctx->be.native_texture(ctx->be.user_data, ctx->gpu.tgt_o);
    ctx->gpu.o_far = 0; /* the engine writes O from here, whether or not this frame is ended */
    return FOGVOL_SUCCESS;
}

FOGVOL_API fogvol_result fogvol_mrt_prepare(fogvol_context *ctx, fogvol_mrt_info *info)
{
    fogvol_constants k;
    fogvol_result r;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!info) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "mrt_prepare: info is NULL");
    memset(info, 0, sizeof *info);
    if (ctx->cfg.tier != FOGVOL_TIER_MRT || !ctx->cur.in_frame || !ctx->be.native_texture) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: mrt_prepare needs the MRT tier, an open frame and a "
                                                 "backend with native_texture");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    r = fogvol__prepare_o(ctx, &k, &info->texture);
    if (r != FOGVOL_SUCCESS) return r;
    info->format = ctx->cfg.float_o ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8;
    if (ctx->cfg.float_o) { /* d = 1, the far plane; fogvol_mrt[0].z = N = 0 marks the R32F target */
        info->clear_color[0] = 1.0f;
    } else {
        info->clear_color[0] = info->clear_color[1] = info->clear_color[2] = (float)(ctx->cfg.enc.levels - 1) / 255.0f;
        info->uniforms[2] = (float)ctx->cfg.enc.levels;
        info->uniforms[3] = (float)ctx->cfg.enc.levels * (float)ctx->cfg.enc.levels;
    }
    info->uniforms[0] = k.near_far[0];
    info->uniforms[1] = k.near_far[1];
    info->uniforms[4] = k.depth_offset;
    info->uniforms[5] = k.depth_max;
    info->uniforms[6] = (float)ctx->cfg.enc.dither_steps;
    info->uniforms[7] = ctx->cfg.dither ? 1.0f + fogvol__dither_offset(ctx) : 0.0f; /* (+ the frame's offset) */
    ctx->cur.mrt_ready = 1;
    return FOGVOL_SUCCESS;
}

/* The engine depth's convention: NDC z in [0, 1] (1) or [-1, 1] (0), and the depth range r[0], r[1]
   it was drawn with, from fd (overrides) or info (reported). */
static int fogvol__engine_convention(const fogvol_frame_desc *fd, const fogvol_frame_info *info, double r[2])
{
    r[0] = info->depth_range[0];
    r[1] = info->depth_range[1];
    if (fd->engine_depth_range[0] != 0.0f || fd->engine_depth_range[1] != 0.0f) {
        r[0] = fd->engine_depth_range[0];
        r[1] = fd->engine_depth_range[1];
    } else if (r[0] == 0.0 && r[1] == 0.0) {
        r[1] = 1.0;
    }
    return fd->engine_depth_zero_to_one ? fd->engine_depth_zero_to_one > 0 : info->depth_zero_to_one != 0;
}

/* fv_lin, fv_lin2: the engine depth texture's window depth -> view depth, for the camera in
   ctx (eyerow, invvp) and the depth conventions of fd (overrides) or info (reported). */
static void fogvol__lin_uniforms(const fogvol_context *ctx, const fogvol_frame_desc *fd, const fogvol_frame_info *info,
                                 fogvol_pass *ps)
{
    double n[4], dn[4], a, b, sy, r0, r1, rr[2];
    int i, z01;
    /* q = (s, t, window depth, 1) -> NDC (2s - 1, +-(2t - 1), a z + b, 1), folded into the
       rows eyerow * invVP (numerator) and invVP row 3 (denominator) */
    z01 = fogvol__engine_convention(fd, info, rr);
    r0 = rr[0];
    r1 = rr[1];
    a = (z01 ? 1.0 : 2.0) / (r1 != r0 ? r1 - r0 : 1.0);
    b = -r0 * a - (z01 ? 0.0 : 1.0);
    sy = info->clip_upper_left ? -1.0 : 1.0;
    for (i = 0; i < 4; ++i) {
        n[i] = ctx->cur.eyerow[0] * ctx->cur.invvp[i * 4] + ctx->cur.eyerow[1] * ctx->cur.invvp[i * 4 + 1] +
               ctx->cur.eyerow[2] * ctx->cur.invvp[i * 4 + 2] + ctx->cur.eyerow[3] * ctx->cur.invvp[i * 4 + 3];
        dn[i] = ctx->cur.invvp[i * 4 + 3];
    }
    ps->uniforms[FOGVOL_U_LINEAR][0] = (float)(2.0 * n[0]);
    ps->uniforms[FOGVOL_U_LINEAR][1] = (float)(2.0 * sy * n[1]);
    ps->uniforms[FOGVOL_U_LINEAR][2] = (float)(a * n[2]);
    ps->uniforms[FOGVOL_U_LINEAR][3] = (float)(n[3] - n[0] - sy * n[1] + b * n[2]);
    ps->uniforms[FOGVOL_U_LINEAR_W][0] = (float)(2.0 * dn[0]);
    ps->uniforms[FOGVOL_U_LINEAR_W][1] = (float)(2.0 * sy * dn[1]);
    ps->uniforms[FOGVOL_U_LINEAR_W][2] = (float)(a * dn[2]);
    ps->uniforms[FOGVOL_U_LINEAR_W][3] = (float)(dn[3] - dn[0] - sy * dn[1] + b * dn[2]);
}

/* The view depths of the 8 corners of mesh m's bounds under model: their least and greatest. */
static void fogvol__mesh_depths(const fogvol_context *ctx, const fogvol_mesh *m, const float model[16], double *emin,
                                double *emax)
{
    int c, j;
    for (c = 0; c < 8; ++c) {
        double p[3], e = ctx->cur.eyerow[3];
        p[0] = (c & 1) ? m->bmax[0] : m->bmin[0];
        p[1] = (c & 2) ? m->bmax[1] : m->bmin[1];
        p[2] = (c & 4) ? m->bmax[2] : m->bmin[2];
        for (j = 0; j < 3; ++j)
            e += ctx->cur.eyerow[j] * (model[j] * p[0] + model[4 + j] * p[1] + model[8 + j] * p[2] + model[12 + j]);
        if (c == 0 || e < *emin) *emin = e;
        if (c == 0 || e > *emax) *emax = e;
    }
}

/* The greatest normalised depth d = (e - znear) / (zfar - znear) of mesh m's bounds under model, or dmax. */
static double fogvol__mesh_dmax(const fogvol_context *ctx, const fogvol_mesh *m, const float model[16], double dmax)
{
    double emin = 0.0, emax = 0.0, d;
    fogvol__mesh_depths(ctx, m, model, &emin, &emax);
    d = (emax - ctx->cur.frame.znear) / ((double)ctx->cur.frame.zfar - ctx->cur.frame.znear);
    return d > dmax ? d : dmax;
}

/* fv_misc.x (clip z = k d - w: the near plane clips exactly, nothing beyond the far plane
   is clipped, k d <= 2 w everywhere) and .z (near-clamp w); fv_lin, fv_lin2 (engine depth:
   window depth -> view depth through the inverse view-projection). */
static void fogvol__clip_uniforms(const fogvol_context *ctx, const fogvol_frame_info *info, fogvol_pass *ps)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    double range = (double)fd->zfar - fd->znear, k = 1.0, dmax = 0.0;
    int i;
    if (ctx->cur.wscale > 0.0) {
        k = 2.0 * ctx->cur.wscale * range; /* k d <= 2 s (e - near) <= 2 w */
    } else { /* orthographic: w is constant, bound d over what fogvol draws: the volumes and, with lights,
                the lights and the occluders that hide them (an engine-drawn occluder: the whole range) */
        for (i = 0; i < ctx->cur.nvol; ++i) dmax = fogvol__mesh_dmax(ctx, ctx->cur.vols[i].mesh, ctx->cur.vols[i].model, dmax);
        for (i = 0; i < ctx->cur.nlight; ++i)
            dmax = fogvol__mesh_dmax(ctx, ctx->cur.lights[i].mesh, ctx->cur.lights[i].model, dmax);
        for (i = 0; ctx->cur.nlight > 0 && i < ctx->cur.nocc; ++i)
            dmax = ctx->cur.occ[i].fn ? (dmax > 1.0 ? dmax : 1.0)
                                      : fogvol__mesh_dmax(ctx, ctx->cur.occ[i].mesh, ctx->cur.occ[i].model, dmax);
        if (dmax > 0.0) k = 1.98 * ctx->cur.wconst / dmax;
    }
    /* the whole [0, 1] depth range: a 16-bit depth buffer (GLES2, WebGL1) orders the occluders'
       faces as finely as a standard projection would (k = 1 left it 1 / (2 (far - near)) of it) */
    ps->uniforms[FOGVOL_U_MISC][0] = (float)k;
    /* near clamp: clip w of the near plane for perspective projections, none for orthographic */
    ps->uniforms[FOGVOL_U_MISC][2] = ctx->cur.wscale > 0.0 ? (float)(ctx->cur.wscale * fd->znear) : -1e30f;
    fogvol__lin_uniforms(ctx, fd, info, ps);
}

FOGVOL_API fogvol_result fogvol_occluder_prepare(fogvol_context *ctx, fogvol_occluder_info *info)
{
    fogvol_constants k;
    fogvol_result r;
    int fl;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!info) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "occluder_prepare: info is NULL");
    memset(info, 0, sizeof *info);
    fl = ctx->cfg.tier == FOGVOL_TIER_FLOAT;
    if (!ctx->cur.in_frame || ctx->cur.nocc > 0 || !ctx->be.native_texture) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: occluder_prepare needs an open frame without "
                                                 "fogvol_add_occluder* calls and a backend with native_texture");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    if (ctx->cur.frame.downsample == 2) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: engine-drawn occluders need full-resolution sums "
                                                 "(fogvol_frame_desc.downsample 0 or 1)");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if ((ctx->cfg.tier != FOGVOL_TIER_PS20 && !fl) ||
        fogvol__has(ctx, FOGVOL_VARIANT_COUNT | FOGVOL_VARIANT_WIDE | FOGVOL_VARIANT_ENGINE_DEPTH)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: engine-drawn occluders need tier PS20 or FLOAT without the "
                                                 "COUNT, WIDE and ENGINE_DEPTH variants (tier %s, variants 0x%x)%s",
                    fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants,
                    ctx->cfg.tier == FOGVOL_TIER_MRT ? "; the MRT tier has fogvol_mrt_prepare" : "");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    r = fogvol__prepare_o(ctx, &k, &info->texture);
    if (r != FOGVOL_SUCCESS) return r;
    fl = fl || ctx->cfg.float_o; /* from here: O is R32F (FLOAT, or PS20 with FOGVOL_SPEEDUP_FLOAT_O) */
    info->width = ctx->gpu.target_w;
    info->height = ctx->gpu.target_h;
    info->samples = ctx->cur.samples;
    info->format = fl ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8;
    if (fl) info->clear_color[0] = 1.0f;
    else info->clear_color[0] = info->clear_color[1] = info->clear_color[2] = (float)(ctx->cfg.enc.levels - 1) / 255.0f;
    info->uniforms[0] = k.near_far[0];
    info->uniforms[1] = k.near_far[1];
    info->uniforms[2] = fl ? 0.0f : (float)ctx->cfg.enc.levels;
    info->uniforms[3] = fl ? 0.0f : (float)ctx->cfg.enc.levels * (float)ctx->cfg.enc.levels;
    info->uniforms[4] = fl ? 0.0f : k.depth_offset;
    info->uniforms[5] = fl ? 1.0f : k.depth_max;
    info->uniforms[6] = (float)ctx->cfg.enc.dither_steps;
    info->uniforms[7] = ctx->cfg.dither && !fl ? 1.0f + fogvol__dither_offset(ctx) : 0.0f;
    ctx->cur.engine_occluders = 1;
    return FOGVOL_SUCCESS;
}

/* The view depths of the 8 corners of volume v's bounds: their least and greatest. */
static void fogvol__volume_depths(const fogvol_context *ctx, const fogvol__volume *v, double *emin, double *emax)
{
    fogvol__mesh_depths(ctx, v->mesh, v->model, emin, emax);
}

/* COUNT adds the opaque depth once per back face without its front face, so it
   needs every front face in front of the near plane: a volume that the near
   plane may cut (the camera inside it or within znear of it) breaks the count.
   Decided conservatively from the view depths of the corners of each volume's
   bounds: some corner nearer than znear and some in front of the eye. Returns
   the first such volume, or -1. */
static int fogvol__count_near_cut(const fogvol_context *ctx)
{
    int i;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        double emin = 0.0, emax = 0.0;
        fogvol__volume_depths(ctx, &ctx->cur.vols[i], &emin, &emax);
        if (emin < ctx->cur.frame.znear && emax > 0.0) return i;
    }
    return -1;
}

/* Frames fogvol refuses before touching the backend (logged; the caller cancels the frame). */
static fogvol_result fogvol__frame_refusal(fogvol_context *ctx)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    int engine = fogvol__has(ctx, FOGVOL_VARIANT_ENGINE_DEPTH), i;
    if (ctx->cfg.tier == FOGVOL_TIER_MRT && !ctx->cur.mrt_ready) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: MRT tier: call fogvol_mrt_prepare and let the engine "
                                                 "write O before fogvol_end_frame");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    if (engine && fd->engine_depth_source == FOGVOL_DEPTH_SOURCE_TEXTURE && !fd->engine_depth_texture) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: ENGINE_DEPTH variant without engine_depth_texture");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (engine && fd->engine_depth_source != FOGVOL_DEPTH_SOURCE_TEXTURE && !ctx->be.copy_depth) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the backend cannot copy a framebuffer's depth (copy_depth); "
                                                 "pass a depth texture (engine_depth_texture)");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (fd->downsample == 2 && (ctx->cur.nlight > 0 || !fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_DOWNSAMPLE))) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                    "fogvol: downsample 2 needs the FLOAT tier without ENGINE_DEPTH or COLORS and no "
                    "fogvol_add_light (tier %s, variants 0x%x, %d lights); nothing drawn",
                    fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants, ctx->cur.nlight);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (fogvol__has(ctx, FOGVOL_VARIANT_COUNT) && (i = fogvol__count_near_cut(ctx)) >= 0) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                    "fogvol: COUNT variant: the near plane may cut volume %d (the camera is inside it or closer than "
                    "znear), which breaks the face count; nothing drawn. Draw such views without COUNT",
                    i);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    return FOGVOL_SUCCESS;
}

/* >>passes ================================================================ */
/* The passes of fogvol_end_frame: opaque O, face sums, composite, debug read-back. */

static void fogvol__end_pass(fogvol_context *ctx)
{
    if (ctx->be.end_pass) ctx->be.end_pass(ctx->be.user_data);
}

/* A ramp in the one-pass colour group this frame (FOGVOL_VARIANT_COLORS): a colour ramp none of whose
   volumes has a density or colour texture this frame (the colour group's programs draw neither: such
   a ramp is a group of its own, drawn as without COLORS). */
static int fogvol__color_member(const fogvol_context *ctx, const fogvol_ramp *ramp)
{
    return (ctx->cfg.variants & FOGVOL_VARIANT_COLORS) && ramp->colors && ramp->textured != ctx->cur.serial;
}

/* The frame's colour-ramp groups as lists, once per end_frame, so that each group's passes visit its
   own volumes only: each ramp's first and last volume (stamped with this end_frame), each volume's
   next of the same ramp, in the frame's order; the one-pass colour group's first volume. (The ramps
   belong to the context; the const of the volume desc is the caller's promise, not theirs.) */
static void fogvol__link_groups(fogvol_context *ctx)
{
    int i;
    ctx->cur.group_stamp++;
    ctx->cur.color_first = -1;
    ctx->cur.color_pos = 0;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        fogvol__volume *v = &ctx->cur.vols[i];
        fogvol_ramp *rp = (fogvol_ramp *)(uintptr_t)v->ramp;
        v->next = -1;
        if (rp->stamp != ctx->cur.group_stamp) {
            rp->stamp = ctx->cur.group_stamp;
            rp->head = i;
        } else {
            ctx->cur.vols[rp->tail].next = i;
        }
        rp->tail = i;
        if (fogvol__color_member(ctx, rp)) {
            if (ctx->cur.color_first < 0) ctx->cur.color_first = i;
            ctx->cur.color_pos |= !v->negative;
        }
    }
}

/* The first volume of a ramp's group in this frame (then vols[i].next), -1: none. */
static int fogvol__first(const fogvol_context *ctx, const fogvol_ramp *ramp)
{
    return ramp->stamp == ctx->cur.group_stamp ? ramp->head : -1;
}

/* Draw the volumes of one ramp group into the current pass: negative = 0
   positives, 1 negatives, -1 both (FLOAT: the sign goes to the shader). */
static int fogvol__draw_group(fogvol_context *ctx, const fogvol_ramp *ramp, int negative)
{
    int i, n = 0;
    fogvol_draw dr;
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        if ((negative >= 0 && v->negative != negative) || v->density) continue;
        fogvol__draw_for(ctx, v->model, &dr);
        if (v->negative) dr.sign = -1.0f;
        ctx->be.draw_mesh(ctx->be.user_data, v->mesh->handle, &dr);
        ++n;
    }
    return n;
}

/* The reference depth c of a density-textured volume (normalised): the depth of the centre of its
   bounds, 0 when the bounds reach nearer than znear (a front face may be clipped away there). */
static float fogvol__density_ref(const fogvol_context *ctx, const fogvol__volume *v)
{
    double emin = 1e300, sum = 0.0, range = (double)ctx->cur.frame.zfar - ctx->cur.frame.znear, d;
    int c, j;
    for (c = 0; c < 8; ++c) {
        double p[3], e = ctx->cur.eyerow[3];
        for (j = 0; j < 3; ++j) p[j] = (c >> j & 1) ? v->mesh->bmax[j] : v->mesh->bmin[j];
        for (j = 0; j < 3; ++j)
            e += ctx->cur.eyerow[j] * (v->model[j] * p[0] + v->model[4 + j] * p[1] + v->model[8 + j] * p[2] + v->model[12 + j]);
        if (e < emin) emin = e;
        sum += e;
    }
    if (emin < ctx->cur.frame.znear) return 0.0f;
    d = (sum / 8.0 - ctx->cur.frame.znear) / range;
    return (float)(d > 1.0 ? 1.0 : d);
}

/* SPECIALIZE_DITHER where the encode computes by integer ALU with the dither on */
static unsigned fogvol__dither_bit(const fogvol_context *ctx)
{
    return ctx->cfg.dither && fogvol__has(ctx, FOGVOL_VARIANT_ALU) ? (unsigned)FOGVOL_SPECIALIZE_DITHER : 0u;
}

/* SPECIALIZE_DEPTH_FROM_Z where the pass's fv_lin and fv_lin2 (fogvol__lin_uniforms) do not depend on
   the pixel: their x and y terms, which come out of eyerow * invVP as rounding residues for a
   projection without an oblique near plane (1e-17 of the others from separate view and projection
   matrices, 4e-9 from a float view-projection), are below 2^-24 of the z and constant terms, the
   rounding the general program's float dot products make in those anyway */
static unsigned fogvol__depth_from_z_bit(const fogvol_pass *ps)
{
    const float *a = ps->uniforms[FOGVOL_U_LINEAR], *b = ps->uniforms[FOGVOL_U_LINEAR_W];
    double tiny = 1.0 / 16777216.0;
    return fabs(a[0]) + fabs(a[1]) <= tiny * (fabs(a[2]) + fabs(a[3])) &&
                   fabs(b[0]) + fabs(b[1]) <= tiny * (fabs(b[2]) + fabs(b[3]))
               ? (unsigned)FOGVOL_SPECIALIZE_DEPTH_FROM_Z
               : 0u;
}

/* SPECIALIZE_ORIGIN where the frame's viewport starts at the window origin (its offset, added to
   every read of fogvol's targets and of the engine's depth, is 0) */
static unsigned fogvol__origin_bit(const fogvol_context *ctx)
{
    return ctx->cur.frame.viewport[0] == 0 && ctx->cur.frame.viewport[1] == 0 ? (unsigned)FOGVOL_SPECIALIZE_ORIGIN : 0u;
}

/* After a sum pass (its state in *base): each density-textured volume of the group in a pass of
   its own with its texture and texture-coordinate rows (negative as in fogvol__draw_group).
   Returns the passes issued. */
static int fogvol__draw_textured(fogvol_context *ctx, const fogvol__run *run, const fogvol_pass *base,
                                 const fogvol_ramp *ramp, int negative)
{
    int i, n = 0;
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        fogvol_pass ps;
        fogvol_draw dr;
        if ((negative >= 0 && v->negative != negative) || !v->density) continue;
        ps = *base;
        ps.clear = 0;
        if (ps.read_target) { /* (the general program samples O) */
            ps.textures[FOGVOL__UNIT_OPAQUE] = ps.read_target;
            ps.read_target = 0;
        }
        ps.program = fogvol__program(ctx, FOGVOL_PROGRAM_FACE, run->p.origin_bit); /* density texture */
        ps.textures[FOGVOL__UNIT_DENSITY] = v->density->texture;
        memcpy(ps.uniforms[FOGVOL_U_DENSITY_U], v->density_map, 4 * sizeof(float));
        memcpy(ps.uniforms[FOGVOL_U_DENSITY_V], v->density_map + 4, 4 * sizeof(float));
        ps.uniforms[FOGVOL_U_DENSITY][0] = fogvol__density_ref(ctx, v);
        ps.uniforms[FOGVOL_U_DENSITY][1] = 1.0f;
        ps.uniforms[FOGVOL_U_DENSITY][2] = 1.0f / (ctx->cur.frame.zfar - ctx->cur.frame.znear);
        ctx->be.begin_pass(ctx->be.user_data, &ps);
        fogvol__draw_for(ctx, v->model, &dr);
        if (v->negative) dr.sign = -1.0f;
        ctx->be.draw_mesh(ctx->be.user_data, v->mesh->handle, &dr);
        fogvol__end_pass(ctx);
        ++n;
    }
    return n;
}

/* The composite of a group: the colour texture of its first volume that has one. */
static void fogvol__group_color(const fogvol_context *ctx, const fogvol_ramp *ramp, fogvol_pass *ps)
{
    int i;
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        if (!v->color) continue;
        ps->textures[FOGVOL__UNIT_CTEX] = v->color->texture;
        memcpy(ps->uniforms[FOGVOL_U_COLOR_U], v->color_map, 3 * sizeof(float));
        memcpy(ps->uniforms[FOGVOL_U_COLOR_V], v->color_map + 3, 3 * sizeof(float));
        ps->uniforms[FOGVOL_U_COLOR_U][3] = 1.0f;
        return;
    }
}

/* One sum pass over a group: the faces culled by 'cull' are left out for the
   positive volumes; the negative volumes swap front and back. */
static int fogvol__sum_pass(fogvol_context *ctx, const fogvol__run *run, fogvol_pass *ps, fogvol_handle target,
                            int clear, fogvol_cull cull, fogvol_pass_blend blend, const fogvol_ramp *ramp, int has_neg)
{
    int passes = 1;
    ps->target = target;
    ps->clear = clear;
    ps->cull = cull;
    ps->blend = blend;
    ctx->be.begin_pass(ctx->be.user_data, ps);
    fogvol__draw_group(ctx, ramp, 0);
    fogvol__end_pass(ctx);
    passes += fogvol__draw_textured(ctx, run, ps, ramp, 0);
    if (has_neg) {
        ps->clear = 0;
        ps->cull = cull == FOGVOL_CULL_FRONT ? FOGVOL_CULL_BACK : FOGVOL_CULL_FRONT;
        ctx->be.begin_pass(ctx->be.user_data, ps);
        fogvol__draw_group(ctx, ramp, 1);
        fogvol__end_pass(ctx);
        passes += 1 + fogvol__draw_textured(ctx, run, ps, ramp, 1);
    }
    return passes;
}

/* SINGLE_TARGET: the sum goes up (back faces) then down (front faces), so a
   channel that saturated at 255 can come back below it; the debug read-back
   also looks at S after the additions. Marks saturated pixels in sat. */
static fogvol_result fogvol__single_peak(fogvol_context *ctx, unsigned char *sat)
{
    size_t n = (size_t)ctx->gpu.target_w * (size_t)ctx->gpu.target_h, i;
    unsigned char *px;
    fogvol_result r;
    if (!ctx->be.read_target) return FOGVOL_ERROR_UNSUPPORTED;
    px = (unsigned char *)fogvol__alloc(&ctx->alloc, n * 4u);
    if (!px) return FOGVOL_ERROR_OUT_OF_MEMORY;
    r = ctx->be.read_target(ctx->be.user_data, ctx->gpu.tgt_b, px, n * 4u);
    for (i = 0; r == FOGVOL_SUCCESS && i < n; ++i)
        sat[i] = px[4 * i] == 255 || px[4 * i + 1] == 255 || px[4 * i + 2] == 255 || px[4 * i + 3] == 255;
    fogvol__free(&ctx->alloc, px);
    return r;
}

/* WIDE: six digits over two attachments per sum. */
static fogvol_result fogvol__debug_capture_wide(fogvol_context *ctx, int *overflow)
{
    size_t n = (size_t)ctx->gpu.target_w * (size_t)ctx->gpu.target_h, i;
    unsigned char *px[4];
    fogvol_handle t[4];
    fogvol_result r = FOGVOL_SUCCESS;
    double range = (double)ctx->cur.frame.zfar - ctx->cur.frame.znear, n3 = (double)ctx->cfg.enc.levels * ctx->cfg.enc.levels * ctx->cfg.enc.levels;
    int k;
    t[0] = ctx->gpu.tgt_b;
    t[1] = ctx->gpu.tgt_f;
    t[2] = ctx->gpu.tgt_b2;
    t[3] = ctx->gpu.tgt_f2;
    px[0] = (unsigned char *)fogvol__alloc(&ctx->alloc, n * 16u);
    if (!px[0]) return FOGVOL_ERROR_OUT_OF_MEMORY;
    for (k = 1; k < 4; ++k) px[k] = px[0] + n * 4u * (size_t)k;
    for (k = 0; k < 4 && r == FOGVOL_SUCCESS; ++k) r = ctx->be.read_target(ctx->be.user_data, t[k], px[k], n * 4u);
    *overflow = 0;
    for (i = 0; r == FOGVOL_SUCCESS && i < n; ++i) {
        int sat = 0, c;
        for (k = 0; k < 4; ++k)
            for (c = 0; c < 4; ++c) sat |= px[k][4 * i + c] == 255;
        *overflow += sat;
        ctx->cur.frame.debug_thickness[i] = (float)((fogvol_decode_difference(&ctx->cfg.enc, px[0] + 4 * i, px[1] + 4 * i) +
                                                 fogvol_decode_difference(&ctx->cfg.enc, px[2] + 4 * i, px[3] + 4 * i) / n3) *
                                                range);
    }
    fogvol__free(&ctx->alloc, px[0]);
    return r;
}

/* fogvol_frame_desc.downsample 2: the viewport's debug thickness from the half-resolution float sums,
   bilinear as the composite reads them (FV_DOWNSAMPLE: the tw x th texels span the w x h pixels) */
static void fogvol__debug_upsample(fogvol_context *ctx, const float *lo, double range)
{
    int w = ctx->cur.frame.viewport[2], h = ctx->cur.frame.viewport[3], tw = ctx->gpu.target_w, th = ctx->gpu.target_h, x, y;
    for (y = 0; y < h; ++y) {
        double py = (y + 0.5) * th / h - 0.5, iy = floor(py), fy = py - iy;
        int y0 = iy < 0 ? 0 : iy > th - 1 ? th - 1 : (int)iy, y1 = iy + 1 > th - 1 ? th - 1 : (int)iy + 1;
        for (x = 0; x < w; ++x) {
            double px = (x + 0.5) * tw / w - 0.5, ix = floor(px), fx = px - ix;
            int x0 = ix < 0 ? 0 : ix > tw - 1 ? tw - 1 : (int)ix, x1 = ix + 1 > tw - 1 ? tw - 1 : (int)ix + 1;
            double a = lo[y0 * tw + x0] + (lo[y0 * tw + x1] - (double)lo[y0 * tw + x0]) * fx;
            double c = lo[y1 * tw + x0] + (lo[y1 * tw + x1] - (double)lo[y1 * tw + x0]) * fx;
            ctx->cur.frame.debug_thickness[(size_t)y * (size_t)w + (size_t)x] = (float)((a + (c - a) * fy) * range);
        }
    }
}

/* Decoded thickness per pixel (world units) from the sum targets, and the
   count of pixels whose sums saturated (peak: SINGLE_TARGET's marks or NULL). */
static fogvol_result fogvol__debug_read(fogvol_context *ctx, const fogvol__run *run, const unsigned char *peak,
                                        int *overflow)
{
    size_t n = (size_t)ctx->gpu.target_w * (size_t)ctx->gpu.target_h, i;
    unsigned char *b, *f, *o;
    float *fl;
    fogvol_result r;
    double range = (double)ctx->cur.frame.zfar - ctx->cur.frame.znear;
    int single = run->p.single, count = run->p.count;
    if (!ctx->be.read_target) return FOGVOL_ERROR_UNSUPPORTED;
    if (ctx->gpu.tgt_b2) return fogvol__debug_capture_wide(ctx, overflow);
    b = (unsigned char *)fogvol__alloc(&ctx->alloc, n * 12u);
    if (!b) return FOGVOL_ERROR_OUT_OF_MEMORY;
    f = b + n * 4u;
    o = f + n * 4u;
    *overflow = 0;
    r = ctx->be.read_target(ctx->be.user_data, ctx->gpu.tgt_b, b, n * 4u);
    if (run->p.float_sums) {
        fl = (float *)(void *)b;
        if (r == FOGVOL_SUCCESS && ctx->cur.frame.downsample == 2) fogvol__debug_upsample(ctx, fl, range);
        else
            for (i = 0; r == FOGVOL_SUCCESS && i < n; ++i) ctx->cur.frame.debug_thickness[i] = (float)(fl[i] * range);
        fogvol__free(&ctx->alloc, b);
        return r;
    }
    if (run->xsum) { /* FOGVOL_SPEEDUP_EXACT_SUM: a 32-bit integer (two's complement), 2^24 per depth range */
        for (i = 0; r == FOGVOL_SUCCESS && i < n; ++i) {
            const unsigned char *p = b + 4 * i;
            uint32_t u = (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
            double v = u >= 0x80000000u ? (double)u - 4294967296.0 : (double)u;
            ctx->cur.frame.debug_thickness[i] = (float)(v / 16777216.0 * range);
        }
        fogvol__free(&ctx->alloc, b);
        return r;
    }
    if (r == FOGVOL_SUCCESS && !single) r = ctx->be.read_target(ctx->be.user_data, ctx->gpu.tgt_f, f, n * 4u);
    if (r == FOGVOL_SUCCESS && count) r = ctx->be.read_target(ctx->be.user_data, ctx->gpu.tgt_o, o, n * 4u);
    for (i = 0; r == FOGVOL_SUCCESS && i < n; ++i) {
        unsigned char *pb = b + 4 * i, *pf = f + 4 * i;
        int k, sat = 0;
        double t;
        if (single) {
            for (k = 0; k < 4; ++k) {
                sat |= pb[k] == 255 || pb[k] == 0;
                pf[k] = 128; /* S - bias */
            }
            if (peak) sat |= peak[i];
        } else {
            for (k = 0; k < 4; ++k) sat |= pb[k] == 255 || pf[k] == 255;
        }
        if (count) { /* alpha holds face counts: add the opaque depth per missing back face */
            int missing = (int)pf[3] - (int)pb[3];
            pb[3] = pf[3] = 0;
            t = fogvol_decode_difference(&ctx->cfg.enc, pb, pf) + missing * fogvol_decode(&ctx->cfg.enc, o + 4 * i);
        } else {
            t = fogvol_decode_difference(&ctx->cfg.enc, pb, pf);
        }
        *overflow += sat;
        ctx->cur.frame.debug_thickness[i] = (float)(t * range);
    }
    fogvol__free(&ctx->alloc, b);
    return r;
}

/* The debug read-back, a failure logged (debug_thickness is then not written). */
static fogvol_result fogvol__debug_capture(fogvol_context *ctx, const fogvol__run *run, const unsigned char *peak,
                                           int *overflow)
{
    fogvol_result r = fogvol__debug_read(ctx, run, peak, overflow);
    if (r != FOGVOL_SUCCESS)
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: debug read-back failed (%s): debug_thickness not written",
                    fogvol_result_string(r));
    return r;
}

static int fogvol__want_debug(const fogvol_context *ctx, const fogvol_ramp *ramp, int captured)
{
    return ctx->cur.frame.debug_thickness && !captured && !ctx->cur.debug_gone &&
           (ctx->cur.frame.debug_ramp == NULL || ctx->cur.frame.debug_ramp == ramp);
}

/* After the groups: a debug read-back that no group made (the frame draws no volume of debug_ramp,
   or no volume at all) is the thickness the frame draws for it, 0. */
static void fogvol__debug_empty(fogvol_context *ctx, const fogvol__run *run)
{
    size_t n = (size_t)ctx->cur.frame.viewport[2] * (size_t)ctx->cur.frame.viewport[3], i;
    if (!ctx->cur.frame.debug_thickness || run->captured) return;
    for (i = 0; i < n; ++i) ctx->cur.frame.debug_thickness[i] = 0.0f;
}

/* Window rectangles (x, y, w, h) that hold every pixel some volumes can cover:
   the 8 corners of each mesh's box projected (fogvol__rect_add, into the window
   extent lo, hi), rounded out by a pixel, within the viewport
   (fogvol__rect_finish). A corner nearer than the near plane (perspective;
   NEAR_CLAMP moves such vertices) or at w <= 0 gives the whole viewport
   (rect_add returns 0). An empty rectangle is 1x1 in the corner (nothing is
   drawn). */
static int fogvol__rect_add(const fogvol_context *ctx, const fogvol__volume *v, double lo[2], double hi[2])
{
    const int *vp = ctx->cur.frame.viewport;
    double m[16], mvp[16], wmin;
    int k, c;
    wmin = ctx->cur.frame.projection[15] == 0.0f ? (double)ctx->cur.frame.znear * (1.0 - 1e-6) : 1e-12;
    fogvol__tod(m, v->model);
    fogvol__mul4(mvp, ctx->cur.viewproj, m);
    for (k = 0; k < 8; ++k) {
        double p[3], clip[4];
        for (c = 0; c < 3; ++c) p[c] = (k >> c & 1) ? v->mesh->bmax[c] : v->mesh->bmin[c];
        for (c = 0; c < 4; ++c) clip[c] = mvp[c] * p[0] + mvp[4 + c] * p[1] + mvp[8 + c] * p[2] + mvp[12 + c];
        if (!(clip[3] >= wmin)) return 0; /* behind the near plane (or NaN): whole viewport */
        for (c = 0; c < 2; ++c) {
            double win = vp[c] + (clip[c] / clip[3] * 0.5 + 0.5) * vp[c + 2];
            if (win < lo[c]) lo[c] = win;
            if (win > hi[c]) hi[c] = win;
        }
    }
    return 1;
}

/* The extent rounded out and clamped to the viewport in floating point before it becomes integers (a
   volume far off screen projects to any double: 1e9 pixels and more, or infinite). */
static void fogvol__rect_finish(const fogvol_context *ctx, const double lo[2], const double hi[2], int rect[4])
{
    const int *vp = ctx->cur.frame.viewport;
    int c;
    for (c = 0; c < 2; ++c) { /* downsample 2: the bilinear read spreads a texel over 2 more pixels */
        double m = ctx->cur.frame.downsample == 2 ? 2.0 : 0.0, v0 = vp[c], v1 = (double)vp[c] + vp[c + 2];
        double a = FOGVOL_FLOOR(lo[c]) - 1.0 - m, b = FOGVOL_FLOOR(hi[c]) + 2.0 + m;
        a = !(a >= v0) ? v0 : a > v1 ? v1 : a;
        b = !(b >= v0) ? v0 : b > v1 ? v1 : b;
        rect[c] = (int)a;
        rect[c + 2] = b > a ? (int)(b - a) : 0;
    }
    if (rect[2] <= 0 || rect[3] <= 0) { /* off screen: a 1x1 rectangle the volumes do not reach */
        rect[0] = vp[0];
        rect[1] = vp[1];
        rect[2] = rect[3] = 1;
    }
}

/* The rectangle of the volumes of a ramp group. */
static void fogvol__group_rect(const fogvol_context *ctx, const fogvol_ramp *ramp, int rect[4])
{
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    int i;
    memcpy(rect, ctx->cur.frame.viewport, 4 * sizeof(int));
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next)
        if (!fogvol__rect_add(ctx, &ctx->cur.vols[i], lo, hi)) return;
    fogvol__rect_finish(ctx, lo, hi, rect);
}

static void fogvol__target_space(fogvol_context *ctx, fogvol_pass *ps)
{
    ps->viewport[0] = ps->viewport[1] = 0;
    ps->viewport[2] = ctx->gpu.target_w;
    ps->viewport[3] = ctx->gpu.target_h;
    ps->uniforms[FOGVOL_U_SCREEN][2] = ps->uniforms[FOGVOL_U_SCREEN][3] = 0.0f;
    memset(ps->scissor, 0, sizeof ps->scissor);
    ps->draw_buffer = ps->alpha_coverage = 0;
    memset(ps->textures, 0, sizeof ps->textures);
    memset(ps->native_textures, 0, sizeof ps->native_textures);
    ps->textures[FOGVOL__UNIT_RG] = ctx->gpu.tex_rg;
    ps->textures[FOGVOL__UNIT_BLUE] = ctx->gpu.tex_blue;
    ps->textures[FOGVOL__UNIT_DITHER] = ctx->gpu.tex_dither;
}

/* The uniforms every pass of the frame gets, in run->base (target space, lookup textures bound). */
static void fogvol__frame_uniforms(fogvol_context *ctx, fogvol__run *run)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    fogvol_pass *ps = &run->base;
    fogvol_constants k;
    fogvol_compute_constants(&ctx->cfg.enc, fd->znear, fd->zfar, 0.0f, &k);
    memset(ps, 0, sizeof *ps);
    ps->per_sample = ctx->cur.samples > 1;
    ps->uniforms[FOGVOL_U_ENC][0] = (float)ctx->cfg.enc.levels;
    ps->uniforms[FOGVOL_U_ENC][1] = (float)ctx->cfg.enc.levels * (float)ctx->cfg.enc.levels;
    ps->uniforms[FOGVOL_U_ENC][2] = k.depth_offset;
    ps->uniforms[FOGVOL_U_ENC][3] = k.depth_max;
    ps->uniforms[FOGVOL_U_DITHER][0] = ctx->cfg.dither ? 255.0f : 0.0f;
    ps->uniforms[FOGVOL_U_DITHER][1] = 1.0f / (float)ctx->cfg.enc.dither_steps;
    ps->uniforms[FOGVOL_U_DITHER][2] = (float)ctx->cfg.enc.dither_steps;
    ps->uniforms[FOGVOL_U_DITHER][3] = ctx->cfg.dither ? fogvol__dither_offset(ctx) : 0.0f;
    ps->uniforms[FOGVOL_U_SCREEN][0] = 1.0f / (float)ctx->gpu.target_w; /* target space (downsample: half) */
    ps->uniforms[FOGVOL_U_SCREEN][1] = 1.0f / (float)ctx->gpu.target_h;
    if (!run->p.float_sums) {
        memcpy(ps->uniforms[FOGVOL_U_DECODE], k.decode, sizeof k.decode);
        if (!run->p.borrow) ps->uniforms[FOGVOL_U_DECODE][3] = 0.0f; /* alpha: counts, or no borrow */
        if (run->p.wide) { /* u = clamp(d, 0, 1 - N^-6), no offset */
            double n6 = (double)ctx->cfg.enc.levels * ctx->cfg.enc.levels * ctx->cfg.enc.levels;
            n6 *= n6;
            ps->uniforms[FOGVOL_U_ENC][2] = 0.0f;
            ps->uniforms[FOGVOL_U_ENC][3] = (float)(1.0 - 1.0 / n6);
        }
    } else {
        ps->uniforms[FOGVOL_U_DECODE][0] = fd->zfar - fd->znear;
    }
    fogvol__clip_uniforms(ctx, &run->info, ps);
    ps->uniforms[FOGVOL_U_MISC][1] = 1.0f; /* fogvol's own clip z in every pass */
    ps->uniforms[FOGVOL_U_NEARFAR][0] = k.near_far[0];
    ps->uniforms[FOGVOL_U_NEARFAR][1] = k.near_far[1];
    ps->uniforms[FOGVOL_U_NEARFAR][2] = (float)fd->viewport[0]; /* ENGINE_DEPTH: target pixel -> engine texel */
    ps->uniforms[FOGVOL_U_NEARFAR][3] = (float)fd->viewport[1];
    fogvol__target_space(ctx, ps);
    run->p.depth_from_z_bit = fogvol__depth_from_z_bit(ps);
}

/* The opaque depth O, encoded like the volumes' depth: the occluders drawn by fogvol (or by the
   engine's callbacks), or PS20 + ENGINE_DEPTH: the engine's depth texture encoded full-screen. Not
   drawn where the engine wrote O (MRT, fogvol_occluder_prepare) or the tier reads no O. */
static void fogvol__opaque_pass(fogvol_context *ctx, fogvol__run *run)
{
    const fogvol__plan *p = &run->p;
    fogvol_pass ps = run->base;
    int engine = p->o_engine, i;
    if (!p->own_o) {
        ctx->gpu.o_far = 0; /* the engine wrote O (or there is none) */
        return;
    }
    if (p->no_opaque && ctx->gpu.o_far) return; /* O still holds the far plane of an earlier frame */
    ctx->gpu.o_far = p->no_opaque;
    ps.target = ctx->gpu.tgt_o;
    ps.clear = 1;
    if (!p->float_o) /* the far plane: every digit N - 1, or d = 1 */
        ps.clear_color[0] = ps.clear_color[1] = ps.clear_color[2] = (float)(ctx->cfg.enc.levels - 1) / 255.0f;
    else ps.clear_color[0] = 1.0f;
    ps.depth_test = ps.depth_write = 1;
    ps.program = fogvol__program(ctx, FOGVOL_PROGRAM_ENCODE, (engine ? p->origin_bit | p->depth_from_z_bit : 0u) |
                                                                 p->dither_bit | p->count_bit);
    if (engine) ps.native_textures[FOGVOL__UNIT_OPAQUE] = run->engine_depth;
    ctx->be.begin_pass(ctx->be.user_data, &ps);
    run->st.passes++;
    ctx->cur.in_occluder_pass = 1;
    if (engine) ctx->be.draw_fullscreen(ctx->be.user_data);
    for (i = 0; i < ctx->cur.nocc && !engine; ++i) {
        const fogvol__occluder *o = &ctx->cur.occ[i];
        if (o->fn) {
            o->fn(ctx, o->user_data);
        } else {
            fogvol_draw dr;
            fogvol__draw_for(ctx, o->model, &dr);
            ctx->be.draw_mesh(ctx->be.user_data, o->mesh->handle, &dr);
        }
        run->st.occluders++;
    }
    ctx->cur.in_occluder_pass = 0;
    fogvol__end_pass(ctx);
}

/* The face program of a group's sums: summing in integers where the group does (run->xsum,
   FOGVOL_SPEEDUP_EXACT_SUM), reading O from the framebuffer where the frame's faces read fogvol's O
   (ps->read_target: O beside the sum; FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH). A program that does not build
   turns its speed-up off (the integer sum first) and the next is tried: digits, O sampled. */
static fogvol_handle fogvol__face_program(fogvol_context *ctx, fogvol__run *run, fogvol_pass *ps, unsigned spec)
{
    int fetch = run->p.fetch_o;
    for (;;) { /* the integer sum (FOGVOL_SPEEDUP_EXACT_SUM), O from the framebuffer, each dropped if it fails */
        unsigned bits = spec | (run->xsum ? (unsigned)FOGVOL_SPECIALIZE_EXACT_SUM : 0u) |
                        (fetch ? (unsigned)FOGVOL_SPECIALIZE_FETCH_O : 0u);
        fogvol_handle h = fogvol__program(ctx, FOGVOL_PROGRAM_FACE, bits);
        if (bits == spec || (h && h != ctx->gpu.prog[FOGVOL_PROGRAM_FACE])) { /* (the general one: a failure) */
            ps->read_target = fetch ? ctx->gpu.tgt_o : 0;
            run->st.fetched_o |= fetch;
            return h;
        }
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: no face program %s (it did not build): %s",
                    run->xsum ? "summing in integers" : "reading O from the framebuffer",
                    run->xsum ? "the faces sum digits (FOGVOL_SPEEDUP_EXACT_SUM off)"
                              : "the faces sample O (FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH off)");
        if (run->xsum) {
            ctx->cfg.exact_sum = run->p.exact_sum = run->xsum = 0;
        } else {
            ctx->cfg.fetch_o = run->p.fetch_o = 0;
            fetch = 0;
        }
    }
}

/* The face program of FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST frames. */
static unsigned fogvol__engine_test_spec(void)
{
    return FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_NO_DENSITY | FOGVOL_SPECIALIZE_ORIGIN; /* (reads nothing) */
}

/* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: E in the texel coordinates of the engine's depth (its texture, or
   copy_depth's copy, which keeps them) at any viewport, so that the depth lines up with E as its depth
   buffer: the window up to the viewport's far corner, grown as the viewports of later frames need (the
   two halves of a split screen share it), never shrunk. 0: none; a backend that makes no such target
   turns the speed-up off (single-sample, logged) or leaves that sample count's frames to the per-sample
   read (logged once). */
static fogvol_handle fogvol__window_e(fogvol_context *ctx)
{
    const int *vp = ctx->cur.frame.viewport;
    int w = vp[0] + vp[2], h = vp[1] + vp[3], ms = ctx->cur.samples > 1;
    fogvol_target_desc td;
    if (ctx->gpu.tgt_e && ctx->gpu.e_samples == ctx->cur.samples && ctx->gpu.e_w >= w && ctx->gpu.e_h >= h)
        return ctx->gpu.tgt_e;
    if (ms && ctx->gpu.e_refused == ctx->cur.samples) return 0;
    if (ctx->gpu.tgt_e) {
        if (ctx->gpu.e_samples == ctx->cur.samples) {
            if (ctx->gpu.e_w > w) w = ctx->gpu.e_w;
            if (ctx->gpu.e_h > h) h = ctx->gpu.e_h;
        }
        ctx->be.destroy_target(ctx->be.user_data, ctx->gpu.tgt_e);
        ctx->gpu.tgt_e = 0;
        ctx->gpu.e_w = ctx->gpu.e_h = ctx->gpu.e_samples = 0;
    }
    memset(&td, 0, sizeof td);
    td.width = w;
    td.height = h;
    td.samples = ctx->cur.samples;
    td.format = FOGVOL_FORMAT_RG32F;
    td.color_count = 1;
    td.label = ms ? "fogvol depth sum and face count, depth-tested (float, multisample)"
                  : "fogvol depth sum and face count, depth-tested (float)";
    if (ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_e) != FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, ms ? FOGVOL_LOG_INFO : FOGVOL_LOG_WARNING,
                    ms ? "fogvol: no %dx%d multisample RG32F target: multisampled FLOAT + ENGINE_DEPTH frames read the "
                         "engine's depth per sample"
                       : "fogvol: no %dx%d RG32F target: FLOAT + ENGINE_DEPTH frames read the engine's depth per face "
                         "(FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST off)",
                    w, h);
        if (ms) ctx->gpu.e_refused = ctx->cur.samples;
        else ctx->cfg.engine_test = 0;
        ctx->gpu.tgt_e = 0;
        return 0;
    }
    ctx->gpu.e_w = w;
    ctx->gpu.e_h = h;
    ctx->gpu.e_samples = ctx->cur.samples;
    return ctx->gpu.tgt_e;
}

/* The depth-tested face program: a single-sample one in multisampled frames too, which draw it shaded
   once per pixel and tested per sample (fogvol_pass.per_sample 2); it reads nothing. */
static fogvol_handle fogvol__engine_test_face(fogvol_context *ctx)
{
    return fogvol__program_set(ctx, FOGVOL_PROGRAM_FACE, fogvol__engine_test_spec(), 0);
}

/* Whether the depth-tested face program exists (built on first use); if it does not, the speed-up is
   off from this frame on (logged) and the frame reads the engine's depth per face. */
static int fogvol__engine_test_programs(fogvol_context *ctx)
{
    if (fogvol__engine_test_face(ctx)) return 1;
    fogvol__log(&ctx->log, FOGVOL_LOG_WARNING, "fogvol: no depth-tested face program: FLOAT + ENGINE_DEPTH reads the "
                                               "engine's depth per face (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST off)");
    ctx->cfg.engine_test = 0;
    return 0;
}

/* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: every face of the group in one pass into the RG32F sum E, whose depth
   buffer is the engine's depth (run->engine_depth: its texture, or fogvol's copy), tested, not written;
   each face's clip z is the engine's (plan zmap), so the test compares what the engine's rasteriser
   wrote with what it would write for the face. */
static void fogvol__engine_test_pass(fogvol_context *ctx, fogvol__run *run, const fogvol_ramp *ramp)
{
    fogvol_pass ps = run->base;
    fogvol_draw dr;
    int i, j;
    ps.program = fogvol__engine_test_face(ctx);
    ps.per_sample = ctx->cur.samples > 1 ? 2 : 0; /* multisampled: tested per sample, shaded per pixel */
    ps.target = run->e;
    ps.clear = 1;
    memcpy(ps.viewport, ctx->cur.frame.viewport, sizeof ps.viewport); /* E in window coordinates: the */
    memcpy(ps.scissor, ctx->cur.frame.viewport, sizeof ps.scissor);   /* engine's viewport, cleared inside */
    ps.blend = FOGVOL_PASS_BLEND_ADD;
    ps.depth_test = 1;
    ps.depth_texture = run->engine_depth;
    ps.depth_greater = run->p.z_greater;
    ps.uniforms[FOGVOL_U_MISC][1] = 0.0f; /* the projection's clip z (mapped below), not fogvol's */
    ctx->be.begin_pass(ctx->be.user_data, &ps);
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        fogvol__draw_for(ctx, v->model, &dr);
        for (j = 0; j < 4; ++j) /* row z of the column-major mvp */
            dr.mvp[j * 4 + 2] = (float)(run->p.zmap[0] * dr.mvp[j * 4 + 2] + run->p.zmap[1] * dr.mvp[j * 4 + 3]);
        if (v->negative) dr.sign = -1.0f;
        ctx->be.draw_mesh(ctx->be.user_data, v->mesh->handle, &dr);
    }
    fogvol__end_pass(ctx);
    run->st.passes++;
}

/* A FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST group's composite and debug read-back: E, the engine's depth, and
   fv_misc.w = c, the sum of the signs of the group's volumes that hold the near plane's rectangle (their
   front faces clipped on every pixel: r - o (g - c)). */
static void fogvol__engine_test_sources(const fogvol_context *ctx, const fogvol__run *run, const fogvol_ramp *ramp,
                                        fogvol_pass *ps)
{
    int i, c = 0;
    for (i = fogvol__first(ctx, ramp); i >= 0; i = ctx->cur.vols[i].next)
        if (ctx->cur.vols[i].near_inside) c += ctx->cur.vols[i].negative ? -1 : 1;
    ps->textures[FOGVOL__UNIT_BACK] = run->e;
    ps->native_textures[FOGVOL__UNIT_OPAQUE] = run->engine_depth;
    ps->uniforms[FOGVOL_U_MISC][3] = (float)c;
    ps->uniforms[FOGVOL_U_SCREEN][0] = 1.0f / (float)ctx->gpu.e_w; /* E in window coordinates (the */
    ps->uniforms[FOGVOL_U_SCREEN][1] = 1.0f / (float)ctx->gpu.e_h; /* program is ORIGIN): FV_SCREEN's scale */
}

/* The debug read-back of a FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST group: r - o (g - c), as its composite takes
   it, written into B (R32F) by the composite program (fv_rampmap.w = 1: the thickness, not a colour),
   for fogvol__debug_capture to read as any FLOAT sum. */
static fogvol_result fogvol__engine_test_resolve(fogvol_context *ctx, fogvol__run *run, const fogvol_ramp *ramp)
{
    fogvol_pass ps = run->base;
    memset(ps.textures, 0, sizeof ps.textures);
    fogvol__engine_test_sources(ctx, run, ramp, &ps);
    ps.uniforms[FOGVOL_U_SCREEN][2] = (float)ctx->cur.frame.viewport[0]; /* B's pixel -> E's (window) */
    ps.uniforms[FOGVOL_U_SCREEN][3] = (float)ctx->cur.frame.viewport[1]; /* pixel; the engine's texel too */
    ps.target = ctx->gpu.tgt_b;
    ps.clear = 1;
    ps.uniforms[FOGVOL_U_RAMP][3] = 1.0f;
    ps.program = fogvol__program(ctx, FOGVOL_PROGRAM_COMPOSITE,
                                 FOGVOL_SPECIALIZE_ENGINE_TEST | FOGVOL_SPECIALIZE_RAMP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE |
                                     FOGVOL_SPECIALIZE_NO_OVERFLOW | run->p.origin_bit | run->p.depth_from_z_bit);
    if (!ps.program) return FOGVOL_ERROR_BACKEND;
    ctx->be.begin_pass(ctx->be.user_data, &ps);
    ctx->be.draw_fullscreen(ctx->be.user_data);
    fogvol__end_pass(ctx);
    return FOGVOL_SUCCESS;
}

/* The face sums of one ramp group: FLOAT one signed pass into B; SINGLE_TARGET back faces up and
   front faces down in B (with the overflow check at the peak); else back faces into B and front
   faces into F. The debug read-back, when asked for this group, follows the sums. */
static void fogvol__sum_passes(fogvol_context *ctx, fogvol__run *run, const fogvol_ramp *ramp, int has_neg)
{
    const fogvol__plan *p = &run->p;
    fogvol_pass ps = run->base;
    unsigned char *peak = NULL;
    fogvol_result r;
    unsigned spec = FOGVOL_SPECIALIZE_NO_DENSITY | p->origin_bit; /* textured volumes: below */
    if (p->engine_test) { /* (no density texture in such frames) */
        fogvol__engine_test_pass(ctx, run, ramp);
        if (fogvol__want_debug(ctx, ramp, run->captured)) {
            r = fogvol__engine_test_resolve(ctx, run, ramp);
            if (r == FOGVOL_SUCCESS) r = fogvol__debug_capture(ctx, run, NULL, &run->overflow);
            run->captured = 1;
            if (r != FOGVOL_SUCCESS) run->r = r;
        }
        return;
    }
    if (p->no_opaque) spec |= FOGVOL_SPECIALIZE_NO_OPAQUE;
    else if (p->float_sums) spec |= FOGVOL_SPECIALIZE_OPAQUE;
    if (p->engine_read) spec |= p->depth_from_z_bit; /* (the faces read the engine's depth) */
    spec |= p->dither_bit | p->count_bit;
    ps.program = fogvol__face_program(ctx, run, &ps, spec);
    ps.depth_test = p->count; /* COUNT: against the opaque depth shared from O */
    ps.uniforms[FOGVOL_U_SPEEDUP][0] = p->no_opaque && p->float_sums ? 1.0f : 0.0f;
    ps.uniforms[FOGVOL_U_MISC][3] = p->near_clamp;
    if (p->engine_read) ps.native_textures[FOGVOL__UNIT_OPAQUE] = run->engine_depth;
    else if (!ps.read_target) ps.textures[FOGVOL__UNIT_OPAQUE] = ctx->gpu.tgt_o;
    ps.textures[FOGVOL__UNIT_OPAQUE2] = ctx->gpu.tgt_o2;
    if (p->float_sums || run->xsum) { /* every face, signed by gl_FrontFacing */
        ps.target = ctx->gpu.tgt_b;
        ps.clear = 1;
        ps.blend = run->xsum ? FOGVOL_PASS_BLEND_NONE : FOGVOL_PASS_BLEND_ADD; /* (EXACT_SUM: the program adds) */
        ctx->be.begin_pass(ctx->be.user_data, &ps);
        fogvol__draw_group(ctx, ramp, -1);
        fogvol__end_pass(ctx);
        run->st.passes += 1 + fogvol__draw_textured(ctx, run, &ps, ramp, -1);
        run->st.exact_sum += run->xsum;
    } else if (p->single) {
        ps.clear_color[0] = ps.clear_color[1] = ps.clear_color[2] = ps.clear_color[3] = 128.0f / 255.0f;
        run->st.passes +=
            fogvol__sum_pass(ctx, run, &ps, ctx->gpu.tgt_b, 1, FOGVOL_CULL_FRONT, FOGVOL_PASS_BLEND_ADD, ramp, has_neg);
        if (run->checks) fogvol__check_pass(ctx, run, &ps, 1, &run->st); /* saturation at the peak of the sum */
        if (fogvol__want_debug(ctx, ramp, run->captured)) {
            peak = (unsigned char *)fogvol__alloc(&ctx->alloc, (size_t)run->w * (size_t)run->h);
            r = peak ? fogvol__single_peak(ctx, peak) : FOGVOL_ERROR_OUT_OF_MEMORY;
            if (r != FOGVOL_SUCCESS) run->r = r;
        }
        run->st.passes +=
            fogvol__sum_pass(ctx, run, &ps, ctx->gpu.tgt_b, 0, FOGVOL_CULL_BACK, FOGVOL_PASS_BLEND_SUBTRACT, ramp, has_neg);
    } else {
        run->st.passes +=
            fogvol__sum_pass(ctx, run, &ps, ctx->gpu.tgt_b, 1, FOGVOL_CULL_FRONT, FOGVOL_PASS_BLEND_ADD, ramp, has_neg);
        run->st.passes +=
            fogvol__sum_pass(ctx, run, &ps, ctx->gpu.tgt_f, 1, FOGVOL_CULL_BACK, FOGVOL_PASS_BLEND_ADD, ramp, has_neg);
    }
    if (fogvol__want_debug(ctx, ramp, run->captured)) {
        r = fogvol__debug_capture(ctx, run, peak, &run->overflow);
        run->captured = 1;
        if (r != FOGVOL_SUCCESS) run->r = r;
    }
    fogvol__free(&ctx->alloc, peak);
}

/* *ps: target-space state reading the sums (composite texture units), scissored to the group's
   window rectangle as the composite is (the passes after the sums read nothing outside it); PS13
   first resolves B - F into T, which the later passes read instead (not with
   FOGVOL_SPEEDUP_INLINE_RESOLVE: they resolve it themselves). */
static void fogvol__sum_sources(fogvol_context *ctx, fogvol__run *run, const fogvol_ramp *ramp, fogvol_pass *ps)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    int *rc = run->rect;
    *ps = run->base;
    memset(rc, 0, sizeof run->rect);
    fogvol__group_rect(ctx, ramp, rc);
    if (run->info.clip_upper_left) /* NDC y points down the window: mirror the rectangle */
        rc[1] = 2 * fd->viewport[1] + fd->viewport[3] - rc[1] - rc[3];
    ps->scissor[0] = rc[0] - fd->viewport[0]; /* target pixel = window pixel - viewport origin */
    ps->scissor[1] = rc[1] - fd->viewport[1];
    ps->scissor[2] = rc[2];
    ps->scissor[3] = rc[3];
    memset(ps->textures, 0, sizeof ps->textures);
    ps->textures[FOGVOL__UNIT_BACK] = ctx->gpu.tgt_b;
    ps->textures[FOGVOL__UNIT_FRONT] = ctx->gpu.tgt_f;
    ps->textures[FOGVOL__UNIT_COUNTS] = run->p.count ? ctx->gpu.tgt_o : 0;
    ps->textures[FOGVOL__UNIT_BACK2] = ctx->gpu.tgt_b2;
    ps->textures[FOGVOL__UNIT_FRONT2] = ctx->gpu.tgt_f2;
    if (!run->p.resolve) return;
    ps->target = ctx->gpu.tgt_t;
    ps->program = fogvol__program(ctx, FOGVOL_PROGRAM_RESOLVE, run->p.origin_bit | run->p.count_bit);
    ctx->be.begin_pass(ctx->be.user_data, ps);
    ctx->be.draw_fullscreen(ctx->be.user_data);
    fogvol__end_pass(ctx);
    run->st.passes++;
    ps->textures[FOGVOL__UNIT_BACK] = ctx->gpu.tgt_t;
    ps->textures[FOGVOL__UNIT_FRONT] = 0;
}

/* fv_soft of a ramp's composite: (s, 1/(4s), 2s, 0), zeros for hard edges (fogvol_ramp_desc.softness) */
static void fogvol__soft_uniforms(const fogvol_ramp *ramp, fogvol_pass *ps)
{
    float s = ramp->softness;
    ps->uniforms[FOGVOL_U_SOFT][0] = s;
    ps->uniforms[FOGVOL_U_SOFT][1] = s > 0.0f ? 0.25f / s : 0.0f;
    ps->uniforms[FOGVOL_U_SOFT][2] = 2.0f * s;
    ps->uniforms[FOGVOL_U_SOFT][3] = 0.0f;
}

/* FOGVOL_SPEEDUP_BLEND_COLOR: a composite of one colour (spec: EXP, no colour texture, no
   overflow test) takes it from the blend unit where the backend can. */
static void fogvol__blend_color(const fogvol__run *run, fogvol_pass *ps, unsigned *spec)
{
    unsigned need = FOGVOL_SPECIALIZE_EXP | FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE | FOGVOL_SPECIALIZE_NO_OVERFLOW;
    ps->blend_constant = 0;
    if ((*spec & need) != need || !run->p.blend_color) return;
    *spec |= FOGVOL_SPECIALIZE_BLEND_COLOR;
    ps->blend_constant = 1;
    memcpy(ps->blend_color, ps->uniforms[FOGVOL_U_SPEEDUP], 3 * sizeof(float));
    ps->blend_color[3] = 1.0f;
}

/* Composite one ramp group into the engine framebuffer: thickness -> ramp colour and alpha, blended
   as fog or light. ps: the state of fogvol__sum_sources. */
static void fogvol__composite_pass(fogvol_context *ctx, fogvol__run *run, fogvol_pass *ps, const fogvol_ramp *ramp)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    unsigned spec;
    ps->target = 0;
    ps->clear = 0;
    memcpy(ps->viewport, fd->viewport, sizeof ps->viewport);
    memcpy(ps->scissor, run->rect, sizeof ps->scissor);
    ps->uniforms[FOGVOL_U_SCREEN][2] = -(float)fd->viewport[0]; /* window pixel -> target pixel */
    ps->uniforms[FOGVOL_U_SCREEN][3] = -(float)fd->viewport[1];
    ps->blend = ramp->blend == FOGVOL_BLEND_LIGHT ? FOGVOL_PASS_BLEND_LIGHT : FOGVOL_PASS_BLEND_FOG;
    ps->draw_buffer = fd->draw_buffer;
    ps->alpha_coverage = fd->alpha == FOGVOL_ALPHA_COVERAGE;
    if (run->p.exp_composite) memcpy(ps->uniforms[FOGVOL_U_SPEEDUP], ramp->exp_rgba, sizeof ramp->exp_rgba);
    ps->textures[FOGVOL__UNIT_RAMP] = ramp->texture;
    ps->uniforms[FOGVOL_U_RAMP][0] = (float)((double)(ramp->width - 1) / ((double)ramp->width * ramp->max_thickness));
    ps->uniforms[FOGVOL_U_RAMP][1] = 0.5f / (float)ramp->width;
    ps->uniforms[FOGVOL_U_RAMP][2] = fd->show_overflow ? 1.0f : 0.0f;
    fogvol__soft_uniforms(ramp, ps);
    fogvol__group_color(ctx, ramp, ps);
    spec = ps->uniforms[FOGVOL_U_SPEEDUP][3] > 0.0f ? FOGVOL_SPECIALIZE_EXP : FOGVOL_SPECIALIZE_RAMP;
    if (spec == FOGVOL_SPECIALIZE_EXP && run->p.fast_exp) spec |= FOGVOL_SPECIALIZE_FAST_EXP;
    if (ps->uniforms[FOGVOL_U_COLOR_U][3] < 0.5f) spec |= FOGVOL_SPECIALIZE_NO_COLOR_TEXTURE;
    if (!fd->show_overflow) spec |= FOGVOL_SPECIALIZE_NO_OVERFLOW;
    spec |= run->p.origin_bit | run->p.count_bit | (run->xsum ? (unsigned)FOGVOL_SPECIALIZE_EXACT_SUM : 0u);
    if (run->p.engine_test) /* E and the engine's depth both at gl_FragCoord (fogvol__window_e) */
        spec |= FOGVOL_SPECIALIZE_ENGINE_TEST | run->p.depth_from_z_bit | FOGVOL_SPECIALIZE_ORIGIN;
    ps->uniforms[FOGVOL_U_RAMP][3] = run->xsum ? (float)((double)(fd->zfar - fd->znear) / 16777216.0) : 0.0f;
    fogvol__blend_color(run, ps, &spec);
    if (fd->downsample == 2) { /* window space at the viewport's resolution, sums at half */
        spec |= FOGVOL_SPECIALIZE_DOWNSAMPLE | (ctx->gpu.target_filtered ? (unsigned)FOGVOL_SPECIALIZE_FILTERED : 0u);
        ps->uniforms[FOGVOL_U_SCREEN][0] = 1.0f / (float)fd->viewport[2];
        ps->uniforms[FOGVOL_U_SCREEN][1] = 1.0f / (float)fd->viewport[3];
    }
    ps->program = fogvol__program(ctx, FOGVOL_PROGRAM_COMPOSITE, spec);
    if (!ps->program && (spec & FOGVOL_SPECIALIZE_BLEND_COLOR)) { /* it did not build: the colour from the program */
        ps->blend_constant = 0;
        ps->program = fogvol__program(ctx, FOGVOL_PROGRAM_COMPOSITE, spec & ~(unsigned)FOGVOL_SPECIALIZE_BLEND_COLOR);
    }
    if (run->xsum && ps->program == ctx->gpu.prog[FOGVOL_PROGRAM_COMPOSITE]) { /* the general one reads digits */
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: no composite program for integer sums: group not drawn "
                                                 "(FOGVOL_SPEEDUP_EXACT_SUM off from the next frame)");
        ctx->cfg.exact_sum = run->p.exact_sum = 0;
        ps->program = 0;
    }
    if (!ps->program) {
        if (!run->xsum)
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: no %s composite program: group not drawn%s",
                        run->p.engine_test ? "depth-tested (FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST)" : "half-resolution",
                        run->p.engine_test ? "; the faces read the engine's depth from the next frame" : "");
        if (run->p.engine_test) ctx->cfg.engine_test = 0; /* (off from then on, as for its face program) */
        run->r = FOGVOL_ERROR_BACKEND;
        return;
    }
    ctx->be.begin_pass(ctx->be.user_data, ps);
    run->st.passes++;
    ctx->be.draw_fullscreen(ctx->be.user_data);
    fogvol__end_pass(ctx);
}

/* >>overflow ============================================================== */
/* Overflow checks: the check passes, their occlusion queries and what a count changes. */

/* FOGVOL_SPEEDUP_OVERFLOW_BANDS: no band counted (at the start, and when L changes) */
static void fogvol__bands_forget(fogvol_context *ctx)
{
    int i;
    for (i = 0; i < FOGVOL_OVERFLOW_BANDS; ++i) ctx->ovf.band_count[i] = ctx->ovf.band_frame[i] = -1;
}

/* Counting needs the five query entries and one query that can be created. */
static void fogvol__overflow_init(fogvol_context *ctx, fogvol_overflow_policy policy)
{
    const fogvol_backend *b = &ctx->be;
    ctx->cfg.overflow_policy = policy;
    ctx->ovf.overflow_late = -1;
    ctx->ovf.overflow_frame = -1;
    ctx->ovf.qcur = -1;
    fogvol__bands_forget(ctx);
    if (!fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_CHECK) || policy == FOGVOL_OVERFLOW_OFF) return;
    if (!b->create_query || !b->destroy_query || !b->begin_query || !b->end_query || !b->query_result ||
        b->create_query(b->user_data, &ctx->ovf.qf[0].q[0]) != FOGVOL_SUCCESS) {
        ctx->ovf.qf[0].q[0] = 0;
        fogvol__log(&ctx->log, FOGVOL_LOG_INFO,
                    "fogvol: no occlusion queries: overflow is not counted per frame (show_overflow and the "
                    "debug read-back still see it)");
        return;
    }
    ctx->ovf.counting = 1;
}

/* A frame's count arrived (sum: its check passes' samples). Whole-picture checks give the count;
   a band's count replaces that band's older one and the count is the sum over the bands counted.
   A band drawn before the last change of L (an older encoding) is not kept. */
static int fogvol__overflow_arrived(fogvol_context *ctx, const fogvol__qframe *f, uint64_t sum)
{
    int k;
    if (f->samples > 1) sum = (sum + (uint64_t)f->samples - 1u) / (uint64_t)f->samples; /* samples -> pixels */
    if (f->band >= 0) {
        if (f->frame <= ctx->ovf.band_frame[f->band] || f->frame < ctx->ovf.overflow_epoch) return 0;
        ctx->ovf.band_frame[f->band] = f->frame;
        ctx->ovf.band_count[f->band] = (int64_t)(sum > 0x7fffffffu ? 0x7fffffffu : sum);
        for (sum = 0, k = 0; k < FOGVOL_OVERFLOW_BANDS; ++k)
            if (ctx->ovf.band_count[k] > 0) sum += (uint64_t)ctx->ovf.band_count[k];
        ctx->ovf.overflow_late = sum > 0x7fffffffu ? 0x7fffffff : (int)sum; /* even from a late older frame */
        if (f->frame > ctx->ovf.overflow_frame) ctx->ovf.overflow_frame = f->frame;
        return 1;
    }
    if (f->frame <= ctx->ovf.overflow_frame) return 0;
    ctx->ovf.overflow_frame = f->frame;
    ctx->ovf.overflow_late = sum > 0x7fffffffu ? 0x7fffffff : (int)sum;
    for (k = 0; k < FOGVOL_OVERFLOW_BANDS; ++k) { /* the whole picture supersedes every band before it */
        ctx->ovf.band_frame[k] = f->frame;
        ctx->ovf.band_count[k] = -1;
    }
    return 1;
}

/* Reads the queries of earlier frames without waiting, in the order of their frames (the records are
   reused in any order), up to the first frame whose queries are not all done. Returns 1 when a newer
   frame's count arrived. */
static int fogvol__overflow_poll(fogvol_context *ctx)
{
    int i, k, fresh = 0;
    for (;;) {
        fogvol__qframe *f = NULL;
        uint64_t sum = 0, v = 0;
        for (i = 0; i < FOGVOL__QFRAMES; ++i)
            if (ctx->ovf.qf[i].pending && (!f || ctx->ovf.qf[i].frame < f->frame)) f = &ctx->ovf.qf[i];
        if (!f) break;
        for (k = 0; k < f->used; ++k) {
            if (!ctx->be.query_result(ctx->be.user_data, f->q[k], &v)) break;
            sum += v;
        }
        if (k < f->used) break;
        f->pending = 0;
        if (!f->discard) fresh |= fogvol__overflow_arrived(ctx, f, sum);
    }
    return fresh;
}

/* Picks a free record for this frame's queries; 0 when every record still waits for the GPU
   (the frame is then not counted: nothing ever waits). Checks one band of the picture with
   FOGVOL_SPEEDUP_OVERFLOW_BANDS, unless show_overflow wants the whole mask. */
static int fogvol__overflow_open(fogvol_context *ctx)
{
    int i;
    ctx->ovf.qcur = -1;
    if (!ctx->ovf.counting) return 0;
    for (i = 0; i < FOGVOL__QFRAMES; ++i)
        if (!ctx->ovf.qf[i].pending) {
            ctx->ovf.qcur = i;
            ctx->ovf.qf[i].used = 0;
            ctx->ovf.qf[i].ok = 1;
            ctx->ovf.qf[i].frame = ctx->ovf.frame_no;
            ctx->ovf.qf[i].samples = ctx->cur.samples;
            ctx->ovf.qf[i].band = (ctx->cfg.speedups_off & FOGVOL_SPEEDUP_OVERFLOW_BANDS) || ctx->cur.frame.show_overflow
                                  ? -1
                                  : (int)(ctx->ovf.frame_no % FOGVOL_OVERFLOW_BANDS);
            return 1;
        }
    return 0;
}

static fogvol_handle fogvol__query_begin(fogvol_context *ctx)
{
    fogvol__qframe *f;
    fogvol_handle *q;
    if (ctx->ovf.qcur < 0) return 0;
    f = &ctx->ovf.qf[ctx->ovf.qcur];
    q = &f->q[f->used < FOGVOL__QPER ? f->used : 0];
    if (!f->ok || f->used >= FOGVOL__QPER) {
        f->ok = 0; /* more check passes than queries: the frame is not counted */
        return 0;
    }
    if (!*q && ctx->be.create_query(ctx->be.user_data, q) != FOGVOL_SUCCESS) *q = 0;
    if (!*q || !ctx->be.begin_query(ctx->be.user_data, *q)) {
        f->ok = 0;
        return 0;
    }
    f->used++;
    return *q;
}

/* After the frame's passes: its queries wait for the GPU; a frame without check passes drew no
   volume (or its band holds no pixel) and counts 0 now. */
static void fogvol__overflow_close(fogvol_context *ctx)
{
    fogvol__qframe *f;
    if (ctx->ovf.qcur < 0) return;
    f = &ctx->ovf.qf[ctx->ovf.qcur];
    ctx->ovf.qcur = -1;
    f->discard = !f->ok;
    if (f->used > 0) f->pending = 1; /* (a backend may reset a query only once the GPU is done with it) */
    else if (f->ok) fogvol__overflow_arrived(ctx, f, 0);
}

/* The program and the mask target of the check passes, made on first use. */
static fogvol_result fogvol__ensure_checks(fogvol_context *ctx)
{
    fogvol_target_desc td;
    fogvol_result r = FOGVOL_SUCCESS;
    if (!ctx->gpu.prog[FOGVOL_PROGRAM_CHECK]) r = fogvol__make_program(ctx, FOGVOL_PROGRAM_CHECK, 0, &ctx->gpu.prog[FOGVOL_PROGRAM_CHECK]);
    if (r == FOGVOL_SUCCESS && !ctx->gpu.tgt_v) {
        memset(&td, 0, sizeof td);
        td.width = ctx->gpu.target_w;
        td.height = ctx->gpu.target_h;
        td.depth = fogvol__has(ctx, FOGVOL_VARIANT_SINGLE_TARGET);
        td.samples = ctx->cur.samples; /* (the per-sample composite reads V per sample) */
        td.label = "fogvol V (overflow mask)";
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_v);
        if (r != FOGVOL_SUCCESS) ctx->gpu.tgt_v = 0;
    }
    if (r != FOGVOL_SUCCESS)
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot create the overflow check pass: %s",
                    fogvol_result_string(r));
    return r;
}

/* FOGVOL_SPEEDUP_OVERFLOW_BANDS: scissor (target space, w = 0: the whole w x h target) narrowed
   to rows [h b / B, h (b + 1) / B) of its rectangle, B = FOGVOL_OVERFLOW_BANDS; band -1: unchanged.
   Returns 0 when the band holds no row. */
static int fogvol__band_scissor(const fogvol__run *run, int band, int scissor[4])
{
    int y0, y1;
    if (band < 0) return 1;
    if (scissor[2] <= 0 || scissor[3] <= 0) {
        scissor[0] = scissor[1] = 0;
        scissor[2] = run->w;
        scissor[3] = run->h;
    }
    y0 = (int)((int64_t)scissor[3] * band / FOGVOL_OVERFLOW_BANDS);
    y1 = (int)((int64_t)scissor[3] * (band + 1) / FOGVOL_OVERFLOW_BANDS);
    scissor[1] += y0;
    scissor[3] = y1 - y0;
    return y1 > y0 && scissor[2] > 0;
}

/* One check pass into the mask V: pixels with a saturated sum are written (and counted by a query),
   the rest discarded. base: the pass state of the composite (target space). SINGLE runs it after the
   additions (first: clears V and its depth) and after the subtractions, whose depth test skips the
   pixels already marked, so each pixel counts once. */
static void fogvol__check_pass(fogvol_context *ctx, const fogvol__run *run, const fogvol_pass *base, int first,
                               fogvol_frame_stats *st)
{
    fogvol_pass cp = *base;
    fogvol_handle q;
    int single = run->p.single;
    if (ctx->ovf.qcur >= 0 && !fogvol__band_scissor(run, ctx->ovf.qf[ctx->ovf.qcur].band, cp.scissor)) return;
    cp.target = ctx->gpu.tgt_v;
    cp.read_target = 0; /* (SINGLE_TARGET: the state of the sum passes) */
    cp.clear = first;
    memset(cp.clear_color, 0, sizeof cp.clear_color);
    cp.blend = FOGVOL_PASS_BLEND_NONE;
    cp.cull = FOGVOL_CULL_NONE;
    cp.depth_test = cp.depth_write = single;
    cp.program = fogvol__program(ctx, FOGVOL_PROGRAM_CHECK, run->p.origin_bit);
    memset(cp.native_textures, 0, sizeof cp.native_textures);
    if (single) { /* the one sum target; V is the target here, not a texture */
        memset(cp.textures, 0, sizeof cp.textures);
        cp.textures[FOGVOL__UNIT_BACK] = ctx->gpu.tgt_b;
    }
    ctx->be.begin_pass(ctx->be.user_data, &cp);
    q = fogvol__query_begin(ctx);
    ctx->be.draw_fullscreen(ctx->be.user_data);
    if (q) ctx->be.end_query(ctx->be.user_data, q);
    fogvol__end_pass(ctx);
    st->overflow_passes++;
}

/* FOGVOL_OVERFLOW_LOWER_BITS: L - 1 and the lookup textures that depend on it (programs and
   targets do not). Outside a frame; on failure the old encoding stays. */
static fogvol_result fogvol__lower_bits(fogvol_context *ctx)
{
    fogvol_encoding old = ctx->cfg.enc;
    fogvol_handle t[3] = {0, 0, 0}, *cur[3];
    fogvol_result r = FOGVOL_SUCCESS;
    int i;
    cur[0] = &ctx->gpu.tex_rg;
    cur[1] = &ctx->gpu.tex_blue;
    cur[2] = &ctx->gpu.tex_dither;
    fogvol_encoding_init(old.bits - 1, &ctx->cfg.enc);
    for (i = 0; i < 3 && r == FOGVOL_SUCCESS; ++i)
        if (*cur[i]) r = fogvol__make_texture(ctx, i, &t[i]);
    if (r != FOGVOL_SUCCESS) {
        for (i = 0; i < 3; ++i)
            if (t[i]) ctx->be.destroy_texture(ctx->be.user_data, t[i]);
        ctx->cfg.enc = old;
        return r;
    }
    for (i = 0; i < 3; ++i)
        if (*cur[i]) {
            ctx->be.destroy_texture(ctx->be.user_data, *cur[i]);
            *cur[i] = t[i];
        }
    return FOGVOL_SUCCESS;
}

/* After a frame: the overflow policy, for a count that arrived in it (frames drawn before the last
   change of L are not acted upon). */
static void fogvol__overflow_react(fogvol_context *ctx, int fresh)
{
    int single = fogvol__has(ctx, FOGVOL_VARIANT_SINGLE_TARGET), from = ctx->cfg.enc.bits;
    int faces = single ? ctx->cfg.enc.max_faces_single : ctx->cfg.enc.max_faces;
    if (!fresh || ctx->ovf.overflow_late <= 0 || ctx->ovf.overflow_frame < ctx->ovf.overflow_epoch) return;
    if (ctx->cfg.overflow_policy == FOGVOL_OVERFLOW_COUNT_ONLY) return;
    if (ctx->cfg.overflow_policy == FOGVOL_OVERFLOW_LOWER_BITS && from > 1) {
        fogvol_result r = fogvol__lower_bits(ctx);
        if (r == FOGVOL_SUCCESS) {
            fogvol__bands_forget(ctx);
            fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                        "fogvol: %d pixels of frame %lld have more than %d faces along the ray: encoding_bits "
                        "lowered from %d to %d (%d faces) from frame %lld on",
                        ctx->ovf.overflow_late, (long long)ctx->ovf.overflow_frame, faces, from, ctx->cfg.enc.bits,
                        single ? ctx->cfg.enc.max_faces_single : ctx->cfg.enc.max_faces, (long long)ctx->ovf.frame_no + 1);
            ctx->ovf.overflow_epoch = ctx->ovf.frame_no + 1;
            return;
        }
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot lower encoding_bits: %s", fogvol_result_string(r));
    }
    if (ctx->ovf.overflow_warned) return;
    ctx->ovf.overflow_warned = 1;
    fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                "fogvol: %d pixels of frame %lld have more than %d faces along the ray (%d-bit encoding): their "
                "thickness is wrong (show_overflow marks them; logged once)",
                ctx->ovf.overflow_late, (long long)ctx->ovf.overflow_frame, faces, ctx->cfg.enc.precision_bits);
}

/* FOGVOL_SPEEDUP_SKIP_CHECK: no pixel of the group's sums can saturate, so its check pass would find
   nothing: every volume of the group is convex (at most one front and one back face on a ray; half
   of what a target sums leaves a margin for a mesh convex only within fogvol__convexity's tolerance,
   which a grazing ray could cross again), the faces are not folded onto the near plane
   (NEAR_CLAMP), and SINGLE_TARGET keeps its peak check. */
static int fogvol__unsaturable(const fogvol_context *ctx, const fogvol__run *run, int volumes, int all_convex)
{
    return all_convex && 2 * volumes <= ctx->cfg.enc.max_faces && run->p.skip_check;
}

/* The group's overflow check pass, its program and mask target made on first use (none while every
   group skips it); when they cannot be made the frame is not counted. */
static void fogvol__group_check(fogvol_context *ctx, fogvol__run *run, const fogvol_pass *ps)
{
    fogvol_result r = fogvol__ensure_checks(ctx);
    if (r == FOGVOL_SUCCESS) {
        fogvol__check_pass(ctx, run, ps, 1, &run->st);
        return;
    }
    run->counted = 0; /* (no query begun this frame: any earlier check would have made them) */
    ctx->ovf.qcur = -1;
    run->r = r;
}

/* After the groups: close this frame's overflow queries; the debug read-back's overflow count. */
static fogvol_result fogvol__frame_overflow(fogvol_context *ctx, fogvol__run *run)
{
    fogvol_result r = run->r;
    if (run->counted) fogvol__overflow_close(ctx);
    if (run->p.float_sums) { /* float sums cannot saturate */
        ctx->ovf.overflow_late = 0;
        ctx->ovf.overflow_frame = ctx->ovf.frame_no;
    }
    run->st.overflow_pixels = run->overflow;
    if (run->overflow > 0 && r == FOGVOL_SUCCESS) {
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: %d pixels have more faces along the ray than the %d-bit encoding sums (%d)",
                    run->overflow, ctx->cfg.enc.precision_bits,
                    run->p.single ? ctx->cfg.enc.max_faces_single : ctx->cfg.enc.max_faces);
        r = FOGVOL_ERROR_DEPTH_OVERFLOW;
    }
    return r;
}

/* >>lights ================================================================ */
/* Volume lights by compare (fogvol_add_light). */

FOGVOL_API fogvol_result fogvol_add_light(fogvol_context *ctx, const fogvol_light_desc *desc)
{
    const char *why;
    fogvol__light *l;
    void *arr;
    fogvol_result r;
    float k;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc || !desc->mesh) return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_ARGUMENT, "add_light: desc or its mesh is NULL");
    if (!ctx->cur.in_frame)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE, "add_light outside a frame (after begin_frame only)");
    if (!fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_LIGHT)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: volume lights need tier FLOAT, PS20 or MRT without WIDE "
                    "(tier %s, variants 0x%x)", fogvol_tier_name(ctx->cfg.tier), ctx->cfg.variants);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (desc->mesh->convex != 1) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: a light volume must be a convex closed hull: %s",
                    !desc->mesh->volume        ? "the mesh is not a valid closed hull"
                    : desc->mesh->convex == 0 ? "the mesh is concave (a vertex lies outside a face plane)"
                                              : "the mesh is too large for the convexity check");
        return FOGVOL_ERROR_INVALID_MESH;
    }
    if (!fogvol__finite_n(desc->color, 3) || !fogvol__finite_n(&desc->intensity, 1) ||
        !fogvol__finite_n(desc->position, 3) || !fogvol__finite(desc->falloff_radius) ||
        desc->falloff_radius < 0.0f || !fogvol__finite(desc->edge_softness) || desc->edge_softness < 0.0f) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: non-finite light colour, intensity or position, "
                    "or a negative falloff_radius or edge_softness");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if ((why = fogvol__model_problem(desc->model, 1)) != NULL) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: the light's model matrix %s", why);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    arr = ctx->cur.lights;
    r = fogvol__grow(ctx, &arr, &ctx->cur.caplight, ctx->cur.nlight + 1, sizeof *l);
    ctx->cur.lights = (fogvol__light *)arr;
    if (r != FOGVOL_SUCCESS) return r;
    l = &ctx->cur.lights[ctx->cur.nlight++];
    l->mesh = desc->mesh;
    memcpy(l->model, desc->model, sizeof l->model);
    k = desc->intensity != 0.0f ? desc->intensity : 1.0f;
    l->rgb[0] = desc->color[0] * k;
    l->rgb[1] = desc->color[1] * k;
    l->rgb[2] = desc->color[2] * k;
    memcpy(l->position, desc->position, sizeof l->position);
    l->radius = desc->falloff_radius;
    l->edge = desc->edge_softness;
    return FOGVOL_SUCCESS;
}

/* The program and the front-depth target L, made on first use. */
static fogvol_result fogvol__light_setup(fogvol_context *ctx, const fogvol__run *run)
{
    fogvol_target_desc td;
    fogvol_result r = FOGVOL_SUCCESS;
    if (!ctx->gpu.prog[FOGVOL_PROGRAM_LIGHT])
        r = fogvol__make_program(ctx, FOGVOL_PROGRAM_LIGHT, 0, &ctx->gpu.prog[FOGVOL_PROGRAM_LIGHT]);
    if (r == FOGVOL_SUCCESS && !ctx->gpu.tgt_l) {
        memset(&td, 0, sizeof td);
        td.width = ctx->gpu.target_w;
        td.height = ctx->gpu.target_h;
        td.samples = ctx->cur.samples;
        td.format = run->p.float_sums ? FOGVOL_FORMAT_R32F : FOGVOL_FORMAT_RGBA8;
        td.label = "fogvol L (light front depth)";
        r = ctx->be.create_target(ctx->be.user_data, &td, &ctx->gpu.tgt_l);
        if (r != FOGVOL_SUCCESS) ctx->gpu.tgt_l = 0;
    }
    if (r != FOGVOL_SUCCESS)
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot set up the light passes: %s",
                    fogvol_result_string(r));
    return r;
}

/* The world point on the ray of viewport position (s, t) in [0,1]^2 at view depth e: clip x = (2s - 1) w,
   clip y = sy (2t - 1) w and eyerow . (P, 1) = e, three linear equations in P (Cramer's rule).
   0 where they are singular. */
static int fogvol__ray_point(const fogvol_context *ctx, double s, double t, double sy, double e, double out[3])
{
    const double *m = ctx->cur.viewproj;
    double x = 2.0 * s - 1.0, y = sy * (2.0 * t - 1.0), a[3][3], b[3], det;
    int j, k;
    for (j = 0; j < 3; ++j) {
        a[0][j] = m[j * 4] - x * m[j * 4 + 3];
        a[1][j] = m[j * 4 + 1] - y * m[j * 4 + 3];
        a[2][j] = ctx->cur.eyerow[j];
    }
    b[0] = x * m[15] - m[12];
    b[1] = y * m[15] - m[13];
    b[2] = e - ctx->cur.eyerow[3];
    det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
          a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(det != 0.0) || det - det != 0.0) return 0;
    for (k = 0; k < 3; ++k) { /* column k replaced by b */
        double c[3][3];
        memcpy(c, a, sizeof c);
        for (j = 0; j < 3; ++j) c[j][k] = b[j];
        out[k] = (c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
                  c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0])) / det;
    }
    return 1;
}

/* fv_lq0..5 of a light's compare pass: the scene point P(s, t, o) = A + B s + C t + o (D + E s + F t)
   (P is affine in the screen position at a given view depth and affine in the depth along a ray, for
   perspective and orthographic cameras alike), taken from the ray points at the near and far planes
   of three screen corners, as (P - position) / falloff_radius; the soft edge's scale in lq1.w. */
static void fogvol__light_uniforms(const fogvol_context *ctx, const fogvol__run *run, const fogvol__light *l,
                                   fogvol_pass *ps)
{
    static const double corner[3][2] = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    double p[3][2][3], sy = run->info.clip_upper_left ? -1.0 : 1.0, q[6][3];
    int c, k, j, ok = 1;
    for (k = FOGVOL_U_LIGHT_Q0; k <= FOGVOL_U_LIGHT_Q5; ++k) memset(ps->uniforms[k], 0, sizeof ps->uniforms[k]);
    if (l->edge > 0.0f) ps->uniforms[FOGVOL_U_LIGHT_Q1][3] = (fd->zfar - fd->znear) / l->edge;
    if (!(l->radius > 0.0f)) return;
    for (c = 0; c < 3; ++c)
        for (k = 0; k < 2; ++k)
            ok &= fogvol__ray_point(ctx, corner[c][0], corner[c][1], sy, k ? fd->zfar : fd->znear, p[c][k]);
    if (!ok) return; /* (the camera was validated: not reached) */
    for (j = 0; j < 3; ++j) {
        q[0][j] = p[0][0][j] - l->position[j];
        q[1][j] = p[1][0][j] - p[0][0][j];
        q[2][j] = p[2][0][j] - p[0][0][j];
        q[3][j] = p[0][1][j] - p[0][0][j];
        q[4][j] = p[1][1][j] - p[1][0][j] - q[3][j];
        q[5][j] = p[2][1][j] - p[2][0][j] - q[3][j];
    }
    for (k = 0; k < 6; ++k)
        for (j = 0; j < 3; ++j) ps->uniforms[FOGVOL_U_LIGHT_Q0 + k][j] = (float)(q[k][j] / l->radius);
    ps->uniforms[FOGVOL_U_LIGHT_Q0][3] = 1.0f;
}

/* Per light: its front faces' depth into L (cleared to 0: the near plane, for a camera inside),
   then its back faces over the engine framebuffer, lighting the pixels whose opaque depth lies
   between L and the back face (convex: one front and one back face per pixel). */
static void fogvol__light_passes(fogvol_context *ctx, fogvol__run *run)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    fogvol_pass fp = run->base, bp;
    fogvol_draw dr;
    fogvol_result r;
    int i;
    if (!ctx->cur.nlight) return;
    if ((r = fogvol__light_setup(ctx, run)) != FOGVOL_SUCCESS) {
        run->r = r;
        return;
    }
    fp.program = ctx->gpu.prog[FOGVOL_PROGRAM_LIGHT];
    fp.target = ctx->gpu.tgt_l;
    fp.clear = 1;
    fp.cull = FOGVOL_CULL_BACK;
    bp = fp;
    bp.target = 0;
    bp.clear = 0;
    bp.cull = FOGVOL_CULL_FRONT;
    bp.blend = FOGVOL_PASS_BLEND_LIGHT;
    memcpy(bp.viewport, fd->viewport, sizeof bp.viewport);
    bp.uniforms[FOGVOL_U_SCREEN][2] = -(float)fd->viewport[0]; /* window pixel -> target pixel */
    bp.uniforms[FOGVOL_U_SCREEN][3] = -(float)fd->viewport[1];
    bp.uniforms[FOGVOL_U_NEARFAR][2] = bp.uniforms[FOGVOL_U_NEARFAR][3] = 0.0f; /* gl_FragCoord is the engine's */
    bp.draw_buffer = fd->draw_buffer;
    if (run->p.engine_read) bp.native_textures[FOGVOL__UNIT_OPAQUE] = run->engine_depth;
    else bp.textures[FOGVOL__UNIT_OPAQUE] = ctx->gpu.tgt_o;
    bp.textures[FOGVOL__UNIT_LFRONT] = ctx->gpu.tgt_l;
    bp.uniforms[FOGVOL_U_LIGHT][3] = 1.0f;
    for (i = 0; i < ctx->cur.nlight; ++i) {
        const fogvol__light *l = &ctx->cur.lights[i];
        fogvol__draw_for(ctx, l->model, &dr);
        ctx->be.begin_pass(ctx->be.user_data, &fp);
        ctx->be.draw_mesh(ctx->be.user_data, l->mesh->handle, &dr);
        fogvol__end_pass(ctx);
        memcpy(bp.uniforms[FOGVOL_U_LIGHT], l->rgb, sizeof l->rgb);
        fogvol__light_uniforms(ctx, run, l, &bp);
        ctx->be.begin_pass(ctx->be.user_data, &bp);
        ctx->be.draw_mesh(ctx->be.user_data, l->mesh->handle, &dr);
        fogvol__end_pass(ctx);
        run->st.passes += 2;
        run->st.lights++;
    }
}

/* >>colour groups ========================================================= */
/* One-pass colours (FOGVOL_VARIANT_COLORS): the group's optical depth and emission sums. */

/* The sum pass of the colour group: every member's faces, signed, into the two RGBA32F sums
   (optical depth per channel, emission per channel). Returns 1 if every member is grey. */
static int fogvol__color_sums(fogvol_context *ctx, fogvol__run *run)
{
    fogvol_pass ps = run->base;
    double range = (double)ctx->cur.frame.zfar - ctx->cur.frame.znear, top, scale;
    int i, c, grey = 1;
    ps.program = ctx->gpu.prog[FOGVOL_PROGRAM_COLOR_FACE];
    ps.uniforms[FOGVOL_U_MISC][3] = run->p.near_clamp;
    if (run->p.engine_read) ps.native_textures[FOGVOL__UNIT_OPAQUE] = run->engine_depth;
    else ps.textures[FOGVOL__UNIT_OPAQUE] = ctx->gpu.tgt_o;
    ps.target = ctx->gpu.tgt_c;
    ps.clear = 1;
    ps.blend = FOGVOL_PASS_BLEND_ADD;
    ctx->be.begin_pass(ctx->be.user_data, &ps);
    run->st.passes++;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        const fogvol__volume *v = &ctx->cur.vols[i];
        fogvol_draw dr;
        if (!fogvol__color_member(ctx, v->ramp)) continue;
        fogvol__draw_for(ctx, v->model, &dr);
        if (v->negative) dr.sign = -1.0f;
        for (top = 0.0, c = 0; c < 3; ++c)
            if ((double)v->ramp->sigma[c] * range > top) top = (double)v->ramp->sigma[c] * range;
        /* optical depths past 2^64 per depth range are opaque at any thickness a depth can hold: the channels
           scaled alike to it, so that the signed sums stay finite (emission / extinction, the hue, kept) */
        scale = top > 18446744073709551616.0 ? 18446744073709551616.0 / top : 1.0;
        for (c = 0; c < 3; ++c) {
            dr.extinction[c] = (float)(v->ramp->sigma[c] * range * scale);
            dr.emission[c] = (float)(v->ramp->sigma[c] * range * scale * v->ramp->emit[c]);
        }
        grey &= v->ramp->grey;
        ctx->be.draw_mesh(ctx->be.user_data, v->mesh->handle, &dr);
        run->st.volumes++;
    }
    fogvol__end_pass(ctx);
    return grey;
}

/* The window rectangle of every member's volumes, each projected once. */
static void fogvol__color_rect(const fogvol_context *ctx, int rect[4])
{
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    int i;
    memcpy(rect, ctx->cur.frame.viewport, 4 * sizeof(int));
    for (i = ctx->cur.color_first; i >= 0 && i < ctx->cur.nvol; ++i)
        if (fogvol__color_member(ctx, ctx->cur.vols[i].ramp) && !fogvol__rect_add(ctx, &ctx->cur.vols[i], lo, hi))
            return;
    fogvol__rect_finish(ctx, lo, hi, rect);
}

/* The composite of the colour group into the engine framebuffer: one FOG-blended draw when every
   member is grey, else a multiply draw (scene * T) and an emission draw. */
static void fogvol__color_composite(fogvol_context *ctx, fogvol__run *run, int grey)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    fogvol_pass ps = run->base;
    int step;
    memset(ps.textures, 0, sizeof ps.textures);
    ps.textures[FOGVOL__UNIT_BACK] = ctx->gpu.tgt_c;
    ps.textures[FOGVOL__UNIT_FRONT] = ctx->gpu.tgt_c2;
    memcpy(ps.viewport, fd->viewport, sizeof ps.viewport);
    ps.uniforms[FOGVOL_U_SCREEN][2] = -(float)fd->viewport[0]; /* window pixel -> target pixel */
    ps.uniforms[FOGVOL_U_SCREEN][3] = -(float)fd->viewport[1];
    ps.draw_buffer = fd->draw_buffer;
    ps.alpha_coverage = fd->alpha == FOGVOL_ALPHA_COVERAGE;
    fogvol__color_rect(ctx, ps.scissor);
    if (run->info.clip_upper_left) /* NDC y points down the window: mirror the rectangle */
        ps.scissor[1] = 2 * fd->viewport[1] + fd->viewport[3] - ps.scissor[1] - ps.scissor[3];
    ps.program = ctx->gpu.prog[FOGVOL_PROGRAM_COLOR_COMPOSITE];
    for (step = grey ? 0 : 1; step <= (grey ? 0 : 2); ++step) {
        ps.uniforms[FOGVOL_U_RAMP][2] = (float)step;
        ps.blend = step == 0 ? FOGVOL_PASS_BLEND_FOG : step == 1 ? FOGVOL_PASS_BLEND_MULTIPLY : FOGVOL_PASS_BLEND_EMIT;
        ctx->be.begin_pass(ctx->be.user_data, &ps);
        run->st.passes++;
        ctx->be.draw_fullscreen(ctx->be.user_data);
        fogvol__end_pass(ctx);
    }
}

/* The debug read-back of a colour group (its sums are optical depths of all its ramps): one more
   pass sums the faces of the debug ramp's volumes (debug_ramp NULL: the ramp of the group's first
   volume, g) into B as the FLOAT tier's groups do, and reads that back. */
static void fogvol__color_debug(fogvol_context *ctx, fogvol__run *run, int g)
{
    const fogvol_ramp *ramp = ctx->cur.frame.debug_ramp ? ctx->cur.frame.debug_ramp : ctx->cur.vols[g].ramp;
    int i, has_pos = 0, has_neg = 0;
    if (!fogvol__want_debug(ctx, ramp, run->captured) || !fogvol__color_member(ctx, ramp)) return;
    for (i = g; i < ctx->cur.nvol; ++i)
        if (ctx->cur.vols[i].ramp == ramp) {
            has_neg |= ctx->cur.vols[i].negative;
            has_pos |= !ctx->cur.vols[i].negative;
        }
    if (!has_pos) return; /* (no thickness: the frame's end writes 0) */
    run->xsum = 0;
    fogvol__sum_passes(ctx, run, ramp, has_neg);
}

/* The colour group, drawn where its first member volume g comes in the frame's order (once), if it
   holds a positive volume. */
static void fogvol__color_group(fogvol_context *ctx, fogvol__run *run, int g)
{
    if (g != ctx->cur.color_first || !ctx->cur.color_pos) return;
    run->st.groups++;
    fogvol__color_composite(ctx, run, fogvol__color_sums(ctx, run));
    fogvol__color_debug(ctx, run, g);
}

/* >>end frame ============================================================= */
/* fogvol_end_frame: the frame checked, planned and set up, each group summed and composited in turn
   (or checked for overflow, or drawn as a colour group), the lights, the stats. */

/* FOGVOL_SPEEDUP_DEPTH_TEST: this frame drawn as COUNT (see the speed-up). Beyond the near-plane
   condition of COUNT, no volume crosses the far plane either: there the min compare drops the
   clipped faces while the count would add the far plane for them. */
static int fogvol__depth_test_frame(const fogvol_context *ctx)
{
    int i;
    if ((ctx->cfg.speedups_off & FOGVOL_SPEEDUP_DEPTH_TEST) || ctx->cfg.count_broken || ctx->cfg.float_o || ctx->cur.nocc == 0 ||
        ctx->cur.engine_occluders || ctx->cur.nlight > 0 || !fogvol__tier_has(ctx->cfg.tier, ctx->cfg.variants, FOGVOL__F_DEPTH_TEST))
        return 0;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        double emin = 0.0, emax = 0.0;
        if (ctx->cur.vols[i].density) return 0;
        fogvol__volume_depths(ctx, &ctx->cur.vols[i], &emin, &emax);
        if ((emin < ctx->cur.frame.znear && emax > 0.0) || (emin < ctx->cur.frame.zfar && emax > ctx->cur.frame.zfar)) return 0;
    }
    return 1;
}

/* View depth at the engine's window depth z through fv_lin, fv_lin2 without x and y terms (DEPTH_FROM_Z);
   a denominator of 0 (an infinite far plane) gives 1e300. */
static double fogvol__engine_view_depth(const fogvol_pass *ps, double z)
{
    const float *a = ps->uniforms[FOGVOL_U_LINEAR], *b = ps->uniforms[FOGVOL_U_LINEAR_W];
    double num = a[2] * z + a[3], den = b[2] * z + b[3];
    return fabs(den) <= 1e-12 * fabs(num) ? 1e300 : num / den;
}

/* The engine's window depth at view depth e (the inverse of fogvol__engine_view_depth); 0: none. */
static int fogvol__engine_window_z(const fogvol_pass *ps, double e, double *z)
{
    const float *a = ps->uniforms[FOGVOL_U_LINEAR], *b = ps->uniforms[FOGVOL_U_LINEAR_W];
    double den = e * b[2] - a[2];
    if (!(fabs(den) > 0.0)) return 0;
    *z = (a[3] - e * b[3]) / den;
    return 1;
}

/* The world corners of the frustum's cross-section at the engine's window depth zw: NDC (+-1, +-1) at
   zw through the inverse view-projection (z01: the engine's NDC depth runs 0..1; r: window depths of
   NDC depth -1 or 0 and 1). 0: a corner at infinity. */
static int fogvol__window_rect(const fogvol_context *ctx, int z01, const double r[2], double zw, double c[4][3])
{
    double a = (z01 ? 1.0 : 2.0) / (r[1] - r[0]), zn = a * (zw - r[0]) - (z01 ? 0.0 : 1.0);
    int k, j;
    for (k = 0; k < 4; ++k) {
        double q[4] = {(k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, zn, 1.0}, w[4];
        for (j = 0; j < 4; ++j)
            w[j] = ctx->cur.invvp[j] * q[0] + ctx->cur.invvp[4 + j] * q[1] + ctx->cur.invvp[8 + j] * q[2] +
                   ctx->cur.invvp[12 + j] * q[3];
        if (!(FOGVOL_FABS(w[3]) > 0.0)) return 0;
        for (j = 0; j < 3; ++j) c[k][j] = w[j] / w[3];
    }
    return 1;
}

/* Whether volume v holds the whole rectangle where the projection's near plane cuts the frustum (world
   corners c, at view depth pn): every corner inside every face plane of its convex mesh, by twice the
   convexity test's tolerance and 1/1000 of pn (in view depth: the clipper's rounding), so that on every
   pixel's ray the near plane clips v's one front face and leaves its one back face. The rectangle is
   convex, so its corners decide. */
static int fogvol__near_inside(const fogvol_context *ctx, const fogvol__volume *v, const double c[4][3], double pn)
{
    const fogvol_mesh *m = v->mesh;
    double mm[16], im[16], fro = 0.0, eye, margin;
    int i, j, k;
    if (m->convex != 1 || !m->planes) return 0;
    for (i = 0; i < 16; ++i) mm[i] = v->model[i];
    if (!fogvol__inv4(mm, im)) return 0;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) fro += im[j * 4 + i] * im[j * 4 + i];
    eye = FOGVOL_SQRT(ctx->cur.eyerow[0] * ctx->cur.eyerow[0] + ctx->cur.eyerow[1] * ctx->cur.eyerow[1] +
                      ctx->cur.eyerow[2] * ctx->cur.eyerow[2]);
    if (!(eye > 0.0)) return 0;
    /* a view-depth length L is at most L / eye world units, at most |im| L / eye model units */
    margin = 2.0 * m->plane_tol + 1e-3 * FOGVOL_FABS(pn) * FOGVOL_SQRT(fro) / eye;
    for (k = 0; k < 4; ++k) {
        double q[3];
        for (i = 0; i < 3; ++i) q[i] = im[i] * c[k][0] + im[4 + i] * c[k][1] + im[8 + i] * c[k][2] + im[12 + i];
        for (j = 0; j < m->nplanes; ++j) {
            const float *pl = m->planes + 4 * j;
            if (!(pl[0] * q[0] + pl[1] * q[1] + pl[2] * q[2] - pl[3] < -margin)) return 0;
        }
    }
    return 1;
}

/* FOGVOL_SPEEDUP_ENGINE_DEPTH_TEST: whether this frame (FLOAT + ENGINE_DEPTH, single-sample or, with
   FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE and no debug read-back, multisampled; away from the window origin
   no colour-textured volume) fits the depth-tested faces, and p's depth test and clip z if so.
   r - o (g - c) equals the min compare's sum where the faces on every pixel's ray close but for c
   volumes the near plane opens (each volume unclipped: between both pairs of planes, fogvol's
   znear..zfar and the projection's, which now clips the faces, or wholly outside both; or, the camera
   inside it, convex and holding the projection's whole near plane rectangle at or beyond znear and,
   where that plane lies beyond znear, the rectangle at znear too: by convexity it then holds the
   frustum between the two, so no face lies between znear and the plane that clips it, which the
   count c would otherwise place at znear; fogvol__volume.near_inside, c their signs' sum in a group)
   and the engine's depth is linearised without the pixel (no oblique near plane). */
static int fogvol__engine_test_frame(fogvol_context *ctx, const fogvol__run *run, fogvol__plan *p)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    fogvol_pass lin;
    double r[2], e0, e1, pn, pf, lo, hi, zw, corner[2][4][3];
    int i, z01, corners = 0, gap = 0;
    if (!ctx->cfg.engine_test || !p->engine_read || fd->downsample == 2 || ctx->cur.nlight > 0 || p->colors ||
        p->near_clamp > 0.0f)
        return 0;
    if (ctx->cur.samples > 1 && (!(ctx->be.caps & FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE) || fd->debug_thickness))
        return 0; /* (multisampled: the debug read-back keeps the per-sample read) */
    memset(&lin, 0, sizeof lin);
    fogvol__lin_uniforms(ctx, fd, &run->info, &lin);
    z01 = fogvol__engine_convention(fd, &run->info, r);
    if (!fogvol__depth_from_z_bit(&lin) || r[0] == r[1]) return 0;
    e0 = fogvol__engine_view_depth(&lin, r[0]); /* the projection's planes, in view depth */
    e1 = fogvol__engine_view_depth(&lin, r[1]);
    pn = e0 < e1 ? e0 : e1;
    pf = e0 < e1 ? e1 : e0;
    lo = pn > fd->znear ? pn : fd->znear;
    hi = pf < fd->zfar ? pf : fd->zfar;
    for (i = 0; i < ctx->cur.nvol; ++i) ctx->cur.vols[i].near_inside = 0;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        double emin = 0.0, emax = 0.0;
        if (ctx->cur.vols[i].density) return 0;
        if (ctx->cur.vols[i].color && !p->origin_bit) return 0; /* (its coordinates: across the viewport) */
        fogvol__volume_depths(ctx, &ctx->cur.vols[i], &emin, &emax);
        if ((emin >= lo && emax <= hi) || emax <= (pn < fd->znear ? pn : fd->znear) ||
            emin >= (pf > fd->zfar ? pf : fd->zfar))
            continue;
        /* the camera inside: the near plane at or beyond znear (no face nearer than znear), within hi */
        if (emax > hi || pn < fd->znear - 1e-6 * ((double)fd->zfar - fd->znear)) return 0;
        if (!corners) { /* the near plane's rectangle, and znear's where the near plane lies beyond it */
            if (!fogvol__window_rect(ctx, z01, r, e0 < e1 ? r[0] : r[1], corner[0])) return 0;
            gap = pn > fd->znear + 1e-6 * ((double)fd->zfar - fd->znear);
            if (gap && (!fogvol__engine_window_z(&lin, fd->znear, &zw) || !fogvol__window_rect(ctx, z01, r, zw, corner[1])))
                return 0;
            corners = 1;
        }
        if (!fogvol__near_inside(ctx, &ctx->cur.vols[i], (const double(*)[3])corner[0], pn) ||
            (gap && !fogvol__near_inside(ctx, &ctx->cur.vols[i], (const double(*)[3])corner[1], fd->znear)))
            return 0;
        ctx->cur.vols[i].near_inside = 1;
    }
    /* window depth = a + b z_ndc; fogvol's passes map clip z' to (z' / w + 1) / 2: z' = 2 b z + (2 a - 1) w */
    p->zmap[0] = z01 ? 2.0 * (r[1] - r[0]) : r[1] - r[0];
    p->zmap[1] = (z01 ? 2.0 * r[0] : r[0] + r[1]) - 1.0;
    p->z_greater = (e1 - e0) * (r[1] - r[0]) < 0.0;
    return 1;
}

/* The frame's plan (fogvol__plan), once its sample count is known. Adding a speed-up: its FOGVOL__F_
   entry in the tier table, the context's switch (fogvol__choose_speedups), its field here and the one
   pass function that follows it. */
static void fogvol__plan_frame(fogvol_context *ctx, fogvol__run *run)
{
    fogvol__plan *p = &run->p;
    const fogvol__tier_row *t = fogvol__tier(ctx->cfg.tier);
    unsigned v = ctx->cfg.variants, off = ctx->cfg.speedups_off;
    int enc = fogvol__tier_has(ctx->cfg.tier, v, FOGVOL__F_ENCODE), engine = (v & FOGVOL_VARIANT_ENGINE_DEPTH) != 0;
    int one_sample = ctx->cur.samples <= 1;
    memset(p, 0, sizeof *p);
    p->float_sums = t->sum_format == FOGVOL_FORMAT_R32F;
    p->single = (v & FOGVOL_VARIANT_SINGLE_TARGET) != 0;
    p->wide = (v & FOGVOL_VARIANT_WIDE) != 0;
    p->colors = (v & FOGVOL_VARIANT_COLORS) != 0;
    p->near_clamp = (v & FOGVOL_VARIANT_NEAR_CLAMP) ? 1.0f : 0.0f;
    p->count_bit = fogvol__depth_test_frame(ctx) ? (unsigned)FOGVOL_SPECIALIZE_COUNT : 0u;
    p->count = (v & FOGVOL_VARIANT_COUNT) || p->count_bit;
    p->own_o = enc && !ctx->cur.engine_occluders;
    p->o_engine = enc && engine;
    p->engine_read = engine && !enc;
    p->no_opaque = p->own_o && !engine && !p->count && ctx->cur.nocc == 0 && !(off & FOGVOL_SPEEDUP_SKIP_OPAQUE);
    p->float_o = p->float_sums || ctx->cfg.float_o;
    p->resolve = fogvol__tier_has(ctx->cfg.tier, v, FOGVOL__F_RESOLVE) && !ctx->cfg.inline_resolve;
    p->fetch_o = ctx->cfg.fetch_o && !p->no_opaque && !p->count && one_sample && !p->engine_read;
    p->exact_sum = ctx->cfg.exact_sum && !p->count && one_sample;
    p->borrow = t->borrow && !p->count && !p->wide;
    p->skip_check = !(off & FOGVOL_SPEEDUP_SKIP_CHECK) && !p->near_clamp && !p->single;
    p->exp_composite = !(off & FOGVOL_SPEEDUP_EXP_COMPOSITE);
    p->fast_exp = !(off & FOGVOL_SPEEDUP_FAST_EXP);
    p->blend_color = (ctx->be.caps & FOGVOL_CAP_BLEND_CONSTANT) &&
                     !(off & (FOGVOL_SPEEDUP_BLEND_COLOR | FOGVOL_SPEEDUP_SPECIALIZE));
    p->origin_bit = fogvol__origin_bit(ctx);
    p->dither_bit = fogvol__dither_bit(ctx);
    p->engine_test = fogvol__engine_test_frame(ctx, run, p);
    run->st.depth_tested = p->count;
    run->st.inline_resolved = ctx->cfg.inline_resolve;
}

/* Inside the backend frame, before any pass: sample count, plan, targets, the engine's depth, and the
   overflow count (earlier frames' queries polled without waiting; this frame's check passes). */
static fogvol_result fogvol__frame_setup(fogvol_context *ctx, fogvol__run *run)
{
    const fogvol_frame_desc *fd = &ctx->cur.frame;
    fogvol_result r = fogvol__frame_samples(ctx, &run->info, &run->st);
    if (r == FOGVOL_SUCCESS && (ctx->cur.engine_occluders || ctx->cur.mrt_ready) &&
        ctx->cur.samples != ctx->cur.prepared_samples) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR,
                    "fogvol: the engine framebuffer bound at end_frame is drawn with %d samples per pixel, the one "
                    "bound at fogvol_%s_prepare with %d: O, which the engine drew, has the other count; nothing drawn",
                    ctx->cur.samples ? ctx->cur.samples : 1, ctx->cur.mrt_ready ? "mrt" : "occluder",
                    ctx->cur.prepared_samples ? ctx->cur.prepared_samples : 1);
        r = FOGVOL_ERROR_INVALID_STATE;
    }
    fogvol__plan_frame(ctx, run);
    if (r == FOGVOL_SUCCESS && fd->downsample == 2 && ctx->cur.samples > 1) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: downsample 2 on a %d-sample engine framebuffer drawn per "
                                                 "sample (use FOGVOL_MSAA_SINGLE_SAMPLE); nothing drawn",
                    ctx->cur.samples);
        r = FOGVOL_ERROR_UNSUPPORTED;
    }
    if (r == FOGVOL_SUCCESS) /* downsample 2: half the width and height, rounded up */
        r = fd->downsample == 2 ? fogvol__ensure_targets(ctx, (run->w + 1) / 2, (run->h + 1) / 2, 1)
                                : fogvol__ensure_targets(ctx, run->w, run->h, 0);
    if (r != FOGVOL_SUCCESS) return r;
    run->e = run->p.engine_test ? fogvol__window_e(ctx) : 0;
    run->p.engine_test = run->p.engine_test && run->e && fogvol__engine_test_programs(ctx);
    run->st.engine_depth_tested = run->p.engine_test;
    run->engine_depth = fd->engine_depth_texture;
    if ((run->p.o_engine || run->p.engine_read) && fd->engine_depth_source != FOGVOL_DEPTH_SOURCE_TEXTURE) {
        r = ctx->be.copy_depth(ctx->be.user_data, fd->engine_depth_framebuffer,
                               fd->engine_depth_source == FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER, fd->viewport,
                               ctx->cur.samples > 1 ? ctx->cur.samples : 0, &run->engine_depth);
        if (r != FOGVOL_SUCCESS) {
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot copy the engine's depth buffer: %s",
                        fogvol_result_string(r));
            return r;
        }
    }
    run->fresh = ctx->ovf.counting ? fogvol__overflow_poll(ctx) : 0;
    run->counted = !run->p.float_sums && fogvol__overflow_open(ctx);
    run->checks = run->counted || (!run->p.float_sums && run->p.single && fd->show_overflow);
    /* SINGLE's peak check runs inside the sum passes; the others make the checks when a group first
       draws one (fogvol__group_check) */
    if (run->checks && run->p.single && (r = fogvol__ensure_checks(ctx)) != FOGVOL_SUCCESS) { /* drawn without */
        run->counted = run->checks = 0;
        ctx->ovf.qcur = -1;
        run->r = r;
    }
    return FOGVOL_SUCCESS;
}

/* The passes of the colour-ramp group of volume g, unless an earlier volume shares its ramp (the
   groups come in order of first appearance) or the group holds negative volumes only (they
   subtract from nothing). */
static void fogvol__group(fogvol_context *ctx, fogvol__run *run, int g)
{
    const fogvol_ramp *ramp = ctx->cur.vols[g].ramp;
    fogvol_pass ps;
    int i, has_pos = 0, has_neg = 0, n = 0, convex = 1, density = 0;
    if (fogvol__color_member(ctx, ramp)) {
        fogvol__color_group(ctx, run, g);
        return;
    }
    if (fogvol__first(ctx, ramp) != g) return;
    for (i = g; i >= 0; i = ctx->cur.vols[i].next) {
        if (ctx->cur.vols[i].negative) has_neg = 1;
        else has_pos = 1;
        convex &= ctx->cur.vols[i].mesh->convex == 1;
        density |= ctx->cur.vols[i].density != NULL;
        ++n;
    }
    if (!has_pos) return;
    /* FOGVOL_SPEEDUP_EXACT_SUM: a signed 32-bit sum holds 127 layers as deep as the range (2^24 each) */
    run->xsum = run->p.exact_sum && !density && n < 128;
    run->st.groups++;
    run->st.volumes += n;
    fogvol__sum_passes(ctx, run, ramp, has_neg);
    fogvol__sum_sources(ctx, run, ramp, &ps);
    if (run->p.engine_test) fogvol__engine_test_sources(ctx, run, ramp, &ps); /* r - o (g - c) */
    if (run->p.single) {
        if (run->counted) fogvol__check_pass(ctx, run, &ps, 0, &run->st); /* after the subtractions */
    } else if (run->counted && !run->xsum && !fogvol__unsaturable(ctx, run, n, convex)) { /* (integers cannot saturate) */
        fogvol__group_check(ctx, run, &ps);
    }
    if (run->p.single) ps.textures[FOGVOL__UNIT_FRONT] = ctx->gpu.tgt_v; /* the peak check's mask, for show_overflow */
    fogvol__composite_pass(ctx, run, &ps, ramp);
}

/* fogvol_frame_stats.depth_lsb, and its warning: the step of the digit sums against the view-depth
   extent (within znear..zfar) of the bounds of the frame's smallest positive volume. */
static void fogvol__frame_precision(fogvol_context *ctx, fogvol__run *run)
{
    int bits = ctx->gpu.tgt_b2 ? 2 * ctx->cfg.enc.precision_bits : ctx->cfg.enc.precision_bits, i, coarse;
    double n = ctx->cur.frame.znear, f = ctx->cur.frame.zfar, lsb = (f - n) / (double)(1L << bits), small = 0.0;
    if (run->p.float_sums || run->st.exact_sum >= run->st.groups) return;
    run->st.depth_lsb = (float)lsb;
    for (i = 0; i < ctx->cur.nvol; ++i) {
        double lo = 0.0, hi = 0.0;
        if (ctx->cur.vols[i].negative) continue;
        fogvol__volume_depths(ctx, &ctx->cur.vols[i], &lo, &hi);
        lo = lo < n ? n : lo > f ? f : lo;
        hi = hi < n ? n : hi > f ? f : hi;
        if (hi > lo && (small == 0.0 || hi - lo < small)) small = hi - lo;
    }
    coarse = small > 0.0 && lsb > small / 16.0;
    if (coarse && !ctx->ovf.coarse)
        fogvol__log(&ctx->log, FOGVOL_LOG_WARNING,
                    "fogvol: the %d-bit depth sums step by %g (one LSB: (zfar - znear) / 2^%d), more than 1/16 of "
                    "the smallest volume's depth extent %g: its thickness is quantised that coarsely (move znear "
                    "out or zfar in, or use fewer faces per target, or the FLOAT tier)",
                    bits, lsb, bits, small);
    ctx->ovf.coarse = coarse;
}

/* Restore the engine's state, report, react to the overflow count and reset the frame's lists. */
static fogvol_result fogvol__frame_finish(fogvol_context *ctx, fogvol__run *run, fogvol_result r,
                                         fogvol_frame_stats *stats)
{
    if (ctx->be.end_frame) ctx->be.end_frame(ctx->be.user_data);
    r = fogvol__be_result(ctx, r);
    run->st.frame = ctx->ovf.frame_no;
    run->st.overflow_pixels_late = ctx->ovf.overflow_late;
    run->st.overflow_frame = ctx->ovf.overflow_frame;
    fogvol__overflow_react(ctx, run->fresh);
    ctx->ovf.frame_no++;
    ctx->cur.in_frame = 0;
    ctx->cur.mrt_ready = 0;
    ctx->cur.engine_occluders = 0;
    ctx->cur.nvol = ctx->cur.nocc = 0;
    if (stats) *stats = run->st;
    return r;
}

FOGVOL_API fogvol_result fogvol_end_frame(fogvol_context *ctx, fogvol_frame_stats *stats)
{
    fogvol__run run;
    fogvol_result r;
    int g;
    memset(&run, 0, sizeof run);
    run.st.overflow_pixels_late = -1;
    run.st.overflow_frame = -1;
    if (stats) *stats = run.st;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!ctx->cur.in_frame)
        return fogvol__refuse(ctx, FOGVOL_ERROR_INVALID_STATE,
                              "end_frame without begin_frame (or after the frame was ended or cancelled)");
    r = fogvol__frame_refusal(ctx);
    if (r == FOGVOL_SUCCESS) r = fogvol__begin_backend_frame(ctx, &run.info);
    if (r != FOGVOL_SUCCESS) {
        fogvol_cancel_frame(ctx);
        return r;
    }
    run.w = ctx->cur.frame.viewport[2];
    run.h = ctx->cur.frame.viewport[3];
    fogvol__link_groups(ctx);
    r = fogvol__frame_setup(ctx, &run);
    if (r == FOGVOL_SUCCESS) {
        fogvol__frame_uniforms(ctx, &run);
        fogvol__opaque_pass(ctx, &run);
        fogvol__light_passes(ctx, &run);
        for (g = 0; g < ctx->cur.nvol; ++g) fogvol__group(ctx, &run, g);
        fogvol__debug_empty(ctx, &run);
        fogvol__frame_precision(ctx, &run);
        r = fogvol__frame_overflow(ctx, &run);
    }
    return fogvol__frame_finish(ctx, &run, r, stats);
}

/* >>post effects ========================================================== */
/* Image-space effects after Baker: depth of field, outlines, distance fog. */

/* Full-screen passes over the engine's depth texture: depth of field, outlines,
   distance fog. fv_view_depth(o): view depth of the pixel at offset o (whole
   pixels, clamped to the viewport), from the depth texture's window depth
   through fv_lin / fv_lin2 as in the ENGINE_DEPTH variant. */
static const char fogvol__fs_post_common[] =
    "FV_UNIFORM(vec4, fv_screen)\n"
    "FV_UNIFORM(vec4, fv_lin)\n"
    "FV_UNIFORM(vec4, fv_lin2)\n"
    "FV_UNIFORM(vec4, fv_ptexel)\n" /* (1/texture width, 1/texture height, 1 = perspective, 0) */
    "FV_UNIFORM(vec4, fv_prect)\n"  /* first and last pixel centres of the viewport */
    "FV_UNIFORM(vec4, fv_pparams)\n"
    "FV_BINDING(1) uniform sampler2D fv_pdepth;\n"
    "vec2 fv_ppix(vec2 o) { return clamp(gl_FragCoord.xy + o, fv_prect.xy, fv_prect.zw); }\n"
    "vec4 fv_ptex(sampler2D s, vec2 o) { return FV_TEXTURE(s, fv_ppix(o) * fv_ptexel.xy); }\n"
    "float fv_view_depth(vec2 o) {\n"
    "    vec2 p = fv_ppix(o);\n"
    "    vec4 q = vec4((p + fv_screen.zw) * fv_screen.xy, FV_TEXTURE(fv_pdepth, p * fv_ptexel.xy).r, 1.0);\n"
    "    return dot(fv_lin, q) / dot(fv_lin2, q);\n"
    "}\n";

/* Depth of field: fv_pparams = (focus distance, 1 / focus range, max radius in pixels, frame phase).
   FV_TAPS taps on a golden-angle (Vogel) spiral covering the disc of radius r evenly, tap i at radius
   r sqrt((i + u) / FV_TAPS), angle i 2.39996 + a, the spiral turned per pixel by a = 2 pi
   IGN(p) and its radii jittered by u = IGN(p.yx + (37, 91)), p = pixel + 5.588238 phase (interleaved
   gradient noise, Jimenez 2014): no pixel's taps line up with its neighbours', so the blur shows no
   copies of its taps and no pattern, the taps' expectation is the disc itself (stratified in angle and
   in r^2), and the phase (fogvol_frame_desc.dither_frame) turns it again every frame. */
static const char fogvol__fs_post_dof[] =
    "FV_BINDING(0) uniform sampler2D fv_pscene;\n"
    "float fv_coc(float e) { return clamp(abs(e - fv_pparams.x) * fv_pparams.y, 0.0, 1.0); }\n"
    "float fv_ign(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }\n"
    "void main() {\n"
    "    vec4 c0 = fv_ptex(fv_pscene, vec2(0.0)), sum = vec4(0.0);\n"
    "    float r = fv_coc(fv_view_depth(vec2(0.0))) * fv_pparams.z;\n"
    "    vec2 p = floor(gl_FragCoord.xy) + 5.588238 * fv_pparams.w;\n"
    "    float a = 6.2831853 * fv_ign(p), u = fv_ign(p.yx + vec2(37.0, 91.0));\n"
    "    for (int i = 0; i < FV_TAPS; ++i) {\n"
    "        float fi = float(i), t = a + 2.3999632 * fi;\n"
    "        vec2 o = floor(vec2(cos(t), sin(t)) * (r * sqrt((fi + u) / float(FV_TAPS))) + 0.5);\n"
    "        sum += mix(c0, fv_ptex(fv_pscene, o), fv_coc(fv_view_depth(o)));\n"
    "    }\n"
    "    FV_FRAGCOLOR = sum / float(FV_TAPS);\n"
    "}\n";

/* Outlines: fv_pparams = (depth threshold, normal threshold, 0, 0), fv_pcolor the colour. */
static const char fogvol__fs_post_outlines[] =
    "FV_UNIFORM(vec4, fv_pcolor)\n"
    "float fv_pg(vec2 o) { float e = fv_view_depth(o); return fv_ptexel.z > 0.5 ? 1.0 / e : e; }\n"
    "float fv_pline(vec2 o, float g0) {\n" /* second difference along a line of three, both ends inside */
    "    vec2 a = gl_FragCoord.xy + o, b = gl_FragCoord.xy - o;\n"
    "    if (any(lessThan(min(a, b), fv_prect.xy)) || any(greaterThan(max(a, b), fv_prect.zw))) return 0.0;\n"
    "    return abs(fv_pg(o) + fv_pg(-o) - 2.0 * g0);\n"
    "}\n"
    "#ifdef FV_NORMALS\n"
    "FV_BINDING(2) uniform sampler2D fv_pnormal;\n"
    "vec3 fv_pn(vec2 o) { return normalize(fv_ptex(fv_pnormal, o).rgb * 2.0 - 1.0); }\n"
    "#endif\n"
    "void main() {\n"
    "    float g0 = fv_pg(vec2(0.0));\n"
    "    float d = max(max(fv_pline(vec2(1.0, 0.0), g0), fv_pline(vec2(0.0, 1.0), g0)),\n"
    "                  max(fv_pline(vec2(1.0, 1.0), g0), fv_pline(vec2(1.0, -1.0), g0)));\n"
    "    bool edge = d > fv_pparams.x * abs(g0);\n"
    "#ifdef FV_NORMALS\n"
    "    vec3 n0 = fv_pn(vec2(0.0));\n"
    "    float m = 0.0;\n"
    "    for (int j = -1; j <= 1; ++j)\n"
    "        for (int i = -1; i <= 1; ++i) m = max(m, 1.0 - dot(n0, fv_pn(vec2(float(i), float(j)))));\n"
    "    edge = edge || m > fv_pparams.y;\n"
    "#endif\n"
    "    if (!edge) discard;\n"
    "    FV_FRAGCOLOR = fv_pcolor;\n"
    "}\n";

/* Distance fog: fv_pparams.x = start, fv_rampmap as in the volume composite. */
static const char fogvol__fs_post_fog[] =
    "FV_UNIFORM(vec4, fv_rampmap)\n"
    "FV_BINDING(2) uniform sampler2D fv_colors;\n"
    "void main() {\n"
    "    float t = max(fv_view_depth(vec2(0.0)) - fv_pparams.x, 0.0);\n"
    "    FV_FRAGCOLOR = FV_TEXTURE(fv_colors, vec2(clamp(t * fv_rampmap.x + fv_rampmap.y, 0.0, 1.0), 0.5));\n"
    "}\n";

/* The depth of field's program slot of a tap count (3, 6, 12, 24, 48), -1 for other counts. */
static int fogvol__dof_slot(int taps)
{
    return taps == 3 ? 0 : taps == 6 ? 1 : taps == 12 ? 2 : taps == 24 ? 3 : taps == 48 ? 4 : -1;
}

FOGVOL_API fogvol_result fogvol_post_shader_strings(fogvol_post_effect effect, int variant, fogvol_dialect dialect,
                                                    fogvol_stage stage, const char **strings, int *count)
{
    static const char *const taps[FOGVOL__DOF_TAPSETS] = {"#define FV_TAPS 3\n", "#define FV_TAPS 6\n",
                                                          "#define FV_TAPS 12\n", "#define FV_TAPS 24\n",
                                                          "#define FV_TAPS 48\n"};
    const fogvol__dialect_info *di;
    int n = 0;
    if (!strings || !count) return FOGVOL_ERROR_INVALID_ARGUMENT;
    *count = 0;
    if ((int)dialect <= FOGVOL_GLSL_AUTO || (int)dialect >= FOGVOL_GLSL_COUNT) return FOGVOL_ERROR_UNSUPPORTED;
    if (stage != FOGVOL_STAGE_VERTEX && stage != FOGVOL_STAGE_FRAGMENT) return FOGVOL_ERROR_UNSUPPORTED;
    if (!(effect == FOGVOL_POST_DOF && fogvol__dof_slot(variant) >= 0) &&
        !(effect == FOGVOL_POST_OUTLINES && (variant == 0 || variant == 1)) &&
        !(effect == FOGVOL_POST_DISTANCE_FOG && variant == 0))
        return FOGVOL_ERROR_UNSUPPORTED;
    di = fogvol__dialect(dialect);
    strings[n++] = di->version;
    if (stage == FOGVOL_STAGE_VERTEX) {
        n = fogvol__prelude(strings, n, di->vs);
        strings[n++] = di->decl;
        strings[n++] = fogvol__vs_fullscreen;
    } else {
        strings[n++] = di->fs;
        strings[n++] = di->decl;
        strings[n++] = fogvol__fs_post_common;
        if (effect == FOGVOL_POST_DOF) strings[n++] = taps[fogvol__dof_slot(variant)];
        if (effect == FOGVOL_POST_OUTLINES && variant) strings[n++] = "#define FV_NORMALS\n";
        strings[n++] = effect == FOGVOL_POST_DOF        ? fogvol__fs_post_dof
                       : effect == FOGVOL_POST_OUTLINES ? fogvol__fs_post_outlines
                                                        : fogvol__fs_post_fog;
    }
    *count = n;
    return FOGVOL_SUCCESS;
}

/* The program of an effect variant, built on first use (slot: see FOGVOL__POST_PROGRAMS). */
static fogvol_result fogvol__post_program(fogvol_context *ctx, fogvol_post_effect effect, int variant,
                                          fogvol_handle *out)
{
    static const char *const labels[FOGVOL_POST_EFFECT_COUNT] = {"fogvol depth of field", "fogvol outlines",
                                                                  "fogvol distance fog"};
    int slot = effect == FOGVOL_POST_DOF        ? fogvol__dof_slot(variant)
               : effect == FOGVOL_POST_OUTLINES ? FOGVOL__DOF_TAPSETS + variant
                                                : FOGVOL__DOF_TAPSETS + 2;
    fogvol_program_desc pd;
    fogvol_result r;
    if (!ctx->gpu.post_prog[slot]) {
        memset(&pd, 0, sizeof pd);
        r = fogvol_post_shader_strings(effect, variant, ctx->be.dialect, FOGVOL_STAGE_VERTEX, pd.vs, &pd.vs_count);
        if (r == FOGVOL_SUCCESS)
            r = fogvol_post_shader_strings(effect, variant, ctx->be.dialect, FOGVOL_STAGE_FRAGMENT, pd.fs,
                                           &pd.fs_count);
        pd.samplers[0] = effect == FOGVOL_POST_DOF ? "fv_pscene" : NULL;
        pd.samplers[1] = "fv_pdepth";
        pd.samplers[2] = effect == FOGVOL_POST_DISTANCE_FOG ? "fv_colors"
                         : effect == FOGVOL_POST_OUTLINES && variant ? "fv_pnormal"
                                                                     : NULL;
        pd.label = labels[effect];
        (void)fogvol_dialect_layout(ctx->be.dialect, &pd.layout);
        if (r == FOGVOL_SUCCESS) r = ctx->be.create_program(ctx->be.user_data, &pd, &ctx->gpu.post_prog[slot]);
        if (r != FOGVOL_SUCCESS) {
            (void)fogvol__be_result(ctx, r);
            fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: cannot build the %s program (GLSL %s): %s",
                        labels[effect], fogvol_dialect_name(ctx->be.dialect), fogvol_result_string(r));
            ctx->gpu.post_prog[slot] = 0;
            return r;
        }
    }
    *out = ctx->gpu.post_prog[slot];
    return FOGVOL_SUCCESS;
}

/* What every effect needs: no open frame, a backend that can, a frame desc a frame would accept
   with a depth texture, textures covering the viewport; then the camera (ctx's camera fields). */
static fogvol_result fogvol__post_check(fogvol_context *ctx, const fogvol_frame_desc *d, const int size[2],
                                        const char *what)
{
    const char *why = NULL;
    if (ctx->cur.in_frame) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: %s inside an open frame (call it after end_frame)", what);
        return FOGVOL_ERROR_INVALID_STATE;
    }
    if (!(ctx->be.caps & FOGVOL_CAP_DEPTH_TEXTURE) || !(ctx->be.caps & FOGVOL_CAP_HIGHP_FRAGMENT) ||
        (int)ctx->be.dialect <= FOGVOL_GLSL_AUTO || (int)ctx->be.dialect >= FOGVOL_GLSL_COUNT) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: %s needs depth textures and highp fragment shaders in a "
                    "known GLSL dialect (backend caps 0x%x, GLSL %s)", what, ctx->be.caps,
                    fogvol_dialect_name(ctx->be.dialect));
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (!d) why = "desc->frame is NULL";
    else if (!d->engine_depth_texture || d->engine_depth_source != FOGVOL_DEPTH_SOURCE_TEXTURE)
        why = "no depth texture (frame->engine_depth_texture)";
    else if (!fogvol__finite(d->znear) || !fogvol__finite(d->zfar) || !(d->znear > 0) || !(d->zfar > d->znear))
        why = "need 0 < znear < zfar";
    else if (d->viewport[0] < 0 || d->viewport[1] < 0 || fogvol__viewport_problem(d->viewport))
        why = "viewport origin outside 0..32767 or size outside 1..16384";
    else if (size[0] < 0 || size[1] < 0 || (size[0] && size[0] < d->viewport[0] + d->viewport[2]) ||
             (size[1] && size[1] < d->viewport[1] + d->viewport[3]))
        why = "texture_size smaller than the viewport's extent";
    else if (d->engine_depth_zero_to_one < -1 || d->engine_depth_zero_to_one > 1 ||
             !fogvol__finite_n(d->engine_depth_range, 2))
        why = "engine_depth_zero_to_one not -1, 0 or 1, or non-finite engine_depth_range";
    else if (d->draw_buffer < 0 || d->draw_buffer > 15 ||
             (d->alpha != FOGVOL_ALPHA_KEEP && d->alpha != FOGVOL_ALPHA_COVERAGE))
        why = "draw_buffer outside 0..15 or unknown alpha mode";
    if (why) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: %s: %s", what, why);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    return fogvol__camera(ctx, d);
}

/* One full-screen pass of ps (program, textures, effect uniforms set) into the engine framebuffer. */
static fogvol_result fogvol__post_run(fogvol_context *ctx, const fogvol_frame_desc *fd, const int size[2],
                                      fogvol_pass *ps)
{
    fogvol_frame_info info;
    fogvol_result r = FOGVOL_SUCCESS;
    const int *vp = fd->viewport;
    int tw = size[0] > 0 ? size[0] : vp[0] + vp[2], th = size[1] > 0 ? size[1] : vp[1] + vp[3];
    memset(&info, 0, sizeof info);
    info.draw_buffer = fd->draw_buffer;
    if (ctx->be.begin_frame) r = ctx->be.begin_frame(ctx->be.user_data, &info);
    if (r != FOGVOL_SUCCESS) {
        (void)fogvol__be_result(ctx, r);
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: backend begin_frame failed: %s", fogvol_result_string(r));
        return r;
    }
    fogvol__lin_uniforms(ctx, fd, &info, ps);
    ps->target = 0;
    memcpy(ps->viewport, vp, sizeof ps->viewport);
    ps->draw_buffer = fd->draw_buffer;
    ps->uniforms[FOGVOL_U_SCREEN][0] = 1.0f / (float)vp[2];
    ps->uniforms[FOGVOL_U_SCREEN][1] = 1.0f / (float)vp[3];
    ps->uniforms[FOGVOL_U_SCREEN][2] = -(float)vp[0];
    ps->uniforms[FOGVOL_U_SCREEN][3] = -(float)vp[1];
    ps->uniforms[FOGVOL_U_POST_TEXEL][0] = 1.0f / (float)tw;
    ps->uniforms[FOGVOL_U_POST_TEXEL][1] = 1.0f / (float)th;
    ps->uniforms[FOGVOL_U_POST_TEXEL][2] = ctx->cur.wscale > 0.0 ? 1.0f : 0.0f;
    ps->uniforms[FOGVOL_U_POST_RECT][0] = (float)vp[0] + 0.5f;
    ps->uniforms[FOGVOL_U_POST_RECT][1] = (float)vp[1] + 0.5f;
    ps->uniforms[FOGVOL_U_POST_RECT][2] = (float)(vp[0] + vp[2]) - 0.5f;
    ps->uniforms[FOGVOL_U_POST_RECT][3] = (float)(vp[1] + vp[3]) - 0.5f;
    ps->native_textures[1] = fd->engine_depth_texture;
    ctx->be.begin_pass(ctx->be.user_data, ps);
    ctx->be.draw_fullscreen(ctx->be.user_data);
    fogvol__end_pass(ctx);
    if (ctx->be.end_frame) ctx->be.end_frame(ctx->be.user_data);
    return fogvol__be_result(ctx, FOGVOL_SUCCESS);
}

FOGVOL_API fogvol_result fogvol_post_dof(fogvol_context *ctx, const fogvol_dof_desc *desc)
{
    fogvol_pass ps;
    fogvol_result r;
    fogvol_handle prog;
    int taps;
    float radius;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_dof: desc is NULL");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_check(ctx, desc->frame, desc->texture_size, "post_dof");
    if (r != FOGVOL_SUCCESS) return r;
    taps = desc->taps ? desc->taps : 24;
    radius = desc->max_radius != 0.0f ? desc->max_radius : 4.0f;
    if (!desc->color_texture || fogvol__dof_slot(taps) < 0 || !fogvol__finite(desc->focus_distance) ||
        !(desc->focus_distance > 0.0f) || !fogvol__finite(desc->focus_range) || !(desc->focus_range > 0.0f) ||
        !(radius > 0.0f && radius <= 64.0f)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_dof: need color_texture, taps 3, 6, 12, 24 or 48, "
                    "focus_distance > 0, focus_range > 0, 0 < max_radius <= 64");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_program(ctx, FOGVOL_POST_DOF, taps, &prog);
    if (r != FOGVOL_SUCCESS) return r;
    memset(&ps, 0, sizeof ps);
    ps.program = prog;
    ps.blend = FOGVOL_PASS_BLEND_NONE;
    ps.native_textures[0] = desc->color_texture;
    ps.uniforms[FOGVOL_U_POST_PARAMS][0] = desc->focus_distance;
    ps.uniforms[FOGVOL_U_POST_PARAMS][1] = 1.0f / desc->focus_range;
    ps.uniforms[FOGVOL_U_POST_PARAMS][2] = radius;
    ps.uniforms[FOGVOL_U_POST_PARAMS][3] = (float)((unsigned)desc->frame->dither_frame & 63u);
    return fogvol__post_run(ctx, desc->frame, desc->texture_size, &ps);
}

FOGVOL_API fogvol_result fogvol_post_outlines(fogvol_context *ctx, const fogvol_outline_desc *desc)
{
    fogvol_pass ps;
    fogvol_result r;
    fogvol_handle prog;
    float dt, nt;
    int i, black;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_outlines: desc is NULL");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_check(ctx, desc->frame, desc->texture_size, "post_outlines");
    if (r != FOGVOL_SUCCESS) return r;
    dt = desc->depth_threshold != 0.0f ? desc->depth_threshold : 0.05f;
    nt = desc->normal_threshold != 0.0f ? desc->normal_threshold : 0.3f;
    if (!fogvol__finite_n(desc->color, 4) || !(dt > 0.0f) || !(nt > 0.0f) || !fogvol__finite(dt) ||
        !fogvol__finite(nt)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_outlines: non-finite colour or thresholds not > 0");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_program(ctx, FOGVOL_POST_OUTLINES, desc->normal_texture ? 1 : 0, &prog);
    if (r != FOGVOL_SUCCESS) return r;
    memset(&ps, 0, sizeof ps);
    ps.program = prog;
    ps.blend = FOGVOL_PASS_BLEND_FOG;
    ps.alpha_coverage = desc->frame->alpha == FOGVOL_ALPHA_COVERAGE;
    ps.native_textures[2] = desc->normal_texture;
    black = desc->color[0] == 0.0f && desc->color[1] == 0.0f && desc->color[2] == 0.0f && desc->color[3] == 0.0f;
    for (i = 0; i < 4; ++i) ps.uniforms[FOGVOL_U_POST_COLOR][i] = black ? (i == 3 ? 1.0f : 0.0f) : desc->color[i];
    ps.uniforms[FOGVOL_U_POST_PARAMS][0] = dt;
    ps.uniforms[FOGVOL_U_POST_PARAMS][1] = nt;
    return fogvol__post_run(ctx, desc->frame, desc->texture_size, &ps);
}

FOGVOL_API fogvol_result fogvol_post_distance_fog(fogvol_context *ctx, const fogvol_distance_fog_desc *desc)
{
    fogvol_pass ps;
    fogvol_result r;
    fogvol_handle prog;
    const fogvol_ramp *ramp;
    if (!ctx) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!desc) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_distance_fog: desc is NULL");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_check(ctx, desc->frame, desc->texture_size, "post_distance_fog");
    if (r != FOGVOL_SUCCESS) return r;
    ramp = desc->ramp;
    if (!ramp || !fogvol__finite(desc->start) || !(desc->start >= 0.0f)) {
        fogvol__log(&ctx->log, FOGVOL_LOG_ERROR, "fogvol: post_distance_fog: need a ramp and a finite start >= 0");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    r = fogvol__post_program(ctx, FOGVOL_POST_DISTANCE_FOG, 0, &prog);
    if (r != FOGVOL_SUCCESS) return r;
    memset(&ps, 0, sizeof ps);
    ps.program = prog;
    ps.blend = ramp->blend == FOGVOL_BLEND_LIGHT ? FOGVOL_PASS_BLEND_LIGHT : FOGVOL_PASS_BLEND_FOG;
    ps.alpha_coverage = desc->frame->alpha == FOGVOL_ALPHA_COVERAGE;
    ps.textures[FOGVOL__UNIT_RAMP] = ramp->texture;
    ps.uniforms[FOGVOL_U_RAMP][0] = (float)((double)(ramp->width - 1) / ((double)ramp->width * ramp->max_thickness));
    ps.uniforms[FOGVOL_U_RAMP][1] = 0.5f / (float)ramp->width;
    ps.uniforms[FOGVOL_U_POST_PARAMS][0] = desc->start;
    return fogvol__post_run(ctx, desc->frame, desc->texture_size, &ps);
}

/* >>gl backend ============================================================ */
#ifndef FOGVOL_NO_GL

#ifndef FOGVOL_GLAPIENTRY
#if defined(_WIN32)
#define FOGVOL_GLAPIENTRY __stdcall
#else
#define FOGVOL_GLAPIENTRY
#endif
#endif

typedef unsigned int fogvol__GLenum;
typedef unsigned int fogvol__GLuint;
typedef int fogvol__GLint;
typedef int fogvol__GLsizei;
typedef float fogvol__GLfloat;
typedef double fogvol__GLdouble;
typedef unsigned char fogvol__GLboolean;
typedef unsigned char fogvol__GLubyte;
typedef char fogvol__GLchar;
typedef unsigned int fogvol__GLbitfield;
typedef ptrdiff_t fogvol__GLsizeiptr;

/* GL enums (values from the Khronos registry) */
enum { FOGVOL__GL_SRC_COLOR = 0x0300, FOGVOL__GL_RGBA32F = 0x8814 }; /* FOGVOL_VARIANT_COLORS */
enum { FOGVOL__GL_GREATER = 0x0204, FOGVOL__GL_RG = 0x8227, FOGVOL__GL_RG32F = 0x8230 }; /* FOGVOL_CAP_ATTACH_DEPTH */
enum {
    FOGVOL__GL_NO_ERROR = 0, FOGVOL__GL_TRIANGLES = 0x0004, FOGVOL__GL_NEVER = 0x0200, FOGVOL__GL_LESS = 0x0201,
    FOGVOL__GL_NOTEQUAL = 0x0205, FOGVOL__GL_ZERO = 0, FOGVOL__GL_ONE = 1, FOGVOL__GL_SRC_ALPHA = 0x0302,
    FOGVOL__GL_ONE_MINUS_SRC_ALPHA = 0x0303, FOGVOL__GL_FRONT = 0x0404, FOGVOL__GL_BACK = 0x0405,
    FOGVOL__GL_FRONT_AND_BACK = 0x0408, FOGVOL__GL_CW = 0x0900, FOGVOL__GL_CCW = 0x0901,
    FOGVOL__GL_POLYGON_MODE = 0x0B40, FOGVOL__GL_CULL_FACE = 0x0B44, FOGVOL__GL_CULL_FACE_MODE = 0x0B45,
    FOGVOL__GL_FRONT_FACE = 0x0B46, FOGVOL__GL_DEPTH_TEST = 0x0B71, FOGVOL__GL_DEPTH_WRITEMASK = 0x0B72,
    FOGVOL__GL_DEPTH_CLEAR_VALUE = 0x0B73, FOGVOL__GL_DEPTH_FUNC = 0x0B74, FOGVOL__GL_STENCIL_TEST = 0x0B90,
    FOGVOL__GL_STENCIL_CLEAR_VALUE = 0x0B91, FOGVOL__GL_STENCIL_FUNC = 0x0B92,
    FOGVOL__GL_STENCIL_VALUE_MASK = 0x0B93, FOGVOL__GL_STENCIL_FAIL = 0x0B94,
    FOGVOL__GL_STENCIL_PASS_DEPTH_FAIL = 0x0B95, FOGVOL__GL_STENCIL_PASS_DEPTH_PASS = 0x0B96,
    FOGVOL__GL_STENCIL_REF = 0x0B97, FOGVOL__GL_STENCIL_WRITEMASK = 0x0B98, FOGVOL__GL_VIEWPORT = 0x0BA2,
    FOGVOL__GL_ALPHA_TEST = 0x0BC0, FOGVOL__GL_DITHER = 0x0BD0, FOGVOL__GL_BLEND = 0x0BE2,
    FOGVOL__GL_COLOR_LOGIC_OP = 0x0BF2, FOGVOL__GL_SCISSOR_BOX = 0x0C10, FOGVOL__GL_SCISSOR_TEST = 0x0C11,
    FOGVOL__GL_COLOR_CLEAR_VALUE = 0x0C22, FOGVOL__GL_COLOR_WRITEMASK = 0x0C23,
    FOGVOL__GL_UNPACK_ROW_LENGTH = 0x0CF2, FOGVOL__GL_UNPACK_SKIP_ROWS = 0x0CF3,
    FOGVOL__GL_UNPACK_SKIP_PIXELS = 0x0CF4, FOGVOL__GL_UNPACK_ALIGNMENT = 0x0CF5,
    FOGVOL__GL_PACK_ROW_LENGTH = 0x0D02, FOGVOL__GL_PACK_SKIP_ROWS = 0x0D03, FOGVOL__GL_PACK_SKIP_PIXELS = 0x0D04,
    FOGVOL__GL_PACK_ALIGNMENT = 0x0D05, FOGVOL__GL_STENCIL_BITS = 0x0D57, FOGVOL__GL_TEXTURE_2D = 0x0DE1,
    FOGVOL__GL_UNSIGNED_BYTE = 0x1401, FOGVOL__GL_UNSIGNED_SHORT = 0x1403, FOGVOL__GL_UNSIGNED_INT = 0x1405,
    FOGVOL__GL_FLOAT = 0x1406, FOGVOL__GL_STENCIL = 0x1802, FOGVOL__GL_RGBA = 0x1908, FOGVOL__GL_FILL = 0x1B02,
    FOGVOL__GL_KEEP = 0x1E00, FOGVOL__GL_REPLACE = 0x1E01, FOGVOL__GL_VERSION = 0x1F02, FOGVOL__GL_RENDERER = 0x1F01,
    FOGVOL__GL_EXTENSIONS = 0x1F03, FOGVOL__GL_NEAREST = 0x2600, FOGVOL__GL_LINEAR = 0x2601,
    FOGVOL__GL_TEXTURE_MAG_FILTER = 0x2800, FOGVOL__GL_TEXTURE_MIN_FILTER = 0x2801,
    FOGVOL__GL_TEXTURE_WRAP_S = 0x2802, FOGVOL__GL_TEXTURE_WRAP_T = 0x2803, FOGVOL__GL_REPEAT = 0x2901,
    FOGVOL__GL_POLYGON_OFFSET_FILL = 0x8037, FOGVOL__GL_RGBA8 = 0x8058, FOGVOL__GL_TEXTURE_BINDING_2D = 0x8069,
    FOGVOL__GL_SAMPLE_ALPHA_TO_COVERAGE = 0x809E, FOGVOL__GL_SAMPLE_ALPHA_TO_ONE = 0x809F, FOGVOL__GL_SAMPLE_COVERAGE = 0x80A0,
    FOGVOL__GL_CLAMP_FRAGMENT_COLOR = 0x891B, FOGVOL__GL_MAX_VIEWPORTS = 0x825B,
    FOGVOL__GL_TEXTURE_FIXED_SAMPLE_LOCATIONS = 0x9107,
    FOGVOL__GL_CONSTANT_COLOR = 0x8001, FOGVOL__GL_BLEND_COLOR = 0x8005,
    FOGVOL__GL_BLEND_DST_RGB = 0x80C8, FOGVOL__GL_BLEND_SRC_RGB = 0x80C9, FOGVOL__GL_BLEND_DST_ALPHA = 0x80CA,
    FOGVOL__GL_BLEND_SRC_ALPHA = 0x80CB, FOGVOL__GL_FUNC_ADD = 0x8006, FOGVOL__GL_BLEND_EQUATION_RGB = 0x8009,
    FOGVOL__GL_CLAMP_TO_EDGE = 0x812F, FOGVOL__GL_DEPTH_COMPONENT16 = 0x81A5,
    FOGVOL__GL_DEPTH_COMPONENT24 = 0x81A6, FOGVOL__GL_TEXTURE0 = 0x84C0, FOGVOL__GL_ACTIVE_TEXTURE = 0x84E0,
    FOGVOL__GL_VERTEX_ARRAY_BINDING = 0x85B5, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_ENABLED = 0x8622,
    FOGVOL__GL_VERTEX_ATTRIB_ARRAY_SIZE = 0x8623, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_STRIDE = 0x8624,
    FOGVOL__GL_VERTEX_ATTRIB_ARRAY_TYPE = 0x8625, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_POINTER = 0x8645,
    FOGVOL__GL_STENCIL_BACK_FUNC = 0x8800, FOGVOL__GL_STENCIL_BACK_FAIL = 0x8801,
    FOGVOL__GL_STENCIL_BACK_PASS_DEPTH_FAIL = 0x8802, FOGVOL__GL_STENCIL_BACK_PASS_DEPTH_PASS = 0x8803,
    FOGVOL__GL_BLEND_EQUATION_ALPHA = 0x883D, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_NORMALIZED = 0x886A,
    FOGVOL__GL_ARRAY_BUFFER = 0x8892, FOGVOL__GL_ELEMENT_ARRAY_BUFFER = 0x8893,
    FOGVOL__GL_ARRAY_BUFFER_BINDING = 0x8894, FOGVOL__GL_ELEMENT_ARRAY_BUFFER_BINDING = 0x8895,
    FOGVOL__GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING = 0x889F, FOGVOL__GL_STATIC_DRAW = 0x88E4,
    FOGVOL__GL_PIXEL_PACK_BUFFER = 0x88EB, FOGVOL__GL_PIXEL_UNPACK_BUFFER = 0x88EC,
    FOGVOL__GL_PIXEL_PACK_BUFFER_BINDING = 0x88ED, FOGVOL__GL_PIXEL_UNPACK_BUFFER_BINDING = 0x88EF,
    FOGVOL__GL_SAMPLER_BINDING = 0x8919, FOGVOL__GL_FRAGMENT_SHADER = 0x8B30, FOGVOL__GL_VERTEX_SHADER = 0x8B31,
    FOGVOL__GL_DELETE_STATUS = 0x8B80, FOGVOL__GL_COMPILE_STATUS = 0x8B81, FOGVOL__GL_LINK_STATUS = 0x8B82,
    FOGVOL__GL_INFO_LOG_LENGTH = 0x8B84,
    FOGVOL__GL_CURRENT_PROGRAM = 0x8B8D, FOGVOL__GL_SHADING_LANGUAGE_VERSION = 0x8B8C,
    FOGVOL__GL_RASTERIZER_DISCARD = 0x8C89, FOGVOL__GL_STENCIL_BACK_REF = 0x8CA3,
    FOGVOL__GL_STENCIL_BACK_VALUE_MASK = 0x8CA4, FOGVOL__GL_STENCIL_BACK_WRITEMASK = 0x8CA5,
    FOGVOL__GL_DRAW_FRAMEBUFFER_BINDING = 0x8CA6, FOGVOL__GL_RENDERBUFFER_BINDING = 0x8CA7,
    FOGVOL__GL_READ_FRAMEBUFFER = 0x8CA8, FOGVOL__GL_DRAW_FRAMEBUFFER = 0x8CA9,
    FOGVOL__GL_READ_FRAMEBUFFER_BINDING = 0x8CAA, FOGVOL__GL_FRAMEBUFFER_COMPLETE = 0x8CD5,
    FOGVOL__GL_COLOR_ATTACHMENT0 = 0x8CE0, FOGVOL__GL_DEPTH_ATTACHMENT = 0x8D00,
    FOGVOL__GL_STENCIL_ATTACHMENT = 0x8D20, FOGVOL__GL_FRAMEBUFFER = 0x8D40, FOGVOL__GL_RENDERBUFFER = 0x8D41,
    FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE = 0x8CD0, FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE = 0x8217,
    FOGVOL__GL_FRAMEBUFFER_DEFAULT = 0x8218, FOGVOL__GL_CONTEXT_PROFILE_MASK = 0x9126, FOGVOL__GL_DEBUG_OUTPUT = 0x92E0,
    FOGVOL__GL_COLOR_BUFFER_BIT = 0x4000, FOGVOL__GL_DEPTH_BUFFER_BIT = 0x0100,
    FOGVOL__GL_STENCIL_BUFFER_BIT = 0x0400, FOGVOL__GL_FUNC_REVERSE_SUBTRACT = 0x800B, FOGVOL__GL_RED = 0x1903,
    FOGVOL__GL_R32F = 0x822E, FOGVOL__GL_NUM_EXTENSIONS = 0x821D, FOGVOL__GL_HIGH_FLOAT = 0x8DF2,
    FOGVOL__GL_TEXTURE_COMPARE_MODE = 0x884C, FOGVOL__GL_NONE = 0,
    FOGVOL__GL_DEPTH_RANGE = 0x0B70, FOGVOL__GL_CLIP_ORIGIN = 0x935C, FOGVOL__GL_CLIP_DEPTH_MODE = 0x935D,
    FOGVOL__GL_LOWER_LEFT = 0x8CA1, FOGVOL__GL_UPPER_LEFT = 0x8CA2, FOGVOL__GL_NEGATIVE_ONE_TO_ONE = 0x935E,
    FOGVOL__GL_ZERO_TO_ONE = 0x935F,
    FOGVOL__GL_INVALID_ENUM = 0x0500, FOGVOL__GL_INVALID_VALUE = 0x0501, FOGVOL__GL_INVALID_OPERATION = 0x0502,
    FOGVOL__GL_INVALID_FRAMEBUFFER_OPERATION = 0x0506, FOGVOL__GL_MAX_DRAW_BUFFERS = 0x8824,
    FOGVOL__GL_DRAW_BUFFER0 = 0x8825, FOGVOL__GL_MAX_CLIP_DISTANCES = 0x0D32, FOGVOL__GL_CLIP_DISTANCE0 = 0x3000,
    FOGVOL__GL_PRIMITIVE_RESTART = 0x8F9D, FOGVOL__GL_PRIMITIVE_RESTART_FIXED_INDEX = 0x8D69,
    FOGVOL__GL_DEPTH_CLAMP = 0x864F, FOGVOL__GL_SAMPLE_MASK = 0x8E51,
    FOGVOL__GL_POLYGON_SMOOTH = 0x0B41, FOGVOL__GL_POLYGON_STIPPLE = 0x0B42,
    FOGVOL__GL_TRANSFORM_FEEDBACK_ACTIVE = 0x8E24, FOGVOL__GL_TRANSFORM_FEEDBACK_PAUSED = 0x8E23,
    FOGVOL__GL_DEPTH = 0x1801, FOGVOL__GL_DEPTH_COMPONENT = 0x1902, FOGVOL__GL_DEPTH_STENCIL = 0x84F9,
    FOGVOL__GL_UNSIGNED_INT_24_8 = 0x84FA, FOGVOL__GL_DEPTH24_STENCIL8 = 0x88F0, FOGVOL__GL_DEPTH_COMPONENT32 = 0x81A7,
    FOGVOL__GL_DEPTH_COMPONENT32F = 0x8CAC, FOGVOL__GL_DEPTH32F_STENCIL8 = 0x8CAD,
    FOGVOL__GL_FLOAT_32_UNSIGNED_INT_24_8_REV = 0x8DAD, FOGVOL__GL_DEPTH_STENCIL_ATTACHMENT = 0x821A,
    FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME = 0x8CD1, FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE = 0x8216,
    FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE = 0x8211,
    FOGVOL__GL_SAMPLES_PASSED = 0x8914, FOGVOL__GL_ANY_SAMPLES_PASSED = 0x8C2F,
    FOGVOL__GL_ANY_SAMPLES_PASSED_CONSERVATIVE = 0x8D6A, FOGVOL__GL_CURRENT_QUERY = 0x8865,
    FOGVOL__GL_QUERY_RESULT = 0x8866, FOGVOL__GL_QUERY_RESULT_AVAILABLE = 0x8867
};
/* Multisampled targets and per-sample shading. */
enum {
    FOGVOL__GL_MULTISAMPLE = 0x809D, FOGVOL__GL_SAMPLE_BUFFERS = 0x80A8, FOGVOL__GL_SAMPLES = 0x80A9,
    FOGVOL__GL_SAMPLE_SHADING = 0x8C36, FOGVOL__GL_MIN_SAMPLE_SHADING_VALUE = 0x8C37,
    FOGVOL__GL_TEXTURE_2D_MULTISAMPLE = 0x9100, FOGVOL__GL_TEXTURE_BINDING_2D_MULTISAMPLE = 0x9104
};

/* X(return type, name without "gl", parameter list). Base: GL 2.0 / GLES 2.0. */
#define FOGVOL__GL_BASE(X) \
    X(const fogvol__GLubyte *, GetString, (fogvol__GLenum)) \
    X(void, GetIntegerv, (fogvol__GLenum, fogvol__GLint *)) \
    X(void, GetFloatv, (fogvol__GLenum, fogvol__GLfloat *)) \
    X(void, GetBooleanv, (fogvol__GLenum, fogvol__GLboolean *)) \
    X(fogvol__GLenum, GetError, (void)) \
    X(void, Enable, (fogvol__GLenum)) \
    X(void, Disable, (fogvol__GLenum)) \
    X(fogvol__GLboolean, IsEnabled, (fogvol__GLenum)) \
    X(fogvol__GLboolean, IsTexture, (fogvol__GLuint)) \
    X(void, Viewport, (fogvol__GLint, fogvol__GLint, fogvol__GLsizei, fogvol__GLsizei)) \
    X(void, Scissor, (fogvol__GLint, fogvol__GLint, fogvol__GLsizei, fogvol__GLsizei)) \
    X(void, ClearColor, (fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat)) \
    X(void, Clear, (fogvol__GLbitfield)) \
    X(void, ClearStencil, (fogvol__GLint)) \
    X(void, ColorMask, (fogvol__GLboolean, fogvol__GLboolean, fogvol__GLboolean, fogvol__GLboolean)) \
    X(void, DepthMask, (fogvol__GLboolean)) \
    X(void, DepthFunc, (fogvol__GLenum)) \
    X(void, CullFace, (fogvol__GLenum)) \
    X(void, FrontFace, (fogvol__GLenum)) \
    X(void, BlendFuncSeparate, (fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLenum)) \
    X(void, BlendEquationSeparate, (fogvol__GLenum, fogvol__GLenum)) \
    X(void, BlendEquation, (fogvol__GLenum)) \
    X(void, BlendColor, (fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat)) \
    X(void, StencilFuncSeparate, (fogvol__GLenum, fogvol__GLenum, fogvol__GLint, fogvol__GLuint)) \
    X(void, StencilOpSeparate, (fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLenum)) \
    X(void, StencilMaskSeparate, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, PixelStorei, (fogvol__GLenum, fogvol__GLint)) \
    X(void, ReadPixels, (fogvol__GLint, fogvol__GLint, fogvol__GLsizei, fogvol__GLsizei, fogvol__GLenum, \
                         fogvol__GLenum, void *)) \
    X(void, GenTextures, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(void, DeleteTextures, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BindTexture, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, ActiveTexture, (fogvol__GLenum)) \
    X(void, TexImage2D, (fogvol__GLenum, fogvol__GLint, fogvol__GLint, fogvol__GLsizei, fogvol__GLsizei, \
                         fogvol__GLint, fogvol__GLenum, fogvol__GLenum, const void *)) \
    X(void, TexParameteri, (fogvol__GLenum, fogvol__GLenum, fogvol__GLint)) \
    X(void, GenBuffers, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(void, DeleteBuffers, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BindBuffer, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, BufferData, (fogvol__GLenum, fogvol__GLsizeiptr, const void *, fogvol__GLenum)) \
    X(void, VertexAttribPointer, (fogvol__GLuint, fogvol__GLint, fogvol__GLenum, fogvol__GLboolean, \
                                  fogvol__GLsizei, const void *)) \
    X(void, EnableVertexAttribArray, (fogvol__GLuint)) \
    X(void, DisableVertexAttribArray, (fogvol__GLuint)) \
    X(void, GetVertexAttribiv, (fogvol__GLuint, fogvol__GLenum, fogvol__GLint *)) \
    X(void, GetVertexAttribPointerv, (fogvol__GLuint, fogvol__GLenum, void **)) \
    X(void, DrawElements, (fogvol__GLenum, fogvol__GLsizei, fogvol__GLenum, const void *)) \
    X(void, DrawArrays, (fogvol__GLenum, fogvol__GLint, fogvol__GLsizei)) \
    X(fogvol__GLuint, CreateShader, (fogvol__GLenum)) \
    X(void, ShaderSource, (fogvol__GLuint, fogvol__GLsizei, const fogvol__GLchar *const *, const fogvol__GLint *)) \
    X(void, CompileShader, (fogvol__GLuint)) \
    X(void, GetShaderiv, (fogvol__GLuint, fogvol__GLenum, fogvol__GLint *)) \
    X(void, GetShaderInfoLog, (fogvol__GLuint, fogvol__GLsizei, fogvol__GLsizei *, fogvol__GLchar *)) \
    X(void, DeleteShader, (fogvol__GLuint)) \
    X(fogvol__GLuint, CreateProgram, (void)) \
    X(void, AttachShader, (fogvol__GLuint, fogvol__GLuint)) \
    X(void, BindAttribLocation, (fogvol__GLuint, fogvol__GLuint, const fogvol__GLchar *)) \
    X(void, LinkProgram, (fogvol__GLuint)) \
    X(void, GetProgramiv, (fogvol__GLuint, fogvol__GLenum, fogvol__GLint *)) \
    X(void, GetProgramInfoLog, (fogvol__GLuint, fogvol__GLsizei, fogvol__GLsizei *, fogvol__GLchar *)) \
    X(void, DeleteProgram, (fogvol__GLuint)) \
    X(void, UseProgram, (fogvol__GLuint)) \
    X(fogvol__GLint, GetUniformLocation, (fogvol__GLuint, const fogvol__GLchar *)) \
    X(void, Uniform1i, (fogvol__GLint, fogvol__GLint)) \
    X(void, Uniform1f, (fogvol__GLint, fogvol__GLfloat)) \
    X(void, Uniform4fv, (fogvol__GLint, fogvol__GLsizei, const fogvol__GLfloat *)) \
    X(void, UniformMatrix4fv, (fogvol__GLint, fogvol__GLsizei, fogvol__GLboolean, const fogvol__GLfloat *))

/* Framebuffer objects: GL 3.0, ARB_framebuffer_object, GLES 2.0; EXT_framebuffer_object names as fallback. */
#define FOGVOL__GL_FBO(X) \
    X(void, GenFramebuffers, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(fogvol__GLboolean, IsFramebuffer, (fogvol__GLuint)) \
    X(void, DeleteFramebuffers, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BindFramebuffer, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, FramebufferTexture2D, (fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLuint, fogvol__GLint)) \
    X(fogvol__GLenum, CheckFramebufferStatus, (fogvol__GLenum)) \
    X(void, GenRenderbuffers, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(void, DeleteRenderbuffers, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BindRenderbuffer, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, RenderbufferStorage, (fogvol__GLenum, fogvol__GLenum, fogvol__GLsizei, fogvol__GLsizei)) \
    X(void, FramebufferRenderbuffer, (fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLuint)) \
    X(void, GetFramebufferAttachmentParameteriv, (fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLint *))

/* Vertex array objects: GL 3.0, GLES 3.0 (required in core profiles). */
#define FOGVOL__GL_VAO(X) \
    X(void, GenVertexArrays, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(fogvol__GLboolean, IsVertexArray, (fogvol__GLuint)) \
    X(void, DeleteVertexArrays, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BindVertexArray, (fogvol__GLuint))

/* Sampler objects: GL 3.3, GLES 3.0 (to unbind the engine's from our units, and to sample the engine's
   depth texture whatever its own filter and compare mode). */
#define FOGVOL__GL_SAMPLER(X) X(void, BindSampler, (fogvol__GLuint, fogvol__GLuint)) \
    X(void, GenSamplers, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(void, DeleteSamplers, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, SamplerParameteri, (fogvol__GLuint, fogvol__GLenum, fogvol__GLint))

/* Framebuffer blits: GL 3.0, GLES 3.0, ARB_framebuffer_object (the engine's depth buffer into a texture). */
#define FOGVOL__GL_BLIT(X) \
    X(void, BlitFramebuffer, (fogvol__GLint, fogvol__GLint, fogvol__GLint, fogvol__GLint, fogvol__GLint, \
                              fogvol__GLint, fogvol__GLint, fogvol__GLint, fogvol__GLbitfield, fogvol__GLenum))

/* GL 3.0 / GLES 3.0: extension strings one by one. */
#define FOGVOL__GL_3(X) X(const fogvol__GLubyte *, GetStringi, (fogvol__GLenum, fogvol__GLuint))

/* Several colour outputs: GL 2.0, GLES 3.0 (WIDE); desktop GL 3.0 binds output names. */
#define FOGVOL__GL_DRAW_BUFFERS(X) X(void, DrawBuffers, (fogvol__GLsizei, const fogvol__GLenum *))
#define FOGVOL__GL_3_DESKTOP(X) X(void, BindFragDataLocation, (fogvol__GLuint, fogvol__GLuint, const fogvol__GLchar *))

/* Per-draw-buffer colour mask and blend enable: GL 3.0, GLES 3.2 (3.0/3.1 + OES_/EXT_draw_buffers_indexed). */
#define FOGVOL__GL_INDEXED_MASK(X) \
    X(fogvol__GLboolean, IsEnabledi, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, Enablei, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, Disablei, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, ColorMaski, (fogvol__GLuint, fogvol__GLboolean, fogvol__GLboolean, fogvol__GLboolean, fogvol__GLboolean))
/* The indexed queries: GL 3.0, GLES 3.0 (GetBooleani_v: GLES 3.1; on GLES 3.0 the masks are read as integers). */
#define FOGVOL__GL_INDEXED_QUERY(X) \
    X(void, GetBooleani_v, (fogvol__GLenum, fogvol__GLuint, fogvol__GLboolean *)) \
    X(void, GetIntegeri_v, (fogvol__GLenum, fogvol__GLuint, fogvol__GLint *))
/* Per-draw-buffer blend functions and equations: GL 4.0 (3.x + ARB_draw_buffers_blend: ...iARB), GLES 3.2
   (3.0/3.1 + OES_ or EXT_draw_buffers_indexed: ...iOES, ...iEXT, like the masks above). */
#define FOGVOL__GL_INDEXED_BLEND(X) \
    X(void, BlendFuncSeparatei, (fogvol__GLuint, fogvol__GLenum, fogvol__GLenum, fogvol__GLenum, fogvol__GLenum)) \
    X(void, BlendEquationSeparatei, (fogvol__GLuint, fogvol__GLenum, fogvol__GLenum)) \
    X(void, BlendEquationi, (fogvol__GLuint, fogvol__GLenum))
/* Pausing the engine's transform feedback: GL 4.0 (or 3.x + ARB_transform_feedback2, same names), GLES 3.0. */
#define FOGVOL__GL_TF_PAUSE(X) X(void, PauseTransformFeedback, (void)) X(void, ResumeTransformFeedback, (void))

/* Desktop only. */
#define FOGVOL__GL_DESKTOP(X) \
    X(void, PolygonMode, (fogvol__GLenum, fogvol__GLenum)) \
    X(void, ClearDepth, (fogvol__GLdouble)) \
    X(void, GetDoublev, (fogvol__GLenum, fogvol__GLdouble *)) \
    X(void, DepthRange, (fogvol__GLdouble, fogvol__GLdouble))

/* GLES only. */
#define FOGVOL__GL_ES(X) \
    X(void, ClearDepthf, (fogvol__GLfloat)) \
    X(void, DepthRangef, (fogvol__GLfloat, fogvol__GLfloat)) \
    X(void, GetShaderPrecisionFormat, (fogvol__GLenum, fogvol__GLenum, fogvol__GLint *, fogvol__GLint *))

/* Optional, desktop: viewport arrays (GL 4.1, ARB_viewport_array): fogvol's passes and its restore write
   index 0 alone (glViewport, glScissor, glDepthRange and the scissor enable would write every index);
   colour clamping (GL 3.0 compatibility profiles: glClampColor(GL_CLAMP_FRAGMENT_COLOR)). */
#define FOGVOL__GL_VIEWPORT_ARRAY(X) \
    X(void, ViewportIndexedf, (fogvol__GLuint, fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat, fogvol__GLfloat)) \
    X(void, ScissorIndexed, (fogvol__GLuint, fogvol__GLint, fogvol__GLint, fogvol__GLsizei, fogvol__GLsizei)) \
    X(void, DepthRangeIndexed, (fogvol__GLuint, fogvol__GLdouble, fogvol__GLdouble))
#define FOGVOL__GL_VIEWPORT_ARRAY_ES(X) X(void, DepthRangeIndexedf, (fogvol__GLuint, fogvol__GLfloat, fogvol__GLfloat))
#define FOGVOL__GL_CLAMP(X) X(void, ClampColor, (fogvol__GLenum, fogvol__GLenum))

/* Optional: clip control (GL 4.5, ARB_clip_control; GLES: EXT_clip_control as glClipControlEXT). */
#define FOGVOL__GL_CLIP_CONTROL(X) X(void, ClipControl, (fogvol__GLenum, fogvol__GLenum))

/* Occlusion queries: GL 1.5, GLES 3.0 (optional: per-frame overflow counting). */
#define FOGVOL__GL_QUERY(X) \
    X(void, GenQueries, (fogvol__GLsizei, fogvol__GLuint *)) \
    X(void, DeleteQueries, (fogvol__GLsizei, const fogvol__GLuint *)) \
    X(void, BeginQuery, (fogvol__GLenum, fogvol__GLuint)) \
    X(void, EndQuery, (fogvol__GLenum)) \
    X(void, GetQueryiv, (fogvol__GLenum, fogvol__GLenum, fogvol__GLint *)) \
    X(void, GetQueryObjectuiv, (fogvol__GLuint, fogvol__GLenum, fogvol__GLuint *))

#define FOGVOL__GL_ALL(X) \
    FOGVOL__GL_BASE(X) FOGVOL__GL_FBO(X) FOGVOL__GL_VAO(X) FOGVOL__GL_SAMPLER(X) FOGVOL__GL_BLIT(X) FOGVOL__GL_3(X) \
        FOGVOL__GL_DRAW_BUFFERS(X) FOGVOL__GL_3_DESKTOP(X) FOGVOL__GL_DESKTOP(X) FOGVOL__GL_ES(X) \
            FOGVOL__GL_CLIP_CONTROL(X) FOGVOL__GL_INDEXED_QUERY(X) FOGVOL__GL_INDEXED_MASK(X) FOGVOL__GL_INDEXED_BLEND(X) FOGVOL__GL_TF_PAUSE(X) \
                FOGVOL__GL_QUERY(X) FOGVOL__GL_VIEWPORT_ARRAY(X) FOGVOL__GL_VIEWPORT_ARRAY_ES(X) FOGVOL__GL_CLAMP(X)

#define FOGVOL__GL_PFN(ret, name, params) typedef ret(FOGVOL_GLAPIENTRY *fogvol__PFN_##name) params;
FOGVOL__GL_ALL(FOGVOL__GL_PFN)
#undef FOGVOL__GL_PFN

/* Multisampled targets: GL 3.2 (texture multisample), per-sample shading GL 4.0 / ARB_sample_shading. */
#define FOGVOL__GL_MSAA(X) \
    X(void, TexImage2DMultisample, (fogvol__GLenum, fogvol__GLsizei, fogvol__GLenum, fogvol__GLsizei, \
                                    fogvol__GLsizei, fogvol__GLboolean)) \
    X(void, RenderbufferStorageMultisample, (fogvol__GLenum, fogvol__GLsizei, fogvol__GLenum, fogvol__GLsizei, \
                                             fogvol__GLsizei)) \
    X(void, MinSampleShading, (fogvol__GLfloat)) \
    X(void, GetTexLevelParameteriv, (fogvol__GLenum, fogvol__GLint, fogvol__GLenum, fogvol__GLint *))
#define FOGVOL__GL_PFN_MSAA(ret, name, params) typedef ret(FOGVOL_GLAPIENTRY *fogvol__PFN_##name) params;
FOGVOL__GL_MSAA(FOGVOL__GL_PFN_MSAA)
#undef FOGVOL__GL_PFN_MSAA
#define FOGVOL__GL_MAX_DB 8 /* draw buffers saved and restored (GL guarantees at least 8 on GL 3.0+) */

/* ---- the engine state fogvol saves and restores ----
   One table per kind of state, walked by fogvol__gl_save, fogvol__gl_restore and every pass:
   - FOGVOL__GL_ENABLES (below): every glEnable capability, with the contexts that have it (W: a
     FOGVOL__GLW_* test of fogvol__gl_has) and what every fogvol pass does with it (P: OFF turns it off,
     SET leaves it to the pass, which sets it itself or keeps the engine's value);
   - fogvol__gl_values (after struct fogvol__gl): plain values read with glGet* and written back by one
     call each (fogvol__gl_put), pixel-store values with fogvol's own value for its passes;
   - small functions for the rest: bindings (fogvol__gl_save_bindings), depth clear value, depth range
     and clip control (fogvol__gl_save_depth), the engine FBO's draw buffers and per-draw-buffer blend
     state (fogvol__gl_save_draw_buffers), multisample bindings (fogvol__gl_save_msaa).
   To save one more piece of state: a row here or in fogvol__gl_values (plus its field in
   fogvol__gl_state, and a FOGVOL__GLV_* setter in fogvol__gl_put if no existing call writes it).
   Why the state beyond the GL 2.0 list matters to fogvol's draws:
   - the draw-buffer list of an engine FBO: the composite writes one buffer, the others stay intact;
   - per-draw-buffer blend functions, equations, colour masks and blend enables: fogvol's non-indexed
     calls overwrite every buffer's values;
   - PRIMITIVE_RESTART (+ _FIXED_INDEX): would cut fogvol's index lists at the engine's restart index
     (the index itself is never changed, so it is not saved);
   - CLIP_DISTANCE0..7 (CLIP_PLANEi): fogvol's shaders write no gl_ClipDistance, so an enabled one is
     undefined there;
   - DEPTH_CLAMP: disables the near/far clipping that the thickness passes rely on;
   - SAMPLE_SHADING, SAMPLE_MASK: per-sample shading / dropped samples on a multisampled engine target;
   - SAMPLE_ALPHA_TO_ONE: on a multisampled engine target, every fogvol fragment's alpha forced to 1
     before blending (opaque fog, and the alpha digit of the RGBA8 sums);
   - CLAMP_FRAGMENT_COLOR (GL 3.0+ compatibility profiles, glClampColor; fogvol__gl_values): GL_TRUE
     clamps the signed float sums; fogvol's passes set GL_FALSE;
   - viewport arrays (GL 4.1): glViewport, glScissor, glDepthRange and glDisable(GL_SCISSOR_TEST)
     write every index, so fogvol writes index 0 alone (fogvol__gl_viewport, fogvol__gl_scissor,
     fogvol__gl_depth_range) and turns the scissor test off for every index in its passes, putting each
     index's enable back (fogvol__gl_state.scissor_enables: a GL may apply any index's enable to all);
   - POLYGON_SMOOTH, POLYGON_STIPPLE (compatibility): coverage-scaled or stippled fragments;
   - an active, unpaused transform feedback: paused and resumed by fogvol__gl_host_enter/leave (GL 4.0,
     GLES 3.0; on GL 3.x it cannot be queried: do not call fogvol inside glBeginTransformFeedback).
   Judged irrelevant, not touched:
   - MULTISAMPLE: fogvol's targets are single-sample; on a multisampled engine target the full-screen
     composite covers every sample whether it is on or off (saved only where fogvol's own multisampled
     passes turn it on);
   - FRAMEBUFFER_SRGB: acts only on sRGB attachments, which fogvol's RGBA8/R32F targets are not; on an
     sRGB engine target it selects the blending space the engine wants (see fogvol_ramp_desc);
   - MIN_SAMPLE_SHADING_VALUE, PRIMITIVE_RESTART_INDEX: read only while their enables are on (fogvol
     turns those off);
   - PROVOKING_VERTEX: fogvol's shaders have no flat varyings;
   - PATCH_VERTICES and default patch levels: fogvol draws TRIANGLES with no tessellation stage;
   - uniform, shader-storage, atomic-counter and image bindings: no fogvol shader reads them;
   - texture bindings of targets other than TEXTURE_2D on fogvol's units: it samples sampler2D only;
   - conditional rendering: it cannot be queried; fogvol must not be called between
     glBeginConditionalRender and glEndConditionalRender (its passes could be discarded). */
#define FOGVOL__GL_ENABLES(X) \
    X(FOGVOL__GL_BLEND, ALL, SET) \
    X(FOGVOL__GL_DEPTH_TEST, ALL, SET) \
    X(FOGVOL__GL_CULL_FACE, ALL, SET) \
    X(FOGVOL__GL_SCISSOR_TEST, ALL, OFF) \
    X(FOGVOL__GL_STENCIL_TEST, ALL, SET) \
    X(FOGVOL__GL_DITHER, ALL, OFF) \
    X(FOGVOL__GL_SAMPLE_ALPHA_TO_COVERAGE, ALL, OFF) \
    X(FOGVOL__GL_SAMPLE_COVERAGE, ALL, OFF) \
    X(FOGVOL__GL_SAMPLE_ALPHA_TO_ONE, DESKTOP, OFF) \
    X(FOGVOL__GL_POLYGON_OFFSET_FILL, ALL, OFF) \
    X(FOGVOL__GL_RASTERIZER_DISCARD, DISCARD, OFF) \
    X(FOGVOL__GL_COLOR_LOGIC_OP, DESKTOP, OFF) \
    X(FOGVOL__GL_ALPHA_TEST, COMPAT, OFF) \
    X(FOGVOL__GL_MULTISAMPLE, MSAA, SET) \
    X(FOGVOL__GL_PRIMITIVE_RESTART, RESTART, OFF) \
    X(FOGVOL__GL_PRIMITIVE_RESTART_FIXED_INDEX, RESTART_FIXED, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 0, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 1, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 2, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 3, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 4, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 5, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 6, CLIP, OFF) \
    X(FOGVOL__GL_CLIP_DISTANCE0 + 7, CLIP, OFF) \
    X(FOGVOL__GL_DEPTH_CLAMP, DEPTH_CLAMP, OFF) \
    X(FOGVOL__GL_SAMPLE_SHADING, SAMPLE_SHADING, OFF) \
    X(FOGVOL__GL_SAMPLE_MASK, SAMPLE_MASK, OFF) \
    X(FOGVOL__GL_POLYGON_SMOOTH, DESKTOP, OFF) \
    X(FOGVOL__GL_POLYGON_STIPPLE, COMPAT, OFF)
#define FOGVOL__GL_ONE(cap, when, pass) +1
enum { FOGVOL__GL_N_ENABLES = 0 FOGVOL__GL_ENABLES(FOGVOL__GL_ONE) };
#undef FOGVOL__GL_ONE

typedef struct fogvol__gl_state {
    /* bindings (fogvol__gl_save_bindings, fogvol__gl_save_msaa) */
    fogvol__GLint draw_fbo, read_fbo, renderbuffer, program, vao, array_buffer, element_buffer, active_texture,
        tex2d[FOGVOL_MAX_TEXTURE_UNITS], sampler[FOGVOL_MAX_TEXTURE_UNITS], unpack_buffer, pack_buffer;
    fogvol__GLint program_deleted; /* the engine deleted its current program: it is freed once fogvol binds its own */
    fogvol__GLint a0_enabled, a0_size, a0_type, a0_normalized, a0_stride, a0_buffer;
    void *a0_pointer;
    fogvol__GLint tex2dms[FOGVOL_MAX_TEXTURE_UNITS]; /* multisample texture bindings (GL 3.2+) */
    fogvol__GLfloat min_sample_shading;
    /* the rows of fogvol__gl_values */
    fogvol__GLint viewport[4], scissor_box[4], blend_func[4], blend_eq[2], depth_func, cull_mode, front_face,
        polygon_mode[2], clamp_fragment;
    unsigned long scissor_enables; /* viewport arrays: the scissor test of each index (bit i) */
    fogvol__GLint st_func[3], st_op[3], st_wmask, stb_func[3], stb_op[3], stb_wmask, st_clear; /* stb: back */
    fogvol__GLint pixel_align[2], unpack_rows[3], pack_rows[3]; /* row length, skip rows, skip pixels */
    fogvol__GLboolean depth_mask, color_mask[4];
    fogvol__GLfloat clear_color[4], blend_color[4];
    /* the rows of FOGVOL__GL_ENABLES, in order */
    fogvol__GLboolean enabled[FOGVOL__GL_N_ENABLES];
    /* fogvol__gl_save_depth */
    fogvol__GLfloat clear_depth;
    fogvol__GLdouble clear_depth_d; /* desktop: kept in double so it comes back exactly */
    fogvol__GLdouble depth_range_d[2]; /* desktop (double, exact); GLES: depth_range */
    fogvol__GLfloat depth_range[2];
    fogvol__GLint clip_origin, clip_depth; /* with clip control */
    /* The engine framebuffer's draw buffers (an FBO's list; not read for the default framebuffer), and
       per-draw-buffer blend state (GL 3.0 / 4.0, GLES 3.2) that the non-indexed calls overwrite
       (fogvol__gl_save_draw_buffers). */
    fogvol__GLint n_draw_buffers, draw_buffers[FOGVOL__GL_MAX_DB], draw_buffers_set;
    fogvol__GLint n_indexed, bi_src_rgb[FOGVOL__GL_MAX_DB], bi_dst_rgb[FOGVOL__GL_MAX_DB],
        bi_src_a[FOGVOL__GL_MAX_DB], bi_dst_a[FOGVOL__GL_MAX_DB], bi_eq_rgb[FOGVOL__GL_MAX_DB],
        bi_eq_a[FOGVOL__GL_MAX_DB];
    fogvol__GLboolean bi_mask[FOGVOL__GL_MAX_DB][4], bi_blend[FOGVOL__GL_MAX_DB];
} fogvol__gl_state;

/* Textures and targets share this header so either can be bound for sampling. */
typedef struct fogvol__gl_texture {
    fogvol__GLuint tex;
    int samples; /* > 1: a multisample texture (GL_TEXTURE_2D_MULTISAMPLE) */
} fogvol__gl_texture;

typedef struct fogvol__gl_target {
    fogvol__gl_texture base; /* the colour texture */
    fogvol__GLuint fbo, depth;
    int width, height;
    int owns_depth; /* 0 when depth is another target's renderbuffer */
    fogvol__GLuint read_tex; /* fogvol_pass.read_target's texture at colour attachment 1 (0: none) */
    fogvol_format format;
    int unfixed; /* multisample: storage made with fixedsamplelocations GL_FALSE (an engine depth's, attached) */
    struct fogvol__gl_target *second; /* WIDE: attachment 1 as a target of its own (own FBO) */
} fogvol__gl_target;

typedef struct fogvol__gl_program {
    fogvol__GLuint id;
    fogvol__GLint u_mvp, u_depth, u_sign, u_vec[FOGVOL_U_COUNT];
    fogvol__GLint u_ext, u_emit; /* FOGVOL_PROGRAM_COLOR_FACE */
} fogvol__gl_program;

typedef struct fogvol__gl_mesh {
    fogvol__GLuint vbo, ibo, vao;
    fogvol__GLsizei count;
    fogvol__GLenum index_type;
    fogvol__GLsizei stride; /* the engine's vertex layout, read in place */
    size_t offset;
} fogvol__gl_mesh;

typedef struct fogvol__gl {
#define FOGVOL__GL_MEMBER(ret, name, params) fogvol__PFN_##name name;
    FOGVOL__GL_ALL(FOGVOL__GL_MEMBER)
#undef FOGVOL__GL_MEMBER
    fogvol_allocator alloc;
    fogvol_logger log;
    int major, minor, gles, core;
    int has_vao, has_sampler, has_split_fbo, has_pixel_buffers, has_row_length, has_discard, has_uint_index;
    int has_pack_rows; /* PACK_ROW_LENGTH, PACK_SKIP_*: GL, GLES 3, GLES 2 + NV_pack_subimage (has_row_length:
                          the UNPACK_ ones, GLES 2 + EXT_unpack_subimage) */
    int has_msaa; /* multisample textures and per-sample shading */
    int float_linear; /* R32F textures can be filtered (GL 3.0; GLES 3 + OES_texture_float_linear) */
    int mrt_highp;    /* fogvol_gl_desc.mrt_highp */
#define FOGVOL__GL_MEMBER_MSAA(ret, name, params) fogvol__PFN_##name name;
    FOGVOL__GL_MSAA(FOGVOL__GL_MEMBER_MSAA)
#undef FOGVOL__GL_MEMBER_MSAA
    int has_indexed_mask, has_indexed_blend, has_tf_pause, max_draw_buffers, n_clip;
    int has_restart, has_restart_fixed, has_depth_clamp, has_sample_shading, has_sample_mask;
    int n_viewports; /* viewport arrays (gl->ViewportIndexedf): the scissor enables saved per index, up to 32 */
    int host_depth, host_n, tf_paused;                  /* fogvol__gl_host_enter / leave */
    fogvol__GLenum host_errors[4];                      /* the engine's pending GL errors, raised again */
    fogvol__GLuint err_shader, err_fbo;                 /* objects that make GL raise a chosen error (err_fbo:
                                                           made at creation without VAOs, the context's mark) */
    int has_debug_output;                               /* GL_DEBUG_OUTPUT can be switched (KHR_debug) */
    int skip_draws;                                     /* this pass has an engine texture that is none */
    fogvol__GLuint depth_attached; /* the FBO whose depth attachment is fogvol_pass.depth_texture until end_pass */
    fogvol__GLenum depth_attached_target; /* ... and its texture target (2D or 2D_MULTISAMPLE) */
    fogvol_result own;                                  /* fogvol's own first error since take_error */
    void *(*current_context)(void *user_data);          /* fogvol_gl_desc.current_context, its user_data, */
    void *user_data, *context_id;                       /* and what it returned at creation */
    unsigned caps;
    fogvol_dialect dialect;
    fogvol__gl_state saved;
    int in_frame;
    fogvol__gl_program *program;
    fogvol__gl_mesh fullscreen;
    fogvol__GLuint native_sampler; /* engine textures (ENGINE_DEPTH): nearest, clamp, no depth compare */
    fogvol__GLuint depth_tex, depth_fbo; /* the engine's depth copied by copy_depth */
    int depth_w, depth_h, depth_samples; /* depth_samples > 1: a multisample texture */
    fogvol__GLenum depth_format;
    int has_query; /* occlusion queries loaded (GL 1.5+, GLES 3.0+) */
    int webgl;     /* a WebGL context behind GLES (GL_VERSION names WebGL, as emscripten reports it) */
} fogvol__gl;

static int fogvol__has_ext(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    if (!list) return 0;
    while ((p = strstr(p, name)) != NULL) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
        p += n;
    }
    return 0;
}

static void fogvol__gl_enable(fogvol__gl *gl, fogvol__GLenum cap, int on)
{
    if (cap == FOGVOL__GL_SCISSOR_TEST && gl->ViewportIndexedf && on) {
        gl->Enablei(cap, 0); /* (viewport arrays: on for index 0 alone; off for every index, since a GL may
                                apply any index's enable to every viewport, put back by index at the end) */
    } else if (on) {
        gl->Enable(cap);
    } else {
        gl->Disable(cap);
    }
}

/* glViewport, glScissor and glDepthRange of index 0 alone where the context has viewport arrays. */
static void fogvol__gl_viewport(fogvol__gl *gl, fogvol__GLint x, fogvol__GLint y, fogvol__GLsizei w, fogvol__GLsizei h)
{
    if (gl->ViewportIndexedf)
        gl->ViewportIndexedf(0, (fogvol__GLfloat)x, (fogvol__GLfloat)y, (fogvol__GLfloat)w, (fogvol__GLfloat)h);
    else gl->Viewport(x, y, w, h);
}

static void fogvol__gl_scissor(fogvol__gl *gl, fogvol__GLint x, fogvol__GLint y, fogvol__GLsizei w, fogvol__GLsizei h)
{
    if (gl->ViewportIndexedf) gl->ScissorIndexed(0, x, y, w, h);
    else gl->Scissor(x, y, w, h);
}

static void fogvol__gl_depth_range(fogvol__gl *gl, fogvol__GLdouble n, fogvol__GLdouble f)
{
    if (gl->gles && gl->ViewportIndexedf) gl->DepthRangeIndexedf(0, (fogvol__GLfloat)n, (fogvol__GLfloat)f);
    else if (gl->gles) gl->DepthRangef((fogvol__GLfloat)n, (fogvol__GLfloat)f);
    else if (gl->ViewportIndexedf) gl->DepthRangeIndexed(0, n, f);
    else gl->DepthRange(n, f);
}

/* Which contexts have a piece of state (the W column of FOGVOL__GL_ENABLES, when of fogvol__gl_values). */
enum {
    FOGVOL__GLW_ALL, FOGVOL__GLW_DESKTOP, FOGVOL__GLW_COMPAT, FOGVOL__GLW_ROW_LENGTH, FOGVOL__GLW_PACK_ROWS,
    FOGVOL__GLW_DISCARD,
    FOGVOL__GLW_MSAA, FOGVOL__GLW_RESTART, FOGVOL__GLW_RESTART_FIXED, FOGVOL__GLW_CLIP, FOGVOL__GLW_DEPTH_CLAMP,
    FOGVOL__GLW_SAMPLE_SHADING, FOGVOL__GLW_SAMPLE_MASK, FOGVOL__GLW_CLAMP
};
enum { FOGVOL__GLP_SET, FOGVOL__GLP_OFF };

static int fogvol__gl_has(const fogvol__gl *gl, int when, fogvol__GLenum name)
{
    switch (when) {
    case FOGVOL__GLW_DESKTOP: return !gl->gles;
    case FOGVOL__GLW_COMPAT: return !gl->gles && !gl->core;
    case FOGVOL__GLW_ROW_LENGTH: return gl->has_row_length;
    case FOGVOL__GLW_PACK_ROWS: return gl->has_pack_rows;
    case FOGVOL__GLW_DISCARD: return gl->has_discard;
    case FOGVOL__GLW_MSAA: return gl->has_msaa;
    case FOGVOL__GLW_RESTART: return gl->has_restart;
    case FOGVOL__GLW_RESTART_FIXED: return gl->has_restart_fixed;
    case FOGVOL__GLW_CLIP: return (int)(name - FOGVOL__GL_CLIP_DISTANCE0) < gl->n_clip;
    case FOGVOL__GLW_DEPTH_CLAMP: return gl->has_depth_clamp;
    case FOGVOL__GLW_SAMPLE_SHADING: return gl->has_sample_shading;
    case FOGVOL__GLW_SAMPLE_MASK: return gl->has_sample_mask;
    case FOGVOL__GLW_CLAMP: return gl->ClampColor != NULL;
    default: return 1;
    }
}

typedef struct fogvol__gl_enable_row {
    fogvol__GLenum cap;
    unsigned char when, pass; /* FOGVOL__GLW_*, FOGVOL__GLP_* */
} fogvol__gl_enable_row;

static const fogvol__gl_enable_row fogvol__gl_enables[FOGVOL__GL_N_ENABLES] = {
#define FOGVOL__GL_ENABLE_ROW(cap, when, pass) {(fogvol__GLenum)(cap), FOGVOL__GLW_##when, FOGVOL__GLP_##pass},
    FOGVOL__GL_ENABLES(FOGVOL__GL_ENABLE_ROW)
#undef FOGVOL__GL_ENABLE_ROW
};

/* The call that writes a row of fogvol__gl_values back. */
enum {
    FOGVOL__GLV_PIXEL_STORE, FOGVOL__GLV_VIEWPORT, FOGVOL__GLV_SCISSOR, FOGVOL__GLV_BLEND_FUNC, FOGVOL__GLV_BLEND_EQ,
    FOGVOL__GLV_DEPTH_FUNC, FOGVOL__GLV_CULL_FACE, FOGVOL__GLV_FRONT_FACE, FOGVOL__GLV_POLYGON_MODE,
    FOGVOL__GLV_DEPTH_MASK, FOGVOL__GLV_COLOR_MASK, FOGVOL__GLV_CLEAR_COLOR, FOGVOL__GLV_STENCIL_FUNC,
    FOGVOL__GLV_STENCIL_OP, FOGVOL__GLV_STENCIL_MASK, FOGVOL__GLV_CLEAR_STENCIL, FOGVOL__GLV_BLEND_COLOR,
    FOGVOL__GLV_CLAMP_COLOR
};

/* Plain values: each name of a row is read with glGet<type>v into per consecutive values from the row's
   field on, and the row is written back by one call (fogvol__gl_put). */
typedef struct fogvol__gl_value_row {
    unsigned char put, type, when, per; /* FOGVOL__GLV_*; 'i', 'b' or 'f'; FOGVOL__GLW_*; values per name */
    unsigned short offset;              /* the field in fogvol__gl_state */
    fogvol__GLenum arg;                 /* stencil: the face; pixel store: fogvol's value in its passes */
    fogvol__GLenum names[4];            /* 0 ends the list */
} fogvol__gl_value_row;

#define FOGVOL__GL_AT(field) (unsigned short)offsetof(fogvol__gl_state, field)
static const fogvol__gl_value_row fogvol__gl_values[] = {
    {FOGVOL__GLV_VIEWPORT, 'i', FOGVOL__GLW_ALL, 4, FOGVOL__GL_AT(viewport), 0, {FOGVOL__GL_VIEWPORT}},
    {FOGVOL__GLV_SCISSOR, 'i', FOGVOL__GLW_ALL, 4, FOGVOL__GL_AT(scissor_box), 0, {FOGVOL__GL_SCISSOR_BOX}},
    {FOGVOL__GLV_BLEND_FUNC, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(blend_func), 0,
     {FOGVOL__GL_BLEND_SRC_RGB, FOGVOL__GL_BLEND_DST_RGB, FOGVOL__GL_BLEND_SRC_ALPHA, FOGVOL__GL_BLEND_DST_ALPHA}},
    {FOGVOL__GLV_BLEND_EQ, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(blend_eq), 0,
     {FOGVOL__GL_BLEND_EQUATION_RGB, FOGVOL__GL_BLEND_EQUATION_ALPHA}},
    {FOGVOL__GLV_DEPTH_FUNC, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(depth_func), 0, {FOGVOL__GL_DEPTH_FUNC}},
    {FOGVOL__GLV_CULL_FACE, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(cull_mode), 0, {FOGVOL__GL_CULL_FACE_MODE}},
    {FOGVOL__GLV_FRONT_FACE, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(front_face), 0, {FOGVOL__GL_FRONT_FACE}},
    {FOGVOL__GLV_POLYGON_MODE, 'i', FOGVOL__GLW_DESKTOP, 2, FOGVOL__GL_AT(polygon_mode), 0, {FOGVOL__GL_POLYGON_MODE}},
    {FOGVOL__GLV_DEPTH_MASK, 'b', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(depth_mask), 0, {FOGVOL__GL_DEPTH_WRITEMASK}},
    {FOGVOL__GLV_COLOR_MASK, 'b', FOGVOL__GLW_ALL, 4, FOGVOL__GL_AT(color_mask), 0, {FOGVOL__GL_COLOR_WRITEMASK}},
    {FOGVOL__GLV_CLEAR_COLOR, 'f', FOGVOL__GLW_ALL, 4, FOGVOL__GL_AT(clear_color), 0, {FOGVOL__GL_COLOR_CLEAR_VALUE}},
    {FOGVOL__GLV_BLEND_COLOR, 'f', FOGVOL__GLW_ALL, 4, FOGVOL__GL_AT(blend_color), 0, {FOGVOL__GL_BLEND_COLOR}},
    {FOGVOL__GLV_STENCIL_FUNC, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(st_func), FOGVOL__GL_FRONT,
     {FOGVOL__GL_STENCIL_FUNC, FOGVOL__GL_STENCIL_REF, FOGVOL__GL_STENCIL_VALUE_MASK}},
    {FOGVOL__GLV_STENCIL_OP, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(st_op), FOGVOL__GL_FRONT,
     {FOGVOL__GL_STENCIL_FAIL, FOGVOL__GL_STENCIL_PASS_DEPTH_FAIL, FOGVOL__GL_STENCIL_PASS_DEPTH_PASS}},
    {FOGVOL__GLV_STENCIL_MASK, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(st_wmask), FOGVOL__GL_FRONT,
     {FOGVOL__GL_STENCIL_WRITEMASK}},
    {FOGVOL__GLV_STENCIL_FUNC, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(stb_func), FOGVOL__GL_BACK,
     {FOGVOL__GL_STENCIL_BACK_FUNC, FOGVOL__GL_STENCIL_BACK_REF, FOGVOL__GL_STENCIL_BACK_VALUE_MASK}},
    {FOGVOL__GLV_STENCIL_OP, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(stb_op), FOGVOL__GL_BACK,
     {FOGVOL__GL_STENCIL_BACK_FAIL, FOGVOL__GL_STENCIL_BACK_PASS_DEPTH_FAIL, FOGVOL__GL_STENCIL_BACK_PASS_DEPTH_PASS}},
    {FOGVOL__GLV_STENCIL_MASK, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(stb_wmask), FOGVOL__GL_BACK,
     {FOGVOL__GL_STENCIL_BACK_WRITEMASK}},
    {FOGVOL__GLV_CLEAR_STENCIL, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(st_clear), 0, {FOGVOL__GL_STENCIL_CLEAR_VALUE}},
    {FOGVOL__GLV_CLAMP_COLOR, 'i', FOGVOL__GLW_CLAMP, 1, FOGVOL__GL_AT(clamp_fragment), 0,
     {FOGVOL__GL_CLAMP_FRAGMENT_COLOR}},
    {FOGVOL__GLV_PIXEL_STORE, 'i', FOGVOL__GLW_ALL, 1, FOGVOL__GL_AT(pixel_align), 4,
     {FOGVOL__GL_UNPACK_ALIGNMENT, FOGVOL__GL_PACK_ALIGNMENT}},
    {FOGVOL__GLV_PIXEL_STORE, 'i', FOGVOL__GLW_ROW_LENGTH, 1, FOGVOL__GL_AT(unpack_rows), 0,
     {FOGVOL__GL_UNPACK_ROW_LENGTH, FOGVOL__GL_UNPACK_SKIP_ROWS, FOGVOL__GL_UNPACK_SKIP_PIXELS}},
    {FOGVOL__GLV_PIXEL_STORE, 'i', FOGVOL__GLW_PACK_ROWS, 1, FOGVOL__GL_AT(pack_rows), 0,
     {FOGVOL__GL_PACK_ROW_LENGTH, FOGVOL__GL_PACK_SKIP_ROWS, FOGVOL__GL_PACK_SKIP_PIXELS}}};
#undef FOGVOL__GL_AT
#define FOGVOL__GL_N_VALUES (int)(sizeof fogvol__gl_values / sizeof fogvol__gl_values[0])

static void fogvol__gl_put(fogvol__gl *gl, const fogvol__gl_value_row *r, const void *p)
{
    const fogvol__GLint *v = (const fogvol__GLint *)p;
    const fogvol__GLboolean *b = (const fogvol__GLboolean *)p;
    const fogvol__GLfloat *f = (const fogvol__GLfloat *)p;
    int k;
    switch (r->put) {
    case FOGVOL__GLV_VIEWPORT: fogvol__gl_viewport(gl, v[0], v[1], v[2], v[3]); break;
    case FOGVOL__GLV_SCISSOR: fogvol__gl_scissor(gl, v[0], v[1], v[2], v[3]); break;
    case FOGVOL__GLV_CLAMP_COLOR: gl->ClampColor(FOGVOL__GL_CLAMP_FRAGMENT_COLOR, (fogvol__GLenum)v[0]); break;
    case FOGVOL__GLV_BLEND_FUNC:
        gl->BlendFuncSeparate((fogvol__GLenum)v[0], (fogvol__GLenum)v[1], (fogvol__GLenum)v[2], (fogvol__GLenum)v[3]);
        break;
    case FOGVOL__GLV_BLEND_EQ: /* (one equation for both: the advanced ones, KHR_blend_equation_advanced, */
        if (v[0] == v[1]) gl->BlendEquation((fogvol__GLenum)v[0]); /* which the Separate call refuses) */
        else gl->BlendEquationSeparate((fogvol__GLenum)v[0], (fogvol__GLenum)v[1]);
        break;
    case FOGVOL__GLV_DEPTH_FUNC: gl->DepthFunc((fogvol__GLenum)v[0]); break;
    case FOGVOL__GLV_CULL_FACE: gl->CullFace((fogvol__GLenum)v[0]); break;
    case FOGVOL__GLV_FRONT_FACE: gl->FrontFace((fogvol__GLenum)v[0]); break;
    case FOGVOL__GLV_POLYGON_MODE: /* core profiles accept only FRONT_AND_BACK; both entries hold the same mode */
        gl->PolygonMode(FOGVOL__GL_FRONT_AND_BACK, (fogvol__GLenum)v[0]);
        if (!gl->core && v[1] != v[0]) gl->PolygonMode(FOGVOL__GL_BACK, (fogvol__GLenum)v[1]);
        break;
    case FOGVOL__GLV_DEPTH_MASK: gl->DepthMask(b[0]); break;
    case FOGVOL__GLV_COLOR_MASK: gl->ColorMask(b[0], b[1], b[2], b[3]); break;
    case FOGVOL__GLV_CLEAR_COLOR: gl->ClearColor(f[0], f[1], f[2], f[3]); break;
    case FOGVOL__GLV_BLEND_COLOR: gl->BlendColor(f[0], f[1], f[2], f[3]); break;
    case FOGVOL__GLV_STENCIL_FUNC:
        gl->StencilFuncSeparate(r->arg, (fogvol__GLenum)v[0], v[1], (fogvol__GLuint)v[2]);
        break;
    case FOGVOL__GLV_STENCIL_OP:
        gl->StencilOpSeparate(r->arg, (fogvol__GLenum)v[0], (fogvol__GLenum)v[1], (fogvol__GLenum)v[2]);
        break;
    case FOGVOL__GLV_STENCIL_MASK: gl->StencilMaskSeparate(r->arg, (fogvol__GLuint)v[0]); break;
    case FOGVOL__GLV_CLEAR_STENCIL: gl->ClearStencil(v[0]); break;
    default:
        for (k = 0; k < 4 && r->names[k]; ++k) gl->PixelStorei(r->names[k], v[k]);
        break;
    }
}

/* Reads every row of both tables that the context has. */
static void fogvol__gl_save_tables(fogvol__gl *gl, fogvol__gl_state *s)
{
    int i, k;
    for (i = 0; i < FOGVOL__GL_N_VALUES; ++i) {
        const fogvol__gl_value_row *r = &fogvol__gl_values[i];
        void *p = (char *)s + r->offset;
        if (!fogvol__gl_has(gl, r->when, 0)) continue;
        for (k = 0; k < 4 && r->names[k]; ++k) {
            if (r->type == 'b') gl->GetBooleanv(r->names[k], (fogvol__GLboolean *)p + k * r->per);
            else if (r->type == 'f') gl->GetFloatv(r->names[k], (fogvol__GLfloat *)p + k * r->per);
            else gl->GetIntegerv(r->names[k], (fogvol__GLint *)p + k * r->per);
        }
    }
    for (i = 0; i < FOGVOL__GL_N_ENABLES; ++i)
        if (fogvol__gl_has(gl, fogvol__gl_enables[i].when, fogvol__gl_enables[i].cap))
            s->enabled[i] = gl->IsEnabled(fogvol__gl_enables[i].cap);
    s->scissor_enables = 0;
    for (i = 0; gl->ViewportIndexedf && i < gl->n_viewports; ++i)
        if (gl->IsEnabledi(FOGVOL__GL_SCISSOR_TEST, (fogvol__GLuint)i)) s->scissor_enables |= 1ul << i;
}

static void fogvol__gl_restore_tables(fogvol__gl *gl, const fogvol__gl_state *s)
{
    int i;
    for (i = 0; i < FOGVOL__GL_N_VALUES; ++i)
        if (fogvol__gl_has(gl, fogvol__gl_values[i].when, 0))
            fogvol__gl_put(gl, &fogvol__gl_values[i], (const char *)s + fogvol__gl_values[i].offset);
    for (i = 0; i < FOGVOL__GL_N_ENABLES; ++i)
        if (fogvol__gl_has(gl, fogvol__gl_enables[i].when, fogvol__gl_enables[i].cap))
            fogvol__gl_enable(gl, fogvol__gl_enables[i].cap, s->enabled[i]);
    for (i = 0; gl->ViewportIndexedf && i < gl->n_viewports; ++i) {
        if (s->scissor_enables >> i & 1ul) gl->Enablei(FOGVOL__GL_SCISSOR_TEST, (fogvol__GLuint)i);
        else gl->Disablei(FOGVOL__GL_SCISSOR_TEST, (fogvol__GLuint)i);
    }
}

/* Every pass: the capabilities marked OFF turned off (fogvol__gl_begin_pass sets the others). */
static void fogvol__gl_pass_enables(fogvol__gl *gl)
{
    int i;
    for (i = 0; i < FOGVOL__GL_N_ENABLES; ++i)
        if (fogvol__gl_enables[i].pass == FOGVOL__GLP_OFF &&
            fogvol__gl_has(gl, fogvol__gl_enables[i].when, fogvol__gl_enables[i].cap))
            fogvol__gl_enable(gl, fogvol__gl_enables[i].cap, 0);
    if (gl->ClampColor) gl->ClampColor(FOGVOL__GL_CLAMP_FRAGMENT_COLOR, 0); /* (signed sums, float targets) */
}

/* Multisample texture bindings of fogvol's units, multisampling and sample shading. */
static void fogvol__gl_save_msaa(fogvol__gl *gl, fogvol__gl_state *s)
{
    fogvol__GLint active = 0;
    int i;
    if (!gl->has_msaa) return;
    gl->GetIntegerv(FOGVOL__GL_ACTIVE_TEXTURE, &active);
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->GetIntegerv(FOGVOL__GL_TEXTURE_BINDING_2D_MULTISAMPLE, &s->tex2dms[i]);
    }
    gl->ActiveTexture((fogvol__GLenum)active);
    gl->GetFloatv(FOGVOL__GL_MIN_SAMPLE_SHADING_VALUE, &s->min_sample_shading); /* the enables: the table */
}

static void fogvol__gl_restore_msaa(fogvol__gl *gl, const fogvol__gl_state *s)
{
    int i;
    if (!gl->has_msaa) return;
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->BindTexture(FOGVOL__GL_TEXTURE_2D_MULTISAMPLE, (fogvol__GLuint)s->tex2dms[i]);
    }
    gl->ActiveTexture((fogvol__GLenum)s->active_texture);
    gl->MinSampleShading(s->min_sample_shading);
}

static fogvol__GLuint fogvol__gl_native(fogvol__gl *gl, fogvol__GLuint tex); /* (with the pass's program) */

/* A pass on multisampled targets: their textures on the multisample binding
   points, multisampling on and every sample shaded (per_sample 1; 2: shaded
   once per pixel, tested per sample); other passes shade once per pixel. An engine texture of a per-sample pass (its depth) is
   a multisample texture as well. */
static void fogvol__gl_sample_pass(fogvol__gl *gl, const fogvol_pass *p)
{
    int i;
    if (!gl->has_msaa) return;
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        const fogvol__gl_texture *t = (const fogvol__gl_texture *)p->textures[i];
        fogvol__GLuint tex = t && t->samples > 1 ? t->tex : 0;
        if (p->native_textures[i])
            tex = p->per_sample ? fogvol__gl_native(gl, (fogvol__GLuint)p->native_textures[i]) : 0;
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->BindTexture(FOGVOL__GL_TEXTURE_2D_MULTISAMPLE, tex);
    }
    fogvol__gl_enable(gl, FOGVOL__GL_SAMPLE_SHADING, p->per_sample == 1);
    if (p->per_sample) {
        gl->Enable(FOGVOL__GL_MULTISAMPLE);
        gl->MinSampleShading(1.0f);
    }
}

/* The engine FBO's draw-buffer list and the per-draw-buffer colour masks, blend enables, functions
   and equations (the module comment above FOGVOL__GL_ENABLES says why). */
static void fogvol__gl_save_draw_buffers(fogvol__gl *gl, fogvol__gl_state *s)
{
    int i;
    if (gl->max_draw_buffers > 0 && s->draw_fbo != 0)
        for (i = 0; i < gl->max_draw_buffers; ++i) {
            gl->GetIntegerv((fogvol__GLenum)(FOGVOL__GL_DRAW_BUFFER0 + i), &s->draw_buffers[i]);
            if (s->draw_buffers[i] != FOGVOL__GL_NONE) s->n_draw_buffers = i + 1;
        }
    s->n_indexed = gl->has_indexed_mask ? gl->max_draw_buffers : 0;
    for (i = 0; i < s->n_indexed; ++i) {
        if (gl->GetBooleani_v) {
            gl->GetBooleani_v(FOGVOL__GL_COLOR_WRITEMASK, (fogvol__GLuint)i, s->bi_mask[i]);
        } else { /* GLES 3.0 */
            fogvol__GLint m[4] = {1, 1, 1, 1}, k;
            gl->GetIntegeri_v(FOGVOL__GL_COLOR_WRITEMASK, (fogvol__GLuint)i, m);
            for (k = 0; k < 4; ++k) s->bi_mask[i][k] = (fogvol__GLboolean)(m[k] != 0);
        }
        s->bi_blend[i] = gl->IsEnabledi(FOGVOL__GL_BLEND, (fogvol__GLuint)i);
        if (!gl->has_indexed_blend) continue;
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_SRC_RGB, (fogvol__GLuint)i, &s->bi_src_rgb[i]);
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_DST_RGB, (fogvol__GLuint)i, &s->bi_dst_rgb[i]);
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_SRC_ALPHA, (fogvol__GLuint)i, &s->bi_src_a[i]);
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_DST_ALPHA, (fogvol__GLuint)i, &s->bi_dst_a[i]);
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_EQUATION_RGB, (fogvol__GLuint)i, &s->bi_eq_rgb[i]);
        gl->GetIntegeri_v(FOGVOL__GL_BLEND_EQUATION_ALPHA, (fogvol__GLuint)i, &s->bi_eq_a[i]);
    }
}

/* Runs last in fogvol__gl_restore: the engine framebuffer is bound again and the non-indexed blend
   state is back, so the per-buffer values go on top of it. */
static void fogvol__gl_restore_draw_buffers(fogvol__gl *gl, const fogvol__gl_state *s)
{
    int i;
    if (s->draw_buffers_set) {
        fogvol__GLenum bufs[FOGVOL__GL_MAX_DB];
        for (i = 0; i < s->n_draw_buffers; ++i) bufs[i] = (fogvol__GLenum)s->draw_buffers[i];
        gl->DrawBuffers(s->n_draw_buffers, bufs);
    }
    for (i = 0; i < s->n_indexed; ++i) {
        fogvol__GLuint u = (fogvol__GLuint)i;
        if (gl->has_indexed_blend) {
            gl->BlendFuncSeparatei(u, (fogvol__GLenum)s->bi_src_rgb[i], (fogvol__GLenum)s->bi_dst_rgb[i],
                                   (fogvol__GLenum)s->bi_src_a[i], (fogvol__GLenum)s->bi_dst_a[i]);
            if (s->bi_eq_rgb[i] == s->bi_eq_a[i]) gl->BlendEquationi(u, (fogvol__GLenum)s->bi_eq_rgb[i]);
            else gl->BlendEquationSeparatei(u, (fogvol__GLenum)s->bi_eq_rgb[i], (fogvol__GLenum)s->bi_eq_a[i]);
        }
        gl->ColorMaski(u, s->bi_mask[i][0], s->bi_mask[i][1], s->bi_mask[i][2], s->bi_mask[i][3]);
        if (s->bi_blend[i]) gl->Enablei(FOGVOL__GL_BLEND, u);
        else gl->Disablei(FOGVOL__GL_BLEND, u);
    }
}

/* The engine's pending GL errors. glGetError returns and clears them, so the first fogvol entry of a
   call (depth 0) reads them all, fogvol's own checks then see only fogvol's errors, and the last exit
   raises each again with a call that fails with exactly that code and changes no state. An active,
   unpaused transform feedback is paused over the same span (fogvol's draws must not be captured). */
static void fogvol__gl_host_enter(fogvol__gl *gl)
{
    fogvol__GLenum e;
    int i, k;
    if (gl->host_depth++ > 0) return;
    gl->host_n = 0;
    for (i = 0; i < 8 && (e = gl->GetError()) != FOGVOL__GL_NO_ERROR; ++i) { /* one flag per code at most */
        for (k = 0; k < gl->host_n && gl->host_errors[k] != e; ++k) {
        }
        if (k == gl->host_n && gl->host_n < 4) gl->host_errors[gl->host_n++] = e;
    }
    gl->tf_paused = 0;
    if (gl->has_tf_pause) {
        fogvol__GLboolean active = 0, paused = 0;
        gl->GetBooleanv(FOGVOL__GL_TRANSFORM_FEEDBACK_ACTIVE, &active);
        gl->GetBooleanv(FOGVOL__GL_TRANSFORM_FEEDBACK_PAUSED, &paused);
        if (active && !paused) {
            gl->PauseTransformFeedback();
            gl->tf_paused = 1;
        }
    }
}

static void fogvol__gl_raise(fogvol__gl *gl, fogvol__GLenum e)
{
    fogvol__GLint v = 0;
    fogvol__GLenum fb = gl->has_split_fbo ? FOGVOL__GL_DRAW_FRAMEBUFFER : FOGVOL__GL_FRAMEBUFFER;
    switch (e) {
    case FOGVOL__GL_INVALID_ENUM: gl->GetIntegerv(FOGVOL__GL_NONE, &v); break; /* no state is named 0 */
    case FOGVOL__GL_INVALID_VALUE: gl->Viewport(0, 0, -1, -1); break;          /* negative size */
    case FOGVOL__GL_INVALID_OPERATION: /* a shader object where a program object is expected */
        if (!gl->err_shader) gl->err_shader = gl->CreateShader(FOGVOL__GL_VERTEX_SHADER);
        gl->GetProgramiv(gl->err_shader, FOGVOL__GL_LINK_STATUS, &v);
        break;
    case FOGVOL__GL_INVALID_FRAMEBUFFER_OPERATION: /* clearing nothing through an FBO with no attachment */
        if (!gl->BindFramebuffer) break; /* (a context creation that failed before loading them) */
        gl->GetIntegerv(FOGVOL__GL_DRAW_FRAMEBUFFER_BINDING, &v);
        if (!gl->err_fbo) gl->GenFramebuffers(1, &gl->err_fbo);
        gl->BindFramebuffer(fb, gl->err_fbo);
        gl->Clear(0);
        gl->BindFramebuffer(fb, (fogvol__GLuint)v);
        break;
    default:
        fogvol__log(&gl->log, FOGVOL_LOG_WARNING,
                    "fogvol: the engine's pending GL error 0x%04x was read and cannot be raised again", e);
        break;
    }
}

/* fogvol's own GL errors, read while the engine's are held: the first becomes the public call's result
   (FOGVOL_ERROR_BACKEND, through the backend's take_error), logged. */
static void fogvol__gl_drain(fogvol__gl *gl)
{
    fogvol__GLenum first = gl->GetError();
    int more = 0;
    if (first == FOGVOL__GL_NO_ERROR) return;
    while (more < 8 && gl->GetError() != FOGVOL__GL_NO_ERROR) ++more; /* (a lost context repeats its code) */
    if (gl->own != FOGVOL_SUCCESS) return;
    gl->own = FOGVOL_ERROR_BACKEND;
    fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: GL error 0x%04x raised by fogvol's own GL calls (%d more after it)",
                first, more);
}

/* The last exit: fogvol's errors read, then the engine's raised again with GL_DEBUG_OUTPUT off where
   KHR_debug lets it be switched (the raising calls then reach no debug callback nor the message log;
   the enable is put back). */
static void fogvol__gl_host_leave(fogvol__gl *gl)
{
    int i, dbg;
    if (gl->host_depth <= 0 || --gl->host_depth > 0) return;
    if (gl->tf_paused) gl->ResumeTransformFeedback();
    gl->tf_paused = 0;
    fogvol__gl_drain(gl);
    dbg = gl->host_n > 0 && gl->has_debug_output && gl->IsEnabled(FOGVOL__GL_DEBUG_OUTPUT);
    if (dbg) gl->Disable(FOGVOL__GL_DEBUG_OUTPUT);
    for (i = 0; i < gl->host_n; ++i) fogvol__gl_raise(gl, gl->host_errors[i]);
    if (dbg) gl->Enable(FOGVOL__GL_DEBUG_OUTPUT);
    gl->host_n = 0;
}

/* Another GL context current than fogvol's: fogvol_gl_desc.current_context says so, or fogvol's own
   per-context object is not there (its full-screen vertex array object; without VAOs a framebuffer
   object made at creation; neither is shared between contexts). The first refusal of a call is
   logged and is its result (INVALID_STATE, through take_error); the entry then touches nothing. */
static int fogvol__gl_foreign(fogvol__gl *gl)
{
    int other = gl->current_context && gl->current_context(gl->user_data) != gl->context_id;
    if (!other && gl->has_vao) other = gl->fullscreen.vao && !gl->IsVertexArray(gl->fullscreen.vao);
    else if (!other) other = gl->err_fbo && !gl->IsFramebuffer(gl->err_fbo);
    if (other && gl->own == FOGVOL_SUCCESS) {
        gl->own = FOGVOL_ERROR_INVALID_STATE;
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: another GL context is current than the one fogvol was "
                                                "created in (its objects are not in it): nothing done; make "
                                                "fogvol's context current");
    }
    return other;
}

/* fogvol_backend.take_error */
static fogvol_result fogvol__gl_take_error(void *u)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol_result r = gl->own;
    gl->own = FOGVOL_SUCCESS;
    return r;
}

/* Vertex attribute 0 where there is no vertex array object to keep it. */
static void fogvol__gl_save_attrib0(fogvol__gl *gl, fogvol__gl_state *s)
{
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_ENABLED, &s->a0_enabled);
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_SIZE, &s->a0_size);
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_TYPE, &s->a0_type);
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_NORMALIZED, &s->a0_normalized);
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_STRIDE, &s->a0_stride);
    gl->GetVertexAttribiv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_BUFFER_BINDING, &s->a0_buffer);
    gl->GetVertexAttribPointerv(0, FOGVOL__GL_VERTEX_ATTRIB_ARRAY_POINTER, &s->a0_pointer);
}

static void fogvol__gl_restore_attrib0(fogvol__gl *gl, const fogvol__gl_state *s)
{
    gl->BindBuffer(FOGVOL__GL_ARRAY_BUFFER, (fogvol__GLuint)s->a0_buffer);
    gl->VertexAttribPointer(0, s->a0_size, (fogvol__GLenum)s->a0_type, (fogvol__GLboolean)s->a0_normalized,
                            s->a0_stride, s->a0_pointer);
    if (s->a0_enabled) gl->EnableVertexAttribArray(0);
    else gl->DisableVertexAttribArray(0);
    gl->BindBuffer(FOGVOL__GL_ELEMENT_ARRAY_BUFFER, (fogvol__GLuint)s->element_buffer);
}

/* Framebuffers, renderbuffer, program, vertex input, textures and samplers of fogvol's units, pixel
   buffers. */
static void fogvol__gl_save_bindings(fogvol__gl *gl, fogvol__gl_state *s)
{
    int i;
    gl->GetIntegerv(FOGVOL__GL_DRAW_FRAMEBUFFER_BINDING, &s->draw_fbo); /* == FRAMEBUFFER_BINDING */
    if (gl->has_split_fbo) gl->GetIntegerv(FOGVOL__GL_READ_FRAMEBUFFER_BINDING, &s->read_fbo);
    gl->GetIntegerv(FOGVOL__GL_RENDERBUFFER_BINDING, &s->renderbuffer);
    gl->GetIntegerv(FOGVOL__GL_CURRENT_PROGRAM, &s->program);
    s->program_deleted = 0;
    if (s->program) gl->GetProgramiv((fogvol__GLuint)s->program, FOGVOL__GL_DELETE_STATUS, &s->program_deleted);
    if (gl->has_vao) gl->GetIntegerv(FOGVOL__GL_VERTEX_ARRAY_BINDING, &s->vao);
    gl->GetIntegerv(FOGVOL__GL_ARRAY_BUFFER_BINDING, &s->array_buffer);
    gl->GetIntegerv(FOGVOL__GL_ELEMENT_ARRAY_BUFFER_BINDING, &s->element_buffer);
    if (!gl->has_vao) fogvol__gl_save_attrib0(gl, s);
    gl->GetIntegerv(FOGVOL__GL_ACTIVE_TEXTURE, &s->active_texture);
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->GetIntegerv(FOGVOL__GL_TEXTURE_BINDING_2D, &s->tex2d[i]);
        if (gl->has_sampler) gl->GetIntegerv(FOGVOL__GL_SAMPLER_BINDING, &s->sampler[i]);
    }
    gl->ActiveTexture((fogvol__GLenum)s->active_texture);
    if (gl->has_pixel_buffers) {
        gl->GetIntegerv(FOGVOL__GL_PIXEL_UNPACK_BUFFER_BINDING, &s->unpack_buffer);
        gl->GetIntegerv(FOGVOL__GL_PIXEL_PACK_BUFFER_BINDING, &s->pack_buffer);
    }
}

static void fogvol__gl_restore_bindings(fogvol__gl *gl, const fogvol__gl_state *s)
{
    int i;
    if (gl->has_split_fbo) {
        gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, (fogvol__GLuint)s->draw_fbo);
        gl->BindFramebuffer(FOGVOL__GL_READ_FRAMEBUFFER, (fogvol__GLuint)s->read_fbo);
    } else {
        gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, (fogvol__GLuint)s->draw_fbo);
    }
    gl->BindRenderbuffer(FOGVOL__GL_RENDERBUFFER, (fogvol__GLuint)s->renderbuffer);
    gl->UseProgram(s->program_deleted ? 0u : (fogvol__GLuint)s->program); /* (a freed name: INVALID_VALUE) */
    if (gl->has_vao) gl->BindVertexArray((fogvol__GLuint)s->vao); /* brings its element buffer back */
    else fogvol__gl_restore_attrib0(gl, s);
    gl->BindBuffer(FOGVOL__GL_ARRAY_BUFFER, (fogvol__GLuint)s->array_buffer);
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->BindTexture(FOGVOL__GL_TEXTURE_2D, (fogvol__GLuint)s->tex2d[i]);
        if (gl->has_sampler) gl->BindSampler((fogvol__GLuint)i, (fogvol__GLuint)s->sampler[i]);
    }
    gl->ActiveTexture((fogvol__GLenum)s->active_texture);
    if (gl->has_pixel_buffers) {
        gl->BindBuffer(FOGVOL__GL_PIXEL_UNPACK_BUFFER, (fogvol__GLuint)s->unpack_buffer);
        gl->BindBuffer(FOGVOL__GL_PIXEL_PACK_BUFFER, (fogvol__GLuint)s->pack_buffer);
    }
}

/* Depth clear value and depth range (double on desktop GL, so they come back exactly), clip control. */
static void fogvol__gl_save_depth(fogvol__gl *gl, fogvol__gl_state *s)
{
    if (gl->gles) {
        gl->GetFloatv(FOGVOL__GL_DEPTH_CLEAR_VALUE, &s->clear_depth);
        gl->GetFloatv(FOGVOL__GL_DEPTH_RANGE, s->depth_range);
    } else {
        gl->GetDoublev(FOGVOL__GL_DEPTH_CLEAR_VALUE, &s->clear_depth_d);
        gl->GetDoublev(FOGVOL__GL_DEPTH_RANGE, s->depth_range_d);
        s->depth_range[0] = (fogvol__GLfloat)s->depth_range_d[0];
        s->depth_range[1] = (fogvol__GLfloat)s->depth_range_d[1];
    }
    s->clip_origin = FOGVOL__GL_LOWER_LEFT;
    s->clip_depth = FOGVOL__GL_NEGATIVE_ONE_TO_ONE;
    if (gl->ClipControl) {
        gl->GetIntegerv(FOGVOL__GL_CLIP_ORIGIN, &s->clip_origin);
        gl->GetIntegerv(FOGVOL__GL_CLIP_DEPTH_MODE, &s->clip_depth);
    }
}

static void fogvol__gl_restore_depth(fogvol__gl *gl, const fogvol__gl_state *s)
{
    if (gl->gles) {
        gl->ClearDepthf(s->clear_depth);
        fogvol__gl_depth_range(gl, s->depth_range[0], s->depth_range[1]);
    } else {
        gl->ClearDepth(s->clear_depth_d);
        fogvol__gl_depth_range(gl, s->depth_range_d[0], s->depth_range_d[1]);
    }
    if (gl->ClipControl) gl->ClipControl((fogvol__GLenum)s->clip_origin, (fogvol__GLenum)s->clip_depth);
}

static void fogvol__gl_save(fogvol__gl *gl, fogvol__gl_state *s)
{
    memset(s, 0, sizeof *s);
    fogvol__gl_save_msaa(gl, s);
    fogvol__gl_save_bindings(gl, s);
    fogvol__gl_save_tables(gl, s);
    fogvol__gl_save_depth(gl, s);
    fogvol__gl_save_draw_buffers(gl, s); /* after the bindings: reads the engine FBO's list */
}

static void fogvol__gl_restore(fogvol__gl *gl, const fogvol__gl_state *s)
{
    fogvol__gl_restore_msaa(gl, s);
    fogvol__gl_restore_bindings(gl, s);
    fogvol__gl_restore_tables(gl, s);
    fogvol__gl_restore_depth(gl, s);
    fogvol__gl_restore_draw_buffers(gl, s);
}

/* Pixel-transfer state fogvol's uploads and read-backs assume: no pixel buffers, and the pixel-store
   rows of fogvol__gl_values at their arg values. */
static void fogvol__gl_pixel_defaults(fogvol__gl *gl)
{
    int i, k;
    if (gl->has_pixel_buffers) {
        gl->BindBuffer(FOGVOL__GL_PIXEL_UNPACK_BUFFER, 0);
        gl->BindBuffer(FOGVOL__GL_PIXEL_PACK_BUFFER, 0);
    }
    for (i = 0; i < FOGVOL__GL_N_VALUES; ++i) {
        const fogvol__gl_value_row *r = &fogvol__gl_values[i];
        if (r->put != FOGVOL__GLV_PIXEL_STORE || !fogvol__gl_has(gl, r->when, 0)) continue;
        for (k = 0; k < 4 && r->names[k]; ++k) gl->PixelStorei(r->names[k], (fogvol__GLint)r->arg);
    }
}

/* Resource entries called outside a frame save and restore the state they touch. */
static void fogvol__gl_enter(fogvol__gl *gl, fogvol__gl_state *s)
{
    fogvol__gl_host_enter(gl);
    if (!gl->in_frame) fogvol__gl_save(gl, s);
    fogvol__gl_pixel_defaults(gl);
}

static void fogvol__gl_leave(fogvol__gl *gl, const fogvol__gl_state *s)
{
    if (!gl->in_frame) fogvol__gl_restore(gl, s);
    fogvol__gl_host_leave(gl);
}

/* The engine draw buffer the composite writes: refused with a logged reason where GL cannot. */
static fogvol_result fogvol__gl_check_draw_buffer(fogvol__gl *gl, int k)
{
    const char *why = NULL;
    if (k > 0 && gl->saved.draw_fbo == 0) why = "the default framebuffer has one colour buffer";
    else if (k > 0 && gl->gles) why = "OpenGL ES can only write list position i to COLOR_ATTACHMENTi";
    else if (k >= (gl->max_draw_buffers > 0 ? gl->max_draw_buffers : 1)) why = "past GL_MAX_DRAW_BUFFERS";
    else if (gl->saved.draw_fbo != 0 && gl->max_draw_buffers > 0 && gl->saved.draw_buffers[k] == FOGVOL__GL_NONE)
        why = "the engine's draw buffer there is GL_NONE";
    if (!why) return FOGVOL_SUCCESS;
    fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: cannot composite into draw buffer %d: %s", k, why);
    return FOGVOL_ERROR_UNSUPPORTED;
}

static fogvol_result fogvol__gl_begin_frame(void *u, fogvol_frame_info *info)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol_result r;
    if (gl->in_frame) return FOGVOL_ERROR_INVALID_STATE;
    if (fogvol__gl_foreign(gl)) return FOGVOL_ERROR_INVALID_STATE;
    fogvol__gl_host_enter(gl);
    fogvol__gl_save(gl, &gl->saved);
    r = fogvol__gl_check_draw_buffer(gl, info->draw_buffer);
    if (r != FOGVOL_SUCCESS) {
        fogvol__gl_host_leave(gl);
        return r;
    }
    gl->in_frame = 1;
    fogvol__gl_pixel_defaults(gl);
    if (gl->has_msaa || gl->major >= 3) { /* of the engine's draw framebuffer, still bound (GL 3.0, GLES 3: */
        fogvol__GLint buffers = 0, samples = 0; /* multisample framebuffers without per-sample shading) */
        gl->GetIntegerv(FOGVOL__GL_SAMPLE_BUFFERS, &buffers);
        gl->GetIntegerv(FOGVOL__GL_SAMPLES, &samples);
        info->samples = buffers ? samples : 0;
    }
    /* the engine's depth conventions (for its depth texture); fogvol's passes use NDC z in
       [-1,1] and depth range (0,1) with the engine's clip origin, so its images line up
       with the engine's and the face orientation stays that of the NDC triangle */
    info->depth_zero_to_one = gl->saved.clip_depth == FOGVOL__GL_ZERO_TO_ONE;
    info->clip_upper_left = gl->saved.clip_origin == FOGVOL__GL_UPPER_LEFT;
    info->depth_range[0] = gl->saved.depth_range[0];
    info->depth_range[1] = gl->saved.depth_range[1];
    if (gl->ClipControl) gl->ClipControl((fogvol__GLenum)gl->saved.clip_origin, FOGVOL__GL_NEGATIVE_ONE_TO_ONE);
    fogvol__gl_depth_range(gl, 0.0, 1.0);
    return FOGVOL_SUCCESS;
}

static void fogvol__gl_end_frame(void *u)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    if (!gl->in_frame) return;
    fogvol__gl_restore(gl, &gl->saved);
    gl->in_frame = 0;
    gl->program = NULL;
    fogvol__gl_host_leave(gl);
}

static fogvol_result fogvol__gl_check(fogvol__gl *gl, const char *what)
{
    fogvol__GLenum e = gl->GetError();
    if (e == FOGVOL__GL_NO_ERROR) return FOGVOL_SUCCESS;
    while (gl->GetError() != FOGVOL__GL_NO_ERROR) {
    }
    fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: GL error 0x%04x in %s", e, what);
    return FOGVOL_ERROR_BACKEND;
}

/* A new 2D texture bound on the active unit: RGBA8 or R32F, filter, wrap, pixels (may be NULL). */
static fogvol__GLuint fogvol__gl_new_texture(fogvol__gl *gl, int w, int h, fogvol_format format, fogvol__GLint filter,
                                             fogvol__GLint wrap, const void *pixels)
{
    fogvol__GLuint tex = 0;
    gl->GenTextures(1, &tex);
    gl->BindTexture(FOGVOL__GL_TEXTURE_2D, tex);
    gl->TexParameteri(FOGVOL__GL_TEXTURE_2D, FOGVOL__GL_TEXTURE_MIN_FILTER, filter);
    gl->TexParameteri(FOGVOL__GL_TEXTURE_2D, FOGVOL__GL_TEXTURE_MAG_FILTER, filter);
    gl->TexParameteri(FOGVOL__GL_TEXTURE_2D, FOGVOL__GL_TEXTURE_WRAP_S, wrap);
    gl->TexParameteri(FOGVOL__GL_TEXTURE_2D, FOGVOL__GL_TEXTURE_WRAP_T, wrap);
    if (format == FOGVOL_FORMAT_R32F)
        gl->TexImage2D(FOGVOL__GL_TEXTURE_2D, 0, FOGVOL__GL_R32F, w, h, 0, FOGVOL__GL_RED, FOGVOL__GL_FLOAT, pixels);
    else if (format == FOGVOL_FORMAT_RGBA32F)
        gl->TexImage2D(FOGVOL__GL_TEXTURE_2D, 0, FOGVOL__GL_RGBA32F, w, h, 0, FOGVOL__GL_RGBA, FOGVOL__GL_FLOAT, pixels);
    else if (format == FOGVOL_FORMAT_RG32F)
        gl->TexImage2D(FOGVOL__GL_TEXTURE_2D, 0, FOGVOL__GL_RG32F, w, h, 0, FOGVOL__GL_RG, FOGVOL__GL_FLOAT, pixels);
    else
        gl->TexImage2D(FOGVOL__GL_TEXTURE_2D, 0, gl->gles && gl->major < 3 ? FOGVOL__GL_RGBA : FOGVOL__GL_RGBA8, w, h,
                       0, FOGVOL__GL_RGBA, FOGVOL__GL_UNSIGNED_BYTE, pixels);
    return tex;
}

/* The storage of multisample colour texture tex (RGBA8, R32F or RG32F), bound on the active unit. */
static void fogvol__gl_ms_storage(fogvol__gl *gl, fogvol__GLuint tex, fogvol_format format, int samples, int w, int h,
                                  int fixed)
{
    fogvol__GLenum f = format == FOGVOL_FORMAT_R32F    ? (fogvol__GLenum)FOGVOL__GL_R32F
                       : format == FOGVOL_FORMAT_RG32F ? (fogvol__GLenum)FOGVOL__GL_RG32F
                                                       : (fogvol__GLenum)FOGVOL__GL_RGBA8;
    gl->BindTexture(FOGVOL__GL_TEXTURE_2D_MULTISAMPLE, tex);
    gl->TexImage2DMultisample(FOGVOL__GL_TEXTURE_2D_MULTISAMPLE, samples, f, w, h, (fogvol__GLboolean)(fixed != 0));
}

/* A new multisample colour texture (RGBA8, R32F or RG32F, fixed sample locations) bound on the active unit. */
static fogvol__GLuint fogvol__gl_new_texture_ms(fogvol__gl *gl, const fogvol_target_desc *d)
{
    fogvol__GLuint tex = 0;
    gl->GenTextures(1, &tex);
    fogvol__gl_ms_storage(gl, tex, d->format, d->samples, d->width, d->height, 1);
    return tex;
}

static fogvol_result fogvol__gl_create_texture(void *u, const fogvol_texture_desc *d, fogvol_handle *out)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_state s;
    fogvol__GLuint tex = 0;
    fogvol__GLint filt = d->filter == FOGVOL_FILTER_LINEAR ? FOGVOL__GL_LINEAR : FOGVOL__GL_NEAREST;
    fogvol__GLint wrap = d->wrap == FOGVOL_WRAP_REPEAT ? FOGVOL__GL_REPEAT : FOGVOL__GL_CLAMP_TO_EDGE;
    fogvol__gl_texture *t;
    fogvol_result r;
    *out = 0;
    if (fogvol__gl_foreign(gl)) return FOGVOL_ERROR_INVALID_STATE;
    t = (fogvol__gl_texture *)fogvol__alloc(&gl->alloc, sizeof *t);
    if (!t) return FOGVOL_ERROR_OUT_OF_MEMORY;
    fogvol__gl_enter(gl, &s);
    fogvol__gl_drain(gl);
    gl->ActiveTexture(FOGVOL__GL_TEXTURE0);
    tex = fogvol__gl_new_texture(gl, d->width, d->height, FOGVOL_FORMAT_RGBA8, filt, wrap, d->pixels);
    r = fogvol__gl_check(gl, d->label ? d->label : "create_texture");
    if (r != FOGVOL_SUCCESS) gl->DeleteTextures(1, &tex);
    if (gl->in_frame) gl->BindTexture(FOGVOL__GL_TEXTURE_2D, 0);
    fogvol__gl_leave(gl, &s);
    if (r != FOGVOL_SUCCESS) {
        fogvol__free(&gl->alloc, t);
        return r;
    }
    t->tex = tex;
    t->samples = 0;
    *out = (fogvol_handle)t;
    return FOGVOL_SUCCESS;
}

static void fogvol__gl_destroy_texture(void *u, fogvol_handle h)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_texture *t = (fogvol__gl_texture *)h;
    if (!t) return;
    if (!fogvol__gl_foreign(gl)) gl->DeleteTextures(1, &t->tex); /* deleting unbinds; touches no other state */
    fogvol__free(&gl->alloc, t);
}

static void fogvol__gl_free_target(fogvol__gl *gl, fogvol__gl_target *t)
{
    if (!t) return;
    if (t->second) fogvol__gl_free_target(gl, t->second);
    if (!fogvol__gl_foreign(gl)) {
        gl->DeleteFramebuffers(1, &t->fbo);
        gl->DeleteTextures(1, &t->base.tex);
        if (t->owns_depth) gl->DeleteRenderbuffers(1, &t->depth);
    }
    fogvol__free(&gl->alloc, t);
}

/* WIDE: a second RGBA8 texture at attachment 1 of t's bound FBO, also a target of its own (own FBO,
   for reading it back); t->second stays NULL when out of memory. */
static void fogvol__gl_target_second(fogvol__gl *gl, fogvol__gl_target *t, const fogvol_target_desc *d)
{
    static const fogvol__GLenum bufs[2] = {FOGVOL__GL_COLOR_ATTACHMENT0, FOGVOL__GL_COLOR_ATTACHMENT0 + 1};
    fogvol__gl_target *t2 = (fogvol__gl_target *)fogvol__alloc(&gl->alloc, sizeof *t2);
    if (!t2) return;
    memset(t2, 0, sizeof *t2); /* no depth of its own, no second attachment */
    t2->width = d->width;
    t2->height = d->height;
    t2->format = d->format; /* WIDE: RGBA8; COLORS: RGBA32F */
    t2->base.tex = fogvol__gl_new_texture(gl, d->width, d->height, d->format, FOGVOL__GL_NEAREST,
                                          FOGVOL__GL_CLAMP_TO_EDGE, NULL);
    gl->GenFramebuffers(1, &t2->fbo); /* for reading it back */
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, t2->fbo);
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_COLOR_ATTACHMENT0, FOGVOL__GL_TEXTURE_2D,
                             t2->base.tex, 0);
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, t->fbo);
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_COLOR_ATTACHMENT0 + 1, FOGVOL__GL_TEXTURE_2D,
                             t2->base.tex, 0);
    gl->DrawBuffers(2, bufs); /* framebuffer state of our FBO */
    t->second = t2;
}

/* The depth renderbuffer of t's bound FBO: another target's (share_depth) or a new one. */
static void fogvol__gl_target_depth(fogvol__gl *gl, fogvol__gl_target *t, const fogvol_target_desc *d)
{
    if (d->share_depth) {
        t->depth = ((const fogvol__gl_target *)d->share_depth)->depth;
        gl->FramebufferRenderbuffer(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_DEPTH_ATTACHMENT, FOGVOL__GL_RENDERBUFFER,
                                    t->depth);
    } else if (d->depth) {
        t->owns_depth = 1;
        gl->GenRenderbuffers(1, &t->depth);
        gl->BindRenderbuffer(FOGVOL__GL_RENDERBUFFER, t->depth);
        if (t->base.samples)
            gl->RenderbufferStorageMultisample(FOGVOL__GL_RENDERBUFFER, d->samples, FOGVOL__GL_DEPTH_COMPONENT24,
                                               d->width, d->height);
        else
            gl->RenderbufferStorage(FOGVOL__GL_RENDERBUFFER,
                                    gl->gles && gl->major < 3 ? FOGVOL__GL_DEPTH_COMPONENT16 : FOGVOL__GL_DEPTH_COMPONENT24,
                                    d->width, d->height);
        gl->FramebufferRenderbuffer(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_DEPTH_ATTACHMENT, FOGVOL__GL_RENDERBUFFER,
                                    t->depth);
    }
}

static fogvol_result fogvol__gl_create_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_state s;
    fogvol__gl_target *t;
    fogvol__GLenum status;
    fogvol_result r;
    *out = 0;
    if (d->samples > 1 && (!gl->has_msaa || d->color_count == 2)) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %s: no %d-sample target%s on this context",
                    d->label ? d->label : "target", d->samples, d->color_count == 2 ? " with two attachments" : "");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (d->linear && (d->samples > 1 || d->format != FOGVOL_FORMAT_R32F || !gl->float_linear))
        return FOGVOL_ERROR_UNSUPPORTED; /* fogvol filters in the shader instead */
    t = (fogvol__gl_target *)fogvol__alloc(&gl->alloc, sizeof *t);
    if (!t) return FOGVOL_ERROR_OUT_OF_MEMORY;
    memset(t, 0, sizeof *t);
    t->width = d->width;
    t->height = d->height;
    t->format = d->format;
    fogvol__gl_enter(gl, &s);
    fogvol__gl_drain(gl);
    gl->ActiveTexture(FOGVOL__GL_TEXTURE0);
    if (d->samples > 1)
        t->base.tex = fogvol__gl_new_texture_ms(gl, d);
    else
        t->base.tex = fogvol__gl_new_texture(gl, d->width, d->height, d->format,
                                             d->linear ? FOGVOL__GL_LINEAR : FOGVOL__GL_NEAREST,
                                             FOGVOL__GL_CLAMP_TO_EDGE, NULL);
    t->base.samples = d->samples > 1 ? d->samples : 0;
    gl->GenFramebuffers(1, &t->fbo);
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, t->fbo);
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_COLOR_ATTACHMENT0,
                             t->base.samples ? (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D_MULTISAMPLE
                                             : (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D,
                             t->base.tex, 0);
    if (d->color_count == 2 && gl->DrawBuffers) fogvol__gl_target_second(gl, t, d);
    fogvol__gl_target_depth(gl, t, d);
    status = gl->CheckFramebufferStatus(FOGVOL__GL_FRAMEBUFFER);
    r = fogvol__gl_check(gl, d->label ? d->label : "create_target");
    if (r == FOGVOL_SUCCESS && d->color_count == 2 && !t->second) r = FOGVOL_ERROR_OUT_OF_MEMORY;
    if (r == FOGVOL_SUCCESS && status != FOGVOL__GL_FRAMEBUFFER_COMPLETE) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %s: framebuffer incomplete (0x%04x) at %dx%d",
                    d->label ? d->label : "target", status, d->width, d->height);
        r = FOGVOL_ERROR_FRAMEBUFFER;
    }
    if (r != FOGVOL_SUCCESS) {
        fogvol__gl_free_target(gl, t);
        t = NULL;
    }
    if (gl->in_frame) { /* the next pass rebinds what it needs; keep the saved renderbuffer binding */
        gl->BindRenderbuffer(FOGVOL__GL_RENDERBUFFER, (fogvol__GLuint)gl->saved.renderbuffer);
        gl->BindTexture(FOGVOL__GL_TEXTURE_2D, 0);
        if (gl->has_msaa) gl->BindTexture(FOGVOL__GL_TEXTURE_2D_MULTISAMPLE, 0);
    }
    fogvol__gl_leave(gl, &s);
    if (t) *out = (fogvol_handle)t;
    return r;
}

static void fogvol__gl_destroy_target(void *u, fogvol_handle h)
{
    fogvol__gl_free_target((fogvol__gl *)u, (fogvol__gl_target *)h);
}

static fogvol_handle fogvol__gl_target_attachment(void *u, fogvol_handle h, int index)
{
    const fogvol__gl_target *t = (const fogvol__gl_target *)h;
    (void)u;
    if (!t) return 0;
    return index == 0 ? h : index == 1 ? (fogvol_handle)t->second : 0;
}

static fogvol_native fogvol__gl_native_texture(void *u, fogvol_handle h)
{
    (void)u;
    return h ? (fogvol_native)((const fogvol__gl_texture *)h)->tex : 0;
}

static fogvol__GLuint fogvol__gl_shader(fogvol__gl *gl, fogvol__GLenum type, const char *const *src, int n,
                                        const char *label, fogvol_result *r)
{
    fogvol__GLint ok = 0, len = 0;
    fogvol__GLuint sh = gl->CreateShader(type);
    gl->ShaderSource(sh, n, src, NULL);
    gl->CompileShader(sh);
    gl->GetShaderiv(sh, FOGVOL__GL_COMPILE_STATUS, &ok);
    if (ok) return sh;
    gl->GetShaderiv(sh, FOGVOL__GL_INFO_LOG_LENGTH, &len);
    {
        char buf[1024];
        fogvol__GLsizei got = 0;
        buf[0] = 0;
        gl->GetShaderInfoLog(sh, (fogvol__GLsizei)sizeof buf, &got, buf);
        buf[sizeof buf - 1] = 0;
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %s %s shader (GLSL %s) failed to compile: %s", label,
                    type == FOGVOL__GL_VERTEX_SHADER ? "vertex" : "fragment", fogvol_dialect_name(gl->dialect), buf);
    }
    gl->DeleteShader(sh);
    *r = FOGVOL_ERROR_SHADER_COMPILE;
    return 0;
}

static fogvol_result fogvol__gl_create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_state s;
    fogvol__gl_program *p;
    fogvol__GLuint vs, fs;
    fogvol__GLint ok = 0;
    fogvol_result r = FOGVOL_SUCCESS;
    const char *label = d->label ? d->label : "program";
    int i;
    *out = 0;
    if (fogvol__gl_foreign(gl)) return FOGVOL_ERROR_INVALID_STATE;
    p = (fogvol__gl_program *)fogvol__alloc(&gl->alloc, sizeof *p);
    if (!p) return FOGVOL_ERROR_OUT_OF_MEMORY;
    memset(p, 0, sizeof *p);
    fogvol__gl_enter(gl, &s);
    fogvol__gl_drain(gl); /* (earlier calls' errors are theirs, not this program's) */
    vs = fogvol__gl_shader(gl, FOGVOL__GL_VERTEX_SHADER, d->vs, d->vs_count, label, &r);
    fs = r == FOGVOL_SUCCESS ? fogvol__gl_shader(gl, FOGVOL__GL_FRAGMENT_SHADER, d->fs, d->fs_count, label, &r) : 0;
    if (r == FOGVOL_SUCCESS) {
        p->id = gl->CreateProgram();
        gl->AttachShader(p->id, vs);
        gl->AttachShader(p->id, fs);
        gl->BindAttribLocation(p->id, 0, "fv_position");
        if (gl->BindFragDataLocation) gl->BindFragDataLocation(p->id, 0, "fv_frag"); /* WIDE outputs, 130/150 */
        gl->LinkProgram(p->id);
        gl->GetProgramiv(p->id, FOGVOL__GL_LINK_STATUS, &ok);
        if (!ok) {
            char buf[1024];
            fogvol__GLsizei got = 0;
            buf[0] = 0;
            gl->GetProgramInfoLog(p->id, (fogvol__GLsizei)sizeof buf, &got, buf);
            buf[sizeof buf - 1] = 0;
            fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %s failed to link: %s", label, buf);
            r = FOGVOL_ERROR_SHADER_LINK;
            gl->DeleteProgram(p->id);
        }
    }
    if (vs) gl->DeleteShader(vs);
    if (fs) gl->DeleteShader(fs);
    if (r == FOGVOL_SUCCESS) {
        gl->UseProgram(p->id);
        p->u_mvp = gl->GetUniformLocation(p->id, "fv_mvp");
        p->u_depth = gl->GetUniformLocation(p->id, "fv_depth");
        p->u_sign = gl->GetUniformLocation(p->id, "fv_sign");
        p->u_ext = gl->GetUniformLocation(p->id, "fv_ext");
        p->u_emit = gl->GetUniformLocation(p->id, "fv_emit");
        for (i = 0; i < FOGVOL_U_COUNT; ++i) p->u_vec[i] = gl->GetUniformLocation(p->id, fogvol_uniform_name((fogvol_uniform)i));
        for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i)
            if (d->samplers[i]) gl->Uniform1i(gl->GetUniformLocation(p->id, d->samplers[i]), i);
        r = fogvol__gl_check(gl, label);
        if (r != FOGVOL_SUCCESS) gl->DeleteProgram(p->id);
        if (gl->in_frame) gl->UseProgram(gl->program ? gl->program->id : 0);
    }
    fogvol__gl_leave(gl, &s);
    if (r != FOGVOL_SUCCESS) {
        fogvol__free(&gl->alloc, p);
        return r;
    }
    *out = (fogvol_handle)p;
    return FOGVOL_SUCCESS;
}

static void fogvol__gl_destroy_program(void *u, fogvol_handle h)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_program *p = (fogvol__gl_program *)h;
    if (!p) return;
    if (!fogvol__gl_foreign(gl)) gl->DeleteProgram(p->id); /* deferred while current: no state change */
    if (gl->program == p) gl->program = NULL;
    fogvol__free(&gl->alloc, p);
}

static void fogvol__gl_bind_mesh(fogvol__gl *gl, const fogvol__gl_mesh *m)
{
    if (gl->has_vao) {
        gl->BindVertexArray(m->vao);
    } else {
        gl->BindBuffer(FOGVOL__GL_ARRAY_BUFFER, m->vbo);
        gl->VertexAttribPointer(0, 3, FOGVOL__GL_FLOAT, 0, m->stride, (const void *)m->offset);
        gl->EnableVertexAttribArray(0);
        gl->BindBuffer(FOGVOL__GL_ELEMENT_ARRAY_BUFFER, m->ibo);
    }
}

/* Uploads the vertex bytes as the engine laid them out (stride, offset) and
   the indices (16-bit as given, or 32-bit narrowed to 16 where they fit). */
static fogvol_result fogvol__gl_upload(fogvol__gl *gl, fogvol__gl_mesh *m, const fogvol_mesh_data *d)
{
    fogvol__gl_state s;
    fogvol_result r;
    void *tmp = NULL;
    const uint32_t *idx = d->indices;
    const void *data = idx;
    size_t isz = 4, vbytes;
    int i, nv = d->vertex_count, ni = d->index_count;
    memset(m, 0, sizeof *m);
    m->count = ni;
    m->index_type = FOGVOL__GL_UNSIGNED_INT;
    m->stride = d->stride ? d->stride : 12;
    m->offset = (size_t)d->offset;
    vbytes = m->offset + (size_t)(nv - 1) * (size_t)m->stride + 12u;
    if (d->index_type == FOGVOL_INDEX_UINT16) {
        data = d->indices16;
        isz = 2;
        m->index_type = FOGVOL__GL_UNSIGNED_SHORT;
    } else if (idx && nv <= 65535) { /* 16-bit indices where they fit (GLES2 needs them) */
        uint16_t *s16 = (uint16_t *)fogvol__alloc(&gl->alloc, sizeof(uint16_t) * (size_t)ni);
        if (!s16) return FOGVOL_ERROR_OUT_OF_MEMORY;
        for (i = 0; i < ni; ++i) s16[i] = (uint16_t)idx[i];
        tmp = s16;
        data = s16;
        isz = 2;
        m->index_type = FOGVOL__GL_UNSIGNED_SHORT;
    } else if (idx && !gl->has_uint_index) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %d vertices need 32-bit indices, which this GLES2 lacks", nv);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    fogvol__gl_enter(gl, &s);
    fogvol__gl_drain(gl);
    if (gl->has_vao) {
        gl->GenVertexArrays(1, &m->vao);
        gl->BindVertexArray(m->vao);
    }
    gl->GenBuffers(1, &m->vbo);
    gl->BindBuffer(FOGVOL__GL_ARRAY_BUFFER, m->vbo);
    gl->BufferData(FOGVOL__GL_ARRAY_BUFFER, (fogvol__GLsizeiptr)vbytes, d->positions, FOGVOL__GL_STATIC_DRAW);
    if (data) {
        gl->GenBuffers(1, &m->ibo);
        gl->BindBuffer(FOGVOL__GL_ELEMENT_ARRAY_BUFFER, m->ibo);
        gl->BufferData(FOGVOL__GL_ELEMENT_ARRAY_BUFFER, (fogvol__GLsizeiptr)(isz * (size_t)ni), data,
                       FOGVOL__GL_STATIC_DRAW);
    }
    if (gl->has_vao) {
        gl->VertexAttribPointer(0, 3, FOGVOL__GL_FLOAT, 0, m->stride, (const void *)m->offset);
        gl->EnableVertexAttribArray(0);
    }
    r = fogvol__gl_check(gl, "create_mesh");
    if (r != FOGVOL_SUCCESS) {
        if (m->vao) gl->DeleteVertexArrays(1, &m->vao);
        if (m->vbo) gl->DeleteBuffers(1, &m->vbo);
        if (m->ibo) gl->DeleteBuffers(1, &m->ibo);
    }
    if (gl->in_frame) { /* restore the bindings the frame save knows about */
        if (gl->has_vao) gl->BindVertexArray((fogvol__GLuint)gl->saved.vao);
        else gl->BindBuffer(FOGVOL__GL_ELEMENT_ARRAY_BUFFER, (fogvol__GLuint)gl->saved.element_buffer);
        gl->BindBuffer(FOGVOL__GL_ARRAY_BUFFER, (fogvol__GLuint)gl->saved.array_buffer);
    }
    fogvol__gl_leave(gl, &s);
    fogvol__free(&gl->alloc, tmp);
    return r;
}

static void fogvol__gl_free_mesh(fogvol__gl *gl, fogvol__gl_mesh *m)
{
    if (m->vao) gl->DeleteVertexArrays(1, &m->vao);
    if (m->vbo) gl->DeleteBuffers(1, &m->vbo);
    if (m->ibo) gl->DeleteBuffers(1, &m->ibo);
}

static fogvol_result fogvol__gl_create_mesh(void *u, const fogvol_mesh_data *d, fogvol_handle *out)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_mesh *m;
    fogvol_result r;
    *out = 0;
    if (fogvol__gl_foreign(gl)) return FOGVOL_ERROR_INVALID_STATE;
    m = (fogvol__gl_mesh *)fogvol__alloc(&gl->alloc, sizeof *m);
    if (!m) return FOGVOL_ERROR_OUT_OF_MEMORY;
    r = fogvol__gl_upload(gl, m, d);
    if (r != FOGVOL_SUCCESS) {
        fogvol__free(&gl->alloc, m);
        return r;
    }
    *out = (fogvol_handle)m;
    return FOGVOL_SUCCESS;
}

static void fogvol__gl_destroy_mesh(void *u, fogvol_handle h)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_mesh *m = (fogvol__gl_mesh *)h;
    if (!m) return;
    if (!fogvol__gl_foreign(gl)) fogvol__gl_free_mesh(gl, m);
    fogvol__free(&gl->alloc, m);
}

/* Blending of a pass: off, sums (add, or dst - src), or the composite over the engine's colour. */
static void fogvol__gl_pass_blend(fogvol__gl *gl, const fogvol_pass *p)
{
    switch (p->blend) {
    case FOGVOL_PASS_BLEND_ADD:
    case FOGVOL_PASS_BLEND_SUBTRACT:
        gl->Enable(FOGVOL__GL_BLEND);
        gl->BlendFuncSeparate(FOGVOL__GL_ONE, FOGVOL__GL_ONE, FOGVOL__GL_ONE, FOGVOL__GL_ONE);
        break;
    case FOGVOL_PASS_BLEND_FOG:
    case FOGVOL_PASS_BLEND_LIGHT:
        gl->Enable(FOGVOL__GL_BLEND);
        if (p->blend_constant)
            gl->BlendColor(p->blend_color[0], p->blend_color[1], p->blend_color[2], p->blend_color[3]);
        gl->BlendFuncSeparate(p->blend_constant ? FOGVOL__GL_CONSTANT_COLOR : FOGVOL__GL_SRC_ALPHA,
                              p->blend == FOGVOL_PASS_BLEND_FOG ? FOGVOL__GL_ONE_MINUS_SRC_ALPHA : FOGVOL__GL_ONE,
                              p->alpha_coverage ? FOGVOL__GL_ONE : FOGVOL__GL_ZERO,
                              p->alpha_coverage ? FOGVOL__GL_ONE_MINUS_SRC_ALPHA : FOGVOL__GL_ONE);
        break;
    case FOGVOL_PASS_BLEND_MULTIPLY: /* scene * T per channel; coverage: dst.a * mean T */
        gl->Enable(FOGVOL__GL_BLEND);
        gl->BlendFuncSeparate(FOGVOL__GL_ZERO, FOGVOL__GL_SRC_COLOR, FOGVOL__GL_ZERO,
                              p->alpha_coverage ? FOGVOL__GL_SRC_ALPHA : FOGVOL__GL_ONE);
        break;
    case FOGVOL_PASS_BLEND_EMIT: /* + emission; coverage: + (1 - mean T) */
        gl->Enable(FOGVOL__GL_BLEND);
        gl->BlendFuncSeparate(FOGVOL__GL_ONE, FOGVOL__GL_ONE, p->alpha_coverage ? FOGVOL__GL_ONE : FOGVOL__GL_ZERO,
                              FOGVOL__GL_ONE);
        break;
    default: gl->Disable(FOGVOL__GL_BLEND); break;
    }
    if (p->blend == FOGVOL_PASS_BLEND_SUBTRACT) /* dst - src */
        gl->BlendEquationSeparate(FOGVOL__GL_FUNC_REVERSE_SUBTRACT, FOGVOL__GL_FUNC_REVERSE_SUBTRACT);
    else
        gl->BlendEquationSeparate(FOGVOL__GL_FUNC_ADD, FOGVOL__GL_FUNC_ADD);
}

/* The program of a pass with its uniforms, and its textures on fogvol's units. */
/* An engine texture of a pass (engine depth, post effect inputs): a name that is no texture of the
   current context is not bound (in a compatibility profile binding it would make an empty one) and
   the pass draws nothing; the call's result is INVALID_ARGUMENT, logged. */
static fogvol__GLuint fogvol__gl_native(fogvol__gl *gl, fogvol__GLuint tex)
{
    if (gl->IsTexture(tex)) return tex;
    gl->skip_draws = 1;
    if (gl->own == FOGVOL_SUCCESS) {
        gl->own = FOGVOL_ERROR_INVALID_ARGUMENT;
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: texture %u handed to fogvol (an engine depth, colour or "
                    "normal texture) is not a texture of the current GL context: its passes draw nothing", tex);
    }
    return 0;
}

/* After glBindTexture(GL_TEXTURE_2D, tex) of an engine texture: one of another target (a multisample
   texture outside a per-sample pass, a 3D or cube texture) is not bound, its GL error taken here (fogvol's
   own call), and the pass draws nothing rather than with the texture left on the unit. */
static void fogvol__gl_native_2d(fogvol__gl *gl, fogvol__GLuint tex)
{
    fogvol__GLint bound = 0;
    gl->GetIntegerv(FOGVOL__GL_TEXTURE_BINDING_2D, &bound);
    if ((fogvol__GLuint)bound == tex) return;
    (void)gl->GetError();
    gl->skip_draws = 1;
    if (gl->own == FOGVOL_SUCCESS) {
        gl->own = FOGVOL_ERROR_INVALID_ARGUMENT;
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: texture %u handed to fogvol is not a 2D texture (a "
                    "multisample one is read only by frames drawn per sample): its passes draw nothing", tex);
    }
}

static void fogvol__gl_pass_program(fogvol__gl *gl, const fogvol_pass *p)
{
    int i;
    gl->program = (fogvol__gl_program *)p->program;
    gl->UseProgram(gl->program ? gl->program->id : 0);
    if (gl->program)
        for (i = 0; i < FOGVOL_U_COUNT; ++i)
            if (gl->program->u_vec[i] >= 0) gl->Uniform4fv(gl->program->u_vec[i], 1, p->uniforms[i]);
    for (i = 0; i < FOGVOL_MAX_TEXTURE_UNITS; ++i) {
        /* texture and target handles both start with the texture name */
        fogvol__GLuint tex = p->textures[i] ? ((const fogvol__gl_texture *)p->textures[i])->tex : 0;
        if (p->textures[i] && ((const fogvol__gl_texture *)p->textures[i])->samples > 1) tex = 0; /* below */
        if (p->native_textures[i]) /* (per-sample passes: on the multisample binding, below) */
            tex = p->per_sample ? 0 : fogvol__gl_native(gl, (fogvol__GLuint)p->native_textures[i]);
        gl->ActiveTexture((fogvol__GLenum)(FOGVOL__GL_TEXTURE0 + i));
        gl->BindTexture(FOGVOL__GL_TEXTURE_2D, tex);
        if (p->native_textures[i] && tex) fogvol__gl_native_2d(gl, tex);
        if (gl->has_sampler) gl->BindSampler((fogvol__GLuint)i, p->native_textures[i] ? gl->native_sampler : 0);
    }
}

/* fogvol_pass.read_target: its texture at colour attachment 1 of t's FBO, in the draw buffers (the
   program reads it there), or nothing there; FBO state of our own FBO, changed only when it differs. */
static void fogvol__gl_attach_read(fogvol__gl *gl, fogvol__gl_target *t, const fogvol_pass *p)
{
    static const fogvol__GLenum bufs[2] = {FOGVOL__GL_COLOR_ATTACHMENT0, FOGVOL__GL_COLOR_ATTACHMENT0 + 1};
    fogvol__GLuint tex = p->read_target ? ((const fogvol__gl_target *)p->read_target)->base.tex : 0;
    if (!t || t->second || t->read_tex == tex) return; /* (WIDE's attachment 1 is its own) */
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_COLOR_ATTACHMENT0 + 1, FOGVOL__GL_TEXTURE_2D, tex, 0);
    gl->DrawBuffers(tex ? 2 : 1, bufs);
    t->read_tex = tex;
}

/* fogvol_pass.depth_texture: the engine's depth texture as t's depth buffer (FBO state of our own FBO,
   detached at end_pass; a multisample one on a multisampled t); a framebuffer it does not complete draws
   nothing (INVALID_ARGUMENT, logged). */
static void fogvol__gl_attach_depth(fogvol__gl *gl, fogvol__gl_target *t, const fogvol_pass *p)
{
    fogvol__GLuint tex = fogvol__gl_native(gl, (fogvol__GLuint)p->depth_texture);
    fogvol__GLenum target = t->base.samples > 1 ? (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D_MULTISAMPLE
                                                : (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D;
    if (tex && t->base.samples > 1) { /* the attachments' fixedsamplelocations must agree: the colour's follows */
        fogvol__GLint fixed = 1;
        gl->BindTexture(target, tex);
        gl->GetTexLevelParameteriv(target, 0, FOGVOL__GL_TEXTURE_FIXED_SAMPLE_LOCATIONS, &fixed);
        if ((fixed == 0) != t->unfixed) {
            fogvol__gl_ms_storage(gl, t->base.tex, t->format, t->base.samples, t->width, t->height, fixed != 0);
            t->unfixed = fixed == 0;
        }
        gl->BindTexture(target, 0);
    }
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_DEPTH_ATTACHMENT, target, tex, 0);
    gl->depth_attached = t->fbo;
    gl->depth_attached_target = target;
    if (!tex || gl->CheckFramebufferStatus(FOGVOL__GL_FRAMEBUFFER) == FOGVOL__GL_FRAMEBUFFER_COMPLETE) return;
    gl->skip_draws = 1;
    if (gl->own == FOGVOL_SUCCESS) {
        gl->own = FOGVOL_ERROR_INVALID_ARGUMENT;
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: engine depth texture %u cannot be a depth buffer (not a "
                    "2D depth texture of the target's samples?): the depth-tested face pass draws nothing", tex);
    }
}

static void fogvol__gl_end_pass(void *u)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    if (!gl->depth_attached) return;
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, gl->depth_attached);
    gl->FramebufferTexture2D(FOGVOL__GL_FRAMEBUFFER, FOGVOL__GL_DEPTH_ATTACHMENT, gl->depth_attached_target, 0, 0);
    gl->depth_attached = 0;
}

static void fogvol__gl_begin_pass(void *u, const fogvol_pass *p)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__gl_target *t = (fogvol__gl_target *)p->target;
    gl->skip_draws = 0;
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, t ? t->fbo : (fogvol__GLuint)gl->saved.draw_fbo);
    fogvol__gl_attach_read(gl, t, p);
    if (t && p->depth_texture) fogvol__gl_attach_depth(gl, t, p);
    fogvol__gl_viewport(gl, p->viewport[0], p->viewport[1], p->viewport[2], p->viewport[3]);
    fogvol__gl_pass_enables(gl);
    if (!gl->gles) gl->PolygonMode(FOGVOL__GL_FRONT_AND_BACK, FOGVOL__GL_FILL);
    if (!t && (gl->saved.n_draw_buffers > 1 || p->draw_buffer > 0)) { /* only the named engine buffer */
        fogvol__GLenum buf = (fogvol__GLenum)gl->saved.draw_buffers[p->draw_buffer];
        gl->DrawBuffers(1, &buf);
        gl->saved.draw_buffers_set = 1;
    }
    if (p->scissor[2] > 0 && p->scissor[3] > 0) {
        fogvol__gl_enable(gl, FOGVOL__GL_SCISSOR_TEST, 1);
        fogvol__gl_scissor(gl, p->scissor[0], p->scissor[1], p->scissor[2], p->scissor[3]);
    }
    gl->ColorMask(1, 1, 1, 1);
    if (p->read_target && t) gl->ColorMaski(1, 0, 0, 0, 0); /* read, never written (nor cleared) */
    if (p->clear) {
        fogvol__GLbitfield bits = FOGVOL__GL_COLOR_BUFFER_BIT;
        gl->ClearColor(p->clear_color[0], p->clear_color[1], p->clear_color[2], p->clear_color[3]);
        if (t && t->owns_depth) {
            gl->DepthMask(1);
            if (gl->gles) gl->ClearDepthf(1.0f);
            else gl->ClearDepth(1.0);
            bits |= FOGVOL__GL_DEPTH_BUFFER_BIT;
        }
        gl->Clear(bits);
    }
    fogvol__gl_pass_blend(gl, p);
    if (p->cull == FOGVOL_CULL_NONE) {
        gl->Disable(FOGVOL__GL_CULL_FACE);
    } else {
        gl->Enable(FOGVOL__GL_CULL_FACE);
        gl->CullFace(p->cull == FOGVOL_CULL_FRONT ? FOGVOL__GL_FRONT : FOGVOL__GL_BACK);
    }
    gl->FrontFace(FOGVOL__GL_CCW);
    fogvol__gl_enable(gl, FOGVOL__GL_DEPTH_TEST, p->depth_test);
    gl->DepthFunc(p->depth_greater ? (fogvol__GLenum)FOGVOL__GL_GREATER : (fogvol__GLenum)FOGVOL__GL_LESS);
    gl->DepthMask((fogvol__GLboolean)(p->depth_write != 0));
    gl->Disable(FOGVOL__GL_STENCIL_TEST); /* the engine's stencil buffer is its own */
    fogvol__gl_pass_program(gl, p);
    fogvol__gl_sample_pass(gl, p);
}

static void fogvol__gl_set_draw(void *u, const fogvol_draw *d)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    if (!gl->program) return;
    if (gl->program->u_mvp >= 0) gl->UniformMatrix4fv(gl->program->u_mvp, 1, 0, d->mvp);
    if (gl->program->u_depth >= 0) gl->Uniform4fv(gl->program->u_depth, 1, d->depth);
    if (gl->program->u_sign >= 0) gl->Uniform1f(gl->program->u_sign, d->sign);
    if (gl->program->u_ext >= 0) gl->Uniform4fv(gl->program->u_ext, 1, d->extinction);
    if (gl->program->u_emit >= 0) gl->Uniform4fv(gl->program->u_emit, 1, d->emission);
    gl->FrontFace(d->front_cw ? FOGVOL__GL_CW : FOGVOL__GL_CCW);
}

static void fogvol__gl_draw_mesh(void *u, fogvol_handle h, const fogvol_draw *d)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    const fogvol__gl_mesh *m = (const fogvol__gl_mesh *)h;
    if (!m || gl->skip_draws) return;
    fogvol__gl_set_draw(u, d);
    fogvol__gl_bind_mesh(gl, m);
    gl->DrawElements(FOGVOL__GL_TRIANGLES, m->count, m->index_type, NULL);
}

static void fogvol__gl_draw_fullscreen(void *u)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    if (gl->skip_draws) return;
    fogvol__gl_bind_mesh(gl, &gl->fullscreen);
    gl->DrawArrays(FOGVOL__GL_TRIANGLES, 0, 3);
}

/* The depth texture format that blits from the read framebuffer's depth
   buffer (same depth bits and type, with the stencil of a packed buffer);
   0 when there is no depth buffer or no such texture format. */
static fogvol__GLenum fogvol__gl_depth_format(fogvol__gl *gl, int default_fb)
{
    fogvol__GLint type = 0, bits = 0, stencil = 0, ctype = 0, dname = 0, sname = 0, stype = 0;
    fogvol__GLenum datt = default_fb ? FOGVOL__GL_DEPTH : FOGVOL__GL_DEPTH_ATTACHMENT;
    fogvol__GLenum satt = default_fb ? FOGVOL__GL_STENCIL : FOGVOL__GL_STENCIL_ATTACHMENT;
    gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, datt,
                                            FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    if (type == FOGVOL__GL_NONE) return 0;
    gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, datt,
                                            FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
    gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, datt,
                                            FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &ctype);
    gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, satt,
                                            FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &stype);
    if (stype != FOGVOL__GL_NONE) {
        gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, satt,
                                                FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, &stencil);
        if (!default_fb) { /* a separate stencil buffer is not part of the depth format */
            gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, datt,
                                                    FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &dname);
            gl->GetFramebufferAttachmentParameteriv(FOGVOL__GL_READ_FRAMEBUFFER, satt,
                                                    FOGVOL__GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &sname);
            if (dname != sname || type != stype) stencil = 0;
        }
    }
    if (ctype == FOGVOL__GL_FLOAT)
        return bits != 32 ? 0 : stencil ? FOGVOL__GL_DEPTH32F_STENCIL8 : FOGVOL__GL_DEPTH_COMPONENT32F;
    if (stencil) return bits == 24 ? FOGVOL__GL_DEPTH24_STENCIL8 : 0;
    if (bits == 16) return FOGVOL__GL_DEPTH_COMPONENT16;
    if (bits == 24) return FOGVOL__GL_DEPTH_COMPONENT24;
    return bits == 32 && !gl->gles ? FOGVOL__GL_DEPTH_COMPONENT32 : 0;
}

/* The copy texture and its framebuffer deleted: the next copy makes them again. */
static void fogvol__gl_depth_release(fogvol__gl *gl)
{
    if (gl->depth_fbo) gl->DeleteFramebuffers(1, &gl->depth_fbo);
    if (gl->depth_tex) gl->DeleteTextures(1, &gl->depth_tex);
    gl->depth_fbo = gl->depth_tex = 0;
    gl->depth_w = gl->depth_h = gl->depth_samples = 0;
}

/* The copy texture and its framebuffer for a format, size and sample count (0: single-sample),
   recreated only when the format or samples differ or it is too small (it keeps the engine's
   texel coordinates, so the views of a split screen share one); leaves the draw framebuffer alone. */
static void fogvol__gl_depth_target(fogvol__gl *gl, fogvol__GLenum format, int w, int h, int samples)
{
    static const fogvol__GLenum none = FOGVOL__GL_NONE;
    int packed = format == FOGVOL__GL_DEPTH24_STENCIL8 || format == FOGVOL__GL_DEPTH32F_STENCIL8;
    fogvol__GLenum target = samples ? (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D_MULTISAMPLE
                                    : (fogvol__GLenum)FOGVOL__GL_TEXTURE_2D;
    fogvol__GLenum type = format == FOGVOL__GL_DEPTH_COMPONENT16 ? FOGVOL__GL_UNSIGNED_SHORT
                          : format == FOGVOL__GL_DEPTH24_STENCIL8 ? FOGVOL__GL_UNSIGNED_INT_24_8
                          : format == FOGVOL__GL_DEPTH32F_STENCIL8 ? FOGVOL__GL_FLOAT_32_UNSIGNED_INT_24_8_REV
                          : format == FOGVOL__GL_DEPTH_COMPONENT32F ? FOGVOL__GL_FLOAT
                                                                    : FOGVOL__GL_UNSIGNED_INT;
    fogvol__GLuint fbo = 0;
    if (gl->depth_tex && gl->depth_format == format && gl->depth_samples == samples) {
        if (gl->depth_w >= w && gl->depth_h >= h) return;
        w = w > gl->depth_w ? w : gl->depth_w; /* grow only: views of other sizes keep fitting */
        h = h > gl->depth_h ? h : gl->depth_h;
    }
    fogvol__gl_depth_release(gl);
    gl->GetIntegerv(FOGVOL__GL_DRAW_FRAMEBUFFER_BINDING, (fogvol__GLint *)&fbo);
    gl->GenTextures(1, &gl->depth_tex);
    gl->ActiveTexture(FOGVOL__GL_TEXTURE0);
    gl->BindTexture(target, gl->depth_tex);
    if (samples) {
        gl->TexImage2DMultisample(target, samples, format, w, h, 1);
    } else {
        gl->TexParameteri(target, FOGVOL__GL_TEXTURE_MIN_FILTER, FOGVOL__GL_NEAREST);
        gl->TexParameteri(target, FOGVOL__GL_TEXTURE_MAG_FILTER, FOGVOL__GL_NEAREST);
        gl->TexImage2D(target, 0, (fogvol__GLint)format, w, h, 0,
                       packed ? FOGVOL__GL_DEPTH_STENCIL : FOGVOL__GL_DEPTH_COMPONENT, type, NULL);
    }
    gl->BindTexture(target, 0);
    gl->GenFramebuffers(1, &gl->depth_fbo);
    gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, gl->depth_fbo);
    gl->FramebufferTexture2D(FOGVOL__GL_DRAW_FRAMEBUFFER,
                             packed ? FOGVOL__GL_DEPTH_STENCIL_ATTACHMENT : FOGVOL__GL_DEPTH_ATTACHMENT, target,
                             gl->depth_tex, 0);
    gl->DrawBuffers(1, &none); /* depth only (framebuffer state of our own FBO) */
    gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, fbo);
    gl->depth_format = format;
    gl->depth_samples = samples;
    gl->depth_w = w;
    gl->depth_h = h;
}

/* The samples per pixel of framebuffer fb (0: single-sample); leaves fb bound for drawing. */
static int fogvol__gl_fb_samples(fogvol__gl *gl, fogvol__GLuint fb)
{
    fogvol__GLint buffers = 0, samples = 0;
    if (!gl->has_msaa) return 0;
    gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, fb);
    gl->GetIntegerv(FOGVOL__GL_SAMPLE_BUFFERS, &buffers);
    gl->GetIntegerv(FOGVOL__GL_SAMPLES, &samples);
    return buffers ? samples : 0;
}

/* Why the depth of a framebuffer of src samples cannot be copied with samples samples, or NULL. */
static const char *fogvol__gl_copy_refusal(const fogvol__gl *gl, int src, int samples)
{
    if (samples && !gl->has_msaa) return "a per-sample copy needs multisample textures (GL 3.2)";
    if (samples && src > 1 && src != samples)
        return "its sample count differs from the engine framebuffer's drawn per sample (GL cannot blit it)";
    if (samples && src <= 1 && gl->gles)
        return "OpenGL ES cannot blit a single-sample depth buffer into a multisampled one";
    return NULL;
}

static fogvol_result fogvol__gl_copy_depth(void *u, fogvol_native framebuffer, int bound, const int rect[4], int samples,
                                           fogvol_native *texture)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__GLuint src = bound ? (fogvol__GLuint)gl->saved.draw_fbo : (fogvol__GLuint)framebuffer;
    fogvol__GLenum format;
    fogvol_result r;
    const char *why;
    int x1 = rect[0] + rect[2], y1 = rect[1] + rect[3], src_samples;
    *texture = 0;
    if (!gl->in_frame || !gl->BlitFramebuffer || !gl->has_split_fbo || !gl->DrawBuffers) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: copying a depth buffer needs glBlitFramebuffer "
                                                "(GL 3.0, GLES 3.0 or ARB_framebuffer_object)");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    if (rect[0] < 0 || rect[1] < 0) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: copy_depth: viewport origin (%d, %d) is negative", rect[0],
                    rect[1]);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (src && !gl->IsFramebuffer(src)) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: engine_depth_framebuffer %u is not a framebuffer of the "
                                                "current GL context", src);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    fogvol__gl_drain(gl);
    src_samples = fogvol__gl_fb_samples(gl, src);
    if ((why = fogvol__gl_copy_refusal(gl, src_samples, samples > 1 ? samples : 0)) != NULL) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: copy_depth of framebuffer %u (%d samples): %s", src,
                    src_samples, why);
        return src_samples > 1 && samples > 1 ? FOGVOL_ERROR_INVALID_ARGUMENT : FOGVOL_ERROR_UNSUPPORTED;
    }
    gl->BindFramebuffer(FOGVOL__GL_READ_FRAMEBUFFER, src);
    format = fogvol__gl_depth_format(gl, src == 0);
    if (!format) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR,
                    "fogvol: framebuffer %u has no depth buffer, or one whose format no depth texture matches", src);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    fogvol__gl_depth_target(gl, format, x1, y1, samples > 1 ? samples : 0);
    gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, gl->depth_fbo); /* every copy names its destination */
    fogvol__gl_enable(gl, FOGVOL__GL_SCISSOR_TEST, 0);
    if (gl->has_discard) gl->Disable(FOGVOL__GL_RASTERIZER_DISCARD);
    /* the same rectangle on both sides: required to resolve a multisampled source */
    gl->BlitFramebuffer(rect[0], rect[1], x1, y1, rect[0], rect[1], x1, y1, FOGVOL__GL_DEPTH_BUFFER_BIT,
                        FOGVOL__GL_NEAREST);
    gl->BindFramebuffer(FOGVOL__GL_READ_FRAMEBUFFER, (fogvol__GLuint)gl->saved.read_fbo);
    gl->BindFramebuffer(FOGVOL__GL_DRAW_FRAMEBUFFER, (fogvol__GLuint)gl->saved.draw_fbo);
    r = fogvol__gl_check(gl, "copy_depth (glBlitFramebuffer of the engine's depth)");
    if (r == FOGVOL_SUCCESS) *texture = gl->depth_tex;
    else fogvol__gl_depth_release(gl); /* (a texture the GL refused, e.g. too large: not kept for later frames) */
    return r;
}

static fogvol_result fogvol__gl_read_target(void *u, fogvol_handle h, unsigned char *rgba, size_t size)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    const fogvol__gl_target *t = (const fogvol__gl_target *)h;
    fogvol__gl_state s;
    fogvol_result r;
    if (!t || !rgba || size < (size_t)t->width * (size_t)t->height * (t->format == FOGVOL_FORMAT_RGBA32F ? 16u : 4u))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (t->base.samples) return FOGVOL_ERROR_UNSUPPORTED; /* a multisample texture has no single value per pixel */
    fogvol__gl_enter(gl, &s);
    fogvol__gl_drain(gl);
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, t->fbo);
    if (t->format == FOGVOL_FORMAT_R32F)
        gl->ReadPixels(0, 0, t->width, t->height, FOGVOL__GL_RED, FOGVOL__GL_FLOAT, rgba);
    else if (t->format == FOGVOL_FORMAT_RGBA32F)
        gl->ReadPixels(0, 0, t->width, t->height, FOGVOL__GL_RGBA, FOGVOL__GL_FLOAT, rgba);
    else
        gl->ReadPixels(0, 0, t->width, t->height, FOGVOL__GL_RGBA, FOGVOL__GL_UNSIGNED_BYTE, rgba);
    r = fogvol__gl_check(gl, "read_target");
    fogvol__gl_leave(gl, &s);
    return r;
}

/* Occlusion queries (names as handles): SAMPLES_PASSED, or on GLES 3 ANY_SAMPLES_PASSED (0 or 1). */
static fogvol_result fogvol__gl_create_query(void *u, fogvol_handle *out)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__GLuint id = 0;
    if (fogvol__gl_foreign(gl)) return FOGVOL_ERROR_INVALID_STATE;
    gl->GenQueries(1, &id); /* names only: no state */
    *out = (fogvol_handle)id;
    return id ? FOGVOL_SUCCESS : FOGVOL_ERROR_BACKEND;
}

static void fogvol__gl_destroy_query(void *u, fogvol_handle q)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__GLuint id = (fogvol__GLuint)q;
    if (!fogvol__gl_foreign(gl)) gl->DeleteQueries(1, &id);
}

/* Not while the engine has an occlusion query running: BeginQuery would fail (and add its error to
   the engine's), and the engine's count would include fogvol's pixels. */
static int fogvol__gl_begin_query(void *u, fogvol_handle q)
{
    static const fogvol__GLenum kinds[3] = {FOGVOL__GL_SAMPLES_PASSED, FOGVOL__GL_ANY_SAMPLES_PASSED,
                                            FOGVOL__GL_ANY_SAMPLES_PASSED_CONSERVATIVE};
    fogvol__gl *gl = (fogvol__gl *)u;
    int i, first = gl->gles ? 1 : 0, n;
    n = gl->gles || gl->major > 4 || (gl->major == 4 && gl->minor >= 3) ? 3
        : gl->major > 3 || (gl->major == 3 && gl->minor >= 3)          ? 2
                                                                        : 1;
    for (i = first; i < n; ++i) {
        fogvol__GLint cur = 0;
        gl->GetQueryiv(kinds[i], FOGVOL__GL_CURRENT_QUERY, &cur);
        if (cur) return 0;
    }
    gl->BeginQuery(gl->gles ? FOGVOL__GL_ANY_SAMPLES_PASSED : FOGVOL__GL_SAMPLES_PASSED, (fogvol__GLuint)q);
    return 1;
}

static void fogvol__gl_end_query(void *u, fogvol_handle q)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    (void)q;
    gl->EndQuery(gl->gles ? FOGVOL__GL_ANY_SAMPLES_PASSED : FOGVOL__GL_SAMPLES_PASSED);
}

static int fogvol__gl_query_result(void *u, fogvol_handle q, uint64_t *samples)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol__GLuint avail = 0, v = 0;
    gl->GetQueryObjectuiv((fogvol__GLuint)q, FOGVOL__GL_QUERY_RESULT_AVAILABLE, &avail);
    if (!avail) return 0; /* never wait for the GPU */
    gl->GetQueryObjectuiv((fogvol__GLuint)q, FOGVOL__GL_QUERY_RESULT, &v);
    *samples = v;
    return 1;
}

static void fogvol__gl_destroy(void *u)
{
    fogvol__gl *gl = (fogvol__gl *)u;
    fogvol_allocator a;
    if (!gl) return;
    if (!fogvol__gl_foreign(gl)) {
        fogvol__gl_free_mesh(gl, &gl->fullscreen);
        if (gl->native_sampler) gl->DeleteSamplers(1, &gl->native_sampler);
        if (gl->err_shader) gl->DeleteShader(gl->err_shader);
        if (gl->err_fbo) gl->DeleteFramebuffers(1, &gl->err_fbo); /* never left bound: no binding changes */
        fogvol__gl_depth_release(gl);
    }
    a = gl->alloc;
    fogvol__free(&a, gl);
}

static int fogvol__gl_has_ext3(fogvol__gl *gl, const char *name)
{
    fogvol__GLint n = 0, i;
    gl->GetIntegerv(FOGVOL__GL_NUM_EXTENSIONS, &n);
    for (i = 0; i < n; ++i) {
        const char *e = (const char *)gl->GetStringi(FOGVOL__GL_EXTENSIONS, (fogvol__GLuint)i);
        if (e && strcmp(e, name) == 0) return 1;
    }
    return 0;
}

/* What the context can do (ext: the GL 2 / GLES 2 extension string or NULL). */
static unsigned fogvol__gl_caps(fogvol__gl *gl, const char *ext)
{
    unsigned caps = FOGVOL_CAP_BLEND_CONSTANT; /* glBlendColor: GL 1.4, GLES 2 */
    if (gl->gles) {
        fogvol__GLint range[2] = {0, 0}, precision = 0;
        gl->GetShaderPrecisionFormat(FOGVOL__GL_FRAGMENT_SHADER, FOGVOL__GL_HIGH_FLOAT, range, &precision);
        if (precision > 0) caps |= FOGVOL_CAP_HIGHP_FRAGMENT;
        if (gl->major >= 3) {
            caps |= FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE;
            if (fogvol__gl_has_ext3(gl, "GL_EXT_color_buffer_float")) {
                if (fogvol__gl_has_ext3(gl, "GL_EXT_float_blend")) caps |= FOGVOL_CAP_FLOAT_BLEND;
                if (gl->mrt_highp) caps |= FOGVOL_CAP_FLOAT_TARGET; /* (fogvol_gl_desc.mrt_highp) */
            }
            gl->float_linear = fogvol__gl_has_ext3(gl, "GL_OES_texture_float_linear");
            if (gl->float_linear) caps |= FOGVOL_CAP_FILTER_FLOAT;
        } else if (fogvol__has_ext(ext, "GL_OES_depth_texture") || fogvol__has_ext(ext, "GL_WEBGL_depth_texture") ||
                   fogvol__has_ext(ext, "WEBGL_depth_texture")) { /* (WebGL 1 under emscripten: the WEBGL names) */
            caps |= FOGVOL_CAP_DEPTH_TEXTURE;
        }
    } else {
        caps |= FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_MRT | FOGVOL_CAP_DEPTH_TEXTURE;
        if (gl->major >= 3) /* R32F render targets and float blending are core */
            caps |= FOGVOL_CAP_FLOAT_BLEND | FOGVOL_CAP_FLOAT_TARGET;
        gl->float_linear = gl->major >= 3;
        if (gl->float_linear) caps |= FOGVOL_CAP_FILTER_FLOAT;
    }
    /* RG32F targets and FBOs; not WebGL, whose feedback-loop rule forbids the composite's read of a depth
       texture that is attached to the bound framebuffer, even with depth writes off (not tested here) */
    if (gl->major >= 3 && (caps & FOGVOL_CAP_FLOAT_BLEND) && !gl->webgl) caps |= FOGVOL_CAP_ATTACH_DEPTH;
    return caps;
}

/* Multisample targets and per-sample shading: GL 4.0, or GL 3.2 with
   ARB_sample_shading (desktop; GLES 3.1/3.2 would need a 310 es dialect). */
static int fogvol__gl_load_msaa(fogvol__gl *gl, const fogvol_gl_desc *desc)
{
    int v4 = gl->major >= 4;
    if (gl->gles || gl->major < 3 || (gl->major == 3 && gl->minor < 2)) return 0;
    if (!v4 && !fogvol__gl_has_ext3(gl, "GL_ARB_sample_shading")) return 0;
    gl->TexImage2DMultisample =
        (fogvol__PFN_TexImage2DMultisample)desc->get_proc_address("glTexImage2DMultisample", desc->user_data);
    gl->RenderbufferStorageMultisample = (fogvol__PFN_RenderbufferStorageMultisample)desc->get_proc_address(
        "glRenderbufferStorageMultisample", desc->user_data);
    gl->MinSampleShading = (fogvol__PFN_MinSampleShading)desc->get_proc_address(
        v4 ? "glMinSampleShading" : "glMinSampleShadingARB", desc->user_data);
    gl->GetTexLevelParameteriv = (fogvol__PFN_GetTexLevelParameteriv)desc->get_proc_address(
        "glGetTexLevelParameteriv", desc->user_data);
    gl->has_msaa = gl->TexImage2DMultisample && gl->RenderbufferStorageMultisample && gl->MinSampleShading &&
                   gl->GetTexLevelParameteriv;
    return gl->has_msaa;
}

/* Which of the state of FOGVOL__GL_ENABLES and fogvol__gl_save_draw_buffers the context has. */
static void fogvol__gl_raster_caps(fogvol__gl *gl)
{
    fogvol__GLint n = 0;
    int es = gl->gles, v = gl->major * 10 + gl->minor;
    if (gl->DrawBuffers) {
        gl->GetIntegerv(FOGVOL__GL_MAX_DRAW_BUFFERS, &n);
        gl->max_draw_buffers = n < 1 ? 1 : n > FOGVOL__GL_MAX_DB ? FOGVOL__GL_MAX_DB : n;
    }
    if (!es) { /* CLIP_PLANEi of GL 2.x are the same enables as CLIP_DISTANCEi */
        n = 0;
        gl->GetIntegerv(FOGVOL__GL_MAX_CLIP_DISTANCES, &n);
        gl->n_clip = n < 0 ? 0 : n > 8 ? 8 : n;
    }
    gl->has_restart = !es && v >= 31;
    gl->has_restart_fixed = es ? v >= 30 && !gl->webgl : v >= 43; /* WebGL 2: always on, no enable */
    gl->has_depth_clamp = !es && v >= 32;
    gl->has_sample_shading = (es ? v >= 32 : v >= 40) || gl->has_msaa; /* GL 3.2 + ARB_sample_shading */
    gl->has_sample_mask = es ? v >= 31 : v >= 32;
    if (gl->ViewportIndexedf) {
        n = 0;
        gl->GetIntegerv(FOGVOL__GL_MAX_VIEWPORTS, &n);
        gl->n_viewports = n < 1 ? 1 : n > 32 ? 32 : n;
    }
}

/* Parse "M.m" at the first digit of s. */
static void fogvol__parse_version(const char *s, int *major, int *minor)
{
    *major = *minor = 0;
    if (!s) return;
    while (*s && (*s < '0' || *s > '9')) ++s;
    while (*s >= '0' && *s <= '9') *major = *major * 10 + (*s++ - '0');
    if (*s == '.') ++s;
    while (*s >= '0' && *s <= '9') *minor = *minor * 10 + (*s++ - '0');
}

#define FOGVOL__GL_LOAD(ret, name, params) \
    gl->name = (fogvol__PFN_##name)desc->get_proc_address("gl" #name, desc->user_data);
#define FOGVOL__GL_REQUIRE(ret, name, params) \
    if (!gl->name) { \
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: required GL function gl%s is missing", #name); \
        return FOGVOL_ERROR_MISSING_FUNCTION; \
    }

/* The GL 1.x/2.0 functions, then the context's version and profile (or the older one desc asks for):
   GL 2.0 / GLES 2.0 at least. */
static fogvol_result fogvol__gl_version(fogvol__gl *gl, const fogvol_gl_desc *desc, const char **ver)
{
    FOGVOL__GL_BASE(FOGVOL__GL_LOAD)
    FOGVOL__GL_BASE(FOGVOL__GL_REQUIRE)
    *ver = (const char *)gl->GetString(FOGVOL__GL_VERSION);
    if (!*ver) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: glGetString(GL_VERSION) returned NULL: no current context?");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    gl->gles = strncmp(*ver, "OpenGL ES", 9) == 0;
    gl->webgl = gl->gles && strstr(*ver, "WebGL") != NULL;
    fogvol__parse_version(*ver, &gl->major, &gl->minor);
    if (!gl->gles && (gl->major > 3 || (gl->major == 3 && gl->minor >= 2))) {
        fogvol__GLint mask = 0;
        gl->GetIntegerv(FOGVOL__GL_CONTEXT_PROFILE_MASK, &mask);
        gl->core = (mask & 1) != 0;
    }
    if (desc->version_major > 0) { /* treat the context as an older one */
        gl->major = desc->version_major;
        gl->minor = desc->version_minor;
        gl->gles = desc->gles != 0;
        if (gl->core && gl->major < 3) { /* (GL 3.x stays the core profile it is; GLES 3 has VAOs too) */
            fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: a core-profile context cannot be treated as %s %d.%d "
                        "(drawn without vertex array objects, one GL_EXTENSIONS string): use a compatibility "
                        "profile for that override", gl->gles ? "OpenGL ES" : "GL", gl->major, gl->minor);
            return FOGVOL_ERROR_UNSUPPORTED;
        }
        if (gl->gles) gl->core = 0;
    }
    if ((!gl->gles && gl->major < 2) || (gl->gles && gl->major < 2)) {
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: %s %d.%d has no GLSL; need GL 2.0 or GLES 2.0",
                    gl->gles ? "OpenGL ES" : "OpenGL", gl->major, gl->minor);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    return FOGVOL_SUCCESS;
}

/* GLES, optional: viewport arrays (OES_viewport_array, glViewportIndexedfOES ...; with glEnablei). */
static void fogvol__gl_load_es_viewport_array(fogvol__gl *gl, const fogvol_gl_desc *desc)
{
    if (gl->major < 3 || !fogvol__gl_has_ext3(gl, "GL_OES_viewport_array")) return;
    gl->ViewportIndexedf = (fogvol__PFN_ViewportIndexedf)desc->get_proc_address("glViewportIndexedfOES", desc->user_data);
    gl->ScissorIndexed = (fogvol__PFN_ScissorIndexed)desc->get_proc_address("glScissorIndexedOES", desc->user_data);
    gl->DepthRangeIndexedf =
        (fogvol__PFN_DepthRangeIndexedf)desc->get_proc_address("glDepthRangeIndexedfOES", desc->user_data);
    if (!gl->ViewportIndexedf || !gl->ScissorIndexed || !gl->DepthRangeIndexedf || !gl->Enablei || !gl->Disablei ||
        !gl->IsEnabledi)
        gl->ViewportIndexedf = NULL; /* (fogvol__gl_viewport and the others test this one) */
}

/* Desktop, optional: viewport arrays (GL 4.1 or ARB_viewport_array, with glEnablei for the scissor
   test; all or none) and glClampColor where colour clamping exists (GL 3.0+ compatibility profiles). */
static void fogvol__gl_load_desktop_extras(fogvol__gl *gl, const fogvol_gl_desc *desc)
{
    if (gl->major >= 3 && (gl->major > 4 || (gl->major == 4 && gl->minor >= 1) ||
                           fogvol__gl_has_ext3(gl, "GL_ARB_viewport_array"))) {
        FOGVOL__GL_VIEWPORT_ARRAY(FOGVOL__GL_LOAD)
        if (!gl->ViewportIndexedf || !gl->ScissorIndexed || !gl->DepthRangeIndexed || !gl->Enablei || !gl->Disablei ||
            !gl->IsEnabledi)
            gl->ViewportIndexedf = NULL; /* (fogvol__gl_viewport and the others test this one) */
    }
    if (gl->major >= 3 && !gl->core) FOGVOL__GL_CLAMP(FOGVOL__GL_LOAD)
}

/* Loads gl<nm><suffix> (locals: char name[64], const char *suffix: "" for the core name, "EXT", "ARB" or
   "OES" where an extension provides the function); _SUFFIXED: missing is an error. */
#define FOGVOL__GL_LOAD_NAMED(ret, nm, params) \
    snprintf(name, sizeof name, "gl%s%s", #nm, suffix); \
    gl->nm = (fogvol__PFN_##nm)desc->get_proc_address(name, desc->user_data);
#define FOGVOL__GL_LOAD_SUFFIXED(ret, nm, params) \
    FOGVOL__GL_LOAD_NAMED(ret, nm, params) \
    if (!gl->nm) { \
        fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: required GL function %s is missing", name); \
        return FOGVOL_ERROR_MISSING_FUNCTION; \
    }

/* Framebuffer objects (core, ARB_framebuffer_object or EXT_framebuffer_object: suffix "EXT") and
   what else the version has; ext: the GL 2 / GLES 2 extension string (NULL on 3.x and later). */
static fogvol_result fogvol__gl_features(fogvol__gl *gl, const fogvol_gl_desc *desc, const char **ext)
{
    const char *suffix = "";
    char name[64];
    gl->has_split_fbo = gl->major >= 3;
    gl->has_vao = gl->major >= 3;
    gl->has_sampler = gl->gles ? gl->major >= 3 : (gl->major > 3 || (gl->major == 3 && gl->minor >= 3));
    gl->has_pixel_buffers = gl->gles ? gl->major >= 3 : (gl->major > 2 || (gl->major == 2 && gl->minor >= 1));
    gl->has_row_length = gl->has_pack_rows = !gl->gles || gl->major >= 3;
    gl->has_discard = gl->major >= 3;
    gl->has_uint_index = !gl->gles || gl->major >= 3;
    if (gl->major < 3) *ext = (const char *)gl->GetString(FOGVOL__GL_EXTENSIONS);
    if (gl->gles && gl->major < 3) { /* GLES 2's pixel-transfer extensions: the same state as GLES 3's, saved too */
        gl->has_row_length = fogvol__has_ext(*ext, "GL_EXT_unpack_subimage");
        gl->has_pack_rows = fogvol__has_ext(*ext, "GL_NV_pack_subimage");
        gl->has_pixel_buffers = fogvol__has_ext(*ext, "GL_NV_pixel_buffer_object");
    }
    if (gl->gles && gl->major < 3) gl->has_uint_index = fogvol__has_ext(*ext, "GL_OES_element_index_uint");
    if (!gl->gles && gl->major < 3 && !fogvol__has_ext(*ext, "GL_ARB_framebuffer_object")) {
        if (!fogvol__has_ext(*ext, "GL_EXT_framebuffer_object")) {
            fogvol__log(&gl->log, FOGVOL_LOG_ERROR, "fogvol: GL %d.%d without framebuffer objects", gl->major,
                        gl->minor);
            return FOGVOL_ERROR_UNSUPPORTED;
        }
        suffix = "EXT";
    }
    if (!gl->gles && gl->major < 3) /* ARB_framebuffer_object / EXT_framebuffer_blit: separate read and draw */
        gl->has_split_fbo = fogvol__has_ext(*ext, "GL_ARB_framebuffer_object") ||
                            fogvol__has_ext(*ext, "GL_EXT_framebuffer_blit");
    FOGVOL__GL_FBO(FOGVOL__GL_LOAD_SUFFIXED)
    return FOGVOL_SUCCESS;
}

/* Per-draw-buffer masks and blending, which the engine may have set and fogvol puts back, and the
   transform feedback pause. GL 3.x and GLES 3.0/3.1 contexts may have the later versions' functions
   as extensions (a driver may give exactly the 3.3 asked for): the masks are GL 3.0, GLES 3.2 or
   OES_/EXT_draw_buffers_indexed (...iOES/...iEXT, blending too); the blending GL 4.0 or
   ARB_draw_buffers_blend (...iARB); the pause GL 4.0, GLES 3.0 or ARB_transform_feedback2. */
static fogvol_result fogvol__gl_load_indexed(fogvol__gl *gl, const fogvol_gl_desc *desc)
{
    const char *mask = NULL, *blend = NULL, *suffix; /* the functions' suffixes; NULL: none */
    char name[64];
    if (!gl->gles) {
        mask = gl->major >= 3 ? "" : NULL;
        blend = gl->major >= 4                                                              ? ""
                : gl->major == 3 && fogvol__gl_has_ext3(gl, "GL_ARB_draw_buffers_blend") ? "ARB"
                                                                                            : NULL;
    } else if (gl->major > 3 || (gl->major == 3 && gl->minor >= 2)) {
        mask = blend = "";
    } else if (gl->major == 3) {
        mask = blend = fogvol__gl_has_ext3(gl, "GL_OES_draw_buffers_indexed")   ? "OES"
                       : fogvol__gl_has_ext3(gl, "GL_EXT_draw_buffers_indexed") ? "EXT"
                                                                               : NULL;
    }
    if (mask) {
        suffix = mask;
        FOGVOL__GL_INDEXED_MASK(FOGVOL__GL_LOAD_NAMED)
    }
    if (blend) {
        suffix = blend;
        FOGVOL__GL_INDEXED_BLEND(FOGVOL__GL_LOAD_NAMED)
    }
    /* an extension counts only with all its functions (WebGL 2 lists OES_draw_buffers_indexed without
       IsEnablediOES): else the context is taken as without it; core functions are required */
#define FOGVOL__GL_HAVE(ret, nm, params) &&gl->nm
#define FOGVOL__GL_CLEAR(ret, nm, params) gl->nm = NULL;
    if (mask && *mask && !(1 FOGVOL__GL_INDEXED_MASK(FOGVOL__GL_HAVE) FOGVOL__GL_INDEXED_BLEND(FOGVOL__GL_HAVE))) {
        fogvol__log(&gl->log, FOGVOL_LOG_INFO,
                    "fogvol: %s_draw_buffers_indexed is listed without all its functions: the engine's per-buffer "
                    "blend state is not saved", mask);
        FOGVOL__GL_INDEXED_MASK(FOGVOL__GL_CLEAR)
        mask = blend = NULL;
    }
    if (blend && *blend && !(1 FOGVOL__GL_INDEXED_BLEND(FOGVOL__GL_HAVE))) {
        fogvol__log(&gl->log, FOGVOL_LOG_INFO,
                    "fogvol: %s_draw_buffers_blend is listed without all its functions: the engine's per-buffer "
                    "blend functions are not saved", blend);
        blend = NULL;
    }
    if (!blend) {
        FOGVOL__GL_INDEXED_BLEND(FOGVOL__GL_CLEAR)
    }
#undef FOGVOL__GL_CLEAR
#undef FOGVOL__GL_HAVE
    gl->has_indexed_mask = mask != NULL;
    gl->has_indexed_blend = blend != NULL;
    gl->has_tf_pause = gl->gles ? gl->major >= 3
                                : gl->major >= 4 ||
                                      (gl->major == 3 && fogvol__gl_has_ext3(gl, "GL_ARB_transform_feedback2"));
    if (mask) {
        FOGVOL__GL_INDEXED_MASK(FOGVOL__GL_REQUIRE)
        FOGVOL__GL_INDEXED_QUERY(FOGVOL__GL_LOAD)
        FOGVOL__GL_REQUIRE(void, GetIntegeri_v, ())
        if (gl->gles && gl->major == 3 && gl->minor == 0) gl->GetBooleani_v = NULL; /* GLES 3.1 */
        else FOGVOL__GL_REQUIRE(void, GetBooleani_v, ())
    }
    if (blend) {
        FOGVOL__GL_INDEXED_BLEND(FOGVOL__GL_REQUIRE)
    }
    if (gl->has_tf_pause) {
        FOGVOL__GL_TF_PAUSE(FOGVOL__GL_LOAD)
        FOGVOL__GL_TF_PAUSE(FOGVOL__GL_REQUIRE)
    }
    return FOGVOL_SUCCESS;
}

/* The functions of the later versions that the context has. */
static fogvol_result fogvol__gl_load_versioned(fogvol__gl *gl, const fogvol_gl_desc *desc, const char *ext)
{
    fogvol_result r;
    if (gl->has_vao) {
        FOGVOL__GL_VAO(FOGVOL__GL_LOAD)
        FOGVOL__GL_VAO(FOGVOL__GL_REQUIRE)
    }
    if (gl->has_sampler) {
        FOGVOL__GL_SAMPLER(FOGVOL__GL_LOAD)
        FOGVOL__GL_SAMPLER(FOGVOL__GL_REQUIRE)
    }
    if (gl->major >= 3 || (!gl->gles && fogvol__has_ext(ext, "GL_ARB_framebuffer_object"))) {
        FOGVOL__GL_BLIT(FOGVOL__GL_LOAD) /* optional: without it copy_depth refuses */
    }
    if (gl->major >= 3) {
        FOGVOL__GL_3(FOGVOL__GL_LOAD)
        FOGVOL__GL_3(FOGVOL__GL_REQUIRE)
        if (!gl->gles) {
            FOGVOL__GL_3_DESKTOP(FOGVOL__GL_LOAD)
            FOGVOL__GL_3_DESKTOP(FOGVOL__GL_REQUIRE)
        }
    }
    if (!gl->gles || gl->major >= 3) {
        FOGVOL__GL_DRAW_BUFFERS(FOGVOL__GL_LOAD)
        FOGVOL__GL_DRAW_BUFFERS(FOGVOL__GL_REQUIRE)
    } else if (fogvol__has_ext(ext, "GL_EXT_draw_buffers")) { /* GLES 2: the engine's list, saved and narrowed */
        gl->DrawBuffers = (fogvol__PFN_DrawBuffers)desc->get_proc_address("glDrawBuffersEXT", desc->user_data);
    }
    if ((r = fogvol__gl_load_indexed(gl, desc)) != FOGVOL_SUCCESS) return r;
    if (!gl->gles || gl->major >= 3) { /* optional */
        FOGVOL__GL_QUERY(FOGVOL__GL_LOAD)
#define FOGVOL__GL_HAVE(ret, name, params) &&gl->name
        gl->has_query = 1 FOGVOL__GL_QUERY(FOGVOL__GL_HAVE);
#undef FOGVOL__GL_HAVE
    }
    if (gl->gles) {
        FOGVOL__GL_ES(FOGVOL__GL_LOAD)
        FOGVOL__GL_ES(FOGVOL__GL_REQUIRE)
        fogvol__gl_load_es_viewport_array(gl, desc);
    } else {
        FOGVOL__GL_DESKTOP(FOGVOL__GL_LOAD)
        FOGVOL__GL_DESKTOP(FOGVOL__GL_REQUIRE)
        fogvol__gl_load_desktop_extras(gl, desc);
    }
    return FOGVOL_SUCCESS;
}
#undef FOGVOL__GL_LOAD
#undef FOGVOL__GL_REQUIRE

/* GL 4.5 / ARB_clip_control, or GLES EXT_clip_control (glClipControlEXT). */
static void fogvol__gl_load_clip_control(fogvol__gl *gl, const fogvol_gl_desc *desc, const char *ext)
{
    if (!gl->gles && (gl->major > 4 || (gl->major == 4 && gl->minor >= 5) ||
                      (gl->major >= 3 ? fogvol__gl_has_ext3(gl, "GL_ARB_clip_control")
                                      : fogvol__has_ext(ext, "GL_ARB_clip_control"))))
        gl->ClipControl = (fogvol__PFN_ClipControl)desc->get_proc_address("glClipControl", desc->user_data);
    else if (gl->gles && (gl->major >= 3 ? fogvol__gl_has_ext3(gl, "GL_EXT_clip_control")
                                         : fogvol__has_ext(ext, "GL_EXT_clip_control")))
        gl->ClipControl = (fogvol__PFN_ClipControl)desc->get_proc_address("glClipControlEXT", desc->user_data);
}

/* The dialect, capabilities, the sampler for engine textures and the full-screen triangle. */
/* Without VAOs, the context's mark (fogvol__gl_foreign): a framebuffer object, which exists once bound
   (also the one fogvol__gl_raise clears through); the bindings are put back. */
static void fogvol__gl_mark(fogvol__gl *gl)
{
    fogvol__GLint draw = 0, read = 0;
    gl->GetIntegerv(FOGVOL__GL_DRAW_FRAMEBUFFER_BINDING, &draw);
    if (gl->has_split_fbo) gl->GetIntegerv(FOGVOL__GL_READ_FRAMEBUFFER_BINDING, &read);
    gl->GenFramebuffers(1, &gl->err_fbo);
    gl->BindFramebuffer(FOGVOL__GL_FRAMEBUFFER, gl->err_fbo);
    gl->BindFramebuffer(gl->has_split_fbo ? FOGVOL__GL_DRAW_FRAMEBUFFER : FOGVOL__GL_FRAMEBUFFER, (fogvol__GLuint)draw);
    if (gl->has_split_fbo) gl->BindFramebuffer(FOGVOL__GL_READ_FRAMEBUFFER, (fogvol__GLuint)read);
}

static fogvol_result fogvol__gl_setup(fogvol__gl *gl, const fogvol_gl_desc *desc, const char *ext)
{
    static const float tri[9] = {-1, -1, 0, 3, -1, 0, -1, 3, 0};
    fogvol_mesh_data tri_data;
    fogvol_result r;
    gl->dialect = desc->dialect;
    if (gl->dialect == FOGVOL_GLSL_AUTO) gl->dialect = fogvol__dialect_for_gl(gl->gles, gl->major, gl->minor);
    gl->mrt_highp = desc->mrt_highp != 0;
    gl->caps = fogvol__gl_caps(gl, ext);
    if (fogvol__gl_load_msaa(gl, desc)) gl->caps |= FOGVOL_CAP_MULTISAMPLE;
    if ((gl->caps & FOGVOL_CAP_ATTACH_DEPTH) && (gl->caps & FOGVOL_CAP_MULTISAMPLE))
        gl->caps |= FOGVOL_CAP_ATTACH_DEPTH_MULTISAMPLE; /* (GL_TEXTURE_2D_MULTISAMPLE depth attachments) */
    if (desc->software > 0 ||
        (desc->software == 0 && fogvol_renderer_is_software((const char *)gl->GetString(FOGVOL__GL_RENDERER))))
        gl->caps |= FOGVOL_CAP_SOFTWARE_RENDERER;
    if ((gl->dialect == FOGVOL_GLSL_330 || gl->dialect == FOGVOL_GLSL_300ES) && gl->has_indexed_mask &&
        gl->DrawBuffers &&
        (gl->major >= 3 ? fogvol__gl_has_ext3(gl, "GL_EXT_shader_framebuffer_fetch")
                        : fogvol__has_ext(ext, "GL_EXT_shader_framebuffer_fetch")))
        gl->caps |= FOGVOL_CAP_FRAMEBUFFER_FETCH; /* (FOGVOL_SPEEDUP_FRAMEBUFFER_FETCH) */
    fogvol__gl_load_clip_control(gl, desc, ext);
    fogvol__gl_raster_caps(gl);
    if (gl->has_sampler) { /* sampler objects hold no binding: no state to save */
        gl->GenSamplers(1, &gl->native_sampler);
        gl->SamplerParameteri(gl->native_sampler, FOGVOL__GL_TEXTURE_MIN_FILTER, FOGVOL__GL_NEAREST);
        gl->SamplerParameteri(gl->native_sampler, FOGVOL__GL_TEXTURE_MAG_FILTER, FOGVOL__GL_NEAREST);
        gl->SamplerParameteri(gl->native_sampler, FOGVOL__GL_TEXTURE_WRAP_S, FOGVOL__GL_CLAMP_TO_EDGE);
        gl->SamplerParameteri(gl->native_sampler, FOGVOL__GL_TEXTURE_WRAP_T, FOGVOL__GL_CLAMP_TO_EDGE);
        gl->SamplerParameteri(gl->native_sampler, FOGVOL__GL_TEXTURE_COMPARE_MODE, FOGVOL__GL_NONE);
    }
    gl->has_debug_output = gl->gles ? gl->major > 3 || (gl->major == 3 && gl->minor >= 2)
                                    : gl->major > 4 || (gl->major == 4 && gl->minor >= 3);
    if (!gl->has_debug_output)
        gl->has_debug_output = gl->major >= 3 ? fogvol__gl_has_ext3(gl, "GL_KHR_debug") : fogvol__has_ext(ext, "GL_KHR_debug");
    memset(&tri_data, 0, sizeof tri_data);
    tri_data.positions = tri;
    tri_data.vertex_count = 3;
    r = fogvol__gl_upload(gl, &gl->fullscreen, &tri_data);
    if (r == FOGVOL_SUCCESS && !gl->has_vao) fogvol__gl_mark(gl);
    if (r != FOGVOL_SUCCESS && gl->native_sampler) gl->DeleteSamplers(1, &gl->native_sampler);
    return r;
}

static void fogvol__gl_fill_table(fogvol__gl *gl, fogvol_backend *out)
{
    out->user_data = gl;
    out->dialect = gl->dialect;
    out->caps = gl->caps | FOGVOL_CAP_MESH_LAYOUT;
    out->native_texture = fogvol__gl_native_texture;
    out->target_attachment = fogvol__gl_target_attachment;
    out->copy_depth = fogvol__gl_copy_depth;
    out->begin_frame = fogvol__gl_begin_frame;
    out->end_frame = fogvol__gl_end_frame;
    out->end_pass = fogvol__gl_end_pass;
    out->create_texture = fogvol__gl_create_texture;
    out->destroy_texture = fogvol__gl_destroy_texture;
    out->create_target = fogvol__gl_create_target;
    out->destroy_target = fogvol__gl_destroy_target;
    out->create_program = fogvol__gl_create_program;
    out->destroy_program = fogvol__gl_destroy_program;
    out->create_mesh = fogvol__gl_create_mesh;
    out->destroy_mesh = fogvol__gl_destroy_mesh;
    out->begin_pass = fogvol__gl_begin_pass;
    out->set_draw = fogvol__gl_set_draw;
    out->draw_mesh = fogvol__gl_draw_mesh;
    out->draw_fullscreen = fogvol__gl_draw_fullscreen;
    out->read_target = fogvol__gl_read_target;
    out->destroy = fogvol__gl_destroy;
    out->take_error = fogvol__gl_take_error;
    if (gl->has_query) {
        out->create_query = fogvol__gl_create_query;
        out->destroy_query = fogvol__gl_destroy_query;
        out->begin_query = fogvol__gl_begin_query;
        out->end_query = fogvol__gl_end_query;
        out->query_result = fogvol__gl_query_result;
    }
}

/* fogvol_gl_desc's plain loaders behind the get_proc_address interface (user: the desc) */
static fogvol_gl_proc fogvol__gl_plain_proc(const char *name, void *user)
{
    const fogvol_gl_desc *d = (const fogvol_gl_desc *)user;
    fogvol_gl_proc f = NULL;
    void *p;
    if (d->get_proc) return d->get_proc(name);
    p = d->get_proc_pointer(name); /* (a data pointer to a function pointer: bit for bit, as POSIX dlsym) */
    if (p && sizeof p == sizeof f) memcpy(&f, &p, sizeof f);
    return f;
}

FOGVOL_API fogvol_result fogvol_gl_backend_create(const fogvol_gl_desc *in, const fogvol_allocator *alloc,
                                                  const fogvol_logger *logger, fogvol_backend *out)
{
    fogvol__gl *gl;
    fogvol_logger silent;
    fogvol_gl_desc plain; /* in with a plain loader: get_proc_address calls it */
    const fogvol_gl_desc *desc = in;
    const char *ver = NULL, *ext = NULL;
    fogvol_result r;
    if (!out) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    memset(&silent, 0, sizeof silent);
    if (!logger) logger = &silent;
    if (in && !in->get_proc_address && (in->get_proc || in->get_proc_pointer)) {
        plain = *in;
        plain.get_proc_address = fogvol__gl_plain_proc;
        plain.user_data = (void *)in;
        desc = &plain;
    }
    if (!desc || !desc->get_proc_address) {
        fogvol__log(logger, FOGVOL_LOG_ERROR,
                    "fogvol: the GL backend needs a loader (get_proc_address, get_proc or get_proc_pointer)");
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if ((int)desc->dialect < 0 || (int)desc->dialect >= FOGVOL_GLSL_COUNT) {
        fogvol__log(logger, FOGVOL_LOG_ERROR, "fogvol: unknown GLSL dialect %d in fogvol_gl_desc (FOGVOL_GLSL_*)",
                    (int)desc->dialect);
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    }
    if (desc->dialect == FOGVOL_GLSL_VULKAN) { /* SPIR-V, not GL */
        fogvol__log(logger, FOGVOL_LOG_ERROR, "fogvol: the GL backend cannot take FOGVOL_GLSL_VULKAN (a dialect for "
                    "SPIR-V backends)");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    gl = (fogvol__gl *)fogvol__alloc(alloc, sizeof *gl);
    if (!gl) return FOGVOL_ERROR_OUT_OF_MEMORY;
    memset(gl, 0, sizeof *gl);
    if (alloc) gl->alloc = *alloc;
    gl->log = *logger;
    gl->current_context = in->current_context;
    gl->user_data = in->user_data; /* (the caller's, also with a plain loader) */
    if (gl->current_context) gl->context_id = gl->current_context(gl->user_data);
    r = fogvol__gl_version(gl, desc, &ver);
    if (r == FOGVOL_SUCCESS) { /* (the engine's pending errors held: fogvol's own are this call's) */
        fogvol__gl_host_enter(gl);
        r = fogvol__gl_features(gl, desc, &ext);
        if (r == FOGVOL_SUCCESS) r = fogvol__gl_load_versioned(gl, desc, ext);
        if (r == FOGVOL_SUCCESS) r = fogvol__gl_setup(gl, desc, ext);
        fogvol__gl_host_leave(gl);
        if (r == FOGVOL_SUCCESS && fogvol__gl_take_error(gl) != FOGVOL_SUCCESS) {
            fogvol__gl_destroy(gl);
            return FOGVOL_ERROR_BACKEND;
        }
    }
    if (r != FOGVOL_SUCCESS) {
        if (gl->err_shader) gl->DeleteShader(gl->err_shader); /* (made to raise the engine's error) */
        if (gl->err_fbo && gl->DeleteFramebuffers) gl->DeleteFramebuffers(1, &gl->err_fbo);
        fogvol__free(alloc, gl);
        return r;
    }
    fogvol__log(logger, FOGVOL_LOG_INFO, "fogvol: GL backend on %s (%s%d.%d%s), GLSL %s", ver,
                gl->gles ? "ES " : "", gl->major, gl->minor, gl->core ? " core" : "", fogvol_dialect_name(gl->dialect));
    fogvol__gl_fill_table(gl, out);
    return FOGVOL_SUCCESS;
}

#endif /* FOGVOL_NO_GL */

#ifdef __cplusplus
}
#endif

#endif /* FOGVOL_IMPLEMENTATION_DONE */
#endif /* FOGVOL_IMPLEMENTATION */

/*
   REVISION HISTORY
     0.2.0  (2026-11)  density and colour textures on volumes, volume light by compare,
                       image-space effects (depth of field, outlines, distance fog), GLES and
                       WebGL tested, float SIMD analytic kernels, engine conventions (clip
                       control, reversed-Z, G-buffers, MSAA, engine depth and occluders),
                       overflow counted every frame; outputs last everywhere; programs
                       specialised per configuration, PS20/MRT encode by arithmetic by default,
                       resolve and check passes scissored; declarations in reading order; one
                       tier table, sections by what they hold, preferred variants, plain GL
                       loaders (see CHANGELOG.md)
     0.1.0  (2026-11)  first release: RGB encoding with dithered blue ramp, ramp and
                       colour-ramp textures, mesh validation, PS20 renderer, GL backend,
                       recording null backend.

   ------------------------------------------------------------------------------
   This software is available under 2 licenses -- choose whichever you prefer.
   ------------------------------------------------------------------------------
   ALTERNATIVE A - MIT License
   Copyright (c) 2026 the fogvol.h authors
   Permission is hereby granted, free of charge, to any person obtaining a copy of
   this software and associated documentation files (the "Software"), to deal in
   the Software without restriction, including without limitation the rights to
   use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
   of the Software, and to permit persons to whom the Software is furnished to do
   so, subject to the following conditions:
   The above copyright notice and this permission notice shall be included in all
   copies or substantial portions of the Software.
   THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
   IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
   FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
   AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
   LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
   OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
   SOFTWARE.
   ------------------------------------------------------------------------------
   ALTERNATIVE B - Public Domain (www.unlicense.org)
   This is free and unencumbered software released into the public domain.
   Anyone is free to copy, modify, publish, use, compile, sell, or distribute this
   software, either in source code form or as a compiled binary, for any purpose,
   commercial or non-commercial, and by any means.
   In jurisdictions that recognize copyright laws, the author or authors of this
   software dedicate any and all copyright interest in the software to the public
   domain. We make this dedication for the benefit of the public at large and to
   the detriment of our heirs and successors. We intend this dedication to be an
   overt act of relinquishment in perpetuity of all present and future rights to
   this software under copyright law.
   THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
   IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
   FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
   AUTHORS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN
   ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION
   WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
   ------------------------------------------------------------------------------
*/
