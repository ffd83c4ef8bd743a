/* cli_stream.h - data larger than memory in the command-line tool:
 * --streaming auto|off|on and --cache-dir DIR, the progress of a file's first
 * open on stderr, Ctrl-C during that open as a clean cancel, the split of
 * --memory-budget between the volume (CPU side) and the renderer (GL side),
 * and the streaming lines of `info` and `render`. */
#ifndef VXL_CLI_STREAM_H
#define VXL_CLI_STREAM_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "voxlight.h"

/* Exit status of a command cancelled with Ctrl-C (128 + SIGINT, as shells report it). */
#define VXL_CLI_CANCELLED_STATUS 130

typedef struct vxl_cli_stream {
    uint32_t streaming;     /* --streaming: VXL_STREAMING_* */
    const char *cache_dir;  /* --cache-dir; NULL: the library's default */
    uint64_t total_budget;  /* the whole process's budget (--memory-budget, else the library's default) */
    uint64_t volume_budget; /* the volume's share of it (vxl_load_options.memory_budget_bytes) */
    int streamed;           /* the volume opened is streamed (set by vxl_cli_stream_renderer_budget) */
    /* progress of the open in flight */
    const char *input;
    int tty;                /* stderr is a terminal: one line rewritten in place */
    int line_open;          /* a progress line without its newline is on the terminal */
    int last_step;          /* the last percent (terminal) or quarter (log) printed, -1 none */
    char stage[64];         /* the stage last printed */
} vxl_cli_stream;

void vxl_cli_stream_init(vxl_cli_stream *s);
/* argv[*i] is --streaming or --cache-dir: 1 (and *i past its value); a bad
 * value: -1 with the message in err; not one of them: 0. */
int vxl_cli_stream_option(int argc, char **argv, int *i, vxl_cli_stream *s, char *err, size_t err_size);

/* Before the volume is opened: fills lo's streaming fields, its progress
 * callback and its share of total_budget (0 = the library's default), and
 * makes Ctrl-C cancel the open instead of killing the process. */
void vxl_cli_stream_begin(vxl_cli_stream *s, const char *input, uint64_t total_budget, vxl_load_options *lo);
/* After the open returned load_rc: ends the progress line and restores
 * Ctrl-C. Returns 0 to go on, or VXL_CLI_CANCELLED_STATUS after printing
 * why when Ctrl-C came during the open (the caller frees *v, if any, and
 * exits with it). */
int vxl_cli_stream_end(vxl_cli_stream *s, int load_rc);

/* The renderer's share of the budget for volume v (vxl_renderer_options.memory_budget_bytes;
 * 0 = the library's default): see the usage text's "memory budget" note. */
uint64_t vxl_cli_stream_renderer_budget(vxl_cli_stream *s, const vxl_volume *v);

/* `info`: whether the volume is streamed, its levels, resident and read bytes. */
void vxl_cli_stream_print_info(const vxl_volume_info *in, FILE *out);
/* `render`: what a streamed volume's frame read and waited for (nothing for other volumes). */
void vxl_cli_stream_print_stats(const vxl_cli_stream *s, const vxl_render_stats *st, FILE *out);

#endif
