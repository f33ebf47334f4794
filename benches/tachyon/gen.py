#!/usr/bin/env python3
"""Write `gtsphere bench trace`'s scene (gtsphere::bench::scenes::random_spheres) twice: as VRML97
for gtsphere and as a Tachyon scene file (.dat), the same spheres, camera and lights.

    gen.py N OUT.wrl OUT.dat [--size PX] [--plain]

Only the Python 3 standard library. The scene (as in src/bench/scenes.rs and benches/embree):

- N spheres: SplitMix64 with state 1, three draws (x, y, z) per sphere, u = (next >> 11) *
  2^-53, centre 2u - 1; every radius 0.6 * N^(-1/3). All opaque, VRML's default Material
  (diffuseColor 0.8 0.8 0.8, no specular, ambientIntensity 0.2, which no light uses).
- Camera at (0, 0, 4) looking down -z, up +y, fieldOfView 0.785398 (square image).
- A white PointLight at (3, 3, 3) (no attenuation) and a white DirectionalLight along
  (-1, -1, -1), intensity 1, ambientIntensity 0; headlight off; black background.

Numbers are written with 9 significant digits (`%.9g`, enough to give back every f32, which
is what Embree sees), the same text in both files.

VRML: the `PROTO Particle` form that `gtsphere convert` writes (the same PROTO; one line
`Particle { position x y z radius r }` per sphere), or with --plain, ordinary
`Transform { translation .. children Shape { appearance Appearance { material Material { } }
geometry Sphere { radius r } } }` nodes.

Tachyon: Tachyon is left-handed (its camera's right vector is up x view), so every point
and vector is written with z negated, a mirror, and the picture comes out the same, not
mirrored. One named texture (TEXDEF) shared by all spheres: COLOR 0.8, DIFFUSE 1, AMBIENT 0,
SPECULAR 0 (Tachyon's SPECULAR is mirror reflection), no PHONG, OPACITY 1, which is the same
Lambert term as VRML's. ANTIALIASING 0 (one ray per pixel), RAYDEPTH 1. The image plane is
given by FRUSTUM rather than ZOOM: Tachyon puts pixel k's ray on the far edge of the pixel
(lowleft + (k + 1) * pixel size, k from 0), so the frustum is moved back by half a pixel and
the rays go through the pixel centres, as gtsphere's `--sampler center`.
"""

import argparse
import math

MASK = (1 << 64) - 1
FOV = 0.785398  # bench trace's stated value (random_spheres)


def spheres(n):
    """The centres in order, as f64 (Python floats), from SplitMix64 seeded with 1."""
    state = 1
    scale = 1.0 / (1 << 53)
    for _ in range(n):
        c = []
        for _ in range(3):
            state = (state + 0x9E3779B97F4A7C15) & MASK
            z = state
            z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
            z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
            z ^= z >> 31
            c.append(2.0 * ((z >> 11) * scale) - 1.0)
        yield c


def num(v):
    return "%.9g" % v


# `gtsphere convert`'s PROTO (src/particles/write.rs), radius default 1.
PROTO = """PROTO Particle [
  field SFVec3f position 0 0 0
  field SFFloat radius 1
  field SFColor color 0.8 0.8 0.8
  field SFColor emission 0 0 0
  field SFFloat transparency 0
] {
  Transform {
    translation IS position
    children Shape {
      appearance Appearance {
        material Material { diffuseColor IS color emissiveColor IS emission transparency IS transparency }
      }
      geometry Sphere { radius IS radius }
    }
  }
}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("n", type=float, help="number of spheres (1e6 is accepted)")
    ap.add_argument("wrl")
    ap.add_argument("dat")
    ap.add_argument("--size", type=int, default=512, help="Tachyon's RESOLUTION (square)")
    ap.add_argument("--plain", action="store_true", help="Transform/Shape/Sphere nodes")
    a = ap.parse_args()
    n = int(a.n)
    if n < 1 or a.size < 1:
        ap.error("N and --size must be positive")
    radius = num(0.6 * float(n) ** (-1.0 / 3.0))

    # Tachyon's image plane sits at distance 1 (focal length 1) from the eye: half-height
    # tan(fov / 2); moved back by half a pixel (see above).
    h = math.tan(FOV / 2.0)
    half_px = h / a.size
    lo, hi = num(-h - half_px), num(h - half_px)
    d = 1.0 / math.sqrt(3.0)

    with open(a.wrl, "w") as w, open(a.dat, "w") as t:
        w.write("#VRML V2.0 utf8\n")
        w.write(f"# gtsphere bench trace's scene (scenes::random_spheres), N = {n}, "
                "written by benches/tachyon/gen.py\n")
        w.write("NavigationInfo { headlight FALSE }\n")
        w.write(f'Viewpoint {{ position 0 0 4 fieldOfView {FOV} description "bench" }}\n')
        # radius 100 (the default) reaches every sphere: the farthest is 7 units away.
        w.write("PointLight { location 3 3 3 }\n")
        w.write("DirectionalLight { direction -1 -1 -1 }\n")
        if not a.plain:
            w.write(PROTO)

        t.write("BEGIN_SCENE\n")
        t.write(f"  RESOLUTION {a.size} {a.size}\n")
        t.write("CAMERA\n  ZOOM 1.0\n  ASPECTRATIO 1.0\n  ANTIALIASING 0\n  RAYDEPTH 1\n"
                "  CENTER 0 0 -4\n  VIEWDIR 0 0 1\n  UPDIR 0 1 0\n"
                f"  FRUSTUM {lo} {hi} {lo} {hi}\nEND_CAMERA\n")
        t.write("BACKGROUND 0 0 0\n")
        t.write("LIGHT CENTER 3 3 -3 RAD 0 COLOR 1 1 1\n")
        t.write(f"DIRECTIONAL_LIGHT DIRECTION {num(-d)} {num(-d)} {num(d)} COLOR 1 1 1\n")
        t.write("TEXDEF grey AMBIENT 0 DIFFUSE 1 SPECULAR 0 OPACITY 1 "
                "COLOR 0.8 0.8 0.8 TEXFUNC 0\n")

        wl, tl = [], []
        for x, y, z in spheres(n):
            sx, sy = num(x), num(y)
            if a.plain:
                wl.append(f"Transform {{ translation {sx} {sy} {num(z)} children Shape {{ "
                          "appearance Appearance { material Material { } } "
                          f"geometry Sphere {{ radius {radius} }} }} }}\n")
            else:
                wl.append(f"Particle {{ position {sx} {sy} {num(z)} radius {radius} }}\n")
            tl.append(f"SPHERE CENTER {sx} {sy} {num(-z)} RAD {radius} grey\n")
            if len(wl) >= 65536:
                w.writelines(wl)
                t.writelines(tl)
                wl, tl = [], []
        w.writelines(wl)
        t.writelines(tl)
        t.write("END_SCENE\n")


if __name__ == "__main__":
    main()
