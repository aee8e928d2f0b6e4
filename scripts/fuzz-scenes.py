#!/usr/bin/env python3
"""Mutation fuzzer for `canopy render`: scene JSON, OBJ/MTL files and special files.

Every mutant is a scene (plus any OBJ/MTL it needs) in its own directory, rendered with
`canopy render scene.json --spp 1 --out out.exr` at an 8 x 8 film (the film is rewritten in the
seed before mutation, so only mutations aimed at `film` change it). An outcome passes when it is

  * exit 0 and out.exr exists with every pixel finite (checked with `iinfo --stats`), or
  * exit 2 and stderr is exactly one line, without control bytes, valid UTF-8, that begins with
    the scene path as given (when that path is printable).

Anything else fails: a timeout, a signal, exit 1, any other exit code, a multi-line or unescaped
exit-2 message, a missing or non-finite image. Each failing mutant is moved to OUT/failures/<id>
with `cmd.sh` (reproduces it), `stdout.txt`, `stderr.txt` and `result.txt`.

Mutant i depends only on --seed and i (not on --count or --jobs), so a failure is reproduced by
`--seed S --only i`. Standard library only. docs/testing.md has the short and the long form.
"""

import argparse
import concurrent.futures
import copy
import json
import math
import os
import random
import re
import shutil
import signal
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


# ------------------------------------------------------------------ mutant generation
CATEGORIES = [("json", 55), ("bytes", 15), ("obj", 30)]


def weighted(rng, items):
    total = sum(w for _, w in items)
    r = rng.uniform(0, total)
    for item, w in items:
        r -= w
        if r <= 0:
            return item
    return items[-1][0]


def make_mutant(ident, base_seed, seeds, specials):
    if ident < len(specials):
        kind, arg, files, setup, args, names = specials[ident]
        m = Mutant(ident, None)
        m.kind = "cli" if kind.startswith("cli ") else "special"
        m.ops.append(kind)
        m.scene_arg = arg
        m.files = dict(files)
        m.setup = setup
        m.args = args
        m.names = names
        m.expect_error = kind.startswith(("scene-", "obj-", "mtl-", "cli "))
        return m
    rng = random.Random(f"{base_seed}/{ident}")
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

    seeds = load_seeds(not args.no_heavy)
    specials = [] if args.no_special else special_cases()
    ids = args.only if args.only else list(range(args.count))
    mutants = [make_mutant(i, args.seed, seeds, specials) for i in ids]
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
    print(f"fuzz: {len(mutants)} mutants from {len(seeds)} seeds, --seed {args.seed}, "
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
