"""dcg: the Domain Connected Graph skeleton of a closed 3D mesh, for rigging.

    import dcg
    V, F = dcg.load_mesh("hand.obj")            # float64 n x 3, int64 m x 3
    skeleton = dcg.extract_skeleton(V, F, tau=0.85)
    print(skeleton.kinds, skeleton.timings)
    open("hand.json", "w").write(skeleton.to_json())

Stage by stage (each result kept, as in the paper's Fig. 4):

    ex = dcg.Extractor(V, F)
    working = ex.prepare()        # stage 0: closed, uniform, normalized working mesh
    balls = ex.domain_balls()     # stages 1-2
    prongs = ex.prongs()          # stage 3: prong peaks and their significance
    fewer = ex.prongs(tau=0.7)    # re-thresholded, no new geodesics
    ends = ex.end_points()        # a stage-1 ball per prong that sees its peak
    field = ex.force_field()      # stage 4: F and |F| at the domain points (or at any points)
    points = ex.connection_points()  # stage 5: shrunk along the field, merged
    graph = ex.domain_graph()     # stage 6: face labels, links, spanning tree + handle cycles
    remapped = ex.remap()         # stage 7: snake-fitted link polylines
    skeleton = ex.skeleton()
    print(ex.timings)             # [(stage, seconds), ...]

Errors: ValueError for bad data or options, OSError for unreadable files, dcg.Cancelled when a
progress callback returns False. The heavy work runs with the GIL released.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Dict, Optional, Tuple

import numpy as np

from . import _core, bones  # noqa: F401  (dcg.bones: the bone planner)
from .options import OPTIONS, SKELETON_OPTIONS, OptionInfo, normalize_options
from .skeleton import FORMAT, Skeleton
from .weights import SkinWeights, skin_weights

__all__ = [
    "Cancelled", "Extractor", "OPTIONS", "OptionInfo", "Skeleton", "FORMAT", "Balls",
    "PreparedMesh", "Prongs", "extract_skeleton", "load_mesh", "as_mesh",
    "SkinWeights", "skin_weights",
    "Field", "ConnectionPoints", "DomainGraph", "Remapped",
]
__version__ = "0.1.0"

#: Raised when a progress callback returns False.
Cancelled = _core.Cancelled

#: progress(stage, fraction) -> bool | None; return False to cancel.
ProgressCallback = Callable[[str, float], Optional[bool]]


def load_mesh(path) -> Tuple[np.ndarray, np.ndarray]:
    """Reads an OBJ, OFF, PLY or STL file.

    Returns V (#V x 3 float64) and F (#F x 3 int64; polygons fan-triangulated). Raises OSError
    when the file is missing or unreadable, ValueError when it holds no valid triangles.
    """
    V, F = _core.load_mesh(str(path))
    return np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64)


def as_mesh(V, F) -> Tuple[np.ndarray, np.ndarray]:
    """Checks shapes and dtypes and returns contiguous float64 / int64 copies (ValueError)."""
    try:
        V = np.ascontiguousarray(V, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"V must be an n x 3 array of numbers: {error}") from None
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"V must be an n x 3 array of vertex positions, got shape {V.shape}")
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"F must be an m x 3 array of triangle indices, got shape {F.shape}")
    if F.size and not np.issubdtype(F.dtype, np.integer):
        if not np.issubdtype(F.dtype, np.floating) or not np.all(np.isfinite(F)) or np.any(
                F != np.round(F)):
            raise ValueError(f"F must hold integer vertex indices, got dtype {F.dtype}")
    return V, np.ascontiguousarray(F, dtype=np.int64)


@dataclass
class PreparedMesh:
    """Stage 0. vertices/faces: the working mesh in normalized units (input = v*scale+offset)."""

    vertices: np.ndarray
    faces: np.ndarray
    scale: float
    offset: np.ndarray
    genus: int
    repaired: bool
    report: Dict[str, Any]
    map_face: np.ndarray
    map_barycentric: np.ndarray
    remeshed: bool = False
    wrap_alpha: float = 0.0


@dataclass
class Balls:
    """Balls inside the shape, in normalized units. source: index among the stage-1 balls."""

    centers: np.ndarray
    radii: np.ndarray
    source: Optional[np.ndarray] = None


@dataclass
class Prongs:
    """Stage 3, in normalized units on the working mesh (PreparedMesh.vertices / faces).

    vertices      #P int64 peak vertex of each prong in the working mesh, strongest first
    positions     #P x 3 float64 peak positions (normalized units)
    significance  #P float64 ratio valley / peak (lower = stronger), increasing
    tau           the smoothness ratio they were selected with
    The rest is filled by Extractor.prongs() without tau (None after re-thresholding):
    scale_function  #V float64 f(v), mean geodesic distance to the surface (normalized units)
    sources / source_weights  #S int64 geodesic sources and the area each stands for
    peaks         dict of #K arrays over every local maximum of f, by increasing ratio:
                  vertices, values, valleys, ratios, global (bool)
    """

    vertices: np.ndarray
    positions: np.ndarray
    significance: np.ndarray
    tau: float
    scale_function: Optional[np.ndarray] = None
    sources: Optional[np.ndarray] = None
    source_weights: Optional[np.ndarray] = None
    peaks: Optional[Dict[str, np.ndarray]] = None

    @staticmethod
    def _from_core(d) -> "Prongs":
        def opt(key, dtype=None):
            return np.asarray(d[key], dtype=dtype) if key in d else None

        peaks = None
        if "peaks" in d:
            peaks = {key: np.asarray(value) for key, value in dict(d["peaks"]).items()}
        return Prongs(
            vertices=np.asarray(d["vertices"], dtype=np.int64),
            positions=np.asarray(d["positions"], dtype=np.float64).reshape(-1, 3),
            significance=np.asarray(d["significance"], dtype=np.float64),
            tau=float(d["tau"]), scale_function=opt("scale_function", np.float64),
            sources=opt("sources", np.int64), source_weights=opt("source_weights", np.float64),
            peaks=peaks)


@dataclass
class Field:
    """Stage 4 at some points (normalized units): force #P x 3, magnitude #P (|F|), r_min #P
    (shortest ray distance), outside_rays #P (rays that did not leave through the back of a face:
    0 inside)."""

    force: np.ndarray
    magnitude: np.ndarray
    r_min: np.ndarray
    outside_rays: np.ndarray


@dataclass
class ConnectionPoints:
    """Stage 5 (normalized units). Per domain point (#D): shrunk positions, shrunk_magnitude,
    shrunk_radii, steps, converged (bool), cluster (index of the connection point that absorbed
    it). Per connection point (#C, by increasing |F|): positions, radii, magnitude, source."""

    shrunk: np.ndarray
    shrunk_magnitude: np.ndarray
    shrunk_radii: np.ndarray
    steps: np.ndarray
    converged: np.ndarray
    cluster: np.ndarray
    positions: np.ndarray
    radii: np.ndarray
    magnitude: np.ndarray
    source: np.ndarray


@dataclass
class DomainGraph:
    """Stage 6 (normalized units, faces of PreparedMesh.faces). points #P x 3 (connection points
    then end points), radii, prong (-1 for connection points); face_labels #F (point per face);
    candidates #L x 2 and costs #L (mean |F|, inf when the segment leaves the shape);
    candidate_state #L (0 unused, 1 tree, 2 kept cycle); nodes #N (point of each node), links
    #K x 2 (node pairs), kinds #N, node_of_point #P, face_nodes #F; cycles, components and the
    counts of each rule in `stats`."""

    points: np.ndarray
    radii: np.ndarray
    prong: np.ndarray
    face_labels: np.ndarray
    candidates: np.ndarray
    costs: np.ndarray
    candidate_state: np.ndarray
    nodes: np.ndarray
    links: np.ndarray
    kinds: np.ndarray
    node_of_point: np.ndarray
    face_nodes: np.ndarray
    cycles: int
    components: int
    stats: Dict[str, int]


@dataclass
class Remapped:
    """Stage 7 (normalized units): one polyline per DomainGraph link (node a .. node b),
    snake iterations and rerouted (1: the straight link left the shape) per link."""

    polylines: list
    iterations: np.ndarray
    rerouted: np.ndarray
    moves_refused: int
    unrouted: int


class Extractor:
    """Runs the pipeline one stage at a time and keeps every result (paper Fig. 4).

    Each method runs the stages it needs first; calling it again returns the kept result.
    """

    def __init__(self, V, F, progress: Optional[ProgressCallback] = None, **options):
        V, F = as_mesh(V, F)
        self.options = normalize_options(options)
        self._core = _core.Extractor(V, F, self.options, progress)
        self._skeleton: Optional[Skeleton] = None

    def prepare(self) -> PreparedMesh:
        d = self._core.prepare()
        return PreparedMesh(
            vertices=np.asarray(d["vertices"]), faces=np.asarray(d["faces"]),
            scale=float(d["scale"]), offset=np.asarray(d["offset"]).reshape(3),
            genus=int(d["genus"]), repaired=bool(d["repaired"]), report=dict(d["report"]),
            map_face=np.asarray(d["map_face"]), map_barycentric=np.asarray(d["map_barycentric"]),
            remeshed=bool(d["remeshed"]), wrap_alpha=float(d["wrap_alpha"]))

    def voronoi_balls(self) -> Balls:
        d = self._core.voronoi_balls()
        return Balls(np.asarray(d["centers"]).reshape(-1, 3), np.asarray(d["radii"]))

    def domain_balls(self) -> Balls:
        d = self._core.domain_balls()
        return Balls(np.asarray(d["centers"]).reshape(-1, 3), np.asarray(d["radii"]),
                     np.asarray(d["source"], dtype=np.int64))

    def prongs(self, tau: Optional[float] = None) -> Prongs:
        """Stage 3 at the extractor's tau, or re-thresholded at `tau` (no new geodesics)."""
        if tau is not None:
            try:
                tau = float(tau)
            except (TypeError, ValueError):
                raise ValueError(f"tau must be a number, got {tau!r}") from None
        return Prongs._from_core(self._core.prongs(tau))

    def end_points(self) -> Balls:
        """Each prong's end point (strongest prong first): the stage-1 ball nearest to its peak
        that sees it. source: index among voronoi_balls(), -1 (radius 0, the peak itself) when
        no ball sees the peak. Normalized units."""
        d = self._core.end_points()
        return Balls(np.asarray(d["centers"]).reshape(-1, 3), np.asarray(d["radii"]),
                     np.asarray(d["source"], dtype=np.int64))

    def force_field(self, points=None) -> Field:
        """Stage 4: F at `points` (#P x 3, normalized units), or at the domain points."""
        if points is not None:
            points = np.ascontiguousarray(points, dtype=np.float64)
            if points.ndim != 2 or points.shape[1] != 3:
                raise ValueError(f"points must be an n x 3 array, got shape {points.shape}")
        d = self._core.force_field(points)
        return Field(np.asarray(d["force"]).reshape(-1, 3), np.asarray(d["magnitude"]),
                     np.asarray(d["r_min"]), np.asarray(d["outside_rays"], dtype=np.int64))

    def connection_points(self) -> ConnectionPoints:
        """Stage 5: the domain points shrunk along the field and merged greedily."""
        d = self._core.connection_points()
        return ConnectionPoints(
            shrunk=np.asarray(d["shrunk"]).reshape(-1, 3),
            shrunk_magnitude=np.asarray(d["shrunk_magnitude"]),
            shrunk_radii=np.asarray(d["shrunk_radii"]), steps=np.asarray(d["steps"]),
            converged=np.asarray(d["converged"], dtype=bool), cluster=np.asarray(d["cluster"]),
            positions=np.asarray(d["positions"]).reshape(-1, 3), radii=np.asarray(d["radii"]),
            magnitude=np.asarray(d["magnitude"]), source=np.asarray(d["source"]))

    def domain_graph(self) -> DomainGraph:
        """Stage 6: domain surfaces (face labels), links and the kept graph."""
        d = dict(self._core.domain_graph())
        arrays = {key: np.asarray(d.pop(key)) for key in (
            "points", "radii", "prong", "face_labels", "candidates", "costs", "candidate_state",
            "nodes", "links", "node_of_point", "face_nodes")}
        arrays["points"] = arrays["points"].reshape(-1, 3)
        arrays["candidates"] = arrays["candidates"].reshape(-1, 2)
        arrays["links"] = arrays["links"].reshape(-1, 2)
        kinds = np.asarray(d.pop("kinds"), dtype=str)
        cycles, components = int(d.pop("cycles")), int(d.pop("components"))
        stats = {key: int(value) for key, value in d.items() if np.ndim(value) == 0}
        return DomainGraph(kinds=kinds, cycles=cycles, components=components, stats=stats,
                           **arrays)

    def remap(self) -> Remapped:
        """Stage 7: the snake-fitted polyline of every DomainGraph link."""
        d = self._core.remap()
        return Remapped([np.asarray(p).reshape(-1, 3) for p in d["polylines"]],
                        np.asarray(d["iterations"]), np.asarray(d["rerouted"]),
                        int(d["moves_refused"]), int(d["unrouted"]))

    @property
    def timings(self):
        """[(stage, seconds), ...] for the stages run so far, in order."""
        return list(self._core.timings)

    def skeleton(self) -> Skeleton:
        if self._skeleton is None:
            # The options that made it (the weights' own do not change a skeleton).
            made_with = {k: v for k, v in self.options.items() if k in SKELETON_OPTIONS}
            self._skeleton = Skeleton._from_core(self._core.skeleton(), made_with)
        return self._skeleton


def extract_skeleton(V, F, progress: Optional[ProgressCallback] = None, **options) -> Skeleton:
    """The DCG skeleton of the mesh (V #V x 3, F #F x 3), in the mesh's coordinates.

    options: see dcg.OPTIONS (names, defaults, ranges) and README.md. progress(stage, fraction)
    is called from the calling thread; return False to cancel (raises dcg.Cancelled).
    """
    return Extractor(V, F, progress, **options).skeleton()
