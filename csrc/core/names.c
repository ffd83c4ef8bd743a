/* names.c - the names of the public enumerations (voxlight.h), the one list
 * the CLI's options, its messages and the Blender add-on's menus read. */
#include <strings.h>

#include "error.h"
#include "voxlight.h"

static const char *const filter_names[VXL_FILTER_COUNT] = {"central", "forward3", "sobel8", "sobel14",
                                                           "sobel26", "precomputed", "cubic", "cubic-smooth"};
static const char *const preset_names[VXL_PRESET_COUNT] = {"auto", "gray", "bone", "hot", "mri", "ct"};
static const char *const storage_names[VXL_STORAGE_COUNT] = {"auto", "dense", "bricked", "sparse", "compressed"};
static const char *const classify_names[VXL_CLASSIFY_COUNT] = {"post", "pre", "preint"};
static const char *const gopacity_names[VXL_GOPACITY_COUNT] = {"off", "boundary", "iso"};
static const char *const gradient_store_names[VXL_GRADIENT_STORE_COUNT] = {"8bit", "16f", "32f"};
static const char *const shading_model_names[VXL_SHADING_COUNT] = {"phong", "shadowed", "scatter", "path"};
static const char *const technique_names[VXL_TECHNIQUE_COUNT] = {"raycast", "slices2d", "slices3d"};
static const char *const mode_names[VXL_MODE_COUNT] = {"dvr", "mip", "minip", "average", "iso"};
static const char *const interpolation_names[VXL_INTERP_COUNT] = {"nearest", "linear", "cubic"};
static const char *const label_mode_names[VXL_LABEL_MODE_COUNT] = {"surface", "mask", "tint"};
static const char *const streaming_names[VXL_STREAMING_COUNT] = {"auto", "off", "on"};
static const char *const blend_names[VXL_BLEND_COUNT] = {"over", "add", "max"};
static const char *const opacity_source_names[VXL_OPACITY_SOURCE_COUNT] = {"luminance", "channel", "alpha"};
static const char *const color_source_names[VXL_COLOR_SOURCE_COUNT] = {"auto", "data", "tf"};
static const char *const channels_mode_names[VXL_CHANNELS_COUNT] = {"auto", "on", "off"};
static const char *const channel_blend_names[VXL_CHANNEL_BLEND_COUNT] = {"add", "max"};
static const char *const backend_names[VXL_BACKEND_COUNT] = {"auto", "osmesa", "egl", "wgl"};
static const char *const dtype_names[VXL_DTYPE_COUNT] = {NULL,    "uint8", "int8",    "uint16", "int16",
                                                         "uint32", "int32", "float32", "float64"};

static int lookup(const char *const *names, uint32_t n, const char *name, uint32_t *out, const char *what)
{
    if (!name || !out) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "%s name is NULL", what);
    for (uint32_t i = 0; i < n; i++)
        if (!strcasecmp(names[i], name)) {
            *out = i;
            return VXL_OK;
        }
    return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "unknown %s '%.64s'", what, name);
}

/* One name function and one lookup per enumeration, all alike. */
#define VXL_NAMES(fn, table, count, what)                                                                  \
    const char *vxl_##fn##_name(uint32_t v) { return v < (count) ? table[v] : NULL; }                      \
    int vxl_##fn##_from_name(const char *name, uint32_t *out) { return lookup(table, count, name, out, what); }

VXL_NAMES(filter, filter_names, VXL_FILTER_COUNT, "filter")
VXL_NAMES(preset, preset_names, VXL_PRESET_COUNT, "preset")
VXL_NAMES(storage, storage_names, VXL_STORAGE_COUNT, "storage")
VXL_NAMES(classify, classify_names, VXL_CLASSIFY_COUNT, "classify mode")
VXL_NAMES(gradient_opacity, gopacity_names, VXL_GOPACITY_COUNT, "gradient opacity mode")
VXL_NAMES(gradient_store, gradient_store_names, VXL_GRADIENT_STORE_COUNT, "gradient store")
VXL_NAMES(backend, backend_names, VXL_BACKEND_COUNT, "backend")
VXL_NAMES(shading_model, shading_model_names, VXL_SHADING_COUNT, "shading model")
VXL_NAMES(technique, technique_names, VXL_TECHNIQUE_COUNT, "technique")
VXL_NAMES(mode, mode_names, VXL_MODE_COUNT, "render mode")
VXL_NAMES(interpolation, interpolation_names, VXL_INTERP_COUNT, "interpolation")
VXL_NAMES(label_mode, label_mode_names, VXL_LABEL_MODE_COUNT, "label mode")
VXL_NAMES(streaming, streaming_names, VXL_STREAMING_COUNT, "streaming mode")
VXL_NAMES(blend, blend_names, VXL_BLEND_COUNT, "blend")
VXL_NAMES(opacity_source, opacity_source_names, VXL_OPACITY_SOURCE_COUNT, "opacity source")
VXL_NAMES(color_source, color_source_names, VXL_COLOR_SOURCE_COUNT, "color source")
VXL_NAMES(channels_mode, channels_mode_names, VXL_CHANNELS_COUNT, "channels mode")
VXL_NAMES(channel_blend, channel_blend_names, VXL_CHANNEL_BLEND_COUNT, "channel blend")


const char *vxl_dtype_name(uint32_t dtype) { return dtype < VXL_DTYPE_COUNT ? dtype_names[dtype] : NULL; }
