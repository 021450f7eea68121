"""The worker process: every long or risky call of the core (meshing, runs, re-extraction,
the checks of the shapes, surface meshes) runs in `topopt worker`, a program of its own, so
that a crash, an abort or a hang of OCCT, Gmsh or our code ends that process and never
FreeCAD. This is how FreeCAD FEM runs CalculiX and Gmsh.

run() writes the request (the job, the shapes as BREP files, arrays as NPY files) into a
temporary folder, starts the worker in its own process group, reads its progress lines in the
calling thread and hands them to on_progress, then loads the results and removes the folder.
Cancel (on_progress returning True, or cancel() returning True) kills the process group at
once. A worker that dies or stops answering becomes a TopOptError whose message names the
stage it was in and what to try.

The worker program travels with the package: topopt/bin/topopt beside this package's
__init__.py (the build stages it there).
"""
import json
import os
import select
import shutil
import signal
import subprocess
import tempfile
import time

import numpy as np

from .. import compiled_dirs, core_problem
from . import checks
from .errors import TopOptError

#: stage of the progress lines → (who fails there, what it was doing, what the user can try)
_STAGES = {
    "start": ("the TopOpt worker", "starting",
              "rebuild TopOpt (scripts/build) and install it again"),
    "read": ("the geometry kernel (OCCT)", "reading the shapes",
             "check the shapes with Part > Check geometry, or export them again"),
    "brep": ("the geometry kernel (OCCT)", "checking the shapes",
             "check the shapes with Part > Check geometry, or export them again"),
    "mesh": ("the mesher", "meshing",
             "try another mesher (the study's Mesher 'gmsh' or 'native') or another mesh size"),
    "solve": ("the solver", "solving", "try a coarser mesh size"),
    "simp": ("the optimiser", "optimising", "try a coarser mesh size or fewer iterations"),
    "surface": ("the result-shape extraction", "extracting the result shape",
                "try another threshold"),
    "step": ("the STEP export", "writing the result as a STEP solid",
             "raise the study's StepMaxTriangles (Output; the job's step_max_triangles), turn off its "
             "WriteStep or try another mesh size"),
    "verification": ("the verification", "meshing and analysing the result solid",
                     "turn off the study's Verify (Output) or try another mesh size"),
    "write": ("the TopOpt worker", "writing the results",
              "check that the temporary folder has free space"),
}


def executable():
    """The worker program staged with this package (topopt/bin/topopt; in a clone of the
    repository, the in-place build's)."""
    for folder in compiled_dirs():
        path = os.path.join(folder, "bin", "topopt")
        if os.access(path, os.X_OK):
            return path
    raise TopOptError(core_problem() or "TopOpt's worker program is missing", "Internal")


def _write_request(folder, operation, job, part, nondesign, arrays, params):
    """Writes the request and its inputs into `folder`; returns the request's path."""
    request = {"operation": operation, "output": "out", "params": dict(params or {})}
    if job is not None:
        request["job"] = json.loads(checks.job_text(job))
    for key, brep in (("part", part), ("nondesign", nondesign)):
        if brep:
            with open(os.path.join(folder, key + ".brep"), "w") as f:
                f.write(brep)
            request[key] = key + ".brep"
    request["arrays"] = {}
    for name, array in (arrays or {}).items():
        np.save(os.path.join(folder, name + ".npy"), np.ascontiguousarray(array))
        request["arrays"][name] = name + ".npy"
    path = os.path.join(folder, "request.json")
    with open(path, "w") as f:
        json.dump(request, f, allow_nan=False)
    return path


class _Progress:
    """Where the worker is: the stage, message and iteration of its last progress line."""

    def __init__(self):
        self.stage, self.message, self.iteration = "start", "", None

    def update(self, record):
        if "iteration" in record:
            self.stage, self.message, self.iteration = "simp", "", record["iteration"]
        elif "stage" in record:
            self.stage, self.message = str(record["stage"]), str(record.get("message", ""))

    def activity(self):
        """'meshing (faces)', 'optimising (iteration 3)', ..."""
        words = _STAGES.get(self.stage, ("", "the stage '%s'" % self.stage, ""))[1]
        detail = "iteration %d" % self.iteration if self.stage == "simp" and self.iteration else self.message
        return "%s (%s)" % (words, detail) if detail and detail != words else words

    def stalled_message(self, seconds):
        who, _, advice = _STAGES.get(self.stage, ("the TopOpt worker", "", "try other settings"))
        return "%s did not finish within %g s while %s and was stopped: %s; your document is unchanged" % (
            who, seconds, self.activity(), advice)

    def crash_message(self, how):
        who, _, advice = _STAGES.get(self.stage, ("the TopOpt worker", "", "try other settings"))
        return "%s crashed (%s) while %s: %s; your document is unchanged" % (who, how, self.activity(), advice)


def _how_it_ended(returncode):
    if returncode is not None and returncode < 0:
        try:
            name = signal.Signals(-returncode).name
        except ValueError:
            name = "signal %d" % -returncode
        return {"SIGSEGV": "access violation, SIGSEGV", "SIGABRT": "aborted, SIGABRT"}.get(name, name)
    return "it ended with exit code %s without an answer" % returncode


class _Worker:
    """One running worker process in its own process group, read line by line."""

    def __init__(self, request_path, folder):
        self.log_path = os.path.join(folder, "worker.log")
        with open(self.log_path, "wb") as log:
            self.proc = subprocess.Popen([executable(), "worker", request_path], stdin=subprocess.DEVNULL,
                                         stdout=subprocess.PIPE, stderr=log, cwd=folder,
                                         start_new_session=True)
        self.buffer = b""
        self.eof = False

    def exited(self):
        """True once the worker process has ended (it stays unreaped, so that its process group
        id cannot be reused before end() kills what is left of the group)."""
        return os.waitid(os.P_PID, self.proc.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None

    def read(self, wait):
        """The complete lines that arrive within `wait` seconds, and whether anything arrived
        (sets eof when the worker's end of the pipe is closed)."""
        fd = self.proc.stdout.fileno()
        ready, _, _ = select.select([fd], [], [], wait)
        chunk = os.read(fd, 1 << 16) if ready else b""
        self.eof = bool(ready) and not chunk
        self.buffer += chunk
        *complete, self.buffer = self.buffer.split(b"\n")
        return complete, bool(chunk)

    def wait_exit(self, seconds):
        """Waits up to `seconds` for the worker to end by itself (after its last line)."""
        deadline = time.monotonic() + seconds
        while not self.exited() and time.monotonic() < deadline:
            time.sleep(0.01)

    def end(self):
        """Kills the process group (the worker and anything it started) and reaps the worker.
        Returns the worker's exit status (negative: the signal that ended it)."""
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.proc.stdout.close()
        return self.proc.wait()

    def log_tail(self, lines=12):
        try:
            with open(self.log_path, "rb") as f:
                return b"\n".join(f.read().splitlines()[-lines:]).decode("utf-8", "replace")
        except OSError:
            return ""


def _parse(line):
    try:
        record = json.loads(line.decode("utf-8", "replace"))
    except ValueError:
        return None  # not a protocol line
    return record if isinstance(record, dict) else None


def _hand_over(record, on_progress):
    """Calls on_progress(record); True when it asks to cancel. Raises what the callback raises,
    and TopOptError when it returns something other than True, False or None."""
    if on_progress is None:
        return False
    answer = on_progress(record)
    if answer is None or isinstance(answer, (bool, np.bool_)):
        return bool(answer)
    raise TopOptError("the progress callback returned %r (%s): it must return True (cancel), False or None"
                      % (answer, type(answer).__name__), "InvalidParameter")


def _follow(worker, on_progress, cancel, timeout, on_result=None):
    """Reads the worker's lines until its last one; returns that final record (None if the
    worker ended without one) and where it was. on_result(): called when the worker says its
    result is ready ({"stage": "result"}) before it goes on. Raises TopOptError on cancel or
    timeout."""
    where = _Progress()
    deadline = time.monotonic() + timeout if timeout else None
    final = None
    while not worker.eof:
        ended = worker.exited()
        lines, more = worker.read(0 if ended else 0.05)
        for line in lines:
            record = _parse(line)
            if record is None or "warning" in record:
                continue
            if "done" in record or "error" in record:
                final = record
                continue
            where.update(record)
            if record.get("stage") == "result" and on_result is not None:
                on_result()
            if _hand_over(record, on_progress):
                raise TopOptError("cancelled while %s" % where.activity(), "Cancelled")
        if ended and not more:
            break  # nothing more to read, even if a child of the worker still holds the pipe
        if cancel is not None and cancel():
            raise TopOptError("cancelled while %s" % where.activity(), "Cancelled")
        if deadline is not None and time.monotonic() > deadline:
            raise TopOptError(where.stalled_message(timeout), "Timeout")
    return final, where


def _load(out):
    """result.json's values, its arrays (numpy) and, under "files", the contents (bytes) of
    the files it lists (an optimisation's result.step, verification.json and .vtu)."""
    with open(os.path.join(out, "result.json")) as f:
        result = json.load(f)
    for name in result.pop("arrays", []):
        result[name] = np.load(os.path.join(out, name + ".npy"))
    files = {}
    for name in result.pop("files", []):
        with open(os.path.join(out, os.path.basename(name)), "rb") as f:
            files[os.path.basename(name)] = f.read()
    result["files"] = files
    return result


def run(operation, job=None, part=None, nondesign=None, arrays=None, params=None, on_progress=None,
        cancel=None, timeout=None, on_result=None):
    """Runs one operation of the core in the worker process and returns its results.

    operation: "optimize", "mesh" (need `job`, a job dict, and `part`), "info", "surface_mesh"
    (need `part`), "extract_surface" (needs `arrays`). part, nondesign: BREP strings
    (Shape.exportBrepToString()) or "" / None. arrays: {name: numpy array}. params: the
    operation's numbers (see `topopt worker --help`). on_progress(record) gets each progress
    dict ({"stage", "fraction", "message"} or {"iteration", "compliance", "volume", "change",
    "seconds"}) in the calling thread; it returns True to cancel, False or None to go on.
    cancel(): polled ten to twenty times a second; True cancels. timeout: seconds, None for no limit.
    on_result(result): with params {"result_first": 1} to "optimize" (and the job's
    output.verification on), called in the calling thread with the result as it stands before
    the verification (the dict below, without the verification's files) while the worker goes
    on to verify it; a cancel after that stops the verification only (the caller has the result).

    Returns a dict: the operation's scalars (result.json) and its arrays (numpy).
    Raises TopOptError: the core's own errors with their codes; "WorkerCrashed" (naming the
    stage and what to try) when the worker died; "Cancelled"; "Timeout"; and whatever
    on_progress raised, as it was raised.
    """
    folder = tempfile.mkdtemp(prefix="topopt-worker-")
    try:
        worker = _Worker(_write_request(folder, operation, job, part, nondesign, arrays, params), folder)
        try:
            early = (lambda: on_result(_load(os.path.join(folder, "out")))) if on_result is not None else None
            final, where = _follow(worker, on_progress, cancel, timeout, early)
            worker.wait_exit(10.0)  # its last line is out; let it close down by itself
        finally:
            status = worker.end()
        if final is not None and "error" in final:
            e = final["error"]
            error = TopOptError(str(e.get("message", "")), str(e.get("code", "Internal")))
            error.stage = e.get("stage", where.stage)
            raise error
        if final is None or status != 0:
            error = TopOptError(where.crash_message(_how_it_ended(status)), "WorkerCrashed")
            error.stage, error.details = where.stage, worker.log_tail()
            raise error
        return _load(os.path.join(folder, "out"))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
