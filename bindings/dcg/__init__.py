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
    prongs.hierarchy.prongs(0.7)  # the same from the kept ProngHierarchy (a slider's call)
    ends = ex.end_points()        # a stage-1 ball per prong that sees its peak
    field = ex.force_field()      # stage 4: F and |F| at the domain points (or at any points)
    points = ex.connection_points()  # stage 5: shrunk along the field, merged
    graph = ex.domain_graph()     # stage 6: face labels, links, spanning tree + handle cycles
    remapped = ex.remap()         # stage 7: snake-fitted link polylines
    skeleton = ex.skeleton()
    print(ex.timings)             # [(stage, seconds), ...]
    ex.retune(0.7)                # a live tau: only end points, graph, remap, skeleton rerun
    fewer_bones = ex.skeleton()

Each result is the engine's own object, read-only (cpp/include/dcg/<stage>.h documents its
fields); it keeps the extractor alive (those after stage 3, which a retune replaces, are
copies). skin_weights and BoneHeat (bone heat solved once per bone
set on a precomputed mesh) are in dcg.weights.

Errors: ValueError for bad data or options, OSError for unreadable files, dcg.Cancelled when a
progress callback returns False. The heavy work runs with the GIL released.
"""

from __future__ import annotations

from typing import Callable, Optional, Tuple

import numpy as np

from . import _core


def _check_numpy(pybind11_version: Tuple[int, int], numpy_version: str) -> None:
    """ImportError, instead of a crash at the first array, when the compiled module's pybind11
    predates numpy 2 support (2.12) and numpy 2 or later is installed."""
    numpy_major = int(numpy_version.split(".")[0])
    if numpy_major >= 2 and tuple(pybind11_version) < (2, 12):
        raise ImportError(
            f"dcg's compiled module was built with pybind11 {pybind11_version[0]}."
            f"{pybind11_version[1]}, which cannot pass arrays to numpy {numpy_version}: use the "
            "dcg wheel (built with pybind11 >= 2.12), rebuild against pybind11 >= 2.12, or run "
            "it with numpy < 2")


_check_numpy(getattr(_core, "pybind11_version", (2, 12)), np.__version__)

from . import bones, humanoid, rig_warnings, rolls, symmetry  # noqa: E402,F401  (bone planner)
from .options import OPTIONS, SKELETON_OPTIONS, OptionInfo, normalize_options  # noqa: E402
from .skeleton import FORMAT, Skeleton  # noqa: E402
from .weights import BoneHeat, SkinWeights, skin_weights  # noqa: E402

# The stages' results: engine objects, read-only, each field as its header documents it
# (cpp/include/dcg/<stage>.h); arrays are float64 / int64 numpy arrays.
PreparedMesh = _core.PreparedMesh
Balls = _core.Balls
DomainBalls = _core.DomainBalls
Prongs = _core.Prongs
ProngHierarchy = _core.ProngHierarchy
EndPoints = _core.EndPoints
FieldSamples = _core.FieldSamples
Field = FieldSamples  # its former name
ConnectionPoints = _core.ConnectionPoints
DomainGraph = _core.DomainGraph
Remapped = _core.Remapped

__all__ = [
    "Cancelled", "Extractor", "OPTIONS", "OptionInfo", "Skeleton", "FORMAT", "Balls",
    "PreparedMesh", "Prongs", "extract_skeleton", "load_mesh", "as_mesh",
    "SkinWeights", "skin_weights", "BoneHeat", "ProngHierarchy", "DomainBalls", "EndPoints",
    "Field", "FieldSamples", "ConnectionPoints", "DomainGraph", "Remapped", "repair_summary",
    "limit_threads",
]
__version__ = "0.1.0"

#: Raised when a progress callback returns False.
Cancelled = _core.Cancelled

#: progress(stage, fraction) -> bool | None; return False to cancel.
ProgressCallback = Callable[[str, float], Optional[bool]]


def limit_threads(count: int) -> int:
    """Let the engine's parallel loops in this process use at most `count` threads (0: every
    core, the default); return the limit now in force. For processes that share a machine's
    cores with others: `dcg batch`'s workers each use their own share (one per core on a local
    cluster), not every core apiece."""
    if isinstance(count, bool) or not isinstance(count, int) or count < 0:
        raise ValueError(f"count must be a whole number >= 0, got {count!r}")
    return _core.limit_threads(count)


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


def repair_summary(prepared) -> Optional[str]:
    """What stage 0 did to a mesh that is not one closed manifold, in a sentence for the user
    (the add-on's report, the CLI), or None when the mesh was used as it is.

    prepared: a dcg.PreparedMesh (Extractor.prepare()). The union of closed parts keeps the
    input's own surface; fins left out, parts that crossed themselves wrapped alone and the alpha
    wrap of the whole (a closed proxy) are said so.
    """
    if not prepared.repaired:
        return None
    r = prepared.report
    problems = []
    if r["components"] > 1:
        problems.append(_count(r["components"], "part"))
    if r["border_edges"]:
        problems.append(f"{_count(r['border_edges'], 'border edge')} in "
                        f"{_count(r['border_loops'], 'hole')}")
    if r["non_manifold_edges"]:
        problems.append(_count(r["non_manifold_edges"], "non-manifold edge"))
    if r["non_manifold_vertices"]:
        problems.append(_count(r["non_manifold_vertices"], "pinched vertex", "pinched vertices"))
    if not r["orientable"]:
        problems.append("a non-orientable surface")
    found = "the mesh has " + (", ".join(problems) or "no single closed surface")
    if prepared.wrap_alpha > 0:
        return (f"{found}: skeleton of its alpha wrap, a closed proxy that smooths over "
                f"details below {prepared.wrap_alpha:.1%} of the bounding-box diagonal")
    fins, holes = r.get("fin_faces", 0), r.get("filled_holes", 0)
    cavities, rewrapped = r.get("cavities", 0), r.get("wrapped_parts", 0)
    done = ""
    if rewrapped:
        one = rewrapped == 1
        done += (f", {_count(rewrapped, 'part')} that crossed {'itself' if one else 'themselves'}"
                 f" replaced by {'its' if one else 'their'} alpha wrap (details below "
                 f"{r.get('part_wrap_alpha', 0):.1%} of the diagonal smoothed)")
    if fins:
        done += f", leaving out {fins} faces of zero-volume fins or inner walls"
    if holes:
        done += f", once its {_count(holes, 'hole')} {'is' if holes == 1 else 'are'} filled"
    if cavities:
        done += f", and {_count(cavities, 'cavity', 'cavities')} enclosed between the parts filled"
    return f"{found}: skeleton of the union of its closed parts{done}"


def _count(n: int, thing: str, things: Optional[str] = None) -> str:
    return f"{n} {thing}" if n == 1 else f"{n} {things or thing + 's'}"


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
        """Stage 0: the closed working mesh (normalized units) and the repair report."""
        return self._core.prepare()

    def voronoi_balls(self) -> Balls:
        """Stage 1: Voronoi balls inside the shape (normalized units)."""
        return self._core.voronoi_balls()

    def domain_balls(self) -> DomainBalls:
        """Stage 2: non-intersecting domain balls, largest first (normalized units)."""
        return self._core.domain_balls()

    def prongs(self, tau: Optional[float] = None) -> Prongs:
        """Stage 3 at the extractor's tau, or re-thresholded at `tau` (no new geodesics)."""
        if tau is not None:
            try:
                tau = float(tau)
            except (TypeError, ValueError):
                raise ValueError(f"tau must be a number, got {tau!r}") from None
        return self._core.prongs(tau)

    def retune(self, tau: float) -> None:
        """A live tau: make `tau` this extractor's smoothness ratio. The prongs are
        re-thresholded (no new geodesics) and only the stages that follow from them (end
        points, domain graph, remap, skeleton) run again at the next call; the voronoi and
        domain balls, the force field and the connection points are kept. Results taken
        before stay as they were. ValueError for tau outside (0, 1]."""
        try:
            tau = float(tau)
        except (TypeError, ValueError):
            raise ValueError(f"tau must be a number, got {tau!r}") from None
        self._core.retune(tau)
        self.options["tau"] = tau
        self._skeleton = None

    def end_points(self) -> EndPoints:
        """Each prong's end point (strongest prong first): the stage-1 ball nearest to its peak
        that sees it and is near it (a small ball far down a thin part is passed over:
        dcg/end_points.h, kEndBallFarRadii). source: index among voronoi_balls(), -1 (radius 0,
        the peak itself) when no such ball sees the peak. Normalized units."""
        return self._core.end_points()

    def force_field(self, points=None) -> FieldSamples:
        """Stage 4: F at `points` (#P x 3, normalized units), or at the domain points."""
        if points is not None:
            points = np.ascontiguousarray(points, dtype=np.float64)
            if points.ndim != 2 or points.shape[1] != 3:
                raise ValueError(f"points must be an n x 3 array, got shape {points.shape}")
        return self._core.force_field(points)

    def connection_points(self) -> ConnectionPoints:
        """Stage 5: the domain points shrunk along the field and merged greedily."""
        return self._core.connection_points()

    def domain_graph(self) -> DomainGraph:
        """Stage 6: domain surfaces (face labels), links and the kept graph."""
        return self._core.domain_graph()

    def remap(self) -> Remapped:
        """Stage 7: the snake-fitted polyline of every DomainGraph link."""
        return self._core.remap()

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
