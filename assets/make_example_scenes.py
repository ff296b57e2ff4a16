#!/usr/bin/env python3
"""Writes the Bézier-patch example scenes: scenes/pool.toml with assets/pool_water.obj (a
bicubic B-spline water surface, 11×11 control points, so 8×8 Bézier patches), scenes/ring.toml
with assets/ring.obj (a mirror ring: one rational B-spline cylinder), scenes/ring_gold.toml (the
ring in rough gold), scenes/ring_window.toml with assets/ring_window.obj (the ring trimmed by a
window), scenes/ring_usd.toml with assets/ring_window.usda (the same trimmed ring as an OpenUSD
NurbsPatch, with a Mesh tile and a Sphere marble), scenes/lens.toml (a biconvex lens of 2 patches), scenes/lens_dispersive.toml (the lens
in SF11 glass), and scenes/prism.toml with assets/prism.obj (a dispersive prism).
Run from the project folder: python3 assets/make_example_scenes.py"""
import math



def fmt(v):
    return "%.6g" % v


def exact(v):
    """15 significant digits (every digit of the geometry; rounding noise below 1e-15 is 0)."""
    return "0" if abs(v) < 1e-15 else "%.15g" % v


def point(p, digits=fmt):
    return "[" + ", ".join(digits(c) for c in p) + "]"


def patch_toml(points, digits=fmt):
    """16 points, row i (along u) of four points (along v) per line."""
    rows = [", ".join(point(points[4 * i + j], digits) for j in range(4)) for i in range(4)]
    return "[\n    " + ",\n    ".join(rows) + ",\n]"


# --- pool: gentle waves as a uniform bicubic B-spline, 11 x 11 control points 0.6 apart ---
n = 11
heights = []
for j in range(n):
    for i in range(n):
        x, z = -3 + 0.6 * i, -3 + 0.6 * j
        h = 1.7 * (0.16 * math.sin(3.3 * x + 0.7) * math.cos(2.9 * z - 0.4)
             + 0.12 * math.sin(2.6 * z + 1.7 * x + 0.5) + 0.08 * math.cos(3.7 * x - 2.2 * z))
        heights.append((x, h, z))
lines = ["# Gentle waves: a bicubic B-spline surface (11 x 11 control points, uniform knots),",
         "# 8 x 8 Bezier patches once read, over [-2.4, 2.4] in x and z.",
         "# Made by assets/make_example_scenes.py."]
for p in heights:
    lines.append("v %s %s %s" % tuple(fmt(c) for c in p))
lines += ["cstype bspline", "deg 3 3",
          # u runs along z (j), v along x (i), so dP/du x dP/dv = +z x +x = +y: up, out of
          # the water. OBJ lists u fastest: list position j + 11 i holds vertex (i, j).
          "surf 3 11 3 11 " + " ".join(str(1 + j * n + i) for i in range(n) for j in range(n)),
          "parm u " + " ".join(str(k) for k in range(n + 4)),
          "parm v " + " ".join(str(k) for k in range(n + 4)), "end"]
open("assets/pool_water.obj", "w").write("\n".join(lines) + "\n")

# --- lens: two pillow-shaped patches sharing their square boundary, in the plane x = 0 ---
def lens_patch(sign):
    pts = []
    for i in range(4):              # u along z
        for j in range(4):          # v along y
            y, z = -1 + 2 * j / 3, -1 + 2 * i / 3
            inner = 0 < i < 3 and 0 < j < 3
            pts.append((sign * 0.62 if inner else 0.0, y + 1.6, z))
    return pts

front = lens_patch(-1.0)   # faces the light (-x)
back = lens_patch(1.0)
# Normal = dP/du x dP/dv = +z x +y = -x for this order: right for the front; the back's rows
# are reversed (u runs down) so that its normal faces +x, out of the glass.
back = [back[4 * (3 - i) + j] for i in range(4) for j in range(4)]

HEADER = "# Made by assets/make_example_scenes.py; edit that script, not this file, to change the\n# geometry (or edit the control points in the viewer and save).\n"

open("scenes/pool.toml", "w").write(HEADER + """# A pool at noon: gentle waves (a bicubic B-spline surface from assets/pool_water.obj, read as
# 8 x 8 Bezier patches of water, ior 1.33) over a tiled floor, lit by a small distant sphere
# light. Each wave crest focuses the light: the floor shows the familiar network of bright
# lines. Drag a wave's control point in the viewer and the network follows.

[camera]
position = [0.0, 4.2, 5.4]
look_at = [0.0, -1.2, -0.2]
fov = 42
width = 640
height = 480

[render]
renderer = "ppm"
photons_per_pass = 400000
max_depth = 10

[materials.water]
type = "glass"
ior = 1.33
color = [0.85, 0.95, 1.0]

[materials.tiles]
type = "diffuse"
texture = { checker = [[0.8, 0.86, 0.88], [0.62, 0.74, 0.82]], mapping = "planar", normal = [0, 1, 0], scale = 2.0 }

[materials.wall]
type = "diffuse"
color = [0.55, 0.75, 0.85]

[[lights]]
type = "sphere"
center = [1.5, 9.0, -3.0]
radius = 0.12
power = 3500

[[objects]]
type = "patches"
name = "water"
file = "../assets/pool_water.obj"
material = "water"

[[objects]]
type = "quad"
name = "floor"
corner = [-2.4, -1.5, -2.4]
edge_u = [0, 0, 4.8]
edge_v = [4.8, 0, 0]
material = "tiles"

[[objects]]
type = "quad"
name = "back wall"
corner = [-2.4, -1.5, -2.4]
edge_u = [4.8, 0, 0]
edge_v = [0, 1.7, 0]
material = "wall"

[[objects]]
type = "quad"
name = "left wall"
corner = [-2.4, -1.5, -2.4]
edge_u = [0, 1.7, 0]
edge_v = [0, 0, 4.8]
material = "wall"

[[objects]]
type = "quad"
name = "right wall"
corner = [2.4, -1.5, -2.4]
edge_u = [0, 0, 4.8]
edge_v = [0, 1.7, 0]
material = "wall"

[[objects]]
type = "quad"
name = "front wall"
corner = [-2.4, -1.5, 2.4]
edge_u = [0, 1.7, 0]
edge_v = [4.8, 0, 0]
material = "wall"
""")



def ring_scene(path, about, name, material, ring_object):
    """The ring on its table under its lamp, with `about` as its comment, the material table
    `material` of the ring, named `name`, and the ring's object table `ring_object` (%s: the
    material's name)."""
    open(path, "w").write(HEADER + about + """
[camera]
position = [0.0, 4.0, 1.6]
look_at = [0.0, 0.0, 0.05]
fov = 40
width = 640
height = 480

[render]
renderer = "ppm"
photons_per_pass = 400000

[materials.""" + name + """]
""" + material + """

[materials.table]
type = "diffuse"
color = [0.45, 0.4, 0.35]

[[lights]]
type = "point"
position = [4.0, 1.6, 0.8]
power = 1100

[[objects]]
type = "plane"
name = "table"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "table"

""" + ring_object % name)


RING_FILE = """# One rational B-spline surface (u up the wall, v around: exactly round), as CAD programs
# write a cylinder.
[[objects]]
type = "patches"
name = "ring"
material = "%s"
file = "../assets/ring.obj"
"""
ring_scene("scenes/ring.toml", """# The coffee-cup caustic: a mirror ring (a cylinder read from assets/ring.obj as one rational
# B-spline surface, exactly round) on a table, lit by a point light low and off to one side.
# Light reflected inside the ring gathers into a cardioid-like cusp on the table. Drag the
# ring's control points (its own NURBS net) to bend the cusp.
""", "mirror", """type = "mirror"
color = [0.95, 0.9, 0.8]""", RING_FILE)
ring_scene("scenes/ring_gold.toml", """# The coffee-cup caustic from a ring of brushed gold: the same ring as ring.toml, its metal
# rough (GGX roughness 0.08), so that the cusp it casts is soft and golden and the ring itself
# glossy.
""", "gold", """type = "metal"
conductor = "gold"
roughness = 0.08""", RING_FILE)

def lens_scene(path, about, glass):
    open(path, "w").write(HEADER + about + """
[camera]
position = [-2.2, 3.0, 5.0]
look_at = [1.0, 1.3, 0.0]
fov = 45
width = 640
height = 480

[render]
renderer = "ppm"
photons_per_pass = 300000
max_depth = 10

[materials.glass]
type = "glass"
""" + glass + """

[materials.wall]
type = "diffuse"
color = [0.8, 0.8, 0.8]

[materials.floor]
type = "diffuse"
color = [0.5, 0.45, 0.4]

[[lights]]
type = "spot"
position = [-4.0, 1.6, 0.0]
direction = [1, 0, 0]
cone_angle = 22
power = 400

[[lights]]
type = "point"
position = [-1.0, 4.5, 3.0]
power = 60

[[objects]]
type = "plane"
name = "wall"
point = [2.5, 0, 0]
normal = [-1, 0, 0]
material = "wall"

[[objects]]
type = "plane"
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

# The face towards the light, then the back; each line one row of four control points.
[[objects]]
type = "patches"
name = "lens"
material = "glass"
patches = [
""" + patch_toml(front) + ",\n" + patch_toml(back) + """,
]
""")


lens_scene("scenes/lens.toml", """# A biconvex glass lens (two bicubic patches sharing their square rim) in front of a spot
# light: the light is focused to a bright point on the wall behind it. Drag the lens's inner
# control points to change its power and watch the spot sharpen or blur.
""", "ior = 1.5")
lens_scene("scenes/lens_dispersive.toml", """# The lens of lens.toml in dense flint glass (SF11, whose index falls from 1.85 at 400 nm to
# 1.77 at 700 nm): blue light is bent more and comes to a focus nearer the lens than red, so
# the spot on the wall is ringed with colour (chromatic aberration).
""", 'glass = "SF11"')

# --- prism: an equilateral SF11 prism lit by a narrow beam at minimum deviation ---
SIDE, CENTRE_Y, HALF_LENGTH = 0.9, 3.3, 0.5
h = SIDE * math.sqrt(3) / 2
tri = [(-SIDE / 2, CENTRE_Y - h / 3), (SIDE / 2, CENTRE_Y - h / 3), (0.0, CENTRE_Y + 2 * h / 3)]
verts = [(x, y, z) for z in (HALF_LENGTH, -HALF_LENGTH) for (x, y) in tri]
# Counter-clockwise seen from outside, so that each face's normal points out of the glass.
faces = [(1, 2, 3), (4, 6, 5), (1, 4, 5), (1, 5, 2), (2, 5, 6), (2, 6, 3), (3, 6, 4), (3, 4, 1)]
open("assets/prism.obj", "w").write(
    "# An equilateral triangular prism (side %g, length %g), apex up; made by make_example_scenes.py\n"
    % (SIDE, 2 * HALF_LENGTH)
    + "".join("v %s %s %s\n" % tuple(fmt(c) for c in v) for v in verts)
    + "".join("f %d %d %d\n" % f for f in faces))
# SF11's index at 587.56 nm gives the angle of incidence of minimum deviation, the beam
# inside then running parallel to the base.
N_D, APEX = 1.78472, math.radians(60)
incidence = math.asin(N_D * math.sin(APEX / 2))
# The left face's inward normal points 30° below +x; the beam rises at the incidence less that.
rise = incidence - APEX / 2
beam = (math.cos(rise), math.sin(rise), 0.0)
face_mid = ((tri[0][0] + tri[2][0]) / 2, (tri[0][1] + tri[2][1]) / 2, 0.0)
spot = tuple(face_mid[k] - 3.0 * beam[k] for k in range(3))
open("scenes/prism.toml", "w").write(HEADER + """# White light through a glass prism: a narrow beam from a spot light enters an equilateral
# prism of dense flint glass (SF11) at the angle of least deviation and leaves spread into its
# colours, violet bent most, which fall on the wall as a spectrum. A dim lamp above shows the
# room.

[camera]
position = [0.6, 1.9, 3.8]
look_at = [1.7, 2.1, 0.0]
fov = 62
width = 640
height = 480

[render]
renderer = "ppm"
photons_per_pass = 300000
max_depth = 10

[materials.prism]
type = "glass"
glass = "SF11"
color = [1, 1, 1]

[materials.wall]
type = "diffuse"
color = [0.8, 0.8, 0.8]

[materials.floor]
type = "diffuse"
color = [0.45, 0.42, 0.4]

[[lights]]
type = "spot"
position = """ + point(spot) + """
direction = """ + point(beam) + """
cone_angle = 0.8
cone_falloff = 0.2
power = 2.5

[[lights]]
type = "point"
position = [-1.0, 5.0, 4.0]
power = 250

[[objects]]
type = "plane"
name = "wall"
point = [3.5, 0, 0]
normal = [-1, 0, 0]
material = "wall"

[[objects]]
type = "plane"
name = "back wall"
point = [0, 0, -3.0]
normal = [0, 0, 1]
material = "wall"

[[objects]]
type = "plane"
name = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

[[objects]]
type = "mesh"
name = "prism"
file = "../assets/prism.obj"
material = "prism"
""")

# --- ring_window: the ring as a trimmed NURBS, a window cut through its wall towards the lamp ---
# The cylinder is one rational B-spline surface (u up the wall, degree 1; v around, degree 2 with
# 9 points, weights 1 and sqrt(1/2), knots 0 0 0 1 1 2 2 3 3 4 4 4), as CAD programs write it.
# The window is a hole: an ellipse in (u, v) (the rational circle scaled, which is exact) that
# is about round on the wall, 0.3 across, centred 11 degrees round from +x at mid-height.
h = math.sqrt(0.5)
circle = [(1, 0, 1), (1, 1, h), (0, 1, 1), (-1, 1, h), (-1, 0, 1), (-1, -1, h), (0, -1, 1), (1, -1, h), (1, 0, 1)]
lines = ["# The mirror ring of ring.toml as one trimmed rational B-spline surface with a round window",
         "# cut through its wall. Made by assets/make_example_scenes.py."]
for (x, z, w) in circle:
    for y in (0.0, 0.6):
        lines.append("v %s %s %s %s" % (exact(x), exact(y), exact(z), exact(w)))
SURFACE = ["cstype rat bspline", "deg 1 2", "surf 0 1 0 4 " + " ".join(str(k) for k in range(1, 19)),
           "parm u 0 0 1 1", "parm v 0 0 0 1 1 2 2 3 3 4 4 4"]
open("assets/ring.obj", "w").write("\n".join(
    ["# The mirror ring of ring.toml: a cylinder of radius 1 and height 0.6 as one rational",
     "# B-spline surface (u up the wall, degree 1; v around, degree 2). Made by",
     "# assets/make_example_scenes.py."] + lines[2:] + SURFACE + ["end"]) + "\n")
centre_u, centre_v, radius_u, radius_v = 0.5, 11 / 90, 0.15 / 0.6, 0.15 / (math.pi / 2)
for (a, b, w) in circle:
    lines.append("vp %s %s %s" % (exact(centre_u + radius_u * a), exact(centre_v + radius_v * b), exact(w)))
lines += ["cstype rat bspline", "deg 2", "curv2 " + " ".join(str(k) for k in range(1, 10)),
          "parm u 0 0 0 1 1 2 2 3 3 4 4 4", "end",
          ] + SURFACE + ["hole 0 4 1", "end"]
open("assets/ring_window.obj", "w").write("\n".join(lines) + "\n")
ring_scene("scenes/ring_window.toml", """# The mirror ring with a window: the ring of ring.toml read as one trimmed NURBS surface
# (assets/ring_window.obj, a rational B-spline with a 'hole' loop), a round window cut through
# its wall on the lamp's side. Light through the window falls on the table inside the ring,
# and the cusp loses the light the cut-away wall would have sent it.
""", "mirror", """type = "mirror"
color = [0.95, 0.9, 0.8]""", """# One rational B-spline surface (u up the wall, v around) with a trim loop cutting the window.
[[objects]]
type = "patches"
name = "ring"
material = "%s"
file = "../assets/ring_window.obj"
""")

# --- ring_usd: the trimmed ring as OpenUSD writes it, with a Mesh and a Sphere beside it ---
# A NurbsPatch lists its points with u fastest (as OBJ does), its weights apart (not
# pre-weighted), orders (degree + 1) and full knot vectors. Its trim curves are homogeneous
# (u w, v w, w); USD has no hole flag, so the outer boundary of the domain is a loop of its own
# and the window, inside it, is a hole by the odd winding rule.
def usd_list(items):
    return "[" + ", ".join(items) + "]"


def usd_tuple(values):
    return "(" + ", ".join(exact(v) for v in values) + ")"


ring_points = [(x, y, z) for (x, z, w) in circle for y in (0.0, 0.6)]
ring_weights = [w for (x, z, w) in circle for y in (0.0, 0.6)]
window = [(centre_u + radius_u * a, centre_v + radius_v * b, w) for (a, b, w) in circle]
boundary = [(0, 0, 1), (1, 0, 1), (1, 4, 1), (0, 4, 1), (0, 0, 1)]
trim_points = boundary + [(u * w, v * w, w) for (u, v, w) in window]
open("assets/ring_window.usda", "w").write("""#usda 1.0
(
    doc = "The mirror ring of ring_window.obj as an OpenUSD NurbsPatch with its window as a trim
curve, a tile (Mesh) and a marble (Sphere) with display colours. Made by
assets/make_example_scenes.py."
    upAxis = "Y"
    metersPerUnit = 1
)

def Xform "World"
{
    def NurbsPatch "Ring"
    {
        int uVertexCount = 2
        int vVertexCount = 9
        int uOrder = 2
        int vOrder = 3
        double[] uKnots = [0, 0, 1, 1]
        double[] vKnots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
        double2 uRange = (0, 1)
        double2 vRange = (0, 4)
        point3f[] points = """ + usd_list(usd_tuple(p) for p in ring_points) + """
        double[] pointWeights = """ + usd_list(exact(w) for w in ring_weights) + """
        int[] trimCurve:counts = [1, 1]
        int[] trimCurve:orders = [2, 3]
        int[] trimCurve:vertexCounts = [5, 9]
        double[] trimCurve:knots = [0, 0, 1, 2, 3, 4, 4, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
        double2[] trimCurve:ranges = [(0, 4), (0, 4)]
        double3[] trimCurve:points = """ + usd_list(usd_tuple(p) for p in trim_points) + """
    }

    def Mesh "Tile"
    {
        int[] faceVertexCounts = [4]
        int[] faceVertexIndices = [0, 1, 2, 3]
        point3f[] points = [(1.05, 0.002, -0.75), (1.05, 0.002, -0.35), (1.45, 0.002, -0.35), (1.45, 0.002, -0.75)]
        color3f[] primvars:displayColor = [(0.15, 0.3, 0.7)]
        uniform token subdivisionScheme = "none"
    }

    def Sphere "Marble"
    {
        double radius = 0.15
        color3f[] primvars:displayColor = [(0.75, 0.12, 0.08)]
        double3 xformOp:translate = (1.3, 0.15, 1.0)
        uniform token[] xformOpOrder = ["xformOp:translate"]
    }
}
""")
ring_scene("scenes/ring_usd.toml", """# The mirror ring with a window, read from OpenUSD: assets/ring_window.usda holds the ring as a
# NurbsPatch prim (the rational B-spline of ring_window.obj, its window a trim curve), a blue
# tile (a Mesh prim) and a red marble (a Sphere prim), their colours from displayColor. The
# object below reads the whole file: the ring as its surface, the tile and the marble as
# objects of their own.
""", "mirror", """type = "mirror"
color = [0.95, 0.9, 0.8]""", """# The USD file's NurbsPatch surfaces take this object's material; its Mesh and Sphere prims
# become objects with their displayColor.
[[objects]]
type = "patches"
name = "ring"
material = "%s"
file = "../assets/ring_window.usda"
""")


# --- design: a glass slab whose flat top (4 x 4 bicubic patches, 13 x 13 control points once
# their shared edges are welded) `caustic design` shapes until the light draws a target below
def flat_patches(y):
    """4 x 4 flat patches over [-1.2, 1.2] in x and z at height y, facing +y (u along z, v
    along x: S_u x S_v = +z x +x = +y, out of the glass or water below)."""
    return [[((-12 + 6 * pj + 2 * j) / 10, y, (-12 + 6 * pi + 2 * i) / 10)
             for i in range(4) for j in range(4)] for pi in range(4) for pj in range(4)]


bottom = [(-1.2 + 0.8 * i, -0.15, -1.2 + 0.8 * j) for i in range(4) for j in range(4)]
open("scenes/design.toml", "w").write(HEADER + """# Designing a caustic: a glass slab under a point light, its top (`lens`: 4 x 4 flat bicubic
# patches, 13 x 13 control points once their shared edges are welded) shaped by `caustic design`
# or the viewer's Design panel until the light draws a target on the floor (`screen`). The
# camera looks straight down at the screen from between the slab and the screen, and its square
# image is exactly the screen's rectangle: a render compares with the target pixel for pixel
# (the target's top-left pixel is the screen's corner + edge_v). As it is, the flat slab lights
# the screen evenly. (The camera does not see the slab: Frame, in the Edit section, shows it.)
#   caustic design scenes/design.toml --surface lens --receiver screen \\
#     --target assets/design_smooth.png --refine 0 --out designed.toml

[camera]
position = [0.0, -0.3, 0.0]
look_at = [0.0, -1.5, 0.0]
up = [0, 0, -1]
fov = 90
width = 256
height = 256

[render]
renderer = "ppm"
photons_per_pass = 200000
# The ray tracer sees no caustics: a little ambient light shows it the screen.
ambient = [0.03, 0.03, 0.03]

[materials.glass]
type = "glass"
ior = 1.5

[materials.screen]
type = "diffuse"
color = [0.8, 0.8, 0.8]

[[lights]]
type = "point"
position = [0.0, 6.0, 0.0]
power = 600

[[objects]]
type = "patches"
name = "lens"
material = "glass"
patches = [""" + ", ".join(patch_toml(q) for q in flat_patches(0.0)) + """]

# The slab's flat bottom, 0.15 below, facing down (out of the glass).
[[objects]]
type = "patches"
name = "slab bottom"
material = "glass"
patches = [""" + patch_toml(bottom) + """]

[[objects]]
type = "quad"
name = "screen"
corner = [-1.2, -1.5, 1.2]
edge_u = [2.4, 0, 0]
edge_v = [0, 0, -2.4]
material = "screen"
""")


def write_grey_png(path, width, height, value):
    """An 8-bit grey PNG of `value(x, y)` in [0, 1], row 0 at the top."""
    import struct
    import zlib
    rows = b"".join(b"\0" + bytes(max(0, min(255, round(255 * value(x, y)))) for x in range(width))
                    for y in range(height))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    open(path, "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                           + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def smooth_target(x, y):
    """Two soft spots and a faint floor: a smooth target for the designer."""
    u, v = (x + 0.5) / 64, (y + 0.5) / 64
    spot = lambda cu, cv, r: math.exp(-((u - cu) ** 2 + (v - cv) ** 2) / (2 * r * r))
    return 0.12 + 0.85 * spot(0.33, 0.36, 0.12) + 0.55 * spot(0.68, 0.66, 0.09)


write_grey_png("assets/design_smooth.png", 64, 64, smooth_target)


# --- design_pool: still water of 4 x 4 flat patches (13 x 13 welded points) over a floor ---
water = flat_patches(0.0)
open("scenes/design_pool.toml", "w").write(HEADER + '# A still pool for `caustic design`: a flat water surface (4 x 4 bicubic patches, 13 x 13\n# control points once their shared edges are welded) over a floor named "screen", lit by a\n# point light above. Flat, the water lights the floor evenly; the README\'s command shapes it\n# until the light draws assets/design_target.png (a "C"), as does the viewer\'s Design panel:\n#   caustic design scenes/design_pool.toml --surface water --receiver screen \\\n#     --target assets/design_target.png --refine 0 --out designed.toml\n\n[camera]\nposition = [0.0, -0.45, 2.3]\nlook_at = [0.0, -1.5, -0.1]\nfov = 55\nwidth = 480\nheight = 360\n\n[render]\nrenderer = "ppm"\nphotons_per_pass = 300000\n# The ray tracer sees no caustics: a little ambient light shows it the floor.\nambient = [0.03, 0.03, 0.03]\n\n[materials.water]\ntype = "glass"\nior = 1.33\n\n[materials.floor]\ntype = "diffuse"\ncolor = [0.8, 0.8, 0.8]\n\n[[lights]]\ntype = "point"\nposition = [0.0, 6.0, 0.0]\npower = 600\n\n' + """[[objects]]
type = "patches"
name = "water"
material = "water"
patches = [""" + ", ".join(patch_toml(q) for q in water) + """]

""" + '[[objects]]\ntype = "quad"\nname = "screen"\ncorner = [-1.2, -1.5, 1.2]\nedge_u = [2.4, 0, 0]\nedge_v = [0, 0, -2.4]\nmaterial = "floor"\n')
