"""The viewport's compositing of a reduced-scale frame (plugin/core/upsample.py,
the maths of viewport._FRAG): no blocks in a smooth preview, and at a mesh
silhouette no volume from behind the mesh on the mesh and no rays cut short
by the mesh beside it."""

import numpy as np
import pytest

from voxlight.core import depth, upsample

W, H = 96, 64
NEAR, FAR = 3.0, 5.0


def _proj(near=0.1, far=100.0):
    p = np.zeros((4, 4))
    p[0, 0] = p[1, 1] = 1.5
    p[2, 2] = -(far + near) / (far - near)
    p[2, 3] = -2.0 * far * near / (far - near)
    p[3, 2] = -1.0
    return p


PROJ = _proj()


def _smooth(w, h):
    """A smooth premultiplied image: alpha 1, colour a gentle wave."""
    y, x = np.mgrid[0:h, 0:w]
    u, v = (x + 0.5) / w, (y + 0.5) / h
    c = 0.5 + 0.4 * np.sin(2.0 * np.pi * u) * np.cos(np.pi * v)
    return np.dstack([c, c, c, np.ones_like(c)])


def _downsample_rgba(img, w, h):
    return np.dstack([depth.downsample(img[..., k], w, h) for k in range(4)])


@pytest.mark.parametrize("scale", [0.1, 0.23, 0.35, 0.5])
def test_smooth_preview_has_no_blocks(scale):
    w, h = max(1, round(W * scale)), max(1, round(H * scale))
    full = _smooth(W, H)
    coarse = _downsample_rgba(full, w, h)
    ones = np.ones((h, w))
    scene = np.ones((H, W))
    tol = upsample.tolerance(0.01)
    near, _ = upsample.composite(coarse, ones, ones, scene, PROJ, NEAR, FAR, tol, upsample.NEAREST)
    bil, _ = upsample.composite(coarse, ones, ones, scene, PROJ, NEAR, FAR, tol)
    # The largest step between neighbouring screen pixels: the full image's
    # own slope times a little, never the coarse frame's texel-to-texel jump.
    slope = max(np.abs(np.diff(full[..., 0], axis=1)).max(), np.abs(np.diff(full[..., 0], axis=0)).max())
    step = max(np.abs(np.diff(bil[..., 0], axis=1)).max(), np.abs(np.diff(bil[..., 0], axis=0)).max())
    step_near = np.abs(np.diff(near[..., 0], axis=1)).max()
    assert step <= 1.5 * slope + 1e-6, (step, slope)
    assert step_near > 1.5 * step  # what nearest did: blocks
    err = np.sqrt(np.mean((bil - full) ** 2))
    err_near = np.sqrt(np.mean((near - full) ** 2))
    assert err < err_near


def _scene_with_box(x_edge):
    """A mesh at planar depth 3.5 over x < x_edge, nothing (cleared) beyond."""
    scene = np.ones((H, W), np.float32)
    scene[:, :x_edge] = depth.planar_to_window(np.float32(3.5), PROJ)
    return scene


@pytest.mark.parametrize("scale", [0.1, 0.23, 0.35, 0.5, 1.0])
@pytest.mark.parametrize("x_edge", [31, 40, 47])
def test_silhouette_is_clean(scale, x_edge):
    """The volume spans the box 3.0..5.0; its opaque colour starts at 4.0,
    behind the mesh (3.5). Where the mesh is, nothing may show; beside it
    the full colour, as a full-resolution frame gives it."""
    w, h = max(1, round(W * scale)), max(1, round(H * scale))
    scene = _scene_with_box(x_edge)
    stop = depth.downsample(scene, w, h)
    # rays stopped by the mesh (at 3.5) see nothing; the rest the colour
    hit_planar = np.where(stop < 1.0, np.inf, 4.0)
    hit = depth.planar_to_window(hit_planar, PROJ)
    color = np.zeros((h, w, 4))
    color[stop >= 1.0] = (0.6, 0.5, 0.4, 1.0)
    tol = upsample.tolerance(0.01)
    rgba, frag = upsample.composite(color, hit, stop, scene, PROJ, NEAR, FAR, tol)
    mesh = scene < 1.0
    # never volume from behind the mesh on the mesh ...
    assert rgba[mesh][:, 3].max() == 0.0
    # ... and beside it the full colour: no band of rays cut short
    assert np.allclose(rgba[~mesh], (0.6, 0.5, 0.4, 1.0))
    # the fragment depth never lies behind the scene
    assert (frag <= scene).all()


def test_far_volume_never_covers_a_near_mesh():
    """A random scene of near meshes and holes, a frame whose rays passed
    them: any screen pixel whose scene is nearer (beyond the tolerance)
    than every neighbouring frame pixel's stop gets no colour."""
    rng = np.random.default_rng(3)
    w, h = 24, 16
    planar_scene = np.where(rng.random((H, W)) < 0.3, 3.2, np.inf)
    scene = depth.planar_to_window(planar_scene, PROJ)
    stop = depth.downsample(scene, w, h)
    color = rng.random((h, w, 4))
    color[..., :3] *= color[..., 3:]
    hit = depth.planar_to_window(np.full((h, w), 4.5), PROJ)
    tol = upsample.tolerance(0.01)
    rgba, frag = upsample.composite(color, hit, stop, scene, PROJ, NEAR, FAR, tol)
    ds = upsample.clamped_planar(stop, PROJ, NEAR, FAR)
    dp = upsample.clamped_planar(scene, PROJ, NEAR, FAR)
    x0, x1, y0, y1, _, _ = upsample._neighbours(h, w, H, W)
    nearest_stop = np.minimum.reduce([ds[yi][:, xi] for yi in (y0, y1) for xi in (x0, x1)])
    covered = dp < nearest_stop - tol
    assert covered.any()
    assert (rgba[covered] == 0.0).all()
    assert (frag <= scene + 1e-7).all()


def test_full_scale_equals_the_frame():
    """At scale 1 every screen pixel is its own frame pixel, as before."""
    rng = np.random.default_rng(1)
    color = rng.random((H, W, 4))
    scene = np.ones((H, W), np.float32)
    hit = np.ones((H, W))
    rgba, _ = upsample.composite(color, hit, scene, scene, PROJ, NEAR, FAR, 0.02)
    assert np.allclose(rgba, color)


@pytest.mark.parametrize("scale", [0.1, 0.23, 0.35, 0.5])
@pytest.mark.parametrize("line_planar, covered", [(4.8, True), (3.05, False)])
def test_thin_line_behind_the_volume_is_covered_and_in_front_stays(scale, line_planar, covered):
    """A one-pixel wire (the box outline's edges) that no ray of the coarse
    frame met: behind the volume's opaque surface (4.0) the preview covers
    it, as the full frame does, instead of showing it through in dashes;
    in front of that surface it stays whole."""
    w, h = max(1, round(W * scale)), max(1, round(H * scale))
    scene = np.ones((H, W), np.float32)
    line = np.zeros((H, W), bool)
    line[:, 45] = True
    scene[line] = depth.planar_to_window(np.float32(line_planar), PROJ)
    stop = np.ones((h, w))  # the coarse frame's samples missed the line
    hit = np.full((h, w), depth.planar_to_window(np.float32(4.0), PROJ))
    color = np.tile((0.6, 0.5, 0.4, 1.0), (h, w, 1))
    tol = upsample.tolerance(0.01)
    rgba, frag = upsample.composite(color, hit, stop, scene, PROJ, NEAR, FAR, tol)
    if covered:
        assert np.allclose(rgba[line], (0.6, 0.5, 0.4, 1.0))
    else:
        assert (rgba[line] == 0.0).all()
    assert np.allclose(rgba[~line], (0.6, 0.5, 0.4, 1.0))
    assert (frag <= scene + 1e-7).all()
