/* reader_spawn.h - runs one command of a reader helper process
 * (reader_stream.h) and checks every byte it sends. Used by
 * remote_readers.c. */
#ifndef VXL_READER_SPAWN_H
#define VXL_READER_SPAWN_H

#include <stdint.h>

#include "reader_stream.h"
#include "volume.h"

/* A helper and what the user is told about it. */
typedef struct vxl_reader {
    const char *helper;   /* file name next to libvoxlight.so, VXL_HELPER_* */
    const char *env;      /* the variable overriding its path */
    const char *name;     /* "the OpenVDB reader", as messages name it */
    const char *formats;  /* "OpenVDB files": "<formats> need <library>" */
    const char *library;  /* "OpenImageIO" */
    const char *soname;   /* the library's file, "libOpenImageIO.so.2.4" */
    const char *package;  /* its Debian package; "" when the build could not tell */
    int linux_only;       /* its library has no Windows build: Windows refuses the formats */
} vxl_reader;

/* Runs `helper command path options` and collects its reply of kind
 * VXL_REPLY_*. On success *h is the checked header and *body the malloc'd
 * body of h->nbytes (free() it): for a volume, texels that passed the
 * limits in opt (checked before allocating, with a colour volume's colour)
 * and the value checks, and *colour a colour volume's malloc'd RGB8 of
 * h->colour_bytes (NULL for grey; colour may be NULL for a series list),
 * and *channels a multi-channel volume's malloc'd packed channels of
 * h->channel_bytes (charged to the budget with the texels; NULL without
 * channels; channels may be NULL for a series list);
 * for a series list, records whose strings are NUL-terminated. input_bytes (what
 * the helper will read) scales the time limit. The helper is always reaped;
 * a crash, a hang, a missing library or a bad stream is an error. */
int vxl_reader_run(const vxl_reader *r, const char *command, const char *path, const vxl_load_options *opt,
                   uint32_t kind, uint64_t input_bytes, vxl_reader_header *h, void **body, uint8_t **colour,
                   uint16_t **channels, vxl_err *e);

/* 0 where r's library has no build for this OS (Windows and a linux_only
 * reader): vxl_reader_run then refuses its formats by name. */
int vxl_reader_runs_here(const vxl_reader *r);

#endif
