/* helper_zarr.c - voxlight-read-zarr: the helper process that reads
 * OME-Zarr stores (zarr.h) for libvoxlight (reader_stream.h). It links
 * libzstd and libblosc, which libvoxlight.so must not (the library loads
 * inside Blender, next to Blender's own copies), and a decoder fault on a
 * hostile chunk ends only this process. */
#include "helper_main.h"
#include "reader_stream.h"
#include "zarr.h"

int main(int argc, char **argv)
{
    static const vxl_helper_command cmds[] = {
        {.name = VXL_CMD_ZARR, .read = vxl_zarr_read},
    };
    return vxl_helper_main(VXL_HELPER_ZARR, argc, argv, cmds, (int)(sizeof cmds / sizeof cmds[0]));
}
