"""How large the viewport's interactive frames are: the resolution scale
that keeps a moving view at about 10 frames a second, learnt from the
frames already rendered. No bpy, so it is tested in plain Python
(tests/python/test_resolution_policy.py).

A frame's time is a fixed cost per library call plus a cost per pixel it
renders (the library marches one ray per pixel, cropped to the volume's
footprint):

    seconds = overhead + seconds_per_pixel * pixels

The overhead is fitted (least squares) over the last frames whenever their
pixel counts differ enough to tell the two apart, and kept otherwise; the
seconds per pixel is what each frame's time leaves after the overhead,
smoothed over frames. The scale for the next frame is the one whose
predicted time fits the budget:

    overhead + seconds_per_pixel * pixels_at_scale_1 * scale**2 = target_seconds

When the overhead alone eats most of the budget (a slow software GL),
shrinking the picture cannot reach the budget, so the pixels still get a
quarter of it instead of the preview collapsing to the smallest scale.

Smooth: the seconds per pixel is a moving average (in log space, so a
single slow frame does not halve the resolution), and the scale moves by at
most a factor `max_step` per frame, so the picture does not pump. Clamped
to [min_scale, max_scale]; max_scale is the artist's "While Moving"
resolution, min_scale keeps the preview recognisable.

Also the refinement steps once the view is still (refine_scales): half the
still resolution first when that is noticeably sharper than the preview on
screen, then the full still resolution.
"""

import collections
import math

TARGET_SECONDS = 0.1   # ~10 frames a second while orbiting
MIN_SCALE = 0.05


class ScalePolicy:
    """Per viewport and volume: observe() each interactive frame's time,
    ask next_scale() for the next one."""

    def __init__(self, start_scale, target_seconds=TARGET_SECONDS, min_scale=MIN_SCALE,
                 smoothing=0.5, max_step=1.5):
        self.target_seconds = float(target_seconds)
        self.min_scale = float(min_scale)
        self.smoothing = float(smoothing)   # weight of the newest frame, 0..1
        self.max_step = float(max_step)     # largest scale change per frame
        self.scale = float(start_scale)
        self.seconds_per_pixel = None       # unknown until the first frame
        self.overhead = 0.0                 # fixed seconds per frame
        self._recent = collections.deque(maxlen=8)  # (pixels, seconds)

    def observe(self, seconds, pixels):
        """A frame of `pixels` rendered pixels took `seconds`. Frames with
        no pixels or no measurable time teach nothing."""
        if pixels <= 0 or not seconds > 0.0 or not math.isfinite(seconds):
            return
        self._recent.append((float(pixels), float(seconds)))
        self._fit_overhead()
        cost = max(seconds - self.overhead, 0.1 * seconds) / float(pixels)
        if self.seconds_per_pixel is None:
            self.seconds_per_pixel = cost
        else:
            a = self.smoothing
            self.seconds_per_pixel = math.exp(
                (1.0 - a) * math.log(self.seconds_per_pixel) + a * math.log(cost))

    def _fit_overhead(self):
        """Intercept of seconds over pixels, when the recent frames span
        enough pixel counts (at least 1.3x) to tell it from the slope; kept
        when they do not or the fit is implausible. Never more than the
        fastest recent frame took."""
        if len(self._recent) < 3:
            return
        xs = [x for x, _ in self._recent]
        ys = [y for _, y in self._recent]
        if max(xs) < 1.3 * min(xs):
            return
        n = float(len(xs))
        mx, my = sum(xs) / n, sum(ys) / n
        sxx = sum((x - mx) ** 2 for x in xs)
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
        intercept = my - slope * mx
        if slope > 0.0 and intercept >= 0.0:
            self.overhead = min(intercept, min(ys))

    def next_scale(self, pixels_at_full_scale, max_scale):
        """The scale for the next interactive frame, which would render
        `pixels_at_full_scale` pixels at scale 1; clamped to
        [min_scale, max_scale] and to max_step from the last scale."""
        hi = max(float(max_scale), self.min_scale)
        if self.seconds_per_pixel is None or pixels_at_full_scale <= 0:
            wanted = self.scale  # nothing measured yet: keep the start
        else:
            budget = max(self.target_seconds - self.overhead, 0.25 * self.target_seconds)
            wanted = math.sqrt(budget / (self.seconds_per_pixel * float(pixels_at_full_scale)))
        wanted = min(max(wanted, self.scale / self.max_step), self.scale * self.max_step)
        self.scale = min(max(wanted, self.min_scale), hi)
        return self.scale


def refine_scales(preview_scale, still_scale, sharper=1.25):
    """The scales of the frames that follow the preview once the view is
    still: (still/2, still) when half the still resolution is at least
    `sharper` times the preview's, else (still,)."""
    half = still_scale * 0.5
    if half >= preview_scale * sharper:
        return (half, still_scale)
    return (still_scale,)
