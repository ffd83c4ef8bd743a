"""Presets fitted to the data (no bpy, tested in plain Python): what kind
of data a volume holds, where its background ends and its foreground
quantiles lie (from the library's histogram, vxl_volume_histogram), and the
window and ColorRamp stops a preset gets on it.

CT presets are in Hounsfield units and are used as they are on CT. On MR
and other arbitrary-unit data a preset is placed by the quantiles of the
non-background voxels (tf_presets.Preset.fit), so the same preset works on
data that spans 0..130 and on data that spans 0..4000.
"""

import numpy as np

from . import tf_presets

KINDS = ("ct", "mr", "pet", "other")
HISTOGRAM_BINS = 1024  # the histogram presets are fitted with (runtime.open_volume)
_DEFAULT_PRESET = {"ct": "CT", "mr": "MRI", "pet": "HOT", "other": "MRI"}


def guess_kind(value_min, value_max, modality=""):
    """'ct', 'mr', 'pet' or 'other'. A DICOM modality decides when there is
    one; otherwise data reaching Hounsfield air (about -1024, scanners pad
    with down to -3024) and bone (a few hundred and up) is CT, and anything
    else is arbitrary-unit data, treated like MR."""
    m = (modality or "").strip().upper()
    if m == "CT":
        return "ct"
    if m == "MR":
        return "mr"
    if m in ("PT", "NM"):
        return "pet"
    if -4000.0 <= value_min <= -500.0 and value_max >= 300.0:
        return "ct"
    return "mr" if not m else "other"


def default_preset(kind):
    """The preset an import of this kind of data starts with."""
    return _DEFAULT_PRESET.get(kind, "MRI")


class DataStats:
    """Background and foreground quantiles from a histogram: `counts` in
    equal bins over [lo, hi].

    The background is the peak at the low end of the histogram (air around
    a head, zeros around a skull-stripped brain, CT air) when the
    histogram's mode lies in its lowest quarter and stands out (three times
    the median of the occupied bins above it): it ends at the first valley
    after that peak (counts smoothed over ~1% of the range). The voxels above
    are the foreground. With no such peak, every voxel is foreground."""

    def __init__(self, counts, lo, hi):
        c = np.asarray(counts, np.float64).ravel()
        self.lo, self.hi = float(lo), float(hi)
        if not self.hi > self.lo:
            self.hi = self.lo + 1.0
        self.counts = c
        n = len(c)
        self.bin_width = (self.hi - self.lo) / max(n, 1)
        self.first_foreground_bin, peak_end = self._valley(c)
        self.background_peak_end = self.lo + peak_end * self.bin_width
        fg = c[self.first_foreground_bin:]
        if fg.sum() <= 0:  # nothing above the background: use every voxel
            self.first_foreground_bin = 0
            fg = c
        self._fg = fg
        self._cum = np.concatenate([[0.0], np.cumsum(fg)])

    @staticmethod
    def _valley(c):
        """(first foreground bin, bin where the background peak has fallen
        to half), both 0 when there is no background."""
        n = len(c)
        if n < 4 or c.sum() <= 0:
            return 0, 0
        k = max(1, n // 128)
        s = np.convolve(c, np.ones(2 * k + 1) / (2 * k + 1), mode="same")
        m = int(np.argmax(s))
        if m >= n // 4:
            return 0, 0
        above = s[m + 1:][c[m + 1:] > 0]
        if len(above) and s[m] < 3.0 * np.median(above):  # no peak standing out: no background
            return 0, 0
        i = m
        while i + 1 < n and s[i + 1] <= s[i]:
            i += 1
        if i == m:
            return 0, 0
        half = m + int(np.argmax(s[m:i + 1] < 0.5 * s[m]))
        return i, half

    @property
    def background_edge(self):
        """The value below which voxels are background (lo when none)."""
        return self.lo + self.first_foreground_bin * self.bin_width

    @property
    def background_fraction(self):
        total = self.counts.sum()
        return float(self.counts[:self.first_foreground_bin].sum() / total) if total > 0 else 0.0

    def quantile(self, q):
        """The q quantile (0..1) of the foreground voxels, in data units,
        interpolated within bins; 0 is the lowest occupied foreground bin's
        lower edge and 1 the highest one's upper edge."""
        cum = self._cum
        total = cum[-1]
        start = self.lo + self.first_foreground_bin * self.bin_width
        if total <= 0:
            return self.lo + q * (self.hi - self.lo)
        q = min(max(float(q), 0.0), 1.0)
        occupied = np.nonzero(self._fg > 0)[0]
        if q <= 0.0:
            return start + occupied[0] * self.bin_width
        if q >= 1.0:
            return start + (occupied[-1] + 1) * self.bin_width
        target = q * total
        j = int(np.searchsorted(cum, target, side="left")) - 1  # bin holding the target
        j = min(max(j, 0), len(self._fg) - 1)
        inside = (target - cum[j]) / self._fg[j] if self._fg[j] > 0 else 0.0
        return start + (j + min(max(inside, 0.0), 1.0)) * self.bin_width


    @property
    def few_valued(self):
        """Masks, labels, binary phantoms: the foreground's quantiles sit
        within a tenth of the span from the background peak to the maximum,
        so they say nothing about where a ramp should go."""
        span = self.hi - self.background_peak_end
        return span > 0 and self.quantile(0.995) - self.quantile(0.0) < 0.1 * span

    def level(self, q):
        """Where presets put share q of the foreground: its q quantile, or
        for few-valued data share q of the span from the background peak
        (where it has fallen to half) to the maximum, so the edges between
        the values stay visible."""
        if self.few_valued:
            start = self.background_peak_end
            return start + min(max(q, 0.0), 1.0) * (self.hi - start)
        return self.quantile(q)


def never_empty(lo, hi):
    """(lo, hi) as floats, hi moved just above lo when it is not above it,
    so a window always has a width."""
    if not hi > lo:
        hi = lo + max(abs(lo), 1.0) * 1e-3
    return float(lo), float(hi)


def fit_window(stats, low_quantile=0.0, high_quantile=0.995):
    """(low, high) spanning the foreground from one quantile to another,
    inside the data range; never empty."""
    lo = stats.level(low_quantile)
    hi = stats.level(high_quantile)
    return never_empty(max(lo, stats.lo), min(hi, stats.hi))


FLOOR_ENTRIES = 3  # transparent table entries kept below a preset's first rise (place)


def place(preset, kind, stats):
    """(low, high, stops) for `preset` (a tf_presets.Preset or its key) on
    data of `kind` described by `stats` (DataStats): the window in data
    units and the ColorRamp stops [(position 0..1, rgba)] over it.

    Hounsfield presets on CT keep their units. Otherwise preset units are
    mapped linearly so the preset's fit anchors land on the data's
    foreground quantiles, and the window is clipped to the data range
    (values beyond it do not occur, so nothing visible is lost; the ramp
    holds the preset's colours at the clipped ends). Either way the
    window starts at the last stop before the preset's opacity first
    rises: below that the preset is transparent and the table clamps, so
    its entries are spent where the preset changes."""
    pr = tf_presets.PRESETS[preset] if isinstance(preset, str) else preset
    u = np.array([s[0] for s in pr.stops], np.float64)
    alpha = np.array([s[1][3] for s in pr.stops], np.float64)
    if pr.hu and kind == "ct":
        x = u.copy()
        clip = False
    else:
        u_a, q_a, u_b, q_b = pr.fit
        d_a, d_b = stats.level(q_a), stats.level(q_b)
        # Anchors at least 2% of the foreground's span apart: a plateau
        # (many voxels at one value) must not squeeze the ramp to a step.
        least = 0.02 * (stats.level(1.0) - stats.level(0.0))
        if d_b - d_a < least:
            d_a = d_b - least
        if not d_b > d_a:
            d_b = d_a + max(abs(d_a), 1.0) * 1e-3
        x = d_a + (u - u_a) * (d_b - d_a) / (u_b - u_a)
        clip = True
    visible = np.nonzero(alpha > 0)[0]
    lo = x[max(visible[0] - 1, 0)] if len(visible) else x[0]
    hi = x[-1]
    if len(visible) and visible[0] > 0:
        # A few table entries of exact transparency below the first rise:
        # the library skips a brick only when every entry its values can
        # reach (one either side, for filtering) is transparent, so a ramp
        # that rises from entry 0 leaves even pure background unskippable
        # (ch2better's F12 frame 10x slower). 3 of 255 entries move the
        # rise by about 1% of the window.
        f = FLOOR_ENTRIES / (tf_presets.TABLE_SIZE - 1)
        lo -= f * (hi - lo) / (1.0 - f)
    if clip:
        lo, hi = max(lo, stats.lo), min(hi, stats.hi)
    if not hi > lo:
        hi = lo + max(abs(lo), 1.0) * 1e-3
    inside = (x > lo) & (x < hi)
    xs = np.concatenate([[lo], x[inside], [hi]])
    rgba = pr.rgba_at(np.interp(xs, x, u))  # x is an increasing linear map of u
    stops = [(float((v - lo) / (hi - lo)), tuple(float(c) for c in col)) for v, col in zip(xs, rgba)]
    return float(lo), float(hi), stops


def table(preset, kind, stats, size=tf_presets.TABLE_SIZE):
    """The (size, 4) table the placed preset gives over its window: what
    the ColorRamp must reproduce."""
    return tf_presets.stops_table(place(preset, kind, stats)[2], size)
