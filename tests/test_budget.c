/* test_budget.c - the renderer's memory budget is one accountant with one
 * formula (csrc/gl/budget.h): a derived volume (precomputed gradients, cubic
 * B-spline coefficients, the pre-classified volume) is charged with the
 * storage and every other derived volume resident beside it, whichever was
 * made first. A dense 32^3 float volume makes the sums exact: the volume,
 * the coefficients and the classified volume take 4 bytes a voxel each;
 * 8-bit gradients take 4 more, and their transient blur 4 while they are
 * made. One byte under the sum refuses, naming the budget; the sum itself
 * renders. */
#include <string.h>

#include "harness.h"
#include "test_util.h"

#define N 32
#define VOXELS ((uint64_t)N * N * N)
#define W 16
#define H 16

static vxl_volume *ball_volume(void)
{
    const double prm[4] = {N / 2.0, N / 2.0, N / 2.0, N / 3.0};
    return make_volume_f32(N, N, N, field_ball, prm);
}

/* A renderer within `budget` bytes holding the ball. */
static vxl_renderer *budgeted(uint64_t budget, vxl_volume *v)
{
    vxl_renderer_options o;
    memset(&o, 0, sizeof o);
    o.struct_size = sizeof o;
    o.backend = software_backend();
    o.memory_budget_bytes = budget;
    vxl_renderer *r = NULL;
    if (vxl_renderer_create(&o, &r) != VXL_OK) return NULL;
    if (vxl_renderer_set_volume(r, v) != VXL_OK) {
        fprintf(stderr, "  set_volume: %s\n", vxl_renderer_error(r));
        vxl_renderer_destroy(r);
        return NULL;
    }
    return r;
}

static int frame(vxl_renderer *r, uint32_t filter, uint32_t classify)
{
    static float img[W * H * 4];
    vxl_render_params p = default_params(W, H);
    p.filter = filter;
    p.classify = classify;
    p.gradient_store = VXL_GRADIENT_STORE_8BIT;
    return vxl_render(r, &p, img, NULL);
}

static int names_budget(vxl_renderer *r) { return strstr(vxl_renderer_error(r), "memory budget") != NULL; }

/* One frame that pre-classifies (the classified volume is made first) and
 * then needs the filter's derived volume: both are charged. */
TEST(a_frame_charges_its_derived_volume_with_the_classified_one)
{
    vxl_volume *v = ball_volume();
    REQUIRE(v);
    const uint64_t volume = 4 * VOXELS, classified = 4 * VOXELS;
    const struct {
        uint32_t filter;
        uint64_t own; /* the derived volume's bytes, transient ones included */
        const char *name;
    } cases[2] = {{VXL_FILTER_CUBIC, 4 * VOXELS, "cubic"}, {VXL_FILTER_PRECOMPUTED, 8 * VOXELS, "precomputed"}};
    for (int i = 0; i < 2; i++) {
        const uint64_t all = volume + classified + cases[i].own;
        vxl_renderer *tight = budgeted(all - 1, v), *enough = budgeted(all, v);
        REQUIRE(tight && enough);
        CHECKF(frame(tight, cases[i].filter, VXL_CLASSIFY_PRE) == VXL_ERR_LIMIT && names_budget(tight), "%s: %s",
               cases[i].name, vxl_renderer_error(tight));
        fprintf(stderr, "    %s: %s\n", cases[i].name, vxl_renderer_error(tight));
        CHECKF(frame(enough, cases[i].filter, VXL_CLASSIFY_PRE) == VXL_OK, "%s: %s", cases[i].name,
               vxl_renderer_error(enough));
        vxl_renderer_destroy(tight);
        vxl_renderer_destroy(enough);
    }
    vxl_volume_destroy(v);
}

/* The other order: the coefficients stay resident after a cubic frame, so a
 * later pre-classification is charged with them. */
TEST(the_classified_volume_is_charged_with_resident_coefficients)
{
    vxl_volume *v = ball_volume();
    REQUIRE(v);
    const uint64_t all = 4 * VOXELS * 3; /* volume, coefficients, classified */
    vxl_renderer *tight = budgeted(all - 1, v), *enough = budgeted(all, v);
    REQUIRE(tight && enough);
    CHECKF(frame(tight, VXL_FILTER_CUBIC, VXL_CLASSIFY_POST) == VXL_OK, "%s", vxl_renderer_error(tight));
    CHECKF(frame(tight, VXL_FILTER_CUBIC, VXL_CLASSIFY_PRE) == VXL_ERR_LIMIT && names_budget(tight), "%s",
           vxl_renderer_error(tight));
    CHECKF(frame(enough, VXL_FILTER_CUBIC, VXL_CLASSIFY_POST) == VXL_OK, "%s", vxl_renderer_error(enough));
    CHECKF(frame(enough, VXL_FILTER_CUBIC, VXL_CLASSIFY_PRE) == VXL_OK, "%s", vxl_renderer_error(enough));
    vxl_renderer_destroy(tight);
    vxl_renderer_destroy(enough);
    vxl_volume_destroy(v);
}

/* The storage is charged alone: exactly the volume's bytes fit. */
TEST(the_volume_alone_fits_its_own_size)
{
    vxl_volume *v = ball_volume();
    REQUIRE(v);
    vxl_renderer *exact = budgeted(4 * VOXELS, v);
    CHECK(exact != NULL);
    if (exact) CHECKF(frame(exact, VXL_FILTER_CENTRAL, VXL_CLASSIFY_POST) == VXL_OK, "%s", vxl_renderer_error(exact));
    vxl_renderer_destroy(exact);
    vxl_volume_destroy(v);
}

int main(void)
{
    RUN(a_frame_charges_its_derived_volume_with_the_classified_one);
    RUN(the_classified_volume_is_charged_with_resident_coefficients);
    RUN(the_volume_alone_fits_its_own_size);
    return TEST_SUMMARY();
}
