"""The ctypes binding (plugin/core/native.py) against the real library, without
Blender."""

import ctypes
import os
import subprocess

import numpy as np
import pytest

from voxlight.core import native
from nifti_write import phantom, write_nifti


def software_backend():
    """OSMesa where libOSMesa loads (as the library loads it), else Mesa's
    surfaceless EGL: the software path of a release without OSMesa."""
    try:
        ctypes.CDLL("libOSMesa.so.8")
        return "osmesa"
    except OSError:
        return "egl"


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
    # The add-on ships the library in its top folder, above core/.
    addon = os.path.dirname(os.path.dirname(native.__file__))
    assert paths[2] == os.path.join(addon, "libvoxlight.so")
    assert paths[3] == os.path.join(os.path.dirname(addon), "build", "libvoxlight.so")


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


def test_histogram_matches_numpy(lib):
    rng = np.random.default_rng(3)
    a = rng.normal(100.0, 30.0, (20, 16, 12)).astype(np.int16)
    v = native.Volume.from_array(a, lib=lib)
    try:
        h = v.histogram(16)
        ref, _ = np.histogram(a, bins=16, range=(a.min(), a.max()))
        # the edges of 16-bit normalised storage may move a voxel by one bin
        assert h.sum() == a.size and np.abs(h - ref).sum() <= 2, (h, ref)
    finally:
        v.close()


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


def test_filter_names_come_from_the_library(lib):
    """The add-on's filter list is read from vxl_filter_name; the fallback
    tuple must agree with it (added 'cubic' as VXL_FILTER_CUBIC = 6)."""
    names = lib.filter_names()
    assert names == native.FILTERS == native.filter_names(lib)
    assert names[6] == "cubic" and lib.filter_index("cubic") == 6
    assert lib.preset_names() == native.PRESETS


def test_cubic_filter_renders_differently(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    base = dict(width=32, height=32, jitter=False)
    imgs = {f: renderer.render(filter=f, **base)[0] for f in ("central", "cubic", "precomputed")}
    assert np.isfinite(imgs["cubic"]).all() and imgs["cubic"][..., 3].max() > 0.5
    assert np.abs(imgs["cubic"] - imgs["central"]).max() > 1e-3
    assert np.abs(imgs["cubic"] - imgs["precomputed"]).max() > 1e-3


def test_render_stats(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    renderer.render(width=32, height=32)
    st = renderer.stats()
    assert st["rays"] > 0 and st["samples"] >= st["rays"]
    assert 0 < st["bricks_occupied"] <= st["bricks_total"] and st["brick_size"] > 0
    renderer.render(width=32, height=32, no_skip=True)
    assert renderer.stats()["bricks_total"] == 0


def test_bricked_storage_matches_dense(lib, ball_file):
    """The storage option reaches the library; bricked renders what dense
    renders and reports its resident memory."""
    imgs, stats = {}, {}
    for storage in ("dense", "bricked", "sparse", "compressed"):
        r = native.Renderer(backend=software_backend(), lib=lib, storage=storage, page_brick=8)
        try:
            with native.Volume.load(ball_file, lib=lib) as v:
                r.set_volume(v)
            imgs[storage], _ = r.render(width=32, height=32)
            stats[storage] = r.stats()
        finally:
            r.close()
    for storage in ("bricked", "sparse"):
        assert np.abs(imgs[storage] - imgs["dense"]).max() < 1e-3
        assert stats[storage]["storage_name"] == storage
        assert stats[storage]["pages_total"] > 0 and stats[storage]["resident_bytes"] > 0
    assert stats["dense"]["storage_name"] == "dense" and stats["dense"]["pages_total"] == 0
    # compressed: 256 palette levels per brick of 10^3 voxels
    print("compressed: max difference", np.abs(imgs["compressed"] - imgs["dense"]).max())
    assert np.abs(imgs["compressed"] - imgs["dense"]).max() < 2e-2
    assert stats["compressed"]["storage_name"] == "compressed" and stats["compressed"]["decode_ms"] > 0


def _camera_params(renderer, lib, w, h, **kw):
    view, proj = renderer.default_camera(width=w, height=h)
    return native.make_params(width=w, height=h, view=view, proj=proj, lib=lib, **kw)


@pytest.mark.parametrize("jitter_seed", [0, 12345])
def test_tiled_render_equals_whole_render(lib, renderer, ball_file, jitter_seed):
    """Bands of the image (viewport refinement) give the same image as one
    call, jitter included (tile_params carries the tile offset through the
    seed), with a scene depth that is cropped per band."""
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    w, h = 61, 47
    p0 = _camera_params(renderer, lib, w, h)
    _, vd = renderer.render(p0)
    wall = np.full((h, w), np.inf, np.float32)
    wall[:, :25] = float(np.nanmin(vd[np.isfinite(vd)])) + 2.0  # inside the ball
    p = _camera_params(renderer, lib, w, h, scene_depth=wall, jitter_seed=jitter_seed)
    whole, wd = renderer.render(p)
    calls = []
    renderer.on_render = lambda: calls.append(1)
    try:
        tiled, td, st = renderer.render_tiled(p, rows=5)
    finally:
        renderer.on_render = None
    assert len(calls) == st["calls"] == (h + 4) // 5
    assert np.abs(tiled - whole).max() < 5e-3
    assert np.array_equal(np.isfinite(td), np.isfinite(wd))
    fin = np.isfinite(wd)
    assert np.abs(td[fin] - wd[fin]).max() < 1e-2 * np.abs(wd[fin]).max()
    assert st["rays"] > 0 and st["samples"] > 0
    # Without the seed offset the jitter pattern would differ per band.
    renderer.render(p)
    samples_whole = renderer.stats()["samples"]
    assert st["samples"] == samples_whole


def test_tiled_render_of_a_footprint_and_stopping(lib, renderer, ball_file):
    with native.Volume.load(ball_file, lib=lib) as v:
        renderer.set_volume(v)
    w, h = 64, 64
    p = _camera_params(renderer, lib, w, h)
    whole, _ = renderer.render(p)
    ys, xs = np.nonzero(whole[..., 3] > 0)
    rect = (xs.min() - 1, ys.min() - 1, xs.max() + 2, ys.max() + 2)
    part, _, st = renderer.render_tiled(p, rect=rect, rows=h)
    assert st["calls"] == 1 and np.abs(part - whole).max() < 5e-3
    asked = []

    def stop():
        asked.append(1)
        return len(asked) > 2  # stop before the third band
    assert renderer.render_tiled(p, rows=4, should_stop=stop) is None
    assert len(asked) == 3
    with pytest.raises(ValueError):
        native.tile_params(native.make_params(width=8, height=8, lib=lib), 0, 0, 4, 4)


def test_params_digest_covers_every_input(lib):
    view, proj = np.eye(4), np.diag([1.0, 1.0, -1.0, 1.0])
    depth = np.full((8, 8), np.inf, np.float32)

    def key(**kw):
        args = dict(width=8, height=8, view=view, proj=proj, scene_depth=depth, lib=lib)
        args.update(kw)
        extra = args.pop("extra", "vol-a")
        return native.params_digest(native.make_params(**args), extra)
    ref = key()
    assert key() == ref and key(scene_depth=depth.copy()) == ref
    d2 = depth.copy()
    d2[3, 4] = 2.0
    variants = [dict(scene_depth=d2), dict(scene_depth=None), dict(width=9, scene_depth=None),
                dict(view=np.diag([1.0, 1.0, 1.0, 1.0]) + np.eye(4) * 0 + np.array(
                    [[0, 0, 0, 0.1], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]])),
                dict(filter="cubic"), dict(step=0.25), dict(opacity_scale=0.5),
                dict(lights=[((0, 0, 1, 0), (1, 1, 1), 1.0)]), dict(jitter=False),
                dict(extra="vol-b"), dict(no_skip=True), dict(window=(1.0, 2.0))]
    keys = {key(**v) for v in variants}
    assert ref not in keys and len(keys) == len(variants)


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


def test_render_params_tail_matches_header():
    """The fields replaced the reserved slots, keeping the size (624
    bytes up to reserved[0]) until gave the struct new reserved room
    after them (offsets and sizes against the compiler: test_abi.py), from
    which to 19 took their fields: the oldest layout still ends
    where the first of them begins plus one word."""
    import ctypes
    P = native.RenderParams
    assert P.shading_model.offset + 4 == 624
    # 688 bytes up to the reserved room's end; appended the labels'
    # pointer, then overlay_count and progressive before the
    # overlays' pointer, which keeps it on its 8-byte alignment; MinIP's
    # floor (flag and value) follows it, then colour volumes' colour source (and a reserved word)
    assert P.labels.offset == 688 and P.overlays.offset == 704 and P.minip_floor.offset == 716
    # and the World's light (a pointer on its alignment), then the path
    # model's four words (samples, offset, bounces, seed), ending on the alignment
    assert P.color_source.offset == 720 and P.environment.offset == 728
    assert P.path_samples.offset == 736 and P.path_seed.offset == 748
    assert P.channel_count.offset == 752 and P.channels.offset == 760
    assert ctypes.sizeof(P) == 768
    assert P.labels.offset == P.reserved.offset + 4 * native.RENDER_PARAMS_RESERVED
    assert P.preint_size.offset == P.no_skip.offset + 4
    names = [n for n, _t in P._fields_]
    names = names[names.index("preint_size"):names.index("labels") + 1]
    assert names == ["preint_size", "gradient_opacity", "gradient_ref", "gradient_exp",
                     "iso_value", "iso_thickness", "shading_model", "light_shapes",
                     "ambient_occlusion", "occlusion_strength", "anisotropy", "illumination_size",
                     "technique", "mode", "cutaway", "scene_shadows", "matcap", "reserved",
                     "labels"]
    # the pointers and 19 sit on their 8-byte alignment
    assert P.cutaway.offset % 8 == 0 and P.matcap.offset + 8 == P.reserved.offset


def test_make_params_transfer_function_and_modes(lib):
    tf = np.zeros((256, 4), np.float32)
    tf[:, 3] = np.linspace(0, 1, 256)
    p = native.make_params(width=8, height=8, view=np.eye(4), proj=np.eye(4), tf_rgba=tf,
                           classify="preint", gradient_opacity="iso", iso_value=3.0,
                           iso_thickness=2.0, gradient_ref=0.1, gradient_exp=2.0, lib=lib)
    assert p.tf_size == 256 and p.tf_rgba[255 * 4 + 3] == 1.0
    assert p.classify == 2 and p.gradient_opacity == 2
    assert (p.iso_value, p.iso_thickness) == (3.0, 2.0)
    d1 = native.params_digest(p)
    tf2 = tf.copy()
    tf2[10, 0] = 0.5
    p2 = native.make_params(width=8, height=8, view=np.eye(4), proj=np.eye(4), tf_rgba=tf2,
                            classify="preint", gradient_opacity="iso", iso_value=3.0,
                            iso_thickness=2.0, gradient_ref=0.1, gradient_exp=2.0, lib=lib)
    assert native.params_digest(p2) != d1  # the table is part of the frame key
    t = native.tile_params(p, 0, 0, 4, 8)
    assert t.tf_rgba[255 * 4 + 3] == 1.0 and t._tf is p._tf
