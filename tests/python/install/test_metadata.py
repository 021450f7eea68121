"""package.xml, what FreeCAD and its Addon Manager read: complete and in step with the project
(version as CMakeLists.txt and topopt.__version__ say, a real date, the licence file present,
repository and bug-tracker urls, dependencies, the icons present), and the repository fit to be
cloned into a Mod folder (Init.py and InitGui.py at its root, the package in Mod/topopt).
Runs with /usr/bin/python3 (ctest: install.metadata)."""
import datetime
import os
import re
import unittest
import xml.etree.ElementTree as ET

SOURCE = os.environ.get("TOPOPT_SOURCE", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
NS = {"p": "https://wiki.freecad.org/Package_Metadata"}


class PackageXml(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = ET.parse(os.path.join(SOURCE, "package.xml")).getroot()

    def text(self, path):
        return self.root.find(path, NS).text.strip()

    def test_version_is_the_projects(self):
        with open(os.path.join(SOURCE, "CMakeLists.txt")) as f:
            cmake = re.search(r"project\(TopOpt VERSION ([0-9.]+)", f.read()).group(1)
        with open(os.path.join(SOURCE, "Mod", "topopt", "__init__.py")) as f:
            package = re.search(r'__version__ = "([0-9.]+)"', f.read()).group(1)
        self.assertEqual(self.text("p:version"), cmake)
        self.assertEqual(package, cmake)

    def test_date_licence_urls_dependencies(self):
        date = datetime.date.fromisoformat(self.text("p:date"))
        self.assertLessEqual(date, datetime.date.today())
        licence = self.root.find("p:license", NS)
        self.assertEqual(licence.text.strip(), "LGPL-2.1-or-later")
        with open(os.path.join(SOURCE, licence.get("file"))) as f:
            self.assertIn("GNU LESSER GENERAL PUBLIC LICENSE", f.read(200))
        urls = {u.get("type"): u.text.strip() for u in self.root.findall("p:url", NS)}
        for kind in ("repository", "bugtracker"):
            self.assertTrue(urls.get(kind, "").startswith("https://"), kind)
        depends = [d.text.strip() for d in self.root.findall("p:depend", NS)]
        for dep in ("FEM", "Part", "Mesh", "numpy"):
            self.assertIn(dep, depends)

    def test_workbench_entry_and_icons(self):
        wb = self.root.find("p:content/p:workbench", NS)
        self.assertEqual(wb.find("p:classname", NS).text.strip(), "TopOptWorkbench")
        for icon in (self.text("p:icon"), wb.find("p:icon", NS).text.strip()):
            self.assertTrue(os.path.isfile(os.path.join(SOURCE, icon)), icon)
        subdir = os.path.join(SOURCE, wb.find("p:subdirectory", NS).text.strip())
        for name in ("Init.py", "InitGui.py"):
            self.assertTrue(os.path.isfile(os.path.join(subdir, name)), name)
        self.assertTrue(os.path.isfile(os.path.join(SOURCE, "Mod", "topopt", "__init__.py")))

    def test_qt_only_through_freecads_pyside(self):
        for folder, _, files in os.walk(os.path.join(SOURCE, "Mod", "topopt")):
            for name in files:
                if name.endswith(".py"):
                    with open(os.path.join(folder, name)) as f:
                        text = f.read()
                    self.assertNotRegex(text, r"\b(PySide2|PySide6|PyQt5|PyQt6)\b", name)
                    self.assertNotIn("QtWidgets", text, name)


if __name__ == "__main__":
    unittest.main()
