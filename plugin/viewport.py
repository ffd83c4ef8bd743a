"""3D viewport: a POST_VIEW draw handler that composites the library's
premultiplied RGBA + depth into the view.

Per region and volume, on every redraw:
  1. Skip volumes that are hidden, excluded or outside the view frustum:
     they cost no render, no depth read-back and no job.
  2. Read the depth of the bound framebuffer (the scene's depth at
     POST_VIEW), convert it to planar view distance and reduce it to what
     can change the image (depth.for_library): rays stop at geometry.
     The per-pixel maths runs only inside the volume's screen footprint
     and is cached by the depth's contents (crc32), so the redraws of a
     still view (refine steps arriving, hover) do not redo it.
  3. Build the render parameters and hash them (native.params_digest: every
     struct field, the scene depth's contents and the volume's identity).
     Equal hash = the image on screen is still right: nothing is rendered.
  4. Otherwise, progressive refinement:
       * an interactive frame (reduced resolution, doubled step) is
         rendered synchronously so the view follows the mouse; its
         resolution adapts to the measured frame time so that it takes
         about PREVIEW_SECONDS, half of a 10 fps frame
         (resolution_policy.ScalePolicy, at most the "While Moving"
         resolution);
       * once the view has been still for "Refine After" seconds, refined
         frames are queued on the renderer's background worker
         (runtime.Worker): half the still resolution first (when that is
         sharper than the preview and the full frame is predicted slow:
         _worth_a_half_step), then the full still resolution. When the
         full frame is predicted quick, each moving draw prepares it
         (_prepare_refine) and the settle timer queues it directly,
         without waiting for a redraw. The
         worker renders them in bands and drops one between bands as soon
         as it is stale (the view or anything else changed); a timer polls
         for the result and redraws. The draw handler never waits for a
         refined frame: at most for the band in flight.
  5. Draw a full-screen quad, depth test LESS_EQUAL and premultiplied
     blending (no depth writes). A frame at a reduced scale is upsampled
     in the shader with a depth-aware bilinear filter against the scene's
     full-resolution depth (core/upsample.py holds the same maths and
     why): no blocks in a preview, and no band of wrong texels along a
     mesh's silhouette. gl_FragDepth is the volume's hit, never behind the
     scene's own depth, so its colour (in front of that geometry, since
     the rays stopped there) always blends.
  6. Draw the front edges of each volume's box outline again, over the
     volume (box_outline.py says why).

VOXLIGHT_PROFILE=1 in the environment prints where each draw's time goes
(_Profile).
"""

import collections
import os
import time
import zlib

import bpy
import gpu
import numpy as np
from bpy.app.handlers import persistent

from . import app_handlers, box_outline, gpu_quad, overlay_frames, params, scene_shadows, scene_shadows_viewport
from .core import depth as _depth
from .core import upsample as _upsample
from .core import native, path_progress, resolution_policy, runtime, volume_space

_handle = None
_shader = None
_batch = None
_states = {}          # (region pointer, object name) -> _State
_refine_pending = False
_refine_redraw = False  # the settle timer also redraws (someone asked for it)
_poll_registered = False
last_error = ""

# Diagnostics for the tests and the panel.
draw_count = 0        # draw handler calls
culled_count = 0      # volumes skipped because they were outside the frustum
# (seconds in the handler, view moving, a refined frame in flight at its start)
draw_log = collections.deque(maxlen=256)
# Each newly shown image: (object name, "preview" | "half" | "full", scale,
# width, height); the refinement steps the artist saw, in order.
shown_log = collections.deque(maxlen=256)


class _Profile:
    """VOXLIGHT_PROFILE=1 in the environment: where one viewport draw's
    time goes. Each step is timed from the previous mark to its own
    (time.perf_counter) and summed per name; every draw prints one line

        voxlight profile: t=<perf_counter> handler 0.31 s [moving] setup 0.001
            ... gl_sync 0.20 glreadpixels 0.01 ... render 0.09 ... | blender scene 0.5
            overlays 0.001 | rendered 119x98 (rect ...) in 0.09 s ...; preview 119x98 scale 0.112

    "gl_sync" is the wait for the GL work Blender queued for this redraw
    (its own scene), which the depth read has to wait for; "blender scene"
    is Blender's own drawing between the region's PRE_VIEW and this
    POST_VIEW handler, "overlays" what follows it up to POST_PIXEL. Off
    (the default) a mark costs one attribute test."""

    def __init__(self, enabled):
        self.enabled = enabled
        self.steps = {}
        self.notes = []
        self._t = 0.0
        self._pre_view = None   # perf_counter at this region's PRE_VIEW
        self._handler_end = None
        self._line = None       # the handler's part, printed at POST_PIXEL

    def begin(self):
        self.steps, self.notes = {}, []
        self._t = time.perf_counter()

    def mark(self, step):
        if self.enabled:
            t = time.perf_counter()
            self.steps[step] = self.steps.get(step, 0.0) + (t - self._t)
            self._t = t

    def note(self, text):
        if self.enabled:
            self.notes.append(text)

    def end(self, seconds, moving):
        if not self.enabled:
            return
        self._handler_end = time.perf_counter()
        scene_s = "" if self._pre_view is None else " | blender scene %.4f" % (
            self._handler_end - seconds - self._pre_view)
        self._line = "voxlight profile: t=%.3f handler %.4f s%s %s%s" % (
            self._handler_end, seconds, " [moving]" if moving else "",
            " ".join("%s %.4f" % kv for kv in self.steps.items()), scene_s)

    def pre_view(self):
        self._pre_view = time.perf_counter()

    def post_pixel(self):
        if self._line is None:
            return
        tail = " overlays %.4f" % (time.perf_counter() - self._handler_end)
        notes = (" | " + "; ".join(self.notes)) if self.notes else ""
        print(self._line + tail + notes, flush=True)
        self._line = self._pre_view = None


_profile = _Profile(os.environ.get("VOXLIGHT_PROFILE", "") not in ("", "0"))
_profile_handles = []


class _Image:
    """One rendered frame, uploaded: GPUTextures must outlive the draw call
    that samples them, so they live here until replaced."""

    # streamed volumes: bricks drawn coarser than the frame wanted
    # (stats refine_pending), the coarsest level drawn, when it was made, and
    # since when the passes of its view have not got finer (None: they do).
    pending = 0
    level = 0
    made_at = 0.0
    stalled_since = None
    # the path model: samples the image holds (0: not a path frame), and its
    # colour kept for the next pass's running mean (core/path_progress.py)
    path_samples = 0
    rgba = None

    def __init__(self, key, rgba, vdepth, win_small, proj, full, scale=1.0, rect=None,
                 box=(0.0, 1e30, 0.0)):
        self.key = key
        self.box = box     # (near, far, tolerance): the shader's depth comparison
        self.full = full
        self.scale = scale
        self.height, self.width = rgba.shape[:2]
        self.vdepth = vdepth
        self.proj = proj
        self.rect = rect   # the rendered pixels; outside them vdepth is +inf
        _profile.mark("result")
        self.color = _texture(rgba, "RGBA32F")
        _profile.mark("color_texture")
        self.depth = None
        self.depth_crc = None
        self.update_depth(win_small)

    def update_depth(self, win_small):
        """The (hit, stop) depths the shader composites with, from the
        volume's hit depth and the scene depth now on screen at this
        resolution. Cheap (no library call); redone only when that scene
        depth changed, e.g. by less than the quantum of the frame key."""
        crc = _crc(win_small) if win_small is not None else None
        if crc == self.depth_crc and self.depth is not None:
            _profile.mark("depth_check")
            return
        frag = _fragment_depth(self.vdepth, self.proj, win_small, self.rect)
        _profile.mark("fragment_depth")
        self.depth = _texture(frag, "RG32F")
        self.depth_crc = crc
        _profile.mark("depth_texture")


class _State:
    def __init__(self):
        self.view_key = None
        self.moved_at = -1e9
        self.used_at = 0.0
        self.fast = None      # latest interactive _Image
        self.half = None      # latest refined _Image at half the still resolution
        self.full = None      # latest full-resolution _Image
        self.policy = None    # resolution_policy.ScalePolicy of the interactive frames
        self.pixels_at_scale_1 = 0  # the volume's footprint at scale 1, from the last preview
        self.shown = None     # the _Image drawn last
        self.job = None       # runtime.Job of the full frame being refined
        self.job_entry = None
        self.announced = False
        self.error_key = None
        self.refine_spp = None  # seconds a pixel of the last refined frame took (worker)
        # (entry, _Frame, is the full step, owner): the first refine step of
        # the view the last moving draw showed, queued by the settle timer
        self.next_refine = None

    # compatibility with older tests and scripts: the drawn textures
    @property
    def color(self):
        return self.shown.color if self.shown is not None else None

    def cancel_job(self):
        if self.job is not None and not self.job.done and self.job_entry is not None:
            self.job_entry.worker.cancel(self.job)
        self.job = None
        self.next_refine = None

    def submit(self, entry, frame, full, owner, path_offset=None):
        """Queue `frame` on the entry's worker as this volume's refine job;
        path_offset: the path model's sample it renders (None: not a path
        frame; 0 for the first)."""
        self.cancel_job()
        self.job = entry.worker.submit(runtime.Job(owner, frame.key, frame.params, frame.rect))
        self.job.full = full  # for busy_full(): the last, slowest refine step
        self.job.path_offset = path_offset if path_offset is not None else \
            (0 if getattr(frame, "path", False) else None)
        self.job_entry = entry
        self.announced = False
        _ensure_poll()


# The compositing shader: plugin/core/upsample.py in GLSL (its docstring
# says why). color_tex is the frame's premultiplied RGBA, depth_tex its
# (hit, stop) window depths, scene_tex the scene's window depth at full
# resolution. proj_rows = (p22, p23, p32, p33) of the projection, box =
# (near, far, tolerance) in planar distance, filter_mode 1 = bilateral,
# 0 = nearest (the compositing before it, kept for the bench and tests).
_FRAG = """
float planar(float w)
{
    if (w >= 1.0) {
        return box.y;
    }
    float ndc = w * 2.0 - 1.0;
    float d = -(proj_rows.y - ndc * proj_rows.w) / (ndc * proj_rows.z - proj_rows.x);
    return clamp(d, box.x, box.y);
}

/* The library's image is scene-linear (params.look_kwargs) and is filtered
   as such; the viewport draws display colour, so the straight colour is
   encoded as sRGB at the end, as the Standard view transform would
   (core/colour_space.py's linear_to_srgb). */
vec4 to_display(vec4 c)
{
    if (c.a <= 0.0) {
        return vec4(0.0);
    }
    vec3 s = clamp(c.rgb / c.a, 0.0, 1.0);
    vec3 e = mix(s * 12.92, 1.055 * pow(s, vec3(1.0 / 2.4)) - 0.055, greaterThan(s, vec3(0.0031308)));
    return vec4(e * c.a, c.a);
}

void main()
{
    ivec2 cs = textureSize(color_tex, 0);
    ivec2 ss = textureSize(scene_tex, 0);
    float scene = texelFetch(scene_tex, clamp(ivec2(uv * vec2(ss)), ivec2(0), ss - 1), 0).r;
    if (filter_mode == 0) {
        ivec2 t = clamp(ivec2(uv * vec2(cs)), ivec2(0), cs - 1);
        vec2 hs = texelFetch(depth_tex, t, 0).rg;
        fragColor = to_display(texelFetch(color_tex, t, 0));
        gl_FragDepth = hs.r < 1.0 ? min(hs.r, hs.g) : hs.g;
        return;
    }
    float dp = planar(scene);
    vec2 f = uv * vec2(cs) - 0.5;
    vec2 i0 = floor(f);
    vec2 fr = f - i0;
    /* a: stopped at this pixel's depth, b: stopped nearer, c: went past
       it; weighted sum, plain sum, count, nearest hit (no arrays: Mesa's
       llvmpipe got the dynamically indexed ones wrong) */
    vec4 acc_a = vec4(0.0), accu_a = vec4(0.0), acc_b = vec4(0.0), accu_b = vec4(0.0);
    vec4 acc_c = vec4(0.0), accu_c = vec4(0.0);
    float w_a = 0.0, n_a = 0.0, hit_a = 1.0, w_b = 0.0, n_b = 0.0, hit_b = 1.0;
    float w_c = 0.0, n_c = 0.0, hit_c = 1.0;
    for (int k = 0; k < 4; k++) {
        int ox = k - 2 * (k / 2);
        int oy = k / 2;
        ivec2 t = clamp(ivec2(i0) + ivec2(ox, oy), ivec2(0), cs - 1);
        float wx = ox == 1 ? fr.x : 1.0 - fr.x;
        float wy = oy == 1 ? fr.y : 1.0 - fr.y;
        float wb = wx * wy;
        vec2 hs = texelFetch(depth_tex, t, 0).rg;
        float ds = planar(hs.g);
        vec4 c = texelFetch(color_tex, t, 0);
        if (abs(ds - dp) <= box.z) {
            acc_a += wb * c;
            accu_a += c;
            w_a += wb;
            n_a += 1.0;
            hit_a = min(hit_a, hs.r);
        }
        else if (ds < dp - box.z) {
            acc_b += wb * c;
            accu_b += c;
            w_b += wb;
            n_b += 1.0;
            hit_b = min(hit_b, hs.r);
        }
        else {
            acc_c += wb * c;
            accu_c += c;
            w_c += wb;
            n_c += 1.0;
            hit_c = min(hit_c, hs.r);
        }
    }
    float hit = 1.0;
    fragColor = vec4(0.0);
    if (n_a > 0.0) {
        fragColor = w_a > 1e-4 ? acc_a / w_a : accu_a / n_a;
        hit = hit_a;
    }
    else if (n_b > 0.0) {
        fragColor = w_b > 1e-4 ? acc_b / w_b : accu_b / n_b;
        hit = hit_b;
    }
    else if (n_c > 0.0 && hit_c <= scene) {
        fragColor = w_c > 1e-4 ? acc_c / w_c : accu_c / n_c;
        hit = hit_c;
    }
    fragColor = to_display(fragColor);
    gl_FragDepth = min(hit, scene);
}
"""

# "bilateral" (the default) or "nearest" (how frames were composited
# before: blocks at preview scales); the bench and the GUI test switch it.
PREVIEW_FILTER = os.environ.get("VOXLIGHT_PREVIEW_FILTER", "bilateral")


def _get_shader():
    global _shader, _batch
    if _shader is None:
        _shader, _batch = gpu_quad.quad_shader(
            "voxlight", ("color_tex", "depth_tex", "scene_tex"), _FRAG,
            constants=(("VEC4", "proj_rows"), ("VEC4", "box"), ("INT", "filter_mode")))
    return _shader, _batch


WindowDepth = collections.namedtuple("WindowDepth", "pixels crc")  # what _read_window_depth read


def _read_window_depth(width, height):
    """The bound framebuffer's depth (window depth 0..1) as a WindowDepth:
    a (height, width) array, row 0 = bottom, and the crc32 of its bytes
    (what the frames' depth conversions are cached by); None without a
    depth attachment.

    The read waits for the GL work Blender queued for this redraw (its own
    scene): with VOXLIGHT_PROFILE=1 a one-pixel read first times that wait
    apart ("gl_sync") from the read itself ("glreadpixels").

    Read into a one-dimensional Buffer on purpose: Blender 3.4's
    gpu.types.Buffer exports multi-dimensional shapes to the buffer
    protocol with Fortran strides (stride[0] = item size) although the data
    is row-major, so np.asarray() of read_depth()'s (height, width) Buffer
    is the transposed memory reshaped: a mesh in front of part of the view
    came out as vertical stripes. A flat Buffer has one stride and no
    ambiguity."""
    buf = gpu.types.Buffer("FLOAT", width * height)
    _profile.mark("depth_alloc")
    try:
        fb = gpu.state.active_framebuffer_get()
        if _profile.enabled:  # wait for Blender's queued GL work, timed on its own
            fb.read_depth(0, 0, 1, 1)
            _profile.mark("gl_sync")
        fb.read_depth(0, 0, width, height, data=buf)
    except Exception:  # no depth attachment: draw without occlusion input
        return None
    _profile.mark("glreadpixels")
    pixels = np.asarray(buf, dtype=np.float32).reshape(height, width)
    window = WindowDepth(pixels, _crc(pixels))
    _profile.mark("depth_numpy_crc")
    return window


def _crc(arr):
    """crc32 of an array's bytes, without copying a contiguous one."""
    return zlib.crc32(np.ascontiguousarray(arr))


def _library_depth(win_small, proj, near, far, quantum, rect):
    """The scene depth the library is given (depth.for_library of the
    planar depth), computed in the footprint `rect` only: for_library sets
    every pixel outside it to +inf, and both steps work pixel by pixel, so
    the result equals the whole image's at a fraction of the work."""
    if rect is None:
        return _depth.for_library(_depth.window_to_planar(win_small, proj), near, far, quantum)
    x0, y0, x1, y1 = rect
    out = np.full(win_small.shape, np.inf, np.float32)
    out[y0:y1, x0:x1] = _depth.for_library(
        _depth.window_to_planar(win_small[y0:y1, x0:x1], proj), near, far, quantum)
    return out


def _fragment_depth(vdepth, proj, win_small, rect):
    """(h, w, 2): the window depth of the volume's hit (1 where its ray hit
    nothing) and of the scene depth that stopped the frame's rays (1
    without one), as upsample.composite takes them. Outside `rect` a frame
    has no hit (render_tiled leaves +inf there), so only the footprint is
    converted; the result equals the whole image's."""
    h, w = vdepth.shape
    out = np.ones((h, w, 2), np.float32)
    if win_small is not None:
        out[..., 1] = win_small
    x0, y0, x1, y1 = rect if rect is not None else (0, 0, w, h)
    out[y0:y1, x0:x1, 0] = _depth.planar_to_window(vdepth[y0:y1, x0:x1], proj)
    return out


# The scene's window depth at full resolution as a texture, for the
# shader's depth-aware upsampling; one upload per new depth buffer.
_scene_tex = {}


def _scene_texture(window):
    key = None if window is None else (window.crc, window.pixels.shape)
    tex = _scene_tex.get(key)
    if tex is None:
        _scene_tex.clear()
        tex = _scene_tex[key] = _texture(window.pixels if window is not None
                                         else np.ones((1, 1), np.float32), "R32F")
        _profile.mark("scene_texture")
    return tex


# Scene depth converted for the library, per frame size and footprint,
# keyed by the window depth's contents: a still view redraws (hover,
# refine steps arriving) reuse it instead of redoing the per-pixel maths.
_DEPTH_CACHE_SIZE = 6
_depth_cache = collections.OrderedDict()


def _scene_depth(window, w, h, proj, near, far, quantum, rect):
    """(window depth at w x h, the library's scene depth) of a frame."""
    key = (window.crc, window.pixels.shape, w, h, proj.tobytes(), near, far, quantum, rect)
    hit = _depth_cache.get(key)
    if hit is not None:
        _depth_cache.move_to_end(key)
        return hit
    win_small = _depth.downsample(window.pixels, w, h)
    hit = (win_small, _library_depth(win_small, proj, near, far, quantum, rect))
    _depth_cache[key] = hit
    while len(_depth_cache) > _DEPTH_CACHE_SIZE:
        _depth_cache.popitem(last=False)
    return hit


def _texture(arr, fmt):
    h, w = arr.shape[:2]
    a = np.ascontiguousarray(arr, np.float32).ravel()
    buf = gpu.types.Buffer("FLOAT", a.size, a)
    return gpu.types.GPUTexture((w, h), format=fmt, data=buf)


def _outside_frustum(model, dims, view, proj):
    return volume_space.outside_frustum(model, dims, view, proj)


# ------------------------------------------------------------- timers

def _refine():
    """The settle timer. A volume whose view has been still for Refine After
    gets its first refine step queued now, from the frame its last moving
    draw prepared: waiting for a redraw to queue it would add one of
    Blender's own redraws (0.2-0.4 s on software GL) before the render
    starts; the poll timer redraws once the step is done. A volume without
    a prepared frame (or whose renderer closed) gets the redraw that queues
    it, as does every other caller of _schedule_refine (a light that
    settles); a view still moving (not settled yet) brings the timer back."""
    global _refine_pending, _refine_redraw
    _refine_pending = False
    redraw, _refine_redraw = _refine_redraw, False
    now = time.monotonic()
    for st in list(_states.values()):
        pending = st.next_refine
        if pending is None:
            continue
        entry, frame, full, owner, settle = pending
        wait = settle - (now - st.moved_at)
        if wait > 0.0:
            _schedule_refine(wait + 0.01, redraw=False)
            continue
        try:
            st.submit(entry, frame, full, owner)
        except native.VoxlightError:
            st.next_refine = None
            redraw = True
    if redraw:
        from .properties import tag_redraw
        tag_redraw()
    return None


def _schedule_refine(delay, redraw=True):
    """Run the settle timer in `delay` s; `redraw`: it must also redraw
    (not needed by a volume whose refine frame is prepared)."""
    global _refine_pending, _refine_redraw
    _refine_redraw |= redraw
    if not _refine_pending:
        _refine_pending = True
        bpy.app.timers.register(_refine, first_interval=max(delay, 0.02))


def _tag_region(region_ptr):
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for win in wm.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D" and any(r.as_pointer() == region_ptr for r in area.regions):
                area.tag_redraw()


def _tag_properties():
    wm = getattr(bpy.context, "window_manager", None)
    for win in (wm.windows if wm is not None else ()):
        for area in win.screen.areas:
            if area.type == "PROPERTIES":
                area.tag_redraw()


def _poll():
    """Main-thread timer: redraw the regions whose refined frame is ready."""
    global _poll_registered
    waiting = False
    for (region_ptr, _name), st in list(_states.items()):
        job = st.job
        if job is None:
            continue
        if job.done:
            if not st.announced:
                st.announced = True
                _tag_region(region_ptr)
        else:
            waiting = True
    if waiting:
        return 0.03
    _poll_registered = False
    return None


def _ensure_poll():
    global _poll_registered
    if not _poll_registered:
        _poll_registered = True
        bpy.app.timers.register(_poll, first_interval=0.03)


def busy():
    """True while a refined frame is queued or being rendered."""
    return any(st.job is not None and not st.job.done for st in _states.values()) \
        or runtime.busy()


def busy_full():
    """True while a full-resolution refine (not the half step) is queued or
    being rendered."""
    return any(st.job is not None and not st.job.done and st.job.full
               for st in _states.values())


# --------------------------------------------------------------- frames

class _Frame:
    """Everything one render of one volume at one size needs, and its key."""

    def __init__(self, ob, entry, w, h, view, proj, model, window_depth, lights, fast, scale=1.0):
        self.w, self.h = w, h
        self.scale = scale
        dims = tuple(ob.voxlight.dims)
        _profile.mark("frame_setup")
        ovl = overlay_frames.current(ob.name)  # the pixels and depths of its overlays too
        self.rect = overlay_frames.screen_rect(model, dims, ovl, view, proj, w, h)
        self.win_small = None
        scene_depth = None
        near, far = overlay_frames.planar_range(model, dims, ovl, view)
        self.box = (max(near, 0.0), far, _upsample.tolerance(volume_space.voxel_size(model)))
        if window_depth is not None:
            quantum = 0.125 * volume_space.voxel_size(model)
            self.win_small, scene_depth = _scene_depth(window_depth, w, h, proj, near, far,
                                                       quantum, self.rect)
        _profile.mark("scene_depth")
        self.params = params.build(ob, w, h, view, proj, scene_depth=scene_depth,
                                   lights=lights, fast=fast,
                                   scene_shadows=scene_shadows.for_viewport(ob), overlays=ovl.overlays)
        # never wait for a streamed volume's bricks here; what is
        # still loading is drawn coarser and refined later (_keep_refining).
        self.params.progressive = 1
        # the path model: one sample a pass (offset set when queued), the
        # passes accumulated while the view is still (_keep_refining)
        self.path = self.params.shading_model == _path_model()
        self.path_target = ob.voxlight.path_viewport_samples if self.path else 0
        if self.path:
            self.params.path_samples, self.params.path_sample_offset = 1, 0
        _profile.mark("params")
        self.key = native.params_digest(self.params, entry.identity)
        _profile.mark("digest")


def _path_model():
    """VXL_SHADING_PATH's number, or -1 with a library without it."""
    try:
        return native.load_library().index("shading_model", "path")
    except (ValueError, KeyError, native.VoxlightError, native.LibraryUnavailable):
        return -1


def _size(W, H, frac):
    return max(1, round(W * frac)), max(1, round(H * frac))


def _frame_at(scale, ob, entry, W, H, view, proj, model, window_depth, lights, fast):
    w, h = _size(W, H, scale)
    return _Frame(ob, entry, w, h, view, proj, model, window_depth, lights, fast, scale)


def _rect_pixels(rect):
    return 0 if rect is None else (rect[2] - rect[0]) * (rect[3] - rect[1])


def _draw_image(img, shader, batch, scene_tex):
    if img is None or img.color is None:
        return
    shader.bind()
    shader.uniform_sampler("color_tex", img.color)
    shader.uniform_sampler("depth_tex", img.depth)
    shader.uniform_sampler("scene_tex", scene_tex)
    p = np.asarray(img.proj, np.float64).reshape(4, 4)
    shader.uniform_float("proj_rows", (p[2, 2], p[2, 3], p[3, 2], p[3, 3]))
    shader.uniform_float("box", (img.box[0], img.box[1], img.box[2], 0.0))
    shader.uniform_int("filter_mode", 0 if PREVIEW_FILTER == "nearest" else 1)
    gpu.state.depth_test_set("LESS_EQUAL")
    # No depth writes: Blender may redraw only the overlays and keep the
    # scene's depth buffer, and the next frame's depth read must not see
    # the volume's own depth (that feedback made rays stop at stale hits).
    gpu.state.depth_mask_set(False)
    gpu.state.blend_set("ALPHA_PREMULT")
    batch.draw(shader)
    gpu.state.blend_set("NONE")
    gpu.state.depth_test_set("NONE")


def _kind(st, img):
    """Which refinement step an image of `st` is (shown_log, profile)."""
    return "full" if img.full else "half" if img is st.half else "preview"


def _report(e):
    global last_error
    if last_error != str(e):
        print("Voxlight: viewport render failed: %s" % e)
    last_error = str(e)


def _rendering():
    """True while an F12 render job runs. Blender's render thread then runs
    this add-on's render handlers, which wait for Python's lock, while
    holding scene data; a redraw that evaluates the viewport's depsgraph
    (evaluated_depsgraph_get) waits for that data while it holds Python's
    lock: Blender froze for good (test_gui_f12 caught it in 1 run of 3, in
    Workbench, after renders in every engine). So the viewport draws no
    volume until the render ends; Blender redraws it then."""
    running = getattr(bpy.app, "is_job_running", None)
    return bool(running and running("RENDER"))


def _draw():
    global draw_count, culled_count, last_error
    t_draw = time.perf_counter()
    if _profile.enabled:
        _profile.begin()
    draw_count += 1
    in_flight = busy()
    ctx = bpy.context
    scene = ctx.scene
    if scene is None or not scene.voxlight.viewport_enabled:
        return
    if _rendering():
        return
    region, rv3d, space = ctx.region, ctx.region_data, ctx.space_data
    if rv3d is None or region is None:
        return
    view_layer = ctx.view_layer
    # visible_get covers hidden objects, disabled and excluded collections
    # and local view; such volumes cost nothing.
    objs = [o for o in view_layer.objects
            if o.type in volume_space.VOLUME_TYPES and o.voxlight.is_volume and o.visible_get(viewport=space)]
    # an overlay is drawn inside its base's frame, not on its own.
    fused = {b.name: ovs for b, ovs in overlay_frames.fuse(objs)}
    outlined = objs
    objs = [o for o in objs if o.name in fused]
    region_ptr = region.as_pointer()
    drawn = set()
    moving_any = False
    if objs:
        s = scene.voxlight
        vp = gpu.state.viewport_get()
        W, H = (vp[2], vp[3]) if vp[2] > 0 and vp[3] > 0 else (region.width, region.height)
        view = np.array(rv3d.view_matrix, np.float64)
        proj = np.array(rv3d.window_matrix, np.float64)
        depsgraph = ctx.evaluated_depsgraph_get()
        now = time.monotonic()
        view_key = (view.tobytes(), proj.tobytes(), W, H)
        window_depth = None
        depth_read = False
        lights = None
        shader, batch = _get_shader()

        for obj in objs:
            ob = obj.evaluated_get(depsgraph)
            model = params.model_matrix(ob)
            overlays = [o.evaluated_get(depsgraph) for o in fused[obj.name]]
            if _outside_frustum(model, tuple(ob.voxlight.dims), view, proj) and all(
                    _outside_frustum(params.model_matrix(o), tuple(o.voxlight.dims), view, proj) for o in overlays):
                culled_count += 1
                continue
            key = (region_ptr, obj.name)
            drawn.add(key)
            st = _states.get(key)
            if st is None:
                st = _states[key] = _State()
            st.used_at = now
            if view_key != st.view_key:
                if st.view_key is not None:
                    st.moved_at = now
                st.view_key = view_key
            moving = (now - st.moved_at) < s.settle_time
            moving_any |= moving
            _profile.mark("setup")
            try:
                entry = runtime.entry_for(bpy.path.abspath(ob.voxlight.filepath), ob.voxlight,
                                          scene.frame_current, **runtime.options_of(s))
                overlay_frames.prepare(entry, ob, overlays, scene.frame_current)
            except native.VoxlightError as e:
                _report(e)
                continue
            _profile.mark("entry")
            if not depth_read:
                window_depth = _read_window_depth(W, H)
                depth_read = True
                _profile.mark("depth_read")
                lights = params.scene_lights(scene, depsgraph)
                # a light being dragged gets a coarse illumination
                # volume, refined by a redraw once it settles (params.py).
                lights, light_settles_in = params.while_lights_move(lights, now, s.settle_time)
                if light_settles_in is not None:
                    _schedule_refine(light_settles_in + 0.01)
                _profile.mark("lights")
                # the meshes that shadow the volumes, and the
                # volumes' shadow on the meshes (drawn under the volumes).
                scene_shadows.refresh_viewport(depsgraph, objs)
                scene_shadows_viewport.draw_layer(scene, depsgraph, objs, window_depth, W, H,
                                                  view, proj, lights, region_ptr)
                _profile.mark("scene_shadows")
            try:
                shown = _update(st, ob, entry, W, H, view, proj, model, window_depth, lights,
                                moving, key)
            except native.VoxlightError as e:
                _report(e)
                continue
            last_error = ""
            if moving:
                _schedule_refine(s.settle_time - (now - st.moved_at) + 0.01,
                                 redraw=st.next_refine is None)
            if shown is not None and shown is not st.shown:
                shown_log.append((obj.name, _kind(st, shown), shown.scale, shown.width,
                                  shown.height))
            st.shown = shown
            _profile.mark("update")
            _draw_image(shown, shader, batch, _scene_texture(window_depth))
            _profile.mark("gpu_draw")
            if shown is not None:
                _profile.note("%s %dx%d scale %.3f" % (_kind(st, shown), shown.width, shown.height,
                                                       shown.scale))
        box_outline.draw(outlined, view, rv3d.is_perspective, space, (W, H))
        _profile.mark("outline")

    # Volumes of this region that were not drawn (hidden, culled, deleted)
    # must not keep a worker busy.
    for key, st in _states.items():
        if key[0] == region_ptr and key not in drawn:
            st.cancel_job()
    if len(_states) > 64:  # forget regions and objects not drawn for a minute
        now = time.monotonic()
        for k in [k for k, v in _states.items() if now - v.used_at > 60.0]:
            _states.pop(k).cancel_job()
    seconds = time.perf_counter() - t_draw
    draw_log.append((seconds, moving_any, in_flight))
    if _profile.enabled:
        _profile.mark("bookkeeping")
        _profile.end(seconds, moving_any)


def _update(st, ob, entry, W, H, view, proj, model, window_depth, lights, moving, owner):
    """Decide what to show for one volume; render only what is missing."""
    s = bpy.context.scene.voxlight
    if st.policy is None:
        st.policy = resolution_policy.ScalePolicy(s.interactive_resolution,
                                                  target_seconds=PREVIEW_SECONDS)
    args = (ob, entry, W, H, view, proj, model, window_depth, lights)
    if not moving:
        decided, shown = _refine_still(st, s, args, owner)
        if decided:
            return shown
    else:
        st.cancel_job()
    shown = _preview(st, s, args)
    if moving and shown is not None and st.next_refine is None:
        _prepare_refine(st, s, args, owner)
    return shown


def _prepare_refine(st, s, args, owner):
    """A moving draw: build the full-resolution frame of this view (what
    _refine_still would queue), for the settle timer to queue as soon as
    the view has been still for Refine After. Only when that frame is
    predicted quick, so that one redraw less is what the artist waits for;
    a slow one shows the half step first and is queued by a redraw as
    before. Costs a few milliseconds (scene depth in the footprint,
    parameters, key) per new preview, and the still draw finds that scene
    depth cached."""
    ob, entry, W, H, view, proj, model = args[:7]
    steps = resolution_policy.refine_scales(st.fast.scale if st.fast is not None
                                            else st.policy.scale, s.viewport_resolution)
    w, h = _size(W, H, steps[-1])
    rect = volume_space.screen_rect(model, tuple(ob.voxlight.dims), view, proj, w, h)
    if rect is None or st.refine_spp is None or len(_worth_a_half_step(st, steps, rect)) > 1:
        return
    full = _frame_at(steps[-1], *args, fast=False)
    if full.rect is not None and st.error_key != full.key:
        st.next_refine = (entry, full, True, owner, s.settle_time)
    _profile.mark("prepare_refine")


# The library's time budget for an interactive frame: half of a 10 fps
# frame, the other half left to Blender's own scene (which alone takes
# 0.2-0.4 s on 2-core software GL, docs/viewport_latency.md), so the
# preview's resolution, not the add-on, gives way while orbiting.
PREVIEW_SECONDS = 0.05

# Showing the half-resolution step costs the artist one more of Blender's
# redraws before the full image (0.3-0.4 s of Blender's own scene on
# software GL), and its render delays the full one: it is only worth it when
# the full frame itself is slow.
HALF_STEP_WORTH_S = 0.3


def _worth_a_half_step(st, steps, full_rect):
    """`steps` (refine_scales), without the half step when the full frame
    (footprint `full_rect`) is predicted, from the per-pixel time of this
    volume's last refined frame, to take under HALF_STEP_WORTH_S. Unknown
    (no refined frame yet): keep the half step."""
    if len(steps) < 2 or st.refine_spp is None:
        return steps
    if st.refine_spp * _rect_pixels(full_rect) < HALF_STEP_WORTH_S:
        return steps[-1:]
    return steps


def _refine_still(st, s, args, owner):
    """The view is still: collect a finished refined frame, queue the next
    step (half, then full still resolution) and return the sharpest image
    ready for this view. Returns (True, image or None to show nothing), or
    (False, None) to show the preview."""
    preview_scale = st.fast.scale if st.fast is not None else st.policy.scale
    steps = resolution_policy.refine_scales(preview_scale, s.viewport_resolution)
    full = _frame_at(steps[-1], *args, fast=False)
    steps = _worth_a_half_step(st, steps, full.rect)
    built = {}

    def half_frame():
        """The half-resolution step (None when there is none), built only
        when needed: not on the redraws of a view whose full frame shows."""
        if len(steps) < 2:
            return None
        if "half" not in built:
            built["half"] = _frame_at(steps[0], *args, fast=False)
        return built["half"]

    job = st.job
    fr = None
    if job is not None and job.done:
        fr = full if job.key == full.key else half_frame()
    if fr is not None and job.key == fr.key:
        if job.result is not None:
            rgba, vdepth, stats = job.result
            offset = getattr(job, "path_offset", None)
            if offset is not None:  # a path pass: the running mean of its samples
                prev = st.full if fr is full and st.full is not None and st.full.key == fr.key else None
                rgba = path_progress.accumulate(prev.rgba if prev is not None else None, rgba,
                                                offset if prev is not None else 0)
            if _rect_pixels(fr.rect) > 0 and stats.get("seconds", 0.0) > 0.0:
                st.refine_spp = stats["seconds"] / _rect_pixels(fr.rect)
            img = _Image(fr.key, rgba, vdepth, fr.win_small, args[5], fr is full, fr.scale, fr.rect,
                         fr.box)
            _note_streaming(img, stats, st.full if fr is full and st.full is not None
                            and st.full.key == fr.key else None)
            if offset is not None:
                img.rgba = rgba
                img.path_samples = offset + 1 if prev is not None else 1
            st.job = None
            if fr is full:
                st.full = img
                _tag_properties()  # the Statistics panel shows this final frame, not the preview
            else:
                st.half = img
        elif job.error is not None:
            st.job = None
            st.error_key = fr.key
            raise native.VoxlightError(str(job.error))
    if st.full is not None and st.full.key == full.key:
        st.full.update_depth(full.win_small)
        if not _keep_refining(st, args[1], full, owner):
            st.cancel_job()
        return True, st.full
    half = half_frame()
    if st.error_key in [fr.key for fr in (full, half) if fr is not None] or full.rect is None:
        return True, None  # failed with exactly these inputs, or nothing on screen
    have_half = half is not None and st.half is not None and st.half.key == half.key
    step = full if half is None or have_half else half
    if st.job is None or st.job.key != step.key or (st.job.done and st.job.result is None):
        st.submit(args[1], step, step is full, owner)
    if have_half:
        st.half.update_depth(half.win_small)
        return True, st.half
    return False, None


# a streamed volume's frame is drawn at once from the bricks at
# hand, coarser where finer ones are still loading on the renderer's loader
# thread (stats refine_pending > 0). The still view is then rendered again
# every STREAM_REFINE_S, each finer image replacing the last, until nothing
# is pending. A safety net ends it when the passes have not got finer for
# STREAM_STALL_S: neither fewer pending bricks nor a finer coarsest level.
# Loading a level can take a while with the count unchanged (12 s for the
# 3 GiB volume of tests/blender/test_streaming.py on 2 busy cores), so the
# net is wide.
STREAM_REFINE_S = 0.25
STREAM_STALL_S = 60.0


def _note_streaming(img, stats, previous):
    """img's pending bricks and coarsest level from its stats, and since
    when its view has not got finer, against the image of the same view it
    replaces (None: a new view)."""
    img.pending = int(stats.get("refine_pending", 0))
    img.level = int(stats.get("stream_level", 0))
    img.made_at = time.monotonic()
    if previous is not None and previous.pending and img.pending >= previous.pending \
            and img.level >= previous.level:
        img.stalled_since = previous.stalled_since if previous.stalled_since is not None \
            else previous.made_at


def _keep_refining(st, entry, full, owner):
    """The full image of a still view is on screen: while it is coarser than
    wanted, queue the next pass of the same frame (or a redraw that queues
    it once STREAM_REFINE_S has passed). False when it is final."""
    img = st.full
    now = time.monotonic()
    if full.path and not img.pending:
        nxt = path_progress.next_offset(img.path_samples, full.path_target)
        if nxt is None:
            return False
        if st.job is not None and not st.job.done:
            return True  # the next sample is on its way; the poll timer redraws
        full.params.path_sample_offset = nxt
        st.submit(entry, full, True, owner, path_offset=nxt)
        return True
    if not img.pending or (img.stalled_since is not None and now - img.stalled_since > STREAM_STALL_S):
        return False
    if st.job is not None and not st.job.done:
        return True  # the next pass is on its way; the poll timer redraws
    wait = STREAM_REFINE_S - (now - img.made_at)
    if wait > 0.0:
        _schedule_refine(wait)
        return True
    st.submit(entry, full, True, owner)
    return True


def _preview(st, s, args):
    """The interactive frame at the policy's scale: rendered synchronously
    when missing, timed, and the time fed back to the policy."""
    fast = _frame_at(st.policy.scale, *args, fast=True)
    if st.fast is not None and st.fast.key == fast.key:
        st.fast.update_depth(fast.win_small)
        return st.fast
    # A new frame is needed anyway: the scale may adapt first.
    scale = st.policy.next_scale(st.pixels_at_scale_1, s.interactive_resolution)
    if scale != fast.scale:
        fast = _frame_at(scale, *args, fast=True)
    if fast.rect is None or st.error_key == fast.key:
        return None  # off screen, or failed with exactly these inputs: no retry per redraw
    _profile.mark("policy")
    t = time.perf_counter()
    try:
        rgba, vdepth, stats = runtime.render_rect(args[1], fast.params, fast.rect)
    except native.VoxlightError:
        st.error_key = fast.key
        raise
    _profile.mark("render")
    _profile.note("rendered %dx%d (rect %s) in %.4f s, library calls %.4f s" % (
        fast.w, fast.h, fast.rect, time.perf_counter() - t, stats.get("seconds", 0.0)))
    pixels = _rect_pixels(fast.rect)
    st.policy.observe(time.perf_counter() - t, pixels)
    st.pixels_at_scale_1 = pixels / (fast.scale * fast.scale)
    st.fast = _Image(fast.key, rgba, vdepth, fast.win_small, args[5], False, fast.scale, fast.rect,
                     fast.box)
    return st.fast


def _forget_all():
    for st in _states.values():
        st.cancel_job()
    _states.clear()
    scene_shadows_viewport.forget()
    _depth_cache.clear()
    _scene_tex.clear()


@persistent
def _on_load_pre(*_args):
    """A file is being opened: its regions are new, drop every cached
    frame and refine in flight."""
    _forget_all()


def register():
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")
        if _profile.enabled:
            _profile_handles.extend([
                ("WINDOW", bpy.types.SpaceView3D.draw_handler_add(_profile.pre_view, (), "WINDOW", "PRE_VIEW")),
                ("WINDOW", bpy.types.SpaceView3D.draw_handler_add(_profile.post_pixel, (), "WINDOW", "POST_PIXEL"))])
    app_handlers.add(((bpy.app.handlers.load_pre, _on_load_pre),))


def unregister():
    global _handle, _shader, _batch, _refine_pending, _poll_registered, _refine_redraw
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
    while _profile_handles:
        region_type, h = _profile_handles.pop()
        bpy.types.SpaceView3D.draw_handler_remove(h, region_type)
    for fn in (_refine, _poll):
        if bpy.app.timers.is_registered(fn):
            bpy.app.timers.unregister(fn)
    _refine_pending = _poll_registered = _refine_redraw = False
    app_handlers.remove(((bpy.app.handlers.load_pre, _on_load_pre),))
    _forget_all()
    _shader = _batch = None
