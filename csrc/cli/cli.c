/* cli.c - the `voxlight` command-line tool: `render`, `info` and `labels`. Every
 * failure ends with one line "voxlight: error: ..." and exit status 1; Ctrl-C
 * while a file is first opened ends with "voxlight: cancelled: ..." and exit
 * status 130 (cli_stream.c). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "clock.h"
#include "os.h"

#include "cli_cut.h"   /* --clip-plane, --crop, --no-caps */
#include "cli_environment.h" /* --environment, --environment-rotation: the World's light */
#include "cli_modes.h" /* --mode, --iso-value, --matcap, --ortho, --view */
#include "cli_labels.h" /* the labels command */
#include "cli_labels_render.h" /* render --labels ... */
#include "cli_overlays.h" /* render --overlay ... */
#include "cli_channels.h" /* --channel, --channels, --channel-color, --channel-window, --channel-blend */
#include "cli_colour.h" /* --color-source, --opacity-source, the components line */
#include "cli_stream.h" /* --streaming, --cache-dir, first-open progress, Ctrl-C, budget split */
#include "cli_path.h" /* --samples, --sample-offset, --bounces, --seed: --shading path */
#include "voxlight_dev.h" /* phantoms (phantom:NAME inputs) and --no-skip */

/* The option values come from the library's name functions (vxl_*_name),
 * filled in by print_usage, so a value added there shows up here. */
static const char usage_format[] =
    "usage:\n"
    "  voxlight render INPUT -o OUT.png|OUT.exr [--size WxH] [--filter NAME] [--sample-distance D]\n"
    "                  [--reuse-gradients] [--step S] [--azimuth DEG] [--elevation DEG] [--preset NAME]\n"
    "                  [--window LO:HI] [--no-shading] [--backend %s] [--memory-budget SIZE]\n"
    "                  [--gradient-store %s] [--classify %s] [--no-jitter] [--no-skip]\n"
    "                  [--gradient-opacity %s] [--gradient-ref G] [--iso VALUE] [--iso-thickness R]\n"
    "                  [--voxel-size X[,Y,Z]] [--frame N] [--series N|UID]\n"
    "                  [--storage %s] [--page-brick 8|16|32|64] [--renderer %s]\n"
    "                  [--light dir:X,Y,Z[,INTENSITY] | point:X,Y,Z[,INTENSITY]]... [--shading %s]\n"
    "                  [--ambient-occlusion RADIUS] [--anisotropy G] [--samples N] [--sample-offset K]\n"
    "                  [--bounces B] [--seed S]\n"
    "                  [--environment FILE.hdr|FILE.exr|R,G,B[,STRENGTH]] [--environment-rotation DEG]\n"
    "                  [--mode %s] [--iso-value V] [--matcap FILE.png] [--ortho]\n"
    "                  [--view x|-x|y|-y|z|-z] [--streaming %s] [--cache-dir DIR]\n"
    "                  [--clip-plane A,B,C,D[,T]]... [--crop X0:X1,Y0:Y1,Z0:Z1] [--no-caps]\n"
    "                  [--labels LABELS [--label-lut FILE] [--label-mode surface|mask|tint] [--label-surface smooth|voxels]\n"
    "                   [--hide-labels ID,...] [--label-opacity ID:ALPHA,...]]\n"
    "                  [--overlay FILE[:PRESET][:LO:HI] [--overlay-blend over|add|max] [--overlay-opacity X]]...\n"
    "                  [--color-source auto|data|tf] [--opacity-source luminance|alpha|channel:N]\n"
    "                  [--color-space display|linear]\n"
    "                  [--channel N] [--channel-axis auto|on|off] [--channels all|I,J,...\n"
    "                   [--channel-color I:R,G,B]... [--channel-window I:LO:HI]... [--channel-blend add|max]]\n"
    "  voxlight info INPUT [--voxel-size X[,Y,Z]] [--frame N] [--series N|UID] [--streaming MODE] [--cache-dir DIR]\n"
    "                  [--opacity-source luminance|alpha|channel:N] [--channel N] [--channel-axis auto|on|off]\n"
    "  voxlight labels FILE   (a label lookup table: FreeSurfer LUT, ITK-SNAP, Slicer .ctbl, MRIcron .lut/.txt)\n"
    "INPUT: a file, a folder of images or DICOM slices, a DICOMDIR; --frame picks a volume of a 4D file,\n"
    "--series a series of a DICOM folder (index or SeriesInstanceUID, as `info` lists them);\n"
    "--voxel-size (mm) is for inputs without geometry (TIFF/PNG stacks); one value sets all three\n"
    "memory budget: --memory-budget SIZE (default 2G) bounds the volume and the renderer together: the\n"
    "         volume's CPU side gets half (a file read whole must fit it); a streamed volume keeps its index,\n"
    "         coarse level and brick cache in that half and the renderer (GL side) gets the other half; a\n"
    "         volume read whole is freed once uploaded, so the renderer may then use all of it\n"
    "streaming: auto reads bricks on demand when the voxels exceed half of the volume's share, on always,\n"
    "         off never; a .nii.gz is streamed once into a bricked cache (beside the file, or in --cache-dir)\n"
    "         with progress on stderr; Ctrl-C during that first open cancels it (exit status 130, no cache kept)\n"
    "colour (RGB, RGBA: NIfTI RGB24/RGBA32, vector NIfTI): rendered in the data's colour (--color-source\n"
    "         auto or data; tf: the transfer function's), opacity from the transfer function of the\n"
    "         --opacity-source scalar (luminance by default, alpha, or channel:N, 0 red .. 3 alpha)\n"
    "channels (NIfTI dim[5], an NRRD channel axis; docs/channels.md): --channel N renders channel N alone\n"
    "         (default 0); --channels all or I,J,... draws those in one pass, each in its colour (default red,\n"
    "         green, blue, magenta, cyan, yellow, orange, white; --channel-color, linear 0..1) through a grey\n"
    "         ramp over its window (default its data range; --channel-window in its data units), blended\n"
    "         add (default: the sum of the channels) or max (the most opaque channel at each step);\n"
    "         --channel-axis on reads a 3-4 entry axis as channels rather than colour, off never as channels\n"
    "filters: %s; presets: %s\n"
    "storage: auto = one texture when it fits the texture limit and --memory-budget, else bricked;\n"
    "         sparse keeps only the bricks the transfer function can show; compressed holds every brick\n"
    "         as a palette of <= 256 values + 8-bit codes and decodes the visible ones into a cache\n"
    "         (compressed storage: every filter but precomputed and cubic; bricked and sparse: every filter and mode)\n"
    "renderer: raycast (default); slices2d / slices3d are the slice-based comparison modes (docs/slicing.md)\n"
    "lights: --light (repeatable, up to 8) replaces the headlight: dir: the world direction towards a\n"
    "         directional light, point: a point light's world position; INTENSITY > 0, default 1.\n"
    "         --shading phong: local lighting; shadowed: with shadows and --ambient-occlusion (voxels,\n"
    "         0 = off); scatter: also single scattering, forward for --anisotropy G > 0 (-0.99..0.99)\n"
    "         path: multiple scattering by path tracing, the mean of --samples N (default 1) per pixel\n"
    "         from sample --sample-offset K, up to --bounces B (default 4, 1 = single scattering) per\n"
    "         path; --seed S picks the noise (the same seed, the same image) (docs/lighting.md)\n"
    "environment: --environment lights the volume from every side, as Blender's World: a Radiance .hdr\n"
    "         latitude-longitude map (Blender's equirectangular mapping) or a uniform linear colour, times\n"
    "         STRENGTH (default 1), turned by --environment-rotation DEG about world +Z (a Mapping node's Z\n"
    "         rotation); with no --light it replaces the headlight (docs/lighting.md)\n"
    "cutaways: --clip-plane (repeatable, up to 6) keeps A x + B y + C z + D >= 0 (world mm), only the slab\n"
    "         up to T mm from the plane when T > 0; --crop keeps voxels X0..X1, Y0..Y1, Z0..Z1 (indices from 0,\n"
    "         inclusive); cut faces are shaded as surfaces (caps) unless --no-caps (docs/cutaways.md)\n"
    "labels: --labels draws an integer label image (any loader) with its lookup file (--label-lut, else the\n"
    "         same stem with .lut/.txt/.ctbl/.label beside it, else a palette for every nonzero id);\n"
    "         surface (default) shades each label as a surface, mask / tint apply the transfer function\n"
    "         inside visible labels (tint: times the label colour) (docs/labels.md)\n"
    "overlays: --overlay (repeatable, up to 3) adds a volume in its own grid (placed by its affine) to the\n"
    "         same ray march, classified by PRESET (default auto) and the window LO:HI in its data units;\n"
    "         --overlay-blend and --overlay-opacity (a scale, > 0) set the --overlay given last (docs/overlays.md)\n"
    "INPUT may be a generated phantom: phantom:NAME[:WxHxD], NAME one of\n"
    "         %s\n"
    "         (large-sparse: default 2500x1500x400, 1.5 GB of 8-bit voxels)\n";

typedef const char *(*name_fn)(uint32_t value);

/* The names of one of the library's enumerations from value `first` up to
 * the first NULL, joined by sep, into buf. */
static const char *name_list(name_fn name, uint32_t first, const char *sep, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (uint32_t i = first; name(i); i++) {
        int n = snprintf(buf + len, size - len, "%s%s", i > first ? sep : "", name(i));
        if (n < 0 || (size_t)n >= size - len) break;
        len += (size_t)n;
    }
    return buf;
}

static void print_usage(FILE *out)
{
    char backends[64], stores[64], classify[64], gopacity[64], storage[128], filters[256], presets[128], phantoms[256],
        techniques[64], shading[64], modes[64], streaming[64];
    fprintf(out, usage_format, name_list(vxl_backend_name, 0, "|", backends, sizeof backends),
            name_list(vxl_gradient_store_name, 0, "|", stores, sizeof stores),
            name_list(vxl_classify_name, 0, "|", classify, sizeof classify),
            name_list(vxl_gradient_opacity_name, 0, "|", gopacity, sizeof gopacity),
            name_list(vxl_storage_name, 0, "|", storage, sizeof storage),
            name_list(vxl_technique_name, 0, "|", techniques, sizeof techniques),
            name_list(vxl_shading_model_name, 0, "|", shading, sizeof shading),
            name_list(vxl_mode_name, 0, "|", modes, sizeof modes),
            name_list(vxl_streaming_name, 0, "|", streaming, sizeof streaming),
            name_list(vxl_filter_name, 0, " ", filters, sizeof filters),
            name_list(vxl_preset_name, 0, " ", presets, sizeof presets),
            name_list(vxl_phantom_name, 1, " ", phantoms, sizeof phantoms));
}

static int die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("voxlight: error: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return 1;
}

static int parse_float(const char *s, float *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v)) return 0;
    *out = (float)v;
    return 1;
}

/* "2G", "512M", "1048576" -> bytes */
static int parse_size(const char *s, uint64_t *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || !(v > 0) || !isfinite(v)) return 0;
    double mul = 1;
    if (*end) {
        switch (*end) {
        case 'k': case 'K': mul = 1024.0; break;
        case 'm': case 'M': mul = 1048576.0; break;
        case 'g': case 'G': mul = 1073741824.0; break;
        case 't': case 'T': mul = 1099511627776.0; break;
        default: return 0;
        }
        if (end[1] && strcasecmp(end + 1, "b") && strcasecmp(end + 1, "ib")) return 0;
    }
    if (v * mul >= 1.8e19) return 0;
    *out = (uint64_t)(v * mul);
    return 1;
}

/* "0.5" or "0.5,0.5,2" -> voxel size in mm, each finite and > 0 */
static int parse_voxel_size(const char *s, double out[3])
{
    char *end;
    for (int a = 0; a < 3; a++) {
        out[a] = strtod(s, &end);
        if (end == s || !isfinite(out[a]) || !(out[a] > 0)) return 0;
        if (a == 0 && !*end) {
            out[1] = out[2] = out[0];
            return 1;
        }
        if (*end != (a < 2 ? ',' : '\0')) return 0;
        s = end + 1;
    }
    return 1;
}

static int voxel_size_option(const char *val, vxl_load_options *lo)
{
    if (!val) return die("--voxel-size needs a value");
    if (!parse_voxel_size(val, lo->voxel_size)) return die("bad --voxel-size '%s': use X,Y,Z or one value in mm, each > 0", val);
    return 0;
}

/* A value of one of the library's enumerations given by name; an unknown
 * name is an error listing the names there are. `what` names the option in
 * the message. */
static int enum_option(const char *what, const char *val, name_fn name, int (*from_name)(const char *, uint32_t *),
                       uint32_t *out)
{
    if (from_name(val, out) == VXL_OK) return 0;
    char names[256];
    return die("unknown %s '%s' (%s)", what, val, name_list(name, 0, ", ", names, sizeof names));
}

/* "dir:X,Y,Z[,INTENSITY]" or "point:X,Y,Z[,INTENSITY]" -> a light in world
 * space. */
static int light_option(const char *val, vxl_render_params *p)
{
    if (p->light_count >= VXL_MAX_LIGHTS) return die("more than %d --light options", VXL_MAX_LIGHTS);
    vxl_light *l = &p->lights[p->light_count];
    memset(l, 0, sizeof *l);
    const char *s;
    if (!strncmp(val, "dir:", 4)) s = val + 4;
    else if (!strncmp(val, "point:", 6)) s = val + 6, l->position[3] = 1;
    else return die("bad --light '%s': use dir:X,Y,Z[,INTENSITY] or point:X,Y,Z[,INTENSITY]", val);
    float v[4] = {0, 0, 0, 1}; /* X, Y, Z, intensity */
    int n = 0;
    for (;;) {
        char *end;
        double x = strtod(s, &end);
        if (n == 4 || end == s || !isfinite(x) || (*end && *end != ','))
            return die("bad --light '%s': three numbers X,Y,Z and an optional intensity", val);
        v[n++] = (float)x;
        if (!*end) break;
        s = end + 1;
    }
    if (n < 3) return die("bad --light '%s': three numbers X,Y,Z and an optional intensity", val);
    if (!(v[3] > 0) || v[3] > 1e6) return die("bad --light '%s': the intensity must be in (0, 1e6]", val);
    if (l->position[3] == 0 && v[0] == 0 && v[1] == 0 && v[2] == 0)
        return die("bad --light '%s': a direction cannot be zero", val);
    memcpy(l->position, v, 3 * sizeof *v);
    l->intensity = v[3];
    p->light_count++;
    return 0;
}

/* --light, --shading, --ambient-occlusion, --anisotropy. Returns
 * 1 if argv[*i] was one of them (*i advanced past its value), -1 on a bad
 * value, 0 otherwise. The library checks the ranges and names the field. */
static int parse_lighting_option(int argc, char **argv, int *i, vxl_render_params *p)
{
    const char *o = argv[*i];
    if (strcmp(o, "--light") && strcmp(o, "--shading") && strcmp(o, "--ambient-occlusion") &&
        strcmp(o, "--anisotropy"))
        return 0;
    if (*i + 1 >= argc) { die("%s needs a value", o); return -1; }
    const char *val = argv[++*i];
    if (!strcmp(o, "--light")) return light_option(val, p) ? -1 : 1;
    if (!strcmp(o, "--shading"))
        return enum_option("--shading", val, vxl_shading_model_name, vxl_shading_model_from_name, &p->shading_model)
                   ? -1 : 1;
    if (!strcmp(o, "--ambient-occlusion")) {
        if (!parse_float(val, &p->ambient_occlusion) || p->ambient_occlusion < 0)
            return die("bad --ambient-occlusion '%s': a radius in voxels, 0 = off", val), -1;
        return 1;
    }
    if (!parse_float(val, &p->anisotropy) || !(fabsf(p->anisotropy) < 1))
        return die("bad --anisotropy '%s': a number between -1 and 1 (exclusive)", val), -1;
    return 1;
}

/* --frame N / --series S / --voxel-size X[,Y,Z], shared by render and info.
 * Returns 1 if o was one of them (*i advanced past its value), -1 on a bad
 * value, 0 otherwise. */
static int parse_input_option(int argc, char **argv, int *i, vxl_load_options *lo)
{
    const char *o = argv[*i];
    if (strcmp(o, "--frame") && strcmp(o, "--series") && strcmp(o, "--voxel-size")) return 0;
    if (*i + 1 >= argc) { die("%s needs a value", o); return -1; }
    const char *val = argv[++*i];
    if (!strcmp(o, "--voxel-size")) return voxel_size_option(val, lo) ? -1 : 1;
    if (!strcmp(o, "--series")) {
        if (!*val) { die("--series needs an index or a SeriesInstanceUID"); return -1; }
        lo->series = val;
        return 1;
    }
    char *end;
    unsigned long f = strtoul(val, &end, 10);
    if (end == val || *end || val[0] == '-' || f > UINT32_MAX) { die("bad --frame '%s': a frame number from 0", val); return -1; }
    lo->frame = (uint32_t)f;
    return 1;
}

/* The series of a DICOM input, one line each; nothing for other formats.
 * Returns how many there are. */
static uint32_t print_dicom_series(const char *path)
{
    uint32_t n = 0;
    if (vxl_dicom_list_series(path, NULL, 0, &n) || n == 0) return 0;
    vxl_dicom_series *s = calloc(n, sizeof *s);
    if (!s) return 0;
    s[0].struct_size = sizeof *s;
    if (vxl_dicom_list_series(path, s, n, &n) == VXL_OK) {
        printf("DICOM series: %u\n", n);
        for (uint32_t i = 0; i < n; i++) {
            printf("  [%u] %s  %s  %u x %u x %u", i, s[i].uid, s[i].modality[0] ? s[i].modality : "?", s[i].dims[0],
                   s[i].dims[1], s[i].dims[2]);
            if (s[i].frame_count > 1) printf(" x %u time points", s[i].frame_count);
            if (s[i].description[0]) printf("  \"%s\"", s[i].description);
            if (s[i].gantry_tilt_deg > 0) printf("  gantry tilt %.2f deg (sheared affine)", s[i].gantry_tilt_deg);
            if (!s[i].loadable) printf("  NOT LOADABLE: %s", s[i].problem);
            printf("\n");
        }
    }
    free(s);
    return n;
}

/* "phantom:NAME[:WxHxD]" generates an analytic phantom, anything else is a
 * file. Returns 0 or the library's error code (message in vxl_last_error). */
static int load_input(const char *input, const vxl_load_options *lo, vxl_volume **v)
{
    if (strncmp(input, "phantom:", 8)) return vxl_volume_load(input, lo, v);
    char name[64];
    const char *colon = strchr(input + 8, ':');
    size_t len = colon ? (size_t)(colon - input - 8) : strlen(input + 8);
    if (len >= sizeof name) len = sizeof name - 1;
    memcpy(name, input + 8, len);
    name[len] = '\0';
    vxl_phantom_desc d = {.struct_size = sizeof d};
    for (uint32_t k = 1; k < VXL_PHANTOM_COUNT; k++)
        if (!strcmp(vxl_phantom_name(k), name)) d.kind = k;
    if (!d.kind) return die("unknown phantom '%s' (see voxlight --help)", name), VXL_ERR_INVALID_ARGUMENT;
    char extra;
    if (colon && (sscanf(colon + 1, "%ux%ux%u%c", &d.dims[0], &d.dims[1], &d.dims[2], &extra) != 3 || !d.dims[0] ||
                  !d.dims[1] || !d.dims[2]))
        return die("bad phantom size '%s': use WxHxD", colon + 1), VXL_ERR_INVALID_ARGUMENT;
    int rc = vxl_phantom_create(&d, v);
    if (rc) die("%s", vxl_last_error());
    return rc;
}

static int cmd_info(int argc, char **argv)
{
    vxl_load_options lo = {.struct_size = sizeof lo};
    vxl_cli_stream stream;
    vxl_cli_stream_init(&stream);
    char serr[512];
    const char *input = NULL;
    for (int i = 0; i < argc; i++) {
        int r = parse_input_option(argc, argv, &i, &lo);
        if (r < 0) return 1;
        if (r) continue;
        if ((r = vxl_cli_stream_option(argc, argv, &i, &stream, serr, sizeof serr)) != 0 ||
            (r = vxl_cli_colour_option(argc, argv, &i, NULL, &lo, serr, sizeof serr)) != 0 ||
            (r = vxl_cli_channels_option(argc, argv, &i, NULL, &lo, serr, sizeof serr)) != 0) {
            if (r < 0) return die("%s", serr);
            continue;
        }
        if (argv[i][0] == '-' && argv[i][1]) return die("unknown option '%s' (see voxlight --help)", argv[i]);
        if (input) return die("info takes one INPUT (see voxlight --help)");
        input = argv[i];
    }
    if (!input) return die("info takes one INPUT (see voxlight --help)");
    /* several series and none chosen: the listing is the answer */
    uint32_t series = print_dicom_series(input);
    if (series > 1 && !lo.series) {
        printf("choose one with --series N|UID\n");
        return 0;
    }
    vxl_volume *v = NULL;
    vxl_cli_stream_begin(&stream, input, 0, &lo);
    int load_rc = load_input(input, &lo, &v);
    int cancelled = vxl_cli_stream_end(&stream, load_rc);
    if (cancelled) return vxl_volume_destroy(v), cancelled;
    if (load_rc) return strncmp(input, "phantom:", 8) ? die("%s", vxl_last_error()) : 1;
    vxl_volume_info in = {.struct_size = sizeof in};
    vxl_volume_get_info(v, &in);
    /* NIfTI names its two affines; other formats store one (reported as 2) */
    const char *const src[] = {"none (spacing)", "qform", in.nifti_version ? "sform" : "from header"};
    printf("file:        %s\n", input);
    if (in.nifti_version) printf("format:      NIfTI-%u\n", in.nifti_version);
    else if (series) printf("format:      DICOM (LPS converted to RAS)\n");
    else printf("format:      %s\n", strrchr(input, '.') ? strrchr(input, '.') + 1 : "image stack");
    printf("dimensions:  %u x %u x %u\n", in.dims[0], in.dims[1], in.dims[2]);
    if (in.frame_count > 1) printf("frames:      %u (this is frame %u; --frame N)\n", in.frame_count, in.frame);
    /* what the reader decided rather than read, so no guess goes unseen */
    if (in.notes[0]) printf("notes:       %s\n", in.notes);
    printf("spacing:     %g x %g x %g mm\n", in.spacing[0], in.spacing[1], in.spacing[2]);
    const char *dtype = vxl_dtype_name(in.dtype);
    printf("data type:   %s (stored as %u-bit %s)\n", dtype ? dtype : "?", in.texture_bits,
           in.texture_bits == 32 ? "float" : "normalised");
    vxl_cli_colour_print_info(&in, stdout);
    vxl_cli_channels_print_info(&in, stdout);
    printf("value range: %g .. %g\n", in.value_min, in.value_max);
    printf("nan voxels:  %llu\n", (unsigned long long)in.nan_count);
    printf("inf voxels:  %llu\n", (unsigned long long)in.inf_count);
    printf("affine:      %s (voxel -> world mm)\n", in.affine_source < 3 ? src[in.affine_source] : "?");
    for (int r = 0; r < 4; r++)
        /* %g: microscopy voxels are 0.0002 mm, which a fixed 4 decimals would round */
        printf("  [%10.6g %10.6g %10.6g %10.6g]\n", in.affine[r], in.affine[4 + r], in.affine[8 + r], in.affine[12 + r]);
    vxl_cli_stream_print_info(&in, stdout);
    vxl_volume_destroy(v);
    return 0;
}

typedef struct render_args {
    const char *input, *output;
    vxl_render_params p;
    vxl_renderer_options ro;
    vxl_load_options lo;
    vxl_cli_modes modes;
    vxl_cli_cut cut;     /* cutaways */
    vxl_cli_labels labels; /* label maps */
    vxl_cli_overlays overlays; /* overlays */
    vxl_cli_channels channels; /* multi-channel volumes */
    vxl_cli_stream stream; /* streaming */
    vxl_cli_environment environment; /* the World's light */
} render_args;

static int parse_render(int argc, char **argv, render_args *a)
{
    vxl_render_params *p = &a->p;
    int r;
    char err[512];
    for (int i = 0; i < argc; i++) {
        const char *o = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED_VALUE() do { if (!val) return die("%s needs a value", o); i++; } while (0)
        if (!strcmp(o, "-o") || !strcmp(o, "--output")) { NEED_VALUE(); a->output = val; }
        else if (!strcmp(o, "--size")) {
            NEED_VALUE();
            unsigned w, h; char extra;
            if (sscanf(val, "%ux%u%c", &w, &h, &extra) != 2 || !w || !h || w > 16384 || h > 16384)
                return die("bad --size '%s': use WxH, each 1..16384", val);
            p->width = w; p->height = h;
        } else if (!strcmp(o, "--filter")) {
            NEED_VALUE();
            if (enum_option("filter", val, vxl_filter_name, vxl_filter_from_name, &p->filter)) return 1;
        } else if (!strcmp(o, "--sample-distance")) {
            NEED_VALUE();
            if (!parse_float(val, &p->sample_distance) || p->sample_distance <= 0) return die("bad --sample-distance '%s'", val);
        } else if (!strcmp(o, "--reuse-gradients")) p->reuse_gradients = 1;
        else if (!strcmp(o, "--step")) {
            NEED_VALUE();
            if (!parse_float(val, &p->step) || p->step <= 0) return die("bad --step '%s': a positive number of voxels", val);
        } else if (!strcmp(o, "--azimuth")) { NEED_VALUE(); if (!parse_float(val, &p->azimuth_deg)) return die("bad --azimuth '%s'", val); }
        else if (!strcmp(o, "--elevation")) { NEED_VALUE(); if (!parse_float(val, &p->elevation_deg)) return die("bad --elevation '%s'", val); }
        else if (!strcmp(o, "--preset")) {
            NEED_VALUE();
            if (enum_option("preset", val, vxl_preset_name, vxl_preset_from_name, &p->preset)) return 1;
        } else if (!strcmp(o, "--window")) {
            NEED_VALUE();
            const char *colon = strchr(val, ':');
            char lo[64];
            if (!colon || colon - val >= (long)sizeof lo) return die("bad --window '%s': use LO:HI", val);
            memcpy(lo, val, (size_t)(colon - val));
            lo[colon - val] = '\0';
            if (!parse_float(lo, &p->window_low) || !parse_float(colon + 1, &p->window_high) || p->window_low == p->window_high)
                return die("bad --window '%s': use LO:HI with LO != HI", val);
            p->has_window = 1;
        } else if (!strcmp(o, "--no-shading")) p->shading_off = 1;
        else if (!strcmp(o, "--no-jitter")) p->jitter_off = 1;
        else if (!strcmp(o, "--no-skip")) p->no_skip = 1;
        else if (!strcmp(o, "--gradient-opacity")) {
            NEED_VALUE();
            if (enum_option("--gradient-opacity", val, vxl_gradient_opacity_name, vxl_gradient_opacity_from_name,
                            &p->gradient_opacity))
                return 1;
        } else if (!strcmp(o, "--iso")) {
            NEED_VALUE();
            if (!parse_float(val, &p->iso_value)) return die("bad --iso '%s'", val);
        } else if (!strcmp(o, "--iso-thickness")) {
            NEED_VALUE();
            if (!parse_float(val, &p->iso_thickness) || p->iso_thickness <= 0) return die("bad --iso-thickness '%s'", val);
        } else if (!strcmp(o, "--gradient-ref")) {
            NEED_VALUE();
            if (!parse_float(val, &p->gradient_ref) || p->gradient_ref <= 0) return die("bad --gradient-ref '%s'", val);
        } else if (!strcmp(o, "--classify")) {
            NEED_VALUE();
            if (enum_option("--classify", val, vxl_classify_name, vxl_classify_from_name, &p->classify)) return 1;
        } else if (!strcmp(o, "--renderer")) {
            NEED_VALUE();
            if (enum_option("--renderer", val, vxl_technique_name, vxl_technique_from_name, &p->technique)) return 1;
        }
        else if (!strcmp(o, "--gradient-store")) {
            NEED_VALUE();
            if (enum_option("--gradient-store", val, vxl_gradient_store_name, vxl_gradient_store_from_name,
                            &p->gradient_store))
                return 1;
        } else if (!strcmp(o, "--backend")) {
            NEED_VALUE();
            if (enum_option("backend", val, vxl_backend_name, vxl_backend_from_name, &a->ro.backend)) return 1;
        } else if (!strcmp(o, "--memory-budget")) {
            NEED_VALUE();
            /* the whole budget for now: cmd_render splits it (cli_stream.c) */
            if (!parse_size(val, &a->ro.memory_budget_bytes)) return die("bad --memory-budget '%s': e.g. 2G or 512M", val);
        } else if (!strcmp(o, "--storage")) {
            NEED_VALUE();
            if (enum_option("storage", val, vxl_storage_name, vxl_storage_from_name, &a->ro.storage)) return 1;
        } else if (!strcmp(o, "--page-brick")) {
            NEED_VALUE();
            char *end;
            long b = strtol(val, &end, 10);
            if (*end || (b != 8 && b != 16 && b != 32 && b != 64)) return die("bad --page-brick '%s': 8, 16, 32 or 64", val);
            a->ro.page_brick = (uint32_t)b;
        } else if ((r = parse_input_option(argc, argv, &i, &a->lo)) != 0) {
            if (r < 0) return 1;
        } else if ((r = parse_lighting_option(argc, argv, &i, p)) != 0) {
            if (r < 0) return 1;
        } else if ((r = vxl_cli_modes_option(argc, argv, &i, &a->modes, p, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err);
        } else if ((r = vxl_cli_cut_option(argc, argv, &i, &a->cut, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err);
        } else if ((r = vxl_cli_labels_option(argc, argv, &i, &a->labels, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err);
        } else if ((r = vxl_cli_overlays_option(argc, argv, &i, &a->overlays, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err); /* overlays */
        } else if ((r = vxl_cli_stream_option(argc, argv, &i, &a->stream, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err);
        } else if ((r = vxl_cli_colour_option(argc, argv, &i, p, &a->lo, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err); /* colour volumes */
        } else if ((r = vxl_cli_channels_option(argc, argv, &i, &a->channels, &a->lo, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err); /* multi-channel volumes */
        } else if ((r = vxl_cli_environment_option(argc, argv, &i, &a->environment, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err);
        } else if ((r = vxl_cli_path_option(argc, argv, &i, p, err, sizeof err)) != 0) {
            if (r < 0) return die("%s", err); /* --shading path */
        } else if (o[0] == '-' && o[1]) return die("unknown option '%s' (see voxlight --help)", o);
        else if (!a->input) a->input = o;
        else return die("unexpected argument '%s'", o);
#undef NEED_VALUE
    }
    if (!a->input) return die("render needs an INPUT file (see voxlight --help)");
    if (!a->output) return die("render needs -o OUT.png or OUT.exr");
    return 0;
}

static int cmd_render(int argc, char **argv)
{
    render_args a;
    memset(&a, 0, sizeof a);
    a.p.struct_size = sizeof a.p;
    a.ro.struct_size = sizeof a.ro;
    a.lo.struct_size = sizeof a.lo;
    vxl_cli_modes_init(&a.modes);
    vxl_cli_cut_init(&a.cut);
    vxl_cli_labels_init(&a.labels);
    vxl_cli_overlays_init(&a.overlays);
    vxl_cli_channels_init(&a.channels);
    vxl_cli_stream_init(&a.stream);
    vxl_cli_environment_init(&a.environment);
    if (parse_render(argc, argv, &a)) return 1;
    uint32_t w = a.p.width ? a.p.width : 512, h = a.p.height ? a.p.height : 512;
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    float *rgba = NULL, *depth = NULL;
    int status = 1;
    /* --memory-budget is split between the volume and the renderer */
    vxl_cli_stream_begin(&a.stream, a.input, a.ro.memory_budget_bytes, &a.lo);
    int load_rc = load_input(a.input, &a.lo, &v);
    int cancelled = vxl_cli_stream_end(&a.stream, load_rc);
    if (cancelled) { status = cancelled; goto done; }
    if (load_rc) {
        if (strncmp(a.input, "phantom:", 8)) die("%s", vxl_last_error());
        goto done;
    }
    a.ro.memory_budget_bytes = vxl_cli_stream_renderer_budget(&a.stream, v);
    a.p.progressive = 0; /* a file is written once: wait for every brick at full resolution */
    if (vxl_renderer_create(&a.ro, &r)) { die("%s", vxl_last_error()); goto done; }
    if (vxl_renderer_set_volume(r, v)) { die("%s", vxl_renderer_error(r)); goto done; }
    char merr[512];
    if (vxl_cli_modes_apply(&a.modes, r, v, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    if (vxl_cli_cut_apply(&a.cut, v, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    if (vxl_cli_labels_apply(&a.labels, r, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    if (vxl_cli_overlays_apply(&a.overlays, r, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    if (vxl_cli_environment_apply(&a.environment, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    if (vxl_cli_channels_apply(&a.channels, &a.lo, v, &a.p, merr, sizeof merr)) { die("%s", merr); goto done; }
    vxl_volume_destroy(v);
    v = NULL;
    rgba = malloc((size_t)w * h * 4 * sizeof *rgba);
    depth = malloc((size_t)w * h * sizeof *depth);
    if (!rgba || !depth) { die("out of memory for a %ux%u image", w, h); goto done; }
    const double t0 = vxl_monotonic_s();
    if (vxl_render(r, &a.p, rgba, depth)) { die("%s", vxl_renderer_error(r)); goto done; }
    const double t1 = vxl_monotonic_s();
    vxl_cli_colour_for_output(&a.p, a.output, rgba, (size_t)w * h);
    if (vxl_write_image(a.output, rgba, depth, w, h)) { die("%s", vxl_last_error()); goto done; }
    vxl_renderer_info ri = {.struct_size = sizeof ri};
    vxl_renderer_get_info(r, &ri);
    fprintf(stderr, "voxlight: wrote %s (%ux%u, %s, %s)\n", a.output, w, h, ri.backend_name, ri.gl_renderer);
    vxl_render_stats st = {.struct_size = sizeof st};
    vxl_renderer_get_stats(r, &st);
    double secs = t1 - t0;
    if (st.page_brick)
        fprintf(stderr, "voxlight: storage %s, %.1f MiB resident, %u of %u bricks of %u^3 in the pool, %u constant; frame %.3f s\n",
                vxl_storage_name(st.storage), st.resident_bytes / 1048576.0, st.pages_resident, st.pages_total,
                st.page_brick, st.pages_constant, secs);
    else
        fprintf(stderr, "voxlight: storage %s, %.1f MiB resident; frame %.3f s\n", vxl_storage_name(st.storage),
                st.resident_bytes / 1048576.0, secs);
    if (st.storage == VXL_STORAGE_COMPRESSED)
        fprintf(stderr, "voxlight: compressed bricks decoded into the cache in %.1f ms\n", st.decode_ms);
    vxl_cli_stream_print_stats(&a.stream, &st, stderr);
    if (st.lod_level) /* never silently coarser */
        fprintf(stderr, "voxlight: LOD fallback: level %u (%ux coarser per axis): the visible bricks need %.1f MiB at full "
                "resolution, over the memory budget of %.1f MiB\n", st.lod_level, 1u << st.lod_level,
                st.lod_wanted_bytes / 1048576.0,
                (a.ro.memory_budget_bytes ? a.ro.memory_budget_bytes : 2ull << 30) / 1048576.0);
    status = 0;
done:
    free(rgba);
    free(depth);
    vxl_cli_modes_free(&a.modes);
    vxl_cli_labels_free(&a.labels);
    vxl_cli_environment_free(&a.environment);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    return status;
}

/* `labels FILE`: the lookup table as the library reads it (cli_labels.c). */
static int cmd_labels(int argc, char **argv)
{
    if (argc != 1 || argv[0][0] == '-') return die("labels takes one FILE (see voxlight --help)");
    char err[600];
    return vxl_cli_labels_print(argv[0], stdout, err, sizeof err) ? die("%s", err) : 0;
}

int main(int argc, char **argv)
{
    if (vxl_os_utf8_args(&argc, &argv)) return die("the command line cannot be read as UTF-8");
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        print_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 1 : 0;
    }
    if (vxl_abi_version() != VXL_ABI_VERSION) return die("libvoxlight ABI %u, expected %u", vxl_abi_version(), VXL_ABI_VERSION);
    if (!strcmp(argv[1], "render")) return cmd_render(argc - 2, argv + 2);
    if (!strcmp(argv[1], "info")) return cmd_info(argc - 2, argv + 2);
    if (!strcmp(argv[1], "labels")) return cmd_labels(argc - 2, argv + 2);
    return die("unknown command '%s' (see voxlight --help)", argv[1]);
}
