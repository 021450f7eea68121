"""The Debian package (scripts/package, CPack): built, its control data and contents checked,
and its files, unpacked into a fresh FreeCAD user home's Mod folder as dpkg would lay them
under /usr/share/freecad/Mod, load in FreeCADCmd and run a study; and, where the test runs as
root and may make a private mount namespace, the package installed with dpkg and FreeCAD's GUI
started, which lists the workbench. Runs with /usr/bin/python3 (ctest: install.deb). The
system is never changed: that install happens under copy-on-write overlays of /usr, /etc and
/var/lib/dpkg that exist only in the test's own mount namespace and vanish with it.

Environment: TOPOPT_SOURCE (the repository), TOPOPT_PACKAGE_BUILD_DIR (where scripts/package
builds; default build-package/ in the repository), CCACHE_BASEDIR.
"""
import os
import shutil
import subprocess
import tempfile
import textwrap
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
        worker = [line for line in self.files.splitlines() if line.endswith("./%s/topopt/bin/topopt" % MOD)][0]
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
    print("@@package", os.path.normpath(topopt.__file__), topopt.core_problem())
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

    def test_dpkg_install_lists_the_workbench(self):
        if os.geteuid() != 0 or shutil.which("unshare") is None:
            self.skipTest("installing with dpkg needs root and unshare (a private mount namespace)")
        probe = subprocess.run(["unshare", "-m", "--propagation", "private", "true"], stderr=subprocess.PIPE)
        if probe.returncode != 0:
            self.skipTest("no private mount namespace here: " + probe.stderr.decode().strip())
        out = subprocess.run(["unshare", "-m", "--propagation", "private", "bash", "-c", _INSTALL_AND_LIST,
                              "install", self.deb, self.tmp],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=900)
        log = out.stdout.decode("utf-8", "replace")
        self.assertEqual(out.returncode, 0, log)
        self.assertIn("Setting up freecad-topopt (%s)" % version(), log)
        with open(os.path.join(self.tmp, "listed.txt")) as f:
            listed = dict(line.rstrip("\n").split(" ", 1) for line in f)
        self.assertIn("TopOptWorkbench", listed["workbenches"].split(), listed)
        self.assertEqual(listed["active"], "TopOptWorkbench")
        self.assertEqual(os.path.normpath(listed["module"]), "/usr/share/freecad/Mod/TopOpt/topopt/__init__.py")
        self.assertEqual(listed["core_problem"], "None")
        self.assertIn("/usr/bin/topopt", log)  # the command-line tool on the PATH runs
        self.assertIn("usage: topopt", log)
        # the host never saw the package
        self.assertFalse(os.path.exists("/usr/share/freecad/Mod/TopOpt"))
        status = subprocess.run(["dpkg-query", "-W", "freecad-topopt"], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE)
        self.assertNotEqual(status.returncode, 0, status.stdout)


#: Run by bash in a private mount namespace with $1 = the .deb and $2 = a scratch folder:
#: overlays /usr, /etc and /var/lib/dpkg (their changes go to a tmpfs), installs the package
#: with dpkg, runs topopt from the PATH and starts FreeCAD's GUI under Xvfb with a fresh user
#: home, which writes $2/listed.txt (the workbenches it lists, the one activated, where topopt
#: was imported from and whether its core loads).
_INSTALL_AND_LIST = textwrap.dedent(r"""
    set -euo pipefail
    deb="$1"; tmp="$2"; ovl="$tmp/overlays"
    mkdir -p "$ovl"
    mount -t tmpfs tmpfs "$ovl"
    for d in usr etc var/lib/dpkg; do
      n="${d//\//_}"; mkdir -p "$ovl/$n.up" "$ovl/$n.work"
      mount -t overlay overlay -o "lowerdir=/$d,upperdir=$ovl/$n.up,workdir=$ovl/$n.work" "/$d"
    done
    dpkg -i "$deb"
    command -v topopt
    topopt --help 2>&1 | head -n 3 || true
    mkdir -p "$tmp/syshome/Mod"
    cat > "$tmp/list.py" <<PY
    import os
    import FreeCADGui
    import topopt
    with open("$tmp/listed.txt", "w") as out:
        out.write("workbenches %s\n" % " ".join(sorted(FreeCADGui.listWorkbenches())))
        FreeCADGui.activateWorkbench("TopOptWorkbench")
        out.write("active %s\n" % FreeCADGui.activeWorkbench().name())
        out.write("module %s\n" % topopt.__file__)
        out.write("core_problem %s\n" % topopt.core_problem())
    os._exit(0)
    PY
    export FREECAD_USER_HOME="$tmp/syshome" QTWEBENGINE_DISABLE_SANDBOX=1 QTWEBENGINE_CHROMIUM_FLAGS=--no-sandbox
    timeout 600 xvfb-run -a -s "-screen 0 1280x1024x24" freecad "$tmp/list.py" > "$tmp/freecad.log" 2>&1
    """)


if __name__ == "__main__":
    unittest.main()
