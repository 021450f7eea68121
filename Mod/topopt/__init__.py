"""TopOpt: topology optimisation for FreeCAD.

`topopt.app` is the headless API (FreeCADCmd or FreeCAD), `topopt.gui` the workbench's
commands and panels (imported only with the GUI). The compiled core is `topopt._native`, the
worker program `topopt/bin/topopt`.

Every path is found from this file, never from FreeCAD's own folders. Two layouts exist:

- installed (the staged build `build/workbench/TopOpt`, the .deb, `scripts/install-workbench`):
  `TopOpt/topopt/` (this package, with `_native` and `bin/topopt` inside) and `TopOpt/Resources/`;
- a clone of the repository in FreeCAD's Mod folder (`Mod/TopOpt`, what the Addon Manager
  makes): `TopOpt/Mod/topopt/` (this package, sources only), `TopOpt/Resources/`, and the
  compiled parts in the in-place build `TopOpt/build/workbench/TopOpt/topopt/`, which this
  package adds to its own search path so that `topopt._native` and the worker are found there.
"""
import os

__version__ = "0.1.0"


def package_dir():
    """The folder of this package (…/topopt)."""
    return os.path.dirname(os.path.abspath(__file__))


def source_root():
    """The repository's root when this package is the one of a clone (…/Mod/topopt inside a
    folder holding scripts/build and CMakeLists.txt), else None."""
    parent = os.path.dirname(package_dir())
    if os.path.basename(parent) != "Mod":
        return None
    root = os.path.dirname(parent)
    if os.path.isfile(os.path.join(root, "scripts", "build")) and os.path.isfile(os.path.join(root, "CMakeLists.txt")):
        return root
    return None


def build_package_dir():
    """Where the in-place build of a clone stages this package with its compiled parts
    (ROOT/build/workbench/TopOpt/topopt), or None outside a clone."""
    root = source_root()
    return os.path.join(root, "build", "workbench", "TopOpt", "topopt") if root else None


def _search_build():
    """Adds the in-place build's staged package to this package's search path, after the
    sources, so that `_native` (and only what the sources lack) is found there."""
    staged = build_package_dir()
    if staged and staged not in __path__:
        __path__.append(staged)


_search_build()


def resources_dir():
    """The workbench's Resources folder (icons): beside this package when installed, at the
    repository's root in a clone."""
    root = source_root()
    return os.path.join(root or os.path.dirname(package_dir()), "Resources")


def compiled_dirs():
    """The folders that may hold the compiled parts (`_native`, `bin/topopt`), in search order."""
    return [d for d in __path__ if os.path.isdir(d)]


def build_command():
    """The shell command that builds the compiled core in place (a clone), or None when this
    package was installed and cannot build itself."""
    root = source_root()
    if root is None:
        return None
    return "cd '%s' && scripts/build --workbench" % root


def _refresh_finders():
    """Forgets what Python's import system cached about the in-place build's folder, so that
    a core built while FreeCAD runs is found without a restart."""
    import importlib
    import sys
    for d in __path__:
        if sys.path_importer_cache.get(d, True) is None:
            del sys.path_importer_cache[d]
    importlib.invalidate_caches()


def core_problem():
    """None when the compiled core (`topopt._native`) imports and the worker program is
    there; otherwise a message for the user that says what is missing and how to get it
    (the build command for a clone, reinstalling for an installed workbench)."""
    _refresh_finders()
    missing = []
    try:
        from . import _native  # noqa: F401
    except ImportError as e:
        missing.append("the compiled module (%s)" % e)
    if not any(os.access(os.path.join(d, "bin", "topopt"), os.X_OK) for d in compiled_dirs()):
        missing.append("the worker program (topopt/bin/topopt)")
    if not missing:
        return None
    what = " and ".join(missing) + (" are" if len(missing) > 1 else " is")
    command = build_command()
    if command:
        return ("TopOpt's native core is not built yet: %s missing.\n\nBuild it once with\n\n    %s\n\n"
                "(or the menu Topology Optimization > Build the native core). The build needs CMake, a C++ "
                "compiler and the libraries that 'sudo scripts/setup --build-deps' installs on Debian or "
                "Ubuntu." % (what, command))
    return ("TopOpt's native core is missing or does not match this FreeCAD: %s missing. Install the "
            "TopOpt package for this system again." % what)


def native():
    """The compiled core, with a message that says what to do when it is missing."""
    import sys
    if __name__ + "._native" not in sys.modules:
        _refresh_finders()
    try:
        from . import _native
    except ImportError:
        raise ImportError(core_problem() or "TopOpt's compiled module does not import") from None
    return _native
