#!/usr/bin/python3
"""Writes the benchmark's stress set: meshes like the ones users bring, generated the same way
every time (numpy only, no random draw without a fixed seed), with a MANIFEST.tsv in the
columns of ../shared/meshes/MANIFEST.tsv (expected ends where the shape makes them obvious).

    /usr/bin/python3 scripts/make_stress_set.py [--out out/bench/stress] [--only NAME ...]

The meshes (every piece a closed, outward-oriented surface unless said otherwise):
- spheres-chain4.obj: four spheres overlapping in a row (4 parts);
- spheres-disjoint.obj: three spheres of different sizes apart from each other;
- body-eyes-inside / -touching / -outside.obj: a capsule body and two small spheres for eyes,
  inside the head, half out of it, and floating just in front of it;
- pinched-blobs.obj: two closed blobs sharing one vertex (a non-manifold, pinched vertex);
- scan-open.obj: a bumpy blob with its bottom cut off, four holes and a little noise (open);
- lowpoly-biped.obj, lowpoly-quadruped.obj: game-like figures of 1-3k faces made of separate
  closed capsules and spheres pushed into a torso, each piece at its own resolution (uneven
  triangle sizes, long thin ones on the capsules' sides);
- biped-30k.ply, quadruped-100k.ply: the same figures midpoint-subdivided (the shape and its
  parts unchanged, scripts/make_big_mesh.py's subdivision) to about 30k and 100k faces.

tests/python/conftest.py takes its uv_sphere from here.
"""
import argparse
import sys
from pathlib import Path

import numpy as np

from make_big_mesh import subdivide, write_ply
from mesh_parts import topology, weld_exact

ROOT = Path(__file__).resolve().parents[1]
MANIFEST_COLUMNS = ["file", "source_repo", "path_in_repo", "license", "vertex_count",
                    "face_count", "closed", "genus", "components", "expected_end_points", "notes"]


# --- pieces ------------------------------------------------------------------------------------

def uv_sphere(rings: int = 16, segments: int = 24, radius: float = 1.0):
    """A closed, outward-oriented UV sphere."""
    verts = [[0, 0, radius]]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            verts.append([radius * np.sin(theta) * np.cos(phi),
                          radius * np.sin(theta) * np.sin(phi), radius * np.cos(theta)])
    verts.append([0, 0, -radius])
    faces = []
    bottom = len(verts) - 1

    def ring(i, j):
        return 1 + (i - 1) * segments + j % segments

    for j in range(segments):
        faces.append([0, ring(1, j), ring(1, j + 1)])
        faces.append([bottom, ring(rings - 1, j + 1), ring(rings - 1, j)])
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [[a, c, b], [b, c, d]]
    return np.array(verts, dtype=float), np.array(faces, dtype=np.int64)


def rotation_from_z(direction):
    """3 by 3 rotation taking +Z to `direction` (Rodrigues)."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    z = np.array([0.0, 0.0, 1.0])
    v, c = np.cross(z, d), float(z @ d)
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def ellipsoid(center, radii, rings=12, segments=16):
    """A UV sphere scaled by `radii` (x, y, z) and moved to `center`."""
    V, F = uv_sphere(rings, segments)
    return V * np.asarray(radii, dtype=float) + np.asarray(center, dtype=float), F


def capsule(start, end, radius, rings=9, segments=12):
    """A closed capsule from `start` to `end` (the caps' tips), radius `radius`: a UV sphere of
    an odd number of rings cut at its equator and stretched, so its side is one band of long
    triangles while the caps are fine."""
    if rings % 2 == 0:
        raise ValueError("capsule: rings must be odd (no ring on the equator)")
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    length = max(float(np.linalg.norm(end - start)) - 2 * radius, 0.0)
    V, F = uv_sphere(rings, segments, radius)
    V[:, 2] += np.sign(V[:, 2]) * length / 2
    return V @ rotation_from_z(end - start).T + (start + end) / 2, F


def combine(*pieces):
    """One mesh of several (V, F) pieces, kept as separate parts."""
    Vs, Fs, offset = [], [], 0
    for V, F in pieces:
        Vs.append(V)
        Fs.append(F + offset)
        offset += len(V)
    return np.vstack(Vs), np.vstack(Fs)


# --- the shapes ---------------------------------------------------------------------------------

def spheres_chain4():
    return combine(*(ellipsoid((1.4 * i, 0, 0), (1, 1, 1), 16, 24) for i in range(4)))


def spheres_disjoint():
    return combine(ellipsoid((0, 0, 0), (1, 1, 1), 16, 24),
                   ellipsoid((2.4, 0.3, 0), (0.6, 0.6, 0.6), 12, 18),
                   ellipsoid((4.0, -0.2, 0.4), (0.35, 0.35, 0.35), 10, 14))


def body_with_eyes(where):
    """A standing capsule (radius 0.8, 3.2 tall) and two eyes (radius 0.15) at head height:
    'inside' the head (0.3 under its surface), 'touching' (centred on the surface, half out) or
    'outside' (0.1 in front of it)."""
    radius = 0.8
    body = capsule((0, 0, -1.6), (0, 0, 1.6), radius, rings=17, segments=24)
    depth = {"inside": radius - 0.3, "touching": radius, "outside": radius + 0.25}[where]
    eyes = []
    for side in (-1, 1):
        direction = np.array([0.3 * side, -1.0, 0.0])
        direction /= np.linalg.norm(direction)
        centre = depth * direction + [0, 0, 0.9]
        eyes.append(ellipsoid(centre, (0.15, 0.15, 0.15), 8, 12))
    return combine(body, *eyes)


def pinched_blobs():
    """Two upright ellipsoids, one on top of the other, touching at one vertex that both use:
    closed, but that vertex is pinched (two fans)."""
    top_V, top_F = ellipsoid((0, 0, 1.2), (0.6, 0.5, 1.2), 16, 24)
    low_V, low_F = ellipsoid((0, 0, -1.0), (0.7, 0.55, 1.0), 14, 20)
    angle = 0.3  # the lower blob turned about Z, so that the two are not aligned
    twist = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0],
                      [0, 0, 1]])
    low_V = low_V @ twist.T
    V, F = combine((top_V, top_F), (low_V, low_F))
    top_south, low_north = len(top_V) - 1, len(top_V)  # both at the origin
    F = np.where(F == low_north, top_south, F)
    keep = np.arange(len(V)) != low_north
    remap = np.cumsum(keep) - 1
    return V[keep], remap[F]


def scan_open(seed=7):
    """A blob with three bumps (two ears and a snout) seen by a scanner: the bottom below
    z = -0.55 missing, four round holes, 0.2% noise along the radius."""
    V, F = uv_sphere(48, 80)
    rng = np.random.default_rng(seed)
    r = np.ones(len(V))
    for bump, height, width in (((0.45, 0.0, 0.89), 0.55, 0.10), ((-0.45, 0.0, 0.89), 0.55, 0.10),
                                ((0.0, -1.0, 0.2), 0.35, 0.15)):
        b = np.asarray(bump) / np.linalg.norm(bump)
        r += height * np.exp(-(1 - V @ b) / width)
    r *= 1 + 0.002 * (2 * rng.random(len(V)) - 1)
    V = V * r[:, None] * [1.0, 0.8, 0.9]
    centroids = V[F].mean(axis=1)
    drop = centroids[:, 2] < -0.55
    candidates = np.flatnonzero(V[:, 2] > -0.2)
    for v in candidates[np.floor(rng.random(4) * len(candidates)).astype(int)]:
        drop |= np.linalg.norm(centroids - V[v], axis=1) < 0.12
    F = F[~drop]
    used = np.unique(F)
    index = np.full(len(V), -1)
    index[used] = np.arange(len(used))
    return V[used], index[F]


def lowpoly_biped():
    """A standing figure about 4 tall: torso, head, arms, legs and hands, each its own closed
    piece pushed into the torso (or the arm), each at its own resolution."""
    return combine(
        capsule((0, 0, 1.6), (0, 0, 3.1), 0.5, rings=15, segments=20),        # torso
        ellipsoid((0, 0, 3.45), (0.35, 0.33, 0.4), 12, 16),                   # head
        capsule((-0.3, 0, 2.8), (-1.5, 0, 2.2), 0.14, rings=9, segments=10),  # arms
        capsule((0.3, 0, 2.8), (1.5, 0, 2.2), 0.14, rings=9, segments=10),
        ellipsoid((-1.55, 0, 2.15), (0.14, 0.1, 0.16), 5, 8),                 # hands
        ellipsoid((1.55, 0, 2.15), (0.14, 0.1, 0.16), 5, 8),
        capsule((-0.22, 0, 1.9), (-0.3, 0, 0.0), 0.18, rings=11, segments=12),  # legs
        capsule((0.22, 0, 1.9), (0.3, 0, 0.0), 0.18, rings=11, segments=12))


def lowpoly_quadruped():
    """A four-legged animal: a horizontal body, four legs, a neck, a head and a tail, separate
    closed pieces pushed into the body."""
    legs = [capsule((x, y, 1.3), (x * 1.05, y * 1.1, 0.0), 0.16, rings=9, segments=10)
            for x in (-0.9, 0.9) for y in (-0.3, 0.3)]
    return combine(
        capsule((-1.4, 0, 1.5), (1.4, 0, 1.5), 0.55, rings=13, segments=24),  # body
        *legs,
        capsule((1.1, 0, 1.7), (1.7, 0, 2.5), 0.2, rings=7, segments=10),     # neck
        ellipsoid((1.95, 0, 2.6), (0.42, 0.22, 0.25), 10, 14),                # head
        capsule((-1.3, 0, 1.7), (-2.3, 0, 1.2), 0.07, rings=7, segments=8))   # tail


def subdivided(shape, levels):
    V, F = shape()
    for _ in range(levels):
        V, F = subdivide(V, F)
    return V, F


# (file, build, expected ends (MANIFEST's column, "" where the shape does not make it
# obvious), notes)
SHAPES = [
    ("spheres-chain4.obj", spheres_chain4, "2 (the chain's two ends)",
     "4 unit spheres overlapping in a row (centres 1.4 apart); self-intersecting union"),
    ("spheres-disjoint.obj", spheres_disjoint, "",
     "3 spheres (radius 1, 0.6, 0.35) apart from each other"),
    ("body-eyes-inside.obj", lambda: body_with_eyes("inside"), "2 (the body's two ends)",
     "capsule body + 2 eye spheres wholly inside the head"),
    ("body-eyes-touching.obj", lambda: body_with_eyes("touching"), "2-4 (body; eyes may bump)",
     "capsule body + 2 eye spheres centred on its surface (half out)"),
    ("body-eyes-outside.obj", lambda: body_with_eyes("outside"), "",
     "capsule body + 2 eye spheres 0.1 in front of it (detached)"),
    ("pinched-blobs.obj", pinched_blobs, "",
     "2 closed ellipsoids sharing one vertex (pinched, non-manifold vertex)"),
    ("scan-open.obj", scan_open, "",
     "bumpy blob (2 ears, snout), bottom cut off, 4 holes, 0.2% noise (seed 7): open"),
    ("lowpoly-biped.obj", lowpoly_biped, "5 (2 arms, 2 legs, head)",
     "game-like biped: 8 closed capsules/spheres pushed into the torso, uneven triangles"),
    ("lowpoly-quadruped.obj", lowpoly_quadruped, "6 (4 legs, head, tail)",
     "game-like quadruped: 8 closed pieces pushed into the body, uneven triangles"),
    ("biped-30k.ply", lambda: subdivided(lowpoly_biped, 2), "5 (2 arms, 2 legs, head)",
     "lowpoly-biped.obj midpoint-subdivided twice"),
    ("quadruped-100k.ply", lambda: subdivided(lowpoly_quadruped, 3), "6 (4 legs, head, tail)",
     "lowpoly-quadruped.obj midpoint-subdivided three times"),
]


def write_obj(path, V, F):
    lines = ["# scripts/make_stress_set.py"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in V]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in F]
    path.write_text("\n".join(lines) + "\n")


def manifest_row(name, V, F, expected, notes):
    topo = topology(weld_exact(V, F)[1])
    closed = "yes" if topo["closed"] else "no"
    if not topo["closed"]:
        bits = [f"{topo['border_edges']} border edges" if topo["border_edges"] else "",
                f"{topo['pinched_vertices']} pinched vertex" if topo["pinched_vertices"] else "",
                f"{topo['non_manifold_edges']} non-manifold edges"
                if topo["non_manifold_edges"] else ""]
        notes = f"NOT a closed manifold: {', '.join(b for b in bits if b)}; {notes}"
    row = {"file": name, "source_repo": "generated", "path_in_repo": "scripts/make_stress_set.py",
           "license": "GPL-3.0-or-later (generated)", "vertex_count": len(V),
           "face_count": len(F), "closed": closed,
           "genus": "" if topo["genus"] is None else topo["genus"],
           "components": topo["parts"], "expected_end_points": expected, "notes": notes}
    return "\t".join(str(row[c]) for c in MANIFEST_COLUMNS)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench" / "stress")
    parser.add_argument("--only", action="append", default=[], metavar="NAME",
                        help="write only this mesh (file name; repeatable)")
    args = parser.parse_args(argv)
    known = {name for name, *_ in SHAPES}
    unknown = sorted(set(args.only) - known)
    if unknown:
        print(f"make_stress_set: unknown mesh {', '.join(unknown)} (known: "
              f"{', '.join(sorted(known))})", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    rows = ["\t".join(MANIFEST_COLUMNS)]
    for name, build, expected, notes in SHAPES:
        if args.only and name not in args.only:
            continue
        V, F = build()
        path = args.out / name
        if path.suffix == ".ply":
            write_ply(path, V, F)
        else:
            write_obj(path, V, F)
        rows.append(manifest_row(name, V, F, expected, notes))
        print(f"make_stress_set: {path}: {len(V)} vertices, {len(F)} faces", file=sys.stderr)
    (args.out / "MANIFEST.tsv").write_text("\n".join(rows) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
