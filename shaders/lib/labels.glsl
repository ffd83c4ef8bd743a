// labels.glsl - issue 20 label maps (docs/labels.md; the GL side is
// csrc/labels/labels.c). LABELS is the label mode + 1: 1 SURFACE (label_march
// replaces march), 2 MASK and 3 TINT (label_mask on march's samples).
// Ids are never interpolated: ids are fetched with texelFetch and each
// visible id's indicator (1 on its voxels) is filtered with the cubic
// B-spline (4^3 taps; trilinear filtering leaves +-0.4 voxel bumps on a
// labelled sphere); the sample lies in the id with the largest filtered
// indicator when that is >= 0.5: boundaries are its smooth 0.5 level.
#ifdef LABELS

uniform usampler3D u_labels;        // R16UI ids, nearest
uniform sampler2D u_label_table;    // 256x256: id -> straight RGBA, alpha -1 = hidden or unlisted
uniform mat4 u_label_from_vox;      // intensity voxel -> label voxel
uniform mat3 u_label_grad_to_vox;   // label-voxel gradient -> intensity-voxel gradient (transposed linear part)

const uint LABEL_NONE = 0xffffffffu;

vec4 label_entry(uint id)
{
    if (id == LABEL_NONE) return vec4(0.0, 0.0, 0.0, -1.0);
    return texelFetch(u_label_table, ivec2(int(id & 255u), int(id >> 8u)), 0);
}

// The 8 ids around intensity-voxel point p (LABEL_NONE outside the label
// volume) and the fractional position f in the label voxel cell.
bool label_corners(vec3 p, out uint ids[8], out vec3 f)
{
    vec3 q = (u_label_from_vox * vec4(p, 1.0)).xyz;
    ivec3 dims = textureSize(u_labels, 0);
    f = vec3(0.0);
    for (int c = 0; c < 8; c++) ids[c] = LABEL_NONE;
    // outside by more than a voxel, or not a number (odd cameras): no label
    if (!all(greaterThan(q, vec3(-1.0))) || !all(lessThan(q, vec3(dims)))) return false;
    vec3 b = floor(q);
    f = q - b;
    ivec3 ib = ivec3(b);
    for (int c = 0; c < 8; c++) {
        ivec3 v = ib + ivec3(c & 1, (c >> 1) & 1, c >> 2);
        if (all(greaterThanEqual(v, ivec3(0))) && all(lessThan(v, dims))) ids[c] = texelFetch(u_labels, v, 0).r;
    }
    return true;
}

// Cubic B-spline weights of the 4 taps at floor - 1 .. floor + 2 (w) and
// their derivatives (d), per axis.
void label_bspline(float f, out vec4 w, out vec4 d)
{
    float g = 1.0 - f, f2 = f * f;
    w = vec4(g * g * g, 3.0 * f2 * f - 6.0 * f2 + 4.0, -3.0 * f2 * f + 3.0 * f2 + 3.0 * f + 1.0, f2 * f) / 6.0;
    d = vec4(-0.5 * g * g, 1.5 * f2 - 2.0 * f, -1.5 * f2 + f + 0.5, 0.5 * f2);
}

// The visible id at p with the largest filtered indicator (ind), its table
// entry; id LABEL_NONE where that indicator is below 0.5 or no id is visible.
// Candidates are the distinct visible ids of the 8 nearest voxels: an id
// none of them has cannot reach 0.5 (the outer taps weigh < 0.43 in all).
struct LabelHit {
    uint id;
    float ind;
    vec4 color;
};

LabelHit label_at(vec3 p)
{
    LabelHit h;
    h.id = LABEL_NONE;
    h.ind = 0.0;
    h.color = vec4(0.0);
    uint ids[8];
    vec3 f;
    if (!label_corners(p, ids, f)) return h;
    // One id on all 8 (most samples): inside it when it is visible (the 8
    // inner taps weigh >= 0.579), no 64-tap filter and one table fetch.
    bool same = true;
    for (int c = 1; c < 8; c++) same = same && ids[c] == ids[0];
    if (same) {
        vec4 e = label_entry(ids[0]);
        if (e.a >= 0.0) {
            h.id = ids[0];
            h.ind = 1.0;
            h.color = e;
        }
        return h;
    }
    uint cand[8];
    float sum[8];
    int n = 0;
    for (int c = 0; c < 8; c++) {
        if (ids[c] == LABEL_NONE || label_entry(ids[c]).a < 0.0) continue;
        bool dup = false;
        for (int k = 0; k < n; k++) dup = dup || cand[k] == ids[c];
        if (dup) continue;
        cand[n] = ids[c];
        sum[n++] = 0.0;
    }
    if (n == 0) return h;
    vec4 wx, wy, wz, dd;
    label_bspline(f.x, wx, dd);
    label_bspline(f.y, wy, dd);
    label_bspline(f.z, wz, dd);
    ivec3 b = ivec3(floor((u_label_from_vox * vec4(p, 1.0)).xyz)) - 1, dims = textureSize(u_labels, 0);
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                ivec3 v = b + ivec3(x, y, z);
                if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, dims))) continue;
                uint id = texelFetch(u_labels, v, 0).r;
                float w = wx[x] * wy[y] * wz[z];
                for (int k = 0; k < n; k++) sum[k] += cand[k] == id ? w : 0.0;
            }
    for (int k = 0; k < n; k++)
        if (sum[k] > h.ind) {
            h.id = cand[k];
            h.ind = sum[k];
        }
    h.color = label_entry(h.id);
    if (h.ind < 0.5) h.id = LABEL_NONE;
    return h;
}

#if LABELS == 1
// The filtered indicator of label id at p and its gradient in intensity
// voxels (analytic: the derivative of the B-spline weights).
float label_indicator(vec3 p, uint id, out vec3 grad)
{
    grad = vec3(0.0);
    vec3 q = (u_label_from_vox * vec4(p, 1.0)).xyz;
    ivec3 dims = textureSize(u_labels, 0);
    if (!all(greaterThan(q, vec3(-1.0))) || !all(lessThan(q, vec3(dims)))) return 0.0;
    vec3 fl = floor(q), f = q - fl;
    vec4 wx, wy, wz, dx, dy, dz;
    label_bspline(f.x, wx, dx);
    label_bspline(f.y, wy, dy);
    label_bspline(f.z, wz, dz);
    ivec3 b = ivec3(fl) - 1;
    float s = 0.0;
    vec3 gq = vec3(0.0);
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                ivec3 v = b + ivec3(x, y, z);
                if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, dims))) continue;
                if (texelFetch(u_labels, v, 0).r != id) continue;
                s += wx[x] * wy[y] * wz[z];
                gq += vec3(dx[x] * wy[y] * wz[z], wx[x] * dy[y] * wz[z], wx[x] * wy[y] * dz[z]);
            }
    grad = u_label_grad_to_vox * gq;
    return s;
}

// SURFACE: the first crossing into each visible label along the ray,
// refined by bisection to the label's 0.5 level, shaded with the label's
// colour (the lights, shading model or MatCap), its alpha as opacity. The
// intensity volume is not read; empty-space skipping is off (frame_labels.c).
vec4 label_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    vec4 acc = vec4(0.0);
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
    uint prev = LABEL_NONE;
    float t_prev = t0;
    for (int i = 0; i < u_max_steps; i++) {
        float t = min(t0 + float(i) * u_step, t1);
        taken++;
        LabelHit h = label_at(o + t * dir);
        if (h.id != LABEL_NONE && h.id != prev) {
            float th = t;
            if (i > 0) { // the crossing lies in (t_prev, t]: bisect on "in this label"
                float a = t_prev, b = t;
                for (int k = 0; k < 12; k++) {
                    float m = 0.5 * (a + b);
                    if (label_at(o + m * dir).id == h.id) b = m;
                    else a = m;
                }
                th = b;
            }
            vec3 p = o + th * dir;
            vec3 g;
            label_indicator(p, h.id, g);
            vec3 rgb = h.color.rgb;
#ifdef SHADING
            rgb = shade_at(rgb, g, th, p, r);
#endif
            acc += (1.0 - acc.a) * h.color.a * vec4(rgb, 1.0);
            if (isinf(depth) && acc.a >= u_depth_threshold) depth = -(r.z0 + r.dz * th);
            if (acc.a >= u_early_termination) break;
        }
        prev = h.id;
        t_prev = t;
        if (t >= t1) break;
    }
    return acc;
}
#else
// MASK: the transfer function's sample c only inside visible labels; TINT:
// its colour times the label's too.
vec4 label_mask(vec3 p, vec4 c)
{
    LabelHit h = label_at(p);
    if (h.id == LABEL_NONE) return vec4(0.0);
#if LABELS == 3
    c.rgb *= h.color.rgb;
#endif
    return c;
}
#endif

#endif
