/* frame.h - render parameters resolved against the volume: defaults filled
 * in, values validated, matrices in the form the shaders take. Pure CPU, so
 * it can be tested and reused by a reference renderer. */
#ifndef VXL_FRAME_H
#define VXL_FRAME_H

#include <stddef.h>
#include <stdint.h>

#include "bricks.h"
#include "error.h"
#include "frame_cut.h"
#include "transfer.h"
#include "voxlight.h"

typedef struct vxl_volume_geom {
    uint32_t dims[3];
    double affine[16];          /* voxel -> world */
    double tex_lo, tex_hi;      /* stored [0,1] -> data value */
    double value_min, value_max;
} vxl_volume_geom;

struct vxl_volume;
/* The geometry and value mapping a frame needs of a CPU volume. */
vxl_volume_geom vxl_volume_geom_of(const struct vxl_volume *v);

/* One overlay of a frame, resolved against its volume's geometry. */
/* A side volume's own transfer function and value mapping (an overlay's, a
 * channel's), resolved by vxl_frame_resolve_table as the frame resolves
 * its own. */
typedef struct vxl_frame_table {
    const float *tf;            /* tf_size straight RGBA, clamped to [0,1]: tf_copy or preset_tf */
    uint32_t tf_size;
    float window_offset, window_scale, opacity_scale; /* as the frame's, on the side volume's normalised texels */
    uint64_t key;               /* vxl_classification_key of the above: the GL side's table and occupancy cache */
    float *tf_copy;             /* owned when the caller gave a table */
    float preset_tf[VXL_PRESET_TABLE_SIZE * 4];
} vxl_frame_table;

typedef struct vxl_frame_overlay {
    uint32_t slot, blend, interpolation; /* VXL_BLEND_*, VXL_INTERP_* */
    uint32_t shading;           /* lit (the frame shades and the overlay's shading_off is 0) */
    double model[16];           /* overlay voxel -> world */
    vxl_frame_table table;      /* its transfer function on its own texels */
} vxl_frame_overlay;

/* One drawn channel of a multi-channel volume (frame_channels.c), resolved
 * against that channel's value mapping. */
typedef struct vxl_frame_channel {
    uint32_t channel;           /* the volume's channel index */
    float color[3];
    vxl_frame_table table;      /* its transfer function on the channel's normalised texels */
} vxl_frame_channel;

typedef struct vxl_frame {
    uint32_t width, height;
    uint32_t filter, shading, reuse, store, jitter, seed;
    uint32_t classify, preint_size;
    uint32_t gopacity;          /* VXL_GOPACITY_* */
    uint32_t technique;         /* VXL_TECHNIQUE_*: the ray caster or a slicing comparison mode (slices.c) */
    uint32_t color_space;       /* VXL_COLOR_SPACE_*: display-referred or scene-linear colours */
    uint32_t color_source;      /* VXL_COLOR_SOURCE_*: whether a colour volume's own colour replaces the table's */
    float gradient_ref, gradient_exp, iso_pos, iso_thickness; /* iso_pos: normalised value */
    float sample_distance, step;
    int max_steps;
    double view[16], proj[16], model[16];
    /* clip -> voxel space with the NDC depth folded in (in double) at z = -1
     * and z = +1: each maps vec4(ndc.xy, 0, 1) to a homogeneous point. Folding
     * in float would cancel catastrophically for near planes of 1e-6. */
    float ray_near[16], ray_far[16];
    float mv[16], normal[9];
    const float *tf;            /* tf_size*4 straight RGBA, clamped to [0,1] */
    uint32_t tf_size;
    float window_offset, window_scale, opacity_scale;
    float material[4];
    int light_count;
    float light_pos[VXL_MAX_LIGHTS][4], light_color[VXL_MAX_LIGHTS][3];
    /* Lighting beyond Phong (frame_lighting.c; the formulas are
     * voxlight.h's VXL_SHADING_*). Per light i < light_count: */
    uint32_t shading_model;     /* VXL_SHADING_* */
    float ao_radius;            /* voxels; 0 = no occlusion */
    float ao_strength;          /* occlusion_strength, 0 resolved to 1 */
    float anisotropy;           /* Henyey-Greenstein g, [-0.99, 0.99] */
    uint32_t illumination_size; /* cells along the longest side; 0 = automatic (the GL side decides) */
    /* PATH (frame_path.c): samples offset .. offset + samples - 1 of every
     * pixel, at most `bounces` collisions per path, the seed; 0s resolved. */
    uint32_t path_samples, path_offset, path_bounces, path_seed;
    float light_world[VXL_MAX_LIGHTS][4];     /* world space, w 0 or 1; a direction (w = 0) is unit
                                                 length; the headlight's is the eye's direction */
    float light_spot_dir[VXL_MAX_LIGHTS][3];  /* view space unit vector the spot points along */
    float light_spot_cos[VXL_MAX_LIGHTS];     /* cos(spot_angle / 2); -2 when the light has no cone */
    float light_spot_blend[VXL_MAX_LIGHTS];   /* spot_blend, 0..1 (0 = hard edge) */
    float light_size[VXL_MAX_LIGHTS];         /* directional: angular diameter (radians); point:
                                                 radius (world units); 0 = hard shadows */
    /* scene shadows (frame_scene.c): the scene's occluder meshes,
     * validated (indices in range, vertices finite); none when
     * occluder_triangle_count is 0. The arrays are the caller's. */
    const float *occluder_vertices;      /* world xyz per vertex */
    const uint32_t *occluder_indices;    /* 3 per triangle */
    uint32_t occluder_vertex_count, occluder_triangle_count;
    uint32_t shadow_map_size;            /* texels per side, 0 resolved to the default */
    uint64_t occluder_key;               /* the caller's version, or the arrays' hash; never 0 with occluders */
    float early_termination, depth_threshold;
    int skip;                   /* empty-space skipping and the screen-space bound */
    uint32_t progressive;       /* 1 = draw streamed volumes from what is resident (docs/streaming.md) */
    const float *scene_depth;
    float preset_tf[VXL_PRESET_TABLE_SIZE * 4];
    float *tf_copy;             /* owned when the caller gave a table */
    /* modes (frame_mode.c): the projection or iso-surface, and the
     * MatCap when one is given and shading reads it (DVR with shading, ISO). */
    uint32_t mode;              /* VXL_MODE_* */
    uint32_t minip_floor_on;    /* MinIP skips samples below minip_floor_pos */
    float minip_floor_pos;      /* normalised value */
    const float *matcap_rgba;   /* NULL: the material and lights */
    uint32_t matcap_width, matcap_height;
    uint64_t matcap_key;        /* the caller's key; 0: the GL side hashes the pixels */
    /* cutaways (frame_cut.c): clip planes and crop box in voxel
     * space, the cutters checked; cut.any is 0 without params.cutaway. */
    vxl_frame_cut cut;
    /* labels (frame_labels.c): on is 0 without params.labels. */
    struct {
        int on;
        uint32_t mode;                  /* VXL_LABEL_MODE_* */
        int voxels;                     /* boundary VXL_LABEL_BOUNDARY_VOXELS: the voxels' faces */
        const vxl_label_entry *entries; /* the caller's, checked */
        uint32_t count, stride;         /* entries and their stride in bytes */
        uint64_t key;                   /* hash of the table (ids, colours, visibility) */
    } labels;
    /* The World's light (frame_environment.c): on is 0 without params.environment. */
    struct {
        int on;
        const float *rgb;           /* the caller's, checked: width*height*3 finite, >= 0 */
        uint32_t width, height;
        float strength, rotation_deg; /* rotation in (-360, 360) */
        uint64_t key;               /* the map, its size, strength and rotation; never 0 when on */
    } env;
    /* overlays (frame_overlays.c): count is 0 without params.overlays. */
    struct {
        uint32_t count;
        vxl_frame_overlay ov[VXL_MAX_OVERLAYS];
    } overlays;
    /* multi-channel drawing (frame_channels.c): on is 0 without params.channels;
     * ch[0..count) are the drawn ones (listed, not hidden, solo when any is). */
    struct {
        int on;
        uint32_t listed, count, blend; /* VXL_CHANNEL_BLEND_* */
        vxl_frame_channel ch[VXL_MAX_CHANNELS];
    } channels;
} vxl_frame;

/* The frame's transfer function at normalised value vn, as the GPU reads
 * it: the table sampled with GL_LINEAR at classify.glsl's coordinate,
 * opacity scaled and clamped (straight RGBA; the CPU renderers' lookup). */
void vxl_frame_classify(const vxl_frame *f, double vn, double out[4]);

/* The gradient filter a frame evaluates: rays that never evaluate gradients
 * (no shading, no gradient opacity) run one program for every filter. */
static inline uint32_t vxl_frame_filter(const vxl_frame *f)
{
    return f->shading || f->gopacity ? f->filter : VXL_FILTER_CENTRAL;
}

/* A hash of everything the classification depends on (table, window,
 * opacity scale): caches derived from it compare keys. */
uint64_t vxl_classification_key(const vxl_frame *f);

/* What brick occupancy depends on in this frame, as bricks.h takes it;
 * fills *out and returns it. */
static inline const vxl_occupancy_rule *vxl_frame_occupancy_rule(const vxl_frame *f, vxl_occupancy_rule *out)
{
    *out = (vxl_occupancy_rule){.table_key = vxl_classification_key(f),
                                .tf = f->tf,
                                .tf_size = f->tf_size,
                                .window_offset = f->window_offset,
                                .window_scale = f->window_scale,
                                .opacity_scale = f->opacity_scale,
                                .iso = f->gopacity == VXL_GOPACITY_ISO,
                                .iso_pos = f->iso_pos,
                                .iso_thickness = f->iso_thickness,
                                .filter = f->filter,
                                .sample_distance = f->sample_distance};
    return out;
}

/* The caller's params as this library's struct: zero-filled past the
 * caller's struct_size (older layouts get the defaults), reserved words
 * checked. p may be NULL (all defaults). Every reader of vxl_render_params
 * goes through it, so none reads past an older caller's struct. */
int vxl_render_params_read(vxl_render_params *q, const vxl_render_params *p, vxl_err *e);

/* p may be NULL (all defaults). On success free with vxl_frame_free. */
int vxl_frame_resolve(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *g, vxl_err *e);
void vxl_frame_free(vxl_frame *f);

/* Validates the lighting fields of p (shading_model, light_shapes,
 * ambient_occlusion, occlusion_strength, anisotropy, illumination_size) into
 * f; needs f->view and the lights resolved. Part of vxl_frame_resolve. */
int vxl_frame_resolve_lighting(vxl_frame *f, const vxl_render_params *p, vxl_err *e);

/* Validates p->environment (size, pixels, strength, rotation) into
 * f->env. Before the lights: an environment with light_count 0 means no
 * lamps, not the headlight. Part of vxl_frame_resolve (frame_environment.c). */
int vxl_frame_resolve_environment(vxl_frame *f, const vxl_render_params *p, vxl_err *e);
/* PATH's fields of p (frame_path.c): the sample range, bounces and seed. */
int vxl_frame_resolve_path(vxl_frame *f, const vxl_render_params *p, vxl_err *e);
/* What PATH cannot draw yet, refused with a message (called once the whole
 * frame, overlays included, is resolved); VXL_OK for the other models. */
int vxl_frame_path_check(const vxl_frame *f, vxl_err *e);

/* Whether mode (VXL_MODE_*) shades: DVR and ISO do, the projections have no surface. */
static inline int vxl_mode_shades(uint32_t mode) { return mode == VXL_MODE_DVR || mode == VXL_MODE_ISO; }

/* Validates the mode fields of p (mode, iso_value, matcap) and how
 * the mode combines with classify, gradient_opacity and technique, into f.
 * Part of vxl_frame_resolve (frame_mode.c). */
int vxl_frame_resolve_mode(vxl_frame *f, const vxl_render_params *p, vxl_err *e);

/* labels: validates p->labels (mode, reserved, entries NULL with a
 * count, colours NaN or outside [0, 1], ids outside [0, VXL_MAX_LABEL_ID],
 * duplicate ids) into f->labels; needs f->mode and f->technique (labels take
 * the ray caster's DVR mode). SURFACE turns empty-space skipping off: the
 * intensity volume's occupancy says nothing of the labels'. Part of
 * vxl_frame_resolve (frame_labels.c). */
int vxl_frame_resolve_labels(vxl_frame *f, const vxl_render_params *p, vxl_err *e);
/* The label's own material (4 floats) of an entry read with `stride`, or
 * NULL when the entry has none (has_material 0, or a struct from before it). */
static inline const float *vxl_label_material(const vxl_label_entry *en, uint32_t stride)
{
    if (stride < offsetof(vxl_label_entry, material) + sizeof en->material || !en->has_material) return NULL;
    return en->material;
}

/* overlays: validates p->overlays (count <= VXL_MAX_OVERLAYS, the
 * stride, each slot in range, listed once and set (geoms[slot] non-NULL:
 * the overlay volume's geometry, else VXL_ERR_STATE), blend, interpolation,
 * reserved, a finite invertible model; DVR with the ray caster only, not
 * with SURFACE labels, pre-integration or gradient opacity) into
 * f->overlays, each transfer function and window resolved against its own
 * volume (vxl_frame_resolve_tf). Widens f->step and f->max_steps to the
 * union of all boxes, in the base volume's voxels. After vxl_frame_resolve
 * (it needs the mode, matrices and labels); frame_overlays.c. */
int vxl_frame_resolve_overlays(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *const geoms[VXL_MAX_OVERLAYS],
                               const vxl_volume_geom *base, vxl_err *e);
/* Frees what vxl_frame_resolve_overlays allocated (part of vxl_frame_free). */
void vxl_frame_overlays_free(vxl_frame *f);

/* Multi-channel drawing: validates p->channels (count <= VXL_MAX_CHANNELS,
 * the stride, each channel < n_channels and listed once, colours in [0, 1],
 * blend, reserved; the ray caster's DVR mode with post classification,
 * PHONG shading or none, no gradient opacity, labels, overlays or World's
 * light) into f->channels, each table and window resolved against its own
 * channel's value mapping geoms[c] (vxl_frame_resolve_tf). n_channels 0
 * with a nonzero channel_count is VXL_ERR_STATE. After vxl_frame_resolve
 * and vxl_frame_resolve_overlays; frame_channels.c. */
int vxl_frame_resolve_channels(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *geoms,
                               uint32_t n_channels, vxl_err *e);
/* Frees what vxl_frame_resolve_channels allocated (part of vxl_frame_free). */
void vxl_frame_channels_free(vxl_frame *f);
/* The default colour of channel c when its style gives none. */
void vxl_channel_default_color(uint32_t c, float rgb[3]);

/* The transfer function, window and opacity scale of p (preset or table,
 * resampled to at most 4096 entries and clamped) against volume g into
 * f->tf, f->tf_size, f->window_offset/scale, f->opacity_scale (f->tf_copy
 * owned). Part of vxl_frame_resolve; overlays resolve theirs with it. */
int vxl_frame_resolve_tf(vxl_frame *f, const vxl_render_params *p, const vxl_volume_geom *g, vxl_err *e);
/* A side volume's table from q (preset or table, window, opacity scale) on
 * geometry g, as vxl_frame_resolve_tf resolves the frame's, into *t (whose
 * tf_copy, if any, the caller frees). A failure's message is prefixed
 * "what[index]: ". */
int vxl_frame_resolve_table(vxl_frame_table *t, const vxl_render_params *q, const vxl_volume_geom *g, const char *what,
                            uint32_t index, vxl_err *e);

/* Validates p->scene_shadows into f's occluder fields: NULL
 * arrays with counts, indices out of range, vertices not finite and map
 * sizes out of range fail naming the field. Part of vxl_frame_resolve. */
int vxl_frame_resolve_scene_shadows(vxl_frame *f, const vxl_render_params *p, vxl_err *e);

/* Blender's spot mask (voxlight.h, vxl_light_shape.spot_blend) of light i
 * for a sample whose direction from the light makes cos_a with the spot's
 * axis: 1 inside the cone, 0 outside, smooth over the blend. */
double vxl_frame_spot_mask(const vxl_frame *f, int i, double cos_a);

/* The default camera: frames the volume's bounding sphere, orbiting about
 * world +Z by azimuth and elevation (degrees). */
void vxl_frame_default_camera(const vxl_volume_geom *g, uint32_t w, uint32_t h, double az_deg, double el_deg,
                              double view[16], double proj[16]);

#endif
