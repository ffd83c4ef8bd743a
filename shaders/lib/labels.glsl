// labels.glsl - issue 20 label maps (docs/labels.md; the GL side is
// csrc/labels/labels.c). LABELS is the label mode + 1: 1 SURFACE (label_march
// replaces march), 2 MASK and 3 TINT (label_leap and label_mask in march).
// Ids are never interpolated: ids are fetched with texelFetch and each
// visible id's indicator (1 on its voxels) is filtered with the cubic
// B-spline (4^3 taps; trilinear filtering leaves +-0.4 voxel bumps on a
// labelled sphere); the sample lies in the id with the largest filtered
// indicator when that is >= 0.5: boundaries are its smooth 0.5 level.
// Speed: the label bricks (labels/label_bricks.h) say per brick of label
// voxels how far the nearest visible label may be, and which brick holds
// one visible id alone; rays leap over the rest exactly as the samples
// would have found it, and read no voxel inside a uniform brick.
#ifdef LABELS

uniform usampler3D u_labels;        // R16UI ids, nearest
uniform sampler2D u_label_table;    // 256x256: id -> straight RGBA, alpha -1 = hidden or unlisted
uniform usampler3D u_label_bricks;  // per brick: distance (bits 0-7), UNIFORM (bit 8), its id (16-31): label_bricks.h
uniform mat4 u_label_from_vox;      // intensity voxel -> label voxel
uniform mat3 u_label_grad_to_vox;   // label-voxel gradient -> intensity-voxel gradient (transposed linear part)

const uint LABEL_NONE = 0xffffffffu;
const int LABEL_BRICK = 4;          // label_bricks.h's VXL_LABEL_BRICK
const uint LABEL_UNIFORM = 0x100u;  // label_bricks.h's VXL_LABEL_UNIFORM

vec4 label_entry(uint id)
{
    if (id == LABEL_NONE) return vec4(0.0, 0.0, 0.0, -1.0);
    return texelFetch(u_label_table, ivec2(int(id & 255u), int(id >> 8u)), 0);
}

// The label's own material (ambient, diffuse, specular, shininess), x -1
// for the frame's: the table's second half (labels.c).
vec4 label_material(uint id)
{
    if (id == LABEL_NONE) return vec4(-1.0);
    return texelFetch(u_label_table, ivec2(int(id & 255u), 256 + int(id >> 8u)), 0);
}

// Intensity voxel p in label voxels.
vec3 label_q(vec3 p)
{
    return (u_label_from_vox * vec4(p, 1.0)).xyz;
}

// No label lies outside (-1, dims) (nor at a point that is not a number):
// there the 4^3 taps that are inside weigh < 0.5 together.
bool label_inside(vec3 q)
{
    return all(greaterThan(q, vec3(-1.0))) && all(lessThan(q, vec3(textureSize(u_labels, 0))));
}

// The 8 ids around label point q (LABEL_NONE outside the label volume) and
// the fractional position f in the label voxel cell; q is inside.
void label_corners(vec3 q, out uint ids[8], out vec3 f)
{
    ivec3 dims = textureSize(u_labels, 0);
    vec3 b = floor(q);
    f = q - b;
    ivec3 ib = ivec3(b);
    for (int c = 0; c < 8; c++) {
        ivec3 v = ib + ivec3(c & 1, (c >> 1) & 1, c >> 2);
        ids[c] = LABEL_NONE;
        if (all(greaterThanEqual(v, ivec3(0))) && all(lessThan(v, dims))) ids[c] = texelFetch(u_labels, v, 0).r;
    }
}

// Cubic B-spline weights of the 4 taps at floor - 1 .. floor + 2 (w) and
// their derivatives (d), per axis.
void label_bspline(float f, out vec4 w, out vec4 d)
{
    float g = 1.0 - f, f2 = f * f;
    w = vec4(g * g * g, 3.0 * f2 * f - 6.0 * f2 + 4.0, -3.0 * f2 * f + 3.0 * f2 + 3.0 * f + 1.0, f2 * f) / 6.0;
    d = vec4(-0.5 * g * g, 1.5 * f2 - 2.0 * f, -1.5 * f2 + f + 0.5, 0.5 * f2);
}

// The visible id at a point with the largest filtered indicator (ind), its
// table entry; id LABEL_NONE where that indicator is below 0.5 or no id is
// visible.
struct LabelHit {
    uint id;
    float ind;
    vec4 color;
};

LabelHit label_nothing()
{
    LabelHit h;
    h.id = LABEL_NONE;
    h.ind = 0.0;
    h.color = vec4(0.0);
    return h;
}

// The label at a point where s[c] is the filtered indicator of corner c's id
// over the taps read so far, and r the weight of the taps not read: the id
// with the most, once that is >= 0.5, is the one (no other can reach it; if
// it is hidden, nothing is); when even r could not lift it to 0.5, no id
// reaches 0.5. False while undecided.
bool label_decide(uint ids[8], float s[8], float r, inout LabelHit h)
{
    float top = s[0];
    uint id = ids[0];
    for (int c = 1; c < 8; c++) { // no index chosen at run time: llvmpipe would put the arrays in memory
        id = s[c] > top ? ids[c] : id;
        top = max(top, s[c]);
    }
    if (top + r < 0.5) return true;
    if (top < 0.5) return false;
    vec4 e = label_entry(id);
    if (e.a >= 0.0) {
        h.id = id;
        h.ind = top;
        h.color = e;
    }
    return true;
}

// w[i] without an index chosen at run time.
float label_pick(vec4 w, int i)
{
    return dot(w, vec4(equal(ivec4(i), ivec4(0, 1, 2, 3))));
}

// Adds tap v of weight w to s[c] of every corner c with its id.
void label_tap(ivec3 v, float w, uint ids[8], inout float s[8])
{
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, textureSize(u_labels, 0)))) return;
    uint id = texelFetch(u_labels, v, 0).r;
    for (int c = 0; c < 8; c++) s[c] += id == ids[c] ? w : 0.0;
}

// label_at in a brick where visible labels can be but not one alone. Only
// the ids of the 8 nearest voxels can win (an id none of them has cannot
// reach 0.5: the outer taps weigh < 0.43 in all). The 64 taps of the
// B-spline are read in stages, nearest first (the 8 inner ones, then the 8
// beyond each pair of faces, then the 32 others) until the winner is
// certain (label_decide): most samples stop after the first. ind is a lower
// bound of the winner's filtered indicator.
LabelHit label_at_mixed(vec3 q)
{
    LabelHit h = label_nothing();
    uint ids[8];
    vec3 f;
    label_corners(q, ids, f);
    // One id on all 8: inside it when it is visible (the 8 inner taps weigh
    // >= 0.579), one table fetch.
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
    vec4 wx, wy, wz, dd;
    label_bspline(f.x, wx, dd);
    label_bspline(f.y, wy, dd);
    label_bspline(f.z, wz, dd);
    float s[8], w8[8];
    for (int c = 0; c < 8; c++)
        w8[c] = ((c & 1) != 0 ? wx.z : wx.y) * ((c & 2) != 0 ? wy.z : wy.y) * ((c & 4) != 0 ? wz.z : wz.y);
    for (int c = 0; c < 8; c++) {
        s[c] = 0.0;
        for (int d = 0; d < 8; d++) s[c] += ids[d] == ids[c] ? w8[d] : 0.0;
        if (ids[c] == LABEL_NONE) s[c] = 0.0;
    }
    vec3 inner = vec3(wx[1] + wx[2], wy[1] + wy[2], wz[1] + wz[2]), out3 = 1.0 - inner;
    float r = 1.0 - inner.x * inner.y * inner.z;
    if (label_decide(ids, s, r, h)) return h;
    ivec3 b = ivec3(floor(q)) - 1;
    // the taps beyond the faces across x, then y, then z
    for (int a = 0; a < 3; a++) {
        for (int k = 0; k < 8; k++) {
            int o = (k & 1) * 3, u = 1 + ((k >> 1) & 1), v = 1 + (k >> 2); // outer along a, inner along the others
            ivec3 t = a == 0 ? ivec3(o, u, v) : a == 1 ? ivec3(u, o, v) : ivec3(u, v, o);
            label_tap(b + t, label_pick(wx, t.x) * label_pick(wy, t.y) * label_pick(wz, t.z), ids, s);
        }
        vec3 face = a == 0 ? vec3(out3.x, inner.y, inner.z) : a == 1 ? vec3(inner.x, out3.y, inner.z) : vec3(inner.xy, out3.z);
        r -= face.x * face.y * face.z;
        if (label_decide(ids, s, max(r, 0.0), h)) return h;
    }
    // the 32 taps outer along two or three axes
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                int outer = int(x == 0 || x == 3) + int(y == 0 || y == 3) + int(z == 0 || z == 3);
                if (outer >= 2) label_tap(b + ivec3(x, y, z), label_pick(wx, x) * label_pick(wy, y) * label_pick(wz, z), ids, s);
            }
    label_decide(ids, s, 0.0, h);
    return h;
}

// One ray in label voxels (label point qo + t qd at ray parameter t), the
// part of it inside the label volume, its samples (t_start + i step) and the
// label brick of the last lookup: about LABEL_BRICK / step samples share one.
struct LabelRay {
    vec3 qo, qd;
    float t_in, t_out;  // inside (-1, dims) on (t_in, t_out); none when t_in >= t_out
    float t_start, step;
    ivec3 brick;
    uint word;          // brick's word (label_bricks.h)
    vec4 color;         // a UNIFORM brick's table entry
};

LabelRay label_ray(vec3 o, vec3 dir, float t_start, float step)
{
    LabelRay lr;
    lr.qo = label_q(o);
    lr.qd = mat3(u_label_from_vox) * dir;
    // per axis, not indexed: an index chosen at run time puts vectors in memory (llvmpipe)
    vec3 dims = vec3(textureSize(u_labels, 0));
    bvec3 flat_axis = lessThan(abs(lr.qd), vec3(1e-12));
    vec3 ta = (vec3(-1.0) - lr.qo) / lr.qd, tb = (dims - lr.qo) / lr.qd;
    vec3 t_in = mix(min(ta, tb), vec3(-1e30), flat_axis), t_out = mix(max(ta, tb), vec3(1e30), flat_axis);
    lr.t_in = max(t_in.x, max(t_in.y, t_in.z));
    lr.t_out = min(t_out.x, min(t_out.y, t_out.z));
    vec3 q_flat = mix(vec3(0.0), lr.qo, flat_axis); // parallel to a face and outside it: no part inside
    if (!all(greaterThan(q_flat, vec3(-1.0))) || !all(lessThan(q_flat, dims))) lr.t_in = lr.t_out = 0.0;
    lr.t_start = t_start;
    lr.step = step;
    lr.brick = ivec3(-1);
    lr.word = 0u;
    lr.color = vec4(0.0);
    return lr;
}

// The word of the brick of label point q (inside), read once per brick.
uint label_word(inout LabelRay lr, vec3 q)
{
    ivec3 b = clamp(ivec3(floor(q / float(LABEL_BRICK))), ivec3(0), textureSize(u_label_bricks, 0) - 1);
    if (b != lr.brick) {
        lr.brick = b;
        lr.word = texelFetch(u_label_bricks, b, 0).r;
        if ((lr.word & LABEL_UNIFORM) != 0u) lr.color = label_entry(lr.word >> 16u);
    }
    return lr.word;
}

// The label at label point q (label_at_mixed's meaning): nothing outside the
// label volume or where no visible label can be, a UNIFORM brick's id with
// no voxel read (every tap is that id: the indicator is exactly 1).
LabelHit label_at(inout LabelRay lr, vec3 q)
{
    if (!label_inside(q)) return label_nothing();
    uint w = label_word(lr, q);
    if ((w & 0xffu) != 0u) return label_nothing();
    if ((w & LABEL_UNIFORM) == 0u) return label_at_mixed(q);
    LabelHit h;
    h.id = w >> 16u;
    h.ind = 1.0;
    h.color = lr.color;
    return h;
}

// Where the ray leaves the bricks [lo, hi) (per axis); past the grid's
// faces the box has no bound (no labels lie beyond the edge bricks).
float label_box_exit(LabelRay lr, ivec3 lo, ivec3 hi)
{
    ivec3 n = textureSize(u_label_bricks, 0);
    vec3 hi_face = mix(vec3(hi * LABEL_BRICK), vec3(1e30), greaterThanEqual(hi, n));
    vec3 lo_face = mix(vec3(lo * LABEL_BRICK), vec3(-1e30), lessThanEqual(lo, ivec3(0)));
    vec3 te = (mix(lo_face, hi_face, greaterThan(lr.qd, vec3(0.0))) - lr.qo) / lr.qd;
    te = mix(te, vec3(1e30), lessThan(abs(lr.qd), vec3(1e-12)));
    return min(te.x, min(te.y, te.z));
}

// The next sample to look at when sample i (at t, label point q) and those
// after it up to that one find nothing new: in no visible label (keep
// becomes LABEL_NONE: outside the label volume, or in the cube of empty
// bricks the distance map gives) or, for keep != LABEL_NONE, in a UNIFORM
// brick of label keep. -1 when sample i must be looked at. Sample positions
// stay t_start + i step, so leaping changes no sample that counts.
int label_leap(inout LabelRay lr, int i, float t, vec3 q, inout uint keep)
{
    float t_exit;
    if (!label_inside(q)) {
        // before the label volume: on to where the ray enters it; after it: done
        if (!(lr.t_in < lr.t_out) || t >= 0.5 * (lr.t_in + lr.t_out)) return u_max_steps;
        t_exit = lr.t_in;
        keep = LABEL_NONE;
    } else {
        uint w = label_word(lr, q);
        uint k = w & 0xffu;
        if (k > 0u) {
            t_exit = label_box_exit(lr, lr.brick - ivec3(k - 1u), lr.brick + ivec3(k));
            keep = LABEL_NONE;
        } else if ((w & LABEL_UNIFORM) != 0u && keep != LABEL_NONE && (w >> 16u) == keep) {
            t_exit = label_box_exit(lr, lr.brick, lr.brick + 1);
        } else {
            return -1;
        }
    }
    // the sample at the exit is looked at (minus a hair for rounding)
    int next = int(min(ceil((t_exit - lr.t_start) / lr.step - 1e-3), float(u_max_steps)));
    return max(next, i + 1);
}

#if LABELS == 1
// The indicator of one label on the 4^3 taps of one label cell, as 64 bits
// (bit x + 4 y + 16 z): the bisection and the normal at a crossing read the
// cell's voxels once, not once per step.
struct LabelCell {
    ivec3 base; // the first tap: floor(q) - 1
    uint id;
    uvec2 bits;
};

void label_cell_fill(inout LabelCell c, vec3 q, uint id)
{
    ivec3 base = ivec3(floor(q)) - 1;
    if (base == c.base && id == c.id) return;
    c.base = base;
    c.id = id;
    c.bits = uvec2(0u);
    ivec3 dims = textureSize(u_labels, 0);
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++) {
                ivec3 v = base + ivec3(x, y, z);
                if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, dims))) continue;
                if (texelFetch(u_labels, v, 0).r != id) continue;
                int bit = x + 4 * y + 16 * z;
                if (bit < 32) c.bits.x |= 1u << uint(bit);
                else c.bits.y |= 1u << uint(bit - 32);
            }
}

// The filtered indicator of label id at label point q (inside or not) and its
// gradient in intensity voxels (analytic: the derivative of the B-spline weights).
float label_indicator(inout LabelCell c, vec3 q, uint id, out vec3 grad)
{
    label_cell_fill(c, q, id);
    vec3 f = q - floor(q);
    vec4 wx, wy, wz, dx, dy, dz;
    label_bspline(f.x, wx, dx);
    label_bspline(f.y, wy, dy);
    label_bspline(f.z, wz, dz);
    float s = 0.0;
    vec3 gq = vec3(0.0);
    for (int z = 0; z < 4; z++)
        for (int y = 0; y < 4; y++) {
            int row = y + 4 * z;
            uint nib = ((row < 8 ? c.bits.x : c.bits.y) >> uint(4 * (row & 7))) & 15u;
            vec4 m = vec4(uvec4(nib, nib >> 1u, nib >> 2u, nib >> 3u) & 1u);
            float sx = dot(wx, m), dsx = dot(dx, m);
            float wyy = label_pick(wy, y), wzz = label_pick(wz, z), dyy = label_pick(dy, y), dzz = label_pick(dz, z);
            s += sx * wyy * wzz;
            gq += vec3(dsx * wyy * wzz, sx * dyy * wzz, sx * wyy * dzz);
        }
    grad = u_label_grad_to_vox * gq;
    return s;
}

// SURFACE: the first crossing into each visible label along the ray,
// refined by bisection to the label's 0.5 level, shaded with the label's
// colour (the lights, shading model or MatCap), its alpha as opacity. The
// intensity volume is not read; the label bricks skip empty space and
// the inside of uniform bricks of the label the ray is in.
vec4 label_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    vec4 acc = vec4(0.0);
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
    LabelRay lr = label_ray(o, dir, t0, u_step);
    LabelCell cell;
    cell.base = ivec3(-0x7fffffff);
    cell.id = LABEL_NONE;
    cell.bits = uvec2(0u);
    uint prev = LABEL_NONE;
    float t_prev = t0;
    for (int i = 0; i < u_max_steps; i++) {
        float t = min(t0 + float(i) * u_step, t1);
        vec3 q = label_q(o + t * dir);
        int next = label_leap(lr, i, t, q, prev);
        if (next >= 0) { // samples i .. next - 1 are all prev (or none): nothing crosses
            if (t >= t1) break;
            i = next - 1;
            t_prev = min(t0 + float(i) * u_step, t1);
            continue;
        }
        taken++;
        LabelHit h = label_at(lr, q);
        if (h.id != LABEL_NONE && h.id != prev) {
            float th = t;
            vec3 g;
            if (i > 0) { // the crossing lies in (t_prev, t]: bisect on "in this label" (its indicator >= 0.5)
                float a = t_prev, b = t;
                for (int k = 0; k < 12; k++) {
                    float m = 0.5 * (a + b);
                    vec3 qm = label_q(o + m * dir);
                    if (label_inside(qm) && label_indicator(cell, qm, h.id, g) >= 0.5) b = m;
                    else a = m;
                }
                th = b;
            }
            vec3 p = o + th * dir;
            label_indicator(cell, label_q(p), h.id, g);
            vec3 rgb = h.color.rgb;
#ifdef SHADING
            g_label_material = label_material(h.id);
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
// its colour times the label's too. lr is march's (label_ray).
vec4 label_mask(inout LabelRay lr, vec3 p, vec4 c)
{
    LabelHit h = label_at(lr, label_q(p));
    if (h.id == LABEL_NONE) return vec4(0.0);
    g_label_material = label_material(h.id); // the sample, if shaded next, is lit with its label's material
#if LABELS == 3
    c.rgb *= h.color.rgb;
#endif
    return c;
}
#endif

#endif
