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
