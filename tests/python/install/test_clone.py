"""Installing the FreeCAD way: the repository cloned as Mod/TopOpt into a fresh user home (what
FreeCAD's Addon Manager does) loads as a workbench; before its native core is built it says so
with the command that builds it; the menu command builds it in place (with progress) and the
workbench then works without a restart; a new FreeCADCmd imports it from the clone and runs a
study. Runs with /usr/bin/python3 (ctest: install.clone); FreeCAD runs as child processes.

Environment: TOPOPT_SOURCE (the repository: its HEAD commit is cloned). The build runs with
CCACHE_BASEDIR at the clone's parent folder, so that ccache reuses the objects of a build of
the same sources elsewhere.
"""
import os
import shutil
import signal
import subprocess
import tempfile
import textwrap
import unittest

SOURCE = os.environ.get("TOPOPT_SOURCE", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
GUI_ENV = {"QTWEBENGINE_DISABLE_SANDBOX": "1", "QTWEBENGINE_CHROMIUM_FLAGS": "--no-sandbox"}


def run_freecad(home, script, gui=False, timeout=1500):
    """Runs `script` (Python text; it ends FreeCAD itself with os._exit) in FreeCAD with the
    user home `home`; returns (exit status, output)."""
    path = os.path.join(home, "script.py")
    with open(path, "w") as f:
        f.write(textwrap.dedent(script))
    # the build in the clone reuses compiled objects: ccache hashes paths relative to its base
    env = dict(os.environ, FREECAD_USER_HOME=home, CCACHE_BASEDIR=os.path.join(home, "Mod"), **GUI_ENV)
    if gui:
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad", path]
    else:
        cmd = ["freecadcmd", "-c", "exec(open(%r).read())" % path]
    # its own session: on a timeout the whole group goes (FreeCAD, Xvfb, a build FreeCAD started)
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, cwd=home,
                         start_new_session=True)
    try:
        out, _ = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        out, _ = p.communicate()
        return "timeout", out.decode("utf-8", "replace")
    return p.returncode, out.decode("utf-8", "replace")


_PRELUDE = """
import os, sys, traceback
def done(ok):
    sys.stdout.flush()
    os._exit(0 if ok else 3)
"""


class CloneIntoMod(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.home = tempfile.mkdtemp(prefix="topopt-clone-home-")
        cls.clone = os.path.join(cls.home, "Mod", "TopOpt")
        head = subprocess.check_output(["git", "-C", SOURCE, "rev-parse", "HEAD"]).decode().strip()
        subprocess.check_call(["git", "clone", "-q", "--no-checkout", SOURCE, cls.clone])
        subprocess.check_call(["git", "-C", cls.clone, "checkout", "-q", head])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.home, ignore_errors=True)

    def test_1_unbuilt_clone_loads_and_says_how_to_build(self):
        code, out = run_freecad(self.home, _PRELUDE + """
try:
    import FreeCAD, FreeCADGui
    FreeCAD.ConfigSet("TopOptNoDialogs", "1")
    import topopt
    print("@@package", os.path.normpath(topopt.__file__))
    print("@@listed", "TopOptWorkbench" in FreeCADGui.listWorkbenches())
    FreeCADGui.activateWorkbench("TopOptWorkbench")
    print("@@commands", all(c in FreeCADGui.listCommands() for c in ("TopOpt_NewStudy", "TopOpt_BuildCore")))
    print("@@problem", (topopt.core_problem() or "").replace(chr(10), " "))
    done(True)
except Exception:
    traceback.print_exc()
    done(False)
""", gui=True)
        self.assertEqual(code, 0, out)
        self.assertIn("@@package %s" % os.path.join(self.clone, "Mod", "topopt", "__init__.py"), out)
        self.assertIn("@@listed True", out)
        self.assertIn("@@commands True", out)
        self.assertIn("native core is not built yet", out)
        self.assertIn("cd '%s' && scripts/build --workbench" % self.clone, out)

    def test_2_menu_builds_the_core_and_the_workbench_works_at_once(self):
        code, out = run_freecad(self.home, _PRELUDE + """
try:
    import FreeCAD, FreeCADGui, Part
    FreeCAD.ConfigSet("TopOptNoDialogs", "1")
    FreeCADGui.getMainWindow().show()
    FreeCADGui.activateWorkbench("TopOptWorkbench")
    import topopt
    from topopt.gui import build_core
    builds = []
    original = build_core.CoreBuild.run
    def run(self):
        result = original(self)
        builds.append(self.percent)
        return result
    build_core.CoreBuild.run = run
    FreeCADGui.runCommand("TopOpt_BuildCore")
    print("@@percent", builds)
    print("@@problem", topopt.core_problem())
    from topopt.app import api
    report = api.info(Part.makeBox(10, 10, 10))
    print("@@solids", report["part"]["solids"] if "part" in report else report)
    done(topopt.core_problem() is None)
except Exception:
    traceback.print_exc()
    done(False)
""", gui=True)
        self.assertEqual(code, 0, out)
        self.assertIn("@@percent [100]", out)
        self.assertIn("@@problem None", out)
        self.assertTrue(os.access(os.path.join(self.clone, "build", "workbench", "TopOpt", "topopt", "bin", "topopt"),
                                  os.X_OK))
        self.assertFalse(os.path.exists(os.path.join(self.clone, "build", "tests")))  # the workbench alone

    def test_3_headless_import_and_run_from_the_clone(self):
        code, out = run_freecad(self.home, _PRELUDE + """
try:
    import FreeCAD, Part
    import topopt
    from topopt.app import api
    print("@@native", os.path.normpath(topopt.native().__file__))
    doc = FreeCAD.newDocument("Clone")
    beam = doc.addObject("Part::Feature", "Beam")
    beam.Shape = Part.makeBox(40, 8, 8)
    doc.recompute()
    study = api.new_study(doc, beam, (), volume_fraction=0.4, mesh_size=4.0)
    study.MaxIterations = 3
    api.add_fixed(study, "Face1")
    api.add_force(study, "Face2", (0, 0, -50))
    result = api.run(study)
    print("@@solid", result.Mesh.isSolid(), study.FemResult is not None)
    done(True)
except Exception:
    traceback.print_exc()
    done(False)
""")
        self.assertEqual(code, 0, out)
        staged = os.path.join(self.clone, "build", "workbench", "TopOpt", "topopt")
        self.assertIn("@@native %s" % os.path.join(staged, "_native"), out)
        self.assertIn("@@solid True True", out)
        self.assertIn("TopOpt: meshing", out)  # the run's own lines, FreeCAD's progress lines left out
        self.assertNotIn("(100 %)", out[out.index("TopOpt: reading"):])


if __name__ == "__main__":
    unittest.main()
