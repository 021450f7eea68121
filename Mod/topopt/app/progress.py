"""What the user sees of a worker call while it runs and after: the overall progress in %,
a label in the user's words for the current stage, one line per stage for headless runs,
and the run summary for the report view. Shared by the GUI (panel, status bar, progress
dialogs) and headless scripts; no FreeCAD GUI here.
"""
import contextlib
import math
import time

#: stage → what the user reads
TITLES = {
    "read": "reading the shapes",
    "brep": "checking the shapes",
    "mesh": "meshing",
    "simp": "optimising",
    "surface": "extracting the result shape",
    "solve": "analysing the last iterate",
    "write": "writing the results",
    "step": "writing the result as a STEP solid",
    "result": "result ready, verifying it",
    "verification": "verifying the result solid (meshing and analysing it)",
    "document": "updating the document",
}

#: operation → stage → (start, end) of the stage's share of the whole operation
SPANS = {
    "optimize": {"read": (0.0, 0.02), "brep": (0.02, 0.06), "mesh": (0.06, 0.40), "simp": (0.40, 0.90),
                 "surface": (0.90, 0.93), "solve": (0.93, 0.95), "write": (0.95, 0.96),
                 "step": (0.96, 0.97), "result": (0.97, 0.97), "verification": (0.97, 1.0)},
    "mesh": {"read": (0.0, 0.03), "brep": (0.03, 0.10), "mesh": (0.10, 0.95), "write": (0.95, 1.0)},
    "extract_surface": {"read": (0.0, 0.1), "surface": (0.1, 0.9), "write": (0.9, 1.0)},
    "info": {"read": (0.0, 0.2), "brep": (0.2, 1.0), "mesh": (0.2, 1.0)},
}


def stage_of(record):
    """The stage a worker record belongs to ('simp' for iterations). The mesher's first line
    ('checking the part …') is the shape check, reported before the checks' own lines."""
    if "iteration" in record:
        return "simp"
    stage = str(record.get("stage", ""))
    if stage == "mesh" and str(record.get("message", "")).startswith("checking"):
        return "brep"
    return stage


# The core's default stopping tolerance on the compliance's relative change (simp::SimpParams::
# tol_objective, docs/optimization.md); only the progress bar's estimate reads it here.
TOL_OBJECTIVE = 2e-4


def simp_fraction(iteration, max_iterations, compliances, tol_objective=TOL_OBJECTIVE):
    """How far SIMP has come, in [0, 1]: the larger of the share of the iteration cap used and
    how close the compliance's relative change per iteration is to the tolerance that stops
    the run (on a log scale), so that a run that converges early does not sit far from its end
    and then jump."""
    by_cap = iteration / float(max(1, max_iterations))
    by_change = 0.0
    if len(compliances) >= 2 and compliances[-1] != 0:
        change = abs(compliances[-1] - compliances[-2]) / abs(compliances[-1])
        if change > 0:
            by_change = math.log(change) / math.log(tol_objective)
        else:
            by_change = 1.0
    return min(1.0, max(0.0, by_cap, by_change))


class Tracker:
    """Follows one worker call: feed it every record with update(); read `fraction` (0–1,
    never going back), `label` (e.g. 'meshing: faces'), and `stages` (each stage with the
    seconds it took, in order)."""

    def __init__(self, operation="optimize", max_iterations=100, clock=time.monotonic):
        self.spans = SPANS.get(operation, SPANS["optimize"])
        self.max_iterations = max_iterations
        self.clock = clock
        self.started = clock()
        self.fraction = 0.0
        self.stage = None
        self.label = "starting"
        self.stages = []  # [stage, seconds]
        self.compliances = []
        self.last_iteration = None

    def update(self, record):
        """Takes one worker record; returns True when it starts a stage not seen before."""
        stage = stage_of(record)
        new = stage not in [s for s, _ in self.stages]
        if stage != self.stage:
            self._close_stage()
            if new:
                self.stages.append([stage, 0.0])
            self.stage, self.stage_started = stage, self.clock()
        start, end = self.spans.get(stage, (self.fraction, self.fraction))
        within = self._within(stage, record)
        self.fraction = max(self.fraction, start + (end - start) * within)
        self.label = self._label(stage, record)
        return new

    def _within(self, stage, record):
        if "iteration" in record:
            self.last_iteration = record
            self.compliances.append(float(record.get("compliance", 0.0)))
            return simp_fraction(int(record["iteration"]), self.max_iterations, self.compliances)
        f = record.get("fraction", -1)
        return min(1.0, float(f)) if isinstance(f, (int, float)) and f >= 0 else 0.0

    def _label(self, stage, record):
        title = TITLES.get(stage, stage)
        if "iteration" in record:
            return "%s: iteration %d of at most %d (compliance %.4g N·mm, volume %.3f)" % (
                title, record["iteration"], self.max_iterations, record.get("compliance", 0.0),
                record.get("volume", 0.0))
        message = str(record.get("message", ""))
        return "%s: %s" % (title, message) if message and message != title else title

    def _close_stage(self):
        if self.stage is not None:
            for entry in self.stages:
                if entry[0] == self.stage:
                    entry[1] += self.clock() - self.stage_started

    def finish(self):
        """Ends the last stage; returns the total seconds."""
        self._close_stage()
        self.stage = None
        self.fraction = 1.0
        return self.clock() - self.started

    @contextlib.contextmanager
    def timed(self, stage):
        """Counts the time spent inside as `stage` (work done after the worker, in FreeCAD)."""
        start = self.clock()
        try:
            yield
        finally:
            self.stages.append([stage, self.clock() - start])

    def percent(self):
        return int(round(100 * self.fraction))


def stage_line(stage, max_iterations=None):
    """The line a headless run prints when a stage starts."""
    title = TITLES.get(stage, stage)
    if stage == "simp" and max_iterations:
        return "TopOpt: %s (at most %d iterations)" % (title, max_iterations)
    return "TopOpt: %s" % title


def mesher_used(chosen, warnings):
    """The mesher that made the mesh: the study's choice, or Gmsh where 'auto' fell back to it
    (the core says so in a warning)."""
    if chosen == "auto":
        fell_back = any("Gmsh's OCC fragments instead" in str(w) for w in warnings)
        return "gmsh (auto: the native mesher could not close this mesh)" if fell_back else "native (auto)"
    return chosen


def run_summary(study, result, tracker, seconds):
    """The run summary for the report view: lines of text (time, iterations, compliance,
    volume, mesh and mesher, warnings, where the results are)."""
    history = result.get("history", [])
    last = history[-1] if history else {}
    times = ", ".join("%s %.1f s" % (TITLES.get(s, s), t) for s, t in tracker.stages if t >= 0.05)
    lines = ["TopOpt: %s finished in %.1f s (%s)" % (study.Label, seconds, times),
             "  iterations: %d (%s)" % (len(history), result.get("status", "")),
             "  compliance: %.6g N·mm; volume: %.3f of the design domain (asked %.3f)" % (
                 float(last.get("compliance", 0.0)), float(last.get("volume", 0.0)), float(study.VolumeFraction)),
             "  mesh: %d tets, %d nodes; mesher: %s" % (
                 len(result.get("tets", [])), len(result.get("nodes", [])),
                 mesher_used(str(getattr(study, "Mesher", "auto")), result.get("warnings", [])))]
    if "threshold" in result:
        lines.append("  result shape at density threshold %.3f" % float(result["threshold"]))
    warnings = result.get("warnings", [])
    lines.append("  warnings: %s" % ("; ".join(str(w) for w in warnings) if warnings else "none"))
    return lines
