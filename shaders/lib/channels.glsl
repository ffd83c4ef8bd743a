// channels.glsl - multi-channel volumes (docs/channels.md; the GL side is
// csrc/channels/channels.c). CHANNEL_GROUPS (1 or 2) textures hold up to
// four 16-bit channels each on the volume's grid (dense storage), or as
// pools of page bricks (PAGED, below); channel_march replaces
// march. At each step one fetch per group samples every channel; each
// drawn channel (bit c of u_ch_drawn) is classified by its own table,
// window and opacity scale, coloured by its colour and lit with its own
// central-difference gradient (six fetches per group give four channels'
// gradients). u_ch_blend 0 (add): every channel composites on its own along
// the ray and the pixel is the sum, so the image equals the sum of the
// channels drawn one at a time; 1 (max): the step takes the channel of the
// largest opacity, one medium front to back. Samples lie at t_start + i *
// step whether or not the ray skips, and a leap crosses only bricks where
// every drawn channel is empty (u_ch_distance: the union of occupancies),
// so skipping changes no sample that counts.
#ifdef CHANNEL_GROUPS
#define CH_SLOTS (4 * CHANNEL_GROUPS)

uniform sampler3D u_ch_data0;           // channels 0-3, normalised, linear
#if CHANNEL_GROUPS > 1
uniform sampler3D u_ch_data1;           // channels 4-7
#endif
uniform sampler1D u_ch_tf[CH_SLOTS];    // straight RGBA, opacity per voxel of path
uniform vec4 u_ch_class[CH_SLOTS];      // window offset, window scale, table size, opacity scale
uniform vec3 u_ch_color[CH_SLOTS];      // the channel's colour, times the table's
uniform int u_ch_drawn;                 // bit c: channel c is drawn
uniform int u_ch_blend;                 // VXL_CHANNEL_BLEND_*: 0 add, 1 max
uniform usampler3D u_ch_distance;       // 0 occupied by a drawn channel; k: bricks within k-1 are empty
uniform int u_ch_brick_size;

#ifdef PAGED
// Paged storage (csrc/channels/channel_pages.c): each group's texture is a
// pool of the scalar's page bricks with their ghost borders, every pool
// with the same slots, so one page table serves all groups. Every brick is
// resident (a brick constant in every channel points at a slot of its
// constants), so the lookup is the scalar's without its w >= 0 branch, at
// full resolution (u_dims) whatever level the scalar's pool holds.
uniform sampler3D u_ch_page;
uniform vec3 u_ch_pool_dims;

vec3 ch_coord(vec3 p)
{
    page_entry_at(u_ch_page, u_dims, p);
    return (p + 0.5) / u_ch_pool_dims;
}
#else
vec3 ch_coord(vec3 p) { return voxel_to_tex(p); }
#endif

// Group grp at texture coordinate t (ch_coord: one page lookup serves every group).
vec4 ch_fetch_at(int grp, vec3 t)
{
#if CHANNEL_GROUPS > 1
    if (grp == 1) return textureLod(u_ch_data1, t, 0.0);
#endif
    return textureLod(u_ch_data0, t, 0.0);
}
vec4 ch_fetch(int grp, vec3 p) { return ch_fetch_at(grp, ch_coord(p)); }

bool ch_drawn(int c) { return ((u_ch_drawn >> c) & 1) != 0; }

// Straight colour and per-voxel opacity of channel c at normalised value v.
vec4 ch_classify(int c, float v)
{
    vec4 k = u_ch_class[c];
    float x = clamp((v - k.x) * k.y, 0.0, 1.0);
    vec4 e = textureLod(u_ch_tf[c], (x * (k.z - 1.0) + 0.5) / k.z, 0.0);
    return vec4(e.rgb * u_ch_color[c], clamp(e.a * k.w, 0.0, 1.0));
}

#ifdef SHADING
// Central differences of one group's four channels along each axis, taps
// u_sample_distance apart: the gradients of all four from six fetches.
void ch_gradients(int grp, vec3 p, out vec4 gx, out vec4 gy, out vec4 gz)
{
    float d = u_sample_distance;
    gx = (ch_fetch(grp, p + vec3(d, 0.0, 0.0)) - ch_fetch(grp, p - vec3(d, 0.0, 0.0))) / (2.0 * d);
    gy = (ch_fetch(grp, p + vec3(0.0, d, 0.0)) - ch_fetch(grp, p - vec3(0.0, d, 0.0))) / (2.0 * d);
    gz = (ch_fetch(grp, p + vec3(0.0, 0.0, d)) - ch_fetch(grp, p - vec3(0.0, 0.0, d))) / (2.0 * d);
}
#endif

vec4 channel_march(vec3 o, vec3 dir, float t0, float t1, RaySetup r, out float depth, out uint taken)
{
    float jitter = u_jitter != 0 ? jitter_hash(uvec2(gl_FragCoord.xy), u_jitter_seed) : 0.0;
    float t_start = t0 + jitter * u_step;
    vec4 acc[CH_SLOTS]; // add: one image per channel; max: acc[0] only
    for (int c = 0; c < CH_SLOTS; c++) acc[c] = vec4(0.0);
    depth = uintBitsToFloat(0x7f800000u);
    taken = 0u;
    for (int i = 0; i < u_max_steps; i++) {
        float t = t_start + float(i) * u_step;
        if (t >= t1) break;
#ifdef CUT_CUTTERS
        CUT_SKIP_REMOVED(i, t, t_start) // removed by a cutter (lib/cut.glsl)
#endif
        vec3 p = o + t * dir;
        if (u_skip != 0) {
            ivec3 b = ivec3(floor((p + 0.5) / float(u_ch_brick_size)));
            uint k = texelFetch(u_ch_distance, clamp(b, ivec3(0), textureSize(u_ch_distance, 0) - 1), 0).r;
            if (k > 0u) {
                i = last_sample_before(brick_cube_exit(b, k, float(u_ch_brick_size), o, dir), t_start, u_step,
                                       u_max_steps, i);
                continue;
            }
        }
        taken++;
        vec4 s[CHANNEL_GROUPS];
        vec3 tc = ch_coord(p);
        for (int grp = 0; grp < CHANNEL_GROUPS; grp++) s[grp] = ch_fetch_at(grp, tc);
        vec4 cs[CH_SLOTS];
        bool any = false;
        for (int c = 0; c < CH_SLOTS; c++) {
            cs[c] = ch_drawn(c) ? ch_classify(c, s[c / 4][c % 4]) : vec4(0.0);
            any = any || cs[c].a > 0.0;
        }
        if (!any) continue;
        if (u_ch_blend == 1) { // the dominant channel is the step's one sample
            int m = 0;
            for (int c = 1; c < CH_SLOTS; c++)
                if (cs[c].a > cs[m].a) m = c;
            for (int c = 0; c < CH_SLOTS; c++)
                if (c != m) cs[c].a = 0.0;
        }
#ifdef SHADING
        vec4 gx[CHANNEL_GROUPS], gy[CHANNEL_GROUPS], gz[CHANNEL_GROUPS];
        for (int grp = 0; grp < CHANNEL_GROUPS; grp++) {
            bool lit = false;
            for (int k = 0; k < 4; k++) lit = lit || cs[grp * 4 + k].a > 0.0;
            gx[grp] = gy[grp] = gz[grp] = vec4(0.0);
            if (lit) ch_gradients(grp, p, gx[grp], gy[grp], gz[grp]);
        }
#endif
        bool done = true;
        for (int c = 0; c < CH_SLOTS; c++) {
            int slot = u_ch_blend == 1 ? 0 : c;
            if (cs[c].a > 0.0 && acc[slot].a < u_early_termination) {
                float a = correct_opacity(cs[c].a, u_step);
                vec3 rgb = cs[c].rgb;
#ifdef SHADING
                vec3 g = vec3(gx[c / 4][c % 4], gy[c / 4][c % 4], gz[c / 4][c % 4]);
                CUT_CAP(g, t); // the first sample behind a cut takes the cut's normal
                rgb = shade_at(rgb, g, t, p, r);
#endif
                acc[slot] += (1.0 - acc[slot].a) * a * vec4(rgb, 1.0);
                if (isinf(depth) && acc[slot].a >= u_depth_threshold) depth = -(r.z0 + r.dz * t);
            }
            if (ch_drawn(c) && acc[slot].a < u_early_termination) done = false;
        }
        if (done) break;
    }
    vec4 sum = vec4(0.0);
    for (int c = 0; c < CH_SLOTS; c++) sum += acc[c];
    return sum;
}
#endif
