"""The result as a CAD solid at the study's current threshold (issue 23): "Result as solid" and
"Export STEP" follow the threshold slider.

At the last run's threshold (RunThreshold) the solid is the run's result.step (analytic faces
where the part's faces are kept). At another threshold, where the slider left it, the solid is
made from the result shape at that threshold: the shown result mesh when it is at that
threshold, else the shape the worker extracts there; its triangles become the faces of one
closed shell (no analytic faces: FreeCAD's mesh-to-shape conversion). A core path that writes a
result.step for any threshold can take the place of that conversion without changing callers.
"""
from .errors import TopOptError

#: thresholds closer than this are the same one (the slider moves in steps of 0.01)
SAME = 0.005


def chosen(study, threshold=None):
    """The threshold to use: `threshold`, or the study's current one (where the slider left
    it) when None. Raises TopOptError for a value outside (0, 1) or a study without a result."""
    t = float(study.Threshold) if threshold is None else threshold
    try:
        t = float(t)
    except (TypeError, ValueError):
        raise TopOptError("the threshold must be a number in (0, 1), not %r" % (threshold,),
                          "InvalidParameter") from None
    if not 0.0 < t < 1.0:
        if threshold is None:
            raise TopOptError("the study has no result yet: run it first", "InvalidParameter")
        raise TopOptError("the threshold must lie strictly between 0 and 1 (it is %g)" % t, "InvalidParameter")
    return t


def is_the_runs(study, threshold):
    """True when `threshold` is the one the last run's result.step was written at (documents
    of older versions, which did not record it: the study's current Threshold)."""
    run = float(getattr(study, "RunThreshold", -1.0))
    if not 0.0 < run < 1.0:
        run = float(study.Threshold)
    return abs(threshold - run) < SAME


def _mesh_at(study, threshold, cancel=None):
    """A Mesh.Mesh of the result shape at `threshold`: the shown result's when it is there."""
    from . import runner
    if study.Result is not None and abs(float(study.Threshold) - threshold) < SAME:
        return study.Result.Mesh
    result = runner.extract_at(study, threshold, cancel)
    return runner.result_mesh(result["surface_points"], result["surface_triangles"])


def solid_at(study, threshold, cancel=None):
    """One closed solid (Part.Solid) of the study's result shape at `threshold`, its triangles
    as planar faces. Raises TopOptError if the study has no result, if the worker fails, or if
    the triangles do not close into one valid solid (saying what to try)."""
    import Part
    from . import quiet
    mesh = _mesh_at(study, threshold, cancel)
    with quiet.no_progress_lines():
        shape = Part.Shape()
        shape.makeShapeFromMesh(mesh.Topology, 1e-7)
        try:
            solid = Part.Solid(Part.Shell(shape.Faces))
        except Exception as e:  # OCCT refused the shell: FreeCAD raises its own exception types
            raise TopOptError("the result shape at threshold %.2f does not close into a solid (%s): move the "
                              "threshold slider a little and try again" % (threshold, e), "InvalidShape") from None
    if solid.Volume < 0:
        solid.complement()
    if not solid.isValid() or not solid.Volume > 0:
        raise TopOptError("the result shape at threshold %.2f is not a valid solid: move the threshold slider a "
                          "little and try again" % threshold, "InvalidShape")
    return solid
