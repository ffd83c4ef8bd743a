// labels.glsl - label maps (docs/labels.md; the GL side is
// csrc/labels/labels.c). LABELS is the label mode + 1: 1 SURFACE (label_march
// replaces march), 2 MASK and 3 TINT (label_leap and label_mask in march).
// Ids are never interpolated: ids are fetched with texelFetch. Smooth
// boundaries (the default): each voxel's margin inside its own label
// (labels/label_margin.h: its label's indicator smoothed with a Gaussian,
// minus 0.5, at least 0.05) makes label L's field +margin on L's voxels and
// -margin on the others'; a sample lies in the label of the 8 nearest
// voxels whose field, interpolated trilinearly, is largest, and L's
// boundary is where its field crosses that of its neighbour (0 between two
// labels). The cubic B-spline of the bare indicator tried before left the
// voxels' stairs on gently sloping faces (its 4 taps span one step).
// LABEL_VOXELS: the label of the nearest voxel, the voxels' faces.
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

#ifndef LABEL_VOXELS
uniform sampler3D u_label_margin;   // R8 per label voxel: margin * 2 (label_margin.h)
#endif

// The visible id at a point (LABEL_NONE where the label there is hidden,
// unlisted or none) and its table entry.
struct LabelHit {
    uint id;
    vec4 color;
};

LabelHit label_nothing()
{
    LabelHit h;
    h.id = LABEL_NONE;
    h.color = vec4(0.0);
    return h;
}

LabelHit label_hit(uint id)
{
    LabelHit h = label_nothing();
    vec4 e = label_entry(id);
    if (e.a >= 0.0) {
        h.id = id;
        h.color = e;
    }
    return h;
}

bool label_voxel_in(ivec3 v)
{
    return all(greaterThanEqual(v, ivec3(0))) && all(lessThan(v, textureSize(u_labels, 0)));
}

#ifdef LABEL_VOXELS
// The id of the voxel nearest to label point q, visible or not.
uint label_nearest(vec3 q)
{
    ivec3 v = ivec3(floor(q + 0.5));
    return label_voxel_in(v) ? texelFetch(u_labels, v, 0).r : LABEL_NONE;
}

LabelHit label_at_mixed(vec3 q)
{
    return label_hit(label_nearest(q));
}
#else
// The 8 voxels around label point q (the cell at floor(q)): their ids and
// margins (outside the label volume: no label, as deep as a margin gets).
struct LabelCell {
    ivec3 base;
    uint ids[8];
    float mu[8];
};

void label_cell_fill(inout LabelCell c, vec3 q)
{
    ivec3 base = ivec3(floor(q));
    if (base == c.base) return;
    c.base = base;
    for (int k = 0; k < 8; k++) {
        ivec3 v = base + ivec3(k & 1, (k >> 1) & 1, k >> 2);
        bool in_vol = label_voxel_in(v);
        c.ids[k] = in_vol ? texelFetch(u_labels, v, 0).r : LABEL_NONE;
        c.mu[k] = in_vol ? 0.5 * texelFetch(u_label_margin, v, 0).r : 0.5;
    }
}

LabelCell label_cell_new()
{
    LabelCell c;
    c.base = ivec3(-0x7fffffff);
    for (int k = 0; k < 8; k++) {
        c.ids[k] = LABEL_NONE;
        c.mu[k] = 0.0;
    }
    return c;
}

// Trilinear weights of the cell's corners at fraction f.
void label_weights(vec3 f, out float w[8])
{
    vec3 g = 1.0 - f;
    for (int k = 0; k < 8; k++)
        w[k] = ((k & 1) != 0 ? f.x : g.x) * ((k & 2) != 0 ? f.y : g.y) * ((k & 4) != 0 ? f.z : g.z);
}

// The field of label id at the cell's point with weights w: +margin on its
// voxels, -margin on the others'.
float label_field_w(LabelCell c, float w[8], uint id)
{
    float s = 0.0;
    for (int k = 0; k < 8; k++) s += w[k] * (c.ids[k] == id ? c.mu[k] : -c.mu[k]);
    return s;
}

// The id (visible or not) of the corner whose label's field is largest,
// given the corners' ids and margins and the point's weights w: the label
// the point lies in. A label's field is 2 S - T, with S the sum of w * margin
// over its own corners and T that over all, so the largest S wins. No
// index chosen at run time (llvmpipe would put the arrays in memory).
uint label_winner_w(uint ids[8], float mu[8], float w[8])
{
    float wm[8];
    for (int k = 0; k < 8; k++) wm[k] = w[k] * mu[k];
    uint id = ids[0];
    float top = -1.0;
    for (int k = 0; k < 8; k++) {
        float s = 0.0;
        for (int d = 0; d < 8; d++) s += ids[d] == ids[k] ? wm[d] : 0.0;
        id = s > top ? ids[k] : id;
        top = max(top, s);
    }
    return id;
}

uint label_winner(inout LabelCell c, vec3 q)
{
    label_cell_fill(c, q);
    float w[8];
    label_weights(q - floor(q), w);
    return label_winner_w(c.ids, c.mu, w);
}

// Label id's field at label point q, read afresh (the normal's taps).
float label_field(vec3 q, uint id)
{
    LabelCell c = label_cell_new();
    label_cell_fill(c, q);
    float w[8];
    label_weights(q - floor(q), w);
    return label_field_w(c, w, id);
}

// label_at in a brick where visible labels can be but not one alone.
LabelHit label_at_mixed(vec3 q)
{
    ivec3 b = ivec3(floor(q));
    uint ids[8];
    bool same = true;
    for (int k = 0; k < 8; k++) {
        ivec3 v = b + ivec3(k & 1, (k >> 1) & 1, k >> 2);
        ids[k] = label_voxel_in(v) ? texelFetch(u_labels, v, 0).r : LABEL_NONE;
        same = same && ids[k] == ids[0];
    }
    if (same) return label_hit(ids[0]); // one id on all 8 corners: in it, the margins unread
    float mu[8], w[8];
    for (int k = 0; k < 8; k++) {
        ivec3 v = b + ivec3(k & 1, (k >> 1) & 1, k >> 2);
        mu[k] = ids[k] != LABEL_NONE ? 0.5 * texelFetch(u_label_margin, v, 0).r : 0.5;
    }
    label_weights(q - vec3(b), w);
    return label_hit(label_winner_w(ids, mu, w));
}
#endif

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
// no voxel read (every corner is that id).
LabelHit label_at(inout LabelRay lr, vec3 q)
{
    if (!label_inside(q)) return label_nothing();
    uint w = label_word(lr, q);
    if ((w & 0xffu) != 0u) return label_nothing();
    if ((w & LABEL_UNIFORM) == 0u) return label_at_mixed(q);
    LabelHit h;
    h.id = w >> 16u;
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
// Whether label point q lies in label id (the crossing's bisection).
#ifdef LABEL_VOXELS
bool label_in(vec3 q, uint id)
{
    return label_inside(q) && label_nearest(q) == id;
}
#else
bool label_in(inout LabelCell c, vec3 q, uint id)
{
    return label_inside(q) && label_winner(c, q) == id;
}

// The gradient of label id's field at label point q, in intensity voxels:
// central differences one label voxel apart, which interpolate the voxels'
// own differences, so the normal turns smoothly from cell to cell.
vec3 label_normal(vec3 q, uint id)
{
    vec3 gq = vec3(label_field(q + vec3(0.5, 0.0, 0.0), id) - label_field(q - vec3(0.5, 0.0, 0.0), id),
                   label_field(q + vec3(0.0, 0.5, 0.0), id) - label_field(q - vec3(0.0, 0.5, 0.0), id),
                   label_field(q + vec3(0.0, 0.0, 0.5), id) - label_field(q - vec3(0.0, 0.0, 0.5), id));
    return u_label_grad_to_vox * gq;
}
#endif

// SURFACE: the first crossing into each visible label along the ray,
// refined by bisection to the label's boundary, shaded with the label's
// colour (the lights, shading model or MatCap), its alpha as opacity. The
// intensity volume is not read; the label bricks skip empty space and
// the inside of uniform bricks of the label the ray is in.
vec4 label_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    vec4 acc = vec4(0.0);
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
    LabelRay lr = label_ray(o, dir, t0, u_step);
#ifndef LABEL_VOXELS
    LabelCell cell = label_cell_new();
#endif
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
            float th = t, ta = t;
            if (i > 0) { // the crossing lies in (t_prev, t]: bisect on "in this label"
                float a = t_prev, b = t;
                for (int k = 0; k < 12; k++) {
                    float m = 0.5 * (a + b);
                    vec3 qm = label_q(o + m * dir);
#ifdef LABEL_VOXELS
                    if (label_in(qm, h.id)) b = m;
#else
                    if (label_in(cell, qm, h.id)) b = m;
#endif
                    else a = m;
                }
                th = b;
                ta = a;
            }
            vec3 p = o + th * dir;
#ifdef LABEL_VOXELS
            // the face crossed: from the voxel before it to the one after
            // (the ray's own direction where it starts inside the label)
            vec3 gq = vec3(ivec3(floor(label_q(p) + 0.5)) - ivec3(floor(label_q(o + ta * dir) + 0.5)));
            if (i == 0 || gq == vec3(0.0)) gq = lr.qd;
            vec3 g = u_label_grad_to_vox * gq;
#else
            vec3 g = label_normal(label_q(p), h.id);
#endif
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
