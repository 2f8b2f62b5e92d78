"""The skeleton result and its JSON form (format "dcg-skeleton/1", documented in README.md)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any, Dict, List

import numpy as np

FORMAT = "dcg-skeleton/1"


@dataclass
class Skeleton:
    """A DCG skeleton in the input mesh's coordinates.

    positions    #N x 3 float64 node positions
    kinds        #N str: "end", "joint" or "connection"
    radii        #N float64 distance from each node to the surface
    significance #N float64 prong ratio valley/peak of end nodes (lower = stronger), else 0
    links        #L x 2 int64 node index pairs
    polylines    #L arrays (p_i x 3), from node links[i,0] to node links[i,1], both included
    root         the root node (the torso joint), -1 for an empty skeleton
    face_labels  #F int64 node of each input face (its domain surface), -1 = not labelled
    timings      stage -> seconds, in the order the stages ran, then "total"
    """

    positions: np.ndarray
    kinds: np.ndarray
    radii: np.ndarray
    significance: np.ndarray
    links: np.ndarray
    polylines: List[np.ndarray]
    root: int
    face_labels: np.ndarray
    timings: Dict[str, float]
    genus: int = 0
    repaired: bool = False
    method: str = ""
    input_vertices: int = 0
    input_faces: int = 0
    options: Dict[str, Any] = field(default_factory=dict)

    @classmethod
    def _from_core(cls, d: Dict[str, Any], options: Dict[str, Any]) -> "Skeleton":
        return cls(
            positions=np.asarray(d["positions"], dtype=np.float64).reshape(-1, 3),
            kinds=np.asarray(d["kinds"], dtype=str),
            radii=np.asarray(d["radii"], dtype=np.float64),
            significance=np.asarray(d["significance"], dtype=np.float64),
            links=np.asarray(d["links"], dtype=np.int64).reshape(-1, 2),
            polylines=[np.asarray(p, dtype=np.float64).reshape(-1, 3) for p in d["polylines"]],
            root=int(d["root"]),
            face_labels=np.asarray(d["face_labels"], dtype=np.int64),
            timings={name: float(s) for name, s in d["timings"]},
            genus=int(d["genus"]),
            repaired=bool(d["repaired"]),
            method=str(d["method"]),
            input_vertices=int(d["input_vertices"]),
            input_faces=int(d["input_faces"]),
            options=dict(options),
        )

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
                }
                for (a, b), poly in zip(self.links.tolist(), self.polylines)
            ],
            "root": self.root,
            "timings": dict(self.timings),
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
            root=int(doc["root"]),
            face_labels=np.full(int(doc["mesh"]["faces"]), -1, dtype=np.int64),
            timings={k: float(v) for k, v in doc.get("timings", {}).items()},
            genus=int(doc["mesh"]["genus"]),
            repaired=bool(doc["mesh"]["repaired"]),
            method=str(doc.get("method", "")),
            input_vertices=int(doc["mesh"]["vertices"]),
            input_faces=int(doc["mesh"]["faces"]),
            options=dict(doc.get("options", {})),
        )

    @classmethod
    def from_json(cls, text: str) -> "Skeleton":
        return cls.from_dict(json.loads(text))
