"""GUI test, run by FreeCAD itself under Xvfb (see tests/CMakeLists.txt). It checks, and saves
screenshots of (to $HOMESH_SCREENSHOT_DIR):

1. The toolbar command "High-order mesh" on a box with a hole opens the task panel, which
   meshes on a worker thread: the command returns with the job running on a thread other
   than the GUI's, a QTimer on the GUI thread keeps firing while the job runs and sees it at
   several points of its progress, the progress bar rises at least 5 times during the
   optimiser, and the job ends with a valid mesh applied to the object (panel.png during the
   run, histogram.png). These are counts of events, not durations: the largest gap between
   the timer's firings is printed, and bench/gui_responsiveness records it.
2. The mesh is drawn in the quality colours with its legend (view.png, window.png).
3. The task panels are their .ui files' forms (Resources/ui/), with labels, ranges, tooltips
   and values filled from the parameter table. Stop (and Escape) during an order-6 job ends it with CancelledError and leaves the object
   exactly as it was (the latency is printed, not asserted); the sizing panel predicts for typed values before applying them, and the size
   field is drawn (sizing.png).
4. A mesh with invalid elements carries the warning icon and Status, and Show "Invalid
   elements" draws them alone (invalid.png, invalid_window.png).
5. A boundary layer picked on the hole's face, recomputed behind the progress dialog
   (layer.png).
6. "Curve FEM mesh" on FEM's Gmsh mesh of a cylinder, then "To FEM mesh" of the result.

FreeCAD's GUI never exits by itself, so the script ends with os._exit(status).
"""

import os
import sys
import time
import traceback

status = 1
try:
    import FreeCAD
    import FreeCADGui
    from PySide2 import QtCore, QtGui, QtWidgets

    out = os.environ.get("HOMESH_SCREENSHOT_DIR", os.getcwd())
    os.makedirs(out, exist_ok=True)

    assert "HOMeshWorkbench" in FreeCADGui.listWorkbenches(), "workbench not registered"
    FreeCADGui.activateWorkbench("HOMeshWorkbench")

    sys.path.insert(0, os.path.join(os.environ["HOMESH_TESTS_DIR"], "freecad"))
    from fixtures import box_with_hole
    import homesh.freecad
    from homesh.freecad import arguments, commands

    app = QtWidgets.QApplication.instance()
    window = FreeCADGui.getMainWindow()

    def settle(n=10):
        for _ in range(n):
            app.processEvents()

    def grab_window(name):
        settle()
        QtWidgets.QApplication.primaryScreen().grabWindow(window.winId()).save(
            os.path.join(out, name))

    def stage():
        return getattr(getattr(commands.active_panel(), "job", None), "stage", "")

    def progress():
        return getattr(getattr(commands.active_panel(), "job", None), "stage_fraction", 0.0)

    def run_until(condition, during=None, running=None):
        """Runs the GUI's event loop until condition() holds (a hang is ended by the `timeout`
        CTest runs this script under, never by a clock here); returns the largest gap between
        the firings of a 50 ms QTimer while running() (default: throughout; printed only), the
        number of firings, and the number of distinct (stage, progress) states of the job those
        firings saw."""
        stamps = []
        timer = QtCore.QTimer()
        timer.setInterval(50)
        timer.timeout.connect(lambda: stamps.append((time.monotonic(), stage(), progress()))
                              if running is None or running() else None)
        timer.start()
        while not condition():
            app.processEvents(QtCore.QEventLoop.AllEvents, 20)
            if during is not None and during():
                stamps.append(None)  # the test itself was busy (a screenshot): not a gap
            time.sleep(0.005)
        timer.stop()
        gaps = [(b[0] - a[0], b[1]) for a, b in zip(stamps, stamps[1:])
                if a is not None and b is not None]
        worst = max(gaps) if gaps else (0.0, "")
        if worst[0] > 0.1:
            print("HOMesh GUI: largest gap %.3f s, during %s" % worst)
        seen = {t[1:] for t in stamps if t is not None}
        return worst[0], sum(1 for t in stamps if t is not None), len(seen)

    from homesh.api import parameters
    TABLE = {p["property"]: p for p in parameters() if p["property"]}

    def check_form_from_table(panel, form_name, obj, prop):
        """The panel is its .ui file's form (the root's name is stated there alone) and the
        widget of ``prop`` shows the parameter table's label, range, doc and the object's
        value."""
        assert panel.form.objectName() == form_name, panel.form.objectName()
        p = TABLE[prop]
        widget = panel.widgets[prop]
        label = panel.form.findChild(QtWidgets.QLabel, prop + "Label")
        expected = p["label"][:1].upper() + p["label"][1:]
        assert label is not None and label.text() == expected, (prop, label and label.text())
        high = p["max"] if p["max"] != float("inf") else 1e9
        assert widget.maximum() == min(high, 2 ** 31 - 1), (prop, widget.maximum(), p["max"])
        assert p["doc"] in widget.toolTip() and p["range"] in widget.toolTip(), widget.toolTip()
        value = getattr(obj, prop)
        assert widget.value() == float(getattr(value, "Value", value)), (prop, widget.value())
        print("HOMesh GUI: %s from %s: %s %r, up to %g" % (prop, form_name, expected,
                                                          widget.value(), widget.maximum()))

    doc = FreeCAD.newDocument("Smoke")
    cut = box_with_hole(doc)
    view = FreeCADGui.ActiveDocument.ActiveView
    view.viewIsometric()

    # 1. The command opens the panel, which meshes on a worker thread. -------------------------
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cut)
    FreeCADGui.runCommand("HOMesh_HighOrderMesh")
    panel = commands.active_panel()
    assert panel is not None, "the command opened no task panel"
    job = panel.job
    assert job is not None and job.running, "the panel did not start meshing"
    import threading
    assert job._thread is not threading.main_thread(), "the job runs on the GUI thread"
    meshes = [o for o in doc.Objects if getattr(o, "Proxy", None) is not None
              and getattr(o.Proxy, "Type", "") == "HOMesh::HighOrderMesh"]
    assert len(meshes) == 1, "the command made %d mesh objects" % len(meshes)
    mesh = meshes[0]
    shot = {"taken": False}

    def panel_shot():
        if not shot["taken"] and job.stage == "optimise" and job.stage_fraction > 0.2:
            shot["taken"] = True
            grab_window("panel.png")
            return True
        return False

    gap, ticks, states = run_until(lambda: job.done, panel_shot, lambda: job.running)
    t0 = time.monotonic()
    run_until(lambda: not panel.timer.isActive())
    print("HOMesh GUI: applying the result to the document took %.3f s"
          % (time.monotonic() - t0))
    print("HOMesh GUI: job of %.1f s; GUI timer fired %d times at %d states of the job, "
          "largest gap %.3f s" % (job.elapsed, ticks, states, gap))
    # The GUI thread's event loop ran while the job progressed: its timer fired at three or
    # more distinct points of the job's progress (a job on the GUI thread would let it fire
    # at most before and after).
    assert states >= 3, "the GUI's timer saw the job at only %d states" % states
    assert job.error is None, "the job failed: %s" % job.error
    rises = [v for stage, v in panel.progress_values if stage.startswith("optimise")]
    rises = sum(1 for a, b in zip(rises, rises[1:]) if b > a)
    print("HOMesh GUI: the progress bar rose %d times during the optimiser (%d sweeps)"
          % (rises, panel.log.toPlainText().count("optimise sweep")))
    assert rises >= 5, "the progress bar rose only %d times during the optimiser" % rises
    assert mesh.isValid() and mesh.NumElements > 0 and mesh.Order == 4
    assert mesh.InvalidElements == 0 and "Touched" not in mesh.State, mesh.State
    assert not cut.ViewObject.Visibility, "the meshed shape should be hidden"
    assert "all elements proven valid" in panel.summary.text()
    assert panel.log.toPlainText().count("sweep") >= 5, "the log misses the optimiser's sweeps"
    panel.canvas.grab().save(os.path.join(out, "histogram.png"))
    print("HOMesh GUI: %d nodes, %d elements, worst scaled Jacobian %.3f"
          % (mesh.NumNodes, mesh.NumElements, mesh.MinScaledJacobian))
    FreeCADGui.Control.closeDialog()
    settle()

    # 2. The coloured mesh and its legend. --------------------------------------------------------
    view.viewIsometric()
    view.fitAll()
    settle()
    view_png = os.path.join(out, "view.png")
    view.saveImage(view_png, 800, 600, "White")
    grab_window("window.png")
    image = QtGui.QImage(view_png)

    def coloured(x_range, y_range, test):
        hits = total = 0
        for y in range(y_range[0], y_range[1], 2):
            for x in range(x_range[0], x_range[1], 2):
                c = QtGui.QColor(image.pixel(x, y))
                total += 1
                hits += bool(test(c))
        return hits / float(max(total, 1))

    def greenish(c):
        return c.green() > 60 and c.green() > c.blue() + 40

    mesh_part = coloured((80, 800), (0, 600), greenish)
    print("HOMesh GUI: %.0f %% of the view (beside the legend) shows the mesh"
          % (100 * mesh_part))
    # The fitted isometric view of the 4 x 4 x 2 part fills about a third of the image; a view
    # without the mesh has no such pixels at all.
    assert mesh_part > 0.15, "the mesh is not visible in the 3D view"
    # The legend's bar (viewproviders.LEGEND_BOX, in -1..1 view coordinates) in the 800 x 600
    # image: its top band (1, green) and its bottom band (0, red), a few pixels inside each.
    from homesh.freecad.viewproviders import LEGEND_BOX, LEGEND_STEPS
    x0, x1, y0, y1 = LEGEND_BOX
    band = (y1 - y0) / LEGEND_STEPS

    def pixels(lo, hi, size):
        return int((lo + 1) / 2 * size) + 3, int((hi + 1) / 2 * size) - 3

    columns = pixels(x0, x1, 800)
    top = coloured(columns, pixels(-y1, -(y1 - band), 600), greenish)
    bottom = coloured(columns, pixels(-(y0 + band), -y0, 600),
                      lambda c: c.red() > 150 and c.green() < 90)
    print("HOMesh GUI: legend: %.0f %% green at its top, %.0f %% red at its bottom"
          % (100 * top, 100 * bottom))
    assert top > 0.8 and bottom > 0.8, "no colour legend in the view"

    # 3. Stop during a longer job: the document stays as it was. ----------------------------------
    def state(obj):
        return {p: str(getattr(obj, p)) for p in obj.PropertiesList if p != "Proxy"}

    before = state(mesh)
    nodes_before = homesh.freecad.get_mesh(mesh).nodes.copy()
    FreeCADGui.ActiveDocument.setEdit(mesh.Name)
    panel = commands.active_panel()
    for prop in ("Order", "OptimiserIterations", "JobTimeLimit"):
        check_form_from_table(panel, "HighOrderMeshPanel", mesh, prop)
    panel.form.grab().save(os.path.join(out, "task_panel.png"))
    flag = panel.flags["SolidsOnly"]
    assert flag.text() == "Solids only" == TABLE["SolidsOnly"]["label"].capitalize()
    assert TABLE["SolidsOnly"]["doc"] in flag.toolTip(), flag.toolTip()
    panel.widgets["Order"].setValue(6)
    job = panel.mesh()
    assert job is not None
    run_until(lambda: job.stage.startswith("optimise") or job.done)
    assert not job.done, "the job ended before the optimiser: %s" % job.error
    time.sleep(0.3)
    t0 = time.monotonic()
    panel.stop_button.click()
    run_until(lambda: job.done)
    stop_seconds = time.monotonic() - t0
    run_until(lambda: not panel.timer.isActive())
    # bench/gui_responsiveness reads this line.
    print("HOMesh GUI: Stop ended the job in %.3f s (%s)" % (stop_seconds, job.error))
    assert isinstance(job.error, homesh.CancelledError), job.error
    assert state(mesh) == before, "cancelling changed the object"
    assert (homesh.freecad.get_mesh(mesh).nodes == nodes_before).all()
    assert "Touched" not in mesh.State and mesh.Order == 4
    assert "the document is unchanged" in panel.log.toPlainText()
    # Escape does the same as Stop.
    job = panel.mesh()
    run_until(lambda: job.stage.startswith("optimise") or job.done)
    assert not job.done, "the job ended before the optimiser: %s" % job.error
    t0 = time.monotonic()
    field = panel.widgets["Order"]
    field.setFocus()
    for kind in (QtCore.QEvent.KeyPress, QtCore.QEvent.KeyRelease):
        app.sendEvent(field, QtGui.QKeyEvent(kind, QtCore.Qt.Key_Escape, QtCore.Qt.NoModifier))
    run_until(lambda: job.done)
    print("HOMesh GUI: Escape ended the job in %.3f s" % (time.monotonic() - t0))
    assert isinstance(job.error, homesh.CancelledError), job.error
    assert state(mesh) == before, "cancelling with Escape changed the object"
    # The CAD check's switches are check boxes whose values reach the job's arguments.
    assert panel.flags["Heal"].isChecked() and not panel.flags["SolidsOnly"].isChecked()
    panel.flags["SolidsOnly"].setChecked(True)
    assert arguments.mesh_arguments(mesh, panel.values())["solids_only"] is True
    panel.flags["SolidsOnly"].setChecked(False)
    FreeCADGui.Control.closeDialog()
    settle()

    # The sizing panel predicts for the values typed, without touching the object.
    sizing = homesh.freecad.make_sizing(doc, cut)
    doc.recompute()
    FreeCADGui.ActiveDocument.setEdit(sizing.Name)
    sizing_panel = commands.active_panel()
    for prop in ("Eps", "MaxDelta"):
        check_form_from_table(sizing_panel, "SizingPanel", sizing, prop)
    sizing_panel.form.grab().save(os.path.join(out, "sizing_panel.png"))
    default_count = sizing.PredictedElements
    sizing_panel.widgets["MaxDelta"].setValue(0.2)
    finer = sizing_panel.predict()
    print("HOMesh GUI: sizing panel: %d predicted with MaxDelta 0.2 (object: %d)"
          % (finer, default_count))
    assert finer > 2 * default_count and sizing.PredictedElements == default_count
    assert sizing_panel.result.text().startswith("%d elements predicted (sizes " % finer), \
        sizing_panel.result.text()
    sizing_panel.apply()
    assert sizing.MaxDelta.Value == 0.2 and sizing.PredictedElements == finer
    FreeCADGui.Control.closeDialog()
    # The size field is drawn: a point per octree leaf inside or on the shape.
    drawn = sizing.ViewObject.Proxy.coords.point.getNum()
    print("HOMesh GUI: size field: %d leaves drawn" % drawn)
    assert drawn > 100
    mesh.ViewObject.Visibility = False
    view.fitAll()
    settle()
    view.saveImage(os.path.join(out, "sizing.png"), 800, 600, "White")
    mesh.ViewObject.Visibility = True
    doc.removeObject(sizing.Name)
    settle()

    # 4. Invalid elements: a warning in the tree and the report, drawn alone. ---------------------
    bad = homesh.freecad.make_high_order_mesh(doc, cut, order=4, size=3.0, name="Coarse")
    bad.OptimiserIterations = 0
    bad.RepairRounds = 0
    doc.recompute()  # behind the cancellable progress dialog
    settle()
    print("HOMesh GUI: coarse mesh: %s" % bad.Status)
    assert bad.InvalidElements > 0 and "NOT VALID" in bad.Status
    assert " at Face" in bad.Status, bad.Status  # where on the part, from the core's note
    assert bad.ViewObject.Proxy.getIcon().endswith("homesh_mesh_invalid.svg")
    mesh.ViewObject.Visibility = False
    bad.ViewObject.Show = "Invalid elements"
    drawn = len(bad.ViewObject.Proxy.faces.coordIndex) // 4
    print("HOMesh GUI: invalid elements drawn alone: %d sub-triangles" % drawn)
    assert drawn > 0
    view.fitAll()
    settle()
    view.saveImage(os.path.join(out, "invalid.png"), 800, 600, "White")
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(bad)
    grab_window("invalid_window.png")
    FreeCADGui.Selection.clearSelection()
    doc.removeObject(bad.Name)  # the layer command links to the shape's only mesh
    mesh.ViewObject.Visibility = True

    # 5. A boundary layer on the hole, picked in the selection. ----------------------------------
    (hole,) = [i + 1 for i, f in enumerate(cut.Shape.Faces)
               if f.Surface.__class__.__name__ == "Cylinder"]
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(cut, "Face%d" % hole)
    FreeCADGui.runCommand("HOMesh_BoundaryLayer")
    assert mesh.BoundaryLayer is not None, "the command did not link the layer to the mesh"
    assert mesh.isValid() and mesh.InvalidElements == 0, "the mesh with a layer is not valid"
    prisms = homesh.freecad.get_mesh(mesh).report()["elements"]["prism"]
    assert prisms > 0, "no prisms in the mesh"
    print("HOMesh GUI: with a boundary layer: %d elements (%d prisms), worst %.3f"
          % (mesh.NumElements, prisms, mesh.MinScaledJacobian))
    view.viewTop()
    view.fitAll()
    settle()
    view.saveImage(os.path.join(out, "layer.png"), 800, 600, "White")

    # 6. FEM both ways through the commands: curve FEM's Gmsh mesh of a cylinder, then make a
    # FEM mesh object of the result. -------------------------------------------------------------
    import shutil
    if shutil.which("gmsh"):
        from test_fem import gmsh_fem_mesh
        cyl = doc.addObject("Part::Cylinder", "Cylinder2")
        cyl.Radius, cyl.Height = 1.0, 2.0
        cyl.Placement.Base = FreeCAD.Vector(10, 0, 0)
        doc.recompute()
        femmesh = gmsh_fem_mesh(doc, cyl)
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(femmesh)
        assert FreeCADGui.Command.get("HOMesh_CurveFemMesh").isActive()
        FreeCADGui.runCommand("HOMesh_CurveFemMesh")
        panel = commands.active_panel()
        job = panel.job
        run_until(lambda: job.done and not panel.timer.isActive())
        curved = panel.obj
        print("HOMesh GUI: curved FEM mesh: %s" % curved.Status)
        assert job.error is None and curved.InvalidElements == 0 and curved.UndecidedElements == 0
        assert curved.NumElements == femmesh.FemMesh.VolumeCount
        # Curving a FEM mesh runs no CAD check: its switches are shown greyed out.
        assert not any(flag.isEnabled() for flag in panel.flags.values()), panel.flags
        FreeCADGui.Control.closeDialog()
        settle()
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.Selection.addSelection(curved)
        FreeCADGui.runCommand("HOMesh_ToFemMesh")
        made = [o for o in doc.Objects if o.Name.endswith("_FEM") or o.Label.endswith("_FEM")]
        assert made and made[-1].FemMesh.VolumeCount == curved.NumElements, made
        print("HOMesh GUI: To FEM mesh: %d nodes, %d quadratic tetrahedra"
              % (made[-1].FemMesh.NodeCount, made[-1].FemMesh.VolumeCount))
    status = 0
except Exception:
    traceback.print_exc()
finally:
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
