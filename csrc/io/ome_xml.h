/* ome_xml.h - the few facts an OME-TIFF's OME-XML (its first page's
 * ImageDescription) gives a volume reader: the first image's Pixels sizes
 * and DimensionOrder, which say which page holds which (z, c, t) plane, and
 * its channels' Name and Color. Not an XML parser: attributes of the
 * <Pixels> and <Channel> start tags are found by name, with the five
 * predefined entities decoded; everything else is ignored. Bounded by the
 * text's length, never recursive, so hostile text costs a scan. */
#ifndef VXL_OME_XML_H
#define VXL_OME_XML_H

#include <stddef.h>
#include <stdint.h>

#include "volume.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vxl_ome_pixels {
    char order[6];        /* DimensionOrder: "XY" then Z, C, T in some order, fastest first */
    uint64_t size[3];     /* SizeZ, SizeC, SizeT */
    uint64_t size_x, size_y;
    uint32_t channels;    /* <Channel> elements of the image (counted past VXL_MAX_CHANNELS) */
    vxl_channel_meta meta[VXL_MAX_CHANNELS]; /* Name, Color of the first VXL_MAX_CHANNELS */
    char notes[160];      /* a Name or Color not taken, for the volume's notes; "" */
} vxl_ome_pixels;

/* 1 when text[0..len) is OME-XML whose first <Pixels> has a valid
 * DimensionOrder and positive SizeX, SizeY, SizeZ, SizeC and SizeT (*p
 * filled); 0 otherwise (not OME, or not usable: the reader then reads the
 * pages as before). */
int vxl_ome_xml_parse(const char *text, size_t len, vxl_ome_pixels *p);

/* The 0-based page of plane (z, c, t) under p's DimensionOrder. */
uint64_t vxl_ome_page(const vxl_ome_pixels *p, uint64_t z, uint64_t c, uint64_t t);

#ifdef __cplusplus
}
#endif

#endif
