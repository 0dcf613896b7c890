"""e(v), e(kappa) and e(u): `restitution predict` on numpy arrays."""

from __future__ import annotations

from typing import Dict, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _restitution as _ext
from ._restitution import InputError

DEFAULT_TOL: float = _ext.DEFAULT_TOL


def _flat(x: ArrayLike, name: str) -> Tuple[NDArray[np.float64], Tuple[int, ...]]:
    # A complex value would be cast to its real part with only a numpy warning.
    if np.iscomplexobj(x):
        raise InputError(f"{name}: expected real numbers, got complex values")
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise InputError(f"{name}: expected numbers ({err})") from None
    return np.ascontiguousarray(a.reshape(-1)), a.shape


def _shaped(values: NDArray[np.float64], shape: Tuple[int, ...]) -> Union[NDArray[np.float64], np.float64]:
    return values.reshape(shape)[()] if shape == () else values.reshape(shape)


def e_of_kappa(
    kappa: ArrayLike,
    contact_end: str = "overlap",
    method: str = "master",
    tol: float = DEFAULT_TOL,
) -> Union[NDArray[np.float64], np.float64]:
    """Coefficient of restitution of the viscoelastic model against kappa, elementwise.

    kappa is the dimensionless damping (`restitution predict --kappa`); the model is universal in
    it. Any array shape; a scalar gives a numpy scalar.

    Parameters
    ----------
    kappa : array_like
        Values >= 0.
    contact_end : {"overlap", "force"}
        The paper's rule (contact ends when the overlap returns to zero) or Schwager & Poeschel's
        (when the force does).
    method : {"master", "dop853", "dopri5"}
        The master-curve table (about 20 ns per value, error below 1e-14; the default ODE
        above kappa = 100) or an ODE integration at tolerance `tol` for every value.
    tol : float
        Tolerance of the ODE methods (rtol = atol), in [1e-15, 1): a double cannot meet a
        tighter one.

    Raises
    ------
    InputError (a ValueError)
        A value that is negative, NaN or infinite, or an unknown option.
    NumericalError (a RuntimeError)
        The ODE gave up (kappa above about 3000 with the overlap rule).
    """
    k, shape = _flat(kappa, "kappa")
    return _shaped(_ext.e_of_kappa(k, contact_end=contact_end, method=method, tol=tol), shape)


def e_of_u(u: ArrayLike) -> Union[NDArray[np.float64], np.float64]:
    """Coefficient of restitution of the plastic model against u = V/V_Y, elementwise.

    The closed form (`restitution predict --model pm --u`): e = 1 up to yield (u <= 1), then
    falling as about 1.185 u^(-1/4). Any array shape; a scalar gives a numpy scalar.

    Raises
    ------
    InputError (a ValueError)
        A value that is negative, NaN or infinite.
    """
    x, shape = _flat(u, "u")
    return _shaped(_ext.e_of_u(x), shape)


def predict(
    model: str,
    v_m_s: Optional[ArrayLike] = None,
    *,
    d_mm: Optional[float] = None,
    d2_mm: Optional[float] = None,
    wall: bool = False,
    material: Optional[str] = None,
    youngs_pa: Optional[float] = None,
    poisson: Optional[float] = None,
    density_kg_m3: Optional[float] = None,
    eta: Optional[float] = None,
    sigma_y_pa: Optional[float] = None,
    contact_end: str = "overlap",
    method: str = "master",
    tol: float = DEFAULT_TOL,
    kappa: Optional[ArrayLike] = None,
    u: Optional[ArrayLike] = None,
    full_output: bool = False,
) -> Union[NDArray[np.float64], Tuple[NDArray[np.float64], Dict[str, NDArray[np.float64]]]]:
    """e(v) from the viscoelastic ("vm") or plastic ("pm") model: `restitution predict`.

    Parameters
    ----------
    model : {"vm", "pm"}
        "vm": Hertz contact with damping eta (Eqs. 9-10); "pm": Hertz up to yield, then
        perfectly plastic (Eqs. 12-18).
    v_m_s : array_like
        Normal impact speeds, m/s (> 0). Needs the material and the geometry.
    d_mm, d2_mm, wall : float, float, bool
        Diameter of the sphere (mm); a second, different sphere of the same material (mm), or a
        flat wall of the same material (``wall=True``, or ``d2_mm=inf``); identical spheres when
        neither is given.
    material : str
        A preset ("nylon", the paper's, "steel", "glass", "aluminium"), or instead all of
        `youngs_pa` (Pa), `poisson` and `density_kg_m3`.
    eta : float
        Damping, kg/(s m) (vm).
    sigma_y_pa : float
        Yield stress, Pa (pm).
    contact_end : {"overlap", "force"}
        End-of-contact rule (vm).
    method, tol
        As for :func:`e_of_kappa`.
    kappa, u : array_like
        Instead of `v_m_s`, without material or geometry: kappa (vm) or u = V/V_Y (pm).
    full_output : bool
        Also return every column of ``restitution predict --format csv``.

    Returns
    -------
    e : ndarray
        Same shape as the input speeds.
    columns : dict of ndarray, only with ``full_output=True``
        The CLI's columns in its order: for vm ``v_m_s, e, one_minus_e, kappa,
        contact_time_s, max_overlap_m, max_force_n``; for pm ``v_m_s, e, one_minus_e, u,
        v_yield_m_s``; with `kappa` ``kappa, e, one_minus_e, tau_contact, x_max, force_max``;
        with `u` ``u, e, one_minus_e``. The trajectory columns (contact time, maximum overlap
        and force) integrate the ODE, about 20 us per value.

    Raises
    ------
    InputError (a ValueError), NumericalError (a RuntimeError)
    """
    arrays = {}
    shape: Tuple[int, ...] = ()
    for name, value in (("v_m_s", v_m_s), ("kappa", kappa), ("u", u)):
        if value is not None:
            arrays[name], shape = _flat(value, name)
    cols = _ext.predict(
        model,
        d_mm=d_mm,
        d2_mm=d2_mm,
        wall=wall,
        material=material,
        youngs_pa=youngs_pa,
        poisson=poisson,
        density_kg_m3=density_kg_m3,
        eta=eta,
        sigma_y_pa=sigma_y_pa,
        contact_end=contact_end,
        method=method,
        tol=tol,
        full_output=full_output,
        **arrays,
    )
    out = {name: values.reshape(shape) for name, values in cols}
    e = _shaped(out["e"], shape)
    return (e, out) if full_output else e
