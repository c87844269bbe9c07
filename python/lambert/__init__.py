"""lambert: diffuse view factors and gray-body radiative exchange, from Python.

>>> import lambert
>>> scene = lambert.Scene.load("cases/cube_furnace/scene.toml")
>>> vf = scene.view_factors()            # scipy.sparse.csr_array in vf.matrix
>>> result = scene.solve()
>>> result.surface.heat_rate             # numpy array, W, one per surface

Every computation runs the library's own route (the CLI's method choice, stores and
refusals) with the GIL released. Errors are :mod:`lambert.errors` exceptions with the CLI's
messages; warnings go to Python's :mod:`warnings` as :class:`LambertWarning`.
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _lambert
from .errors import (
    ComputeError,
    Error,
    InputError,
    LambertIOError,
    LambertWarning,
    UnsupportedError,
    UsageError,
)

__all__ = [
    "Scene",
    "ViewFactors",
    "Result",
    "NodeResults",
    "ProgressEvent",
    "SIGMA",
    "Error",
    "InputError",
    "UsageError",
    "UnsupportedError",
    "ComputeError",
    "LambertIOError",
    "LambertWarning",
]

#: Stefan–Boltzmann constant, W m⁻² K⁻⁴ (the library's value).
SIGMA: float = _lambert.SIGMA

PathLike = Union[str, "os.PathLike[str]"]


class ProgressEvent(NamedTuple):
    """One progress report to a ``progress=callable``: a call starting (``"view factors"``,
    ``"solve"``, ``"point view factors"``, then ``"done"``; ``done``, ``total`` and ``stage``
    are None); a phase of the library's run starting (``phase`` and ``stage`` both name it:
    ``"bvh"``, ``"view factors"``, ``"enforcement"``, ``"solve"``; ``done`` and ``total`` are
    None); or the counts of the running stage: ``done`` of ``total`` units, ``phase`` naming
    the units (``"pairs"``, ``"point-patch pairs"``) and ``stage`` the library's phase they
    belong to."""

    phase: str
    done: Optional[int] = None
    total: Optional[int] = None
    stage: Optional[str] = None


Progress = Union[None, bool, str, Callable[[ProgressEvent], Any]]


def _warn(messages: Sequence[str]) -> None:
    for m in messages:
        warnings.warn(m, LambertWarning, stacklevel=3)


class _Reporter:
    """Hands the library's progress to a callback (``ProgressEvent``s) or a tqdm bar
    (``progress=True`` with tqdm installed; without it, the library's own display on stderr,
    as ``progress="stderr"``). The counts are polled while the computation runs with the GIL
    released; they never change a number."""

    def __init__(self, progress: Progress) -> None:
        self.callback = progress if callable(progress) else None
        self.tqdm: Any = None
        if progress is True:
            try:
                from tqdm.auto import tqdm

                self.tqdm = tqdm
            except ImportError:
                pass
        self.stderr = progress == "stderr" or (progress is True and self.tqdm is None)
        self.bar: Any = None
        self.stage = 0
        self.stage_name: Optional[str] = None
        self.counted = 0
        self.counted_in: Optional[str] = None
        self.last_counts: Any = None

    def watch(self) -> Optional[Callable[[int, int, int, str, List[str]], None]]:
        """The counts callback for the extension, when anyone listens."""
        return self._counts if (self.callback is not None or self.tqdm is not None) else None

    def phase(self, name: str) -> None:
        if self.callback is not None:
            self.callback(ProgressEvent(name))
        if name == "done":
            self.close()

    def _counts(self, stages: int, done: int, total: int, what: str, phases: List[str]) -> None:
        for p in phases:
            self.stage_name = p
            if self.callback is not None:
                self.callback(ProgressEvent(p, stage=p))
        if stages == 0 or (stages, done, total) == self.last_counts:
            return
        if stages != self.counted:
            # A new counted stage belongs to the phase the library was in when it began.
            self.counted, self.counted_in = stages, self.stage_name
        self.last_counts = (stages, done, total)
        if self.callback is not None:
            self.callback(ProgressEvent(what, done, total, self.counted_in))
        if self.tqdm is not None:
            if stages != self.stage:
                self.close()
                self.bar = self.tqdm(total=total, unit=" " + what, unit_scale=True, leave=False)
                self.stage = stages
            self.bar.update(done - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


@dataclass
class ViewFactors:
    """A view-factor matrix with its errors and diagnostics.

    ``matrix`` is a ``scipy.sparse.csr_array`` of F_ij (row i = from, column j = to);
    ``std_error`` the same pattern with each entry's standard error (0 for exact methods);
    ``method`` the same pattern with each entry's method code (see :meth:`method_names`).
    """

    level: str
    names: List[str]
    areas: np.ndarray
    matrix: Any
    std_error: Any
    method: Any
    method_bits: List[str]
    row_sums: np.ndarray
    patch_row_sums: np.ndarray
    pairs: int
    seconds: float
    warnings: List[str]
    notes: List[str]
    store: str = "sparse"
    _handle: Any = field(default=None, repr=False)

    @classmethod
    def _from(cls, d: Dict[str, Any], handle: Any) -> "ViewFactors":
        from scipy.sparse import csr_array

        n = len(d["names"])
        shape = (n, n)
        pattern = (d["indices"], d["indptr"])
        return cls(
            level=d["level"],
            names=list(d["names"]),
            areas=d["areas"],
            matrix=csr_array((d["data"], *pattern), shape=shape),
            std_error=csr_array((d["std_error"], *pattern), shape=shape),
            method=csr_array((d["method"], *pattern), shape=shape),
            method_bits=list(d["method_names"]),
            row_sums=d["row_sums"],
            patch_row_sums=d["patch_row_sums"],
            pairs=int(d["pairs"]),
            seconds=float(d["seconds"]),
            warnings=list(d["warnings"]),
            notes=list(d["notes"]),
            store=d.get("store", "file"),
            _handle=handle,
        )

    @property
    def row_errors(self) -> np.ndarray:
        """|Σ_j F_ij − 1| per row (meaningful for a closed scene)."""
        return np.abs(self.row_sums - 1.0)

    def dense(self) -> np.ndarray:
        """The matrix as a dense numpy array (small scenes)."""
        return self.matrix.toarray()

    def method_names(self, code: int) -> str:
        """The method(s) behind a method code, as the CSV's ``method`` column writes them."""
        names = [n for k, n in enumerate(self.method_bits) if code & (1 << k)]
        return "+".join(names) if names else "none"

    def index(self, name: str) -> int:
        """The row/column of a surface or patch name."""
        return self.names.index(name)

    def save(self, path: PathLike) -> None:
        """Writes the CLI's view-factor CSV (``lambert viewfactors -o``), read back by
        :meth:`Scene.read_view_factors` and by ``lambert solve --viewfactors``."""
        self._handle.save(os.fspath(path))


@dataclass
class NodeResults:
    """Per-node arrays of a solve (one entry per surface or per patch)."""

    names: List[str]
    area: np.ndarray
    emissivity: np.ndarray
    surface: np.ndarray
    temperature: np.ndarray
    heat_flux: np.ndarray
    heat_rate: np.ndarray
    radiosity: np.ndarray
    irradiation: np.ndarray
    heat_rate_error: np.ndarray

    def __getitem__(self, name: str) -> Dict[str, float]:
        """The values of one node by name."""
        k = self.names.index(name)
        return {
            f: float(getattr(self, f)[k])
            for f in ("area", "emissivity", "temperature", "heat_flux", "heat_rate", "radiosity", "irradiation")
        }


@dataclass
class Result:
    """A solved scene: per-surface results, per-patch results (when solved per patch) and
    diagnostics."""

    scene: "Scene"
    surface: NodeResults
    patch: Optional[NodeResults]
    path: str
    solver: str
    iterations: int
    residual: float
    solve_seconds: float
    ambient: Optional[tuple]
    warnings: List[str]
    notes: List[str]
    _handle: Any = field(default=None, repr=False)

    def heat_balance(self) -> float:
        """Σ heat_rate over the surfaces plus the ambient's, W (≈ 0 by energy conservation)."""
        amb = self.ambient[1] if self.ambient else 0.0
        return float(self.surface.heat_rate.sum() + amb)

    def save(self, path: PathLike, patches: bool = False) -> None:
        """Writes the CLI's results CSV (``lambert solve -o``), per surface or per patch."""
        if patches and self.patch is None:
            raise UsageError("patches=True: this result was solved per surface (saved surface view factors)")
        self._handle.save(os.fspath(path), patches)

    def to_pyvista(self) -> Any:
        """The scene's patches as ``pyvista.PolyData`` with the results as cell_data: per-patch
        values where solved per patch, and each surface's values (``surface_*``) on its patches."""
        mesh = self.scene.to_pyvista()
        cells = mesh.cell_data["patch"]
        owner = self.scene.patch_surface[cells]
        for f in ("temperature", "heat_flux", "heat_rate", "radiosity", "irradiation", "heat_rate_error"):
            if self.patch is not None:
                mesh.cell_data[f] = getattr(self.patch, f)[cells]
            mesh.cell_data["surface_" + f] = getattr(self.surface, f)[owner]
        return mesh


def _nodes(d: Dict[str, Any]) -> NodeResults:
    return NodeResults(**{k: (list(v) if k == "names" else v) for k, v in d.items()})


def _per_surface(value: Any, ids: np.ndarray, what: str, optional: bool) -> List[Optional[float]]:
    """A per-surface list from a scalar, a sequence in surface order, or a mapping id → value."""
    if value is None:
        if optional:
            return [None] * len(ids)
        raise InputError(f"<arrays>: {what} is required")
    if isinstance(value, Mapping):
        unknown = [k for k in value if k not in set(ids.tolist())]
        if unknown:
            raise InputError(f"<arrays>: {what}: no face has surface id {unknown[0]!r}")
        return [None if value.get(i) is None else float(value[i]) for i in ids.tolist()]
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return [float(arr)] * len(ids)
    if arr.shape != (len(ids),):
        raise InputError(
            f"<arrays>: {what} has shape {arr.shape}; give a scalar, one value per surface ({len(ids)}), "
            "or a dict surface id → value"
        )
    return [float(x) for x in arr]


class Scene:
    """A scene: named surfaces made of patches, with emissivities and boundary conditions.

    Build one with :meth:`load`, :meth:`from_arrays` or :meth:`from_pyvista`.
    """

    def __init__(self, inner: Any) -> None:
        self._inner = inner

    # ----- construction -----
    @classmethod
    def load(
        cls, path: PathLike, *, unit: Optional[str] = None, repair: bool = False, allow_outside_paths: bool = False
    ) -> "Scene":
        """Loads a scene file as the CLI does: TOML, glTF/GLB, STL, OBJ or View3D .vs3.
        ``unit`` (m, mm, cm, in, ft) and ``repair`` apply to a bare mesh file."""
        return cls(_lambert._Scene.load(os.fspath(path), unit, repair, allow_outside_paths))

    @classmethod
    def from_arrays(
        cls,
        vertices: Any,
        faces: Any,
        surface_ids: Any,
        *,
        emissivity: Any = 1.0,
        temperature: Any = None,
        heat_flux: Any = None,
        names: Optional[Mapping[Any, str]] = None,
        ambient: Optional[float] = None,
        title: Optional[str] = None,
    ) -> "Scene":
        """A scene from arrays: ``vertices`` (n, 3) in m; ``faces`` (m, k) vertex indices
        (triangles, quads, …; counter-clockwise seen from the front) or a list of index lists;
        ``surface_ids`` (m,) the surface of each face (ints or strings; surfaces in order of
        first appearance). Each face is a patch.

        ``emissivity``, ``temperature`` (K) and ``heat_flux`` (W/m²): a scalar, one value per
        surface, or a dict surface id → value (missing or ``None``: not prescribed).
        ``names``: surface id → name (default ``str(id)``). ``ambient``: the temperature (K) of
        the black environment of an open scene; ``None`` makes a closed enclosure.
        """
        v = np.asarray(vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 3:
            raise InputError(f"<arrays>: vertices has shape {v.shape}; expected (n, 3)")
        if isinstance(faces, np.ndarray) or (len(faces) and not isinstance(faces[0], (list, tuple, np.ndarray))):
            f = np.asarray(faces)
            if f.ndim != 2 or f.shape[1] < 3:
                raise InputError(f"<arrays>: faces has shape {f.shape}; expected (m, k) with k >= 3 vertices per face")
            if not np.issubdtype(f.dtype, np.integer):
                raise InputError(f"<arrays>: faces has dtype {f.dtype}; expected integer vertex indices")
            rings = [row for row in f.astype(np.int64)]
        else:
            rings = [np.asarray(r, dtype=np.int64) for r in faces]
            short = [k for k, r in enumerate(rings) if r.ndim != 1 or len(r) < 3]
            if short:
                raise InputError(f"<arrays>: faces[{short[0]}] needs at least 3 vertex indices")
        ids = np.asarray(surface_ids)
        if ids.shape != (len(rings),):
            raise InputError(f"<arrays>: surface_ids has shape {ids.shape}; expected one id per face ({len(rings)},)")
        order: Dict[Any, int] = {}
        for s in ids.tolist():
            order.setdefault(s, len(order))
        unique = np.array(list(order), dtype=object)
        index = np.array([order[s] for s in ids.tolist()], dtype=np.int64)
        surface_names = [str(names.get(s, s)) if names else str(s) for s in order]
        if len(set(surface_names)) != len(surface_names):
            raise InputError("<arrays>: two surfaces have the same name")
        eps = [x for x in _per_surface(emissivity, unique, "emissivity", False)]
        temps = _per_surface(temperature, unique, "temperature", True)
        fluxes = _per_surface(heat_flux, unique, "heat_flux", True)
        offsets = np.zeros(len(rings) + 1, dtype=np.int64)
        offsets[1:] = np.cumsum([len(r) for r in rings])
        flat = np.concatenate(rings) if rings else np.zeros(0, dtype=np.int64)
        inner = _lambert._Scene.from_arrays(
            np.ascontiguousarray(v), flat, offsets, index, surface_names, eps, temps, fluxes, ambient, title
        )
        return cls(inner)

    @classmethod
    def from_pyvista(
        cls,
        mesh: Any,
        *,
        surface_ids: str = "surface_id",
        emissivity: Union[str, float, Any] = "emissivity",
        temperature: Optional[str] = "temperature",
        heat_flux: Optional[str] = "heat_flux",
        ambient: Optional[float] = None,
        title: Optional[str] = None,
    ) -> "Scene":
        """A scene from ``pyvista.PolyData``: each cell a patch, grouped into surfaces by the
        cell_data array ``surface_ids`` (every cell its own surface when absent). Emissivity,
        temperature and heat flux come from cell_data arrays of those names when present (NaN
        = not prescribed), and must agree within a surface; ``emissivity`` may also be a number."""
        poly = mesh.extract_surface() if not hasattr(mesh, "faces") else mesh
        faces = poly.faces
        rings, k = [], 0
        while k < len(faces):
            n = int(faces[k])
            rings.append(faces[k + 1 : k + 1 + n])
            k += n + 1
        cd = poly.cell_data
        ids = np.asarray(cd[surface_ids]) if surface_ids in cd else np.arange(len(rings))

        def per_surface(name: Any, what: str) -> Any:
            if not isinstance(name, str):
                return name
            if name not in cd:
                return None
            vals = np.asarray(cd[name], dtype=float)
            out: Dict[Any, Optional[float]] = {}
            for s, x in zip(ids.tolist(), vals.tolist()):
                x = None if np.isnan(x) else x
                if s in out and out[s] != x:
                    raise InputError(f"<pyvista>: cell_data {name!r}: surface {s!r} has two values, {out[s]} and {x}")
                out[s] = x
            return out

        eps = per_surface(emissivity, "emissivity")
        return cls.from_arrays(
            np.asarray(poly.points),
            rings,
            ids,
            emissivity=1.0 if eps is None else eps,
            temperature=per_surface(temperature, "temperature"),
            heat_flux=per_surface(heat_flux, "heat_flux"),
            ambient=ambient,
            title=title,
        )

    # ----- description -----
    @property
    def surface_names(self) -> List[str]:
        """Surface names, in the scene's order."""
        return self._inner.surface_names

    @property
    def patch_names(self) -> List[str]:
        """Patch names (``surface#k``; a surface of one patch by its own name)."""
        return self._inner.patch_names

    @property
    def surface_areas(self) -> np.ndarray:
        """Surface areas, m²."""
        return self._inner.surface_areas

    @property
    def patch_areas(self) -> np.ndarray:
        """Patch areas, m²."""
        return self._inner.patch_areas

    @property
    def patch_surface(self) -> np.ndarray:
        """The surface index of each patch."""
        return self._inner.patch_surface

    @property
    def emissivity(self) -> np.ndarray:
        """Surface emissivities."""
        return self._inner.emissivity

    @property
    def is_closed(self) -> bool:
        """True for a closed enclosure (no ambient)."""
        return self._inner.is_closed

    @property
    def ambient(self) -> Optional[float]:
        """The ambient temperature of an open scene, K."""
        return self._inner.ambient

    @property
    def source(self) -> str:
        """The file the scene came from (``<arrays>`` for array scenes)."""
        return self._inner.source

    @property
    def warnings(self) -> List[str]:
        """What the loader warned about."""
        return self._inner.warnings

    @property
    def fingerprint(self) -> str:
        """The geometry fingerprint that saved view factors carry."""
        return self._inner.fingerprint

    def __repr__(self) -> str:
        return f"<lambert.Scene {self.source!r}: {len(self.surface_names)} surfaces, {len(self.patch_names)} patches>"

    def to_pyvista(self) -> Any:
        """The patches as ``pyvista.PolyData`` (cell_data ``patch`` and ``surface`` indices)."""
        import pyvista as pv

        points, faces, cells = self._inner.mesh()
        mesh = pv.PolyData(points, faces)
        mesh.cell_data["patch"] = cells
        mesh.cell_data["surface"] = self.patch_surface[cells]
        return mesh

    # ----- computations -----
    def view_factors(
        self,
        method: str = "auto",
        tolerance: Optional[float] = None,
        patches: bool = False,
        *,
        samples: Optional[int] = None,
        resolution: Optional[int] = None,
        seed: int = 0,
        enforce: Optional[str] = None,
        threads: Optional[int] = None,
        progress: Progress = None,
    ) -> ViewFactors:
        """View factors as ``lambert viewfactors`` computes them (same method choice, store,
        enforcement and refusals). ``tolerance``: auto's absolute goal on each F (default 1e-4
        or the scene file's View3D eps). ``enforce``: none, reciprocity or closure (default:
        none, or closure for a View3D enclosure). ``threads``: worker threads (results do not
        depend on it). ``progress``: a callable that receives :class:`ProgressEvent`s (phases,
        and pairs done of the total while it computes), True for a tqdm bar (the library's
        display on stderr without tqdm), or ``"stderr"``; it never changes a number."""
        report = _Reporter(progress)
        report.phase("view factors")
        try:
            d, handle = self._inner.view_factors(
                method, tolerance, samples, resolution, seed, patches, enforce, threads, report.stderr, report.watch()
            )
        finally:
            report.close()
        report.phase("done")
        _warn(d["warnings"])
        return ViewFactors._from(d, handle)

    def point_view_factors(
        self,
        points: Any,
        normals: Any,
        patches: bool = False,
        *,
        threads: Optional[int] = None,
        progress: Progress = None,
    ) -> np.ndarray:
        """View factors from points to surfaces: F(dA_k → surface j) for a point k (a sensor,
        a differential element) at ``points[k]`` (m) with normal ``normals[k]`` (any non-zero
        length), as ``lambert viewfactors --points`` computes them (the same numbers).

        Returns a dense array of shape (n_points, n_surfaces), columns in
        :attr:`surface_names` order (``patches=True``: one column per patch, in
        :attr:`patch_names` order). Each factor is exact: Lambert's point-to-polygon formula
        with the pair methods' exact shadows. A point on a surface is not shadowed by it; a
        point behind a surface sees none of it. In a closed scene each row of a point inside
        the enclosure sums to 1; rows that do not draw a :class:`LambertWarning` naming the
        points. Bad arrays (shapes, NaN, infinite values, a zero normal) raise
        :class:`InputError` (a ValueError). ``threads`` and ``progress`` as in
        :meth:`view_factors`."""
        p = np.asarray(points, dtype=float)
        n = np.asarray(normals, dtype=float)
        if p.ndim != 2 or p.shape[1:] != (3,):
            raise InputError(f"<arrays>: points has shape {p.shape}; expected (n, 3)")
        if n.shape != p.shape:
            raise InputError(f"<arrays>: normals has shape {n.shape}; expected the shape of points, {p.shape}")
        report = _Reporter(progress)
        report.phase("point view factors")
        try:
            factors, said = self._inner.point_view_factors(
                np.ascontiguousarray(p), np.ascontiguousarray(n), patches, threads, report.watch()
            )
        finally:
            report.close()
        report.phase("done")
        _warn(said)
        return factors

    def read_view_factors(self, path: PathLike) -> ViewFactors:
        """Reads a view-factor CSV of ``lambert viewfactors`` (or :meth:`ViewFactors.save`)
        written for this scene; refused when its geometry fingerprint is another scene's."""
        d, handle, stamped = self._inner.read_view_factors(os.fspath(path))
        vf = ViewFactors._from(d, handle)
        vf._stamped = stamped  # type: ignore[attr-defined]
        vf._file = os.fspath(path)  # type: ignore[attr-defined]
        return vf

    def solve(
        self,
        method: str = "auto",
        tolerance: Optional[float] = None,
        patches: bool = True,
        *,
        view_factors: Optional[ViewFactors] = None,
        samples: Optional[int] = None,
        resolution: Optional[int] = None,
        seed: int = 0,
        enforce: Optional[str] = None,
        solver: str = "direct",
        exchange: str = "auto",
        threads: Optional[int] = None,
        progress: Progress = None,
    ) -> Result:
        """The net-radiation solve as ``lambert solve`` runs it (same route: hierarchical,
        dense or sparse; same enforcement default: closure for a closed scene, reciprocity for an
        open one). ``view_factors``: view factors computed or read before (``solve
        --viewfactors``). Returns per-surface and (where solved per patch) per-patch arrays.
        ``progress`` as in :meth:`view_factors` (the counts are those of the view-factor stage)."""
        saved = None
        if view_factors is not None:
            saved = (
                view_factors._handle,
                getattr(view_factors, "_stamped", True),
                getattr(view_factors, "_file", None),
            )
        report = _Reporter(progress)
        report.phase("solve")
        try:
            d, handle = self._inner.solve(
                method,
                tolerance,
                samples,
                resolution,
                seed,
                patches and (view_factors is None or view_factors.level == "patch"),
                enforce,
                threads,
                report.stderr,
                solver,
                exchange,
                saved,
                report.watch(),
            )
        finally:
            report.close()
        report.phase("done")
        _warn(d["warnings"])
        return Result(
            scene=self,
            surface=_nodes(d["surface"]),
            patch=_nodes(d["patch"]) if "patch" in d else None,
            path=d["path"],
            solver=d["solver"],
            iterations=int(d["iterations"]),
            residual=float(d["residual"]),
            solve_seconds=float(d["solve_seconds"]),
            ambient=d["ambient"],
            warnings=list(d["warnings"]),
            notes=list(d["notes"]),
            _handle=handle,
        )
