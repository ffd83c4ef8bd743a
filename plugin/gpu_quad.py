"""A full-screen quad and its shader, for the viewport's layers (the
volume's image in viewport.py, the scene shadows in
scene_shadows_viewport.py): `uv` runs over [0, 1]^2 across the view."""

import gpu
from gpu_extras.batch import batch_for_shader

_VERT = "void main() { uv = pos * 0.5 + 0.5; gl_Position = vec4(pos, 0.0, 1.0); }"


def quad_shader(name, samplers, fragment_source, constants=()):
    """(shader, batch) of a quad whose fragment shader reads the 2D float
    textures named in `samplers` (bound to units 0, 1, ...) at `uv` and
    writes `fragColor`; `constants` are (type, name) uniforms
    ("VEC4", "INT", ...)."""
    iface = gpu.types.GPUStageInterfaceInfo(name + "_iface")
    iface.smooth("VEC2", "uv")
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, "VEC2", "pos")
    info.vertex_out(iface)
    for unit, sampler in enumerate(samplers):
        info.sampler(unit, "FLOAT_2D", sampler)
    for kind, uniform in constants:
        info.push_constant(kind, uniform)
    info.fragment_out(0, "VEC4", "fragColor")
    info.vertex_source(_VERT)
    info.fragment_source(fragment_source)
    shader = gpu.shader.create_from_info(info)
    return shader, batch_for_shader(shader, "TRI_FAN",
                                    {"pos": ((-1, -1), (1, -1), (1, 1), (-1, 1))})
