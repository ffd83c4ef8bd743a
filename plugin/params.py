"""Builds library render parameters from a volume object's properties, a
camera and the scene's lights. Shared by the viewport, F12 and the
scripting API so all three render the same thing."""

import numpy as np

from .core import channel_plan, lighting
from .core import lights as _lights
from .core import native
from . import channel_props, cutaway
from . import label_props
from . import mode_start
from . import tf as _tf
from . import world_light


def model_matrix(obj):
    """voxel -> world for the object as it is now (follows the object)."""
    v2l = np.array(obj.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
    return np.array(obj.matrix_world, np.float64) @ v2l


def look_kwargs(props, fast=False, dragging=False, channels=True):
    """The properties that decide how the volume looks, as make_params
    keyword arguments. `fast` doubles the step for interactive frames;
    `dragging` (a light is being dragged) coarsens the illumination volume;
    `channels` False leaves a multi-channel volume's channels out (its
    scalar alone: what classifying the scalar wants)."""
    # The ColorRamp and the window are the transfer function. Volumes not
    # converted yet (tf_version 0: appended from an old file) keep the old
    # switches: library preset unless Use ColorRamp, preset window unless
    # Custom Window.
    legacy = props.tf_version < _tf.TF_SINGLE_EDITOR
    window = None
    if props.use_window or not legacy:
        window = channel_plan.ordered_window(props.window_low, props.window_high)
    step = props.step * (2.0 if fast else 1.0)
    return dict(
        # Blender's colours (the ramp, lights, the World, MatCaps) are
        # scene-linear, and so is the image F12 composites; the viewport
        # encodes it for display (viewport.py).
        color_space="linear",
        color_source=props.color_source,
        filter=props.filter,
        sample_distance=props.sample_distance,
        reuse_gradients=props.reuse_gradients,
        gradient_16f=props.gradient_16f,
        step=step,
        jitter=props.jitter,
        preset=props.preset,
        window=window,
        opacity_scale=props.opacity_scale,
        shading=props.shading,
        material=(props.ambient, props.diffuse, props.specular, props.shininess),
        # Projections scale the ramp's opacity to full (mode_start.look_table).
        tf_rgba=mode_start.look_table(
            props, _tf.table(props) if props.use_color_ramp or not legacy else None),
        classify=props.classify,
        gradient_opacity=props.gradient_opacity,
        gradient_ref=props.gradient_ref,
        gradient_exp=props.gradient_exp,
        iso_value=props.iso_value,
        minip_floor=props.minip_floor if props.use_minip_floor else None,
        iso_thickness=props.iso_thickness,
        **lighting.look_kwargs(props, dragging),
        **cutaway.look_kwargs(props),  # mode, MatCap, cutaway
        **label_props.look_kwargs(props),  # label map colours and visibility
        # a multi-channel volume's channels, or {} (its scalar alone)
        **(channel_props.look_kwargs(props) if channels else {}),
    )


def environment_for(look, environment):
    """make_params' environment for a frame with these look_kwargs: the
    World's light does not light a multi-channel volume's channels (the
    library lights them with the lights alone), so a frame that draws them
    has none (the Channels panel says so)."""
    return None if look.get("channels") else environment


def _key_of(v):
    """A hashable value for a look_kwargs value: arrays by their bytes (a
    repr would summarise a long table), lists and dicts item by item (the
    channel styles)."""
    if hasattr(v, "tobytes"):
        return v.tobytes()
    if isinstance(v, dict):
        return tuple(sorted((k, _key_of(x)) for k, x in v.items()))
    if isinstance(v, (list, tuple)):
        return tuple(_key_of(x) for x in v)
    return repr(v)


def look_key(props, fast=False):
    """Hashable summary of look_kwargs, for the viewport's change test."""
    return tuple(sorted((k, _key_of(v)) for k, v in look_kwargs(props, fast).items()))


class _Lights(list):
    """Scene lights, marked while one of them is being dragged, with the
    World's light that goes with them (world_light.scene_environment; None:
    none): make_params' `environment`."""
    dragged = False
    environment = None


def scene_lights(scene, depsgraph, for_render=False):
    out = _Lights(_lights.collect(depsgraph, for_render) if scene.voxlight.use_scene_lights else [])
    out.environment = world_light.scene_environment(scene)
    return out


_light_watch = lighting.LightWatch()


def while_lights_move(lights, now, settle_time):
    """Viewport: (lights, seconds until they settle, or None when they are
    still). Frames built with lights that are being dragged get a coarse
    illumination volume (lighting.DRAG_ILLUMINATION_SIZE); the viewport
    redraws once they settle, and the full one is built then."""
    left = _light_watch.update(lights, now, settle_time)
    out = _Lights(lights)
    out.dragged = left is not None
    out.environment = getattr(lights, "environment", None)
    return out, left


def scalar_only(kw):
    """make_params keyword arguments without a multi-channel volume's
    channels: the shadow a volume casts on the scene is its scalar's (the
    library's scene transmittance marches one scalar)."""
    return {k: v for k, v in kw.items() if k not in ("channels", "channel_blend")}


def build(obj, width, height, view, proj, scene_depth=None, lights=(), fast=False, lib=None,
          scene_shadows=None, overlays=None, channels=True):
    """scene_shadows: the occluders (vertices, triangles, key) that shadow
    the volume, or None. overlays: make_params' overlay dicts
    (overlay_frames.prepare), or None. channels False: the scalar alone
    (look_kwargs)."""
    kw = look_kwargs(obj.voxlight, fast, dragging=getattr(lights, "dragged", False),
                     channels=channels)
    kw["environment"] = environment_for(kw, getattr(lights, "environment", None))
    if overlays:
        kw["overlays"] = overlays
    if scene_shadows is not None:
        kw["scene_shadows"] = scene_shadows
    return native.make_params(width=width, height=height, view=view, proj=proj,
                              model=model_matrix(obj), scene_depth=scene_depth,
                              lights=lights, lib=lib, **kw)
