/* dicom_j2k.c - dicom_j2k.h: JPEG 2000 frames through the system's
 * OpenJPEG, opened once per process like zlib (zlib_api.c).
 *
 * The function table is process-wide and written exactly once
 * (vxl_once_run), then only read; everything else (the stream over the
 * frame, the codec, the message captured from OpenJPEG) lives on the
 * caller's stack for one decode, so frames decode on any number of threads.
 * The types come from openjpeg.h (__typeof__), so a signature slip is a
 * compile error, yet nothing of OpenJPEG is linked. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <openjpeg.h>

#include "dicom_j2k.h"
#include "dynlib.h"
#include "os.h"
#include "threads.h"

typedef struct vxl_openjpeg {
    __typeof__(&opj_version) version;
    __typeof__(&opj_create_decompress) create_decompress;
    __typeof__(&opj_destroy_codec) destroy_codec;
    __typeof__(&opj_set_default_decoder_parameters) set_default_decoder_parameters;
    __typeof__(&opj_setup_decoder) setup_decoder;
    /* 2.5 and later: a codestream cut short is an error, not a frame
     * decoded in part with a warning */
    __typeof__(&opj_decoder_set_strict_mode) decoder_set_strict_mode;
    __typeof__(&opj_set_info_handler) set_info_handler;
    __typeof__(&opj_set_warning_handler) set_warning_handler;
    __typeof__(&opj_set_error_handler) set_error_handler;
    __typeof__(&opj_stream_create) stream_create;
    __typeof__(&opj_stream_destroy) stream_destroy;
    __typeof__(&opj_stream_set_read_function) stream_set_read_function;
    __typeof__(&opj_stream_set_skip_function) stream_set_skip_function;
    __typeof__(&opj_stream_set_seek_function) stream_set_seek_function;
    __typeof__(&opj_stream_set_user_data) stream_set_user_data;
    __typeof__(&opj_stream_set_user_data_length) stream_set_user_data_length;
    __typeof__(&opj_read_header) read_header;
    __typeof__(&opj_decode) decode;
    __typeof__(&opj_end_decompress) end_decompress;
    __typeof__(&opj_image_destroy) image_destroy;
} vxl_openjpeg;

/* In the order of vxl_openjpeg's members. */
static const char *const names[] = {
    "opj_version", "opj_create_decompress", "opj_destroy_codec", "opj_set_default_decoder_parameters",
    "opj_setup_decoder", "opj_decoder_set_strict_mode", "opj_set_info_handler", "opj_set_warning_handler",
    "opj_set_error_handler", "opj_stream_create", "opj_stream_destroy", "opj_stream_set_read_function",
    "opj_stream_set_skip_function", "opj_stream_set_seek_function", "opj_stream_set_user_data",
    "opj_stream_set_user_data_length", "opj_read_header", "opj_decode", "opj_end_decompress", "opj_image_destroy"};

static struct {
    vxl_openjpeg api;
    int ok;
    char why[256];
} state;
static vxl_once once = VXL_ONCE_INIT;

static void load(void)
{
    _Static_assert(sizeof(vxl_openjpeg) == sizeof names / sizeof names[0] * sizeof(vxl_dynlib_fn),
                   "one pointer per name");
    /* VOXLIGHT_LIBOPENJP2 names another file (tests: a missing library) */
    vxl_dynlib *lib = vxl_dynlib_open_table("VOXLIGHT_LIBOPENJP2", vxl_os_openjpeg_name(), names,
                                            sizeof names / sizeof names[0], (vxl_dynlib_fn *)&state.api, state.why,
                                            sizeof state.why);
    if (!lib) return;
    /* the structures the table's types describe are those of major 2 */
    if (state.api.version()[0] != '0' + OPJ_VERSION_MAJOR) {
        snprintf(state.why, sizeof state.why, "it is OpenJPEG %s, not %d.x", state.api.version(), OPJ_VERSION_MAJOR);
        vxl_dynlib_close(lib);
        return;
    }
    state.ok = 1; /* the handle stays open for the process: the table points into it */
}

static const vxl_openjpeg *openjpeg(vxl_err *e)
{
    vxl_once_run(&once, load);
    if (state.ok) return &state.api;
    vxl_fail(e, VXL_ERR_IO, "JPEG 2000 needs OpenJPEG: %s %s (%s)", vxl_os_has_debian_libraries() ? "install" : "put",
             vxl_os_has_debian_libraries() ? "libopenjp2-7" : "openjp2.dll beside voxlight.dll", state.why);
    return NULL;
}

/* ---- the frame as an OpenJPEG input stream */

typedef struct frame_in {
    const uint8_t *p;
    size_t n, at;
} frame_in;

static OPJ_SIZE_T frame_read(void *buf, OPJ_SIZE_T len, void *user)
{
    frame_in *f = user;
    if (f->at >= f->n) return (OPJ_SIZE_T)-1; /* OpenJPEG's "end of stream" */
    const size_t k = len < f->n - f->at ? len : f->n - f->at;
    memcpy(buf, f->p + f->at, k);
    f->at += k;
    return k;
}

/* Forward only: a decoder moves back by seeking. OpenJPEG repeats a skip
 * until all of it is done, so one that cannot move says -1 (the end), never 0. */
static OPJ_OFF_T frame_skip(OPJ_OFF_T k, void *user)
{
    frame_in *f = user;
    if (k == 0) return 0;
    if (k < 0 || f->at >= f->n) return -1;
    const size_t step = (uint64_t)k < f->n - f->at ? (size_t)k : f->n - f->at;
    f->at += step;
    return (OPJ_OFF_T)step;
}

static OPJ_BOOL frame_seek(OPJ_OFF_T to, void *user)
{
    frame_in *f = user;
    if (to < 0 || (uint64_t)to > f->n) return OPJ_FALSE;
    f->at = (size_t)to;
    return OPJ_TRUE;
}

/* ---- OpenJPEG's messages: never printed (a library does not print); the
 * first error, the cause rather than its consequences, becomes the reason */

typedef struct reason {
    char text[200];
} reason;

static void ignore_message(const char *msg, void *user)
{
    (void)msg;
    (void)user;
}

static void keep_error(const char *msg, void *user)
{
    reason *r = user;
    if (r->text[0] || !msg) return;
    snprintf(r->text, sizeof r->text, "%s", msg);
    size_t k = strlen(r->text);
    while (k && (r->text[k - 1] == '\n' || r->text[k - 1] == '\r' || r->text[k - 1] == ' ')) r->text[--k] = 0;
    for (char *c = r->text; *c; c++)
        if (*c == '\n') *c = ' '; /* one line */
}

/* ---- checks of the image against the frame DICOM declares */

/* NULL when the components are those of the frame; else why not. `decoded`:
 * the components hold their pixels (after opj_decode), not just a header. */
static const char *shape_mismatch(const opj_image_t *im, uint32_t rows, uint32_t cols, uint32_t bytes,
                                  uint32_t samples, int decoded, char *why, size_t size)
{
    if (im->x1 < im->x0 || im->y1 < im->y0 || im->x1 - im->x0 != cols || im->y1 - im->y0 != rows) {
        snprintf(why, size, "the frame is %ux%u, the codestream says %ux%u", cols, rows,
                 im->x1 >= im->x0 ? im->x1 - im->x0 : 0, im->y1 >= im->y0 ? im->y1 - im->y0 : 0);
        return why;
    }
    if (im->numcomps != samples || !im->comps) {
        snprintf(why, size, "%u samples per pixel, the codestream has %u components", samples, im->numcomps);
        return why;
    }
    for (uint32_t c = 0; c < samples; c++) {
        const opj_image_comp_t *k = &im->comps[c];
        if (k->dx != 1 || k->dy != 1) {
            snprintf(why, size, "component %u is subsampled (%ux%u), which DICOM frames are not", c, k->dx, k->dy);
            return why;
        }
        if (k->prec < 1 || k->prec > 8 * bytes) {
            snprintf(why, size, "component %u has %u bits, more than %u-byte samples hold", c, k->prec, bytes);
            return why;
        }
        if (decoded && (!k->data || k->w != cols || k->h != rows)) {
            snprintf(why, size, "component %u decoded to %ux%u, not %ux%u", c, k->w, k->h, cols, rows);
            return why;
        }
    }
    return NULL;
}

/* Component c of im into dst's interleaved samples, clamped to its bit
 * depth (lossy decoding rounds; garbage must not wrap). */
static void put_component(const opj_image_comp_t *k, size_t count, uint32_t c, uint32_t samples, uint32_t bytes,
                          void *dst)
{
    const int32_t lo = k->sgnd ? -(int32_t)(1u << (k->prec - 1)) : 0;
    const int32_t hi = k->sgnd ? (int32_t)((1u << (k->prec - 1)) - 1) : (int32_t)((1u << k->prec) - 1);
    for (size_t i = 0; i < count; i++) {
        int32_t v = k->data[i];
        v = v < lo ? lo : v > hi ? hi : v;
        /* a signed value's two's complement in the container is its sign extension */
        if (bytes == 1)
            ((uint8_t *)dst)[i * samples + c] = (uint8_t)(v & 0xFF);
        else
            ((uint16_t *)dst)[i * samples + c] = (uint16_t)(v & 0xFFFF);
    }
}

int vxl_j2k_decode(const uint8_t *data, size_t n, uint32_t rows, uint32_t cols, uint32_t bytes_per_sample,
                   uint32_t samples, void *dst, vxl_err *e)
{
    if (bytes_per_sample != 1 && bytes_per_sample != 2)
        return vxl_fail(e, VXL_ERR_FORMAT, "JPEG 2000 frame: %u-byte samples are not supported", bytes_per_sample);
    if (!rows || !cols || !samples || samples > 4)
        return vxl_fail(e, VXL_ERR_FORMAT, "JPEG 2000 frame: %ux%u pixels of %u samples is no frame", cols, rows,
                        samples);
    static const uint8_t j2k_magic[4] = {0xFF, 0x4F, 0xFF, 0x51}; /* SOC, then SIZ */
    static const uint8_t jp2_magic[12] = {0, 0, 0, 0x0C, 'j', 'P', ' ', ' ', 0x0D, 0x0A, 0x87, 0x0A};
    OPJ_CODEC_FORMAT format;
    if (n >= sizeof j2k_magic && !memcmp(data, j2k_magic, sizeof j2k_magic))
        format = OPJ_CODEC_J2K;
    else if (n >= sizeof jp2_magic && !memcmp(data, jp2_magic, sizeof jp2_magic))
        format = OPJ_CODEC_JP2;
    else
        return vxl_fail(e, VXL_ERR_FORMAT, "JPEG 2000 frame: neither a J2K codestream nor a JP2 file (%zu bytes)", n);
    const vxl_openjpeg *o = openjpeg(e);
    if (!o) return VXL_ERR_IO;

    frame_in in = {data, n, 0};
    reason r = {{0}};
    char why[160];
    const char *bad = NULL;
    int rc = VXL_ERR_FORMAT;
    opj_image_t *im = NULL;
    opj_codec_t *codec = o->create_decompress(format);
    opj_stream_t *s = o->stream_create(n < 65536 ? n : 65536, OPJ_TRUE);
    if (!codec || !s) {
        rc = vxl_fail(e, VXL_ERR_NO_MEMORY, "JPEG 2000 frame: OpenJPEG could not start a decoder");
        goto done;
    }
    o->stream_set_user_data(s, &in, NULL);
    o->stream_set_user_data_length(s, n);
    o->stream_set_read_function(s, frame_read);
    o->stream_set_skip_function(s, frame_skip);
    o->stream_set_seek_function(s, frame_seek);
    o->set_info_handler(codec, ignore_message, NULL);
    o->set_warning_handler(codec, ignore_message, NULL);
    o->set_error_handler(codec, keep_error, &r);
    opj_dparameters_t p;
    o->set_default_decoder_parameters(&p);
    if (!o->setup_decoder(codec, &p) || !o->decoder_set_strict_mode(codec, OPJ_TRUE)) {
        bad = "OpenJPEG refused its parameters";
    } else if (!o->read_header(s, codec, &im) || !im) {
        bad = "its header cannot be read";
    } else if ((bad = shape_mismatch(im, rows, cols, bytes_per_sample, samples, 0, why, sizeof why)) != NULL) {
        /* refused before any tile is decoded: memory stays the frame's */
    } else if (!o->decode(codec, s, im) || !o->end_decompress(codec, s)) {
        bad = "it does not decode";
    } else if ((bad = shape_mismatch(im, rows, cols, bytes_per_sample, samples, 1, why, sizeof why)) != NULL) {
        /* a JP2 palette or channel definition changed the components */
    } else {
        for (uint32_t c = 0; c < samples; c++)
            put_component(&im->comps[c], (size_t)rows * cols, c, samples, bytes_per_sample, dst);
        rc = VXL_OK;
    }
    if (bad)
        rc = vxl_fail(e, VXL_ERR_FORMAT, "JPEG 2000 frame: %s%s%s", bad, r.text[0] ? ": " : "", r.text);
done:
    if (im) o->image_destroy(im);
    if (s) o->stream_destroy(s);
    if (codec) o->destroy_codec(codec);
    return rc;
}
