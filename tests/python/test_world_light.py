"""The scene's World -> the library's environment light
(plugin/core/world_light.py), without Blender: the World, its nodes, links
and image are stand-ins read by attribute, the way the add-on reads
Blender's; and the map through make_params and the library."""

import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

from voxlight.core import native, world_light


class _Sockets(list):
    """node.inputs: by index and by name, as bpy's collections are."""
    def __getitem__(self, key):
        if isinstance(key, str):
            for s in self:
                if s.name == key:
                    return s
            raise KeyError(key)
        return list.__getitem__(self, key)


def _socket(name, value=None, from_node=None):
    links = [NS(from_node=from_node)] if from_node is not None else []
    return NS(name=name, default_value=value, is_linked=bool(links), links=links)


def _node(kind, inputs, **kw):
    return NS(type=kind, inputs=_Sockets(inputs), **kw)


class _Pixels:
    def __init__(self, flat):
        self.flat = np.asarray(flat, np.float32)

    def foreach_get(self, out):
        out[:] = self.flat


def _image(rgba, is_float=True, colorspace="Linear Rec.709"):
    h, w = rgba.shape[:2]
    return NS(size=(w, h), channels=4, pixels=_Pixels(rgba.ravel()), is_float=is_float,
              colorspace_settings=NS(name=colorspace))


def _world(colour_from=None, colour=(0.05, 0.05, 0.05, 1.0), strength=1.0):
    bg = _node("BACKGROUND", [_socket("Color", colour, colour_from), _socket("Strength", strength)])
    out = _node("OUTPUT_WORLD", [_socket("Surface", None, bg)], is_active_output=True)
    return NS(use_nodes=True, node_tree=NS(nodes=[bg, out]), color=(0.2, 0.2, 0.2))


def _env_texture(image, mapping=None, projection="EQUIRECTANGULAR"):
    return _node("TEX_ENVIRONMENT", [_socket("Vector", None, mapping)], image=image, projection=projection)


def _mapping(z_deg, vector_type="POINT"):
    return _node("MAPPING", [_socket("Vector"), _socket("Location", (0, 0, 0)),
                             _socket("Rotation", (0.0, 0.0, math.radians(z_deg))), _socket("Scale", (1, 1, 1))],
                 vector_type=vector_type)


def test_no_world_and_no_nodes():
    assert world_light.world_environment(None) is None
    env = world_light.world_environment(NS(use_nodes=False, node_tree=None, color=(0.1, 0.2, 0.3)))
    assert env.rgb.shape == (1, 1, 3) and env.strength == 1.0 and env.rotation_deg == 0.0
    assert np.allclose(env.rgb.ravel(), (0.1, 0.2, 0.3))


def test_a_background_colour_and_strength():
    env = world_light.world_environment(_world(colour=(1.0, 0.5, 0.25, 1.0), strength=3.0))
    assert np.allclose(env.rgb.ravel(), (1.0, 0.5, 0.25)) and env.strength == 3.0


def test_a_shader_other_than_background_is_not_a_light():
    world = _world()
    world.node_tree.nodes[1].inputs[0].links[0].from_node = _node("EMISSION", [])
    assert world_light.world_environment(world) is None


def test_an_hdri_is_downsampled_by_area_and_keeps_its_mean():
    rng = np.random.default_rng(7)
    rgba = rng.random((256, 512, 4)).astype(np.float32) * 5
    rgba[100, 300, :3] = 5000.0  # a small sun keeps its energy in the mean
    env = world_light.world_environment(_world(_env_texture(_image(rgba)), strength=2.0))
    assert env.rgb.shape == (64, 128, 3) and env.strength == 2.0
    assert np.allclose(env.rgb.mean(axis=(0, 1)), rgba[..., :3].mean(axis=(0, 1)), rtol=1e-4)
    # the sun's block: rows 100 // 4, columns 300 // 4
    assert env.rgb[25, 75, 0] > 300 and env.rgb[25, 75, 0] == env.rgb[..., 0].max()


def test_uneven_sizes_and_small_maps():
    rgb = np.arange(7 * 300 * 3, dtype=np.float32).reshape(7, 300, 3)
    small = world_light.downsample(rgb)
    assert small.shape == (7, 128, 3)
    assert np.isclose(small.mean(), rgb.mean(), rtol=1e-3)  # uneven splits, but every pixel counted
    assert world_light.downsample(rgb[:, :10]).shape == (7, 10, 3)  # nothing to do


def test_a_mapping_nodes_z_rotation():
    rgba = np.ones((8, 16, 4), np.float32)
    img = _image(rgba)
    env = world_light.world_environment(_world(_env_texture(img, _mapping(90.0))))
    assert env.rotation_deg == pytest.approx(90.0)
    env = world_light.world_environment(_world(_env_texture(img, _mapping(90.0, "TEXTURE"))))
    assert env.rotation_deg == pytest.approx(-90.0)  # the inverse transform
    env = world_light.world_environment(_world(_env_texture(img, _node("TEX_COORD", []))))
    assert env.rotation_deg == 0.0  # not a Mapping node: no rotation


def test_byte_images_in_srgb_are_made_linear():
    rgba = np.full((4, 8, 4), 0.5, np.float32)
    env = world_light.world_environment(_world(_env_texture(_image(rgba, is_float=False, colorspace="sRGB"))))
    assert np.allclose(env.rgb, ((0.5 + 0.055) / 1.055) ** 2.4, rtol=1e-5)


def test_a_mirror_ball_gives_its_mean_colour():
    rgba = np.zeros((4, 8, 4), np.float32)
    rgba[:, :4, 0] = 2.0
    env = world_light.world_environment(_world(_env_texture(_image(rgba), projection="MIRROR_BALL")))
    assert env.rgb.shape == (1, 1, 3) and np.allclose(env.rgb.ravel(), (1.0, 0.0, 0.0))


def test_an_image_without_pixels_falls_back_to_the_colour():
    img = _image(np.zeros((1, 1, 4), np.float32))
    img.size = (0, 0)
    env = world_light.world_environment(_world(_env_texture(img), colour=(0.3, 0.3, 0.3, 1.0)))
    assert np.allclose(env.rgb.ravel(), 0.3)


def test_make_params_passes_the_map(tmp_path):
    lib = native.load_library()
    rgb = np.zeros((8, 16, 3), np.float32)
    rgb[:, 8] = 4.0
    env = world_light.Environment(rgb, 2.0, 45.0)
    p = native.make_params(width=8, height=8, environment=env, lib=lib)
    e = p.environment.contents
    assert (e.width, e.height, e.strength, e.rotation_deg) == (16, 8, 2.0, 45.0)
    assert e.rgb[3 * 8] == 4.0
    # the digest sees the map's contents
    q = native.make_params(width=8, height=8, environment=world_light.Environment(rgb * 2, 2.0, 45.0), lib=lib)
    assert native.params_digest(p) != native.params_digest(q)
    assert native.params_digest(p) == native.params_digest(
        native.make_params(width=8, height=8, environment=env, lib=lib))
