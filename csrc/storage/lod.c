/* lod.c - 2x box downsampling of a CPU volume for the LOD fallback. */
#include "lod.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int vxl_volume_downsample2(const vxl_volume *v, vxl_volume **out, vxl_err *e)
{
    *out = NULL;
    vxl_volume *d = malloc(sizeof *d);
    if (!d) return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a coarser level");
    *d = *v;
    d->colour = NULL; /* a coarser level is of the scalar: the colour texture stays at full resolution */
    d->channels = NULL; /* and so are a multi-channel volume's channels */
    d->channel_count = 0;
    for (int a = 0; a < 3; a++) {
        d->dims[a] = (v->dims[a] + 1) / 2;
        d->spacing[a] = v->spacing[a] * 2;
    }
    const size_t n = (size_t)d->dims[0] * d->dims[1] * d->dims[2], bpv = v->texture_bits / 8;
    d->storage_bytes = n * bpv;
    if (!(d->texels = malloc(n * bpv))) {
        free(d);
        return vxl_fail(e, VXL_ERR_NO_MEMORY, "out of memory for a coarser level of %zu voxels", n);
    }
    for (uint32_t z = 0; z < d->dims[2]; z++)
        for (uint32_t y = 0; y < d->dims[1]; y++)
            for (uint32_t x = 0; x < d->dims[0]; x++) {
                const uint32_t c[3] = {x, y, z};
                uint32_t lo[3], hi[3];
                for (int a = 0; a < 3; a++) {
                    lo[a] = 2 * c[a];
                    hi[a] = 2 * c[a] + 1 < v->dims[a] ? 2 * c[a] + 1 : v->dims[a] - 1;
                }
                double s = 0;
                for (int k = 0; k < 8; k++) /* the corners, repeated where the volume ends */
                    s += vxl_volume_texel(v, ((k & 1) ? hi[0] : lo[0]) +
                                                 (size_t)v->dims[0] * (((k & 2) ? hi[1] : lo[1]) +
                                                                       (size_t)v->dims[1] * ((k & 4) ? hi[2] : lo[2])));
                s /= 8;
                size_t i = x + (size_t)d->dims[0] * (y + (size_t)d->dims[1] * z);
                if (bpv == 1) ((uint8_t *)d->texels)[i] = (uint8_t)lround(s * 255);
                else if (bpv == 2) ((uint16_t *)d->texels)[i] = (uint16_t)lround(s * 65535);
                else ((float *)d->texels)[i] = (float)s;
            }
    *out = d;
    return VXL_OK;
}
