"""The `homesh` Python package outside FreeCAD: arrays, quality, writers, persistence, errors,
progress and cancel."""

import json

import numpy as np
import pytest

import homesh
from conftest import DATA, PEER_CASES, ROOT, needs_peer_files
from homesh import tessellation


@pytest.fixture(scope="module")
def sphere(data):
    return homesh.mesh(str(data / "sphere.brep"), order=3, size=0.4)


def test_arrays_have_the_documented_layout(sphere):
    m = sphere
    assert m.order == 3 and m.dim == 3 and m.element_type == "tet"
    assert m.nodes.shape == (m.num_nodes, 3) and m.nodes.dtype == np.float64
    assert m.elements.shape == (m.num_elements, 20) and m.elements.dtype == np.int64
    assert m.elements.min() >= 0 and m.elements.max() < m.num_nodes
    assert m.node_cad_params.shape == (m.num_nodes, 2)
    on_face = m.node_cad_dim == 2
    assert np.all(m.node_cad_index[on_face] == 1)
    # Points of OCCT's sphere: 1 to rounding (~1e-15).
    assert np.allclose(np.linalg.norm(m.nodes[on_face], axis=1), 1.0, atol=1e-9)
    (tris,) = [b for b in m.boundary if b.element_type == "tri"]
    assert tris.elements.shape[1] == 10 and np.all(tris.cad_entity == 1)


def test_quality_and_report(sphere):
    q = sphere.quality()
    assert q["scaled_jacobian"].shape == (sphere.num_elements,)
    assert q["invalid_elements"] == 0
    assert q["min"] == q["scaled_jacobian"].min()  # the same doubles, never printed
    report = sphere.report("sphere.brep")
    assert report["elements"]["tet"] == sphere.num_elements
    assert report["nodes"] == sphere.num_nodes
    json.dumps(report)


def test_summary_is_the_command_lines(sphere, homesh_bin, data):
    """One writer of the summary: the CLI prints the lines Python's summary() returns, and
    repr() and FreeCAD's status start from the same headline."""
    from conftest import run
    r = run([homesh_bin, "mesh", str(data / "sphere.brep"), "--order", "3", "--size", "0.4"])
    assert r.returncode == 0, r.stderr
    printed = [line[len("homesh: "):] for line in r.stderr.splitlines()]
    headline = sphere.headline()
    assert headline.endswith("all elements proven valid")
    assert headline.startswith("%d nodes, %d elements of order 3; scaled Jacobian min "
                               % (sphere.num_nodes, sphere.num_elements))
    assert headline in printed and headline in sphere.summary()
    # The sizing lines carry their time: compare the rest.
    timeless = [s for s in sphere.summary() if not s.startswith("sizing octree")]
    assert all(s in printed for s in timeless), (timeless, printed)
    assert repr(sphere) == "<HighOrderMesh: %s>" % headline


def test_geometry_record_of_a_mesh_made_from_cad(sphere, tmp_path):
    g = sphere.geometry()
    assert g == sphere.report()["geometry"]
    assert g["diagonal"] == pytest.approx(2 * 3 ** 0.5)  # the unit sphere's bounding box
    assert g["max_distance_relative"] == pytest.approx(g["max_distance"] / g["diagonal"])
    assert g["samples"] > g["angle_samples"] > 0  # lines on the seam: distance only
    assert 0 < g["mean_normal_angle_deg"] <= g["max_normal_angle_deg"]
    assert g["worst_angle_entity"] == "Face1" and len(g["worst_point"]) == 3
    sphere.write(tmp_path / "s.npz")
    assert homesh.load(tmp_path / "s.npz").geometry() is None  # no CAD, no record



def test_optimising_a_mesh_made_from_cad_remeasures_its_geometry(data):
    m = homesh.mesh(str(data / "sphere.brep"), order=2, size=0.6)
    before = m.geometry()
    m.optimise(optimise=2)
    after = m.geometry()  # the boundary slid on the CAD: measured again, same sampling
    assert after is not None and after["samples"] == before["samples"]
    # Nodes on the sphere: the quadratic boundary stays nearer than the chord of an edge 1.5
    # times the size (Gmsh's edges stay within that) sags from the unit sphere.
    assert after["max_distance"] < 1 - (1 - (1.5 * 0.6 / 2) ** 2) ** 0.5


def test_npz_round_trip_keeps_everything(sphere, tmp_path):
    path = tmp_path / "m.npz"
    sphere.write(path)
    back = homesh.load(path)
    assert np.array_equal(back.nodes, sphere.nodes)
    assert np.array_equal(back.elements, sphere.elements)
    assert np.array_equal(back.node_cad_dim, sphere.node_cad_dim)
    np.testing.assert_array_equal(back.quality()["scaled_jacobian"],
                                  sphere.quality()["scaled_jacobian"])
    back.write(tmp_path / "again.msh")
    assert (tmp_path / "again.msh").stat().st_size > 0


def test_brep_text_input(data):
    text = (data / "sphere.brep").read_text()
    m = homesh.mesh(text, order=2, size=0.5)
    assert m.num_elements > 0


def test_planar_face_gives_a_2d_mesh(tmp_path):
    # A unit square face as BRep text written by OCCT (FreeCAD's Part.makePlane(1, 1)).
    import subprocess
    square = tmp_path / "square.brep"
    subprocess.run(["freecadcmd", "-c",
                    "import Part; Part.makePlane(2, 1).exportBrep(%r)" % str(square)],
                   check=True, capture_output=True, timeout=120)
    m = homesh.mesh(str(square), order=4, size=0.3)
    assert m.dim == 2 and m.element_type == "tri"
    assert m.quality()["invalid_elements"] == 0
    assert all(b.element_type == "line" for b in m.boundary)


@pytest.mark.parametrize("kwargs, error", [
    (dict(order=0), homesh.ParameterError),
    (dict(order=11), homesh.ParameterError),
    (dict(order=2.5), homesh.ParameterError),
    (dict(order=True), homesh.ParameterError),
    (dict(size=-1), homesh.ParameterError),
    (dict(size=float("nan")), homesh.ParameterError),  # 0 is automatic, as in FreeCAD
    (dict(size="big"), homesh.ParameterError),
    (dict(threads=-1), homesh.ParameterError),  # (0 is every core)
    (dict(threads=100000), homesh.ParameterError),
    (dict(order=2**40), homesh.ParameterError),
    (dict(verbosity=2**40), homesh.ParameterError),
])
def test_bad_parameters_raise(data, kwargs, error):
    with pytest.raises(error):
        homesh.mesh(str(data / "sphere.brep"), **kwargs)


def test_bad_inputs_raise_named_errors(tmp_path):
    with pytest.raises(homesh.FileError, match="does not exist"):
        homesh.mesh(str(tmp_path / "nope.step"))
    fake = tmp_path / "fake.step"
    fake.write_text("not a step file")
    with pytest.raises(homesh.FileError, match="fake.step"):
        homesh.mesh(str(fake))
    with pytest.raises(homesh.CadError):
        homesh.mesh("\nCASCADE Topology V1, garbage\nnot really\n")
    with pytest.raises(homesh.ParameterError):
        homesh.mesh(42)
    # The errors are ordinary Python exceptions with the standard bases.
    assert issubclass(homesh.ParameterError, ValueError)
    assert issubclass(homesh.FileError, OSError)
    assert issubclass(homesh.HOMeshError, RuntimeError)


def test_load_rejects_files_that_are_not_ours(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(homesh.FileError):
        homesh.load(bad)
    np.savez(tmp_path / "other.npz", x=np.arange(3))
    with pytest.raises(homesh.FileError):
        homesh.load(tmp_path / "other.npz")
    with pytest.raises(homesh.FileError):
        homesh.load(tmp_path / "missing.npz")


def test_writing_twice_keeps_the_report_consistent(sphere, tmp_path):
    sphere.write(tmp_path / "a.msh")
    sphere.write(tmp_path / "a.vtu")
    def unique_keys(pairs):
        keys = [k for k, _ in pairs]
        assert len(keys) == len(set(keys)), keys
        return dict(pairs)

    report = json.loads(sphere._core.report_json("x"), object_pairs_hook=unique_keys)
    assert "output" not in report["timings_s"]


def test_concurrent_jobs_in_threads(data):
    """The core runs without the GIL: jobs from several threads must not disturb each other
    (OCCT's STEP reader and Gmsh have process-wide state)."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(4) as pool:
        meshes = list(pool.map(lambda _: homesh.mesh(str(data / "box_hole.step"), order=2,
                                                     size=1.0), range(8)))
    counts = {m.num_elements for m in meshes}
    assert len(counts) == 1 and counts.pop() > 0


def test_progress_reports_stages_and_can_cancel(data):
    seen = []
    homesh.mesh(str(data / "sphere.brep"), order=2, size=0.5,
                progress=lambda stage, seconds: seen.append((stage, seconds)))
    assert [s for s, t in seen if t is None] == [
        "cad", "linear", "high_order", "quality", "boundary_fit", "geometry"]
    assert all(t >= 0 for s, t in seen if t is not None)

    def stop(stage, seconds):
        if stage == "linear" and seconds is not None:
            raise RuntimeError("user pressed cancel")

    with pytest.raises(homesh.CancelledError, match="user pressed cancel"):
        homesh.mesh(str(data / "sphere.brep"), order=2, size=0.5, progress=stop)

    def stop_at_the_end(stage, seconds):
        if stage == "quality" and seconds is not None:
            raise KeyboardInterrupt

    with pytest.raises(homesh.CancelledError):
        homesh.mesh(str(data / "sphere.brep"), order=2, size=0.5, progress=stop_at_the_end)

    def unprintable(stage, seconds):
        raise ValueError("\udcff")  # str() of it cannot be encoded to UTF-8

    with pytest.raises(homesh.CancelledError):
        homesh.mesh(str(data / "sphere.brep"), order=2, size=0.5, progress=unprintable)


def test_tessellation_follows_the_curved_surface(sphere):
    geometry = tessellation.surface_and_edges(sphere, level=6)
    pts = geometry["points"]
    assert len(geometry["triangles"]) == len(geometry["colors"])
    assert geometry["triangles"].max() < len(pts)
    # Points sampled inside curved boundary triangles are on (or extremely near) the sphere:
    # far closer than the straight-sided chords would be. Cubic interpolation of the unit
    # sphere over triangles of diameter h errs by about Lambda h^4 / 4! at most, Lambda = 2.3
    # the Lebesgue constant of the cubic triangle and h the longest boundary edge of Gmsh's
    # mesh (0.65 here; it moves with the CAD's last bits). Measured: 0.05 of that bound for
    # sizes 0.3 to 0.8. A flat tessellation would be off by h^2 / 8, 3x the bound at h = 0.65.
    (tris,) = [b for b in sphere.boundary if b.element_type == "tri"]
    corners = sphere.nodes[tris.elements[:, :3]]
    h = max(np.linalg.norm(corners[:, i] - corners[:, (i + 1) % 3], axis=1).max()
            for i in range(3))
    bound = 2.3 * h ** 4 / 24
    radius = np.linalg.norm(pts, axis=1)
    assert np.max(np.abs(radius - 1.0)) < bound
    edge_radius = np.linalg.norm(geometry["edge_points"], axis=1)
    assert np.max(np.abs(edge_radius - 1.0)) < bound
    assert geometry["edge_polylines"].shape[1] == 7


# NekMesh's cylinder case (peer files, skipped where absent): 3d_bl_cyl.stp (millimetres), the
# cylinder's two faces 1 and 8 between the end planes z = 0 and 500.
CYLINDER = PEER_CASES / "meshgen"
# The repository's box with a hole (4 x 4 x 2 mm, the hole of radius 1 mm along z): Face7 the
# hole's wall, between the planes z = 0 and 2.
BOX_HOLE = DATA / "box_hole.step"
HOLE_FACE = 7


def _boundary_layer_argument(cad, faces, thickness, ends):
    # A layer of the given thickness on the faces, 3 layers growing by 1.2 from the wall.
    m = homesh.mesh(str(cad), order=2, optimise=50, threads=2,
                    boundary_layer={"faces": faces, "thickness": thickness, "layers": 3,
                                    "progression": 1.2})
    report = m.report()
    layer = report["boundary_layer"]
    assert layer["faces"] == faces and layer["layers"] == 3
    assert report["elements"]["prism"] == 3 * layer["macro_cells"] > 0
    # First layer: thickness (1 - 1.2) / (1 - 1.2^3), measured at the wall's quadrature points
    # within the worst deviation the report gives, itself within the 5 % asked for.
    first, expected = layer["first_height"], thickness * 0.2 / (1.2 ** 3 - 1)
    assert first["worst_deviation"] <= 0.05 and first["corner_cells"] == 0
    for key in ("min", "max"):
        assert abs(first[key] / expected - 1) <= first["worst_deviation"] + 1e-12
    assert m.quality()["invalid_elements"] == 0
    blocks = {b.element_type for b in m.element_blocks}
    assert blocks == {"tet", "prism"}
    # Drawn: the walls' triangles and the layer's side quadrilaterals (on the end planes), each
    # owned by a prism or tetrahedron; two sub-triangles per quad lattice cell.
    level = 3
    geometry = tessellation.surface_and_edges(m, level=level)
    faces = {b.element_type: b.elements for b in m.boundary}
    assert len(geometry["triangles"]) == \
        level ** 2 * len(faces["tri"]) + 2 * level ** 2 * len(faces["quad"])
    for kind, corners in (("tri", 3), ("quad", 4)):
        assert (tessellation.face_owners(m.element_blocks, faces[kind], corners) >= 0).all()
    quad_points = geometry["points"][-len(faces["quad"]) * (level + 1) ** 2:]
    # On the planes to the rounding of the Lagrange sums of coordinates up to ~1e3 (1e-9 mm).
    z = quad_points[:, 2]
    assert np.all(np.minimum(abs(z - ends[0]), abs(z - ends[1])) < 1e-9)


def test_boundary_layer_argument_and_mcf_keys():
    needs_peer_files()
    # The cylinder STEP read as is (millimetres): a 40 mm layer on the cylinder's two faces.
    _boundary_layer_argument(CYLINDER / "3d_bl_cyl.stp", [1, 8], 40, (0, 500))
    # A .mcf's BndLayer keys are used when no boundary_layer is given.
    c = homesh.mesh(str(CYLINDER / "3d_bl_cyl.mcf"), order=2, optimise=50, threads=2)
    assert c.report()["boundary_layer"]["layers"] == 6


def test_boundary_layer_argument_and_mcf_keys_on_a_hole(tmp_path):
    # The box with a hole read as is (millimetres): a 0.2 mm layer on the hole's wall.
    _boundary_layer_argument(BOX_HOLE, [HOLE_FACE], 0.2, (0, 2))
    # A .mcf written beside a copy of the STEP (read in metres): its BndLayer keys are used when
    # no boundary_layer is given.
    (tmp_path / BOX_HOLE.name).write_bytes(BOX_HOLE.read_bytes())
    mcf = tmp_path / "hole.mcf"
    mcf.write_text("""<NEKTAR><MESHING>
  <INFORMATION>
    <I PROPERTY="CADFile" VALUE="%s" />
    <I PROPERTY="MeshType" VALUE="3DBndLayer" />
  </INFORMATION>
  <PARAMETERS>
    <P PARAM="MinDelta" VALUE="0.0001" />
    <P PARAM="MaxDelta" VALUE="0.0004" />
    <P PARAM="EPS" VALUE="0.1" />
    <P PARAM="Order" VALUE="2" />
    <P PARAM="BndLayerSurfaces" VALUE="%d" />
    <P PARAM="BndLayerThickness" VALUE="0.0001" />
    <P PARAM="BndLayerLayers" VALUE="4" />
  </PARAMETERS>
</MESHING></NEKTAR>
""" % (BOX_HOLE.name, HOLE_FACE))
    c = homesh.mesh(str(mcf), order=2, optimise=50, threads=2)
    layer = c.report()["boundary_layer"]
    assert layer["faces"] == [HOLE_FACE] and layer["layers"] == 4
    assert c.report()["elements"]["prism"] == 4 * layer["macro_cells"] > 0


# Errors in the boundary_layer argument, named before any meshing: on the repository's box with a
# hole (7 faces), and on NekMesh's cylinder (8 faces) where the peer files are here.
@pytest.fixture(params=["box_hole", "peer_cylinder"])
def layer_cad(request):
    if request.param == "peer_cylinder":
        needs_peer_files()
        return CYLINDER / "3d_bl_cyl.stp"
    return BOX_HOLE


def test_boundary_layer_grows_into_the_solid_named():
    """examples/sphere_box.step: a sphere in a box, imprinted so that the sphere's face lies
    between the two solids; the layer on it grows into the solid named (the box around, as for
    the flow past the sphere), and needs one named."""
    sphere_box = ROOT / "examples" / "sphere_box.step"
    spec = {"faces": [1], "thickness": 0.05, "layers": 2}
    with pytest.raises(homesh.ParameterError, match="name the one the layer grows into"):
        homesh.mesh(str(sphere_box), order=2, boundary_layer=spec)
    m = homesh.mesh(str(sphere_box), order=2, boundary_layer=dict(spec, solids=[2]))
    layer = m.report()["boundary_layer"]
    assert layer["solids"] == [2] and layer["macro_cells"] > 0
    assert m.report()["elements"]["prism"] == 2 * layer["macro_cells"]
    assert m.quality()["invalid_elements"] == 0


@pytest.mark.parametrize("spec, message", [
    ({"faces": [1]}, "needs 'thickness'"),
    ({"faces": [1], "thickness": 40, "layer": 3}, "unknown key 'layer'"),
    ({"faces": [9], "thickness": 1}, "face 9 does not exist"),
    ({"faces": [1], "thickness": "x*"}, "not an expression of x, y, z"),
    ({"faces": [1], "thickness": True}, "must be a number or an expression"),
    ({"faces": [1], "thickness": 1, "layers": 0}, "layers must be an integer from 1 to 100"),
    (5, "must be a dict"),
    ({"faces": [1], "thickness": 1, "solids": [2]}, "boundary-layer solid 2 does not exist"),
    ({"faces": [1], "thickness": 1, "solids": ["a"]}, "solids must be an integer"),
])
def test_bad_boundary_layers_are_named(layer_cad, spec, message):
    with pytest.raises(homesh.ParameterError, match=message):
        homesh.mesh(str(layer_cad), order=2, boundary_layer=spec)


def test_size_field_is_the_octree_that_predict_integrates(data):
    """size_field's leaves: sizes within [MinDelta, MaxDelta], smaller on the sphere's surface
    (curvature) than inside, and the same predicted count as predict()."""
    text = (data / "sphere.brep").read_text()
    field = homesh.size_field(text, min_delta=0.05, max_delta=0.5, eps=0.01)
    n = len(field["delta"])
    assert field["centre"].shape == (n, 3) and field["half_width"].shape == (n,)
    assert n > 100 and 0 < field["boundary"].sum() < n
    assert field["delta"].min() >= 0.05 and field["delta"].max() <= 0.5
    # Curvature radius 1 with eps 0.01: 2 sqrt(0.01 * 1.99) = 0.28 on the surface, graded
    # inward by 0.2 per unit length up to 0.5: boundary leaves are the finer ones.
    boundary = field["boundary"] == 1
    assert field["delta"][boundary].mean() < field["delta"][~boundary].mean()
    report = homesh.predict(text, min_delta=0.05, max_delta=0.5, eps=0.01)
    # The report gives the count as a whole number.
    assert abs(field["predicted_elements"] - report["predicted_elements"]) < 1.0
    # Every leaf centre lies within its half width (times sqrt 3) of the unit ball.
    radius = np.linalg.norm(field["centre"], axis=1)
    assert (radius <= 1.0 + np.sqrt(3.0) * field["half_width"] + 1e-12).all()


def test_an_optimiser_time_limit_stops_it_with_the_best_state(data):
    text = (data / "sphere.brep").read_text()
    m = homesh.mesh(text, order=4, size=0.5, optimise=50, optimise_seconds=1e-6,
                    repair_rounds=0)
    record = m.report()["optimiser"]
    assert record["stopped"] == "time budget"
    assert record["iterations"] == 0 and record["kept_iteration"] == 0
    with pytest.raises(homesh.ParameterError, match="optimiser time limit must be a number >= 0"):
        homesh.mesh(text, order=2, size=0.5, optimise=5, optimise_seconds=-1.0)


@pytest.mark.parametrize("key, value, name, top", [("facet_weight", 1.0, "facet weight", "100"),
                                                    ("fidelity_weight", 10.0, "fidelity weight",
                                                     "1000")])
def test_the_boundary_terms_reach_the_core_and_are_checked(data, key, value, name, top):
    # The sphere at size 0.5, order 4: the optimiser slides its nodes with and without the
    # term; both valid, and the term changes the result (it is applied, not dropped).
    text = (data / "sphere.brep").read_text()
    plain = homesh.mesh(text, order=4, size=0.5, optimise=20, **{key: 0.0})
    term = homesh.mesh(text, order=4, size=0.5, optimise=20, **{key: value})
    for m in (plain, term):
        assert m.report()["optimiser"]["invalid_after"] == 0
    assert not np.array_equal(plain.nodes, term.nodes)
    with pytest.raises(homesh.ParameterError,
                       match="%s must be a number from 0 to %s" % (name, top)):
        homesh.mesh(text, order=2, size=0.5, optimise=5, **{key: -1.0})
    with pytest.raises(homesh.ParameterError,
                       match="%s must be a number from 0 to %s, got '1'" % (name, top)):
        homesh.mesh(text, order=2, size=0.5, optimise=5, **{key: "1"})


def test_the_command_line_takes_a_time_limit(homesh_bin, data, tmp_path):
    from conftest import run
    report = tmp_path / "r.json"
    ok = run([homesh_bin, "mesh", data / "sphere.brep", "--order", "4", "--size", "0.5",
              "--optimise", "--time-limit", "0.000001", "--repair-rounds", "0",
              "--report", report, "-q"])
    assert ok.returncode in (0, 4), ok.stderr
    assert json.loads(report.read_text())["optimiser"]["stopped"] == "time budget"
    bad = run([homesh_bin, "mesh", data / "sphere.brep", "--time-limit", "-2"])
    assert bad.returncode == 2 and "--time-limit must be a number >= 0" in bad.stderr


def test_options_are_checked_once_by_the_parameter_table(data):
    """The keywords of mesh, curve and predict go to the core as one options mapping: a name
    the table does not have, a value of the wrong kind or out of range, and a name the function
    has no use for are refused with one message naming the option."""
    text = (data / "sphere.brep").read_text()
    with pytest.raises(homesh.ParameterError, match="unknown option 'ordr'"):
        homesh.mesh(text, ordr=2)
    with pytest.raises(homesh.ParameterError,
                       match="order must be an integer from 1 to 10, got '4'"):
        homesh.mesh(text, order="4")
    with pytest.raises(homesh.ParameterError,
                       match="order must be an integer from 1 to 10, got true"):
        homesh.mesh(text, order=True)
    with pytest.raises(homesh.ParameterError, match="heal must be true or false, got 1"):
        homesh.mesh(text, heal=1)
    with pytest.raises(homesh.ParameterError,
                       match=r"option 'size' does not apply here \(options: order, optimise"):
        homesh.curve(text, [[0, 0, 0]] * 4, [[0, 1, 2, 3]], size=1.0)
    with pytest.raises(homesh.ParameterError, match="option 'order' does not apply here"):
        homesh.predict(text, order=2)
    # The layer's own parameters belong in its dict, not among the job's.
    with pytest.raises(homesh.ParameterError, match="option 'layers' does not apply here"):
        homesh.mesh(text, layers=3)


def test_keywords_and_their_help_come_from_the_parameter_table(data):
    import inspect
    table = {p["key"]: p for p in homesh.parameters()}
    signature = inspect.signature(homesh.mesh).parameters
    for key in ("order", "repair_rounds", "linear_seconds", "heal", "min_delta"):
        p = table[key]
        assert key in homesh.mesh.__doc__ and p["range"] in homesh.mesh.__doc__, key
        default = signature[key].default
        assert default is None if p["zero_is_automatic"] else default == p["default"], key
    assert signature["optimise"].default is False  # asked for with True or a number
    assert "facet_weight" in inspect.signature(homesh.curve).parameters
    assert "fidelity_weight" in inspect.signature(homesh.curve).parameters
    assert "size" not in inspect.signature(homesh.curve).parameters
    # optimise=True is the table's number of sweeps, the most a run may take.
    record = homesh.mesh((data / "sphere.brep").read_text(), order=2, size=0.5,
                         optimise=True).report()["optimiser"]
    assert 1 <= record["iterations"] <= table["optimise"]["default"]
