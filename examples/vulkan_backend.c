/* vulkan_backend.c - an engine on Vulkan that lets fogvol draw its fog volumes through a
   fogvol_backend of its own (examples/fogvol_vulkan.h). Headless: Mesa's lavapipe will do.

   The engine renders its opaque scene (flat-coloured occluders, depth tested) into its own colour
   and depth images with its own pipeline, then hands the command buffer to fogvol, which records
   its passes into it; the engine submits once per frame and waits only to read the picture back
   (a debug read-back of fogvol's thickness is the one wait inside a frame: the flush below).

     vulkan_backend [OUT.png]            one frame, FLOAT tier, engine depth reused -> OUT.png
     vulkan_backend --tier ps20 OUT.png  another tier (ps13, ps20, mrt, float)
     vulkan_backend --check              the self-check (examples/vulkan_check.h): every tier the
                                         backend runs, several frames with the camera and occluders
                                         moving, against the ray caster and the GL backend's picture
     vulkan_backend --bench              milliseconds per frame, this backend beside the GL one

   The validation layers (VK_LAYER_KHRONOS_validation) are on when installed; every message they
   send is printed and counted, from vkCreateInstance to the end of the program: the count is reported
   after the last Vulkan object is gone, the run fails on any (the picture and --check alike), and a
   message after the count was reported fails it too (report_validation_count).
   Build: cc -std=c99 -I. examples/vulkan_backend.c -lvulkan -l:libshaderc_combined.a -lstdc++ -lOSMesa -lm */
#define FOGVOL_IMPLEMENTATION
#include "fogvol.h"
#include <vulkan/vulkan.h>
#define FOGVOL_VULKAN_IMPLEMENTATION
#include "examples/fogvol_vulkan.h"
#include "tests/shapes.h"
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FRAMES_IN_FLIGHT 2

/* ---- the engine ------------------------------------------------------------------------- */

typedef struct engine_mesh {
    VkBuffer vbuf, ibuf;
    VkDeviceMemory vmem, imem;
    uint32_t count;
} engine_mesh;

typedef struct engine {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice pd;
    VkDevice dev;
    uint32_t family;
    VkQueue queue;
    VkCommandPool pool;
    VkCommandBuffer cmd[FRAMES_IN_FLIGHT];
    VkFence fence[FRAMES_IN_FLIGHT];
    int frame;                    /* frames recorded so far */
    int width, height;
    VkImage color, depth;         /* the engine's framebuffer */
    VkDeviceMemory color_mem, depth_mem;
    VkImageView color_view, depth_view;
    VkBuffer readback;            /* colour, then depth (floats), read after the frame */
    VkDeviceMemory readback_mem;
    unsigned char *readback_map;
    VkPipelineLayout layout;
    VkPipeline pipeline;          /* flat colour, depth test */
    VkPipeline pipeline_o;        /* the same, and fogvol's O as a second output (the MRT tier) */
    VkFormat o_format;
    int validation;               /* the layers are on */
} engine;

/* The validation messages of the whole program (not of one engine: a message may come while an
   engine is being destroyed, or from vkDestroyInstance after its messenger is gone), and the count
   reported (-1: none yet). */
static int g_validation_messages;
static int g_validation_reported = -1;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                    VkDebugUtilsMessageTypeFlagsEXT types,
                                                    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)types;
    (void)user;
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        g_validation_messages++;
        fprintf(stderr, "validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

/* The count, once every engine is destroyed (the last message can only come before that); at exit,
   any message after it fails the program (atexit, set in main). */
static int report_validation_count(void)
{
    g_validation_reported = g_validation_messages;
    return g_validation_reported;
}

static void fail_on_late_validation(void)
{
    if (g_validation_reported < 0 || g_validation_messages == g_validation_reported) return;
    fprintf(stderr, "vulkan_backend: %d validation messages after the count (%d) was reported\n",
            g_validation_messages - g_validation_reported, g_validation_reported);
    fflush(stdout);
    _Exit(1);
}

static void on_fogvol_log(void *user, fogvol_log_level level, const char *msg)
{
    (void)user;
    if (level <= FOGVOL_LOG_WARNING) fprintf(stderr, "%s\n", msg);
}

#define VK_CHECK(x) \
    do { \
        VkResult r_ = (x); \
        if (r_ != VK_SUCCESS) { \
            fprintf(stderr, "%s:%d: %s failed (%d)\n", __FILE__, __LINE__, #x, (int)r_); \
            exit(1); \
        } \
    } while (0)

static int has_layer(const char *name)
{
    VkLayerProperties props[64];
    uint32_t n = 64, i;
    if (vkEnumerateInstanceLayerProperties(&n, props) < 0) return 0;
    for (i = 0; i < n; ++i)
        if (!strcmp(props[i].layerName, name)) return 1;
    return 0;
}

static void create_instance(engine *e)
{
    const char *layer = "VK_LAYER_KHRONOS_validation";
    const char *ext[2] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkApplicationInfo app;
    VkInstanceCreateInfo ii;
    VkDebugUtilsMessengerCreateInfoEXT mi;
    VkValidationFeaturesEXT vf;
    const VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    PFN_vkCreateDebugUtilsMessengerEXT create;
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "fogvol vulkan_backend";
    app.apiVersion = VK_API_VERSION_1_3;
    memset(&mi, 0, sizeof mi); /* (the layers' synchronization validation is on too) */
    mi.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = on_validation;
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ii.pApplicationInfo = &app;
    memset(&vf, 0, sizeof vf); /* synchronization validation too: every missing barrier is a message */
    vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    vf.pNext = &mi; /* messages from vkCreateInstance itself too */
    if (e->validation) {
        ii.pNext = &vf;
        ii.enabledLayerCount = 1;
        ii.ppEnabledLayerNames = &layer;
        ii.enabledExtensionCount = 2;
        ii.ppEnabledExtensionNames = ext;
    }
    VK_CHECK(vkCreateInstance(&ii, NULL, &e->instance));
    if (!e->validation) return;
    create = (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(e->instance, "vkCreateDebugUtilsMessengerEXT");
    if (create) VK_CHECK(create(e->instance, &mi, NULL, &e->messenger));
}

static void create_device(engine *e)
{
    const char *ext = FOGVK_DEVICE_EXTENSION;
    VkPhysicalDevice pds[8];
    uint32_t n = 8, nf = 16, i;
    VkQueueFamilyProperties fam[16];
    float prio = 1.0f;
    VkDeviceQueueCreateInfo qi;
    VkPhysicalDeviceVulkan12Features f12;
    VkPhysicalDeviceVulkan13Features f13;
    VkPhysicalDeviceFeatures2 f2;
    VkDeviceCreateInfo di;
    VK_CHECK(vkEnumeratePhysicalDevices(e->instance, &n, pds));
    if (n == 0) {
        fprintf(stderr, "no Vulkan device (Mesa's lavapipe: apt-get install mesa-vulkan-drivers)\n");
        exit(1);
    }
    e->pd = pds[0];
    vkGetPhysicalDeviceQueueFamilyProperties(e->pd, &nf, fam);
    for (i = 0; i < nf && !(fam[i].queueFlags & VK_QUEUE_GRAPHICS_BIT); ++i) continue;
    e->family = i;
    memset(&qi, 0, sizeof qi);
    qi.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qi.queueFamilyIndex = e->family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &prio;
    memset(&f12, 0, sizeof f12);
    memset(&f13, 0, sizeof f13);
    memset(&f2, 0, sizeof f2);
    f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    f13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    f2.pNext = &f12;
    f12.pNext = &f13;
    fogvk_enable_features(&f2, &f12, &f13); /* what fogvol's backend needs */
    memset(&di, 0, sizeof di);
    di.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    di.pNext = &f2;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    di.enabledExtensionCount = 1;
    di.ppEnabledExtensionNames = &ext;
    VK_CHECK(vkCreateDevice(e->pd, &di, NULL, &e->dev));
    vkGetDeviceQueue(e->dev, e->family, 0, &e->queue);
}

static uint32_t memory_type(engine *e, uint32_t bits, VkMemoryPropertyFlags want)
{
    VkPhysicalDeviceMemoryProperties mp;
    uint32_t i;
    vkGetPhysicalDeviceMemoryProperties(e->pd, &mp);
    for (i = 0; i < mp.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) return i;
    fprintf(stderr, "no memory type\n");
    exit(1);
}

static void make_buffer(engine *e, VkDeviceSize size, VkBufferUsageFlags usage, const void *data, VkBuffer *buf,
                        VkDeviceMemory *mem, void **map)
{
    VkBufferCreateInfo bi;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo ai;
    void *p;
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = size;
    bi.usage = usage;
    VK_CHECK(vkCreateBuffer(e->dev, &bi, NULL, buf));
    vkGetBufferMemoryRequirements(e->dev, *buf, &req);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex =
        memory_type(e, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VK_CHECK(vkAllocateMemory(e->dev, &ai, NULL, mem));
    VK_CHECK(vkBindBufferMemory(e->dev, *buf, *mem, 0));
    VK_CHECK(vkMapMemory(e->dev, *mem, 0, VK_WHOLE_SIZE, 0, &p));
    if (data) memcpy(p, data, (size_t)size);
    if (map) *map = p;
    else vkUnmapMemory(e->dev, *mem);
}

static void make_image(engine *e, VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                       VkImage *img, VkDeviceMemory *mem, VkImageView *view)
{
    VkImageCreateInfo ii;
    VkImageViewCreateInfo vi;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo ai;
    memset(&ii, 0, sizeof ii);
    ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = format;
    ii.extent.width = (uint32_t)e->width;
    ii.extent.height = (uint32_t)e->height;
    ii.extent.depth = 1;
    ii.mipLevels = ii.arrayLayers = 1;
    ii.samples = VK_SAMPLE_COUNT_1_BIT;
    ii.tiling = VK_IMAGE_TILING_OPTIMAL;
    ii.usage = usage;
    VK_CHECK(vkCreateImage(e->dev, &ii, NULL, img));
    vkGetImageMemoryRequirements(e->dev, *img, &req);
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memory_type(e, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VK_CHECK(vkAllocateMemory(e->dev, &ai, NULL, mem));
    VK_CHECK(vkBindImageMemory(e->dev, *img, *mem, 0));
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = *img;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange.aspectMask = aspect;
    vi.subresourceRange.levelCount = vi.subresourceRange.layerCount = 1;
    VK_CHECK(vkCreateImageView(e->dev, &vi, NULL, view));
}

static VkShaderModule engine_shader(engine *e, shaderc_compiler_t sc, const char *src, shaderc_shader_kind kind)
{
    shaderc_compilation_result_t r = shaderc_compile_into_spv(sc, src, strlen(src), kind, "engine", "main", NULL);
    VkShaderModuleCreateInfo mi;
    VkShaderModule m;
    if (shaderc_result_get_compilation_status(r) != shaderc_compilation_status_success) {
        fprintf(stderr, "engine shader: %s\n", shaderc_result_get_error_message(r));
        exit(1);
    }
    memset(&mi, 0, sizeof mi);
    mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    mi.codeSize = shaderc_result_get_length(r);
    mi.pCode = (const uint32_t *)shaderc_result_get_bytes(r);
    VK_CHECK(vkCreateShaderModule(e->dev, &mi, NULL, &m));
    shaderc_result_release(r);
    return m;
}

/* The engine's own pipelines: position in, flat colour out (push constants: mvp, colour, the view-space
   z row for the view depth, and fogvol's MRT values); o_format != UNDEFINED: the MRT tier's second
   output, fogvol's O, written with fogvol_mrt_snippet() (its uniforms in the engine's push constants). */
#define ENGINE_DRAW_BLOCK "layout(push_constant) uniform draw { mat4 mvp; vec4 color; vec4 view_z; vec4 fogvol_mrt[2]; };\n"
static VkPipeline create_pipeline(engine *e, VkFormat o_format)
{
    static const char *vs = "layout(location = 0) in vec3 pos;\n" ENGINE_DRAW_BLOCK
                            "#ifdef WITH_O\n"
                            "layout(location = 0) out float view_depth;\n"
                            "#endif\n"
                            "void main() {\n"
                            "    gl_Position = mvp * vec4(pos, 1.0);\n"
                            "#ifdef WITH_O\n"
                            "    view_depth = -dot(view_z, vec4(pos, 1.0));\n"
                            "#endif\n"
                            "}\n";
    static const char *fs = "#version 450\n" ENGINE_DRAW_BLOCK
                            "layout(location = 0) out vec4 frag;\n"
                            "void main() { frag = color; }\n";
    static const char *fs_mrt_head = "#version 450\n" ENGINE_DRAW_BLOCK "#define FOGVOL_MRT_IN_BLOCK\n";
    static const char *fs_mrt_tail = "layout(location = 0) in float view_depth;\n"
                                     "layout(location = 0) out vec4 frag;\n"
                                     "layout(location = 1) out vec4 fogvol_o;\n"
                                     "void main() {\n"
                                     "    frag = color;\n"
                                     "    fogvol_o = fogvol_encode_view_depth(view_depth);\n"
                                     "}\n";
    const VkFormat cf[2] = {VK_FORMAT_R8G8B8A8_UNORM, o_format};
    const VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    shaderc_compiler_t sc = shaderc_compiler_initialize();
    VkPushConstantRange pc = {VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, 128};
    VkPipelineLayoutCreateInfo li;
    VkPipeline pipeline;
    char fs_mrt[8192], vs_text[2048];
    int mrt = o_format != VK_FORMAT_UNDEFINED;
    VkPipelineShaderStageCreateInfo st[2];
    VkVertexInputBindingDescription vb = {0, 12, VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription va = {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
    VkPipelineVertexInputStateCreateInfo vi;
    VkPipelineInputAssemblyStateCreateInfo ia;
    VkPipelineViewportStateCreateInfo vp;
    VkPipelineRasterizationStateCreateInfo rs;
    VkPipelineMultisampleStateCreateInfo ms;
    VkPipelineDepthStencilStateCreateInfo ds;
    VkPipelineColorBlendAttachmentState ba[2];
    VkPipelineColorBlendStateCreateInfo cb;
    VkPipelineDynamicStateCreateInfo dy;
    VkPipelineRenderingCreateInfo ri;
    VkGraphicsPipelineCreateInfo pi;
    memset(&li, 0, sizeof li);
    li.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    li.pushConstantRangeCount = 1;
    li.pPushConstantRanges = &pc;
    if (!e->layout) VK_CHECK(vkCreatePipelineLayout(e->dev, &li, NULL, &e->layout));
    snprintf(fs_mrt, sizeof fs_mrt, "%s%s%s", fs_mrt_head, fogvol_mrt_snippet(), fs_mrt_tail);
    snprintf(vs_text, sizeof vs_text, "#version 450\n%s%s", mrt ? "#define WITH_O\n" : "", vs);
    memset(st, 0, sizeof st);
    st[0].sType = st[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    st[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    st[0].module = engine_shader(e, sc, vs_text, shaderc_vertex_shader);
    st[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    st[1].module = engine_shader(e, sc, mrt ? fs_mrt : fs, shaderc_fragment_shader);
    st[0].pName = st[1].pName = "main";
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    vi.vertexBindingDescriptionCount = vi.vertexAttributeDescriptionCount = 1;
    vi.pVertexBindingDescriptions = &vb;
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
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.lineWidth = 1.0f;
    memset(&ms, 0, sizeof ms);
    ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    memset(&ds, 0, sizeof ds);
    ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    ds.depthTestEnable = ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = VK_COMPARE_OP_LESS;
    memset(ba, 0, sizeof ba);
    ba[0].colorWriteMask = ba[1].colorWriteMask = 0xf; /* (no blending into fogvol's O) */
    memset(&cb, 0, sizeof cb);
    cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    cb.attachmentCount = mrt ? 2 : 1;
    cb.pAttachments = ba;
    memset(&dy, 0, sizeof dy);
    dy.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dy.dynamicStateCount = 2;
    dy.pDynamicStates = dyn;
    memset(&ri, 0, sizeof ri);
    ri.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    ri.colorAttachmentCount = mrt ? 2 : 1;
    ri.pColorAttachmentFormats = cf;
    ri.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
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
    pi.layout = e->layout;
    VK_CHECK(vkCreateGraphicsPipelines(e->dev, VK_NULL_HANDLE, 1, &pi, NULL, &pipeline));
    vkDestroyShaderModule(e->dev, st[0].module, NULL);
    vkDestroyShaderModule(e->dev, st[1].module, NULL);
    shaderc_compiler_release(sc);
    return pipeline;
}

static void engine_init(engine *e, int width, int height, int validation)
{
    VkCommandPoolCreateInfo pi;
    VkCommandBufferAllocateInfo ai;
    VkFenceCreateInfo fi;
    int i;
    memset(e, 0, sizeof *e);
    e->width = width;
    e->height = height;
    e->validation = validation && has_layer("VK_LAYER_KHRONOS_validation");
    if (validation && !e->validation) fprintf(stderr, "validation layers not installed (vulkan-validationlayers)\n");
    create_instance(e);
    create_device(e);
    memset(&pi, 0, sizeof pi);
    pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = e->family;
    VK_CHECK(vkCreateCommandPool(e->dev, &pi, NULL, &e->pool));
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = e->pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = FRAMES_IN_FLIGHT;
    VK_CHECK(vkAllocateCommandBuffers(e->dev, &ai, e->cmd));
    memset(&fi, 0, sizeof fi);
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    for (i = 0; i < FRAMES_IN_FLIGHT; ++i) VK_CHECK(vkCreateFence(e->dev, &fi, NULL, &e->fence[i]));
    make_image(e, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
               VK_IMAGE_ASPECT_COLOR_BIT, &e->color, &e->color_mem, &e->color_view);
    make_image(e, VK_FORMAT_D32_SFLOAT,
               VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
               VK_IMAGE_ASPECT_DEPTH_BIT, &e->depth, &e->depth_mem, &e->depth_view);
    make_buffer(e, (VkDeviceSize)width * height * 12, VK_BUFFER_USAGE_TRANSFER_DST_BIT, NULL, &e->readback,
                &e->readback_mem, (void **)&e->readback_map);
    e->pipeline = create_pipeline(e, VK_FORMAT_UNDEFINED);
}

static void engine_mesh_upload(engine *e, const shp_mesh *m, engine_mesh *out)
{
    make_buffer(e, (VkDeviceSize)m->vcount * 12, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, m->pos, &out->vbuf, &out->vmem, NULL);
    make_buffer(e, (VkDeviceSize)m->icount * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT, m->idx, &out->ibuf, &out->imem, NULL);
    out->count = (uint32_t)m->icount;
}

static void engine_mesh_free(engine *e, engine_mesh *m)
{
    vkDestroyBuffer(e->dev, m->vbuf, NULL);
    vkDestroyBuffer(e->dev, m->ibuf, NULL);
    vkFreeMemory(e->dev, m->vmem, NULL);
    vkFreeMemory(e->dev, m->imem, NULL);
}

static void barrier(VkCommandBuffer cmd, VkImage img, VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                    VkPipelineStageFlags src, VkAccessFlags src_access, VkPipelineStageFlags dst,
                    VkAccessFlags dst_access)
{
    VkImageMemoryBarrier b;
    memset(&b, 0, sizeof b);
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = src_access;
    b.dstAccessMask = dst_access;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img;
    b.subresourceRange.aspectMask = aspect;
    b.subresourceRange.levelCount = b.subresourceRange.layerCount = 1;
    vkCmdPipelineBarrier(cmd, src, dst, 0, 0, NULL, 0, NULL, 1, &b);
}

/* The next frame's command buffer, once the GPU is done with its previous use. */
static VkCommandBuffer engine_begin(engine *e)
{
    int slot = e->frame % FRAMES_IN_FLIGHT;
    VkCommandBufferBeginInfo bi;
    VK_CHECK(vkWaitForFences(e->dev, 1, &e->fence[slot], VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(e->dev, 1, &e->fence[slot]));
    VK_CHECK(vkResetCommandBuffer(e->cmd[slot], 0));
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(e->cmd[slot], &bi));
    return e->cmd[slot];
}

static void engine_submit(engine *e, VkCommandBuffer cmd)
{
    int slot = e->frame % FRAMES_IN_FLIGHT;
    VkSubmitInfo si;
    VK_CHECK(vkEndCommandBuffer(cmd));
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK_CHECK(vkQueueSubmit(e->queue, 1, &si, e->fence[slot]));
    e->frame++;
}

/* fogvk_frame.flush (debug read-back only): submit what is recorded, wait, go on in the same buffer. */
static VkCommandBuffer engine_flush(void *user, VkCommandBuffer cmd)
{
    engine *e = (engine *)user;
    int slot = e->frame % FRAMES_IN_FLIGHT;
    VkSubmitInfo si;
    VkCommandBufferBeginInfo bi;
    VK_CHECK(vkEndCommandBuffer(cmd));
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VK_CHECK(vkQueueSubmit(e->queue, 1, &si, e->fence[slot]));
    VK_CHECK(vkWaitForFences(e->dev, 1, &e->fence[slot], VK_TRUE, UINT64_MAX));
    VK_CHECK(vkResetFences(e->dev, 1, &e->fence[slot]));
    VK_CHECK(vkResetCommandBuffer(cmd, 0));
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    return cmd;
}

typedef struct engine_draw {
    const engine_mesh *mesh;
    float mvp[16];
    float color[4];
    float view_z[4]; /* row 2 of view * model: the view depth is -dot(view_z, (pos, 1)) */
} engine_draw;

/* The MRT tier: fogvol's O as the engine pass's second colour attachment (fogvol_mrt_prepare). */
typedef struct engine_mrt {
    VkImageView view;
    VkFormat format;
    float clear[4];
    float uniforms[8];
} engine_mrt;

static VkFormat fogvol_vk_format(fogvol_format f)
{
    return f == FOGVOL_FORMAT_R32F ? VK_FORMAT_R32_SFLOAT : VK_FORMAT_R8G8B8A8_UNORM;
}

/* The opaque scene: clear, draw flat-coloured meshes with depth (and fogvol's O: mrt != NULL). Leaves
   the colour image in COLOR_ATTACHMENT_OPTIMAL and the depth image in DEPTH_ATTACHMENT_OPTIMAL (what
   fogvk_frame says). */
static void engine_draw_scene(engine *e, VkCommandBuffer cmd, const engine_draw *draws, int n, const float sky[4],
                              const engine_mrt *mrt)
{
    VkRenderingAttachmentInfo ca[2], da;
    VkRenderingInfo ri;
    VkViewport vp;
    VkRect2D sc;
    int i;
    /* (after the previous frame's uses: fogvol's passes, the read-back copies, a frame still in flight) */
    barrier(cmd, e->color, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    barrier(cmd, e->depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
            VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    memset(ca, 0, sizeof ca);
    ca[0].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    ca[0].imageView = e->color_view;
    ca[0].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    ca[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    ca[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    memcpy(ca[0].clearValue.color.float32, sky, 16);
    da = ca[0];
    if (mrt) { /* fogvol's O, cleared to "far" (fogvk_engine_attachment made it an attachment) */
        ca[1] = ca[0];
        ca[1].imageView = mrt->view;
        memcpy(ca[1].clearValue.color.float32, mrt->clear, 16);
        if (e->o_format != mrt->format) {
            if (e->pipeline_o) vkDestroyPipeline(e->dev, e->pipeline_o, NULL);
            e->pipeline_o = create_pipeline(e, mrt->format);
            e->o_format = mrt->format;
        }
    }
    da.imageView = e->depth_view;
    da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    da.clearValue.depthStencil.depth = 1.0f;
    memset(&ri, 0, sizeof ri);
    ri.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    ri.renderArea.extent.width = (uint32_t)e->width;
    ri.renderArea.extent.height = (uint32_t)e->height;
    ri.layerCount = 1;
    ri.colorAttachmentCount = mrt ? 2 : 1;
    ri.pColorAttachments = ca;
    ri.pDepthAttachment = &da;
    vkCmdBeginRendering(cmd, &ri);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mrt ? e->pipeline_o : e->pipeline);
    vp.x = vp.y = 0.0f;
    vp.width = (float)e->width;
    vp.height = (float)e->height;
    vp.minDepth = 0.0f;
    vp.maxDepth = 1.0f;
    vkCmdSetViewport(cmd, 0, 1, &vp);
    sc.offset.x = sc.offset.y = 0;
    sc.extent.width = (uint32_t)e->width;
    sc.extent.height = (uint32_t)e->height;
    vkCmdSetScissor(cmd, 0, 1, &sc);
    for (i = 0; i < n; ++i) {
        VkDeviceSize zero = 0;
        float pc[32];
        memset(pc, 0, sizeof pc);
        memcpy(pc, draws[i].mvp, 64);
        memcpy(pc + 16, draws[i].color, 16);
        memcpy(pc + 20, draws[i].view_z, 16);
        if (mrt) memcpy(pc + 24, mrt->uniforms, 32);
        vkCmdPushConstants(cmd, e->layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, 128, pc);
        vkCmdBindVertexBuffers(cmd, 0, 1, &draws[i].mesh->vbuf, &zero);
        vkCmdBindIndexBuffer(cmd, draws[i].mesh->ibuf, 0, VK_INDEX_TYPE_UINT32);
        vkCmdDrawIndexed(cmd, draws[i].mesh->count, 1, 0, 0, 0);
    }
    vkCmdEndRendering(cmd);
}

/* Records a copy of the colour image (RGBA8) into region 0 or 1 of the read-back buffer and, with
   depth != 0, of the depth image (floats) into region 2; the engine reads them after the frame. */
static void engine_record_readback(engine *e, VkCommandBuffer cmd, int region, int depth)
{
    VkBufferImageCopy c;
    VkBufferMemoryBarrier bb;
    memset(&bb, 0, sizeof bb); /* after the copies of an earlier frame into the same buffer */
    bb.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    bb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.buffer = e->readback;
    bb.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 1, &bb, 0, NULL);
    barrier(cmd, e->color, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
            VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    memset(&c, 0, sizeof c);
    c.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    c.imageSubresource.layerCount = 1;
    c.imageExtent.width = (uint32_t)e->width;
    c.imageExtent.height = (uint32_t)e->height;
    c.imageExtent.depth = 1;
    c.bufferOffset = (VkDeviceSize)region * e->width * e->height * 4;
    vkCmdCopyImageToBuffer(cmd, e->color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, e->readback, 1, &c);
    barrier(cmd, e->color, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
            VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    if (depth) {
        barrier(cmd, e->depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_TRANSFER_READ_BIT);
        c.bufferOffset = (VkDeviceSize)e->width * e->height * 8;
        c.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        vkCmdCopyImageToBuffer(cmd, e->depth, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, e->readback, 1, &c);
        barrier(cmd, e->depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    }
    memset(&bb, 0, sizeof bb);
    bb.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    bb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.buffer = e->readback;
    bb.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, NULL, 1, &bb, 0, NULL);
}

/* Waits for every frame in flight: the read-back buffer then holds the last frame's copy. */
static void engine_wait(engine *e) { VK_CHECK(vkQueueWaitIdle(e->queue)); }

static void engine_frame_desc(engine *e, VkCommandBuffer cmd, fogvk_frame *f)
{
    memset(f, 0, sizeof *f);
    f->cmd = cmd;
    f->slot = e->frame % FRAMES_IN_FLIGHT;
    f->color_image = e->color;
    f->color_view = e->color_view;
    f->color_format = VK_FORMAT_R8G8B8A8_UNORM;
    f->color_layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    f->depth_image = e->depth;
    f->depth_format = VK_FORMAT_D32_SFLOAT;
    f->depth_layout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    f->width = e->width;
    f->height = e->height;
    f->flush = engine_flush;
    f->flush_user_data = e;
}

static void engine_destroy(engine *e)
{
    PFN_vkDestroyDebugUtilsMessengerEXT destroy;
    int i;
    vkDeviceWaitIdle(e->dev);
    vkDestroyPipeline(e->dev, e->pipeline, NULL);
    if (e->pipeline_o) vkDestroyPipeline(e->dev, e->pipeline_o, NULL);
    vkDestroyPipelineLayout(e->dev, e->layout, NULL);
    vkDestroyBuffer(e->dev, e->readback, NULL);
    vkFreeMemory(e->dev, e->readback_mem, NULL);
    vkDestroyImageView(e->dev, e->color_view, NULL);
    vkDestroyImageView(e->dev, e->depth_view, NULL);
    vkDestroyImage(e->dev, e->color, NULL);
    vkDestroyImage(e->dev, e->depth, NULL);
    vkFreeMemory(e->dev, e->color_mem, NULL);
    vkFreeMemory(e->dev, e->depth_mem, NULL);
    for (i = 0; i < FRAMES_IN_FLIGHT; ++i) vkDestroyFence(e->dev, e->fence[i], NULL);
    vkDestroyCommandPool(e->dev, e->pool, NULL);
    vkDestroyDevice(e->dev, NULL);
    destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(e->instance, "vkDestroyDebugUtilsMessengerEXT");
    if (e->messenger && destroy) destroy(e->instance, e->messenger, NULL);
    vkDestroyInstance(e->instance, NULL);
}

/* ---- matrices: the engine's camera, Vulkan style ---------------------------------------------- */

/* GL's gluPerspective with depth mapped to [0, 1] (Vulkan's clip volume); flip_y: y down the image
   as Vulkan engines draw (row 0 at the top of the view). */
static void perspective01(float m[16], float fovy_deg, float aspect, float n, float f, int flip_y)
{
    float t = 1.0f / (float)tan(fovy_deg * 3.14159265358979 / 360.0);
    memset(m, 0, 64);
    m[0] = t / aspect;
    m[5] = flip_y ? -t : t;
    m[10] = f / (n - f);
    m[11] = -1.0f;
    m[14] = f * n / (n - f);
}

#include "examples/vulkan_scene.h"

/* ---- main ------------------------------------------------------------------------------------------ */

int main(int argc, char **argv)
{
    const char *out = "vulkan.png";
    fogvol_tier tier = FOGVOL_TIER_FLOAT;
    int i, check = 0, bench = 0, rc;
    setvbuf(stdout, NULL, _IOLBF, 0); /* in order with the validation messages on stderr, in a log too */
    atexit(fail_on_late_validation);
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--check")) check = 1;
        else if (!strcmp(argv[i], "--bench")) bench = 1;
        else if (!strcmp(argv[i], "--tier") && i + 1 < argc) {
            const char *t = argv[++i];
            tier = !strcmp(t, "ps13") ? FOGVOL_TIER_PS13 : !strcmp(t, "ps20") ? FOGVOL_TIER_PS20
                   : !strcmp(t, "mrt") ? FOGVOL_TIER_MRT : FOGVOL_TIER_FLOAT;
        } else out = argv[i];
    }
    if (check) return run_check();
    if (bench) return run_bench();
    rc = render_picture(tier, out); /* row 0 is the top of the view: the PNG's order */
    return rc;
}
