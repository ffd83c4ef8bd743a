"""plugin/core/shadow_plan.py: light groups for the volume's shadows in F12,
reverting them, and the compositor graph, evaluated on arrays."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "plugin"))
from core import shadow_plan as sp  # noqa: E402
from core.shadow_plan import Light  # noqa: E402


def test_group_names_are_blender_identifiers_and_unique():
    assert sp.group_name("Sun.001") == "Voxlight_Sun_001"
    assert sp.group_name("Key light", taken={"Voxlight_Key_light"}) == "Voxlight_Key_light_1"


def test_lights_without_a_group_get_their_own_and_user_groups_stay():
    lights = [Light("Sun"), Light("Fill", lightgroup="rim"), Light("Back", lightgroup="rim"),
              Light("Lamp.1")]
    plan = sp.plan_groups(lights, existing_groups=["rim"])
    assert plan.groups == {"Voxlight_Sun": ["Sun"], "rim": ["Fill", "Back"],
                           "Voxlight_Lamp_1": ["Lamp.1"]}
    assert plan.assign == {"Sun": "Voxlight_Sun", "Lamp.1": "Voxlight_Lamp_1"}
    assert plan.create == ["Voxlight_Sun", "Voxlight_Lamp_1"]  # "rim" is the user's, exists


def test_a_second_plan_changes_nothing():
    first = sp.plan_groups([Light("Sun")])
    again = sp.plan_groups([Light("Sun", "Voxlight_Sun", "Voxlight_Sun")],
                           existing_groups=first.create)
    assert again.groups == first.groups and again.assign == {} and again.create == []


def test_a_group_the_user_gave_after_the_addon_wins():
    plan = sp.plan_groups([Light("Sun", lightgroup="mine", assigned="Voxlight_Sun")])
    assert plan.groups == {"mine": ["Sun"]} and plan.assign == {}


def test_revert_takes_back_only_what_the_addon_did():
    lights = [Light("Sun", "Voxlight_Sun", "Voxlight_Sun"),        # ours, untouched: reset
              Light("Fill", "rim"),                                 # the user's
              Light("Lamp", "studio", "Voxlight_Lamp")]             # the user moved it since
    reset, remove = sp.revert(lights, ["Voxlight_Sun", "rim", "studio", "Voxlight_Lamp",
                                       "Voxlight_Old"])
    assert reset == ["Sun"]
    assert remove == ["Voxlight_Sun", "Voxlight_Lamp", "Voxlight_Old"]
    # A user's light that joined the add-on's group keeps that group alive.
    _r, remove = sp.revert([Light("Sun", "Voxlight_Sun", "Voxlight_Sun"),
                            Light("Mine", "Voxlight_Sun")], ["Voxlight_Sun"])
    assert remove == []


def test_group_weights():
    assert sp.group_weights(["a", "b"], {"a": 3.0, "b": 1.0}) == {"a": 0.75, "b": 0.25}
    assert sp.group_weights(["a", "b"], {}) == {"a": 0.5, "b": 0.5}


def _evaluate(nodes, passes, images, origin):
    """Run a node plan on arrays as the compositor would (mix nodes at
    factor 1 on colour)."""
    out = {}

    def src(s):
        if s[0] == "origin":
            return origin
        if s[0] == "pass":
            return passes[s[1]]
        return out[s[1]]
    ops = {"MULTIPLY": np.multiply, "ADD": np.add, "SUBTRACT": np.subtract}
    for n in nodes:
        out[n.name] = images[n.inputs[0]] if n.kind == "image" else ops[n.kind](*map(src, n.inputs))
    return out[sp.NODE_OUT]


def test_light_group_chain_multiplies_each_group_by_its_transmittance():
    rng = np.random.default_rng(1)
    groups = ["Voxlight_Sun", "rim"]
    lg = {g: rng.random((4, 5, 3)) for g in groups}
    rest = rng.random((4, 5, 3))          # world and emission: no group
    image = rest + sum(lg.values())
    t = {g: rng.random((4, 5, 3)) for g in groups}
    nodes = sp.node_plan(sp.MODE_LIGHT_GROUPS, groups)
    assert nodes[-1].name == sp.NODE_OUT and all(n.name.startswith(sp.NODE_PREFIX) for n in nodes)
    result = _evaluate(nodes, {sp.lightgroup_socket(g): lg[g] for g in groups},
                       {sp.image_name(g): 1.0 - t[g] for g in groups}, image)
    np.testing.assert_allclose(result, rest + sum(lg[g] * t[g] for g in groups), atol=1e-12)
    assert sp.node_plan(sp.MODE_LIGHT_GROUPS, []) == []


def test_direct_chain_multiplies_the_image_by_one_minus_the_shadow_amount():
    """No pass of the engine's is read: the image is multiplied by a smooth
    factor, so the passes' rounding cannot show (docs/scene_shadows.md)."""
    rng = np.random.default_rng(2)
    image = rng.random((3, 3, 3))
    amount = rng.random((3, 3, 3))
    nodes = sp.node_plan(sp.MODE_DIRECT)
    assert not [s for n in nodes if n.kind != "image" for s in n.inputs if s[0] == "pass"]
    result = _evaluate(nodes, {}, {sp.KEY_IMAGE: amount}, image)
    np.testing.assert_allclose(result, image * (1.0 - amount), atol=1e-12)


def test_mode_per_engine():
    assert sp.choose_mode("CYCLES", True) == (sp.MODE_LIGHT_GROUPS, None)
    mode, why = sp.choose_mode("BLENDER_EEVEE_NEXT", True)
    assert mode == sp.MODE_DIRECT and why.startswith("EEVEE has no light group passes")
    with pytest.raises(ValueError):
        sp.node_plan("nope")
