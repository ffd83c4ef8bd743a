"""The ctypes structs (plugin/core/native_abi.py) against the C headers: every
public struct's size, alignment and field offsets as the C compiler lays
them out, so a field added, moved or resized on one side only fails here.

The field names come from the headers' text (csrc/include/*.h), the numbers
from a small C program compiled against them: a name the parser got wrong
fails to compile, it cannot pass silently."""

import ctypes
import os
import re
import shutil
import subprocess

import pytest

import conftest
from voxlight.core import native

INCLUDE = os.path.join(conftest.ROOT, "csrc", "include")
HEADERS = ("voxlight.h", "voxlight_dev.h")

# Every struct of the headers and its ctypes twin.
BINDINGS = {
    "vxl_load_options": native.LoadOptions,
    "vxl_volume_desc": native.VolumeDesc,
    "vxl_volume_info": native.VolumeInfo,
    "vxl_dicom_series": native.DicomSeries,
    "vxl_renderer_options": native.RendererOptions,
    "vxl_renderer_info": native.RendererInfo,
    "vxl_light": native.Light,
    "vxl_light_shape": native.LightShape,
    "vxl_render_params": native.RenderParams,
    "vxl_clip_plane": native.ClipPlane,
    "vxl_label_entry": native.LabelEntry,
    "vxl_label_style": native.LabelStyle,
    "vxl_overlay_style": native.OverlayStyle,
    "vxl_channel_style": native.native_abi.ChannelStyle,
    "vxl_cutter": native.Cutter,
    "vxl_cutaway": native.Cutaway,
    "vxl_matcap": native.Matcap,
    "vxl_environment": native.Environment,
    "vxl_scene_shadows": native.SceneShadows,
    "vxl_slice_params": native.SliceParams,
    "vxl_grid_params": native.GridParams,
    "vxl_grid_info": native.GridInfo,
    "vxl_render_stats": native.RenderStats,
    "vxl_phantom_desc": native.PhantomDesc,
}


def header_structs():
    """{struct name: [field names in declaration order]} of every
    `typedef struct X { ... } X;` in the public headers."""
    structs = {}
    for h in HEADERS:
        with open(os.path.join(INCLUDE, h)) as f:
            text = f.read()
        text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
        text = re.sub(r"//[^\n]*", " ", text)
        for name, body, tail in re.findall(r"typedef\s+struct\s+(\w+)\s*\{(.*?)\}\s*(\w+)\s*;", text,
                                           flags=re.S):
            assert name == tail, "typedef struct %s { } %s" % (name, tail)
            fields = []
            for decl in body.split(";"):
                decl = re.sub(r"\[[^\]]*\]", "", decl).strip()  # array sizes
                if not decl:
                    continue
                fn = re.search(r"\(\s*\*\s*(\w+)\s*\)", decl)  # "int (*progress)(void *, ...)"
                if fn:
                    fields.append(fn.group(1))
                    continue
                first, *more = [d.strip() for d in decl.split(",")]
                fields.append(re.findall(r"\w+", first)[-1])  # "const float *scene_depth"
                fields.extend(more)  # "float ambient, diffuse, ..."
            structs[name] = fields
    return structs


def compiler_layout(structs):
    """{struct: (sizeof, alignof, [(field, offsetof, sizeof)])} from a C
    program compiled against the headers."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    assert cc, "no C compiler (cc) on PATH: the ABI test needs one"
    lines = ["#include <stddef.h>", "#include <stdio.h>", '#include "voxlight_dev.h"',
             "int main(void)", "{"]
    for s, fields in structs.items():
        lines.append('    printf("S %s %%zu %%zu\\n", sizeof(%s), _Alignof(%s));' % (s, s, s))
        for f in fields:
            lines.append('    printf("F %s %s %%zu %%zu\\n", offsetof(%s, %s), sizeof(((%s *)0)->%s));'
                         % (s, f, s, f, s, f))
    lines += ["    return 0;", "}"]
    return lines, cc


@pytest.fixture(scope="module")
def layout(tmp_path_factory):
    structs = header_structs()
    lines, cc = compiler_layout(structs)
    d = tmp_path_factory.mktemp("abi")
    src, exe = d / "layout.c", d / "layout"
    src.write_text("\n".join(lines) + "\n")
    r = subprocess.run([cc, "-std=c11", "-Wall", "-Werror", "-I", INCLUDE, str(src), "-o", str(exe)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    result = {}
    for line in out.splitlines():
        kind, s, *rest = line.split()
        if kind == "S":
            result[s] = (int(rest[0]), int(rest[1]), [])
        else:
            result[s][2].append((rest[0], int(rest[1]), int(rest[2])))
    return result


def test_every_header_struct_has_a_binding():
    assert set(header_structs()) == set(BINDINGS)


def test_the_parser_reads_the_fields_the_compiler_knows(layout):
    """A few fields whose declarations share a line or are pointers."""
    params = [f for f, _o, _s in layout["vxl_render_params"][2]]
    assert params[:3] == ["struct_size", "width", "height"]
    assert {"scene_depth", "window_low", "window_high", "ambient", "shininess", "reserved"} <= set(params)


@pytest.mark.parametrize("struct", sorted(BINDINGS))
def test_struct_layout_matches_the_compiler(layout, struct):
    size, align, fields = layout[struct]
    cls = BINDINGS[struct]
    assert [f for f, _o, _s in fields] == [f for f, *_t in cls._fields_], "field names and order"
    for name, offset, fsize in fields:
        d = getattr(cls, name)
        assert (d.offset, d.size) == (offset, fsize), "%s.%s: ctypes offset %d size %d, C %d %d" % (
            struct, name, d.offset, d.size, offset, fsize)
    assert ctypes.sizeof(cls) == size
    assert ctypes.alignment(cls) == align


def test_fallback_names_are_the_librarys():
    """The tuples the add-on registers with when no library loads are the
    library's own names, in its order."""
    lib = native.load_library()
    for kind, fallback in native.ENUM_FALLBACKS.items():
        assert lib.names(kind) == fallback, kind
