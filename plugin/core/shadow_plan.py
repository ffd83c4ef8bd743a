"""Planning of the volume's shadows on the scene in F12: which
light goes into which Cycles light group, and the compositor nodes that
multiply each group's light by its transmittance. No bpy: the Blender side
(scene_shadows.py, compositor.py) carries the plan out, and
tests/python/test_shadow_plan.py checks it, the node graph included, by
evaluating it on arrays.

What the nodes compute. Cycles gives, per light group g, a pass LG_g with the
light of the group's lights (Render Layers output "Combined_<g>"). The
library gives, per group, the transmittance T_g from every visible scene
point to the group's lights through the volume. With S_g = 1 - T_g (the
shadow amount, stored in the image "Voxlight Shadow <g>"):

    result = Image - sum_g LG_g * S_g  =  Image + sum_g LG_g * (T_g - 1)

so each group's light is multiplied by its transmittance and everything not
in a group (the world, emission, lights the add-on does not shadow) stays.
Where an engine has no light groups (EEVEE), the whole image is multiplied
by one factor per pixel, 1 - F with F = sum_l w_l (1 - T_l) and w_l each
light's share of the pixel's light, from geometry (core/light_shares.py;
F is stored in the image KEY_IMAGE):

    result = Image - Image * F

Subtracting EEVEE's direct-light passes times the shadow instead striped
the shadows: the passes hold about 1 % precision, and where direct light is
nearly all the light, what is left after the subtraction is that rounding.

Light groups. A light the user put in a group keeps it (the group is then
shadowed as a whole, by its lights' transmittances weighted by intensity).
A light in no group gets one of its own, GROUP_PREFIX + its name, recorded
on the light (ASSIGNED_PROP) so that revert() takes back exactly what the
add-on did and never a group the user made.
"""

import re
from typing import NamedTuple

GROUP_PREFIX = "Voxlight_"
ASSIGNED_PROP = "voxlight_lightgroup"   # custom property: the group the add-on gave a light
NODE_PREFIX = "Voxlight Shadow"         # every compositor node of the shadow chain
NODE_OUT = NODE_PREFIX + " Out"         # the chain's last node (feeds the Alpha Over)
IMAGE_PREFIX = "Voxlight Shadow "       # + group name (or KEY_IMAGE): 1 - transmittance
KEY_IMAGE = IMAGE_PREFIX + "Key Light"

MODE_LIGHT_GROUPS = "light_groups"
MODE_DIRECT = "direct"

# Blender's light group names hold letters, digits and underscores only.
_BAD = re.compile(r"[^A-Za-z0-9_]")


def group_name(light_name, taken=()):
    """The add-on's light group name for a light: GROUP_PREFIX + the name
    with every other character an underscore, made unique among `taken`."""
    base = GROUP_PREFIX + _BAD.sub("_", light_name)
    name, i = base, 1
    while name in taken:
        name = "%s_%d" % (base, i)
        i += 1
    return name


class Light(NamedTuple):
    """A light as the plan needs it: object name, its light group now ("" =
    none), the group the add-on gave it ("" = none) and its weight
    (intensity times its brightest colour channel)."""
    name: str
    lightgroup: str = ""
    assigned: str = ""
    weight: float = 1.0


class GroupPlan(NamedTuple):
    groups: dict       # group name -> [light names], in the lights' order
    assign: dict       # light name -> group the add-on sets (and records)
    create: list       # light groups to add to the view layer


def plan_groups(lights, existing_groups=()):
    """Which group shadows each light. A light in a group the user chose
    keeps it; one in no group (or still in the one the add-on gave it)
    gets the add-on's own group."""
    existing = set(existing_groups)
    user = {l.lightgroup for l in lights if l.lightgroup and l.lightgroup != l.assigned}
    taken = set(user)
    groups, assign, create = {}, {}, []
    for l in lights:
        if l.lightgroup and l.lightgroup != l.assigned:
            g = l.lightgroup
        else:
            g = l.assigned if l.assigned and l.assigned not in taken else group_name(l.name, taken)
            taken.add(g)
            if l.lightgroup != g or l.assigned != g:
                assign[l.name] = g
        groups.setdefault(g, []).append(l.name)
        if g not in existing and g not in create:
            create.append(g)
    return GroupPlan(groups, assign, create)


def revert(lights, existing_groups=()):
    """(light names to take out of their group, groups to remove): the
    add-on's assignments that are still as it left them, and its groups
    that no light outside the add-on's assignments uses."""
    reset = [l.name for l in lights if l.assigned and l.lightgroup == l.assigned]
    kept = {l.lightgroup for l in lights if l.lightgroup and l.name not in reset}
    remove = [g for g in existing_groups if g.startswith(GROUP_PREFIX) and g not in kept]
    return reset, remove


def group_weights(members, weight_of):
    """{light name: share} of a group's lights by weight (equal shares when
    all weigh nothing): a group's transmittance is its lights' mean, which
    is exact for a group of one light."""
    w = [max(float(weight_of.get(n, 0.0)), 0.0) for n in members]
    total = sum(w)
    if total <= 0.0:
        return {n: 1.0 / len(members) for n in members} if members else {}
    return {n: wi / total for n, wi in zip(members, w)}


def image_name(group):
    return IMAGE_PREFIX + group


# ----------------------------------------------------------- node graph

class Node(NamedTuple):
    """One compositor node: name, kind ("image" or a mix blend type
    MULTIPLY / ADD / SUBTRACT), inputs (for a mix: (a, b) sources; for an
    image: its image name) and location (x, y). A source is ("pass", key)
    for a Render Layers output (PASS_SOCKETS), ("node", name) or
    ("origin",) for what fed the chain (the render's Image)."""
    name: str
    kind: str
    inputs: tuple
    location: tuple


# Render Layers outputs per pass key: the names differ between versions
# (5.0 spells them out); the Blender side takes the first that exists.
PASS_SOCKETS = {
    "diffuse_direct": ("DiffDir", "Diffuse Direct"),
    "diffuse_color": ("DiffCol", "Diffuse Color"),
    "glossy_direct": ("GlossDir", "Glossy Direct"),
    "glossy_color": ("GlossCol", "Glossy Color"),
}


def lightgroup_socket(group):
    return "Combined_" + group


def node_plan(mode, groups=(), origin=(0.0, 0.0)):
    """The chain's nodes, in build order; the last is NODE_OUT. mode
    MODE_LIGHT_GROUPS: one multiply and one subtract per group in `groups`
    (a group's pass is ("pass", "Combined_<g>")); MODE_DIRECT: the image
    times 1 - F, F the per-light shadow weighted by each light's share."""
    x, y = origin
    nodes = []
    if mode == MODE_LIGHT_GROUPS:
        groups = list(groups)
        if not groups:
            return []
        acc = ("origin",)
        for i, g in enumerate(groups):
            gx = x + 200 * (i + 1)
            img = "%s Image %s" % (NODE_PREFIX, g)
            mul = "%s Multiply %s" % (NODE_PREFIX, g)
            sub = NODE_OUT if i == len(groups) - 1 else "%s Subtract %s" % (NODE_PREFIX, g)
            nodes.append(Node(img, "image", (image_name(g),), (gx - 180, y - 300 - 40 * i)))
            nodes.append(Node(mul, "MULTIPLY", (("pass", lightgroup_socket(g)), ("node", img)),
                              (gx, y - 200)))
            nodes.append(Node(sub, "SUBTRACT", (acc, ("node", mul)), (gx + 100, y)))
            acc = ("node", sub)
        return nodes
    if mode == MODE_DIRECT:
        img = NODE_PREFIX + " Image Key"
        return [
            Node(img, "image", (KEY_IMAGE,), (x + 200, y - 300)),
            Node(NODE_PREFIX + " Multiply", "MULTIPLY", (("origin",), ("node", img)),
                 (x + 400, y - 200)),
            Node(NODE_OUT, "SUBTRACT", (("origin",), ("node", NODE_PREFIX + " Multiply")),
                 (x + 600, y)),
        ]
    raise ValueError("unknown shadow mode %r" % (mode,))


def choose_mode(engine, has_lightgroups):
    """MODE_LIGHT_GROUPS where the engine gives light group passes (Cycles,
    Blender 3.2+), else MODE_DIRECT (EEVEE and others), with the sentence
    the panel and the console show for the fallback (None when exact)."""
    if engine == "CYCLES" and has_lightgroups:
        return MODE_LIGHT_GROUPS, None
    return MODE_DIRECT, ("%s has no light group passes: the volume's shadow darkens each "
                         "light's estimated share of the light (specular, area lights and "
                         "the meshes' own shadows approximate)" % _ENGINE_NAMES.get(engine, engine))


_ENGINE_NAMES = {"BLENDER_EEVEE": "EEVEE", "BLENDER_EEVEE_NEXT": "EEVEE",
                 "BLENDER_WORKBENCH": "Workbench", "CYCLES": "Cycles"}
