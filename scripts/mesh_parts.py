#!/usr/bin/python3
"""A mesh's parts and whether a skeleton lies inside one of them (make bench, numpy only).

    PYTHONPATH=build/python /usr/bin/python3 scripts/mesh_parts.py \\
        --results out/bench/results.jsonl --out out/bench/parts.jsonl

Parts are the connected components over shared edges after welding exactly repeated points
(what stage 0 reports as `components`, and what a game character made of separate closed
pieces has several of). dcg_bench's inside % tests a sample against the whole input by ray
parity, which is right for one closed part and wrong for several: a sample where two parts
overlap, or inside an eye inside the head, crosses an even number of surfaces and counts as
outside. Here a sample is inside when it is inside at least one part, by that part's winding
number (above 1/2; on an open part, a scan with holes, that is still a fair answer where
parity is not). The samples are dcg_bench's (scripts/bench.py's skeleton files): every node
and polyline point, and a point each 0.5% of the bounding-box diagonal along every polyline
segment; CGAL's MCF skeleton alike (its vertices, along its edges).

As a script: for every mesh of dcg_bench's JSON lines with more than one part or an open
surface (one closed part: dcg_bench's own parity is kept), one JSON line per mesh: `mesh`,
`path`, `parts`, `closed`, `inside_percent` (ours), `mcf_inside_percent`, `samples`,
`mcf_samples`. The mesh is read with dcg.load_mesh (the reader dcg_bench uses).
"""
import argparse
import json
import sys
from pathlib import Path

import numpy as np

#: Samples along skeleton segments, in bounding-box diagonals (dcg_bench's spacing).
SAMPLE_SPACING = 0.005
#: Winding-number pairs (points x faces) per numpy block.
BLOCK = 1 << 20


def weld_exact(V, F):
    """(V', F'): exactly repeated points merged into one, unreferenced points dropped."""
    used = np.unique(F)
    unique, inverse = np.unique(V[used], axis=0, return_inverse=True)
    index = np.full(len(V), -1, dtype=np.int64)
    index[used] = inverse.reshape(-1)
    return unique, index[F]


def connected_components(n, pairs):
    """#n labels 0..k-1 (in order of first appearance) of the graph on n nodes with edges
    `pairs` (#P by 2 int), numpy only: every edge hooks the larger of its two roots under the
    smaller, then every node jumps to its root, until no edge joins two roots."""
    label = np.arange(n, dtype=np.int64)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    while True:
        ra, rb = label[a], label[b]
        differ = ra != rb
        if not differ.any():
            break
        a, b, ra, rb = a[differ], b[differ], ra[differ], rb[differ]
        np.minimum.at(label, np.maximum(ra, rb), np.minimum(ra, rb))
        while True:  # pointer jumping: a root's label is its own
            jumped = label[label]
            if np.array_equal(jumped, label):
                break
            label = jumped
    _, first, dense = np.unique(label, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))  # number the parts by their first node
    return order[dense.reshape(-1)]


def edge_faces(F):
    """(edges #E by 2 sorted vertex pairs, face_of #3F, edge_of #3F): every face corner's edge
    (corner k of face f is edge F[f, k] - F[f, k+1], row 3f + k)."""
    corner_edges = np.sort(np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    n = int(F.max()) + 1 if F.size else 1
    keys, edge_of = np.unique(corner_edges[:, 0] * n + corner_edges[:, 1], return_inverse=True)
    edges = np.stack([keys // n, keys % n], axis=1)
    face_of = np.repeat(np.arange(len(F)), 3)
    return edges, face_of, edge_of.reshape(-1)


def face_parts(F):
    """#F part labels: faces joined where they share an edge (two faces sharing only a vertex,
    a pinch, are in different parts). Weld first (weld_exact) when points repeat."""
    F = np.asarray(F, dtype=np.int64)
    if len(F) == 0:
        return np.zeros(0, dtype=np.int64)
    _, face_of, edge_of = edge_faces(F)
    order = np.argsort(edge_of, kind="stable")
    same = edge_of[order][1:] == edge_of[order][:-1]
    pairs = np.stack([face_of[order][:-1][same], face_of[order][1:][same]], axis=1)
    return connected_components(len(F), pairs)


def topology(F, parts=None):
    """Counts of a (welded) triangle mesh: border and non-manifold edges, non-manifold
    (pinched) vertices, parts, and the genus summed over the parts (None unless the mesh is a
    closed manifold). `parts`: face_parts(F) when already known."""
    F = np.asarray(F, dtype=np.int64)
    edges, face_of, edge_of = edge_faces(F)
    per_edge = np.bincount(edge_of, minlength=len(edges))
    parts = face_parts(F) if parts is None else parts
    # Fans around each vertex: corners (row 3 f + k: vertex F[f, k]) joined across the
    # manifold edges they share. Row r of edge_of is the edge from corner r to the next one.
    order = np.argsort(edge_of, kind="stable")
    lo, hi = order[:-1], order[1:]
    keep = (edge_of[lo] == edge_of[hi]) & (per_edge[edge_of[lo]] == 2)
    lo, hi = lo[keep], hi[keep]
    lo_next, hi_next = lo - lo % 3 + (lo % 3 + 1) % 3, hi - hi % 3 + (hi % 3 + 1) % 3
    flat = F.reshape(-1)
    same = flat[lo] == flat[hi]  # the faces run the shared edge the same way (misoriented)
    pairs = np.concatenate([
        np.stack([lo, np.where(same, hi, hi_next)], axis=1),
        np.stack([lo_next, np.where(same, hi_next, hi)], axis=1)])
    fan = connected_components(3 * len(F), pairs)
    vertex_fans = np.unique(np.stack([F.reshape(-1), fan], axis=1), axis=0)[:, 0]
    pinched = int(np.sum(np.bincount(vertex_fans) > 1))
    border = int(np.sum(per_edge == 1))
    non_manifold = int(np.sum(per_edge > 2))
    closed = border == 0 and non_manifold == 0 and pinched == 0
    genus = None
    if closed:
        k = int(parts.max()) + 1 if len(parts) else 0
        euler = len(np.unique(F)) - len(edges) + len(F)  # sum over parts of 2 - 2 g
        genus = (2 * k - euler) // 2
    return {"border_edges": border, "non_manifold_edges": non_manifold,
            "pinched_vertices": pinched, "parts": int(parts.max()) + 1 if len(parts) else 0,
            "closed": closed, "genus": genus}


def winding_numbers(points, V, F):
    """#P generalized winding numbers of the triangles (V, F) at `points` (#P by 3): 1 inside
    a closed outward-oriented surface, 0 outside, in between near holes of an open one
    (Jacobson et al. 2013; solid angles by Van Oosterom and Strackee)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    A, B, C = (np.asarray(V, dtype=float)[np.asarray(F)[:, k]] for k in range(3))
    out = np.zeros(len(points))
    step = max(1, BLOCK // max(1, len(A)))
    for start in range(0, len(points), step):
        p = points[start:start + step, None, :]
        a, b, c = A[None] - p, B[None] - p, C[None] - p
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
        denom = (la * lb * lc + np.einsum("pfi,pfi->pf", a, b) * lc
                 + np.einsum("pfi,pfi->pf", b, c) * la + np.einsum("pfi,pfi->pf", c, a) * lb)
        out[start:start + step] = np.arctan2(det, denom).sum(axis=1) / (2 * np.pi)
    return out


def inside_any_part(points, V, F, parts=None):
    """#P booleans: inside at least one part of (V, F) (winding number above 1/2 for that
    part's triangles). `parts`: #F labels (face_parts of the welded mesh by default). Points
    outside a part's bounding box are not tested against it."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    if parts is None:
        Vw, Fw = weld_exact(V, F)
        parts = face_parts(Fw)
    inside = np.zeros(len(points), dtype=bool)
    for part in range(int(parts.max()) + 1 if len(parts) else 0):
        Fp = F[parts == part]
        lo, hi = V[Fp].reshape(-1, 3).min(axis=0), V[Fp].reshape(-1, 3).max(axis=0)
        todo = ~inside & np.all((points >= lo) & (points <= hi), axis=1)
        if todo.any():
            inside[todo] = winding_numbers(points[todo], V, Fp) > 0.5
    return inside


def polyline_samples(points, segments, spacing):
    """The points (#P by 3) and, along every segment (a, b), its inner points each `spacing`
    (ceil(|b - a| / spacing) - 1 of them): dcg_bench's inside samples."""
    out = [np.asarray(points, dtype=float).reshape(-1, 3)]
    for a, b in segments:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = int(np.ceil(np.linalg.norm(b - a) / spacing)) if spacing > 0 else 1
        if n > 1:
            t = np.arange(1, n)[:, None] / n
            out.append(a + (b - a) * t)
    return np.concatenate(out)


def skeleton_samples(skeleton, spacing):
    """Samples of our skeleton as dcg_bench's skeleton files hold it (positions, polylines):
    the nodes, the polylines' inner points, and along every polyline segment."""
    points = [np.asarray(skeleton.get("positions") or [], dtype=float).reshape(-1, 3)]
    segments = []
    for line in skeleton.get("polylines") or []:
        line = np.asarray(line, dtype=float).reshape(-1, 3)
        points.append(line[1:-1])
        segments += list(zip(line[:-1], line[1:]))
    return polyline_samples(np.concatenate(points), segments, spacing)


def graph_samples(points, edges, spacing):
    """Samples of a skeleton graph (CGAL's MCF: vertices #P by 3, edges #E by 2)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    return polyline_samples(points, [(points[i], points[j]) for i, j in edges], spacing)


def inside_percent(samples, V, F, parts):
    if len(samples) == 0:
        return None
    return float(100.0 * np.mean(inside_any_part(samples, V, F, parts)))


def measure(V, F, skeleton_file=None):
    """One mesh's record: parts and closedness of (V, F) and, from a dcg_bench skeleton file,
    the inside % of ours and of MCF's by parts."""
    V = np.asarray(V, dtype=float)
    F = np.asarray(F, dtype=np.int64)
    Vw, Fw = weld_exact(V, F)
    parts = face_parts(Fw)
    topo = topology(Fw, parts)
    record = {"parts": topo["parts"], "closed": topo["closed"]}
    if skeleton_file is None:
        return record
    spacing = SAMPLE_SPACING * float(np.linalg.norm(Vw.max(axis=0) - Vw.min(axis=0)))
    data = json.loads(Path(skeleton_file).read_text())
    if data.get("ours"):
        samples = skeleton_samples(data["ours"], spacing)
        record["samples"] = len(samples)
        record["inside_percent"] = inside_percent(samples, Vw, Fw, parts)
    if data.get("mcf"):
        samples = graph_samples(data["mcf"]["points"], data["mcf"]["edges"], spacing)
        record["mcf_samples"] = len(samples)
        record["mcf_inside_percent"] = inside_percent(samples, Vw, Fw, parts)
    return record


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, required=True, help="dcg_bench's JSON lines")
    parser.add_argument("--out", type=Path, required=True, help="JSON lines to write")
    args = parser.parse_args(argv)
    import dcg  # the engine's reader, as dcg_bench reads the files

    lines = []
    for line in args.results.read_text().splitlines():
        row = json.loads(line) if line.strip() else {}
        if row.get("type") != "mesh":
            continue
        record = {"mesh": row["mesh"], "path": row["path"]}
        try:
            V, F = dcg.load_mesh(row["path"])
            record.update(measure(V, F))
            if (record["parts"] > 1 or not record["closed"]) and row.get("skeleton_file"):
                record.update(measure(V, F, row["skeleton_file"]))
                record["inside_by"] = "parts"
            else:
                record["inside_by"] = "dcg_bench"  # one closed part: its ray parity is right
        except Exception as e:  # noqa: BLE001 - one bad mesh is a note, the others go on
            record["error"] = f"{type(e).__name__}: {e}"
        lines.append(json.dumps(record))
        print(f"mesh_parts: {row['mesh']}: {record.get('parts', '?')} part(s)"
              + (f", inside {record['inside_percent']:.1f}%"
                 if record.get("inside_percent") is not None else ""), file=sys.stderr)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text("".join(line + "\n" for line in lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
