#!/usr/bin/env python3
"""The scenes of docs/evaluation.md, each written twice: as VRML97 for gtsphere and as a
Tachyon scene file (.dat) with the same spheres and camera.

    scenes.py pymol  OUT.wrl OUT.dat [--size PX]   # the PyMOL export, read in place
    scenes.py random OUT.wrl OUT.dat [--size PX]   # 20 000 unit spheres, no overlaps
    scenes.py fcc    OUT.wrl OUT.dat [--size PX]   # an FCC crystal, 32 000 atoms

Only the Python 3 standard library.

- pymol: the corpus's tools/pymol/pymol_peptide800_spheres.wrl (PyMOL 3, 12 960
  atoms as Transform/Sphere nodes, a rod along x about 21 across). gtsphere reads the file
  itself, through an Inline in a small VRML file that adds the camera (a Viewpoint named
  "eval", chosen with --viewpoint); Tachyon gets the translations and radii read from it.
- random: random sequential addition of unit spheres in a cube 65.4 across with no two
  overlapping (a volume fraction of 0.30; such packings jam at 0.38); Python's
  random.Random(1).
- fcc: 20 x 20 x 20 cubic cells of side 2 sqrt 2 (nearest neighbours 2 apart), radius 0.98,
  so neighbouring atoms leave a gap of 0.04.

The camera is perspective, on the +z side looking down -z with up +y, square, its field of
view set per scene. Tachyon is left-handed, so every z is written negated (a mirror: the
picture comes out the same); the frustum is moved by half a pixel so that Tachyon's rays go
through the pixel centres, as gtsphere's `--sampler center` (see benches/tachyon/gen.py).
The Tachyon material is white (COLOR 1, AMBIENT 0, DIFFUSE 1, SPECULAR 0; Tachyon scales its
skylight by the diffuse coefficient) and the scene has
no lights, so with `-add_skylight 1` the picture is Tachyon's ambient occlusion alone.
"""

import argparse
import math
import os
import random
import re

# The VRML corpus beside the checkout (as the tests find it), or $GTSPHERE_CORPUS.
CORPUS = os.environ.get(
    "GTSPHERE_CORPUS",
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "corpus"),
)
PYMOL = os.path.join(CORPUS, "tools", "pymol", "pymol_peptide800_spheres.wrl")


def num(v):
    return "%.9g" % v


def pymol():
    text = open(PYMOL).read()
    centres = [tuple(float(v) for v in m)
               for m in re.findall(r"translation\s+(\S+)\s+(\S+)\s+(\S+)", text)]
    radii = [float(m) for m in re.findall(r"Sphere\s*\{\s*radius\s+(\S+)", text)]
    assert len(centres) == len(radii) == 12960, (len(centres), len(radii))
    # camera 60 above the rod's middle; 24 across at the rod's axis
    return list(zip(centres, radii)), (0.0, 0.0, 60.0), 2.0 * math.atan(12.0 / 60.0)


def random_packing(n=20000, phi=0.30):
    side = (n * 4.0 / 3.0 * math.pi / phi) ** (1.0 / 3.0)
    rng = random.Random(1)
    cell = 2.0
    grid = {}
    out = []
    while len(out) < n:
        p = (rng.uniform(1, side - 1), rng.uniform(1, side - 1), rng.uniform(1, side - 1))
        k = tuple(int(c / cell) for c in p)
        ok = True
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for q in grid.get((k[0] + dx, k[1] + dy, k[2] + dz), ()):
                        if (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2 < 4.0:
                            ok = False
                            break
                    if not ok:
                        break
                if not ok:
                    break
            if not ok:
                break
        if ok:
            grid.setdefault(k, []).append(p)
            out.append(p)
    h = side / 2.0
    spheres = [((x - h, y - h, z - h), 1.0) for x, y, z in out]
    # camera 1.6 sides from the middle, the whole cube in view
    return spheres, (0.0, 0.0, 1.6 * side), 2.0 * math.atan(0.5 * side / (1.1 * side))


def fcc(cells=20, radius=0.98):
    a = 2.0 * math.sqrt(2.0)
    basis = ((0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5))
    h = cells * a / 2.0
    spheres = []
    for i in range(cells):
        for j in range(cells):
            for k in range(cells):
                for b in basis:
                    spheres.append((((i + b[0]) * a - h, (j + b[1]) * a - h,
                                     (k + b[2]) * a - h), radius))
    side = cells * a
    # a corner-on view would need a rotated camera; looking down -z at the (001) face, off
    # centre so that the crystal's edge and its steps are in the picture
    return spheres, (0.3 * side, 0.3 * side, 1.4 * side), 2.0 * math.atan(0.35 * side / (0.9 * side))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", choices=("pymol", "random", "fcc"))
    ap.add_argument("wrl")
    ap.add_argument("dat")
    ap.add_argument("--size", type=int, default=384)
    a = ap.parse_args()
    spheres, eye, fov = {"pymol": pymol, "random": random_packing, "fcc": fcc}[a.scene]()

    with open(a.wrl, "w") as w:
        w.write("#VRML V2.0 utf8\n")
        w.write(f"# docs/evaluation.md's scene '{a.scene}', written by benches/ao/scenes.py\n")
        w.write(f'Viewpoint {{ position {num(eye[0])} {num(eye[1])} {num(eye[2])} '
                f'fieldOfView {num(fov)} description "eval" }}\n')
        if a.scene == "pymol":
            # gtsphere loads an Inline given as a path relative to the including file
            rel = os.path.relpath(PYMOL, os.path.dirname(os.path.abspath(a.wrl)))
            w.write(f'Inline {{ url "{rel}" }}\n')
        else:
            w.write("PROTO Particle [ field SFVec3f position 0 0 0 field SFFloat radius 1 ] {\n"
                    "  Transform { translation IS position children Shape {\n"
                    "    appearance Appearance { material Material { } }\n"
                    "    geometry Sphere { radius IS radius } } } }\n")
            for (x, y, z), r in spheres:
                w.write(f"Particle {{ position {num(x)} {num(y)} {num(z)} radius {num(r)} }}\n")

    h = math.tan(fov / 2.0)  # Tachyon's image plane is at distance 1
    half_px = h / a.size
    lo, hi = num(-h - half_px), num(h - half_px)
    with open(a.dat, "w") as t:
        t.write("BEGIN_SCENE\n")
        t.write(f"  RESOLUTION {a.size} {a.size}\n")
        t.write("CAMERA\n  ZOOM 1.0\n  ASPECTRATIO 1.0\n  ANTIALIASING 0\n  RAYDEPTH 1\n"
                f"  CENTER {num(eye[0])} {num(eye[1])} {num(-eye[2])}\n"
                "  VIEWDIR 0 0 1\n  UPDIR 0 1 0\n"
                f"  FRUSTUM {lo} {hi} {lo} {hi}\nEND_CAMERA\n")
        t.write("BACKGROUND 0 0 0\n")
        t.write("TEXDEF white AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 "
                "COLOR 1 1 1 TEXFUNC 0\n")
        for (x, y, z), r in spheres:
            t.write(f"SPHERE CENTER {num(x)} {num(y)} {num(-z)} RAD {num(r)} white\n")
        t.write("END_SCENE\n")


if __name__ == "__main__":
    main()
