"""Shapes the benches build with FreeCAD (freecadcmd), shared between them: each a script
that defines `dom`, the solid (or compound of solids) to mesh, with `V` = FreeCAD.Vector and
`Part` imported."""

# The wing: NACA 0012 sections lofted from the root (chord 1, on the box's symmetry face
# z = 0) to the tip (chord 0.5, z = 4, leading edge swept 30 degrees), the tip capped flat, in a
# box 20 chords long; BLUNT: the open trailing edge (0.25 % of the chord) as a face of its own.
WING = """import math
BLUNT = %s
def section(chord, x0, z, n=40):
    a4 = -0.1015 if BLUNT else -0.1036
    yt = lambda x: 0.6 * (0.2969 * math.sqrt(x) - 0.126 * x - 0.3516 * x * x + 0.2843 * x ** 3
                          + a4 * x ** 4)
    xs = [0.5 * (1 - math.cos(math.pi * i / n)) for i in range(n + 1)]
    pts = [V(x0 + chord * x, chord * yt(x), z) for x in reversed(xs)]
    pts += [V(x0 + chord * x, -chord * yt(x), z) for x in xs[1:]]
    if not BLUNT:
        pts[-1] = pts[0]
    curve = Part.BSplineCurve()
    curve.interpolate(pts)
    edges = [curve.toShape()]
    if BLUNT:
        edges.append(Part.LineSegment(pts[-1], pts[0]).toShape())
    return Part.Wire(edges)
sweep = 4 * math.tan(math.radians(30))
wing = Part.makeLoft([section(1.0, 0.0, 0.0), section(0.5, sweep, 4.0)], True)
dom = Part.makeBox(20, 10, 8, V(-5, -5, 0)).cut(wing)
inside = lambda c: -4 < c.x < 14 and abs(c.y) < 4 and 0 < c.z < 7
"""

# The wing-body junction: the wing above (blunt or sharp by BLUNT) through the side of a
# cylindrical fuselage (radius 0.4, from x = -1.5 to 3.5, hemispherical ends) whose axis lies in
# the symmetry face, so that the half body in the box meets the wing at a concave junction all
# round the root. The layer on every face of the body and the wing.
WING_BODY = WING + """fuselage = Part.makeCylinder(0.4, 5.0, V(-1.5, 0, 0), V(1, 0, 0))
fuselage = fuselage.fuse(Part.makeSphere(0.4, V(-1.5, 0, 0))).fuse(Part.makeSphere(0.4, V(3.5, 0, 0)))
dom = Part.makeBox(20, 10, 8, V(-5, -5, 0)).cut(fuselage.fuse(wing).removeSplitter())
inside = lambda c: -4 < c.x < 14 and abs(c.y) < 4 and 0.01 < c.z < 7
"""

# The Ahmed body (SAE 840300) at length 1: 1 x 0.373 x 0.228 with its four front edges rounded
# (radius 0.096), the rear slant at 25 degrees (0.2126 long), on four cylindrical stilts (radius
# 0.015) 0.048 above the floor of a box 5.5 x 2.4 x 1.2; the layer on the body, not the stilts.
AHMED = """import math
L, W, H, R, C = 1.0, 0.373, 0.276, 0.096, 0.048
body = Part.makeBox(L, W, H - C, V(0, -W / 2, C))
body = body.makeFillet(R, [e for e in body.Edges if all(abs(v.X) < 1e-9 for v in e.Vertexes)])
dz, dx = 0.2126 * math.sin(math.radians(25)), 0.2126 * math.cos(math.radians(25))
slant = Part.makePolygon([V(L - dx, -W, H), V(L + 0.01, -W, H - dz - 0.01 * math.tan(math.radians(25))),
                          V(L + 0.01, -W, H + 0.1), V(L - dx, -W, H + 0.1), V(L - dx, -W, H)])
body = body.cut(Part.Face(slant).extrude(V(0, 2 * W, 0)))
for x in (0.16, 0.63):
    for y in (-0.1, 0.1):
        body = body.fuse(Part.makeCylinder(0.015, C + 0.01, V(x, y, 0)))
dom = Part.makeBox(5.5, 2.4, 1.2, V(-1.5, -1.2, 0)).cut(body.removeSplitter())
inside = lambda c: -0.01 < c.x < 1.01 and abs(c.y) < 0.2 and 0.047 < c.z < 0.3
"""
