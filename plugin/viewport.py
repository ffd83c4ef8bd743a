"""3D viewport: a POST_VIEW draw handler that composites the library's
premultiplied RGBA + depth into the view.

Per region and volume it
  1. reads the depth of the bound framebuffer (the scene's depth at
     POST_VIEW) and converts it to planar view distance, so the library's
     rays stop at geometry (a mesh inside the volume hides what is behind);
  2. re-renders only when an input changed: view, projection, size, the
     volume's properties, its matrix, the lights or the depth;
  3. renders at reduced resolution (and double step) while the view moves,
     and a timer asks for a full-resolution frame once it has settled;
  4. draws a full-screen quad with gl_FragDepth from the library's depth,
     depth test LESS_EQUAL and premultiplied blending (no depth writes).
     Where the volume has no hit the fragment gets the scene's own depth,
     so its colour (in front of that geometry, since the rays stopped
     there) always blends.
"""

import time
import zlib

import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from . import depth as _depth
from . import native, params, runtime, volume_space

_handle = None
_shader = None
_batch = None
_states = {}          # (region pointer, object name) -> _State
_refine_pending = False
last_error = ""


class _State:
    def __init__(self):
        self.view_key = None
        self.moved_at = -1e9
        self.key = None
        # GPUTextures must outlive the draw call that samples them.
        self.color = None
        self.depth = None
        self.used_at = 0.0


_VERT = "void main() { uv = pos * 0.5 + 0.5; gl_Position = vec4(pos, 0.0, 1.0); }"
_FRAG = ("void main() { fragColor = texture(color_tex, uv);"
         " gl_FragDepth = texture(depth_tex, uv).r; }")


def _get_shader():
    global _shader, _batch
    if _shader is None:
        iface = gpu.types.GPUStageInterfaceInfo("voxlight_iface")
        iface.smooth("VEC2", "uv")
        info = gpu.types.GPUShaderCreateInfo()
        info.vertex_in(0, "VEC2", "pos")
        info.vertex_out(iface)
        info.sampler(0, "FLOAT_2D", "color_tex")
        info.sampler(1, "FLOAT_2D", "depth_tex")
        info.fragment_out(0, "VEC4", "fragColor")
        info.vertex_source(_VERT)
        info.fragment_source(_FRAG)
        _shader = gpu.shader.create_from_info(info)
        _batch = batch_for_shader(_shader, "TRI_FAN",
                                  {"pos": ((-1, -1), (1, -1), (1, 1), (-1, 1))})
    return _shader, _batch


def _read_window_depth(width, height):
    try:
        fb = gpu.state.active_framebuffer_get()
        buf = fb.read_depth(0, 0, width, height)
    except Exception:  # no depth attachment: draw without occlusion input
        return None
    return np.asarray(buf, dtype=np.float32).reshape(height, width)


def _downsample(img, w, h):
    """Nearest sample at the centre of each low-resolution pixel."""
    H, W = img.shape[:2]
    if (W, H) == (w, h):
        return img
    ys = np.minimum(((np.arange(h) + 0.5) * H / h).astype(np.int64), H - 1)
    xs = np.minimum(((np.arange(w) + 0.5) * W / w).astype(np.int64), W - 1)
    return np.ascontiguousarray(img[ys][:, xs])


def _texture(arr, fmt):
    h, w = arr.shape[:2]
    a = np.ascontiguousarray(arr, np.float32).ravel()
    buf = gpu.types.Buffer("FLOAT", a.size, a)
    return gpu.types.GPUTexture((w, h), format=fmt, data=buf)


def _outside_frustum(model, dims, view, proj):
    """True when all 8 box corners lie beyond the same clip plane."""
    c = volume_space.world_corners(model, dims)
    clip = np.c_[c, np.ones(8)] @ (proj @ view).T
    w = clip[:, 3:4]
    return bool(np.any(np.all(clip[:, :3] > w, axis=0)) or
                np.any(np.all(clip[:, :3] < -w, axis=0)))


def _refine():
    global _refine_pending
    _refine_pending = False
    from .properties import tag_redraw
    tag_redraw()
    return None


def _schedule_refine(delay):
    global _refine_pending
    if not _refine_pending:
        _refine_pending = True
        bpy.app.timers.register(_refine, first_interval=max(delay, 0.02))


def _draw():
    global last_error
    ctx = bpy.context
    scene = ctx.scene
    if scene is None or not scene.voxlight.viewport_enabled:
        return
    region, rv3d, space = ctx.region, ctx.region_data, ctx.space_data
    if rv3d is None or region is None:
        return
    view_layer = ctx.view_layer
    objs = [o for o in view_layer.objects
            if o.type == "EMPTY" and o.voxlight.is_volume and o.visible_get(viewport=space)]
    if not objs:
        return
    s = scene.voxlight
    W, H = region.width, region.height
    view = np.array(rv3d.view_matrix, np.float64)
    proj = np.array(rv3d.window_matrix, np.float64)
    window_depth = _read_window_depth(W, H)
    depsgraph = ctx.evaluated_depsgraph_get()
    lights = params.scene_lights(scene, depsgraph)
    now = time.monotonic()
    view_key = (view.tobytes(), proj.tobytes(), W, H)
    shader, batch = _get_shader()

    for obj in objs:
        ob = obj.evaluated_get(depsgraph)
        model = params.model_matrix(ob)
        if _outside_frustum(model, tuple(ob.voxlight.dims), view, proj):
            continue
        st = _states.get((region.as_pointer(), obj.name))
        if st is None:
            st = _states[(region.as_pointer(), obj.name)] = _State()
        st.used_at = now
        if view_key != st.view_key:
            if st.view_key is not None:
                st.moved_at = now
            st.view_key = view_key
        moving = (now - st.moved_at) < s.settle_time
        frac = s.interactive_resolution if moving else s.viewport_resolution
        w, h = max(1, round(W * frac)), max(1, round(H * frac))
        win_small = _downsample(window_depth, w, h) if window_depth is not None else None
        key = (view_key, w, h, params.look_key(ob.voxlight, fast=moving), tuple(lights),
               model.tobytes(), ob.voxlight.filepath,
               zlib.crc32(win_small.tobytes()) if win_small is not None else None)
        if key != st.key:
            try:
                entry = runtime.get_entry(bpy.path.abspath(ob.voxlight.filepath), s.backend)
                scene_depth = (_depth.window_to_planar(win_small, proj)
                               if win_small is not None else None)
                p = params.build(ob, w, h, view, proj, scene_depth=scene_depth,
                                 lights=lights, fast=moving)
                rgba, vdepth = runtime.render(entry, p)
            except native.VoxlightError as e:
                if last_error != str(e):
                    print("Voxlight: viewport render failed: %s" % e)
                last_error = str(e)
                st.key, st.color, st.depth = key, None, None
                continue
            last_error = ""
            frag_depth = _depth.planar_to_window(vdepth, proj)
            if win_small is not None:
                frag_depth = np.where(np.isfinite(vdepth),
                                      np.minimum(frag_depth, win_small), win_small)
            st.color = _texture(rgba, "RGBA32F")
            st.depth = _texture(frag_depth, "R32F")
            st.key = key
        if moving:
            _schedule_refine(s.settle_time - (now - st.moved_at) + 0.01)
        if st.color is None:
            continue
        shader.bind()
        shader.uniform_sampler("color_tex", st.color)
        shader.uniform_sampler("depth_tex", st.depth)
        gpu.state.depth_test_set("LESS_EQUAL")
        # No depth writes: Blender may redraw only the overlays and keep the
        # scene's depth buffer, and the next frame's depth read must not see
        # the volume's own depth (that feedback made rays stop at stale hits).
        gpu.state.depth_mask_set(False)
        gpu.state.blend_set("ALPHA_PREMULT")
        batch.draw(shader)
        gpu.state.blend_set("NONE")
        gpu.state.depth_test_set("NONE")

    if len(_states) > 64:  # forget regions and objects not drawn for a minute
        for k in [k for k, v in _states.items() if now - v.used_at > 60.0]:
            del _states[k]


def register():
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")


def unregister():
    global _handle, _shader, _batch, _refine_pending
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
    if bpy.app.timers.is_registered(_refine):
        bpy.app.timers.unregister(_refine)
    _refine_pending = False
    _states.clear()
    _shader = _batch = None
