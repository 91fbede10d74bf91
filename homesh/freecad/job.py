"""A meshing job on a worker thread, so FreeCAD's GUI keeps drawing and answering while the core
works (it runs with the GIL released).

The worker only calls :func:`homesh.mesh` on BRep text taken from the shape beforehand (FreeCAD
objects are touched on the GUI thread only); its progress goes into a queue that the GUI thread
drains with :meth:`MeshJob.poll` from a timer. :meth:`MeshJob.cancel` sets the core's cancel
token, which the core reads between stages, Gmsh's dimensions and the optimiser's colour
groups. Nothing here changes the document: whoever started the job applies the result.
"""

import os
import queue
import shutil
import tempfile
import threading
import time

import homesh

# Rough shares of the run per stage, for one overall percentage (the optimiser dominates when it
# runs); stages not listed (repair rounds) take the remainder.
_STAGE_WEIGHTS = {"cad": 2, "classify": 3, "sizing": 3, "linear": 10, "boundary_layer": 5, "high_order": 10,
                  "optimise_low_order": 20, "raise_order": 3, "optimise": 40, "quality": 4,
                  "boundary_fit": 3, "split_layers": 2, "geometry": 2}

_WORKER_NICENESS = 10


class MeshJob:
    """``MeshJob(brep_text, name, function, **arguments)`` (function: homesh.mesh by default, or
    homesh.curve); ``start()``, then ``poll()`` from the GUI
    thread until ``done``; ``result`` (a :class:`homesh.HighOrderMesh`) or ``error`` (the
    exception, :class:`homesh.CancelledError` after :meth:`cancel`)."""

    def __init__(self, brep_text, name, function=None, **arguments):
        self.brep_text = brep_text
        self.name = name
        self.function = function or homesh.mesh  # homesh.curve for a FEM mesh
        self.arguments = arguments
        self.token = homesh.CancelToken()
        self.events = queue.Queue()
        self.result = None
        self.npz_path = None  # the result written as .npz (by the worker), for the document
        self.folder = None
        self.error = None
        self.stage = ""
        self.detail = ""
        self.stage_fraction = 0.0
        self.log = []
        self._finished_weight = 0.0
        self._complete = False
        self._thread = None
        self._start = None
        self._end = None

    def start(self):
        self._start = time.monotonic()
        self._thread = threading.Thread(target=self._run, name="HOMesh " + self.name,
                                        daemon=True)
        self._thread.start()
        return self

    def _run(self):
        # Below the GUI's priority: the core keeps every core busy, and the GUI thread must
        # still get the processor at once when it has events to handle. Threads the core
        # starts from here (OpenMP's) inherit it. Linux applies niceness per thread.
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), _WORKER_NICENESS)
        except (AttributeError, OSError):
            pass
        try:
            self.result = self.function(self.brep_text, name=self.name,
                                        progress=self._progress, cancel=self.token,
                                        **self.arguments)
            # The document's copy of the mesh, compressed here rather than on the GUI thread.
            self.folder = tempfile.mkdtemp(prefix="homesh-")
            self.npz_path = os.path.join(self.folder, "mesh.npz")
            self.result.write(self.npz_path)
        except BaseException as e:  # noqa: B902 - handed to the GUI thread, never lost
            self.error = e
            self.result = None
        finally:
            self._end = time.monotonic()
            self.events.put(("done",))

    def _progress(self, stage, seconds, fraction, detail):
        # On the worker thread: only the queue is touched.
        self.events.put(("progress", stage, seconds, fraction, detail))

    def cancel(self):
        """Asks the core to stop; the job ends with CancelledError within a fraction of a
        second (Gmsh's meshing runs in a child process, which is then killed)."""
        self.token.cancel()

    @property
    def cancelled(self):
        return self.token.cancelled

    @property
    def running(self):
        return self._thread is not None and self._thread.is_alive()

    @property
    def done(self):
        return self._end is not None and not self.running

    @property
    def elapsed(self):
        if self._start is None:
            return 0.0
        return (self._end if self._end is not None else time.monotonic()) - self._start

    @property
    def fraction(self):
        """Estimated share of the whole job done, 0..1 (1 once poll() has seen it succeed: the
        stages a run skips, sizing or repair rounds, would otherwise leave it short)."""
        if self._complete:
            return 1.0
        total = sum(_STAGE_WEIGHTS.values())
        current = _STAGE_WEIGHTS.get(self.stage, 0) * self.stage_fraction
        return min(1.0, (self._finished_weight + current) / total)

    def poll(self):
        """Drains the progress queue (GUI thread): updates stage, detail, fractions and the log
        and returns the new log lines."""
        lines = []
        while True:
            try:
                event = self.events.get_nowait()
            except queue.Empty:
                break
            if event[0] != "progress":  # "done"
                self._complete = self.error is None
                continue
            _, stage, seconds, fraction, detail = event
            self.stage = stage
            self.stage_fraction = fraction
            if seconds is not None:
                self._finished_weight += _STAGE_WEIGHTS.get(stage, 0)
                self.stage_fraction = 0.0
                lines.append("%s: %.2f s" % (stage, seconds))
            elif detail:
                self.detail = detail
                lines.append("  " + detail)
            else:
                self.detail = ""
                lines.append("%s ..." % stage)
        self.log.extend(lines)
        return lines

    def discard_files(self):
        """Removes the worker's .npz copy (after the document has taken its own)."""
        if self.folder is not None:
            shutil.rmtree(self.folder, ignore_errors=True)
            self.folder = self.npz_path = None

    def wait(self, timeout=None):
        """Blocks until the worker ends (headless use)."""
        if self._thread is not None:
            self._thread.join(timeout)
        return self.done
