#!/usr/bin/env python3
"""Writes directlab's own Nori-format test files and their meshes (run from this folder).

- ttest-lambert.xml: a diffuse floor (albedo 0.5) under five polygonal lights of radiance 3,
  one per scene, each seen at one floor point by a 1x1 camera; references from Lambert's
  polygon formula (irradiance E = L/2 sum_k theta_k (g_k . n), radiance 0.5 / pi * E). The
  scenes name Nori's path_mis, as course test scenes do: only direct light exists in them.
- ttest-furnace.xml: a camera inside a closed box that emits 1 and reflects with albedo a:
  the direct illumination it sees is 1 + a (its own emission plus the reflected emission of
  the whole enclosure), one scene per direct strategy Nori names.
- ttest-albedo.xml: BSDF albedos at four incidence angles (diffuse: its reflectance; mirror: 1).
- chi2test-bsdfs.xml: Nori's BSDFs (diffuse, microfacet) sampled against their pdfs.
The Rust test noritest::tests recomputes the Lambert references with directlab's analytic
module, so a wrong number here fails there.
"""
import math

L, ALBEDO = 3.0, 0.5
LUM = (0.212671, 0.715160, 0.072169)


def sub(a, b): return [a[i] - b[i] for i in range(3)]
def dot(a, b): return sum(a[i] * b[i] for i in range(3))
def cross(a, b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
def norm(a): return math.sqrt(dot(a, a))


def newell(v):
    n = [0.0, 0.0, 0.0]
    for k in range(len(v)):
        c = cross(v[k], v[(k + 1) % len(v)])
        n = [n[i] + c[i] for i in range(3)]
    return n


def facing_origin(v):
    """The outline wound so that its normal (right-hand rule) faces the origin."""
    return v if dot(newell(v), sub([0, 0, 0], v[0])) > 0 else v[::-1]


def irradiance(v, x=(0, 0, 0), n=(0, 1, 0)):
    s = 0.0
    for k in range(len(v)):
        a, b = sub(v[k], x), sub(v[(k + 1) % len(v)], x)
        c = cross(a, b)
        s += math.atan2(norm(c), dot(a, b)) * dot(c, n) / norm(c)
    return -0.5 * L * s


def write_obj(name, verts, tris):
    with open(f"meshes/{name}", "w") as f:
        for p in verts:
            f.write("v %.9g %.9g %.9g\n" % tuple(p))
        for t in tris:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t))


def fan(n):
    return [(0, k, k + 1) for k in range(1, n - 1)]


def oriented(v, tris):
    """Triangles wound as the outline's normal (flipped where the outline was reversed)."""
    out = []
    for t in tris:
        a, b, c = (v[i] for i in t)
        out.append(t if dot(cross(sub(b, a), sub(c, a)), newell(v)) > 0 else t[::-1])
    return out


pentagon = [[0.5 + math.cos(2 * math.pi * k / 5), 2.0, 0.5 + math.sin(2 * math.pi * k / 5)]
            for k in range(5)]
lights = {
    "triangle": ([[-0.5, 1, -0.2], [0.6, 1, 0.1], [0.0, 1, 0.8]], None),
    "square": ([[0.3, 0.7, -0.5], [1.3, 0.7, -0.5], [1.3, 0.7, 0.5], [0.3, 0.7, 0.5]], None),
    "tilted": ([[-1, 0.5, -1], [-1, 1.5, -1.4], [1, 1.5, -1.4], [1, 0.5, -1]], None),
    "pentagon": (pentagon, None),
    # Not convex: the outline for Lambert, two rectangles' triangles for the mesh.
    "l-shape": ([[-0.6, 1.2, -0.6], [0.6, 1.2, -0.6], [0.6, 1.2, -0.1], [-0.1, 1.2, -0.1],
                 [-0.1, 1.2, 0.6], [-0.6, 1.2, 0.6]],
                [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]),
}

SCENE = """
\t<scene>
\t\t<integrator type="{integrator}"/>
\t\t<camera type="perspective">
\t\t\t<transform name="toWorld">
\t\t\t\t<lookat origin="{origin}" target="{target}" up="{up}"/>
\t\t\t</transform>
\t\t\t<float name="fov" value="1e-3"/>
\t\t\t<integer name="width" value="1"/>
\t\t\t<integer name="height" value="1"/>
\t\t</camera>
{shapes}\t</scene>
"""

MESH = """\t\t<mesh type="obj">
\t\t\t<string name="filename" value="meshes/{file}"/>
\t\t\t<bsdf type="diffuse"><color name="albedo" value="{albedo}"/></bsdf>
{emitter}\t\t</mesh>
"""
EMITTER = '\t\t\t<emitter type="area"><color name="radiance" value="{r}"/></emitter>\n'

write_obj("floor.obj", [[-20, 0, -20], [-20, 0, 20], [20, 0, 20], [20, 0, -20]],
          [(0, 1, 2), (0, 2, 3)])
refs, scenes = [], []
for name, (outline, tris) in lights.items():
    v = facing_origin(outline)
    if tris is None:
        tris = fan(len(v))
    elif v is not outline:
        tris = [tuple(len(v) - 1 - i for i in t) for t in tris]
    write_obj(f"light-{name}.obj", v, oriented(v, tris))
    refs.append(ALBEDO / math.pi * irradiance(v))
    shapes = MESH.format(file="floor.obj", albedo=f"{ALBEDO} {ALBEDO} {ALBEDO}", emitter="")
    shapes += MESH.format(file=f"light-{name}.obj", albedo="0 0 0",
                          emitter=EMITTER.format(r=f"{L} {L} {L}"))
    scenes.append(f"\t<!-- light: {name} -->" + SCENE.format(
        integrator="path_mis", origin="0, 0.01, 0", target="0, 0, 0", up="0, 0, 1",
        shapes=shapes))
with open("ttest-lambert.xml", "w") as f:
    f.write('<?xml version="1.0" encoding="utf-8"?>\n<!-- Written by make_tests.py. -->\n')
    f.write('<test type="ttest">\n')
    f.write('\t<string name="references" value="%s"/>\n' % " ".join("%.9g" % r for r in refs))
    f.write("".join(scenes))
    f.write("</test>\n")

# A closed box, normals inward (every face's triangles wound to face the centre).
c = [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
box = []
for q in faces:
    for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3])):
        a, b, d = (c[i] for i in t)
        inward = dot(cross(sub(b, a), sub(d, a)), sub([0, 0, 0], a)) > 0
        box.append(t if inward else t[::-1])
write_obj("box.obj", c, box)
furnace = []
refs = []
for integrator, a in (("direct_ems", 0.6), ("direct_mats", 0.3), ("direct_mis", 0.8)):
    shapes = MESH.format(file="box.obj", albedo=f"{a} {a} {a}", emitter=EMITTER.format(r="1 1 1"))
    furnace.append(SCENE.format(integrator=integrator, origin="0.1, -0.2, 0",
                                target="0.1, -0.2, 1", up="0, 1, 0", shapes=shapes))
    refs.append(1 + a)
with open("ttest-furnace.xml", "w") as f:
    f.write('<?xml version="1.0" encoding="utf-8"?>\n<!-- Written by make_tests.py. -->\n')
    f.write('<test type="ttest">\n')
    f.write('\t<string name="references" value="%s"/>\n' % " ".join("%.9g" % r for r in refs))
    f.write("".join(furnace))
    f.write("</test>\n")

angles = [0, 30, 60, 85]
colour = (0.2, 0.5, 0.8)
albedo_refs = [0.5] * 4 + [sum(LUM[i] * colour[i] for i in range(3))] * 4 + [1.0] * 4
with open("ttest-albedo.xml", "w") as f:
    f.write('<?xml version="1.0" encoding="utf-8"?>\n<!-- Written by make_tests.py. -->\n')
    f.write('<test type="ttest">\n')
    f.write('\t<string name="angles" value="%s"/>\n' % " ".join(map(str, angles)))
    f.write('\t<string name="references" value="%s"/>\n'
            % " ".join("%.9g" % r for r in albedo_refs))
    f.write('\t<integer name="sampleCount" value="10000"/>\n')
    f.write('\t<bsdf type="diffuse"><color name="albedo" value="0.5 0.5 0.5"/></bsdf>\n')
    f.write('\t<bsdf type="diffuse"><color name="albedo" value="%g %g %g"/></bsdf>\n' % colour)
    f.write('\t<bsdf type="mirror"/>\n')
    f.write("</test>\n")

with open("chi2test-bsdfs.xml", "w") as f:
    f.write('<?xml version="1.0" encoding="utf-8"?>\n<!-- Written by make_tests.py. -->\n')
    f.write('<test type="chi2test">\n')
    f.write('\t<integer name="testCount" value="3"/>\n')
    f.write('\t<bsdf type="diffuse"/>\n')
    for alpha in (0.1, 0.4):
        f.write('\t<bsdf type="microfacet"><float name="alpha" value="%g"/>'
                '<color name="kd" value="0.3 0.3 0.3"/></bsdf>\n' % alpha)
    f.write("</test>\n")
