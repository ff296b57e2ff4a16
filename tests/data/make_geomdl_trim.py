#!/usr/bin/env python3
"""Writes tests/data/geomdl_trim.obj and geomdl_trim_points.txt: a trimmed rational B-spline
surface whose points and trim curves are evaluated by geomdl 5.4 (pip install geomdl), an
evaluator independent of caustic's. The surface is rational, degree 2 along u and 3 along v
with uneven knots and weights; its outer trim loop is a rational cubic B-spline (closed, uneven
weights), read backwards, and its hole a rational quadratic circle. The OBJ is written here from
geomdl's own control points, weights and knots; the points file holds geomdl's evaluation of the
surface (`s u v x y z`) and of the trim curves (`t LOOP u v`, LOOP 0 the outer loop, 1 the hole).
Run from the project folder: python3 tests/data/make_geomdl_trim.py"""
import math

from geomdl import NURBS

surface = NURBS.Surface()
surface.degree_u, surface.degree_v = 2, 3
nu, nv = 5, 6
points, weights = [], []
for i in range(nu):
    for j in range(nv):
        x, y = 0.5 * i, 0.4 * j
        z = 0.3 * math.sin(1.3 * x + 0.4) * math.cos(1.1 * y - 0.2)
        w = 1.0 + 0.35 * math.sin(2.0 * i + 3.0 * j)
        points.append([x, y, z])
        weights.append(w)
# geomdl's control points are listed with v varying fastest (i along u, j along v).
surface.ctrlpts_size_u, surface.ctrlpts_size_v = nu, nv
surface.ctrlptsw = [[p[0] * w, p[1] * w, p[2] * w, w] for p, w in zip(points, weights)]
surface.knotvector_u = [0, 0, 0, 0.3, 0.55, 1, 1, 1]
surface.knotvector_v = [0, 0, 0, 0, 0.4, 0.7, 1, 1, 1, 1]

# Outer loop: a closed rational cubic B-spline (first and last points equal, clamped).
outer_pts = [(0.1, 0.5), (0.1, 0.1), (0.5, 0.05), (0.9, 0.1), (0.95, 0.5), (0.9, 0.9), (0.5, 0.95), (0.1, 0.9), (0.1, 0.5)]
outer_w = [1.0, 1.4, 0.8, 1.2, 1.0, 0.7, 1.3, 0.9, 1.0]
outer = NURBS.Curve()
outer.degree = 3
outer.ctrlptsw = [[u * w, v * w, w] for (u, v), w in zip(outer_pts, outer_w)]
outer.knotvector = [0, 0, 0, 0, 0.2, 0.3, 0.5, 0.6, 0.8, 1, 1, 1, 1]

# Hole: a circle of radius 0.12 about (0.55, 0.45) as a rational quadratic (weights 1, √½).
h = math.sqrt(0.5)
unit = [(1, 0, 1), (1, 1, h), (0, 1, 1), (-1, 1, h), (-1, 0, 1), (-1, -1, h), (0, -1, 1), (1, -1, h), (1, 0, 1)]
hole = NURBS.Curve()
hole.degree = 2
hole.ctrlptsw = [[(0.55 + 0.12 * a) * w, (0.45 + 0.12 * b) * w, w] for a, b, w in unit]
hole.knotvector = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]

lines = ["# geomdl 5.4.0 NURBS.Surface, degree 2x3, 5x6 control points, with two trim loops;",
         "# made by tests/data/make_geomdl_trim.py"]
# OBJ lists u fastest: vertex (i, j) at position i + nu j.
for j in range(nv):
    for i in range(nu):
        p, w = points[i * nv + j], weights[i * nv + j]
        lines.append("v %r %r %r %r" % (p[0], p[1], p[2], w))
for (u, v), w in zip(outer_pts, outer_w):
    lines.append("vp %r %r %r" % (u, v, w))
for a, b, w in unit:
    lines.append("vp %r %r %r" % (0.55 + 0.12 * a, 0.45 + 0.12 * b, w))
lines += ["cstype rat bspline", "deg 3", "curv2 " + " ".join(str(k) for k in range(1, 10)),
          "parm u " + " ".join(repr(k) for k in outer.knotvector), "end",
          "cstype rat bspline", "deg 2", "curv2 " + " ".join(str(k) for k in range(10, 19)),
          "parm u " + " ".join(repr(k) for k in hole.knotvector), "end",
          "cstype rat bspline", "deg 2 3",
          "surf 0 1 0 1 " + " ".join(str(k) for k in range(1, nu * nv + 1)),
          "parm u " + " ".join(repr(k) for k in surface.knotvector_u),
          "parm v " + " ".join(repr(k) for k in surface.knotvector_v),
          "trim 1 0 1", "hole 0 1 2", "end"]
open("tests/data/geomdl_trim.obj", "w").write("\n".join(lines) + "\n")

out = ["# s u v x y z: the surface at (u, v); t LOOP u v: trim loop LOOP at 200 parameters; by geomdl"]
for a in range(11):
    for b in range(11):
        u, v = a / 10, b / 10
        x, y, z = surface.evaluate_single((u, v))
        out.append("s %r %r %r %r %r" % (u, v, x, y, z))
for loop, curve in enumerate([outer, hole]):
    for k in range(200):
        u, v = curve.evaluate_single(k / 200)
        out.append("t %d %r %r" % (loop, u, v))
open("tests/data/geomdl_trim_points.txt", "w").write("\n".join(out) + "\n")
