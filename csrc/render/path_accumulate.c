/* path_accumulate.c - vxl_path_accumulate (voxlight.h): the running mean
 * the viewport keeps over PATH calls of consecutive sample ranges, so the
 * caller needs no arithmetic of its own to refine frame by frame. */
#include "error.h"
#include "voxlight.h"

int vxl_path_accumulate(float *acc, const float *img, size_t n, uint32_t offset, uint32_t samples)
{
    if (!acc || !img) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "vxl_path_accumulate: acc or img is NULL");
    if (samples == 0) return vxl_fail(NULL, VXL_ERR_INVALID_ARGUMENT, "vxl_path_accumulate: samples is 0");
    /* acc holds the mean of `offset` samples, img that of the next `samples`:
     * weight img by its share of the total (offset 0: acc becomes img); equal
     * values stay, so a depth of +inf does not turn into NaN */
    const double total = (double)offset + samples;
    const float share = (float)(samples / total);
    for (size_t i = 0; i < n; i++) acc[i] = offset == 0 || img[i] == acc[i] ? img[i] : acc[i] + (img[i] - acc[i]) * share;
    return VXL_OK;
}
