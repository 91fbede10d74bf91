"""The Type strings of HOMesh's document objects and the one test of an object's type.

The bottom of the package: every layer (meshing, objects, view providers, commands) names the
objects' types from here, so none has to import the proxies to recognise an object.
"""

TYPE_HIGH_ORDER_MESH = "HOMesh::HighOrderMesh"
TYPE_SIZING = "HOMesh::Sizing"
TYPE_BOUNDARY_LAYER = "HOMesh::BoundaryLayer"
TYPE_MESH_REGION = "HOMesh::MeshRegion"
TYPE_BOUNDARY_GROUP = "HOMesh::BoundaryGroup"


def type_of(obj):
    """The Type of ``obj``'s proxy ("" for an object without a HOMesh proxy)."""
    return getattr(getattr(obj, "Proxy", None), "Type", "")


def is_high_order_mesh(obj):
    """Whether ``obj`` is a HOMesh HighOrderMesh object."""
    return type_of(obj) == TYPE_HIGH_ORDER_MESH


def is_sizing(obj):
    """Whether ``obj`` is a HOMesh Sizing object."""
    return type_of(obj) == TYPE_SIZING


def is_boundary_layer(obj):
    """Whether ``obj`` is a HOMesh BoundaryLayer object."""
    return type_of(obj) == TYPE_BOUNDARY_LAYER
