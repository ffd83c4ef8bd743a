/* shader_source.h - GLSL sources: embedded at build time (tools/embed_files.c)
 * or, for shader development, read from a directory (VOXLIGHT_SHADER_DIR,
 * vxl_renderer_options.shader_dir: the shaders/ folder). Every name, of a
 * program and in `#include "x"` lines alike, is a path under shaders/:
 * "lib/common.glsl" (shared code), "compute/probe.comp", "render/raycast.frag".
 * Includes are expanded, each file at most once per program: where it is
 * first named, so a file two users need is not included inside an #if. */
#ifndef VXL_SHADER_SOURCE_H
#define VXL_SHADER_SOURCE_H

#include "error.h"

typedef struct vxl_embedded_file {
    const char *name;
    const char *text;
} vxl_embedded_file;

extern const vxl_embedded_file vxl_embedded_shaders[];

/* Returns a malloc'd complete source: "#version 450 core", the given defines
 * (a string of "#define ..." lines, may be NULL), then `name` with includes
 * expanded. dir NULL = embedded. */
int vxl_shader_source(const char *dir, const char *name, const char *defines, char **out, vxl_err *e);

#endif
