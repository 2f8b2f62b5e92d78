"""The skeleton result and its JSON form (format "dcg-skeleton/1", documented in README.md)."""

from __future__ import annotations

import copy
import json
from dataclasses import field, make_dataclass
from typing import Any, Dict, List

import numpy as np

from . import _core

FORMAT = "dcg-skeleton/1"


def result_fields(core_class) -> List[str]:
    """The fields the engine binds on `core_class` (bindings/bind_results.cpp), in order."""
    return [name for name, value in vars(core_class).items() if isinstance(value, property)]


#: The skeleton's fields: those of the engine's dcg::Skeleton (cpp/include/dcg/skeleton.h).
FIELDS = result_fields(_core.Skeleton)


def measured_polyline_radii(skeleton):
    """`skeleton.polyline_radii` (the distance to the surface at each polyline point, one array
    per polyline) or None where it has none (an older document, a view without them)."""
    radii = getattr(skeleton, "polyline_radii", None)
    polylines = skeleton.polylines
    return radii if radii is not None and len(radii) == len(polylines) > 0 else None


class _SkeletonMethods:
    """What dcg.Skeleton adds to its fields: JSON, dicts, node_count."""

    @classmethod
    def _from_core(cls, core, options: Dict[str, Any]) -> "Skeleton":
        """A copy of the engine's skeleton (which would keep the whole extractor alive)."""
        return cls(**{name: copy.deepcopy(getattr(core, name)) for name in FIELDS},
                   options=dict(options))

    @property
    def node_count(self) -> int:
        return int(self.positions.shape[0])

    def to_dict(self) -> Dict[str, Any]:
        """The JSON document as Python objects (lists, floats, ints)."""
        return {
            "format": FORMAT,
            "mesh": {
                "vertices": self.input_vertices,
                "faces": self.input_faces,
                "genus": self.genus,
                "repaired": self.repaired,
            },
            "options": dict(self.options),
            "method": self.method,
            "nodes": [
                {
                    "id": i,
                    "kind": str(self.kinds[i]),
                    "position": [float(x) for x in self.positions[i]],
                    "radius": float(self.radii[i]),
                    "significance": float(self.significance[i]),
                }
                for i in range(self.node_count)
            ],
            "links": [
                {
                    "a": int(a),
                    "b": int(b),
                    "polyline": [[float(x) for x in p] for p in poly],
                    **({"radii": [float(r) for r in self.polyline_radii[l]]}
                       if measured_polyline_radii(self) is not None else {}),
                }
                for l, ((a, b), poly) in enumerate(zip(self.links.tolist(), self.polylines))
            ],
            "root": self.root,
            "timings": dict(self.timings),
            "mirror": {"plane": [float(x) for x in self.mirror_plane],
                       "error": float(self.mirror_error)},
        }

    def to_json(self, indent: int | None = None) -> str:
        return json.dumps(self.to_dict(), indent=indent)

    @classmethod
    def from_dict(cls, doc: Dict[str, Any]) -> "Skeleton":
        """Reads a document written by to_dict / to_json (face labels are not stored there)."""
        if doc.get("format") != FORMAT:
            raise ValueError(f"not a {FORMAT} document (format = {doc.get('format')!r})")
        nodes = doc["nodes"]
        links = doc["links"]
        return cls(
            positions=np.array([n["position"] for n in nodes], dtype=np.float64).reshape(-1, 3),
            kinds=np.array([n["kind"] for n in nodes], dtype=str),
            radii=np.array([n["radius"] for n in nodes], dtype=np.float64),
            significance=np.array([n["significance"] for n in nodes], dtype=np.float64),
            links=np.array([[l["a"], l["b"]] for l in links], dtype=np.int64).reshape(-1, 2),
            polylines=[np.array(l["polyline"], dtype=np.float64).reshape(-1, 3) for l in links],
            # Documents written before the polylines' radii were kept have none ([]).
            polyline_radii=[np.array(l["radii"], dtype=np.float64) for l in links]
            if all("radii" in l for l in links) and links else [],
            root=int(doc["root"]),
            face_labels=np.full(int(doc["mesh"]["faces"]), -1, dtype=np.int64),
            timings={k: float(v) for k, v in doc.get("timings", {}).items()},
            genus=int(doc["mesh"]["genus"]),
            repaired=bool(doc["mesh"]["repaired"]),
            method=str(doc.get("method", "")),
            input_vertices=int(doc["mesh"]["vertices"]),
            input_faces=int(doc["mesh"]["faces"]),
            options=dict(doc.get("options", {})),
            # Documents written before the mirror plane was kept have none (error 1).
            mirror_plane=np.array(doc.get("mirror", {}).get("plane", [0.0] * 4), dtype=np.float64),
            mirror_error=float(doc.get("mirror", {}).get("error", 1.0)),
        )

    @classmethod
    def from_json(cls, text: str) -> "Skeleton":
        return cls.from_dict(json.loads(text))


Skeleton = make_dataclass(
    "Skeleton", [(name, Any) for name in FIELDS]
    + [("options", Dict[str, Any], field(default_factory=dict))],
    bases=(_SkeletonMethods,), namespace={"__module__": __name__})
Skeleton.__doc__ = f"""A DCG skeleton in the input mesh's coordinates.

A plain dataclass (picklable, made without the engine by from_dict / from_json) of the engine's
dcg::Skeleton fields ({", ".join(FIELDS)}; cpp/include/dcg/skeleton.h documents them:
positions #N x 3 float64, kinds #N str, links #L x 2 int64, face_labels #F int64, timings
stage -> seconds, ...) and the options that made it."""
