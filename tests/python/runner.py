"""Runs one unittest module inside FreeCAD (FreeCADCmd, or the GUI under Xvfb) and exits with
its status. `freecadcmd script.py` exits 0 even when the script raises, so this runner ends
the process itself with os._exit and the real status.

Environment: TOPOPT_TEST_FILE = path of the test module to run.
"""
import os
import sys
import traceback
import unittest


def main():
    path = os.environ["TOPOPT_TEST_FILE"]
    sys.path.insert(0, os.path.dirname(path))
    sys.path.insert(0, os.path.dirname(os.path.abspath(os.path.dirname(path))))
    try:
        name = os.path.splitext(os.path.basename(path))[0]
        suite = unittest.defaultTestLoader.loadTestsFromName(name)
        result = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(suite)
        code = 0 if result.wasSuccessful() and result.testsRun > 0 else 1
    except BaseException:
        traceback.print_exc(file=sys.stdout)
        code = 2
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


main()
