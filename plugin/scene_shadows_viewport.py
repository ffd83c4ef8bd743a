"""The volume's shadow on the meshes in the 3D viewport: a
multiply layer drawn by the viewport's draw handler before the volumes
(as black with coverage 1 - T, which multiplies the scene under it by T).

From the scene depth the handler already read, at a quarter of the view's
resolution (the shadow is soft; the texture is filtered up), the library
gives each light's transmittance T_l from every visible scene point through
the volumes that cast shadows (vxl_scene_transmittance, the product over
volumes). The layer is

    1 - sum_l w_l (1 - T_l)

with w_l light l's share of the point's light, from the point's place and
normal (normals from the depth's neighbours), the lights and the world's
light (core/light_shares.py, as EEVEE's F12): each light's shadow darkens
only its own share, and the world's light stays, so a shadow is as dark as
the light the volume takes away and keeps its penumbra where the volume is
translucent. Approximate, as a preview: Blender's viewport gives no
per-light passes; specular light is shared like the diffuse, and a mesh's
own shadow is not known. A depth pixel is one sample at the quarter
resolution, so edges of meshes in front of a shadow are soft.

Cost: the transmittance is computed on the renderer's background worker
(runtime.Worker, a Job with `run`), only once the view, the lights, the
volumes and the scene depth have been still for Refine After, and reused
while they stay so; while anything moves, the layer is not drawn (a shadow
from another view would be in the wrong place).
"""

import hashlib
import time

import bpy
import gpu
import numpy as np

from . import gpu_quad, params, scene_shadows
from .core import depth as _depth
from .core import facing, light_shares, native, runtime

SCALE = 0.25
OWNER = "scene shadows"

_states = {}      # region pointer -> _State
_shader = None
_batch = None
_timer_on = False


class _State:
    def __init__(self):
        self.key = None
        self.changed_at = -1e9
        self.job = None
        self.job_key = None
        self.shown_key = None
        self.texture = None


# Black at coverage 1 - T, premultiplied: the handler draws into the
# buffer Blender lays over its scene (result = ours + scene * (1 - alpha)),
# so the scene is multiplied by T (a MULTIPLY blend there would only
# multiply that buffer, not the meshes), and the volumes drawn after it
# cover it as they cover the scene.
_FRAG = "void main() { fragColor = vec4(0.0, 0.0, 0.0, 1.0 - texture(t_tex, uv).r); }"


def _get_shader():
    global _shader, _batch
    if _shader is None:
        _shader, _batch = gpu_quad.quad_shader("voxlight_shadow", ("t_tex",), _FRAG)
    return _shader, _batch


def _combine(entries_params, lights, ambient, view, proj, planar, stop):
    """Worker side: the layer 1 - F from (entry, params) per casting volume."""
    trans = {}
    for entry, p in entries_params:
        for i in range(len(lights)):
            if stop():
                return None
            t = entry.renderer.scene_transmittance(p, i)
            trans[i] = t if i not in trans else trans[i] * t
    positions = facing.pixel_positions(planar, view, proj)
    normals = facing.depth_normals(positions, view)
    amount = light_shares.shadow_amount(
        light_shares.shares(lights, positions, normals, ambient), trans)
    return None if amount is None else 1.0 - amount


def draw_layer(scene, depsgraph, objs, window_depth, W, H, view, proj, lights, region_ptr):
    """Draw the multiply layer of the volumes in `objs` (the viewport's
    visible volumes, original objects) over what Blender drew; queue its
    computation when the inputs changed and have settled."""
    st = _states.setdefault(region_ptr, _State())
    casters = [o.evaluated_get(depsgraph) for o in objs if o.voxlight.cast_shadows]
    if not casters or not lights or window_depth is None:
        st.key = None
        return
    w, h = max(1, round(W * SCALE)), max(1, round(H * SCALE))
    digest = hashlib.blake2b(digest_size=16)
    ambient = scene_shadows.world_light(scene)
    digest.update(repr((window_depth.crc, w, h, [repr(l) for l in lights], ambient)).encode())
    digest.update(np.asarray(view, np.float64).tobytes() + np.asarray(proj, np.float64).tobytes())
    built = []
    for ob in casters:
        try:
            entry = runtime.entry_for(bpy.path.abspath(ob.voxlight.filepath), ob.voxlight,
                                      scene.frame_current, **runtime.options_of(scene.voxlight))
        except native.VoxlightError:
            continue
        built.append((ob, entry))
        digest.update(repr((entry.identity, params.look_key(ob.voxlight))).encode())
        digest.update(params.model_matrix(ob).tobytes())
    if not built:
        return
    key = digest.digest()
    now = time.monotonic()
    if key != st.key:
        st.key, st.changed_at = key, now
    settle = scene.voxlight.settle_time
    job = st.job
    if job is not None and job.done:
        if job.result is not None and st.job_key == key:
            st.texture = _texture(job.result)
            st.shown_key = key
        st.job = None
    if st.shown_key != key and st.job is None:
        left = settle - (now - st.changed_at)
        if left > 0:
            _wake(left + 0.01)
        else:
            win = _depth.downsample(window_depth.pixels, w, h)
            planar = _depth.window_to_planar(win, proj)
            pairs = [(entry, params.build(ob, w, h, view, proj, scene_depth=planar, lights=lights,
                                          channels=False))
                     for ob, entry in built]
            job = runtime.Job((region_ptr, OWNER), key, None)
            job.run = lambda stop, pairs=pairs, lights=list(lights), args=(
                ambient, np.array(view, np.float64), np.array(proj, np.float64), planar): \
                _combine(pairs, lights, *args, stop)
            st.job, st.job_key = built[0][1].worker.submit(job), key
            _wake(0.05)
    if st.shown_key == key and st.texture is not None:
        _draw(st.texture)


def _texture(t):
    h, w = t.shape
    a = np.ascontiguousarray(t, np.float32).ravel()
    return gpu.types.GPUTexture((w, h), format="R32F", data=gpu.types.Buffer("FLOAT", a.size, a))


def _draw(texture):
    shader, batch = _get_shader()
    shader.bind()
    shader.uniform_sampler("t_tex", texture)
    gpu.state.depth_test_set("NONE")
    gpu.state.depth_mask_set(False)
    gpu.state.blend_set("ALPHA_PREMULT")
    batch.draw(shader)
    gpu.state.blend_set("NONE")


def _wake(delay):
    """Redraw the 3D views in `delay` s (settled inputs, a finished job)."""
    global _timer_on
    if not _timer_on:
        _timer_on = True
        bpy.app.timers.register(_tick, first_interval=max(delay, 0.02))


def _tick():
    """Waits for the jobs in flight, then redraws once (which shows their
    result, or queues the job of inputs that have settled)."""
    global _timer_on
    if any(st.job is not None and not st.job.done for st in _states.values()):
        return 0.05
    _timer_on = False
    from .properties import tag_redraw
    tag_redraw()
    return None


def forget():
    global _timer_on
    for st in _states.values():
        if st.job is not None and not st.job.done:
            st.job.cancelled = True
    _states.clear()
    if _timer_on and bpy.app.timers.is_registered(_tick):
        bpy.app.timers.unregister(_tick)
    _timer_on = False
