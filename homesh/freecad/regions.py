"""Mesh regions and boundary groups: child objects of a HighOrderMesh, their sub-shapes picked in
the 3D view (FreeCAD FEM's mesh regions and groups are the model).

MeshRegion: a smaller element size near faces, edges and vertices of the meshed shape. Each
becomes refinement sources of the sizing octree: a vertex a sphere, an edge the core's curve
source, a face spheres at points sampled on it no farther apart than ``Distance`` (so that they
cover it).

BoundaryGroup: a name (wall, inlet, outlet, farfield ...) for faces of the shape (2D: edges);
every export writes them as one Gmsh physical group / Nektar++ composite of that name.
"""

import math

import FreeCAD

from .objects import _Proxy

TYPE_MESH_REGION = "HOMesh::MeshRegion"
TYPE_BOUNDARY_GROUP = "HOMesh::BoundaryGroup"


def make_mesh_region(doc, mesh, references, size, distance=0.0, name="MeshRegion"):
    """Adds a MeshRegion to HighOrderMesh ``mesh``: element size ``size`` within ``distance``
    (0: 2 x size) of ``references``, a list of (object, ["Face1", "Edge3", "Vertex2", ...])."""
    obj = doc.addObject("App::FeaturePython", name)
    MeshRegionProxy(obj)
    obj.References = references
    obj.Size = size
    obj.Distance = distance
    mesh.Regions = list(mesh.Regions) + [obj]
    _view_provider(obj)
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
    _view_provider(obj)
    return obj


def _view_provider(obj):
    if FreeCAD.GuiUp:
        from .viewproviders import ViewProviderIconOnly
        ViewProviderIconOnly(obj.ViewObject)


def _sub_names(obj):
    """[(object, "FaceN"), ...] of a References property."""
    out = []
    for linked, names in obj.References:
        for name in names:
            out.append((linked, name))
    return out


def _index(name, kind):
    if not name.startswith(kind) or not name[len(kind):].isdigit():
        return None
    return int(name[len(kind):])


class MeshRegionProxy(_Proxy):
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
        sources(obj, obj.References[0][0] if obj.References else None)


def sources(region, part):
    """The refinement sources (dicts for homesh.mesh) a MeshRegion stands for. ValueError naming
    the region when it has no references, a bad size, or references of another shape."""
    size = region.Size.Value
    if not size > 0:
        raise ValueError("%s: Size must be a length > 0, got %g" % (region.Label, size))
    radius = region.Distance.Value or 2.0 * size
    subs = _sub_names(region)
    if not subs:
        raise ValueError("%s: no faces, edges or vertices (select them and set References)"
                         % region.Label)
    out = []
    for linked, name in subs:
        if part is not None and linked != part:
            raise ValueError("%s: %s belongs to %s, but the mesh is of %s"
                             % (region.Label, name, linked.Label, part.Label))
        shape = linked.Shape
        if _index(name, "Vertex") is not None:
            p = shape.Vertexes[_index(name, "Vertex") - 1].Point
            out.append({"kind": "sphere", "a": (p.x, p.y, p.z), "radius": radius,
                        "delta": size})
        elif _index(name, "Edge") is not None:
            out.append({"kind": "curve", "edge": _index(name, "Edge"), "radius": radius,
                        "delta": size})
        elif _index(name, "Face") is not None:
            out += _face_spheres(shape.Faces[_index(name, "Face") - 1], radius, size)
        else:
            raise ValueError("%s: %r is not a face, edge or vertex" % (region.Label, name))
    return out


def _face_spheres(face, radius, size):
    """Spheres of radius ``radius`` at points of ``face`` sampled on a grid of its parameters
    at most ``radius`` apart in space (along both parameter directions): every point of the
    face lies within 0.71 radius of a sample, so the spheres cover the face and a band around
    it. Samples outside the face's trimming are left out."""
    u0, u1, v0, v1 = face.ParameterRange

    def longest(along_u):
        """The longest iso-parameter curve of the face in that direction (sampled)."""
        best = 0.0
        for k in range(5):
            fixed = (v0 + (v1 - v0) * k / 4.0) if along_u else (u0 + (u1 - u0) * k / 4.0)
            points = [face.valueAt(u0 + (u1 - u0) * i / 32.0, fixed) if along_u else
                      face.valueAt(fixed, v0 + (v1 - v0) * i / 32.0) for i in range(33)]
            best = max(best, sum((b - a).Length for a, b in zip(points, points[1:])))
        return best

    nu = max(1, int(math.ceil(longest(True) / radius)))
    nv = max(1, int(math.ceil(longest(False) / radius)))
    out = []
    for i in range(nu + 1):
        for j in range(nv + 1):
            u = u0 + (u1 - u0) * i / nu
            v = v0 + (v1 - v0) * j / nv
            if not face.isPartOfDomain(u, v):
                continue
            p = face.valueAt(u, v)
            out.append({"kind": "sphere", "a": (p.x, p.y, p.z), "radius": radius,
                        "delta": size})
    return out


class BoundaryGroupProxy(_Proxy):
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


def group_entities(group, part=None):
    """(name, [entity numbers]) of a BoundaryGroup. ValueError naming the group when the name
    is empty or a reference is not a face (2D: an edge) of the meshed shape."""
    name = group.GroupName.strip()
    if not name:
        raise ValueError("%s: GroupName is empty" % group.Label)
    entities = []
    for linked, sub in _sub_names(group):
        if part is not None and linked != part:
            raise ValueError("%s: %s belongs to %s, but the mesh is of %s"
                             % (group.Label, sub, linked.Label, part.Label))
        solid = bool(linked.Shape.Solids)
        index = _index(sub, "Face" if solid else "Edge")
        if index is None:
            raise ValueError("%s: %r is not a %s" % (group.Label, sub,
                                                    "face" if solid else "edge"))
        entities.append(index)
    if not entities:
        raise ValueError("%s: no faces (select them and set References)" % group.Label)
    return name, sorted(set(entities))


def mesh_groups(obj):
    """{name: [entities]} of a HighOrderMesh's BoundaryGroup children, for writing."""
    out = {}
    for group in getattr(obj, "Groups", []) or []:
        name, entities = group_entities(group, obj.Part)
        if name in out:
            raise ValueError("%s: two boundary groups are called %r" % (obj.Label, name))
        out[name] = entities
    return out


def mesh_sources(obj):
    """The refinement sources of a HighOrderMesh's MeshRegion children."""
    out = []
    for region in getattr(obj, "Regions", []) or []:
        out += sources(region, obj.Part)
    return out
