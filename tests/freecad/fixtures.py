"""Document fixtures shared by the headless FreeCAD tests and the GUI smoke test."""

import FreeCAD


def box_with_hole(doc):
    """A 4 x 4 x 2 Part::Box minus a radius-1 Part::Cylinder through its centre (Part::Cut)."""
    box = doc.addObject("Part::Box", "Box")
    box.Length, box.Width, box.Height = 4, 4, 2
    cyl = doc.addObject("Part::Cylinder", "Cylinder")
    cyl.Radius, cyl.Height = 1, 2
    cyl.Placement.Base = FreeCAD.Vector(2, 2, 0)
    cut = doc.addObject("Part::Cut", "Cut")
    cut.Base, cut.Tool = box, cyl
    doc.recompute()
    return cut
