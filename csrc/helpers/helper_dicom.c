/* helper_dicom.c - voxlight-read-dicom: the helper process that reads DICOM
 * series (dicom.cpp) through dcmtk for libvoxlight (reader_stream.h), and
 * lists the series of a folder for vxl_dicom_list_series. */
#include "helper_main.h"
#include "reader_stream.h"

int main(int argc, char **argv)
{
    static const vxl_helper_command cmds[] = {
        {.name = VXL_CMD_DICOM, .read = vxl_dicom_read},
        {.name = VXL_CMD_DICOM_SERIES, .list = vxl_dicom_read_series},
    };
    return vxl_helper_main(VXL_HELPER_DICOM, argc, argv, cmds, (int)(sizeof cmds / sizeof cmds[0]));
}
