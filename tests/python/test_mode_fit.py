"""core/mode_fit.py: where each render mode starts, from the histogram."""

import numpy as np

from voxlight.core import mode_fit, tf_fit


def _stats(values, lo, hi, bins=1024):
    counts, _ = np.histogram(values, bins=bins, range=(lo, hi))
    return tf_fit.DataStats(counts, lo, hi)


def _head_like(seed=0):
    """Air (zeros) around a head: tissue from 51 to 130, as in ch2better."""
    rng = np.random.default_rng(seed)
    air = np.zeros(600000)
    tissue = np.clip(rng.normal(95, 15, 400000), 51, 130)
    return np.concatenate([air, tissue])


def test_iso_sits_in_the_gap_between_air_and_tissue():
    s = _stats(_head_like(), 0.0, 130.0)
    v = mode_fit.iso_value(s)
    assert 15.0 < v < 45.0, v  # the middle of the empty 0..51 gap, not 0.1


def test_iso_on_ct_separates_air_from_the_body():
    rng = np.random.default_rng(1)
    data = np.concatenate([rng.normal(-1000, 20, 500000), rng.normal(40, 30, 400000),
                           rng.normal(700, 150, 50000)])
    s = _stats(data, -1100.0, 1500.0)
    v = mode_fit.iso_value(s)
    assert -800.0 < v < -100.0, v


def test_iso_inside_range_on_flat_or_empty_histograms():
    s = tf_fit.DataStats(np.zeros(64), 5.0, 9.0)
    assert 5.0 < mode_fit.iso_value(s) < 9.0
    s = tf_fit.DataStats(np.ones(64), 5.0, 9.0)
    assert 5.0 < mode_fit.iso_value(s) < 9.0


def test_projection_windows_are_inside_the_data_and_ordered():
    s = _stats(_head_like(), 0.0, 130.0)
    mip = mode_fit.window("mip", s)
    avg = mode_fit.window("average", s)
    minip = mode_fit.window("minip", s)
    assert 51.0 < mip[0] < mip[1] <= 130.0, mip  # the bright half of the tissue
    assert avg[0] == 0.0 and 51.0 < avg[1] < mip[1], avg
    assert minip[0] < minip[1]
    assert mode_fit.window("dvr", s) is None


def test_mip_window_ends_at_the_maximum():
    # A window ending below the data's maximum turns every ray that meets a
    # brighter voxel white: MIP of a head was a white silhouette.
    s = _stats(_head_like(), 0.0, 130.0)
    assert mode_fit.window("mip", s)[1] == 130.0


def test_minip_floor_is_above_the_air_and_starts_the_window():
    s = _stats(_head_like(), 0.0, 130.0)
    floor = mode_fit.minip_floor(s)
    assert 5.0 < floor < 51.0, floor  # between the air and the tissue
    lo, hi = mode_fit.window("minip", s)
    assert lo < floor < hi  # the floor itself is visible on the ramp


def test_iso_window_puts_the_iso_value_on_the_brightest_entry():
    s = _stats(_head_like(), 0.0, 130.0)
    table = np.zeros((256, 4), np.float32)
    table[:, 3] = np.linspace(0, 1, 256)
    table[:, :3] = np.sin(np.linspace(0, np.pi, 256))[:, None]  # brightest at the middle
    lo, hi = mode_fit.window("iso", s, iso=30.0, table=table)
    t = (30.0 - lo) / (hi - lo)
    assert abs(t - 0.5) < 0.01, t


def test_projection_table_scales_opacity_to_one_and_keeps_colours():
    table = np.zeros((8, 4), np.float32)
    table[:, 0] = 0.5
    table[:, 3] = np.linspace(0, 0.25, 8)
    out = mode_fit.projection_table(table)
    assert np.isclose(out[:, 3].max(), 1.0)
    assert np.allclose(out[:, 3], table[:, 3] * 4.0)
    assert np.allclose(out[:, :3], table[:, :3])
    assert np.allclose(mode_fit.projection_table(np.zeros((4, 4))), 0.0)
