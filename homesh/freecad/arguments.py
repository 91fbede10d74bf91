"""What a document object stands for in a call of the core, without the document: the
keyword arguments of :func:`homesh.mesh` / :func:`homesh.predict` that a HighOrderMesh, a Sizing
or a BoundaryLayer object gives, the refinement sources of MeshRegion children and the named
groups of BoundaryGroup children. Each reads the object's properties only, and raises
ValueError naming the object and the property when one is missing or out of range. No Qt.
"""

import math

from .object_types import is_boundary_layer, is_sizing
from .properties import allowed, definition


def part_shape(obj):
    """The shape a HighOrderMesh meshes; ValueError naming the object when there is none."""
    if obj.Part is None:
        raise ValueError("%s: no shape to mesh (set its Part property)" % obj.Label)
    shape = getattr(obj.Part, "Shape", None)
    if shape is None or shape.isNull():
        raise ValueError("%s: %s has no shape" % (obj.Label, obj.Part.Label))
    return shape


def mesh_arguments(obj, values=None):
    """The keyword arguments of :func:`homesh.mesh` that a HighOrderMesh object stands for,
    with ``values`` ({property: value}, from a task panel) in place of its own properties.

    Raises ValueError naming the object and the property when something is missing or out of
    range.
    """
    values = dict(values or {})

    def get(prop):
        value = values[prop] if prop in values else getattr(obj, prop)
        value = float(getattr(value, "Value", value))
        p = definition(prop)
        if not allowed(p, value):
            raise ValueError("%s: %s must be %s, got %g" % (obj.Label, prop, p["range"], value))
        return value

    size = get("Size")
    arguments = {"order": int(get("Order")), "size": size if size > 0 else None,
                 "optimise": int(get("OptimiserIterations")),
                 "optimise_seconds": get("OptimiserTimeLimit"),
                 "facet_weight": get("FacetWeight"),
                 "fidelity_weight": get("FidelityWeight"),
                 "linear_seconds": get("LinearTimeLimit"),
                 "job_seconds": get("JobTimeLimit"),
                 "heal": bool(get("Heal")), "solids_only": bool(get("SolidsOnly")),
                 "surface": bool(get("Surface")), "auto": bool(get("AutoMode")),
                 "imprint": bool(get("Imprint")),
                 "repair_rounds": int(get("RepairRounds")), "threads": int(get("Threads"))}
    sizing = values.get("Sizing", getattr(obj, "Sizing", None))
    if arguments["size"] is None and sizing is not None:
        if not is_sizing(sizing):
            raise ValueError("%s: Sizing must link to a HOMesh Sizing object, not %s"
                             % (obj.Label, sizing.Label))
        arguments.update(sizing_arguments(sizing))
    if getattr(obj, "Regions", None) and getattr(obj, "FemMesh", None) is None:
        if arguments["size"] is not None:
            raise ValueError("%s: mesh regions refine the sizing octree: set Size to 0 "
                             "(automatic) to use them" % obj.Label)
        arguments["sources"] = list(arguments.get("sources", ())) + mesh_sources(obj)
    if obj.BoundaryLayer is not None and getattr(obj, "FemMesh", None) is None:
        if not is_boundary_layer(obj.BoundaryLayer):
            raise ValueError("%s: BoundaryLayer must link to a HOMesh BoundaryLayer object, "
                             "not %s" % (obj.Label, obj.BoundaryLayer.Label))
        arguments["boundary_layer"] = boundary_layer_arguments(obj.BoundaryLayer, obj.Part)
    return arguments


def cad_modes(shape):
    """How a Sizing object sizes `shape`: its solids (faces in no solid left out), or, for a
    shape without solids, its faces as a surface mesh."""
    surface = len(shape.Solids) == 0
    return {"solids_only": not surface, "surface": surface}


def sizing_arguments(obj):
    """The keyword arguments of :func:`homesh.predict` / :func:`homesh.mesh` that a Sizing
    object stands for: min_delta, max_delta (None when automatic), eps and sources.

    Raises ValueError naming the object and the property when a parameter is out of range.
    """
    min_delta = obj.MinDelta.Value
    max_delta = obj.MaxDelta.Value
    eps = obj.Eps
    if not allowed(definition("Eps"), eps):
        raise ValueError("%s: Eps must be %s, got %g" % (obj.Label, definition("Eps")["range"],
                                                         eps))
    if min_delta > 0 and max_delta > 0 and min_delta > max_delta:
        raise ValueError("%s: MinDelta (%g) must not exceed MaxDelta (%g)"
                         % (obj.Label, min_delta, max_delta))
    centres, radii, deltas = obj.RefinementSpheres, obj.RefinementRadii, obj.RefinementDeltas
    if not len(centres) == len(radii) == len(deltas):
        raise ValueError("%s: RefinementSpheres, RefinementRadii and RefinementDeltas must have "
                         "the same length, got %d, %d and %d"
                         % (obj.Label, len(centres), len(radii), len(deltas)))
    sources = []
    for i, (centre, radius, delta) in enumerate(zip(centres, radii, deltas)):
        for prop, value in (("RefinementRadii", radius), ("RefinementDeltas", delta)):
            if not value > 0:
                raise ValueError("%s: %s[%d] must be positive, got %g"
                                 % (obj.Label, prop, i, value))
        sources.append({"kind": "sphere", "a": (centre.x, centre.y, centre.z),
                        "radius": float(radius), "delta": float(delta)})
    return {"min_delta": min_delta if min_delta > 0 else None,
            "max_delta": max_delta if max_delta > 0 else None,
            "eps": float(eps), "sources": sources}


def boundary_layer_arguments(obj, part=None):
    """The ``boundary_layer`` argument of :func:`homesh.mesh` a BoundaryLayer object stands for.

    Raises ValueError naming the object and the property when its faces are missing, are not
    faces, or (with ``part``) belong to another object than the one meshed.
    """
    linked = obj.Faces
    if not linked or linked[0] is None:
        raise ValueError("%s: no faces (select faces of the shape and set Faces)" % obj.Label)
    owner, names = linked[0], list(linked[1])
    if part is not None and owner != part:
        raise ValueError("%s: its faces belong to %s, but the mesh is of %s"
                         % (obj.Label, owner.Label, part.Label))
    # Faces of a solid (3D), or edges of a planar shape (2D: the layer grows from curves).
    kind = "Edge" if names and names[0].startswith("Edge") else "Face"
    faces = []
    for name in names:
        if not name.startswith(kind) or not name[len(kind):].isdigit():
            raise ValueError("%s: Faces must name faces (Face1, Face2, ...), or for a planar "
                             "shape edges (Edge1, ...), all of one kind; got %r"
                             % (obj.Label, name))
        faces.append(int(name[len(kind):]))
    if kind == "Edge" and getattr(owner, "Shape", None) is not None and owner.Shape.Solids:
        raise ValueError("%s: Faces must name faces of a solid (Face1, Face2, ...); edges carry "
                         "a layer only on a planar shape, got %r" % (obj.Label, names[0]))
    if not faces:
        raise ValueError("%s: no faces (select faces of the shape and set Faces)" % obj.Label)
    text = obj.Thickness.strip()
    try:
        thickness = float(text)
    except ValueError:
        thickness = text  # an expression of x, y, z: the core parses it and names any error
    out = {"faces": sorted(set(faces)), "thickness": thickness, "layers": int(obj.Layers),
           "progression": float(obj.Progression)}
    solids = list(getattr(obj, "Solids", []) or [])
    if solids:
        out["solids"] = sorted(set(int(s) for s in solids))
    return out


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


def region_sources(region, part):
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
        out += region_sources(region, obj.Part)
    return out
