"""Builds a big test mesh by midpoint subdivision of armadillo.obj (each triangle -> 4, edge
midpoints shared, so the result stays a closed manifold of the same shape) and writes it as a
binary PLY. Two levels turn the 86k-face armadillo into 1.38M faces.

    PYTHONPATH=build/python python3 scripts/make_big_mesh.py [--mesh ../shared/meshes/armadillo.obj] [--levels 2]
                                                         [--out out/bench/armadillo-1m.ply]
"""

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def subdivide(V, F):
    """One midpoint subdivision: a new vertex on every edge, four triangles per triangle."""
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    mid = len(V) + inverse.reshape(3, -1).T  # per face: midpoints of edges 01, 12, 20
    V2 = np.vstack([V, 0.5 * (V[unique[:, 0]] + V[unique[:, 1]])])
    a, b, c = F[:, 0], F[:, 1], F[:, 2]
    ab, bc, ca = mid[:, 0], mid[:, 1], mid[:, 2]
    F2 = np.concatenate([np.column_stack(t) for t in
                         ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    return V2, F2


def write_ply(path, V, F):
    path.parent.mkdir(parents=True, exist_ok=True)
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(V)}\nproperty double x\nproperty double y\nproperty double z\n"
              f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
    faces = np.empty(len(F), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"] = 3
    faces["i"] = F
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        f.write(faces.tobytes())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", type=Path, default=ROOT.parent / "shared/meshes/armadillo.obj")
    parser.add_argument("--levels", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "out/bench/armadillo-1m.ply")
    args = parser.parse_args(argv)
    if not args.mesh.is_file():
        print(f"make_big_mesh: {args.mesh} not found (set --mesh)", file=sys.stderr)
        return 1
    import dcg  # the built module (PYTHONPATH=build/python, as bench_big.py runs it)
    V, F = dcg.load_mesh(args.mesh)
    for _ in range(args.levels):
        V, F = subdivide(V, F)
    write_ply(args.out, V, F)
    print(f"make_big_mesh: {args.out}: {len(V)} vertices, {len(F)} faces")
    return 0


if __name__ == "__main__":
    sys.exit(main())
