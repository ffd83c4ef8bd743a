"""The viewport's adaptive interactive resolution (plugin/core/resolution_policy.py):
given measured frame times and pixel counts, the next scale aims at the
frame budget, is clamped, moves smoothly, and the still view refines in
visible steps."""

import math

import pytest

from voxlight.core.resolution_policy import TARGET_SECONDS, ScalePolicy, refine_scales

FULL = 1321 * 852  # the viewport of the report, at scale 1


def simulate(policy, seconds_per_pixel, frames, max_scale=1.0, overhead=0.0):
    """Orbit for `frames` frames on a machine with this cost; the scales used."""
    scales = []
    for _ in range(frames):
        s = policy.next_scale(FULL, max_scale)
        pixels = round(FULL * s * s)
        policy.observe(overhead + seconds_per_pixel * pixels, pixels)
        scales.append(s)
    return scales


@pytest.mark.parametrize("cost", [1e-6, 4e-7, 1e-7])
def test_converges_to_the_frame_budget(cost):
    p = ScalePolicy(0.35)
    scales = simulate(p, cost, 30)
    expected = math.sqrt(TARGET_SECONDS / (cost * FULL))
    assert scales[-1] == pytest.approx(min(expected, 1.0), rel=0.02)
    # The predicted frame time is the budget (or less when clamped).
    assert cost * FULL * scales[-1] ** 2 <= TARGET_SECONDS * 1.05


def test_clamped_to_the_artists_maximum_and_a_floor():
    fast = ScalePolicy(0.35)
    assert max(simulate(fast, 1e-10, 30, max_scale=0.35)) == pytest.approx(0.35)
    slow = ScalePolicy(0.35, min_scale=0.05)
    assert min(simulate(slow, 1e-3, 30)) == pytest.approx(0.05)


def test_changes_are_gradual():
    p = ScalePolicy(0.35, max_step=1.5)
    scales = simulate(p, 1e-9, 10)  # much faster than the start assumes
    ratios = [b / a for a, b in zip([0.35] + scales, scales)]
    assert max(ratios) <= 1.5 + 1e-9 and scales[-1] == pytest.approx(1.0)
    scales = simulate(p, 1e-5, 10)  # a sudden slow transfer function
    ratios = [a / b for a, b in zip([1.0] + scales, scales)]
    assert max(ratios) <= 1.5 + 1e-9


def test_one_slow_frame_does_not_collapse_the_resolution():
    p = ScalePolicy(0.35)
    simulate(p, 2e-7, 30)
    steady = p.scale
    p.observe(50 * 2e-7 * FULL * steady ** 2, FULL * steady ** 2)  # a hiccup, 50x slower
    after = p.next_scale(FULL, 1.0)
    assert after >= steady / 1.5 - 1e-9
    assert simulate(p, 2e-7, 20)[-1] == pytest.approx(steady, rel=0.02)


def test_smaller_footprint_allows_a_higher_scale():
    p = ScalePolicy(0.2)
    simulate(p, 1e-6, 30)
    whole = p.scale
    for _ in range(30):
        s = p.next_scale(FULL / 4, 1.0)
        p.observe(1e-6 * FULL / 4 * s * s, FULL / 4 * s * s)
    assert p.scale == pytest.approx(min(1.0, 2 * whole), rel=0.02)


def test_nothing_measured_keeps_the_start_and_bad_samples_are_ignored():
    p = ScalePolicy(0.35)
    assert p.next_scale(FULL, 1.0) == pytest.approx(0.35)
    p.observe(0.0, 1000)
    p.observe(0.1, 0)
    p.observe(float("nan"), 1000)
    assert p.seconds_per_pixel is None
    assert p.next_scale(0, 1.0) == pytest.approx(0.35)
    assert p.next_scale(FULL, 0.2) == pytest.approx(0.2)  # the maximum still applies


def test_fixed_cost_per_frame_is_learnt():
    # 50 ms per call whatever the size, plus the pixels: the pixels get the
    # other 50 ms (a per-pixel-only model would shrink the preview far more).
    p = ScalePolicy(0.35)
    scales = simulate(p, 1e-7, 40, overhead=0.05)
    assert p.overhead == pytest.approx(0.05, rel=0.05)
    assert scales[-1] == pytest.approx(math.sqrt(0.05 / (1e-7 * FULL)), rel=0.05)


def test_overhead_beyond_the_budget_does_not_collapse_the_preview():
    # A call costs 0.2 s however small: the pixels get a quarter of the
    # budget instead of the smallest scale.
    p = ScalePolicy(0.35)
    scales = simulate(p, 1e-7, 40, overhead=0.2)
    assert scales[-1] == pytest.approx(math.sqrt(0.025 / (1e-7 * FULL)), rel=0.1)
    assert scales[-1] > 2 * p.min_scale


def test_refinement_steps():
    assert refine_scales(0.2, 1.0) == (0.5, 1.0)   # preview, half, full
    assert refine_scales(0.45, 1.0) == (1.0,)      # half barely sharper: straight to full
    assert refine_scales(0.1, 0.5) == (0.25, 0.5)
