"""One clean, quiet, single-threaded gmsh model per call.

gmsh is a process-wide singleton.  A call must neither leave state behind (models,
options) nor break a caller that already runs gmsh itself (FreeCAD's FEM can), so a
session initialises gmsh only when nobody else has, works in a fresh model of its own,
and restores every option it touched.
"""

from __future__ import annotations

import itertools
import threading
from contextlib import contextmanager

import gmsh

_LOCK = threading.RLock()
_COUNTER = itertools.count()


class GmshSession:
    """Handle for the session's options; records originals so they can be put back."""

    def __init__(self, owner: bool):
        self.owner = owner
        self._saved: dict[str, float] = {}

    def set(self, name: str, value: float) -> None:
        if not self.owner and name not in self._saved:
            self._saved[name] = gmsh.option.getNumber(name)
        gmsh.option.setNumber(name, value)

    def restore(self) -> None:
        for name, value in self._saved.items():
            gmsh.option.setNumber(name, value)


@contextmanager
def gmsh_session(threads: int = 1):
    """Yield a GmshSession with a fresh current model, quiet and ``threads``-threaded."""
    with _LOCK:
        owner = not gmsh.isInitialized()
        if owner:
            gmsh.initialize(readConfigFiles=False, interruptible=False)
            previous_model = None
        else:
            previous_model = gmsh.model.getCurrent()
        session = GmshSession(owner)
        try:
            for name, value in (("General.Terminal", 0), ("General.Verbosity", 0),
                                ("General.NumThreads", threads),
                                ("Mesh.MaxNumThreads2D", threads)):
                session.set(name, value)
            gmsh.model.add(f"quadcnn_{next(_COUNTER)}")
            yield session
        finally:
            try:
                gmsh.model.remove()
            finally:
                if owner:
                    gmsh.finalize()
                else:
                    session.restore()
                    if previous_model:
                        gmsh.model.setCurrent(previous_model)


@contextmanager
def silenced_stdio():
    """Mute C-level stdout/stderr: OpenCASCADE's readers print banners straight to fd 1."""
    import os
    import sys

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError, OSError):
            pass
    saved = []
    try:
        with open(os.devnull, "w") as devnull:
            for fd in (1, 2):
                try:
                    saved.append((fd, os.dup(fd)))
                    os.dup2(devnull.fileno(), fd)
                except OSError:
                    pass
            yield
    finally:
        for fd, copy in saved:
            os.dup2(copy, fd)
            os.close(copy)
