/* gl_bindings.h - every texture unit, image unit and shader-storage binding
 * the library uses, named once. A number with several names has several
 * jobs that never meet in one program (the comment says which program uses
 * which name). Samplers get their unit from C (vxl_uniform_i); images and
 * storage buffers are fixed in GLSL with layout(binding = ...), and GLSL
 * sees the same numbers through vxl_glsl_binding_defines(), which gl_util.c
 * puts before every shader's own defines. */
#ifndef VXL_GL_BINDINGS_H
#define VXL_GL_BINDINGS_H

/* Texture (sampler) units. */
#define VXL_VOLUME_UNIT 0         /* the volume texture or brick pool; a compute pass's source texture */
#define VXL_DERIVED_UNIT 1        /* raycast, probe: precomputed gradients or B-spline coefficients (one filter per program) */
#define VXL_TF_UNIT 2             /* the transfer-function table (1D) */
#define VXL_SCENE_DEPTH_UNIT 3    /* raycast: the host scene's depth */
#define VXL_DISTANCE_UNIT 4       /* raycast: the brick distance map of empty-space skipping */
#define VXL_CLASSIFIED_UNIT 5     /* raycast: the pre-classified volume (RGBA8) */
#define VXL_PREINT_UNIT 6         /* raycast: the pre-integration table */
#define VXL_SCRATCH_UNIT 7        /* used only to create and fill textures, so that never disturbs units 0-6 */
#define VXL_PAGE_UNIT 8           /* bricked storage: the page table */
#define VXL_GPAGE_UNIT 9          /* bricked storage: the gradient pool's page table */
#define VXL_CODE_UNIT 10          /* compressed storage: the code pool while decoding */
#define VXL_PALETTE_UNIT 11       /* compressed storage: the palettes */
#define VXL_CPAGE_UNIT 12         /* bricked storage: the coefficient pool's page table */
#define VXL_ILLUMINATION_UNIT 13  /* raycast, illumination.comp: the lights' transmittance and the occlusion, stacked */
#define VXL_EXTINCTION_UNIT 14    /* illumination.comp: the optical depth per cell the lights and occlusion read */
#define VXL_SHADOW_MAP_UNIT 15    /* illumination.comp (pass 3), scene_transmittance.comp: the lights' shadow maps */
#define VXL_MATCAP_UNIT 16        /* raycast: the MatCap image (render/matcap.c) */
#define VXL_LABELS_UNIT 18        /* raycast: the label volume (R16UI, labels/labels.c) */
#define VXL_LABEL_TABLE_UNIT 19   /* raycast: the per-label colour table */
#define VXL_ENVIRONMENT_UNIT 22   /* raycast: the World's irradiance volume (RGBA16F, light/illumination.c) */
#define VXL_LABEL_MARGIN_UNIT 20  /* raycast: per label voxel, its margin inside its own label (R8, labels/label_margin.c) */
#define VXL_COLOUR_UNIT 21        /* raycast, slices, slice_plane.comp: a colour volume's own colour (RGB8, colour/colour.c) */
#define VXL_LABEL_BRICKS_UNIT 23  /* raycast: per label brick, the visible-label distance map and uniform id (labels/label_bricks.c) */
/* Overlays (overlay/overlays.c) take three units each from 32 up (within GL 4.5's 80
 * combined units), so the units below stay free for the other rooms. */
#define VXL_OVERLAY_VOLUME_UNIT 32   /* raycast: overlay k's volume on unit 32 + k, k < VXL_MAX_OVERLAYS */
#define VXL_OVERLAY_TF_UNIT 35       /* raycast: overlay k's transfer function on unit 35 + k */
#define VXL_OVERLAY_DISTANCE_UNIT 38 /* raycast: overlay k's brick distance map (empty-space skipping) on unit 38 + k */
/* A multi-channel volume (channels/channels.c) takes units from 41 up, after the overlays'. */
#define VXL_CHANNEL_DATA_UNIT 41     /* raycast: channel group g's texture (four 16-bit channels) on unit 41 + g, g < 2 */
#define VXL_CHANNEL_TF_UNIT 43       /* raycast: channel c's transfer function on unit 43 + c, c < VXL_MAX_CHANNELS */
#define VXL_CHANNEL_DISTANCE_UNIT 51 /* raycast: the drawn channels' union brick distance map */
#define VXL_CHANNEL_PAGE_UNIT 52     /* raycast, paged storage: the page table of the channel groups' pools */
#define VXL_BRICK_MINMAX_UNIT 17  /* raycast: the brick min-max grid the modes skip by (render/mode_bricks.c) */
#define VXL_MAJORANT_UNIT 24      /* path.frag: the extinction majorant per skipping brick (render/path.c) */

/* The ray caster reads every unit above at once, so no two may share a
 * number: with distinct units the sum of their bits equals their union
 * (two rooms added on separate branches once took the same unit). */
#define VXL_UNIT_BIT_(u) (1ull << (u))
#define VXL_UNITS_SUM_                                                                                               \
    (VXL_UNIT_BIT_(VXL_VOLUME_UNIT) + VXL_UNIT_BIT_(VXL_DERIVED_UNIT) + VXL_UNIT_BIT_(VXL_TF_UNIT) +                  \
     VXL_UNIT_BIT_(VXL_SCENE_DEPTH_UNIT) + VXL_UNIT_BIT_(VXL_DISTANCE_UNIT) + VXL_UNIT_BIT_(VXL_CLASSIFIED_UNIT) +    \
     VXL_UNIT_BIT_(VXL_PREINT_UNIT) + VXL_UNIT_BIT_(VXL_SCRATCH_UNIT) + VXL_UNIT_BIT_(VXL_PAGE_UNIT) +                \
     VXL_UNIT_BIT_(VXL_GPAGE_UNIT) + VXL_UNIT_BIT_(VXL_CODE_UNIT) + VXL_UNIT_BIT_(VXL_PALETTE_UNIT) +                 \
     VXL_UNIT_BIT_(VXL_CPAGE_UNIT) + VXL_UNIT_BIT_(VXL_ILLUMINATION_UNIT) + VXL_UNIT_BIT_(VXL_EXTINCTION_UNIT) +      \
     VXL_UNIT_BIT_(VXL_SHADOW_MAP_UNIT) + VXL_UNIT_BIT_(VXL_MATCAP_UNIT) + VXL_UNIT_BIT_(VXL_LABELS_UNIT) +           \
     VXL_UNIT_BIT_(VXL_LABEL_TABLE_UNIT) + VXL_UNIT_BIT_(VXL_ENVIRONMENT_UNIT) + VXL_UNIT_BIT_(VXL_LABEL_MARGIN_UNIT) + \
     VXL_UNIT_BIT_(VXL_COLOUR_UNIT) + VXL_UNIT_BIT_(VXL_LABEL_BRICKS_UNIT) + VXL_UNIT_BIT_(VXL_BRICK_MINMAX_UNIT) +    \
     VXL_UNIT_BIT_(VXL_MAJORANT_UNIT) +    \
     (7ull << VXL_OVERLAY_VOLUME_UNIT) + (7ull << VXL_OVERLAY_TF_UNIT) + (7ull << VXL_OVERLAY_DISTANCE_UNIT) +      \
     (3ull << VXL_CHANNEL_DATA_UNIT) + (255ull << VXL_CHANNEL_TF_UNIT) + VXL_UNIT_BIT_(VXL_CHANNEL_DISTANCE_UNIT) +    \
     VXL_UNIT_BIT_(VXL_CHANNEL_PAGE_UNIT))
#define VXL_UNITS_UNION_                                                                                             \
    (VXL_UNIT_BIT_(VXL_VOLUME_UNIT) | VXL_UNIT_BIT_(VXL_DERIVED_UNIT) | VXL_UNIT_BIT_(VXL_TF_UNIT) |                  \
     VXL_UNIT_BIT_(VXL_SCENE_DEPTH_UNIT) | VXL_UNIT_BIT_(VXL_DISTANCE_UNIT) | VXL_UNIT_BIT_(VXL_CLASSIFIED_UNIT) |    \
     VXL_UNIT_BIT_(VXL_PREINT_UNIT) | VXL_UNIT_BIT_(VXL_SCRATCH_UNIT) | VXL_UNIT_BIT_(VXL_PAGE_UNIT) |                \
     VXL_UNIT_BIT_(VXL_GPAGE_UNIT) | VXL_UNIT_BIT_(VXL_CODE_UNIT) | VXL_UNIT_BIT_(VXL_PALETTE_UNIT) |                 \
     VXL_UNIT_BIT_(VXL_CPAGE_UNIT) | VXL_UNIT_BIT_(VXL_ILLUMINATION_UNIT) | VXL_UNIT_BIT_(VXL_EXTINCTION_UNIT) |      \
     VXL_UNIT_BIT_(VXL_SHADOW_MAP_UNIT) | VXL_UNIT_BIT_(VXL_MATCAP_UNIT) | VXL_UNIT_BIT_(VXL_LABELS_UNIT) |           \
     VXL_UNIT_BIT_(VXL_LABEL_TABLE_UNIT) | VXL_UNIT_BIT_(VXL_ENVIRONMENT_UNIT) | VXL_UNIT_BIT_(VXL_LABEL_MARGIN_UNIT) | \
     VXL_UNIT_BIT_(VXL_COLOUR_UNIT) | VXL_UNIT_BIT_(VXL_LABEL_BRICKS_UNIT) | VXL_UNIT_BIT_(VXL_BRICK_MINMAX_UNIT) |    \
     VXL_UNIT_BIT_(VXL_MAJORANT_UNIT) |    \
     (7ull << VXL_OVERLAY_VOLUME_UNIT) | (7ull << VXL_OVERLAY_TF_UNIT) | (7ull << VXL_OVERLAY_DISTANCE_UNIT) |      \
     (3ull << VXL_CHANNEL_DATA_UNIT) | (255ull << VXL_CHANNEL_TF_UNIT) | VXL_UNIT_BIT_(VXL_CHANNEL_DISTANCE_UNIT) |    \
     VXL_UNIT_BIT_(VXL_CHANNEL_PAGE_UNIT))
_Static_assert(VXL_UNITS_SUM_ == VXL_UNITS_UNION_, "two texture units share a number (gl_bindings.h)");

/* Image units. */
#define VXL_IMAGE_OUT 0           /* every compute pass: the texture it writes (the B-spline prefilter also reads it) */
#define VXL_IMAGE_SLICE_ACCUM 1   /* slices.frag: the colour attachment, read and composited slice by slice */
#define VXL_IMAGE_SLICE_DEPTH 2   /* slices.frag: the depth attachment, the same way */

/* Shader-storage buffer bindings. */
#define VXL_SSBO_GRADIENT_MAX 0   /* gradients.comp's max pass: the largest |gradient| as float bits */
#define VXL_SSBO_PROBE_POINTS 0   /* probe.comp: the points to probe */
#define VXL_SSBO_PROBE_RESULTS 1  /* probe.comp: what it measured */
#define VXL_SSBO_STATS 2          /* raycast.frag: the frame's sample counts */
#define VXL_SSBO_CUT_LAYERS 3     /* raycast, cut_peel.frag: the cutter crossings per pixel (cut/cutaway.c) */
#define VXL_SSBO_BRICK_LIST 2     /* gradients.comp (bricked), decode_bricks.comp: per slot, the brick (or code slot) to derive */

#define VXL_GLSL_STR_(x) #x
#define VXL_GLSL_STR(x) VXL_GLSL_STR_(x)
#define VXL_GLSL_DEFINE(name) "#define " #name " " VXL_GLSL_STR(name) "\n"

/* The image and storage bindings above as GLSL #defines, one a line, for
 * layout(binding = VXL_...) in shaders. */
static inline const char *vxl_glsl_binding_defines(void)
{
    return VXL_GLSL_DEFINE(VXL_IMAGE_OUT) VXL_GLSL_DEFINE(VXL_SSBO_GRADIENT_MAX) VXL_GLSL_DEFINE(VXL_SSBO_PROBE_POINTS)
        VXL_GLSL_DEFINE(VXL_SSBO_PROBE_RESULTS) VXL_GLSL_DEFINE(VXL_SSBO_STATS) VXL_GLSL_DEFINE(VXL_SSBO_BRICK_LIST) VXL_GLSL_DEFINE(VXL_SSBO_CUT_LAYERS)
        VXL_GLSL_DEFINE(VXL_IMAGE_SLICE_ACCUM) VXL_GLSL_DEFINE(VXL_IMAGE_SLICE_DEPTH);
}

#endif
