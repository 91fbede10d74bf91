"""The GUI's waits on a meshing job: a cancellable progress dialog around a job (the recompute
of a mesh object while the GUI is up) and the question asked before a mesh larger than the
object's ElementLimit. Gui only; Qt is imported where it is used, so that the document objects
can name these functions without loading Qt headless."""


def run_with_progress_dialog(job, title):
    """Runs ``job`` while a cancellable progress dialog keeps the GUI alive (FreeCAD's
    recompute of a mesh object when the GUI is up). Returns the mesh or raises the job's
    error. Escape or the dialog's Cancel cancels the job."""
    from PySide2 import QtCore, QtWidgets
    dialog = QtWidgets.QProgressDialog(title, "Cancel", 0, 1000, _main_window())
    dialog.setWindowTitle("HOMesh")
    dialog.setWindowModality(QtCore.Qt.WindowModal)  # no second recompute while this runs
    dialog.setMinimumDuration(300)
    dialog.canceled.connect(job.cancel)
    loop = QtCore.QEventLoop()
    timer = QtCore.QTimer()

    def tick():
        job.poll()
        dialog.setValue(int(1000 * job.fraction))
        dialog.setLabelText("%s\n%s %s (%.0f s)"
                            % (title, job.stage, job.detail, job.elapsed))
        if job.done:
            loop.quit()

    timer.timeout.connect(tick)
    job.start()
    timer.start(100)
    loop.exec_()
    timer.stop()
    job.poll()
    dialog.reset()
    dialog.deleteLater()
    if job.error is not None:
        raise job.error
    return job.result


def confirm_large_mesh(message):
    """Asks (GUI) whether to mesh although the predicted size exceeds the object's limit."""
    from PySide2 import QtWidgets
    answer = QtWidgets.QMessageBox.question(
        _main_window(), "HOMesh: large mesh", message + "\n\nMesh it anyway?",
        QtWidgets.QMessageBox.Yes | QtWidgets.QMessageBox.No, QtWidgets.QMessageBox.No)
    return answer == QtWidgets.QMessageBox.Yes


def _main_window():
    try:
        import FreeCADGui
        return FreeCADGui.getMainWindow()
    except Exception:  # noqa: BLE001 - no GUI: a dialog without parent
        return None
