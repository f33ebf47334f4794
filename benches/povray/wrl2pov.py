#!/usr/bin/env python3
"""Write a gtsphere scene (VRML97) as a POV-Ray 3.7 scene that renders the same picture.

    wrl2pov.py SCENE.wrl OUT.pov [--samples N] [--width W --height H]

Reads the subset of VRML97 that `gtsphere bench gas --write` and `gtsphere convert` write
(and hand-written files like it): Transform (translation, uniform scale), Group, Shape,
Appearance, Material, Sphere, PointLight, DirectionalLight, Viewpoint, Background,
NavigationInfo, DEF/USE. Anything else stops the conversion with a message, so that a
picture is never silently different.

The model (gtsphere's docs/model.md) in POV-Ray terms, per sphere:

- gas (0 < transparency <= 1): extinction sigma = -ln(transparency) / (2 r), albedo a =
  diffuseColor, emission C = emissiveColor. A `hollow` sphere with a fully transparent
  surface (`pigment { rgbt 1 }`, every finish term 0) holding
      media { method 2 intervals 1 samples N,N
              absorption sigma (1 - a)
              emission   sigma C
              scattering { 1, sigma a / (4 pi) extinction 4 pi } }
  POV-Ray's isotropic phase function is 1 per steradian, ours 1 / (4 pi): the scattering
  colour carries the 1 / (4 pi), and `extinction 4 pi` puts sigma a back into the
  extinction, so that absorption + extinction * scattering = sigma in every channel.
- opaque: `pigment { rgb diffuseColor } finish { ambient 0 diffuse 1 }` (Lambert only;
  a specularColor other than 0 is refused).

Lights: a PointLight is a `light_source` of colour color * intensity (attenuation must be
1 0 0: no fall-off, as in POV-Ray without fade); a DirectionalLight a `parallel` light far
along -direction. Both have `media_attenuation on media_interaction on`, so that gas
shadows and is lit. Ambient terms are refused unless 0 (POV-Ray's `ambient_light 0`).

Coordinates: VRML is right-handed, POV-Ray left-handed, so every point and vector is written
with z negated (a mirror), and the camera's right / up / direction vectors are given
explicitly: the picture is the same, not mirrored. `fieldOfView` is the angle of the smaller
image side (VRML), so the camera needs the image's aspect: --width / --height (default 128).

--exposure K scales the picture by K (lights, emission, background), so that a linear
16-bit PNG holds it with small steps; png2pfm.py --exposure K undoes it.
"""

import argparse
import math
import re
import sys

TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"|[{}\[\]]|[^\s,{}\[\]"#]+')


def tokens(text):
    out = []
    for line in text.splitlines():
        # A '#' outside a string starts a comment (the strings we read hold no '#').
        in_string = False
        for k, ch in enumerate(line):
            if ch == '"':
                in_string = not in_string
            elif ch == "#" and not in_string:
                line = line[:k]
                break
        out.extend(TOKEN.findall(line))
    return out


class Parser:
    def __init__(self, toks):
        self.t = toks
        self.i = 0
        self.defs = {}

    def peek(self, k=0):
        j = self.i + k
        return self.t[j] if j < len(self.t) else None

    def take(self):
        tok = self.peek()
        if tok is None:
            sys.exit("wrl2pov: unexpected end of file")
        self.i += 1
        return tok

    def expect(self, what):
        tok = self.take()
        if tok != what:
            sys.exit(f"wrl2pov: expected {what!r}, found {tok!r} (token {self.i})")

    def at_node(self):
        tok = self.peek()
        return tok in ("DEF", "USE", "NULL") or (
            tok is not None and self.peek(1) == "{" and re.match(r"[A-Za-z_]", tok)
        )

    def node(self):
        tok = self.take()
        if tok == "DEF":
            name = self.take()
            n = self.node()
            self.defs[name] = n
            return n
        if tok == "USE":
            name = self.take()
            if name not in self.defs:
                sys.exit(f"wrl2pov: USE {name} before its DEF")
            return self.defs[name]
        if tok == "NULL":
            return None
        if tok in ("PROTO", "EXTERNPROTO", "ROUTE"):
            sys.exit(f"wrl2pov: {tok} is not supported")
        node = {"type": tok}
        self.expect("{")
        while self.peek() != "}":
            field = self.take()
            node[field] = self.value()
        self.expect("}")
        return node

    def value(self):
        if self.peek() == "[":
            self.take()
            items = []
            while self.peek() != "]":
                items.append(self.node() if self.at_node() else self.scalar())
            self.take()
            return items
        if self.at_node():
            return self.node()
        tok = self.peek()
        if tok.startswith('"'):
            return self.take()
        if tok in ("TRUE", "FALSE"):
            return self.take() == "TRUE"
        nums = []
        while self.peek() is not None and is_number(self.peek()):
            nums.append(float(self.take()))
        if not nums:
            sys.exit(f"wrl2pov: cannot read a value at {tok!r}")
        return nums

    def scalar(self):
        tok = self.take()
        return tok if tok.startswith('"') else float(tok)


def is_number(tok):
    try:
        float(tok)
        return True
    except ValueError:
        return False


def vec(node, field, default):
    v = node.get(field, default)
    return list(v) if isinstance(v, list) else v


class Scene:
    def __init__(self):
        self.spheres = []  # (centre, radius, material dict)
        self.points = []
        self.directionals = []
        self.viewpoint = None
        self.background = [0.0, 0.0, 0.0]
        self.headlight = True


def children(node):
    c = node.get("children", [])
    return c if isinstance(c, list) else [c]


def walk(node, offset, scale, scene):
    if node is None:
        return
    kind = node["type"]
    if kind == "Transform":
        s = vec(node, "scale", [1, 1, 1])
        if not s[0] == s[1] == s[2]:
            sys.exit("wrl2pov: non-uniform scale (ellipsoids) is not supported")
        if vec(node, "rotation", [0, 0, 1, 0])[3] != 0:
            sys.exit("wrl2pov: Transform.rotation is not supported")
        if any(vec(node, "center", [0, 0, 0])):
            sys.exit("wrl2pov: Transform.center is not supported")
        t = vec(node, "translation", [0, 0, 0])
        new_off = [offset[k] + scale * t[k] for k in range(3)]
        for ch in children(node):
            walk(ch, new_off, scale * s[0], scene)
    elif kind in ("Group", "Anchor", "Collision"):
        for ch in children(node):
            walk(ch, offset, scale, scene)
    elif kind == "Shape":
        geo = node.get("geometry")
        if geo is None:
            return
        if geo["type"] != "Sphere":
            sys.exit(f"wrl2pov: geometry {geo['type']} is not supported")
        r = scale * vec(geo, "radius", [1.0])[0]
        app = node.get("appearance")
        mat = app.get("material") if app else None
        scene.spheres.append((list(offset), r, mat))
    elif kind == "PointLight":
        if vec(node, "on", True):
            att = vec(node, "attenuation", [1, 0, 0])
            if att != [1, 0, 0]:
                sys.exit("wrl2pov: PointLight.attenuation other than 1 0 0 is not supported")
            if vec(node, "ambientIntensity", [0.0])[0] != 0:
                sys.exit("wrl2pov: ambientIntensity other than 0 is not supported")
            loc = vec(node, "location", [0, 0, 0])
            loc = [offset[k] + scale * loc[k] for k in range(3)]
            col = vec(node, "color", [1, 1, 1])
            i = vec(node, "intensity", [1.0])[0]
            scene.points.append((loc, [c * i for c in col]))
    elif kind == "DirectionalLight":
        if vec(node, "on", True):
            if vec(node, "ambientIntensity", [0.0])[0] != 0:
                sys.exit("wrl2pov: ambientIntensity other than 0 is not supported")
            d = vec(node, "direction", [0, 0, -1])
            col = vec(node, "color", [1, 1, 1])
            i = vec(node, "intensity", [1.0])[0]
            # Scope: POV-Ray lights everything; gtsphere's writer puts a light that lights
            # every sphere at the top level, which is what we accept.
            scene.directionals.append((d, [c * i for c in col]))
    elif kind == "Viewpoint":
        if scene.viewpoint is None:
            scene.viewpoint = node
    elif kind == "Background":
        sky = node.get("skyColor", [0, 0, 0])
        scene.background = [float(v) for v in sky[:3]]
    elif kind == "NavigationInfo":
        scene.headlight = vec(node, "headlight", True)
    elif kind == "WorldInfo":
        pass
    else:
        sys.exit(f"wrl2pov: node {kind} is not supported")


def rotate(q_axis_angle, v):
    """Rodrigues: rotate v about the unit axis by the angle."""
    x, y, z, a = q_axis_angle
    n = math.sqrt(x * x + y * y + z * z) or 1.0
    k = [x / n, y / n, z / n]
    c, s = math.cos(a), math.sin(a)
    dot = sum(k[i] * v[i] for i in range(3))
    cross = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]]
    return [v[i] * c + cross[i] * s + k[i] * dot * (1 - c) for i in range(3)]


def pv(v):
    """A VRML point or vector as a POV-Ray vector: z negated (right- to left-handed)."""
    return f"<{v[0]!r}, {v[1]!r}, {-v[2]!r}>"


def rgb(c):
    return f"rgb <{c[0]!r}, {c[1]!r}, {c[2]!r}>"


def material_pov(mat, r, samples, exposure):
    m = mat or {}
    if mat is None:
        sys.exit("wrl2pov: Shapes without a Material (unlit) are not supported")
    diffuse = vec(m, "diffuseColor", [0.8, 0.8, 0.8])
    emissive = vec(m, "emissiveColor", [0.0, 0.0, 0.0])
    specular = vec(m, "specularColor", [0.0, 0.0, 0.0])
    transparency = vec(m, "transparency", [0.0])[0]
    if transparency <= 0:
        if any(specular) or any(emissive):
            sys.exit("wrl2pov: opaque spheres with specular or emissive colour are not supported")
        return (
            f"texture {{ pigment {{ {rgb(diffuse)} }} "
            f"finish {{ ambient 0 diffuse 1 specular 0 phong 0 }} }}"
        )
    sigma = -math.log(transparency) / (2 * r)
    absorption = [sigma * (1 - a) for a in diffuse]
    scattering = [sigma * a / (4 * math.pi) for a in diffuse]
    emission = [exposure * sigma * c for c in emissive]
    lines = [
        "texture { pigment { rgbt 1 } finish { ambient 0 diffuse 0 specular 0 phong 0 } }",
        f"interior {{ media {{ method 2 intervals 1 samples {samples},{samples}",
        f"  absorption {rgb(absorption)}",
    ]
    if any(emission):
        lines.append(f"  emission {rgb(emission)}")
    if any(scattering):
        lines.append(
            f"  scattering {{ 1, {rgb(scattering)} extinction {4 * math.pi!r} }}"
        )
    lines.append("} }")
    return "\n  ".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--samples", type=int, default=16, help="media samples per interval")
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--height", type=int, default=128)
    ap.add_argument(
        "--exposure",
        type=float,
        default=1.0,
        help="multiply every light, emission and the background by this (the picture scales "
        "with it): brings the values near 1, where a 16-bit PNG's steps of 1/65535 are small "
        "against them; png2pfm.py --exposure divides it back out",
    )
    args = ap.parse_args()

    with open(args.scene, encoding="utf-8") as f:
        text = f.read()
    if not text.startswith("#VRML V2.0"):
        sys.exit("wrl2pov: not a VRML97 file")
    p = Parser(tokens(text))
    scene = Scene()
    while p.peek() is not None:
        walk(p.node(), [0.0, 0.0, 0.0], 1.0, scene)
    if scene.headlight:
        sys.exit("wrl2pov: the headlight is on (NavigationInfo { headlight FALSE } is needed)")

    out = []
    w = out.append
    w(f"// Written by wrl2pov.py from {args.scene}: {len(scene.spheres)} spheres.")
    w("#version 3.7;")
    w("global_settings { assumed_gamma 1.0 max_trace_level 256 adc_bailout 0 ambient_light 0 }")
    k = args.exposure
    w(f"background {{ {rgb([k * c for c in scene.background])} }}")

    vp = scene.viewpoint or {}
    pos = vec(vp, "position", [0, 0, 10])
    ori = vec(vp, "orientation", [0, 0, 1, 0])
    fov = vec(vp, "fieldOfView", [math.pi / 4])[0]
    fwd = rotate(ori, [0, 0, -1])
    up = rotate(ori, [0, 1, 0])
    right = rotate(ori, [1, 0, 0])
    small = min(args.width, args.height)
    # POV-Ray's ray through image point (u, v) in [0,1]^2 is direction + (u - 1/2) right +
    # (1/2 - v) up; the smaller side spans tan(fov / 2) each way at unit distance.
    sx, sy = args.width / small, args.height / small
    dl = 0.5 / math.tan(fov / 2)
    w(
        "camera { perspective "
        f"location {pv(pos)} "
        f"direction {pv([c * dl for c in fwd])} "
        f"right {pv([c * sx for c in right])} "
        f"up {pv([c * sy for c in up])} }}"
    )
    for loc, col in scene.points:
        w(
            f"light_source {{ {pv(loc)} color {rgb([k * c for c in col])} "
            "media_attenuation on media_interaction on }"
        )
    for d, col in scene.directionals:
        n = math.sqrt(sum(c * c for c in d))
        far = [-1e3 * c / n for c in d]
        w(
            f"light_source {{ {pv(far)} color {rgb([k * c for c in col])} parallel point_at <0, 0, 0> "
            "media_attenuation on media_interaction on }"
        )

    # One declared material per (VRML material, radius): the clouds use a few colours and
    # one radius, so the file stays small and POV-Ray parses it quickly.
    declared = {}
    body = []
    for c, r, mat in scene.spheres:
        key = (id(mat), r)
        if key not in declared:
            name = f"M{len(declared)}"
            declared[key] = name
            w(f"#declare {name} = material {{\n  {material_pov(mat, r, args.samples, args.exposure)}\n}}")
        gas = mat is not None and vec(mat, "transparency", [0.0])[0] > 0
        body.append(
            f"sphere {{ {pv(c)}, {r!r} {'hollow ' if gas else ''}material {{ {declared[key]} }} }}"
        )
    out.extend(body)
    with open(args.out, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")
    print(
        f"wrl2pov: wrote {args.out}: {len(scene.spheres)} spheres, {len(declared)} materials, "
        f"{len(scene.points)} point and {len(scene.directionals)} directional lights",
        file=sys.stderr,
    )


if __name__ == "__main__":
    main()
