"""Render modes and MatCaps through the ctypes binding, without
Blender: make_params(mode=..., iso_value=..., matcap=...) reaches the library.
Through an orthographic camera looking along a world axis, with one pixel per
voxel and rays through voxel centres, MIP, MinIP and average equal numpy's
max, min and mean along that axis; ISO's depth finds an analytic sphere; a
MatCap colours each side of it; unknown modes and bad MatCaps are refused."""

import numpy as np
import pytest

from voxlight.core import native

NX, NY, NZ = 14, 12, 10


@pytest.fixture(scope="module")
def noise():
    """Values on 64 levels in [0, 1], a[i, j, k] at world (i, j, k)."""
    return np.random.default_rng(7).integers(0, 64, (NX, NY, NZ)).astype(np.float32) / 63


@pytest.fixture(scope="module")
def renderer(lib, noise):
    r = native.Renderer(lib=lib)
    r.set_volume(native.Volume.from_array(noise, lib=lib))
    yield r
    r.close()


def axis_camera(axis, dims):
    """View from the + side of world axis 0 (x) or 2 (z), orthographic, framing
    the box [-0.5, n - 0.5] with one pixel per voxel: (view, proj, w, h)."""
    c = (np.asarray(dims, float) - 1) / 2
    if axis == 2:  # +x right, +y up, looking down z
        rot, w, h = np.eye(3), dims[0], dims[1]
    else:  # +y right, +z up, looking down x
        rot, w, h = np.array([[0, 1, 0], [0, 0, 1], [1, 0, 0]], float), dims[1], dims[2]
    eye = c.copy()
    eye[axis] += dims[axis] + 5
    view = np.eye(4)
    view[:3, :3] = rot
    view[:3, 3] = -rot @ eye
    n, f = 1.0, 2.0 * dims[axis] + 10
    proj = np.diag([2.0 / w, 2.0 / h, -2 / (f - n), 1.0])
    proj[2, 3] = -(f + n) / (f - n)
    return view, proj, w, h


def _params(lib, axis, dims, **kw):
    view, proj, w, h = axis_camera(axis, dims)
    grey = np.stack([np.linspace(0, 1, 4096)] * 3 + [np.ones(4096)], axis=1)  # colour = value, opaque
    base = dict(width=w, height=h, view=view, proj=proj, tf_rgba=grey, window=(0, 1), jitter=False,
                step=0.5, lib=lib)
    base.update(kw)
    return native.make_params(**base)


@pytest.mark.parametrize("mode", ["mip", "minip", "average"])
@pytest.mark.parametrize("axis", [2, 0])
def test_projection_equals_numpy(lib, renderer, noise, mode, axis):
    rgba, _ = renderer.render(_params(lib, axis, noise.shape, mode=mode))
    want = {"mip": np.max, "minip": np.min, "average": np.mean}[mode](noise, axis=axis)
    # image rows are the up axis (y for z, z for x), columns the right one
    want = want.T
    tol = 2e-3
    if mode == "average":  # step-0.5 samples weigh the end voxels by 3/4 and 1/4 (docs/modes.md)
        n = noise.shape[axis]
        ends = np.abs(np.take(noise, 0, axis=axis) - np.take(noise, n - 1, axis=axis)).T
        tol = tol + ends / (4 * n)
    assert np.all(np.abs(rgba[..., 0] - want) <= tol)
    assert np.allclose(rgba[..., 3], 1)


@pytest.fixture(scope="module")
def sphere(lib):
    """A distance field: |x - c| with c = (15.3, 15.6, 15.45); the ball r < 10."""
    i = np.arange(32)
    x, y, z = np.meshgrid(i, i, i, indexing="ij")
    c = (15.3, 15.6, 15.45)
    d = np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2).astype(np.float32)
    r = native.Renderer(lib=lib)
    r.set_volume(native.Volume.from_array(d, lib=lib))
    yield r, c
    r.close()


def test_iso_depth_finds_the_sphere(lib, sphere):
    r, c = sphere
    p = _params(lib, 2, (32, 32, 32), mode="iso", iso_value=10.0, window=(0, 20))
    rgba, depth = r.render(p)
    eye_z = 15.5 + 32 + 5
    x, y = np.meshgrid(np.arange(32), np.arange(32))  # [row = y, column = x]
    rho2 = (x - c[0]) ** 2 + (y - c[1]) ** 2
    inner = rho2 < 8.5 ** 2
    want = eye_z - (c[2] + np.sqrt(np.maximum(100 - rho2, 0)))
    assert np.abs(depth[inner] - want[inner]).max() < 0.1
    assert np.all(rgba[inner][:, 3] == 1)
    assert np.all(np.isinf(depth[rho2 > 11 ** 2]))


def test_matcap_colours_each_side(lib, sphere):
    r, c = sphere
    cap = np.zeros((32, 32, 3), np.float32)
    cap[:, :16, 0] = 1
    cap[:, 16:, 1] = 1
    p = _params(lib, 2, (32, 32, 32), mode="iso", iso_value=10.0, window=(0, 20),
                tf_rgba=[[1, 1, 1, 1], [1, 1, 1, 1]], matcap=cap, matcap_key=5)
    rgba, _ = r.render(p)
    x, y = np.meshgrid(np.arange(32), np.arange(32))
    inner = (x - c[0]) ** 2 + (y - c[1]) ** 2 < 8 ** 2
    left, right = inner & (x < c[0] - 5), inner & (x > c[0] + 5)
    assert rgba[left][:, 0].mean() > 0.8 and rgba[left][:, 1].mean() < 0.2
    assert rgba[right][:, 1].mean() > 0.8 and rgba[right][:, 0].mean() < 0.2


def test_bad_input_is_refused(lib, renderer, noise):
    with pytest.raises(native.VoxlightError, match="mode"):
        renderer.render(_params(lib, 2, noise.shape, mode=7))
    with pytest.raises(native.VoxlightError, match="iso_value"):
        renderer.render(_params(lib, 2, noise.shape, mode="iso", iso_value=float("nan")))
    with pytest.raises(native.VoxlightError, match="classify"):
        renderer.render(_params(lib, 2, noise.shape, mode="mip", classify="pre"))
    with pytest.raises(ValueError):
        _params(lib, 2, noise.shape, matcap=np.zeros((0, 4, 3), np.float32))
    # the renderer still renders
    rgba, _ = renderer.render(_params(lib, 2, noise.shape, mode="mip"))
    assert rgba[..., 3].min() == 1
