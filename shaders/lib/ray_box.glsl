// ray_box.glsl - a ray o + t * d against axis-aligned boxes in voxel space:
// where it enters and leaves the volume's box, and where it leaves a cube
// of skipped bricks. One copy for the ray caster's box and leaps, the
// render modes' brick leaps and the overlays' boxes and leaps, so a change
// to the guard or the rounding reaches them all. (labels.glsl keeps its own
// forms: its boxes are unbounded past the grid's faces.)

// Narrows [t0, t1] to the part inside the box [lo, hi]; false when the ray
// is parallel to a slab and outside it (then [t0, t1] means nothing). The
// reciprocal is guarded: an axis-parallel ray whose origin lies on a slab
// plane would otherwise give 0 * inf = NaN. The caller tests t0 < t1.
bool box_clip(vec3 o, vec3 d, vec3 lo, vec3 hi, inout float t0, inout float t1)
{
    for (int a = 0; a < 3; a++) {
        if (abs(d[a]) < 1e-12) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
        } else {
            float inv = 1.0 / d[a];
            float ta = (lo[a] - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        }
    }
    return true;
}

// Where the ray leaves the cube of bricks within k - 1 of brick b (bricks of
// bs voxels, voxel centres at integers): a Chebyshev distance map's k says
// that cube is empty (k = 1: brick b alone). Axes the ray runs parallel to
// bound nothing.
float brick_cube_exit(ivec3 b, uint k, float bs, vec3 o, vec3 d)
{
    vec3 lo = vec3(b - ivec3(k - 1u)) * bs - 0.5;
    vec3 hi = vec3(b + ivec3(k)) * bs - 0.5;
    vec3 te = vec3(1e30);
    for (int a = 0; a < 3; a++)
        if (abs(d[a]) >= 1e-12) te[a] = ((d[a] > 0.0 ? hi[a] : lo[a]) - o[a]) / d[a];
    return min(te.x, min(te.y, te.z));
}

// The index of the last sample t_start + j * step before t_exit (at least
// i, at most max_steps - 1): the sample loop's i++ then lands on the first
// one at or past t_exit, which is evaluated (minus a hair for rounding).
int last_sample_before(float t_exit, float t_start, float step, int max_steps, int i)
{
    int next = int(min(ceil((t_exit - t_start) / step - 1e-3), float(max_steps)));
    return max(i, next - 1);
}
