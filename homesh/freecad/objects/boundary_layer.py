"""The BoundaryLayer document object: the faces (picked by selecting them), thickness, layers
and progression of a boundary layer; recomputing checks them and gives the first layer's
height. A HighOrderMesh whose BoundaryLayer property links to it grows, curves and splits it.
"""

import FreeCAD

from ..arguments import boundary_layer_arguments
from ..object_types import TYPE_BOUNDARY_LAYER
from ..properties import add_parameter_property
from .base import GuardedProxy


def make_boundary_layer(doc, part, faces, thickness, layers=None, progression=None,
                        name="BoundaryLayer", solids=None):
    """Adds a BoundaryLayer object on ``faces`` of ``part`` (FreeCAD's numbers, 1 for Face1, or
    names "Face1"; for a planar shape edges, named "Edge1"): ``thickness`` a length in the model's units or an expression of x, y, z
    (text), split into ``layers`` layers whose heights grow by ``progression`` from the wall
    (left out: the parameter table's defaults); ``solids`` (1 for Solid1), where a layer face
    lies between two solids of the shape, names the one it grows into.
    Link it from a HighOrderMesh's BoundaryLayer property. The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    BoundaryLayerProxy(obj)
    obj.Faces = (part, [f if isinstance(f, str) else "Face%d" % f for f in faces])
    obj.Thickness = str(thickness)
    if layers is not None:
        obj.Layers = layers
    if progression is not None:
        obj.Progression = progression
    if solids:
        obj.Solids = [int(s) for s in solids]
    return obj


class BoundaryLayerProxy(GuardedProxy):
    """Proxy of an App::FeaturePython holding a boundary layer's parameters; recomputing checks
    them and gives the first layer's height (for a constant thickness)."""

    Type = TYPE_BOUNDARY_LAYER

    @staticmethod
    def add_properties(obj):
        """Adds missing properties and makes the outputs read-only; safe to call again."""
        have = obj.PropertiesList
        if "Faces" not in have:
            obj.addProperty("App::PropertyLinkSub", "Faces", "Layer",
                            "Faces of the meshed shape that carry the layer (select them); for "
                            "a planar shape, its edges")
        if "Thickness" not in have:
            obj.addProperty("App::PropertyString", "Thickness", "Layer",
                            "Total thickness in the model's units, or an expression of x, y, z "
                            "such as 0.01+0.05*x")
        if "Solids" not in have:
            obj.addProperty("App::PropertyIntegerList", "Solids", "Layer",
                            "Where a layer face lies between two solids of the shape: the one "
                            "it grows into (1 for Solid1)")
        add_parameter_property(obj, "layers", "Layer")
        add_parameter_property(obj, "progression", "Layer")
        for prop, kind, doc in (
                ("FirstLayerHeight", "App::PropertyFloat",
                 "Height of the wall layer for a constant thickness (0 for an expression)"),
                ("Status", "App::PropertyString", "Summary, or why the parameters are wrong")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
            obj.setEditorMode(prop, 1)  # read-only

    def execute(self, obj):
        try:
            args = boundary_layer_arguments(obj)
            if not args["thickness"]:
                raise ValueError("%s: no Thickness given" % obj.Label)
        except ValueError as e:
            obj.FirstLayerHeight = 0.0
            obj.Status = "Failed: %s" % e
            FreeCAD.Console.PrintError("HOMesh: %s\n" % e)
            raise
        n, r, t = args["layers"], args["progression"], args["thickness"]
        first = 0.0
        if isinstance(t, float):
            first = t / n if r == 1.0 else t * (1.0 - r) / (1.0 - r ** n)
        obj.FirstLayerHeight = first
        obj.Status = ("%d faces of %s, thickness %s, %d layers, progression %g%s"
                      % (len(args["faces"]), obj.Faces[0].Label, t, n, r,
                         ", first layer %.4g" % first if first else ""))
