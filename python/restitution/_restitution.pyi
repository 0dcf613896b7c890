"""Type stubs of the compiled extension (the public API is in restitution/__init__.py)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
from numpy.typing import NDArray

class InputError(ValueError):
    path: Optional[str]
    line: Optional[int]
    column: Optional[str]
    detail: Optional[str]
    kind: Optional[str]  # io, format, schema or value

class NumericalError(RuntimeError): ...

DEFAULT_TOL: float
G_STANDARD_M_S2: float
K_HOMOGENEOUS: float
PAPER_CAMERA: Dict[str, Any]

def material_presets() -> List[str]: ...
def _panic_for_test() -> None: ...
def e_of_kappa(
    kappa: NDArray[np.float64], contact_end: str = ..., method: str = ..., tol: float = ...
) -> NDArray[np.float64]: ...
def e_of_kappa_timed(
    kappa: NDArray[np.float64], contact_end: str = ..., method: str = ..., tol: float = ...
) -> Tuple[NDArray[np.float64], float]: ...
def e_of_u(u: NDArray[np.float64]) -> NDArray[np.float64]: ...
def predict(
    model: str,
    v_m_s: Optional[NDArray[np.float64]] = ...,
    kappa: Optional[NDArray[np.float64]] = ...,
    u: Optional[NDArray[np.float64]] = ...,
    d_mm: Optional[float] = ...,
    d2_mm: Optional[float] = ...,
    wall: bool = ...,
    material: Optional[str] = ...,
    youngs_pa: Optional[float] = ...,
    poisson: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    eta: Optional[float] = ...,
    sigma_y_pa: Optional[float] = ...,
    contact_end: str = ...,
    method: str = ...,
    tol: float = ...,
    full_output: bool = ...,
) -> List[Tuple[str, NDArray[np.float64]]]: ...

class Fitted:
    rust_seconds: float
    def json(self) -> str: ...
    def table_text(self) -> str: ...
    def markdown(self) -> str: ...
    def csv(self) -> str: ...
    def fig7_svg(self, title: str) -> str: ...
    def residuals_svg(self, title: str) -> str: ...
    def input_warnings(self) -> List[str]: ...

def fit(
    path: Optional[Union[str, PathLike[str]]] = ...,
    name: Optional[str] = ...,
    text: Optional[str] = ...,
    material: Optional[str] = ...,
    youngs_pa: Optional[float] = ...,
    poisson: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    model: str = ...,
    contact_end: str = ...,
    exact: bool = ...,
    strict: bool = ...,
) -> Fitted: ...
def walton_fit(
    path: Optional[Union[str, PathLike[str]]] = ...,
    name: Optional[str] = ...,
    text: Optional[str] = ...,
    material: Optional[str] = ...,
    youngs_pa: Optional[float] = ...,
    poisson: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    inertia_k: float = ...,
    weights: str = ...,
    bootstrap: int = ...,
    seed: int = ...,
) -> Dict[str, Any]: ...
def kinematics(
    path: Optional[Union[str, PathLike[str]]] = ...,
    name: Optional[str] = ...,
    text: Optional[str] = ...,
    material: Optional[str] = ...,
    youngs_pa: Optional[float] = ...,
    poisson: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    fixed_gravity: bool = ...,
    g_m_s2: float = ...,
    inertia_k: float = ...,
    s_subpixels: float = ...,
    subpixel_m: Optional[float] = ...,
    fov_m: float = ...,
    pixels_x: int = ...,
    subpixel_expansion: float = ...,
    strict: bool = ...,
) -> Dict[str, Any]: ...

VERIFY_TOLERANCE: float

def export(
    engine: str,
    params_path: Optional[Union[str, PathLike[str]]] = ...,
    params_name: Optional[str] = ...,
    params_text: Optional[str] = ...,
    model: Optional[str] = ...,
    walton_path: Optional[Union[str, PathLike[str]]] = ...,
    walton_name: Optional[str] = ...,
    walton_text: Optional[str] = ...,
    mu0: Optional[float] = ...,
    beta0: Optional[float] = ...,
    material: Optional[str] = ...,
    youngs_pa: Optional[float] = ...,
    poisson: Optional[float] = ...,
    density_kg_m3: Optional[float] = ...,
    d_mm: Optional[List[float]] = ...,
    wall: bool = ...,
    eta: Optional[float] = ...,
    sigma_y_pa: Optional[float] = ...,
    contact_end: Optional[str] = ...,
    v_range: Optional[Tuple[float, float]] = ...,
    weight: str = ...,
    tolerance: Optional[float] = ...,
    table_points: int = ...,
    law: str = ...,
    speeds_m_s: Optional[List[float]] = ...,
    out: Optional[Union[str, PathLike[str]]] = ...,
    verify: bool = ...,
) -> Dict[str, Any]: ...

def track(
    dirs: List[str],
    fps: float,
    pixel_m: Optional[float] = ...,
    d_mm: Optional[List[float]] = ...,
    out: Optional[Union[str, PathLike[str]]] = ...,
    strict: bool = ...,
) -> Dict[str, Any]: ...
