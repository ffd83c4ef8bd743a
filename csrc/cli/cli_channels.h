/* cli_channels.h - multi-channel volumes in the command-line tool
 * (docs/channels.md): --channel N (the scalar is channel N, rendered
 * alone as before), --channel-axis auto|on|off (how a file's channel axis
 * is read), --channels all|I,J,... (draw those channels in one march),
 * --channel-color I:R,G,B, --channel-window I:LO:HI, --channel-blend
 * add|max, and the channels lines of `info`. */
#ifndef VXL_CLI_CHANNELS_H
#define VXL_CLI_CHANNELS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "voxlight.h"

typedef struct vxl_cli_channels {
    int scalar_set;                   /* --channel given */
    int drawn;                        /* --channels given */
    int all;                          /* --channels all */
    uint32_t mask;                    /* --channels I,J,...: bit I */
    uint32_t blend;                   /* VXL_CHANNEL_BLEND_* */
    uint32_t color_mask, window_mask; /* which channels --channel-color / --channel-window set */
    float color[VXL_MAX_CHANNELS][3];
    float window[VXL_MAX_CHANNELS][2];
    vxl_channel_style styles[VXL_MAX_CHANNELS]; /* what params.channels points to after apply */
} vxl_cli_channels;

void vxl_cli_channels_init(vxl_cli_channels *c);
/* argv[*i] is one of the options: 1 (and *i past its value); a bad value: -1
 * with the message in err; not one of them: 0. c NULL (info): only the
 * load options (--channel, --channel-axis). */
int vxl_cli_channels_option(int argc, char **argv, int *i, vxl_cli_channels *c, vxl_load_options *lo, char *err,
                            size_t err_size);
/* Checks the options against the loaded volume (a channel it does not
 * have, colours or windows of channels not drawn, --channel of a volume
 * without channels) and points p's channels at the styles: -1 with the
 * message in err. */
int vxl_cli_channels_apply(vxl_cli_channels *c, const vxl_load_options *lo, const vxl_volume *v,
                           vxl_render_params *p, char *err, size_t err_size);
/* `info`: the channel count, which is the scalar, and each channel's range. */
void vxl_cli_channels_print_info(const vxl_volume_info *in, FILE *out);

#endif
