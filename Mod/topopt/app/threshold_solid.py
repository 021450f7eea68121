"""Which threshold the result as a CAD solid is taken at (issue 23): "Result as solid" and
"Export STEP" follow the threshold slider. At the last run's threshold (RunThreshold) the
solid is the run's result.step; at another one the core writes the STEP of the shape there
from the stored densities (asbuilt.step_at_threshold)."""
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
    from . import asbuilt
    run = float(getattr(study, "RunThreshold", -1.0))
    if not 0.0 < run < 1.0:  # verification.json's record, else the study's current one
        recorded = asbuilt.run_threshold(study)
        run = recorded if recorded is not None else float(study.Threshold)
    return abs(threshold - run) < SAME
