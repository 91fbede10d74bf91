"""Mesh regions and boundary groups: child objects of a HighOrderMesh, their sub-shapes picked in
the 3D view (FreeCAD FEM's mesh regions and groups are the model).

MeshRegion: a smaller element size near faces, edges and vertices of the meshed shape. Each
becomes refinement sources of the sizing octree: a vertex a sphere, an edge the core's curve
source, a face spheres at points sampled on it no farther apart than ``Distance`` (so that they
cover it).

BoundaryGroup: a name (wall, inlet, outlet, farfield ...) for faces of the shape (2D: edges);
every export writes them as one Gmsh physical group / Nektar++ composite of that name.
The sources and groups themselves are made in arguments.py.
"""

import FreeCAD

from ..arguments import group_entities, region_sources
from ..object_types import TYPE_BOUNDARY_GROUP, TYPE_MESH_REGION
from .base import Proxy


def make_mesh_region(doc, mesh, references, size, distance=0.0, name="MeshRegion"):
    """Adds a MeshRegion to HighOrderMesh ``mesh``: element size ``size`` within ``distance``
    (0: 2 x size) of ``references``, a list of (object, ["Face1", "Edge3", "Vertex2", ...])."""
    obj = doc.addObject("App::FeaturePython", name)
    MeshRegionProxy(obj)
    obj.References = references
    obj.Size = size
    obj.Distance = distance
    mesh.Regions = list(mesh.Regions) + [obj]
    if FreeCAD.GuiUp:  # headless, objects have no ViewObject
        from ..viewproviders import ViewProviderIconOnly
        ViewProviderIconOnly(obj.ViewObject)
    return obj


def make_boundary_group(doc, mesh, references, group_name, name="BoundaryGroup"):
    """Adds a BoundaryGroup called ``group_name`` on ``references`` (faces; 2D: edges) to
    HighOrderMesh ``mesh``."""
    obj = doc.addObject("App::FeaturePython", name)
    BoundaryGroupProxy(obj)
    obj.References = references
    obj.GroupName = group_name
    obj.Label = group_name
    mesh.Groups = list(mesh.Groups) + [obj]
    if FreeCAD.GuiUp:  # headless, objects have no ViewObject
        from ..viewproviders import ViewProviderIconOnly
        ViewProviderIconOnly(obj.ViewObject)
    return obj


class MeshRegionProxy(Proxy):
    Type = TYPE_MESH_REGION

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)
        self.refused = []

    @staticmethod
    def add_properties(obj):
        have = obj.PropertiesList
        if "References" not in have:
            obj.addProperty("App::PropertyLinkSubList", "References", "Region",
                            "Faces, edges and vertices of the meshed shape (select them)")
        if "Size" not in have:
            obj.addProperty("App::PropertyDistance", "Size", "Region",
                            "Element size near the references (> 0)")
        if "Distance" not in have:
            obj.addProperty("App::PropertyDistance", "Distance", "Region",
                            "How far from the references the size applies; 0: twice Size")

    def onDocumentRestored(self, obj):
        self.add_properties(obj)
        self.refused = []

    def onChanged(self, obj, prop):
        """A negative Size or Distance is refused (and reported); Size 0 is caught when the
        mesh is made (a region must have a size)."""
        if prop not in ("Size", "Distance") or prop not in obj.PropertiesList:
            return
        good = self.__dict__.setdefault("_good", {})
        value = getattr(obj, prop).Value
        if value >= 0:
            good[prop] = value
            return
        message = ("%s: %s = %g refused: it must be a length >= 0; kept %g"
                   % (obj.Label, prop, value, good.get(prop, 0.0)))
        self.__dict__.setdefault("refused", []).append(message)
        FreeCAD.Console.PrintWarning("HOMesh: %s\n" % message)
        setattr(obj, prop, good.get(prop, 0.0))

    def execute(self, obj):
        region_sources(obj, obj.References[0][0] if obj.References else None)


class BoundaryGroupProxy(Proxy):
    Type = TYPE_BOUNDARY_GROUP

    def __init__(self, obj):
        obj.Proxy = self
        self.add_properties(obj)

    @staticmethod
    def add_properties(obj):
        have = obj.PropertiesList
        if "References" not in have:
            obj.addProperty("App::PropertyLinkSubList", "References", "Group",
                            "Faces of the meshed shape (2D: edges) in this group (select "
                            "them)")
        if "GroupName" not in have:
            obj.addProperty("App::PropertyString", "GroupName", "Group",
                            "Name of the group in every export: Gmsh physical group, "
                            "Nektar++ composite (wall, inlet, outlet, farfield ...)")

    def onDocumentRestored(self, obj):
        self.add_properties(obj)

    def execute(self, obj):
        group_entities(obj)
