#!/usr/bin/env python3
"""Bad-input catalogue for zcheck.

    python3 tests/bad_input/catalogue.py /path/to/zcheck /path/to/models_dir
            [--list] [-k SUBSTRING] [--all] [-v] [--keep]

Every case feeds zcheck one malformed input (a mesh, a camera file, a depth map, an output
path, an option) generated at test time into its own fresh folder, and demands:

  1. exit status 2 (bad input); 3 (internal failure) or anything else is a failure;
  2. exactly one line on stderr, starting 'zcheck: error:', matching a case-specific regex
     that names the culprit (file, option or JSON key, and/or value, and/or the rule);
  3. a time bound (default 20 s; 5 s for hostile inputs that could hang or allocate, with
     a bound on peak memory too; 2 s for suite output paths); a timeout is a "hang";
  4. no crash (a signal is reported as "crash (signal N)");
  5. the case folder is unchanged afterwards: pre-existing outputs ("old <name>\\n") are
     byte-identical, no new file appeared, no 'zcheck-tmp' temporary is left;
  6. stdout holds nothing that looks like a report.

Standard library only (python 3.11), except that the HDF5 depth-map cases write their files
with h5py (python3-h5py), imported inside their files= callables. Cases run on 2 worker
threads. The cases named in EXTRA (variations of the same code paths) run only with --all,
to keep the default run within ~90 s on 2 cores. The camera-format cases are made from zcheck's
own table of formats (`zcheck formats --json`), so --list without ZCHECK leaves them out. -v prints every case's stderr; --keep keeps
the case folders. Prints per-category counts and ends with the line "N passed, M failed";
exit 0 iff M == 0.
"""

from __future__ import annotations

import argparse
import base64
import concurrent.futures
import dataclasses
import hashlib
import json
import os
import re
import resource
import shlex
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from typing import Callable, Optional, Union

# --------------------------------------------------------------------------------------
# The case record
# --------------------------------------------------------------------------------------

FIFO = object()      # files[...] = FIFO: make a named pipe
DIR = object()       # files[...] = DIR: make a directory

FileSpec = Union[bytes, str, object, Callable[[str], None]]


@dataclasses.dataclass
class Case:
    category: str
    name: str
    argv: list                       # '{models}', '{examples}', '{dir}' are substituted
    expect: str                      # regex (re.search, case-insensitive) on the stderr line
    files: dict = dataclasses.field(default_factory=dict)   # relative path -> FileSpec
    setup: Optional[Callable[[str], None]] = None           # extra set-up in the case folder
    guard: tuple = ()                # outputs that exist in the scenario: "old <name>\n"
    status: int = 2
    limit: float = 20.0              # seconds
    fsize: Optional[int] = None      # RLIMIT_FSIZE in bytes (a full disk)
    max_rss_mb: Optional[float] = None


CASES: list[Case] = []


def case(category, name, argv, expect, **kw):
    CASES.append(Case(category, name, list(argv), expect, **kw))


HOSTILE = 5.0       # seconds: inputs that used to hang or allocate without bound
HOSTILE_RSS = 600   # MiB: a run that starts allocating for a declared size goes far beyond this

# --------------------------------------------------------------------------------------
# Input builders
# --------------------------------------------------------------------------------------


class Raw:
    """A number written verbatim into JSON (1e400, which Python cannot hold)."""

    def __init__(self, text):
        self.text = text


def to_json(value, indent=None):
    raws = {}

    def swap(v):
        if isinstance(v, Raw):
            key = f"@@raw{len(raws)}@@"
            raws[key] = v.text
            return key
        if isinstance(v, dict):
            return {k: swap(x) for k, x in v.items()}
        if isinstance(v, list):
            return [swap(x) for x in v]
        return v

    text = json.dumps(swap(value), indent=indent)
    for key, raw in raws.items():
        text = text.replace(json.dumps(key), raw)
    return text + "\n"


def camera(width=64, height=48, drop=(), **patch):
    """A valid 64x48 perspective camera of builtin:default; patch with dotted keys
    (camera(**{"projection.near": 0})); drop removes dotted keys."""
    cam = {
        "convention": "opengl",
        "image": {"width": width, "height": height},
        "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100},
        "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]},
        "depth": {"format": "float32", "reversed": False, "range": [0, 1]},
    }
    for dotted, value in patch.items():
        parts = dotted.split(".")
        node = cam
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
    for dotted in drop:
        parts = dotted.split(".")
        node = cam
        for p in parts[:-1]:
            node = node[p]
        del node[parts[-1]]
    return to_json(cam)


def camera_with(projection=None, view=None, **top):
    cam = {"image": {"width": 64, "height": 48}}
    cam["projection"] = projection or {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100}
    cam["view"] = view or {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]}
    cam.update(top)
    return to_json(cam)


GOOD_CAM = camera()
CAM640 = camera(640, 480)
# Looks straight up from (0,1,3), away from everything in builtin:default (looking along +z
# horizontally still sees the ground plane below the horizon).
AWAY_CAM = camera(**{"view.eye": [0, 1, 3], "view.target": [0, 11, 3], "view.up": [0, 0, -1]})
IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]


def ply_header(fmt, elements, first="ply", end=True):
    """elements: [(name, count, [property lines])]"""
    lines = [first, f"format {fmt} 1.0"]
    for name, count, props in elements:
        lines.append(f"element {name} {count}")
        lines += [f"property {p}" for p in props]
    if end:
        lines.append("end_header")
    return ("\n".join(lines) + "\n").encode()


XYZ = ["float x", "float y", "float z"]
FACE = ["list uchar int vertex_indices"]
STRIP = ["list int int vertex_indices"]
TRI = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]


def ply_ascii(verts=TRI, faces=((0, 1, 2),), vcount=None, fcount=None, vprops=XYZ, fprops=FACE,
              face_elem="face", vlines=None, flines=None, first="ply", end=True, extra_header=()):
    vl = vlines if vlines is not None else [" ".join(str(c) for c in v) for v in verts]
    fl = flines if flines is not None else [" ".join(str(i) for i in (len(f),) + tuple(f)) for f in faces]
    elements = [("vertex", len(vl) if vcount is None else vcount, vprops),
                (face_elem, len(fl) if fcount is None else fcount, fprops)]
    head = ply_header("ascii", elements, first=first, end=False).decode()
    head += "".join(x + "\n" for x in extra_header)
    if end:
        head += "end_header\n"
    return (head + "".join(x + "\n" for x in vl + fl)).encode()


def ply_binary(endian="<", verts=TRI, faces=((0, 1, 2),), vcount=None, fcount=None, cut=0,
               vtype="f", list_fmt=("B", "i"), list_len=None, face_elem="face"):
    """Binary PLY; endian '<' little or '>' big; cut removes bytes from the end."""
    fmt = "binary_little_endian" if endian == "<" else "binary_big_endian"
    names = {"f": "float", "d": "double"}
    ltypes = {"B": "uchar", "i": "int", "I": "uint", "H": "ushort"}
    head = ply_header(fmt, [
        ("vertex", len(verts) if vcount is None else vcount, [f"{names[vtype]} {a}" for a in "xyz"]),
        (face_elem, len(faces) if fcount is None else fcount,
         [f"list {ltypes[list_fmt[0]]} {ltypes[list_fmt[1]]} vertex_indices"]),
    ])
    body = b"".join(struct.pack(endian + vtype * 3, *v) for v in verts)
    for f in faces:
        n = len(f) if list_len is None else list_len
        body += struct.pack(endian + list_fmt[0], n) + struct.pack(endian + list_fmt[1] * len(f), *f)
    data = head + body
    return data[:len(data) - cut] if cut else data


def obj(*lines):
    return ("\n".join(lines) + "\n").encode()


def stl_binary(tris, count=None, cut=0, header=b"binary stl made by the zcheck bad-input catalogue"):
    head = header.ljust(80, b"\0")[:80] + struct.pack("<I", len(tris) if count is None else count)
    body = b"".join(struct.pack("<12fH", 0, 0, 1, *a, *b, *c, 0) for a, b, c in tris)
    data = head + body
    return data[:len(data) - cut] if cut else data


def stl_ascii(body):
    return ("solid t\n" + body + "endsolid t\n").encode()


STL_FACET = ("facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n"
             " endloop\nendfacet\n")


def gltf_parts(positions=TRI, indices=(0, 1, 2)):
    """(json dict without buffer uri, binary buffer) for one triangle."""
    pos = b"".join(struct.pack("<3f", *p) for p in positions)
    idx = struct.pack(f"<{len(indices)}H", *indices)
    buf = pos + idx
    buf += b"\0" * (-len(buf) % 4)
    lo = [min(p[i] for p in positions) for i in range(3)]
    hi = [max(p[i] for p in positions) for i in range(3)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(buf)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
    }
    return doc, buf


def gltf(mutate=None, uri=None, **kw):
    """A .gltf with an embedded data: URI buffer; mutate(doc) edits it."""
    doc, buf = gltf_parts(**kw)
    doc["buffers"][0]["uri"] = uri if uri is not None else (
        "data:application/octet-stream;base64," + base64.b64encode(buf).decode())
    if mutate:
        mutate(doc)
    return to_json(doc).encode()


def glb(mutate=None, magic=b"glTF", version=2, length=None, json_cut=0, json_declared=None, **kw):
    doc, buf = gltf_parts(**kw)
    if mutate:
        mutate(doc)
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    chunk0 = struct.pack("<I4s", len(js) if json_declared is None else json_declared, b"JSON") + js
    chunk1 = struct.pack("<I4s", len(buf), b"BIN\0") + buf
    if json_cut:
        body = chunk0[:len(chunk0) - json_cut]
    else:
        body = chunk0 + chunk1
    total = 12 + len(body)
    return magic + struct.pack("<II", version, total if length is None else length) + body


def pfm(width, height, value=5.0, channels=1, scale=-1.0, cut=0, header=None):
    """A float PFM filled with one value (little-endian: negative scale)."""
    head = header if header is not None else (
        f"{'Pf' if channels == 1 else 'PF'}\n{width} {height}\n{scale}\n".encode())
    n = width * height * channels
    data = head + struct.pack("<f", value) * n
    return data[:len(data) - cut] if cut else data


def png16(width, height, value=5000, cut=0):
    """A valid 16-bit greyscale PNG (colour type 0, bit depth 16)."""
    def chunk(kind, payload):
        return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", zlib.crc32(kind + payload))
    row = b"\0" + struct.pack(">H", value) * width
    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(row * height)) + chunk(b"IEND", b""))
    return data[:len(data) - cut] if cut else data


def garbage(n, seed=7):
    """Deterministic binary junk (with NULs, newlines and high bytes)."""
    out = bytearray()
    x = seed
    while len(out) < n:
        x = (x * 6364136223846793005 + 1442695040888963407) % 2**64
        out += (x >> 24).to_bytes(5, "little")
    return bytes(out[:n])


def symlink(target, name):
    def make(d):
        os.symlink(target, os.path.join(d, name))
    return make


def q(name):
    """Regex for a path as zcheck quotes it."""
    return re.escape(name)


def value_rx(value):
    """Regex for a value as a whole word, optionally quoted ('0' must not match '1024')."""
    return rf"(?<![\w.+-])'?{re.escape(value)}'?(?![\w.])"


MAP_CAM = {"cam.json": GOOD_CAM}
GOOD_MAP = pfm(64, 48, value=float("inf"))          # 64x48 eye-z map, all misses
MESH_ARGS = ["--width", "64", "--height", "48"]

# --------------------------------------------------------------------------------------
# Mesh files
# --------------------------------------------------------------------------------------


def mesh(name, filename, content, expect, limit=20.0, rss=None, cmd="check"):
    if cmd == "check":
        argv = ["check", "--scene", filename] + MESH_ARGS
        files = {filename: content}
    elif cmd == "export":
        argv = ["export", "--scene", filename, "--camera", "cam.json", "-o", "out.exr"]
        files = {filename: content, "cam.json": GOOD_CAM}
    else:
        argv = ["verify", "--scene", filename, "--camera", "cam.json", "--depth-map", "map.pfm", "--quantity", "eye-z"]
        files = {filename: content, "cam.json": GOOD_CAM, "map.pfm": GOOD_MAP}
    case("mesh", name, argv, expect, files=files, limit=limit, max_rss_mb=rss)


DEGENERATE = r"degenerate|zero area"

# PLY ---------------------------------------------------------------------------------
mesh("ply-binary-le-truncated-vertices", "t.ply", ply_binary("<", faces=(), fcount=0, cut=5),
     rf"'{q('t.ply')}'.*vertex.*(ends early|truncat|fewer|declares 3 items, more than)", limit=HOSTILE)
mesh("ply-binary-be-truncated-vertices", "t.ply", ply_binary(">", faces=(), fcount=0, cut=5),
     rf"'{q('t.ply')}'.*vertex.*(ends early|truncat|fewer|declares 3 items, more than)", limit=HOSTILE)
mesh("ply-binary-le-face-list-longer-than-data", "t.ply", ply_binary("<", list_len=9),
     rf"'{q('t.ply')}'.*face.*(ends early|more than the data|truncat)", limit=HOSTILE)
mesh("ply-binary-be-face-list-longer-than-data", "t.ply", ply_binary(">", list_len=9),
     rf"'{q('t.ply')}'.*face.*(ends early|more than the data|truncat)", limit=HOSTILE)
mesh("ply-ascii-face-list-longer-than-line", "t.ply", ply_ascii(flines=["9 0 1 2"]),
     rf"'{q('t.ply')}'.*face.*(fewer values|ends early|more than)", limit=HOSTILE)
mesh("ply-strip-list-count-huge", "t.ply",
     ply_binary("<", face_elem="tristrips", list_fmt=("i", "i"), list_len=268435456),
     rf"'{q('t.ply')}'.*268435456.*(more than|ends early)", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("ply-header-without-end_header", "t.ply", ply_ascii(end=False),
     rf"'{q('t.ply')}'.*(end_header|header)")
mesh("ply-22-byte-binary_big_", "t.ply", b"ply\nformat binary_big_",
     rf"'{q('t.ply')}'.*(end_header|header|format)", limit=HOSTILE)
mesh("ply-binary-2000000000-vertices", "t.ply", ply_binary("<", vcount=2000000000),
     rf"'{q('t.ply')}'.*2000000000.*(more than|bytes|exceeds|file)", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("ply-binary-be-2000000000-vertices", "t.ply", ply_binary(">", vcount=2000000000),
     rf"'{q('t.ply')}'.*2000000000.*(more than|bytes|exceeds|file)", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("ply-ascii-2000000000-vertices", "t.ply", ply_ascii(vcount=2000000000),
     rf"'{q('t.ply')}'.*(2000000000|ends early|fewer|more than)", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("ply-binary-more-vertices-than-present", "t.ply", ply_binary("<", vcount=4, faces=(), fcount=0),
     rf"'{q('t.ply')}'.*(vertex|4).*(ends early|more than|fewer|bytes)", limit=HOSTILE)
mesh("ply-ascii-more-vertices-than-present", "t.ply", ply_ascii(vcount=4, faces=(), fcount=0),
     rf"'{q('t.ply')}'.*vertex.*(ends early|fewer|declares 4 items, more than)", limit=HOSTILE)
mesh("ply-ascii-vertex-too-few-values", "t.ply", ply_ascii(vlines=["0 0 0", "1 0", "0 1 0"]),
     rf"'{q('t.ply')}'.*vertex 1.*fewer values")
mesh("ply-ascii-vertex-too-many-values", "t.ply", ply_ascii(vlines=["0 0 0", "1 0 0 7", "0 1 0"]),
     rf"'{q('t.ply')}'.*vertex 1.*more values")
mesh("ply-ascii-non-number", "t.ply", ply_ascii(vlines=["0 0 0", "1 abc 0", "0 1 0"]),
     rf"'{q('t.ply')}'.*vertex 1.*'abc.*not a number")
mesh("ply-strip-without-z", "t.ply",
     ply_ascii(vlines=["0 0", "1 0", "0 1"], vprops=["float x", "float y"], face_elem="tristrips",
               fprops=STRIP, flines=["3 0 1 2"]),
     rf"'{q('t.ply')}'.*no 'z' property")
mesh("ply-unknown-property-type", "t.ply", ply_ascii(vprops=["float x", "float y", "quad z"]),
     rf"'{q('t.ply')}'.*unknown property type 'quad'")
mesh("ply-list-count-float", "t.ply", ply_ascii(fprops=["list float int vertex_indices"]),
     rf"'{q('t.ply')}'.*list count.*integer")
mesh("ply-duplicate-property", "t.ply", ply_ascii(vprops=["float x", "float y", "float z", "float x"],
                                                   vlines=["0 0 0 0", "1 0 0 1", "0 1 0 0"]),
     rf"'{q('t.ply')}'.*'x'.*twice")
mesh("ply-unknown-header-keyword", "t.ply", ply_ascii(extra_header=["frobnicate 1"]),
     rf"'{q('t.ply')}'.*(unknown header keyword|frobnicate)")
mesh("ply-first-line-not-ply", "t.ply", ply_ascii(first="plx"),
     rf"'{q('t.ply')}'.*first line is not 'ply'")
mesh("ply-unknown-format", "t.ply", ply_header("binary_middle_endian", [("vertex", 3, XYZ)]),
     rf"'{q('t.ply')}'.*binary_middle_endian")
mesh("ply-element-count-not-a-number", "t.ply", ply_header("ascii", [("vertex", "three", XYZ)]),
     rf"'{q('t.ply')}'.*count.*(whole number|number)")
mesh("ply-no-vertex-element", "t.ply", ply_header("ascii", [("face", 1, FACE)]) + b"3 0 1 2\n",
     rf"'{q('t.ply')}'.*no vertex element")
mesh("ply-ascii-face-index-out-of-range", "t.ply", ply_ascii(faces=((0, 1, 7),)),
     rf"'{q('t.ply')}'.*vertex 7.*3")
mesh("ply-binary-face-index-out-of-range", "t.ply", ply_binary("<", faces=((0, 1, 3),)),
     rf"'{q('t.ply')}'.*vertex 3.*3")
mesh("ply-binary-be-face-index-out-of-range", "t.ply", ply_binary(">", faces=((0, 1000000, 2),)),
     rf"'{q('t.ply')}'.*1000000")
mesh("ply-ascii-negative-face-index", "t.ply", ply_ascii(faces=((0, -1, 2),)),
     rf"'{q('t.ply')}'.*-1.*(out of range|negative)")
mesh("ply-binary-negative-face-index", "t.ply", ply_binary("<", faces=((0, -5, 2),)),
     rf"'{q('t.ply')}'.*-5.*(out of range|negative)")
mesh("ply-face-with-2-indices", "t.ply", ply_ascii(faces=((0, 1),)),
     rf"'{q('t.ply')}'.*face 0.*at least 3.*2")
mesh("ply-ascii-nan-coordinate", "t.ply", ply_ascii(vlines=["0 0 0", "nan 0 0", "0 1 0"]),
     rf"'{q('t.ply')}'.*(nan).*(finite|number)")
mesh("ply-ascii-inf-coordinate", "t.ply", ply_ascii(vlines=["0 0 0", "1 0 0", "0 inf 0"]),
     rf"'{q('t.ply')}'.*inf.*(finite|number)")
mesh("ply-binary-inf-coordinate", "t.ply", ply_binary("<", verts=[(0, 0, 0), (1, 0, 0), (0, float("inf"), 0)]),
     rf"'{q('t.ply')}'.*inf.*finite")
mesh("ply-binary-nan-coordinate", "t.ply", ply_binary(">", verts=[(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)]),
     rf"'{q('t.ply')}'.*nan.*finite")
mesh("ply-ascii-coordinate-1e19", "t.ply",
     ply_ascii(vprops=["double x", "double y", "double z"], vlines=["0 0 0", "1e19 0 0", "0 1 0"]),
     rf"'{q('t.ply')}'.*e\+(19|18).*(1e\+?15|10\^15|1e\+?18|10\^18)")
mesh("ply-collinear-triangle", "t.ply", ply_ascii(verts=[(0, 0, 0), (1, 1, 1), (2, 2, 2)]),
     rf"'{q('t.ply')}'.*({DEGENERATE})")
mesh("ply-repeated-index-face", "t.ply", ply_ascii(faces=((1, 1, 1),)),
     rf"'{q('t.ply')}'.*({DEGENERATE})")
mesh("ply-strip-all-repeated", "t.ply", ply_ascii(face_elem="tristrips", fprops=STRIP, flines=["4 0 0 0 0"]),
     rf"'{q('t.ply')}'.*({DEGENERATE})")
mesh("ply-strip-index-out-of-range", "t.ply",
     ply_ascii(face_elem="tristrips", fprops=STRIP, flines=["4 0 1 2 3"]),
     rf"'{q('t.ply')}'.*vertex 3.*3")
mesh("ply-strip-index-2^32", "t.ply",
     ply_ascii(face_elem="tristrips", fprops=STRIP, flines=["3 0 1 4294967296"]),
     rf"'{q('t.ply')}'.*4294967296.*out of range")

# OBJ ---------------------------------------------------------------------------------
V3 = ("v 0 0 0", "v 1 0 0", "v 0 1 0")
mesh("obj-face-index-0", "t.obj", obj(*V3, "f 0 1 2"), rf"'{q('t.obj')}'.*line 4.*(index 0|0 is|out of range)")
mesh("obj-face-index-beyond", "t.obj", obj(*V3, "f 1 2 9"), rf"'{q('t.obj')}'.*vertex 9.*\b3\b")
mesh("obj-face-negative-beyond", "t.obj", obj(*V3, "f -1 -2 -9"), rf"'{q('t.obj')}'.*line 4.*-9.*(out of range|3)")
mesh("obj-vertex-2-values", "t.obj", obj("v 0 0 0", "v 1 0", "v 0 1 0", "f 1 2 3"),
     rf"'{q('t.obj')}'.*line 2.*2 values")
mesh("obj-non-number", "t.obj", obj("v 0 0 0", "v 1 zero 0", "v 0 1 0", "f 1 2 3"),
     rf"'{q('t.obj')}'.*line 2.*'zero'.*not a number")
mesh("obj-1e400", "t.obj", obj("v 0 0 0", "v 1e400 0 0", "v 0 1 0", "f 1 2 3"),
     rf"'{q('t.obj')}'.*line 2.*1e400")
mesh("obj-nan-vertex", "t.obj", obj("v 0 0 0", "v nan 0 0", "v 0 1 0", "f 1 2 3"),
     rf"'{q('t.obj')}'.*line 2.*nan")
mesh("obj-coordinate-1e19", "t.obj", obj("v 0 0 0", "v 1e19 0 0", "v 0 1 0", "f 1 2 3"),
     rf"'{q('t.obj')}'.*e\+(19|18).*(1e\+?15|10\^15|1e\+?18|10\^18)")
mesh("obj-binary-garbage", "t.obj", garbage(4096), rf"'{q('t.obj')}'.*line \d+.*unknown statement", limit=HOSTILE)
mesh("obj-unknown-statement", "t.obj", obj(*V3, "frobnicate 1 2 3", "f 1 2 3"),
     rf"'{q('t.obj')}'.*line 4.*unknown statement 'frobnicate'")
mesh("obj-empty", "t.obj", b"", rf"'{q('t.obj')}'.*(no triangles|empty)")
mesh("obj-only-vertices", "t.obj", obj(*V3), rf"'{q('t.obj')}'.*no triangles")
mesh("obj-only-degenerate-faces", "t.obj", obj("v 0 0 0", "v 1 1 1", "v 2 2 2", "f 1 2 3", "f 1 1 2"),
     rf"'{q('t.obj')}'.*({DEGENERATE})")
mesh("obj-face-2-vertices", "t.obj", obj(*V3, "f 1 2"), rf"'{q('t.obj')}'.*line 4.*at least 3.*2")
mesh("obj-face-corner-not-index", "t.obj", obj(*V3, "f a b c"), rf"'{q('t.obj')}'.*line 4.*'a'")

# STL ---------------------------------------------------------------------------------
T1 = [((0, 0, 0), (1, 0, 0), (0, 1, 0))]
mesh("stl-binary-size-mismatch", "t.stl", stl_binary(T1, count=2),
     rf"'{q('t.stl')}'.*declares 2 triangles.*134")
mesh("stl-binary-too-short", "t.stl", b"\x00\x01binary" * 5,
     rf"'{q('t.stl')}'.*84 bytes.*40")
mesh("stl-binary-2000000000-triangles", "t.stl", stl_binary(T1, count=2000000000),
     rf"'{q('t.stl')}'.*2000000000", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("stl-binary-nan", "t.stl", stl_binary([((0, 0, 0), (float("nan"), 0, 0), (0, 1, 0))]),
     rf"'{q('t.stl')}'.*nan.*finite")
mesh("stl-binary-degenerate", "t.stl", stl_binary([((0, 0, 0), (1, 1, 1), (2, 2, 2))]),
     rf"'{q('t.stl')}'.*({DEGENERATE})")
mesh("stl-ascii-loop-of-2", "t.stl",
     stl_ascii("facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n endloop\nendfacet\n"),
     rf"'{q('t.stl')}'.*line 6.*exactly 3")
mesh("stl-ascii-unknown-keyword", "t.stl", stl_ascii(STL_FACET + "banana 1 2 3\n"),
     rf"'{q('t.stl')}'.*line 9.*unknown keyword")
mesh("stl-ascii-vertex-2-numbers", "t.stl",
     stl_ascii("facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0\n  vertex 0 1 0\n endloop\nendfacet\n"),
     rf"'{q('t.stl')}'.*line 5.*three numbers")
mesh("stl-ascii-ends-inside-loop", "t.stl", b"solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n",
     rf"'{q('t.stl')}'.*inside a loop")

# glTF / glb --------------------------------------------------------------------------


def set_path(path, value):
    def mutate(doc):
        node = doc
        for p in path[:-1]:
            node = node[p]
        node[path[-1]] = value
    return mutate


def del_path(path):
    def mutate(doc):
        node = doc
        for p in path[:-1]:
            node = node[p]
        del node[path[-1]]
    return mutate


def node_cycle(doc):
    doc["nodes"] = [{"mesh": 0}, {"children": [2]}, {"children": [1]}]


def self_child(doc):
    doc["nodes"] = [{"mesh": 0, "children": [0]}]


mesh("glb-wrong-magic", "t.glb", glb(magic=b"gLTf"), rf"'{q('t.glb')}'.*(magic|'gLTf'|not a GLB|not a binary glTF)")
mesh("glb-wrong-length", "t.glb", glb(length=99999), rf"'{q('t.glb')}'.*99999")
mesh("glb-wrong-version", "t.glb", glb(version=1), rf"'{q('t.glb')}'.*version 1")
mesh("glb-too-short", "t.glb", b"glTF\x02\x00", rf"'{q('t.glb')}'.*12 bytes.*6", limit=HOSTILE)
mesh("glb-truncated-json-chunk", "t.glb", glb(json_cut=40), rf"'{q('t.glb')}'.*chunk.*(declares|cut short)",
     limit=HOSTILE)
mesh("glb-json-chunk-declares-4GiB", "t.glb", glb(json_declared=0xFFFFFFF0),
     rf"'{q('t.glb')}'.*chunk.*4294967280", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("gltf-accessor-count-beyond-buffer", "t.gltf", gltf(set_path(["accessors", 0, "count"], 1000)),
     rf"'{q('t.gltf')}'.*accessors\[0\].*1000")
mesh("glb-accessor-count-beyond-buffer", "t.glb", glb(set_path(["accessors", 1, "count"], 3000000000)),
     rf"'{q('t.glb')}'.*accessors\[1\].*3000000000", limit=HOSTILE, rss=HOSTILE_RSS)
mesh("gltf-index-out-of-range", "t.gltf", gltf(indices=(0, 1, 7)),
     rf"'{q('t.gltf')}'.*index 7")
mesh("gltf-missing-position", "t.gltf", gltf(set_path(["meshes", 0, "primitives", 0, "attributes"], {})),
     rf"'{q('t.gltf')}'.*POSITION")
mesh("gltf-node-cycle", "t.gltf", gltf(node_cycle), rf"'{q('t.gltf')}'.*nodes\[[12]\].*cycle", limit=HOSTILE)
mesh("gltf-node-own-child", "t.gltf", gltf(self_child), rf"'{q('t.gltf')}'.*nodes\[0\]", limit=HOSTILE)
mesh("gltf-not-json", "t.gltf", b"this is not JSON at all\n", rf"'{q('t.gltf')}'.*JSON")
mesh("gltf-deep-nesting-unbalanced", "t.gltf", b"[" * 100000, rf"'{q('t.gltf')}'.*JSON", limit=HOSTILE)
mesh("gltf-deep-nesting-balanced", "t.gltf",
     b'{"asset": {"version": "2.0"}, "extras": ' + b"[" * 100000 + b"]" * 100000 + b"}",
     rf"'{q('t.gltf')}'.*(deeper|nest|depth)", limit=HOSTILE)
mesh("gltf-top-level-array", "t.gltf", b"[1, 2, 3]\n", rf"'{q('t.gltf')}'.*(array|object)")
mesh("gltf-external-buffer-missing", "t.gltf", gltf(uri="no-such-buffer.bin"),
     rf"'{q('t.gltf')}'.*no-such-buffer\.bin")
mesh("gltf-external-buffer-dotdot", "t.gltf", gltf(uri="../outside.bin"),
     rf"'{q('t.gltf')}'.*\.\./outside\.bin.*\.\.")
mesh("gltf-external-buffer-absolute", "t.gltf", gltf(uri="/etc/passwd"),
     rf"'{q('t.gltf')}'.*/etc/passwd.*absolute")
mesh("gltf-buffer-http-uri", "t.gltf", gltf(uri="http://example.com/b.bin"),
     rf"'{q('t.gltf')}'.*http://example\.com/b\.bin.*scheme")
mesh("gltf-bad-base64", "t.gltf", gltf(uri="data:application/octet-stream;base64,AAAA*AAA"),
     rf"'{q('t.gltf')}'.*buffers\[0\].*base64")
mesh("gltf-version-1", "t.gltf", gltf(set_path(["asset", "version"], "1.0")),
     rf"'{q('t.gltf')}'.*asset\.version '1\.0'")
mesh("gltf-nan-position", "t.gltf", gltf(positions=[(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)]),
     rf"'{q('t.gltf')}'.*(finite|nan)")
mesh("gltf-degenerate", "t.gltf", gltf(positions=[(0, 0, 0), (1, 1, 1), (2, 2, 2)]),
     rf"'{q('t.gltf')}'.*({DEGENERATE})")

# unsupported formats and paths ---------------------------------------------------------
mesh("unsupported-fbx", "t.fbx", b"Kaydara FBX Binary  \0\x1a\0", r"unsupported format '\.fbx'")
mesh("unsupported-3ds", "t.3ds", b"MM\x10\0\0\0\x02\0\x0a\0\0\0\x03\0\0\0", r"unsupported format '\.3ds'")
mesh("unsupported-no-extension", "meshfile", obj(*V3, "f 1 2 3"),
     rf"'{q('meshfile')}'.*unsupported format.*no extension")
case("mesh", "path-missing", ["check", "--scene", "no-such.obj"] + MESH_ARGS, rf"'{q('no-such.obj')}'.*No such file")
case("mesh", "path-directory", ["check", "--scene", "adir.obj"] + MESH_ARGS,
     rf"'{q('adir.obj')}'.*directory", files={"adir.obj": DIR})
case("mesh", "path-fifo", ["check", "--scene", "pipe.obj"] + MESH_ARGS,
     rf"'{q('pipe.obj')}'.*(FIFO|regular file)", files={"pipe.obj": FIFO}, limit=HOSTILE)
case("mesh", "path-dev-zero", ["check", "--scene", "/dev/zero"] + MESH_ARGS,
     r"'/dev/zero'.*regular file", limit=HOSTILE)
case("mesh", "path-empty", ["check", "--scene", ""] + MESH_ARGS, r"scene.*empty")
case("mesh", "builtin-unknown", ["check", "--scene", "builtin:nothing"] + MESH_ARGS, r"builtin:nothing")
case("mesh", "builtin-terrain-n-1", ["check", "--scene", "builtin:terrain?n=1"] + MESH_ARGS,
     rf"'n'.*{value_rx('1')}")
case("mesh", "builtin-terrain-n-not-a-number", ["check", "--scene", "builtin:terrain?n=abc"] + MESH_ARGS,
     r"'n'.*abc")
case("mesh", "builtin-unknown-parameter", ["check", "--scene", "builtin:terrain?m=3"] + MESH_ARGS, r"parameter 'm'")
mesh("ply-element-with-no-properties", "t.ply",
     ply_header("ascii", [("junk", 18446744073709551615, []), ("vertex", 3, XYZ)]) + b"0 0 0\n1 0 0\n0 1 0\n",
     r"'junk' has no properties", limit=HOSTILE)
case("mesh", "builtin-terrain-n-huge", ["check", "--scene", "builtin:terrain?n=1000000"] + MESH_ARGS,
     rf"'n'.*{value_rx('1000000')}", limit=HOSTILE, max_rss_mb=HOSTILE_RSS)
# the same readers behind export and verify
mesh("export-ply-truncated", "t.ply", ply_binary("<", faces=(), fcount=0, cut=5),
     rf"'{q('t.ply')}'.*vertex.*(ends early|truncat|fewer|declares 3 items, more than)", cmd="export")
mesh("export-obj-index-beyond", "t.obj", obj(*V3, "f 1 2 9"), rf"'{q('t.obj')}'.*vertex 9", cmd="export")
mesh("export-glb-wrong-length", "t.glb", glb(length=99999), rf"'{q('t.glb')}'.*99999", cmd="export")
mesh("verify-stl-loop-of-2", "t.stl",
     stl_ascii("facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n endloop\nendfacet\n"),
     rf"'{q('t.stl')}'.*exactly 3", cmd="verify")
mesh("verify-ply-2000000000-vertices", "t.ply", ply_binary("<", vcount=2000000000),
     rf"'{q('t.ply')}'.*2000000000", limit=HOSTILE, rss=HOSTILE_RSS, cmd="verify")
mesh("verify-obj-degenerate", "t.obj", obj("v 0 0 0", "v 1 1 1", "v 2 2 2", "f 1 2 3"),
     rf"'{q('t.obj')}'.*({DEGENERATE})", cmd="verify")

# --------------------------------------------------------------------------------------
# Camera files
# --------------------------------------------------------------------------------------


def cam_case(name, content, expect, cmd="check", limit=20.0, fname="c.json"):
    files = {fname: content} if content is not None else {}
    if cmd == "check":
        argv = ["check", "--camera", fname]
    elif cmd == "matrices":
        argv = ["matrices", "--camera", fname]
    elif cmd == "precision":
        argv = ["precision", "--camera", fname]
    elif cmd == "unproject":
        argv = ["unproject", "--camera", fname, "--pixel", "1,1"]
    elif cmd == "unproject-depth":
        argv = ["unproject", "--camera", fname, "--pixel", "1,1", "--depth", "0.5", "--quantity", "window"]
    elif cmd == "export":
        argv = ["export", "--camera", fname, "-o", "out.exr"]
    elif cmd == "verify":
        argv = ["verify", "--camera", fname, "--depth-map", "map.pfm", "--quantity", "eye-z"]
        files["map.pfm"] = GOOD_MAP
    else:
        raise ValueError(cmd)
    case("camera", f"{cmd}-{name}", argv, expect, files=files, limit=limit)


C = "c\\.json"
GLU = [1.299038105676658, 0, 0, 0,  0, 1.7320508075688772, 0, 0,  0, 0, -1.002002002002002, -0.2002002002002002,
       0, 0, -1, 0]  # gluPerspective(60, 64/48, 0.1, 100), row-major, column vectors (OpenGL)
two_mib = ('{"projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100},'
           + " " * (2 * 1024 * 1024) + '"view": {"eye": [0, 1, 3], "target": [0, 0, 0]}}\n')

cam_case("not-json", "hello, camera\n", rf"{C}.*not valid JSON")
cam_case("truncated-json", GOOD_CAM[:len(GOOD_CAM) // 2], rf"{C}.*not valid JSON")
cam_case("empty-file", "", rf"{C}.*(not valid JSON|empty)")
cam_case("top-level-array", "[1, 2, 3]\n", rf"{C}.*(object|array)")
cam_case("duplicate-top-level-key", GOOD_CAM.replace('"convention": "opengl"',
                                                     '"convention": "opengl", "convention": "vulkan"'),
         rf"{C}.*'convention'.*twice")
cam_case("duplicate-key-in-projection", GOOD_CAM.replace('"near": 0.1', '"near": 0.1, "near": 0.5'),
         rf"{C}.*'(projection\.)?near'.*twice")
cam_case("unknown-top-level-key", camera(lense=50), rf"{C}.*unknown key 'lense'")
# Lens models (lens.h): refused with the model, the parameter and the rule.
PINHOLE64 = {"type": "pinhole", "fx": 60, "fy": 60, "cx": 31.5, "cy": 23.5, "near": 0.1, "far": 100}
cam_case("lens-with-perspective", camera(lens={"model": "opencv", "k1": 0.1}),
         rf"{C}.*'lens' goes with a pinhole projection")
cam_case("lens-unknown-model", camera_with(PINHOLE64, lens={"model": "brown"}), rf"{C}.*'lens.model' must be one of")
cam_case("lens-model-missing", camera_with(PINHOLE64, lens={"k1": 0.1}), rf"{C}.*'lens.model' is missing")
cam_case("lens-huge-coefficient", camera_with(PINHOLE64, lens={"model": "opencv", "k1": -1e300}),
         rf"{C}.*lens model opencv.*folds")
cam_case("lens-folds-inside-image", camera_with(PINHOLE64, lens={"model": "opencv", "k1": -1.5}),
         rf"{C}.*lens model opencv folds \(is no longer one-to-one\).*inside the image")
cam_case("lens-fx-twice", camera_with(PINHOLE64, lens={"model": "opencv_fisheye", "fx": 60}),
         rf"{C}.*'lens.fx' is the pinhole projection's")
cam_case("lens-unknown-parameter", camera_with(PINHOLE64, lens={"model": "opencv_fisheye", "k5": 0.1}),
         rf"{C}.*unknown key 'lens.k5'")
cam_case("lens-parameter-not-a-number", camera_with(PINHOLE64, lens={"model": "opencv_fisheye", "k1": "0.1"}),
         rf"{C}.*'lens.k1' must be a number")
cam_case("lens-fov-omega-out-of-range", camera_with(PINHOLE64, lens={"model": "fov", "omega": 7}),
         rf"{C}.*'omega' must lie in \(0, π\)")
cam_case("lens-panorama-over-360", camera_with({"near": 0.1, "far": 100}, lens={
    "model": "equirectangular", "lon_min_deg": -180, "lon_max_deg": 200, "lat_min_deg": -90, "lat_max_deg": 90}),
         rf"{C}.*'lon_max_deg' must be at most 360°")
cam_case("lens-panorama-latitude-beyond-pole", camera_with({"near": 0.1, "far": 100}, lens={
    "model": "equirectangular", "lon_min_deg": -180, "lon_max_deg": 180, "lat_min_deg": -91, "lat_max_deg": 90}),
         rf"{C}.*'lat_min_deg' must be at least -90")
cam_case("lens-panorama-with-pinhole", camera_with(PINHOLE64, lens={
    "model": "equirectangular", "lon_min_deg": -180, "lon_max_deg": 180, "lat_min_deg": -90, "lat_max_deg": 90}),
         rf"{C}.*does not take a pinhole's fx")
cam_case("lens-window-quantity", camera_with(PINHOLE64, lens={"model": "opencv_fisheye", "k1": 0.01}),
         r"--depth 0\.5 \(window\): a lens model \(opencv_fisheye\) has no depth buffer", cmd="unproject-depth")
cam_case("lens-pixel-outside-field", camera_with(PINHOLE64, lens={"model": "opencv", "k1": -0.9}),
         r"image point \(1\.5, 1\.5\) is outside the lens model's field \(opencv", cmd="unproject")
cam_case("unknown-nested-key", camera(**{"projection.fov": 60}), rf"{C}.*unknown key 'projection\.fov'")
cam_case("near-is-string", camera(**{"projection.near": "0.1"}), rf"{C}.*projection\.near.*(number|string)")
cam_case("convention-is-number", camera(convention=5), rf"{C}.*convention.*(string|number)")
cam_case("width-is-string", camera(**{"image.width": "64"}), rf"{C}.*image\.width.*(integer|number|string)")
cam_case("width-not-integer", camera(**{"image.width": 64.5}), rf"{C}.*image\.width.*(integer|whole|64\.5)")
cam_case("eye-is-string", camera(**{"view.eye": "origin"}), rf"{C}.*view\.eye")
cam_case("eye-2-numbers", camera(**{"view.eye": [0, 1]}), rf"{C}.*view\.eye.*(3|three)")
cam_case("reversed-is-string", camera(**{"depth.reversed": "yes"}), rf"{C}.*depth\.reversed.*(bool|true)")
cam_case("near-0", camera(**{"projection.near": 0}), rf"{C}.*projection\.near")
cam_case("near-negative", camera(**{"projection.near": -1}), rf"{C}.*projection\.near.*-1")
cam_case("far-equals-near", camera(**{"projection.near": 5, "projection.far": 5}), rf"{C}.*projection\.far")
cam_case("far-below-near", camera(**{"projection.near": 5, "projection.far": 1}), rf"{C}.*projection\.far")
cam_case("far-near-ratio-1e13", camera(**{"projection.near": 1e-9, "projection.far": 1e4}),
         rf"{C}.*projection\.(far|near).*(10\^12|1e\+?12)")
cam_case("far-bad-string", camera(**{"projection.far": "infinite"}), rf"{C}.*projection\.far.*(infinite|\"inf\")")
cam_case("fovy-0", camera(**{"projection.fovy_deg": 0}), rf"{C}.*projection\.fovy_deg")
cam_case("fovy-180", camera(**{"projection.fovy_deg": 180}), rf"{C}.*projection\.fovy_deg.*got 180\b")
cam_case("fovy-1e400", camera(**{"projection.fovy_deg": Raw("1e400")}), rf"{C}.*(fovy_deg|'1e400')")
cam_case("width-0", camera(**{"image.width": 0}), rf"{C}.*image\.width.*0")
cam_case("width-100000", camera(**{"image.width": 100000}), rf"{C}.*image\.width.*100000")
cam_case("height-0", camera(**{"image.height": 0}), rf"{C}.*image\.height.*0")
cam_case("over-2^25-pixels", camera(16384, 16384), rf"{C}.*(2\^25|33554432|pixels)")
cam_case("unknown-convention", camera(convention="directx"), rf"{C}.*convention.*directx")
cam_case("unknown-projection-type", camera(**{"projection.type": "fisheye"}), rf"{C}.*projection\.type.*fisheye")
cam_case("missing-projection", camera(drop=["projection"]), rf"{C}.*projection")
cam_case("missing-view", camera(drop=["view"]), rf"{C}.*view")
cam_case("eye-equals-target", camera(**{"view.eye": [1, 2, 3], "view.target": [1, 2, 3]}),
         rf"{C}.*view\.(eye|target)")
cam_case("up-parallel", camera(**{"view.eye": [0, 5, 0], "view.target": [0, 0, 0], "view.up": [0, 1, 0]}),
         rf"{C}.*view\.up")
cam_case("up-zero", camera(**{"view.up": [0, 0, 0]}), rf"{C}.*view\.up")
cam_case("depth-range-reversed", camera(**{"depth.range": [1, 0]}), rf"{C}.*depth\.range")
cam_case("depth-format-unorm8", camera(**{"depth.format": "unorm8"}), rf"{C}.*depth\.format.*unorm8")
cam_case("singular-matrix", camera_with({"type": "matrix", "clip_from_eye": [0] * 16, "layout": "row-major",
                                         "vectors": "column"}), rf"{C}.*clip_from_eye.*singular")
cam_case("matrix-15-numbers", camera_with({"type": "matrix", "clip_from_eye": GLU[:15], "layout": "row-major",
                                           "vectors": "column"}), rf"{C}.*clip_from_eye.*(16|15)")
cam_case("matrix-no-layout", camera_with({"type": "matrix", "clip_from_eye": GLU, "vectors": "column"}),
         rf"{C}.*layout")
cam_case("matrix-bad-vectors", camera_with({"type": "matrix", "clip_from_eye": GLU, "layout": "row-major",
                                            "vectors": "diagonal"}),
         rf"{C}.*projection\.vectors.*(diagonal|column.*row)")
cam_case("matrix-wrong-convention", camera_with({"type": "matrix", "clip_from_eye": GLU, "layout": "row-major",
                                                 "vectors": "column"}, convention="direct3d"),
         rf"{C}.*clip_from_eye.*(convention|reversed)")
cam_case("non-rigid-view", camera_with(view={"eye_from_world": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, -3, 0, 0, 0, 1],
                                             "layout": "row-major", "vectors": "column"}),
         rf"{C}.*eye_from_world.*(rigid|scale|shear)")
cam_case("both-view-matrices", camera_with(view={"eye_from_world": IDENTITY, "world_from_eye": IDENTITY,
                                                 "layout": "row-major", "vectors": "column"}),
         rf"{C}.*(eye_from_world|world_from_eye).*both")
cam_case("eye-at-1e20", camera(**{"view.eye": [1e20, 0, 0]}), rf"{C}.*view\.eye.*e\+20.*1e\+?15")
cam_case("ortho-box-1e19", camera_with({"type": "orthographic", "left": -1e19, "right": 1e19, "bottom": -1,
                                        "top": 1, "near": 0.1, "far": 100}),
         rf"{C}.*(projection\.(left|right)|box|frustum).*e\+19.*1e\+?15")
cam_case("raw-view-translation-1e20", camera_with(view={"eye_from_world": [1, 0, 0, 1e20, 0, 1, 0, 0, 0, 0, 1, 0,
                                                                           0, 0, 0, 1],
                                                        "layout": "row-major", "vectors": "column"}),
         rf"{C}.*(eye_from_world|view translation).*e\+20.*1e\+?15")
cam_case("unknown-axonometric", camera_with({"type": "orthographic", "left": -2, "right": 2, "bottom": -1.5, "top": 1.5,
                                             "near": 0.1, "far": 100},
                                            {"axonometric": "isometrik", "target": [0, 0, 0], "distance": 5}),
         rf"{C}.*axonometric.*isometrik")
cam_case("2-MiB-file", two_mib, rf"{C}.*1 MiB", limit=HOSTILE)
cam_case("deep-nesting", '{"projection": ' + "[" * 100000 + "]" * 100000 + "}\n",
         rf"{C}.*(deep|nest|depth|projection)", limit=HOSTILE)
cam_case("deep-nesting-unbalanced", "[" * 100000, rf"{C}.*(JSON|deep|nest)", limit=HOSTILE)
case("camera", "check-fifo", ["check", "--camera", "c.json"], rf"{C}.*(FIFO|regular file)",
     files={"c.json": FIFO}, limit=HOSTILE)
case("camera", "check-directory", ["check", "--camera", "c.json"], rf"{C}.*directory", files={"c.json": DIR})
case("camera", "check-missing", ["check", "--camera", "c.json"], rf"{C}.*No such file")
case("camera", "check-empty-path", ["check", "--camera", ""], r"camera.*empty")
# the same reader behind the other commands
cam_case("near-0", camera(**{"projection.near": 0}), rf"{C}.*projection\.near", cmd="matrices")
cam_case("duplicate-key-in-projection", GOOD_CAM.replace('"far": 100', '"far": 100, "far": 50'),
         rf"{C}.*'(projection\.)?far'.*twice", cmd="matrices")
cam_case("singular-matrix", camera_with({"type": "matrix", "clip_from_eye": [0] * 16, "layout": "column-major",
                                         "vectors": "column"}), rf"{C}.*clip_from_eye.*singular", cmd="matrices")
cam_case("eye-at-1e20", camera(**{"view.eye": [0, 0, 1e20]}), rf"{C}.*view\.eye.*e\+20.*1e\+?15", cmd="matrices")
cam_case("far-below-near", camera(**{"projection.near": 5, "projection.far": 1}), rf"{C}.*projection\.far",
         cmd="precision")
cam_case("top-level-array", "[]\n", rf"{C}.*(object|array)", cmd="precision")
cam_case("2-MiB-file", two_mib, rf"{C}.*1 MiB", cmd="precision", limit=HOSTILE)
cam_case("unknown-key", camera(**{"view.look": [0, 0, 0]}), rf"{C}.*unknown key 'view\.look'", cmd="unproject")
cam_case("up-parallel", camera(**{"view.eye": [0, 0, 0], "view.target": [0, -3, 0]}), rf"{C}.*view\.up",
         cmd="unproject")
cam_case("fovy-180.5", camera(**{"projection.fovy_deg": 180.5}), rf"{C}.*fovy_deg.*got 180\.5\b", cmd="export")
cam_case("width-100000", camera(**{"image.width": 100000}), rf"{C}.*image\.width", cmd="verify")
case("camera", "matrices-directory", ["matrices", "--camera", "c.json"], rf"{C}.*directory", files={"c.json": DIR})
case("camera", "unproject-fifo", ["unproject", "--camera", "c.json", "--pixel", "1,1"], rf"{C}.*(FIFO|regular file)",
     files={"c.json": FIFO}, limit=HOSTILE)
case("camera", "precision-missing", ["precision", "--camera", "nope.json"], rf"{q('nope.json')}.*No such file")
case("camera", "matrices-empty-path", ["matrices", "--camera", ""], r"camera.*empty")

# --------------------------------------------------------------------------------------
# Depth maps
# --------------------------------------------------------------------------------------


def map_case(name, files, expect, extra=(), limit=20.0, rss=None, quantity="eye-z", mapname=None):
    mapname = mapname or next((k for k in files), "map.pfm")
    for cmd in ("verify", "unproject"):
        if cmd == "verify":
            argv = ["verify", "--camera", "cam.json", "--depth-map", mapname, "--quantity", quantity]
        else:
            argv = ["unproject", "--camera", "cam.json", "--depth-map", mapname, "--quantity", quantity,
                    "-o", "cloud.ply"]
        case("depth-map", f"{cmd}-{name}", argv + list(extra), expect, files={**MAP_CAM, **files},
             limit=limit, max_rss_mb=rss)


M = "m\\.pfm"
map_case("pfm-2000000000x1", {"m.pfm": b"Pf\n2000000000 1\n-1.0\n" + b"\0" * 64},
         rf"'{M}'.*2000000000x1.*64x48", limit=HOSTILE, rss=HOSTILE_RSS)
map_case("pfm-20000x20000", {"m.pfm": b"Pf\n20000 20000\n-1.0\n" + b"\0" * 64},
         rf"'{M}'.*20000x20000.*64x48", limit=HOSTILE, rss=HOSTILE_RSS)
map_case("pfm-truncated", {"m.pfm": pfm(64, 48, cut=1000)},
         rf"'{M}'.*(truncat).*|'{M}'.*11288.*12288|'{M}'.*12288.*11288")
map_case("pfm-bad-magic", {"m.pfm": pfm(64, 48, header=b"PX\n64 48\n-1.0\n")}, rf"'{M}'.*(header|PX|magic|first bytes)")
map_case("pfm-width-not-number", {"m.pfm": pfm(64, 48, header=b"Pf\nabc 48\n-1.0\n")}, rf"'{M}'.*header.*'abc'")
map_case("pfm-scale-0", {"m.pfm": pfm(64, 48, header=b"Pf\n64 48\n0\n")}, rf"'{M}'.*scale '0'")
map_case("pfm-empty", {"m.pfm": b""}, rf"'{M}'.*(empty|header|truncat|0 bytes|first bytes)")
map_case("pfm-wrong-size", {"m.pfm": pfm(32, 24)}, rf"'{M}'.*32x24.*64x48")
map_case("exr-garbage", {"m.exr": garbage(3000)}, rf"'{q('m.exr')}'.*(not an? |EXR|format|first bytes|magic)")
map_case("fifo", {"m.pfm": FIFO}, rf"'{M}'.*(FIFO|regular file)", limit=HOSTILE)
map_case("directory", {"m.pfm": DIR}, rf"'{M}'.*directory")
case("depth-map", "verify-missing", ["verify", "--camera", "cam.json", "--depth-map", "m.pfm", "--quantity", "eye-z"],
     rf"'{M}'.*No such file", files=dict(MAP_CAM))
case("depth-map", "unproject-missing", ["unproject", "--camera", "cam.json", "--depth-map", "m.pfm", "--quantity",
                                        "eye-z", "-o", "cloud.ply"], rf"'{M}'.*No such file", files=dict(MAP_CAM))
map_case("png16-without-scale", {"m.png": png16(64, 48)}, rf"'{q('m.png')}'.*--scale")
map_case("png16-truncated", {"m.png": png16(64, 48, cut=30)}, rf"'{q('m.png')}'.*(truncat|ends early|corrupt)",
         extra=["--scale", "1000"])
map_case("png16-wrong-size", {"m.png": png16(32, 48)}, rf"'{q('m.png')}'.*32x48.*64x48", extra=["--scale", "1000"])
map_case("scale-negative", {"m.pfm": GOOD_MAP}, r"--scale.*-1", extra=["--scale", "-1"])
map_case("scale-nan", {"m.pfm": GOOD_MAP}, r"--scale.*nan", extra=["--scale", "nan"])
map_case("scale-0", {"m.pfm": GOOD_MAP}, r"--scale.*\b0\b", extra=["--scale", "0"])
map_case("scale-inf", {"m.pfm": GOOD_MAP}, r"--scale.*inf", extra=["--scale", "inf"])
map_case("miss-not-a-number", {"m.pfm": GOOD_MAP}, r"miss value 'abc' is neither a number", extra=["--miss", "abc"])
map_case("miss-comparison-with-inf", {"m.pfm": GOOD_MAP}, r"miss value '>=inf'", extra=["--miss", ">=inf"])
# regression: an empty --miss was silently taken for none given
map_case("miss-empty", {"m.pfm": GOOD_MAP}, r"--miss: miss value '' is neither a number", extra=["--miss", ""])
map_case("offset-nan", {"m.pfm": GOOD_MAP}, r"--offset.*nan", extra=["--offset", "nan"])
map_case("channel-absent", {"m.pfm": GOOD_MAP}, rf"'{M}'.*no channel 'Depth\.Z'.*'Y'", extra=["--channel", "Depth.Z"])
map_case("pfm-rgb-no-depth-channel", {"m.pfm": pfm(64, 48, channels=3)},
         rf"'{M}'.*none of its 3 channels.*--channel")
case("depth-map", "verify-depth-map-empty-path", ["verify", "--camera", "cam.json", "--depth-map", "",
                                                  "--quantity", "eye-z"], r"depth.map.*empty", files=dict(MAP_CAM))

# --------------------------------------------------------------------------------------
# Outputs
# --------------------------------------------------------------------------------------
UNPROJ = ["unproject", "--camera", "cam.json", "--depth-map", "x.pfm", "--quantity", "eye-z"]
UNPROJ_FILES = {"cam.json": GOOD_CAM, "x.pfm": pfm(64, 48)}
EXPORT = ["export", "--camera", "cam.json"]

case("output", "unproject-output-is-input", UNPROJ + ["-o", "x.pfm"], r"'x\.pfm'.*input", files=dict(UNPROJ_FILES))
case("output", "unproject-output-is-input-dot-slash", UNPROJ + ["-o", "./x.pfm"], r"'\./x\.pfm'.*input",
     files=dict(UNPROJ_FILES))
case("output", "unproject-output-is-input-symlink", UNPROJ + ["-o", "link.pfm"], r"'link\.pfm'.*input",
     files=dict(UNPROJ_FILES), setup=symlink("x.pfm", "link.pfm"))
case("output", "unproject-output-is-input-absolute", UNPROJ + ["-o", "{dir}/x.pfm"], r"x\.pfm'.*input",
     files=dict(UNPROJ_FILES))
case("output", "unproject-output-is-camera", UNPROJ + ["-o", "cam.json"], r"'cam\.json'.*input",
     files=dict(UNPROJ_FILES))
case("output", "unproject-output-is-directory", UNPROJ + ["-o", "cloud.ply"], r"'cloud\.ply'.*(folder|directory)",
     files={**UNPROJ_FILES, "cloud.ply": DIR})
case("output", "unproject-output-trailing-slash", UNPROJ + ["-o", "cloud/"], r"'cloud/'.*(folder|file path)",
     files=dict(UNPROJ_FILES))
case("output", "unproject-output-empty", UNPROJ + ["-o", ""], r"(-o|--output).*empty", files=dict(UNPROJ_FILES))
case("output", "unproject-output-missing-folder", UNPROJ + ["-o", "no/such/dir/c.ply"],
     r"'no/such/dir/c\.ply'.*(does not exist|No such)", files=dict(UNPROJ_FILES))
case("output", "export-preview-same-as-output", EXPORT + ["-o", "d.png", "--scale", "1000", "--preview", "d.png"],
     r"'d\.png'.*same file", files=dict(MAP_CAM))
case("output", "export-preview-same-as-existing-output",
     EXPORT + ["-o", "d.png", "--scale", "1000", "--preview", "d.png"], r"'d\.png'.*same file",
     files=dict(MAP_CAM), guard=("d.png",))
case("output", "export-preview-same-as-sidecar", EXPORT + ["-o", "k.exr", "--preview", "k.exr.json"],
     r"'k\.exr\.json'.*same file", files=dict(MAP_CAM), guard=("k.exr",))
# regression: the message listed only the formats loaded so far (".h5" for a .npy, not ".exr")
case("output", "export-several-quantities-into-npy", EXPORT + ["--quantity", "eye-z,distance", "-o", "k.npy"],
     r"'k\.npy': several quantities go into one file only as \.exr or \.h5$", files=dict(MAP_CAM))
case("output", "export-preview-missing-folder", EXPORT + ["-o", "k.exr", "--preview", "no/such/dir/p.png"],
     r"'no/such/dir/p\.png'.*(does not exist|No such)", files=dict(MAP_CAM), guard=("k.exr",))
# Must fail before the work: rendering this terrain (8.4 M triangles) takes ~6 s of CPU.
case("output", "export-sidecar-is-directory", EXPORT + ["--scene", "builtin:terrain?n=2048", "-o", "k.exr"],
     r"'k\.exr\.json'.*(folder|directory)", files={**MAP_CAM, "k.exr.json": DIR}, guard=("k.exr",), limit=3.0)
case("output", "export-output-is-directory", EXPORT + ["-o", "k.exr"], r"'k\.exr'.*(folder|directory)",
     files={**MAP_CAM, "k.exr": DIR})
case("output", "export-output-trailing-slash", EXPORT + ["-o", "out/"], r"'out/'.*(folder|file path)",
     files=dict(MAP_CAM))
case("output", "export-output-empty", EXPORT + ["-o", ""], r"(-o|--output).*empty", files=dict(MAP_CAM))
case("output", "export-no-output", EXPORT, r"needs -o|-o.*required", files=dict(MAP_CAM))
case("output", "export-unknown-format", EXPORT + ["-o", "d.bmp"], r"'d\.bmp'.*(format|\.bmp)", files=dict(MAP_CAM))
case("output", "export-several-quantities-into-pfm", EXPORT + ["--quantity", "eye-z,distance", "-o", "m.pfm"],
     r"'m\.pfm'.*(several|\.exr)", files=dict(MAP_CAM), guard=("m.pfm",))
case("output", "export-png-without-scale", EXPORT + ["-o", "d.png"], r"'d\.png'.*--scale", files=dict(MAP_CAM),
     guard=("d.png",))
case("output", "export-png-scale-overflow", EXPORT + ["-o", "d.png", "--scale", "1000000"],
     r"'d\.png'.*65535.*(largest scale|fits)", files=dict(MAP_CAM), guard=("d.png",))
case("output", "export-png-normal", EXPORT + ["--quantity", "normal", "-o", "d.png", "--scale", "1000"],
     r"'d\.png'.*normal", files=dict(MAP_CAM))
case("output", "export-pfm-primitive-id", EXPORT + ["--quantity", "primitive-id", "-o", "d.pfm"],
     r"'d\.pfm'.*primitive-id", files=dict(MAP_CAM))
for cmd in ("check", "verify"):
    base = (["check", "--camera", "cam.json"] if cmd == "check" else
            ["verify", "--camera", "cam.json", "--depth-map", "map.pfm", "--quantity", "eye-z"])
    files = {"cam.json": GOOD_CAM, "map.pfm": GOOD_MAP}
    case("output", f"{cmd}-out-report-json-is-directory", base + ["--out", "res"],
         r"report\.json'?.*(folder|directory)",
         files={**files, "res/report.json": DIR}, guard=("res/ray_depth.exr", "res/notes.txt"), limit=HOSTILE)
    case("output", f"{cmd}-out-heatmap-is-directory", base + ["--out", "res"],
         r"error_heatmap\.png'?.*(folder|directory)",
         files={**files, "res/error_heatmap.png": DIR}, guard=("res/report.json",), limit=HOSTILE)
    case("output", f"{cmd}-out-is-regular-file", base + ["--out", "res.txt"], r"'res\.txt'.*not a folder",
         files=files, guard=("res.txt",))
    case("output", f"{cmd}-out-empty", base + ["--out", ""], r"--out.*empty", files=files)
    case("output", f"{cmd}-out-is-input", base + ["--out", "cam.json"], r"'cam\.json'.*(not a folder|input)",
         files=files)
SUITE = ["suite", "--quick", "--models", "{models}"]
case("output", "suite-out-missing-parent", SUITE + ["--out", "missing/dir/res"],
     r"'missing/dir/res'.*(does not exist|No such)", limit=2.0)
case("output", "suite-out-is-regular-file", SUITE + ["--out", "res.txt"], r"'res\.txt'.*not a folder",
     files={"res.txt": "kept\n"}, guard=("res.txt",), limit=2.0)
case("output", "suite-out-json-is-directory", SUITE + ["--out", "res"], r"suite\.json'?.*(folder|directory)",
     files={"res/suite.json": DIR, "res/suite.html": "kept\n"}, guard=("res/suite.html",), limit=2.0)
case("output", "suite-out-empty", SUITE + ["--out", ""], r"--out.*empty", limit=2.0)
case("output", "suite-json-takes-no-file", SUITE + ["--json", "r.json"], r"r\.json", limit=2.0)

# Full disk: RLIMIT_FSIZE 20 KiB, every output larger than that.
FSIZE = 20 * 1024
FULL = r"(too large|fail|space|write|short)"   # the reason, whatever the writer's words
PERSP = "{examples}/perspective.json"
for ext, extra in (("png", ["--scale", "1000"]), ("exr", []), ("pfm", []), ("tif", [])):
    case("full-disk", f"export-{ext}", ["export", "--camera", PERSP, "-o", f"big.{ext}"] + extra,
         rf"'big\.{ext}'.*{FULL}", guard=(f"big.{ext}",), fsize=FSIZE)
case("full-disk", "export-exr-with-preview", ["export", "--camera", PERSP, "-o", "big.exr", "--preview", "p.png"],
     rf"('big\.exr'|'p\.png').*{FULL}", guard=("big.exr", "p.png"), fsize=FSIZE)
case("full-disk", "unproject-ply", ["unproject", "--camera", "cam640.json", "--depth-map", "in.pfm", "--quantity",
                                    "eye-z", "-o", "big.ply"], rf"'big\.ply'.*{FULL}",
     files={"cam640.json": CAM640, "in.pfm": pfm(640, 480)}, guard=("big.ply",), fsize=FSIZE)
case("full-disk", "unproject-ascii-ply", ["unproject", "--camera", "cam640.json", "--depth-map", "in.pfm",
                                          "--quantity", "eye-z", "--ascii", "-o", "big.ply"], rf"'big\.ply'.*{FULL}",
     files={"cam640.json": CAM640, "in.pfm": pfm(640, 480)}, fsize=FSIZE)
case("full-disk", "check-out", ["check", "--camera", PERSP, "--out", "res"], rf"'res/[\w.]+'.*{FULL}",
     files={"res": DIR}, guard=("res/report.json", "res/ray_depth.exr"), fsize=FSIZE)
case("full-disk", "verify-out", ["verify", "--camera", "cam640.json", "--depth-map", "in.pfm", "--quantity", "eye-z",
                                 "--out", "res"], rf"'res/[\w.]+'.*{FULL}",
     files={"cam640.json": CAM640, "in.pfm": pfm(640, 480, value=float("inf")), "res": DIR},
     guard=("res/raster_depth.exr",), fsize=FSIZE)

# --------------------------------------------------------------------------------------
# Options
# --------------------------------------------------------------------------------------
VERIFY = ["verify", "--camera", "cam.json", "--depth-map", "map.pfm", "--quantity", "eye-z"]
VFILES = {"cam.json": GOOD_CAM, "map.pfm": GOOD_MAP}
UNPIX = ["unproject", "--camera", "cam.json"]
THREAD_CMDS = {
    "check": (["check", "--camera", "cam.json"], dict(MAP_CAM), 20.0),
    "export": (["export", "--camera", "cam.json", "-o", "t.exr"], dict(MAP_CAM), 20.0),
    "verify": (VERIFY, VFILES, 20.0),
    "suite": (SUITE, {}, 2.0),
}
for cmd, (base, files, lim) in THREAD_CMDS.items():
    for value in ("0", "-3", "abc", "2000"):
        case("options", f"{cmd}-threads-{value}", base + ["--threads", value], rf"--threads.*{value_rx(value)}",
             files=dict(files), limit=lim)
for value in ("0", "-1", "99999", "abc"):
    case("options", f"check-width-{value}", ["check", "--width", value], rf"--width.*{value_rx(value)}")
case("options", "check-height-0", ["check", "--height", "0"], r"--height.*\b0\b")
case("options", "check-over-2^25-pixels", ["check", "--width", "8193", "--height", "4096"],
     r"(2\^25|33554432|pixels).*|8193")
case("options", "unproject-stride-0", UNPROJ + ["-o", "c.ply", "--stride", "0"], r"--stride.*\b0\b",
     files=dict(UNPROJ_FILES))
case("options", "check-depth-format-bogus", ["check", "--depth-format", "bogus"], r"depth.format.*'?bogus")
for cmd, base, files in (("check", ["check"], {}), ("matrices", ["matrices", "--camera", "cam.json"], MAP_CAM),
                         ("precision", ["precision", "--camera", "cam.json"], MAP_CAM),
                         ("unproject", UNPIX + ["--pixel", "1,1"], MAP_CAM),
                         ("export", ["export", "-o", "t.exr"], {}), ("verify", VERIFY, VFILES)):
    case("options", f"{cmd}-convention-bogus", base + ["--convention", "bogus"], r"convention.*'?bogus",
         files=dict(files))
case("options", "verify-quantity-bogus", ["verify", "--camera", "cam.json", "--depth-map", "map.pfm", "--quantity",
                                          "bogus"], r"quantity.*'?bogus", files=dict(VFILES))
case("options", "unproject-quantity-bogus", UNPIX + ["--pixel", "1,1", "--depth", "0.5", "--quantity", "bogus"],
     r"quantity.*'?bogus", files=dict(MAP_CAM))
case("options", "unproject-map-quantity-bogus", UNPROJ[:-2] + ["-o", "c.ply", "--quantity", "bogus"],
     r"quantity.*'?bogus", files=dict(UNPROJ_FILES))
case("options", "export-quantity-bogus", ["export", "--quantity", "bogus", "-o", "t.exr"], r"quantity.*'?bogus")
case("options", "export-quantity-list-bogus", ["export", "--quantity", "eye-z,bogus", "-o", "t.exr"],
     r"quantity.*'?bogus")
case("options", "export-quantity-empty", ["export", "--quantity", "", "-o", "t.exr"], r"quantity")
case("options", "export-backend-bogus", ["export", "--backend", "bogus", "-o", "t.exr"], r"--backend.*'?bogus")
case("options", "unproject-space-bogus", UNPROJ + ["-o", "c.ply", "--space", "bogus"], r"--space.*'?bogus",
     files=dict(UNPROJ_FILES))
for label, pixel, rx in (("col-64", "64,0", r"--pixel.*64,0.*64x48"), ("row-48", "0,48", r"--pixel.*0,48.*64x48"),
                         ("negative", "-1,0", r"--pixel.*-1"), ("not-numbers", "a,b", r"--pixel.*'a'"),
                         ("fraction", "1.5,2", r"--pixel.*1\.5"), ("one-number", "5", rf"--pixel.*{value_rx('5')}"),
                         ("three-numbers", "1,2,3", r"--pixel.*1,2,3")):
    case("options", f"unproject-pixel-{label}", UNPIX + ["--pixel", pixel], rx, files=dict(MAP_CAM))
for quantity, depth in (("window", "1.5"), ("window", "-0.1"), ("ndc", "2"), ("eye-z", "-1"), ("eye-z", "0"),
                        ("distance", "0"), ("window", "nan"), ("eye-z", "inf")):
    case("options", f"unproject-depth-{quantity}-{depth}",
         UNPIX + ["--pixel", "1,1", "--depth", depth, "--quantity", quantity],
         rf"^(?=.*\b{quantity}\b).*--depth[ :=]+{value_rx(depth)}", files=dict(MAP_CAM))
case("options", "precision-at-not-number", ["precision", "--camera", "cam.json", "--at", "1,abc"], r"--at.*'abc'",
     files=dict(MAP_CAM))
case("options", "precision-at-outside", ["precision", "--camera", "cam.json", "--at", "0.01"], r"0\.01.*(outside|near)",
     files=dict(MAP_CAM))
case("options", "precision-at-empty", ["precision", "--camera", "cam.json", "--at", ""], r"--at",
     files=dict(MAP_CAM))
case("options", "suite-filter-matches-nothing", SUITE + ["--filter", "no-such-configuration"],
     r"--filter.*no-such-configuration", limit=HOSTILE)
case("options", "suite-models-missing", ["suite", "--quick", "--models", "no/such/models"], r"no/such/models",
     limit=HOSTILE)
case("options", "check-unknown-option", ["check", "--frobnicate"], r"--frobnicate")
case("options", "export-unknown-option", ["export", "-o", "t.exr", "--width", "64"], r"--width")
case("options", "unknown-subcommand", ["fly"], r"'?fly\b")
case("options", "no-subcommand", [], r"subcommand")
case("options", "verify-without-depth-map", ["verify", "--camera", "cam.json", "--quantity", "eye-z"],
     r"--depth-map", files=dict(MAP_CAM))
case("options", "unproject-neither-pixel-nor-map", UNPIX, r"--pixel.*--depth-map|--depth-map.*--pixel",
     files=dict(MAP_CAM))
case("options", "unproject-map-without-output", UNPROJ, r"--depth-map.*-o", files=dict(UNPROJ_FILES))
case("options", "unproject-depth-without-pixel", UNPROJ + ["-o", "c.ply", "--depth", "0.5"], r"--depth",
     files=dict(UNPROJ_FILES))
case("options", "matrices-without-camera", ["matrices"], r"--camera")
case("options", "check-reversed-z-with-value", ["check", "--reversed-z=maybe"], r"reversed-z|maybe")

# --------------------------------------------------------------------------------------
# Nothing to compare
# --------------------------------------------------------------------------------------
NOTHING = r"nothing (was )?compared|nothing to compare"
case("nothing-to-compare", "check-camera-looks-away", ["check", "--camera", "away.json"], NOTHING,
     files={"away.json": AWAY_CAM})
case("nothing-to-compare", "check-mesh-camera-looks-away", ["check", "--scene", "t.obj", "--camera", "away.json"],
     NOTHING, files={"away.json": AWAY_CAM, "t.obj": obj(*V3, "f 1 2 3")})
case("nothing-to-compare", "verify-camera-looks-away", ["verify", "--camera", "away.json", "--depth-map", "map.pfm",
                                                        "--quantity", "eye-z"], NOTHING,
     files={"away.json": AWAY_CAM, "map.pfm": GOOD_MAP})
case("nothing-to-compare", "verify-camera-looks-away-out", ["verify", "--camera", "away.json", "--depth-map", "map.pfm",
                                                            "--quantity", "eye-z", "--out", "res"], NOTHING,
     files={"away.json": AWAY_CAM, "map.pfm": GOOD_MAP, "res": DIR}, guard=("res/report.json",))
case("nothing-to-compare", "check-camera-looks-away-json", ["check", "--camera", "away.json", "--json"], NOTHING,
     files={"away.json": AWAY_CAM})

# --------------------------------------------------------------------------------------
# Imported cameras: COLMAP models, transforms.json, OpenCV and ROS calibration, FILE#FRAME
# --------------------------------------------------------------------------------------
COLMAP_CAMERAS = "# CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]\n1 PINHOLE 64 48 50 50 32 24\n"
# Two images (each line followed by its POINTS2D line), looking down +z (OpenCV) from z = -3.
COLMAP_IMAGES = ("# IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME\n"
                 "1 1 0 0 0 0 0 3 1 img_000.png\n\n"
                 "2 1 0 0 0 0 0 4 1 img_001.png\n\n")


def colmap_text(cameras=COLMAP_CAMERAS, images=COLMAP_IMAGES, folder="model"):
    """The files of a COLMAP text model in `folder` (cameras.txt, images.txt)."""
    return {f"{folder}/cameras.txt": cameras, f"{folder}/images.txt": images}


def colmap_cameras_bin(cameras=((1, 1, 64, 48, (50, 50, 32, 24)),), count=None, cut=0):
    """cameras.bin: uint64 count; per camera uint32 id, int32 model id, uint64 width, height,
    float64 params. cut removes bytes from the end."""
    data = struct.pack("<Q", len(cameras) if count is None else count)
    for cam_id, model, width, height, params in cameras:
        data += struct.pack(f"<IiQQ{len(params)}d", cam_id, model, width, height, *params)
    return data[:len(data) - cut] if cut else data


def colmap_images_bin(images=((1, 0.0, 3.0, 1, "img_000.png", 0),), count=None):
    """images.bin: uint64 count; per image uint32 id, qvec (1, 0, 0, 0), tvec (0, ty, tz),
    uint32 camera id, NUL-terminated name, uint64 num_points2D and (declared) that many
    24-byte points, of which none are written when the count is above 4."""
    data = struct.pack("<Q", len(images) if count is None else count)
    for image_id, ty, tz, cam_id, name, points in images:
        data += struct.pack("<I4d3dI", image_id, 1, 0, 0, 0, 0, ty, tz, cam_id) + name.encode() + b"\0"
        data += struct.pack("<Q", points) + (b"\0" * 24 * points if points <= 4 else b"")
    return data


def colmap_binary(cameras=None, images=None, folder="model"):
    return {f"{folder}/cameras.bin": cameras if cameras is not None else colmap_cameras_bin(),
            f"{folder}/images.bin": images if images is not None else colmap_images_bin()}


POSE = [[1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, 3], [0, 0, 0, 1]]   # at (0, 1, 3) looking down -z (OpenGL)


def transforms(frames=None, frame_patch=None, **top):
    """A nerfstudio transforms.json: 64x48 pinhole intrinsics at the top level and one frame
    (with a depth map path) unless `frames` is given; frame_patch updates frames[0]."""
    doc = {"camera_model": "OPENCV", "fl_x": 50, "fl_y": 50, "cx": 32, "cy": 24, "w": 64, "h": 48,
           "k1": 0, "k2": 0, "p1": 0, "p2": 0}
    doc.update(top)
    if frames is None:
        frames = [{"file_path": "images/frame_000.png", "depth_file_path": "depth/frame_000.npy",
                   "transform_matrix": POSE}]
        frames[0].update(frame_patch or {})
    doc["frames"] = frames
    return to_json(doc, indent=2)


def opencv_yaml(k=(50, 0, 32, 0, 50, 24, 0, 0, 1), drop=()):
    """OpenCV FileStorage YAML as cv::FileStorage writes it (%YAML:1.0, !!opencv-matrix), K
    on line 9; drop leaves out top-level keys."""
    body = [
        "image_width: 64",
        "image_height: 48",
        "camera_matrix: !!opencv-matrix",
        "   rows: 3",
        "   cols: 3",
        "   dt: d",
        "   data: [ " + ", ".join(str(v) for v in k) + " ]",
        "distortion_coefficients: !!opencv-matrix",
        "   rows: 1",
        "   cols: 5",
        "   dt: d",
        "   data: [ 0., 0., 0., 0., 0. ]",
    ]
    out, skipping = [], False
    for line in body:
        if not line.startswith(" "):
            skipping = line.split(":")[0] in drop
        if not skipping:
            out.append(line)
    return "%YAML:1.0\n---\n" + "\n".join(out) + "\n"


def opencv_xml(body=None, prolog='<?xml version="1.0"?>\n'):
    body = body if body is not None else (
        "<image_width>64</image_width>\n<image_height>48</image_height>\n"
        '<camera_matrix type_id="opencv-matrix">\n  <rows>3</rows>\n  <cols>3</cols>\n  <dt>d</dt>\n'
        "  <data>\n    50. 0. 32. 0. 50. 24. 0. 0. 1.</data></camera_matrix>\n")
    return prolog + "<opencv_storage>\n" + body + "</opencv_storage>\n"


def ros_yaml(k=(50, 0, 32, 0, 50, 24, 0, 0, 1), extra=()):
    """A ROS camera_calibration_parsers file (camera_info_manager's YAML)."""
    return "\n".join([
        "image_width: 64",
        "image_height: 48",
        "camera_name: narrow_stereo",
        "camera_matrix:",
        "  rows: 3",
        "  cols: 3",
        "  data: [" + ", ".join(str(v) for v in k) + "]",
        "distortion_model: plumb_bob",
        "distortion_coefficients:",
        "  rows: 1",
        "  cols: 5",
        "  data: [0, 0, 0, 0, 0]",
        "projection_matrix:",
        "  rows: 3",
        "  cols: 4",
        "  data: [50, 0, 32, 0, 0, 50, 24, 0, 0, 0, 1, 0]",
        *extra,
    ]) + "\n"


# A CameraInfo message as `rostopic echo` prints it for a camera that was never calibrated:
# everything zero (REP 104: K[0] = 0 means uncalibrated).
ROS_UNCALIBRATED = (
    "header:\n  seq: 0\n  stamp: {secs: 0, nsecs: 0}\n  frame_id: camera_optical\nheight: 48\nwidth: 64\n"
    "distortion_model: plumb_bob\nD: [0.0, 0.0, 0.0, 0.0, 0.0]\nK: [" + ", ".join(["0.0"] * 9) + "]\n"
    "R: [" + ", ".join(["0.0"] * 9) + "]\nP: [" + ", ".join(["0.0"] * 12) + "]\nbinning_x: 0\nbinning_y: 0\n"
    "roi: {x_offset: 0, y_offset: 0, height: 0, width: 0, do_rectify: False}\n")

CAMERA_USERS = {
    "camera": lambda ref: ["camera", ref],
    "check": lambda ref: ["check", "--camera", ref],
    "matrices": lambda ref: ["matrices", "--camera", ref],
    "precision": lambda ref: ["precision", "--camera", ref],
    "unproject": lambda ref: ["unproject", "--camera", ref, "--pixel", "1,1"],
    "export": lambda ref: ["export", "--camera", ref, "-o", "out.exr"],
    "verify": lambda ref: ["verify", "--camera", ref, "--depth-map", "map.pfm", "--quantity", "eye-z"],
}


def import_case(name, files, ref, expect, cmd="check", extra=(), limit=20.0, rss=None):
    """A camera file (or COLMAP model) that one of the commands reads with --camera REF
    (`zcheck camera REF` for cmd="camera")."""
    files = dict(files)
    if cmd == "verify":
        files["map.pfm"] = GOOD_MAP
    case("camera-import", f"{cmd}-{name}", CAMERA_USERS[cmd](ref) + list(extra), expect, files=files, limit=limit,
         max_rss_mb=rss)


CT = r"model/cameras\.txt'"
CB = r"model/cameras\.bin'"
IB = r"model/images\.bin'"
TJ = r"'t\.json'"
BIG = str(2**60)

# COLMAP text
import_case("colmap-txt-parameter-count", colmap_text("1 PINHOLE 64 48 50 50 32\n"), "model#img_000.png",
            rf"{CT}.*line 1.*PINHOLE.*takes 4 parameters.*has 3")
import_case("colmap-txt-unknown-model", colmap_text("1 PINHOLEX 64 48 50 50 32 24\n"), "model#img_000.png",
            rf"{CT}.*line 1.*unknown camera model 'PINHOLEX'", cmd="camera")
import_case("colmap-txt-non-numeric-parameter", colmap_text("1 PINHOLE 64 48 50 5O 32 24\n"), "model#img_000.png",
            rf"{CT}.*line 1.*'5O'.*not a (finite )?number", cmd="matrices")
import_case("colmap-txt-duplicate-camera-id",
            colmap_text("1 PINHOLE 64 48 50 50 32 24\n# again\n1 PINHOLE 64 48 60 60 32 24\n"), "model#img_000.png",
            rf"{CT}.*line 3.*CAMERA_ID 1.*twice")
import_case("colmap-txt-image-names-missing-camera",
            colmap_text(images="1 1 0 0 0 0 0 3 1 img_000.png\n\n2 1 0 0 0 0 0 4 7 img_001.png\n\n"),
            "model#img_000.png", r"images\.txt'? line 3.*CAMERA_ID 7.*not in", cmd="camera")
import_case("colmap-txt-opencv-folds", colmap_text("1 OPENCV 64 48 50 50 32 24 -2.5 0 0 0\n"),
            "model#img_000.png", r"cameras\.txt'? line 1.*OPENCV.*lens model opencv folds", cmd="camera")
import_case("colmap-txt-fisheye-window-export", colmap_text("1 OPENCV_FISHEYE 64 48 50 50 32 24 0 0 0 0\n"),
            "model#img_001.png", r"quantity window: a lens model \(opencv_fisheye\) has no depth buffer",
            extra=["--quantity", "window"], cmd="export")
import_case("colmap-txt-width-0", colmap_text("1 PINHOLE 0 48 50 50 32 24\n"), "model#img_000.png",
            rf"{CT}.*line 1.*WIDTH.*'?0'?.*1\.\.16384")
import_case("colmap-txt-negative-focal-length", colmap_text("1 PINHOLE 64 48 -50 50 32 24\n"), "model#img_000.png",
            rf"(cameras\.txt'? line 1|{CT}.*line 1).*(focal|fx|parameter 1).*-50", cmd="camera")
# COLMAP binary
import_case("colmap-bin-truncated", colmap_binary(colmap_cameras_bin(cut=12)), "model#img_000.png",
            rf"{CB}.*byte \d+.*needs 8 bytes.*(cut short|truncat)", limit=HOSTILE)
import_case("colmap-bin-2^60-cameras", colmap_binary(colmap_cameras_bin(count=2**60)), "model#img_000.png",
            rf"{CB}.*{BIG} cameras.*more than", limit=HOSTILE, rss=HOSTILE_RSS, cmd="camera")
import_case("colmap-bin-2^60-images", colmap_binary(images=colmap_images_bin(count=2**60)), "model#img_000.png",
            rf"{IB}.*{BIG} images.*more than", limit=HOSTILE, rss=HOSTILE_RSS)
import_case("colmap-bin-unknown-model-id", colmap_binary(colmap_cameras_bin(((1, 99, 64, 48, (50, 50, 32, 24)),))),
            "model#img_000.png", rf"{CB}.*camera 1.*model id 99", cmd="precision")
import_case("colmap-bin-2^60-points2D",
            colmap_binary(images=colmap_images_bin(((1, 0.0, 3.0, 1, "img_000.png", 2**60),))), "model#img_000.png",
            rf"{IB}.*image record 0.*{BIG} 2-D points.*more than", limit=HOSTILE, rss=HOSTILE_RSS)
# transforms.json
import_case("transforms-no-frames", {"t.json": transforms(frames=[])}, "t.json",
            rf"{TJ}.*(no frames?|no camera|empty)", cmd="camera")
import_case("transforms-matrix-3-numbers", {"t.json": transforms(frame_patch={"transform_matrix": [1, 0, 0]})},
            "t.json#0", rf"{TJ}.*'frames\[0\]\.transform_matrix'.*4 rows")
import_case("transforms-matrix-reflection",
            {"t.json": transforms(frame_patch={"transform_matrix": [[-1, 0, 0, 0], [0, 1, 0, 1], [0, 0, 1, 3],
                                                                    [0, 0, 0, 1]]})}, "t.json#0",
            rf"{TJ}.*frames\[0\]\.transform_matrix.*(reflection|mirror|det|handed)", cmd="verify")
import_case("transforms-matrix-scaled-rotation",
            {"t.json": transforms(frame_patch={"transform_matrix": [[2, 0, 0, 0], [0, 2, 0, 1], [0, 0, 2, 3],
                                                                    [0, 0, 0, 1]]})}, "t.json#0",
            rf"{TJ}.*frames\[0\]\.transform_matrix.*(scale|rigid|orthonormal|not a rotation)", cmd="unproject")
import_case("transforms-w-640.5", {"t.json": transforms(w=640.5)}, "t.json#0",
            rf"{TJ}.*'w'.*whole number.*640\.5")
import_case("transforms-vr180-camera-model", {"t.json": transforms(frame_patch={"camera_model": "VR180_L"})},
            "t.json#0", rf"{TJ}.*VR180_L.*starts its rays 32 mm", cmd="camera")
import_case("transforms-distortion-params-count", {"t.json": transforms(distortion_params=[0.1, 0, 0])},
            "t.json#0", rf"{TJ}.*holds 3 numbers; camera_model OPENCV takes 6", cmd="camera")
import_case("transforms-lens-folds", {"t.json": transforms(k1=-3.0)}, "t.json#0",
            rf"{TJ}.*lens model brown_conrady folds", cmd="camera")
# OpenCV FileStorage YAML and XML
import_case("opencv-yaml-no-camera-matrix", {"c.yml": opencv_yaml(drop=("camera_matrix",))}, "c.yml",
            r"'c\.yml'.*no camera matrix")
import_case("opencv-yaml-skew", {"c.yml": opencv_yaml(k=(50, 7, 32, 0, 50, 24, 0, 0, 1))}, "c.yml",
            r"'c\.yml'.*camera_matrix.*skew", cmd="camera")
import_case("opencv-yaml-repeated-key", {"c.yml": opencv_yaml() + "image_width: 640\n"}, "c.yml",
            r"'c\.yml'.*line 15.*'?image_width'?.*repeated")
import_case("opencv-yaml-unterminated-flow-sequence",
            {"c.yml": opencv_yaml().replace("data: [ 50, 0, 32, 0, 50, 24, 0, 0, 1 ]", "data: [ 50, 0, 32, 0, 50,")},
            "c.yml", r"'c\.yml'.*\bline 9\b.*flow sequence|'c\.yml'.*flow sequence.*\bline 9\b", cmd="camera")
import_case("opencv-yaml-anchor-alias",
            {"c.yml": opencv_yaml().replace("camera_matrix: !!opencv-matrix", "camera_matrix: &K !!opencv-matrix")
             + "new_camera_matrix: *K\n"}, "c.yml", r"'c\.yml'.*line (5|15).*anchor")
import_case("opencv-yaml-deep-nesting", {"c.yml": "%YAML:1.0\n---\nimage_width: 64\nnest: " + "[" * 100000 +
                                         "]" * 100000 + "\n"}, "c.yml",
            r"'c\.yml'.*line 4.*(nested|deeper|depth)", limit=HOSTILE, rss=HOSTILE_RSS)
import_case("opencv-xml-mismatched-tags", {"c.xml": opencv_xml().replace("<cols>3</cols>", "<cols>3</rows>")}, "c.xml",
            r"'c\.xml'.*line 7.*</rows>.*closes.*<cols>", cmd="camera")
import_case("opencv-xml-doctype",
            {"c.xml": opencv_xml(prolog='<?xml version="1.0"?>\n<!DOCTYPE opencv_storage [<!ENTITY x "50.">]>\n')},
            "c.xml", r"'c\.xml'.*line 2.*DOCTYPE")
import_case("opencv-xml-deep-nesting", {"c.xml": opencv_xml("<a>" + "<b>" * 100000 + "</b>" * 100000 + "</a>\n")},
            "c.xml", r"'c\.xml'.*line 3.*(nested|deeper|depth)", limit=HOSTILE, rss=HOSTILE_RSS, cmd="camera")
# FileStorage's third form, JSON: the nesting limit of its reader names the file too
import_case("opencv-json-deep-nesting", {"c.json": '{"camera_matrix": ' + "[" * 100000 + "]" * 100000 + "}\n"},
            "c.json", r"'c\.json'.*(nested|deeper|depth)", extra=["--camera-format", "opencv"], limit=HOSTILE,
            rss=HOSTILE_RSS, cmd="camera")
def opencv_yaml_distortion(values, fisheye=False):
    """opencv_yaml with `values` as its distortion_coefficients (one row), and fisheye_model: 1."""
    text = opencv_yaml().replace("   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]",
                                 f"   cols: {len(values)}\n   dt: d\n   data: [ " + ", ".join(str(v) for v in values) + " ]")
    return text + ("fisheye_model: 1\n" if fisheye else "")


import_case("opencv-yaml-distortion-count", {"c.yml": opencv_yaml_distortion([0.1, 0, 0, 0, 0, 0])}, "c.yml",
            r"'c\.yml'.*holds 6 coefficients; OpenCV's calib3d takes 4, 5, 8, 12 or 14", cmd="camera")
import_case("opencv-yaml-fisheye-count", {"c.yml": opencv_yaml_distortion([0.1, 0, 0, 0, 0], fisheye=True)}, "c.yml",
            r"'c\.yml'.*fisheye.*4", cmd="camera")
import_case("opencv-yaml-lens-folds", {"c.yml": opencv_yaml_distortion([-3.0, 0, 0, 0])}, "c.yml",
            r"'c\.yml'.*lens model opencv folds", cmd="camera")
# ROS CameraInfo
import_case("ros-unknown-distortion-model",
            {"c.yaml": ros_yaml().replace("distortion_model: plumb_bob", "distortion_model: pinhole_fancy")},
            "c.yaml#raw", r"'c\.yaml'.*distortion_model 'pinhole_fancy' is unknown", cmd="camera")
import_case("ros-k-zero-uncalibrated", {"c.yaml": ROS_UNCALIBRATED}, "c.yaml", r"'c\.yaml'.*K\[0\].*uncalibrated",
            cmd="camera")
import_case("ros-binning", {"c.yaml": ros_yaml(extra=("binning_x: 2", "binning_y: 1"))}, "c.yaml",
            r"'c\.yaml'.*binning_x is 2.*binned")
# glTF camera nodes (FILE#NODE-NAME)


def gltf_camera(node=None, **perspective):
    """A mutate for gltf(): a perspective camera node 'cam' at (0, 1, 3) added to the scene."""
    def mutate(doc):
        lens = {"yfov": 0.8, "znear": 0.1, "zfar": 100, **perspective}
        doc["cameras"] = [{"type": "perspective", "perspective": lens}]
        doc["nodes"].append({"name": "cam", "camera": 0, "translation": [0, 1, 3], **(node or {})})
        doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    return mutate


import_case("gltf-yfov-beyond-pi", {"t.gltf": gltf(gltf_camera(yfov=4))}, "t.gltf#cam",
            r"'t\.gltf'.*cameras\[0\]\.perspective\.yfov.*\b4\b.*pi", cmd="camera")
case("camera-import", "check-gltf-camera-scaled-to-zero", ["check", "--scene", "t.gltf", "--camera", "t.gltf#cam"],
     r"'t\.gltf'.*nodes\[1\].*scales its camera to zero", files={"t.gltf": gltf(gltf_camera({"scale": [0, 1, 1]}))})
# FILE#FRAME, folders, --camera-format
import_case("frame-unknown", colmap_text(), "model#img_007.png", r"'model'.*no frame 'img_007\.png'", cmd="camera")
import_case("frame-ambiguous",
            colmap_text(images="1 1 0 0 0 0 0 3 1 left/img.png\n\n2 1 0 0 0 0 0 4 1 right/img.png\n\n"),
            "model#img", r"'model'.*frame 'img'.*several cameras")
import_case("folder-not-a-colmap-model", {"model/cameras.txt": COLMAP_CAMERAS}, "model",
            r"'model'.*(not a COLMAP model|images\.(txt|bin))")
import_case("camera-format-unknown", {"c.json": GOOD_CAM}, "c.json", r"camera.format.*'colmap2'.*(expected|colmap, )",
            extra=["--camera-format", "colmap2"])

# --------------------------------------------------------------------------------------
# Depth map formats: NumPy .npy, COLMAP dense maps, HDF5
# --------------------------------------------------------------------------------------


def npy(shape=(48, 64), descr="<f4", value=5.0, header=None, length=None, cut=0, data=None):
    """A NumPy .npy (version 1.0) holding `value` everywhere; `header` replaces the dict,
    `length` the declared header length, `data` the payload."""
    head = header if header is not None else (
        "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, repr(tuple(shape))))
    head += " " * ((64 - (10 + len(head) + 1) % 64) % 64) + "\n"
    if data is None:
        count = 1
        for n in shape:
            count *= n
        data = struct.pack("<f", value) * count if count <= 1 << 20 else b""
    out = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head) if length is None else length) + head.encode() + data
    return out[:len(out) - cut] if cut else out


def colmap_depth(width=64, height=48, channels=1, value=5.0, header=None, cut=0):
    """A COLMAP dense map: "W&H&C&" and float32 values (none when the header is huge)."""
    head = header if header is not None else f"{width}&{height}&{channels}&".encode()
    n = width * height * channels
    out = head + (struct.pack("<f", value) * n if n <= 1 << 20 else b"")
    return out[:len(out) - cut] if cut else out


def hdf5_file(build):
    """A files= callable: an HDF5 file made with h5py (imported here, so that the catalogue
    itself needs only the standard library); build(h5py_file) fills it."""
    def make(path):
        import h5py  # python3-h5py
        with h5py.File(path, "w") as f:
            build(f)
    return make


def depth_case(name, files, expect, extra=(), limit=20.0, rss=None, quantity="eye-z"):
    mapname = next(iter(files))
    case("depth-format", name, ["verify", "--camera", "cam.json", "--depth-map", mapname, "--quantity", quantity]
         + list(extra), expect, files={**MAP_CAM, **files}, limit=limit, max_rss_mb=rss)


NPY = r"'m\.npy'"
CDB = r"'m\.bin'"
H5 = r"'m\.h5'"
depth_case("npy-dtype-bool", {"m.npy": npy(descr="|b1", data=b"\1" * 3072)},
           rf"{NPY}.*\|b1.*(not one zcheck reads|dtype)")
depth_case("npy-1-d-shape", {"m.npy": npy(shape=(3072,))}, rf"{NPY}.*1 dimensions?.*(height, width)")
depth_case("npy-header-length-beyond-file", {"m.npy": npy(length=60000)}, rf"{NPY}.*header.*60000.*more than the file")
depth_case("npy-99999999999-rows", {"m.npy": npy(shape=(99999999999, 64))}, rf"{NPY}.*64x99999999999.*64x48",
           limit=HOSTILE, rss=HOSTILE_RSS)
depth_case("colmap-3-channels", {"m.bin": colmap_depth(channels=3)}, rf"{CDB}.*3 channels.*(normal map|depth has 1)")
depth_case("colmap-truncated", {"m.bin": colmap_depth(cut=100)}, rf"{CDB}.*12188 bytes.*12288.*truncated")
depth_case("colmap-huge-header", {"m.bin": colmap_depth(header=b"9999999999&9999999999&1&")},
           rf"{CDB}.*9999999999x9999999999.*64x48", limit=HOSTILE, rss=HOSTILE_RSS)
depth_case("hdf5-signature-then-garbage", {"m.h5": b"\x89HDF\r\n\x1a\n" + garbage(4000)},
           rf"{H5}.*(malformed|HDF5)", limit=HOSTILE, rss=HOSTILE_RSS)
depth_case("hdf5-99999999999-rows",
           {"m.h5": hdf5_file(lambda f: f.create_dataset("depth", shape=(99999999999, 64), dtype="f4",
                                                         chunks=(1, 64)))},
           rf"{H5}.*'depth'.*64x99999999999.*(16384|64x48)", limit=HOSTILE, rss=HOSTILE_RSS)


def group_only(f):
    f.create_group("depth").attrs["units"] = "m"


depth_case("hdf5-no-dataset", {"m.h5": hdf5_file(group_only)}, rf"{H5}.*no dataset")

# --------------------------------------------------------------------------------------
# Datasets: dataset verify, report, import, submit
# --------------------------------------------------------------------------------------
DS_FILES = {"t.json": transforms()}
DSV = ["dataset", "verify", "t.json", "--quantity", "eye-z"]


def record(index=0, of=1, source="t.json", frame="images/frame_000.png", consistent=True):
    """One line of a results file (`dataset verify -o`), with the keys `dataset report` needs."""
    return json.dumps({"frame": frame, "source": source, "scene": "builtin:default", "index": index, "of": of,
                       "consistent": consistent, "seconds": 0.1}) + "\n"


case("dataset", "verify-missing-source", ["dataset", "verify", "nothere.json", "--quantity", "eye-z"],
     r"^(?!.*COLMAP).*'nothere\.json'.*No such file")
case("dataset", "verify-camera-file-as-source", ["dataset", "verify", "cam.json", "--quantity", "eye-z"],
     r"'cam\.json'.*zcheck camera.*(transforms\.json|COLMAP|manifest)", files=dict(MAP_CAM))
case("dataset", "verify-colmap-without-depth", ["dataset", "verify", "model", "--quantity", "eye-z"],
     r"'model'.*--depth", files=colmap_text())
case("dataset", "verify-shard-3-of-3", DSV + ["--shard", "3/3"], r"--shard.*'?3/3'?.*(I < N|0 <= I)",
     files=dict(DS_FILES))
case("dataset", "verify-shard-x", DSV + ["--shard", "x"], r"--shard.*'x'.*I/N", files=dict(DS_FILES))
case("dataset", "verify-results-exist-without-resume", DSV + ["-o", "results.jsonl"],
     r"'results\.jsonl'.*exists.*--resume", files=dict(DS_FILES), guard=("results.jsonl",))
case("dataset", "verify-resume-without-output", DSV + ["--resume"], r"--resume.*-o", files=dict(DS_FILES))
case("dataset", "verify-resume-results-of-another-dataset", DSV + ["-o", "results.jsonl", "--resume"],
     r"'results\.jsonl' line 1.*'other/t\.json'.*not this run",
     files={**DS_FILES, "results.jsonl": record(source="other/t.json", of=5)})
case("dataset", "verify-manifest-without-frames", ["dataset", "verify", "m.jsonl", "--quantity", "eye-z"],
     r"'m\.jsonl'.*no frames", files={"m.jsonl": "\n  \n\n"})
case("dataset", "report-malformed-line-not-last", ["dataset", "report", "r.jsonl"],
     r"'r\.jsonl' line 2.*(JSON|parse)",
     files={"r.jsonl": record(0, 3) + '{"frame": "images/frame_001.png", "source": \n' + record(2, 3, frame="f2")})
case("dataset", "report-two-datasets", ["dataset", "report", "a.jsonl", "b.jsonl"],
     r"'b\.jsonl' line 1.*dataset 'b\.json'.*'a\.json'.*(do not merge|different)",
     files={"a.jsonl": record(source="a.json", of=2), "b.jsonl": record(1, 2, source="b.json")})
case("dataset", "report-out-is-a-results-file", ["dataset", "report", "r.jsonl", "--out", "r.jsonl"],
     r"'r\.jsonl'.*(not a folder|input)", files={"r.jsonl": record()}, guard=("r.jsonl",))
case("dataset", "import-manifest", ["dataset", "import", "m.jsonl", "-o", "out.jsonl"], r"'m\.jsonl'.*manifest already",
     files={"m.jsonl": '{"frame": "f0", "camera": "cam.json", "depth": "d.pfm", "quantity": "eye-z"}\n', **MAP_CAM})
case("dataset", "submit-tasks-0", ["dataset", "submit", "t.json", "--quantity", "eye-z", "--tasks", "0", "--out", "run",
                                   "--dry-run"], rf"--tasks.*{value_rx('0')}", files=dict(DS_FILES))

# --------------------------------------------------------------------------------------
# Run only with --all: variations that exercise the same code path as a case above. Every
# zcheck start costs ~0.3 s of CPU (262 shared libraries), and the default run must fit in
# ~90 s on 2 cores.
# --------------------------------------------------------------------------------------
EXTRA = set("""mesh/ply-binary-be-face-list-longer-than-data mesh/ply-ascii-face-list-longer-than-line
mesh/ply-binary-be-2000000000-vertices mesh/ply-ascii-2000000000-vertices mesh/ply-unknown-format
mesh/ply-element-count-not-a-number mesh/ply-no-vertex-element mesh/ply-binary-be-face-index-out-of-range
mesh/ply-binary-face-index-out-of-range
mesh/ply-binary-negative-face-index mesh/ply-binary-nan-coordinate mesh/ply-ascii-inf-coordinate
mesh/ply-ascii-coordinate-1e19 mesh/ply-strip-all-repeated mesh/ply-strip-index-out-of-range
mesh/ply-strip-index-2^32 mesh/obj-nan-vertex mesh/obj-face-2-vertices mesh/obj-face-corner-not-index
mesh/obj-unknown-statement mesh/stl-binary-nan mesh/stl-binary-degenerate mesh/stl-ascii-vertex-2-numbers
mesh/stl-ascii-ends-inside-loop mesh/glb-wrong-version mesh/glb-too-short mesh/glb-accessor-count-beyond-buffer
mesh/gltf-node-own-child mesh/gltf-top-level-array
mesh/gltf-external-buffer-dotdot mesh/gltf-external-buffer-absolute mesh/gltf-buffer-http-uri
mesh/gltf-bad-base64 mesh/gltf-version-1 mesh/gltf-nan-position mesh/gltf-degenerate mesh/path-dev-zero
mesh/builtin-unknown mesh/builtin-terrain-n-1 mesh/export-obj-index-beyond mesh/verify-obj-degenerate
camera/check-empty-file camera/check-width-is-string
camera/check-width-not-integer camera/check-eye-is-string camera/check-eye-2-numbers
camera/check-reversed-is-string camera/check-far-near-ratio-1e13 camera/check-far-bad-string
camera/check-height-0 camera/check-over-2^25-pixels camera/check-missing-projection camera/check-missing-view
camera/check-up-zero camera/check-depth-range-reversed camera/check-depth-format-unorm8
camera/check-matrix-15-numbers camera/check-matrix-no-layout camera/check-matrix-bad-vectors
camera/check-matrix-wrong-convention camera/check-both-view-matrices camera/check-unknown-axonometric
camera/check-deep-nesting-unbalanced camera/check-unknown-nested-key camera/precision-top-level-array
camera/matrices-empty-path camera/unproject-unknown-key camera/precision-missing camera/matrices-directory
camera/matrices-singular-matrix
depth-map/unproject-pfm-bad-magic depth-map/unproject-pfm-width-not-number depth-map/unproject-pfm-scale-0
depth-map/unproject-pfm-empty depth-map/verify-pfm-empty depth-map/unproject-exr-garbage
depth-map/unproject-directory depth-map/unproject-missing depth-map/unproject-png16-truncated
depth-map/unproject-png16-wrong-size depth-map/unproject-scale-negative depth-map/verify-scale-nan
depth-map/unproject-scale-0 depth-map/verify-scale-inf
output/unproject-output-is-input-absolute output/unproject-output-is-camera output/export-output-trailing-slash
output/export-unknown-format output/export-png-normal output/export-pfm-primitive-id output/verify-out-empty
output/verify-out-is-input output/check-out-is-input
output/verify-out-heatmap-is-directory output/check-out-heatmap-is-directory output/export-preview-same-as-output
full-disk/unproject-ascii-ply
options/export-quantity-list-bogus options/export-quantity-empty options/unproject-map-quantity-bogus
options/unproject-pixel-negative options/unproject-pixel-fraction options/unproject-pixel-three-numbers
options/unproject-pixel-row-48 options/unproject-depth-eye-z-inf options/precision-convention-bogus
options/unproject-convention-bogus options/check-reversed-z-with-value options/export-unknown-option
options/matrices-without-camera options/check-over-2^25-pixels options/precision-at-outside
options/suite-models-missing
nothing-to-compare/check-camera-looks-away-json nothing-to-compare/verify-camera-looks-away-out
mesh/obj-coordinate-1e19 options/suite-filter-matches-nothing output/unproject-output-is-directory
output/export-output-is-directory output/export-png-without-scale output/unproject-output-missing-folder
output/suite-out-json-is-directory output/suite-json-takes-no-file full-disk/export-exr-with-preview
depth-map/verify-depth-map-empty-path camera/verify-width-100000 camera/unproject-up-parallel
camera-import/camera-opencv-xml-deep-nesting camera-import/check-gltf-camera-scaled-to-zero
""".split())

# --------------------------------------------------------------------------------------
# The runner
# --------------------------------------------------------------------------------------

REPORT_LOOK = re.compile(r"CONSISTENT|verdict|both hit|\"eye_from_world\"|\"ray\"|best for this camera|"
                         r"clean configurations|\"covered_pixels\"|\"pixels\"")


def materialise(c: Case, folder: str):
    os.makedirs(folder)
    for rel, spec in c.files.items():
        path = os.path.join(folder, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        if spec is FIFO:
            os.mkfifo(path)
        elif spec is DIR:
            os.makedirs(path, exist_ok=True)
        elif callable(spec):
            spec(path)
        else:
            with open(path, "wb") as f:
                f.write(spec.encode() if isinstance(spec, str) else spec)
    for rel in c.guard:
        path = os.path.join(folder, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(f"old {os.path.basename(rel)}\n".encode())
    if c.setup:
        c.setup(folder)


BIG_FILE = 64 << 20  # bytes: beyond, a file is fingerprinted by its size, time and ends


def snapshot(folder: str) -> dict:
    """relative path -> (kind, sha256 for regular files)"""
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, folder)
            st = os.lstat(path)
            if os.path.islink(path):
                out[rel] = ("link", os.readlink(path))
            elif os.path.isdir(path):
                out[rel] = ("dir", None)
            elif os.path.isfile(path) and st.st_size > BIG_FILE:
                # the sparse files of the size-limit cases: their size, time and both ends
                with open(path, "rb") as f:
                    ends = f.read(1 << 20) + (f.seek(-(1 << 20), os.SEEK_END) and f.read())
                out[rel] = ("file", st.st_size, st.st_mtime_ns, hashlib.sha256(ends).hexdigest())
            elif os.path.isfile(path):
                with open(path, "rb") as f:
                    out[rel] = ("file", hashlib.sha256(f.read()).hexdigest())
            else:
                out[rel] = ("special", st.st_mode)
    return out


def run(argv, cwd, limit, fsize, io_dir, tag):
    """(returncode or None on timeout, stdout, stderr, seconds, max RSS MiB, CPU seconds)"""
    def limit_files():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))

    out_path, err_path = os.path.join(io_dir, tag + ".out"), os.path.join(io_dir, tag + ".err")
    with open(out_path, "wb") as out_f, open(err_path, "wb") as err_f:
        start = time.monotonic()
        proc = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out_f, stderr=err_f,
                                start_new_session=True, preexec_fn=limit_files if fsize else None)
        timed_out = False
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > limit:
                timed_out = True
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                pid, status, usage = os.wait4(proc.pid, 0)
                break
            time.sleep(0.01)
        seconds = time.monotonic() - start
        code = os.waitstatus_to_exitcode(status)
        proc.returncode = code          # reaped here; keep Popen from waiting again
    with open(out_path, "rb") as f:
        stdout = f.read().decode("utf-8", "replace")
    with open(err_path, "rb") as f:
        stderr = f.read().decode("utf-8", "replace")
    return ((None if timed_out else code), stdout, stderr, seconds, usage.ru_maxrss / 1024.0,
            usage.ru_utime + usage.ru_stime)


def check_case(c: Case, zcheck: str, models: str, examples: str, root: str) -> tuple:
    folder = os.path.join(root, "cases", c.category + "--" + c.name.replace("/", "_"))
    materialise(c, folder)
    before = snapshot(folder)
    argv = [zcheck] + [a.replace("{examples}", examples).replace("{models}", models).replace("{dir}", folder)
                       for a in c.argv]
    code, stdout, stderr, seconds, rss, cpu = run(argv, folder, c.limit, c.fsize, os.path.join(root, "io"),
                                             c.category + "--" + c.name)
    problems = []
    if code is None:
        problems.append(f"hang (killed after {c.limit:g} s)")
    elif code < 0:
        problems.append(f"crash (signal {-code})")
    elif code != c.status:
        problems.append(f"exit status {code}, expected {c.status}")
    elif seconds > c.limit:
        problems.append(f"too slow: {seconds:.2f} s > {c.limit:g} s")
    if c.max_rss_mb is not None and rss > c.max_rss_mb:
        problems.append(f"memory: peak RSS {rss:.0f} MiB > {c.max_rss_mb:g} MiB")
    lines = stderr.splitlines()
    if len(lines) != 1:
        problems.append(f"stderr has {len(lines)} lines, expected 1")
    line = lines[0] if lines else ""
    if not line.startswith("zcheck: error:"):
        problems.append("stderr does not start with 'zcheck: error:'")
    elif not re.search(c.expect, stderr.strip(), re.IGNORECASE):
        problems.append(f"stderr does not match /{c.expect}/")
    if REPORT_LOOK.search(stdout):
        problems.append("stdout looks like a report: " + stdout.strip().replace("\n", " | ")[:200])
    after = snapshot(folder)
    for rel in sorted(set(before) | set(after)):
        if "zcheck-tmp" in rel and rel in after:
            problems.append(f"temporary left behind: {rel}")
        elif rel not in after:
            problems.append(f"removed: {rel}")
        elif rel not in before:
            problems.append(f"new file: {rel}")
        elif before[rel] != after[rel]:
            problems.append(f"changed: {rel}" + (" (guarded output)" if rel in c.guard else ""))
    return problems, argv, code, stderr, seconds, rss, cpu


def camera_format_cases(zcheck):
    """Cases for every row of zcheck's table of camera formats (`zcheck formats --json`), so a new
    format is covered without an edit here: forced with --camera-format, an empty file, bytes
    that are no format at all, and (for a one-file format) a file one byte over the format's
    size limit, sparse, refused before it is read; a folder format, an empty folder."""
    listed = subprocess.run([zcheck, "formats", "--json"], capture_output=True, text=True, check=True).stdout
    cases = []
    for row in json.loads(listed)["camera_formats"]:
        name = row["name"]

        def add(what, files, ref, expect, limit=20.0):
            cases.append(Case("camera-format", f"{name}-{what}", ["camera", ref, "--camera-format", name], expect,
                              files=files, limit=limit))

        if row["writes_folder"]:
            add("empty-folder", {"model": DIR}, "model", r"'model'.*(not a|holds no|no camera)")
            continue

        def over_limit(path, size=row["max_bytes"] + 1):
            with open(path, "wb") as f:
                f.truncate(size)

        add("empty-file", {"c": b""}, "c", r"'c'")
        add("binary-garbage", {"c": bytes(range(256)) * 4}, "c", r"'c'")
        add("over-its-limit", {"c": over_limit}, "c", r"'c'.*over the .* limit", limit=HOSTILE)
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("zcheck", nargs="?")
    parser.add_argument("models", nargs="?")
    parser.add_argument("--list", action="store_true", help="print the case names and exit")
    parser.add_argument("-k", dest="substring", default=None, help="run only cases whose name contains this")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    parser.add_argument("--all", action="store_true", help="also run the extra variations (slower)")
    parser.add_argument("-v", dest="verbose", action="store_true", help="print every case's stderr")
    args = parser.parse_args()
    if args.zcheck:
        CASES.extend(camera_format_cases(os.path.abspath(args.zcheck)))

    names = [f"{c.category}/{c.name}" for c in CASES]
    duplicates = {n for n in names if names.count(n) > 1}
    if duplicates:
        sys.exit(f"duplicate case names: {sorted(duplicates)}")
    unknown = EXTRA - set(names)
    if unknown:
        sys.exit(f"EXTRA names unknown cases: {sorted(unknown)}")
    selected = [c for c, n in zip(CASES, names)
                if (args.all or n not in EXTRA) and (args.substring is None or args.substring in n)]
    if args.list:
        for c in selected:
            print(f"{c.category}/{c.name}")
        return 0
    if not args.zcheck or not args.models:
        parser.error("usage: catalogue.py ZCHECK MODELS_DIR [--list] [-k SUBSTRING]")
    zcheck = os.path.abspath(args.zcheck)
    models = os.path.abspath(args.models)
    examples = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples"))
    if not os.access(zcheck, os.X_OK):
        sys.exit(f"not an executable: {zcheck}")

    root = tempfile.mkdtemp(prefix="zc-bad-input-")
    os.makedirs(os.path.join(root, "io"))
    start = time.monotonic()
    counts = {}
    failed = []
    stray = []
    total_cpu = 0.0
    try:
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            futures = [pool.submit(check_case, c, zcheck, models, examples, root) for c in selected]
            for c, fut in zip(selected, futures):
                try:
                    problems, argv, code, stderr, seconds, rss, cpu = fut.result()
                except Exception as e:  # a bug in the catalogue itself
                    problems, argv, code, stderr = [f"catalogue error: {e!r}"], c.argv, None, ""
                    seconds = rss = cpu = 0
                total_cpu += cpu
                ok = not problems
                p, f = counts.get(c.category, (0, 0))
                counts[c.category] = (p + ok, f + (not ok))
                if ok and args.verbose:
                    print(f"ok   {c.category}/{c.name}  ({seconds:.2f} s): {stderr.strip()}")
                if not ok:
                    failed.append(c)
                    print(f"FAIL {c.category}/{c.name}  ({seconds:.2f} s, {rss:.0f} MiB)")
                    print("  command: " + shlex.join(argv) + "   (run in the case folder)")
                    print(f"  exit:    {'timeout' if code is None else code}")
                    print("  stderr:  " + (stderr.rstrip("\n").replace("\n", "\n           ") or "(empty)"))
                    for problem in problems:
                        print("  - " + problem)
        # a temporary anywhere in the tree, also outside the case folders (counts as a failure)
        for dirpath, dirs, files in os.walk(root):
            for name in dirs + files:
                if "zcheck-tmp" in name and "/cases/" not in dirpath + "/":
                    print(f"FAIL temporary left behind outside the case folders: {os.path.join(dirpath, name)}")
                    stray.append(name)
    finally:
        if not args.keep:
            shutil.rmtree(root, ignore_errors=True)
        else:
            print(f"kept {root}")
    elapsed = time.monotonic() - start
    print()
    for category, (p, f) in counts.items():
        print(f"{category:20s} {p + f:4d} cases: {p} passed, {f} failed")
    print(f"({elapsed:.1f} s wall, {total_cpu:.1f} s CPU in zcheck)")
    total_failed = len(failed) + len(stray)
    print(f"{len(selected) - len(failed)} passed, {total_failed} failed")
    return 0 if total_failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
