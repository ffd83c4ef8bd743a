"""The volume's shadow follows what is shown: a clip plane, a crop box and
hidden labels remove their part of the volume from its shadow on the scene
(vxl_scene_transmittance) as from the image, and the shadow comes back when
they go. A ball over a floor under an overhead sun; the label map splits
the ball into its -x half (label 1) and its +x half (label 2)."""

import numpy as np
import pytest

from voxlight.core import native
from test_scene_shadows import H, N, W, HALF_VIEW, _floor_camera, _params


@pytest.fixture(scope="module")
def renderer():
    r = native.Renderer()
    c = (N - 1) / 2
    i = np.arange(N)
    x, y, z = np.meshgrid(i, i, i, indexing="ij")
    dist = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    r.set_volume(native.Volume.from_array((1 / (1 + np.exp(2 * (dist - N / 4)))).astype(np.float32), lib=r.lib))
    r.set_labels(native.Volume.from_array(np.where(x < N // 2, 1, 2).astype(np.uint16), lib=r.lib))
    yield r
    r.close()


def _halves():
    """Floor masks under the ball's -x and +x halves (away from the middle)."""
    xs = ((np.arange(W) + 0.5) / W * 2 - 1) * HALF_VIEW
    x, y = np.meshgrid(xs, xs)
    disc = np.hypot(x, y) < 0.38
    return disc & (x < -0.1), disc & (x > 0.1)


def _shadow(renderer, **kw):
    return renderer.scene_transmittance(_params(renderer.lib, **_floor_camera(), **kw), 0)


def test_a_clip_plane_removes_the_shadow_of_what_it_cuts_away(renderer):
    left, right = _halves()
    whole = _shadow(renderer)
    assert whole[left].max() < 0.2 and whole[right].max() < 0.2
    cut = _shadow(renderer, cutaway=dict(clip_planes=[((1.0, 0.0, 0.0, 0.0), 0.0)]))  # keeps x >= 0
    assert cut[left].min() > 0.95, cut[left].min()
    assert cut[right].max() < 0.2, cut[right].max()
    assert np.array_equal(_shadow(renderer), whole)  # the cut gone, the shadow is back


def test_a_crop_box_keeps_only_its_shadow(renderer):
    left, right = _halves()
    box = np.diag([0.5, 2.0, 2.0, 1.0])
    box[0, 3] = 0.5  # x in [0, 1]
    crop = _shadow(renderer, cutaway=dict(crop_box=box))
    assert crop[left].min() > 0.95 and crop[right].max() < 0.2


@pytest.mark.parametrize("mode", ["mask", "tint", "surface"])
def test_a_hidden_label_casts_no_shadow(renderer, mode):
    left, right = _halves()
    white = (1.0, 1.0, 1.0, 1.0)
    shown = _shadow(renderer, labels=(mode, [(1, white, True), (2, white, True)]))
    assert shown[left].max() < 0.2 and shown[right].max() < 0.2
    hidden = _shadow(renderer, labels=(mode, [(1, white, False), (2, white, True)]))
    assert hidden[left].min() > 0.95, hidden[left].min()
    assert hidden[right].max() < 0.2, hidden[right].max()
