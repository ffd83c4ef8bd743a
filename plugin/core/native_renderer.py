"""libvoxlight renderers: the render params built from the add-on's
settings (make_params), and the Renderer, whole-frame or tiled.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes
import os
import time

import numpy as np

from .native_abi import (CHANNEL_BLENDS, COLOR_SOURCES, COLOR_SPACES, LABEL_BOUNDARIES, Environment, LabelEntry, LabelStyle, LibraryObject, OverlayStyle, LightShape, MAX_LIGHTS, RenderParams, RenderStats,
                         ChannelStyle, RendererInfo, RendererOptions, SceneShadows, VoxlightError, matrix_from_cm, _fptr,
                         _matrix_cm, _sized)
from .native_cutaway import cutaway_struct, matcap_struct, slice_struct
from .native_channels import channel_array
from .native_overlays import overlay_array
from .native_library import load_library
from .native_tiles import _empty_stats, _merge_stats, tile_params


# ----------------------------------------------------------- render params

def _light_shapes(lights):
    """The LightShape array of `lights` (entries (position4, color3,
    intensity[, shape]) with shape = (spot_direction3, spot_angle,
    spot_blend, size)), or None when every light is plain."""
    shapes = [l[3] if len(l) > 3 and l[3] is not None else None for l in lights]
    if all(s is None or not any(s[0]) and not any(s[1:]) for s in shapes):
        return None
    arr = (LightShape * len(lights))()
    for dst, s in zip(arr, shapes):
        dst.struct_size = ctypes.sizeof(LightShape)
        if s is not None:
            dst.spot_direction[:] = [float(v) for v in s[0]]
            dst.spot_angle, dst.spot_blend, dst.size = float(s[1]), float(s[2]), float(s[3])
    return arr


def make_params(width=0, height=0, view=None, proj=None, model=None, scene_depth=None,
                filter="central", sample_distance=1.0, reuse_gradients=False,
                gradient_16f=False, step=0.5, jitter=True, jitter_seed=0,
                preset="auto", window=None, opacity_scale=1.0, shading=True,
                material=None, lights=(), azimuth=0.0, elevation=0.0,
                early_termination=0.0, depth_threshold=0.0, no_skip=False,
                tf_rgba=None, classify="post", gradient_opacity="off", gradient_ref=0.0,
                gradient_exp=0.0, iso_value=0.0, iso_thickness=0.0, preint_size=0,
                shading_model=0, ambient_occlusion=0.0, occlusion_strength=0.0, anisotropy=0.0,
                illumination_size=0, mode="dvr", matcap=None, matcap_key=0, cutaway=None,
                scene_shadows=None, labels=None, overlays=None, minip_floor=None, environment=None,
                color_space="display", color_source="auto", path_samples=0, path_sample_offset=0,
                path_bounces=0, path_seed=0, channels=None, channel_blend="add", lib=None):
    """Build a RenderParams. Keyword names are the Blender panel's. `lights`
    is a sequence of (position4, color3, intensity); `material` is
    (ambient, diffuse, specular, shininess) or None for the defaults;
    `window` is (low, high) or None for the preset's default. `tf_rgba` is
    an (n, 4) straight-RGBA table (alpha = opacity per voxel of path) that
    replaces the preset; `window` maps its [0, 1] onto data values.
    `classify` and `gradient_opacity` are the library's names of their modes
    (Library.names("classify"), ...) or their VXL_* numbers, and so is
    `shading_model`. A light may carry a fourth item, its shape
    (spot_direction3, spot_angle, spot_blend, size, as vxl_light_shape);
    the shapes' array lives as long as the params.
    `mode` is a render mode's name (Library.names("mode")) or
    VXL_MODE_*; `matcap` an (h, w, 3|4) linear image (row 0 = bottom) with
    `matcap_key` its name, or None for the material and lights; `cutaway`
    a dict as native_cutaway.cutaway_struct takes it, or None. Their structs
    live as long as the params, and their contents are in _keep.
    `scene_shadows` is (vertices (n, 3) world, triangles (m, 3)
    vertex indices, key[, shadow_map_size]), the scene's opaque meshes that
    shadow the volume; key 0 lets the library hash the arrays, a nonzero key
    names this version of them (the same key: no shadow map is rebuilt).
    `overlays` is a list of dicts or OverlayStyles
    (native_overlays.py), each naming a slot filled by Renderer.set_overlay.
    `environment` is the World's light, (rgb (h, w, 3) linear, row 0 at the
    bottom; strength; rotation_deg about world +Z) as world_light.Environment
    gives it, or None. `color_space` is "display" (sRGB-encoded colours
    in and out, as the CLI's PNGs) or "linear" (scene-linear, Blender's and
    Cycles' colours: the add-on's), or VXL_COLOR_SPACE_*. `color_source`
    says where a colour volume's colour comes from: "auto" (its own RGB;
    the table's for a grey volume), "data" or "tf" (COLOR_SOURCES).
    `path_samples`, `path_sample_offset`, `path_bounces` and `path_seed`
    are the `path` shading model's (vxl_render_params; 0: its defaults).
    `channels` lists the channels of a multi-channel volume to draw in one
    march, dicts as native_channels.py takes them (None: the scalar alone);
    `channel_blend` is "add" or "max" (CHANNEL_BLENDS) or
    VXL_CHANNEL_BLEND_*."""
    lib = lib or load_library()
    p = _sized(RenderParams)
    p.width, p.height = int(width), int(height)
    if view is not None or proj is not None:
        if view is None or proj is None:
            raise ValueError("view and proj must be given together")
        p.has_camera = 1
        p.view = _matrix_cm(view)
        p.proj = _matrix_cm(proj)
    p.azimuth_deg, p.elevation_deg = azimuth, elevation
    if model is not None:
        p.has_model = 1
        p.model = _matrix_cm(model)
    p._keep = []
    if scene_depth is not None:
        w, h = p.width or 512, p.height or 512
        d = np.ascontiguousarray(scene_depth, dtype=np.float32)
        if d.size != w * h:
            raise ValueError("scene_depth has %d values, image has %dx%d" % (d.size, w, h))
        p._keep.append(d)
        p.scene_depth = _fptr(d)
        p._scene_depth = d
    p.filter = filter if isinstance(filter, int) else lib.filter_index(filter)
    p.sample_distance = sample_distance
    p.reuse_gradients = 1 if reuse_gradients else 0
    p.gradient_store = 1 if gradient_16f else 0
    p.step = step
    p.jitter_off = 0 if jitter else 1
    p.jitter_seed = jitter_seed
    p.preset = preset if isinstance(preset, int) else lib.preset_index(preset)
    if window is not None:
        p.has_window = 1
        p.window_low, p.window_high = float(window[0]), float(window[1])
    if tf_rgba is not None:
        tf = np.ascontiguousarray(tf_rgba, dtype=np.float32).reshape(-1, 4)
        if len(tf) < 2:
            raise ValueError("tf_rgba needs at least 2 entries")
        p._keep.append(tf)
        p._tf = tf
        p.tf_size = len(tf)
        p.tf_rgba = _fptr(tf)
    p.color_space = color_space if isinstance(color_space, int) else COLOR_SPACES.index(color_space)
    p.color_source = color_source if isinstance(color_source, int) else COLOR_SOURCES.index(color_source)
    p.path_samples, p.path_sample_offset = int(path_samples), int(path_sample_offset)
    p.path_bounces, p.path_seed = int(path_bounces), int(path_seed) & 0xFFFFFFFF
    p.classify = classify if isinstance(classify, int) else lib.index("classify", classify)
    p.gradient_opacity = (gradient_opacity if isinstance(gradient_opacity, int)
                          else lib.index("gradient_opacity", gradient_opacity))
    p.gradient_ref = gradient_ref
    p.gradient_exp = gradient_exp
    p.iso_value = iso_value
    p.iso_thickness = iso_thickness
    if minip_floor is not None:  # MinIP keeps the smallest sample at or above it
        p.minip_floor_on = 1
        p.minip_floor = float(minip_floor)
    p.preint_size = preint_size
    p.opacity_scale = opacity_scale
    p.shading_off = 0 if shading else 1
    if material is not None:
        p.has_material = 1
        p.ambient, p.diffuse, p.specular, p.shininess = [float(v) for v in material]
    lights = list(lights)
    if len(lights) > MAX_LIGHTS:
        raise ValueError("at most %d lights" % MAX_LIGHTS)
    p.light_count = len(lights)
    for i, light in enumerate(lights):
        pos, col, inten = light[:3]
        p.lights[i].position[:] = [float(v) for v in pos]
        p.lights[i].color[:] = [float(v) for v in col]
        p.lights[i].intensity = float(inten)
    shapes = _light_shapes(lights)
    if shapes is not None:
        # The digest hashes _keep; this view also keeps the array alive.
        p._shapes = np.frombuffer(shapes, np.uint8)
        p._keep.append(p._shapes)
        p.light_shapes = ctypes.cast(shapes, ctypes.POINTER(LightShape))
    p.shading_model = (shading_model if isinstance(shading_model, int)
                       else lib.index("shading_model", shading_model))
    p.ambient_occlusion = ambient_occlusion
    p.occlusion_strength = occlusion_strength
    p.anisotropy = anisotropy
    p.illumination_size = int(illumination_size)
    p.early_termination = early_termination
    p.depth_threshold = depth_threshold
    p.no_skip = 1 if no_skip else 0
    _mode_and_cutaway_inputs(p, lib, mode, matcap, matcap_key, cutaway)
    if labels is not None:
        _set_labels(p, lib, *labels)
    if overlays:  # the struct array and its tables live as long as p
        p._overlays, p._overlay_tables, digest = overlay_array(overlays, lib)
        p._keep.extend(digest)
        p.overlay_count = len(overlays)
        p.overlays = ctypes.cast(p._overlays, ctypes.POINTER(OverlayStyle))
    if channels:  # the struct array and its tables live as long as p
        p._channels, p._channel_tables, digest = channel_array(channels, lib)
        p._keep.extend(digest)
        p.channel_count = len(channels)
        p.channels = ctypes.cast(p._channels, ctypes.POINTER(ChannelStyle))
    p.channel_blend = (channel_blend if isinstance(channel_blend, int)
                       else CHANNEL_BLENDS.index(channel_blend))
    if scene_shadows is not None:
        _set_scene_shadows(p, *scene_shadows)
    if environment is not None:
        _set_environment(p, *environment)
    return p


def _set_environment(p, rgb, strength, rotation_deg):
    """params.environment from an (h, w, 3) map; the map and the struct live
    as long as p, and _keep holds them for the digest."""
    m = np.ascontiguousarray(rgb, dtype=np.float32)
    if m.ndim != 3 or m.shape[2] != 3:
        raise ValueError("environment map must be (height, width, 3), not %r" % (m.shape,))
    e = _sized(Environment)
    e.height, e.width = m.shape[:2]
    e.rgb = _fptr(m)
    e.strength = float(strength)
    e.rotation_deg = float(rotation_deg)
    p._environment = e
    p._env_map = m
    p._keep.extend((m, np.array([e.strength, e.rotation_deg], np.float32)))
    p.environment = ctypes.pointer(e)


def _set_scene_shadows(p, vertices, triangles, key=0, shadow_map_size=0):
    """params.scene_shadows from numpy-able arrays; the arrays and the
    struct live as long as p. The digest (native_tiles.params_digest) sees
    the key, or the arrays themselves when the key is 0."""
    v = np.ascontiguousarray(vertices, dtype=np.float32).reshape(-1, 3)
    t = np.ascontiguousarray(triangles, dtype=np.uint32).reshape(-1, 3)
    s = _sized(SceneShadows)
    s.occluder_vertex_count, s.occluder_triangle_count = len(v), len(t)
    s.occluder_vertices = _fptr(v)
    s.occluder_indices = t.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))
    s.shadow_map_size = int(shadow_map_size)
    s.occluder_key = int(key) & 0xFFFFFFFFFFFFFFFF
    p._scene_shadows = s
    p._occluders = (v, t)
    p._keep.append(np.array([s.occluder_key, len(v), len(t), s.shadow_map_size], np.uint64))
    if not s.occluder_key:
        p._keep.extend((v, t))
    p.scene_shadows = ctypes.pointer(s)


def _set_labels(p, lib, mode, entries, boundary="smooth"):
    """params.labels (each label's colour, visibility and material) from
    `mode` (a label mode's name or number), `boundary` ("smooth" or
    "voxels", or VXL_LABEL_BOUNDARY_*'s number) and entries, a sequence of (id, rgba, visible[, material]) where
    material, when given and not None, is the label's own (ambient,
    diffuse, specular, shininess); the struct and its entries live as long
    as p, and _keep holds their bytes for the digest."""
    entries = list(entries)
    arr = (LabelEntry * max(1, len(entries)))()
    for e, entry in zip(arr, entries):
        ident, rgba, visible = entry[:3]
        material = entry[3] if len(entry) > 3 else None
        e.struct_size = ctypes.sizeof(LabelEntry)
        e.id = int(ident)
        rgba = tuple(float(c) for c in rgba)
        e.color[:] = rgba if len(rgba) == 4 else rgba + (1.0,)
        e.visible = 1 if visible else 0
        if material is not None:
            e.has_material = 1
            e.material[:] = tuple(float(m) for m in material)
    s = _sized(LabelStyle)
    s.mode = mode if isinstance(mode, int) else lib.index("label_mode", mode)
    s.entry_count = len(entries)
    s.entries = ctypes.cast(arr, ctypes.POINTER(LabelEntry))
    if isinstance(boundary, str):
        if boundary not in LABEL_BOUNDARIES:
            raise ValueError("label boundary %r: one of %s" % (boundary, ", ".join(LABEL_BOUNDARIES)))
        boundary = LABEL_BOUNDARIES.index(boundary)
    s.boundary = int(boundary)
    p._labels, p._label_entries = s, arr
    # the style's bytes but its pointer (which changes with every call)
    p._keep.append(np.frombuffer(bytes(s)[:16] + bytes(s)[LabelStyle.boundary.offset:] +
                                 bytes(arr)[:ctypes.sizeof(LabelEntry) * len(entries)], np.uint8))
    p.labels = ctypes.pointer(s)


def _mode_and_cutaway_inputs(p, lib, mode, matcap, matcap_key, cutaway):
    """The render mode, MatCap and cutaway of make_params."""
    p.mode = mode if isinstance(mode, int) else lib.index("mode", mode)
    if cutaway is not None:
        p._cutaway, arrays = cutaway_struct(cutaway)
        p._keep.extend(arrays)
        p.cutaway = ctypes.pointer(p._cutaway)
    if matcap is not None:
        p._matcap, arrays = matcap_struct(matcap, matcap_key)
        p._keep.extend(arrays)
        p.matcap = ctypes.pointer(p._matcap)


# -------------------------------------------------------------- renderer

class Renderer(LibraryObject):
    """One library renderer: its own GL context on its own thread, holding
    one volume. Safe to call from any Python thread."""

    def __init__(self, backend="auto", memory_budget=0, shader_dir=None, lib=None,
                 storage="auto", page_brick=0):
        self.lib = lib or load_library()
        opt = _sized(RendererOptions)
        opt.backend = self.lib.index("backend", backend) if isinstance(backend, str) else int(backend)
        opt.memory_budget_bytes = memory_budget
        opt.storage = self.lib.index("storage", storage) if isinstance(storage, str) else int(storage)
        opt.page_brick = page_brick
        opt.shader_dir = os.fsencode(shader_dir) if shader_dir else None
        h = ctypes.c_void_p()
        self.lib.check(self.lib.cdll.vxl_renderer_create(ctypes.byref(opt), ctypes.byref(h)),
                       what="renderer")
        self._handle = h
        self.volume_info = None
        # Called with no arguments after every vxl_render (counts library calls).
        self.on_render = None

    @property
    def handle(self):
        if not self._handle:
            raise VoxlightError("renderer is closed")
        return self._handle

    def _check(self, code, what=""):
        self.lib.check(code, self._handle, what)

    def info(self):
        i = _sized(RendererInfo)
        self._check(self.lib.cdll.vxl_renderer_get_info(self.handle, ctypes.byref(i)))
        return {"backend": i.backend, "backend_name": i.backend_name.decode(),
                "gl_renderer": i.gl_renderer.decode(), "gl_version": i.gl_version.decode(),
                "max_3d_texture_size": i.max_3d_texture_size}

    def set_labels(self, volume):
        """The label volume: a Volume of integer ids, or None to remove it."""
        self._check(self.lib.cdll.vxl_renderer_set_labels(self.handle, volume.handle if volume is not None else None),
                    "set labels")

    def set_overlay(self, slot, volume):
        """Overlay slot `slot` (< MAX_OVERLAYS): a Volume in any
        grid (its affine places it), or None to empty the slot."""
        self._check(self.lib.cdll.vxl_renderer_set_overlay(self.handle, int(slot),
                                                           volume.handle if volume is not None else None),
                    "set overlay %d" % slot)

    def label_uploads(self):
        """(label volumes, label tables) uploaded so far (voxlight_dev.h)."""
        v, t = ctypes.c_uint64(), ctypes.c_uint64()
        self._check(self.lib.cdll.vxl_renderer_label_uploads(self.handle, ctypes.byref(v), ctypes.byref(t)))
        return v.value, t.value

    def set_volume(self, volume):
        self._check(self.lib.cdll.vxl_renderer_set_volume(self.handle, volume.handle),
                    "set volume")
        self.volume_info = dict(volume.info)

    def render(self, params=None, want_depth=True, **kwargs):
        """Render; returns (rgba[h, w, 4], depth[h, w] or None), float32,
        row 0 = bottom, premultiplied RGBA."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        w, h = params.width or 512, params.height or 512
        rgba = np.empty((h, w, 4), np.float32)
        depth = np.empty((h, w), np.float32) if want_depth else None
        self._check(self.lib.cdll.vxl_render(self.handle, ctypes.byref(params), _fptr(rgba),
                                             _fptr(depth) if want_depth else None), "render")
        if self.on_render is not None:
            self.on_render()
        return rgba, depth

    def scene_transmittance(self, params, light=0):
        """The volume's shadow on the scene: for every pixel of
        params' scene_depth, the transmittance from that scene point to
        light `light` (an index into params' lights) through the volume;
        (h, w) float32, row 0 = bottom, 1 where the path misses the volume
        or there is no geometry. Multiply the light's direct pass by it."""
        w, h = params.width or 512, params.height or 512
        out = np.empty((h, w), np.float32)
        self._check(self.lib.cdll.vxl_scene_transmittance(self.handle, ctypes.byref(params),
                                                          int(light), _fptr(out)),
                    "scene transmittance")
        return out

    def stats(self):
        """What the last render did (vxl_renderer_get_stats) as a dict."""
        st = _sized(RenderStats)
        self._check(self.lib.cdll.vxl_renderer_get_stats(self.handle, ctypes.byref(st)), "stats")
        d = {k: getattr(st, k) for k, _t in RenderStats._fields_ if k != "struct_size"}
        d["storage_name"] = self.lib.name("storage", d["storage"]) or "?"
        return d

    def render_tiled(self, params, rect=None, rows=None, target_seconds=0.05,
                     should_stop=None):
        """Render the image `params` describes as horizontal bands of the
        pixel rectangle `rect` = (x0, y0, x1, y1) (default: the whole
        image); pixels outside it are empty (alpha 0, depth +inf), which is
        exact when rect holds the volume's screen footprint.

        Each band is one library call, sized to take about target_seconds
        (or `rows` rows), and should_stop() is asked before every band: a
        caller on another thread abandons a stale frame within one band,
        and the renderer (whose calls serialize) is free again. Returns
        (rgba, depth, stats), or None when stopped. Equals render() up to
        float rounding of the narrowed projections (the jitter pattern is
        the same)."""
        W, H = params.width or 512, params.height or 512
        rgba = np.zeros((H, W, 4), np.float32)
        depth = np.full((H, W), np.inf, np.float32)
        acc = _empty_stats()
        x0, y0, x1, y1 = rect if rect is not None else (0, 0, W, H)
        x0, y0, x1, y1 = max(0, x0), max(0, y0), min(W, x1), min(H, y1)
        if x1 <= x0 or y1 <= y0:
            return rgba, depth, acc
        n = int(rows) if rows else max(1, 16384 // (x1 - x0))  # first band ~16k pixels
        y = y0
        t_start = time.perf_counter()
        while y < y1:
            if should_stop is not None and should_stop():
                return None
            n = max(1, min(n, y1 - y))
            tp = tile_params(params, x0, y, x1, y + n)
            t = time.perf_counter()
            c, d = self.render(tp)
            dt = time.perf_counter() - t
            rgba[y:y + n, x0:x1] = c
            depth[y:y + n, x0:x1] = d
            _merge_stats(acc, self.stats())
            acc["calls"] += 1
            y += n
            if not rows:  # aim at target_seconds, growing at most 2x per band
                n = int(max(1, min(2 * n, y1 - y0, target_seconds * n / max(dt, 1e-4))))
        acc["seconds"] = time.perf_counter() - t_start
        return rgba, depth, acc

    def default_camera(self, params=None, **kwargs):
        """(view, proj) as numpy 4x4 math matrices."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        view = (ctypes.c_float * 16)()
        proj = (ctypes.c_float * 16)()
        self._check(self.lib.cdll.vxl_default_camera(self.handle, ctypes.byref(params),
                                                     view, proj), "default camera")
        return matrix_from_cm(view), matrix_from_cm(proj)

    def probe_gradients(self, points, params=None, **kwargs):
        """Gradient of the selected filter at voxel-space points (n, 3)."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        pts = np.ascontiguousarray(points, dtype=np.float32).reshape(-1, 3)
        out = np.empty_like(pts)
        self._check(self.lib.cdll.vxl_probe_gradients(self.handle, ctypes.byref(params),
                                                      _fptr(pts), len(pts), _fptr(out)),
                    "probe gradients")
        return out

    def render_slice(self, params, plane_to_world, interpolation="linear"):
        """The volume resampled on a plane (vxl_render_slice): plane_to_world
        is a 4x4 math matrix whose square [-1, 1]^2 at z = 0 is the slice
        (a Blender plane's matrix_world); params gives the size, the
        volume's placement (model), the window and the colour map.
        interpolation: "nearest", "linear", "cubic" or VXL_INTERP_*.
        Returns rgba[h, w, 4] float32, row 0 = bottom: the colour map's
        colour with alpha 1 inside the volume's box, 0 outside."""
        interp = (interpolation if isinstance(interpolation, int)
                  else self.lib.index("interpolation", interpolation))
        s = slice_struct(plane_to_world, interp)
        w, h = params.width or 512, params.height or 512
        rgba = np.empty((h, w, 4), np.float32)
        self._check(self.lib.cdll.vxl_render_slice(self.handle, ctypes.byref(params),
                                                   ctypes.byref(s), _fptr(rgba)), "slice")
        return rgba

    def close(self):
        if self._handle:
            self.lib.cdll.vxl_renderer_destroy(self._handle)
            self._handle = None
