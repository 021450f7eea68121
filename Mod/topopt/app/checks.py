"""Argument checks of the Python API, made before anything reaches the native core: numbers
finite and in range, index arrays non-negative and within their tables, lengths that match.
Each failure is a TopOptError (code "InvalidParameter") whose message names the argument or
property, the value and what to give instead.
"""
import math

import numpy as np

from .errors import TopOptError


def _fail(message):
    raise TopOptError(message, "InvalidParameter")


def number(value, name):
    """`value` as a finite float; `name` names it in the message."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        _fail("%s must be a number, not %r" % (name, value))
    if not math.isfinite(x):
        _fail("%s is %r: give a finite number" % (name, x))
    return x


def in_range(value, name, low=None, high=None, open_low=False, open_high=False):
    """`value` as a finite float within [low, high] (an open end excludes its bound; None: no bound)."""
    x = number(value, name)
    too_low = low is not None and (x <= low if open_low else x < low)
    too_high = high is not None and (x >= high if open_high else x > high)
    if too_low or too_high:
        left = "(" if open_low else "["
        right = ")" if open_high else "]"
        span = "%s%s, %s%s" % (left, "-inf" if low is None else "%g" % low, "inf" if high is None else "%g" % high,
                               right)
        _fail("%s is %g, outside %s: give a value in that range" % (name, x, span))
    return x


def nonfinite_key(value, path="job"):
    """The key path ("job.optimization.volume_fraction") of the first NaN or infinite number
    inside nested dicts and lists `value`, or None."""
    if isinstance(value, float) and not math.isfinite(value):
        return path
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        found = nonfinite_key(item, "%s.%s" % (path, key) if isinstance(key, str) else "%s[%d]" % (path, key))
        if found:
            return found
    return None


def job_text(job):
    """A job (dict or JSON text) as JSON text, every number finite."""
    if isinstance(job, str):
        return job
    bad = nonfinite_key(job)
    if bad:
        _fail("%s is not a finite number (NaN or infinite): give a number" % bad)
    import json
    return json.dumps(job, allow_nan=False)


def real_array(values, name, columns=None):
    """`values` as a float64 array, #rows by `columns` (None: 1-D), every entry finite."""
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        _fail("%s must be an array of numbers" % name)
    a = _check_shape(a, name, columns)
    bad = np.flatnonzero(~np.isfinite(a.reshape(-1)))
    if len(bad):
        _fail("%s: entry %d is %r: every value must be a finite number" % (name, bad[0], a.reshape(-1)[bad[0]]))
    return np.ascontiguousarray(a)


def index_array(values, name, limit, columns=None, what="rows"):
    """`values` as an int32 array, #rows by `columns` (None: 1-D), each index in [0, limit);
    `what` names the table it points into ("nodes")."""
    a = np.asarray(values)
    if a.size == 0:
        a = a.astype(np.int64)
    if not np.issubdtype(a.dtype, np.integer):
        if not np.issubdtype(a.dtype, np.floating) or not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
            _fail("%s must hold whole numbers (indices)" % name)
        a = a.astype(np.int64)
    a = _check_shape(a, name, columns)
    flat = a.reshape(-1)
    bad = np.flatnonzero((flat < 0) | (flat >= limit))
    if len(bad):
        row = bad[0] // (columns or 1)
        _fail("%s: row %d holds %d, but there are %d %s (indices 0 to %d)"
              % (name, row, flat[bad[0]], limit, what, limit - 1))
    return np.ascontiguousarray(a, dtype=np.int32)


def same_length(array, count, name, per):
    """Checks that `array` has `count` rows: one per `per` ("tet", "triangle")."""
    if len(array) != count:
        _fail("%s has %d entries for %d %ss: give one per %s" % (name, len(array), count, per, per))


def _check_shape(a, name, columns):
    """`a` with the expected layout (an empty array takes it); else the error."""
    if a.size == 0:
        return a.reshape((0,) if columns is None else (0, columns))
    if columns is None and a.ndim != 1:
        _fail("%s must be a flat list (1-D), not an array of shape %s" % (name, a.shape))
    if columns is not None and (a.ndim != 2 or a.shape[1] != columns):
        _fail("%s must have %d columns (an array #rows x %d), not shape %s" % (name, columns, columns, a.shape))
    return a


def stored_tets(study):
    """The analysis mesh a study stored (nodes #V x 3, tets #T x 4, domain #T), every index and
    length checked: a damaged or hand-edited document gives an error that says to mesh or run
    the study again."""
    try:
        return _stored_tets(study)
    except TopOptError as e:
        raise TopOptError("the mesh stored in %s is damaged (%s): mesh or run the study again"
                          % (study.Label, e), "InvalidParameter") from None


def stored_mesh(study):
    """The analysis mesh and densities a study stored at its last run, as arrays (nodes #V x 3,
    tets #T x 4, domain #T, densities #T), every index and length checked: a damaged or
    hand-edited document gives an error that says to run the study again."""
    try:
        nodes, tets, domain = _stored_tets(study)
        densities = real_array(study.Densities, "Densities")
        same_length(densities, len(tets), "Densities", "tet")
    except TopOptError as e:
        raise TopOptError("the result stored in %s is damaged (%s): run the study again"
                          % (study.Label, e), "InvalidParameter") from None
    return nodes, tets, domain, densities


def stored_boundary(study, node_count):
    """The boundary of the analysis mesh a study stored at its last run, as the worker's arrays
    ({"boundary_triangles" #F x 3, "boundary_faces" #F, "boundary_nondesign_faces" #F}), every
    index and length checked; {} when the study holds none (a document saved before it kept
    them): the threshold slider then cannot place the supports and loads, and says so."""
    if not getattr(study, "MeshBoundary", None):
        return {}
    try:
        flat = np.asarray(study.MeshBoundary, dtype=np.int64)
        if len(flat) % 3:
            _fail("MeshBoundary holds %d numbers, not three per triangle" % len(flat))
        triangles = index_array(flat.reshape(-1, 3), "MeshBoundary", node_count, 3, "nodes")
        faces = index_array(study.MeshBoundaryFaces, "MeshBoundaryFaces", 1 << 30)
        same_length(faces, len(triangles), "MeshBoundaryFaces", "triangle")
        nondesign = index_array(study.MeshBoundaryNonDesignFaces, "MeshBoundaryNonDesignFaces", 1 << 30)
        same_length(nondesign, len(triangles), "MeshBoundaryNonDesignFaces", "triangle")
    except TopOptError as e:
        raise TopOptError("the result stored in %s is damaged (%s): run the study again"
                          % (study.Label, e), "InvalidParameter") from None
    return {"boundary_triangles": triangles, "boundary_faces": faces, "boundary_nondesign_faces": nondesign}


def _stored_tets(study):
    nodes = real_array([[v.x, v.y, v.z] for v in study.MeshNodes], "MeshNodes", 3)
    flat = np.asarray(study.MeshTets, dtype=np.int64)
    if len(flat) == 0 or len(flat) % 4:
        _fail("MeshTets holds %d numbers, not four per tet" % len(flat))
    tets = index_array(flat.reshape(-1, 4), "MeshTets", len(nodes), 4, "nodes")
    domain = index_array(study.MeshDomains, "MeshDomains", 1 << 30)
    if len(domain) == 0:
        domain = np.zeros(len(tets), dtype=np.int32)
    same_length(domain, len(tets), "MeshDomains", "tet")
    return nodes, tets, domain
