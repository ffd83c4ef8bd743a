"""The add-on's Blender-free core: everything here runs in plain Python.

What belongs here: the ctypes binding of libvoxlight (native and its
native_* parts), the maths of placing, framing and depth-testing a volume,
the lighting and transfer-function logic read from objects by attribute
only, and the background workers (runtime, import_job, frames). These
modules never import bpy, mathutils, gpu or bgl, directly or through what
they import, so tests/python tests them without Blender
(tests/python/test_core_is_bpy_free.py enforces it).

What does not: anything that registers Blender classes, reads bpy data,
draws with gpu or reports through operators; that lives beside this folder
in plugin/ and calls in here.
"""
