"""`track`: sphere centres and spins from directories of video frames (`restitution track`)."""

from __future__ import annotations

import copy
import csv
import html
import io
import json
import os
import warnings
from typing import Any, Dict, List, Optional, Sequence, Union

from . import _restitution as _ext
from ._tables import frame

PathLike = Union[str, "os.PathLike[str]"]


class TrackResult:
    """The outcome of :func:`track`: per collision the detections, the tracks and the spins.

    ``to_dict()`` is exactly the document of ``restitution track --format json`` (built by the
    same library function): one record per collision with the pixel scale (and its
    uncertainty when it comes from the diameters), the diameters, the phase split, the spins
    per sphere and phase, every frame's detections (centre and radius in pixels and metres,
    fit residual, edge points used, coverage, markers) and the warnings.

    Attributes
    ----------
    tracks_csv : str
        tracks.csv: the ``kinematics`` schema with the spin columns, as ``--format csv`` prints
        it; :meth:`tracks` gives it as a table and :func:`kinematics` takes it directly.
    warnings : list of str
        Frames left out, spheres without a spin (also issued as ``UserWarning``).
    """

    def __init__(self, raw: Dict[str, Any]):
        self._doc = json.loads(raw["json"])
        self.tracks_csv: str = raw["tracks_csv"]
        self._table: str = raw["table"]
        self.warnings: List[str] = list(raw["warnings"])
        for line in self.warnings:
            warnings.warn(line, UserWarning, stacklevel=3)

    def to_dict(self) -> List[Dict[str, Any]]:
        """The ``restitution track --format json`` document (a list, one record per collision)."""
        return copy.deepcopy(self._doc)

    def text(self) -> str:
        """The summary ``restitution track`` prints."""
        return self._table

    def tracks(self):
        """tracks.csv as a table (a DataFrame when pandas is installed, else a dict of lists):
        ``collision``, ``t_s``, the centres in metres, the diameters and the spins (None where
        not measured). ``rs.kinematics(result.tracks(), "nylon")`` continues the chain."""
        rows = list(csv.reader(io.StringIO(self.tracks_csv)))
        header, body = rows[0], rows[1:]
        cols: Dict[str, List[Any]] = {h: [] for h in header}
        for r in body:
            for h, cell in zip(header, r):
                if h in ("collision", "phase"):
                    cols[h].append(cell)
                else:
                    cols[h].append(None if cell == "" else float(cell))
        return frame(cols)

    def __repr__(self) -> str:
        ids = ", ".join(str(c["collision"]) for c in self._doc)
        return f"<TrackResult: {len(self._doc)} collision(s): {ids}>"

    def _repr_html_(self) -> str:
        return f"<pre>{html.escape(self._table)}</pre>"


def track(
    dirs: Union[PathLike, Sequence[PathLike]],
    fps: float,
    *,
    pixel_m: Optional[float] = None,
    d_mm: Union[None, float, Sequence[float]] = None,
    out: Optional[PathLike] = None,
    strict: bool = False,
) -> TrackResult:
    """Sphere centres and spins from video frames: ``restitution track`` (the paper's Sec. III).

    Parameters
    ----------
    dirs : path or sequence of paths
        One directory per collision, holding its frames (PNG 8/16-bit grey or colour, TIFF),
        ordered by the integer in the file name; the collision id is the directory's name and
        t_s = (frame number - first frame number) / fps.
    fps : float
        Frames per second.
    pixel_m : float, optional
        Pixel size in the object plane, m. Without it the scale comes from `d_mm` (the fitted
        disc diameters over all frames; reported with its uncertainty).
    d_mm : float or (float, float), optional
        The sphere diameters, mm (one value: both spheres).
    out : path, optional
        Write tracks.csv, detections.csv, spins.csv, collisions.csv and one overlay SVG per
        collision there, all or none.
    strict : bool
        A bad frame (unreadable, no sphere, three blobs) is an error instead of a warning.

    Raises
    ------
    InputError (a ValueError)
        A missing or empty directory, no readable frame, a bad argument: the message names the
        file or the argument.
    """
    paths = [dirs] if isinstance(dirs, (str, os.PathLike)) else list(dirs)
    if d_mm is None:
        d = None
    elif isinstance(d_mm, (int, float)):
        d = [float(d_mm)]
    else:
        d = [float(x) for x in d_mm]
    raw = _ext.track(
        [os.fspath(p) for p in paths],
        float(fps),
        pixel_m=pixel_m,
        d_mm=d,
        out=None if out is None else os.fspath(out),
        strict=strict,
    )
    return TrackResult(raw)
