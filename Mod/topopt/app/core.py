"""The native core's calls that stay in FreeCAD's process: small and safe ones on arrays a
script already holds, each with every argument checked here before it reaches C++ (indices in
range and non-negative, lengths that match, finite numbers), so that a wrong index gives a
TopOptError instead of taking FreeCAD down. Long or risky work (meshing shapes, runs, checks
of shapes, re-extraction of a study's result) goes through topopt.app.worker instead.
"""
from .. import native
from . import checks
from .errors import TopOptError


def _call(name, *args):
    core = native()
    try:
        return getattr(core, name)(*args)
    except core.TopOptError as e:
        raise TopOptError(str(e), getattr(e, "code", "Internal")) from None


def _tet_mesh(nodes, tets, domain):
    """Checked nodes #V x 3, tets #T x 4 and domain #T (empty: all design)."""
    nodes = checks.real_array(nodes, "nodes", 3)
    tets = checks.index_array(tets, "tets", len(nodes), 4, "nodes")
    if len(tets) == 0:
        raise TopOptError("tets is empty: give at least one tet", "InvalidParameter")
    domain = checks.index_array(domain if domain is not None else [], "domain", 1 << 30)
    if len(domain):
        checks.same_length(domain, len(tets), "domain", "tet")
    return nodes, tets, domain


def solve(nodes, tets, tris, tri_face, domain, job):
    """Linear static analysis on a tet mesh (the native `solve`), arguments checked first.

    nodes #V x 3 (mm), tets #T x 4 (0-based node numbers), tris #F x 3 boundary triangles with
    tri_face #F (FreeCAD face numbers, 1-based), domain #T (0 design, i non-design solid i; or
    empty), job: a job dict or its JSON text. Returns the native result dict (case_names,
    displacement, von_mises, compliance). Raises TopOptError naming the argument at fault.
    """
    nodes, tets, domain = _tet_mesh(nodes, tets, domain)
    tris = checks.index_array(tris, "tris", len(nodes), 3, "nodes")
    tri_face = checks.index_array(tri_face, "tri_face", 1 << 30)
    checks.same_length(tri_face, len(tris), "tri_face", "triangle")
    return _call("solve", nodes, tets, tris, tri_face, domain, checks.job_text(job))


def volume_mesh(nodes, triangles, size=0.0, delaunay_bulk=True):
    """Fills a closed surface (nodes #V x 3, triangles #F x 3, outward) with tets (the native
    `volume_mesh`), arguments checked first. size: target size in mm (0: from the boundary).
    Returns the native result dict (nodes, tets, seconds)."""
    nodes = checks.real_array(nodes, "nodes", 3)
    triangles = checks.index_array(triangles, "triangles", len(nodes), 3, "nodes")
    if len(triangles) < 4:
        raise TopOptError("triangles: a closed surface needs at least 4 triangles, got %d" % len(triangles),
                          "InvalidParameter")
    size = checks.in_range(size, "size", 0.0)
    return _call("volume_mesh", nodes, triangles, size, bool(delaunay_bulk))


def extract_surface(nodes, tets, domain, densities, threshold=-1.0, volume_fraction=-1.0,
                    smoothing_iterations=None, optimization=None):
    """The smoothed result shape of element densities (the native `extract_surface`),
    arguments checked first: nodes #V x 3, tets #T x 4, domain #T (or empty), densities #T
    (finite); a threshold in (0, 1), or a volume_fraction in (0, 1) whose threshold is found.
    optimization: the job's "optimization" section (dict or JSON text; job.study_optimization
    gives a study's), None for the defaults: with an overhang control the shape's too-flat
    downward facets are lifted as the run lifts them (a control standing the part on a base
    face cannot be placed on these arrays and raises). smoothing_iterations: None for the
    section's (20 by default).
    Returns (points #P x 3, triangles #Q x 3). Large meshes are better re-extracted through
    the worker (runner.reextract does)."""
    nodes, tets, domain = _tet_mesh(nodes, tets, domain)
    densities = checks.real_array(densities, "densities")
    checks.same_length(densities, len(tets), "densities", "tet")
    threshold = checks.number(threshold, "threshold")
    volume_fraction = checks.number(volume_fraction, "volume_fraction")
    if not 0 < threshold < 1 and not 0 < volume_fraction < 1:
        raise TopOptError("give a threshold in (0, 1) or a volume_fraction in (0, 1)", "InvalidParameter")
    smoothing = -1 if smoothing_iterations is None else int(
        checks.in_range(smoothing_iterations, "smoothing_iterations", 0, 1000))
    settings = checks.job_text(optimization) if optimization is not None else ""
    return _call("extract_surface", nodes, tets, domain, densities, threshold, volume_fraction, smoothing, settings)


def check_job(job):
    """Checks a job (a dict or its JSON text) as the core checks a job file before a run,
    without reading shapes or running anything. Raises TopOptError naming the key at fault."""
    return _call("check_job", checks.job_text(job))
