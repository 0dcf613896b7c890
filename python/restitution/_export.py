"""`export`: a fitted contact law as simulation-engine input (`restitution export`)."""

from __future__ import annotations

import copy
import html
import json
import os
import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _restitution as _ext

#: Largest |LAMMPS e - toolkit e| that ``verify=True`` accepts.
VERIFY_TOLERANCE: float = _ext.VERIFY_TOLERANCE


def _document(what: str, doc: Any) -> Dict[str, Any]:
    """A params.json / walton.json argument as the extension's keyword arguments."""
    if doc is None:
        return {}
    if isinstance(doc, (str, os.PathLike)):
        return {f"{what}_path": os.fspath(doc)}
    if hasattr(doc, "to_dict"):
        # A FitResult or WaltonResult: its document is the file `--out` writes.
        return {f"{what}_name": f"<{type(doc).__name__}>", f"{what}_text": json.dumps(doc.to_dict())}
    if isinstance(doc, dict):
        return {f"{what}_name": f"<{what} dict>", f"{what}_text": json.dumps(doc)}
    raise _ext.InputError(
        f"{what}: expected a path, a {'FitResult' if what == 'params' else 'WaltonResult'} or a "
        f"dict, got {type(doc).__name__}"
    )


def _floats(name: str, x: Any) -> Optional[List[float]]:
    if x is None:
        return None
    if isinstance(x, (int, float)):
        return [float(x)]
    try:
        return [float(v) for v in x]
    except (TypeError, ValueError):
        raise _ext.InputError(f"{name}: expected a number or a sequence of numbers") from None


class ExportResult:
    """The outcome of :func:`export`: the engine's files and what they carry.

    ``to_dict()`` is the document ``restitution export --out`` writes as ``export.json``
    (built by the same library function): the source, the scene, per pair the exported law
    (exact, closest viscoelastic or constant e) with its largest deviation from the fitted
    e(v) over the range, the friction, the file names and, with ``verify=True``, the LAMMPS
    round trip.

    Attributes
    ----------
    files : dict of str to bytes
        Every file by name (``in.restitution``, ``collide.in``, ``constant_e.csv``,
        ``table.csv``, ``laws.svg``, ...), written to `out` when it was given.
    report : str
        The summary ``restitution export`` prints.
    warnings : list of str
        A law or friction from a fit that did not converge (also issued as ``UserWarning``).
    verify_table : str or None
        The LAMMPS round trip as printed, with ``verify=True``.
    """

    def __init__(self, raw: Dict[str, Any]):
        self._doc = json.loads(raw["json"])
        self.files: Dict[str, bytes] = dict(raw["files"])
        self.report: str = raw["report"]
        self.warnings: List[str] = list(raw["warnings"])
        self.verify_table: Optional[str] = raw["verify_table"]
        for line in self.warnings:
            warnings.warn(line, UserWarning, stacklevel=3)

    def to_dict(self) -> Dict[str, Any]:
        return copy.deepcopy(self._doc)

    def text(self, name: str) -> str:
        """A file's text (every file the export writes is UTF-8 text)."""
        return self.files[name].decode("utf-8")

    def __repr__(self) -> str:
        return f"<ExportResult: {', '.join(self.files)}>"

    def _repr_html_(self) -> str:
        figure = self.files.get("laws.svg")
        svg = figure.decode("utf-8") if figure else ""
        return f"<pre>{html.escape(self.report)}</pre>{svg}"


def export(
    params: Any = None,
    engine: str = "lammps",
    *,
    model: Optional[str] = None,
    walton: Any = None,
    mu0: Optional[float] = None,
    beta0: Optional[float] = None,
    material: Optional[str] = None,
    youngs_pa: Optional[float] = None,
    poisson: Optional[float] = None,
    density_kg_m3: Optional[float] = None,
    d_mm: Union[None, float, Sequence[float]] = None,
    wall: bool = False,
    eta: Optional[float] = None,
    sigma_y_pa: Optional[float] = None,
    contact_end: Optional[str] = None,
    v_range: Optional[Tuple[float, float]] = None,
    weight: str = "log",
    tolerance: Optional[float] = None,
    table_points: int = 41,
    law: str = "auto",
    speeds_m_s: Optional[Sequence[float]] = None,
    out: Union[None, str, "os.PathLike[str]"] = None,
    verify: bool = False,
) -> ExportResult:
    """A fitted law as simulation-engine input: ``restitution export``.

    Parameters
    ----------
    params : path, FitResult or dict, optional
        The fit: a params.json written by ``restitution fit --out``, the result of
        :func:`fit`, or its ``to_dict()``. Without it the law is given as numbers: a material
        (preset or `youngs_pa`, `poisson`, `density_kg_m3`), `eta` and/or `sigma_y_pa`, `model`
        and `contact_end`.
    engine : {"lammps", "constant-e", "table"}
        "lammps": ``pair_style granular`` input (exact for vm, otherwise the closest
        viscoelastic law or constant e over `v_range`, see `law`); "constant-e": the best
        velocity-independent e per pair (LAMMPS damping tsuji, LIGGGHTS); "table": e(v_n) per
        pair for event-driven codes (`table_points` speeds).
    model : str, optional
        The model to export (default: the fit's preferred one, or its only model).
    walton : path, WaltonResult or dict, optional
        mu_0 and beta_0 from ``restitution walton fit``; or give `mu0` (and `beta0`).
    d_mm : float or sequence, optional
        The scene's sphere sizes, mm, one engine type each (default: the fit data's spheres,
        both of each pair, with a wall if the data hit one).
    wall : bool
        Spheres also hit flat walls of the same material (also when `d_mm` is not given and the
        fit data hit a wall).
    v_range : (lo, hi), optional
        The scene's normal impact speeds, m/s (needed by every law but vm's).
    weight : {"log", "uniform"}
        How speeds are spread over the range for the best constant e and eta.
    tolerance : float, optional
        Names the simplest law within this deviation from the fitted e(v) (needs `v_range`).
    law : {"auto", "viscoelastic", "constant-e"}
        Which law the LAMMPS files carry when the model has no exact LAMMPS form.
    speeds_m_s : sequence, optional
        Speeds of the collisions in collide.in (default: the range's ends and middle).
    out : path, optional
        Write every file (and export.json) there, all or none.
    verify : bool
        Run LAMMPS (``lmp``) on collide.in and compare e with the toolkit's (fails above
        :data:`VERIFY_TOLERANCE`).

    Raises
    ------
    InputError (a ValueError)
        Bad arguments or files; the message names the argument as a keyword.
    NumericalError (a RuntimeError)
        LAMMPS ran but its e differs from the toolkit's.
    """
    kwargs: Dict[str, Any] = {}
    kwargs.update(_document("params", params))
    kwargs.update(_document("walton", walton))
    v = None if v_range is None else tuple(float(x) for x in v_range)
    if v is not None and len(v) != 2:
        raise _ext.InputError(f"v_range: expected (lo, hi), got {len(v)} numbers")
    raw = _ext.export(
        engine,
        model=model,
        mu0=mu0,
        beta0=beta0,
        material=material,
        youngs_pa=youngs_pa,
        poisson=poisson,
        density_kg_m3=density_kg_m3,
        d_mm=_floats("d_mm", d_mm),
        wall=wall,
        eta=eta,
        sigma_y_pa=sigma_y_pa,
        contact_end=contact_end,
        v_range=v,
        weight=weight,
        tolerance=tolerance,
        table_points=table_points,
        law=law,
        speeds_m_s=_floats("speeds_m_s", speeds_m_s),
        out=None if out is None else os.fspath(out),
        verify=verify,
        **kwargs,
    )
    return ExportResult(raw)
