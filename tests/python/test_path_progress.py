"""core/path_progress.py: the viewport's running mean of path samples
equals the mean of all of them, whatever the passes' sizes, and the pass
offsets stop at the target."""
import numpy as np

from voxlight.core import path_progress


def test_running_mean_of_passes_is_the_mean_of_all_samples():
    rng = np.random.default_rng(7)
    samples = rng.random((10, 4, 5, 4)).astype(np.float32)
    mean, done = None, 0
    for size in (1, 3, 1, 5):
        img = samples[done:done + size].mean(axis=0)
        mean = path_progress.accumulate(mean, img, done, size)
        done += size
    assert np.abs(mean - samples.mean(axis=0)).max() < 1e-6
    # offset 0 starts again, whatever the mean held
    again = path_progress.accumulate(mean, samples[0], 0)
    assert np.array_equal(again, samples[0])


def test_next_offset_counts_up_to_the_target():
    assert [path_progress.next_offset(d, 4) for d in range(6)] == [0, 1, 2, 3, None, None]
    assert path_progress.next_offset(0, 0) == 0 and path_progress.next_offset(1, 0) is None
