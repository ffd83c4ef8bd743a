/* helper_oiio.c - voxlight-read-oiio: the helper process that reads TIFF/PNG
 * stacks (image_stack.cpp), OpenVDB files (vdb.cpp) and OpenEXR World maps
 * (environment_exr.cpp) through OpenImageIO
 * for libvoxlight (reader_stream.h). Debian's libopenvdb aborts on some
 * corrupt files; in here that ends only this process. */
#include "helper_main.h"
#include "reader_stream.h"

int main(int argc, char **argv)
{
    static const vxl_helper_command cmds[] = {
        {.name = VXL_CMD_STACK, .read = vxl_image_stack_read},
        {.name = VXL_CMD_VDB, .read = vxl_vdb_read},
        {.name = VXL_CMD_ENVIRONMENT, .image = vxl_environment_exr_read},
    };
    return vxl_helper_main(VXL_HELPER_OIIO, argc, argv, cmds, (int)(sizeof cmds / sizeof cmds[0]));
}
