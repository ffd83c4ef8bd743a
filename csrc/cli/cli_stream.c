/* cli_stream.c - streaming options, first-open progress, Ctrl-C and the
 * memory budget split of the command-line tool (cli_stream.h). */
#include "cli_stream.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "files.h"
#include "os.h"

#define CLI_DEFAULT_BUDGET (2ull << 30) /* voxlight.h: a budget of 0 means 2 GiB */

/* Set by SIGINT while a file is opened, returned by the progress callback
 * so the library stops and removes what it started. The tool is one
 * process with one open at a time, so a static flag is all it needs (the
 * library itself keeps no such state). */
static volatile sig_atomic_t interrupted;
/* C's signal(), which POSIX and Windows consoles both deliver Ctrl-C to
 * (glibc's restarts interrupted reads, so the library's reads go on and it
 * stops at its next progress call). */
static void (*previous_sigint)(int);

static void on_sigint(int sig)
{
    if (interrupted) { /* a second Ctrl-C: the open did not stop in time, stop now */
        signal(sig, SIG_DFL);
        raise(sig);
        return;
    }
    interrupted = 1;
}

void vxl_cli_stream_init(vxl_cli_stream *s)
{
    memset(s, 0, sizeof *s);
    s->streaming = VXL_STREAMING_AUTO;
    s->last_step = -1;
}

int vxl_cli_stream_option(int argc, char **argv, int *i, vxl_cli_stream *s, char *err, size_t err_size)
{
    const char *o = argv[*i];
    if (strcmp(o, "--streaming") && strcmp(o, "--cache-dir")) return 0;
    if (*i + 1 >= argc) {
        snprintf(err, err_size, "%s needs a value", o);
        return -1;
    }
    const char *val = argv[++*i];
    if (!strcmp(o, "--cache-dir")) {
        if (!*val) {
            snprintf(err, err_size, "--cache-dir needs a folder");
            return -1;
        }
        s->cache_dir = val;
        return 1;
    }
    if (vxl_streaming_from_name(val, &s->streaming) == VXL_OK) return 1;
    char names[64] = "";
    for (uint32_t m = 0; vxl_streaming_name(m); m++) {
        size_t len = strlen(names);
        snprintf(names + len, sizeof names - len, "%s%s", m ? ", " : "", vxl_streaming_name(m));
    }
    snprintf(err, err_size, "unknown --streaming '%s' (%s)", val, names);
    return -1;
}

static const char *base_name(const char *path)
{
    const char *slash = vxl_path_last_separator(path);
    return slash && slash[1] ? slash + 1 : path;
}

/* vxl_load_options.progress: a line rewritten in place on a terminal,
 * else one line per quarter of each stage, so a log stays short. Returns
 * nonzero (cancel) once Ctrl-C was pressed. */
static int print_progress(void *user, double fraction, const char *stage)
{
    vxl_cli_stream *s = user;
    if (!(fraction >= 0)) fraction = 0;
    if (fraction > 1) fraction = 1;
    if (!stage || !*stage) stage = "reading";
    int new_stage = strncmp(s->stage, stage, sizeof s->stage - 1) != 0;
    if (new_stage) {
        snprintf(s->stage, sizeof s->stage, "%s", stage);
        s->last_step = -1;
    }
    /* a terminal line changes with each whole percent, a log line with each quarter */
    int step = (int)(fraction * (s->tty ? 100.0 : 4.0));
    if (step > s->last_step) {
        s->last_step = step;
        if (s->tty) {
            fprintf(stderr, "\rvoxlight: %s: %s %3.0f%%\033[K", base_name(s->input), s->stage, fraction * 100.0);
            s->line_open = 1;
        } else {
            fprintf(stderr, "voxlight: %s: %s %.0f%%\n", base_name(s->input), s->stage, fraction * 100.0);
        }
        fflush(stderr);
    }
    return interrupted ? 1 : 0;
}

void vxl_cli_stream_begin(vxl_cli_stream *s, const char *input, uint64_t total_budget, vxl_load_options *lo)
{
    s->input = input;
    s->tty = vxl_os_is_terminal(stderr);
    s->line_open = 0;
    s->last_step = -1;
    s->stage[0] = '\0';
    s->total_budget = total_budget;
    /* The volume's CPU side gets half: a volume read whole (at most this
     * half) and its copy on the GL side then fit the budget together, and a
     * streamed volume's index, coarse level and brick cache leave the other
     * half to the renderer (vxl_cli_stream_renderer_budget). */
    s->volume_budget = (total_budget ? total_budget : CLI_DEFAULT_BUDGET) / 2;
    lo->memory_budget_bytes = s->volume_budget;
    lo->streaming = s->streaming;
    lo->cache_dir = s->cache_dir;
    lo->progress = print_progress;
    lo->progress_user = s;
    interrupted = 0;
    previous_sigint = signal(SIGINT, on_sigint);
}

int vxl_cli_stream_end(vxl_cli_stream *s, int load_rc)
{
    signal(SIGINT, previous_sigint == SIG_ERR ? SIG_DFL : previous_sigint);
    if (s->line_open) {
        fputc('\n', stderr);
        s->line_open = 0;
    }
    if (!interrupted && load_rc != VXL_ERR_CANCELLED) return 0;
    interrupted = 0;
    fprintf(stderr, "voxlight: cancelled: %s was not opened (Ctrl-C); no partial cache was kept\n", s->input);
    return VXL_CLI_CANCELLED_STATUS;
}

uint64_t vxl_cli_stream_renderer_budget(vxl_cli_stream *s, const vxl_volume *v)
{
    vxl_volume_info in = {.struct_size = sizeof in};
    s->streamed = vxl_volume_get_info(v, &in) == VXL_OK && in.streamed;
    if (!s->streamed)
        /* Read whole: the CPU copy is freed once it is on the GL side, so
         * the renderer may use the whole budget (as for any volume read whole). */
        return s->total_budget;
    uint64_t total = s->total_budget ? s->total_budget : CLI_DEFAULT_BUDGET;
    return total - s->volume_budget;
}

static void print_bytes(FILE *out, const char *label, uint64_t bytes)
{
    fprintf(out, "%s%.1f MiB\n", label, bytes / 1048576.0);
}

void vxl_cli_stream_print_info(const vxl_volume_info *in, FILE *out)
{
    fprintf(out, "streamed:    %s\n", in->streamed ? "yes (bricks read on demand)" : "no (read whole)");
    fprintf(out, "levels:      %u\n", in->level_count ? in->level_count : 1);
    print_bytes(out, "resident:    ", in->resident_bytes);
    print_bytes(out, "read:        ", in->bytes_read);
}

void vxl_cli_stream_print_stats(const vxl_cli_stream *s, const vxl_render_stats *st, FILE *out)
{
    if (!s->streamed) return;
    fprintf(out, "voxlight: streamed: the frame read %.1f MiB and waited %.1f ms for bricks; coarsest level drawn %u",
            st->bytes_read / 1048576.0, st->load_ms, st->stream_level);
    if (st->refine_pending) fprintf(out, ", %u bricks still coarser than wanted", st->refine_pending);
    fputc('\n', out);
}
