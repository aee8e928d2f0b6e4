#!/usr/bin/env python3
"""Mutation fuzzer for `canopy render`: scene JSON, OBJ/MTL, pbrt-v4 and PLY files, special files.

Every mutant is a scene (plus any OBJ/MTL it needs; for pbrt, scene.pbrt plus the files it
includes and the PLY files it references) in its own directory, rendered with
`canopy render scene.json --spp 1 --out out.exr` (scene.pbrt) at an 8 x 8 film (the film is
rewritten in the seed before mutation, so only mutations aimed at `film` change it). An outcome
passes when it is

  * exit 0 and out.exr exists with every pixel finite (checked with `iinfo --stats`), or
  * exit 2 and stderr is exactly one line, without control bytes, valid UTF-8, that begins with
    the scene path as given (when that path is printable); for pbrt, with `FILE: ` or
    `FILE:LINE: ` where FILE is the scene path or one of the mutant's files.

Anything else fails: a timeout, a signal, exit 1, any other exit code, a multi-line or unescaped
exit-2 message, a missing or non-finite image. Each failing mutant is moved to OUT/failures/<id>
with `cmd.sh` (reproduces it), `stdout.txt`, `stderr.txt` and `result.txt`.

Mutant i depends only on --seed, --formats and i (not on --count or --jobs), so a failure is
reproduced by `--seed S [--formats F] --only i`. Standard library only. docs/testing.md has the short and the long form.
"""

import argparse
import concurrent.futures
import copy
import gzip
import io
import json
import math
import os
import random
import re
import shutil
import signal
import struct
import subprocess
import sys
import threading
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FILM = 8
# Seeds whose load alone takes seconds (10^6 lights, 3*10^5 lights + a 300 KB OBJ): only in the
# long form (--no-heavy leaves them out).
HEAVY_SEEDS = {"cornell-1m.json", "city.json", "city-fog.json"}
# A mutant whose legal workload is large (many lights, a big film) says nothing about robustness
# and would only time out: it is redrawn. Illegal values (above the format's limits) are kept.
MAX_LIGHTS = 2_000_000
MAX_PIXELS = 4_000_000
LIGHT_CAP = 50_000_000  # docs/scene-format.md: at most 5*10^7 lights
FILM_CAP = 16384


# ------------------------------------------------------------------ JSON tree with duplicates
class Obj(list):
    """A JSON object as an ordered list of [key, value] pairs (keys may repeat or be bytes)."""


class Raw:
    """A token written verbatim (NaN, 1e999, a huge integer, ...)."""

    def __init__(self, text):
        self.b = text.encode() if isinstance(text, str) else text

    def __repr__(self):
        return self.b.decode("latin-1")


class RawStr:
    """A string whose bytes are written verbatim between quotes (raw control or invalid bytes)."""

    def __init__(self, b):
        self.b = b

    def __repr__(self):
        return '"' + self.b.decode("latin-1").encode("unicode_escape").decode() + '"'


def strip_comments(text):
    out, i, n, in_str = [], 0, len(text), False
    while i < n:
        c = text[i]
        if in_str:
            out.append(c)
            if c == "\\" and i + 1 < n:
                out.append(text[i + 1])
                i += 2
                continue
            if c == '"':
                in_str = False
            i += 1
        elif c == '"':
            in_str = True
            out.append(c)
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
            out.append(" ")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def parse(text):
    return json.loads(strip_comments(text), object_pairs_hook=lambda p: Obj([list(kv) for kv in p]))


def key_bytes(k):
    if isinstance(k, bytes):
        return b'"' + k + b'"'
    return json.dumps(k).encode()


def is_scalar(v):
    return not isinstance(v, list)


def dump(v, ind=0):
    pad = b"  " * (ind + 1)
    if isinstance(v, Obj):
        if not v:
            return b"{}"
        items = [pad + key_bytes(k) + b": " + dump(x, ind + 1) for k, x in v]
        return b"{\n" + b",\n".join(items) + b"\n" + b"  " * ind + b"}"
    if isinstance(v, list):
        if len(v) <= 8 and all(is_scalar(x) for x in v):
            return b"[" + b", ".join(dump(x, ind + 1) for x in v) + b"]"
        return b"[\n" + b",\n".join(pad + dump(x, ind + 1) for x in v) + b"\n" + b"  " * ind + b"]"
    if isinstance(v, Raw):
        return v.b
    if isinstance(v, RawStr):
        return b'"' + v.b + b'"'
    if v is None or isinstance(v, bool):
        return json.dumps(v).encode()
    if isinstance(v, str):
        return json.dumps(v).encode()
    if isinstance(v, int):
        return str(v).encode()
    if isinstance(v, float):
        return repr(v).encode()
    raise TypeError(type(v))


def slots(node, path="$"):
    """Every (parent, index, path) below node; parent is an Obj (index of the pair) or a list."""
    if isinstance(node, Obj):
        for i, (k, v) in enumerate(node):
            p = f"{path}.{k if isinstance(k, str) else repr(k)}"
            yield node, i, p
            yield from slots(v, p)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            p = f"{path}[{i}]"
            yield node, i, p
            yield from slots(v, p)


def get(parent, i):
    return parent[i][1] if isinstance(parent, Obj) else parent[i]


def put(parent, i, v):
    if isinstance(parent, Obj):
        parent[i][1] = v
    else:
        parent[i] = v


def key_of(parent, i):
    return parent[i][0] if isinstance(parent, Obj) else None


def member(obj, key):
    if isinstance(obj, Obj):
        for k, v in obj:
            if k == key:
                return v
    return None


def set_member(obj, key, value):
    for pair in obj:
        if pair[0] == key:
            pair[1] = value
            return
    obj.append([key, value])


def as_number(v):
    if isinstance(v, bool):
        return None
    if isinstance(v, (int, float)):
        return float(v)
    if isinstance(v, Raw):
        try:
            return float(v.b.decode("latin-1"))
        except ValueError:
            return None
    return None


def is_number(v):
    return as_number(v) is not None


# ------------------------------------------------------------------ mutation vocabulary
EXTREMES = [
    "0", "-0", "-0.0", "1e-45", "-1e-45", "1e-40", "-1e-40", "1e-300", "0.5", "-1",
    "1e18", "1e19", "1e38", "-1e38", "3e38", "-3e38", "3.4028235e38", "3.5e38", "1e308", "-1e308",
    "1e999", "-1e999", "NaN", "nan", "Infinity", "-Infinity", "inf",
    "123456789012345678901234567890", "-123456789012345678901234567890",
    "16777216", "16777217", "2147483647", "2147483648", "4294967295", "4294967296",
    "-2147483649", "18446744073709551616",
    "0x10", "1.", ".5", "+1", "01", "1e", "--1", "1e38.5",
]

WEIRD_STRINGS = [
    "", " ", "a\nb", "line1\nline2\nline3", "a\rb", "a\u0000b", "\u0000", "tab\there",
    "\u001b[31mred\u001b[0m", "\u007f", "\u202eevil", "ключ", "\U0001f600", "x" * 10000,
    "%s%n%x", "{}{}", "../../../../etc/passwd", 'a"b', "a\\b",
]
WEIRD_RAW = [b"\xff\xfe", b"a\nb", b"\xc3", b"a\x00b", b"\xed\xa0\x80", b"\x1b[2J", b"a\tb"]

ENUMS = [
    "point", "spot", "sphere", "quad", "triangle", "disk", "obj", "box", "grid", "random_box", "spiral",
    "mesh_surface", "diffuse", "conductor", "plastic", "gold", "silver", "Gold", "aluminum",
    "uniform", "power", "tree", "tree-split", "exhaustive", "Tree",
    "tree_split", "tree-split ", "POINT",
]

KNOWN_KEYS = [
    "camera", "film", "integrator", "materials", "shapes", "lights", "light_sets", "position",
    "look_at", "up", "fov", "width", "height", "spp", "max_depth", "light_sampler",
    "split_threshold", "seed", "name", "type", "albedo", "material", "emission", "two_sided",
    "transform", "file", "corner", "edge1", "edge2", "min", "max", "rotate_y", "scale", "rotate",
    "axis", "degrees", "translate", "intensity", "direction", "cone_angle", "falloff_start",
    "center", "radius", "radiance", "v0", "v1", "v2", "light", "count", "variation", "instance",
    "origin", "nx", "ny", "inner_radius", "turns", "height", "shape", "offset", "align_to_normal",
    "color", "roughness", "metal", "eta", "k", "specular", "ior", "normal",
]

PATH_VALUES = ["", ".", "/", "/dev/null", "/dev/zero", "/etc/passwd", "missing.obj",
               "scene.json", "nodir/x.obj", "x" * 5000 + ".obj"]

POSITION_KEYS = {"position", "look_at", "corner", "min", "max", "center", "origin", "v0", "v1",
                 "v2", "translate"}
EMISSION_KEYS = {"intensity", "radiance", "emission"}
COUNT_KEYS = {"count", "nx", "ny"}


def type_values():
    return [Raw("null"), True, False, 0, 1, -1, "", "1", "abc", [], [1], [1, 2, 3], [[1, 2, 3]],
            Obj(), Obj([["x", 1]]), [None, None, None], ["1", "2", "3"], [1, 2, 3, 4]]


def weird_string(rng):
    if rng.random() < 0.3:
        return RawStr(rng.choice(WEIRD_RAW))
    return rng.choice(WEIRD_STRINGS)


# ------------------------------------------------------------------ tree mutations
class Mutant:
    def __init__(self, ident, seed_path):
        self.ident = ident
        self.seed = seed_path
        self.ops = []  # human-readable descriptions
        self.files = {}  # name -> bytes (written into the mutant directory)
        self.setup = []  # (kind, name, target) for special files: fifo, dir, symlink
        self.scene_arg = "scene.json"
        self.kind = ""
        self.args = []  # extra command-line options (CLI cases)
        self.expect_error = False  # exit 0 is a failure too (input that must be refused)
        self.names = None  # what the one-line error must begin with (default: the scene path)
        self.pbrt = False  # a pbrt scene: the error may begin with any file of the mutant


def pick_slot(rng, tree, pred):
    cands = [(p, i, path) for p, i, path in slots(tree) if pred(p, i)]
    return rng.choice(cands) if cands else None


def m_key_rename(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(p, Obj))
    if not s:
        return False
    p, i, path = s
    k = p[i][0]
    k = k if isinstance(k, str) else "k"
    choice = rng.randrange(5)
    if choice == 0 and len(k) > 1:
        j = rng.randrange(len(k))
        new = k[:j] + k[j + 1:]
    elif choice == 1:
        new = k.upper()
    elif choice == 2:
        new = rng.choice(KNOWN_KEYS)
    elif choice == 3:
        new = k + rng.choice(["s", "_", " ", "2"])
    else:
        new = ""
    p[i][0] = new
    m.ops.append(f"key-rename {path} -> {new!r}")
    return True


def m_key_delete(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(p, Obj))
    if not s:
        return False
    p, i, path = s
    del p[i]
    m.ops.append(f"key-delete {path}")
    return True


def m_key_duplicate(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(p, Obj))
    if not s:
        return False
    p, i, path = s
    dup = copy.deepcopy(p[i])
    if rng.random() < 0.5:
        dup[1] = rng.choice(type_values())
    p.insert(i + 1, dup)
    m.ops.append(f"key-duplicate {path}")
    return True


def m_key_weird(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(p, Obj))
    if not s:
        return False
    p, i, path = s
    w = weird_string(rng)
    k = p[i][0] if isinstance(p[i][0], str) else "k"
    if isinstance(w, RawStr):
        p[i][0] = (k.encode() + w.b) if rng.random() < 0.5 else w.b
    else:
        p[i][0] = (k + w) if rng.random() < 0.5 else w
    m.ops.append(f"key-weird {path} -> {p[i][0]!r:.60}")
    return True


def m_string(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(get(p, i), str))
    if not s:
        return False
    p, i, path = s
    r = rng.random()
    if key_of(p, i) == "file" and r < 0.5:
        v = rng.choice(PATH_VALUES)
    elif r < 0.5:
        v = rng.choice(ENUMS)
    else:
        v = weird_string(rng)
    put(p, i, v)
    m.ops.append(f"string {path} = {v!r:.60}")
    return True


def m_type(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: True)
    if not s:
        return False
    p, i, path = s
    v = rng.choice(type_values())
    put(p, i, v)
    m.ops.append(f"type {path} = {dump(v).decode('latin-1')[:40]}")
    return True


def m_number(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: is_number(get(p, i)))
    if not s:
        return False
    p, i, path = s
    v = Raw(rng.choice(EXTREMES))
    put(p, i, v)
    m.ops.append(f"number {path} = {v!r}")
    return True


def m_vector(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(get(p, i), list) and not isinstance(
        get(p, i), Obj) and get(p, i) and all(is_number(x) for x in get(p, i)))
    if not s:
        return False
    p, i, path = s
    vec = get(p, i)
    c = rng.randrange(4)
    if c == 0:
        vec.pop(rng.randrange(len(vec)))
        what = "drop a component"
    elif c == 1:
        vec.append(rng.choice([1, Raw("NaN"), "1"]))
        what = "add a component"
    elif c == 2:
        vec.clear()
        what = "empty"
    else:
        vec[:] = [Raw(rng.choice(EXTREMES))] * len(vec)
        what = f"all = {vec[0]!r}"
    m.ops.append(f"vector {path}: {what}")
    return True


def m_array(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: isinstance(get(p, i), list) and not isinstance(
        get(p, i), Obj) and get(p, i) and isinstance(get(p, i)[0], Obj))
    if not s:
        return False
    p, i, path = s
    arr = get(p, i)
    c = rng.randrange(4)
    j = rng.randrange(len(arr))
    if c == 0:
        del arr[j]
        what = f"delete [{j}]"
    elif c == 1:
        arr.insert(j, copy.deepcopy(arr[j]))
        what = f"duplicate [{j}]"
    elif c == 2:
        arr[j:j + 1] = [copy.deepcopy(arr[j]) for _ in range(100)]
        what = f"[{j}] x 100"
    else:
        arr.clear()
        what = "empty"
    m.ops.append(f"array {path}: {what}")
    return True


def m_translate(rng, tree, m):
    """Moves the whole scene (camera included): coordinates far from the origin (finding 3/6)."""
    off = rng.choice([1e3, 1e4, 1e5, 1e6, 1e8, 1e12, 1e18, 1e30, 1e37, 1e38, 3e38, -3e38])
    axis = rng.randrange(3)
    n = 0
    for p, i, path in list(slots(tree)):
        k = key_of(p, i)
        v = get(p, i)
        if ".light_sets[" in path and (".light." in path or ".instance." in path):
            continue
        if k in POSITION_KEYS and isinstance(v, list) and len(v) == 3 and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
            # Light-set template offsets stay offsets: only absolute positions move.
            v[axis] = float(v[axis]) + off
            n += 1
    m.ops.append(f"translate axis {axis} by {off:g} ({n} positions)")
    return n > 0


def m_scale(rng, tree, m):
    """Scales every length: the scene at a huge or tiny scale."""
    f = rng.choice([1e-30, 1e-20, 1e-10, 1e10, 1e20, 1e30, 1e37])
    n = 0
    for p, i, _ in list(slots(tree)):
        k = key_of(p, i)
        v = get(p, i)
        if k in POSITION_KEYS | {"edge1", "edge2"} and isinstance(v, list) and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
            v[:] = [float(x) * f for x in v]
            n += 1
        elif k in {"radius", "offset", "inner_radius", "height"} and isinstance(
                v, (int, float)) and not isinstance(v, bool):
            put(p, i, float(v) * f)
            n += 1
    m.ops.append(f"scale lengths by {f:g} ({n} values)")
    return n > 0


def m_emission(rng, tree, m):
    """Every emission at one extreme value (film overflow, denormal energies)."""
    val = rng.choice(["3e38", "3.4e38", "1e38", "1e37", "1e30", "1e-30", "1e-38", "1e-40",
                      "1e-45", "0"])
    n = 0
    for p, i, _ in list(slots(tree)):
        if key_of(p, i) in EMISSION_KEYS:
            put(p, i, Raw(val))
            n += 1
    # 16 samples per pixel: one sample cannot overflow the film's per-pixel sum (finding 4).
    m.args = ["--spp", "16"]
    m.ops.append(f"emission all = {val} ({n} values), --spp 16")
    return n > 0


def m_counts(rng, tree, m):
    s = pick_slot(rng, tree, lambda p, i: key_of(p, i) in COUNT_KEYS | {"width", "height"})
    if not s:
        return False
    p, i, path = s
    v = Raw(rng.choice(["0", "-1", "1", "1.5", '"10"', "50000001", "2147483648", "4294967297",
                        "1e308", "1e9", "16385", "100000000000"]))
    put(p, i, v)
    m.ops.append(f"count {path} = {v!r}")
    return True


def m_extent(rng, tree, m):
    """Extents that are finite but whose derived values overflow: a box from -X to +X, a
    transform scale of X, a light-set origin or edge of X (X near the float maximum)."""
    x = rng.choice([1e30, 1e37, 1e38, 3e38, 3.4e38])
    objs = [p for p, i, _ in slots(tree) if isinstance(p, Obj) and i == 0]
    boxes = [o for o in objs if member(o, "min") is not None and member(o, "max") is not None]
    shapes = [o for o in objs if member(o, "type") in ("box", "quad", "obj")]
    sets = [o for o in objs if member(o, "origin") is not None or member(o, "center") is not None]
    c = rng.randrange(3)
    if c == 0 and boxes:
        o = rng.choice(boxes)
        set_member(o, "min", [-x, -x, -x] if rng.random() < 0.5 else [-x, 0, -x])
        set_member(o, "max", [x, x, x])
        m.ops.append(f"extent: box from -{x:g} to {x:g}")
    elif c == 1 and shapes:
        o = rng.choice(shapes)
        set_member(o, "transform", Obj([["scale", x if rng.random() < 0.5 else [x, 1, 1]]]))
        m.ops.append(f"extent: transform scale {x:g}")
    elif sets:
        o = rng.choice(sets)
        key = "origin" if member(o, "origin") is not None else "center"
        set_member(o, key, [x, x, -x])
        if member(o, "edge1") is not None:
            set_member(o, "edge1", [x, 0, 0])
        m.ops.append(f"extent: {key} ({x:g}, {x:g}, {-x:g})")
    else:
        return False
    return True


TREE_OPS = {
    "key-rename": (m_key_rename, 4), "key-delete": (m_key_delete, 5),
    "key-duplicate": (m_key_duplicate, 4), "key-weird": (m_key_weird, 4),
    "string": (m_string, 6), "type": (m_type, 8), "number": (m_number, 14),
    "vector": (m_vector, 5), "array": (m_array, 4), "translate": (m_translate, 4),
    "scale": (m_scale, 2), "emission": (m_emission, 3), "count": (m_counts, 3),
    "extent": (m_extent, 4),
}


def estimated_work(tree):
    """(lights, pixels) the scene asks for, as far as the mutated values can be read."""
    lights = 0.0
    sets = member(tree, "light_sets")
    if isinstance(sets, list) and not isinstance(sets, Obj):
        for ls in sets:
            c = as_number(member(ls, "count"))
            if c is None:
                nx, ny = as_number(member(ls, "nx")), as_number(member(ls, "ny"))
                c = nx * ny if nx is not None and ny is not None else 0.0
            if not math.isnan(c) and c > 0:
                lights += c
    film = member(tree, "film")
    w, h = as_number(member(film, "width")), as_number(member(film, "height"))
    pixels = (w if w is not None else 640) * (h if h is not None else 480)
    return lights, pixels


def too_heavy(tree):
    if not isinstance(tree, Obj):
        return False
    lights, pixels = estimated_work(tree)
    legal_lights = lights <= LIGHT_CAP
    return (legal_lights and lights > MAX_LIGHTS) or (pixels > MAX_PIXELS and not math.isnan(
        pixels) and pixels <= FILM_CAP * FILM_CAP)


# ------------------------------------------------------------------ byte mutations
def b_mutate(rng, data, m):
    data = bytearray(data)
    c = rng.randrange(8)
    if c == 0 or not data:
        cut = rng.randrange(len(data) + 1)
        m.ops.append(f"truncate at byte {cut} of {len(data)}")
        return bytes(data[:cut])
    if c == 1:
        n = rng.randint(1, 8)
        for _ in range(n):
            data[rng.randrange(len(data))] = rng.randrange(256)
        m.ops.append(f"flip {n} bytes")
    elif c == 2:
        ins = rng.choice([b"\x00", b"\xff", b"\n", b"{", b"}", b"[", b"]", b'"', b",", b":",
                          b"/*", b"//", b"\\", b"\xc3\x28", bytes(rng.randrange(256)
                                                              for _ in range(16))])
        pos = rng.randrange(len(data) + 1)
        data[pos:pos] = ins
        m.ops.append(f"insert {ins!r} at {pos}")
    elif c == 3:
        a = rng.randrange(len(data))
        b = min(len(data), a + rng.randint(1, 64))
        del data[a:b]
        m.ops.append(f"delete bytes {a}..{b}")
    elif c == 4:
        a = rng.randrange(len(data))
        b = min(len(data), a + rng.randint(1, 200))
        pos = rng.randrange(len(data) + 1)
        data[pos:pos] = data[a:b]
        m.ops.append(f"splice bytes {a}..{b} at {pos}")
    elif c == 5:
        enc = rng.randrange(4)
        if enc == 0:
            data = bytearray(b"\xef\xbb\xbf" + data)
            m.ops.append("UTF-8 BOM")
        elif enc == 1:
            data = bytearray(data.decode("utf-8", "replace").encode("utf-16"))
            m.ops.append("UTF-16")
        elif enc == 2:
            data = data + data
            m.ops.append("two documents")
        else:
            data = data + b"\x00" * 16
            m.ops.append("trailing NULs")
    elif c == 6:
        depth = rng.choice([1000, 100000])
        opener = rng.choice([b"[", b"{\"a\":"])
        data = bytearray(opener * depth)
        m.ops.append(f"nesting {opener!r} x {depth}")
    else:
        pos = rng.randrange(len(data) + 1)
        data[pos:pos] = b"1" * rng.choice([400, 5000])
        m.ops.append(f"long digit run at {pos}")
    return bytes(data)


# ------------------------------------------------------------------ OBJ / MTL mutations
OBJ_POOL = ["tests/fuzz/mesh.obj", "scenes/cornell/cornell.obj", "tests/data/emissive.obj",
            "scenes/mesh-light/torus.obj"]
BAD_COORDS = ["nan", "NaN", "-nan", "inf", "-inf", "infinity", "1e38", "3e38", "-3e38", "3.5e38",
              "1e39", "1e-45", "1e-40", "1e308", "abc", "1e", "--1", "0x1p3", "", "1,5"]
BAD_INDICES = ["0", "999999", "-999999", "2147483648", "99999999999999999999", "a", "1/2/3/4",
               "1//", "//1", "-0", "1.5", ""]


def obj_lines_mutation(rng, lines, m, name):
    vs = [i for i, l in enumerate(lines) if l.startswith("v ")]
    fs = [i for i, l in enumerate(lines) if l.startswith("f ")]
    c = rng.randrange(9)
    if c == 0 and vs:
        i = rng.choice(vs)
        parts = lines[i].split()
        j = rng.randrange(1, len(parts))
        parts[j] = rng.choice(BAD_COORDS)
        lines[i] = " ".join(parts)
        m.ops.append(f"{name}: vertex line {i + 1} -> {lines[i]!r}")
    elif c == 1 and vs:
        i = rng.choice(vs)
        parts = lines[i].split()
        k = rng.choice([1, 2, 3, 5, 7])
        lines[i] = " ".join(parts[:k]) if k <= len(parts) else " ".join(parts + ["1"] * (k - len(parts)))
        m.ops.append(f"{name}: vertex line {i + 1} with {k - 1} components")
    elif c == 2 and fs:
        i = rng.choice(fs)
        parts = lines[i].split()
        j = rng.randrange(1, len(parts))
        parts[j] = rng.choice(BAD_INDICES)
        lines[i] = " ".join(parts)
        m.ops.append(f"{name}: face line {i + 1} -> {lines[i]!r}")
    elif c == 3 and fs:
        i = rng.choice(fs)
        parts = lines[i].split()
        k = rng.choice([1, 2, 3])
        lines[i] = " ".join(parts[:k])
        m.ops.append(f"{name}: face line {i + 1} with {k - 1} vertices")
    elif c == 4:
        n = rng.choice([1000, 20000, 100000])
        base = len(vs)
        for k in range(n):
            a = 2 * math.pi * k / n
            lines.append(f"v {math.cos(a):.7f} 1.5 {math.sin(a):.7f}")
        lines.append("f " + " ".join(str(base + k + 1) for k in range(n)))
        m.ops.append(f"{name}: one face of {n} vertices")
    elif c == 5 and lines:
        i = rng.randrange(len(lines))
        what = rng.randrange(3)
        if what == 0:
            del lines[i]
            m.ops.append(f"{name}: delete line {i + 1}")
        elif what == 1:
            lines.insert(i, lines[i])
            m.ops.append(f"{name}: duplicate line {i + 1}")
        else:
            lines[i] = rng.choice(["mtllib missing.mtl", "mtllib .", "mtllib /dev/null",
                                   "mtllib", "usemtl nosuch", "usemtl", "usemtl a\x1bb",
                                   "mtllib a\x00b.mtl", "o", "g", "s off", "vn nan 0 0",
                                   "vt 1e39 0", "l 1 2", "p 1", "f", "v", "\x00", "\xff\xfe"])
            m.ops.append(f"{name}: line {i + 1} -> {lines[i]!r}")
    elif c == 6:
        lines[:] = [l for l in lines if not l.startswith("f ")]
        m.ops.append(f"{name}: no faces")
    elif c == 7 and fs:
        i = rng.choice(fs)
        lines[i:i + 1] = [lines[i]] * 1000
        m.ops.append(f"{name}: face line {i + 1} x 1000")
    else:
        return False
    return True


def mtl_lines_mutation(rng, lines, m, name):
    vals = [i for i, l in enumerate(lines) if re.match(r"\s*(Kd|Ke|Ks|Ns|Ka|d|Tr|Ni)\b", l)]
    c = rng.randrange(5)
    if c <= 1 and vals:
        i = rng.choice(vals)
        parts = lines[i].split()
        if c == 0 and len(parts) > 1:
            j = rng.randrange(1, len(parts))
            parts[j] = rng.choice(BAD_COORDS + ["-1", "2", "-0"])
        else:
            parts = parts[:rng.choice([1, 2, 3])]
        lines[i] = " ".join(parts)
        m.ops.append(f"{name}: line {i + 1} -> {lines[i]!r}")
    elif c == 2:
        mats = [i for i, l in enumerate(lines) if l.startswith("newmtl")]
        if not mats:
            return False
        i = rng.choice(mats)
        if rng.random() < 0.5:
            lines[i] = rng.choice(["newmtl", "newmtl a\nb", "newmtl \x1b[31m", "newmtl " + "m" * 5000])
        else:
            lines.insert(i, lines[i])
        m.ops.append(f"{name}: newmtl line {i + 1} -> {lines[i]!r:.60}")
    elif c == 3:
        lines.append(rng.choice(["Ke 3e38 3e38 3e38", "Ke 1e-45 0 0", "Ke nan 1 1", "Kd 1 1 1",
                                 "Ke 1e30 1e30 1e30", "map_Kd /dev/zero", "map_Kd missing.png"]))
        m.ops.append(f"{name}: append {lines[-1]!r}")
    else:
        if not lines:
            return False
        i = rng.randrange(len(lines))
        del lines[i]
        m.ops.append(f"{name}: delete line {i + 1}")
    return True


def obj_shape_slots(tree):
    """(obj, pair index) of every `file` member of an obj shape (shapes and instances)."""
    out = []
    for p, i, _ in slots(tree):
        if isinstance(p, Obj) and p[i][0] == "file" and member(p, "type") == "obj":
            out.append((p, i))
    return out


def mutate_obj(rng, tree, m):
    cands = obj_shape_slots(tree)
    if cands:
        p, i = rng.choice(cands)
        src = Path(p[i][1])
        if not src.is_absolute():
            return False
    else:
        src = ROOT / rng.choice(OBJ_POOL)
        shapes = member(tree, "shapes")
        if not isinstance(shapes, list) or isinstance(shapes, Obj):
            shapes = []
            set_member(tree, "shapes", shapes)
        shape = Obj([["type", "obj"], ["file", str(src)]])
        shapes.append(shape)
        p, i = shape, 1
    text = src.read_text(encoding="utf-8", errors="replace")
    lines = text.split("\n")
    # Copy the OBJ and its MTL files next to the scene; rewrite mtllib to the copies.
    mtls = {}
    for k, l in enumerate(lines):
        if l.startswith("mtllib "):
            name = l.split(None, 1)[1].strip()
            mpath = src.parent / name
            if mpath.is_file():
                mtls["m_" + Path(name).name] = mpath.read_text(encoding="utf-8", errors="replace")
                lines[k] = "mtllib m_" + Path(name).name
    p[i][1] = "m.obj"
    m.ops.append(f"obj {src.relative_to(ROOT) if src.is_relative_to(ROOT) else src}")
    ok = False
    for _ in range(rng.choice([1, 1, 2, 3])):
        if mtls and rng.random() < 0.35:
            mname = rng.choice(sorted(mtls))
            mlines = mtls[mname].split("\n")
            if mtl_lines_mutation(rng, mlines, m, mname):
                mtls[mname] = "\n".join(mlines)
                ok = True
        elif rng.random() < 0.1:
            data = b_mutate(rng, "\n".join(lines).encode("utf-8", "surrogateescape"), m)
            lines = data.decode("utf-8", "surrogateescape").split("\n")
            ok = True
        elif obj_lines_mutation(rng, lines, m, "m.obj"):
            ok = True
    m.files["m.obj"] = "\n".join(lines).encode("utf-8", "surrogateescape")
    for name, t in mtls.items():
        m.files[name] = t.encode("utf-8", "surrogateescape")
    return ok


# ------------------------------------------------------------------ seeds
def absolutize(tree, seed_dir):
    for p, i in obj_shape_slots(tree):
        f = p[i][1]
        if isinstance(f, str) and not os.path.isabs(f):
            p[i][1] = str((seed_dir / f).resolve())


def load_seeds(heavy):
    paths = sorted((ROOT / "scenes").glob("*.json")) + sorted((ROOT / "tests/fuzz").glob("*.json"))
    seeds = []
    for path in paths:
        if not heavy and path.name in HEAVY_SEEDS:
            continue
        tree = parse(path.read_text(encoding="utf-8"))
        absolutize(tree, path.parent)
        set_member(tree, "film", Obj([["width", FILM], ["height", FILM]]))
        seeds.append((path, tree))
    return seeds


def minimal_scene(obj_file):
    return Obj([
        ["camera", Obj([["position", [0, 1, 4]], ["look_at", [0, 0.5, 0]]])],
        ["film", Obj([["width", FILM], ["height", FILM]])],
        ["shapes", [Obj([["type", "obj"], ["file", obj_file]])]],
        ["lights", [Obj([["type", "point"], ["position", [0, 1.8, 0]], ["intensity", 1]])]],
    ])


def mesh_with_mtl(mtl_name):
    text = (ROOT / "tests/fuzz/mesh.obj").read_text()
    return text.replace("mtllib mesh.mtl", f"mtllib {mtl_name}").encode()


# Special files, each run once as the first mutants (ids 0 ...): the scene path, an OBJ path and
# an MTL path that are not regular files, or whose names carry control characters.
def special_cases():
    ok_scene = dump(minimal_scene("m.obj"))
    mesh = (ROOT / "tests/fuzz/mesh.obj").read_bytes()
    mtl = (ROOT / "tests/fuzz/mesh.mtl").read_bytes()
    cases = []

    def case(kind, arg="scene.json", files=None, setup=(), args=(), names=None):
        cases.append((kind, arg, files or {}, list(setup), list(args), names))

    case("scene-fifo", setup=[("fifo", "scene.json", None)])
    case("scene-dev-zero", arg="/dev/zero")
    case("scene-dev-null", arg="/dev/null")
    case("scene-symlink-dev-zero", setup=[("symlink", "scene.json", "/dev/zero")])
    case("scene-directory", setup=[("dir", "scene.json", None)])
    case("scene-missing", arg="missing.json")
    case("scene-empty", files={"scene.json": b""})
    case("scene-symlink-loop", setup=[("symlink", "scene.json", "loop.json"),
                                      ("symlink", "loop.json", "scene.json")])
    case("scene-name-newline", arg="bad\nname.json", files={"bad\nname.json": b"{"})
    case("scene-name-escape", arg="\x1b[31mred.json", files={"\x1b[31mred.json": b"{\"camera\": 1}"})
    case("obj-fifo", files={"scene.json": ok_scene}, setup=[("fifo", "m.obj", None)])
    case("obj-dev-zero", files={"scene.json": dump(minimal_scene("/dev/zero"))})
    case("obj-directory", files={"scene.json": ok_scene}, setup=[("dir", "m.obj", None)])
    case("obj-missing", files={"scene.json": ok_scene})
    case("obj-empty", files={"scene.json": ok_scene, "m.obj": b""})
    case("obj-symlink-loop", files={"scene.json": ok_scene},
         setup=[("symlink", "m.obj", "n.obj"), ("symlink", "n.obj", "m.obj")])
    case("obj-name-newline", files={"scene.json": dump(minimal_scene("a\nb.obj"))})
    case("mtl-fifo", files={"scene.json": ok_scene, "m.obj": mesh_with_mtl("m.mtl")},
         setup=[("fifo", "m.mtl", None)])
    case("mtl-dev-zero", files={"scene.json": ok_scene, "m.obj": mesh_with_mtl("m.mtl")},
         setup=[("symlink", "m.mtl", "/dev/zero")])
    case("mtl-directory", files={"scene.json": ok_scene, "m.obj": mesh_with_mtl("m.mtl")},
         setup=[("dir", "m.mtl", None)])
    case("mtl-missing", files={"scene.json": ok_scene, "m.obj": mesh_with_mtl("m.mtl")})
    case("mtl-empty", files={"scene.json": ok_scene, "m.obj": mesh_with_mtl("m.mtl"),
                             "m.mtl": b""})
    case("mtl-name-newline", files={"scene.json": ok_scene,
                                    "m.obj": mesh_with_mtl("x\ny.mtl"), "m.mtl": mtl})
    # Command-line options that must be refused with one line naming the option.
    good = {"scene.json": dump(minimal_scene("m.obj")), "m.obj": mesh_with_mtl("m.mtl"),
            "m.mtl": mtl}
    for opt, val in [("--split-threshold", "nan"), ("--split-threshold", "inf"),
                     ("--split-threshold", "2"), ("--spp", "0"), ("--spp", "-1"),
                     ("--spp", "abc"), ("--spp", "99999999999"), ("--seed", "-1"),
                     ("--seed", "4294967296"), ("--light-sampler", "bogus"),
                     ("--light-sampler", "a\nb")]:
        case(f"cli {opt} {val!r}", files=good, args=[opt, val], names=opt)
    # Emission near the float maximum at 16 spp: the film's per-pixel sum must not overflow to Inf
    # (finding 4 of issue 9); exit 0 with a finite image or a one-line error.
    hot = parse((ROOT / "tests/fuzz/lights.json").read_text())
    set_member(hot, "film", Obj([["width", FILM], ["height", FILM]]))
    for p, i, _ in list(slots(hot)):
        if key_of(p, i) in EMISSION_KEYS:
            put(p, i, Raw("3e38"))
    cases.append(("emission 3e38 at 16 spp", "scene.json", {"scene.json": dump(hot)}, [],
                  ["--spp", "16"], None))
    return cases


# ------------------------------------------------------------------ pbrt-v4 scenes
# A pbrt mutant is a directory of files: scene.pbrt (the seed's top-level file, renamed), the
# files it includes and the PLY meshes it references, under their own names. Its film is 8 x 8.
PBRT_FILM = b'Film "rgb" "integer xresolution" [8] "integer yresolution" [8]\n' \
            b'Sampler "zsobol" "integer pixelsamples" [1]\n'
PBRT_MAX_PIXELS = 65536  # a larger legal film (1280 x 720 when Film is dropped) only costs time
PBRT_TOKEN = re.compile(rb'"[^"\n]*"?|\[|\]|#[^\n]*|[^\s\[\]"#]+')
PBRT_EXTREMES = [
    "0", "-0", "-1", "1e-45", "1e-40", "1e38", "-1e38", "3e38", "3.5e38", "1e39", "-1e39",
    "1e308", "1e999", "-1e999", "nan", "NaN", "inf", "-inf", "Infinity", "2147483647",
    "2147483648", "4294967295", "4294967296", "-2147483649", "18446744073709551616",
    "123456789012345678901234567890", "0x10", "1.5.5", "1e", "+", "-", ".", "--1", "1e18", "1e19",
    "16385", "100000", "0.5",
]
PBRT_TYPES = ["float", "integer", "string", "bool", "rgb", "blackbody", "spectrum", "point3",
              "point2", "point", "normal", "normal3", "vector3", "vector", "texture", "color",
              "bogus", "", "Float"]
PBRT_INSERTS = [
    "AttributeEnd", "TransformEnd", "ObjectEnd", "AttributeBegin", "TransformBegin",
    'ObjectBegin "o"', "WorldBegin", "WorldEnd", "ReverseOrientation", "Identity",
    'Include "scene.pbrt"', 'Include "scene-inc.pbrt"', 'Import "scene.pbrt"', 'Include "./scene.pbrt"',
    'Include "missing.pbrt"', 'Include "/dev/zero"', 'Include "/dev/null"', 'Include "."',
    'Include ""', 'Include "mesh_be.ply"', 'Include "nodir/x.pbrt"', "Include",
    'Frobnicate "x" 1 2 [3]', "frob", "ActiveTransform StartTime", "TransformTimes 0 1",
    'MakeNamedMedium "m" "string type" "homogeneous"', 'MediumInterface "m" ""',
    'Attribute "shape" "float radius" 2', 'Option "bool disablepixeljitter" true',
    'ColorSpace "aces2065-1"', 'PixelFilter "gaussian"', 'Accelerator "bvh"',
    'Camera "orthographic"', 'Camera "perspective" "float fov" [179.999]',
    'Camera "perspective" "float fov" [0]', 'Camera "perspective" "float fov" [180]',
    'Texture "t" "spectrum" "imagemap" "string filename" "missing.png"',
    'Material "diffuse" "texture reflectance" "t"', 'LightSource "goniometric"',
    'Texture "t" "spectrum" "imagemap" "string filename" "tex.png"',
    'Texture "r" "float" "imagemap" "string filename" "tex.png" "string wrap" "mirror"',
    'Texture "r" "float" "imagemap" "string filename" "tex.png" "string encoding" "gamma -1"',
    'Texture "t" "spectrum" "imagemap" "string filename" "scene.pbrt"',
    'Texture "t" "spectrum" "imagemap" "string filename" "mesh.ply"',
    'Texture "t" "spectrum" "imagemap" "string filename" "/dev/zero"',
    'Texture "t" "spectrum" "imagemap" "string filename" "."',
    'Texture "t" "float" "scale" "texture tex" "t" "texture scale" "t"',
    'Texture "t" "spectrum" "mix"', 'Texture "t" "color" "imagemap"',
    'Texture "t" "spectrum" "checkerboard" "float uscale" 1e30 "texture tex2" "t"',
    'Texture "t" "float" "mix" "texture amount" "r" "float tex2" -1',
    'Material "mix" "string materials" ["red" "red"] "texture amount" "r"',
    'Material "diffusetransmission" "texture transmittance" "t" "float scale" 1e30',
    'Material "conductor" "texture roughness" "r"', 'Material "conductor" "texture roughness" "t"',
    'Material "coateddiffuse" "texture uroughness" "r" "texture vroughness" "t"',
    'LightSource "infinite" "string filename" "missing.exr"',
    'LightSource "infinite" "string filename" "mesh.ply"',
    'LightSource "infinite" "rgb L" [1 1 1] "string filename" "x.exr"',
    'LightSource "distant" "rgb L" [1 1 1]', 'LightSource "point" "rgb I" [1 1 1] "float power" 10',
    'LightSource "spot" "float coneangle" [0] "float conedelta" [0]',
    'LightSource "spot" "float coneangle" [-1] "float conedelta" [90]',
    'AreaLightSource "diffuse" "rgb L" [3e38 3e38 3e38]', 'AreaLightSource "diffuse" "rgb L" [-1 0 0]',
    'Shape "curve"', 'Shape "plymesh"', 'Shape "plymesh" "string filename" "missing.ply"',
    'Shape "plymesh" "string filename" "/dev/zero"', 'Shape "plymesh" "string filename" "."',
    'Shape "plymesh" "string filename" "scene.pbrt"', 'Shape "plymesh" "string filename" "mesh.ply.gz"',
    'Shape "plymesh" "string filename" "/dev/null"', 'Shape "trianglemesh"',
    'Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 5]',
    'Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0]',
    'Shape "trianglemesh" "point3 P" [0 0 0 0 0 0 0 0 0]',
    'Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0]', 'Shape "sphere" "float radius" [-1]',
    'Shape "sphere" "float radius" [0]', 'Shape "sphere" "float radius" [1e30]',
    'Shape "sphere" "float zmin" [0.5] "float zmax" [-0.5]', 'Shape "disk" "float radius" [0]',
    'Shape "disk" "float innerradius" [2] "float radius" [1]', 'NamedMaterial "nosuch"',
    'ObjectInstance "nosuch"', 'ObjectInstance "pair"', 'CoordSysTransform "nosuch"',
    'CoordSysTransform "camera"', 'MakeNamedMaterial "red" "string type" "diffuse"',
    'MakeNamedMaterial "x" "string type" "nosuch"', 'MakeNamedMaterial "x"',
    'Material "conductor" "spectrum eta" "metal-Xx-eta" "float roughness" [-1]',
    'Material "conductor" "float reflectance" [1]', 'Material "coateddiffuse" "float eta" [0]',
    'Material "diffuse" "rgb reflectance" [1e39 0 0]', "Scale 0 0 0", "Scale 1e30 1e30 1e30",
    "Scale 1e-30 1e-30 1e-30", "Scale -1 1 1", "Translate 1e19 0 0", "Translate 1e17 0 0",
    "Rotate 90 0 0 0", "Rotate 1e30 0 1 0", "LookAt 0 0 0 0 0 0 0 1 0", "LookAt 0 0 0 0 0 1 0 0 1",
    "Transform [0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0]", "Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 0]",
    "ConcatTransform [1 0 0 1 0 1 0 0 0 0 1 0 0 0 0 1]", "Transform [1 2 3]",
    'Film "rgb" "integer xresolution" [0]', 'Film "rgb" "integer xresolution" [16385]',
    'Film "rgb" "integer xresolution" [2147483648] "integer yresolution" [8]',
    'Film "rgb" "float scale" [1e38] "float iso" [1e38]', 'Film "gbuffer" "string filename" "x.png"',
    'Sampler "halton" "integer pixelsamples" [0]', 'Integrator "path" "integer maxdepth" [-1]',
    'Integrator "path" "integer maxdepth" [100000]', 'Integrator "bdpt"',
]
LONG_STRINGS = [b"x" * 1000, b"x" * 100000, b"a\tb", b"a\x1bb", b"a\x00b", b"\x7f", b"\xff\xfe",
                b"\xc3", b"%s%n", b"../../../../etc/passwd", "ключ".encode(), b"a\\b", b"a\\"]
PLY_NAMES = ["mesh.ply", "mesh_be.ply", "mesh_le.ply.gz", "missing.ply", "/dev/zero", ".", "",
             "scene.pbrt", "plain.ply.gz", "/dev/null", "mesh.PLY", "x" * 5000 + ".ply"]


def pbrt_tokens(data):
    """The tokens of a pbrt file (bytes), comments left out."""
    return [t for t in PBRT_TOKEN.findall(data) if not t.startswith(b"#")]


def is_directive(t):
    return t[:1].isalpha() and t not in (b"true", b"false")


def is_pbrt_number(t):
    return bool(re.fullmatch(rb"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?", t))


def pbrt_join(tokens):
    out = bytearray()
    for t in tokens:
        if out:
            out += b"\n" if is_directive(t) else b" "
        out += t
    return bytes(out) + b"\n"


def pbrt_refs(data):
    """Relative files a pbrt file names: Include/Import targets and "string filename" values."""
    toks, refs = pbrt_tokens(data), []
    for k, t in enumerate(toks[:-1]):
        nxt = toks[k + 1]
        if t in (b"Include", b"Import") or re.fullmatch(rb'"string\s+filename"', t):
            if nxt.startswith(b'"') and nxt.endswith(b'"') and len(nxt) > 1:
                refs.append(nxt[1:-1].decode())
    return refs


def pbrt_normalize(data):
    """Drops Film and Sampler directives (an 8 x 8 film and 1 spp are put first instead)."""
    toks, out, skip = pbrt_tokens(data), [], False
    for t in toks:
        if is_directive(t):
            skip = t in (b"Film", b"Sampler")
        if not skip:
            out.append(t)
    return out


def load_pbrt_seeds():
    """[(path, {name: bytes})]: every top-level .pbrt file of scenes/pbrt/ and tests/fuzz/ with
    the files it references (Include, PLY, ...), normalised to an 8 x 8 film and 1 spp."""
    paths = sorted((ROOT / "scenes/pbrt").glob("*.pbrt")) + sorted(
        (ROOT / "tests/fuzz").glob("*.pbrt"))
    included = set()
    for p in paths:
        for r in pbrt_refs(p.read_bytes()):
            included.add((p.parent / r).resolve())
    seeds = []
    for p in paths:
        if p.resolve() in included:
            continue
        files, todo = {}, [(p, "scene.pbrt")]
        while todo:
            src, name = todo.pop()
            if name in files or not src.is_file():
                continue
            data = src.read_bytes()
            if name.endswith(".pbrt"):
                toks = pbrt_normalize(data)
                if name == "scene.pbrt":
                    toks = pbrt_tokens(PBRT_FILM) + toks
                data = pbrt_join(toks)
                for r in pbrt_refs(data):
                    if not os.path.isabs(r) and "/" not in r:
                        todo.append((src.parent / r, r))
            files[name] = data
        if "mesh.ply" in files:
            files["plain.ply.gz"] = files["mesh.ply"]  # not gzip data despite the name
        seeds.append((p, files))
    return seeds


def directive_spans(toks):
    """[(start, end)] of each directive with its arguments."""
    starts = [k for k, t in enumerate(toks) if is_directive(t)]
    return [(s, e) for s, e in zip(starts, starts[1:] + [len(toks)])]


def bracket_lists(toks):
    """[(open, close)] index pairs of every [ ... ] without nested brackets."""
    out, open_at = [], None
    for k, t in enumerate(toks):
        if t == b"[":
            open_at = k
        elif t == b"]" and open_at is not None:
            out.append((open_at, k))
            open_at = None
    return out


def param_values(toks, decl_re):
    """Token indices of the values of every parameter whose declaration matches decl_re."""
    out = []
    for k, t in enumerate(toks):
        if t.startswith(b'"') and re.fullmatch(decl_re, t.strip(b'"')):
            if k + 1 < len(toks) and toks[k + 1] == b"[":
                j = k + 2
                idx = []
                while j < len(toks) and toks[j] != b"]":
                    idx.append(j)
                    j += 1
                out.append(idx)
            elif k + 1 < len(toks):
                out.append([k + 1])
    return [o for o in out if o]


def pbrt_mutation(rng, toks, m, name):
    """One token-level mutation of the pbrt file `name` (its token list, changed in place)."""
    if not toks:
        toks.append(b"WorldBegin")
    c = weighted(rng, [("drop", 6), ("dup", 4), ("swap", 4), ("number", 12), ("numbers", 4),
                       ("bracket", 5), ("insert", 14), ("string", 5), ("ptype", 6), ("pname", 3),
                       ("array", 8), ("indices", 5), ("directive", 7), ("plyname", 3)])
    spans = directive_spans(toks)
    world = [s for s, _ in spans if toks[s] not in (b"Film", b"Sampler", b"Camera", b"LookAt")]
    if c == "drop":
        k = rng.randrange(len(toks))
        m.ops.append(f"{name}: drop token {k} {toks[k][:40]!r}")
        del toks[k]
    elif c == "dup":
        k = rng.randrange(len(toks))
        toks.insert(k, toks[k])
        m.ops.append(f"{name}: duplicate token {k} {toks[k][:40]!r}")
    elif c == "swap":
        if len(toks) < 2:
            return False
        k = rng.randrange(len(toks) - 1)
        toks[k], toks[k + 1] = toks[k + 1], toks[k]
        m.ops.append(f"{name}: swap tokens {k} {toks[k + 1][:30]!r} and {toks[k][:30]!r}")
    elif c in ("number", "numbers"):
        nums = [k for k, t in enumerate(toks) if is_pbrt_number(t)]
        if not nums:
            return False
        v = rng.choice(PBRT_EXTREMES).encode()
        if c == "number":
            k = rng.choice(nums)
            m.ops.append(f"{name}: number {k} {toks[k]!r} -> {v!r}")
            toks[k] = v
        else:
            with_numbers = [(a, b) for a, b in spans if any(a <= k < b for k in nums)]
            s, e = rng.choice(with_numbers or spans)
            for k in range(s, e):
                if is_pbrt_number(toks[k]):
                    toks[k] = v
            m.ops.append(f"{name}: every number of {toks[s][:30]!r} (token {s}) -> {v!r}")
    elif c == "bracket":
        k = rng.randrange(len(toks) + 1)
        what = rng.choice([b"[", b"]", b'"', b'"x', b"[[", b"]]"])
        if what == b'"' and rng.random() < 0.5:
            strs = [j for j, t in enumerate(toks) if t.startswith(b'"') and len(t) > 1]
            if strs:
                j = rng.choice(strs)
                toks[j] = toks[j][:-1]
                m.ops.append(f"{name}: unterminated string at token {j}")
                return True
        toks.insert(k, what)
        m.ops.append(f"{name}: insert {what!r} at token {k}")
    elif c == "insert":
        ins = rng.choice(PBRT_INSERTS)
        s = rng.choice(world) if world and rng.random() < 0.8 else rng.randrange(len(toks) + 1)
        toks[s:s] = pbrt_tokens(ins.encode("latin-1"))
        m.ops.append(f"{name}: insert {ins[:60]!r} at token {s}")
    elif c == "string":
        strs = [j for j, t in enumerate(toks) if t.startswith(b'"')]
        if not strs:
            return False
        j = rng.choice(strs)
        v = rng.choice(LONG_STRINGS)
        toks[j] = b'"' + v + b'"'
        m.ops.append(f"{name}: string {j} -> {v[:30]!r} ({len(v)} chars)")
    elif c in ("ptype", "pname"):
        decls = [j for j, t in enumerate(toks) if re.fullmatch(rb'"\w+ +\w+"', t)]
        if not decls:
            return False
        j = rng.choice(decls)
        ty, nm = toks[j].strip(b'"').split()
        if c == "ptype":
            new = rng.choice(PBRT_TYPES).encode() + b" " + nm
        else:
            new = rng.choice([ty + b" " + nm + b"x", ty, ty + b" " + nm + b" extra", b"",
                              b" " + ty + b"  " + nm + b" ", ty + b" " + nm.upper(),
                              ty + b" " + rng.choice([b"L", b"I", b"P", b"indices", b"radius",
                                                      b"filename", b"scale", b"from", b"to"])])
        m.ops.append(f"{name}: parameter {toks[j]!r} -> {new!r}")
        toks[j] = b'"' + new + b'"'
    elif c == "array":
        lists = bracket_lists(toks)
        if not lists:
            return False
        o, cl = rng.choice(lists)
        what = rng.randrange(6)
        if what == 0:
            del toks[o + 1:cl]
            m.ops.append(f"{name}: empty the list at token {o}")
        elif what == 1 and cl > o + 1:
            k = rng.randrange(o + 1, cl)
            del toks[k]
            m.ops.append(f"{name}: drop element {k - o - 1} of the list at token {o}")
        elif what == 2:
            toks.insert(cl, rng.choice([b"1", b"0", b"-1", b'"a"', b"true"]))
            m.ops.append(f"{name}: add an element to the list at token {o}")
        elif what == 3:
            body = toks[o + 1:cl]
            toks[o + 1:cl] = body * rng.choice([2, 3, 100])
            m.ops.append(f"{name}: repeat the list at token {o}")
        elif what == 4:
            toks[o:cl + 1] = [rng.choice([b"1", b'"x"', b"true", b"[", b"]"])]
            m.ops.append(f"{name}: replace the list at token {o} by one token")
        else:
            toks[o:cl + 1] = [t for t in toks[o + 1:cl]]
            m.ops.append(f"{name}: drop the brackets of the list at token {o}")
    elif c == "indices":
        vals = param_values(toks, rb"integer +indices")
        if not vals:
            return False
        idx = rng.choice(vals)
        k = rng.choice(idx)
        v = rng.choice([b"-1", b"999999", b"2147483647", b"2147483648", b"4294967296", b"1.5",
                        b"1e3", str(len(idx)).encode(), b"nan"])
        m.ops.append(f"{name}: index token {k} {toks[k]!r} -> {v!r}")
        toks[k] = v
    elif c == "directive":
        if not spans:
            return False
        s, e = rng.choice(spans)
        what = rng.randrange(4)
        block = toks[s:e]
        if what == 0:
            del toks[s:e]
            m.ops.append(f"{name}: delete directive {block[0][:30]!r} at token {s}")
        elif what == 1:
            n = rng.choice([2, 2, 10, 50])
            toks[s:e] = block * n
            m.ops.append(f"{name}: directive {block[0][:30]!r} at token {s} x {n}")
        elif what == 2:
            del toks[s:e]
            k = rng.choice([sp[0] for sp in directive_spans(toks)] + [len(toks)])
            toks[k:k] = block
            m.ops.append(f"{name}: move directive {block[0][:30]!r} from token {s} to {k}")
        else:
            toks[s:e] = [toks[s]] + block[1:][:rng.randrange(max(1, e - s - 1))]
            m.ops.append(f"{name}: cut the arguments of {block[0][:30]!r} at token {s}")
    else:
        fns = [v[0] for v in param_values(toks, rb"string +filename")]
        if not fns:
            return False
        k = rng.choice(fns)
        v = rng.choice(PLY_NAMES)
        m.ops.append(f"{name}: filename {toks[k][:40]!r} -> {v[:40]!r}")
        toks[k] = b'"' + v.encode() + b'"'
    return True


def pbrt_too_heavy(data):
    """A legal film of more than PBRT_MAX_PIXELS (the last Film directive of scene.pbrt)."""
    toks = pbrt_tokens(data)
    films = [(s, e) for s, e in directive_spans(toks) if toks[s] == b"Film"]
    size = {b"xresolution": 1280.0, b"yresolution": 720.0}
    if films:
        s, e = films[-1]
        for k in range(s, e):
            m = re.fullmatch(rb'"integer +(xresolution|yresolution)"', toks[k])
            if m:
                vals = [t for t in toks[k + 1:e] if t not in (b"[",)][:1]
                try:
                    size[m.group(1)] = float(vals[0])
                except (IndexError, ValueError):
                    return False
    w, h = size[b"xresolution"], size[b"yresolution"]
    if not (0 < w <= FILM_CAP and 0 < h <= FILM_CAP):
        return False
    return w * h > PBRT_MAX_PIXELS


# ------------------------------------------------------------------ PLY files
PLY_SCALARS = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
               "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
               "float": "f", "float32": "f", "double": "d", "float64": "d"}
PLY_FORMATS = ["ascii", "binary_little_endian", "binary_big_endian"]
PLY_BAD_TYPES = ["float16", "int64", "uint64", "string", "", "list", "FLOAT", "float float"]
PLY_BAD_VALUES = ["nan", "-nan", "inf", "-inf", "1e39", "-1e39", "3e38", "1e999", "-1", "999999",
                  "255", "256", "2147483648", "4294967296", "-2147483649", "abc", "", "1.5",
                  "0x10", "1e", "+", "1,5"]


def ply_split(data):
    """(header lines, body bytes); header None when there is no end_header line."""
    k = data.find(b"end_header")
    if k < 0:
        return None, data
    nl = data.find(b"\n", k)
    end = len(data) if nl < 0 else nl + 1
    return data[:end].decode("latin-1").split("\n")[:-1] if nl >= 0 else \
        data[:end].decode("latin-1").split("\n"), data[end:]


def ply_parse(data):
    """(format, [(element, count, [(name, list count type or None, type)])], rows per element)
    of a well-formed PLY file (the seeds); rows are lists of values (lists for list properties)."""
    lines, body = ply_split(data)
    fmt, elems = None, []
    for l in lines:
        p = l.split()
        if p[:1] == ["format"]:
            fmt = p[1]
        elif p[:1] == ["element"]:
            elems.append((p[1], int(p[2]), []))
        elif p[:1] == ["property"]:
            elems[-1][2].append((p[-1], p[2], p[3]) if p[1] == "list" else (p[-1], None, p[1]))
    rows = []
    if fmt == "ascii":
        vals, pos = body.split(), 0
        for _, n, props in elems:
            er = []
            for _ in range(n):
                row = []
                for _, lt, ty in props:
                    if lt:
                        c = int(vals[pos])
                        row.append([float(x) for x in vals[pos + 1:pos + 1 + c]])
                        pos += 1 + c
                    else:
                        row.append(float(vals[pos]))
                        pos += 1
                er.append(row)
            rows.append(er)
    else:
        end, pos = "<" if fmt == "binary_little_endian" else ">", 0

        def rd(ty):
            nonlocal pos
            f = end + PLY_SCALARS[ty]
            v = struct.unpack_from(f, body, pos)[0]
            pos += struct.calcsize(f)
            return v
        for _, n, props in elems:
            er = []
            for _ in range(n):
                row = []
                for _, lt, ty in props:
                    row.append([rd(ty) for _ in range(rd(lt))] if lt else rd(ty))
                er.append(row)
            rows.append(er)
    return fmt, elems, rows


def ply_pack(end, code, x):
    """x as the binary PLY scalar `code`; an integer out of range wraps like a C cast."""
    if code in "fd":
        return struct.pack(end + code, float(x))
    bits = struct.calcsize(code) * 8
    x = int(x) if not (isinstance(x, float) and (math.isnan(x) or math.isinf(x))) else 0
    lo = -(1 << (bits - 1)) if code.islower() else 0
    return struct.pack(end + code, (x - lo) % (1 << bits) + lo)


def ply_write(fmt, elems, rows):
    h = [f"ply", f"format {fmt} 1.0"]
    for (name, n, props), er in zip(elems, rows):
        h.append(f"element {name} {len(er)}")
        for pn, lt, ty in props:
            h.append(f"property list {lt} {ty} {pn}" if lt else f"property {ty} {pn}")
    h.append("end_header")
    out = bytearray(("\n".join(h) + "\n").encode())
    for (_, _, props), er in zip(elems, rows):
        for row in er:
            if fmt == "ascii":
                parts = []
                for (_, lt, ty), v in zip(props, row):
                    vs = v if lt else [v]
                    if lt:
                        parts.append(str(len(vs)))
                    parts += [repr(x) if isinstance(x, float) and not x.is_integer() else
                              str(int(x)) if not (isinstance(x, float) and (math.isnan(x) or math.isinf(x)))
                              else str(x) for x in vs]
                out += (" ".join(parts) + "\n").encode()
            else:
                end = "<" if fmt == "binary_little_endian" else ">"
                for (_, lt, ty), v in zip(props, row):
                    vs = v if lt else [v]
                    if lt:
                        out += ply_pack(end, PLY_SCALARS[lt], len(vs))
                    for x in vs:
                        out += ply_pack(end, PLY_SCALARS[ty], x)
    return bytes(out)


def ply_model_mutation(rng, data, m, name):
    """Re-encodes a (seed) PLY file, consistently, in another format and/or with bad values."""
    try:
        fmt, elems, rows = ply_parse(data)
    except Exception:
        return None
    fmt2 = rng.choice(PLY_FORMATS)
    what = []
    if fmt2 != fmt:
        what.append(f"as {fmt2}")
    elems = [(n, c, list(props)) for n, c, props in elems]
    for _ in range(rng.choice([0, 1, 1, 2])):
        ei = rng.randrange(len(elems))
        en, _, props = elems[ei]
        er = rows[ei]
        if not er or not props:
            continue
        r, pi = rng.randrange(len(er)), rng.randrange(len(props))
        pn, lt, ty = props[pi]
        if lt:
            c = rng.randrange(5)
            if c == 0:
                er[r][pi] = []
            elif c == 1:
                er[r][pi] = er[r][pi][:rng.choice([1, 2])]
            elif c == 2:
                er[r][pi] = er[r][pi] * rng.choice([2, 64, 300])
            elif c == 3 and er[r][pi]:
                er[r][pi][rng.randrange(len(er[r][pi]))] = rng.choice(
                    [-1, len(rows[0]), 999999, 2 ** 31 - 1, 2 ** 31, 2 ** 32 - 1])
            else:
                props[pi] = (pn, rng.choice(["uchar", "char", "ushort", "int", "uint", "float"]),
                             rng.choice(["int", "uint", "uchar", "short", "float", "double"]))
                what.append(f"{en}.{pn} as list {props[pi][1]} {props[pi][2]}")
            what.append(f"{en} {r}.{pn} = {er[r][pi][:8]}")
        else:
            v = rng.choice([math.nan, math.inf, -math.inf, 3e38, 1e38, -1e30, 1e-45, 0.0, 1e19])
            er[r][pi] = v
            if PLY_SCALARS.get(ty, "f") not in "fd" and not rng.random() < 0.5:
                props[pi] = (pn, None, "double")
            what.append(f"{en} {r}.{pn} = {v}")
    if rng.random() < 0.2:
        ei = rng.randrange(len(elems))
        rows[ei] = rows[ei] * rng.choice([0, 2])
        what.append(f"{elems[ei][0]}: {len(rows[ei])} rows")
    out = ply_write(fmt2, elems, rows)
    m.ops.append(f"{name}: re-encoded {', '.join(what) or 'unchanged'}")
    return out


def ply_header_mutation(rng, data, m, name):
    lines, body = ply_split(data)
    if lines is None:
        return None
    els = [i for i, l in enumerate(lines) if l.startswith("element ")]
    props = [i for i, l in enumerate(lines) if l.startswith("property ")]
    lists = [i for i in props if lines[i].split()[1:2] == ["list"]]
    c = rng.randrange(10)
    if c == 0 and els:
        i = rng.choice(els)
        p = lines[i].split()
        n = int(p[2]) if p[2].isdigit() else 1
        p[2] = str(rng.choice([0, n - 1, n + 1, 2 * n, 2 ** 31, 2 ** 32 + n, 2 ** 64, -1, -n,
                               "abc", "1e3", 10 ** 9, 1, ""]))
        lines[i] = " ".join(p)
    elif c == 1 and props:
        i = rng.choice(props)
        p = lines[i].split()
        k = rng.randrange(1, len(p) - 1) if len(p) > 2 else 1
        if p[k] != "list":
            p[k] = rng.choice(list(PLY_SCALARS) + PLY_BAD_TYPES)
        lines[i] = " ".join(p)
    elif c == 2 and lists:
        i = rng.choice(lists)
        p = lines[i].split()
        p[2], p[3] = rng.choice([("int", "int"), ("float", "int"), ("uchar", "float"),
                                 ("char", "int"), ("ushort", "uint"), ("uchar", "double"),
                                 ("uint", "uchar"), ("double", "double"), ("uchar", "list")])
        lines[i] = " ".join(p)
    elif c == 3:
        fi = [i for i, l in enumerate(lines) if l.startswith("format")]
        new = rng.choice(["format " + f + " 1.0" for f in PLY_FORMATS] + [
            "format ascii 2.0", "format binary_little_endian", "format", "format binary_middle_endian 1.0",
            "format ascii 1.0 extra", "FORMAT ascii 1.0"])
        if fi:
            lines[fi[0]] = new
        else:
            lines.insert(1, new)
        if rng.random() < 0.2 and fi:
            del lines[fi[0]]
            new = "(deleted)"
        m.ops.append(f"{name}: format line -> {new!r}")
        return ("\n".join(lines) + "\n").encode("latin-1") + body
    elif c == 4:
        ei = [i for i, l in enumerate(lines) if l.strip() == "end_header"]
        what = rng.randrange(3)
        if what == 0:
            del lines[ei[0]]
        elif what == 1:
            lines[ei[0]] = rng.choice(["end_heade", "end_header x", "END_HEADER", "endheader"])
        else:
            lines.insert(ei[0], "end_header")
    elif c == 5 and props:
        i = rng.choice(props)
        lines.insert(i, lines[i]) if rng.random() < 0.6 else lines.pop(i)
    elif c == 6 and len(els) > 1:
        # the face element (with its properties) before the vertex element
        blocks, cur = [], None
        head = [l for l in lines[:els[0]]]
        for l in lines[els[0]:-1]:
            if l.startswith("element "):
                cur = [l]
                blocks.append(cur)
            else:
                cur.append(l)
        rng.shuffle(blocks)
        lines = head + [l for b in blocks for l in b] + ["end_header"]
    elif c == 7:
        at = rng.randrange(2, len(lines))
        lines[at:at] = rng.choice([["element extra 3", "property float a"], ["element extra 0"],
                                   ["element vertex 1", "property float x"],
                                   ["property float w"], ["element face 1"],
                                   ["comment " + "c" * 10000], ["comment a\x00b\xff"],
                                   ["obj_info x"], [""], ["   "], ["bogus line"]])
    elif c == 8:
        first = rng.choice(["PLY", "ply ", "", "plyx", "\xef\xbb\xbfply"])
        lines[0] = first
    elif c == 9:
        m.ops.append(f"{name}: CRLF header")
        return ("\r\n".join(lines) + "\r\n").encode("latin-1") + body
    else:
        return None
    m.ops.append(f"{name}: header -> {' | '.join(lines)[:150]!r}")
    return ("\n".join(lines) + "\n").encode("latin-1") + body


def ply_body_mutation(rng, data, m, name):
    lines, body = ply_split(data)
    hlen = len(data) - len(body)
    c = rng.randrange(5)
    if c == 0:
        cut = rng.randrange(len(data) + 1) if rng.random() < 0.2 else hlen + rng.randrange(len(body) + 1)
        m.ops.append(f"{name}: truncate at byte {cut} of {len(data)} (body at {hlen})")
        return data[:cut]
    data = bytearray(data)
    if c == 1 and body:
        n = rng.randint(1, 8)
        for _ in range(n):
            data[hlen + rng.randrange(len(body))] = rng.randrange(256)
        m.ops.append(f"{name}: flip {n} body bytes")
    elif c == 2:
        extra = rng.choice([b"\n", b"\x00" * 7, b"1 2 3\n", bytes(range(256))])
        data += extra
        m.ops.append(f"{name}: append {len(extra)} bytes")
    elif c == 3 and b"ascii" in data[:hlen]:
        toks = [mt.span() for mt in re.finditer(rb"\S+", bytes(data[hlen:]))]
        if not toks:
            return None
        a, b = rng.choice(toks)
        v = rng.choice(PLY_BAD_VALUES).encode()
        data[hlen + a:hlen + b] = v
        m.ops.append(f"{name}: ascii value at byte {hlen + a} -> {v!r}")
    elif body:
        a = rng.randrange(len(body))
        b = min(len(body), a + rng.randint(1, 16))
        del data[hlen + a:hlen + b]
        m.ops.append(f"{name}: delete body bytes {a}..{b}")
    else:
        return None
    return bytes(data)


def gzip_bytes(data):
    buf = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buf, mtime=0) as g:
        g.write(data)
    return buf.getvalue()


def gzip_mutation(rng, gz, m, name):
    c = rng.randrange(7)
    d = bytearray(gz)
    if c == 0:
        cut = rng.randrange(len(gz))
        m.ops.append(f"{name}: gzip truncated at byte {cut} of {len(gz)}")
        return gz[:cut]
    if c == 1:
        n = rng.randint(1, 4)
        for _ in range(n):
            d[rng.randrange(10, len(d) - 8)] = rng.randrange(256)
        m.ops.append(f"{name}: gzip: {n} deflate bytes flipped")
    elif c == 2:
        k = len(d) - rng.randint(1, 8)
        d[k] ^= 0xFF
        m.ops.append(f"{name}: gzip trailer (CRC / size) byte {k} changed")
    elif c == 3:
        extra = rng.choice([gz, b"\x1f\x8b", b"garbage", b"\x00" * 8, gzip_bytes(b"")])
        d += extra
        m.ops.append(f"{name}: gzip: {len(extra)} bytes after the member")
    elif c == 4:
        d = bytearray(rng.choice([b"", b"\x1f\x8b", gz[:10], gzip_bytes(b""),
                                  gzip_bytes(b"ply\nformat ascii 1.0\nend_header\n")]))
        m.ops.append(f"{name}: gzip: replaced by {bytes(d)[:12]!r} ({len(d)} bytes)")
    elif c == 5:
        d[3] |= rng.choice([0x04, 0x08, 0x10, 0x02, 0xE0])  # FEXTRA/FNAME/FCOMMENT/FHCRC/reserved
        m.ops.append(f"{name}: gzip flags {d[3]:#x}")
    else:
        d[2] = rng.choice([0, 7, 9, 255])
        m.ops.append(f"{name}: gzip method {d[2]}")
    return bytes(d)


def ply_mutation(rng, files, m):
    """Mutates one PLY file of the mutant (plain or gzip)."""
    plys = sorted(n for n in files if n.endswith((".ply", ".ply.gz")) and n != "plain.ply.gz")
    if not plys:
        return False
    name = rng.choice(plys)
    data = files[name]
    gz = name.endswith(".gz")
    if gz and rng.random() < 0.4:
        files[name] = gzip_mutation(rng, data, m, name)
        return True
    if gz:
        data = gzip.decompress(data)
    out = None
    for _ in range(rng.choice([1, 1, 2])):
        c = rng.randrange(10)
        fn = ply_header_mutation if c < 4 else ply_body_mutation if c < 7 else \
            ply_model_mutation if c < 9 else None
        if fn:
            # The second mutation may meet a header the first broke: then it does nothing.
            try:
                new = fn(rng, data, m, name)
            except (ValueError, IndexError, KeyError, struct.error):
                new = None
        else:
            new = b_mutate(rng, data, m)
            m.ops[-1] = f"{name}: bytes: {m.ops[-1]}"
        if new is not None:
            data = out = new
    if out is None:
        return False
    files[name] = gzip_bytes(out) if gz else out
    return True


def make_pbrt_mutant(rng, ident, pbrt_seeds, cat):
    for _attempt in range(50):
        if cat == "ply":
            cands = [s for s in pbrt_seeds if any(n.endswith((".ply", ".gz")) for n in s[1])]
        else:
            cands = pbrt_seeds
        seed_path, seed_files = rng.choice(cands)
        m = Mutant(ident, seed_path)
        m.kind = cat
        m.scene_arg = "scene.pbrt"
        m.pbrt = True
        files = dict(seed_files)
        ok = False
        if cat == "ply":
            ok = ply_mutation(rng, files, m)
            if ok and rng.random() < 0.1:
                cat = "pbrt"  # and a pbrt mutation too
        if cat == "pbrt":
            names = sorted(n for n in files if n.endswith(".pbrt"))
            for _ in range(rng.choice([1, 1, 1, 2, 3])):
                name = "scene.pbrt" if rng.random() < 0.6 else rng.choice(names)
                if rng.random() < 0.12:
                    files[name] = b_mutate(rng, files[name], m)
                    m.ops[-1] = f"{name}: bytes: {m.ops[-1]}"
                    ok = True
                    continue
                toks = pbrt_tokens(files[name])
                if pbrt_mutation(rng, toks, m, name):
                    files[name] = pbrt_join(toks)
                    ok = True
        if not ok or pbrt_too_heavy(files["scene.pbrt"]):
            continue
        m.files = files
        return m
    raise RuntimeError(f"mutant {ident}: no applicable pbrt mutation in 50 attempts")


def pbrt_special_cases():
    """Special files of a pbrt scene: the scene, an Include and a PLY file that are not regular
    files, missing, empty or loops; each must give exit 2 and one line."""
    seed = dict(load_pbrt_seeds()[-1][1])  # tests/fuzz/scene.pbrt (sorted last)
    cases = []

    def case(kind, files=None, setup=(), drop=(), arg="scene.pbrt", expect=True):
        f = dict(seed)
        f.update(files or {})
        for d in drop:
            f.pop(d, None)
        cases.append((kind, arg, f, list(setup), [], None, expect))

    case("pbrt scene-fifo", drop=["scene.pbrt"], setup=[("fifo", "scene.pbrt", None)])
    case("pbrt scene-directory", drop=["scene.pbrt"], setup=[("dir", "scene.pbrt", None)])
    case("pbrt scene-missing", arg="missing.pbrt")
    case("pbrt scene-symlink-dev-zero", drop=["scene.pbrt"],
         setup=[("symlink", "scene.pbrt", "/dev/zero")])
    case("pbrt scene-empty", files={"scene.pbrt": b""}, expect=False)
    for inc, kinds in [("scene-inc.pbrt", "fifo dev-zero directory missing loop empty"),
                       ("mesh.ply", "fifo dev-zero directory missing empty"),
                       ("mesh_be.ply", "missing empty"), ("mesh_le.ply.gz", "fifo dev-zero empty")]:
        kinds = kinds.split()
        if "fifo" in kinds:
            case(f"pbrt {inc}-fifo", drop=[inc], setup=[("fifo", inc, None)])
        if "dev-zero" in kinds:
            case(f"pbrt {inc}-dev-zero", drop=[inc], setup=[("symlink", inc, "/dev/zero")])
        if "directory" in kinds:
            case(f"pbrt {inc}-directory", drop=[inc], setup=[("dir", inc, None)])
        if "missing" in kinds:
            case(f"pbrt {inc}-missing", drop=[inc])
        if "loop" in kinds:
            case(f"pbrt {inc}-symlink-loop", drop=[inc],
                 setup=[("symlink", inc, "loop"), ("symlink", "loop", inc)])
        if "empty" in kinds:  # an empty included file is an empty scene part, not an error
            case(f"pbrt {inc}-empty", files={inc: b""}, expect=not inc.endswith(".pbrt"))
    return cases


# ------------------------------------------------------------------ mutant generation
CATEGORIES = [("json", 55), ("bytes", 15), ("obj", 30)]
# The share of pbrt-v4 mutants (a pbrt file mutated, or a PLY file it references) among the
# random ones; --formats json / pbrt leaves the other out (mutant i of a --formats pbrt run is
# mutant i of a full run whenever that one is a pbrt mutant).
FORMATS = [("json", 70), ("pbrt", 30)]
PBRT_CATEGORIES = [("pbrt", 65), ("ply", 35)]


def weighted(rng, items):
    total = sum(w for _, w in items)
    r = rng.uniform(0, total)
    for item, w in items:
        r -= w
        if r <= 0:
            return item
    return items[-1][0]


def make_mutant(ident, base_seed, seeds, specials, pbrt_seeds, formats):
    if ident < len(specials):
        kind, arg, files, setup, args, names, *expect = specials[ident]
        m = Mutant(ident, None)
        m.kind = "cli" if kind.startswith("cli ") else "special"
        m.ops.append(kind)
        m.scene_arg = arg
        m.files = dict(files)
        m.setup = setup
        m.args = args
        m.names = names
        m.pbrt = kind.startswith("pbrt ")
        m.expect_error = expect[0] if expect else kind.startswith(("scene-", "obj-", "mtl-", "cli "))
        return m
    rng = random.Random(f"{base_seed}/{ident}")
    # The format from a stream of its own: a JSON mutant i is the one it was before pbrt mutants
    # existed, a pbrt mutant i the same in a --formats pbrt run.
    fmt_rng = random.Random(f"{base_seed}/{ident}/format")
    if weighted(fmt_rng, [f for f in FORMATS if f[0] in formats]) == "pbrt":
        return make_pbrt_mutant(rng, ident, pbrt_seeds, weighted(rng, PBRT_CATEGORIES))
    for _attempt in range(50):
        seed_path, seed_tree = rng.choice(seeds)
        m = Mutant(ident, seed_path)
        tree = copy.deepcopy(seed_tree)
        cat = weighted(rng, CATEGORIES)
        m.kind = cat
        ok = False
        if cat == "json":
            for _ in range(rng.choice([1, 1, 1, 2, 3])):
                op = weighted(rng, [(k, w) for k, (_, w) in TREE_OPS.items()])
                ok |= TREE_OPS[op][0](rng, tree, m)
        elif cat == "obj":
            ok = mutate_obj(rng, tree, m)
        if cat != "bytes" and not ok:
            continue
        if too_heavy(tree):
            continue
        data = dump(tree) + b"\n"
        if cat == "bytes":
            data = b_mutate(rng, data, m)
        m.files["scene.json"] = data
        return m
    raise RuntimeError(f"mutant {ident}: no applicable mutation in 50 attempts")


# ------------------------------------------------------------------ running and classifying
def printable(s):
    return all(0x20 <= ord(c) < 0x7F for c in s)


def has_control(b):
    return any(c < 0x20 or c == 0x7F for c in b)


def image_finite(iinfo, exr):
    r = subprocess.run([iinfo, "--stats", str(exr)], capture_output=True, timeout=120)
    text = r.stdout.decode("utf-8", "replace")
    nan = re.search(r"NanCount:\s*([\d ]+)", text)
    inf = re.search(r"InfCount:\s*([\d ]+)", text)
    if r.returncode != 0 or not nan or not inf:
        return None, text + r.stderr.decode("utf-8", "replace")
    counts = [int(x) for x in (nan.group(1) + " " + inf.group(1)).split()]
    return all(c == 0 for c in counts), text


def classify(m, rc, timed_out, out, err, wdir, iinfo):
    """(passed, outcome class, detail)."""
    if timed_out:
        return False, "timeout", ""
    if rc < 0:
        try:
            name = signal.Signals(-rc).name
        except ValueError:
            name = str(-rc)
        return False, f"signal {name}", ""
    if rc == 0:
        if m.expect_error:
            return False, "exit 0 where an error was due", ""
        exr = wdir / "out.exr"
        if not exr.is_file():
            return False, "exit 0, no image", ""
        finite, text = image_finite(iinfo, exr)
        if finite is None:
            return False, "exit 0, unreadable image", text
        if not finite:
            return False, "exit 0, non-finite image", text
        return True, "ok: image", ""
    if rc == 2:
        lines = err.split(b"\n")
        if lines[-1] == b"":
            lines.pop()
        if len(lines) != 1:
            return False, f"exit 2, {len(lines)} stderr lines", ""
        if not err.endswith(b"\n"):
            return False, "exit 2, unterminated stderr line", ""
        line = err[:-1]
        if has_control(line):
            return False, "exit 2, control bytes in message", ""
        try:
            text = line.decode("utf-8")
        except UnicodeDecodeError:
            return False, "exit 2, invalid UTF-8 in message", ""
        if m.names is not None:
            if m.names not in text:
                return False, f"exit 2, message does not name {m.names}", ""
        elif m.pbrt:
            # pbrt: "<file>: ..." or "<file>:<line>: ..." where <file> is the scene path as given
            # or a file of the mutant (an included pbrt file, a PLY file).
            names = {m.scene_arg} | set(m.files) | {name for _, name, _ in m.setup}
            hit = re.match(r"(.*?)(:\d+)?: ", text)
            if not hit or not any(text.startswith(n + ":") and hit.group(1) == n for n in names
                                  if printable(n)):
                return False, "exit 2, message does not begin with a file of the scene", ""
        elif printable(m.scene_arg) and not text.startswith(m.scene_arg + ": "):
            return False, "exit 2, message does not name the file", ""
        return True, "ok: one-line error", ""
    return False, f"exit {rc}", ""


def signature(cls, err):
    """A short description of a failure for grouping: the class and its telling stderr line."""
    lines = [l for l in err.decode("utf-8", "replace").splitlines() if l.strip()]
    tell = ""
    for pat in ("Assertion", "AddressSanitizer", "runtime error", "terminate called", "canopy:",
                "what()"):
        hit = [l for l in lines if pat in l]
        if hit:
            tell = hit[0]
            break
    if not tell and lines:
        tell = lines[-1] if cls.startswith("signal") else lines[0]
    tell = re.sub(r"^[^:]*\.json: ", "", tell)  # the scene file name
    tell = re.sub(r"/\S+/", "", tell)  # directories
    tell = re.sub(r"\d+(\.\d+)?(e[+-]?\d+)?", "N", tell)
    tell = re.sub(r"'[^']*'", "'…'", tell)
    return f"{cls}: {tell[:110]}" if tell else cls


def write_files(m, wdir):
    wdir.mkdir(parents=True)
    for name, data in m.files.items():
        (wdir / name).write_bytes(data)
    for kind, name, target in m.setup:
        p = wdir / name
        if kind == "fifo":
            os.mkfifo(p)
        elif kind == "dir":
            p.mkdir()
        elif kind == "symlink":
            os.symlink(target, p)


def shell_quote(s):
    if re.fullmatch(r"[A-Za-z0-9_./=+-]+", s):
        return s
    return "$'" + "".join(c if 0x20 <= ord(c) < 0x7F and c not in "'\\" else f"\\x{ord(c):02x}"
                          for c in s) + "'"


def run_one(m, args, work, failures):
    wdir = work / f"{m.ident:05d}"
    if wdir.exists():
        shutil.rmtree(wdir)
    cmd = [str(args.canopy), "render", m.scene_arg, "--spp", "1", "--out", "out.exr"] + m.args
    if "--spp" in m.args:
        cmd[3:5] = []
    t0 = time.monotonic()
    rc, timed_out, out, err, detail = None, False, b"", b"", ""
    try:
        write_files(m, wdir)
        run = cmd
        if args.mem_limit_mb > 0:
            # The kernel enforces the limit on the process itself: /dev/zero read without bound
            # ends in bad_alloc instead of exhausting the machine.
            run = ["/bin/sh", "-c", f'ulimit -v {args.mem_limit_mb * 1024} && exec "$@"', "sh"] + cmd
        # A render that times out is run again with three times the timeout (--retries), so a
        # slow render on a busy machine is not mistaken for a hang.
        for limit in [args.timeout] + [3 * args.timeout] * args.retries:
            if (wdir / "out.exr").exists():
                (wdir / "out.exr").unlink()
            p = subprocess.Popen(run, cwd=wdir, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, start_new_session=True)
            try:
                out, err = p.communicate(timeout=limit)
                timed_out = False
            except subprocess.TimeoutExpired:
                timed_out = True
                os.killpg(p.pid, signal.SIGKILL)
                out, err = p.communicate()
            if not timed_out:
                break
        rc = p.returncode
        passed, cls, detail = classify(m, rc, timed_out, out, err, wdir, args.iinfo)
    except Exception:  # a failure of the fuzzer itself is a failure too
        passed, cls, detail = False, "fuzzer error", traceback.format_exc()
    secs = time.monotonic() - t0
    result = {"id": m.ident, "kind": m.kind, "seed": str(m.seed.relative_to(ROOT)) if m.seed else "",
              "ops": m.ops, "passed": passed, "class": cls, "rc": rc, "seconds": round(secs, 2),
              "signature": "" if passed else signature(cls, err + detail.encode())}
    if passed and not args.keep:
        shutil.rmtree(wdir, ignore_errors=True)
        return result
    dest = (failures if not passed else work.parent / "passed") / f"{m.ident:05d}-{m.kind}"
    if dest.exists():
        shutil.rmtree(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    if wdir.exists():
        os.rename(wdir, dest)
    else:
        dest.mkdir()
    (dest / "stdout.txt").write_bytes(out[:65536])
    (dest / "stderr.txt").write_bytes(err[:65536])
    (dest / "result.txt").write_text(json.dumps(result, indent=2, ensure_ascii=True) + "\n" +
                                     detail[:65536])
    sh = ["#!/bin/bash",
          f"# fuzz mutant {m.ident} (--seed {args.seed}); seed scene: {result['seed'] or '-'}",
          *[f"#   {o!r}"[:200] for o in m.ops],
          f"# outcome: {cls}",
          'cd "$(dirname "$0")"']
    for kind, name, target in m.setup:
        if kind == "fifo":
            sh.append(f"[ -p {shell_quote(name)} ] || mkfifo {shell_quote(name)}")
        elif kind == "dir":
            sh.append(f"mkdir -p {shell_quote(name)}")
        else:
            sh.append(f"[ -L {shell_quote(name)} ] || ln -s {shell_quote(target)} {shell_quote(name)}")
    sh.append(f'exec "${{CANOPY:-{args.canopy}}}" ' + " ".join(shell_quote(a) for a in cmd[1:]))
    (dest / "cmd.sh").write_text("\n".join(sh) + "\n")
    os.chmod(dest / "cmd.sh", 0o755)
    result["dir"] = str(dest)
    return result


def table(rows, header):
    widths = [max(len(str(r[i])) for r in rows + [header]) for i in range(len(header))]
    fmt = "  ".join("{:<%d}" % w if i == 0 else "{:>%d}" % w for i, w in enumerate(widths))
    lines = [fmt.format(*header), fmt.format(*["-" * w for w in widths])]
    lines += [fmt.format(*r) for r in rows]
    return "\n".join(lines)


def summarize(results):
    out = []
    classes = {}
    for r in results:
        classes[r["class"]] = classes.get(r["class"], 0) + 1
    rows = sorted(classes.items(), key=lambda kv: (not kv[0].startswith("ok"), -kv[1]))
    out.append(table([[k, v] for k, v in rows], ["outcome", "mutants"]))
    out.append("")
    ops = {}
    for r in results:
        op = r["ops"][0].split()[0] if r["kind"] == "special" else (
            "bytes" if r["kind"] == "bytes" else
            r["kind"] + ":" + (r["ops"][0].split()[0].rstrip(":") if r["kind"] == "json" and r["ops"] else ""))
        if r["kind"] in ("pbrt", "ply") and r["ops"]:
            words = r["ops"][0].split()
            op = r["kind"] + ":" + (words[1].rstrip(":") if len(words) > 1 else "")
        if r["kind"] == "obj":
            op = "obj/mtl"
        if r["kind"] == "special":
            op = "special files"
        if r["kind"] == "cli":
            op = "command-line options"
        row = ops.setdefault(op, [0, 0, 0, 0])
        row[0] += 1
        if r["class"] == "ok: image":
            row[1] += 1
        elif r["class"] == "ok: one-line error":
            row[2] += 1
        else:
            row[3] += 1
    out.append(table([[k, *v] for k, v in sorted(ops.items())],
                     ["mutation (first op)", "mutants", "ok image", "ok error", "FAILED"]))
    fails = [r for r in results if not r["passed"]]
    if fails:
        groups = {}
        for r in fails:
            groups.setdefault(r["signature"], []).append(r)
        out.append("")
        out.append("failures by cause (count, first reproducer):")
        for sig, rs in sorted(groups.items(), key=lambda kv: -len(kv[1])):
            out.append(f"  {len(rs):4d}  {sig}")
            out.append(f"        {rs[0].get('dir', '')}/cmd.sh")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 epilog="See docs/testing.md for the short and the long form.")
    ap.add_argument("--canopy", default=str(ROOT / "build/canopy"), help="canopy binary")
    ap.add_argument("--iinfo", default=shutil.which("iinfo") or "iinfo",
                    help="OpenImageIO's iinfo (finiteness of the image)")
    ap.add_argument("--count", type=int, default=1000, help="number of mutants (default 1000)")
    ap.add_argument("--jobs", type=int, default=2, help="renders in parallel")
    ap.add_argument("--seed", type=int, default=1, help="fuzzer seed (the mutants depend on it)")
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds per render")
    ap.add_argument("--retries", type=int, default=1,
                    help="reruns of a timed-out render, with 3x the timeout (default 1)")
    ap.add_argument("--mem-limit-mb", type=int, default=4096,
                    help="address-space limit per render (0: none; must be 0 under ASan)")
    ap.add_argument("--out", default="fuzz-out", help="output directory (failures/, results.jsonl)")
    ap.add_argument("--no-heavy", action="store_true",
                    help=f"leave out the slow seeds ({', '.join(sorted(HEAVY_SEEDS))})")
    ap.add_argument("--no-special", action="store_true", help="leave out the special-file cases")
    ap.add_argument("--formats", choices=["all", "json", "pbrt"], default="all",
                    help="mutate JSON scenes (with OBJ/MTL), pbrt-v4 scenes (with PLY) or both")
    ap.add_argument("--only", type=int, action="append", help="run only mutant ID (repeatable)")
    ap.add_argument("--keep", action="store_true", help="keep passing mutants too (OUT/passed)")
    ap.add_argument("--list", action="store_true", help="print the mutations, run nothing")
    args = ap.parse_args()

    args.canopy = Path(args.canopy).resolve()
    if not args.list:
        if not os.access(args.canopy, os.X_OK):
            sys.exit(f"fuzz: {args.canopy}: not an executable (build canopy or pass --canopy)")
        if not shutil.which(args.iinfo):
            sys.exit(f"fuzz: {args.iinfo}: not found (openimageio-tools, scripts/install-deps.sh)")
        if args.mem_limit_mb and b"__asan_init" in args.canopy.read_bytes():
            # ASan reserves terabytes of address space: ulimit -v cannot work. Its own RSS limit
            # takes the place (the process dies with an ASan report, a failure like bad_alloc).
            print("fuzz: the binary uses AddressSanitizer: RSS limit instead of ulimit -v",
                  flush=True)
            opts = os.environ.get("ASAN_OPTIONS", "")
            os.environ["ASAN_OPTIONS"] = (opts + ":" if opts else "") + \
                f"hard_rss_limit_mb={args.mem_limit_mb}"
            args.mem_limit_mb = 0
            # LSan's scan of dynamic TLS crashes on some renders (tests/sanitizers/lsan-no-tls.supp
            # says which and why): leaks are still checked, without the TLS roots, and the system
            # libraries that keep data only there are suppressed by name.
            lsan = os.environ.get("LSAN_OPTIONS", "")
            supp = ROOT / "tests" / "sanitizers" / "lsan-no-tls.supp"
            os.environ["LSAN_OPTIONS"] = (lsan + ":" if lsan else "") + \
                f"use_tls=0:print_suppressions=0:suppressions={supp}"

    seeds = load_seeds(not args.no_heavy)
    pbrt_seeds = load_pbrt_seeds()
    formats = ["json", "pbrt"] if args.formats == "all" else [args.formats]
    specials = [] if args.no_special else (
        (special_cases() if "json" in formats else []) +
        (pbrt_special_cases() if "pbrt" in formats else []))
    ids = args.only if args.only else list(range(args.count))
    mutants = [make_mutant(i, args.seed, seeds, specials, pbrt_seeds, formats) for i in ids]
    if args.list:
        for m in mutants:
            seed = m.seed.relative_to(ROOT) if m.seed else "-"
            print(f"{m.ident:5d} {m.kind:8s} {seed}: " + repr("; ".join(m.ops))[:300])
        return 0

    outdir = Path(args.out).resolve()
    work, failures = outdir / "work", outdir / "failures"
    for d in (work, failures, outdir / "passed"):
        shutil.rmtree(d, ignore_errors=True)
    work.mkdir(parents=True)
    print(f"fuzz: {len(mutants)} mutants from {len(seeds) + len(pbrt_seeds)} seeds, --seed {args.seed}, "
          f"{args.jobs} jobs, timeout {args.timeout:g} s, {args.canopy}", flush=True)

    t0 = time.monotonic()
    results, lock = [], threading.Lock()
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futs = [pool.submit(run_one, m, args, work, failures) for m in mutants]
        for fut in concurrent.futures.as_completed(futs):
            r = fut.result()
            with lock:
                results.append(r)
                if not r["passed"]:
                    print(f"FAIL {r['id']:5d} {r['class']}: {'; '.join(r['ops'])[:160]!r}"
                          f" -> {r.get('dir', '')}", flush=True)
                if len(results) % 100 == 0:
                    print(f"fuzz: {len(results)}/{len(mutants)} done, "
                          f"{time.monotonic() - t0:.0f} s", flush=True)
    shutil.rmtree(work, ignore_errors=True)
    results.sort(key=lambda r: r["id"])
    with open(outdir / "results.jsonl", "w") as f:
        for r in results:
            f.write(json.dumps(r, ensure_ascii=True) + "\n")
    summary = summarize(results)
    n_fail = sum(not r["passed"] for r in results)
    slowest = max(results, key=lambda r: r["seconds"])
    tail = (f"wall {time.monotonic() - t0:.1f} s; slowest mutant {slowest['id']} "
            f"{slowest['seconds']:.1f} s\nfuzz: {len(results) - n_fail} passed, {n_fail} failed")
    (outdir / "summary.txt").write_text(summary + "\n" + tail + "\n")
    print(summary)
    print(tail)
    return 1 if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
