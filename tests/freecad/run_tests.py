"""Runs the unittest modules of tests/freecad inside freecadcmd and exits 0 only if all pass.

Invoked as: freecadcmd -c "import runpy; runpy.run_path('tests/freecad/run_tests.py',
run_name='__main__')" (freecadcmd turns sys.exit's status into its own).
"""

import os
import sys
import unittest

here = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, here)
suite = unittest.defaultTestLoader.discover(here, pattern="test_*.py", top_level_dir=here)
result = unittest.TextTestRunner(verbosity=2, stream=sys.stdout).run(suite)
sys.stdout.flush()
sys.exit(0 if result.wasSuccessful() and result.testsRun > 0 else 1)
