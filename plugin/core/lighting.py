"""The volume's lighting settings as library render parameters:
shading model, ambient occlusion, anisotropy and the illumination volumes'
resolution ("shadow quality"), how volumes from older files keep their
look, and the coarser illumination volume while a light is dragged in the
viewport. No bpy: properties are read by attribute, so tests/python
(test_lighting.py) covers all of it.

Defaults (a new volume): `shadowed` with an occlusion radius of 4 voxels
at strength 0.5. Shadows are what a new user should see at once; 4 voxels
darkens folds and crevices a few voxels deep (the cortex's sulci on a 1 mm
scan) without the wide, muddy darkening of a large radius, and half
strength keeps the ambient term from going black inside cavities
(Slicer's screen-space occlusion is off by default because its full
strength made images too dark). Anisotropy 0: isotropic scattering, the
neutral choice until an artist wants a forward-scattering glow.
"""

import math

DEFAULT_MODEL = "shadowed"
DEFAULT_OCCLUSION_RADIUS = 4.0   # voxels
DEFAULT_OCCLUSION_STRENGTH = 0.5

# Shadow quality -> vxl_render_params.illumination_size (cells along the
# illumination volume's longest side). The enum item's number is the size
# itself, so a saved file or a keyframe keeps meaning the same resolution.
# AUTO (0) lets the library choose within the memory budget.
SHADOW_QUALITIES = (
    ("AUTO", "Auto", "The library picks the resolution that suits the volume and the memory "
                     "budget", 0),
    ("LOW", "Low", "64 cells along the longest side: fast to rebuild, soft shadow edges", 64),
    ("MEDIUM", "Medium", "128 cells along the longest side", 128),
    ("HIGH", "High", "256 cells along the longest side: crisp shadows, slower to rebuild when "
                     "a light moves", 256),
)
_SIZE_OF = {key: size for key, _n, _d, size in SHADOW_QUALITIES}
# While a light is dragged in the viewport, a quality finer than this (the
# library's automatic size, AUTO_SIZE in csrc/light/illumination.c) drops to it:
# each redraw then sweeps 64^3 cells instead of 128^3 or 256^3 (1/8, 1/64),
# and the switch costs no extinction pass, which the library keeps when only
# the lights' grid gets coarser (about 0.9 s at 64 cells on ch2better under
# load, so a drag that rebuilt it at start and settle felt worse than none).
# Auto and Low are not coarsened: their light sweep is already the cheap
# one, and a switch would rebuild the occlusion volume twice per drag.
DRAG_ILLUMINATION_SIZE = 64

# Object.voxlight.tf_version from which volumes have these settings
# (tf.TF_VERSION is at least this). A volume from an older file has no
# stored shading model: it keeps the look it was saved with, Phong.
TF_LIGHTING = 3
LEGACY_MODEL = "phong"


def illumination_size(quality, dragging=False):
    """vxl_render_params.illumination_size of a shadow quality key; while a
    light is dragged, no finer than DRAG_ILLUMINATION_SIZE."""
    size = _SIZE_OF.get(quality, 0)
    return DRAG_ILLUMINATION_SIZE if dragging and size > DRAG_ILLUMINATION_SIZE else size


def shading_model_of(props):
    """The model a volume renders with. A volume from before TF_LIGHTING
    that was not upgraded yet (appended from an old file, whose load
    handler never ran) and never had a model set renders as it always did."""
    if props.tf_version < TF_LIGHTING and props.get("shading_model") is None:
        return LEGACY_MODEL
    return props.shading_model


def upgrade(props, old_version):
    """Bring a volume saved with tf_version `old_version` up to
    TF_LIGHTING, looking the same: Phong, the only model it had."""
    if old_version < TF_LIGHTING and props.get("shading_model") is None:
        props.shading_model = LEGACY_MODEL


def look_kwargs(props, dragging=False):
    """make_params keyword arguments of the volume's lighting settings."""
    strength = min(max(float(props.occlusion_strength), 0.0), 1.0)
    return dict(
        shading_model=shading_model_of(props),
        # The library reads a strength of 0 as 1: no occlusion is no radius.
        ambient_occlusion=max(float(props.occlusion_radius), 0.0) if strength > 0.0 else 0.0,
        occlusion_strength=strength,
        anisotropy=min(max(float(props.anisotropy), -0.99), 0.99),
        illumination_size=illumination_size(props.shadow_quality, dragging),
        # the path model: F12's samples (the viewport renders one a pass,
        # viewport.py), bounces, and the seed (the same frame, the same noise)
        path_samples=max(int(getattr(props, "path_samples", 0)), 1),
        path_bounces=max(int(getattr(props, "path_bounces", 0)), 0),
    )


def light_key(lights):
    """What of the lights decides the illumination volumes: positions,
    directions and shapes (not colour or intensity, which scale them)."""
    return tuple((tuple(l[0]), tuple(l[3]) if len(l) > 3 else ()) for l in lights)


class LightWatch:
    """Tells, per viewport redraw, whether a light is being dragged: its
    key changed since the last redraw, and the last change is younger than
    the settle time (the same test the viewport uses for the view)."""

    def __init__(self):
        self.key = None
        self.changed_at = -math.inf

    def update(self, lights, now, settle_time):
        """Seconds until the lights count as settled (> 0) while they are
        dragged, else None."""
        key = light_key(lights)
        if self.key is not None and key != self.key:
            self.changed_at = now
        self.key = key
        left = settle_time - (now - self.changed_at)
        return left if left > 0 else None
