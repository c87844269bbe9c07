"""Type stubs of the extension module (the Rust half of lambert)."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

SIGMA: float

class _ViewFactors:
    def save(self, path: str) -> None: ...

class _Solution:
    def save(self, path: str, patches: bool) -> None: ...

class _Scene:
    @staticmethod
    def load(path: str, unit: Optional[str] = None, repair: bool = False, allow_outside_paths: bool = False) -> _Scene: ...
    @staticmethod
    def from_arrays(
        vertices: npt.NDArray[np.float64],
        faces: npt.NDArray[np.int64],
        offsets: npt.NDArray[np.int64],
        surface: npt.NDArray[np.int64],
        names: Sequence[str],
        emissivity: Sequence[float],
        temperature: Sequence[Optional[float]],
        heat_flux: Sequence[Optional[float]],
        ambient: Optional[float] = None,
        title: Optional[str] = None,
        source: Optional[str] = None,
    ) -> _Scene: ...
    @property
    def surface_names(self) -> List[str]: ...
    @property
    def patch_names(self) -> List[str]: ...
    @property
    def surface_areas(self) -> npt.NDArray[np.float64]: ...
    @property
    def patch_areas(self) -> npt.NDArray[np.float64]: ...
    @property
    def patch_surface(self) -> npt.NDArray[np.int64]: ...
    @property
    def emissivity(self) -> npt.NDArray[np.float64]: ...
    @property
    def is_closed(self) -> bool: ...
    @property
    def ambient(self) -> Optional[float]: ...
    @property
    def source(self) -> str: ...
    @property
    def title(self) -> Optional[str]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def fingerprint(self) -> str: ...
    def mesh(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
    def view_factors(
        self,
        method: str,
        tolerance: Optional[float],
        samples: Optional[int],
        resolution: Optional[int],
        seed: int,
        patches: bool,
        enforce: Optional[str],
        threads: Optional[int],
        progress: bool,
        watch: Optional[Callable[[int, int, int, str, List[str]], None]] = None,
    ) -> Tuple[Dict[str, Any], _ViewFactors]: ...
    def point_view_factors(
        self,
        points: npt.NDArray[np.float64],
        normals: npt.NDArray[np.float64],
        patches: bool,
        threads: Optional[int],
        watch: Optional[Callable[[int, int, int, str, List[str]], None]] = None,
    ) -> Tuple[npt.NDArray[np.float64], List[str]]: ...
    def read_view_factors(self, path: str) -> Tuple[Dict[str, Any], _ViewFactors, bool]: ...
    def solve(
        self,
        method: str,
        tolerance: Optional[float],
        samples: Optional[int],
        resolution: Optional[int],
        seed: int,
        patches: bool,
        enforce: Optional[str],
        threads: Optional[int],
        progress: bool,
        solver: str,
        exchange: str,
        viewfactors: Optional[Tuple[_ViewFactors, bool, Optional[str]]] = None,
        watch: Optional[Callable[[int, int, int, str, List[str]], None]] = None,
    ) -> Tuple[Dict[str, Any], _Solution]: ...
