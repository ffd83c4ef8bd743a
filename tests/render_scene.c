/* render_scene.c - one fixed scene rendered with the AUTO backend and its
 * image written raw, so tests/cli/test_windows_render.py can compare the
 * Windows build (under Wine) with the Linux build, pixel by pixel:
 *
 *   render_scene OUT.bin     -> "backend NAME (GL_RENDERER)" on stdout;
 *   OUT.bin: uint32 width, height, then width*height RGBA floats, then
 *   width*height depth floats (little-endian, +inf where no volume).
 *
 * The scene: the Marschner-Lobb phantom (64^3) with the bone preset over
 * [0.35, 0.75], azimuth 20, elevation 25, cubic gradients, no jitter. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scenes.h"
#include "voxlight.h"
#include "voxlight_dev.h"

#define W 96
#define H 96

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: render_scene OUT.bin\n");
        return 2;
    }
    vxl_phantom_desc d;
    memset(&d, 0, sizeof d);
    d.struct_size = sizeof d;
    d.kind = VXL_PHANTOM_MARSCHNER_LOBB;
    vxl_volume *v = NULL;
    vxl_renderer *r = NULL;
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    if (vxl_phantom_create(&d, &v) != VXL_OK || vxl_renderer_create(&o, &r) != VXL_OK ||
        vxl_renderer_set_volume(r, v) != VXL_OK) {
        fprintf(stderr, "render_scene: %s\n", vxl_last_error());
        return 1;
    }
    vxl_renderer_info info;
    memset(&info, 0, sizeof info);
    info.struct_size = sizeof info;
    vxl_renderer_get_info(r, &info);
    vxl_render_params p = phantom_scene(W, H, VXL_FILTER_CUBIC, VXL_CLASSIFY_POST);
    p.jitter_off = 1;
    static float rgba[W * H * 4], depth[W * H];
    if (vxl_render(r, &p, rgba, depth) != VXL_OK) {
        fprintf(stderr, "render_scene: %s\n", vxl_last_error());
        return 1;
    }
    FILE *f = fopen(argv[1], "wb");
    const uint32_t size[2] = {W, H};
    int ok = f && fwrite(size, sizeof size, 1, f) == 1 && fwrite(rgba, sizeof rgba, 1, f) == 1 &&
             fwrite(depth, sizeof depth, 1, f) == 1;
    if (f && fclose(f)) ok = 0;
    printf("backend %s (%s)\n", info.backend_name, info.gl_renderer);
    vxl_renderer_destroy(r);
    vxl_volume_destroy(v);
    return ok ? 0 : 1;
}
