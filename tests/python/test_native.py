"""The ctypes binding (plugin/native.py) against the real library, without
Blender."""

import os
import subprocess

import numpy as np
import pytest

from voxlight import native
from nifti_write import phantom, write_nifti


@pytest.fixture(scope="module")
def lib():
    return native.load_library()


@pytest.fixture(scope="module")
def renderer(lib):
    r = native.Renderer(lib=lib)
    yield r
    r.close()


@pytest.fixture(scope="module")
def ball_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("vol") / "ball.nii.gz"
    aff = np.diag([2.0, 2.0, 3.0, 1.0])
    aff[:3, 3] = [-31.0, -31.0, -46.5]
    return str(write_nifti(path, phantom(32), aff))


def _compile_so(tmp_path, source, name):
    src = tmp_path / (name + ".c")
    src.write_text(source)
    out = tmp_path / (name + ".so")
    subprocess.run(["cc", "-shared", "-fPIC", "-o", str(out), str(src)], check=True)
    return str(out)


def test_library_loads_with_abi_1(lib):
    assert lib.abi_version == native.ABI_VERSION == 1
    ok, msg = native.library_status()
    assert ok and "ABI 1" in msg


def test_missing_library_is_reported():
    with pytest.raises(native.LibraryUnavailable) as e:
        native.Library("/nonexistent/libvoxlight.so")
    assert "cannot load" in str(e.value)


def test_wrong_abi_is_reported(tmp_path):
    so = _compile_so(tmp_path, "unsigned vxl_abi_version(void) { return 2; }", "abi2")
    with pytest.raises(native.LibraryUnavailable) as e:
        native.Library(so)
    assert "ABI version 2" in str(e.value)


def test_foreign_library_is_reported(tmp_path):
    so = _compile_so(tmp_path, "int something_else(void) { return 0; }", "other")
    with pytest.raises(native.LibraryUnavailable) as e:
        native.Library(so)
    assert "not libvoxlight" in str(e.value)


def test_explicit_broken_path_is_not_silently_replaced(tmp_path):
    so = _compile_so(tmp_path, "unsigned vxl_abi_version(void) { return 7; }", "abi7")
    with pytest.raises(native.LibraryUnavailable) as e:
        native.load_library(so)
    assert "ABI version 7" in str(e.value)
    native.load_library(reload=True)  # restore the good one for later tests


def test_candidate_order(monkeypatch):
    monkeypatch.setenv("VOXLIGHT_LIB", "/env/libvoxlight.so")
    paths = native.candidate_paths("/explicit/libvoxlight.so")
    assert paths[0] == "/explicit/libvoxlight.so" and paths[1] == "/env/libvoxlight.so"
    assert paths[2] == os.path.join(os.path.dirname(native.__file__), "libvoxlight.so")


def test_volume_load_info(lib, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        info = v.info
    assert info["dims"] == (32, 32, 32)
    assert info["dtype"] == "float32"
    assert np.allclose(np.diag(info["affine"]), [2, 2, 3, 1])
    assert np.allclose(info["affine"][:3, 3], [-31, -31, -46.5])
    data = phantom(32)
    assert info["value_min"] == pytest.approx(data.min())
    assert info["value_max"] == pytest.approx(data.max(), rel=1e-6)


def test_bad_file_raises_with_library_message(lib, tmp_path):
    bad = tmp_path / "bad.nii"
    bad.write_bytes(b"this is not a nifti file" * 4)
    with pytest.raises(native.VoxlightError) as e:
        native.Volume.load(str(bad), lib=lib)
    assert e.value.code in (2, 3)  # VXL_ERR_IO or VXL_ERR_FORMAT
    assert "bad.nii" in str(e.value) and len(str(e.value)) > len("bad.nii: ")
    with pytest.raises(native.VoxlightError):
        native.Volume.load(str(tmp_path / "missing.nii"), lib=lib)


def test_from_array_matches_file(lib, ball_file):
    data = phantom(32)
    aff = np.diag([2.0, 2.0, 3.0, 1.0])
    with native.Volume.from_array(data, affine=aff, lib=lib) as v:
        assert v.info["dims"] == (32, 32, 32)
        assert v.info["value_max"] == pytest.approx(data.max(), rel=1e-6)
    with pytest.raises(ValueError):
        native.Volume.from_array(np.zeros((4, 4)), lib=lib)


def test_array_index_order_reaches_the_shader(lib, renderer):
    """array[i, j, k] = i must give a gradient along voxel +x."""
    n = 16
    ramp = np.broadcast_to(np.arange(n, dtype=np.float32)[:, None, None], (n, n, 8)).copy()
    with native.Volume.from_array(ramp, lib=lib) as v:
        renderer.set_volume(v)
    g = renderer.probe_gradients([[8.0, 8.0, 4.0], [5.0, 7.0, 3.0]], filter="central")
    assert g.shape == (2, 3)
    for row in g:
        assert row[0] > 0 and abs(row[1]) < 1e-3 * row[0] and abs(row[2]) < 1e-3 * row[0]


def test_render_outputs(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    rgba, depth = renderer.render(width=48, height=40)
    assert rgba.shape == (40, 48, 4) and rgba.dtype == np.float32
    assert depth.shape == (40, 48)
    assert np.isfinite(rgba).all()
    assert (rgba[..., 3] >= rgba[..., :3].max(axis=2) - 1e-5).all()  # premultiplied
    assert rgba[..., 3].max() > 0.5 and rgba[0, 0, 3] < 0.01  # ball in the middle only
    hit = np.isfinite(depth)
    assert hit.any() and (~hit).any() and (depth[hit] > 0).all()


def test_explicit_camera_equals_default_camera(lib, renderer, ball_file):
    """Round-trips the matrices through numpy: checks the column-major transpose."""
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    view, proj = renderer.default_camera(width=32, height=32)
    a, da = renderer.render(width=32, height=32)
    b, db = renderer.render(width=32, height=32, view=view, proj=proj)
    assert np.abs(a - b).max() < 1e-4
    # A camera moved sideways must move the image.
    shifted = view.copy()
    shifted[0, 3] += 10.0
    c, _ = renderer.render(width=32, height=32, view=shifted, proj=proj)
    assert np.abs(a - c).max() > 0.05


def test_scene_depth_stops_rays(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    full, depth = renderer.render(width=32, height=32)
    near = float(np.nanmin(depth[np.isfinite(depth)])) * 0.5
    wall = np.full((32, 32), np.inf, np.float32)
    wall[:, :16] = near  # opaque geometry in front of the left half
    occl, _ = renderer.render(width=32, height=32, scene_depth=wall)
    assert occl[:, :16, 3].max() < 1e-3
    assert np.abs(occl[:, 16:] - full[:, 16:]).max() < 1e-4


def test_every_setting_changes_the_image(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    base = dict(width=32, height=32, jitter=False)
    ref, _ = renderer.render(**base)
    changes = [dict(filter="sobel26"), dict(sample_distance=2.0), dict(step=1.5),
               dict(preset="hot"), dict(window=(20.0, 60.0)), dict(opacity_scale=0.3),
               dict(shading=False), dict(material=(0.9, 0.2, 0.8, 4.0)), dict(jitter=True),
               dict(lights=[((1.0, 0.0, 0.0, 0.0), (1.0, 0.5, 0.2), 2.0)])]
    for change in changes:
        img, _ = renderer.render(**dict(base, **change))
        assert np.abs(img - ref).max() > 1e-3, change


def test_param_validation(lib):
    with pytest.raises(ValueError):
        native.make_params(width=4, height=4, view=np.eye(4), lib=lib)
    with pytest.raises(ValueError):
        native.make_params(width=4, height=4, scene_depth=np.zeros(5), lib=lib)
    with pytest.raises(ValueError):
        native.make_params(lights=[((0, 0, 1, 0), (1, 1, 1), 1.0)] * 9, lib=lib)
    with pytest.raises(native.VoxlightError):
        native.make_params(filter="no-such-filter", lib=lib)
    for i, name in enumerate(native.FILTERS):
        assert lib.filter_index(name) == i
    for i, name in enumerate(native.PRESETS):
        assert lib.preset_index(name) == i


def test_write_image(lib, tmp_path):
    rgba = np.zeros((8, 8, 4), np.float32)
    rgba[:4] = (0.5, 0.25, 0.0, 0.5)
    out = tmp_path / "x.png"
    lib.write_image(str(out), rgba)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_closed_handles(lib, ball_file):
    r = native.Renderer(lib=lib)
    r.close()
    r.close()  # destroy twice is harmless
    with pytest.raises(native.VoxlightError):
        r.render(width=4, height=4)
