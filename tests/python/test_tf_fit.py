"""Transfer-function presets and their fit to the data (plugin/core/tf_presets.py,
tf_fit.py, histogram_image.py) without Blender; the built-in tables are
checked against the library's own."""

import numpy as np
import pytest

from voxlight.core import histogram_image, native, tf_fit, tf_presets
from nifti_write import phantom

BUILTINS = ("gray", "bone", "hot", "mri", "ct")


def _mr_like(seed=1):
    """A skull-stripped-MR-like volume: 60% exact zeros, the rest integer
    values around 70 and 105 (grey and white matter), up to ~130."""
    rng = np.random.default_rng(seed)
    n = 200_000
    fg = np.concatenate([rng.normal(72, 8, n // 2), rng.normal(105, 6, n // 2)])
    fg = np.clip(np.round(fg), 45, 130)
    return np.concatenate([np.zeros(int(n * 1.5)), fg])


def _stats(values, bins=tf_fit.HISTOGRAM_BINS):
    lo, hi = float(values.min()), float(values.max())
    counts, _ = np.histogram(values, bins, (lo, hi))
    return tf_fit.DataStats(counts, lo, hi)


# ------------------------------------------------------------------ presets

@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_tables_round_trip_through_ramp_stops(name):
    t = tf_presets.builtin_table(name)
    stops = tf_presets.table_to_stops(t)
    assert 2 <= len(stops) <= tf_presets.MAX_STOPS <= 30
    err = np.abs(tf_presets.stops_table(stops) - t).max()
    assert err <= tf_presets.TABLE_TOLERANCE, err


@pytest.fixture(scope="module")
def renderer():
    lib = native.load_library()
    r = native.Renderer(lib=lib)
    vol = native.Volume.from_array(phantom(32).astype(np.float32) * (3000.0 / 120.0) - 1000.0,
                                   lib=lib)
    r.set_volume(vol)
    yield lib, r
    r.close()
    vol.close()


@pytest.mark.parametrize("name", BUILTINS)
def test_builtin_tables_equal_the_librarys(renderer, name):
    """The library's preset and our copy of its table, as tf_rgba, render
    the same image: same formulas as csrc/frame/transfer.c."""
    lib, r = renderer
    kw = dict(width=48, height=48, jitter=False, window=(-1000.0, 2000.0), azimuth=30.0)
    a, _ = r.render(native.make_params(preset=name, lib=lib, **kw))
    b, _ = r.render(native.make_params(tf_rgba=tf_presets.builtin_table(name), lib=lib, **kw))
    assert a[..., 3].max() > 0.05, name  # the preset shows something on this volume
    assert np.abs(a - b).max() < 1e-5, (name, np.abs(a - b).max())


def test_every_preset_is_in_the_menu_once():
    keys = [p.key for _h, ps in tf_presets.menu_sections() for p in ps]
    assert sorted(keys) == sorted(tf_presets.PRESETS)
    assert set(tf_presets.LEGACY_ENUM.values()) <= set(tf_presets.PRESETS)
    assert {k for k, p in tf_presets.PRESETS.items() if p.hu} == \
        {"CT", "CT_BONE", "CT_SOFT_TISSUE", "CT_LUNG"}
    assert all(len(p.stops) <= tf_presets.MAX_STOPS for p in tf_presets.PRESETS.values())


# -------------------------------------------------------------- statistics

def test_background_and_quantiles_of_mr_like_data():
    v = _mr_like()
    s = _stats(v)
    fg = v[v > 0]
    assert 0.0 < s.background_edge <= fg.min() + s.bin_width
    assert abs(s.background_fraction - 0.6) < 1e-6
    for q in (0.01, 0.25, 0.5, 0.9, 0.995):
        assert abs(s.quantile(q) - np.quantile(fg, q)) <= 1.5, q
    assert abs(s.quantile(0.0) - fg.min()) <= s.bin_width
    assert abs(s.quantile(1.0) - fg.max()) <= s.bin_width


def test_noisy_air_is_background_too():
    rng = np.random.default_rng(2)
    air = np.abs(rng.normal(0, 4, 300_000))
    tissue = rng.normal(300, 40, 150_000)
    v = np.concatenate([air, tissue])
    s = _stats(v)
    assert 15 < s.background_edge < 200, s.background_edge
    assert abs(s.quantile(0.5) - np.median(tissue)) < 5


def test_data_without_background_is_all_foreground():
    v = np.random.default_rng(3).uniform(-5.0, 5.0, 100_000)
    s = _stats(v)
    assert s.background_fraction == 0.0
    assert abs(s.quantile(0.5)) < 0.2


def test_few_valued_data_spans_from_the_background_edge():
    """A binary mask (0 and 100): quantiles of the foreground all sit at
    100, so presets span from the background's edge to the maximum."""
    v = np.concatenate([np.zeros(50_000), np.full(5_000, 100.0)])
    s = _stats(v)
    assert s.few_valued and not _stats(_mr_like()).few_valued
    lo, hi = tf_fit.fit_window(s)
    assert lo < 5.0 and hi > 95.0, (lo, hi)
    lo, hi, _stops = tf_fit.place("MRI", "mr", s)
    assert lo < 5.0 and hi > 95.0, (lo, hi)


def test_guess_kind():
    assert tf_fit.guess_kind(0, 130) == "mr"
    assert tf_fit.guess_kind(-1024, 3071) == "ct"
    assert tf_fit.guess_kind(-3024, 2000) == "ct"
    assert tf_fit.guess_kind(-1.0, 1.0) == "mr"          # signed arbitrary units
    assert tf_fit.guess_kind(-1024, 3071, "MR") == "mr"   # the modality decides
    assert tf_fit.guess_kind(0, 4000, "CT") == "ct"
    assert tf_fit.guess_kind(0, 10, "PT") == "pet"
    assert tf_fit.guess_kind(0, 10, "US") == "other"
    assert {tf_fit.default_preset(k) for k in tf_fit.KINDS} <= set(tf_presets.PRESETS)


# ---------------------------------------------------------------- placement

@pytest.mark.parametrize("key", sorted(tf_presets.PRESETS))
def test_presets_on_arbitrary_units_lie_inside_the_data(key):
    v = _mr_like()
    s = _stats(v)
    lo, hi, stops = tf_fit.place(key, "mr", s)
    assert v.min() <= lo < hi <= v.max(), (key, lo, hi)
    pos = [p for p, _c in stops]
    assert pos[0] == 0.0 and pos[-1] == 1.0 and pos == sorted(pos)
    assert len(stops) <= 32
    # the placed ramp shows something of the foreground, and not the background
    table = tf_presets.stops_table(stops)
    fg = v[v > 0]
    alpha_fg = np.interp((fg - lo) / (hi - lo), np.linspace(0, 1, len(table)), table[:, 3])
    assert np.mean(alpha_fg > 0.01) > 0.005, key
    assert lo > 0 or table[0, 3] == 0


def test_fitting_follows_the_data_scale():
    """The same preset placed on data 0..130 and on the same data x 30 gets
    a window 30 times wider: histogram quantiles, not fixed numbers."""
    v = _mr_like()
    for key in ("MRI", "MR_DEFAULT", "GRAY", "CT_BONE"):
        a = tf_fit.place(key, "mr", _stats(v))
        b = tf_fit.place(key, "mr", _stats(v * 30.0))
        assert abs(b[0] - 30 * a[0]) < 30 * 0.5 and abs(b[1] - 30 * a[1]) < 30 * 0.5, key


def test_ct_presets_keep_hounsfield_units_on_ct():
    rng = np.random.default_rng(4)
    v = np.concatenate([np.full(50_000, -1024.0), rng.normal(40, 30, 50_000),
                        rng.normal(1200, 200, 5_000)])
    s = _stats(v)
    lo, hi, stops = tf_fit.place("CT_BONE", "ct", s)
    # the window starts FLOOR_ENTRIES table entries below the preset's last
    # transparent point (-16.4458 HU), so those entries stay exactly 0
    f = tf_fit.FLOOR_ENTRIES / (tf_presets.TABLE_SIZE - 1)
    assert abs(lo - (-16.4458 - f * (3071.0 + 16.4458) / (1 - f))) < 1e-6 and hi == 3071.0
    table = tf_presets.stops_table(stops)
    assert (table[:tf_fit.FLOOR_ENTRIES, 3] == 0).all() and table[-1, 3] > 0
    # The built-in CT preset placed on CT is the library's CT table over
    # the library's CT window (-1000..2000 HU), within the ramp tolerance.
    lo, hi, stops = tf_fit.place("CT", "ct", s)
    hu = np.linspace(-1000.0, 2000.0, 601)
    pos = np.array([p for p, _c in stops])
    col = np.array([c for _p, c in stops])
    ours = np.stack([np.interp((hu - lo) / (hi - lo), pos, col[:, c]) for c in range(4)], 1)
    lib = tf_presets.builtin_table("ct")
    x = np.linspace(0, 1, len(lib))
    ref = np.stack([np.interp((hu + 1000.0) / 3000.0, x, lib[:, c]) for c in range(4)], 1)
    assert np.abs(ours - ref).max() <= tf_presets.TABLE_TOLERANCE + 1e-6


def test_fit_window_lies_inside_the_data_range():
    for v in (_mr_like(), _mr_like() * 7.5 + 3.0, np.random.default_rng(5).gamma(2.0, 50.0, 90_000)):
        s = _stats(v)
        lo, hi = tf_fit.fit_window(s)
        assert v.min() <= lo < hi <= v.max()
        fg = v[v > s.background_edge]
        assert abs(hi - np.quantile(fg, 0.995)) <= 2 * s.bin_width + 1.0


# ------------------------------------------------------------- the picture

def test_histogram_picture_marks_the_window_and_aligns_with_the_ramp():
    counts = np.zeros(100)
    counts[50] = 1000  # every voxel at ~50.5 in data 0..100
    w, h, strip = 200, 80, 16
    img = histogram_image.render(counts, 0.0, 100.0, 25.0, 75.0, None, w, h, strip)
    assert img.shape == (h, w, 4)
    top = img[strip + 2:]
    filled = (np.abs(top[..., :3] - histogram_image.BACKGROUND[:3]).max(axis=2) > 0.05).any(axis=0)
    cols = np.nonzero(filled)[0]
    # 50..51 in a window of 25..75 is the middle 2% of the ramp's width
    assert cols.min() >= int(0.49 * w) - 1 and cols.max() <= int(0.52 * w) + 1, cols
    lo_col, hi_col = histogram_image.mark_columns(0.0, 100.0, 25.0, 75.0, w)
    assert (lo_col, hi_col) == (50, 150)
    for c in (lo_col, hi_col):
        assert np.allclose(img[:strip, c], histogram_image.MARK)
    # log scale: a bin 1000 times smaller still shows, at about half the height
    counts[20] = 1
    img = histogram_image.render(counts, 0.0, 100.0, 0.0, 100.0, None, w, h, strip)
    top = img[strip + 2:]
    col_hts = (np.abs(top[..., :3] - histogram_image.BACKGROUND[:3]).max(axis=2) > 0.05).sum(axis=0)
    assert 0.05 * top.shape[0] < col_hts[41] < 0.2 * top.shape[0] and \
        col_hts[101] == top.shape[0], (col_hts[41], col_hts[101])


def test_histogram_picture_has_no_comb_on_integer_data():
    v = _mr_like()
    counts, _ = np.histogram(v, tf_fit.HISTOGRAM_BINS, (0.0, 130.0))
    img = histogram_image.render(counts, 0.0, 130.0, 60.0, 120.0, None, 256, 96, 16)
    top = img[18:]
    col_hts = (np.abs(top[..., :3] - histogram_image.BACKGROUND[:3]).max(axis=2) > 0.05).sum(axis=0)
    assert col_hts.min() > 0.5 * top.shape[0], col_hts.min()  # no empty columns between bars


def test_histogram_picture_draws_the_ramp():
    counts = np.ones(64)
    table = tf_presets.stops_table([(0.0, (1, 0, 0, 0)), (1.0, (1, 0, 0, 1))], 64)
    img = histogram_image.render(counts, 0.0, 1.0, 0.0, 1.0, table, 128, 64, 8)
    top = img[10:]
    assert (top[..., 0] > top[..., 1] + 0.2).mean() > 0.3  # bars in the ramp's red
    white = np.all(top[..., :3] > 0.99, axis=2)
    assert white[:, 120].any() and np.nonzero(white[:, 120])[0].max() > 0.8 * top.shape[0]
    assert np.nonzero(white[:, 4])[0].min() < 0.2 * top.shape[0]  # opacity rises left to right


@pytest.mark.parametrize("key", sorted(tf_presets.PRESETS))
def test_placed_presets_keep_background_skippable(key):
    """A preset that starts transparent keeps its first table entries at
    exactly zero opacity once placed, so the library can still skip bricks of
    background (it widens each brick's table range by one entry either way):
    ramps that rose from entry 0 made ch2better's F12 frame 5x slower."""
    pr = tf_presets.PRESETS[key]
    if pr.stops[0][1][3] > 0:
        return  # visible from its first value: nothing to skip below it
    for kind in ("mr", "ct"):
        _lo, _hi, stops = tf_fit.place(key, kind, _stats(_mr_like()))
        assert (tf_presets.stops_table(stops)[:tf_fit.FLOOR_ENTRIES, 3] == 0).all(), (key, kind)
