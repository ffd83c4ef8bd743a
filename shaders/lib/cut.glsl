// cut.glsl - cutaways (voxlight.h's vxl_cutaway) in the ray
// caster, and the layer format the cutter peel writes (render/cut_peel.frag).
//
// CUT_CONVEX: clip planes (half-spaces or slabs) and the crop box narrow
// the ray's [t0, t1] in main() (cut_begin): the ray only spans the kept
// part, so skipping, bricks and early termination work as before and a
// clipped-away brick is never visited.
// CUT_CUTTERS: csrc/cut/cutaway.c rasterised the cutter meshes from the
// camera into up to CUT_LAYERS crossings per pixel; cut_begin sorts them
// into the ray's kept intervals (at most CUT_MAX_INTERVALS) and the march
// leaps over the removed ones (cut_leap). A pixel with more crossings than
// CUT_LAYERS has lost some: its ray is dropped (drawn empty), never drawn
// with a cut in the wrong place.
// Caps: the first sample of a kept interval that starts at a cut surface is
// shaded with that surface's normal (cut_cap) instead of the data gradient.
// Without CUT_CONVEX and CUT_CUTTERS only the macros below (empty) and the
// unused packing helpers are compiled: a frame without cutaways is today's.

#define CUT_LAYERS 8 // = VXL_CUT_LAYERS in csrc/cut/cutaway.h

// A crossing's second word: the surface's unit normal (gradient space,
// octahedral, 15 bits a component) and its cutter (2 bits).
vec2 cut_oct_wrap(vec2 v) { return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

uint cut_pack(vec3 n, uint cutter)
{
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 e = n.z >= 0.0 ? n.xy : cut_oct_wrap(n.xy);
    uvec2 q = uvec2(clamp(round((e * 0.5 + 0.5) * 32767.0), 0.0, 32767.0));
    return q.x | (q.y << 15) | (cutter << 30);
}

vec3 cut_unpack_normal(uint w)
{
    vec2 e = vec2(float(w & 32767u), float((w >> 15) & 32767u)) / 32767.0 * 2.0 - 1.0;
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = cut_oct_wrap(n.xy);
    return normalize(n);
}

#if defined(CUT_CUTTERS) || defined(CUT_PEEL)
// Per pixel (y * u_cut_width + x): its crossing count in word pix, then
// from word u_cut_pixels its CUT_LAYERS crossings of two words: the planar
// view-space depth (float bits) and cut_pack's word.
layout(std430, binding = VXL_SSBO_CUT_LAYERS) buffer CutLayers { uint cut_words[]; };
uniform int u_cut_width;
uniform int u_cut_pixels;
#endif

#if defined(CUT_CONVEX) || defined(CUT_CUTTERS)
#define CUT_ANY 1
uniform int u_cut_caps; // 0: caps off

#ifdef CUT_CUTTERS
#define CUT_MAX_INTERVALS (CUT_LAYERS / 2 + 1)
uniform uint u_cut_outside; // bit c: cutter c removes its outside (keeps only its inside)
#else
#define CUT_MAX_INTERVALS 1
#endif

// The ray's kept intervals [cut_lo[k], cut_hi[k]), front to back, each with
// the gradient-space normal of the cut surface it starts at (zero: it starts
// at the box or the eye, no cap); cut_cur is the one the march is in.
float cut_lo[CUT_MAX_INTERVALS], cut_hi[CUT_MAX_INTERVALS];
vec3 cut_cap_n[CUT_MAX_INTERVALS];
int cut_count, cut_cur;

#ifdef CUT_CONVEX
uniform int u_cut_plane_count;
uniform vec4 u_cut_planes[6];     // voxel space: dot(xyz, p) + w = signed world distance, kept >= 0
uniform float u_cut_thickness[6]; // > 0: kept only up to it (a slab)
uniform int u_cut_has_crop;
uniform mat4 u_cut_crop;          // voxel -> box space, kept inside [-1, 1]^3

// Keeps lo <= a + b t (<= hi for a slab) on [t0, t1]; n becomes the cap's
// normal when the entry moves. As frame_cut.c's keep_between (the reference).
bool cut_keep_between(float a, float b, float lo, float hi, bool slab, vec3 n, inout float t0, inout float t1,
                      inout vec3 cap)
{
    if (abs(b) < 1e-30) return a >= lo && (!slab || a <= hi);
    float ta = (lo - a) / b, tb = slab ? (hi - a) / b : (b > 0.0 ? 1e30 : -1e30);
    float enter = min(ta, tb), leave = max(ta, tb);
    if (enter > t0) {
        t0 = enter;
        cap = n;
    }
    t1 = min(t1, leave);
    return t0 < t1;
}

bool cut_convex(vec3 o, vec3 dir, inout float t0, inout float t1, inout vec3 cap)
{
    for (int i = 0; i < u_cut_plane_count; i++) {
        vec4 q = u_cut_planes[i];
        float th = u_cut_thickness[i];
        if (!cut_keep_between(dot(q.xyz, o) + q.w, dot(q.xyz, dir), 0.0, th, th > 0.0, q.xyz, t0, t1, cap))
            return false;
    }
    if (u_cut_has_crop != 0) {
        vec3 a = (u_cut_crop * vec4(o, 1.0)).xyz, b = mat3(u_cut_crop) * dir;
        for (int r = 0; r < 3; r++) {
            vec3 n = vec3(u_cut_crop[0][r], u_cut_crop[1][r], u_cut_crop[2][r]); // d(box r) / d(voxel)
            if (!cut_keep_between(a[r], b[r], -1.0, 1.0, true, n, t0, t1, cap)) return false;
        }
    }
    return true;
}
#endif

#ifdef CUT_CUTTERS
// Whether the cutters keep a point whose winding count inside cutter c is cnt[c].
bool cut_kept(int cnt[4])
{
    for (int c = 0; c < 4; c++) {
        bool inside = cnt[c] > 0, outside_removed = ((u_cut_outside >> uint(c)) & 1u) != 0u;
        if (inside != outside_removed) return false;
    }
    return true;
}

// Appends the part of [lo, hi) inside [t0, t1]; a start cut to t0 takes the
// convex cut's cap there.
void cut_add(float lo, float hi, vec3 n, float t0, float t1, vec3 cap0)
{
    if (lo < t0) {
        lo = t0;
        n = cap0;
    }
    hi = min(hi, t1);
    if (lo < hi && cut_count < CUT_MAX_INTERVALS) {
        cut_lo[cut_count] = lo;
        cut_hi[cut_count] = hi;
        cut_cap_n[cut_count] = n;
        cut_count++;
    }
}
#endif

// The kept intervals of this pixel's ray o + t dir inside [t0, t1] (the
// volume box, the eye, the scene depth), which become their hull; z0 + t dz
// is the planar view depth. False when nothing is kept.
bool cut_begin(vec3 o, vec3 dir, float z0, float dz, inout float t0, inout float t1)
{
    vec3 cap0 = vec3(0.0);
    cut_count = 0;
    cut_cur = 0;
#ifdef CUT_CONVEX
    if (!cut_convex(o, dir, t0, t1, cap0)) return false;
#endif
#ifdef CUT_CUTTERS
    int pix = int(gl_FragCoord.y) * u_cut_width + int(gl_FragCoord.x);
    uint n = cut_words[pix];
    if (n > uint(CUT_LAYERS) || !(dz < 0.0)) return false; // over-full: crossings were lost; fail safe
    float ts[CUT_LAYERS];
    uint ws[CUT_LAYERS];
    int m = int(n);
    for (int k = 0; k < m; k++) { // insertion sort, front to back
        int at = u_cut_pixels + 2 * (pix * CUT_LAYERS + k);
        float t = (-uintBitsToFloat(cut_words[at]) - z0) / dz;
        uint w = cut_words[at + 1];
        int j = k;
        for (; j > 0 && ts[j - 1] > t; j--) {
            ts[j] = ts[j - 1];
            ws[j] = ws[j - 1];
        }
        ts[j] = t;
        ws[j] = w;
    }
    // Winding count per cutter: +1 where the ray enters (the outward normal
    // against it), -1 where it leaves. A surface the near plane clipped
    // away leaves the ray starting inside: the count starts at the deepest
    // the running sum goes below zero.
    int cnt[4] = int[4](0, 0, 0, 0), low[4] = int[4](0, 0, 0, 0);
    for (int k = 0; k < m; k++) {
        int c = int(ws[k] >> 30);
        cnt[c] += dot(cut_unpack_normal(ws[k]), dir) < 0.0 ? 1 : -1;
        low[c] = min(low[c], cnt[c]);
    }
    for (int c = 0; c < 4; c++) cnt[c] = -low[c];
    bool kept = cut_kept(cnt);
    float lo = -1e30;
    vec3 lo_n = vec3(0.0);
    for (int k = 0; k < m; k++) {
        int c = int(ws[k] >> 30);
        vec3 nk = cut_unpack_normal(ws[k]);
        cnt[c] += dot(nk, dir) < 0.0 ? 1 : -1;
        bool now = cut_kept(cnt);
        if (now == kept) continue;
        if (now) {
            lo = ts[k];
            lo_n = nk;
        } else {
            cut_add(lo, ts[k], lo_n, t0, t1, cap0);
        }
        kept = now;
    }
    if (kept) cut_add(lo, 1e30, lo_n, t0, t1, cap0);
    if (cut_count == 0) return false;
    t0 = cut_lo[0];
    t1 = cut_hi[cut_count - 1];
#else
    cut_lo[0] = t0;
    cut_hi[0] = t1;
    cut_cap_n[0] = cap0;
    cut_count = 1;
#endif
    return true;
}

// Sample i at t (grid t_start + i * step) inside the current kept interval:
// -1. Otherwise the index of the first sample of the next kept interval
// (max_steps when there is none), after moving cut_cur there.
int cut_leap(int i, float t, float t_start, float step, int max_steps)
{
    while (cut_cur < cut_count && t >= cut_hi[cut_cur]) cut_cur++;
    if (cut_cur == cut_count) return max_steps;
    if (t >= cut_lo[cut_cur]) return -1;
    return max(i + 1, int(ceil((cut_lo[cut_cur] - t_start) / step)));
}

// The gradient sample t is shaded with: the cap's normal for the first
// sample behind a cut surface (within one step of it), scaled to at least
// unit length so the scatter model takes it for a surface; g otherwise.
vec3 cut_cap(vec3 g, float t, float step)
{
    vec3 n = cut_cap_n[cut_cur];
    if (u_cut_caps == 0 || !(t < cut_lo[cut_cur] + step) || n == vec3(0.0)) return g;
    return normalize(n) * max(length(g), 1.0);
}

#define CUT_CAP(g, t) g = cut_cap(g, t, u_step)
#else
#define CUT_CAP(g, t)
#endif

// For a sample loop (march, the modes' marches): leaps sample i at t over a
// cutter's removed interval. Nothing without cutters.
#ifdef CUT_CUTTERS
#define CUT_SKIP_REMOVED(i, t, t_start) { int cut_next_ = cut_leap(i, t, t_start, u_step, u_max_steps); if (cut_next_ >= 0) { i = cut_next_ - 1; continue; } }
#else
#define CUT_SKIP_REMOVED(i, t, t_start)
#endif
