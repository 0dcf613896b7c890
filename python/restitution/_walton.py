"""`walton_fit` and `kinematics`: Walton's operator from oblique collisions, and collision
properties from tracked sphere centres (`restitution walton fit`, `restitution kinematics`)."""

from __future__ import annotations

import copy
import json
import warnings
import html
from typing import Any, Dict, List, Optional

from . import _restitution as _ext
from ._tables import Source, TableLike, frame


def _call(fn: Any, source: Source, **kwargs: Any) -> Dict[str, Any]:
    try:
        return fn(**kwargs, **source.kwargs)
    except _ext.InputError as err:
        raise source.relocate(err) from None


class WaltonResult:
    """The outcome of :func:`walton_fit`: the library's fit of Walton's operator.

    ``to_dict()`` is exactly the document of ``restitution walton fit --format json`` (built by
    the same library function): ``e`` (weighted mean, stderr, bootstrap ``ci95``, spread, min,
    max), ``beta0``, ``mu0``, ``slope``, ``psi_kink`` (value, stderr, ci95, bound),
    ``gamma0_deg``, ``classes``, the impulse-ratio and momentum cross-checks, ``converged``,
    ``message`` and one record per collision under ``collisions``.
    """

    def __init__(self, doc: Dict[str, Any], input_warnings: List[str]):
        self._doc = doc
        self.converged: bool = doc["converged"]
        self.message: str = doc["message"]
        self.warnings: List[str] = input_warnings
        self.params: Dict[str, Dict[str, Any]] = {
            name: {
                "value": doc[name]["value"],
                "stderr": doc[name]["stderr"],
                "interval": doc[name]["ci95"],
            }
            for name in ("e", "beta0", "mu0", "slope", "psi_kink")
        }

    def to_dict(self) -> Dict[str, Any]:
        return copy.deepcopy(self._doc)

    def collisions(self):
        """Per collision: line, collision (id), e, beta, psi, v_n_m_s, v_s_m_s, impulse_ratio,
        class, residual (a DataFrame when pandas is installed, else a list of dicts)."""
        rows = self._doc["collisions"]
        keys = list(rows[0]) if rows else []
        return frame({k: [r[k] for r in rows] for k in keys})

    def table(self):
        """One row per parameter: value, stderr, ci95_low, ci95_high."""
        names = list(self.params)
        p = self.params
        return frame(
            {
                "param": names,
                "value": [p[n]["value"] for n in names],
                "stderr": [p[n]["stderr"] for n in names],
                "ci95_low": [p[n]["interval"][0] if p[n]["interval"] else None for n in names],
                "ci95_high": [p[n]["interval"][1] if p[n]["interval"] else None for n in names],
            }
        )

    def __repr__(self) -> str:
        p = self.params
        return (
            f"<WaltonResult: e = {p['e']['value']:.4g}, beta0 = {p['beta0']['value']:.4g}, "
            f"mu0 = {p['mu0']['value']:.4g}; {self.message}>"
        )

    def _repr_html_(self) -> str:
        def num(x: Any) -> str:
            return "-" if x is None else f"{x:.4g}"

        def interval(ci: Any) -> str:
            return "-" if not ci else f"[{num(ci[0])}, {num(ci[1])}]"

        rows = "".join(
            f"<tr><td>{n}</td><td>{num(v['value'])}</td><td>{num(v['stderr'])}</td>"
            f"<td>{interval(v['interval'])}</td></tr>"
            for n, v in self.params.items()
        )
        d = self._doc
        return (
            f"<p>Walton fit of {html.escape(str(d['data']['path']))}: {d['n']} collisions "
            f"({d['classes']['sliding']} sliding, {d['classes']['rolling']} rolling, "
            f"{d['classes']['head_on']} head-on); "
            f"{html.escape(self.message)}</p><table><tr><th>parameter</th><th>value</th>"
            f"<th>stderr</th><th>95% interval (bootstrap)</th></tr>{rows}</table>"
        )


def walton_fit(
    data: TableLike,
    material: Optional[str] = None,
    *,
    youngs_pa: Optional[float] = None,
    poisson: Optional[float] = None,
    density_kg_m3: Optional[float] = None,
    inertia_k: float = _ext.K_HOMOGENEOUS,
    weights: str = "camera",
    bootstrap: int = 2000,
    seed: int = 1,
) -> WaltonResult:
    """Fit e, beta_0 and mu_0 of Walton's operator to oblique collisions: ``restitution walton
    fit`` (the paper's Fig. 6).

    Parameters
    ----------
    data : path, dict of arrays or pandas DataFrame
        The collisions in the CLI's schema (``restitution walton fit --help``): ``d1_mm,
        d2_mm`` (``inf``: a wall), centres ``x1_m, y1_m, x2_m, y2_m`` at contact, velocities
        and spins before (``v1x_m_s, v1y_m_s, w1z_rad_s``, same for sphere 2) and after (with
        ``_post`` before the unit); optional 3-D columns and a ``collision`` id.
    material : str
        A preset, or instead `youngs_pa`, `poisson`, `density_kg_m3`.
    inertia_k : float
        K = 4I/(m d^2), 0.4 for homogeneous spheres.
    weights : {"camera", "equal"}
        "camera": every velocity measured with the same error (beta weighted by |v_s|^2, e by
        v_n^2); "equal": every collision counts the same.
    bootstrap, seed : int
        Resamples of the 95% intervals (0: none) and their seed (reproducible).

    Raises
    ------
    InputError (a ValueError), NumericalError (a RuntimeError)
    """
    source = Source(data)
    doc = _call(
        _ext.walton_fit,
        source,
        material=material,
        youngs_pa=youngs_pa,
        poisson=poisson,
        density_kg_m3=density_kg_m3,
        inertia_k=inertia_k,
        weights=weights,
        bootstrap=bootstrap,
        seed=seed,
    )
    return WaltonResult(json.loads(doc["json"]), source.relocate_lines(doc["input_warnings"]))


class KinematicsResult:
    """The outcome of :func:`kinematics`: one row per measured collision.

    ``to_dict()`` is exactly the document of ``restitution kinematics --format json`` (built by
    the same library function): ``collisions``, a list with one record per collision whose keys
    are the ``kinematics.csv`` columns, and ``skipped`` and ``unmeasured_spins`` as below.
    ``columns()`` gives the same numbers by column, with the CLI's single ``v_err_m_s`` (the rms
    of the eight velocity errors) split into the eight errors ``v1x_err_m_s`` ...
    ``v2y_post_err_m_s``, and None for a momentum check a collision does not have (the CLI's
    null, an empty cell in CSV).

    Attributes
    ----------
    sigma_pos_m : float
        The position noise pooled over all collisions, m.
    skipped : list of str
        Collisions that could not be measured, with the reason (the CLI's warnings).
    fits_meet : list of str
        Collisions whose time is where pre- and post-collision fits meet (the fallback rule).
    unmeasured_spins : list of str
        Collisions with empty spin cells, taken as 0 in beta and psi (the CLI's warnings; each
        is also issued as a ``UserWarning``).
    """

    def __init__(self, raw: Dict[str, Any]):
        self._raw = raw
        self._doc = json.loads(raw["json"])
        self.sigma_pos_m: float = raw["sigma_pos_m"]
        self.subpixel_m: float = raw["subpixel_m"]
        self.skipped: List[str] = raw["skipped"]
        self.fits_meet: List[str] = raw["fits_meet"]
        self.unmeasured_spins: List[str] = raw["unmeasured_spins"]
        for line in self.unmeasured_spins:
            warnings.warn(line, UserWarning, stacklevel=3)

    def to_dict(self) -> Dict[str, Any]:
        """The ``restitution kinematics --format json`` document: ``collisions`` (a list of
        records), ``skipped`` and ``unmeasured_spins``."""
        return copy.deepcopy(self._doc)

    def columns(self) -> Dict[str, List[Any]]:
        """The per-collision numbers by column, with the eight velocity errors."""
        return copy.deepcopy(self._raw["columns"])

    def table(self):
        """The per-collision columns (a DataFrame when pandas is installed, else row dicts)."""
        return frame(self._raw["columns"])

    def fit_data(self) -> Dict[str, List[float]]:
        """The columns :func:`fit` takes (``d_mm, d2_mm, v_n_m_s, e, e_err``), so the two
        chain as ``fit(k.fit_data(), "nylon")``."""
        c = self._raw["columns"]
        return {
            "d_mm": list(c["d1_mm"]),
            "d2_mm": list(c["d2_mm"]),
            "v_n_m_s": list(c["v_n_m_s"]),
            "e": list(c["e"]),
            "e_err": list(c["e_err"]),
        }

    def __repr__(self) -> str:
        n = len(self._doc["collisions"])
        return f"<KinematicsResult: {n} collisions, {len(self.skipped)} skipped>"


def kinematics(
    tracks: TableLike,
    material: Optional[str] = None,
    *,
    youngs_pa: Optional[float] = None,
    poisson: Optional[float] = None,
    density_kg_m3: Optional[float] = None,
    fixed_gravity: bool = False,
    g_m_s2: float = _ext.G_STANDARD_M_S2,
    inertia_k: float = _ext.K_HOMOGENEOUS,
    s_subpixels: float = _ext.PAPER_CAMERA["s_subpixels"],
    subpixel_m: Optional[float] = None,
    fov_m: float = _ext.PAPER_CAMERA["fov_m"],
    pixels_x: int = _ext.PAPER_CAMERA["pixels_x"],
    subpixel_expansion: float = _ext.PAPER_CAMERA["subpixel_expansion"],
    strict: bool = False,
) -> KinematicsResult:
    """Velocities, e, beta and psi from tracked sphere centres: ``restitution kinematics``
    (the paper's Sec. III).

    Parameters
    ----------
    tracks : path, dict of arrays or pandas DataFrame
        ``collision, t_s, x1_m, y1_m, x2_m, y2_m, d1_mm, d2_mm``, optional ``phase``
        (pre/post) and spins ``w1z_rad_s, w2z_rad_s, w1z_post_rad_s, w2z_post_rad_s``; y is up.
    fixed_gravity : bool
        Straight lines plus the known gravity `g_m_s2` instead of free quadratics (3-4 times
        more precise when the spheres fly freely).
    s_subpixels, subpixel_m, fov_m, pixels_x, subpixel_expansion
        The camera, for Eq. (8)'s error (the paper's by default); `subpixel_m` defaults to
        fov_m / pixels_x / subpixel_expansion.
    strict : bool
        An unmeasurable collision is an error instead of being skipped.

    Raises
    ------
    InputError (a ValueError), NumericalError (a RuntimeError)
    """
    source = Source(tracks)
    doc = _call(
        _ext.kinematics,
        source,
        material=material,
        youngs_pa=youngs_pa,
        poisson=poisson,
        density_kg_m3=density_kg_m3,
        fixed_gravity=fixed_gravity,
        g_m_s2=g_m_s2,
        inertia_k=inertia_k,
        s_subpixels=s_subpixels,
        subpixel_m=subpixel_m,
        fov_m=fov_m,
        pixels_x=pixels_x,
        subpixel_expansion=subpixel_expansion,
        strict=strict,
    )
    return KinematicsResult(doc)
