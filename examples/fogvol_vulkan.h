/* fogvol_vulkan.h - a complete fogvol_backend on Vulkan 1.3 (header-only, C99 / C++11), the model for
   an engine's own backend. examples/vulkan_backend.c is the engine around it.

   What the engine does:
     fogvk_desc d = {instance, physical device, device, frames in flight, logger};
     fogvol_backend be;  fogvk_create(&d, &be);          // before fogvol_create_context
     cd.backend = be;  fogvol_create_context(&cd, &fv);   // dialect FOGVOL_GLSL_VULKAN, caps below
     every frame, once, before the first fogvol call that records into cmd (fogvol_end_frame; for the
     MRT tier fogvol_mrt_prepare, before the engine's pass), outside any render pass:
       fogvk_frame f = {cmd, slot, colour image, depth image, size, flush};
       fogvk_set_frame(&be, &f);
       fogvol_begin_frame ... fogvol_end_frame            // records fogvol's passes into f.cmd
       fogvk_frame_command(&be)                           // the command buffer to submit (a debug
                                                          // read-back hands out a new one)
     and at the end: fogvol_destroy_context, then be.destroy(be.user_data) (it waits for the device).

   The device needs Vulkan 1.3 with dynamicRendering, Vulkan 1.2's hostQueryReset, occlusionQueryPrecise
   and the extension VK_KHR_push_descriptor (fogvk_device_extensions / fogvk_enable_features say so).

   How each entry of the table maps to Vulkan:
     programs      GLSL of FOGVOL_GLSL_VULKAN compiled by shaderc into two shader modules; the pipeline
                   layout is built from fogvol_program_desc.layout (push descriptors at set 0: the 8
                   samplers and the pass block; the per-draw values as push constants): no reflection
     pipelines     made on first use and cached per (program, blend, target formats, depth format);
                   viewport, scissor, cull mode, front face, depth test and write, blend constants and
                   the vertex stride are dynamic state
     passes        dynamic rendering (vkCmdBeginRendering) in the engine's command buffer; every image
                   is moved to the layout its use needs with a barrier from its last recorded use
     textures      RGBA8 images; the pixels go through a staging buffer whose copy is recorded into
                   the next command buffer fogvol records into (no queue submit of our own)
     targets       RGBA8, R32F or RGBA32F colour images (one or two), own or shared D32 depth
     meshes        vertex and index buffers as fogvol hands them (stride, offset, 16/32-bit indices)
     queries       one occlusion query pool, reset on the host (hostQueryReset), precise counts
     read_target   the debug read-back: copies the target into a buffer, then the engine's flush
                   submits what was recorded and waits: the only wait inside a frame
     copy_depth    vkCmdCopyImage from the engine's depth image into a sampled depth image of ours
     native objects (fogvol_native): a VkImageView. fogvol_frame_desc.engine_depth_texture: a view of a
                   depth image the engine left in VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL with its
                   writes made visible to fragment shaders; native_texture: the view of fogvol's target
                   (its layout: fogvk_target_layout)
   Conventions: fogvol's GL-style matrices and rows stay as they are: row 0 of every image is
   framebuffer y 0 (read_target's rows in that order), fogvol's clip z is mapped to [0, w] in its
   vertex shader (the same window depths as GL), and GL's counter-clockwise front faces are Vulkan's
   VK_FRONT_FACE_CLOCKWISE (Vulkan's area has the opposite sign for the same framebuffer
   coordinates). The engine's own projection may flip y and map depth to [0, 1] as Vulkan engines
   do: fogvol sees the mirroring in the matrix, and begin_frame reports depth_zero_to_one.
   Lifetimes: objects fogvol destroys are freed when their frame slot comes round again (the engine
   promises, by fogvk_frame.slot, that the slot's previous command buffer has completed), and so are
   the staging buffers of textures, once their copies are recorded. fogvk_set_frame is that "comes
   round again": called a second time inside one frame, it would free what the frame's own commands
   still read (the MRT tier's fogvol_mrt_prepare has recorded uploads by then) and rewind the uniforms
   of passes already recorded; the frame's description is given once, with the layouts the engine's
   images are in when fogvol_end_frame records.

   In exactly one file: #define FOGVOL_VULKAN_IMPLEMENTATION before #include "fogvol_vulkan.h"
   (after fogvol.h and <vulkan/vulkan.h>); link -lvulkan -lshaderc. */
#ifndef FOGVOL_VULKAN_H
#define FOGVOL_VULKAN_H

#include <vulkan/vulkan.h>

typedef struct fogvk_desc {
    VkInstance instance;
    VkPhysicalDevice physical_device;
    VkDevice device;
    int frames_in_flight; /* command buffers the engine has in flight at once: 0 = 2 */
    fogvol_logger logger;
} fogvk_desc;

/* One engine frame: what fogvol records into and draws over. */
typedef struct fogvk_frame {
    VkCommandBuffer cmd;      /* recording, outside any render pass */
    int slot;                 /* 0 .. frames_in_flight - 1; its previous command buffer has completed */
    VkImage color_image;      /* the engine's colour target (fogvol_pass.target 0), single-sample */
    VkImageView color_view;
    VkFormat color_format;
    VkImageLayout color_layout; /* its layout when fogvol_end_frame records; fogvol leaves it in this layout */
    VkImage depth_image;      /* the engine's depth buffer (copy_depth, FOGVOL_DEPTH_SOURCE_BOUND_FRAMEBUFFER) */
    VkFormat depth_format;
    VkImageLayout depth_layout; /* the same: when fogvol_end_frame records, and after */
    int width, height;
    /* debug read-back only: end and submit cmd, wait until it has run, and return a new command
       buffer in the recording state (NULL: read_target fails with FOGVOL_ERROR_UNSUPPORTED) */
    VkCommandBuffer (*flush)(void *user_data, VkCommandBuffer cmd);
    void *flush_user_data;
} fogvk_frame;

/* The device extensions and features the backend needs (for vkCreateDevice). */
#define FOGVK_DEVICE_EXTENSION VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME
void fogvk_enable_features(VkPhysicalDeviceFeatures2 *f2, VkPhysicalDeviceVulkan12Features *f12,
                           VkPhysicalDeviceVulkan13Features *f13);

fogvol_result fogvk_create(const fogvk_desc *desc, fogvol_backend *out);
/* Starts a frame in frame->slot, once per frame: frees what was let go of in the slot's previous
   frame and rewinds its uniform ring (see Lifetimes above). */
void fogvk_set_frame(fogvol_backend *backend, const fogvk_frame *frame);
/* the command buffer the frame's commands are in now (a read-back's flush replaces it) */
VkCommandBuffer fogvk_frame_command(const fogvol_backend *backend);
/* the layout a fogvol target's colour image is in now (after what has been recorded) */
VkImageLayout fogvk_target_layout(const fogvol_backend *backend, fogvol_handle target);
/* Before the engine renders into one of fogvol's targets itself (the MRT tier's O,
   fogvol_mrt_info.texture; fogvol_occluder_info.texture): records into cmd the barrier that makes
   that image a colour attachment in VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, after fogvol's last use
   of it, and notes that the engine writes it there (fogvol's passes then wait for those writes).
   FOGVOL_ERROR_INVALID_ARGUMENT when no target of the backend has this view. */
fogvol_result fogvk_engine_attachment(fogvol_backend *backend, VkCommandBuffer cmd, fogvol_native view);

#endif /* FOGVOL_VULKAN_H */

#ifdef FOGVOL_VULKAN_IMPLEMENTATION
#include <shaderc/shaderc.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FOGVK_SAMPLERS FOGVOL_MAX_TEXTURE_UNITS
#define FOGVK_QUERIES 256
#define FOGVK_RING (1u << 20) /* bytes of pass uniforms per frame slot (3000+ passes) */
#define FOGVK_MAX_SLOTS 8

typedef struct fogvk_image {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;
    VkFormat format;
    VkImageAspectFlags aspect;
    int width, height;
    /* the last use recorded: the next barrier waits for it */
    VkImageLayout layout;
    VkPipelineStageFlags stage;
    VkAccessFlags access;
} fogvk_image;

typedef struct fogvk_texture {
    fogvk_image img;
    VkSampler sampler;
    VkBuffer staging; /* pixels waiting for their copy (next recorded command) */
    VkDeviceMemory staging_memory;
    struct fogvk_texture *next_upload;
} fogvk_texture;

typedef struct fogvk_target {
    fogvk_texture color;         /* first: a target handle is sampled as its colour texture */
    struct fogvk_target *second; /* attachment 1 (WIDE, COLORS): a target of its own */
    fogvk_image depth;           /* own depth buffer (depth.image != 0) */
    struct fogvk_target *share;  /* or the depth buffer of this target */
    fogvol_format format;
    struct fogvk_target *next;   /* the backend's list of targets (fogvk_engine_attachment) */
} fogvk_target;

typedef struct fogvk_program {
    VkShaderModule vs, fs;
} fogvk_program;

typedef struct fogvk_mesh {
    VkBuffer vbuf, ibuf;
    VkDeviceMemory vmem, imem;
    VkDeviceSize voffset;
    VkDeviceSize stride;
    VkIndexType itype;
    uint32_t count;
} fogvk_mesh;

typedef struct fogvk_pipeline {
    const fogvk_program *program;
    int blend, coverage, constant, color_count;
    VkFormat color[2], depth;
    VkPipeline pipeline;
} fogvk_pipeline;

typedef struct fogvk_garbage {
    VkObjectType type;
    uint64_t handle;
} fogvk_garbage;

typedef struct fogvk_slot {
    VkBuffer ring;
    VkDeviceMemory ring_memory;
    unsigned char *ring_data;
    VkDeviceSize used;
    fogvk_garbage *garbage;
    int ngarbage, cap;
} fogvk_slot;

typedef struct fogvk {
    VkPhysicalDevice pd;
    VkDevice dev;
    VkPhysicalDeviceMemoryProperties mem;
    VkDeviceSize ubo_align;
    PFN_vkCmdPushDescriptorSetKHR push_descriptors;
    fogvol_logger log;
    shaderc_compiler_t compiler;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    fogvol_uniform_layout ul; /* what the pipeline layout was built from */
    VkSampler samplers[4];    /* [linear * 2 + clamp] */
    VkQueryPool queries;
    unsigned char query_used[FOGVK_QUERIES];
    fogvk_texture *dummy;     /* bound to the units a pass leaves empty */
    fogvk_texture *uploads;   /* textures whose pixels wait for a command buffer */
    fogvk_target *targets;    /* every target (attachments 1 too) */
    fogvk_mesh fullscreen;
    fogvk_pipeline *pipes;
    int npipes, pipe_cap;
    fogvk_slot slots[FOGVK_MAX_SLOTS];
    int nslots;
    /* the frame */
    fogvk_frame frame;
    int have_frame, slot;
    fogvk_image engine_color, engine_depth; /* the engine's images, their layouts as recorded */
    fogvk_image depth_copy;                 /* copy_depth's texture */
    int rendering;
    const fogvol_pass *pass;
    fogvk_target *pass_target;
} fogvk;

static void fogvk__log(fogvk *vk, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    if (!vk->log.func) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    vk->log.func(vk->log.user_data, FOGVOL_LOG_ERROR, buf);
}

void fogvk_enable_features(VkPhysicalDeviceFeatures2 *f2, VkPhysicalDeviceVulkan12Features *f12,
                           VkPhysicalDeviceVulkan13Features *f13)
{
    f2->features.occlusionQueryPrecise = VK_TRUE;
    f12->hostQueryReset = VK_TRUE;
    f13->dynamicRendering = VK_TRUE;
}

/* ---- memory, buffers, images ---- */

static int fogvk__memory_type(fogvk *vk, uint32_t bits, VkMemoryPropertyFlags want)
{
    uint32_t i;
    for (i = 0; i < vk->mem.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (vk->mem.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

static VkResult fogvk__bind_memory(fogvk *vk, VkMemoryRequirements req, VkMemoryPropertyFlags want,
                                   VkDeviceMemory *out)
{
    VkMemoryAllocateInfo ai;
    int type = fogvk__memory_type(vk, req.memoryTypeBits, want);
    if (type < 0) return VK_ERROR_OUT_OF_DEVICE_MEMORY;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = (uint32_t)type;
    return vkAllocateMemory(vk->dev, &ai, NULL, out);
}

/* A buffer in host-visible, coherent memory, filled with data (NULL: left as it is); *map: kept mapped. */
static VkResult fogvk__buffer(fogvk *vk, VkDeviceSize size, VkBufferUsageFlags usage, const void *data,
                              VkBuffer *buf, VkDeviceMemory *mem, void **map)
{
    VkBufferCreateInfo bi;
    VkMemoryRequirements req;
    void *p = NULL;
    VkResult r;
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size;
    bi.usage = usage;
    bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    *buf = VK_NULL_HANDLE;
    *mem = VK_NULL_HANDLE;
    r = vkCreateBuffer(vk->dev, &bi, NULL, buf);
    if (r != VK_SUCCESS) return r;
    vkGetBufferMemoryRequirements(vk->dev, *buf, &req);
    r = fogvk__bind_memory(vk, req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, mem);
    if (r == VK_SUCCESS) r = vkBindBufferMemory(vk->dev, *buf, *mem, 0);
    if (r == VK_SUCCESS) r = vkMapMemory(vk->dev, *mem, 0, VK_WHOLE_SIZE, 0, &p);
    if (r != VK_SUCCESS) {
        vkDestroyBuffer(vk->dev, *buf, NULL);
        if (*mem) vkFreeMemory(vk->dev, *mem, NULL);
        *buf = VK_NULL_HANDLE;
        *mem = VK_NULL_HANDLE;
        return r;
    }
    if (data) memcpy(p, data, (size_t)size);
    if (map) *map = p;
    else vkUnmapMemory(vk->dev, *mem);
    return VK_SUCCESS;
}

static VkResult fogvk__image(fogvk *vk, fogvk_image *im, int w, int h, VkFormat format, VkImageUsageFlags usage)
{
    VkImageCreateInfo ii;
    VkImageViewCreateInfo vi;
    VkMemoryRequirements req;
    VkResult r;
    int depth = format == VK_FORMAT_D32_SFLOAT || format == VK_FORMAT_D24_UNORM_S8_UINT ||
                format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_D32_SFLOAT_S8_UINT;
    memset(im, 0, sizeof *im);
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = format;
    ii.extent.width = (uint32_t)w;
    ii.extent.height = (uint32_t)h;
    ii.extent.depth = 1;
    ii.mipLevels = 1;
    ii.arrayLayers = 1;
    ii.samples = VK_SAMPLE_COUNT_1_BIT;
    ii.tiling = VK_IMAGE_TILING_OPTIMAL;
    ii.usage = usage;
    ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    r = vkCreateImage(vk->dev, &ii, NULL, &im->image);
    if (r != VK_SUCCESS) return r;
    vkGetImageMemoryRequirements(vk->dev, im->image, &req);
    r = fogvk__bind_memory(vk, req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &im->memory);
    if (r == VK_SUCCESS) r = vkBindImageMemory(vk->dev, im->image, im->memory, 0);
    im->format = format;
    im->aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    im->width = w;
    im->height = h;
    im->layout = VK_IMAGE_LAYOUT_UNDEFINED;
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = im->image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange.aspectMask = im->aspect;
    vi.subresourceRange.levelCount = 1;
    vi.subresourceRange.layerCount = 1;
    if (r == VK_SUCCESS) r = vkCreateImageView(vk->dev, &vi, NULL, &im->view);
    return r;
}

static void fogvk__free_garbage(fogvk *vk, fogvk_slot *s);

/* Objects fogvol lets go of: freed when their frame slot comes round again (or at destroy). */
static void fogvk__defer(fogvk *vk, VkObjectType type, uint64_t handle)
{
    fogvk_slot *s = &vk->slots[vk->slot];
    if (!handle) return;
    if (s->ngarbage == s->cap) {
        int cap = s->cap ? s->cap * 2 : 64;
        fogvk_garbage *g = (fogvk_garbage *)realloc(s->garbage, (size_t)cap * sizeof *g);
        if (!g) { /* out of memory for the list: the one place that waits, to free everything now */
            fogvk_garbage one;
            fogvk_slot now;
            one.type = type;
            one.handle = handle;
            memset(&now, 0, sizeof now);
            now.garbage = &one;
            now.ngarbage = 1;
            vkDeviceWaitIdle(vk->dev);
            fogvk__free_garbage(vk, s);
            fogvk__free_garbage(vk, &now);
            return;
        }
        s->garbage = g;
        s->cap = cap;
    }
    s->garbage[s->ngarbage].type = type;
    s->garbage[s->ngarbage].handle = handle;
    s->ngarbage++;
}

static void fogvk__free_garbage(fogvk *vk, fogvk_slot *s)
{
    int i;
    for (i = 0; i < s->ngarbage; ++i) {
        uint64_t h = s->garbage[i].handle;
        switch (s->garbage[i].type) {
        case VK_OBJECT_TYPE_IMAGE: vkDestroyImage(vk->dev, (VkImage)h, NULL); break;
        case VK_OBJECT_TYPE_IMAGE_VIEW: vkDestroyImageView(vk->dev, (VkImageView)h, NULL); break;
        case VK_OBJECT_TYPE_BUFFER: vkDestroyBuffer(vk->dev, (VkBuffer)h, NULL); break;
        case VK_OBJECT_TYPE_DEVICE_MEMORY: vkFreeMemory(vk->dev, (VkDeviceMemory)h, NULL); break;
        case VK_OBJECT_TYPE_PIPELINE: vkDestroyPipeline(vk->dev, (VkPipeline)h, NULL); break;
        case VK_OBJECT_TYPE_SHADER_MODULE: vkDestroyShaderModule(vk->dev, (VkShaderModule)h, NULL); break;
        default: break;
        }
    }
    s->ngarbage = 0;
}

#define FOGVK__H(x) ((uint64_t)(x))
static void fogvk__defer_image(fogvk *vk, fogvk_image *im)
{
    fogvk__defer(vk, VK_OBJECT_TYPE_IMAGE_VIEW, FOGVK__H(im->view));
    fogvk__defer(vk, VK_OBJECT_TYPE_IMAGE, FOGVK__H(im->image));
    fogvk__defer(vk, VK_OBJECT_TYPE_DEVICE_MEMORY, FOGVK__H(im->memory));
    memset(im, 0, sizeof *im);
}

/* ---- barriers: every image moves from its last recorded use to the next ---- */

static void fogvk__use(VkCommandBuffer cmd, fogvk_image *im, VkImageLayout layout, VkPipelineStageFlags stage,
                       VkAccessFlags access)
{
    const VkAccessFlags writes = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                                 VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkImageMemoryBarrier b;
    if (im->layout == layout && !(im->access & writes) && !(access & writes)) { /* read after read */
        im->stage |= stage;
        im->access |= access;
        return;
    }
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = im->access & writes;
    b.dstAccessMask = access;
    b.oldLayout = im->layout;
    b.newLayout = layout;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = im->image;
    b.subresourceRange.aspectMask = im->aspect;
    if (im->aspect == VK_IMAGE_ASPECT_DEPTH_BIT &&
        (im->format == VK_FORMAT_D16_UNORM_S8_UINT || im->format == VK_FORMAT_D24_UNORM_S8_UINT ||
         im->format == VK_FORMAT_D32_SFLOAT_S8_UINT)) /* (a layout is both aspects' without separateDepthStencilLayouts) */
        b.subresourceRange.aspectMask |= VK_IMAGE_ASPECT_STENCIL_BIT;
    b.subresourceRange.levelCount = 1;
    b.subresourceRange.layerCount = 1;
    vkCmdPipelineBarrier(cmd, im->stage ? im->stage : (VkPipelineStageFlags)VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, stage, 0,
                         0, NULL, 0, NULL, 1, &b);
    im->layout = layout;
    im->stage = stage;
    im->access = access;
}

static void fogvk__sampled(VkCommandBuffer cmd, fogvk_image *im)
{
    fogvk__use(cmd, im, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
               VK_ACCESS_SHADER_READ_BIT);
}

static void fogvk__end_rendering(fogvk *vk)
{
    if (!vk->rendering) return;
    vkCmdEndRendering(vk->frame.cmd);
    vk->rendering = 0;
}

/* The copies of the textures created since the last command buffer fogvol recorded into. */
static void fogvk__record_uploads(fogvk *vk)
{
    VkCommandBuffer cmd = vk->frame.cmd;
    while (vk->uploads) {
        fogvk_texture *t = vk->uploads;
        VkBufferImageCopy c;
        vk->uploads = t->next_upload;
        t->next_upload = NULL;
        fogvk__use(cmd, &t->img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_WRITE_BIT);
        memset(&c, 0, sizeof c);
        c.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        c.imageSubresource.layerCount = 1;
        c.imageExtent.width = (uint32_t)t->img.width;
        c.imageExtent.height = (uint32_t)t->img.height;
        c.imageExtent.depth = 1;
        vkCmdCopyBufferToImage(cmd, t->staging, t->img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
        fogvk__sampled(cmd, &t->img);
        fogvk__defer(vk, VK_OBJECT_TYPE_BUFFER, FOGVK__H(t->staging)); /* read by this frame's commands */
        fogvk__defer(vk, VK_OBJECT_TYPE_DEVICE_MEMORY, FOGVK__H(t->staging_memory));
        t->staging = VK_NULL_HANDLE;
        t->staging_memory = VK_NULL_HANDLE;
    }
}

/* ---- frames ---- */

void fogvk_set_frame(fogvol_backend *backend, const fogvk_frame *frame)
{
    fogvk *vk = (fogvk *)backend->user_data;
    fogvk_slot *s;
    vk->frame = *frame;
    vk->slot = frame->slot >= 0 && frame->slot < vk->nslots ? frame->slot : 0;
    vk->have_frame = frame->cmd != VK_NULL_HANDLE;
    s = &vk->slots[vk->slot];
    fogvk__free_garbage(vk, s); /* the slot's previous command buffer has completed */
    s->used = 0;
    memset(&vk->engine_color, 0, sizeof vk->engine_color);
    vk->engine_color.image = frame->color_image;
    vk->engine_color.view = frame->color_view;
    vk->engine_color.format = frame->color_format;
    vk->engine_color.aspect = VK_IMAGE_ASPECT_COLOR_BIT;
    vk->engine_color.width = frame->width;
    vk->engine_color.height = frame->height;
    vk->engine_color.layout = frame->color_layout;
    /* the engine's last write to each image is not known (a draw, a resolve or blit, a compute pass): the
       first barrier waits for every earlier command's writes */
    vk->engine_color.stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    vk->engine_color.access = VK_ACCESS_MEMORY_WRITE_BIT;
    memset(&vk->engine_depth, 0, sizeof vk->engine_depth);
    vk->engine_depth.image = frame->depth_image;
    vk->engine_depth.format = frame->depth_format;
    vk->engine_depth.aspect = VK_IMAGE_ASPECT_DEPTH_BIT;
    vk->engine_depth.width = frame->width;
    vk->engine_depth.height = frame->height;
    vk->engine_depth.layout = frame->depth_layout;
    vk->engine_depth.stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    vk->engine_depth.access = VK_ACCESS_MEMORY_WRITE_BIT;
}

VkCommandBuffer fogvk_frame_command(const fogvol_backend *backend)
{
    return ((const fogvk *)backend->user_data)->frame.cmd;
}

VkImageLayout fogvk_target_layout(const fogvol_backend *backend, fogvol_handle target)
{
    (void)backend;
    return target ? ((const fogvk_target *)target)->color.img.layout : VK_IMAGE_LAYOUT_UNDEFINED;
}

fogvol_result fogvk_engine_attachment(fogvol_backend *backend, VkCommandBuffer cmd, fogvol_native view)
{
    fogvk *vk = (fogvk *)backend->user_data;
    fogvk_target *t;
    for (t = vk->targets; t; t = t->next)
        if ((fogvol_native)t->color.img.view == view) {
            fogvk__use(cmd, &t->color.img, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                       VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
            return FOGVOL_SUCCESS;
        }
    return FOGVOL_ERROR_INVALID_ARGUMENT;
}

static fogvol_result fogvk__begin_frame(void *u, fogvol_frame_info *info)
{
    fogvk *vk = (fogvk *)u;
    if (!vk->have_frame) {
        fogvk__log(vk, "fogvk: fogvol_end_frame without fogvk_set_frame (no command buffer)");
        return FOGVOL_ERROR_INVALID_STATE;
    }
    if (info->draw_buffer > 0) return FOGVOL_ERROR_UNSUPPORTED; /* the engine hands one colour image */
    info->samples = 1;
    info->depth_zero_to_one = 1; /* Vulkan's depth range */
    info->clip_upper_left = 0;   /* NDC y -1 is row 0, as GL's lower-left origin is */
    info->depth_range[0] = 0.0f;
    info->depth_range[1] = 1.0f;
    fogvk__record_uploads(vk);
    return FOGVOL_SUCCESS;
}

/* The engine's images go back to the layouts it handed them in. */
static void fogvk__end_frame(void *u)
{
    fogvk *vk = (fogvk *)u;
    fogvk__end_rendering(vk);
    if (vk->engine_color.layout != vk->frame.color_layout) /* (only where a pass drew into it) */
        fogvk__use(vk->frame.cmd, &vk->engine_color, vk->frame.color_layout, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                   VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    if (vk->engine_depth.image && vk->engine_depth.layout != vk->frame.depth_layout)
        fogvk__use(vk->frame.cmd, &vk->engine_depth, vk->frame.depth_layout, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                   VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
}

/* ---- textures and targets ---- */

static VkFormat fogvk__format(fogvol_format f)
{
    return f == FOGVOL_FORMAT_R32F      ? VK_FORMAT_R32_SFLOAT
           : f == FOGVOL_FORMAT_RGBA32F ? VK_FORMAT_R32G32B32A32_SFLOAT
                                        : VK_FORMAT_R8G8B8A8_UNORM;
}

static fogvol_result fogvk__create_texture(void *u, const fogvol_texture_desc *d, fogvol_handle *out)
{
    fogvk *vk = (fogvk *)u;
    fogvk_texture *t;
    VkDeviceSize size;
    *out = 0;
    if (!d || d->width <= 0 || d->height <= 0 || !d->pixels) return FOGVOL_ERROR_INVALID_ARGUMENT;
    t = (fogvk_texture *)calloc(1, sizeof *t);
    if (!t) return FOGVOL_ERROR_OUT_OF_MEMORY;
    size = (VkDeviceSize)d->width * (VkDeviceSize)d->height * 4;
    if (fogvk__image(vk, &t->img, d->width, d->height, VK_FORMAT_R8G8B8A8_UNORM,
                     VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT) != VK_SUCCESS ||
        fogvk__buffer(vk, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, d->pixels, &t->staging, &t->staging_memory, NULL) !=
            VK_SUCCESS) {
        fogvk__log(vk, "fogvk: cannot create the texture %s", d->label ? d->label : "");
        fogvk__defer_image(vk, &t->img);
        free(t);
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    t->sampler = vk->samplers[(d->filter == FOGVOL_FILTER_LINEAR) * 2 + (d->wrap == FOGVOL_WRAP_CLAMP)];
    t->next_upload = vk->uploads; /* rows bottom to top: row 0 first, as the image stores it */
    vk->uploads = t;
    *out = (fogvol_handle)t;
    return FOGVOL_SUCCESS;
}

static void fogvk__destroy_texture(void *u, fogvol_handle h)
{
    fogvk *vk = (fogvk *)u;
    fogvk_texture *t = (fogvk_texture *)h, **p;
    if (!t) return;
    for (p = &vk->uploads; *p; p = &(*p)->next_upload)
        if (*p == t) {
            *p = t->next_upload;
            break;
        }
    fogvk__defer(vk, VK_OBJECT_TYPE_BUFFER, FOGVK__H(t->staging));
    fogvk__defer(vk, VK_OBJECT_TYPE_DEVICE_MEMORY, FOGVK__H(t->staging_memory));
    fogvk__defer_image(vk, &t->img);
    free(t);
}

static fogvk_target *fogvk__new_target(fogvk *vk, const fogvol_target_desc *d)
{
    fogvk_target *t = (fogvk_target *)calloc(1, sizeof *t);
    if (!t) return NULL;
    t->format = d->format;
    if (fogvk__image(vk, &t->color.img, d->width, d->height, fogvk__format(d->format),
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                         VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != VK_SUCCESS) {
        fogvk__defer_image(vk, &t->color.img);
        free(t);
        return NULL;
    }
    t->color.sampler = vk->samplers[d->linear ? 3 : 1];
    t->next = vk->targets;
    vk->targets = t;
    return t;
}

static void fogvk__destroy_target(void *u, fogvol_handle h)
{
    fogvk *vk = (fogvk *)u;
    fogvk_target *t = (fogvk_target *)h, **p;
    if (!t) return;
    for (p = &vk->targets; *p; p = &(*p)->next)
        if (*p == t) {
            *p = t->next;
            break;
        }
    if (t->second) fogvk__destroy_target(u, (fogvol_handle)t->second);
    fogvk__defer_image(vk, &t->depth);
    fogvk__defer_image(vk, &t->color.img);
    free(t);
}

static fogvol_result fogvk__create_target(void *u, const fogvol_target_desc *d, fogvol_handle *out)
{
    fogvk *vk = (fogvk *)u;
    fogvk_target *t;
    *out = 0;
    if (d->samples > 1) return FOGVOL_ERROR_UNSUPPORTED; /* no FOGVOL_CAP_MULTISAMPLE */
    t = fogvk__new_target(vk, d);
    if (!t) return FOGVOL_ERROR_FRAMEBUFFER;
    if (d->color_count == 2 && !(t->second = fogvk__new_target(vk, d))) {
        fogvk__destroy_target(u, (fogvol_handle)t);
        return FOGVOL_ERROR_FRAMEBUFFER;
    }
    if (d->share_depth) {
        t->share = (fogvk_target *)d->share_depth;
    } else if (d->depth && fogvk__image(vk, &t->depth, d->width, d->height, VK_FORMAT_D32_SFLOAT,
                                        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) != VK_SUCCESS) {
        fogvk__destroy_target(u, (fogvol_handle)t);
        return FOGVOL_ERROR_FRAMEBUFFER;
    }
    *out = (fogvol_handle)t;
    return FOGVOL_SUCCESS;
}

static fogvol_handle fogvk__target_attachment(void *u, fogvol_handle h, int index)
{
    const fogvk_target *t = (const fogvk_target *)h;
    (void)u;
    if (!t) return 0;
    return index == 0 ? h : index == 1 ? (fogvol_handle)t->second : 0;
}

static fogvol_native fogvk__native_texture(void *u, fogvol_handle h)
{
    (void)u;
    return h ? (fogvol_native)((const fogvk_texture *)h)->img.view : 0;
}

/* ---- programs and pipelines ---- */

static VkShaderModule fogvk__module(fogvk *vk, const char *const *src, int n, shaderc_shader_kind kind,
                                    const char *label)
{
    shaderc_compile_options_t opt = shaderc_compile_options_initialize();
    shaderc_compilation_result_t res;
    VkShaderModuleCreateInfo mi;
    VkShaderModule m = VK_NULL_HANDLE;
    size_t len = 0, at = 0;
    char *text;
    int i;
    for (i = 0; i < n; ++i) len += strlen(src[i]);
    text = (char *)malloc(len + 1);
    if (!text || !opt) {
        free(text);
        if (opt) shaderc_compile_options_release(opt);
        return VK_NULL_HANDLE;
    }
    for (i = 0; i < n; ++i) {
        size_t k = strlen(src[i]);
        memcpy(text + at, src[i], k);
        at += k;
    }
    text[len] = 0;
    shaderc_compile_options_set_target_env(opt, shaderc_target_env_vulkan, shaderc_env_version_vulkan_1_0);
    res = shaderc_compile_into_spv(vk->compiler, text, len, kind, label, "main", opt);
    if (shaderc_result_get_compilation_status(res) != shaderc_compilation_status_success) {
        fogvk__log(vk, "fogvk: %s: %s", label, shaderc_result_get_error_message(res));
    } else {
        memset(&mi, 0, sizeof mi);
        mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        mi.codeSize = shaderc_result_get_length(res);
        mi.pCode = (const uint32_t *)shaderc_result_get_bytes(res);
        if (vkCreateShaderModule(vk->dev, &mi, NULL, &m) != VK_SUCCESS) m = VK_NULL_HANDLE;
    }
    shaderc_result_release(res);
    shaderc_compile_options_release(opt);
    free(text);
    return m;
}

static fogvol_result fogvk__create_program(void *u, const fogvol_program_desc *d, fogvol_handle *out)
{
    fogvk *vk = (fogvk *)u;
    fogvk_program *p;
    const char *label = d->label ? d->label : "fogvol program";
    *out = 0;
    /* the pipeline layout is built from this layout: every program must share it */
    if (memcmp(&d->layout, &vk->ul, sizeof vk->ul) != 0) {
        fogvk__log(vk, "fogvk: %s: not the FOGVOL_GLSL_VULKAN layout", label);
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    p = (fogvk_program *)calloc(1, sizeof *p);
    if (!p) return FOGVOL_ERROR_OUT_OF_MEMORY;
    p->vs = fogvk__module(vk, d->vs, d->vs_count, shaderc_vertex_shader, label);
    p->fs = p->vs ? fogvk__module(vk, d->fs, d->fs_count, shaderc_fragment_shader, label) : VK_NULL_HANDLE;
    if (!p->fs) {
        if (p->vs) vkDestroyShaderModule(vk->dev, p->vs, NULL);
        free(p);
        return FOGVOL_ERROR_SHADER_COMPILE;
    }
    *out = (fogvol_handle)p;
    return FOGVOL_SUCCESS;
}

static void fogvk__destroy_program(void *u, fogvol_handle h)
{
    fogvk *vk = (fogvk *)u;
    fogvk_program *p = (fogvk_program *)h;
    int i;
    if (!p) return;
    for (i = 0; i < vk->npipes;)
        if (vk->pipes[i].program == p) {
            fogvk__defer(vk, VK_OBJECT_TYPE_PIPELINE, FOGVK__H(vk->pipes[i].pipeline));
            vk->pipes[i] = vk->pipes[--vk->npipes];
        } else {
            ++i;
        }
    fogvk__defer(vk, VK_OBJECT_TYPE_SHADER_MODULE, FOGVK__H(p->vs));
    fogvk__defer(vk, VK_OBJECT_TYPE_SHADER_MODULE, FOGVK__H(p->fs));
    free(p);
}

/* fogvol_pass_blend as Vulkan blend factors (the GL backend's glBlendFuncSeparate, one to one). */
static void fogvk__blend(const fogvk_pipeline *k, VkPipelineColorBlendAttachmentState *a)
{
    VkBlendFactor one = VK_BLEND_FACTOR_ONE, zero = VK_BLEND_FACTOR_ZERO;
    memset(a, 0, sizeof *a);
    a->colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                        VK_COLOR_COMPONENT_A_BIT;
    a->blendEnable = k->blend != FOGVOL_PASS_BLEND_NONE;
    a->colorBlendOp = a->alphaBlendOp =
        k->blend == FOGVOL_PASS_BLEND_SUBTRACT ? VK_BLEND_OP_REVERSE_SUBTRACT : VK_BLEND_OP_ADD;
    a->srcColorBlendFactor = a->dstColorBlendFactor = a->srcAlphaBlendFactor = a->dstAlphaBlendFactor = one;
    switch (k->blend) {
    case FOGVOL_PASS_BLEND_FOG:
    case FOGVOL_PASS_BLEND_LIGHT:
        a->srcColorBlendFactor = k->constant ? VK_BLEND_FACTOR_CONSTANT_COLOR : VK_BLEND_FACTOR_SRC_ALPHA;
        a->dstColorBlendFactor = k->blend == FOGVOL_PASS_BLEND_FOG ? VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA : one;
        a->srcAlphaBlendFactor = k->coverage ? one : zero;
        a->dstAlphaBlendFactor = k->coverage ? VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA : one;
        break;
    case FOGVOL_PASS_BLEND_MULTIPLY:
        a->srcColorBlendFactor = zero;
        a->dstColorBlendFactor = VK_BLEND_FACTOR_SRC_COLOR;
        a->srcAlphaBlendFactor = zero;
        a->dstAlphaBlendFactor = k->coverage ? VK_BLEND_FACTOR_SRC_ALPHA : one;
        break;
    case FOGVOL_PASS_BLEND_EMIT: a->srcAlphaBlendFactor = k->coverage ? one : zero; break;
    default: break;
    }
}

static VkPipeline fogvk__make_pipeline(fogvk *vk, const fogvk_pipeline *k)
{
    static const VkDynamicState dyn[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                         VK_DYNAMIC_STATE_CULL_MODE, VK_DYNAMIC_STATE_FRONT_FACE,
                                         VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE, VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE,
                                         VK_DYNAMIC_STATE_DEPTH_COMPARE_OP, VK_DYNAMIC_STATE_BLEND_CONSTANTS,
                                         VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE};
    VkPipelineShaderStageCreateInfo st[2];
    VkVertexInputBindingDescription vb = {0, 12, VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription va = {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
    VkPipelineVertexInputStateCreateInfo vi;
    VkPipelineInputAssemblyStateCreateInfo ia;
    VkPipelineViewportStateCreateInfo vp;
    VkPipelineRasterizationStateCreateInfo rs;
    VkPipelineMultisampleStateCreateInfo ms;
    VkPipelineDepthStencilStateCreateInfo ds;
    VkPipelineColorBlendAttachmentState att[2];
    VkPipelineColorBlendStateCreateInfo cb;
    VkPipelineDynamicStateCreateInfo dy;
    VkPipelineRenderingCreateInfo ri;
    VkGraphicsPipelineCreateInfo pi;
    VkPipeline pipe = VK_NULL_HANDLE;
    memset(st, 0, sizeof st);
    st[0].sType = st[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    st[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    st[0].module = k->program->vs;
    st[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    st[1].module = k->program->fs;
    st[0].pName = st[1].pName = "main";
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    vi.vertexBindingDescriptionCount = 1;
    vi.pVertexBindingDescriptions = &vb; /* (the stride is dynamic: fogvol_mesh_data.stride) */
    vi.vertexAttributeDescriptionCount = 1;
    vi.pVertexAttributeDescriptions = &va;
    memset(&ia, 0, sizeof ia);
    ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    memset(&vp, 0, sizeof vp);
    vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    vp.viewportCount = vp.scissorCount = 1;
    memset(&rs, 0, sizeof rs);
    rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.lineWidth = 1.0f;
    memset(&ms, 0, sizeof ms);
    ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    memset(&ds, 0, sizeof ds);
    ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    fogvk__blend(k, &att[0]);
    att[1] = att[0]; /* both attachments blend alike (GL: glBlendFunc for every draw buffer) */
    memset(&cb, 0, sizeof cb);
    cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    cb.attachmentCount = (uint32_t)k->color_count;
    cb.pAttachments = att;
    memset(&dy, 0, sizeof dy);
    dy.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dy.dynamicStateCount = (uint32_t)(sizeof dyn / sizeof dyn[0]);
    dy.pDynamicStates = dyn;
    memset(&ri, 0, sizeof ri);
    ri.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    ri.colorAttachmentCount = (uint32_t)k->color_count;
    ri.pColorAttachmentFormats = k->color;
    ri.depthAttachmentFormat = k->depth;
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    pi.pNext = &ri;
    pi.stageCount = 2;
    pi.pStages = st;
    pi.pVertexInputState = &vi;
    pi.pInputAssemblyState = &ia;
    pi.pViewportState = &vp;
    pi.pRasterizationState = &rs;
    pi.pMultisampleState = &ms;
    pi.pDepthStencilState = &ds;
    pi.pColorBlendState = &cb;
    pi.pDynamicState = &dy;
    pi.layout = vk->layout;
    if (vkCreateGraphicsPipelines(vk->dev, VK_NULL_HANDLE, 1, &pi, NULL, &pipe) != VK_SUCCESS) pipe = VK_NULL_HANDLE;
    return pipe;
}

/* The cached pipeline of (program, blend state, attachment formats), made on first use. */
static VkPipeline fogvk__pipeline(fogvk *vk, const fogvk_pipeline *key)
{
    int i;
    for (i = 0; i < vk->npipes; ++i) {
        const fogvk_pipeline *k = &vk->pipes[i];
        if (k->program == key->program && k->blend == key->blend && k->coverage == key->coverage &&
            k->constant == key->constant && k->color_count == key->color_count && k->color[0] == key->color[0] &&
            k->color[1] == key->color[1] && k->depth == key->depth)
            return k->pipeline;
    }
    if (vk->npipes == vk->pipe_cap) {
        int cap = vk->pipe_cap ? vk->pipe_cap * 2 : 32;
        fogvk_pipeline *p = (fogvk_pipeline *)realloc(vk->pipes, (size_t)cap * sizeof *p);
        if (!p) return VK_NULL_HANDLE;
        vk->pipes = p;
        vk->pipe_cap = cap;
    }
    vk->pipes[vk->npipes] = *key;
    vk->pipes[vk->npipes].pipeline = fogvk__make_pipeline(vk, key);
    if (!vk->pipes[vk->npipes].pipeline) {
        fogvk__log(vk, "fogvk: vkCreateGraphicsPipelines failed");
        return VK_NULL_HANDLE;
    }
    return vk->pipes[vk->npipes++].pipeline;
}

/* ---- meshes ---- */

static fogvol_result fogvk__create_mesh(void *u, const fogvol_mesh_data *d, fogvol_handle *out)
{
    fogvk *vk = (fogvk *)u;
    fogvk_mesh *m;
    VkDeviceSize stride = d->stride ? (VkDeviceSize)d->stride : 12, vbytes, ibytes;
    int i16 = d->index_type == FOGVOL_INDEX_UINT16;
    *out = 0;
    if (!d->positions || d->vertex_count <= 0 || d->index_count <= 0 || (i16 ? !d->indices16 : !d->indices))
        return FOGVOL_ERROR_INVALID_ARGUMENT;
    m = (fogvk_mesh *)calloc(1, sizeof *m);
    if (!m) return FOGVOL_ERROR_OUT_OF_MEMORY;
    /* the bytes as the engine laid them out: vertex i's x at offset + i * stride */
    vbytes = (VkDeviceSize)d->offset + (VkDeviceSize)(d->vertex_count - 1) * stride + 12;
    ibytes = (VkDeviceSize)d->index_count * (i16 ? 2u : 4u);
    m->voffset = (VkDeviceSize)d->offset;
    m->stride = stride;
    m->itype = i16 ? VK_INDEX_TYPE_UINT16 : VK_INDEX_TYPE_UINT32;
    m->count = (uint32_t)d->index_count;
    if (fogvk__buffer(vk, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, d->positions, &m->vbuf, &m->vmem, NULL) !=
            VK_SUCCESS ||
        fogvk__buffer(vk, ibytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                      i16 ? (const void *)d->indices16 : (const void *)d->indices, &m->ibuf, &m->imem,
                      NULL) != VK_SUCCESS) {
        if (m->vbuf) vkDestroyBuffer(vk->dev, m->vbuf, NULL);
        if (m->vmem) vkFreeMemory(vk->dev, m->vmem, NULL);
        free(m);
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    }
    *out = (fogvol_handle)m;
    return FOGVOL_SUCCESS;
}

static void fogvk__free_mesh(fogvk *vk, fogvk_mesh *m)
{
    fogvk__defer(vk, VK_OBJECT_TYPE_BUFFER, FOGVK__H(m->vbuf));
    fogvk__defer(vk, VK_OBJECT_TYPE_DEVICE_MEMORY, FOGVK__H(m->vmem));
    fogvk__defer(vk, VK_OBJECT_TYPE_BUFFER, FOGVK__H(m->ibuf));
    fogvk__defer(vk, VK_OBJECT_TYPE_DEVICE_MEMORY, FOGVK__H(m->imem));
}

static void fogvk__destroy_mesh(void *u, fogvol_handle h)
{
    fogvk_mesh *m = (fogvk_mesh *)h;
    if (!m) return;
    fogvk__free_mesh((fogvk *)u, m);
    free(m);
}

/* ---- passes ---- */

/* The pass's samplers and uniform block, written straight into the command buffer (push descriptors);
   0 when the frame's uniform ring is full (the pass then draws nothing). */
static int fogvk__descriptors(fogvk *vk, const fogvol_pass *p)
{
    VkWriteDescriptorSet w[FOGVK_SAMPLERS + 1];
    VkDescriptorImageInfo img[FOGVK_SAMPLERS];
    VkDescriptorBufferInfo ubo;
    fogvk_slot *s = &vk->slots[vk->slot];
    int i;
    for (i = 0; i < FOGVK_SAMPLERS; ++i) {
        fogvk_texture *t = p->textures[i] ? (fogvk_texture *)p->textures[i] : vk->dummy;
        img[i].sampler = t->sampler;
        img[i].imageView = t->img.view;
        img[i].imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        if (p->native_textures[i]) { /* the engine's depth (or our copy of it): nearest, clamped */
            img[i].sampler = vk->samplers[1];
            img[i].imageView = (VkImageView)p->native_textures[i];
        }
        memset(&w[i], 0, sizeof w[i]);
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstBinding = (uint32_t)vk->ul.sampler_bindings[i];
        w[i].descriptorCount = 1;
        w[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        w[i].pImageInfo = &img[i];
    }
    /* fogvol_pass.uniforms is the std140 block as it is (fogvol_uniform_layout) */
    if (s->used + (VkDeviceSize)vk->ul.pass_size > FOGVK_RING) {
        fogvk__log(vk, "fogvk: more passes in a frame than the uniform ring holds (FOGVK_RING): pass skipped");
        return 0;
    }
    memcpy(s->ring_data + s->used, p->uniforms, (size_t)vk->ul.pass_size);
    ubo.buffer = s->ring;
    ubo.offset = s->used;
    ubo.range = (VkDeviceSize)vk->ul.pass_size;
    s->used += ((VkDeviceSize)vk->ul.pass_size + vk->ubo_align - 1) / vk->ubo_align * vk->ubo_align;
    memset(&w[i], 0, sizeof w[i]);
    w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w[i].dstBinding = (uint32_t)vk->ul.pass_binding;
    w[i].descriptorCount = 1;
    w[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    w[i].pBufferInfo = &ubo;
    vk->push_descriptors(vk->frame.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, vk->layout, 0, FOGVK_SAMPLERS + 1, w);
    return 1;
}

/* Barriers: the textures a pass samples to SHADER_READ_ONLY, its attachments to ATTACHMENT. */
static void fogvk__pass_images(fogvk *vk, const fogvol_pass *p, fogvk_image **color, int ncolor, fogvk_image *depth)
{
    VkCommandBuffer cmd = vk->frame.cmd;
    int i;
    for (i = 0; i < FOGVK_SAMPLERS; ++i) {
        if (p->native_textures[i]) {
            if ((VkImageView)p->native_textures[i] == vk->depth_copy.view) fogvk__sampled(cmd, &vk->depth_copy);
        } else {
            fogvk__sampled(cmd, p->textures[i] ? &((fogvk_texture *)p->textures[i])->img : &vk->dummy->img);
        }
    }
    for (i = 0; i < ncolor; ++i)
        fogvk__use(cmd, color[i], VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    if (depth)
        fogvk__use(cmd, depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

static void fogvk__begin_rendering(fogvk *vk, const fogvol_pass *p, fogvk_image **color, int ncolor,
                                   fogvk_image *depth, int clear_depth)
{
    VkRenderingAttachmentInfo ca[2], da;
    VkRenderingInfo ri;
    int i, scissored = p->scissor[2] > 0 && p->scissor[3] > 0;
    memset(ca, 0, sizeof ca);
    for (i = 0; i < ncolor; ++i) {
        ca[i].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        ca[i].imageView = color[i]->view;
        ca[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        ca[i].loadOp = p->clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        ca[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        memcpy(ca[i].clearValue.color.float32, p->clear_color, sizeof p->clear_color);
    }
    memset(&da, 0, sizeof da);
    da.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    da.imageView = depth ? depth->view : VK_NULL_HANDLE;
    da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    da.loadOp = clear_depth ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    da.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    da.clearValue.depthStencil.depth = 1.0f;
    memset(&ri, 0, sizeof ri);
    ri.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    /* a clear covers the scissor rectangle only, as glClear under GL's scissor test does */
    ri.renderArea.offset.x = scissored ? p->scissor[0] : 0;
    ri.renderArea.offset.y = scissored ? p->scissor[1] : 0;
    ri.renderArea.extent.width = (uint32_t)(scissored ? p->scissor[2] : color[0]->width);
    ri.renderArea.extent.height = (uint32_t)(scissored ? p->scissor[3] : color[0]->height);
    ri.layerCount = 1;
    ri.colorAttachmentCount = (uint32_t)ncolor;
    ri.pColorAttachments = ca;
    ri.pDepthAttachment = depth ? &da : NULL;
    vkCmdBeginRendering(vk->frame.cmd, &ri);
    vk->rendering = 1;
}

static void fogvk__dynamic_state(fogvk *vk, const fogvol_pass *p, const fogvk_image *c0)
{
    VkCommandBuffer cmd = vk->frame.cmd;
    VkViewport v;
    VkRect2D sc;
    v.x = (float)p->viewport[0];
    v.y = (float)p->viewport[1]; /* row 0 is framebuffer y 0: GL's window y, unchanged */
    v.width = (float)p->viewport[2];
    v.height = (float)p->viewport[3];
    v.minDepth = 0.0f;
    v.maxDepth = 1.0f;
    vkCmdSetViewport(cmd, 0, 1, &v);
    if (p->scissor[2] > 0 && p->scissor[3] > 0) {
        sc.offset.x = p->scissor[0];
        sc.offset.y = p->scissor[1];
        sc.extent.width = (uint32_t)p->scissor[2];
        sc.extent.height = (uint32_t)p->scissor[3];
    } else {
        sc.offset.x = sc.offset.y = 0;
        sc.extent.width = (uint32_t)c0->width;
        sc.extent.height = (uint32_t)c0->height;
    }
    vkCmdSetScissor(cmd, 0, 1, &sc);
    vkCmdSetCullMode(cmd, p->cull == FOGVOL_CULL_BACK    ? VK_CULL_MODE_BACK_BIT
                          : p->cull == FOGVOL_CULL_FRONT ? VK_CULL_MODE_FRONT_BIT
                                                         : VK_CULL_MODE_NONE);
    vkCmdSetFrontFace(cmd, VK_FRONT_FACE_CLOCKWISE); /* GL's counter-clockwise (see the top of the file) */
    vkCmdSetDepthTestEnable(cmd, p->depth_test ? VK_TRUE : VK_FALSE);
    vkCmdSetDepthWriteEnable(cmd, p->depth_write ? VK_TRUE : VK_FALSE);
    vkCmdSetDepthCompareOp(cmd, VK_COMPARE_OP_LESS);
    vkCmdSetBlendConstants(cmd, p->blend_color);
}

static void fogvk__begin_pass(void *u, const fogvol_pass *p)
{
    fogvk *vk = (fogvk *)u;
    fogvk_target *t = (fogvk_target *)p->target;
    fogvk_image *color[2], *depth = NULL;
    fogvk_pipeline key;
    VkPipeline pipe;
    int ncolor = 1;
    fogvk__end_rendering(vk);
    fogvk__record_uploads(vk);
    vk->pass = p;
    vk->pass_target = t;
    color[0] = t ? &t->color.img : &vk->engine_color;
    if (t && t->second) color[ncolor++] = &t->second->color.img;
    if (t) depth = t->depth.image ? &t->depth : t->share && t->share->depth.image ? &t->share->depth : NULL;
    fogvk__pass_images(vk, p, color, ncolor, depth);
    memset(&key, 0, sizeof key);
    key.program = (const fogvk_program *)p->program;
    key.blend = (int)p->blend;
    key.coverage = p->alpha_coverage != 0;
    key.constant = p->blend_constant != 0;
    key.color_count = ncolor;
    key.color[0] = color[0]->format;
    key.color[1] = ncolor > 1 ? color[1]->format : VK_FORMAT_UNDEFINED;
    key.depth = depth ? depth->format : VK_FORMAT_UNDEFINED;
    fogvk__begin_rendering(vk, p, color, ncolor, depth, p->clear && t && t->depth.image);
    pipe = key.program ? fogvk__pipeline(vk, &key) : VK_NULL_HANDLE;
    if (!pipe) {
        vk->pass = NULL; /* draws are skipped: nothing is drawn rather than something wrong */
        return;
    }
    vkCmdBindPipeline(vk->frame.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
    fogvk__dynamic_state(vk, p, color[0]);
    if (!fogvk__descriptors(vk, p)) vk->pass = NULL;
}

static void fogvk__set_draw(void *u, const fogvol_draw *d)
{
    fogvk *vk = (fogvk *)u;
    unsigned char pc[128];
    const int *o = vk->ul.draw_offsets;
    if (!vk->pass) return;
    memset(pc, 0, sizeof pc);
    memcpy(pc + o[FOGVOL_DRAW_MVP], d->mvp, sizeof d->mvp);
    memcpy(pc + o[FOGVOL_DRAW_DEPTH], d->depth, sizeof d->depth);
    memcpy(pc + o[FOGVOL_DRAW_EXTINCTION], d->extinction, sizeof d->extinction);
    memcpy(pc + o[FOGVOL_DRAW_EMISSION], d->emission, sizeof d->emission);
    memcpy(pc + o[FOGVOL_DRAW_SIGN], &d->sign, sizeof d->sign);
    vkCmdPushConstants(vk->frame.cmd, vk->layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                       (uint32_t)vk->ul.draw_size, pc);
    vkCmdSetFrontFace(vk->frame.cmd, d->front_cw ? VK_FRONT_FACE_COUNTER_CLOCKWISE : VK_FRONT_FACE_CLOCKWISE);
}

static void fogvk__draw_mesh(void *u, fogvol_handle h, const fogvol_draw *d)
{
    fogvk *vk = (fogvk *)u;
    const fogvk_mesh *m = (const fogvk_mesh *)h;
    if (!m || !vk->pass) return;
    fogvk__set_draw(u, d);
    vkCmdBindVertexBuffers2(vk->frame.cmd, 0, 1, &m->vbuf, &m->voffset, NULL, &m->stride);
    vkCmdBindIndexBuffer(vk->frame.cmd, m->ibuf, 0, m->itype);
    vkCmdDrawIndexed(vk->frame.cmd, m->count, 1, 0, 0, 0);
}

static void fogvk__draw_fullscreen(void *u)
{
    fogvk *vk = (fogvk *)u;
    if (!vk->pass) return;
    vkCmdBindVertexBuffers2(vk->frame.cmd, 0, 1, &vk->fullscreen.vbuf, &vk->fullscreen.voffset, NULL,
                            &vk->fullscreen.stride);
    vkCmdDraw(vk->frame.cmd, 3, 1, 0, 0);
}

static void fogvk__end_pass(void *u)
{
    fogvk *vk = (fogvk *)u;
    fogvk__end_rendering(vk);
    vk->pass = NULL;
}

/* ---- the engine's depth, read-back, queries ---- */

static fogvol_result fogvk__copy_depth(void *u, fogvol_native framebuffer, int bound, const int rect[4], int samples,
                                       fogvol_native *texture)
{
    fogvk *vk = (fogvk *)u;
    VkCommandBuffer cmd = vk->frame.cmd;
    VkImageCopy c;
    (void)framebuffer;
    if (!bound || !vk->engine_depth.image || samples > 1) { /* (no FOGVOL_CAP_MULTISAMPLE: samples is 0) */
        fogvk__log(vk, "fogvk: copy_depth copies the single-sample depth image of fogvk_frame only");
        return FOGVOL_ERROR_UNSUPPORTED;
    }
    fogvk__end_rendering(vk);
    if (vk->depth_copy.width != vk->frame.width || vk->depth_copy.height != vk->frame.height ||
        vk->depth_copy.format != vk->frame.depth_format) {
        fogvk__defer_image(vk, &vk->depth_copy);
        if (fogvk__image(vk, &vk->depth_copy, vk->frame.width, vk->frame.height, vk->frame.depth_format,
                         VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT) != VK_SUCCESS) {
            fogvk__defer_image(vk, &vk->depth_copy);
            return FOGVOL_ERROR_OUT_OF_MEMORY;
        }
    }
    fogvk__use(cmd, &vk->engine_depth, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_READ_BIT);
    fogvk__use(cmd, &vk->depth_copy, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_WRITE_BIT);
    memset(&c, 0, sizeof c);
    c.srcSubresource.aspectMask = c.dstSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    c.srcSubresource.layerCount = c.dstSubresource.layerCount = 1;
    c.srcOffset.x = c.dstOffset.x = rect[0]; /* the same texel coordinates */
    c.srcOffset.y = c.dstOffset.y = rect[1];
    c.extent.width = (uint32_t)rect[2];
    c.extent.height = (uint32_t)rect[3];
    c.extent.depth = 1;
    vkCmdCopyImage(cmd, vk->engine_depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, vk->depth_copy.image,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    fogvk__sampled(cmd, &vk->depth_copy);
    *texture = (fogvol_native)vk->depth_copy.view;
    return FOGVOL_SUCCESS;
}

static size_t fogvk__pixel_bytes(fogvol_format f) { return f == FOGVOL_FORMAT_RGBA32F ? 16u : 4u; }

/* The debug read-back: the only place that waits for the GPU inside a frame (the engine's flush). */
static fogvol_result fogvk__read_target(void *u, fogvol_handle h, unsigned char *out, size_t size)
{
    fogvk *vk = (fogvk *)u;
    fogvk_target *t = (fogvk_target *)h;
    VkBuffer buf;
    VkDeviceMemory mem;
    VkBufferImageCopy c;
    VkBufferMemoryBarrier bb;
    void *map = NULL;
    size_t bytes;
    if (!t || !out) return FOGVOL_ERROR_INVALID_ARGUMENT;
    bytes = (size_t)t->color.img.width * (size_t)t->color.img.height * fogvk__pixel_bytes(t->format);
    if (size < bytes) return FOGVOL_ERROR_INVALID_ARGUMENT;
    if (!vk->have_frame || !vk->frame.flush) return FOGVOL_ERROR_UNSUPPORTED;
    if (fogvk__buffer(vk, (VkDeviceSize)bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, NULL, &buf, &mem, &map) != VK_SUCCESS)
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    fogvk__end_rendering(vk);
    fogvk__use(vk->frame.cmd, &t->color.img, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_TRANSFER_READ_BIT);
    memset(&c, 0, sizeof c);
    c.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    c.imageSubresource.layerCount = 1;
    c.imageExtent.width = (uint32_t)t->color.img.width;
    c.imageExtent.height = (uint32_t)t->color.img.height;
    c.imageExtent.depth = 1;
    vkCmdCopyImageToBuffer(vk->frame.cmd, t->color.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf, 1, &c);
    memset(&bb, 0, sizeof bb);
    bb.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    bb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.buffer = buf;
    bb.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(vk->frame.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, NULL, 1, &bb,
                         0, NULL);
    vk->frame.cmd = vk->frame.flush(vk->frame.flush_user_data, vk->frame.cmd); /* submit and wait */
    if (vk->frame.cmd) memcpy(out, map, bytes); /* rows in the image's order: row 0 first */
    vkUnmapMemory(vk->dev, mem);
    vkDestroyBuffer(vk->dev, buf, NULL); /* the GPU is done with it */
    vkFreeMemory(vk->dev, mem, NULL);
    if (!vk->frame.cmd) {
        vk->have_frame = 0;
        return FOGVOL_ERROR_BACKEND;
    }
    return FOGVOL_SUCCESS;
}

static fogvol_result fogvk__create_query(void *u, fogvol_handle *out)
{
    fogvk *vk = (fogvk *)u;
    int i;
    for (i = 0; i < FOGVK_QUERIES; ++i)
        if (!vk->query_used[i]) {
            vk->query_used[i] = 1;
            *out = (fogvol_handle)(i + 1);
            return FOGVOL_SUCCESS;
        }
    return FOGVOL_ERROR_OUT_OF_MEMORY;
}

static void fogvk__destroy_query(void *u, fogvol_handle q)
{
    if (q) ((fogvk *)u)->query_used[q - 1] = 0;
}

/* fogvol begins a query again only after its result arrived: the host reset cannot race the GPU */
static int fogvk__begin_query(void *u, fogvol_handle q)
{
    fogvk *vk = (fogvk *)u;
    if (!vk->rendering) return 0;
    vkResetQueryPool(vk->dev, vk->queries, (uint32_t)(q - 1), 1);
    vkCmdBeginQuery(vk->frame.cmd, vk->queries, (uint32_t)(q - 1), VK_QUERY_CONTROL_PRECISE_BIT);
    return 1;
}

static void fogvk__end_query(void *u, fogvol_handle q)
{
    fogvk *vk = (fogvk *)u;
    vkCmdEndQuery(vk->frame.cmd, vk->queries, (uint32_t)(q - 1));
}

static int fogvk__query_result(void *u, fogvol_handle q, uint64_t *samples)
{
    fogvk *vk = (fogvk *)u;
    uint64_t r[2] = {0, 0}; /* the count, then availability */
    VkResult res = vkGetQueryPoolResults(vk->dev, vk->queries, (uint32_t)(q - 1), 1, sizeof r, r, sizeof r,
                                         VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
    if ((res != VK_SUCCESS && res != VK_NOT_READY) || !r[1]) return 0; /* never waits */
    *samples = r[0];
    return 1;
}

/* ---- creation ---- */

static void fogvk__destroy(void *u)
{
    fogvk *vk = (fogvk *)u;
    int i;
    vkDeviceWaitIdle(vk->dev);
    if (vk->dummy) fogvk__destroy_texture(vk, (fogvol_handle)vk->dummy);
    fogvk__free_mesh(vk, &vk->fullscreen);
    fogvk__defer_image(vk, &vk->depth_copy);
    for (i = 0; i < vk->npipes; ++i) fogvk__defer(vk, VK_OBJECT_TYPE_PIPELINE, FOGVK__H(vk->pipes[i].pipeline));
    for (i = 0; i < vk->nslots; ++i) {
        fogvk__free_garbage(vk, &vk->slots[i]);
        free(vk->slots[i].garbage);
        if (vk->slots[i].ring) vkDestroyBuffer(vk->dev, vk->slots[i].ring, NULL);
        if (vk->slots[i].ring_memory) vkFreeMemory(vk->dev, vk->slots[i].ring_memory, NULL);
    }
    for (i = 0; i < 4; ++i)
        if (vk->samplers[i]) vkDestroySampler(vk->dev, vk->samplers[i], NULL);
    if (vk->queries) vkDestroyQueryPool(vk->dev, vk->queries, NULL);
    if (vk->layout) vkDestroyPipelineLayout(vk->dev, vk->layout, NULL);
    if (vk->set_layout) vkDestroyDescriptorSetLayout(vk->dev, vk->set_layout, NULL);
    if (vk->compiler) shaderc_compiler_release(vk->compiler);
    free(vk->pipes);
    free(vk);
}

/* One descriptor set of push descriptors (8 samplers, the pass block) and the push constants, as
   fogvol_dialect_layout(FOGVOL_GLSL_VULKAN) places them. */
static VkResult fogvk__pipeline_layout(fogvk *vk)
{
    VkDescriptorSetLayoutBinding b[FOGVK_SAMPLERS + 1];
    VkDescriptorSetLayoutCreateInfo si;
    VkPushConstantRange pc;
    VkPipelineLayoutCreateInfo li;
    VkResult r;
    int i;
    memset(b, 0, sizeof b);
    for (i = 0; i <= FOGVK_SAMPLERS; ++i) {
        b[i].binding = (uint32_t)(i < FOGVK_SAMPLERS ? vk->ul.sampler_bindings[i] : vk->ul.pass_binding);
        b[i].descriptorType = i < FOGVK_SAMPLERS ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
                                                 : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
        b[i].descriptorCount = 1;
        b[i].stageFlags = i < FOGVK_SAMPLERS ? VK_SHADER_STAGE_FRAGMENT_BIT
                                             : VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    }
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    si.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    si.bindingCount = FOGVK_SAMPLERS + 1;
    si.pBindings = b;
    r = vkCreateDescriptorSetLayout(vk->dev, &si, NULL, &vk->set_layout);
    if (r != VK_SUCCESS) return r;
    pc.stageFlags = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    pc.offset = 0;
    pc.size = (uint32_t)vk->ul.draw_size;
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    li.setLayoutCount = 1;
    li.pSetLayouts = &vk->set_layout;
    li.pushConstantRangeCount = 1;
    li.pPushConstantRanges = &pc;
    return vkCreatePipelineLayout(vk->dev, &li, NULL, &vk->layout);
}

static VkResult fogvk__samplers(fogvk *vk)
{
    int i;
    for (i = 0; i < 4; ++i) {
        VkSamplerCreateInfo si;
        VkResult r;
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
        si.magFilter = si.minFilter = (i & 2) ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
        si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        si.addressModeU = si.addressModeV = si.addressModeW =
            (i & 1) ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE : VK_SAMPLER_ADDRESS_MODE_REPEAT;
        si.maxLod = 0.0f;
        r = vkCreateSampler(vk->dev, &si, NULL, &vk->samplers[i]);
        if (r != VK_SUCCESS) return r;
    }
    return VK_SUCCESS;
}

/* What the device can do, as fogvol's caps. */
static unsigned fogvk__caps(fogvk *vk)
{
    VkFormatProperties r32, rgba32;
    VkPhysicalDeviceProperties props;
    const VkFormatFeatureFlags blend = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT;
    unsigned caps = FOGVOL_CAP_MRT | FOGVOL_CAP_HIGHP_FRAGMENT | FOGVOL_CAP_DEPTH_TEXTURE | FOGVOL_CAP_MESH_LAYOUT |
                    FOGVOL_CAP_BLEND_CONSTANT | FOGVOL_CAP_FLOAT_TARGET;
    vkGetPhysicalDeviceProperties(vk->pd, &props);
    if (props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) caps |= FOGVOL_CAP_SOFTWARE_RENDERER; /* (lavapipe) */
    vkGetPhysicalDeviceFormatProperties(vk->pd, VK_FORMAT_R32_SFLOAT, &r32);
    vkGetPhysicalDeviceFormatProperties(vk->pd, VK_FORMAT_R32G32B32A32_SFLOAT, &rgba32);
    if ((r32.optimalTilingFeatures & blend) && (rgba32.optimalTilingFeatures & blend)) caps |= FOGVOL_CAP_FLOAT_BLEND;
    if (r32.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) caps |= FOGVOL_CAP_FILTER_FLOAT;
    return caps;
}

static fogvol_result fogvk__setup(fogvk *vk, const fogvk_desc *d)
{
    static const float tri[9] = {-1.0f, -1.0f, 0.0f, 3.0f, -1.0f, 0.0f, -1.0f, 3.0f, 0.0f};
    static const unsigned char white[4] = {255, 255, 255, 255};
    VkPhysicalDeviceProperties props;
    VkQueryPoolCreateInfo qi;
    fogvol_texture_desc td;
    fogvol_handle h;
    int i;
    vkGetPhysicalDeviceProperties(vk->pd, &props);
    vkGetPhysicalDeviceMemoryProperties(vk->pd, &vk->mem);
    vk->ubo_align = props.limits.minUniformBufferOffsetAlignment ? props.limits.minUniformBufferOffsetAlignment : 1;
    vk->push_descriptors =
        (PFN_vkCmdPushDescriptorSetKHR)vkGetDeviceProcAddr(vk->dev, "vkCmdPushDescriptorSetKHR");
    vk->compiler = shaderc_compiler_initialize();
    if (!vk->push_descriptors || !vk->compiler || fogvol_dialect_layout(FOGVOL_GLSL_VULKAN, &vk->ul) != FOGVOL_SUCCESS)
        return FOGVOL_ERROR_MISSING_FUNCTION;
    if (fogvk__pipeline_layout(vk) != VK_SUCCESS || fogvk__samplers(vk) != VK_SUCCESS)
        return FOGVOL_ERROR_BACKEND;
    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qi.queryType = VK_QUERY_TYPE_OCCLUSION;
    qi.queryCount = FOGVK_QUERIES;
    if (vkCreateQueryPool(vk->dev, &qi, NULL, &vk->queries) != VK_SUCCESS) return FOGVOL_ERROR_BACKEND;
    vkResetQueryPool(vk->dev, vk->queries, 0, FOGVK_QUERIES);
    vk->nslots = d->frames_in_flight > 0 ? d->frames_in_flight : 2;
    if (vk->nslots > FOGVK_MAX_SLOTS) vk->nslots = FOGVK_MAX_SLOTS;
    for (i = 0; i < vk->nslots; ++i)
        if (fogvk__buffer(vk, FOGVK_RING, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, NULL, &vk->slots[i].ring,
                          &vk->slots[i].ring_memory, (void **)&vk->slots[i].ring_data) != VK_SUCCESS)
            return FOGVOL_ERROR_OUT_OF_MEMORY;
    vk->fullscreen.stride = 12;
    vk->fullscreen.count = 3;
    if (fogvk__buffer(vk, sizeof tri, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, tri, &vk->fullscreen.vbuf,
                      &vk->fullscreen.vmem, NULL) != VK_SUCCESS)
        return FOGVOL_ERROR_OUT_OF_MEMORY;
    memset(&td, 0, sizeof td);
    td.width = td.height = 1;
    td.pixels = white;
    td.label = "fogvk dummy";
    if (fogvk__create_texture(vk, &td, &h) != FOGVOL_SUCCESS) return FOGVOL_ERROR_OUT_OF_MEMORY;
    vk->dummy = (fogvk_texture *)h;
    return FOGVOL_SUCCESS;
}

fogvol_result fogvk_create(const fogvk_desc *d, fogvol_backend *out)
{
    fogvk *vk;
    fogvol_result r;
    if (!d || !out || !d->device || !d->physical_device) return FOGVOL_ERROR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    vk = (fogvk *)calloc(1, sizeof *vk);
    if (!vk) return FOGVOL_ERROR_OUT_OF_MEMORY;
    vk->pd = d->physical_device;
    vk->dev = d->device;
    vk->log = d->logger;
    r = fogvk__setup(vk, d);
    if (r != FOGVOL_SUCCESS) {
        fogvk__log(vk, "fogvk: set-up failed: %s", fogvol_result_string(r));
        fogvk__destroy(vk);
        return r;
    }
    out->user_data = vk;
    out->dialect = FOGVOL_GLSL_VULKAN;
    out->caps = fogvk__caps(vk);
    out->begin_frame = fogvk__begin_frame;
    out->end_frame = fogvk__end_frame;
    out->create_texture = fogvk__create_texture;
    out->destroy_texture = fogvk__destroy_texture;
    out->create_target = fogvk__create_target;
    out->destroy_target = fogvk__destroy_target;
    out->create_program = fogvk__create_program;
    out->destroy_program = fogvk__destroy_program;
    out->create_mesh = fogvk__create_mesh;
    out->destroy_mesh = fogvk__destroy_mesh;
    out->begin_pass = fogvk__begin_pass;
    out->set_draw = fogvk__set_draw;
    out->draw_mesh = fogvk__draw_mesh;
    out->draw_fullscreen = fogvk__draw_fullscreen;
    out->end_pass = fogvk__end_pass;
    out->read_target = fogvk__read_target;
    out->destroy = fogvk__destroy;
    out->native_texture = fogvk__native_texture;
    out->target_attachment = fogvk__target_attachment;
    out->copy_depth = fogvk__copy_depth;
    out->create_query = fogvk__create_query;
    out->destroy_query = fogvk__destroy_query;
    out->begin_query = fogvk__begin_query;
    out->end_query = fogvk__end_query;
    out->query_result = fogvk__query_result;
    return FOGVOL_SUCCESS;
}

#endif /* FOGVOL_VULKAN_IMPLEMENTATION */
