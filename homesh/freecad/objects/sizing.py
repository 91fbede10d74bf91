"""The Sizing document object: the sizing octree's parameters for its ``Part`` (MinDelta,
MaxDelta, Eps, refinement spheres); recomputing predicts the element count. A HighOrderMesh
whose Sizing property links to it meshes with that octree.
"""

import FreeCAD

from ..arguments import cad_modes, sizing_arguments
from ..meshing import prediction_summary
from ..object_types import TYPE_SIZING
from ..properties import add_parameter_property
from .base import GuardedProxy


def make_sizing(doc, part, min_delta=None, max_delta=None, eps=None, name="Sizing"):
    """Adds a Sizing object for ``part`` (a document object with a Shape): the sizing octree's
    parameters and its predicted element count.

    Left out (None): the parameter table's defaults. ``min_delta`` / ``max_delta`` 0 mean
    automatic (max: bounding-box diagonal / 20; min: the smallest size the shape asks for, at
    most max / 20 and at least max / 200). Refinement spheres go in RefinementSpheres (centres), RefinementRadii and
    RefinementDeltas (parallel lists). The caller recomputes.
    """
    obj = doc.addObject("App::FeaturePython", name)
    SizingProxy(obj)
    obj.Part = part
    for prop, value in (("MinDelta", min_delta), ("MaxDelta", max_delta), ("Eps", eps)):
        if value is not None:
            setattr(obj, prop, value)
    if FreeCAD.GuiUp:  # headless, objects have no ViewObject
        from ..viewproviders import ViewProviderSizing
        ViewProviderSizing(obj.ViewObject)
    return obj


class SizingProxy(GuardedProxy):
    """Proxy of an App::FeaturePython holding the sizing octree's parameters for its ``Part``;
    recomputing predicts the element count (:func:`homesh.predict`).

    A failed prediction or a bad parameter leaves the message in Status, zero outputs, and the
    object marked as failed (the exception goes to FreeCAD's recompute, which reports it).
    """

    Type = TYPE_SIZING
    GRADATION = 0.2  # fixed in the core: sizes change by at most 0.2 per unit distance

    @staticmethod
    def add_properties(obj):
        """Adds missing properties and makes the outputs read-only; safe to call again."""
        have = obj.PropertiesList
        if "Part" not in have:
            obj.addProperty("App::PropertyLink", "Part", "Sizing", "Shape whose sizing this is")
        add_parameter_property(obj, "min_delta", "Sizing")
        add_parameter_property(obj, "max_delta", "Sizing")
        add_parameter_property(obj, "eps", "Sizing")
        if "Gradation" not in have:
            obj.addProperty("App::PropertyFloat", "Gradation", "Sizing",
                            "Most change of size per unit distance (fixed)")
            obj.Gradation = SizingProxy.GRADATION
        if "RefinementSpheres" not in have:
            obj.addProperty("App::PropertyVectorList", "RefinementSpheres", "Refinement",
                            "Centres of refinement spheres: inside sphere i the size is at most "
                            "RefinementDeltas[i]")
        if "RefinementRadii" not in have:
            obj.addProperty("App::PropertyFloatList", "RefinementRadii", "Refinement",
                            "Radius of each refinement sphere (same length as "
                            "RefinementSpheres)")
        if "RefinementDeltas" not in have:
            obj.addProperty("App::PropertyFloatList", "RefinementDeltas", "Refinement",
                            "Element size inside each refinement sphere (same length as "
                            "RefinementSpheres)")
        for prop, kind, doc in (
                ("PredictedElements", "App::PropertyInteger",
                 "Predicted number of linear elements (0 after a failure)"),
                ("OctreeLeaves", "App::PropertyInteger", "Leaves of the sizing octree"),
                ("SmallestSize", "App::PropertyLength", "Smallest size in the octree"),
                ("Status", "App::PropertyString",
                 "Summary of the last prediction, or why it failed")):
            if prop not in have:
                obj.addProperty(kind, prop, "Result", doc)
        for prop in ("Gradation", "PredictedElements", "OctreeLeaves", "SmallestSize", "Status"):
            obj.setEditorMode(prop, 1)  # read-only

    def execute(self, obj):
        import homesh
        try:
            if obj.Part is None:
                raise ValueError("%s: no shape (set its Part property)" % obj.Label)
            shape = getattr(obj.Part, "Shape", None)
            if shape is None or shape.isNull():
                raise ValueError("%s: %s has no shape" % (obj.Label, obj.Part.Label))
            # Sizes of the solids (faces in no solid left out): a mesh object without
            # SolidsOnly refuses such a shape and says why; the sizing stays drawable. A shape
            # without solids is sized as a surface mesh of its faces (the mesh object's Surface).
            report = homesh.predict(shape, name=obj.Part.Label, **cad_modes(shape),
                                    **sizing_arguments(obj))
        except (ValueError, homesh.HOMeshError) as e:
            obj.PredictedElements = 0
            obj.OctreeLeaves = 0
            obj.SmallestSize = 0
            obj.Status = "Failed: %s" % e
            FreeCAD.Console.PrintError("HOMesh: %s: %s\n" % (obj.Label, e))
            raise
        sizing = report["sizing"]
        octree = sizing["octree"]
        obj.PredictedElements = int(report["predicted_elements"])
        obj.OctreeLeaves = int(octree["leaves"])
        obj.SmallestSize = float(octree["smallest_delta"])
        obj.Gradation = float(sizing.get("gradation", SizingProxy.GRADATION))
        obj.Status = prediction_summary(report)
        FreeCAD.Console.PrintMessage("HOMesh: %s: %s\n" % (obj.Label, obj.Status))
