"""The scene's World -> the library's environment light (vxl_environment).
No bpy: the World, its nodes and its image are read by attribute only, so
the tests (tests/python/test_world_light.py) pass stand-ins.

What is read (documented in README.md):
  * No node tree (use_nodes off): World.color, strength 1.
  * The active World Output's Surface from a Background node: its Strength,
    and its Color, either as set (a uniform colour, a 1x1 map) or from an
    Environment Texture node's image (equirectangular; a mirror ball gives
    the image's mean colour, uniform). A Mapping node feeding the texture's
    Vector gives the rotation: its Z rotation in degrees, negated for the
    Texture vector type (the inverse transform). Anything else in between
    (a colour ramp, a mix) is not evaluated: the Background's own colour is
    used then.
  * The image is downsampled to at most MAX_WIDTH x MAX_HEIGHT by box
    averaging (numpy), so the library reduces a small map per change; byte
    images stored in sRGB are made linear first.
"""

import math
from typing import NamedTuple

import numpy as np

from .colour_space import srgb_to_linear

MAX_WIDTH, MAX_HEIGHT = 128, 64


class Environment(NamedTuple):
    """vxl_environment's inputs: rgb is (height, width, 3) float32 linear
    radiance, row 0 at the bottom (Blender's Image.pixels order)."""
    rgb: np.ndarray
    strength: float
    rotation_deg: float


def downsample(rgb, max_width=MAX_WIDTH, max_height=MAX_HEIGHT):
    """(h, w, 3) -> at most (max_height, max_width, 3), each output pixel the
    mean of the input pixels it covers (uneven splits where the sizes do not
    divide): the map's mean and its bright spots' energy are kept."""
    rgb = np.asarray(rgb, np.float32)
    h, w = rgb.shape[:2]
    out_w, out_h = min(w, max_width), min(h, max_height)
    if (out_w, out_h) == (w, h):
        return np.ascontiguousarray(rgb)
    xs = np.linspace(0, w, out_w + 1).astype(np.int64)
    ys = np.linspace(0, h, out_h + 1).astype(np.int64)
    acc = np.add.reduceat(np.add.reduceat(rgb.astype(np.float64), ys[:-1], axis=0), xs[:-1], axis=1)
    counts = np.outer(np.diff(ys), np.diff(xs))[:, :, None]
    return np.ascontiguousarray(acc / counts, dtype=np.float32)


def image_rgb(image):
    """An image's pixels as (h, w, 3) linear floats, row 0 at the bottom, or
    None when it has none (not loaded, missing file)."""
    w, h = (int(v) for v in image.size)
    ch = int(image.channels)
    if w < 1 or h < 1 or ch < 1:
        return None
    buf = np.empty(w * h * ch, np.float32)
    image.pixels.foreach_get(buf)
    px = buf.reshape(h, w, ch)
    rgb = np.repeat(px[:, :, :1], 3, axis=2) if ch < 3 else px[:, :, :3]
    colorspace = getattr(getattr(image, "colorspace_settings", None), "name", "")
    if not getattr(image, "is_float", True) and colorspace == "sRGB":
        rgb = srgb_to_linear(rgb)
    return np.maximum(np.nan_to_num(rgb, nan=0.0, posinf=0.0), 0.0)


def _input(node, name, index):
    try:
        return node.inputs[name]
    except (KeyError, IndexError, TypeError):
        return node.inputs[index]


def _linked_node(socket):
    links = getattr(socket, "links", ())
    return links[0].from_node if socket.is_linked and links else None


def _uniform(colour, strength):
    rgb = np.asarray(list(colour)[:3], np.float32).reshape(1, 1, 3)
    return Environment(np.maximum(rgb, 0.0), float(strength), 0.0)


def mapping_rotation_deg(node):
    """The Z rotation (degrees) a Mapping node gives the texture lookup."""
    rot = getattr(node, "rotation", None)  # Blender < 2.81 kept it on the node
    try:
        rot = _input(node, "Rotation", 2).default_value
    except (KeyError, IndexError, AttributeError):
        pass
    z = math.degrees(float(rot[2])) if rot is not None else 0.0
    return -z if getattr(node, "vector_type", "POINT") == "TEXTURE" else z


def _output_node(tree):
    outputs = [n for n in tree.nodes if n.type == "OUTPUT_WORLD"]
    active = [n for n in outputs if getattr(n, "is_active_output", False)]
    return (active or outputs or [None])[0]


def world_environment(world, image_reader=image_rgb):
    """The World's light as an Environment, or None when there is no World
    or it is not a Background (a shader the library cannot evaluate)."""
    if world is None:
        return None
    tree = getattr(world, "node_tree", None)
    if not getattr(world, "use_nodes", False) or tree is None:
        return _uniform(world.color, 1.0)
    out = _output_node(tree)
    bg = _linked_node(_input(out, "Surface", 0)) if out is not None else None
    if bg is None or bg.type != "BACKGROUND":
        return None
    strength = float(_input(bg, "Strength", 1).default_value)
    colour = _input(bg, "Color", 0)
    tex = _linked_node(colour)
    if tex is None or tex.type != "TEX_ENVIRONMENT" or getattr(tex, "image", None) is None:
        return _uniform(colour.default_value, strength)
    rgb = image_reader(tex.image)
    if rgb is None:
        return _uniform(colour.default_value, strength)
    rgb = downsample(rgb)
    if getattr(tex, "projection", "EQUIRECTANGULAR") != "EQUIRECTANGULAR":
        return _uniform(rgb.reshape(-1, 3).mean(axis=0), strength)
    rotation = 0.0
    vector = _input(tex, "Vector", 0)
    mapping = _linked_node(vector)
    if mapping is not None and mapping.type == "MAPPING":
        rotation = mapping_rotation_deg(mapping)
    return Environment(rgb, strength, rotation)
