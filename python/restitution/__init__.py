"""restitution: the coefficient of restitution of colliding spheres, from Python.

After Labous, Rosato & Dave, Phys. Rev. E 56, 5717 (1997). The package calls the Rust library
behind the ``restitution`` command line directly, so every number is the command line's:

>>> import restitution as rs
>>> rs.predict("vm", [0.5, 2.0], d_mm=25.4, material="nylon", eta=190.0)   # e(v)
>>> rs.e_of_kappa(np.logspace(-4, 1, 6))                                     # master curve
>>> r = rs.fit("data/fig7_nylon.csv", "nylon")                              # restitution fit
>>> r.preferred, r.params["min"]["eta"], r.table()

Functions: :func:`predict`, :func:`e_of_kappa`, :func:`e_of_u`, :func:`fit`,
:func:`walton_fit`, :func:`kinematics`, :func:`track`, :func:`export`. Units are in argument and column names (``v_m_s``,
``d_mm``, ``sigma_y_pa``), SI otherwise. Bad input raises :class:`InputError` (a ValueError)
with the command line's one-line message; a numerical method that gives up raises
:class:`NumericalError` (a RuntimeError). Long calls release the GIL.
"""

from ._restitution import InputError, NumericalError, material_presets
from ._models import DEFAULT_TOL, e_of_kappa, e_of_u, predict
from ._fit import FIT_COLUMNS, DataWarning, FitResult, fit
from ._walton import KinematicsResult, WaltonResult, kinematics, walton_fit
from ._export import VERIFY_TOLERANCE, ExportResult, export
from ._track import TrackResult, track

__all__ = [
    "DEFAULT_TOL",
    "FIT_COLUMNS",
    "DataWarning",
    "ExportResult",
    "FitResult",
    "InputError",
    "KinematicsResult",
    "NumericalError",
    "TrackResult",
    "WaltonResult",
    "e_of_kappa",
    "e_of_u",
    "export",
    "fit",
    "kinematics",
    "material_presets",
    "predict",
    "track",
    "VERIFY_TOLERANCE",
    "walton_fit",
]
