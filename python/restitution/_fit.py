"""`fit`: measured e(v_n) to eta, sigma_y and more, as `restitution fit` does."""

from __future__ import annotations

import copy
import html
import json
import os
import warnings
from typing import Any, Dict, List, Optional, Tuple

from . import _restitution as _ext
from ._tables import Source, TableLike, frame

#: The columns of the fit schema (others in a table are ignored, as in a file).
FIT_COLUMNS: Tuple[str, ...] = ("d_mm", "v_n_m_s", "e", "e_err", "v_err_m_s", "d2_mm")


class DataWarning(UserWarning):
    """A suspicious input value that was kept (e > 1, a diameter below 0.1 mm): the CLI's
    ``restitution: warning:`` lines."""


class FitResult:
    """The outcome of :func:`fit`.

    Everything here comes from the library's report of one fit: ``to_dict()`` is the document of
    ``restitution fit --format json``, ``fig7_svg()`` and ``residuals_svg()`` the figures of
    ``--out``, ``text()`` the table the CLI prints.

    Attributes
    ----------
    preferred : str or None
        The model preferred by AIC (within delta AIC <= 2, the fewest parameters); where models
        reproduce unweighted points to rounding, the one of them with the fewest parameters if
        one alone has them; None where no fit converged or none is so chosen.
    unranked : str or None
        Why AIC did not choose: no fit converged, or models reproduce the points to rounding,
        where AIC would rank rounding.
    models : list of str
        The fitted models, in the document's order.
    params : dict
        ``params[model][name]`` is a dict with ``value``, ``stderr`` (scaled by sqrt(s),
        s = max(1, chi2/dof) with error bars, chi2/dof without),
        ``interval`` (95% profile-likelihood interval, ends None where open), ``unit`` and
        ``status`` ("estimate", or a bound when the data cannot determine the parameter).
    warnings : list of str
        Suspicious input values that were kept (also issued as :class:`DataWarning`).
    """

    def __init__(self, fitted: Any, source_name: str):
        self._fitted = fitted
        self._name = source_name
        self._cache: Optional[Dict[str, Any]] = None
        self.warnings: List[str] = fitted.input_warnings()

    @property
    def _doc(self) -> Dict[str, Any]:
        # Rendered and parsed on first use: a fit in a loop that reads nothing pays nothing.
        if self._cache is None:
            self._cache = json.loads(self._fitted.json())
        return self._cache

    @property
    def preferred(self) -> Optional[str]:
        return self._doc["preferred"]

    @property
    def unranked(self) -> Optional[str]:
        return self._doc["unranked"]

    @property
    def models(self) -> List[str]:
        return [f["model"] for f in self._doc["fits"]]

    @property
    def params(self) -> Dict[str, Dict[str, Dict[str, Any]]]:
        return {
            f["model"]: {
                name: {
                    "value": p["value"],
                    "stderr": p["stderr"],
                    "interval": tuple(p["ci95"]),
                    "unit": p["unit"],
                    "status": p["status"],
                }
                for name, p in f["params"].items()
            }
            for f in self._doc["fits"]
        }

    def to_dict(self) -> Dict[str, Any]:
        """The ``restitution fit --format json`` document (a fresh copy)."""
        return copy.deepcopy(self._doc)

    def to_json(self) -> str:
        """The same document as JSON text."""
        return self._fitted.json()

    def text(self) -> str:
        """The table ``restitution fit`` prints."""
        return self._fitted.table_text()

    def markdown(self) -> str:
        """params.md of ``restitution fit --out``."""
        return self._fitted.markdown()

    def csv(self) -> str:
        """params.csv of ``restitution fit --out`` (and ``--format csv``)."""
        return self._fitted.csv()

    def fig7_svg(self, title: Optional[str] = None) -> str:
        """fig7.svg of ``restitution fit --out``: the data with error bars and every fitted
        model. The default title is the CLI's."""
        if title is None:
            title = f"Coefficient of restitution vs normal impact speed: {self._name}"
        return self._fitted.fig7_svg(title)

    def residuals_svg(self, title: Optional[str] = None) -> str:
        """residuals.svg of ``restitution fit --out``. The default title is the CLI's."""
        if title is None:
            title = f"Residuals: {self._name}"
        return self._fitted.residuals_svg(title)

    def table(self):
        """One row per model and parameter: a pandas DataFrame when pandas is installed, else
        a list of dicts. Columns: model, k, reduced_chi2, delta_aic, preferred, param, value,
        stderr, ci95_low, ci95_high, unit, status."""
        delta = {r["model"]: r["delta_aic"] for r in (self._doc["comparison"] or [])}
        cols: Dict[str, List[Any]] = {
            k: []
            for k in (
                "model", "k", "reduced_chi2", "delta_aic", "preferred", "param", "value",
                "stderr", "ci95_low", "ci95_high", "unit", "status",
            )
        }
        for f in self._doc["fits"]:
            for name, p in f["params"].items():
                row = (
                    f["model"], len(f["params"]), f["reduced_chi2"], delta.get(f["model"]),
                    f["model"] == self.preferred, name, p["value"], p["stderr"], p["ci95"][0],
                    p["ci95"][1], p["unit"], p["status"],
                )
                for k, v in zip(cols, row):
                    cols[k].append(v)
        return frame(cols)

    def __repr__(self) -> str:
        return (
            f"<FitResult of {self._doc['data']['path']}: {len(self.models)} model(s) "
            f"({', '.join(self.models)}), preferred {self.preferred}>"
        )

    def _repr_html_(self) -> str:
        def num(x: Any) -> str:
            return "-" if x is None else f"{x:.4g}" if isinstance(x, float) else str(x)

        delta = {r["model"]: r["delta_aic"] for r in (self._doc["comparison"] or [])}
        rows = []
        for f in self._doc["fits"]:
            ps = "; ".join(
                f"{html.escape(n)} = {num(p['value'])} &plusmn; {num(p['stderr'])} "
                f"[{num(p['ci95'][0])}, {num(p['ci95'][1])}] {html.escape(p['unit'])}"
                + ("" if p["status"] == "estimate" else f" ({html.escape(p['status'])})")
                for n, p in f["params"].items()
            )
            name = html.escape(f["model"])
            if f["model"] == self.preferred:
                name = f"<b>{name} (preferred)</b>"
            rows.append(
                f"<tr><td>{name}</td><td>{num(f['reduced_chi2'])}</td>"
                f"<td>{num(delta.get(f['model']))}</td><td>{ps}</td></tr>"
            )
        d = self._doc["data"]
        head = (
            f"<p>Fit of {html.escape(str(d['path']))}: {d['n']} points, errors from "
            f"{html.escape(d['errors'])}; contact end {self._doc['contact_end']}, "
            f"{html.escape(self._doc['vm_method'])}</p>"
        )
        table = (
            "<table><tr><th>model</th><th>chi2/dof</th><th>dAIC</th>"
            "<th>parameters (stderr, 95% interval)</th></tr>" + "".join(rows) + "</table>"
        )
        return head + table + f"<div>{self.fig7_svg()}</div>"


def fit(
    data: TableLike,
    material: Optional[str] = None,
    *,
    youngs_pa: Optional[float] = None,
    poisson: Optional[float] = None,
    density_kg_m3: Optional[float] = None,
    model: str = "all",
    contact_end: str = "overlap",
    exact: bool = False,
    strict: bool = False,
) -> FitResult:
    """Fit models of e(v_n) to measured coefficients of restitution: ``restitution fit``.

    Parameters
    ----------
    data : path, dict of arrays or pandas DataFrame
        A CSV file, or a table with the file's columns: ``d_mm``, ``v_n_m_s``, ``e``, optional
        ``e_err`` or ``v_err_m_s`` (then sigma_e = 2 e v_err / v_n, the paper's error model),
        optional ``d2_mm`` (``inf`` for a flat wall; absent for identical spheres). Other
        columns are ignored. A table is read by the same reader as a file, so it gets the same
        checks; errors then name its row.
    material : str
        A preset (``nylon``, ...), or instead all of `youngs_pa` (Pa), `poisson`,
        `density_kg_m3`.
    model : {"all", "vm", "pm", "min", "product", "powerlaw"}
        "all" fits the five and compares them by AIC.
    contact_end : {"overlap", "force"}
        End-of-contact rule of the viscoelastic model.
    exact : bool
        Integrate the ODE for every point instead of the master curve (hundreds of times
        slower, same numbers to 1e-7 in eta).
    strict : bool
        Suspicious values (e > 1, diameters below 0.1 mm) become errors instead of warnings.

    Returns
    -------
    FitResult

    Raises
    ------
    InputError (a ValueError)
        Unreadable file, a bad cell (the message names file, line, column and value, or the
        table's row), too few points, a bad option.
    NumericalError (a RuntimeError)
        A model evaluation failed during the fit.

    The Rust work runs with the GIL released: other Python threads go on meanwhile.
    """
    source = Source(data, columns=FIT_COLUMNS)
    try:
        fitted = _ext.fit(
            material=material,
            youngs_pa=youngs_pa,
            poisson=poisson,
            density_kg_m3=density_kg_m3,
            model=model,
            contact_end=contact_end,
            exact=exact,
            strict=strict,
            **source.kwargs,
        )
    except _ext.InputError as err:
        raise source.relocate(err) from None
    for w in source.relocate_lines(fitted.input_warnings()):
        warnings.warn(w, DataWarning, stacklevel=2)
    if "path" in source.kwargs:
        name = os.path.basename(source.kwargs["path"]) or source.kwargs["path"]
    else:
        name = source.kwargs["name"]
    result = FitResult(fitted, name)
    result.warnings = source.relocate_lines(result.warnings)
    return result
