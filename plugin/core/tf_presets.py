"""Transfer-function presets as ColorRamp stops (no bpy, tested in plain
Python).

Every preset the panel offers is a piecewise-linear function of "preset
units" given as stops [(u, (r, g, b, a)), ...], plus how it is placed on
data (tf_fit.place turns that into a window and ColorRamp stops):

  * the library's built-in tables (Gray, Bone, Hot, MRI, CT; csrc/frame/transfer.c)
    are re-computed here with the same formulas and reduced to at most
    MAX_STOPS stops whose linear interpolation stays within TABLE_TOLERANCE
    of the 256-entry table, so loading one into a ColorRamp reproduces what
    the library renders without a ramp;
  * 3D Slicer's volume-rendering presets (opacity and colour points in data
    units, Hounsfield units for CT).

Placement: `hu` presets are in Hounsfield units and used as they are on CT
data. Every preset also has `fit` anchors (u_a, q_a, u_b, q_b): preset unit
u_a goes to the q_a quantile of the data's non-background voxels and u_b to
the q_b quantile, which is how presets are placed on MR and other
arbitrary-unit data (and CT presets on data that is not CT).
"""

import numpy as np

TABLE_SIZE = 256          # the library's VXL_PRESET_TABLE_SIZE and the ramp's sampling
MAX_STOPS = 30            # Blender's ColorRamp holds 32 elements; 2 spare for cropping
TABLE_TOLERANCE = 0.004   # largest error of a built-in table rebuilt from its stops


def _smoothstep(a, b, x):
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def builtin_table(name, size=TABLE_SIZE):
    """The library's built-in table `name` (csrc/frame/transfer.c,
    vxl_preset_table), (size, 4) float32 straight RGBA over x in [0, 1]."""
    x = np.linspace(0.0, 1.0, size)
    one, zero = np.ones_like(x), np.zeros_like(x)
    if name == "gray":
        rgba = (x, x, x, 0.1 * x)
    elif name == "bone":  # ivory surfaces, soft ramp so thin bone still shows
        rgba = (0.85 + 0.15 * x, 0.8 + 0.2 * x, 0.7 + 0.3 * x, 0.6 * _smoothstep(0.1, 0.5, x))
    elif name == "hot":  # black-red-yellow-white heat map
        rgba = (np.minimum(1, 3 * x), np.minimum(1, np.maximum(0, 3 * x - 1)),
                np.minimum(1, np.maximum(0, 3 * x - 2)), 0.3 * _smoothstep(0.05, 0.6, x))
    elif name == "mri":  # skin in warm tone fading to white matter
        rgba = (0.8 + 0.2 * x, 0.65 + 0.3 * x, 0.55 + 0.4 * x, 0.25 * _smoothstep(0.15, 0.45, x))
    elif name == "ct":  # soft tissue faint red, bone opaque ivory
        s = _smoothstep(0.3, 0.5, x)
        rgba = (0.9 * one, 0.5 + 0.45 * s, 0.4 + 0.5 * s,
                0.02 * _smoothstep(0.12, 0.2, x) + 0.7 * _smoothstep(0.3, 0.45, x))
    else:
        raise KeyError("no built-in table %r" % name)
    out = np.stack([np.asarray(c, np.float64) + zero for c in rgba], axis=1)
    return out.astype(np.float32)


def table_to_stops(table, tolerance=TABLE_TOLERANCE, max_stops=MAX_STOPS):
    """The fewest stops (position in [0, 1], rgba) found by greedy
    refinement whose linear interpolation reproduces `table` (n, 4) within
    `tolerance`: start from both ends and add the entry with the largest
    error until every entry is close enough or max_stops is reached."""
    t = np.asarray(table, np.float64)
    n = len(t)
    x = np.linspace(0.0, 1.0, n)
    keep = [0, n - 1]
    while len(keep) < max_stops:
        idx = sorted(keep)
        approx = np.stack([np.interp(x, x[idx], t[idx, c]) for c in range(4)], axis=1)
        err = np.abs(approx - t).max(axis=1)
        worst = int(np.argmax(err))
        if err[worst] <= tolerance:
            break
        keep.append(worst)
    return [(float(x[i]), tuple(float(v) for v in t[i])) for i in sorted(keep)]


def stops_table(stops, size=TABLE_SIZE):
    """A linear ColorRamp's table: `stops` [(position, rgba)] sampled at
    i / (size - 1), constant beyond the first and last stop."""
    pos = np.array([s[0] for s in stops], np.float64)
    col = np.array([s[1] for s in stops], np.float64)
    x = np.linspace(0.0, 1.0, size)
    return np.stack([np.interp(x, pos, col[:, c]) for c in range(4)], axis=1).astype(np.float32)


def _slicer_stops(opacity, color):
    """Stops at the union of a Slicer preset's opacity and colour points."""
    op = np.array(opacity, np.float64)
    co = np.array(color, np.float64)
    xs = np.unique(np.concatenate([op[:, 0], co[:, 0]]))
    return [(float(x), tuple([float(np.interp(x, co[:, 0], co[:, c])) for c in (1, 2, 3)]
                             + [float(np.interp(x, op[:, 0], op[:, 1]))])) for x in xs]


class Preset:
    def __init__(self, key, name, description, stops, fit, hu=False, group="any"):
        self.key = key
        self.name = name
        self.description = description
        self.stops = stops     # [(u, rgba)] in preset units, increasing u
        self.fit = fit         # (u_a, q_a, u_b, q_b): placement by the data's quantiles
        self.hu = hu           # stops are Hounsfield units: used as they are on CT
        self.group = group     # "any" or "ct": the menu's sections

    def rgba_at(self, u):
        """The preset's colour and opacity at preset units u (array)."""
        pos = np.array([s[0] for s in self.stops], np.float64)
        col = np.array([s[1] for s in self.stops], np.float64)
        u = np.asarray(u, np.float64)
        return np.stack([np.interp(u, pos, col[:, c]) for c in range(4)], axis=-1)


# 3D Slicer, Modules/Loadable/VolumeRendering/Resources/presets.xml
# (VolumeProperty "scalarOpacity" = x, opacity pairs; "colorTransfer" =
# x, r, g, b quadruples; x in data units: Hounsfield units for CT).
SLICER_PRESETS = {
    "CT_BONE": {
        "name": "CT Bone", "slicer": "CT-Bone",
        "opacity": [(-3024, 0), (-16.4458, 0), (641.385, 0.715686), (3071, 0.705882)],
        "color": [(-3024, 0, 0, 0), (-16.4458, 0.729412, 0.254902, 0.301961),
                  (641.385, 0.905882, 0.815686, 0.552941), (3071, 1, 1, 1)],
    },
    "CT_SOFT_TISSUE": {
        "name": "CT Soft Tissue", "slicer": "CT-Soft-Tissue",
        "opacity": [(-2048, 0), (-167.01, 0), (-160, 1), (240, 1), (3661, 1)],
        "color": [(-2048, 0, 0, 0), (-167.01, 0, 0, 0),
                  (-160, 0.0556356, 0.0556356, 0.0556356), (240, 1, 1, 1), (3661, 1, 1, 1)],
    },
    "CT_LUNG": {
        "name": "CT Lung", "slicer": "CT-Lung",
        "opacity": [(-1000, 0), (-600, 0), (-599, 0.15), (-400, 0.15), (-399, 0), (2952, 0)],
        "color": [(-1000, 0.3, 0.3, 1), (-600, 0, 0, 1), (-530, 0.134704, 0.781726, 0.0724558),
                  (-460, 0.929244, 1, 0.109473), (-400, 0.888889, 0.254949, 0.0240258),
                  (2952, 1, 0.3, 0.3)],
    },
    "MR_DEFAULT": {
        "name": "MR Default", "slicer": "MR-Default",
        "opacity": [(0, 0), (20, 0), (40, 0.15), (120, 0.3), (220, 0.375), (1024, 0.5)],
        "color": [(0, 0, 0, 0), (20, 0.168627, 0, 0), (40, 0.403922, 0.145098, 0.0784314),
                  (120, 0.780392, 0.607843, 0.380392), (220, 0.847059, 0.835294, 0.788235),
                  (1024, 1, 1, 1)],
    },
    "MR_ANGIO": {
        "name": "MR Angio", "slicer": "MR-Angio",
        "opacity": [(-2048, 0), (151.354, 0), (158.279, 0.4375), (190.112, 0.580357),
                    (200.873, 0.732143), (3661, 0.741071)],
        "color": [(-2048, 0, 0, 0), (151.354, 0, 0, 0), (158.279, 0.74902, 0.376471, 0),
                  (190.112, 1, 0.866667, 0.733333), (200.873, 0.937255, 0.937255, 0.937255),
                  (3661, 1, 1, 1)],
    },
}

# Where each preset goes on data that is not in Hounsfield units: preset
# unit u_a at the q_a quantile of the non-background voxels, u_b at q_b.
# Built-in tables span the whole foreground, as the library spans the data
# range; Slicer's MR presets keep their ramp (skin at the foreground's foot,
# Slicer's 220 near its top; angio: only the brightest few per cent, the
# vessels); CT presets put soft tissue low and bone at the top.
_FIT_BUILTIN = (0.0, 0.0, 1.0, 0.995)
_FIT_SLICER = {
    "CT_BONE": (-16.4458, 0.5, 641.385, 0.995),
    "CT_SOFT_TISSUE": (-167.01, 0.0, 240.0, 0.5),
    "CT_LUNG": (-1000.0, 0.0, 2952.0, 1.0),
    "MR_DEFAULT": (20.0, 0.0, 220.0, 0.95),
    "MR_ANGIO": (151.354, 0.97, 200.873, 0.995),
}

_BUILTIN_UI = {
    "gray": ("Gray", "Grey ramp, faint and even: shows everything, for a first look at any data"),
    "bone": ("Bone", "Ivory surfaces with a soft ramp (the library's Bone, placed by the "
                     "data's histogram); not 3D Slicer's CT Bone"),
    "hot": ("Hot", "Black-red-yellow-white heat map, for maps and arbitrary-unit data"),
    "mri": ("MRI", "Warm skin tone fading to white, placed by the data's histogram: the "
                   "default for MR and other arbitrary-unit data"),
    "ct": ("CT", "Soft tissue faint red, bone opaque ivory, window -1000..2000 HU: the "
                 "default for CT"),
}
_SLICER_UI = {
    "CT_BONE": "3D Slicer's CT-Bone: bone in Hounsfield units",
    "CT_SOFT_TISSUE": "3D Slicer's CT-Soft-Tissue: skin and soft tissue in Hounsfield units",
    "CT_LUNG": "3D Slicer's CT-Lung: the airways in Hounsfield units",
    "MR_DEFAULT": "3D Slicer's MR-Default, placed by the data's histogram",
    "MR_ANGIO": "3D Slicer's MR-Angio: only the brightest voxels (vessels), placed by the "
                "data's histogram",
}


def _build():
    out = {}
    for key, (name, desc) in _BUILTIN_UI.items():
        ct = key == "ct"
        stops = table_to_stops(builtin_table(key))
        if ct:  # the library's CT window: -1000..2000 HU
            stops = [(-1000.0 + 3000.0 * u, c) for u, c in stops]
            fit = (-1000.0, 0.0, 2000.0, 1.0)
        else:
            fit = _FIT_BUILTIN
        out[key.upper()] = Preset(key.upper(), name, desc, stops, fit, hu=ct,
                                  group="ct" if ct else "any")
    for key, pr in SLICER_PRESETS.items():
        ct = key.startswith("CT")
        out[key] = Preset(key, pr["name"], _SLICER_UI[key],
                          _slicer_stops(pr["opacity"], pr["color"]), _FIT_SLICER[key], hu=ct,
                          group="ct" if ct else "any")
    return out


PRESETS = _build()

# The old "Transfer Function" enum (the library's presets by name) -> preset
# key; "auto" is resolved from the data (tf_fit.default_preset).
LEGACY_ENUM = {"gray": "GRAY", "bone": "BONE", "hot": "HOT", "mri": "MRI", "ct": "CT"}


def menu_sections():
    """[(heading, [Preset, ...])] in menu order."""
    return [("Any Data (placed by histogram)", [p for p in PRESETS.values() if p.group == "any"]),
            ("CT (Hounsfield units)", [p for p in PRESETS.values() if p.group == "ct"])]
