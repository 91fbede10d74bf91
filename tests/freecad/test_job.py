"""The meshing job on a worker thread, headless: the calling thread stays free while it runs,
its progress arrives through poll() in order (stages, then the optimiser's sweeps), cancel()
ends it with CancelledError at its next check (the latency is printed: a loaded machine decides
it, so no test asserts it; bench/gui_responsiveness measures it), and a finished job's mesh is
the one homesh.mesh makes with the same arguments."""

import threading
import time
import unittest

import FreeCAD

import homesh
import homesh.freecad
from homesh.freecad import meshing

from fixtures import box_with_hole


class MeshJobs(unittest.TestCase):
    def setUp(self):
        self.doc = FreeCAD.newDocument("HOMeshJob")
        self.part = box_with_hole(self.doc)
        self.obj = homesh.freecad.make_high_order_mesh(self.doc, self.part, order=4, size=0.8)
        self.obj.Threads = 2

    def tearDown(self):
        FreeCAD.closeDocument(self.doc.Name)

    def test_a_job_runs_beside_the_calling_thread_and_reports_its_sweeps(self):
        job = meshing.job_for(self.obj).start()
        self.assertIsNot(job._thread, threading.current_thread())
        polls = 0
        while not job.done:
            job.poll()
            polls += 1
            time.sleep(0.01)
        job.poll()
        self.assertIsNone(job.error)
        self.assertGreater(polls, 1)  # the caller ran while the job did
        stages = [line.split(" ...")[0] for line in job.log if line.endswith(" ...")]
        self.assertEqual(stages[:3], ["cad", "linear", "high_order"])
        self.assertIn("optimise", stages)
        sweeps = [line for line in job.log if "optimise sweep" in line]
        self.assertGreaterEqual(len(sweeps), 1)
        self.assertTrue(sweeps[0].strip().startswith("optimise sweep 1:"))
        self.assertEqual(job.fraction, 1.0)
        same = homesh.mesh(self.part.Shape, **job.arguments)
        self.assertEqual(same.num_elements, job.result.num_elements)
        self.assertEqual(same.quality()["min"], job.result.quality()["min"])
        job.discard_files()

    def test_gmsh_runs_in_a_child_that_a_time_limit_or_a_cancel_ends(self):
        # Gmsh 4.8 grinds on a needle-thin cone for tens of seconds, then crashes: in its own
        # process, a time limit or a Stop ends it and this process carries on.
        import Part
        needle = self.doc.addObject("Part::Feature", "Needle")
        needle.Shape = Part.makeCone(0.01, 0.0, 100.0)
        mesh = homesh.freecad.make_high_order_mesh(self.doc, needle, order=2)
        mesh.LinearTimeLimit = 2
        job = meshing.job_for(mesh).start()
        job.wait(900)  # a hang guard: wait() returns as soon as the job ends
        job.poll()
        # The message proves that the limit ended Gmsh: left alone it grinds on and crashes.
        self.assertIsInstance(job.error, homesh.MeshingError)
        self.assertIn("stopped at its time budget of 2 s", str(job.error))
        mesh.LinearTimeLimit = 600
        job = meshing.job_for(mesh).start()
        while job.stage != "linear" and not job.done:
            job.poll()
            time.sleep(0.01)
        time.sleep(0.5)  # inside Gmsh now
        start = time.monotonic()
        job.cancel()
        job.wait(900)
        job.poll()
        print("cancel inside Gmsh took %.3f s" % (time.monotonic() - start))
        # CancelledError proves the cancel ended it: Gmsh alone would crash (MeshingError).
        self.assertIsInstance(job.error, homesh.CancelledError)
        # The process is intact: the next job meshes.
        job = meshing.job_for(self.obj).start()
        job.wait(300)
        job.poll()
        self.assertIsNone(job.error)
        self.assertGreater(job.result.num_elements, 0)
        job.discard_files()

    def test_cancel_ends_the_job_at_its_next_check(self):
        self.obj.Order = 6  # long enough to be caught in the optimiser
        job = meshing.job_for(self.obj).start()
        while not job.stage.startswith("optimise") and not job.done:
            job.poll()
            time.sleep(0.01)
        self.assertFalse(job.done, "the job ended before the optimiser")
        start = time.monotonic()
        job.cancel()
        job.wait(900)
        print("cancel in the optimiser took %.3f s" % (time.monotonic() - start))
        self.assertTrue(job.done)
        self.assertIsInstance(job.error, homesh.CancelledError)
        self.assertIsNone(job.result)
        self.assertIsNone(job.npz_path)


if __name__ == "__main__":
    unittest.main()
