"""Headless runs without FreeCAD's console progress lines.

Without its GUI, FreeCAD reports the progress of recomputes, saves and mesh building as
lines of "(0 %) … (100 %)" that its console sequencer writes straight to the process's
standard output; a script that recomputes or saves a few times prints them by the hundred
and buries its own output. There is no setting for it, so while such an operation runs
headless, no_progress_lines() points file descriptor 1 at /dev/null (warnings and errors go
to standard error and stay visible). With the GUI it does nothing: there the progress goes
to the status bar.
"""
import contextlib
import os
import sys

import FreeCAD


def _flush_all():
    """Flushes Python's and the C library's buffers of standard output (FreeCAD's sequencer
    writes through C's stdio, whose buffer would otherwise empty itself after the switch)."""
    sys.stdout.flush()
    try:
        import ctypes
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library handle: Python's flush is all we can do
        pass


@contextlib.contextmanager
def no_progress_lines():
    """Context manager: FreeCAD's console progress lines (standard output) are dropped inside it
    when FreeCAD runs without its GUI."""
    if FreeCAD.GuiUp:
        yield
        return
    _flush_all()
    saved = os.dup(1)
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, 1)
        finally:
            os.close(devnull)
        yield
    finally:
        _flush_all()
        os.dup2(saved, 1)
        os.close(saved)


def recompute(doc):
    """doc.recompute() without the console's progress lines."""
    with no_progress_lines():
        doc.recompute()


def save(doc, path=None):
    """Saves `doc` (to `path` when given, as doc.saveAs does) without the console's progress
    lines. Returns the file's path."""
    with no_progress_lines():
        if path:
            doc.saveAs(str(path))
        else:
            doc.save()
    return doc.FileName


def open_document(path):
    """FreeCAD.openDocument(path) without the console's progress lines."""
    with no_progress_lines():
        return FreeCAD.openDocument(str(path))
