#!/usr/bin/env python3
"""Generates the showroom of Liu, Xu & Yan 2019, Fig. 1 ("Car Exhibition"): a glossy metal
object on a glossy floor, lit by thousands of small disk lights around and above it and by one
large area light on the ceiling.

    python3 scripts/gen-showroom.py            # rewrites scenes/showroom.json and scenes/showroom/*.obj
    python3 scripts/gen-showroom.py --ceiling 80 --side 100 --out /tmp/showroom-big.json

The paper's car (43,486 disk lights, 1280 x 720) is not available; the object is a stylised car
built from smooth parametric surfaces with per-vertex normals (`vn`):

  * body: a superellipsoid 4.2 x 0.9 x 1.8 m (exponent 0.3: a rounded box), gold conductor,
    roughness 0.15 (`"metal": "gold"`);
  * cabin: a superellipsoid 2.2 x 0.7 x 1.5 m on top, dark tinted plastic, roughness 0.05 (glass);
  * four wheels: tori (radius 0.34 m, tube 0.13 m), black rubber plastic, roughness 0.4.

The floor is a 40 m x 40 m quad of grey plastic, roughness 0.12 (a polished floor with blurred
reflections of the lights). The lights (all `"type": "disk"`, one-sided, facing the car):

  * a ceiling grid of C x C disks (radius 4 cm) at y = 5.5 over x, z in [-6, 6], facing down;
  * four side grids (S x 6 disks each) at |x| = 7 and |z| = 7, y in [4, 5], facing the centre and
    tilted 35 degrees down;
  * one 4 m x 3 m quad light at y = 6.2, facing down (the paper's large area light).

The camera looks down at the car from (6.5, 3.4, 7.5) so that every emitter is above the frame:
lights appear only in reflections (on the car and the floor), and the error measures the light
transport, not the anti-aliasing of visible emitters. With the defaults (C = 48, S = 60) the scene
has 48^2 + 4 * 60 * 6 = 3,744 disk lights and one quad light. Deterministic; standard library only.
"""
import argparse
import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESH_DIR = os.path.join(ROOT, "scenes", "showroom")
DISK_RADIUS = 0.04
CEILING_RADIANCE = (9.0, 8.6, 8.0)
SIDE_RADIANCE = (7.0, 7.4, 8.0)
AREA_RADIANCE = (4.0, 4.0, 4.0)
SIDE_ROWS = 6
SIDE_TILT = math.radians(35.0)


def spow(x, e):
    return math.copysign(abs(x) ** e, x)


def superellipsoid(a, b, c, e, nu, nv, centre):
    """A rounded box |x/a|^(2/e) + |y/b|^(2/e) + |z/c|^(2/e) = 1 (both exponents e), as a grid of
    nu (around y) x nv (pole to pole) quads with single pole vertices. Normals: the normalised
    gradient of the implicit function, exact for the surface."""
    verts, norms, faces = [], [], []

    def add(p):
        x, y, z = p
        g = (spow(x / a, 2 / e - 1) / a, spow(y / b, 2 / e - 1) / b, spow(z / c, 2 / e - 1) / c)
        n = math.sqrt(sum(t * t for t in g))
        verts.append((x + centre[0], y + centre[1], z + centre[2]))
        norms.append(tuple(t / n for t in g) if n > 0 else (0.0, 1.0, 0.0))
        return len(verts) - 1

    top = add((0.0, b, 0.0))
    rings = []
    for j in range(1, nv):
        v = math.pi / 2 - math.pi * j / nv  # latitude, +pi/2 (top) .. -pi/2
        ring = []
        for i in range(nu):
            u = 2 * math.pi * i / nu
            cv = spow(math.cos(v), e)
            ring.append(add((a * cv * spow(math.cos(u), e), b * spow(math.sin(v), e),
                             c * cv * spow(math.sin(u), e))))
        rings.append(ring)
    bottom = add((0.0, -b, 0.0))
    # Counter-clockwise seen from outside: u turns from +x to +z, latitude runs top to bottom.
    for i in range(nu):
        i1 = (i + 1) % nu
        faces.append((top, rings[0][i1], rings[0][i]))
        for j in range(len(rings) - 1):
            r0, r1 = rings[j], rings[j + 1]
            faces.append((r0[i], r0[i1], r1[i1]))
            faces.append((r0[i], r1[i1], r1[i]))
        faces.append((bottom, rings[-1][i], rings[-1][i1]))
    return verts, norms, faces


def torus_z(R, r, nu, nv, centre):
    """A torus around the z axis (a wheel rolling along x), outward normals."""
    verts, norms, faces = [], [], []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            n = (math.cos(b) * math.cos(a), math.cos(b) * math.sin(a), math.sin(b))
            verts.append(((R + r * math.cos(b)) * math.cos(a) + centre[0],
                          (R + r * math.cos(b)) * math.sin(a) + centre[1],
                          r * math.sin(b) + centre[2]))
            norms.append(n)
    for i in range(nu):
        for j in range(nv):
            p00 = i * nv + j
            p10 = ((i + 1) % nu) * nv + j
            p01 = i * nv + (j + 1) % nv
            p11 = ((i + 1) % nu) * nv + (j + 1) % nv
            faces.append((p00, p10, p11))
            faces.append((p00, p11, p01))
    return verts, norms, faces


def fix_winding(verts, norms, faces):
    """Orients every triangle so that its geometric normal agrees with the vertex normals."""
    out = []
    for f in faces:
        a, b, c = (verts[k] for k in f)
        e1 = [b[i] - a[i] for i in range(3)]
        e2 = [c[i] - a[i] for i in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
             e1[0] * e2[1] - e1[1] * e2[0])
        avg = [sum(norms[k][i] for k in f) for i in range(3)]
        out.append(f if sum(n[i] * avg[i] for i in range(3)) >= 0 else (f[0], f[2], f[1]))
    return out


def write_obj(path, parts, comment):
    with open(path + ".tmp", "w") as f:
        f.write(f"# {comment}: generated by scripts/gen-showroom.py, do not edit.\n")
        base = 0
        ntri = 0
        for verts, norms, faces in parts:
            faces = fix_winding(verts, norms, faces)
            for v in verts:
                f.write("v %.5f %.5f %.5f\n" % v)
            for n in norms:
                f.write("vn %.5f %.5f %.5f\n" % n)
            for t in faces:
                a, b, c = (k + 1 + base for k in t)
                f.write(f"f {a}//{a} {b}//{b} {c}//{c}\n")
            base += len(verts)
            ntri += len(faces)
    os.replace(path + ".tmp", path)
    return ntri


def write_meshes():
    os.makedirs(MESH_DIR, exist_ok=True)
    body = superellipsoid(2.1, 0.45, 0.9, 0.3, 64, 32, (0.0, 0.78, 0.0))
    cabin = superellipsoid(1.1, 0.35, 0.75, 0.35, 48, 24, (-0.25, 1.5, 0.0))
    wheels = [torus_z(0.34, 0.13, 32, 12, (x, 0.47, z)) for x in (-1.3, 1.3) for z in (-0.78, 0.78)]
    n = write_obj(os.path.join(MESH_DIR, "body.obj"), [body], "Car body (superellipsoid)")
    n += write_obj(os.path.join(MESH_DIR, "cabin.obj"), [cabin], "Car cabin (superellipsoid)")
    n += write_obj(os.path.join(MESH_DIR, "wheels.obj"), wheels, "Four wheels (tori)")
    return n


def fmt(x):
    return "%.6g" % (0.0 if abs(x) < 1e-12 else x)


def vec(v):
    return "[" + ", ".join(fmt(x) for x in v) + "]"


def disk(normal, radiance):
    return (f'{{ "type": "disk", "normal": {vec(normal)}, "radius": {fmt(DISK_RADIUS)}, '
            f'"radiance": {vec(radiance)} }}')


def scene_text(ceiling, side, args_text):
    n_disks = ceiling * ceiling + 4 * side * SIDE_ROWS
    sets = []
    sets.append(f"""    {{
      // Ceiling: {ceiling} x {ceiling} disks facing down.
      "type": "grid", "nx": {ceiling}, "ny": {ceiling},
      "origin": [-6, 5.5, -6], "edge1": [12, 0, 0], "edge2": [0, 0, 12],
      "light": {disk((0, -1, 0), CEILING_RADIANCE)}
    }}""")
    ct, st = math.cos(SIDE_TILT), math.sin(SIDE_TILT)
    # (name, origin, edge1 along the wall, inward normal)
    walls = [("back (z = -7)", (-7, 4, -7), (14, 0, 0), (0, -st, ct)),
             ("front (z = +7)", (-7, 4, 7), (14, 0, 0), (0, -st, -ct)),
             ("left (x = -7)", (-7, 4, -7), (0, 0, 14), (ct, -st, 0)),
             ("right (x = +7)", (7, 4, -7), (0, 0, 14), (-ct, -st, 0))]
    for name, origin, e1, n in walls:
        sets.append(f"""    {{
      // Side, {name}: {side} x {SIDE_ROWS} disks facing the car, tilted down.
      "type": "grid", "nx": {side}, "ny": {SIDE_ROWS},
      "origin": {vec(origin)}, "edge1": {vec(e1)}, "edge2": [0, 1, 0],
      "light": {disk(n, SIDE_RADIANCE)}
    }}""")
    sets_text = ",\n".join(sets)
    return f"""// Generated by scripts/gen-showroom.py{args_text}; do not edit.
// After Liu, Xu & Yan 2019, Fig. 1 (Car Exhibition): a gold car-like object on a polished floor,
// {n_disks} small disk lights around and above it and one large quad light on the ceiling.
// Units: metres, y up. Format: docs/scene-format.md.
{{
  "camera": {{
    "position": [6.5, 3.4, 7.5],
    "look_at": [0, 0.6, 0],
    "up": [0, 1, 0],
    "fov": 32
  }},
  "film": {{ "width": 320, "height": 240 }},
  "integrator": {{ "spp": 16, "max_depth": 3 }},
  "materials": [
    {{ "name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.15 }},
    {{ "name": "glass_tint", "type": "plastic", "albedo": [0.01, 0.012, 0.015], "specular": 1,
      "roughness": 0.05, "ior": 1.5 }},
    {{ "name": "rubber", "type": "plastic", "albedo": [0.03, 0.03, 0.03], "specular": 0.5,
      "roughness": 0.4, "ior": 1.5 }},
    {{ "name": "floor", "type": "plastic", "albedo": [0.25, 0.25, 0.27], "specular": 1,
      "roughness": 0.12, "ior": 1.5 }}
  ],
  "shapes": [
    {{ "type": "quad", "name": "floor", "material": "floor",
      "corner": [-20, 0, -20], "edge1": [0, 0, 40], "edge2": [40, 0, 0] }},
    {{ "type": "obj", "name": "body", "file": "showroom/body.obj", "material": "gold" }},
    {{ "type": "obj", "name": "cabin", "file": "showroom/cabin.obj", "material": "glass_tint" }},
    {{ "type": "obj", "name": "wheels", "file": "showroom/wheels.obj", "material": "rubber" }}
  ],
  "lights": [
    // The large area light: 4 m x 3 m at y = 6.2, facing down.
    {{ "type": "quad", "corner": [-2, 6.2, -1.5], "edge1": [0, 0, 3], "edge2": [4, 0, 0],
      "radiance": {vec(AREA_RADIANCE)} }}
  ],
  "light_sets": [
{sets_text}
  ]
}}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ceiling", type=int, default=48,
                    help="ceiling grid: C x C disks (default 48)")
    ap.add_argument("--side", type=int, default=60,
                    help="disks along each of the four side grids (6 rows each; default 60)")
    ap.add_argument("--out", default=os.path.join(ROOT, "scenes", "showroom.json"))
    ap.add_argument("--no-mesh", action="store_true", help="do not rewrite scenes/showroom/*.obj")
    a = ap.parse_args()
    if a.ceiling < 1 or a.side < 1:
        ap.error("--ceiling and --side must be >= 1")
    if not a.no_mesh:
        n = write_meshes()
        print(f"wrote {MESH_DIR}/{{body,cabin,wheels}}.obj: {n} triangles")
    args_text = ""
    if a.ceiling != 48:
        args_text += f" --ceiling {a.ceiling}"
    if a.side != 60:
        args_text += f" --side {a.side}"
    text = scene_text(a.ceiling, a.side, args_text)
    out_dir = os.path.dirname(os.path.abspath(a.out))
    os.makedirs(out_dir, exist_ok=True)
    if out_dir != os.path.join(ROOT, "scenes"):
        rel = os.path.relpath(os.path.join(ROOT, "scenes"), out_dir)
        text = text.replace('"file": "showroom/', f'"file": "{rel}/showroom/')
    with open(a.out + ".tmp", "w") as f:
        f.write(text)
    os.replace(a.out + ".tmp", a.out)
    print(f"wrote {a.out}: {a.ceiling * a.ceiling + 4 * a.side * SIDE_ROWS} disk lights + 1 quad")


if __name__ == "__main__":
    main()
