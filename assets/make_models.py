#!/usr/bin/env python3
"""Generates the seed report's models as .bpt patch files, and the scroll's painting.

Run from this folder: `python3 make_models.py`. Standard library only; the outputs are
committed, so nothing runs this at build or test time.

- leaf.bpt: a leaf from two bicubic patches meeting along the midrib, the tip collapsed to a
  point (a pole), the blade arched along its length and drooping towards its edges.
- scroll.bpt, scroll_rollers.bpt: an unrolled hand scroll: the sheet (one patch, textured with
  the painting through its own (u,v)) and two wooden rollers, cylinders of four quarter-circle
  patches each.
- hairpin.bpt, hairpin_bead.bpt: a hairpin: a tapered, gently curved stick of 8 patches ending
  in a point, and a bead of 8 octant patches (surfaces of revolution) at its head.
- painting.png: a small procedural landscape (sky, sun, mountains, water) for the scroll.
"""
import math
import struct
import zlib

K = 4.0 / 3.0 * math.tan(math.pi / 8.0)  # cubic Bézier quarter-circle handle length


def write_bpt(path, patches):
    with open(path, "w") as f:
        f.write(f"{len(patches)}\n")
        for p in patches:
            assert len(p) == 16
            f.write("3 3\n")
            for x, y, z in p:
                f.write(f"{x:.6f} {y:.6f} {z:.6f}\n")


def leaf():
    xs = [0.0, 1.3, 2.7, 4.0]
    arch = [0.0, 0.35, 0.35, 0.0]
    width = [0.15, 1.45, 1.05, 0.0]
    patches = []
    for side in (1.0, -1.0):
        p = []
        for i in range(4):  # u: stem to tip
            for j in range(4):  # v: midrib to edge
                f = j / 3.0
                x = xs[i] + 0.25 * f * (1.0 if i in (1, 2) else 0.0)
                y = side * width[i] * f
                z = arch[i] - 0.3 * f * f * (1.0 if i < 3 else 0.0)
                p.append((x, y, z))
        patches.append(p)
    return patches


def quarter_arcs(radius):
    """Four quarter circles in (a, b) as cubic control polygons, counter-clockwise from +a."""
    arcs = []
    for q in range(4):
        a0 = q * math.pi / 2.0
        c0, s0 = math.cos(a0), math.sin(a0)
        c1, s1 = math.cos(a0 + math.pi / 2.0), math.sin(a0 + math.pi / 2.0)
        arcs.append([
            (radius * c0, radius * s0),
            (radius * (c0 - K * s0), radius * (s0 + K * c0)),
            (radius * (c1 + K * s1), radius * (s1 - K * c1)),
            (radius * c1, radius * s1),
        ])
    return arcs


def scroll():
    half_len, half_h, lift = 3.0, 1.2, 0.3
    sheet = []
    for i in range(4):  # u along the scroll's length
        x = -half_len + 2.0 * half_len * i / 3.0
        for j in range(4):  # v across its height
            y = -half_h + 2.0 * half_h * j / 3.0
            z = lift + 0.04 * math.sin(math.pi * i / 3.0)
            sheet.append((x, y, z))
    patches = [sheet]
    for cx in (-half_len - 0.3, half_len + 0.3):
        for arc in quarter_arcs(0.3):
            p = []
            for a, b in arc:  # u around the roller
                for j in range(4):  # v along its axis (y)
                    y = -(half_h + 0.15) + 2.0 * (half_h + 0.15) * j / 3.0
                    p.append((cx + a, y, b))
            patches.append(p)
    return patches


def hairpin():
    patches = []
    # Stick: along +x from the head (x = 0) to the tip (x = 6), tapering, curving up in z.
    def centre(t):
        return (6.0 * t, 0.0, 0.5 * t * t)

    def radius(t):
        return 0.12 * (1.0 - t) ** 0.8

    for seg in range(2):
        ts = [seg / 2.0 + k / 6.0 for k in range(4)]
        for arc in quarter_arcs(1.0):
            p = []
            for a, b in arc:
                for t in ts:
                    cx, cy, cz = centre(t)
                    r = radius(t) if t < 1.0 else 0.0
                    p.append((cx, cy + r * a, cz + r * b))
            patches.append(p)
    # Bead: an ellipsoid of revolution around x at the head, 8 octants.
    rx, rr, x0 = 0.45, 0.38, -0.35
    meridian = [(1.0, 0.0), (1.0, K), (K, 1.0), (0.0, 1.0)]  # (radial, axial) quarter circle
    for hemi in (1.0, -1.0):
        for arc in quarter_arcs(1.0):
            p = []
            for a, b in arc:
                for radial, axial in meridian:
                    p.append((x0 + hemi * rx * axial, rr * radial * a, rr * radial * b))
            patches.append(p)
    return patches


def painting(w=384, h=192):
    rows = []
    for y in range(h):
        row = bytearray([0])  # PNG filter: none
        for x in range(w):
            u, v = x / (w - 1), 1.0 - y / (h - 1)
            # Sky gradient, a sun, layered mountains, water.
            r, g, b = 0.95 - 0.35 * v, 0.85 - 0.25 * v, 0.7 + 0.2 * v
            if (u - 0.75) ** 2 + ((v - 0.78) * 2.0) ** 2 < 0.004:
                r, g, b = 0.95, 0.45, 0.2
            m1 = 0.55 + 0.12 * math.sin(9.0 * u) + 0.06 * math.sin(23.0 * u + 1.0)
            m2 = 0.42 + 0.08 * math.sin(6.0 * u + 2.0) + 0.04 * math.sin(31.0 * u)
            if v < m1:
                r, g, b = 0.45, 0.5, 0.55
            if v < m2:
                r, g, b = 0.2, 0.3, 0.25
            if v < 0.25:
                shade = 0.5 + 0.5 * math.sin(60.0 * v + 8.0 * u)
                r, g, b = 0.25 + 0.1 * shade, 0.4 + 0.1 * shade, 0.55 + 0.1 * shade
            row += bytes(int(max(0.0, min(1.0, c)) * 255 + 0.5) for c in (r, g, b))
        rows.append(bytes(row))
    raw = b"".join(rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open("painting.png", "wb") as f:
        f.write(png)


if __name__ == "__main__":
    write_bpt("leaf.bpt", leaf())
    sc = scroll()
    write_bpt("scroll.bpt", sc[:1])
    write_bpt("scroll_rollers.bpt", sc[1:])
    hp = hairpin()
    write_bpt("hairpin.bpt", hp[:8])
    write_bpt("hairpin_bead.bpt", hp[8:])
    painting()
