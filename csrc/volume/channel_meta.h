/* channel_meta.h - what a file says about its channels (vxl_channel_meta,
 * volume.h) taken from the forms OME writes them in: OME-Zarr's omero
 * "label" and "color": "RRGGBB", OME-XML's <Channel Name= Color=> whose
 * Color is a signed 32-bit RGBA integer. Shared by the OME-Zarr reader
 * (zarr_store.c) and the OME-TIFF reader (image_stack.cpp), so both decide
 * the same way and say so in the same words. */
#ifndef VXL_CHANNEL_META_H
#define VXL_CHANNEL_META_H

#include <stdint.h>

#include "volume.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The outcome of taking one value. */
enum { VXL_META_TAKEN, VXL_META_CUT /* name shortened */, VXL_META_REFUSED /* left unknown */ };

/* Copies name into m->name: cut at a UTF-8 character boundary to fit
 * VXL_CHANNEL_NAME_MAX (VXL_META_CUT); a name holding control characters
 * is refused (VXL_META_REFUSED, m->name stays ""), since names reach a
 * terminal and Blender's UI. */
int vxl_channel_meta_name(vxl_channel_meta *m, const char *name);

/* "RRGGBB" (an optional leading '#'; either case) into m->color_srgb /
 * 255 and has_color; anything else is VXL_META_REFUSED. */
int vxl_channel_meta_hex(vxl_channel_meta *m, const char *hex);

/* OME-XML's Color: the signed 32-bit integer of 0xRRGGBBAA (alpha
 * ignored: channels are blended additively). */
void vxl_channel_meta_rgba32(vxl_channel_meta *m, int64_t value);

#ifdef __cplusplus
}
#endif

#endif
