"""The Debian package (scripts/package, CPack): built, its control data and contents checked,
and its files, unpacked into a fresh FreeCAD user home's Mod folder as dpkg would lay them
under /usr/share/freecad/Mod, load in FreeCADCmd and run a study. Runs with /usr/bin/python3
(ctest: install.deb); it does not install anything into the system.

Environment: TOPOPT_SOURCE (the repository), TOPOPT_PACKAGE_BUILD_DIR (where scripts/package
builds; default build-package/ in the repository), CCACHE_BASEDIR.
"""
import os
import shutil
import subprocess
import tempfile
import unittest

SOURCE = os.environ.get("TOPOPT_SOURCE", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
MOD = "usr/share/freecad/Mod/TopOpt"


def version():
    import re
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
        return re.search(r"project\(TopOpt VERSION ([0-9.]+)", f.read()).group(1)


class DebianPackage(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="topopt-deb-")
        # scripts/package builds in build-package/ beside build/, so ccache serves its objects
        out = subprocess.run([os.path.join(SOURCE, "scripts", "package")], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, timeout=3000)
        if out.returncode != 0:
            raise AssertionError("scripts/package failed:\n" + out.stderr.decode()[-3000:])
        cls.deb = out.stdout.decode().strip().splitlines()[-1]
        cls.files = subprocess.check_output(["dpkg-deb", "-c", cls.deb]).decode()
        cls.fields = {k: subprocess.check_output(["dpkg-deb", "-f", cls.deb, k]).decode().strip()
                      for k in ("Package", "Version", "Depends", "Architecture", "Section")}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_control_data(self):
        self.assertEqual(self.fields["Package"], "freecad-topopt")
        self.assertEqual(self.fields["Version"], version())
        self.assertEqual(self.fields["Architecture"], "amd64")
        depends = self.fields["Depends"]
        for dep in ("freecad (>= 0.20)", "python3-numpy", "python3 (>= 3.11)", "python3 (<< 3.12)"):
            self.assertIn(dep, depends)
        for lib in ("libocct-modeling-data", "libcholmod", "libgmsh", "libc6"):  # found by dpkg-shlibdeps
            self.assertTrue(any(d.strip().startswith(lib) for d in depends.split(",")), (lib, depends))

    def test_description_is_one_paragraph(self):
        description = subprocess.check_output(["dpkg-deb", "-f", self.deb, "Description"]).decode()
        self.assertNotIn(";", description)
        self.assertIn("SIMP topology optimisation", description)

    def test_contents(self):
        for path in ("Init.py", "InitGui.py", "package.xml", "LICENSE", "Resources/icons/TopOptRun.svg",
                     "topopt/__init__.py", "topopt/app/api.py", "topopt/gui/panels.py", "topopt/bin/topopt",
                     "topopt/_native.cpython-311-x86_64-linux-gnu.so"):
            self.assertIn("./%s/%s" % (MOD, path), self.files)
        self.assertIn("./usr/bin/topopt -> ../share/freecad/Mod/TopOpt/topopt/bin/topopt", self.files)
        self.assertNotIn("__pycache__", self.files)
        self.assertNotIn("/tests/", self.files)
        self.assertNotIn("/src/", self.files)
        worker = [line for line in self.files.splitlines() if line.endswith("topopt/bin/topopt")][0]
        self.assertTrue(worker.startswith("-rwxr-xr-x"), worker)

    def test_unpacked_workbench_loads_and_runs(self):
        root = os.path.join(self.tmp, "root")
        subprocess.check_call(["dpkg-deb", "-x", self.deb, root])
        home = os.path.join(self.tmp, "home")
        os.makedirs(os.path.join(home, "Mod"))
        os.symlink(os.path.join(root, MOD), os.path.join(home, "Mod", "TopOpt"))
        script = os.path.join(self.tmp, "check.py")
        with open(script, "w") as f:
            f.write("""import os, sys, traceback
try:
    import FreeCAD, Part, topopt
    from topopt.app import api
    print("@@package", topopt.__file__, topopt.core_problem())
    doc = FreeCAD.newDocument("Deb")
    beam = doc.addObject("Part::Feature", "Beam")
    beam.Shape = Part.makeBox(40, 8, 8)
    study = api.new_study(doc, beam, (), volume_fraction=0.4, mesh_size=4.0)
    study.MaxIterations = 3
    api.add_fixed(study, "Face1")
    api.add_force(study, "Face2", (0, 0, -50))
    print("@@solid", api.run(study, verbose=False).Mesh.isSolid())
    code = 0
except Exception:
    traceback.print_exc()
    code = 3
sys.stdout.flush()
os._exit(code)
""")
        p = subprocess.run(["freecadcmd", "-c", "exec(open(%r).read())" % script],
                           env=dict(os.environ, FREECAD_USER_HOME=home),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
        out = p.stdout.decode("utf-8", "replace")
        self.assertEqual(p.returncode, 0, out)
        self.assertIn("@@package %s None" % os.path.join(home, "Mod", "TopOpt", "topopt", "__init__.py"), out)
        self.assertIn("@@solid True", out)


if __name__ == "__main__":
    unittest.main()
