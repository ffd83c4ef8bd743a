"""Scene shadows through the ctypes binding, without Blender:
make_params(scene_shadows=...) reaches the library (a plate over half of a
ball darkens that half), Renderer.scene_transmittance gives the ball's
shadow on a floor where the geometry puts it, bad occluders raise an error
naming the field, and the params digest follows the occluders' key."""

import math

import numpy as np
import pytest

from voxlight.core import native
from voxlight.core.native_tiles import params_digest, tile_params

N = 32
W = H = 48
EYE_Z, FLOOR_Z, HALF_VIEW = 5.0, -1.5, 2.0


@pytest.fixture(scope="module")
def renderer():
    """A ball of radius 0.5 at the origin, the volume on the world box [-1, 1]^3."""
    r = native.Renderer()
    c = (N - 1) / 2
    i = np.arange(N)
    x, y, z = np.meshgrid(i, i, i, indexing="ij")
    dist = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    r.set_volume(native.Volume.from_array((1 / (1 + np.exp(2 * (dist - N / 4)))).astype(np.float32), lib=r.lib))
    yield r
    r.close()


@pytest.fixture(scope="module")
def lib(renderer):
    return renderer.lib


def _model():
    s = 2.0 / N
    m = np.eye(4)
    m[:3, :3] *= s
    m[:3, 3] = -1 + 0.5 * s
    return m


def _plate(x0, key=0):
    """A quad at z = 1.5 over x in [x0, 3], y in [-3, 3]."""
    v = np.array([[x0, -3, 1.5], [3, -3, 1.5], [3, 3, 1.5], [x0, 3, 1.5]], np.float32)
    return v, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), key


def _params(lib, **kw):
    base = dict(width=W, height=H, model=_model(), tf_rgba=[[1, 1, 1, 0], [1, 1, 1, 1]],
                window=(0.3, 0.7), shading_model="shadowed", illumination_size=N, jitter=False,
                lights=[((0, 0, 1, 0), (1, 1, 1), 1)], lib=lib)
    base.update(kw)
    return native.make_params(**base)


def _floor_camera():
    """Straight down on the floor z = FLOOR_Z, which fills [-2, 2]^2."""
    view = np.eye(4)
    view[2, 3] = -EYE_Z
    t, n, f = HALF_VIEW / (EYE_Z - FLOOR_Z), 0.1, 20.0
    proj = np.zeros((4, 4))
    proj[0, 0] = proj[1, 1] = 1 / t
    proj[2, 2], proj[2, 3], proj[3, 2] = -(f + n) / (f - n), -2 * f * n / (f - n), -1
    return dict(view=view, proj=proj, scene_depth=np.full((H, W), EYE_Z - FLOOR_Z, np.float32))


def _brightness(rgba, cols):
    """Mean straight colour of the opaque pixels in those columns."""
    px = rgba[:, cols]
    m = px[..., 3] > 0.5
    return px[..., :3][m].sum() / (3 * px[..., 3][m].sum())


def test_a_plate_darkens_the_half_of_the_ball_it_covers(lib, renderer):
    bare, _ = renderer.render(_params(lib), want_depth=False)
    shadowed, _ = renderer.render(_params(lib, scene_shadows=_plate(0.0)), want_depth=False)
    # the default camera looks from +Y: the image's left half is world +x, under the plate
    covered, open_ = slice(0, W // 2 - 3), slice(W // 2 + 3, W)
    assert _brightness(shadowed, open_) == pytest.approx(_brightness(bare, open_), abs=0.01)
    assert _brightness(bare, covered) > 0.35
    assert _brightness(shadowed, covered) < 0.31  # the ambient 0.3 and little else
    assert renderer.stats()["illumination_rebuilt"] == 1
    renderer.render(_params(lib, scene_shadows=_plate(0.0), azimuth=30.0), want_depth=False)
    assert renderer.stats()["illumination_rebuilt"] == 0  # a camera move


def test_the_transmittance_image_is_the_balls_shadow_on_the_floor(lib, renderer):
    t = renderer.scene_transmittance(_params(lib, **_floor_camera()), 0)
    assert t.shape == (H, W) and t.dtype == np.float32
    xs = ((np.arange(W) + 0.5) / W * 2 - 1) * HALF_VIEW
    x, y = np.meshgrid(xs, xs)
    r = np.hypot(x, y)
    assert (t[r < 0.5 - 0.12] < 0.2).all()
    assert (t[r > 0.5 + 0.12] > 0.98).all()
    assert (t[(np.abs(x) > 1.1) | (np.abs(y) > 1.1)] == 1).all()  # paths that miss the volume


def test_the_plate_shadows_the_floor_through_the_volume(lib, renderer):
    """The floor under the box's footprint, below the plate's shadow on the volume."""
    p = _params(lib, scene_shadows=_plate(0.3), **_floor_camera())
    t = renderer.scene_transmittance(p, 0)
    xs = ((np.arange(W) + 0.5) / W * 2 - 1) * HALF_VIEW
    x, y = np.meshgrid(xs, xs)
    under = (x > 0.45) & (x < 0.85) & (np.abs(y) < 0.85) & (np.hypot(x, y) > 0.65)
    assert under.sum() > 20 and (t[under] < 0.2).all()
    assert (t[(x < 0.15) & (np.hypot(x, y) > 0.65) & (np.abs(y) < 0.85)] > 0.98).all()


def test_bad_occluders_name_the_field(lib, renderer):
    v, tri, _ = _plate(0.0)
    tri = tri.copy()
    tri[1, 2] = 9
    with pytest.raises(native.VoxlightError, match="occluder_indices"):
        renderer.render(_params(lib, scene_shadows=(v, tri, 0)), want_depth=False)
    v = v.copy()
    v[2, 0] = math.nan
    with pytest.raises(native.VoxlightError, match="occluder_vertices"):
        renderer.render(_params(lib, scene_shadows=(v, _plate(0.0)[1], 0)), want_depth=False)
    with pytest.raises(native.VoxlightError, match="scene_depth"):
        renderer.scene_transmittance(_params(lib), 0)
    with pytest.raises(native.VoxlightError, match="light 2"):
        renderer.scene_transmittance(_params(lib, **_floor_camera()), 2)


def test_the_digest_follows_the_key_or_the_arrays(lib):
    a = params_digest(_params(lib, scene_shadows=_plate(0.0, key=5)))
    assert params_digest(_params(lib, scene_shadows=_plate(0.2, key=5))) == a  # the key says unchanged
    assert params_digest(_params(lib, scene_shadows=_plate(0.0, key=6))) != a
    h = params_digest(_params(lib, scene_shadows=_plate(0.0)))
    assert params_digest(_params(lib, scene_shadows=_plate(0.0))) == h
    assert params_digest(_params(lib, scene_shadows=_plate(0.2))) != h  # key 0: the arrays count
    assert params_digest(_params(lib)) not in (a, h)


def test_tiles_keep_the_occluders(lib, renderer):
    cam = _floor_camera()
    del cam["scene_depth"]
    p = _params(lib, scene_shadows=_plate(0.0), **cam)
    whole, _ = renderer.render(p, want_depth=False)
    t = tile_params(p, 0, 0, W, H // 2)
    assert t.scene_shadows.contents.occluder_triangle_count == 2
    part, _ = renderer.render(t, want_depth=False)
    assert np.allclose(part, whole[: H // 2], atol=1e-5)
